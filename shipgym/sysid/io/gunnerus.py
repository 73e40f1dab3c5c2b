"""R/V Gunnerus sea trials (NTNU, 27 Oct 2022, ``gunnerus_seatrials``), full scale.

Comma-separated with columns ``tvec, N, E, psi, u, v, r, Azi, RPM`` (SOURCES.md). Conversions:
``delta = -azimuth`` (both pods steer together; positive azimuth turns to port), ``azimuth``
kept with its own sign; ``psi``, ``r``, ``Azi`` deg -> rad; ``x = N``, ``y = E``; ``u``, ``v``
rescaled by 1.9834 / 1.943844 (the origin used 1/1.9834 instead of 1/1.943844 for kn -> m/s).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from shipgym.sysid.ingest import (
    base_meta,
    check_units,
    flag_irregular,
    read_columns,
    read_lines,
    repair_heading,
    silent,
    warn_repair,
)
from shipgym.sysid.io.registry import SourceFormat
from shipgym.sysid.record import Record

__all__ = ["FORMAT", "by_path", "load_gunnerus", "sniff"]

_GUNNERUS_SPEED_FIX = 1.9834 / (3600.0 / 1852.0)  # origin divided knots by 1.9834, not 1.943844


def load_gunnerus(path: Path, say: Callable[[str], None] = silent) -> Record:
    """Read one gunnerus file (module docstring); ``say`` takes progress lines."""
    lines = read_lines(path)
    needed = ["tvec", "N", "E", "psi", "u", "v", "r", "Azi", "RPM"]
    meta = base_meta(
        path,
        "gunnerus",
        vessel="R/V Gunnerus (NTNU), sea trials 27 Oct 2022",
        L=33.9,
        scale="full",
        frame="north/east [m] (flat earth at 63.47 N, 10.54 E)",
    )
    t, data, ix = read_columns(path, "gunnerus", lines, ",", needed, "tvec", meta, say)
    deg = np.pi / 180.0
    r = data[:, ix["r"]] * deg
    azimuth = data[:, ix["Azi"]] * deg
    u = data[:, ix["u"]] * _GUNNERUS_SPEED_FIX
    v = data[:, ix["v"]] * _GUNNERUS_SPEED_FIX
    check_units(
        t,
        data[:, ix["psi"]] * deg,
        r,
        -azimuth,
        meta,
        names={"time": "tvec", "delta": "Azi"},
    )
    psi = repair_heading(t, data[:, ix["psi"]] * deg, r, meta)
    warn_repair(
        meta,
        f"u, v multiplied by {_GUNNERUS_SPEED_FIX:.5f}: the origin converted knots with "
        "1/1.9834 instead of 1/1.943844",
    )
    meta["conversions"] += [
        "psi, r, Azi deg -> rad",
        "delta = -azimuth (both pods steer together; positive azimuth turns to port)",
        "x = N, y = E",
    ]
    meta["r_source"] = "measured"
    meta["notes"] += [
        "Azi and RPM are orders (commands) of the port azimuth / starboard rpm: the pods lag",
        "u, v are ground speeds (include current); v about +0.2 m/s on straight runs",
        "r has a bias of about -0.03 deg/s; turn rate is asymmetric (port/starboard)",
    ]
    flag_irregular(t, meta)
    return Record(
        time=t,
        delta=-azimuth,
        psi=psi,
        r=r,
        x=data[:, ix["N"]],
        y=data[:, ix["E"]],
        u=u,
        v=v,
        U=np.hypot(u, v),
        azimuth=azimuth,
        rpm=data[:, ix["RPM"]],
        meta=meta,
    )


def sniff(head: str) -> bool:
    """A comma-separated header with ``tvec``, ``Azi`` and ``RPM`` columns."""
    first = head.splitlines()[0] if head.strip() else ""
    return {"tvec", "Azi", "RPM"} <= {c.strip() for c in first.split(",")}


def by_path(path: Path) -> bool:
    """``rvg_*`` files and the ``gunnerus_seatrials`` folder."""
    return path.name.lower().startswith("rvg_") or path.parent.name.lower() == (
        "gunnerus_seatrials"
    )


FORMAT = SourceFormat("gunnerus", load_gunnerus, sniff, by_path)
"""The gunnerus format of :func:`shipgym.sysid.io.load`."""

"""Field tests of a small twin-hull USV (Fuzhou, ``usv_field``).

Comma-separated with columns ``time, lon, lat, speed, heading, rudder`` (SOURCES.md).
Conversions: ``delta`` from the measured ``rudder`` column [deg] (starboard-positive; the
``delta`` and ``-rudder`` columns of the file are its negative and are ignored); ``x``, ``y``
recomputed from lat/lon on the WGS84 local tangent plane; ``U = speed [kn] * 0.514444``; ``r``
derived from the heading.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from shipgym.sysid.ingest import (
    base_meta,
    check_units,
    derive_yaw_rate,
    flag_irregular,
    latlon_to_ne,
    read_columns,
    read_lines,
    repair_heading,
    silent,
)
from shipgym.sysid.io.registry import SourceFormat
from shipgym.sysid.record import Record
from shipgym.sysid.units import KNOT

__all__ = ["FORMAT", "by_path", "load_usv", "sniff"]


def load_usv(path: Path, say: Callable[[str], None] = silent) -> Record:
    """Read one usv file (module docstring); ``say`` takes progress lines."""
    lines = read_lines(path)
    needed = ["time", "lon", "lat", "speed", "heading", "rudder"]
    meta = base_meta(
        path,
        "usv",
        vessel="small twin-hull USV (Fuzhou field tests)",
        L=3.6,
        scale="full",
        frame="north/east [m] from the first GPS fix (WGS84 local tangent plane)",
    )
    t, data, ix = read_columns(path, "usv", lines, ",", needed, "time", meta, say)
    deg = np.pi / 180.0
    delta = data[:, ix["rudder"]] * deg
    x, y = latlon_to_ne(data[:, ix["lat"]], data[:, ix["lon"]])
    speed = data[:, ix["speed"]] * KNOT
    check_units(
        t,
        data[:, ix["heading"]] * deg,
        None,
        delta,
        meta,
        names={"psi": "heading", "delta": "rudder"},
    )
    psi = repair_heading(t, data[:, ix["heading"]] * deg, None, meta)
    flag_irregular(t, meta)
    window = 2.0
    r = derive_yaw_rate(t, psi, window)
    meta["r_source"] = (
        f"derived from psi (local quadratic / Savitzky-Golay, {window} s window): no yaw-rate "
        "sensor"
    )
    meta["conversions"] += [
        "delta = rudder [deg] -> rad (starboard positive; the file's delta / -rudder columns are"
        " its negative and are not used)",
        "heading deg -> rad",
        "x, y recomputed from lat/lon (the zigzag file's y0 is not a true east distance)",
        "U = speed [kn, most likely] * 0.514444",
    ]
    meta["notes"] += ["wind and current drift; heading quantised to 1 deg in the turning file"]
    same_fix = (np.diff(data[:, ix["lat"]]) == 0) & (np.diff(data[:, ix["lon"]]) == 0)
    if np.any(same_fix):
        meta["notes"].append(
            f"{int(same_fix.sum())} rows repeat the previous GPS fix (not updated); x, y kept"
        )
    return Record(time=t, delta=delta, psi=psi, r=r, x=x, y=y, U=speed, meta=meta)


def sniff(head: str) -> bool:
    """A comma-separated header with ``lon``, ``lat``, ``heading`` and ``rudder`` columns."""
    first = head.splitlines()[0] if head.strip() else ""
    return {"lon", "lat", "heading", "rudder"} <= {c.strip() for c in first.split(",")}


def by_path(path: Path) -> bool:
    """Files of the ``usv_field`` folder."""
    return path.parent.name.lower() == "usv_field"


FORMAT = SourceFormat("usv", load_usv, sniff, by_path)
"""The usv format of :func:`shipgym.sysid.io.load`."""

"""SSPA blog zigzag (``sspa_blog_zigzag``): a ship model's zigzag, ``;``-separated.

Columns ``time;delta;x0;y0;psi;r`` (SOURCES.md). Conversions: ``delta`` negated (the source's
positive rudder gives a port turn); ``r`` recomputed from ``psi`` by a Savitzky-Golay derivative
(the source's ``r`` is ``numpy.gradient(psi)``, not measured); ``U`` from the positions.
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
    header_error,
    measure_rudder_offset,
    read_columns,
    read_lines,
    repair_heading,
    silent,
    split_header,
    warn_repair,
)
from shipgym.sysid.io.registry import SourceFormat
from shipgym.sysid.record import Record

__all__ = ["FORMAT", "by_path", "load_sspa", "sniff"]


def load_sspa(path: Path, say: Callable[[str], None] = silent) -> Record:
    """Read one sspa file (module docstring); ``say`` takes progress lines."""
    lines = read_lines(path)
    needed = ["time", "delta", "x0", "y0", "psi", "r"]
    if len(split_header(lines[0], ";")) < 2:
        raise header_error(
            path, "sspa", "a ';'-separated header 'time;delta;x0;y0;psi;r'", lines[0]
        )
    meta = base_meta(
        path,
        "sspa",
        vessel="unknown SSPA ship model (not documented)",
        scale="model",
        frame="x0 along the approach course, y0 to starboard (earth-fixed)",
    )
    t, data, ix = read_columns(path, "sspa", lines, ";", needed, "time", meta, say)
    delta = -data[:, ix["delta"]]
    meta["conversions"].append("delta negated (source: positive rudder gives a port turn)")
    x, y = data[:, ix["x0"]], data[:, ix["y0"]]
    window = 0.3
    speed = np.hypot(derive_yaw_rate(t, x, window), derive_yaw_rate(t, y, window))
    check_units(
        t, data[:, ix["psi"]], data[:, ix["r"]], delta, meta, U=speed, speed_is_derived=True
    )
    psi = repair_heading(t, data[:, ix["psi"]], data[:, ix["r"]], meta)
    r = derive_yaw_rate(t, psi, window)
    meta["r_source"] = f"derived from psi (local quadratic / Savitzky-Golay, {window} s window)"
    warn_repair(
        meta,
        "source r is numpy.gradient(psi), not measured; replaced by a Savitzky-Golay "
        f"derivative of psi ({window} s window)",
    )
    meta["notes"].append("U derived from x0, y0 (Savitzky-Golay derivative, 0.3 s window)")
    meta["notes"].append("rudder quantised in steps of about 0.02 deg")
    measure_rudder_offset(t, delta, meta)
    flag_irregular(t, meta)
    return Record(time=t, delta=delta, psi=psi, r=r, x=x, y=y, U=speed, meta=meta)


def sniff(head: str) -> bool:
    """A header starting ``time;delta;``."""
    first = head.splitlines()[0] if head.strip() else ""
    return first.replace(" ", "").startswith("time;delta;")


def by_path(path: Path) -> bool:
    """``example_zigzag*`` files and the ``sspa_blog_zigzag`` folder."""
    return path.name.lower().startswith("example_zigzag") or path.parent.name.lower() == (
        "sspa_blog_zigzag"
    )


FORMAT = SourceFormat("sspa", load_sspa, sniff, by_path)
"""The sspa format of :func:`shipgym.sysid.io.load`."""

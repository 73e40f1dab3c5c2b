"""HSVA KVLCC2 captive-free model tests (CPMC, SIMMAN 2008, ``hsva_kvlcc2``), model scale.

Four header lines (cp1252) starting `` HSVA``, then 12 whitespace-separated columns
(SOURCES.md). Conversions: deg -> rad; ``delta`` negated ("positive steering to port side");
earth-fixed velocities rotated into body ``u``, ``v``; ``rpm = 60 n``; ``thrust`` [N] from
column 11.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from shipgym.sysid.ingest import (
    base_meta,
    header_error,
    parse_table,
    read_lines,
    repair_time,
    report_empty_rows,
    require_complete_rows,
    silent,
    tank_channels,
)
from shipgym.sysid.io.registry import SourceFormat
from shipgym.sysid.record import Record

__all__ = ["FORMAT", "by_path", "load_hsva", "sniff"]


def load_hsva(path: Path, say: Callable[[str], None] = silent) -> Record:
    """Read one hsva file (module docstring); ``say`` takes progress lines."""
    lines = read_lines(path, encoding="cp1252")
    if "HSVA" not in lines[0]:
        raise header_error(
            path,
            "hsva",
            "4 header lines starting with ' HSVA' then 12 whitespace-separated columns",
            lines[0],
        )
    meta = base_meta(
        path,
        "hsva",
        vessel="KVLCC2, INSEAN model 2487 (HSVA CPMC, SIMMAN 2008)",
        L=7.0,
        scale="model",
        title=lines[2].strip(),
        frame="earth-fixed x0, y0 (y to starboard)",
    )
    data, n_empty = parse_table(lines[4:], None, 12, path, 5, say)
    report_empty_rows(n_empty, meta)
    require_complete_rows(data, range(11), meta)
    t, data = repair_time(data[:, 0], data, meta)
    channels = tank_channels(
        t, data, meta, {"x": 1, "y": 2, "psi": 3, "dx": 4, "dy": 5, "r": 6, "delta": 8},
        "report: positive = steering to port side",
    )  # fmt: skip
    meta["conversions"] += [
        "rpm = 60 * n [rps]",
        "thrust [N] from column 11 (total propeller thrust, model scale)",
    ]
    return Record(**channels, rpm=60.0 * data[:, 9], thrust=data[:, 10], meta=meta)

def sniff(head: str) -> bool:
    """A first line holding ``HSVA``."""
    first = head.splitlines()[0] if head.strip() else ""
    return first.strip().startswith("HSVA")


def by_path(path: Path) -> bool:
    """``hsva_*`` files and the ``hsva_kvlcc2`` folder."""
    return path.name.lower().startswith("hsva_") or path.parent.name.lower() == "hsva_kvlcc2"


FORMAT = SourceFormat("hsva", load_hsva, sniff, by_path)
"""The hsva format of :func:`shipgym.sysid.io.load`."""

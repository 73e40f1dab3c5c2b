"""MARIN KVLCC2 free-running trials (SIMMAN 2008, ``marin_kvlcc2``), full scale.

Tab-separated, a ``MARIN`` title line, 11 columns (time x0 y0 phi psi dx0 dy0 p r delta rpm;
SOURCES.md). Conversions: deg -> rad for ``psi``, ``r``, ``delta``; ``delta`` negated (the
source's positive rudder gives a port turn); time rebuilt as ``index * 0.135264 s`` (the time
stamps have 3 significant digits); earth-fixed ``dx0/dt``, ``dy0/dt`` rotated into body
``u``, ``v``.
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

__all__ = ["FORMAT", "by_path", "load_marin", "sniff"]

_MARIN_SCALE = 45.714
_MARIN_DT = 0.135264  # s full scale = 0.02 s model scale * sqrt(45.714)


def load_marin(path: Path, say: Callable[[str], None] = silent) -> Record:
    """Read one marin file (module docstring); ``say`` takes progress lines."""
    lines = read_lines(path)
    if not lines[0].startswith("MARIN"):
        raise header_error(
            path,
            "marin",
            "a first title line starting with 'MARIN' and 11 "
            "tab-separated columns (time x0 y0 phi psi dx0 dy0 p r delta rpm)",
            lines[0],
        )
    meta = base_meta(
        path,
        "marin",
        vessel="KVLCC2 (MARIN free running, SIMMAN 2008)",
        L=320.0,
        scale="full",
        model_scale_factor=_MARIN_SCALE,
        title=lines[1].strip(),
        frame="earth-fixed x0, y0 (NED-like)",
    )
    data, n_empty = parse_table(lines[3:], "\t", 11, path, 4, say)
    report_empty_rows(n_empty, meta)
    require_complete_rows(data, range(11), meta)
    t, data = repair_time(data[:, 0], data, meta, known_dt=_MARIN_DT)
    meta["notes"] += [
        "all values have 3 significant digits (psi resolution 1 deg above 100 deg, x0 10 m above"
        " 1000 m)",
        "full scale; model scale: time and speeds / sqrt(45.714), lengths / 45.714",
    ]
    channels = tank_channels(
        t, data, meta, {"x": 1, "y": 2, "psi": 4, "dx": 5, "dy": 6, "r": 8, "delta": 9},
        "source: positive rudder gives a port turn",
    )  # fmt: skip
    return Record(**channels, rpm=data[:, 10], meta=meta)

def sniff(head: str) -> bool:
    """A first line starting ``MARIN``."""
    return head.startswith("MARIN")


def by_path(path: Path) -> bool:
    """``marin_free*`` files and the ``marin_kvlcc2`` folder."""
    return path.name.lower().startswith("marin_free") or path.parent.name.lower() == (
        "marin_kvlcc2"
    )


FORMAT = SourceFormat("marin", load_marin, sniff, by_path)
"""The marin format of :func:`shipgym.sysid.io.load`."""

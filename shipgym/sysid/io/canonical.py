"""The canonical CSV of :meth:`Record.to_csv <shipgym.sysid.record.Record.to_csv>` as a format.

The canonical CSV is the record's own file: :mod:`shipgym.sysid.record` writes and reads it
(:func:`~shipgym.sysid.record.read_canonical`, where its layout and meta lines are described).
This module recognises it: a file that starts with ``# shipgym canonical``, or whose header (the
first line that is not a ``#`` meta line) names only canonical columns (``time_s, delta_rad,
psi_rad, r_rad_s`` and the optional ones; the reader names a required one that is missing). A
table with any other column (``time_s, rudder_deg, heading_deg``) is not canonical whatever its
first column: it goes to the table loader (:mod:`shipgym.sysid.io.table`).
"""

from __future__ import annotations

from shipgym.sysid.io.registry import SourceFormat
from shipgym.sysid.record import CANONICAL_COLUMNS, read_canonical

__all__ = ["FORMAT", "sniff"]


def sniff(head: str) -> bool:
    """Whether the start of a file is a canonical CSV (module docstring)."""
    lines = head.splitlines()
    if lines and lines[0].startswith("# shipgym canonical"):  # any version
        return True
    header = next((ln for ln in lines if ln.strip() and not ln.startswith("#")), "")
    cols = {c.strip() for c in header.split(",")}
    return len(cols) > 1 and cols <= set(CANONICAL_COLUMNS)


FORMAT = SourceFormat("canonical", read_canonical, sniff)
"""The canonical format of :func:`shipgym.sysid.io.load`."""

"""The project's measured records: where they are and all of them at once (:func:`load_all`).

The six measured sources are the datasets of :mod:`shipgym.datasets` (their origins, licences
and citations; ``shipgym data list``); each has a loader module in :mod:`shipgym.sysid.io`.
:func:`measured_root` is the registry's: ``$SHIPGYM_MEASURED_DATA`` when set, else the user
cache that ``shipgym data fetch`` fills.
"""

from __future__ import annotations

from pathlib import Path

from shipgym.datasets import MEASURED_DATA_ENV, measured_root
from shipgym.sysid.io.registry import load
from shipgym.sysid.record import Record

__all__ = ["MEASURED_DATA_ENV", "load_all", "measured_root"]

_SOURCE_GLOBS: tuple[tuple[str, str], ...] = (
    ("sspa_blog_zigzag/*.csv", "sspa"),
    ("marin_kvlcc2/*.dat", "marin"),
    ("hsva_kvlcc2/*.dat", "hsva"),
    ("esso_osaka_frt/*/*.csv", "esso_osaka"),
    ("usv_field/*.csv", "usv"),
    ("gunnerus_seatrials/*.csv", "gunnerus"),
)


def load_all(root: str | Path) -> list[Record]:
    """Load every file of the six measured sources under ``root`` (sorted by source, name).

    ``root`` is the ``measured`` folder (:func:`measured_root`), one folder per source.

    Raises
    ------
    ValueError
        If ``root`` is not a folder or holds none of the sources.
    """
    root = Path(root)
    if not root.is_dir():
        raise ValueError(f"{root} is not a folder (expected the measured-data root)")
    records: list[Record] = []
    for pattern, fmt in _SOURCE_GLOBS:
        for f in sorted(root.glob(pattern)):
            records.append(load(f, fmt))
    if not records:
        raise ValueError(
            f"no measured-data files under {root}; expected folders "
            f"{[p.split('/')[0] for p, _ in _SOURCE_GLOBS]}"
        )
    return records

"""The registry of record formats: each format's loader and how a file is recognised as it.

A format is a :class:`SourceFormat`: its name, its loader ``(path, say, **options) -> Record``,
a sniffer of the first kB of a file, optionally a test of the file's path (the name of a
measured source's file or folder) and the loader's keyword options. :func:`register` adds one;
:mod:`shipgym.sysid.io` registers the built-in formats, one module each.

Detection (:func:`detect_format`) asks, in this order: every format's header sniffer (the
formats whose header is distinctive); every format's path test; then the sniffers of the
fallback formats, in the order registered (a file of NMEA sentences, then any delimited table).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shipgym.sysid.ingest import UTF8_BOM, ProgressArg, load_with_progress
from shipgym.sysid.record import Record

__all__ = ["HEAD_BYTES", "REGISTRY", "SourceFormat", "detect_format", "load", "register"]

HEAD_BYTES: int = 4096
"""Bytes at the start of a file that the sniffers see."""


@dataclass(frozen=True)
class SourceFormat:
    """One record format of :func:`load`.

    Attributes
    ----------
    name : str
        The format's name (``format=`` of :func:`load`, ``--format`` of the command line).
    load : callable
        ``(path, say, **options) -> Record``: ``say`` takes one-line progress messages.
    sniff : callable
        ``(head) -> bool``: whether the first :data:`HEAD_BYTES` of a file (as text, a UTF-8
        byte-order mark dropped) are this format's.
    by_path : callable, optional
        ``(path) -> bool``: whether the file's name or folder names this format (the measured
        sources, whose headers alone may not tell).
    fallback : bool
        A guess from the content only (NMEA sentences, any delimited table): asked after every
        other format's header and path.
    options : tuple of str
        The keyword options the loader takes (``columns``, ``max_gap_s``).
    """

    name: str
    load: Callable[..., Record]
    sniff: Callable[[str], bool]
    by_path: Callable[[Path], bool] | None = None
    fallback: bool = False
    options: tuple[str, ...] = ()


REGISTRY: dict[str, SourceFormat] = {}
"""Format name -> :class:`SourceFormat`, in the order registered."""


def register(fmt: SourceFormat) -> SourceFormat:
    """Add ``fmt`` to :data:`REGISTRY` (``ValueError`` for a name registered already)."""
    if fmt.name in REGISTRY:
        raise ValueError(f"format {fmt.name!r} is registered already")
    REGISTRY[fmt.name] = fmt
    return fmt


def _names() -> str:
    return ", ".join(REGISTRY)


def detect_format(path: str | Path) -> str:
    """The format of a record file: by its header, then by its name, then by its content.

    Raises
    ------
    ValueError
        If no format recognises the file; the message lists the formats.
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            head = fh.read(HEAD_BYTES).removeprefix(UTF8_BOM).decode("cp1252", errors="replace")
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc}") from exc
    formats = list(REGISTRY.values())
    for fmt in formats:
        if not fmt.fallback and fmt.sniff(head):
            return fmt.name
    for fmt in formats:
        if fmt.by_path is not None and fmt.by_path(path):
            return fmt.name
    for fmt in formats:
        if fmt.fallback and fmt.sniff(head):
            return fmt.name
    first = head.splitlines()[0] if head.strip() else ""
    reason = "the file is empty" if not first else f"first line {first[:80]!r}"
    raise ValueError(
        f"cannot detect the format of {path.name} ({reason}); accepted formats: {_names()} "
        "(pass format=...)"
    )


def load(
    path: str | Path,
    format: str | None = None,
    *,
    progress: ProgressArg = None,
    columns: str | Mapping[str, str] | None = None,
    max_gap_s: float | None = None,
) -> Record:
    """Load one record file into a canonical :class:`~shipgym.sysid.record.Record`.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.
    format : str, optional
        A name of :data:`REGISTRY` (:data:`shipgym.sysid.io.FORMATS`); detected from the
        header, the file and folder name and the content when None (:func:`detect_format`).
    progress : callable, file, bool or None
        Where one-line progress messages go while loading (a callable taking the line, a text
        file, True for stderr, False for none). None (default): stderr for files larger than
        :data:`shipgym.sysid.ingest.PROGRESS_FILE_BYTES`, nothing for smaller ones.
    columns : str or mapping, optional
        A column map for a ship's own table (format ``table``, implied):
        ``"time=t,delta=-rudder:deg,psi=hdg:deg,r=rot:deg/min,U=sog:kn"``
        (:func:`shipgym.sysid.io.table.parse_columns`).
    max_gap_s : float, optional
        Formats ``table`` and ``nmea``: the longest time step [s] inside a segment (a longer
        one splits the record into ``meta["segments"]``).

    Returns
    -------
    Record
        One record per file (the long Gunnerus sea-trial file is one record).

    Raises
    ------
    ValueError
        Unknown format, a file that does not match the (given) format, empty or malformed
        files, probable unit errors (:func:`shipgym.sysid.ingest.check_units`), and data
        oddities that cannot be repaired safely.

    Warns
    -----
    SysidDataWarning
        For every repair, for borderline unit checks, and for a record of more than
        :data:`shipgym.sysid.ingest.LARGE_RECORD_SAMPLES` samples.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path} is not a file")
    if columns is not None:
        if format not in (None, "table"):
            raise ValueError(f"a column map goes with format 'table', not {format!r}")
        format = "table"
    if format is None:
        format = detect_format(path)
    fmt = REGISTRY.get(format) if isinstance(format, str) else None
    if fmt is None:
        raise ValueError(f"unknown format {format!r}; accepted formats: {_names()}")
    kw: dict[str, Any] = {}
    for option, value in (("max_gap_s", max_gap_s), ("columns", columns)):
        if value is None:
            continue
        if option not in fmt.options:
            takes = [f.name for f in REGISTRY.values() if option in f.options]
            raise ValueError(
                f"{option} applies to the formats {' and '.join(takes)}, not {format!r}"
            )
        kw[option] = value
    return load_with_progress(fmt.load, path, format, progress, **kw)

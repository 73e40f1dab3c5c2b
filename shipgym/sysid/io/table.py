"""A ship's own log as a :class:`~shipgym.sysid.record.Record`: any delimited table, any units.

A delimited text table (:func:`load_table`, ``load(path, columns=...)``, ``shipgym identify
FILE --columns ...``) whose columns are named by a column map or by headers that state their
unit; its columns go through the pipeline of arrays in any units
(:func:`shipgym.sysid.record.record_from_arrays`, also :meth:`Record.from_arrays
<shipgym.sysid.record.Record.from_arrays>`). Format detection sends every delimited table
that is not one of the other formats here (:func:`sniff`), whatever its first column is called.

Column map
----------
``time=t,delta=-rudder_deg:deg,psi=hdg:deg,r=rot:deg/min,U=sog:kn`` (or the same as a mapping
``{"delta": "-rudder_deg:deg", ...}``): each entry maps a channel of the record to a column of
the file, with its unit after the last ``:`` and a leading ``-`` to negate the column. Channels
and units (:data:`shipgym.sysid.units.UNITS`):

=========== =================================================== ============================
channel     meaning (record convention)                         units
=========== =================================================== ============================
time        time                                                s, ms, min, h, datetime (ISO
                                                                8601 strings, e.g.
                                                                ``2026-12-31T23:59:58.1Z``)
delta       rudder, **positive turns the ship to starboard**     rad, deg
psi         heading, **clockwise from north**                   rad, deg
r           yaw rate, positive clockwise (optional: derived)    rad/s, deg/s, deg/min
U, u, v     speed; body surge and sway (optional)               m/s, kn, km/h
x, y        north and east position (optional)                  m, km
lat, lon    latitude and longitude (optional; projected to a    deg
            local tangent plane like the USV loader)
rpm         propeller speed (optional)                          rpm, rev/s
=========== =================================================== ============================

A port-positive rudder is ``delta=-rudder:deg``; a mathematical (counter-clockwise) heading or
yaw rate ``psi=-yaw:rad`` and ``r=-yawrate:rad/s`` (a heading measured from east needs an
offset as well: convert it before). Required: ``time``, ``delta``, ``psi``.

Headers that state their unit are mapped without a column map: a name of :data:`ALIASES`
(``rudder``, ``heading``, ``yaw_rate``, ``rot``, ``sog``, ``lat`` ...) with the unit in
brackets or parentheses (``rudder [deg]``, ``yaw_rate (deg/s)``) or as a suffix
(``heading_deg``, ``r_rad_s``, ``t_s``, ``speed_kn``). Latitude and longitude have one unit
(decimal degrees) and are mapped by name alone. A header whose unit is not stated is never
guessed: the error names the columns found, the channels needed and a ``--columns`` example
built from the file's header.

Text
----
Delimiter ``,``, ``;``, tab or runs of blanks (the one that splits the header into the most
fields); fields in double quotes (which may hold the delimiter); a decimal comma (``12,5`` with
``;``, tab or blanks between fields, or ``"12,5"`` quoted with any); comment lines starting
with ``#``, ``%`` or ``//`` anywhere; UTF-8 with or without a byte-order mark, or else
Windows-1252 (a Windows export with a degree sign in a header).

Meta lines: ``# key: value`` comment lines before the header go into the record's meta, the
value as a number when it is one, else as text: the ship's main particulars (``# L: 7.0``,
``# B: 1.27``, ``# draft: 0.46``, ``# displacement_m3: 3.27``, ``# x_G: 0.25``, read by the 3-DOF
models, :func:`shipgym.models.vmm.find_particulars`), ``# vessel: ...`` and the like. A key the
loader writes itself (``source``, ``file``, ``conversions``, ``repairs``, ``notes`` and the keys
of the processing) or a key given twice is refused, naming the line.

Gaps and segments
-----------------
A row that misses a value of a mapped channel (an empty field, ``nan``) is a gap, and so is a
time step longer than ``max_gap_s`` (default :data:`~shipgym.sysid.record.GAP_FACTOR` times the
median step). The
record is split there into segments rather than interpolated across: the rows of a gap are
dropped, ``meta["segments"]`` lists each segment's ``[t0, t1]`` and a
:class:`~shipgym.sysid.ingest.SysidDataWarning` reports them; :meth:`Record.segments` returns them
as records and :func:`~shipgym.sysid.engine.identify` fits one-record models to the longest.
A segment of fewer than :data:`~shipgym.sysid.record.MIN_SEGMENT_SAMPLES` samples is dropped and
reported.

Processing (as the measured-source loaders do, per segment where it matters): units to SI and
radians, time from datetimes to seconds from the first sample (``meta["start_time"]``), the
unit checks of :mod:`shipgym.sysid.ingest` (a heading in degrees, a yaw rate in deg/s, knots ...),
heading unwrapped and repaired, yaw rate derived from the heading when absent (local quadratic,
:data:`~shipgym.sysid.record.R_WINDOW_S`), the neutral rudder measured
(``meta["rudder_offset_rad"]``).
"""

from __future__ import annotations

import csv
import math
import re
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from shipgym.sysid.ingest import base_meta, read_lines, silent, warn_repair
from shipgym.sysid.io.registry import SourceFormat
from shipgym.sysid.record import Record, meta_expected, record_from_arrays
from shipgym.sysid.units import (
    CHANNELS,
    REQUIRED_INPUTS,
    UNIT_SPELLINGS,
    UNITS,
    parse_numbers,
    parse_time,
    unit_of,
)

__all__ = ["ALIASES", "FORMAT", "load_table", "parse_columns", "sniff"]

#: Header names (lower case, blanks and dashes as ``_``) of each channel.
ALIASES: dict[str, tuple[str, ...]] = {
    "time": ("time", "t", "timestamp", "utc", "datetime", "date_time", "elapsed", "elapsed_time"),
    "delta": ("delta", "rudder", "rudder_angle", "rsa", "helm"),
    "psi": ("psi", "heading", "hdg", "heading_true", "true_heading", "hdt", "yaw"),
    "r": ("r", "yaw_rate", "rot", "rate_of_turn", "turn_rate", "yawrate"),
    "U": ("u_total", "speed", "sog", "speed_over_ground", "stw", "speed_through_water"),
    "u": ("u", "surge", "surge_velocity"),
    "v": ("v", "sway", "sway_velocity"),
    "x": ("x", "north", "northing"),
    "y": ("y", "east", "easting"),
    "lat": ("lat", "latitude"),
    "lon": ("lon", "long", "lng", "longitude"),
    "rpm": ("rpm", "shaft_speed", "propeller_speed"),
}

_COMMENT = ("#", "%", "//")
_BRACKET = re.compile(r"^(?P<name>.*?)\s*[\[(](?P<unit>[^\])]*)[\])]\s*$")
_DECIMAL_COMMA = re.compile(r"^[-+]?\d+,\d+([eE][-+]?\d+)?$")


# ----------------------------------------------------------------------------------------------
# column maps
# ----------------------------------------------------------------------------------------------
def _norm(name: str) -> str:
    return re.sub(r"[\s\-]+", "_", name.strip().lower())


def parse_columns(columns: str | Mapping[str, str]) -> dict[str, tuple[str, str, bool]]:
    """Parse a column map into ``{channel: (column, unit, negate)}``.

    Parameters
    ----------
    columns : str or mapping
        ``"time=t,delta=-rudder_deg:deg,psi=hdg:deg"`` or ``{"time": "t", "delta":
        "-rudder_deg:deg", ...}``. A time column without a unit is in seconds; every other
        channel states its unit (``lat``/``lon``: degrees, may be omitted).

    Raises
    ------
    ValueError
        For an unknown channel, a channel given twice, a missing or unknown unit, or an entry
        that is not ``channel=column[:unit]``.
    """
    if isinstance(columns, str):
        entries: list[tuple[str, str]] = []
        for part in columns.split(","):
            if not part.strip():
                continue
            channel, sep, spec = part.partition("=")
            if not sep or not channel.strip() or not spec.strip():
                raise ValueError(
                    f"column map entry {part.strip()!r} is not channel=column[:unit] (for "
                    "example 'psi=hdg:deg')"
                )
            entries.append((channel.strip(), spec.strip()))
    elif isinstance(columns, Mapping):
        entries = [(str(k).strip(), str(v).strip()) for k, v in columns.items()]
    else:
        raise ValueError(
            f"columns must be a str like 'time=t,psi=hdg:deg' or a mapping, got "
            f"{type(columns).__name__}"
        )
    out: dict[str, tuple[str, str, bool]] = {}
    for channel, spec in entries:
        if channel not in CHANNELS:
            raise ValueError(
                f"unknown channel {channel!r} in the column map; expected any of "
                f"{', '.join(CHANNELS)}"
            )
        if channel in out:
            raise ValueError(f"channel {channel!r} appears twice in the column map")
        column, unit = spec, ""
        head, sep, tail = spec.rpartition(":")
        if sep and (tail.strip().lower() in UNIT_SPELLINGS or tail.strip() in UNITS[channel]):
            column, unit = head, tail
        negate = column.startswith("-")
        column = column[1:].strip() if negate else column.strip()
        if not column:
            raise ValueError(f"channel {channel!r} in the column map names no column: {spec!r}")
        if not unit:
            if channel == "time":
                unit = "s"
            elif channel in ("lat", "lon"):
                unit = "deg"
            else:
                raise ValueError(
                    f"channel {channel!r} (column {column!r}) has no unit in the column map; "
                    f"expected {channel}={'-' if negate else ''}{column}:UNIT with UNIT one of "
                    f"{', '.join(UNITS[channel])}"
                )
        unit = unit_of(channel, unit, f"column map entry {channel}={spec}")
        if negate and channel in ("time", "lat", "lon", "rpm"):
            raise ValueError(f"channel {channel!r} cannot be negated in the column map")
        out[channel] = (column, unit, negate)
    return out


def _header_channel(header: str) -> tuple[str | None, str | None]:
    """``(channel, unit)`` a header names (either may be None)."""
    m = _BRACKET.match(header)
    bare = (m.group("name") if m else header).strip()
    if bare == "U" or bare.startswith("U_"):  # the capital U of the speed, not the surge u
        unit = m.group("unit") if m else (bare[2:].replace("_", "/", 1) or None)
        if unit is None:
            return "U", None
        spelled = UNIT_SPELLINGS.get(unit.strip().lower(), unit.strip())
        return ("U", spelled) if spelled in UNITS["U"] else (None, None)
    names = [(_norm(m.group("name")), m.group("unit"))] if m else []
    norm = _norm(header)
    names.append((norm, None))
    # a unit suffix: the longest spelling that ends the name after an underscore
    for spelling in sorted(UNIT_SPELLINGS, key=len, reverse=True):
        if norm.endswith("_" + spelling) and len(norm) > len(spelling) + 1:
            names.append((norm[: -len(spelling) - 1], spelling))
    for name, unit in names:
        for channel, aliases in ALIASES.items():
            if name in aliases:
                if unit is not None:
                    spelled = UNIT_SPELLINGS.get(unit.strip().lower(), unit.strip())
                    if spelled not in UNITS[channel]:
                        continue
                    return channel, spelled
                return channel, None
    return None, None


def _auto_columns(
    cols: Sequence[str], where: str
) -> tuple[dict[str, tuple[str, str, bool]], dict[str, str]]:
    """The column map that the headers state (see the module docstring) and the optional
    channels left out for want of a unit (channel -> column), or a ValueError that names the
    columns found, the channels needed and a ``--columns`` example."""
    found: dict[str, tuple[str, str, bool]] = {}
    unitless: dict[str, str] = {}
    for col in cols:
        channel, unit = _header_channel(col)
        if channel is None or channel in found:
            continue
        if unit is None and channel in ("lat", "lon"):
            unit = "deg"
        if unit is None:
            unitless.setdefault(channel, col)
        else:
            found[channel] = (col, unit, False)
    missing = [ch for ch in REQUIRED_INPUTS if ch not in found]
    if not missing:  # every required channel is mapped; unit-less optional columns are skipped
        return found, {ch: col for ch, col in unitless.items() if ch not in found}
    example = []
    for channel in CHANNELS:
        col = found.get(channel, (unitless.get(channel),))[0]
        if col is None:
            continue
        unit = found[channel][1] if channel in found else "|".join(UNITS[channel])
        example.append(
            f"{channel}={col}:{unit}" if channel in found else f"{channel}={col}:<{unit}>"
        )
    if not any(e.startswith("time=") for e in example):
        example.insert(0, "time=<column>:<s|ms|datetime>")
    for channel in ("delta", "psi"):
        if not any(e.startswith(channel + "=") for e in example):
            example.append(f"{channel}=<column>:<{'|'.join(UNITS[channel])}>")
    need = " and ".join(
        f"{ch} ({'unit not stated' if ch in unitless else 'no column'})" for ch in missing
    )
    raise ValueError(
        f"{where}: cannot map the columns {list(cols)} to a record: {need}; a header's unit is "
        "never guessed. Needed: time, delta (rudder, starboard positive), psi (heading, "
        "clockwise from north); optional r, U, u, v, x, y, lat, lon, rpm. Map them with "
        f"--columns \"{','.join(example)}\" (choose each <unit>; '-column' negates, e.g. a "
        "port-positive rudder)"
    )


# ----------------------------------------------------------------------------------------------
# text
# ----------------------------------------------------------------------------------------------
def _is_comment(line: str) -> bool:
    s = line.lstrip()
    return not s or s.startswith(_COMMENT)


def _split(line: str, sep: str | None) -> list[str]:
    """The fields of a line (``sep`` None: runs of blanks); a field in double quotes may hold
    the delimiter (``"12,5"`` in a comma-separated export with a decimal comma)."""
    if sep is None:
        return line.split()
    if '"' not in line:
        return line.split(sep)
    return next(csv.reader([line], delimiter=sep))


def _sniff(header: str, sample: str) -> str | None:
    """The delimiter (None: runs of blanks) that splits the header and a data row alike."""
    best: tuple[int, str | None] = (1, None)
    for sep in (",", ";", "\t"):
        n = len(_split(header, sep))
        if n > best[0] and len(_split(sample, sep)) == n:
            best = (n, sep)
    if best[1] is None and len(header.split()) == len(sample.split()) > 1:
        return None
    if best[0] == 1:
        raise ValueError("no delimiter")
    return best[1]


_META_LINE = re.compile(r"^#\s*(?P<key>[A-Za-z_][A-Za-z0-9_.\-]*)\s*:\s*(?P<value>\S.*?)\s*$")
#: Meta keys a table's meta lines may not set: the loader and the processing write them.
_LOADER_KEYS = frozenset(
    (
        "source",
        "file",
        "conversions",
        "repairs",
        "notes",
        "segments",
        "slice_s",
        "r_source",
        "start_time",
        "irregular_sampling",
        "rudder_offset_rad",
        "first_rudder_order_s",
        "resampled_dt",
    )
)


def _meta_lines(name: str, lines: Sequence[str]) -> dict[str, Any]:
    """The ``# key: value`` lines before the header (module docstring): a number when the value
    is one, else the text."""
    meta: dict[str, Any] = {}
    line_of: dict[str, int] = {}
    for number, line in enumerate(lines, start=1):
        m = _META_LINE.match(line.strip())
        if m is None:
            continue
        key, text = m.group("key"), m.group("value")
        where = f"{name} line {number}"
        if key in _LOADER_KEYS:
            raise ValueError(
                f"{where}: meta key {key!r} is written by the loader; expected a key of the "
                "ship or the trial (e.g. vessel, L, B, draft, displacement_m3, x_G)"
            )
        if key in line_of:
            raise ValueError(
                f"{where}: meta key {key!r} repeats line {line_of[key]}; expected each meta "
                "key once"
            )
        try:
            value: Any = float(text)
        except ValueError:
            value = text
        if isinstance(value, float) and not math.isfinite(value):
            raise ValueError(f"{where}: meta {key} = {text!r}; expected a finite number")
        expected = meta_expected(key, value)
        if expected is not None:
            raise ValueError(f"{where}: meta {key} = {text!r}; expected {expected}")
        meta[key] = value
        line_of[key] = number
    return meta


def load_table(
    path: Path,
    say: Callable[[str], None] = silent,
    *,
    columns: str | Mapping[str, str] | None = None,
    max_gap_s: float | None = None,
) -> Record:
    """Load a delimited table with a column map or unit-stating headers (module docstring).

    Parameters
    ----------
    path : pathlib.Path
        The file.
    say : callable
        Progress printer.
    columns : str or mapping, optional
        Column map (:func:`parse_columns`); None maps the headers that state their unit.
    max_gap_s : float, optional
        Longest time step [s] inside a segment (default :data:`GAP_FACTOR` median steps).

    Raises
    ------
    ValueError
        Naming the file and what was wrong: an unknown column, a channel without a stated unit,
        a column of text, time going backwards, fewer than two samples.
    """
    try:
        lines = read_lines(path)
        windows = False
    except ValueError as exc:  # a Windows export (a degree sign in a header): code page 1252
        if not isinstance(exc.__cause__, UnicodeDecodeError):
            raise
        lines = read_lines(path, "cp1252")
        windows = True
    rows = [(k + 1, line) for k, line in enumerate(lines) if not _is_comment(line)]
    if len(rows) < 3:
        raise ValueError(
            f"{path.name}: {max(len(rows) - 1, 0)} data rows; expected a header line and at "
            "least two samples"
        )
    header_line, header = rows[0]
    try:
        sep = _sniff(header, rows[1][1])
    except ValueError:
        raise ValueError(
            f"{path.name} line {header_line}: cannot split the header {header[:80]!r} and the "
            "first data row into the same fields with ',', ';', tab or blanks"
        ) from None
    cols = [c.strip().strip('"') for c in _split(header, sep)]
    seen: dict[str, int] = {}
    for j, c in enumerate(cols):
        if c in seen:
            raise ValueError(
                f"{path.name}: column {c!r} appears twice in the header (columns {seen[c] + 1} "
                f"and {j + 1}); expected each column name once"
            )
        seen[c] = j
    skipped: dict[str, str] = {}
    if columns is not None:
        mapping = parse_columns(columns)
    else:
        mapping, skipped = _auto_columns(cols, path.name)
    for channel, (col, _, _) in mapping.items():
        if col not in seen:
            raise ValueError(
                f"{path.name}: the column map names column {col!r} for {channel}, which the "
                f"header does not have; columns: {cols}"
            )
    missing = [ch for ch in REQUIRED_INPUTS if ch not in mapping]
    if missing:
        raise ValueError(
            f"{path.name}: the column map has no {', '.join(missing)}; required: time, delta, psi"
        )
    say(f"{path.name}: {len(rows) - 1} rows, delimiter {sep or 'blanks'!r}")
    ncol = len(cols)
    fields: list[list[str]] = []
    # a decimal comma: unquoted between other delimiters, or quoted ("12,5") with any
    decimal_comma = any(_DECIMAL_COMMA.match(f.strip().strip('"')) for f in _split(rows[1][1], sep))
    for line_no, line in rows[1:]:
        parts = _split(line, sep)
        if len(parts) != ncol:
            raise ValueError(
                f"{path.name} line {line_no}: expected {ncol} fields like the header, got "
                f"{len(parts)}"
            )
        fields.append(parts)
    meta = base_meta(path, "table", scale="full")
    meta.update(_meta_lines(path.name, lines[: header_line - 1]))
    if skipped:
        warn_repair(
            meta,
            f"column(s) {list(skipped.values())} not used: no unit stated (map them with "
            "--columns, e.g. "
            + ",".join(f"{ch}={col}:{next(iter(UNITS[ch]))}" for ch, col in skipped.items())
            + ")",
        )
    used = {col for col, _, _ in mapping.values()} | set(skipped.values())
    unused = [c for c in cols if c not in used]
    if unused:
        meta["notes"].append(f"column(s) {unused} not read (no channel of a record)")
    if windows:
        meta["conversions"].append("not UTF-8: read as Windows-1252 (code page 1252)")
    if decimal_comma:
        meta["conversions"].append("decimal comma read as a decimal point")
    arrays: dict[str, Any] = {}
    units: dict[str, str] = {}
    for channel, (col, unit, negate) in mapping.items():
        j = seen[col]
        values = [
            (f[j].strip().strip('"').replace(",", ".") if decimal_comma else f[j].strip('" '))
            for f in fields
        ]
        where = f"{path.name}: column {col!r} ({channel})"
        if channel == "time":
            arrays["time"], start = parse_time(values, unit, where)
            if start is not None:
                meta["start_time"] = start
            units["time"] = "s" if unit == "datetime" else unit
        else:
            numbers = parse_numbers(values, where)
            arrays[channel] = -numbers if negate else numbers
            units[channel] = unit
        stated = _BRACKET.match(col) is not None  # "rudder [deg]" names its unit already
        text = f"{channel} = {'-' if negate else ''}{col}" + ("" if stated else f" [{unit}]")
        meta["conversions"].append(text)
    names = {ch: col for ch, (col, _, _) in mapping.items()}
    return record_from_arrays(
        arrays,
        units=units,
        meta=meta,
        max_gap_s=max_gap_s,
        names=names,
        line_numbers=[ln for ln, _ in rows[1:]],
    )


def sniff(head: str) -> bool:
    """A header and a data row (``#`` lines skipped) that split into the same two or more
    fields with ``,``, ``;``, tab or blanks."""
    lines = [ln for ln in head.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if len(lines) < 2:
        return False
    for sep in (",", ";", "\t", None):
        n = len(lines[0].split(sep))
        if n >= 2 and len(lines[1].split(sep)) == n:
            return True
    return False


FORMAT = SourceFormat("table", load_table, sniff, fallback=True, options=("columns", "max_gap_s"))
"""The table format of :func:`shipgym.sysid.io.load` (a fallback: after every other format)."""

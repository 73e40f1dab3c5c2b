"""A ship's own log as a :class:`~shipgym.sysid.data.Record`: any delimited table, any units.

Two ways in, one processing pipeline (:func:`record_from_arrays`, also
:meth:`Record.from_arrays <shipgym.sysid.data.Record.from_arrays>`):

* a delimited text table (:func:`load_table`, ``load(path, columns=...)``, ``shipgym identify
  FILE --columns ...``) whose columns are named by a column map or by headers that state their
  unit;
* arrays already in memory (:meth:`Record.from_arrays`).

Column map
----------
``time=t,delta=-rudder_deg:deg,psi=hdg:deg,r=rot:deg/min,U=sog:kn`` (or the same as a mapping
``{"delta": "-rudder_deg:deg", ...}``): each entry maps a channel of the record to a column of
the file, with its unit after the last ``:`` and a leading ``-`` to negate the column. Channels
and units (:data:`UNITS`):

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

Gaps and segments
-----------------
A row that misses a value of a mapped channel (an empty field, ``nan``) is a gap, and so is a
time step longer than ``max_gap_s`` (default :data:`GAP_FACTOR` times the median step). The
record is split there into segments rather than interpolated across: the rows of a gap are
dropped, ``meta["segments"]`` lists each segment's ``[t0, t1]`` and a
:class:`~shipgym.sysid.data.SysidDataWarning` reports them; :meth:`Record.segments` returns them
as records and :func:`~shipgym.sysid.engine.identify` fits one-record models to the longest.
A segment of fewer than :data:`MIN_SEGMENT_SAMPLES` samples is dropped and reported.

Processing (as the measured-source loaders do, per segment where it matters): units to SI and
radians, time from datetimes to seconds from the first sample (``meta["start_time"]``), the
unit checks of :mod:`shipgym.sysid.data` (a heading in degrees, a yaw rate in deg/s, knots ...),
heading unwrapped and repaired, yaw rate derived from the heading when absent (local quadratic,
:data:`R_WINDOW_S`), the neutral rudder measured (``meta["rudder_offset_rad"]``).
"""

from __future__ import annotations

import csv
import itertools
import math
import re
from collections.abc import Callable, Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.sysid.data import (
    _KNOT,
    Record,
    _base_meta,
    _check_units,
    _flag_irregular,
    _latlon_to_ne,
    _read_lines,
    _repair_heading,
    _repair_time,
    _rudder_offset,
    _silent,
    _warn,
    derive_yaw_rate,
)

__all__ = [
    "ALIASES",
    "CHANNELS",
    "GAP_FACTOR",
    "MIN_SEGMENT_SAMPLES",
    "R_WINDOW_S",
    "UNITS",
    "load_table",
    "parse_columns",
    "record_from_arrays",
]

_DEG = math.pi / 180.0

#: Unit of each kind -> factor to SI (``datetime`` for time is handled apart).
_KIND_UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0, "datetime": math.nan},
    "angle": {"rad": 1.0, "deg": _DEG},
    "rate": {"rad/s": 1.0, "deg/s": _DEG, "deg/min": _DEG / 60.0},
    "speed": {"m/s": 1.0, "kn": _KNOT, "km/h": 1.0 / 3.6},
    "length": {"m": 1.0, "km": 1000.0},
    "geo": {"deg": 1.0},
    "revs": {"rpm": 1.0, "rev/s": 60.0},
}

#: Channel -> kind of unit.
CHANNELS: dict[str, str] = {
    "time": "time",
    "delta": "angle",
    "psi": "angle",
    "r": "rate",
    "U": "speed",
    "u": "speed",
    "v": "speed",
    "x": "length",
    "y": "length",
    "lat": "geo",
    "lon": "geo",
    "rpm": "revs",
}

#: Channel -> accepted units and their factor to SI.
UNITS: dict[str, dict[str, float]] = {ch: _KIND_UNITS[kind] for ch, kind in CHANNELS.items()}

_REQUIRED_CHANNELS = ("time", "delta", "psi")

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

#: Unit spellings in headers -> the unit of :data:`UNITS`.
_UNIT_SPELLINGS: dict[str, str] = {
    "s": "s",
    "sec": "s",
    "secs": "s",
    "seconds": "s",
    "ms": "ms",
    "min": "min",
    "h": "h",
    "rad": "rad",
    "radians": "rad",
    "deg": "deg",
    "degree": "deg",
    "degrees": "deg",
    "°": "deg",
    "rad/s": "rad/s",
    "rad_s": "rad/s",
    "deg/s": "deg/s",
    "deg_s": "deg/s",
    "°/s": "deg/s",
    "dps": "deg/s",
    "deg/min": "deg/min",
    "deg_min": "deg/min",
    "deg_per_s": "deg/s",
    "deg_per_sec": "deg/s",
    "deg_per_min": "deg/min",
    "rad_per_s": "rad/s",
    "rad_per_sec": "rad/s",
    "m_per_s": "m/s",
    "rev_per_s": "rev/s",
    "°/min": "deg/min",
    "m/s": "m/s",
    "m_s": "m/s",
    "kn": "kn",
    "kt": "kn",
    "kts": "kn",
    "knots": "kn",
    "km/h": "km/h",
    "km_h": "km/h",
    "kmh": "km/h",
    "m": "m",
    "km": "km",
    "rpm": "rpm",
    "rev/s": "rev/s",
    "rev_s": "rev/s",
    "iso": "datetime",
    "datetime": "datetime",
    "utc": "datetime",
}

GAP_FACTOR: float = 5.0
"""A time step longer than this many median steps is a gap (default of ``max_gap_s``)."""

MIN_SEGMENT_SAMPLES: int = 10
"""A segment between gaps with fewer samples is dropped (and reported)."""

R_WINDOW_S: float = 2.0
"""Window [s] of the yaw rate derived from the heading when the log has none."""

_COMMENT = ("#", "%", "//")
_BRACKET = re.compile(r"^(?P<name>.*?)\s*[\[(](?P<unit>[^\])]*)[\])]\s*$")
_DECIMAL_COMMA = re.compile(r"^[-+]?\d+,\d+([eE][-+]?\d+)?$")


# ----------------------------------------------------------------------------------------------
# column maps
# ----------------------------------------------------------------------------------------------
def _norm(name: str) -> str:
    return re.sub(r"[\s\-]+", "_", name.strip().lower())


def _unit_of(channel: str, unit: str, where: str) -> str:
    spelled = _UNIT_SPELLINGS.get(unit.strip().lower(), unit.strip())
    if spelled not in UNITS[channel]:
        raise ValueError(
            f"{where}: unit {unit!r} of channel {channel!r}; expected one of "
            f"{', '.join(UNITS[channel])}"
        )
    return spelled


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
        if sep and (tail.strip().lower() in _UNIT_SPELLINGS or tail.strip() in UNITS[channel]):
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
        unit = _unit_of(channel, unit, f"column map entry {channel}={spec}")
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
        spelled = _UNIT_SPELLINGS.get(unit.strip().lower(), unit.strip())
        return ("U", spelled) if spelled in UNITS["U"] else (None, None)
    names = [(_norm(m.group("name")), m.group("unit"))] if m else []
    norm = _norm(header)
    names.append((norm, None))
    # a unit suffix: the longest spelling that ends the name after an underscore
    for spelling in sorted(_UNIT_SPELLINGS, key=len, reverse=True):
        if norm.endswith("_" + spelling) and len(norm) > len(spelling) + 1:
            names.append((norm[: -len(spelling) - 1], spelling))
    for name, unit in names:
        for channel, aliases in ALIASES.items():
            if name in aliases:
                if unit is not None:
                    spelled = _UNIT_SPELLINGS.get(unit.strip().lower(), unit.strip())
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
    missing = [ch for ch in _REQUIRED_CHANNELS if ch not in found]
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


def _parse_time(values: Sequence[str], unit: str, where: str) -> tuple[np.ndarray, str | None]:
    """Seconds from the first sample (and its ISO time for datetimes)."""
    if unit != "datetime":
        return _numbers(values, where), None
    out = np.empty(len(values))
    first: datetime | None = None
    for k, text in enumerate(values):
        s = text.strip()
        if not s:
            out[k] = math.nan
            continue
        try:
            stamp = datetime.fromisoformat(s)
        except ValueError:
            raise ValueError(
                f"{where} row {k + 1}: {s!r} is not an ISO-8601 date and time (expected "
                "e.g. 2026-12-31T23:59:58.1Z)"
            ) from None
        if stamp.tzinfo is None:
            stamp = stamp.replace(tzinfo=UTC)
        if first is None:
            first = stamp
        out[k] = (stamp - first).total_seconds()
    return out, None if first is None else first.isoformat()


def _numbers(values: Sequence[str], where: str) -> np.ndarray:
    """Floats of text fields; empty fields and ``nan`` are NaN; text is refused."""
    try:
        return np.array([float(v) if v.strip() else math.nan for v in values], dtype=np.float64)
    except ValueError:
        for k, v in enumerate(values):
            try:
                float(v) if v.strip() else None
            except ValueError:
                bad = [x for x in values if x.strip() and not _is_number(x)]
                raise ValueError(
                    f"{where} row {k + 1}: {v.strip()!r} is not a number ({len(bad)} text "
                    "fields in the column); expected numbers (is it the right column?)"
                ) from None
    raise AssertionError("unreachable")  # pragma: no cover


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def load_table(
    path: Path,
    say: Callable[[str], None] = _silent,
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
        lines = _read_lines(path)
        windows = False
    except ValueError as exc:  # a Windows export (a degree sign in a header): code page 1252
        if not isinstance(exc.__cause__, UnicodeDecodeError):
            raise
        lines = _read_lines(path, "cp1252")
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
    missing = [ch for ch in _REQUIRED_CHANNELS if ch not in mapping]
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
    meta = _base_meta(path, "table", scale="full")
    if skipped:
        _warn(
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
            arrays["time"], start = _parse_time(values, unit, where)
            if start is not None:
                meta["start_time"] = start
            units["time"] = "s" if unit == "datetime" else unit
        else:
            arrays[channel] = -_numbers(values, where) if negate else _numbers(values, where)
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


# ----------------------------------------------------------------------------------------------
# the pipeline
# ----------------------------------------------------------------------------------------------
def record_from_arrays(
    arrays: Mapping[str, Any],
    *,
    units: Mapping[str, str] | None = None,
    meta: Mapping[str, Any] | None = None,
    max_gap_s: float | None = None,
    names: Mapping[str, str] | None = None,
    line_numbers: Sequence[int] | None = None,
) -> Record:
    """A :class:`Record` from channel arrays in any units (:meth:`Record.from_arrays`).

    Parameters
    ----------
    arrays : mapping
        Channel -> 1-D array (channels of :data:`CHANNELS`; ``time`` may be datetime64 or ISO
        strings when its unit is ``"datetime"``). Required: ``time``, ``delta``, ``psi``.
    units : mapping, optional
        Channel -> unit of :data:`UNITS`; a channel not named is in SI units (seconds, radians,
        rad/s, m/s, metres; lat/lon in degrees).
    meta : mapping, optional
        Merged into the record's meta (``source``, ``file``, ``conversions``, ``repairs`` ...).
    max_gap_s : float, optional
        Longest time step [s] inside a segment (default :data:`GAP_FACTOR` median steps).
    names : mapping, optional
        Channel -> the source's column name, for the messages.
    line_numbers : sequence of int, optional
        The text line of each sample (for the messages of text files).
    """
    units = dict(units or {})
    out_meta: dict[str, Any] = {"source": "arrays", "conversions": [], "repairs": [], "notes": []}
    out_meta.update({k: (list(v) if isinstance(v, list) else v) for k, v in (meta or {}).items()})
    for key in ("conversions", "repairs", "notes"):
        out_meta[key] = list(out_meta.get(key) or [])
    where = out_meta.get("file") or "record"
    unknown = sorted(set(arrays) - set(CHANNELS))
    if unknown:
        raise ValueError(f"{where}: unknown channel(s) {unknown}; expected any of {list(CHANNELS)}")
    missing = [ch for ch in _REQUIRED_CHANNELS if arrays.get(ch) is None]
    if missing:
        raise ValueError(f"{where}: channel(s) {missing} missing; required: time, delta, psi")
    for ch, unit in units.items():
        if ch not in CHANNELS:
            raise ValueError(f"{where}: unit given for unknown channel {ch!r}")
        _unit_of(ch, unit, f"{where}: units")
    data: dict[str, np.ndarray] = {}
    n: int | None = None
    for ch, value in arrays.items():
        if value is None:
            continue
        if ch == "time" and units.get("time") == "datetime":
            arr = np.asarray(value)
            if np.issubdtype(arr.dtype, np.datetime64):
                first = arr[0]
                sec = (arr - first) / np.timedelta64(1, "ns") * 1e-9
                out_meta.setdefault("start_time", str(first))
                arr = sec.astype(np.float64)
            else:
                arr, start = _parse_time([str(v) for v in arr], "datetime", f"{where}: time")
                if start is not None:
                    out_meta.setdefault("start_time", start)
            units["time"] = "s"
        else:
            try:
                arr = np.asarray(value, dtype=np.float64)
            except (TypeError, ValueError):
                raise ValueError(
                    f"{where}: channel {ch!r} is not numeric (expected numbers in "
                    f"{units.get(ch, next(iter(UNITS[ch])))})"
                ) from None
        if arr.ndim != 1:
            raise ValueError(f"{where}: channel {ch!r} must be 1-D, got shape {arr.shape}")
        if n is None:
            n = arr.size
        elif arr.size != n:
            raise ValueError(f"{where}: channel {ch!r} has {arr.size} samples, time has {n}")
        factor = UNITS[ch][units.get(ch, next(iter(UNITS[ch])))]
        data[ch] = arr * factor if factor != 1.0 else arr.copy()
    if (data.get("lat") is None) != (data.get("lon") is None):
        raise ValueError(f"{where}: lat and lon go together; got only one of them")
    if data.get("lat") is not None and (data.get("x") is not None or data.get("y") is not None):
        raise ValueError(f"{where}: give positions as x, y or as lat, lon, not both")
    if n is None or n < 2:
        raise ValueError(f"{where}: {n or 0} samples; expected at least two")
    for ch, unit in units.items():
        if names is None and ch in data and unit not in (next(iter(UNITS[ch])), "datetime"):
            out_meta["conversions"].append(f"{ch} {unit} -> SI")
    # gaps: missing values and long time steps split the record into segments
    t_all = data["time"]
    if np.any(np.isfinite(t_all[1:]) & np.isfinite(t_all[:-1]) & (np.diff(t_all) < 0)):
        i = int(np.flatnonzero(np.diff(t_all) < 0)[0])
        col = (names or {}).get("time", "time")
        row = f" (line {line_numbers[i + 1]})" if line_numbers else f" (sample {i + 1})"
        raise ValueError(
            f"{where}: time goes backwards at {t_all[i]:g} -> {t_all[i + 1]:g} s in column "
            f"{col!r}{row}; expected increasing time"
        )
    ok = np.ones(n, dtype=bool)
    for arr in data.values():
        ok &= np.isfinite(arr)
    n_missing = int(n - ok.sum())
    for ch, arr in data.items():
        if not np.isfinite(arr).any():
            col = (names or {}).get(ch, ch)
            raise ValueError(f"{where}: column {col!r} ({ch}) has no value in any row")
    if ok.sum() < 2:
        raise ValueError(f"{where}: {int(ok.sum())} complete samples; expected at least two")
    # exact duplicates and quantised stamps are the data module's business (good rows only)
    # the rows of a missing value are removed; where they were, the segments split (the mark
    # travels with its row through the time repairs, which may drop duplicate rows)
    keep = np.flatnonzero(ok)
    after_hole = np.zeros(keep.size)
    after_hole[1:] = np.diff(keep) > 1
    table = np.column_stack([*(data[ch][keep] for ch in data), after_hole])
    t_good, table = _repair_time(data["time"][keep], table, out_meta)
    gaps_at = table[:, -1] > 0.0
    data = {ch: table[:, j] for j, ch in enumerate(data)}
    data["time"] = t_good
    if n_missing:
        _warn(out_meta, f"{n_missing} rows miss a value of a mapped channel: treated as gaps")
    segs = _segments_with_breaks(t_good, gaps_at, max_gap_s)
    short = [(a, b) for a, b in segs if b - a < MIN_SEGMENT_SAMPLES]
    segs = [(a, b) for a, b in segs if b - a >= MIN_SEGMENT_SAMPLES]
    if not segs:
        raise ValueError(
            f"{where}: no stretch of at least {MIN_SEGMENT_SAMPLES} samples without a gap "
            f"(longest {max((b - a for a, b in short), default=0)})"
        )
    if short:
        _warn(
            out_meta,
            f"dropped {len(short)} segments shorter than {MIN_SEGMENT_SAMPLES} samples "
            f"({sum(b - a for a, b in short)} samples)",
        )
    # lat/lon to north/east from the first kept fix
    if "lat" in data:
        first = segs[0][0]
        lat, lon = data.pop("lat"), data.pop("lon")
        north, east = _latlon_to_ne(lat[first:], lon[first:])
        data["x"] = np.concatenate((np.zeros(first), north))
        data["y"] = np.concatenate((np.zeros(first), east))
        out_meta["conversions"].append("x, y north/east from lat/lon (WGS84 local tangent plane)")
        out_meta.setdefault(
            "frame", "north/east [m] from the first fix (WGS84 local tangent plane)"
        )
    idx = np.concatenate([np.arange(a, b) for a, b in segs])
    t = data["time"][idx]
    col_names = {"time": "time", "psi": "psi", "r": "r", "delta": "delta", "U": "U"}
    col_names.update({k: v for k, v in (names or {}).items() if k in col_names})
    r_in = data.get("r")
    for a, b in segs:  # each stretch on its own: nothing is compared across a gap

        def part(ch: str, a: int = a, b: int = b) -> np.ndarray | None:
            return None if data.get(ch) is None else data[ch][a:b]

        _check_units(
            data["time"][a:b],
            data["psi"][a:b],
            part("r"),
            data["delta"][a:b],
            out_meta,
            names=col_names,
            U=part("U"),
            x=part("x"),
            y=part("y"),
            declared=units,
        )
    psi_parts, r_parts = [], []
    prev_end: float | None = None
    for a, b in segs:
        ts = data["time"][a:b]
        psi = _repair_heading(ts, data["psi"][a:b], None if r_in is None else r_in[a:b], out_meta)
        if prev_end is not None:  # the same turn count as the previous segment's end
            psi = psi - 2.0 * math.pi * round((psi[0] - prev_end) / (2.0 * math.pi))
        prev_end = float(psi[-1])
        psi_parts.append(psi)
        r_parts.append(r_in[a:b] if r_in is not None else derive_yaw_rate(ts, psi, R_WINDOW_S))
    if r_in is None:
        out_meta["r_source"] = (
            f"derived from psi (local quadratic / Savitzky-Golay, {R_WINDOW_S} s window): no "
            "yaw-rate column"
        )
    else:
        out_meta.setdefault("r_source", "measured")
    chans = {ch: arr[idx] for ch, arr in data.items() if ch not in ("psi", "r", "time")}
    chans["psi"] = np.concatenate(psi_parts)
    chans["r"] = np.concatenate(r_parts)
    for a, b in segs[:1]:
        _rudder_offset(data["time"][a:b], data["delta"][a:b], out_meta)
    inner = np.concatenate([np.diff(data["time"][a:b]) for a, b in segs])
    if inner.size and float(np.max(inner) - np.min(inner)) > 0.01 * float(np.median(inner)):
        _flag_irregular(np.concatenate(([0.0], np.cumsum(inner))), out_meta)
    if len(segs) > 1:
        spans = [[float(data["time"][a]), float(data["time"][b - 1])] for a, b in segs]
        out_meta["segments"] = spans
        longest = max(range(len(segs)), key=lambda k: spans[k][1] - spans[k][0])
        _warn(
            out_meta,
            f"split into {len(segs)} segments at gaps (not interpolated across): "
            + ", ".join(f"{s0:g}-{s1:g} s" for s0, s1 in spans)
            + f"; the longest is {spans[longest][0]:g}-{spans[longest][1]:g} s",
        )
    return Record(time=t, **chans, meta=out_meta)


def _segments_with_breaks(
    t: np.ndarray, breaks: np.ndarray, max_gap_s: float | None
) -> list[tuple[int, int]]:
    """Index ranges ``[a, b)`` split before every ``breaks`` row and at long time steps."""
    steps = np.diff(t)
    if max_gap_s is None:
        inner = steps[~breaks[1:]]
        max_gap_s = GAP_FACTOR * float(np.median(inner if inner.size else steps))
    elif not (math.isfinite(max_gap_s) and max_gap_s > 0):
        raise ValueError(f"max_gap_s must be a finite time > 0 s, got {max_gap_s!r}")
    cut = np.flatnonzero(breaks[1:] | (steps > max_gap_s)) + 1
    bounds = np.concatenate(([0], cut, [t.size]))
    return [(int(a), int(b)) for a, b in itertools.pairwise(bounds)]

"""The canonical record of a manoeuvre: :class:`Record`, its CSV file and the array pipeline.

The system-identification tools fit Nomoto-type models (seed 000: the first-order
model ``T r' + r = K delta`` and its second-order relative) and 3-DOF models to measured time
series. Every loader of :mod:`shipgym.sysid.io` turns its source into one :class:`Record` in
the project's units and sign convention:

* time ``time`` [s], strictly increasing (float64);
* rudder ``delta`` [rad], **positive gives a starboard turn** (r > 0), so a Nomoto fit gives
  K > 0 (see docs/ARCHITECTURE.md "Nomoto sign");
* heading ``psi`` [rad], clockwise from north (or from the source's earth x axis), continuous
  (unwrapped);
* yaw rate ``r`` [rad/s], positive clockwise;
* optional (``None`` when absent): position ``x``, ``y`` [m] (north/east or the source's
  earth-fixed x/y frame), **body-fixed** ``u``, ``v`` [m/s], speed ``U`` [m/s], pod azimuth
  ``azimuth`` [rad] (raw pod sign: positive turns to PORT, seed 001 eq. 19-20), ``rpm``
  [rev/min], total propeller ``thrust`` [N], and the apparent (relative) wind at the ship:
  ``wind_speed`` [m/s] and ``wind_angle`` [rad], the direction the wind comes FROM measured from
  the bow, positive clockwise (to starboard), wrapped to (-pi, pi]: 0 = head wind, +pi/2 = wind
  from starboard (pushes the ship to port).

Arrays of a ship's own log in any units (:func:`record_from_arrays`, also
:meth:`Record.from_arrays`) go through one pipeline, which the table and NMEA loaders use too:
units to SI and radians (:data:`shipgym.sysid.units.UNITS`), time from datetimes to seconds
from the first sample (``meta["start_time"]``), gaps (a missing value, or a time step longer
than ``max_gap_s``, default :data:`GAP_FACTOR` median steps) split into segments rather than
interpolated across (``meta["segments"]``, :meth:`Record.segments`; a segment of fewer than
:data:`MIN_SEGMENT_SAMPLES` samples is dropped and reported), the unit checks and repairs of
:mod:`shipgym.sysid.ingest` per segment, the yaw rate derived from the heading when absent
(local quadratic, :data:`R_WINDOW_S`), the neutral rudder measured
(``meta["rudder_offset_rad"]``).

Canonical CSV (:meth:`Record.to_csv`, :meth:`Record.from_csv`, :func:`read_canonical`,
``load(..., "canonical")``)::

    # shipgym canonical record v1
    # source: "marin"
    # repairs: ["time stamps quantised ..."]
    time_s,delta_rad,psi_rad,r_rad_s,x_m,y_m,u_m_s,v_m_s,U_m_s,rpm
    0,0.0142...,...

Meta lines are ``# key: <JSON value>``, each key once, validated on reading (a ``ValueError``
names the file, the line and what was expected): ``conversions``, ``repairs``, ``notes`` are lists
of strings; ``source``, ``file``, ``vessel``, ``scale``, ``frame``, ``title``, ``licence``,
``r_source``, ``maneuver`` strings; ``L`` a positive number or null; ``irregular_sampling`` a
boolean; ``slice_s`` two numbers; ``rudder_offset_rad``, ``first_rudder_order_s``,
``manoeuvre_start_s``, ``manoeuvre_end_s``, ``resampled_dt``, ``model_scale_factor`` numbers;
``particulars`` an object; other keys any JSON. Only present channels are written (columns
``time_s, delta_rad, psi_rad, r_rad_s`` required; ``x_m, y_m, u_m_s, v_m_s, U_m_s, azimuth_rad,
rpm, thrust_N, wind_speed_m_s, wind_angle_rad`` optional); numbers have 17 significant digits so
the round trip is exact. A canonical file is trusted to be processed: on reading only the time
(duplicates, quantisation), empty rows, irregular sampling (unless already flagged), a wrapped
psi and a wind angle outside (-pi, pi] (re-wrapped) are checked.
"""

from __future__ import annotations

import itertools
import json
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.sysid.ingest import (
    ProgressArg,
    check_units,
    derive_yaw_rate,
    flag_irregular,
    latlon_to_ne,
    load_with_progress,
    measure_rudder_offset,
    parse_table,
    read_lines,
    repair_heading,
    repair_time,
    report_empty_rows,
    require_columns,
    require_complete_rows,
    silent,
    split_header,
    ssa,
    warn_repair,
    wrap_angle,
)
from shipgym.sysid.units import CHANNELS, REQUIRED_INPUTS, UNITS, parse_time, unit_of

__all__ = [
    "CANONICAL_COLUMNS",
    "CANONICAL_MAGIC",
    "CANONICAL_REQUIRED",
    "GAP_FACTOR",
    "MIN_SEGMENT_SAMPLES",
    "R_WINDOW_S",
    "Record",
    "meta_expected",
    "read_canonical",
    "record_from_arrays",
]


#: Canonical CSV column name -> :class:`Record` attribute.
CANONICAL_COLUMNS: dict[str, str] = {
    "time_s": "time",
    "delta_rad": "delta",
    "psi_rad": "psi",
    "r_rad_s": "r",
    "x_m": "x",
    "y_m": "y",
    "u_m_s": "u",
    "v_m_s": "v",
    "U_m_s": "U",
    "azimuth_rad": "azimuth",
    "rpm": "rpm",
    "thrust_N": "thrust",
    "wind_speed_m_s": "wind_speed",
    "wind_angle_rad": "wind_angle",
}
_REQUIRED = ("time", "delta", "psi", "r")
CANONICAL_REQUIRED: tuple[str, ...] = ("time_s", "delta_rad", "psi_rad", "r_rad_s")
"""The columns every canonical CSV has (those of the required channels)."""
_OPTIONAL = ("x", "y", "u", "v", "U", "azimuth", "rpm", "thrust", "wind_speed", "wind_angle")
_ANGLE_CHANNELS = ("wind_angle",)  # wrapped to (-pi, pi]; psi is continuous instead
CANONICAL_MAGIC = "# shipgym canonical record v1"
"""First line of a canonical CSV."""

# canonical meta keys with a fixed type (what the loaders write and the package reads); any other
# key may hold any JSON value. A validator returns None when the value is fine, else what was
# expected.
_META_STR_KEYS = (
    "source",
    "file",
    "vessel",
    "scale",
    "frame",
    "title",
    "licence",
    "r_source",
    "maneuver",
    "start_time",
)
_META_LIST_KEYS = ("conversions", "repairs", "notes")
_META_NUMBER_KEYS = (
    "rudder_offset_rad",
    "first_rudder_order_s",
    "manoeuvre_start_s",
    "manoeuvre_end_s",
    "resampled_dt",
    "model_scale_factor",
)

_WRITE_ROWS = 250_000  # rows per write call of Record.to_csv

GAP_FACTOR: float = 5.0
"""A time step longer than this many median steps is a gap (default of ``max_gap_s``)."""

MIN_SEGMENT_SAMPLES: int = 10
"""A segment between gaps with fewer samples is dropped (and reported)."""

R_WINDOW_S: float = 2.0
"""Window [s] of the yaw rate derived from the heading when the log has none."""


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def meta_expected(key: str, value: Any) -> str | None:
    """What ``meta[key]`` must be when ``value`` does not fit the schema, else None."""
    if key in _META_LIST_KEYS:
        if not (isinstance(value, list) and all(isinstance(v, str) for v in value)):
            return 'a JSON list of strings, e.g. ["dropped 3 all-empty rows"]'
    elif key in _META_STR_KEYS:
        if not isinstance(value, str):
            return 'a JSON string in double quotes, e.g. "text"'
    elif key in _META_NUMBER_KEYS:
        if not _is_number(value):
            return "a finite JSON number"
    elif key == "L":
        if not (value is None or (_is_number(value) and value > 0)):
            return "the ship length in m: a positive JSON number or null"
    elif key == "irregular_sampling":
        if not isinstance(value, bool):
            return "true or false"
    elif key == "slice_s":
        if not (isinstance(value, list) and len(value) == 2 and all(map(_is_number, value))):
            return "a JSON list of two numbers [t0, t1]"
    elif key == "particulars":
        if not isinstance(value, dict):
            return "a JSON object"
    elif key == "segments":
        if not (
            isinstance(value, list)
            and value
            and all(
                isinstance(v, list) and len(v) == 2 and all(map(_is_number, v)) and v[0] < v[1]
                for v in value
            )
        ):
            return "a JSON list of [t0, t1] spans with t0 < t1, e.g. [[0, 120.5], [180, 600]]"
    return None


def _describe_json(value: Any) -> str:
    kind = {bool: "boolean", int: "number", float: "number", str: "string", list: "list"}.get(
        type(value), "object" if isinstance(value, dict) else "null"
    )
    text = json.dumps(value)
    return f"{kind} {text[:60] + '...' if len(text) > 60 else text}"


def _jsonable(meta: dict[str, Any]) -> dict[str, Any]:
    """Normalise ``meta`` to its JSON form (tuples -> lists, numpy scalars -> Python)."""

    def default(o: Any) -> Any:
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
        if isinstance(o, Path):
            return str(o)
        raise TypeError(type(o).__name__)

    try:
        return json.loads(json.dumps(meta, default=default))
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"Record.meta must be JSON-serialisable (str, numbers, lists, dicts): {exc}"
        ) from exc


@dataclass(eq=False)
class Record:
    """One measured manoeuvre in the canonical schema (SI units, radians, starboard-positive).

    Attributes
    ----------
    time : numpy.ndarray
        Time [s], strictly increasing, float64.
    delta : numpy.ndarray
        Rudder angle [rad]; positive gives a starboard turn (r > 0). For the Gunnerus it is
        ``-azimuth``.
    psi : numpy.ndarray
        Heading [rad], clockwise, continuous (unwrapped).
    r : numpy.ndarray
        Yaw rate [rad/s], positive clockwise. ``meta["r_source"]`` says whether it was measured.
    x, y : numpy.ndarray or None
        Earth-fixed position [m]: north/east, or the source's earth x/y axes (y to starboard of
        x); ``meta["frame"]`` describes it.
    u, v : numpy.ndarray or None
        Body-fixed surge and sway velocity [m/s] (ground-referenced).
    U : numpy.ndarray or None
        Speed [m/s].
    azimuth : numpy.ndarray or None
        Pod azimuth [rad] with the pods' own sign (positive turns the ship to PORT).
    rpm : numpy.ndarray or None
        Propeller speed [rev/min] (for the Gunnerus: the rpm order).
    thrust : numpy.ndarray or None
        Measured total propeller thrust [N].
    wind_speed : numpy.ndarray or None
        Apparent (relative) wind speed at the ship [m/s], >= 0.
    wind_angle : numpy.ndarray or None
        Apparent (relative) wind angle of attack [rad]: the direction the wind comes FROM,
        measured from the bow, positive clockwise (to starboard), wrapped to (-pi, pi]. So
        0 = head wind, +pi/2 = wind from starboard (it pushes the ship to port), pi = wind from
        astern. The apparent wind is the true wind minus the ship's velocity over ground.
    meta : dict
        JSON-serialisable description: ``source``, ``file``, ``vessel``, ``L`` [m] or None,
        ``scale`` ("model"/"full"), ``conversions`` (list of str), ``repairs`` (list of str),
        ``notes`` (list of str) and source-specific keys.
    """

    time: np.ndarray
    delta: np.ndarray
    psi: np.ndarray
    r: np.ndarray
    x: np.ndarray | None = None
    y: np.ndarray | None = None
    u: np.ndarray | None = None
    v: np.ndarray | None = None
    U: np.ndarray | None = None
    azimuth: np.ndarray | None = None
    rpm: np.ndarray | None = None
    thrust: np.ndarray | None = None
    wind_speed: np.ndarray | None = None
    wind_angle: np.ndarray | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        n: int | None = None
        for name in _REQUIRED + _OPTIONAL:
            value = getattr(self, name)
            if value is None:
                if name in _REQUIRED:
                    raise ValueError(f"Record.{name} is required, got None")
                continue
            arr = np.array(value, dtype=np.float64)
            if arr.ndim != 1:
                raise ValueError(f"Record.{name} must be 1-D, got shape {arr.shape}")
            if n is None:
                n = arr.size
            elif arr.size != n:
                raise ValueError(
                    f"Record.{name} has {arr.size} samples, expected {n} (length of time)"
                )
            if not np.all(np.isfinite(arr)):
                bad = int(np.flatnonzero(~np.isfinite(arr))[0])
                raise ValueError(f"Record.{name} has a non-finite value at sample {bad}")
            if name in _ANGLE_CHANNELS and np.any((arr <= -np.pi) | (arr > np.pi)):
                bad = int(np.flatnonzero((arr <= -np.pi) | (arr > np.pi))[0])
                raise ValueError(
                    f"Record.{name} must be wrapped to (-pi, pi] rad, got {arr[bad]!r} at sample"
                    f" {bad}"
                )
            if name == "wind_speed" and np.any(arr < 0.0):
                bad = int(np.flatnonzero(arr < 0.0)[0])
                raise ValueError(
                    f"Record.wind_speed must be >= 0 m/s, got {arr[bad]!r} at sample {bad}"
                )
            setattr(self, name, arr)
        if n is None or n < 2:
            raise ValueError(f"a Record needs at least 2 samples, got {n}")
        dt = np.diff(self.time)
        if np.any(dt <= 0.0):
            i = int(np.flatnonzero(dt <= 0.0)[0])
            raise ValueError(
                f"Record.time must be strictly increasing; time[{i}]={self.time[i]!r} is followed"
                f" by time[{i + 1}]={self.time[i + 1]!r}"
            )
        self.meta = _jsonable(dict(self.meta))

    # -- basic properties ----------------------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.time.size)

    def __len__(self) -> int:
        return self.n

    @property
    def dt(self) -> float:
        """Median sample interval [s]."""
        return float(np.median(np.diff(self.time)))

    @property
    def duration(self) -> float:
        """``time[-1] - time[0]`` [s]."""
        return float(self.time[-1] - self.time[0])

    def channels(self) -> dict[str, np.ndarray]:
        """The present channels, in canonical order, as ``{attribute: array}``."""
        out: dict[str, np.ndarray] = {}
        for name in _REQUIRED + _OPTIONAL:
            value = getattr(self, name)
            if value is not None:
                out[name] = value
        return out

    def _replace(self, channels: dict[str, np.ndarray], meta: dict[str, Any]) -> Record:
        return Record(**channels, meta=meta)

    @classmethod
    def from_arrays(
        cls,
        *,
        time: Any,
        delta: Any,
        psi: Any,
        r: Any = None,
        U: Any = None,
        x: Any = None,
        y: Any = None,
        lat: Any = None,
        lon: Any = None,
        u: Any = None,
        v: Any = None,
        rpm: Any = None,
        units: Mapping[str, str] | None = None,
        meta: Mapping[str, Any] | None = None,
        max_gap_s: float | None = None,
    ) -> Record:
        """A record from arrays of a ship's own log, in any of the units of a column map.

        The arrays go through the processing of a loaded table (:func:`record_from_arrays`):
        units to SI and radians, gaps split into segments, unit checks, heading unwrapped and
        repaired, yaw rate derived from the heading when ``r`` is None, neutral rudder
        measured.

        Parameters
        ----------
        time : array_like
            Time in ``units["time"]`` (``"s"`` by default; ``"ms"``, ``"min"``, ``"h"``, or
            ``"datetime"`` for numpy datetime64 values or ISO-8601 strings).
        delta, psi : array_like
            Rudder (positive turns to starboard) and heading (clockwise from north); radians
            unless ``units`` says ``"deg"``.
        r, U, x, y, lat, lon, u, v, rpm : array_like, optional
            Yaw rate (clockwise), speed, north/east position, latitude/longitude [deg] (instead
            of x, y), body surge/sway, propeller speed.
        units : mapping, optional
            Channel -> unit of :data:`shipgym.sysid.units.UNITS` (``{"psi": "deg", "r":
            "deg/min", "U": "kn"}``); channels not named are SI.
        meta : mapping, optional
            Merged into the record's meta (``source``, ``vessel``, ``L`` ...).
        max_gap_s : float, optional
            Longest time step [s] inside a segment (default: 5 median steps); a sample with a
            NaN is a gap as well.
        """
        given = {"time": time, "delta": delta, "psi": psi, "r": r, "U": U, "x": x, "y": y}
        given.update(lat=lat, lon=lon, u=u, v=v, rpm=rpm)
        arrays = {k: val for k, val in given.items() if val is not None}
        return record_from_arrays(arrays, units=units, meta=meta, max_gap_s=max_gap_s)

    def segments(self) -> list[Record]:
        """The record's stretches between gaps (``meta["segments"]``), or ``[self]``."""
        spans = self.meta.get("segments")
        if not spans:
            return [self]
        out = []
        for t0, t1 in spans:
            mask = (self.time >= t0) & (self.time <= t1)
            meta = {k: val for k, val in self.meta.items() if k != "segments"}
            meta["slice_s"] = [float(t0), float(t1)]
            out.append(self._replace({k: a[mask] for k, a in self.channels().items()}, meta))
        return out

    # -- selection and resampling --------------------------------------------------------------
    def slice(self, t0: float, t1: float) -> Record:
        """Samples with ``t0 <= time <= t1`` as a new Record (``meta["slice_s"] = [t0, t1]``).

        Raises
        ------
        ValueError
            If ``t1 <= t0`` or fewer than 2 samples fall in the interval.
        """
        if not (np.isfinite(t0) and np.isfinite(t1) and t1 > t0):
            raise ValueError(f"slice needs finite t0 < t1, got t0={t0!r}, t1={t1!r}")
        mask = (self.time >= t0) & (self.time <= t1)
        if int(mask.sum()) < 2:
            raise ValueError(
                f"slice [{t0}, {t1}] s holds {int(mask.sum())} samples; the record spans "
                f"[{self.time[0]}, {self.time[-1]}] s"
            )
        meta = dict(self.meta)
        meta["slice_s"] = [float(t0), float(t1)]
        if meta.get("segments"):
            kept = [[max(a, t0), min(b, t1)] for a, b in meta["segments"] if b > t0 and a < t1]
            if len(kept) > 1:
                meta["segments"] = kept
            else:
                del meta["segments"]
        return self._replace({k: v[mask] for k, v in self.channels().items()}, meta)

    def resample(self, dt: float) -> Record:
        """Linear interpolation of every channel onto the uniform grid ``time[0] + k dt``.

        The grid runs from ``time[0]`` up to ``time[-1]`` (inclusive when it falls on the grid).
        Linear interpolation is exact for piecewise-linear signals and does not overshoot; it
        does low-pass filter when downsampling only as much as the dropped samples are ignored
        (no anti-alias filter is applied: filter first if ``dt`` is much larger than
        :attr:`dt`). ``psi`` is continuous, so interpolating it is safe; ``wind_angle`` is
        wrapped, so it is unwrapped, interpolated and wrapped again to (-pi, pi]. The result
        records ``meta["resampled_dt"]``.

        Parameters
        ----------
        dt : float
            New sample interval [s], > 0 and smaller than the duration.
        """
        if not (np.isfinite(dt) and dt > 0.0):
            raise ValueError(f"resample dt must be a positive finite time step in s, got {dt!r}")
        if self.meta.get("segments"):  # each segment on its own grid, never across a gap
            parts = [seg.resample(dt) for seg in self.segments()]
            meta = dict(self.meta)
            meta["segments"] = [[float(p.time[0]), float(p.time[-1])] for p in parts]
            meta["resampled_dt"] = float(dt)
            meta.pop("irregular_sampling", None)
            chans = {k: np.concatenate([getattr(p, k) for p in parts]) for k in self.channels()}
            return self._replace(chans, meta)
        if dt >= self.duration:
            raise ValueError(
                f"resample dt={dt} s must be smaller than the record duration {self.duration} s"
            )
        k = math.floor(self.duration / dt + 1e-9)
        t_new = self.time[0] + dt * np.arange(k + 1)
        chans: dict[str, np.ndarray] = {}
        for name, value in self.channels().items():
            if name == "time":
                chans[name] = t_new
            elif name in _ANGLE_CHANNELS:
                chans[name] = wrap_angle(np.interp(t_new, self.time, np.unwrap(value)))
            else:
                chans[name] = np.interp(t_new, self.time, value)
        meta = dict(self.meta)
        meta["resampled_dt"] = float(dt)
        meta.pop("irregular_sampling", None)
        return self._replace(chans, meta)

    # -- canonical CSV -------------------------------------------------------------------------
    def to_csv(self, path: str | Path) -> Path:
        """Write the canonical CSV: ``# key: <json>`` meta lines, a header with units, data.

        Numbers are written with 17 significant digits, so :meth:`from_csv` gives back exactly
        the same arrays and meta.
        """
        path = Path(path)
        chans = self.channels()
        inverse = {attr: col for col, attr in CANONICAL_COLUMNS.items()}
        lines = [CANONICAL_MAGIC]
        for key, value in self.meta.items():
            if not re.fullmatch(r"[A-Za-z0-9_.\-]+", str(key)):
                raise ValueError(f"meta key {key!r} must match [A-Za-z0-9_.-]+ for canonical CSV")
            lines.append(f"# {key}: {json.dumps(value)}")
        lines.append(",".join(inverse[name] for name in chans))
        data = np.column_stack(list(chans.values()))
        row_format = ",".join(["%.17g"] * data.shape[1])  # as format(v, ".17g"), per row
        with path.open("w", encoding="utf-8", newline="\n") as fh:
            fh.write("\n".join(lines) + "\n")
            for a in range(0, data.shape[0], _WRITE_ROWS):
                block = data[a : a + _WRITE_ROWS].tolist()
                fh.write("\n".join([row_format % tuple(row) for row in block]) + "\n")
        return path

    @classmethod
    def from_csv(cls, path: str | Path, *, progress: ProgressArg = None) -> Record:
        """Read a canonical CSV written by :meth:`to_csv` (``load(path, "canonical")``)."""
        path = Path(path)
        if not path.is_file():
            raise ValueError(f"{path} is not a file")
        return load_with_progress(read_canonical, path, "canonical", progress)


# ----------------------------------------------------------------------------------------------
# the canonical CSV
# ----------------------------------------------------------------------------------------------
def read_canonical(path: Path, say: Callable[[str], None] = silent) -> Record:
    """Read a canonical CSV (module docstring; :meth:`Record.from_csv` with progress lines)."""
    lines = read_lines(path)
    meta: dict[str, Any] = {}
    k = 0
    meta_line: dict[str, int] = {}
    while k < len(lines) and lines[k].startswith("#"):
        body = lines[k][1:].strip()
        if lines[k] != CANONICAL_MAGIC and ":" in body:
            key, _, value = body.partition(":")
            key = key.strip()
            try:
                parsed = json.loads(value)
            except json.JSONDecodeError as exc:
                raise ValueError(
                    f"{path.name} line {k + 1}: meta value of {key!r} is not JSON ({exc})"
                ) from exc
            if key in meta_line:
                raise ValueError(
                    f"{path.name} line {k + 1}: meta key {key!r} repeats line "
                    f"{meta_line[key]}; expected each meta key once"
                )
            expected = meta_expected(key, parsed)
            if expected is not None:
                raise ValueError(
                    f"{path.name} line {k + 1}: meta {key!r} is a {_describe_json(parsed)}; "
                    f"expected {expected}"
                )
            meta[key] = parsed
            meta_line[key] = k + 1
        k += 1
    if k >= len(lines):
        raise ValueError(f"{path.name}: canonical CSV without a header line")
    cols = split_header(lines[k], ",")
    require_columns(path, "canonical", cols, CANONICAL_REQUIRED)
    unknown = [c for c in cols if c not in CANONICAL_COLUMNS]
    if unknown:
        raise ValueError(
            f"{path.name}: unknown canonical column(s) {unknown}; expected a subset of "
            f"{list(CANONICAL_COLUMNS)}"
        )
    data, n_empty = parse_table(lines[k + 1 :], ",", len(cols), path, k + 2, say)
    named = "file" in meta
    meta.setdefault("file", path.name)  # for the warnings; removed again if the file had none
    report_empty_rows(n_empty, meta)
    require_complete_rows(data, range(len(cols)), meta)
    t, data = repair_time(data[:, cols.index("time_s")], data, meta)
    chans = {CANONICAL_COLUMNS[c]: data[:, j] for j, c in enumerate(cols)}
    chans["time"] = t
    check_units(
        t,
        chans["psi"],
        chans["r"],
        chans["delta"],
        meta,
        names={
            "time": "time_s",
            "psi": "psi_rad",
            "r": "r_rad_s",
            "delta": "delta_rad",
            "U": "U_m_s",
        },
        U=chans.get("U"),
        x=chans.get("x"),
        y=chans.get("y"),
    )
    # canonical psi is already processed (glitches repaired by the source loader): only enforce
    # continuity, so that a clean file round-trips bit for bit
    psi = chans["psi"]
    if np.any(np.abs(np.diff(psi)) > np.pi):
        chans["psi"] = psi[0] + np.concatenate(([0.0], np.cumsum(ssa(np.diff(psi)))))
        warn_repair(meta, "psi was wrapped (jumps > pi); unwrapped to a continuous heading")
    for name in _ANGLE_CHANNELS:
        angle = chans.get(name)
        if angle is not None and np.any((angle <= -np.pi) | (angle > np.pi)):
            chans[name] = wrap_angle(angle)
            warn_repair(meta, f"{name} outside (-pi, pi]; wrapped to (-pi, pi]")
    if meta.get("irregular_sampling") is not True:
        flag_irregular(t, meta)
    if not named:
        del meta["file"]
    return Record(**chans, meta=meta)


# ----------------------------------------------------------------------------------------------
# arrays of any units
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
        Channel -> 1-D array (channels of :data:`~shipgym.sysid.units.CHANNELS`; ``time`` may
        be datetime64 or ISO strings when its unit is ``"datetime"``). Required: ``time``,
        ``delta``, ``psi``.
    units : mapping, optional
        Channel -> unit of :data:`~shipgym.sysid.units.UNITS`; a channel not named is in SI
        units (seconds, radians, rad/s, m/s, metres; lat/lon in degrees).
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
    missing = [ch for ch in REQUIRED_INPUTS if arrays.get(ch) is None]
    if missing:
        raise ValueError(f"{where}: channel(s) {missing} missing; required: time, delta, psi")
    for ch, unit in units.items():
        if ch not in CHANNELS:
            raise ValueError(f"{where}: unit given for unknown channel {ch!r}")
        unit_of(ch, unit, f"{where}: units")
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
                arr, start = parse_time([str(v) for v in arr], "datetime", f"{where}: time")
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
    t_good, table = repair_time(data["time"][keep], table, out_meta)
    gaps_at = table[:, -1] > 0.0
    data = {ch: table[:, j] for j, ch in enumerate(data)}
    data["time"] = t_good
    if n_missing:
        warn_repair(out_meta, f"{n_missing} rows miss a value of a mapped channel: treated as gaps")
    segs = _segments_with_breaks(t_good, gaps_at, max_gap_s)
    short = [(a, b) for a, b in segs if b - a < MIN_SEGMENT_SAMPLES]
    segs = [(a, b) for a, b in segs if b - a >= MIN_SEGMENT_SAMPLES]
    if not segs:
        raise ValueError(
            f"{where}: no stretch of at least {MIN_SEGMENT_SAMPLES} samples without a gap "
            f"(longest {max((b - a for a, b in short), default=0)})"
        )
    if short:
        warn_repair(
            out_meta,
            f"dropped {len(short)} segments shorter than {MIN_SEGMENT_SAMPLES} samples "
            f"({sum(b - a for a, b in short)} samples)",
        )
    # lat/lon to north/east from the first kept fix
    if "lat" in data:
        first = segs[0][0]
        lat, lon = data.pop("lat"), data.pop("lon")
        north, east = latlon_to_ne(lat[first:], lon[first:])
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

        check_units(
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
        psi = repair_heading(ts, data["psi"][a:b], None if r_in is None else r_in[a:b], out_meta)
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
        measure_rudder_offset(data["time"][a:b], data["delta"][a:b], out_meta)
    inner = np.concatenate([np.diff(data["time"][a:b]) for a, b in segs])
    if inner.size and float(np.max(inner) - np.min(inner)) > 0.01 * float(np.median(inner)):
        flag_irregular(np.concatenate(([0.0], np.cumsum(inner))), out_meta)
    if len(segs) > 1:
        spans = [[float(data["time"][a]), float(data["time"][b - 1])] for a, b in segs]
        out_meta["segments"] = spans
        longest = max(range(len(segs)), key=lambda k: spans[k][1] - spans[k][0])
        warn_repair(
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

"""Measured manoeuvring data: one canonical record type and loaders for every measured source.

The system-identification tools fit Nomoto-type models (seed 000: the first-order
model ``T r' + r = K delta`` and its second-order relative) and 3-DOF models to measured time
series. This module turns the six measured sources described in
``../shared/data/measured/SOURCES.md`` into one :class:`Record` in the project's units and sign
convention:

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

Per-source conversions (the columns and conventions are those verified in SOURCES.md):

=========== ================================================================================
source      conversion
=========== ================================================================================
sspa        delta negated (source: positive = port turn); r recomputed from psi (the source r
            is ``numpy.gradient(psi)``, not measured); U from the positions.
marin       full scale. deg -> rad for psi, r, delta; delta negated; time rebuilt as
            ``index * 0.135264 s`` (3-significant-digit time stamps); earth-fixed dx0/dt,
            dy0/dt rotated into body u, v.
hsva        model scale, cp1252 header. deg -> rad; delta negated ("positive steering to port
            side"); earth-fixed velocities rotated into body u, v; rpm = 60 n; thrust [N] from
            column 11.
esso_osaka  MMG convention already starboard-positive (no flip); psi_hat unwrapped;
            rpm = 60 n; trailing all-empty rows dropped. Apparent wind from
            ``wind_velo_relative_mid`` / ``wind_dir_relative_mid``: the source angle is already
            "from", clockwise from the bow (verified against the true wind and the ship motion,
            residual below 0.04 deg RMS), only wrapped from [0, 2 pi) to (-pi, pi].
usv         delta from the measured ``rudder`` column [deg] (starboard-positive; the ``delta``
            and ``-rudder`` columns of the file are its negative and are ignored); x, y
            recomputed from lat/lon on the WGS84 local tangent plane; U = speed [kn] * 0.514444;
            r derived from the heading.
gunnerus    delta = -azimuth (both pods steer together; positive azimuth turns to port), azimuth
            kept with its own sign; psi, r, Azi deg -> rad; x = N, y = E; u, v rescaled by
            1.9834 / 1.943844 (the origin used 1/1.9834 instead of 1/1.943844 for kn -> m/s).
=========== ================================================================================

Repairs: every data oddity is either repaired with a :class:`SysidDataWarning` and recorded in
``meta["repairs"]``, or refused with a ``ValueError``; nothing is changed silently.

* heading: increments are wrapped with the smallest signed angle (unwrap). When ``r`` is
  measured, an increment that disagrees with the trapezoidal integral of ``r`` by more than
  ``max(HEADING_GLITCH_TOL, 10 sigma)`` (sigma: robust MAD spread of that disagreement over the
  record) is bad. A run of two or more bad increments is a glitch (e.g. the Gunnerus headings
  interpolated across 359 -> 0 deg): its samples are replaced by the integral of ``r`` corrected
  linearly so that it meets the good samples at both ends (the total change is taken modulo
  2 pi nearest to the integral of r; at a record end it follows r). A single bad increment is a
  step of the whole heading (e.g. an estimator reset): it is kept and reported with a warning.
  Without ``r``, single-sample spikes larger than ``HEADING_SPIKE_TOL`` (a jump and its return)
  are interpolated linearly.
* time: exact duplicate rows are dropped; quantised (non-decreasing, repeated) time stamps that
  lie on a uniform grid to within their quantisation are rebuilt on that grid; time going
  backwards is refused.
* irregular sampling is kept but flagged (``meta["irregular_sampling"]``, warning); use
  :meth:`Record.resample`.
* missing or derived yaw rate: ``r`` is computed from ``psi`` by a local quadratic least-squares
  derivative over a centred time window (identical to a Savitzky-Golay derivative filter,
  ``scipy.signal.savgol_filter(psi, w, 2, deriv=1)``, on a uniform grid).
* a non-zero neutral rudder (rudder before the first rudder order) is measured and stored in
  ``meta["rudder_offset_rad"]`` (canonical sign, with ``meta["first_rudder_order_s"]``) and
  warned about when above 0.3 deg; ``delta`` itself is kept as measured.
* rows with a missing value in a used column are refused (ValueError); all-empty rows dropped.
* text: a UTF-8 byte-order mark before the first line is dropped (every format); a header that
  names a column twice is refused (ValueError naming the column), never resolved silently.

Unit checks (every format, on the values as read, before any repair). Clear unit errors are
refused with a ``ValueError`` naming the column and the probable unit; borderline values load
with a :class:`SysidDataWarning` and a ``meta["notes"]`` entry starting ``"unit check:"``.

==================================== ===========================================================
check                                refused (ValueError) / warned
==================================== ===========================================================
heading range                        refused: a jump of 360 +- 30 between two samples (a heading
                                     in degrees wrapped at 360)
yaw rate vs heading derivative       the heading change over ~200 blocks against the integral
                                     of r (least-squares ratio, used when they correlate above
                                     0.9): refused within a factor 1.2 of 180/pi (psi in deg),
                                     pi/180 (r in deg/s), 1e-3 (time in ms), 0.057 (psi in deg
                                     and time in ms) or -1 (opposite signs), and outside
                                     [0.5, 2]; warned outside [0.8, 1.25]
yaw-rate magnitude                   refused above 2 rad/s (99.9th percentile of abs(r):
                                     deg/s, named with psi when psi agrees), warned above 1 rad/s
rudder magnitude                     refused above pi rad (degrees), warned above pi/2
sample time vs speed                 (canonical files) distance run by x, y over blocks of at
                                     most 5 s against the integral of U: refused within a
                                     factor 1.2 of 1e-3 (time in ms or x, y in km), 0.514 (U in
                                     knots), 1/3.6 (U in km/h), warned outside [0.5, 2]; a
                                     median sample interval above 10 s is warned about (time in
                                     ms?), with the median speed
==================================== ===========================================================

A heading and a yaw rate that are both in degrees (so agree with each other) of a slowly turning
ship (below 2 deg/s) and not wrapping at 360 pass these checks: nothing in the record itself tells
them from radians.

Large records: rows are parsed by :func:`numpy.loadtxt` in chunks of 250 000 (a chunk numpy
refuses is parsed again row by row to name the bad line); files above
:data:`PROGRESS_FILE_BYTES` print one progress line per chunk to stderr by default (``progress``
of :func:`load`), and a record of more than :data:`LARGE_RECORD_SAMPLES` samples loads with a
:class:`SysidDataWarning` that suggests cutting or resampling it. (Measured on a canonical
file of 2 million rows and 7 channels, 239 MB: about 45 s of parsing and 0.8 GB peak memory on
a busy machine; the per-row Python loop this replaces was about 7 times slower.)

Canonical CSV (:meth:`Record.to_csv`, :meth:`Record.from_csv`, ``load(..., "canonical")``)::

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

import json
import math
import os
import re
import sys
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from scipy.signal import savgol_filter

__all__ = [
    "FORMATS",
    "HEADING_GLITCH_TOL",
    "HEADING_SPIKE_TOL",
    "LARGE_RECORD_SAMPLES",
    "PROGRESS_FILE_BYTES",
    "Record",
    "SysidDataWarning",
    "derive_yaw_rate",
    "detect_format",
    "load",
    "load_all",
    "measured_root",
    "wrap_angle",
]

FORMATS: tuple[str, ...] = (
    "sspa",
    "marin",
    "hsva",
    "esso_osaka",
    "usv",
    "gunnerus",
    "canonical",
    "table",
    "nmea",
)
"""Accepted values of ``format`` in :func:`load`: the six measured sources, the canonical CSV,
any delimited ``table`` with a column map or unit-stating headers
(:mod:`shipgym.sysid.table`) and NMEA 0183 logs (:mod:`shipgym.sysid.nmea`)."""

HEADING_GLITCH_TOL: float = math.radians(4.0)
"""Smallest tolerance [rad] for the disagreement between one heading increment and the
integral of r; the tolerance used is ``max(HEADING_GLITCH_TOL, 10 sigma)`` with sigma the robust
(MAD) spread of that disagreement over the record."""

LARGE_RECORD_SAMPLES: int = 500_000
"""A record with more samples than this (e.g. 14 h at 10 Hz) is loaded with a
:class:`SysidDataWarning` (loading takes about 25 s per million rows and 0.4 kB of memory per
sample; every fit of the identification replays every sample)."""

PROGRESS_FILE_BYTES: int = 32_000_000
"""By default :func:`load` prints progress lines to stderr for files larger than this (about
200 000 rows of a canonical CSV with every channel)."""

ProgressArg = Callable[[str], None] | TextIO | bool | None
"""Where :func:`load` sends its progress lines (see its ``progress`` parameter)."""

HEADING_SPIKE_TOL: float = math.radians(15.0)
"""Without a measured r: a heading jump [rad] larger than this that returns at the next sample
is a spike."""

_KNOT = 1852.0 / 3600.0  # m/s per knot
_MARIN_SCALE = 45.714
_MARIN_DT = 0.135264  # s full scale = 0.02 s model scale * sqrt(45.714)
_GUNNERUS_SPEED_FIX = 1.9834 / (3600.0 / 1852.0)  # origin divided knots by 1.9834, not 1.943844
_WGS84_A = 6378137.0
_WGS84_E2 = 6.69437999014e-3

# canonical CSV column name -> Record attribute
_CANONICAL_COLUMNS: dict[str, str] = {
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
_OPTIONAL = ("x", "y", "u", "v", "U", "azimuth", "rpm", "thrust", "wind_speed", "wind_angle")
_ANGLE_CHANNELS = ("wind_angle",)  # wrapped to (-pi, pi]; psi is continuous instead
_CANONICAL_MAGIC = "# shipgym canonical record v1"

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


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _meta_expected(key: str, value: Any) -> str | None:
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


class SysidDataWarning(UserWarning):
    """A data oddity in a measured record was repaired (the repair is listed in ``meta``)."""


def _warn(meta: dict[str, Any], message: str) -> None:
    """Record a repair in ``meta["repairs"]`` and emit a :class:`SysidDataWarning`."""
    meta.setdefault("repairs", []).append(message)
    where = meta.get("file", "")
    warnings.warn(f"{where}: {message}" if where else message, SysidDataWarning, stacklevel=3)


def _ssa(a: np.ndarray) -> np.ndarray:
    """Smallest signed angle, as ``shipgym.models.ssa``: wrap to [-pi, pi)."""
    return np.mod(a + np.pi, 2.0 * np.pi) - np.pi


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Wrap to (-pi, pi] (the wind-angle convention); values already inside are kept bit for bit."""
    a = np.asarray(a, dtype=np.float64)
    outside = (a <= -np.pi) | (a > np.pi)
    wrapped = np.pi - np.mod(np.pi - a, 2.0 * np.pi)
    wrapped = np.where(wrapped <= -np.pi, wrapped + 2.0 * np.pi, wrapped)  # mod rounding to 2 pi
    return np.where(outside, wrapped, a)


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

        The arrays go through the processing of a loaded table (:mod:`shipgym.sysid.table`):
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
            Channel -> unit of :data:`shipgym.sysid.table.UNITS` (``{"psi": "deg", "r":
            "deg/min", "U": "kn"}``); channels not named are SI.
        meta : mapping, optional
            Merged into the record's meta (``source``, ``vessel``, ``L`` ...).
        max_gap_s : float, optional
            Longest time step [s] inside a segment (default: 5 median steps); a sample with a
            NaN is a gap as well.
        """
        from shipgym.sysid.table import record_from_arrays

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
        inverse = {attr: col for col, attr in _CANONICAL_COLUMNS.items()}
        lines = [_CANONICAL_MAGIC]
        for key, value in self.meta.items():
            if not re.fullmatch(r"[A-Za-z0-9_.\-]+", str(key)):
                raise ValueError(f"meta key {key!r} must match [A-Za-z0-9_.-]+ for canonical CSV")
            lines.append(f"# {key}: {json.dumps(value)}")
        lines.append(",".join(inverse[name] for name in chans))
        data = np.column_stack(list(chans.values()))
        row_format = ",".join(["%.17g"] * data.shape[1])  # as format(v, ".17g"), per row
        with path.open("w", encoding="utf-8", newline="\n") as fh:
            fh.write("\n".join(lines) + "\n")
            for a in range(0, data.shape[0], _PARSE_CHUNK):
                block = data[a : a + _PARSE_CHUNK].tolist()
                fh.write("\n".join([row_format % tuple(row) for row in block]) + "\n")
        return path

    @classmethod
    def from_csv(cls, path: str | Path, *, progress: ProgressArg = None) -> Record:
        """Read a canonical CSV written by :meth:`to_csv` (``load(path, "canonical")``)."""
        return load(path, "canonical", progress=progress)


# ----------------------------------------------------------------------------------------------
# generic helpers
# ----------------------------------------------------------------------------------------------
def _silent(_msg: str) -> None:
    """The progress printer that prints nothing."""


_PARSE_CHUNK = 250_000  # rows per numpy parse call (one progress line each on large files)


def _parse_rows_slow(
    rows: Sequence[str], sep: str | None, ncol: int, path: Path, line_of: Sequence[int]
) -> np.ndarray:
    """Row-by-row parse with empty fields -> NaN and a message naming the bad line."""
    out = np.empty((len(rows), ncol))
    for k, line in enumerate(rows):
        fields = line.split(sep) if sep is not None else line.split()
        if len(fields) != ncol:
            raise ValueError(
                f"{path.name} line {line_of[k]}: expected {ncol} fields, got {len(fields)}"
            )
        try:
            out[k] = [float(f) if f.strip() else math.nan for f in fields]
        except ValueError as exc:
            raise ValueError(f"{path.name} line {line_of[k]}: non-numeric field ({exc})") from exc
    return out


def _parse_table(
    rows: Sequence[str],
    sep: str | None,
    ncol: int,
    path: Path,
    first_line: int,
    say: Callable[[str], None] = _silent,
) -> tuple[np.ndarray, int]:
    """Parse text rows into a float array; empty fields -> NaN. Returns (data, n_empty_rows).

    Rows holding only separators and blanks are dropped and counted. The rest is parsed by
    :func:`numpy.loadtxt` in chunks of :data:`_PARSE_CHUNK` rows (C speed, one progress line
    per chunk); a chunk numpy refuses (an empty field, a wrong field count, text) is parsed again
    row by row, which reads empty fields as NaN and names the first bad line.
    """
    blank = (sep or "") + " \t\r\n\f\v"
    keep = [k for k, line in enumerate(rows) if line.strip(blank)]
    n_empty = len(rows) - len(keep)
    if not keep:
        raise ValueError(f"{path.name}: no data rows")
    good = rows if n_empty == 0 else [rows[k] for k in keep]
    n = len(good)
    out = np.empty((n, ncol))
    t0 = time.perf_counter()
    for a in range(0, n, _PARSE_CHUNK):
        chunk = good[a : a + _PARSE_CHUNK]
        try:
            part = np.loadtxt(chunk, delimiter=sep, comments=None, ndmin=2, dtype=np.float64)
            if part.shape != (len(chunk), ncol):
                raise ValueError("field count")
        except ValueError:
            lines_of = [first_line + k for k in keep[a : a + len(chunk)]]
            part = _parse_rows_slow(chunk, sep, ncol, path, lines_of)
        out[a : a + len(chunk)] = part
        if n > _PARSE_CHUNK:
            done = min(a + _PARSE_CHUNK, n)
            say(
                f"{path.name}: parsed {done:,} of {n:,} rows ({100 * done / n:.0f} %, "
                f"{time.perf_counter() - t0:.1f} s)"
            )
    return out, n_empty


def _drop_empty(n_empty: int, meta: dict[str, Any]) -> None:
    if n_empty:
        _warn(meta, f"dropped {n_empty} all-empty rows")


def _drop_nan_rows(data: np.ndarray, cols: Sequence[int], meta: dict[str, Any]) -> np.ndarray:
    """Refuse rows that miss a used value (partial rows are not guessed); returns ``data``."""
    bad = ~np.all(np.isfinite(data[:, list(cols)]), axis=1)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{meta.get('file', '')}: {int(bad.sum())} rows miss a value (first at data row {i});"
            " expected every used column to be numeric"
        )
    return data


def _repair_time(
    t: np.ndarray,
    data: np.ndarray,
    meta: dict[str, Any],
    known_dt: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Make ``t`` strictly increasing (see module docstring). Returns (t, data) (rows may drop)."""
    if known_dt is not None:
        t_new = t[0] + known_dt * np.arange(t.size)
        tol = 0.005 * np.abs(t_new) + 1e-3 * known_dt
        if np.any(np.abs(t - t_new) > tol):
            i = int(np.argmax(np.abs(t - t_new) - tol))
            raise ValueError(
                f"{meta.get('file', '')}: time stamps are not a uniform {known_dt} s grid"
                f" (row {i}: {t[i]} s vs {t_new[i]} s); refusing to rebuild the time"
            )
        if np.any(np.diff(t) <= 0) or np.max(np.abs(t - t_new)) > 1e-9:
            _warn(
                meta,
                f"time stamps quantised ({int(np.sum(np.diff(t) <= 0))} repeated); rebuilt as "
                f"t0 + index * {known_dt} s",
            )
        return t_new, data
    dt = np.diff(t)
    if np.all(dt > 0):
        return t, data
    if np.any(dt < 0):
        i = int(np.flatnonzero(dt < 0)[0])
        raise ValueError(
            f"{meta.get('file', '')}: time goes backwards at row {i + 1} ({t[i]} -> {t[i + 1]} s);"
            " expected non-decreasing time"
        )
    # exact duplicate rows
    dup = np.zeros(t.size, dtype=bool)
    same = np.all((data[1:] == data[:-1]) | (np.isnan(data[1:]) & np.isnan(data[:-1])), axis=1)
    dup[1:] = same
    if np.any(dup):
        _warn(meta, f"dropped {int(dup.sum())} exact duplicate rows")
        t, data = t[~dup], data[~dup]
        if np.all(np.diff(t) > 0):
            return t, data
    # quantised time stamps: accept a uniform grid that reproduces them within the quantum
    idx = np.arange(t.size, dtype=np.float64)
    slope, intercept = np.polyfit(idx, t, 1)
    steps = np.diff(t)
    quantum = float(np.min(steps[steps > 0])) if np.any(steps > 0) else 0.0
    t_new = intercept + slope * idx
    if slope > 0 and quantum > 0 and np.max(np.abs(t - t_new)) <= quantum:
        _warn(
            meta,
            f"time stamps quantised ({int(np.sum(steps == 0))} repeated, quantum {quantum:g} s);"
            f" rebuilt on a uniform grid, dt = {slope:.9g} s",
        )
        return t_new, data
    i = int(np.flatnonzero(steps == 0)[0])
    raise ValueError(
        f"{meta.get('file', '')}: repeated time stamp {t[i]} s at rows {i}, {i + 1} with different"
        " data, and the time is not a quantised uniform grid; expected strictly increasing time"
    )


def _flag_irregular(t: np.ndarray, meta: dict[str, Any]) -> None:
    dt = np.diff(t)
    med = float(np.median(dt))
    if float(np.max(dt) - np.min(dt)) > 0.01 * med:
        meta["irregular_sampling"] = True
        _warn(
            meta,
            f"irregular sampling (dt {float(np.min(dt)):g}..{float(np.max(dt)):g} s, median "
            f"{med:g} s) kept as is; use Record.resample for a uniform grid",
        )


def derive_yaw_rate(time: np.ndarray, psi: np.ndarray, window_s: float) -> np.ndarray:
    """Yaw rate [rad/s] from a continuous heading by a local quadratic least-squares derivative.

    At each sample a parabola is fitted to the samples within ``|t - t_i| <= window_s / 2``
    (at least 5 samples; the window is shifted inwards near the ends) and its slope at ``t_i``
    is returned. On a uniform grid this is the Savitzky-Golay derivative filter
    ``scipy.signal.savgol_filter(psi, w, polyorder=2, deriv=1, delta=dt, mode="interp")``,
    which is used there.

    Parameters
    ----------
    time : numpy.ndarray
        Strictly increasing time [s].
    psi : numpy.ndarray
        Continuous heading [rad].
    window_s : float
        Window length [s].
    """
    t = np.asarray(time, dtype=np.float64)
    p = np.asarray(psi, dtype=np.float64)
    n = t.size
    if n < 5:
        raise ValueError(f"derive_yaw_rate needs at least 5 samples, got {n}")
    dt = np.diff(t)
    med = float(np.median(dt))
    w = round(window_s / med)
    w = max(5, w + (1 - w % 2))
    w = min(w, n if n % 2 else n - 1)
    if float(np.max(dt) - np.min(dt)) <= 1e-6 * med:
        return savgol_filter(p, w, 2, deriv=1, delta=med, mode="interp")
    half = w // 2
    out = np.empty(n)
    for i in range(n):
        lo = min(max(0, i - half), n - w)
        tt = t[lo : lo + w] - t[i]
        coef = np.polyfit(tt, p[lo : lo + w], 2)
        out[i] = coef[1]
    return out


# unit checks -----------------------------------------------------------------------------------
#: ratio of the heading change to the integral of r (both per block) -> the probable unit error
_HEADING_RATIO_UNITS: tuple[tuple[float, str], ...] = (
    (180.0 / math.pi, "{psi} looks like degrees (with {r} in rad/s); expected radians"),
    (math.pi / 180.0, "{r} looks like deg/s (with {psi} in rad); expected rad/s"),
    (1.0e-3, "{time} looks like milliseconds; expected seconds"),
    (
        180.0 / math.pi * 1.0e-3,
        "{psi} looks like degrees and {time} like milliseconds; expected radians and seconds",
    ),
    (
        -1.0,
        "{r} has the opposite sign of the heading's rate of change; expected both positive "
        "clockwise (negate one of them)",
    ),
)
#: ratio of the distance run (from x, y) to the integral of the speed -> the probable unit error
_SPEED_RATIO_UNITS: tuple[tuple[float, str], ...] = (
    (1.0e-3, "{time} looks like milliseconds (or x, y like km); expected seconds and metres"),
    (_KNOT, "{U} looks like knots; expected m/s"),
    (1.0 / 3.6, "{U} looks like km/h; expected m/s"),
)
_UNIT_TOL = 1.2  # a ratio within this factor of a unit factor names that unit
_MAX_YAW_RATE = 2.0  # rad/s (115 deg/s): above it the yaw rate is refused as deg/s
_WARN_YAW_RATE = 1.0  # rad/s (57 deg/s): above it a warning
_MAX_RUDDER = math.pi  # rad: a larger |delta| is refused as degrees
_WARN_RUDDER = 0.5 * math.pi  # rad: above it a warning
_WARN_DT = 10.0  # s: a longer median sample interval is warned about


def _block_ratio(num: np.ndarray, den: np.ndarray) -> tuple[float, float]:
    """Least-squares ratio ``num / den`` of block sums (about 200 blocks) and their correlation.

    Summing over blocks averages the noise of the increments; (nan, nan) when there are fewer
    than 10 blocks or one of the sums does not vary.
    """
    m = max(1, num.size // 200)
    nb = num.size // m
    if nb < 10:
        return math.nan, math.nan
    a = num[: nb * m].reshape(nb, m).sum(axis=1)
    b = den[: nb * m].reshape(nb, m).sum(axis=1)
    if float(np.std(a)) == 0.0 or float(np.std(b)) == 0.0:
        return math.nan, math.nan
    return float(a @ b / (b @ b)), float(np.corrcoef(a, b)[0, 1])


def _unit_verdict(ratio: float, units: Sequence[tuple[float, str]]) -> tuple[str, str | None]:
    """("ok" | "warn" | "refuse", the named unit error or None) for a consistency ratio."""
    for factor, message in units:
        if ratio * factor > 0 and abs(math.log(ratio / factor)) < math.log(_UNIT_TOL):
            return ("ok", None) if factor == 1.0 else ("refuse", message)
    if ratio <= 0 or abs(math.log(ratio)) > math.log(2.0):
        return "refuse", None
    if abs(math.log(ratio)) > math.log(1.25):
        return "warn", None
    return "ok", None


def _check_units(
    t: np.ndarray,
    psi_raw: np.ndarray,
    r: np.ndarray | None,
    delta: np.ndarray,
    meta: dict[str, Any],
    *,
    names: dict[str, str] | None = None,
    U: np.ndarray | None = None,
    x: np.ndarray | None = None,
    y: np.ndarray | None = None,
    speed_is_derived: bool = False,
    declared: Mapping[str, str] | None = None,
) -> None:
    """Refuse clear unit errors and warn about borderline ones (see the module docstring).

    ``psi_raw`` is the heading as read (radians by the format, not yet unwrapped); ``r`` the
    yaw rate as read (None when the source has none); ``U`` the speed (derived from ``x, y``
    when ``speed_is_derived``). ``names`` maps ``time, psi, r, delta, U`` to the source's
    column names for the messages; ``declared`` the channels whose unit the user stated (a
    column map) to that unit: an impossible value there is no unit mix-up, and the message
    says so rather than suggest a conversion.
    """
    col = {"time": "time", "psi": "psi", "r": "r", "delta": "delta", "U": "U", **(names or {})}
    label = {k: f"column {v!r}" for k, v in col.items()}
    where = meta.get("file") or "record"

    def refuse(what: str) -> ValueError:
        return ValueError(f"{where}: {what}")

    def warn(what: str) -> None:
        notes = meta.setdefault("notes", [])
        if f"unit check: {what}" not in notes:  # a canonical file re-read keeps one copy
            notes.append(f"unit check: {what}")
        warnings.warn(f"{where}: {what}", SysidDataWarning, stacklevel=4)

    # heading: a jump of about 360 between samples is a heading in degrees wrapped at 360
    d = np.diff(psi_raw)
    jump360 = np.abs(np.abs(d) - 360.0) < 30.0
    if np.any(jump360):
        i = int(np.flatnonzero(jump360)[0])
        raise refuse(
            f"{label['psi']} looks like degrees: it jumps from {psi_raw[i]:.6g} to "
            f"{psi_raw[i + 1]:.6g} at t = {t[i + 1]:g} s (a heading wrapped at 360 deg); values "
            f"span [{float(np.min(psi_raw)):.6g}, {float(np.max(psi_raw)):.6g}]; expected "
            "radians (convert with numpy.radians)"
        )
    declared = dict(declared or {})

    def stated(channel: str) -> str:
        """The end of a refusal for a channel whose unit the user stated."""
        return (
            f"in {declared[channel]} as stated in the column map, so not a unit mix-up: is it "
            "the right column?"
        )

    # rudder and yaw-rate magnitudes (robust to single spikes: 99.9th percentile)
    big_delta = float(np.percentile(np.abs(delta), 99.9))
    if big_delta > _MAX_RUDDER:
        raise refuse(
            f"{label['delta']} reaches {big_delta:.4g} rad ({math.degrees(big_delta):.4g} deg), "
            + (
                f"beyond any rudder angle, {stated('delta')}"
                if "delta" in declared
                else "beyond any rudder angle: it looks like degrees; expected radians (convert "
                "with numpy.radians)"
            )
        )
    if big_delta > _WARN_RUDDER:
        warn(
            f"{label['delta']} reaches {big_delta:.4g} rad ({math.degrees(big_delta):.0f} deg), "
            "more than 90 deg; check that it is in radians"
        )
    h = np.diff(t)
    ratio = corr = math.nan
    if r is not None:
        keep = np.abs(d) < math.pi  # increments that look like wraps left out
        ratio, corr = _block_ratio(
            np.where(keep, d, 0.0), np.where(keep, 0.5 * (r[1:] + r[:-1]) * h, 0.0)
        )
        big_r = float(np.percentile(np.abs(r), 99.9))
        if big_r > _MAX_YAW_RATE:
            agrees = math.isfinite(ratio) and abs(corr) > 0.9 and abs(math.log(ratio)) < 0.2
            raise refuse(
                f"{label['r']} reaches {big_r:.4g} rad/s ({math.degrees(big_r):.4g} deg/s), "
                f"faster than any ship turns (limit {_MAX_YAW_RATE:g} rad/s)"
                + (
                    f", {stated('r')}"
                    if "r" in declared
                    else ": it looks like "
                    + (
                        f"deg/s, and {label['psi']}, which agrees with it, like degrees; "
                        "expected rad/s and radians"
                        if agrees
                        else "deg/s; expected rad/s"
                    )
                )
            )
        if big_r > _WARN_YAW_RATE:
            warn(
                f"{label['r']} reaches {big_r:.4g} rad/s ({math.degrees(big_r):.0f} deg/s), "
                "fast for a ship; check that it is in rad/s"
            )
    fmt = {k: label[k] for k in ("time", "psi", "r", "U")}
    # yaw rate against the heading's rate of change
    if r is not None:
        if math.isfinite(ratio) and abs(corr) > 0.9:
            verdict, named = _unit_verdict(ratio, _HEADING_RATIO_UNITS)
            what = (
                f"the heading changes {ratio:.4g} times the integral of the yaw rate "
                f"({label['psi']} against {label['r']}; expected 1 with radians, rad/s and "
                "seconds)"
            )
            if verdict == "refuse":
                raise refuse(f"{what}: {(named or 'inconsistent units').format(**fmt)}")
            if verdict == "warn":
                warn(what)
    # distance run against the speed, and the sample interval
    dt = float(np.median(h))
    if U is not None and x is not None and y is not None and not speed_is_derived:
        # straight-line distance over blocks of at most 5 s (close to the arc run, and the
        # position noise averages out) against the integral of the speed over the same blocks
        m = max(1, min(t.size // 200, round(5.0 / dt) if dt > 0 else 1))
        ends = np.arange(0, t.size, m)
        chord = np.hypot(np.diff(x[ends]), np.diff(y[ends]))
        run = np.diff(np.concatenate(([0.0], np.cumsum(0.5 * (U[1:] + U[:-1]) * h)))[ends])
        ratio = float(np.sum(chord) / np.sum(run)) if np.sum(run) > 0 else math.nan
        if math.isfinite(ratio) and ratio > 0 and float(np.median(U)) > 0.05:
            verdict, named = _unit_verdict(ratio, ((1.0, ""), *_SPEED_RATIO_UNITS))
            what = (
                f"the positions x, y advance {ratio:.4g} times the integral of the speed "
                f"{label['U']} (expected 1 with metres, m/s and seconds)"
            )
            if verdict == "refuse" and named is not None:
                raise refuse(f"{what}: {named.format(**fmt)}")
            if verdict != "ok":
                warn(what)
    if dt > _WARN_DT:
        speed = "" if U is None else f" at a median speed of {float(np.median(U)):.3g} m/s"
        warn(
            f"the median sample interval is {dt:g} s{speed}, long for manoeuvring data "
            f"(expected <= {_WARN_DT:g} s): if {label['time']} is in milliseconds, divide it by "
            "1000"
        )


def _repair_heading(
    t: np.ndarray, psi_raw: np.ndarray, r: np.ndarray | None, meta: dict[str, Any]
) -> np.ndarray:
    """Unwrap the heading and repair glitches (module docstring). Returns continuous psi."""
    d = _ssa(np.diff(psi_raw))
    n_wraps = int(np.sum(np.abs(np.diff(psi_raw)) > np.pi))
    if n_wraps:
        meta.setdefault("conversions", []).append(f"psi unwrapped ({n_wraps} wraps)")
    h = np.diff(t)
    if r is not None:
        expected = 0.5 * (r[:-1] + r[1:]) * h
    else:
        # neighbour consistency: a spike is a large increment followed by its return
        expected = np.zeros_like(d)
        big = np.abs(d) > HEADING_SPIKE_TOL
        ret = np.zeros_like(big)
        ret[:-1] = big[:-1] & big[1:] & (np.abs(d[:-1] + d[1:]) < 0.5 * np.abs(d[:-1]))
        bad_nr = ret.copy()
        bad_nr[1:] |= ret[:-1]
        expected[~bad_nr] = d[~bad_nr]
    mismatch = d - expected
    sigma = 1.4826 * float(np.median(np.abs(mismatch - np.median(mismatch))))
    tol = max(HEADING_GLITCH_TOL, 10.0 * sigma)
    bad = np.abs(mismatch) > tol
    if not np.any(bad):
        return psi_raw[0] + np.concatenate(([0.0], np.cumsum(d)))
    d = d.copy()
    edges = np.flatnonzero(np.diff(np.concatenate(([0], bad.astype(np.int8), [0]))))
    runs = list(zip(edges[::2], edges[1::2], strict=True))  # increments a..b-1 are bad
    n_glitch = 0
    for a, b in runs:
        integral = float(np.sum(expected[a:b]))
        anchored = (a > 0 and b < d.size) or b - a == 1
        if anchored:
            # samples a and b are good: keep their difference, modulo 2 pi nearest to the r-integral
            total = float(np.sum(d[a:b]))
            total += 2.0 * np.pi * round((integral - total) / (2.0 * np.pi))
        else:
            total = integral  # the glitch touches an end of the record: follow r there
        if anchored and abs(total - integral) > tol:
            _warn(
                meta,
                f"unexplained heading change of {math.degrees(total - integral):+.1f} deg "
                f"between t = {t[a]:g} and {t[b]:g} s kept (disagrees with the "
                + ("yaw rate)" if r is not None else "neighbouring samples)"),
            )
        # spread the change like the expected increments, corrected linearly to the total
        d[a:b] = expected[a:b] + (total - integral) * (h[a:b] / float(np.sum(h[a:b])))
        n_glitch += b - a - 1
    if n_glitch:
        glitch_runs = [b - a - 1 for a, b in runs if b - a > 1]
        _warn(
            meta,
            f"heading glitches repaired: {n_glitch} samples in {len(glitch_runs)} runs (longest "
            f"{max(glitch_runs)}) "
            "disagreed with the "
            + ("measured yaw rate" if r is not None else "neighbouring samples")
            + (
                " and were replaced by the integral of r, corrected to meet the good samples"
                if r is not None
                else " and were interpolated linearly"
            ),
        )
    return psi_raw[0] + np.concatenate(([0.0], np.cumsum(d)))


def _rudder_offset(t: np.ndarray, delta: np.ndarray, meta: dict[str, Any]) -> None:
    """Store the neutral rudder before the first rudder order (canonical sign) in meta."""
    moved = np.flatnonzero(np.abs(delta - delta[0]) > math.radians(1.0))
    if moved.size == 0 or moved[0] < 3:
        return
    i = int(moved[0])
    offset = float(np.median(delta[:i]))
    # walk back to the first sample that left the neutral rudder by more than 0.05 deg
    while i > 1 and abs(delta[i - 1] - offset) > math.radians(0.05):
        i -= 1
    meta["rudder_offset_rad"] = offset
    meta["first_rudder_order_s"] = float(t[i])
    if abs(offset) > math.radians(0.3):
        _warn(
            meta,
            f"neutral rudder is {math.degrees(offset):+.2f} deg before the first rudder order "
            f"(t < {t[i]:g} s); delta kept as measured, offset in meta['rudder_offset_rad']",
        )


def _body_velocities(
    dx: np.ndarray, dy: np.ndarray, psi: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Rotate earth-fixed velocities into body axes (u forward, v starboard)."""
    c, s = np.cos(psi), np.sin(psi)
    return dx * c + dy * s, -dx * s + dy * c


def _base_meta(path: Path, source: str, **kw: Any) -> dict[str, Any]:
    meta: dict[str, Any] = {
        "source": source,
        "file": path.name,
        "vessel": "",
        "L": None,
        "scale": "",
        "conversions": [],
        "repairs": [],
        "notes": [],
    }
    meta.update(kw)
    return meta


_UTF8_BOM = b"\xef\xbb\xbf"


def _read_lines(path: Path, encoding: str = "utf-8") -> list[str]:
    """The file's lines, a leading UTF-8 byte-order mark dropped (whatever ``encoding``)."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc}") from exc
    raw = raw.removeprefix(_UTF8_BOM)
    try:
        text = raw.decode(encoding)
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path.name}: cannot decode as {encoding}: {exc}") from exc
    del raw
    lines = text.splitlines()
    if not any(line.strip() for line in lines):
        raise ValueError(f"{path.name}: the file is empty")
    return lines


def _header_error(path: Path, fmt: str, expected: str, got: str) -> ValueError:
    return ValueError(
        f"{path.name} does not look like format {fmt!r}: expected {expected}, got {got[:120]!r}"
    )


def _columns(header: str, sep: str) -> list[str]:
    return [c.strip() for c in header.split(sep)]


def _require(path: Path, fmt: str, cols: list[str], needed: Sequence[str]) -> dict[str, int]:
    seen: set[str] = set()
    for c in cols:
        if c in seen:
            where = [j + 1 for j, name in enumerate(cols) if name == c]
            raise ValueError(
                f"{path.name}: column {c!r} appears {len(where)} times in the header (columns "
                f"{', '.join(map(str, where))}); expected each column name once"
            )
        seen.add(c)
    missing = [c for c in needed if c not in cols]
    if missing:
        raise ValueError(
            f"{path.name} does not look like format {fmt!r}: missing column(s) {missing}; "
            f"expected columns {list(needed)}, got {cols}"
        )
    return {c: cols.index(c) for c in cols}


# ----------------------------------------------------------------------------------------------
# per-source loaders
# ----------------------------------------------------------------------------------------------
def _load_sspa(path: Path, say: Callable[[str], None] = _silent) -> Record:
    lines = _read_lines(path)
    cols = _columns(lines[0], ";")
    needed = ["time", "delta", "x0", "y0", "psi", "r"]
    if len(cols) < 2:
        raise _header_error(
            path, "sspa", "a ';'-separated header 'time;delta;x0;y0;psi;r'", lines[0]
        )
    ix = _require(path, "sspa", cols, needed)
    meta = _base_meta(
        path,
        "sspa",
        vessel="unknown SSPA ship model (not documented)",
        scale="model",
        frame="x0 along the approach course, y0 to starboard (earth-fixed)",
    )
    data, n_empty = _parse_table(lines[1:], ";", len(cols), path, 2, say)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, [ix[c] for c in needed], meta)
    t, data = _repair_time(data[:, ix["time"]], data, meta)
    delta = -data[:, ix["delta"]]
    meta["conversions"].append("delta negated (source: positive rudder gives a port turn)")
    x, y = data[:, ix["x0"]], data[:, ix["y0"]]
    window = 0.3
    speed = np.hypot(derive_yaw_rate(t, x, window), derive_yaw_rate(t, y, window))
    _check_units(
        t, data[:, ix["psi"]], data[:, ix["r"]], delta, meta, U=speed, speed_is_derived=True
    )
    psi = _repair_heading(t, data[:, ix["psi"]], data[:, ix["r"]], meta)
    r = derive_yaw_rate(t, psi, window)
    meta["r_source"] = f"derived from psi (local quadratic / Savitzky-Golay, {window} s window)"
    _warn(
        meta,
        "source r is numpy.gradient(psi), not measured; replaced by a Savitzky-Golay "
        f"derivative of psi ({window} s window)",
    )
    meta["notes"].append("U derived from x0, y0 (Savitzky-Golay derivative, 0.3 s window)")
    meta["notes"].append("rudder quantised in steps of about 0.02 deg")
    _rudder_offset(t, delta, meta)
    _flag_irregular(t, meta)
    return Record(time=t, delta=delta, psi=psi, r=r, x=x, y=y, U=speed, meta=meta)


def _load_marin(path: Path, say: Callable[[str], None] = _silent) -> Record:
    lines = _read_lines(path)
    if not lines[0].startswith("MARIN"):
        raise _header_error(
            path,
            "marin",
            "a first title line starting with 'MARIN' and 11 "
            "tab-separated columns (time x0 y0 phi psi dx0 dy0 p r delta rpm)",
            lines[0],
        )
    meta = _base_meta(
        path,
        "marin",
        vessel="KVLCC2 (MARIN free running, SIMMAN 2008)",
        L=320.0,
        scale="full",
        model_scale_factor=_MARIN_SCALE,
        title=lines[1].strip(),
        frame="earth-fixed x0, y0 (NED-like)",
    )
    data, n_empty = _parse_table(lines[3:], "\t", 11, path, 4, say)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, range(11), meta)
    t, data = _repair_time(data[:, 0], data, meta, known_dt=_MARIN_DT)
    deg = np.pi / 180.0
    r = data[:, 8] * deg
    delta = -data[:, 9] * deg
    _check_units(
        t,
        data[:, 4] * deg,
        r,
        delta,
        meta,
        names={"psi": "psi (column 5)", "r": "r (column 9)", "delta": "delta (column 10)"},
    )
    psi = _repair_heading(t, data[:, 4] * deg, r, meta)
    u, v = _body_velocities(data[:, 5], data[:, 6], psi)
    meta["conversions"] += [
        "psi, r, delta deg -> rad",
        "delta negated (source: positive rudder gives a port turn)",
        "earth-fixed dx0/dt, dy0/dt rotated into body u, v",
    ]
    meta["r_source"] = "measured"
    meta["notes"] += [
        "all values have 3 significant digits (psi resolution 1 deg above 100 deg, x0 10 m above"
        " 1000 m)",
        "full scale; model scale: time and speeds / sqrt(45.714), lengths / 45.714",
    ]
    _rudder_offset(t, delta, meta)
    _flag_irregular(t, meta)
    return Record(
        time=t,
        delta=delta,
        psi=psi,
        r=r,
        x=data[:, 1],
        y=data[:, 2],
        u=u,
        v=v,
        U=np.hypot(data[:, 5], data[:, 6]),
        rpm=data[:, 10],
        meta=meta,
    )


def _load_hsva(path: Path, say: Callable[[str], None] = _silent) -> Record:
    lines = _read_lines(path, encoding="cp1252")
    if "HSVA" not in lines[0]:
        raise _header_error(
            path,
            "hsva",
            "4 header lines starting with ' HSVA' then 12 whitespace-separated columns",
            lines[0],
        )
    meta = _base_meta(
        path,
        "hsva",
        vessel="KVLCC2, INSEAN model 2487 (HSVA CPMC, SIMMAN 2008)",
        L=7.0,
        scale="model",
        title=lines[2].strip(),
        frame="earth-fixed x0, y0 (y to starboard)",
    )
    data, n_empty = _parse_table(lines[4:], None, 12, path, 5, say)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, range(11), meta)
    t, data = _repair_time(data[:, 0], data, meta)
    deg = np.pi / 180.0
    r = data[:, 6] * deg
    delta = -data[:, 8] * deg
    _check_units(
        t,
        data[:, 3] * deg,
        r,
        delta,
        meta,
        names={"psi": "psi (column 4)", "r": "r (column 7)", "delta": "delta (column 9)"},
    )
    psi = _repair_heading(t, data[:, 3] * deg, r, meta)
    u, v = _body_velocities(data[:, 4], data[:, 5], psi)
    meta["conversions"] += [
        "psi, r, delta deg -> rad",
        "delta negated (report: positive = steering to port side)",
        "earth-fixed dx0/dt, dy0/dt rotated into body u, v",
        "rpm = 60 * n [rps]",
        "thrust [N] from column 11 (total propeller thrust, model scale)",
    ]
    meta["r_source"] = "measured"
    _rudder_offset(t, delta, meta)
    _flag_irregular(t, meta)
    return Record(
        time=t,
        delta=delta,
        psi=psi,
        r=r,
        x=data[:, 1],
        y=data[:, 2],
        u=u,
        v=v,
        U=np.hypot(data[:, 4], data[:, 5]),
        rpm=60.0 * data[:, 9],
        thrust=data[:, 10],
        meta=meta,
    )


_ESSO_COLS = [
    "t [s]",
    "x_position_mid [m]",
    "u_velo [m/s]",
    "y_position_mid [m]",
    "vm_velo [m/s]",
    "psi_hat [rad]",
    "r_angvelo [rad/s]",
    "n_prop [rps]",
    "delta_rudder [rad]",
]
_ESSO_WIND_COLS = ["wind_velo_relative_mid [m/s]", "wind_dir_relative_mid [rad]"]


def _load_esso(path: Path, say: Callable[[str], None] = _silent) -> Record:
    lines = _read_lines(path)
    cols = _columns(lines[0], ",")
    ix = _require(path, "esso_osaka", cols, _ESSO_COLS)
    meta = _base_meta(
        path,
        "esso_osaka",
        vessel="Esso Osaka VLCC model (Osaka Univ., Inukai pond)",
        L=3.0,
        scale="model",
        frame="pond frame O0-x0y0 (right-handed, z down); psi clockwise from x0",
        licence="CC BY-NC 4.0 (cite Wakita et al. 2022; Miyauchi et al. 2022)",
    )
    data, n_empty = _parse_table(lines[1:], ",", len(cols), path, 2, say)
    _drop_empty(n_empty, meta)
    has_wind = all(c in ix for c in _ESSO_WIND_COLS)
    used = _ESSO_COLS + (_ESSO_WIND_COLS if has_wind else [])
    _drop_nan_rows(data, [ix[c] for c in used], meta)
    t, data = _repair_time(data[:, ix["t [s]"]], data, meta)
    r = data[:, ix["r_angvelo [rad/s]"]]
    delta = data[:, ix["delta_rudder [rad]"]]
    _check_units(
        t,
        data[:, ix["psi_hat [rad]"]],
        r,
        delta,
        meta,
        names={
            "time": "t [s]",
            "psi": "psi_hat [rad]",
            "r": "r_angvelo [rad/s]",
            "delta": "delta_rudder [rad]",
        },
    )
    psi = _repair_heading(t, data[:, ix["psi_hat [rad]"]], r, meta)
    n_prop = data[:, ix["n_prop [rps]"]]
    u, v = data[:, ix["u_velo [m/s]"]], data[:, ix["vm_velo [m/s]"]]
    meta["conversions"] += ["none for delta (MMG: positive = starboard turn)", "rpm = 60 * n"]
    meta["r_source"] = "measured"
    wind_speed = wind_angle = None
    if has_wind:
        wind_speed = data[:, ix["wind_velo_relative_mid [m/s]"]]
        wind_angle = wrap_angle(data[:, ix["wind_dir_relative_mid [rad]"]])
        meta["conversions"].append(
            "wind_speed = wind_velo_relative_mid; wind_angle = wind_dir_relative_mid wrapped from"
            " [0, 2 pi) to (-pi, pi]: the source angle is already the apparent wind direction"
            " the wind comes FROM, clockwise from the bow (verified: apparent wind rebuilt from"
            " wind_velo_true / wind_dir_true (from, clockwise from x0) minus the ship velocity"
            " u, v rotated by psi matches within 0.04 deg RMS and 0.001 m/s RMS)"
        )
        meta["notes"].append(
            "real wind of the order of the ship speed or larger; the apparent (relative) wind at"
            " midship is loaded as wind_speed, wind_angle (true wind not loaded)"
        )
    else:
        meta["notes"].append(
            "real wind of the order of the ship speed (no apparent-wind columns in this file)"
        )
    kind = path.parent.name
    if kind in ("zigzag", "turning") or path.name.startswith(("zigzag", "turn")):
        active = np.flatnonzero(np.abs(delta) > math.radians(10.0))
        running = np.flatnonzero(n_prop > 0)
        if active.size and running.size and running[-1] > active[0]:
            meta["manoeuvre_start_s"] = float(t[active[0]])
            meta["manoeuvre_end_s"] = float(t[running[-1]])
            meta["notes"].append(
                "starts from rest with manual corrections and ends coasting: cut to "
                "[manoeuvre_start_s, manoeuvre_end_s] (first |delta| > 10 deg .. last n > 0) "
                "before fitting"
            )
    _flag_irregular(t, meta)
    return Record(
        time=t,
        delta=delta,
        psi=psi,
        r=r,
        x=data[:, ix["x_position_mid [m]"]],
        y=data[:, ix["y_position_mid [m]"]],
        u=u,
        v=v,
        U=np.hypot(u, v),
        rpm=60.0 * n_prop,
        wind_speed=wind_speed,
        wind_angle=wind_angle,
        meta=meta,
    )


def _latlon_to_ne(lat_deg: np.ndarray, lon_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """North/east [m] from the first fix on the WGS84 local tangent plane (flat earth)."""
    lat0 = math.radians(float(lat_deg[0]))
    s2 = math.sin(lat0) ** 2
    m_rad = _WGS84_A * (1.0 - _WGS84_E2) / (1.0 - _WGS84_E2 * s2) ** 1.5
    n_rad = _WGS84_A / math.sqrt(1.0 - _WGS84_E2 * s2)
    north = np.radians(lat_deg - lat_deg[0]) * m_rad
    east = np.radians(lon_deg - lon_deg[0]) * n_rad * math.cos(lat0)
    return north, east


def _load_usv(path: Path, say: Callable[[str], None] = _silent) -> Record:
    lines = _read_lines(path)
    cols = _columns(lines[0], ",")
    needed = ["time", "lon", "lat", "speed", "heading", "rudder"]
    ix = _require(path, "usv", cols, needed)
    meta = _base_meta(
        path,
        "usv",
        vessel="small twin-hull USV (Fuzhou field tests)",
        L=3.6,
        scale="full",
        frame="north/east [m] from the first GPS fix (WGS84 local tangent plane)",
    )
    data, n_empty = _parse_table(lines[1:], ",", len(cols), path, 2, say)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, [ix[c] for c in needed], meta)
    t, data = _repair_time(data[:, ix["time"]], data, meta)
    deg = np.pi / 180.0
    delta = data[:, ix["rudder"]] * deg
    x, y = _latlon_to_ne(data[:, ix["lat"]], data[:, ix["lon"]])
    speed = data[:, ix["speed"]] * _KNOT
    _check_units(
        t,
        data[:, ix["heading"]] * deg,
        None,
        delta,
        meta,
        names={"psi": "heading", "delta": "rudder"},
    )
    psi = _repair_heading(t, data[:, ix["heading"]] * deg, None, meta)
    _flag_irregular(t, meta)
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


def _load_gunnerus(path: Path, say: Callable[[str], None] = _silent) -> Record:
    lines = _read_lines(path)
    cols = _columns(lines[0], ",")
    needed = ["tvec", "N", "E", "psi", "u", "v", "r", "Azi", "RPM"]
    ix = _require(path, "gunnerus", cols, needed)
    meta = _base_meta(
        path,
        "gunnerus",
        vessel="R/V Gunnerus (NTNU), sea trials 27 Oct 2022",
        L=33.9,
        scale="full",
        frame="north/east [m] (flat earth at 63.47 N, 10.54 E)",
    )
    data, n_empty = _parse_table(lines[1:], ",", len(cols), path, 2, say)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, [ix[c] for c in needed], meta)
    t, data = _repair_time(data[:, ix["tvec"]], data, meta)
    deg = np.pi / 180.0
    r = data[:, ix["r"]] * deg
    azimuth = data[:, ix["Azi"]] * deg
    u = data[:, ix["u"]] * _GUNNERUS_SPEED_FIX
    v = data[:, ix["v"]] * _GUNNERUS_SPEED_FIX
    _check_units(
        t,
        data[:, ix["psi"]] * deg,
        r,
        -azimuth,
        meta,
        names={"time": "tvec", "delta": "Azi"},
    )
    psi = _repair_heading(t, data[:, ix["psi"]] * deg, r, meta)
    _warn(
        meta,
        f"u, v multiplied by {_GUNNERUS_SPEED_FIX:.5f}: the origin converted knots with "
        "1/1.9834 instead of 1/1.943844",
    )
    meta["conversions"] += [
        "psi, r, Azi deg -> rad",
        "delta = -azimuth (both pods steer together; positive azimuth turns to port)",
        "x = N, y = E",
    ]
    meta["r_source"] = "measured"
    meta["notes"] += [
        "Azi and RPM are orders (commands) of the port azimuth / starboard rpm: the pods lag",
        "u, v are ground speeds (include current); v about +0.2 m/s on straight runs",
        "r has a bias of about -0.03 deg/s; turn rate is asymmetric (port/starboard)",
    ]
    _flag_irregular(t, meta)
    return Record(
        time=t,
        delta=-azimuth,
        psi=psi,
        r=r,
        x=data[:, ix["N"]],
        y=data[:, ix["E"]],
        u=u,
        v=v,
        U=np.hypot(u, v),
        azimuth=azimuth,
        rpm=data[:, ix["RPM"]],
        meta=meta,
    )


def _load_canonical(path: Path, say: Callable[[str], None] = _silent) -> Record:
    lines = _read_lines(path)
    meta: dict[str, Any] = {}
    k = 0
    meta_line: dict[str, int] = {}
    while k < len(lines) and lines[k].startswith("#"):
        body = lines[k][1:].strip()
        if lines[k] != _CANONICAL_MAGIC and ":" in body:
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
            expected = _meta_expected(key, parsed)
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
    cols = _columns(lines[k], ",")
    required_cols = ["time_s", "delta_rad", "psi_rad", "r_rad_s"]
    _require(path, "canonical", cols, required_cols)
    unknown = [c for c in cols if c not in _CANONICAL_COLUMNS]
    if unknown:
        raise ValueError(
            f"{path.name}: unknown canonical column(s) {unknown}; expected a subset of "
            f"{list(_CANONICAL_COLUMNS)}"
        )
    data, n_empty = _parse_table(lines[k + 1 :], ",", len(cols), path, k + 2, say)
    named = "file" in meta
    meta.setdefault("file", path.name)  # for the warnings; removed again if the file had none
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, range(len(cols)), meta)
    t, data = _repair_time(data[:, cols.index("time_s")], data, meta)
    chans = {_CANONICAL_COLUMNS[c]: data[:, j] for j, c in enumerate(cols)}
    chans["time"] = t
    _check_units(
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
        chans["psi"] = psi[0] + np.concatenate(([0.0], np.cumsum(_ssa(np.diff(psi)))))
        _warn(meta, "psi was wrapped (jumps > pi); unwrapped to a continuous heading")
    for name in _ANGLE_CHANNELS:
        angle = chans.get(name)
        if angle is not None and np.any((angle <= -np.pi) | (angle > np.pi)):
            chans[name] = wrap_angle(angle)
            _warn(meta, f"{name} outside (-pi, pi]; wrapped to (-pi, pi]")
    if meta.get("irregular_sampling") is not True:
        _flag_irregular(t, meta)
    if not named:
        del meta["file"]
    return Record(**chans, meta=meta)


def _load_table(path: Path, say: Callable[[str], None] = _silent, **kw: Any) -> Record:
    from shipgym.sysid.table import load_table

    return load_table(path, say, **kw)


def _load_nmea(path: Path, say: Callable[[str], None] = _silent, **kw: Any) -> Record:
    from shipgym.sysid.nmea import load_nmea

    return load_nmea(path, say, **kw)


_LOADERS: dict[str, Callable[..., Record]] = {
    "sspa": _load_sspa,
    "marin": _load_marin,
    "hsva": _load_hsva,
    "esso_osaka": _load_esso,
    "usv": _load_usv,
    "gunnerus": _load_gunnerus,
    "canonical": _load_canonical,
    "table": _load_table,
    "nmea": _load_nmea,
}


def detect_format(path: str | Path) -> str:
    """Guess the format of a measured-data file by header sniffing, then by its name.

    Raises
    ------
    ValueError
        If the format cannot be recognised; the message lists :data:`FORMATS`.
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            head = fh.read(4096).removeprefix(_UTF8_BOM).decode("cp1252", errors="replace")
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc}") from exc
    first = head.splitlines()[0] if head.strip() else ""
    if first.startswith("# shipgym canonical") or first.startswith("time_s,"):
        return "canonical"
    if first.replace(" ", "").startswith("time;delta;"):
        return "sspa"
    if first.startswith("MARIN"):
        return "marin"
    if first.strip().startswith("HSVA"):
        return "hsva"
    if first.startswith("t [s],") and "psi_hat" in first:
        return "esso_osaka"
    cols = [c.strip() for c in first.split(",")]
    if {"lon", "lat", "heading", "rudder"} <= set(cols):
        return "usv"
    if {"tvec", "Azi", "RPM"} <= set(cols):
        return "gunnerus"
    name, parent = path.name.lower(), path.parent.name.lower()
    by_name = [
        ("marin_free", "marin"),
        ("hsva_", "hsva"),
        ("rvg_", "gunnerus"),
        ("example_zigzag", "sspa"),
    ]
    for key, fmt in by_name:
        if name.startswith(key):
            return fmt
    by_folder = {
        "sspa_blog_zigzag": "sspa",
        "marin_kvlcc2": "marin",
        "hsva_kvlcc2": "hsva",
        "usv_field": "usv",
        "gunnerus_seatrials": "gunnerus",
    }
    if parent in by_folder:
        return by_folder[parent]
    if path.parent.parent.name.lower() == "esso_osaka_frt":
        return "esso_osaka"
    from shipgym.sysid.nmea import looks_like_nmea

    if looks_like_nmea(head):
        return "nmea"
    if _looks_like_table(head):
        return "table"
    reason = "the file is empty" if not first else f"first line {first[:80]!r}"
    raise ValueError(
        f"cannot detect the format of {path.name} ({reason}); accepted formats: "
        f"{', '.join(FORMATS)} (pass format=...)"
    )


def _looks_like_table(head: str) -> bool:
    """A header and a data row that split into the same two or more fields."""
    lines = [ln for ln in head.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if len(lines) < 2:
        return False
    for sep in (",", ";", "\t", None):
        n = len(lines[0].split(sep))
        if n >= 2 and len(lines[1].split(sep)) == n:
            return True
    return False


def progress_printer(progress: ProgressArg) -> Callable[[str], None]:
    """A one-line printer from ``progress``: a callable, a text file, True (stderr), or
    silence (False or None)."""
    if progress is True:
        progress = sys.stderr
    if progress is None or progress is False:
        return _silent
    if callable(progress):
        return progress
    stream = progress

    def say(msg: str) -> None:
        print(msg, file=stream, flush=True)

    return say


def _progress_printer(path: Path, progress: ProgressArg) -> Callable[[str], None]:
    """:func:`progress_printer`, where None means stderr for files above
    :data:`PROGRESS_FILE_BYTES` and silence for smaller ones."""
    if progress is None:
        try:
            progress = path.stat().st_size > PROGRESS_FILE_BYTES
        except OSError:
            progress = False
    return progress_printer(progress)


def _load_with_progress(path: Path, format: str, progress: ProgressArg = None, **kw: Any) -> Record:
    """Run the loader of ``format`` with progress lines and the large-record warning."""
    say = _progress_printer(path, progress)
    t0 = time.perf_counter()
    size = path.stat().st_size
    if say is not _silent:
        say(f"loading {path.name} ({size / 1e6:.1f} MB, format {format}) ...")
    record = _LOADERS[format](path, say, **kw)
    if record.n > LARGE_RECORD_SAMPLES:
        warnings.warn(
            f"{path.name}: large record of {record.n:,} samples ({size / 1e6:.0f} MB, "
            f"{record.duration:g} s at dt {record.dt:g} s; more than {LARGE_RECORD_SAMPLES:,}): "
            "loading needs about 0.4 kB of memory per sample and each identification fit "
            "replays every sample; cut it (Record.slice) or resample it (Record.resample) to "
            "the manoeuvres of interest",
            SysidDataWarning,
            stacklevel=3,
        )
    if say is not _silent:
        say(f"loaded {path.name}: {record.n:,} samples in {time.perf_counter() - t0:.1f} s")
    return record


def load(
    path: str | Path,
    format: str | None = None,
    *,
    progress: ProgressArg = None,
    columns: str | Mapping[str, str] | None = None,
    max_gap_s: float | None = None,
) -> Record:
    """Load one measured-data file into a canonical :class:`Record`.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.
    format : str, optional
        One of :data:`FORMATS`; detected from the header (and the file/folder name) when None.
    progress : callable, file, bool or None
        Where one-line progress messages go while loading (a callable taking the line, a text
        file, True for stderr, False for none). None (default): stderr for files larger than
        :data:`PROGRESS_FILE_BYTES`, nothing for smaller ones.
    columns : str or mapping, optional
        A column map for a ship's own table (format ``table``, implied):
        ``"time=t,delta=-rudder:deg,psi=hdg:deg,r=rot:deg/min,U=sog:kn"``
        (:func:`shipgym.sysid.table.parse_columns`).
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
        files, probable unit errors (see the module docstring), and data oddities that cannot
        be repaired safely.

    Warns
    -----
    SysidDataWarning
        For every repair, for borderline unit checks, and for a record of more than
        :data:`LARGE_RECORD_SAMPLES` samples.
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
    if format not in _LOADERS:
        raise ValueError(f"unknown format {format!r}; accepted formats: {', '.join(FORMATS)}")
    kw: dict[str, Any] = {}
    if max_gap_s is not None:
        if format not in ("table", "nmea"):
            raise ValueError(f"max_gap_s applies to the formats table and nmea, not {format!r}")
        kw["max_gap_s"] = max_gap_s
    if columns is not None:
        kw["columns"] = columns
    return _load_with_progress(path, format, progress, **kw)


MEASURED_DATA_ENV = "SHIPGYM_MEASURED_DATA"
"""Environment variable naming the ``measured`` folder (a copy of ``../shared/data/measured``)."""


def measured_root() -> Path:
    """The measured-data folder: ``$SHIPGYM_MEASURED_DATA`` when set, else
    ``../shared/data/measured`` beside the checkout (where the project's sources keep it)."""
    env = os.environ.get(MEASURED_DATA_ENV)
    if env:
        return Path(env).expanduser()
    return Path(__file__).resolve().parents[3] / "shared" / "data" / "measured"


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

    ``root`` is the ``measured`` folder (``../shared/data/measured`` from the repo root).

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

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

Canonical CSV (:meth:`Record.to_csv`, :meth:`Record.from_csv`, ``load(..., "canonical")``)::

    # shipgym canonical record v1
    # source: "marin"
    # repairs: ["time stamps quantised ..."]
    time_s,delta_rad,psi_rad,r_rad_s,x_m,y_m,u_m_s,v_m_s,U_m_s,rpm
    0,0.0142...,...

Meta lines are ``# key: <JSON value>``; only present channels are written (columns
``time_s, delta_rad, psi_rad, r_rad_s`` required; ``x_m, y_m, u_m_s, v_m_s, U_m_s, azimuth_rad,
rpm, thrust_N, wind_speed_m_s, wind_angle_rad`` optional); numbers have 17 significant digits so
the round trip is exact. A canonical file is trusted to be processed: on reading only the time
(duplicates, quantisation), empty rows, irregular sampling (unless already flagged), a wrapped
psi and a wind angle outside (-pi, pi] (re-wrapped) are checked.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.signal import savgol_filter

__all__ = [
    "FORMATS",
    "HEADING_GLITCH_TOL",
    "HEADING_SPIKE_TOL",
    "Record",
    "SysidDataWarning",
    "derive_yaw_rate",
    "detect_format",
    "load",
    "load_all",
    "wrap_angle",
]

FORMATS: tuple[str, ...] = ("sspa", "marin", "hsva", "esso_osaka", "usv", "gunnerus", "canonical")
"""Accepted values of ``format`` in :func:`load`."""

HEADING_GLITCH_TOL: float = math.radians(4.0)
"""Smallest tolerance [rad] for the disagreement between one heading increment and the
integral of r; the tolerance used is ``max(HEADING_GLITCH_TOL, 10 sigma)`` with sigma the robust
(MAD) spread of that disagreement over the record."""

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
        lines.extend(",".join(format(float(v), ".17g") for v in row) for row in data)
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        return path

    @classmethod
    def from_csv(cls, path: str | Path) -> Record:
        """Read a canonical CSV written by :meth:`to_csv` (see :func:`load`)."""
        return _load_canonical(Path(path))


# ----------------------------------------------------------------------------------------------
# generic helpers
# ----------------------------------------------------------------------------------------------
def _parse_table(
    rows: Sequence[str], sep: str | None, ncol: int, path: Path, first_line: int
) -> tuple[np.ndarray, int]:
    """Parse text rows into a float array; empty fields -> NaN. Returns (data, n_empty_rows)."""
    out: list[list[float]] = []
    n_empty = 0
    for k, line in enumerate(rows):
        fields = line.split(sep) if sep is not None else line.split()
        if sep is not None and len(fields) == 1 and not fields[0].strip():
            fields = [""] * ncol
        if all(not f.strip() for f in fields):
            n_empty += 1
            continue
        if len(fields) != ncol:
            raise ValueError(
                f"{path.name} line {first_line + k}: expected {ncol} fields, got {len(fields)}"
            )
        try:
            out.append([float(f) if f.strip() else math.nan for f in fields])
        except ValueError as exc:
            raise ValueError(
                f"{path.name} line {first_line + k}: non-numeric field ({exc})"
            ) from exc
    if not out:
        raise ValueError(f"{path.name}: no data rows")
    return np.asarray(out, dtype=np.float64), n_empty


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


def _read_lines(path: Path, encoding: str = "utf-8") -> list[str]:
    try:
        text = path.read_text(encoding=encoding)
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path.name}: cannot decode as {encoding}: {exc}") from exc
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
def _load_sspa(path: Path) -> Record:
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
    data, n_empty = _parse_table(lines[1:], ";", len(cols), path, 2)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, [ix[c] for c in needed], meta)
    t, data = _repair_time(data[:, ix["time"]], data, meta)
    delta = -data[:, ix["delta"]]
    meta["conversions"].append("delta negated (source: positive rudder gives a port turn)")
    psi = _repair_heading(t, data[:, ix["psi"]], data[:, ix["r"]], meta)
    window = 0.3
    r = derive_yaw_rate(t, psi, window)
    meta["r_source"] = f"derived from psi (local quadratic / Savitzky-Golay, {window} s window)"
    _warn(
        meta,
        "source r is numpy.gradient(psi), not measured; replaced by a Savitzky-Golay "
        f"derivative of psi ({window} s window)",
    )
    x, y = data[:, ix["x0"]], data[:, ix["y0"]]
    speed = np.hypot(derive_yaw_rate(t, x, window), derive_yaw_rate(t, y, window))
    meta["notes"].append("U derived from x0, y0 (Savitzky-Golay derivative, 0.3 s window)")
    meta["notes"].append("rudder quantised in steps of about 0.02 deg")
    _rudder_offset(t, delta, meta)
    _flag_irregular(t, meta)
    return Record(time=t, delta=delta, psi=psi, r=r, x=x, y=y, U=speed, meta=meta)


def _load_marin(path: Path) -> Record:
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
    data, n_empty = _parse_table(lines[3:], "\t", 11, path, 4)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, range(11), meta)
    t, data = _repair_time(data[:, 0], data, meta, known_dt=_MARIN_DT)
    deg = np.pi / 180.0
    r = data[:, 8] * deg
    psi = _repair_heading(t, data[:, 4] * deg, r, meta)
    delta = -data[:, 9] * deg
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


def _load_hsva(path: Path) -> Record:
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
    data, n_empty = _parse_table(lines[4:], None, 12, path, 5)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, range(11), meta)
    t, data = _repair_time(data[:, 0], data, meta)
    deg = np.pi / 180.0
    r = data[:, 6] * deg
    psi = _repair_heading(t, data[:, 3] * deg, r, meta)
    delta = -data[:, 8] * deg
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


def _load_esso(path: Path) -> Record:
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
    data, n_empty = _parse_table(lines[1:], ",", len(cols), path, 2)
    _drop_empty(n_empty, meta)
    has_wind = all(c in ix for c in _ESSO_WIND_COLS)
    used = _ESSO_COLS + (_ESSO_WIND_COLS if has_wind else [])
    _drop_nan_rows(data, [ix[c] for c in used], meta)
    t, data = _repair_time(data[:, ix["t [s]"]], data, meta)
    r = data[:, ix["r_angvelo [rad/s]"]]
    psi = _repair_heading(t, data[:, ix["psi_hat [rad]"]], r, meta)
    delta = data[:, ix["delta_rudder [rad]"]]
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


def _load_usv(path: Path) -> Record:
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
    data, n_empty = _parse_table(lines[1:], ",", len(cols), path, 2)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, [ix[c] for c in needed], meta)
    t, data = _repair_time(data[:, ix["time"]], data, meta)
    deg = np.pi / 180.0
    psi = _repair_heading(t, data[:, ix["heading"]] * deg, None, meta)
    delta = data[:, ix["rudder"]] * deg
    x, y = _latlon_to_ne(data[:, ix["lat"]], data[:, ix["lon"]])
    speed = data[:, ix["speed"]] * _KNOT
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


def _load_gunnerus(path: Path) -> Record:
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
    data, n_empty = _parse_table(lines[1:], ",", len(cols), path, 2)
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, [ix[c] for c in needed], meta)
    t, data = _repair_time(data[:, ix["tvec"]], data, meta)
    deg = np.pi / 180.0
    r = data[:, ix["r"]] * deg
    psi = _repair_heading(t, data[:, ix["psi"]] * deg, r, meta)
    azimuth = data[:, ix["Azi"]] * deg
    u = data[:, ix["u"]] * _GUNNERUS_SPEED_FIX
    v = data[:, ix["v"]] * _GUNNERUS_SPEED_FIX
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


def _load_canonical(path: Path) -> Record:
    lines = _read_lines(path)
    meta: dict[str, Any] = {}
    k = 0
    while k < len(lines) and lines[k].startswith("#"):
        body = lines[k][1:].strip()
        if lines[k] != _CANONICAL_MAGIC and ":" in body:
            key, _, value = body.partition(":")
            try:
                meta[key.strip()] = json.loads(value)
            except json.JSONDecodeError as exc:
                raise ValueError(
                    f"{path.name} line {k + 1}: meta value of {key.strip()!r} is not JSON ({exc})"
                ) from exc
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
    data, n_empty = _parse_table(lines[k + 1 :], ",", len(cols), path, k + 2)
    named = "file" in meta
    meta.setdefault("file", path.name)  # for the warnings; removed again if the file had none
    _drop_empty(n_empty, meta)
    _drop_nan_rows(data, range(len(cols)), meta)
    t, data = _repair_time(data[:, cols.index("time_s")], data, meta)
    chans = {_CANONICAL_COLUMNS[c]: data[:, j] for j, c in enumerate(cols)}
    chans["time"] = t
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


_LOADERS = {
    "sspa": _load_sspa,
    "marin": _load_marin,
    "hsva": _load_hsva,
    "esso_osaka": _load_esso,
    "usv": _load_usv,
    "gunnerus": _load_gunnerus,
    "canonical": _load_canonical,
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
            head = fh.read(4096).decode("cp1252", errors="replace")
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
    reason = "the file is empty" if not first else f"first line {first[:80]!r}"
    raise ValueError(
        f"cannot detect the format of {path.name} ({reason}); accepted formats: "
        f"{', '.join(FORMATS)} (pass format=...)"
    )


def load(path: str | Path, format: str | None = None) -> Record:
    """Load one measured-data file into a canonical :class:`Record`.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.
    format : str, optional
        One of :data:`FORMATS`; detected from the header (and the file/folder name) when None.

    Returns
    -------
    Record
        One record per file (the long Gunnerus sea-trial file is one record).

    Raises
    ------
    ValueError
        Unknown format, a file that does not match the (given) format, empty or malformed
        files, and data oddities that cannot be repaired safely.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path} is not a file")
    if format is None:
        format = detect_format(path)
    if format not in _LOADERS:
        raise ValueError(f"unknown format {format!r}; accepted formats: {', '.join(FORMATS)}")
    return _LOADERS[format](path)


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

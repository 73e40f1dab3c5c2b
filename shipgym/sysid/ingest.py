"""What every loader of measured data shares: text, numbers, units, unit checks and repairs.

The loaders of :mod:`shipgym.sysid.io` (one module per source) and the record pipeline of
:mod:`shipgym.sysid.record` are built from these steps, so that every source is read, checked
and repaired by the same rules.

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
of :func:`shipgym.sysid.io.load`), and a record of more than :data:`LARGE_RECORD_SAMPLES`
samples loads with a :class:`SysidDataWarning` that suggests cutting or resampling it.
(Measured on a canonical file of 2 million rows and 7 channels, 239 MB: about 45 s of parsing
and 0.8 GB peak memory on a busy machine; the per-row Python loop this replaces was about 7
times slower.)
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, Protocol, TextIO, TypeVar

import numpy as np
from scipy.signal import savgol_filter

from shipgym.sysid.units import KNOT

__all__ = [
    "HEADING_GLITCH_TOL",
    "HEADING_SPIKE_TOL",
    "LARGE_RECORD_SAMPLES",
    "PROGRESS_FILE_BYTES",
    "UTF8_BOM",
    "ProgressArg",
    "SysidDataWarning",
    "base_meta",
    "body_velocities",
    "check_units",
    "derive_yaw_rate",
    "flag_irregular",
    "header_error",
    "latlon_to_ne",
    "load_with_progress",
    "measure_rudder_offset",
    "parse_table",
    "progress_printer",
    "read_lines",
    "repair_heading",
    "repair_time",
    "report_empty_rows",
    "require_columns",
    "require_complete_rows",
    "silent",
    "split_header",
    "ssa",
    "warn_repair",
    "wrap_angle",
]


HEADING_GLITCH_TOL: float = math.radians(4.0)
"""Smallest tolerance [rad] for the disagreement between one heading increment and the
integral of r; the tolerance used is ``max(HEADING_GLITCH_TOL, 10 sigma)`` with sigma the robust
(MAD) spread of that disagreement over the record."""

LARGE_RECORD_SAMPLES: int = 500_000
"""A record with more samples than this (e.g. 14 h at 10 Hz) is loaded with a
:class:`SysidDataWarning` (loading takes about 25 s per million rows and 0.4 kB of memory per
sample; every fit of the identification replays every sample)."""

PROGRESS_FILE_BYTES: int = 32_000_000
"""By default :func:`shipgym.sysid.io.load` prints progress lines to stderr for files larger
than this (about 200 000 rows of a canonical CSV with every channel)."""

ProgressArg = Callable[[str], None] | TextIO | bool | None
"""Where :func:`shipgym.sysid.io.load` sends its progress lines (see its ``progress``
parameter)."""

HEADING_SPIKE_TOL: float = math.radians(15.0)
"""Without a measured r: a heading jump [rad] larger than this that returns at the next sample
is a spike."""

_WGS84_A = 6378137.0
_WGS84_E2 = 6.69437999014e-3


class _Sized(Protocol):
    """What :func:`load_with_progress` reads of a loaded record."""

    @property
    def n(self) -> int: ...

    @property
    def duration(self) -> float: ...

    @property
    def dt(self) -> float: ...


_Loaded = TypeVar("_Loaded", bound=_Sized)


class SysidDataWarning(UserWarning):
    """A data oddity in a measured record was repaired (the repair is listed in ``meta``)."""


def warn_repair(meta: dict[str, Any], message: str) -> None:
    """Record a repair in ``meta["repairs"]`` and emit a :class:`SysidDataWarning`."""
    meta.setdefault("repairs", []).append(message)
    where = meta.get("file", "")
    warnings.warn(f"{where}: {message}" if where else message, SysidDataWarning, stacklevel=3)


def ssa(a: np.ndarray) -> np.ndarray:
    """Smallest signed angle, as ``shipgym.models.ssa``: wrap to [-pi, pi)."""
    return np.mod(a + np.pi, 2.0 * np.pi) - np.pi


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Wrap to (-pi, pi] (the wind-angle convention); values already inside are kept bit for bit."""
    a = np.asarray(a, dtype=np.float64)
    outside = (a <= -np.pi) | (a > np.pi)
    wrapped = np.pi - np.mod(np.pi - a, 2.0 * np.pi)
    wrapped = np.where(wrapped <= -np.pi, wrapped + 2.0 * np.pi, wrapped)  # mod rounding to 2 pi
    return np.where(outside, wrapped, a)


# ----------------------------------------------------------------------------------------------
# text and numbers
# ----------------------------------------------------------------------------------------------
def silent(_msg: str) -> None:
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


def parse_table(
    rows: Sequence[str],
    sep: str | None,
    ncol: int,
    path: Path,
    first_line: int,
    say: Callable[[str], None] = silent,
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


def report_empty_rows(n_empty: int, meta: dict[str, Any]) -> None:
    """Report ``n_empty`` all-empty rows dropped by :func:`parse_table` (a repair)."""
    if n_empty:
        warn_repair(meta, f"dropped {n_empty} all-empty rows")


def require_complete_rows(
    data: np.ndarray, cols: Sequence[int], meta: dict[str, Any]
) -> np.ndarray:
    """Refuse rows that miss a used value (partial rows are not guessed); returns ``data``."""
    bad = ~np.all(np.isfinite(data[:, list(cols)]), axis=1)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{meta.get('file', '')}: {int(bad.sum())} rows miss a value (first at data row {i});"
            " expected every used column to be numeric"
        )
    return data


def repair_time(
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
            warn_repair(
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
        warn_repair(meta, f"dropped {int(dup.sum())} exact duplicate rows")
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
        warn_repair(
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


def flag_irregular(t: np.ndarray, meta: dict[str, Any]) -> None:
    """Flag ``meta["irregular_sampling"]`` (and warn) when the time step varies by more than 1 %."""
    dt = np.diff(t)
    med = float(np.median(dt))
    if float(np.max(dt) - np.min(dt)) > 0.01 * med:
        meta["irregular_sampling"] = True
        warn_repair(
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
    (KNOT, "{U} looks like knots; expected m/s"),
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


def check_units(
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


def repair_heading(
    t: np.ndarray, psi_raw: np.ndarray, r: np.ndarray | None, meta: dict[str, Any]
) -> np.ndarray:
    """Unwrap the heading and repair glitches (module docstring). Returns continuous psi."""
    d = ssa(np.diff(psi_raw))
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
            warn_repair(
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
        warn_repair(
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


def measure_rudder_offset(t: np.ndarray, delta: np.ndarray, meta: dict[str, Any]) -> None:
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
        warn_repair(
            meta,
            f"neutral rudder is {math.degrees(offset):+.2f} deg before the first rudder order "
            f"(t < {t[i]:g} s); delta kept as measured, offset in meta['rudder_offset_rad']",
        )


def body_velocities(
    dx: np.ndarray, dy: np.ndarray, psi: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Rotate earth-fixed velocities into body axes (u forward, v starboard)."""
    c, s = np.cos(psi), np.sin(psi)
    return dx * c + dy * s, -dx * s + dy * c


def tank_channels(
    t: np.ndarray,
    data: np.ndarray,
    meta: dict[str, Any],
    columns: Mapping[str, int],
    rudder_sign: str,
) -> dict[str, np.ndarray]:
    """The motion channels of a tank record in degrees with earth-fixed positions and
    velocities (the SIMMAN 2008 HSVA and MARIN files): heading, yaw rate and a port-positive
    rudder in degrees are converted, unit-checked (:func:`check_units`), the heading repaired
    (:func:`repair_heading`), the rudder negated to the project's convention and its neutral
    offset measured (:func:`measure_rudder_offset`), the velocities ``dx0/dt, dy0/dt`` rotated
    into body ``u, v`` and the time step checked (:func:`flag_irregular`); the conversions go
    to ``meta``.

    Parameters
    ----------
    t, data : numpy.ndarray
        Sample times [s] and the table's columns.
    meta : dict
        The record's meta (updated).
    columns : mapping
        Column of ``x``, ``y``, ``psi``, ``dx``, ``dy``, ``r`` and ``delta`` in ``data``.
    rudder_sign : str
        The source's words for its rudder sign (kept in the conversions).

    Returns
    -------
    dict
        ``time, delta, psi, r, x, y, u, v, U`` for :class:`~shipgym.sysid.record.Record`.
    """
    c = columns
    deg = math.pi / 180.0
    r = data[:, c["r"]] * deg
    delta = -data[:, c["delta"]] * deg
    names = {k: f"{k} (column {c[k] + 1})" for k in ("psi", "r", "delta")}
    check_units(t, data[:, c["psi"]] * deg, r, delta, meta, names=names)
    psi = repair_heading(t, data[:, c["psi"]] * deg, r, meta)
    dx, dy = data[:, c["dx"]], data[:, c["dy"]]
    u, v = body_velocities(dx, dy, psi)
    meta["conversions"] += [
        "psi, r, delta deg -> rad",
        f"delta negated ({rudder_sign})",
        "earth-fixed dx0/dt, dy0/dt rotated into body u, v",
    ]
    meta["r_source"] = "measured"
    measure_rudder_offset(t, delta, meta)
    flag_irregular(t, meta)
    return {"time": t, "delta": delta, "psi": psi, "r": r, "x": data[:, c["x"]],
            "y": data[:, c["y"]], "u": u, "v": v, "U": np.hypot(dx, dy)}  # fmt: skip


def base_meta(path: Path, source: str, **kw: Any) -> dict[str, Any]:
    """The meta every loader starts from: ``source``, ``file``, ``vessel``, ``L``, ``scale`` and
    empty ``conversions``, ``repairs``, ``notes`` (``kw`` added or overriding)."""
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


UTF8_BOM = b"\xef\xbb\xbf"


def read_lines(path: Path, encoding: str = "utf-8") -> list[str]:
    """The file's lines, a leading UTF-8 byte-order mark dropped (whatever ``encoding``)."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc}") from exc
    raw = raw.removeprefix(UTF8_BOM)
    try:
        text = raw.decode(encoding)
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path.name}: cannot decode as {encoding}: {exc}") from exc
    del raw
    lines = text.splitlines()
    if not any(line.strip() for line in lines):
        raise ValueError(f"{path.name}: the file is empty")
    return lines


def header_error(path: Path, fmt: str, expected: str, got: str) -> ValueError:
    """The error of a file whose header is not that of format ``fmt``."""
    return ValueError(
        f"{path.name} does not look like format {fmt!r}: expected {expected}, got {got[:120]!r}"
    )


def split_header(header: str, sep: str) -> list[str]:
    """Column names of a header line, blanks around them dropped."""
    return [c.strip() for c in header.split(sep)]


def require_columns(path: Path, fmt: str, cols: list[str], needed: Sequence[str]) -> dict[str, int]:
    """Column name -> index, refusing a column named twice or a missing ``needed`` column."""
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


def read_columns(
    path: Path,
    fmt: str,
    lines: list[str],
    sep: str,
    needed: Sequence[str],
    time_column: str,
    meta: dict[str, Any],
    say: Callable[[str], None],
    optional: Sequence[str] = (),
) -> tuple[np.ndarray, np.ndarray, dict[str, int]]:
    """The rows of a delimited file with a one-line header of column names: the ``needed``
    columns located (:func:`require_columns`), the rows parsed (:func:`parse_table`), rows
    incomplete in the ``needed`` columns, and in the ``optional`` ones when every one of them
    is present, dropped, and the time column repaired (:func:`repair_time`); what was done goes
    to ``meta``.

    Returns
    -------
    t, data, ix : numpy.ndarray, numpy.ndarray, dict
        Sample times [s], the rows that remain and column name -> index.
    """
    cols = split_header(lines[0], sep)
    ix = require_columns(path, fmt, cols, needed)
    data, n_empty = parse_table(lines[1:], sep, len(cols), path, 2, say)
    report_empty_rows(n_empty, meta)
    used = [*needed, *(optional if all(c in ix for c in optional) else ())]
    require_complete_rows(data, [ix[c] for c in used], meta)
    t, data = repair_time(data[:, ix[time_column]], data, meta)
    return t, data, ix


# ----------------------------------------------------------------------------------------------
# per-source loaders
def latlon_to_ne(lat_deg: np.ndarray, lon_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """North/east [m] from the first fix on the WGS84 local tangent plane (flat earth)."""
    lat0 = math.radians(float(lat_deg[0]))
    s2 = math.sin(lat0) ** 2
    m_rad = _WGS84_A * (1.0 - _WGS84_E2) / (1.0 - _WGS84_E2 * s2) ** 1.5
    n_rad = _WGS84_A / math.sqrt(1.0 - _WGS84_E2 * s2)
    north = np.radians(lat_deg - lat_deg[0]) * m_rad
    east = np.radians(lon_deg - lon_deg[0]) * n_rad * math.cos(lat0)
    return north, east


# ----------------------------------------------------------------------------------------------
# progress
# ----------------------------------------------------------------------------------------------
def progress_printer(progress: ProgressArg) -> Callable[[str], None]:
    """A one-line printer from ``progress``: a callable, a text file, True (stderr), or
    silence (False or None)."""
    if progress is True:
        progress = sys.stderr
    if progress is None or progress is False:
        return silent
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


def load_with_progress(
    loader: Callable[..., _Loaded],
    path: Path,
    format: str,
    progress: ProgressArg = None,
    **kw: Any,
) -> _Loaded:
    """``loader(path, say, **kw)`` with progress lines and the large-record warning.

    Parameters
    ----------
    loader : callable
        A loader of :mod:`shipgym.sysid.io`: ``(path, say, **options) -> Record``.
    path : pathlib.Path
        The file.
    format : str
        The format's name, for the progress lines.
    progress : callable, file, bool or None
        As in :func:`shipgym.sysid.io.load`: None prints to stderr for files larger than
        :data:`PROGRESS_FILE_BYTES` only.
    """
    say = _progress_printer(path, progress)
    t0 = time.perf_counter()
    size = path.stat().st_size
    if say is not silent:
        say(f"loading {path.name} ({size / 1e6:.1f} MB, format {format}) ...")
    record = loader(path, say, **kw)
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
    if say is not silent:
        say(f"loaded {path.name}: {record.n:,} samples in {time.perf_counter() - t0:.1f} s")
    return record

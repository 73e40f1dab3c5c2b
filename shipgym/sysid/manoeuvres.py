"""Manoeuvre-level validation of ship models against records with rpm and azimuth orders.

A record with the ORDERS of the propulsion (``rpm``) and of the pods (``azimuth``, raw pod sign:
positive turns the ship to port) -- the R/V Gunnerus sea trials -- is cut automatically into
manoeuvres, each summarised by a few quantities that a model must reproduce. The same
quantities are then computed from a model that replays the recorded orders
(:func:`simulate_manoeuvre`), tabulated (:func:`validation_table`, :func:`render_markdown`,
:func:`plot_validation`) and used for cross-validation by manoeuvre (:func:`folds`).

Holds
-----
The orders are cut into *holds* greedily, in time order: a hold grows sample by sample while
the range (max - min) of the azimuth order stays within :data:`AZ_BAND` and that of the rpm
order within :data:`RPM_BAND`. No filter is applied (the Gunnerus orders jitter by about
+-0.4 deg and +-1 rpm). A *straight hold* is instead a maximal run of ``|azimuth| <``
:data:`STRAIGHT_MAX_AZ` cut greedily by the rpm band only (a helmsman's small course
corrections stay inside one straight).

Manoeuvres
----------
All index spans are half-open ``[i0, i1)``; ``span`` includes the approach and the transient
(the samples to exclude from a fit), ``settled`` is the part the quantities are read from.
Speeds are ``U = hypot(u, v)`` (the speed along the path; on the Gunnerus it is the speed over
ground, and the +0.2 m/s sway offset changes it by less than 0.1 %); a missing ``v`` counts
as 0.

``straight``
    A straight hold of at least :data:`STRAIGHT_MIN_HOLD_S`. The settled part starts at least
    :data:`STRAIGHT_SETTLE_S` after the hold start, at the first sample where the
    :data:`SETTLE_SMOOTH_S` moving mean of ``U`` is within :data:`SETTLE_TOL` of the median
    ``U`` of the hold's last :data:`SETTLE_TAIL_S` (a slow drift with the current does not
    postpone it); it must last at least :data:`MIN_SETTLED_S`. Quantities: ``rpm`` and
    ``azimuth`` (mean orders), ``U`` (mean speed), ``duration`` (of the settled part [s]).
``turn``
    A hold of at least :data:`TURN_MIN_HOLD_S` with ``|azimuth| >=`` :data:`TURN_MIN_AZ`. The
    *execute* is the first sample of the azimuth ramp into the hold (walking back from the
    hold while the order has the hold's sign and ``|azimuth| >=`` :data:`STRAIGHT_MAX_AZ`);
    ``span`` starts :data:`TURN_APPROACH_S` before it. The settled part starts
    :data:`TURN_SETTLE_S` after the hold start, must last :data:`MIN_SETTLED_S`, and is cut to
    the largest whole number of 360 deg heading turns when it holds at least one (the ground
    speed of a full circle is free of the current's bias); otherwise it is used whole
    (``circles = 0``). Quantities: ``azimuth``, ``rpm`` (mean orders of the hold), ``r`` (mean,
    signed), ``U`` (mean), ``diameter = 2 U / |r|``, ``U_approach``, ``speed_ratio = U /
    U_approach``, ``circles``, ``duration``.

    ``U_approach`` is the straight speed at the turn's rpm, so that ``speed_ratio`` is the
    speed loss due to the azimuth alone. When the :data:`TURN_APPROACH_S` before the execute
    are a straight (``|azimuth| <`` :data:`STRAIGHT_MAX_AZ`, rpm within :data:`RPM_BAND`) at
    the turn's rpm (within :data:`TURN_RPM_MATCH`), it is their mean speed; otherwise (the
    Gunnerus entered its 20 and 30 deg turns while cutting the rpm) it is the mean ``U`` of the
    extracted straights of the rpm class nearest the turn's rpm (within
    :data:`STRAIGHT_CLASS_RPM` of the nearest), kept in ``Manoeuvre.reference``. Either speed
    is scaled by ``rpm_turn / rpm_straight`` (propeller law: thrust ~ n^2 and resistance ~ U^2
    give U ~ n; a few percent at most).
``zigzag``
    Holds of :data:`ZIGZAG_MIN_HOLD_S` to :data:`TURN_MIN_HOLD_S` (exclusive) with ``|azimuth|
    >=`` :data:`ZIGZAG_MIN_AZ` (same-sign holds closer than :data:`ZIGZAG_MAX_GAP_S` are
    merged unless an opposite order of at least :data:`ZIGZAG_MIN_AZ` lies between) form a
    zigzag when at least :data:`ZIGZAG_MIN_REVERSALS` consecutive ones reverse the sign, each
    following the previous within :data:`ZIGZAG_MAX_GAP_S` and with magnitudes within a factor
    :data:`ZIGZAG_MAGNITUDE_RATIO`. A *reversal* is the first sample at which the order has
    left the previous hold's sign (``events``). Its overshoot is the heading excursion beyond
    the heading at the reversal in the direction the ship was turning (``d``: the sign of
    ``delta = -azimuth`` of the previous hold): ``max(d (psi - psi_rev))`` over the samples
    from the reversal to the next reversal (the last one: to the end of the last hold), i.e.
    the heading extreme reached before the heading turns back. ``span`` starts
    :data:`ZIGZAG_LEAD_S` before the ramp into the first hold and ends with the last hold;
    ``settled`` starts at the first hold. Quantities: ``overshoots`` (list [rad]),
    ``overshoot_mean``, ``overshoot_max``, ``amplitude`` (mean ``|azimuth|`` of the holds),
    ``rpm``, ``n_reversals``, ``duration`` and ``delta_signs`` (the ``d`` of each reversal).

Model replay (:func:`simulate_manoeuvre`)
-----------------------------------------
The model gets the recorded orders over ``span`` from the measured state at ``span[0]``
(``x, y, psi, u, v, r``, each the median of :data:`X0_SAMPLES` samples centred there; nothing
is subtracted, not even the Gunnerus sway offset), then holds the settled part's mean orders
(a zigzag: its last orders) for ``hold_s`` more seconds (:data:`STRAIGHT_HOLD_S`,
:data:`TURN_HOLD_S`, 0 for zigzags). Its quantities are computed by the same code as the
measured ones, over the LAST ``settled`` duration of the simulation (so with ``hold_s = 0``
exactly over the measured settled samples). A turn's model ``U_approach`` is the model's mean
speed over the same approach samples or, when the measured one came from reference straights,
the model's speeds on those straights (replayed the same way), scaled alike. Zigzag overshoots
use the same reversal samples.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.sysid.data import Record

__all__ = [
    "AZ_BAND",
    "KINDS",
    "MIN_SETTLED_S",
    "RPM_BAND",
    "SETTLE_SMOOTH_S",
    "SETTLE_TAIL_S",
    "SETTLE_TOL",
    "STRAIGHT_CLASS_RPM",
    "STRAIGHT_HOLD_S",
    "STRAIGHT_MAX_AZ",
    "STRAIGHT_MIN_HOLD_S",
    "STRAIGHT_SETTLE_S",
    "TURN_APPROACH_S",
    "TURN_HOLD_S",
    "TURN_MIN_AZ",
    "TURN_MIN_HOLD_S",
    "TURN_RPM_MATCH",
    "TURN_SETTLE_S",
    "X0_SAMPLES",
    "ZIGZAG_LEAD_S",
    "ZIGZAG_MAGNITUDE_RATIO",
    "ZIGZAG_MAX_GAP_S",
    "ZIGZAG_MIN_AZ",
    "ZIGZAG_MIN_HOLD_S",
    "ZIGZAG_MIN_REVERSALS",
    "Manoeuvre",
    "Simulator",
    "extract_manoeuvres",
    "folds",
    "plot_validation",
    "render_markdown",
    "simulate_manoeuvre",
    "validation_table",
]

KINDS: tuple[str, ...] = ("straight", "turn", "zigzag")
"""Manoeuvre kinds, in the order of the tables."""

AZ_BAND: float = math.radians(2.0)
"""Largest range (max - min) of the azimuth order within one hold [rad]."""

RPM_BAND: float = 6.0
"""Largest range (max - min) of the rpm order within one hold [rpm]."""

STRAIGHT_MAX_AZ: float = math.radians(1.5)
"""A straight has ``|azimuth order|`` below this [rad]."""

STRAIGHT_MIN_HOLD_S: float = 60.0
"""Shortest straight hold [s]."""

STRAIGHT_SETTLE_S: float = 60.0
"""Least time skipped after the start of a straight hold before its settled part [s]."""

SETTLE_TOL: float = 0.015
"""Relative speed tolerance of a settled straight (to the speed at the end of the hold)."""

SETTLE_SMOOTH_S: float = 10.0
"""Moving-mean window of the speed for the settling test [s]."""

SETTLE_TAIL_S: float = 30.0
"""Tail of a straight hold whose median speed is the settled target [s]."""

MIN_SETTLED_S: float = 30.0
"""Shortest settled part of a straight [s]."""

TURN_MIN_AZ: float = math.radians(4.0)
"""A steady turn has ``|azimuth order|`` at least this [rad]."""

TURN_MIN_HOLD_S: float = 60.0
"""Shortest steady-turn hold [s] (shorter holds may belong to zigzags)."""

TURN_SETTLE_S: float = 60.0
"""Time skipped after the start of a turn hold (yaw and speed transient) [s]."""

TURN_APPROACH_S: float = 30.0
"""Approach window before a turn's execute: start of the replay and of ``U_approach`` [s]."""

TURN_RPM_MATCH: float = 6.0
"""The approach gives ``U_approach`` only if its rpm is within this of the turn's [rpm]."""

STRAIGHT_CLASS_RPM: float = 5.0
"""Straights within this of the rpm nearest a turn's rpm form its reference class [rpm]."""

ZIGZAG_MIN_AZ: float = math.radians(4.0)
"""Smallest ``|azimuth order|`` of a zigzag hold [rad]."""

ZIGZAG_MIN_HOLD_S: float = 5.0
"""Shortest zigzag hold [s]."""

ZIGZAG_MAX_GAP_S: float = 10.0
"""Longest time between the end of a zigzag hold and the start of the next [s]."""

ZIGZAG_MAGNITUDE_RATIO: float = 1.5
"""Largest ratio of the ``|azimuth|`` of two consecutive zigzag holds."""

ZIGZAG_MIN_REVERSALS: int = 3
"""Fewest consecutive order reversals of a zigzag."""

ZIGZAG_LEAD_S: float = 10.0
"""Samples kept before the ramp into a zigzag's first hold (start of the replay) [s]."""

STRAIGHT_HOLD_S: float = 300.0
"""Default time the model holds a straight's orders after the recorded span [s]."""

TURN_HOLD_S: float = 300.0
"""Default time the model holds a turn's orders after the recorded span [s]."""

X0_SAMPLES: int = 5
"""Samples (centred, median) of the measured initial state of a replay."""

Simulator = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""``simulate(time, rpm, azimuth, x0) -> (n, 6)`` states ``x, y, psi, u, v, r``."""

_REQUIRED = ("rpm", "azimuth", "u", "r", "psi")


@dataclass(frozen=True)
class Manoeuvre:
    """One manoeuvre found in a record.

    Attributes
    ----------
    name : str
        ``"<kind>-<nn>"``, numbered in time order within its kind.
    kind : str
        ``"straight"``, ``"turn"`` or ``"zigzag"``.
    span : tuple of int
        Half-open sample span ``(i0, i1)`` of the whole manoeuvre with its approach and
        transient (excluded from fitting; the replay starts at ``i0``).
    settled : tuple of int
        Half-open span ``(s0, s1)`` the quantities were read from (``s1 = i1``).
    quantities : dict
        Measured quantities (SI units, radians; see the module docstring).
    events : tuple of int
        Turn: ``(approach_start, execute)``; zigzag: the reversal samples; straight: ``()``.
    n_record : int
        Number of samples of the record (for :func:`folds`).
    reference : tuple of Manoeuvre
        Turn only: the straights that gave ``U_approach`` (empty when the approach did).
    """

    name: str
    kind: str
    span: tuple[int, int]
    settled: tuple[int, int]
    quantities: dict[str, Any]
    events: tuple[int, ...] = ()
    n_record: int = 0
    reference: tuple[Manoeuvre, ...] = field(default=())

    @property
    def side(self) -> str:
        """``"port"`` / ``"starboard"`` for turns and ``""`` otherwise (raw pod sign)."""
        if self.kind != "turn":
            return ""
        return "port" if self.quantities["azimuth"] > 0.0 else "starboard"


# ----------------------------------------------------------------------------------------------
# input checks and small helpers


def _check_record(record: Record) -> float:
    missing = [k for k in _REQUIRED if getattr(record, k, None) is None]
    if missing:
        raise ValueError(
            "manoeuvre extraction needs the record channels rpm, azimuth, u, r and psi; "
            f"missing: {', '.join(missing)}"
        )
    dt = np.diff(np.asarray(record.time, dtype=float))
    step = float(np.median(dt))
    if not np.all(np.abs(dt - step) <= 0.01 * step):
        raise ValueError(
            "manoeuvre extraction needs uniform sampling (time steps within 1 % of the median "
            f"{step:g} s); resample the record first (Record.resample)"
        )
    return step


def _states(record: Record) -> np.ndarray:
    """``(n, 6)`` measured ``x, y, psi, u, v, r`` (missing ``x, y, v`` as 0)."""
    zero = np.zeros_like(record.time)
    cols = [getattr(record, k) for k in ("x", "y", "psi", "u", "v", "r")]
    return np.column_stack([zero if c is None else c for c in cols])


def _n(seconds: float, dt: float) -> int:
    return round(seconds / dt)


def _speed(states: np.ndarray) -> np.ndarray:
    return np.hypot(states[:, 3], states[:, 4])


def _moving_mean(x: np.ndarray, w: int) -> np.ndarray:
    if w <= 1 or x.size < w:
        return x.copy()
    c = np.convolve(x, np.ones(w) / w, mode="same")
    counts = np.convolve(np.ones_like(x), np.ones(w), mode="same")
    return c * w / counts


def _band_holds(
    az: np.ndarray, rpm: np.ndarray, lo: int, hi: int, az_band: float
) -> list[tuple[int, int]]:
    """Greedy cut of ``[lo, hi)`` into holds with az range <= az_band and rpm range <= band."""
    out: list[tuple[int, int]] = []
    i = lo
    while i < hi:
        amin = amax = az[i]
        rmin = rmax = rpm[i]
        j = i + 1
        while j < hi:
            a, p = az[j], rpm[j]
            amin, amax = min(amin, a), max(amax, a)
            rmin, rmax = min(rmin, p), max(rmax, p)
            if amax - amin > az_band or rmax - rmin > RPM_BAND:
                break
            j += 1
        out.append((i, j))
        i = j
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    d = np.diff(np.r_[0, mask.astype(np.int8), 0])
    starts, ends = np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist()
    return list(zip(starts, ends, strict=True))


def _nanmean(x: np.ndarray) -> float:
    return float(np.mean(x)) if x.size and np.all(np.isfinite(x)) else math.nan


def _ratio(a: float, b: float) -> float:
    return a / b if math.isfinite(a) and math.isfinite(b) and b != 0.0 else math.nan


# ----------------------------------------------------------------------------------------------
# quantities (shared by the measured record and the model replays)


def _straight_speed(states: np.ndarray) -> float:
    return _nanmean(_speed(states))


def _turn_stats(states: np.ndarray) -> dict[str, float]:
    """r, U, diameter and whole circles over ``states`` (cut to whole 360 deg turns)."""
    psi = states[:, 2]
    circles = 0
    n = psi.size
    if n >= 2 and np.all(np.isfinite(psi)):
        turned = np.abs(psi - psi[0])
        circles = int(np.max(turned) // (2.0 * math.pi))
        if circles >= 1:
            n = int(np.argmax(turned >= circles * 2.0 * math.pi)) + 1
    r = _nanmean(states[:n, 5])
    speed = _nanmean(_speed(states[:n]))
    diameter = 2.0 * speed / abs(r) if math.isfinite(r) and r != 0.0 else math.nan
    return {"r": r, "U": speed, "diameter": diameter, "circles": float(circles)}


def _overshoots(psi: np.ndarray, delta_sign: Sequence[float], rev: Sequence[int]) -> list[float]:
    """Heading overshoots beyond the heading at each reversal (indices into ``psi``)."""
    out = []
    ends = [*list(rev[1:]), psi.size]
    for k, (i, j) in enumerate(zip(rev, ends, strict=True)):
        seg = delta_sign[k] * (psi[i:j] - psi[i])
        out.append(float(np.max(seg)) if seg.size and np.all(np.isfinite(seg)) else math.nan)
    return out


# ----------------------------------------------------------------------------------------------
# extraction


def _straights(record: Record, dt: float, states: np.ndarray) -> list[Manoeuvre]:
    az, rpm = record.azimuth, record.rpm
    speed = _speed(states)
    smooth = _moving_mean(speed, max(1, _n(SETTLE_SMOOTH_S, dt)))
    out = []
    for lo, hi in _runs(np.abs(az) < STRAIGHT_MAX_AZ):
        for h0, h1 in _band_holds(np.zeros_like(az), rpm, lo, hi, AZ_BAND):
            if h1 - h0 < _n(STRAIGHT_MIN_HOLD_S, dt):
                continue
            target = float(np.median(speed[max(h0, h1 - _n(SETTLE_TAIL_S, dt)) : h1]))
            first = h0 + _n(STRAIGHT_SETTLE_S, dt)
            near = np.flatnonzero(np.abs(smooth[first:h1] - target) <= SETTLE_TOL * target)
            s0 = first + int(near[0]) if near.size else h1
            if h1 - s0 < _n(MIN_SETTLED_S, dt):
                continue
            q = {
                "rpm": float(np.mean(rpm[s0:h1])),
                "azimuth": float(np.mean(az[s0:h1])),
                "U": _straight_speed(states[s0:h1]),
                "duration": float(record.time[h1 - 1] - record.time[s0]),
            }
            out.append(Manoeuvre("", "straight", (h0, h1), (s0, h1), q, (), record.n))
    return out


def _execute(az: np.ndarray, h0: int) -> int:
    """First sample of the azimuth ramp into the hold starting at ``h0``."""
    sign = np.sign(az[h0])
    e = h0
    while e > 0 and np.sign(az[e - 1]) == sign and abs(az[e - 1]) >= STRAIGHT_MAX_AZ:
        e -= 1
    return e


def _reference_straights(rpm: float, straights: list[Manoeuvre]) -> tuple[Manoeuvre, ...]:
    if not straights:
        return ()
    dist = [abs(s.quantities["rpm"] - rpm) for s in straights]
    best = straights[int(np.argmin(dist))].quantities["rpm"]
    return tuple(s for s in straights if abs(s.quantities["rpm"] - best) <= STRAIGHT_CLASS_RPM)


def _reference_speed(rpm: float, refs: Sequence[Manoeuvre], speeds: Sequence[float]) -> float:
    n_ref = float(np.mean([s.quantities["rpm"] for s in refs]))
    return float(np.mean(speeds)) * rpm / n_ref


def _turns(
    record: Record, dt: float, states: np.ndarray, straights: list[Manoeuvre]
) -> list[Manoeuvre]:
    az, rpm = record.azimuth, record.rpm
    speed = _speed(states)
    out = []
    for h0, h1 in _band_holds(az, rpm, 0, record.n, AZ_BAND):
        if h1 - h0 < _n(TURN_MIN_HOLD_S, dt) or abs(np.mean(az[h0:h1])) < TURN_MIN_AZ:
            continue
        s0 = h0 + _n(TURN_SETTLE_S, dt)
        if h1 - s0 < _n(MIN_SETTLED_S, dt):
            continue
        e = _execute(az, h0)
        a0 = max(0, e - _n(TURN_APPROACH_S, dt))
        q: dict[str, Any] = {
            "azimuth": float(np.mean(az[h0:h1])),
            "rpm": float(np.mean(rpm[h0:h1])),
        }
        q.update(_turn_stats(states[s0:h1]))
        straight_approach = (
            e - a0 >= 2
            and bool(np.all(np.abs(az[a0:e]) < STRAIGHT_MAX_AZ))
            and float(np.ptp(rpm[a0:e])) <= RPM_BAND
            and abs(float(np.mean(rpm[a0:e])) - q["rpm"]) <= TURN_RPM_MATCH
        )
        refs: tuple[Manoeuvre, ...] = ()
        if straight_approach:
            q["U_approach"] = float(np.mean(speed[a0:e])) * q["rpm"] / float(np.mean(rpm[a0:e]))
        else:
            refs = _reference_straights(q["rpm"], straights)
            q["U_approach"] = (
                _reference_speed(q["rpm"], refs, [s.quantities["U"] for s in refs])
                if refs
                else math.nan
            )
        q["speed_ratio"] = _ratio(q["U"], q["U_approach"])
        q["duration"] = float(record.time[h1 - 1] - record.time[s0])
        out.append(Manoeuvre("", "turn", (a0, h1), (s0, h1), q, (a0, e), record.n, refs))
    return out


def _zigzags(record: Record, dt: float, states: np.ndarray) -> list[Manoeuvre]:
    az, rpm = record.azimuth, record.rpm
    gap = _n(ZIGZAG_MAX_GAP_S, dt)
    holds: list[list[int]] = []
    for h0, h1 in _band_holds(az, rpm, 0, record.n, AZ_BAND):
        dur = h1 - h0
        if not (_n(ZIGZAG_MIN_HOLD_S, dt) <= dur < _n(TURN_MIN_HOLD_S, dt)):
            continue
        if abs(float(np.median(az[h0:h1]))) < ZIGZAG_MIN_AZ:
            continue
        if holds and np.sign(az[h0]) == np.sign(az[holds[-1][0]]) and h0 - holds[-1][1] <= gap:
            # a same-sign hold split by the band, unless an opposite order lies in between
            if not np.any(az[holds[-1][1] : h0] * np.sign(az[h0]) <= -ZIGZAG_MIN_AZ):
                holds[-1][1] = h1
                continue
        holds.append([h0, h1])

    def level(h: list[int]) -> float:
        return float(np.median(az[h[0] : h[1]]))

    chains: list[list[list[int]]] = []
    for h in holds:
        if chains:
            prev = chains[-1][-1]
            a, b = abs(level(prev)), abs(level(h))
            if (
                np.sign(level(prev)) == -np.sign(level(h))
                and h[0] - prev[1] <= gap
                and max(a, b) <= ZIGZAG_MAGNITUDE_RATIO * min(a, b)
            ):
                chains[-1].append(h)
                continue
        chains.append([h])
    out = []
    for chain in chains:
        if len(chain) - 1 < ZIGZAG_MIN_REVERSALS:
            continue
        rev = []
        for prev, nxt in itertools.pairwise(chain):
            sign = np.sign(level(prev))
            k = prev[1] - 1
            while k < nxt[0] and np.sign(az[k]) == sign:
                k += 1
            rev.append(k)
        first, i1 = chain[0][0], chain[-1][1]
        i0 = max(0, _execute(az, first) - _n(ZIGZAG_LEAD_S, dt))
        signs = [-float(np.sign(level(h))) for h in chain[:-1]]
        shoots = _overshoots(states[i0:i1, 2], signs, [k - i0 for k in rev])
        q: dict[str, Any] = {
            "overshoots": shoots,
            "overshoot_mean": float(np.mean(shoots)),
            "overshoot_max": float(np.max(shoots)),
            "amplitude": float(np.mean([abs(level(h)) for h in chain])),
            "rpm": float(np.mean(rpm[first:i1])),
            "n_reversals": float(len(rev)),
            "duration": float(record.time[i1 - 1] - record.time[first]),
            "delta_signs": signs,
        }
        out.append(Manoeuvre("", "zigzag", (i0, i1), (first, i1), q, tuple(rev), record.n))
    return out


def _named(ms: list[Manoeuvre]) -> list[Manoeuvre]:
    out = []
    for kind in KINDS:
        same = sorted((m for m in ms if m.kind == kind), key=lambda m: m.span[0])
        for k, m in enumerate(same, 1):
            refs = tuple(
                next(o for o in out if o.kind == "straight" and o.span == r.span)
                for r in m.reference
            )
            out.append(
                Manoeuvre(
                    f"{kind}-{k:02d}",
                    m.kind,
                    m.span,
                    m.settled,
                    m.quantities,
                    m.events,
                    m.n_record,
                    refs,
                )
            )
    return sorted(out, key=lambda m: (m.span[0], KINDS.index(m.kind)))


def extract_manoeuvres(record: Record) -> list[Manoeuvre]:
    """Find the straights, steady turns and zigzags of a record with rpm and azimuth orders.

    Parameters
    ----------
    record : Record
        Uniformly sampled, with ``rpm``, ``azimuth`` (raw pod sign), ``u``, ``r`` and ``psi``
        (``x``, ``y``, ``v`` optional, taken as 0 when absent).

    Returns
    -------
    list of Manoeuvre
        Sorted by start sample. Definitions and thresholds: see the module docstring.

    Raises
    ------
    ValueError
        If a required channel is missing or the sampling is not uniform.
    """
    dt = _check_record(record)
    states = _states(record)
    straights = _straights(record, dt, states)
    found = straights + _turns(record, dt, states, straights) + _zigzags(record, dt, states)
    return _named(found)


# ----------------------------------------------------------------------------------------------
# model replay


def _initial_state(states: np.ndarray, i0: int) -> np.ndarray:
    h = X0_SAMPLES // 2
    lo, hi = max(0, i0 - h), min(states.shape[0], i0 + h + 1)
    return np.median(states[lo:hi], axis=0)


def _replay(
    record: Record,
    states: np.ndarray,
    simulate: Simulator,
    span: tuple[int, int],
    hold: tuple[float, float],
    hold_s: float,
    dt: float,
) -> np.ndarray:
    i0, i1 = span
    n_ext = max(0, _n(hold_s, dt))
    t = np.r_[record.time[i0:i1], record.time[i1 - 1] + dt * np.arange(1, n_ext + 1)]
    rpm = np.r_[record.rpm[i0:i1], np.full(n_ext, hold[0])]
    az = np.r_[record.azimuth[i0:i1], np.full(n_ext, hold[1])]
    out = np.asarray(simulate(t, rpm, az, _initial_state(states, i0)), dtype=np.float64)
    if out.shape != (t.size, 6):
        raise ValueError(
            f"simulate must return an array of shape ({t.size}, 6) [x, y, psi, u, v, r], "
            f"got {out.shape}"
        )
    return out


def _hold_orders(record: Record, m: Manoeuvre) -> tuple[float, float]:
    s0, s1 = m.settled
    return float(np.mean(record.rpm[s0:s1])), float(np.mean(record.azimuth[s0:s1]))


def _simulate_straight(
    m: Manoeuvre,
    record: Record,
    states: np.ndarray,
    simulate: Simulator,
    hold_s: float,
    dt: float,
) -> float:
    sim = _replay(record, states, simulate, m.span, _hold_orders(record, m), hold_s, dt)
    n = m.settled[1] - m.settled[0]
    return _straight_speed(sim[-n:])


def simulate_manoeuvre(
    m: Manoeuvre, record: Record, simulate: Simulator, hold_s: float | None = None
) -> dict[str, Any]:
    """The quantities of a manoeuvre computed from a model replaying the recorded orders.

    Parameters
    ----------
    m : Manoeuvre
        From :func:`extract_manoeuvres` on ``record``.
    record : Record
        The record ``m`` was extracted from.
    simulate : callable
        ``simulate(time, rpm, azimuth, x0) -> (n, 6)`` array ``[x, y, psi, u, v, r]`` (``u,
        v`` through the water), given 1-D order arrays (raw pod azimuth sign) and the initial
        state ``x0 = [x, y, psi, u, v, r]``.
    hold_s : float, optional
        Time [s] the hold's mean orders are kept after the recorded span; default
        :data:`STRAIGHT_HOLD_S` (straight), :data:`TURN_HOLD_S` (turn, also for its reference
        straights), 0 (zigzag). With 0 and a ``simulate`` that returns the record itself the
        measured quantities come back.

    Returns
    -------
    dict
        The keys of ``m.quantities``; orders (``rpm``, ``azimuth``, ``amplitude``) are copied.
        Non-finite simulations give NaN quantities.

    Raises
    ------
    ValueError
        On a record without the needed channels or a wrongly shaped simulation.
    """
    dt = _check_record(record)
    states = _states(record)
    if m.kind not in KINDS:
        raise ValueError(f"unknown manoeuvre kind {m.kind!r}; expected one of {KINDS}")
    if hold_s is None:
        hold_s = {"straight": STRAIGHT_HOLD_S, "turn": TURN_HOLD_S, "zigzag": 0.0}[m.kind]
    if hold_s < 0.0 or not math.isfinite(hold_s):
        raise ValueError(f"hold_s must be a finite time >= 0 s, got {hold_s!r}")
    q = dict(m.quantities)
    if m.kind == "straight":
        q["U"] = _simulate_straight(m, record, states, simulate, hold_s, dt)
        return q
    if m.kind == "turn":
        sim = _replay(record, states, simulate, m.span, _hold_orders(record, m), hold_s, dt)
        q.update(_turn_stats(sim[-(m.settled[1] - m.settled[0]) :]))
        if m.reference:
            speeds = [
                _simulate_straight(s, record, states, simulate, hold_s, dt) for s in m.reference
            ]
            q["U_approach"] = _reference_speed(q["rpm"], m.reference, speeds)
        else:
            a0, e = m.events
            rpm_app = float(np.mean(record.rpm[a0:e]))
            speed = _straight_speed(sim[a0 - m.span[0] : e - m.span[0]])
            q["U_approach"] = speed * q["rpm"] / rpm_app
        q["speed_ratio"] = _ratio(q["U"], q["U_approach"])
        return q
    last = m.span[1] - 1
    hold = (float(record.rpm[last]), float(record.azimuth[last]))
    sim = _replay(record, states, simulate, m.span, hold, hold_s, dt)
    shoots = _overshoots(sim[:, 2], q["delta_signs"], [k - m.span[0] for k in m.events])
    finite = bool(np.all(np.isfinite(shoots)))
    q["overshoots"] = shoots
    q["overshoot_mean"] = float(np.mean(shoots)) if finite else math.nan
    q["overshoot_max"] = float(np.max(shoots)) if finite else math.nan
    return q


# ----------------------------------------------------------------------------------------------
# table, Markdown and plot


def _pct(model: float, meas: float) -> float:
    return 100.0 * _ratio(model - meas, meas)


def _errors(kind: str, meas: dict[str, Any], mod: dict[str, Any]) -> dict[str, float]:
    if kind == "straight":
        return {"speed_pct": _pct(mod["U"], meas["U"])}
    if kind == "turn":
        return {
            "speed_pct": _pct(mod["U"], meas["U"]),
            "yaw_rate_pct": _pct(mod["r"], meas["r"]),
            "diameter_pct": _pct(mod["diameter"], meas["diameter"]),
            "speed_ratio_abs": mod["speed_ratio"] - meas["speed_ratio"],
        }
    return {
        "overshoot_mean_deg": math.degrees(mod["overshoot_mean"] - meas["overshoot_mean"]),
        "overshoot_max_deg": math.degrees(mod["overshoot_max"] - meas["overshoot_max"]),
    }


def validation_table(
    manoeuvres: Sequence[Manoeuvre],
    record: Record,
    models: dict[str, Simulator],
    hold_s: float | None = None,
) -> list[dict[str, Any]]:
    """Measured and modelled quantities of every manoeuvre, with the models' errors.

    Parameters
    ----------
    manoeuvres : sequence of Manoeuvre
        From :func:`extract_manoeuvres` on ``record``.
    record : Record
        The record.
    models : dict
        ``{name: simulate}`` (see :func:`simulate_manoeuvre`).
    hold_s : float, optional
        Passed to :func:`simulate_manoeuvre` (default: the per-kind hold times).

    Returns
    -------
    list of dict
        One row per manoeuvre: ``name``, ``kind``, ``t_start``, ``t_end`` [s] (of ``span``),
        ``rpm``, ``azimuth`` [rad] (turns and straights; zigzags: ``amplitude``), ``measured``
        (the quantities), ``models`` (``{name: quantities}``) and ``errors`` (``{name:
        errors}``): ``speed_pct`` (straight, turn), ``yaw_rate_pct``, ``diameter_pct``
        (``100 (model - measured) / measured``; for the signed ``r``: negative when the model
        turns slower, below -100 % when it turns the other way), ``speed_ratio_abs`` (turn),
        ``overshoot_mean_deg``, ``overshoot_max_deg`` (zigzag, model - measured, deg).
    """
    _check_record(record)
    rows = []
    for m in manoeuvres:
        q = m.quantities
        row: dict[str, Any] = {
            "name": m.name,
            "kind": m.kind,
            "t_start": float(record.time[m.span[0]]),
            "t_end": float(record.time[m.span[1] - 1]),
            "rpm": q["rpm"],
            "azimuth": q.get("azimuth", q.get("amplitude")),
            "measured": dict(q),
            "models": {},
            "errors": {},
        }
        for name, fn in models.items():
            mod = simulate_manoeuvre(m, record, fn, hold_s)
            row["models"][name] = mod
            row["errors"][name] = _errors(m.kind, q, mod)
        rows.append(row)
    return rows


# quantity key, label, scale to the table's unit, format
_SHOWN: dict[str, tuple[tuple[str, str, float, str], ...]] = {
    "straight": (("U", "U [m/s]", 1.0, ".2f"),),
    "turn": (
        ("r", "r [deg/s]", math.degrees(1.0), ".2f"),
        ("U", "U [m/s]", 1.0, ".2f"),
        ("diameter", "diameter [m]", 1.0, ".0f"),
        ("speed_ratio", "U/U_approach", 1.0, ".3f"),
    ),
    "zigzag": (
        ("overshoot_mean", "mean overshoot [deg]", math.degrees(1.0), ".1f"),
        ("overshoot_max", "max overshoot [deg]", math.degrees(1.0), ".1f"),
    ),
}
_ERROR_OF = {
    ("straight", "U"): ("speed_pct", "{:+.1f} %"),
    ("turn", "U"): ("speed_pct", "{:+.1f} %"),
    ("turn", "r"): ("yaw_rate_pct", "{:+.1f} %"),
    ("turn", "diameter"): ("diameter_pct", "{:+.1f} %"),
    ("turn", "speed_ratio"): ("speed_ratio_abs", "{:+.3f}"),
    ("zigzag", "overshoot_mean"): ("overshoot_mean_deg", "{:+.1f} deg"),
    ("zigzag", "overshoot_max"): ("overshoot_max_deg", "{:+.1f} deg"),
}


def _fmt(x: float, fmt: str) -> str:
    return format(x, fmt) if isinstance(x, float | int) and math.isfinite(x) else "n/a"


def _orders(row: dict[str, Any]) -> str:
    az = math.degrees(row["azimuth"])
    if row["kind"] == "zigzag":
        return f"+-{az:.1f} deg, {row['rpm']:.0f} rpm"
    return f"{az:+.1f} deg, {row['rpm']:.0f} rpm"


def render_markdown(rows: Sequence[dict[str, Any]]) -> str:
    """A Markdown table of :func:`validation_table` rows (degrees, one line per quantity).

    Parameters
    ----------
    rows : sequence of dict
        From :func:`validation_table`.

    Returns
    -------
    str
        Markdown: one table with the columns manoeuvre, time, orders (azimuth: raw pod sign,
        positive turns to port), quantity, measured, and per model its value and error.
    """
    names: list[str] = []
    for row in rows:
        names += [n for n in row["models"] if n not in names]
    head = ["manoeuvre", "time [s]", "orders", "quantity", "measured"]
    for n in names:
        head += [n, f"{n} error"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        for key, label, scale, fmt in _SHOWN[row["kind"]]:
            cells = [
                row["name"],
                f"{row['t_start']:.0f}-{row['t_end']:.0f}",
                _orders(row),
                label,
                _fmt(row["measured"][key] * scale, fmt),
            ]
            err_key, err_fmt = _ERROR_OF[(row["kind"], key)]
            for n in names:
                mod = row["models"].get(n)
                err = row["errors"].get(n, {}).get(err_key, math.nan)
                cells.append(_fmt(mod[key] * scale, fmt) if mod else "n/a")
                cells.append(err_fmt.format(err) if math.isfinite(err) else "n/a")
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot_validation(rows: Sequence[dict[str, Any]], path: str | Path) -> Path:
    """Measured versus modelled quantities, one scatter panel per quantity, as one PNG.

    Parameters
    ----------
    rows : sequence of dict
        From :func:`validation_table`.
    path : str or pathlib.Path
        Output PNG.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [
        ("straight", "U", "straight speed [m/s]", 1.0),
        ("turn", "U", "turn speed [m/s]", 1.0),
        ("turn", "r", "turn r, measured direction > 0 [deg/s]", math.degrees(1.0)),
        ("turn", "diameter", "turn diameter [m]", 1.0),
        ("turn", "speed_ratio", "speed ratio U/U_approach", 1.0),
        ("zigzag", "overshoot_mean", "zigzag mean overshoot [deg]", math.degrees(1.0)),
    ]
    names: list[str] = []
    for row in rows:
        names += [n for n in row["models"] if n not in names]
    fig, axes = plt.subplots(2, 3, figsize=(13, 8))
    for ax, (kind, key, label, scale) in zip(axes.ravel(), panels, strict=True):
        sel = [row for row in rows if row["kind"] == kind]
        # signed quantities (r) are shown in the measured direction: a wrong turn is < 0
        sign = np.array([math.copysign(1.0, row["measured"][key]) for row in sel])
        meas = np.array([row["measured"][key] * scale for row in sel]) * sign
        lo, hi = math.inf, -math.inf
        for k, n in enumerate(names):
            mod = sign * np.array(
                [row["models"][n][key] * scale if n in row["models"] else math.nan for row in sel]
            )
            ok = np.isfinite(mod) & np.isfinite(meas)
            if ok.any():
                ax.scatter(meas[ok], mod[ok], label=n, color=f"C{k}", s=28)
                lo, hi = (
                    min(lo, mod[ok].min(), meas[ok].min()),
                    max(hi, mod[ok].max(), meas[ok].max()),
                )
        if math.isfinite(lo):
            pad = 0.05 * (hi - lo) + 1e-9
            ax.plot([lo - pad, hi + pad], [lo - pad, hi + pad], "k--", lw=0.8)
        ax.set_title(label)
        ax.set_xlabel("measured")
        ax.set_ylabel("model")
        ax.grid(alpha=0.3)
    if names:
        axes.ravel()[0].legend(fontsize=8)
    fig.suptitle("Manoeuvre validation: model vs measured (dashed: 1:1)")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


# ----------------------------------------------------------------------------------------------
# cross-validation


def folds(manoeuvres: Sequence[Manoeuvre], k: int) -> list[tuple[list[Manoeuvre], np.ndarray]]:
    """Cross-validation folds by manoeuvre.

    Rule: the manoeuvres are dealt round-robin into ``k`` groups, class by class -- port
    turns, starboard turns, straights, zigzags, each class in time order -- with one deal
    counter running on across the classes (so the group sizes differ by at most one, and every
    group gets turns to both sides when each side has at least ``k`` turns).

    Parameters
    ----------
    manoeuvres : sequence of Manoeuvre
        From :func:`extract_manoeuvres` (one record).
    k : int
        Number of groups, ``2 <= k <= len(manoeuvres)``.

    Returns
    -------
    list of (list of Manoeuvre, numpy.ndarray)
        Per group its manoeuvres (time order) and a boolean mask over the record's samples,
        False over the ``span`` of each of its manoeuvres (True: samples a model may be fitted
        on for this fold).
    """
    ms = list(manoeuvres)
    if not isinstance(k, int | np.integer) or not 2 <= k <= len(ms):
        raise ValueError(
            f"k must be an integer in [2, {len(ms)}] (number of manoeuvres), got {k!r}"
        )
    sizes = {m.n_record for m in ms}
    if len(sizes) != 1 or min(sizes) <= 0:
        raise ValueError(f"manoeuvres must come from one record (n_record values: {sorted(sizes)})")
    n = sizes.pop()
    classes = [
        [m for m in ms if m.kind == "turn" and m.side == "port"],
        [m for m in ms if m.kind == "turn" and m.side == "starboard"],
        [m for m in ms if m.kind == "straight"],
        [m for m in ms if m.kind == "zigzag"],
    ]
    groups: list[list[Manoeuvre]] = [[] for _ in range(k)]
    deal = 0
    for cls in classes:
        for m in sorted(cls, key=lambda m: m.span[0]):
            groups[deal % k].append(m)
            deal += 1
    out = []
    for g in groups:
        g.sort(key=lambda m: m.span[0])
        mask = np.ones(n, dtype=bool)
        for m in g:
            mask[m.span[0] : m.span[1]] = False
        out.append((g, mask))
    return out

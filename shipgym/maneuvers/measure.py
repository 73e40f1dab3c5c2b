"""Trial quantities of any time series: a simulation or a measured record.

The zigzag overshoots (ITTC; IMO MSC/Circ.1053, the definition of :func:`zigzag
<shipgym.maneuvers.zigzag>`) and the turning circle's advance, transfer, tactical diameter and
speed ratio (seed 002 Fig. 1) measured from the time histories of rudder, heading, position
and speed alone, so that a measured record (e.g. the SIMMAN 2008 free-running tests) and a
simulation are measured by the same code. The first execute is the start of the first rudder
ramp that reaches 20 % of the largest rudder angle.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["turning_quantities", "zigzag_quantities"]


def _execute(delta: np.ndarray) -> tuple[int, float, float]:
    """First rudder execute, the rudder threshold of the trial and the side of the first
    rudder (+1 starboard): the rudder reaches 20 % of its largest angle (at least 0.5 deg)
    first at some sample; the execute is the start of that ramp, where the rudder began to move
    away from its initial angle."""
    if delta.size == 0 or not np.all(np.isfinite(delta)):
        raise ValueError("delta must be a non-empty series of finite rudder angles [rad]")
    thr = max(math.radians(0.5), 0.2 * float(np.max(np.abs(delta))))
    hits = np.flatnonzero(np.abs(delta) >= thr)
    if hits.size == 0:
        raise ValueError("the rudder never leaves amidships: no trial in this series")
    k = int(hits[0])
    side = float(np.sign(delta[k]))
    d0 = delta[0]
    while k > 0 and abs(delta[k - 1] - d0) < abs(delta[k] - d0):
        k -= 1
    return k, thr, side


def _series(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    out = tuple(np.asarray(a, dtype=np.float64) for a in arrays)
    n = out[0].size
    if any(a.shape != (n,) for a in out) or n < 3:
        shapes = [a.shape for a in out]
        raise ValueError(f"the series must be 1-D and of one length >= 3, got {shapes}")
    return out


def zigzag_quantities(
    time: np.ndarray, psi: np.ndarray, delta: np.ndarray, check: float
) -> dict[str, Any]:
    """Overshoots of a zigzag from its time series, simulated or measured.

    The first execute is the start of the first rudder ramp that reaches 20 % of the largest
    angle; the heading change ``h = psi - psi_0`` counts from the heading there. After each
    rudder reversal (the rudder crossing amidships) the overshoot is the heading excursion
    beyond the check heading ``check`` in the direction the ship was turning, up to the next
    reversal or, after the last one, to the end of the series if the heading has peaked
    (ITTC; the same definition as :func:`zigzag`). A reversal is the rudder reaching the
    execute threshold on the other side, timed from its last crossing of amidships.

    Parameters
    ----------
    time, psi, delta : numpy.ndarray
        Time [s], unwrapped heading [rad] and rudder angle [rad] (positive to starboard).
    check : float
        Heading change ``b`` [rad] of the trial.

    Returns
    -------
    dict
        ``first`` ("starboard" or "port"), ``n_reversals``, ``overshoot1_deg`` and
        ``overshoot2_deg`` (NaN when the record stops before the swing is checked),
        ``reversal_times`` [s].
    """
    time, psi, delta = _series(time, psi, delta)
    if not (math.isfinite(check) and check > 0.0):
        raise ValueError(f"check must be a heading change > 0 rad, got {check!r}")
    i0, thr, side = _execute(delta)
    h = psi - psi[i0]
    # a reversal: the rudder reaches the threshold on the other side; it counts from the last
    # crossing of amidships before that (noise around zero makes no reversal)
    rev = []
    current = side
    for k in range(i0, delta.size):
        if np.sign(delta[k]) == -current and abs(delta[k]) >= thr:
            m = k
            while m > i0 and np.sign(delta[m - 1]) == -current:
                m -= 1
            rev.append(m)
            current = -current
    shoots = []
    for j in range(2):
        d = side if j % 2 == 0 else -side  # the side the ship turned to before reversal j
        if j < len(rev):
            # up to the next reversal, or to the end when the heading has peaked before it
            swing = d * h[rev[j] : rev[j + 1] if j + 1 < len(rev) else h.size]
            peak = int(np.argmax(swing))
            checked = j + 1 < len(rev) or peak < swing.size - 1
            shoots.append(math.degrees(float(swing[peak]) - check) if checked else math.nan)
        else:
            shoots.append(math.nan)
    return {
        "first": "starboard" if side > 0 else "port",
        "n_reversals": len(rev),
        "overshoot1_deg": shoots[0],
        "overshoot2_deg": shoots[1],
        "reversal_times": [float(time[k]) for k in rev],
        "rudder_threshold_deg": math.degrees(thr),
    }


def turning_quantities(
    time: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    psi: np.ndarray,
    delta: np.ndarray,
    speed: np.ndarray,
) -> dict[str, Any]:
    """Advance, transfer, tactical diameter and speed loss of a turning circle from its time
    series, simulated or measured.

    The execute is the start of the first rudder ramp that reaches 20 % of the largest angle;
    distances are measured from the position there along and across the heading there.
    Advance and transfer at 90 deg of heading change, the tactical diameter (across) at 180 deg,
    the speed ratio is the mean speed between 360 and 720 deg of heading change (or from 270 deg
    to the end when the record turns less) over the mean speed of the last 10 s before the
    execute (its speed when there are none).

    Parameters
    ----------
    time, x, y, psi, delta, speed : numpy.ndarray
        Time [s], north and east position [m], unwrapped heading [rad], rudder angle [rad]
        (positive to starboard) and speed [m/s].

    Returns
    -------
    dict
        ``side``, ``advance``, ``transfer``, ``tactical_diameter`` [m] (NaN when not reached),
        ``approach_speed`` [m/s] and ``speed_ratio``.
    """
    time, x, y, psi, delta, speed = _series(time, x, y, psi, delta, speed)
    i0, _, side = _execute(delta)
    h = side * (psi[i0:] - psi[i0])
    c, s = math.cos(psi[i0]), math.sin(psi[i0])
    dx, dy = x[i0:] - x[i0], y[i0:] - y[i0]
    along = dx * c + dy * s
    across = side * (-dx * s + dy * c)

    def at(values: np.ndarray, angle: float) -> float:
        k = np.flatnonzero(h >= angle)
        if k.size == 0 or k[0] == 0:
            return math.nan
        j = int(k[0])
        return float(np.interp(angle, h[j - 1 : j + 1], values[j - 1 : j + 1]))

    before = (time >= time[i0] - 10.0) & (np.arange(time.size) < i0)
    u0 = float(np.mean(speed[before])) if np.any(before) else float(speed[i0])
    turned = speed[i0:][(h >= 2 * math.pi) & (h <= 4 * math.pi)]
    if turned.size == 0:
        turned = speed[i0:][h >= 1.5 * math.pi]
    return {
        "side": "starboard" if side > 0 else "port",
        "advance": at(along, math.pi / 2),
        "transfer": at(across, math.pi / 2),
        "tactical_diameter": at(across, math.pi),
        "approach_speed": u0,
        "speed_ratio": float(np.mean(turned)) / u0 if turned.size else math.nan,
    }

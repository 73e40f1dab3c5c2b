"""The direct and reverse spiral: the steady delta-r curve (seed 004 Fig. 1).

Seed 002 introduction; seed 004 section 1.1 and Fig. 1, the delta-r plot.
*Direct* (Dieudonné): the rudder is held at each angle of a sequence from starboard to port and
back and the steady yaw rate recorded; an unstable ship shows a hysteresis loop. *Reverse*
(Bech): a yaw-rate controller (PI on ``r``) holds ``r`` at each setpoint and the mean rudder
needed is recorded; this traces the whole S-shaped curve, including the unstable branch inside
the loop. For the Norrbin model the steady curve is ``n3 r^3 + n2 r|r| + n1 r + n0 = K delta``
(seed 002 eq. 1-3, seed 004 eq. 4).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from shipgym.maneuvers._common import (
    ModelLike,
    Progress,
    Rig,
    Run,
    TimeSeries,
    hold_until_steady,
    json_deg,
    json_num,
    wind_json,
)
from shipgym.maneuvers.particulars import ShipParticulars
from shipgym.models.seaway_options import Wind

__all__ = ["SpiralResult", "spiral"]


@dataclass(frozen=True, eq=False)
class SpiralResult:
    """A direct or reverse spiral: the steady delta-r curve (seed 004 Fig. 1).

    Attributes
    ----------
    model, particulars, approach_speed, series, wind
        As in :class:`ZigZagResult`.
    kind : str
        ``"direct"`` (Dieudonné) or ``"reverse"`` (Bech).
    rudder : numpy.ndarray
        Steady (mean) rudder angle of each point [rad].
    yaw_rate : numpy.ndarray
        Steady (mean) yaw rate of each point [rad/s].
    speed : numpy.ndarray
        Steady (mean) speed [m/s].
    leg : tuple of str
        ``"down"`` (starboard to port) or ``"up"`` (back) for each point.
    setpoints : numpy.ndarray or None
        Yaw-rate setpoints [rad/s] of the reverse spiral.
    steady : numpy.ndarray
        Whether each point settled within the longest hold.
    saturated : numpy.ndarray
        Reverse spiral: the rudder hit its limit (the point is not on the curve).
    hysteresis : bool
        Direct: the down and up legs give yaw rates of opposite sign at one rudder angle.
        Reverse: the rudder needed decreases with the yaw rate somewhere (an S-curve).
        Either means the ship is directionally unstable.
    loop_width : float
        Width of the hysteresis loop in rudder angle [rad] (0 if none). Direct: the span of
        the rudder angles at which the legs disagree (at the resolution of the sequence);
        reverse: the rudder span of the unstable (negative-slope) branch.
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    kind: str
    rudder: np.ndarray
    yaw_rate: np.ndarray
    speed: np.ndarray
    leg: tuple[str, ...]
    setpoints: np.ndarray | None
    steady: np.ndarray
    saturated: np.ndarray
    hysteresis: bool
    loop_width: float
    series: TimeSeries
    dt: float
    wind: Wind | None = None

    def to_dict(self, include_series: bool = False) -> dict[str, Any]:
        """The delta-r points for JSON; degrees in ``*_deg`` keys."""
        d: dict[str, Any] = {
            "manoeuvre": "spiral",
            "kind": self.kind,
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": self.particulars.length,
            "approach_speed_m_s": json_num(self.approach_speed),
            "dt_s": self.dt,
            "rudder_deg": [json_deg(v) for v in self.rudder],
            "yaw_rate_deg_s": [json_deg(v) for v in self.yaw_rate],
            "speed_m_s": [json_num(v) for v in self.speed],
            "leg": list(self.leg),
            "steady": [bool(v) for v in self.steady],
            "saturated": [bool(v) for v in self.saturated],
            "hysteresis": self.hysteresis,
            "loop_width_deg": json_deg(self.loop_width),
            "wind": wind_json(self.wind),
        }
        if self.setpoints is not None:
            d["yaw_rate_setpoint_deg_s"] = [json_deg(v) for v in self.setpoints]
        if include_series:
            d["series"] = self.series.to_dict()
        return d


class _YawRatePI:
    """PI yaw-rate controller with conditional integration (anti-windup) for the reverse
    spiral: ``delta_c = kp (r_d - r) + ki int (r_d - r) dt``, saturated at the rudder limit."""

    def __init__(self, rig: Rig) -> None:
        self.rig = rig
        self.kp = rig.settings.kp
        self.ki = rig.settings.kp / rig.settings.ti
        self.setpoint = 0.0
        self.integral = 0.0

    def __call__(self, t: float, x: np.ndarray) -> float:
        e = self.setpoint - x[self.rig.ir]
        limit = self.rig.max_rudder
        unsat = self.kp * e + self.integral
        if abs(unsat) < limit or unsat * e < 0:
            self.integral += self.ki * e * self.rig.dt
            self.integral = min(max(self.integral, -limit), limit)
        return min(max(self.kp * e + self.integral, -limit), limit)


def _monotonic_loop(r: np.ndarray, delta: np.ndarray) -> tuple[bool, float]:
    """Negative-slope (unstable) branch of delta(r): exists? and its rudder span."""
    dd = delta[np.argsort(r)]
    slope = np.diff(dd)
    neg = np.nonzero(slope < -1e-9 * max(1.0, float(np.max(np.abs(dd)))))[0]
    if len(neg) == 0:
        return False, 0.0
    ends = np.concatenate([dd[neg], dd[neg + 1]])
    return True, float(np.max(ends) - np.min(ends))


def spiral(
    model: ModelLike = "norrbin",
    rudders_deg: Sequence[float] | None = None,
    kind: str = "direct",
    yaw_rates_deg_s: Sequence[float] | None = None,
    return_leg: bool = True,
    dt: float | None = None,
    progress: Progress = None,
    wind: Mapping[str, Any] | None = None,
) -> SpiralResult:
    """Direct (Dieudonné) or reverse (Bech) spiral: the steady delta-r curve.

    Parameters
    ----------
    model : str or ShipModel
        Model name or model.
    rudders_deg : sequence of float, optional
        Direct spiral: rudder angles [deg] from starboard to port (default 20, 15, 10, 5, 3,
        2, 1, 0, -1, ..., -20 for the Mariner models); with ``return_leg`` the sequence is
        run back again, so that an unstable ship shows its hysteresis loop.
    kind : {"direct", "reverse"}
        Trial.
    yaw_rates_deg_s : sequence of float, optional
        Reverse spiral: yaw-rate setpoints [deg/s] (default 21 values from +r_max to
        -r_max, 1.43 deg/s for the Mariner models and 4.6 deg/s for the RVG).
    return_leg : bool
        Direct spiral: run the sequence back from port to starboard.
    dt : float, optional
        Integration step [s].
    progress : callable, optional
        Called with a one-line message after each point.
    wind : dict, optional
        A constant true wind from the start on, as :func:`~shipgym.maneuvers.turning_circle`'s.

    Returns
    -------
    SpiralResult
    """
    rig = Rig(model, dt, wind)
    if kind not in ("direct", "reverse"):
        raise ValueError(f"spiral kind must be 'direct' or 'reverse', got {kind!r}")
    limit_deg = math.degrees(rig.max_rudder)
    if kind == "direct":
        seq = rig.settings.spiral_rudders_deg if rudders_deg is None else tuple(rudders_deg)
        if len(seq) < 2:
            raise ValueError(f"rudders_deg needs at least 2 angles, got {seq!r}")
        for v in seq:
            if not (isinstance(v, int | float) and math.isfinite(v) and abs(v) <= limit_deg):
                raise ValueError(
                    f"spiral rudder angles must be finite and within +-{limit_deg:g} deg, got {v!r}"
                )
        targets = [math.radians(v) for v in seq]
        legs = ["down"] * len(seq)
        if return_leg:
            targets += targets[-2::-1]
            legs += ["up"] * (len(seq) - 1)
        hold = {"delta": targets[0]}
        run = Run(rig, lambda t, x: hold["delta"])
        setpoints = None
    else:
        if yaw_rates_deg_s is None:
            r_max = rig.settings.spiral_yaw_rate
            targets = list(np.linspace(r_max, -r_max, 21))
        else:
            targets = []
            for v in yaw_rates_deg_s:
                if not (isinstance(v, int | float) and math.isfinite(v) and abs(v) <= 30):
                    raise ValueError(
                        f"yaw-rate setpoints must be finite and within +-30 deg/s, got {v!r}"
                    )
                targets.append(math.radians(v))
            if len(targets) < 2:
                raise ValueError(f"yaw_rates_deg_s needs at least 2 values, got {targets!r}")
        legs = ["down"] * len(targets)
        pi = _YawRatePI(rig)
        run = Run(rig, pi)
        setpoints = np.array(targets, dtype=float)
    rows = []
    for k, target in enumerate(targets):
        if kind == "direct":
            hold["delta"] = target
        else:
            pi.setpoint = target
        ok, mean = hold_until_steady(run, rig, min_time=2 * rig.settings.chunk)
        rows.append((*mean, ok))
        if progress is not None:
            what = (
                f"rudder {math.degrees(target):+6.2f} deg"
                if kind == "direct"
                else f"r_d {math.degrees(target):+6.3f} deg/s"
            )
            progress(
                f"{kind} spiral {k + 1}/{len(targets)}: {what} -> r {math.degrees(mean[0]):+.3f} "
                f"deg/s, rudder {math.degrees(mean[2]):+.2f} deg" + ("" if ok else " (not settled)")
            )
    arr = np.array([row[:3] for row in rows])
    r_ss, v_ss, d_ss = arr[:, 0], arr[:, 1], arr[:, 2]
    steady = np.array([row[3] for row in rows], dtype=bool)
    if kind == "direct":
        saturated = np.zeros(len(rows), dtype=bool)
        tol = max(1e-4, 0.02 * float(np.max(np.abs(r_ss))))
        down = {round(d, 9): r for d, r, g in zip(targets, r_ss, legs, strict=True) if g == "down"}
        split = [
            d
            for d, r, g in zip(targets, r_ss, legs, strict=True)
            if g == "up"
            and round(d, 9) in down
            and abs(down[round(d, 9)] - r) > tol
            and down[round(d, 9)] * r < 0
        ]
        hysteresis = bool(split)
        width = float(max(split) - min(split)) if split else 0.0
    else:
        saturated = np.abs(d_ss) >= 0.99 * rig.max_rudder
        ok = ~saturated
        hysteresis, width = _monotonic_loop(r_ss[ok], d_ss[ok])
    return SpiralResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        kind=kind,
        rudder=d_ss,
        yaw_rate=r_ss,
        speed=v_ss,
        leg=tuple(legs),
        setpoints=setpoints,
        steady=steady,
        saturated=saturated,
        hysteresis=hysteresis,
        loop_width=width,
        series=rig.series(run.result()),
        dt=rig.dt,
        wind=rig.wind,
    )

r"""Constant-bearing target tracking: hold a set distance from a moving target (seed 004 eq. 11).

Seed 004 eq. 11 (Fossen 2011, constant-bearing target-tracking guidance) gives the desired
velocity of an interceptor::

    v_d   = v_t + v_a
    v_a   = -kappa p~ / |p~|
    kappa = U_a,max |p~| / sqrt(p~^T p~ + Delta^2)

so ``v_a = -U_a,max p~ / sqrt(p~^T p~ + Delta^2)``: the ship approaches along the line of
sight with at most ``U_a,max`` relative to the target and slows down smoothly within about
``Delta`` of the goal. In the seed ``p~ = p - p_t`` and the ship runs into the target.

Here the ship must *hold a distance* ``d`` from the target, so ``p~`` is measured from an aim
point at distance ``d`` from the target on the line from the target to the ship::

    p_a = p_t + d (p - p_t) / |p - p_t|,     p~ = p - p_a

(``|p~| = | |p - p_t| - d |``). The ship closes (or opens) the range along the line of sight
and then keeps station at ``d`` on whatever bearing it arrived from, moving with the target
(``v_d -> v_t``). ``d = 0`` is the seed's interception. On the target itself the bearing is
undefined; the aim point is then placed behind the target (against its velocity).

Outputs: course ``chi_d = atan2(v_d,e, v_d,n)`` [rad, clockwise from north] and speed
``U_d = |v_d|`` clipped to ``[U_min, U_max]``. Both are over ground: in a current, turn the
course into a heading with the crab angle (``psi_d = chi_d - beta``). When ``|v_d|`` is
almost zero the course is undefined and the previous ``chi_d`` is kept.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from controllers._angles import StepClock, finite, nonnegative, point, positive, ssa

__all__ = ["ConstantBearingGuidance"]

#: Below this desired speed [m/s] the course is held (atan2 of a vanishing vector is noise).
_MIN_COURSE_SPEED = 1e-6


class ConstantBearingGuidance:
    """Constant-bearing guidance that holds ``distance`` from a target (module docstring).

    Parameters
    ----------
    max_approach_speed : float
        ``U_a,max`` [m/s]: largest speed relative to the target (> 0).
    delta : float
        ``Delta`` [m]: the distance from the aim point over which the approach slows (> 0).
    distance : float
        ``d`` [m]: the range to hold (0 intercepts the target).
    min_speed, max_speed : float
        Limits [m/s] of the speed command ``U_d`` (0 and ``inf`` by default).
    dt : float
        Nominal sample time [s]; used to difference target positions when no target
        velocity is given.

    Attributes
    ----------
    desired_velocity : numpy.ndarray
        Last ``v_d`` (north, east) [m/s].
    approach_velocity : numpy.ndarray
        Last ``v_a`` [m/s].
    aim_point : numpy.ndarray
        Last ``p_a`` [m].
    range : float
        Last distance ``|p - p_t|`` [m].
    range_error : float
        ``range - distance`` [m].
    chi_d, U_d : float
        Last course [rad] and speed [m/s] commands.
    """

    def __init__(
        self,
        max_approach_speed: float,
        delta: float,
        distance: float = 0.0,
        *,
        min_speed: float = 0.0,
        max_speed: float = math.inf,
        dt: float = 1.0,
    ) -> None:
        self.max_approach_speed = positive("max_approach_speed", max_approach_speed)
        self.delta = positive("delta", delta)
        self.distance = nonnegative("distance", distance)
        self.min_speed = nonnegative("min_speed", min_speed)
        self.max_speed = positive("max_speed", max_speed, allow_inf=True)
        if self.max_speed < self.min_speed:
            raise ValueError(f"max_speed={max_speed!r} must be >= min_speed={min_speed!r} [m/s]")
        self._clock = StepClock(dt)
        self.reset()

    def reset(self, *, t: float | None = None, course: float = 0.0) -> None:
        """Forget the past: the held course [rad] and the previous target position."""
        self._clock.reset(t)
        self.chi_d = ssa(finite("course", course))
        self.U_d = 0.0
        self._prev_target: np.ndarray | None = None
        self.desired_velocity = np.zeros(2)
        self.approach_velocity = np.zeros(2)
        self.aim_point = np.zeros(2)
        self.range = math.nan
        self.range_error = math.nan

    def desired_velocity_at(
        self,
        position: npt.ArrayLike,
        target_position: npt.ArrayLike,
        target_velocity: npt.ArrayLike,
    ) -> np.ndarray:
        """``v_d`` (north, east) [m/s] at one instant (no state is changed)."""
        p = point("position", position)
        pt = point("target_position", target_position)
        vt = point("target_velocity", target_velocity)
        return self._velocity(p, pt, vt)[0]

    def _velocity(
        self, p: np.ndarray, pt: np.ndarray, vt: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        los = p - pt
        rng = math.hypot(los[0], los[1])
        if rng > 0:
            unit = los / rng
        else:
            speed_t = math.hypot(vt[0], vt[1])
            unit = -vt / speed_t if speed_t > 0 else np.array([-1.0, 0.0])
        aim = pt + self.distance * unit
        pe = p - aim
        v_a = -self.max_approach_speed * pe / math.sqrt(pe[0] ** 2 + pe[1] ** 2 + self.delta**2)
        return vt + v_a, v_a, aim, rng

    def update(
        self,
        t: float | None,
        position: npt.ArrayLike,
        target_position: npt.ArrayLike,
        target_velocity: npt.ArrayLike | None = None,
    ) -> tuple[float, float]:
        """Course and speed commands for the present positions.

        Parameters
        ----------
        t : float or None
            Time [s] (only used to difference target positions when ``target_velocity`` is
            ``None``).
        position : array_like
            Ship position (north, east) [m], shape ``(2,)``.
        target_position : array_like
            Target position (north, east) [m].
        target_velocity : array_like, optional
            Target velocity over ground (north, east) [m/s]; estimated from successive target
            positions when omitted (zero on the first call).

        Returns
        -------
        tuple of float
            ``(chi_d, U_d)``: course [rad, in [-pi, pi)] and speed [m/s].
        """
        p = point("position", position)
        pt = point("target_position", target_position)
        h = self._clock.step(t)
        if target_velocity is None:
            if self._prev_target is not None and h > 0:
                vt = (pt - self._prev_target) / h
            else:
                vt = np.zeros(2)
        else:
            vt = point("target_velocity", target_velocity)
        self._prev_target = pt
        v_d, v_a, aim, rng = self._velocity(p, pt, vt)
        speed = math.hypot(v_d[0], v_d[1])
        if speed > _MIN_COURSE_SPEED:
            self.chi_d = ssa(math.atan2(v_d[1], v_d[0]))
        self.U_d = min(max(speed, self.min_speed), self.max_speed)
        self.desired_velocity = v_d
        self.approach_velocity = v_a
        self.aim_point = aim
        self.range = rng
        self.range_error = rng - self.distance
        return self.chi_d, self.U_d

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

Batches. The law runs on a batch of ships: with one distance per ship (an array of shape
``(n,)``) it takes positions, target positions and target velocities of shape ``(n, 2)`` and
returns courses and speeds of shape ``(n,)``; with one distance it takes one ship's vectors and
returns floats. One ship is a batch of one of the same code, and every row of a batch gives
bitwise the floats of that ship guided alone (``hypot``, ``atan2`` and the squares come from
:mod:`math`, element by element, where NumPy's SIMD versions round the last bit differently).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from controllers._angles import (
    StepClock,
    batch_size,
    constant,
    finite_batch,
    math_elementwise,
    nonnegative,
    positive,
    ssa_array,
)

__all__ = ["ConstantBearingGuidance", "course_and_speed"]

#: Below this desired speed [m/s] the course is held (atan2 of a vanishing vector is noise).
_MIN_COURSE_SPEED = 1e-6


def course_and_speed(velocity: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Course over ground ``atan2(v_E, v_N)`` [rad] and speed ``|v|`` [m/s] of NED velocities
    ``(n, 2)``, each row as :func:`math.atan2` and :func:`math.hypot` give it for one ship."""
    v = np.asarray(velocity, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 2:
        raise ValueError(f"velocity must have shape (n, 2) (north, east) [m/s], got {v.shape}")
    return math_elementwise(math.atan2, v[:, 1], v[:, 0]), math_elementwise(
        math.hypot, v[:, 0], v[:, 1]
    )


class ConstantBearingGuidance:
    """Constant-bearing guidance that holds ``distance`` from a target (module docstring).

    Parameters
    ----------
    max_approach_speed : float
        ``U_a,max`` [m/s]: largest speed relative to the target (> 0).
    delta : float
        ``Delta`` [m]: the distance from the aim point over which the approach slows (> 0).
    distance : float or array_like
        ``d`` [m]: the range to hold (0 intercepts the target). A float guides one ship; an
        array of shape ``(n,)`` (one distance per ship, ``np.full(n, d)`` for one distance)
        guides a batch of ``n`` ships.
    min_speed, max_speed : float
        Limits [m/s] of the speed command ``U_d`` (0 and ``inf`` by default).
    dt : float
        Nominal sample time [s]; used to difference target positions when no target
        velocity is given.

    Attributes
    ----------
    n_ships : int
        Number of ships guided (1 for a float ``distance``).
    desired_velocity : numpy.ndarray
        Last ``v_d`` (north, east) [m/s]: shape ``(2,)``, or ``(n, 2)`` for a batch.
    approach_velocity : numpy.ndarray
        Last ``v_a`` [m/s], shaped as ``desired_velocity``.
    aim_point : numpy.ndarray
        Last ``p_a`` [m], shaped as ``desired_velocity``.
    range : float or numpy.ndarray
        Last distance ``|p - p_t|`` [m] (shape ``(n,)`` for a batch).
    range_error : float or numpy.ndarray
        ``range - distance`` [m].
    chi_d, U_d : float or numpy.ndarray
        Last course [rad] and speed [m/s] commands.

    Examples
    --------
    >>> g = ConstantBearingGuidance(2.0, 100.0, distance=50.0)
    >>> chi, u = g.update(0.0, (0.0, 0.0), (1000.0, 0.0), (0.0, 0.0))  # target due north
    >>> round(chi, 6), round(u, 3)
    (0.0, 1.989)
    >>> batch = ConstantBearingGuidance(2.0, 100.0, distance=[50.0, 50.0])
    >>> chi, u = batch.update(0.0, [[0.0, 0.0], [0.0, 0.0]], [[1000.0, 0.0], [0.0, 1000.0]],
    ...                       [[0.0, 0.0], [0.0, 0.0]])
    >>> chi.round(4), u.round(3)
    (array([0.    , 1.5708]), array([1.989, 1.989]))
    """

    def __init__(
        self,
        max_approach_speed: float,
        delta: float,
        distance: float | npt.ArrayLike = 0.0,
        *,
        min_speed: float = 0.0,
        max_speed: float = math.inf,
        dt: float = 1.0,
    ) -> None:
        self.max_approach_speed = positive("max_approach_speed", max_approach_speed)
        self.delta = positive("delta", delta)
        self._distance, self._batch = _distances(distance)
        self.n_ships = self._distance.size
        self.min_speed = nonnegative("min_speed", min_speed)
        self.max_speed = positive("max_speed", max_speed, allow_inf=True)
        if self.max_speed < self.min_speed:
            raise ValueError(f"max_speed={max_speed!r} must be >= min_speed={min_speed!r} [m/s]")
        self._clock = StepClock(dt)
        # the law's numbers as 0-d arrays (faster with NumPy arrays, the same values)
        self._c = {
            "delta^2": constant(self.delta**2),
            "-U_a,max": constant(-self.max_approach_speed),
            "min_speed": constant(self.min_speed),
            "max_speed": constant(self.max_speed),
        }
        self.reset()

    def reset(self, *, t: float | None = None, course: npt.ArrayLike = 0.0) -> None:
        """Forget the past: the held course [rad] (one per ship, or one for all) and the
        previous target position."""
        self._clock.reset(t)
        n = self.n_ships
        courses = finite_batch("course", course, n if self._batch else None)
        self._chi_d = ssa_array(courses)
        self._U_d = np.zeros(n)
        self._prev_target: np.ndarray | None = None
        self._v_d = self._v_a = self._aim = np.zeros((n, 2))  # replaced, never written into
        self._range = self._range_error = np.full(n, np.nan)

    def _out(self, a: np.ndarray) -> float | np.ndarray:
        """A read-out: the array in a batch, one ship's row (a float or a (2,) array) otherwise."""
        if self._batch:
            return a
        return a[0] if a.ndim == 2 else a.item(0)

    def _points(self, name: str, value: npt.ArrayLike) -> np.ndarray:
        """``(n, 2)`` finite (north, east) values, checked against the batch size."""
        n = self.n_ships if self._batch else None
        return finite_batch(name, value, n, per_ship=(2,), broadcast=False)

    # ------------------------------------------------------------------- read-outs
    @property
    def distance(self) -> float | np.ndarray:
        """``d`` [m]: the range to hold."""
        return self._out(self._distance)

    @property
    def chi_d(self) -> float | np.ndarray:
        """Course command [rad] in ``[-pi, pi)`` of the last update (held at low speed)."""
        return self._out(self._chi_d)

    @property
    def U_d(self) -> float | np.ndarray:
        """Speed command [m/s] of the last update."""
        return self._out(self._U_d)

    @property
    def desired_velocity(self) -> np.ndarray:
        """``v_d`` (north, east) [m/s] of the last update."""
        return self._out(self._v_d)

    @property
    def approach_velocity(self) -> np.ndarray:
        """``v_a`` (north, east) [m/s] of the last update."""
        return self._out(self._v_a)

    @property
    def aim_point(self) -> np.ndarray:
        """``p_a`` (north, east) [m] of the last update."""
        return self._out(self._aim)

    @property
    def range(self) -> float | np.ndarray:
        """``|p - p_t|`` [m] at the last update."""
        return self._out(self._range)

    @property
    def range_error(self) -> float | np.ndarray:
        """``range - distance`` [m] at the last update."""
        return self._out(self._range_error)

    # ------------------------------------------------------------------- the law
    def desired_velocity_at(
        self,
        position: npt.ArrayLike,
        target_position: npt.ArrayLike,
        target_velocity: npt.ArrayLike,
    ) -> np.ndarray:
        """``v_d`` (north, east) [m/s] at one instant (no state is changed)."""
        p = self._points("position", position)
        pt = self._points("target_position", target_position)
        vt = self._points("target_velocity", target_velocity)
        return self._out(self._velocity(p, pt, vt)[0])

    def _velocity(
        self, p: np.ndarray, pt: np.ndarray, vt: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``v_d``, ``v_a``, ``p_a`` (each ``(n, 2)``) and the range ``(n,)``."""
        c = self._c
        los = p - pt
        rng = math_elementwise(math.hypot, los[:, 0], los[:, 1])
        on_target = rng == 0.0
        if not on_target.any():
            unit = los / rng[:, None]
        else:  # the bearing is undefined on the target: aim behind it
            with np.errstate(divide="ignore", invalid="ignore"):
                unit = los / rng[:, None]
                vt0 = vt[on_target]
                speed_t = math_elementwise(math.hypot, vt0[:, 0], vt0[:, 1])
                behind = -vt0 / speed_t[:, None]
            behind[speed_t == 0.0] = (-1.0, 0.0)
            unit[on_target] = behind
        aim = pt + self._distance[:, None] * unit
        pe = p - aim
        # pe**2 as the one-ship code squared it (libm pow, not always pe * pe to the last bit)
        square = math_elementwise(math.pow, pe, np.full(pe.shape, 2.0))
        root = np.sqrt(square[:, 0] + square[:, 1] + c["delta^2"])
        v_a = c["-U_a,max"] * pe / root[:, None]
        return vt + v_a, v_a, aim, rng

    def update(
        self,
        t: float | None,
        position: npt.ArrayLike,
        target_position: npt.ArrayLike,
        target_velocity: npt.ArrayLike | None = None,
    ) -> tuple[float, float] | tuple[np.ndarray, np.ndarray]:
        """Course and speed commands for the present positions.

        Parameters
        ----------
        t : float or None
            Time [s], one for the whole batch (only used to difference target positions when
            ``target_velocity`` is ``None``).
        position : array_like
            Ship position (north, east) [m]: shape ``(2,)``, or ``(n, 2)`` for a batch.
        target_position : array_like
            Target position (north, east) [m], shaped as ``position``.
        target_velocity : array_like, optional
            Target velocity over ground (north, east) [m/s], shaped as ``position``; estimated
            from successive target positions when omitted (zero on the first call).

        Returns
        -------
        tuple of float or of numpy.ndarray
            ``(chi_d, U_d)``: course [rad, in [-pi, pi)] and speed [m/s]; arrays of shape
            ``(n,)`` for a batch.
        """
        p = self._points("position", position)
        pt = self._points("target_position", target_position)
        if target_velocity is not None:
            vt = self._points("target_velocity", target_velocity)
        h = self._clock.step(t)
        if target_velocity is None:
            if self._prev_target is not None and h > 0:
                vt = (pt - self._prev_target) / h
            else:
                vt = np.zeros(pt.shape)
        self._prev_target = pt  # a copy of the caller's array
        v_d, v_a, aim, rng = self._velocity(p, pt, vt)
        speed = math_elementwise(math.hypot, v_d[:, 0], v_d[:, 1])
        course = ssa_array(math_elementwise(math.atan2, v_d[:, 1], v_d[:, 0]))
        self._chi_d = np.where(speed > _MIN_COURSE_SPEED, course, self._chi_d)
        self._U_d = np.minimum(np.maximum(speed, self._c["min_speed"]), self._c["max_speed"])
        self._v_d, self._v_a, self._aim, self._range = v_d, v_a, aim, rng
        self._range_error = rng - self._distance
        return self._out(self._chi_d), self._out(self._U_d)


def _distances(distance: float | npt.ArrayLike) -> tuple[np.ndarray, bool]:
    """The distances [m] as an ``(n,)`` array and whether a batch (an array) was given."""
    n = batch_size(distance=distance)
    if n is None:
        return np.array([nonnegative("distance", distance)]), False
    if n == 0:
        raise ValueError("distance must be a number >= 0 [m] or one per ship, got an empty array")
    d = finite_batch("distance", distance, n)
    negative = np.flatnonzero(d < 0.0)
    if negative.size:
        i = int(negative[0])
        raise ValueError(f"distance[{i}] must be >= 0 [m], got {float(d[i])!r}")
    return d, True

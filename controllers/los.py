"""Lookahead line-of-sight (LOS) path-following guidance.

Both guidance laws return a desired course ``chi_d`` [rad] (used as the heading setpoint of a
heading autopilot) from the measured position ``(north, east)`` [m], heading ``psi`` [rad] and
yaw rate ``r`` [rad/s], for any :class:`controllers.paths.Path`.

Cross-track error and sign convention (Fossen 2011, ch. 10)::

    e = -(x - x_p) sin(chi_p) + (y - y_p) cos(chi_p)

is positive when the ship is to the right (starboard) of the path direction ``chi_p``. A
positive ``e`` must be corrected by steering to port, so the correction angle ``chi_r`` has the
opposite sign of ``e``.

:class:`LOSGuidance` (seed 004 section 2.2, eq. 9-10) is the lookahead-based steering law with
the seed's *conditional integrator*::

    chi_d = chi_p + chi_r,       chi_r = -atan(Kp e + I),     Kp = 1 / Delta      (eq. 9)
    I     = int Ki e_i dt                                                           (eq. 10)
    e_i   = 0                               if |r| > r_lim or |e| > e_lim
          = e / (k1 + k2 |I| / I_max)       if (I > I_max and e > 0) or (I < -I_max and e < 0)
          = e                               otherwise

and the anti-windup clamp ``|I| <= I_hard``. The seed writes ``chi_r = atan(P - I)`` with
``P = Kp e``; with its cross-track error measured positive to *port* (the seed flips the sign
of the steering input, "a fixed gain of -1 on delta_c") that is the same law. Written with the
starboard-positive ``e`` above, proportional and integral action must both enter with a minus
sign, ``chi_r = -atan(Kp e + I)`` (otherwise the integral would push the ship away from the
path); ``I`` has the sign of the accumulated ``e`` and, in steady state, ``atan(I)`` equals the
crab angle needed against the current. The integrator only runs near the path and when the
ship is not turning (``e_i = 0`` otherwise), so that it compensates slow disturbances (current,
wind) rather than transients; beyond ``I_max`` it winds further only slowly (soft
saturation), and never beyond ``I_hard``.

:class:`IntegralLOS` is the integral LOS of Borhaug, Pavlov and Pettersen (2008), "Integral
LOS control for path following of underactuated marine surface vessels in the presence of
constant ocean currents", IEEE CDC::

    chi_d = chi_p - atan((e + sigma e_int) / Delta),
    d e_int / dt = Delta e / ((e + sigma e_int)^2 + Delta^2).

Linearised about the path for a ship at speed ``U`` that follows ``chi_d`` instantly, both
give ``e'' + (U / Delta) e' + U Ki e = 0`` (ILOS: ``U sigma / Delta^2`` for ``U Ki``); critical
damping needs ``Ki = U / (4 Delta^2)`` and ``sigma = U / 4``, the defaults at ``design_speed``.
Without integral action a cross current ``V_c`` leaves the steady cross-track error
``e_ss = Delta V_c / sqrt(U^2 - V_c^2)``.

Segments. On a :class:`~controllers.paths.WaypointPath` the guidance follows one leg at a time
and switches to the next when the ship enters the circle of acceptance of the leg's end
waypoint (``switching="circle"``, radius ``acceptance_radius``) or when its along-track
distance on the leg passes the leg length (``switching="along_track"``). On continuous paths
(:class:`~controllers.paths.FilletPath`, :class:`~controllers.paths.SplinePath`) it uses the
closest path point, searched near the previous one and never moving backwards. Past the last
waypoint the guidance keeps following the extension of the path's end tangent and reports
``finished``.

Batches. Both laws run on a batch of ships: given one path per ship they take positions of
shape ``(n, 2)`` and yaw rates of shape ``(n,)`` and return ``chi_d`` of shape ``(n,)``; given
one path they take one ship's measurements and return floats. One ship is a batch of one of the
same code, and every row of a batch gives bitwise the floats of that ship run alone (the
transcendental functions come from :mod:`math`, element by element, where NumPy's SIMD versions
round the last bit differently). In a batch of :class:`~controllers.paths.WaypointPath` the leg
tables are padded to the longest path and every ship switches legs on its own; continuous paths
are followed ship by ship with the same code.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from controllers._angles import (
    constant,
    finite_batch,
    math_elementwise,
    nonnegative,
    positive,
    ssa_array,
)
from controllers.paths import Path, WaypointPath

__all__ = ["INTEGRATOR_MODES", "IntegralLOS", "LOSGuidance"]

#: Names of the conditional integrator's modes; :attr:`LOSGuidance.integrator_mode_code` holds
#: indices into this tuple.
INTEGRATOR_MODES: tuple[str, ...] = ("off", "frozen", "soft", "linear")
_OFF, _FROZEN, _SOFT, _LINEAR = (np.array(i, dtype=np.int8) for i in range(len(INTEGRATOR_MODES)))

_PATH_KINDS = "controllers.paths.Path (WaypointPath, FilletPath, SplinePath)"


def _as_paths(path: Path | Sequence[Path]) -> tuple[tuple[Path, ...], bool]:
    """The paths, one per ship, and whether a batch (a sequence) was given."""
    if isinstance(path, Path):
        return (path,), False
    if isinstance(path, str) or not isinstance(path, Sequence):
        raise ValueError(
            f"path must be a {_PATH_KINDS} or a sequence of them (one per ship), got "
            f"{type(path).__name__}"
        )
    if len(path) == 0:
        raise ValueError("path must hold at least one path (one per ship), got an empty sequence")
    for i, p in enumerate(path):
        if not isinstance(p, Path):
            raise ValueError(f"path[{i}] must be a {_PATH_KINDS}, got {type(p).__name__}")
    kinds = [isinstance(p, WaypointPath) for p in path]
    if any(kinds) and not all(kinds):
        i, j = kinds.index(True), kinds.index(False)
        raise ValueError(
            f"path must hold only WaypointPaths or only continuous paths (FilletPath, "
            f"SplinePath), got {type(path[i]).__name__} at {i} and {type(path[j]).__name__} "
            f"at {j}"
        )
    return tuple(path), True


class _LOSBase:
    """Path bookkeeping shared by the LOS laws: cross-track error, segment, switching."""

    def __init__(
        self,
        path: Path | Sequence[Path],
        lookahead: float,
        *,
        switching: str = "along_track",
        acceptance_radius: float | None = None,
    ) -> None:
        paths, self._batch = _as_paths(path)
        if switching not in ("circle", "along_track"):
            raise ValueError(f"switching must be 'circle' or 'along_track', got {switching!r}")
        self.path = path if not self._batch else paths
        self.paths = paths
        self.n_ships = len(paths)
        self.lookahead = positive("lookahead", lookahead)
        self.switching = switching
        self.acceptance_radius = (
            self.lookahead
            if acceptance_radius is None
            else positive("acceptance_radius", acceptance_radius)
        )
        self._radius = constant(self.acceptance_radius)
        self._radius_ulps = constant(4.0 * np.spacing(self.acceptance_radius))
        waypoint_paths = [p for p in paths if isinstance(p, WaypointPath)]
        self._is_waypoint = bool(waypoint_paths)
        if self._is_waypoint:
            self._tabulate_legs(waypoint_paths)
        else:
            self._stations = [p.waypoint_s for p in paths]
            self._lengths = np.array([p.length for p in paths])
        self.reset()

    def _tabulate_legs(self, paths: Sequence[WaypointPath]) -> None:
        """Waypoint and leg tables of all ships, one row of ``m + 1`` entries per ship (``m``
        legs of the longest path, padded with NaN), flattened: ship ``i``'s leg ``k`` is
        entry ``(m + 1) i + k``."""
        n_legs = np.array([len(p.waypoints) - 1 for p in paths])
        n, width = len(paths), int(n_legs.max()) + 1
        wp = np.full((n, width, 2), np.nan)
        leg_s, leg_len, leg_chi, cos, sin = np.full((5, n, width), np.nan)
        for i, p in enumerate(paths):
            k = n_legs[i]
            wp[i, : k + 1] = p.waypoints
            leg_s[i, : k + 1] = p.waypoint_s
            leg_len[i, :k] = p.leg_lengths
            leg_chi[i, :k] = p.leg_angles
            cos[i, :k] = [math.cos(chi) for chi in p.leg_angles]
            sin[i, :k] = [math.sin(chi) for chi in p.leg_angles]
        self._wp = wp.reshape(-1, 2)
        self._leg_s, self._leg_len, self._leg_chi, self._cos, self._sin = (
            a.ravel() for a in (leg_s, leg_len, leg_chi, cos, sin)
        )
        self._row_start = width * np.arange(n)
        self._last = n_legs - 1

    def reset(self) -> None:
        """Start over: first segment, no time history, integrator state zero."""
        n = self.n_ships
        self._t: float | None = None
        self._segment = np.zeros(n, dtype=np.intp)
        self._s = np.full(n, np.nan)  # continuous paths: the station of the last update
        self._finished = np.zeros(n, dtype=bool)
        nan = np.full(n, np.nan)  # read-out arrays are replaced, never written into
        self._e = self._along = self._chi_p = self._chi_r = self._chi_d = nan
        self._reset_integrator()

    def _out(self, a: np.ndarray) -> float | int | bool | np.ndarray:
        """A read-out: the array in a batch, its one element as a Python scalar otherwise."""
        return a if self._batch else a.item(0)

    # --------------------------------------------------------------------- read-outs
    @property
    def cross_track_error(self) -> float | np.ndarray:
        """Cross-track error ``e`` [m] at the last update (positive: ship to starboard)."""
        return self._out(self._e)

    @property
    def along_track(self) -> float | np.ndarray:
        """Along-track position [m] on the whole path at the last update.

        Arc length of the path point abeam of the ship; before the start or past the end it
        continues along the end tangents (negative before the start, above ``length`` after
        the end). On a :class:`WaypointPath` it is the station of the active leg's start plus
        the along-track distance on that leg.
        """
        return self._out(self._along)

    @property
    def chi_p(self) -> float | np.ndarray:
        """Path angle ``chi_p`` [rad] used at the last update."""
        return self._out(self._chi_p)

    @property
    def chi_r(self) -> float | np.ndarray:
        """Cross-track correction ``chi_r = chi_d - chi_p`` [rad] of the last update."""
        return self._out(self._chi_r)

    @property
    def chi_d(self) -> float | np.ndarray:
        """Desired course ``chi_d`` [rad] of the last update, in ``[-pi, pi)``."""
        return self._out(self._chi_d)

    @property
    def segment(self) -> int | np.ndarray:
        """Index of the active segment: leg from waypoint ``k`` to ``k + 1``."""
        return self._out(self._segment)

    @property
    def finished(self) -> bool | np.ndarray:
        """True once the ship has reached the end of the path (stays True until reset)."""
        return self._out(self._finished)

    # --------------------------------------------------------------------- update
    def update(
        self,
        t: float,
        position: npt.ArrayLike,
        psi: npt.ArrayLike = 0.0,
        r: npt.ArrayLike = 0.0,
    ) -> float | np.ndarray:
        """Desired course ``chi_d`` [rad] in ``[-pi, pi)`` for the measurement at time ``t``.

        Parameters
        ----------
        t : float
            Time [s], one for the whole batch; non-decreasing between calls (the integrators
            use the difference).
        position : array_like
            Ship position ``(north, east)`` [m]: shape ``(2,)`` for one path, ``(n, 2)`` for a
            batch of ``n`` paths.
        psi : float or array_like
            Heading [rad], one per ship (a scalar is used for every ship). Not used by the
            guidance law (accepted so that every controller takes the same measurements).
        r : float or array_like
            Yaw rate [rad/s], one per ship (a scalar is used for every ship); the conditional
            integrator of :class:`LOSGuidance` stops while ``|r| > r_lim``.

        Returns
        -------
        float or numpy.ndarray
            ``chi_d = chi_p + chi_r`` [rad]: a float for one path, shape ``(n,)`` for a batch.
        """
        try:
            tt = float(t)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"t must be a time [s], got {t!r}") from exc
        if not math.isfinite(tt):
            raise ValueError(f"t must be finite [s], got {t!r}")
        if self._t is not None and tt < self._t:
            raise ValueError(f"t must not decrease: got {tt!r} s after {self._t!r} s")
        dt = 0.0 if self._t is None else tt - self._t
        n = self.n_ships if self._batch else None
        p = finite_batch("position", position, n, per_ship=(2,), broadcast=False)
        rr = finite_batch("r", r, n)
        finite_batch("psi", psi, n)
        self._t = tt
        if self._is_waypoint:
            self._locate_waypoints(p)
        else:
            self._locate_continuous(p)
        self._chi_r = self._correction(self._e, rr, dt)
        self._chi_d = ssa_array(self._chi_p + self._chi_r)
        return self._out(self._chi_d)

    __call__ = update

    def _locate_waypoints(self, p: npt.NDArray[np.float64]) -> None:
        """Switch legs (as often as needed in one update) and measure on the active legs."""
        k = self._segment
        while True:
            leg = self._row_start + k
            cos, sin = self._cos[leg], self._sin[leg]
            d = p - self._wp[leg]
            along = d[:, 0] * cos + d[:, 1] * sin
            if self.switching == "circle":
                reached = self._within_acceptance(p - self._wp[leg + 1])
            else:
                reached = along >= self._leg_len[leg]
            switch = reached & (k < self._last)
            if not switch.any():
                break
            k = k + switch
        self._finished = self._finished | reached  # every ship that reached is on its last leg
        self._segment = k
        self._chi_p = self._leg_chi[leg]
        self._e = -d[:, 0] * sin + d[:, 1] * cos
        self._along = self._leg_s[leg] + along

    def _within_acceptance(self, d: npt.NDArray[np.float64]) -> npt.NDArray[np.bool_]:
        """``hypot(d) <= acceptance_radius`` row by row, decided as :func:`math.hypot` does.

        NumPy's ``hypot`` and :func:`math.hypot` are both accurate to under one ulp, so they
        can only decide differently within a few ulps of the radius: those rows are measured
        again with :func:`math.hypot`.
        """
        radius = self._radius
        dist = np.hypot(d[:, 0], d[:, 1])
        near = np.abs(dist - radius) <= self._radius_ulps
        if near.any():
            dist[near] = math_elementwise(math.hypot, d[near, 0], d[near, 1])
        return dist <= radius

    def _locate_continuous(self, p: npt.NDArray[np.float64]) -> None:
        """Closest point on each ship's continuous path, never moving backwards."""
        n = self.n_ships
        s_new, chi_p, e, along = (np.empty(n) for _ in range(4))
        segment = np.empty(n, dtype=np.intp)
        for i, path in enumerate(self.paths):
            pi, s_prev = p[i], self._s[i]
            if math.isnan(s_prev):
                s, _ = path.closest(pi)
            else:
                s, _ = path.closest(pi, s_hint=s_prev)
                s = max(s, s_prev)  # monotone progress along the path
            d = pi - path.point(s)
            chi = float(path.tangent_angle(s))
            s_new[i], chi_p[i] = s, chi
            e[i] = -d[0] * math.sin(chi) + d[1] * math.cos(chi)
            along[i] = s
            if s <= 0.0 or s >= path.length:  # continue along the end tangent
                along[i] = s + float(d[0] * math.cos(chi) + d[1] * math.sin(chi))
            stations = self._stations[i]
            k = int(np.searchsorted(stations, s, side="right")) - 1
            segment[i] = min(max(k, 0), len(stations) - 2)
        self._s, self._chi_p, self._e, self._along, self._segment = s_new, chi_p, e, along, segment
        self._finished = self._finished | (along >= self._lengths)

    # --------------------------------------------------------------------- the law
    def _reset_integrator(self) -> None:
        raise NotImplementedError

    def _correction(
        self, e: npt.NDArray[np.float64], r: npt.NDArray[np.float64], dt: float
    ) -> npt.NDArray[np.float64]:
        raise NotImplementedError


class LOSGuidance(_LOSBase):
    """Lookahead LOS with the conditional integrator of seed 004 eq. (9)-(10).

    ``chi_d = chi_p - atan(e / Delta + I)``; see the module docstring for ``I``.

    Parameters
    ----------
    path : controllers.paths.Path or sequence of WaypointPath
        The path to follow, or one path per ship for a batch (module docstring).
    lookahead : float
        Lookahead distance ``Delta`` [m] > 0; ``Kp = 1 / Delta``.
    ki : float, optional
        Integral gain ``Ki`` [1/(m s)] >= 0. Default ``design_speed / (4 Delta^2)`` (critical
        damping of the linearised loop).
    r_lim : float
        The integrator stops while ``|r| > r_lim`` [rad/s] (``inf``: never).
    e_lim : float, optional
        The integrator stops while ``|e| > e_lim`` [m] (``inf``: never). Default ``Delta``.
    i_max : float
        Soft limit ``I_max`` [-] of the integral (``atan(I_max)`` is the crab angle it can
        supply at full rate). Beyond it, winding further is slowed.
    k1, k2 : float
        Soft saturation ``e_i = e / (k1 + k2 |I| / I_max)`` beyond ``I_max``; ``k1, k2 >= 0``
        and ``k1 + k2 >= 1`` (so it always slows).
    i_hard : float, optional
        Hard anti-windup bound: ``|I| <= i_hard``; default ``2 i_max``; must be ``>= i_max``.
    integral : bool
        ``False`` ablates the integrator (pure lookahead LOS, ``I = 0``).
    design_speed : float
        Speed ``U`` [m/s] for the default ``ki``.
    switching : {"along_track", "circle"}
        Leg switching on a :class:`~controllers.paths.WaypointPath` (ignored on continuous
        paths).
    acceptance_radius : float, optional
        Circle of acceptance [m] for ``switching="circle"``; default ``Delta``.

    Attributes
    ----------
    paths : tuple of controllers.paths.Path
        One path per ship (one entry when a single path was given).
    n_ships : int
        Ships guided. The read-outs (``chi_d``, ``chi_p``, ``chi_r``, ``cross_track_error``,
        ``along_track``, ``segment``, ``finished`` and those below) are Python scalars for a
        single path and arrays of shape ``(n_ships,)`` for a batch.
    integrator : float or numpy.ndarray
        The integral state ``I`` [-] after the last update.
    integrator_input : float or numpy.ndarray
        ``e_i`` [m] of the last update.
    integrator_mode : str or numpy.ndarray
        ``"off"`` (ablated), ``"frozen"`` (``|r| > r_lim`` or ``|e| > e_lim``), ``"soft"``
        (soft saturation) or ``"linear"``; an array of these strings for a batch.
    integrator_mode_code : int or numpy.ndarray
        The same as indices into :data:`INTEGRATOR_MODES`.

    Examples
    --------
    >>> from controllers.paths import WaypointPath
    >>> los = LOSGuidance(WaypointPath([[0, 0], [1000, 0]]), lookahead=100.0)
    >>> round(los.update(0.0, (0.0, 100.0), psi=0.0, r=0.0), 4)  # 100 m east: steer west
    -0.7854

    A batch: one path per ship, one row per ship.

    >>> batch = LOSGuidance([WaypointPath([[0, 0], [1000, 0]])] * 2, lookahead=100.0)
    >>> batch.update(0.0, [[0.0, 100.0], [0.0, -100.0]]).round(4)
    array([-0.7854,  0.7854])
    """

    def __init__(
        self,
        path: Path | Sequence[Path],
        lookahead: float,
        *,
        ki: float | None = None,
        r_lim: float = 0.01,
        e_lim: float | None = None,
        i_max: float = 0.3,
        k1: float = 1.0,
        k2: float = 1.0,
        i_hard: float | None = None,
        integral: bool = True,
        design_speed: float = 5.0,
        switching: str = "along_track",
        acceptance_radius: float | None = None,
    ) -> None:
        delta = positive("lookahead", lookahead)
        self.design_speed = positive("design_speed", design_speed)
        self.ki = self.design_speed / (4.0 * delta**2) if ki is None else nonnegative("ki", ki)
        self.r_lim = positive("r_lim", r_lim, allow_inf=True)
        self.e_lim = delta if e_lim is None else positive("e_lim", e_lim, allow_inf=True)
        self.i_max = positive("i_max", i_max)
        self.k1 = nonnegative("k1", k1)
        self.k2 = nonnegative("k2", k2)
        if self.k1 + self.k2 < 1.0:
            raise ValueError(
                f"k1 + k2 must be >= 1 so that the soft saturation slows the integrator, got "
                f"k1={k1!r}, k2={k2!r}"
            )
        self.i_hard = 2.0 * self.i_max if i_hard is None else positive("i_hard", i_hard)
        if self.i_hard < self.i_max:
            raise ValueError(f"i_hard must be >= i_max = {self.i_max!r}, got {i_hard!r}")
        if not isinstance(integral, bool | np.bool_):
            raise ValueError(f"integral must be True or False, got {integral!r}")
        self.integral_enabled = bool(integral)
        # the law's numbers as 0-d arrays (faster with NumPy arrays, the same values)
        self._c = {
            name: constant(value)
            for name, value in (
                ("r_lim", self.r_lim), ("e_lim", self.e_lim), ("i_max", self.i_max),
                ("-i_max", -self.i_max), ("k1", self.k1), ("k2", self.k2), ("ki", self.ki),
                ("i_hard", self.i_hard), ("-i_hard", -self.i_hard), ("delta", delta),
            )
        }  # fmt: skip
        super().__init__(path, delta, switching=switching, acceptance_radius=acceptance_radius)

    @property
    def integrator(self) -> float | np.ndarray:
        """Integral state ``I`` [-] after the last update."""
        return self._out(self._I)

    @property
    def integrator_input(self) -> float | np.ndarray:
        """``e_i`` [m] used by the last update."""
        return self._out(self._e_i)

    @property
    def integrator_mode(self) -> str | np.ndarray:
        """``"off"``, ``"frozen"``, ``"soft"`` or ``"linear"`` at the last update."""
        return self._out(np.asarray(INTEGRATOR_MODES)[self._mode])

    @property
    def integrator_mode_code(self) -> int | np.ndarray:
        """:attr:`integrator_mode` as indices into :data:`INTEGRATOR_MODES`."""
        return self._out(self._mode)

    def _reset_integrator(self) -> None:
        n = self.n_ships
        self._I = np.zeros(n)  # stays zero, and the mode "off", when the integrator is ablated
        self._e_i = np.zeros(n)
        self._mode = np.full(n, _LINEAR if self.integral_enabled else _OFF, dtype=np.int8)

    def _correction(
        self, e: npt.NDArray[np.float64], r: npt.NDArray[np.float64], dt: float
    ) -> npt.NDArray[np.float64]:
        c = self._c
        if self.integral_enabled:
            big_i = self._I
            frozen = (np.abs(r) > c["r_lim"]) | (np.abs(e) > c["e_lim"])
            beyond = ((big_i > c["i_max"]) & (e > 0.0)) | ((big_i < c["-i_max"]) & (e < 0.0))
            soft = beyond & ~frozen
            e_i = np.where(frozen, 0.0, e)
            if soft.any():  # e / (k1 + k2 |I| / I_max) there (the divisor is > 0 there)
                slow = c["k1"] + c["k2"] * np.abs(big_i) / c["i_max"]
                np.divide(e, slow, out=e_i, where=soft)
            self._mode = np.where(frozen, _FROZEN, np.where(soft, _SOFT, _LINEAR))
            self._e_i = e_i
            big_i = big_i + c["ki"] * e_i * dt
            self._I = np.minimum(np.maximum(big_i, c["-i_hard"]), c["i_hard"])
        return -math_elementwise(math.atan, e / c["delta"] + self._I)


class IntegralLOS(_LOSBase):
    """Integral LOS of Borhaug et al. (2008), same interface as :class:`LOSGuidance`.

    ``chi_d = chi_p - atan((e + sigma e_int) / Delta)`` and
    ``e_int' = Delta e / ((e + sigma e_int)^2 + Delta^2)`` (forward in time with the update
    interval).

    Parameters
    ----------
    path : controllers.paths.Path or sequence of WaypointPath
        The path to follow, or one path per ship for a batch (module docstring).
    lookahead : float
        ``Delta`` [m] > 0.
    sigma : float, optional
        Integral gain ``sigma`` [m/s] >= 0; default ``design_speed / 4`` (critical damping of
        the linearised loop).
    design_speed : float
        Speed ``U`` [m/s] for the default ``sigma``.
    switching, acceptance_radius
        As for :class:`LOSGuidance`.

    Attributes
    ----------
    paths, n_ships
        As for :class:`LOSGuidance`.
    integrator : float or numpy.ndarray
        The state ``e_int`` [s] after the last update (``sigma e_int`` is in metres).
    """

    def __init__(
        self,
        path: Path | Sequence[Path],
        lookahead: float,
        *,
        sigma: float | None = None,
        design_speed: float = 5.0,
        switching: str = "along_track",
        acceptance_radius: float | None = None,
    ) -> None:
        self.design_speed = positive("design_speed", design_speed)
        self.sigma = 0.25 * self.design_speed if sigma is None else nonnegative("sigma", sigma)
        super().__init__(path, lookahead, switching=switching, acceptance_radius=acceptance_radius)
        delta = self.lookahead
        self._c = {"sigma": constant(self.sigma), "delta": constant(delta)}
        self._c["delta^2"] = constant(delta * delta)

    @property
    def integrator(self) -> float | np.ndarray:
        """The state ``e_int`` [s] after the last update."""
        return self._out(self._e_int)

    def _reset_integrator(self) -> None:
        self._e_int = np.zeros(self.n_ships)

    def _correction(
        self, e: npt.NDArray[np.float64], r: npt.NDArray[np.float64], dt: float
    ) -> npt.NDArray[np.float64]:
        c = self._c
        z = e + c["sigma"] * self._e_int
        self._e_int = self._e_int + dt * self.lookahead * e / (z * z + c["delta^2"])
        return -math_elementwise(math.atan, (e + c["sigma"] * self._e_int) / c["delta"])

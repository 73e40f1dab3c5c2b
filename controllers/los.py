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
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from controllers._angles import nonnegative, positive, ssa
from controllers.paths import Path, WaypointPath

__all__ = ["IntegralLOS", "LOSGuidance"]


class _LOSBase:
    """Path bookkeeping shared by the LOS laws: cross-track error, segment, switching."""

    def __init__(
        self,
        path: Path,
        lookahead: float,
        *,
        switching: str = "along_track",
        acceptance_radius: float | None = None,
    ) -> None:
        if not isinstance(path, Path):
            raise ValueError(
                f"path must be a controllers.paths.Path (WaypointPath, FilletPath, SplinePath), "
                f"got {type(path).__name__}"
            )
        if switching not in ("circle", "along_track"):
            raise ValueError(f"switching must be 'circle' or 'along_track', got {switching!r}")
        self.path = path
        self.lookahead = positive("lookahead", lookahead)
        self.switching = switching
        self.acceptance_radius = (
            self.lookahead
            if acceptance_radius is None
            else positive("acceptance_radius", acceptance_radius)
        )
        self._is_waypoint = isinstance(path, WaypointPath)
        if self._is_waypoint:
            wp = path.waypoints
            self._wp = wp
            self._leg_len = path.leg_lengths
            self._leg_chi = path.leg_angles
            self._leg_s = path.waypoint_s
        self._wp_s = path.waypoint_s
        self.reset()

    def reset(self) -> None:
        """Start over: first segment, no time history, integrator state zero."""
        self._t: float | None = None
        self._segment = 0
        self._s: float | None = None
        self._finished = False
        self._e = math.nan
        self._along = math.nan
        self._chi_p = math.nan
        self._chi_r = math.nan
        self._chi_d = math.nan
        self._reset_integrator()

    # --------------------------------------------------------------------- read-outs
    @property
    def cross_track_error(self) -> float:
        """Cross-track error ``e`` [m] at the last update (positive: ship to starboard)."""
        return self._e

    @property
    def along_track(self) -> float:
        """Along-track position [m] on the whole path at the last update.

        Arc length of the path point abeam of the ship; before the start or past the end it
        continues along the end tangents (negative before the start, above ``length`` after
        the end). On a :class:`WaypointPath` it is the station of the active leg's start plus
        the along-track distance on that leg.
        """
        return self._along

    @property
    def chi_p(self) -> float:
        """Path angle ``chi_p`` [rad] used at the last update."""
        return self._chi_p

    @property
    def chi_r(self) -> float:
        """Cross-track correction ``chi_r = chi_d - chi_p`` [rad] of the last update."""
        return self._chi_r

    @property
    def chi_d(self) -> float:
        """Desired course ``chi_d`` [rad] of the last update, in ``[-pi, pi)``."""
        return self._chi_d

    @property
    def segment(self) -> int:
        """Index of the active segment: leg from waypoint ``k`` to ``k + 1``."""
        return self._segment

    @property
    def finished(self) -> bool:
        """True once the ship has reached the end of the path (stays True until reset)."""
        return self._finished

    # --------------------------------------------------------------------- update
    def update(self, t: float, position: npt.ArrayLike, psi: float = 0.0, r: float = 0.0) -> float:
        """Desired course ``chi_d`` [rad] in ``[-pi, pi)`` for the measurement at time ``t``.

        Parameters
        ----------
        t : float
            Time [s]; non-decreasing between calls (the integrators use the difference).
        position : array_like
            Ship position ``(north, east)`` [m].
        psi : float
            Heading [rad]. Not used by the guidance law (accepted so that every controller
            takes the same measurements).
        r : float
            Yaw rate [rad/s]; the conditional integrator of :class:`LOSGuidance` stops while
            ``|r| > r_lim``.

        Returns
        -------
        float
            ``chi_d = chi_p + chi_r`` [rad].
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
        p = np.asarray(position, dtype=np.float64)
        if p.shape != (2,) or not np.all(np.isfinite(p)):
            raise ValueError(f"position must be a finite (north, east) pair [m], got {position!r}")
        try:
            rr = float(r)
            float(psi)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"psi and r must be numbers [rad, rad/s], got {psi!r}, {r!r}") from exc
        if not math.isfinite(rr):
            raise ValueError(f"r must be a finite yaw rate [rad/s], got {r!r}")
        self._t = tt
        if self._is_waypoint:
            self._locate_waypoint(p)
        else:
            self._locate_continuous(p)
        self._chi_r = self._correction(self._e, rr, dt)
        self._chi_d = ssa(self._chi_p + self._chi_r)
        return self._chi_d

    __call__ = update

    def _locate_waypoint(self, p: npt.NDArray[np.float64]) -> None:
        k = self._segment
        last = len(self._leg_len) - 1
        while True:
            chi = self._leg_chi[k]
            d = p - self._wp[k]
            along = d[0] * math.cos(chi) + d[1] * math.sin(chi)
            if self.switching == "circle":
                reached = math.hypot(*(p - self._wp[k + 1])) <= self.acceptance_radius
            else:
                reached = along >= self._leg_len[k]
            if not reached or k == last:
                if reached:
                    self._finished = True
                break
            k += 1
        self._segment = k
        self._chi_p = float(self._leg_chi[k])
        self._e = float(-d[0] * math.sin(chi) + d[1] * math.cos(chi))
        self._along = float(self._leg_s[k] + along)

    def _locate_continuous(self, p: npt.NDArray[np.float64]) -> None:
        path = self.path
        if self._s is None:
            s, _ = path.closest(p)
        else:
            s, _ = path.closest(p, s_hint=self._s)
            s = max(s, self._s)  # monotone progress along the path
        self._s = s
        pp = path.point(s)
        chi = float(path.tangent_angle(s))
        d = p - pp
        self._chi_p = chi
        self._e = float(-d[0] * math.sin(chi) + d[1] * math.cos(chi))
        along = s
        if s <= 0.0 or s >= path.length:  # continue along the end tangent
            along = s + float(d[0] * math.cos(chi) + d[1] * math.sin(chi))
        self._along = float(along)
        if self._along >= path.length:
            self._finished = True
        k = int(np.searchsorted(self._wp_s, s, side="right")) - 1
        self._segment = min(max(k, 0), len(self._wp_s) - 2)

    # --------------------------------------------------------------------- the law
    def _reset_integrator(self) -> None:
        raise NotImplementedError

    def _correction(self, e: float, r: float, dt: float) -> float:
        raise NotImplementedError


class LOSGuidance(_LOSBase):
    """Lookahead LOS with the conditional integrator of seed 004 eq. (9)-(10).

    ``chi_d = chi_p - atan(e / Delta + I)``; see the module docstring for ``I``.

    Parameters
    ----------
    path : controllers.paths.Path
        The path to follow.
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
    integrator : float
        The integral state ``I`` [-] after the last update.
    integrator_input : float
        ``e_i`` [m] of the last update.
    integrator_mode : str
        ``"off"`` (ablated), ``"frozen"`` (``|r| > r_lim`` or ``|e| > e_lim``), ``"soft"``
        (soft saturation) or ``"linear"``.

    Examples
    --------
    >>> from controllers.paths import WaypointPath
    >>> los = LOSGuidance(WaypointPath([[0, 0], [1000, 0]]), lookahead=100.0)
    >>> round(los.update(0.0, (0.0, 100.0), psi=0.0, r=0.0), 4)  # 100 m east: steer west
    -0.7854
    """

    def __init__(
        self,
        path: Path,
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
        super().__init__(path, delta, switching=switching, acceptance_radius=acceptance_radius)

    @property
    def integrator(self) -> float:
        """Integral state ``I`` [-] after the last update."""
        return self._I

    @property
    def integrator_input(self) -> float:
        """``e_i`` [m] used by the last update."""
        return self._e_i

    @property
    def integrator_mode(self) -> str:
        """``"off"``, ``"frozen"``, ``"soft"`` or ``"linear"`` at the last update."""
        return self._mode

    def _reset_integrator(self) -> None:
        self._I = 0.0
        self._e_i = 0.0
        self._mode = "off" if not self.integral_enabled else "linear"

    def _correction(self, e: float, r: float, dt: float) -> float:
        if not self.integral_enabled:
            self._mode, self._e_i = "off", 0.0
        else:
            big_i = self._I
            if abs(r) > self.r_lim or abs(e) > self.e_lim:
                self._mode, e_i = "frozen", 0.0
            elif (big_i > self.i_max and e > 0.0) or (big_i < -self.i_max and e < 0.0):
                self._mode = "soft"
                e_i = e / (self.k1 + self.k2 * abs(big_i) / self.i_max)
            else:
                self._mode, e_i = "linear", e
            self._e_i = e_i
            big_i += self.ki * e_i * dt
            self._I = min(max(big_i, -self.i_hard), self.i_hard)
        return -math.atan(e / self.lookahead + self._I)


class IntegralLOS(_LOSBase):
    """Integral LOS of Borhaug et al. (2008), same interface as :class:`LOSGuidance`.

    ``chi_d = chi_p - atan((e + sigma e_int) / Delta)`` and
    ``e_int' = Delta e / ((e + sigma e_int)^2 + Delta^2)`` (forward in time with the update
    interval).

    Parameters
    ----------
    path : controllers.paths.Path
        The path to follow.
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
    integrator : float
        The state ``e_int`` [s] after the last update (``sigma e_int`` is in metres).
    """

    def __init__(
        self,
        path: Path,
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

    @property
    def integrator(self) -> float:
        """The state ``e_int`` [s] after the last update."""
        return self._e_int

    def _reset_integrator(self) -> None:
        self._e_int = 0.0

    def _correction(self, e: float, r: float, dt: float) -> float:
        delta = self.lookahead
        z = e + self.sigma * self._e_int
        self._e_int += dt * delta * e / (z * z + delta * delta)
        return -math.atan((e + self.sigma * self._e_int) / delta)

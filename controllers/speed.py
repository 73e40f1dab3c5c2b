r"""PI speed autopilot with steady-state feed-forward (seed 004 section 1.2, eq. 8).

Control law::

    e  = u_ref - u
    c  = c_ff(u_ref) + Kp e + Ki integral(e dt)

limited to ``[min_command, max_command]`` (the upper limit may depend on the speed, e.g. the
thrust limit ``T_bollard (1 - u_r / u_0)`` of the Gunnerus pods) and optionally to a rate
``|dc/dt| <= max_rate``. ``c_ff`` is the steady command that holds ``u_ref``; with an exact
feed-forward the PI only has to remove the transient and model errors. Anti-windup as in the
heading autopilot (back-calculation by default; ``controllers._angles``).

The autopilot runs a batch of ships with the same gains and limits: its states are arrays
``(n,)``, one entry per ship, and one ship is a batch of one of the same code (numbers in,
a float out). The feed-forward and a speed-dependent limit are then called with arrays, so
they must work elementwise (the functions below do).

Feed-forward models (no ``shipgym`` import: give numbers or a callable):

* quadratic drag (Gunnerus, seed 001 eq. 15 in calm water with ``v = r = 0``):
  ``X = d1 u + d2 u|u|`` total surge force, so a pod of two gets ``share = 0.5`` of it
  (``d1 = 1117.6 N s/m``, ``d2 = 1671.6 N s^2/m^2``): :func:`quadratic_drag_feedforward`;
* the linear surge model of seed 004 eq. 8, ``U' = (K_u n - U) / T_u``: ``n = U / K_u``
  (:func:`linear_feedforward`).

Gains by pole placement on a first-order model ``u / c = K / (1 + T s)`` (seed 004 eq. 8):
the closed loop ``T s^2 + (1 + K Kp) s + K Ki = 0`` equals ``T (s^2 + 2 zeta w_n s + w_n^2)``
for ``Kp = (2 zeta w_n T - 1) / K`` and ``Ki = w_n^2 T / K``
(:meth:`SpeedAutopilot.from_first_order`).
A quadratic-drag plant is linearised at a design speed ``u0``: ``m du' = dc / share -
(d1 + 2 d2 |u0|) du``, so ``K = 1 / (share d_lin)`` and ``T = m / d_lin``
(:func:`linearised_drag_model`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

from controllers._angles import (
    BatchValue,
    StepClock,
    anti_windup_mode,
    batch_size,
    batch_value,
    bounds,
    clip,
    constant,
    finite,
    finite_batch,
    integrate_with_anti_windup,
    nonnegative,
    optional_limit,
    positive,
    rate_limit,
    tracking_time,
)

__all__ = [
    "SpeedAutopilot",
    "linear_feedforward",
    "linearised_drag_model",
    "quadratic_drag_feedforward",
]

#: A function of the speed [m/s], a float or an array of speeds (one per ship) to as many values.
SpeedFunction = Callable[[ArrayLike], ArrayLike]
Limit = float | SpeedFunction | None


def quadratic_drag_feedforward(d1: float, d2: float = 0.0, *, share: float = 1.0) -> SpeedFunction:
    """Feed-forward ``c_ff(u) = share (d1 u + d2 u|u|)``: the force that balances the drag
    (elementwise for an array of speeds).

    Parameters
    ----------
    d1 : float
        Linear surge damping [N s/m] (>= 0).
    d2 : float
        Quadratic surge damping [N s^2/m^2] (>= 0).
    share : float
        Fraction of the total force one command gives (0.5 per pod when two equal pods
        share the load; 1 for a total-force command).
    """
    d1 = nonnegative("d1", d1)
    d2 = nonnegative("d2", d2)
    share = positive("share", share)

    def feedforward(u: ArrayLike) -> ArrayLike:
        return share * (d1 * u + d2 * u * abs(u))

    return feedforward


def linear_feedforward(gain: float) -> SpeedFunction:
    """Feed-forward ``c_ff(u) = u / gain`` of a linear steady relation ``u = gain * c``
    (elementwise for an array of speeds).

    For the Nomoto-family surge model ``U' = (K_u n - U) / T_u`` the gain is ``K_u`` [m/s per
    rev/s] and the command is the shaft speed ``n`` [rev/s].
    """
    gain = finite("gain", gain)
    if gain == 0:
        raise ValueError("feed-forward gain must be non-zero, got 0")

    def feedforward(u: ArrayLike) -> ArrayLike:
        return u / gain

    return feedforward


def linearised_drag_model(
    mass: float, d1: float, d2: float, u0: float, *, share: float = 1.0
) -> tuple[float, float]:
    """First-order model ``(K, T)`` of ``m u' = c / share - d1 u - d2 u|u|`` at speed ``u0``.

    Parameters
    ----------
    mass : float
        Surge mass including added mass [kg] (``m + X_udot``).
    d1, d2 : float
        Linear [N s/m] and quadratic [N s^2/m^2] damping.
    u0 : float
        Design speed [m/s].
    share : float
        Fraction of the total force one command unit gives.

    Returns
    -------
    tuple of float
        ``K`` [m/s per command unit] and ``T`` [s].
    """
    mass = positive("mass", mass)
    d1 = nonnegative("d1", d1)
    d2 = nonnegative("d2", d2)
    u0 = finite("u0", u0)
    share = positive("share", share)
    d_lin = d1 + 2.0 * d2 * abs(u0)
    if d_lin <= 0:
        raise ValueError(f"damping at u0={u0!r} is zero; give d1 > 0 or u0 != 0")
    return 1.0 / (share * d_lin), mass / d_lin


class SpeedAutopilot:
    """PI speed autopilot with feed-forward, limits and anti-windup (module docstring), for
    one ship or a batch of ships with the same gains and limits.

    Parameters
    ----------
    kp : float
        Proportional gain [command per m/s].
    ki : float
        Integral gain [command per m].
    dt : float
        Nominal sample time [s] (used when :meth:`update` gets ``t=None``).
    feedforward : callable, optional
        ``c_ff(u_ref)``: the steady command for a speed; none by default. Called with a
        float for one ship and with an array ``(n,)`` for a batch (elementwise).
    min_command : float
        Lower command limit (``-inf`` by default; 0 for thrust that cannot reverse).
    max_command : float or callable, optional
        Upper command limit, a number or a function of the measured speed ``u`` (e.g. a
        thrust limit that falls with speed; called as ``feedforward`` is); none by default.
    max_rate : float, optional
        Command rate limit [command/s].
    anti_windup : {"back_calculation", "conditional", "none"} or bool
        As in :class:`~controllers.heading.HeadingAutopilot`.

    Attributes
    ----------
    error, integral, command, unsaturated_command, feedforward_command : float or ndarray
        Last speed error [m/s], error integral [m], applied and unlimited command, and the
        feed-forward part: floats for one ship, arrays ``(n,)`` for a batch.
    batch_size : int or None
        Ships in the batch; ``None`` for one ship (scalar mode).

    Notes
    -----
    The states are arrays of shape ``(n,)``; one ship is a batch of one of the same code.
    :meth:`reset` with arrays (``integral`` or ``command``) starts a batch; a reset with
    numbers leaves the choice to the next :meth:`update`: numbers run one ship (scalar mode,
    a float returned), arrays ``(n,)`` a batch of ``n`` (the reset's numbers are every
    ship's). Each ship of a batch gets exactly the numbers it would get alone.
    """

    error = BatchValue("Last speed error [m/s].")
    integral = BatchValue("Speed-error integral [m].")
    command = BatchValue("Last command after the limits.")
    unsaturated_command = BatchValue("Last command before the limits.")
    feedforward_command = BatchValue("Last feed-forward part of the command.")

    def __init__(
        self,
        kp: float,
        ki: float,
        dt: float,
        *,
        feedforward: SpeedFunction | None = None,
        min_command: float = -math.inf,
        max_command: Limit = None,
        max_rate: float | None = None,
        anti_windup: str | bool = "back_calculation",
    ) -> None:
        self.kp = finite("kp", kp)
        self.ki = finite("ki", ki)
        self._clock = StepClock(dt)
        self.dt = self._clock.dt
        if feedforward is not None and not callable(feedforward):
            raise ValueError(f"feedforward must be a callable u -> command, got {feedforward!r}")
        self.feedforward = feedforward
        try:
            self.min_command = float(min_command)
        except (TypeError, ValueError):
            self.min_command = math.nan
        if math.isnan(self.min_command) or self.min_command == math.inf:
            raise ValueError(f"min_command must be a number or -inf, got {min_command!r}")
        if max_command is None:
            self._max: float | SpeedFunction = math.inf
        elif callable(max_command):
            self._max = max_command
        else:
            mx = finite("max_command", max_command) if max_command != math.inf else math.inf
            if mx <= self.min_command:
                raise ValueError(
                    f"max_command={max_command!r} must be larger than min_command={min_command!r}"
                )
            self._max = mx
        self.max_rate = optional_limit("max_rate", max_rate)
        self.anti_windup = anti_windup_mode(anti_windup)
        self.tracking_time = tracking_time(self.kp, self.ki)
        self.reset()
        self._initialised = False

    @classmethod
    def from_first_order(
        cls,
        K: float,
        T: float,
        dt: float,
        *,
        omega_n: float,
        zeta: float = 1.0,
        feedforward: SpeedFunction | None = None,
        min_command: float = -math.inf,
        max_command: Limit = None,
        max_rate: float | None = None,
        anti_windup: str | bool = "back_calculation",
    ) -> SpeedAutopilot:
        """PI by pole placement on ``u / c = K / (1 + T s)`` (seed 004 eq. 8).

        Parameters
        ----------
        K : float
            Steady gain [m/s per command unit] (non-zero).
        T : float
            Time constant [s] (> 0).
        dt : float
            Sample time [s].
        omega_n, zeta : float
            Closed-loop natural frequency [rad/s] and damping.
        Other parameters
            As in :class:`SpeedAutopilot`.
        """
        K = finite("K", K)
        if K == 0:
            raise ValueError("surge gain K must be non-zero, got 0")
        T = positive("T", T)
        wn = positive("omega_n", omega_n)
        zeta = positive("zeta", zeta)
        kp = (2.0 * zeta * wn * T - 1.0) / K
        ki = wn * wn * T / K
        return cls(
            kp,
            ki,
            dt,
            feedforward=feedforward,
            min_command=min_command,
            max_command=max_command,
            max_rate=max_rate,
            anti_windup=anti_windup,
        )

    def max_command(self, u: ArrayLike) -> float | np.ndarray:
        """Upper command limit at measured speed ``u`` [m/s]: a float for a number, an array
        for an array of speeds (unless the limit is a constant)."""
        if not callable(self._max):
            return self._max
        if np.ndim(u) == 0:
            return float(self._max(u))
        return np.asarray(self._max(u), dtype=np.float64)

    def reset(
        self,
        *,
        t: float | None = None,
        integral: ArrayLike = 0.0,
        command: ArrayLike | None = None,
    ) -> None:
        """Restart: clear the integral (or set it), the rate limiter and the clock.

        Parameters
        ----------
        t : float, optional
            Time [s] of the restart (one for the batch); the next :meth:`update` integrates
            from it.
        integral : float or array_like
            Initial error integral [m]: a number, or one per ship (an array ``(n,)``, which
            starts a batch of ``n``).
        command : float or array_like, optional
            The actuator's present command, the start of the rate limiter (a number, or one
            per ship).

        Raises
        ------
        ValueError
            For a value that is not finite (an array names the index of the first bad
            entry) or arrays of different lengths.
        """
        n = batch_size(integral=integral, command=command)
        self._integral = finite_batch("integral", integral, n)
        shape = self._integral.shape
        self._command = np.full(shape, math.nan)
        if command is not None:
            self._command = finite_batch("command", command, n)
        self._unsaturated_command = self._command
        self._error = self._feedforward_command = np.zeros(shape)
        self._clock.reset(t)
        self.batch_size = n
        #: a reset with numbers leaves one ship or a batch to the next update
        self._size_open = n is None
        self._initialised = True

    def update(self, t: float | None, u: ArrayLike, u_ref: ArrayLike) -> float | np.ndarray:
        """One controller step; returns the command.

        Parameters
        ----------
        t : float or None
            Sample time [s] of the whole batch; the step is the difference to the previous
            ``t``.
        u : float or array_like
            Measured speed [m/s] (surge speed through the water, or over ground): a number
            for one ship, an array ``(n,)`` for a batch.
        u_ref : float or array_like
            Speed setpoint [m/s]; for a batch an array ``(n,)`` or one setpoint for all.

        Returns
        -------
        float or numpy.ndarray
            Command within the limits: a float for one ship, an array ``(n,)`` for a batch.

        Raises
        ------
        ValueError
            For a value that is not finite (an array names the index), a shape that is not
            the batch's (naming both shapes), a feed-forward that returns a value that is
            not finite, or a time that goes backwards.
        """
        if not self._initialised:
            self.reset()
        n = batch_size(u=u, u_ref=u_ref) if self._size_open else self.batch_size
        u_a = finite_batch("u", u, n, broadcast=False)
        u_ref_a = finite_batch("u_ref", u_ref, n)
        if self._size_open:
            if n is not None:  # the reset's numbers become every ship's
                self._integral = np.full(n, self._integral[0])
                self._command = self._unsaturated_command = np.full(n, self._command[0])
                self._error = self._feedforward_command = np.zeros(n)
            self.batch_size, self._size_open = n, False
        h = self._clock.step(t)
        e = u_ref_a - u_a
        ff = np.zeros(e.shape)
        if self.feedforward is not None:
            speed = batch_value(u_ref_a, n)
            name = "feedforward(u_ref)" if n is not None else f"feedforward({speed!r})"
            ff = finite_batch(name, self.feedforward(speed), n)
        c = ff + constant(self.kp) * e + constant(self.ki) * self._integral
        hi = np.maximum(self.max_command(batch_value(u_a, n)), self.min_command)
        c_lim = np.minimum(clip(c, *bounds(self.min_command, math.inf)), hi)
        if math.isfinite(self.max_rate):
            c_lim = rate_limit(c_lim, self._command, self.max_rate * h)
        self._integral = integrate_with_anti_windup(
            self._integral, e, h, self.ki, c - c_lim, self.anti_windup, self.tracking_time
        )
        self._error = e
        self._feedforward_command = ff
        self._unsaturated_command = c
        self._command = c_lim
        return batch_value(c_lim, n)

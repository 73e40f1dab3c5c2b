"""Angle and input-check helpers of the controllers (no ``shipgym`` import).

``ssa`` is Fossen's smallest signed angle with the same semantics as ``shipgym.models.ssa``:
``ssa(a) = ((a + pi) mod 2 pi) - pi``, in [-pi, pi). The controllers keep angles such as the
reference heading *unwrapped* inside and wrap only differences (errors) with ``ssa``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

TWO_PI = 2.0 * math.pi


def ssa(angle: float) -> float:
    """Smallest signed angle of a scalar: wrap ``angle`` [rad] to [-pi, pi)."""
    return (float(angle) + math.pi) % TWO_PI - math.pi


def ssa_array(angle: npt.ArrayLike) -> np.ndarray:
    """Smallest signed angle of every element of ``angle`` [rad], in [-pi, pi)."""
    a = np.asarray(angle, dtype=np.float64)
    return np.mod(a + np.pi, TWO_PI) - np.pi


def unwrap_towards(reference: float, angle: float) -> float:
    """The angle equal to ``angle`` modulo 2 pi that lies closest to ``reference`` [rad].

    ``reference + ssa(angle - reference)``: a new heading setpoint is reached the short way.
    """
    return float(reference) + ssa(angle - reference)


def finite(name: str, value: Any) -> float:
    """``value`` as a finite float, or ``ValueError`` naming ``name``."""
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number, got {value!r}") from None
    if not math.isfinite(f):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return f


def positive(name: str, value: Any, *, allow_inf: bool = False) -> float:
    """``value`` as a float > 0 (finite unless ``allow_inf``), or ``ValueError``."""
    try:
        f = float(value)
    except (TypeError, ValueError):
        f = math.nan
    if not (f > 0 and (allow_inf or math.isfinite(f))):
        kind = "a number > 0 (inf allowed)" if allow_inf else "a finite number > 0"
        raise ValueError(f"{name} must be {kind}, got {value!r}")
    return f


def nonnegative(name: str, value: Any) -> float:
    """``value`` as a finite float >= 0, or ``ValueError``."""
    try:
        f = float(value)
    except (TypeError, ValueError):
        f = math.nan
    if not (math.isfinite(f) and f >= 0):
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return f


def optional_limit(name: str, value: Any) -> float:
    """A limit that may be ``None`` (no limit, returned as ``inf``) or a number > 0."""
    if value is None:
        return math.inf
    return positive(name, value, allow_inf=True)


def point(name: str, value: Any) -> np.ndarray:
    """A finite ``(2,)`` (north, east) vector, or ``ValueError``."""
    try:
        v = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        v = np.array([np.nan])
    if v.shape != (2,) or not (math.isfinite(v[0]) and math.isfinite(v[1])):
        raise ValueError(f"{name} must be 2 finite (north, east) values, got {value!r}")
    return v


class StepClock:
    """Step lengths from successive sample times, with a fixed nominal ``dt``.

    ``step(t)`` returns the time [s] since the previous call: ``dt`` when ``t`` is ``None``,
    ``t - t_prev`` otherwise, and 0 on the first call after :meth:`reset` (the states were just
    initialised at that instant). A time that goes backwards raises ``ValueError``.
    """

    def __init__(self, dt: float) -> None:
        self.dt = positive("dt", dt)
        self.t_prev: float | None = None
        self.started = False

    def reset(self, t: float | None = None) -> None:
        """Forget the previous time; ``t`` [s] is the instant of the initial state."""
        self.t_prev = None if t is None else finite("t", t)
        self.started = t is not None

    def step(self, t: float | None) -> float:
        """Time [s] elapsed since the previous sample."""
        if t is None:
            h = self.dt if self.started else 0.0
            if self.t_prev is not None:
                self.t_prev += h
        else:
            t = finite("t", t)
            if self.t_prev is None:
                h = 0.0
            else:
                h = t - self.t_prev
                if h < 0:
                    raise ValueError(
                        f"time went backwards: t={t!r} after t={self.t_prev!r}; call reset() "
                        "to start again"
                    )
            self.t_prev = t
        self.started = True
        return h


ANTI_WINDUP_MODES = ("back_calculation", "conditional", "none")


def anti_windup_mode(value: str | bool) -> str:
    """Normalise an ``anti_windup`` argument: ``True`` -> back-calculation, ``False`` -> none."""
    if value is True:
        return "back_calculation"
    if value is False:
        return "none"
    if isinstance(value, str) and value in ANTI_WINDUP_MODES:
        return value
    raise ValueError(f"anti_windup must be one of {ANTI_WINDUP_MODES} or a bool, got {value!r}")


def integrate_with_anti_windup(
    integral: float,
    error: float,
    h: float,
    ki: float,
    excess: float,
    mode: str,
    tracking_time: float,
) -> float:
    """One step of an error integral with anti-windup; returns the new integral.

    Parameters
    ----------
    integral : float
        The integral so far; the control law adds ``ki * integral``.
    error : float
        Control error (setpoint minus measurement).
    h : float
        Step [s].
    ki : float
        Integral gain (either sign).
    excess : float
        ``u - u_lim``: how far the unlimited command lies beyond the applied one (0 when no
        limit is active).
    mode : {"back_calculation", "conditional", "none"}
        ``"conditional"``: skip the step while limited and ``ki * error`` pushes the command
        further into the limit. ``"back_calculation"``: the same, and in addition
        ``integral' = -excess / (ki T_t)`` (exact for ``h``), which brings the integral term
        back until the command leaves the limit. ``"none"``: plain integration.
    tracking_time : float
        ``T_t`` [s] of the back-calculation.
    """
    into_limit = excess != 0.0 and ki * error * excess > 0.0
    if mode == "none" or not into_limit:
        integral += error * h
    if mode == "back_calculation" and ki != 0.0 and excess != 0.0:
        integral -= excess / ki * -math.expm1(-h / tracking_time)
    return integral


def tracking_time(kp: float, ki: float, kd: float = 0.0) -> float:
    """Back-calculation time ``T_t = sqrt(T_i T_d)`` (``T_i`` for a PI) [s] (Åström)."""
    if ki == 0:
        return math.inf
    ti = abs(kp / ki)
    td = abs(kd / kp) if kp != 0 else 0.0
    tt = math.sqrt(ti * td) if td > 0 else ti
    return tt if tt > 0 else 1.0

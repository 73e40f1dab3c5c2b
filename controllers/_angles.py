"""Angle, input-check and batch helpers of the controllers (no ``shipgym`` import).

``ssa`` is Fossen's smallest signed angle with the same semantics as ``shipgym.models.ssa``:
``ssa(a) = ((a + pi) mod 2 pi) - pi``, in [-pi, pi); ``ssa_array`` is the same on arrays, bit for
bit (NumPy's floor modulo and Python's ``%`` on floats are the same operation). The controllers
keep angles such as the reference heading *unwrapped* inside and wrap only differences (errors).

Batches: the autopilots keep their states as arrays of shape ``(n,)``, one entry per ship, and
one ship is a batch of one (arrays of shape ``(1,)``) of the same code. :func:`batch_size`
finds ``n`` from the arguments (``None``: numbers given, one ship in *scalar mode*),
:func:`finite_batch` checks an argument (a number or a row such as a (north, east) position
per ship; the one check of every controller's array arguments), and :class:`BatchValue` reads
a state back as a float in scalar mode and as an array for a batch.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

TWO_PI = 2.0 * math.pi


def constant(value: float) -> np.ndarray:
    """``value`` as a 0-d float64 array.

    The same number, but NumPy combines an array with a 0-d array about twice as fast as with
    a Python float (no conversion of the scalar in every operation), which is most of the
    cost of a small batch; the controllers keep their gains and limits in this form.
    """
    return np.array(value, dtype=np.float64)


_PI, _TWO_PI, _ZERO = constant(math.pi), constant(TWO_PI), constant(0.0)


def ssa(angle: float) -> float:
    """Smallest signed angle of a scalar: wrap ``angle`` [rad] to [-pi, pi)."""
    return (float(angle) + math.pi) % TWO_PI - math.pi


def ssa_array(angle: npt.ArrayLike) -> np.ndarray:
    """Smallest signed angle of every element of ``angle`` [rad], in [-pi, pi)."""
    a = np.asarray(angle, dtype=np.float64)
    return np.mod(a + _PI, _TWO_PI) - _PI


def unwrap_towards(reference: npt.ArrayLike, angle: npt.ArrayLike) -> np.ndarray:
    """The angles equal to ``angle`` modulo 2 pi that lie closest to ``reference`` [rad].

    ``reference + ssa(angle - reference)`` elementwise: a new heading setpoint is reached the
    short way.
    """
    return reference + ssa_array(np.subtract(angle, reference))


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


def batch_size(**values: Any) -> int | None:
    """The number of ships ``n`` of arguments given together (keyword name -> value).

    Numbers (and ``None``, an argument not given) say nothing; every 1-D argument must have
    the same shape ``(n,)``. Returns ``None`` when no argument is an array: one ship, in scalar
    mode.

    Raises
    ------
    ValueError
        For an argument with more than one dimension, or two 1-D arguments of different
        lengths (the message names both and their shapes).
    """
    n: int | None = None
    first = ""
    for name, value in values.items():
        if value is None:
            continue
        shape = np.shape(value)
        if len(shape) > 1:
            raise ValueError(
                f"{name} must be a number or a 1-D array with one entry per ship, got shape {shape}"
            )
        if len(shape) == 1:
            if n is None:
                n, first = shape[0], name
            elif shape[0] != n:
                raise ValueError(
                    f"{name} has shape {shape} but {first} has shape ({n},): one entry per ship "
                    "expected in both"
                )
    return n


def finite_batch(
    name: str,
    value: Any,
    n: int | None,
    *,
    per_ship: tuple[int, ...] = (),
    broadcast: bool = True,
) -> np.ndarray:
    """``value`` as a new finite float64 array for a batch of ``n`` ships, or ``ValueError``.

    The one check of the controllers' array arguments. The result is always a copy: the
    caller may change its array later.

    Parameters
    ----------
    name : str
        The argument's name for the error message.
    value : float or array_like
        An array of shape ``(n, *per_ship)`` for a batch; for one ship in scalar mode (``n``
        ``None``) an array of shape ``per_ship`` (a number when ``per_ship`` is ``()``),
        returned with a leading axis of length 1; with ``broadcast``, a number for every
        entry of a batch.
    n : int or None
        Ships in the batch; ``None`` for one ship in scalar mode.
    per_ship : tuple of int
        Shape of one ship's entry, e.g. ``(2,)`` for a (north, east) position.
    broadcast : bool
        Accept a number for every entry of a batch.

    Raises
    ------
    ValueError
        For a value that has the wrong shape (naming its shape and the expected one) or that
        is not finite (naming the index and the value of the first bad entry).
    """
    if isinstance(value, float | int) and not per_ship and (n is None or broadcast):
        return np.full(1 if n is None else n, finite(name, value))
    shape = per_ship if n is None else (n, *per_ship)
    expected = f"{shape}" if shape else "a number"
    try:
        a = np.array(value, dtype=np.float64)  # a copy: the caller may change its array later
    except (TypeError, ValueError):
        msg = f"{name} must be finite numbers, got {value!r}, expected {expected}"
        raise ValueError(msg) from None
    if a.shape != shape:
        if n is None:
            raise ValueError(
                f"{name} has shape {a.shape}, expected {expected}: the controller runs one ship"
            )
        if not (broadcast and a.ndim == 0):
            alternative = " or a number" if broadcast else ""
            raise ValueError(f"{name} has shape {a.shape}, expected {expected}{alternative}")
        a = np.full(shape, finite(name, a.item()))
    bad = ~np.isfinite(a)
    if bad.any():
        i = np.unravel_index(int(np.argmax(bad)), a.shape)
        where = f"{name}[{', '.join(str(int(j)) for j in i)}]" if i else name
        raise ValueError(f"{where} must be a finite number, got {float(a[i])!r}")
    return a if n is not None else a[None]


def batch_value(values: np.ndarray, n: int | None) -> float | np.ndarray:
    """A state read back: ``float(values[0])`` for one ship in scalar mode (``n`` ``None``),
    a copy of ``values`` for a batch."""
    return float(values[0]) if n is None else values.copy()


class BatchValue:
    """A read-only attribute over the ``(n,)`` array ``_<name>`` of its owner.

    Reads as a float when the owner's ``batch_size`` is ``None`` (one ship, scalar mode) and as
    a copy of the array for a batch (:func:`batch_value`).
    """

    def __init__(self, doc: str) -> None:
        self.__doc__ = doc
        self.name = self.private = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name, self.private = name, "_" + name

    def __get__(self, obj: Any, objtype: type | None = None) -> Any:
        if obj is None:
            return self
        return batch_value(getattr(obj, self.private), obj.batch_size)

    def __set__(self, obj: Any, value: Any) -> None:
        raise AttributeError(f"{self.name} is read-only: it is a state of the controller")


def bounds(lo: float, hi: float) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Bounds for :func:`clip`: 0-d arrays (:func:`constant`), ``None`` for an infinite one."""
    return (None if lo == -math.inf else constant(lo)), (None if hi == math.inf else constant(hi))


def clip(x: np.ndarray, lo: np.ndarray | None, hi: np.ndarray | None) -> np.ndarray:
    """``min(max(x, lo), hi)`` elementwise with :func:`bounds`; a bound ``None`` (infinite) is
    not applied (the same result for numbers), and without bounds ``x`` itself is returned."""
    if lo is not None:
        x = np.maximum(x, lo)
        if hi is not None:
            np.minimum(x, hi, out=x)
    elif hi is not None:
        x = np.minimum(x, hi)
    return x


def rate_limit(command: np.ndarray, previous: np.ndarray, step: float) -> np.ndarray:
    """``command`` moved at most ``step`` from ``previous``, elementwise, where ``previous``
    is a number (``nan``: no command yet, no limit)."""
    step_ = constant(step)
    limited = np.fmax(command, previous - step_)  # fmax and fmin ignore nan
    return np.fmin(limited, previous + step_, out=limited)


def optional_limit(name: str, value: Any) -> float:
    """A limit that may be ``None`` (no limit, returned as ``inf``) or a number > 0."""
    if value is None:
        return math.inf
    return positive(name, value, allow_inf=True)


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
    integral: np.ndarray,
    error: np.ndarray,
    h: float,
    ki: float,
    excess: np.ndarray,
    mode: str,
    tracking_time: float,
) -> np.ndarray:
    """One step of error integrals with anti-windup, elementwise; returns the new integrals.

    Parameters
    ----------
    integral : numpy.ndarray
        The integrals so far (one per ship); the control law adds ``ki * integral``.
    error : numpy.ndarray
        Control errors (setpoint minus measurement).
    h : float
        Step [s].
    ki : float
        Integral gain (either sign).
    excess : numpy.ndarray
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
    stepped = integral + error * constant(h)
    if mode == "none":
        return stepped
    ki_ = constant(ki)
    np.copyto(stepped, integral, where=ki_ * error * excess > _ZERO)  # limited, into the limit
    if mode == "back_calculation" and ki != 0.0:
        back = excess / ki_ * constant(-math.expm1(-h / tracking_time))
        np.subtract(stepped, back, out=stepped, where=excess != _ZERO)
    return stepped


def tracking_time(kp: float, ki: float, kd: float = 0.0) -> float:
    """Back-calculation time ``T_t = sqrt(T_i T_d)`` (``T_i`` for a PI) [s] (Åström)."""
    if ki == 0:
        return math.inf
    ti = abs(kp / ki)
    td = abs(kd / kp) if kp != 0 else 0.0
    tt = math.sqrt(ti * td) if td > 0 else ti
    return tt if tt > 0 else 1.0


def math_elementwise(func: Any, *args: np.ndarray) -> np.ndarray:
    """``func`` of the :mod:`math` module applied to every element of equally shaped arrays.

    Gives bitwise what the one-ship code gives with Python floats. NumPy's SIMD ``arctan``,
    ``arctan2``, ``hypot`` and ``power`` round the last bit differently from :mod:`math` for a
    small share of float64 inputs (measured on an AVX-512 machine: 1 ulp on 0.3 %, 2 %,
    0.2 % and 0.1 % of random inputs); ``sin``, ``cos``, ``sqrt`` and ``mod`` agree exactly.
    """
    shape = args[0].shape
    flat = [np.ravel(a).tolist() for a in args]
    return np.fromiter(map(func, *flat), np.float64, count=len(flat[0])).reshape(shape)


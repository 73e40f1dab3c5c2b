"""Angle helpers: the one wrapping function used everywhere (Fossen's smallest signed angle)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from shipgym.models._checks import real_array
from shipgym.models._jit import kernel

TWO_PI = 2.0 * math.pi


@kernel
def ssa_scalar(angle: float) -> float:
    """Smallest signed angle: wrap ``angle`` [rad] to [-pi, pi) (compiled, for kernels; from
    Python use :func:`ssa`, which checks its argument).

    ``angle - 2 pi floor((angle + pi) / 2 pi)``: no library call (a floating-point ``%`` is a
    call to ``fmod``), so the loops of the task kernels vectorise. It agrees with the exact
    remainder of :func:`ssa` to a few units in the last place of ``angle``; at the very ends
    of the range that rounding may give -pi minus one ulp.
    """
    return angle - TWO_PI * np.floor((angle + math.pi) / TWO_PI)


def ssa(angle: npt.ArrayLike) -> np.ndarray:
    """Smallest signed angle of an array: wrap every element [rad] to [-pi, pi).

    Parameters
    ----------
    angle : array_like
        Angles in radians.

    Returns
    -------
    numpy.ndarray
        The wrapped angles, same shape as ``angle``. A NaN stays NaN (a missing angle stays
        missing).

    Raises
    ------
    TypeError
        When ``angle`` is not real numbers.
    ValueError
        For an infinite angle (it has no direction: wrapping it would give NaN).
    """
    a = real_array(angle, "angle")
    if np.isinf(a).any():
        raise ValueError(f"angle must not be infinite (rad), got {a[np.isinf(a)][0]!r}")
    return np.mod(a + np.pi, TWO_PI) - np.pi

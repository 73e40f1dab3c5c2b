"""Angle helpers: the one wrapping function used everywhere (Fossen's smallest signed angle)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from shipgym.models._jit import kernel

TWO_PI = 2.0 * math.pi


@kernel
def ssa_scalar(angle: float) -> float:
    """Smallest signed angle: wrap ``angle`` [rad] to [-pi, pi)."""
    return (angle + math.pi) % TWO_PI - math.pi


def ssa(angle: npt.ArrayLike) -> np.ndarray:
    """Smallest signed angle of an array: wrap every element [rad] to [-pi, pi).

    Parameters
    ----------
    angle : array_like
        Angles in radians.

    Returns
    -------
    numpy.ndarray
        The wrapped angles, same shape as ``angle``.
    """
    a = np.asarray(angle, dtype=np.float64)
    return np.mod(a + np.pi, TWO_PI) - np.pi

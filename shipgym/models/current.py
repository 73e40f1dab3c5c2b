"""Constant, irrotational ocean current (seed 001 eq. 7-9).

The current is uniform in space and steady in time. Its earth-frame velocity is
``nu_c^n = V_c [cos(beta_c), sin(beta_c), 0]`` (eq. 7) where ``V_c`` [m/s] is the speed and
``beta_c`` [rad] the direction the water moves *toward*, clockwise from north (NED). Every
model kernel receives the current as an array of shape ``(n, 2)`` holding the north and east
components ``(V_c cos beta_c, V_c sin beta_c)`` [m/s] per ship in the batch.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from shipgym.models._checks import real_array

_MAX_ROWS = 10**9
"""Most rows :meth:`Current.as_batch` makes (16 GB; more would not fit in memory)."""


@dataclass(frozen=True)
class Current:
    """A constant, irrotational current.

    Attributes
    ----------
    speed : float
        Current speed ``V_c`` [m/s], non-negative.
    direction : float
        Direction the water moves toward, ``beta_c`` [rad], clockwise from north.
    """

    speed: float = 0.0
    direction: float = 0.0

    def __post_init__(self) -> None:
        if not math.isfinite(self.speed) or self.speed < 0.0:
            raise ValueError(f"current speed must be a finite number >= 0 m/s, got {self.speed!r}")
        if not math.isfinite(self.direction):
            raise ValueError(
                f"current direction must be a finite angle in rad, got {self.direction!r}"
            )

    @property
    def ned(self) -> tuple[float, float]:
        """North and east velocity components [m/s] (seed 001 eq. 7)."""
        return (self.speed * math.cos(self.direction), self.speed * math.sin(self.direction))

    def as_batch(self, n: int = 1) -> np.ndarray:
        """The current as the ``(n, 2)`` north/east array that model kernels take."""
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 0:
            raise ValueError(f"Current.as_batch: n must be an integer >= 0, got {n!r}")
        if n > _MAX_ROWS:
            raise ValueError(f"Current.as_batch: n must be at most {_MAX_ROWS:.0e}, got {n}")
        return np.tile(np.array(self.ned, dtype=np.float64), (n, 1))


def current_ned(speed: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Batch of currents as ``(n, 2)`` north/east components [m/s] from speed and direction.

    Parameters
    ----------
    speed : array_like
        Current speeds ``V_c`` [m/s], finite and >= 0.
    direction : array_like
        Directions the water moves toward, ``beta_c`` [rad], finite; broadcast with ``speed``.

    Returns
    -------
    numpy.ndarray
        Shape ``broadcast(speed, direction).shape + (2,)``.

    Raises
    ------
    TypeError
        When either is not real numbers.
    ValueError
        When the shapes do not broadcast, a speed is negative or a value is not finite.
    """
    speed = real_array(speed, "current speed")
    direction = real_array(direction, "current direction")
    try:
        speed, direction = np.broadcast_arrays(speed, direction)
    except ValueError:
        raise ValueError(
            f"current speed and direction must broadcast to one shape, got {speed.shape} and "
            f"{direction.shape}"
        ) from None
    if not (np.isfinite(speed).all() and (speed >= 0.0).all()):
        bad = speed[~(np.isfinite(speed) & (speed >= 0.0))][0]
        raise ValueError(f"current speed must be finite and >= 0 m/s, got {bad!r}")
    if not np.isfinite(direction).all():
        bad = direction[~np.isfinite(direction)][0]
        raise ValueError(f"current direction must be finite (rad), got {bad!r}")
    return np.stack((speed * np.cos(direction), speed * np.sin(direction)), axis=-1)

"""Constant, irrotational ocean current (seed 001 eq. 7-9).

The current is uniform in space and steady in time. Its earth-frame velocity is
``nu_c^n = V_c [cos(beta_c), sin(beta_c), 0]`` (eq. 7) where ``V_c`` [m/s] is the speed and
``beta_c`` [rad] the direction the water moves *toward*, clockwise from north (NED). Every
model kernel receives the current as an array of shape ``(n, 2)`` holding the north and east
components ``(V_c cos beta_c, V_c sin beta_c)`` [m/s] per ship in the batch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


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
        return np.tile(np.array(self.ned, dtype=np.float64), (n, 1))


def current_ned(speed: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Batch of currents as ``(n, 2)`` north/east components [m/s] from speed and direction."""
    speed = np.asarray(speed, dtype=np.float64)
    direction = np.asarray(direction, dtype=np.float64)
    return np.stack((speed * np.cos(direction), speed * np.sin(direction)), axis=-1)

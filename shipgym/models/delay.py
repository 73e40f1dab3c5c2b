"""Transport delay of a sampled command: the ``input_delay`` of an identified ship.

A command sampled every ``dt`` and held over each step reaches the ship ``tau`` seconds late.
With ``tau = (m + f) dt`` (``m`` whole steps, ``0 <= f < 1``) the command applied at step
``k`` is

    ``u_applied[k] = (1 - f) u[k - m] + f u[k - m - 1]``,

the commanded sequence at ``t_k - tau`` interpolated linearly between its samples, with the
first command held before the start (``u[j] = u[0]`` for ``j < 0``). It is exactly the shift
``numpy.interp(t - tau, t, u)`` that the identification applies to a recorded rudder
(``input_delay`` of :mod:`shipgym.sysid.families.nomoto`), so a model identified with a delay
and simulated by :meth:`ShipModel.simulate <shipgym.models.ShipModel.simulate>` or stepped by an
env gives the response the identification scored. One :class:`DelayLine` serves both, one row
per ship of a batch.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["DelayLine"]


class DelayLine:
    """A batch of delay lines (one row per ship) for commands of ``width`` entries.

    Parameters
    ----------
    delay : float
        Delay ``tau`` [s], finite and >= 0.
    dt : float
        Sample interval of the commands [s], > 0.
    rows, width : int
        Number of ships and entries per command.
    """

    def __init__(self, delay: float, dt: float, rows: int, width: int) -> None:
        if not (math.isfinite(delay) and delay >= 0.0):
            raise ValueError(f"input delay must be a finite time >= 0 s, got {delay!r}")
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f"dt must be a finite step > 0 s, got {dt!r}")
        steps = delay / dt
        self.m = math.floor(steps + 1e-12)
        self.f = max(steps - self.m, 0.0)
        self.delay, self.dt = float(delay), float(dt)
        self.history = np.zeros((rows, self.m + 2, width))
        self.pos = 0  # slot of the newest command
        self.fresh = np.ones(rows, dtype=bool)

    def reset(self, rows: slice | np.ndarray = slice(None)) -> None:
        """Start ``rows`` afresh: their next command is also their whole history."""
        self.fresh[rows] = True

    def push(self, u: np.ndarray) -> np.ndarray:
        """Store this step's commands ``(rows, width)`` and return the ones applied now."""
        size = self.m + 2
        self.pos = (self.pos + 1) % size
        self.history[:, self.pos] = u
        if self.fresh.any():
            self.history[self.fresh] = u[self.fresh, None, :]
            self.fresh[:] = False
        late = self.history[:, (self.pos - self.m) % size]
        if self.f == 0.0:
            return late.copy()
        later = self.history[:, (self.pos - self.m - 1) % size]
        return (1.0 - self.f) * late + self.f * later

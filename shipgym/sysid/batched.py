"""Finite-difference Jacobians whose columns are simulated side by side.

:func:`scipy.optimize.least_squares` estimates the Jacobian of an output-error fit by forward
differences: one replay of the record per free parameter, each with that parameter nudged
(its steps and their adjustment at the bounds are SciPy's own). Those replays are independent,
and the model kernels step a block of ships whose parameters may differ from ship to ship
(:func:`shipgym.models._jit.param`), so all of a Jacobian's replays run as the ships of one
block, whose loops over the ships compile to SIMD code, rather than one after another.
:class:`SideBySide` hands them to such a batched residual function through
``least_squares``'s ``workers`` argument (SciPy >= 1.16). The numbers are those of the
one-at-a-time replays, bit for bit: each ship of a block runs the same arithmetic.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np

from shipgym.models.integrate import SIMD_LANES

__all__ = ["BATCH_BYTES", "SideBySide", "lanes"]

#: Memory [bytes] one batch of side-by-side replays may take (their states and residuals); a
#: Jacobian whose replays need more runs in several batches, one SIMD vector of replays at
#: least, or one replay at a time where even that does not fit (a very long record).
BATCH_BYTES = 256 * 2**20


class SideBySide:
    """Map-like ``workers`` for :func:`scipy.optimize.least_squares` that evaluates the points
    of a finite-difference Jacobian together, in calls of a batched residual function.

    Parameters
    ----------
    residuals : callable
        ``residuals(points)``: for points of shape ``(k, n_parameters)``, the ``k`` residual
        vectors of the fit's residual function at those points, computed together. It must be
        the batched form of the residual function given to ``least_squares``: the ``fun``
        that ``least_squares`` passes in is not called.
    bytes_per_point : int
        Memory one point's replay and residuals take: the points go in batches of whole SIMD
        vectors within :data:`BATCH_BYTES`.
    """

    def __init__(
        self, residuals: Callable[[np.ndarray], Sequence[np.ndarray]], bytes_per_point: int
    ) -> None:
        self._residuals = residuals
        fit = BATCH_BYTES // max(int(bytes_per_point), 1)
        self.batch = fit // SIMD_LANES * SIMD_LANES if fit >= SIMD_LANES else 1

    def __call__(self, fun: Any, points: Iterable[np.ndarray]) -> list[np.ndarray]:
        pts = np.array(list(points), dtype=np.float64)
        out: list[np.ndarray] = []
        for i in range(0, len(pts), self.batch):
            out += list(self._residuals(pts[i : i + self.batch]))
        return out


def lanes(variants: int) -> np.ndarray:
    """Which variant each ship of a block replays: ``range(variants)``, and for several
    variants the last again up to a multiple of
    :data:`~shipgym.models.integrate.SIMD_LANES`, so that the loops over the ships run in whole
    SIMD vectors (a remainder would run one ship at a time). One variant is a block of one.

    Raises
    ------
    ValueError
        Unless ``variants`` is an integer >= 1.
    """
    if isinstance(variants, bool) or not isinstance(variants, int | np.integer) or variants < 1:
        raise ValueError(f"variants must be an integer >= 1 (replays of a block), got {variants!r}")
    width = variants if variants == 1 else -(-variants // SIMD_LANES) * SIMD_LANES
    return np.minimum(np.arange(width), variants - 1)

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

__all__ = ["SideBySide", "lanes"]


class SideBySide:
    """Map-like ``workers`` for :func:`scipy.optimize.least_squares` that evaluates every
    point of a finite-difference Jacobian in one call of a batched residual function.

    Parameters
    ----------
    residuals : callable
        ``residuals(points)``: for points of shape ``(k, n_parameters)``, the ``k`` residual
        vectors of the fit's residual function at those points, computed together. It must be
        the batched form of the residual function given to ``least_squares``: the ``fun``
        that ``least_squares`` passes in is not called.
    """

    def __init__(self, residuals: Callable[[np.ndarray], Sequence[np.ndarray]]) -> None:
        self._residuals = residuals

    def __call__(self, fun: Any, points: Iterable[np.ndarray]) -> list[np.ndarray]:
        return list(self._residuals(np.array(list(points), dtype=np.float64)))


def lanes(variants: int) -> np.ndarray:
    """Which variant each ship of a block replays: ``0 .. variants - 1``, and for several
    variants the last again up to a multiple of
    :data:`~shipgym.models.integrate.SIMD_LANES`, so that the loops over the ships run in whole
    SIMD vectors (a remainder would run one ship at a time). One variant is a block of one."""
    width = variants if variants == 1 else -(-variants // SIMD_LANES) * SIMD_LANES
    return np.minimum(np.arange(width), variants - 1)

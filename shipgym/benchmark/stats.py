"""Confidence for the benchmark: bootstrap intervals and paired comparisons on shared seeds.

Every controller of a benchmark cell runs the same episode seeds (the same initial states,
setpoints, paths, targets and current draws), so two controllers are compared episode by
episode: the paired difference ``d_k = a_k - b_k`` of each seed ``k``, its mean and a
percentile-bootstrap 95 % interval (Efron and Tibshirani 1993, ch. 13) of that mean. A
controller is named the winner only where the interval excludes zero (:func:`verdict`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["RESAMPLES", "bootstrap_ci", "paired_difference", "verdict"]

RESAMPLES = 4000
"""Bootstrap resamples (fixed generator seed: the intervals are reproducible)."""


def bootstrap_ci(
    values: Sequence[float], *, confidence: float = 0.95, resamples: int = RESAMPLES, seed: int = 0
) -> tuple[float, float]:
    """Percentile-bootstrap interval of the mean of ``values``.

    Raises
    ------
    ValueError
        For fewer than two finite values or a confidence outside (0, 1).
    """
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    if x.size < 2:
        raise ValueError(f"a bootstrap interval needs at least 2 finite values, got {x.size}")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, x.size, size=(resamples, x.size))].mean(axis=1)
    tail = 50.0 * (1.0 - confidence)
    lo, hi = np.percentile(means, [tail, 100.0 - tail])
    return float(lo), float(hi)


def paired_difference(
    a: Sequence[float], b: Sequence[float], **kwargs: float
) -> tuple[float, float, float]:
    """Mean of ``a - b`` over paired episodes and its bootstrap interval ``(mean, lo, hi)``.

    Raises
    ------
    ValueError
        If ``a`` and ``b`` differ in length (the episodes must pair by seed).
    """
    a_arr, b_arr = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a_arr.shape != b_arr.shape:
        raise ValueError(f"paired values need equal lengths, got {a_arr.size} and {b_arr.size}")
    d = a_arr - b_arr
    lo, hi = bootstrap_ci(d, **kwargs)  # type: ignore[arg-type]
    return float(np.mean(d[np.isfinite(d)])), lo, hi


def verdict(lo: float, hi: float, higher_is_better: bool = True) -> str:
    """``"better"``, ``"worse"`` or ``"no difference"`` for an interval of ``a - b``."""
    if lo > 0.0:
        return "better" if higher_is_better else "worse"
    if hi < 0.0:
        return "worse" if higher_is_better else "better"
    return "no difference"

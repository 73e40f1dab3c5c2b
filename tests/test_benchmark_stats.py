"""Bootstrap intervals and paired comparisons of the benchmark (shipgym.benchmark.stats)."""

from __future__ import annotations

import numpy as np
import pytest

from shipgym.benchmark.report import paired_table
from shipgym.benchmark.stats import bootstrap_ci, paired_difference, verdict


def test_bootstrap_interval_covers_the_mean_at_the_normal_width() -> None:
    rng = np.random.default_rng(1)
    x = rng.normal(10.0, 2.0, 400)
    lo, hi = bootstrap_ci(x)
    half = 1.96 * x.std(ddof=1) / np.sqrt(x.size)  # the normal-theory half width
    assert lo < x.mean() < hi
    assert (hi - lo) / 2 == pytest.approx(half, rel=0.1)
    assert bootstrap_ci(x) == (lo, hi)  # reproducible


def test_pairing_removes_the_shared_seed_variance() -> None:
    """Two controllers on the same seeds: the seed-to-seed spread is shared, so the paired
    interval of a small, real difference excludes zero while unpaired intervals overlap."""
    rng = np.random.default_rng(2)
    scenario = rng.normal(0.0, 50.0, 30)  # how hard each seed is
    a = scenario + 5.0 + rng.normal(0.0, 1.0, 30)
    b = scenario + rng.normal(0.0, 1.0, 30)
    mean, lo, hi = paired_difference(a, b)
    assert mean == pytest.approx(5.0, abs=1.0) and lo > 0.0
    assert verdict(lo, hi) == "better"
    a_lo, _ = bootstrap_ci(a)
    _, b_hi = bootstrap_ci(b)
    assert a_lo < b_hi  # unpaired, no winner could be named
    assert verdict(-1.0, 2.0) == "no difference" and verdict(-3.0, -1.0) == "worse"
    with pytest.raises(ValueError, match="equal lengths"):
        paired_difference(a, b[:-1])
    with pytest.raises(ValueError, match="at least 2"):
        bootstrap_ci([1.0])


def test_paired_table_names_a_winner_only_outside_zero() -> None:
    base = {"env": "shipgym/RVGHeading-v0", "condition": "nominal"}
    entries = [
        {**base, "controller": "classic", "returns": [0.0, 10.0, 20.0, 30.0]},
        {**base, "controller": "ppo", "returns": [1.0, 11.0, 21.0, 31.5]},
        {**base, "controller": "sac", "returns": [5.0, 5.0, 25.0, 25.0]},
    ]
    lines = "\n".join(paired_table(entries, reference="classic"))
    assert "| RVGHeading-v0 | nominal | ppo | +1.12 |" in lines and "better" in lines
    assert "| RVGHeading-v0 | nominal | sac |" in lines and "no difference" in lines

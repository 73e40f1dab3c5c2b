"""Tuned classic gains: the search picks the best candidate on the tuning seeds, steps past
the grid's edge, keeps its record; the shipped gains load, beat the design rule on the seeds
they were tuned on and never on the benchmark's."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import shipgym
from shipgym.benchmark import evaluate, make_policy
from shipgym.benchmark.policies import CLASSIC, classic_policy
from shipgym.benchmark.tuning import (
    BOUNDS,
    SEARCH,
    _beyond_edge,
    candidates,
    load_tuned,
    tune,
    tuned_path,
    write_tuned,
)
from shipgym.envs import env_task
from shipgym.rl.train import BENCHMARK_SEED, VALIDATION_SEED

HEADING = "shipgym/RVGHeading-v1"


def _quiet(line: str) -> None:
    pass


def test_grid_and_edge_steps() -> None:
    grid = {"a": (1.0, 2.0), "b": (None, 0.5)}
    assert candidates(grid) == [
        {"a": 1.0, "b": None}, {"a": 1.0, "b": 0.5}, {"a": 2.0, "b": None}, {"a": 2.0, "b": 0.5},
    ]  # fmt: skip
    assert _beyond_edge((0.1, 0.2, 0.4), 0.4) == pytest.approx(0.8)
    assert _beyond_edge((0.1, 0.2, 0.4), 0.1) == pytest.approx(0.05)
    assert _beyond_edge((0.1, 0.2, 0.4), 0.2) is None
    assert _beyond_edge((None, 0.2, 0.4), None) is None  # the design rule
    assert _beyond_edge((1.0, 2.0, 0.0), 0.0) is None  # "off"
    assert _beyond_edge((0.1, 0.2), 0.2, (0.0, 0.3)) == pytest.approx(0.3)  # held at the bound
    assert _beyond_edge((0.1, 0.3), 0.3, (0.0, 0.3)) is None
    for task, grid in SEARCH.items():  # every searched name is a design parameter, in bounds
        assert set(grid) <= set(CLASSIC[task].DESIGN)
        for name, values in grid.items():
            lo, hi = BOUNDS[name]
            assert all(lo <= v <= hi for v in values if v is not None and v != 0)


def test_tune_picks_the_best_candidate_and_records_it(tmp_path: Path) -> None:
    lines: list[str] = []
    record = tune(HEADING, episodes=2, grid={"omega_n": (None, 0.5, 0.75)}, progress=lines.append)
    rows = record["candidates"]
    assert len(lines) == len(rows) == record["budget"]["candidates"] >= 3
    best = max(rows, key=lambda r: r["mean_return"])
    assert record["score"] == best["mean_return"]
    assert record["design"]["omega_n"] == best["design"]["omega_n"]
    # the rest of the design stays at the rule
    for key in ("reference_omega", "max_turn_rate"):
        assert record["design"][key] == CLASSIC["RVGHeading"].DESIGN[key]
    rule = next(r for r in rows if r["design"]["omega_n"] is None)
    assert record["design_rule_score"] == rule["mean_return"]
    # the scores are what evaluate gives on the tuning seeds
    check = evaluate(HEADING, classic_policy(HEADING, **best["design"]), "c", 2, 0, progress=_quiet)
    assert np.mean(check.returns) == pytest.approx(best["mean_return"])
    assert record["seeds"] == [0, 1] and record["budget"]["env_steps"] == 2 * 600 * len(rows)
    # a winner on the edge is followed past it
    if record["design"]["omega_n"] == 0.75 or any(r["design"]["omega_n"] > 0.75 for r in rows):
        assert any(r["design"]["omega_n"] == pytest.approx(1.125) for r in rows)
    path = write_tuned(record, tmp_path)
    assert path == tuned_path(HEADING, tmp_path)
    assert load_tuned(HEADING, tmp_path)["design"] == record["design"]


def test_tune_refuses_bad_grids() -> None:
    with pytest.raises(ValueError, match="some of"):
        tune(HEADING, episodes=1, grid={"lookahead_lengths": (1.0,)})
    with pytest.raises(ValueError, match="at least one value"):
        tune(HEADING, episodes=1, grid={"omega_n": ()})
    with pytest.raises(ValueError, match="episodes"):
        tune(HEADING, episodes=0)


def test_missing_or_foreign_records_are_clear_errors(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"scripts/tune_classic\.py --only RVGHeading-v1"):
        load_tuned(HEADING, tmp_path)
    path = tuned_path(HEADING, tmp_path)
    path.write_text(json.dumps({"env": HEADING, "design": {"lookahead_lengths": 3.0}}))
    with pytest.raises(ValueError, match="unknown design parameter"):
        load_tuned(HEADING, tmp_path)
    path.write_text(json.dumps({"env": HEADING, "design": {"omega_n": "fast"}}))
    with pytest.raises(ValueError, match="omega_n must be a finite number"):
        load_tuned(HEADING, tmp_path)


@pytest.mark.parametrize("env_id", shipgym.CURRENT_ENV_IDS)
def test_shipped_tuned_gains_and_their_record(env_id: str) -> None:
    record = load_tuned(env_id)
    task = env_task(env_id)
    assert set(record["design"]) == set(CLASSIC[task].DESIGN)
    # tuned on the RL training seeds, never on validation or benchmark seeds
    lo, hi = record["seeds"]
    assert 0 <= lo <= hi < VALIDATION_SEED < BENCHMARK_SEED
    assert record["score"] >= record["design_rule_score"]
    assert record["budget"]["episodes"] == record["budget"]["candidates"] * record["episodes"]
    best = max(record["candidates"], key=lambda r: r["mean_return"])
    assert record["score"] == best["mean_return"]
    # no winner left on an edge the search could step past, unless stepping lost; every
    # candidate within the engineering limits
    for name, values in record["grid"].items():
        lo, hi = BOUNDS[name]
        assert all(
            lo <= r["design"][name] <= hi
            for r in record["candidates"]
            if r["design"][name] is not None and r["design"][name] != 0
        )
        beyond = _beyond_edge(values, record["design"][name], BOUNDS[name])
        if beyond is not None:
            tried = [r for r in record["candidates"] if r["design"][name] == pytest.approx(beyond)]
            assert tried and all(r["mean_return"] <= record["score"] for r in tried)
    # the policy built from the record is the classic structure with those gains
    policy = make_policy("classic-tuned", env_id)
    assert type(policy) is CLASSIC[task] and policy.design == record["design"]

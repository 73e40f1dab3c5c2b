"""Tuned gains for the classic controllers: a grid search over each structure's few design
parameters, scored as the agents are, with its budget on record.

An engineer commissioning an autopilot keeps its structure and adjusts a handful of design
parameters (bandwidth, damping, reference-model speed, lookahead, approach speed) until the
closed loop does what is asked. :func:`tune` does that for the classic policy of an env
(:mod:`shipgym.benchmark.policies`): every combination of :data:`SEARCH` is run on the episodes
of the **RL training seeds** (``seed .. seed + episodes - 1``, 0-15 by default: the seeds the
agents' sub-envs are trained on, disjoint from the validation and benchmark seeds), on the
env's nominal ship, and the combination with the best mean return wins; where it lies on the
edge of the grid, the search steps past that edge while the return improves, within the
engineering limits of :data:`BOUNDS`. The record keeps every candidate's score, the design-rule
candidate's, and the budget in episodes and env steps, to set beside the agents' training
budgets (2-3 million env steps for PPO).

The shipped records live in ``shipgym/benchmark/tuned/<env>.json`` (one per env of
:data:`shipgym.envs.CURRENT_ENV_IDS`); ``make_policy("classic-tuned", env_id)`` reads them.
``python scripts/tune_classic.py`` rewrites them.
"""

from __future__ import annotations

import itertools
import json
import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.benchmark.evaluate import evaluate
from shipgym.benchmark.policies import CLASSIC, classic_policy, nominal_ship
from shipgym.envs import ENV_IDS, env_task

#: Folder of the shipped tuned gains.
TUNED_DIR = Path(__file__).resolve().parent / "tuned"
#: Default episodes per candidate and first seed: the agents' training seeds 0-15.
TUNING_EPISODES = 16
TUNING_SEED = 0

#: Steps past the grid's edge, at most, when the best candidate lies on it.
MAX_EDGE_STEPS = 4
#: Engineering limits the search never steps past: a lookahead of at least one ship length
#: (Fossen recommends 1.5-2.5; shorter, LOS chases its own cross-track noise), loop and
#: reference-model frequencies of at most 1.5 rad/s (the pods slew 35 deg in 3.5 s), a
#: turn-rate limit of at most 0.2 rad/s (four times the Gunnerus's steady turning rate at full
#: azimuth, 0.05 rad/s: no limit at all), approach speeds up to the guidance's 6 m/s.
BOUNDS: dict[str, tuple[float, float]] = {
    "lookahead_lengths": (1.0, 10.0),
    "omega_n": (0.01, 1.5),
    "reference_omega": (0.01, 1.5),
    "max_turn_rate": (0.01, 0.2),
    "approach_speed": (0.5, 6.0),
    "zeta": (0.4, 2.0),
    "reference_ratio": (0.5, 8.0),
    "min_thrust": (0.0, 1.0),
}

#: The grid searched per task: design parameter -> candidate values (``None``: the design
#: rule's value). Every other design parameter keeps its design-rule value.
SEARCH: dict[str, dict[str, tuple[float | None, ...]]] = {
    "NomotoHeading": {
        "omega_n": (None, 0.035, 0.05, 0.07, 0.1, 0.14, 0.2),
        "zeta": (0.6, 0.8, 1.0),
        "reference_ratio": (1.0, 2.0, 4.0, 0.0),
    },
    "RVGHeading": {
        "omega_n": (None, 0.25, 0.35, 0.5, 0.75, 1.0),
        "reference_omega": (0.1, 0.2, 0.4, 0.8),
        "max_turn_rate": (0.03, 0.06, 0.12, 0.2),
    },
    "RVGSpeed": {
        "omega_n": (0.05, 0.1, 0.2, 0.3, 0.5, 0.8, 1.2),
        "zeta": (0.5, 0.7, 1.0, 1.5),
    },
    "RVGPathFollowing": {
        "lookahead_lengths": (1.5, 2.0, 3.0, 4.0, 6.0),
        "omega_n": (None, 0.5),
        "reference_omega": (0.3, 0.6, 1.0),
        "max_turn_rate": (0.04, 0.08, 0.15),
    },
    "RVGTargetTracking": {
        "approach_speed": (2.0, 3.0, 4.0, 5.0, 6.0),
        "min_thrust": (0.0, 0.25, 0.5),
        "omega_n": (None, 0.5),
        "reference_omega": (0.1, 0.3),
        "max_turn_rate": (0.03, 0.08),
    },
}


def candidates(grid: Mapping[str, Sequence[float | None]]) -> list[dict[str, float | None]]:
    """Every combination of ``grid``'s values, the first value of each parameter first."""
    names = list(grid)
    return [dict(zip(names, values, strict=True)) for values in itertools.product(*grid.values())]


def tune(
    env_id: str,
    episodes: int = TUNING_EPISODES,
    seed: int = TUNING_SEED,
    grid: Mapping[str, Sequence[float | None]] | None = None,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Choose the classic policy's design parameters for ``env_id`` by a grid search.

    Parameters
    ----------
    env_id : str
        One of :data:`shipgym.envs.ENV_IDS`.
    episodes, seed : int
        Episodes per candidate and the first seed (default: the RL training seeds 0-15).
    grid : mapping, optional
        Design parameter -> values (default :data:`SEARCH` of the env's task). Every name must
        be one of the policy's ``DESIGN`` parameters.
    progress : callable, optional
        Called with a line per candidate (default: print to stderr).

    Returns
    -------
    dict
        The record: ``env``, ``nominal``, ``design`` (the winner, every design parameter),
        ``score`` and ``design_rule_score`` (mean return), ``candidates`` (each with its mean
        and standard deviation of the return), ``grid``, ``episodes``, ``seeds``,
        ``budget`` (``candidates``, ``episodes``, ``env_steps``) and ``wall_time_s``.
    """
    if env_id not in ENV_IDS:
        raise ValueError(f"unknown env {env_id!r}; expected one of {ENV_IDS}")
    if not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    task = env_task(env_id)
    grid = dict(SEARCH[task] if grid is None else grid)
    design_rule = CLASSIC[task].DESIGN
    unknown = sorted(set(grid) - set(design_rule))
    if unknown or not grid or any(len(v) == 0 for v in grid.values()):
        raise ValueError(
            f"grid for {env_id} must give at least one value for some of {sorted(design_rule)}; "
            f"got {dict(grid)!r}"
        )
    if progress is None:

        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)

    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    env_steps = 0
    todo = candidates(grid)
    rule = {k: design_rule[k] for k in grid}
    if rule not in todo:  # the design rule is always scored, on the same episodes
        todo.append(rule)

    def score(design: dict[str, float | None], label: str) -> dict[str, Any]:
        nonlocal env_steps
        result = evaluate(
            env_id,
            classic_policy(env_id, **design),
            "classic",
            episodes,
            seed,
            progress=lambda line: None,
        )
        env_steps += sum(len(log.time) for log in result.logs)
        returns = np.asarray(result.returns)
        row = {
            "design": dict(design),
            # a design that blows up in any episode never wins (its returns are undefined)
            "mean_return": -math.inf if result.blown_up else float(returns.mean()),
            "std_return": math.nan if result.blown_up else float(returns.std()),
            "blown_up": result.blown_up,
        }
        rows.append(row)
        progress(
            f"[{label}] {env_id} "
            + ", ".join(f"{n}={_fmt(v)}" for n, v in design.items())
            + f": return {row['mean_return']:.1f} +- {row['std_return']:.1f}"
        )
        return row

    for k, design in enumerate(todo, 1):
        score(design, f"{k}/{len(todo)}")
    best = max(rows, key=lambda r: r["mean_return"])
    # a winner on the edge of the grid is not a result: step beyond the edge (the grid's own
    # ratio) while that improves the return
    for _ in range(MAX_EDGE_STEPS):
        improved = False
        for name, values in grid.items():
            beyond = _beyond_edge(values, best["design"][name], BOUNDS.get(name, (0, math.inf)))
            if beyond is None:
                continue
            row = score({**best["design"], name: beyond}, "edge")
            if row["mean_return"] > best["mean_return"]:
                best, improved = row, True
        if not improved:
            break
    rule_row = next(r for r in rows if r["design"] == rule)
    return {
        "env": env_id,
        "nominal": nominal_ship(env_id),
        "design": {**design_rule, **best["design"]},
        "score": best["mean_return"],
        "design_rule": dict(design_rule),
        "design_rule_score": rule_row["mean_return"],
        "grid": {k: list(v) for k, v in grid.items()},
        "episodes": episodes,
        "seeds": [seed, seed + episodes - 1],
        "budget": {
            "candidates": len(rows),
            "episodes": len(rows) * episodes,
            "env_steps": env_steps,
        },
        "candidates": rows,
        "wall_time_s": round(time.perf_counter() - start, 1),
    }


def _beyond_edge(
    values: Sequence[float | None],
    value: float | None,
    bounds: tuple[float, float] = (0.0, math.inf),
) -> float | None:
    """The next value past the end of ``values`` that ``value`` sits on (geometric step of the
    last two values, held within ``bounds``), or ``None`` if ``value`` is inside the grid, is
    ``None`` (the design rule), is 0 (off) or already at the bound."""
    grid = sorted(v for v in values if v is not None and v > 0)
    if value is None or value <= 0 or len(grid) < 2:
        return None
    if value >= grid[-1]:
        nxt = min(value * grid[-1] / grid[-2], bounds[1])
    elif value <= grid[0]:
        nxt = max(value * grid[0] / grid[1], bounds[0])
    else:
        return None
    return None if math.isclose(nxt, value) else nxt


def _fmt(value: float | None) -> str:
    return "rule" if value is None else f"{value:g}"


def tuned_path(env_id: str, directory: str | Path | None = None) -> Path:
    """Path of the tuned-gains record of ``env_id`` (default folder :data:`TUNED_DIR`)."""
    return Path(directory or TUNED_DIR) / f"{env_id.split('/')[-1]}.json"


def write_tuned(record: dict[str, Any], directory: str | Path | None = None) -> Path:
    """Write a :func:`tune` record as ``<directory>/<env>.json``."""
    path = tuned_path(record["env"], directory)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(record, indent=1) + "\n")
    return path


def load_tuned(env_id: str, directory: str | Path | None = None) -> dict[str, Any]:
    """The tuned-gains record of ``env_id`` (:func:`tune`'s output).

    Raises
    ------
    FileNotFoundError
        If none exists for ``env_id``, naming the command that makes one.
    ValueError
        If the record is for another env or names unknown design parameters.
    """
    if env_id not in ENV_IDS:
        raise ValueError(f"unknown env {env_id!r}; expected one of {ENV_IDS}")
    path = tuned_path(env_id, directory)
    if not path.is_file():
        raise FileNotFoundError(
            f"no tuned classic gains for {env_id} (missing {path}); make them with "
            f"'python scripts/tune_classic.py --only {env_id.split('/')[-1]}'"
        )
    record = json.loads(path.read_text())
    design = record.get("design")
    if record.get("env") != env_id or not isinstance(design, dict):
        raise ValueError(f"{path}: not a tuned-gains record of {env_id} (no 'env' and 'design')")
    try:
        classic_policy(env_id, **design)  # the policy checks every name and value
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from None
    return record


__all__ = [
    "BOUNDS",
    "SEARCH",
    "TUNED_DIR",
    "TUNING_EPISODES",
    "TUNING_SEED",
    "candidates",
    "load_tuned",
    "tune",
    "tuned_path",
    "write_tuned",
]

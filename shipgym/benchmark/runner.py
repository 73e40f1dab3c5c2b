"""The benchmark: every env, every controller, identical scenarios, nominal, stressed and on
the wrong ship.

:func:`run_benchmark` evaluates the ``classic`` controller, the trained ``ppo`` and ``sac``
agents and the ``zero`` command with :func:`shipgym.benchmark.evaluate.evaluate` on the same
seeds (episode ``k`` has seed ``seed + k``: the same initial state, setpoints, path, target and
current draw for every controller). Three conditions:

* ``nominal``: the env's own current draws (speed uniform in ``[0, max_current_speed]``, the
  range the agents were trained on);
* ``stress``: the current speed fixed at ``STRESS_FACTOR`` (1.5) times that training maximum,
  with the same seeded directions (no different from nominal for the Nomoto ship: a uniform
  current does not enter its yaw dynamics);
* ``mismatch``: the same scenarios on a ship the agents and the classic gains were not made for
  (:data:`MISMATCH_KWARGS`: the nonlinear Bech Mariner instead of the first-order Nomoto one;
  the sea-trial Gunnerus instead of seed 001's).

The default first seed, :data:`shipgym.rl.train.BENCHMARK_SEED`, lies outside every agent's
training and validation seeds; :func:`run_benchmark` checks that against each agent's record.
"""

from __future__ import annotations

import csv
import json
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym

from shipgym.benchmark.evaluate import METRICS, EvaluationResult, evaluate
from shipgym.benchmark.policies import POLICIES, make_policy
from shipgym.envs import ENV_IDS
from shipgym.rl.train import BENCHMARK_SEED

CONTROLLERS = ("classic", "ppo", "sac", "zero")
CONDITIONS = ("nominal", "stress", "mismatch")
#: Stress condition: current speed as a multiple of the training maximum.
STRESS_FACTOR = 1.5
#: Model-mismatch condition: the ship the agents and gains were not made for (the nonlinear
#: Bech Mariner for the first-order Nomoto env; the sea-trial Gunnerus for the seed-001 one).
MISMATCH_KWARGS: dict[str, dict[str, Any]] = {
    "shipgym/NomotoHeading-v0": {"model": "bech"},
    "shipgym/RVGHeading-v0": {"params": "sea_trials"},
    "shipgym/RVGSpeed-v0": {"params": "sea_trials"},
    "shipgym/RVGPathFollowing-v0": {"params": "sea_trials"},
    "shipgym/RVGTargetTracking-v0": {"params": "sea_trials"},
}


@dataclass
class BenchmarkResult:
    """The evaluations of a benchmark run and its settings."""

    results: list[EvaluationResult]
    episodes: int
    seed: int
    stress_current: dict[str, float]
    runtime_s: float
    throughput: list[dict[str, Any]] | None = None
    agents: dict[str, dict[str, Any]] = field(default_factory=dict)

    @property
    def envs(self) -> list[str]:
        """The env ids evaluated, in order."""
        return list(dict.fromkeys(r.env for r in self.results))

    @property
    def controllers(self) -> list[str]:
        """The controllers evaluated, in order."""
        return list(dict.fromkeys(r.controller for r in self.results))

    @property
    def conditions(self) -> list[str]:
        """The conditions evaluated, in order."""
        return list(dict.fromkeys(r.condition for r in self.results))

    def get(self, env_id: str, controller: str, condition: str = "nominal") -> EvaluationResult:
        """The evaluation of one (env, controller, condition)."""
        for r in self.results:
            if (r.env, r.controller, r.condition) == (env_id, controller, condition):
                return r
        raise KeyError((env_id, controller, condition))

    def to_list(self) -> list[dict[str, Any]]:
        """The JSON document: a list of ``shipgym evaluate`` objects (with ``condition``)."""
        return [r.to_dict() for r in self.results]

    def rows(self) -> list[dict[str, Any]]:
        """Long-form rows (one per env, controller, condition and metric) for the CSV."""
        rows = []
        for r in self.results:
            d = r.to_dict()
            base = {
                "env": r.env,
                "controller": r.controller,
                "condition": r.condition,
                "episodes": r.episodes,
                "seed": r.seed,
                "current_speed": r.options.get("current_speed", ""),
            }
            rows.append(
                {**base, "metric": "return", "mean": d["mean_return"], "std": d["std_return"]}
            )
            for key, value in d["metrics"].items():
                rows.append({**base, "metric": key, "mean": value, "std": d["metrics_std"][key]})
        return rows

    def write_json(self, path: str | Path) -> Path:
        """Write :meth:`to_list` as JSON."""
        path = Path(path)
        path.write_text(json.dumps(self.to_list(), indent=2) + "\n")
        return path

    def write_csv(self, path: str | Path) -> Path:
        """Write :meth:`rows` as CSV."""
        path = Path(path)
        rows = self.rows()
        with path.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        return path

    def table(self) -> str:
        """Plain-text table: per env, each controller's return and metrics, mean +- std."""
        lines = [
            f"{self.episodes} episodes per cell from seed {self.seed}; stress = current at "
            f"{STRESS_FACTOR:g} x the training maximum; mean +- std over episodes"
        ]
        controllers, conditions = self.controllers, self.conditions
        for env_id in self.envs:
            stress = self.stress_current.get(env_id)
            lines.append("")
            lines.append(
                env_id + (f" (stress current {stress:.2f} m/s)" if "stress" in conditions else "")
            )
            keys = ("return", *METRICS[env_id])
            header = ["controller", "condition", *keys]
            body = [
                [name, cond] + [_cell(self.get(env_id, name, cond), key) for key in keys]
                for name in controllers
                for cond in conditions
            ]
            widths = [max(len(r[i]) for r in [header, *body]) for i in range(len(header))]
            for r in [header, *body]:
                lines.append(
                    ("  " + "  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True))).rstrip()
                )
        return "\n".join(lines)


def _cell(result: EvaluationResult, key: str) -> str:
    d = result.to_dict()
    if key == "return":
        return f"{d['mean_return']:.1f} +- {d['std_return']:.1f}"
    return f"{d['metrics'][key]:.3g} +- {d['metrics_std'][key]:.2g}"


def training_max_current(env_id: str) -> float:
    """The env's default ``max_current_speed`` [m/s], the range the agents train on."""
    env = gym.make(env_id)
    try:
        return float(env.unwrapped.task.max_current_speed)
    finally:
        env.close()


def check_seeds_disjoint(meta: dict[str, Any], seed: int, episodes: int) -> None:
    """Raise ``ValueError`` if ``[seed, seed + episodes)`` meets an agent's own seeds."""
    for key in ("training_seeds", "validation_seeds"):
        lo, hi = meta[key]
        if seed <= hi and lo <= seed + episodes - 1:
            raise ValueError(
                f"evaluation seeds {seed}..{seed + episodes - 1} overlap the {key.split('_')[0]} "
                f"seeds {lo}..{hi} of agent {meta['name']}; choose a first seed outside them "
                f"(the default {BENCHMARK_SEED} is)"
            )


def run_benchmark(
    episodes: int = 100,
    seed: int = BENCHMARK_SEED,
    envs: Sequence[str] = ENV_IDS,
    controllers: Sequence[str] = CONTROLLERS,
    conditions: Sequence[str] = CONDITIONS,
    agents_dir: str | Path | None = None,
    progress: Callable[[str], None] | None = None,
) -> BenchmarkResult:
    """Evaluate ``controllers`` on ``envs`` under ``conditions`` on identical seeds.

    Parameters
    ----------
    episodes : int
        Episodes per (env, controller, condition); seeds ``seed .. seed + episodes - 1``.
    seed : int
        First seed; must miss the agents' training and validation seeds.
    envs, controllers, conditions : sequence of str
        Subsets of :data:`~shipgym.envs.ENV_IDS`, :data:`CONTROLLERS`, :data:`CONDITIONS`.
    agents_dir : path, optional
        Folder of the PPO/SAC agents (default: the shipped ones).
    progress : callable, optional
        Called with a line per finished evaluation (default: print to stderr).

    Returns
    -------
    BenchmarkResult
    """
    if not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    for name, given, allowed in (
        ("env", envs, ENV_IDS),
        ("controller", controllers, POLICIES),
        ("condition", conditions, CONDITIONS),
    ):
        bad = [g for g in given if g not in allowed]
        if bad or not given:
            raise ValueError(f"unknown {name}(s) {bad or given!r}; expected some of {allowed}")
    if progress is None:

        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)

    start = time.perf_counter()
    policies: dict[tuple[str, str], Any] = {}
    agents: dict[str, dict[str, Any]] = {}
    for env_id in envs:  # load (and check) every policy before the first episode
        for name in controllers:
            policy = make_policy(name, env_id, agents_dir)
            if hasattr(policy, "meta"):
                check_seeds_disjoint(policy.meta, seed, episodes)
                agents[policy.meta["name"]] = {
                    k: policy.meta[k] for k in ("env", "algo", "timesteps", "seed", "wall_time_s")
                }
            policies[env_id, name] = policy
    stress_current = {env_id: STRESS_FACTOR * training_max_current(env_id) for env_id in envs}
    results = []
    total = len(envs) * len(controllers) * len(conditions)
    for env_id in envs:
        for condition in conditions:
            options = {"current_speed": stress_current[env_id]} if condition == "stress" else None
            env_kwargs = MISMATCH_KWARGS[env_id] if condition == "mismatch" else None
            for name in controllers:
                t0 = time.perf_counter()
                result = evaluate(
                    env_id,
                    policies[env_id, name],
                    name,
                    episodes=episodes,
                    seed=seed,
                    env_kwargs=env_kwargs,
                    reset_options=options,
                    progress=lambda line: None,
                    condition=condition,
                )
                results.append(result)
                d = result.to_dict()
                progress(
                    f"[{len(results)}/{total}] {env_id} {name} {condition}: return "
                    f"{d['mean_return']:.1f} +- {d['std_return']:.1f} "
                    f"({time.perf_counter() - t0:.1f} s)"
                )
    return BenchmarkResult(
        results=results,
        episodes=episodes,
        seed=seed,
        stress_current=stress_current,
        runtime_s=time.perf_counter() - start,
        agents=agents,
    )

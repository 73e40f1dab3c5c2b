"""The benchmark: every env, every controller, identical scenarios, nominal and under the
conditions a ship meets: strong current, the wrong ship, noisy sensors, a slow actuator.

:func:`run_benchmark` evaluates the ``classic`` controller with its design-rule gains and with
its tuned gains (``classic-tuned``), the trained ``ppo`` and ``sac`` agents and the ``zero``
command with :func:`shipgym.benchmark.evaluate.evaluate` on the same seeds (episode ``k`` has
seed ``seed + k``: the same initial state, setpoints, path, target and current draw for every
controller). Conditions:

* ``nominal``: the env's own current draws (speed uniform in ``[0, max_current_speed]``, the
  range the agents were trained on);
* ``stress``: the current speed fixed at ``STRESS_FACTOR`` (1.5) times that training maximum,
  with the same seeded directions (no different from nominal for the Nomoto ship: a uniform
  current does not enter its yaw dynamics);
* ``mismatch``: the same scenarios on ships the agents and the classic gains were not made for
  (:data:`MISMATCH_SHIPS`: the nonlinear Bech and Norrbin Mariners for the first-order Nomoto
  env; the other Gunnerus parameter set for the Gunnerus envs), one result per ship, labelled
  ``mismatch:<ship>``;
* ``noise``: :class:`~shipgym.envs.wrappers.SensorNoise` at its default levels (heading 0.5
  deg, yaw rate 0.1 deg/s, speed 0.1 m/s, position 1 m);
* ``delay``: :class:`~shipgym.envs.wrappers.ActuatorDelay` of :data:`ACTUATOR_DELAY_STEPS`
  control steps (1 s on the Gunnerus, 2 s on the Mariner).

The ``zero`` command, a baseline, runs in the nominal condition only. The default first seed,
:data:`shipgym.rl.train.BENCHMARK_SEED`, lies outside every agent's training and validation
seeds and the tuning seeds; :func:`run_benchmark` checks that against each agent's record.
"""

from __future__ import annotations

import csv
import json
import multiprocessing
import os
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym

from shipgym.benchmark.evaluate import METRICS, EvaluationResult, evaluate
from shipgym.benchmark.policies import POLICIES, make_policy
from shipgym.envs import CURRENT_ENV_IDS, ENV_IDS, env_task
from shipgym.envs.wrappers import ActuatorDelay, SensorNoise
from shipgym.rl.train import BENCHMARK_SEED

CONTROLLERS = ("classic", "classic-tuned", "ppo", "sac", "zero")
CONDITIONS = ("nominal", "stress", "mismatch", "noise", "delay")
#: Controllers run in the nominal condition only (baselines).
NOMINAL_ONLY = ("zero",)
#: Stress condition: current speed as a multiple of the training maximum.
STRESS_FACTOR = 1.5
#: Actuator-delay condition: the delay in control steps of the env.
ACTUATOR_DELAY_STEPS = 2
#: Model-mismatch condition: the ships the agents and gains were not made for, by label (the
#: nonlinear Bech and Norrbin Mariners for the first-order Nomoto env; for the Gunnerus envs
#: the other parameter set: seed 001's for the sea-trial ship of ``-v1``, the sea-trial ship
#: for ``-v0``).
MISMATCH_SHIPS: dict[str, dict[str, dict[str, Any]]] = {
    env_id: (
        {"bech": {"model": "bech"}, "norrbin": {"model": "norrbin"}}
        if env_task(env_id) == "NomotoHeading"
        else {"seed001": {"params": "seed001"}}
        if env_id.endswith("-v1")
        else {"sea_trials": {"params": "sea_trials"}}
    )
    for env_id in ENV_IDS
}


def condition_order(label: str) -> int:
    """Sort key of a scenario label (``"mismatch:bech"``): its condition's place in
    :data:`CONDITIONS`."""
    return CONDITIONS.index(label.split(":")[0])


@dataclass(frozen=True)
class Scenario:
    """One condition of one env as :func:`evaluate` runs it."""

    label: str
    env_kwargs: dict[str, Any] | None = None
    reset_options: dict[str, Any] | None = None
    wrappers: tuple[Callable[[gym.Env], gym.Env], ...] = ()


def scenarios(env_id: str, condition: str, stress_current: float) -> list[Scenario]:
    """The scenarios of ``condition`` on ``env_id`` (one per mismatched ship)."""
    if condition == "nominal":
        return [Scenario("nominal")]
    if condition == "stress":
        return [Scenario("stress", reset_options={"current_speed": stress_current})]
    if condition == "mismatch":
        return [
            Scenario(f"mismatch:{label}", env_kwargs=kwargs)
            for label, kwargs in MISMATCH_SHIPS[env_id].items()
        ]
    if condition == "noise":
        return [Scenario("noise", wrappers=(SensorNoise,))]
    if condition == "delay":

        def delayed(env: gym.Env) -> gym.Env:
            return ActuatorDelay(env, ACTUATOR_DELAY_STEPS * env.unwrapped.dt)

        return [Scenario("delay", wrappers=(delayed,))]
    raise ValueError(f"unknown condition {condition!r}; expected one of {CONDITIONS}")


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
        """The conditions evaluated (scenario labels), in the order of :data:`CONDITIONS`."""
        return sorted(dict.fromkeys(r.condition for r in self.results), key=condition_order)

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
                "blown_up": r.blown_up,
            }
            rows.append(
                {**base, "metric": "return", "mean": d["mean_return"], "std": d["std_return"]}
            )
            for key, value in d["metrics"].items():
                rows.append({**base, "metric": key, "mean": value, "std": d["metrics_std"][key]})
        return rows

    def write_json(self, path: str | Path) -> Path:
        """Write :meth:`to_list` as JSON, one evaluation per line (the per-episode values
        make an indented file needlessly long)."""
        path = Path(path)
        path.write_text("[\n" + ",\n".join(json.dumps(d) for d in self.to_list()) + "\n]\n")
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
                [r.controller, r.condition] + [_cell(r, key) for key in keys]
                for name in controllers
                for cond in conditions
                for r in self.results
                if (r.env, r.controller, r.condition) == (env_id, name, cond)
            ]
            widths = [max(len(r[i]) for r in [header, *body]) for i in range(len(header))]
            for r in [header, *body]:
                lines.append(
                    ("  " + "  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True))).rstrip()
                )
        return "\n".join(lines)


def _cell(result: EvaluationResult, key: str) -> str:
    if result.blown_up:
        return f"blew up {result.blown_up}/{result.episodes}" if key == "return" else "-"
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
    """Raise ``ValueError`` if ``[seed, seed + episodes)`` meets the seeds an agent was
    trained or selected on, or the seeds tuned gains were chosen on (``*_seeds`` entries of
    ``meta``)."""
    for key in ("training_seeds", "validation_seeds", "tuning_seeds"):
        if key not in meta:
            continue
        lo, hi = meta[key]
        if seed <= hi and lo <= seed + episodes - 1:
            raise ValueError(
                f"evaluation seeds {seed}..{seed + episodes - 1} overlap the {key.split('_')[0]} "
                f"seeds {lo}..{hi} of {meta['name']}; choose a first seed outside them "
                f"(the default {BENCHMARK_SEED} is)"
            )


def _one_thread() -> None:
    """Worker initializer: one torch thread per worker process (the workers share the cores)."""
    try:
        import torch
    except ImportError:  # pragma: no cover - the rl extra is not installed
        return
    torch.set_num_threads(1)


def _evaluate_cell(
    env_id: str,
    condition: str,
    label: str,
    stress: float,
    name: str,
    episodes: int,
    seed: int,
    agents_dir: str | Path | None,
    keep_logs: int | None,
) -> EvaluationResult:
    """One benchmark cell: ``name`` on the ``label`` scenario of ``condition`` on ``env_id``
    (the policy is made here, so that a worker process needs nothing but these arguments)."""
    scenario = next(s for s in scenarios(env_id, condition, stress) if s.label == label)
    result = evaluate(
        env_id,
        make_policy(name, env_id, agents_dir),
        name,
        episodes=episodes,
        seed=seed,
        env_kwargs=scenario.env_kwargs,
        reset_options=scenario.reset_options,
        progress=lambda line: None,
        condition=label,
        wrappers=scenario.wrappers,
    )
    if keep_logs is not None:
        result.logs = result.logs[:keep_logs]
    return result


def run_benchmark(
    episodes: int = 100,
    seed: int = BENCHMARK_SEED,
    envs: Sequence[str] = CURRENT_ENV_IDS,
    controllers: Sequence[str] = CONTROLLERS,
    conditions: Sequence[str] = CONDITIONS,
    agents_dir: str | Path | None = None,
    progress: Callable[[str], None] | None = None,
    jobs: int | None = None,
    keep_logs: int | None = 1,
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
    jobs : int, optional
        Evaluations run at once, each in its own process (default: one per core); 1 runs
        them in this process. The results are the same either way.
    keep_logs : int or None
        Episode logs kept per evaluation (1: the first, for the trajectory figures; ``None``:
        all). The metrics and per-episode values are kept for every episode regardless.

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
    jobs = (os.cpu_count() or 1) if jobs is None else jobs
    if not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs must be an integer >= 1, got {jobs!r}")
    if progress is None:

        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)

    start = time.perf_counter()
    agents: dict[str, dict[str, Any]] = {}
    for env_id in envs:  # load (and check) every policy before the first episode
        for name in controllers:
            policy = make_policy(name, env_id, agents_dir)
            if hasattr(policy, "meta"):
                check_seeds_disjoint(policy.meta, seed, episodes)
                agents[policy.meta["name"]] = {
                    k: policy.meta[k] for k in ("env", "algo", "timesteps", "seed", "wall_time_s")
                }
            if name == "classic-tuned":
                from shipgym.benchmark.tuning import load_tuned

                tuned = load_tuned(env_id)
                check_seeds_disjoint(
                    {"name": f"{env_id} classic-tuned", "tuning_seeds": tuned["seeds"]},
                    seed,
                    episodes,
                )
    stress_current = {env_id: STRESS_FACTOR * training_max_current(env_id) for env_id in envs}
    cells = [
        (env_id, condition, scenario.label, stress_current[env_id], name, episodes, seed,
         agents_dir, keep_logs)
        for env_id in envs
        for condition in conditions
        for scenario in scenarios(env_id, condition, stress_current[env_id])
        for name in controllers
        if scenario.label == "nominal" or name not in NOMINAL_ONLY
    ]  # fmt: skip
    results: list[EvaluationResult] = []

    def report(result: EvaluationResult, seconds: float) -> None:
        results.append(result)
        progress(
            f"[{len(results)}/{len(cells)}] {result.env} {result.controller} {result.condition}: "
            f"return {_cell(result, 'return')} ({seconds:.1f} s)"
        )

    if jobs == 1:
        for cell in cells:
            t0 = time.perf_counter()
            report(_evaluate_cell(*cell), time.perf_counter() - t0)
    else:
        context = multiprocessing.get_context("spawn")  # no fork of torch's or numba's threads
        with ProcessPoolExecutor(jobs, mp_context=context, initializer=_one_thread) as pool:
            t0 = time.perf_counter()
            futures = {pool.submit(_evaluate_cell, *cell): k for k, cell in enumerate(cells)}
            for future in as_completed(futures):
                report(future.result(), time.perf_counter() - t0)
        order = {(c[0], c[2], c[4]): k for k, c in enumerate(cells)}  # env, label, controller
        results.sort(key=lambda r: order[r.env, r.condition, r.controller])
    return BenchmarkResult(
        results=results,
        episodes=episodes,
        seed=seed,
        stress_current=stress_current,
        runtime_s=time.perf_counter() - start,
        agents=agents,
    )

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
* ``noise``: :class:`~shipgym.envs.wrappers.VectorSensorNoise` at its default levels (heading 0.5
  deg, yaw rate 0.1 deg/s, speed 0.1 m/s, position 1 m);
* ``delay``: :class:`~shipgym.envs.wrappers.VectorActuatorDelay` of :data:`ACTUATOR_DELAY_STEPS`
  control steps (1 s on the Gunnerus, 2 s on the Mariner);
* ``seaway``: the ship at sea (:data:`SEAWAY`): a moderate sea, WMO sea state 4 (``H_s``
  2.0 m, JONSWAP with gamma 3.3, the peak period of each ship's waters) and a fresh breeze,
  Beaufort 5 (9.5 m/s at 10 m, with NORSOK gusts), the wind's and the waves' directions drawn
  uniformly per episode (from its seed: the same sea for every controller), on top of the
  env's own current. The controllers sail on the measured heading, which carries the
  wave-frequency motion; the heading tasks' ``lf_heading_rms_deg`` is the error of the
  low-frequency heading the autopilot is to hold.

The ``zero`` command, a baseline, runs in the nominal condition only; ``classic-wf`` (the
``classic`` controller with a wave filter in its heading loop, which in calm water passes the
heading through unchanged) in the seaway condition only. The default first seed,
:data:`shipgym.rl.train.BENCHMARK_SEED`, lies outside every agent's training and validation
seeds and the tuning seeds; :func:`run_benchmark` checks that against each agent's record.

Campaigns that outgrow one machine run on Ray (``ray=`` of :func:`run_benchmark` and
:func:`run_evaluation`, ``--ray`` of the commands): each cell's episodes are split into
:class:`EpisodeBatch` es of consecutive seeds, each batch is one Ray task running
:func:`~shipgym.benchmark.evaluate.evaluate`, and the batches are merged back
(:func:`~shipgym.benchmark.evaluate.merge_results`). An episode's numbers depend on its seed
only, so the results equal those of a local run with the same seeds.
"""

from __future__ import annotations

import csv
import json
import math
import multiprocessing
import os
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import VectorEnv

from shipgym.benchmark.evaluate import (
    METRICS,
    EpisodeError,
    EvaluationResult,
    evaluate,
    merge_results,
)
from shipgym.benchmark.policies import POLICIES, make_policy
from shipgym.envs import CURRENT_ENV_IDS, ENV_IDS, env_task
from shipgym.envs.wrappers import VectorActuatorDelay, VectorSensorNoise
from shipgym.rl.agents import agent_files, load_meta
from shipgym.rl.train import ALGOS, BENCHMARK_SEED

CONTROLLERS = ("classic", "classic-wf", "classic-tuned", "ppo", "sac", "zero")
CONDITIONS = ("nominal", "stress", "mismatch", "noise", "delay", "seaway")
#: Controllers run in the nominal condition only (baselines).
NOMINAL_ONLY = ("zero",)
#: Controllers run in the seaway condition only (in calm water the same as another).
SEAWAY_ONLY = ("classic-wf",)
#: Seaway condition: significant wave height [m] (WMO sea state 4, "moderate", 1.25-2.5 m).
SEAWAY_HEIGHT = 2.0
#: Seaway condition: mean wind speed at 10 m [m/s] (Beaufort 5, "fresh breeze", 8.0-10.7 m/s).
SEAWAY_WIND_SPEED = 9.5
#: Seaway condition: peak period [s] of each task's waters. The Mariner, an ocean-going cargo
#: ship: 8.8 s, the most probable modal period of sea state 4 in the open North Atlantic
#: (Lee and Bales 1984, as tabulated in NATO STANAG 4194). The R/V Gunnerus, a coastal
#: research vessel off mid-Norway: 7.0 s, the fully developed wind sea of the fresh breeze
#: itself (Pierson-Moskowitz, ``omega_p = 0.877 g / U`` and ``H_s = 0.21 U^2 / g``: 6.9 to
#: 7.1 s and 1.9 to 2.0 m for ``U`` 9.5 m/s at 10 m to 9.75 m/s at 19.5 m), shorter than the
#: ocean's mixed sea with swell.
SEAWAY_PERIOD: dict[str, float] = {
    "NomotoHeading": 8.8,
    "RVGHeading": 7.0,
    "RVGSpeed": 7.0,
    "RVGPathFollowing": 7.0,
    "RVGTargetTracking": 7.0,
}
#: The seaway condition of each task (:func:`env_task`): the ``wind`` and ``sea_state``
#: options of every episode's reset (directions left out: drawn uniformly per episode).
SEAWAY: dict[str, dict[str, dict[str, float]]] = {
    task: {
        "wind": {"speed": SEAWAY_WIND_SPEED},
        "sea_state": {"significant_height": SEAWAY_HEIGHT, "peak_period": period},
    }
    for task, period in SEAWAY_PERIOD.items()
}
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
    """One condition of one env as :func:`evaluate` runs it.

    ``design_model`` is the ship the classic controllers of the Nomoto env are designed on
    (``make_policy(..., model=)``; None: the env's nominal ship). ``shipgym evaluate --model``
    sails and designs on the same ship; the mismatch condition sails another ship
    (``env_kwargs``) and keeps the design on the nominal one, as the agents keep their training.
    """

    label: str
    env_kwargs: dict[str, Any] | None = None
    reset_options: dict[str, Any] | None = None
    wrappers: tuple[Callable[[VectorEnv], VectorEnv], ...] = ()
    design_model: str | None = None


def delayed(env: VectorEnv) -> VectorEnv:
    """``env`` behind the delay condition's actuator delay: :data:`ACTUATOR_DELAY_STEPS`
    control steps (:class:`~shipgym.envs.wrappers.VectorActuatorDelay`)."""
    return VectorActuatorDelay(env, ACTUATOR_DELAY_STEPS * env.unwrapped.task.dt)


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
        return [Scenario("noise", wrappers=(VectorSensorNoise,))]
    if condition == "delay":
        return [Scenario("delay", wrappers=(delayed,))]
    if condition == "seaway":
        return [Scenario("seaway", reset_options=SEAWAY[env_task(env_id)])]
    raise ValueError(f"unknown condition {condition!r}; expected one of {CONDITIONS}")


def benchmark_cells(
    envs: Sequence[str], controllers: Sequence[str], conditions: Sequence[str]
) -> list[tuple[str, str, str]]:
    """The cells of a benchmark, in table order: ``(env, condition, scenario label)`` of each
    scenario and each controller (the baselines of :data:`NOMINAL_ONLY` in the nominal
    condition only, those of :data:`SEAWAY_ONLY` in the seaway only), as ``(env, condition,
    label, controller)``."""
    return [
        (env_id, condition, scenario.label, name)
        for env_id in envs
        for condition in conditions
        for scenario in scenarios(env_id, condition, 0.0)
        for name in controllers
        if (scenario.label == "nominal" or name not in NOMINAL_ONLY)
        and (condition == "seaway" or name not in SEAWAY_ONLY)
    ]


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
    if key == "return":
        return f"{result.mean_return:.1f} +- {float(np.std(result.returns)):.1f}"
    return f"{result.metrics[key]:.3g} +- {result.metrics_std[key]:.2g}"


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
                f"(--seed {BENCHMARK_SEED}, the benchmark's and evaluate's default, is)"
            )


#: Ray tasks aimed at per CPU of the cluster when a campaign is split automatically (more
#: than one, so that CPUs whose tasks end early take further ones).
TASKS_PER_CPU = 4
#: Fewest episodes of an automatically sized task (each task makes its env and policy).
MIN_TASK_EPISODES = 10
#: Most episodes of an automatically sized task (a task holds its episodes' envs and logs).
MAX_TASK_EPISODES = 500


@dataclass(frozen=True)
class EpisodeBatch:
    """Episodes of consecutive seeds of one (env, controller, scenario): one Ray task, or a
    whole cell before it is split (:meth:`split`).

    ``keep_logs`` is the number of episode logs returned (from the first seed; ``None``: all).
    The policy is made on the worker from its name, so a batch is a few small values.
    """

    env_id: str
    controller: str
    scenario: Scenario
    seed: int
    episodes: int
    agents_dir: str | None = None
    keep_logs: int | None = None

    def describe(self) -> str:
        """``"<env> <controller> (<condition>), seeds a..b"``."""
        last = self.seed + self.episodes - 1
        seeds = f"seed {self.seed}" if self.episodes == 1 else f"seeds {self.seed}..{last}"
        return f"{self.env_id} {self.controller} ({self.scenario.label}), {seeds}"

    def split(self, size: int) -> list[EpisodeBatch]:
        """This batch as consecutive batches of at most ``size`` episodes, as even as possible,
        the logs kept from the first seeds."""
        n = math.ceil(self.episodes / size)
        base, extra = divmod(self.episodes, n)
        parts, offset = [], 0
        for k in range(n):
            count = base + (k < extra)
            keep = None if self.keep_logs is None else max(0, min(count, self.keep_logs - offset))
            parts.append(replace(self, seed=self.seed + offset, episodes=count, keep_logs=keep))
            offset += count
        return parts

    def run(self) -> EvaluationResult:
        """Evaluate the batch here (on a Ray worker: the task's body)."""
        result = evaluate(
            self.env_id,
            make_policy(
                self.controller,
                self.env_id,
                self.agents_dir,
                model=self.scenario.design_model,
            ),
            self.controller,
            episodes=self.episodes,
            seed=self.seed,
            env_kwargs=self.scenario.env_kwargs,
            reset_options=self.scenario.reset_options,
            progress=lambda line: None,
            condition=self.scenario.label,
            wrappers=self.scenario.wrappers,
        )
        if self.keep_logs is not None:
            result.logs = result.logs[: self.keep_logs]
        return result


def _run_batch(batch: EpisodeBatch) -> EvaluationResult:
    """The Ray task: :meth:`EpisodeBatch.run`."""
    return batch.run()


def _cell_batch(
    env_id: str,
    condition: str,
    label: str,
    stress: float,
    name: str,
    episodes: int,
    seed: int,
    agents_dir: str | Path | None,
    keep_logs: int | None,
) -> EpisodeBatch:
    """The benchmark cell ``name`` on the ``label`` scenario of ``condition`` on ``env_id``."""
    scenario = next(s for s in scenarios(env_id, condition, stress) if s.label == label)
    agents = None if agents_dir is None else str(agents_dir)
    return EpisodeBatch(env_id, name, scenario, seed, episodes, agents, keep_logs)


def _evaluate_cell(*cell: Any) -> EvaluationResult:
    """One benchmark cell, evaluated here (the arguments of :func:`_cell_batch`: names and
    numbers, so that a spawned worker process needs nothing else), with its bootstrap
    intervals computed (in the worker, beside the other cells, rather than one after another
    in the process that writes the tables)."""
    result = _cell_batch(*cell).run()
    _ = result.return_ci95, result.metrics_ci95
    return result


def _episode_steps(env_id: str) -> int:
    """The registered episode length of ``env_id`` [steps]."""
    return int(gym.spec(env_id).max_episode_steps or 0)


def task_episodes(total: int, cpus: int) -> int:
    """Episodes per task for a campaign of ``total`` episodes on ``cpus`` CPUs: about
    :data:`TASKS_PER_CPU` tasks per CPU, within [:data:`MIN_TASK_EPISODES`,
    :data:`MAX_TASK_EPISODES`]."""
    return min(MAX_TASK_EPISODES, max(MIN_TASK_EPISODES, math.ceil(total / (TASKS_PER_CPU * cpus))))


def run_on_ray(
    cells: Sequence[EpisodeBatch],
    address: str | None = None,
    num_cpus: int | None = None,
    task_size: int | None = None,
    progress: Callable[[str], None] | None = None,
    on_cell: Callable[[EvaluationResult, float], None] | None = None,
) -> list[EvaluationResult]:
    """Evaluate ``cells`` as Ray tasks of at most ``task_size`` episodes each.

    Parameters
    ----------
    cells : sequence of EpisodeBatch
        The evaluations (one per env, controller and scenario, over all their seeds).
    address : str, optional
        Ray cluster to join (``host:port``, ``ray://host:port``, ``"auto"``); ``None`` starts
        Ray on this machine (see :func:`shipgym.cluster.ray_session`).
    num_cpus : int, optional
        CPUs of a local Ray (default: every core).
    task_size : int, optional
        Episodes per task (default: :func:`task_episodes` of the campaign on the cluster's
        CPUs). The results do not depend on it.
    progress : callable, optional
        Called with a line per finished task (default: print to stderr).
    on_cell : callable, optional
        Called with each cell's merged result and the seconds since the start when its last
        task finishes.

    Returns
    -------
    list of EvaluationResult
        One per cell, in the order of ``cells``; equal to :func:`evaluate` of each cell.

    Raises
    ------
    EpisodeError
        An episode raised on a worker (names the env, controller, condition and seed).
    shipgym.cluster.ClusterTaskError
        A task failed otherwise (its policy could not be made, its worker died); names the
        env, controller, condition and seeds of the task.
    """
    from shipgym.cluster import cluster_cpus, ray_session, run_tasks

    if task_size is not None and (
        isinstance(task_size, bool) or not isinstance(task_size, int) or task_size < 1
    ):
        raise ValueError(f"task_size must be an integer >= 1 episodes, got {task_size!r}")
    if progress is None:

        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)

    with ray_session(address, num_cpus) as ray:
        cpus = cluster_cpus()
        size = task_size or task_episodes(sum(c.episodes for c in cells), cpus)
        tasks = [(i, part) for i, cell in enumerate(cells) for part in cell.split(size)]
        left = [0] * len(cells)
        for i, _ in tasks:
            left[i] += 1
        parts: list[list[EvaluationResult]] = [[] for _ in cells]
        merged: list[EvaluationResult | None] = [None] * len(cells)
        where = "local Ray" if address is None else f"Ray cluster {address}"
        progress(
            f"{len(tasks)} Ray tasks of up to {size} episodes for {len(cells)} evaluation(s) on "
            f"the {where} ({cpus} CPUs, {ray.__version__})"
        )
        t0 = time.perf_counter()
        finished = 0

        def done(k: int, result: EvaluationResult) -> None:
            nonlocal finished
            finished += 1
            i, batch = tasks[k]
            seconds = time.perf_counter() - t0
            progress(f"[{finished}/{len(tasks)} tasks, {seconds:.1f} s] {batch.describe()} done")
            parts[i].append(result)
            left[i] -= 1
            if left[i] == 0:
                merged[i] = merge_results(parts[i])
                if on_cell is not None:
                    on_cell(merged[i], seconds)

        run_tasks(
            _run_batch,
            [batch for _, batch in tasks],
            describe=EpisodeBatch.describe,
            on_done=done,
            passthrough=(EpisodeError,),
        )
    return [m for m in merged if m is not None]


def evaluate_on_ray(
    env_id: str,
    controller: str,
    episodes: int = 10,
    seed: int = 0,
    *,
    address: str | None = None,
    num_cpus: int | None = None,
    task_size: int | None = None,
    env_kwargs: dict[str, Any] | None = None,
    reset_options: dict[str, Any] | None = None,
    condition: str = "nominal",
    wrappers: Sequence[Callable[[VectorEnv], VectorEnv]] = (),
    agents_dir: str | Path | None = None,
    keep_logs: int | None = None,
    progress: Callable[[str], None] | None = None,
    design_model: str | None = None,
) -> EvaluationResult:
    """:func:`~shipgym.benchmark.evaluate.evaluate` of the controller ``controller`` (one of
    :data:`~shipgym.benchmark.policies.POLICIES`) split into Ray tasks; the same result.

    ``design_model`` is the ship the classic controllers are designed on (:class:`Scenario`).

    ``address``, ``num_cpus``, ``task_size`` and ``progress`` are those of :func:`run_on_ray`;
    the other parameters those of :func:`~shipgym.benchmark.evaluate.evaluate` (``wrappers``
    are sent to the workers, so they must pickle: classes and functions, also local ones).
    ``keep_logs`` episode logs come back (``None``: all; the per-episode values always do).

    Raises
    ------
    ValueError
        An unknown env or controller or a bad count, before Ray starts.
    EpisodeError, shipgym.cluster.ClusterTaskError
        As :func:`run_on_ray`.
    """
    if env_id not in ENV_IDS:
        raise ValueError(f"unknown env {env_id!r}; expected one of {ENV_IDS}")
    if controller not in POLICIES:
        raise ValueError(f"unknown controller {controller!r}; expected one of {POLICIES}")
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    cell = EpisodeBatch(
        env_id,
        controller,
        Scenario(condition, env_kwargs, reset_options, tuple(wrappers), design_model),
        seed,
        episodes,
        None if agents_dir is None else str(agents_dir),
        keep_logs,
    )
    (result,) = run_on_ray([cell], address, num_cpus, task_size, progress)
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
    ray: bool | str = False,
    ray_cpus: int | None = None,
    task_size: int | None = None,
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
        them in this process. The results are the same either way. Not with ``ray``.
    keep_logs : int or None
        Episode logs kept per evaluation (1: the first, for the trajectory figures; ``None``:
        all). The metrics and per-episode values are kept for every episode regardless.
    ray : bool or str
        Run the episodes as Ray tasks (:func:`run_on_ray`) instead of local processes:
        ``True`` or ``"local"`` starts Ray on this machine, ``"host:port"`` (or
        ``"ray://host:port"``, ``"auto"``) joins that cluster. The results are the same.
    ray_cpus : int, optional
        CPUs of a local Ray (default: every core).
    task_size : int, optional
        Episodes per Ray task (default: about four tasks per CPU of the cluster).

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
    address: str | None = None
    if ray is not False:
        from shipgym.cluster import parse_address

        if jobs is not None:
            raise ValueError(
                f"jobs={jobs!r} sets the local process pool; with ray the Ray cluster's CPUs run "
                "the episodes (ray_cpus for a local Ray)"
            )
        address = None if ray is True else parse_address(ray)
        if address is not None and ray_cpus is not None:
            raise ValueError("ray_cpus is for a local Ray only; a cluster has its own CPUs")
    jobs = (os.cpu_count() or 1) if jobs is None else jobs
    if not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs must be an integer >= 1, got {jobs!r}")
    if progress is None:

        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)

    start = time.perf_counter()
    agents: dict[str, dict[str, Any]] = {}
    for env_id in envs:  # check every policy's record before the first episode
        for name in controllers:
            if name in ALGOS:  # the agent's record and file (the workers load the network)
                meta = load_meta(env_id, name, agents_dir)
                weights, _ = agent_files(env_id, name, agents_dir)
                if not weights.is_file():
                    raise FileNotFoundError(
                        f"{meta['name']}: the record is there but the agent {weights} is not"
                    )
                check_seeds_disjoint(meta, seed, episodes)
                agents[meta["name"]] = {
                    k: meta[k] for k in ("env", "algo", "timesteps", "seed", "wall_time_s")
                }
            else:
                make_policy(name, env_id, agents_dir)
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
        (env_id, condition, label, stress_current[env_id], name, episodes, seed, agents_dir,
         keep_logs)
        for env_id, condition, label, name in benchmark_cells(envs, controllers, conditions)
    ]  # fmt: skip
    results: list[EvaluationResult] = []

    def report(result: EvaluationResult, seconds: float) -> None:
        results.append(result)
        progress(
            f"[{len(results)}/{len(cells)}] {result.env} {result.controller} {result.condition}: "
            f"return {_cell(result, 'return')} ({seconds:.1f} s)"
        )

    if ray is not False:
        batches = [_cell_batch(*cell) for cell in cells]
        in_order = run_on_ray(batches, address, ray_cpus, task_size, progress, on_cell=report)
        results[:] = in_order  # cell order, as the local run gives them
    elif jobs == 1:
        for cell in cells:
            t0 = time.perf_counter()
            report(_evaluate_cell(*cell), time.perf_counter() - t0)
    else:
        context = multiprocessing.get_context("spawn")  # no fork of torch's or numba's threads
        pool = ProcessPoolExecutor(jobs, mp_context=context)  # (evaluate: one torch thread)
        try:
            t0 = time.perf_counter()
            # the longest episodes first, so that no worker waits on a long last cell
            longest_first = sorted(cells, key=lambda c: -_episode_steps(c[0]))
            futures = {pool.submit(_evaluate_cell, *cell): cell for cell in longest_first}
            for future in as_completed(futures):
                report(future.result(), time.perf_counter() - t0)
        finally:  # the workers wind down (torch's exit takes a second) while the tables are made
            pool.shutdown(wait=False, cancel_futures=True)
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

"""Training of stable-baselines3 agents (PPO, SAC) on the shipgym environments.

:func:`train` runs SB3 on :class:`shipgym.rl.vec_env.ShipgymVecEnv` (one batched kernel for all
sub-envs), with observation normalisation (``VecNormalize``; rewards too for PPO, whose value
targets it steadies, not for SAC, whose entropy temperature is tuned against the reward
scale), an evaluation callback on fixed validation seeds that keeps the best policy, and a
progress bar. The result is an agent file (SB3 ``.zip``) and a JSON record of how it was made:
algorithm, hyperparameters, budget, seeds, wall time, learning curve, library versions, and the
observation normaliser the policy needs (:func:`shipgym.rl.agents.load_agent` applies it).

Nothing waits for the end: at every evaluation the best policy so far is written as the agent
(its record marked ``"partial": true``) and the latest state as a checkpoint
(:mod:`shipgym.rl.checkpoints`), which :func:`resume` continues with the same counter, curve
and TensorBoard run. SB3's logs go to TensorBoard (``tensorboard/`` of the output folder by
default), with the validation return as ``eval/mean_reward``.

Seeds. Training sub-env ``i`` is seeded with ``seed + i``; the evaluation callback uses
``VALIDATION_SEED + i``; the benchmark evaluates from ``BENCHMARK_SEED`` on. The three ranges
are disjoint for ``seed < VALIDATION_SEED - num_envs``, so no agent is scored on an episode it
was trained or selected on.
"""

from __future__ import annotations

import math
import os
import platform
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.envs import env_task
from shipgym.rl import checkpoints

ALGOS = ("ppo", "sac")
#: First seed of the evaluation callback's validation episodes.
VALIDATION_SEED = 100_000
#: First seed of the benchmark's episodes (``shipgym benchmark``).
BENCHMARK_SEED = 1_000_000

#: Per-algorithm defaults; :data:`TRAINING` overrides them per env.
DEFAULTS: dict[str, dict[str, Any]] = {
    "ppo": {
        "num_envs": 16,
        "timesteps": 2_000_000,
        "hyperparameters": {
            "n_steps": 256,
            "batch_size": 512,
            "n_epochs": 10,
            "gamma": 0.99,
            "gae_lambda": 0.95,
            "learning_rate": 3e-4,
            "clip_range": 0.2,
            "ent_coef": 0.0,
            "policy_kwargs": {"net_arch": [64, 64], "log_std_init": -0.5},
        },
    },
    "sac": {
        "num_envs": 8,
        "timesteps": 200_000,
        "hyperparameters": {
            "buffer_size": 300_000,
            "batch_size": 256,
            "learning_starts": 5_000,
            "train_freq": 1,
            "gradient_steps": 2,
            "gamma": 0.99,
            "tau": 0.005,
            "learning_rate": 3e-4,
            "policy_kwargs": {"net_arch": [64, 64]},
        },
    },
}

#: Budgets and hyperparameters of the shipped agents, by task and algorithm (merged over
#: :data:`DEFAULTS`; ``hyperparameters`` entries replace the default's).
TRAINING: dict[str, dict[str, dict[str, Any]]] = {
    # SAC: three times the budget its validation curves were still rising at (200k-300k
    # steps), so that its curves flatten out before the end
    "NomotoHeading": {"sac": {"timesteps": 600_000}},
    "RVGHeading": {"sac": {"timesteps": 600_000}},
    "RVGSpeed": {"sac": {"timesteps": 600_000}},
    "RVGPathFollowing": {"ppo": {"timesteps": 3_000_000}, "sac": {"timesteps": 900_000}},
    "RVGTargetTracking": {
        "ppo": {"timesteps": 3_000_000},
        # with gamma 0.99, 300k steps gave a validation return of -1176 (zero: about -1430):
        # the approach to a target up to 2 km away needs the longer horizon
        "sac": {"timesteps": 1_000_000, "hyperparameters": {"gamma": 0.995}},
    },
}


def config(env_id: str, algo: str) -> dict[str, Any]:
    """The training configuration (``num_envs``, ``timesteps``, ``hyperparameters``)."""
    task = env_task(env_id)
    if algo not in ALGOS:
        raise ValueError(f"unknown algorithm {algo!r}; expected one of {ALGOS}")
    base = DEFAULTS[algo]
    over = TRAINING[task].get(algo, {})
    return {
        "num_envs": over.get("num_envs", base["num_envs"]),
        "timesteps": over.get("timesteps", base["timesteps"]),
        "hyperparameters": {**base["hyperparameters"], **over.get("hyperparameters", {})},
    }


def agent_name(env_id: str, algo: str) -> str:
    """File stem of an agent: ``NomotoHeading-v0-ppo`` for ``shipgym/NomotoHeading-v0``."""
    return f"{env_id.split('/')[-1]}-{algo}"


@dataclass
class TrainResult:
    """What :func:`train` made: the agent file, its JSON record and the record itself."""

    model_path: Path
    meta_path: Path
    meta: dict[str, Any] = field(repr=False)


def console_logger(verbose: int = 0) -> Any:
    """An SB3 logger that writes to stdout (``verbose >= 1``) or nowhere, and no folder.

    SB3's default logger makes an ``SB3-<date>`` folder in the temporary directory on every
    ``learn`` even when it writes nothing there; pass this to ``model.set_logger`` instead.
    """
    import sys

    from stable_baselines3.common.logger import HumanOutputFormat, Logger

    return Logger(folder=None, output_formats=[HumanOutputFormat(sys.stdout)] if verbose else [])


def _obs_normaliser(vec_normalize: Any) -> dict[str, Any]:
    rms = vec_normalize.obs_rms
    return {
        "mean": [float(v) for v in rms.mean],
        "var": [float(v) for v in rms.var],
        "clip": float(vec_normalize.clip_obs),
        "epsilon": float(vec_normalize.epsilon),
    }


def tensorboard_logger(folder: Path | None, verbose: int = 0) -> Any:
    """An SB3 logger that writes TensorBoard events into ``folder`` (and stdout if verbose).

    ``folder`` None gives :func:`console_logger`. Several event files in one folder (a run
    resumed after an interrupt) show as one run in TensorBoard, the steps continuing.
    """
    import sys

    from stable_baselines3.common.logger import HumanOutputFormat, Logger, TensorBoardOutputFormat

    if folder is None:
        return console_logger(verbose)
    folder.mkdir(parents=True, exist_ok=True)
    formats: list[Any] = [TensorBoardOutputFormat(str(folder))]
    if verbose:
        formats.append(HumanOutputFormat(sys.stdout))
    return Logger(folder=str(folder), output_formats=formats)


def _next_tensorboard_run(root: Path, name: str) -> str:
    """``<name>_<k>`` with ``k`` one more than the runs of ``name`` already in ``root`` (SB3's
    naming: a new training into the same folder is a new run in TensorBoard)."""
    taken = [0]
    if root.is_dir():
        for child in root.iterdir():
            head, _, tail = child.name.rpartition("_")
            if head == name and tail.isdigit():
                taken.append(int(tail))
    return f"{name}_{max(taken) + 1}"


def _tensorboard_root(out: Path, tensorboard_log: str | Path | bool) -> Path | None:
    if tensorboard_log is False:
        return None
    if tensorboard_log is True:
        return out / checkpoints.TENSORBOARD
    return Path(tensorboard_log)


def _versions() -> dict[str, str]:
    import stable_baselines3
    import torch

    return {
        "python": platform.python_version(),
        "stable_baselines3": stable_baselines3.__version__,
        "torch": torch.__version__,
        "numpy": np.__version__,
    }


class _Run:
    """One training session: the model, its envs, the record so far and the checkpoints.

    A fresh training and a resumed one differ only in how the model, the normaliser and the
    record are made; evaluating, checkpointing and finishing are this class.
    """

    def __init__(
        self,
        out: Path,
        record: dict[str, Any],
        model: Any,
        venv: Any,
        eval_env: Any,
        tb_root: Path | None,
        progress: Callable[[str], None] | None,
        on_evaluation: Callable[[dict[str, Any]], None] | None,
        verbose: int,
        best: dict[str, Any] | None = None,
        stop: threading.Event | None = None,
    ) -> None:
        self.out = out
        self.stop = stop
        self.stopped = False
        self.record = record
        self.name = record["name"]
        self.algo = record["algo"]
        self.model = model
        self.venv = venv
        self.eval_env = eval_env
        self.progress = progress
        self.on_evaluation = on_evaluation
        self.best: dict[str, Any] = dict(best or {})
        self.tb_folder = None if tb_root is None else tb_root / record["tensorboard_run"]
        self.logger = tensorboard_logger(self.tb_folder, verbose)
        model.set_logger(self.logger)
        self.wall_before = float(record.get("wall_time_s", 0.0))
        self.steps_at_start = int(model.num_timesteps)
        self.start = time.perf_counter()
        curve = record["learning_curve"]
        self.next_eval = self._after(curve["timesteps"][-1] if curve["timesteps"] else 0)

    def _after(self, step: int) -> int:
        freq = int(self.record["eval_freq"])
        return (step // freq + 1) * freq

    def wall(self) -> float:
        return self.wall_before + time.perf_counter() - self.start

    def snapshot(self, partial: bool, obs_normaliser: dict[str, Any]) -> dict[str, Any]:
        """The record as of now (``partial`` until the requested steps are done)."""
        steps = int(self.model.num_timesteps)
        wall = self.wall()
        curve = self.record["learning_curve"]
        return {
            **self.record,
            "timesteps": steps,
            "partial": partial,
            "wall_time_s": round(wall, 2),
            "steps_per_s": round(steps / max(wall, 1e-9), 1),
            "best_timestep": self.best.get("timestep"),
            "best_validation_return": self.best.get("reward"),
            "final_validation_return": curve["mean_return"][-1] if curve["mean_return"] else None,
            "obs_normaliser": obs_normaliser,
        }

    def evaluate(self, final: bool = False) -> None:
        """Score the deterministic policy on the validation episodes; checkpoint best/latest."""
        from stable_baselines3.common.evaluation import evaluate_policy
        from stable_baselines3.common.vec_env import sync_envs_normalization

        step = int(self.model.num_timesteps)
        curve = self.record["learning_curve"]
        if curve["timesteps"] and curve["timesteps"][-1] == step and not final:
            return
        evaluated = not (curve["timesteps"] and curve["timesteps"][-1] == step)
        if evaluated:
            sync_envs_normalization(self.venv, self.eval_env)
            returns, lengths = evaluate_policy(
                self.model,
                self.eval_env,
                n_eval_episodes=int(self.record["validation_seeds"][1])
                - int(self.record["validation_seeds"][0])
                + 1,
                deterministic=True,
                return_episode_rewards=True,
            )
            mean = float(np.mean(returns))
            curve["timesteps"].append(step)
            curve["mean_return"].append(mean)
            curve["std_return"].append(float(np.std(returns)))
            self.logger.record("eval/mean_reward", mean)
            self.logger.record("eval/mean_ep_length", float(np.mean(lengths)))
            self.logger.dump(step)
            obs = _obs_normaliser(self.venv)
            if not all(math.isfinite(v) for v in obs["mean"]):
                raise RuntimeError(f"{self.name}: the observation normaliser is not finite")
            if "reward" not in self.best or mean > self.best["reward"]:
                self.best = {"obs": obs, "timestep": step, "reward": mean}
                checkpoints.write_best(
                    self.out, self.name, self.model, self.venv, self.snapshot(not final, obs)
                )
        obs = _obs_normaliser(self.venv)
        checkpoints.write_latest(
            self.out,
            self.name,
            self.model,
            self.venv,
            self.snapshot(not final, obs),
            replay_buffer=self.record["checkpoint_replay_buffer"],
        )
        self.next_eval = self._after(step)
        mean = curve["mean_return"][-1]
        if self.progress is not None and evaluated:
            total = int(self.record["requested_timesteps"])
            rate = (step - self.steps_at_start) / max(time.perf_counter() - self.start, 1e-9)
            self.progress(
                f"{self.name}: {step}/{total} steps ({100 * step / total:.0f} %, "
                f"{rate:.0f} steps/s), validation return {mean:.1f}, "
                f"best {self.best['reward']:.1f}"
            )
        if self.on_evaluation is not None:
            self.on_evaluation(
                {
                    "timesteps": step,
                    "validation_return": mean,
                    "best_validation_return": self.best["reward"],
                    "best_timestep": self.best["timestep"],
                    "final": final,
                }
            )

    def callback(self) -> Any:
        """The SB3 callback that evaluates every ``eval_freq`` environment steps."""
        from stable_baselines3.common.callbacks import BaseCallback

        run = self

        class _Evaluations(BaseCallback):
            def _on_step(self) -> bool:
                if run.stop is not None and run.stop.is_set():
                    run.evaluate()  # score and checkpoint the policy of this step, then stop
                    run.stopped = True
                    return False
                if self.num_timesteps >= run.next_eval:
                    run.evaluate()
                return True

        return _Evaluations()

    def learn(self, callbacks: Sequence[Any], progress_bar: bool, fresh: bool) -> TrainResult:
        """Train to the requested steps, evaluate a last time and write the final record."""
        from stable_baselines3.common.callbacks import CallbackList

        total = int(self.record["requested_timesteps"])
        try:
            self.model.learn(
                total - self.steps_at_start,
                callback=CallbackList([self.callback(), *callbacks]),
                progress_bar=progress_bar,
                reset_num_timesteps=fresh,
            )
            if not self.stopped:
                # a final evaluation (unless one fell on the last step), so the end can win too
                self.evaluate(final=True)
        finally:
            self.logger.close()
            self.venv.close()
            self.eval_env.close()
        if self.stopped:
            raise KeyboardInterrupt(f"{self.name}: stopped at step {self.model.num_timesteps}")
        meta = self.snapshot(False, self.best["obs"])
        checkpoints.write_final_record(self.out, self.name, meta)
        return TrainResult(
            model_path=self.out / f"{self.name}.zip",
            meta_path=self.out / f"{self.name}.json",
            meta=meta,
        )


def _make_envs(
    env_id: str,
    num_envs: int,
    seed: int,
    eval_episodes: int,
    env_kwargs: dict[str, Any],
    norm_reward: bool,
    gamma: float,
    vecnormalize_path: Path | None = None,
) -> tuple[Any, Any]:
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from shipgym.rl.vec_env import ShipgymVecEnv

    inner = VecMonitor(ShipgymVecEnv(env_id, num_envs, **env_kwargs))
    if vecnormalize_path is None:
        venv = VecNormalize(inner, norm_obs=True, norm_reward=norm_reward, gamma=gamma)
    else:
        venv = VecNormalize.load(str(vecnormalize_path), inner)
        venv.training = True
    venv.seed(seed)
    eval_env = VecNormalize(
        VecMonitor(ShipgymVecEnv(env_id, eval_episodes, fixed_seed=VALIDATION_SEED, **env_kwargs)),
        training=False,
        norm_obs=True,
        norm_reward=False,
    )
    return venv, eval_env


def _check_fresh_folder(out: Path, name: str, overwrite: bool) -> None:
    """Refuse to start over a training whose checkpoint is unfinished (unless ``overwrite``)."""
    record_path = checkpoints.latest_dir(out, name) / f"{name}.json"
    if overwrite or not record_path.is_file():
        return
    try:
        record = checkpoints.read_record(record_path)
    except ValueError:
        return  # not ours to protect
    if record.get("partial"):
        raise ValueError(
            f"{out} holds an unfinished training of {name} ({record['timesteps']} of "
            f"{record['requested_timesteps']} steps); continue it with resume "
            f"(shipgym train --resume {out}) or start over with overwrite=True (--overwrite)"
        )


def train(
    env_id: str,
    algo: str,
    timesteps: int | None = None,
    seed: int = 0,
    out_dir: str | Path = ".",
    num_envs: int | None = None,
    eval_freq: int | None = None,
    eval_episodes: int = 16,
    progress_bar: bool = True,
    progress: Callable[[str], None] | None = None,
    verbose: int = 0,
    hyperparameters: dict[str, Any] | None = None,
    env_kwargs: dict[str, Any] | None = None,
    *,
    tensorboard_log: str | Path | bool = True,
    overwrite: bool = False,
    callbacks: Sequence[Any] = (),
    on_evaluation: Callable[[dict[str, Any]], None] | None = None,
    stop: threading.Event | None = None,
) -> TrainResult:
    """Train a PPO or SAC agent on ``env_id``, checkpointing the best and the latest policy.

    At every evaluation the best policy so far is the agent in ``out_dir`` (record marked
    ``"partial": true``) and the latest state is a checkpoint that :func:`resume` continues
    (layout in :mod:`shipgym.rl.checkpoints`), so an interrupted run loses at most the steps
    since the last evaluation.

    Parameters
    ----------
    env_id : str
        One of :data:`shipgym.envs.ENV_IDS`.
    algo : {"ppo", "sac"}
        The stable-baselines3 algorithm.
    timesteps : int, optional
        Environment steps (summed over sub-envs); default from :func:`config`.
    seed : int
        Seed of the networks and of the training sub-envs (``seed + i``); must be below
        ``VALIDATION_SEED - num_envs``.
    out_dir : path
        Where ``<name>.zip`` and ``<name>.json`` go (:func:`agent_name`), with the
        checkpoints in ``checkpoints/<name>/``; created if missing.
    num_envs : int, optional
        Training sub-envs; default from :func:`config`.
    eval_freq : int, optional
        Environment steps between evaluations, and so between checkpoints (default: about 20
        over the run, and for PPO at least one rollout, ``n_steps x num_envs``: its policy
        only changes once a rollout).
    eval_episodes : int
        Validation episodes per evaluation (seeds ``VALIDATION_SEED + i``).
    progress_bar : bool
        Show SB3's progress bar (needs ``tqdm`` and ``rich``, in the ``rl`` extra).
    progress : callable, optional
        Called with a line at every evaluation (for logs, or when several trainings share a
        terminal and a bar each would garble it).
    verbose : int
        SB3 verbosity.
    hyperparameters : dict, optional
        Overrides of the algorithm's keyword arguments.
    env_kwargs : dict, optional
        Keyword arguments of the env (e.g. ``max_current_speed``).
    tensorboard_log : path or bool
        Folder of the TensorBoard runs (``True``: ``out_dir/tensorboard``; ``False``: none).
        Each training is a run ``<name>_<k>`` in it; a resumed one continues its run.
    overwrite : bool
        Start over even when ``out_dir`` holds an unfinished training of this agent (by
        default that is refused, so that a repeated command cannot wipe a long run).
    callbacks : sequence of SB3 callbacks
        Called after the evaluation callback at every step.
    on_evaluation : callable, optional
        Called with ``{"timesteps", "validation_return", "best_validation_return",
        "best_timestep", "final"}`` after every evaluation (e.g. to report to Ray Tune).
    stop : threading.Event, optional
        When set (e.g. by a signal handler), the training evaluates and checkpoints the
        policy of the current step, then raises ``KeyboardInterrupt``: a stop that loses
        nothing, at a step where the model is consistent.

    Returns
    -------
    TrainResult

    Raises
    ------
    KeyboardInterrupt
        On an interrupt, or after a ``stop``; the checkpoints stay (continue with
        :func:`resume`).
    """
    from stable_baselines3 import PPO, SAC

    cfg = config(env_id, algo)
    timesteps = cfg["timesteps"] if timesteps is None else timesteps
    num_envs = cfg["num_envs"] if num_envs is None else num_envs
    if not isinstance(timesteps, int) or timesteps < 1:
        raise ValueError(f"timesteps must be an integer >= 1, got {timesteps!r}")
    if not isinstance(num_envs, int) or num_envs < 1:
        raise ValueError(f"num_envs must be an integer >= 1, got {num_envs!r}")
    if not isinstance(seed, int) or not 0 <= seed < VALIDATION_SEED - num_envs:
        raise ValueError(
            f"seed must be an integer in [0, {VALIDATION_SEED - num_envs}) so that training "
            f"seeds stay apart from the validation seeds, got {seed!r}"
        )
    if not isinstance(eval_episodes, int) or eval_episodes < 1:
        raise ValueError(f"eval_episodes must be an integer >= 1, got {eval_episodes!r}")
    params = {**cfg["hyperparameters"], **(hyperparameters or {})}
    if eval_freq is None:
        eval_freq = max(timesteps // 20, 1)
        if algo == "ppo":  # the policy changes once a rollout; more evaluations repeat it
            eval_freq = max(eval_freq, int(params.get("n_steps", 2048)) * num_envs)
    if not isinstance(eval_freq, int) or eval_freq < 1:
        raise ValueError(f"eval_freq must be an integer >= 1, got {eval_freq!r}")
    out = Path(out_dir)
    name = agent_name(env_id, algo)
    _check_fresh_folder(out, name, overwrite)
    out.mkdir(parents=True, exist_ok=True)
    checkpoints.clear(out, name)
    env_kwargs = dict(env_kwargs or {})
    tb_root = _tensorboard_root(out, tensorboard_log)

    norm_reward = algo == "ppo"
    venv, eval_env = _make_envs(
        env_id, num_envs, seed, eval_episodes, env_kwargs, norm_reward, params.get("gamma", 0.99)
    )
    cls = {"ppo": PPO, "sac": SAC}[algo]
    model = cls("MlpPolicy", venv, seed=seed, verbose=verbose, device="cpu", **params)
    record = {
        "name": name,
        "env": env_id,
        "algo": algo,
        "partial": True,
        "timesteps": 0,
        "requested_timesteps": int(timesteps),
        "num_envs": int(num_envs),
        "seed": int(seed),
        "training_seeds": [int(seed), int(seed + num_envs - 1)],
        "validation_seeds": [VALIDATION_SEED, VALIDATION_SEED + eval_episodes - 1],
        "eval_freq": int(eval_freq),
        "wall_time_s": 0.0,
        "steps_per_s": 0.0,
        "best_timestep": None,
        "best_validation_return": None,
        "final_validation_return": None,
        "learning_curve": {"timesteps": [], "mean_return": [], "std_return": []},
        "obs_normaliser": _obs_normaliser(venv),
        "reward_normalised": norm_reward,
        "hyperparameters": params,
        "env_kwargs": env_kwargs,
        "resumed_at": [],
        "tensorboard_run": None if tb_root is None else _next_tensorboard_run(tb_root, name),
        # SAC's replay buffer (tens of MB at the default size) goes into the latest
        # checkpoint, so that a resumed SAC run continues with the experience it had
        "checkpoint_replay_buffer": algo == "sac",
        "versions": _versions(),
        "machine": _machine(),
    }
    run = _Run(
        out, record, model, venv, eval_env, tb_root, progress, on_evaluation, verbose, stop=stop
    )
    return run.learn(callbacks, progress_bar, fresh=True)


def _machine() -> str:
    import torch

    return f"{os.cpu_count()} CPUs, torch threads {torch.get_num_threads()}"


def resume(
    out_dir: str | Path,
    env_id: str | None = None,
    algo: str | None = None,
    timesteps: int | None = None,
    progress_bar: bool = True,
    progress: Callable[[str], None] | None = None,
    verbose: int = 0,
    *,
    tensorboard_log: str | Path | bool = True,
    callbacks: Sequence[Any] = (),
    on_evaluation: Callable[[dict[str, Any]], None] | None = None,
    stop: threading.Event | None = None,
) -> TrainResult:
    """Continue the training in ``out_dir`` from its latest checkpoint.

    The env, algorithm, hyperparameters, seeds and evaluation settings are the record's; the
    model (with its optimiser state), the ``VecNormalize`` statistics and, for SAC, the replay
    buffer are the checkpoint's. The timestep counter, the learning curve, the best policy and
    the TensorBoard run continue. The training sub-envs start new episodes from their seeds
    (the state of the episodes in progress is not saved), so a resumed run is not
    bit-identical to an uninterrupted one.

    Parameters
    ----------
    out_dir : path
        The output folder of the interrupted :func:`train`.
    env_id, algo : str, optional
        Which agent, if the folder holds checkpoints of several (checked against the record).
    timesteps : int, optional
        The new total of environment steps (default: the record's ``requested_timesteps``);
        must exceed the steps done.
    progress_bar, progress, verbose, tensorboard_log, callbacks, on_evaluation, stop
        As in :func:`train`.

    Returns
    -------
    TrainResult

    Raises
    ------
    ValueError
        When ``out_dir`` holds no usable checkpoint (see
        :func:`shipgym.rl.checkpoints.find_latest`) or the training is already done.
    """
    from stable_baselines3 import PPO, SAC

    out = Path(out_dir)
    folder, record = checkpoints.find_latest(out, env_id, algo)
    name, env_id, algo = record["name"], record["env"], record["algo"]
    total = int(record["requested_timesteps"]) if timesteps is None else timesteps
    if not isinstance(total, int) or total < 1:
        raise ValueError(f"timesteps must be an integer >= 1, got {total!r}")
    done = int(record["timesteps"])
    if total <= done:
        raise ValueError(
            f"{name} in {out} has already trained {done} of {total} steps; give a larger total "
            "(--timesteps N) to train on"
        )
    for key in ("eval_freq", "validation_seeds", "training_seeds", "tensorboard_run"):
        if key not in record:
            raise ValueError(f"{folder / (name + '.json')} cannot be resumed (missing {key})")
    eval_episodes = int(record["validation_seeds"][1]) - int(record["validation_seeds"][0]) + 1
    params = dict(record["hyperparameters"])
    venv, eval_env = _make_envs(
        env_id,
        int(record["num_envs"]),
        int(record["seed"]),
        eval_episodes,
        dict(record.get("env_kwargs", {})),
        bool(record.get("reward_normalised", algo == "ppo")),
        params.get("gamma", 0.99),
        vecnormalize_path=folder / checkpoints.VECNORMALIZE,
    )
    cls = {"ppo": PPO, "sac": SAC}[algo]
    model = cls.load(folder / f"{name}.zip", env=venv, device="cpu")
    buffer = folder / checkpoints.REPLAY_BUFFER
    if algo == "sac" and buffer.is_file():
        model.load_replay_buffer(buffer)
    steps = int(model.num_timesteps)
    best: dict[str, Any] = {}
    best_path = checkpoints.best_dir(out, name) / f"{name}.json"
    if best_path.is_file():
        best_record = checkpoints.read_record(best_path)
        if best_record.get("best_validation_return") is not None:
            best = {
                "obs": best_record["obs_normaliser"],
                "timestep": best_record["best_timestep"],
                "reward": float(best_record["best_validation_return"]),
            }
    tb_root = _tensorboard_root(out, tensorboard_log)
    if tb_root is not None and record["tensorboard_run"] is None:
        record["tensorboard_run"] = _next_tensorboard_run(tb_root, name)
    curve = record["learning_curve"]
    # evaluations after the checkpoint's step (none, unless the files were edited) are dropped
    keep = sum(1 for t in curve["timesteps"] if t <= steps)
    record = {
        **record,
        "partial": True,
        "requested_timesteps": int(total),
        "learning_curve": {key: list(values[:keep]) for key, values in curve.items()},
        "resumed_at": [*record.get("resumed_at", []), steps],
        "checkpoint_replay_buffer": algo == "sac",
        "versions": _versions(),
        "machine": _machine(),
    }
    if progress is not None:
        progress(f"{name}: resuming at step {steps} of {total} from {folder}")
    run = _Run(
        out,
        record,
        model,
        venv,
        eval_env,
        tb_root,
        progress,
        on_evaluation,
        verbose,
        best=best,
        stop=stop,
    )
    return run.learn(callbacks, progress_bar, fresh=False)

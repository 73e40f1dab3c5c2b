"""Training of stable-baselines3 agents (PPO, SAC) on the shipgym environments.

:func:`train` runs SB3 on :class:`shipgym.rl.vec_env.ShipgymVecEnv` (one batched kernel for all
sub-envs), with observation normalisation (``VecNormalize``; rewards too for PPO, whose value
targets it steadies, not for SAC, whose entropy temperature is tuned against the reward
scale), an evaluation callback on fixed validation seeds that keeps the best policy, and a
progress bar. The result is an agent file (SB3 ``.zip``) and a JSON record of how it was made:
algorithm, hyperparameters, budget, seeds, wall time, learning curve, library versions, and the
observation normaliser the policy needs (:func:`shipgym.rl.agents.load_agent` applies it).

Seeds. Training sub-env ``i`` is seeded with ``seed + i``; the evaluation callback uses
``VALIDATION_SEED + i``; the benchmark evaluates from ``BENCHMARK_SEED`` on. The three ranges
are disjoint for ``seed < VALIDATION_SEED - num_envs``, so no agent is scored on an episode it
was trained or selected on.
"""

from __future__ import annotations

import json
import math
import os
import platform
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.envs import env_task

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


def _atomic_write_text(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.chmod(tmp, 0o644)  # mkstemp makes it private; the record is a plain package file
    os.replace(tmp, path)


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
) -> TrainResult:
    """Train a PPO or SAC agent on ``env_id`` and save the best policy of the evaluations.

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
        Where ``<name>.zip`` and ``<name>.json`` go (:func:`agent_name`); created if missing.
    num_envs : int, optional
        Training sub-envs; default from :func:`config`.
    eval_freq : int, optional
        Environment steps between evaluations (default: about 20 over the run, and for PPO at
        least one rollout, ``n_steps x num_envs``: its policy only changes once a rollout).
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

    Returns
    -------
    TrainResult
    """
    import stable_baselines3
    import torch
    from stable_baselines3 import PPO, SAC
    from stable_baselines3.common.callbacks import CallbackList, EvalCallback
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from shipgym.rl.vec_env import ShipgymVecEnv

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
    out.mkdir(parents=True, exist_ok=True)
    name = agent_name(env_id, algo)
    env_kwargs = dict(env_kwargs or {})

    norm_reward = algo == "ppo"
    venv = VecNormalize(
        VecMonitor(ShipgymVecEnv(env_id, num_envs, **env_kwargs)),
        norm_obs=True,
        norm_reward=norm_reward,
        gamma=params.get("gamma", 0.99),
    )
    venv.seed(seed)
    eval_env = VecNormalize(
        VecMonitor(ShipgymVecEnv(env_id, eval_episodes, fixed_seed=VALIDATION_SEED, **env_kwargs)),
        training=False,
        norm_obs=True,
        norm_reward=False,
    )
    cls = {"ppo": PPO, "sac": SAC}[algo]
    model = cls("MlpPolicy", venv, seed=seed, verbose=verbose, device="cpu", **params)
    model.set_logger(console_logger(verbose))

    best: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:

        class _SaveBest(EvalCallback):
            """EvalCallback that also keeps the normaliser of the best policy."""

            def _on_step(self) -> bool:
                previous = self.best_mean_reward
                go_on = super()._on_step()
                if self.best_mean_reward > previous:
                    best["obs"] = _obs_normaliser(venv)
                    best["timestep"] = int(self.num_timesteps)
                    best["reward"] = float(self.best_mean_reward)
                if progress is not None and self.n_calls % self.eval_freq == 0:
                    rate = self.num_timesteps / max(time.perf_counter() - start, 1e-9)
                    progress(
                        f"{name}: {self.num_timesteps}/{timesteps} steps "
                        f"({100 * self.num_timesteps / timesteps:.0f} %, {rate:.0f} steps/s), "
                        f"validation return {self.last_mean_reward:.1f}, "
                        f"best {self.best_mean_reward:.1f}"
                    )
                return go_on

        # EvalCallback counts calls, one per vector step of num_envs env steps
        callback = _SaveBest(
            eval_env,
            n_eval_episodes=eval_episodes,
            eval_freq=max(eval_freq // num_envs, 1),
            best_model_save_path=tmp,
            log_path=tmp,
            deterministic=True,
            verbose=verbose,
        )
        start = time.perf_counter()
        model.learn(timesteps, callback=CallbackList([callback]), progress_bar=progress_bar)
        # a final evaluation, so the end of the run can win too
        callback.n_calls = 0
        callback._on_step()
        wall = time.perf_counter() - start
        curve = {
            "timesteps": [int(t) for t in callback.evaluations_timesteps],
            "mean_return": [float(np.mean(r)) for r in callback.evaluations_results],
            "std_return": [float(np.std(r)) for r in callback.evaluations_results],
        }
        best_model = cls.load(os.path.join(tmp, "best_model.zip"), device="cpu")

    model_path = out / f"{name}.zip"
    best_model.save(model_path, exclude=["replay_buffer", "_last_obs", "_last_original_obs"])
    meta = {
        "name": name,
        "env": env_id,
        "algo": algo,
        "timesteps": int(model.num_timesteps),
        "requested_timesteps": int(timesteps),
        "num_envs": int(num_envs),
        "seed": int(seed),
        "training_seeds": [int(seed), int(seed + num_envs - 1)],
        "validation_seeds": [VALIDATION_SEED, VALIDATION_SEED + eval_episodes - 1],
        "wall_time_s": round(wall, 2),
        "steps_per_s": round(model.num_timesteps / wall, 1),
        "best_timestep": best.get("timestep"),
        "best_validation_return": best.get("reward"),
        "final_validation_return": curve["mean_return"][-1] if curve["mean_return"] else None,
        "learning_curve": curve,
        "obs_normaliser": best.get("obs", _obs_normaliser(venv)),
        "reward_normalised": norm_reward,
        "hyperparameters": params,
        "env_kwargs": env_kwargs,
        "versions": {
            "python": platform.python_version(),
            "stable_baselines3": stable_baselines3.__version__,
            "torch": torch.__version__,
            "numpy": np.__version__,
        },
        "machine": f"{os.cpu_count()} CPUs, torch threads {torch.get_num_threads()}",
    }
    if not all(math.isfinite(v) for v in meta["obs_normaliser"]["mean"]):
        raise RuntimeError(f"{name}: the observation normaliser is not finite")
    meta_path = out / f"{name}.json"
    _atomic_write_text(meta_path, json.dumps(meta, indent=2) + "\n")
    venv.close()
    eval_env.close()
    return TrainResult(model_path=model_path, meta_path=meta_path, meta=meta)

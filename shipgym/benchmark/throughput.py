"""Training throughput: PPO's environment steps per second on each env against CartPole.

The env must never be what slows training down. :func:`ppo_throughput` times
stable-baselines3 PPO ``learn`` with the shipped agents' PPO settings
(:data:`shipgym.rl.train.DEFAULTS`: the same sub-env count, rollout length, batch, epochs,
network, ``VecMonitor`` + ``VecNormalize``) on each shipgym env (through
:class:`~shipgym.rl.vec_env.ShipgymVecEnv`) and on ``CartPole-v1`` (through SB3's standard
``make_vec_env``), in one process, and reports the ratio to CartPole. The runs are interleaved
and repeated and the best of each is kept, so a moment of load elsewhere does not decide the
ratio. The target is a ratio of at least :data:`TARGET_RATIO`.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

from shipgym.envs import CURRENT_ENV_IDS

CARTPOLE = "CartPole-v1"
#: PPO steps/s on a shipgym env relative to CartPole-v1 that counts as "not the bottleneck".
TARGET_RATIO = 0.9


def _make_venv(env_id: str, num_envs: int, seed: int) -> Any:
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from shipgym.rl.vec_env import ShipgymVecEnv

    if env_id == CARTPOLE:
        inner = make_vec_env(CARTPOLE, n_envs=num_envs, seed=seed)  # DummyVecEnv + Monitor
    else:
        inner = VecMonitor(ShipgymVecEnv(env_id, num_envs))
        inner.seed(seed)
    return VecNormalize(inner, norm_obs=True, norm_reward=True)


def ppo_steps_per_second(env_id: str, timesteps: int, seed: int = 0) -> float:
    """Environment steps per second of PPO ``learn`` on ``env_id`` (after one warm-up rollout)."""
    from stable_baselines3 import PPO

    from shipgym.rl.train import DEFAULTS, console_logger

    settings = DEFAULTS["ppo"]
    params = dict(settings["hyperparameters"])
    if env_id == CARTPOLE:  # a discrete action space has no log-std
        params["policy_kwargs"] = {
            k: v for k, v in params["policy_kwargs"].items() if k != "log_std_init"
        }
    venv = _make_venv(env_id, settings["num_envs"], seed)
    model = PPO("MlpPolicy", venv, seed=seed, device="cpu", verbose=0, **params)
    model.set_logger(console_logger(0))
    rollout = params["n_steps"] * settings["num_envs"]
    model.learn(rollout)  # warm-up: kernels, torch, first update
    start = time.perf_counter()
    model.learn(timesteps, reset_num_timesteps=False)
    elapsed = time.perf_counter() - start
    venv.close()
    return (model.num_timesteps - rollout) / elapsed


def ppo_throughput(
    env_ids: Sequence[str] = CURRENT_ENV_IDS,
    timesteps: int = 16_384,
    repeats: int = 2,
    progress: Callable[[str], None] | None = None,
) -> list[dict[str, Any]]:
    """PPO steps/s on each env and on CartPole, best of ``repeats`` interleaved runs.

    Returns
    -------
    list of dict
        One entry per env (CartPole first): ``env``, ``steps_per_s``, ``runs`` (every run),
        ``ratio`` (to CartPole), ``target`` and ``met``.
    """
    if not isinstance(timesteps, int) or timesteps < 1:
        raise ValueError(f"timesteps must be an integer >= 1, got {timesteps!r}")
    if not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"repeats must be an integer >= 1, got {repeats!r}")
    if progress is None:

        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)

    ids = [CARTPOLE, *env_ids]
    runs: dict[str, list[float]] = {env_id: [] for env_id in ids}
    for rep in range(repeats):
        for env_id in ids:
            rate = ppo_steps_per_second(env_id, timesteps)
            runs[env_id].append(rate)
            progress(f"PPO throughput {rep + 1}/{repeats}: {env_id} {rate:.0f} steps/s")
    reference = max(runs[CARTPOLE])
    out = []
    for env_id in ids:
        best = max(runs[env_id])
        ratio = best / reference
        out.append(
            {
                "env": env_id,
                "steps_per_s": best,
                "runs": runs[env_id],
                "ratio": ratio,
                "target": None if env_id == CARTPOLE else TARGET_RATIO,
                "met": None if env_id == CARTPOLE else bool(ratio >= TARGET_RATIO),
            }
        )
    return out


def throughput_table(rows: list[dict[str, Any]]) -> str:
    """Plain-text table of :func:`ppo_throughput`'s rows."""
    lines = ["PPO training throughput (env steps/s, best of the runs; same PPO settings)"]
    for r in rows:
        verdict = "" if r["met"] is None else ("met" if r["met"] else "MISSED")
        target = "" if r["target"] is None else f">= {r['target']:g}"
        lines.append(
            f"  {r['env']:32s} {r['steps_per_s']:9.0f}  ratio {r['ratio']:.2f}  {target:7s} "
            f"{verdict}"
        )
    return "\n".join(lines)

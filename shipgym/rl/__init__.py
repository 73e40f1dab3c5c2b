"""Reinforcement learning on the shipgym envs: SB3 adapter, training, shipped agents, report.

* :class:`~shipgym.rl.vec_env.ShipgymVecEnv`: a stable-baselines3 ``VecEnv`` over the
  NumPy-batched vector env (imported on first use: it needs stable-baselines3);
* :func:`~shipgym.rl.train.train`: PPO or SAC with normalisation and an evaluation callback,
  checkpointed at every evaluation (:mod:`~shipgym.rl.checkpoints`);
  :func:`~shipgym.rl.train.resume` continues an interrupted one;
* :func:`~shipgym.rl.sweep.run_sweep`: hyperparameter sweeps as Ray Tune trials;
* :func:`~shipgym.rl.agents.load_agent`: the shipped agents (or any trained folder) as
  evaluation policies.

Needs the ``rl`` extra: ``pip install 'shipgym[rl]'``.
"""

from __future__ import annotations

from typing import Any

from shipgym.rl.agents import AGENT_DIR, AgentPolicy, load_agent, load_meta
from shipgym.rl.train import (
    ALGOS,
    BENCHMARK_SEED,
    VALIDATION_SEED,
    TrainResult,
    resume,
    train,
)


def __getattr__(name: str) -> Any:
    if name == "ShipgymVecEnv":
        from shipgym.rl.vec_env import ShipgymVecEnv

        return ShipgymVecEnv
    raise AttributeError(f"module 'shipgym.rl' has no attribute {name!r}")


__all__ = [
    "AGENT_DIR",
    "ALGOS",
    "BENCHMARK_SEED",
    "VALIDATION_SEED",
    "AgentPolicy",
    "ShipgymVecEnv",
    "TrainResult",
    "load_agent",
    "load_meta",
    "resume",
    "train",
]

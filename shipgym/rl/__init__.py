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

Importing this package points torch's compiler cache (``TORCHINDUCTOR_CACHE_DIR``) into
shipgym's cache folder (``$SHIPGYM_CACHE_DIR/torchinductor``, ``~/.cache/shipgym/torchinductor``
by default) unless it is set already. torch 2.13 makes that folder when it imports
``torch._dynamo``, which it does the first time an optimiser is built (SB3 builds one to make
or load a model): by default in the temporary directory, ``/tmp/torchinductor_<user>``, where
it would outlive every command. shipgym compiles nothing with torch, so the folder stays
empty; torch's own discussion of the default is pytorch/pytorch#121122.
"""

from __future__ import annotations

import os
from typing import Any

from shipgym._cache import cache_root
from shipgym.rl.agents import AGENT_DIR, AgentPolicy, load_agent, load_meta
from shipgym.rl.train import (
    ALGOS,
    BENCHMARK_SEED,
    VALIDATION_SEED,
    TrainResult,
    resume,
    train,
)


def _keep_torch_cache_out_of_tmp() -> None:
    """Set ``TORCHINDUCTOR_CACHE_DIR`` to shipgym's cache folder unless it is set (before
    torch reads it: at the import of ``torch._dynamo``)."""
    if "TORCHINDUCTOR_CACHE_DIR" in os.environ:
        return
    os.environ["TORCHINDUCTOR_CACHE_DIR"] = os.path.join(cache_root(), "torchinductor")


_keep_torch_cache_out_of_tmp()


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

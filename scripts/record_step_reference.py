"""Record the reference trajectories that the kernel regression test compares against.

Runs every environment (4 sub-envs of the vector env, seed 3, 100 steps of seeded random
actions) and every environment model's bare RK4 step (4 ships, 100 steps of 0.1 s) and writes
states, observations and rewards to ``tests/data/step_reference.npz``. The file in the
repository was recorded with the per-ship kernels that used the C library's sine and cosine
(commit ccf287a), before the physics became SIMD block kernels; the test asserts that every
later kernel reproduces it to 1e-9 relative.

Usage: ``python scripts/record_step_reference.py [OUT.npz]``.
"""

from __future__ import annotations

import sys
import warnings

import gymnasium as gym
import numpy as np

import shipgym  # noqa: F401  (registers the environments)
from shipgym.envs import ENV_IDS
from shipgym.models import make_model

SHIPS = 4
STEPS = 100
ENV_MODELS = ("nomoto1", "nomoto2", "norrbin", "bech", "rvg3dof")


def model_start(name: str) -> tuple[np.ndarray, np.ndarray]:
    """Seeded start states (a turn in progress, actuators moving) and constant inputs."""
    model = make_model(name)
    rng = np.random.default_rng(2)
    x = rng.normal(0.0, 0.1, (SHIPS, model.nx))
    names = model.state_names
    x[:, names.index("U" if "U" in names else "u")] = 5.0
    u = rng.uniform(-0.3, 0.3, (SHIPS, model.nu))
    if name == "rvg3dof":
        x[:, names.index("T1")] = x[:, names.index("T2")] = 2e4
        u[:, 0:2] = 3e4
    else:
        u[:, 1] = 1.0
    return x, u


def record() -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    for env_id in ENV_IDS:
        env = gym.make_vec(env_id, num_envs=SHIPS, vectorization_mode="vector_entry_point")
        env.reset(seed=3)
        rng = np.random.default_rng(1)
        states, obs, rewards = [], [], []
        for _ in range(STEPS):
            o, r, _, _, info = env.step(rng.uniform(-1.0, 1.0, env.action_space.shape))
            states.append(info["state"])
            obs.append(o)
            rewards.append(r)
        out[f"{env_id}/state"] = np.array(states)
        out[f"{env_id}/obs"] = np.array(obs)
        out[f"{env_id}/reward"] = np.array(rewards)
        env.close()
    for name in ENV_MODELS:
        model = make_model(name)
        x, u = model_start(name)
        traj = []
        for _ in range(STEPS):
            x = model.step(x, u, 0.1)
            traj.append(x)
        out[f"model/{name}"] = np.array(traj)
    return out


if __name__ == "__main__":
    warnings.filterwarnings("ignore", category=DeprecationWarning)
    path = sys.argv[1] if len(sys.argv) > 1 else "tests/data/step_reference.npz"
    np.savez_compressed(path, **record())
    print(f"wrote {path}")

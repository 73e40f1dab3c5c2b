"""Nothing is left in the temporary directory by the RL side of the package.

torch makes its compiler cache folder (``torchinductor_<user>``) in the temporary directory the
first time it builds an optimiser, which SB3 does to load or make a model; importing
:mod:`shipgym.rl` points that cache into shipgym's cache folder instead. The check runs in a
fresh process whose ``TMPDIR`` is an empty folder of the test's own.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

#: Load a shipped agent and run it for a few steps, then make a new model (its optimiser too).
_RUN = """
import json, os, tempfile
import gymnasium as gym
import numpy as np
from shipgym.rl.agents import load_agent
from shipgym.rl.vec_env import ShipgymVecEnv

env_id = "shipgym/RVGHeading-v1"
policy = load_agent(env_id, "ppo")
env = gym.make(env_id)
obs, info = env.reset(seed=0)
policy.reset(env, obs, info)
for _ in range(5):
    obs, reward, terminated, truncated, info = env.step(policy.act(obs, info))
from stable_baselines3 import SAC
SAC("MlpPolicy", ShipgymVecEnv(env_id, num_envs=1), policy_kwargs={"net_arch": [4]})
print(json.dumps({"tempdir": tempfile.gettempdir(),
                  "torch_cache": os.environ["TORCHINDUCTOR_CACHE_DIR"],
                  "finite": bool(np.all(np.isfinite(obs)))}))
"""


def test_loading_and_running_an_agent_leaves_nothing_in_the_temp_dir(tmp_path: Path) -> None:
    temp = tmp_path / "tmp"
    temp.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "TORCHINDUCTOR_CACHE_DIR"}
    env["TMPDIR"] = str(temp)
    proc = subprocess.run(
        [sys.executable, "-c", _RUN], env=env, capture_output=True, text=True, check=False
    )
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["tempdir"] == str(temp) and report["finite"]
    assert sorted(p.name for p in temp.iterdir()) == []
    cache = Path(report["torch_cache"])
    assert cache.name == "torchinductor" and temp not in cache.parents


def test_a_torch_cache_folder_the_user_chose_is_kept(tmp_path: Path) -> None:
    chosen = tmp_path / "my-inductor-cache"
    env = {**os.environ, "TORCHINDUCTOR_CACHE_DIR": str(chosen)}
    code = "import os, shipgym.rl; print(os.environ['TORCHINDUCTOR_CACHE_DIR'])"
    proc = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert proc.stdout.strip() == str(chosen)

"""The envs in the hands of their common clients: stable-baselines3's evaluation through
``VecMonitor`` and Gymnasium's ``RecordVideo``."""

from __future__ import annotations

import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import shipgym  # noqa: F401  (registers the environments)

ENV = "shipgym/RVGHeading-v1"
#: Short episodes: the time limit of the runs below.
STEPS = 60
SEED = 100


def test_evaluate_policy_through_vec_monitor_returns_the_summed_rewards() -> None:
    """``evaluate_policy(model, VecMonitor(ShipgymVecEnv(...)))``: no Monitor warning, and each
    episode's reward is the sum of the rewards of the single env that sub-env equals (reset
    with seed ``fixed_seed + i``, stepped with the model's actions)."""
    pytest.importorskip("stable_baselines3")
    from stable_baselines3 import PPO
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.vec_env import VecMonitor

    from shipgym.rl.vec_env import ShipgymVecEnv

    n = 3
    bare = ShipgymVecEnv(ENV, num_envs=n, fixed_seed=SEED, max_episode_steps=STEPS)
    policy_kwargs = {"net_arch": [8]}
    model = PPO("MlpPolicy", bare, seed=0, n_steps=8, batch_size=8, policy_kwargs=policy_kwargs)
    with pytest.warns(UserWarning, match="not wrapped with a ``Monitor`` wrapper"):
        evaluate_policy(model, bare, n_eval_episodes=n)  # what the docstring warns about

    env = VecMonitor(ShipgymVecEnv(ENV, num_envs=n, fixed_seed=SEED, max_episode_steps=STEPS))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a Monitor warning (or any other) fails the test
        returns, lengths = evaluate_policy(
            model, env, n_eval_episodes=n, return_episode_rewards=True
        )
    assert lengths == [STEPS] * n

    for i in range(n):
        single = gym.make(ENV, max_episode_steps=STEPS)
        obs, _ = single.reset(seed=SEED + i)
        total, done = 0.0, False
        while not done:
            action, _ = model.predict(obs, deterministic=True)
            obs, reward, terminated, truncated, _ = single.step(action)
            total += reward
            done = terminated or truncated
        # the adapter hands SB3 float32 rewards, which VecMonitor sums
        assert returns[i] == pytest.approx(total, rel=1e-5), i
    assert len(set(returns)) == n  # the sub-envs ran different episodes
    assert np.all(np.isfinite(returns))


def test_record_video_writes_an_mp4_of_an_episode(tmp_path: Path) -> None:
    """``RecordVideo`` (the ``video`` extra's MoviePy) records a short episode of an env with
    ``render_mode="rgb_array"`` into an MP4 file, as the rendering module documents."""
    pytest.importorskip("moviepy", reason="the video extra is not installed")
    from gymnasium.wrappers import RecordVideo

    steps = 8
    env = gym.make("shipgym/RVGPathFollowing-v1", render_mode="rgb_array", max_episode_steps=steps)
    folder = tmp_path / "videos"
    env = RecordVideo(env, str(folder), episode_trigger=lambda episode: episode == 0, fps=10)
    env.reset(seed=0)
    done, frames = False, 0
    while not done:
        _, _, terminated, truncated, _ = env.step(np.array([0.1, 0.5], dtype=np.float32))
        frames += 1
        done = terminated or truncated
    env.close()
    assert frames == steps
    videos = sorted(folder.iterdir())
    assert [p.name for p in videos] == ["rl-video-episode-0.mp4"]
    data = videos[0].read_bytes()
    assert data[4:8] == b"ftyp" and len(data) > 1_000  # an MP4 (ISO base media) file

"""RL training and the shipped agents.

The SB3 adapter's same-step autoreset against single envs, tiny ``learn(64)``-sized trainings
of PPO and SAC on every env (through :func:`shipgym.rl.train.train`, which also saves and
records the agent), every shipped agent loading and beating the ``zero`` command, and the
lockstep evaluation of memoryless policies matching the one-episode-at-a-time loop.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import torch
from gymnasium.vector import AutoresetMode

from shipgym.benchmark import evaluate, make_policy
from shipgym.envs import CURRENT_ENV_IDS
from shipgym.rl.agents import AGENT_DIR, agent_files, load_agent, load_meta
from shipgym.rl.train import (
    ALGOS,
    BENCHMARK_SEED,
    VALIDATION_SEED,
    agent_name,
    console_logger,
    train,
)
from shipgym.rl.vec_env import ShipgymVecEnv


def _quiet(line: str) -> None:
    pass


# ------------------------------------------------------------------------------------------
# the SB3 VecEnv adapter
# ------------------------------------------------------------------------------------------
def test_adapter_autoresets_in_the_same_step_like_single_envs() -> None:
    n, steps, seed = 3, 5, 42
    venv = ShipgymVecEnv("shipgym/RVGSpeed-v0", n, max_episode_steps=steps)
    venv.seed(seed)
    obs = venv.reset()
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, size=(steps, n, 1)).astype(np.float32)
    singles = [gym.make("shipgym/RVGSpeed-v0").unwrapped for _ in range(n)]
    first = [env.reset(seed=seed + i)[0] for i, env in enumerate(singles)]
    np.testing.assert_array_equal(obs, np.stack(first))
    for k in range(steps):
        venv.step_async(actions[k])
        obs, rewards, dones, infos = venv.step_wait()
        expected = [env.step(actions[k, i]) for i, env in enumerate(singles)]
        np.testing.assert_allclose(rewards, [e[1] for e in expected], rtol=1e-6)
        if k < steps - 1:
            assert not dones.any()
            assert all(info == {} for info in infos)
            np.testing.assert_array_equal(obs, np.stack([e[0] for e in expected]))
    # the time limit ended every episode: final obs in the info, the new episode's obs returned
    assert dones.all()
    for i, info in enumerate(infos):
        np.testing.assert_array_equal(info["terminal_observation"], expected[i][0])
        assert info["TimeLimit.truncated"] is True
    np.testing.assert_array_equal(obs, np.stack([env.reset()[0] for env in singles]))


def test_adapter_fixed_seed_repeats_the_episodes_at_every_reset() -> None:
    venv = ShipgymVecEnv("shipgym/NomotoHeading-v0", 4, fixed_seed=VALIDATION_SEED)
    a = venv.reset()
    venv.step_async(np.ones((4, 1), dtype=np.float32))
    venv.step_wait()
    np.testing.assert_array_equal(venv.reset(), a)
    unseeded = ShipgymVecEnv("shipgym/NomotoHeading-v0", 4)
    assert not np.array_equal(unseeded.reset(), unseeded.reset())


def test_vector_env_same_step_mode_reports_the_final_observation() -> None:
    envs = gym.make_vec(
        "shipgym/RVGHeading-v0",
        num_envs=2,
        vectorization_mode="vector_entry_point",
        autoreset_mode=AutoresetMode.SAME_STEP,
        max_episode_steps=2,
    )
    assert envs.metadata["autoreset_mode"] is AutoresetMode.SAME_STEP
    envs.reset(seed=0)
    envs.step(np.zeros((2, 1), dtype=np.float32))
    obs, _, _, truncated, info = envs.step(np.zeros((2, 1), dtype=np.float32))
    assert truncated.all() and info["_final_obs"].all()
    assert not np.array_equal(info["final_obs"], obs)  # obs is the next episode's first
    with pytest.raises(ValueError, match="autoreset_mode"):
        gym.make_vec(
            "shipgym/RVGHeading-v0",
            num_envs=2,
            vectorization_mode="vector_entry_point",
            autoreset_mode="sometimes",
        )


def test_adapter_rejects_bad_arguments() -> None:
    with pytest.raises(ValueError, match="unknown env"):
        ShipgymVecEnv("CartPole-v1", 2)
    with pytest.raises(ValueError, match="num_envs"):
        ShipgymVecEnv("shipgym/RVGSpeed-v0", 0)


# ------------------------------------------------------------------------------------------
# tiny trainings: learn(64) on every env with each algorithm
# ------------------------------------------------------------------------------------------
TINY = {
    "ppo": {"n_steps": 32, "batch_size": 32, "n_epochs": 2},
    "sac": {"learning_starts": 16, "batch_size": 32, "buffer_size": 1000},
}


@pytest.mark.parametrize("algo", ALGOS)
@pytest.mark.parametrize("env_id", CURRENT_ENV_IDS)
def test_tiny_training_learns_saves_and_records(env_id: str, algo: str, tmp_path: Path) -> None:
    torch.manual_seed(0)
    result = train(
        env_id,
        algo,
        timesteps=64,
        seed=3,
        out_dir=tmp_path,
        num_envs=2,
        eval_freq=32,
        eval_episodes=2,
        progress_bar=False,
        hyperparameters=TINY[algo],
    )
    meta = json.loads(result.meta_path.read_text())
    assert meta["timesteps"] >= 64 and meta["env"] == env_id and meta["algo"] == algo
    assert meta["training_seeds"] == [3, 4]
    assert meta["validation_seeds"] == [VALIDATION_SEED, VALIDATION_SEED + 1]
    assert meta["wall_time_s"] > 0 and len(meta["learning_curve"]["timesteps"]) >= 2
    assert meta["reward_normalised"] is (algo == "ppo")
    # the agent loads, with the normaliser it was trained behind, and acts in range
    policy = load_agent(env_id, algo, tmp_path)
    assert np.all(np.isfinite(policy.mean))
    obs = np.stack([gym.make(env_id).reset(seed=s)[0] for s in range(3)])
    actions = policy.act_batch(obs)
    assert actions.shape == (3, gym.make(env_id).action_space.shape[0])
    assert np.all(np.abs(actions) <= 1.0)


def test_ppo_is_evaluated_once_a_rollout_by_default(tmp_path: Path) -> None:
    """PPO's policy changes once a rollout (``n_steps x num_envs`` = 64 steps here); the default
    evaluation frequency (1/20 of the budget) never evaluates it more often than that."""
    result = train(
        "shipgym/RVGSpeed-v0",
        "ppo",
        timesteps=128,
        seed=3,
        out_dir=tmp_path,
        num_envs=2,
        eval_episodes=1,
        progress_bar=False,
        hyperparameters=TINY["ppo"],
    )
    curve = json.loads(result.meta_path.read_text())["learning_curve"]["timesteps"]
    assert 2 <= len(curve) <= 3  # after each of the two rollouts, and the final evaluation
    assert all(b - a >= 64 for a, b in itertools.pairwise(curve[:-1]))


def test_training_changes_the_policy(tmp_path: Path) -> None:
    """The tiny budget really updates the network (the smoke tests could not fail otherwise)."""
    from stable_baselines3 import PPO

    model = PPO("MlpPolicy", ShipgymVecEnv("shipgym/RVGSpeed-v0", 2), seed=0, **TINY["ppo"])
    model.set_logger(console_logger(0))
    before = [p.detach().clone() for p in model.policy.parameters()]
    model.learn(64)
    after = list(model.policy.parameters())
    assert any(not torch.equal(b, a) for b, a in zip(before, after, strict=True))


def test_training_rejects_bad_arguments(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="algorithm"):
        train("shipgym/RVGSpeed-v0", "dqn", out_dir=tmp_path)
    with pytest.raises(ValueError, match="timesteps"):
        train("shipgym/RVGSpeed-v0", "ppo", timesteps=0, out_dir=tmp_path)
    with pytest.raises(ValueError, match="seed"):
        train("shipgym/RVGSpeed-v0", "ppo", seed=VALIDATION_SEED, out_dir=tmp_path)
    assert not list(tmp_path.iterdir())


def test_missing_agent_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="shipgym train --env shipgym/RVGSpeed-v0"):
        load_agent("shipgym/RVGSpeed-v0", "ppo", tmp_path)


# ------------------------------------------------------------------------------------------
# the shipped agents
# ------------------------------------------------------------------------------------------
SHIPPED = [(env_id, algo) for env_id in CURRENT_ENV_IDS for algo in ALGOS]


@pytest.mark.parametrize(("env_id", "algo"), SHIPPED)
def test_shipped_agent_is_small_recorded_and_beats_zero(env_id: str, algo: str) -> None:
    model_path, meta_path = agent_files(env_id, algo)
    assert meta_path.is_file()
    assert model_path.parent == AGENT_DIR
    assert model_path.stat().st_size < 1_000_000  # small files inside the package
    meta = load_meta(env_id, algo)
    assert meta["name"] == agent_name(env_id, algo)
    for key in ("timesteps", "seed", "wall_time_s", "hyperparameters", "learning_curve"):
        assert key in meta
    # evaluation seeds are disjoint from the training and validation seeds
    assert meta["training_seeds"][1] < BENCHMARK_SEED
    assert meta["validation_seeds"][1] < BENCHMARK_SEED
    agent = evaluate(env_id, load_agent(env_id, algo), algo, 4, BENCHMARK_SEED, progress=_quiet)
    zero = evaluate(env_id, make_policy("zero", env_id), "zero", 4, BENCHMARK_SEED, progress=_quiet)
    assert np.mean(agent.returns) > np.mean(zero.returns) + 0.1 * abs(np.mean(zero.returns))

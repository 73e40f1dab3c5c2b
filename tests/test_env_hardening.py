"""Hardening of the environments: bounded reset options, observations that are always inside
the observation space, bounded rewards and no stepping past the end of an episode.

Every reset option has a physical range, derived from the ship and the task (its top speed,
its length, the distance it covers in one episode) and written in the env docstring; a value
outside it is refused with a ``ValueError`` naming the option, the value and the range. The
kernels never pass a NaN into an observation or a reward, and the rewards stay within the
bounds each env documents, whatever the state.
"""

from __future__ import annotations

import math
import re
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from test_envs import (  # the env ids of the env tests: one per task
    ENV_IDS,
    NOMOTO,
    RVG_HEADING,
    RVG_PATH,
    RVG_SPEED,
    RVG_TARGET,
    zero_action,
)

import shipgym

#: The benchmark's stress current: 1.5 times the largest ``--max-current-speed`` of the CLI.
BENCHMARK_MAX_STRESS_CURRENT = 1.5 * 5.0


def rvg_state(**values: float) -> dict[str, float]:
    """A full Gunnerus state, zero unless given."""
    state = dict.fromkeys(("x", "y", "psi", "u", "v", "r", "T1", "T2", "alpha1", "alpha2"), 0.0)
    state.update(values)
    return state


def assert_in_space(env: gym.Env, obs: np.ndarray) -> None:
    assert np.all(np.isfinite(obs)), obs
    assert env.observation_space.contains(obs), obs


def assert_reward_bounded(env: gym.Env, reward: float) -> None:
    low, high = env.unwrapped.task.reward_bounds
    assert math.isfinite(reward) and low <= reward <= high, (reward, (low, high))


def refusal(name: str, value: str, low: str, high: str) -> str:
    """Pattern of the refusal of ``name``: the option, its value and the accepted range."""
    return rf"{re.escape(name)}.*\[{re.escape(low)}, {re.escape(high)}\].*{re.escape(value)}"


# --------------------------------------------------------------------------------------------
# reset options: bounded, refused with option, value and range
# --------------------------------------------------------------------------------------------

#: (env id, options, pattern of the message): one row per option of every env.
REFUSED = [
    # the ship: speeds up to 1.5 times its top speed (Gunnerus 8.7 m/s, Mariner 9.9 m/s)
    (
        RVG_SPEED,
        {"initial_state": {"u": 100.0}},
        refusal("initial_state['u']", "100", "-13.05", "13.05"),
    ),
    (
        RVG_HEADING,
        {"initial_state": {"v": -20.0}},
        refusal("initial_state['v']", "-20", "-13.05", "13.05"),
    ),
    (NOMOTO, {"initial_state": {"U": 20.0}}, refusal("initial_state['U']", "20", "0", "14.85")),
    (NOMOTO, {"initial_state": {"U": -1.0}}, refusal("initial_state['U']", "-1", "0", "14.85")),
    # yaw rate: the bow moving sideways at the top speed
    (
        RVG_PATH,
        {"initial_state": {"r": 1.0}},
        refusal("initial_state['r']", "1", "-0.5133", "0.5133"),
    ),
    (
        NOMOTO,
        {"initial_state": {"r": 0.5}},
        refusal("initial_state['r']", "0.5", "-0.1231", "0.1231"),
    ),
    # actuators at their physical limits
    (
        RVG_TARGET,
        {"initial_state": {"T2": 1e300}},
        refusal("initial_state['T2']", "1e+300", "0", "121700"),
    ),
    (
        RVG_SPEED,
        {"initial_state": {"T1": -1.0}},
        refusal("initial_state['T1']", "-1", "0", "121700"),
    ),
    (
        RVG_HEADING,
        {"initial_state": {"alpha1": 4.0}},
        refusal("initial_state['alpha1']", "4", "-3.142", "3.142"),
    ),
    (
        NOMOTO,
        {"initial_state": {"delta": 1.0}},
        refusal("initial_state['delta']", "1", "-0.6109", "0.6109"),
    ),
    # positions within the distance the ship covers in one episode at its top speed
    (
        RVG_HEADING,
        {"initial_state": {"x": 1e7}},
        refusal("initial_state['x']", "10000000", "-2610", "2610"),
    ),
    (
        NOMOTO,
        {"initial_state": {"y": -1e308}},
        refusal("initial_state['y']", "-1e+308", "-7920", "7920"),
    ),
    # headings: up to 100 whole turns either way
    (
        RVG_SPEED,
        {"initial_state": {"psi": 1e4}},
        refusal("initial_state['psi']", "10000", "-628.4", "628.4"),
    ),
    # a full state vector names the bad entry too
    (
        RVG_SPEED,
        {"initial_state": list(rvg_state(u=100.0).values())},
        refusal("initial_state['u']", "100", "-13.05", "13.05"),
    ),
    # current: up to the ship's top speed, direction up to 100 turns
    (RVG_PATH, {"current_speed": 50.0}, refusal("current_speed", "50", "0", "8.7")),
    (NOMOTO, {"current_speed": 1e308}, refusal("current_speed", "1e+308", "0", "9.9")),
    (
        RVG_TARGET,
        {"current_direction": 1e6},
        refusal("current_direction", "1000000", "-628.4", "628.4"),
    ),
    # task options
    (RVG_SPEED, {"setpoints": [2.0, 8739.0]}, refusal("setpoints", "8739", "0", "8.7")),
    (NOMOTO, {"setpoints": [0.5, -1e5]}, refusal("setpoints", "-100000", "-628.4", "628.4")),
    (RVG_HEADING, {"setpoints": [1e300]}, refusal("setpoints", "1e+300", "-628.4", "628.4")),
    (
        RVG_PATH,
        {"waypoints": [[0.0, 0.0], [1e7, 0.0]]},
        refusal("waypoints", "10000000", "-6960", "6960"),
    ),
    (
        RVG_TARGET,
        {"target_position": [1e308, 1e308]},
        refusal("target_position", "1e+308", "-6960", "6960"),
    ),
    (
        RVG_TARGET,
        {"target_velocity": [1e308, -1e308]},
        refusal("target_velocity", "1e+308", "0", "13.05"),
    ),
    (
        RVG_TARGET,
        {"target_velocity": [10.0, 10.0]},
        refusal("target_velocity", "14.14", "0", "13.05"),
    ),
    (RVG_TARGET, {"distance": 1e6}, r"'distance'.*\(0, 3000\].*1000000"),
    (RVG_TARGET, {"distance": 0.0}, r"'distance'.*\(0, 3000\].*0"),
]


@pytest.mark.parametrize(("env_id", "options", "pattern"), REFUSED)
def test_out_of_range_option_refused_naming_option_value_and_range(
    env_id: str, options: dict[str, Any], pattern: str
) -> None:
    env, twin = gym.make(env_id), gym.make(env_id)
    env.reset(seed=5)
    twin.reset(seed=5)
    with pytest.raises(ValueError, match=pattern):
        env.reset(seed=0, options=options)
    # nothing changed: the episode goes on as its twin's
    a = np.full(env.action_space.shape, 0.3, dtype=np.float32)
    for _ in range(3):
        got, want = env.step(a), twin.step(a)
        assert np.array_equal(got[0], want[0]) and got[1] == want[1]
    with pytest.raises(ValueError, match=pattern):
        gym.make_vec(env_id, 2, vectorization_mode="vector_entry_point").reset(
            seed=0, options=options
        )


#: (env id, options) at the ends of the ranges: accepted.
ACCEPTED = [
    (RVG_SPEED, {"initial_state": {"u": 13.0, "T1": 121.7e3, "T2": 0.0}, "setpoints": [0.0, 8.7]}),
    (RVG_SPEED, {"initial_state": {"u": -13.0}, "setpoints": [8.7]}),
    (RVG_HEADING, {"initial_state": {"psi": -600.0, "alpha1": -math.pi, "r": -0.5}}),
    (NOMOTO, {"initial_state": {"U": 14.8, "delta": -0.6, "r": 0.12}, "setpoints": [600.0]}),
    (RVG_PATH, {"waypoints": [[-6960.0, 6960.0], [6960.0, -6960.0]], "current_speed": 8.7}),
    (
        RVG_TARGET,
        {"target_position": [6960.0, -6960.0], "target_velocity": [0.0, -13.0], "distance": 3000},
    ),
    (RVG_TARGET, {"initial_state": {"x": -6960.0, "y": 6960.0}, "current_direction": -628.0}),
]


@pytest.mark.parametrize(("env_id", "options"), ACCEPTED)
def test_options_at_range_ends_accepted(env_id: str, options: dict[str, Any]) -> None:
    env = gym.make(env_id)
    obs, _ = env.reset(seed=1, options=options)
    assert_in_space(env, obs)
    for _ in range(20):
        obs, reward, term, _, _ = env.step(env.action_space.sample())
        assert_in_space(env, obs)
        assert_reward_bounded(env, reward)
        if term:
            break


@pytest.mark.parametrize("env_id", shipgym.ENV_IDS)
def test_benchmark_stress_current_accepted(env_id: str) -> None:
    """The benchmark's stress scenario (1.5 times the training current) stays accepted."""
    env = gym.make(env_id)
    stress = 1.5 * env.unwrapped.task.max_current_speed
    for speed in (stress, BENCHMARK_MAX_STRESS_CURRENT):
        _, info = env.reset(seed=0, options={"current_speed": speed, "current_direction": 2.0})
        assert info["current_speed"] == speed


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_drawn_initial_state_is_a_valid_option(env_id: str) -> None:
    """What ``info["state"]`` reports after a reset or a run can be given back at reset."""
    env = gym.make(env_id)
    for seed in range(5):
        _, info = env.reset(seed=seed)
        for _ in range(50):
            _, _, term, _, info = env.step(env.action_space.sample())
            if term:
                break
        obs, _ = env.reset(
            seed=seed,
            options={
                "initial_state": info["state"].tolist(),
                "current_speed": info["current_speed"],
                "current_direction": info["current_direction"],
            },
        )
        assert_in_space(env, obs)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_max_current_speed_beyond_top_speed_refused(env_id: str) -> None:
    with pytest.raises(ValueError, match=r"max_current_speed.*\[0, (8\.7|9\.9)\].*100"):
        gym.make(env_id, max_current_speed=100.0)


# --------------------------------------------------------------------------------------------
# observations: always inside the observation space, never NaN
# --------------------------------------------------------------------------------------------


def _overflowing_positions(env: gym.Env) -> None:
    """Put the ship (and the target) at finite positions whose differences overflow."""
    task = env.unwrapped.task
    names = task.model.state_names
    big = 1.7e308
    task.x[0, names.index("x")] = -big
    task.x[0, names.index("y")] = big
    task.x[0, names.index("psi")] = math.pi / 4
    if hasattr(task, "target"):
        task.target[0] = (big, -big)
    if hasattr(task, "tangent"):
        task.tangent[0, :, 0] = big
        task.tangent[0, :, 1] = -big


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_observation_and_reward_finite_when_finite_state_overflows(env_id: str) -> None:
    """A finite state whose observation overflows to NaN ends the episode as a blow-up with the
    last observation, as a non-finite state does; the observation stays in the space."""
    env = gym.make(env_id)
    env.reset(seed=0)
    obs_before, *_ = env.step(zero_action(env))
    _overflowing_positions(env)
    obs, reward, term, _, info = env.step(zero_action(env))
    assert_in_space(env, obs)
    assert_reward_bounded(env, reward)
    if term:
        assert info["termination_reason"] in ("numerical_blow_up", "failure")
    if info["termination_reason"] == "numerical_blow_up":
        assert np.array_equal(obs, obs_before) and reward == 0.0


def test_target_far_away_after_many_steps_stays_in_space() -> None:
    """The fastest accepted target at the edge of the range, run for a whole episode."""
    env = gym.make(RVG_TARGET, max_distance=1e9)
    obs, _ = env.reset(
        seed=0, options={"target_position": [6960.0, 6960.0], "target_velocity": [9.0, 9.0]}
    )
    for _ in range(200):
        obs, reward, term, _, _ = env.step(env.action_space.sample())
        assert_in_space(env, obs)
        assert_reward_bounded(env, reward)
        assert not term


@pytest.mark.parametrize("env_id", shipgym.ENV_IDS)
def test_random_options_give_observations_in_space(env_id: str) -> None:
    """Random states anywhere in the accepted ranges: every observation is in the space."""
    env = gym.make(env_id)
    task = env.unwrapped.task
    rng = np.random.default_rng(7)
    ranges = task.state_ranges()
    for seed in range(8):
        state = {name: float(rng.uniform(lo, hi)) for name, (lo, hi) in ranges.items()}
        obs, _ = env.reset(seed=seed, options={"initial_state": state})
        assert_in_space(env, obs)
        for _ in range(10):
            obs, reward, term, _, _ = env.step(env.action_space.sample())
            assert_in_space(env, obs)
            assert_reward_bounded(env, reward)
            if term:
                break


# --------------------------------------------------------------------------------------------
# rewards: bounded and documented
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_reward_bounds_are_documented(env_id: str) -> None:
    env = gym.make(env_id)
    low, high = env.unwrapped.task.reward_bounds
    assert math.isfinite(low) and math.isfinite(high) and low < high
    doc = type(env.unwrapped).__doc__
    assert f"[{low:g}, {high:g}]" in doc


@pytest.mark.parametrize("u", [60.0, -40.0])
def test_speed_reward_bounded_however_fast_the_ship(u: float) -> None:
    """The speed error in the reward is that of the observation, clipped to +-25 m/s."""
    env = gym.make(RVG_SPEED)
    env.reset(seed=0, options={"setpoints": [8.7]})
    env.unwrapped.task.x[0, 3] = u
    _, reward, _, _, _ = env.step(zero_action(env))
    assert_reward_bounded(env, reward)
    assert reward == pytest.approx(-12.5 - 0.05 * env.unwrapped.task.obs[0, 2] ** 2)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_rewards_bounded_along_random_episodes(env_id: str) -> None:
    env = gym.make(env_id)
    for seed in range(3):
        env.reset(seed=seed)
        env.action_space.seed(seed)
        for _ in range(200):
            _, reward, term, trunc, _ = env.step(env.action_space.sample())
            assert_reward_bounded(env, reward)
            if term or trunc:
                break


# --------------------------------------------------------------------------------------------
# no step after the end of an episode
# --------------------------------------------------------------------------------------------


def _run_to_success(env: gym.Env) -> float:
    env.reset(
        seed=0,
        options={
            "waypoints": [[0.0, 0.0], [150.0, 0.0]],
            "current_speed": 0.0,
            "initial_state": rvg_state(u=5.144, T1=25e3, T2=25e3),
        },
    )
    for _ in range(200):
        _, reward, term, _, info = env.step(zero_action(env))
        if term:
            assert info["termination_reason"] == "success"
            return reward
    raise AssertionError("no success")


@pytest.mark.parametrize("unwrapped", [False, True])
def test_step_after_success_raises_until_reset(unwrapped: bool) -> None:
    env = gym.make(RVG_PATH)
    if unwrapped:
        env = env.unwrapped
    assert _run_to_success(env) > 5.0
    for _ in range(2):  # no further bonus, ever: every further step is refused
        with pytest.raises(gym.error.ResetNeeded, match=r"terminated.*success.*reset"):
            env.step(zero_action(env))
    # a refused reset keeps the episode ended
    with pytest.raises(ValueError):
        env.reset(options={"current_speed": -1.0})
    with pytest.raises(gym.error.ResetNeeded):
        env.step(zero_action(env))
    env.reset(seed=1)
    _, reward, term, _, _ = env.step(zero_action(env))
    assert not term and reward < 5.0


def test_step_after_failure_raises() -> None:
    env = gym.make(RVG_TARGET)
    env.reset(seed=0, options={"target_position": [4000.0, 0.0], "target_velocity": [0.0, 0.0]})
    _, _, term, _, info = env.step(zero_action(env))
    assert term and info["termination_reason"] == "failure"
    with pytest.raises(gym.error.ResetNeeded, match="failure"):
        env.step(zero_action(env))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_step_after_blow_up_raises(env_id: str) -> None:
    env = gym.make(env_id)
    env.reset(seed=0)
    env.unwrapped.task.x[0, 4] = np.nan
    _, _, term, _, info = env.step(zero_action(env))
    assert term and info["termination_reason"] == "numerical_blow_up"
    with pytest.raises(gym.error.ResetNeeded, match="numerical_blow_up"):
        env.step(zero_action(env))
    obs, _ = env.reset(seed=0)
    assert_in_space(env, obs)
    env.step(zero_action(env))


def test_step_after_truncation_is_left_to_the_time_limit() -> None:
    """Truncation is the ``TimeLimit`` wrapper's business: the env itself may go on."""
    env = gym.make(RVG_HEADING, max_episode_steps=3)
    env.reset(seed=0)
    for _ in range(3):
        *_, trunc, _ = env.step(zero_action(env))
    assert trunc
    env.step(zero_action(env))


def test_pickled_terminated_env_stays_terminated() -> None:
    import pickle

    env = gym.make(RVG_PATH).unwrapped
    _run_to_success(env)
    clone = pickle.loads(pickle.dumps(env))
    with pytest.raises(gym.error.ResetNeeded):
        clone.step(zero_action(clone))

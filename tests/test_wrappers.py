"""The robustness wrappers: sensor noise through the task's own observation, and an actuator
transport delay; :meth:`Task.observe` leaves the task untouched."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import shipgym
from shipgym.envs.wrappers import SENSOR_NOISE, ActuatorDelay, SensorNoise

HEADING = "shipgym/RVGHeading-v1"
PATH = "shipgym/RVGPathFollowing-v1"


def _actions(env: gym.Env, n: int, seed: int = 5) -> list[np.ndarray]:
    env.action_space.seed(seed)
    return [env.action_space.sample() for _ in range(n)]


@pytest.mark.parametrize("env_id", shipgym.CURRENT_ENV_IDS)
def test_observe_reproduces_the_kernel_and_changes_nothing(env_id: str) -> None:
    env, twin = gym.make(env_id), gym.make(env_id)
    env.reset(seed=4)
    twin.reset(seed=4)
    task = env.unwrapped.task
    for a in _actions(env, 40):
        obs, *_ = env.step(a)
        # the observation of the true state is the env's own
        np.testing.assert_allclose(task.observe(task.x.copy())[0], obs, rtol=1e-6, atol=1e-4)
        # a far-off state changes no part of the task (segment, reward, flags)
        task.observe(task.x + 500.0)
        twin_obs, twin_reward, *_ = twin.step(a)
    obs, reward, *_ = env.step(np.zeros(env.action_space.shape, np.float32))
    twin_obs, twin_reward, *_ = twin.step(np.zeros(env.action_space.shape, np.float32))
    assert np.array_equal(obs, twin_obs) and reward == twin_reward
    with pytest.raises(ValueError, match="shape"):
        task.observe(np.zeros(3))


def test_noise_off_is_the_plain_env_and_the_truth_is_untouched() -> None:
    actions = _actions(gym.make(PATH), 50)
    quiet = SensorNoise(gym.make(PATH), heading=0, yaw_rate=0, speed=0, position=0)
    noisy, plain = SensorNoise(gym.make(PATH)), gym.make(PATH)
    for env in (quiet, noisy, plain):
        env.reset(seed=9)
    for a in actions:
        q = quiet.step(a)
        n = noisy.step(a)
        p = plain.step(a)
        np.testing.assert_allclose(q[0], p[0], rtol=1e-6, atol=1e-5)
        # noise changes what the controller sees, never the ship
        assert np.array_equal(n[4]["state"], p[4]["state"]) and n[1] == p[1]
    assert not np.allclose(n[0], p[0])


def test_noise_levels_and_their_path_to_the_observation() -> None:
    env = SensorNoise(gym.make(HEADING))
    env.reset(seed=1)
    errors, shifts = [], []
    for _ in range(1500):
        obs, _, term, trunc, info = env.step(np.zeros(1, np.float32))
        truth = env.unwrapped.task.observe(info["state"][None, :])[0]
        err = info["measured_state"] - info["state"]
        errors.append(err)
        shifts.append(obs[0] - truth[0])
        if term or trunc:
            env.reset()
    err = np.array(errors)
    names = env.unwrapped.task.model.state_names
    for channel, states in (("heading", ["psi"]), ("yaw_rate", ["r"]), ("speed", ["u", "v"]),
                            ("position", ["x", "y"])):  # fmt: skip
        for s in states:
            assert np.std(err[:, names.index(s)]) == pytest.approx(SENSOR_NOISE[channel], rel=0.1)
    assert np.all(err[:, names.index("alpha1")] == 0.0)  # the actuator feedback is exact
    # the heading error the controller sees moves by minus the heading error of the sensor
    np.testing.assert_allclose(shifts, -err[:, names.index("psi")], atol=1e-6)


def test_noise_is_seeded_by_the_episode() -> None:
    a, b = SensorNoise(gym.make(HEADING)), SensorNoise(gym.make(HEADING))
    oa, _ = a.reset(seed=3)
    ob, _ = b.reset(seed=3)
    assert np.array_equal(oa, ob)
    oc, _ = b.reset(seed=4)
    assert not np.array_equal(oa, oc)
    with pytest.raises(ValueError, match="unknown noise channel"):
        SensorNoise(gym.make(HEADING), gps=1.0)
    with pytest.raises(ValueError, match="heading must be >= 0"):
        SensorNoise(gym.make(HEADING), heading=-1.0)


@pytest.mark.parametrize("env_id", [HEADING, PATH])
def test_delay_applies_each_command_k_steps_late(env_id: str) -> None:
    delayed = ActuatorDelay(gym.make(env_id), delay=1.0)
    assert delayed.steps == 2 and delayed.delay == 1.0
    plain = gym.make(env_id)
    delayed.reset(seed=2)
    plain.reset(seed=2)
    hold = delayed._holding_action()
    actions = _actions(plain, 40)
    for a, applied in zip(actions, [hold, hold, *actions], strict=False):
        d = delayed.step(a)
        p = plain.step(applied)
        assert np.array_equal(d[4]["state"], p[4]["state"])
    # holding the actuators: the pods stay where they start while the first command travels
    env = ActuatorDelay(gym.make(env_id), delay=1.0)
    _, info0 = env.reset(seed=2)
    _, _, _, _, info1 = env.step(np.ones(env.action_space.shape, np.float32))
    names = env.unwrapped.task.model.state_names
    for s in ("alpha1", "T1"):
        i = names.index(s)
        assert info1["state"][i] == pytest.approx(
            info0["state"][i], abs=1e-6 * (1 + abs(info0["state"][i]))
        )


def test_delay_checks_its_input() -> None:
    with pytest.raises(ValueError, match="'delay' must be finite"):
        ActuatorDelay(gym.make(HEADING), delay=math.nan)
    env = ActuatorDelay(gym.make(HEADING), delay=1.0)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="1 finite values"):
        env.step(np.zeros(3, np.float32))
    with pytest.raises(ValueError, match="1 finite values"):
        env.step(np.array([np.nan], np.float32))
    assert ActuatorDelay(gym.make(HEADING), delay=0.0).steps == 0

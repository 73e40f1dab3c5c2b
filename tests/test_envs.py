"""Tests of the Gymnasium environments of :mod:`shipgym.envs` (single and vector).

Covers the Gymnasium API (``check_env``), seeding and determinism, the equivalence of the
NumPy-batched vector environments with the single environments (one thread and several,
next-step autoreset), pickling, reset options, input validation, numerical blow-ups,
rendering and the contents of ``info``.
"""

from __future__ import annotations

import math
import pickle
import warnings
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

import shipgym
from shipgym.envs import TASKS, NomotoHeadingEnv, RVGSpeedEnv, env_task
from shipgym.envs.kernels import REASONS
from shipgym.models.angles import ssa
from shipgym.models.rvg import SERVICE_SPEED

#: One id per task (every code path); the ``-v1`` ids differ only in the default parameter set
#: and have their own tests below.
ENV_IDS = tuple(e for e in shipgym.ENV_IDS if e.endswith("-v0"))
NOMOTO = "shipgym/NomotoHeading-v0"
RVG_HEADING = "shipgym/RVGHeading-v0"
RVG_SPEED = "shipgym/RVGSpeed-v0"
RVG_PATH = "shipgym/RVGPathFollowing-v0"
RVG_TARGET = "shipgym/RVGTargetTracking-v0"
RVG_IDS = (RVG_HEADING, RVG_SPEED, RVG_PATH, RVG_TARGET)
NOMOTO_MODELS = ("nomoto1", "nomoto2", "norrbin", "bech")
#: Gunnerus environments whose action can switch the thrust off: (id, zero-thrust action).
ZERO_THRUST = {RVG_SPEED: [-1.0], RVG_PATH: [0.0, -1.0], RVG_TARGET: [0.0, -1.0]}

METRICS = {
    NOMOTO: ("heading_error", "heading_setpoint"),
    RVG_HEADING: ("heading_error", "heading_setpoint"),
    RVG_SPEED: ("speed_error", "speed_setpoint"),
    RVG_PATH: ("cross_track_error", "segment", "completed"),
    RVG_TARGET: ("distance", "distance_error"),
}

ACT_DIM = {NOMOTO: 1, RVG_HEADING: 1, RVG_SPEED: 1, RVG_PATH: 2, RVG_TARGET: 2}

N_STEPS = 50


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------


def make_vec(env_id: str, num_envs: int, **kwargs: Any) -> VectorEnv:
    return gym.make_vec(
        env_id, num_envs=num_envs, vectorization_mode="vector_entry_point", **kwargs
    )


def zero_action(env: gym.Env) -> np.ndarray:
    return np.zeros(env.action_space.shape, dtype=np.float32)


def sampled_actions(space: gym.Space, n: int, seed: int) -> list[np.ndarray]:
    space.seed(seed)
    return [space.sample() for _ in range(n)]


def assert_info_equal(a: dict[str, Any], b: dict[str, Any]) -> None:
    assert a.keys() == b.keys()
    for key in a:
        if isinstance(a[key], np.ndarray):
            assert np.array_equal(a[key], b[key], equal_nan=True), key
        else:
            assert a[key] == b[key], key


def assert_step_equal(a: tuple, b: tuple) -> None:
    """Two ``step`` results are bitwise identical."""
    obs_a, rew_a, term_a, trunc_a, info_a = a
    obs_b, rew_b, term_b, trunc_b, info_b = b
    assert np.array_equal(obs_a, obs_b)
    assert rew_a == rew_b
    assert (term_a, trunc_a) == (term_b, trunc_b)
    assert_info_equal(info_a, info_b)


def rollout(env: gym.Env, seed: int | None, actions: list[Any], options: Any = None) -> list:
    """``[(obs, info)]`` of the reset followed by every step result."""
    out: list = [env.reset(seed=seed, options=options)]
    out.extend(env.step(a) for a in actions)
    return out


def state_of(env: gym.Env, info: dict[str, Any], name: str) -> float:
    return float(info["state"][env.unwrapped.state_names.index(name)])


def rvg_state(**values: float) -> dict[str, float]:
    """A full Gunnerus state, zero unless given."""
    state = dict.fromkeys(("x", "y", "psi", "u", "v", "r", "T1", "T2", "alpha1", "alpha2"), 0.0)
    state.update(values)
    return state


def body_current(speed: float, direction: float, psi: float) -> tuple[float, float]:
    """Current ``(u_c, v_c)`` in the body frame of a ship with heading ``psi``."""
    cn, ce = speed * math.cos(direction), speed * math.sin(direction)
    return cn * math.cos(psi) + ce * math.sin(psi), -cn * math.sin(psi) + ce * math.cos(psi)


# --------------------------------------------------------------------------------------------
# Gymnasium API
# --------------------------------------------------------------------------------------------


def _check_env_without_warnings(env: gym.Env) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    assert not caught, [str(w.message) for w in caught]


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_check_env_passes_without_warnings(env_id: str) -> None:
    _check_env_without_warnings(gym.make(env_id))


@pytest.mark.parametrize("model", NOMOTO_MODELS)
def test_check_env_nomoto_models(model: str) -> None:
    env = gym.make(NOMOTO, model=model)
    assert env.unwrapped.task.model.name == model
    _check_env_without_warnings(env)


def test_all_ids_registered() -> None:
    assert len(ENV_IDS) == 5
    assert len(shipgym.ENV_IDS) == 9
    for env_id in shipgym.ENV_IDS:
        spec = gym.spec(env_id)
        assert spec.vector_entry_point is not None
        assert spec.max_episode_steps == gym.make(env_id).unwrapped.task.max_episode_steps
    assert shipgym.CURRENT_ENV_IDS == (NOMOTO, *(e.replace("-v0", "-v1") for e in RVG_IDS))
    assert [env_task(e) for e in shipgym.CURRENT_ENV_IDS] == list(TASKS)
    with pytest.raises(ValueError, match="unknown env"):
        env_task("shipgym/RVGHeading-v7")


@pytest.mark.parametrize("env_id", RVG_IDS)
def test_v1_is_the_sea_trial_ship_and_v0_is_unchanged(env_id: str) -> None:
    v1 = env_id.replace("-v0", "-v1")
    assert gym.make(env_id).unwrapped.task.model.params.name == "seed001"
    assert gym.make(v1).unwrapped.task.model.params.name == "sea_trials"
    vec = gym.make_vec(v1, num_envs=2, vectorization_mode="vector_entry_point")
    assert vec.task.model.params.name == "sea_trials"
    _check_env_without_warnings(gym.make(v1))
    # v1 is v0 with the sea-trial parameters: the same rollout to the last bit
    actions = sampled_actions(gym.make(v1).action_space, 60, seed=3)
    a = rollout(gym.make(v1), 11, actions)
    b = rollout(gym.make(env_id, params="sea_trials"), 11, actions)
    c = rollout(gym.make(env_id), 11, actions)
    assert np.array_equal(a[-1][4]["state"], b[-1][4]["state"])
    assert np.array_equal(a[-1][0], b[-1][0])
    assert not np.array_equal(a[-1][4]["state"], c[-1][4]["state"])


# --------------------------------------------------------------------------------------------
# seeding and determinism
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_rollout(env_id: str) -> None:
    env_a, env_b = gym.make(env_id), gym.make(env_id)
    actions_a = sampled_actions(env_a.action_space, 100, seed=7)
    actions_b = sampled_actions(env_b.action_space, 100, seed=7)
    assert all(np.array_equal(a, b) for a, b in zip(actions_a, actions_b, strict=True))
    run_a = rollout(env_a, 123, actions_a)
    run_b = rollout(env_b, 123, actions_b)
    assert np.array_equal(run_a[0][0], run_b[0][0])
    assert_info_equal(run_a[0][1], run_b[0][1])
    for step_a, step_b in zip(run_a[1:], run_b[1:], strict=True):
        assert_step_equal(step_a, step_b)
    # Reseeding a used environment replays the episode.
    assert_step_equal(rollout(env_a, 123, actions_a)[-1], run_a[-1])
    # Another seed gives another episode; a reset without a seed starts a new one.
    assert not np.array_equal(env_b.reset(seed=124)[1]["state"], run_a[0][1]["state"])
    assert not np.array_equal(env_a.reset()[1]["state"], run_a[0][1]["state"])


# --------------------------------------------------------------------------------------------
# vector environments
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_make_vec_batched_spaces(env_id: str) -> None:
    n = 4
    venv = make_vec(env_id, n)
    single = gym.make(env_id)
    assert isinstance(venv, VectorEnv)
    assert venv.num_envs == n
    assert venv.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert venv.single_observation_space == single.observation_space
    assert venv.single_action_space == single.action_space
    assert venv.observation_space == batch_space(single.observation_space, n)
    assert venv.action_space == batch_space(single.action_space, n)
    assert venv.observation_space.shape == (n, *single.observation_space.shape)
    assert venv.action_space.shape == (n, *single.action_space.shape)
    obs, info = venv.reset(seed=0)
    assert isinstance(info, dict)
    assert obs.dtype == np.float32 and obs in venv.observation_space
    obs, rew, term, trunc, info = venv.step(venv.action_space.sample())
    assert obs.shape == venv.observation_space.shape and obs in venv.observation_space
    assert rew.shape == term.shape == trunc.shape == (n,)
    assert term.dtype == trunc.dtype == np.bool_
    assert isinstance(info, dict)


@pytest.mark.parametrize("num_envs", [3, 80])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_env_matches_single_envs(env_id: str, num_envs: int) -> None:
    """Sub-env ``i`` seeded with ``s`` equals a single env seeded with ``s + i``, bitwise."""
    seed = 1000
    venv = make_vec(env_id, num_envs)
    actions = sampled_actions(venv.action_space, N_STEPS, seed=seed)
    obs, _ = venv.reset(seed=seed)
    v_obs, v_rew, v_term = [obs], [], []
    for a in actions:
        obs, rew, term, trunc, _ = venv.step(a)
        assert not trunc.any()
        v_obs.append(obs)
        v_rew.append(rew)
        v_term.append(term)
    v_obs, v_rew, v_term = np.stack(v_obs), np.stack(v_rew), np.stack(v_term)
    assert not np.array_equal(v_obs[0, 0], v_obs[0, 1])  # sub-envs are seeded differently

    for i in range(num_envs):
        env = gym.make(env_id)
        obs, _ = env.reset(seed=seed + i)
        s_obs, s_rew, s_term = [obs], [], []
        for a in actions:
            obs, rew, term, _, _ = env.step(a[i])
            s_obs.append(obs)
            s_rew.append(rew)
            s_term.append(term)
        assert np.array_equal(np.stack(s_obs), v_obs[:, i]), f"observations of sub-env {i}"
        assert np.array_equal(np.array(s_rew), v_rew[:, i]), f"rewards of sub-env {i}"
        assert np.array_equal(np.array(s_term), v_term[:, i]), f"terminations of sub-env {i}"


@pytest.mark.parametrize(
    ("env_id", "options"),
    [
        (
            RVG_PATH,
            {
                "waypoints": [[0.0, 0.0], [200.0, 100.0], [0.0, 400.0]],
                "current_speed": 0.2,
                "current_direction": 1.0,
            },
        ),
        (NOMOTO, {"setpoints": [1.0, 2.0], "initial_state": {"r": 0.01}}),
        (RVG_TARGET, {"target_position": [300.0, 0.0], "distance": 80.0}),
    ],
)
def test_vector_reset_options_match_single_env(env_id: str, options: dict[str, Any]) -> None:
    venv = make_vec(env_id, 3)
    actions = sampled_actions(venv.action_space, 10, seed=1)
    obs, _ = venv.reset(seed=40, options=options)
    steps = [venv.step(a)[0] for a in actions]
    for i in range(3):
        env = gym.make(env_id)
        run = rollout(env, 40 + i, [a[i] for a in actions], options=options)
        assert np.array_equal(run[0][0], obs[i])
        assert all(np.array_equal(r[0], o[i]) for r, o in zip(run[1:], steps, strict=True))
    task = venv.unwrapped.task
    if "current_speed" in options:
        assert np.all(task.current == [options["current_speed"], options["current_direction"]])


@pytest.mark.parametrize("num_envs", [3, 80])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_autoreset_after_truncation(env_id: str, num_envs: int) -> None:
    """Next-step autoreset continues each sub-env's random stream like ``env.reset()``."""
    seed, limit = 20, 10
    venv = make_vec(env_id, num_envs, max_episode_steps=limit)
    actions = sampled_actions(venv.action_space, 2 * limit + 3, seed=seed)
    obs0, _ = venv.reset(seed=seed)
    results = [venv.step(a) for a in actions]
    v_obs = np.stack([r[0] for r in results])
    v_rew, v_term, v_trunc = (np.stack([r[k] for r in results]) for k in (1, 2, 3))

    # Truncated after `limit` steps, reset on the next step, truncated again `limit` later.
    assert not v_trunc[: limit - 1].any() and v_trunc[limit - 1].all()
    assert not v_trunc[limit].any() and not v_term[limit].any()
    assert np.all(v_rew[limit] == 0.0)
    assert not v_trunc[limit + 1 : 2 * limit].any() and v_trunc[2 * limit].all()
    assert np.all(v_rew[2 * limit + 1] == 0.0)

    for i in range(num_envs):
        env = gym.make(env_id, max_episode_steps=limit)
        obs, _ = env.reset(seed=seed + i)
        assert np.array_equal(obs, obs0[i])
        done = False
        for t, a in enumerate(actions):
            if done:
                obs, _ = env.reset()
                rew, term, trunc = 0.0, False, False
                assert not np.array_equal(obs, obs0[i])  # a new episode, not a replay
            else:
                obs, rew, term, trunc, _ = env.step(a[i])
            assert np.array_equal(obs, v_obs[t, i]), f"sub-env {i}, step {t}"
            assert rew == v_rew[t, i], f"sub-env {i}, step {t}"
            assert (term, trunc) == (v_term[t, i], v_trunc[t, i]), f"sub-env {i}, step {t}"
            done = term or trunc


@pytest.mark.parametrize("num_envs", [3, 80])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_autoreset_after_blow_up(env_id: str, num_envs: int) -> None:
    """Only the sub-envs that terminated are reset, each like ``env.reset()``."""
    seed = 5
    blown = [1, num_envs - 1]
    venv = make_vec(env_id, num_envs)
    actions = sampled_actions(venv.action_space, 8, seed=seed)
    venv.reset(seed=seed)
    obs_before, *_ = venv.step(actions[0])
    venv.unwrapped.task.x[blown, 3] = np.nan
    obs, rew, term, trunc, info = venv.step(actions[1])
    assert np.flatnonzero(term).tolist() == blown and not trunc.any()
    assert [info["termination_reason"][i] for i in blown] == ["numerical_blow_up"] * 2
    assert np.all(rew[blown] == 0.0)
    assert np.array_equal(obs[blown], obs_before[blown]) and np.all(np.isfinite(obs))
    later = [venv.step(a) for a in actions[2:]]
    assert np.all(later[0][1][blown] == 0.0)
    assert not later[0][2].any() and not later[0][3].any()

    for i in range(num_envs):
        env = gym.make(env_id)
        env.reset(seed=seed + i)
        env.step(actions[0][i])
        if i in blown:
            expected = [env.reset()[0]] + [env.step(a[i])[0] for a in actions[3:]]
        else:
            assert np.array_equal(env.step(actions[1][i])[0], obs[i])
            expected = [env.step(a[i])[0] for a in actions[2:]]
        assert all(np.array_equal(e, r[0][i]) for e, r in zip(expected, later, strict=True)), i


@pytest.mark.parametrize(
    "bad_options",
    [{"current_speed": -1.0}, {"waypoints": [[0.0, 0.0]]}, {"initial_state": {"u": np.inf}}],
)
def test_rejected_reset_leaves_episode_untouched(bad_options: dict[str, Any]) -> None:
    env, twin = gym.make(RVG_PATH), gym.make(RVG_PATH)
    actions = sampled_actions(env.action_space, 10, seed=0)
    env.reset(seed=3)
    twin.reset(seed=3)
    for a in actions[:5]:
        env.step(a)
        twin.step(a)
    with pytest.raises(ValueError):
        env.reset(options=bad_options)
    for a in actions[5:]:
        assert_step_equal(env.step(a), twin.step(a))


# --------------------------------------------------------------------------------------------
# pickling
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("steps_before", [0, 5])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_env_pickles(env_id: str, steps_before: int) -> None:
    env = gym.make(env_id)
    actions = sampled_actions(env.action_space, steps_before + 20, seed=3)
    env.reset(seed=11)
    for a in actions[:steps_before]:
        env.step(a)
    copy = pickle.loads(pickle.dumps(env))
    for a in actions[steps_before:]:
        assert_step_equal(copy.step(a), env.step(a))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_unpickled_env_keeps_read_only_model_parameters(env_id: str) -> None:
    """``ShipModel.p`` is read-only; a writable copy is another Numba type (a recompile)."""
    for env in (gym.make(env_id), make_vec(env_id, 2)):
        env.reset(seed=0)
        assert not env.unwrapped.task.model.p.flags.writeable
        copy = pickle.loads(pickle.dumps(env))
        assert not copy.unwrapped.task.model.p.flags.writeable
        assert np.array_equal(copy.unwrapped.task.model.p, env.unwrapped.task.model.p)


@pytest.mark.parametrize("steps_before", [0, 5])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_env_pickles(env_id: str, steps_before: int) -> None:
    venv = make_vec(env_id, 4)
    actions = sampled_actions(venv.action_space, steps_before + 20, seed=3)
    venv.reset(seed=11)
    for a in actions[:steps_before]:
        venv.step(a)
    copy = pickle.loads(pickle.dumps(venv))
    for a in actions[steps_before:]:
        got, want = copy.step(a), venv.step(a)
        for k in range(4):
            assert np.array_equal(got[k], want[k])


# --------------------------------------------------------------------------------------------
# reset options: current
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_current_options_in_info(env_id: str) -> None:
    env = gym.make(env_id)
    _, info = env.reset(seed=0, options={"current_speed": 0.3, "current_direction": -1.2})
    assert (info["current_speed"], info["current_direction"]) == (0.3, -1.2)
    _, _, _, _, info = env.step(zero_action(env))
    assert (info["current_speed"], info["current_direction"]) == (0.3, -1.2)
    max_speed = env.unwrapped.task.max_current_speed
    speeds, directions = [], []
    for seed in range(20):
        _, info = env.reset(seed=seed)
        speeds.append(info["current_speed"])
        directions.append(info["current_direction"])
    assert 0.0 <= min(speeds) and max(speeds) <= max_speed and len(set(speeds)) == 20
    assert -math.pi <= min(directions) and max(directions) < math.pi


@pytest.mark.parametrize("direction", [0.0, math.pi / 2, 2.5, -2.0])
@pytest.mark.parametrize("env_id", list(ZERO_THRUST))
def test_rvg_at_rest_in_water_drifts_with_current(env_id: str, direction: float) -> None:
    """Without thrust, a ship at rest relative to the water moves exactly with the current."""
    speed, psi, steps = 0.4, 1.0, 200
    uc, vc = body_current(speed, direction, psi)
    env = gym.make(env_id)
    _, info = env.reset(
        seed=0,
        options={
            "current_speed": speed,
            "current_direction": direction,
            "initial_state": rvg_state(psi=psi, u=uc, v=vc),
        },
    )
    action = np.array(ZERO_THRUST[env_id], dtype=np.float32)
    for _ in range(steps):
        _, _, term, _, info = env.step(action)
        assert not term
    t = steps * env.unwrapped.dt
    north, east = state_of(env, info, "x"), state_of(env, info, "y")
    # NED: x north, y east; the direction is where the water goes, clockwise from north.
    assert north == pytest.approx(speed * t * math.cos(direction), abs=1e-6)
    assert east == pytest.approx(speed * t * math.sin(direction), abs=1e-6)
    assert state_of(env, info, "psi") == pytest.approx(psi, abs=1e-9)
    assert state_of(env, info, "r") == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("direction", [0.0, 2.5, -2.0])
def test_rvg_at_rest_over_ground_is_carried_by_current(direction: float) -> None:
    """A ship with u = v = r = 0 and no thrust is picked up by the current."""
    speed = 0.4
    env = gym.make(RVG_SPEED, max_episode_steps=3000)
    env.reset(
        seed=0,
        options={
            "current_speed": speed,
            "current_direction": direction,
            "initial_state": rvg_state(psi=1.0),
        },
    )
    for _ in range(2000):
        _, _, term, _, info = env.step(np.array([-1.0], dtype=np.float32))
        assert not term
    x, y, psi, u, v = info["state"][:5]
    v_north = u * math.cos(psi) - v * math.sin(psi)
    v_east = u * math.sin(psi) + v * math.cos(psi)
    assert (
        math.hypot(v_north - speed * math.cos(direction), v_east - speed * math.sin(direction))
        < 0.1
    )
    assert math.hypot(x, y) > 200.0
    assert abs(ssa(math.atan2(y, x) - direction)) < 0.4


def test_rvg_without_current_stays_at_rest() -> None:
    env = gym.make(RVG_SPEED)
    env.reset(seed=0, options={"current_speed": 0.0, "initial_state": rvg_state(psi=1.0)})
    for _ in range(50):
        _, _, _, _, info = env.step(np.array([-1.0], dtype=np.float32))
    assert np.array_equal(info["state"], list(rvg_state(psi=1.0).values()))


@pytest.mark.parametrize("env_id", [RVG_HEADING, RVG_PATH, RVG_TARGET])
def test_rvg_starts_at_service_speed_through_water(env_id: str) -> None:
    env = gym.make(env_id)
    _, info = env.reset(seed=2, options={"current_speed": 0.5, "current_direction": 1.0})
    psi, u, v, r = info["state"][2:6]
    uc, vc = body_current(0.5, 1.0, psi)
    assert u - uc == pytest.approx(SERVICE_SPEED) and v - vc == pytest.approx(0.0, abs=1e-12)
    assert r == 0.0


@pytest.mark.parametrize("model", NOMOTO_MODELS)
def test_nomoto_current_carries_ship_without_turning_it(model: str) -> None:
    speed, direction, steps = 0.8, 2.0, 100
    final = []
    for v in (0.0, speed):
        env = gym.make(NOMOTO, model=model)
        env.reset(seed=3, options={"current_speed": v, "current_direction": direction})
        for _ in range(steps):
            _, _, _, _, info = env.step(np.array([0.3], dtype=np.float32))
        final.append(info["state"])
    drift = final[1] - final[0]
    t = steps * env.unwrapped.dt
    assert drift[0] == pytest.approx(speed * t * math.cos(direction), abs=1e-6)
    assert drift[1] == pytest.approx(speed * t * math.sin(direction), abs=1e-6)
    assert np.all(drift[2:] == 0.0)


# --------------------------------------------------------------------------------------------
# reset options: task
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", [NOMOTO, RVG_HEADING])
def test_heading_setpoints_option(env_id: str) -> None:
    env = gym.make(env_id, setpoint_interval=5.0)
    hold = round(5.0 / env.unwrapped.dt)
    setpoints = [0.5, -1.0, 4.0]
    expected = [0.5, -1.0, 4.0 - 2 * math.pi]
    obs, info = env.reset(seed=1, options={"setpoints": setpoints})
    for k in range(4 * hold):
        if k:
            obs, _, _, _, info = env.step(zero_action(env))
        want = expected[min(k // hold, 2)]
        assert info["heading_setpoint"] == pytest.approx(want, abs=1e-12), k
        err = ssa(want - state_of(env, info, "psi"))
        assert info["heading_error"] == pytest.approx(err, abs=1e-12)
        assert obs[0] == np.float32(info["heading_error"])


@pytest.mark.parametrize(("env_id", "rudder", "sign"), [(NOMOTO, 1.0, 1), (RVG_HEADING, 1.0, -1)])
def test_heading_action_turns_documented_way(env_id: str, rudder: float, sign: int) -> None:
    """Positive rudder turns the Mariner to starboard, positive pod azimuth turns RVG to port."""
    env = gym.make(env_id)
    _, info = env.reset(seed=0, options={"current_speed": 0.0})
    psi0 = state_of(env, info, "psi")
    for _ in range(20):
        _, _, _, _, info = env.step(np.array([rudder], dtype=np.float32))
    assert sign * ssa(state_of(env, info, "psi") - psi0) > 0.05
    assert sign * state_of(env, info, "r") > 0


def test_speed_setpoints_option() -> None:
    env = gym.make(RVG_SPEED, setpoint_interval=5.0)
    hold = round(5.0 / env.unwrapped.dt)
    obs, info = env.reset(
        seed=1, options={"setpoints": [2.0, 3.5], "current_speed": 0.3, "current_direction": 0.7}
    )
    for k in range(3 * hold):
        if k:
            obs, _, _, _, info = env.step(np.array([0.2], dtype=np.float32))
        want = 2.0 if k < hold else 3.5
        assert info["speed_setpoint"] == want and obs[3] == np.float32(want)
        psi, u = state_of(env, info, "psi"), state_of(env, info, "u")
        u_r = u - body_current(0.3, 0.7, psi)[0]
        assert info["speed_error"] == pytest.approx(want - u_r, abs=1e-12)
        assert obs[0] == np.float32(info["speed_error"])
    with pytest.raises(ValueError, match="setpoints"):
        env.reset(options={"setpoints": [2.0, -1.0]})


def test_waypoints_option_sets_path() -> None:
    path = [[0.0, 0.0], [300.0, 0.0], [300.0, 300.0]]
    env = gym.make(RVG_PATH)
    obs, info = env.reset(
        seed=0,
        options={
            "waypoints": path,
            "current_speed": 0.0,
            "initial_state": rvg_state(y=20.0, u=SERVICE_SPEED, T1=25e3, T2=25e3),
        },
    )
    assert np.array_equal(env.unwrapped.task.waypoints(0), np.array(path))
    # Ship 20 m east of a northbound leg: right of the path, positive cross-track error.
    assert info["cross_track_error"] == pytest.approx(20.0)
    assert obs[0] == np.float32(20.0)
    assert obs[2] == pytest.approx(300.0)  # along-track distance left
    assert obs[3] == pytest.approx(math.pi / 2)  # turn to starboard at the end of the leg
    assert info["segment"] == 0 and info["completed"] is False
    for _ in range(200):
        obs, _, term, _, info = env.step(np.array([0.0, 0.0], dtype=np.float32))
        assert not term
        if info["segment"] == 1:
            break
    assert info["segment"] == 1
    north = state_of(env, info, "x")
    # On the eastbound leg from (300, 0) the ship is to its south: right of the path.
    assert info["cross_track_error"] == pytest.approx(300.0 - north)
    assert north < 300.0


def test_waypoints_default_start_near_first_waypoint() -> None:
    env = gym.make(RVG_PATH)
    for seed in range(5):
        _, info = env.reset(seed=seed, options={"waypoints": [[100.0, -50.0], [400.0, 350.0]]})
        start = info["state"][:2]
        assert abs(info["cross_track_error"]) <= 30.0
        assert np.hypot(*(start - [100.0, -50.0])) <= 30.0 + 1e-9


def test_path_completion_and_failure() -> None:
    env = gym.make(RVG_PATH)
    start = rvg_state(u=SERVICE_SPEED, T1=25e3, T2=25e3)
    env.reset(
        seed=0,
        options={
            "waypoints": [[0.0, 0.0], [150.0, 0.0]],
            "current_speed": 0.0,
            "initial_state": start,
        },
    )
    for _ in range(100):
        _, rew, term, trunc, info = env.step(np.array([0.0, 0.0], dtype=np.float32))
        if term:
            break
    assert term and not trunc
    assert info["completed"] is True and info["termination_reason"] == "success"
    assert rew > 5.0
    env.reset(
        seed=0,
        options={
            "waypoints": [[0.0, 0.0], [500.0, 0.0]],
            "current_speed": 0.0,
            "initial_state": {**start, "y": 300.0},
        },
    )
    _, rew, term, _, info = env.step(np.array([0.0, 0.0], dtype=np.float32))
    assert term and info["termination_reason"] == "failure" and info["completed"] is False
    assert rew < -5.0


def test_target_options() -> None:
    env = gym.make(RVG_TARGET)
    pos, vel = np.array([120.0, 50.0]), np.array([1.0, -0.5])
    obs, info = env.reset(
        seed=0,
        options={
            "target_position": pos.tolist(),
            "target_velocity": vel.tolist(),
            "distance": 30.0,
            "current_speed": 0.0,
            "initial_state": rvg_state(u=SERVICE_SPEED, T1=25e3, T2=25e3),
        },
    )
    assert info["distance"] == pytest.approx(130.0)
    assert info["distance_error"] == pytest.approx(100.0)
    assert obs[:2] == pytest.approx([120.0, 50.0])  # heading north: body = NED axes
    assert obs[4] == np.float32(info["distance_error"])
    dt = env.unwrapped.dt
    for k in range(1, 21):
        obs, _, _, _, info = env.step(np.array([0.1, 0.0], dtype=np.float32))
        target = pos + vel * k * dt
        d = float(np.hypot(*(target - info["state"][:2])))
        assert info["distance"] == pytest.approx(d, abs=1e-9)
        assert info["distance_error"] == pytest.approx(d - 30.0, abs=1e-9)
    env.reset(seed=0, options={"target_position": [4000.0, 0.0], "target_velocity": [0.0, 0.0]})
    _, rew, term, _, info = env.step(zero_action(env))
    assert term and info["termination_reason"] == "failure" and rew <= -10.0


# --------------------------------------------------------------------------------------------
# bad input
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_non_finite_action_raises(env_id: str, bad: float) -> None:
    env, twin = gym.make(env_id), gym.make(env_id)
    env.reset(seed=4)
    twin.reset(seed=4)
    action = zero_action(env)
    action[-1] = bad
    with pytest.raises(ValueError, match=r"NaN|inf"):
        env.step(action)
    # The rejected step changed nothing.
    a = np.full(env.action_space.shape, 0.5, dtype=np.float32)
    assert_step_equal(env.step(a), twin.step(a))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_non_finite_action_raises(env_id: str) -> None:
    venv = make_vec(env_id, 3)
    venv.reset(seed=0)
    actions = np.zeros(venv.action_space.shape, dtype=np.float32)
    actions[2, 0] = np.nan
    with pytest.raises(ValueError, match=r"NaN|inf"):
        venv.step(actions)


def _wrong_shapes(act_dim: int) -> list[tuple[int, ...]]:
    shapes = [(act_dim + 1,), (2, act_dim), (0,)]
    if act_dim > 1:
        shapes += [(1,), ()]
    return shapes


@pytest.mark.parametrize(
    ("env_id", "shape"),
    [(i, s) for i in ENV_IDS for s in _wrong_shapes(ACT_DIM[i])],
    ids=lambda v: f"shape{v}" if isinstance(v, tuple) else v,
)
def test_wrong_action_shape_raises(env_id: str, shape: tuple[int, ...]) -> None:
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(np.zeros(shape, dtype=np.float32))


@pytest.mark.parametrize("which", ["extra_column", "missing_row", "unbatched"])
@pytest.mark.parametrize("env_id", [NOMOTO, RVG_PATH])
def test_vector_wrong_action_shape_raises(env_id: str, which: str) -> None:
    venv = make_vec(env_id, 3)
    venv.reset(seed=0)
    n, d = venv.action_space.shape
    shape = {"extra_column": (n, d + 1), "missing_row": (n - 1, d), "unbatched": (d,)}[which]
    with pytest.raises(ValueError, match="action"):
        venv.step(np.zeros(shape, dtype=np.float32))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_out_of_range_actions_are_clipped(env_id: str) -> None:
    env_raw, env_clip = gym.make(env_id), gym.make(env_id)
    rng = np.random.default_rng(0)
    raw = [
        rng.uniform(-5.0, 5.0, env_raw.action_space.shape).astype(np.float32)
        for _ in range(N_STEPS)
    ]
    raw[0][:] = 5.0
    raw[1][:] = -7.0
    clipped = [np.clip(a, -1.0, 1.0) for a in raw]
    assert not all(np.array_equal(a, b) for a, b in zip(raw, clipped, strict=True))
    run_raw = rollout(env_raw, 9, raw)
    run_clip = rollout(env_clip, 9, clipped)
    for step_raw, step_clip in zip(run_raw[1:], run_clip[1:], strict=True):
        assert_step_equal(step_raw, step_clip)


def test_vector_out_of_range_actions_are_clipped() -> None:
    venv_raw, venv_clip = make_vec(RVG_PATH, 3), make_vec(RVG_PATH, 3)
    venv_raw.reset(seed=0)
    venv_clip.reset(seed=0)
    raw = np.array([[5.0, -5.0], [-2.0, 3.0], [0.5, 1.5]], dtype=np.float32)
    for _ in range(10):
        got, want = venv_raw.step(raw.copy()), venv_clip.step(np.clip(raw, -1.0, 1.0))
        for k in range(4):
            assert np.array_equal(got[k], want[k])


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_bad_current_options_raise(env_id: str) -> None:
    env = gym.make(env_id)
    with pytest.raises(ValueError, match="current_speed"):
        env.reset(seed=0, options={"current_speed": -0.1})
    with pytest.raises(ValueError, match="current_direction"):
        env.reset(seed=0, options={"current_direction": float("nan")})


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_unknown_option_raises(env_id: str) -> None:
    env = gym.make(env_id)
    with pytest.raises(ValueError, match=r"unknown reset option.*foo"):
        env.reset(seed=0, options={"foo": 1})
    with pytest.raises(ValueError, match="initial_state"):
        env.reset(seed=0, options={"initial_state": {"not_a_state": 1.0}})
    foreign = "target_position" if env_id != RVG_TARGET else "waypoints"
    with pytest.raises(ValueError, match=f"unknown reset option.*{foreign}"):
        env.reset(seed=0, options={foreign: [[0.0, 0.0], [1.0, 1.0]]})
    with pytest.raises(ValueError, match="unknown reset option"):
        make_vec(env_id, 2).reset(seed=0, options={"foo": 1})


def test_unknown_model_raises() -> None:
    with pytest.raises(ValueError, match=r"unknown model 'foo'"):
        gym.make(NOMOTO, model="foo")
    with pytest.raises(ValueError, match="unknown model"):
        make_vec(NOMOTO, 2, model="foo")


@pytest.mark.parametrize(
    "waypoints", [[[0.0, 0.0]], [], [[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [1.0, np.nan]]]
)
def test_bad_waypoints_raise(waypoints: list) -> None:
    env = gym.make(RVG_PATH)
    with pytest.raises(ValueError, match="waypoints"):
        env.reset(seed=0, options={"waypoints": waypoints})


# --------------------------------------------------------------------------------------------
# numerical blow-up
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [np.inf, np.nan])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_blow_up_terminates_with_finite_observation(env_id: str, bad: float) -> None:
    env = gym.make(env_id)
    env.reset(seed=0)
    for _ in range(3):
        obs_before, *_ = env.step(zero_action(env))
    env.unwrapped.task.x[0, 4] = bad
    obs, rew, term, trunc, info = env.step(zero_action(env))
    assert term and not trunc
    assert info["termination_reason"] == "numerical_blow_up"
    assert rew == 0.0
    assert not np.any(np.isnan(obs)) and np.array_equal(obs, obs_before)


@pytest.mark.parametrize("env_id", RVG_IDS)
def test_blow_up_from_huge_state(env_id: str) -> None:
    """A huge (unobserved) pod thrust makes the integration overflow in the first step (the
    reset options refuse it, so it is written into the state as a diverging run leaves it)."""
    env = gym.make(env_id)
    obs0, info = env.reset(seed=0)
    env.unwrapped.task.x[0, env.unwrapped.state_names.index("T2")] = 1e300
    assert info["termination_reason"] == "running"
    obs, rew, term, _, info = env.step(zero_action(env))
    assert term and info["termination_reason"] == "numerical_blow_up"
    assert not np.all(np.isfinite(info["state"]))
    assert not np.any(np.isnan(obs)) and np.array_equal(obs, obs0) and rew == 0.0


# --------------------------------------------------------------------------------------------
# rendering
# --------------------------------------------------------------------------------------------


def _assert_frame(frame: Any) -> None:
    assert isinstance(frame, np.ndarray) and frame.dtype == np.uint8
    assert frame.ndim == 3 and frame.shape[2] == 3 and min(frame.shape[:2]) > 0
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) > 10  # not blank


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_render_rgb_array(env_id: str) -> None:
    env = gym.make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    first = env.render()
    _assert_frame(first)
    for _ in range(6):
        env.step(env.action_space.sample())
    later = env.render()
    _assert_frame(later)
    assert later.shape == first.shape and not np.array_equal(later, first)
    env.close()


def test_vector_render_rgb_array() -> None:
    venv = make_vec(RVG_PATH, 2, render_mode="rgb_array")
    venv.reset(seed=0)
    _assert_frame(venv.render())
    venv.step(venv.action_space.sample())
    _assert_frame(venv.render())


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_invalid_render_mode_raises(env_id: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # Gymnasium warns before the env raises
        with pytest.raises(ValueError, match="render_mode"):
            gym.make(env_id, render_mode="foo")
    with pytest.raises(ValueError, match="render_mode"):
        make_vec(env_id, 2, render_mode="human")


def test_invalid_render_mode_raises_on_class() -> None:
    with pytest.raises(ValueError, match="render_mode"):
        NomotoHeadingEnv(render_mode="rgb")
    with pytest.raises(ValueError, match="render_mode"):
        RVGSpeedEnv(render_mode="ansi")


# --------------------------------------------------------------------------------------------
# info and observations
# --------------------------------------------------------------------------------------------


def _check_info(env: gym.Env, env_id: str, obs: np.ndarray, info: dict[str, Any]) -> None:
    state = info["state"]
    assert isinstance(state, np.ndarray)
    assert len(state) == len(env.unwrapped.state_names)
    assert np.array_equal(state, env.unwrapped.task.x[0])
    assert isinstance(info["current_speed"], float)
    assert isinstance(info["current_direction"], float)
    assert info["termination_reason"] in REASONS
    for key in METRICS[env_id]:
        assert key in info, key
    if env_id in (NOMOTO, RVG_HEADING):
        err = ssa(info["heading_setpoint"] - state_of(env, info, "psi"))
        assert info["heading_error"] == pytest.approx(err, abs=1e-12)
        assert obs[0] == np.float32(info["heading_error"])
    elif env_id == RVG_SPEED:
        assert obs[0] == np.float32(info["speed_error"])
        assert obs[3] == np.float32(info["speed_setpoint"])
    elif env_id == RVG_PATH:
        assert obs[0] == np.float32(info["cross_track_error"])
        assert isinstance(info["segment"], int) and isinstance(info["completed"], bool)
    else:
        target = env.unwrapped.task.target[0]
        assert info["distance"] == pytest.approx(float(np.hypot(*(target - state[:2]))))
        assert info["distance_error"] == pytest.approx(info["distance"] - 50.0)
        assert obs[4] == np.float32(info["distance_error"])


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_info_contents(env_id: str) -> None:
    env = gym.make(env_id)
    obs, info = env.reset(seed=8)
    _check_info(env, env_id, obs, info)
    assert info["termination_reason"] == "running"
    for a in sampled_actions(env.action_space, 30, seed=8):
        obs, _, _, _, info = env.step(a)
        _check_info(env, env_id, obs, info)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_observations_float32_in_space(env_id: str) -> None:
    env = gym.make(env_id)
    space = env.observation_space
    assert space.dtype == np.float32
    assert env.action_space.dtype == np.float32 and env.action_space.shape == (ACT_DIM[env_id],)
    assert np.all(env.action_space.low == -1.0) and np.all(env.action_space.high == 1.0)
    obs, _ = env.reset(seed=0)
    assert obs.dtype == np.float32 and obs.shape == space.shape and obs in space
    for a in sampled_actions(env.action_space, 200, seed=0):
        obs, rew, term, trunc, _ = env.step(a)
        assert obs.dtype == np.float32 and obs in space
        assert isinstance(rew, float) and math.isfinite(rew)
        assert isinstance(term, bool) and isinstance(trunc, bool)
        if term:
            obs, _ = env.reset()


@pytest.mark.parametrize(
    "env_id",
    ["shipgym/RVGHeading-v0", "shipgym/RVGSpeed-v0", "shipgym/RVGPathFollowing-v0",
     "shipgym/RVGTargetTracking-v0"],
)  # fmt: skip
def test_rvg_envs_take_the_parameter_set(env_id: str) -> None:
    """``params="sea_trials"`` puts the identified Gunnerus in the single and the vector env; the
    same seed and actions then give another trajectory than seed 001; a bad name is refused."""
    from shipgym.models import RVGParams

    finals = {}
    for name in ("seed001", "sea_trials"):
        env = gym.make(env_id, params=name)
        assert env.unwrapped.task.model.params.name == name
        env.reset(seed=3)
        action = np.full(env.action_space.shape, 0.5, dtype=np.float32)
        for _ in range(60):
            obs, *_ = env.step(action)
        finals[name] = obs
        env.close()
    assert not np.allclose(finals["seed001"], finals["sea_trials"])
    vec = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point",
                       params=RVGParams.sea_trials())  # fmt: skip
    assert vec.unwrapped.task.model.params.name == "sea_trials"
    vec.close()
    with pytest.raises(ValueError, match="sea_trials"):
        gym.make(env_id, params="real")


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_env_refuses_calls_out_of_order_as_the_single_env_does(env_id: str) -> None:
    """Step or render before the first reset: Gymnasium's ``ResetNeeded``, as the single env
    raises; any call after ``close``: ``ClosedEnvironmentError``; the state is untouched."""
    single = gym.make(env_id, render_mode="rgb_array")
    vec = gym.make_vec(
        env_id, num_envs=2, vectorization_mode="vector_entry_point", render_mode="rgb_array"
    )
    actions = np.zeros((2, *single.action_space.shape), np.float32)
    for call in (lambda e: e.step(actions[0]), lambda e: e.render()):
        with pytest.raises(gym.error.ResetNeeded, match="before calling"):
            call(single)
    for call in (lambda e: e.step(actions), lambda e: e.render()):
        with pytest.raises(gym.error.ResetNeeded, match=r"before calling env\.reset\(\)"):
            call(vec)
    vec.reset(seed=0)
    vec.step(actions)
    state = vec.task.x.copy()
    vec.close()
    for call in (lambda e: e.step(actions), lambda e: e.reset(seed=1)):
        with pytest.raises(gym.error.ClosedEnvironmentError, match="closed"):
            call(vec)
    assert np.array_equal(vec.task.x, state)


@pytest.mark.parametrize("env_id", ["shipgym/NomotoHeading-v0", "shipgym/RVGPathFollowing-v1"])
def test_vector_env_threads_give_bitwise_the_same_run(env_id: str) -> None:
    """``num_threads`` changes who steps the batch, never a number (across autoresets); the
    batch split into more parts than there are CPUs gives the same numbers too."""
    from shipgym.envs import kernels

    threads = kernels.available_threads()
    runs = []
    for count in (1, None, 3):
        venv = make_vec(env_id, 130, num_threads=1 if count == 3 else count, max_episode_steps=15)
        assert venv.num_threads == (threads if count is None else 1)
        if count == 3:  # three parts of 44, 43 and 43 rows, whatever the machine has
            venv.task.num_threads = 3
        obs, _ = venv.reset(seed=9)
        rng = np.random.default_rng(2)
        trace = [obs]
        for _ in range(40):
            obs, rew, term, trunc, _ = venv.step(rng.uniform(-1, 1, venv.action_space.shape))
            trace += [obs, rew, term, trunc]
        runs.append(trace)
    assert all(np.array_equal(a, b) for a, b in zip(runs[0], runs[1], strict=True))
    assert all(np.array_equal(a, b) for a, b in zip(runs[0], runs[2], strict=True))
    # truncated at steps 15 and 31 (step 16 is the autoreset): the run crosses episodes
    assert runs[0][4 * 15].all() and runs[0][4 * 31].all()


def _step_in_child(venv: VectorEnv, queue: Any) -> None:
    venv.step(np.zeros(venv.action_space.shape))
    queue.put(venv.unwrapped.task.steps.sum())


def test_threaded_step_works_in_a_forked_child() -> None:
    """A process forked after a threaded step has none of the step's pool threads: its steps
    make their own (before, they would wait for the parent's threads for ever)."""
    import multiprocessing

    venv = make_vec("shipgym/NomotoHeading-v0", 130, num_threads=1)
    venv.task.num_threads = 2
    venv.reset(seed=3)
    venv.step(np.zeros(venv.action_space.shape))  # the pool exists in this process now
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    child = ctx.Process(target=_step_in_child, args=(venv, queue))
    child.start()
    child.join(timeout=60)
    stuck = child.is_alive()
    child.kill()
    assert not stuck and child.exitcode == 0
    assert queue.get(timeout=5) == 2 * 130


def test_threaded_step_refuses_a_bad_action_without_stepping_any_part() -> None:
    venv = make_vec("shipgym/NomotoHeading-v0", 130, num_threads=1)
    venv.task.num_threads = 3
    venv.reset(seed=1)
    state = venv.task.x.copy()
    actions = np.zeros((130, 1))
    actions[100] = np.nan  # in the last part
    with pytest.raises(ValueError, match="sub-env 100's action holds NaN"):
        venv.step(actions)
    assert np.array_equal(venv.task.x, state)


@pytest.mark.parametrize("bad", [0, -1, 10**6, 1.5, "2", True])
def test_vector_env_refuses_bad_num_threads(bad: Any) -> None:
    with pytest.raises(ValueError, match=r"num_threads must be an integer in \[1, \d+\]"):
        make_vec("shipgym/NomotoHeading-v0", 4, num_threads=bad)


def test_row_streams_draw_what_gymnasium_generators_draw() -> None:
    """The array-held PCG64 streams of the vector env are Gymnasium's ``np_random`` bit for
    bit, whichever rows are drawn and in which order."""
    from gymnasium.utils import seeding

    from shipgym.envs.streams import RowStreams

    seeds = [0, 1, 7, 2**40 + 3, 123_456_789]
    streams = RowStreams(len(seeds), seeds)
    generators = [seeding.np_random(s)[0] for s in seeds]
    rng = np.random.default_rng(0)
    for _ in range(20):
        rows = rng.choice(len(seeds), size=rng.integers(1, 6), replace=False)
        size = int(rng.integers(1, 9))
        drawn = streams.random(rows, size)
        for k, i in enumerate(rows):
            assert np.array_equal(drawn[k], generators[i].random(size))
    assert np.array_equal(streams.generator(3).random(4), generators[3].random(4))
    with pytest.raises(ValueError, match="seed list must have 5 entries"):
        streams.seed([1, 2])

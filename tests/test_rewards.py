"""Every env's reward at hand-set states against the formula its docstring documents.

Each test puts an env at a state set through ``reset(options=...)`` (``initial_state``, the
current, setpoints, waypoints or the target), takes known actions, and recomputes the reward
from the documented formula with this file's own arithmetic: the heading error from the state
after the step and the setpoint, the speed through the water from the state and the current,
the cross-track error and the progress along the leg from the waypoints, the distance from
the target moved on at its velocity. Nothing of the env's own observation or kernel is used.
Actions outside [-1, 1] are clipped before they enter the reward (every docstring says so).
The vector envs are checked the same way, row by row, with a different action per row.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import shipgym  # noqa: F401  (registers the environments)
from shipgym.envs import ENV_IDS, env_task
from shipgym.models.rvg import SERVICE_SPEED

# the -v0 ids are out of date by design (the -v1 ids are newer): their rewards are checked too
pytestmark = pytest.mark.filterwarnings("ignore:.*is out of date:DeprecationWarning")

#: The actions of every case: inside the box, at its edge and beyond it (clipped to +-1).
ACTIONS_1D = (0.0, 0.6, -1.0, 1.7)
#: Two-input actions (azimuth, thrust).
ACTIONS_2D = ((0.0, 0.0), (0.3, -0.4), (-1.0, 1.0), (2.5, -3.0))
#: The cases of a vector env: one action per row.
N_ROWS = 4

#: RVG state at rest on a northerly heading, pods at 20 kN and 0.1 rad azimuth.
RVG_STATE = {
    "x": 10.0, "y": -20.0, "psi": 0.1, "u": 4.0, "v": 0.3, "r": 0.01,
    "T1": 20_000.0, "T2": 20_000.0, "alpha1": 0.1, "alpha2": 0.1,
}  # fmt: skip
CURRENT = {"current_speed": 0.4, "current_direction": 2.0}


def _wrap(angle: float) -> float:
    """The angle in [-pi, pi]."""
    return math.remainder(angle, 2.0 * math.pi)


def _cost(action: Any) -> float:
    """``|a|^2`` of the clipped action."""
    a = np.clip(np.atleast_1d(np.asarray(action, dtype=np.float64)), -1.0, 1.0)
    return float(a @ a)


def _state(
    info: dict[str, Any], names: tuple[str, ...], row: int | None = None
) -> dict[str, float]:
    values = info["state"] if row is None else info["state"][row]
    return dict(zip(names, (float(v) for v in values), strict=True))


# ---- the documented formulas ---------------------------------------------------------------
def heading_reward(s: dict[str, float], setpoint: float, action: Any) -> float:
    """``-|psi_d - psi| / pi - 0.05 a^2`` (``NomotoHeading``, ``RVGHeading``)."""
    return -abs(_wrap(setpoint - s["psi"])) / math.pi - 0.05 * _cost(action)


def speed_reward(
    s: dict[str, float], setpoint: float, current: dict[str, float], bollard: float
) -> float:
    """``-|u_d - u_r| / 2 - 0.05 (T / T_bollard)^2`` with ``u_r`` the surge speed through the
    water (the surge velocity less the current's component along the heading): the cost is
    the thrust the pods give, not the command."""
    speed, toward = current["current_speed"], current["current_direction"]
    u_r = s["u"] - speed * math.cos(toward - s["psi"])
    error = min(max(setpoint - u_r, -25.0), 25.0)
    fraction = min(max(s["T1"] / bollard, 0.0), 1.0)
    return -abs(error) / 2.0 - 0.05 * fraction**2


def _leg(waypoints: np.ndarray, k: int) -> tuple[np.ndarray, float, float]:
    start, end = waypoints[k], waypoints[k + 1]
    d = end - start
    return start, math.atan2(d[1], d[0]), float(np.hypot(*d))


def path_terms(s: dict[str, float], waypoints: np.ndarray, k: int) -> tuple[float, float, float]:
    """Cross-track error (positive right of the path), along-track distance left on leg ``k``
    and the course error ``ssa(chi_p - psi)``."""
    start, chi, length = _leg(waypoints, k)
    dn, de = s["x"] - start[0], s["y"] - start[1]
    e = -dn * math.sin(chi) + de * math.cos(chi)
    left = length - (dn * math.cos(chi) + de * math.sin(chi))
    return e, left, _wrap(chi - s["psi"])


def path_reward(
    before: dict[str, float], after: dict[str, float], waypoints: np.ndarray, dt: float,
    action: Any,
) -> float:  # fmt: skip
    """``0.5 clip(progress / (5.14 m/s dt), -1, 1) + 0.5 exp(-(e / 25 m)^2)
    - 0.1 |chi_p - psi| / pi - 0.05 |a|^2`` on the first leg (no bonus)."""
    _, left_before, _ = path_terms(before, waypoints, 0)
    e, left, chi_err = path_terms(after, waypoints, 0)
    progress = left_before - left
    return (
        0.5 * min(max(progress / (SERVICE_SPEED * dt), -1.0), 1.0)
        + 0.5 * math.exp(-((e / 25.0) ** 2))
        - 0.1 * abs(chi_err) / math.pi
        - 0.05 * _cost(action)
    )


def target_reward(s: dict[str, float], target: np.ndarray, distance: float, action: Any) -> float:
    """``1 - min(|d - d_set| / 100 m, 2) - 0.05 |a|^2``, -20 beyond ``max_distance`` (3 km)."""
    d = float(np.hypot(target[0] - s["x"], target[1] - s["y"]))
    reward = 1.0 - min(abs(d - distance) / 100.0, 2.0) - 0.05 * _cost(action)
    return reward - 20.0 if d > 3000.0 else reward


# ---- the cases of each task ----------------------------------------------------------------
HEADING_SETPOINT = 1.2
SPEED_SETPOINT = 6.0
#: Two legs: north 400 m, then east; the ship starts 12 m right of the first leg.
WAYPOINTS = np.array([[0.0, 0.0], [400.0, 0.0], [400.0, 400.0]])
TARGET_POSITION = np.array([300.0, 150.0])
TARGET_VELOCITY = np.array([1.5, -2.0])
TARGET_DISTANCE = 80.0


def _options(task: str) -> dict[str, Any]:
    if task == "NomotoHeading":
        state = {"x": 0.0, "y": 0.0, "psi": -0.4, "U": 7.7, "r": 0.004, "delta": 0.1}
        return {"initial_state": state, "setpoints": [HEADING_SETPOINT], **CURRENT}
    if task == "RVGHeading":
        return {"initial_state": RVG_STATE, "setpoints": [HEADING_SETPOINT], **CURRENT}
    if task == "RVGSpeed":
        return {"initial_state": RVG_STATE, "setpoints": [SPEED_SETPOINT], **CURRENT}
    if task == "RVGPathFollowing":
        state = {**RVG_STATE, "x": 30.0, "y": 12.0, "psi": 0.2}
        return {"initial_state": state, "waypoints": WAYPOINTS, **CURRENT}
    state = {**RVG_STATE, "psi": 0.4}
    return {
        "initial_state": state,
        "target_position": TARGET_POSITION,
        "target_velocity": TARGET_VELOCITY,
        "distance": TARGET_DISTANCE,
        **CURRENT,
    }


def _expected(
    task: str, env: Any, before: dict[str, float], after: dict[str, float], steps: int,
    action: Any,
) -> float:  # fmt: skip
    """The documented reward of the ``steps``-th step, which left the ship at ``after``."""
    if task in ("NomotoHeading", "RVGHeading"):
        return heading_reward(after, HEADING_SETPOINT, action)
    if task == "RVGSpeed":
        bollard = env.task.params.bollard_thrust
        return speed_reward(after, SPEED_SETPOINT, CURRENT, bollard)
    if task == "RVGPathFollowing":
        return path_reward(before, after, WAYPOINTS, env.task.dt, action)
    target = TARGET_POSITION + TARGET_VELOCITY * env.task.dt * steps
    return target_reward(after, target, TARGET_DISTANCE, action)


def _actions(env: Any) -> tuple[Any, ...]:
    return ACTIONS_1D if env.task.act_dim == 1 else ACTIONS_2D


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_reward_is_the_documented_formula(env_id: str) -> None:
    """Three steps of each action from the hand-set state: every reward is the formula's."""
    task = env_task(env_id)
    env = gym.make(env_id).unwrapped
    names = env.state_names
    for value in _actions(env):
        action = np.atleast_1d(np.asarray(value, dtype=np.float32))  # what the agent sends
        _, info = env.reset(seed=0, options=_options(task))
        before = _state(info, names)
        for step in range(1, 4):
            _, reward, terminated, _, info = env.step(action)
            after = _state(info, names)
            assert not terminated
            expected = _expected(task, env, before, after, step, action)
            assert reward == pytest.approx(expected, rel=1e-9, abs=1e-12), (action, step)
            before = after


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_reward_of_each_row_is_the_documented_formula(env_id: str) -> None:
    """The NumPy-batched env: the reward of row ``i`` is the formula at row ``i``'s state and
    action (each row a different action)."""
    task = env_task(env_id)
    venv = gym.make_vec(env_id, num_envs=N_ROWS, vectorization_mode="vector_entry_point")
    env = venv.unwrapped
    names = env.task.model.state_names
    actions = np.array(_actions(env)[:N_ROWS], dtype=np.float32).reshape(N_ROWS, -1)
    _, info = venv.reset(seed=0, options=_options(task))
    before = [_state(info, names, i) for i in range(N_ROWS)]
    for step in range(1, 4):
        _, rewards, terminated, _, info = venv.step(actions)
        assert not terminated.any()
        for i in range(N_ROWS):
            after = _state(info, names, i)
            expected = _expected(task, env, before[i], after, step, actions[i])
            assert rewards[i] == pytest.approx(expected, rel=1e-9, abs=1e-12), (i, step)
            before[i] = after
    venv.close()


def test_heading_reward_values_at_known_errors() -> None:
    """Closed form at the reset state: with no time to turn, one step of the Nomoto ship
    leaves the heading error close to the one set; the reward is that error over pi plus the
    action's cost, 0 on heading with the rudder amidships."""
    env = gym.make("shipgym/NomotoHeading-v0").unwrapped
    state = {"x": 0.0, "y": 0.0, "psi": 0.0, "U": 7.7, "r": 0.0, "delta": 0.0}
    env.reset(options={"initial_state": state, "setpoints": [0.0], "current_speed": 0.0})
    _, reward, *_ = env.step(np.zeros(1, dtype=np.float32))
    assert reward == 0.0  # on heading, rudder amidships, no current: nothing moves it
    env.reset(options={"initial_state": state, "setpoints": [math.pi / 2], "current_speed": 0.0})
    _, reward, _, _, info = env.step(np.array([1.0], dtype=np.float32))
    psi = _state(info, env.state_names)["psi"]
    assert abs(psi) < 0.01  # one second of a rudder still on its way
    assert reward == pytest.approx(-(math.pi / 2 - psi) / math.pi - 0.05, rel=1e-12)
    assert reward == pytest.approx(-0.55, abs=0.01 / math.pi)


def test_path_reward_pays_the_bonus_at_the_last_waypoint_and_the_penalty_off_the_path() -> None:
    """+20 with the step that reaches the last waypoint, -20 with the one that leaves the path
    beyond ``max_cross_track``; both end the episode."""
    env = gym.make("shipgym/RVGPathFollowing-v1").unwrapped
    names = env.state_names
    legs = np.array([[0.0, 0.0], [400.0, 0.0]])
    action = np.array([0.2, 0.5], dtype=np.float32)
    for start, bonus, completed in (((380.0, 5.0), 20.0, True), ((100.0, 260.0), -20.0, False)):
        state = {**RVG_STATE, "x": start[0], "y": start[1], "psi": 0.0}
        _, info = env.reset(options={"initial_state": state, "waypoints": legs, **CURRENT})
        before = _state(info, names)
        _, reward, terminated, _, info = env.step(action)
        after = _state(info, names)
        assert terminated and info["completed"] is completed
        expected = path_reward(before, after, legs, env.dt, action) + bonus
        assert reward == pytest.approx(expected, rel=1e-9)


def test_target_reward_penalises_a_target_beyond_max_distance() -> None:
    env = gym.make("shipgym/RVGTargetTracking-v1").unwrapped
    names = env.state_names
    far = np.array([3100.0, 0.0])
    options = {"initial_state": RVG_STATE, "target_position": far, "target_velocity": [0, 0]}
    env.reset(options={**options, **CURRENT})
    action = np.array([0.1, 0.2], dtype=np.float32)
    _, reward, terminated, _, info = env.step(action)
    assert terminated and info["termination_reason"] == "failure"
    expected = target_reward(_state(info, names), far, 50.0, action)
    assert expected < -20.0
    assert reward == pytest.approx(expected, rel=1e-9)

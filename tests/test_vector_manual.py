"""The native vector env in Gymnasium's manual mode, and the vector robustness wrappers.

``autoreset_mode=AutoresetMode.DISABLED`` with ``reset(options={"reset_mask": mask})`` must give
what ``SyncVectorEnv`` of single envs gives in that mode (observations, rewards, flags and
``info``, bitwise) over a loop that resets the finished sub-envs by hand: truncations,
numerical blow-ups, task failures and completed paths, with int, list and no seeds. Beyond
``SyncVectorEnv``, a finished sub-env that is not reset is parked: it does not advance and the
others step as if it were not there. ``reset_mask`` works in the other modes too.

:class:`~shipgym.envs.wrappers.VectorSensorNoise` and
:class:`~shipgym.envs.wrappers.VectorActuatorDelay` must equal ``SyncVectorEnv`` of single envs
wrapped in :class:`~shipgym.envs.wrappers.SensorNoise` and
:class:`~shipgym.envs.wrappers.ActuatorDelay`, bitwise, with the same per-episode seeding.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, VectorEnv
from test_vector_info import (  # the SyncVectorEnv comparison of the other two modes
    BLOW_UPS,
    FAILING,
    NUM_ENVS,
    _equal,
    assert_same_info,
    blow_up,
    make_pair,
)

import shipgym
from shipgym.envs.wrappers import (
    ActuatorDelay,
    SensorNoise,
    VectorActuatorDelay,
    VectorSensorNoise,
    noise_generator,
)

pytestmark = pytest.mark.filterwarnings("ignore:.*is out of date:DeprecationWarning")

DISABLED = AutoresetMode.DISABLED
LIMIT = 6
N_STEPS = 3 * LIMIT + 4
HEADING = "shipgym/RVGHeading-v1"
PATH = "shipgym/RVGPathFollowing-v1"
#: A short path that the ships complete at different steps (``success`` terminations).
SHORT_PATH = {"waypoints": [[0.0, 0.0], [150.0, 0.0]], "current_speed": 0.0}


def reseed(t: int) -> int | list[int | None] | None:
    """The seed of the manual reset after step ``t``: an int, a list (with a None) or none."""
    return (100 + t, [200 + t, None, 202 + t, 203 + t], None)[t % 3]


def make_native(
    env_id: str,
    mode: AutoresetMode = DISABLED,
    limit: int = LIMIT,
    num_envs: int = NUM_ENVS,
    **kwargs: Any,
) -> VectorEnv:
    return gym.make_vec(
        env_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        autoreset_mode=mode,
        max_episode_steps=limit,
        **kwargs,
    )


def make_wrapped_pair(
    env_id: str,
    mode: AutoresetMode,
    vector_wrapper: Callable[[VectorEnv], VectorEnv],
    wrapper: Callable[[gym.Env], gym.Env],
    limit: int = LIMIT,
) -> tuple[VectorEnv, VectorEnv]:
    """A wrapped native vector env and ``SyncVectorEnv`` of wrapped single envs."""
    native = vector_wrapper(make_native(env_id, mode, limit))
    sync = gym.make_vec(
        env_id,
        num_envs=NUM_ENVS,
        vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": mode},
        wrappers=[wrapper],
        max_episode_steps=limit,
    )
    return native, sync


def step_both(
    native: VectorEnv, sync: VectorEnv, t: int, act: Callable[[np.ndarray], np.ndarray] = np.copy
) -> tuple:
    """Step both envs with one sampled action (through ``act``); compare everything; return
    the sync env's result."""
    action = act(native.action_space.sample())
    out_n, out_s = native.step(action), sync.step(action)
    for k, name in enumerate(("obs", "reward", "terminated", "truncated")):
        assert np.array_equal(out_n[k], out_s[k]), f"step {t}: {name}"
    assert_same_info(out_n[4], out_s[4], f"step {t}")
    return out_s


def compare_manual(
    native: VectorEnv,
    sync: VectorEnv,
    seed: int,
    options: dict[str, Any] | None = None,
    blow_ups: Sequence[tuple[int, int]] = BLOW_UPS,
    n_steps: int = N_STEPS,
    act: Callable[[np.ndarray], np.ndarray] = np.copy,
) -> dict[str, int]:
    """Step both envs in manual mode, resetting the finished sub-envs with ``reset_mask``
    after every step; compare everything and count the episode ends by reason."""
    obs_n, info_n = native.reset(seed=seed, options=options)
    obs_s, info_s = sync.reset(seed=seed, options=options)
    assert np.array_equal(obs_n, obs_s)
    assert_same_info(info_n, info_s, "reset")
    native.action_space.seed(seed)
    ups = dict(blow_ups)
    ends: dict[str, int] = {"truncated": 0}
    for t in range(n_steps):
        if t in ups:
            blow_up(native, sync, ups[t])
        out_s = step_both(native, sync, t, act)
        terminated, truncated = out_s[2], out_s[3]
        for i in np.flatnonzero(terminated):
            reason = out_s[4]["termination_reason"][i]
            ends[reason] = ends.get(reason, 0) + 1
        ends["truncated"] += int(truncated.sum())
        done = terminated | truncated
        if done.any():  # (each env takes its own dict: SyncVectorEnv pops reset_mask)
            where = f"reset after step {t}"
            seed_t = reseed(t)
            obs_n, info_n = native.reset(
                seed=seed_t, options={**(options or {}), "reset_mask": done}
            )
            obs_s, info_s = sync.reset(
                seed=seed_t, options={**(options or {}), "reset_mask": done.copy()}
            )
            assert np.array_equal(obs_n, obs_s), where
            assert_same_info(info_n, info_s, where)
            assert info_n["_state"].tolist() == done.tolist()  # only the reset sub-envs
    return ends


# --------------------------------------------------------------------------------------------
# the manual mode against SyncVectorEnv
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("mode", [AutoresetMode.DISABLED, "Disabled"])
def test_disabled_mode_is_accepted(mode: Any) -> None:
    venv = make_native(HEADING, mode)
    assert venv.unwrapped.autoreset_mode is DISABLED
    assert venv.metadata["autoreset_mode"] is DISABLED


def test_bad_mode_error_lists_every_mode() -> None:
    with pytest.raises(ValueError, match=r"\['NextStep', 'SameStep', 'Disabled'\], got 'Manual'"):
        make_native(HEADING, "Manual")


@pytest.mark.parametrize("env_id", shipgym.ENV_IDS)
def test_manual_mode_matches_sync_vector_env(env_id: str) -> None:
    native, sync = make_pair(env_id, DISABLED)
    ends = compare_manual(native, sync, seed=11)
    assert ends["numerical_blow_up"] >= len(BLOW_UPS) and ends["truncated"] > NUM_ENVS


@pytest.mark.parametrize("env_id", sorted(FAILING))
def test_manual_mode_matches_sync_vector_env_after_task_failures(env_id: str) -> None:
    native, sync = make_pair(env_id, DISABLED, limit=12, **FAILING[env_id])
    ends = compare_manual(native, sync, seed=3, blow_ups=(), n_steps=40)
    assert ends["failure"] >= 2


def test_manual_mode_matches_sync_vector_env_on_completed_paths() -> None:
    """Ships that reach the end of a short path at different steps, reset with its options."""

    def ahead(a: np.ndarray) -> np.ndarray:
        a[:, 1] = np.abs(a[:, 1])  # thrust at least half
        return a

    native, sync = make_pair(PATH, DISABLED, limit=60)
    ends = compare_manual(native, sync, 1, SHORT_PATH, blow_ups=(), n_steps=80, act=ahead)
    assert ends["success"] >= 5


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_reset_mask_in_the_autoreset_modes_matches_sync_vector_env(mode: AutoresetMode) -> None:
    """A masked reset in the middle of episodes, also of a sub-env about to be autoreset."""
    native, sync = make_pair(HEADING, mode)
    for venv in (native, sync):
        venv.reset(seed=4)
    native.action_space.seed(4)
    for t in range(N_STEPS):
        step_both(native, sync, t)
        if t % 4 == 1:
            mask = np.arange(NUM_ENVS) % 2 == (t // 4) % 2
            options = {"current_speed": 0.2}
            res_n = native.reset(seed=t, options={**options, "reset_mask": mask})
            res_s = sync.reset(seed=t, options={**options, "reset_mask": mask.copy()})
            assert np.array_equal(res_n[0], res_s[0])
            assert_same_info(res_n[1], res_s[1], f"reset after step {t}")


@pytest.mark.parametrize(
    "mask",
    [
        [True, False, True, False],  # a list
        np.array([1, 0, 1, 0]),  # not bool
        np.ones(NUM_ENVS + 1, dtype=bool),  # the wrong shape
        np.zeros(NUM_ENVS, dtype=bool),  # no sub-env
    ],
)
def test_bad_reset_mask_raises_and_changes_nothing(mask: Any) -> None:
    venv, twin = make_native(HEADING), make_native(HEADING)
    actions = np.full((NUM_ENVS, 1), 0.4)
    for env in (venv, twin):
        env.reset(seed=2)
        env.step(actions)
    with pytest.raises(
        ValueError, match=r"reset_mask'\] must be a numpy bool array of shape \(4,\)"
    ):
        venv.reset(seed=9, options={"reset_mask": mask, "current_speed": 0.1})
    for _ in range(LIMIT + 1):  # the same episodes, ended and parked at the same step
        out, out_twin = venv.step(actions), twin.step(actions)
        for a, b in zip(out[:4], out_twin[:4], strict=True):
            assert np.array_equal(a, b)
    assert out[4]["_state"].tolist() == [False] * NUM_ENVS  # all parked


def test_reset_mask_before_the_first_reset_needs_a_full_reset() -> None:
    venv = make_native(HEADING)
    with pytest.raises(gym.error.ResetNeeded, match="reset_mask"):
        venv.reset(options={"reset_mask": np.array([True, False, False, False])})
    _, info = venv.reset(seed=0, options={"reset_mask": np.ones(NUM_ENVS, dtype=bool)})
    assert info["_state"].all()


# --------------------------------------------------------------------------------------------
# parked sub-envs
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("num_threads", [1, None])
@pytest.mark.parametrize("env_id", shipgym.CURRENT_ENV_IDS)
def test_finished_sub_envs_are_parked_and_the_others_step_on(
    env_id: str, num_threads: int | None
) -> None:
    """Sub-envs that end (blow-ups at different steps, then truncation) and are not reset
    stay as they ended, whatever their action (NaN too); the others step on exactly as single
    envs; a parked sub-env reset by mask then runs as a single env reset with its seed."""
    n, seed, limit = 70, 8, 12  # (70 >= the batch size from which threads split the rows)
    venv = make_native(env_id, limit=limit, num_envs=n, num_threads=num_threads)
    space = venv.action_space
    space.seed(seed)
    actions = [space.sample() for _ in range(limit + 2)]
    obs, _ = venv.reset(seed=seed)
    blow_at = {2: [1, 5], 6: [2, 40, 69]}
    end_of = {i: t for t, rows in blow_at.items() for i in rows}
    results = []
    for t, a in enumerate(actions):
        for i in blow_at.get(t, []):
            venv.unwrapped.task.x[i, 3] = np.nan
        a = a.copy()
        a[venv.unwrapped.ended] = np.nan  # ignored for parked sub-envs
        results.append(venv.step(a))
    for i in range(n):
        env = gym.make(env_id, max_episode_steps=limit)
        env.reset(seed=seed + i)
        ended_at = None
        for t, (a, (obs_v, rew_v, term_v, trunc_v, info_v)) in enumerate(
            zip(actions, results, strict=True)
        ):
            if ended_at is None:
                if i in blow_at.get(t, []):
                    env.unwrapped.task.x[0, 3] = np.nan
                obs, rew, term, trunc, info = env.step(a[i])
                assert np.array_equal(obs, obs_v[i]) and rew == rew_v[i], (i, t)
                assert (term, trunc) == (term_v[i], trunc_v[i]), (i, t)
                assert info_v["_state"][i] and _equal(info_v["state"][i], info["state"])
                if term or trunc:
                    ended_at, last = t, obs
            else:  # parked: as it ended
                assert np.array_equal(obs_v[i], last), (i, t)
                assert rew_v[i] == 0.0 and not term_v[i] and not trunc_v[i], (i, t)
                assert not info_v["_state"][i] and not np.any(info_v["state"][i])
                assert info_v["termination_reason"][i] is None
        assert ended_at == end_of.get(i, limit - 1), i
    # every sub-env is parked: a step changes nothing
    task = venv.unwrapped.task
    x, steps = task.x.copy(), task.steps.copy()
    obs, rew, term, trunc, info = venv.step(np.full(space.shape, np.nan))
    assert np.array_equal(task.x, x, equal_nan=True) and np.array_equal(task.steps, steps)
    assert not rew.any() and not term.any() and not trunc.any() and not info["_state"].any()
    assert np.array_equal(obs, results[-1][0])
    # a parked sub-env reset by mask starts anew as a single env with its seed
    mask = np.zeros(n, dtype=bool)
    mask[[0, 40]] = True
    obs, info = venv.reset(seed=[50 + i for i in range(n)], options={"reset_mask": mask})
    assert np.array_equal(obs[~mask], results[-1][0][~mask])  # the others keep theirs
    a = space.sample()
    obs_v, rew_v, term_v, _, _ = venv.step(a)
    for i in (0, 40):
        env = gym.make(env_id, max_episode_steps=limit)
        assert np.array_equal(env.reset(seed=50 + i)[0], obs[i])
        obs_s, rew_s, *_ = env.step(a[i])
        assert np.array_equal(obs_s, obs_v[i]) and rew_s == rew_v[i]
    assert not rew_v[~mask].any() and not term_v.any()


def test_a_live_bad_action_is_refused_and_steps_no_sub_env() -> None:
    venv = make_native(HEADING)
    venv.reset(seed=0)
    venv.unwrapped.task.x[1, 3] = np.nan
    venv.step(np.zeros((NUM_ENVS, 1)))  # sub-env 1 ends and is parked
    task = venv.unwrapped.task
    x = task.x.copy()
    with pytest.raises(ValueError, match="sub-env 2's action holds NaN"):
        venv.step(np.array([[0.0], [np.nan], [np.nan], [0.0]]))
    assert np.array_equal(task.x, x, equal_nan=True)


def test_task_steps_a_subset_of_rows_bitwise_as_all_rows() -> None:
    venv, twin = make_native(PATH, num_envs=6), make_native(PATH, num_envs=6)
    for env in (venv, twin):
        env.reset(seed=3)
    task, full = venv.unwrapped.task, twin.unwrapped.task
    rows = np.array([0, 2, 5])
    for a in np.linspace(-1.0, 1.0, 12).reshape(6, 2)[None].repeat(5, axis=0):
        before = task.x.copy()
        task.a[:] = full.a[:] = a
        assert task.step(rows) == -1 and full.step() == -1
        for name in ("x", "obs", "rew", "term", "steps", "seg"):
            assert np.array_equal(getattr(task, name)[rows], getattr(full, name)[rows]), name
        assert np.array_equal(np.delete(task.x, rows, axis=0), np.delete(before, rows, axis=0))
    with pytest.raises(ValueError, match=r"rows must be a vector of row indices in \[0, 6\)"):
        task.step(np.array([0, 6]))


# --------------------------------------------------------------------------------------------
# vector wrappers
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", shipgym.CURRENT_ENV_IDS)
def test_vector_sensor_noise_matches_sync_vector_env_in_manual_mode(env_id: str) -> None:
    """Observations and ``info["measured_state"]`` (every info key) bitwise, through manual
    resets with int, list and no seeds: row ``i`` reset with seed ``s`` draws the noise of
    ``noise_generator(s)``, one without a seed from its random stream as the single env."""
    native, sync = make_wrapped_pair(env_id, DISABLED, VectorSensorNoise, SensorNoise)
    ends = compare_manual(native, sync, seed=21)
    assert ends["truncated"] > NUM_ENVS


def test_vector_sensor_noise_matches_sync_vector_env_with_autoresets() -> None:
    """The default (next-step) mode, over several episodes of every sub-env."""
    native, sync = make_wrapped_pair(HEADING, AutoresetMode.NEXT_STEP, VectorSensorNoise,
                                     SensorNoise)  # fmt: skip
    for venv in (native, sync):
        venv.reset(seed=6)
    native.action_space.seed(6)
    truncations = 0
    for t in range(3 * LIMIT + 2):
        out_s = step_both(native, sync, t)
        truncations += int(out_s[3].sum())
    assert truncations == 3 * NUM_ENVS


def test_vector_sensor_noise_rows_draw_their_own_episode_noise() -> None:
    """Row ``i`` reset with seed ``s + i`` measures with ``noise_generator(s + i)``: its noise
    is ``measured - true`` of that generator's standard normals times the levels."""
    venv = VectorSensorNoise(make_native(HEADING))
    _, info = venv.reset(seed=30)
    names = venv.unwrapped.task.model.state_names
    psi = names.index("psi")
    for i in range(NUM_ENVS):
        first = noise_generator(30 + i).standard_normal(1)[0]  # heading: the first channel
        error = info["measured_state"][i, psi] - info["state"][i, psi]
        assert error == pytest.approx(venv.std["heading"] * first, rel=1e-9)


def test_parked_rows_draw_no_noise_and_leave_the_others_alone() -> None:
    """Each row has its own generator: a row that ends and is parked (or not) changes no
    other row's noise; a parked row keeps its last noisy observation and is unflagged."""
    runs = []
    for blow in (False, True):
        venv = VectorSensorNoise(make_native(HEADING, limit=40))
        venv.reset(seed=12)
        steps = []
        for t in range(10):
            if blow and t == 3:
                venv.unwrapped.task.x[1, 3] = np.nan
            steps.append(venv.step(np.full((NUM_ENVS, 1), 0.2)))
        runs.append(steps)
    live = [0, 2, 3]
    for t, (quiet, parked) in enumerate(zip(*runs, strict=True)):
        assert np.array_equal(quiet[0][live], parked[0][live]), t
        assert np.array_equal(quiet[4]["measured_state"][live], parked[4]["measured_state"][live])
        if t > 3:  # parked since step 3
            assert np.array_equal(parked[0][1], runs[1][3][0][1])
            assert not parked[4]["_measured_state"][1] and not parked[4]["measured_state"][1].any()


@pytest.mark.parametrize("mode", [AutoresetMode.DISABLED, AutoresetMode.NEXT_STEP,
                                  AutoresetMode.SAME_STEP], ids=lambda m: m.value)  # fmt: skip
@pytest.mark.parametrize("env_id", [HEADING, PATH])
def test_vector_actuator_delay_matches_sync_vector_env(env_id: str, mode: AutoresetMode) -> None:
    native, sync = make_wrapped_pair(
        env_id,
        mode,
        lambda env: VectorActuatorDelay(env, delay=1.0),
        lambda env: ActuatorDelay(env, delay=1.0),
    )
    assert native.steps == 2 and native.delay == 1.0
    if mode is DISABLED:
        compare_manual(native, sync, seed=13)
        return
    for venv in (native, sync):
        venv.reset(seed=13)
    native.action_space.seed(13)
    for t in range(N_STEPS):
        step_both(native, sync, t)


def test_vector_actuator_delay_checks_live_actions_only() -> None:
    venv = VectorActuatorDelay(make_native(HEADING), delay=1.0)
    venv.reset(seed=0)
    venv.unwrapped.task.x[3, 3] = np.nan
    venv.step(np.zeros((NUM_ENVS, 1)))  # sub-env 3 ends and is parked
    venv.step(np.array([[0.1], [0.2], [0.3], [np.nan]]))  # its NaN is ignored
    with pytest.raises(ValueError, match="sub-env 1's action must be 1 finite values"):
        venv.step(np.array([[0.1], [np.inf], [0.3], [0.0]]))
    with pytest.raises(ValueError, match=r"actions must have shape \(4, 1\)"):
        venv.step(np.zeros((NUM_ENVS, 2)))
    assert VectorActuatorDelay(make_native(HEADING), delay=0.0).steps == 0


def test_vector_wrappers_refuse_what_they_cannot_wrap() -> None:
    with pytest.raises(ValueError, match="'SameStep'"):
        VectorSensorNoise(make_native(HEADING, AutoresetMode.SAME_STEP))
    sync = gym.make_vec(HEADING, num_envs=2, vectorization_mode="sync")
    for wrap in (VectorSensorNoise, lambda env: VectorActuatorDelay(env, 1.0)):
        with pytest.raises(ValueError, match="wraps a shipgym vector env"):
            wrap(sync)
    with pytest.raises(ValueError, match="unknown noise channel"):
        VectorSensorNoise(make_native(HEADING), gps=1.0)

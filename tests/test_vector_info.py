"""The native vector env's ``info`` and ``reset(options=...)`` against Gymnasium's SyncVectorEnv.

``gymnasium.make_vec(id, vectorization_mode="vector_entry_point")`` must return, at reset and at
every step, the ``info`` that ``vectorization_mode="sync"`` (a ``SyncVectorEnv`` of single envs)
returns for the same seed and actions: the same keys, the same ``_key`` masks, the same dtypes
and the same (bit-identical) values, in both autoreset modes and across episode boundaries
(truncations, numerical blow-ups and task failures in different sub-envs at different steps),
including ``final_obs`` and ``final_info`` of same-step autoreset. Also the reset options an
autoreset uses: forgotten by default as in ``SyncVectorEnv``, kept with ``keep_options=True``.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, VectorEnv

import shipgym

#: The -v0 ids are compared too; their "out of date" notice is expected.
pytestmark = pytest.mark.filterwarnings("ignore:.*is out of date:DeprecationWarning")

MODES = (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP)
NUM_ENVS = 4
LIMIT = 6  # short episodes: several truncations per rollout
N_STEPS = 3 * LIMIT + 4
#: (step, sub-env) where a state entry is set to NaN: a numerical blow-up terminates that
#: sub-env in the middle of its episode, so sub-envs end at different steps.
BLOW_UPS = ((2, 1), (9, 2), (13, 1))

#: Env keyword arguments that make a task fail early for some sub-envs (a ``failure`` reason).
FAILING = {
    "shipgym/RVGPathFollowing-v1": {"max_cross_track": 20.0},
    "shipgym/RVGTargetTracking-v1": {"max_distance": 700.0},
}


def make_native(env_id: str, mode: AutoresetMode, limit: int = LIMIT, **kwargs: Any) -> VectorEnv:
    return gym.make_vec(
        env_id,
        num_envs=NUM_ENVS,
        vectorization_mode="vector_entry_point",
        autoreset_mode=mode,
        max_episode_steps=limit,
        **kwargs,
    )


def make_pair(
    env_id: str, mode: AutoresetMode, limit: int = LIMIT, **kwargs: Any
) -> tuple[VectorEnv, VectorEnv]:
    native = make_native(env_id, mode, limit, **kwargs)
    sync = gym.make_vec(
        env_id,
        num_envs=NUM_ENVS,
        vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": mode},
        max_episode_steps=limit,
        **kwargs,
    )
    return native, sync


def _equal(a: Any, b: Any) -> bool:
    """Bit-identical arrays or scalars (NaN equal to NaN: a blown-up state)."""
    a, b = np.asarray(a), np.asarray(b)
    return np.array_equal(a, b, equal_nan=a.dtype.kind in "fc" and b.dtype.kind in "fc")


def _same_value(a: Any, b: Any) -> bool:
    if isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and a.dtype == b.dtype and _equal(a, b)
    return type(a) is type(b) and a == b


def assert_same_info(native: dict[str, Any], sync: dict[str, Any], where: str) -> None:
    """Keys, masks, dtypes and values of two vector ``info`` dicts are the same."""
    assert sorted(native) == sorted(sync), f"{where}: keys differ"
    for key, expected in sync.items():
        got = native[key]
        at = f"{where}[{key!r}]"
        if isinstance(expected, dict):
            assert isinstance(got, dict), at
            assert_same_info(got, expected, at)
            continue
        assert isinstance(got, np.ndarray), f"{at}: {type(got).__name__}, not an array"
        assert got.dtype == expected.dtype, f"{at}: dtype {got.dtype} != {expected.dtype}"
        assert got.shape == expected.shape, f"{at}: shape {got.shape} != {expected.shape}"
        if key.startswith("_"):
            assert np.array_equal(got, expected), f"{at}: mask {got} != {expected}"
            continue
        mask = sync[f"_{key}"]
        for i in range(NUM_ENVS):
            if not mask[i]:  # Gymnasium leaves an entry without its flag at zero (None)
                blank = got[i] is None if got.dtype == object else not np.any(got[i])
                assert blank, f"{at}: sub-env {i} has no flag but holds {got[i]!r}"
            elif got.dtype == object:
                assert _same_value(got[i], expected[i]), f"{at}: sub-env {i}"
            else:
                assert _equal(got[i], expected[i]), (
                    f"{at}: sub-env {i}: {got[i]!r} != {expected[i]!r}"
                )


def blow_up(native: VectorEnv, sync: VectorEnv, i: int) -> None:
    native.unwrapped.task.x[i, 3] = np.nan
    sync.envs[i].unwrapped.task.x[0, 3] = np.nan


def compare_rollouts(
    native: VectorEnv, sync: VectorEnv, seed: int, options: dict[str, Any] | None = None
) -> dict[str, int]:
    """Step both envs with the same actions and compare everything; count the episode ends."""
    obs_n, info_n = native.reset(seed=seed, options=options)
    obs_s, info_s = sync.reset(seed=seed, options=options)
    assert np.array_equal(obs_n, obs_s)
    assert_same_info(info_n, info_s, "reset")
    native.action_space.seed(seed)
    blow_ups = dict(BLOW_UPS)
    ends = {"terminated": 0, "truncated": 0}
    for t in range(N_STEPS):
        if t in blow_ups:
            blow_up(native, sync, blow_ups[t])
        action = native.action_space.sample()
        out_n = native.step(action)
        out_s = sync.step(action)
        for k, name in enumerate(("obs", "reward", "terminated", "truncated")):
            assert np.array_equal(out_n[k], out_s[k]), f"step {t}: {name}"
        assert_same_info(out_n[4], out_s[4], f"step {t}")
        ends["terminated"] += int(out_s[2].sum())
        ends["truncated"] += int(out_s[3].sum())
    # a reset in the middle of episodes continues every sub-env's random stream
    assert_same_info(native.reset()[1], sync.reset()[1], "second reset")
    return ends


@pytest.mark.parametrize("mode", MODES, ids=lambda m: m.value)
@pytest.mark.parametrize("env_id", shipgym.ENV_IDS)
def test_vector_info_matches_sync_vector_env(env_id: str, mode: AutoresetMode) -> None:
    native, sync = make_pair(env_id, mode)
    ends = compare_rollouts(native, sync, seed=11)
    assert ends["terminated"] >= len(BLOW_UPS) and ends["truncated"] > NUM_ENVS


@pytest.mark.parametrize("mode", MODES, ids=lambda m: m.value)
@pytest.mark.parametrize("env_id", sorted(FAILING))
def test_vector_info_matches_sync_vector_env_after_task_failures(
    env_id: str, mode: AutoresetMode
) -> None:
    native, sync = make_pair(env_id, mode, limit=12, **FAILING[env_id])
    ends = compare_rollouts(native, sync, seed=3)
    assert ends["terminated"] > len(BLOW_UPS)  # failures besides the blow-ups


@pytest.mark.parametrize("mode", MODES, ids=lambda m: m.value)
def test_vector_info_matches_sync_vector_env_with_reset_options(mode: AutoresetMode) -> None:
    native, sync = make_pair("shipgym/RVGSpeed-v1", mode)
    compare_rollouts(native, sync, seed=5, options={"current_speed": 0.4, "setpoints": [3.0]})


def test_next_step_autoreset_info_describes_the_new_episode() -> None:
    native, _ = make_pair("shipgym/RVGPathFollowing-v1", AutoresetMode.NEXT_STEP)
    native.reset(seed=0)
    native.unwrapped.task.x[2, 3] = np.nan
    _, _, terminated, _, info = native.step(np.zeros((NUM_ENVS, 2)))
    assert terminated[2] and info["termination_reason"][2] == "numerical_blow_up"
    _, reward, terminated, _, info = native.step(np.zeros((NUM_ENVS, 2)))
    assert not terminated[2] and reward[2] == 0.0
    assert info["termination_reason"][2] == "running"
    assert np.all(np.isfinite(info["state"][2])) and info["segment"][2] == 0
    assert "final_info" not in info and "final_obs" not in info


def test_same_step_final_info_holds_the_finished_episode() -> None:
    native, _ = make_pair("shipgym/RVGHeading-v1", AutoresetMode.SAME_STEP)
    native.reset(seed=0)
    native.unwrapped.task.x[1, 3] = np.nan
    obs, _, terminated, truncated, info = native.step(np.zeros((NUM_ENVS, 1)))
    assert terminated.tolist() == [False, True, False, False] and not truncated.any()
    assert info["_final_obs"].tolist() == info["_final_info"].tolist() == terminated.tolist()
    final = info["final_info"]
    assert final["termination_reason"][1] == "numerical_blow_up"
    assert final["_termination_reason"].tolist() == terminated.tolist()
    assert not np.all(np.isfinite(final["state"][1]))  # the state that blew up
    assert info["termination_reason"][1] == "running"  # the new episode's first info
    assert np.all(np.isfinite(info["state"][1]))
    assert info["final_obs"][1].dtype == np.float32 and not np.array_equal(
        info["final_obs"][1], obs[1]
    )


# --------------------------------------------------------------------------------------------
# reset options and autoresets
# --------------------------------------------------------------------------------------------

OPTIONS = {"current_speed": 0.3, "current_direction": 1.0, "setpoints": [0.5, -0.5]}
ENV_ID = "shipgym/RVGHeading-v1"


def single_rollouts(
    actions: list[np.ndarray], mode: AutoresetMode, seed: int, autoreset_options: Any
) -> np.ndarray:
    """Observations ``(steps, NUM_ENVS, obs_dim)`` of single envs autoreset by hand."""
    out = []
    for i in range(NUM_ENVS):
        env = gym.make(ENV_ID, max_episode_steps=LIMIT)
        env.reset(seed=seed + i, options=OPTIONS)
        rows, done = [], False
        for a in actions:
            if done and mode is AutoresetMode.NEXT_STEP:
                obs, _ = env.reset(options=autoreset_options)
                done = False
            else:
                obs, _, term, trunc, _ = env.step(a[i])
                done = term or trunc
                if done and mode is AutoresetMode.SAME_STEP:
                    obs, _ = env.reset(options=autoreset_options)
                    done = False
            rows.append(obs)
        out.append(rows)
    return np.swapaxes(np.array(out), 0, 1)


@pytest.mark.parametrize("keep", [False, True])
@pytest.mark.parametrize("mode", MODES, ids=lambda m: m.value)
def test_autoresets_use_the_reset_options_only_with_keep_options(
    mode: AutoresetMode, keep: bool
) -> None:
    venv = gym.make_vec(
        ENV_ID,
        num_envs=NUM_ENVS,
        vectorization_mode="vector_entry_point",
        autoreset_mode=mode,
        max_episode_steps=LIMIT,
        keep_options=keep,
    )
    venv.reset(seed=9, options=OPTIONS)
    venv.action_space.seed(9)
    actions = [venv.action_space.sample() for _ in range(3 * LIMIT)]
    results = [venv.step(a) for a in actions]
    expected = single_rollouts(actions, mode, 9, OPTIONS if keep else None)
    assert np.array_equal(np.array([r[0] for r in results]), expected)
    speeds = np.array([r[4]["current_speed"] for r in results])
    assert bool(np.all(speeds == 0.3)) is keep  # forgotten at the first autoreset unless kept
    venv.reset(seed=9)  # a reset without options clears the kept ones
    for a in actions:
        info = venv.step(a)[4]
    assert not np.any(info["current_speed"] == 0.3)


@pytest.mark.parametrize("flag", ["keep_options", "step_info"])
def test_flags_must_be_bools(flag: str) -> None:
    with pytest.raises(ValueError, match=f"{flag} must be True or False, got 1"):
        gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point", **{flag: 1})


@pytest.mark.parametrize("mode", MODES, ids=lambda m: m.value)
@pytest.mark.parametrize("env_id", ["shipgym/NomotoHeading-v0", "shipgym/RVGPathFollowing-v1"])
def test_without_step_info_only_what_autoresets_hand_over(env_id: str, mode: AutoresetMode) -> None:
    """``step_info=False`` steps exactly as the full env (episode ends, blow-ups and task
    failures included) and returns no ``info`` but the finished episodes' ``final_obs``."""
    kwargs = FAILING.get(env_id, {})
    full, _ = make_pair(env_id, mode, **kwargs)
    lean = make_native(env_id, mode, step_info=False, **kwargs)
    assert lean.reset(seed=3)[1] == {}
    full.reset(seed=3)
    full.action_space.seed(3)
    blow_ups = dict(BLOW_UPS)
    finished = 0
    for t in range(N_STEPS):
        if t in blow_ups:
            for venv in (full, lean):
                venv.unwrapped.task.x[blow_ups[t], 3] = np.nan
        action = full.action_space.sample()
        out_f, out_l = full.step(action), lean.step(action)
        for k, name in enumerate(("obs", "reward", "terminated", "truncated")):
            assert np.array_equal(out_l[k], out_f[k]), f"step {t}: {name}"
        info_f, info_l = out_f[4], out_l[4]
        done = out_f[2] | out_f[3]
        finished += int(done.any())
        if mode is AutoresetMode.SAME_STEP and done.any():
            assert sorted(info_l) == ["_final_obs", "final_obs"], f"step {t}"
            assert info_l["_final_obs"].tolist() == info_f["_final_obs"].tolist() == done.tolist()
            for i in range(NUM_ENVS):
                expected = info_f["final_obs"][i]
                got = info_l["final_obs"][i]
                assert (got is None) if expected is None else np.array_equal(got, expected)
        else:
            assert info_l == {}, f"step {t}: {sorted(info_l)}"
    assert finished >= 3  # truncations, blow-ups and failures all went through the lean path
    assert lean.reset()[1] == {}


def test_sb3_adapter_builds_no_info_it_does_not_pass_on() -> None:
    """SB3's per-env dicts carry only the terminal observation and the truncation flag: the
    adapter's vector env builds nothing else, and those two are the full env's."""
    from shipgym.rl.vec_env import ShipgymVecEnv

    venv = ShipgymVecEnv(ENV_ID, NUM_ENVS, fixed_seed=0, max_episode_steps=LIMIT)
    full, _ = make_pair(ENV_ID, AutoresetMode.SAME_STEP)
    assert venv.venv.unwrapped.step_info is False
    full.reset(seed=0)
    venv.reset()
    action = np.full((NUM_ENVS, 1), 0.3, dtype=np.float32)
    for _ in range(LIMIT):
        venv.step_async(action)
        obs, _, dones, infos = venv.step_wait()
        obs_f, _, _, trunc, info = full.step(action)
        assert np.array_equal(obs, obs_f)
    assert dones.all() and trunc.all()  # every sub-env truncated at the limit
    for i in range(NUM_ENVS):
        assert sorted(infos[i]) == ["TimeLimit.truncated", "terminal_observation"]
        assert infos[i]["TimeLimit.truncated"] is True
        assert np.array_equal(infos[i]["terminal_observation"], info["final_obs"][i])


def test_sb3_adapter_keeps_its_reset_options_for_autoresets() -> None:
    from shipgym.rl.vec_env import ShipgymVecEnv

    for keep in (False, True):
        venv = ShipgymVecEnv(
            ENV_ID, 3, fixed_seed=0, reset_options=OPTIONS, keep_options=keep, max_episode_steps=2
        )
        venv.reset()
        for _ in range(3):
            venv.step_async(np.zeros((3, 1), dtype=np.float32))
            venv.step_wait()
        speeds = venv.venv.unwrapped.task.current[:, 0]
        assert bool(np.all(speeds == 0.3)) is keep


@pytest.mark.parametrize("env_id", shipgym.ENV_IDS)
def test_vector_info_arrays_are_new_and_stay_as_they_were(env_id: str) -> None:
    """No array of a step's ``info`` shares memory with the env (or with another step's): a
    caller that keeps it sees the values of that step after the next steps."""
    native, _ = make_pair(env_id, AutoresetMode.NEXT_STEP)
    native.reset(seed=1)
    task = native.unwrapped.task
    actions = np.full((NUM_ENVS, *native.single_action_space.shape), 0.5)
    info = native.step(actions)[4]
    kept = {key: value.copy() for key, value in info.items()}
    owned = [a for a in vars(task).values() if isinstance(a, np.ndarray)]
    for key, value in info.items():
        assert not any(np.shares_memory(value, a) for a in owned), key
    for _ in range(3):
        later = native.step(actions)[4]
        for key, value in info.items():
            assert not np.shares_memory(value, later[key]), key
    for key, value in info.items():
        np.testing.assert_array_equal(value, kept[key], err_msg=key)

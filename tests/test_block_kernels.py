"""The SIMD block kernels: same numbers as before, as the C library, for any batch size.

* The environments and the bare model steps reproduce the trajectories recorded with the
  per-ship kernels that used the C library's sine and cosine (``tests/data``, written by
  ``scripts/record_step_reference.py``) to 1e-9 over 100 steps.
* :mod:`shipgym.models.vmath` agrees with the C library to 2 ulp (1 ulp measured) over the
  angles the models meet, and keeps NaN, infinities and signed zeros right.
* A ship's derivative does not depend on which lane of a block it is computed in: a batch of
  any size gives, bitwise, the derivative of each ship alone (the SIMD body and the scalar
  remainder of the loop compute the same IEEE operations).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numba
import numpy as np
import pytest

from shipgym.models import make_model
from shipgym.models.integrate import BLOCK
from shipgym.models.vmath import atan2, sincos

# one worker runs this file: its module fixtures are built once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_block_kernels")

REFERENCE = Path(__file__).parent / "data" / "step_reference.npz"


def _record() -> dict[str, np.ndarray]:
    import runpy

    script = Path(__file__).parents[1] / "scripts" / "record_step_reference.py"
    return runpy.run_path(str(script))["record"]()


@pytest.fixture(scope="module")
def trajectories() -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        now = _record()
    with np.load(REFERENCE) as ref:
        return {k: ref[k] for k in ref.files}, now


def test_trajectories_agree_with_the_recorded_reference(
    trajectories: tuple[dict[str, np.ndarray], dict[str, np.ndarray]],
) -> None:
    ref, now = trajectories
    assert set(ref) == set(now)
    for key, expected in ref.items():
        assert expected.shape[0] == 100, key
        np.testing.assert_allclose(now[key], expected, rtol=1e-9, atol=1e-9, err_msg=key)


def test_the_reference_is_not_trivial(
    trajectories: tuple[dict[str, np.ndarray], dict[str, np.ndarray]],
) -> None:
    """Every recorded trajectory moves: agreement is not agreement at rest."""
    ref, _ = trajectories
    for key, value in ref.items():
        if key.endswith("/state") or key.startswith("model/"):
            assert np.ptp(value[:, :, :2], axis=0).max() > 10.0, key  # tens of metres


@numba.njit(error_model="numpy")
def _sincos_many(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    s = np.empty_like(x)
    c = np.empty_like(x)
    for i in range(x.size):
        s[i], c[i] = sincos(x[i])
    return s, c


@numba.njit(error_model="numpy")
def _atan2_many(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    out = np.empty_like(x)
    for i in range(x.size):
        out[i] = atan2(y[i], x[i])
    return out


def _ulp_error(got: np.ndarray, want: np.ndarray) -> float:
    return float((np.abs(got - want) / np.spacing(np.maximum(np.abs(want), 1e-300))).max())


@pytest.mark.parametrize("scale", [1e-6, 1.0, math.pi, 100.0, 2e3, 1e5])
def test_sincos_is_within_two_ulp_of_the_c_library(scale: float) -> None:
    x = np.random.default_rng(7).uniform(-scale, scale, 100_000)
    s, c = _sincos_many(x)
    # ulps of the result, or of 1 near a zero of the function (an absolute error of 2^-53)
    assert np.abs(s - np.sin(x)).max() <= 2 * np.spacing(1.0) / 2
    assert np.abs(c - np.cos(x)).max() <= 2 * np.spacing(1.0) / 2
    tiny = np.abs(x) < 1e-3  # there sin(x) ~ x: relative accuracy
    big = np.abs(np.sin(x)) > 1e-3
    for mask in (tiny, big):
        if mask.any():
            assert _ulp_error(s[mask], np.sin(x[mask])) <= 2.0


def test_sincos_special_values() -> None:
    s, c = _sincos_many(np.array([0.0, -0.0, math.nan, math.inf, -math.inf]))
    assert s[0] == 0.0 and c[0] == 1.0 and c[1] == 1.0
    assert np.isnan(s[2:]).all() and np.isnan(c[2:]).all()
    k = np.arange(-50, 51) * (math.pi / 2)  # the quadrant boundaries
    s, c = _sincos_many(k)
    assert np.abs(s - np.sin(k)).max() < 1e-14 and np.abs(c - np.cos(k)).max() < 1e-14


@pytest.mark.parametrize("scale", [1e-8, 1.0, 1e3, 1e8])
def test_atan2_is_within_two_ulp_of_the_c_library(scale: float) -> None:
    rng = np.random.default_rng(11)
    y = rng.uniform(-scale, scale, 100_000)
    x = rng.uniform(-1.0, 1.0, 100_000)
    assert _ulp_error(_atan2_many(y, x), np.arctan2(y, x)) <= 2.0
    assert _ulp_error(_atan2_many(x, y), np.arctan2(x, y)) <= 2.0


def test_atan2_signed_zeros_and_axes() -> None:
    values = np.array([0.0, -0.0, 1.0, -1.0, 5e-324, 1e300])
    y, x = (a.ravel() for a in np.meshgrid(values, values))
    got = _atan2_many(y, x)
    want = np.arctan2(y, x)
    assert np.all(np.abs(got - want) <= 2 * np.spacing(np.abs(want)))
    assert np.array_equal(np.signbit(got), np.signbit(want))


@pytest.mark.parametrize("name", ["nomoto1", "nomoto2", "norrbin", "bech", "rvg3dof"])
def test_derivative_and_step_do_not_depend_on_the_batch(name: str) -> None:
    """2 BLOCK + 5 ships (SIMD body and scalar remainder) give, bitwise, each ship alone."""
    model = make_model(name)
    n = 2 * BLOCK + 5
    rng = np.random.default_rng(5)
    x = rng.normal(0.0, 0.5, (n, model.nx))
    x[:, 3] += 4.0
    u = rng.uniform(-0.5, 0.5, (n, model.nu))
    if name == "rvg3dof":
        x[:, 6:8] = u[:, 0:2] = rng.uniform(0.0, 4e4, (n, 2))
    c = rng.uniform(-0.5, 0.5, (n, 2))
    batch_d = model.deriv(x, u, c)
    batch_x = model.step(x, u, 0.2, c)
    for i in range(n):
        assert np.array_equal(model.deriv(x[i : i + 1], u[i : i + 1], c[i : i + 1]), batch_d[[i]])
        assert np.array_equal(
            model.step(x[i : i + 1], u[i : i + 1], 0.2, c[i : i + 1]), batch_x[[i]]
        )


@pytest.mark.parametrize("env_id", ["RVGSpeed-v1", "RVGPathFollowing-v1", "RVGTargetTracking-v1"])
def test_the_gunnerus_task_kernels_refuse_another_ship(env_id: str) -> None:
    """The speed, path and target kernels compile the R/V Gunnerus alone: a Nomoto model id is
    refused with an error, not stepped as if it were the Gunnerus."""
    import gymnasium as gym

    from shipgym.envs import kernels
    from shipgym.models.integrate import NOMOTO1

    env = gym.make(f"shipgym/{env_id}")
    env.reset(seed=0)
    task = env.unwrapped.task
    args = list(task._args(True, np.arange(1)))
    args[2] = NOMOTO1
    before = task.x.copy()
    with pytest.raises(ValueError, match="sail the R/V Gunnerus"):
        kernels.KERNELS[task.kernel_name](*args)
    np.testing.assert_array_equal(task.x, before)


@pytest.mark.parametrize("name", ["nomoto1", "nomoto2", "norrbin", "bech"])
def test_full_blocks_step_each_model_as_the_single_env_does(name: str) -> None:
    """The vector env steps its full blocks with each model's own copy of the RK4 step, the
    single env a block of one with the step shared by all models: the same numbers, bitwise."""
    import gymnasium as gym

    n = BLOCK + 3
    venv = gym.make_vec(
        "shipgym/NomotoHeading-v0", num_envs=n, vectorization_mode="vector_entry_point", model=name
    )
    venv.reset(seed=4)
    actions = np.random.default_rng(2).uniform(-1.0, 1.0, (5, n, 1))
    for a in actions:
        venv.step(a)
    states = venv.unwrapped.task.x
    for i in (0, BLOCK - 1, BLOCK + 2):
        env = gym.make("shipgym/NomotoHeading-v0", model=name)
        env.reset(seed=4 + i)
        for a in actions:
            env.step(a[i])
        assert np.array_equal(env.unwrapped.task.x[0], states[i]), i
    assert np.ptp(states[:, 4]) > 0.0  # the ships turn, differently


def test_heading_kernel_runs_an_unlisted_shape_as_a_listed_one() -> None:
    """The heading kernel compiles its loops with the counts of each ship family it lists as
    constants, and runs any other shape with the counts read at run time: the same numbers.

    One observed state fewer than NomotoHeading's (``r`` only) is not a listed family; it must
    step the ships, count the steps, reward and flag them, and observe ``[e, r]`` exactly as
    the listed family does (blow-ups included)."""
    import gymnasium as gym

    from shipgym.envs import kernels

    n = BLOCK + 5
    venv = gym.make_vec(
        "shipgym/NomotoHeading-v0", num_envs=n, vectorization_mode="vector_entry_point"
    )
    venv.reset(seed=6)
    venv.step(np.zeros((n, 1)))  # the env's own call: the kernel's one signature
    heading = kernels.KERNELS["heading"]
    signatures = list(heading.signatures)
    task = venv.unwrapped.task
    nx, nu = task.x.shape[1], task.u.shape[1]
    assert (nx, nu, 1, 3) in kernels.HEADING_DIMS and (nx, nu, 1, 2) not in kernels.HEADING_DIMS

    def copied(args: list) -> list:  # the read-only tables stay read-only: the same types
        return [np.array(v) if isinstance(v, np.ndarray) and v.flags.writeable else v
                for v in args]  # fmt: skip

    listed = copied(task._args(True, np.arange(n)))
    other = copied(listed)
    # args: ..., x 3, ..., xm 8 (x itself in calm water), a 10, ..., obs_idx 14, ..., steps 17,
    # obs 18, rew 19, term 20, reason 21, obs_lo 22, obs_hi 23
    listed[8], other[8] = listed[3], other[3]
    other[14] = listed[14][:1].copy()
    other[18] = listed[18][:, :2].copy()
    other[22], other[23] = listed[22][:2].copy(), listed[23][:2].copy()
    rng = np.random.default_rng(3)
    for step in range(12):
        a = rng.uniform(-1.5, 1.5, (n, 1))
        listed[10][:], other[10][:] = a, a
        if step == 4:
            listed[3][7, 2] = other[3][7, 2] = np.nan  # a blow-up in one row
        assert heading(*listed) == heading(*other) == -1
        for k, name in ((3, "x"), (17, "steps"), (19, "rew"), (20, "term"), (21, "reason")):
            np.testing.assert_array_equal(other[k], listed[k], err_msg=f"step {step}: {name}")
        np.testing.assert_array_equal(other[18], listed[18][:, :2], err_msg=f"step {step}: obs")
    assert listed[21][7] == kernels.BLOW_UP and np.ptp(listed[3][:, 4]) > 0.0
    # both ran the code the env compiled: an unlisted shape costs no second compilation
    assert heading.signatures == signatures

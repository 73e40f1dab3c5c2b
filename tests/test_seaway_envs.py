"""The envs at sea: wind and waves as options, drawn from the episode's seed, the same in the
single and the vector env, and each part against its closed form or library function."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
import scipy.integrate
import scipy.signal

import shipgym  # noqa: F401  (registers the envs)
from shipgym.models import seaway as sw
from shipgym.models import wind as W
from shipgym.models.angles import ssa
from shipgym.models.integrate import BLOCK
from shipgym.models.rvg import CG_FORWARD_OF_AP, GRAVITY, LPP
from shipgym.models.seaway_options import SeawayArrays, sea_option, wind_option
from shipgym.models.waves import (
    SeaState,
    box_waterline,
    encounter_frequency,
    mean_drift_force,
    reflection_factor,
)

SEA = {"significant_height": 2.0, "peak_period": 8.0}
WIND = {"speed": 12.0}
IDS = [
    "shipgym/NomotoHeading-v0",
    "shipgym/RVGHeading-v1",
    "shipgym/RVGSpeed-v1",
    "shipgym/RVGPathFollowing-v1",
    "shipgym/RVGTargetTracking-v1",
]


def test_calm_water_by_default() -> None:
    env = gym.make("shipgym/RVGHeading-v1")
    _, info = env.reset(seed=0)
    task = env.unwrapped.task
    assert task.xm is task.x and task.seaway is None
    assert not {"wind", "sea_state", "wave_motion", "measured_state"} & set(info)


@pytest.mark.parametrize("env_id", IDS)
def test_single_equals_vector_at_sea(env_id: str) -> None:
    """Three sub-envs at sea with drawn wind and waves equal three single envs seeded
    ``s + i`` bit for bit: observations, rewards, the measured state and the wave motion."""
    n, seed = 3, 11
    kwargs = {"wind": {"speed": (5.0, 15.0)}, "sea_state": {**SEA, "peak_period": (6.0, 9.0)}}
    venv = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kwargs)
    singles = [gym.make(env_id, **kwargs) for _ in range(n)]
    obs, info = venv.reset(seed=seed)
    for i, env in enumerate(singles):
        o, inf = env.reset(seed=seed + i)
        np.testing.assert_array_equal(obs[i], o)
        np.testing.assert_array_equal(info["measured_state"][i], inf["measured_state"])
        np.testing.assert_array_equal(info["sea_state"][i], inf["sea_state"])
    rng = np.random.default_rng(0)
    for _ in range(60):
        a = rng.uniform(-1, 1, (n, *venv.single_action_space.shape)).astype(np.float32)
        obs, rew, term, _, info = venv.step(a)
        for i, env in enumerate(singles):
            o, r, t, _, inf = env.step(a[i])
            np.testing.assert_array_equal(obs[i], o)
            assert rew[i] == r and term[i] == t
            np.testing.assert_array_equal(info["wave_motion"][i], inf["wave_motion"])
            np.testing.assert_array_equal(info["wind"][i], inf["wind"])
    assert np.ptp(info["sea_state"][:, 1]) > 0  # the sub-envs drew their own seas
    assert np.abs(info["wave_motion"]).max() > 0


def test_an_episodes_seaway_is_a_function_of_its_seed() -> None:
    def run(seed: int) -> np.ndarray:
        env = gym.make("shipgym/NomotoHeading-v0")
        env.reset(seed=seed, options={"wind": {"speed": (5.0, 15.0)}, "sea_state": SEA})
        return np.array([env.step(np.zeros(1))[4]["wave_motion"] for _ in range(30)])

    np.testing.assert_array_equal(run(4), run(4))
    assert not np.array_equal(run(4), run(5))


@pytest.mark.parametrize("height", [0.0, (0.0, 3.0)])
def test_a_flat_sea_moves_nothing_and_a_range_draws_each_ships_sea(height) -> None:
    """A wave height of 0 (fixed, or drawn from a range that starts at 0) is a sea without
    waves: no wave motion and no drift; each ship of a range has its own drawn sea."""
    env = gym.make_vec("shipgym/RVGHeading-v1", num_envs=8, vectorization_mode="vector_entry_point")
    sea = {"significant_height": height, "peak_period": (5.0, 9.0)}
    _, info = env.reset(seed=2, options={"sea_state": sea})
    for _ in range(5):
        info = env.step(np.zeros((8, 1)))[4]
    flat = info["sea_state"][:, 0] == 0.0
    if height == 0.0:
        assert flat.all()
    else:
        assert not flat.any() and np.unique(info["sea_state"][:, 0]).size == 8
    np.testing.assert_array_equal(info["wave_motion"][flat], 0.0)
    np.testing.assert_array_equal(info["measured_state"][flat], info["state"][flat])
    task = env.unwrapped.task
    np.testing.assert_array_equal(task.c[flat, 2:], 0.0)
    assert (np.abs(info["wave_motion"][~flat]).max(axis=1) > 0.0).all()


def test_calm_draws_are_unchanged_by_a_seaway_option_of_another_reset() -> None:
    """A reset without a seaway draws what it always drew (the seaway's draws come after)."""
    calm = gym.make("shipgym/NomotoHeading-v0")
    calm_obs = calm.reset(seed=9)[0]
    env = gym.make("shipgym/NomotoHeading-v0")
    env.reset(seed=1, options={"wind": WIND})
    obs, info = env.reset(seed=9, options={"wind": None})
    task = env.unwrapped.task
    np.testing.assert_array_equal(obs, calm_obs)
    np.testing.assert_array_equal(info["measured_state"], info["state"])
    assert info["wind"][0] == 0.0 and not task.c[0, 2:].any()


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"wind": {"speed": 40.0}}, r"wind\['speed'\] must be in \[0, 30\] m/s, got 40"),
        ({"wind": {"speed": (9.0, 3.0)}}, "low <= high"),
        ({"wind": {"direction": 1.0}}, "'speed' \\(required\\)"),
        ({"wind": 12.0}, "option 'wind' must be None or a dict"),
        ({"wind": {"speed": 5.0, "gusts": "yes"}}, "gusts'\\] must be True or False"),
        ({"sea_state": {"significant_height": 9.0, "peak_period": 12.0}}, r"\[0, 8\] m"),
        ({"sea_state": {"significant_height": 2.0, "peak_period": 1.0}}, r"\[2, 20\] s"),
        ({"sea_state": {"significant_height": 4.0, "peak_period": 4.0}}, "too steep"),
        ({"sea_state": {"significant_height": 1.0}}, "'peak_period' \\(required\\)"),
        ({"sea_state": {**SEA, "gamma": 9.0}}, r"gamma'\] must be in \[1, 7\]"),
    ],
)
def test_bad_seaway_options_are_refused_with_the_value_and_range(
    options: dict, message: str
) -> None:
    env = gym.make("shipgym/RVGHeading-v1")
    env.reset(seed=0)
    x = env.unwrapped.task.x.copy()
    with pytest.raises(ValueError, match=message):
        env.reset(seed=1, options=options)
    np.testing.assert_array_equal(env.unwrapped.task.x, x)  # nothing changed
    with pytest.raises(ValueError, match=message):
        gym.make("shipgym/RVGHeading-v1", **options)


def test_a_ship_without_wind_data_is_refused() -> None:
    from shipgym.models.model_file import nomoto_document

    fit = {"nomoto": nomoto_document("nomoto1", {"K": 0.05, "T": 20.0}, length=12.0)}
    env = gym.make("shipgym/NomotoHeading-v0", model=fit)
    with pytest.raises(ValueError, match="wind areas and hull"):
        env.reset(seed=0, options={"wind": WIND})


def test_the_observation_is_measured_and_the_reward_low_frequency() -> None:
    env = gym.make("shipgym/NomotoHeading-v0", sea_state={**SEA, "significant_height": 4.0})
    env.reset(seed=3)
    for _ in range(20):
        action = np.array([0.3], dtype=np.float32)
        obs, rew, _, _, info = env.step(action)
        sp, psi, psi_m = info["heading_setpoint"], info["state"][2], info["measured_state"][2]
        assert psi_m == psi + info["wave_motion"][2] != psi
        assert obs[0] == np.float32(ssa(sp - psi_m))
        cost = 0.05 * float(action[0]) ** 2
        assert rew == pytest.approx(-abs(ssa(sp - psi)) / math.pi - cost, abs=1e-12)


# ---------------------------------------------------------------------------------------------
# the parts against their closed forms and library functions, through the envs' own step


def _batch(ship: sw.SeawayShip, n: int, nx: int, wind, sea, dt: float, seed: int = 0):
    """``n`` ships of ``ship`` at rest at heading 0 with the seaway set, and their arrays."""
    x = np.zeros((n, nx))
    c = np.zeros((n, 5))
    xm = x.copy()
    arrays = SeawayArrays(n, ship, dt, 4 if nx < 10 else 5)
    rows = np.arange(n)
    draws = np.random.default_rng(seed).random((n, 6))
    arrays.set_rows(rows, wind_option(wind), sea_option(sea), draws)
    sw.start_rows(rows, x, c, arrays.sea, arrays.wf, arrays.rng, dt)
    return x, c, xm, arrays, rows


def _step(x, c, xm, arrays, rows, dt, advance=True) -> None:
    a = arrays
    for start in range(0, rows.size, BLOCK):
        sw.seaway_block(rows, start, min(BLOCK, rows.size - start), x, c, xm, a.sea, a.wf, a.rng,
                        a.tables, a.gains, a.constants, a.ir, dt, advance)  # fmt: skip


def test_a_block_of_more_ships_than_its_scratch_holds_is_refused() -> None:
    """The block kernel's scratch holds BLOCK ships; a longer block is refused, not overrun."""
    x, c, xm, arrays, rows = _batch(sw.gunnerus_seaway(), BLOCK + 1, 10, {"speed": 8.0}, None, 1.0)
    a = arrays
    with pytest.raises(ValueError, match="at most BLOCK ships"):
        sw.seaway_block(rows, 0, rows.size, x, c, xm, a.sea, a.wf, a.rng, a.tables, a.gains,
                        a.constants, a.ir, 1.0, True)  # fmt: skip


def test_gusts_have_the_norsok_variance_and_integral_time_scale() -> None:
    """The gust process's variance is NORSOK's spectrum integrated, and its lag-one
    correlation exp(-dt / T) with T = S(0) / (4 sigma^2), the spectrum's integral time scale
    (so the process's spectrum at zero frequency equals NORSOK's peak)."""
    u10, dt = 12.0, 1.0
    x, c, xm, arrays, rows = _batch(sw.gunnerus_seaway(), 64, 10, {"speed": u10}, None, dt)
    record = np.empty((3000, rows.size))
    for k in range(record.shape[0]):
        _step(x, c, xm, arrays, rows, dt)
        record[k] = arrays.wf[:, sw.W_SPEED]
    gust = record - u10
    variance = scipy.integrate.quad(lambda f: W.norsok_spectrum(f, u10), 0, np.inf, limit=400)[0]
    assert gust.var() == pytest.approx(variance, rel=0.1)
    scale = W.norsok_spectrum(0.0, u10) / (4.0 * variance)
    lag1 = np.mean(gust[1:] * gust[:-1]) / np.mean(gust * gust)
    assert lag1 == pytest.approx(math.exp(-dt / scale), abs=0.01)


@pytest.mark.parametrize("direction_deg", [0.0, 60.0, 135.0, -100.0])
def test_the_gunnerus_wind_load_is_blendermanns_at_the_apparent_wind(direction_deg: float) -> None:
    """A steady wind (no gusts) on a Gunnerus making 3 m/s: the load is Blendermann's at the
    apparent wind, its moment moved from midship to the model's origin (table: within 0.5 %)."""
    wind = {"speed": 11.0, "direction": math.radians(direction_deg), "gusts": False}
    x, c, xm, arrays, rows = _batch(sw.gunnerus_seaway(), 1, 10, wind, None, 0.5)
    x[0, 2], x[0, 3], x[0, 4] = 0.4, 3.0, 0.2
    _step(x, c, xm, arrays, rows, 0.5, advance=False)
    va, angle = W.apparent_wind(11.0, wind["direction"], 0.4, 3.0, 0.2)
    fx, fy, fn = W.blendermann_load(va, angle, *W.GUNNERUS_WIND.args())
    fn += (0.5 * LPP - CG_FORWARD_OF_AP) * fy
    scale = 0.5 * W.RHO_AIR * va**2 * W.GUNNERUS_WIND.lateral_area * 36.25
    np.testing.assert_allclose(c[0, 2:], (fx, fy, fn), atol=5e-3 * scale)
    assert abs(fy) > 0.1 * scale / 36.25 or direction_deg == 0.0


@pytest.mark.parametrize("direction_deg", [30.0, 90.0, -120.0])
def test_the_mariner_wind_is_its_equivalent_rudder_and_leeway(direction_deg: float) -> None:
    wind = {"speed": 15.0, "direction": math.radians(direction_deg), "gusts": False}
    x, c, xm, arrays, rows = _batch(sw.mariner_seaway(), 1, 6, wind, None, 1.0)
    x[0, 3] = 7.7  # service speed, heading 0, no current
    _step(x, c, xm, arrays, rows, 1.0, advance=False)
    va, angle = W.apparent_wind(15.0, wind["direction"], 0.0, 7.7, 0.0)
    delta_w, v_w = W.mariner_nomoto_wind(va, angle, 7.7)
    assert c[0, 2] == pytest.approx(delta_w, rel=0.01, abs=1e-5)
    assert c[0, 3] == pytest.approx(v_w, rel=0.01, abs=1e-4)


@pytest.mark.parametrize("heading_deg", [0.0, 45.0, 90.0, 160.0])
def test_the_drift_is_faltinsens_times_ursells_reflection(heading_deg: float) -> None:
    sea = SeaState(2.5, 7.0, 0.3)
    x, c, xm, arrays, rows = _batch(
        sw.gunnerus_seaway(), 1, 10, None, {"significant_height": 2.5, "peak_period": 7.0,
                                            "direction": 0.3}, 0.5)  # fmt: skip
    x[0, 2] = math.radians(heading_deg)
    _step(x, c, xm, arrays, rows, 0.5, advance=False)
    arm = 0.5 * LPP - CG_FORWARD_OF_AP
    fx, fy, fn = mean_drift_force(sea, x[0, 2], box_waterline(LPP, 9.6))
    share = reflection_factor(sea, 2.7)
    expected = share * np.array([fx, fy, fn + arm * fy])
    scale = 1025 * GRAVITY * 2.5**2 / 16 * LPP * share
    np.testing.assert_allclose(c[0, 2:], expected, atol=0.01 * scale)
    assert 0.0 < share < 1.0


def test_the_wave_motion_has_its_rms_and_the_encounter_frequency() -> None:
    """The Gunnerus at 4 m/s in bow-quartering seas: the wave-frequency heading's RMS is
    ``H_s / 4`` times the table's gain, and its spectrum peaks at the encounter frequency of the
    sea's peak."""
    dt, heading, speed = 0.5, math.radians(30.0), 4.0
    sea = {"significant_height": 2.0, "peak_period": 7.0, "direction": math.pi}
    x, c, xm, arrays, rows = _batch(sw.gunnerus_seaway(), 32, 10, None, sea, dt)
    x[:, 2], x[:, 3] = heading, speed
    record = np.empty((4096, rows.size))
    for k in range(record.shape[0]):
        _step(x, c, xm, arrays, rows, dt)
        record[k] = xm[:, 2] - x[:, 2]
    beta = ssa(math.pi - heading)
    gains = sw.wave_motion_gains(SeaState(2.0, 7.0, math.pi), LPP)
    expected = 0.5 * abs(np.interp(beta, sw.GAIN_ANGLES, gains[1]))
    assert record.std() == pytest.approx(expected, rel=0.1)
    f, psd = scipy.signal.welch(record, fs=1 / dt, nperseg=512, axis=0)
    peak = 2 * math.pi * f[np.argmax(psd.mean(axis=1))]
    we = abs(float(encounter_frequency(2 * math.pi / 7.0, speed, beta)))
    assert peak == pytest.approx(we, rel=0.1)


def test_wave_motion_table_interpolates_the_factors_of_any_sea() -> None:
    """The compiled step's shared table, interpolated as the step does (linearly in
    ``sqrt(|s|)`` and ``gamma``), gives the factors computed directly at spectrum shapes and
    ``s`` off its grid, to 0.3 % of F_xi's largest value and 0.5 % of F_psi's; and the gains
    of a ship's sea are those factors at ``kappa cos(beta)``."""
    table = sw.wave_motion_table()
    rng = np.random.default_rng(3)
    for gamma in (1.0, 1.7, 3.3, 5.2, 7.0):
        s = np.concatenate(([0.0, 1e-3], rng.uniform(0.0, 100.0, 300)))
        direct = sw.wave_motion_factors(gamma, s)
        t = np.sqrt(s) / sw.WAVE_MOTION_STEP
        k = np.minimum(np.floor(t), table.shape[2] - 2).astype(int)
        f = t - k
        j = min(int(gamma - 1.0), len(sw.TABLE_GAMMAS) - 2)
        g = gamma - sw.TABLE_GAMMAS[j]
        at = [(1 - f) * table[:, q, k] + f * table[:, q, k + 1] for q in (j, j + 1)]
        interpolated = (1 - g) * at[0] + g * at[1]
        np.testing.assert_allclose(interpolated[0], direct[0], atol=0.003)
        np.testing.assert_allclose(interpolated[1], direct[1], atol=0.005 * table[1].max())
    sea = SeaState(2.0, 7.0, 0.0, 3.3)
    kappa = sea.peak_frequency**2 * LPP / (2 * GRAVITY)
    factors = sw.wave_motion_factors(3.3, kappa * np.cos(sw.GAIN_ANGLES))
    gains = sw.wave_motion_gains(sea, LPP)
    np.testing.assert_allclose(gains[0], 4 * factors[0], rtol=1e-12)
    np.testing.assert_allclose(gains[1], 24 / LPP * np.sin(sw.GAIN_ANGLES) * factors[1],
                               rtol=1e-12, atol=1e-15)  # fmt: skip


def test_wave_motion_gains_have_their_long_wave_limits() -> None:
    """For waves much longer than the ship, the displacement is the wave's orbit (gain 1 per
    unit amplitude) and the yaw ``k sin(beta) cos(beta)`` (the closed forms of the module),
    ``k`` weighted by the spectrum."""
    sea = SeaState(1.0, 20.0, 0.0, gamma=7.0)  # a narrow spectrum of 624 m waves
    gains = sw.wave_motion_gains(sea, 10.0) / 4.0  # per unit H_s/4 -> per unit amplitude
    top = 4.0 * sea.peak_frequency
    m0 = scipy.integrate.quad(sea.spectrum, 1e-3, top, limit=200)[0]
    k2 = scipy.integrate.quad(lambda w: sea.spectrum(w) * (w * w / GRAVITY) ** 2, 1e-3, top,
                              limit=200)[0] / m0  # fmt: skip
    np.testing.assert_allclose(gains[0], 1.0, rtol=2e-3)
    long_wave = math.sqrt(k2) * np.sin(sw.GAIN_ANGLES) * np.cos(sw.GAIN_ANGLES)
    np.testing.assert_allclose(gains[1], long_wave, atol=0.01 * math.sqrt(k2))

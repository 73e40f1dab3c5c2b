"""The wave filter of the heading autopilot (:mod:`controllers.wave_filter`): in a seaway the
filtered autopilot holds the low-frequency heading as in calm water with little more rudder;
fed the measured heading, it chases the waves."""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers.heading import HeadingAutopilot
from controllers.wave_filter import WaveFilter

K, T, DT = 0.185, 107.3, 0.5  # the Mariner's first-order Nomoto model (nomoto1)
PEAK = 0.6  # encounter peak frequency [rad/s]
DURATION, SETTLE = 1500.0, 300.0


def _waves(std_deg: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A wave-frequency heading and yaw rate drawn from a JONSWAP-shaped spectrum (gamma 3.3)
    as a sum of 200 components: not the filter's own second-order wave model."""
    rng = np.random.default_rng(seed)
    om = np.linspace(0.3, 1.5, 200) + rng.uniform(0.0, 0.006, 200)
    width = np.where(om <= PEAK, 0.07, 0.09)
    s = om**-5 * np.exp(-1.25 * (PEAK / om) ** 4) * 3.3 ** np.exp(
        -((om - PEAK) ** 2) / (2 * width**2 * PEAK**2)
    )
    amp = np.sqrt(2 * s * (om[1] - om[0]))
    amp *= math.radians(std_deg) / np.sqrt(np.sum(amp**2) / 2)
    phase = rng.uniform(0.0, 2 * math.pi, 200)
    t = np.arange(int(DURATION / DT))[:, None] * DT
    arg = om * t + phase
    return (amp * np.sin(arg)).sum(1), (amp * om * np.cos(arg)).sum(1)


def _run(waves: tuple[np.ndarray, np.ndarray] | None, wave_filter: WaveFilter | None):
    """Setpoint steps of 10 deg every 300 s; returns the ship's (LF) heading [rad] at every
    step and the rudder travel [deg/min] after the first 300 s."""
    autopilot = HeadingAutopilot.from_nomoto(
        K, T, DT, max_command=math.radians(35.0), max_rate=math.radians(2.3)
    )
    psi = r = delta = 0.0
    if wave_filter is not None:
        wave_filter.reset(0.0)
    headings, rudder = [], []
    for k in range(int(DURATION / DT)):
        ref = math.radians(10.0 * ((k * DT) // 300.0 % 3))
        psi_m = psi + (waves[0][k] if waves else 0.0)
        r_m = r + (waves[1][k] if waves else 0.0)
        if wave_filter is not None:
            psi_f, r_f = wave_filter.update(np.array([psi_m]), np.array([delta]))
            psi_m, r_m = float(psi_f[0]), float(r_f[0])
        delta = float(autopilot.update(None, psi_m, r_m, ref))
        for _ in range(10):  # the ship: T r' + r = K delta, psi' = r
            r += DT / 10 * (K * delta - r) / T
            psi += DT / 10 * r
        headings.append(psi)
        rudder.append(delta)
    start = int(SETTLE / DT)
    travel = np.abs(np.diff(np.degrees(rudder[start:]))).sum() / ((DURATION - SETTLE) / 60.0)
    return np.asarray(headings), float(travel)


@pytest.mark.parametrize(
    ("design_deg", "sea_deg", "travel_factor"),
    [(1.5, 1.5, 2.0), (3.0, 1.0, 2.0), (1.5, 3.0, 3.5)],
    ids=["as-designed", "calmer", "twice-the-design"],
)
def test_the_filtered_autopilot_holds_the_lf_heading_without_chasing_the_waves(
    design_deg: float, sea_deg: float, travel_factor: float
) -> None:
    waves = _waves(sea_deg, seed=1)
    calm, calm_travel = _run(None, None)
    wave_filter = WaveFilter(K, T, DT, PEAK, math.radians(design_deg))
    filtered, travel = _run(waves, wave_filter)
    raw, raw_travel = _run(waves, None)
    # the ship's LF heading as in calm water, within 0.1 deg RMS (0.01-0.04 deg here)
    deviation = np.degrees(np.sqrt(np.mean((filtered - calm) ** 2)))
    assert deviation < 0.1
    assert travel < travel_factor * calm_travel  # with little more rudder (1.2-2.7 x)
    # unfiltered, the rudder chases the waves (about 135 deg/min against 0.46) and, rate
    # limited, lets the LF heading wander by degrees
    assert raw_travel > 100.0 * calm_travel
    assert np.degrees(np.sqrt(np.mean((raw - calm) ** 2))) > 2.0


def test_in_calm_water_the_filter_passes_the_heading_through() -> None:
    wave_filter = WaveFilter(K, T, DT, PEAK, math.radians(1.5))
    calm, calm_travel = _run(None, None)
    filtered, travel = _run(None, wave_filter)
    assert np.degrees(np.max(np.abs(filtered - calm))) < 0.5
    assert travel == pytest.approx(calm_travel, rel=0.1)


def test_a_constant_rudder_bias_is_estimated() -> None:
    """A ship held straight against a 2 deg rudder bias: the bias estimate converges to it."""
    wave_filter = WaveFilter(K, T, DT, PEAK, math.radians(1.5))
    wave_filter.reset(np.zeros(3))
    bias = math.radians(2.0)
    delta = np.full(3, -bias)  # the rudder that holds the biased ship straight
    for _ in range(int(4000 / DT)):
        wave_filter.update(np.zeros(3), delta)
    assert wave_filter.bias == pytest.approx(np.full(3, bias), rel=0.02)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"T": 0.0}, "T must be"),
        ({"peak_frequency": 0.0}, "peak_frequency must be"),
        ({"wave_heading_std": math.nan}, "wave_heading_std must be"),
        ({"K": 0.0}, "K must be"),
        ({"peak_frequency": [0.5, -0.1]}, "peak_frequency must be"),
        ({"peak_frequency": [0.5, 0.6], "wave_heading_std": [0.01, 0.02, 0.03]}, "one value"),
    ],
)
def test_bad_parameters_are_refused(kwargs: dict, message: str) -> None:
    args = {"K": K, "T": T, "dt": DT, "peak_frequency": PEAK, "wave_heading_std": 0.02} | kwargs
    with pytest.raises(ValueError, match=message):
        WaveFilter(**args)


def test_a_wave_model_per_ship_equals_each_ships_own_filter() -> None:
    """Three ships with their own encounter frequencies and wave motion: each row is the
    filter made for that ship alone; a retune gives the design of the new values."""
    peaks, stds = np.array([0.4, 0.6, 0.9]), np.radians([0.5, 1.5, 3.0])
    batch = WaveFilter(K, T, DT, peaks, stds)
    assert batch.ships == 3
    singles = [WaveFilter(K, T, DT, w, s) for w, s in zip(peaks, stds, strict=True)]
    waves, _ = _waves(1.5, seed=2)
    rng = np.random.default_rng(3)
    rudder = rng.uniform(-0.1, 0.1, (400, 3))
    batch.reset(np.zeros(3))
    for f in singles:
        f.reset(0.0)
    for k in range(400):
        psi, r = batch.update(waves[k] * np.array([0.3, 1.0, 2.0]), rudder[k])
        for i, f in enumerate(singles):
            psi_i, r_i = f.update(np.array([waves[k] * [0.3, 1.0, 2.0][i]]), rudder[k, i : i + 1])
            assert psi[i] == pytest.approx(psi_i[0], abs=1e-12)
            assert r[i] == pytest.approx(r_i[0], abs=1e-12)
    batch.retune([1], 0.9, math.radians(3.0))
    np.testing.assert_allclose(batch.gain[1], singles[2].gain, rtol=1e-12)
    np.testing.assert_allclose(batch.transition[1], singles[2].transition, rtol=1e-12)
    np.testing.assert_allclose(batch.gain[0], singles[0].gain, rtol=1e-12)


def test_retune_needs_a_wave_model_per_ship() -> None:
    with pytest.raises(ValueError, match="retune needs a filter with a wave model per ship"):
        WaveFilter(K, T, DT, PEAK, 0.02).retune([0], PEAK, 0.02)


def test_a_directionally_unstable_ship_is_filtered() -> None:
    """An unstable Nomoto ship (T < 0, as seed 001's Gunnerus) held on course by a rudder
    that cancels its divergence: the filter's LF heading follows the true heading through the
    waves (its error a fraction of the wave motion)."""
    k_u, t_u = 0.1, -20.0
    wave_filter = WaveFilter(k_u, t_u, DT, PEAK, math.radians(1.5))
    waves, _ = _waves(1.5, seed=4)
    psi = r = delta = 0.0
    wave_filter.reset(0.0)
    errors = []
    for k in range(int(DURATION / DT)):
        psi_f, r_f = wave_filter.update(np.array([psi + waves[k]]), np.array([delta]))
        delta = float(2.0 * psi_f[0] + 40.0 * r_f[0])  # a PD that stabilises the ship
        for _ in range(10):
            r += DT / 10 * (k_u * delta - r) / t_u
            psi += DT / 10 * r
        errors.append(psi_f[0] - psi)
    error = np.degrees(np.sqrt(np.mean(np.square(errors[int(SETTLE / DT) :]))))
    assert error < 0.2  # 0.05 deg; the waves are 1.5 deg RMS
    assert abs(math.degrees(psi)) < 0.5  # held on course

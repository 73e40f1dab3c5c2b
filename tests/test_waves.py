"""Tests of :mod:`shipgym.models.waves`: spectra, encounter frequency, the seeded sea surface,
the linear wave response model and the mean drift force, each against a closed form or a
statistic of a long simulated record."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.linalg import solve_discrete_lyapunov
from scipy.signal import get_window, welch

from shipgym.models.rvg import GRAVITY, WATER_DENSITY
from shipgym.models.waves import (
    SeaRealisation,
    SeaState,
    box_waterline,
    encounter_angle,
    encounter_frequency,
    fit_wave_response,
    jonswap_spectrum,
    mean_drift_force,
    pierson_moskowitz_spectrum,
    realise_sea,
    wave_response_model,
)

SEA = SeaState(significant_height=3.0, peak_period=9.0, direction=0.3)
RHO_G = WATER_DENSITY * GRAVITY


def _m0(sea: SeaState) -> float:
    wp = sea.peak_frequency
    lo = quad(lambda w: float(sea.spectrum(w)), 0.0, wp, limit=200)[0]
    return lo + quad(lambda w: float(sea.spectrum(w)), wp, np.inf, limit=200)[0]


# --------------------------------------------------------------------------------------------
# spectra
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("gamma", [1.0, 2.0, 3.3, 5.0])
def test_spectrum_integral_is_hs_squared_over_16(gamma: float) -> None:
    sea = SeaState(4.0, 10.0, 0.0, gamma)
    assert _m0(sea) == pytest.approx(4.0**2 / 16.0, rel=0.01)


@pytest.mark.parametrize("gamma", [1.0, 3.3, 7.0])
def test_spectrum_peaks_at_the_peak_frequency(gamma: float) -> None:
    sea = SeaState(2.0, 7.0, 0.0, gamma)
    wp = 2.0 * math.pi / 7.0
    w = np.linspace(0.2, 3.0, 28001) * wp
    s = sea.spectrum(w)
    assert w[np.argmax(s)] == pytest.approx(wp, rel=1e-3)
    a_gamma = 1.0 - 0.287 * math.log(gamma)
    expected = a_gamma * gamma * 5.0 / 16.0 * 4.0 * math.exp(-1.25) / wp
    assert s.max() == pytest.approx(expected, rel=1e-6)
    assert sea.peak_density == pytest.approx(expected, rel=1e-12)


def test_pierson_moskowitz_is_jonswap_with_gamma_one_and_dnv_closed_form() -> None:
    w = np.array([0.0, 0.3, 0.6, 0.9, 1.5, 3.0])
    hs, tp = 5.0, 12.0
    wp = 2.0 * math.pi / tp
    pm = pierson_moskowitz_spectrum(w, hs, tp)
    np.testing.assert_array_equal(pm, jonswap_spectrum(w, hs, tp, 1.0))
    closed = 5.0 / 16.0 * hs**2 * wp**4 * w[1:] ** -5 * np.exp(-1.25 * (w[1:] / wp) ** -4)
    np.testing.assert_allclose(pm[1:], closed, rtol=1e-12)
    assert pm[0] == 0.0
    assert jonswap_spectrum(0.8, hs, tp).shape == ()


def test_jonswap_is_higher_than_pm_at_the_peak_and_lower_in_the_tail() -> None:
    wp = SEA.peak_frequency
    pm = pierson_moskowitz_spectrum([wp, 3 * wp], 3.0, 9.0)
    js = jonswap_spectrum([wp, 3 * wp], 3.0, 9.0, 3.3)
    assert js[0] > 2.0 * pm[0]
    assert js[1] == pytest.approx((1.0 - 0.287 * math.log(3.3)) * pm[1], rel=1e-9)


# --------------------------------------------------------------------------------------------
# encounter frequency
# --------------------------------------------------------------------------------------------


def test_encounter_frequency_closed_forms() -> None:
    w = np.array([0.4, 0.8, 1.2])
    np.testing.assert_array_equal(encounter_frequency(w, 0.0, 1.0), w)
    u = 6.0
    head = encounter_frequency(w, u, math.pi)
    following = encounter_frequency(w, u, 0.0)
    np.testing.assert_allclose(head, w + w**2 * u / GRAVITY, rtol=1e-14)
    np.testing.assert_allclose(following, w - w**2 * u / GRAVITY, rtol=1e-14)
    assert (head > w).all() and (following < w).all()
    np.testing.assert_allclose(encounter_frequency(w, u, math.pi / 2), w, rtol=1e-14)
    # overtaking short following waves: negative
    assert encounter_frequency(2.0, 10.0, 0.0) < 0.0
    assert encounter_frequency(w[:, None], [0.0, u], 0.0).shape == (3, 2)


def test_encounter_angle_convention() -> None:
    # waves travelling north met by a ship heading south: head seas; heading north: following
    assert abs(encounter_angle(0.0, math.pi)) == pytest.approx(math.pi)
    assert encounter_angle(0.0, 0.0) == 0.0
    # waves travelling east, ship heading north: they travel to starboard
    assert encounter_angle(math.pi / 2, 0.0) == pytest.approx(math.pi / 2)
    np.testing.assert_allclose(encounter_angle(0.1, [0.1 + 2 * math.pi, -0.2]), [0.0, 0.3])


# --------------------------------------------------------------------------------------------
# sea surface
# --------------------------------------------------------------------------------------------


def _expected_welch(sea: SeaState, fs: float, nperseg: int, w: np.ndarray) -> np.ndarray:
    """Mean of a Hann-window Welch estimate [m^2 s/rad] of a process with spectrum S: the sum
    over lags of the window's autocorrelation times the autocovariance ``R(tau) = int S cos``."""
    win = get_window("hann", nperseg)
    corr = np.correlate(win, win, mode="full")[nperseg - 1 :]
    grid = np.linspace(1e-4, 12.0 * sea.peak_frequency, 40001)
    lags = np.arange(nperseg) / fs
    cov = np.trapezoid(sea.spectrum(grid) * np.cos(np.outer(lags, grid)), grid, axis=1)
    weights = np.where(np.arange(nperseg) == 0, 1.0, 2.0) * corr * cov
    two_sided = weights @ np.cos(np.outer(lags, w))
    return 2.0 * two_sided / (fs * np.sum(win**2)) / (2.0 * math.pi)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_long_record_has_the_spectrum_it_was_drawn_from(seed: int) -> None:
    fs, nperseg = 2.0, 512
    t = np.arange(0.0, 3 * 3600.0, 1.0 / fs)  # 3 hours at 0.5 s
    zeta = realise_sea(SEA, seed).elevation(t)
    f, p = welch(zeta, fs=fs, nperseg=nperseg)
    w, s = 2.0 * math.pi * f, p / (2.0 * math.pi)
    # integral: 4 sqrt(m0) = H_s
    assert 4.0 * math.sqrt(np.trapezoid(s, w)) == pytest.approx(3.0, rel=0.1)
    assert 4.0 * math.sqrt(np.var(zeta)) == pytest.approx(3.0, rel=0.1)
    # peak: frequency, and height against the estimator's mean (the spectrum seen through
    # the Hann window), itself close to the spectrum's peak
    i = np.argmax(s)
    assert w[i] == pytest.approx(SEA.peak_frequency, rel=0.1)
    expected = _expected_welch(SEA, fs, nperseg, w)
    assert s[i] == pytest.approx(expected.max(), rel=0.1)
    assert expected.max() == pytest.approx(SEA.peak_density, rel=0.1)


def test_same_seed_same_sea_different_seed_different_sea() -> None:
    t = np.arange(0.0, 600.0, 0.5)
    a = realise_sea(SEA, 7).elevation(t, 10.0, -5.0)
    np.testing.assert_array_equal(a, realise_sea(SEA, 7).elevation(t, 10.0, -5.0))
    np.testing.assert_array_equal(
        a, realise_sea(SEA, np.random.default_rng(7)).elevation(t, 10.0, -5.0)
    )
    b = realise_sea(SEA, 8).elevation(t, 10.0, -5.0)
    assert np.max(np.abs(a - b)) > 0.5
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.2


def test_record_does_not_repeat_after_the_interval_period() -> None:
    """Equally spaced frequencies would repeat the record after ``2 pi / d omega``; the
    randomised ones do not."""
    n = 1000
    sea = realise_sea(SEA, 3, n_components=n)
    dw = 4.5 * SEA.peak_frequency / n
    t = np.arange(0.0, 1800.0, 0.5)
    a = sea.elevation(t)
    b = sea.elevation(t + 2.0 * math.pi / dw)
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.25
    # multiples of d omega (the band's interval midpoints, rounded): a period of 2 pi / d omega
    regular = SeaRealisation(dw * (np.arange(n) + 112), sea.amplitudes, sea.phases, 0.3)
    np.testing.assert_allclose(
        regular.elevation(t + 2.0 * math.pi / dw), regular.elevation(t), atol=1e-8
    )


def test_a_regular_wave_travels_toward_its_direction_at_the_phase_speed() -> None:
    omega, direction = 0.7, 0.4
    wave = SeaRealisation(np.array([omega]), np.array([1.5]), np.array([0.2]), direction)
    c = GRAVITY / omega
    t = np.linspace(0.0, 30.0, 61)
    here = wave.elevation(t)
    dist = c * 5.0
    there = wave.elevation(t + 5.0, dist * math.cos(direction), dist * math.sin(direction))
    np.testing.assert_allclose(there, here, atol=1e-9)
    np.testing.assert_allclose(here, 1.5 * np.cos(omega * t + 0.2), atol=1e-12)
    # along the crest (perpendicular to travel) the elevation is the same
    side = wave.elevation(t, -50.0 * math.sin(direction), 50.0 * math.cos(direction))
    np.testing.assert_allclose(side, here, atol=1e-9)


def test_elevation_broadcasts_time_and_position() -> None:
    sea = realise_sea(SEA, 1, n_components=50)
    z = sea.elevation(np.arange(4.0)[:, None], np.array([0.0, 10.0, 20.0]), 0.0)
    assert z.shape == (4, 3)
    assert z[2, 1] == pytest.approx(float(sea.elevation(2.0, 10.0, 0.0)))


def test_amplitudes_hold_the_spectrum_variance() -> None:
    sea = realise_sea(SEA, 5)
    assert 0.5 * np.sum(sea.amplitudes**2) == pytest.approx(3.0**2 / 16.0, rel=0.01)
    assert (
        (sea.frequencies >= 0.5 * SEA.peak_frequency)
        & (sea.frequencies <= 5.0 * SEA.peak_frequency)
    ).all()


# --------------------------------------------------------------------------------------------
# wave response model
# --------------------------------------------------------------------------------------------


def test_response_model_psd_peak_equals_the_spectrum_peak() -> None:
    model = wave_response_model(SEA, 0.5)
    assert model.natural_frequency == pytest.approx(SEA.peak_frequency)
    assert model.sigma**2 == pytest.approx(SEA.peak_density, rel=1e-12)
    assert float(model.psd(model.natural_frequency)) == pytest.approx(SEA.peak_density, rel=1e-12)
    assert model.gain == pytest.approx(2 * model.damping * model.natural_frequency * model.sigma)


def test_response_model_damping_is_the_least_squares_fit() -> None:
    lam, sigma = fit_wave_response(SEA)
    w = np.linspace(0.01, 4.0, 400) * SEA.peak_frequency
    s = SEA.spectrum(w)
    wp = SEA.peak_frequency

    def cost(x: float) -> float:
        psd = 4 * (x * wp * sigma) ** 2 * w**2 / ((wp**2 - w**2) ** 2 + 4 * (x * wp * w) ** 2)
        return float(np.sum((psd - s) ** 2))

    assert cost(lam) < cost(0.95 * lam) and cost(lam) < cost(1.05 * lam)
    # a broader spectrum (Pierson-Moskowitz) needs more damping; lambda depends on gamma only
    lam_pm, _ = fit_wave_response(SeaState(1.0, 6.0, 0.0, 1.0))
    assert lam_pm > 2.0 * lam
    assert fit_wave_response(SeaState(6.0, 14.0, 1.0))[0] == pytest.approx(lam, rel=1e-4)


def test_response_model_variance_closed_form_discrete_and_simulated() -> None:
    model = wave_response_model(SEA, 0.5, speed=5.0, heading=SEA.direction + math.pi)
    # head seas: omega_0 is the encounter peak frequency
    wp = SEA.peak_frequency
    assert model.natural_frequency == pytest.approx(wp + wp**2 * 5.0 / GRAVITY, rel=1e-12)
    integral = quad(lambda w: float(model.psd(w)), 0.0, np.inf, limit=500)[0]
    assert model.variance == pytest.approx(integral, rel=1e-6)
    bd = model.noise_gain
    stationary = solve_discrete_lyapunov(model.transition, bd @ bd.T)
    assert stationary[1, 1] == pytest.approx(model.variance, rel=1e-9)
    y = model.simulate(20 * 7200, seed=11)  # 20 hours at 0.5 s
    assert np.var(y) == pytest.approx(model.variance, rel=0.1)
    f, p = welch(y, fs=2.0, nperseg=1024)
    assert 2 * math.pi * f[np.argmax(p)] == pytest.approx(model.natural_frequency, rel=0.1)


def test_response_model_is_seeded_and_steps_batches() -> None:
    model = wave_response_model(SEA, 0.2)
    a = model.simulate(500, 3)
    np.testing.assert_array_equal(a, model.simulate(500, 3))
    assert not np.allclose(a, model.simulate(500, 4))
    rng = np.random.default_rng(0)
    x = rng.standard_normal((3, 4, 2))
    n = rng.standard_normal((3, 4, 2))
    out = model.step(x, n)
    assert out.shape == (3, 4, 2)
    np.testing.assert_allclose(
        out[1, 2], model.transition @ x[1, 2] + model.noise_gain @ n[1, 2], rtol=1e-14
    )


def test_response_model_vanishes_when_following_waves_are_matched() -> None:
    wp = SEA.peak_frequency
    speed = GRAVITY / wp  # the ship moves with the peak waves: omega_e = 0
    model = wave_response_model(SEA, 0.5, speed=speed, heading=SEA.direction)
    assert model.natural_frequency == pytest.approx(0.0, abs=1e-12)
    assert model.variance == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(model.simulate(100, 0), 0.0, atol=1e-12)


# --------------------------------------------------------------------------------------------
# mean drift force
# --------------------------------------------------------------------------------------------


def test_drift_force_box_at_beam_and_head_seas() -> None:
    sea = SeaState(2.5, 8.0, math.pi / 2)  # waves travelling east
    length, beam = 160.0, 23.0
    c = RHO_G * 2.5**2 / 16.0
    box = box_waterline(length, beam)
    # heading north: the waves travel to starboard, pushing the ship to starboard
    x, y, n = mean_drift_force(sea, 0.0, box)
    assert y == pytest.approx(c * length, rel=1e-12)
    assert x == pytest.approx(0.0, abs=1e-6 * c)
    assert n == pytest.approx(0.0, abs=1e-6 * c * length)
    # heading west: head seas, pushing the ship astern
    x, y, n = mean_drift_force(sea, -math.pi / 2, box)
    assert x == pytest.approx(-c * beam, rel=1e-12)
    assert y == pytest.approx(0.0, abs=1e-6 * c)
    # heading east: following seas push it ahead
    assert mean_drift_force(sea, math.pi / 2, box)[0] == pytest.approx(c * beam, rel=1e-12)


def test_drift_force_box_oblique_closed_form_and_symmetry() -> None:
    sea = SeaState(3.0, 9.0, 0.0)
    length, beam = 30.0, 9.6
    c = RHO_G * 9.0 / 16.0
    psi = np.linspace(-math.pi, math.pi, 37)
    x, y, n = mean_drift_force(sea, psi, box_waterline(length, beam))
    beta = -psi
    np.testing.assert_allclose(x, c * beam * np.cos(beta) * np.abs(np.cos(beta)), atol=1e-6 * c)
    np.testing.assert_allclose(y, c * length * np.sin(beta) * np.abs(np.sin(beta)), atol=1e-6 * c)
    np.testing.assert_allclose(n, 0.0, atol=1e-6 * c * length)
    # quadratic in H_s, and pointing where the waves travel
    x2, y2, _ = mean_drift_force(SeaState(6.0, 9.0, 0.0), psi, box_waterline(length, beam))
    np.testing.assert_allclose(x2, 4.0 * x, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(y2, 4.0 * y, rtol=1e-12, atol=1e-9)
    travel = np.cos(beta) * x + np.sin(beta) * y
    assert (travel > 0.0).all()


def test_drift_moment_of_a_pointed_bow() -> None:
    """A pentagon: box stern and sides to ``x = a``, a wedge bow to ``x = L/2``."""
    length, beam, a = 100.0, 20.0, 30.0
    hull = np.array([[-50.0, -10.0], [a, -10.0], [50.0, 0.0], [a, 10.0], [-50.0, 10.0]])
    sea = SeaState(2.0, 8.0, math.pi / 2)
    c = RHO_G * 4.0 / 16.0
    x, y, n = mean_drift_force(sea, 0.0, hull)  # beam seas travelling to starboard
    # lit: port side (length a + L/2, normal -y) and the port bow face
    side = a + length / 2
    dx, dy = length / 2 - a, beam / 2
    face = math.hypot(dx, dy)
    nx, ny = dy / face, -dx / face  # outward normal of the port bow face
    f_face = c * ny**2 * face
    mid = ((a + length / 2) / 2, -beam / 4)
    assert x == pytest.approx(-f_face * nx, rel=1e-12)
    assert y == pytest.approx(c * side - f_face * ny, rel=1e-12)
    expected_n = c * side * (a - length / 2) / 2 + (mid[0] * -f_face * ny - mid[1] * -f_face * nx)
    assert n == pytest.approx(expected_n, rel=1e-12)
    # mirror: waves to port give the opposite sway and yaw, the same surge
    xm, ym, nm = mean_drift_force(sea, math.pi, hull)
    assert (xm, ym, nm) == pytest.approx((x, -y, -n), rel=1e-12)
    # either vertex order
    assert mean_drift_force(sea, 0.0, hull[::-1]) == pytest.approx((x, y, n), rel=1e-12)


# --------------------------------------------------------------------------------------------
# bad inputs
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"significant_height": -1.0}, r"significant_height must be > 0 m, got -1\.0"),
        ({"significant_height": math.nan}, r"significant_height must be finite"),
        ({"peak_period": 0.0}, r"peak_period must be > 0 s, got 0\.0"),
        ({"gamma": 8.0}, r"gamma must be in \[1, 7\], got 8\.0"),
        ({"gamma": 0.5}, r"gamma must be in \[1, 7\]"),
        ({"direction": math.inf}, r"direction must be finite"),
        ({"significant_height": 10.0, "peak_period": 5.0}, r"too steep .* at most 1/7"),
    ],
)
def test_bad_sea_states_are_refused(kwargs: dict[str, float], match: str) -> None:
    args = {"significant_height": 3.0, "peak_period": 9.0, "direction": 0.0} | kwargs
    with pytest.raises(ValueError, match=match):
        SeaState(**args)


def test_bad_arguments_are_refused() -> None:
    with pytest.raises(ValueError, match=r"omega must be >= 0 rad/s, got -0\.5"):
        jonswap_spectrum([1.0, -0.5], 3.0, 9.0)
    with pytest.raises(ValueError, match="omega must be finite"):
        encounter_frequency([math.nan], 1.0, 0.0)
    with pytest.raises(ValueError, match="speed must be finite"):
        encounter_frequency(1.0, math.inf, 0.0)
    with pytest.raises(ValueError, match="n_components must be >= 1, got 0"):
        realise_sea(SEA, 0, n_components=0)
    with pytest.raises(ValueError, match=r"band must be \(low, high\) with 0 <= low < high"):
        realise_sea(SEA, 0, band=(2.0, 1.0))
    with pytest.raises(TypeError, match="sea_state must be a SeaState"):
        realise_sea({"significant_height": 3.0}, 0)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="dt must be a finite step > 0 s"):
        wave_response_model(SEA, 0.0)
    model = wave_response_model(SEA, 0.5)
    with pytest.raises(ValueError, match=r"state and noise must have one shape \(\.\.\., 2\)"):
        model.step(np.zeros((3, 2)), np.zeros((2, 2)))
    with pytest.raises(ValueError, match="n_steps must be >= 0, got -1"):
        model.simulate(-1, 0)
    with pytest.raises(ValueError, match=r"t, north and east must broadcast"):
        realise_sea(SEA, 0, n_components=5).elevation(np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError, match=r"beam must be > 0 m, got 0\.0"):
        box_waterline(10.0, 0.0)
    with pytest.raises(ValueError, match="waterline must be a convex polygon"):
        mean_drift_force(SEA, 0.0, [[0, 0], [2, 0], [1, 0.2], [2, 1], [0, 1]])
    with pytest.raises(ValueError, match=r"waterline must have shape \(m, 2\) with m >= 3"):
        mean_drift_force(SEA, 0.0, [[0, 0], [1, 0]])
    with pytest.raises(ValueError, match="waterline must not repeat a vertex"):
        mean_drift_force(SEA, 0.0, [[0, 0], [1, 0], [1, 0], [0, 1]])
    with pytest.raises(ValueError, match=r"rho must be > 0 kg/m\^3, got -1\.0"):
        mean_drift_force(SEA, 0.0, box_waterline(10.0, 2.0), rho=-1.0)

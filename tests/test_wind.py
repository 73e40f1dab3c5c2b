"""Wind: gust spectra and records, Isherwood's and Blendermann's loads, the Nomoto mapping
(shipgym.models.wind)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.signal import welch

from shipgym.models.wind import (
    BLENDERMANN_COEFFICIENTS,
    GUNNERUS_WIND,
    MARINER_WIND,
    RHO_AIR,
    BlendermannShip,
    IsherwoodShip,
    blendermann_load,
    harris_spectrum,
    isherwood_coefficients,
    isherwood_load,
    mariner_nomoto_wind,
    norsok_spectrum,
    wind_gusts,
)

# a ship with round ratios: 2 A_L / L^2 = 0.2, 2 A_F / B^2 = 1.5, L / B = 5, S / L = 1.2,
# C / L = 0.5, A_SS / A_L = 0.25, M = 2
_SHIP = IsherwoodShip(100.0, 20.0, 1000.0, 300.0, 250.0, 120.0, 50.0, 2.0)


def _coefficients(angle_deg: float, ship: IsherwoodShip = _SHIP) -> tuple[float, float, float]:
    return isherwood_coefficients(math.radians(angle_deg), *ship.args())


# ----------------------------------------------------------------------------- gusts


def test_gust_spectra_closed_form_values() -> None:
    """At f = 0: NORSOK 320 (U/10)^2 (z/10)^0.45, Harris 4 kappa L U / 2^(5/6); NORSOK at
    x = 1 (f = 1/172 Hz for U = 10 m/s, z = 10 m) is 320 / 2^(5/(3 n))."""
    assert norsok_spectrum(0.0, 10.0) == pytest.approx(320.0)
    assert norsok_spectrum(0.0, 20.0, height=40.0) == pytest.approx(320.0 * 4.0 * 4.0**0.45)
    assert norsok_spectrum(1.0 / 172.0, 10.0) == pytest.approx(320.0 / 2.0 ** (5 / (3 * 0.468)))
    assert harris_spectrum(0.0, 10.0) == pytest.approx(4 * 0.0026 * 1800 * 10 / 2 ** (5 / 6))
    f = np.array([0.01, 0.1])
    assert norsok_spectrum(f, 10.0).shape == (2,)


@pytest.mark.parametrize(
    ("spectrum", "peak"),
    [
        # f S(f) peaks at x^n = 3/2 (NORSOK) and x = sqrt(3) (Harris)
        ("norsok", 1.5 ** (1 / 0.468) / 172.0),
        ("harris", math.sqrt(3.0) * 10.0 / 1800.0),
    ],
)
def test_gust_record_has_the_spectrum_it_was_drawn_from(spectrum: str, peak: float) -> None:
    """An 18-hour record's variance is the spectrum's integral over the simulated band, and the
    Welch estimate's integral over the peak region (of f S(f)) is the spectrum's, within 10 %."""
    dt, duration = 1.0, 65536.0
    record = wind_gusts(10.0, duration, dt, seed=7, spectrum=spectrum)
    target = {"norsok": norsok_spectrum, "harris": harris_spectrum}[spectrum]

    def density(f: float) -> float:
        return float(target(f, 10.0))

    variance, _ = quad(density, 1.0 / duration, 0.5 / dt, limit=400)
    assert np.var(record) == pytest.approx(variance, rel=0.10)
    f, psd = welch(record - record.mean(), fs=1.0 / dt, nperseg=4096)
    band = (f >= peak / 2) & (f <= 2 * peak)
    measured = np.trapezoid(psd[band], f[band])
    expected, _ = quad(density, f[band][0], f[band][-1])
    assert measured == pytest.approx(expected, rel=0.10)


def test_gust_record_mean_and_seed() -> None:
    """The record's mean is the mean speed; the same seed gives the same record, another seed
    another; calm air gives zeros."""
    a = wind_gusts(12.0, 1800.0, 0.5, seed=3)
    assert a.shape == (3600,)
    assert a.mean() == pytest.approx(12.0, abs=1e-12)
    assert np.array_equal(a, wind_gusts(12.0, 1800.0, 0.5, seed=3))
    assert not np.allclose(a, wind_gusts(12.0, 1800.0, 0.5, seed=4))
    assert a.std() > 0.5
    assert np.array_equal(wind_gusts(0.0, 10.0, 1.0, seed=1), np.zeros(10))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"mean_speed": -1.0}, "mean_speed must be a finite speed >= 0 m/s, got -1.0"),
        ({"mean_speed": math.nan}, "mean_speed must be a finite speed >= 0 m/s"),
        ({"duration": math.inf}, "duration must be a finite duration > 0 s"),
        ({"duration": 1.0}, "duration must be at least two steps"),
        ({"dt": -0.1}, "dt must be a finite step > 0 s"),
        ({"spectrum": "kaimal"}, "spectrum must be one of"),
        ({"components": 0}, r"components must be an integer in \[1, 100000\]"),
        ({"height": -5.0}, "height must be a finite height > 0 m"),
    ],
)
def test_bad_gust_inputs_are_refused(kwargs: dict, match: str) -> None:
    args = {"mean_speed": 10.0, "duration": 60.0, "dt": 1.0, "seed": 0} | kwargs
    with pytest.raises(ValueError, match=match):
        wind_gusts(**args)


def test_bad_spectrum_inputs_are_refused() -> None:
    with pytest.raises(ValueError, match=r"frequency must be >= 0 Hz, got -0\.1"):
        norsok_spectrum([0.1, -0.1], 10.0)
    with pytest.raises(ValueError, match="frequency must be finite"):
        harris_spectrum([np.nan], 10.0)
    with pytest.raises(ValueError, match="mean_speed must be a finite speed > 0 m/s"):
        harris_spectrum(0.1, -3.0)
    with pytest.raises(ValueError, match="length_scale must be a finite length > 0 m"):
        harris_spectrum(0.1, 3.0, length_scale=0.0)


# ----------------------------------------------------------------------------- Isherwood


@pytest.mark.parametrize(
    ("angle_deg", "cx", "cy", "cn"),
    [
        # by hand from Isherwood's table rows (A_i, B_i, C_i at 0, 30, 90, 150, 180 deg)
        (0.0, -(2.152 - 5.00 * 0.2 + 0.243 * 1.5 - 0.164 * 5), 0.0, 0.0),
        (
            30.0,
            -(1.965 - 4.81 * 0.2 + 0.243 * 1.5 - 0.154 * 5 + 0.041 * 2),
            -(0.225 + 1.38 * 0.2 + 0.023 * 5 - 0.29 * 0.5),
            -(0.2258 + 0.245 * 0.2 - 0.380 * 0.5),
        ),
        (
            90.0,
            -(0.355 - 0.247 * 1.2 + 0.018 * 2),
            -(0.889 + 0.138 * 1.5 - 0.66 * 0.5),
            -(0.2627 - 0.508 * 0.5),
        ),
        (
            150.0,
            -(-0.723 + 3.14 * 0.2 + 0.064 * 5 - 0.475 * 1.2 - 0.032 * 2),
            -(0.536 + 0.176 * 1.5 - 0.029 * 5 - 0.163 * 1.2 + 0.27 * 0.25),
            -(0.0552 - 0.0381 * 1.5 + 0.0109 * 5 + 0.0689 * 1.2 - 0.476 * 0.5),
        ),
        (180.0, -(-2.529 + 3.76 * 0.2 - 0.174 * 1.5 + 0.128 * 5 + 1.55 * 0.5), 0.0, 0.0),
    ],
)
def test_isherwood_coefficients_against_the_published_table(
    angle_deg: float, cx: float, cy: float, cn: float
) -> None:
    """A wind from starboard (g > 0): C_X from the table (aft in a head wind, forward from
    astern), C_Y to port (leeward), C_N the bow to leeward on the bow, the stern on the
    quarter."""
    got = _coefficients(angle_deg)
    assert got == (pytest.approx(cx, abs=1e-12), pytest.approx(cy, abs=1e-12),
                   pytest.approx(cn, abs=1e-12))  # fmt: skip


def test_isherwood_shape_interpolation_and_symmetry() -> None:
    """Head wind pushes aft, following wind forward; |C_Y| peaks between the bow quarter and
    the beam and C_N changes sign between bow and quarter winds; between table angles the
    coefficients are interpolated linearly; X is even in g, Y and N odd; the loads are the
    coefficients times the dynamic pressure and areas."""
    assert _coefficients(0.0)[0] < 0.0 < _coefficients(180.0)[0]
    grid = range(0, 181, 10)
    cy = [abs(_coefficients(a)[1]) for a in grid]
    assert 50 <= 10 * int(np.argmax(cy)) <= 130
    assert _coefficients(30.0)[2] < 0.0 < _coefficients(150.0)[2]
    mid = _coefficients(35.0)
    for k in range(3):
        assert mid[k] == pytest.approx(0.5 * (_coefficients(30.0)[k] + _coefficients(40.0)[k]))
    for angle_deg in (10.0, 47.0, 90.0, 133.0, 170.0):
        x, y, n = isherwood_load(15.0, math.radians(angle_deg), *_SHIP.args())
        xm, ym, nm = isherwood_load(15.0, -math.radians(angle_deg), *_SHIP.args())
        assert (xm, ym, nm) == (pytest.approx(x), pytest.approx(-y), pytest.approx(-n))
        cx, cy_, cn = _coefficients(angle_deg)
        q = 0.5 * RHO_AIR * 15.0**2
        assert (x, y, n) == (pytest.approx(q * 300 * cx), pytest.approx(q * 1000 * cy_),
                             pytest.approx(q * 1000 * 100 * cn))  # fmt: skip


def test_isherwood_ship_refuses_bad_particulars() -> None:
    with pytest.raises(ValueError, match=r"IsherwoodShip\.lateral_area must be a finite number"):
        IsherwoodShip(100.0, 20.0, -1.0, 300.0, 250.0, 120.0, 50.0, 2.0)
    with pytest.raises(ValueError, match=r"IsherwoodShip\.beam must be a finite number > 0"):
        IsherwoodShip(100.0, math.inf, 1000.0, 300.0, 250.0, 120.0, 50.0, 2.0)


# ----------------------------------------------------------------------------- Blendermann


def test_blendermann_research_vessel_row_and_the_gunnerus() -> None:
    """The research-vessel row (C_Dt 0.85, C_Dl,AF 0.55 from ahead and 0.65 from astern,
    delta 0.60; Blendermann 1994, MSS blendermann94.m type 13) in closed form on the Gunnerus:
    at head, following and beam winds D = 1."""
    assert BLENDERMANN_COEFFICIENTS["research_vessel"] == (0.85, 0.55, 0.65, 0.60)
    assert GUNNERUS_WIND.length_overall == 36.25
    a_f, a_l, s_l, l_oa = (GUNNERUS_WIND.frontal_area, GUNNERUS_WIND.lateral_area,
                           GUNNERUS_WIND.centre, GUNNERUS_WIND.length_overall)  # fmt: skip
    q = 0.5 * RHO_AIR * 10.0**2
    x, y, n = blendermann_load(10.0, 0.0, *GUNNERUS_WIND.args())
    assert (x, y, n) == (pytest.approx(-q * a_f * 0.55), 0.0, 0.0)
    x, _, _ = blendermann_load(10.0, math.pi, *GUNNERUS_WIND.args())
    assert x == pytest.approx(q * a_f * 0.65)
    x, y, n = blendermann_load(10.0, math.pi / 2, *GUNNERUS_WIND.args())
    assert x == pytest.approx(0.0, abs=1e-9)
    assert y == pytest.approx(-q * a_l * 0.85)
    assert n == pytest.approx(-q * a_l * l_oa * (s_l / l_oa) * 0.85)
    with pytest.raises(ValueError, match=r"BlendermannShip\.ship_type must be one of"):
        BlendermannShip(90.0, 200.0, 4.0, 36.25, "yacht")
    with pytest.raises(ValueError, match=r"BlendermannShip\.centre must be a finite number"):
        BlendermannShip(90.0, 200.0, 40.0, 36.25, "research_vessel")


# ----------------------------------------------------------------------------- Nomoto


def test_mariner_nomoto_wind_by_hand() -> None:
    """A 20 m/s wind 30 deg on the starboard bow of the Mariner at 15 knots: Isherwood's N_w and
    Y_w by hand from the table's 30 deg rows, delta_w = N_w / (139e-5 1/2 rho U^2 L^3) and the
    leeway v_w = Y_w / (1160e-5 1/2 rho U L^2): both to port (negative)."""
    s = MARINER_WIND
    r1 = 2 * s.lateral_area / s.length_overall**2
    r2 = 2 * s.frontal_area / s.beam**2
    r3 = s.length_overall / s.beam
    r5 = s.centroid / s.length_overall
    cy = -(0.225 + 1.38 * r1 + 0.023 * r3 - 0.29 * r5)
    cn = -(0.2258 + 0.245 * r1 - 0.380 * r5)
    assert r2 > 0
    q_air = 0.5 * 1.224 * 20.0**2
    n_w = q_air * s.lateral_area * s.length_overall * cn
    y_w = q_air * s.lateral_area * cy
    u = 7.7175
    delta_w, v_w = mariner_nomoto_wind(20.0, math.radians(30.0), u)
    assert delta_w == pytest.approx(n_w / (139e-5 * 0.5 * 1025 * u**2 * 160.93**3))
    assert v_w == pytest.approx(y_w / (1160e-5 * 0.5 * 1025 * u * 160.93**2))
    assert delta_w < 0.0 and v_w < 0.0
    assert math.degrees(abs(delta_w)) < 2.0  # a fresh gale on the bow: a degree or so of rudder
    d2, v2 = mariner_nomoto_wind(20.0, -math.radians(30.0), u)
    assert (d2, v2) == (pytest.approx(-delta_w), pytest.approx(-v_w))


def test_the_vmm_wind_terms_fitted_to_blendermann_recover_its_loads() -> None:
    """The comparison of identified wind terms with Blendermann's (scripts/esso_osaka_wind.py):
    terms put through the VMM's wind loads come back from the fit, and Blendermann's loads of
    the Esso Osaka model fitted by the terms keep its beam-wind side force within 10 % and its
    head-wind drag within 50 % (its ``1 / den`` flattens the curves the terms cannot)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    try:
        import esso_osaka_wind as ew
    finally:
        sys.path.pop(0)
    terms = {"X_wc": -2e-5, "Y_ws": -5e-5, "N_ws": 3e-7, "N_w2": -4e-6}
    got = ew.fit_wind_terms(ew.vmm_loads(terms))
    assert got == pytest.approx(terms, rel=1e-9)
    loads = ew.blendermann_loads(1000.0, 3.0)
    fitted = ew.fit_wind_terms(loads)
    beam = int(np.argmin(np.abs(ew._ANGLES - math.pi / 2)))
    head = int(np.argmin(np.abs(ew._ANGLES)))
    assert fitted["Y_ws"] == pytest.approx(loads[1, beam], rel=0.1)
    assert fitted["X_wc"] == pytest.approx(loads[0, head], rel=0.5)
    assert fitted["Y_ws"] < 0.0 and fitted["X_wc"] < 0.0  # pushed to port by a starboard wind

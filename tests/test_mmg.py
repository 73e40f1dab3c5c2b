"""Tests of the MMG standard model and the KVLCC2 (shipgym.models.mmg).

Physics against invariants (self-propulsion equilibrium, rudder sign, a uniform current that
only carries the ship, Froude similarity), and against ShipMMG, an independent implementation:
with ShipMMG's two departures from the paper switched on, shipgym reproduces the trajectories
ShipMMG computed (``python scripts/shipmmg_compare.py`` records them in docs/shipmmg.json).
"""

from __future__ import annotations

import importlib.util
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from shipgym import maneuvers
from shipgym.models import MMGParams, RVGParams, make_model
from shipgym.models.mmg import KVLCC2_SCALE, KVLCC2_SIMMAN_SPEED, KVLCC2_WIND_AREAS
from shipgym.models.wind import (
    BLENDERMANN_COEFFICIENTS,
    RHO_AIR,
    apparent_wind,
    blendermann_load,
)

REPO = Path(__file__).resolve().parents[1]


def _straight(ship, u0: float = KVLCC2_SIMMAN_SPEED) -> np.ndarray:
    """State of straight running at ``u0`` [m/s] (heading north, rudder amidships)."""
    x0 = np.zeros(ship.nx)
    x0[ship.index("u")] = u0
    return x0


def test_self_propulsion_point_holds_the_simman_speed() -> None:
    """At the model's self-propulsion point thrust balances R'_0: straight running at 1.179
    m/s stays there (u' = 0 exactly, no sway or yaw), and 5 % more revolutions accelerate."""
    p = MMGParams.kvlcc2()
    n = p.self_propulsion_rps(KVLCC2_SIMMAN_SPEED)
    assert 11.0 < n < 13.0
    ship = make_model("kvlcc2")
    x0 = _straight(ship)
    d = ship.deriv(x0, [0.0, n])[0]
    assert d[ship.index("u")] == pytest.approx(0.0, abs=1e-12)
    assert d[ship.index("v")] == 0.0 and d[ship.index("r")] == 0.0
    assert ship.deriv(x0, [0.0, 1.05 * n])[0, ship.index("u")] > 0.0
    res = ship.simulate(x0, np.tile([0.0, n], (2000, 1)), 0.05)
    assert res["u"][-1] == pytest.approx(KVLCC2_SIMMAN_SPEED, abs=1e-9)
    assert res["y"][-1] == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError, match="speed"):
        p.self_propulsion_rps(-1.0)


def test_positive_rudder_turns_to_starboard_and_the_gear_is_rate_limited() -> None:
    p = MMGParams.kvlcc2()
    n = p.self_propulsion_rps(KVLCC2_SIMMAN_SPEED)
    ship = make_model("kvlcc2")
    res = ship.simulate(_straight(ship), np.tile([math.radians(20.0), n], (400, 1)), 0.05)
    assert res["r"][-1] > 0.0 and res["psi"][-1] > 0.0
    rate = np.diff(res["delta"]) / 0.05
    assert np.max(rate) <= p.rudder_rate * (1 + 1e-9)
    assert p.rudder_rate == pytest.approx(math.radians(2.32) * math.sqrt(320.0 / 7.0))
    assert res["delta"][-1] == pytest.approx(math.radians(20.0), abs=1e-6)


def test_a_uniform_current_only_carries_the_ship() -> None:
    """For a constant irrotational current the motion through the water is that of calm water:
    heading, yaw rate and rudder are the same and the track is the calm-water track plus the
    current times the time (the relative-velocity formulation, Fossen 2011 property 10.1)."""
    p = MMGParams.kvlcc2()
    n = p.self_propulsion_rps(KVLCC2_SIMMAN_SPEED)
    ship = make_model("kvlcc2")
    cur = np.array([0.3, -0.2])
    cmd = np.tile([math.radians(35.0), n], (1500, 1))
    calm = ship.simulate(_straight(ship), cmd, 0.05)
    x0 = _straight(ship)
    x0[ship.index("u")] += cur[0]  # heading north: the current's surge and sway components
    x0[ship.index("v")] += cur[1]
    moving = ship.simulate(x0, cmd, 0.05, current=cur)
    for k in ("psi", "r", "delta"):
        np.testing.assert_allclose(moving[k], calm[k], atol=1e-9)
    np.testing.assert_allclose(moving["x"], calm["x"] + cur[0] * calm.time, atol=1e-7)
    np.testing.assert_allclose(moving["y"], calm["y"] + cur[1] * calm.time, atol=1e-7)


def test_full_scale_ship_turns_like_the_model_in_ship_lengths() -> None:
    """Froude similarity: the 320 m ship at 1.179 sqrt(320 / 7) m/s, on the trial rig scaled
    with it, makes the model's turning circle in ship lengths, and the 35 deg advance and
    tactical diameter (3.1 L) lie within the SIMMAN 2008 free-running results of about 3.1-3.3 L
    (Yasukawa and Yoshimura 2015)."""
    model = maneuvers.turning_circle("kvlcc2", 35.0)
    full_params = MMGParams.kvlcc2().scaled(KVLCC2_SCALE)
    assert full_params.approach_speed == pytest.approx(7.97, abs=0.01)
    assert full_params.self_propulsion_rps(full_params.approach_speed) == pytest.approx(
        MMGParams.kvlcc2().self_propulsion_rps(KVLCC2_SIMMAN_SPEED) / math.sqrt(KVLCC2_SCALE)
    )
    full = maneuvers.turning_circle(make_model("kvlcc2", full_params), 35.0)
    assert full.particulars.length == pytest.approx(320.0)
    a, b = model.advance / 7.0, model.tactical_diameter / 7.0
    assert 2.9 < a < 3.4 and 2.9 < b < 3.4
    assert full.advance / 320.0 == pytest.approx(a, rel=0.01)
    assert full.tactical_diameter / 320.0 == pytest.approx(b, rel=0.01)


def test_bad_parameters_are_refused() -> None:
    with pytest.raises(ValueError, match="wake_formula"):
        MMGParams(wake_formula="nope")
    with pytest.raises(ValueError, match="length"):
        MMGParams(length=-1.0)
    with pytest.raises(ValueError, match="t_p"):
        MMGParams(t_p=float("nan"))
    with pytest.raises(ValueError, match="unknown MMG parameter set"):
        make_model("kvlcc2", "kcs")
    with pytest.raises(ValueError, match="takes MMGParams, got RVGParams"):
        make_model("kvlcc2", RVGParams())


def _compare_script():
    spec = importlib.util.spec_from_file_location("shipmmg_compare", REPO / "scripts" /
                                                  "shipmmg_compare.py")  # fmt: skip
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_shipmmg_formulas_reproduce_shipmmg_and_the_paper_differs() -> None:
    """With ShipMMG's wake fraction and its U, beta at the centre of gravity, shipgym's
    trajectories give ShipMMG's recorded advance and tactical diameter within 0.2 % and its
    zigzag overshoots within 0.05 deg; the paper's equations differ from ShipMMG by more than
    that (up to about 1 deg of overshoot)."""
    doc = json.loads((REPO / "docs" / "shipmmg.json").read_text())
    mod = _compare_script()
    p = MMGParams.kvlcc2()
    n = p.self_propulsion_rps(KVLCC2_SIMMAN_SPEED)
    assert doc["propeller_rps"] == pytest.approx(n, rel=1e-9)
    recorded = {row["case"]: row for row in doc["rows"]}
    both = replace(p, wake_formula="shipmmg", speed_at_cg=True)
    differs = 0
    for case in mod.cases(p):
        ref = recorded[case["name"]]["ShipMMG"]
        got = case["metric"](mod.run_shipgym(both, case["t"], case["delta"], n))
        paper = case["metric"](mod.run_shipgym(p, case["t"], case["delta"], n))
        for k, v in ref.items():
            tol = 0.05 if k.endswith("_deg") else 2e-3 * abs(v)
            assert got[k] == pytest.approx(v, abs=tol), (case["name"], k)
            differs += abs(paper[k] - v) > tol
    assert differs >= 4


# --------------------------------------------------------------------------------------------
# wind (Blendermann 1994, shipgym.models.wind)

_TANKER = BLENDERMANN_COEFFICIENTS["tanker_loaded"]


def _load(speed: float, angle_deg: float, p: MMGParams) -> tuple[float, float, float]:
    return blendermann_load(speed, math.radians(angle_deg), p.wind_frontal_area,
                            p.wind_lateral_area, p.wind_area_centre, p.length_overall,
                            *_TANKER)  # fmt: skip


def test_blendermann_tanker_coefficients_in_closed_form() -> None:
    """The loaded tanker's published coefficients (C_Dt 0.70, C_Dl,AF 0.90 from ahead and
    0.55 from astern, delta 0.40; Blendermann 1994, MSS blendermann94.m) at head, beam, stern
    and bow-quarter winds, with the wind pushing the ship to leeward and turning a bow wind's
    bow away from it; odd in the angle for Y and N, even for X."""
    assert _TANKER == (0.70, 0.90, 0.55, 0.40)
    p = MMGParams.kvlcc2()
    q = 0.5 * RHO_AIR * 2.5**2
    a_f, a_l, s_l, l_oa = (p.wind_frontal_area, p.wind_lateral_area, p.wind_area_centre,
                           p.length_overall)  # fmt: skip
    x, y, n = _load(2.5, 0.0, p)
    assert (x, y, n) == (pytest.approx(-q * a_f * 0.90), 0.0, 0.0)
    x, y, n = _load(2.5, 180.0, p)
    assert x == pytest.approx(q * a_f * 0.55) and abs(y) < 1e-12 and abs(n) < 1e-12
    x, y, n = _load(2.5, 90.0, p)  # from starboard: to port, moment of the area's centroid
    assert abs(x) < 1e-12
    assert y == pytest.approx(-q * a_l * 0.70)
    assert n == pytest.approx(q * a_l * s_l * -0.70)
    den = 1.0 - 0.5 * 0.40 * (1.0 - 0.90 * a_f / a_l / 0.70)  # sin^2(2 g) = 1 at 45 deg
    x, y, n = _load(2.5, 45.0, p)
    c_y = -0.70 * math.sin(math.pi / 4) / den
    assert x == pytest.approx(-q * a_f * 0.90 * math.cos(math.pi / 4) / den)
    assert y == pytest.approx(q * a_l * c_y)
    assert n == pytest.approx(q * a_l * l_oa * (s_l / l_oa + 0.18 * math.pi / 4) * c_y)
    assert y < 0.0 and n < 0.0  # pushed to port, bow turned to port (away from the wind)
    xm, ym, nm = _load(2.5, -45.0, p)
    assert (xm, ym, nm) == (pytest.approx(x), pytest.approx(-y), pytest.approx(-n))


def test_apparent_wind_is_the_true_wind_less_the_ship_velocity() -> None:
    """Head wind of a ship moving in still air; a true wind from the east on a ship heading
    north at rest comes from starboard; moving, the apparent wind turns towards the bow."""
    assert apparent_wind(0.0, 1.0, 0.3, 1.2, 0.0) == (pytest.approx(1.2), pytest.approx(0.0))
    assert apparent_wind(2.0, math.pi / 2, 0.0, 0.0, 0.0) == (
        pytest.approx(2.0), pytest.approx(math.pi / 2))  # fmt: skip
    speed, angle = apparent_wind(2.0, math.pi / 2, 0.0, 2.0, 0.0)
    assert speed == pytest.approx(2.0 * math.sqrt(2.0)) and angle == pytest.approx(math.pi / 4)
    speed, angle = apparent_wind(1.0, 0.0, math.pi / 2, 0.0, 0.0)  # heading east, wind from N
    assert angle == pytest.approx(-math.pi / 2)  # from port


def test_wind_enters_the_motion_equations_and_no_wind_changes_nothing() -> None:
    """The wind adds Blendermann's load of the apparent wind to the right of eq. 4 (the same
    accelerations as the calm-water ones plus the load through the mass matrix); with no wind
    the ship's wind data change nothing, bit for bit."""
    calm = MMGParams.kvlcc2()
    windy = replace(calm, wind_speed=2.5, wind_direction=0.7)
    n = calm.self_propulsion_rps(KVLCC2_SIMMAN_SPEED)
    x = np.array([1.0, 2.0, 0.4, 1.1, -0.05, 0.01, math.radians(10.0)])
    u = [math.radians(10.0), n]
    d0 = make_model("kvlcc2", calm).deriv(x, u)[0]
    d1 = make_model("kvlcc2", windy).deriv(x, u)[0]
    va, g = apparent_wind(2.5, 0.7, x[2], x[3], x[4])
    xw, yw, nw = _load(va, math.degrees(g), calm)
    m = calm.mass
    mx, my, jz = calm.added_masses
    mass = np.array([[m + my, calm.x_g * m], [calm.x_g * m,
                     calm.yaw_inertia + calm.x_g**2 * m + jz]])  # fmt: skip
    assert d1[3] - d0[3] == pytest.approx(xw / (m + mx), rel=1e-9)
    np.testing.assert_allclose(d1[4:6] - d0[4:6], np.linalg.solve(mass, [yw, nw]), rtol=1e-7)
    np.testing.assert_array_equal(d1[:3], d0[:3])
    other = replace(
        calm, wind_frontal_area=9.0, wind_lateral_area=9.0, wind_area_centre=1.0,
        length_overall=8.0, wind_direction=2.0, wind_ship_type="tanker_ballast",
    )  # fmt: skip
    cmd = np.tile(u, (400, 1))
    x0 = _straight(make_model("kvlcc2"))
    np.testing.assert_array_equal(
        make_model("kvlcc2", other).simulate(x0, cmd, 0.05).states,
        make_model("kvlcc2", calm).simulate(x0, cmd, 0.05).states,
    )


def test_wind_scales_with_the_ship_and_bad_wind_data_are_refused() -> None:
    """Froude similarity with wind: the full-scale ship in the Froude-scaled wind turns like
    the model in ship lengths."""
    windy = replace(MMGParams.kvlcc2(), wind_speed=2.5, wind_direction=1.0)
    full = windy.scaled(KVLCC2_SCALE)
    assert full.wind_speed == pytest.approx(2.5 * math.sqrt(KVLCC2_SCALE))
    assert full.wind_lateral_area == pytest.approx(KVLCC2_WIND_AREAS[1])
    model = maneuvers.turning_circle(make_model("kvlcc2", windy), 35.0)
    ship = maneuvers.turning_circle(make_model("kvlcc2", full), 35.0)
    assert ship.tactical_diameter / 320.0 == pytest.approx(model.tactical_diameter / 7.0, rel=0.01)
    with pytest.raises(ValueError, match="wind_speed must be >= 0"):
        MMGParams(wind_speed=-1.0)
    with pytest.raises(ValueError, match="wind_ship_type must be one of"):
        MMGParams(wind_ship_type="yacht")
    with pytest.raises(ValueError, match="wind_lateral_area must be > 0"):
        MMGParams(wind_lateral_area=0.0)

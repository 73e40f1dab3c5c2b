"""The manoeuvres in wind: the Nomoto family (the Mariner) and the R/V Gunnerus through the
env's seaway (one load function), a vmm with identified wind terms through its apparent-wind
inputs, and ``shipgym simulate ... --wind``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from shipgym import maneuvers as mv
from shipgym.cli import main
from shipgym.maneuvers._common import Rig
from shipgym.models import make_model
from shipgym.models.model_file import nomoto_document
from shipgym.models.rvg import CG_FORWARD_OF_AP, LPP
from shipgym.models.wind import (
    GUNNERUS_WIND,
    RHO_AIR,
    apparent_wind,
    blendermann_load,
    mariner_nomoto_wind,
)
from shipgym.sysid.generator import vmm_truth

SHIPS = {
    "mariner": lambda: "nomoto1",
    "gunnerus_seed001": lambda: make_model("rvg3dof", "seed001"),
    "gunnerus_sea_trials": lambda: make_model("rvg3dof", "sea_trials"),
}


def _wind(speed: float, from_deg: float, **kw) -> dict:
    return {"speed": speed, "direction": math.radians(from_deg), **kw}


def _off_downwind(res: mv.TurningResult, from_deg: float) -> float:
    """The drift's direction less the downwind direction [rad], in [-pi, pi]."""
    return math.remainder(res.drift_direction - math.radians(from_deg + 180.0), 2 * math.pi)


@pytest.mark.parametrize("ship", list(SHIPS))
def test_a_turn_in_wind_drifts_downwind_faster_in_a_stronger_wind(ship: str) -> None:
    model = SHIPS[ship]()
    offsets = {10.0: [], 15.0: []}
    for from_deg in (0.0, 90.0, 225.0):
        light, fresh = (mv.turning_circle(model, 35.0, wind=_wind(v, from_deg)) for v in (10, 15))
        for speed, res in ((10.0, light), (15.0, fresh)):
            offsets[speed].append(_off_downwind(res, from_deg))
        # the wind load grows with the square of the apparent wind: 2.25 times the drift at
        # 1.5 times the wind, a little less (the ship's own velocity is part of the apparent
        # wind); measured 2.09-2.15
        assert 1.8 < fresh.drift_speed / light.drift_speed < 2.4
        assert fresh.drift_speed > 0.02
    for off in offsets.values():
        # the steady turn is the same whichever way the wind blows, turned with it: so is
        # its drift (equal leans to 0.01 deg here)
        assert max(off) - min(off) < math.radians(0.5)
        if ship == "mariner":
            # the Nomoto family has no surge load: its drift is the leeway, which points
            # downwind over a turn of even yaw rate; the equivalent rudder (a few % of the 35 deg)
            # makes the yaw rate uneven around the turn: 0.8-1.3 deg off downwind
            assert abs(off[0]) < math.radians(3.0)
        else:
            # the Gunnerus's speed and yaw rate answer the wind with the lags of its surge and
            # yaw, so its drift leans from downwind to the turn's side: 26 deg (seed001) and
            # 71-77 deg (sea_trials) to starboard; the drift keeps a downwind component
            assert 0.0 < off[0] < math.radians(90.0)


@pytest.mark.parametrize("ship", ["mariner", "gunnerus_seed001"])
def test_a_port_turn_in_wind_is_the_mirror_image(ship: str) -> None:
    model = SHIPS[ship]()
    wind = _wind(15.0, 0.0)  # the mirror about north keeps a north wind
    starboard = mv.turning_circle(model, 35.0, "starboard", wind=wind)
    port = mv.turning_circle(model, 35.0, "port", wind=wind)
    assert port.drift_speed == pytest.approx(starboard.drift_speed, rel=1e-6)
    assert _off_downwind(port, 0.0) == pytest.approx(-_off_downwind(starboard, 0.0), abs=1e-6)


@pytest.mark.parametrize("ship", list(SHIPS))
def test_zero_wind_is_calm_water_bit_for_bit(ship: str) -> None:
    model = SHIPS[ship]()
    calm = mv.turning_circle(model, 35.0)
    still = mv.turning_circle(model, 35.0, wind=_wind(0.0, 90.0))
    assert np.array_equal(calm.series.simulation.states, still.series.simulation.states)
    assert still.drift == calm.drift
    zig_calm = mv.zigzag(model, 20.0, n_reversals=2)
    zig_still = mv.zigzag(model, 20.0, n_reversals=2, wind=_wind(0.0, 45.0))
    assert np.array_equal(zig_calm.series.simulation.states, zig_still.series.simulation.states)


def _states(rig: Rig) -> list[np.ndarray]:
    """The approach state (a straight run at service speed, heading north: the wind from 90
    deg is on the beam) and two others, with heading and sway."""
    out = [rig.x0.copy()]
    for psi, v in ((0.3, 0.4), (-2.0, -0.2)):
        x = rig.x0.copy()
        x[rig.ipsi] = psi
        if "v" in rig.ship.state_names:
            x[rig.ship.index("v")] = v
        out.append(x)
    return out


def test_the_mariners_load_in_a_beam_wind_is_the_library_function() -> None:
    rig = Rig("nomoto1", None, _wind(15.0, 90.0))
    load = rig.wind_load()
    assert load is not None
    speed = rig.ship.index("U")
    for x in _states(rig):
        u = x[speed]
        want = mariner_nomoto_wind(*apparent_wind(15.0, 0.5 * math.pi, x[rig.ipsi], u, 0.0), u)
        # Isherwood's coefficients are linear between his 10 deg angles, which the seaway's
        # 2 deg table holds: the table is the function to rounding
        np.testing.assert_allclose(load(0.0, x), [*want, 0.0], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("params", ["seed001", "sea_trials"])
def test_the_gunnerus_load_in_a_beam_wind_is_blendermanns(params: str) -> None:
    rig = Rig(make_model("rvg3dof", params), None, _wind(15.0, 90.0))
    load = rig.wind_load()
    assert load is not None
    iu, iv = rig.ship.index("u"), rig.ship.index("v")
    arm = 0.5 * LPP - CG_FORWARD_OF_AP  # midship forward of the model's origin
    for x in _states(rig):
        va, g = apparent_wind(15.0, 0.5 * math.pi, x[rig.ipsi], x[iu], x[iv])
        fx, fy, n = blendermann_load(va, g, *GUNNERUS_WIND.args())
        got = load(0.0, x)
        # linear interpolation on the 2 deg table of smooth coefficients: an error of at most
        # h^2 / 8 |C''| = 1.5e-4 |C''| (h = 2 deg) of the load's scale q A_L (q A_L L_oa)
        q_area = 0.5 * RHO_AIR * va * va * GUNNERUS_WIND.lateral_area
        scale = np.array([1.0, 1.0, GUNNERUS_WIND.length_overall]) * q_area
        assert np.all(np.abs(got - [fx, fy, n + arm * fy]) <= 1e-3 * scale)


def test_gusts_are_one_fixed_realisation_about_the_mean_wind() -> None:
    steady = mv.turning_circle("nomoto1", 35.0, wind=_wind(15.0, 90.0))
    gusty, again = (
        mv.turning_circle("nomoto1", 35.0, wind=_wind(15.0, 90.0, gusts=True)) for _ in range(2)
    )
    assert np.array_equal(gusty.series.simulation.states, again.series.simulation.states)
    assert not np.array_equal(gusty.series.simulation.states, steady.series.simulation.states)
    assert abs(_off_downwind(gusty, 90.0)) < math.radians(45.0)
    with pytest.raises(ValueError, match="gusts are modelled for the Nomoto family"):
        mv.turning_circle("kvlcc2", 35.0, wind=_wind(1.0, 90.0, gusts=True))


def test_a_vmm_takes_the_wind_through_its_identified_wind_terms() -> None:
    truth = vmm_truth()
    with pytest.raises(ValueError, match="has no identified wind terms"):
        mv.turning_circle(make_model("vmm", truth), 35.0, wind=_wind(2.0, 90.0))
    terms = {**truth.coefficients, "X_wc": -8e-6, "Y_ws": -2e-5, "N_w2": -3e-6}
    windy = make_model("vmm", truth.with_coefficients(terms))
    calm = mv.turning_circle(windy, 35.0)
    light, fresh = (mv.turning_circle(windy, 35.0, wind=_wind(v, 90.0)) for v in (1.0, 2.0))
    assert calm.drift_speed < 0.05 * light.drift_speed  # (a turn not quite settled)
    # the wind terms go with (V_w / U)^2: about four times the drift at twice the wind
    assert 3.0 < fresh.drift_speed / light.drift_speed < 4.5
    assert abs(_off_downwind(fresh, 90.0)) < math.radians(45.0)  # 27-28 deg to port


def test_a_trials_wind_is_checked() -> None:
    for wind, message in (
        ({"speed": 5.0}, "a trial's wind must be a dict with 'speed'"),
        ({"speed": (5.0, 10.0), "direction": 0.0}, "not a range"),
        ({"speed": 45.0, "direction": 0.0}, r"must be in \[0, 30\] m/s, got 45.0"),
    ):
        with pytest.raises(ValueError, match=message):
            mv.turning_circle("nomoto1", 35.0, wind=wind)


def test_simulate_turning_in_wind_states_the_wind_and_the_drift(tmp_path: Path, capsys) -> None:
    for model, library in (("nomoto1", "nomoto1"), ("rvg3dof", make_model("rvg3dof"))):
        out = tmp_path / f"{model}.json"
        argv = ["simulate", "turning", "--model", model, "--wind", "15,90", "--json", str(out)]
        assert main(argv) == 0
        text = capsys.readouterr().out
        assert "in a true wind of 15 m/s from 090.0 deg, constant" in text
        assert "drift over the steady turn" in text
        doc = json.loads(out.read_text())
        assert doc["wind"] == {"speed_m_s": 15.0, "from_deg": 90.0, "gusts": False}
        if model == "rvg3dof":  # the CLI's Gunnerus is the newest parameter set
            library = make_model("rvg3dof", doc["params"])
        expected = mv.turning_circle(library, 35.0, wind=_wind(15.0, 90.0))
        assert doc["drift_m"] == pytest.approx(list(expected.drift), rel=1e-5)
        assert doc["drift_speed_m_s"] == pytest.approx(expected.drift_speed, rel=1e-5)


def test_simulate_zigzag_in_wind_states_the_wind(tmp_path: Path, capsys) -> None:
    out = tmp_path / "zigzag.json"
    argv = ["simulate", "zigzag", "--model", "rvg3dof", "--wind", "10,270", "--reversals", "2"]
    assert main([*argv, "--json", str(out)]) == 0
    assert "in a true wind of 10 m/s from 270.0 deg" in capsys.readouterr().out
    doc = json.loads(out.read_text())
    assert doc["wind"] == {"speed_m_s": 10.0, "from_deg": 270.0, "gusts": False}
    assert doc["completed"]


def test_simulate_refuses_a_bad_wind_naming_it(tmp_path: Path, capsys) -> None:
    model_file = tmp_path / "fit.json"
    doc = {"nomoto": nomoto_document("nomoto1", {"K": 0.185, "T": 107.3})}
    model_file.write_text(json.dumps(doc))
    for argv, message in (
        (["--model", "nomoto1", "--wind", "15"], "must be SPEED,DIR"),
        (["--model", "nomoto1", "--wind=40,90"], "speed must be in [0, 30] m/s"),
        (["--model", "rvg3dof", "--wind", "fresh,90"], "'fresh,90'"),
        (["--model", str(model_file), "--wind", "15,90"], "not for a 'nomoto1' ship identified"),
        (["--model", "nomoto1", "--gusts"], "--gusts needs --wind"),
    ):
        assert main(["simulate", "turning", *argv]) == 2
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err, err

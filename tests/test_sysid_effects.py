"""Tests of the identification engine with the Nomoto family on generated records.

:func:`shipgym.sysid.engine.identify` with the bases of :mod:`shipgym.sysid.families.nomoto`.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from shipgym.sysid import identify
from shipgym.sysid.data import Record
from shipgym.sysid.families import FAMILIES
from shipgym.sysid.families.base import lag_filter
from shipgym.sysid.families.nomoto import NOMOTO_BASES, NOMOTO_EFFECTS
from shipgym.sysid.generator import EFFECTS_BY_BASE, generate_record

DT = 0.5
DURATION = 600.0


def _record(effect: str | None, maneuver: str = "zigzag", seed: int = 0) -> Record:
    return generate_record(effect, maneuver=maneuver, dt=DT, duration=DURATION, seed=seed)


def test_catalogue_matches_generator() -> None:
    assert set(NOMOTO_EFFECTS) == set(EFFECTS_BY_BASE["nomoto1"])
    assert set(FAMILIES["nomoto1"].catalogue) == set(NOMOTO_EFFECTS)
    # a base that has an effect's term does not offer it
    assert set(NOMOTO_EFFECTS) - set(FAMILIES["nomoto2"].catalogue) == {"second_order"}
    assert set(NOMOTO_EFFECTS) - set(FAMILIES["norrbin"].catalogue) == {"yaw_nonlinearity"}
    assert set(NOMOTO_EFFECTS) - set(FAMILIES["bech"].catalogue) == {
        "second_order",
        "yaw_nonlinearity",
    }
    for base in NOMOTO_BASES:
        for effect in FAMILIES[base].catalogue.values():
            assert effect.term and effect.parameters and effect.source
    # parameters added (the parsimony rule counts them)
    n_added = {name: e.n_added for name, e in NOMOTO_EFFECTS.items()}
    assert n_added == {
        "rudder_offset": 1,
        "yaw_nonlinearity": 3,
        "rudder_lag": 1,
        "input_delay": 1,
        "current": 2,
        "second_order": 2,
    }


@pytest.mark.parametrize("maneuver", ["zigzag", "random"])
@pytest.mark.parametrize("seed", [0, 1])
def test_clean_record_gets_no_effect(maneuver: str, seed: int) -> None:
    res = identify(_record(None, maneuver, seed))
    assert res.effects == []
    assert res.verdict.identifiable, res.verdict.reasons
    assert res.error_after == res.error_before
    # base fit at the noise level (0.1 deg heading noise, 0.02 deg/s yaw-rate noise)
    assert res.error_before["psi_rms_deg"] < 0.2
    assert res.error_before["r_rms_deg_s"] < 0.03
    assert abs(res.parameters_after["K"] - 0.185) < 0.01
    assert abs(res.parameters_after["T"] - 107.3) < 5.0


@pytest.mark.parametrize("dt", [0.1, 1.0])
@pytest.mark.parametrize("maneuver", ["zigzag", "random"])
def test_clean_record_gets_no_effect_at_other_sampling_rates(maneuver: str, dt: float) -> None:
    rec = generate_record(None, maneuver=maneuver, dt=dt, duration=DURATION, seed=0)
    assert identify(rec).effects == []


@pytest.mark.parametrize("dt", [0.1, 1.0])
@pytest.mark.parametrize("effect", ["rudder_offset", "yaw_nonlinearity", "second_order"])
def test_yaw_effect_named_at_other_sampling_rates(effect: str, dt: float) -> None:
    rec = generate_record(effect, maneuver="random", dt=dt, duration=DURATION, seed=1)
    res = identify(rec)
    assert res.effect_names[:1] == [effect], res.rounds[0]
    assert res.error_after["psi_rms_deg"] <= 0.5 * res.error_before["psi_rms_deg"]


@pytest.mark.parametrize(
    "effect", ["rudder_offset", "yaw_nonlinearity", "rudder_lag", "input_delay", "second_order"]
)
def test_yaw_effect_is_named_first_and_halves_the_error(effect: str) -> None:
    res = identify(_record(effect))
    assert res.effects, f"no effect found; rounds: {res.rounds}"
    assert res.effects[0]["name"] == effect, res.rounds[0]
    assert res.error_after["psi_rms_deg"] <= 0.5 * res.error_before["psi_rms_deg"]
    ev = res.effects[0]["evidence"]
    assert ev["delta_J"] < 0
    assert ev["relative_drop"] > 0.2
    assert ev["heldout_rms_after"]["psi"] < ev["heldout_rms_before"]["psi"]
    # the effect's own parameters, from its catalogue entry
    assert set(res.effects[0]["parameters"]) >= set(NOMOTO_EFFECTS[effect].parameters)


def test_a_slow_second_order_mode_does_not_stand_in_for_a_rudder_offset() -> None:
    """On a rudder-offset record the second-order candidate fits a mode far slower than the
    record (an integrator: its T2 fixes only K / T2) and matches the offset's BIC to within
    1 %; its fit is not determined, so it is not significant and the offset is named."""
    rec = generate_record("rudder_offset", maneuver="zigzag", dt=1.0, duration=DURATION, seed=0)
    res = identify(rec, max_effects=1)
    assert res.effect_names == ["rudder_offset"]
    second = res.rounds[0]["second_order"]
    offset = res.rounds[0]["rudder_offset"]
    assert second["delta_J"] < offset["delta_J"] < 0.98 * second["delta_J"]
    assert not second["significant"]
    assert re.match(r"T\d = \d+ s is more than 10 times the record", second["not_determined"])
    assert res.verdict.identifiable
    # the effect's parameters are the whole-record fit's; the training fit is its candidate
    ev = res.effects[0]["evidence"]
    assert res.effects[0]["parameters"]["delta0"] == res.parameters_after["delta0"]
    assert ev["candidate_parameters"]["delta0"] == pytest.approx(math.radians(-2.0), abs=0.005)


def test_effect_parameters_close_to_truth() -> None:
    rec = _record("input_delay")
    res = identify(rec, max_effects=1)
    assert res.effect_names == ["input_delay"]
    assert abs(res.effects[0]["parameters"]["tau"] - 3.0) < 0.75
    rec = _record("rudder_offset")
    res = identify(rec, max_effects=1)
    # delta0 is the rudder ADDED to the record: the truth needs -2 deg
    assert math.degrees(res.parameters_after["delta0"]) == pytest.approx(-2.0, abs=0.2)


def test_current_named_with_positions() -> None:
    rec = _record("current")
    res = identify(rec)
    assert res.effect_names == ["current"]
    truth = rec.meta["truth"]["effect_params"]
    p = res.effects[0]["parameters"]
    assert p["V_n"] == pytest.approx(truth["V_n"], abs=0.05)
    assert p["V_e"] == pytest.approx(truth["V_e"], abs=0.05)
    assert p["speed"] == pytest.approx(math.hypot(p["V_n"], p["V_e"]))
    assert res.error_after["xy_rms_m"] <= 0.5 * res.error_before["xy_rms_m"]
    ev = res.effects[0]["evidence"]
    assert ev["t_stat"] > 5.0
    # the yaw model is unchanged; the held-out dead-reckoning positions improve
    assert ev["heldout_rms_after"]["psi"] == ev["heldout_rms_before"]["psi"]
    assert ev["heldout_rms_after"]["x"] < ev["heldout_rms_before"]["x"]
    assert res.heldout["error_after"] == res.heldout["error_before"]


def test_current_needs_positions() -> None:
    rec = _record("current")
    no_xy = Record(time=rec.time, delta=rec.delta, psi=rec.psi, r=rec.r, U=rec.U)
    res = identify(no_xy)
    assert "current" not in res.effect_names
    assert "xy_rms_m" not in res.error_before


def test_diagnostics_report_whiteness_and_signatures() -> None:
    clean = identify(_record(None))
    lagged = identify(_record("input_delay"), max_effects=0)
    q_clean = clean.diagnostics["base"]["ljung_box"]
    q_lag = lagged.diagnostics["base"]["ljung_box"]
    # white residual: Q ~ chi2(20) (mean 20); a missing delay colours the residual strongly
    assert q_clean < 60.0
    assert q_lag > 10.0 * q_clean
    sig = lagged.diagnostics["base"]["signatures"]
    # the phase-lag signatures explain part of the residual, offset and cubic term none of it
    assert sig["input_delay"]["r2"] > 0.1
    assert sig["input_delay"]["r2"] > 5.0 * sig["rudder_offset"]["r2"]
    assert sig["input_delay"]["r2"] > 5.0 * sig["yaw_nonlinearity"]["r2"]
    # the residual of a delayed ship is correlated with the rudder, the clean one is not
    assert abs(lagged.diagnostics["base"]["xcorr_delta"][0]) > 0.2
    assert abs(clean.diagnostics["base"]["xcorr_delta"][0]) < 0.1
    assert lagged.effects == []
    assert set(lagged.diagnostics["base"]["xcorr_delta"]) >= {0, 5}


def test_progress_and_validation() -> None:
    msgs: list[str] = []
    rec = _record(None)
    identify(rec, max_effects=1, progress=msgs.append)
    assert msgs and msgs[0].startswith("base nomoto1")
    with pytest.raises(ValueError, match="holdout"):
        identify(rec, holdout=0.9)
    with pytest.raises(ValueError, match="model"):
        identify(rec, "abkowitz")
    with pytest.raises(ValueError, match="max_effects"):
        identify(rec, max_effects=-1)
    with pytest.raises(ValueError, match="Record"):
        identify(np.zeros(3))  # type: ignore[arg-type]
    short = Record(time=rec.time[:50], delta=rec.delta[:50], psi=rec.psi[:50], r=rec.r[:50])
    with pytest.raises(ValueError, match="too short"):
        identify(short)


def test_lag_filter_is_the_ship_model_steering_gear() -> None:
    """The compiled ``lag_filter`` takes the steps of ``ShipModel.simulate`` exactly."""
    from shipgym.models import Nomoto1Params, SteeringGear, make_model
    from shipgym.models.nomoto import IDELTA

    rec = _record("rudder_lag")
    t, d = rec.time, rec.delta
    model = make_model("nomoto1", Nomoto1Params(), gear=SteeringGear(time_constant=8.0))
    h = DT / math.ceil(DT / 0.1 - 1e-9)
    tf = t[0] + h * np.arange(round((t[-1] - t[0]) / h) + 1)
    inputs = np.zeros((tf.size - 1, model.nu))
    inputs[:, 0] = np.interp(tf[:-1], t, d)
    x0 = np.zeros(model.nx)
    x0[IDELTA] = 0.01
    sim = model.simulate(x0, inputs, h)
    expected = np.interp(t, tf, sim.states[:, IDELTA])
    np.testing.assert_array_equal(lag_filter(t, d, 8.0, 0.01), expected)

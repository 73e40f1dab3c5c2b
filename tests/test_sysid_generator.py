"""Tests of the synthetic-record generator with one undeclared effect (shipgym.sysid.generator).

The generator and the output-error fitter must agree on clean records (K, T recovered), every
yaw-side effect must make the first-order fit clearly worse, and the current must be invisible to
the yaw fit but visible against a current-free dead-reckoning replay.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.models import Nomoto1Params
from shipgym.sysid.data import Record
from shipgym.sysid.fit import fit_output_error, replay
from shipgym.sysid.generator import EFFECT_DEFAULTS, EFFECTS, NOISE, generate_record

_BASE = Nomoto1Params()
_YAW_EFFECTS = tuple(e for e in EFFECTS if e != "current")
#: Smallest accepted ratio of the effect's psi residual RMS to the clean one (measured >= 7).
_MIN_RATIO = 3.0


def _fit(rec: Record):
    return fit_output_error(rec.time, rec.delta, rec.psi, rec.r, "nomoto1")


@pytest.fixture(scope="module")
def clean_fits() -> dict[str, object]:
    return {m: _fit(generate_record(None, maneuver=m, seed=1)) for m in ("zigzag", "random")}


@pytest.mark.parametrize("maneuver", ["zigzag", "random"])
@pytest.mark.parametrize("dt", [0.1, 0.5, 1.0])
def test_clean_record_fits_truth(maneuver: str, dt: float) -> None:
    rec = generate_record(None, maneuver=maneuver, dt=dt, seed=2)
    n = round(600.0 / dt) + 1
    assert rec.time.shape == (n,)
    np.testing.assert_allclose(np.diff(rec.time), dt, rtol=1e-9)
    for name in ("x", "y", "U"):
        assert getattr(rec, name) is not None
    fit = _fit(rec)
    assert fit.values["K"] == pytest.approx(_BASE.K, rel=0.02)
    assert fit.values["T"] == pytest.approx(_BASE.T, rel=0.03)
    # the residual is the sensor noise (the replayed rudder noise adds a slow heading drift, up
    # to about 2x the heading noise at dt = 1 s; see the generator's module docstring)
    assert fit.rms_r == pytest.approx(NOISE["r"], rel=0.1)
    assert NOISE["psi"] * 0.9 < fit.rms_psi < 2.5 * NOISE["psi"]
    assert rec.meta["truth"]["effect"] is None
    assert rec.meta["truth"]["model"] == "nomoto1"


@pytest.mark.parametrize("maneuver", ["zigzag", "random"])
@pytest.mark.parametrize("effect", _YAW_EFFECTS)
def test_effect_degrades_first_order_fit(effect: str, maneuver: str, clean_fits) -> None:
    rec = generate_record(effect, maneuver=maneuver, seed=1)
    truth = rec.meta["truth"]
    assert truth["effect"] == effect
    assert truth["magnitude"] == pytest.approx(EFFECT_DEFAULTS[effect])
    assert truth["effect_params"]
    fit = _fit(rec)
    clean = clean_fits[maneuver]
    assert fit.rms_psi > _MIN_RATIO * clean.rms_psi, (effect, fit.rms_psi / clean.rms_psi)


@pytest.mark.parametrize("maneuver", ["zigzag", "random"])
def test_current_invisible_in_yaw_visible_in_track(maneuver: str, clean_fits) -> None:
    rec = generate_record("current", maneuver=maneuver, seed=1)
    fit = _fit(rec)
    clean = clean_fits[maneuver]
    assert fit.rms_psi == pytest.approx(clean.rms_psi, rel=0.1)
    assert fit.values["K"] == pytest.approx(_BASE.K, rel=0.02)
    assert fit.values["T"] == pytest.approx(_BASE.T, rel=0.03)

    def drift(r: Record, f) -> tuple[np.ndarray, float]:
        sim = replay("nomoto1", f.params, r.time, r.delta + f.delta0, f.x0, U=r.U)
        dx, dy = r.x - sim[:, 0], r.y - sim[:, 1]
        slope = np.array([np.polyfit(r.time, dx, 1)[0], np.polyfit(r.time, dy, 1)[0]])
        return slope, float(np.max(np.hypot(dx, dy)))

    slope, dev = drift(rec, fit)
    clean_rec = generate_record(None, maneuver=maneuver, seed=1)
    clean_slope, clean_dev = drift(clean_rec, clean)
    true_current = np.array(rec.meta["truth"]["current"])
    assert np.hypot(*true_current) == pytest.approx(0.5)
    # dead reckoning without current drifts by the current velocity (0.5 m/s * 600 s = 300 m)
    np.testing.assert_allclose(slope, true_current, atol=0.02)
    assert dev > 250.0
    assert clean_dev < 15.0
    assert np.hypot(*clean_slope) < 0.02


def test_input_delay_is_a_pure_delay_of_the_recorded_rudder() -> None:
    clean = generate_record(None, maneuver="random", noise=False, seed=4, dt=0.5)
    rec = generate_record("input_delay", maneuver="random", noise=False, seed=4, dt=0.5)
    tau = rec.meta["truth"]["effect_params"]["tau"]
    assert tau == pytest.approx(3.0)
    k = round(tau / 0.5)
    np.testing.assert_allclose(rec.delta, clean.delta, atol=1e-12)
    np.testing.assert_allclose(rec.psi[k:], clean.psi[:-k], atol=1e-9)
    np.testing.assert_allclose(rec.psi[:k], 0.0, atol=1e-12)


def test_rudder_lag_records_the_command() -> None:
    rec = generate_record("rudder_lag", maneuver="zigzag", noise=False, seed=0)
    assert set(np.round(np.degrees(np.abs(rec.delta)), 9)) == {20.0}
    assert rec.meta["truth"]["gear"]["time_constant"] == pytest.approx(8.0)
    clean = generate_record(None, maneuver="zigzag", noise=False, seed=0)
    assert np.degrees(np.max(np.abs(np.diff(clean.delta)))) < 2.32 * 0.5 + 1e-9


def test_rudder_offset_not_in_recorded_rudder_and_truth_replays() -> None:
    rec = generate_record("rudder_offset", maneuver="zigzag", noise=False, seed=0)
    truth = rec.meta["truth"]
    assert truth["model"] == "norrbin"
    assert truth["params"]["n0"] == pytest.approx(_BASE.K * math.radians(2.0))
    clean = generate_record(None, maneuver="zigzag", noise=False, seed=0)
    # the recorded rudder is still a symmetric +-20 deg zigzag (no offset in delta)
    assert np.degrees(rec.delta.max()) == pytest.approx(20.0, abs=1e-6)
    assert np.degrees(rec.delta.min()) == pytest.approx(-20.0, abs=1e-6)
    assert not np.allclose(rec.psi, clean.psi, atol=1e-3)
    # a first-order fit WITH a rudder offset recovers it: the effect is a genuine bias
    fit = fit_output_error(rec.time, rec.delta, rec.psi, rec.r, "nomoto1", bias=True)
    assert -fit.values["delta0"] == pytest.approx(math.radians(2.0), rel=0.02)


def test_second_order_truth() -> None:
    rec = generate_record("second_order", noise=False, dt=1.0, duration=100.0)
    p = rec.meta["truth"]["params"]
    assert rec.meta["truth"]["model"] == "nomoto2"
    assert (p["T1"], p["T2"], p["T3"]) == pytest.approx((118.0, 7.8, 18.5))
    assert p["T1"] + p["T2"] - p["T3"] == pytest.approx(_BASE.T)


@pytest.mark.parametrize("effect", [None, *EFFECTS])
def test_undeclared_and_reproducible(effect: str | None) -> None:
    a = generate_record(effect, maneuver="random", seed=7, dt=1.0, duration=200.0)
    b = generate_record(effect, maneuver="random", seed=7, dt=1.0, duration=200.0)
    c = generate_record(effect, maneuver="random", seed=8, dt=1.0, duration=200.0)
    for name in ("time", "delta", "psi", "r", "x", "y", "U"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert not np.array_equal(a.psi, c.psi)
    assert a.meta == b.meta
    # only meta["truth"] says which effect was applied
    other = {k: v for k, v in a.meta.items() if k != "truth"}
    clean = generate_record(None, maneuver="random", seed=7, dt=1.0, duration=200.0)
    assert other == {k: v for k, v in clean.meta.items() if k != "truth"}
    assert a.u is None and a.v is None and a.azimuth is None and a.rpm is None
    # noise does not change the trajectory, only the measurements
    quiet = generate_record(effect, maneuver="random", seed=7, dt=1.0, duration=200.0, noise=False)
    assert np.std(a.psi - quiet.psi) == pytest.approx(NOISE["psi"], rel=0.3)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"effect": "wind"}, "rudder_offset"),
        ({"maneuver": "turning"}, "zigzag"),
        ({"dt": 0.0}, "dt"),
        ({"dt": math.nan}, "dt"),
        ({"dt": "fast"}, "dt"),
        ({"duration": 1.0}, "duration"),
        ({"base_model": "rvg3dof"}, "base_model"),
        ({"magnitude": 1.0}, "effect"),
        ({"effect": "rudder_lag", "magnitude": -1.0}, "> 0"),
        ({"effect": "current", "magnitude": math.inf}, "finite"),
        ({"effect": "second_order", "magnitude": 200.0}, "T1"),
    ],
)
def test_bad_input(kwargs: dict, match: str) -> None:
    effect = kwargs.pop("effect", None)
    with pytest.raises(ValueError, match=match):
        generate_record(effect, **kwargs)


def test_sampling_rate_not_multiple_of_fine_step() -> None:
    rec = generate_record("input_delay", dt=0.25, duration=50.0, magnitude=1.1)
    assert rec.time[1] == pytest.approx(0.25)
    assert rec.meta["truth"]["fine_step"] <= 0.1
    assert rec.meta["truth"]["effect_params"]["tau"] == pytest.approx(1.1, abs=0.05)

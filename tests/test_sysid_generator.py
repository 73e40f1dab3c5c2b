"""Tests of the synthetic-record generator with one undeclared effect (shipgym.sysid.generator).

The generator and the output-error fitter must agree on clean records (K, T recovered), every
yaw-side effect must make the first-order fit clearly worse, and the current must be invisible to
the yaw fit but visible against a current-free dead-reckoning replay.

R/V Gunnerus base (``base_model="rvg3dof"``): a clean record is an independent
``ShipModel.simulate`` of its recorded commands through the propeller law, the sign conventions
are the sea trial's (positive azimuth turns to port, ``delta = -azimuth``), and each effect
changes the motion the way its physics predicts (offset: a port turn for ``alpha_0 > 0``; foil
lift: faster steady turns; current: a drift of ``V_c t``).

MMG KVLCC2 runs (:func:`generate_mmg_runs`): a clean run is ``make_model("kvlcc2")`` simulated
directly, and each effect is what it says (the offset shifts the turn like a rudder change, the
lagged gear's command leads the actual rudder, the delay shifts the motion, the current only
carries the ship, the recorded apparent wind adds up to the true wind).
"""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from shipgym.models import MMGParams, Nomoto1Params, RVGParams, make_model
from shipgym.models import rvg as rvg_model
from shipgym.models.mmg import KVLCC2_SIMMAN_SPEED
from shipgym.sysid.data import Record, wrap_angle
from shipgym.sysid.fit import fit_output_error, replay
from shipgym.sysid.generator import (
    BASE_MODELS,
    EFFECT_DEFAULTS,
    EFFECTS,
    EFFECTS_BY_BASE,
    MMG_DURATION,
    MMG_EFFECT_RANGES,
    MMG_EFFECTS,
    MMG_NOISE,
    MMG_RUNS,
    MMG_SPEED_SPREAD,
    NOISE,
    RANDOM_HOLD,
    RANDOM_MAX_RUDDER,
    RVG_RPM_HOLD,
    RVG_RPM_LEVELS,
    RVG_ZIGZAG_RPM,
    ZIGZAG_ANGLE,
    generate_mmg_runs,
    generate_record,
)

# one worker runs this file: its module fixtures are built once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_sysid_generator")

_BASE = Nomoto1Params()
_NOMOTO_EFFECTS = EFFECTS_BY_BASE["nomoto1"]
_RVG_EFFECTS = EFFECTS_BY_BASE["rvg3dof"]
_YAW_EFFECTS = tuple(e for e in _NOMOTO_EFFECTS if e != "current")
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


@pytest.mark.parametrize("effect", [None, *_NOMOTO_EFFECTS])
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
        ({"base_model": "kvlcc2"}, "base_model"),
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


# --------------------------------------------------------------------------------------------
# R/V Gunnerus base (base_model="rvg3dof")
# --------------------------------------------------------------------------------------------


def _rvg(effect: str | None = None, **kwargs) -> Record:
    return generate_record(effect, base_model="rvg3dof", **kwargs)


def _rvg_replay(rec: Record, params: RVGParams, alpha_0: float = 0.0) -> np.ndarray:
    """Independent simulation of a record's commands (needs dt = fine step, e.g. 0.1 s).

    The propeller law turns the recorded rpm into the thrust command at every step; the pods
    get the recorded azimuth plus ``alpha_0``.
    """
    truth = rec.meta["truth"]
    assert truth["fine_step"] == pytest.approx(rec.dt)
    model = make_model("rvg3dof", params)
    current = np.array(truth["current"])

    def controller(t: float, x: np.ndarray) -> list[float]:
        k = round(t / rec.dt)
        t1, t2 = rvg_model.pod_thrusts(rec.rpm[k], x, current, model.p)
        alpha = rec.azimuth[k] + alpha_0
        return [t1, t2, alpha, alpha]

    sim = model.simulate(truth["x0"], controller, rec.dt, n_steps=rec.n - 1, current=current)
    return sim.states


def _held(rec: Record, seconds: float) -> np.ndarray:
    """Samples at which both commands have been constant for at least ``seconds``."""
    k = round(seconds / rec.dt)
    same = (np.diff(rec.azimuth) == 0.0) & (np.diff(rec.rpm) == 0.0)
    run = np.zeros(rec.n, dtype=int)
    for i in range(1, rec.n):
        run[i] = run[i - 1] + 1 if same[i - 1] else 0
    return run >= k


def test_effect_catalogue_per_base() -> None:
    assert BASE_MODELS == ("nomoto1", "rvg3dof")
    assert _RVG_EFFECTS == (
        "thruster_lift",
        "azimuth_offset",
        "current",
        "sway_offset",
        "wave_resistance",
    )
    assert EFFECTS == (
        *_NOMOTO_EFFECTS,
        "thruster_lift",
        "azimuth_offset",
        "sway_offset",
        "wave_resistance",
    )
    assert set(EFFECT_DEFAULTS) == set(EFFECTS)
    assert EFFECT_DEFAULTS["thruster_lift"] == pytest.approx(5.22e3, rel=0.01)
    assert EFFECT_DEFAULTS["azimuth_offset"] == pytest.approx(math.radians(2.0))


@pytest.mark.parametrize("maneuver", ["zigzag", "random"])
def test_rvg_clean_record_is_an_independent_simulation_of_its_commands(maneuver: str) -> None:
    rec = _rvg(maneuver=maneuver, dt=0.1, duration=300.0, noise=False, seed=3)
    states = _rvg_replay(rec, RVGParams())
    for name, i in (("x", 0), ("y", 1), ("psi", 2), ("u", 3), ("v", 4), ("r", 5)):
        np.testing.assert_allclose(getattr(rec, name), states[:, i], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(rec.delta, -rec.azimuth)
    np.testing.assert_allclose(rec.U, np.hypot(rec.u, rec.v), rtol=1e-15)
    # the start is steady straight running at the initial rpm: the only nonzero rate is x' = u
    truth = rec.meta["truth"]
    model = make_model("rvg3dof", RVGParams())
    x0 = np.array(truth["x0"])
    thrust = rvg_model.pod_thrust(rec.rpm[0], x0[rvg_model.IU], model.p)
    assert x0[rvg_model.IT1] == x0[rvg_model.IT2] == pytest.approx(thrust, rel=1e-12)
    rates = model.deriv(x0, [thrust, thrust, 0.0, 0.0])[0]
    assert rates[rvg_model.IX] == pytest.approx(x0[rvg_model.IU])
    assert np.max(np.abs(rates[rvg_model.IY :])) < 1e-9
    assert x0[rvg_model.IPSI] == 0.0 and x0[rvg_model.IR] == 0.0 and x0[rvg_model.IV] == 0.0


def test_rvg_zigzag_commands_and_sign_convention() -> None:
    rec = _rvg(noise=False)
    assert rec.duration == pytest.approx(1200.0) and rec.dt == pytest.approx(0.5)
    assert rec.n == 2401
    for name in ("x", "y", "u", "v", "U", "azimuth", "rpm"):
        assert getattr(rec, name) is not None
    np.testing.assert_array_equal(rec.rpm, RVG_ZIGZAG_RPM)
    assert set(np.round(np.abs(rec.azimuth), 12)) == {round(ZIGZAG_ANGLE, 12)}
    # delta = -azimuth starts at +20 deg: a starboard turn, so the raw azimuth is negative
    assert rec.delta[0] == pytest.approx(ZIGZAG_ANGLE) and rec.azimuth[0] < 0.0
    # steady running at 170 rpm: the sea trial's 5.2-5.3 m/s
    assert rec.u[0] == pytest.approx(5.25, abs=0.1)
    first = rec.time < 10.0
    assert np.all(rec.r[first & (rec.time > 1.0)] > 0.0)
    # positive recorded delta (negative azimuth) turns to starboard: at the end of every phase
    # of the zigzag the yaw rate has the sign of delta, and the heading crossed +-20 deg
    ends = np.flatnonzero(np.diff(rec.azimuth) != 0.0)
    assert len(ends) >= 10
    assert np.all(np.sign(rec.r[ends]) == np.sign(rec.delta[ends]))
    np.testing.assert_array_less(ZIGZAG_ANGLE, np.abs(rec.psi[ends + 1]) + 1e-12)
    assert rec.meta["L"] == pytest.approx(33.9)
    assert "Gunnerus" in rec.meta["vessel"]


def test_rvg_random_commands() -> None:
    rec = _rvg(maneuver="random", noise=False, seed=11)
    assert np.max(np.abs(rec.azimuth)) <= RANDOM_MAX_RUDDER
    assert set(rec.rpm) <= set(RVG_RPM_LEVELS)
    assert len(set(rec.rpm)) >= 2
    az_switch = rec.time[1:][np.diff(rec.azimuth) != 0.0]
    rpm_switch = rec.time[1:][np.diff(rec.rpm) != 0.0]
    assert len(az_switch) >= 15
    # hold times (to within the sampling interval) inside the documented ranges
    assert np.min(np.diff(az_switch)) >= RANDOM_HOLD[0] - rec.dt
    assert np.max(np.diff(az_switch)) <= RANDOM_HOLD[1] + rec.dt
    assert np.min(np.diff(rpm_switch)) >= RVG_RPM_HOLD[0] - rec.dt
    assert np.max(np.diff(rpm_switch)) <= RVG_RPM_HOLD[1] + rec.dt
    # the rpm changes make the speed vary (what separates foil lift from thrust)
    assert np.ptp(rec.u) > 1.0


def test_rvg_sway_offset_shifts_only_the_recorded_transverse_speed() -> None:
    clean = _rvg(maneuver="random", duration=200.0, noise=False, seed=4)
    rec = _rvg("sway_offset", maneuver="random", duration=200.0, noise=False, seed=4)
    np.testing.assert_allclose(rec.v - clean.v, 0.2, atol=1e-12)
    for ch in ("psi", "r", "x", "y", "u", "azimuth", "rpm"):
        np.testing.assert_array_equal(getattr(rec, ch), getattr(clean, ch))
    np.testing.assert_allclose(rec.U, np.hypot(rec.u, rec.v))


@pytest.mark.parametrize("maneuver", ["zigzag", "random"])
@pytest.mark.parametrize("alpha_0_deg", [2.0, -2.0])
def test_rvg_azimuth_offset_turns_the_way_alpha_0_predicts(
    maneuver: str, alpha_0_deg: float
) -> None:
    clean = _rvg(maneuver=maneuver, duration=30.0, noise=False, seed=2)
    rec = _rvg(
        "azimuth_offset",
        maneuver=maneuver,
        duration=30.0,
        noise=False,
        seed=2,
        magnitude=math.radians(alpha_0_deg),
    )
    # same start and the same recorded commands (no offset in the record) up to the zigzag's
    # first switch (later the closed-loop zigzag switches on the offset ship's own heading)
    upto = rec.time <= 12.0
    for name in ("azimuth", "delta", "rpm"):
        np.testing.assert_array_equal(getattr(rec, name)[upto], getattr(clean, name)[upto])
    assert rec.meta["truth"]["x0"] == clean.meta["truth"]["x0"]
    # the pods sit alpha_0 further to port-turning azimuth: relative to the commanded ship the
    # offset ship turns to port (r < 0) for alpha_0 > 0 and to starboard for alpha_0 < 0 (the
    # pods slew at their rate limit for the first 2 s, then the difference builds up)
    early = (rec.time >= 4.0) & upto
    assert np.all(np.sign(rec.r[early] - clean.r[early]) == -np.sign(alpha_0_deg))


def test_rvg_azimuth_offset_differs_from_clean_only_through_the_offset() -> None:
    kwargs = {"maneuver": "random", "dt": 0.1, "duration": 300.0, "noise": False, "seed": 6}
    clean = _rvg(**kwargs)
    rec = _rvg("azimuth_offset", **kwargs)
    truth = rec.meta["truth"]
    assert truth["effect_params"] == {"alpha_0": pytest.approx(math.radians(2.0))}
    assert truth["params"]["pod_lift_coefficient"] == 0.0
    np.testing.assert_array_equal(rec.azimuth, clean.azimuth)
    np.testing.assert_array_equal(rec.rpm, clean.rpm)
    assert np.max(np.abs(rec.psi - clean.psi)) > math.radians(5.0)
    # the clean ship driven by the recorded azimuth + alpha_0 is the offset record
    states = _rvg_replay(rec, RVGParams(), alpha_0=math.radians(2.0))
    np.testing.assert_allclose(rec.psi, states[:, 2], rtol=0, atol=1e-9)
    np.testing.assert_allclose(rec.x, states[:, 0], rtol=0, atol=1e-6)
    np.testing.assert_allclose(rec.u, states[:, 3], rtol=0, atol=1e-9)


@pytest.mark.parametrize("seed", [0, 1])
def test_rvg_thruster_lift_steadies_the_turns_at_the_same_commands(seed: int) -> None:
    """The pods' normal force from their own inflow damps sway and yaw like a skeg: at the same
    orders the ship with it turns more slowly than the directionally unstable seed-001 ship."""
    clean = _rvg(maneuver="random", noise=False, seed=seed)
    rec = _rvg("thruster_lift", maneuver="random", noise=False, seed=seed)
    truth = rec.meta["truth"]
    assert truth["params"]["pod_lift_coefficient"] == pytest.approx(
        rvg_model.POD_LIFT_COEFFICIENT_FMU
    )
    assert truth["effect_params"]["c_L"] == pytest.approx(5.22e3, rel=0.01)
    np.testing.assert_array_equal(rec.azimuth, clean.azimuth)
    np.testing.assert_array_equal(rec.rpm, clean.rpm)
    # near-steady turns: the same azimuth (>= 10 deg) and rpm held for 30 s or more
    steady = _held(rec, 30.0) & (np.abs(rec.azimuth) >= math.radians(10.0))
    assert steady.sum() > 100
    assert np.all(np.sign(rec.r[steady]) == np.sign(rec.delta[steady]))
    both = steady & (np.sign(clean.r) == np.sign(clean.delta))
    assert both.sum() > 50
    # (not everywhere: the unstable seed-001 ship is sometimes still swinging into a turn)
    assert np.median(np.abs(rec.r[both]) / np.abs(clean.r[both])) < 0.85


@pytest.mark.parametrize("maneuver", ["zigzag", "random"])
def test_rvg_current_drifts_the_track_by_the_current_velocity(maneuver: str) -> None:
    clean = _rvg(maneuver=maneuver, noise=False, seed=5)
    rec = _rvg("current", maneuver=maneuver, noise=False, seed=5)
    truth = rec.meta["truth"]
    v_n, v_e = truth["current"]
    ep = truth["effect_params"]
    assert ep["speed"] == pytest.approx(0.5) and math.hypot(v_n, v_e) == pytest.approx(0.5)
    assert (ep["V_n"], ep["V_e"]) == pytest.approx((v_n, v_e))
    assert (v_n, v_e) == pytest.approx(
        (0.5 * math.cos(ep["direction"]), 0.5 * math.sin(ep["direction"]))
    )
    # an irrotational current leaves the motion relative to the water unchanged (the ship
    # starts steady in the water): the heading is the clean one and the track drifts by V_c t
    np.testing.assert_allclose(rec.psi, clean.psi, rtol=0, atol=1e-8)
    np.testing.assert_allclose(rec.x - clean.x, v_n * rec.time, rtol=0, atol=1e-4)
    np.testing.assert_allclose(rec.y - clean.y, v_e * rec.time, rtol=0, atol=1e-4)
    assert np.hypot(rec.x - clean.x, rec.y - clean.y)[-1] == pytest.approx(600.0, rel=1e-6)
    # the recorded u, v are over ground: the clean ones plus the body-frame current
    u_c = v_n * np.cos(rec.psi) + v_e * np.sin(rec.psi)
    v_c = -v_n * np.sin(rec.psi) + v_e * np.cos(rec.psi)
    np.testing.assert_allclose(rec.u - clean.u, u_c, rtol=0, atol=1e-8)
    np.testing.assert_allclose(rec.v - clean.v, v_c, rtol=0, atol=1e-8)


@pytest.mark.parametrize("effect", [None, *_RVG_EFFECTS])
def test_rvg_noise_on_measurements_only(effect: str | None) -> None:
    noisy = _rvg(effect, maneuver="random", seed=4)
    quiet = _rvg(effect, maneuver="random", seed=4, noise=False)
    n = noisy.n
    expected = {"psi": "psi", "r": "r", "x": "xy", "y": "xy", "u": "uv", "v": "uv"}
    for channel, key in expected.items():
        err = getattr(noisy, channel) - getattr(quiet, channel)
        # sampling error of a standard deviation: 1 / sqrt(2 n), about 1.4 % here
        assert np.std(err) == pytest.approx(NOISE[key], rel=5.0 / math.sqrt(2 * n)), channel
        assert abs(np.mean(err)) < 5.0 * NOISE[key] / math.sqrt(n), channel
    for channel in ("azimuth", "delta", "rpm"):
        np.testing.assert_array_equal(getattr(noisy, channel), getattr(quiet, channel))
    np.testing.assert_allclose(noisy.U, np.hypot(noisy.u, noisy.v), rtol=1e-15)
    assert noisy.meta["noise"] == pytest.approx(
        {"psi": NOISE["psi"], "r": NOISE["r"], "xy": NOISE["xy"], "uv": NOISE["uv"]}
    )
    assert quiet.meta["noise"] is None


@pytest.mark.parametrize(
    ("effect", "magnitude", "expected"),
    [
        (None, None, {}),
        ("thruster_lift", 3.0e3, {"c_L": 3.0e3}),
        ("azimuth_offset", -0.05, {"alpha_0": -0.05}),
        ("current", 0.3, {"speed": 0.3}),
        ("sway_offset", 0.15, {"v_0": 0.15}),
    ],
)
def test_rvg_truth(effect: str | None, magnitude: float | None, expected: dict) -> None:
    rec = _rvg(effect, magnitude=magnitude, duration=20.0, seed=9)
    truth = rec.meta["truth"]
    assert truth["model"] == "rvg3dof" and truth["base_model"] == "rvg3dof"
    assert truth["effect"] == effect
    assert truth["magnitude"] == magnitude
    for key, value in expected.items():
        assert truth["effect_params"][key] == pytest.approx(value)
    if effect is None:
        assert truth["effect_params"] == {}
    # the parameters are plain JSON and rebuild the true ship
    params = truth["params"]
    assert isinstance(params["added_mass"], list) and len(params["added_mass"]) == 3
    rebuilt = RVGParams(
        **{k: tuple(v) if k in ("pod_x", "pod_y") else v for k, v in params.items()}
    )
    lift = magnitude if effect == "thruster_lift" else 0.0
    assert rebuilt.pod_lift_coefficient == pytest.approx(lift)
    np.testing.assert_array_equal(rebuilt.added_mass, RVGParams().added_mass)
    assert truth["base_params"]["pod_lift_coefficient"] == 0.0
    speed = magnitude if effect == "current" else 0.0
    assert math.hypot(*truth["current"]) == pytest.approx(speed)
    assert truth["fine_step"] <= 0.1


@pytest.mark.parametrize("effect", [None, *_RVG_EFFECTS])
def test_rvg_undeclared_and_reproducible(effect: str | None) -> None:
    kwargs = {"maneuver": "random", "dt": 1.0, "duration": 300.0, "base_model": "rvg3dof"}
    a = generate_record(effect, seed=7, **kwargs)
    b = generate_record(effect, seed=7, **kwargs)
    c = generate_record(effect, seed=8, **kwargs)
    for name in ("time", "delta", "azimuth", "rpm", "psi", "r", "x", "y", "u", "v", "U"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert not np.array_equal(a.psi, c.psi)
    assert not np.array_equal(a.azimuth, c.azimuth)
    assert a.meta == b.meta
    other = {k: v for k, v in a.meta.items() if k != "truth"}
    clean = generate_record(None, seed=7, **kwargs)
    assert other == {k: v for k, v in clean.meta.items() if k != "truth"}


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"effect": "wind", "base_model": "rvg3dof"}, r"'wind'.*'rvg3dof'.*thruster_lift"),
        ({"effect": "rudder_lag", "base_model": "rvg3dof"}, r"'rudder_lag'.*'rvg3dof'.*current"),
        ({"effect": "second_order", "base_model": "rvg3dof"}, r"'second_order'.*'rvg3dof'"),
        ({"effect": "thruster_lift"}, r"'thruster_lift'.*'nomoto1'.*rudder_offset"),
        ({"effect": "azimuth_offset", "base_model": "nomoto1"}, r"'azimuth_offset'.*'nomoto1'"),
        ({"effect": "thruster_lift", "base_model": "rvg3dof", "magnitude": -1.0}, ">= 0"),
        ({"effect": "azimuth_offset", "base_model": "rvg3dof", "magnitude": 2.0}, "alpha_0"),
        ({"effect": "current", "base_model": "rvg3dof", "magnitude": -0.1}, ">= 0"),
        ({"effect": "current", "base_model": "rvg3dof", "magnitude": math.nan}, "finite"),
        ({"base_model": "rvg3dof", "magnitude": 1.0}, "effect"),
        ({"base_model": "rvg3dof", "maneuver": "turning"}, "zigzag"),
        ({"base_model": "rvg3dof", "duration": 1.0}, "duration"),
    ],
)
def test_rvg_bad_input(kwargs: dict, match: str) -> None:
    effect = kwargs.pop("effect", None)
    with pytest.raises(ValueError, match=match):
        generate_record(effect, **kwargs)


# --------------------------------------------------------------------------------------------
# runs of the MMG KVLCC2 (generate_mmg_runs)


def _mmg(effect: str | None = None, n_runs: int = 2, **kwargs) -> list[Record]:
    return generate_mmg_runs(effect, n_runs=n_runs, noise=kwargs.pop("noise", False), **kwargs)


def _direct(rec: Record, command: Callable[[np.ndarray], np.ndarray], **changes) -> object:
    """``make_model("kvlcc2")`` (with ``changes`` to its parameters) simulated from the record's
    true initial state at its fine step with the rudder command ``command(t)`` and the
    record's propeller revolutions, over the record's length."""
    truth = rec.meta["truth"]
    h = truth["fine_step"]
    t = np.arange(round(rec.time[-1] / h)) * h
    ship = make_model("kvlcc2", replace(MMGParams.kvlcc2(), **changes))
    u = np.column_stack((command(t), np.full(t.size, truth["rps"])))
    return ship.simulate(np.array(truth["x0"]), u, h)


def _turn(rec: Record, angle: float, offset: float = 0.0) -> Callable[[np.ndarray], np.ndarray]:
    """The turning run's command: ``offset`` during the approach, then ``angle + offset``."""
    start = rec.meta["truth"]["approach_s"]
    return lambda t: np.where(t < start, 0.0, angle) + offset


def test_mmg_clean_turn_is_the_kvlcc2_simulated_directly() -> None:
    """With no effect and no noise, the 35 deg turn is make_model("kvlcc2") simulated with its
    programme (straight approach, then 35 deg to starboard at constant revolutions); the
    record's rudder is the gear's actual angle and the propeller runs at the approach speed's
    self-propulsion point."""
    rec = _mmg(None, seed=0)[1]
    assert rec.meta["maneuver"] == "turning" and "starboard" in rec.meta["file"]
    sim = _direct(rec, _turn(rec, math.radians(35.0)))
    every = round(rec.dt / rec.meta["truth"]["fine_step"])
    for k in ("psi", "r", "x", "y", "u", "v", "delta"):
        np.testing.assert_array_equal(getattr(rec, k), sim[k][::every])
    speed = rec.meta["truth"]["x0"][3]
    assert abs(speed / KVLCC2_SIMMAN_SPEED - 1.0) <= MMG_SPEED_SPREAD
    assert rec.rpm[0] / 60.0 == pytest.approx(MMGParams.kvlcc2().self_propulsion_rps(speed))
    assert MMG_DURATION[0] <= rec.time[-1] <= MMG_DURATION[1]


def test_mmg_rudder_offset_shifts_the_turn_like_a_rudder_change_of_delta_0() -> None:
    """The actual rudder is the recorded one plus delta_0: the turn is the clean ship's with
    the rudder at 35 deg + delta_0 (the record still says 35 deg), and its steady turn rate
    moves from the clean record's by dr/d(delta) delta_0."""
    clean = _mmg(None, seed=0)[1]
    rec = _mmg("rudder_offset", seed=0)[1]
    d0 = rec.meta["truth"]["effect_parameters"]["delta_0"]
    assert math.radians(1.0) <= abs(d0) <= math.radians(2.0)
    assert d0 < 0.0  # seed 0: the starboard 35 deg turn stays inside the rudder limit
    np.testing.assert_allclose(rec.delta[-100:], math.radians(35.0), atol=1e-9)
    sim = _direct(rec, _turn(rec, math.radians(35.0), d0))
    np.testing.assert_array_equal(rec.psi, sim["psi"][:: round(rec.dt / sim.time[1])])
    lo = _direct(clean, _turn(clean, math.radians(33.0)))["r"][-1]
    slope = (clean.r[-1] - lo) / math.radians(2.0)
    shift = rec.r[-1] - clean.r[-1]
    assert abs(shift) > 0.005 * clean.r[-1]
    assert shift == pytest.approx(slope * d0, rel=0.05)


def test_mmg_rudder_lag_records_the_command_that_leads_the_actual_rudder() -> None:
    """The recorded rudder is the command of a slow gear (T_delta from its range): a clean
    ship with that gear, ordered the recorded rudder, replays the record, and its actual
    rudder crosses zero at each zigzag switch a little over T_delta ln 2 after the recorded
    one (the rate limit slows it at first)."""
    rec = _mmg("rudder_lag", seed=2, dt=0.05)[0]
    t_d = rec.meta["truth"]["effect_parameters"]["T_delta"]
    assert 1.0 <= t_d <= 1.4
    assert set(np.round(np.degrees(rec.delta), 9)) == {0.0, 10.0, -10.0}  # the orders
    sim = _direct(rec, lambda t: rec.delta[: t.size], rudder_time_constant=t_d)
    np.testing.assert_allclose(rec.psi[:-1], sim["psi"][:-1], atol=1e-12)
    actual = sim["delta"]
    for k in np.flatnonzero(np.diff(np.sign(rec.delta[:-1])) != 0)[1:]:  # switches after the 1st
        lag = np.flatnonzero(np.sign(actual[k + 1 :]) == np.sign(rec.delta[k + 1]))[0] + 1
        assert t_d * math.log(2.0) < lag * rec.dt < 1.5 * t_d


def test_mmg_input_delay_records_the_rudder_tau_early() -> None:
    """In the turn, whose programme does not depend on the heading, the record with an input
    delay has the clean record's rudder and the clean motion tau later."""
    clean = _mmg(None, seed=3, dt=0.05)[1]
    rec = _mmg("input_delay", seed=3, dt=0.05)[1]
    tau = rec.meta["truth"]["effect_parameters"]["tau"]
    assert 0.6 - 0.05 <= tau <= 1.0 + 0.05
    d = round(tau / rec.dt)
    np.testing.assert_array_equal(rec.delta, clean.delta)
    for k in ("psi", "r", "u", "v"):
        np.testing.assert_allclose(getattr(rec, k)[d:], getattr(clean, k)[:-d], atol=1e-9)
    assert np.max(np.abs(rec.psi - clean.psi)) > math.radians(1.0)


def test_mmg_current_only_carries_the_ship() -> None:
    """A current of 4-8 % of the approach speed: the ship starts steady in the water, so its
    heading, rudder and motion through the water are the clean record's and its track drifts
    by the current times the time."""
    clean = _mmg(None, seed=4)
    for rc, cur in zip(clean, _mmg("current", seed=4), strict=True):
        p = cur.meta["truth"]["effect_parameters"]
        assert 0.04 <= p["speed"] / KVLCC2_SIMMAN_SPEED <= 0.08
        for k in ("psi", "r", "delta"):
            np.testing.assert_allclose(getattr(cur, k), getattr(rc, k), atol=1e-9)
        np.testing.assert_allclose(cur.x - rc.x, p["V_n"] * cur.time, atol=1e-7)
        np.testing.assert_allclose(cur.y - rc.y, p["V_e"] * cur.time, atol=1e-7)
        u_c = p["V_n"] * np.cos(cur.psi) + p["V_e"] * np.sin(cur.psi)
        np.testing.assert_allclose(cur.u - rc.u, u_c, atol=1e-9)


def test_mmg_report_takes_each_effect_back_out_of_the_records() -> None:
    """The MMG report's bound (``scripts/identify_mmg_records.py``, ``effect_removed``): from a
    record's truth it gives the rudder the ship felt (the gear's actual angle of the slow
    gear, the recorded rudder tau later, or plus the zero error) and, for a current, the
    clean record's motion through the water."""
    spec = importlib.util.spec_from_file_location(
        "identify_mmg_records", Path(__file__).parents[1] / "scripts" / "identify_mmg_records.py"
    )
    assert spec is not None and spec.loader is not None
    report = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(report)
    for rc, back in zip(_mmg(None, seed=4), report.effect_removed(_mmg("current", seed=4)),
                        strict=True):  # fmt: skip
        for k in ("x", "y", "u", "v", "U", "psi", "delta"):
            np.testing.assert_allclose(getattr(back, k), getattr(rc, k), atol=1e-9)
    rec = _mmg("rudder_lag", seed=2, dt=0.05)[0]
    t_d = rec.meta["truth"]["effect_parameters"]["T_delta"]
    actual = _direct(rec, lambda t: rec.delta[: t.size], rudder_time_constant=t_d)["delta"]
    felt = report.effect_removed([rec])[0].delta
    assert np.max(np.abs(felt - rec.delta)) > math.radians(10.0)  # the gear lags the order
    np.testing.assert_allclose(felt[: actual.size], actual[: felt.size], atol=1e-9)
    rec = _mmg("input_delay", seed=3, dt=0.05)[1]
    d = round(rec.meta["truth"]["effect_parameters"]["tau"] / rec.dt)
    felt = report.effect_removed([rec])[0].delta
    np.testing.assert_allclose(felt[d:], rec.delta[:-d], atol=1e-12)
    rec = _mmg("rudder_offset", seed=0)[1]
    felt = report.effect_removed([rec])[0].delta
    d0 = rec.meta["truth"]["effect_parameters"]["delta_0"]
    np.testing.assert_allclose(felt - rec.delta, d0, atol=1e-12)


def test_mmg_wind_records_the_apparent_wind_of_a_constant_true_wind() -> None:
    """The recorded apparent wind plus the ship's velocity over ground is the true wind of the
    truth, constant (2-3 m/s from a seed-drawn direction), and the wind changes the motion."""
    clean = _mmg(None, seed=5)
    runs = _mmg("wind", seed=5)
    p = runs[0].meta["truth"]["effect_parameters"]
    assert 2.0 <= p["speed"] <= 3.0
    for rec, rc in zip(runs, clean, strict=True):
        g, va = rec.wind_angle, rec.wind_speed
        air_x, air_y = -va * np.cos(g) + rec.u, -va * np.sin(g) + rec.v  # air over ground, body
        north = air_x * np.cos(rec.psi) - air_y * np.sin(rec.psi)
        east = air_x * np.sin(rec.psi) + air_y * np.cos(rec.psi)
        np.testing.assert_allclose(north, -p["speed"] * math.cos(p["direction"]), atol=1e-9)
        np.testing.assert_allclose(east, -p["speed"] * math.sin(p["direction"]), atol=1e-9)
        assert rec.rpm[0] == rc.rpm[0]  # the tank's calm-water set-point
    assert max(np.max(np.abs(a.psi - b.psi)) for a, b in zip(runs, clean, strict=True)) > (
        math.radians(1.0))  # fmt: skip


def test_mmg_noise_on_every_channel_meta_and_reproducible() -> None:
    """Noise of the stated size on every channel, the same motions without it; the meta
    states the ship's main particulars as plain keys; a seed gives the same records, another
    seed other headings, lengths and effect sizes."""
    noisy = _mmg("wind", seed=1, noise=True)
    quiet = _mmg("wind", seed=1)
    pairs = list(zip(noisy, quiet, strict=True))
    for k, key in (("psi", "psi"), ("r", "r"), ("x", "xy"), ("y", "xy"), ("u", "uv"),
                   ("v", "uv"), ("delta", "delta"), ("rpm", "rpm"),
                   ("wind_speed", "wind_speed")):  # fmt: skip
        e = np.concatenate([getattr(a, k) - getattr(b, k) for a, b in pairs])
        assert np.std(e) == pytest.approx(MMG_NOISE[key], rel=0.15), k
    e = np.concatenate([wrap_angle(a.wind_angle - b.wind_angle) for a, b in pairs])
    assert np.std(e) == pytest.approx(MMG_NOISE["wind_angle"], rel=0.15)
    meta = noisy[0].meta
    p = MMGParams.kvlcc2()
    assert {k: meta[k] for k in ("L", "B", "draft", "displacement_m3", "x_G",
                                 "propeller_diameter", "rho")} == {
        "L": p.length, "B": p.breadth, "draft": p.draught, "displacement_m3": p.displacement,
        "x_G": p.x_g, "propeller_diameter": p.propeller_diameter, "rho": p.rho,
    }  # fmt: skip
    assert "particulars" not in meta and meta["scale"] == "model"
    again = _mmg("wind", seed=1, noise=True)
    for a, b in zip(noisy, again, strict=True):
        np.testing.assert_array_equal(a.psi, b.psi)
        np.testing.assert_array_equal(a.wind_angle, b.wind_angle)
    other = _mmg("wind", seed=2, noise=True)
    assert other[0].meta["truth"]["effect_parameters"] != meta["truth"]["effect_parameters"]
    assert other[0].time[-1] != noisy[0].time[-1]
    assert [r.meta["file"] for r in generate_mmg_runs(None, noise=False)] == [
        f"MMG run {k + 1} ({label})" for k, label in enumerate((
            "zigzag 10/10 starboard", "turning 35 starboard", "zigzag 20/20 starboard",
            "zigzag 10/10 port", "turning 35 port", "zigzag 20/20 port"))
    ]  # fmt: skip
    assert len(MMG_RUNS) == 8 and set(MMG_EFFECTS) == set(MMG_EFFECT_RANGES)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"effect": "asymmetry"}, "unknown effect 'asymmetry'"),
        ({"n_runs": 0}, r"n_runs must be an integer in \[1, 8\]"),
        ({"n_runs": 2.0}, "n_runs must be an integer"),
        ({"dt": 1.0}, r"dt must be in \[0.01, 0.5\] s, got 1.0"),
        ({"seed": -1}, "seed must be an integer >= 0, got -1"),
        ({"magnitude": 0.0}, "magnitude must be a finite number > 0, got 0.0"),
        ({"magnitude": float("nan")}, "magnitude must be a finite number > 0"),
    ],
)
def test_mmg_bad_input(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        generate_mmg_runs(**kwargs)

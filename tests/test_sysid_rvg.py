"""Tests of the R/V Gunnerus family of the identification engine (shipgym.sysid.families.rvg).

Known truth from the project's generator (seed-001 Gunnerus ship with one undeclared effect,
sensor noise, random azimuth and rpm orders): the right effect is named, its parameter is
recovered, the error drops by at least half, and a clean record gets no effect.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from shipgym.models import RVGParams
from shipgym.models.rvg import POD_LIFT_COEFFICIENT_FMU, POD_SLIPSTREAM_FMU
from shipgym.sysid import identify
from shipgym.sysid.families.rvg import CALIBRATED, replay_windows
from shipgym.sysid.generator import generate_record


def _rvg(effect: str | None, seed: int = 2, maneuver: str = "random", magnitude=None):
    return generate_record(
        effect, base_model="rvg3dof", maneuver=maneuver, seed=seed, magnitude=magnitude
    )


@pytest.mark.parametrize("seed", [0, 2])
def test_clean_rvg_record_gets_no_effect_and_calibration_near_seed001(seed: int) -> None:
    res = identify(_rvg(None, seed=seed), "rvg3dof")
    assert res.effects == []
    assert res.model == "rvg3dof" and res.window_s == 60.0
    base = RVGParams()
    assert res.parameters_before["bollard_thrust"] == pytest.approx(base.bollard_thrust, rel=0.05)
    assert res.parameters_before["surge_quadratic_damping"] == pytest.approx(
        base.surge_quadratic_damping, rel=0.1
    )
    assert set(CALIBRATED) <= set(res.parameters_before)
    # u and positions are simulated (not inputs) for the RVG, so they are scored
    assert {"psi_rms_deg", "r_rms_deg_s", "xy_rms_m", "u_rms_m_s"} <= set(res.error_after)


@pytest.mark.parametrize(
    ("effect", "key", "truth", "tol"),
    [
        ("thruster_lift", "pod_lift_coefficient", POD_LIFT_COEFFICIENT_FMU, 0.15),
        ("azimuth_offset", "alpha_0", math.radians(2.0), 0.15),
        ("current", "speed", 0.5, 0.15),
        ("sway_offset", "v_0", 0.2, 0.15),
        # (inside the fitted range [0, 0.1], whose bound the loop does not accept)
        ("wave_resistance", "wave_resistance", 0.09, 0.15),
    ],
)
def test_rvg_effect_is_named_recovered_and_halves_the_error(
    effect: str, key: str, truth: float, tol: float
) -> None:
    rec = _rvg(effect, magnitude=truth if effect == "wave_resistance" else None)
    res = identify(rec, "rvg3dof")
    assert res.effect_names == [effect]
    assert res.effects[0]["parameters"][key] == pytest.approx(truth, rel=tol)
    # the error of what the effect acts on halves: the speed for a resistance term
    err = "u_rms_m_s" if effect == "wave_resistance" else "psi_rms_deg"
    assert res.error_after[err] < 0.5 * res.error_before[err]
    held = res.heldout
    assert held["error_after"][err] < 0.5 * held["error_before"][err]
    if effect == "current":
        v = rec.meta["truth"]["effect_params"]
        got = res.effects[0]["parameters"]
        assert got["V_n"] == pytest.approx(v["V_n"], abs=0.08)
        assert got["V_e"] == pytest.approx(v["V_e"], abs=0.08)


def test_replay_windows_restart_from_the_measured_state() -> None:
    rec = _rvg(None, seed=0)
    starts = np.array([0, 100, 250])
    sim = replay_windows(rec, RVGParams(), starts)
    measured = np.column_stack((rec.x, rec.y, rec.psi, rec.u, rec.v, rec.r))
    noise = np.array([1.0, 1.0, math.radians(0.1), 0.02, 0.02, math.radians(0.02)])
    for i in starts:  # the local fit of the measurements: within the sensor noise of them
        assert np.all(np.abs(sim[i, :6] - measured[i]) < 3.0 * noise)
        assert not np.allclose(sim[i, :6], measured[i])
    # the truth model replays a noise-free record in 60 s windows within the sampling error
    # (the record's 0.5 s samples of orders that switch between samples); a ship whose pod
    # lift is 20 % off does not (after the first window, whose pod start is a guess). The
    # truth is the ship with pod lift: the seed-001 hull is directionally unstable, and its
    # windows amplify any difference e-fold every 6 s.
    clean = generate_record(
        "thruster_lift", base_model="rvg3dof", maneuver="random", seed=0, noise=False
    )
    starts = np.arange(0, clean.time.size, 120)

    def rms_psi_deg(c_l: float) -> float:
        ship = RVGParams(pod_lift_coefficient=c_l, pod_slipstream=POD_SLIPSTREAM_FMU)
        sim = replay_windows(clean, ship, starts)
        return math.degrees(float(np.sqrt(np.mean((sim[120:, 2] - clean.psi[120:]) ** 2))))

    assert rms_psi_deg(POD_LIFT_COEFFICIENT_FMU) < 0.6
    assert rms_psi_deg(0.8 * POD_LIFT_COEFFICIENT_FMU) > 2.0


def test_replay_places_an_order_change_half_a_sample_before_it_was_logged() -> None:
    """An order logged at 0.5 s changed somewhere in the step before its sample: the replay
    switches it at the step's midpoint, its expected time. A 20 deg azimuth step logged at
    t = 10 s: the pods (rate limit 10 deg/s, which a 20 deg error at 1 s saturates) start
    turning at 9.75 s and stand at 2.5 deg at 10 s and 7.5 deg at 10.5 s (a zero-order hold
    of the samples would start them half a sample late, at 10 s)."""
    from shipgym.models.rvg import IA1, IA2
    from shipgym.sysid.data import Record

    t = np.arange(0.0, 20.0, 0.5)
    az = np.where(t >= 10.0, math.radians(20.0), 0.0)
    n = t.size
    rec = Record(
        time=t, azimuth=az, delta=-az, rpm=np.full(n, 150.0), psi=np.zeros(n), r=np.zeros(n),
        x=5.0 * t, y=np.zeros(n), u=np.full(n, 5.0), v=np.zeros(n),
    )  # fmt: skip
    sim = replay_windows(rec, RVGParams(), np.array([0]))
    k = int(np.flatnonzero(t == 10.0)[0])
    assert np.all(sim[:k, IA1] == 0.0)
    np.testing.assert_allclose(sim[k : k + 2, IA1], np.radians([2.5, 7.5]), rtol=1e-9)
    np.testing.assert_array_equal(sim[:, IA1], sim[:, IA2])


def test_rvg_identification_rejects_records_without_rpm_or_positions() -> None:
    rec = generate_record(None, maneuver="zigzag", seed=0)  # a Nomoto record: no rpm
    with pytest.raises(ValueError, match="rpm"):
        identify(rec, "rvg3dof")
    short = _rvg(None)
    with pytest.raises(ValueError, match="window"):
        identify(short, "rvg3dof", window_s=1000.0)


@pytest.mark.parametrize(
    ("effect", "maneuver", "dt"),
    [
        (None, "zigzag", 1.0),
        ("azimuth_offset", "zigzag", 1.0),
        ("current", "zigzag", 0.25),
        ("thruster_lift", "random", 1.0),
        ("sway_offset", "zigzag", 0.5),
    ],
)
def test_rvg_effects_on_other_manoeuvres_and_sampling_rates(
    effect: str | None, maneuver: str, dt: float
) -> None:
    rec = generate_record(effect, base_model="rvg3dof", maneuver=maneuver, seed=1, dt=dt)
    res = identify(rec, "rvg3dof")
    assert res.effect_names == ([] if effect is None else [effect])
    if effect is not None:
        assert res.error_after["psi_rms_deg"] < 0.5 * res.error_before["psi_rms_deg"]


def _steady(params: RVGParams, rpm: float, azimuth_deg: float) -> tuple[float, float, float]:
    """Straight speed, then steady yaw rate [deg/s], diameter [m] and speed ratio at azimuth."""
    from shipgym.sysid.families.rvg import simulate_orders

    t = np.arange(0.0, 600.0, 0.5)
    rpm_in = np.full(t.size, rpm)
    s = simulate_orders(params, t, rpm_in, np.zeros(t.size), np.array([0, 0, 0, 5.0, 0, 0]))
    u0 = math.hypot(s[-1, 3], s[-1, 4])
    turn = simulate_orders(params, t, rpm_in, np.full(t.size, math.radians(azimuth_deg)), s[-1])
    tail = turn[-200:]
    speed = float(np.hypot(tail[:, 3], tail[:, 4]).mean())
    r = float(tail[:, 5].mean())
    return math.degrees(r), 2.0 * speed / abs(r), speed / u0


@pytest.mark.parametrize(
    ("rpm", "azimuth_deg", "r_deg_s", "diameter_m", "ratio"),
    [(170.0, 10.0, (2.26, 2.45), (223, 248), (0.85, 0.92)),
     (165.0, 20.0, (3.47, 3.55), (122, 124), (0.71, 0.73)),
     (106.0, 30.0, (2.66, 2.95), (68, 82), (0.49, 0.57))],
)  # fmt: skip
def test_sea_trials_set_turns_like_the_real_ship(
    rpm: float, azimuth_deg: float, r_deg_s: tuple, diameter_m: tuple, ratio: tuple
) -> None:
    """The shipped sea-trial set reproduces the settled turns of the Gunnerus trials
    (RVG_PARAMETERS.md: yaw rate within 10 %, diameter within 15 %, speed ratio within 0.05 of
    the measured ranges); seed 001 does not. Positive azimuth turns to port."""

    def within(x: float, rng: tuple, rel: float = 0.0, tol: float = 0.0) -> bool:
        return rng[0] * (1 - rel) - tol <= x <= rng[1] * (1 + rel) + tol

    r, d, q = _steady(RVGParams.sea_trials(), rpm, azimuth_deg)
    assert r < 0.0
    assert within(-r, r_deg_s, rel=0.10)
    assert within(d, diameter_m, rel=0.15)
    assert within(q, ratio, tol=0.05)
    r, d, q = _steady(RVGParams(), rpm, azimuth_deg)
    assert not (within(-r, r_deg_s, rel=0.10) and within(d, diameter_m, rel=0.15))


@pytest.mark.parametrize(("rpm", "speed"), [(110.0, 3.72), (170.0, 5.45), (195.0, 6.10)])
def test_sea_trials_set_runs_straight_at_the_measured_speeds(rpm: float, speed: float) -> None:
    """Straight running at the trials' rpm orders settles within 3 % of the measured mean
    speeds (RVG_PARAMETERS.md; the runs on opposite headings differ by 4-10 % around these
    means: current and wind). (Seed 001, held exactly straight, is 10 % slow at 110 rpm and
    1 % slow at 195 rpm: its resistance grows as u^2 only.)"""
    from shipgym.sysid.families.rvg import simulate_orders

    t = np.arange(0.0, 900.0, 0.5)
    s = simulate_orders(
        RVGParams.sea_trials(), t, np.full(t.size, rpm), np.zeros(t.size), np.zeros(6)
    )
    assert abs(s[-1, 3] - s[-200, 3]) < 1e-3  # settled
    assert s[-1, 3] == pytest.approx(speed, rel=0.03)


def test_sea_trials_loop_names_the_pod_lift_first() -> None:
    """On the real Gunnerus trials the loop from the seed-001 base names the pod normal force
    first, with a coefficient within a factor 2 of the Kongsberg pod data, and cuts the held-out
    heading error at least fourfold against the calibrated base."""

    from shipgym.sysid import load
    from shipgym.sysid.data import measured_root

    path = measured_root() / "gunnerus_seatrials/RVG_ManeuveringTests.csv"
    if not path.exists():
        pytest.skip(f"measured record not found: {path} (set SHIPGYM_MEASURED_DATA)")
    res = identify(load(path), "rvg3dof", max_effects=1)
    assert res.effect_names == ["thruster_lift"]
    c_l = res.effects[0]["parameters"]["pod_lift_coefficient"]
    assert 0.5 * POD_LIFT_COEFFICIENT_FMU < c_l < 2.0 * POD_LIFT_COEFFICIENT_FMU
    held = res.heldout
    assert held["error_after"]["psi_rms_deg"] < 0.25 * held["error_before"]["psi_rms_deg"]
    assert held["error_after"]["psi_rms_deg"] < held["error_seed001"]["psi_rms_deg"] / 5


def test_propeller_hull_interaction_fits_the_wake_with_holtrops_thrust_deduction() -> None:
    """Without a thrust measurement ``t`` and the bollard thrust are one product, so the effect
    fits ``w`` only and takes Holtrop and Mennen's twin-screw ``t = 0.325 C_B - 0.1885 D /
    sqrt(B T)``: 0.137 for the Gunnerus (C_B 0.637 from 574 t on 33.9 x 9.6 x 2.7 m, D 1.9 m)."""
    from shipgym.models.rvg import THRUST_DEDUCTION_HOLTROP
    from shipgym.sysid.families.rvg import RVG_EFFECTS, apply_values

    c_b = 574_127.69 / 1025.0 / (33.9 * 9.6 * 2.7)
    assert c_b == pytest.approx(0.637, abs=1e-3)
    expected = 0.325 * c_b - 0.1885 * 1.9 / math.sqrt(9.6 * 2.7)
    assert THRUST_DEDUCTION_HOLTROP == pytest.approx(expected, rel=1e-12)
    assert 0.13 < THRUST_DEDUCTION_HOLTROP < 0.14
    assert RVG_EFFECTS["propeller_hull_interaction"].parameters == ("wake_fraction",)
    p = apply_values(RVGParams(), {"wake_fraction": 0.1})
    assert (p.thrust_deduction, p.wake_fraction) == (THRUST_DEDUCTION_HOLTROP, 0.1)
    assert apply_values(RVGParams(), {}).thrust_deduction == 0.0


def test_sea_trials_thrust_on_the_hull_agrees_with_mcsims_thrust_coefficient() -> None:
    """The identified thrust at the rpm order, 0.70 of the Kongsberg open-water table, is inside
    its documented range (not at a bound) and within 10 % of the thrust MCSim's own manoeuvring
    model gives the hull (``F = C_t n^2``, ``C_t`` = 2.2: 88 kN at 200 rpm); split with
    Holtrop's thrust deduction, the pods deliver within 20 % of the Kongsberg table."""
    from shipgym.models.rvg import THRUST_DEDUCTION_HOLTROP

    p = RVGParams.sea_trials()
    band = CALIBRATED["bollard_thrust"]
    span = band.high - band.low
    assert band.low + 0.01 * span < p.bollard_thrust < band.high - 0.01 * span
    assert p.bollard_thrust == pytest.approx(2.2 * 200.0**2, rel=0.10)
    pods = p.bollard_thrust / (1.0 - THRUST_DEDUCTION_HOLTROP)
    assert abs(pods / RVGParams().bollard_thrust - 1.0) < 0.20


def test_the_days_current_explains_the_opposite_heading_straight_speeds() -> None:
    """On the trials the runs at one rpm order are 0.2-0.3 m/s faster eastbound than westbound.
    A constant current fitted to the whole record (the ship held at the sea-trial set) sets
    eastward, and predicting the straights in it cuts their RMS speed error by at least a fifth
    (the two 110 rpm runs heading east and north-east stay 3-6 % slow: the current is not
    constant over 2.5 h of tide)."""

    from shipgym.sysid import load
    from shipgym.sysid import manoeuvres as mn
    from shipgym.sysid.data import measured_root
    from shipgym.sysid.families.base import window_starts
    from shipgym.sysid.families.rvg import RVG_WINDOW_S, fit_rvg, simulate_orders

    path = measured_root() / "gunnerus_seatrials/RVG_ManeuveringTests.csv"
    if not path.exists():
        pytest.skip(f"measured record not found: {path} (set SHIPGYM_MEASURED_DATA)")
    rec = load(path)
    starts = window_starts(rec.time, RVG_WINDOW_S)
    mask = np.ones(rec.time.size, dtype=bool)
    mask[starts] = False
    ship = RVGParams.sea_trials()
    fit = fit_rvg(rec, starts, mask, ("current",), base=ship, calibrate=False)
    v_n, v_e = fit.current
    assert 0.08 < v_e < 0.3 and abs(v_n) < 0.15

    def model(current: tuple[float, float]):
        return lambda t, rpm, az, x0: simulate_orders(ship, t, rpm, az, x0, current=current)

    straights = [m for m in mn.extract_manoeuvres(rec) if m.kind == "straight"]
    rows = mn.validation_table(
        straights, rec, {"calm": model((0.0, 0.0)), "current": model(fit.current)}
    )
    rms = {
        k: float(np.sqrt(np.mean([r["errors"][k]["speed_pct"] ** 2 for r in rows])))
        for k in ("calm", "current")
    }
    assert len(rows) == 11
    assert rms["current"] < 0.8 * rms["calm"], rms


def test_screening_fit_on_thinned_samples_agrees_with_the_full_fit() -> None:
    """Candidate effects are fitted on the record thinned to 1 s steps: on a record with the
    pod lift, the thinned fit recovers the same lift coefficient as the full one (within 3 %)
    from the same start, and a bad stride is refused."""
    from shipgym.sysid.families.base import window_starts
    from shipgym.sysid.families.rvg import fit_rvg

    rec = _rvg("thruster_lift")
    starts = window_starts(rec.time, 60.0)
    mask = np.ones(rec.time.size, dtype=bool)
    mask[starts] = False
    full = fit_rvg(rec, starts, mask, ("thruster_lift",), calibrate=False)
    thin = fit_rvg(rec, starts, mask, ("thruster_lift",), calibrate=False, stride=2)
    key = "pod_lift_coefficient"
    assert thin.values[key] == pytest.approx(full.values[key], rel=0.03)
    assert full.values[key] == pytest.approx(POD_LIFT_COEFFICIENT_FMU, rel=0.15)
    for bad in (0, 1.5, True):
        with pytest.raises(ValueError, match="stride"):
            fit_rvg(rec, starts, mask, ("thruster_lift",), calibrate=False, stride=bad)


def _forces(params: RVGParams, x: np.ndarray) -> np.ndarray:
    """Surge, sway force and yaw moment ``M nu'`` of the model at state ``x`` with the thrust
    and azimuth orders at the pods' states (the pod dynamics at rest)."""
    from shipgym.models import make_model
    from shipgym.models.rvg import IA1, IA2, IR, IT1, IT2, IU

    model = make_model("rvg3dof", params)
    d = model.deriv(x, [x[IT1], x[IT2], x[IA1], x[IA2]])[0]
    assert np.all(d[IT1 : IA2 + 1] == 0.0)
    return params.mass_matrix @ d[IU : IR + 1]


def test_thrust_asymmetry_adds_eps_times_the_total_thrust_times_the_pod_arm() -> None:
    """The port pod delivers (1 + eps), the starboard pod (1 - eps) of its thrust state: at zero
    azimuth the yaw moment grows by eps (T_1 + T_2) |y_t| (|y_t| = 2.7 m), positive (to
    starboard) for a stronger port pod, the surge force by eps (T_1 - T_2) and the sway force
    not at all; with both pods at azimuth alpha and equal thrusts the forces stay and the
    moment is eps (T_1 + T_2) |y_t| cos(alpha)."""

    from shipgym.models.rvg import IA1, IA2, IT1, IT2, IU

    eps = 0.04
    x = np.zeros(10)
    x[IU] = 5.0
    x[IT1], x[IT2] = 30e3, 24e3
    ship = RVGParams()
    added = _forces(replace(ship, thrust_asymmetry=eps), x) - _forces(ship, x)
    arm = 2.7
    assert ship.pod_y == (-arm, arm)
    np.testing.assert_allclose(
        added, [eps * (30e3 - 24e3), 0.0, eps * (30e3 + 24e3) * arm], atol=1e-6
    )
    alpha = math.radians(15.0)
    x[IT1] = x[IT2] = 27e3
    x[IA1] = x[IA2] = alpha
    added = _forces(replace(ship, thrust_asymmetry=eps), x) - _forces(ship, x)
    np.testing.assert_allclose(added, [0.0, 0.0, eps * 54e3 * arm * math.cos(alpha)], atol=1e-6)


def test_thrust_asymmetry_is_zero_by_default_and_mirrors_with_the_ship() -> None:
    """Default 0 (seed 001's model; an explicit 0 is the same model, bit for bit); the ship
    mirrored (pods' thrusts and angles swapped and negated, sway and yaw negated) with -eps
    moves as the mirror image of the ship with eps; beyond +-THRUST_ASYMMETRY_MAX refused."""
    from shipgym.models.rvg import IA1, IA2, IR, IT1, IT2, IU, IV, THRUST_ASYMMETRY_MAX

    ship = RVGParams()
    assert ship.thrust_asymmetry == 0.0
    x = np.zeros(10)
    x[IU], x[IV], x[IR] = 5.0, 0.3, 0.02
    x[IT1], x[IT2], x[IA1], x[IA2] = 30e3, 24e3, 0.1, 0.05
    assert np.array_equal(_forces(ship, x), _forces(replace(ship, thrust_asymmetry=0.0), x))
    mirror = x.copy()
    mirror[IV], mirror[IR] = -x[IV], -x[IR]
    mirror[IT1], mirror[IT2], mirror[IA1], mirror[IA2] = x[IT2], x[IT1], -x[IA2], -x[IA1]
    f = _forces(replace(ship, thrust_asymmetry=0.05), x)
    g = _forces(replace(ship, thrust_asymmetry=-0.05), mirror)
    np.testing.assert_allclose(g, f * [1.0, -1.0, -1.0], rtol=1e-12, atol=1e-6)
    assert THRUST_ASYMMETRY_MAX == 0.1
    with pytest.raises(ValueError, match="thrust_asymmetry must be within"):
        RVGParams(thrust_asymmetry=0.11)


def _record_of(ship: RVGParams, seed: int = 2):
    """A generated Gunnerus record of ``ship``: the generator's random azimuth and rpm orders
    of ``seed`` replayed by :func:`simulate_orders` on ``ship``, with the generator's sensor
    noise (the generator itself makes the seed-001 ship)."""
    from shipgym.sysid.families.rvg import simulate_orders
    from shipgym.sysid.generator import NOISE

    clean = generate_record(None, base_model="rvg3dof", maneuver="random", seed=seed, noise=False)
    x0 = np.array([0.0, 0.0, 0.0, clean.u[0], clean.v[0], clean.r[0]])
    s = simulate_orders(ship, clean.time, clean.rpm, clean.azimuth, x0)
    rng = np.random.default_rng(7)
    n = clean.time.size

    def noisy(col: int, sd: float) -> np.ndarray:
        return s[:, col] + sd * rng.standard_normal(n)

    return replace(
        clean, x=noisy(0, NOISE["xy"]), y=noisy(1, NOISE["xy"]), psi=noisy(2, NOISE["psi"]),
        u=noisy(3, NOISE["uv"]), v=noisy(4, NOISE["uv"]), r=noisy(5, NOISE["r"]),
    )  # fmt: skip


def test_a_known_thrust_asymmetry_is_named_and_recovered() -> None:
    """A generated Gunnerus record (the generator's random azimuth and rpm orders, the ship's
    port pod 8 % stronger than its starboard pod at one order, sensor noise): the loop names
    ``thrust_asymmetry`` alone, recovers eps within 15 % and halves the heading error."""
    eps = 0.08
    res = identify(_record_of(RVGParams(thrust_asymmetry=eps)), "rvg3dof")
    assert res.effect_names == ["thrust_asymmetry"]
    got = res.effects[0]["parameters"]
    assert got["thrust_asymmetry"] == pytest.approx(eps, rel=0.15)
    assert got["port_to_starboard_thrust"] == pytest.approx((1 + eps) / (1 - eps), rel=0.03)
    assert (
        res.heldout["error_after"]["psi_rms_deg"] < 0.5 * res.heldout["error_before"]["psi_rms_deg"]
    )


@pytest.mark.parametrize("tau", [0.5, 2.8, 9.0])
@pytest.mark.parametrize("step_deg", [2.0, 30.0])
def test_the_azimuth_lag_is_the_shared_first_order_gear_on_the_pods(
    tau: float, step_deg: float
) -> None:
    """The pods' azimuth after a step order ``a`` (from 0, the hull at rest) is the first-order
    servo of the shared ``rudder_lag`` cause with the pods' rate limit ``R`` = 10 deg/s: ``a
    (1 - exp(-t / tau))`` while ``a / tau <= R``, else a ramp ``R t`` until the error is ``R
    tau``, then ``a - R tau exp(-(t - t_1) / tau)``; and it is what the shared
    :func:`~shipgym.sysid.families.base.lag_filter` makes of the order with the pods' limits.
    Time constants: the floor, about the sea trials' fit, the ceiling of
    ``AZIMUTH_TIME_CONSTANT_RANGE``."""
    from shipgym.models import SteeringGear, make_model
    from shipgym.models.rvg import AZIMUTH_TIME_CONSTANT_RANGE, IA1, IA2
    from shipgym.sysid.families.base import lag_filter

    assert AZIMUTH_TIME_CONSTANT_RANGE == (0.5, 9.0)
    ship = RVGParams(azimuth_time_constant=tau)
    rate = ship.azimuth_max_rate
    assert rate == pytest.approx(math.radians(10.0))
    a = math.radians(step_deg)
    h, n = 0.05, 600
    t = h * np.arange(n + 1)
    sim = make_model("rvg3dof", ship).simulate(np.zeros(10), np.tile([0.0, 0.0, a, a], (n, 1)), h)
    alpha = sim.states[:, IA1]
    np.testing.assert_array_equal(alpha, sim.states[:, IA2])
    if a / tau <= rate:
        closed = a * (1.0 - np.exp(-t / tau))
    else:
        t1 = (a - rate * tau) / rate
        closed = np.where(t < t1, rate * t, a - rate * tau * np.exp(-(t - t1) / tau))
        assert t1 > 0.0
    np.testing.assert_allclose(alpha, closed, rtol=0.0, atol=1e-5 * a)
    gear = SteeringGear(time_constant=tau, max_angle=ship.azimuth_max, max_rate=rate)
    shared = lag_filter(t, np.full(t.size, a), tau, y0=0.0, gear=gear)
    np.testing.assert_allclose(shared, alpha, rtol=0.0, atol=1e-5 * a)


def test_a_known_azimuth_lag_is_named_and_recovered() -> None:
    """A generated Gunnerus record whose pods follow their order with a 2.5 s time constant
    (the seed's 1 s in the model the loop starts from; sensor noise): the loop names
    ``rudder_lag`` alone (not the azimuth offset, which it could be mistaken for), recovers
    the time constant within 10 % and halves the held-out heading error."""
    tau = 2.5
    res = identify(_record_of(RVGParams(azimuth_time_constant=tau)), "rvg3dof")
    assert res.effect_names == ["rudder_lag"]
    got = res.effects[0]["parameters"]["azimuth_time_constant"]
    assert got == pytest.approx(tau, rel=0.10)
    assert res.parameters_before.get("azimuth_time_constant") is None
    assert (
        res.heldout["error_after"]["psi_rms_deg"] < 0.5 * res.heldout["error_before"]["psi_rms_deg"]
    )


def test_the_current_and_the_azimuth_lag_are_shared_causes() -> None:
    """The Gunnerus catalogue takes ``current`` from the shared causes (one definition for
    every family), with its parameters V_n, V_e, and ``rudder_lag`` as the pods' azimuth
    servo (the shared cause with the Gunnerus term, parameter and bounds), beside its own
    effects; the lag's parameter is the model's ``azimuth_time_constant``."""
    from dataclasses import fields

    from shipgym.models.rvg import AZIMUTH_TIME_CONSTANT_RANGE
    from shipgym.sysid.families.base import CAUSES
    from shipgym.sysid.families.rvg import RVG_EFFECTS, apply_values

    assert RVG_EFFECTS["current"] == CAUSES["current"]
    assert RVG_EFFECTS["current"].parameters == ("V_n", "V_e")
    lag = RVG_EFFECTS["rudder_lag"]
    assert lag == replace(
        CAUSES["rudder_lag"], term=lag.term, parameters=lag.parameters, bounds=lag.bounds,
        source=lag.source,
    )  # fmt: skip
    assert lag.parameters == ("azimuth_time_constant",)
    assert lag.bounds == {"azimuth_time_constant": AZIMUTH_TIME_CONSTANT_RANGE}
    assert "azimuth_time_constant" in {f.name for f in fields(RVGParams)}
    assert apply_values(RVGParams(), {"azimuth_time_constant": 2.2}).azimuth_time_constant == 2.2
    assert {"thruster_lift", "thrust_asymmetry", "azimuth_offset", "sway_offset"} <= set(
        RVG_EFFECTS
    )

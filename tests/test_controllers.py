"""Tests of the classic controllers in :mod:`controllers` (heading, speed, target, allocation).

Design checks use python-control (closed-loop poles, margins, ``control.place``); the
performance checks close the loop around the shipgym models (``ShipModel.simulate``): the
Mariner (Nomoto, seed 004) for the heading autopilot and R/V Gunnerus (seed 001) for the
speed autopilot, the unstable-ship heading autopilot, target tracking and pod allocation.
"""

from __future__ import annotations

import math
import subprocess
import sys

import control
import numpy as np
import pytest

from controllers import (
    BOLLARD_THRUST,
    ConstantBearingGuidance,
    HeadingAutopilot,
    HeadingReferenceModel,
    PodCommand,
    SpeedAutopilot,
    allocate_force_moment,
    azimuth_to_action,
    default_bandwidth,
    linear_feedforward,
    linearised_drag_model,
    pid_gains_nomoto,
    pod_forces,
    quadratic_drag_feedforward,
    ssa,
    thrust_to_action,
)
from shipgym.envs.tasks import RVGHeadingTask, RVGPathTask, RVGSpeedTask, RVGTargetTask
from shipgym.models import NorrbinParams, make_model
from shipgym.models import ssa as shipgym_ssa
from shipgym.models.rvg import SERVICE_SPEED

# Mariner (seed 004 / Fossen 1994) and its steering gear
K_MARINER, T_MARINER = 0.185, 107.3
RUDDER_MAX, RUDDER_RATE, SERVO_T = math.radians(35.0), math.radians(2.32), 2.0
SERVICE_SHAFT = 1.4
# Gunnerus pods
AZ_MAX, AZ_RATE = math.radians(35.0), math.radians(10.0)

SIGN_CASES = [
    (0.185, 107.3, 0.05),  # stable ship, rudder
    (-0.185, 107.3, 0.05),  # negative gain: positive command turns to port
    (0.0761, -5.57, 0.3),  # directionally unstable (Gunnerus-like, azimuth)
    (-0.0761, -5.57, 0.3),
]


# ------------------------------------------------------------------------------------------
# helpers
# ------------------------------------------------------------------------------------------
def mariner_step(
    pilot: HeadingAutopilot,
    step_deg: float,
    *,
    ship_name: str = "nomoto1",
    params: NorrbinParams | None = None,
    psi0: float = 0.0,
    duration: float = 800.0,
):
    """Heading step of the Mariner with ``pilot`` in the loop (1 s steps)."""
    ship = make_model(ship_name, params)
    x0 = np.zeros(ship.nx)
    x0[ship.index("U")] = 7.7
    x0[ship.index("psi")] = psi0
    ipsi, ir = ship.index("psi"), ship.index("r")
    ref = psi0 + math.radians(step_deg)
    pilot.reset(psi0, 0.0, t=0.0, command=0.0)

    def ctl(t: float, x: np.ndarray) -> tuple[float, float]:
        return (pilot.update(t, x[ipsi], x[ir], ref), SERVICE_SHAFT)

    return ship.simulate(x0, ctl, 1.0, round(duration))


def step_metrics(time: np.ndarray, psi: np.ndarray, target: float, band: float):
    """Overshoot beyond ``target`` (in the step direction), settling time into ``band``."""
    err = psi - target
    outside = np.nonzero(np.abs(err) > band)[0]
    settle = 0.0 if outside.size == 0 else float(time[min(outside[-1] + 1, time.size - 1)])
    return float(np.max(psi) - target), settle, float(err[-1])


def rvg_yaw_linearisation(speed: float = SERVICE_SPEED):
    """Sway-yaw linearisation of the RVG model at ``speed``: ``(A, b_azimuth, b_moment)``."""
    ship = make_model("rvg3dof")
    p = ship.params
    thrust = 0.5 * (p.linear_damping[0, 0] * speed + p.surge_quadratic_damping * speed**2)
    x0 = np.zeros(10)
    x0[3], x0[6], x0[7] = speed, thrust, thrust
    u0 = np.array([thrust, thrust, 0.0, 0.0])
    f0 = ship.deriv(x0, u0)[0][[4, 5]]
    eps = 1e-6
    A = np.zeros((2, 2))
    for j, k in enumerate((4, 5)):
        x = x0.copy()
        x[k] += eps
        A[:, j] = (ship.deriv(x, u0)[0][[4, 5]] - f0) / eps
    x = x0.copy()
    x[8] = x[9] = eps
    b_az = (ship.deriv(x, u0)[0][[4, 5]] - f0) / eps
    b_n = np.linalg.inv(p.mass_matrix)[1:, 2]
    return A, b_az, b_n


def nomoto_of_unstable(A: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """First-order Nomoto ``(K, T)`` that keeps the unstable pole and the high-frequency gain.

    ``T = -1 / lambda_unstable`` and ``K / T`` = the initial yaw acceleration per unit input.
    """
    lam = float(np.max(np.linalg.eigvals(A).real))
    assert lam > 0, "the Gunnerus model is expected to be directionally unstable"
    T = -1.0 / lam
    return float(b[1]) * T, T


# ------------------------------------------------------------------------------------------
# heading: design
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("K", "T", "wn"), SIGN_CASES)
def test_pole_placement_exact(K: float, T: float, wn: float) -> None:
    pilot = HeadingAutopilot.from_nomoto(K, T, 1.0, omega_n=wn, zeta=0.8)
    rep = pilot.design_report()
    want = np.array([complex(-0.8 * wn, 0.6 * wn), complex(-0.8 * wn, -0.6 * wn), -0.1 * wn])
    np.testing.assert_allclose(np.sort_complex(rep.design_poles), np.sort_complex(want))
    np.testing.assert_allclose(
        np.sort_complex(rep.closed_loop_poles), np.sort_complex(want), rtol=1e-6, atol=1e-9
    )
    assert rep.stable
    assert 30.0 < rep.phase_margin_deg < 90.0
    assert rep.gain_crossover > 0
    if T > 0:  # open-loop stable (besides the integrator): upper gain margin infinite
        assert rep.gain_margin > 1.0
    else:
        # open-loop unstable: the margin is a lower one; check its meaning with python-control
        assert 0.0 < rep.gain_margin < 1.0
        below = control.feedback(0.9 * rep.gain_margin * rep.loop, 1)
        above = control.feedback(1.1 * rep.gain_margin * rep.loop, 1)
        assert np.max(control.poles(below).real) > 0
        assert np.max(control.poles(above).real) < 0
    if T > 0:  # a stable ship: all gains have the sign of K
        assert np.sign(pilot.kp) == np.sign(pilot.ki) == np.sign(pilot.kd) == np.sign(K)


@pytest.mark.parametrize(("K", "T", "wn"), SIGN_CASES)
def test_pole_placement_matches_control_place(K: float, T: float, wn: float) -> None:
    """State feedback on [integral of psi, psi, r] from ``control.place`` = the PID gains."""
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0 / T]])
    B = np.array([[0.0], [0.0], [K / T]])
    z = 0.8
    poles = [complex(-z * wn, 0.6 * wn), complex(-z * wn, -0.6 * wn), -0.1 * wn]
    k = control.place(A, B, poles).ravel()  # u = -k x; the PID gives u = -Ki I - Kp psi - Kd r
    kp, ki, kd = pid_gains_nomoto(K, T, wn, z)
    np.testing.assert_allclose([ki, kp, kd], k, rtol=1e-6)


@pytest.mark.parametrize(("K", "T", "wn"), SIGN_CASES)
def test_fossen_formulas_close_to_design(K: float, T: float, wn: float) -> None:
    kp, ki, kd = pid_gains_nomoto(K, T, wn, 0.8, method="fossen")
    assert kp == pytest.approx(wn**2 * T / K)
    assert kd == pytest.approx((2 * 0.8 * wn * T - 1) / K)
    assert ki == pytest.approx(wn**3 * T / (10 * K))
    pilot = HeadingAutopilot.from_nomoto(K, T, 1.0, omega_n=wn, method="fossen")
    rep = pilot.design_report()
    assert rep.stable
    pair = rep.closed_loop_poles[np.abs(rep.closed_loop_poles.imag) > 0]
    assert pair.size == 2
    assert abs(pair[0]) == pytest.approx(wn, rel=0.1)  # natural frequency
    assert -pair[0].real / abs(pair[0]) == pytest.approx(0.8, abs=0.08)  # damping


def test_default_bandwidth_rule() -> None:
    # Mariner: T_a = 35 / 2.32 s = 15.1 s, w_n = 1 / sqrt(107.3 * 15.1) = 0.0249 rad/s
    wn = default_bandwidth(
        T_MARINER, actuator_time_constant=SERVO_T, max_command=RUDDER_MAX, max_rate=RUDDER_RATE
    )
    assert wn == pytest.approx(1.0 / math.sqrt(T_MARINER * 35.0 / 2.32), rel=1e-9)
    assert 1.0 / T_MARINER < wn < 1.0 / SERVO_T
    assert default_bandwidth(-5.0, actuator_time_constant=0.1) >= 2.0 / 5.0  # unstable ship
    pilot = HeadingAutopilot.from_nomoto(
        K_MARINER, T_MARINER, 1.0, max_command=RUDDER_MAX, max_rate=RUDDER_RATE
    )
    assert pilot.omega_n == pytest.approx(wn)
    assert pilot.design_report(actuator_time_constant=SERVO_T).stable


def test_reference_model_matches_transfer_function() -> None:
    ref = HeadingReferenceModel(0.05, 1.0)
    ref.reset(0.0)
    dt, n = 1.0, 300
    psi_d = np.array([0.0] + [ref.update(0.5, dt)[0] for _ in range(n)])
    t = np.arange(n + 1) * dt
    _, y = control.forced_response(ref.transfer_function(), t, np.full(n + 1, 0.5))
    assert np.max(np.abs(psi_d - y)) < 1e-4 * 0.5
    assert psi_d[-1] == pytest.approx(0.5, abs=1e-3)
    assert np.all(np.diff(psi_d) >= -1e-12)  # zeta_r = 1: no overshoot


def test_reference_model_limits() -> None:
    ref = HeadingReferenceModel(0.1, 1.0, max_turn_rate=0.02, max_turn_accel=0.001)
    ref.reset(0.0)
    out = np.array([ref.update(math.radians(120), 0.5) for _ in range(600)])
    assert np.max(np.abs(out[:, 1])) == pytest.approx(0.02)  # the limit is reached, not passed
    assert np.max(np.abs(out[:, 2])) == pytest.approx(0.001)
    assert out[-1, 0] == pytest.approx(math.radians(120), abs=1e-3)
    assert np.max(out[:, 0]) < math.radians(120.01)
    # a turn at the limit takes at least angle / rate
    assert np.argmax(out[:, 0] > math.radians(119)) * 0.5 > math.radians(119) / 0.02


def test_reference_model_short_way() -> None:
    ref = HeadingReferenceModel(0.05)
    ref.reset(math.radians(170))
    out = np.array([ref.update(math.radians(-170), 1.0) for _ in range(400)])
    assert np.all(np.diff(out[:, 0]) >= -1e-12)  # turning to starboard through 180 deg
    assert out[-1, 0] == pytest.approx(math.radians(190), abs=1e-3)  # unwrapped inside
    assert ssa(out[-1, 0]) == pytest.approx(math.radians(-170), abs=1e-3)


# ------------------------------------------------------------------------------------------
# heading: closed loop on the Mariner
# ------------------------------------------------------------------------------------------
def test_mariner_30deg_step_default_design() -> None:
    pilot = HeadingAutopilot.from_nomoto(
        K_MARINER,
        T_MARINER,
        1.0,
        actuator_time_constant=SERVO_T,
        max_command=RUDDER_MAX,
        max_rate=RUDDER_RATE,
    )
    res = mariner_step(pilot, 30.0)
    over, settle, final = step_metrics(res.time, np.degrees(res["psi"]), 30.0, 2.0)
    assert over < 5.0
    assert settle < 400.0
    assert abs(final) < 0.5
    cmd = res["delta_c"]
    assert np.max(np.abs(cmd)) <= RUDDER_MAX + 1e-12
    assert np.max(np.abs(np.diff(cmd))) <= RUDDER_RATE * 1.0 + 1e-12


def test_mariner_rudder_offset_removed_by_integrator() -> None:
    offset = math.radians(3.0)  # a 3 deg rudder bias: n0 = K * offset
    params = NorrbinParams(n0=K_MARINER * offset, n3=0.0)  # linear Nomoto with a bias
    pilot = HeadingAutopilot.from_nomoto(
        K_MARINER, T_MARINER, 1.0, omega_n=0.05, max_command=RUDDER_MAX, max_rate=RUDDER_RATE
    )
    res = mariner_step(pilot, 30.0, ship_name="norrbin", params=params, duration=1500.0)
    psi = np.degrees(res["psi"])
    over, settle, final = step_metrics(res.time, psi, 30.0, 2.0)
    assert over < 5.0
    assert settle < 300.0
    assert abs(final) < 0.02  # zero steady-state error
    assert pilot.offset_estimate == pytest.approx(offset, abs=math.radians(0.05))
    # without the integrator the same bias leaves a steady error of offset * K / (K Kp)
    pd = HeadingAutopilot(pilot.kp, 0.0, pilot.kd, 1.0, reference_omega=0.05)
    res_pd = mariner_step(pd, 30.0, ship_name="norrbin", params=params, duration=1500.0)
    err_pd = np.degrees(res_pd["psi"][-1]) - 30.0
    assert err_pd == pytest.approx(-math.degrees(offset / pilot.kp), rel=0.05)
    # keep_offset moves the learned offset into b0
    pilot.reset(0.0, keep_offset=True)
    assert pilot.offset == pytest.approx(offset, abs=math.radians(0.05))
    assert pilot.integral == 0.0


def test_nomoto_feedforward_tracks_reference_model() -> None:
    """With ``(T a_d + r_d) / K`` fed forward the ship follows psi_d closely."""
    errors = {}
    for ff in (False, True):
        pilot = HeadingAutopilot.from_nomoto(
            K_MARINER,
            T_MARINER,
            1.0,
            omega_n=0.05,
            reference_omega=0.03,
            max_command=RUDDER_MAX,
            max_rate=RUDDER_RATE,
            nomoto_feedforward=ff,
        )
        psi_d = []
        ship = make_model("nomoto1")
        x0 = np.zeros(ship.nx)
        x0[3] = 7.7
        pilot.reset(0.0, t=0.0, command=0.0)

        def ctl(
            t: float, x: np.ndarray, pilot: HeadingAutopilot = pilot, psi_d: list = psi_d
        ) -> tuple[float, float]:
            u = pilot.update(t, x[2], x[4], math.radians(30.0))
            psi_d.append(pilot.psi_d)
            return (u, SERVICE_SHAFT)

        res = ship.simulate(x0, ctl, 1.0, 600)
        errors[ff] = np.max(np.abs(res["psi"][:-1] - np.array(psi_d)))
    assert errors[True] < math.radians(0.3)
    assert errors[True] < 0.2 * errors[False]


def test_anti_windup_large_step() -> None:
    """150 deg step straight into the PID (no reference model): the rudder saturates."""
    results = {}
    for mode in ("back_calculation", "conditional", "none"):
        pilot = HeadingAutopilot.from_nomoto(
            K_MARINER,
            T_MARINER,
            1.0,
            omega_n=0.05,
            reference_omega=0,
            max_command=RUDDER_MAX,
            max_rate=RUDDER_RATE,
            anti_windup=mode,
        )
        res = mariner_step(pilot, 150.0, duration=1200.0)
        over, _, final = step_metrics(res.time, np.degrees(res["psi"]), 150.0, 2.0)
        results[mode] = over
        assert abs(final) < 0.5
    assert results["none"] > 40.0  # integrator windup
    assert results["back_calculation"] < 2.0
    assert results["conditional"] < 0.5 * results["none"]


def test_mariner_heading_through_180() -> None:
    pilot = HeadingAutopilot.from_nomoto(
        K_MARINER, T_MARINER, 1.0, omega_n=0.05, max_command=RUDDER_MAX, max_rate=RUDDER_RATE
    )
    ship = make_model("nomoto1")
    x0 = np.zeros(ship.nx)
    x0[3], x0[2] = 7.7, math.radians(170.0)

    def ctl(t: float, x: np.ndarray) -> tuple[float, float]:
        return (pilot.update(t, x[2], x[4], math.radians(-170.0)), SERVICE_SHAFT)

    res = ship.simulate(x0, ctl, 1.0, 600)
    turned = np.degrees(res["psi"] - x0[2])  # the model integrates psi without wrapping
    assert turned.max() == pytest.approx(20.0, abs=1.0)
    assert turned.min() > -0.5  # never turned to port
    assert math.degrees(shipgym_ssa(res["psi"][-1])) == pytest.approx(-170.0, abs=0.2)
    assert math.degrees(pilot.psi_d) == pytest.approx(-170.0, abs=0.05)  # wrapped for display


def test_update_with_t_none_and_time_checks() -> None:
    pilot = HeadingAutopilot(1.0, 0.1, 10.0, 0.5)  # no reference model: the error is 0.2 rad
    pilot.update(None, 0.0, 0.0, 0.2)
    pilot.update(None, 0.0, 0.0, 0.2)
    assert pilot.integral == pytest.approx(0.2 * 0.5)  # one dt of integration happened
    pilot.reset(0.0, t=10.0)
    pilot.update(10.0, 0.0, 0.0, 0.1)
    with pytest.raises(ValueError, match="backwards"):
        pilot.update(9.0, 0.0, 0.0, 0.1)


# ------------------------------------------------------------------------------------------
# heading: R/V Gunnerus (unstable, negative high-frequency gain)
# ------------------------------------------------------------------------------------------
def test_rvg_heading_autopilot() -> None:
    A, b_az, _ = rvg_yaw_linearisation()
    K, T = nomoto_of_unstable(A, b_az)
    assert K / T < 0  # positive azimuth turns to port
    assert T < 0  # unstable
    dt = 0.5
    pilot = HeadingAutopilot.from_nomoto(
        K,
        T,
        dt,
        omega_n=0.3,
        reference_omega=0.05,
        max_turn_rate=0.02,
        max_command=AZ_MAX,
        max_rate=AZ_RATE,
    )
    # the full linearised sway-yaw model with the 1 s azimuth servo, with python-control
    sway_yaw = control.ss(A, b_az.reshape(2, 1), [[0.0, 1.0]], 0.0)
    plant = control.ss2tf(sway_yaw) * control.tf([1.0], [1.0, 0.0]) * control.tf([1], [1.0, 1.0])
    rep = pilot.design_report(plant)
    assert rep.stable
    assert rep.phase_margin_deg > 20.0

    ship = make_model("rvg3dof")
    thrust = ship.params.service_thrust
    for step_deg in (30.0, 120.0):
        x0 = np.zeros(10)
        x0[3], x0[6], x0[7] = SERVICE_SPEED, thrust, thrust
        pilot.reset(0.0, 0.0, t=0.0, command=0.0)
        ref = math.radians(step_deg)

        def ctl(t: float, x: np.ndarray, ref: float = ref) -> np.ndarray:
            return PodCommand(pilot.update(t, x[2], x[5], ref), thrust).model_input()

        res = ship.simulate(x0, ctl, dt, 600)
        over, _, final = step_metrics(res.time, np.degrees(res["psi"]), step_deg, 2.0)
        assert over < 2.0
        assert abs(final) < 0.5
        assert np.max(np.abs(res["r"])) < 0.035  # the turn stays checkable
        assert np.max(np.abs(res["alpha1_c"])) <= AZ_MAX + 1e-12


# ------------------------------------------------------------------------------------------
# speed
# ------------------------------------------------------------------------------------------
def rvg_speed_run(pilot: SpeedAutopilot, u0: float, u_ref: float, n_steps: int = 600):
    ship = make_model("rvg3dof")
    p = ship.params
    x0 = np.zeros(10)
    x0[3] = u0
    x0[6] = x0[7] = 0.5 * (p.linear_damping[0, 0] * u0 + p.surge_quadratic_damping * u0**2)
    pilot.reset(t=0.0)

    def ctl(t: float, x: np.ndarray) -> np.ndarray:
        return PodCommand(0.0, pilot.update(t, x[3], u_ref)).model_input()

    return ship.simulate(x0, ctl, 0.5, n_steps)


def test_rvg_speed_autopilot_step() -> None:
    p = make_model("rvg3dof").params
    m = p.mass + p.added_mass[0, 0]
    d1, d2 = p.linear_damping[0, 0], p.surge_quadratic_damping
    ff = quadratic_drag_feedforward(d1, d2, share=0.5)
    K, T = linearised_drag_model(m, d1, d2, 4.0, share=0.5)
    assert T == pytest.approx(m / (d1 + 8.0 * d2))
    pilot = SpeedAutopilot.from_first_order(
        K, T, 0.5, omega_n=0.1, feedforward=ff, min_command=0.0, max_command=p.max_thrust
    )
    res = rvg_speed_run(pilot, 3.0, 5.0)
    u = res["u"]
    over, settle, final = step_metrics(res.time, u, 5.0, 0.05)
    assert over < 0.1
    assert settle < 60.0
    assert abs(final) < 1e-3
    thrust = res["T1_c"]
    assert np.all(thrust >= 0.0)
    assert np.all(thrust <= p.max_thrust(0.0))
    # limits follow the speed: never more than the pod gives at that speed
    assert np.all(thrust <= [p.max_thrust(v) + 1e-6 for v in u[:-1]])


def test_rvg_speed_feedforward_alone() -> None:
    p = make_model("rvg3dof").params
    ff = quadratic_drag_feedforward(p.linear_damping[0, 0], p.surge_quadratic_damping, share=0.5)
    assert ff(SERVICE_SPEED) == pytest.approx(p.service_thrust, rel=0.01)
    pilot = SpeedAutopilot(0.0, 0.0, 0.5, feedforward=ff, min_command=0.0)
    res = rvg_speed_run(pilot, 3.0, 5.0, n_steps=800)
    assert res["u"][-1] == pytest.approx(5.0, abs=0.01)


def test_nomoto_surge_speed_autopilot() -> None:
    ship = make_model("nomoto1")
    surge = ship.surge
    assert surge is not None
    ff = linear_feedforward(surge.gain)
    assert ff(surge.service_speed) == pytest.approx(surge.service_shaft_speed)
    pilot = SpeedAutopilot.from_first_order(
        surge.gain,
        surge.time_constant,
        1.0,
        omega_n=0.03,
        feedforward=ff,
        min_command=0.0,
        max_command=surge.max_shaft_speed,
    )
    x0 = np.zeros(ship.nx)
    x0[3] = surge.service_speed
    pilot.reset(t=0.0)
    res = ship.simulate(x0, lambda t, x: (0.0, pilot.update(t, x[3], 5.0)), 1.0, 600)
    assert res["U"][-1] == pytest.approx(5.0, abs=0.01)
    assert res["U"].min() > 5.0 - 0.1  # critically damped: no undershoot worth the name


def test_speed_rate_limit_and_antiwindup() -> None:
    pilot = SpeedAutopilot(1.0, 0.5, 1.0, min_command=0.0, max_command=2.0, max_rate=0.1)
    pilot.reset(t=0.0, command=0.0)
    cmds = [pilot.update(float(k), 0.0, 10.0) for k in range(1, 60)]
    assert np.max(np.diff([0.0, *cmds])) <= 0.1 + 1e-12
    assert max(cmds) == pytest.approx(2.0)
    # the integral term did not run away while saturated
    assert pilot.ki * pilot.integral < 10.0


# ------------------------------------------------------------------------------------------
# target tracking
# ------------------------------------------------------------------------------------------
def test_constant_bearing_law_closed_form() -> None:
    g = ConstantBearingGuidance(3.0, 100.0, 0.0)
    p, pt, vt = np.array([400.0, 300.0]), np.array([0.0, 0.0]), np.array([1.0, -2.0])
    p_tilde = p - pt  # seed 004 eq. 11 with d = 0
    kappa = 3.0 * np.linalg.norm(p_tilde) / math.sqrt(p_tilde @ p_tilde + 100.0**2)
    want = vt - kappa * p_tilde / np.linalg.norm(p_tilde)
    chi, speed = g.update(0.0, p, pt, vt)
    np.testing.assert_allclose(g.desired_velocity, want)
    assert chi == pytest.approx(math.atan2(want[1], want[0]))
    assert speed == pytest.approx(np.linalg.norm(want))
    # holding a distance: at the aim point the ship just moves with the target
    g = ConstantBearingGuidance(3.0, 100.0, 50.0)
    np.testing.assert_allclose(g.desired_velocity_at([30.0, 40.0], [0.0, 0.0], vt), vt)
    # closer than d: open the range along the line of sight
    v = g.desired_velocity_at([30.0, 40.0 - 20.0], [0.0, 0.0], [0.0, 0.0])
    assert v @ np.array([30.0, 20.0]) > 0
    # speed limits
    g = ConstantBearingGuidance(3.0, 100.0, 50.0, min_speed=1.0, max_speed=2.0)
    assert g.update(0.0, [5000.0, 0.0], [0.0, 0.0], [0.0, 0.0])[1] == 2.0


def test_constant_bearing_kinematic_convergence() -> None:
    """Ideal velocity tracking: the range converges monotonically to ``d``."""
    g = ConstantBearingGuidance(2.0, 80.0, 50.0, dt=1.0)
    p, pt, vt = np.array([0.0, 0.0]), np.array([600.0, -200.0]), np.array([0.0, 2.0])
    errs = []
    for k in range(800):
        g.update(float(k), p, pt)  # target velocity estimated from its positions
        p = p + g.desired_velocity
        pt = pt + vt
        errs.append(abs(np.linalg.norm(p - pt) - 50.0))
    assert errs[-1] < 0.5
    assert np.all(np.diff(errs[2:]) <= 1e-9)


@pytest.mark.parametrize("chain", ["allocation", "azimuth"])
def test_rvg_target_tracking(chain: str) -> None:
    """Gunnerus holds 50 m from a target moving east at 2 m/s.

    ``allocation``: heading autopilot -> yaw moment, speed autopilot -> surge force,
    :func:`allocate_force_moment` -> pods. ``azimuth``: heading autopilot -> azimuth, speed
    autopilot -> thrust per pod.
    """
    ship = make_model("rvg3dof")
    p = ship.params
    m = p.mass + p.added_mass[0, 0]
    d1, d2 = p.linear_damping[0, 0], p.surge_quadratic_damping
    A, b_az, b_n = rvg_yaw_linearisation()
    dt, d = 0.5, 50.0
    if chain == "allocation":
        K, T = nomoto_of_unstable(A, b_n)
        n_max = 2 * p.service_thrust * abs(p.pod_x[0]) * math.sin(AZ_MAX)
        heading = HeadingAutopilot.from_nomoto(
            K, T, dt, omega_n=0.3, reference_omega=0.05, max_turn_rate=0.02, max_command=n_max
        )
        Ku, Tu = linearised_drag_model(m, d1, d2, 3.0)
        speed = SpeedAutopilot.from_first_order(
            Ku,
            Tu,
            dt,
            omega_n=0.1,
            feedforward=quadratic_drag_feedforward(d1, d2),
            min_command=0.0,
            max_command=lambda u: 2.0 * p.max_thrust(u),
        )
    else:
        K, T = nomoto_of_unstable(A, b_az)
        heading = HeadingAutopilot.from_nomoto(
            K,
            T,
            dt,
            omega_n=0.3,
            reference_omega=0.05,
            max_turn_rate=0.02,
            max_command=AZ_MAX,
            max_rate=AZ_RATE,
        )
        Ku, Tu = linearised_drag_model(m, d1, d2, 3.0, share=0.5)
        speed = SpeedAutopilot.from_first_order(
            Ku,
            Tu,
            dt,
            omega_n=0.1,
            feedforward=quadratic_drag_feedforward(d1, d2, share=0.5),
            min_command=0.0,
            max_command=p.max_thrust,
        )
    guidance = ConstantBearingGuidance(2.0, 100.0, d, max_speed=6.0, dt=dt)
    pt0, vt = np.array([400.0, 300.0]), np.array([0.0, 2.0])
    x0 = np.zeros(10)
    x0[3], x0[6], x0[7] = SERVICE_SPEED, p.service_thrust, p.service_thrust
    ranges = []

    def ctl(t: float, x: np.ndarray) -> np.ndarray:
        chi_d, u_d = guidance.update(t, x[:2], pt0 + vt * t, vt)
        ranges.append(guidance.range)
        if chain == "allocation":
            N = heading.update(t, x[2], x[5], chi_d)
            X = speed.update(t, x[3], u_d)
            return np.array(allocate_force_moment(X, N, max_thrust=p.max_thrust(x[3])))
        az = heading.update(t, x[2], x[5], chi_d)
        return PodCommand(az, speed.update(t, x[3], u_d)).model_input()

    res = ship.simulate(x0, ctl, dt, 1600)
    rng = np.array(ranges)
    late = res.time[:-1] >= 500.0
    assert rng.min() > 0.8 * d  # no collision course
    assert np.all(np.abs(rng[late] - d) < 0.1 * d)
    assert res["u"][-1] == pytest.approx(2.0, abs=0.1)  # moving with the target


# ------------------------------------------------------------------------------------------
# allocation and action scaling
# ------------------------------------------------------------------------------------------
def test_allocation_round_trip() -> None:
    rng = np.random.default_rng(0)
    X = rng.uniform(5e3, 150e3, 200)
    N = rng.uniform(-1.0, 1.0, 200) * X * 15.56 * math.tan(math.radians(30))
    T1, T2, a1, a2 = allocate_force_moment(X, N)
    np.testing.assert_array_equal(T1, T2)
    np.testing.assert_array_equal(a1, a2)
    assert np.all(np.abs(a1) <= math.radians(35) + 1e-12)
    assert np.all((T1 >= 0) & (T1 <= BOLLARD_THRUST))
    Xa, Ya, Na = pod_forces(T1, T2, a1, a2)
    np.testing.assert_allclose(Xa, X, rtol=1e-10)
    np.testing.assert_allclose(Na, N, rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(Ya, -N / 15.56, rtol=1e-9, atol=1e-9)  # Y = 2 s = N / x_p


def test_pod_forces_match_the_model() -> None:
    """eq. 20 as the RVG model applies it: at rest, M nu' = tau."""
    ship = make_model("rvg3dof")
    T1, T2, a1, a2 = allocate_force_moment(60e3, -300e3)
    x = np.zeros(10)
    x[6:] = (T1, T2, a1, a2)
    nu_dot = ship.deriv(x, x[6:])[0][3:6]
    tau = ship.params.mass_matrix @ nu_dot
    np.testing.assert_allclose(tau, pod_forces(T1, T2, a1, a2), rtol=1e-9, atol=1e-6)
    assert a1 > 0  # negative (port) moment from a positive azimuth on aft pods
    # asymmetric pods: the y terms no longer cancel, the closed form still holds
    T1, T2, a1, a2 = allocate_force_moment(60e3, 1e5, pod_x=(-15.0, -16.0), pod_y=(-2.0, 3.0))
    Xa, _, Na = pod_forces(T1, T2, a1, a2, pod_x=(-15.0, -16.0), pod_y=(-2.0, 3.0))
    assert (float(Xa), float(Na)) == pytest.approx((60e3, 1e5))


def test_allocation_saturation() -> None:
    tmax, amax, xp = 50e3, math.radians(35), 15.56
    # yaw priority, small X, large N: the moment is kept, the surge force grows
    N = -2 * 20e3 * xp  # needs 20 kN of side force per pod
    T1, _, a1, _ = allocate_force_moment(1e3, N, max_thrust=tmax, max_azimuth=amax)
    assert float(a1) == pytest.approx(amax)
    Xa, _, Na = pod_forces(T1, T1, a1, a1)
    assert float(Na) == pytest.approx(N)
    assert float(Xa) > 1e3
    # surge priority: X kept, moment reduced to what the azimuth limit allows
    T1, _, a1, _ = allocate_force_moment(
        10e3, N, max_thrust=tmax, max_azimuth=amax, priority="surge"
    )
    Xa, _, Na = pod_forces(T1, T1, a1, a1)
    assert float(Xa) == pytest.approx(10e3)
    assert float(Na) == pytest.approx(-10e3 * xp * math.tan(amax))
    # beyond the thrust limit: full thrust, full azimuth (yaw) / straight ahead (surge)
    T1, _, a1, _ = allocate_force_moment(1e6, -1e7, max_thrust=tmax, max_azimuth=amax)
    assert (float(T1), float(a1)) == pytest.approx((tmax, amax))
    T1, _, a1, _ = allocate_force_moment(
        1e6, -1e7, max_thrust=tmax, max_azimuth=amax, priority="surge"
    )
    assert (float(T1), float(a1)) == pytest.approx((tmax, 0.0))
    # a large X within the azimuth sector is scaled down keeping the moment (yaw priority)
    T1, _, a1, _ = allocate_force_moment(4 * tmax, -2 * 5e3 * xp, max_thrust=tmax)
    Xa, _, Na = pod_forces(T1, T1, a1, a1)
    assert float(T1) == pytest.approx(tmax)
    assert float(Na) == pytest.approx(-2 * 5e3 * xp)
    # no astern thrust: negative X gives zero thrust (surge priority), or only the moment
    T1, _, _, _ = allocate_force_moment(-1e4, 0.0, priority="surge")
    assert float(T1) == 0.0
    T1, _, a1, _ = allocate_force_moment(-1e4, 1e4)
    assert float(pod_forces(T1, T1, a1, a1)[2]) == pytest.approx(1e4)


@pytest.mark.parametrize(
    ("task_cls", "env", "n_act"),
    [
        (RVGHeadingTask, "heading", 1),
        (RVGSpeedTask, "speed", 1),
        (RVGPathTask, "path", 2),
        (RVGTargetTask, "target", 2),
    ],
)
def test_pod_command_inverts_env_mapping(task_cls, env: str, n_act: int) -> None:
    task = task_cls(1)
    rng = np.random.default_rng(1)
    for _ in range(20):
        az = rng.uniform(-AZ_MAX, AZ_MAX)
        thrust = rng.uniform(0.0, BOLLARD_THRUST)
        cmd = PodCommand(az, thrust)
        a = cmd.to_env_action(env)
        assert a.shape == (n_act,) and a.dtype == np.float32
        u = task.u0 + task.B @ a.astype(np.float64)  # the env's mapping
        if env != "speed":
            assert u[2] == pytest.approx(az, abs=1e-6) and u[3] == u[2]
        else:
            assert u[2] == u[3] == 0.0
        if env != "heading":
            assert u[0] == pytest.approx(thrust, rel=1e-6) and u[1] == u[0]
        back = PodCommand.from_env_action(a, env)
        np.testing.assert_allclose(back.model_input(), u, rtol=1e-6, atol=1e-6)
    assert azimuth_to_action(AZ_MAX) == pytest.approx(1.0)
    assert thrust_to_action(0.0) == -1.0 and thrust_to_action(BOLLARD_THRUST) == 1.0
    # clipped like the env unless asked not to
    big = PodCommand(math.radians(60), 2 * BOLLARD_THRUST)
    assert np.all(big.to_env_action("path") == 1.0)
    assert np.all(big.to_env_action("path", clip=False) > 1.0)


# ------------------------------------------------------------------------------------------
# bad input
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "call",
    [
        lambda: pid_gains_nomoto(0.0, 100.0, 0.05),
        lambda: pid_gains_nomoto(0.1, 0.0, 0.05),
        lambda: pid_gains_nomoto(0.1, 100.0, -0.05),
        lambda: pid_gains_nomoto(0.1, 100.0, 0.05, zeta=0.0),
        lambda: pid_gains_nomoto(0.1, 100.0, 0.05, method="magic"),
        lambda: HeadingAutopilot.from_nomoto(math.nan, 100.0, 1.0),
        lambda: HeadingAutopilot(1.0, 0.0, 1.0, dt=0.0),
        lambda: HeadingAutopilot(1.0, 0.0, 1.0, 1.0, max_command=-1.0),
        lambda: HeadingAutopilot(1.0, 0.0, 1.0, 1.0, anti_windup="sometimes"),
        lambda: HeadingAutopilot(1.0, 0.0, 1.0, 1.0, max_turn_rate=0.02),
        lambda: HeadingAutopilot(1.0, 0.0, 1.0, 1.0).update(0.0, math.nan, 0.0, 0.0),
        lambda: HeadingAutopilot(1.0, 0.0, 1.0, 1.0).design_report(),
        lambda: HeadingAutopilot(1.0, 0.0, 1.0, 1.0, nomoto_feedforward=True),
        lambda: HeadingReferenceModel(0.0),
        lambda: SpeedAutopilot(1.0, 0.1, 1.0, min_command=1.0, max_command=0.5),
        lambda: SpeedAutopilot(1.0, 0.1, 1.0, feedforward=3.0),
        lambda: SpeedAutopilot.from_first_order(0.0, 10.0, 1.0, omega_n=0.1),
        lambda: SpeedAutopilot(1.0, 0.1, 1.0).update(0.0, math.inf, 1.0),
        lambda: linear_feedforward(0.0),
        lambda: quadratic_drag_feedforward(-1.0),
        lambda: linearised_drag_model(1e5, 0.0, 10.0, 0.0),
        lambda: ConstantBearingGuidance(0.0, 100.0),
        lambda: ConstantBearingGuidance(1.0, 100.0, -5.0),
        lambda: ConstantBearingGuidance(1.0, 100.0, min_speed=3.0, max_speed=2.0),
        lambda: ConstantBearingGuidance(1.0, 100.0).update(0.0, [0.0], [0.0, 0.0], [0.0, 0.0]),
        lambda: allocate_force_moment(1e4, math.nan),
        lambda: allocate_force_moment(1e4, 0.0, max_thrust=0.0),
        lambda: allocate_force_moment(1e4, 0.0, max_azimuth=math.radians(120)),
        lambda: allocate_force_moment(1e4, 0.0, pod_x=(-15.0, 15.0)),
        lambda: allocate_force_moment(1e4, 0.0, priority="sway"),
        lambda: PodCommand(math.nan, 1e4),
        lambda: PodCommand(0.1, 1e4).to_env_action("zigzag"),  # type: ignore[arg-type]
        lambda: PodCommand.from_env_action([0.1], "path"),
    ],
)
def test_bad_input_raises(call) -> None:
    with pytest.raises(ValueError):
        call()


def test_ssa_matches_shipgym() -> None:
    for a in np.linspace(-10.0, 10.0, 101):
        assert ssa(a) == pytest.approx(float(shipgym_ssa(a)), abs=1e-12)


def test_controllers_do_not_import_shipgym() -> None:
    code = (
        "import sys, controllers, controllers.heading, controllers.speed, controllers.target, "
        "controllers.allocation; "
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('shipgym', 'gymnasium')); "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stdout + out.stderr


def test_turn_rate_limit_bounds_the_implied_yaw_rate_demand() -> None:
    """With ``max_turn_rate`` the PID acts as a cascade whose yaw-rate demand is clipped."""
    K, T = 0.076, -5.57  # the Gunnerus, unstable
    pilot = HeadingAutopilot.from_nomoto(
        K, T, 0.5, omega_n=0.3, reference_omega=0.3, max_turn_rate=0.02
    )
    free = HeadingAutopilot.from_nomoto(K, T, 0.5, omega_n=0.3, reference_omega=0.3)
    pilot.reset(0.0, 0.0, t=0.0)
    free.reset(0.0, 0.0, t=0.0)
    for k in range(1, 40):  # a 90 deg setpoint: the heading error grows large
        u = pilot.update(0.5 * k, 0.0, 0.0, math.radians(90.0))
        u_free = free.update(0.5 * k, 0.0, 0.0, math.radians(90.0))
    # the ship does not turn (r = 0): the clipped demand is at most 0.02 rad/s
    assert abs(u) == pytest.approx(abs(pilot.kd) * 0.02, rel=1e-9)
    assert abs(u_free) > 3 * abs(u)
    # below the limit the two laws are the same PID
    small = HeadingAutopilot.from_nomoto(
        K, T, 0.5, omega_n=0.3, reference_omega=0.3, max_turn_rate=0.02
    )
    small_free = HeadingAutopilot.from_nomoto(K, T, 0.5, omega_n=0.3, reference_omega=0.3)
    small.reset(0.0, 0.0, t=0.0)
    small_free.reset(0.0, 0.0, t=0.0)
    a = small.update(0.5, 0.0, 0.0, math.radians(0.5))
    b = small_free.update(0.5, 0.0, 0.0, math.radians(0.5))
    assert a == pytest.approx(b, rel=1e-12)

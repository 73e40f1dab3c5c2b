"""Physics tests of the vessel models in :mod:`shipgym.models`.

Every test checks a physical property against an independent reference: a closed-form
solution, a conservation/dissipation law, a symmetry, a steady-state balance or the
convergence order of the integrator.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from shipgym.models import (
    NOMOTO_MODEL_NAMES,
    BechParams,
    Current,
    Nomoto1Params,
    Nomoto2Params,
    NorrbinParams,
    RVGParams,
    ShipModel,
    SteeringGear,
    SurgeModel,
    make_model,
)

RVG_X0_ZERO = np.zeros(10)


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------


def _body_current(current: np.ndarray, psi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Body-frame current ``R_z(psi)^T nu_c^n`` (surge, sway components)."""
    cn, ce = current
    return cn * np.cos(psi) + ce * np.sin(psi), -cn * np.sin(psi) + ce * np.cos(psi)


def _relative_velocity(states: np.ndarray, current: np.ndarray) -> np.ndarray:
    """``nu_r = nu - R^T nu_c^n`` along an RVG trajectory, shape ``(n, 3)``."""
    uc, vc = _body_current(current, states[:, 2])
    return np.stack((states[:, 3] - uc, states[:, 4] - vc, states[:, 5]), axis=1)


def _mirror_rvg_state(x: np.ndarray) -> np.ndarray:
    """Mirror an RVG state about the ship's centre plane (port <-> starboard)."""
    m = np.array(x, dtype=np.float64, copy=True)
    m[..., 1] = -x[..., 1]  # y
    m[..., 2] = -x[..., 2]  # psi
    m[..., 4] = -x[..., 4]  # v
    m[..., 5] = -x[..., 5]  # r
    m[..., 6], m[..., 7] = x[..., 7], x[..., 6]  # thrust of port <-> starboard pod
    m[..., 8], m[..., 9] = -x[..., 9], -x[..., 8]  # azimuths swapped and negated
    return m


def _mirror_rvg_input(u: np.ndarray) -> np.ndarray:
    m = np.array(u, dtype=np.float64, copy=True)
    m[..., 0], m[..., 1] = u[..., 1], u[..., 0]
    m[..., 2], m[..., 3] = -u[..., 3], -u[..., 2]
    return m


def _run_batch(model, x0: np.ndarray, u: np.ndarray, dt: float, n_steps: int) -> np.ndarray:
    """Advance a batch of ships with ``model.step`` (constant inputs), return final states."""
    x = np.array(x0, dtype=np.float64, ndmin=2)
    for _ in range(n_steps):
        x = model.step(x, u, dt)
    return x


def _loglog_slope(dts: np.ndarray, errors: np.ndarray) -> float:
    return float(np.polyfit(np.log(dts), np.log(errors), 1)[0])


# --------------------------------------------------------------------------------------------
# 1. first-order Nomoto against its closed form
# --------------------------------------------------------------------------------------------


def test_nomoto1_step_response_matches_closed_form() -> None:
    """Gear at rest, constant speed: r and psi follow the exact first-order solution."""
    params = Nomoto1Params()
    K, T = params.K, params.T
    surge = SurgeModel()
    model = make_model("nomoto1", params)
    delta0 = math.radians(10.0)
    n_shaft = 1.0
    speed = surge.gain * n_shaft  # U' = (K_u n - U) / T_u = 0 exactly
    dt, n_steps = 0.5, 1200
    x0 = np.array([0.0, 0.0, 0.0, speed, 0.0, delta0])
    res = model.simulate(x0, np.tile([delta0, n_shaft], (n_steps, 1)), dt)
    t = res.time

    r_exact = K * delta0 * (1.0 - np.exp(-t / T))
    psi_exact = K * delta0 * (t - T * (1.0 - np.exp(-t / T)))
    np.testing.assert_allclose(res["r"], r_exact, rtol=0, atol=1e-10 * K * delta0)
    np.testing.assert_allclose(res["psi"], psi_exact, rtol=1e-10, atol=1e-12)
    # actuators at rest
    np.testing.assert_array_equal(res["delta"], delta0)
    np.testing.assert_array_equal(res["U"], speed)

    # positions: quadrature of U cos(psi), U sin(psi) along the exact heading
    def psi_of(s: float) -> float:
        return K * delta0 * (s - T * (1.0 - math.exp(-s / T)))

    for k in (200, 600, n_steps):
        xe = quad(lambda s: speed * math.cos(psi_of(s)), 0.0, t[k], limit=200, epsabs=1e-11)[0]
        ye = quad(lambda s: speed * math.sin(psi_of(s)), 0.0, t[k], limit=200, epsabs=1e-11)[0]
        assert res["x"][k] == pytest.approx(xe, abs=1e-7 * speed * t[k])
        assert res["y"][k] == pytest.approx(ye, abs=1e-7 * speed * t[k])


def test_nomoto1_with_steering_lag_matches_cascade_closed_form() -> None:
    """Rudder step through a first-order gear (no rate limit): exact cascade of two lags."""
    params = Nomoto1Params()
    K, T = params.K, params.T
    gear = SteeringGear(time_constant=2.0, max_rate=math.radians(10.0))
    tau = gear.time_constant
    model = make_model("nomoto1", params, gear=gear)
    d = math.radians(3.0)
    speed = SurgeModel().gain * 1.0
    dt, n_steps = 0.05, 6000
    x0 = np.array([0.0, 0.0, 0.0, speed, 0.0, 0.0])
    res = model.simulate(x0, np.tile([d, 1.0], (n_steps, 1)), dt)
    t = res.time

    # the gear stays in its linear range: rate below the limit, angle below the limit
    rates = model.deriv(res.states, np.tile([d, 1.0], (n_steps + 1, 1)))[:, 5]
    assert np.max(np.abs(rates)) < 0.5 * gear.max_rate
    assert np.max(np.abs(res["delta"])) < gear.max_angle

    delta_exact = d * (1.0 - np.exp(-t / tau))
    r_exact = K * d * (1.0 - (T * np.exp(-t / T) - tau * np.exp(-t / tau)) / (T - tau))
    psi_exact = (
        K
        * d
        * (t - (T**2 * (1.0 - np.exp(-t / T)) - tau**2 * (1.0 - np.exp(-t / tau))) / (T - tau))
    )
    # RK4 with dt / tau = 0.025: global errors ~1e-9 (delta), ~2e-11 (r) relative
    np.testing.assert_allclose(res["delta"], delta_exact, rtol=0, atol=5e-9 * d)
    np.testing.assert_allclose(res["r"], r_exact, rtol=0, atol=1e-10 * K * d)
    np.testing.assert_allclose(res["psi"], psi_exact, rtol=0, atol=1e-12 * np.max(psi_exact))


# --------------------------------------------------------------------------------------------
# 2. passivity of the RVG hull: relative kinetic energy never grows without thrust
# --------------------------------------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(
    psi=st.floats(-2 * math.pi, 2 * math.pi),
    u=st.floats(-3.0, 6.0),
    v=st.floats(-2.0, 2.0),
    r=st.floats(-0.1, 0.1),
    alpha1=st.floats(-math.pi, math.pi),
    alpha2=st.floats(-math.pi, math.pi),
    current_speed=st.floats(0.0, 1.5),
    current_dir=st.floats(-math.pi, math.pi),
)
def test_rvg_relative_kinetic_energy_never_increases_without_thrust(
    psi: float,
    u: float,
    v: float,
    r: float,
    alpha1: float,
    alpha2: float,
    current_speed: float,
    current_dir: float,
) -> None:
    params = RVGParams()
    M = params.mass_matrix
    assert np.allclose(M, M.T)
    model = make_model("rvg3dof", params)
    current = np.array(Current(current_speed, current_dir).ned)
    x0 = np.array([0.0, 0.0, psi, u, v, r, 0.0, 0.0, alpha1, alpha2])
    res = model.simulate(x0, np.tile([0.0, 0.0, alpha1, alpha2], (300, 1)), 0.1, current=current)

    np.testing.assert_array_equal(res["T1"], 0.0)
    np.testing.assert_array_equal(res["T2"], 0.0)
    nu_r = _relative_velocity(res.states, current)
    energy = 0.5 * np.einsum("ki,ij,kj->k", nu_r, M, nu_r)
    increase = np.diff(energy)
    assert np.all(increase <= 1e-9 * energy[:-1] + 1e-12), (
        f"relative kinetic energy grew by up to {increase.max():.3e} J"
    )
    if energy[0] > 1.0:  # damping really dissipates
        assert energy[-1] < energy[0]


# --------------------------------------------------------------------------------------------
# 3. port/starboard mirror symmetry
# --------------------------------------------------------------------------------------------


def test_rvg_mirrored_inputs_give_mirrored_trajectory() -> None:
    model = make_model("rvg3dof")
    dt, n_steps = 0.1, 600
    t = np.arange(n_steps) * dt
    inputs = np.column_stack(
        (
            30e3 + 10e3 * np.sin(0.05 * t),
            20e3 + 5e3 * np.cos(0.03 * t),
            0.3 * np.sin(0.02 * t) + 0.1,  # fast enough to hit the azimuth rate limit
            -0.2 + 0.4 * (t > 20.0),
        )
    )
    x0 = np.array([5.0, -3.0, 0.4, 4.0, 0.3, -0.02, 20e3, 35e3, 0.2, -0.1])
    current = np.array(Current(0.7, 2.0).ned)
    res = model.simulate(x0, inputs, dt, current=current)
    mirrored = model.simulate(
        _mirror_rvg_state(x0),
        _mirror_rvg_input(inputs),
        dt,
        current=current * np.array([1.0, -1.0]),
    )
    # the trajectory is not trivially symmetric: it turns and the pods differ
    assert np.ptp(res["psi"]) > 0.1
    assert np.max(np.abs(res["T1"] - res["T2"])) > 1e3
    scale = np.maximum(np.max(np.abs(res.states), axis=0), 1.0)
    np.testing.assert_allclose(
        mirrored.states / scale, _mirror_rvg_state(res.states) / scale, rtol=0, atol=1e-9
    )


_MIRROR_PARAMS = {
    "nomoto1": Nomoto1Params(),
    "nomoto2": Nomoto2Params(),
    # odd nonlinear terms only (the r|r| term must be odd, so it is exercised here)
    "norrbin": NorrbinParams(n2=40.0),
    "bech": BechParams(b2=200.0),
}


@pytest.mark.parametrize("name", NOMOTO_MODEL_NAMES)
def test_nomoto_family_negated_rudder_gives_mirrored_trajectory(name: str) -> None:
    model = make_model(name, _MIRROR_PARAMS[name])
    dt, n_steps = 0.5, 1200
    t = np.arange(n_steps) * dt
    # includes angle saturation (0.9 rad > 35 deg) and the rate limit
    delta_c = 0.9 * np.sign(np.sin(0.01 * t)) + 0.1 * np.sin(0.05 * t)
    inputs = np.column_stack((delta_c, np.full(n_steps, 1.2)))
    x0 = np.array([10.0, 20.0, 0.3, 4.0, 0.01, 0.05, 1e-4][: model.nx])
    current = np.array(Current(0.5, 0.7).ned)
    res = model.simulate(x0, inputs, dt, current=current)

    mirror_idx = [
        model.index(s) for s in ("y", "psi", "r", "delta", "r_dot") if s in model.state_names
    ]
    sign = np.ones(model.nx)
    sign[mirror_idx] = -1.0
    mirrored = model.simulate(
        x0 * sign,
        inputs * np.array([-1.0, 1.0]),
        dt,
        current=current * np.array([1.0, -1.0]),
    )
    assert np.ptp(res["r"]) > 1e-3
    scale = np.maximum(np.max(np.abs(res.states), axis=0), 1.0)
    np.testing.assert_allclose(
        mirrored.states / scale, res.states * sign / scale, rtol=0, atol=1e-12
    )


# --------------------------------------------------------------------------------------------
# 4. drifting with the current
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("speed", "direction", "psi0"), [(1.2, 2.0, 0.7), (1.0, math.pi / 2, -2.5), (0.4, -1.0, 3.0)]
)
def test_rvg_at_rest_in_water_drifts_with_current(
    speed: float, direction: float, psi0: float
) -> None:
    model = make_model("rvg3dof")
    current = np.array(Current(speed, direction).ned)
    uc, vc = _body_current(current, np.array(psi0))
    x0 = np.array([3.0, -4.0, psi0, uc, vc, 0.0, 0.0, 0.0, 0.4, -1.1])
    dt, n_steps = 0.5, 1200
    res = model.simulate(x0, np.tile([0.0, 0.0, 0.4, -1.1], (n_steps, 1)), dt, current=current)
    t = res.time
    assert np.all(np.abs(res["x"] - (3.0 + current[0] * t)) <= 1e-9 * (1.0 + t))
    assert np.all(np.abs(res["y"] - (-4.0 + current[1] * t)) <= 1e-9 * (1.0 + t))
    np.testing.assert_allclose(res["psi"], psi0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(_relative_velocity(res.states, current), 0.0, atol=1e-12)


@pytest.mark.parametrize(("speed", "direction"), [(1.0, 2.0), (1.5, -0.5), (0.6, math.pi)])
def test_rvg_relative_motion_does_not_depend_on_current(speed: float, direction: float) -> None:
    """Irrotational constant current (property 8.1): in the water's frame nothing changes.

    A ship started with the same velocity relative to the water, with the same commands,
    has the same relative velocity, heading, yaw rate and actuator states as in still water,
    and its position is the still-water one plus ``current * t``.
    """
    model = make_model("rvg3dof")
    dt, n_steps = 0.1, 600
    t = np.arange(n_steps) * dt
    inputs = np.column_stack(
        (
            np.where(t < 15.0, 1e6, 30e3 + 10e3 * np.sin(0.05 * t)),  # saturated at first
            20e3 + 5e3 * np.cos(0.03 * t),
            0.3 * np.sin(0.02 * t) + 0.1,
            -0.2 + 0.4 * (t > 20.0),
        )
    )
    x0 = np.array([0.0, 0.0, 0.4, 4.0, 0.3, -0.02, 20e3, 35e3, 0.2, -0.1])
    still = model.simulate(x0, inputs, dt)

    current = np.array(Current(speed, direction).ned)
    xc = x0.copy()
    uc0, vc0 = _body_current(current, np.array(x0[2]))
    xc[3] += uc0
    xc[4] += vc0
    moving = model.simulate(xc, inputs, dt, current=current)
    in_water = moving.states.copy()
    in_water[:, 0] -= current[0] * moving.time
    in_water[:, 1] -= current[1] * moving.time
    in_water[:, 3:6] = _relative_velocity(moving.states, current)

    assert np.max(still["T1"]) > 60e3  # the speed-dependent thrust limit was active
    scale = np.maximum(np.max(np.abs(still.states), axis=0), 1.0)
    # equal up to the RK4 truncation error (the map nu -> nu_r depends on psi)
    np.testing.assert_allclose(in_water / scale, still.states / scale, rtol=0, atol=1e-8)


def test_rvg_pod_forces_at_rest_follow_eq20() -> None:
    """At rest in still water only the pods act (eq. 20).

    ``M nu' = sum_k T_k [cos a_k, sin a_k, x_k sin a_k - y_k cos a_k]``.
    """
    params = RVGParams()
    model = make_model("rvg3dof", params)
    rng = np.random.default_rng(7)
    for _ in range(10):
        thrust = rng.uniform(0.0, 100e3, 2)
        alpha = rng.uniform(-math.pi, math.pi, 2)
        x = np.array([0.0, 0.0, rng.uniform(-3, 3), 0.0, 0.0, 0.0, *thrust, *alpha])
        nu_dot = model.deriv(x, [*thrust, *alpha])[0, 3:6]
        force = np.zeros(3)
        for k in range(2):
            ca, sa = math.cos(alpha[k]), math.sin(alpha[k])
            force += thrust[k] * np.array([ca, sa, params.pod_x[k] * sa - params.pod_y[k] * ca])
        np.testing.assert_allclose(params.mass_matrix @ nu_dot, force, rtol=1e-9, atol=1e-6)
    # port pod alone, straight ahead: pushes the port side forward, the bow goes to starboard
    x = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 50e3, 0.0, 0.0, 0.0])
    assert model.deriv(x, [50e3, 0.0, 0.0, 0.0])[0, 5] > 0.0


def _pod_lift_force(params: RVGParams, x: np.ndarray) -> np.ndarray:
    """Independent evaluation of the pod normal force of the module docstring (on the hull)."""
    from shipgym.models.rvg import WATER_DENSITY

    u, v, r = x[3:6]
    force = np.zeros(3)
    for k in range(2):
        xt, yt = params.pod_x[k], params.pod_y[k]
        up, vp = u - yt * r, v + xt * r
        beta = math.atan2(vp, up)
        aoa = (x[8 + k] - beta + math.pi) % (2 * math.pi) - math.pi
        stall = params.pod_stall_angle
        if aoa > math.pi - stall:  # flow from astern: the foil's angle turned by pi
            aoa -= math.pi
        elif aoa < stall - math.pi:
            aoa += math.pi
        aoa = float(np.clip(aoa, -stall, stall))
        slip = 8 * x[6 + k] / (WATER_DENSITY * math.pi * params.propeller_diameter**2)
        lift = params.pod_lift_coefficient * (up**2 + vp**2 + params.pod_slipstream * slip)
        lift *= math.sin(aoa)
        fx, fy = -lift * math.sin(x[8 + k]), lift * math.cos(x[8 + k])
        force += np.array([fx, fy, xt * fy - yt * fx])
    return force


def _assert_lift_force(base: ShipModel, lift: ShipModel, x: np.ndarray) -> None:
    """The derivative of ``lift`` differs from that of ``base`` (no lift) at state ``x``, with
    the inputs held at the state, by ``M^-1`` times :func:`_pod_lift_force`."""
    inputs = x[6:10]
    diff = (lift.deriv(x, inputs) - base.deriv(x, inputs))[0, 3:6]
    expected = _pod_lift_force(lift.params, x)
    np.testing.assert_allclose(lift.params.mass_matrix @ diff, expected, rtol=1e-9, atol=1e-6)


def test_rvg_pod_lift_in_every_inflow_direction_stall_and_flow_from_astern() -> None:
    """The pod normal force for inflows from every direction and any azimuth, astern and beyond
    the stall angle included, against the angles formed explicitly (atan2, wrap, turn by pi,
    clip); also for a ship at rest with its pods thrusting (no inflow, the slipstream only)."""
    base = make_model("rvg3dof", RVGParams())
    for stall in (math.radians(30.0), 1.2):
        lift = make_model(
            "rvg3dof",
            RVGParams(pod_lift_coefficient=6.5e3, pod_slipstream=0.5, pod_stall_angle=stall),
        )
        rng = np.random.default_rng(11)
        for k in range(300):
            u, v = rng.uniform(-4, 4, 2) if k % 10 else (0.0, 0.0)
            r = rng.uniform(-0.1, 0.1) if k % 10 else 0.0
            alpha = rng.uniform(-math.pi, math.pi, 2)
            thrust = rng.uniform(0, 60e3, 2)
            _assert_lift_force(base, lift, np.array([0.0, 0.0, 0.3, u, v, r, *thrust, *alpha]))
    with pytest.raises(ValueError, match=r"pod_stall_angle must be an angle in \(0, pi/2\)"):
        RVGParams(pod_stall_angle=math.radians(95.0))


def test_rvg_pod_lift_adds_the_foil_force_from_each_pods_inflow() -> None:
    """With ``c_L > 0`` the derivative differs from seed 001's by ``M^-1`` times the normal force
    of each pod from its own inflow angle (with stall and slipstream), normal to the pod's chord;
    it turns the ship the same way as the thrust's side component (positive azimuth: to port)."""
    c_l = 6.5e3
    base = make_model("rvg3dof", RVGParams())
    lift = make_model("rvg3dof", RVGParams(pod_lift_coefficient=c_l, pod_slipstream=0.5))
    rng = np.random.default_rng(3)
    for _ in range(20):
        u, v, r = rng.uniform(0.5, 6), rng.uniform(-1, 1), rng.uniform(-0.05, 0.05)
        alpha = rng.uniform(-0.9, 0.9, 2)
        thrust = rng.uniform(0, 60e3, 2)
        _assert_lift_force(base, lift, np.array([0.0, 0.0, 0.3, u, v, r, *thrust, *alpha]))
    x = np.array([0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 30e3, 30e3, 0.1, 0.1])
    r_dot_base = base.deriv(x, [30e3, 30e3, 0.1, 0.1])[0, 5]
    r_dot_lift = lift.deriv(x, [30e3, 30e3, 0.1, 0.1])[0, 5]
    assert r_dot_lift < r_dot_base < 0.0


def test_rvg_pod_lift_damps_sway_and_yaw_and_stalls() -> None:
    """Straight ahead the normal force is ``c_L u^2 sin(alpha)`` per pod, normal to the chord
    (so it also brakes); a sway velocity at zero azimuth gives a restoring side force
    ``dY/dv = -2 c_L u`` (both pods); beyond the stall angle the normal force no longer grows."""
    c_l = 6.5e3
    params = RVGParams(pod_lift_coefficient=c_l)
    u = 5.0
    for a in (0.05, 0.2):
        x = np.array([0.0, 0.0, 0.0, u, 0.0, 0.0, 0.0, 0.0, a, a])
        side = 2 * c_l * u * u * math.sin(a)  # normal to the chord
        np.testing.assert_allclose(
            _pod_lift_force(params, x)[:2], [-side * math.sin(a), side * math.cos(a)]
        )
    model = make_model("rvg3dof", params)
    seed = make_model("rvg3dof", RVGParams())
    dv = 1e-4
    x = np.array([0.0, 0.0, 0.0, u, dv, 0.0, 0.0, 0.0, 0.0, 0.0])
    side = params.mass_matrix @ (model.deriv(x, [0, 0, 0, 0]) - seed.deriv(x, [0, 0, 0, 0]))[0, 3:6]
    assert side[1] / dv == pytest.approx(-2 * c_l * u, rel=1e-3)
    assert side[2] / dv == pytest.approx(-2 * c_l * u * params.pod_x[0], rel=1e-3)  # > 0: stable
    stalled = [
        float(np.hypot(*_pod_lift_force(params, np.array([0, 0, 0, u, 0, 0, 0, 0, a, a]))[:2]))
        for a in np.radians([35.0, 45.0, 60.0])
    ]
    assert stalled[1] == pytest.approx(stalled[0]) and stalled[2] == pytest.approx(stalled[0])


def test_rvg_turning_speed_loss_and_crossflow_cross_terms() -> None:
    """``X_vv v^2 + X_vr v r + X_rr r^2`` enters surge as written; the cross-flow terms equal the
    strip integral ``-rho/2 T C_cf int |v + x r|(v + x r) (1, x) dx`` over the hull less its pure
    sway and pure yaw parts (so they vanish when v or r is zero)."""
    from scipy.integrate import quad

    from shipgym.models.rvg import CG_FORWARD_OF_AP, DRAUGHT, LPP, WATER_DENSITY

    seed = make_model("rvg3dof", RVGParams())
    surge = RVGParams(surge_vv=-3e4, surge_vr=2e5, surge_rr=-1e6)
    cross = RVGParams(crossflow_coefficient=0.8)
    xa, xf = -CG_FORWARD_OF_AP, LPP - CG_FORWARD_OF_AP
    rng = np.random.default_rng(5)
    for _ in range(10):
        u, v, r = rng.uniform(1, 6), rng.uniform(-1, 1), rng.uniform(-0.08, 0.08)
        x = np.array([0.0, 0.0, 0.0, u, v, r, 0.0, 0.0, 0.0, 0.0])
        base = seed.deriv(x, [0, 0, 0, 0])[0, 3:6]
        f = surge.mass_matrix @ (make_model("rvg3dof", surge).deriv(x, [0, 0, 0, 0])[0, 3:6] - base)
        x_force = surge.surge_vv * v * v + surge.surge_vr * v * r + surge.surge_rr * r * r
        np.testing.assert_allclose(f, [x_force, 0.0, 0.0], atol=1e-6 * abs(x_force) + 1e-9)
        f = cross.mass_matrix @ (make_model("rvg3dof", cross).deriv(x, [0, 0, 0, 0])[0, 3:6] - base)

        def g(s: float) -> float:
            return abs(s) * s

        k = -0.5 * WATER_DENSITY * DRAUGHT * 0.8

        def integrand(xx: float, v: float = v, r: float = r) -> float:
            return g(v + xx * r) - g(v) - g(xx * r)

        y = k * quad(integrand, xa, xf, limit=200)[0]
        n = k * quad(lambda xx: xx * integrand(xx), xa, xf, limit=200)[0]
        np.testing.assert_allclose(f[1:], [y, n], rtol=1e-2, atol=1.0)  # 12-point quadrature
    for v, r in ((0.7, 0.0), (0.0, 0.05)):
        x = np.array([0.0, 0.0, 0.0, 4.0, v, r, 0.0, 0.0, 0.0, 0.0])
        np.testing.assert_allclose(
            make_model("rvg3dof", cross).deriv(x, [0, 0, 0, 0]), seed.deriv(x, [0, 0, 0, 0])
        )


def test_rvg_propeller_hull_interaction() -> None:
    """Thrust deduction scales the pod force on the hull by ``1 - t``; the wake fraction lowers
    the advance speed of the propeller law and the thrust limit to ``(1 - w) u_r``."""
    from shipgym.models.rvg import pack_rvg, pod_thrust

    t, w = 0.12, 0.2
    params = RVGParams(thrust_deduction=t, wake_fraction=w)
    seed = RVGParams()
    x = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 40e3, 30e3, 0.2, -0.1])
    d_int = make_model("rvg3dof", params).deriv(x, [40e3, 30e3, 0.2, -0.1])[0, 3:6]
    d_seed = make_model("rvg3dof", seed).deriv(x, [40e3, 30e3, 0.2, -0.1])[0, 3:6]
    np.testing.assert_allclose(d_int, (1 - t) * d_seed, rtol=1e-12)
    for ur in (1.0, 4.0):
        assert pod_thrust(170.0, ur, pack_rvg(params)) == pytest.approx(
            pod_thrust(170.0, (1 - w) * ur, pack_rvg(seed)), rel=1e-12
        )
        assert params.max_thrust(ur) == pytest.approx(seed.max_thrust((1 - w) * ur))


def test_rvg_pod_thrust_follows_the_kongsberg_bollard_table_and_the_thrust_limit() -> None:
    """The propeller law reproduces the bollard thrusts of RVG_PARAMETERS.md (68.5 / 98.6 /
    121.7 / 147.3 kN at 150 / 180 / 200 / 220 rpm) and equals the speed-dependent thrust limit
    at the reference 200 rpm; the documented lift coefficient reproduces the 34.3 kN side force
    at 5 m/s, 180 rpm, 10 deg."""
    from shipgym.models.rvg import POD_LIFT_COEFFICIENT_THRUSTER_DATA, pack_rvg, pod_thrust

    params = RVGParams()
    p = pack_rvg(params)
    table = {150: 68.5e3, 180: 98.6e3, 200: 121.7e3, 220: 147.3e3}
    for rpm, thrust in table.items():
        assert pod_thrust(float(rpm), 0.0, p) == pytest.approx(thrust, rel=2e-3)
    for ur in (0.0, 2.0, 5.0, 8.0):
        assert pod_thrust(200.0, ur, p) == pytest.approx(params.max_thrust(ur), rel=1e-12)
    assert pod_thrust(100.0, 20.0, p) == 0.0
    a = math.radians(10.0)
    side = pod_thrust(180.0, 5.0, p) * math.sin(a) + POD_LIFT_COEFFICIENT_THRUSTER_DATA * 25.0 * (
        math.sin(a)
    )
    assert side == pytest.approx(34.3e3, rel=1e-9)


def test_current_direction_convention() -> None:
    """``direction`` is where the water goes, clockwise from north: pi/2 moves it east."""
    north, east = Current(2.0, math.pi / 2).ned
    assert north == pytest.approx(0.0, abs=1e-15)
    assert east == pytest.approx(2.0)
    north, east = Current(2.0, math.pi).ned
    assert north == pytest.approx(-2.0)
    assert east == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("name", NOMOTO_MODEL_NAMES)
def test_nomoto_ship_with_no_speed_drifts_with_current(name: str) -> None:
    model = make_model(name)
    current = np.array(Current(0.8, 2.5).ned)
    x0 = np.zeros(model.nx)
    x0[model.index("psi")] = 1.1
    dt, n_steps = 1.0, 600
    res = model.simulate(x0, np.zeros((n_steps, 2)), dt, current=current)
    t = res.time
    assert np.all(np.abs(res["x"] - current[0] * t) <= 1e-9 * (1.0 + t))
    assert np.all(np.abs(res["y"] - current[1] * t) <= 1e-9 * (1.0 + t))
    np.testing.assert_array_equal(res["psi"], 1.1)
    np.testing.assert_array_equal(res["U"], 0.0)


# --------------------------------------------------------------------------------------------
# 5. RK4 convergence order
# --------------------------------------------------------------------------------------------


def test_rk4_global_error_is_fourth_order_nomoto2() -> None:
    # slow gear (no rate or angle limit active), accelerating surge, current: smooth, coupled
    gear = SteeringGear(time_constant=8.0, max_rate=1.0)
    model = make_model("nomoto2", gear=gear)
    x0 = np.array([0.0, 0.0, 0.3, 3.0, 0.0, 0.0, 0.0])
    command = np.array([0.15, 1.4])
    assert command[0] < gear.max_angle and command[0] / gear.time_constant < gear.max_rate
    current = np.array(Current(0.8, 1.0).ned)
    t_end = 200.0

    def final_state(dt: float) -> np.ndarray:
        n = round(t_end / dt)
        return model.simulate(x0, np.tile(command, (n, 1)), dt, current=current).states[-1]

    reference = final_state(0.02)
    dts = np.array([4.0, 2.0, 1.0, 0.5])
    errors = np.array([np.max(np.abs(final_state(dt) - reference)) for dt in dts])
    slope = _loglog_slope(dts, errors)
    assert 3.5 < slope < 4.5, (slope, errors)


def test_rk4_global_error_is_fourth_order_rvg() -> None:
    model = make_model("rvg3dof")
    params = model.params
    x0 = np.array([0.0, 0.0, 0.2, 4.0, 0.5, -0.03, 20e3, 20e3, 0.02, 0.02])
    command = np.array([30e3, 25e3, 0.05, 0.04])
    current = np.array(Current(0.5, 1.0).ned)
    t_end = 16.0

    def simulate(dt: float):
        n = round(t_end / dt)
        return model.simulate(x0, np.tile(command, (n, 1)), dt, current=current)

    ref = simulate(0.005)
    # smoothness premise: no |.| kink crossed, no thrust or azimuth-rate limit active
    nu_r = _relative_velocity(ref.states, current)
    for k in range(3):
        assert np.all(np.sign(nu_r[:, k]) == np.sign(nu_r[0, k]))
    assert np.max(command[:2]) < min(params.max_thrust(ur) for ur in nu_r[:, 0])
    assert np.all(
        np.abs(command[2:] - x0[8:]) / params.azimuth_time_constant < params.azimuth_max_rate
    )

    dts = np.array([0.8, 0.4, 0.2, 0.1])
    scale = np.maximum(np.max(np.abs(ref.states), axis=0), 1.0)
    errors = np.array(
        [np.max(np.abs(simulate(dt).states[-1] - ref.states[-1]) / scale) for dt in dts]
    )
    slope = _loglog_slope(dts, errors)
    assert 3.5 < slope < 4.5, (slope, errors)


# --------------------------------------------------------------------------------------------
# 6. service speed of the RVG
# --------------------------------------------------------------------------------------------


def _rvg_straight_run_at_service_thrust():
    model = make_model("rvg3dof")
    thrust = model.params.service_thrust
    res = model.simulate(RVG_X0_ZERO, np.tile([thrust, thrust, 0.0, 0.0], (3000, 1)), 0.2)
    return model, res


def test_rvg_straight_line_speed_at_service_thrust() -> None:
    model, res = _rvg_straight_run_at_service_thrust()
    params = model.params
    u_end = res["u"][-1]
    assert abs(u_end - 5.1) <= 0.1 * 5.1
    # symmetric thrust keeps the ship exactly on a straight course
    np.testing.assert_array_equal(res["v"], 0.0)
    np.testing.assert_array_equal(res["r"], 0.0)
    np.testing.assert_array_equal(res["psi"], 0.0)
    # steady state: total thrust balances linear + quadratic surge drag
    assert abs(model.deriv(res.states[-1], res.inputs[-1])[0, 3]) < 1e-8
    drag = params.linear_damping[0, 0] * u_end + params.surge_quadratic_damping * u_end**2
    assert drag == pytest.approx(2.0 * params.service_thrust, rel=1e-6)
    # accelerating from rest, the speed rises monotonically (first-order-like surge response)
    assert np.all(np.diff(res["u"]) >= 0.0)


def test_rvg_wave_resistance_is_the_froude_scaled_drag() -> None:
    """``R_w = c_w Fn^2 rho/2 S u^2``: the straight run settles where the thrust balances the
    seed's drag plus this term, and the term acts on surge only, as ``|u| u^3``."""
    from shipgym.models.rvg import GRAVITY, LPP, WATER_DENSITY, WETTED_SURFACE

    params = RVGParams(wave_resistance=0.04)
    model = make_model("rvg3dof", params)
    thrust = params.service_thrust
    res = model.simulate(RVG_X0_ZERO, np.tile([thrust, thrust, 0.0, 0.0], (3000, 1)), 0.2)
    u = res["u"][-1]
    fn2 = u * u / (GRAVITY * LPP)
    drag = (
        params.linear_damping[0, 0] * u
        + params.surge_quadratic_damping * u * u
        + 0.04 * fn2 * 0.5 * WATER_DENSITY * WETTED_SURFACE * u * u
    )
    assert drag == pytest.approx(2.0 * thrust, rel=1e-6)
    assert u < _rvg_straight_run_at_service_thrust()[1]["u"][-1] - 0.05
    seed = make_model("rvg3dof")
    for uu in (-3.0, 0.0, 2.0, 6.0):
        x = np.array([0.0, 0.0, 0.0, uu, 0.4, 0.03, 0.0, 0.0, 0.0, 0.0])
        f = (
            params.mass_matrix
            @ (model.deriv(x, [0, 0, 0, 0]) - seed.deriv(x, [0, 0, 0, 0]))[0, 3:6]
        )
        r_w = 0.04 * WATER_DENSITY * WETTED_SURFACE / (2 * GRAVITY * LPP) * abs(uu) * uu**3
        np.testing.assert_allclose(f, [-r_w, 0.0, 0.0], atol=1e-6 * abs(r_w) + 1e-9)


def test_rvg_service_thrust_holds_documented_service_speed() -> None:
    _, res = _rvg_straight_run_at_service_thrust()
    assert res["u"][-1] == pytest.approx(5.144, rel=5e-3)
    # the sea-trial set carries its own service thrust, which holds the same speed
    sea = make_model("rvg3dof", "sea_trials")
    thrust = sea.params.service_thrust
    assert thrust != pytest.approx(25.0e3, rel=0.05)
    res = sea.simulate(RVG_X0_ZERO, np.tile([thrust, thrust, 0.0, 0.0], (3000, 1)), 0.2)
    assert res["u"][-1] == pytest.approx(5.144, rel=1e-3)


# --------------------------------------------------------------------------------------------
# special cases of the nonlinear Nomoto models
# --------------------------------------------------------------------------------------------


def _nomoto_test_inputs(n_steps: int, dt: float) -> np.ndarray:
    t = np.arange(n_steps) * dt
    delta_c = 0.7 * np.sign(np.sin(0.015 * t)) + 0.05 * np.sin(0.2 * t)
    return np.column_stack((delta_c, 1.0 + 0.3 * np.sin(0.01 * t)))


def test_linear_norrbin_equals_nomoto1() -> None:
    yaw = Nomoto1Params(K=0.2, T=60.0)
    nomoto = make_model("nomoto1", yaw)
    norrbin = make_model("norrbin", NorrbinParams(K=0.2, T=60.0, n0=0.0, n1=1.0, n2=0.0, n3=0.0))
    x0 = np.array([1.0, 2.0, 0.5, 4.0, 0.01, -0.1])
    inputs = _nomoto_test_inputs(800, 0.5)
    current = np.array(Current(0.6, -0.4).ned)
    a = nomoto.simulate(x0, inputs, 0.5, current=current)
    b = norrbin.simulate(x0, inputs, 0.5, current=current)
    assert np.ptp(a["r"]) > 1e-2
    np.testing.assert_allclose(b.states, a.states, rtol=1e-14, atol=1e-15)


def test_linear_bech_equals_nomoto2() -> None:
    K = 0.185
    nomoto = make_model("nomoto2", Nomoto2Params(K=K, T1=118.0, T2=7.8, T3=18.5))
    bech = make_model(
        "bech", BechParams(K=K, T1=118.0, T2=7.8, T3=18.5, b0=0.0, b1=1.0 / K, b2=0.0, b3=0.0)
    )
    x0 = np.array([1.0, 2.0, 0.5, 4.0, 0.01, -0.1, 1e-4])
    inputs = _nomoto_test_inputs(800, 0.5)
    current = np.array(Current(0.6, -0.4).ned)
    a = nomoto.simulate(x0, inputs, 0.5, current=current)
    b = bech.simulate(x0, inputs, 0.5, current=current)
    assert np.ptp(a["r"]) > 1e-2
    scale = np.maximum(np.max(np.abs(a.states), axis=0), 1.0)
    np.testing.assert_allclose(b.states / scale, a.states / scale, rtol=0, atol=1e-12)


def test_norrbin_steady_yaw_rate_solves_spiral_equation() -> None:
    params = NorrbinParams(n0=0.002, n1=1.0, n2=40.0, n3=2.9e3)
    model = make_model("norrbin", params)
    deltas = np.array([-0.5, -0.2, -0.05, 0.0, 0.1, 0.35])
    n = deltas.size
    x0 = np.zeros((n, model.nx))
    x0[:, model.index("U")] = SurgeModel().gain
    x0[:, model.index("delta")] = deltas  # gear at rest on the command
    u = np.column_stack((deltas, np.ones(n)))
    r_sim = _run_batch(model, x0, u, 2.0, 1500)[:, model.index("r")]

    for delta, r in zip(deltas, r_sim, strict=True):
        rhs = params.K * delta - params.n0
        roots = []
        for s in (1.0, -1.0):  # r >= 0: r|r| = r^2; r < 0: r|r| = -r^2
            for z in np.roots([params.n3, s * params.n2, params.n1, -rhs]):
                if abs(z.imag) < 1e-12 and (z.real >= 0) == (s > 0):
                    roots.append(z.real)
        assert len(roots) == 1
        assert r == pytest.approx(roots[0], rel=1e-7, abs=1e-12)
    # the cubic term really bends the spiral: far below the linear K delta at large rudder
    assert abs(r_sim[0]) < 0.5 * params.K * abs(deltas[0])


# --------------------------------------------------------------------------------------------
# actuators
# --------------------------------------------------------------------------------------------


def test_steering_gear_respects_angle_and_rate_limits() -> None:
    gear = SteeringGear()
    model = make_model("nomoto1", gear=gear)
    dt = 0.1
    n1, n2 = 600, 800
    inputs = np.vstack((np.tile([1.0, 1.0], (n1, 1)), np.tile([-1.0, 1.0], (n2, 1))))
    x0 = np.array([0.0, 0.0, 0.0, 5.5, 0.0, 0.0])
    res = model.simulate(x0, inputs, dt)
    delta = res["delta"]
    rate = np.diff(delta) / dt
    assert np.max(np.abs(delta)) <= gear.max_angle * (1 + 1e-12)
    assert np.max(np.abs(rate)) <= gear.max_rate * (1 + 1e-12)
    # both limits are reached, so they were actually binding
    assert np.max(np.abs(rate)) == pytest.approx(gear.max_rate, rel=1e-9)
    assert delta[n1] == pytest.approx(gear.max_angle, rel=1e-6)
    assert delta[-1] == pytest.approx(-gear.max_angle, rel=1e-6)
    # derivative itself respects the rate limit at every sample
    rates = model.deriv(res.states[:-1], inputs)[:, model.index("delta")]
    assert np.max(np.abs(rates)) <= gear.max_rate


def test_rvg_thrust_derivative_targets_speed_dependent_limit() -> None:
    params = RVGParams()
    model = make_model("rvg3dof", params)
    tau = params.thrust_time_constant
    current = np.array(Current(1.0, math.pi).ned)  # head current for psi = 0: u_c = -1
    for u in (-3.0, -1.0, 0.0, 2.0, 5.0, 7.7, 10.0):
        ur = u + 1.0
        x = np.array([0.0, 0.0, 0.0, u, 0.0, 0.0, 10e3, 50e3, 0.0, 0.0])
        xdot = model.deriv(x, [1e7, -5e4, 0.0, 0.0], current)[0]
        assert xdot[6] == pytest.approx((params.max_thrust(ur) - 10e3) / tau, rel=1e-12, abs=1e-9)
        assert xdot[7] == pytest.approx(-50e3 / tau, rel=1e-12)  # no reverse thrust
    assert params.max_thrust(0.0) == params.bollard_thrust
    assert params.max_thrust(params.thrust_zero_speed) == 0.0
    assert params.max_thrust(-5.0) == params.bollard_thrust


def test_rvg_full_thrust_saturates_at_max_thrust_of_relative_speed() -> None:
    params = RVGParams()
    model = make_model("rvg3dof", params)
    # exactly opposite the heading: Current(1, pi).ned has a 1e-16 east part, and the hull is
    # course-unstable enough that such a perturbation grows into a full turn within 200 s
    current = np.array([-1.0, 0.0])
    res = model.simulate(
        RVG_X0_ZERO, np.tile([1e7, 1e7, 0.0, 0.0], (2000, 1)), 0.2, current=current
    )
    ur_end = res["u"][-1] + 1.0
    t_max = params.max_thrust(ur_end)
    assert res["T1"][-1] == pytest.approx(t_max, rel=1e-7)
    assert res["T2"][-1] == pytest.approx(t_max, rel=1e-7)
    assert np.max(res["T1"]) <= params.bollard_thrust
    # well below the bollard thrust at speed: the limit falls with relative speed
    assert t_max < 0.6 * params.bollard_thrust
    # steady state: that thrust balances the drag at the relative speed
    drag = params.linear_damping[0, 0] * ur_end + params.surge_quadratic_damping * ur_end**2
    assert drag == pytest.approx(2.0 * t_max, rel=1e-6)


def test_rvg_azimuth_respects_rate_and_angle_limits() -> None:
    params = RVGParams()
    model = make_model("rvg3dof", params)
    dt = 0.1
    inputs = np.tile([0.0, 0.0, math.pi / 2, 4.0], (400, 1))  # 4 rad is beyond the pi limit
    res = model.simulate(RVG_X0_ZERO, inputs, dt)
    for name, target in (("alpha1", math.pi / 2), ("alpha2", params.azimuth_max)):
        rate = np.diff(res[name]) / dt
        assert np.max(np.abs(rate)) <= params.azimuth_max_rate * (1 + 1e-12)
        assert np.max(np.abs(rate)) == pytest.approx(params.azimuth_max_rate, rel=1e-9)
        assert np.max(res[name]) <= target * (1 + 1e-12)
        assert res[name][-1] == pytest.approx(target, rel=1e-6)


# --------------------------------------------------------------------------------------------
# turning direction
# --------------------------------------------------------------------------------------------


def test_rvg_positive_azimuth_turns_to_port() -> None:
    model = make_model("rvg3dof")
    thrust = model.params.service_thrust
    alpha = math.radians(10.0)
    x0 = np.array([0.0, 0.0, 0.0, 5.0, 0.0, 0.0, thrust, thrust, alpha, alpha])
    u = np.array([thrust, thrust, alpha, alpha])
    assert model.deriv(x0, u)[0, 5] < 0.0  # yaw moment of aft pods pushed to starboard
    res = model.simulate(x0, np.tile(u, (300, 1)), 0.1)
    assert np.all(res["r"][1:] < 0.0)
    assert res["psi"][-1] < 0.0


@pytest.mark.parametrize("name", NOMOTO_MODEL_NAMES)
def test_nomoto_positive_rudder_turns_to_starboard(name: str) -> None:
    model = make_model(name)
    x0 = np.zeros(model.nx)
    x0[model.index("U")] = 7.7
    res = model.simulate(x0, np.tile([math.radians(10.0), 7.7 / 5.5], (240, 1)), 0.5)
    assert np.all(res["r"][1:] > 0.0)
    assert res["psi"][-1] > 0.0
    assert res["y"][-1] > 0.0  # heading north, a starboard turn moves the ship east


# --------------------------------------------------------------------------------------------
# input validation
# --------------------------------------------------------------------------------------------


def test_bad_inputs_raise_value_error_naming_the_problem() -> None:
    with pytest.raises(ValueError, match="unknown model 'foo'"):
        make_model("foo")
    with pytest.raises(ValueError, match=r"Nomoto1Params\.T must be"):
        Nomoto1Params(T=-1.0)
    with pytest.raises(ValueError, match="current speed"):
        Current(speed=-1.0)
    with pytest.raises(ValueError, match=r"SteeringGear\.max_rate"):
        SteeringGear(max_rate=0.0)
    with pytest.raises(ValueError, match="takes Nomoto2Params"):
        make_model("nomoto2", Nomoto1Params())
    model = make_model("nomoto1")
    with pytest.raises(ValueError, match=r"state must have shape \(n, 6\)"):
        model.deriv(np.zeros(7), np.zeros(2))
    with pytest.raises(ValueError, match="input must have shape"):
        model.deriv(np.zeros(6), np.zeros(3))
    with pytest.raises(ValueError, match="current must be"):
        model.deriv(np.zeros(6), np.zeros(2), np.zeros(3))
    with pytest.raises(ValueError, match="dt must be"):
        model.simulate(np.zeros(6), np.zeros((5, 2)), 0.0)


def test_linearize_matches_the_analytic_nomoto_jacobian() -> None:
    params = Nomoto1Params(K=0.2, T=60.0)
    model = make_model("nomoto1", params)
    psi, speed = 0.3, 7.0
    A, B = model.linearize([0.0, 0.0, psi, speed, 0.0, 0.0], [0.0, speed / model.surge.gain])
    assert A[4, 4] == pytest.approx(-1.0 / params.T, rel=1e-8)  # dr'/dr
    assert A[4, 5] == pytest.approx(params.K / params.T, rel=1e-8)  # dr'/ddelta
    assert A[0, 2] == pytest.approx(-speed * np.sin(psi), rel=1e-6)  # dx'/dpsi
    assert A[1, 3] == pytest.approx(np.sin(psi), rel=1e-6)  # dy'/dU
    assert B[5, 0] == pytest.approx(1.0 / model.gear.time_constant, rel=1e-8)  # ddelta'/ddelta_c
    assert B[3, 1] == pytest.approx(model.surge.gain / model.surge.time_constant, rel=1e-8)


def test_linearized_rvg_is_directionally_unstable_at_service_speed() -> None:
    """The documented property of the seed-001 model: one unstable sway-yaw eigenvalue."""
    model = make_model("rvg3dof")
    x0 = np.zeros(model.nx)
    x0[3] = 5.144  # service speed [m/s]
    x0[6:8] = RVGParams().service_thrust
    A, _ = model.linearize(x0, [x0[6], x0[7], 0.0, 0.0])
    eig = np.sort(np.linalg.eigvals(A[np.ix_([4, 5], [4, 5])]).real)
    assert eig[0] < 0 < eig[1]
    assert eig[1] == pytest.approx(0.18, abs=0.02)


def test_rvg_pod_model_reproduces_the_kongsberg_pod_data() -> None:
    """With the FMU-fitted ``c_L`` and ``k_s`` the pod forces (through the kernel) match rows of
    the Kongsberg pod FMU table (one pod; NTNU-MCS/MCSim_python, commit 861fd47a) within 7 kN,
    where seed 001 (no pod lift) misses the side force by tens of kN."""
    from dataclasses import replace

    from shipgym.models.rvg import (
        IT1,
        IT2,
        POD_LIFT_COEFFICIENT_FMU,
        POD_SLIPSTREAM_FMU,
        pack_rvg,
        pod_thrusts,
    )

    # u [m/s], v [m/s], azimuth [deg], rpm, Fx [kN], Fy [kN]
    rows = [(5, 0, 10, 180, 27.9, 34.3), (5, 0, 30, 180, 0.9, 88.9), (2, 0, 20, 180, 61.4, 44.0),
            (5, 0, 20, 220, 43.8, 86.4), (6.5, 0, 30, 180, -31.8, 110.6),
            (5, 1, 0, 180, 32.7, -33.6), (5, 2, 20, 180, 30.7, 5.2)]  # fmt: skip
    params = RVGParams(
        pod_lift_coefficient=POD_LIFT_COEFFICIENT_FMU, pod_slipstream=POD_SLIPSTREAM_FMU
    )
    worst_seed = 0.0
    for u, v, a_deg, rpm, fx, fy in rows:
        a = math.radians(a_deg)
        forces = []
        for p in (params, RVGParams()):
            x = np.array([0.0, 0.0, 0.0, u, v, 0.0, 0.0, 0.0, a, a])
            x[IT1], x[IT2] = pod_thrusts(float(rpm), x, np.zeros(2), pack_rvg(p))
            full = make_model("rvg3dof", p).deriv(x, [x[IT1], x[IT2], a, a])[0, 3:6]
            x[IT1] = x[IT2] = 0.0
            bare = make_model("rvg3dof", replace(p, pod_lift_coefficient=0.0))
            hull = bare.deriv(x, [0.0, 0.0, a, a])[0, 3:6]
            forces.append((p.mass_matrix @ (full - hull))[:2] / 2e3)
        np.testing.assert_allclose(forces[0], [fx, fy], atol=7.0)
        worst_seed = max(worst_seed, abs(forces[1][1] - fy))
    assert worst_seed > 30.0


def test_make_model_selects_the_rvg_parameter_set_by_name() -> None:
    sea = make_model("rvg3dof", "sea_trials").params
    assert sea.name == "sea_trials" and sea.pod_lift_coefficient > 0
    assert make_model("rvg3dof", "seed001").params.pod_lift_coefficient == 0.0
    np.testing.assert_array_equal(sea.linear_damping, RVGParams.sea_trials().linear_damping)
    with pytest.raises(ValueError, match="seed001"):
        make_model("rvg3dof", "gunnerus")
    with pytest.raises(ValueError, match="rvg3dof or kvlcc2 only"):
        make_model("nomoto1", "sea_trials")

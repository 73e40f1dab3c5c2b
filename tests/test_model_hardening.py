"""The model API refuses bad input: wrong shapes, non-finite values, bad steps and policies, and
steps beyond the RK4 stability limit, with a ValueError (or TypeError) that names the problem.

No test here hands a kernel mismatched arrays on purpose with many rows: the shape tests use a
handful of rows, so that on code without the checks they read a little past an array and fail
rather than crash the test process.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.models import Current, current_ned, integrate, make_model, ssa
from shipgym.models.vmm import VMMParams, pack_vmm, propeller_loading, term_matrix, term_monomials

THREE_DOF = ("rvg3dof", "kvlcc2")


def _vmm_params() -> VMMParams:
    from shipgym.sysid.generator import vmm_truth

    return vmm_truth()


def _model(name: str):
    return make_model(name, _vmm_params()) if name == "vmm" else make_model(name)


def _cruise(name: str) -> tuple[np.ndarray, np.ndarray]:
    """A straight-running state and input of each model."""
    model = _model(name)
    x = np.zeros(model.nx)
    u = np.zeros(model.nu)
    if name == "rvg3dof":
        thrust = model.params.service_thrust
        x[model.index("u")] = 5.0
        x[model.index("T1")] = x[model.index("T2")] = thrust
        u[:2] = thrust
    elif name == "kvlcc2":
        x[model.index("u")] = model.params.approach_speed
        u[1] = model.params.self_propulsion_rps(model.params.approach_speed)
    elif name == "vmm":
        x[model.index("u")] = model.params.approach_speed
        u[1] = model.params.approach_thrust()
    else:
        x[model.index("U")] = 7.0
        u[1] = 1.4
    return x, u


# --------------------------------------------------------------------------------------------
# shapes: every entry point that reaches a kernel checks its rows and columns first
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["nomoto1", "rvg3dof", "kvlcc2"])
def test_simulate_refuses_a_batch_of_initial_states(name: str) -> None:
    model = _model(name)
    message = rf"x0 must have shape \({model.nx},\).*got \(3, {model.nx}\)"
    with pytest.raises(ValueError, match=message):
        model.simulate(np.zeros((3, model.nx)), np.zeros((4, model.nu)), 0.05)


def test_linearize_refuses_a_batch_of_states() -> None:
    model = _model("rvg3dof")
    with pytest.raises(ValueError, match=r"x0 must have shape \(10,\).*got \(2, 10\)"):
        model.linearize(np.zeros((2, 10)), np.zeros(4))
    with pytest.raises(ValueError, match=r"u0 must have shape \(4,\).*got \(2, 4\)"):
        model.linearize(np.zeros(10), np.zeros((2, 4)))


def test_simulate_refuses_inputs_of_three_dimensions() -> None:
    model = _model("nomoto1")
    with pytest.raises(ValueError, match=r"inputs must have shape \(n_steps, 2\)"):
        model.simulate(np.zeros(6), np.zeros((3, 2, 2)), 0.1)


def test_step_and_deriv_refuse_rows_that_do_not_match() -> None:
    model = _model("nomoto1")
    with pytest.raises(ValueError, match=r"input must have shape \(3, 2\)"):
        model.step(np.zeros((3, 6)), np.zeros((2, 2)), 0.1)
    with pytest.raises(ValueError, match=r"current must be \(n, 2\).*n=3"):
        model.deriv(np.zeros((3, 6)), np.zeros(2), np.zeros((2, 2)))


def test_integrate_entry_points_check_rows_columns_and_parameters() -> None:
    model = _model("rvg3dof")
    x = np.zeros((3, 10))
    u = np.zeros((3, 4))
    c = np.zeros((3, 2))
    out = np.empty_like(x)
    with pytest.raises(ValueError, match=r"u must have shape \(3, 4\).*got \(1, 4\)"):
        integrate.rhs(integrate.RVG3DOF, x, u[:1], model.p, c, out)
    with pytest.raises(ValueError, match=r"c must have shape \(3, 2\).*got \(2, 2\)"):
        integrate.rk4_step(integrate.RVG3DOF, x, u, model.p, c[:2], 0.1)
    with pytest.raises(ValueError, match=r"x must have shape \(n, 10\).*got \(3, 6\)"):
        integrate.rk4_step(integrate.RVG3DOF, np.zeros((3, 6)), u, model.p, c, 0.1)
    with pytest.raises(ValueError, match=r"out must have shape \(3, 10\)"):
        integrate.rhs(integrate.RVG3DOF, x, u, model.p, c, np.empty((2, 10)))
    with pytest.raises(ValueError, match=r"p of model 'rvg3dof' must have \d+ entries"):
        integrate.rhs(integrate.RVG3DOF, x, u, model.p[:10], c, out)
    with pytest.raises(ValueError, match="model_id must be one of"):
        integrate.rhs(9, x, u, model.p, c, out)
    with pytest.raises(ValueError, match="dt must be a finite step > 0 s"):
        integrate.rk4_step(integrate.RVG3DOF, x, u, model.p, c, -0.1)
    with pytest.raises(TypeError, match="x must be a writable float64 array"):
        integrate.rk4_step(integrate.RVG3DOF, [[0.0] * 10], u[:1], model.p, c[:1], 0.1)


def test_integrate_entry_points_match_the_model_methods() -> None:
    model = _model("rvg3dof")
    x, u = _cruise("rvg3dof")
    xb = np.tile(x, (2, 1))
    ub = np.tile(u, (2, 1))
    c = np.array([[0.3, -0.2], [0.0, 0.5]])
    out = np.empty_like(xb)
    integrate.rhs(integrate.RVG3DOF, xb, ub, model.p, c, out)
    np.testing.assert_array_equal(out, model.deriv(xb, ub, c))
    stepped = xb.copy()
    integrate.rk4_step(integrate.RVG3DOF, stepped, ub, model.p, c, 0.1)
    np.testing.assert_array_equal(stepped, model.step(xb, ub, 0.1, c))


def test_term_monomials_checks_rows_and_columns() -> None:
    params = _vmm_params()
    p = pack_vmm(params)
    k = len(params.coefficients)
    x = np.zeros((4, 7))
    x[:, 3] = 1.0
    inputs = np.zeros((4, 4))
    with pytest.raises(ValueError, match=r"inputs must have shape \(4, 4\).*got \(3, 4\)"):
        term_monomials(x, inputs[:3], p, np.zeros(2), np.empty((4, k)), np.empty(4))
    with pytest.raises(ValueError, match=rf"out must have shape \(4, {k}\)"):
        term_monomials(x, inputs, p, np.zeros(2), np.empty((4, k + 1)), np.empty(4))
    with pytest.raises(ValueError, match=r"u2 must have shape \(4,\)"):
        term_monomials(x, inputs, p, np.zeros(2), np.empty((4, k)), np.empty(2))
    with pytest.raises(ValueError, match=r"current must have shape \(2,\)"):
        term_monomials(x, inputs, p, np.zeros((4, 2)), np.empty((4, k)), np.empty(4))
    out = np.empty((4, k))
    u2 = np.empty(4)
    term_monomials(x, inputs, p, np.zeros(2), out, u2)
    assert np.all(np.isfinite(out)) and np.allclose(u2, 1.0)
    assert term_matrix(["X_u"]).shape == (1, 12)


def test_current_and_angle_helpers_refuse_bad_arrays() -> None:
    with pytest.raises(ValueError, match=r"speed and direction must broadcast.*\(3,\).*\(2,\)"):
        current_ned(np.ones(3), np.zeros(2))
    with pytest.raises(ValueError, match="current speed must be finite and >= 0"):
        current_ned(np.array([1.0, -1.0]), np.zeros(2))
    with pytest.raises(ValueError, match="current direction must be finite"):
        current_ned(1.0, math.nan)
    with pytest.raises(TypeError, match="real numbers"):
        current_ned(np.array([1j]), 0.0)
    with pytest.raises(ValueError, match=r"Current\.as_batch: n must be an integer >= 0"):
        Current(1.0, 0.0).as_batch(-1)
    with pytest.raises(ValueError, match=r"Current\.as_batch: n must be at most 1e\+09"):
        Current(1.0, 0.0).as_batch(2**63)  # no OverflowError from NumPy
    with pytest.raises(ValueError, match="angle must not be infinite"):
        ssa(np.array([0.0, math.inf]))
    with pytest.raises(TypeError, match="real numbers"):
        ssa("north")
    assert np.isnan(ssa(np.array([math.nan, 4.0])))[0]  # a missing angle stays missing
    with pytest.raises(ValueError, match="rps must be finite"):
        propeller_loading(np.array([1.0, math.nan]), 1.0, 1000.0)
    with pytest.raises(ValueError, match="diameter must be a finite number > 0"):
        propeller_loading(np.ones(2), -1.0, 1000.0)
    with pytest.raises(ValueError, match=r"too large\) must be finite"):
        propeller_loading(np.ones(2), 1e300, 1025.0)  # D^4 overflows: ValueError, no OverflowError
    # zero revolutions give zero thrust however large D^4 is (never inf * 0 = NaN)
    with np.errstate(all="raise"):
        np.testing.assert_array_equal(propeller_loading(np.zeros(3), 2e76, 1025.0), np.zeros(3))


# --------------------------------------------------------------------------------------------
# values: non-finite numbers, bad steps, policies that return nothing
# --------------------------------------------------------------------------------------------


def test_simulate_refuses_non_finite_inputs_state_and_current() -> None:
    model = _model("nomoto1")
    x, u = _cruise("nomoto1")
    inputs = np.tile(u, (5, 1))
    inputs[2, 0] = math.nan
    with pytest.raises(ValueError, match=r"inputs must be finite.*row 2"):
        model.simulate(x, inputs, 0.1)
    bad = x.copy()
    bad[4] = math.nan
    with pytest.raises(ValueError, match=r"x0 must be finite.*'r'"):
        model.simulate(bad, np.tile(u, (5, 1)), 0.1)
    with pytest.raises(ValueError, match="current must be finite"):
        model.simulate(x, np.tile(u, (5, 1)), 0.1, current=[math.inf, 0.0])


@pytest.mark.parametrize(
    ("returned", "what"),
    [(None, "None"), ([0.0], r"shape \(1,\)"), ([math.nan, 1.4], "nan"), ("left", "str")],
)
def test_simulate_refuses_a_policy_that_returns_no_input(returned: object, what: str) -> None:
    model = _model("nomoto1")
    x, _ = _cruise("nomoto1")
    with pytest.raises(
        ValueError, match=rf"policy must return an array of shape \(2,\).*t=0 s.*{what}"
    ):
        model.simulate(x, lambda t, x: returned, 0.1, n_steps=3)


@pytest.mark.parametrize("dt", [-1.0, 0.0, math.nan, math.inf, -math.inf])
def test_step_and_simulate_refuse_a_step_that_is_not_finite_and_positive(dt: float) -> None:
    model = _model("norrbin")
    x, u = _cruise("norrbin")
    with pytest.raises(ValueError, match=r"dt must be a finite step > 0 s, got"):
        model.step(x, u, dt)
    with pytest.raises(ValueError, match=r"dt must be a finite step > 0 s, got"):
        model.simulate(x, np.tile(u, (3, 1)), dt)


def test_step_refuses_a_step_that_is_not_a_number() -> None:
    model = _model("norrbin")
    x, u = _cruise("norrbin")
    for dt in ("0.1", None, True, [0.1]):
        with pytest.raises(TypeError, match="dt must be a real number of seconds"):
            model.step(x, u, dt)  # type: ignore[arg-type]


@pytest.mark.parametrize("where", ["x", "u", "current"])
def test_step_and_deriv_refuse_non_finite_values(where: str) -> None:
    model = _model("rvg3dof")
    x, u = _cruise("rvg3dof")
    c = np.zeros(2)
    {"x": x, "u": u, "current": c}[where][1] = math.nan
    with pytest.raises(ValueError, match=rf"{where} must be finite"):
        model.step(x, u, 0.1, c)
    with pytest.raises(ValueError, match=rf"{where} must be finite"):
        model.deriv(x, u, c)


def test_a_state_that_overflows_raises_instead_of_returning_inf() -> None:
    model = _model("rvg3dof")
    x, u = _cruise("rvg3dof")
    x[model.index("u")] = 1e200
    with pytest.raises(ValueError, match="derivative is not finite"):
        model.deriv(x, u)
    with pytest.raises(ValueError, match="not finite after the step"):
        model.step(x, u, 0.1)


def test_non_real_arrays_raise_type_error() -> None:
    model = _model("nomoto1")
    with pytest.raises(TypeError, match=r"x must be an array of real numbers.*complex"):
        model.step(np.zeros(6, dtype=complex), np.zeros(2), 0.1)
    with pytest.raises(TypeError, match=r"u must be an array of real numbers.*<U"):
        model.deriv(np.zeros(6), ["0", "1"])
    with pytest.raises(TypeError, match=r"x must be an array of real numbers.*bool"):
        model.deriv(np.zeros(6, dtype=bool), np.zeros(2))


def test_make_model_refuses_a_name_or_actuator_of_the_wrong_type() -> None:
    with pytest.raises(TypeError, match="model name must be a str"):
        make_model(np.array(["nomoto1"]))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="gear must be a SteeringGear"):
        make_model("nomoto1", gear=5)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="surge must be a SurgeModel"):
        make_model("norrbin", surge="fast")  # type: ignore[arg-type]


# --------------------------------------------------------------------------------------------
# steps beyond the RK4 stability limit
# --------------------------------------------------------------------------------------------


def test_rvg_refuses_a_five_second_step_naming_the_stable_step() -> None:
    model = _model("rvg3dof")
    x, u = _cruise("rvg3dof")
    message = (
        r"dt=5 s is beyond the stable RK4 step of model 'rvg3dof' "
        r"\(about 2.79 s\); use dt <= 2.78"
    )
    with pytest.raises(ValueError, match=message):
        model.simulate(x, np.tile(u, (20, 1)), 5.0)
    with pytest.raises(ValueError, match=message):
        model.step(x, u, 5.0)
    with pytest.raises(ValueError, match=message):
        model.simulate(x, lambda t, x: u, 5.0, n_steps=20)


def test_norrbin_refuses_a_fifty_second_step_naming_the_stable_step() -> None:
    model = _model("norrbin")
    x, u = _cruise("norrbin")
    u[0] = 0.3
    message = (
        r"dt=50 s is beyond the stable RK4 step of model 'norrbin' "
        r"\(about 5.57 s\); use dt <= 5.57"
    )
    with pytest.raises(ValueError, match=message):
        model.simulate(x, np.tile(u, (50, 1)), 50.0)
    with pytest.raises(ValueError, match=message):
        model.step(x, u, 50.0)


@pytest.mark.parametrize(
    ("name", "expected"),
    [("nomoto1", 5.5706), ("nomoto2", 5.5706), ("norrbin", 5.5706), ("bech", 5.5706),
     ("rvg3dof", 2.7853), ("kvlcc2", 0.13927), ("vmm", 0.13927)],
)  # fmt: skip
def test_stable_step_at_cruise_is_set_by_the_actuator_time_constant(
    name: str, expected: float
) -> None:
    """RK4 is stable for ``h |lambda| <= 2.785`` on the negative real axis: the steering gear
    (2 s; the 7 m KVLCC2 0.05 s) and the RVG's pods (1 s) are the fastest modes."""
    model = _model(name)
    x, u = _cruise(name)
    assert model.stable_step(x, u) == pytest.approx(expected, rel=1e-3)


def test_rk4_stable_step_of_eigenvalues() -> None:
    assert integrate.rk4_stable_step(np.array([-1.0, 0.0, 0.3])) == pytest.approx(2.7853, rel=1e-4)
    assert integrate.rk4_stable_step(np.array([2j, -2j])) == pytest.approx(math.sqrt(2.0), rel=1e-4)
    assert integrate.rk4_stable_step(np.array([0.0, 0.5])) == math.inf


@pytest.mark.parametrize(("name", "dt"), [("nomoto1", 1.0), ("norrbin", 0.1), ("bech", 1.0),
                                          ("rvg3dof", 0.5), ("rvg3dof", 0.1), ("kvlcc2", 0.05),
                                          ("vmm", 0.05)])  # fmt: skip
def test_the_package_steps_stay_accepted(name: str, dt: float) -> None:
    """The environments' steps (1 s Nomoto family, 0.5 s RVG), the manoeuvres' (0.1 s, the 7 m
    model ships 0.05 s) and identification's fine steps (<= 0.1 s) pass the check."""
    model = _model(name)
    x, u = _cruise(name)
    res = model.simulate(x, np.tile(u, (10, 1)), dt)
    assert np.all(np.isfinite(res.states))
    assert np.all(np.isfinite(model.step(x, u, dt)))
    rest = model.simulate(np.zeros(model.nx), np.zeros((10, model.nu)), dt)
    assert np.all(np.isfinite(rest.states))

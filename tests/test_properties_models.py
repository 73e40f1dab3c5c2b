"""Property tests: the public API of :mod:`shipgym.models` takes anything without harm.

Random arrays of every shape (0-d, 1-d of any length, 2-d, 3-d, empty) and dtype (float64,
float32, int, bool, complex, strings, objects), and random scalars (NaN, inf, negative, huge,
strings, None, bools, complex) go into :func:`make_model` for every model name, the
:class:`ShipModel` methods (``deriv``, ``step``, ``simulate``, ``linearize``, ``stable_step``),
the checked kernel entry points (``integrate.rhs``, ``integrate.rk4_step``,
``vmm.term_monomials``) and the current, angle and propeller helpers. Whatever comes in, the
call either returns finite numbers or raises ``ValueError`` / ``TypeError`` with a message:
nothing crashes the interpreter, raises anything else or returns NaN silently (``ssa`` keeps a
NaN angle NaN, a missing angle; nothing else may).

The compiled per-ship kernels (``*_col``, ``*_row``, ``rk4_block``, ``rk4_stages``, the
kinematics helpers, ``pod_thrust``) are building blocks for compiled code and take their
arguments unchecked; they are not part of this contract.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from shipgym.models import (
    MODEL_NAMES,
    Current,
    Nomoto1Params,
    ShipModel,
    SimulationResult,
    SteeringGear,
    SurgeModel,
    current_ned,
    integrate,
    make_model,
    ssa,
)
from shipgym.models.vmm import pack_vmm, propeller_loading, term_monomials

SETTINGS = settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


@cache
def _model(name: str) -> ShipModel:
    if name == "vmm":
        from shipgym.sysid.generator import vmm_truth

        return make_model("vmm", vmm_truth())
    return make_model(name)


# --------------------------------------------------------------------------------------------
# strategies
# --------------------------------------------------------------------------------------------

_FLOATS = st.one_of(
    st.floats(-10.0, 10.0), st.floats(allow_nan=True, allow_infinity=True), st.just(1e300)
)
_OBJECTS = st.one_of(st.floats(-5.0, 5.0), st.none(), st.text(max_size=2), st.integers(-9, 9))
_ELEMENTS = {
    "float64": _FLOATS,
    "float32": st.floats(width=32, allow_nan=True, allow_infinity=True),
    "int64": st.integers(-(2**40), 2**40),
    "bool": st.booleans(),
    "complex128": st.complex_numbers(max_magnitude=1e3),
    # NumPy strings cannot hold a trailing NUL: leave it out of the alphabet
    "<U3": st.text(st.characters(exclude_characters="\x00"), max_size=3),
    "object": _OBJECTS,
}


@st.composite
def any_array(draw: st.DrawFn, width: int) -> np.ndarray:
    """An array of any dtype and shape (often ``width`` columns, to pass the shape check)."""
    dtype = draw(st.sampled_from(list(_ELEMENTS)))
    cols = st.one_of(st.just(width), st.integers(0, 12))
    shape = draw(
        st.one_of(
            st.just(()),
            st.tuples(cols),
            st.tuples(st.integers(0, 4), cols),
            st.tuples(st.integers(0, 2), st.integers(0, 3), st.integers(0, 3)),
        )
    )
    return draw(hnp.arrays(np.dtype(dtype), shape, elements=_ELEMENTS[dtype]))


@st.composite
def good_array(draw: st.DrawFn, width: int, rows: int | None = None) -> np.ndarray:
    """A float64 array of the right width, with values anywhere from small to NaN."""
    shape = (width,) if rows is None else (rows, width)
    return draw(hnp.arrays(np.float64, shape, elements=_FLOATS))


def array_like(width: int) -> st.SearchStrategy[Any]:
    return st.one_of(good_array(width), any_array(width), st.lists(_OBJECTS, max_size=12))


SCALARS = st.one_of(
    st.floats(0.01, 2.0),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-10, 10**20),
    st.booleans(),
    st.none(),
    st.text(max_size=3),
    st.complex_numbers(max_magnitude=10.0),
    st.just(np.float32(0.1)),
    st.just(np.array(0.1)),
    st.just(np.array([0.1, 0.2])),
)

# --------------------------------------------------------------------------------------------
# the contract
# --------------------------------------------------------------------------------------------


def _finite(value: Any) -> bool:
    if isinstance(value, SimulationResult):
        return bool(np.isfinite(value.states).all() and np.isfinite(value.inputs).all())
    if isinstance(value, tuple):
        return all(_finite(v) for v in value)
    if isinstance(value, float):
        return not math.isnan(value)  # inf is a valid "no limit"
    if isinstance(value, np.ndarray):
        return bool(np.isfinite(value).all())
    return True  # a model, a Current


def _call(fn: Any, *args: Any, **kwargs: Any) -> Any:
    """``fn(*args)``: returns finite numbers or raises ValueError/TypeError with a message."""
    try:
        out = fn(*args, **kwargs)
    except (ValueError, TypeError) as exc:
        assert str(exc).strip(), f"{type(exc).__name__} without a message"
        return None
    assert out is None or _finite(out), f"{getattr(fn, '__name__', fn)} returned NaN: {out!r}"
    return out


names = st.sampled_from(MODEL_NAMES)


@SETTINGS
@given(
    name=st.one_of(names, st.text(max_size=8), st.integers(), st.none(), st.just(["nomoto1"])),
    params=st.one_of(st.none(), st.text(max_size=8), st.integers(), st.just(Nomoto1Params())),
    gear=st.one_of(st.none(), st.just(SteeringGear()), st.integers(), st.text(max_size=3)),
    surge=st.one_of(st.none(), st.just(SurgeModel()), st.floats(), st.just(np.zeros(3))),
)
def test_make_model_takes_any_name_and_parameters(
    name: Any, params: Any, gear: Any, surge: Any
) -> None:
    model = _call(make_model, name, params, gear=gear, surge=surge)
    assert model is None or isinstance(model, ShipModel)


@SETTINGS
@given(data=st.data(), name=names)
def test_deriv_and_stable_step_take_any_arrays(data: st.DataObject, name: str) -> None:
    model = _model(name)
    x = data.draw(array_like(model.nx), "x")
    u = data.draw(array_like(model.nu), "u")
    current = data.draw(st.one_of(st.none(), array_like(2)), "current")
    out = _call(model.deriv, x, u, current)
    assert out is None or out.shape[1] == model.nx
    _call(model.stable_step, x, u, current)


@SETTINGS
@given(data=st.data(), name=names, dt=SCALARS)
def test_step_takes_any_arrays_and_steps(data: st.DataObject, name: str, dt: Any) -> None:
    model = _model(name)
    x = data.draw(array_like(model.nx), "x")
    u = data.draw(array_like(model.nu), "u")
    current = data.draw(st.one_of(st.none(), array_like(2), st.just(Current(0.5, 1.0))))
    out = _call(model.step, x, u, dt, current)
    assert out is None or out.shape[1] == model.nx


@SETTINGS
@given(data=st.data(), name=names, eps=st.one_of(st.just(1e-6), SCALARS))
def test_linearize_takes_any_arrays(data: st.DataObject, name: str, eps: Any) -> None:
    model = _model(name)
    x0 = data.draw(array_like(model.nx), "x0")
    u0 = data.draw(array_like(model.nu), "u0")
    out = _call(model.linearize, x0, u0, None, eps)
    assert out is None or (out[0].shape, out[1].shape) == ((model.nx,) * 2, (model.nx, model.nu))


@SETTINGS
@given(
    data=st.data(),
    name=names,
    dt=SCALARS,
    n_steps=st.one_of(st.none(), st.integers(-3, 12), st.just(10**12), st.floats(), st.text()),
    use_policy=st.booleans(),
)
def test_simulate_takes_any_arrays_steps_and_policies(
    data: st.DataObject, name: str, dt: Any, n_steps: Any, use_policy: bool
) -> None:
    model = _model(name)
    x0 = data.draw(array_like(model.nx), "x0")
    current = data.draw(st.one_of(st.none(), array_like(2)), "current")
    if use_policy:
        returned = data.draw(
            st.one_of(good_array(model.nu), any_array(model.nu), SCALARS), "policy output"
        )
        inputs: Any = lambda t, x: returned  # noqa: E731
    else:
        inputs = data.draw(st.one_of(good_array(model.nu, rows=5), any_array(model.nu)))
    out = _call(model.simulate, x0, inputs, dt, n_steps, current)
    assert out is None or out.states.shape[1] == model.nx


@SETTINGS
@given(data=st.data(), name=names, h=SCALARS)
def test_integrate_entry_points_take_any_arrays(data: st.DataObject, name: str, h: Any) -> None:
    model = _model(name)
    model_id = data.draw(st.one_of(st.just(model.model_id), st.integers(-2, 9), SCALARS))
    rows = data.draw(st.integers(0, 3))
    x = data.draw(st.one_of(good_array(model.nx, rows), any_array(model.nx)), "x")
    u = data.draw(st.one_of(good_array(model.nu, rows), any_array(model.nu)), "u")
    c = data.draw(st.one_of(good_array(2, rows), any_array(2)), "c")
    p = data.draw(st.one_of(st.just(model.p), any_array(model.p.size)), "p")
    out = data.draw(st.one_of(st.just(np.empty((rows, model.nx))), any_array(model.nx)))
    before = x.copy() if isinstance(x, np.ndarray) else None
    if _call(integrate.rhs, model_id, x, u, p, c, out) is None and isinstance(x, np.ndarray):
        np.testing.assert_array_equal(x, before)  # the derivative never writes into x
    try:
        integrate.rk4_step(model_id, x, u, p, c, h)
    except (ValueError, TypeError) as exc:
        assert str(exc).strip()


@SETTINGS
@given(data=st.data())
def test_term_monomials_and_propeller_loading_take_any_arrays(data: st.DataObject) -> None:
    model = _model("vmm")
    p = pack_vmm(model.params)
    k = len(model.params.coefficients)
    rows = data.draw(st.integers(0, 3))
    x = data.draw(st.one_of(good_array(7, rows), any_array(7)), "x")
    inputs = data.draw(st.one_of(good_array(4, rows), any_array(4)), "inputs")
    c = data.draw(st.one_of(good_array(2), any_array(2)), "current")
    pp = data.draw(st.one_of(st.just(p), any_array(p.size)), "p")
    out = data.draw(st.one_of(st.just(np.empty((rows, k))), any_array(k)), "out")
    u2 = data.draw(st.one_of(st.just(np.empty(rows)), any_array(rows)), "u2")
    try:
        term_monomials(x, inputs, pp, c, out, u2)
    except (ValueError, TypeError) as exc:
        assert str(exc).strip()
    else:
        assert np.isfinite(out).all() and np.isfinite(u2).all()
    _call(
        propeller_loading,
        data.draw(array_like(3)),
        data.draw(st.one_of(st.just(1.0), SCALARS)),
        data.draw(st.one_of(st.just(1025.0), SCALARS)),
    )


#: Batch sizes for ``Current.as_batch``: small ones, the refused ones and any other scalar, but
#: no valid batch of more than 64 rows (a billion rows is valid and takes 16 GB to build).
BATCH_SIZES = st.one_of(
    st.integers(-3, 5),
    st.integers(min_value=10**9 + 1),
    SCALARS.filter(lambda v: not (isinstance(v, int) and 64 < v <= 10**9)),
)


@SETTINGS
@given(
    speed=st.one_of(array_like(3), SCALARS),
    direction=st.one_of(array_like(3), SCALARS),
    n=BATCH_SIZES,
)
def test_current_helpers_take_any_arrays(speed: Any, direction: Any, n: Any) -> None:
    out = _call(current_ned, speed, direction)
    assert out is None or out.shape[-1] == 2
    cur = _call(Current, speed, direction)
    if cur is not None:
        _call(cur.as_batch, n)


@SETTINGS
@given(angle=st.one_of(array_like(5), SCALARS))
def test_ssa_wraps_finite_angles_keeps_nan_and_refuses_the_rest(angle: Any) -> None:
    try:
        out = ssa(angle)
    except (ValueError, TypeError) as exc:
        assert str(exc).strip()
        return
    a = np.asarray(angle, dtype=np.float64)
    np.testing.assert_array_equal(np.isnan(out), np.isnan(a))
    finite = out[np.isfinite(out)]
    assert np.all((finite >= -math.pi) & (finite < math.pi))


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_every_model_round_trips_through_the_checks_at_rest(name: str) -> None:
    """The checks accept what the models produce: a state from ``simulate`` steps again."""
    model = _model(name)
    res = model.simulate(np.zeros(model.nx), np.zeros((3, model.nu)), 0.05)
    assert np.isfinite(model.step(res.states[-1], res.inputs[-1], 0.05)).all()

"""Identification replays side by side: a block of ships with a parameter vector each.

The model functions read their parameters through ``param(p, k, b)``: one vector shared by a
block, or a table with a column per ship. A finite-difference Jacobian's replays then run as
the ships of one block (``shipgym.sysid.batched``). The invariant checked here is exact: each
ship of such a block gets, bit for bit, what it gets stepped alone with its own vector, and a
fit whose Jacobians are replayed side by side is the fit whose replays ran one at a time.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from shipgym.models import RVGParams, make_model
from shipgym.models import integrate as I
from shipgym.models import rvg as R
from shipgym.sysid import batched
from shipgym.sysid import fit as nf
from shipgym.sysid.families import rvg as fr
from shipgym.sysid.families.base import window_starts
from shipgym.sysid.generator import generate_record


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


def test_lanes_pad_several_variants_to_whole_simd_vectors() -> None:
    w = I.SIMD_LANES
    assert batched.lanes(1).tolist() == [0]
    assert batched.lanes(3).tolist() == [0, 1, 2] + [2] * (w - 3)
    assert batched.lanes(w).tolist() == list(range(w))
    assert batched.lanes(w + 1).tolist() == [*range(w + 1)] + [w] * (w - 1)
    for bad in (0, -3, 2.0, True):
        with pytest.raises(ValueError, match="variants must be an integer >= 1"):
            batched.lanes(bad)


def _variants(name: str, ships: int) -> tuple[int, list[np.ndarray]]:
    """Model id and ``ships`` distinct packed parameter vectors of a model (for the RVG, the pod
    lift and the cross-flow drag on in some ships only)."""
    model = make_model(name)
    rng = np.random.default_rng(7)
    out = []
    for b in range(ships):
        if name == "rvg3dof":
            params = replace(
                RVGParams(),
                bollard_thrust=RVGParams().bollard_thrust * (1.0 + 0.05 * b),
                pod_lift_coefficient=4000.0 if b % 2 else 0.0,
                crossflow_coefficient=0.8 if b % 3 == 1 else 0.0,
                wake_fraction=0.02 * b,
            )
            out.append(R.pack_rvg(params))
        else:
            p = model.p.copy()
            p[I.nomoto.P_YAW :] *= 1.0 + 0.1 * rng.random(p.size - I.nomoto.P_YAW)
            out.append(p)
    return I.MODEL_IDS[name], out


@pytest.mark.parametrize("name", ["nomoto1", "nomoto2", "norrbin", "bech", "rvg3dof"])
def test_a_parameter_table_steps_each_ship_as_alone_with_its_own_vector(name: str) -> None:
    """20 RK4 steps of 11 ships (a width with a SIMD remainder) each with its own parameters,
    as one block with a parameter table, equal each ship stepped alone, bit for bit."""
    model_id, ps = _variants(name, 11)
    n = len(ps)
    nx, nu = I.STATE_COUNTS[model_id], I.INPUT_COUNTS[model_id]
    rng = np.random.default_rng(3)
    X = rng.normal(size=(nx, n))
    X[2] *= 3.0  # headings of several turns
    if name == "rvg3dof":
        X[3] = rng.uniform(2.0, 6.0, n)
        X[6:8] = rng.uniform(1e4, 4e4, (2, n))
        U = np.vstack([X[6:8] * 1.1, X[8:10] + 0.1])
    else:
        X[3] = rng.uniform(2.0, 8.0, n)
        U = rng.normal(size=(nu, n)) * 0.2
    C = I.disturbance_block(rng.uniform(-0.5, 0.5, (2, n)).T)  # current, no seaway load
    P = _readonly(np.column_stack(ps))
    together = X.copy()
    W = np.empty((3, nx, n))
    for _ in range(20):
        I.rk4_block(model_id, together, U, P, C, 0.2, n, W)
    for b in range(n):
        alone = np.ascontiguousarray(X[:, b : b + 1])
        for _ in range(20):
            I.rk4_block(
                model_id, alone, np.ascontiguousarray(U[:, b : b + 1]), _readonly(ps[b]),
                np.ascontiguousarray(C[:, b : b + 1]), 0.2, 1, np.empty((3, nx, 1)),
            )  # fmt: skip
        np.testing.assert_array_equal(together[:, b], alone[:, 0], err_msg=f"ship {b}")
    assert not np.allclose(together[:, 0], together[:, 1])  # the ships did differ


def test_pod_thrusts_are_the_propeller_law_at_each_pods_axial_inflow() -> None:
    """The column form with the polynomial sine and cosine agrees with the law written out with
    the C library's to 1e-13, for a ship with a wake fraction, in a current, turning."""
    params = replace(RVGParams(), wake_fraction=0.1)
    p = R.pack_rvg(params)
    x = np.array([0.0, 0.0, 2.3, 4.1, 0.4, 0.03, 0.0, 0.0, 0.35, -0.2])
    c = (0.3, -0.2)
    psi, u, v, r = x[2], x[3], x[4], x[5]
    uc = c[0] * math.cos(psi) + c[1] * math.sin(psi)
    vc = -c[0] * math.sin(psi) + c[1] * math.cos(psi)
    want = []
    for k in range(2):
        a = x[8 + k]
        inflow = (u - uc - params.pod_y[k] * r) * math.cos(a) + (
            v - vc + params.pod_x[k] * r
        ) * math.sin(a)
        s = 170.0 / params.reference_rpm
        want.append(
            params.bollard_thrust * (s * s - s * (1.0 - 0.1) * inflow / params.thrust_zero_speed)
        )
    got = R.pod_thrusts(170.0, x, c, p)
    assert got == pytest.approx(want, rel=1e-13)
    assert want[0] != pytest.approx(want[1], rel=1e-3)  # the two pods see different inflows


def _rvg_record():
    return generate_record("thruster_lift", base_model="rvg3dof", maneuver="random", seed=2)


def test_rvg_variants_replayed_side_by_side_equal_each_replayed_alone() -> None:
    rec = _rvg_record()
    starts = window_starts(rec.time, 60.0)
    args = (rec.time, fr.start_states(rec), rec.rpm, fr.azimuth_orders(rec), starts)
    _, ps = _variants("rvg3dof", 3)
    currents = [(0.0, 0.0), (0.2, -0.1), (-0.1, 0.3)]
    alphas, v0s = [0.0, 0.02, -0.01], [0.0, -0.05, 0.1]
    together = fr._replay(*args, ps, currents, alphas, v0s)
    assert together.shape == (rec.n, 3, 10)
    for b in range(3):
        alone = fr._replay(*args, [ps[b]], [currents[b]], [alphas[b]], [v0s[b]])[:, 0]
        np.testing.assert_array_equal(together[:, b], alone, err_msg=f"variant {b}")
    # the public replay is the one-variant case
    fit = fr.RVGFit(params=RVGParams(), alpha_0=0.02, current=(0.2, -0.1), v_0=-0.05)
    np.testing.assert_array_equal(
        fit.simulate(rec, starts),
        fr._replay(*args, [R.pack_rvg(RVGParams())], [(0.2, -0.1)], [0.02], [-0.05])[:, 0],
    )


def test_nomoto_variants_replayed_side_by_side_equal_each_replayed_alone() -> None:
    rec = generate_record(None, maneuver="random", dt=0.2, duration=300.0, seed=1)
    speed = np.full(rec.n, 7.0)
    h, n_cmd = nf._replay_steps(rec.time, speed)
    _, ps = _variants("nomoto2", 5)
    x0s = [np.array([0.0, 0.0, 0.1 * b, 7.0, 0.0, 0.001 * b, 0.0]) for b in range(5)]
    d0s = [0.0, 0.01, -0.02, 0.005, 0.0]
    together = nf._replay_kernel(I.NOMOTO2, x0s, rec.delta, d0s, speed, n_cmd, h, ps, rec.n)
    for b in range(5):
        alone = nf._replay_kernel(
            I.NOMOTO2, [x0s[b]], rec.delta, [d0s[b]], speed, n_cmd, h, [ps[b]], rec.n
        )[:, 0]
        np.testing.assert_array_equal(together[:, b], alone, err_msg=f"variant {b}")


@pytest.fixture
def one_at_a_time(monkeypatch: pytest.MonkeyPatch):
    """Make every fit replay its Jacobians one column at a time, through its residual function
    (SciPy's own loop), instead of side by side."""

    def sequential(self, fun, points):
        return [fun(x) for x in points]

    def use() -> None:
        monkeypatch.setattr(batched.SideBySide, "__call__", sequential)

    return use


def test_side_by_side_batches_stay_within_the_memory_budget(monkeypatch) -> None:
    calls: list[int] = []

    def residuals(points: np.ndarray) -> list[np.ndarray]:
        calls.append(len(points))
        return [2.0 * p for p in points]

    w, per = I.SIMD_LANES, 1000
    monkeypatch.setattr(batched, "BATCH_BYTES", (2 * w + 3) * per)  # room for 2 vectors and 3
    pts = [np.full(3, float(i)) for i in range(4 * w + 3)]
    out = batched.SideBySide(residuals, per)(None, iter(pts))
    assert calls == [2 * w, 2 * w, 3]
    assert [o[0] for o in out] == [2.0 * i for i in range(4 * w + 3)]
    calls.clear()
    monkeypatch.setattr(batched, "BATCH_BYTES", (w - 1) * per)  # not one vector: one at a time
    batched.SideBySide(residuals, per)(None, pts[:3])
    assert calls == [1, 1, 1]


@pytest.mark.parametrize("batches", ["one", "several"])
def test_rvg_fit_with_side_by_side_jacobians_is_the_one_at_a_time_fit(
    one_at_a_time, monkeypatch, batches: str
) -> None:
    rec = _rvg_record()
    starts = window_starts(rec.time, 60.0)
    mask = np.ones(rec.n, dtype=bool)
    mask[starts] = False
    effects = ("thruster_lift", "current")
    if batches == "several":  # one SIMD vector of replays per batch: the 9 go as 8 and 1
        per_point = (10 * mask[::2].size + 6 * int(mask[::2].sum())) * 8
        monkeypatch.setattr(batched, "BATCH_BYTES", I.SIMD_LANES * per_point)
    fast = fr.fit_rvg(rec, starts, mask, effects, max_nfev=12, stride=2)
    one_at_a_time()
    slow = fr.fit_rvg(rec, starts, mask, effects, max_nfev=12, stride=2)
    assert len(fast.values) == len(fr.CALIBRATED) + 3  # a Jacobian of 9 replays
    assert fast.values == slow.values and fast.stderr == slow.stderr
    assert fast.values["pod_lift_coefficient"] != pytest.approx(0.0)


@pytest.mark.parametrize(
    ("model", "effect"), [("nomoto1", "rudder_offset"), ("norrbin", "yaw_nonlinearity")]
)
def test_nomoto_fit_with_side_by_side_jacobians_is_the_one_at_a_time_fit(
    one_at_a_time, model: str, effect: str
) -> None:
    rec = generate_record(effect, maneuver="zigzag", dt=0.5, duration=900.0, seed=4)
    fast = nf.fit_output_error(rec.time, rec.delta, rec.psi, rec.r, model)
    one_at_a_time()
    slow = nf.fit_output_error(rec.time, rec.delta, rec.psi, rec.r, model)
    assert fast.values == slow.values
    np.testing.assert_array_equal(fast.x0, slow.x0)

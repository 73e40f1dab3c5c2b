"""The bare batched model step against the attainable kernel for the same physics.

The reference here is the fastest form of the R/V Gunnerus RK4 step this machine can run: one
loop over the ships whose state, derivative and stage values stay in registers (structure of
arrays in and out, every parameter hoisted out of the loop, straight-line code that compiles to
SIMD instructions with the polynomial sine and cosine of :mod:`shipgym.models.vmath`). It is
written for the seed-001 ship (``RVGParams()``: no pod lift, cross-flow or wave terms), with
its constants taken from ``pack_rvg``. It is a yardstick, not a second model: the package
keeps one derivative per model, and this script checks that the two agree before it times
them.

The script times, in one process on 4096 ships (medians of interleaved repetitions):

* ``integrate.rk4_step_kernel`` on the RVG (the package's bare batched step, ships as rows),
* ``integrate.rk4_block`` on one block of ships (the same step without the row layout),
* the reference loop,

and prints million ship-steps per second and the ratio reference / package (the target: the
package within 3 x of the reference).

Usage: ``python scripts/bench_kernel.py [--ships N] [--repeats N]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numba
import numpy as np

from shipgym.models import RVGParams, integrate
from shipgym.models import rvg as R
from shipgym.models.vmath import sincos


@numba.njit(error_model="numpy", nogil=True, inline="always")
def _deriv(st, u, cn, ce, q):  # pragma: no cover - jit
    """Seed-001 RVG derivative of one ship: scalars in, a tuple out (``q`` the parameters)."""
    (mi, ma, dl, m11, m22, m23, a11, a22, a23, dq0, dq1, dq2, x1, y1, x2, y2,
     itt, ita, arate, amax, tb, iu0, ht, adv) = q  # fmt: skip
    _, _, psi, uu, vv, r, th1, th2, al1, al2 = st
    u0, u1, u2, u3 = u
    sn, cs = sincos(psi)
    uc = cn * cs + ce * sn
    vc = -cn * sn + ce * cs
    ur = uu - uc
    vr = vv - vc
    sa1, ca1 = sincos(al1)
    sa2, ca2 = sincos(al2)
    t1 = th1 * ht
    t2 = th2 * ht
    fx = t1 * ca1 + t2 * ca2
    fy = t1 * sa1 + t2 * sa2
    fn = t1 * (-y1 * ca1 + x1 * sa1) + t2 * (-y2 * ca2 + x2 * sa2)
    b0 = (fx + (m22 * vv + m23 * r) * r + (a22 * vr + a23 * r) * r
          - (dl[0] * ur + dl[1] * vr + dl[2] * r + dq0 * abs(ur) * ur)
          + ma[0] * r * vc - ma[1] * r * uc)  # fmt: skip
    b1 = (fy - m11 * uu * r - a11 * ur * r
          - (dl[3] * ur + dl[4] * vr + dl[5] * r + dq1 * abs(vr) * vr)
          + ma[3] * r * vc - ma[4] * r * uc)  # fmt: skip
    b2 = (fn - ((m22 * vv + m23 * r) * uu - m11 * uu * vv)
          - ((a22 * vr + a23 * r) * ur - a11 * ur * vr)
          - (dl[6] * ur + dl[7] * vr + dl[8] * r + dq2 * abs(r) * r)
          + ma[6] * r * vc - ma[7] * r * uc)  # fmt: skip
    tmax = tb * min(max(1.0 - adv * ur * iu0, 0.0), 1.0)
    return (
        cs * uu - sn * vv,
        sn * uu + cs * vv,
        r,
        mi[0] * b0 + mi[1] * b1 + mi[2] * b2,
        mi[3] * b0 + mi[4] * b1 + mi[5] * b2,
        mi[6] * b0 + mi[7] * b1 + mi[8] * b2,
        (min(max(u0, 0.0), tmax) - th1) * itt,
        (min(max(u1, 0.0), tmax) - th2) * itt,
        min(max((min(max(u2, -amax), amax) - al1) * ita, -arate), arate),
        min(max((min(max(u3, -amax), amax) - al2) * ita, -arate), arate),
    )


@numba.njit(error_model="numpy", nogil=True, inline="always")
def _axpy(s0, a, k):  # pragma: no cover - jit
    return (s0[0] + a * k[0], s0[1] + a * k[1], s0[2] + a * k[2], s0[3] + a * k[3],
            s0[4] + a * k[4], s0[5] + a * k[5], s0[6] + a * k[6], s0[7] + a * k[7],
            s0[8] + a * k[8], s0[9] + a * k[9])  # fmt: skip


@numba.njit(error_model="numpy", nogil=True)
def _reference_step(X, U, C, q, h):  # pragma: no cover - jit
    for i in range(X.shape[1]):
        s0 = (X[0, i], X[1, i], X[2, i], X[3, i], X[4, i],
              X[5, i], X[6, i], X[7, i], X[8, i], X[9, i])  # fmt: skip
        u = (U[0, i], U[1, i], U[2, i], U[3, i])
        cn, ce = C[0, i], C[1, i]
        k1 = _deriv(s0, u, cn, ce, q)
        k2 = _deriv(_axpy(s0, 0.5 * h, k1), u, cn, ce, q)
        k3 = _deriv(_axpy(s0, 0.5 * h, k2), u, cn, ce, q)
        k4 = _deriv(_axpy(s0, h, k3), u, cn, ce, q)
        # k1 + 2 k2 + 2 k3 + k4, then the step; written as tuples (a loop over a tuple's
        # entries indexes it at run time, which keeps the values in memory and the loop scalar)
        ks = _axpy(_axpy(_axpy(k1, 2.0, k2), 2.0, k3), 1.0, k4)
        (X[0, i], X[1, i], X[2, i], X[3, i], X[4, i], X[5, i], X[6, i], X[7, i], X[8, i],
         X[9, i]) = _axpy(s0, h / 6.0, ks)  # fmt: skip


def _constants(p: np.ndarray) -> tuple:
    """The packed parameters as a tuple of floats (registers, no memory in the loop)."""
    f = [float(v) for v in p]
    return (
        tuple(f[0:9]), tuple(f[9:18]), tuple(f[18:27]), *f[R.P_MRB : R.P_MRB + 3],
        *f[R.P_MA_C : R.P_MA_C + 3], *f[R.P_DQ : R.P_DQ + 3], *f[R.P_POD : R.P_POD + 4],
        f[R.P_INV_TAU_T], f[R.P_INV_TAU_A], f[R.P_ARATE], f[R.P_AMAX], f[R.P_TBOLL],
        f[R.P_INV_U0], f[R.P_HULL_T], f[R.P_ADV],
    )  # fmt: skip


def _start(ships: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    x = np.zeros((ships, 10))
    x[:, 2] = rng.uniform(-np.pi, np.pi, ships)
    x[:, 3] = rng.uniform(2.0, 6.0, ships)
    x[:, 5] = rng.uniform(-0.05, 0.05, ships)
    x[:, 6:8] = rng.uniform(1e4, 4e4, (ships, 2))
    x[:, 8:10] = rng.uniform(-0.3, 0.3, (ships, 2))
    u = np.column_stack([x[:, 6] * 1.1, x[:, 7] * 1.1, x[:, 8] + 0.1, x[:, 9] - 0.1])
    c = rng.uniform(-0.5, 0.5, (ships, 2))
    return x, u, c


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ships", type=int, default=4096)
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()
    p = R.pack_rvg(RVGParams())
    assert p[R.P_LIFT] == p[R.P_CF] == p[R.P_XW] == p[R.P_XVV] == 0.0
    x, u, c = _start(args.ships)
    q = _constants(p)
    h = 0.1
    # the two agree before anything is timed
    a = x.copy()
    XT, UT = np.ascontiguousarray(x.T), np.ascontiguousarray(u.T)
    CT = integrate.disturbance_block(c)
    for _ in range(100):
        integrate.rk4_step_kernel(integrate.RVG3DOF, a, u, p, c, h)
        _reference_step(XT, UT, CT, q, h)
    worst = float((np.abs(a - XT.T) / (np.abs(a) + 1.0)).max())
    print(f"agreement after 100 steps: max |diff| / (|x| + 1) = {worst:.1e}")
    if worst > 1e-9:
        raise SystemExit("the package's step and the reference disagree")

    W = np.empty((3, 10, args.ships))
    block = integrate.rk4_block

    @numba.njit(error_model="numpy")
    def block_step(X, U, p, C, h, W):  # pragma: no cover - jit
        block(integrate.RVG3DOF, X, U, p, C, h, X.shape[1], W)

    block_step(XT, UT, p, CT, h, W)
    runs = {
        "package rk4_step_kernel (ships as rows)": lambda: integrate.rk4_step_kernel(
            integrate.RVG3DOF, a, u, p, c, h
        ),
        "package rk4_block (one block)": lambda: block_step(XT, UT, p, CT, h, W),
        "reference loop": lambda: _reference_step(XT, UT, CT, q, h),
    }
    times: dict[str, list[float]] = {k: [] for k in runs}
    steps = 20
    for _ in range(args.repeats):
        for name, fn in runs.items():
            t0 = time.perf_counter()
            for _ in range(steps):
                fn()
            times[name].append((time.perf_counter() - t0) / steps)
    ref = statistics.median(times["reference loop"])
    print(f"{args.ships} ships, one thread, medians of {args.repeats} interleaved repeats")
    for name, ts in times.items():
        med = statistics.median(ts)
        print(f"  {name:42s} {args.ships / med / 1e6:7.2f} M ship-steps/s  x{med / ref:5.2f}")


if __name__ == "__main__":
    main()

"""How fast a NomotoHeading vector step can be on this machine, against CartPoleVectorEnv.

``shipgym bench`` times the heading env's vector step against Gymnasium's CartPoleVectorEnv.
This script times, in one process and in interleaved rounds, beside those two:

* the attainable step: the same task written as fast as the package's physics allows, with
  nothing the env must also do. The ships' states are held as structure of arrays (no rows to
  gather into blocks and scatter back), and one pass per block of 32 ships clips and maps the
  rudder orders, takes the package's own RK4 step of the first-order Nomoto model
  (``integrate._rk4`` with ``nomoto.nomoto1_col``, the derivative every user of the model
  shares), and writes the heading error, the float32 observation, the reward and the
  finite-state flag. It builds no ``info``, no autoreset, no check of the actions, no
  per-sub-env termination reason, and writes no previous observation for a blow-up. It is a
  yardstick for the target "NomotoHeading vector step >= 3 x CartPoleVectorEnv", not a second
  env: nothing in the package uses it.
* that loop on both cores (two halves of the batch on two threads, the loop releases the GIL),
* the env's step with and without its ``info`` (``step_info``).

It prints million environment steps per second and, for each, the median over the rounds of
its ratio to CartPoleVectorEnv timed in the same round.

Usage: ``python scripts/bench_heading_bound.py [--envs N] [--repeats N] [--plot OUT.png]``
(``--plot`` draws the ratios as bars, with the target and parity with CartPoleVectorEnv).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from concurrent.futures import ThreadPoolExecutor

import gymnasium as gym
import numba
import numpy as np
from gymnasium.envs.classic_control.cartpole import CartPoleVectorEnv

import shipgym  # noqa: F401  (registers the environments)
from shipgym.models import integrate
from shipgym.models.angles import ssa_scalar
from shipgym.models.nomoto import IDELTA, IPSI, IR, IU, nomoto1_col

ENV_ID = "shipgym/NomotoHeading-v0"
BLOCK = integrate.BLOCK
NX = 6  # first-order Nomoto states: x, y, psi, u, r, delta


@numba.njit(error_model="numpy", nogil=True)
def _attainable_step(
    X, A, U, C, p, h, steps, hold, sched, obs, rew, ok, lo, hi
):  # pragma: no cover - jit
    """One heading step of ships ``0 .. X.shape[1] - 1`` (a multiple of ``BLOCK``)."""
    n = X.shape[1]
    last = sched.shape[0] - 1
    dmax = p[0]
    XB = np.empty((NX, BLOCK))
    UB = np.empty((2, BLOCK))
    CB = np.zeros((integrate.NC, BLOCK))  # current; no seaway load
    W = np.empty((3, NX, BLOCK))
    for s in range(0, n, BLOCK):
        for b in range(BLOCK):
            UB[0, b] = dmax * min(max(A[s + b], -1.0), 1.0)
            UB[1, b] = U[s + b]
            CB[0, b] = C[0, s + b]
            CB[1, b] = C[1, s + b]
            for j in range(NX):
                XB[j, b] = X[j, s + b]
        integrate._rk4(integrate._cols, nomoto1_col, NX, XB, UB, p, CB, h, BLOCK, W)
        for b in range(BLOCK):
            i = s + b
            finite = True
            for j in range(NX):
                X[j, i] = XB[j, b]
                finite &= math.isfinite(XB[j, b])
            steps[i] += 1
            e = ssa_scalar(sched[min(steps[i] // hold, last), i] - XB[IPSI, b])
            a = min(max(A[i], -1.0), 1.0)
            obs[i, 0] = np.float32(min(max(e, lo[0]), hi[0]))
            obs[i, 1] = np.float32(min(max(XB[IR, b], lo[1]), hi[1]))
            obs[i, 2] = np.float32(min(max(XB[IDELTA, b], lo[2]), hi[2]))
            rew[i] = (-abs(e) / math.pi - 0.05 * a * a) if finite else 0.0
            ok[i] = finite


class _Ships:
    """The attainable step's arrays for ``n`` ships (each contiguous, states as rows)."""

    def __init__(self, n: int, p: np.ndarray, seed: int) -> None:
        rng = np.random.default_rng(seed)
        self.X = np.zeros((NX, n))
        self.X[IU] = 7.0
        self.X[IPSI] = rng.uniform(-np.pi, np.pi, n)
        self.A = rng.uniform(-1.0, 1.0, n)
        self.U = np.full(n, 7.0)
        self.C = rng.uniform(-0.5, 0.5, (2, n))
        self.steps = np.zeros(n, dtype=np.int64)
        self.sched = rng.uniform(-np.pi, np.pi, (8, n))
        self.obs = np.zeros((n, 3), dtype=np.float32)
        self.rew = np.zeros(n)
        self.ok = np.zeros(n, dtype=np.bool_)
        self.lo = np.array([-math.pi, -0.5, -math.pi / 2])
        self.hi = -self.lo
        self.p = p

    def step(self) -> None:
        _attainable_step(self.X, self.A, self.U, self.C, self.p, 1.0, self.steps, 200,
                         self.sched, self.obs, self.rew, self.ok, self.lo, self.hi)  # fmt: skip


class Attainable:
    """``n`` ships of the attainable step in ``threads`` equal parts, one per thread."""

    def __init__(self, n: int, p: np.ndarray, threads: int, pool: ThreadPoolExecutor) -> None:
        self.parts = [_Ships(n // threads, p, seed) for seed in range(threads)]
        self.pool = pool

    def step(self, max_steps: int = 800) -> tuple[np.ndarray, ...]:
        """One step, with what a vector step hands back (the copies and flags, no info)."""
        futures = [self.pool.submit(part.step) for part in self.parts[1:]]
        self.parts[0].step()
        for f in futures:
            f.result()
        if len(self.parts) == 1:
            part = self.parts[0]
            return part.obs.copy(), part.rew.copy(), ~part.ok, part.steps >= max_steps
        return (
            np.concatenate([part.obs for part in self.parts]),
            np.concatenate([part.rew for part in self.parts]),
            ~np.concatenate([part.ok for part in self.parts]),
            np.concatenate([part.steps for part in self.parts]) >= max_steps,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--envs", type=int, default=4096)
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--steps", type=int, default=100, help="vector steps per repeat")
    parser.add_argument("--plot", metavar="OUT.png", help="write a bar chart of the ratios")
    args = parser.parse_args()
    n = args.envs - args.envs % (2 * BLOCK)
    if n < 2 * BLOCK:
        raise SystemExit(f"--envs must be at least {2 * BLOCK}")

    def make(step_info: bool) -> gym.vector.VectorEnv:
        env = gym.make_vec(ENV_ID, num_envs=n, vectorization_mode="vector_entry_point",
                           step_info=step_info)  # fmt: skip
        env.reset(seed=0)
        return env

    full, lean = make(True), make(False)
    p = np.ascontiguousarray(full.unwrapped.task.model.p)
    cart = CartPoleVectorEnv(num_envs=n)
    cart.reset(seed=0)
    rng = np.random.default_rng(0)
    act = rng.uniform(-1.0, 1.0, (n, 1)).astype(np.float32)
    cart_act = rng.integers(0, 2, n)
    pool = ThreadPoolExecutor(1)
    one, two = Attainable(n, p, 1, pool), Attainable(n, p, 2, pool)
    runs = {
        "CartPoleVectorEnv": lambda: cart.step(cart_act),
        "NomotoHeading-v0 vector step": lambda: full.step(act),
        "NomotoHeading-v0, step_info=False": lambda: lean.step(act),
        "attainable heading step, 1 thread": one.step,
        "attainable heading step, 2 threads": two.step,
    }
    for fn in runs.values():  # compile and warm up
        for _ in range(5):
            fn()
    rates: dict[str, list[float]] = {k: [] for k in runs}
    for r in range(args.repeats):
        for name, fn in runs.items():
            t0 = time.perf_counter()
            for _ in range(args.steps):
                fn()
            rates[name].append(args.steps * n / (time.perf_counter() - t0))
        print(f"  round {r + 1}/{args.repeats}", flush=True)
    cart_rates = rates["CartPoleVectorEnv"]
    print(f"{n} envs, medians of {args.repeats} interleaved rounds of {args.steps} steps")
    print("| step | M env-steps/s | ratio to CartPoleVectorEnv (same round) |")
    print("|---|---:|---:|")
    ratios = {}
    for name, values in rates.items():
        ratios[name] = statistics.median(a / b for a, b in zip(values, cart_rates, strict=True))
        print(f"| {name} | {statistics.median(values) / 1e6:.2f} | {ratios[name]:.2f} |")
    pool.shutdown()
    if args.plot:
        _plot(ratios, n, args.repeats, args.plot)


def _plot(ratios: dict[str, float], n: int, repeats: int, path: str) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 4.6), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    names = [k for k in ratios if k != "CartPoleVectorEnv"]
    values = [ratios[k] for k in names]
    colors = ["#b8312f" if k.startswith("NomotoHeading") else "#4a7ab8" for k in names]
    bars = ax.bar(range(len(names)), values, color=colors, width=0.6, zorder=2)
    ax.bar_label(bars, fmt="%.2f", fontsize=9)
    ax.axhline(3.0, color="black", ls="--", lw=1.4, label="target: NomotoHeading >= 3 x")
    ax.axhline(1.0, color="#555555", lw=0.8, label="parity with CartPoleVectorEnv")
    ax.set_xticks(range(len(names)), [k.replace(", ", ",\n") for k in names], fontsize=8)
    ax.set_ylim(0, 3.9)
    ax.set_ylabel("steps/s / CartPoleVectorEnv steps/s")
    ax.set_title(
        f"NomotoHeading vector step ({n} envs) against the attainable heading step\n"
        f"(median of {repeats} same-round ratios; red: the env, blue: the yardstick)",
        fontsize=10,
    )
    ax.grid(True, axis="y", alpha=0.3, zorder=0)
    ax.legend(fontsize=8, loc="upper right")
    fig.savefig(path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()

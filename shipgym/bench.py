"""Speed benchmark of the shipgym environments against Gymnasium's CartPole (``shipgym bench``).

All numbers come from one process, so they share the machine state and are comparable:

* **single**: time per ``env.step`` through :func:`gymnasium.make` (so with Gymnasium's
  default wrappers) for ``CartPole-v1`` and every shipgym id, in the same loop: one fixed
  action drawn once from the seeded action space, ``reset`` on ``terminated or truncated``,
  warm-up steps first. Ratio ``env_time / cartpole_time`` (lower is better).
* **vector**: environment steps per second of the NumPy-batched vector envs,
  ``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point")``, against
  Gymnasium's ``CartPoleVectorEnv(num_envs=N)``, each stepped with one fixed batch of random
  actions (autoreset inside the env). Ratio ``env_sps / cartpole_sps`` (higher is better).
  The envs with a vector target are also timed with ``step_info=False`` (no ``info`` built,
  as a training loop that never reads it runs them; :class:`~shipgym.envs.core.ShipVectorEnv`),
  which shows how much of the step the ``info`` takes; the targets are for the full ``info``.

Every env is made and warmed up first; then each of the ``repeats`` rounds times one loop of
every measurement in turn, CartPole included, and a measurement's ratio is the median over the
rounds of its ratio to CartPole in the same round. A shared machine changes speed by tens of
per cent from one minute to the next (a neighbour's load, the clock); within a round both sides
of a ratio see the same machine, so such a change cancels, where ratios of values timed minutes
apart would carry it. Reported besides: the best and the median of each measurement's values.

Each vector env is measured on one thread (``num_threads=1``, the default) and on one thread
per CPU (``num_threads=None``); ``busy=N`` (``shipgym bench --busy N``) runs the whole
benchmark while ``N`` helper processes keep cores busy, as an RL learner, a test suite or a
sweep does, so that both paths are compared on shared cores too. CartPole is measured under
the same load, so the ratios compare like with like.

Targets (``TARGETS``) are printed as PASS/MISS. It is a measurement, not a test: the exit code
does not depend on them.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import platform
import statistics
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, TextIO

import gymnasium as gym
import numpy as np

import shipgym
from shipgym.envs import CURRENT_ENV_IDS, ENV_IDS
from shipgym.envs.kernels import available_threads

CARTPOLE_ID = "CartPole-v1"
CARTPOLE_VECTOR = "CartPoleVectorEnv"

#: Targets: (kind, env id, threads) -> (comparison, value), on an idle machine. Single: time
#: ratio, lower is better; vector: throughput ratio at that many threads (0: all of them),
#: higher is better.
TARGETS: dict[tuple[str, str, int], tuple[str, float]] = {
    ("single", "shipgym/NomotoHeading-v0", 1): ("<=", 1.0),
    ("single", "shipgym/RVGPathFollowing-v1", 1): ("<=", 1.5),
    ("vector", "shipgym/RVGPathFollowing-v1", 0): (">=", 2.0),
    ("vector", "shipgym/RVGPathFollowing-v1", 1): (">=", 1.0),
    ("vector", "shipgym/NomotoHeading-v0", 0): (">=", 3.0),
}

DEFAULT_STEPS = 20_000
DEFAULT_NUM_ENVS = 4096
DEFAULT_REPEATS = 5


@dataclass
class Measurement:
    """One benchmark line.

    Attributes
    ----------
    kind : {"single", "vector"}
    env_id : str
    best, median : float
        Single: seconds per step; vector: environment steps per second.
    repeats : list of float
        Every repeat (same unit), one per round.
    threads : int
        Threads of a vector env's step (``num_threads``); 1 for the single env and CartPole.
    info : bool
        Whether a vector env's step built its ``info`` (``step_info``); True for the others.
    ratio : float or None
        Against CartPole: the median of ``round_ratios`` (``None`` for the CartPole lines).
    round_ratios : list of float
        The ratio to CartPole timed in the same round, one per round.
    target : str or None
        E.g. ``"<= 1.0"``.
    passed : bool or None
    """

    kind: str
    env_id: str
    best: float
    median: float
    repeats: list[float] = field(default_factory=list)
    threads: int = 1
    info: bool = True
    ratio: float | None = None
    round_ratios: list[float] = field(default_factory=list)
    target: str | None = None
    passed: bool | None = None

    @property
    def unit(self) -> str:
        return "s/step" if self.kind == "single" else "steps/s"


def _check_target(
    kind: str, env_id: str, threads: int, ratio: float, info: bool = True
) -> tuple[str | None, bool | None]:
    if not info:  # the targets are for the step with its info
        return None, None
    all_threads = threads == available_threads() and threads > 1
    target = TARGETS.get((kind, env_id, 0 if all_threads else threads))
    if target is None:
        return None, None
    op, value = target
    passed = ratio <= value if op == "<=" else ratio >= value
    return f"{op} {value}", bool(passed)


class _Loop:
    """One measurement's env, made and warmed up once, then timed one repeat at a time.

    ``kind`` ``"single"``: ``gymnasium.make(env_id)``, :meth:`time` returns seconds per step;
    ``"vector"``: a vector env of ``num_envs`` (``threads``: its ``num_threads``, ``info``: its
    ``step_info``), :meth:`time` returns environment steps per second.
    """

    def __init__(
        self,
        kind: str,
        env_id: str,
        steps: int,
        warmup: int,
        num_envs: int = 1,
        threads: int = 1,
        info: bool = True,
        seed: int = 0,
    ) -> None:
        self.kind, self.steps, self.num_envs = kind, steps, num_envs
        self.env: Any = (
            gym.make(env_id) if kind == "single" else _make_vector(env_id, num_envs, threads, info)
        )
        self.env.action_space.seed(seed)
        self.action = self.env.action_space.sample()
        self.env.reset(seed=seed)
        self._run(warmup)

    def _run(self, n: int) -> None:
        step, action = self.env.step, self.action
        if self.kind == "vector":  # (autoreset inside the env)
            for _ in range(n):
                step(action)
            return
        reset = self.env.reset
        for _ in range(n):
            _, _, terminated, truncated, _ = step(action)
            if terminated or truncated:
                reset()

    def time(self) -> float:
        """Time one repeat: seconds per step (single) or environment steps per second."""
        t0 = time.perf_counter()
        self._run(self.steps)
        elapsed = time.perf_counter() - t0
        return (
            elapsed / self.steps if self.kind == "single" else self.steps * self.num_envs / elapsed
        )

    def close(self) -> None:
        self.env.close()


def _make_vector(
    env_id: str, num_envs: int, threads: int = 1, info: bool = True
) -> gym.vector.VectorEnv:
    if env_id == CARTPOLE_VECTOR:
        from gymnasium.envs.classic_control.cartpole import CartPoleVectorEnv

        return CartPoleVectorEnv(num_envs=num_envs)
    return gym.make_vec(
        env_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        num_threads=threads,
        step_info=info,
    )


def _spin(stop: Any) -> None:  # pragma: no cover - runs in a helper process
    """Keep one core busy until ``stop`` is set (a helper of ``busy``)."""
    x = 0
    while not stop.is_set():
        for _ in range(100_000):
            x += 1


class BusyCores:
    """Context manager that keeps ``n`` helper processes spinning on the CPU.

    Parameters
    ----------
    n : int
        Helper processes (0: none). Each is a plain Python loop, a stand-in for the other
        work on a shared machine (a learner's gradient steps, a test suite, a sweep).
    """

    def __init__(self, n: int) -> None:
        if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= 64:
            raise ValueError(f"busy must be an integer in [0, 64] helper processes, got {n!r}")
        self.n = n
        self._procs: list[Any] = []
        self._stop: Any = None

    def __enter__(self) -> BusyCores:
        if self.n:
            ctx = multiprocessing.get_context("spawn")
            self._stop = ctx.Event()
            self._procs = [
                ctx.Process(target=_spin, args=(self._stop,), daemon=True) for _ in range(self.n)
            ]
            for p in self._procs:
                p.start()
            time.sleep(0.5)  # let them start spinning
        return self

    def __exit__(self, *exc: object) -> None:
        if self._stop is not None:
            self._stop.set()
        for p in self._procs:
            # a helper still importing its module (spawn: seconds on loaded cores) stops at its
            # first poll once it runs
            p.join(timeout=60)
            if p.is_alive():  # pragma: no cover - a helper that ignores the event
                p.terminate()
        self._procs = []


def _fmt_value(m: Measurement) -> str:
    if m.kind == "single":
        return f"{m.best * 1e6:8.2f} us/step"
    return f"{m.best / 1e6:8.3f} M steps/s"


def run_bench(
    steps: int = DEFAULT_STEPS,
    num_envs: int = DEFAULT_NUM_ENVS,
    repeats: int = DEFAULT_REPEATS,
    vec_steps: int | None = None,
    env_ids: tuple[str, ...] = CURRENT_ENV_IDS,
    progress: TextIO | bool = True,
    threads: tuple[int | None, ...] = (1, None),
    busy: int = 0,
) -> dict[str, Any]:
    """Run the benchmark and return its results (the ``--json`` content).

    Parameters
    ----------
    steps : int
        Timed steps per repeat of the single-env loop (warm-up: a tenth of it, at least 10).
    num_envs : int
        Batch size of the vector envs.
    repeats : int
        Rounds: each times one repeat of every measurement, CartPole included.
    vec_steps : int, optional
        Timed batched steps per repeat of the vector loop; default ``max(5, steps // 200)``.
    env_ids : tuple of str
        shipgym ids to measure.
    progress : file or bool
        Where a line per round (as it completes) and a line per measurement are printed: a
        file, ``True`` for ``sys.stderr`` (the default) or ``False`` for silence.
    threads : tuple of int or None
        ``num_threads`` values each vector env is measured with (``None``: one thread per
        CPU; a value equal to an earlier one is measured once).
    busy : int
        Helper processes that keep cores busy during the whole benchmark (:class:`BusyCores`).

    Returns
    -------
    dict
        ``config``, ``system``, ``results`` (list of measurements) and ``ratios``
        (``{"single": {id: ratio}, "vector": {id: ratio}}``).
    """
    for name, value in (("steps", steps), ("num_envs", num_envs), ("repeats", repeats)):
        if not isinstance(value, int) or value < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    vec_steps = max(5, steps // 200) if vec_steps is None else vec_steps
    if not isinstance(vec_steps, int) or vec_steps < 1:
        raise ValueError(f"vec_steps must be an integer >= 1, got {vec_steps!r}")
    unknown = [e for e in env_ids if e not in ENV_IDS]
    if unknown:
        raise ValueError(f"unknown env id(s) {unknown}; expected any of {list(ENV_IDS)}")
    max_threads = available_threads()
    thread_counts: list[int] = []
    for t in threads:
        count = max_threads if t is None else t
        if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= max_threads:
            raise ValueError(f"threads must be in [1, {max_threads}] or None, got {t!r}")
        if count not in thread_counts:
            thread_counts.append(count)
    busy_cores = BusyCores(busy)
    stream: TextIO | None = sys.stderr if progress is True else (progress or None)
    warmup = max(10, steps // 10)
    vec_warmup = max(2, vec_steps // 10)

    plan: list[tuple[str, str, int, bool]] = [
        ("single", e, 1, True) for e in (CARTPOLE_ID, *env_ids)
    ]
    with_target = {env_id for kind, env_id, _ in TARGETS if kind == "vector"}
    for env_id in (CARTPOLE_VECTOR, *env_ids):
        for count in [1] if env_id == CARTPOLE_VECTOR else thread_counts:
            plan.append(("vector", env_id, count, True))
        if env_id in with_target:  # and without building the info
            plan.extend(("vector", env_id, count, False) for count in thread_counts)

    def say(line: str) -> None:
        if stream is not None:
            print(line, file=stream, flush=True)

    t_start = time.perf_counter()
    values: list[list[float]] = [[] for _ in plan]
    loops: list[_Loop] = []
    with busy_cores:
        try:
            for kind, env_id, count, info in plan:  # make and warm up every env first
                single = kind == "single"
                loops.append(
                    _Loop(kind, env_id, steps, warmup)
                    if single
                    else _Loop(kind, env_id, vec_steps, vec_warmup, num_envs, count, info)
                )
            say(f"shipgym bench: {len(plan)} envs made and warmed up; {repeats} rounds")
            for r in range(repeats):  # every measurement once per round
                for k, loop in enumerate(loops):
                    values[k].append(loop.time())
                say(f"  round {r + 1}/{repeats} done ({time.perf_counter() - t_start:.0f} s)")
        finally:
            for loop in loops:
                loop.close()

    results: list[Measurement] = []
    reference = {kind: values[k] for k, (kind, env_id, _, _) in enumerate(plan)
                 if env_id in (CARTPOLE_ID, CARTPOLE_VECTOR)}  # fmt: skip
    for k, (kind, env_id, count, info) in enumerate(plan, start=1):
        v = values[k - 1]
        best = min(v) if kind == "single" else max(v)
        m = Measurement(kind, env_id, best, statistics.median(v), v, count, info)
        if env_id not in (CARTPOLE_ID, CARTPOLE_VECTOR):
            m.round_ratios = [a / b for a, b in zip(v, reference[kind], strict=True)]
            m.ratio = statistics.median(m.round_ratios)
            if not busy:  # the targets are for an idle machine
                m.target, m.passed = _check_target(kind, env_id, count, m.ratio, info)
        results.append(m)
        extra = "" if m.ratio is None else f"  ratio {m.ratio:.3f}"
        where = f"{env_id} ({_threads_label(m.threads, m.info)})" if kind == "vector" else env_id
        say(f"[{k:2d}/{len(plan)}] {kind:6s} {where:38s} {_fmt_value(m)}{extra}")

    ratios: dict[str, dict[str, float]] = {"single": {}, "vector": {}}
    for m in results:
        if m.ratio is not None:
            key = m.env_id if m.kind == "single" else f"{m.env_id} threads={m.threads}"
            ratios[m.kind][key + ("" if m.info else " no info")] = m.ratio
    return {
        "config": {
            "steps": steps,
            "vec_steps": vec_steps,
            "num_envs": num_envs,
            "repeats": repeats,
            "threads": thread_counts,
            "busy": busy,
            "warmup": warmup,
            "vec_warmup": vec_warmup,
            "single_reference": CARTPOLE_ID,
            "vector_reference": CARTPOLE_VECTOR,
            "statistic": (
                "ratio: median over the rounds of the ratio to CartPole timed in the same round; "
                "best: min time per step, max steps per second"
            ),
        },
        "system": {
            "shipgym": shipgym.__version__,
            "gymnasium": gym.__version__,
            "numpy": np.__version__,
            "numba": _numba_version(),
            "python": platform.python_version(),
            "platform": platform.platform(),
            "cpu_count": os.cpu_count(),
            "elapsed_s": round(time.perf_counter() - t_start, 2),
        },
        "results": [asdict(m) for m in results],
        "ratios": ratios,
        "targets": {
            f"{kind} {env_id} threads={t or 'all'}": f"{op} {v}"
            for (kind, env_id, t), (op, v) in TARGETS.items()
        },
    }


def _threads_label(threads: int, info: bool) -> str:
    """``"2 thr"``, or ``"2 thr, no info"`` for a vector step without its ``info``."""
    return f"{threads} thr" + ("" if info else ", no info")


def _numba_version() -> str:
    try:
        import numba
    except ImportError:  # pragma: no cover - numba is a dependency
        return "n/a"
    return str(numba.__version__)


def format_table(report: dict[str, Any]) -> str:
    """The results as a plain-text table (Markdown-compatible)."""
    cfg = report["config"]
    lines = [
        f"shipgym bench: {cfg['repeats']} rounds, ratio = median over the rounds of the ratio to "
        f"CartPole in the same round; single env {cfg['steps']} steps per round via "
        f"gymnasium.make; vector {cfg['num_envs']} envs x {cfg['vec_steps']} steps"
        + (f"; {cfg['busy']} busy helper processes" if cfg.get("busy") else "; idle"),
        "",
        "| measurement | env | threads | best | median | ratio vs CartPole | target | result |",
        "|---|---|---:|---:|---:|---:|---:|---|",
    ]
    for r in report["results"]:
        if r["kind"] == "single":
            best, median = f"{r['best'] * 1e6:.2f} us/step", f"{r['median'] * 1e6:.2f} us/step"
            what = "single env step time"
        else:
            best, median = f"{r['best'] / 1e6:.3f} M/s", f"{r['median'] / 1e6:.3f} M/s"
            what = f"vector env steps/s ({cfg['num_envs']})"
        ratio = "-" if r["ratio"] is None else f"{r['ratio']:.3f}"
        target = r["target"] or "-"
        result = "" if r["passed"] is None else ("PASS" if r["passed"] else "MISS")
        threads = f"{r.get('threads', 1)}" + ("" if r.get("info", True) else ", no info")
        lines.append(
            f"| {what} | {r['env_id']} | {threads} | {best} | {median} | {ratio} "
            f"| {target} | {result} |"
        )
    return "\n".join(lines)


def plot_ratios(report: dict[str, Any], path: str | Path) -> Path:
    """Bar chart of the ratios against CartPole with the targets; writes a PNG."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    cfg = report["config"]
    fig = Figure(figsize=(14, 5.8), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2, width_ratios=[1, 2.6])
    titles = {
        "single": (
            "single env: step time / CartPole-v1 step time\n(lower is better)",
            "time ratio",
        ),
        "vector": (
            f"vector env ({cfg['num_envs']} envs): steps/s / CartPoleVectorEnv steps/s"
            "\n(higher is better)",
            "throughput ratio",
        ),
    }
    for ax, kind in zip(axes, ("single", "vector"), strict=True):
        rows = [r for r in report["results"] if r["kind"] == kind and r["ratio"] is not None]
        names = [
            r["env_id"].removeprefix("shipgym/")
            + (
                f" ({_threads_label(r.get('threads', 1), r.get('info', True))})"
                if kind == "vector"
                else ""
            )
            for r in rows
        ]
        values = [r["ratio"] for r in rows]
        colors = [
            "#9a9a9a" if r["passed"] is None else ("#2a8a4a" if r["passed"] else "#b8312f")
            for r in rows
        ]
        x = np.arange(len(rows))
        hatches = ["" if r.get("info", True) else "//" for r in rows]
        bars = ax.bar(x, values, color=colors, width=0.6, zorder=2, hatch=hatches, ec="white")
        top = max([*values, *(float(r["target"].split()[1]) for r in rows if r["target"]), 1.0])
        ax.set_ylim(0, 1.18 * top)
        for bar, v in zip(bars, values, strict=True):
            label = f"{v:.3f}" if v < 1 else f"{v:.2f}"
            inside = v > 0.25 * top  # value inside the bar top; short bars get it above
            ax.annotate(
                label,
                xy=(bar.get_x() + bar.get_width() / 2, v),
                xytext=(0, -4 if inside else 3),
                textcoords="offset points",
                ha="center",
                va="top" if inside else "bottom",
                fontsize=8,
                fontweight="bold",
                color="white" if inside else "black",
                zorder=4,
            )
        for i, r in enumerate(rows):
            if r["target"]:
                value = float(r["target"].split()[1])
                ax.hlines(
                    value, i - 0.42, i + 0.42, colors="black", linestyles="--", lw=1.6, zorder=3
                )
                ax.annotate(
                    f"target {r['target']}",
                    xy=(i, value),
                    xytext=(0, 4),
                    textcoords="offset points",
                    ha="center",
                    fontsize=8,
                    zorder=4,
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
                )
        ax.axhline(1.0, color="#555555", lw=0.8, zorder=1)
        ax.set_xticks(x, names, rotation=20 if kind == "single" else 35, ha="right", fontsize=9)
        ax.set_title(titles[kind][0], fontsize=10)
        ax.set_ylabel(titles[kind][1])
        ax.grid(True, axis="y", alpha=0.3, zorder=0)
    handles = [
        Line2D([], [], color="#2a8a4a", lw=8, label="meets target"),
        Line2D([], [], color="#b8312f", lw=8, label="misses target"),
        Line2D([], [], color="#9a9a9a", lw=8, label="no target"),
        Patch(fc="#9a9a9a", ec="white", hatch="//", label="without info (step_info=False)"),
        Line2D([], [], color="black", ls="--", lw=1.6, label="target"),
        Line2D([], [], color="#555555", lw=0.8, label="parity with CartPole"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncols=6, fontsize=9)
    sysinfo = report["system"]
    fig.suptitle(
        f"shipgym {sysinfo['shipgym']} speed vs Gymnasium CartPole (one process, "
        f"{sysinfo['cpu_count']} CPUs, numba {sysinfo['numba']})\neach ratio: the median over "
        f"{cfg['repeats']} rounds of the ratio to CartPole timed in the same round",
        fontsize=11,
    )
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    return out


def write_json(report: dict[str, Any], path: str | Path) -> Path:
    """Write the report as JSON."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=2) + "\n")
    return out

"""Compile the kernels ahead of use: ``python -m shipgym.warmup [PART ...]``.

shipgym's kernels are compiled on first use and cached on disk
(:mod:`shipgym.models._jit`), after which every process loads them. A machine that starts
many processes at once from a cold cache (the test suite's workers, Ray workers, a fresh
container) would otherwise compile the same kernels in each of them. This runs the public
entry points once with the argument types they always get, so the cache holds every kernel:

* ``heading``, ``speed``, ``path_following``, ``target_tracking``: the envs of each task,
  single and vector (one step each; each task has its own kernel), ``envs`` all four;
* ``models``: every model's ``simulate``, ``step``, ``deriv`` and ``linearize``, and the
  standard manoeuvres' simulation;
* ``sysid``: the identification replays of the Nomoto-family fits, the steering-gear lag and
  the R/V Gunnerus model's windows, on short synthetic records.

The parts are independent: ``python -m shipgym.warmup --parallel`` runs them in two processes
of about equal compile time at once (:data:`PARALLEL_GROUPS`), so the next call costs nothing
(the test suite does this before its workers start).
A part that has run leaves a marker in the cache folder, which is keyed by the kernels' content
(:data:`shipgym.models._jit.CACHE_DIR`): :func:`cold_parts` tells which parts a run would have
to compile, and :func:`compile_estimate_s` about how long that takes
(:data:`COLD_COMPILE_S`, measured), which ``shipgym benchmark`` announces before it warms
the parts it needs (:data:`BENCHMARK_GROUPS`).
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

__all__ = [
    "BENCHMARK_GROUPS",
    "COLD_COMPILE_S",
    "ENVS",
    "ENV_PARTS",
    "PARALLEL_GROUPS",
    "PARTS",
    "cold_parts",
    "compile_estimate_s",
    "main",
    "warm",
    "warm_cache",
]


#: The env tasks (:data:`shipgym.envs.TASKS`) of each env part of the warm-up.
ENV_PARTS: dict[str, tuple[str, ...]] = {
    "heading": ("NomotoHeading", "RVGHeading"),
    "speed": ("RVGSpeed",),
    "path_following": ("RVGPathFollowing",),
    "target_tracking": ("RVGTargetTracking",),
}
#: What ``envs`` stands for: every env part.
ENVS = tuple(ENV_PARTS)


def _envs(tasks: Sequence[str]) -> None:
    import gymnasium as gym

    import shipgym  # noqa: F401 (registers the envs)
    from shipgym.envs import ENV_IDS, env_task

    for env_id in (i for i in ENV_IDS if env_task(i) in tasks):
        env = gym.make(env_id)
        env.reset(seed=0)
        env.step(env.action_space.sample())
        vec = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point")
        vec.reset(seed=0)
        vec.step(vec.action_space.sample())


def _models() -> None:
    from shipgym.models import MODEL_NAMES, make_model
    from shipgym.sysid.generator import vmm_truth

    for name in MODEL_NAMES:
        model = make_model(name, vmm_truth()) if name == "vmm" else make_model(name)
        x = np.zeros(model.nx)
        u = np.zeros(model.nu)
        model.simulate(x, np.zeros((2, model.nu)), 0.01)
        model.step(x, u, 0.01)
        model.deriv(x, u)
        model.linearize(x, u)


def _sysid() -> None:
    from shipgym.models import make_model
    from shipgym.sysid import generate_record
    from shipgym.sysid.families.base import lag_filter, window_starts
    from shipgym.sysid.families.rvg import replay_windows
    from shipgym.sysid.fit import replay

    t = np.arange(20.0)
    delta = np.radians(np.where(t < 10, 5.0, -5.0))
    for name in ("nomoto1", "nomoto2", "norrbin", "bech"):
        model = make_model(name)
        replay(name, model.params, t, delta, np.zeros(model.nx), U=7.7)
    lag_filter(t, delta, 2.0)
    rvg = generate_record(None, base_model="rvg3dof", dt=1.0, duration=20.0, seed=0)
    replay_windows(rvg, make_model("rvg3dof").params, window_starts(rvg.time, 10.0))


PARTS: dict[str, Callable[[], None]] = {
    **{part: functools.partial(_envs, tasks) for part, tasks in ENV_PARTS.items()},
    "models": _models,
    "sysid": _sysid,
}
"""The parts of the warm-up by name (``envs`` stands for :data:`ENVS`)."""


def _marker(part: str) -> Path | None:
    """The file that says part ``part`` of the warm-up has filled the cache (None: no cache)."""
    from shipgym.models._jit import CACHE_DIR

    return Path(CACHE_DIR) / f"warmup-{part}.done" if CACHE_DIR else None


def _expand(parts: Sequence[str]) -> list[str]:
    """``parts`` with ``envs`` written out (:data:`ENVS`), each once, in order.

    Raises
    ------
    ValueError
        For a name that is neither a part nor ``envs``.
    """
    unknown = [p for p in parts if p not in PARTS and p != "envs"]
    if unknown:
        raise ValueError(
            f"unknown warm-up part(s) {unknown}; expected any of {[*PARTS, 'envs']}"
        )
    out: list[str] = []
    for part in parts:
        out += [p for p in (ENVS if part == "envs" else (part,)) if p not in out]
    return out


def warm(parts: Sequence[str] = tuple(PARTS), say: Callable[[str], None] = print) -> None:
    """Run the warm-up ``parts`` (names of :data:`PARTS`, or ``envs``) in this process and mark
    each warm."""
    for part in _expand(parts):
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            PARTS[part]()
        marker = _marker(part)
        if marker is not None:
            marker.parent.mkdir(parents=True, exist_ok=True)
            marker.touch()
        say(f"shipgym warm-up: {part} in {time.perf_counter() - t0:.1f} s")


def cold_parts(parts: Sequence[str] = tuple(PARTS)) -> list[str]:
    """The ``parts`` (``envs`` written out) whose kernels are not in the cache yet (all of
    them without a cache)."""
    return [p for p in _expand(parts) if (marker := _marker(p)) is None or not marker.exists()]


#: Seconds of one core to compile each part from a cold cache, each part in a process of its
#: own or after the parts before it in its group: ``SHIPGYM_CACHE_DIR=<empty folder> python -m
#: shipgym.warmup <part>`` and the groups below, on a two-vCPU AMD EPYC virtual machine,
#: measured 2026-11-27 (Numba 0.68.1). A kernel already in the cache is loaded, not compiled:
#: in :data:`PARALLEL_GROUPS` ``models`` took 0.5 s (the parts before it or ``sysid`` beside it
#: had compiled what it needs), so the estimate of those groups is high by about 20 s.
#: ``heading`` and ``sysid`` are scaled by the ratio of their compile times after a change to
#: before it, side by side (2026-11-28): ``heading`` 35 s x 0.875 without the per-model copies
#: of the RK4 step (65.9 / 75.3 s), ``sysid`` 49 s x 0.86 with the Nomoto replays compiling
#: their own model alone (144 / 167 s).
COLD_COMPILE_S: dict[str, float] = {
    "heading": 30.5,
    "speed": 16.5,
    "path_following": 18.0,
    "target_tracking": 17.0,
    "models": 21.0,
    "sysid": 42.0,
}

#: The parts split in processes of about equal compile time.
PARALLEL_GROUPS: tuple[tuple[str, ...], ...] = (
    ("heading", "speed", "path_following", "models"),
    ("sysid", "target_tracking"),
)

#: The parts ``shipgym benchmark`` needs (the envs and the models' linearisations), in two
#: processes of about equal compile time.
BENCHMARK_GROUPS: tuple[tuple[str, ...], ...] = (
    ("heading", "speed"),
    ("path_following", "target_tracking", "models"),
)


def compile_estimate_s(
    groups: Sequence[Sequence[str]] = PARALLEL_GROUPS,
    cpus: int | None = None,
    other_load: float | None = None,
) -> float:
    """About how long :func:`warm_cache` of ``groups`` takes, from :data:`COLD_COMPILE_S`.

    On ``cpus`` idle cores (default: this machine's) it is the longest group, or the total
    shared out over the cores when there are more groups than cores; parts already warm
    (:func:`cold_parts`) cost nothing. ``other_load`` processes of others that want a core
    meanwhile (default: the 1-minute load average less this process, where the system has one)
    share the cores with the compiling processes and slow them down in proportion.
    """
    if cpus is None:
        cpus = os.cpu_count() or 1
    if cpus < 1:
        raise ValueError(f"cpus must be >= 1, got {cpus!r}")
    if other_load is None:
        try:
            other_load = max(0.0, os.getloadavg()[0] - 1.0)
        except OSError:  # no load average (Windows)
            other_load = 0.0
    if other_load < 0:
        raise ValueError(f"other_load must be >= 0, got {other_load!r}")
    times = [sum(COLD_COMPILE_S[p] for p in cold_parts(group)) for group in groups]
    running = min(cpus, sum(t > 0 for t in times))
    idle = max([*times, sum(times) / cpus])
    return idle * max(1.0, (other_load + running) / cpus)


def warm_cache(
    groups: Sequence[Sequence[str]] = PARALLEL_GROUPS, say: Callable[[str], None] = print
) -> bool:
    """Fill the kernel cache once, each group in its own process, all at once.

    Only the cold parts (:func:`cold_parts`) run; the processes import the same copy of
    shipgym as this one. Their lines (one per part) are passed to ``say`` when they end.
    Returns True when the parts are warm afterwards, False when one failed or the cache is
    disabled (``SHIPGYM_NO_CACHE``).
    """
    import shipgym
    from shipgym.models._jit import CACHE_DIR

    if not CACHE_DIR:
        return False
    todo = [cold for group in groups if (cold := cold_parts(group))]
    site = str(Path(shipgym.__file__).resolve().parents[1])
    path = os.pathsep.join(p for p in (site, os.environ.get("PYTHONPATH")) if p)
    procs = [
        subprocess.Popen(
            [sys.executable, "-m", "shipgym.warmup", *group],
            env={**os.environ, "PYTHONPATH": path},
            stdout=subprocess.PIPE,
            text=True,
        )
        for group in todo
    ]
    ok = True
    for proc in procs:
        out, _ = proc.communicate()
        for line in out.splitlines():
            say(line)
        ok = ok and proc.returncode == 0
    return ok


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m shipgym.warmup [PART ...]`` (all parts by default, in this process) or
    ``python -m shipgym.warmup --parallel`` (:func:`warm_cache`)."""
    args = list(sys.argv[1:] if argv is None else argv)
    if args == ["--parallel"]:
        return 0 if warm_cache() else 1
    try:
        warm(args or tuple(PARTS))
    except ValueError as exc:
        print(f"shipgym.warmup: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

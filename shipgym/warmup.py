"""Compile the kernels ahead of use: ``python -m shipgym.warmup [PART ...]``.

shipgym's kernels are compiled on first use and cached on disk
(:mod:`shipgym.models._jit`), after which every process loads them. A machine that starts
many processes at once from a cold cache (the test suite's workers, Ray workers, a fresh
container) would otherwise compile the same kernels in each of them. This runs the public
entry points once with the argument types they always get, so the cache holds every kernel:

* ``envs``: every env, single and vector (one step each; the task kernels);
* ``models``: every model's ``simulate``, ``step``, ``deriv`` and ``linearize``, and the
  standard manoeuvres' simulation;
* ``sysid``: the identification replays of the Nomoto-family fits, the steering-gear lag and
  the R/V Gunnerus model's windows, on short synthetic records.

The parts are independent: ``python -m shipgym.warmup --parallel`` runs them in two processes
at once and marks the cache warm, so the next call costs nothing (the test suite does this
before its workers start).
"""

from __future__ import annotations

import sys
import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

__all__ = ["PARALLEL_GROUPS", "PARTS", "main", "warm", "warm_cache"]


def _envs() -> None:
    import gymnasium as gym

    import shipgym  # noqa: F401 (registers the envs)
    from shipgym.envs import ENV_IDS

    for env_id in ENV_IDS:
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


PARTS: dict[str, Callable[[], None]] = {"envs": _envs, "models": _models, "sysid": _sysid}
"""The parts of the warm-up by name."""


def warm(parts: Sequence[str] = tuple(PARTS), say: Callable[[str], None] = print) -> None:
    """Run the warm-up ``parts`` (names of :data:`PARTS`) in this process."""
    unknown = [p for p in parts if p not in PARTS]
    if unknown:
        raise ValueError(f"unknown warm-up part(s) {unknown}; expected any of {list(PARTS)}")
    for part in parts:
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            PARTS[part]()
        say(f"shipgym warm-up: {part} in {time.perf_counter() - t0:.1f} s")


#: The parts split in two processes of about equal compile time (about 60 s each cold on a
#: 2.45 GHz Zen 3 core).
PARALLEL_GROUPS: tuple[tuple[str, ...], ...] = (("envs", "models"), ("sysid",))

_MARKER = "warmup.done"


def warm_cache(groups: Sequence[Sequence[str]] = PARALLEL_GROUPS) -> bool:
    """Fill the kernel cache once, each group in its own process, all at once.

    Returns True when the cache is warm afterwards. Nothing runs when the cache is already
    warm (a marker in the cache folder, which is keyed by the kernels' sources) or disabled
    (``SHIPGYM_NO_CACHE``).
    """
    import subprocess

    from shipgym.models import _jit

    if not _jit._CACHE_DIR:
        return False
    marker = Path(_jit._CACHE_DIR) / _MARKER
    if marker.exists():
        return True
    procs = [subprocess.Popen([sys.executable, "-m", "shipgym.warmup", *group]) for group in groups]
    if any(proc.wait() != 0 for proc in procs):
        return False
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.touch()
    return True


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

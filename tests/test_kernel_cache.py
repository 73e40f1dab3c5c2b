"""The on-disk cache of compiled kernels: keyed by content (two copies of the same code share
it, a change misses), filled by the warm-up, and an entry it cannot read repairs itself."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from shipgym import warmup

# compiles one small kernel from the cache folder given in the environment
_RUN = (
    "import warnings, numpy as np\n"
    "warnings.simplefilter('always')\n"
    "from shipgym.models.angles import ssa_scalar\n"
    "assert abs(ssa_scalar(4.0) - (4.0 - 2 * np.pi)) < 1e-12\n"
    "print('ok')\n"
)


def _env(cache: Path, **extra: str) -> dict[str, str]:
    """This process's environment with the kernel cache in ``cache`` and ``extra`` set."""
    env = {**os.environ, "SHIPGYM_CACHE_DIR": str(cache), **extra}
    env.pop("SHIPGYM_NO_CACHE", None)
    return env


def _run(cache: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", _RUN], env=_env(cache), capture_output=True, text=True, timeout=300
    )


def test_unreadable_cache_entry_is_recompiled_and_replaced(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = _run(cache)
    assert first.returncode == 0, first.stderr
    index = sorted(cache.rglob("*ssa*.nbi"))
    data = sorted(cache.rglob("*ssa*.nbc"))
    assert index and data, f"no cache entry written in {cache}"
    for path in index:  # empty, as a full disk or a killed process leaves it
        path.write_bytes(b"")
    for path in data:  # garbled
        path.write_bytes(b"\x80\x04not a pickle\xff" * 7)

    repaired = _run(cache)
    assert repaired.returncode == 0, repaired.stderr
    assert repaired.stdout.strip() == "ok"
    assert "unreadable compiled-kernel cache" in repaired.stderr
    assert "recompiling" in repaired.stderr
    assert all(p.stat().st_size > 0 for p in cache.rglob("*ssa*.nb[ic]"))

    for path in sorted(cache.rglob("*ssa*.nbc")):  # a garbled data file behind a good index
        path.write_bytes(b"garbage")
    again = _run(cache)
    assert again.returncode == 0 and "unreadable compiled-kernel cache" in again.stderr

    clean = _run(cache)
    assert clean.returncode == 0, clean.stderr
    assert "unreadable" not in clean.stderr


_SIMULATE = (
    "import numpy as np\n"
    "from shipgym.models import integrate, make_model\n"
    "m = make_model('nomoto2')\n"
    "m.simulate(np.zeros(m.nx), np.zeros((3, m.nu)), 0.1)\n"
    "print(len(integrate.rk4_step_kernel.stats.cache_hits),"
    " len(integrate.rk4_step_kernel.stats.cache_misses))\n"
)


@pytest.mark.skipif(
    bool(os.environ.get("SHIPGYM_NO_CACHE")), reason="SHIPGYM_NO_CACHE: no kernel cache to check"
)
def test_the_warm_up_fills_the_cache_that_later_processes_and_copies_load(tmp_path: Path) -> None:
    """The suite's own warm-up (``warm_cache`` before the workers start, ``conftest.py``)
    filled this session's cache: no part is cold, and a later process compiles nothing for a
    model simulation, nor does a copy of the package at another path (an installed copy beside
    a checkout), which finds the same cache folder. An empty cache has every part cold."""

    def run(*args: str, **extra: str) -> subprocess.CompletedProcess[str]:
        env = {k: v for k, v in os.environ.items() if k != "SHIPGYM_NO_CACHE"}
        return subprocess.run(
            [sys.executable, *args],
            env={**env, **extra},
            capture_output=True,
            text=True,
            timeout=600,
            cwd=tmp_path,
        )

    bad = run("-m", "shipgym.warmup", "kernels")
    assert bad.returncode == 2 and "unknown warm-up part(s) ['kernels']" in bad.stderr
    parts = "from shipgym.warmup import cold_parts; print(*cold_parts())"
    empty = run("-c", parts, SHIPGYM_CACHE_DIR=str(tmp_path / "empty"))
    assert empty.stdout.split() == list(warmup.PARTS), empty.stderr
    warm = run("-c", parts)
    assert warm.returncode == 0 and warm.stdout.split() == [], warm.stderr
    later = run("-c", _SIMULATE)
    assert later.returncode == 0, later.stderr
    assert later.stdout.split() == ["1", "0"]  # one cache hit, no compilation
    import shipgym

    site = Path(shipgym.__file__).resolve().parents[1]
    copy = tmp_path / "site"
    for package in ("shipgym", "controllers"):
        shutil.copytree(
            site / package, copy / package, ignore=shutil.ignore_patterns("__pycache__", "*.zip")
        )
    folder = (
        "import shipgym; from shipgym.models import _jit; print(shipgym.__file__, _jit.CACHE_DIR)"
    )
    here, there = run("-c", folder), run("-c", folder, PYTHONPATH=str(copy))
    assert there.stdout.split()[0] == str(copy / "shipgym" / "__init__.py"), there.stderr
    assert there.stdout.split()[1] == here.stdout.split()[1]  # the same key for both copies
    copied = run("-c", _SIMULATE, PYTHONPATH=str(copy))
    assert copied.returncode == 0, copied.stderr
    assert copied.stdout.split() == ["1", "0"]


# a module of kernels outside the package, in a folder given by PYTHONPATH
_MODULE = """
from shipgym.models._jit import kernel


@kernel
def scaled(x):
    return {factor} * x
"""
_CALL = (
    "import kernel_copy as m\n"
    "print(m.__file__, m.scaled(2.0), len(m.scaled.stats.cache_hits),"
    " len(m.scaled.stats.cache_misses))\n"
)


def test_two_copies_of_the_same_kernels_share_one_entry_and_a_change_misses(
    tmp_path: Path,
) -> None:
    cache = tmp_path / "cache"

    def call(folder: Path, factor: float) -> list[str]:
        folder.mkdir(exist_ok=True)
        (folder / "kernel_copy.py").write_text(_MODULE.format(factor=factor))
        run = subprocess.run(
            [sys.executable, "-c", _CALL],
            env=_env(cache, PYTHONPATH=str(folder)),
            capture_output=True,
            text=True,
            timeout=300,
            cwd=tmp_path,
        )
        assert run.returncode == 0, run.stderr
        where, value, hits, misses = run.stdout.split()
        assert where == str(folder / "kernel_copy.py")
        assert float(value) == 2.0 * factor
        return [hits, misses]

    assert call(tmp_path / "checkout", 3.0) == ["0", "1"]  # compiled and saved
    assert call(tmp_path / "installed", 3.0) == ["1", "0"]  # the same content elsewhere: loaded
    assert call(tmp_path / "checkout", 3.0) == ["1", "0"]
    assert call(tmp_path / "installed", 5.0) == ["0", "1"]  # changed: compiled afresh
    assert len(list(cache.rglob("kernel_copy.scaled-*.nbi"))) == 1


_TARGET = (
    "import llvmlite.binding as llvm, numba\n"
    "import shipgym.models._jit\n"
    "host = llvm.get_host_cpu_features().flatten().split(',')\n"
    "print('+avx512f' in host, numba.config.CPU_NAME, numba.config.CPU_FEATURES)\n"
)


def test_wide_vectors_on_avx512_and_the_users_cpu_settings_stand() -> None:
    """On an AVX-512 host the kernels compile for the host CPU without LLVM's 256-bit preference
    (elsewhere nothing is set); a ``NUMBA_CPU_NAME`` or ``NUMBA_CPU_FEATURES`` of the user's is
    never overridden."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU")}
    run = subprocess.run(
        [sys.executable, "-c", _TARGET], env=env, capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr
    avx512, name, features = run.stdout.split(maxsplit=2)
    if avx512 == "True":
        assert name != "None" and features.strip().endswith(",-prefer-256-bit")
    else:
        assert (name, features.strip()) == ("None", "None")
    generic = subprocess.run(
        [sys.executable, "-c", _TARGET],
        env={**env, "NUMBA_CPU_NAME": "generic"},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert generic.returncode == 0, generic.stderr
    assert generic.stdout.split()[1:] == ["generic"]  # and no features: Numba's generic CPU

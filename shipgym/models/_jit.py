"""The one place that decides how shipgym compiles its physics kernels.

Every model and task kernel is a Numba ``njit`` function, so the same compiled code serves the
single environment, the vector environment, the manoeuvres and system identification
(ARCHITECTURE.md, "One physics, many users").

Compiled code is cached on disk in a directory keyed by a hash of every source that holds
kernels (``shipgym/models/*.py`` and ``shipgym/envs/kernels.py``):
Numba alone only invalidates a cached function when its own file changes, and a kernel that
inlines a changed kernel from another file would otherwise load stale machine code. The
directory is ``$SHIPGYM_CACHE_DIR`` or ``~/.cache/shipgym/numba-<hash>``; set
``SHIPGYM_NO_CACHE=1`` to compile without any cache.

A cache entry that cannot be read (an empty file left by a full disk or a killed process, a
garbled or foreign file) repairs itself: the function's index and data files are removed with a
``RuntimeWarning`` naming them, the kernel is recompiled and the fresh entry replaces them.
Numba alone would raise ``EOFError``/``UnpicklingError`` on every later run until the folder is
deleted by hand.
"""

from __future__ import annotations

import glob
import hashlib
import os
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import llvmlite.binding as llvm
import numba
import numpy as np
from numba.core.caching import FunctionCache
from numba.extending import overload

F = TypeVar("F", bound=Callable[..., Any])

_CACHE = os.environ.get("SHIPGYM_NO_CACHE", "") in ("", "0")

# LLVM vectorises a loop whose arrays may overlap only behind run-time overlap checks, and gives
# up beyond 128 of them. The loop over a block of ships reads and writes one array per state
# row, which needs more (checked once per block, a few ns); the limit is raised for the
# process. It changes which loops are vectorised, never a result.
llvm.set_option("", "-vectorize-memory-check-threshold=4096")


def _prefer_wide_vectors() -> None:
    """On a CPU with AVX-512, let LLVM's vectoriser choose 512-bit vectors.

    LLVM tunes Intel's AVX-512 CPUs to prefer 256-bit vectors (older ones lowered their clock
    for 512-bit instructions), so the loops over a block of ships ran four ships at a time where
    the registers hold eight: with the preference lifted the RVG RK4 over a batch is about 1.25 x
    faster (``scripts/bench_kernel.py``). It only changes which instructions compile a loop,
    never a result (no fast-math). It applies when shipgym's kernels are the first Numba code a
    process compiles (the target machine is made then) and never over a ``NUMBA_CPU_NAME`` or
    ``NUMBA_CPU_FEATURES`` of the user's.
    """
    if numba.config.CPU_NAME or numba.config.CPU_FEATURES:
        return
    features = llvm.get_host_cpu_features().flatten()
    if "+avx512f" in features.split(","):
        numba.config.CPU_NAME = llvm.get_host_cpu_name()
        numba.config.CPU_FEATURES = features + ",-prefer-256-bit"


_prefer_wide_vectors()


def _cache_dir() -> str:
    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha1(numba.__version__.encode())
    for path in sorted([*root.glob("models/*.py"), root / "envs" / "kernels.py"]):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.environ.get("SHIPGYM_CACHE_DIR") or os.path.join(
        base, "shipgym", f"numba-{digest.hexdigest()[:16]}"
    )


_CACHE_DIR = _cache_dir() if _CACHE else ""


class _SelfRepairingCache(FunctionCache):
    """Numba's on-disk function cache, which replaces an entry it cannot read.

    Any error while reading the index or a data file (``EOFError`` for an empty file,
    ``UnpicklingError`` or another unpickling error for a garbled one) removes this function's
    cache files with a warning and reports a miss, so Numba compiles the kernel and saves a
    fresh entry in their place.
    """

    def _repair(self, exc: BaseException) -> None:
        cache_file = self._cache_file
        index = cache_file._index_path
        stem = os.path.join(cache_file._cache_path, os.path.basename(index)[: -len(".nbi")])
        files = [index, *glob.glob(glob.escape(stem) + ".*.nbc")]
        removed = []
        for path in files:
            try:
                os.remove(path)
                removed.append(os.path.basename(path))
            except OSError:  # already gone, or not ours to remove: Numba overwrites it
                pass
        warnings.warn(
            f"shipgym: unreadable compiled-kernel cache for {self._py_func.__qualname__} in "
            f"{cache_file._cache_path} ({type(exc).__name__}: {exc}); removed "
            f"{', '.join(removed) or 'nothing'} and recompiling",
            RuntimeWarning,
            stacklevel=2,
        )

    def load_overload(self, sig: Any, target_context: Any) -> Any:
        try:
            return super().load_overload(sig, target_context)
        except Exception as exc:  # any unreadable entry: a miss, repaired below
            self._repair(exc)
            return None

    def save_overload(self, sig: Any, data: Any) -> None:
        try:
            super().save_overload(sig, data)
        except OSError:
            raise
        except Exception as exc:  # the index was unreadable: start it afresh
            self._repair(exc)
            super().save_overload(sig, data)


def _compile(func: F, **options: Any) -> F:
    if not _CACHE:
        return numba.njit(**options)(func)  # type: ignore[return-value]
    previous = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = _CACHE_DIR  # read once, when the dispatcher sets up its cache
    try:
        dispatcher = numba.njit(cache=True, **options)(func)
        dispatcher._cache = _SelfRepairingCache(dispatcher.py_func)
        return dispatcher  # type: ignore[return-value]
    finally:
        numba.config.CACHE_DIR = previous


def kernel(func: F) -> F:
    """Compile ``func`` as a serial kernel (no fast-math: results are exact IEEE)."""
    return _compile(func, nogil=True, error_model="numpy")


def row_kernel(func: F) -> F:
    """Compile a per-ship kernel that Numba inlines into the batch loops that call it."""
    return _compile(func, nogil=True, error_model="numpy", inline="always")


def simd_kernel(func: F) -> F:
    """Compile a per-ship model function that the compiler inlines into the loops over a block
    of ships and turns into SIMD code.

    Inlined by LLVM (``forceinline``), not by Numba: Numba's inlining would add reference
    counting of the array arguments inside the loop over the ships, which keeps LLVM from
    vectorising it.
    """
    return _compile(func, nogil=True, error_model="numpy", forceinline=True)


def param(p: Any, k: int, b: int) -> float:
    """Parameter ``k`` of ship ``b`` of a block, in the model functions.

    ``p`` is either the model's one packed parameter vector, shared by every ship of the block
    (the environments, the manoeuvres, a single replay), or a table of shape
    ``(n_parameters, ships)`` with a parameter vector per ship, column ``b`` for ship ``b``
    (identification, which steps the variants of a model that a finite-difference Jacobian
    needs side by side as the ships of one block). Chosen when the caller is compiled, from the
    dimensions of ``p``: a shared vector compiles to the same code as ``p[k]``, and a table to
    loads along the block's ships, which keep the loop over them SIMD code.
    """
    return float(p[k] if np.ndim(p) == 1 else p[k, b])


def param_nonzero(p: Any, k: int, n: int) -> bool:
    """Whether parameter ``k`` (:func:`param`) is not zero for any of ships ``0 .. n-1``."""
    return bool(np.any(p[k] != 0.0) if np.ndim(p) == 1 else np.any(p[k, :n] != 0.0))


@overload(param, jit_options={"nogil": True, "error_model": "numpy", "forceinline": True})
def _param(p, k, b):  # type: ignore[no-untyped-def]  # Numba matches the names
    """Numba's implementation of :func:`param` for the type of ``p``."""
    if p.ndim == 1:
        return lambda p, k, b: p[k]
    return lambda p, k, b: p[k, b]


@overload(param_nonzero, jit_options={"nogil": True, "error_model": "numpy", "forceinline": True})
def _param_nonzero(p, k, n):  # type: ignore[no-untyped-def]
    """Numba's implementation of :func:`param_nonzero` for the type of ``p``."""
    if p.ndim == 1:
        return lambda p, k, n: p[k] != 0.0

    def table(p, k, n):  # type: ignore[no-untyped-def]
        for b in range(n):
            if p[k, b] != 0.0:
                return True
        return False

    return table

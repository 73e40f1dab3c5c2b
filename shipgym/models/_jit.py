"""The one place that decides how shipgym compiles its physics kernels.

Every model and task kernel is a Numba ``njit`` function, so the same compiled code serves the
single environment, the vector environment, the manoeuvres and system identification
(ARCHITECTURE.md, "One physics, many users").

Compiled code is cached on disk in one folder per version of the kernels,
``$SHIPGYM_CACHE_DIR/numba-<key>`` (``~/.cache/shipgym/numba-<key>`` by default), where the key is
a hash of the content of every source the kernels depend on (each module of the ``shipgym`` and
``controllers`` packages that imports this one, this one, and the project's modules they import)
and of the Python, Numba, llvmlite and NumPy versions. Inside it a kernel's entry is found by its
module's name and is fresh while its source file's content is unchanged
(:class:`_ContentLocator`). Numba's own
locators file an entry under a hash of the source folder's absolute path, so a checkout and an
installed copy of the same code (the test suite and the command line) would each compile every
kernel; here they share one entry. And Numba alone only invalidates a cached function when its
own file changes, so a kernel that inlines a changed kernel from another file would load stale
machine code; the key over all kernel sources rules that out. Set ``SHIPGYM_NO_CACHE=1`` to
compile without any cache.

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
import re
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar, TypeVar

import llvmlite.binding as llvm
import numba
import numpy as np
from llvmlite import __version__ as llvm_version
from numba.core.caching import CompileResultCacheImpl, FunctionCache, _CacheLocator
from numba.extending import overload

from shipgym._cache import cache_root

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


#: how a module that defines kernels imports the decorators (the text searched for)
_KERNEL_IMPORT = re.compile(rb"^from shipgym\.models\._jit import", re.MULTILINE)
#: an import of the project's modules: ``from a.b import c, d`` (the names maybe in
#: parentheses over several lines) or ``import a.b``
_PROJECT_IMPORT = re.compile(
    rb"^(?:from\s+((?:shipgym|controllers)[\w.]*)\s+import\s+(?:\(([^)]*)\)|([\w \t,]*))"
    rb"|import\s+((?:shipgym|controllers)[\w.]*))",
    re.MULTILINE,
)


def _module_file(site: Path, name: str) -> Path | None:
    """The source file of module ``name`` under ``site`` (None: not a module there)."""
    base = site.joinpath(*name.split("."))
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _kernel_sources(site: Path) -> list[Path]:
    """The source files of the ``shipgym`` and ``controllers`` packages under ``site`` that the
    compiled kernels depend on: every module that imports this module's decorators, this
    module, and every module of the project they import, directly or not (a kernel compiles in
    the values of the globals it reads, such as an imported constant)."""
    todo = [Path(__file__).resolve()]
    for package in ("shipgym", "controllers"):
        todo += [p for p in (site / package).rglob("*.py") if _KERNEL_IMPORT.search(p.read_bytes())]
    found: set[Path] = set()
    while todo:
        path = todo.pop()
        if path in found:
            continue
        found.add(path)
        for module, listed, names, plain in _PROJECT_IMPORT.findall(path.read_bytes()):
            if plain:
                candidates = [plain.decode()]
            else:
                module = module.decode()
                names = (listed or names).decode().replace(",", " ").split()
                candidates = [module, *(f"{module}.{n}" for n in names)]
            todo += [f for c in candidates if (f := _module_file(site, c)) is not None]
    return sorted(found)


def _cache_dir() -> str:
    """The cache folder of this version of the kernels (see the module docstring)."""
    site = Path(__file__).resolve().parents[2]  # the folder holding the shipgym package
    digest = hashlib.sha256()
    for version in (sys.version_info[:2], numba.__version__, llvm_version, np.__version__):
        digest.update(f"{version}\n".encode())
    for path in _kernel_sources(site):
        digest.update(path.relative_to(site).as_posix().encode() + b"\n")
        digest.update(hashlib.sha256(path.read_bytes()).digest())
    return os.path.join(cache_root(), f"numba-{digest.hexdigest()[:16]}")


CACHE_DIR = _cache_dir() if _CACHE else ""
"""The kernel cache folder of this version of the kernels ("" when ``SHIPGYM_NO_CACHE`` is set)."""


class _ContentLocator(_CacheLocator):
    """Numba's locator of a kernel's cache entry, keyed by content rather than by path.

    The entry lives in ``CACHE_DIR/<module name>`` and is fresh while the SHA-256 of the source
    file is unchanged: two copies of the same module at different paths share it (Numba's own
    locators use a hash of the folder's absolute path and, before Numba 0.68, the file's
    modification time).
    """

    def __init__(self, py_func: Callable[..., Any], py_file: str) -> None:
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(CACHE_DIR, py_func.__module__)

    def get_cache_path(self) -> str:
        return self._cache_path

    def get_source_stamp(self) -> str:
        return hashlib.sha256(Path(self._py_file).read_bytes()).hexdigest()

    def get_disambiguator(self) -> str:
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func: Callable[..., Any], py_file: str) -> _ContentLocator | None:
        if not os.path.isfile(py_file):
            return None
        self = cls(py_func, py_file)
        try:
            self.ensure_cache_path()
        except OSError:  # not writable: Numba's own locators are tried next
            return None
        return self


class _ContentKeyedImpl(CompileResultCacheImpl):
    """Numba's compile-result cache with :class:`_ContentLocator` tried first."""

    _locator_classes: ClassVar[list[type[_CacheLocator]]] = [
        _ContentLocator,
        *CompileResultCacheImpl._locator_classes,
    ]


class _SelfRepairingCache(FunctionCache):
    """Numba's on-disk function cache, which replaces an entry it cannot read.

    Any error while reading the index or a data file (``EOFError`` for an empty file,
    ``UnpicklingError`` or another unpickling error for a garbled one) removes this function's
    cache files with a warning and reports a miss, so Numba compiles the kernel and saves a
    fresh entry in their place.
    """

    _impl_class = _ContentKeyedImpl

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
    dispatcher = numba.njit(**options)(func)
    if _CACHE:
        dispatcher._cache = _SelfRepairingCache(dispatcher.py_func)
    return dispatcher  # type: ignore[return-value]


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

"""The one place that decides how shipgym compiles its physics kernels.

Every model kernel is a Numba ``njit`` function with on-disk caching, so the same compiled
code serves the single environment, the vector environment, the manoeuvres and system
identification (ARCHITECTURE.md, "One physics, many users"). Set ``SHIPGYM_NO_CACHE=1``
to compile without the on-disk cache (useful while editing a kernel that another cached
kernel calls, since Numba only invalidates a cache when its own file changes).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any, TypeVar

import numba

F = TypeVar("F", bound=Callable[..., Any])

_CACHE = os.environ.get("SHIPGYM_NO_CACHE", "") in ("", "0")


def kernel(func: F) -> F:
    """Compile ``func`` as a cached, serial Numba kernel (no fast-math: results are exact IEEE)."""
    return numba.njit(cache=_CACHE, nogil=True, error_model="numpy")(func)  # type: ignore[return-value]


def row_kernel(func: F) -> F:
    """Compile a per-ship kernel that Numba inlines into the batch loops that call it."""
    return numba.njit(cache=_CACHE, nogil=True, inline="always", error_model="numpy")(func)  # type: ignore[return-value]


def parallel_kernel(func: F) -> F:
    """Compile a batch kernel whose ``prange`` loop runs on all cores."""
    return numba.njit(cache=_CACHE, nogil=True, parallel=True)(func)  # type: ignore[return-value]

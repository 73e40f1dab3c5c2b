"""Where shipgym keeps what it builds on a machine: one cache folder for the compiled kernels
(:mod:`shipgym.models._jit`) and the folders third-party libraries would otherwise leave in the
temporary directory (torch's compiler cache, :mod:`shipgym.rl`)."""

from __future__ import annotations

import os

CACHE_DIR_ENV = "SHIPGYM_CACHE_DIR"
"""Environment variable naming shipgym's cache folder."""


def cache_root() -> str:
    """shipgym's cache folder: ``$SHIPGYM_CACHE_DIR``, else ``$XDG_CACHE_HOME/shipgym``, else
    ``~/.cache/shipgym``."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.environ.get(CACHE_DIR_ENV) or os.path.join(base, "shipgym")

"""Ray, the distributed engine behind ``--ray``: connecting to a cluster or starting one locally.

shipgym does not run its own process pool for campaigns that outgrow one machine; evaluation
campaigns and training sweeps are Ray tasks and trials. Ray lives in the ``cluster`` extra
(``pip install "shipgym[cluster]"``). Without an address :func:`ray_session` starts a local Ray
on this machine; with one (``ray start --head`` prints it, e.g. ``192.168.1.10:6379``, or
``auto`` for the cluster this machine belongs to) it joins that cluster.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from typing import Any

#: What to install when Ray is missing.
INSTALL_HINT = 'pip install "shipgym[cluster]"'


def require_ray() -> Any:
    """The ``ray`` module, or ``ImportError`` saying how to install it."""
    try:
        import ray
    except ImportError as exc:  # pragma: no cover - the cluster extra is installed in the tests
        raise ImportError(f"--ray needs Ray: {INSTALL_HINT}") from exc
    return ray


@contextlib.contextmanager
def ray_session(address: str | None = None, num_cpus: int | None = None) -> Iterator[Any]:
    """Connect to the Ray cluster at ``address``, or start a local one, for the ``with`` block.

    Parameters
    ----------
    address : str, optional
        ``host:port`` of a running cluster's head (``ray start --head``), ``"auto"``, or
        ``None`` to start Ray on this machine only (``num_cpus`` of its cores).
    num_cpus : int, optional
        CPUs of a local Ray (default: every core); not allowed with an ``address``.

    Yields
    ------
    module
        ``ray``. A session this function started is shut down on leaving the block; one that
        was already running (``ray.init`` by the caller) is left running.
    """
    ray = require_ray()
    if address is not None and num_cpus is not None:
        raise ValueError("num_cpus is for a local Ray only; a cluster has its own CPUs")
    if num_cpus is not None and (not isinstance(num_cpus, int) or num_cpus < 1):
        raise ValueError(f"num_cpus must be an integer >= 1, got {num_cpus!r}")
    if ray.is_initialized():
        yield ray
        return
    # the workers import shipgym from this checkout's parent like the driver does
    os.environ.setdefault("RAY_ENABLE_UV_RUN_RUNTIME_ENV", "0")
    ray.init(
        address=address,
        num_cpus=num_cpus,
        include_dashboard=False,
        log_to_driver=False,
        configure_logging=False,
    )
    try:
        yield ray
    finally:
        ray.shutdown()

"""Ray, the distributed engine behind ``--ray``: connecting to a cluster or starting one locally,
and running a list of tasks on it.

shipgym does not run its own process pool for campaigns that outgrow one machine; evaluation
campaigns and training sweeps are Ray tasks and trials. Ray lives in the ``cluster`` extra
(``pip install "shipgym[cluster]"``). Without an address (or with ``"local"``)
:func:`ray_session` starts a private Ray on this machine, whose sockets, logs and spilled
objects live in a short temporary folder removed at the end; with one (``ray start --head``
prints it, e.g. ``192.168.1.10:6379``, or ``auto`` for the cluster this machine belongs to) it
joins that cluster. :func:`run_tasks` runs a function on each item of a list as Ray tasks,
reports each result as it arrives and turns a failed task into one error that names the item.
"""

from __future__ import annotations

import contextlib
import ipaddress
import os
import re
import shutil
import socket
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, TypeVar

#: What to install when Ray is missing.
INSTALL_HINT = 'pip install "shipgym[cluster]"'

#: Seconds to wait for a cluster's head to accept a connection before giving up.
CONNECT_TIMEOUT_S = 5.0

#: Longest temporary folder of a local Ray: its session folder (about 45 characters) and
#: socket names (about 20) go below it, and a unix socket path has at most 107 bytes.
MAX_TEMP_DIR = 40

_HOST_PORT = re.compile(r"^(?:ray://)?(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9.-]+):(?P<port>\d+)$")
_HOSTNAME = re.compile(r"^(?=.{1,253}$)[A-Za-z0-9](?:[A-Za-z0-9-]{0,61}[A-Za-z0-9])?"
                       r"(?:\.[A-Za-z0-9](?:[A-Za-z0-9-]{0,61}[A-Za-z0-9])?)*$")  # fmt: skip

T = TypeVar("T")
R = TypeVar("R")


class ClusterTaskError(RuntimeError):
    """A Ray task failed (its function raised, or its worker or node died); the message names
    the task's item (see :func:`run_tasks`)."""


def require_ray() -> Any:
    """The ``ray`` module, or ``ImportError`` saying how to install it."""
    try:
        import ray
    except ImportError as exc:  # pragma: no cover - the cluster extra is installed in the tests
        raise ImportError(f"--ray needs Ray: {INSTALL_HINT}") from exc
    return ray


def parse_address(text: str | None) -> str | None:
    """Check a ``--ray`` value: ``None``, ``""`` or ``"local"`` (start Ray on this machine:
    returns ``None``), ``"auto"``, or ``[ray://]host:port`` (returned as given).

    Raises
    ------
    ValueError
        Naming the value and the forms expected.
    """
    if text is None:
        return None
    word = text.strip()
    if word.lower() in ("", "local"):
        return None
    if word.lower() == "auto":
        return "auto"
    expected = (
        "expected host:port of the cluster's head (e.g. 192.168.1.10:6379, as 'ray start "
        "--head' prints it), ray://host:port, 'auto' or 'local'"
    )
    match = _HOST_PORT.match(word)
    if match is None:
        raise ValueError(f"bad Ray address {text!r}: {expected}")
    host, port = match["host"], int(match["port"])
    if not 1 <= port <= 65535:
        raise ValueError(f"bad Ray address {text!r}: port {port} is not in [1, 65535]; {expected}")
    if host.startswith("["):
        try:
            ipaddress.IPv6Address(host[1:-1])
        except ValueError:
            raise ValueError(f"bad Ray address {text!r}: {host} is no IPv6 address") from None
    elif not _HOSTNAME.match(host):
        raise ValueError(f"bad Ray address {text!r}: {host!r} is no host name; {expected}")
    return word


def _check_reachable(address: str) -> None:
    """Raise ``ConnectionError`` if ``host:port`` does not accept a TCP connection within
    :data:`CONNECT_TIMEOUT_S` (Ray itself would retry for a minute before failing)."""
    match = _HOST_PORT.match(address)
    if match is None:  # "auto": Ray finds the cluster itself
        return
    host, port = match["host"].strip("[]"), int(match["port"])
    try:
        with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S):
            pass
    except OSError as exc:
        raise ConnectionError(
            f"cannot reach the Ray cluster at {address}: {exc.strerror or exc} (is 'ray start "
            f"--head' running there, and is port {port} open?)"
        ) from None


def _short_temp_dir() -> Path:
    """A new private folder for a local Ray, short enough for Ray's unix socket paths: in the
    temporary directory if its path is short, else in ``/tmp``."""
    for base in (tempfile.gettempdir(), "/tmp"):
        if len(base) + len("/ray-xxxxxxxx") <= MAX_TEMP_DIR and os.path.isdir(base):
            return Path(tempfile.mkdtemp(prefix="ray-", dir=base))
    raise OSError(
        f"no temporary directory with a path shorter than {MAX_TEMP_DIR} characters for Ray's "
        f"sockets (TMPDIR is {tempfile.gettempdir()!r}); set TMPDIR to a short path"
    )


@contextlib.contextmanager
def ray_session(address: str | None = None, num_cpus: int | None = None) -> Iterator[Any]:
    """Connect to the Ray cluster at ``address``, or start a local one, for the ``with`` block.

    Parameters
    ----------
    address : str, optional
        ``host:port`` of a running cluster's head (``ray start --head``), ``ray://host:port``,
        ``"auto"``, or ``None`` / ``"local"`` to start a private Ray on this machine only
        (``num_cpus`` of its cores; its files live in a short temporary folder that is removed
        when the block ends).
    num_cpus : int, optional
        CPUs of a local Ray (default: every core); not allowed with an ``address``.

    Yields
    ------
    module
        ``ray``. A session this function started is shut down on leaving the block; one that
        was already running (``ray.init`` by the caller) is used as it is and left running.

    Raises
    ------
    ValueError
        A malformed ``address``, or ``num_cpus`` that is not a positive integer or comes with
        an ``address``.
    ConnectionError
        If the head at ``host:port`` does not answer.
    """
    ray = require_ray()
    address = parse_address(address)
    if address is not None and num_cpus is not None:
        raise ValueError("num_cpus is for a local Ray only; a cluster has its own CPUs")
    if num_cpus is not None and (
        isinstance(num_cpus, bool) or not isinstance(num_cpus, int) or num_cpus < 1
    ):
        raise ValueError(f"num_cpus must be an integer >= 1, got {num_cpus!r}")
    if ray.is_initialized():
        yield ray
        return
    # the workers import shipgym from the environment the driver runs in
    os.environ.setdefault("RAY_ENABLE_UV_RUN_RUNTIME_ENV", "0")
    options: dict[str, Any] = {
        "include_dashboard": False,
        "log_to_driver": False,
        "configure_logging": False,
    }
    temp_dir = None
    if address is None:
        temp_dir = _short_temp_dir()
        options.update(address="local", num_cpus=num_cpus, _temp_dir=str(temp_dir))
    else:
        _check_reachable(address)
        options.update(address=address)
    try:
        ray.init(**options)
        try:
            yield ray
        finally:
            ray.shutdown()
    finally:
        if temp_dir is not None:
            _remove(temp_dir)


def _remove(folder: Path) -> None:
    """Remove ``folder``; Ray's processes may still write their last log lines for a moment."""
    for _ in range(20):
        shutil.rmtree(folder, ignore_errors=True)
        if not folder.exists():
            return
        time.sleep(0.1)


def cluster_cpus() -> int:
    """CPUs of the Ray cluster this process is connected to (at least 1)."""
    ray = require_ray()
    return max(1, int(ray.cluster_resources().get("CPU", 1)))


def run_tasks(
    fn: Callable[[T], R],
    items: Sequence[T],
    *,
    describe: Callable[[T], str],
    on_done: Callable[[int, R], None] | None = None,
    passthrough: tuple[type[BaseException], ...] = (),
) -> list[R]:
    """Run ``fn(item)`` for every item as a Ray task (one CPU each) in the current session.

    Parameters
    ----------
    fn : callable
        A function of one item, importable on the workers (a module-level function).
    items : sequence
        The tasks' arguments; each is sent to a worker.
    describe : callable
        A short description of an item (what it computes), for error messages.
    on_done : callable, optional
        Called with the item's index and its result as each task finishes (in finishing
        order), e.g. to print progress.
    passthrough : tuple of exception types
        Errors of ``fn`` that already say which item failed: re-raised as they are (with the
        worker's traceback as a note) instead of wrapped.

    Returns
    -------
    list
        The results, in the order of ``items``.

    Raises
    ------
    ClusterTaskError
        The first task that failed, named by ``describe`` with its error (the other tasks are
        cancelled).
    """
    ray = require_ray()
    if not ray.is_initialized():
        raise RuntimeError("run_tasks needs a Ray session: call it inside ray_session()")
    remote = ray.remote(num_cpus=1)(fn)
    refs = {remote.remote(item): k for k, item in enumerate(items)}
    results: list[Any] = [None] * len(items)
    pending = list(refs)
    try:
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            for ref in done:
                k = refs[ref]
                try:
                    results[k] = ray.get(ref)
                except ray.exceptions.RayTaskError as exc:
                    cause = exc.cause
                    if isinstance(cause, passthrough):
                        cause.add_note(f"worker traceback:\n{exc}")  # Ray's text of it
                        raise cause from None
                    raise ClusterTaskError(
                        f"{describe(items[k])}: {type(cause).__name__}: {cause}"
                    ) from None
                except ray.exceptions.RayError as exc:  # worker or node died, object lost
                    first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
                    raise ClusterTaskError(
                        f"{describe(items[k])}: the Ray task did not finish "
                        f"({type(exc).__name__}: {first})"
                    ) from None
                if on_done is not None:
                    on_done(k, results[k])
    finally:
        for ref in pending:
            ray.cancel(ref)
    return results

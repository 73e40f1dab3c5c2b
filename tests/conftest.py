"""Test-session setup: the run's temporary files live in one folder, removed at the end.

``TMPDIR`` (for subprocesses), :data:`tempfile.tempdir` and pytest's ``tmp_path`` base all point
into a fresh folder for the session; the pytest-xdist workers share the folder of the process
that started them (their ``tmp_path`` bases are ``pytest/gw<N>`` in it). Whatever the code under
test leaves there outside pytest's own ``tmp_path`` folders (an ``SB3-<date>`` logger folder, a
temporary file not cleaned up) fails the run with the names of what was left; the folder is
removed either way, so a test run leaves nothing in the system's temporary directory. Torch runs
on one thread (tiny networks). A cold kernel cache is filled before the tests start
(:func:`shipgym.warmup.warm_cache`). The measured records are read in place from the local
mirror beside the checkout (``../shared/data/measured``) when ``SHIPGYM_MEASURED_DATA`` is unset.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest

#: the session's folder, made by the process that runs pytest and shared by its xdist workers
_ROOT_VARIABLE = "SHIPGYM_TEST_ROOT"
_PYTEST_DIR = "pytest"
#: the project's local mirror of the measured datasets, beside the checkout (as in CI): the
#: tests read the records there in place unless ``SHIPGYM_MEASURED_DATA`` names another copy
_MEASURED_MIRROR = Path(__file__).resolve().parents[2] / "shared" / "data" / "measured"


def _is_worker(config: pytest.Config) -> bool:
    return hasattr(config, "workerinput")  # a pytest-xdist worker


def _root() -> Path:
    return Path(os.environ[_ROOT_VARIABLE])


def pytest_configure(config: pytest.Config) -> None:
    from shipgym.datasets import MEASURED_DATA_ENV

    if not os.environ.get(MEASURED_DATA_ENV) and _MEASURED_MIRROR.is_dir():
        os.environ[MEASURED_DATA_ENV] = str(_MEASURED_MIRROR)
    if not _is_worker(config):  # the workers get their tmp_path base from xdist, inside it
        root = Path(tempfile.mkdtemp(prefix="shipgym-tests-"))
        os.environ[_ROOT_VARIABLE] = str(root)
        config.option.basetemp = str(root / _PYTEST_DIR)
    os.environ["TMPDIR"] = str(_root())
    tempfile.tempdir = str(_root())
    if not _is_worker(config):
        # a cold kernel cache is filled once, by two processes at once, before the workers
        # start: otherwise every worker (and every Ray worker and command the tests start)
        # compiles the same kernels
        from shipgym.warmup import warm_cache

        warm_cache()
    # the tests' networks are tiny: torch's thread pool only adds synchronisation, and on
    # shared cores (a loaded CI machine) it makes each layer several times slower
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    try:
        import torch
    except ImportError:  # pragma: no cover - the rl extra is part of the test install
        return
    torch.set_num_threads(1)


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    if _is_worker(session.config):  # checked once, by the process that started the workers
        return
    left = sorted(
        p.name
        for p in _root().iterdir()
        if p.name != _PYTEST_DIR
    )
    if left:
        reporter = session.config.pluginmanager.get_plugin("terminalreporter")
        if reporter is not None:
            reporter.write_line(
                f"the tests left these in the temporary directory: {', '.join(left)}", red=True
            )
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_unconfigure(config: pytest.Config) -> None:
    if not _is_worker(config) and _ROOT_VARIABLE in os.environ:
        shutil.rmtree(_root(), ignore_errors=True)

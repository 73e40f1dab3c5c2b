"""Argument types, output checks and progress lines shared by the ``shipgym`` commands."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path

PROG = "shipgym"
#: A command's handler: parsed arguments -> exit code.
Handler = Callable[[argparse.Namespace], int]
#: A command's builder: adds its parser to the subcommands and sets ``handler``.
Builder = Callable[["argparse._SubParsersAction[argparse.ArgumentParser]"], None]


def int_in(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: an integer in ``[lo, hi]`` (a bound on every count and seed, so that
    no flag can ask for an unbounded allocation)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"must be an integer in [{lo}, {hi:,}], got {text!r}")
        return value

    return parse


def float_in(lo: float, hi: float, unit: str) -> Callable[[str], float]:
    """An argparse type: a finite number in ``[lo, hi]`` (``unit`` for the message)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and lo <= value <= hi):
            raise argparse.ArgumentTypeError(
                f"must be a number in [{lo:g}, {hi:g}] {unit}, got {text!r}"
            )
        return value

    return parse


#: Largest seed (numpy's and Gymnasium's seeds are 32-bit here) and episode count of a run.
MAX_SEED = 2**32 - 1


MAX_EPISODES = 1_000_000


def finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def progress_line(msg: str) -> None:
    print(f"  {msg}", file=sys.stderr, flush=True)


def probe_directory(directory: Path, flag: str, target: str) -> None:
    """Create and remove a temporary file in ``directory``: can ``target`` be written there?"""
    import os
    import tempfile

    try:
        fd, probe = tempfile.mkstemp(prefix=".shipgym-probe-", dir=directory)
    except OSError as exc:
        raise ValueError(f"{flag}: cannot write {target!r}: {exc.strerror or exc}") from None
    os.close(fd)
    os.unlink(probe)


def output_path(text: str | None, flag: str, suffix: str | None = None) -> Path | None:
    """Check an output file before the (possibly long) run; ``-`` and None pass.

    The file's directory must exist and take a new file (tried with a temporary file); an
    existing output must be a regular file, which is replaced.
    """
    if text is None or text == "-":
        return None
    path = Path(text)
    if suffix is not None and path.suffix.lower() != suffix:
        raise ValueError(f"{flag} must name a {suffix} file, got {text!r}")
    if path.is_dir():
        raise ValueError(f"{flag} names a directory, expected a file: {text!r}")
    if path.exists() and not path.is_file():
        raise ValueError(f"{flag}: {text!r} exists and is not a regular file")
    if not path.parent.is_dir():
        raise ValueError(f"{flag}: the directory {str(path.parent)!r} of {text!r} does not exist")
    probe_directory(path.parent, flag, text)
    return path


def output_dir(text: str, flag: str) -> Path:
    """Check an output directory before the run: an existing one that takes files, or a new
    one in an existing directory (created when the outputs are written, never its parents)."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{flag} names a file, expected a directory: {text!r}")
    if not path.exists() and not path.parent.is_dir():
        raise ValueError(f"{flag}: the directory {str(path.parent)!r} of {text!r} does not exist")
    probe_directory(path if path.exists() else path.parent, flag, text)
    return path


def model_name(text: str) -> str:
    """``--model``: a model name or a model file ``*.json`` (read by the handler)."""
    from shipgym.models import MODEL_NAMES

    if text in MODEL_NAMES or text.lower().endswith(".json"):
        return text
    raise argparse.ArgumentTypeError(
        f"must be one of {', '.join(MODEL_NAMES)} or a model file FIT.json, got {text!r}"
    )

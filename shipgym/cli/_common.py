"""Argument types, output checks and progress lines shared by the ``shipgym`` commands."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from shipgym._io import write_atomically

PROG = "shipgym"
#: A command's handler: parsed arguments -> exit code.
Handler = Callable[[argparse.Namespace], int]
#: A command's builder: adds its parser to the subcommands and sets ``handler``.
Builder = Callable[["argparse._SubParsersAction[argparse.ArgumentParser]"], None]


def int_in(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: an integer in ``[lo, hi]`` (a bound on every count and seed, so that
    no flag can ask for an unbounded allocation). Written as a user writes counts: ``100000``,
    ``100_000`` or ``1e5`` (a number in exponent form that is a whole number)."""

    def parse(text: str) -> int:
        value = parse_count(text)
        if value is None or not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"must be an integer in [{lo}, {hi:,}], got {text!r}")
        return value

    return parse


def parse_count(text: str) -> int | None:
    """``text`` as a whole number (``"100000"``, ``"100_000"``, ``"1e5"``, ``"2.5e3"``), or None
    when it is not one (``"1.5"``, ``"ten"``, ``"nan"``)."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        value = float(text)
    except ValueError:
        return None
    return int(value) if math.isfinite(value) and value.is_integer() else None


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
    """An argparse type: any finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def progress_line(msg: str) -> None:
    """Print one progress line of a long run to stderr, indented under the command's header."""
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

    Missing parent folders are made (as ``mkdir -p`` would); the folder must take a new file
    (tried with a temporary file); an existing output must be a regular file, which is replaced.
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
    _make_folder(path.parent, flag, text)
    return path


def output_dir(text: str, flag: str) -> Path:
    """Check an output folder before the run: an existing one that takes files, or a new one,
    made with its missing parents (as ``mkdir -p`` would)."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{flag} names a file, expected a directory: {text!r}")
    _make_folder(path, flag, text)
    return path


def _make_folder(folder: Path, flag: str, target: str) -> None:
    """Make ``folder`` and its missing parents, then check that it takes a new file."""
    for parent in (folder, *folder.parents):
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(
                    f"{flag}: {str(parent)!r} is a file, so the folder of {target!r} cannot be made"
                )
            break
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(
            f"{flag}: cannot make the folder {str(folder)!r}: {exc.strerror or exc}"
        ) from None
    probe_directory(folder, flag, target)


def model_name(text: str) -> str:
    """``--model``: a model name or a model file ``*.json`` (read by the handler)."""
    from shipgym.models import MODEL_NAMES

    if text in MODEL_NAMES or text.lower().endswith(".json"):
        return text
    raise argparse.ArgumentTypeError(
        f"must be one of {', '.join(MODEL_NAMES)} or a model file FIT.json, got {text!r}"
    )


def write_outputs(
    outputs: Sequence[tuple[Path, Callable[[Path], Any]]], stream: Any = None
) -> None:
    """Write every output at once (:func:`shipgym._io.write_atomically`: all or none), then
    print a ``wrote PATH`` line for each (to ``stream``, stdout by default)."""
    write_atomically(outputs)
    for target, _ in outputs:
        print(f"wrote {target}", file=stream or sys.stdout)

"""Output files written together and atomically, for every command and the demo.

Every writer first writes a temporary file beside its target; only when all have succeeded are
they renamed over their targets, so an interrupted or failed run never leaves half a set of
outputs or a truncated file.
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any


def write_atomically(outputs: Sequence[tuple[Path, Callable[[Path], Any]]]) -> None:
    """Write every ``(target, writer)`` to a temporary file next to it, then rename them all.

    A failure in any writer leaves no output (and no temporary file) behind, and its message
    names the target. A target's own directory is created, never its parents.

    Parameters
    ----------
    outputs : sequence of (Path, callable)
        Each target and the function that writes its content into the path it is given (a
        temporary name with the target's suffix, so writers that infer a format from it work).

    Raises
    ------
    OSError
        Naming the target whose writer failed.
    """
    temps: list[tuple[Path, Path]] = []
    try:
        for target, write in outputs:
            target.parent.mkdir(exist_ok=True)
            tmp = target.with_name(f".{target.name}.{uuid.uuid4().hex[:8]}.tmp{target.suffix}")
            temps.append((tmp, target))
            try:
                write(tmp)
            except OSError as exc:
                raise OSError(f"cannot write {str(target)!r}: {exc.strerror or exc}") from exc
        for tmp, target in temps:
            os.replace(tmp, target)
    finally:
        for tmp, _ in temps:
            tmp.unlink(missing_ok=True)

"""Run every example of the README as written, as a newcomer would on a fresh clone.

    python scripts/check_readme_examples.py [--mirror DIR|URL] [--keep DIR]

Each fenced ``bash`` and ``python`` block of ``README.md`` runs in a new scratch folder (with a
copy of ``examples/``, which the README's commands name), one command after the other, the
measured data fetched first by ``shipgym data fetch`` into a scratch cache with
``SHIPGYM_MEASURED_DATA`` unset, exactly as the README tells a user. ``--mirror`` reads the
data from a local copy laid out like the public sources (CI: ``../shared/data/measured``);
without it the files come from their original public sources.

A few lines are not run here, each for a stated reason (an install step, which the caller has
done; the test suite and the documentation build, which CI runs as steps of their own; CI
itself). A command that fails stops the check with its exit code and output. Each command's
time is printed as it completes.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FENCE = re.compile(r"^```(bash|python)\n(.*?)^```", flags=re.M | re.S)

#: Commands not run here, with the reason printed for each (matched on the start of the line).
NOT_RUN: dict[str, str] = {
    'pip install ".[dev]" && python -m pytest': "CI runs it as its first step",
    "pip install -e": "an install step: the caller has installed shipgym",
    "python -m pytest": "the test suite: CI runs it as a step of its own",
    ".ci/run": "CI itself",
    "ruff check": "the linter: CI runs it as a step of its own",
}
#: An install prefix whose command is run without it (the caller has installed shipgym).
INSTALL = re.compile(r'^pip install "[^"]*"\s*&&\s*')
#: The documentation build: CI runs it with warnings as errors in a step of its own.
DOCS_BUILD = "python -m sphinx"


def readme_commands(text: str) -> list[tuple[str, str]]:
    """The README's examples in order: ``("bash", command)`` per shell command (continuation
    lines joined, comments dropped) and ``("python", source)`` per Python block."""
    out: list[tuple[str, str]] = []
    for kind, body in FENCE.findall(text):
        if kind == "python":
            out.append(("python", body))
            continue
        joined = body.replace("\\\n", " ")
        for line in joined.splitlines():
            line = line.split("  #", 1)[0].strip()
            if line and not line.startswith("#"):
                out.append(("bash", line))
    return out


def skip_reason(command: str) -> str | None:
    """Why ``command`` is not run here, or None."""
    if DOCS_BUILD in command:
        return "the documentation build: CI runs it with warnings as errors"
    for start, reason in NOT_RUN.items():
        if command.startswith(start):
            return reason
    return None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--mirror",
        default=None,
        metavar="DIR|URL",
        help="read the measured data from this copy of the public sources (SHIPGYM_DATA_MIRROR)",
    )
    parser.add_argument(
        "--keep",
        default=None,
        metavar="DIR",
        help="run in this folder and keep it (default: a scratch folder, removed at the end)",
    )
    args = parser.parse_args(argv)
    commands = readme_commands((ROOT / "README.md").read_text())
    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="shipgym-readme-"))
    work.mkdir(parents=True, exist_ok=True)
    env = {k: v for k, v in os.environ.items() if k != "SHIPGYM_MEASURED_DATA"}
    env["SHIPGYM_DATA_DIR"] = str(work / "data-cache")
    env["MPLBACKEND"] = "Agg"
    if args.mirror:
        local = "://" not in args.mirror
        env["SHIPGYM_DATA_MIRROR"] = str(Path(args.mirror).resolve()) if local else args.mirror
    shutil.copytree(ROOT / "examples", work / "examples", dirs_exist_ok=True)
    print(f"README examples: {len(commands)} commands in {work}", flush=True)
    t_all = time.perf_counter()
    try:
        for i, (kind, command) in enumerate(commands, start=1):
            label = command if kind == "bash" else "python block: " + command.splitlines()[0]
            reason = skip_reason(command) if kind == "bash" else None
            if reason:
                print(f"[{i}/{len(commands)}] not run: {label}  ({reason})", flush=True)
                continue
            if kind == "bash":
                command = INSTALL.sub("", command)
                cmd = ["bash", "-c", command]
            else:
                cmd = [sys.executable, "-c", command]
            t0 = time.perf_counter()
            proc = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True)
            took = time.perf_counter() - t0
            if proc.returncode != 0:
                print(f"[{i}/{len(commands)}] FAILED (exit {proc.returncode}) {label}", flush=True)
                print(proc.stdout[-4000:], proc.stderr[-4000:], sep="\n", file=sys.stderr)
                return 1
            print(f"[{i}/{len(commands)}] ok in {took:5.1f} s: {label}", flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    print(f"every README example ran as written ({time.perf_counter() - t_all:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

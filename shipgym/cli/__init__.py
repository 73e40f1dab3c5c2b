"""The ``shipgym`` command.

Subcommands::

    shipgym demo  [--out DIR] [--model nomoto1|nomoto2|norrbin|bech]
    shipgym bench [--steps N] [--num-envs N] [--repeats N] [--vec-steps N] [--json OUT]
                  [--plot OUT.png]
    shipgym envs
    shipgym simulate zigzag|turning|pullout|spiral|imo [--model NAME|FIT.json] [...] [--json F]
                     [--plot P]
    shipgym evaluate --env ID [--controller classic|classic-tuned|ppo|sac|zero] [--episodes N]
                     [--model NAME|FIT.json] [--gains FILE]
                     [--seed S] [--agents DIR] [--json OUT] [--plot DIR]
                     [--ray [ADDRESS]] [--ray-cpus N] [--task-episodes N]
    shipgym train --env ID --algo ppo|sac [--timesteps N] [--seed S] [--out DIR]
                  [--tensorboard DIR | --no-tensorboard] [--overwrite]
    shipgym train --resume DIR [--timesteps N]
    shipgym train --ray [ADDRESS] [--ray-cpus N] --sweep FILE [--seeds S1,S2,...] [--out DIR]
    shipgym benchmark [--episodes N] [--json OUT] [--csv OUT] [--plots DIR] [--out DIR]
                      [--env ID]... [--controller NAME]... [--condition C]... [--jobs N]
                      [--ray [ADDRESS]] [--ray-cpus N] [--task-episodes N]
                      [--throughput [--throughput-steps N]]
    shipgym identify PATH [--format F] [--columns MAP] [--max-gap S] [--length L]
                     [--model nomoto1|nomoto2|norrbin|bech|rvg3dof|vmm:...|kvlcc2]
                     [--json OUT|-] [--plot OUT.png] [--window S|auto|none] [--holdout FRAC]
                     [--max-effects N] [--quiet]
    shipgym design FILE.json [--json OUT] [--plot OUT.png] [--bandwidth W] [--damping Z]

Each subcommand is a module of this package with a ``build(sub)`` that adds its parser and
sets ``handler``; ``SUBCOMMANDS`` maps the names to them. Bad input ends with a one-line
message and exit code 2 (argparse's own message for bad arguments, ``shipgym: error: ...``
for a ``ValueError`` raised by the library), never a traceback. Heavy imports happen inside
the handlers, so ``shipgym --help`` is fast.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import NoReturn

from shipgym.cli import (
    bench,
    benchmark,
    data,
    demo,
    design,
    envs,
    evaluate,
    identify,
    simulate,
    train,
)
from shipgym.cli._common import PROG, Builder

__all__ = ["SUBCOMMANDS", "build_parser", "main"]


#: Subcommand name -> builder.
SUBCOMMANDS: dict[str, Builder] = {
    "demo": demo.build,
    "bench": bench.build,
    "envs": envs.build,
    "simulate": simulate.build,
    "evaluate": evaluate.build,
    "train": train.build,
    "benchmark": benchmark.build,
    "identify": identify.build,
    "design": design.build,
    "data": data.build,
}


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and a hint, not the whole usage."""

    def error(self, message: str) -> NoReturn:
        """Print ``<prog>: error: <message>`` and where the options are listed; exit 2."""
        self.exit(
            2, f"{self.prog}: error: {message}\n  hint: '{self.prog} --help' lists the options\n"
        )


def build_parser() -> argparse.ArgumentParser:
    """The ``shipgym`` argument parser with every subcommand of ``SUBCOMMANDS``."""
    from shipgym import __version__

    parser = _Parser(
        prog=PROG,
        description=(
            "shipgym: ship manoeuvring environments, vessel models, classic control and "
            "identification."
        ),
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(
        dest="command", metavar="COMMAND", required=True, help="the command to run"
    )
    for build in SUBCOMMANDS.values():
        build(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``shipgym`` command; returns the exit code (2 for bad input).

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` by default.
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse has printed usage and the message (or the help)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    try:
        return int(args.handler(args))
    except ValueError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    except (OSError, ImportError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130

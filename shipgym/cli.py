"""The ``shipgym`` command.

Subcommands::

    shipgym demo  [--out DIR] [--model nomoto1|nomoto2|norrbin|bech]
    shipgym bench [--steps N] [--num-envs N] [--repeats N] [--vec-steps N] [--json OUT]
                  [--plot OUT.png]
    shipgym envs

Each subcommand is registered by a builder in ``SUBCOMMANDS`` (name -> function that adds its
parser and sets ``handler``), so later subcommands (simulate, evaluate, identify, train,
benchmark) plug in with one entry. Bad input ends with a one-line message and exit code 2
(argparse's own message for bad arguments, ``shipgym: error: ...`` for a ``ValueError`` raised
by the library), never a traceback. Heavy imports happen inside the handlers, so
``shipgym --help`` is fast.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from typing import Any

PROG = "shipgym"
Handler = Callable[[argparse.Namespace], int]
Builder = Callable[["argparse._SubParsersAction[argparse.ArgumentParser]"], None]


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text!r}")
    return value


# ------------------------------------------------------------------------------------------
# demo
# ------------------------------------------------------------------------------------------
def _run_demo(args: argparse.Namespace) -> int:
    from shipgym.demo import format_summary, run_demo

    print(
        f"running the shipgym demo (zigzag 20/20 with {args.model}, path following) ...", flush=True
    )
    summary = run_demo(args.out, model=args.model)
    print(format_summary(summary))
    return 0


def _build_demo(sub: Any) -> None:
    from shipgym.models import NOMOTO_MODEL_NAMES

    p = sub.add_parser(
        "demo",
        help="zigzag trial and path-following episode, written as PNG figures",
        description=(
            "Simulate a 20/20 zigzag of a Nomoto-family ship (the Mariner class cargo ship) "
            "and a path-following episode of R/V Gunnerus in shipgym/RVGPathFollowing-v0 "
            "with a lookahead-LOS guidance and PD heading policy. Writes zigzag.png and "
            "path_following.png and prints the overshoots and the cross-track error."
        ),
    )
    p.add_argument(
        "--out",
        default="shipgym-demo",
        metavar="DIR",
        help="output directory (default: %(default)s)",
    )
    p.add_argument(
        "--model",
        default="nomoto1",
        choices=NOMOTO_MODEL_NAMES,
        help="Nomoto-family model of the zigzag (default: %(default)s)",
    )
    p.set_defaults(handler=_run_demo)


# ------------------------------------------------------------------------------------------
# bench
# ------------------------------------------------------------------------------------------
def _run_bench(args: argparse.Namespace) -> int:
    from shipgym.bench import format_table, plot_ratios, run_bench, write_json

    print(
        f"shipgym bench: single env {args.steps} steps x {args.repeats} repeats, vector "
        f"{args.num_envs} envs; one line per measurement as it completes",
        file=sys.stderr,
        flush=True,
    )
    report = run_bench(
        steps=args.steps, num_envs=args.num_envs, repeats=args.repeats, vec_steps=args.vec_steps
    )
    print(format_table(report))
    if args.json:
        print(f"wrote {write_json(report, args.json)}")
    if args.plot:
        print(f"wrote {plot_ratios(report, args.plot)}")
    return 0


def _build_bench(sub: Any) -> None:
    from shipgym.bench import DEFAULT_NUM_ENVS, DEFAULT_REPEATS, DEFAULT_STEPS

    p = sub.add_parser(
        "bench",
        help="speed benchmark against Gymnasium's CartPole (single and vector envs)",
        description=(
            "Measure, in one process, the single-env step time (via gymnasium.make) and the "
            "vector-env throughput (vector_entry_point) of every shipgym env relative to "
            "CartPole-v1 and CartPoleVectorEnv, and compare the ratios with the targets. "
            "The exit code does not depend on PASS/MISS."
        ),
    )
    p.add_argument(
        "--steps",
        type=_positive_int,
        default=DEFAULT_STEPS,
        metavar="N",
        help="timed single-env steps per repeat (default: %(default)s)",
    )
    p.add_argument(
        "--num-envs",
        type=_positive_int,
        default=DEFAULT_NUM_ENVS,
        metavar="N",
        help="vector env batch size (default: %(default)s)",
    )
    p.add_argument(
        "--repeats",
        type=_positive_int,
        default=DEFAULT_REPEATS,
        metavar="N",
        help="timed repeats per measurement, best one counts (default: %(default)s)",
    )
    p.add_argument(
        "--vec-steps",
        type=_positive_int,
        default=None,
        metavar="N",
        help="timed vector steps per repeat (default: max(5, steps // 200))",
    )
    p.add_argument("--json", default=None, metavar="OUT", help="write the numbers as JSON")
    p.add_argument(
        "--plot",
        default=None,
        metavar="OUT.png",
        help="write a bar chart of the ratios with the targets",
    )
    p.set_defaults(handler=_run_bench)


# ------------------------------------------------------------------------------------------
# envs
# ------------------------------------------------------------------------------------------
def _run_envs(args: argparse.Namespace) -> int:
    import gymnasium as gym

    from shipgym.envs import ENV_IDS

    tasks = _env_tasks()
    rows = []
    for env_id in ENV_IDS:
        env = gym.make(env_id)
        try:
            steps = env.spec.max_episode_steps if env.spec else None
            dt = float(env.unwrapped.dt)
            rows.append(
                (
                    env_id,
                    str(env.action_space.shape[0]),
                    str(env.observation_space.shape[0]),
                    f"{dt:g}",
                    "-" if steps is None else f"{steps} ({steps * dt:g} s)",
                    tasks.get(env_id, ""),
                )
            )
        finally:
            env.close()
    header = ("id", "actions", "obs", "dt [s]", "max steps", "task")
    widths = [max(len(r[i]) for r in (header, *rows)) for i in range(5)]
    for r in (header, *rows):
        cells = [c.ljust(w) for c, w in zip(r[:5], widths, strict=True)]
        print("  ".join(cells) + "  " + r[5])
    return 0


def _env_tasks() -> dict[str, str]:
    """Task and action of each id, from the table in :mod:`shipgym.envs`' docstring."""
    import shipgym.envs

    tasks = {}
    for line in (shipgym.envs.__doc__ or "").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 3 and cells[0].startswith("``shipgym/"):
            tasks[cells[0].strip("`")] = f"{cells[1]}; action: {cells[2]}"
    return tasks


def _build_envs(sub: Any) -> None:
    p = sub.add_parser(
        "envs",
        help="list the environment ids with their action/observation sizes and time step",
        description="List the registered shipgym environments.",
    )
    p.set_defaults(handler=_run_envs)


#: Subcommand name -> builder. Planned: simulate, evaluate, identify, train, benchmark.
SUBCOMMANDS: dict[str, Builder] = {
    "demo": _build_demo,
    "bench": _build_bench,
    "envs": _build_envs,
}


def build_parser() -> argparse.ArgumentParser:
    """The ``shipgym`` argument parser with every subcommand of ``SUBCOMMANDS``."""
    from shipgym import __version__

    parser = argparse.ArgumentParser(
        prog=PROG,
        description=(
            "shipgym: ship manoeuvring environments, vessel models, classic control and "
            "identification."
        ),
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
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
    except OSError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

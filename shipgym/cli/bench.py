"""``shipgym bench``: the env step speed against Gymnasium's CartPole."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from shipgym.cli._common import int_in, output_path, write_outputs


def run(args: argparse.Namespace) -> int:
    from shipgym.bench import format_table, plot_ratios, run_bench, write_json

    json_path = output_path(args.json, "--json", ".json")
    plot_path = output_path(args.plot, "--plot", ".png")
    print(
        f"shipgym bench: single env {args.steps} steps x {args.repeats} rounds, vector "
        f"{args.num_envs} envs; a line per round as it completes",
        file=sys.stderr,
        flush=True,
    )
    report = run_bench(
        steps=args.steps,
        num_envs=args.num_envs,
        repeats=args.repeats,
        vec_steps=args.vec_steps,
        busy=args.busy,
    )
    print(format_table(report))
    outputs: list[tuple[Path, Callable[[Path], Any]]] = []
    if json_path is not None:
        outputs.append((json_path, lambda p: write_json(report, p)))
    if plot_path is not None:
        outputs.append((plot_path, lambda p: plot_ratios(report, p)))
    write_outputs(outputs)
    return 0


def build(sub: Any) -> None:
    from shipgym.bench import DEFAULT_NUM_ENVS, DEFAULT_REPEATS, DEFAULT_STEPS

    p = sub.add_parser(
        "bench",
        help="speed benchmark against Gymnasium's CartPole (single and vector envs)",
        description=(
            "Measure, in one process, the single-env step time (via gymnasium.make) and the "
            "vector-env throughput (vector_entry_point) of every shipgym env relative to "
            "CartPole-v1 and CartPoleVectorEnv, timed in interleaved rounds, and compare the "
            "ratios with the targets. "
            "The exit code does not depend on PASS/MISS."
        ),
    )
    p.add_argument(
        "--steps",
        type=int_in(1, 10**8),
        default=DEFAULT_STEPS,
        metavar="N",
        help="timed single-env steps per repeat (default: %(default)s)",
    )
    p.add_argument(
        "--num-envs",
        type=int_in(1, 10**6),
        default=DEFAULT_NUM_ENVS,
        metavar="N",
        help="vector env batch size (default: %(default)s)",
    )
    p.add_argument(
        "--repeats",
        type=int_in(1, 1000),
        default=DEFAULT_REPEATS,
        metavar="N",
        help=(
            "rounds, each timing every measurement once; a ratio is the median over the "
            "rounds of the ratio to CartPole in the same round (default: %(default)s)"
        ),
    )
    p.add_argument(
        "--vec-steps",
        type=int_in(1, 10**8),
        default=None,
        metavar="N",
        help="timed vector steps per repeat (default: max(5, steps // 200))",
    )
    p.add_argument(
        "--busy",
        type=int_in(0, 64),
        default=0,
        metavar="N",
        help=(
            "run with N helper processes keeping cores busy (a shared machine), to compare the "
            "one-thread and all-thread vector steps under load (default: %(default)s, idle)"
        ),
    )
    p.add_argument("--json", default=None, metavar="OUT", help="write the numbers as JSON")
    p.add_argument(
        "--plot",
        default=None,
        metavar="OUT.png",
        help="write a bar chart of the ratios with the targets",
    )
    p.set_defaults(handler=run)

"""``shipgym demo``: a zigzag trial and a path-following episode, written as figures."""

from __future__ import annotations

import argparse
from typing import Any

from shipgym.cli._common import output_dir


def run(args: argparse.Namespace) -> int:
    from shipgym.demo import format_summary, run_demo

    out = output_dir(args.out, "--out")
    print(
        f"running the shipgym demo (zigzag 20/20 with {args.model}, path following) ...", flush=True
    )
    summary = run_demo(out, model=args.model)
    print(format_summary(summary))
    return 0


def build(sub: Any) -> None:
    from shipgym.models import NOMOTO_MODEL_NAMES

    p = sub.add_parser(
        "demo",
        help="zigzag trial and path-following episode, written as PNG figures",
        description=(
            "Simulate a 20/20 zigzag of a Nomoto-family ship (the Mariner class cargo ship) "
            "and a path-following episode of R/V Gunnerus in shipgym/RVGPathFollowing-v1 "
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
    p.set_defaults(handler=run)

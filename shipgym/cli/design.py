"""``shipgym design``: heading-autopilot gains from an identified model."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from shipgym.cli._common import PROG, float_in, output_path, write_outputs


def run(args: argparse.Namespace) -> int:
    import json

    from shipgym.benchmark.design import (
        check_designable,
        design_heading_autopilot,
        plot_heading_design,
    )
    from shipgym.models import NOMOTO_MODEL_NAMES
    from shipgym.models.model_file import load_model

    json_path = output_path(args.json, "--json", ".json")
    plot_path = output_path(args.plot, "--plot", ".png")
    path = Path(args.model_file)
    if not path.is_file():
        raise ValueError(
            f"model file {args.model_file!r} does not exist (expected the JSON that "
            "shipgym identify --json writes)"
        )
    for out in (json_path, plot_path):
        if out is not None and out.resolve() == path.resolve():
            raise ValueError(f"output {str(out)!r} is the model file; refusing")
    try:
        verdict = json.loads(path.read_text(encoding="utf-8")).get("verdict")
    except (ValueError, AttributeError):
        verdict = None  # load_model names what is wrong with the file
    if isinstance(verdict, dict) and verdict.get("identifiable") is False:
        reasons = "; ".join(str(r) for r in verdict.get("reasons") or []) or "no reason given"
        raise ValueError(
            f"{args.model_file!r} is not identifiable: {reasons}; shipgym design needs a model "
            "the record determines (identify the ship from a record that moves the rudder and "
            "turns the ship: zigzag, pull-out, random rudder)"
        )
    model = load_model(path)
    if model.name not in NOMOTO_MODEL_NAMES:
        raise ValueError(
            f"{args.model_file!r} holds a {model.name!r} model (3-DOF manoeuvring); shipgym "
            f"design takes a Nomoto-family model ({', '.join(NOMOTO_MODEL_NAMES)}: shipgym "
            "identify LOG --model nomoto1 --json FILE)"
        )
    check_designable(model)
    print(f"designing the heading autopilot for {args.model_file} ...", file=sys.stderr, flush=True)
    design = design_heading_autopilot(model, omega_n=args.bandwidth, zeta=args.damping)
    print(design.summary())
    text = json.dumps(design.gains_document(), indent=2, allow_nan=False) + "\n"
    outputs: list[tuple[Path, Callable[[Path], Any]]] = []
    if json_path is not None:
        outputs.append((json_path, lambda p: p.write_text(text, encoding="utf-8")))
    if plot_path is not None:
        outputs.append((plot_path, lambda p: plot_heading_design(design, p)))
    write_outputs(outputs)
    if json_path is not None:
        print(
            f"run it on the identified ship: {PROG} evaluate --env shipgym/NomotoHeading-v0 "
            f"--model {args.model_file} --controller classic --gains {json_path}"
        )
    return 0


def build(sub: Any) -> None:
    p = sub.add_parser(
        "design",
        help="heading autopilot for an identified Nomoto-family ship, checked in simulation",
        description=(
            "Design the PID heading autopilot of a ship identified by shipgym identify --json "
            "(nomoto1, nomoto2, norrbin or bech) by the rule of the classic controller of "
            "shipgym/NomotoHeading-v0: pole placement on the first-order model that matches "
            "the ship at the design bandwidth, bandwidth from the steering gear and the ship. "
            "Prints the gains, the open-loop margins with the ship's input delay, the "
            "simulated 10 and 30 deg heading steps and the open-loop 20/20 zigzag. --json "
            "writes the gains for shipgym evaluate --gains. A model it cannot design for is "
            "refused with exit code 2 and the reason: an identification whose verdict is not "
            "identifiable, or a gain K <= 0 (a positive rudder must give a positive yaw rate)."
        ),
    )
    p.add_argument(
        "model_file", metavar="FILE.json", help="model file (shipgym identify --json FILE.json)"
    )
    p.add_argument(
        "--json", default=None, metavar="OUT", help="write the gains and the design as JSON"
    )
    p.add_argument(
        "--plot",
        default=None,
        metavar="OUT.png",
        help="write the step responses, their rudder and the zigzag as a PNG",
    )
    p.add_argument(
        "--bandwidth",
        type=float_in(1e-4, 10.0, "rad/s"),
        default=None,
        metavar="W",
        help="closed-loop natural frequency [rad/s] (default: from the steering gear and ship)",
    )
    p.add_argument(
        "--damping",
        type=float_in(0.05, 5.0, "(damping ratio)"),
        default=0.8,
        metavar="Z",
        help="closed-loop relative damping (default: %(default)s)",
    )
    p.set_defaults(handler=run)

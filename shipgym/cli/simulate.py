"""``shipgym simulate``: the standard manoeuvres of a vessel model (zigzag, turning circle,
pull-out, spiral, the IMO table)."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from shipgym.cli._common import (
    finite_float,
    float_in,
    int_in,
    model_name,
    output_path,
    progress_line,
    write_outputs,
)

# Each trial runner prints its metrics and returns (JSON payload, figure writer, IMO rows).
_Trial = tuple[dict[str, Any], Callable[[str], Any], list[Any]]


def _simulate_zigzag(args: argparse.Namespace) -> _Trial:
    import math

    from shipgym import maneuvers as mv

    a = 20.0 if args.angle_deg is None else args.angle_deg
    n = 4 if args.reversals is None else args.reversals
    res = mv.zigzag(
        args.ship, a, args.heading_deg, args.side or "starboard", n, dt=args.dt, wind=args.wind
    )
    over = ", ".join("not checked" if math.isnan(o) else f"{o:.2f}" for o in res.overshoots_deg)
    print(
        f"zigzag {res.label} ({res.first} first): {res.particulars.vessel} ({res.model}), "
        f"U = {res.approach_speed:.2f} m/s"
    )
    print(f"  overshoots [deg]: {over}")
    print(
        f"  initial turning time {res.initial_turning_time:.1f} s, time to check yaw "
        f"{res.time_to_check_yaw:.1f} s, period {res.period:.1f} s"
    )
    if not res.completed:
        print("  the swing was not checked within the run (directionally unstable ship)")
    rows = mv.imo_rows(res.particulars, zigzags=[res])
    return res.to_dict(), lambda out: mv.plot_zigzag(res, out), rows


def _simulate_turning(args: argparse.Namespace) -> _Trial:
    import math

    from shipgym import maneuvers as mv

    a = 35.0 if args.angle_deg is None else args.angle_deg
    res = mv.turning_circle(args.ship, a, args.side or "starboard", dt=args.dt, wind=args.wind)
    L = res.particulars.length
    print(
        f"turning circle {math.degrees(res.rudder):g} deg to {res.side}: "
        f"{res.particulars.vessel} ({res.model}), L = {L:g} m, U = {res.approach_speed:.2f} m/s"
    )
    for name, value in (
        ("advance", res.advance),
        ("transfer", res.transfer),
        ("tactical diameter", res.tactical_diameter),
        ("steady turning diameter", res.steady_diameter),
    ):
        print(f"  {name:24s} {value:8.1f} m  ({value / L:.2f} L)")
    loss = round(100.0 * (1.0 - res.speed_ratio), 1) + 0.0  # no "-0.0"
    print(
        f"  steady yaw rate {math.degrees(res.steady_yaw_rate):+.3f} deg/s, steady speed "
        f"{res.steady_speed:.2f} m/s = {100 * res.speed_ratio:.1f} % of approach "
        f"(speed loss {loss:.1f} %)"
    )
    if args.wind is not None:
        print(
            f"  drift over the steady turn {math.hypot(*res.drift):.1f} m ("
            f"{res.drift_speed:.3f} m/s toward {math.degrees(res.drift_direction) % 360:.0f} deg)"
            " in the wind: the trial correction removes it"
        )
    rows = mv.imo_rows(res.particulars, turning=[res])
    return res.to_dict(), lambda out: mv.plot_turning_circle(res, out), rows


def _simulate_pullout(args: argparse.Namespace) -> _Trial:
    import math

    from shipgym import maneuvers as mv

    a = 20.0 if args.angle_deg is None else args.angle_deg
    res = mv.pullout(args.ship, a, args.side or "starboard", dt=args.dt, wind=args.wind)
    print(
        f"pull-out after {math.degrees(res.rudder):g} deg to {res.side}: "
        f"{res.particulars.vessel} ({res.model})"
    )
    print(
        f"  turning yaw rate {math.degrees(res.turn_yaw_rate):+.4f} deg/s, residual "
        f"{math.degrees(res.residual_yaw_rate):+.4f} deg/s -> "
        f"{'stable' if res.stable else 'directionally UNSTABLE'}"
    )
    return res.to_dict(), lambda out: mv.plot_pullout(res, out), []


def _simulate_spiral(args: argparse.Namespace) -> _Trial:
    import math

    from shipgym import maneuvers as mv

    if args.side is not None:
        raise ValueError("--side does not apply to the spiral (it sweeps both sides)")
    rudders = None
    if args.angle_deg is not None:
        if not 0 < args.angle_deg <= 35:
            raise ValueError(f"--angle-deg must be in (0, 35] deg, got {args.angle_deg!r}")
        fractions = (1.0, 0.75, 0.5, 0.25, 0.15, 0.1, 0.05)
        leg = [args.angle_deg * f for f in fractions]
        rudders = [*leg, 0.0, *(-d for d in reversed(leg))]
    kinds = ("direct", "reverse") if args.kind in (None, "both") else (args.kind,)
    results = [
        mv.spiral(args.ship, rudders, k, dt=args.dt, progress=progress_line, wind=args.wind)
        for k in kinds
    ]
    for res in results:
        print(f"{res.kind} spiral: {res.particulars.vessel} ({res.model})")
        print("  rudder [deg]   r [deg/s]   leg")
        for d, r, leg_name in zip(res.rudder, res.yaw_rate, res.leg, strict=True):
            print(f"  {math.degrees(d):+11.3f}  {math.degrees(r):+10.4f}   {leg_name}")
        if res.hysteresis:
            print(
                f"  hysteresis: loop width about {math.degrees(res.loop_width):.1f} deg "
                "(directionally unstable)"
            )
        else:
            print("  no hysteresis (directionally stable)")
    spirals = [r.to_dict() for r in results]
    payload = {"manoeuvre": "spiral", "wind": spirals[0]["wind"], "spirals": spirals}
    return payload, lambda out: mv.plot_spiral(results, out), []


def _simulate_imo(args: argparse.Namespace) -> _Trial:
    from shipgym import maneuvers as mv

    if args.side is not None:
        raise ValueError("--side does not apply to 'imo' (both sides are tested)")
    if args.angle_deg is not None:
        raise ValueError("--angle-deg does not apply to 'imo' (its trials are fixed)")
    report = mv.imo_criteria(args.ship, dt=args.dt, progress=progress_line, wind=args.wind)
    print(mv.format_imo_table(report))
    print(f"overall: {'PASS' if report.passed else 'FAIL'}")
    return report.to_dict(), lambda out: mv.plot_imo(report, out), []


_SIMULATE: dict[str, Callable[[argparse.Namespace], _Trial]] = {
    "zigzag": _simulate_zigzag,
    "turning": _simulate_turning,
    "pullout": _simulate_pullout,
    "spiral": _simulate_spiral,
    "imo": _simulate_imo,
}


def wind_option(text: str) -> dict[str, float]:
    """``--wind SPEED,DIR``: true wind speed [m/s] and the direction it comes from [deg,
    clockwise from north]; returned as the trials' ``wind`` (the env's ``wind`` option: SI
    units and radians)."""
    import math

    from shipgym.models.seaway_options import WIND_SPEED_RANGE

    parts = text.split(",")
    try:
        speed, direction = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be SPEED,DIR (m/s and deg the wind comes from), got {text!r}"
        ) from None
    low, high = WIND_SPEED_RANGE
    if not (math.isfinite(speed) and low <= speed <= high and abs(direction) <= 360.0):
        raise argparse.ArgumentTypeError(
            f"speed must be in [{low:g}, {high:g}] m/s and the direction in [-360, 360] deg, "
            f"got {text!r}"
        )
    return {"speed": speed, "direction": math.radians(direction)}


def run(args: argparse.Namespace) -> int:
    import json

    from shipgym.maneuvers import PARTICULARS, format_imo_table

    kind = args.manoeuvre
    for flag, value, only in (
        ("--kind", args.kind, "spiral"),
        ("--heading-deg", args.heading_deg, "zigzag"),
        ("--reversals", args.reversals, "zigzag"),
    ):
        if value is not None and kind != only:
            raise ValueError(f"{flag} applies to the {only} only, not to {kind!r}")
    json_path = output_path(args.json, "--json", ".json")
    plot_path = output_path(args.plot, "--plot", ".png")
    from shipgym.models import make_model
    from shipgym.models.model_file import is_model_file
    from shipgym.models.rvg import NEWEST_RVG_PARAMETERS, RVG_PARAMETER_SETS

    model_file = is_model_file(args.model)
    if model_file:
        if args.params is not None:
            raise ValueError("--params does not go with a model file (the file is the model)")
        args.ship = args.model
        make_model(args.model)  # a bad model file fails here, before the trial starts
    elif args.model == "vmm":
        if args.params is None:
            raise ValueError(
                "--model vmm needs --params FIT.json: a fitted model (shipgym identify "
                "--model vmm:<term set> --json FIT.json)"
            )
        args.ship = make_model("vmm", args.params)
    elif args.model == "rvg3dof":
        if args.params is not None and args.params not in RVG_PARAMETER_SETS:
            raise ValueError(
                f"--params for rvg3dof must be one of {RVG_PARAMETER_SETS}, got {args.params!r}"
            )
        args.params = args.params or NEWEST_RVG_PARAMETERS
        args.ship = make_model("rvg3dof", args.params)
    elif args.params is not None:
        raise ValueError(
            f"--params selects an rvg3dof parameter set or a fitted vmm, not one of {args.model!r}"
        )
    else:
        args.ship = args.model
    if args.gusts:
        if args.wind is None:
            raise ValueError("--gusts needs --wind SPEED,DIR (the mean wind)")
        args.wind["gusts"] = True
    params = f" --params {args.params}" if args.params else ""
    print(f"shipgym simulate {kind} --model {args.model}{params} ...", file=sys.stderr, flush=True)
    if args.wind is not None:
        gusts = " with NORSOK gusts" if args.gusts else ", constant"
        print(
            f"in a true wind of {args.wind['speed']:g} m/s from "
            f"{math.degrees(args.wind['direction']) % 360.0:05.1f} deg{gusts} (from the first "
            "execute on)"
        )
    payload, draw, rows = _SIMULATE[kind](args)
    if args.model == "rvg3dof":
        payload["params"] = args.ship.params.name
    if kind in ("zigzag", "turning"):
        if model_file:
            lu = payload["length_m"] / payload["approach_speed_m_s"]
        elif args.model == "vmm":
            lu = args.ship.params.length / args.ship.params.approach_speed
        else:
            lu = PARTICULARS[args.model].length_over_speed
        if math.isfinite(lu):
            title = f"IMO MSC.137(76) criteria from this trial (L/U = {lu:.1f} s)"
            print(format_imo_table(rows, title=title))
            payload["imo"] = [row.to_dict() for row in rows]
        else:
            print(
                f"IMO criteria not computed: {args.model} states no ship length (they are "
                "ratios to L; set length_m in the file, or identify with --length L)"
            )
    text = json.dumps(payload, indent=1, allow_nan=False) + "\n"
    outputs: list[tuple[Path, Callable[[Path], Any]]] = []
    if json_path is not None:
        outputs.append((json_path, lambda p: p.write_text(text)))
    if plot_path is not None:
        outputs.append((plot_path, draw))
    write_outputs(outputs)
    return 0


def build(sub: Any) -> None:
    from shipgym.models import MODEL_NAMES
    from shipgym.models.rvg import NEWEST_RVG_PARAMETERS, RVG_PARAMETER_SETS

    p = sub.add_parser(
        "simulate",
        help="standard manoeuvres (zigzag, turning circle, pull-out, spiral) and IMO criteria",
        description=(
            "Simulate a standard manoeuvring trial on one model and print its metrics: "
            "zigzag a/b (overshoots, initial turning time, time to check yaw, period), "
            "turning circle (advance, transfer, tactical and steady diameter, speed loss), "
            "pull-out (residual yaw rate), spiral (direct/reverse delta-r curve, hysteresis) "
            "or 'imo', the IMO MSC.137(76) criteria to both sides as a pass/fail table. "
            "For rvg3dof the rudder is the common pod azimuth at service thrust with the sign "
            "flipped (positive = starboard turn)."
        ),
    )
    p.add_argument(
        "manoeuvre",
        choices=tuple(_SIMULATE),
        help="the trial: zigzag, turning circle, pull-out, spiral or the IMO table",
    )
    p.add_argument(
        "--model",
        default="nomoto1",
        type=model_name,
        metavar="NAME|FIT.json",
        help=f"model: one of {', '.join(MODEL_NAMES)} or an identified model file "
        "(shipgym identify --json FIT.json); default %(default)s",
    )
    p.add_argument(
        "--params",
        default=None,
        metavar="SET|FIT.json",
        help=f"rvg3dof parameter set ({' or '.join(RVG_PARAMETER_SETS)}; default "
        f"{NEWEST_RVG_PARAMETERS}, the Gunnerus identified from its sea trials; seed001 is the "
        "unvalidated seed model); for vmm the model file of a fit (shipgym identify --model "
        "vmm:<term set> --json FIT.json)",
    )
    p.add_argument(
        "--wind",
        type=wind_option,
        default=None,
        metavar="SPEED,DIR",
        help="a constant true wind from the first execute on: speed [m/s] and the direction it "
        "comes from [deg, clockwise from north], at the model's scale; the turning circle "
        "reports its drift. The Nomoto family (the Mariner, Isherwood 1972) and rvg3dof "
        "(Blendermann 1994) through the env's seaway, kvlcc2 through its MMG model's wind, a "
        "vmm with identified wind terms through its apparent-wind inputs",
    )
    p.add_argument(
        "--gusts",
        action="store_true",
        help="with --wind: gusts about the mean wind (the env's NORSOK gust process, one fixed "
        "realisation; the Nomoto family and rvg3dof)",
    )
    p.add_argument(
        "--angle-deg",
        type=finite_float,
        default=None,
        metavar="A",
        help="rudder angle [deg]: zigzag a (20), turning (35), pull-out (20), largest "
        "angle of the direct spiral (20)",
    )
    p.add_argument(
        "--heading-deg",
        type=finite_float,
        default=None,
        metavar="B",
        help="zigzag: heading change b [deg] at which the rudder is reversed (default: A)",
    )
    p.add_argument(
        "--side",
        choices=("starboard", "port"),
        default=None,
        help="turn side (turning, pull-out) or first rudder side (zigzag); default starboard",
    )
    p.add_argument(
        "--reversals",
        type=int_in(1, 100),
        default=None,
        metavar="N",
        help="zigzag: number of rudder reversals (default 4)",
    )
    p.add_argument(
        "--kind",
        choices=("direct", "reverse", "both"),
        default=None,
        help="spiral: direct (Dieudonne), reverse (Bech) or both (default)",
    )
    p.add_argument(
        "--dt",
        type=float_in(1e-3, 60.0, "s"),
        default=None,
        metavar="S",
        help="integration time step of the trial [s]",
    )
    p.add_argument("--json", default=None, metavar="OUT", help="write the results as JSON")
    p.add_argument("--plot", default=None, metavar="OUT.png", help="write the standard figure")
    p.set_defaults(handler=run)

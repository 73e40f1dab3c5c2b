"""The ``shipgym`` command.

Subcommands::

    shipgym demo  [--out DIR] [--model nomoto1|nomoto2|norrbin|bech]
    shipgym bench [--steps N] [--num-envs N] [--repeats N] [--vec-steps N] [--json OUT]
                  [--plot OUT.png]
    shipgym envs
    shipgym simulate zigzag|turning|pullout|spiral|imo [--model NAME] [...] [--json F] [--plot P]
    shipgym evaluate --env ID [--controller classic|zero] [--episodes N] [--seed S]
                     [--json OUT] [--plot DIR]

Each subcommand is registered by a builder in ``SUBCOMMANDS`` (name -> function that adds its
parser and sets ``handler``), so later subcommands (identify, train, benchmark) plug in with
one entry. Bad input ends with a one-line message and exit code 2
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


# ------------------------------------------------------------------------------------------
# simulate
# ------------------------------------------------------------------------------------------
def _finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


# Each trial runner prints its metrics and returns (JSON payload, figure writer, IMO rows).
_Trial = tuple[dict[str, Any], Callable[[str], Any], list[Any]]


def _progress(msg: str) -> None:
    print(f"  {msg}", file=sys.stderr, flush=True)


def _simulate_zigzag(args: argparse.Namespace) -> _Trial:
    import math

    from shipgym import maneuvers as mv

    a = 20.0 if args.angle_deg is None else args.angle_deg
    n = 4 if args.reversals is None else args.reversals
    res = mv.zigzag(args.model, a, args.heading_deg, args.side or "starboard", n, dt=args.dt)
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
    res = mv.turning_circle(args.model, a, args.side or "starboard", dt=args.dt)
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
    rows = mv.imo_rows(res.particulars, turning=[res])
    return res.to_dict(), lambda out: mv.plot_turning_circle(res, out), rows


def _simulate_pullout(args: argparse.Namespace) -> _Trial:
    import math

    from shipgym import maneuvers as mv

    a = 20.0 if args.angle_deg is None else args.angle_deg
    res = mv.pullout(args.model, a, args.side or "starboard", dt=args.dt)
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
    results = [mv.spiral(args.model, rudders, k, dt=args.dt, progress=_progress) for k in kinds]
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
    payload = {"manoeuvre": "spiral", "spirals": [r.to_dict() for r in results]}
    return payload, lambda out: mv.plot_spiral(results, out), []


def _simulate_imo(args: argparse.Namespace) -> _Trial:
    from shipgym import maneuvers as mv

    if args.side is not None:
        raise ValueError("--side does not apply to 'imo' (both sides are tested)")
    if args.angle_deg is not None:
        raise ValueError("--angle-deg does not apply to 'imo' (its trials are fixed)")
    report = mv.imo_criteria(args.model, dt=args.dt, progress=_progress)
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


def _run_simulate(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from shipgym.maneuvers import PARTICULARS, format_imo_table

    kind = args.manoeuvre
    for flag, value, only in (
        ("--kind", args.kind, "spiral"),
        ("--heading-deg", args.heading_deg, "zigzag"),
        ("--reversals", args.reversals, "zigzag"),
    ):
        if value is not None and kind != only:
            raise ValueError(f"{flag} applies to the {only} only, not to {kind!r}")
    if args.plot and Path(args.plot).suffix.lower() != ".png":
        raise ValueError(f"--plot must name a .png file, got {args.plot!r}")
    print(f"shipgym simulate {kind} --model {args.model} ...", file=sys.stderr, flush=True)
    payload, draw, rows = _SIMULATE[kind](args)
    if kind in ("zigzag", "turning"):
        lu = PARTICULARS[args.model].length_over_speed
        title = f"IMO MSC.137(76) criteria from this trial (L/U = {lu:.1f} s)"
        print(format_imo_table(rows, title=title))
        payload["imo"] = [row.to_dict() for row in rows]
    if args.json:
        out = Path(args.json)
        out.write_text(json.dumps(payload, indent=1, allow_nan=False) + "\n")
        print(f"wrote {out}")
    if args.plot:
        print(f"wrote {draw(args.plot)}")
    return 0


def _build_simulate(sub: Any) -> None:
    from shipgym.models import MODEL_NAMES

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
    p.add_argument("manoeuvre", choices=tuple(_SIMULATE), help="trial to run")
    p.add_argument(
        "--model", default="nomoto1", choices=MODEL_NAMES, help="model (default: %(default)s)"
    )
    p.add_argument(
        "--angle-deg",
        type=_finite_float,
        default=None,
        metavar="A",
        help="rudder angle [deg]: zigzag a (20), turning (35), pull-out (20), largest "
        "angle of the direct spiral (20)",
    )
    p.add_argument(
        "--heading-deg",
        type=_finite_float,
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
        type=_positive_int,
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
        "--dt", type=_finite_float, default=None, metavar="S", help="integration step [s]"
    )
    p.add_argument("--json", default=None, metavar="OUT", help="write the results as JSON")
    p.add_argument("--plot", default=None, metavar="OUT.png", help="write the standard figure")
    p.set_defaults(handler=_run_simulate)


#: Subcommand name -> builder. Planned: identify, train, benchmark.
# ------------------------------------------------------------------------------------------
# evaluate
# ------------------------------------------------------------------------------------------
def _run_evaluate(args: argparse.Namespace) -> int:
    import json

    from shipgym.benchmark import evaluate, make_policy
    from shipgym.benchmark.plots import plot_result

    policy = make_policy(args.controller, args.env)
    result = evaluate(
        args.env,
        policy,
        args.controller,
        episodes=args.episodes,
        seed=args.seed,
        env_kwargs={}
        if args.max_current_speed is None
        else {"max_current_speed": args.max_current_speed},
    )
    summary = result.to_dict()
    print(
        f"{args.env} controller {args.controller}: {args.episodes} episodes from seed {args.seed}"
    )
    print(f"  return {summary['mean_return']:.2f} +- {summary['std_return']:.2f}")
    for key, value in summary["metrics"].items():
        print(f"  {key:22s} {value:10.3f} +- {summary['metrics_std'][key]:.3f}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(summary, fh, indent=2)
        print(f"wrote {args.json}")
    if args.plot:
        for path in plot_result(result, args.plot, max_episodes=args.episodes):
            print(f"wrote {path}")
    return 0


def _build_evaluate(sub: Any) -> None:
    from shipgym.benchmark.policies import POLICIES
    from shipgym.envs import ENV_IDS

    p = sub.add_parser(
        "evaluate",
        help="run a controller on an env over seeded episodes and report the task metrics",
        description=(
            "Run the classic controller (or the zero baseline) of an env for N episodes with "
            "seeds S, S+1, ... (identical initial states, setpoints, paths, targets and "
            "currents for every controller) and print the mean return and the task metrics."
        ),
    )
    p.add_argument("--env", required=True, choices=ENV_IDS, help="environment id")
    p.add_argument("--controller", default="classic", choices=POLICIES, help="%(default)s")
    p.add_argument("--episodes", type=_positive_int, default=10, metavar="N")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="first seed (%(default)s)")
    p.add_argument(
        "--max-current-speed",
        type=_finite_float,
        default=None,
        metavar="M_S",
        help="upper end of the drawn current speed [m/s] (default: the env's)",
    )
    p.add_argument("--json", default=None, metavar="OUT", help="write the summary as JSON")
    p.add_argument(
        "--plot", default=None, metavar="DIR", help="write a figure per episode into DIR"
    )
    p.set_defaults(handler=_run_evaluate)


SUBCOMMANDS: dict[str, Builder] = {
    "demo": _build_demo,
    "bench": _build_bench,
    "envs": _build_envs,
    "simulate": _build_simulate,
    "evaluate": _build_evaluate,
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

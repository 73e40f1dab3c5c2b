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

Each subcommand is registered by a builder in ``SUBCOMMANDS`` (name -> function that adds its
parser and sets ``handler``). Bad input ends with a one-line message and exit code 2
(argparse's own message for bad arguments, ``shipgym: error: ...`` for a ``ValueError`` raised
by the library), never a traceback. Heavy imports happen inside the handlers, so
``shipgym --help`` is fast.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from shipgym._io import write_atomically

PROG = "shipgym"
Handler = Callable[[argparse.Namespace], int]
Builder = Callable[["argparse._SubParsersAction[argparse.ArgumentParser]"], None]


def _int_in(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: an integer in ``[lo, hi]`` (a bound on every count and seed, so that
    no flag can ask for an unbounded allocation)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"must be an integer in [{lo}, {hi:,}], got {text!r}")
        return value

    return parse


def _float_in(lo: float, hi: float, unit: str) -> Callable[[str], float]:
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


# ------------------------------------------------------------------------------------------
# demo
# ------------------------------------------------------------------------------------------
def _run_demo(args: argparse.Namespace) -> int:
    from shipgym.demo import format_summary, run_demo

    out = _output_dir(args.out, "--out")
    print(
        f"running the shipgym demo (zigzag 20/20 with {args.model}, path following) ...", flush=True
    )
    summary = run_demo(out, model=args.model)
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

    json_path = _output_path(args.json, "--json", ".json")
    plot_path = _output_path(args.plot, "--plot", ".png")
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
    write_atomically(outputs)
    for target, _ in outputs:
        print(f"wrote {target}")
    return 0


def _build_bench(sub: Any) -> None:
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
        type=_int_in(1, 10**8),
        default=DEFAULT_STEPS,
        metavar="N",
        help="timed single-env steps per repeat (default: %(default)s)",
    )
    p.add_argument(
        "--num-envs",
        type=_int_in(1, 10**6),
        default=DEFAULT_NUM_ENVS,
        metavar="N",
        help="vector env batch size (default: %(default)s)",
    )
    p.add_argument(
        "--repeats",
        type=_int_in(1, 1000),
        default=DEFAULT_REPEATS,
        metavar="N",
        help=(
            "rounds, each timing every measurement once; a ratio is the median over the "
            "rounds of the ratio to CartPole in the same round (default: %(default)s)"
        ),
    )
    p.add_argument(
        "--vec-steps",
        type=_int_in(1, 10**8),
        default=None,
        metavar="N",
        help="timed vector steps per repeat (default: max(5, steps // 200))",
    )
    p.add_argument(
        "--busy",
        type=_int_in(0, 64),
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
    res = mv.zigzag(args.ship, a, args.heading_deg, args.side or "starboard", n, dt=args.dt)
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
    res = mv.turning_circle(args.ship, a, args.side or "starboard", dt=args.dt)
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
    res = mv.pullout(args.ship, a, args.side or "starboard", dt=args.dt)
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
    results = [mv.spiral(args.ship, rudders, k, dt=args.dt, progress=_progress) for k in kinds]
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
    report = mv.imo_criteria(args.ship, dt=args.dt, progress=_progress)
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


def _model_name(text: str) -> str:
    """``--model``: a model name or a model file ``*.json`` (read by the handler)."""
    from shipgym.models import MODEL_NAMES

    if text in MODEL_NAMES or text.lower().endswith(".json"):
        return text
    raise argparse.ArgumentTypeError(
        f"must be one of {', '.join(MODEL_NAMES)} or a model file FIT.json, got {text!r}"
    )


def _run_simulate(args: argparse.Namespace) -> int:
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
    json_path = _output_path(args.json, "--json", ".json")
    plot_path = _output_path(args.plot, "--plot", ".png")
    from shipgym.models import make_model
    from shipgym.models.model_file import is_model_file
    from shipgym.models.rvg import RVG_PARAMETER_SETS

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
        args.ship = make_model("rvg3dof", args.params)
    elif args.params is not None:
        raise ValueError(
            f"--params selects an rvg3dof parameter set or a fitted vmm, not one of {args.model!r}"
        )
    else:
        args.ship = args.model
    params = f" --params {args.params}" if args.params else ""
    print(f"shipgym simulate {kind} --model {args.model}{params} ...", file=sys.stderr, flush=True)
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
    write_atomically(outputs)
    for target, _ in outputs:
        print(f"wrote {target}")
    return 0


def _build_simulate(sub: Any) -> None:
    from shipgym.models import MODEL_NAMES
    from shipgym.models.rvg import RVG_PARAMETER_SETS

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
        "--model",
        default="nomoto1",
        type=_model_name,
        metavar="NAME|FIT.json",
        help=f"model: one of {', '.join(MODEL_NAMES)} or an identified model file "
        "(shipgym identify --json FIT.json); default %(default)s",
    )
    p.add_argument(
        "--params",
        default=None,
        metavar="SET|FIT.json",
        help=f"rvg3dof parameter set ({' or '.join(RVG_PARAMETER_SETS)}; default seed001); for "
        "vmm the model file of a fit (shipgym identify --model vmm:<term set> --json FIT.json)",
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
        type=_int_in(1, 100),
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
        type=_float_in(1e-3, 60.0, "s"),
        default=None,
        metavar="S",
        help="integration step [s]",
    )
    p.add_argument("--json", default=None, metavar="OUT", help="write the results as JSON")
    p.add_argument("--plot", default=None, metavar="OUT.png", help="write the standard figure")
    p.set_defaults(handler=_run_simulate)


# ------------------------------------------------------------------------------------------
# evaluate
# ------------------------------------------------------------------------------------------
def _ray_address(text: str) -> str:
    """``--ray``: ``local`` (Ray on this machine), ``auto`` or ``[ray://]host:port``."""
    from shipgym.cluster import parse_address

    try:
        address = parse_address(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("bad Ray address ")) from None
    return "local" if address is None else address


def _add_ray_flags(p: argparse.ArgumentParser, what: str) -> None:
    """``--ray [ADDRESS]``, ``--ray-cpus N`` and ``--task-episodes N``."""
    p.add_argument(
        "--ray",
        nargs="?",
        const="local",
        default=None,
        type=_ray_address,
        metavar="ADDRESS",
        help=f"run the {what} as Ray tasks: without ADDRESS on a Ray started on this machine, "
        "with HOST:PORT (as 'ray start --head' prints it) or 'auto' on that cluster; the "
        "results are those of a local run",
    )
    p.add_argument(
        "--ray-cpus",
        type=_int_in(1, 4096),
        default=None,
        metavar="N",
        help="CPUs of the local Ray started by --ray (default: every core)",
    )
    p.add_argument(
        "--task-episodes",
        type=_int_in(1, MAX_EPISODES),
        default=None,
        metavar="N",
        help="episodes per Ray task (default: about four tasks per CPU of the cluster)",
    )


def _ray_options(args: argparse.Namespace) -> tuple[str | None, int | None, int | None] | None:
    """``(address or None for a local Ray, CPUs, episodes per task)`` of ``--ray``, or None
    without it; refuses the Ray flags that do not go together."""
    if args.ray is None:
        for flag, value in (("--ray-cpus", args.ray_cpus), ("--task-episodes", args.task_episodes)):
            if value is not None:
                raise ValueError(f"{flag} goes with --ray (the episodes run as Ray tasks)")
        return None
    address = None if args.ray == "local" else args.ray
    if address is not None and args.ray_cpus is not None:
        raise ValueError(
            f"--ray-cpus is for a Ray started on this machine (--ray without an address); the "
            f"cluster at {address} has its own CPUs"
        )
    return address, args.ray_cpus, args.task_episodes


def _campaign_failed(exc: Exception) -> int:
    """Print a failed episode or Ray task (its message names env, controller, condition
    and seed) as one line; exit code 1."""
    print(f"{PROG}: error: {exc}", file=sys.stderr)
    return 1


def _run_evaluate(args: argparse.Namespace) -> int:
    import json

    from shipgym.benchmark import evaluate, make_policy
    from shipgym.benchmark.evaluate import BLOW_UP, EpisodeError
    from shipgym.benchmark.plots import episode_figures
    from shipgym.cluster import ClusterTaskError

    json_path = _output_path(args.json, "--json", ".json")
    plot_dir = None if args.plot is None else _output_dir(args.plot, "--plot")
    ray = _ray_options(args)
    if args.gains is not None:
        from shipgym.benchmark.policies import GAINS_ENV

        if args.controller != "classic" or args.env != GAINS_ENV:
            raise ValueError(
                f"--gains sets the classic heading autopilot of {GAINS_ENV}: use it with "
                f"--env {GAINS_ENV} --controller classic, not --env {args.env} --controller "
                f"{args.controller}"
            )
        if ray is not None:
            raise ValueError("--gains runs the episodes here; drop --ray")
    env_kwargs: dict[str, Any] = {}
    if args.max_current_speed is not None:
        env_kwargs["max_current_speed"] = args.max_current_speed
    if args.model is not None:
        from shipgym.benchmark.policies import GAINS_ENV

        if args.env != GAINS_ENV:
            raise ValueError(
                f"--model sets the ship of {GAINS_ENV} (a Nomoto-family model or an identified "
                f"model file); {args.env} sails its own ship"
            )
        env_kwargs["model"] = args.model
    policy = make_policy(args.controller, args.env, args.agents, gains=args.gains, model=args.model)
    if hasattr(policy, "meta"):
        from shipgym.benchmark.runner import check_seeds_disjoint

        try:
            check_seeds_disjoint(policy.meta, args.seed, args.episodes)
        except ValueError as exc:
            print(f"{PROG}: warning: {exc}", file=sys.stderr)
    try:
        if ray is None:
            result = evaluate(
                args.env,
                policy,
                args.controller,
                episodes=args.episodes,
                seed=args.seed,
                env_kwargs=env_kwargs,
            )
        else:
            from shipgym.benchmark.runner import evaluate_on_ray

            address, cpus, task_size = ray
            result = evaluate_on_ray(
                args.env,
                args.controller,
                args.episodes,
                args.seed,
                address=address,
                num_cpus=cpus,
                task_size=task_size,
                env_kwargs=env_kwargs,
                agents_dir=args.agents,
                keep_logs=None if plot_dir is not None else 0,
                design_model=args.model,
            )
    except (EpisodeError, ClusterTaskError) as exc:
        return _campaign_failed(exc)
    summary = result.to_dict()
    print(
        f"{args.env} controller {args.controller}: {args.episodes} episodes from seed {args.seed}"
    )
    if result.blown_up:
        ends = zip(result.lengths, result.terminations, strict=True)
        steps = [n for n, reason in ends if reason == BLOW_UP]
        print(
            f"  BLEW UP: {result.blown_up} of {args.episodes} episodes ended in a numerical "
            f"blow-up (at steps {', '.join(map(str, steps[:10]))}"
            f"{', ...' if len(steps) > 10 else ''}); return and metrics undefined"
        )
    else:
        print(f"  return {summary['mean_return']:.2f} +- {summary['std_return']:.2f}")
        for key, value in summary["metrics"].items():
            print(f"  {key:22s} {value:10.3f} +- {summary['metrics_std'][key]:.3f}")
    outputs: list[tuple[Path, Callable[[Path], Any]]] = []
    if json_path is not None:
        outputs.append((json_path, lambda p: p.write_text(json.dumps(summary, indent=2) + "\n")))
    if plot_dir is not None:
        outputs += episode_figures(result, plot_dir, max_episodes=args.episodes)
    write_atomically(outputs)
    for target, _ in outputs:
        print(f"wrote {target}")
    return 0


def _build_evaluate(sub: Any) -> None:
    from shipgym.benchmark.policies import POLICIES
    from shipgym.envs import ENV_IDS

    p = sub.add_parser(
        "evaluate",
        help="run a controller on an env over seeded episodes and report the task metrics",
        description=(
            "Run the classic controller, a trained PPO or SAC agent or the zero command on an "
            "env for N episodes with seeds S, S+1, ... (identical initial states, setpoints, "
            "paths, targets and currents for every controller) and print the mean return and "
            "the task metrics."
        ),
    )
    p.add_argument("--env", required=True, choices=ENV_IDS, help="environment id")
    p.add_argument("--controller", default="classic", choices=POLICIES, help="%(default)s")
    p.add_argument("--episodes", type=_int_in(1, MAX_EPISODES), default=10, metavar="N")
    p.add_argument(
        "--seed", type=_int_in(0, MAX_SEED), default=0, metavar="S", help="first seed (%(default)s)"
    )
    p.add_argument(
        "--agents",
        default=None,
        metavar="DIR",
        help="folder of the ppo/sac agents (default: the agents shipped with shipgym)",
    )
    p.add_argument(
        "--max-current-speed",
        type=_float_in(0.0, 5.0, "m/s"),
        default=None,
        metavar="M_S",
        help="upper end of the drawn current speed [m/s] (default: the env's)",
    )
    p.add_argument(
        "--gains",
        default=None,
        metavar="FILE",
        help="gains of the classic NomotoHeading autopilot (shipgym design MODEL.json --json "
        "FILE) instead of the design rule on the nominal ship",
    )
    p.add_argument(
        "--model",
        default=None,
        type=_model_name,
        metavar="NAME|FIT.json",
        help="the ship of shipgym/NomotoHeading-v0: a Nomoto-family model or an identified "
        "model file (shipgym identify --json FIT.json); the classic controllers are designed "
        "on it (default: the env's)",
    )
    p.add_argument("--json", default=None, metavar="OUT", help="write the summary as JSON")
    p.add_argument(
        "--plot", default=None, metavar="DIR", help="write a figure per episode into DIR"
    )
    _add_ray_flags(p, "episodes")
    p.set_defaults(handler=_run_evaluate)


# ------------------------------------------------------------------------------------------
# train
# ------------------------------------------------------------------------------------------
#: Flags that ``--resume`` takes from the record and so refuses (dest -> flag).
_RESUME_FIXED = {
    "seed": "--seed",
    "num_envs": "--num-envs",
    "eval_freq": "--eval-freq",
    "eval_episodes": "--eval-episodes",
    "sweep": "--sweep",
    "seeds": "--seeds",
    "ray": "--ray",
}


def _seed_list(text: str) -> list[int]:
    """An argparse type: comma-separated seeds, e.g. ``0,1,2``."""
    seeds = []
    for part in text.split(","):
        try:
            seed = int(part)
        except ValueError:
            seed = -1
        if not 0 <= seed <= MAX_SEED:
            raise argparse.ArgumentTypeError(
                f"must be comma-separated integers in [0, {MAX_SEED:,}], got {part!r} in {text!r}"
            )
        seeds.append(seed)
    if len(set(seeds)) != len(seeds):
        raise argparse.ArgumentTypeError(f"repeats a seed: {text!r}")
    return seeds


def _tensorboard_option(args: argparse.Namespace) -> str | bool:
    if args.no_tensorboard:
        return False
    return True if args.tensorboard is None else str(_output_dir(args.tensorboard, "--tensorboard"))


def _interrupted(out: Path, env_id: str | None, algo: str | None) -> int:
    """Say what an interrupted training left and how to continue it; exit code 130."""
    from shipgym.rl.checkpoints import resumable

    found = resumable(out)
    names = [
        n
        for n in found
        if env_id is None
        or algo is None
        or n == f"{env_id.split('/')[-1]}-{algo}"  # the agent of this command only
    ]
    if names:
        print(
            f"{PROG}: interrupted; the best agent so far is in {out} (record marked partial), "
            f"the latest checkpoint in {found[names[0]]}; continue with: "
            f"{PROG} train --resume {out}",
            file=sys.stderr,
        )
    else:
        print(
            f"{PROG}: interrupted before the first evaluation; nothing was saved", file=sys.stderr
        )
    return 130


def _run_train(args: argparse.Namespace) -> int:
    import signal
    import threading

    if args.ray is not None or args.sweep is not None or args.seeds is not None:
        return _run_train_sweep(args)
    if args.ray_cpus is not None:
        raise ValueError("--ray-cpus goes with --ray (a sweep on a Ray started on this machine)")
    if args.resume is not None:
        given = [flag for dest, flag in _RESUME_FIXED.items() if getattr(args, dest) is not None]
        if args.overwrite:
            given.append("--overwrite")
        if given:
            raise ValueError(
                f"--resume continues with the settings of the training's record; {given[0]} "
                "cannot be given with it (allowed: --env, --algo, --timesteps, --tensorboard, "
                "--no-tensorboard, --quiet)"
            )
        out = Path(args.resume)
    else:
        if args.env is None or args.algo is None:
            raise ValueError(
                "--env and --algo are required (or --resume DIR to continue a training)"
            )
        out = _output_dir(args.out, "--out")
    tensorboard = _tensorboard_option(args)
    bar = not args.quiet and sys.stderr.isatty()
    progress = None if (bar or args.quiet) else _progress
    # the first Ctrl-C or SIGTERM (a batch system's stop, kill) evaluates and checkpoints the
    # policy of that step and stops; a second one stops at once (the last checkpoint stays)
    stop = threading.Event()

    def on_signal(signum: int, frame: Any) -> None:
        if stop.is_set():
            raise KeyboardInterrupt
        stop.set()
        print(
            f"{PROG}: stopping: saving the policy of this step (interrupt again to stop at once)",
            file=sys.stderr,
            flush=True,
        )

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        if args.resume is not None:
            from shipgym.rl.train import resume

            result = resume(
                out,
                args.env,
                args.algo,
                timesteps=args.timesteps,
                progress_bar=bar,
                progress=_progress if not args.quiet else None,
                tensorboard_log=tensorboard,
                stop=stop,
            )
        else:
            from shipgym.rl.train import config, train

            cfg = config(args.env, args.algo)
            timesteps = args.timesteps or cfg["timesteps"]
            print(
                f"training {args.algo} on {args.env}: {timesteps} steps, seed {args.seed or 0}, "
                f"{args.num_envs or cfg['num_envs']} sub-envs, into {args.out}",
                flush=True,
            )
            result = train(
                args.env,
                args.algo,
                timesteps=timesteps,
                seed=args.seed or 0,
                out_dir=out,
                num_envs=args.num_envs,
                eval_freq=args.eval_freq,
                eval_episodes=args.eval_episodes or 16,
                progress_bar=bar,
                progress=progress,
                tensorboard_log=tensorboard,
                overwrite=args.overwrite,
                stop=stop,
            )
    except KeyboardInterrupt:
        return _interrupted(out, args.env, args.algo)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    meta = result.meta
    print(
        f"{meta['name']}: {meta['timesteps']} steps in {meta['wall_time_s']:.0f} s "
        f"({meta['steps_per_s']:.0f} steps/s); best validation return "
        f"{meta['best_validation_return']:.1f} at step {meta['best_timestep']}"
    )
    print(f"wrote {result.model_path} and {result.meta_path}")
    if meta.get("tensorboard_run") and tensorboard is not False:
        logdir = out / "tensorboard" if tensorboard is True else Path(tensorboard)
        print(f"TensorBoard: tensorboard --logdir {logdir}")
    return 0


def _run_train_sweep(args: argparse.Namespace) -> int:
    if args.ray is None:
        flag = "--sweep" if args.sweep is not None else "--seeds"
        raise ValueError(
            f"{flag} runs trials on Ray: add --ray (a Ray on this machine) or --ray ADDRESS"
        )
    for dest, flag in (("resume", "--resume"), ("seed", "--seed"), ("overwrite", "--overwrite")):
        if getattr(args, dest) not in (None, False):
            hint = " (a sweep resumes its unfinished trials by itself)" if dest == "resume" else ""
            hint = hint or (" (use --seeds S1,S2,...)" if dest == "seed" else "")
            raise ValueError(f"{flag} does not go with --ray{hint}")
    if args.no_tensorboard or args.tensorboard is not None:
        raise ValueError(
            "a sweep writes each trial's TensorBoard run into the trial's folder; "
            "--tensorboard/--no-tensorboard do not go with --ray"
        )
    from shipgym.rl.sweep import load_sweep, run_sweep

    address = None if args.ray == "local" else args.ray
    if address is not None and args.ray_cpus is not None:
        raise ValueError(
            f"--ray-cpus is for a Ray started on this machine (--ray without an address); the "
            f"cluster at {address} has its own CPUs"
        )
    spec = load_sweep(
        args.sweep,
        env=args.env,
        algo=args.algo,
        timesteps=args.timesteps,
        num_envs=args.num_envs,
        eval_freq=args.eval_freq,
        eval_episodes=args.eval_episodes,
        seeds=args.seeds,
    )
    out = _output_dir(args.out, "--out")
    try:
        result = run_sweep(
            spec,
            out,
            address=address,
            num_cpus=args.ray_cpus,
            progress=None if args.quiet else _progress,
        )
    except KeyboardInterrupt:
        print(
            f"{PROG}: interrupted; every trial keeps its best agent and latest checkpoint under "
            f"{out / 'trials'}; the same command continues the unfinished ones",
            file=sys.stderr,
        )
        return 130
    for line in result.table():
        print(line)
    for path in result.outputs:
        print(f"wrote {path}")
    return 0 if not result.failed else 1


def _build_train(sub: Any) -> None:
    from shipgym.envs import ENV_IDS
    from shipgym.rl.train import ALGOS

    p = sub.add_parser(
        "train",
        help="train a PPO or SAC agent (stable-baselines3) on an env, or a sweep on Ray",
        description=(
            "Train a stable-baselines3 agent on the NumPy-batched vector env (one kernel call "
            "steps every sub-env), with observation normalisation and an evaluation callback "
            "on fixed validation seeds that keeps the best policy. Writes DIR/<name>.zip and "
            "DIR/<name>.json (budget, seeds, wall time, learning curve, normaliser) at every "
            "evaluation (the best policy so far, its record marked partial until the end), the "
            "latest state in DIR/checkpoints/<name>/latest (continue it with --resume DIR) "
            "and TensorBoard logs in DIR/tensorboard. With --ray, trains one agent per "
            "configuration of a --sweep file and seed of --seeds as Ray Tune trials, each in "
            "its own folder under DIR/trials, and writes a summary table and figure. Needs "
            "the rl extra (pip install 'shipgym[rl]'); --ray the cluster extra."
        ),
    )
    p.add_argument("--env", default=None, choices=ENV_IDS, help="environment id")
    p.add_argument("--algo", default=None, choices=ALGOS, help="algorithm")
    p.add_argument(
        "--timesteps",
        type=_int_in(1, 10**9),
        default=None,
        metavar="N",
        help="environment steps (default: the shipped agent's budget; with --resume the new "
        "total, default the recorded one)",
    )
    p.add_argument(
        "--seed",
        type=_int_in(0, MAX_SEED),
        default=None,
        metavar="S",
        help="seed of the networks; training sub-env i gets S + i (default 0)",
    )
    p.add_argument("--out", default="shipgym-agents", metavar="DIR", help="%(default)s")
    p.add_argument(
        "--num-envs",
        type=_int_in(1, 65536),
        default=None,
        metavar="N",
        help="training sub-envs (default: 16 for PPO, 8 for SAC)",
    )
    p.add_argument(
        "--eval-freq",
        type=_int_in(1, 10**9),
        default=None,
        metavar="N",
        help="env steps between evaluations and checkpoints (default: 1/20 of the budget; "
        "PPO: at least a rollout)",
    )
    p.add_argument(
        "--eval-episodes",
        type=_int_in(1, 10**4),
        default=None,
        metavar="N",
        help="validation episodes per evaluation (default 16)",
    )
    p.add_argument(
        "--resume",
        default=None,
        metavar="DIR",
        help="continue the training in DIR from its latest checkpoint (env, algorithm and "
        "hyperparameters from its record; --env/--algo pick one if DIR holds several)",
    )
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="start over even if DIR holds an unfinished training of this agent",
    )
    p.add_argument(
        "--tensorboard",
        default=None,
        metavar="DIR",
        help="folder of the TensorBoard runs (default: tensorboard/ in the output folder)",
    )
    p.add_argument("--no-tensorboard", action="store_true", help="write no TensorBoard logs")
    p.add_argument(
        "--ray",
        nargs="?",
        const="local",
        default=None,
        type=_ray_address,
        metavar="ADDRESS",
        help="run a sweep as Ray Tune trials: without ADDRESS on a Ray started on this machine, "
        "with HOST:PORT (as 'ray start --head' prints it) or 'auto' on that cluster (DIR must "
        "then be on a filesystem every node sees)",
    )
    p.add_argument(
        "--ray-cpus",
        type=_int_in(1, 4096),
        default=None,
        metavar="N",
        help="CPUs of the local Ray started by --ray (default: every core); one per trial",
    )
    p.add_argument(
        "--sweep",
        default=None,
        metavar="FILE",
        help="YAML or JSON file of hyperparameter choices (a grid; see the README)",
    )
    p.add_argument(
        "--seeds",
        type=_seed_list,
        default=None,
        metavar="S1,S2,...",
        help="with --ray: train every configuration once per seed (default: 0)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(handler=_run_train)


# ------------------------------------------------------------------------------------------
# benchmark
# ------------------------------------------------------------------------------------------
def _benchmark_plan(args: argparse.Namespace, say: Callable[[str], None]) -> None:
    """The benchmark's first line, before anything heavy is imported or compiled: what it runs."""
    from shipgym.benchmark.runner import CONDITIONS, CONTROLLERS, benchmark_cells
    from shipgym.envs import CURRENT_ENV_IDS

    envs = args.env or CURRENT_ENV_IDS
    controllers = args.controller or CONTROLLERS
    conditions = args.condition or CONDITIONS
    cells = len(benchmark_cells(envs, controllers, conditions))

    def n(count: int, word: str) -> str:
        return f"{count:,} {word}{'s' * (count != 1)}"

    say(
        f"shipgym benchmark: {n(cells, 'evaluation')} of {n(args.episodes, 'episode')} "
        f"({n(cells * args.episodes, 'episode')}: {n(len(envs), 'env')}, "
        f"{n(len(controllers), 'controller')}, {n(len(conditions), 'condition')})"
        + (" on Ray" if args.ray is not None else "")
        + (", then PPO's training throughput" if args.throughput else "")
    )
    if args.no_throughput:
        say("--no-throughput is the default now (--throughput measures PPO's throughput)")


def _benchmark_kernels(args: argparse.Namespace, say: Callable[[str], None]) -> None:
    """From a cold kernel cache, say so and compile the kernels the benchmark needs, at once in
    one process per part, so that its evaluation processes load them rather than each compiling
    them."""
    import time

    from shipgym.models._jit import CACHE_DIR
    from shipgym.warmup import BENCHMARK_GROUPS, cold_parts, compile_estimate_s, warm_cache

    if not CACHE_DIR:
        say("kernel cache off (SHIPGYM_NO_CACHE): every process compiles the kernels it uses")
        return
    if args.ray not in (None, "local") or not any(cold_parts(g) for g in BENCHMARK_GROUPS):
        return  # warm, or the episodes run on a cluster's own machines
    estimate = compile_estimate_s(BENCHMARK_GROUPS)
    say(f"compiling the kernels (first run only, about {max(10, round(estimate, -1)):.0f} s)")
    t0 = time.perf_counter()
    if warm_cache(BENCHMARK_GROUPS, say=say):
        say(f"kernels compiled in {time.perf_counter() - t0:.0f} s")
    else:
        say("compiling the kernels ahead failed; each evaluation compiles what it uses")


def _run_benchmark(args: argparse.Namespace) -> int:
    ray = _ray_options(args)
    if ray is not None and args.jobs is not None:
        raise ValueError(
            "--jobs sets the local process pool; with --ray the Ray cluster's CPUs run the "
            "episodes (--ray-cpus for a Ray started on this machine)"
        )
    out = _output_dir(args.out, "--out")
    json_path = _output_path(args.json, "--json", ".json") or out / "benchmark.json"
    csv_path = _output_path(args.csv, "--csv", ".csv") or out / "benchmark.csv"
    plots = _output_dir(args.plots, "--plots") if args.plots else out
    progress = (lambda line: None) if args.quiet else _progress
    _benchmark_plan(args, progress)
    _benchmark_kernels(args, progress)

    import json

    from shipgym.benchmark.evaluate import EpisodeError
    from shipgym.benchmark.plots import (
        plot_benchmark_metrics,
        plot_benchmark_robustness,
        plot_benchmark_trajectories,
        plot_throughput,
    )
    from shipgym.benchmark.runner import CONDITIONS, run_benchmark
    from shipgym.benchmark.throughput import ppo_throughput, throughput_table
    from shipgym.cluster import ClusterTaskError

    envs = args.env or None
    controllers = args.controller or None
    kwargs: dict[str, Any] = {}
    if envs:
        kwargs["envs"] = envs
    if controllers:
        kwargs["controllers"] = controllers
    if ray is not None:
        address, cpus, task_size = ray
        kwargs.update(ray=address or True, ray_cpus=cpus, task_size=task_size)
    try:
        result = run_benchmark(
            episodes=args.episodes,
            seed=args.seed,
            conditions=args.condition or CONDITIONS,
            agents_dir=args.agents,
            progress=progress,
            jobs=args.jobs,
            **kwargs,
        )
    except (EpisodeError, ClusterTaskError) as exc:
        return _campaign_failed(exc)
    print(result.table())
    print(f"({result.runtime_s:.0f} s)")
    outputs: list[tuple[Path, Callable[[Path], Any]]] = [
        (json_path, result.write_json),
        (csv_path, result.write_csv),
        (plots / "metrics.png", lambda p: plot_benchmark_metrics(result, p)),
    ]
    if len(result.conditions) > 1:
        outputs.append((plots / "robustness.png", lambda p: plot_benchmark_robustness(result, p)))
    for env_id in result.envs:
        outputs.append(
            (
                plots / f"{env_id.split('/')[-1]}.png",
                lambda p, env_id=env_id: plot_benchmark_trajectories(result, env_id, p),
            )
        )
    write_atomically(outputs)
    for target, _ in outputs:
        print(f"wrote {target}")
    if args.throughput:
        rows = ppo_throughput(result.envs, timesteps=args.throughput_steps, progress=progress)
        print(throughput_table(rows))
        outputs = [
            (out / "throughput.json", lambda p: p.write_text(json.dumps(rows, indent=2) + "\n")),
            (plots / "throughput.png", lambda p: plot_throughput(rows, p)),
        ]
        write_atomically(outputs)
        for target, _ in outputs:
            print(f"wrote {target}")
    return 0


def _build_benchmark(sub: Any) -> None:
    from shipgym.benchmark.runner import CONDITIONS, CONTROLLERS
    from shipgym.envs import ENV_IDS
    from shipgym.rl.train import BENCHMARK_SEED

    p = sub.add_parser(
        "benchmark",
        help="classic controllers (design-rule and tuned gains) vs the PPO/SAC agents vs zero",
        description=(
            "Evaluate the classic controller with its design-rule gains and with its tuned "
            "gains, the shipped PPO and SAC agents and the zero command on the newest version "
            "of every env with identical seeds and current draws (seeds disjoint from the "
            "agents' training and validation seeds and from the tuning seeds), in the nominal "
            "condition and under stress (1.5 x the training current), model mismatch, sensor "
            "noise and an actuator delay. Prints a table of mean +- std of each metric, "
            "writes JSON (a list of 'shipgym evaluate' objects with per-episode values and "
            "bootstrap 95 %% intervals) and CSV, figures of metrics, robustness and "
            "trajectories; with --throughput also PPO's training throughput on each env "
            "against CartPole-v1."
        ),
    )
    p.add_argument(
        "--episodes",
        type=_int_in(1, MAX_EPISODES),
        default=100,
        metavar="N",
        help="episodes per env, controller and condition (%(default)s)",
    )
    p.add_argument(
        "--seed",
        type=_int_in(0, MAX_SEED),
        default=BENCHMARK_SEED,
        metavar="S",
        help="first seed (%(default)s)",
    )
    p.add_argument("--out", default="shipgym-benchmark", metavar="DIR", help="%(default)s")
    p.add_argument("--json", default=None, metavar="OUT", help="default: DIR/benchmark.json")
    p.add_argument("--csv", default=None, metavar="OUT", help="default: DIR/benchmark.csv")
    p.add_argument("--plots", default=None, metavar="DIR", help="figures (default: --out)")
    p.add_argument(
        "--env",
        action="append",
        choices=ENV_IDS,
        default=None,
        metavar="ID",
        help="only this env (repeatable; default: the newest version of each)",
    )
    p.add_argument(
        "--controller",
        action="append",
        choices=CONTROLLERS,
        default=None,
        help="only this controller (repeatable; default: all)",
    )
    p.add_argument(
        "--agents",
        default=None,
        metavar="DIR",
        help="folder of the ppo/sac agents (default: the shipped ones)",
    )
    p.add_argument(
        "--condition",
        action="append",
        choices=CONDITIONS,
        default=None,
        help="only this condition (repeatable; default: all)",
    )
    throughput = p.add_mutually_exclusive_group()
    throughput.add_argument(
        "--throughput",
        action="store_true",
        help=(
            "after the evaluations, measure PPO's training throughput on each env against "
            "CartPole-v1 in interleaved rounds, with the machine's load (minutes; needs an idle "
            "machine to be comparable)"
        ),
    )
    throughput.add_argument(
        "--no-throughput",
        action="store_true",
        help="the default now (accepted for older scripts)",
    )
    p.add_argument(
        "--throughput-steps",
        type=_int_in(1, 10**8),
        default=16_384,
        metavar="N",
        help="with --throughput: timed PPO steps per env and run (%(default)s)",
    )
    p.add_argument(
        "--jobs",
        type=_int_in(1, 1024),
        default=None,
        metavar="N",
        help="evaluations at once, one process each (default: one per core)",
    )
    _add_ray_flags(p, "evaluations' episodes")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.set_defaults(handler=_run_benchmark)


# ------------------------------------------------------------------------------------------
# identify
# ------------------------------------------------------------------------------------------
# parameter name -> unit (the Nomoto family and the effects' own parameters; others unitless)
_PARAM_UNITS: dict[str, str] = {
    "K": "1/s",
    "T": "s",
    "T1": "s",
    "T2": "s",
    "T3": "s",
    "T_d": "s",
    "tau": "s",
    "delta0": "rad",
    "b0": "rad",
    "alpha_0": "rad",
    "n0": "rad/s",
    "n1": "-",
    "n2": "s",
    "n3": "s^2",
    "b1": "s",
    "b2": "s^2",
    "b3": "s^3",
    "V_n": "m/s",
    "V_e": "m/s",
    "speed": "m/s",
}


def _window(text: str) -> float | str | None:
    """``--window``: a positive number of seconds, ``auto`` or ``none``."""
    word = text.strip().lower()
    if word in ("auto", "none"):
        return None if word == "none" else "auto"
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 1.0 <= value <= 1e6):
        raise argparse.ArgumentTypeError(
            f"must be a number of seconds in [1, 1e6], 'auto' or 'none', got {text!r}"
        )
    return value


def _probe_directory(directory: Path, flag: str, target: str) -> None:
    """Create and remove a temporary file in ``directory``: can ``target`` be written there?"""
    import os
    import tempfile

    try:
        fd, probe = tempfile.mkstemp(prefix=".shipgym-probe-", dir=directory)
    except OSError as exc:
        raise ValueError(f"{flag}: cannot write {target!r}: {exc.strerror or exc}") from None
    os.close(fd)
    os.unlink(probe)


def _output_path(text: str | None, flag: str, suffix: str | None = None) -> Path | None:
    """Check an output file before the (possibly long) run; ``-`` and None pass.

    The file's directory must exist and take a new file (tried with a temporary file); an
    existing output must be a regular file, which is replaced.
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
    if not path.parent.is_dir():
        raise ValueError(f"{flag}: the directory {str(path.parent)!r} of {text!r} does not exist")
    _probe_directory(path.parent, flag, text)
    return path


def _output_dir(text: str, flag: str) -> Path:
    """Check an output directory before the run: an existing one that takes files, or a new
    one in an existing directory (created when the outputs are written, never its parents)."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{flag} names a file, expected a directory: {text!r}")
    if not path.exists() and not path.parent.is_dir():
        raise ValueError(f"{flag}: the directory {str(path.parent)!r} of {text!r} does not exist")
    _probe_directory(path if path.exists() else path.parent, flag, text)
    return path


def _format_value(name: str, value: Any, digits: int = 6, unit: bool = False) -> str:
    """``value`` with ``digits`` significant digits; angles [rad] also in degrees.

    ``unit``: append the unit of :data:`_PARAM_UNITS` (before the degrees).
    """
    if value is None:
        return "n/a"
    if isinstance(value, bool) or not isinstance(value, int | float):
        return str(value)
    text = f"{value:.{digits}g}"
    known = _PARAM_UNITS.get(name)
    if unit and known:
        text += f" {known}"
    if known == "rad" and math.isfinite(value):
        text += f" ({math.degrees(value):.4g} deg)"
    return text


def _param_label(name: str) -> str:
    unit = _PARAM_UNITS.get(name)
    return f"{name} [{unit}]" if unit else name


# record channel -> (unit shown, scale from SI) for per-channel evidence dicts
_CHANNEL_UNITS: dict[str, tuple[str, float]] = {
    "psi": ("deg", math.degrees(1.0)),
    "r": ("deg/s", math.degrees(1.0)),
    "u": ("m/s", 1.0),
    "v": ("m/s", 1.0),
    "x": ("m", 1.0),
    "y": ("m", 1.0),
}


def _format_pair(stem: str, before: Any, after: Any) -> str:
    """``"held-out psi RMS 3.701 -> 0.1023 deg"``; per-channel dicts give one item each."""
    from shipgym.sysid.plots import METRIC_LABELS

    where = "held-out " if stem.startswith("heldout_") else ""
    metric = stem.removeprefix("heldout_")
    if isinstance(before, dict) and isinstance(after, dict):  # {channel: value [SI]}
        items = []
        for ch in [*before, *(k for k in after if k not in before)]:
            unit, scale = _CHANNEL_UNITS.get(ch, ("", 1.0))
            b, a = before.get(ch), after.get(ch)
            b = b * scale if isinstance(b, int | float) else b
            a = a * scale if isinstance(a, int | float) else a
            items.append(
                f"{ch} {_format_value(ch, b, 4)} -> {_format_value(ch, a, 4)} {unit}".rstrip()
            )
        return f"{where}{metric.replace('_', ' ')}: " + ", ".join(items)
    label, unit = METRIC_LABELS.get(metric, (metric, ""))
    return (
        f"{where}{label} {_format_value(metric, before, 4)} -> "
        f"{_format_value(metric, after, 4)} {unit}".rstrip()
    )


def _format_evidence(evidence: dict[str, Any]) -> str:
    """One line per effect: BIC change, held-out metrics before -> after, other numbers."""
    parts = []
    done = set()
    if isinstance(evidence.get("delta_J"), int | float):
        parts.append(f"BIC change {evidence['delta_J']:+.1f}")
        done.add("delta_J")
    if isinstance(evidence.get("relative_drop"), int | float):
        parts.append(f"held-out RMS drop {100.0 * evidence['relative_drop']:.1f} %")
        done.add("relative_drop")
    for key in evidence:
        stem = key.removesuffix("_before")
        if key in done or stem == key or stem + "_after" not in evidence:
            continue
        parts.append(_format_pair(stem, evidence[key], evidence[stem + "_after"]))
        done |= {key, stem + "_after"}
    names = {"t_stat": "drift t statistic"}
    for key, value in evidence.items():
        if key not in done:
            parts.append(f"{names.get(key, key)} {_format_value(key, value, 4, unit=True)}")
    return "; ".join(parts)


def _identify_summary(result: Any, source: str) -> str:
    """The readable report of ``shipgym identify`` (the JSON holds the same numbers)."""
    from shipgym.sysid.plots import METRIC_LABELS, format_errors

    lines = [f"shipgym identify {source}", f"model: {result.model}"]
    selection = result.diagnostics.get("term_set_selection")
    if selection:  # vmm:auto: the term set that predicted the held-out runs best
        from shipgym.sysid.families.vmm import describe_selection

        lines.append(f"term set: {describe_selection(selection)}")
    verdict = result.verdict
    if verdict.identifiable:
        lines.append("verdict: identifiable")
    else:
        lines.append("verdict: NOT IDENTIFIABLE: the record does not determine this model:")
        lines.extend(f"  - {reason}" for reason in verdict.reasons)
    starts = result.traces.get("window_starts", [0]) if result.traces else [0]
    if "run" in (result.traces or {}):
        how = "each run simulated from its measured initial state"
        if result.window_s is not None:
            how += f", in windows of {result.window_s:g} s"
    elif result.window_s is None:
        how = "one free run from the estimated initial state"
    else:
        how = (
            f"{len(starts)} consecutive windows of {result.window_s:g} s, each started from the "
            "measured state"
        )
    lines.append(f"window: {'none' if result.window_s is None else f'{result.window_s:g} s'}")
    lines.append(f"simulation error over the whole record ({how}):")
    before, after = result.error_before, result.error_after
    keys = [*before, *(k for k in after if k not in before)]
    rows = [("", "before", "after")]
    for key in keys:
        label, unit = METRIC_LABELS.get(key, (key, ""))
        rows.append(
            (
                f"{label} [{unit}]" if unit else label,
                _format_value(key, before.get(key), 4),
                _format_value(key, after.get(key), 4),
            )
        )
    lines.extend(_table(rows))
    if result.effects:
        lines.append("effects added, in order:")
        for i, effect in enumerate(result.effects, start=1):
            params = ", ".join(
                f"{k} = {_format_value(k, v, unit=True)}"
                for k, v in effect.get("parameters", {}).items()
            )
            lines.append(f"  {i}. {effect['name']}: {params}")
            evidence = dict(effect.get("evidence", {}))
            candidate = evidence.pop("candidate_parameters", None)
            lines.append(f"     evidence: {_format_evidence(evidence)}")
            if candidate and candidate != effect.get("parameters"):
                text = ", ".join(
                    f"{k} = {_format_value(k, v, 4, unit=True)}" for k, v in candidate.items()
                )
                lines.append(f"     candidate when accepted (fit on the training part): {text}")
    else:
        lines.append("effects added: none (no candidate was significant on the held-out part)")
    p_before, p_after = result.parameters_before, result.parameters_after
    stderr = ((result.diagnostics or {}).get("final") or {}).get("stderr") or {}
    lines.append("parameters:")
    rows = [("", "before", "after", "std. error")]
    for name in [*p_before, *(k for k in p_after if k not in p_before)]:
        se = stderr.get(name)
        rows.append(
            (
                _param_label(name),
                _format_value(name, p_before[name]) if name in p_before else "-",
                _format_value(name, p_after[name]) if name in p_after else "-",
                _format_value(name, se, 2) if isinstance(se, float) and math.isfinite(se) else "-",
            )
        )
    lines.extend(_table(rows))
    held = result.heldout or {}
    if held.get("error_before") is not None and held.get("error_after") is not None:
        where = (
            f"runs {', '.join(held['runs'])}"
            if "runs" in held
            else f"part from {held.get('from_s', math.nan):.1f} s"
        )
        lines.append(
            f"held-out {where} (models fitted on the rest): "
            f"{format_errors(held['error_before'], held['error_after'])}"
        )
    final = (result.diagnostics or {}).get("final", {})
    if final.get("collinear"):
        lines.append("terms left out as collinear (pivoted QR), with the terms they follow:")
        lines.extend(f"  {k}: {', '.join(v)}" for k, v in final["collinear"].items())
    if final.get("per_run"):
        lines.append("error of the final model per run:")
        rows = [("run", "psi [deg]", "r [deg/s]", "u [m/s]", "v [m/s]")]
        keys = ("psi_rms_deg", "r_rms_deg_s", "u_rms_m_s", "v_rms_m_s")
        for run, e in final["per_run"].items():
            rows.append((run, *(f"{e[k]:.3g}" for k in keys)))
        lines.extend(_table(rows))
    for key, errors in held.items():  # further reference errors, e.g. of published parameters
        if key.startswith("error_") and key not in ("error_before", "error_after"):
            if isinstance(errors, dict):
                text = ", ".join(
                    f"{METRIC_LABELS.get(k, (k, ''))[0]} {_format_value(k, v, 4)} "
                    f"{METRIC_LABELS.get(k, (k, ''))[1]}".rstrip()
                    for k, v in errors.items()
                )
                lines.append(f"  held-out error of {key.removeprefix('error_')}: {text}")
    lines.append(f"runtime: {result.runtime_s:.1f} s")
    return "\n".join(lines)


def _table(rows: Sequence[tuple[str, ...]], indent: str = "  ") -> list[str]:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    out = []
    for r in rows:
        first = r[0].ljust(widths[0])
        rest = [c.rjust(w) for c, w in zip(r[1:], widths[1:], strict=True)]
        out.append((indent + "  ".join([first, *rest])).rstrip())
    return out


def _load_for_identify(
    path_text: str,
    fmt: str | None,
    note: Callable[[str], None],
    quiet: bool = False,
    columns: str | None = None,
    max_gap_s: float | None = None,
) -> Any:
    """Load the record; repairs (:class:`SysidDataWarning`) and other warnings become notes.

    Progress lines of a large file go to stderr unless ``quiet``."""
    import warnings

    from shipgym.sysid.data import FORMATS, detect_format, load

    path = Path(path_text)
    if not path.exists():
        raise ValueError(
            f"record file {path_text!r} does not exist (expected a measured-data file in one of "
            f"the formats {', '.join(FORMATS)})"
        )
    if not path.is_file():
        raise ValueError(f"{path_text!r} is not a file (expected a measured-data record file)")
    if columns is not None:
        if fmt not in (None, "table"):
            raise ValueError(f"--columns goes with --format table, not --format {fmt}")
        fmt = "table"
    if fmt is None:
        try:
            fmt = detect_format(path)
        except ValueError as exc:
            raise ValueError(
                f"{str(exc).removesuffix(' (pass format=...)')}; pass --format"
            ) from None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        record = load(
            path,
            fmt,
            progress=False if quiet else None,
            columns=columns,
            max_gap_s=max_gap_s,
        )
    messages = [str(w.message) for w in caught]
    for msg in messages:
        note(msg)
    if fmt == "canonical":  # repairs made before the record was written are not re-warned
        for repair in record.meta.get("repairs", []):
            if not any(str(repair) in msg for msg in messages):
                note(f"repaired before it was written: {repair}")
    return record, fmt


def _run_identify(args: argparse.Namespace) -> int:
    import json
    import time
    import warnings

    import numpy as np

    from shipgym.models.vmm import VMMParams, parse_particulars
    from shipgym.sysid import identify
    from shipgym.sysid.fit import SysidWarning

    json_path = _output_path(args.json, "--json")
    plot_path = _output_path(args.plot, "--plot", ".png")
    report = sys.stderr if args.json == "-" else sys.stdout
    t0 = time.perf_counter()

    def note(msg: str) -> None:
        print(f"note: {msg}", file=sys.stderr, flush=True)

    def progress(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:6.1f} s] {msg}", file=sys.stderr, flush=True)

    say = (lambda _msg: None) if args.quiet else progress
    given = None if args.particulars is None else parse_particulars(args.particulars)
    records, sources = [], []
    for path_text in args.path:
        say(f"loading {path_text} ...")
        record, fmt = _load_for_identify(
            path_text, args.format, note, args.quiet, args.columns, args.max_gap
        )
        chans = " ".join(k for k in record.channels() if k != "time")
        sources.append(
            f"{path_text} ({fmt}, {record.n} samples, {record.duration:g} s at dt "
            f"{record.dt:g} s; channels {chans})"
        )
        say(f"loaded {sources[-1]}")
        if args.length is not None:
            record.meta["L"] = args.length
        records.append(record)
    particulars = None
    if given is not None:
        if "approach_speed" not in given:  # the runs' median speed
            speeds = [r.U if r.U is not None else np.hypot(r.u, r.v) for r in records
                      if r.U is not None or (r.u is not None and r.v is not None)]  # fmt: skip
            if speeds:
                given["approach_speed"] = float(np.median(np.concatenate(speeds)))
        try:
            particulars = VMMParams.from_particulars(**given)
        except ValueError as exc:
            raise ValueError(f"--particulars: {exc}") from None
    source = sources[0] if len(sources) == 1 else f"{len(sources)} runs:\n  " + "\n  ".join(sources)
    inputs = {Path(p).resolve() for p in args.path}
    for out_path in (json_path, plot_path):
        if out_path is not None and out_path.resolve() in inputs:
            raise ValueError(f"output {str(out_path)!r} is one of the input records; refusing")
    window = {None: "none", "auto": "auto"}.get(args.window) or f"{args.window:g} s"
    say(
        f"identifying base {args.model} (holdout {args.holdout:g}, at most {args.max_effects} "
        f"effects, window {window}) ..."
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SysidWarning)
        try:
            result = identify(
                records if len(records) > 1 else records[0],
                args.model,
                holdout=args.holdout,
                max_effects=args.max_effects,
                window_s=args.window,
                progress=None if args.quiet else progress,
                particulars=particulars,
            )
        except ValueError as exc:
            raise ValueError(
                f"cannot identify {args.model} from {', '.join(args.path)}: {exc}"
            ) from exc
    for msg in dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught):
        note(msg)
    say(f"done in {result.runtime_s:.1f} s")
    if not result.verdict.identifiable:  # a flagged fit: the warning first, then the report
        print(
            f"warning: not identifiable: {'; '.join(result.verdict.reasons)} (the result is "
            "reported with this verdict; shipgym design refuses it)",
            file=sys.stderr,
            flush=True,
        )

    print(_identify_summary(result, source), file=report, flush=True)
    document = result.to_dict()
    text = json.dumps(document, indent=2, allow_nan=False) + "\n"
    outputs: list[tuple[Path, Callable[[Path], Any]]] = []
    if json_path is not None:
        outputs.append((json_path, lambda p: p.write_text(text, encoding="utf-8")))
    if plot_path is not None:
        from shipgym.sysid.plots import plot_identification

        outputs.append((plot_path, lambda p: plot_identification(result, p)))
    write_atomically(outputs)
    for target, _ in outputs:
        print(f"wrote {target}", file=report)
    if args.json == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
    return 0


def _build_identify(sub: Any) -> None:
    from shipgym.sysid.data import FORMATS
    from shipgym.sysid.families import FAMILIES

    p = sub.add_parser(
        "identify",
        help="fit a model to a measured record and add the effects its residual points to",
        description=(
            "Load a manoeuvre record (any of the measured-data formats or the canonical CSV), "
            "fit the base model by output error, then add effects of the catalogue (rudder "
            "offset, yaw nonlinearity, rudder lag, input delay, current, second order; for "
            "rvg3dof and the 3-DOF models their own catalogues) one at a time while the BIC on "
            "the held-out end of the record improves. The 3-DOF models (vmm:<term set>, seed "
            "003's general model; kvlcc2, the MMG model with refined hull derivatives) take "
            "several runs of one ship and hold every few runs out instead. Prints the "
            "simulation errors before and after (heading, yaw rate, and position / speed where "
            "recorded), the effects with their parameters and "
            "evidence, and the parameters. Progress and data-repair notes go to stderr. "
            "A record that cannot determine any model is refused with exit code 2 ('not "
            "identifiable: no excitation: ...': the rudder never moves, or is held for the "
            "whole record while the ship is already turning, or the heading never changes). "
            "A fit the record does not determine (a needed parameter without a standard error "
            "or with one larger than its estimate, a parameter at its bound, K <= 0, a time "
            "constant far beyond the record, an ill-conditioned regression) is reported with "
            "a warning first and 'verdict: {\"identifiable\": false, \"reasons\": [...]}' "
            "in its JSON, which shipgym design refuses."
        ),
    )
    p.add_argument(
        "path",
        metavar="PATH",
        nargs="+",
        help="record file; several runs of one ship for the 3-DOF models vmm:<term set> "
        "(fitted on some runs, scored on the others)",
    )
    p.add_argument(
        "--format",
        default=None,
        choices=FORMATS,
        help="file format (default: detected from the header and the file name; 'table' is "
        "any delimited file whose headers state their units, 'nmea' an NMEA 0183 log)",
    )
    p.add_argument(
        "--columns",
        default=None,
        metavar="MAP",
        help="column map of your own table, e.g. 'time=t,delta=-rudder:deg,psi=hdg:deg,"
        "r=rot:deg/min,U=sog:kn' (channel=[-]column:unit; '-' negates a port-positive rudder "
        "or a counter-clockwise heading; channels time, delta, psi, r, U, u, v, x, y, lat, "
        "lon, rpm)",
    )
    p.add_argument(
        "--length",
        type=_float_in(0.1, 1000.0, "m"),
        default=None,
        metavar="L",
        help="the ship's length [m], kept in the model file (the envs' option ranges and the "
        "IMO ratios of 'shipgym simulate --model FIT.json' use it); default: the record's",
    )
    p.add_argument(
        "--particulars",
        default=None,
        metavar="KEY=VALUE,...",
        help="the ship of the 3-DOF models (vmm:<term set>) by its main particulars, SI units: "
        "'length=7.0,breadth=1.27,draught=0.46,displacement=3.27,x_g=0.25,"
        "propeller_diameter=0.216' (displacement in m^3, or mass= in kg; optional rho= "
        "(1025), yaw_radius= (0.25 L), block_coefficient= (from the displacement), "
        "approach_speed= (the runs' median speed)); builds the mass, inertia and Clarke's "
        "added masses. Default: the records' own (meta lines such as '# L: 7.0', '# draft: "
        "0.46')",
    )
    p.add_argument(
        "--max-gap",
        type=_float_in(1e-6, 1e6, "s"),
        default=None,
        metavar="S",
        help="table and nmea: a longer time step splits the record into segments (default: "
        "5 median steps)",
    )
    p.add_argument(
        "--model", default="nomoto1", choices=tuple(FAMILIES), help="base model (%(default)s)"
    )
    p.add_argument(
        "--json",
        default=None,
        metavar="OUT",
        help="write the result as JSON ('-': to stdout, the summary then goes to stderr)",
    )
    p.add_argument(
        "--plot",
        default=None,
        metavar="OUT.png",
        help="write measured vs before vs after and the residuals as a PNG",
    )
    p.add_argument(
        "--window",
        type=_window,
        default="auto",
        metavar="S|auto|none",
        help="score the errors over consecutive windows of S seconds, each started from the "
        "measured state; 'none': one free run; 'auto' (default): windows for long records",
    )
    p.add_argument(
        "--holdout",
        type=_finite_float,
        default=0.3,
        metavar="FRAC",
        help="fraction kept out of the fits for scoring: the end of one record, or of several "
        "runs that many, each a manoeuvre of a kind a training run also makes "
        "(default: %(default)s)",
    )
    p.add_argument(
        "--max-effects",
        type=_int_in(0, 10),
        default=3,
        metavar="N",
        help="largest number of effects to add (default: %(default)s)",
    )
    p.add_argument(
        "--quiet",
        action="store_true",
        help="no progress lines (notes, errors and the summary are still printed)",
    )
    p.set_defaults(handler=_run_identify)


# ------------------------------------------------------------------------------------------
# design
# ------------------------------------------------------------------------------------------
def _run_design(args: argparse.Namespace) -> int:
    import json

    from shipgym.benchmark.design import (
        check_designable,
        design_heading_autopilot,
        plot_heading_design,
    )
    from shipgym.models import NOMOTO_MODEL_NAMES
    from shipgym.models.model_file import load_model

    json_path = _output_path(args.json, "--json", ".json")
    plot_path = _output_path(args.plot, "--plot", ".png")
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
    write_atomically(outputs)
    for target, _ in outputs:
        print(f"wrote {target}")
    if json_path is not None:
        print(
            f"run it on the identified ship: {PROG} evaluate --env shipgym/NomotoHeading-v0 "
            f"--model {args.model_file} --controller classic --gains {json_path}"
        )
    return 0


def _build_design(sub: Any) -> None:
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
        type=_float_in(1e-4, 10.0, "rad/s"),
        default=None,
        metavar="W",
        help="closed-loop natural frequency [rad/s] (default: from the steering gear and ship)",
    )
    p.add_argument(
        "--damping",
        type=_float_in(0.05, 5.0, "(damping ratio)"),
        default=0.8,
        metavar="Z",
        help="closed-loop relative damping (default: %(default)s)",
    )
    p.set_defaults(handler=_run_design)


#: Subcommand name -> builder.
SUBCOMMANDS: dict[str, Builder] = {
    "demo": _build_demo,
    "bench": _build_bench,
    "envs": _build_envs,
    "simulate": _build_simulate,
    "evaluate": _build_evaluate,
    "train": _build_train,
    "benchmark": _build_benchmark,
    "identify": _build_identify,
    "design": _build_design,
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
    except (OSError, ImportError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""``shipgym train``: train a stable-baselines3 agent, resume it, or sweep on Ray."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from shipgym.cli._common import MAX_SEED, PROG, int_in, output_dir, progress_line
from shipgym.cli._ray import ray_address

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
    return True if args.tensorboard is None else str(output_dir(args.tensorboard, "--tensorboard"))


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


def run(args: argparse.Namespace) -> int:
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
        out = output_dir(args.out, "--out")
    tensorboard = _tensorboard_option(args)
    bar = not args.quiet and sys.stderr.isatty()
    progress = None if (bar or args.quiet) else progress_line
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
                progress=progress_line if not args.quiet else None,
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
    out = output_dir(args.out, "--out")
    try:
        result = run_sweep(
            spec,
            out,
            address=address,
            num_cpus=args.ray_cpus,
            progress=None if args.quiet else progress_line,
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


def build(sub: Any) -> None:
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
    p.add_argument(
        "--env",
        default=None,
        choices=ENV_IDS,
        help="the environment id to train on (shipgym envs lists them)",
    )
    p.add_argument(
        "--algo", default=None, choices=ALGOS, help="the stable-baselines3 algorithm to train"
    )
    p.add_argument(
        "--timesteps",
        type=int_in(1, 10**9),
        default=None,
        metavar="N",
        help="environment steps (default: the shipped agent's budget; with --resume the new "
        "total, default the recorded one)",
    )
    p.add_argument(
        "--seed",
        type=int_in(0, MAX_SEED),
        default=None,
        metavar="S",
        help="seed of the networks; training sub-env i gets S + i (default 0)",
    )
    p.add_argument(
        "--out",
        default="shipgym-agents",
        metavar="DIR",
        help="folder of the agent, its checkpoints and record, made if missing "
        "(default: %(default)s)",
    )
    p.add_argument(
        "--num-envs",
        type=int_in(1, 65536),
        default=None,
        metavar="N",
        help="training sub-envs (default: 16 for PPO, 8 for SAC)",
    )
    p.add_argument(
        "--eval-freq",
        type=int_in(1, 10**9),
        default=None,
        metavar="N",
        help="env steps between evaluations and checkpoints (default: 1/20 of the budget; "
        "PPO: at least a rollout)",
    )
    p.add_argument(
        "--eval-episodes",
        type=int_in(1, 10**4),
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
        type=ray_address,
        metavar="ADDRESS",
        help="run a sweep as Ray Tune trials: without ADDRESS on a Ray started on this machine, "
        "with HOST:PORT (as 'ray start --head' prints it) or 'auto' on that cluster (DIR must "
        "then be on a filesystem every node sees)",
    )
    p.add_argument(
        "--ray-cpus",
        type=int_in(1, 4096),
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
    p.add_argument("--quiet", action="store_true", help="no progress bar or progress lines")
    p.set_defaults(handler=run)

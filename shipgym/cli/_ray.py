"""The ``--ray``/``--ray-cpus``/``--task-episodes`` flags of the commands that scale out on Ray."""

from __future__ import annotations

import argparse
import sys

from shipgym.cli._common import MAX_EPISODES, PROG, int_in


def ray_address(text: str) -> str:
    """``--ray``: ``local`` (Ray on this machine), ``auto`` or ``[ray://]host:port``."""
    from shipgym.cluster import parse_address

    try:
        address = parse_address(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("bad Ray address ")) from None
    return "local" if address is None else address


def add_ray_flags(p: argparse.ArgumentParser, what: str) -> None:
    """``--ray [ADDRESS]``, ``--ray-cpus N`` and ``--task-episodes N``."""
    p.add_argument(
        "--ray",
        nargs="?",
        const="local",
        default=None,
        type=ray_address,
        metavar="ADDRESS",
        help=f"run the {what} as Ray tasks: without ADDRESS on a Ray started on this machine, "
        "with HOST:PORT (as 'ray start --head' prints it) or 'auto' on that cluster; the "
        "results are those of a local run",
    )
    p.add_argument(
        "--ray-cpus",
        type=int_in(1, 4096),
        default=None,
        metavar="N",
        help="CPUs of the local Ray started by --ray (default: every core)",
    )
    p.add_argument(
        "--task-episodes",
        type=int_in(1, MAX_EPISODES),
        default=None,
        metavar="N",
        help="episodes per Ray task (default: about four tasks per CPU of the cluster)",
    )


def ray_options(args: argparse.Namespace) -> tuple[str | None, int | None, int | None] | None:
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


def campaign_failed(exc: Exception) -> int:
    """Print a failed episode or Ray task (its message names env, controller, condition
    and seed) as one line; exit code 1."""
    print(f"{PROG}: error: {exc}", file=sys.stderr)
    return 1

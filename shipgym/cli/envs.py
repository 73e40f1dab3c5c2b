"""``shipgym envs``: the registered environments, their sizes, time step and task."""

from __future__ import annotations

import argparse
from typing import Any


def run(args: argparse.Namespace) -> int:
    import warnings

    import gymnasium as gym

    from shipgym.envs import ENV_IDS, env_task

    tasks = _env_tasks()
    rows = []
    for env_id in ENV_IDS:
        with warnings.catch_warnings():
            # the table lists the older versions on purpose: no "out of date" warning for them
            warnings.filterwarnings(
                "ignore", message=".*is out of date", category=DeprecationWarning
            )
            env = gym.make(env_id)
        try:
            steps = env.spec.max_episode_steps if env.spec else None
            dt = float(env.unwrapped.dt)
            task = tasks[env_task(env_id)]
            if env_id.startswith("shipgym/RVG"):
                params = env.spec.kwargs.get("params") if env.spec else None
                task += f"; ship: {_GUNNERUS[params or 'seed001']}"
            rows.append(
                (
                    env_id,
                    str(env.action_space.shape[0]),
                    str(env.observation_space.shape[0]),
                    f"{dt:g}",
                    "-" if steps is None else f"{steps} ({steps * dt:g} s)",
                    task,
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


#: The Gunnerus of each parameter set, as the table names it.
_GUNNERUS = {
    "seed001": "Gunnerus, seed 001's parameters",
    "sea_trials": "Gunnerus identified from its sea trials",
}


def _env_tasks() -> dict[str, str]:
    """Task and action of each task name, from the table in :mod:`shipgym.envs`' docstring."""
    import shipgym.envs

    tasks = {}
    for line in (shipgym.envs.__doc__ or "").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 3 and cells[0].startswith("``shipgym/"):
            tasks[shipgym.envs.env_task(cells[0].strip("`"))] = f"{cells[1]}; action: {cells[2]}"
    return tasks


def build(sub: Any) -> None:
    p = sub.add_parser(
        "envs",
        help="list the environment ids with their action/observation sizes and time step",
        description="List the registered shipgym environments.",
    )
    p.set_defaults(handler=run)

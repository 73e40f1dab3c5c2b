"""``shipgym envs``: the registered environments, their sizes, time step and task."""

from __future__ import annotations

import argparse
from typing import Any


def run(args: argparse.Namespace) -> int:
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


def build(sub: Any) -> None:
    p = sub.add_parser(
        "envs",
        help="list the environment ids with their action/observation sizes and time step",
        description="List the registered shipgym environments.",
    )
    p.set_defaults(handler=run)

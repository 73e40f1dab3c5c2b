"""Gymnasium environments of shipgym, registered on ``import shipgym``.

| id | task | action |
|----|------|--------|
| ``shipgym/NomotoHeading-v0`` | hold heading setpoints (Nomoto-family ship) | rudder |
| ``shipgym/RVGHeading-v0`` | hold heading setpoints (Gunnerus) | pod azimuth |
| ``shipgym/RVGSpeed-v0`` | hold speed setpoints (Gunnerus) | pod thrust |
| ``shipgym/RVGPathFollowing-v0`` | follow waypoints (Gunnerus) | azimuth, thrust |
| ``shipgym/RVGTargetTracking-v0`` | intercept and hold distance (Gunnerus) | azimuth, thrust |

Each ``RVG*`` env also has a ``-v1`` id: the same task on the Gunnerus identified from its sea
trials (``params="sea_trials"``, :meth:`shipgym.models.RVGParams.sea_trials`) by default. The
``-v0`` ids keep seed 001's parameters, unchanged. :data:`CURRENT_ENV_IDS` lists the newest
version of every task: the envs the benchmark and the shipped agents use.
"""

from __future__ import annotations

from gymnasium.envs.registration import register, registry

from shipgym.envs.heading import (
    NomotoHeadingEnv,
    NomotoHeadingVectorEnv,
    RVGHeadingEnv,
    RVGHeadingVectorEnv,
)
from shipgym.envs.path_following import RVGPathFollowingEnv, RVGPathFollowingVectorEnv
from shipgym.envs.speed import RVGSpeedEnv, RVGSpeedVectorEnv
from shipgym.envs.target_tracking import RVGTargetTrackingEnv, RVGTargetTrackingVectorEnv
from shipgym.models.rvg import NEWEST_RVG_PARAMETERS

#: The tasks, in the order of every table.
TASKS = ("NomotoHeading", "RVGHeading", "RVGSpeed", "RVGPathFollowing", "RVGTargetTracking")

#: Default keyword arguments per env version (``-v1``: the validated sea-trial Gunnerus).
_VERSIONS: dict[str, dict[str, dict[str, object]]] = {
    "NomotoHeading": {"v0": {}},
    **{task: {"v0": {}, "v1": {"params": NEWEST_RVG_PARAMETERS}} for task in TASKS[1:]},
}

#: Every registered env id.
ENV_IDS = tuple(f"shipgym/{task}-{v}" for task in TASKS for v in _VERSIONS[task])
#: The newest version of each task: what the benchmark, the shipped agents and
#: ``shipgym bench`` use by default.
CURRENT_ENV_IDS = tuple(f"shipgym/{task}-{max(_VERSIONS[task])}" for task in TASKS)


def env_task(env_id: str) -> str:
    """The task of a registered env id (``"shipgym/RVGHeading-v1"`` -> ``"RVGHeading"``).

    Raises
    ------
    ValueError
        If ``env_id`` is not one of :data:`ENV_IDS`.
    """
    if env_id not in ENV_IDS:
        raise ValueError(f"unknown env {env_id!r}; expected one of {ENV_IDS}")
    return env_id.split("/", 1)[1].rsplit("-", 1)[0]


_CLASSES = (
    (NomotoHeadingEnv, NomotoHeadingVectorEnv),
    (RVGHeadingEnv, RVGHeadingVectorEnv),
    (RVGSpeedEnv, RVGSpeedVectorEnv),
    (RVGPathFollowingEnv, RVGPathFollowingVectorEnv),
    (RVGTargetTrackingEnv, RVGTargetTrackingVectorEnv),
)


def register_envs() -> None:
    """Register every shipgym environment with Gymnasium (idempotent)."""
    for task, (single, vector) in zip(TASKS, _CLASSES, strict=True):
        for version, kwargs in _VERSIONS[task].items():
            env_id = f"shipgym/{task}-{version}"
            if env_id in registry:
                continue
            register(
                id=env_id,
                entry_point=f"{single.__module__}:{single.__name__}",
                vector_entry_point=f"{vector.__module__}:{vector.__name__}",
                max_episode_steps=single.task_cls.max_episode_steps,
                kwargs=dict(kwargs),
            )


__all__ = [
    "CURRENT_ENV_IDS",
    "ENV_IDS",
    "TASKS",
    "NomotoHeadingEnv",
    "NomotoHeadingVectorEnv",
    "RVGHeadingEnv",
    "RVGHeadingVectorEnv",
    "RVGPathFollowingEnv",
    "RVGPathFollowingVectorEnv",
    "RVGSpeedEnv",
    "RVGSpeedVectorEnv",
    "RVGTargetTrackingEnv",
    "RVGTargetTrackingVectorEnv",
    "env_task",
    "register_envs",
]

"""Gymnasium environments of shipgym, registered on ``import shipgym``.

| id | task | action |
|----|------|--------|
| ``shipgym/NomotoHeading-v0`` | hold heading setpoints (Nomoto-family ship) | rudder |
| ``shipgym/RVGHeading-v0`` | hold heading setpoints (Gunnerus) | pod azimuth |
| ``shipgym/RVGSpeed-v0`` | hold speed setpoints (Gunnerus) | pod thrust |
| ``shipgym/RVGPathFollowing-v0`` | follow waypoints (Gunnerus) | azimuth, thrust |
| ``shipgym/RVGTargetTracking-v0`` | intercept and hold distance (Gunnerus) | azimuth, thrust |
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

ENV_IDS = (
    "shipgym/NomotoHeading-v0",
    "shipgym/RVGHeading-v0",
    "shipgym/RVGSpeed-v0",
    "shipgym/RVGPathFollowing-v0",
    "shipgym/RVGTargetTracking-v0",
)

_CLASSES = (
    (NomotoHeadingEnv, NomotoHeadingVectorEnv),
    (RVGHeadingEnv, RVGHeadingVectorEnv),
    (RVGSpeedEnv, RVGSpeedVectorEnv),
    (RVGPathFollowingEnv, RVGPathFollowingVectorEnv),
    (RVGTargetTrackingEnv, RVGTargetTrackingVectorEnv),
)


def register_envs() -> None:
    """Register every shipgym environment with Gymnasium (idempotent)."""
    for env_id, (single, vector) in zip(ENV_IDS, _CLASSES, strict=True):
        if env_id in registry:
            continue
        register(
            id=env_id,
            entry_point=f"{single.__module__}:{single.__name__}",
            vector_entry_point=f"{vector.__module__}:{vector.__name__}",
            max_episode_steps=single.task_cls.max_episode_steps,
        )


__all__ = [
    "ENV_IDS",
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
    "register_envs",
]

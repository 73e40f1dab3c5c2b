"""Classic autopilots and guidance laws (independent of shipgym).

A controller takes measurements (time, heading, yaw rate, speed, position) and returns
commands in SI units and radians, so the same object drives a shipgym env, a manoeuvre
script or a real ship. Each is a plain class with ``reset(...)`` and ``update(t, ...)``;
``update`` uses the difference of successive times ``t`` as its step (the ``dt`` given at
construction when ``t`` is ``None``). The autopilots and guidance laws run on a batch of ships:
given arrays (one entry per ship) they return arrays, given scalars they return floats, and one
ship is a batch of one of the same code. This package imports numpy, scipy and python-control
only, never ``shipgym``.

* :class:`HeadingAutopilot`: PID by pole placement on the Nomoto model, third-order
  reference model, actuator limits and anti-windup (seed 004 eq. 6-7).
* :class:`SpeedAutopilot`: PI with steady-state feed-forward (seed 004 eq. 8).
* :class:`ConstantBearingGuidance`: hold a distance from a moving target (seed 004 eq. 11).
* :func:`allocate_force_moment`, :class:`PodCommand`, :func:`pod_env_actions`: R/V Gunnerus
  pod allocation and the envs' action scaling (seed 001 eq. 20).
* :class:`WaypointPath`, :class:`FilletPath`, :class:`SplinePath`: paths with arc length,
  closest point, tangent angle and curvature (seed 004 section 2.1).
* :class:`LOSGuidance` (lookahead LOS with the conditional integrator of seed 004 eq. 9-10)
  and :class:`IntegralLOS` (Borhaug et al. 2008).
"""

from controllers._angles import ssa
from controllers.allocation import (
    BOLLARD_THRUST,
    ENV_MAX_AZIMUTH,
    POD_X,
    POD_Y,
    PodCommand,
    allocate_force_moment,
    azimuth_to_action,
    pod_env_actions,
    pod_forces,
    thrust_to_action,
)
from controllers.heading import (
    HeadingAutopilot,
    HeadingDesignReport,
    HeadingReferenceModel,
    default_bandwidth,
    design_model,
    pid_gains_nomoto,
)
from controllers.los import IntegralLOS, LOSGuidance
from controllers.paths import FilletPath, Path, SplinePath, WaypointPath
from controllers.speed import (
    SpeedAutopilot,
    linear_feedforward,
    linearised_drag_model,
    quadratic_drag_feedforward,
)
from controllers.target import ConstantBearingGuidance, course_and_speed
from controllers.wave_filter import WaveFilter

__all__ = [
    "BOLLARD_THRUST",
    "ENV_MAX_AZIMUTH",
    "POD_X",
    "POD_Y",
    "ConstantBearingGuidance",
    "FilletPath",
    "HeadingAutopilot",
    "HeadingDesignReport",
    "HeadingReferenceModel",
    "IntegralLOS",
    "LOSGuidance",
    "Path",
    "PodCommand",
    "SpeedAutopilot",
    "SplinePath",
    "WaveFilter",
    "WaypointPath",
    "allocate_force_moment",
    "azimuth_to_action",
    "course_and_speed",
    "default_bandwidth",
    "design_model",
    "linear_feedforward",
    "linearised_drag_model",
    "pid_gains_nomoto",
    "pod_env_actions",
    "pod_forces",
    "quadratic_drag_feedforward",
    "ssa",
    "thrust_to_action",
]

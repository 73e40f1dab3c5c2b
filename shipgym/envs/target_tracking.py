"""Target tracking environment ``shipgym/RVGTargetTracking-v0`` (seed 004 section 2.3 task)."""

from __future__ import annotations

import math
from typing import Any

from shipgym.envs.core import ShipEnv, ShipVectorEnv
from shipgym.envs.tasks import RVGTargetTask
from shipgym.models.rvg import BREADTH, LPP


class RVGTargetTrackingEnv(ShipEnv):
    """
    ## Description

    R/V Gunnerus must intercept a target moving at constant velocity and hold a set distance
    (``distance``, 50 m) from it. The target starts 300-800 m away within 60 deg of the bow,
    on a random course at 1-3 m/s. One step is 0.5 s.

    ## Action Space

    ``Box(-1, 1, (2,), float32)``: ``[azimuth, thrust]`` as in ``RVGPathFollowing-v0``.

    ## Observation Space

    ``Box(low, high, (10,), float32)`` with bounds +-1e5 m, +-50 m/s, +-1e5 m, [-10, 15] m/s,
    +-10 m/s, +-0.5 rad/s, +-pi and [0, 1]; observations are clipped to them:

    | Num | Observation | Unit |
    |-----|-------------|------|
    | 0, 1 | target position relative to the ship, body frame (forward, starboard) | m |
    | 2, 3 | target velocity relative to the ship, body frame | m/s |
    | 4 | distance error ``|p_t - p| - d_set`` | m |
    | 5, 6, 7 | ``u``, ``v``, ``r`` | m/s, m/s, rad/s |
    | 8 | azimuth of pod 1 | rad |
    | 9 | thrust of pod 1 over the bollard thrust | - |

    ## Rewards

    ``1 - min(|d - d_set| / 100 m, 2) - 0.05 |a|^2`` per step (positive within 100 m of the set
    distance, at least -1.1); -20 when the distance exceeds ``max_distance``: in [-21.1, 1].

    ## Starting State

    Heading uniform, straight ahead at 5.14 m/s through the water at service thrust; current
    uniform in [0, ``max_current_speed``] (0.5 m/s), direction uniform.

    ## Episode End

    Terminates when the distance exceeds ``max_distance`` (3 km) or on a numerical blow-up;
    truncation after 1600 steps (800 s).
    Once ``terminated`` is returned, a further ``step`` raises ``gymnasium.error.ResetNeeded``
    until ``reset``.

    ## Arguments

    ``gymnasium.make("shipgym/RVGTargetTracking-v1", max_current_speed=0.5, distance=50.0,
    max_distance=3000.0, params="sea_trials", render_mode=None)``. Reset options: ``current_speed``,
    ``current_direction``, ``initial_state``, ``target_position`` and ``target_velocity``
    ((north, east) in m and m/s), ``distance`` [m]. ``info`` holds ``state``, the current,
    ``distance``, ``distance_error`` and ``termination_reason``.
    At sea (``wind`` and ``sea_state``, in the constructor for every episode or in the reset
    options; :mod:`shipgym.models.seaway_options`, off by default) the observations are
    formed from the measured state (the wave-frequency motion added to heading, yaw rate and
    position), the reward from the low-frequency one, and ``info`` adds ``wind``,
    ``sea_state``, ``wave_motion`` and ``measured_state``.
    Option ranges (a value outside raises ``ValueError`` naming the option, the value and the
    range) as for ``RVGHeading-v0``, but positions (``x``, ``y`` and ``target_position``'s
    north and east) within +-6960 m (one episode at the top speed 8.7 m/s, or ``max_distance``
    if larger); ``target_velocity`` a speed in [0, 13.05] m/s (1.5 times the top speed) and
    ``distance`` in (0, ``max_distance``].
    ``params`` selects the Gunnerus parameter set: ``"seed001"`` (seed 001, the default of ``-v0``),
    ``"sea_trials"`` (:meth:`shipgym.models.RVGParams.sea_trials`, identified from the sea
    trials, the default of ``-v1``) or an ``RVGParams``.

    ## Version History

    * v0: Initial version.
    * v1: R/V Gunnerus identified from its sea trials (``params="sea_trials"``) by default;
      the task, observations and rewards are those of v0.
    """

    task_cls = RVGTargetTask

    @property
    def ship_dimensions(self) -> tuple[float, float]:
        return (LPP, BREADTH)

    def _draw_args(self, i: int) -> dict[str, Any]:
        vn, ve = self.task.target_vel[i]
        return {
            "target": (float(self.task.target[i, 0]), float(self.task.target[i, 1])),
            "target_heading": math.atan2(ve, vn),
        }


class RVGTargetTrackingVectorEnv(ShipVectorEnv):
    """NumPy-batched ``shipgym/RVGTargetTracking-v0`` (see :class:`RVGTargetTrackingEnv`)."""

    task_cls = RVGTargetTask
    single_env_cls = RVGTargetTrackingEnv

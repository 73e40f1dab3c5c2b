"""Path following environment ``shipgym/RVGPathFollowing-v0`` (seed 004 section 2.2 task)."""

from __future__ import annotations

from typing import Any

from shipgym.envs.core import ShipEnv, ShipVectorEnv
from shipgym.envs.tasks import RVGPathTask
from shipgym.models.rvg import BREADTH, LPP


class RVGPathFollowingEnv(ShipEnv):
    """
    ## Description

    R/V Gunnerus must follow a path of straight legs between waypoints to its last waypoint.
    Each reset draws a random path (4 to 6 waypoints, legs of 200-400 m, turns up to 60 deg)
    unless ``waypoints`` are given. The active leg switches when the ship comes within
    ``accept_radius`` (2 L = 67.8 m) of its end or passes it along the track. One step is 0.5 s.

    ## Action Space

    ``Box(-1, 1, (2,), float32)``: ``[azimuth, thrust]``. Azimuth of both pods as a fraction of
    35 deg (positive turns to port); thrust from zero (-1) to the bollard thrust (+1) per pod,
    limited by the physics at speed. Clipped to [-1, 1]; NaN or infinity raises ``ValueError``.

    ## Observation Space

    ``Box(low, high, (9,), float32)`` with bounds +-1e4 m, +-pi, +-1e4 m, +-pi, [-10, 15] m/s,
    +-10 m/s, +-0.5 rad/s, +-pi and [0, 1]; observations are clipped to them:

    | Num | Observation | Unit |
    |-----|-------------|------|
    | 0 | cross-track error ``e`` (positive: ship right of the path) | m |
    | 1 | ``ssa(chi_p - psi)``: path angle minus heading | rad |
    | 2 | along-track distance left on the active leg | m |
    | 3 | turn at the end of the active leg (0 on the last leg) | rad |
    | 4 | surge velocity ``u`` | m/s |
    | 5 | sway velocity ``v`` | m/s |
    | 6 | yaw rate ``r`` | rad/s |
    | 7 | azimuth of pod 1 | rad |
    | 8 | thrust of pod 1 over the bollard thrust | - |

    ## Rewards

    ``0.5 clip(progress / (5.14 m/s dt), -1, 1) + 0.5 exp(-(e / 25 m)^2) - 0.1 |chi_p - psi| / pi
    - 0.05 |a|^2`` per step (at most 1; positive while the ship is near the path and making way
    along it, so ending an episode early never pays; at least -0.7), +20 on reaching the last
    waypoint, -20 when the cross-track error exceeds ``max_cross_track``: in [-20.7, 21].

    ## Starting State

    Near the first waypoint: a cross-track offset uniform in [-30, 30] m, heading within 30 deg
    of the first leg, straight ahead at 5.14 m/s through the water at service thrust. Current
    uniform in [0, ``max_current_speed``] (0.5 m/s), direction uniform.

    ## Episode End

    Terminates on reaching the last waypoint (``info["completed"]``), on a cross-track error
    beyond ``max_cross_track`` (250 m) or a numerical blow-up; truncation after 1600 steps.
    Once ``terminated`` is returned, a further ``step`` raises ``gymnasium.error.ResetNeeded``
    until ``reset``.

    ## Arguments

    ``gymnasium.make("shipgym/RVGPathFollowing-v1", max_current_speed=0.5, max_azimuth=0.61,
    accept_radius=67.8, max_cross_track=250.0, params="sea_trials", render_mode=None)``.
    Reset options: ``current_speed``, ``current_direction``, ``initial_state``, ``waypoints``
    (2 to 16 (north, east) points [m]). ``info`` holds ``state``, the current,
    ``cross_track_error``, ``segment``, ``completed`` and ``termination_reason``.
    At sea (``wind`` and ``sea_state``, in the constructor for every episode or in the reset
    options; :mod:`shipgym.models.seaway_options`, off by default) the observations are
    formed from the measured state (the wave-frequency motion added to heading, yaw rate and
    position), the reward from the low-frequency one, and ``info`` adds ``wind``,
    ``sea_state``, ``wave_motion`` and ``measured_state``.
    Option ranges (a value outside raises ``ValueError`` naming the option, the value and the
    range) as for ``RVGHeading-v0``, but positions (``x``, ``y`` and every waypoint's north
    and east) within +-6960 m, the distance covered in one episode at the top speed 8.7 m/s.
    ``params`` selects the Gunnerus parameter set: ``"seed001"`` (seed 001, the default of ``-v0``),
    ``"sea_trials"`` (:meth:`shipgym.models.RVGParams.sea_trials`, identified from the sea
    trials, the default of ``-v1``) or an ``RVGParams``.

    ## Version History

    * v0: Initial version.
    * v1: R/V Gunnerus identified from its sea trials (``params="sea_trials"``) by default;
      the task, observations and rewards are those of v0.
    """

    task_cls = RVGPathTask

    @property
    def ship_dimensions(self) -> tuple[float, float]:
        return (LPP, BREADTH)

    def _draw_args(self, i: int) -> dict[str, Any]:
        return {"path": self.task.waypoints(i)}


class RVGPathFollowingVectorEnv(ShipVectorEnv):
    """NumPy-batched ``shipgym/RVGPathFollowing-v0`` (see :class:`RVGPathFollowingEnv`)."""

    task_cls = RVGPathTask
    single_env_cls = RVGPathFollowingEnv

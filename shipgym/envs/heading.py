"""Heading environments: ``shipgym/NomotoHeading-v0`` and ``shipgym/RVGHeading-v0``.

Physics: :mod:`shipgym.models.nomoto` (seed 004 eq. 1-4, seed 002 eq. 1-3) and
:mod:`shipgym.models.rvg` (seed 001 eq. 5-20); task logic: the ``heading`` kernel of
:mod:`shipgym.envs.kernels`.
"""

from __future__ import annotations

from typing import Any

from shipgym.envs.core import ShipEnv, ShipVectorEnv
from shipgym.envs.tasks import NomotoHeadingTask, RVGHeadingTask
from shipgym.models.rvg import BREADTH, LPP


class NomotoHeadingEnv(ShipEnv):
    """
    ## Description

    A ship steered by its rudder must reach and hold heading setpoints. The yaw dynamics are a
    Nomoto-family model of the Mariner class cargo ship (L = 160.9 m, 7.7 m/s): first-order
    Nomoto (default), second-order Nomoto, Norrbin or Bech (keyword ``model``), with a
    first-order steering gear (2 s, 35 deg, 2.32 deg/s), a first-order surge model held at the
    service shaft speed, and a constant current that carries the ship (it does not turn it).
    Every ``setpoint_interval`` seconds (200 s) the setpoint changes by 10 to 60 deg to a random
    side, four times, then holds. One step is 1 s of simulated time (one RK4 step).

    ## Action Space

    ``Box(-1, 1, (1,), float32)``: rudder command as a fraction of 35 deg (positive turns to
    starboard). Values outside [-1, 1] are clipped; NaN or infinity raises ``ValueError``.

    ## Observation Space

    ``Box(low, high, (3,), float32)`` with bounds +-pi, +-0.5 rad/s and +-pi/2 rad; observations
    are clipped to them:

    | Num | Observation | Unit |
    |-----|-------------|------|
    | 0 | heading error ``ssa(psi_d - psi)`` | rad, in [-pi, pi) |
    | 1 | yaw rate ``r`` | rad/s |
    | 2 | rudder angle ``delta`` | rad, in [-0.61, 0.61] |

    ## Rewards

    ``-|psi_d - psi| / pi - 0.05 a^2`` per step, in [-1.05, 0]: 0 when on heading with the
    rudder amidships.

    ## Starting State

    Heading uniform in [-pi, pi), speed 7.7 m/s, yaw rate and rudder zero, at the origin.
    Current speed uniform in [0, ``max_current_speed``] (1 m/s) and direction uniform.

    ## Episode End

    Truncation after 800 steps (800 s) through ``max_episode_steps``. Termination only if the
    integration blows up (``info["termination_reason"] == "numerical_blow_up"``; the last finite
    observation is returned).
    Once ``terminated`` is returned, a further ``step`` raises ``gymnasium.error.ResetNeeded``
    until ``reset``.

    ## Arguments

    ``gymnasium.make("shipgym/NomotoHeading-v0", model="nomoto1", max_current_speed=1.0,
    setpoint_interval=200.0, render_mode=None)``. ``model`` is a model name, an identified
    ship's model file (``shipgym identify --json FIT.json``), an identification result or a
    Nomoto-family ``ShipModel``; an identified ship brings its steering gear, speed, rudder
    offset and input delay (the rudder command reaches the ship late; the reward's action term
    is that of the command applied). ``reset(options=...)`` accepts
    ``current_speed`` [m/s], ``current_direction`` [rad, toward, clockwise from north],
    ``initial_state`` (dict of named states or a full state vector) and ``setpoints`` (1 to 8
    headings [rad], each held ``setpoint_interval`` seconds, the last held to the end).
    ``info`` holds ``state`` (names in ``env.unwrapped.state_names``), ``current_speed``,
    ``current_direction``, ``heading_error``, ``heading_setpoint`` and ``termination_reason``.
    At sea (``wind`` and ``sea_state``, in the constructor for every episode or in the reset
    options; :mod:`shipgym.models.seaway_options`, off by default) the observations are
    formed from the measured state (the wave-frequency motion added to heading, yaw rate and
    position), the reward from the low-frequency one, and ``info`` adds ``wind``,
    ``sea_state``, ``wave_motion`` and ``measured_state``.

    Option ranges (a value outside raises ``ValueError`` naming the option, the value and the
    range), from the ship's top speed V = 9.9 m/s (at the largest shaft speed) and length
    L = 160.9 m: ``current_speed`` in [0, 9.9] m/s (also the largest ``max_current_speed``);
    ``current_direction``, ``setpoints`` and the heading ``psi`` within +-628.4 rad (100 turns);
    ``initial_state`` positions ``x``, ``y`` within +-7920 m (one episode at top speed),
    ``U`` in [0, 14.85] m/s (1.5 V), ``r`` within +-0.1231 rad/s (2 V / L: the bow sideways
    at top speed), ``r_dot`` within +-0.1231 rad/s^2, ``delta`` within +-0.6109 rad (the
    steering gear's limit). ``env.unwrapped.task.state_ranges()`` lists them.

    ## Version History

    * v0: Initial version.
    """

    task_cls = NomotoHeadingTask

    @property
    def ship_dimensions(self) -> tuple[float, float]:
        return (
            self.task.ship_length,
            NomotoHeadingTask.ship_beam * self.task.ship_length / NomotoHeadingTask.ship_length,
        )

    def _draw_args(self, i: int) -> dict[str, Any]:
        return {"setpoint_heading": float(self.task.metrics(i)["heading_setpoint"])}


class NomotoHeadingVectorEnv(ShipVectorEnv):
    """NumPy-batched ``shipgym/NomotoHeading-v0`` (see :class:`NomotoHeadingEnv`)."""

    task_cls = NomotoHeadingTask
    single_env_cls = NomotoHeadingEnv


class RVGHeadingEnv(ShipEnv):
    """
    ## Description

    R/V Gunnerus (33.9 m, 3-DOF model of seed 001 with two azimuth pods) at service thrust
    must reach and hold heading setpoints by turning both pods together. Every
    ``setpoint_interval`` seconds (100 s) the setpoint changes by 10 to 45 deg to a random side,
    three times. One step is 0.5 s (one RK4 step).

    ## Action Space

    ``Box(-1, 1, (1,), float32)``: common azimuth command of both pods as a fraction of
    ``max_azimuth`` (35 deg). Positive azimuth turns the ship to port. Clipped to [-1, 1]; NaN
    or infinity raises ``ValueError``. Thrust is held at 25 kN per pod (10 kn in calm water).

    ## Observation Space

    ``Box(low, high, (5,), float32)`` with bounds +-pi, +-0.5 rad/s, +-pi, [-10, 15] m/s and
    +-10 m/s; observations are clipped to them:

    | Num | Observation | Unit |
    |-----|-------------|------|
    | 0 | heading error ``ssa(psi_d - psi)`` | rad |
    | 1 | yaw rate ``r`` | rad/s |
    | 2 | azimuth of pod 1 (both are equal) | rad |
    | 3 | surge velocity ``u`` | m/s |
    | 4 | sway velocity ``v`` | m/s |

    ## Rewards

    ``-|psi_d - psi| / pi - 0.05 a^2`` per step, in [-1.05, 0].

    ## Starting State

    Heading uniform, moving straight at 5.14 m/s through the water (plus the current), pods at
    service thrust and zero azimuth. Current uniform in [0, ``max_current_speed``] (0.5 m/s),
    direction uniform.

    ## Episode End

    Truncation after 600 steps (300 s); termination only on a numerical blow-up.
    Once ``terminated`` is returned, a further ``step`` raises ``gymnasium.error.ResetNeeded``
    until ``reset``.

    ## Arguments

    ``gymnasium.make("shipgym/RVGHeading-v1", max_current_speed=0.5, max_azimuth=0.61,
    setpoint_interval=100.0, params="sea_trials", render_mode=None)``. Reset options and
    ``info`` as for ``NomotoHeading-v0``, with the Gunnerus' ``initial_state`` (``x``, ``y``,
    ``psi``, ``u``, ``v``, ``r``, ``T1``, ``T2``, ``alpha1``, ``alpha2``).

    Option ranges (a value outside raises ``ValueError`` naming the option, the value and the
    range), from the top speed V = 8.7 m/s (``thrust_zero_speed``: the pods push no more above
    it) and L = 33.9 m: ``current_speed`` in [0, 8.7] m/s (also the largest
    ``max_current_speed``); ``current_direction``, ``setpoints`` and ``psi`` within +-628.4 rad
    (100 turns); ``x``, ``y`` within +-2610 m (one episode at top speed); ``u``, ``v`` within
    +-13.05 m/s (1.5 V); ``r`` within +-0.5133 rad/s (2 V / L); ``T1``, ``T2`` in [0, 121700] N
    (the bollard thrust; [0, 85070] N with ``"sea_trials"``); ``alpha1``, ``alpha2`` within
    +-3.142 rad (``azimuth_max``). ``env.unwrapped.task.state_ranges()`` lists them.
    ``params`` selects the Gunnerus parameter set: ``"seed001"`` (seed 001, the default of ``-v0``),
    ``"sea_trials"`` (:meth:`shipgym.models.RVGParams.sea_trials`, identified from the sea
    trials, the default of ``-v1``) or an ``RVGParams``.

    ## Version History

    * v0: Initial version.
    * v1: R/V Gunnerus identified from its sea trials (``params="sea_trials"``) by default;
      the task, observations and rewards are those of v0.
    """

    task_cls = RVGHeadingTask

    @property
    def ship_dimensions(self) -> tuple[float, float]:
        return (LPP, BREADTH)

    def _draw_args(self, i: int) -> dict[str, Any]:
        return {"setpoint_heading": float(self.task.metrics(i)["heading_setpoint"])}


class RVGHeadingVectorEnv(ShipVectorEnv):
    """NumPy-batched ``shipgym/RVGHeading-v0`` (see :class:`RVGHeadingEnv`)."""

    task_cls = RVGHeadingTask
    single_env_cls = RVGHeadingEnv


__all__ = ["NomotoHeadingEnv", "NomotoHeadingVectorEnv", "RVGHeadingEnv", "RVGHeadingVectorEnv"]

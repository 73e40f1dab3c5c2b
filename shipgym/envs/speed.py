"""Speed environment ``shipgym/RVGSpeed-v0`` (seed 001 model, seed 004 section 1.2 task)."""

from __future__ import annotations

from shipgym.envs.core import ShipEnv, ShipVectorEnv
from shipgym.envs.tasks import RVGSpeedTask
from shipgym.models.rvg import BREADTH, LPP


class RVGSpeedEnv(ShipEnv):
    """
    ## Description

    R/V Gunnerus must reach and hold speed setpoints (speed through the water, what a speed
    log measures) with the thrust of its two pods, azimuths at zero. Two setpoints uniform in
    [1.5, 6] m/s, each held ``setpoint_interval`` seconds (200 s). One step is 0.5 s.

    ## Action Space

    ``Box(-1, 1, (1,), float32)``: common thrust command, -1 for zero thrust and +1 for the
    bollard thrust of 121.7 kN per pod; the physics limits it further to
    ``121.7 kN (1 - u_r / 8.7 m/s)``. Clipped to [-1, 1]; NaN or infinity raises ``ValueError``.

    ## Observation Space

    ``Box(low, high, (4,), float32)`` with bounds +-25 m/s, [-10, 15] m/s, [0, 1] and
    [0, 15] m/s; observations are clipped to them:

    | Num | Observation | Unit |
    |-----|-------------|------|
    | 0 | speed error ``u_d - u_r`` | m/s |
    | 1 | surge speed through the water ``u_r`` | m/s |
    | 2 | thrust of pod 1 over the bollard thrust | - |
    | 3 | speed setpoint ``u_d`` | m/s |

    ## Rewards

    ``-|u_d - u_r| / 2 - 0.05 (T / T_bollard)^2`` per step, with the speed error and the thrust
    fraction of the observation (clipped to +-25 m/s and [0, 1]): in [-12.55, 0].

    ## Starting State

    Heading uniform, straight ahead at a speed uniform in [0, 5] m/s through the water, zero
    thrust. Current uniform in [0, ``max_current_speed``] (0.5 m/s), direction uniform.

    ## Episode End

    Truncation after 800 steps (400 s); termination only on a numerical blow-up.
    Once ``terminated`` is returned, a further ``step`` raises ``gymnasium.error.ResetNeeded``
    until ``reset``.

    ## Arguments

    ``gymnasium.make("shipgym/RVGSpeed-v1", max_current_speed=0.5, setpoint_interval=200.0,
    params="sea_trials", render_mode=None)``. Reset options: ``current_speed``,
    ``current_direction``,
    ``initial_state``, ``setpoints`` (1 to 8 speeds [m/s]). ``info`` holds ``state``,
    the current, ``speed_error``, ``speed_setpoint`` and ``termination_reason``.
    At sea (``wind`` and ``sea_state``, in the constructor for every episode or in the reset
    options; :mod:`shipgym.models.seaway_options`, off by default) the observations are
    formed from the measured state (the wave-frequency motion added to heading, yaw rate and
    position), the reward from the low-frequency one, and ``info`` adds ``wind``,
    ``sea_state``, ``wave_motion`` and ``measured_state``.
    Option ranges (a value outside raises ``ValueError`` naming the option, the value and the
    range) as for ``RVGHeading-v0``, from the top speed V = 8.7 m/s (``thrust_zero_speed``),
    but positions ``x``, ``y`` within +-3480 m (one episode at top speed) and ``setpoints`` in
    [0, 8.7] m/s (no speed through the water above V is reachable): ``current_speed`` in
    [0, 8.7] m/s, ``current_direction`` and ``psi`` within +-628.4 rad, ``u``, ``v`` within
    +-13.05 m/s (1.5 V), ``r`` within +-0.5133 rad/s, ``T1``, ``T2`` in [0, 121700] N (bollard;
    [0, 85070] N with ``"sea_trials"``), ``alpha1``, ``alpha2`` within +-3.142 rad.
    ``params`` selects the Gunnerus parameter set: ``"seed001"`` (seed 001, the default of ``-v0``),
    ``"sea_trials"`` (:meth:`shipgym.models.RVGParams.sea_trials`, identified from the sea
    trials, the default of ``-v1``) or an ``RVGParams``.

    ## Version History

    * v0: Initial version.
    * v1: R/V Gunnerus identified from its sea trials (``params="sea_trials"``) by default;
      the task, observations and rewards are those of v0.
    """

    task_cls = RVGSpeedTask

    @property
    def ship_dimensions(self) -> tuple[float, float]:
        return (LPP, BREADTH)


class RVGSpeedVectorEnv(ShipVectorEnv):
    """NumPy-batched ``shipgym/RVGSpeed-v0`` (see :class:`RVGSpeedEnv`)."""

    task_cls = RVGSpeedTask
    single_env_cls = RVGSpeedEnv

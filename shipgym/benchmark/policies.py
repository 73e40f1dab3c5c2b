"""Policies for ``shipgym evaluate``: the classic controller of each env and the zero baseline.

A policy has ``reset(env, obs, info)`` (``env`` is the unwrapped shipgym env) and
``act(obs, info) -> action`` (normalised, as the env takes it). The classic policies are thin
adapters: they read the measurements a ship has (heading, yaw rate, speed, position; for target
tracking the target's relative position and velocity as radar/AIS give them) from ``info`` and
the observation, run the controllers of :mod:`controllers`, and scale the physical commands to
the env's actions with :class:`controllers.PodCommand`.

Every classic controller is designed on the env's **nominal ship** (its default model or
parameter set, as the agents are trained on it), so a model-mismatch condition tests gains and
agents the same way. Its few design parameters (:attr:`DESIGN` of each class) come in two sets:

``classic``: the design rules, per env:

* NomotoHeading: PID by pole placement (seed 004 eq. 7) on the first-order Nomoto model that
  matches the ship's linear yaw response at the design bandwidth
  (:func:`controllers.design_model`); bandwidth ``w_n = sqrt(1 / (|T| T_a))`` between the
  ship's and the actuator's time constants (Fossen's rule, :func:`controllers.default_bandwidth`,
  ``T_a`` the rudder's full-scale slew time), damping 0.8, reference model at ``w_n``.
* RVGHeading: the same pole placement on the first-order model that keeps the dominant
  sway-yaw pole of the linearised 3-DOF Gunnerus (:func:`rvg_heading_nomoto`); bandwidth by
  the same rule (for seed 001's directionally unstable ship at least ``2 / |T|``: the loop
  must outrun the divergence); a slow step reference (0.1 rad/s, turn rate 0.03 rad/s) so
  that a 90 deg step never overshoots.
* RVGSpeed: PI by pole placement on the surge dynamics linearised at 4 m/s (seed 004 eq. 8),
  ``w_n`` 0.1 rad/s (ten times the surge pole), critically damped, with the resistance
  feed-forward of the nominal ship.
* RVGPathFollowing: lookahead LOS with the conditional integrator (seed 004 eq. 9-10),
  lookahead three ship lengths, the heading autopilot above with a faster reference (0.3
  rad/s, 0.04 rad/s) so the heading loop stays inside the guidance loop, speed autopilot at
  the service speed.
* RVGTargetTracking: constant-bearing guidance (seed 004 eq. 11) with an approach speed of 2
  m/s and ``Delta`` 100 m, heading autopilot with the step reference, no thrust floor.

``classic-tuned``: the same structures with design parameters chosen by a grid search on the
RL training seeds (:mod:`shipgym.benchmark.tuning`); the chosen values and the search's record
ship in ``shipgym/benchmark/tuned/``.

``classic-wf``: the ``classic`` controllers with a wave filter in their heading loop
(``wave_filter=True`` of the classic policies, :class:`HeadingWaveFilter`): at sea the
autopilot (and the path and target guidance) gets the filter's low-frequency heading and yaw
rate instead of the measured ones, which carry the wave-frequency motion. The filter is
:class:`controllers.WaveFilter` on the first-order Nomoto model the autopilot is designed on,
tuned per ship by Fossen's rule from the sea state in ``info``; a ship in calm water gets the
measured heading unchanged. The speed autopilot has no heading loop: there ``classic-wf`` is
``classic``.

``classic`` with a gains file (``make_policy(..., gains=FILE)``, ``shipgym evaluate --gains``;
NomotoHeading only): the same autopilot with exactly the gains, reference model, limits and
offset of a gains document that ``shipgym design MODEL.json --json FILE`` wrote for an
identified ship (:mod:`shipgym.benchmark.design`), :class:`NomotoHeadingGains`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import cache
from pathlib import Path
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from controllers import (
    ConstantBearingGuidance,
    HeadingAutopilot,
    SpeedAutopilot,
    WaveFilter,
    course_and_speed,
    design_model,
    linearised_drag_model,
    pod_env_actions,
)
from controllers.los import LOSGuidance
from controllers.paths import WaypointPath
from shipgym.envs import ENV_IDS, env_task
from shipgym.models import make_model
from shipgym.models.model_file import is_model_file
from shipgym.models.rvg import IA1, IA2, IR, IT1, IT2, IU, IV, LPP, SERVICE_SPEED, RVGParams
from shipgym.models.seaway import GAIN_ANGLES, MIN_ENCOUNTER_FREQUENCY, wave_motion_gains
from shipgym.models.waves import SeaState, encounter_angle, encounter_frequency


@cache
def rvg_heading_nomoto(
    speed: float = SERVICE_SPEED, params: str = "seed001"
) -> tuple[float, float]:
    """First-order Nomoto ``(K, T)`` of the Gunnerus from common azimuth to yaw rate.

    The 3-DOF model with the parameter set ``params`` is linearised at straight running at
    ``speed`` (pods at the thrust that holds it). ``T = -1 / lambda`` keeps the dominant
    sway-yaw eigenvalue ``lambda`` (the largest real part: unstable, ``T < 0``, for seed 001's
    parameters; stable, ``T`` 4.8 s, for the sea-trial ship) and ``K / T`` is the initial yaw
    acceleration per radian of azimuth, so ``K / T < 0`` (positive azimuth turns to port).
    """
    ship = make_model("rvg3dof", params=params)
    thrust = ship.params.straight_thrust(speed)
    x0 = np.zeros(ship.nx)
    x0[IU], x0[IT1], x0[IT2] = speed, thrust, thrust
    A, _ = ship.linearize(x0, [thrust, thrust, 0.0, 0.0])
    sway_yaw = A[np.ix_([IV, IR], [IV, IR])]
    lam = float(np.max(np.linalg.eigvals(sway_yaw).real))
    if lam == 0:
        raise ValueError("the sway-yaw dynamics have a zero eigenvalue: no Nomoto time constant")
    T = -1.0 / lam
    yaw_accel_per_azimuth = A[IR, IA1] + A[IR, IA2]
    return float(yaw_accel_per_azimuth * T), T


def nomoto_heading_autopilot(
    model: Any,
    dt: float,
    omega_n: float | None = None,
    zeta: float = 0.8,
    reference_ratio: float = 1.0,
) -> HeadingAutopilot:
    """The heading autopilot of a Nomoto-family ship: pole placement on the first-order model
    that matches the ship's linear yaw response at the design bandwidth
    (:func:`controllers.design_model`; the bandwidth from the steering gear and the ship
    unless ``omega_n`` is given), damping ``zeta``, reference model at ``reference_ratio``
    times the bandwidth (0: none)."""
    limits = steering_limits(model)
    K, T, omega = nomoto_design_model(model, omega_n)
    return HeadingAutopilot.from_nomoto(
        K, T, dt, omega_n=omega, zeta=zeta, reference_omega=reference_ratio * omega, **limits
    )


def nomoto_design_model(model: Any, omega_n: float | None = None) -> tuple[float, float, float]:
    """``(K, T, omega_n)``: the first-order Nomoto model of a Nomoto-family ship that matches
    its linear yaw response at the design bandwidth (:func:`controllers.design_model`; the
    bandwidth from the steering gear and the ship unless ``omega_n`` is given)."""
    K, T1, T2, T3, n1 = nomoto_linear_yaw(model)
    return design_model(K, T1, T2, T3, n1=n1, omega=omega_n, **steering_limits(model))


def nomoto_linear_yaw(model: Any) -> tuple[float, float, float, float, float]:
    """``(K, T1, T2, T3, n1)`` of a Nomoto-family ship's yaw response linearised about
    straight running, ``r / delta = K (1 + T3 s) / (T1 T2 s^2 + (T1 + T2) s + n1)`` (the
    arguments of :func:`controllers.design_model`): ``(K, T, 0, 0, n1)`` for the first-order
    Nomoto (``n1 = 1``) and Norrbin models, ``(K, T1, T2, T3, 1)`` for the second-order
    Nomoto and ``n1 = K b1`` for Bech's."""
    y = model.params
    if hasattr(y, "T1"):  # second-order Nomoto, Bech (linear part K b1 r)
        n1 = y.K * y.b1 if hasattr(y, "b1") else 1.0
        return float(y.K), float(y.T1), float(y.T2), float(y.T3), float(n1)
    # first-order Nomoto, Norrbin (linear part n1 r)
    return float(y.K), float(y.T), 0.0, 0.0, float(getattr(y, "n1", 1.0))


def steering_limits(model: Any) -> dict[str, float]:
    """The steering gear of a Nomoto-family ship as the keyword arguments of the design rule:
    ``actuator_time_constant`` [s], ``max_command`` [rad], ``max_rate`` [rad/s]."""
    gear = model.gear
    return {
        "actuator_time_constant": float(gear.time_constant),
        "max_command": float(gear.max_angle),
        "max_rate": float(gear.max_rate),
    }


def _rvg_heading_autopilot(
    dt: float,
    max_azimuth: float,
    params: str,
    omega_n: float | None,
    reference_omega: float,
    max_turn_rate: float,
) -> HeadingAutopilot:
    K, T = rvg_heading_nomoto(params=params)
    p = RVGParams.named(params)
    return HeadingAutopilot.from_nomoto(
        K,
        T,
        dt,
        omega_n=omega_n,
        reference_omega=reference_omega,
        max_turn_rate=max_turn_rate,
        max_command=max_azimuth,
        max_rate=p.azimuth_max_rate,
        actuator_time_constant=p.azimuth_time_constant,
    )


def _rvg_speed_autopilot(
    dt: float,
    params: str,
    omega_n: float,
    zeta: float,
    design_speed: float = 4.0,
    min_thrust: float = 0.0,
) -> SpeedAutopilot:
    """PI on each pod's thrust with the nominal ship's resistance as feed-forward; the
    design model is the surge dynamics linearised at ``design_speed``. ``min_thrust`` is the
    least thrust commanded, as a fraction of the service thrust."""
    p = RVGParams.named(params)
    mass = p.mass + p.added_mass[0, 0]
    h = 1e-3 * design_speed
    slope = (p.straight_resistance(design_speed + h) - p.straight_resistance(design_speed - h)) / (
        2.0 * h
    )
    K, T = linearised_drag_model(
        mass, slope, 0.0, design_speed, share=0.5 / (1.0 - p.thrust_deduction)
    )
    return SpeedAutopilot.from_first_order(
        K,
        T,
        dt,
        omega_n=omega_n,
        zeta=zeta,
        feedforward=p.straight_thrust,
        min_command=min_thrust * p.service_thrust,
        max_command=p.max_thrust,
    )


def _measured(info: dict[str, Any]) -> np.ndarray:
    """The states as the ships' sensors give them, one row per ship:
    ``info["measured_state"]`` under sensor noise, else the env's states."""
    return info.get("measured_state", info["state"])


def _speed_through_water(state: np.ndarray, speed: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Surge speed through the water [m/s] of each ship in a current of ``speed`` toward
    ``direction``."""
    return state[:, IU] - speed * np.cos(direction - state[:, 2])


def _rows(info: dict[str, Any]) -> dict[str, Any]:
    """A single env's ``info`` as the vector ``info`` of a batch of one."""
    return {key: np.asarray(value)[None] for key, value in info.items()}


#: Steps of the wave filter's gain schedule: a ship's filter is designed anew when its
#: encounter peak frequency moves by a step of 5 % or its expected WF heading by one of 10 %
#: (the designs are kept, so a ship back on an old course costs nothing).
SCHEDULE_FREQUENCY_STEP = math.log(1.05)
SCHEDULE_STD_STEP = math.log(1.1)
#: Least WF heading standard deviation [rad] the filter is designed for (head and following
#: seas turn the ship little: the filter then passes the heading nearly unchanged).
MIN_WAVE_HEADING_STD = math.radians(0.02)


@cache
def _yaw_gains(height: float, period: float, length: float) -> np.ndarray:
    """Signed RMS WF yaw per metre of ``H_s / 4`` over :data:`GAIN_ANGLES` (JONSWAP, gamma
    3.3) of a ship of length ``length`` [m]."""
    return wave_motion_gains(SeaState(height, period, 0.0), length)[1]


class HeadingWaveFilter:
    """The wave filter of a classic heading loop: :class:`controllers.WaveFilter` on the
    first-order Nomoto model ``K, T`` the autopilot is designed on, one wave model per ship.

    Design rule (Fossen 2021, section 13.3): the wave model's frequency is the encounter peak
    frequency ``omega_e = |omega_p - omega_p^2 U cos(beta) / g|`` (at least
    :data:`~shipgym.models.seaway.MIN_ENCOUNTER_FREQUENCY`) of the sea state in ``info``
    (``omega_p = 2 pi / T_p``, the direction the waves travel to) at the ship's estimated
    LF heading and measured speed through the water ``U``; its standard deviation the WF
    heading expected there, ``H_s / 4`` times the ship's RMS yaw per metre
    (:func:`~shipgym.models.seaway.wave_motion_gains`, JONSWAP with gamma 3.3) at the
    encounter angle ``beta`` (at least :data:`MIN_WAVE_HEADING_STD`); damping 0.1. The design
    is gain-scheduled on the ship's heading and speed (:data:`SCHEDULE_FREQUENCY_STEP`,
    :data:`SCHEDULE_STD_STEP`). A ship with no waves (``H_s = 0``, or no ``sea_state`` in
    ``info``) gets its measured heading and yaw rate unchanged.

    Parameters
    ----------
    K, T : float
        The Nomoto model [1/s, s] from the rudder (the pods' common azimuth) to yaw rate.
    dt : float
        Control step [s].
    length : float
        The ship's waterline length [m] (its yaw in waves).
    """

    def __init__(self, K: float, T: float, dt: float, length: float) -> None:
        self.K, self.T, self.dt, self.length = K, T, dt, length
        self.filter: WaveFilter | None = None

    def _design(self, psi: np.ndarray, speed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each ship's schedule indices (frequency, standard deviation) at heading ``psi``
        and speed ``speed``."""
        beta = encounter_angle(self.direction, psi)
        omega = np.maximum(
            np.abs(encounter_frequency(self.peak, speed, beta)), MIN_ENCOUNTER_FREQUENCY
        )
        # each ship's yaw gain at its encounter angle, interpolated in its own table row
        t = (beta - GAIN_ANGLES[0]) / (GAIN_ANGLES[1] - GAIN_ANGLES[0])
        k = np.clip(np.floor(t).astype(np.int64), 0, GAIN_ANGLES.size - 2)
        rows = np.arange(len(psi))
        low, high = self.yaw_gains[rows, k], self.yaw_gains[rows, k + 1]
        std = np.abs(low + (t - k) * (high - low)) * self.height / 4.0
        return (
            np.round(np.log(omega) / SCHEDULE_FREQUENCY_STEP),
            np.round(np.log(np.maximum(std, MIN_WAVE_HEADING_STD)) / SCHEDULE_STD_STEP),
        )

    def _retune(self, psi: np.ndarray, speed: np.ndarray) -> None:
        """Design the filters of the ships at sea whose schedule step changed."""
        assert self.filter is not None
        f_idx, s_idx = self._design(psi, speed)
        changed = self.at_sea & ((f_idx != self.schedule[0]) | (s_idx != self.schedule[1]))
        if changed.any():
            rows = np.flatnonzero(changed)
            self.filter.retune(
                rows,
                np.exp(f_idx[rows] * SCHEDULE_FREQUENCY_STEP),
                np.exp(s_idx[rows] * SCHEDULE_STD_STEP),
            )
            self.schedule[0][rows], self.schedule[1][rows] = f_idx[rows], s_idx[rows]

    def reset(
        self, info: dict[str, Any], psi: np.ndarray, r: np.ndarray, speed: np.ndarray
    ) -> None:
        """Start the episodes of every ship: the sea state of each from ``info``, the
        estimates at the measured heading ``psi`` and yaw rate ``r``."""
        n = len(psi)
        sea = np.asarray(info.get("sea_state", np.zeros((n, 3))), dtype=float)
        self.height, self.period, self.direction = sea[:, 0], sea[:, 1], sea[:, 2]
        self.at_sea = self.height > 0.0
        if not self.at_sea.any():
            self.filter = None
            return
        self.peak = 2.0 * math.pi / np.where(self.at_sea, self.period, 2.0 * math.pi)
        #: each ship's yaw gains over GAIN_ANGLES (a table per sea, made once per sea)
        self.yaw_gains = np.array([
            _yaw_gains(h, t, self.length) if h > 0.0 else np.zeros(GAIN_ANGLES.size)
            for h, t in zip(self.height, self.period, strict=True)
        ])  # fmt: skip
        self.filter = WaveFilter(
            self.K, self.T, self.dt, np.ones(n), np.full(n, MIN_WAVE_HEADING_STD)
        )
        self.schedule = (np.full(n, np.nan), np.full(n, np.nan))
        self._retune(psi, speed)
        self.filter.reset(psi, r)

    def update(
        self, psi: np.ndarray, r: np.ndarray, rudder: np.ndarray, speed: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The LF heading and yaw rate of every ship from its measured heading ``psi``, yaw
        rate ``r`` (passed through for ships in calm water), the rudder ``rudder`` [rad] it
        held over the step just ended and its speed through the water ``speed`` [m/s]."""
        if self.filter is None:
            return psi, r
        psi_f, r_f = self.filter.update(psi, rudder)
        self._retune(psi_f, speed)
        return np.where(self.at_sea, psi_f, psi), np.where(self.at_sea, r_f, r)


class ZeroPolicy:
    """The neutral command: rudder or azimuth amidships, half the thrust range (action 0)."""

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        self.act_dim = env.action_space.shape[-1]

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        return np.zeros(self.act_dim, dtype=np.float32)

    def act_batch(self, obs: np.ndarray) -> np.ndarray:
        return np.zeros((len(obs), self.act_dim), dtype=np.float32)


class ClassicPolicy:
    """Base of the classic policies: the nominal ship and the design parameters.

    A classic policy runs a batch of ships: ``reset_vector(env, obs, info)`` with the env (a
    vector env, or a single env: its task holds the ships) and the ``obs`` and vector ``info``
    of every ship, then ``act_vector(obs, info)`` returns one action row per ship. Each ship's
    controllers are the arrays' rows, so a ship's actions depend on its own measurements
    only. ``reset(env, obs, info)`` and ``act(obs, info)`` run one ship (a single env) as a
    batch of one.

    Parameters
    ----------
    nominal : str
        The nominal ship the controller is designed on: a Nomoto-family model name for the
        Nomoto env, an RVG parameter set name (``"seed001"``, ``"sea_trials"``) for the
        Gunnerus envs.
    wave_filter : bool
        Feed the heading loop the low-frequency heading and yaw rate of a
        :class:`HeadingWaveFilter` instead of the measured ones (``classic-wf``).
    **design : float
        Values for some of :attr:`DESIGN` (the rest keep their design-rule values).
    """

    #: Design parameters and their design-rule values (``None``: computed by the rule).
    DESIGN: ClassVar[dict[str, float | None]] = {}
    #: Default nominal ship.
    NOMINAL: ClassVar[str] = "seed001"

    def __init__(
        self, nominal: str | None = None, *, wave_filter: bool = False, **design: float | None
    ) -> None:
        unknown = sorted(set(design) - set(self.DESIGN))
        if unknown:
            raise ValueError(
                f"{type(self).__name__}: unknown design parameter(s) {unknown}; expected some "
                f"of {sorted(self.DESIGN)}"
            )
        for key, value in design.items():
            if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value)):
                raise ValueError(f"design parameter {key} must be a finite number, got {value!r}")
        self.nominal = nominal or self.NOMINAL
        self.design: dict[str, Any] = {**self.DESIGN, **design}
        self.wave_filter = bool(wave_filter)
        self.filter: HeadingWaveFilter | None = None

    def _start_filter(
        self, env: Any, info: dict[str, Any], K: float, T: float, psi: np.ndarray,
        r: np.ndarray, speed: np.ndarray,
    ) -> None:  # fmt: skip
        """Make and start the heading loop's wave filter (if :attr:`wave_filter`) on the
        Nomoto model ``K, T``, for the ships of ``env``'s task."""
        if not self.wave_filter:
            self.filter = None
            return
        task = env.task
        length = task.seaway_ship().length if task.seaway_ship is not None else 1.0
        self.filter = HeadingWaveFilter(K, T, task.dt, length)
        self.filter.reset(info, psi, r, speed)

    def _filtered(
        self, psi: np.ndarray, r: np.ndarray, rudder: np.ndarray, speed: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The heading and yaw rate the heading loop gets: the wave filter's estimates, or
        the measured ones without a filter."""
        if self.filter is None:
            return psi, r
        return self.filter.update(psi, r, rudder, speed)

    def _start_rvg_filter(self, env: Any, info: dict[str, Any], state: np.ndarray) -> None:
        """:meth:`_start_filter` of a Gunnerus heading loop: the Nomoto model of the nominal
        parameter set (:func:`rvg_heading_nomoto`), the pods' common azimuth as the rudder."""
        if self.wave_filter:
            K, T = rvg_heading_nomoto(params=self.nominal)
            speed = _speed_through_water(state, info["current_speed"], info["current_direction"])
            self._start_filter(env, info, K, T, state[:, 2], state[:, IR], speed)

    def _rvg_filtered(self, info: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        """The heading and yaw rate a Gunnerus heading loop gets (:meth:`_filtered`)."""
        state = _measured(info)
        if self.filter is None:
            return state[:, 2], state[:, IR]
        azimuth = 0.5 * (state[:, IA1] + state[:, IA2])
        speed = _speed_through_water(state, info["current_speed"], info["current_direction"])
        return self._filtered(state[:, 2], state[:, IR], azimuth, speed)

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        """Start an episode of one ship (a single env): a batch of one."""
        self.reset_vector(env, np.asarray(obs)[None], _rows(info))

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """The action of one ship (a single env)."""
        return self.act_vector(np.asarray(obs)[None], _rows(info))[0]

    def reset_vector(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        """Start the episodes of every ship of ``env``'s task."""
        raise NotImplementedError

    def act_vector(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """The actions of every ship, shape ``(n, act_dim)``."""
        raise NotImplementedError


class NomotoHeadingClassic(ClassicPolicy):
    """PID autopilot by pole placement on the ship's Nomoto ``K, T`` (seed 004 eq. 7).

    Design parameters: ``omega_n`` (closed-loop bandwidth [rad/s]; ``None``: Fossen's rule
    from the steering gear and the ship), ``zeta`` (closed-loop damping) and
    ``reference_ratio`` (reference-model frequency as a multiple of ``omega_n``; 0: none).
    """

    DESIGN: ClassVar[dict[str, float | None]] = {
        "omega_n": None, "zeta": 0.8, "reference_ratio": 1.0,
    }  # fmt: skip
    NOMINAL: ClassVar[str] = "nomoto1"

    def reset_vector(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        model = env.task.model
        self.max_angle = model.gear.max_angle
        self.dt = env.task.dt
        self.ipsi, self.ir = model.index("psi"), model.index("r")
        self.iu, self.idelta = model.index("U"), model.index("delta")
        self.pilot = self._autopilot(model, self.dt)
        state = _measured(info)
        psi, r = state[:, self.ipsi], state[:, self.ir]
        self.pilot.reset(psi, r, t=0.0)
        if self.wave_filter:
            K, T, _ = nomoto_design_model(self._nominal(model), self.design["omega_n"])
            self._start_filter(env, info, K, T, psi, r, state[:, self.iu])
        self.t = 0.0

    def _nominal(self, model: Any) -> Any:
        """The nominal ship (with the env's gear and speed)."""
        return (
            make_model(self.nominal)  # an identified ship: its own gear, speed and delay
            if is_model_file(self.nominal)
            else make_model(self.nominal, gear=model.gear, surge=model.surge)
        )

    def _autopilot(self, model: Any, dt: float) -> HeadingAutopilot:
        """The design rule on the nominal ship (with the env's gear and speed)."""
        return nomoto_heading_autopilot(self._nominal(model), dt, **self.design)

    def act_vector(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        state = _measured(info)
        psi, r = self._filtered(
            state[:, self.ipsi], state[:, self.ir], state[:, self.idelta], state[:, self.iu]
        )
        delta = self.pilot.update(self.t, psi, r, info["heading_setpoint"])
        self.t += self.dt
        return (delta / self.max_angle).astype(np.float32)[:, None]


#: ``kind`` of the gains document that ``shipgym design --json`` writes
#: (:meth:`shipgym.benchmark.design.HeadingAutopilotDesign.gains_document`) and
#: ``make_policy("classic", ..., gains=...)`` reads.
GAINS_KIND = "shipgym heading autopilot gains"
#: The env and controller structure of a gains document: the classic policy of
#: ``shipgym/NomotoHeading-v0``, a :class:`controllers.HeadingAutopilot` (PID on the heading
#: error with the yaw rate fed back, third-order reference model, rudder limits).
GAINS_ENV = "shipgym/NomotoHeading-v0"
GAINS_STRUCTURE = "HeadingAutopilot"
#: The ``autopilot`` section of a gains document: keyword arguments of
#: :class:`controllers.HeadingAutopilot` and their units (``reference_omega``, ``max_command``,
#: ``max_rate`` may be ``null``: none).
GAINS_UNITS: dict[str, str] = {
    "kp": "rad/rad", "ki": "rad/(rad s)", "kd": "rad s/rad", "reference_omega": "rad/s",
    "reference_zeta": "-", "max_command": "rad", "max_rate": "rad/s", "offset": "rad",
    "anti_windup": "back_calculation|conditional|none",
}  # fmt: skip


def heading_gains_document(
    pilot: HeadingAutopilot, design: Mapping[str, Any] | None = None
) -> dict[str, Any]:
    """The gains document of ``pilot`` (JSON-ready): ``kind``, ``env``, ``controller``,
    ``structure``, ``autopilot`` (the gains, reference model, limits and offset, SI units as
    in :data:`GAINS_UNITS`), ``units`` and, if given, ``design`` (informative, not read)."""

    def limit(value: float) -> float | None:
        return float(value) if math.isfinite(value) else None

    ref = pilot.reference
    doc: dict[str, Any] = {
        "kind": GAINS_KIND,
        "env": GAINS_ENV,
        "controller": "classic",
        "structure": GAINS_STRUCTURE,
        "autopilot": {
            "kp": pilot.kp,
            "ki": pilot.ki,
            "kd": pilot.kd,
            "reference_omega": None if ref is None else ref.omega,
            "reference_zeta": 1.0 if ref is None else ref.zeta,
            "max_command": limit(pilot.max_command),
            "max_rate": limit(pilot.max_rate),
            "offset": pilot.offset,
            "anti_windup": pilot.anti_windup,
        },
        "units": dict(GAINS_UNITS),
    }
    if design is not None:
        doc["design"] = dict(design)
    return doc


def load_gains(source: str | Path | Mapping[str, Any], env_id: str = GAINS_ENV) -> dict[str, Any]:
    """The ``autopilot`` section of a gains document, checked for ``env_id``.

    Parameters
    ----------
    source : str, Path or Mapping
        A gains file (``shipgym design MODEL.json --json FILE``) or its parsed document.
    env_id : str
        The env the gains are to run on.

    Returns
    -------
    dict
        Keyword arguments of :class:`controllers.HeadingAutopilot` (without ``dt``).

    Raises
    ------
    ValueError
        For a missing or unreadable file, a file that is not JSON or not a gains document,
        gains for another env or controller structure, and bad values.
    """
    import json

    if isinstance(source, Mapping):
        doc: Any = source
        where = "the gains document"
    else:
        path = Path(source)
        where = f"gains file {str(path)!r}"
        if not path.is_file():
            raise ValueError(f"{where} does not exist (write one with shipgym design ... --json)")
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise ValueError(f"{where} is not readable JSON: {exc}") from None
    if not isinstance(doc, Mapping) or doc.get("kind") != GAINS_KIND:
        kind = doc.get("kind") if isinstance(doc, Mapping) else type(doc).__name__
        raise ValueError(
            f"{where} is not a heading autopilot gains document (kind {kind!r}, expected "
            f"{GAINS_KIND!r}: written by shipgym design MODEL.json --json FILE)"
        )
    if doc.get("env") != env_id:
        raise ValueError(f"{where} holds gains for env {doc.get('env')!r}, not for {env_id!r}")
    structure = (doc.get("controller"), doc.get("structure"))
    if structure != ("classic", GAINS_STRUCTURE):
        raise ValueError(
            f"{where} holds controller {structure[0]!r} with structure {structure[1]!r}; the "
            f"classic policy of {env_id} is 'classic' with structure {GAINS_STRUCTURE!r}"
        )
    autopilot = doc.get("autopilot")
    keys = set(autopilot) if isinstance(autopilot, Mapping) else set()
    if keys != set(GAINS_UNITS):
        raise ValueError(
            f"{where}: the autopilot section must have the keys {sorted(GAINS_UNITS)}, got "
            f"{sorted(keys) if isinstance(autopilot, Mapping) else type(autopilot).__name__}"
        )
    gains = dict(autopilot)
    for key, value in gains.items():
        nullable = key in ("reference_omega", "max_command", "max_rate")
        if key == "anti_windup" or (nullable and value is None):
            continue
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(f"{where}: autopilot {key} must be a number, got {value!r}")
    try:
        heading_autopilot_from_gains(gains, 1.0)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    return gains


def heading_autopilot_from_gains(
    gains: Mapping[str, Any],
    dt: float,
    *,
    max_command: float | None = None,
    max_rate: float | None = None,
) -> HeadingAutopilot:
    """The :class:`controllers.HeadingAutopilot` of a gains document's ``autopilot`` section
    (:func:`load_gains`) with sample time ``dt`` [s]. ``max_command`` [rad] and ``max_rate``
    [rad/s] are the actuator's limits: where they are tighter than the document's, they
    count (the anti-windup must see the limit the rudder really has)."""
    g = dict(gains)

    def tighter(mine: float | None, theirs: float | None) -> float | None:
        values = [v for v in (mine, theirs) if v is not None]
        return min(values) if values else None

    return HeadingAutopilot(
        g["kp"],
        g["ki"],
        g["kd"],
        dt,
        reference_omega=g["reference_omega"],
        reference_zeta=g["reference_zeta"],
        max_command=tighter(g["max_command"], max_command),
        max_rate=tighter(g["max_rate"], max_rate),
        offset=g["offset"],
        anti_windup=g["anti_windup"],
    )


class NomotoHeadingGains(NomotoHeadingClassic):
    """The classic NomotoHeading policy with the gains of a gains document (``shipgym design
    MODEL.json --json FILE``) instead of the design rule on the nominal ship.

    Parameters
    ----------
    gains : Mapping
        The document's ``autopilot`` section (:func:`load_gains`). The env's steering gear
        limits the command where it is tighter than the document's limits.
    """

    def __init__(self, gains: Mapping[str, Any]) -> None:
        super().__init__()
        self.gains = dict(gains)

    def _autopilot(self, model: Any, dt: float) -> HeadingAutopilot:
        """The document's gains, limited by the env's steering gear."""
        gear = model.gear
        return heading_autopilot_from_gains(
            self.gains, dt, max_command=gear.max_angle, max_rate=gear.max_rate
        )


class RVGHeadingClassic(ClassicPolicy):
    """Gunnerus heading autopilot on the common pod azimuth.

    Design parameters: ``omega_n`` (bandwidth [rad/s]; ``None``: the rule), and the reference
    model's ``reference_omega`` [rad/s] and turn-rate limit ``max_turn_rate`` [rad/s].
    """

    DESIGN: ClassVar[dict[str, float | None]] = {
        "omega_n": None, "reference_omega": 0.1, "max_turn_rate": 0.03,
    }  # fmt: skip

    def reset_vector(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        self.dt = env.task.dt
        self.max_azimuth = env.task.max_azimuth
        self.pilot = _rvg_heading_autopilot(self.dt, self.max_azimuth, self.nominal, **self.design)
        state = _measured(info)
        self.pilot.reset(state[:, 2], state[:, IR], t=0.0)
        self._start_rvg_filter(env, info, state)
        self.t = 0.0

    def act_vector(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        psi, r = self._rvg_filtered(info)
        azimuth = self.pilot.update(self.t, psi, r, info["heading_setpoint"])
        self.t += self.dt
        return pod_env_actions(azimuth, 0.0, "heading", max_azimuth=self.max_azimuth)


class RVGSpeedClassic(ClassicPolicy):
    """PI speed autopilot with resistance feed-forward on the speed through the water.

    Design parameters: ``omega_n`` [rad/s] and ``zeta`` of the speed loop.
    """

    DESIGN: ClassVar[dict[str, float | None]] = {"omega_n": 0.1, "zeta": 1.0}

    def reset_vector(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        self.dt = env.task.dt
        self.pilot = _rvg_speed_autopilot(self.dt, self.nominal, **self.design)
        self.pilot.reset(t=0.0, integral=np.zeros(len(obs)))
        self.t = 0.0

    def act_vector(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        obs = np.asarray(obs, dtype=np.float64)
        thrust = self.pilot.update(self.t, obs[:, 1], obs[:, 3])
        self.t += self.dt
        return pod_env_actions(0.0, thrust, "speed")


class RVGPathClassic(ClassicPolicy):
    """Lookahead LOS with the conditional integrator commanding the heading autopilot.

    As in seed 004 the LOS output is used as the heading setpoint (not course over ground);
    the integrator learns the crab angle that a current needs. A speed autopilot holds the
    service speed through the water. Design parameters: ``lookahead_lengths`` (LOS lookahead
    in ship lengths), the heading loop's ``omega_n``, ``reference_omega`` and
    ``max_turn_rate``.
    """

    DESIGN: ClassVar[dict[str, float | None]] = {
        "lookahead_lengths": 3.0, "omega_n": None, "reference_omega": 0.3, "max_turn_rate": 0.04,
    }  # fmt: skip

    def __init__(
        self,
        nominal: str | None = None,
        integral: bool = True,
        *,
        wave_filter: bool = False,
        **design: float | None,
    ) -> None:
        super().__init__(nominal, wave_filter=wave_filter, **design)
        self.integral = integral

    def reset_vector(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        task = env.task
        self.dt = task.dt
        self.max_azimuth = task.max_azimuth
        d = dict(self.design)
        self.guidance = LOSGuidance(
            [WaypointPath(task.waypoints(i)) for i in range(len(obs))],
            d.pop("lookahead_lengths") * LPP,
            integral=self.integral,
            design_speed=SERVICE_SPEED,
            switching="circle",
            acceptance_radius=task.accept_radius,
        )
        self.heading = _rvg_heading_autopilot(self.dt, task.max_azimuth, self.nominal, **d)
        self.speed = _rvg_speed_autopilot(self.dt, self.nominal, **RVGSpeedClassic.DESIGN)
        state = _measured(info)
        self.heading.reset(state[:, 2], state[:, IR], t=0.0)
        self.speed.reset(t=0.0, integral=np.zeros(len(obs)))
        self._start_rvg_filter(env, info, state)
        self.t = 0.0

    def act_vector(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        state = _measured(info)
        psi, r = self._rvg_filtered(info)
        chi_d = self.guidance.update(self.t, state[:, :2], psi, r)
        azimuth = self.heading.update(self.t, psi, r, chi_d)
        through_water = _speed_through_water(
            state, info["current_speed"], info["current_direction"]
        )
        thrust = self.speed.update(self.t, through_water, SERVICE_SPEED)
        self.t += self.dt
        return pod_env_actions(azimuth, thrust, "path", max_azimuth=self.max_azimuth)


class RVGTargetClassic(ClassicPolicy):
    """Constant-bearing guidance (seed 004 eq. 11) commanding heading and speed autopilots.

    The guidance gives a course and a speed over ground; the heading setpoint is that course
    minus the measured crab angle, and the speed autopilot holds the speed over ground.
    Design parameters: ``approach_speed`` (``U_a,max`` [m/s]), ``delta`` (``Delta`` [m]),
    ``min_thrust`` (the least thrust the speed loop commands, a fraction of the service
    thrust: azimuth pods steer with their thrust, so a floor keeps some to turn with while the
    ship slows down, at the price of holding station behind a slow target) and the heading
    loop's ``omega_n``, ``reference_omega``, ``max_turn_rate``.
    """

    DESIGN: ClassVar[dict[str, float | None]] = {
        "approach_speed": 2.0, "delta": 100.0, "min_thrust": 0.0, "omega_n": None,
        "reference_omega": 0.1, "max_turn_rate": 0.03,
    }  # fmt: skip

    def reset_vector(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        task = env.task
        self.dt = task.dt
        self.max_azimuth = task.max_azimuth
        d = dict(self.design)
        self.guidance = ConstantBearingGuidance(
            d.pop("approach_speed"), d.pop("delta"), task.distance[: len(obs)].copy(),
            max_speed=6.0, dt=self.dt,
        )  # fmt: skip
        min_thrust = d.pop("min_thrust")
        self.heading = _rvg_heading_autopilot(self.dt, task.max_azimuth, self.nominal, **d)
        self.speed = _rvg_speed_autopilot(
            self.dt, self.nominal, **RVGSpeedClassic.DESIGN, design_speed=3.0,
            min_thrust=min_thrust,
        )  # fmt: skip
        state = _measured(info)
        self.heading.reset(state[:, 2], state[:, IR], t=0.0)
        self.speed.reset(t=0.0, integral=np.zeros(len(obs)))
        self._start_rvg_filter(env, info, state)
        self.t = 0.0

    def act_vector(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        state = _measured(info)
        psi, r = self._rvg_filtered(info)
        c, s = np.cos(psi), np.sin(psi)

        def to_ned(a: np.ndarray, b: np.ndarray) -> np.ndarray:  # body frame -> NED, (n, 2)
            # in the precision of the inputs: the float32 observations rotate in float32
            cc, ss = c.astype(a.dtype), s.astype(a.dtype)
            return np.stack([cc * a - ss * b, ss * a + cc * b], axis=1)

        obs = np.asarray(obs)
        target = state[:, :2] + to_ned(obs[:, 0], obs[:, 1])  # the target's relative position
        ship_velocity = to_ned(state[:, IU], state[:, IV])
        target_velocity = ship_velocity + to_ned(obs[:, 2], obs[:, 3])
        chi_d, u_d = self.guidance.update(self.t, state[:, :2], target, target_velocity)
        # the guidance asks for a course and speed over ground: steer the heading that gives
        # that course with the measured sideslip (current, drift), and hold the ground speed
        course, speed = course_and_speed(ship_velocity)
        crab = course - psi
        azimuth = self.heading.update(self.t, psi, r, chi_d - crab)
        thrust = self.speed.update(self.t, speed, u_d)
        self.t += self.dt
        return pod_env_actions(azimuth, thrust, "target", max_azimuth=self.max_azimuth)


#: The classic policy of each task.
CLASSIC: dict[str, type[ClassicPolicy]] = {
    "NomotoHeading": NomotoHeadingClassic,
    "RVGHeading": RVGHeadingClassic,
    "RVGSpeed": RVGSpeedClassic,
    "RVGPathFollowing": RVGPathClassic,
    "RVGTargetTracking": RVGTargetClassic,
}

#: Names accepted by ``shipgym evaluate --controller``: the classic controller with its
#: design-rule gains, with them and a wave filter in its heading loop, and with its tuned
#: gains, the trained PPO and SAC agents (:mod:`shipgym.rl.agents`) and the neutral command.
POLICIES = ("classic", "classic-wf", "classic-tuned", "ppo", "sac", "zero")


def nominal_ship(env_id: str) -> str:
    """The nominal ship of ``env_id``: its default model (Nomoto env) or RVG parameter set."""
    kwargs = gym.spec(env_id).kwargs
    if env_task(env_id) == "NomotoHeading":
        return str(kwargs.get("model", "nomoto1"))
    return str(kwargs.get("params", "seed001"))


def classic_policy(
    env_id: str, ship: str | None = None, *, wave_filter: bool = False, **design: float | None
) -> ClassicPolicy:
    """The classic policy of ``env_id`` designed on ``ship`` (default: its nominal ship) with
    design parameters ``design`` (the rest at their design-rule values), with a wave filter
    in its heading loop if ``wave_filter``."""
    return CLASSIC[env_task(env_id)](
        ship or nominal_ship(env_id), wave_filter=wave_filter, **design
    )


def make_policy(
    name: str,
    env_id: str,
    agents_dir: str | Path | None = None,
    *,
    gains: str | Path | Mapping[str, Any] | None = None,
    model: str | None = None,
) -> Any:
    """The policy ``name`` (one of :data:`POLICIES`) for ``env_id``.

    ``classic-tuned`` uses the tuned design parameters shipped for ``env_id``
    (:func:`shipgym.benchmark.tuning.load_tuned`); ``ppo`` and ``sac`` load the shipped
    agents, or those in ``agents_dir``. ``gains`` (a gains file of ``shipgym design --json``
    or its document) makes the ``classic`` policy of ``shipgym/NomotoHeading-v0`` use exactly
    those gains (:class:`NomotoHeadingGains`); it is refused with any other controller or env.
    ``model`` (a Nomoto-family model name or an identified model file, the env's ``model``)
    is the ship the classic controllers of ``shipgym/NomotoHeading-v0`` are designed on
    (default: the env's nominal ship).
    """
    if env_id not in ENV_IDS:
        raise ValueError(f"unknown env {env_id!r}; expected one of {ENV_IDS}")
    if model is not None and env_task(env_id) != "NomotoHeading":
        raise ValueError(
            f"a model ({model!r}) sets the ship of {GAINS_ENV}; {env_id} sails its own ship"
        )
    if gains is not None:
        if name != "classic":
            raise ValueError(f"gains go with the classic controller, not with {name!r}")
        if env_task(env_id) != "NomotoHeading":
            raise ValueError(
                f"gains set the heading autopilot of {GAINS_ENV}; the classic controller of "
                f"{env_id} has another structure"
            )
        return NomotoHeadingGains(load_gains(gains, env_id))
    if name == "zero":
        return ZeroPolicy()
    if name == "classic":
        return classic_policy(env_id, model)
    if name == "classic-wf":
        return classic_policy(env_id, model, wave_filter=True)
    if name == "classic-tuned":
        from shipgym.benchmark.tuning import load_tuned

        return classic_policy(env_id, model, **load_tuned(env_id)["design"])
    if name in ("ppo", "sac"):
        from shipgym.rl.agents import load_agent

        return load_agent(env_id, name, agents_dir)
    raise ValueError(f"unknown controller {name!r}; expected one of {POLICIES}")

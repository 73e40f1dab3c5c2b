"""Policies for ``shipgym evaluate``: the classic controller of each env and the zero baseline.

A policy has ``reset(env, obs, info)`` (``env`` is the unwrapped shipgym env) and
``act(obs, info) -> action`` (normalised, as the env takes it). The classic policies are thin
adapters: they read the measurements a ship has (heading, yaw rate, speed, position; for target
tracking the target's relative position and velocity as radar/AIS give them) from ``info`` and
the observation, run the controllers of :mod:`controllers`, and scale the physical commands to
the env's actions with :class:`controllers.PodCommand`.

Gains: the Nomoto ship's autopilot is designed by pole placement on the first-order Nomoto
model that matches its linear yaw response at the design bandwidth
(:func:`controllers.design_model`; exact for the first-order models, the unstable Norrbin ship
included). R/V Gunnerus is directionally
unstable, so its autopilot is designed on the first-order Nomoto model that keeps the unstable
sway-yaw pole and the initial yaw acceleration per unit azimuth of the linearised 3-DOF model
(:func:`rvg_heading_nomoto`), with a slow reference model and a turn-rate limit so the swing can
always be checked.
"""

from __future__ import annotations

import math
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from controllers import (
    ConstantBearingGuidance,
    HeadingAutopilot,
    PodCommand,
    SpeedAutopilot,
    design_model,
    linearised_drag_model,
    quadratic_drag_feedforward,
)
from controllers.los import LOSGuidance
from controllers.paths import WaypointPath
from shipgym.models import make_model
from shipgym.models.rvg import IA1, IA2, IR, IT1, IT2, IU, IV, LPP, SERVICE_SPEED

#: Gunnerus heading autopilot: closed-loop bandwidth [rad/s] of the pole placement.
RVG_OMEGA_N = 0.3
#: Reference model (frequency [rad/s], turn-rate limit [rad/s]) for setpoint steps: slow
#: enough that a 30-90 deg step never overshoots (the ship is directionally unstable).
RVG_STEP_REFERENCE = (0.1, 0.03)
#: Reference model for LOS guidance, whose setpoints move smoothly: faster, so the heading
#: loop stays well inside the guidance loop. (Target tracking keeps the step reference: its
#: course-to-heading conversion uses the measured sideslip, which a fast loop excites.)
RVG_GUIDANCE_REFERENCE = (0.3, 0.04)
#: LOS lookahead for the Gunnerus: three ship lengths.
RVG_LOOKAHEAD = 3.0 * LPP


@cache
def rvg_heading_nomoto(speed: float = SERVICE_SPEED) -> tuple[float, float]:
    """First-order Nomoto ``(K, T)`` of the Gunnerus from common azimuth to yaw rate.

    The 3-DOF model is linearised at straight running at ``speed`` (pods at the thrust that
    holds it). ``T = -1 / lambda`` keeps the unstable sway-yaw eigenvalue ``lambda`` and
    ``K / T`` is the initial yaw acceleration per radian of azimuth, so ``K / T < 0``
    (positive azimuth turns to port) and ``T < 0`` (unstable).
    """
    ship = make_model("rvg3dof")
    p = ship.params
    thrust = 0.5 * (p.linear_damping[0, 0] * speed + p.surge_quadratic_damping * speed**2)
    x0 = np.zeros(ship.nx)
    x0[IU], x0[IT1], x0[IT2] = speed, thrust, thrust
    A, _ = ship.linearize(x0, [thrust, thrust, 0.0, 0.0])
    sway_yaw = A[np.ix_([IV, IR], [IV, IR])]
    lam = float(np.max(np.linalg.eigvals(sway_yaw).real))
    if lam <= 0:
        raise ValueError(f"expected a directionally unstable ship, largest eigenvalue {lam}")
    T = -1.0 / lam
    yaw_accel_per_azimuth = A[IR, IA1] + A[IR, IA2]
    return float(yaw_accel_per_azimuth * T), T


def nomoto_heading_autopilot(model: Any, dt: float) -> HeadingAutopilot:
    """The design-rule heading autopilot of a Nomoto-family ship: pole placement on the
    first-order model that matches the ship's linear yaw response at the design bandwidth
    (:func:`controllers.design_model`; the bandwidth from the steering gear and the ship)."""
    y, gear = model.params, model.gear
    if hasattr(y, "T1"):  # second-order Nomoto, Bech (linear part K b1 r)
        args = (y.K, y.T1, y.T2, y.T3)
        n1 = y.K * y.b1 if hasattr(y, "b1") else 1.0
    else:  # first-order Nomoto, Norrbin (linear part n1 r)
        args, n1 = (y.K, y.T), getattr(y, "n1", 1.0)
    limits = {"actuator_time_constant": gear.time_constant, "max_command": gear.max_angle,
              "max_rate": gear.max_rate}  # fmt: skip
    K, T, omega = design_model(*args, n1=n1, **limits)
    return HeadingAutopilot.from_nomoto(K, T, dt, omega_n=omega, **limits)


def _rvg_heading_autopilot(
    dt: float, max_azimuth: float, reference: tuple[float, float]
) -> HeadingAutopilot:
    K, T = rvg_heading_nomoto()
    params = make_model("rvg3dof").params
    return HeadingAutopilot.from_nomoto(
        K,
        T,
        dt,
        omega_n=RVG_OMEGA_N,
        reference_omega=reference[0],
        max_turn_rate=reference[1],
        max_command=max_azimuth,
        max_rate=params.azimuth_max_rate,
        actuator_time_constant=params.azimuth_time_constant,
    )


def _rvg_speed_autopilot(dt: float, design_speed: float = 4.0) -> SpeedAutopilot:
    p = make_model("rvg3dof").params
    mass = p.mass + p.added_mass[0, 0]
    d1, d2 = p.linear_damping[0, 0], p.surge_quadratic_damping
    K, T = linearised_drag_model(mass, d1, d2, design_speed, share=0.5)
    return SpeedAutopilot.from_first_order(
        K,
        T,
        dt,
        omega_n=0.1,
        feedforward=quadratic_drag_feedforward(d1, d2, share=0.5),
        min_command=0.0,
        max_command=p.max_thrust,
    )


def _speed_through_water(state: np.ndarray, current: tuple[float, float]) -> float:
    speed, direction = current
    psi = state[2]
    return float(state[IU] - speed * math.cos(direction - psi))


class ZeroPolicy:
    """The neutral command: rudder or azimuth amidships, half the thrust range (action 0)."""

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        self.act_dim = env.action_space.shape[0]

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        return np.zeros(self.act_dim, dtype=np.float32)

    def act_batch(self, obs: np.ndarray) -> np.ndarray:
        return np.zeros((len(obs), self.act_dim), dtype=np.float32)


class NomotoHeadingClassic:
    """PID autopilot by pole placement on the ship's Nomoto ``K, T`` (seed 004 eq. 7)."""

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        model = env.task.model
        gear = model.gear
        self.max_angle = gear.max_angle
        self.dt = env.dt
        self.ipsi, self.ir = model.index("psi"), model.index("r")
        # gains made on the nominal ship (the env's default model), as the agents are: a
        # model-mismatch condition then tests both the same way
        nominal = make_model("nomoto1", gear=gear, surge=model.surge)
        self.pilot = nomoto_heading_autopilot(nominal, env.dt)
        state = info["state"]
        self.pilot.reset(state[self.ipsi], state[self.ir], t=0.0)
        self.t = 0.0

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        state = info["state"]
        setpoint = info["heading_setpoint"]
        delta = self.pilot.update(self.t, state[self.ipsi], state[self.ir], setpoint)
        self.t += self.dt
        return np.array([delta / self.max_angle], dtype=np.float32)


class RVGHeadingClassic:
    """Gunnerus heading autopilot on the common pod azimuth."""

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        self.dt = env.dt
        self.max_azimuth = env.task.max_azimuth
        self.pilot = _rvg_heading_autopilot(env.dt, env.task.max_azimuth, RVG_STEP_REFERENCE)
        state = info["state"]
        self.pilot.reset(state[2], state[IR], t=0.0)
        self.t = 0.0

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        state = info["state"]
        azimuth = self.pilot.update(self.t, state[2], state[IR], info["heading_setpoint"])
        self.t += self.dt
        return PodCommand(azimuth, 0.0).to_env_action("heading", max_azimuth=self.max_azimuth)


class RVGSpeedClassic:
    """PI speed autopilot with drag feed-forward on the speed through the water."""

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        self.dt = env.dt
        self.pilot = _rvg_speed_autopilot(env.dt)
        self.pilot.reset(t=0.0)
        self.t = 0.0

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        thrust = self.pilot.update(self.t, float(obs[1]), float(obs[3]))
        self.t += self.dt
        return PodCommand(0.0, thrust).to_env_action("speed")


class RVGPathClassic:
    """Lookahead LOS with the conditional integrator commanding the heading autopilot.

    As in seed 004 the LOS output is used as the heading setpoint (not course over ground);
    the integrator learns the crab angle that a current needs. A speed autopilot holds the
    service speed through the water.
    """

    def __init__(self, integral: bool = True, lookahead: float = RVG_LOOKAHEAD) -> None:
        self.integral = integral
        self.lookahead = lookahead

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        task = env.task
        self.dt = env.dt
        self.max_azimuth = task.max_azimuth
        self.guidance = LOSGuidance(
            WaypointPath(task.waypoints(0)),
            self.lookahead,
            integral=self.integral,
            design_speed=SERVICE_SPEED,
            switching="circle",
            acceptance_radius=task.accept_radius,
        )
        self.heading = _rvg_heading_autopilot(env.dt, task.max_azimuth, RVG_GUIDANCE_REFERENCE)
        self.speed = _rvg_speed_autopilot(env.dt)
        state = info["state"]
        self.heading.reset(state[2], state[IR], t=0.0)
        self.speed.reset(t=0.0)
        self.t = 0.0

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        state = info["state"]
        current = (info["current_speed"], info["current_direction"])
        chi_d = self.guidance.update(self.t, state[:2], state[2], state[IR])
        azimuth = self.heading.update(self.t, state[2], state[IR], chi_d)
        thrust = self.speed.update(self.t, _speed_through_water(state, current), SERVICE_SPEED)
        self.t += self.dt
        return PodCommand(azimuth, thrust).to_env_action("path", max_azimuth=self.max_azimuth)


class RVGTargetClassic:
    """Constant-bearing guidance (seed 004 eq. 11) commanding heading and speed autopilots.

    The guidance gives a course and a speed over ground; the heading setpoint is that course
    minus the measured crab angle, and the speed autopilot holds the speed over ground.
    """

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        task = env.task
        self.dt = env.dt
        self.max_azimuth = task.max_azimuth
        self.guidance = ConstantBearingGuidance(
            2.0, 100.0, float(task.distance[0]), max_speed=6.0, dt=env.dt
        )
        self.heading = _rvg_heading_autopilot(env.dt, task.max_azimuth, RVG_STEP_REFERENCE)
        self.speed = _rvg_speed_autopilot(env.dt, design_speed=3.0)
        state = info["state"]
        self.heading.reset(state[2], state[IR], t=0.0)
        self.speed.reset(t=0.0)
        self.t = 0.0

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        state = info["state"]
        psi = state[2]
        rot = np.array([[math.cos(psi), -math.sin(psi)], [math.sin(psi), math.cos(psi)]])
        target = state[:2] + rot @ obs[0:2]  # relative position, body -> NED
        ship_velocity = rot @ state[[IU, IV]]
        target_velocity = ship_velocity + rot @ obs[2:4]
        chi_d, u_d = self.guidance.update(self.t, state[:2], target, target_velocity)
        # the guidance asks for a course and speed over ground: steer the heading that gives
        # that course with the measured sideslip (current, drift), and hold the ground speed
        crab = math.atan2(ship_velocity[1], ship_velocity[0]) - psi
        azimuth = self.heading.update(self.t, psi, state[IR], chi_d - crab)
        thrust = self.speed.update(self.t, float(np.hypot(*ship_velocity)), u_d)
        self.t += self.dt
        return PodCommand(azimuth, thrust).to_env_action("target", max_azimuth=self.max_azimuth)


_CLASSIC = {
    "shipgym/NomotoHeading-v0": NomotoHeadingClassic,
    "shipgym/RVGHeading-v0": RVGHeadingClassic,
    "shipgym/RVGSpeed-v0": RVGSpeedClassic,
    "shipgym/RVGPathFollowing-v0": RVGPathClassic,
    "shipgym/RVGTargetTracking-v0": RVGTargetClassic,
}

#: Names accepted by ``shipgym evaluate --controller``: the classic controller, the trained
#: PPO and SAC agents (:mod:`shipgym.rl.agents`) and the neutral command.
POLICIES = ("classic", "ppo", "sac", "zero")


def make_policy(name: str, env_id: str, agents_dir: str | Path | None = None) -> Any:
    """The policy ``name`` (one of :data:`POLICIES`) for ``env_id``.

    ``ppo`` and ``sac`` load the shipped agents, or those in ``agents_dir``.
    """
    if env_id not in _CLASSIC:
        raise ValueError(f"unknown env {env_id!r}; expected one of {tuple(_CLASSIC)}")
    if name == "zero":
        return ZeroPolicy()
    if name == "classic":
        return _CLASSIC[env_id]()
    if name in ("ppo", "sac"):
        from shipgym.rl.agents import load_agent

        return load_agent(env_id, name, agents_dir)
    raise ValueError(f"unknown controller {name!r}; expected one of {POLICIES}")

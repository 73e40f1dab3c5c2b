"""Batched task state: what each environment holds for ``n`` ships, and how it is reset.

A :class:`Task` owns the arrays of a batch (states, inputs, current, setpoints, paths, targets,
observations, rewards) and one kernel of :mod:`shipgym.envs.kernels`. Resets draw every random
quantity of row ``i`` from that row's own generator, so the vector environment's sub-env ``i``
seeded with ``s + i`` reproduces the single environment seeded with ``s`` exactly.

Current in ``reset(options=...)``: ``current_speed`` [m/s, >= 0] and ``current_direction``
[rad, the direction the water moves toward, clockwise from north]. Without them the speed is
drawn uniformly from ``[0, max_current_speed]`` and the direction uniformly from [-pi, pi).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from shipgym.envs import kernels
from shipgym.models import NOMOTO_MODEL_NAMES, ShipModel, make_model
from shipgym.models.angles import ssa
from shipgym.models.integrate import PARALLEL_MIN_ROWS
from shipgym.models.rvg import IT1, IT2, IU, IV, LPP, SERVICE_SPEED

COMMON_OPTIONS = frozenset({"current_speed", "current_direction", "initial_state"})


def _finite_float(name: str, value: Any) -> float:
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"option {name!r} must be a number, got {value!r}") from None
    if not math.isfinite(f):
        raise ValueError(f"option {name!r} must be finite, got {value!r}")
    return f


def _angles(name: str, value: Any, max_len: int) -> np.ndarray:
    arr = np.atleast_1d(np.asarray(value, dtype=np.float64))
    if arr.ndim != 1 or not 1 <= arr.size <= max_len or not np.all(np.isfinite(arr)):
        raise ValueError(
            f"option {name!r} must be 1 to {max_len} finite values, got {value!r}"
        )
    return arr


class Task:
    """Batched arrays and reset logic shared by the single and the vector environment.

    Parameters
    ----------
    n : int
        Batch size.
    max_current_speed : float
        Upper end [m/s] of the current speed drawn at reset.
    """

    obs_dim: ClassVar[int]
    act_dim: ClassVar[int]
    dt: ClassVar[float]
    max_episode_steps: ClassVar[int]
    task_options: ClassVar[frozenset[str]] = frozenset()
    obs_names: ClassVar[tuple[str, ...]]
    metric_names: ClassVar[tuple[str, ...]] = ()

    def __init__(self, n: int, model: ShipModel, max_current_speed: float) -> None:
        if not isinstance(n, int | np.integer) or n < 1:
            raise ValueError(f"number of environments must be an integer >= 1, got {n!r}")
        if not (math.isfinite(max_current_speed) and max_current_speed >= 0):
            raise ValueError(
                f"max_current_speed must be a finite speed >= 0 m/s, got {max_current_speed!r}"
            )
        self.n = int(n)
        self.model = model
        self.max_current_speed = float(max_current_speed)
        self.x = np.zeros((n, model.nx))
        self.u = np.zeros((n, model.nu))
        self.c = np.zeros((n, 2))
        self.current = np.zeros((n, 2))  # speed [m/s], direction [rad]
        self.a = np.zeros((n, self.act_dim))
        self.obs = np.zeros((n, self.obs_dim))
        self.rew = np.zeros(n)
        self.term = np.zeros(n, dtype=np.bool_)
        self.reason = np.zeros(n, dtype=np.int64)
        self.steps = np.zeros(n, dtype=np.int64)
        self.u0 = np.zeros(model.nu)
        self.B = np.zeros((model.nu, self.act_dim))
        self._step_args: tuple[Any, ...] | None = None

    # --- to be provided by each task -------------------------------------------------------
    def _kernel_args(self) -> tuple[Any, ...]:
        raise NotImplementedError

    kernel_name: ClassVar[str]

    def _kernel(self, n: int) -> Any:
        serial, parallel = kernels.KERNELS[self.kernel_name]
        return parallel if n >= PARALLEL_MIN_ROWS else serial

    def _initial_state(self, rng: np.random.Generator) -> np.ndarray:
        raise NotImplementedError

    def _reset_task(self, i: int, rng: np.random.Generator, options: Mapping[str, Any]) -> None:
        raise NotImplementedError

    def metrics(self, i: int) -> dict[str, Any]:
        """Task metrics of row ``i`` for ``info``."""
        raise NotImplementedError

    # --- shared ------------------------------------------------------------------------------
    def _args(self, advance: bool, rows: np.ndarray) -> tuple[Any, ...]:
        m = self.model
        return (
            advance, rows, m.model_id, self.x, self.u, m.p, self.c, self.dt, self.a, self.u0,
            self.B, *self._kernel_args(), self.steps, self.obs, self.rew, self.term, self.reason,
        )

    def step(self) -> int:
        """Step every row with the actions in ``self.a``; returns a bad action row or -1."""
        if self._step_args is None:  # built once: every array is updated in place
            self._step_args = self._args(True, np.arange(self.n))
        return self._kernel(self.n)(*self._step_args)

    def reset_rows(
        self,
        rows: Sequence[int],
        rngs: Sequence[np.random.Generator],
        options: Mapping[str, Any] | None = None,
    ) -> None:
        """Reset ``rows``, row ``rows[k]`` drawing from ``rngs[k]``, ``options`` overriding draws."""
        options = {} if options is None else options
        if not isinstance(options, Mapping):
            raise ValueError(f"options must be a dict, got {type(options).__name__}")
        unknown = set(options) - COMMON_OPTIONS - self.task_options
        if unknown:
            raise ValueError(
                f"unknown reset option(s) {sorted(unknown)}; expected any of "
                f"{sorted(COMMON_OPTIONS | self.task_options)}"
            )
        for i, rng in zip(rows, rngs, strict=True):
            self._reset_row(int(i), rng, options)
        idx = np.asarray(rows, dtype=np.int64)
        self._kernel(idx.size)(*self._args(False, idx))

    def _reset_row(self, i: int, rng: np.random.Generator, options: Mapping[str, Any]) -> None:
        # Draw everything first, in a fixed order, so options never shift the random stream.
        speed = rng.uniform(0.0, self.max_current_speed)
        direction = rng.uniform(-math.pi, math.pi)
        state = self._initial_state(rng)
        if "current_speed" in options:
            speed = _finite_float("current_speed", options["current_speed"])
            if speed < 0:
                raise ValueError(f"option 'current_speed' must be >= 0 m/s, got {speed!r}")
        if "current_direction" in options:
            direction = _finite_float("current_direction", options["current_direction"])
        self.current[i] = (speed, direction)
        self.c[i] = (speed * math.cos(direction), speed * math.sin(direction))
        if "initial_state" in options:
            state = self._parse_state(options["initial_state"], state)
        self.x[i] = state
        self.steps[i] = 0
        self.a[i] = 0.0
        self._reset_task(i, rng, options)

    def _parse_state(self, value: Any, state: np.ndarray) -> np.ndarray:
        names = self.model.state_names
        if isinstance(value, Mapping):
            state = state.copy()
            for key, v in value.items():
                if key not in names:
                    raise ValueError(f"initial_state has unknown state {key!r}; states: {names}")
                state[names.index(key)] = _finite_float(f"initial_state[{key!r}]", v)
            return state
        arr = np.asarray(value, dtype=np.float64)
        if arr.shape != (len(names),) or not np.all(np.isfinite(arr)):
            raise ValueError(
                f"initial_state must be a dict of named states or {len(names)} finite values "
                f"{names}, got {value!r}"
            )
        return arr.copy()

    def info(self, i: int) -> dict[str, Any]:
        """The ``info`` dict of row ``i``: physical state, current, task metrics."""
        info = {
            "state": self.x[i].copy(),
            "current_speed": float(self.current[i, 0]),
            "current_direction": float(self.current[i, 1]),
            "termination_reason": kernels.REASONS[self.reason[i]],
        }
        info.update(self.metrics(i))
        return info


class HeadingTask(Task):
    """Reach and hold heading setpoints that change every ``setpoint_interval`` seconds."""

    task_options = frozenset({"setpoints"})
    metric_names = ("heading_error", "heading_setpoint")
    max_setpoints: ClassVar[int] = 8
    n_random_setpoints: ClassVar[int]
    change_range_deg: ClassVar[tuple[float, float]]
    obs_state_names: ClassVar[tuple[str, ...]]

    def __init__(
        self, n: int, model: ShipModel, max_current_speed: float, setpoint_interval: float
    ) -> None:
        super().__init__(n, model, max_current_speed)
        hold = round(setpoint_interval / self.dt)
        if not (math.isfinite(setpoint_interval) and hold >= 1):
            raise ValueError(
                f"setpoint_interval must be >= one step ({self.dt} s), got {setpoint_interval!r}"
            )
        self.hold_steps = int(hold)
        self.schedule = np.zeros((n, self.max_setpoints))
        self.ipsi = model.index("psi")
        self.obs_idx = np.array([model.index(s) for s in self.obs_state_names], dtype=np.int64)

    kernel_name = "heading"

    def _kernel_args(self) -> tuple[Any, ...]:
        return (self.ipsi, self.obs_idx, self.schedule, self.hold_steps)

    def _reset_task(self, i: int, rng: np.random.Generator, options: Mapping[str, Any]) -> None:
        lo, hi = np.radians(self.change_range_deg)
        changes = rng.uniform(lo, hi, self.n_random_setpoints) * rng.choice(
            [-1.0, 1.0], self.n_random_setpoints
        )
        setpoints = ssa(self.x[i, self.ipsi] + np.cumsum(changes))
        if "setpoints" in options:
            setpoints = ssa(_angles("setpoints", options["setpoints"], self.max_setpoints))
        self.schedule[i] = setpoints[-1]
        self.schedule[i, : setpoints.size] = setpoints

    def metrics(self, i: int) -> dict[str, Any]:
        k = min(self.steps[i] // self.hold_steps, self.max_setpoints - 1)
        return {"heading_error": float(self.obs[i, 0]), "heading_setpoint": float(self.schedule[i, k])}


class NomotoHeadingTask(HeadingTask):
    """Nomoto-family ship, rudder command, heading setpoints (``shipgym/NomotoHeading-v0``)."""

    obs_dim = 3
    act_dim = 1
    dt = 1.0
    max_episode_steps = 800
    n_random_setpoints = 4
    change_range_deg = (10.0, 60.0)
    obs_state_names = ("r", "delta")
    obs_names = ("heading_error", "r", "delta")

    def __init__(
        self,
        n: int,
        model: str = "nomoto1",
        max_current_speed: float = 1.0,
        setpoint_interval: float = 200.0,
    ) -> None:
        if model not in NOMOTO_MODEL_NAMES:
            raise ValueError(f"unknown model {model!r}; expected one of {NOMOTO_MODEL_NAMES}")
        super().__init__(n, make_model(model), max_current_speed, setpoint_interval)
        gear, surge = self.model.gear, self.model.surge
        assert gear is not None and surge is not None
        self.u0[:] = (0.0, surge.service_shaft_speed)
        self.B[0, 0] = gear.max_angle
        self.service_speed = surge.service_speed

    def _initial_state(self, rng: np.random.Generator) -> np.ndarray:
        x = np.zeros(self.model.nx)
        x[self.ipsi] = rng.uniform(-math.pi, math.pi)
        x[self.model.index("U")] = self.service_speed
        return x


class RVGMixin:
    """Common set-up of the Gunnerus tasks: model, azimuth range, thrust, initial motion."""

    dt = 0.5
    x: np.ndarray
    c: np.ndarray

    def _setup_rvg(self, max_azimuth: float) -> None:
        if not (math.isfinite(max_azimuth) and 0 < max_azimuth <= math.pi):
            raise ValueError(f"max_azimuth must be in (0, pi] rad, got {max_azimuth!r}")
        self.params = make_model("rvg3dof").params
        self.max_azimuth = float(max_azimuth)
        self.bollard = self.params.bollard_thrust

    def _initial_state(self, rng: np.random.Generator) -> np.ndarray:
        """Straight ahead at the service speed through the water (current added later)."""
        x = np.zeros(10)
        x[2] = rng.uniform(-math.pi, math.pi)
        x[IU] = SERVICE_SPEED
        x[IT1] = x[IT2] = self.params.service_thrust
        return x

    def _add_current(self, i: int, options: Mapping[str, Any]) -> None:
        """Make a drawn initial state move with the current (``nu = nu_r + nu_c``)."""
        if "initial_state" in options:
            return
        psi = self.x[i, 2]
        cn, ce = self.c[i]
        self.x[i, IU] += cn * math.cos(psi) + ce * math.sin(psi)
        self.x[i, IV] += -cn * math.sin(psi) + ce * math.cos(psi)


class RVGHeadingTask(RVGMixin, HeadingTask):
    """Gunnerus, common pod azimuth command, heading setpoints (``shipgym/RVGHeading-v0``)."""

    obs_dim = 5
    act_dim = 1
    max_episode_steps = 600
    n_random_setpoints = 3
    change_range_deg = (10.0, 45.0)
    obs_state_names = ("r", "alpha1", "u", "v")
    obs_names = ("heading_error", "r", "alpha1", "u", "v")

    def __init__(
        self,
        n: int,
        max_current_speed: float = 0.5,
        max_azimuth: float = math.radians(35.0),
        setpoint_interval: float = 100.0,
    ) -> None:
        HeadingTask.__init__(self, n, make_model("rvg3dof"), max_current_speed, setpoint_interval)
        self._setup_rvg(max_azimuth)
        ts = self.params.service_thrust
        self.u0[:] = (ts, ts, 0.0, 0.0)
        self.B[2, 0] = self.B[3, 0] = self.max_azimuth

    def _reset_task(self, i: int, rng: np.random.Generator, options: Mapping[str, Any]) -> None:
        self._add_current(i, options)
        HeadingTask._reset_task(self, i, rng, options)


class RVGSpeedTask(RVGMixin, Task):
    """Gunnerus, common pod thrust command, speed setpoints (``shipgym/RVGSpeed-v0``)."""

    obs_dim = 4
    act_dim = 1
    max_episode_steps = 800
    task_options = frozenset({"setpoints"})
    obs_names = ("speed_error", "u_r", "thrust_fraction", "speed_setpoint")
    metric_names = ("speed_error", "speed_setpoint")
    max_setpoints = 8
    speed_range = (1.5, 6.0)

    def __init__(
        self,
        n: int,
        max_current_speed: float = 0.5,
        max_azimuth: float = math.radians(35.0),
        setpoint_interval: float = 200.0,
    ) -> None:
        Task.__init__(self, n, make_model("rvg3dof"), max_current_speed)
        self._setup_rvg(max_azimuth)
        hold = round(setpoint_interval / self.dt)
        if not (math.isfinite(setpoint_interval) and hold >= 1):
            raise ValueError(
                f"setpoint_interval must be >= one step ({self.dt} s), got {setpoint_interval!r}"
            )
        self.hold_steps = int(hold)
        self.schedule = np.zeros((n, self.max_setpoints))
        half = 0.5 * self.bollard
        self.u0[:] = (half, half, 0.0, 0.0)
        self.B[0, 0] = self.B[1, 0] = half

    kernel_name = "speed"

    def _kernel_args(self) -> tuple[Any, ...]:
        return (self.schedule, self.hold_steps)

    def _initial_state(self, rng: np.random.Generator) -> np.ndarray:
        x = super()._initial_state(rng)
        x[IU] = rng.uniform(0.0, 5.0)
        x[IT1] = x[IT2] = 0.0
        return x

    def _reset_task(self, i: int, rng: np.random.Generator, options: Mapping[str, Any]) -> None:
        self._add_current(i, options)
        setpoints = rng.uniform(*self.speed_range, 2)
        if "setpoints" in options:
            setpoints = _angles("setpoints", options["setpoints"], self.max_setpoints)
            if np.any(setpoints < 0):
                raise ValueError(f"option 'setpoints' must be speeds >= 0 m/s, got {setpoints}")
        self.schedule[i] = setpoints[-1]
        self.schedule[i, : setpoints.size] = setpoints

    def metrics(self, i: int) -> dict[str, Any]:
        return {"speed_error": float(self.obs[i, 0]), "speed_setpoint": float(self.obs[i, 3])}


class RVGPathTask(RVGMixin, Task):
    """Gunnerus following straight segments between waypoints (``shipgym/RVGPathFollowing-v0``)."""

    obs_dim = 9
    act_dim = 2
    max_episode_steps = 1600
    task_options = frozenset({"waypoints"})
    obs_names = ("cross_track_error", "course_error", "along_track_left", "next_turn",
                 "u", "v", "r", "alpha1", "thrust_fraction")
    metric_names = ("cross_track_error", "segment", "completed")
    max_waypoints = 16

    def __init__(
        self,
        n: int,
        max_current_speed: float = 0.5,
        max_azimuth: float = math.radians(35.0),
        accept_radius: float = 2.0 * LPP,
        max_cross_track: float = 250.0,
    ) -> None:
        Task.__init__(self, n, make_model("rvg3dof"), max_current_speed)
        self._setup_rvg(max_azimuth)
        for name, v in (("accept_radius", accept_radius), ("max_cross_track", max_cross_track)):
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite distance > 0 m, got {v!r}")
        self.accept_radius = float(accept_radius)
        self.max_cross_track = float(max_cross_track)
        self.wp = np.zeros((n, self.max_waypoints, 2))
        self.tangent = np.zeros((n, self.max_waypoints, 4))  # x_k, y_k, cos chi_k, sin chi_k
        self.leg_length = np.zeros((n, self.max_waypoints))
        self.leg_angle = np.zeros((n, self.max_waypoints))
        self.turn = np.zeros((n, self.max_waypoints))
        self.n_wp = np.full(n, 2, dtype=np.int64)
        self.seg = np.zeros(n, dtype=np.int64)
        half = 0.5 * self.bollard
        self.u0[:] = (half, half, 0.0, 0.0)
        self.B[2, 0] = self.B[3, 0] = self.max_azimuth
        self.B[0, 1] = self.B[1, 1] = half

    kernel_name = "path"

    def _kernel_args(self) -> tuple[Any, ...]:
        return (self.tangent, self.leg_length, self.leg_angle, self.turn,
                self.n_wp, self.seg, self.accept_radius, self.max_cross_track,
                SERVICE_SPEED)

    def _initial_state(self, rng: np.random.Generator) -> np.ndarray:
        x = super()._initial_state(rng)
        x[2] = rng.uniform(-math.radians(30), math.radians(30))  # relative to the first leg
        x[1] = rng.uniform(-30.0, 30.0)  # cross-track offset, rotated onto the first leg below
        return x

    def _random_path(self, rng: np.random.Generator) -> np.ndarray:
        m = int(rng.integers(4, 7))
        legs = rng.uniform(200.0, 400.0, m - 1)
        turns = rng.uniform(-math.radians(60), math.radians(60), m - 1)
        turns[0] = rng.uniform(-math.pi, math.pi)
        course = np.cumsum(turns)
        steps = np.stack((legs * np.cos(course), legs * np.sin(course)), axis=1)
        return np.vstack((np.zeros(2), np.cumsum(steps, axis=0)))

    def _reset_task(self, i: int, rng: np.random.Generator, options: Mapping[str, Any]) -> None:
        path = self._random_path(rng)
        if "waypoints" in options:
            path = np.asarray(options["waypoints"], dtype=np.float64)
            if (path.ndim != 2 or path.shape[1] != 2 or not 2 <= path.shape[0] <= self.max_waypoints
                    or not np.all(np.isfinite(path))):
                raise ValueError(
                    f"option 'waypoints' must be 2 to {self.max_waypoints} finite (north, east) "
                    f"points in m, got {options['waypoints']!r}"
                )
            if np.any(np.hypot(*np.diff(path, axis=0).T) < 1e-6):
                raise ValueError("option 'waypoints' has two consecutive identical waypoints")
        if "initial_state" not in options:
            chi0 = math.atan2(path[1, 1] - path[0, 1], path[1, 0] - path[0, 0])
            offset = self.x[i, 1]
            self.x[i, 0] = path[0, 0] - offset * math.sin(chi0)
            self.x[i, 1] = path[0, 1] + offset * math.cos(chi0)
            self.x[i, 2] = ssa(chi0 + self.x[i, 2])
            self._add_current(i, options)
        m = path.shape[0]
        legs = np.diff(path, axis=0)
        angle = np.arctan2(legs[:, 1], legs[:, 0])
        self.wp[i] = path[-1]
        self.wp[i, :m] = path
        self.tangent[i] = 0.0
        self.tangent[i, :m, :2] = path
        self.tangent[i, : m - 1, 2] = np.cos(angle)
        self.tangent[i, : m - 1, 3] = np.sin(angle)
        self.leg_length[i] = 0.0
        self.leg_length[i, : m - 1] = np.hypot(legs[:, 0], legs[:, 1])
        self.leg_angle[i] = 0.0
        self.leg_angle[i, : m - 1] = angle
        self.turn[i] = 0.0
        self.turn[i, : m - 2] = ssa(np.diff(angle))
        self.n_wp[i] = m
        self.seg[i] = 0

    def metrics(self, i: int) -> dict[str, Any]:
        return {
            "cross_track_error": float(self.obs[i, 0]),
            "segment": int(self.seg[i]),
            "completed": bool(self.reason[i] == kernels.SUCCESS),
        }

    def waypoints(self, i: int) -> np.ndarray:
        """The waypoints (north, east) [m] of row ``i``."""
        return self.wp[i, : self.n_wp[i]].copy()


class RVGTargetTask(RVGMixin, Task):
    """Gunnerus intercepting a moving target and holding a distance (``RVGTargetTracking-v0``)."""

    obs_dim = 10
    act_dim = 2
    max_episode_steps = 1600
    task_options = frozenset({"target_position", "target_velocity", "distance"})
    obs_names = ("target_x_body", "target_y_body", "target_vx_body", "target_vy_body",
                 "distance_error", "u", "v", "r", "alpha1", "thrust_fraction")
    metric_names = ("distance", "distance_error")

    def __init__(
        self,
        n: int,
        max_current_speed: float = 0.5,
        max_azimuth: float = math.radians(35.0),
        distance: float = 50.0,
        max_distance: float = 3000.0,
    ) -> None:
        Task.__init__(self, n, make_model("rvg3dof"), max_current_speed)
        self._setup_rvg(max_azimuth)
        for name, v in (("distance", distance), ("max_distance", max_distance)):
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite distance > 0 m, got {v!r}")
        self.default_distance = float(distance)
        self.max_distance = float(max_distance)
        self.target = np.zeros((n, 2))
        self.target_vel = np.zeros((n, 2))
        self.distance = np.full(n, float(distance))
        half = 0.5 * self.bollard
        self.u0[:] = (half, half, 0.0, 0.0)
        self.B[2, 0] = self.B[3, 0] = self.max_azimuth
        self.B[0, 1] = self.B[1, 1] = half

    kernel_name = "target"

    def _kernel_args(self) -> tuple[Any, ...]:
        return (self.target, self.target_vel, self.distance, self.max_distance)

    def _reset_task(self, i: int, rng: np.random.Generator, options: Mapping[str, Any]) -> None:
        self._add_current(i, options)
        rng_range = rng.uniform(300.0, 800.0)
        bearing = self.x[i, 2] + rng.uniform(-math.pi / 3, math.pi / 3)
        course = rng.uniform(-math.pi, math.pi)
        speed = rng.uniform(1.0, 3.0)
        pos = self.x[i, :2] + rng_range * np.array([math.cos(bearing), math.sin(bearing)])
        vel = speed * np.array([math.cos(course), math.sin(course)])
        for name in ("target_position", "target_velocity"):
            if name in options:
                v = np.asarray(options[name], dtype=np.float64)
                if v.shape != (2,) or not np.all(np.isfinite(v)):
                    raise ValueError(f"option {name!r} must be 2 finite (north, east) values, got {options[name]!r}")
                if name == "target_position":
                    pos = v
                else:
                    vel = v
        d = self.default_distance
        if "distance" in options:
            d = _finite_float("distance", options["distance"])
            if d <= 0:
                raise ValueError(f"option 'distance' must be > 0 m, got {d!r}")
        self.target[i] = pos
        self.target_vel[i] = vel
        self.distance[i] = d

    def metrics(self, i: int) -> dict[str, Any]:
        err = float(self.obs[i, 4])
        return {"distance": err + float(self.distance[i]), "distance_error": err}


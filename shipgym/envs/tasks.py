"""Batched task state: what each environment holds for ``n`` ships, and how it is reset.

A :class:`Task` owns the arrays of a batch (states, inputs, current, setpoints, paths, targets,
observations, rewards) and one kernel of :mod:`shipgym.envs.kernels`. A reset of row ``i``
draws one vector of ``n_draws`` uniform numbers from that row's own generator and maps it to
the initial conditions with NumPy, for all rows being reset at once. The single environment is
a batch of one, so the vector environment's sub-env ``i`` seeded with ``s + i`` reproduces the
single environment seeded with ``s`` exactly, and autoresets of many sub-envs cost one pass.

Wind and waves: ``wind`` and ``sea_state`` (:mod:`shipgym.models.seaway_options`), in the env's
constructor (:meth:`Task.set_seaway`) or ``reset(options=...)``; off by default. At sea a
task's kernel forms the observations from the measured states ``xm`` (the states plus the
wave-frequency motion, :mod:`shipgym.models.seaway`) and the rewards from the states.

Current in ``reset(options=...)``: ``current_speed`` [m/s, 0 to the ship's top speed] and
``current_direction`` [rad, the direction the water moves toward, clockwise from north].
Without them the speed is drawn uniformly from ``[0, max_current_speed]`` and the direction
uniformly from [-pi, pi).

Every reset option has a physical range, and a value outside it raises ``ValueError`` naming
the option, the value and the range (nothing changes then). The ranges come from the ship and
the task: its top speed ``V`` (the Gunnerus' ``thrust_zero_speed``, 8.7 m/s, where its pods
can push no more; the Mariner's speed at its largest shaft speed, 9.9 m/s), its length ``L``
and the distance it covers in one episode at top speed (:attr:`Task.arena`):

* speeds of the ship and of a target: ``|.| <= SPEED_FACTOR V`` (1.5 V); a Nomoto ``U`` >= 0;
* current and speed setpoints: ``[0, V]`` (no current faster than the ship, no setpoint it
  cannot reach);
* yaw rate: ``|r| <= 2 V / L`` (the bow moving sideways at top speed); a yaw acceleration
  that rate per second;
* positions (ship, waypoints, target): ``|x|, |y| <= arena``;
* angles (headings, heading setpoints, current direction): ``|.| <= MAX_ANGLE`` (100 whole
  turns, so an unwrapped heading from a long run is accepted);
* actuators: the rudder within the steering gear's limit, pod thrust in ``[0, bollard]``,
  pod azimuth within ``azimuth_max``.

:meth:`Task.state_ranges` gives the range of each state; range ends are rounded to the four
significant digits the messages show.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from shipgym.envs import kernels
from shipgym.envs.streams import RowStreams
from shipgym.models import NOMOTO_MODEL_NAMES, RVGParams, ShipModel, make_model, seaway_options
from shipgym.models import seaway as sw
from shipgym.models.angles import ssa
from shipgym.models.delay import DelayLine
from shipgym.models.integrate import NC
from shipgym.models.model_file import is_model_file, load_model, model_info
from shipgym.models.rvg import IPSI, IT1, IT2, IU, IV, IX, IY, LPP, SERVICE_SPEED
from shipgym.models.seaway_options import SeawayArrays

COMMON_OPTIONS = frozenset(
    {"current_speed", "current_direction", "initial_state", "wind", "sea_state"}
)
_N_COMMON_DRAWS = 2
#: Largest angle [rad] a reset option may give (heading, setpoint, current direction): 100 turns.
MAX_ANGLE = 200.0 * math.pi
#: Ship and target speeds given at reset may reach this multiple of the ship's top speed.
SPEED_FACTOR = 1.5


def _finite_float(name: str, value: Any) -> float:
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"option {name!r} must be a number, got {value!r}") from None
    if not math.isfinite(f):
        raise ValueError(f"option {name!r} must be finite, got {value!r}")
    return f


def _finite_vector(name: str, value: Any, max_len: int) -> np.ndarray:
    try:
        arr = np.atleast_1d(np.asarray(value, dtype=np.float64))
    except (TypeError, ValueError):
        arr = np.array([np.nan])
    if arr.ndim != 1 or not 1 <= arr.size <= max_len or not np.all(np.isfinite(arr)):
        raise ValueError(f"option {name!r} must be 1 to {max_len} finite values, got {value!r}")
    return arr


def _point(name: str, value: Any) -> np.ndarray:
    try:
        v = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        v = np.array([np.nan])
    if v.shape != (2,) or not np.all(np.isfinite(v)):
        raise ValueError(f"option {name!r} must be 2 finite (north, east) values, got {value!r}")
    return v


def _positive(name: str, value: float) -> float:
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


def _limit(value: float) -> float:
    """A range end rounded away from zero to the 4 significant digits a message shows."""
    if value == 0.0:
        return 0.0
    exp = math.floor(math.log10(abs(value))) - 3
    digits = math.ceil(abs(value) / 10.0**exp - 1e-9)
    return math.copysign(float(f"{digits}e{exp}"), value)


def _check_range(name: str, value: Any, low: float, high: float, unit: str) -> None:
    """Raise ``ValueError`` naming option ``name``, ``value`` and the range unless every entry
    of ``value`` is in ``[low, high]``."""
    arr = np.asarray(value, dtype=np.float64)
    if not np.all((arr >= low) & (arr <= high)):
        got = arr.tolist() if arr.ndim else float(arr)
        raise ValueError(f"option {name} must be in [{low:g}, {high:g}] {unit}, got {got!r}")


#: Unit of each state in the messages of the ``initial_state`` option.
_STATE_UNITS = {
    "x": "m",
    "y": "m",
    "psi": "rad",
    "u": "m/s",
    "v": "m/s",
    "U": "m/s",
    "r": "rad/s",
    "r_dot": "rad/s^2",
    "delta": "rad",
    "T1": "N",
    "T2": "N",
    "alpha1": "rad",
    "alpha2": "rad",
}


#: The kernels' seaway argument in calm water (the types of ``SeawayArrays.kernel_args``, no
#: ships; never written).
_CALM_SEAWAY = (False, np.zeros((0, 0)), np.zeros((0, 0)), np.zeros(0, dtype=np.uint64),
                np.zeros((0, 0)), np.zeros((0, 0, 0)), np.zeros(0), 0)  # fmt: skip


def _uniform(u: np.ndarray, low: float, high: float) -> np.ndarray:
    return low + (high - low) * u


class Task:
    """Batched arrays and reset logic shared by the single and the vector environment.

    Parameters
    ----------
    n : int
        Batch size.
    model : ShipModel
        The vessel model.
    max_current_speed : float
        Upper end [m/s] of the current speed drawn at reset.
    """

    obs_dim: ClassVar[int]
    act_dim: ClassVar[int]
    dt: ClassVar[float]
    max_episode_steps: ClassVar[int]
    kernel_name: ClassVar[str]
    n_task_draws: ClassVar[int]
    task_options: ClassVar[frozenset[str]] = frozenset()
    obs_names: ClassVar[tuple[str, ...]]
    #: Observation bounds (low, high) per entry; observations are clipped to them.
    obs_bounds: ClassVar[tuple[tuple[float, float], ...]]
    #: Bounds (low, high) of the reward of every step, whatever the state.
    reward_bounds: ClassVar[tuple[float, float]]
    #: Length [m] of the ship, for the yaw-rate range of the reset options.
    ship_length: ClassVar[float]

    def __init__(self, n: int, model: ShipModel, max_current_speed: float) -> None:
        if not isinstance(n, int | np.integer) or n < 1:
            raise ValueError(f"number of environments must be an integer >= 1, got {n!r}")
        if not (math.isfinite(max_current_speed) and max_current_speed >= 0):
            raise ValueError(
                f"max_current_speed must be a finite speed >= 0 m/s, got {max_current_speed!r}"
            )
        self.n = int(n)
        self.model = model
        if max_current_speed > self.top_speed:
            raise ValueError(
                f"max_current_speed must be in [0, {self.top_speed:g}] m/s (the ship's top "
                f"speed), got {max_current_speed!r}"
            )
        self.max_current_speed = float(max_current_speed)
        self.x = np.zeros((n, model.nx))
        self.u = np.zeros((n, model.nu))
        self.c = np.zeros((n, NC))  # current north, east; the seaway's load
        #: The measured states: ``x`` plus the wave-frequency motion; ``x`` itself in calm water.
        self.xm = self.x
        #: The seaway of the batch, made at the first reset with wind or waves.
        self.seaway: SeawayArrays | None = None
        self.default_wind: seaway_options.Wind | None = None
        self.default_sea: seaway_options.Sea | None = None
        self.current = np.zeros((n, 2))  # speed [m/s], direction [rad]
        self.a = np.zeros((n, self.act_dim))
        self.obs = np.zeros((n, self.obs_dim))
        self.rew = np.zeros(n)
        self.term = np.zeros(n, dtype=np.bool_)
        self.reason = np.zeros(n, dtype=np.int64)
        self.steps = np.zeros(n, dtype=np.int64)
        self.u0 = np.zeros(model.nu)
        self.B = np.zeros((model.nu, self.act_dim))
        self._step_args: tuple[Any, ...] = ()
        self._step_call: Callable[..., int] | None = None
        #: The rudder command's transport delay of an identified ship (None: no delay).
        self.delay = (
            DelayLine(model.input_delay, self.dt, self.n, self.act_dim)
            if model.input_delay
            else None
        )
        bounds = np.array(self.obs_bounds, dtype=np.float64)
        self.obs_low, self.obs_high = bounds[:, 0].copy(), bounds[:, 1].copy()

    @property
    def n_draws(self) -> int:
        """Uniform numbers drawn from a row's generator at each reset."""
        return _N_COMMON_DRAWS + self.n_task_draws

    # --- ranges of the reset options ---------------------------------------------------------
    @property
    def top_speed(self) -> float:
        """Top speed [m/s] of the ship through the water; also the largest current."""
        raise NotImplementedError

    @property
    def speed_limit(self) -> float:
        """Largest ship or target speed [m/s] a reset option may give."""
        return _limit(SPEED_FACTOR * self.top_speed)

    @property
    def yaw_rate_limit(self) -> float:
        """Largest yaw rate [rad/s] a reset option may give: the bow sideways at top speed."""
        return _limit(2.0 * self.top_speed / self.ship_length)

    @property
    def arena(self) -> float:
        """Largest north or east coordinate [m] of a position given at reset: the distance the
        ship covers in one episode at top speed."""
        return _limit(self.max_episode_steps * self.dt * self.top_speed)

    def state_ranges(self) -> dict[str, tuple[float, float]]:
        """Accepted range (low, high) of each state of the ``initial_state`` option."""
        a, v, r = self.arena, self.speed_limit, self.yaw_rate_limit
        ranges = {
            "x": (-a, a),
            "y": (-a, a),
            "psi": (-_limit(MAX_ANGLE), _limit(MAX_ANGLE)),
            "u": (-v, v),
            "v": (-v, v),
            "U": (0.0, v),
            "r": (-r, r),
            "r_dot": (-r, r),
            **self._actuator_ranges(),
        }
        return {name: ranges[name] for name in self.model.state_names}

    def _actuator_ranges(self) -> dict[str, tuple[float, float]]:
        raise NotImplementedError

    # --- provided by each task ---------------------------------------------------------------
    def _kernel_args(self) -> tuple[Any, ...]:
        raise NotImplementedError

    def _initial_states(self, draws: np.ndarray) -> np.ndarray:
        """Initial states ``(r, nx)`` from the task's uniform draws ``(r, n_task_draws)``."""
        raise NotImplementedError

    def _reset_task(self, rows: np.ndarray, draws: np.ndarray, options: Mapping[str, Any]) -> None:
        """Set the task quantities (setpoints, path, target) of ``rows``."""
        raise NotImplementedError

    def batch_metrics(self, rows: slice | np.ndarray) -> dict[str, Any]:
        """Task metrics of ``rows`` for the vector env's ``info``: each metric an array with one
        entry per row (float64, int64 or bool): a view of the task's arrays, which
        :meth:`batch_info` copies, or an array made for the call, never a task's array itself;
        ``rows`` a slice or an index array.
        """
        raise NotImplementedError

    def metrics(self, i: int) -> dict[str, Any]:
        """Task metrics of row ``i`` for the single env's ``info``, as Python scalars (float,
        int, bool): the values of :meth:`batch_metrics` for that row, read with
        ``ndarray.item`` (a few hundred ns a step, where NumPy scalars cost microseconds)."""
        raise NotImplementedError

    # --- shared ------------------------------------------------------------------------------
    #: Threads of the task kernel (``ShipVectorEnv(num_threads=...)``); 1 runs it serially.
    num_threads: int = 1

    def _kernel(self, n: int) -> Any:
        serial = kernels.KERNELS[self.kernel_name]
        if self.num_threads == 1 or n < kernels.THREADED_MIN_ROWS:
            return serial
        return functools.partial(kernels.run_threaded, serial, self.num_threads)

    def _args(self, advance: bool, rows: np.ndarray) -> tuple[Any, ...]:
        m = self.model
        return (
            advance,
            rows,
            m.model_id,
            self.x,
            self.u,
            m.p,
            self.c,
            self._seaway_args(),
            self.xm,
            self.dt,
            self.a,
            self.u0,
            self.B,
            *self._kernel_args(),
            self.steps,
            self.obs,
            self.rew,
            self.term,
            self.reason,
            self.obs_low,
            self.obs_high,
        )

    #: The ship of the seaway (wind and wave data), or None where they are not known.
    seaway_ship: ClassVar[Callable[[], sw.SeawayShip] | None] = None

    def _seaway_args(self) -> tuple[Any, ...]:
        """The seaway argument of the kernel: the batch's, or the empty one of calm water."""
        return _CALM_SEAWAY if self.seaway is None else self.seaway.kernel_args()

    def set_seaway(self, wind: Any = None, sea_state: Any = None) -> None:
        """Set the wind and sea state of every episode (the env constructors' ``wind`` and
        ``sea_state``; :mod:`shipgym.models.seaway_options`); a reset's options override them.

        Raises
        ------
        ValueError
            For a bad value, or a seaway on a ship whose wind and wave data are not known.
        """
        wind_spec = seaway_options.wind_option(wind)
        sea_spec = seaway_options.sea_option(sea_state)
        if wind_spec is not None or sea_spec is not None:
            self._require_seaway_ship()
        self.default_wind, self.default_sea = wind_spec, sea_spec

    def _require_seaway_ship(self) -> sw.SeawayShip:
        if self.seaway_ship is None:
            raise ValueError(
                "options 'wind' and 'sea_state' need the ship's wind areas and hull: known "
                "for the Mariner of the Nomoto family and the R/V Gunnerus, not for "
                f"{self.model.name!r} identified from a record"
            )
        return self.seaway_ship()

    def _start_seaway(self) -> SeawayArrays:
        """The batch's seaway, made (and the measured states split from the states) at first."""
        if self.seaway is None:
            self.seaway = SeawayArrays(
                self.n, self._require_seaway_ship(), self.dt, self.model.index("r")
            )
            self.xm = self.x.copy()
            self._step_call = None  # the kernel's arguments change
        return self.seaway

    def step(self, rows: np.ndarray | None = None) -> int:
        """Step every row, or only ``rows``, with the actions in ``self.a``.

        Parameters
        ----------
        rows : numpy.ndarray of int64, optional
            Distinct row indices in ``[0, n)`` to step; the others keep their state,
            observation, reward and flags. Each stepped row's result is bitwise the one of
            stepping every row. The actions of every row are checked (set the others' to 0).

        Returns
        -------
        int
            The first row whose action holds a NaN or infinity (then no row is stepped), or -1.
        """
        if rows is not None:
            # the compiled call takes exactly the types it was built for (a C-contiguous int64
            # vector) and does not check the indices
            rows = np.ascontiguousarray(rows, dtype=np.int64)
            if rows.ndim != 1 or (rows.size and not 0 <= rows.min() <= rows.max() < self.n):
                raise ValueError(
                    f"rows must be a vector of row indices in [0, {self.n}), got {rows!r}"
                )
        if self._step_call is None:  # built once: every array is updated in place
            self._step_args = self._args(True, np.arange(self.n))
            self._step_call = kernels.compiled_call(self._kernel(self.n), self._step_args)
        if self.delay is not None and np.isfinite(self.a).all():  # (a bad action steps no row)
            np.clip(self.a, -1.0, 1.0, out=self.a)
            self.a[:] = self.delay.push(self.a)
        if rows is None:
            return self._step_call(*self._step_args)
        advance, _, *rest = self._step_args
        return self._step_call(advance, rows, *rest)

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_step_call"], state["_step_args"] = None, ()  # (compiled code: made anew)
        return state

    def reset_rows(
        self,
        rows: Sequence[int] | np.ndarray,
        rngs: Sequence[np.random.Generator] | RowStreams,
        options: Mapping[str, Any] | None = None,
    ) -> None:
        """Reset ``rows``; row ``rows[k]`` draws from ``rngs[k]``, or from its own stream of a
        :class:`~shipgym.envs.streams.RowStreams` (all rows in one pass); ``options`` override
        draws.

        Raises
        ------
        ValueError
            For an unknown option or an invalid option value; nothing is changed then.
        """
        options = {} if options is None else options
        if not isinstance(options, Mapping):
            raise ValueError(f"options must be a dict, got {type(options).__name__}")
        unknown = set(options) - COMMON_OPTIONS - self.task_options
        if unknown:
            raise ValueError(
                f"unknown reset option(s) {sorted(unknown)}; expected any of "
                f"{sorted(COMMON_OPTIONS | self.task_options)}"
            )
        rows = np.asarray(rows, dtype=np.int64)
        wind = (
            seaway_options.wind_option(options["wind"]) if "wind" in options else self.default_wind
        )
        sea = (
            seaway_options.sea_option(options["sea_state"])
            if "sea_state" in options
            else self.default_sea
        )
        at_sea = wind is not None or sea is not None
        if at_sea:
            self._require_seaway_ship()
        n_draws = self.n_draws + (seaway_options.N_DRAWS if at_sea else 0)
        if isinstance(rngs, RowStreams):
            draws = rngs.random(rows, n_draws)
        else:
            draws = np.empty((rows.size, n_draws))
            for k, rng in enumerate(rngs):
                draws[k] = rng.random(n_draws)
        speed = draws[:, 0] * self.max_current_speed
        direction = _uniform(draws[:, 1], -math.pi, math.pi)
        self._validate_task_options(options)  # every option, before anything is changed
        if "current_speed" in options:
            speed[:] = float(options["current_speed"])
        if "current_direction" in options:
            direction[:] = float(options["current_direction"])
        task_draws = draws[:, _N_COMMON_DRAWS : self.n_draws]
        states = self._initial_states(task_draws)
        if "initial_state" in options:
            self._apply_initial_state(options["initial_state"], states)
        self.current[rows, 0] = speed
        self.current[rows, 1] = direction
        self.c[rows, 0] = speed * np.cos(direction)
        self.c[rows, 1] = speed * np.sin(direction)
        self.x[rows] = states
        self.steps[rows] = 0
        self.a[rows] = 0.0
        if self.delay is not None:
            self.delay.reset(rows)
        self._reset_task(rows, task_draws, options)
        if at_sea or self.seaway is not None:
            seaway = self._start_seaway()
            sea_draws = draws[:, self.n_draws :]
            if not at_sea:  # a calm episode in a batch with a seaway: no draws, no seaway
                sea_draws = np.zeros((rows.size, seaway_options.N_DRAWS))
            seaway.set_rows(rows, wind, sea, sea_draws)
            sw.start_rows(rows, self.x, self.c, seaway.sea, seaway.wf, seaway.rng, self.dt)
        self._kernel(rows.size)(*self._args(False, rows))

    def observe(self, states: np.ndarray) -> np.ndarray:
        """The observations of every row if its state were ``states`` (``(n, nx)``).

        The task's own kernel computes them (its observation pass, as at reset), so a
        measured state with sensor errors gives exactly the observation a ship with those
        errors would form. Nothing of the task changes: state, rewards, flags and task
        quantities (the active path segment) are restored.
        """
        states = np.asarray(states, dtype=np.float64)
        if states.shape != self.x.shape:
            raise ValueError(f"states must have shape {self.x.shape}, got {states.shape}")
        kept = [self.x, self.obs, self.rew, self.term, self.reason, self.c]
        if self.seaway is not None:
            kept += [self.xm, self.seaway.wf]
        kept += [a for a in self._kernel_args() if isinstance(a, np.ndarray)]
        saved = [a.copy() for a in kept]
        try:
            self.x[:] = states
            self._kernel(self.n)(*self._args(False, np.arange(self.n)))
            return self.obs.copy()
        finally:
            for a, old in zip(kept, saved, strict=True):
                a[...] = old

    def _validate_task_options(self, options: Mapping[str, Any]) -> None:
        """Raise ``ValueError`` for a bad option before anything is changed.

        Checks the ranges of the current options here; a task adds its own options' checks.
        """
        if "current_speed" in options:
            speed = _finite_float("current_speed", options["current_speed"])
            _check_range("'current_speed'", speed, 0.0, self.top_speed, "m/s")
        if "current_direction" in options:
            direction = _finite_float("current_direction", options["current_direction"])
            _check_range("'current_direction'", direction, *self.state_ranges()["psi"], "rad")

    def _apply_initial_state(self, value: Any, states: np.ndarray) -> None:
        """Override drawn ``states``: a dict sets the named states, a vector the whole state.

        Each state must be in its :meth:`state_ranges` range.
        """
        names = self.model.state_names
        ranges = self.state_ranges()
        if isinstance(value, Mapping):
            for key, v in value.items():
                if key not in names:
                    raise ValueError(f"initial_state has unknown state {key!r}; states: {names}")
                f = _finite_float(f"initial_state[{key!r}]", v)
                _check_range(f"initial_state[{key!r}]", f, *ranges[key], _STATE_UNITS[key])
                states[:, names.index(key)] = f
            return
        try:
            arr = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            arr = np.array([np.nan])
        if arr.shape != (len(names),) or not np.all(np.isfinite(arr)):
            raise ValueError(
                f"initial_state must be a dict of named states or {len(names)} finite values "
                f"{names}, got {value!r}"
            )
        for key, f in zip(names, arr.tolist(), strict=True):
            _check_range(f"initial_state[{key!r}]", f, *ranges[key], _STATE_UNITS[key])
        states[:] = arr

    def info(self, i: int) -> dict[str, Any]:
        """The ``info`` dict of row ``i``: physical state, current, task metrics."""
        speed, direction = self.current[i].tolist()  # (one call for both Python floats)
        return {
            "state": self.x[i].copy(),
            "current_speed": speed,
            "current_direction": direction,
            "termination_reason": kernels.REASONS[self.reason[i]],
            **self.metrics(i),
            **(self._seaway_row_info(i) if self.seaway is not None else {}),
        }

    def _seaway_row_info(self, i: int) -> dict[str, Any]:
        """The seaway's entries of row ``i``'s ``info``, and its measured state."""
        assert self.seaway is not None
        return {**self.seaway.row_info(i), "measured_state": self.xm[i].copy()}

    def batch_info(self, rows: slice | np.ndarray = slice(None)) -> dict[str, np.ndarray]:
        """The ``info`` of ``rows`` (default all) as arrays: entry ``k`` of each is the value
        of ``info(i)`` for the ``k``-th row ``i``.

        The dtypes are those Gymnasium's ``SyncVectorEnv`` gives the single env's values
        (float64, int64, bool; ``object`` holding ``str`` for ``termination_reason``). Every
        array is new, so it stays valid after later steps. A slice is the fast way to ask for
        all rows (copies instead of fancy indexing).
        """
        reason = self.reason[rows]
        if reason.any():
            names = _REASON_NAMES[reason]
        else:  # the usual step: filling is cheaper than indexing an object array
            names = np.empty(reason.shape, dtype=object)
            names.fill(kernels.REASONS[0])
        info = {
            "state": np.array(self.x[rows]),
            "current_speed": np.array(self.current[rows, 0]),
            "current_direction": np.array(self.current[rows, 1]),
            "termination_reason": names,
        }
        for key, value in self.batch_metrics(rows).items():
            # a view of the task's arrays is copied; an array made for this call is new already
            info[key] = value if value.base is None else value.copy()
        if self.seaway is not None:
            info.update(self.seaway.info(rows))
            info["measured_state"] = np.array(self.xm[rows])
        return info


#: ``kernels.REASONS`` as an object array: ``_REASON_NAMES[reason]`` names a batch of codes.
_REASON_NAMES = np.array(kernels.REASONS, dtype=object)


class ScheduleMixin:
    """Setpoints held ``setpoint_interval`` seconds each, the last one to the end."""

    max_setpoints: ClassVar[int] = 8
    dt: ClassVar[float]
    n: int

    def _setup_schedule(self, setpoint_interval: float) -> None:
        hold = round(setpoint_interval / self.dt) if math.isfinite(setpoint_interval) else 0
        if hold < 1:
            raise ValueError(
                f"setpoint_interval must be a finite time >= one step ({self.dt} s), "
                f"got {setpoint_interval!r}"
            )
        self.hold_steps = int(hold)
        self.schedule = np.zeros((self.n, self.max_setpoints))

    def _set_schedule(self, rows: np.ndarray, setpoints: np.ndarray) -> None:
        """Write ``setpoints`` (``(r, k)`` or ``(k,)``) into the schedule of ``rows``."""
        setpoints = np.broadcast_to(setpoints, (rows.size, setpoints.shape[-1]))
        k = setpoints.shape[1]
        self.schedule[rows] = setpoints[:, -1:]
        self.schedule[rows, :k] = setpoints


class HeadingTask(ScheduleMixin, Task):
    """Reach and hold heading setpoints that change every ``setpoint_interval`` seconds."""

    kernel_name = "heading"
    task_options = frozenset({"setpoints"})
    n_random_setpoints: ClassVar[int]
    change_range_deg: ClassVar[tuple[float, float]]
    obs_state_names: ClassVar[tuple[str, ...]]

    def __init__(
        self, n: int, model: ShipModel, max_current_speed: float, setpoint_interval: float
    ) -> None:
        Task.__init__(self, n, model, max_current_speed)
        self._setup_schedule(setpoint_interval)
        self.ipsi = model.index("psi")
        self.obs_idx = np.array([model.index(s) for s in self.obs_state_names], dtype=np.int64)
        self.n_task_draws = 1 + 2 * self.n_random_setpoints

    def _kernel_args(self) -> tuple[Any, ...]:
        return (self.ipsi, self.obs_idx, self.schedule, self.hold_steps)

    def _validate_task_options(self, options: Mapping[str, Any]) -> None:
        super()._validate_task_options(options)
        if "setpoints" in options:
            sp = _finite_vector("setpoints", options["setpoints"], self.max_setpoints)
            _check_range("'setpoints'", sp, *self.state_ranges()["psi"], "rad")

    def _reset_task(self, rows: np.ndarray, draws: np.ndarray, options: Mapping[str, Any]) -> None:
        if "setpoints" in options:
            setpoints = ssa(_finite_vector("setpoints", options["setpoints"], self.max_setpoints))
        else:
            k = self.n_random_setpoints
            lo, hi = np.radians(self.change_range_deg)
            sign = np.where(draws[:, 1 + k : 1 + 2 * k] < 0.5, -1.0, 1.0)
            changes = _uniform(draws[:, 1 : 1 + k], lo, hi) * sign
            setpoints = ssa(self.x[rows, self.ipsi][:, None] + np.cumsum(changes, axis=1))
        self._set_schedule(rows, setpoints)

    def metrics(self, i: int) -> dict[str, Any]:
        held = min(self.steps.item(i) // self.hold_steps, self.max_setpoints - 1)
        return {
            "heading_error": self.obs.item(i, 0),
            "heading_setpoint": self.schedule.item(i, held),
        }

    def batch_metrics(self, rows: slice | np.ndarray) -> dict[str, Any]:
        held = np.minimum(self.steps[rows] // self.hold_steps, self.max_setpoints - 1)
        # one flat take: twice as fast as 2-D fancy indexing for a large batch
        flat = np.arange(0, self.schedule.size, self.max_setpoints)[rows] + held
        return {"heading_error": self.obs[rows, 0], "heading_setpoint": self.schedule.take(flat)}


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
    obs_bounds = ((-math.pi, math.pi), (-0.5, 0.5), (-math.pi / 2, math.pi / 2))
    reward_bounds = (-1.05, 0.0)
    ship_length = 160.9  # [m], the Mariner class cargo ship
    ship_beam = 23.2  # [m]
    seaway_ship = staticmethod(sw.mariner_seaway)

    def __init__(
        self,
        n: int,
        model: Any = "nomoto1",
        max_current_speed: float = 1.0,
        setpoint_interval: float = 200.0,
    ) -> None:
        if isinstance(getattr(model, "model_file", None), Mapping):
            model = model.model_file  # an identification result: its model file
        ship = nomoto_ship(model)
        if isinstance(model, Mapping) or is_model_file(model):
            length = model_info(model).get("length_m")
            # an identified ship of unknown length: a small craft's, so the ranges are wide
            self.ship_length = float(length) if length else IDENTIFIED_SHIP_LENGTH
            self.seaway_ship = None  # its wind areas and hull are not known
        super().__init__(n, ship, max_current_speed, setpoint_interval)
        gear, surge = self.model.gear, self.model.surge
        assert gear is not None and surge is not None
        self.u0[:] = (0.0, surge.service_shaft_speed)
        self.B[0, 0] = gear.max_angle
        self.service_speed = surge.service_speed

    @property
    def top_speed(self) -> float:
        """Speed [m/s] at the largest shaft speed (9.9 m/s for the Mariner)."""
        surge = self.model.surge
        assert surge is not None
        return _limit(surge.gain * surge.max_shaft_speed)

    def _actuator_ranges(self) -> dict[str, tuple[float, float]]:
        gear = self.model.gear
        assert gear is not None
        return {"delta": (-_limit(gear.max_angle), _limit(gear.max_angle))}

    def _initial_states(self, draws: np.ndarray) -> np.ndarray:
        x = np.zeros((draws.shape[0], self.model.nx))
        x[:, self.ipsi] = _uniform(draws[:, 0], -math.pi, math.pi)
        x[:, self.model.index("U")] = self.service_speed
        return x


IDENTIFIED_SHIP_LENGTH = 10.0
"""Length [m] taken for an identified ship whose model file states none (for the ranges of the
reset options: a short ship allows fast turns)."""


def nomoto_ship(model: Any) -> ShipModel:
    """The Nomoto-family ship of ``shipgym/NomotoHeading-v0``: a model name, a model file
    (``shipgym identify --json``) or its parsed document, or a :class:`ShipModel` of the
    family."""
    if isinstance(model, ShipModel):
        ship = model
    elif isinstance(model, Mapping) or is_model_file(model):
        ship = load_model(model)
    elif isinstance(model, str) and model in NOMOTO_MODEL_NAMES:
        return make_model(model)
    else:
        raise ValueError(
            f"unknown model {model!r}; expected one of {NOMOTO_MODEL_NAMES}, a model file "
            "FIT.json (shipgym identify --json) or a ShipModel of the Nomoto family"
        )
    if ship.name not in NOMOTO_MODEL_NAMES:
        raise ValueError(
            f"model {ship.name!r} ({model!r}) is not of the Nomoto family {NOMOTO_MODEL_NAMES} "
            "that this env steers (an rvg3dof fit sails the Gunnerus envs as params=FILE, the "
            "other 3-DOF fits run in shipgym simulate)"
        )
    return ship


class RVGMixin:
    """Common set-up of the Gunnerus tasks: model, azimuth range, thrust, initial motion.

    A drawn initial state moves straight ahead through the water (``nu_r = [U, 0, 0]``), so
    ``nu = nu_r + nu_c``; an ``initial_state`` option is taken as given.
    """

    dt = 0.5
    ship_length = LPP
    seaway_ship = staticmethod(sw.gunnerus_seaway)
    x: np.ndarray
    c: np.ndarray
    model: ShipModel

    @property
    def top_speed(self) -> float:
        """``thrust_zero_speed`` [m/s]: above it the pods push no more (8.7 m/s)."""
        return _limit(self.model.params.thrust_zero_speed)

    def _actuator_ranges(self) -> dict[str, tuple[float, float]]:
        params = self.model.params
        thrust = (0.0, _limit(params.bollard_thrust))
        azimuth = (-_limit(params.azimuth_max), _limit(params.azimuth_max))
        return {"T1": thrust, "T2": thrust, "alpha1": azimuth, "alpha2": azimuth}

    def _setup_rvg(self, max_azimuth: float) -> None:
        if not (math.isfinite(max_azimuth) and 0 < max_azimuth <= math.pi):
            raise ValueError(f"max_azimuth must be in (0, pi] rad, got {max_azimuth!r}")
        self.params = self.model.params
        self.max_azimuth = float(max_azimuth)
        self.bollard = self.params.bollard_thrust

    def _rvg_states(self, psi: np.ndarray, speed: float | np.ndarray, thrust: float) -> np.ndarray:
        x = np.zeros((psi.size, 10))
        x[:, IPSI] = psi
        x[:, IU] = speed
        x[:, IT1] = x[:, IT2] = thrust
        return x

    def _add_current(self, rows: np.ndarray, options: Mapping[str, Any]) -> None:
        if "initial_state" in options:
            return
        psi = self.x[rows, IPSI]
        cn, ce = self.c[rows, 0], self.c[rows, 1]
        self.x[rows, IU] += cn * np.cos(psi) + ce * np.sin(psi)
        self.x[rows, IV] += -cn * np.sin(psi) + ce * np.cos(psi)

    def _setup_two_input_actions(self) -> None:
        """``[azimuth, thrust]`` actions: azimuth fraction of ``max_azimuth``, thrust 0..bollard."""
        half = 0.5 * self.bollard
        self.u0[:] = (half, half, 0.0, 0.0)  # type: ignore[attr-defined]
        self.B[2, 0] = self.B[3, 0] = self.max_azimuth  # type: ignore[attr-defined]
        self.B[0, 1] = self.B[1, 1] = half  # type: ignore[attr-defined]


class RVGHeadingTask(RVGMixin, HeadingTask):
    """Gunnerus, common pod azimuth command, heading setpoints (``shipgym/RVGHeading-v0``)."""

    obs_dim = 5
    act_dim = 1
    max_episode_steps = 600
    n_random_setpoints = 3
    change_range_deg = (10.0, 45.0)
    obs_state_names = ("r", "alpha1", "u", "v")
    obs_names = ("heading_error", "r", "alpha1", "u", "v")
    obs_bounds = (
        (-math.pi, math.pi),
        (-0.5, 0.5),
        (-math.pi, math.pi),
        (-10.0, 15.0),
        (-10.0, 10.0),
    )
    reward_bounds = (-1.05, 0.0)

    def __init__(
        self,
        n: int,
        max_current_speed: float = 0.5,
        max_azimuth: float = math.radians(35.0),
        setpoint_interval: float = 100.0,
        params: str | RVGParams = "seed001",
    ) -> None:
        model = make_model("rvg3dof", params)
        HeadingTask.__init__(self, n, model, max_current_speed, setpoint_interval)
        self._setup_rvg(max_azimuth)
        ts = self.params.service_thrust
        self.u0[:] = (ts, ts, 0.0, 0.0)
        self.B[2, 0] = self.B[3, 0] = self.max_azimuth

    def _initial_states(self, draws: np.ndarray) -> np.ndarray:
        psi = _uniform(draws[:, 0], -math.pi, math.pi)
        return self._rvg_states(psi, SERVICE_SPEED, self.params.service_thrust)

    def _reset_task(self, rows: np.ndarray, draws: np.ndarray, options: Mapping[str, Any]) -> None:
        self._add_current(rows, options)
        HeadingTask._reset_task(self, rows, draws, options)


class RVGSpeedTask(RVGMixin, ScheduleMixin, Task):
    """Gunnerus, common pod thrust command, speed setpoints (``shipgym/RVGSpeed-v0``)."""

    act_dim, obs_dim = kernels.SPEED_DIMS
    max_episode_steps = 800
    kernel_name = "speed"
    n_task_draws = 4
    task_options = frozenset({"setpoints"})
    obs_names = ("speed_error", "u_r", "thrust_fraction", "speed_setpoint")
    obs_bounds = ((-25.0, 25.0), (-10.0, 15.0), (0.0, 1.0), (0.0, 15.0))
    #: The speed error in the reward is that of the observation, clipped to +-25 m/s.
    reward_bounds = (-12.55, 0.0)
    speed_range = (1.5, 6.0)

    def __init__(
        self,
        n: int,
        max_current_speed: float = 0.5,
        max_azimuth: float = math.radians(35.0),
        setpoint_interval: float = 200.0,
        params: str | RVGParams = "seed001",
    ) -> None:
        Task.__init__(self, n, make_model("rvg3dof", params), max_current_speed)
        self._setup_rvg(max_azimuth)
        self._setup_schedule(setpoint_interval)
        half = 0.5 * self.bollard
        self.u0[:] = (half, half, 0.0, 0.0)
        self.B[0, 0] = self.B[1, 0] = half

    def _kernel_args(self) -> tuple[Any, ...]:
        return (self.schedule, self.hold_steps)

    def _initial_states(self, draws: np.ndarray) -> np.ndarray:
        psi = _uniform(draws[:, 0], -math.pi, math.pi)
        return self._rvg_states(psi, _uniform(draws[:, 1], 0.0, 5.0), 0.0)

    def _validate_task_options(self, options: Mapping[str, Any]) -> None:
        super()._validate_task_options(options)
        if "setpoints" in options:
            sp = _finite_vector("setpoints", options["setpoints"], self.max_setpoints)
            _check_range("'setpoints'", sp, 0.0, self.top_speed, "m/s")

    def _reset_task(self, rows: np.ndarray, draws: np.ndarray, options: Mapping[str, Any]) -> None:
        self._add_current(rows, options)
        if "setpoints" in options:
            setpoints = _finite_vector("setpoints", options["setpoints"], self.max_setpoints)
        else:
            setpoints = _uniform(draws[:, 2:4], *self.speed_range)
        self._set_schedule(rows, setpoints)

    def metrics(self, i: int) -> dict[str, Any]:
        return {"speed_error": self.obs.item(i, 0), "speed_setpoint": self.obs.item(i, 3)}

    def batch_metrics(self, rows: slice | np.ndarray) -> dict[str, Any]:
        return {"speed_error": self.obs[rows, 0], "speed_setpoint": self.obs[rows, 3]}


class RVGPathTask(RVGMixin, Task):
    """Gunnerus following straight legs between waypoints (``shipgym/RVGPathFollowing-v0``)."""

    act_dim, obs_dim = kernels.PATH_DIMS
    max_episode_steps = 1600
    kernel_name = "path"
    max_waypoints = 16
    max_random_legs = 5
    # draws: heading offset, cross-track offset, number of legs, first course, legs, turns
    n_task_draws = 4 + 2 * max_random_legs
    task_options = frozenset({"waypoints"})
    obs_names = (
        "cross_track_error",
        "course_error",
        "along_track_left",
        "next_turn",
        "u",
        "v",
        "r",
        "alpha1",
        "thrust_fraction",
    )
    obs_bounds = (
        (-1e4, 1e4),
        (-math.pi, math.pi),
        (-1e4, 1e4),
        (-math.pi, math.pi),
        (-10.0, 15.0),
        (-10.0, 10.0),
        (-0.5, 0.5),
        (-math.pi, math.pi),
        (0.0, 1.0),
    )
    #: Per step in [-0.7, 1]; +20 on reaching the last waypoint, -20 on leaving the path.
    reward_bounds = (-20.7, 21.0)

    def __init__(
        self,
        n: int,
        max_current_speed: float = 0.5,
        max_azimuth: float = math.radians(35.0),
        accept_radius: float = 2.0 * LPP,
        max_cross_track: float = 250.0,
        params: str | RVGParams = "seed001",
    ) -> None:
        Task.__init__(self, n, make_model("rvg3dof", params), max_current_speed)
        self._setup_rvg(max_azimuth)
        self.accept_radius = _positive("accept_radius", accept_radius)
        self.max_cross_track = _positive("max_cross_track", max_cross_track)
        w = self.max_waypoints
        self.tangent = np.zeros((n, w, 4))  # x_k, y_k, cos chi_k, sin chi_k
        self.leg_length = np.zeros((n, w))
        self.leg_angle = np.zeros((n, w))
        self.turn = np.zeros((n, w))
        self.n_wp = np.full(n, 2, dtype=np.int64)
        self.seg = np.zeros(n, dtype=np.int64)
        self._setup_two_input_actions()

    def _kernel_args(self) -> tuple[Any, ...]:
        return (
            self.tangent,
            self.leg_length,
            self.leg_angle,
            self.turn,
            self.n_wp,
            self.seg,
            self.accept_radius,
            self.max_cross_track,
            SERVICE_SPEED,
        )

    def _initial_states(self, draws: np.ndarray) -> np.ndarray:
        # Placed on the path by _reset_task: psi holds the offset from the first leg's course.
        psi = _uniform(draws[:, 0], -math.radians(30.0), math.radians(30.0))
        return self._rvg_states(psi, SERVICE_SPEED, self.params.service_thrust)

    def _validate_task_options(self, options: Mapping[str, Any]) -> None:
        super()._validate_task_options(options)
        if "waypoints" in options:
            self._given_path(options["waypoints"])

    def _given_path(self, value: Any) -> np.ndarray:
        try:
            path = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            path = np.zeros((0, 2))
        if (
            path.ndim != 2
            or path.shape[1] != 2
            or not 2 <= path.shape[0] <= self.max_waypoints
            or not np.all(np.isfinite(path))
        ):
            raise ValueError(
                f"option 'waypoints' must be 2 to {self.max_waypoints} finite (north, east) "
                f"points in m, got {value!r}"
            )
        if np.any(np.hypot(*np.diff(path, axis=0).T) < 1e-6):
            raise ValueError("option 'waypoints' has two consecutive identical waypoints")
        _check_range("'waypoints'", path, -self.arena, self.arena, "m (north and east)")
        return path

    def _random_paths(self, draws: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Waypoints ``(r, max_random_legs + 1, 2)`` and the number used per row (4 to 6)."""
        k = self.max_random_legs
        n_wp = 4 + np.minimum((draws[:, 2] * 3).astype(np.int64), 2)
        turns = _uniform(draws[:, 4 + k : 4 + 2 * k], -math.radians(60), math.radians(60))
        turns[:, 0] = _uniform(draws[:, 3], -math.pi, math.pi)
        course = np.cumsum(turns, axis=1)
        legs = _uniform(draws[:, 4 : 4 + k], 200.0, 400.0)
        path = np.zeros((draws.shape[0], k + 1, 2))
        path[:, 1:, 0] = np.cumsum(legs * np.cos(course), axis=1)
        path[:, 1:, 1] = np.cumsum(legs * np.sin(course), axis=1)
        return path, n_wp

    def _reset_task(self, rows: np.ndarray, draws: np.ndarray, options: Mapping[str, Any]) -> None:
        r = rows.size
        if "waypoints" in options:
            given = self._given_path(options["waypoints"])
            path = np.broadcast_to(given, (r, *given.shape))
            n_wp = np.full(r, given.shape[0], dtype=np.int64)
        else:
            path, n_wp = self._random_paths(draws)
        kernels.set_path_legs(
            rows, np.ascontiguousarray(path), n_wp, self.tangent, self.leg_length,
            self.leg_angle, self.turn, self.n_wp, self.seg,
        )  # fmt: skip
        if "initial_state" not in options:
            chi0 = self.leg_angle[rows, 0]
            offset = _uniform(draws[:, 1], -30.0, 30.0)
            self.x[rows, IX] = path[:, 0, 0] - offset * np.sin(chi0)
            self.x[rows, IY] = path[:, 0, 1] + offset * np.cos(chi0)
            self.x[rows, IPSI] = ssa(chi0 + self.x[rows, IPSI])
            self._add_current(rows, options)

    def metrics(self, i: int) -> dict[str, Any]:
        return {
            "cross_track_error": self.obs.item(i, 0),
            "segment": self.seg.item(i),
            "completed": self.reason.item(i) == kernels.SUCCESS,
        }

    def batch_metrics(self, rows: slice | np.ndarray) -> dict[str, Any]:
        return {
            "cross_track_error": self.obs[rows, 0],
            "segment": self.seg[rows],
            "completed": self.reason[rows] == kernels.SUCCESS,
        }

    def waypoints(self, i: int) -> np.ndarray:
        """The waypoints (north, east) [m] of row ``i``."""
        return self.tangent[i, : self.n_wp[i], :2].copy()


class RVGTargetTask(RVGMixin, Task):
    """Gunnerus intercepting a moving target and holding a distance (``RVGTargetTracking-v0``)."""

    act_dim, obs_dim = kernels.TARGET_DIMS
    max_episode_steps = 1600
    kernel_name = "target"
    n_task_draws = 5  # heading, target range, bearing, course, speed
    task_options = frozenset({"target_position", "target_velocity", "distance"})
    obs_names = (
        "target_x_body",
        "target_y_body",
        "target_vx_body",
        "target_vy_body",
        "distance_error",
        "u",
        "v",
        "r",
        "alpha1",
        "thrust_fraction",
    )
    obs_bounds = (
        (-1e5, 1e5),
        (-1e5, 1e5),
        (-50.0, 50.0),
        (-50.0, 50.0),
        (-1e5, 1e5),
        (-10.0, 15.0),
        (-10.0, 10.0),
        (-0.5, 0.5),
        (-math.pi, math.pi),
        (0.0, 1.0),
    )
    #: Per step in [-1.1, 1]; -20 when the target gets away.
    reward_bounds = (-21.1, 1.0)

    def __init__(
        self,
        n: int,
        max_current_speed: float = 0.5,
        max_azimuth: float = math.radians(35.0),
        distance: float = 50.0,
        max_distance: float = 3000.0,
        params: str | RVGParams = "seed001",
    ) -> None:
        Task.__init__(self, n, make_model("rvg3dof", params), max_current_speed)
        self._setup_rvg(max_azimuth)
        self.default_distance = _positive("distance", distance)
        self.max_distance = _positive("max_distance", max_distance)
        self.target = np.zeros((n, 2))
        self.target_vel = np.zeros((n, 2))
        self.distance = np.full(n, self.default_distance)
        self._setup_two_input_actions()

    def _kernel_args(self) -> tuple[Any, ...]:
        return (self.target, self.target_vel, self.distance, self.max_distance)

    def _initial_states(self, draws: np.ndarray) -> np.ndarray:
        psi = _uniform(draws[:, 0], -math.pi, math.pi)
        return self._rvg_states(psi, SERVICE_SPEED, self.params.service_thrust)

    @property
    def arena(self) -> float:
        """As for every task, but at least ``max_distance`` [m]."""
        return max(super().arena, _limit(self.max_distance))

    def _validate_task_options(self, options: Mapping[str, Any]) -> None:
        super()._validate_task_options(options)
        if "target_position" in options:
            pos = _point("target_position", options["target_position"])
            _check_range("'target_position'", pos, -self.arena, self.arena, "m (north and east)")
        if "target_velocity" in options:
            vel = _point("target_velocity", options["target_velocity"])
            speed = float(np.hypot(*vel))
            if not speed <= self.speed_limit:
                raise ValueError(
                    f"option 'target_velocity' must have a speed in [0, {self.speed_limit:g}] "
                    f"m/s, got {vel.tolist()!r} ({speed:.4g} m/s)"
                )
        if "distance" in options:
            distance = _finite_float("distance", options["distance"])
            if not 0.0 < distance <= self.max_distance:
                raise ValueError(
                    f"option 'distance' must be in (0, {self.max_distance:g}] m (up to "
                    f"max_distance), got {options['distance']!r}"
                )

    def _reset_task(self, rows: np.ndarray, draws: np.ndarray, options: Mapping[str, Any]) -> None:
        self._add_current(rows, options)
        rng_range = _uniform(draws[:, 1], 300.0, 800.0)
        bearing = self.x[rows, IPSI] + _uniform(draws[:, 2], -math.pi / 3, math.pi / 3)
        course = _uniform(draws[:, 3], -math.pi, math.pi)
        speed = _uniform(draws[:, 4], 1.0, 3.0)
        self.target[rows, 0] = self.x[rows, IX] + rng_range * np.cos(bearing)
        self.target[rows, 1] = self.x[rows, IY] + rng_range * np.sin(bearing)
        self.target_vel[rows, 0] = speed * np.cos(course)
        self.target_vel[rows, 1] = speed * np.sin(course)
        if "target_position" in options:
            self.target[rows] = _point("target_position", options["target_position"])
        if "target_velocity" in options:
            self.target_vel[rows] = _point("target_velocity", options["target_velocity"])
        self.distance[rows] = (
            _finite_float("distance", options["distance"])
            if "distance" in options
            else self.default_distance
        )

    def metrics(self, i: int) -> dict[str, Any]:
        err = self.obs.item(i, 4)
        return {"distance": err + self.distance.item(i), "distance_error": err}

    def batch_metrics(self, rows: slice | np.ndarray) -> dict[str, Any]:
        err = self.obs[rows, 4]
        return {"distance": err + self.distance[rows], "distance_error": err}

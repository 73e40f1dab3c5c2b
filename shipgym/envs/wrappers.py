"""Gymnasium wrappers for the robustness conditions: sensor noise and an actuator delay.

They wrap a single shipgym env or, as Gymnasium vector wrappers, a batch (the native vector
env, ``gymnasium.make_vec(id, n, vectorization_mode="vector_entry_point")``), and change only
what a controller sees or commands, never the ship, so the same scenario (seed) runs with and
without them and metrics stay those of the true motion. A single and a vector wrapper share
their definition (levels, channels, seeding, the holding action), and row ``i`` of a wrapped
batch equals the wrapped single env Gymnasium's ``SyncVectorEnv`` would hold there, bitwise.

:class:`SensorNoise`, :class:`VectorSensorNoise`
    White Gaussian errors on the measured heading, yaw rate, speed (surge and sway) and
    position, drawn at every control step. The observation is the one the task forms from the
    *measured* state (:meth:`shipgym.envs.tasks.Task.observe`: the env's own kernel, so a
    heading error shifts the heading-error channel, a position error the cross-track error
    and the target's relative position); ``info["measured_state"]`` carries the measured
    state for controllers that read states, ``info["state"]`` stays the truth. At sea the
    sensors measure the low-frequency motion plus the wave-frequency motion: the noise is
    added to the env's own ``measured_state`` (the state with the wave-frequency motion), and
    the observation is formed from the noisy state with the wave-frequency motion, as the env
    forms it.
    :data:`SENSOR_NOISE` gives the default levels, typical of a ship's sensors: heading 0.5
    deg (gyrocompass), yaw rate 0.1 deg/s (rate-of-turn sensor), speed 0.1 m/s (speed log,
    GNSS), position 1 m (DGNSS). Each episode has its own noise generator,
    :func:`noise_generator` of its reset seed (of a number drawn from the env's random stream
    when it is reset without one), so a row of a batch draws the noise of the single env
    reset with that row's seed, and rows that do not step (parked) draw nothing.
:class:`ActuatorDelay`, :class:`VectorActuatorDelay`
    A transport delay of ``delay`` seconds (rounded to whole control steps) between the
    command and the actuator; until the first command arrives the actuators hold the setting
    they start the episode with (each row's queue is filled with its holding action at its
    reset).

The vector wrappers follow the env's autoreset mode: next-step, and disabled with
``reset(options={"reset_mask": mask})`` and parked rows (:class:`~shipgym.envs.core.ShipVectorEnv`);
:class:`VectorActuatorDelay` also same-step. :class:`VectorSensorNoise` refuses same-step mode:
there the finished episode's last observation would have to be formed again from its measured
state after the autoreset has replaced the episode's setpoints, path or target.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping, Sequence
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv, VectorWrapper

from shipgym.envs.core import ShipVectorEnv, reset_rows_of, sub_env_seeds
from shipgym.envs.tasks import Task

#: Default sensor noise, one standard deviation per control step: heading [rad], yaw rate
#: [rad/s], speed [m/s], position [m].
SENSOR_NOISE: dict[str, float] = {
    "heading": math.radians(0.5),
    "yaw_rate": math.radians(0.1),
    "speed": 0.1,
    "position": 1.0,
}
#: Measured states per noise channel (states a model lacks are skipped).
_CHANNELS = {
    "heading": ("psi",),
    "yaw_rate": ("r",),
    "speed": ("u", "v", "U"),
    "position": ("x", "y"),
}
#: Second word of the noise generator's seed: the noise stream of an episode is not the env's.
_NOISE_STREAM = 0x5E4503
#: A reset without a seed seeds the noise with an integer in [0, _ENTROPY_HIGH) drawn from the
#: env's random stream.
_ENTROPY_HIGH = 2**62


def _nonnegative(name: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v):
        raise ValueError(f"{name!r} must be finite (a number >= 0), got {value!r}")
    if v < 0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return v


def noise_generator(seed: int) -> np.random.Generator:
    """The sensor-noise generator of an episode reset with ``seed``."""
    return np.random.default_rng([seed, _NOISE_STREAM])


class _NoiseModel:
    """The noise levels of :class:`SensorNoise` and the states of a ship they act on."""

    def __init__(self, state_names: Sequence[str], std: Mapping[str, Any]) -> None:
        unknown = sorted(set(std) - set(SENSOR_NOISE))
        if unknown:
            raise ValueError(f"unknown noise channel(s) {unknown}; expected {list(SENSOR_NOISE)}")
        self.levels = {k: _nonnegative(k, std.get(k, v)) for k, v in SENSOR_NOISE.items()}
        used = [(k, s) for k in self.levels for s in _CHANNELS[k] if s in state_names]
        self.index = np.array([list(state_names).index(s) for _, s in used], dtype=np.int64)
        self.std = np.array([self.levels[k] for k, _ in used])

    def measure(
        self, task: Task, rows: Sequence[int] | np.ndarray, draws: _NoiseDraws
    ) -> tuple[np.ndarray, np.ndarray]:
        """The states of ``task``'s ships with noise on ``rows`` (each of them takes its next
        standard normal per noisy state from its stream of ``draws``): the true states
        ``task.x`` with the noise (what the task's kernel observes: it adds the
        wave-frequency motion itself) and the states as the sensors give them,
        ``task.xm`` (the true states plus the wave-frequency motion at sea) with the same
        noise, both ``(n, nx)`` copies."""
        noisy = np.array(task.x, dtype=np.float64)
        sensed = np.array(task.xm, dtype=np.float64)
        rows = np.asarray(rows, dtype=np.int64)
        if rows.size:
            noise = self.std * draws.next(rows)
            noisy[np.ix_(rows, self.index)] += noise
            sensed[np.ix_(rows, self.index)] += noise
        return noisy, sensed


class _NoiseDraws:
    """The sensor-noise generator of every row (:func:`noise_generator` of its episode's seed),
    drawn :attr:`BLOCK` steps ahead.

    A generator's standard normals come out in the same order however many are asked for at a
    time, so a row's noise is the same as one draw of ``size`` numbers per step, at one
    generator call per row every :attr:`BLOCK` steps.

    Parameters
    ----------
    rows : int
        Rows (sub-envs).
    size : int
        Numbers each row draws per step.
    """

    #: Steps drawn at a time.
    BLOCK = 64

    def __init__(self, rows: int, size: int) -> None:
        self.size = size
        self._rngs: list[np.random.Generator | None] = [None] * rows
        self._ahead = np.zeros((rows, self.BLOCK, size))
        self._used = np.full(rows, self.BLOCK, dtype=np.int64)

    def start(self, rows: Sequence[int] | np.ndarray, seeds: Sequence[int]) -> None:
        """Begin the episodes of ``rows``: row ``rows[k]`` draws from the generator of
        ``seeds[k]``."""
        for i, seed in zip(rows, seeds, strict=True):
            self._rngs[i] = noise_generator(seed)
            self._used[i] = self.BLOCK

    def next(self, rows: np.ndarray) -> np.ndarray:
        """The next ``size`` numbers of each of ``rows`` (distinct), shape ``(len(rows), size)``."""
        for i in rows[self._used[rows] >= self.BLOCK]:
            rng = self._rngs[i]
            if rng is None:
                raise RuntimeError(f"row {i} has no noise generator: reset it first")
            self._ahead[i] = rng.standard_normal((self.BLOCK, self.size))
            self._used[i] = 0
        out = self._ahead[rows, self._used[rows]]
        self._used[rows] += 1
        return out


def _holding_actions(task: Task, rows: Sequence[int] | np.ndarray) -> np.ndarray:
    """Actions ``(len(rows), act_dim)`` (float32) that command every actuator of each row's
    ship to the setting it has now: the least-squares ``a`` of ``B a = u - u0``, clipped to
    [-1, 1] (one solve per row, so a row's action does not depend on the others)."""
    model = task.model
    held_states = [
        (j, model.index(name.removesuffix("_c")))
        for j, name in enumerate(model.input_names)
        if name.removesuffix("_c") in model.state_names
    ]
    out = np.empty((len(rows), task.act_dim), dtype=np.float32)
    for k, i in enumerate(rows):
        held = task.u0.copy()
        for j, s in held_states:
            held[j] = task.x[i, s]
        action, *_ = np.linalg.lstsq(task.B, held - task.u0, rcond=None)
        out[k] = np.clip(action, -1.0, 1.0)
    return out


def _delay_steps(delay: Any, dt: float) -> tuple[int, float]:
    """Whole control steps of a transport delay of ``delay`` seconds, and that delay [s]."""
    steps = round(_nonnegative("delay", delay) / dt)
    return steps, steps * dt


def _ship_vector_env(env: VectorEnv, wrapper: str) -> ShipVectorEnv:
    base = env.unwrapped
    if not isinstance(base, ShipVectorEnv):
        raise ValueError(
            f"{wrapper} wraps a shipgym vector env (gymnasium.make_vec(id, n, "
            f"vectorization_mode='vector_entry_point')), got {type(base).__name__}"
        )
    return base


class SensorNoise(gym.Wrapper):
    """White Gaussian measurement noise on heading, yaw rate, speed and position.

    Parameters
    ----------
    env : gymnasium.Env
        A shipgym env (single).
    heading, yaw_rate, speed, position : float, optional
        Standard deviations [rad, rad/s, m/s, m]; defaults :data:`SENSOR_NOISE`.

    Notes
    -----
    The noise generator of an episode reset with seed ``s`` is :func:`noise_generator` of
    ``s``, so an episode's noise sequence is reproducible and the same for every controller
    run on that seed (a reset without a seed draws one from the env's random stream).
    """

    def __init__(self, env: gym.Env, **std: float) -> None:
        super().__init__(env)
        self._noise = _NoiseModel(env.unwrapped.task.model.state_names, std)
        self.std = self._noise.levels
        self._draws = _NoiseDraws(1, self._noise.index.size)

    def _measure(self, obs: np.ndarray, info: dict[str, Any]) -> tuple[np.ndarray, dict]:
        task = self.env.unwrapped.task
        noisy, measured = self._noise.measure(task, [0], self._draws)
        return task.observe(noisy)[0].astype(obs.dtype), {**info, "measured_state": measured[0]}

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        if seed is None:
            seed = int(self.env.unwrapped.np_random.integers(_ENTROPY_HIGH))
        self._draws.start([0], [seed])
        return self._measure(obs, info)

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        obs, info = self._measure(obs, info)
        return obs, reward, terminated, truncated, info


class VectorSensorNoise(VectorWrapper):
    """:class:`SensorNoise` for a batch: each row with its own episode's noise generator.

    Row ``i`` of a batch reset with seed ``s`` (or ``s[i]`` of a list) draws from
    :func:`noise_generator` of ``s + i`` (``s[i]``), the generator of a single
    :class:`SensorNoise` env reset with that seed; a row reset without a seed (an autoreset,
    ``seed=None``) seeds it from its own random stream as the single env does. So the batch
    equals ``SyncVectorEnv`` of single envs wrapped in :class:`SensorNoise`, observations and
    ``info["measured_state"]`` (``(n, nx)``, flagged by ``info["_measured_state"]``) bitwise.

    Parameters
    ----------
    env : gymnasium.vector.VectorEnv
        A shipgym vector env (possibly wrapped) in next-step or disabled autoreset mode.
    heading, yaw_rate, speed, position : float, optional
        Standard deviations [rad, rad/s, m/s, m]; defaults :data:`SENSOR_NOISE`.

    Notes
    -----
    Rows parked in disabled mode draw no noise and keep their last observation; their
    ``measured_state`` entries are unflagged (zero). Each row has its own generator, so which
    rows are parked never changes the noise of the others.
    """

    def __init__(self, env: VectorEnv, **std: float) -> None:
        super().__init__(env)
        base = _ship_vector_env(env, "VectorSensorNoise")
        if base.autoreset_mode is AutoresetMode.SAME_STEP:
            raise ValueError(
                "VectorSensorNoise needs autoreset_mode 'NextStep' or 'Disabled', got "
                "'SameStep' (a finished episode's last observation cannot be formed from its "
                "measured state after the autoreset)"
            )
        self._noise = _NoiseModel(base.task.model.state_names, std)
        self.std = self._noise.levels
        self._draws = _NoiseDraws(self.num_envs, self._noise.index.size)
        self._obs = np.zeros(self.observation_space.shape, dtype=self.observation_space.dtype)

    def _measure(
        self, obs: np.ndarray, info: dict[str, Any], rows: np.ndarray
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """The noisy observations (``rows`` measured anew, the others as they were) and the
        info with the measured states of ``rows``."""
        task = self.env.unwrapped.task
        noisy, measured = self._noise.measure(task, rows, self._draws)
        self._obs[rows] = task.observe(noisy)[rows]
        flags = np.zeros(self.num_envs, dtype=np.bool_)
        flags[rows] = True
        measured[~flags] = 0.0
        return self._obs.copy(), {**info, "measured_state": measured, "_measured_state": flags}

    def reset(
        self,
        *,
        seed: int | list[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        rows = reset_rows_of(options, self.num_envs)
        seeds = sub_env_seeds(seed, self.num_envs)
        unseeded = [i for i in rows if seeds[i] is None]
        drawn = self.env.unwrapped.draw_integers(unseeded, _ENTROPY_HIGH)
        for i, value in zip(unseeded, drawn, strict=True):
            seeds[i] = value
        self._draws.start(rows, [seeds[i] for i in rows])
        return self._measure(obs, info, rows)

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        base = self.env.unwrapped
        ended = base.ended
        obs, rewards, terminated, truncated, info = self.env.step(actions)
        if base.autoreset_mode is AutoresetMode.NEXT_STEP:  # the ended rows began anew
            restarted = np.flatnonzero(ended)
            self._draws.start(restarted, base.draw_integers(restarted, _ENTROPY_HIGH))
            rows = np.arange(self.num_envs)
        else:  # disabled: the parked rows did not step
            rows = np.flatnonzero(~ended)
        obs, info = self._measure(obs, info, rows)
        return obs, rewards, terminated, truncated, info


class ActuatorDelay(gym.Wrapper):
    """A transport delay between the command and the actuators.

    Parameters
    ----------
    env : gymnasium.Env
        A shipgym env (single).
    delay : float
        Delay [s] (>= 0), rounded to whole control steps of the env.
    """

    def __init__(self, env: gym.Env, delay: float) -> None:
        super().__init__(env)
        self.steps, self.delay = _delay_steps(delay, env.unwrapped.dt)
        self._queue: deque[np.ndarray] = deque()

    def _holding_action(self) -> np.ndarray:
        """The action that commands every actuator to the setting it has now."""
        return _holding_actions(self.env.unwrapped.task, [0])[0]

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        hold = self._holding_action()
        self._queue = deque(hold.copy() for _ in range(self.steps))
        return obs, info

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        if not self.steps:
            return self.env.step(action)
        a = np.array(action, dtype=np.float32, copy=True)
        if a.shape != self.action_space.shape or not np.all(np.isfinite(a)):
            raise ValueError(
                f"action must be {self.action_space.shape[0]} finite values in [-1, 1], "
                f"got {action!r}"
            )
        self._queue.append(a)
        return self.env.step(self._queue.popleft())


class VectorActuatorDelay(VectorWrapper):
    """:class:`ActuatorDelay` for a batch: one queue of ``steps`` actions per row.

    A row's queue is filled with its holding action at its reset (``reset``, an autoreset,
    or ``reset_mask``), so row ``i`` equals a single :class:`ActuatorDelay` env of
    ``SyncVectorEnv``, bitwise.

    Parameters
    ----------
    env : gymnasium.vector.VectorEnv
        A shipgym vector env (possibly wrapped), in any autoreset mode.
    delay : float
        Delay [s] (>= 0), rounded to whole control steps of the env.

    Notes
    -----
    The actions of rows the env does not step (parked in disabled mode, reset by this step in
    next-step mode) are not checked, as the env ignores them.
    """

    def __init__(self, env: VectorEnv, delay: float) -> None:
        super().__init__(env)
        base = _ship_vector_env(env, "VectorActuatorDelay")
        self.steps, self.delay = _delay_steps(delay, base.task.dt)
        shape = (self.num_envs, self.steps, *self.single_action_space.shape)
        self._queue = np.zeros(shape, dtype=np.float32)
        self._oldest = 0  # slot of every row's oldest queued action

    def _hold(self, rows: np.ndarray) -> None:
        if self.steps and rows.size:
            self._queue[rows] = _holding_actions(self.env.unwrapped.task, rows)[:, None, :]

    def reset(
        self,
        *,
        seed: int | list[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        self._hold(reset_rows_of(options, self.num_envs))
        return obs, info

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self.steps:
            return self.env.step(actions)
        base = self.env.unwrapped
        ended = base.ended
        a = np.array(actions, dtype=np.float32, copy=True)
        if a.shape != self.action_space.shape:
            raise ValueError(
                f"actions must have shape {self.action_space.shape} (finite values in [-1, 1]), "
                f"got {actions!r}"
            )
        bad = np.flatnonzero(~np.isfinite(a).all(axis=1) & ~ended)
        if bad.size:
            raise ValueError(
                f"sub-env {bad[0]}'s action must be {a.shape[1]} finite values in [-1, 1], "
                f"got {a[bad[0]]!r}"
            )
        applied = self._queue[:, self._oldest].copy()
        self._queue[:, self._oldest] = a
        self._oldest = (self._oldest + 1) % self.steps
        result = self.env.step(applied)
        if base.autoreset_mode is AutoresetMode.NEXT_STEP:
            self._hold(np.flatnonzero(ended))
        elif base.autoreset_mode is AutoresetMode.SAME_STEP:
            self._hold(np.flatnonzero(result[2] | result[3]))
        return result


__all__ = [
    "SENSOR_NOISE",
    "ActuatorDelay",
    "SensorNoise",
    "VectorActuatorDelay",
    "VectorSensorNoise",
    "noise_generator",
]

"""Gymnasium wrappers for the robustness conditions: sensor noise and an actuator delay.

Both wrap any single shipgym env and change only what a controller sees or commands, never
the ship, so the same scenario (seed) runs with and without them and metrics stay those of
the true motion.

:class:`SensorNoise`
    White Gaussian errors on the measured heading, yaw rate, speed (surge and sway) and
    position, drawn at every control step. The observation is the one the task forms from the
    *measured* state (:meth:`shipgym.envs.tasks.Task.observe`: the env's own kernel, so a
    heading error shifts the heading-error channel, a position error the cross-track error
    and the target's relative position); ``info["measured_state"]`` carries the measured
    state for controllers that read states, ``info["state"]`` stays the truth.
    :data:`SENSOR_NOISE` gives the default levels, typical of a ship's sensors: heading 0.5
    deg (gyrocompass), yaw rate 0.1 deg/s (rate-of-turn sensor), speed 0.1 m/s (speed log,
    GNSS), position 1 m (DGNSS).
:class:`ActuatorDelay`
    A transport delay of ``delay`` seconds (rounded to whole control steps) between the
    command and the actuator; until the first command arrives the actuators hold the setting
    they start the episode with.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np

from shipgym.envs.tasks import _finite_float

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


def _nonnegative(name: str, value: Any) -> float:
    v = _finite_float(name, value)
    if v < 0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return v


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
    The noise generator is seeded from the reset seed (a fixed offset of it), so an episode's
    noise sequence is reproducible and the same for every controller run on that seed.
    """

    def __init__(self, env: gym.Env, **std: float) -> None:
        super().__init__(env)
        unknown = sorted(set(std) - set(SENSOR_NOISE))
        if unknown:
            raise ValueError(f"unknown noise channel(s) {unknown}; expected {list(SENSOR_NOISE)}")
        levels = {k: _nonnegative(k, std.get(k, v)) for k, v in SENSOR_NOISE.items()}
        names = env.unwrapped.task.model.state_names
        self._index = np.array(
            [names.index(s) for k in levels for s in _CHANNELS[k] if s in names], dtype=np.int64
        )
        self._std = np.array([levels[k] for k in levels for s in _CHANNELS[k] if s in names])
        self.std = levels
        self._rng = np.random.default_rng()

    def _measure(self, obs: np.ndarray, info: dict[str, Any]) -> tuple[np.ndarray, dict]:
        task = self.env.unwrapped.task
        measured = np.array(info["state"], dtype=np.float64)
        measured[self._index] += self._std * self._rng.standard_normal(self._index.size)
        noisy = task.observe(measured[None, :])[0].astype(obs.dtype)
        return noisy, {**info, "measured_state": measured}

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        entropy = seed if seed is not None else int(self.env.unwrapped.np_random.integers(2**62))
        self._rng = np.random.default_rng([entropy, 0x5E4503])
        return self._measure(obs, info)

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        obs, info = self._measure(obs, info)
        return obs, reward, terminated, truncated, info


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
        delay = _nonnegative("delay", delay)
        self.steps = round(delay / env.unwrapped.dt)
        self.delay = self.steps * env.unwrapped.dt
        self._queue: deque[np.ndarray] = deque()

    def _holding_action(self) -> np.ndarray:
        """The action that commands every actuator to the setting it has now."""
        task = self.env.unwrapped.task
        model = task.model
        held = task.u0.copy()
        for j, name in enumerate(model.input_names):
            state = name.removesuffix("_c")
            if state in model.state_names:
                held[j] = task.x[0, model.index(state)]
        action, *_ = np.linalg.lstsq(task.B, held - task.u0, rcond=None)
        return np.clip(action, -1.0, 1.0).astype(np.float32)

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


__all__ = ["SENSOR_NOISE", "ActuatorDelay", "SensorNoise"]

"""Generic single and NumPy-batched vector environments around a :class:`~shipgym.envs.tasks.Task`.

``ShipEnv`` is a :class:`gymnasium.Env` holding a task of one row; ``ShipVectorEnv`` is a
:class:`gymnasium.vector.VectorEnv` holding a task of ``num_envs`` rows with next-step
autoreset (as Gymnasium's ``CartPoleVectorEnv``). Both step through the same task kernel, so
the physics exists once. Sub-env ``i`` of a vector env reset with seed ``s`` draws from
``np_random(s + i)``, the generator of a single env reset with seed ``s + i`` (the convention of
``SyncVectorEnv``), so the two produce identical trajectories under identical actions.

The vector env autoresets on the next step by default. With
``autoreset_mode=AutoresetMode.SAME_STEP`` a finished sub-env is reset inside the step that
ended it: the returned observation is the new episode's first one and the last observation of
the finished episode is in ``info["final_obs"]`` (rows flagged by ``info["_final_obs"]``), the
form that stable-baselines3's ``VecEnv`` needs (:mod:`shipgym.rl.vec_env`).
"""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from shipgym.envs.kernels import REASONS
from shipgym.envs.tasks import Task


def _bad_action(action: Any, expected: int, reason: str) -> ValueError:
    return ValueError(
        f"action must be {expected} finite value(s) in [-1, 1] (out-of-range values are "
        f"clipped), got {action!r}: {reason}"
    )


def _checked_shape(action: Any, shape: tuple[int, ...], act_dim: int) -> Any:
    """``action`` if it has ``shape`` (the fast path), else a converted copy or a ValueError."""
    if getattr(action, "shape", None) == shape:
        return action
    try:
        arr = np.asarray(action, dtype=np.float64)
    except (ValueError, TypeError) as exc:
        raise _bad_action(action, act_dim, str(exc)) from None
    if arr.shape != shape:
        raise _bad_action(action, act_dim, f"expected shape {shape}")
    return arr


class _Spaces:
    """Observation and action spaces shared by the single and the vector env."""

    task_cls: ClassVar[type[Task]]

    @classmethod
    def _single_spaces(cls) -> tuple[spaces.Box, spaces.Box]:
        t = cls.task_cls
        bounds = np.array(t.obs_bounds, dtype=np.float32)
        obs = spaces.Box(bounds[:, 0], bounds[:, 1], dtype=np.float32)
        act = spaces.Box(-1.0, 1.0, shape=(t.act_dim,), dtype=np.float32)
        return obs, act


class ShipEnv(_Spaces, gym.Env[np.ndarray, np.ndarray]):
    """A single ship environment. Subclasses set ``task_cls`` and document the task.

    Once a step has returned ``terminated=True`` the episode is over: a further ``step``
    raises Gymnasium's ``ResetNeeded`` until ``reset`` succeeds (no reward is ever paid past
    the end). Truncation is the ``TimeLimit`` wrapper's business and does not stop the env.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["human", "rgb_array"], "render_fps": 10}
    #: Termination reason of the episode that ended, or None while it runs.
    _ended: str | None = None

    def __init__(self, render_mode: str | None = None, **task_kwargs: Any) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        self.render_mode = render_mode
        self.task = self.task_cls(1, **task_kwargs)
        self.observation_space, self.action_space = self._single_spaces()
        self.metadata = {**self.metadata, "render_fps": round(1.0 / self.task.dt)}
        self._renderer: Any = None
        self._trail: list[tuple[float, float]] = []

    @property
    def dt(self) -> float:
        """Time step [s]."""
        return self.task.dt

    @property
    def state_names(self) -> tuple[str, ...]:
        """Names of the entries of ``info["state"]``."""
        return self.task.model.state_names

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        self.task.reset_rows([0], [self.np_random], options)
        self._ended = None
        self._trail = []
        if self._renderer is not None:
            self._renderer.reset_view()
        if self.render_mode == "human":
            self.render()
        return self.task.obs[0].astype(np.float32), self.task.info(0)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._ended is not None:
            raise gym.error.ResetNeeded(
                f"Cannot call env.step() after the episode terminated (termination_reason "
                f"{self._ended!r}); call env.reset() first"
            )
        task = self.task
        task.a[0] = _checked_shape(action, task.a.shape[1:], task.act_dim)
        if task.step() >= 0:
            raise _bad_action(action, task.act_dim, "it holds NaN or infinity")
        if task.term[0]:
            self._ended = REASONS[task.reason[0]]
        if self.render_mode == "human":
            self.render()
        return (
            task.obs[0].astype(np.float32),
            float(task.rew[0]),
            bool(task.term[0]),
            False,
            task.info(0),
        )

    def _draw_args(self, i: int) -> dict[str, Any]:
        return {}

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode at creation")
            return None
        from shipgym.envs.rendering import TopDownRenderer

        task = self.task
        if self._renderer is None:
            length, beam = self.ship_dimensions
            self._renderer = TopDownRenderer(
                length, beam, self.render_mode, title=type(self).__name__
            )
        x = task.x[0]
        self._trail.append((float(x[0]), float(x[1])))
        steps = int(task.steps[0])
        return self._renderer.draw(
            float(x[0]),
            float(x[1]),
            float(x[task.model.index("psi")]),
            trail=np.asarray(self._trail),
            current_speed=float(task.current[0, 0]),
            current_direction=float(task.current[0, 1]),
            text=f"t = {steps * task.dt:.0f} s",
            **self._draw_args(0),
        )

    @property
    def ship_dimensions(self) -> tuple[float, float]:
        """Length and beam [m] used to draw the ship."""
        raise NotImplementedError

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state


class ShipVectorEnv(_Spaces, VectorEnv[np.ndarray, np.ndarray, np.ndarray]):
    """NumPy-batched vector env with next-step autoreset over the same task kernel."""

    metadata: ClassVar[dict[str, Any]] = {
        "render_modes": ["rgb_array"],
        "render_fps": 10,
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int | None = None,
        render_mode: str | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        **task_kwargs: Any,
    ) -> None:
        modes = (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP)
        try:
            mode = AutoresetMode(autoreset_mode)
        except ValueError:
            mode = None
        if mode not in modes:
            raise ValueError(
                f"autoreset_mode must be one of {[m.value for m in modes]}, got {autoreset_mode!r}"
            )
        self.autoreset_mode = mode
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        self.task = self.task_cls(num_envs, **task_kwargs)
        self.num_envs = int(num_envs)
        steps = self.task.max_episode_steps if max_episode_steps is None else max_episode_steps
        if not isinstance(steps, int | np.integer) or steps < 1:
            raise ValueError(
                f"max_episode_steps must be an integer >= 1, got {max_episode_steps!r}"
            )
        self.max_episode_steps = int(steps)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        self.render_mode = render_mode
        self.single_observation_space, self.single_action_space = self._single_spaces()
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._rngs = [seeding.np_random(None)[0] for _ in range(self.num_envs)]
        self._prev_done = np.zeros(self.num_envs, dtype=np.bool_)
        self._single: ShipEnv | None = None
        self._needs_reset = True

    def _check_open(self, call: str, needs_reset: bool = True) -> None:
        """The errors of the single env (Gymnasium's order enforcing) for a call before the
        first ``reset``, and a clear one for a call after ``close``."""
        if self.closed:
            raise gym.error.ClosedEnvironmentError(
                f"Cannot call env.{call}() on a closed vector env; make a new one"
            )
        if needs_reset and self._needs_reset:
            raise gym.error.ResetNeeded(f"Cannot call env.{call}() before calling env.reset()")

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        self._check_open("reset", needs_reset=False)
        if seed is not None:
            seeds = (
                list(seed)
                if isinstance(seed, list | tuple)
                else [seed + i for i in range(self.num_envs)]
            )
            if len(seeds) != self.num_envs:
                raise ValueError(f"seed list must have {self.num_envs} entries, got {len(seeds)}")
            self._rngs = [seeding.np_random(s)[0] for s in seeds]
        self.task.reset_rows(range(self.num_envs), self._rngs, options)
        self._prev_done[:] = False
        self._needs_reset = False
        return self.task.obs.astype(np.float32), {}

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        self._check_open("step")
        task = self.task
        task.a[:] = _checked_shape(actions, task.a.shape, task.act_dim)
        bad = task.step()
        if bad >= 0:
            raise _bad_action(
                actions[bad], task.act_dim, f"sub-env {bad}'s action holds NaN or infinity"
            )
        terminated = task.term.copy()
        truncated = task.steps >= self.max_episode_steps
        rewards = task.rew.copy()
        info: dict[str, Any] = {"reason": task.reason.copy()}
        if self.autoreset_mode is AutoresetMode.SAME_STEP:
            done = terminated | truncated
            if done.any():
                rows = np.flatnonzero(done)
                info["final_obs"] = task.obs.astype(np.float32)
                info["_final_obs"] = done
                task.reset_rows(rows, [self._rngs[i] for i in rows])
            return task.obs.astype(np.float32), rewards, terminated, truncated, info
        if self._prev_done.any():
            rows = np.flatnonzero(self._prev_done)
            task.reset_rows(rows, [self._rngs[i] for i in rows])
            rewards[self._prev_done] = 0.0
            terminated[self._prev_done] = False
            truncated[self._prev_done] = False
        self._prev_done = terminated | truncated
        return task.obs.astype(np.float32), rewards, terminated, truncated, info

    def render(self) -> np.ndarray | None:
        """Top-down view of sub-env 0 (``rgb_array`` only)."""
        if self.render_mode is None:
            return None
        self._check_open("render")
        if self._single is None:
            self._single = self.single_env_cls(render_mode="rgb_array")
            self._single.task = self.task  # share the arrays; draw row 0
        return self._single.render()

    single_env_cls: ClassVar[type[ShipEnv]]

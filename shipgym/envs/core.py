"""Generic single and NumPy-batched vector environments around a :class:`~shipgym.envs.tasks.Task`.

``ShipEnv`` is a :class:`gymnasium.Env` holding a task of one row; ``ShipVectorEnv`` is a
:class:`gymnasium.vector.VectorEnv` holding a task of ``num_envs`` rows with its own autoreset
(as Gymnasium's ``CartPoleVectorEnv``). Both step through the same task kernel, so the physics
exists once. Sub-env ``i`` of a vector env reset with seed ``s`` draws from
``np_random(s + i)``, the generator of a single env reset with seed ``s + i`` (the convention of
``SyncVectorEnv``), so the two produce identical trajectories under identical actions; the
vector env holds these streams as arrays (:class:`~shipgym.envs.streams.RowStreams`), so an
autoreset of any number of sub-envs draws for all of them in one compiled pass.

The vector env behaves as Gymnasium's ``SyncVectorEnv`` of single envs, ``info`` included
(the same keys, ``_key`` flags, dtypes and values; :meth:`Task.batch_info` builds it for all
sub-envs with NumPy), in Gymnasium's three autoreset modes: next-step (the default), same-step
(``autoreset_mode=AutoresetMode.SAME_STEP``: the finished episode's last observation and info
in ``info["final_obs"]`` and ``info["final_info"]``, the form that stable-baselines3's
``VecEnv`` needs, :mod:`shipgym.rl.vec_env`) and disabled (``AutoresetMode.DISABLED``, the
manual mode: the caller resets finished sub-envs with ``reset(options={"reset_mask": mask})``).
``reset_mask`` resets only the flagged sub-envs in every mode, as in ``SyncVectorEnv``.
``keep_options=True`` makes autoresets use the options of the last ``reset(options=...)``,
which ``SyncVectorEnv`` forgets.

Where ``SyncVectorEnv`` refuses to step a finished sub-env in disabled mode, this env *parks*
it: until a reset, a step leaves it as it ended (its action is ignored, even a NaN; the same
observation, reward 0, both flags False, its ``info`` entries unflagged), and only the other
sub-envs go through the kernel. A batch of episodes of different lengths can so be stepped to
the end of the longest without starting new episodes (an evaluation).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from shipgym.envs.kernels import REASONS, available_threads
from shipgym.envs.streams import RowStreams
from shipgym.envs.tasks import Task

#: The autoreset modes of :class:`ShipVectorEnv`.
AUTORESET_MODES = (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP, AutoresetMode.DISABLED)


def sub_env_seeds(seed: int | Sequence[int | None] | None, num_envs: int) -> list[int | None]:
    """The seed of each sub-env for a vector ``reset(seed=seed)``, as ``SyncVectorEnv`` reads
    it: ``None`` for none of them, ``[s, s + 1, ...]`` for an int ``s``, a list as it is.

    Raises
    ------
    ValueError
        If a list does not have ``num_envs`` entries.
    """
    if seed is None:
        return [None] * num_envs
    if isinstance(seed, list | tuple):
        if len(seed) != num_envs:
            raise ValueError(f"seed list must have {num_envs} entries, got {len(seed)}")
        return list(seed)
    return [seed + i for i in range(num_envs)]


def reset_rows_of(options: Mapping[str, Any] | None, num_envs: int) -> np.ndarray:
    """The sub-envs a vector ``reset(options=options)`` resets: those of
    ``options["reset_mask"]`` (checked as the native env checks it), else all of them."""
    if options is None or not isinstance(options, Mapping) or "reset_mask" not in options:
        return np.arange(num_envs)
    mask = options["reset_mask"]
    if (
        not isinstance(mask, np.ndarray)
        or mask.dtype != np.bool_
        or mask.shape != (num_envs,)
        or not mask.any()
    ):
        raise ValueError(
            f"options['reset_mask'] must be a numpy bool array of shape ({num_envs},) with at "
            f"least one True, got {mask!r}"
        )
    return np.flatnonzero(mask)


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
        """``task_kwargs``: the task's (each env's docstring), and ``wind`` and ``sea_state``,
        the seaway of every episode (:mod:`shipgym.models.seaway_options`; none by default)."""
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        self.render_mode = render_mode
        wind, sea_state = task_kwargs.pop("wind", None), task_kwargs.pop("sea_state", None)
        self.task = self.task_cls(1, **task_kwargs)
        self.task.set_seaway(wind, sea_state)
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
        task.a[0] = _checked_shape(action, (task.act_dim,), task.act_dim)
        if task.step() >= 0:
            raise _bad_action(action, task.act_dim, "it holds NaN or infinity")
        terminated = task.term.item(0)  # (Python scalars read with item: the fastest way)
        if terminated:
            self._ended = REASONS[task.reason.item(0)]
        if self.render_mode == "human":
            self.render()
        return task.obs[0].astype(np.float32), task.rew.item(0), terminated, False, task.info(0)

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
    """NumPy-batched vector env over the same task kernel as the single env.

    Equivalent to Gymnasium's ``SyncVectorEnv`` of the single env (``gymnasium.make_vec(id,
    num_envs, vectorization_mode="sync")``) in observations, rewards, flags and ``info``, in
    every autoreset mode, but one kernel call steps every sub-env.

    Parameters
    ----------
    num_envs : int
        Number of sub-envs (>= 1).
    max_episode_steps : int, optional
        Steps after which a sub-env is truncated; default the registered limit of the task.
    render_mode : {None, "rgb_array"}
        ``"rgb_array"`` draws sub-env 0.
    autoreset_mode : AutoresetMode or str
        ``AutoresetMode.NEXT_STEP`` (default): a sub-env that ended is reset by the next
        ``step``, which returns its new episode's first observation with reward 0 and both
        flags False (its action is ignored). ``AutoresetMode.SAME_STEP``: it is reset inside
        the step that ended it, which returns the new episode's first observation; the
        finished episode's last observation and ``info`` are in ``info["final_obs"]`` and
        ``info["final_info"]`` (rows flagged by ``info["_final_obs"]`` and
        ``info["_final_info"]``), the form stable-baselines3 needs (:mod:`shipgym.rl.vec_env`).
        ``AutoresetMode.DISABLED`` (also ``"Disabled"``): no autoreset; the caller resets the
        sub-envs that ended with ``reset(options={"reset_mask": mask})``. A sub-env that ended
        and was not reset is *parked*: ``step`` does not advance it (its action is ignored,
        even a NaN), returns its last observation again with reward 0 and both flags False,
        and leaves its ``info`` entries unflagged (zero, None for strings), so a batch of
        episodes of different lengths runs to the end of the longest without new episodes
        (``SyncVectorEnv`` refuses to step such a sub-env). Only the sub-envs still running
        go through the kernel, with bitwise the results of stepping all.
    num_threads : int or None
        Threads that step the batch. 1 (the default) steps it on the calling thread, which is
        the fastest choice whenever the cores are shared: with other busy processes (an RL
        learner beside the env, a test suite, a sweep) a thread of a threaded step that the
        operating system deschedules holds up the whole step, and the threaded step becomes
        slower than the serial one (``shipgym bench --busy N`` measures it).
        ``None`` uses one thread per CPU the process may run on, for batches of at least 64
        sub-envs on cores the env has to itself: the batch is split into that many contiguous
        parts, each stepped by the same compiled kernel on its own thread (it releases the
        GIL). Results are bitwise the same for every value.
    keep_options : bool
        What an autoreset does with the options of the last ``reset(options=...)``. False (the
        default, Gymnasium's ``SyncVectorEnv`` behaviour): an autoreset draws a fresh scenario
        as ``env.reset()`` does, so the options shape the first episode of each sub-env only.
        True: every autoreset uses them too (a fixed current, setpoints, waypoints or target
        for the whole run), until a ``reset`` with other options or none.
    step_info : bool
        True (the default): ``step`` and ``reset`` return the ``info`` of the Notes below.
        False: they return only what an autoreset hands over, for training loops that never
        read ``info``: in same-step mode ``final_obs`` and ``_final_obs`` when a sub-env
        finished, else an empty dict. The full ``info`` is about ten new arrays a step: half
        the time of a step of 8 sub-envs, a fifth of one of 1024 (stable-baselines3's adapter,
        :mod:`shipgym.rl.vec_env`, steps without it). Observations, rewards and flags are the
        same either way.
    **task_kwargs
        Keyword arguments of the task (as for the single env), and ``wind`` and ``sea_state``:
        the seaway of every episode (:mod:`shipgym.models.seaway_options`; none by default; a
        reset's options override them).

    Notes
    -----
    ``info`` follows Gymnasium's vector convention: each key of the single env's ``info``
    (``state``, ``current_speed``, ``current_direction``, ``termination_reason`` and the task
    metrics) holds an array with one entry per sub-env (``termination_reason`` an object array
    of strings) and ``info["_key"]`` a boolean array flagging the sub-envs that have it (all of
    them, except in ``final_info``). ``reset`` returns the same keys. The entries describe
    each sub-env after the step: on a next-step autoreset, the new episode (as
    ``env.reset()``'s info would); in same-step mode the finished episode's are in
    ``final_info``, whose entries of sub-envs that did not finish are zero (None for strings).
    The arrays are built with NumPy for all sub-envs at once and are new at every call.

    ``reset(options={"reset_mask": mask, ...})`` (every mode) resets only the sub-envs flagged
    by ``mask`` (a numpy bool array of shape ``(num_envs,)``, at least one True), sub-env ``i``
    with ``seed[i]`` of a seed list or ``seed + i`` of an int seed, and the other options;
    the other sub-envs keep their episode and observation, and the ``info`` flags the reset
    sub-envs only (the others' entries zero, None for strings), as ``SyncVectorEnv`` does.
    """

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
        keep_options: bool = False,
        num_threads: int | None = 1,
        step_info: bool = True,
        **task_kwargs: Any,
    ) -> None:
        max_threads = available_threads()
        if num_threads is None:
            num_threads = max_threads
        if (
            isinstance(num_threads, bool)
            or not isinstance(num_threads, int | np.integer)
            or not 1 <= num_threads <= max_threads
        ):
            raise ValueError(
                f"num_threads must be an integer in [1, {max_threads}] (the CPUs this process "
                f"may run on) or None for all of them, got {num_threads!r}"
            )
        try:
            mode = AutoresetMode(autoreset_mode)
        except ValueError:
            mode = None
        if mode not in AUTORESET_MODES:
            raise ValueError(
                f"autoreset_mode must be one of {[m.value for m in AUTORESET_MODES]}, "
                f"got {autoreset_mode!r}"
            )
        for name, flag in (("keep_options", keep_options), ("step_info", step_info)):
            if not isinstance(flag, bool | np.bool_):
                raise ValueError(f"{name} must be True or False, got {flag!r}")
        self.step_info = bool(step_info)
        self.autoreset_mode = mode
        self._parks = mode is AutoresetMode.DISABLED  # (a flag read at every step)
        self.keep_options = bool(keep_options)
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        wind, sea_state = task_kwargs.pop("wind", None), task_kwargs.pop("sea_state", None)
        self.task = self.task_cls(num_envs, **task_kwargs)
        self.task.set_seaway(wind, sea_state)
        self.task.num_threads = self.num_threads = int(num_threads)
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
        #: the random stream of each sub-env (Gymnasium's ``np_random``, held as arrays)
        self._streams = RowStreams(self.num_envs)
        #: sub-envs that ended at their last step and have not been reset since
        self._prev_done = np.zeros(self.num_envs, dtype=np.bool_)
        #: Options of the autoresets: those of the last reset with ``keep_options``, else None.
        self._autoreset_options: dict[str, Any] | None = None
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

    def _info(self) -> dict[str, Any]:
        """The vector ``info`` of every sub-env: each key of the single env's info and its
        ``_key`` flags (all set); empty without ``step_info``."""
        if not self.step_info:
            return {}
        info = self.task.batch_info()
        flags = np.ones((len(info), self.num_envs), dtype=np.bool_)  # one allocation
        for key, flag in zip(tuple(info), flags, strict=True):
            info[f"_{key}"] = flag
        return info

    def _flagged_info(self, flags: np.ndarray) -> dict[str, Any]:
        """The vector ``info`` of the sub-envs flagged by ``flags``, as ``SyncVectorEnv`` builds
        it from theirs alone: the other sub-envs' entries zero (None for objects), every
        ``_key`` a copy of ``flags``."""
        info = self.task.batch_info()
        others = ~flags
        for key in tuple(info):
            value = info[key]
            value[others] = None if value.dtype == object else 0
            info[f"_{key}"] = flags.copy()
        return info

    def _final(self, obs: np.ndarray, done: np.ndarray) -> dict[str, Any]:
        """``final_obs`` and ``final_info`` of the sub-envs flagged by ``done`` (before their
        reset), as ``SyncVectorEnv`` builds them: object array of observations, nested info
        whose entries of the other sub-envs are zero (None for objects); ``final_obs`` alone
        without ``step_info``."""
        rows = np.flatnonzero(done)
        final_obs = np.full(self.num_envs, None, dtype=object)
        for i in rows:
            final_obs[i] = obs[i]
        if not self.step_info:
            return {"final_obs": final_obs, "_final_obs": done.copy()}
        final_info = self._flagged_info(done)
        return {
            "final_obs": final_obs,
            "_final_obs": done.copy(),
            "final_info": final_info,
            "_final_info": done.copy(),
        }

    def reset(
        self,
        *,
        seed: int | list[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset every sub-env, or those of ``options["reset_mask"]``; the other options as for
        the single env, for every sub-env reset.

        Sub-env ``i`` is seeded with ``seed + i`` (an int seed) or ``seed[i]`` (a list; a None
        entry, like ``seed=None``, continues its random stream). Whether the autoresets that
        follow use the options too is ``keep_options``.

        Raises
        ------
        ValueError
            For a bad ``reset_mask`` (a numpy bool array of shape ``(num_envs,)`` with at least
            one True is expected), a seed list of another length or a bad option; no episode
            changes then (after a bad option, the random streams of the sub-envs to reset are
            seeded and drawn from, as the single env's).
        gymnasium.error.ResetNeeded
            For a ``reset_mask`` that leaves out sub-envs before the first full reset.
        """
        self._check_open("reset", needs_reset=False)
        rows = reset_rows_of(options, self.num_envs)
        if isinstance(options, Mapping) and "reset_mask" in options:
            if self._needs_reset and rows.size < self.num_envs:
                raise gym.error.ResetNeeded(
                    "Cannot reset some sub-envs with reset_mask before every sub-env has been "
                    "reset; call env.reset() first"
                )
            options = {k: v for k, v in options.items() if k != "reset_mask"}
        seeds = sub_env_seeds(seed, self.num_envs)
        seeded = [(i, seeding.np_random(seeds[i])[0]) for i in rows if seeds[i] is not None]
        for i, generator in seeded:  # (made first: a bad seed changes nothing)
            self._streams.set_generator(i, generator)
        self.task.reset_rows(rows, self._streams, options)
        self._autoreset_options = dict(options) if self.keep_options and options else None
        self._prev_done[rows] = False
        self._needs_reset = False
        if rows.size == self.num_envs:
            return self.task.obs.astype(np.float32), self._info()
        if not self.step_info:
            return self.task.obs.astype(np.float32), {}
        flags = np.zeros(self.num_envs, dtype=np.bool_)
        flags[rows] = True
        return self.task.obs.astype(np.float32), self._flagged_info(flags)

    @property
    def ended(self) -> np.ndarray:
        """Which sub-envs ended (terminated or truncated) at their last step and have not been
        reset since (a copy): the next ``step`` resets them in next-step mode and leaves them
        parked in disabled mode; none in same-step mode. Wrappers read it before a step."""
        return self._prev_done.copy()

    def draw_integers(self, rows: Sequence[int] | np.ndarray, high: int) -> list[int]:
        """One integer in ``[0, high)`` from the random stream of each sub-env of ``rows``,
        exactly as ``env.np_random.integers(high)`` draws it in the single env that sub-env
        equals, and advancing the stream as that draw does: how a wrapper seeds its own
        generator of a sub-env reset without a seed, as its single-env twin does."""
        values = []
        for i in rows:
            generator = self._streams.generator(int(i))
            values.append(int(generator.integers(high)))
            self._streams.set_generator(int(i), generator)
        return values

    def _autoreset(self, rows: np.ndarray) -> None:
        self.task.reset_rows(rows, self._streams, self._autoreset_options)

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        self._check_open("step")
        task = self.task
        task.a[:] = _checked_shape(actions, task.a.shape, task.act_dim)
        if self._parks and self._prev_done.any():
            return self._step_live(actions)
        bad = task.step()
        if bad >= 0:
            raise _bad_action(
                actions[bad], task.act_dim, f"sub-env {bad}'s action holds NaN or infinity"
            )
        terminated = task.term.copy()
        truncated = task.steps >= self.max_episode_steps
        rewards = task.rew.copy()
        if self.autoreset_mode is AutoresetMode.SAME_STEP:
            done = terminated | truncated
            if not done.any():
                return task.obs.astype(np.float32), rewards, terminated, truncated, self._info()
            final = self._final(task.obs.astype(np.float32), done)
            self._autoreset(np.flatnonzero(done))
            info = self._info()
            info.update(final)
            return task.obs.astype(np.float32), rewards, terminated, truncated, info
        if self._prev_done.any():  # (none in disabled mode: parked sub-envs step elsewhere)
            self._autoreset(np.flatnonzero(self._prev_done))
            rewards[self._prev_done] = 0.0
            terminated[self._prev_done] = False
            truncated[self._prev_done] = False
        self._prev_done = terminated | truncated
        return task.obs.astype(np.float32), rewards, terminated, truncated, self._info()

    def _step_live(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """A disabled-mode step with parked sub-envs (``_prev_done``): only the others go
        through the kernel; the parked ones' actions are zeroed so that only live actions are
        checked."""
        task = self.task
        parked = self._prev_done
        live = ~parked
        task.a[parked] = 0.0
        bad = task.step(np.flatnonzero(live))
        if bad >= 0:
            raise _bad_action(
                actions[bad], task.act_dim, f"sub-env {bad}'s action holds NaN or infinity"
            )
        terminated = task.term & live
        truncated = (task.steps >= self.max_episode_steps) & live
        rewards = np.where(live, task.rew, 0.0)
        self._prev_done = parked | terminated | truncated
        info = self._flagged_info(live) if self.step_info else {}
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

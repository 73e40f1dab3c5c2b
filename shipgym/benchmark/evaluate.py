"""Run a policy on an environment over seeded episodes and compute the task metrics.

Episode ``k`` is reset with seed ``seed + k``, so every policy sees the same initial states,
setpoints, paths, targets and current draws. The episodes of an evaluation run as one batched
rollout: the package's vector env in Gymnasium's manual mode steps all of them at once (an
episode that ends stays ended on its row), the classic controllers act on arrays of ships, and
the signals the metrics need are recorded in preallocated arrays. An episode's numbers depend
on its seed only, not on how many episodes run beside it: the vector env's rows are independent,
each classic controller's row is its own ship, and a batched policy (a neural network) is always
called on blocks of :data:`POLICY_BLOCK` rows in which the episode of seed ``s`` takes row
``s % POLICY_BLOCK`` (matrix kernels round a row differently by its place in the batch). So a
campaign split into batches of seeds (on a Ray cluster, :mod:`shipgym.benchmark.runner`) and
merged with :func:`merge_results` gives the numbers of one run, and they are those of the single
env stepped episode after episode. An error raised in an episode becomes an
:class:`EpisodeError` naming the env, controller, condition and seed. Metrics (means
over episodes):

* heading envs: ``heading_rms_deg`` (RMS heading error over the whole episode, of the
  heading as measured: at sea with the wave-frequency motion), ``lf_heading_rms_deg`` (the
  same of the ship's low-frequency heading, ``info["state"]``: what the autopilot is to hold
  at sea; in calm water the two are the same),
  ``overshoot_deg`` (largest excursion past a new setpoint, in the direction of the change,
  over the setpoint segments of an episode), ``actuator_rms`` (RMS of the normalised command);
* speed env: ``speed_rms_m_s``;
* path following: ``cross_track_rms_m``, ``cross_track_final_m`` (mean |e| over the last 20 %
  of the episode) and ``completed`` (fraction of episodes that reach the last waypoint);
* target tracking: ``distance_error_rms_m`` and ``time_to_intercept_s`` (first time the distance
  is within 10 % of the set distance; the episode length if never).

Engineering metrics beside them (what a control engineer signs off, not what the reward asks):

* ``settling_time_s``: per setpoint segment, the time until the error stays inside the band
  (:data:`HEADING_BAND` 2 deg, :data:`SPEED_BAND` 0.1 m/s; the segment length if never),
  averaged over the segments; ``steady_state_deg`` / ``steady_state_m_s``: RMS error over the
  settled samples;
* ``rudder_travel_deg_min`` and ``rudder_reversals_min``: the rudder's (the pods' azimuth's)
  total travel and number of direction reversals (moves above :data:`REVERSAL_DEADBAND`) per
  minute, the wear of the steering gear;
* ``energy_mj``: propulsion energy of the Gunnerus, the integral of thrust times surge speed
  [MJ];
* ``cross_track_straight_m``: RMS cross-track error on the straight parts of the legs
  (:data:`STRAIGHT_AFTER_S` after each switch), apart from the turns.

Blown-up episodes. An episode whose state stops being finite ends with the termination reason
:data:`BLOW_UP` (the env stops it with reward 0, so its return would look better than any real
run). Its return and metrics are undefined (NaN): the motion after a blow-up is not physical.
A cell with a blown-up episode has no mean return and no metric means at all (NaN, shown as
``blew up k/n`` in every table and figure) rather than means over the episodes that survived,
which would reward a controller for blowing up on its hard cases. Every result carries the
count (``blown_up``) and each episode's termination reason and length in steps.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import math
import sys
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.envs.registration import load_env_creator
from gymnasium.vector import AutoresetMode, VectorEnv

import shipgym  # noqa: F401  (registers the environments)
from shipgym.benchmark.stats import bootstrap_ci
from shipgym.envs import ENV_IDS, env_task
from shipgym.envs.kernels import BLOW_UP as _BLOW_UP_CODE
from shipgym.envs.kernels import REASONS
from shipgym.models import ssa

#: Termination reason of an episode whose state stopped being finite.
BLOW_UP = REASONS[_BLOW_UP_CODE]

_WEAR = ("rudder_travel_deg_min", "rudder_reversals_min")
_TASK_METRICS: dict[str, tuple[str, ...]] = {
    "NomotoHeading": ("heading_rms_deg", "lf_heading_rms_deg", "overshoot_deg", "settling_time_s",
                      "steady_state_deg", "actuator_rms", *_WEAR),
    "RVGHeading": ("heading_rms_deg", "lf_heading_rms_deg", "overshoot_deg", "settling_time_s",
                   "steady_state_deg", "actuator_rms", *_WEAR, "energy_mj"),
    "RVGSpeed": ("speed_rms_m_s", "settling_time_s", "steady_state_m_s", "energy_mj"),
    "RVGPathFollowing": ("cross_track_rms_m", "cross_track_final_m", "cross_track_straight_m",
                         "completed", *_WEAR, "energy_mj"),
    "RVGTargetTracking": ("distance_error_rms_m", "time_to_intercept_s", *_WEAR, "energy_mj"),
}  # fmt: skip
#: The engineering metrics of each env, beside the return.
METRICS: dict[str, tuple[str, ...]] = {e: _TASK_METRICS[env_task(e)] for e in ENV_IDS}
#: The heading-keeping envs.
HEADING_ENVS = tuple(e for e in ENV_IDS if env_task(e) in ("NomotoHeading", "RVGHeading"))

#: Metrics where a larger value is better (for every other metric smaller is better).
HIGHER_IS_BETTER = frozenset({"completed"})

HEADING_BAND = math.radians(2.0)
"""Settling band of the heading envs [rad]."""
SPEED_BAND = 0.1
"""Settling band of the speed env [m/s]."""
STRAIGHT_AFTER_S = 25.0
"""Path following: a leg counts as straight this long after the switch to it [s] (the
Gunnerus legs take 50-70 s; 25 s is about 4 ship lengths of travel)."""
REVERSAL_DEADBAND = math.radians(0.05)
"""Rudder moves smaller than this [rad] are not counted as reversals."""
POLICY_BLOCK = 64
"""Rows of every call of a batched policy's ``act_batch`` (padded with zero observations)."""


class EpisodeError(RuntimeError):
    """An episode of an evaluation raised an error; the message names the env, controller,
    condition and seed, the original error is the ``__cause__``.

    Attributes
    ----------
    env, controller, condition : str
        The evaluation the episode belongs to.
    seeds : tuple of int
        The seed of the failing episode (several when a batched policy call failed for a
        block of episodes and no single one could be singled out).
    """

    def __init__(
        self,
        message: str,
        env: str = "",
        controller: str = "",
        condition: str = "",
        seeds: tuple[int, ...] = (),
    ) -> None:
        super().__init__(message)
        self.env = env
        self.controller = controller
        self.condition = condition
        self.seeds = seeds


@dataclass
class EpisodeLog:
    """Signals of one episode, one row per step (after the step).

    Attributes
    ----------
    seed : int
        The episode's reset seed.
    time : ndarray, shape (L,)
        Time after each step [s].
    state : ndarray, shape (L, nx)
        The true state after each step (``info["state"]``).
    action : ndarray, shape (L, na)
        The normalised action of each step, clipped to [-1, 1] (float32, as the env takes it).
    reward : ndarray, shape (L,)
        Reward of each step.
    signals : dict of str to ndarray
        Every entry of the step ``info`` but the states (the task metrics, the current; at
        sea the wind, sea state and wave motion) over the episode, shape (L,) for a number,
        (L, k) for an entry of k numbers.
    termination_reason : str
        How the episode ended (``info["termination_reason"]`` of its last step).
    reset_info : dict
        The ``info`` of the episode's reset (as the single env gives it).
    extras : dict
        ``waypoints`` (path following) and ``target`` (the target's position at every step,
        target tracking).
    """

    seed: int
    time: np.ndarray
    state: np.ndarray
    action: np.ndarray
    reward: np.ndarray
    signals: dict[str, np.ndarray]
    termination_reason: str
    reset_info: dict[str, Any] = field(default_factory=dict)
    extras: dict[str, Any] = field(default_factory=dict)

    def signal(self, key: str) -> np.ndarray:
        """An ``info`` entry over the episode as an array."""
        try:
            return self.signals[key]
        except KeyError:
            raise KeyError(
                f"no signal {key!r} in this episode's log; it has {sorted(self.signals)}"
            ) from None

    @property
    def steps(self) -> int:
        """Steps of the episode."""
        return int(self.reward.size)

    @property
    def episode_return(self) -> float:
        """Sum of rewards."""
        return float(np.sum(self.reward))


@dataclass
class EvaluationResult:
    """The summary object of ``shipgym evaluate`` and the logs behind it."""

    env: str
    controller: str
    episodes: int
    seed: int
    returns: list[float]
    per_episode: list[dict[str, float]]
    logs: list[EpisodeLog] = field(repr=False)
    options: dict[str, Any] = field(default_factory=dict)
    condition: str = "nominal"
    #: How each episode ended (``info["termination_reason"]`` of its last step).
    terminations: list[str] = field(default_factory=list)
    #: Steps of each episode.
    lengths: list[int] = field(default_factory=list)

    @property
    def blown_up(self) -> int:
        """Episodes that ended in a numerical blow-up (:data:`BLOW_UP`)."""
        return self.terminations.count(BLOW_UP)

    @property
    def mean_return(self) -> float:
        """Mean return; NaN if any episode blew up (see the module docstring)."""
        return math.nan if self.blown_up else float(np.mean(self.returns))

    def values(self, key: str) -> np.ndarray:
        """Per-episode values of a metric (NaN where undefined: never settled)."""
        return np.array([m[key] for m in self.per_episode], dtype=float)

    def _over_defined(self, fn: Callable[[np.ndarray], float]) -> dict[str, float]:
        out = {}
        for k in METRICS[self.env]:
            v = self.values(k)
            v = v[np.isfinite(v)]
            out[k] = float(fn(v)) if v.size and not self.blown_up else math.nan
        return out

    @property
    def metrics(self) -> dict[str, float]:
        """Means over the episodes where each metric is defined."""
        return self._over_defined(np.mean)

    @property
    def metrics_std(self) -> dict[str, float]:
        """Standard deviations over the episodes where each metric is defined."""
        return self._over_defined(np.std)

    @property
    def metrics_defined(self) -> dict[str, int]:
        """Episodes in which each metric is defined (a steady-state error needs a settled
        episode)."""
        return {k: int(np.isfinite(self.values(k)).sum()) for k in METRICS[self.env]}

    @functools.cached_property
    def metrics_ci95(self) -> dict[str, list[float] | None]:
        """Bootstrap 95 % interval of each metric's mean (``None`` below two values).

        Computed on first use and kept (a result does not change after its evaluation): the
        JSON, the CSV and the figures read the same intervals.
        """
        out: dict[str, list[float] | None] = {}
        for k in METRICS[self.env]:
            v = self.values(k)
            defined = np.isfinite(v).sum() >= 2 and not self.blown_up
            out[k] = list(bootstrap_ci(v)) if defined else None
        return out

    @functools.cached_property
    def return_ci95(self) -> list[float] | None:
        """Bootstrap 95 % interval of the mean return (``None`` for one episode or a blow-up);
        computed on first use and kept, as :attr:`metrics_ci95`."""
        valid = self.episodes > 1 and not self.blown_up
        return list(bootstrap_ci(self.returns)) if valid else None

    def to_dict(self) -> dict[str, Any]:
        """The JSON object: env, controller, condition, episodes, mean/std return and its
        bootstrap 95 % interval, each metric's mean, std, interval and number of episodes
        that define it, the per-episode returns and metrics (for paired comparisons), each
        episode's termination reason and length, and the number of blown-up episodes (every
        aggregate is NaN if there is one)."""
        return {
            "env": self.env,
            "controller": self.controller,
            "condition": self.condition,
            "episodes": self.episodes,
            "seed": self.seed,
            "mean_return": self.mean_return,
            "std_return": float(np.std(self.returns)) if not self.blown_up else math.nan,
            "return_ci95": self.return_ci95,
            "blown_up": self.blown_up,
            "metrics": self.metrics,
            "metrics_std": self.metrics_std,
            "metrics_ci95": self.metrics_ci95,
            "metrics_defined": self.metrics_defined,
            "returns": [float(r) for r in self.returns],
            "per_episode": {k: [float(x) for x in self.values(k)] for k in METRICS[self.env]},
            "termination": list(self.terminations),
            "length": list(self.lengths),
            "options": self.options,
        }


def _overshoot_deg(log: EpisodeLog) -> float:
    """Largest overshoot past a new heading setpoint, in the direction of the change [deg]."""
    setpoint = log.signal("heading_setpoint")
    error = log.signal("heading_error")  # ssa(psi_d - psi)
    start = log.reset_info.get("heading_setpoint", setpoint[0])
    psi0 = start - log.reset_info.get("heading_error", 0.0)
    previous_heading = psi0
    worst = 0.0
    k0 = 0
    for k in range(1, len(setpoint) + 1):
        if k == len(setpoint) or setpoint[k] != setpoint[k0]:
            sp = setpoint[k0]
            direction = math.copysign(1.0, _ssa(sp - previous_heading))
            seg = -error[k0:k] * direction  # > 0 when the ship is past the setpoint
            worst = max(worst, float(np.max(seg, initial=0.0)))
            previous_heading = sp
            k0 = k
    return math.degrees(worst)


def _ssa(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _settling(error: np.ndarray, setpoint: np.ndarray, band: float, dt: float) -> tuple[
    float, float
]:  # fmt: skip
    """Mean settling time [s] over the setpoint segments and the RMS of the settled error."""
    times, settled = [], []
    edges = [0, *(np.flatnonzero(np.diff(setpoint) != 0) + 1).tolist(), len(setpoint)]
    for k0, k1 in itertools.pairwise(edges):
        seg = np.abs(error[k0:k1])
        outside = np.flatnonzero(seg > band)
        first_in = 0 if outside.size == 0 else int(outside[-1]) + 1
        times.append(first_in * dt)
        settled.append(error[k0 + first_in : k1])
    rest = np.concatenate(settled) if settled else np.zeros(0)
    ss = float(np.sqrt(np.mean(rest**2))) if rest.size else math.nan
    return float(np.mean(times)), ss


def _wear(angle: np.ndarray, dt: float) -> dict[str, float]:
    """Rudder travel [deg/min] and reversals per minute of a rudder/azimuth angle [rad]."""
    minutes = max(angle.size * dt / 60.0, 1e-9)
    step = np.diff(angle)
    moves = step[np.abs(step) > REVERSAL_DEADBAND]
    reversals = int(np.count_nonzero(np.diff(np.sign(moves)) != 0))
    return {
        "rudder_travel_deg_min": math.degrees(float(np.sum(np.abs(step)))) / minutes,
        "rudder_reversals_min": reversals / minutes,
    }


def _rvg_energy_mj(states: np.ndarray, dt: float) -> float:
    """Propulsion energy [MJ]: thrust of both pods times surge speed, integrated."""
    power = (states[:, 6] + states[:, 7]) * states[:, 3]
    return float(np.sum(np.maximum(power, 0.0)) * dt / 1e6)


def episode_metrics(env_id: str, log: EpisodeLog, dt: float) -> dict[str, float]:
    """The metrics of one episode of ``env_id`` (see the module docstring)."""
    states = np.asarray(log.state, dtype=float)
    rvg = env_id != "shipgym/NomotoHeading-v0"
    rudder = states[:, 8] if rvg else states[:, 5]  # pod azimuth or rudder angle
    extra: dict[str, float] = {}
    if rvg:
        extra["energy_mj"] = _rvg_energy_mj(states, dt)
    if env_id in HEADING_ENVS:
        e = log.signal("heading_error")
        setpoint = log.signal("heading_setpoint")
        lf = ssa(setpoint - states[:, 2])  # the LF heading (psi is state 2 of every model)
        a = np.asarray(log.action, dtype=float)
        settle, ss = _settling(e, setpoint, HEADING_BAND, dt)
        out = {
            "heading_rms_deg": math.degrees(float(np.sqrt(np.mean(e**2)))),
            "lf_heading_rms_deg": math.degrees(float(np.sqrt(np.mean(lf**2)))),
            "overshoot_deg": _overshoot_deg(log),
            "settling_time_s": settle,
            "steady_state_deg": math.degrees(ss),
            "actuator_rms": float(np.sqrt(np.mean(a**2))),
            **_wear(rudder, dt),
        }
    elif env_task(env_id) == "RVGSpeed":
        e = log.signal("speed_error")
        settle, ss = _settling(e, log.signal("speed_setpoint"), SPEED_BAND, dt)
        out = {"speed_rms_m_s": float(np.sqrt(np.mean(e**2))), "settling_time_s": settle,
               "steady_state_m_s": ss}  # fmt: skip
    elif env_task(env_id) == "RVGPathFollowing":
        e = log.signal("cross_track_error")
        tail = e[int(0.8 * len(e)) :]
        segment = log.signal("segment")
        since = np.zeros(segment.size)
        for k in range(1, segment.size):
            since[k] = 0.0 if segment[k] != segment[k - 1] else since[k - 1] + dt
        straight = e[since >= STRAIGHT_AFTER_S]
        out = {
            "cross_track_rms_m": float(np.sqrt(np.mean(e**2))),
            "cross_track_final_m": float(np.mean(np.abs(tail))),
            "cross_track_straight_m": (
                float(np.sqrt(np.mean(straight**2))) if straight.size else math.nan
            ),
            "completed": float(bool(log.signal("completed")[-1])),
            **_wear(rudder, dt),
        }
    elif env_task(env_id) == "RVGTargetTracking":
        err = log.signal("distance_error")
        dist = log.signal("distance")
        within = np.flatnonzero(np.abs(err) <= 0.1 * (dist - err))
        t_int = (within[0] + 1) * dt if within.size else len(err) * dt
        out = {
            "distance_error_rms_m": float(np.sqrt(np.mean(err**2))),
            "time_to_intercept_s": float(t_int),
            **_wear(rudder, dt),
        }
    else:
        raise ValueError(f"unknown env {env_id!r}; expected one of {ENV_IDS}")
    return {**out, **extra}


#: Most episodes stepped as one vector env; more run as consecutive batches of this size (the
#: recorded signals of a batch grow with its size: about 10 MB per 100 Gunnerus episodes).
VECTOR_BATCH = 256


def vector_env(
    env_id: str,
    num_envs: int,
    env_kwargs: dict[str, Any] | None = None,
    wrappers: Sequence[Callable[[VectorEnv], VectorEnv]] = (),
) -> VectorEnv:
    """The package's vector env of ``env_id`` with ``num_envs`` sub-envs in Gymnasium's manual
    mode (``AutoresetMode.DISABLED``: an episode that ends stays on its row, nothing starts
    a new one), with the registered keyword arguments of ``env_id`` updated by
    ``env_kwargs`` and the vector ``wrappers`` applied in order."""
    spec = gym.spec(env_id)
    creator = spec.vector_entry_point
    if isinstance(creator, str):
        creator = load_env_creator(creator)
    kwargs = {**spec.kwargs, **(env_kwargs or {})}
    env: VectorEnv = creator(num_envs=num_envs, autoreset_mode=AutoresetMode.DISABLED, **kwargs)
    for wrap in wrappers:
        env = wrap(env)
    return env


def _row_info(info: dict[str, Any], k: int) -> dict[str, Any]:
    """Row ``k`` of a vector ``info`` as the single env's ``info`` (Python scalars, arrays
    copied)."""
    out: dict[str, Any] = {}
    for key, value in info.items():
        if key.startswith("_"):
            continue
        v = value[k]
        out[key] = v.copy() if isinstance(v, np.ndarray) else getattr(v, "item", lambda v=v: v)()
    return out


def _blocks(seeds: Sequence[int]) -> list[tuple[np.ndarray, np.ndarray]]:
    """The :data:`POLICY_BLOCK`-row blocks of the episodes ``seeds``: for each block, the
    indices into ``seeds`` of its episodes and their rows in it (``s % POLICY_BLOCK``)."""
    seeds = np.asarray(seeds, dtype=np.int64)
    block_of, row_of = np.divmod(seeds, POLICY_BLOCK)
    layout = []
    for b in np.unique(block_of):
        members = np.flatnonzero(block_of == b)
        layout.append((members, row_of[members]))
    return layout


def _act_in_blocks(
    policy: Any,
    obs: np.ndarray,
    seeds: Sequence[int],
    layout: list[tuple[np.ndarray, np.ndarray]] | None = None,
) -> np.ndarray:
    """``policy.act_batch`` on the rows ``obs`` of the episodes ``seeds``, called on blocks
    of :data:`POLICY_BLOCK` rows with seed ``s`` in row ``s % POLICY_BLOCK`` (zeros elsewhere);
    ``layout`` is :func:`_blocks` of ``seeds`` if known."""
    out: np.ndarray | None = None
    for members, rows in layout if layout is not None else _blocks(seeds):
        block = np.zeros((POLICY_BLOCK, *obs.shape[1:]), dtype=obs.dtype)
        block[rows] = obs[members]
        actions = np.asarray(policy.act_batch(block), dtype=np.float32)
        if out is None:
            out = np.empty((len(seeds), *actions.shape[1:]), dtype=np.float32)
        out[members] = actions[rows]
    assert out is not None  # at least one seed
    return out


def _failing_seeds(policy: Any, obs: np.ndarray, seeds: Sequence[int]) -> tuple[int, ...]:
    """The seeds whose rows alone make ``act_batch`` raise (all of ``seeds`` if none does)."""
    for j, s in enumerate(seeds):
        try:
            _act_in_blocks(policy, obs[j : j + 1], [s])
        except Exception:
            return (int(s),)
    return tuple(int(s) for s in seeds)


class _BlockFailed(Exception):
    """A batched policy call failed; ``seeds`` are the episodes it is pinned on, the policy's
    error is the ``__cause__``."""

    def __init__(self, seeds: tuple[int, ...]) -> None:
        super().__init__(seeds)
        self.seeds = seeds


class _Actor:
    """Calls a policy on a batch of episodes in the way it supports (see :func:`evaluate`)."""

    def __init__(self, policy: Any, env: VectorEnv, seeds: Sequence[int]) -> None:
        self.policy = policy
        self.seeds = list(seeds)
        self._seeds = np.asarray(self.seeds, dtype=np.int64)
        self.vector = hasattr(policy, "reset_vector")
        self.memoryless = not self.vector and hasattr(policy, "act_batch")
        self.env = env.unwrapped
        self.act_dim = int(env.single_action_space.shape[0])
        #: the live rows and their blocks, made anew when an episode ends
        self._live: np.ndarray | None = None
        self._layout: list[tuple[np.ndarray, np.ndarray]] = []
        if not (self.vector or self.memoryless) and len(self.seeds) != 1:
            raise ValueError("a policy with act(obs, info) only runs one episode at a time")

    def single_view(self) -> Any:
        """A single env sharing the vector env's task (row 0): what ``reset(env, ...)`` of a
        one-episode policy reads (``task``, ``dt``, the spaces)."""
        view = self.env.single_env_cls()
        view.task = self.env.task
        return view

    def reset(self, obs: np.ndarray, info: dict[str, Any]) -> None:
        if self.vector:
            self.policy.reset_vector(self.env, obs, info)
        else:
            self.policy.reset(self.single_view(), obs[0], _row_info(info, 0))

    def act(self, obs: np.ndarray, info: dict[str, Any], alive: np.ndarray) -> np.ndarray:
        """Actions of every row (rows not ``alive`` are ignored by the env)."""
        if self.vector:
            return np.asarray(self.policy.act_vector(obs, info), dtype=np.float32)
        if self.memoryless:
            if self._live is None or self._live.size != np.count_nonzero(alive):
                self._live = np.flatnonzero(alive)  # (episodes only end: a count tells a change)
                self._layout = _blocks(self._seeds[self._live])
            live = self._live
            seeds = self._seeds[live]
            try:
                acted = _act_in_blocks(self.policy, obs[live], seeds, self._layout)
            except Exception as exc:
                raise _BlockFailed(_failing_seeds(self.policy, obs[live], seeds)) from exc
            actions = np.zeros((len(self.seeds), self.act_dim), dtype=np.float32)
            actions[live] = acted
            return actions
        action = self.policy.act(obs[0], _row_info(info, 0))
        return np.asarray(action, dtype=np.float32).reshape(1, self.act_dim)


def _rollout(
    env: VectorEnv, actor: _Actor, seeds: Sequence[int], options: dict[str, Any] | None
) -> list[EpisodeLog]:
    """Run the episodes ``seeds`` (one per row of ``env``) to their ends; their logs."""
    base = env.unwrapped
    task = base.task
    n, steps = len(seeds), int(base.max_episode_steps)
    obs, info = env.reset(seed=list(seeds), options=None if options is None else dict(options))
    reset_infos = [_row_info(info, k) for k in range(n)]
    x0 = np.array(info["state"])
    actor.reset(obs, info)
    skip = {"state", "measured_state", "termination_reason"}
    keys = [k for k, v in info.items() if not k.startswith("_") and k not in skip]
    # (n, steps, ...) so that an episode's samples are contiguous, as one episode's lists were
    states = np.empty((n, steps, x0.shape[1]))
    actions = np.empty((n, steps, actor.act_dim), dtype=np.float32)
    rewards = np.empty((n, steps))
    signals = {  # a scalar per row, or a row per row (the seaway's wind, sea state, wave motion)
        k: np.empty((n, steps, *np.shape(info[k])[1:]), dtype=np.asarray(info[k]).dtype)
        for k in keys
    }
    targets = np.empty((n, steps, 2)) if hasattr(task, "target") else None
    alive = np.ones(n, dtype=np.bool_)
    lengths = np.zeros(n, dtype=np.int64)
    reasons = [""] * n
    for t in range(steps):
        a = actor.act(obs, info, alive)
        obs, reward, terminated, truncated, info = env.step(a)
        states[:, t] = info["state"]
        actions[:, t] = np.clip(a, -1.0, 1.0)
        rewards[:, t] = reward
        for key in keys:
            signals[key][:, t] = info[key]
        if targets is not None:
            targets[:, t] = task.target
        done = (terminated | truncated) & alive
        if not done.any():
            continue
        for k in np.flatnonzero(done):
            lengths[k] = t + 1
            reasons[k] = str(info["termination_reason"][k])
        alive &= ~done
        if not alive.any():
            break
        for key in ("state", "measured_state"):  # the ended rows feed the policy a finite state
            if key in info:
                info[key][~alive] = x0[~alive]
    logs = []
    for k in range(n):
        length = int(lengths[k])
        extras: dict[str, Any] = {}
        if hasattr(task, "waypoints"):
            extras["waypoints"] = task.waypoints(k)
        if targets is not None:
            extras["target"] = targets[k, :length].copy()
        logs.append(
            EpisodeLog(
                seed=int(seeds[k]),
                time=np.arange(length) * base.task.dt + base.task.dt,
                # copies: a log kept alone (the benchmark keeps one per cell) does not hold the
                # whole batch's arrays
                state=states[k, :length].copy(),
                action=actions[k, :length].copy(),
                reward=rewards[k, :length].copy(),
                signals={key: signals[key][k, :length].copy() for key in keys},
                termination_reason=reasons[k],
                reset_info=reset_infos[k],
                extras=extras,
            )
        )
    return logs


def evaluate(
    env_id: str,
    policy: Any,
    controller: str,
    episodes: int = 10,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
    reset_options: dict[str, Any] | None = None,
    progress: Callable[[str], None] | None = None,
    condition: str = "nominal",
    wrappers: Sequence[Callable[[VectorEnv], VectorEnv]] = (),
) -> EvaluationResult:
    """Run ``policy`` for ``episodes`` episodes with seeds ``seed``, ``seed + 1``, ...

    The episodes run as one batched rollout: the package's vector env of ``env_id`` in
    Gymnasium's manual mode (:func:`vector_env`) steps all of them at once (at most
    :data:`VECTOR_BATCH` per batch), episode ``k`` on a row reset with seed ``seed + k`` (the
    single env reset with that seed: the same initial state, setpoints, path, target and
    current). An episode that ends stays ended on its row while the others go on. The signals
    the metrics need are recorded in preallocated arrays, and the metrics are computed from
    them.

    Parameters
    ----------
    env_id : str
        One of :data:`shipgym.envs.ENV_IDS`.
    policy : object
        One of three kinds, tried in this order:

        * a policy for a batch of ships: ``reset_vector(env, obs, info)`` (``env`` the
          unwrapped vector env, ``obs`` and ``info`` of every row) and ``act_vector(obs,
          info) -> actions`` (one row per episode), as the classic controllers of
          :mod:`shipgym.benchmark.policies`; a row's actions must depend on that row only;
        * a memoryless policy with ``act_batch(obs) -> actions`` (a neural network): called on
          blocks of :data:`POLICY_BLOCK` rows (see the module docstring);
        * any policy with ``reset(env, obs, info)`` and ``act(obs, info) -> action`` (the
          single env's ``obs`` and ``info``): its episodes run one after another, each as a
          vector env of one.
    controller : str
        Name recorded in the result.
    episodes, seed : int
        Number of episodes and the first seed.
    env_kwargs : dict, optional
        Keyword arguments of the env (e.g. ``max_current_speed``, the ship).
    reset_options : dict, optional
        Options passed to every ``reset``.
    progress : callable, optional
        Called with a short line per episode (default: print to stderr).
    condition : str
        Name of the scenario set, recorded in the result (the benchmark's ``nominal``,
        ``stress``, ...).
    wrappers : sequence of callables
        Vector wrappers applied to the vector env in order (``env = w(env)``), e.g. the
        robustness conditions' :class:`~shipgym.envs.wrappers.VectorSensorNoise` and
        :class:`~shipgym.envs.wrappers.VectorActuatorDelay`. Metrics are of the true motion.

    Returns
    -------
    EvaluationResult

    Raises
    ------
    EpisodeError
        If an episode raises (in the env, a wrapper, the policy or the metrics): names the
        env, controller, condition and the episode's seed (the seeds of the batch when the
        error cannot be pinned on one).
    """
    if env_id not in ENV_IDS:
        raise ValueError(f"unknown env {env_id!r}; expected one of {ENV_IDS}")
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    if progress is None:

        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)

    def failed(seeds: Sequence[int], exc: Exception) -> EpisodeError:
        which = (
            f"episode with seed {seeds[0]}"
            if len(seeds) == 1
            else f"one of the episodes with seeds {_seed_list(seeds)}"
        )
        return EpisodeError(
            f"{env_id} {controller} ({condition}): {which} failed: {type(exc).__name__}: {exc}",
            env=env_id,
            controller=controller,
            condition=condition,
            seeds=tuple(seeds),
        )

    batched = hasattr(policy, "reset_vector") or hasattr(policy, "act_batch")
    size = min(episodes, VECTOR_BATCH) if batched else 1
    all_seeds = [seed + k for k in range(episodes)]
    logs: list[EpisodeLog] = []
    env: VectorEnv | None = None
    dt = math.nan
    with _one_torch_thread():
        try:
            for start in range(0, episodes, size):
                seeds = all_seeds[start : start + size]
                try:
                    if env is None or env.num_envs != len(seeds):
                        if env is not None:
                            env.close()
                        env = vector_env(env_id, len(seeds), env_kwargs, wrappers)
                        dt = float(env.unwrapped.task.dt)
                    logs += _rollout(env, _Actor(policy, env, seeds), seeds, reset_options)
                except Exception as exc:
                    seed_k, exc_k = _failing_episode(env_id, env_kwargs, wrappers, policy, seeds,
                                                     reset_options, exc)  # fmt: skip
                    raise failed(seed_k, exc_k) from exc_k
        finally:
            if env is not None:
                env.close()
    per_episode: list[dict[str, float]] = []
    for k, log in enumerate(logs):
        head = f"{env_id} {controller} episode {k + 1}/{episodes} (seed {log.seed}): "
        if log.termination_reason == BLOW_UP:
            metrics = dict.fromkeys(METRICS[env_id], math.nan)
            line = head + f"numerical blow-up at step {log.steps}: no return, no metrics"
        else:
            try:
                metrics = episode_metrics(env_id, log, dt)
            except Exception as exc:
                raise failed([log.seed], exc) from exc
            line = (
                head
                + f"return {log.episode_return:.1f}, "
                + ", ".join(f"{key} {value:.3g}" for key, value in metrics.items())
            )
        per_episode.append(metrics)
        progress(line)
    return EvaluationResult(
        env=env_id,
        controller=controller,
        episodes=episodes,
        seed=seed,
        returns=[
            math.nan if log.termination_reason == BLOW_UP else log.episode_return for log in logs
        ],
        per_episode=per_episode,
        logs=logs,
        options=dict(reset_options or {}),
        condition=condition,
        terminations=[log.termination_reason for log in logs],
        lengths=[log.steps for log in logs],
    )


def _failing_episode(
    env_id: str,
    env_kwargs: dict[str, Any] | None,
    wrappers: Sequence[Callable[[VectorEnv], VectorEnv]],
    policy: Any,
    seeds: Sequence[int],
    options: dict[str, Any] | None,
    exc: Exception,
) -> tuple[Sequence[int], Exception]:
    """The seed whose episode alone raises, and its error, after a batch of ``seeds`` raised
    ``exc``: each episode is run again alone until one raises (``exc`` and every seed if
    none does; the seeds ``act_batch`` named if a batched policy raised)."""
    if isinstance(exc, _BlockFailed):
        cause = exc.__cause__
        return exc.seeds, cause if isinstance(cause, Exception) else exc
    if len(seeds) > 1:
        for s in seeds:
            single = vector_env(env_id, 1, env_kwargs, wrappers)
            try:
                _rollout(single, _Actor(policy, single, [s]), [s], options)
            except Exception as alone:
                return [s], alone
            finally:
                single.close()
    return seeds, exc


@contextlib.contextmanager
def _one_torch_thread() -> Iterator[None]:
    """Run a neural policy on one torch thread, the caller's setting restored after.

    Blocks of :data:`POLICY_BLOCK` rows gain nothing from more threads (measured: the same
    time on one as on two), and on cores that other processes share a descheduled thread of a
    threaded matrix product stalls every call (a PPO evaluation took 8.6 s instead of 0.3 s
    beside two busy processes). Nothing happens if torch is not loaded.
    """
    torch = sys.modules.get("torch")
    if torch is None:
        yield
        return
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


def _seed_list(seeds: Sequence[int]) -> str:
    """``"3, 4, 5"``, or ``"3..99"`` for a run of consecutive seeds."""
    seeds = list(seeds)
    if len(seeds) > 3 and seeds == list(range(seeds[0], seeds[0] + len(seeds))):
        return f"{seeds[0]}..{seeds[-1]}"
    return ", ".join(map(str, seeds))


def merge_results(parts: Sequence[EvaluationResult]) -> EvaluationResult:
    """One evaluation from evaluations of consecutive seed ranges of the same env,
    controller, condition and options (the batches of a campaign split into tasks).

    The episodes, per-episode values and logs are concatenated in seed order; the result
    equals that of one :func:`evaluate` over all the seeds.

    Raises
    ------
    ValueError
        If ``parts`` is empty, mixes evaluations, or its seed ranges leave a gap or overlap.
    """
    if not parts:
        raise ValueError("no evaluations to merge")
    parts = sorted(parts, key=lambda r: r.seed)
    first = parts[0]
    key = (first.env, first.controller, first.condition, first.options)
    expected = first.seed
    for part in parts:
        if (part.env, part.controller, part.condition, part.options) != key:
            raise ValueError(
                f"cannot merge {part.env} {part.controller} ({part.condition}) into "
                f"{first.env} {first.controller} ({first.condition}): different evaluations"
            )
        if part.seed != expected:
            raise ValueError(
                f"seed ranges do not join: expected a part from seed {expected}, got one from "
                f"seed {part.seed}"
            )
        expected = part.seed + part.episodes
    return EvaluationResult(
        env=first.env,
        controller=first.controller,
        episodes=sum(p.episodes for p in parts),
        seed=first.seed,
        returns=[r for p in parts for r in p.returns],
        per_episode=[m for p in parts for m in p.per_episode],
        logs=[log for p in parts for log in p.logs],
        options=dict(first.options),
        condition=first.condition,
        terminations=[t for p in parts for t in p.terminations],
        lengths=[n for p in parts for n in p.lengths],
    )

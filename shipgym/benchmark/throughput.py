"""Training throughput: PPO's environment steps per second on each env against CartPole.

The env must never be what slows training down. :func:`ppo_throughput` times
stable-baselines3 PPO ``learn`` with the shipped agents' PPO settings
(:data:`shipgym.rl.train.DEFAULTS`: the same sub-env count, rollout length, batch, epochs,
network, ``VecMonitor`` + ``VecNormalize``) on each shipgym env (through
:class:`~shipgym.rl.vec_env.ShipgymVecEnv`) and on ``CartPole-v1`` (through SB3's standard
``make_vec_env``), in one process, and reports the ratio to CartPole. The runs are interleaved
and repeated and the best of each is kept, so a moment of load elsewhere does not decide the
ratio. The target is a ratio of at least :data:`TARGET_RATIO`.

A ratio of two speeds means something only if nothing else ran on the cores meanwhile. Each
timed run measures the CPU time other processes used during it (:class:`LoadMeter`: the
machine's busy time from ``/proc/stat`` less this process's own, ``os.times``; elsewhere the
1-minute load average less this process's own use), in cores. When the runs a ratio compares
had more than :data:`BUSY_SHARE` of the machine's cores used by others, the verdict is
"machine busy: not comparable" (:func:`verdict`) instead of met or MISSED.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

from shipgym.envs import CURRENT_ENV_IDS

CARTPOLE = "CartPole-v1"
#: PPO steps/s on a shipgym env relative to CartPole-v1 that counts as "not the bottleneck".
TARGET_RATIO = 0.9
#: Share of the machine's cores that other processes may use during the timed runs before the
#: runs are not comparable (0.2 cores of two).
BUSY_SHARE = 0.1
BUSY = "machine busy: not comparable"
_STAT = "/proc/stat"


def _busy_cpu_s() -> float | None:
    """CPU seconds all processes of the machine have been busy since boot (None: unknown).

    The first line of ``/proc/stat``: user, nice, system, idle, iowait, irq, softirq, steal
    (then guest time, already counted in user), in clock ticks; busy is all but idle and
    iowait.
    """
    try:
        with open(_STAT, encoding="ascii") as f:
            fields = [int(v) for v in f.readline().split()[1:9]]
    except (OSError, ValueError):
        return None
    return (sum(fields) - fields[3] - fields[4]) / os.sysconf("SC_CLK_TCK")


def _own_cpu_s() -> float:
    """CPU seconds this process (all its threads) and its finished children have used."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


class LoadMeter:
    """Cores used by other processes while the ``with`` block runs (a timed run).

    After the block, :attr:`load` holds ``other_cores``, the mean cores used by other processes
    (None: unknown on this system), and ``load_avg_1min``, the 1-minute load average at the end
    (None: unknown).
    """

    load: dict[str, float | None]

    def __enter__(self) -> LoadMeter:
        self._wall = time.perf_counter()
        self._own = _own_cpu_s()
        self._busy = _busy_cpu_s()
        return self

    def __exit__(self, *exc: object) -> None:
        wall = time.perf_counter() - self._wall
        own = (_own_cpu_s() - self._own) / wall
        busy = _busy_cpu_s()
        try:
            load: float | None = os.getloadavg()[0]
        except OSError:  # no load average (Windows)
            load = None
        if busy is not None and self._busy is not None:
            others: float | None = (busy - self._busy) / wall - own
        else:
            others = None if load is None else load - own
        self.load = {
            "other_cores": None if others is None else max(0.0, others),
            "load_avg_1min": load,
        }


def machine_busy(other_cores: float | None, cpus: int) -> bool:
    """Whether other processes used more than :data:`BUSY_SHARE` of ``cpus`` cores (False when
    unknown)."""
    if cpus < 1:
        raise ValueError(f"cpus must be >= 1, got {cpus!r}")
    return other_cores is not None and other_cores > BUSY_SHARE * cpus


def verdict(ratio: float, target: float, other_cores: float | None, cpus: int) -> str:
    """The verdict on a throughput ``ratio`` against ``target``: "met", "MISSED", or
    :data:`BUSY` when other processes used ``other_cores`` of the ``cpus`` cores during the
    runs compared (:func:`machine_busy`)."""
    if machine_busy(other_cores, cpus):
        return BUSY
    return "met" if ratio >= target else "MISSED"


def _make_venv(env_id: str, num_envs: int, seed: int) -> Any:
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from shipgym.rl.vec_env import ShipgymVecEnv

    if env_id == CARTPOLE:
        inner = make_vec_env(CARTPOLE, n_envs=num_envs, seed=seed)  # DummyVecEnv + Monitor
    else:
        inner = VecMonitor(ShipgymVecEnv(env_id, num_envs))
        inner.seed(seed)
    return VecNormalize(inner, norm_obs=True, norm_reward=True)


def ppo_steps_per_second(
    env_id: str, timesteps: int, seed: int = 0, meter: LoadMeter | None = None
) -> float:
    """Environment steps per second of PPO ``learn`` on ``env_id`` (after one warm-up rollout);
    ``meter`` (:class:`LoadMeter`) measures the load during the timed part."""
    from stable_baselines3 import PPO

    from shipgym.rl.train import DEFAULTS, console_logger

    settings = DEFAULTS["ppo"]
    params = dict(settings["hyperparameters"])
    if env_id == CARTPOLE:  # a discrete action space has no log-std
        params["policy_kwargs"] = {
            k: v for k, v in params["policy_kwargs"].items() if k != "log_std_init"
        }
    venv = _make_venv(env_id, settings["num_envs"], seed)
    model = PPO("MlpPolicy", venv, seed=seed, device="cpu", verbose=0, **params)
    model.set_logger(console_logger(0))
    rollout = params["n_steps"] * settings["num_envs"]
    model.learn(rollout)  # warm-up: kernels, torch, first update
    with meter or contextlib.nullcontext():
        start = time.perf_counter()
        model.learn(timesteps, reset_num_timesteps=False)
        elapsed = time.perf_counter() - start
    venv.close()
    return (model.num_timesteps - rollout) / elapsed


def ppo_throughput(
    env_ids: Sequence[str] = CURRENT_ENV_IDS,
    timesteps: int = 16_384,
    repeats: int = 2,
    progress: Callable[[str], None] | None = None,
) -> list[dict[str, Any]]:
    """PPO steps/s on each env and on CartPole, best of ``repeats`` interleaved rounds, with the
    load other processes put on the machine during each timed run.

    Returns
    -------
    list of dict
        One entry per env (CartPole first): ``env``, ``steps_per_s``, ``runs`` (every run),
        ``other_cores`` and ``load_avg_1min`` (per run, :attr:`LoadMeter.load`), ``cpus``,
        ``ratio`` (to CartPole's best), ``target``, ``machine_busy`` (others used more than
        :data:`BUSY_SHARE` of the cores during the env's best run or CartPole's), ``verdict``
        (:func:`verdict`; "" for CartPole) and ``met`` (None for CartPole and when the machine
        was busy).
    """
    if not isinstance(timesteps, int) or timesteps < 1:
        raise ValueError(f"timesteps must be an integer >= 1, got {timesteps!r}")
    if not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"repeats must be an integer >= 1, got {repeats!r}")
    if progress is None:

        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)

    cpus = os.cpu_count() or 1
    ids = [CARTPOLE, *env_ids]
    runs: dict[str, list[float]] = {env_id: [] for env_id in ids}
    loads: dict[str, list[dict[str, float | None]]] = {env_id: [] for env_id in ids}
    meter = LoadMeter()
    for rep in range(repeats):
        for env_id in ids:
            rate = ppo_steps_per_second(env_id, timesteps, meter=meter)
            load = meter.load
            runs[env_id].append(rate)
            loads[env_id].append(load)
            others = load["other_cores"]
            shared = "" if others is None else f" (other processes: {others:.2f} of {cpus} cores)"
            progress(f"PPO throughput {rep + 1}/{repeats}: {env_id} {rate:.0f} steps/s{shared}")

    def best(env_id: str) -> tuple[float, float | None]:
        k = max(range(repeats), key=runs[env_id].__getitem__)
        return runs[env_id][k], loads[env_id][k]["other_cores"]

    reference, reference_others = best(CARTPOLE)
    out = []
    for env_id in ids:
        rate, others = best(env_id)
        ratio = rate / reference
        known = [o for o in (others, reference_others) if o is not None]
        worst = max(known) if known else None
        busy = machine_busy(worst, cpus)
        out.append(
            {
                "env": env_id,
                "steps_per_s": rate,
                "runs": runs[env_id],
                "other_cores": [load["other_cores"] for load in loads[env_id]],
                "load_avg_1min": [load["load_avg_1min"] for load in loads[env_id]],
                "cpus": cpus,
                "ratio": ratio,
                "target": None if env_id == CARTPOLE else TARGET_RATIO,
                "machine_busy": busy,
                "verdict": "" if env_id == CARTPOLE else verdict(ratio, TARGET_RATIO, worst, cpus),
                "met": None if env_id == CARTPOLE or busy else bool(ratio >= TARGET_RATIO),
            }
        )
    return out


def throughput_table(rows: list[dict[str, Any]]) -> str:
    """Plain-text table of :func:`ppo_throughput`'s rows, with the machine's load."""
    lines = ["PPO training throughput (env steps/s, best of the runs; same PPO settings)"]
    for r in rows:
        target = "" if r["target"] is None else f">= {r['target']:g}"
        lines.append(
            f"  {r['env']:32s} {r['steps_per_s']:9.0f}  ratio {r['ratio']:.2f}  {target:7s} "
            f"{r['verdict']}".rstrip()
        )
    others = [o for r in rows for o in r["other_cores"] if o is not None]
    if others:
        lines.append(
            f"  other processes used {min(others):.2f}-{max(others):.2f} of the {rows[0]['cpus']} "
            f"cores during the timed runs (not comparable above {BUSY_SHARE * rows[0]['cpus']:.2g})"
        )
    return "\n".join(lines)

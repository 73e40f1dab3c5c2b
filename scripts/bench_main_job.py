"""How fast the main job runs: the default benchmark and single evaluations, beside CartPole.

``python scripts/bench_main_job.py [--busy N] [--baseline DIR] [--json FILE] [--plot FILE]``

Measured in one process, one after the other, so the figures share the machine state:

* **CartPoleVectorEnv**: sub-env steps per second of Gymnasium's own vector CartPole with as
  many sub-envs as a benchmark cell has episodes (the default 100), random actions;
* **benchmark**: the default ``shipgym benchmark`` run (every cell, 100 episodes each, the
  default process pool, no figures), its wall time and its env steps per second of wall time
  (the steps of every episode of every cell over the whole run's time), and the ratio of that
  to CartPole's sub-env steps per second;
* **evaluate**: each current env with each controller over 100 episodes in the nominal
  condition (what ``shipgym evaluate --episodes 100`` runs after its start-up: imports and
  loading the agent), seconds each; the table prints the classic controller's and the
  slowest controller's;
* **baseline** (``--baseline DIR``, a checkout of an earlier version): the same evaluations
  run by that checkout in a child process, so the speed-up is a ratio measured in one run.

``--busy N`` repeats everything while ``N`` helper processes keep cores busy
(:class:`shipgym.bench.BusyCores`), as other work on a shared machine does, and prints the
busy/idle ratio of each figure. The kernel cache must be warm (run ``shipgym benchmark
--episodes 1`` once before).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.bench import BusyCores
from shipgym.benchmark.policies import make_policy
from shipgym.envs import CURRENT_ENV_IDS

EPISODES = 100
SEED = 1_000_000

_EVALUATE_CHILD = """
import json, sys, time
from shipgym.benchmark import evaluate, make_policy
out = {}
for env_id in sys.argv[2:]:
    t0 = time.perf_counter()
    r = evaluate(env_id, make_policy("classic", env_id), "classic", int(sys.argv[1]), 1000000,
                 progress=lambda line: None)
    out[env_id] = {"seconds": time.perf_counter() - t0, "steps": int(sum(r.lengths))}
print(json.dumps(out))
"""


def cartpole_sps(num_envs: int, seconds: float = 3.0) -> float:
    """Sub-env steps per second of ``CartPoleVectorEnv(num_envs)`` under random actions."""
    from gymnasium.envs.classic_control.cartpole import CartPoleVectorEnv

    env = CartPoleVectorEnv(num_envs=num_envs)
    env.action_space.seed(0)
    env.reset(seed=0)
    actions = [env.action_space.sample() for _ in range(64)]
    for a in actions:
        env.step(a)
    steps, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        for a in actions:
            env.step(a)
        steps += len(actions)
    elapsed = time.perf_counter() - t0
    env.close()
    return steps * num_envs / elapsed


def benchmark_run() -> dict[str, Any]:
    """The default benchmark (no figures): wall time and env steps."""
    from shipgym.benchmark.runner import run_benchmark

    t0 = time.perf_counter()
    result = run_benchmark(progress=lambda line: None)
    seconds = time.perf_counter() - t0
    steps = sum(sum(r.lengths) for r in result.results)
    return {"seconds": seconds, "steps": steps, "cells": len(result.results),
            "steps_per_s": steps / seconds}  # fmt: skip


def evaluations(episodes: int) -> dict[str, dict[str, Any]]:
    """Seconds of ``episodes`` episodes of each current env with each controller: the classic
    controller's (``seconds``, ``steps``) and every controller's (``by_controller``)."""
    from shipgym.benchmark import evaluate
    from shipgym.benchmark.runner import CONTROLLERS

    out: dict[str, dict[str, Any]] = {}
    for env_id in CURRENT_ENV_IDS:
        times = {}
        for name in CONTROLLERS:
            policy = make_policy(name, env_id)
            t0 = time.perf_counter()
            r = evaluate(env_id, policy, name, episodes, SEED, progress=lambda line: None)
            times[name] = time.perf_counter() - t0
            if name == "classic":
                steps = int(sum(r.lengths))
        out[env_id] = {"seconds": times["classic"], "steps": steps, "by_controller": times}
    return out


def baseline(directory: Path, episodes: int) -> dict[str, dict[str, float]]:
    """:func:`evaluations` run by the checkout in ``directory`` (a child process)."""
    env = {**os.environ, "PYTHONPATH": str(directory)}
    done = subprocess.run(
        [sys.executable, "-c", _EVALUATE_CHILD, str(episodes), *CURRENT_ENV_IDS],
        env=env, capture_output=True, text=True, check=True, cwd=directory,
    )  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure(args: argparse.Namespace) -> dict[str, Any]:
    """One round of every measurement."""
    say = print
    out: dict[str, Any] = {}
    out["cartpole_sps"] = cartpole_sps(EPISODES)
    say(f"  CartPoleVectorEnv({EPISODES}): {out['cartpole_sps'] / 1e6:.2f} M sub-env steps/s")
    out["evaluate"] = evaluations(EPISODES)
    for env_id, v in out["evaluate"].items():
        slowest = max(v["by_controller"], key=v["by_controller"].get)
        say(
            f"  evaluate {env_id}, {EPISODES} episodes: classic {v['seconds']:.2f} s, slowest "
            f"{slowest} {v['by_controller'][slowest]:.2f} s"
        )
    if args.baseline is not None:
        out["baseline"] = baseline(args.baseline, args.baseline_episodes)
        for env_id, v in out["baseline"].items():
            now = out["evaluate"][env_id]
            ratio = (now["steps"] / now["seconds"]) / (v["steps"] / v["seconds"])
            v["speedup"] = ratio
            say(f"  baseline {env_id}: {v['steps'] / v['seconds']:.0f} steps/s; now {ratio:.1f}x")
    if not args.no_benchmark:
        out["benchmark"] = b = benchmark_run()
        b["cartpole_ratio"] = b["steps_per_s"] / out["cartpole_sps"]
        say(
            f"  benchmark: {b['cells']} cells, {b['steps'] / 1e6:.2f} M env steps in "
            f"{b['seconds']:.1f} s = {b['steps_per_s']:.0f} steps/s, "
            f"{b['cartpole_ratio']:.4f} x CartPoleVectorEnv"
        )
    return out


def plot(report: dict[str, Any], path: Path) -> None:
    """Bars: seconds of each evaluation and of the benchmark, idle and busy."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rounds = [k for k in ("idle", "busy") if k in report]
    labels = [e.split("/")[1] for e in CURRENT_ENV_IDS]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [3, 1]})
    width = 0.8 / (len(rounds) + ("baseline" in report["idle"]))
    x = np.arange(len(labels))
    for j, name in enumerate(rounds):
        secs = [max(report[name]["evaluate"][e]["by_controller"].values()) for e in CURRENT_ENV_IDS]
        axes[0].bar(x + j * width, secs, width, label=f"now, slowest controller, {name}")
    if "baseline" in report["idle"]:
        base = report["idle"]["baseline"]
        scale = EPISODES / report["baseline_episodes"]
        secs = [base[e]["seconds"] * scale for e in CURRENT_ENV_IDS]
        axes[0].bar(
            x + len(rounds) * width, secs, width, label="earlier version, classic, idle",
            color="0.6",
        )
    axes[0].set_xticks(x + width * (len(rounds) - 1) / 2, labels, rotation=15, fontsize=8)
    axes[0].set_ylabel(f"seconds for {EPISODES} episodes")
    axes[0].set_yscale("log")
    axes[0].legend(fontsize=8)
    axes[0].set_title("evaluate, 100 episodes")
    bench = [report[n]["benchmark"]["seconds"] for n in rounds if "benchmark" in report[n]]
    axes[1].bar(rounds[: len(bench)], bench, color=["#1f5fa8", "#c0392b"][: len(bench)])
    axes[1].set_ylabel("seconds")
    axes[1].set_title("default benchmark")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--busy", type=int, default=0, help="also measure with N busy processes")
    p.add_argument("--baseline", type=Path, help="checkout of an earlier version to compare")
    p.add_argument("--baseline-episodes", type=int, default=10,
                   help="episodes per env of the baseline's evaluations (scaled to 100)")
    p.add_argument("--no-benchmark", action="store_true", help="skip the default benchmark run")
    p.add_argument("--json", type=Path, help="write the figures as JSON")
    p.add_argument("--plot", type=Path, help="write the figure (PNG)")
    args = p.parse_args()
    report: dict[str, Any] = {"cpus": os.cpu_count(), "baseline_episodes": args.baseline_episodes}
    print("idle:")
    report["idle"] = measure(args)
    if args.busy:
        print(f"busy ({args.busy} other processes on the cores):")
        with BusyCores(args.busy):
            report["busy"] = measure(argparse.Namespace(**{**vars(args), "baseline": None}))
        idle, busy = report["idle"], report["busy"]
        for env_id in CURRENT_ENV_IDS:
            r = busy["evaluate"][env_id]["seconds"] / idle["evaluate"][env_id]["seconds"]
            print(f"  busy/idle evaluate {env_id} classic: {r:.2f}")
        if "benchmark" in busy:
            r = busy["benchmark"]["seconds"] / idle["benchmark"]["seconds"]
            print(f"  busy/idle benchmark: {r:.2f}")
            report["busy_over_idle_benchmark"] = r
    if args.json:
        args.json.write_text(json.dumps(report, indent=1) + "\n")
        print(f"wrote {args.json}")
    if args.plot:
        plot(report, args.plot)
        print(f"wrote {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

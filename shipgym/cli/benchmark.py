"""``shipgym benchmark``: every controller and agent on every task and condition."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path
from typing import Any

from shipgym.cli._common import (
    MAX_EPISODES,
    MAX_SEED,
    int_in,
    output_dir,
    output_path,
    progress_line,
    write_outputs,
)
from shipgym.cli._ray import add_ray_flags, campaign_failed, ray_options


def _benchmark_plan(args: argparse.Namespace, say: Callable[[str], None]) -> None:
    """The benchmark's first line, before anything heavy is imported or compiled: what it runs."""
    from shipgym.benchmark.runner import CONDITIONS, CONTROLLERS, benchmark_cells
    from shipgym.envs import CURRENT_ENV_IDS

    envs = args.env or CURRENT_ENV_IDS
    controllers = args.controller or CONTROLLERS
    conditions = args.condition or CONDITIONS
    cells = len(benchmark_cells(envs, controllers, conditions))

    def n(count: int, word: str) -> str:
        return f"{count:,} {word}{'s' * (count != 1)}"

    say(
        f"shipgym benchmark: {n(cells, 'evaluation')} of {n(args.episodes, 'episode')} "
        f"({n(cells * args.episodes, 'episode')}: {n(len(envs), 'env')}, "
        f"{n(len(controllers), 'controller')}, {n(len(conditions), 'condition')})"
        + (" on Ray" if args.ray is not None else "")
        + (", then PPO's training throughput" if args.throughput else "")
    )
    if args.no_throughput:
        say("--no-throughput is the default now (--throughput measures PPO's throughput)")


def _benchmark_kernels(args: argparse.Namespace, say: Callable[[str], None]) -> None:
    """From a cold kernel cache, say so and compile the kernels the benchmark needs, at once in
    one process per part, so that its evaluation processes load them rather than each compiling
    them."""
    import time

    from shipgym.models._jit import CACHE_DIR
    from shipgym.warmup import BENCHMARK_GROUPS, cold_parts, compile_estimate_s, warm_cache

    if not CACHE_DIR:
        say("kernel cache off (SHIPGYM_NO_CACHE): every process compiles the kernels it uses")
        return
    if args.ray not in (None, "local") or not any(cold_parts(g) for g in BENCHMARK_GROUPS):
        return  # warm, or the episodes run on a cluster's own machines
    estimate = compile_estimate_s(BENCHMARK_GROUPS)
    say(f"compiling the kernels (first run only, about {max(10, round(estimate, -1)):.0f} s)")
    t0 = time.perf_counter()
    if warm_cache(BENCHMARK_GROUPS, say=say):
        say(f"kernels compiled in {time.perf_counter() - t0:.0f} s")
    else:
        say("compiling the kernels ahead failed; each evaluation compiles what it uses")


def run(args: argparse.Namespace) -> int:
    ray = ray_options(args)
    if ray is not None and args.jobs is not None:
        raise ValueError(
            "--jobs sets the local process pool; with --ray the Ray cluster's CPUs run the "
            "episodes (--ray-cpus for a Ray started on this machine)"
        )
    out = output_dir(args.out, "--out")
    json_path = output_path(args.json, "--json", ".json") or out / "benchmark.json"
    csv_path = output_path(args.csv, "--csv", ".csv") or out / "benchmark.csv"
    plots = output_dir(args.plots, "--plots") if args.plots else out
    progress = (lambda line: None) if args.quiet else progress_line
    _benchmark_plan(args, progress)
    _benchmark_kernels(args, progress)

    import json

    from shipgym.benchmark.evaluate import EpisodeError
    from shipgym.benchmark.plots import (
        plot_benchmark_metrics,
        plot_benchmark_robustness,
        plot_benchmark_trajectories,
        plot_throughput,
    )
    from shipgym.benchmark.runner import CONDITIONS, run_benchmark
    from shipgym.benchmark.throughput import ppo_throughput, throughput_table
    from shipgym.cluster import ClusterTaskError

    envs = args.env or None
    controllers = args.controller or None
    kwargs: dict[str, Any] = {}
    if envs:
        kwargs["envs"] = envs
    if controllers:
        kwargs["controllers"] = controllers
    if ray is not None:
        address, cpus, task_size = ray
        kwargs.update(ray=address or True, ray_cpus=cpus, task_size=task_size)
    try:
        result = run_benchmark(
            episodes=args.episodes,
            seed=args.seed,
            conditions=args.condition or CONDITIONS,
            agents_dir=args.agents,
            progress=progress,
            jobs=args.jobs,
            **kwargs,
        )
    except (EpisodeError, ClusterTaskError) as exc:
        return campaign_failed(exc)
    print(result.table())
    print(f"({result.runtime_s:.0f} s)")
    outputs: list[tuple[Path, Callable[[Path], Any]]] = [
        (json_path, result.write_json),
        (csv_path, result.write_csv),
        (plots / "metrics.png", lambda p: plot_benchmark_metrics(result, p)),
    ]
    if len(result.conditions) > 1:
        outputs.append((plots / "robustness.png", lambda p: plot_benchmark_robustness(result, p)))
    for env_id in result.envs:
        outputs.append(
            (
                plots / f"{env_id.split('/')[-1]}.png",
                lambda p, env_id=env_id: plot_benchmark_trajectories(result, env_id, p),
            )
        )
    write_outputs(outputs)
    if args.throughput:
        rows = ppo_throughput(result.envs, timesteps=args.throughput_steps, progress=progress)
        print(throughput_table(rows))
        outputs = [
            (out / "throughput.json", lambda p: p.write_text(json.dumps(rows, indent=2) + "\n")),
            (plots / "throughput.png", lambda p: plot_throughput(rows, p)),
        ]
        write_outputs(outputs)
    return 0


def build(sub: Any) -> None:
    from shipgym.benchmark.runner import CONDITIONS, CONTROLLERS
    from shipgym.envs import ENV_IDS
    from shipgym.rl.train import BENCHMARK_SEED

    p = sub.add_parser(
        "benchmark",
        help="classic controllers (design-rule and tuned gains) vs the PPO/SAC agents vs zero",
        description=(
            "Evaluate the classic controller with its design-rule gains and with its tuned "
            "gains, the shipped PPO and SAC agents and the zero command on the newest version "
            "of every env with identical seeds and current draws (seeds disjoint from the "
            "agents' training and validation seeds and from the tuning seeds), in the nominal "
            "condition and under stress (1.5 x the training current), model mismatch, sensor "
            "noise, an actuator delay and at sea (a moderate sea and a fresh breeze, where the "
            "classic heading autopilot also runs with its wave filter: classic-wf). Prints a "
            "table of mean +- std of each metric, "
            "writes JSON (a list of 'shipgym evaluate' objects with per-episode values and "
            "bootstrap 95 % intervals) and CSV, figures of metrics, robustness and "
            "trajectories; with --throughput also PPO's training throughput on each env "
            "against CartPole-v1."
        ),
    )
    p.add_argument(
        "--episodes",
        type=int_in(1, MAX_EPISODES),
        default=100,
        metavar="N",
        help="episodes per env, controller and condition (%(default)s)",
    )
    p.add_argument(
        "--seed",
        type=int_in(0, MAX_SEED),
        default=BENCHMARK_SEED,
        metavar="S",
        help="first seed of every cell; episode k has seed S + k (default: %(default)s)",
    )
    p.add_argument(
        "--out",
        default="shipgym-benchmark",
        metavar="DIR",
        help="folder of the JSON, CSV and figures, made if missing (default: %(default)s)",
    )
    p.add_argument(
        "--json",
        default=None,
        metavar="OUT",
        help="the results as JSON (default: DIR/benchmark.json)",
    )
    p.add_argument(
        "--csv",
        default=None,
        metavar="OUT",
        help="one row per cell as CSV (default: DIR/benchmark.csv)",
    )
    p.add_argument(
        "--plots",
        default=None,
        metavar="DIR",
        help="folder of the figures (default: the --out folder)",
    )
    p.add_argument(
        "--env",
        action="append",
        choices=ENV_IDS,
        default=None,
        metavar="ID",
        help="only this env (repeatable; default: the newest version of each)",
    )
    p.add_argument(
        "--controller",
        action="append",
        choices=CONTROLLERS,
        default=None,
        help="only this controller (repeatable; default: all)",
    )
    p.add_argument(
        "--agents",
        default=None,
        metavar="DIR",
        help="folder of the ppo/sac agents (default: the shipped ones)",
    )
    p.add_argument(
        "--condition",
        action="append",
        choices=CONDITIONS,
        default=None,
        help="only this condition (repeatable; default: all)",
    )
    throughput = p.add_mutually_exclusive_group()
    throughput.add_argument(
        "--throughput",
        action="store_true",
        help=(
            "after the evaluations, measure PPO's training throughput on each env against "
            "CartPole-v1 in interleaved rounds, with the machine's load (minutes; needs an idle "
            "machine to be comparable)"
        ),
    )
    throughput.add_argument(
        "--no-throughput",
        action="store_true",
        help="the default now (accepted for older scripts)",
    )
    p.add_argument(
        "--throughput-steps",
        type=int_in(1, 10**8),
        default=16_384,
        metavar="N",
        help="with --throughput: timed PPO steps per env and run (%(default)s)",
    )
    p.add_argument(
        "--jobs",
        type=int_in(1, 1024),
        default=None,
        metavar="N",
        help="evaluations at once, one process each (default: one per core)",
    )
    add_ray_flags(p, "evaluations' episodes")
    p.add_argument(
        "--quiet", action="store_true", help="no progress lines (the table is still printed)"
    )
    p.set_defaults(handler=run)

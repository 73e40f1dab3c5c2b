"""Speed-up of an evaluation campaign on a local Ray with 1 and with 2 CPUs, in one process.

Runs ``shipgym evaluate``'s campaign (one env, one controller, ``--episodes`` seeded episodes,
split into Ray tasks of ``--task-episodes``) on a Ray started on this machine with 1 CPU and
with 2 CPUs, alternately, ``--repeats`` times each, and prints the median wall times (from the
submission of the first task to the last result; Ray's start-up is timed apart), their ratio
and the load average of the machine before and after. The results of every run are checked to
be identical. ``--local`` adds one run of the plain in-process evaluator for reference.

    python scripts/bench_ray.py --episodes 2000 --repeats 3 --local
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time

from shipgym.benchmark.evaluate import evaluate
from shipgym.benchmark.policies import POLICIES, make_policy
from shipgym.benchmark.runner import evaluate_on_ray
from shipgym.envs import ENV_IDS


def _load() -> str:
    return "/".join(f"{x:.1f}" for x in os.getloadavg())


def run(env_id: str, controller: str, episodes: int, seed: int, cpus: int, task: int):
    """One campaign on a fresh local Ray with ``cpus`` CPUs: (result, start-up s, campaign s)."""
    marks: list[float] = []
    t0 = time.perf_counter()
    result = evaluate_on_ray(
        env_id,
        controller,
        episodes,
        seed,
        num_cpus=cpus,
        task_size=task,
        keep_logs=0,
        progress=lambda line: marks.append(time.perf_counter()),
    )
    t1 = time.perf_counter()
    return result, marks[0] - t0, t1 - marks[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="shipgym/RVGHeading-v1", choices=ENV_IDS)
    parser.add_argument("--controller", default="classic", choices=POLICIES)
    parser.add_argument("--episodes", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=1_000_000)
    parser.add_argument("--task-episodes", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--local", action="store_true", help="also time the in-process run")
    args = parser.parse_args()

    print(
        f"{args.env} {args.controller}: {args.episodes} episodes from seed {args.seed}, "
        f"tasks of {args.task_episodes} episodes; load average before {_load()}",
        flush=True,
    )
    times: dict[int, list[float]] = {1: [], 2: []}
    reference = None
    for repeat in range(args.repeats):
        for cpus in (1, 2):
            result, startup, wall = run(
                args.env, args.controller, args.episodes, args.seed, cpus, args.task_episodes
            )
            document = json.dumps(result.to_dict())
            reference = reference or document
            if document != reference:
                raise SystemExit("the results of the runs differ")
            times[cpus].append(wall)
            print(
                f"  repeat {repeat + 1}, {cpus} CPU(s): campaign {wall:.1f} s (Ray start-up "
                f"{startup:.1f} s), load {_load()}",
                flush=True,
            )
    m1, m2 = statistics.median(times[1]), statistics.median(times[2])
    print(
        f"median campaign time: 1 CPU {m1:.1f} s, 2 CPUs {m2:.1f} s; speed-up {m1 / m2:.2f}x "
        f"({args.episodes / m2:.0f} episodes/s on 2 CPUs); every run gave the same results"
    )
    if args.local:
        t0 = time.perf_counter()
        local = evaluate(
            args.env,
            make_policy(args.controller, args.env),
            args.controller,
            args.episodes,
            args.seed,
            progress=lambda line: None,
        )
        wall = time.perf_counter() - t0
        same = json.dumps(local.to_dict()) == reference
        print(
            f"in-process evaluate (no Ray): {wall:.1f} s; Ray with 1 CPU / in-process "
            f"{m1 / wall:.2f}; same results: {same}"
        )
    print(f"load average after {_load()}")


if __name__ == "__main__":
    main()

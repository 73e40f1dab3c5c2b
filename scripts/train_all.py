"""Train every agent shipgym ships: PPO and SAC on the newest version of each of the five envs.

    python scripts/train_all.py [--out DIR] [--runs DIR] [--resume] [--only TEXT]
                                [--algo ppo|sac] [--jobs N] [--timesteps N] [--seed S]
    python scripts/train_all.py --from-sweep SWEEP_DIR [--out DIR] [--only TEXT] [--algo A]

Each agent is trained by :func:`shipgym.rl.train.train` with the budget and hyperparameters
of :data:`shipgym.rl.train.TRAINING` into its own run folder ``RUNS/<name>`` (default RUNS:
``out/train_all``; the agent, its checkpoints and TensorBoard run), and the finished agent is
copied as ``DIR/<name>.zip`` + ``DIR/<name>.json`` (default DIR: the package's agent folder,
``shipgym/rl/agents``). ``--resume`` continues the runs that an interrupt left unfinished
from their latest checkpoints. ``--jobs 2`` trains two agents at a time, one per core (torch
then uses one thread each).

``--from-sweep SWEEP_DIR`` trains nothing: it takes the output folder of a sweep (``shipgym
train --ray --sweep FILE --out SWEEP_DIR``), picks the trial with the best validation return
of each agent (env and algorithm) and copies its agent and record into DIR, the record noting
the sweep and trial it came from.

At the end it writes ``docs/training.json``, the learning curves ``docs/training.png`` and the
table of ``docs/guide/training.md`` (unless ``--no-report``).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _print(line: str) -> None:
    print(line, flush=True)


def _train_one(
    env_id: str,
    algo: str,
    out: str,
    runs: str,
    timesteps: int | None,
    seed: int,
    threads: int,
    bar: bool,
    resume: bool,
) -> dict:
    import torch

    torch.set_num_threads(threads)
    from shipgym.rl.checkpoints import latest_dir, read_record
    from shipgym.rl.sweep import install_agent
    from shipgym.rl.train import agent_name, train
    from shipgym.rl.train import resume as resume_run

    name = agent_name(env_id, algo)
    run = Path(runs) / name
    latest = latest_dir(run, name) / f"{name}.json"
    if resume and latest.is_file() and read_record(latest).get("partial"):
        result = resume_run(
            run, env_id, algo, timesteps=timesteps, progress_bar=bar, progress=_print
        )
    else:
        result = train(
            env_id,
            algo,
            timesteps=timesteps,
            seed=seed,
            out_dir=run,
            progress_bar=bar,
            progress=None if bar else _print,
            overwrite=True,
        )
    install_agent(run, name, out)
    return result.meta


def _from_sweep(sweep: str, out: str, only: str | None, algo: str | None) -> int:
    """Copy the best trial's agent of each env and algorithm of a sweep into ``out``."""
    from shipgym.rl.checkpoints import read_record
    from shipgym.rl.sweep import best_trials, install_agent

    try:
        best = best_trials(sweep)
    except ValueError as exc:
        print(f"train_all: error: {exc}", file=sys.stderr)
        return 2
    chosen = {
        name: folder
        for name, folder in best.items()
        if (only is None or only in name) and (algo is None or name.endswith(f"-{algo}"))
    }
    if not chosen:
        print(
            f"train_all: error: no finished trial in {sweep} matches --only/--algo "
            f"(agents there: {', '.join(best)})",
            file=sys.stderr,
        )
        return 2
    Path(out).mkdir(exist_ok=True)
    for name, folder in chosen.items():
        record = read_record(folder / f"{name}.json")
        zip_path, _ = install_agent(folder, name, out, f"sweep {sweep}, trial {folder.name}")
        print(
            f"{name}: trial {folder.name}, best validation return "
            f"{record['best_validation_return']:.1f} at step {record['best_timestep']} "
            f"-> {zip_path}",
            flush=True,
        )
    return 0


def main(argv: list[str] | None = None) -> int:
    from shipgym.envs import CURRENT_ENV_IDS, ENV_IDS
    from shipgym.rl.agents import AGENT_DIR
    from shipgym.rl.train import ALGOS, config

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default=str(AGENT_DIR), help="agent folder (%(default)s)")
    p.add_argument(
        "--runs",
        default=str(ROOT / "out" / "train_all"),
        help="folder of the training runs: checkpoints, TensorBoard (%(default)s)",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="continue unfinished runs in RUNS from their latest checkpoint",
    )
    p.add_argument(
        "--from-sweep",
        default=None,
        metavar="SWEEP_DIR",
        help="train nothing: install the best trial of each agent of this sweep into --out",
    )
    p.add_argument(
        "--only",
        default=None,
        help="train only envs whose id contains TEXT (default: the newest version of each)",
    )
    p.add_argument("--algo", choices=ALGOS, default=None, help="train only this algorithm")
    p.add_argument("--jobs", type=int, default=2, help="agents trained at once (%(default)s)")
    p.add_argument("--timesteps", type=int, default=None, help="override every budget")
    p.add_argument("--seed", type=int, default=0, help="training seed (%(default)s)")
    p.add_argument("--no-report", action="store_true", help="skip the report in docs/")
    args = p.parse_args(argv)
    if args.jobs < 1:
        p.error(f"--jobs must be >= 1, got {args.jobs}")
    if args.from_sweep is not None:
        status = _from_sweep(args.from_sweep, args.out, args.only, args.algo)
        if status == 0 and not args.no_report:
            from shipgym.rl.report import write_training_report

            for path in write_training_report(Path(args.out), ROOT):
                print(f"wrote {path}")
        return status
    jobs = [
        (env_id, algo)
        for env_id in (CURRENT_ENV_IDS if args.only is None else ENV_IDS)
        if args.only is None or args.only in env_id
        for algo in ALGOS
        if args.algo in (None, algo)
    ]
    # longest first, so that the pool does not end on one long job (SAC steps cost about ten
    # times PPO's: a gradient step per few env steps)
    jobs.sort(
        key=lambda job: (
            -(args.timesteps or config(*job)["timesteps"]) * (10 if job[1] == "sac" else 1)
        )
    )
    if not jobs:
        p.error(f"no env id contains {args.only!r}; ids: {', '.join(ENV_IDS)}")
    threads = max(1, (os.cpu_count() or 1) // args.jobs)
    bar = args.jobs == 1 and sys.stderr.isatty()  # one bar per terminal, else log lines
    start = time.perf_counter()
    print(
        f"training {len(jobs)} agents, {args.jobs} at a time, in {args.runs}, into {args.out}",
        flush=True,
    )
    failed = 0
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        futures = {
            pool.submit(
                _train_one,
                env_id,
                algo,
                args.out,
                args.runs,
                args.timesteps,
                args.seed,
                threads,
                bar,
                args.resume,
            ): (env_id, algo)
            for env_id, algo in jobs
        }
        for done, future in enumerate(as_completed(futures), 1):
            env_id, algo = futures[future]
            try:
                meta = future.result()
            except Exception as exc:  # report and go on with the others
                failed += 1
                print(f"[{done}/{len(jobs)}] {env_id} {algo} FAILED: {exc!r}", flush=True)
                continue
            print(
                f"[{done}/{len(jobs)}] {env_id} {algo}: {meta['timesteps']} steps in "
                f"{meta['wall_time_s']:.0f} s, best validation return "
                f"{meta['best_validation_return']:.1f} at {meta['best_timestep']}",
                flush=True,
            )
    print(f"done in {time.perf_counter() - start:.0f} s", flush=True)
    if not args.no_report:
        from shipgym.rl.report import write_training_report

        for path in write_training_report(Path(args.out), ROOT):
            print(f"wrote {path}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

"""What retraining in a seaway costs and gives: PPO on ``shipgym/NomotoHeading-v0`` at sea.

    python scripts/retrain_seaway.py [--out DIR] [--timesteps N] [--episodes N]
                                     [--retrain | --evaluate-only] [--docs]

1. Trains PPO on the Nomoto heading task in the benchmark's seaway (the wind and sea state of
   its ``seaway`` condition, :data:`shipgym.benchmark.runner.SEAWAY`: every episode of the
   training a fresh breeze and a moderate sea from its own directions and seed) with the
   shipped agent's configuration (:func:`shipgym.rl.train.config`: budget, seed,
   hyperparameters), into ``DIR`` (default ``out/seaway_retraining``), a progress line per
   evaluation. A finished agent of the same seaway and budget already in ``DIR`` is reused, an
   unfinished training of them continued from its latest checkpoint (``--retrain`` trains
   anew; ``--evaluate-only`` evaluates the agent in ``DIR`` as it stands, the best policy so
   far of an unfinished training).
2. Evaluates the shipped (calm-trained) agent, the retrained one and the classic autopilots in
   calm water and in the seaway: the benchmark's ``nominal`` and ``seaway`` scenarios
   (:func:`shipgym.benchmark.runner.scenarios`) on its episodes (seeds from
   :data:`~shipgym.rl.train.BENCHMARK_SEED`), with :func:`shipgym.benchmark.evaluate.evaluate`.
3. Prints the comparison table: return, the measured heading error (``heading_rms_deg``: what
   the compass shows, with the wave-frequency motion), the low-frequency heading error
   (``lf_heading_rms_deg``, of the heading of ``info["state"]``: what the autopilot must hold,
   and what the reward scores), the rudder travel and reversals per minute, each a mean over
   the episodes with its bootstrap 95 % interval.

``--docs`` also writes the figure ``docs/seaway_retraining.png`` (the retrained agent's
learning curve beside the shipped one's; LF heading error and rudder travel of the four
agent cases) and the table block of ``docs/results/seaway_retraining.md``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ENV_ID = "shipgym/NomotoHeading-v0"
ALGO = "ppo"
#: Classic controllers evaluated for reference (``classic-wf``: with the wave filter).
CLASSIC = ("classic", "classic-wf", "classic-tuned")
#: The benchmark's scenarios evaluated, by the water they put the ship in.
WATERS = {"calm": "nominal", "seaway": "seaway"}
METRICS = (
    "return",
    "heading_rms_deg",
    "lf_heading_rms_deg",
    "rudder_travel_deg_min",
    "rudder_reversals_min",
)
FIGURE = ROOT / "docs" / "seaway_retraining.png"
PAGE = ROOT / "docs" / "results" / "seaway_retraining.md"
PAGE_MARKER = "seaway-retraining"


def _print(line: str) -> None:
    print(line, flush=True)


def _record(path: Path, env_kwargs: dict[str, Any], timesteps: int) -> dict[str, Any] | None:
    """The training record at ``path`` if it is of a training in ``env_kwargs`` towards
    ``timesteps`` steps."""
    from shipgym.rl.checkpoints import read_record

    if not path.is_file():
        return None
    record = read_record(path)
    same_sea = record.get("env_kwargs") == json.loads(json.dumps(env_kwargs))
    return record if same_sea and record.get("requested_timesteps") == timesteps else None


def retrain(out: Path, env_kwargs: dict[str, Any], timesteps: int, again: bool) -> dict:
    """Train PPO on :data:`ENV_ID` in ``env_kwargs`` into ``out``; the agent's record.

    A finished agent of the same seaway and budget in ``out`` is reused and an unfinished
    training of them continued from its latest checkpoint (:func:`shipgym.rl.train.resume`),
    unless ``again``.
    """
    from shipgym.rl.checkpoints import latest_dir
    from shipgym.rl.train import agent_name, resume, train

    name = agent_name(ENV_ID, ALGO)
    if not again:
        record = _record(out / f"{name}.json", env_kwargs, timesteps)
        if record is not None and not record["partial"] and (out / f"{name}.zip").is_file():
            _print(f"reusing the finished agent in {out} ({record['wall_time_s']} s of training)")
            return record
        latest = _record(latest_dir(out, name) / f"{name}.json", env_kwargs, timesteps)
        if latest is not None and latest["partial"]:
            return resume(out, ENV_ID, ALGO, progress_bar=False, progress=_print,
                          tensorboard_log=False).meta  # fmt: skip
    result = train(
        ENV_ID,
        ALGO,
        timesteps=timesteps,
        out_dir=out,
        progress_bar=False,
        progress=_print,
        env_kwargs=env_kwargs,
        tensorboard_log=False,
        overwrite=True,
    )
    return result.meta


def summary(result: Any) -> dict[str, dict[str, Any]]:
    """Mean, bootstrap 95 % interval and per-episode values of :data:`METRICS`."""
    from shipgym.benchmark.stats import bootstrap_ci

    per = {"return": np.asarray(result.returns, dtype=float)}
    per.update({k: result.values(k) for k in METRICS[1:]})
    return {
        key: {
            "mean": float(np.mean(v)),
            "ci95": [float(c) for c in bootstrap_ci(v)],
            "values": [float(x) for x in v],
        }
        for key, v in per.items()
    }


def evaluate_all(
    agents: dict[str, Path | None], episodes: int, seed: int
) -> dict[tuple[str, str], dict[str, dict[str, Any]]]:
    """Summaries by (case, water) of the agents (name -> agent folder, None: shipped) and the
    classic controllers in the benchmark's scenarios of :data:`WATERS`."""
    from shipgym.benchmark.evaluate import evaluate
    from shipgym.benchmark.policies import make_policy
    from shipgym.benchmark.runner import SEAWAY_ONLY, scenarios

    cases: dict[str, Any] = {name: make_policy(ALGO, ENV_ID, d) for name, d in agents.items()}
    cases.update({name: make_policy(name, ENV_ID) for name in CLASSIC})
    out = {}
    for water, condition in WATERS.items():
        (scenario,) = scenarios(ENV_ID, condition, 0.0)
        for name, policy in cases.items():
            if name in SEAWAY_ONLY and condition != "seaway":
                continue
            start = time.perf_counter()
            result = evaluate(ENV_ID, policy, name, episodes, seed,
                              env_kwargs=scenario.env_kwargs,
                              reset_options=scenario.reset_options, progress=lambda line: None,
                              condition=condition, wrappers=scenario.wrappers)  # fmt: skip
            out[name, water] = summary(result)
            mean = out[name, water]["return"]["mean"]
            _print(
                f"evaluated {name} in {water}: {episodes} episodes in "
                f"{time.perf_counter() - start:.1f} s, return {mean:.1f}"
            )
    return out


def _cell(s: dict[str, Any]) -> str:
    lo, hi = s["ci95"]
    return f"{s['mean']:.3g} [{lo:.3g}, {hi:.3g}]"


def table(results: dict[tuple[str, str], dict[str, dict[str, Any]]]) -> str:
    """The Markdown table of ``results`` (one row per case and water)."""
    lines = [
        "| controller | water | " + " | ".join(METRICS) + " |",
        "|---|---|" + "---:|" * len(METRICS),
    ]
    for (name, water), s in results.items():
        lines.append(f"| {name} | {water} | " + " | ".join(_cell(s[m]) for m in METRICS) + " |")
    return "\n".join(lines)


def plot(
    record: dict[str, Any],
    shipped: dict[str, Any],
    results: dict[tuple[str, str], dict[str, dict[str, Any]]],
    agents: tuple[str, str],
    path: Path,
) -> Path:
    """Learning curves (validation return, in each agent's training water) and bars of the
    LF heading error and the rudder travel of the ``agents`` in calm water and the seaway."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    ax = axes[0]
    for rec, label in ((shipped, "shipped (calm water)"), (record, "retrained (seaway)")):
        curve = rec["learning_curve"]
        (line,) = ax.plot(np.asarray(curve["timesteps"]) / 1e6, curve["mean_return"], "o-",
                          ms=3, label=label)  # fmt: skip
        ax.plot(rec["best_timestep"] / 1e6, rec["best_validation_return"], "*", ms=12,
                color=line.get_color())  # fmt: skip
    ax.set_xlabel("environment steps [million]")
    ax.set_ylabel("validation return (own water)")
    ax.set_ylim(bottom=max(ax.get_ylim()[0], -150.0))
    ax.set_title("PPO learning curves (star: the agent kept)")
    ax.legend()
    width = 0.38
    x = np.arange(len(agents))
    for ax, key, label in (
        (axes[1], "lf_heading_rms_deg", "LF heading error RMS [deg]"),
        (axes[2], "rudder_travel_deg_min", "rudder travel [deg/min]"),
    ):
        for j, water in enumerate(("calm", "seaway")):
            s = [results[name, water][key] for name in agents]
            mean = np.array([v["mean"] for v in s])
            err = np.array([[v["mean"] - v["ci95"][0], v["ci95"][1] - v["mean"]] for v in s]).T
            ax.bar(x + (j - 0.5) * width, mean, width, yerr=err, capsize=3,
                   label=f"evaluated in {water}")  # fmt: skip
        ax.set_xticks(x, agents)
        ax.set_ylabel(label)
        ax.legend(loc="lower center", framealpha=0.9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv: list[str]) -> int:
    from shipgym.benchmark.runner import SEAWAY
    from shipgym.envs import env_task
    from shipgym.rl.agents import load_meta
    from shipgym.rl.checkpoints import latest_dir, read_record
    from shipgym.rl.train import BENCHMARK_SEED, agent_name, config

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--out",
        type=Path,
        default=ROOT / "out" / "seaway_retraining",
        help="folder of the retrained agent (default: out/seaway_retraining)",
    )
    parser.add_argument(
        "--timesteps",
        type=int,
        default=config(ENV_ID, ALGO)["timesteps"],
        help="training steps (default: the shipped agent's budget)",
    )
    parser.add_argument(
        "--episodes",
        type=int,
        default=100,
        help="evaluation episodes per case (default: the benchmark's 100)",
    )
    parser.add_argument(
        "--retrain",
        action="store_true",
        help="train anew even if DIR holds a finished agent of this seaway",
    )
    parser.add_argument(
        "--evaluate-only",
        action="store_true",
        help="train nothing: evaluate the agent in DIR as it stands (even an unfinished one)",
    )
    parser.add_argument(
        "--docs",
        action="store_true",
        help=f"write {FIGURE.relative_to(ROOT)} and the table of {PAGE.relative_to(ROOT)}",
    )
    args = parser.parse_args(argv)
    if args.timesteps < 1 or args.episodes < 2:
        parser.error(
            f"--timesteps must be >= 1 and --episodes >= 2, got {args.timesteps}, {args.episodes}"
        )

    sea = SEAWAY[env_task(ENV_ID)]
    _print(f"seaway of the benchmark: {json.dumps(sea)}")
    if args.evaluate_only:
        record = load_meta(ENV_ID, ALGO, args.out)
    else:
        record = retrain(args.out, sea, args.timesteps, args.retrain)
    # an unfinished training's agent record stops at its best step; the latest goes on
    latest = latest_dir(args.out, agent_name(ENV_ID, ALGO)) / f"{agent_name(ENV_ID, ALGO)}.json"
    run = read_record(latest) if record["partial"] and latest.is_file() else record
    cost = (
        f"{run['timesteps']} of {run['requested_timesteps']} steps in {run['wall_time_s']:.0f} s "
        f"({run['steps_per_s']:.0f} steps/s on {run['machine']}); the agent: the policy of step "
        f"{record['best_timestep']}, the best on the validation episodes"
        + (" so far (an unfinished training)" if record["partial"] else "")
    )
    _print(f"training: {cost}")
    agents = {"ppo (shipped)": None, "ppo (seaway)": args.out}
    results = evaluate_all(agents, args.episodes, BENCHMARK_SEED)
    text = table(results)
    print(text)
    if args.docs:
        from shipgym.sysid.report import update_block

        shipped = load_meta(ENV_ID, ALGO)
        _print(f"wrote {plot(run, shipped, results, tuple(agents), FIGURE)}")
        head = (
            f"{args.episodes} episodes per row, seeds {BENCHMARK_SEED}-"
            f"{BENCHMARK_SEED + args.episodes - 1}; seaway: wind {json.dumps(sea['wind'])}, "
            f"sea state {json.dumps(sea['sea_state'])} (directions drawn per episode); "
            "mean over the episodes with its bootstrap 95 % interval. Retraining: "
            f"{cost}."
        )
        update_block(PAGE, head + "\n\n" + text, PAGE_MARKER)
        _print(f"wrote the table of {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

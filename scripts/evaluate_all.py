"""Evaluate the classic controller and the zero baseline on every env; table, JSON and figure.

Usage::

    python scripts/evaluate_all.py [--episodes N] [--seed S] [--out DIR]

Writes ``DIR/evaluation.json`` (a list of ``shipgym evaluate`` objects), ``DIR/evaluation.png``
(the key metric of each env, classic against zero, mean and std over episodes) and prints a
Markdown table.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from shipgym.benchmark import evaluate, make_policy
from shipgym.benchmark.evaluate import METRICS
from shipgym.envs import ENV_IDS

CONTROLLERS = ("classic", "zero")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=10)
    parser.add_argument("--seed", type=int, default=1000)
    parser.add_argument("--out", default="docs")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {
        (env_id, name): evaluate(env_id, make_policy(name, env_id), name, args.episodes, args.seed)
        for env_id in ENV_IDS
        for name in CONTROLLERS
    }
    (out / "evaluation.json").write_text(
        json.dumps([r.to_dict() for r in results.values()], indent=2)
    )
    print("| env | controller | return | " + " | ".join(["metrics (mean +- std)"]) + " |")
    print("|---|---|---:|---|")
    for (env_id, name), r in results.items():
        d = r.to_dict()
        metrics = ", ".join(
            f"{k} {v:.3g} +- {d['metrics_std'][k]:.2g}" for k, v in d["metrics"].items()
        )
        print(
            f"| {env_id.split('/')[1]} | {name} | {d['mean_return']:.1f} +- "
            f"{d['std_return']:.1f} | {metrics} |"
        )
    fig = Figure(figsize=(13, 3.6), constrained_layout=True)
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(ENV_IDS))
    for ax, env_id in zip(axes, ENV_IDS, strict=True):
        key = METRICS[env_id][0]
        means = [results[env_id, c].metrics[key] for c in CONTROLLERS]
        stds = [results[env_id, c].metrics_std[key] for c in CONTROLLERS]
        ax.bar(CONTROLLERS, means, yerr=stds, color=["#1f5fa8", "#9a9a9a"], capsize=4)
        ax.set_title(env_id.split("/")[1], fontsize=10)
        ax.set_ylabel(key)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle(
        f"classic controller vs zero command, {args.episodes} episodes from seed {args.seed} "
        "(lower is better)"
    )
    fig.savefig(out / "evaluation.png", dpi=110)
    print(f"wrote {out / 'evaluation.json'} and {out / 'evaluation.png'}")


if __name__ == "__main__":
    main()

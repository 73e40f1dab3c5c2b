"""Tune the classic controllers of every env: the gains ``classic-tuned`` ships with.

    python scripts/tune_classic.py [--only TEXT] [--episodes N] [--out DIR] [--report-only]

For each env of :data:`shipgym.envs.CURRENT_ENV_IDS` (or those whose id contains TEXT) this
runs :func:`shipgym.benchmark.tuning.tune` (a grid over the classic structure's design
parameters, scored by the mean return on the RL training seeds 0-15) and writes the record to
``DIR/<env>.json`` (default: the package's ``shipgym/benchmark/tuned``). It then draws
``docs/tuning.png`` (every candidate's training-seed return, the design rule's and the
winner's marked) and writes the table between the ``tuning`` markers of
``docs/guide/benchmark.md``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "guide" / "benchmark.md"
"""The documentation page that holds the table."""
PAGE_MARKER = "tuning"


def _fmt(value: Any) -> str:
    return "rule" if value is None else f"{value:g}"


def tuning_table(records: list[dict[str, Any]]) -> str:
    """Markdown table: the design-rule and tuned design parameters, their training-seed
    returns and the search's budget beside the RL agents' training budgets."""
    from shipgym.rl.agents import load_meta

    lines = [
        "| env | design parameter: rule -> tuned | return on seeds 0-15: rule -> tuned | "
        "search: candidates x episodes = env steps | PPO / SAC training env steps |",
        "|---|---|---|---|---|",
    ]
    for r in records:
        changed = [
            f"{k} {_fmt(r['design_rule'][k])} -> {_fmt(v)}"
            for k, v in r["design"].items()
            if k in r["grid"]
        ]
        budgets = []
        for algo in ("ppo", "sac"):
            try:
                budgets.append(f"{load_meta(r['env'], algo)['timesteps']:,}")
            except FileNotFoundError:
                budgets.append("-")
        b = r["budget"]
        lines.append(
            f"| {r['env'].split('/')[-1]} | {'; '.join(changed)} | "
            f"{r['design_rule_score']:.1f} -> {r['score']:.1f} | "
            f"{b['candidates']} x {r['episodes']} = {b['env_steps']:,} | {' / '.join(budgets)} |"
        )
    return "\n".join(lines)


def plot_tuning(records: list[dict[str, Any]], path: Path) -> Path:
    """One panel per env: every candidate's mean return (sorted), rule and winner marked."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3.4 * len(records), 3.2), constrained_layout=True)
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(1, len(records), squeeze=False)[0])
    for ax, r in zip(axes, records, strict=True):
        scores = sorted((c["mean_return"] for c in r["candidates"]), reverse=True)
        ax.plot(range(1, len(scores) + 1), scores, ".", color="#7f8c8d", label="candidates")
        rank_rule = scores.index(r["design_rule_score"]) + 1
        ax.plot(rank_rule, r["design_rule_score"], "s", color="#1f5fa8", label="design rule")
        ax.plot(1, r["score"], "*", ms=12, color="#c0392b", label="tuned")
        ax.set_title(r["env"].split("/")[-1], fontsize=9)
        ax.set_xlabel("candidate (by return)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("mean return, training seeds 0-15")
    axes[0].legend(fontsize=7)
    fig.savefig(path, dpi=110)
    return path


def main(argv: list[str] | None = None) -> int:
    from shipgym.benchmark.tuning import TUNED_DIR, TUNING_EPISODES, load_tuned, tune, write_tuned
    from shipgym.envs import CURRENT_ENV_IDS
    from shipgym.sysid.report import update_block

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--only", default=None, help="tune only envs whose id contains TEXT")
    p.add_argument("--episodes", type=int, default=TUNING_EPISODES, help="per candidate")
    p.add_argument("--out", default=str(TUNED_DIR), help="record folder (%(default)s)")
    p.add_argument("--no-report", action="store_true", help="skip the figure and the page")
    p.add_argument(
        "--report-only",
        action="store_true",
        help="only redraw the figure and the page's table from the records",
    )
    args = p.parse_args(argv)
    if args.episodes < 1:
        p.error(f"--episodes must be >= 1, got {args.episodes}")
    envs = [e for e in CURRENT_ENV_IDS if args.only is None or args.only in e]
    if not envs:
        p.error(f"no env id contains {args.only!r}; ids: {', '.join(CURRENT_ENV_IDS)}")
    for env_id in [] if args.report_only else envs:
        record = tune(env_id, episodes=args.episodes)
        print(
            f"{env_id}: {record['design']} return {record['score']:.1f} (design rule "
            f"{record['design_rule_score']:.1f}), {record['budget']['env_steps']:,} env steps, "
            f"{record['wall_time_s']:.0f} s; wrote {write_tuned(record, args.out)}",
            flush=True,
        )
    if not args.no_report:
        records = [load_tuned(e, args.out) for e in CURRENT_ENV_IDS]
        print(f"wrote {plot_tuning(records, ROOT / 'docs' / 'tuning.png')}")
        update_block(PAGE, tuning_table(records), PAGE_MARKER)
        print(f"updated {PAGE.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

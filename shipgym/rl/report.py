"""The training report of the shipped agents: table, learning curves, documentation block.

:func:`write_training_report` reads every agent record (``<name>.json``) in a folder and
writes ``docs/training.json`` (the rows), ``docs/training.png`` (validation return against
environment steps for PPO and SAC on each env, with the classic controller's return on the
same validation episodes as a reference line) and the block between ``<!-- training -->`` and
``<!-- /training -->`` of the training guide, ``docs/guide/training.md``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from shipgym.envs import CURRENT_ENV_IDS
from shipgym.rl.train import ALGOS, VALIDATION_SEED

PAGE_MARKER = "training"
"""Name of the block in ``docs/guide/training.md``."""
_COLOURS = {"ppo": "#c0392b", "sac": "#2e8b57"}


def training_rows(agent_dir: str | Path) -> list[dict[str, Any]]:
    """One row per agent record found in ``agent_dir`` (env order, then algorithm)."""
    rows = []
    for env_id in CURRENT_ENV_IDS:
        for algo in ALGOS:
            path = Path(agent_dir) / f"{env_id.split('/')[-1]}-{algo}.json"
            if path.is_file():
                rows.append(json.loads(path.read_text()))
    return rows


def classic_validation_return(env_id: str, episodes: int, controller: str = "classic") -> float:
    """Mean return of a classic controller (``classic`` or ``classic-tuned``) on the
    validation episodes of the training."""
    from shipgym.benchmark import evaluate, make_policy

    result = evaluate(
        env_id,
        make_policy(controller, env_id),
        controller,
        episodes,
        VALIDATION_SEED,
        progress=lambda line: None,
    )
    return float(np.mean(result.returns))


def render_training_table(rows: list[dict[str, Any]]) -> str:
    """Markdown table: budget, seed, wall time, speed and best validation return per agent."""
    lines = [
        "| agent | env steps | sub-envs | seed | wall time [s] | steps/s | best validation "
        "return (at step) | file [kB] |",
        "|---|---:|---:|---:|---:|---:|---|---:|",
    ]
    for r in rows:
        size = r.get("file_kb", "")
        lines.append(
            f"| {r['name']} | {r['timesteps']:,} | {r['num_envs']} | {r['seed']} | "
            f"{r['wall_time_s']:.0f} | {r['steps_per_s']:,.0f} | "
            f"{r['best_validation_return']:.1f} ({r['best_timestep']:,}) | {size} |"
        )
    return "\n".join(lines)


def plot_learning_curves(
    rows: list[dict[str, Any]], classic: dict[str, dict[str, float]], path: str | Path
) -> Path:
    """Validation return against env steps, one panel per env, PPO and SAC overlaid, with the
    classic controllers' validation returns (``classic[controller][env_id]``) as lines."""
    envs = [e for e in CURRENT_ENV_IDS if any(r["env"] == e for r in rows)]
    fig = Figure(figsize=(3.6 * len(envs), 3.4), constrained_layout=True)
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(1, len(envs), squeeze=False)[0])
    for ax, env_id in zip(axes, envs, strict=True):
        for r in rows:
            if r["env"] != env_id:
                continue
            curve = r["learning_curve"]
            t = np.asarray(curve["timesteps"], dtype=float)
            m = np.asarray(curve["mean_return"])
            s = np.asarray(curve["std_return"])
            colour = _COLOURS.get(r["algo"], "k")
            ax.plot(t, m, color=colour, label=r["algo"], marker=".", ms=3)
            ax.fill_between(t, m - s, m + s, color=colour, alpha=0.15)
            if r.get("best_timestep") is not None:
                ax.plot(r["best_timestep"], r["best_validation_return"], "*", color=colour, ms=9)
        for name, colour in (("classic", "#7fa7d6"), ("classic-tuned", "#1f5fa8")):
            if env_id in classic.get(name, {}):
                ax.axhline(classic[name][env_id], color=colour, ls="--", lw=1.2, label=name)
        ax.set_xscale("log")
        ax.set_title(env_id.split("/")[-1], fontsize=10)
        ax.set_xlabel("env steps")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("validation return (16 episodes)")
    fig.suptitle(
        "learning curves of the shipped agents (star: the saved policy; band: std over episodes)",
        fontsize=11,
    )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path


def write_training_report(agent_dir: str | Path, root: str | Path) -> list[Path]:
    """Write ``docs/training.json``, ``docs/training.png`` and the block of
    ``docs/guide/training.md`` under ``root`` (the repository)."""
    from shipgym.sysid.report import relative_link, update_block

    rows = training_rows(agent_dir)
    if not rows:
        raise ValueError(f"no agent records (*.json) in {agent_dir}")
    for r in rows:
        zip_path = Path(agent_dir) / f"{r['name']}.zip"
        r["file_kb"] = round(zip_path.stat().st_size / 1024) if zip_path.is_file() else None
    classic = {
        name: {
            env_id: classic_validation_return(env_id, 16, name)
            for env_id in dict.fromkeys(r["env"] for r in rows)
        }
        for name in ("classic", "classic-tuned")
    }
    docs = Path(root) / "docs"
    docs.mkdir(parents=True, exist_ok=True)
    summary = [
        {k: v for k, v in r.items() if k not in ("learning_curve", "obs_normaliser")} for r in rows
    ]
    json_path = docs / "training.json"
    json_path.write_text(json.dumps({"agents": summary, "classic": classic}, indent=2) + "\n")
    png = plot_learning_curves(rows, classic, docs / "training.png")
    total = sum(r["wall_time_s"] for r in rows)
    block = (
        "Trained with `python scripts/train_all.py` (two agents at a time, one core and one "
        f"torch thread each); {len(rows)} agents, {total / 60:.0f} min of training in all. "
        "Validation return: the mean over 16 fixed validation episodes (seeds "
        f"{VALIDATION_SEED}-{VALIDATION_SEED + 15}) of the policy that was saved.\n\n"
        + render_training_table(rows)
    )
    page = docs / "guide" / "training.md"
    block += f"\n\n![learning curves]({relative_link(png, page)})"
    update_block(page, block, PAGE_MARKER)
    return [json_path, png, page]

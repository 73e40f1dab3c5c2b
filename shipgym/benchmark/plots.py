"""Figures of an evaluation: the trajectory and the key signals of each episode."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from shipgym.benchmark.evaluate import BLOW_UP, HEADING_ENVS, EpisodeLog, EvaluationResult
from shipgym.envs import env_task

_TASK_SIGNAL = {
    "NomotoHeading": ("heading_error", "heading error [deg]", math.degrees(1.0)),
    "RVGHeading": ("heading_error", "heading error [deg]", math.degrees(1.0)),
    "RVGSpeed": ("speed_error", "speed error [m/s]", 1.0),
    "RVGPathFollowing": ("cross_track_error", "cross-track error [m]", 1.0),
    "RVGTargetTracking": ("distance_error", "distance error [m]", 1.0),
}


def _track(ax: Any, result: EvaluationResult, log: EpisodeLog) -> None:
    state = np.asarray(log.state)
    x0 = log.reset_info["state"]
    north = np.concatenate(([x0[0]], state[:, 0]))
    east = np.concatenate(([x0[1]], state[:, 1]))
    ax.plot(east, north, color="#1f5fa8", lw=1.8, label="ship track")
    ax.plot(east[0], north[0], "o", color="#2e8b57", label="start")
    ax.plot(east[-1], north[-1], "o", color="#c0392b", label="end")
    extras = log.extras
    if "waypoints" in extras:
        wp = np.asarray(extras["waypoints"])
        ax.plot(wp[:, 1], wp[:, 0], "--s", color="0.4", ms=5, lw=1.2, label="path")
    if "target" in extras:
        tgt = np.asarray(extras["target"])
        ax.plot(tgt[:, 1], tgt[:, 0], color="#e67e22", lw=1.5, label="target")
    speed = log.reset_info["current_speed"]
    direction = log.reset_info["current_direction"]
    ax.set_title(
        f"seed {log.seed}: current {speed:.2f} m/s toward {math.degrees(direction) % 360:.0f} deg",
        fontsize=10,
    )
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")


def plot_episode(result: EvaluationResult, log: EpisodeLog, path: str | Path) -> Path:
    """Write the track and the key signals of one episode to ``path`` (PNG)."""
    fig = Figure(figsize=(12, 5.5), constrained_layout=True)
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(2, 2, width_ratios=(1.1, 1.0))
    _track(fig.add_subplot(grid[:, 0]), result, log)
    key, label, scale = _TASK_SIGNAL[env_task(result.env)]
    t = np.asarray(log.time)
    ax = fig.add_subplot(grid[0, 1])
    ax.plot(t, log.signal(key) * scale, color="#1f5fa8")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_ylabel(label)
    ax.grid(alpha=0.3)
    if result.env in HEADING_ENVS:
        ax2 = ax.twinx()
        ax2.plot(t, np.degrees(log.signal("heading_setpoint")), color="0.5", ls=":", lw=1)
        ax2.set_ylabel("setpoint [deg]", color="0.4")
    ax = fig.add_subplot(grid[1, 1], sharex=ax)
    actions = np.asarray(log.action)
    names = ("azimuth", "thrust") if actions.shape[1] == 2 else ("command",)
    for j, name in enumerate(names):
        ax.plot(t, actions[:, j], lw=1.2, label=name)
    ax.set_ylim(-1.1, 1.1)
    ax.set_ylabel("normalised action [-]")
    ax.set_xlabel("time [s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    reason = log.termination_reason
    outcome = (
        f"NUMERICAL BLOW-UP at step {len(log.time)} (no return, no metrics)"
        if reason == BLOW_UP
        else f"return {log.episode_return:.1f}"
    )
    fig.suptitle(
        f"{result.env}, controller {result.controller}: {outcome}",
        fontsize=12,
        color="#c0392b" if reason == BLOW_UP else "black",
    )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def episode_figures(
    result: EvaluationResult, out_dir: str | Path, max_episodes: int = 5
) -> list[tuple[Path, Callable[[Path], Path]]]:
    """One PNG per episode (the first ``max_episodes``) in ``out_dir``, not yet drawn.

    Returns ``(path, write)`` pairs; ``write(file)`` draws that episode's figure into ``file``,
    so a caller can write them all atomically (temporary files renamed at the end).
    """
    name = result.env.split("/")[-1]
    return [
        (
            Path(out_dir) / f"{name}_{result.controller}_seed{log.seed}.png",
            lambda file, log=log: plot_episode(result, log, file),
        )
        for log in result.logs[:max_episodes]
    ]


# ------------------------------------------------------------------------------------------
# benchmark figures
# ------------------------------------------------------------------------------------------
#: One colour per controller, the same in every benchmark figure.
CONTROLLER_COLOURS = {
    "classic": "#7fa7d6",
    "classic-wf": "#e67e22",
    "classic-tuned": "#1f5fa8",
    "ppo": "#c0392b",
    "sac": "#2e8b57",
    "zero": "#9a9a9a",
}


def _colour(name: str) -> str:
    return CONTROLLER_COLOURS.get(name, "#8e44ad")


def _mean_ci(result: Any, key: str) -> tuple[float, float, float]:
    """Mean and bootstrap 95 % interval of the return or a metric (NaN if undefined)."""
    d = result.to_dict()
    if key == "return":
        mean, ci = d["mean_return"], d["return_ci95"]
    else:
        mean, ci = d["metrics"][key], d["metrics_ci95"][key]
    lo, hi = ci if ci else (mean, mean)
    return mean, lo, hi


def plot_benchmark_metrics(benchmark: Any, path: str | Path) -> Path:
    """Bars of the return and every engineering metric in the nominal condition, one row per
    env: the mean over episodes with its bootstrap 95 % interval, one colour per controller."""
    from shipgym.benchmark.evaluate import HIGHER_IS_BETTER, METRICS

    envs, controllers = benchmark.envs, benchmark.controllers
    ncols = 1 + max(len(METRICS[e]) for e in envs)
    # fixed margins: a constrained layout took 0.7 s of this figure's 2.2 (dozens of axes)
    height = 2.5 * len(envs)  # [in]; margins for the title and the rotated names, in inches
    fig = Figure(figsize=(2.9 * ncols, height))
    fig.subplots_adjust(left=0.04, right=0.99, top=1 - 0.6 / height, bottom=0.85 / height,
                        wspace=0.45, hspace=0.75)  # fmt: skip
    FigureCanvasAgg(fig)
    axes = np.atleast_2d(fig.subplots(len(envs), ncols, squeeze=False))
    for i, env_id in enumerate(envs):
        keys = ("return", *METRICS[env_id])
        names = [n for n in controllers if _has(benchmark, env_id, n, "nominal")]
        for j in range(ncols):
            ax = axes[i, j]
            if j >= len(keys):
                ax.axis("off")
                continue
            key = keys[j]
            stats = [_mean_ci(benchmark.get(env_id, n, "nominal"), key) for n in names]
            means = np.array([m for m, _, _ in stats])
            err = np.array([[m - lo for m, lo, _ in stats], [hi - m for m, _, hi in stats]])
            ax.bar(
                range(len(names)),
                means,
                0.75,
                yerr=err,
                capsize=2,
                color=[_colour(n) for n in names],
            )
            for x, n in enumerate(names):
                result = benchmark.get(env_id, n, "nominal")
                if result.blown_up:  # no bar: its mean is undefined
                    label = f"blew up {result.blown_up}/{result.episodes}"
                    ax.text(
                        x,
                        0.0,
                        label,
                        rotation=90,
                        ha="center",
                        va="bottom",
                        fontsize=7,
                        color="#c0392b",
                    )
            ax.set_xticks(range(len(names)), names, fontsize=7, rotation=30)
            better = "higher" if key == "return" or key in HIGHER_IS_BETTER else "lower"
            title = f"{key} ({better} better)"
            ax.set_title(f"{env_id.split('/')[-1]}: {title}" if j == 0 else title, fontsize=8)
            ax.grid(axis="y", alpha=0.3)
    fig.suptitle(
        f"benchmark, nominal condition: {benchmark.episodes} episodes from seed "
        f"{benchmark.seed} per bar (mean and bootstrap 95 % interval)",
        fontsize=11,
    )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path


def _has(benchmark: Any, env_id: str, name: str, cond: str) -> bool:
    return any(
        (r.env, r.controller, r.condition) == (env_id, name, cond) for r in benchmark.results
    )


def plot_benchmark_robustness(benchmark: Any, path: str | Path) -> Path:
    """Mean return per condition (with its 95 % interval), one panel per env, one line per
    controller: who degrades more, and by how much, away from the nominal condition."""
    envs = benchmark.envs
    fig = Figure(figsize=(3.6 * len(envs), 3.6), constrained_layout=True)
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(1, len(envs), squeeze=False)[0])
    for ax, env_id in zip(axes, envs, strict=True):
        conds = [
            c
            for c in benchmark.conditions
            if any((r.env, r.condition) == (env_id, c) for r in benchmark.results)
        ]
        for name in benchmark.controllers:
            pts = [
                (k, *_mean_ci(benchmark.get(env_id, name, c), "return"))
                for k, c in enumerate(conds)
                if _has(benchmark, env_id, name, c)
            ]
            for k, c in enumerate(conds):
                if _has(benchmark, env_id, name, c) and benchmark.get(env_id, name, c).blown_up:
                    ax.plot(k, 0.0, "x", color=_colour(name), ms=9, mew=2)  # no mean: marked
            if len(pts) < 2:
                continue
            k, m, lo, hi = (np.array(v) for v in zip(*pts, strict=True))
            ax.errorbar(
                k,
                m,
                yerr=[m - lo, hi - m],
                color=_colour(name),
                marker="o",
                ms=4,
                capsize=2,
                lw=1.2,
                label=name,
            )
        ax.set_xticks(range(len(conds)), conds, fontsize=7, rotation=35)
        ax.set_title(env_id.split("/")[-1], fontsize=9)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("mean return (95 % interval); x: blew up, no mean")
    axes[0].legend(fontsize=7)
    fig.suptitle("robustness: the same seeds in every condition", fontsize=11)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path


def plot_seaway(entries: list[dict[str, Any]], path: str | Path) -> Path:
    """The seaway condition against calm water, one row per env: the low-frequency heading
    error (path following: the cross-track error) and the rudder (azimuth) travel of each
    controller, calm and at sea side by side, mean and bootstrap 95 % interval
    (:func:`shipgym.benchmark.report.seaway_rows` gives the numbers)."""
    from shipgym.benchmark.report import seaway_error_key, seaway_rows

    envs = list(dict.fromkeys(e["env"] for e in entries if e["condition"] == "seaway"))
    fig = Figure(figsize=(11, 3.1 * len(envs)), constrained_layout=True)
    FigureCanvasAgg(fig)
    axes = np.atleast_2d(fig.subplots(len(envs), 2, squeeze=False))
    for row, env_id in zip(axes, envs, strict=True):
        rows = seaway_rows(entries, env_id)
        names = [r["controller"] for r in rows]
        x = np.arange(len(names))
        for ax, key, label in (
            (row[0], seaway_error_key(env_id), None),
            (row[1], "rudder_travel_deg_min", "rudder travel [deg/min], log scale"),
        ):
            for shift, cond, hatch in ((-0.2, "calm", ""), (0.2, "seaway", "//")):
                stats = [r[cond].get(key) if r[cond] else None for r in rows]
                mean = np.array([s[0] if s else np.nan for s in stats])
                err = np.array([[s[0] - s[1] if s else 0.0 for s in stats],
                                [s[2] - s[0] if s else 0.0 for s in stats]])  # fmt: skip
                ax.bar(x + shift, mean, 0.4, yerr=err, capsize=2, hatch=hatch,
                       color=[_colour(n) for n in names], edgecolor="0.25", label=cond)  # fmt: skip
            ax.set_xticks(x, names, fontsize=8)
            ax.set_title(f"{env_id.split('/')[-1]}: {label or key}", fontsize=9)
            ax.grid(axis="y", alpha=0.3)
        row[1].set_yscale("log")
        row[0].legend(fontsize=8, title="plain: calm, hatched: at sea", title_fontsize=7)
    from shipgym.benchmark.runner import SEAWAY_HEIGHT, SEAWAY_WIND_SPEED

    fig.suptitle(
        f"seaway condition (H_s {SEAWAY_HEIGHT:g} m, wind {SEAWAY_WIND_SPEED:g} m/s, directions "
        "drawn per episode) against calm water; classic-wf: classic with the wave filter "
        "(calm: classic's bar)",
        fontsize=10,
    )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path


def plot_benchmark_trajectories(benchmark: Any, env_id: str, path: str | Path) -> Path:
    """The first episode of every controller on ``env_id``: track and key signal.

    One row per condition (nominal and stress); left the tracks (with the path or the
    target), right the task's error signal over time. All controllers start from the same
    seeded scenario.
    """
    conditions = [c for c in ("nominal", "stress") if c in benchmark.conditions]
    conditions = conditions or benchmark.conditions[:1]
    controllers = benchmark.controllers
    key, label, scale = _TASK_SIGNAL[env_task(env_id)]
    height = 4.8 * len(conditions)  # [in]; fixed margins (a constrained layout: +50 % time)
    fig = Figure(figsize=(13, height))
    FigureCanvasAgg(fig)
    fig.subplots_adjust(left=0.06, right=0.98, top=1 - 0.7 / height, bottom=0.5 / height,
                        wspace=0.2, hspace=0.3)  # fmt: skip
    axes = fig.subplots(len(conditions), 2, squeeze=False, width_ratios=(1.0, 1.3))
    for i, cond in enumerate(conditions):
        ax_track, ax_sig = axes[i]
        first = None
        for name in controllers:
            if not _has(benchmark, env_id, name, cond):
                continue
            log = benchmark.get(env_id, name, cond).logs[0]
            first = first or log
            state = np.asarray(log.state)
            x0 = log.reset_info["state"]
            north = np.concatenate(([x0[0]], state[:, 0]))
            east = np.concatenate(([x0[1]], state[:, 1]))
            ax_track.plot(east, north, color=_colour(name), lw=1.5, label=name)
            ax_sig.plot(
                log.time,
                log.signal(key) * scale,
                color=_colour(name),
                lw=1.2,
                label=f"{name}: return {log.episode_return:.0f}",
            )
        assert first is not None
        ax_track.plot(
            first.reset_info["state"][1], first.reset_info["state"][0], "ko", ms=5, label="start"
        )
        if "waypoints" in first.extras:
            wp = np.asarray(first.extras["waypoints"])
            ax_track.plot(wp[:, 1], wp[:, 0], "--s", color="0.4", ms=4, lw=1, label="path")
        if "target" in first.extras:
            tgt = np.asarray(first.extras["target"])
            ax_track.plot(tgt[:, 1], tgt[:, 0], color="#e67e22", lw=1.5, ls=":", label="target")
        speed = first.reset_info["current_speed"]
        direction = math.degrees(first.reset_info["current_direction"]) % 360
        ax_track.set_title(
            f"{cond}: seed {first.seed}, current {speed:.2f} m/s toward {direction:.0f} deg",
            fontsize=10,
        )
        ax_track.set_xlabel("east [m]")
        ax_track.set_ylabel("north [m]")
        ax_track.set_aspect("equal", adjustable="datalim")
        ax_track.grid(alpha=0.3)
        ax_track.legend(fontsize=8)
        ax_sig.axhline(0.0, color="k", lw=0.8)
        ax_sig.set_xlabel("time [s]")
        ax_sig.set_ylabel(label)
        ax_sig.grid(alpha=0.3)
        ax_sig.legend(fontsize=8)
    fig.suptitle(f"{env_id}: the same scenario for every controller", fontsize=12)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path


def plot_throughput(rows: list[dict[str, Any]], path: str | Path) -> Path:
    """Bars of PPO training steps/s relative to CartPole-v1, with the target line."""
    fig = Figure(figsize=(9, 3.8), constrained_layout=True)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    names = [r["env"].split("/")[-1] for r in rows]
    ratios = [r["ratio"] for r in rows]
    colours = ["0.6" if r["met"] is None else ("#2e8b57" if r["met"] else "#c0392b") for r in rows]
    ax.bar(names, ratios, color=colours)
    for k, r in enumerate(rows):
        ax.text(k, r["ratio"], f"{r['steps_per_s']:.0f}/s", ha="center", va="bottom", fontsize=8)
    targets = [r["target"] for r in rows if r["target"] is not None]
    if targets:
        ax.axhline(targets[0], color="k", ls="--", lw=1, label=f"target {targets[0]:g}")
        ax.legend(fontsize=8)
    ax.set_ylabel("PPO env steps/s relative to CartPole-v1")
    ax.tick_params(axis="x", labelsize=8)
    ax.grid(axis="y", alpha=0.3)
    ax.set_title("training throughput: same PPO settings, one process", fontsize=10)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path

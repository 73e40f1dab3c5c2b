"""Figures of an evaluation: the trajectory and the key signals of each episode."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from shipgym.benchmark.evaluate import HEADING_ENVS, EpisodeLog, EvaluationResult

_SIGNAL = {
    "shipgym/NomotoHeading-v0": ("heading_error", "heading error [deg]", math.degrees(1.0)),
    "shipgym/RVGHeading-v0": ("heading_error", "heading error [deg]", math.degrees(1.0)),
    "shipgym/RVGSpeed-v0": ("speed_error", "speed error [m/s]", 1.0),
    "shipgym/RVGPathFollowing-v0": ("cross_track_error", "cross-track error [m]", 1.0),
    "shipgym/RVGTargetTracking-v0": ("distance_error", "distance error [m]", 1.0),
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
    key, label, scale = _SIGNAL[result.env]
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
    fig.suptitle(
        f"{result.env}, controller {result.controller}: return {log.episode_return:.1f}",
        fontsize=12,
    )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def plot_result(result: EvaluationResult, out_dir: str | Path, max_episodes: int = 5) -> list[Path]:
    """Write one PNG per episode (the first ``max_episodes``) into ``out_dir``."""
    name = result.env.split("/")[-1]
    return [
        plot_episode(result, log, Path(out_dir) / f"{name}_{result.controller}_seed{log.seed}.png")
        for log in result.logs[:max_episodes]
    ]

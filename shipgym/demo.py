"""The ``shipgym demo``: a zigzag trial of a Nomoto ship and a path-following episode.

Two short jobs that show the package end to end on built-in defaults:

1. **Zigzag 20/20** of a Nomoto-family model (default ``nomoto1``, the Mariner class cargo ship
   of :mod:`shipgym.models.nomoto`) by :func:`shipgym.maneuvers.zigzag` (seed 000 logic).
2. **Path following** in ``shipgym/RVGPathFollowing-v1`` (R/V Gunnerus) along a fixed path in
   current, steered by the tuned classic controller of ``shipgym evaluate --controller
   classic-tuned`` (:func:`shipgym.benchmark.policies.make_policy`: lookahead LOS with the
   conditional integrator commanding the heading autopilot, and a speed autopilot on the pod
   thrust).

Each job writes a PNG; :func:`run_demo` runs both and returns the summary numbers.
Matplotlib is used through :class:`~matplotlib.figure.Figure` objects rendered by the Agg
canvas, so the global pyplot backend is never touched.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

import shipgym  # noqa: F401  (registers the environments)
from shipgym._io import write_atomically
from shipgym.benchmark.policies import make_policy
from shipgym.maneuvers import plot_zigzag, zigzag
from shipgym.models import NOMOTO_MODEL_NAMES
from shipgym.models.rvg import LPP, SERVICE_SPEED

__all__ = [
    "DEMO_WAYPOINTS",
    "PathEpisode",
    "format_summary",
    "path_following_episode",
    "plot_path_following",
    "run_demo",
]

PATH_ENV_ID = "shipgym/RVGPathFollowing-v1"
#: The demo path: (north, east) waypoints [m], five legs of 400-500 m with 39-51 deg turns.
DEMO_WAYPOINTS: tuple[tuple[float, float], ...] = (
    (0.0, 0.0),
    (400.0, 0.0),
    (700.0, 300.0),
    (700.0, 800.0),
    (400.0, 1100.0),
    (400.0, 1500.0),
)
#: Seed of the demo episode (initial offset and heading error drawn by the environment).
DEMO_SEED = 3
#: Current of the demo episode: speed [m/s] and direction the water moves toward [rad].
DEMO_CURRENT = (0.3, math.radians(135.0))
DEMO_MAX_AZIMUTH = math.radians(35.0)

_BLUE, _ORANGE, _GREEN, _RED, _GREY = "#1f5fa8", "#d9731a", "#2a8a4a", "#b8312f", "#6b6b6b"


# ------------------------------------------------------------------------------------------
# path following
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class PathEpisode:
    """One path-following episode.

    Attributes
    ----------
    waypoints : numpy.ndarray
        ``(m, 2)`` (north, east) [m].
    time : numpy.ndarray
        ``(n + 1,)`` [s].
    states : numpy.ndarray
        ``(n + 1, 10)`` RVG states (names in ``state_names``).
    actions : numpy.ndarray
        ``(n, 2)`` normalised actions.
    cross_track : numpy.ndarray
        ``(n + 1,)`` cross-track error [m] to the active leg.
    segment : numpy.ndarray
        ``(n + 1,)`` index of the active leg.
    completed : bool
        Reached the last waypoint.
    termination_reason : str
        As reported by the environment.
    current_speed, current_direction : float
        [m/s], [rad] (toward, clockwise from north).
    total_reward : float
        Sum of the rewards.
    """

    waypoints: np.ndarray
    time: np.ndarray
    states: np.ndarray
    actions: np.ndarray
    cross_track: np.ndarray
    segment: np.ndarray
    completed: bool
    termination_reason: str
    current_speed: float
    current_direction: float
    total_reward: float
    state_names: tuple[str, ...]

    def __getitem__(self, name: str) -> np.ndarray:
        """State column by name, e.g. ``episode["psi"]``."""
        return self.states[:, self.state_names.index(name)]

    @property
    def mean_abs_cross_track(self) -> float:
        """Mean absolute cross-track error [m]."""
        return float(np.mean(np.abs(self.cross_track)))


def path_following_episode(
    policy: Any | None = None,
    waypoints: Any = DEMO_WAYPOINTS,
    seed: int = DEMO_SEED,
    current: tuple[float, float] = DEMO_CURRENT,
) -> PathEpisode:
    """Run one ``shipgym/RVGPathFollowing-v1`` episode with ``policy``.

    Parameters
    ----------
    policy : object, optional
        A policy of :mod:`shipgym.benchmark.policies` (``reset(env, obs, info)``,
        ``act(obs, info)``); by default the classic LOS + heading and speed autopilots with
        the gains tuned on the env's ship (``shipgym evaluate --controller classic-tuned``).
    waypoints : array_like
        ``(m, 2)`` (north, east) waypoints [m], passed as the ``waypoints`` reset option.
    seed : int
        Reset seed (initial offset and heading error).
    current : (float, float)
        Current speed [m/s] and direction [rad].

    Returns
    -------
    PathEpisode
    """
    policy = make_policy("classic-tuned", PATH_ENV_ID) if policy is None else policy
    env = gym.make(PATH_ENV_ID)
    try:
        options = {
            "waypoints": np.asarray(waypoints, dtype=np.float64),
            "current_speed": float(current[0]),
            "current_direction": float(current[1]),
        }
        obs, info = env.reset(seed=seed, options=options)
        policy.reset(env.unwrapped, obs, info)
        dt = float(env.unwrapped.dt)
        limit = env.spec.max_episode_steps if env.spec and env.spec.max_episode_steps else 10_000
        states = np.empty((limit + 1, len(info["state"])))
        actions = np.empty((limit, 2))
        cross = np.empty(limit + 1)
        segment = np.empty(limit + 1, dtype=np.int64)
        states[0], cross[0], segment[0] = info["state"], info["cross_track_error"], info["segment"]
        total = 0.0
        n = 0
        done = False
        while not done and n < limit:
            action = policy.act(obs, info)
            obs, reward, terminated, truncated, info = env.step(action)
            actions[n] = action
            n += 1
            states[n], cross[n], segment[n] = (
                info["state"],
                info["cross_track_error"],
                info["segment"],
            )
            total += float(reward)
            done = terminated or truncated
        names = tuple(env.unwrapped.state_names)
    finally:
        env.close()
    return PathEpisode(
        waypoints=np.asarray(waypoints, dtype=np.float64),
        time=np.arange(n + 1) * dt,
        states=states[: n + 1],
        actions=actions[:n],
        cross_track=cross[: n + 1],
        segment=segment[: n + 1],
        completed=bool(info["completed"]),
        termination_reason=str(info["termination_reason"]),
        current_speed=float(info["current_speed"]),
        current_direction=float(info["current_direction"]),
        total_reward=total,
        state_names=names,
    )


def _hull(north: float, east: float, psi: float, length: float, beam: float) -> np.ndarray:
    """Plan-view hull polygon, columns (east, north)."""
    from shipgym.envs.rendering import hull_outline

    return hull_outline(north, east, psi, length, beam)


def plot_path_following(ep: PathEpisode, path: str | Path, hull_scale: float = 2.0) -> Path:
    """Top-down track with the path and waypoints, cross-track error and azimuth vs time."""
    north, east, psi = ep["x"], ep["y"], ep["psi"]
    wp = ep.waypoints
    t = ep.time
    fig = Figure(figsize=(13, 6.6), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(3, 2, width_ratios=(1.35, 1.0))
    ax = fig.add_subplot(grid[:, 0])
    ax_e = fig.add_subplot(grid[0, 1])
    ax_a = fig.add_subplot(grid[1, 1], sharex=ax_e)
    ax_u = fig.add_subplot(grid[2, 1], sharex=ax_e)

    # --- map: east to the right, north up -------------------------------------------------
    ax.plot(wp[:, 1], wp[:, 0], color=_GREY, lw=1.5, ls="--", label="path", zorder=2)
    ax.plot(wp[:, 1], wp[:, 0], "s", color="black", ms=6, zorder=4, label="waypoints")
    for k, (n_, e_) in enumerate(wp):
        ax.annotate(
            f"WP{k}",
            xy=(e_, n_),
            xytext=(-8, 8),
            textcoords="offset points",
            ha="right",
            fontsize=9,
            fontweight="bold",
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8},
        )
    ax.plot(east, north, color=_BLUE, lw=2.0, label="ship track", zorder=3)
    step = max(1, len(t) // 9)
    for i in [*range(0, len(t) - 1, step), len(t) - 1]:
        poly = _hull(north[i], east[i], psi[i], hull_scale * LPP, hull_scale * 9.6)
        ax.add_patch(Polygon(poly, closed=True, fc="#f2f2f2", ec=_BLUE, lw=1.0, zorder=5))
    ax.plot(
        [],
        [],
        marker=(3, 0, 0),
        ls="none",
        mfc="#f2f2f2",
        mec=_BLUE,
        label=f"ship outline ({hull_scale:g}x scale), every {step * (t[1] - t[0]):.0f} s",
    )
    ax.plot(east[0], north[0], "o", color=_GREEN, ms=7, zorder=6, label="start")
    ax.plot(east[-1], north[-1], "o", color=_RED, ms=7, zorder=6, label="end")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=8.5, framealpha=0.92)
    # current arrow in the upper-left corner (the direction the water moves toward)
    if ep.current_speed > 0:
        d = ep.current_direction
        ax.annotate(
            "",
            xy=(0.10 + 0.06 * math.sin(d), 0.92 + 0.06 * math.cos(d)),
            xytext=(0.10 - 0.06 * math.sin(d), 0.92 - 0.06 * math.cos(d)),
            xycoords="axes fraction",
            arrowprops={"arrowstyle": "-|>", "color": _GREEN, "lw": 2.0, "mutation_scale": 15},
        )
        ax.annotate(
            f"current\n{ep.current_speed:.1f} m/s toward {math.degrees(d) % 360:.0f}°",
            xy=(0.17, 0.92),
            xycoords="axes fraction",
            va="center",
            fontsize=8.5,
            color=_GREEN,
        )
    status = "completed" if ep.completed else f"not completed ({ep.termination_reason})"
    ax.set_title(f"R/V Gunnerus, {PATH_ENV_ID}: {status} in {t[-1]:.0f} s", fontsize=11)

    # --- time series ----------------------------------------------------------------------
    switches = t[1:][np.diff(ep.segment) != 0]
    for axis in (ax_e, ax_a, ax_u):
        for ts in switches:
            axis.axvline(ts, color=_GREY, lw=0.7, ls=":")
        axis.grid(True, alpha=0.3)
    ax_e.axhline(0.0, color="black", lw=0.6)
    ax_e.plot(t, ep.cross_track, color=_BLUE, lw=1.6, label="cross-track error e")
    ax_e.plot([], [], color=_GREY, lw=0.7, ls=":", label="switch to the next leg")
    ax_e.legend(loc="lower left", fontsize=8, framealpha=0.9)
    ax_e.set_ylabel("cross-track error\ne [m] (+ = stbd)")
    ax_e.set_title(
        f"mean |e| = {ep.mean_abs_cross_track:.1f} m, "
        f"max |e| = {np.max(np.abs(ep.cross_track)):.1f} m",
        fontsize=10,
    )
    alpha = np.degrees(ep["alpha1"])
    limit = math.degrees(DEMO_MAX_AZIMUTH)
    ax_a.axhline(0.0, color="black", lw=0.6)
    for level in (limit, -limit):
        ax_a.axhline(level, color=_GREY, lw=0.8, ls="--")
    ax_a.plot(t, alpha, color=_ORANGE, lw=1.4)
    ax_a.set_ylim(-1.2 * limit, 1.2 * limit)
    ax_a.set_ylabel("pod azimuth $\\alpha$ [deg]\n(+ = turn to port)")
    ax_u.plot(t, ep["u"], color=_GREEN, lw=1.4, label="surge speed u")
    ax_u.axhline(SERVICE_SPEED, color=_GREY, lw=0.8, ls="--", label="service speed")
    ax_u.set_ylabel("surge speed\nu [m/s]")
    lo, hi = min(float(ep["u"].min()), SERVICE_SPEED), max(float(ep["u"].max()), SERVICE_SPEED)
    ax_u.set_ylim(min(lo - 0.1, SERVICE_SPEED - 0.5), max(hi + 0.1, SERVICE_SPEED + 0.3))
    ax_u.set_xlabel("time [s]")
    ax_u.legend(loc="lower right", fontsize=8)
    ax_e.set_xlim(t[0], t[-1])
    for axis in (ax_e, ax_a):
        axis.tick_params(labelbottom=False)
    out = Path(path)
    fig.savefig(out)
    return out


# ------------------------------------------------------------------------------------------
# the demo
# ------------------------------------------------------------------------------------------
def run_demo(out_dir: str | Path = "shipgym-demo", model: str = "nomoto1") -> dict[str, Any]:
    """Run the zigzag and the path-following demo; write ``zigzag.png``, ``path_following.png``.

    Parameters
    ----------
    out_dir : str or Path
        Output directory (created if needed).
    model : {"nomoto1", "nomoto2", "norrbin", "bech"}
        Nomoto-family model of the zigzag.

    Returns
    -------
    dict
        ``zigzag_png``, ``path_following_png`` (paths), ``model``,
        ``first_overshoot_deg``, ``second_overshoot_deg``, ``overshoots_deg``,
        ``mean_abs_cross_track_m``, ``max_abs_cross_track_m``, ``completed``,
        ``episode_time_s``, ``termination_reason``.

    Raises
    ------
    ValueError
        For an unknown model or an output directory that cannot be created.
    """
    if model not in NOMOTO_MODEL_NAMES:
        raise ValueError(f"unknown demo model {model!r}; expected one of {NOMOTO_MODEL_NAMES}")
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"cannot create output directory {str(out)!r}: {exc.strerror}") from None
    zz = zigzag(model, a_deg=20.0)
    ep = path_following_episode()
    zz_png, pf_png = out / "zigzag.png", out / "path_following.png"
    write_atomically(
        [(zz_png, lambda p: plot_zigzag(zz, p)), (pf_png, lambda p: plot_path_following(ep, p))]
    )
    return {
        "model": model,
        "zigzag_png": str(zz_png),
        "path_following_png": str(pf_png),
        "first_overshoot_deg": zz.overshoots_deg[0],
        "second_overshoot_deg": zz.overshoots_deg[1],
        "overshoots_deg": list(zz.overshoots_deg),
        "mean_abs_cross_track_m": ep.mean_abs_cross_track,
        "max_abs_cross_track_m": float(np.max(np.abs(ep.cross_track))),
        "completed": ep.completed,
        "episode_time_s": float(ep.time[-1]),
        "termination_reason": ep.termination_reason,
    }


def format_summary(summary: dict[str, Any]) -> str:
    """Human-readable summary of :func:`run_demo`'s result."""
    return "\n".join(
        [
            f"zigzag 20/20 ({summary['model']}): first overshoot "
            f"{summary['first_overshoot_deg']:.1f} deg, second overshoot "
            f"{summary['second_overshoot_deg']:.1f} deg",
            f"path following ({PATH_ENV_ID.removeprefix('shipgym/')}): completed "
            f"{'yes' if summary['completed'] else 'no'} in {summary['episode_time_s']:.0f} s, "
            f"mean |cross-track| {summary['mean_abs_cross_track_m']:.1f} m "
            f"(max {summary['max_abs_cross_track_m']:.1f} m)",
            f"wrote {summary['zigzag_png']}",
            f"wrote {summary['path_following_png']}",
        ]
    )

"""The ``shipgym demo``: a zigzag trial of a Nomoto ship and a path-following episode.

Two short jobs that show the package end to end on built-in defaults:

1. **Zigzag 20/20** of a Nomoto-family model (default ``nomoto1``, the Mariner class cargo ship
   of :mod:`shipgym.models.nomoto`) simulated with :meth:`ShipModel.simulate
   <shipgym.models.base.ShipModel.simulate>` and the classic zigzag autopilot (seed 000) as a
   controller callback: rudder to +20 deg (starboard); when the heading has turned 20 deg to
   starboard of the initial heading, rudder to -20 deg; when it has turned 20 deg to port,
   rudder to +20 deg; and so on. The overshoot after each rudder reversal is the heading
   excursion beyond the 20 deg check heading.
2. **Path following** in ``shipgym/RVGPathFollowing-v0`` (R/V Gunnerus) along a fixed path,
   steered by :class:`LOSPathPolicy`: lookahead line-of-sight guidance and a PD heading law on
   the pod azimuth, with a proportional speed loop on the pod thrust.

Each job writes a PNG; :func:`run_demo` runs both and returns the summary numbers.
Matplotlib is used through :class:`~matplotlib.figure.Figure` objects rendered by the Agg
canvas, so the global pyplot backend is never touched.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

import shipgym  # noqa: F401  (registers the environments)
from shipgym.models import NOMOTO_MODEL_NAMES, SimulationResult, make_model, ssa
from shipgym.models.rvg import LPP, SERVICE_SPEED, RVGParams

__all__ = [
    "DEMO_WAYPOINTS",
    "LOSPathPolicy",
    "PathEpisode",
    "ZigZagPilot",
    "ZigZagResult",
    "path_following_episode",
    "plot_path_following",
    "plot_zigzag",
    "run_demo",
    "zigzag",
]

PATH_ENV_ID = "shipgym/RVGPathFollowing-v0"
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

_MODEL_LABELS = {
    "nomoto1": "first-order Nomoto",
    "nomoto2": "second-order Nomoto",
    "norrbin": "Norrbin",
    "bech": "Bech",
}
_BLUE, _ORANGE, _GREEN, _RED, _GREY = "#1f5fa8", "#d9731a", "#2a8a4a", "#b8312f", "#6b6b6b"


# ------------------------------------------------------------------------------------------
# zigzag
# ------------------------------------------------------------------------------------------
class ZigZagPilot:
    """The zigzag autopilot of seed 000 as a ``(t, x) -> u`` callback for ``simulate``.

    Parameters
    ----------
    angle : float
        Rudder angle and check heading change [rad] (20/20 zigzag: both 20 deg).
    psi0 : float
        Initial heading [rad]; the check headings are ``psi0 +- angle``.
    shaft_speed : float
        Shaft speed command [rev/s], held constant.
    ipsi : int
        Column of the heading in the state vector.

    Attributes
    ----------
    reversal_times : list of float
        Times [s] at which the rudder command was reversed.
    """

    def __init__(self, angle: float, psi0: float, shaft_speed: float, ipsi: int) -> None:
        if not (math.isfinite(angle) and angle > 0):
            raise ValueError(f"zigzag angle must be a finite angle > 0 rad, got {angle!r}")
        self.angle = float(angle)
        self.psi0 = float(psi0)
        self.shaft_speed = float(shaft_speed)
        self.ipsi = ipsi
        self.sign = 1.0
        self.reversal_times: list[float] = []

    def __call__(self, t: float, x: np.ndarray) -> tuple[float, float]:
        turned = float(ssa(x[self.ipsi] - self.psi0))
        if (self.sign > 0 and turned >= self.angle) or (self.sign < 0 and turned <= -self.angle):
            self.sign = -self.sign
            self.reversal_times.append(float(t))
        return (self.sign * self.angle, self.shaft_speed)


@dataclass(frozen=True, eq=False)
class ZigZagResult:
    """A simulated zigzag trial.

    Attributes
    ----------
    model : str
        Model name.
    angle_deg : float
        Rudder angle and check heading change [deg].
    result : SimulationResult
        The trajectory, cropped after the last complete overshoot.
    reversal_times : tuple of float
        Times of the rudder reversals [s].
    overshoots_deg : tuple of float
        Overshoot after each reversal [deg] (first, second, ...).
    overshoot_times : tuple of float
        Times [s] at which each overshoot peaks.
    """

    model: str
    angle_deg: float
    result: SimulationResult
    reversal_times: tuple[float, ...]
    overshoots_deg: tuple[float, ...]
    overshoot_times: tuple[float, ...]
    psi0: float = 0.0


def zigzag(
    model: str = "nomoto1",
    angle_deg: float = 20.0,
    dt: float = 0.1,
    max_duration: float = 4000.0,
    n_overshoots: int = 4,
) -> ZigZagResult:
    """Simulate a zigzag ``angle_deg/angle_deg`` trial of a Nomoto-family model.

    The ship starts on a straight course at its service speed (shaft speed held at the
    service value of :class:`~shipgym.models.nomoto.SurgeModel`), heading north.

    Parameters
    ----------
    model : {"nomoto1", "nomoto2", "norrbin", "bech"}
        Model name (default parameters).
    angle_deg : float
        Rudder angle and heading check angle [deg].
    dt : float
        Integration step [s]; the rudder reversal happens at the first step past the check.
    max_duration : float
        Longest simulated time [s].
    n_overshoots : int
        Number of overshoots to measure; the trajectory is cropped after the last one.

    Returns
    -------
    ZigZagResult

    Raises
    ------
    ValueError
        For a model outside the Nomoto family, a bad angle, or when the ship does not
        complete ``n_overshoots`` overshoots within ``max_duration``.
    """
    if model not in NOMOTO_MODEL_NAMES:
        raise ValueError(f"zigzag model must be one of {NOMOTO_MODEL_NAMES}, got {model!r}")
    if not (math.isfinite(angle_deg) and 0 < angle_deg <= 35):
        raise ValueError(f"zigzag angle must be in (0, 35] deg, got {angle_deg!r}")
    ship = make_model(model)
    assert ship.surge is not None
    x0 = np.zeros(ship.nx)
    x0[ship.index("U")] = ship.surge.service_speed
    ipsi = ship.index("psi")
    pilot = ZigZagPilot(math.radians(angle_deg), 0.0, ship.surge.service_shaft_speed, ipsi)
    n_steps = math.ceil(max_duration / dt)
    res = ship.simulate(x0, pilot, dt, n_steps)
    reversals = pilot.reversal_times
    if len(reversals) < n_overshoots + 1:
        raise ValueError(
            f"model {model!r} made {len(reversals)} rudder reversals in {max_duration:g} s; "
            f"{n_overshoots + 1} are needed to measure {n_overshoots} overshoots"
        )
    psi_deg = np.degrees(res["psi"])
    overshoots, peak_times = [], []
    for k in range(n_overshoots):
        window = (res.time >= reversals[k]) & (res.time <= reversals[k + 1])
        seg = psi_deg[window]
        # Reversal k (0-based) happens at +angle for even k, at -angle for odd k.
        if k % 2 == 0:
            j = int(np.argmax(seg))
            overshoots.append(float(seg[j] - angle_deg))
        else:
            j = int(np.argmin(seg))
            overshoots.append(float(-angle_deg - seg[j]))
        peak_times.append(float(res.time[window][j]))
    end = int(np.searchsorted(res.time, reversals[n_overshoots])) + 1
    cropped = SimulationResult(
        res.time[: end + 1],
        res.states[: end + 1],
        res.inputs[:end],
        res.state_names,
        res.input_names,
    )
    return ZigZagResult(
        model,
        float(angle_deg),
        cropped,
        tuple(reversals[: n_overshoots + 1]),
        tuple(overshoots),
        tuple(peak_times),
    )


def plot_zigzag(zz: ZigZagResult, path: str | Path) -> Path:
    """Plot heading and rudder angle against time with the overshoots marked; write a PNG."""
    res = zz.result
    t = res.time
    psi = np.degrees(res["psi"])
    delta = np.degrees(res["delta"])
    cmd = np.degrees(res["delta_c"])
    a = zz.angle_deg

    fig = Figure(figsize=(10, 5.6), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.axhline(0.0, color="black", lw=0.6)
    for level in (a, -a):
        ax.axhline(level, color=_GREY, lw=0.8, ls=":")
    ax.plot(t, psi, color=_BLUE, lw=2.0, label=r"heading change $\psi - \psi_0$")
    ax.plot(
        t[:-1], cmd, color=_ORANGE, lw=1.0, ls="--", alpha=0.8, label=r"rudder command $\delta_c$"
    )
    ax.plot(t, delta, color=_ORANGE, lw=1.8, label=r"rudder angle $\delta$")
    for i, tr in enumerate(zz.reversal_times):
        ax.axvline(tr, color=_GREY, lw=0.6, alpha=0.5, label="rudder reversal" if i == 0 else None)

    span = max(np.abs(psi).max(), a) * 1.0
    for k, (ov, tp) in enumerate(zip(zz.overshoots_deg, zz.overshoot_times, strict=True)):
        up = k % 2 == 0
        check = a if up else -a
        peak = check + ov if up else check - ov
        ax.annotate(
            "",
            xy=(tp, peak),
            xytext=(tp, check),
            arrowprops={"arrowstyle": "<->", "color": _RED, "lw": 1.3, "shrinkA": 0, "shrinkB": 0},
        )
        ax.plot([tp], [peak], "o", color=_RED, ms=4)
        ordinal = ("1st", "2nd", "3rd", "4th", "5th", "6th")[k] if k < 6 else f"{k + 1}th"
        ax.annotate(
            f"{ordinal} overshoot\n{ov:.1f}°",
            xy=(tp, peak),
            xytext=(8, 6 if up else -6),
            textcoords="offset points",
            ha="left",
            va="bottom" if up else "top",
            fontsize=9,
            color=_RED,
        )
    ax.set_ylim(-1.25 * span, 1.25 * span)
    ax.set_xlim(t[0], t[-1])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("angle [deg]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower left", fontsize=9, framealpha=0.9)
    ship = make_model(zz.model)
    assert ship.surge is not None
    ax.set_title(
        f"Zigzag {a:g}/{a:g}: Mariner class cargo ship, {_MODEL_LABELS[zz.model]} model "
        f"({zz.model}), U = {ship.surge.service_speed:.1f} m/s",
        fontsize=11,
    )
    # the check headings, labelled at the right edge
    for level in (a, -a):
        ax.annotate(
            f"{level:+g}°",
            xy=(1.0, level),
            xycoords=("axes fraction", "data"),
            xytext=(3, 0),
            textcoords="offset points",
            va="center",
            fontsize=8,
            color=_GREY,
        )
    out = Path(path)
    fig.savefig(out)
    return out


# ------------------------------------------------------------------------------------------
# path following
# ------------------------------------------------------------------------------------------
@dataclass
class LOSPathPolicy:
    """Lookahead LOS guidance with a PD heading law for ``shipgym/RVGPathFollowing-v0``.

    Guidance (seed 004, lookahead LOS): ``chi_d = chi_p + atan(-e / Delta)`` with ``e`` the
    cross-track error (positive to starboard of the path) and ``Delta`` the lookahead
    distance. Heading law: the heading error ``e_psi = ssa(chi_d - psi)`` sets a desired yaw
    rate ``r_d = sat(kp / kd e_psi, r_max)`` and the azimuth command is ``alpha_c = kd (r -
    r_d)``; below the yaw-rate limit this is the PD law ``alpha_c = -(kp e_psi - kd r)``.
    The signs follow the pods: a positive azimuth on the aft pods turns the ship to port.
    The yaw-rate limit matters: the RVG model is directionally unstable at service speed,
    and once it swings faster than about 2 deg/s even full opposite azimuth checks the swing
    only slowly. Speed: ``T_c = T_service + k_u (U_service - u)`` per pod, so the pods push
    harder (and steer harder) when the ship slows down in a turn.

    Attributes
    ----------
    lookahead : float
        ``Delta`` [m] (3 ship lengths).
    kp : float
        Heading gain [rad of azimuth per rad].
    kd : float
        Yaw-rate gain [rad of azimuth per rad/s].
    max_yaw_rate : float
        ``r_max`` [rad/s].
    speed_gain : float
        ``k_u`` [N per m/s].
    service_speed, service_thrust, bollard_thrust, max_azimuth : float
        Speed [m/s] and thrust [N] targets, the action scaling of the environment.
    """

    lookahead: float = 3.0 * LPP
    kp: float = 3.0
    kd: float = 30.0
    max_yaw_rate: float = 0.03
    speed_gain: float = 1.0e5
    service_speed: float = SERVICE_SPEED
    service_thrust: float = field(default_factory=lambda: RVGParams().service_thrust)
    bollard_thrust: float = field(default_factory=lambda: RVGParams().bollard_thrust)
    max_azimuth: float = DEMO_MAX_AZIMUTH

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """Action ``[azimuth, thrust]`` in [-1, 1] for one observation."""
        e, path_minus_psi, _, _, u, _, r = (float(v) for v in obs[:7])
        heading_error = float(ssa(path_minus_psi + math.atan(-e / self.lookahead)))
        r_d = min(max(self.kp / self.kd * heading_error, -self.max_yaw_rate), self.max_yaw_rate)
        alpha = self.kd * (r - r_d)
        thrust = self.service_thrust + self.speed_gain * (self.service_speed - u)
        half = 0.5 * self.bollard_thrust  # the env maps a in [-1, 1] to thrust half (1 + a)
        action = np.array([alpha / self.max_azimuth, thrust / half - 1.0], dtype=np.float32)
        return np.clip(action, -1.0, 1.0)


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
    policy: LOSPathPolicy | None = None,
    waypoints: Any = DEMO_WAYPOINTS,
    seed: int = DEMO_SEED,
    current: tuple[float, float] = DEMO_CURRENT,
) -> PathEpisode:
    """Run one ``shipgym/RVGPathFollowing-v0`` episode with ``policy`` (default LOS + PD).

    Parameters
    ----------
    policy : LOSPathPolicy, optional
        Maps an observation to an action.
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
    policy = LOSPathPolicy() if policy is None else policy
    env = gym.make(PATH_ENV_ID, max_azimuth=policy.max_azimuth)
    try:
        options = {
            "waypoints": np.asarray(waypoints, dtype=np.float64),
            "current_speed": float(current[0]),
            "current_direction": float(current[1]),
        }
        obs, info = env.reset(seed=seed, options=options)
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
            action = policy(obs)
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
    zz = zigzag(model)
    zz_png = plot_zigzag(zz, out / "zigzag.png")
    ep = path_following_episode()
    pf_png = plot_path_following(ep, out / "path_following.png")
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
            f"path following (RVGPathFollowing-v0): completed "
            f"{'yes' if summary['completed'] else 'no'} in {summary['episode_time_s']:.0f} s, "
            f"mean |cross-track| {summary['mean_abs_cross_track_m']:.1f} m "
            f"(max {summary['max_abs_cross_track_m']:.1f} m)",
            f"wrote {summary['zigzag_png']}",
            f"wrote {summary['path_following_png']}",
        ]
    )

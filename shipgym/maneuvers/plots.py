"""Figures of the trials: zigzag, turning circle, pull-out, spiral and the IMO criteria.

Each function draws one trial's result as a PNG with :class:`matplotlib.figure.Figure` and the
Agg canvas (no pyplot state): the zigzag's heading and rudder with its overshoots, the turning
circle's track with advance, transfer and diameters (seed 002 Fig. 1) and its three phases
(seed 002 Table 1), the pull-out's yaw rate, the spiral's delta-r curve (seed 004 Fig. 1) and
each MSC.137(76) criterion as value over limit.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from shipgym.maneuvers._common import crossing, side_sign, value_at, wind_text
from shipgym.maneuvers.imo import IMOReport
from shipgym.maneuvers.particulars import ShipParticulars
from shipgym.maneuvers.pullouts import PullOutResult
from shipgym.maneuvers.spirals import SpiralResult
from shipgym.maneuvers.turning import TurningResult
from shipgym.maneuvers.zigzags import ZigZagResult
from shipgym.models.seaway_options import Wind

__all__ = ["plot_imo", "plot_pullout", "plot_spiral", "plot_turning_circle", "plot_zigzag"]


_BLUE, _ORANGE, _GREEN, _RED, _GREY, _PURPLE = (
    "#1f5fa8",
    "#d9731a",
    "#2a8a4a",
    "#b8312f",
    "#6b6b6b",
    "#7b4fa0",
)


_MODEL_LABELS = {
    "nomoto1": "first-order Nomoto",
    "nomoto2": "second-order Nomoto",
    "norrbin": "Norrbin",
    "bech": "Bech",
    "rvg3dof": "3-DOF MCSim",
    "kvlcc2": "MMG KVLCC2",
    "vmm": "VMM",
}


def _new_figure(size: tuple[float, float]) -> Figure:
    fig = Figure(figsize=size, dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _title(model: str, particulars: ShipParticulars, what: str, wind: Wind | None) -> str:
    """The title of a trial's figure (the wind, if any, on a line of its own)."""
    title = f"{what}: {particulars.vessel}, {_MODEL_LABELS.get(model, model)} model ({model})"
    return title if wind is None else f"{title}\nin a {wind_text(wind)}"


def _save(fig: Figure, path: str | Path) -> Path:
    out = Path(path)
    fig.savefig(out)
    return out


def _rudder_label(model: str) -> str:
    if model == "rvg3dof":
        return r"equivalent rudder $\delta = -\alpha$"
    return r"rudder angle $\delta$"


def plot_zigzag(result: ZigZagResult, path: str | Path) -> Path:
    """Heading change and rudder angle against time with the overshoots marked; a PNG.

    When the heading change dwarfs the rudder angle (an unstable ship), the rudder is drawn
    on its own axis at the right. A swing that was never checked is shown until it has gone a
    full circle beyond the check heading.
    """
    sr = result.series
    t = sr.time
    h = np.degrees(sr.psi - sr.psi[0])
    delta = np.degrees(sr.delta)
    cmd = np.degrees(sr.delta_c)
    a, b = math.degrees(result.rudder), math.degrees(result.heading_check)
    s0 = side_sign(result.first)
    n = len(t)
    if not result.completed and result.execute_times:
        k = len(result.overshoots) - 1 if result.overshoots else 0
        s_k = s0 if k % 2 == 0 else -s0
        t_k = result.execute_times[min(k, len(result.execute_times) - 1)]
        beyond = np.nonzero((t >= t_k) & (s_k * h - b > 360.0))[0]
        if len(beyond):
            n = min(n, int(beyond[0]) + 1)
    t, h, delta, cmd = t[:n], h[:n], delta[:n], cmd[:n]

    fig = _new_figure((10.5, 5.8))
    ax = fig.add_subplot()
    span = max(float(np.max(np.abs(h))), a, b)
    separate = span > 3.0 * max(a, b)
    ax_d = ax.twinx() if separate else ax
    ax.axhline(0.0, color="black", lw=0.6)
    for level in (b, -b):
        ax.axhline(level, color=_GREY, lw=0.8, ls=":")
    ax.plot(t, h, color=_BLUE, lw=2.0, label=r"heading change $\psi - \psi_0$", zorder=3)
    rudder = _rudder_label(result.model) + (" (right axis)" if separate else "")
    ax_d.plot(t, cmd, color=_ORANGE, lw=1.0, ls="--", alpha=0.8, label=r"rudder command $\delta_c$")
    ax_d.plot(t, delta, color=_ORANGE, lw=1.8, label=rudder)
    for i, te in enumerate(result.execute_times):
        ax.axvline(te, color=_GREY, lw=0.6, alpha=0.6, label="rudder reversal" if i == 0 else None)
    for k, (ov, tp) in enumerate(zip(result.overshoots_deg, result.overshoot_times, strict=True)):
        if not math.isfinite(ov):
            continue
        s = s0 if k % 2 == 0 else -s0
        check = s * b
        peak = check + s * ov
        ax.annotate(
            "",
            xy=(tp, peak),
            xytext=(tp, check),
            arrowprops={"arrowstyle": "<->", "color": _RED, "lw": 1.3, "shrinkA": 0, "shrinkB": 0},
        )
        ax.plot([tp], [peak], "o", color=_RED, ms=4)
        ordinal = ("1st", "2nd", "3rd")[k] if k < 3 else f"{k + 1}th"
        near_end = tp > t[0] + 0.85 * (t[-1] - t[0])
        ax.annotate(
            f"{ordinal} overshoot\n{ov:.1f}°",
            xy=(tp, peak),
            xytext=(-7 if near_end else 7, 5 * s),
            textcoords="offset points",
            ha="right" if near_end else "left",
            va="bottom" if s > 0 else "top",
            fontsize=9,
            color=_RED,
        )
    ax.set_ylim(-1.3 * span, 1.3 * span)
    if separate:
        ax_d.set_ylim(-1.3 * 3.0 * a, 1.3 * 3.0 * a)
        ax_d.set_ylabel("rudder angle [deg]", color=_ORANGE)
        ax_d.tick_params(axis="y", colors=_ORANGE)
    ax.set_xlim(t[0], t[-1])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("heading change [deg]" if separate else "angle [deg]")
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if separate:
        h2, l2 = ax_d.get_legend_handles_labels()
        handles, labels = handles + h2, labels + l2
    ax.legend(handles, labels, loc="lower left", fontsize=8.5, framealpha=0.92, ncols=2)
    for level in (b, -b):
        ax.annotate(
            f"check {level:+g}°",
            xy=(1.0, level),
            xycoords=("axes fraction", "data"),
            xytext=(-4, 2 if level > 0 else -2),
            textcoords="offset points",
            ha="right",
            va="bottom" if level > 0 else "top",
            fontsize=7.5,
            color=_GREY,
        )
    lines = [
        f"initial turning time {result.initial_turning_time:.1f} s",
        f"time to check yaw {result.time_to_check_yaw:.1f} s",
    ]
    if math.isfinite(result.period):
        lines.append(f"period {result.period:.1f} s")
    if not result.completed:
        lines.append("last swing NOT checked: the ship keeps turning")
    ax.text(
        0.99,
        0.98,
        "\n".join(lines),
        transform=ax.transAxes,
        ha="right",
        va="top",
        fontsize=8.5,
        bbox={"boxstyle": "round,pad=0.35", "fc": "white", "ec": _GREY, "alpha": 0.92},
        zorder=10,
    )
    ax.set_title(
        _title(
            result.model,
            result.particulars,
            f"Zigzag {result.label} ({result.first} first)",
            result.wind,
        )
        + f", U = {result.approach_speed:.2f} m/s",
        fontsize=11,
    )
    return _save(fig, path)


def _hull(north: float, east: float, psi: float, length: float, beam: float) -> np.ndarray:
    """Plan-view hull outline, columns (east, north)."""
    fwd = np.array([0.5, 0.3, -0.45, -0.5, -0.5, -0.45, 0.3]) * length
    stb = np.array([0.0, 0.5, 0.5, 0.4, -0.4, -0.5, -0.5]) * beam
    c, s = math.cos(psi), math.sin(psi)
    return np.column_stack([east + fwd * s + stb * c, north + fwd * c - stb * s])


def _dimension(
    ax: Any,
    p0: tuple[float, float],
    p1: tuple[float, float],
    text: str,
    color: str,
    offset: tuple[float, float] = (0, 0),
    rotation: float = 0.0,
) -> None:
    """A two-headed dimension arrow between (east, north) points with a label."""
    ax.annotate(
        "",
        xy=p1,
        xytext=p0,
        arrowprops={
            "arrowstyle": "<|-|>",
            "color": color,
            "lw": 1.4,
            "shrinkA": 0,
            "shrinkB": 0,
            "mutation_scale": 10,
        },
        zorder=6,
    )
    mid = (0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1]))
    ax.annotate(
        text,
        xy=mid,
        xytext=offset,
        textcoords="offset points",
        ha="center",
        va="center",
        rotation=rotation,
        fontsize=9,
        color=color,
        fontweight="bold",
        bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
        zorder=7,
    )


def plot_turning_circle(result: TurningResult, path: str | Path) -> Path:
    """Track with advance, transfer, tactical and steady diameter; r, speed, rudder vs time."""
    sr = result.series
    L = result.particulars.length
    s = side_sign(result.side)
    east, north = sr.y, sr.x
    h = s * (sr.psi - sr.psi[0])
    fig = _new_figure((13.0, 6.8))
    grid = fig.add_gridspec(3, 2, width_ratios=(1.25, 1.0))
    ax = fig.add_subplot(grid[:, 0])
    ax_r = fig.add_subplot(grid[0, 1])
    ax_v = fig.add_subplot(grid[1, 1], sharex=ax_r)
    ax_d = fig.add_subplot(grid[2, 1], sharex=ax_r)

    # --- track ---------------------------------------------------------------------------
    first = np.nonzero(h <= 2 * math.pi)[0]
    n_first = int(first[-1]) + 1 if len(first) else len(h)
    ax.plot(
        east[n_first - 1 :],
        north[n_first - 1 :],
        color=_BLUE,
        lw=0.8,
        alpha=0.35,
        label="track after the first 360°",
    )
    ax.plot(east[:n_first], north[:n_first], color=_BLUE, lw=2.0, label="track (first 360°)")
    cn, ce = result.steady_center
    ax.add_patch(
        Circle(
            (ce, cn),
            0.5 * result.steady_diameter,
            fill=False,
            ec=_PURPLE,
            lw=1.3,
            ls="--",
            zorder=4,
        )
    )
    ax.plot(
        [],
        [],
        color=_PURPLE,
        lw=1.3,
        ls="--",
        label=f"steady circle, D = {result.steady_diameter:.0f} m "
        f"({result.steady_diameter / L:.2f} L)",
    )
    hull_len, hull_beam = L, result.particulars.beam
    for target in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi):
        cross = crossing(h, target)
        if cross is None:
            continue
        hull_n, hull_e, hull_psi = (value_at(v, cross) for v in (north, east, sr.psi))
        poly = _hull(hull_n, hull_e, hull_psi, hull_len, hull_beam)
        ax.add_patch(
            Polygon(poly, closed=True, fc="#e3e9f2", ec="#8aa6c9", lw=0.8, alpha=0.7, zorder=1.5)
        )
    ax.plot(
        [],
        [],
        marker=(5, 0, 0),
        ls="none",
        mfc="#e3e9f2",
        mec="#8aa6c9",
        label="hull (true scale) at 0, 90, 180, 270°",
    )
    n0, e0 = result.points["execute"]
    n90, e90 = result.points["heading_90"]
    n180, e180 = result.points["heading_180"]
    # approach course line
    extent = max(result.advance, result.tactical_diameter, result.steady_diameter, L)
    ax.plot(
        [e0, e0],
        [n0 - 0.35 * extent, n0 + 1.15 * result.advance],
        color=_GREY,
        lw=0.8,
        ls="-.",
        zorder=1,
    )
    ax.plot(
        [e0, e0], [n0 - 0.35 * extent, n0], color=_GREY, lw=2.0, zorder=2, label="approach course"
    )
    ax.plot([e0], [n0], "o", color=_GREEN, ms=7, zorder=8, label="rudder execute")
    for (n_, e_), lab in (((n90, e90), "90°"), ((n180, e180), "180°")):
        ax.plot([e_], [n_], "D", color=_RED, ms=5, zorder=8)
        ax.annotate(
            lab,
            xy=(e_, n_),
            xytext=(6 * s, 6),
            textcoords="offset points",
            fontsize=8.5,
            color=_RED,
            ha="left" if s > 0 else "right",
        )
    # advance: along the approach course, at the 90 deg point's lateral offset (outside)
    pad = 0.12 * extent
    e_adv = e0 - s * pad
    ax.plot([e_adv - s * 0.03 * extent, e90], [n90, n90], color=_RED, lw=0.6, ls=":")
    _dimension(
        ax,
        (e_adv, n0),
        (e_adv, n90),
        f"advance\n{result.advance:.0f} m\n{result.advance / L:.2f} L",
        _RED,
        offset=(-34 * s, 0),
    )
    # transfer: across, at the 90 deg point's north
    n_tr = n90 + pad
    ax.plot([e90, e90], [n90, n_tr + 0.03 * extent], color=_RED, lw=0.6, ls=":")
    _dimension(
        ax,
        (e0, n_tr),
        (e90, n_tr),
        f"transfer {result.transfer:.0f} m ({result.transfer / L:.2f} L)",
        _RED,
        offset=(0, 11),
    )
    # tactical diameter: across at the 180 deg point, below the track
    n_td = min(float(np.min(north[:n_first])), n180) - pad
    ax.plot([e180, e180], [n180, n_td - 0.03 * extent], color=_ORANGE, lw=0.6, ls=":")
    ax.plot([e0, e0], [n0, n_td - 0.03 * extent], color=_ORANGE, lw=0.6, ls=":")
    _dimension(
        ax,
        (e0, n_td),
        (e180, n_td),
        f"tactical diameter {result.tactical_diameter:.0f} m"
        f" ({result.tactical_diameter / L:.2f} L)",
        _ORANGE,
        offset=(0, -11),
    )
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.09), ncols=3, fontsize=8, framealpha=0.92)
    ax.margins(0.08)
    ax.set_title(
        f"{math.degrees(result.rudder):g}° rudder to {result.side}, approach "
        f"{result.approach_speed:.2f} m/s, L = {L:g} m",
        fontsize=10,
    )

    # --- time histories (seed 002 phases) -------------------------------------------------
    t = sr.time
    t_end = min(t[-1], max(3.0 * result.steady_time, result.time_to_180 * 2.5, 60.0))
    for axis in (ax_r, ax_v, ax_d):
        axis.axvspan(0.0, result.rudder_time, color=_ORANGE, alpha=0.10, lw=0)
        axis.axvspan(result.rudder_time, result.steady_time, color=_BLUE, alpha=0.06, lw=0)
        axis.axvspan(result.steady_time, t_end, color=_GREEN, alpha=0.08, lw=0)
        axis.grid(True, alpha=0.3)
    ax_r.plot(t, np.degrees(sr.r), color=_BLUE, lw=1.6)
    ax_r.axhline(math.degrees(result.steady_yaw_rate), color=_GREY, lw=0.8, ls="--")
    ax_r.set_ylabel("yaw rate r\n[deg/s]")
    for t0_, t1_, lab in (
        (0.0, result.rudder_time, "1st"),
        (result.rudder_time, result.steady_time, "2nd phase"),
        (result.steady_time, t_end, "3rd phase (steady)"),
    ):
        if t1_ - t0_ < 0.06 * t_end * (len(lab) / 3):
            continue  # too narrow for its label
        x_ = 0.5 * (t0_ + t1_)
        ax_r.annotate(
            lab,
            xy=(x_, 0.1 if s > 0 else 0.9),
            xycoords=("data", "axes fraction"),
            ha="center",
            va="center",
            fontsize=8,
            color=_GREY,
        )
    ax_v.plot(t, sr.speed, color=_GREEN, lw=1.6)
    ax_v.axhline(result.approach_speed, color=_GREY, lw=0.8, ls="--")
    ax_v.set_ylabel("speed [m/s]")
    ax_v.set_title(
        f"steady speed {result.steady_speed:.2f} m/s = {100 * result.speed_ratio:.0f} % of "
        f"approach, steady r = {math.degrees(result.steady_yaw_rate):+.2f} deg/s",
        fontsize=9,
    )
    ax_v.set_ylim(0.0, 1.1 * max(result.approach_speed, float(np.max(sr.speed))))
    ax_d.plot(t, np.degrees(sr.delta), color=_ORANGE, lw=1.6)
    ax_d.set_ylabel(
        _rudder_label(result.model).replace("equivalent rudder", "equiv. rudder") + "\n[deg]"
    )
    ax_d.set_xlabel("time [s]")
    ax_r.set_xlim(0.0, t_end)
    for axis in (ax_r, ax_v):
        axis.tick_params(labelbottom=False)
    ax_r.set_title("phases (seed 002): 1st rudder moving, 2nd transient, 3rd steady", fontsize=9)
    fig.suptitle(
        _title(result.model, result.particulars, "Turning circle", result.wind), fontsize=11.5
    )
    return _save(fig, path)


def plot_pullout(result: PullOutResult, path: str | Path) -> Path:
    """Yaw rate (and rudder) against time around the pull-out; a PNG."""
    sr = result.series
    t = sr.time
    fig = _new_figure((10.5, 6.0))
    grid = fig.add_gridspec(2, 1, height_ratios=(2.2, 1.0))
    ax = fig.add_subplot(grid[0])
    ax_d = fig.add_subplot(grid[1], sharex=ax)
    r = np.degrees(sr.r)
    ax.axhline(0.0, color="black", lw=0.6)
    ax.axvline(result.pullout_time, color=_GREY, lw=1.0, ls="--")
    ax.plot(t, r, color=_BLUE, lw=1.8, label="yaw rate r")
    ax.axhline(
        math.degrees(result.turn_yaw_rate),
        color=_GREY,
        lw=0.8,
        ls=":",
        label=f"steady turn {math.degrees(result.turn_yaw_rate):+.3f} deg/s",
    )
    res = math.degrees(result.residual_yaw_rate)
    ax.axhline(res, color=_RED, lw=1.2, ls="--", label=f"residual {res:+.4f} deg/s")
    ax.annotate(
        "rudder amidships",
        xy=(result.pullout_time, 0.0),
        xytext=(5, 8),
        textcoords="offset points",
        fontsize=8.5,
        color=_GREY,
    )
    verdict = (
        "stable: r decays to zero" if result.stable else "UNSTABLE: residual yaw rate (spiral loop)"
    )
    extra = (
        f", decay to 1/e in {result.decay_time:.0f} s"
        if result.stable and math.isfinite(result.decay_time)
        else ""
    )
    ax.set_title(
        _title(
            result.model,
            result.particulars,
            f"Pull-out after {math.degrees(result.rudder):g}° to {result.side}",
            result.wind,
        )
        + f"\n{verdict}{extra}",
        fontsize=11,
    )
    ax.set_ylabel("yaw rate r [deg/s]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8.5, framealpha=0.92)
    ax.tick_params(labelbottom=False)
    ax_d.axhline(0.0, color="black", lw=0.6)
    ax_d.axvline(result.pullout_time, color=_GREY, lw=1.0, ls="--")
    ax_d.plot(t, np.degrees(sr.delta), color=_ORANGE, lw=1.6)
    ax_d.set_ylabel(
        _rudder_label(result.model).replace("equivalent rudder", "equiv. rudder") + "\n[deg]"
    )
    ax_d.set_xlabel("time [s]")
    ax_d.grid(True, alpha=0.3)
    ax.set_xlim(t[0], t[-1])
    return _save(fig, path)


def plot_spiral(results: SpiralResult | Sequence[SpiralResult], path: str | Path) -> Path:
    """The steady delta-r curve of one or more spirals (seed 004 Fig. 1); a PNG."""
    items = [results] if isinstance(results, SpiralResult) else list(results)
    if not items:
        raise ValueError("plot_spiral needs at least one SpiralResult")
    fig = _new_figure((9.0, 6.6))
    ax = fig.add_subplot()
    ax.axhline(0.0, color="black", lw=0.6)
    ax.axvline(0.0, color="black", lw=0.6)
    notes = []
    for res in items:
        d, r = np.degrees(res.rudder), np.degrees(res.yaw_rate)
        if res.kind == "direct":
            for leg, color, marker, name in (
                ("down", _BLUE, "v", "starboard to port"),
                ("up", _ORANGE, "^", "port to starboard"),
            ):
                m = np.array([g == leg for g in res.leg])
                if not m.any():
                    continue
                ax.plot(
                    d[m],
                    r[m],
                    color=color,
                    lw=1.2,
                    marker=marker,
                    ms=6,
                    alpha=0.9,
                    label=f"direct spiral (Dieudonné), {name}",
                )
            bad = ~res.steady
            if bad.any():
                ax.plot(d[bad], r[bad], "x", color=_RED, ms=8, label="not settled")
        else:
            ok = ~res.saturated
            order = np.argsort(r)
            ok_o = ok[order]
            ax.plot(
                d[order][ok_o],
                r[order][ok_o],
                color=_GREEN,
                lw=1.4,
                marker="o",
                ms=5,
                mfc="white",
                label="reverse spiral (Bech), PI on r",
            )
            if (~ok).any():
                ax.plot(d[~ok], r[~ok], "s", color=_GREY, ms=5, label="rudder saturated")
        notes.append(
            f"{res.kind}: "
            + (
                f"hysteresis, loop width ≈ {math.degrees(res.loop_width):.1f}°"
                if res.hysteresis
                else "no hysteresis (stable)"
            )
        )
    if any(res.hysteresis for res in items):
        widths = [res for res in items if res.hysteresis]
        w = max(math.degrees(res.loop_width) for res in widths)
        ax.axvspan(
            -0.5 * w, 0.5 * w, color=_RED, alpha=0.06, lw=0, label="instability loop (width)"
        )
    ax.set_xlabel(
        r"rudder angle $\delta$ [deg]"
        + ("  (equivalent: minus the pod azimuth)" if items[0].model == "rvg3dof" else "")
    )
    ax.set_ylabel("steady yaw rate r [deg/s]  (+ = starboard)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8.5, framealpha=0.92)
    ax.text(
        0.99,
        0.02,
        "\n".join(notes),
        transform=ax.transAxes,
        ha="right",
        va="bottom",
        fontsize=8.5,
        bbox={"boxstyle": "round,pad=0.35", "fc": "white", "ec": _GREY, "alpha": 0.92},
    )
    res0 = items[0]
    ax.set_title(
        _title(res0.model, res0.particulars, "Spiral test, the δ-r curve", res0.wind)
        + f"\napproach {res0.approach_speed:.2f} m/s",
        fontsize=11,
    )
    return _save(fig, path)


def plot_imo(report: IMOReport, path: str | Path) -> Path:
    """Each MSC.137(76) criterion as value / limit (bar), pass below 1; a PNG."""
    rows = list(report.rows)
    fig = _new_figure((10.5, 0.65 * len(rows) + 2.2))
    ax = fig.add_subplot()
    ratios = [row.value / row.limit if math.isfinite(row.value) else math.nan for row in rows]
    cap = 2.0  # bars beyond twice the limit are cut and marked "off scale"
    y = np.arange(len(rows))[::-1]
    for yi, row, q in zip(y, rows, ratios, strict=True):
        color = _GREEN if row.passed else _RED
        off = not math.isfinite(q) or q > cap
        width = cap if off else q
        ax.barh(yi, width, color=color, alpha=0.75, height=0.6, ec=color)
        if off:
            ax.plot([cap], [yi], marker=">", color=color, ms=9, clip_on=False)
        value = "not checked" if not math.isfinite(row.value) else f"{row.value:.2f} {row.unit}"
        scale = f" = {q:.1f} x" if math.isfinite(q) and q > cap else " vs"
        ax.annotate(
            f"{value}{scale} limit {row.limit:.2f} {row.unit}: {'PASS' if row.passed else 'FAIL'}",
            xy=(width, yi),
            xytext=(8, 0),
            textcoords="offset points",
            va="center",
            fontsize=8.5,
            color="black",
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
        )
    ax.axvline(1.0, color="black", lw=1.2, ls="--", zorder=0)
    ax.set_yticks(y, [row.criterion.replace(": ", ":\n", 1) for row in rows], fontsize=9)
    ax.set_xlim(0.0, 3.5)
    ax.set_xlabel("value / IMO limit  (pass < 1)")
    ax.grid(True, axis="x", alpha=0.3)
    p = report.particulars
    note = "" if p.length >= 100.0 else " (L < 100 m: informative only)"
    wind = report.turning[0].wind if report.turning else None
    if wind is not None:
        note += f", in a {wind_text(wind)}"
    fig.suptitle(
        f"IMO MSC.137(76): {p.vessel} ({report.model}), L = {p.length:g} m, U = {p.speed:g} m/s, "
        f"L/U = {p.length_over_speed:.1f} s{note}\noverall: "
        f"{'PASS' if report.passed else 'FAIL'} (worst of starboard and port)",
        fontsize=10.5,
    )
    return _save(fig, path)

"""Figure of an identification run: measured vs base model vs model with the added effects.

:func:`plot_identification` draws the ``traces`` of an
:class:`~shipgym.sysid.engine.IdentificationResult` (the Nomoto family of
:func:`shipgym.sysid.engine.identify` and ``rvg3dof`` alike):

* one row per channel against time: heading ``psi`` [deg], yaw rate ``r`` [deg/s] and, where
  the record has it, surge speed ``u`` [m/s]; each with the measured signal, the simulation of
  the base model fitted to the whole record ("before") and of the final model with the
  accepted effects ("after");
* two residual rows, ``measured - before`` and ``measured - after`` for ``psi`` (wrapped to the
  smallest signed angle) and ``r``;
* where the record has positions, the track (east to the right, north up) in a column of its
  own.

These are the simulations behind ``error_before`` and ``error_after``: one free run from the
estimated initial state, or (``window_s`` set) consecutive windows each started from the
measured state, drawn as separate pieces with a thin vertical line at each window start (when
there are at most :data:`MAX_WINDOW_LINES` windows). The held-out part of the record
(``time >= time[split]``, the part the effects were scored on) is shaded.

Inside the result everything is SI and radians; degrees appear only here, on the axes. The
figure is a :class:`matplotlib.figure.Figure` on the Agg canvas (no pyplot state), so it is safe
in headless processes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

__all__ = ["MAX_WINDOW_LINES", "METRIC_LABELS", "format_errors", "plot_identification"]

MAX_WINDOW_LINES = 60
"""Largest number of windows whose starts are drawn as vertical lines."""

METRIC_LABELS: dict[str, tuple[str, str]] = {
    "psi_rms_deg": ("psi RMS", "deg"),
    "r_rms_deg_s": ("r RMS", "deg/s"),
    "xy_rms_m": ("xy RMS", "m"),
    "u_rms_m_s": ("u RMS", "m/s"),
    "v_rms_m_s": ("v RMS", "m/s"),
}
"""Error key of ``error_before``/``error_after`` -> (label, unit)."""

_MEASURED, _BEFORE, _AFTER, _GREY = "#b3b3b3", "#d9731a", "#1f5fa8", "#6b6b6b"

# channel -> (axis label, scale from SI, wrap the residual as an angle)
_CHANNELS: dict[str, tuple[str, float, bool]] = {
    "psi": ("heading [deg]", math.degrees(1.0), True),
    "r": ("yaw rate [deg/s]", math.degrees(1.0), False),
    "u": ("surge speed u [m/s]", 1.0, False),
}
_RESIDUALS: dict[str, str] = {
    "psi": "residual psi [deg]",
    "r": "residual r [deg/s]",
}


def _number(value: Any, digits: int = 4) -> str:
    if value is None or not math.isfinite(float(value)):
        return "n/a"
    return f"{float(value):.{digits}g}"


def format_errors(before: Mapping[str, Any], after: Mapping[str, Any]) -> str:
    """The errors of both dicts, key by key: ``"psi RMS 11.64 -> 0.09716 deg, r RMS ..."``.

    Parameters
    ----------
    before, after : mapping
        Error dicts such as ``error_before`` and ``error_after`` of an
        :class:`~shipgym.sysid.engine.IdentificationResult` (keys of :data:`METRIC_LABELS`;
        other keys are shown by name).
    """
    parts = []
    for key in [*before, *(k for k in after if k not in before)]:
        label, unit = METRIC_LABELS.get(key, (key, ""))
        text = f"{label} {_number(before.get(key))} -> {_number(after.get(key))}"
        parts.append(f"{text} {unit}".rstrip())
    return ", ".join(parts)


def _broken(t: np.ndarray, y: np.ndarray, starts: Sequence[int]) -> tuple[np.ndarray, ...]:
    """``t``, ``y`` with a NaN before each window start, so the pieces are not joined."""
    cut = [int(i) for i in starts if 0 < int(i) < t.size]
    if not cut:
        return t, y
    return np.insert(t, cut, np.nan), np.insert(np.asarray(y, dtype=float), cut, np.nan)


def _wrap_deg(a: np.ndarray) -> np.ndarray:
    return (a + 180.0) % 360.0 - 180.0


def plot_identification(
    result: Any, path: str | Path | None = None, title: str | None = None
) -> Figure:
    """Measured vs before vs after and the residuals of an identification run.

    Parameters
    ----------
    result : IdentificationResult
        Output of :func:`shipgym.sysid.engine.identify` (any base); its ``traces`` must hold
        ``time``, ``psi`` and ``r``.
    path : str or pathlib.Path, optional
        Write the figure there (the format follows the suffix, PNG for ``.png``).
    title : str, optional
        First part of the title (default ``"Identification"``); the model, the added effects
        and the errors before -> after are always appended.

    Returns
    -------
    matplotlib.figure.Figure
        Rows ``psi``, ``r`` (and ``u``), then the ``psi`` and ``r`` residuals; plus a track
        axis spanning all rows when the record has positions.

    Raises
    ------
    ValueError
        If ``result.traces`` lacks ``time``, ``psi`` or ``r``.
    """
    tr = getattr(result, "traces", None) or {}
    missing = [k for k in ("time", "psi", "r") if k not in tr]
    if missing:
        raise ValueError(
            f"result.traces lacks {missing}; expected the traces of shipgym.sysid.engine.identify"
        )
    t = np.asarray(tr["time"], dtype=float)
    n = t.size
    split = tr.get("split")
    starts = [int(i) for i in np.atleast_1d(tr.get("window_starts", [0]))]
    windowed = getattr(result, "window_s", None) is not None
    sim_starts = starts if windowed else []
    show_windows = windowed and 1 < len(starts) <= MAX_WINDOW_LINES
    effects = [e["name"] for e in getattr(result, "effects", [])]
    model = str(getattr(result, "model", "?"))
    after_label = f"after: {model} + {', '.join(effects)}" if effects else "after (no effect added)"
    channels = [c for c in _CHANNELS if c in tr]
    has_track = "x" in tr and "y" in tr

    rows = len(channels) + len(_RESIDUALS)
    fig = Figure(figsize=(14.0 if has_track else 10.5, 1.9 * rows + 1.2), dpi=120)
    fig.set_layout_engine("constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(
        rows,
        2 if has_track else 1,
        width_ratios=(2.0, 1.0) if has_track else None,
        height_ratios=[1.0] * len(channels) + [0.75] * len(_RESIDUALS),
    )
    axes: list[Any] = []

    def decorate(ax: Any, first: bool) -> None:
        if split is not None and 0 < int(split) < n:
            ax.axvspan(
                t[int(split)],
                t[-1],
                color=_GREY,
                alpha=0.12,
                lw=0,
                label="held-out part" if first else None,
            )
        if show_windows:
            for j, i in enumerate(starts[1:]):
                ax.axvline(
                    t[i],
                    color=_GREY,
                    lw=0.6,
                    ls=":",
                    label="window start" if first and j == 0 else None,
                )
        ax.grid(alpha=0.3)
        ax.set_xlim(t[0], t[-1])

    for k, ch in enumerate(channels):
        label, scale, _ = _CHANNELS[ch]
        ax = fig.add_subplot(grid[k, 0], sharex=axes[0] if axes else None)
        axes.append(ax)
        d = tr[ch]
        ax.plot(t, np.asarray(d["measured"]) * scale, color=_MEASURED, lw=2.6, label="measured")
        ax.plot(
            *_broken(t, np.asarray(d["before"]) * scale, sim_starts),
            color=_BEFORE,
            lw=1.4,
            ls="--",
            label=f"before: {model}",
        )
        ax.plot(
            *_broken(t, np.asarray(d["after"]) * scale, sim_starts),
            color=_AFTER,
            lw=1.4,
            label=after_label,
            zorder=3,
        )
        ax.set_ylabel(label)
        decorate(ax, k == 0)
        if k == 0:
            ax.legend(fontsize=8, loc="best", ncols=2, framealpha=0.9)

    for k, (ch, label) in enumerate(_RESIDUALS.items()):
        _, scale, angle = _CHANNELS[ch]
        ax = fig.add_subplot(grid[len(channels) + k, 0], sharex=axes[0])
        axes.append(ax)
        d = tr[ch]
        meas = np.asarray(d["measured"]) * scale
        for key, color, name in (("before", _BEFORE, "before"), ("after", _AFTER, "after")):
            e = meas - np.asarray(d[key]) * scale
            if angle:
                e = _wrap_deg(e)
            ax.plot(*_broken(t, e, sim_starts), color=color, lw=1.0, label=f"measured - {name}")
        ax.axhline(0.0, color="black", lw=0.6)
        ax.set_ylabel(label)
        decorate(ax, False)
        ax.legend(fontsize=8, loc="best", framealpha=0.9)
    for ax in axes[:-1]:
        ax.tick_params(labelbottom=False)
    axes[-1].set_xlabel("time [s]")
    fig.align_ylabels(axes)

    if has_track:
        ax = fig.add_subplot(grid[:, 1])
        xs, ys = tr["x"], tr["y"]
        ax.plot(ys["measured"], xs["measured"], color=_MEASURED, lw=2.6, label="measured")
        ax.plot(
            _broken(t, ys["before"], sim_starts)[1],
            _broken(t, xs["before"], sim_starts)[1],
            color=_BEFORE,
            lw=1.4,
            ls="--",
            label="before",
        )
        ax.plot(
            _broken(t, ys["after"], sim_starts)[1],
            _broken(t, xs["after"], sim_starts)[1],
            color=_AFTER,
            lw=1.4,
            label="after",
            zorder=3,
        )
        ax.plot(ys["measured"][0], xs["measured"][0], "o", color="#2a8a4a", ms=5, label="start")
        if split is not None and 0 < int(split) < n:
            i = int(split)
            ax.plot(
                ys["measured"][i], xs["measured"][i], "s", color=_GREY, ms=5, label="held-out start"
            )
        ax.set_xlabel("east y [m]")
        ax.set_ylabel("north x [m]")
        ax.set_aspect("equal", adjustable="box")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best", framealpha=0.9)
        ax.set_title("track", fontsize=10)

    added = f"effects added: {', '.join(effects)}" if effects else "no effect added"
    window_s = getattr(result, "window_s", None)
    if "run" in tr:  # several runs, one after the other
        how = "each run from its measured state" + (
            f", in windows of {window_s:g} s" if windowed else ""
        )
    elif windowed:
        how = f"windows of {window_s:g} s from the measured state"
    else:
        how = "free run from the estimated initial state"
    errors = format_errors(
        getattr(result, "error_before", {}) or {}, getattr(result, "error_after", {}) or {}
    )
    fig.suptitle(
        f"{title or 'Identification'}: base {model}, {added}\n{errors} ({how})", fontsize=11
    )
    if path is not None:
        fig.savefig(Path(path))
    return fig

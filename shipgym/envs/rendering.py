"""Top-down map rendering of a ship for the shipgym environments.

The renderer draws a plan view of one ship: a pointed hull outline to scale, its recent
track, the planned path and its waypoints, a target pose, the commanded heading, the
ambient current and a free-form status text. It is used by the environments' ``render``
method and works without any display: frames are rasterised offscreen with Matplotlib's Agg
canvas (a :class:`matplotlib.figure.Figure` attached to a
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg`, so pyplot's global backend is
never touched for ``"rgb_array"`` rendering).

Conventions
-----------
All inputs follow the shipgym conventions: the earth frame is North-East-Down (NED) with
``x`` pointing north and ``y`` pointing east, headings ``psi`` are measured clockwise from
north, and all quantities are SI (metres, metres per second) with angles in radians.

On screen, **east is to the right and north is up**: the plot's horizontal axis is the
NED ``y`` coordinate and its vertical axis is the NED ``x`` coordinate, with equal aspect
so that distances are undistorted. A heading of ``0`` therefore points up the screen and
``pi / 2`` points to the right.

Camera
------
The first frame (and the first after :meth:`TopDownRenderer.reset_view`) is centred on the
ship. Afterwards the view follows the ship with a small dead band (see
:attr:`TopDownRenderer.follow_deadband`): the ship moves freely within the central part of
the frame, which makes its motion visible against the grid, and the view is dragged along
once it leaves that region. The zoom fits the ship, the target and the nearby part of the
path; it is at least :attr:`TopDownRenderer.min_span_lengths` ship lengths and at most
:attr:`TopDownRenderer.max_span_lengths` ship lengths across the shorter image side. It
widens at once when needed and narrows gradually, so animations do not jitter.

Recording videos
----------------
Gymnasium's :class:`gymnasium.wrappers.RecordVideo` writes the ``"rgb_array"`` frames of an
env to MP4 files through MoviePy, which the ``video`` extra installs
(``pip install 'shipgym[video]'``; it brings MoviePy and the ffmpeg binary of
``imageio-ffmpeg``). An env plays at ``render_fps = 1 / dt`` frames per second (real time:
2 for the Gunnerus envs, 1 for ``NomotoHeading``); ``fps`` speeds the video up::

    import gymnasium as gym
    from gymnasium.wrappers import RecordVideo

    import shipgym

    env = gym.make("shipgym/RVGPathFollowing-v1", render_mode="rgb_array")
    env = RecordVideo(env, "videos", episode_trigger=lambda episode: episode == 0, fps=20)
    obs, info = env.reset(seed=0)
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        done = terminated or truncated
    env.close()  # writes videos/rl-video-episode-0.mp4

Examples
--------
>>> import numpy as np
>>> from shipgym.envs.rendering import TopDownRenderer
>>> renderer = TopDownRenderer(ship_length=30.0, ship_beam=8.0, render_mode="rgb_array")
>>> frame = renderer.draw(0.0, 0.0, np.pi / 4, text="t = 0.0 s")
>>> frame.shape, frame.dtype
((600, 600, 3), dtype('uint8'))
>>> renderer.close()
"""

from __future__ import annotations

import math
import warnings
from typing import Any, Final

import matplotlib
import numpy as np
import numpy.typing as npt
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, FancyArrowPatch, Patch, Polygon

__all__ = ["HULL_COLOR", "RENDER_MODES", "TopDownRenderer", "hull_outline"]

#: Render modes accepted by :class:`TopDownRenderer`.
RENDER_MODES: Final[tuple[None, str, str]] = (None, "rgb_array", "human")

#: Fill colour of the ship's hull. No other element uses it, so tests can find the hull.
HULL_COLOR: Final[str] = "#ff7f0e"
# The legend swatch uses a visually identical but numerically distinct shade, so that
# HULL_COLOR pixels belong to the hull polygon only.
_HULL_LEGEND_COLOR: Final[str] = "#f27810"

_SEA_COLOR: Final[str] = "#eaf2f8"
_GRID_COLOR: Final[str] = "#c9d9e6"
_HULL_EDGE_COLOR: Final[str] = "#5c2a00"
_PATH_COLOR: Final[str] = "#1f3a5f"
_TRAIL_COLOR: Final[str] = "#2a9d8f"
_TARGET_COLOR: Final[str] = "#2ca02c"
_SETPOINT_COLOR: Final[str] = "#7b2cbf"
_HEADING_COLOR: Final[str] = "#333333"
_CURRENT_COLOR: Final[str] = "#0077b6"
_TEXT_COLOR: Final[str] = "#1b1b1b"

_DPI: Final[float] = 100.0

_NON_INTERACTIVE_FALLBACK: Final[frozenset[str]] = frozenset(
    {"agg", "cairo", "pdf", "pgf", "ps", "svg", "template"}
)


def hull_outline(
    x: float, y: float, psi: float, length: float, beam: float
) -> npt.NDArray[np.float64]:
    """Return the hull polygon of a ship in plot coordinates (east, north).

    The outline has a square-ish stern with rounded corners, a parallel mid-body and a
    pointed bow at ``+length / 2`` along the body x axis.

    Parameters
    ----------
    x : float
        North position of the ship's reference point (midships) in m.
    y : float
        East position of the ship's reference point in m.
    psi : float
        Heading in rad, clockwise from north.
    length : float
        Overall length in m.
    beam : float
        Overall beam in m.

    Returns
    -------
    numpy.ndarray
        ``(n, 2)`` array of vertices, columns ``(east, north)`` in m, i.e. ready to be
        plotted with east on the horizontal axis.
    """
    half_l = 0.5 * length
    half_b = 0.5 * beam
    # Body frame (forward, starboard), starboard side from stern to bow then port side back.
    forward = np.array(
        [-half_l, -0.96 * half_l, 0.15 * half_l, 0.55 * half_l, 0.82 * half_l, half_l]
    )
    starboard = np.array([0.80 * half_b, half_b, half_b, 0.85 * half_b, 0.50 * half_b, 0.0])
    xb = np.concatenate([forward, forward[-2::-1]])
    yb = np.concatenate([starboard, -starboard[-2::-1]])
    cos_psi = math.cos(psi)
    sin_psi = math.sin(psi)
    north = x + xb * cos_psi - yb * sin_psi
    east = y + xb * sin_psi + yb * cos_psi
    return np.column_stack([east, north])


def _as_points(value: npt.ArrayLike | None, name: str) -> npt.NDArray[np.float64] | None:
    """Validate an optional ``(k, 2)`` array of (north, east) points and drop non-finite rows.

    Parameters
    ----------
    value : array_like or None
        The points, or ``None``.
    name : str
        Argument name used in error messages.

    Returns
    -------
    numpy.ndarray or None
        ``(k, 2)`` float array of finite (north, east) rows, or ``None`` if ``value`` is
        ``None`` or holds no finite row.

    Raises
    ------
    ValueError
        If ``value`` cannot be read as an array of shape ``(k, 2)``.
    """
    if value is None:
        return None
    points = np.asarray(value, dtype=np.float64)
    if points.size == 0:
        return None
    if points.ndim != 2 or points.shape[1] != 2:
        raise ValueError(f"{name} must have shape (k, 2) of (north, east) rows, got {points.shape}")
    points = points[np.all(np.isfinite(points), axis=1)]
    return points if len(points) else None


def _nice_length(target: float) -> float:
    """Return the largest 1, 2 or 5 times a power of ten not exceeding ``target`` (> 0)."""
    exponent = math.floor(math.log10(target))
    base = 10.0**exponent
    for factor in (5.0, 2.0, 1.0):
        if factor * base <= target:
            return factor * base
    return base


def _format_length(metres: float) -> str:
    """Format a scale-bar length in m or km."""
    if metres >= 1000.0:
        return f"{metres / 1000.0:g} km"
    return f"{metres:g} m"


def _is_non_interactive_backend(backend: str) -> bool:
    """Return whether the named Matplotlib backend cannot open windows."""
    name = backend.lower()
    try:
        from matplotlib.backends import BackendFilter, backend_registry

        non_interactive = set(backend_registry.list_builtin(BackendFilter.NON_INTERACTIVE))
    except ImportError:  # pragma: no cover - Matplotlib < 3.9
        non_interactive = set(_NON_INTERACTIVE_FALLBACK)
    return name in non_interactive


class TopDownRenderer:
    """Offscreen top-down (plan view) renderer of a single ship.

    Parameters
    ----------
    ship_length : float
        Length of the drawn hull in m (> 0).
    ship_beam : float
        Beam of the drawn hull in m (> 0).
    render_mode : {None, "rgb_array", "human"}
        ``None`` makes :meth:`draw` a no-op returning ``None`` (nothing is allocated);
        ``"rgb_array"`` makes it return an image; ``"human"`` shows the image in a pyplot
        window and returns ``None``.
    width : int, default 600
        Image width in pixels.
    height : int, default 600
        Image height in pixels.
    title : str, default ""
        Title drawn in bold above the status text (for instance the vessel's name).
    fps : float, default 30.0
        Frame rate of the ``"human"`` window; each frame pauses ``1 / fps`` s.

    Attributes
    ----------
    min_span_lengths : float
        Smallest view span (shorter image side) in ship lengths.
    max_span_lengths : float
        Largest view span in ship lengths; farther targets and waypoints are not fitted.
    follow_deadband : float
        Fraction of the half-span (per axis) by which the ship may leave the view centre
        before the view follows it; ``0`` keeps the ship exactly centred.

    Raises
    ------
    ValueError
        If ``render_mode`` is not one of :data:`RENDER_MODES` or a size is not positive.

    Notes
    -----
    Positions are NED (``x`` north, ``y`` east, m) and angles are radians clockwise from
    north. On screen east is to the right and north is up.
    """

    min_span_lengths: float = 6.0
    max_span_lengths: float = 60.0
    follow_deadband: float = 0.3

    def __init__(
        self,
        ship_length: float,
        ship_beam: float,
        render_mode: str | None,
        width: int = 600,
        height: int = 600,
        title: str = "",
        *,
        fps: float = 30.0,
    ) -> None:
        if render_mode not in RENDER_MODES:
            raise ValueError(
                f"invalid render_mode {render_mode!r}; expected one of {list(RENDER_MODES)!r}"
            )
        if not (math.isfinite(ship_length) and ship_length > 0.0):
            raise ValueError(f"ship_length must be a positive number, got {ship_length!r}")
        if not (math.isfinite(ship_beam) and ship_beam > 0.0):
            raise ValueError(f"ship_beam must be a positive number, got {ship_beam!r}")
        if int(width) != width or width < 16 or int(height) != height or height < 16:
            raise ValueError(
                f"width and height must be integers >= 16 pixels, got {width!r} x {height!r}"
            )
        if not (math.isfinite(fps) and fps > 0.0):
            raise ValueError(f"fps must be a positive number, got {fps!r}")
        self.ship_length: float = float(ship_length)
        self.ship_beam: float = float(ship_beam)
        self.render_mode: str | None = render_mode
        self.width: int = int(width)
        self.height: int = int(height)
        self.title: str = str(title)
        self.fps: float = float(fps)

        short_side = float(min(self.width, self.height))
        # Half-span factors: the view's half-width is half * _fx, its half-height half * _fy.
        self._fx: float = self.width / short_side
        self._fy: float = self.height / short_side
        self._center: tuple[float, float] | None = None  # (east, north) in m
        self._half: float = 0.0

        self._fig: Figure | None = None
        self._canvas: FigureCanvasAgg | None = None
        self._artists: dict[str, Any] = {}
        self._legend_key: tuple[str, ...] | None = None

        self._window_fig: Any = None
        self._window_image: Any = None
        self._window_disabled: bool = False

    # ------------------------------------------------------------------ public API

    def reset_view(self) -> None:
        """Forget the camera so the next frame is centred on the ship and freshly zoomed."""
        self._center = None
        self._half = 0.0

    def draw(
        self,
        x: float,
        y: float,
        psi: float,
        *,
        trail: np.ndarray | None = None,
        path: np.ndarray | None = None,
        target: tuple[float, float] | None = None,
        target_heading: float | None = None,
        setpoint_heading: float | None = None,
        current_speed: float = 0.0,
        current_direction: float = 0.0,
        text: str = "",
    ) -> np.ndarray | None:
        """Draw one frame.

        Parameters
        ----------
        x : float
            North position of the ship in m.
        y : float
            East position of the ship in m.
        psi : float
            Heading in rad, clockwise from north.
        trail : numpy.ndarray or None, optional
            ``(k, 2)`` past positions, columns ``(north, east)`` in m, drawn as a thin line.
        path : numpy.ndarray or None, optional
            ``(m, 2)`` waypoints, columns ``(north, east)`` in m, drawn as a line with
            markers.
        target : tuple of float or None, optional
            Target position ``(north, east)`` in m, drawn as a star.
        target_heading : float or None, optional
            Desired heading at the target in rad; adds a dashed hull outline at the target.
            Ignored without ``target``.
        setpoint_heading : float or None, optional
            Commanded heading in rad, drawn as a dashed ray from the ship.
        current_speed : float, default 0.0
            Current speed in m/s, shown in the top-right compass inset.
        current_direction : float, default 0.0
            Direction the water moves toward, rad clockwise from north.
        text : str, default ""
            Status text (time, errors, ...) printed in the top-left corner.

        Returns
        -------
        numpy.ndarray or None
            ``(height, width, 3)`` ``uint8`` RGB image in ``"rgb_array"`` mode, otherwise
            ``None``.

        Raises
        ------
        ValueError
            If ``trail`` or ``path`` does not have shape ``(k, 2)``.
        """
        if self.render_mode is None:
            return None
        trail_pts = _as_points(trail, "trail")
        path_pts = _as_points(path, "path")
        target_pt: tuple[float, float] | None = None
        if target is not None:
            tn, te = float(target[0]), float(target[1])
            if math.isfinite(tn) and math.isfinite(te):
                target_pt = (tn, te)

        if self._fig is None:
            self._build_figure()
        x, y, psi = float(x), float(y), float(psi)
        self._update_view(x, y, target_pt, path_pts)
        self._update_artists(
            x,
            y,
            psi,
            trail_pts,
            path_pts,
            target_pt,
            target_heading,
            setpoint_heading,
            float(current_speed),
            float(current_direction),
            text,
        )
        frame = self._rasterise()
        if self.render_mode == "human":
            self._show(frame)
            return None
        return frame

    def close(self) -> None:
        """Release the offscreen figure and close the ``"human"`` window, if any."""
        if self._window_fig is not None:
            try:
                import matplotlib.pyplot as plt

                plt.close(self._window_fig)
            except Exception:  # pragma: no cover - closing must never fail
                pass
        self._window_fig = None
        self._window_image = None
        if self._fig is not None:
            self._fig.clear()
        self._fig = None
        self._canvas = None
        self._artists = {}
        self._legend_key = None
        self.reset_view()

    def __enter__(self) -> TopDownRenderer:
        """Return ``self`` for use as a context manager."""
        return self

    def __exit__(self, *exc_info: object) -> None:
        """Close the renderer when leaving a ``with`` block."""
        self.close()

    # ------------------------------------------------------------------ figure set-up

    def _build_figure(self) -> None:
        """Create the offscreen figure and every artist once; later frames update them."""
        fig = Figure(figsize=(self.width / _DPI, self.height / _DPI), dpi=_DPI)
        canvas = FigureCanvasAgg(fig)
        fig.patch.set_facecolor(_SEA_COLOR)
        ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
        ax.set_facecolor(_SEA_COLOR)
        ax.set_aspect("equal", adjustable="box")
        ax.tick_params(
            which="both",
            length=0,
            labelbottom=False,
            labelleft=False,
            bottom=False,
            left=False,
        )
        ax.grid(True, color=_GRID_COLOR, linewidth=0.8)
        ax.set_axisbelow(True)
        for spine in ax.spines.values():
            spine.set_visible(False)

        a: dict[str, Any] = {}
        (a["path"],) = ax.plot(
            [],
            [],
            color=_PATH_COLOR,
            linewidth=1.6,
            marker="o",
            markersize=5.5,
            markerfacecolor="white",
            markeredgecolor=_PATH_COLOR,
            markeredgewidth=1.4,
            zorder=2,
            label="path",
        )
        (a["trail"],) = ax.plot(
            [], [], color=_TRAIL_COLOR, linewidth=1.2, alpha=0.9, zorder=3, label="track"
        )
        a["target_hull"] = Polygon(
            np.zeros((3, 2)),
            closed=True,
            fill=False,
            edgecolor=_TARGET_COLOR,
            linewidth=1.3,
            linestyle=(0, (4, 2)),
            zorder=4.5,
        )
        ax.add_patch(a["target_hull"])
        (a["target"],) = ax.plot(
            [],
            [],
            linestyle="none",
            marker="*",
            markersize=13,
            markerfacecolor=_TARGET_COLOR,
            markeredgecolor="#145214",
            markeredgewidth=0.8,
            zorder=4,
            label="target",
        )
        (a["setpoint"],) = ax.plot(
            [],
            [],
            color=_SETPOINT_COLOR,
            linewidth=1.5,
            linestyle=(0, (5, 3)),
            zorder=4,
            label="heading setpoint",
        )
        (a["heading"],) = ax.plot(
            [], [], color=_HEADING_COLOR, linewidth=1.0, zorder=4, label="heading"
        )
        a["hull"] = Polygon(
            np.zeros((3, 2)),
            closed=True,
            facecolor=HULL_COLOR,
            edgecolor=_HULL_EDGE_COLOR,
            linewidth=1.2,
            joinstyle="round",
            zorder=5,
            label="ship",
        )
        ax.add_patch(a["hull"])
        (a["ship_dot"],) = ax.plot(
            [],
            [],
            linestyle="none",
            marker="o",
            markersize=3.0,
            markerfacecolor=_HULL_EDGE_COLOR,
            markeredgecolor="none",
            zorder=6,
        )

        text_box = {
            "boxstyle": "round,pad=0.35",
            "facecolor": "white",
            "edgecolor": "#9fb3c8",
            "alpha": 0.85,
        }
        a["title"] = ax.text(
            0.015,
            0.985,
            "",
            transform=ax.transAxes,
            ha="left",
            va="top",
            fontsize=10,
            fontweight="bold",
            color=_TEXT_COLOR,
            bbox=text_box,
            zorder=10,
        )
        a["text"] = ax.text(
            0.015,
            0.985,
            "",
            transform=ax.transAxes,
            ha="left",
            va="top",
            fontsize=9,
            family="monospace",
            color=_TEXT_COLOR,
            bbox=text_box,
            zorder=10,
        )

        # Scale bar (bottom left, axes coordinates).
        (a["scale_bar"],) = ax.plot(
            [],
            [],
            color=_TEXT_COLOR,
            linewidth=2.5,
            solid_capstyle="butt",
            transform=ax.transAxes,
            zorder=10,
        )
        a["scale_text"] = ax.text(
            0.0,
            0.0,
            "",
            transform=ax.transAxes,
            ha="center",
            va="bottom",
            fontsize=8.5,
            color=_TEXT_COLOR,
            zorder=10,
        )

        # Compass / current inset (top right).
        inset_w = 0.2 * min(1.0, 1.0 / self._fx)
        inset_h = 0.2 * min(1.0, 1.0 / self._fy)
        inset = fig.add_axes((0.985 - inset_w, 0.985 - inset_h, inset_w, inset_h))
        inset.set_xlim(-1.1, 1.1)
        inset.set_ylim(-1.15, 1.05)
        inset.set_aspect("equal", adjustable="datalim")
        inset.set_axis_off()
        inset.add_patch(
            Circle(
                (0.0, 0.0),
                0.72,
                facecolor="white",
                edgecolor="#9fb3c8",
                linewidth=1.0,
                alpha=0.85,
            )
        )
        inset.text(
            0.0,
            0.9,
            "N",
            ha="center",
            va="center",
            fontsize=8,
            fontweight="bold",
            color=_TEXT_COLOR,
        )
        for angle in np.arange(4) * (0.5 * np.pi):
            s, c = math.sin(angle), math.cos(angle)
            inset.plot(
                [0.62 * s, 0.72 * s],
                [0.62 * c, 0.72 * c],
                color="#9fb3c8",
                linewidth=1.0,
            )
        a["current_arrow"] = FancyArrowPatch(
            (0.0, 0.0),
            (0.0, 0.0),
            arrowstyle="-|>,head_length=4,head_width=2.5",
            mutation_scale=1.6,
            color=_CURRENT_COLOR,
            linewidth=2.0,
            shrinkA=0.0,
            shrinkB=0.0,
        )
        inset.add_patch(a["current_arrow"])
        (a["current_dot"],) = inset.plot(
            [0.0], [0.0], marker="o", markersize=3.5, color=_CURRENT_COLOR, linestyle="none"
        )
        a["current_text"] = inset.text(
            0.0,
            -0.93,
            "",
            ha="center",
            va="center",
            fontsize=8.5,
            color=_TEXT_COLOR,
            bbox={
                "boxstyle": "round,pad=0.25",
                "facecolor": "white",
                "edgecolor": "none",
                "alpha": 0.85,
            },
        )

        self._fig = fig
        self._canvas = canvas
        self._ax: Axes = ax
        self._artists = a
        self._legend_key = None

    # ------------------------------------------------------------------ per-frame updates

    def _desired_half(
        self,
        center: tuple[float, float],
        x: float,
        y: float,
        target: tuple[float, float] | None,
        path: npt.NDArray[np.float64] | None,
    ) -> float:
        """Half-span (m, along the shorter side) that fits the ship, target and near path."""
        length = self.ship_length
        min_half = 0.5 * self.min_span_lengths * length
        max_half = 0.5 * max(self.max_span_lengths, self.min_span_lengths) * length
        points: list[tuple[float, float]] = [(x, y)]  # (north, east)
        if target is not None:
            points.append(target)
        if path is not None:
            points.extend(self._near_path_points(x, y, path))
        ce, cn = center
        needed = 0.0
        for pn, pe in points:
            # Keep 1.5 ship lengths (plus 20 %) of margin around each fitted point.
            d_e = (abs(pe - ce) * 1.2 + 1.5 * length) / self._fx
            d_n = (abs(pn - cn) * 1.2 + 1.5 * length) / self._fy
            needed = max(needed, d_e, d_n)
        return float(min(max(needed, min_half), max_half))

    def _near_path_points(
        self, x: float, y: float, path: npt.NDArray[np.float64]
    ) -> list[tuple[float, float]]:
        """Closest point of the path polyline to the ship and the waypoint after it."""
        if len(path) == 1:
            return [(float(path[0, 0]), float(path[0, 1]))]
        ship = np.array([x, y])
        starts = path[:-1]
        seg = path[1:] - starts
        seg_len2 = np.einsum("ij,ij->i", seg, seg)
        rel = ship - starts
        proj = np.einsum("ij,ij->i", rel, seg)
        t = np.clip(np.divide(proj, seg_len2, out=np.zeros_like(proj), where=seg_len2 > 0), 0, 1)
        closest = starts + t[:, None] * seg
        dist2 = np.sum((closest - ship) ** 2, axis=1)
        i = int(np.argmin(dist2))
        cap = 0.5 * self.max_span_lengths * self.ship_length
        out = [(float(closest[i, 0]), float(closest[i, 1]))]
        nxt = path[i + 1]
        if math.hypot(nxt[0] - x, nxt[1] - y) <= cap:
            out.append((float(nxt[0]), float(nxt[1])))
        return out

    def _update_view(
        self,
        x: float,
        y: float,
        target: tuple[float, float] | None,
        path: npt.NDArray[np.float64] | None,
    ) -> None:
        """Move the camera (dead-band follow) and zoom (grow at once, shrink gradually)."""
        if self._center is None or self._half <= 0.0:
            self._center = (y, x)
            self._half = self._desired_half(self._center, x, y, target, path)
        else:
            ce, cn = self._center
            band = max(0.0, min(self.follow_deadband, 0.9)) * self._half
            band_e, band_n = band * self._fx, band * self._fy
            d_e, d_n = y - ce, x - cn
            if abs(d_e) > band_e:
                ce += d_e - math.copysign(band_e, d_e)
            if abs(d_n) > band_n:
                cn += d_n - math.copysign(band_n, d_n)
            self._center = (ce, cn)
            desired = self._desired_half(self._center, x, y, target, path)
            if desired >= self._half:
                self._half = desired
            else:
                self._half = max(desired, 0.97 * self._half)
        ce, cn = self._center
        half_e, half_n = self._half * self._fx, self._half * self._fy
        self._ax.set_xlim(ce - half_e, ce + half_e)
        self._ax.set_ylim(cn - half_n, cn + half_n)

    def _update_artists(
        self,
        x: float,
        y: float,
        psi: float,
        trail: npt.NDArray[np.float64] | None,
        path: npt.NDArray[np.float64] | None,
        target: tuple[float, float] | None,
        target_heading: float | None,
        setpoint_heading: float | None,
        current_speed: float,
        current_direction: float,
        text: str,
    ) -> None:
        """Push this frame's data into the persistent artists."""
        a = self._artists
        length, beam = self.ship_length, self.ship_beam
        visible: list[str] = ["ship"]

        a["hull"].set_xy(hull_outline(x, y, psi, length, beam))
        a["ship_dot"].set_data([y], [x])

        ray = max(1.5 * length, 0.75 * self._half)
        a["heading"].set_data([y, y + ray * math.sin(psi)], [x, x + ray * math.cos(psi)])

        if setpoint_heading is not None and math.isfinite(setpoint_heading):
            sp = float(setpoint_heading)
            a["setpoint"].set_data([y, y + ray * math.sin(sp)], [x, x + ray * math.cos(sp)])
            a["setpoint"].set_visible(True)
            visible.append("heading setpoint")
        else:
            a["setpoint"].set_visible(False)

        if path is not None:
            a["path"].set_data(path[:, 1], path[:, 0])
            a["path"].set_visible(True)
            visible.append("path")
        else:
            a["path"].set_visible(False)

        if trail is not None and len(trail) >= 2:
            a["trail"].set_data(trail[:, 1], trail[:, 0])
            a["trail"].set_visible(True)
            visible.append("track")
        else:
            a["trail"].set_visible(False)

        if target is not None:
            a["target"].set_data([target[1]], [target[0]])
            a["target"].set_visible(True)
            visible.append("target")
            if target_heading is not None and math.isfinite(target_heading):
                a["target_hull"].set_xy(
                    hull_outline(target[0], target[1], float(target_heading), length, beam)
                )
                a["target_hull"].set_visible(True)
            else:
                a["target_hull"].set_visible(False)
        else:
            a["target"].set_visible(False)
            a["target_hull"].set_visible(False)

        self._update_texts(text)
        self._update_scale_bar()
        self._update_current(current_speed, current_direction)
        self._update_legend(tuple(visible))

    def _update_texts(self, text: str) -> None:
        """Title (bold) and status text stacked in the top-left corner."""
        a = self._artists
        a["title"].set_text(self.title)
        a["title"].set_visible(bool(self.title))
        a["text"].set_text(text)
        a["text"].set_visible(bool(text))
        if self.title:
            n_lines = self.title.count("\n") + 1
            # Shift the status box below the title box (points -> axes fraction).
            shift_px = (n_lines * 10.0 * 1.25 + 12.0) * _DPI / 72.0
            a["text"].set_position((0.015, 0.985 - shift_px / self.height))
        else:
            a["text"].set_position((0.015, 0.985))

    def _update_scale_bar(self) -> None:
        """Scale bar of a round length about a fifth of the view width."""
        a = self._artists
        span_e = 2.0 * self._half * self._fx
        metres = _nice_length(0.2 * span_e)
        frac = metres / span_e
        x0, yb = 0.03, 0.035
        a["scale_bar"].set_data([x0, x0 + frac], [yb, yb])
        a["scale_text"].set_position((x0 + 0.5 * frac, yb + 0.008))
        a["scale_text"].set_text(_format_length(metres))

    def _update_current(self, speed: float, direction: float) -> None:
        """Current arrow in the compass inset; its length saturates at 1 m/s."""
        a = self._artists
        if not math.isfinite(speed):
            speed = 0.0
        if not math.isfinite(direction):
            direction = 0.0
        a["current_text"].set_text(f"current {abs(speed):.2f} m/s")
        if speed < 0.0:  # a negative speed means flow in the opposite direction
            direction += math.pi
            speed = -speed
        if speed > 1e-9:
            r = 0.25 + 0.35 * min(speed, 1.0)
            s, c = math.sin(direction), math.cos(direction)
            a["current_arrow"].set_positions((-r * s, -r * c), (r * s, r * c))
            a["current_arrow"].set_visible(True)
            a["current_dot"].set_visible(False)
        else:
            a["current_arrow"].set_visible(False)
            a["current_dot"].set_visible(True)

    def _update_legend(self, key: tuple[str, ...]) -> None:
        """Rebuild the legend only when the set of drawn elements changes."""
        if key == self._legend_key:
            return
        a = self._artists
        handles: list[Patch | Line2D] = []
        for name in key:
            if name == "ship":
                handles.append(
                    Patch(facecolor=_HULL_LEGEND_COLOR, edgecolor=_HULL_EDGE_COLOR, label="ship")
                )
            elif name == "path":
                handles.append(a["path"])
            elif name == "track":
                handles.append(a["trail"])
            elif name == "target":
                handles.append(a["target"])
            elif name == "heading setpoint":
                handles.append(a["setpoint"])
        legend = self._ax.legend(
            handles=handles,
            loc="lower right",
            fontsize=8,
            framealpha=0.85,
            facecolor="white",
            edgecolor="#9fb3c8",
        )
        legend.set_zorder(10)
        self._legend_key = key

    # ------------------------------------------------------------------ output

    def _rasterise(self) -> np.ndarray:
        """Render the figure with Agg and return an ``(height, width, 3)`` uint8 array."""
        assert self._canvas is not None
        self._canvas.draw()
        rgba = np.asarray(self._canvas.buffer_rgba())
        rgb = np.array(rgba[: self.height, : self.width, :3], dtype=np.uint8)
        if rgb.shape[:2] != (self.height, self.width):  # pragma: no cover - rounding guard
            padded = np.empty((self.height, self.width, 3), dtype=np.uint8)
            padded[...] = rgb[-1:, -1:] if rgb.size else 255
            padded[: rgb.shape[0], : rgb.shape[1]] = rgb
            rgb = padded
        return rgb

    def _show(self, frame: np.ndarray) -> None:
        """Display ``frame`` in a pyplot window; stay silent if no window can be shown."""
        if self._window_disabled:
            return
        try:
            import matplotlib.pyplot as plt

            if _is_non_interactive_backend(matplotlib.get_backend()):
                # Headless (Agg & co.): nothing can be shown; fall back to offscreen only.
                self._window_disabled = True
                return
            plt.ion()
            if self._window_fig is None or not plt.fignum_exists(self._window_fig.number):
                self._window_fig = plt.figure(
                    figsize=(self.width / _DPI, self.height / _DPI), dpi=_DPI
                )
                self._window_fig.subplots_adjust(0.0, 0.0, 1.0, 1.0)
                ax = self._window_fig.add_subplot(1, 1, 1)
                ax.set_axis_off()
                self._window_image = ax.imshow(frame, interpolation="nearest")
                if self.title:
                    manager = self._window_fig.canvas.manager
                    if manager is not None:
                        manager.set_window_title(self.title)
                plt.show(block=False)
            else:
                self._window_image.set_data(frame)
                self._window_fig.canvas.draw_idle()
            plt.pause(1.0 / self.fps)
        except Exception as exc:  # no display, broken GUI toolkit, closed window ...
            self._window_disabled = True
            warnings.warn(
                f"TopDownRenderer: cannot open a 'human' render window ({exc!r}); "
                "frames are rendered offscreen only.",
                UserWarning,
                stacklevel=3,
            )

"""Paths in the NED plane for guidance: straight legs, lines and circles, splines.

Seed 004 section 2.1 compares four ways of joining waypoints ``(north, east)`` [m]:
piecewise-linear legs (:class:`WaypointPath`), straight lines joined by circular arcs of a
chosen turning radius (:class:`FilletPath`), and the two interpolating curves "Piecewise Cubic
Hermite Interpolating Polynomial" and "Cubic spline data interpolation"
(:class:`SplinePath` with ``kind="pchip"`` or ``kind="cubic"``).

Every path is parametrised by its arc length ``s`` in ``[0, length]`` [m] and offers the same
interface (:class:`Path`):

* ``point(s) -> (north, east)``: the path point ``p_p(s)``;
* ``tangent_angle(s) -> chi_p``: the path angle ``chi_p = atan2(dE/ds, dN/ds)``, clockwise
  from north like a heading, wrapped to ``[-pi, pi)``;
* ``curvature(s) = d chi_p / ds`` [1/m], *signed*: positive when the path turns clockwise
  (to starboard), negative when it turns to port, zero on straight parts;
* ``closest(p, s_hint=None) -> (s, e)``: the arc length of the closest path point and the
  cross-track error (Fossen 2011, ch. 10)::

      e = -(x - x_p) sin(chi_p) + (y - y_p) cos(chi_p)

  with ``(x, y) = p`` and ``(x_p, y_p) = p_p(s)``: ``e > 0`` when ``p`` lies to the right
  (starboard) of the path direction, e.g. east of a northbound path.

Lines and arcs are exact (closed-form lengths, closest points and curvature). The splines
are interpolated in the cumulative chord length ``u`` of the waypoints; their arc length
``s(u) = int |p'(u)| du`` is integrated with Gauss-Legendre quadrature and inverted (a
monotone map, safeguarded Newton) so that ``s`` is a true arc length. Curvature of the
splines: ``kappa = (x' y'' - y' x'') / |p'|^3`` (``'`` = d/du).
"""

from __future__ import annotations

import abc
import math

import numpy as np
import numpy.typing as npt
from scipy.interpolate import CubicSpline, PchipInterpolator

from controllers._angles import ssa_array

__all__ = ["FilletPath", "Path", "SplinePath", "WaypointPath"]

FloatArray = npt.NDArray[np.float64]

_TWO_PI = 2.0 * math.pi
# Gauss-Legendre nodes/weights on [0, 1] for the spline arc length.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_GL_X = 0.5 * (_GL_X + 1.0)
_GL_W = 0.5 * _GL_W


def _validate_waypoints(waypoints: npt.ArrayLike) -> FloatArray:
    """Return waypoints as a float ``(n, 2)`` array or raise ``ValueError``."""
    try:
        wp = np.array(waypoints, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"waypoints must be an (n, 2) array of (north, east) [m] numbers, got {waypoints!r}"
        ) from exc
    if wp.ndim != 2 or wp.shape[1] != 2:
        raise ValueError(
            f"waypoints must be an (n, 2) array of (north, east) [m], got shape {wp.shape}"
        )
    if wp.shape[0] < 2:
        raise ValueError(f"a path needs at least two waypoints, got {wp.shape[0]}")
    bad = np.flatnonzero(~np.all(np.isfinite(wp), axis=1))
    if bad.size:
        raise ValueError(
            f"waypoint {bad[0]} is not finite: {wp[bad[0]].tolist()} (expected finite "
            "(north, east) [m])"
        )
    legs = np.hypot(*np.diff(wp, axis=0).T)
    scale = max(1.0, float(np.max(np.abs(wp))))
    dup = np.flatnonzero(legs <= 1e-12 * scale)
    if dup.size:
        i = int(dup[0])
        raise ValueError(
            f"consecutive waypoints {i} and {i + 1} coincide at {wp[i].tolist()}: expected "
            "distinct consecutive waypoints"
        )
    return wp


def _as_points(p: npt.ArrayLike) -> tuple[FloatArray, bool]:
    """Positions as an ``(n, 2)`` float array and whether a single point was given."""
    pts = np.asarray(p, dtype=np.float64)
    single = pts.ndim == 1
    if single:
        pts = pts[None, :]
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(
            f"p must be a (north, east) point or an (n, 2) array of points, got shape {np.shape(p)}"
        )
    if not np.all(np.isfinite(pts)):
        raise ValueError(f"p must be finite (north, east) [m], got {np.asarray(p).tolist()}")
    return pts, single


class Path(abc.ABC):
    """A planar path ``p_p(s) = (north, east)`` [m] parametrised by arc length ``s`` [m].

    Subclasses implement :meth:`point`, :meth:`tangent_angle` and :meth:`curvature`;
    :meth:`closest` has a generic numerical implementation (dense sampling plus bisection on
    ``(p - p_p(s)) . t(s) = 0``) that subclasses may replace by an exact one.

    Arc lengths outside ``[0, length]`` (beyond a relative tolerance of 1e-9) raise
    ``ValueError``; values within the tolerance are clipped.
    """

    def __init__(self, waypoints: npt.ArrayLike) -> None:
        self._waypoints = _validate_waypoints(waypoints)

    # ---------------------------------------------------------------- common properties
    @property
    def waypoints(self) -> FloatArray:
        """The ``(n, 2)`` waypoints (north, east) [m] the path was built from (a copy)."""
        return self._waypoints.copy()

    @property
    @abc.abstractmethod
    def length(self) -> float:
        """Total arc length [m]."""

    @property
    @abc.abstractmethod
    def waypoint_s(self) -> FloatArray:
        """Arc length [m] of the path station belonging to each waypoint, shape ``(n,)``.

        The waypoint itself for paths through the waypoints; for :class:`FilletPath` the
        middle of the arc that rounds the corner. Starts at 0 and ends at :attr:`length`;
        guidance uses it to number the segments.
        """

    # ---------------------------------------------------------------- geometry
    @abc.abstractmethod
    def point(self, s: npt.ArrayLike) -> FloatArray:
        """Path point ``(north, east)`` [m] at arc length ``s``: shape ``np.shape(s) + (2,)``."""

    @abc.abstractmethod
    def tangent_angle(self, s: npt.ArrayLike) -> FloatArray | float:
        """Path angle ``chi_p(s)`` [rad], clockwise from north, in ``[-pi, pi)``."""

    @abc.abstractmethod
    def curvature(self, s: npt.ArrayLike) -> FloatArray | float:
        """Signed curvature ``d chi_p / ds`` [1/m]: positive turning to starboard."""

    def sample(self, ds: float | None = None) -> tuple[FloatArray, FloatArray]:
        """Stations and points for plotting: ``(s (m,), points (m, 2))``.

        Parameters
        ----------
        ds : float, optional
            Spacing [m]; default ``length / 500``.
        """
        if ds is None:
            ds = self.length / 500.0
        if not (np.isfinite(ds) and ds > 0.0):
            raise ValueError(f"ds must be a positive finite spacing [m], got {ds!r}")
        n = max(2, math.ceil(self.length / ds) + 1)
        s = np.linspace(0.0, self.length, n)
        return s, self.point(s)

    def cross_track_error(self, p: npt.ArrayLike, s: npt.ArrayLike) -> FloatArray | float:
        """Fossen's cross-track error of ``p`` relative to the path point at ``s``.

        ``e = -(x - x_p) sin(chi_p) + (y - y_p) cos(chi_p)``: positive to starboard.
        """
        pts, single = _as_points(p)
        s_arr = np.broadcast_to(self._check_s(s), pts.shape[:1])
        e = self._cross_track(pts, s_arr)
        return float(e[0]) if single else e

    def closest(
        self,
        p: npt.ArrayLike,
        s_hint: npt.ArrayLike | None = None,
        window: float | None = None,
    ) -> tuple[float, float] | tuple[FloatArray, FloatArray]:
        """Closest path point to ``p`` and the cross-track error there.

        Parameters
        ----------
        p : array_like
            One point ``(north, east)`` [m] or an ``(n, 2)`` array of points.
        s_hint : float or array_like, optional
            Search only the stations within ``window`` of ``s_hint`` [m] (local search, e.g.
            to keep guidance on the branch it is following where a path passes near itself).
            ``None``: the whole path.
        window : float, optional
            Half-width [m] of the local search; default ``2 |p - p_p(s_hint)|`` (every path
            point closer to ``p`` than ``p_p(s_hint)`` lies within that distance of
            ``p_p(s_hint)``), at least ``1e-9 length``.

        Returns
        -------
        s : float or numpy.ndarray
            Arc length [m] of the closest point, in ``[0, length]``.
        e : float or numpy.ndarray
            Cross-track error [m] at ``s`` (positive: ``p`` to starboard of the path).
        """
        pts, single = _as_points(p)
        lo, hi = self._search_interval(pts, s_hint, window)
        s = self._closest_in(pts, lo, hi)
        e = self._cross_track(pts, s)
        if single:
            return float(s[0]), float(e[0])
        return s, e

    # ---------------------------------------------------------------- helpers
    def _check_s(self, s: npt.ArrayLike) -> FloatArray:
        s_arr = np.asarray(s, dtype=np.float64)
        tol = 1e-9 * max(1.0, self.length)
        if not np.all(np.isfinite(s_arr)):
            raise ValueError(f"arc length s must be finite, got {s!r}")
        if np.any(s_arr < -tol) or np.any(s_arr > self.length + tol):
            raise ValueError(
                f"arc length s must lie in [0, {self.length:.6g}] m, got values in "
                f"[{float(np.min(s_arr)):.6g}, {float(np.max(s_arr)):.6g}]"
            )
        return np.clip(s_arr, 0.0, self.length)

    def _cross_track(self, pts: FloatArray, s: FloatArray) -> FloatArray:
        pp = self.point(s)
        chi = np.asarray(self.tangent_angle(s))
        d = pts - pp
        return -d[..., 0] * np.sin(chi) + d[..., 1] * np.cos(chi)

    def _search_interval(
        self, pts: FloatArray, s_hint: npt.ArrayLike | None, window: float | None
    ) -> tuple[FloatArray, FloatArray]:
        n = pts.shape[0]
        if s_hint is None:
            return np.zeros(n), np.full(n, self.length)
        hint = np.broadcast_to(self._check_s(s_hint), (n,))
        if window is None:
            w = 2.0 * np.hypot(*(pts - self.point(hint)).T)
        else:
            if not (np.isfinite(window) and window >= 0.0):
                raise ValueError(f"window must be a finite distance >= 0 [m], got {window!r}")
            w = np.full(n, float(window))
        w = np.maximum(w, 1e-9 * max(1.0, self.length))
        return np.clip(hint - w, 0.0, self.length), np.clip(hint + w, 0.0, self.length)

    # Generic numerical closest point, in an internal parameter v (s by default). Subclasses
    # can change the parameter (the splines use their interpolation parameter u) through the
    # three hooks below.
    def _v_of_s(self, s: FloatArray) -> FloatArray:
        return s

    def _s_of_v(self, v: FloatArray) -> FloatArray:
        return v

    def _geom(self, v: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Point and (not necessarily unit) derivative ``dp/dv`` at parameter ``v``."""
        chi = np.asarray(self.tangent_angle(v))
        return self.point(v), np.stack([np.cos(chi), np.sin(chi)], axis=-1)

    def _sample_spacing(self) -> float:
        """Spacing [m] of the coarse search: fine enough to land in the right basin."""
        return self.length / 200.0

    def _closest_in(self, pts: FloatArray, lo: FloatArray, hi: FloatArray) -> FloatArray:
        n = pts.shape[0]
        ds = self._sample_spacing()
        m = np.maximum(2, np.ceil((hi - lo) / ds).astype(int) + 1)
        mmax = int(m.max())
        # grid per point: m[i] stations between lo[i] and hi[i] (padded with hi[i])
        frac = np.minimum(np.arange(mmax)[None, :] / np.maximum(m[:, None] - 1, 1), 1.0)
        grid_s = lo[:, None] + (hi - lo)[:, None] * frac
        grid_v = self._v_of_s(grid_s)
        gp, _ = self._geom(grid_v)
        d2 = np.sum((gp - pts[:, None, :]) ** 2, axis=-1)
        j = np.argmin(d2, axis=1)
        rows = np.arange(n)
        a = grid_v[rows, np.maximum(j - 1, 0)]
        b = grid_v[rows, np.minimum(j + 1, mmax - 1)]

        def slope(v: FloatArray) -> FloatArray:
            # (p - p(v)) . p'(v): positive while the distance still decreases with v
            pv, dv = self._geom(v)
            return np.sum((pts - pv) * dv, axis=-1)

        fa, fb = slope(a), slope(b)
        bracket = (fa > 0.0) & (fb < 0.0)
        x0, x1 = a.copy(), b.copy()
        for _ in range(50):
            mid = 0.5 * (x0 + x1)
            fm = slope(mid)
            up = fm > 0.0
            x0 = np.where(up, mid, x0)
            x1 = np.where(up, x1, mid)
        root = np.where(bracket, 0.5 * (x0 + x1), a)
        cand = np.stack([root, a, b, grid_v[rows, j]], axis=1)
        cp, _ = self._geom(cand)
        best = np.argmin(np.sum((cp - pts[:, None, :]) ** 2, axis=-1), axis=1)
        v = cand[rows, best]
        return np.clip(self._s_of_v(v), lo, hi)


class _PiecewisePath(Path):
    """Paths made of straight lines and circular arcs (exact geometry).

    Piece ``k`` starts at station ``s0[k]`` at point ``a[k]`` with path angle ``chi0[k]``;
    lines have ``turn[k] = 0``; arcs have radius ``R``, turn direction ``turn[k] = +1``
    (clockwise, starboard) or ``-1`` (port) and centre ``c[k]``, so that on an arc
    ``chi = chi0 + turn (s - s0) / R`` and ``p = c + R (cos phi, sin phi)`` with
    ``phi = chi - turn pi / 2``.
    """

    def _set_pieces(self, pieces: list[tuple[FloatArray, float, float, int, float]]) -> None:
        """Store pieces given as ``(start point, start angle, length, turn, radius)``."""
        self._a = np.array([pc[0] for pc in pieces], dtype=np.float64)
        self._chi0 = np.array([pc[1] for pc in pieces], dtype=np.float64)
        self._plen = np.array([pc[2] for pc in pieces], dtype=np.float64)
        self._turn = np.array([pc[3] for pc in pieces], dtype=np.float64)
        self._rad = np.array([pc[4] if pc[3] else 1.0 for pc in pieces], dtype=np.float64)
        self._s0 = np.concatenate([[0.0], np.cumsum(self._plen)[:-1]])
        self._length = float(np.sum(self._plen))
        normal = np.stack([-np.sin(self._chi0), np.cos(self._chi0)], axis=-1)
        self._c = self._a + (self._turn * self._rad)[:, None] * normal

    @property
    def length(self) -> float:
        return self._length

    def _piece(self, s: FloatArray) -> FloatArray:
        k = np.searchsorted(self._s0, s, side="right") - 1
        return np.clip(k, 0, self._s0.size - 1)

    def _eval(self, k: FloatArray, ds: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Point and path angle of piece(s) ``k`` at local arc length ``ds``."""
        turn, rad = self._turn[k], self._rad[k]
        chi = self._chi0[k] + turn * ds / rad
        line = self._a[k] + ds[..., None] * np.stack(
            [np.cos(self._chi0[k]), np.sin(self._chi0[k])], axis=-1
        )
        phi = chi - turn * (0.5 * math.pi)
        arc = self._c[k] + rad[..., None] * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
        pt = np.where((turn == 0.0)[..., None], line, arc)
        return pt, chi

    def point(self, s: npt.ArrayLike) -> FloatArray:
        s_arr = self._check_s(s)
        k = self._piece(s_arr)
        pt, _ = self._eval(k, s_arr - self._s0[k])
        return pt

    def tangent_angle(self, s: npt.ArrayLike) -> FloatArray | float:
        s_arr = self._check_s(s)
        k = self._piece(s_arr)
        _, chi = self._eval(k, s_arr - self._s0[k])
        out = ssa_array(chi)
        return float(out) if out.ndim == 0 else out

    def curvature(self, s: npt.ArrayLike) -> FloatArray | float:
        s_arr = self._check_s(s)
        k = self._piece(s_arr)
        out = self._turn[k] / self._rad[k]
        return float(out) if np.ndim(out) == 0 else out

    def _closest_in(self, pts: FloatArray, lo: FloatArray, hi: FloatArray) -> FloatArray:
        # every point (rows) against every piece (columns), restricted to [lo, hi]
        s0, plen = self._s0[None, :], self._plen[None, :]
        wlo = np.clip(lo[:, None] - s0, 0.0, plen)
        whi = np.clip(hi[:, None] - s0, 0.0, plen)
        valid = (hi[:, None] >= s0) & (lo[:, None] <= s0 + plen)
        d = pts[:, None, :] - self._a[None, :, :]
        u = np.stack([np.cos(self._chi0), np.sin(self._chi0)], axis=-1)[None]
        t_line = np.sum(d * u, axis=-1)
        dc = pts[:, None, :] - self._c[None, :, :]
        phi_p = np.arctan2(dc[..., 1], dc[..., 0])
        phi0 = self._chi0 - self._turn * (0.5 * math.pi)
        t_arc = self._rad * np.mod(self._turn * (phi_p - phi0), _TWO_PI)
        t_proj = np.where(self._turn == 0.0, t_line, t_arc)
        inside = (t_proj >= wlo) & (t_proj <= whi)
        # lines: clamping the projection is exact; arcs: projection if inside, else an end
        t1 = np.where(self._turn == 0.0, np.clip(t_proj, wlo, whi), np.where(inside, t_proj, wlo))
        k = np.broadcast_to(np.arange(self._s0.size)[None, :], t1.shape)
        best_t = t1
        best_d = np.full(t1.shape, np.inf)
        for cand in (t1, wlo, whi):
            cp, _ = self._eval(k, cand)
            dist = np.sum((cp - pts[:, None, :]) ** 2, axis=-1)
            better = dist < best_d
            best_t = np.where(better, cand, best_t)
            best_d = np.where(better, dist, best_d)
        best_d = np.where(valid, best_d, np.inf)
        col = np.argmin(best_d, axis=1)
        rows = np.arange(pts.shape[0])
        s = self._s0[col] + best_t[rows, col]
        return np.clip(s, lo, hi)


class WaypointPath(_PiecewisePath):
    """Straight legs between consecutive waypoints (piecewise linear, seed 004 fig. 10).

    Curvature is zero everywhere; the path angle jumps at the waypoints (at a waypoint's
    station ``tangent_angle`` returns the angle of the *next* leg, at the end that of the last).

    Parameters
    ----------
    waypoints : array_like
        ``(n, 2)`` waypoints (north, east) [m], ``n >= 2``, finite, consecutive ones distinct.

    Examples
    --------
    >>> path = WaypointPath([[0, 0], [300, 0], [300, 400]])
    >>> path.length
    700.0
    >>> path.closest([100.0, 20.0])
    (100.0, 20.0)
    """

    def __init__(self, waypoints: npt.ArrayLike) -> None:
        super().__init__(waypoints)
        wp = self._waypoints
        diff = np.diff(wp, axis=0)
        self._leg_lengths = np.hypot(diff[:, 0], diff[:, 1])
        self._leg_angles = np.arctan2(diff[:, 1], diff[:, 0])
        self._set_pieces(
            [
                (wp[i], float(self._leg_angles[i]), float(self._leg_lengths[i]), 0, math.inf)
                for i in range(len(diff))
            ]
        )
        self._wp_s = np.concatenate([[0.0], np.cumsum(self._leg_lengths)])

    @property
    def waypoint_s(self) -> FloatArray:
        return self._wp_s.copy()

    @property
    def leg_lengths(self) -> FloatArray:
        """Length [m] of each leg, shape ``(n - 1,)``."""
        return self._leg_lengths.copy()

    @property
    def leg_angles(self) -> FloatArray:
        """Path angle ``chi_p`` [rad] of each leg, shape ``(n - 1,)``."""
        return self._leg_angles.copy()

    def __repr__(self) -> str:
        return f"WaypointPath({len(self._waypoints)} waypoints, length={self.length:.1f} m)"


class FilletPath(_PiecewisePath):
    """Straight lines joined by circular arcs of one turning radius (seed 004 fig. 10).

    At each inner waypoint ``w_i`` with course change ``theta_i`` (``|theta_i| < pi``) the
    corner is cut by an arc of radius ``R`` tangent to both legs; it starts and ends
    ``R tan(|theta_i| / 2)`` before and after the waypoint. The path is tangent-continuous;
    its curvature is ``+1/R`` (starboard turn) or ``-1/R`` (port turn) on the arcs and 0 on the
    lines, and its length is::

        sum(leg lengths) - sum_i (2 R tan(|theta_i| / 2) - R |theta_i|).

    Parameters
    ----------
    waypoints : array_like
        ``(n, 2)`` waypoints (north, east) [m], ``n >= 2``, finite, consecutive ones distinct.
    turning_radius : float
        Arc radius ``R`` [m] > 0; pick it at least the ship's turning radius.

    Raises
    ------
    ValueError
        If the arcs at the two ends of a leg do not fit on it (naming the corner), if a corner
        reverses the direction (``|theta| = pi``) or on bad waypoints/radius.
    """

    def __init__(self, waypoints: npt.ArrayLike, turning_radius: float) -> None:
        super().__init__(waypoints)
        try:
            radius = float(turning_radius)
        except (TypeError, ValueError) as exc:
            raise ValueError(
                f"turning_radius must be a positive number [m], got {turning_radius!r}"
            ) from exc
        if not (math.isfinite(radius) and radius > 0.0):
            raise ValueError(f"turning_radius must be positive and finite [m], got {radius!r}")
        self._radius = radius
        wp = self._waypoints
        diff = np.diff(wp, axis=0)
        legs = np.hypot(diff[:, 0], diff[:, 1])
        chi = np.arctan2(diff[:, 1], diff[:, 0])
        theta = np.zeros(len(wp))  # course change at each waypoint (0 at both ends)
        theta[1:-1] = ssa_array(chi[1:] - chi[:-1])
        for i in range(1, len(wp) - 1):
            if abs(abs(theta[i]) - math.pi) < 1e-9:
                raise ValueError(
                    f"corner at waypoint {i} {wp[i].tolist()} reverses the direction (course "
                    "change 180 deg): no arc can join these legs"
                )
        theta[np.abs(theta) < 1e-12] = 0.0
        tan_len = radius * np.tan(0.5 * np.abs(theta))
        for j in range(len(legs)):
            need = tan_len[j] + tan_len[j + 1]
            if need > legs[j] * (1.0 + 1e-12):
                corner = j if tan_len[j] >= tan_len[j + 1] else j + 1
                raise ValueError(
                    f"turning_radius {radius:g} m does not fit corner at waypoint {corner} "
                    f"{wp[corner].tolist()}: the arcs at waypoints {j} and {j + 1} need "
                    f"{need:.6g} m of leg {j} ({wp[j].tolist()} -> {wp[j + 1].tolist()}), "
                    f"which is only {legs[j]:.6g} m long; use a smaller radius or move the "
                    "waypoints apart"
                )
        self._theta = theta
        pieces: list[tuple[FloatArray, float, float, int, float]] = []
        station: list[float] = [0.0]
        s = 0.0
        start = wp[0]
        for j in range(len(legs)):
            u = np.array([math.cos(chi[j]), math.sin(chi[j])])
            end = wp[j + 1] - tan_len[j + 1] * u
            line_len = float(np.hypot(*(end - start)))
            if line_len > 0.0:
                pieces.append((start, float(chi[j]), line_len, 0, math.inf))
                s += line_len
            if j + 1 < len(wp) - 1:  # an inner corner follows
                th = float(theta[j + 1])
                if th == 0.0:
                    station.append(s)
                else:
                    arc_len = radius * abs(th)
                    pieces.append((end, float(chi[j]), arc_len, int(np.sign(th)), radius))
                    station.append(s + 0.5 * arc_len)
                    s += arc_len
                u_next = np.array([math.cos(chi[j + 1]), math.sin(chi[j + 1])])
                start = wp[j + 1] + tan_len[j + 1] * u_next
        self._set_pieces(pieces)
        station.append(self._length)
        self._wp_s = np.array(station)

    @property
    def turning_radius(self) -> float:
        """Arc radius ``R`` [m]."""
        return self._radius

    @property
    def course_changes(self) -> FloatArray:
        """Signed course change ``theta_i`` [rad] at each waypoint (0 at the two ends)."""
        return self._theta.copy()

    @property
    def waypoint_s(self) -> FloatArray:
        return self._wp_s.copy()

    def __repr__(self) -> str:
        return (
            f"FilletPath({len(self._waypoints)} waypoints, turning_radius={self._radius:g} m, "
            f"length={self.length:.1f} m)"
        )


class SplinePath(Path):
    """Interpolating PCHIP or cubic spline through the waypoints (seed 004 fig. 10).

    The coordinates are interpolated as functions of the cumulative chord length ``u`` of the
    waypoints (``scipy.interpolate.PchipInterpolator`` or ``CubicSpline`` with not-a-knot
    ends). The arc length ``s(u) = int_0^u |p'(v)| dv`` is integrated with 8-point
    Gauss-Legendre quadrature on 32 sub-intervals per waypoint interval; ``s -> u`` is its
    monotone inverse (safeguarded Newton iterations), so ``point(s)`` moves at unit speed.

    PCHIP keeps each coordinate monotone between waypoints (no overshoot) but sets both
    derivatives to zero at a waypoint where both coordinates have an extremum (for example an
    axis-aligned right-angle corner); the curve has a kink there, its path angle is taken
    from the second derivative and its curvature is ``nan``. The cubic spline is
    curvature-continuous but may overshoot.

    Parameters
    ----------
    waypoints : array_like
        ``(n, 2)`` waypoints (north, east) [m], ``n >= 2``, finite, consecutive ones distinct.
    kind : {"pchip", "cubic"}
        The interpolant.
    """

    _SUB = 32  # sub-intervals per waypoint interval for the arc-length table

    def __init__(self, waypoints: npt.ArrayLike, kind: str = "pchip") -> None:
        super().__init__(waypoints)
        if kind not in ("pchip", "cubic"):
            raise ValueError(f"kind must be 'pchip' or 'cubic', got {kind!r}")
        self._kind = kind
        wp = self._waypoints
        legs = np.hypot(*np.diff(wp, axis=0).T)
        self._knots = np.concatenate([[0.0], np.cumsum(legs)])
        if kind == "pchip":
            self._f = PchipInterpolator(self._knots, wp, axis=0)
        else:
            self._f = CubicSpline(self._knots, wp, axis=0, bc_type="not-a-knot")
        self._d1 = self._f.derivative(1)
        self._d2 = self._f.derivative(2)
        k = self._knots
        sub = np.linspace(0.0, 1.0, self._SUB + 1)
        self._ug = np.concatenate(
            [k[i] + (k[i + 1] - k[i]) * sub[:-1] for i in range(len(k) - 1)] + [k[-1:]]
        )
        pieces = self._gl(self._ug[:-1], self._ug[1:])
        self._sg = np.concatenate([[0.0], np.cumsum(pieces)])
        self._length = float(self._sg[-1])
        self._wp_s = self._sg[:: self._SUB].copy()
        self._min_leg = float(np.min(legs))

    # ------------------------------------------------------------ arc length and its inverse
    def _speed(self, u: FloatArray) -> FloatArray:
        d = self._d1(u)
        return np.hypot(d[..., 0], d[..., 1])

    def _gl(self, u0: FloatArray, u1: FloatArray) -> FloatArray:
        """``int_u0^u1 |p'(u)| du`` by Gauss-Legendre (elementwise)."""
        h = (u1 - u0)[..., None]
        nodes = u0[..., None] + h * _GL_X
        return np.sum(self._speed(nodes) * _GL_W, axis=-1) * h[..., 0]

    def _s_of_u(self, u: FloatArray) -> FloatArray:
        u = np.clip(np.asarray(u, dtype=np.float64), 0.0, self._knots[-1])
        i = np.clip(np.searchsorted(self._ug, u, side="right") - 1, 0, self._ug.size - 2)
        return self._sg[i] + self._gl(self._ug[i], u)

    def _u_of_s(self, s: FloatArray) -> FloatArray:
        s = np.asarray(s, dtype=np.float64)
        i = np.clip(np.searchsorted(self._sg, s, side="right") - 1, 0, self._sg.size - 2)
        u0, u1 = self._ug[i], self._ug[i + 1]
        s0, s1 = self._sg[i], self._sg[i + 1]
        lo, hi = u0.copy(), u1.copy()
        u = u0 + (u1 - u0) * np.clip((s - s0) / np.maximum(s1 - s0, 1e-300), 0.0, 1.0)
        tol = 1e-12 * max(1.0, self._length)
        for _ in range(60):
            g = s0 + self._gl(u0, u) - s
            if np.all(np.abs(g) <= tol):
                break
            lo = np.where(g < 0.0, u, lo)
            hi = np.where(g > 0.0, u, hi)
            sp = self._speed(u)
            with np.errstate(divide="ignore", invalid="ignore"):
                un = u - g / sp
            ok = np.isfinite(un) & (un >= lo) & (un <= hi)
            u = np.where(np.abs(g) <= tol, u, np.where(ok, un, 0.5 * (lo + hi)))
        return u

    # ------------------------------------------------------------ interface
    @property
    def kind(self) -> str:
        """``"pchip"`` or ``"cubic"``."""
        return self._kind

    @property
    def length(self) -> float:
        return self._length

    @property
    def waypoint_s(self) -> FloatArray:
        return self._wp_s.copy()

    def point(self, s: npt.ArrayLike) -> FloatArray:
        u = self._u_of_s(self._check_s(s))
        return np.asarray(self._f(u), dtype=np.float64)

    def _direction(self, u: FloatArray) -> FloatArray:
        d1 = self._d1(u)
        sp = np.hypot(d1[..., 0], d1[..., 1])
        stalled = sp <= 1e-9
        if np.any(stalled):  # PCHIP kink: p' = 0, direction from p''
            d1 = np.where(stalled[..., None], self._d2(u), d1)
        return d1

    def tangent_angle(self, s: npt.ArrayLike) -> FloatArray | float:
        u = self._u_of_s(self._check_s(s))
        d = self._direction(u)
        out = ssa_array(np.arctan2(d[..., 1], d[..., 0]))
        return float(out) if out.ndim == 0 else out

    def curvature(self, s: npt.ArrayLike) -> FloatArray | float:
        u = self._u_of_s(self._check_s(s))
        d1, d2 = self._d1(u), self._d2(u)
        sp = np.hypot(d1[..., 0], d1[..., 1])
        cross = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            out = np.where(sp > 1e-9, cross / sp**3, np.nan)
        return float(out) if out.ndim == 0 else out

    # generic closest point in the spline parameter u (no s -> u inversion per iteration)
    def _v_of_s(self, s: FloatArray) -> FloatArray:
        return self._u_of_s(s)

    def _s_of_v(self, v: FloatArray) -> FloatArray:
        return self._s_of_u(v)

    def _geom(self, v: FloatArray) -> tuple[FloatArray, FloatArray]:
        return np.asarray(self._f(v), dtype=np.float64), self._direction(v)

    def _sample_spacing(self) -> float:
        return min(self.length / 200.0, self._min_leg / 16.0)

    def __repr__(self) -> str:
        return (
            f"SplinePath({len(self._waypoints)} waypoints, kind={self._kind!r}, "
            f"length={self.length:.1f} m)"
        )

"""Kinematic consistency of a record: do its rate channels integrate to its heading and track?

A record measures the same motion twice: the heading ``psi`` and its rate ``r``, the positions
``x, y`` and the body velocities ``u, v``. Their kinematic equations (the yaw and the
north/east rows of ``eta' = R(psi) nu``, Fossen 2021 eq. 2.40 and 2.62)::

    psi' = r,    x' = u cos(psi) - v sin(psi),    y' = u sin(psi) + v cos(psi)

hold whatever the ship's dynamics. Integrated from the measured state at the start of each
window, the rate channels must reproduce the heading and the track up to their sensors' noise.
What they miss binds every model fitted to both: its heading error and the integral of its
yaw-rate error add up to at least it (``psi_model - psi = integral of (r_model - r) +
(psi(t0) + integral of r - psi)``), so a model that predicted the measured ``r`` exactly would
miss the measured heading by it, and one that met the heading would miss the yaw rate. The
integrated white noise of ``r`` is part of it without binding a model, whose rate is smooth; a
scale or timing error of a channel binds. This is the *data compatibility check* of
flight-test identification (Klein and Morelli, *Aircraft System Identification*, AIAA 2006,
chapter 10), where the rates' scale factors and biases are estimated before any model is
fitted. Here the scale factors are estimated per window: a channel timed on another clock shows
as a scale that varies from window to window, a unit slip (knots taken with the wrong factor) as
one that does not.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid

from shipgym.sysid.record import Record

__all__ = ["MIN_TURN", "KinematicConsistency", "kinematic_consistency"]

MIN_TURN = math.radians(10.0)
"""Smallest heading change [rad] over a window for its yaw-rate scale to be estimated."""


@dataclass(frozen=True)
class KinematicConsistency:
    """What a record's rate channels miss of its heading and track, window by window.

    Attributes
    ----------
    starts : numpy.ndarray
        Index of each window's first sample.
    heading_rms : numpy.ndarray
        Per window, the RMS [rad] of ``psi(t0) + integral of r - psi`` over its samples after
        the first.
    position_rms : numpy.ndarray or None
        Per window, the RMS [m] of the distance between the track integrated from ``u, v`` (with
        the measured heading) and the measured positions; None without ``x, y, u, v``.
    yaw_rate_scale : numpy.ndarray
        Per window, the factor on ``r`` that makes its integral fit the heading change best
        (least squares); NaN where the heading changes by less than :data:`MIN_TURN`.
    speed_scale : numpy.ndarray or None
        Per window, the factor on ``u, v`` that makes the integrated track fit the measured one
        best; None without ``x, y, u, v``.
    samples : numpy.ndarray
        Per window, the number of samples compared (all but its first).
    """

    starts: np.ndarray
    heading_rms: np.ndarray
    position_rms: np.ndarray | None
    yaw_rate_scale: np.ndarray
    speed_scale: np.ndarray | None
    samples: np.ndarray

    def pooled_heading_rms(self, windows: np.ndarray | None = None) -> float:
        """The heading RMS [rad] over the samples of ``windows`` (a boolean mask or indices of
        the windows; all by default), each window weighted by its samples."""
        return _pooled(self.heading_rms, self.samples, windows)

    def pooled_position_rms(self, windows: np.ndarray | None = None) -> float:
        """The position RMS [m] over the samples of ``windows``; NaN without positions."""
        if self.position_rms is None:
            return math.nan
        return _pooled(self.position_rms, self.samples, windows)


def _pooled(rms: np.ndarray, counts: np.ndarray, windows: np.ndarray | None) -> float:
    sel = np.arange(rms.size) if windows is None else np.asarray(windows)
    w = counts[sel].astype(float)
    return float(np.sqrt(np.sum(w * rms[sel] ** 2) / np.sum(w))) if np.sum(w) else math.nan


def _scale(model: np.ndarray, measured: np.ndarray) -> float:
    """Least-squares factor ``k`` of ``measured ~ k model``."""
    den = float(np.sum(model * model))
    return float(np.sum(model * measured)) / den if den > 0.0 else math.nan


def kinematic_consistency(record: Record, starts: np.ndarray) -> KinematicConsistency:
    """Integrate the record's ``r`` (and ``u, v``) from the measured state at each window start
    and compare with its ``psi`` (and ``x, y``) (module docstring).

    Parameters
    ----------
    record : Record
        The record (its heading continuous, as every loader gives it).
    starts : numpy.ndarray
        Index of the first sample of each window, increasing, the first 0 (for example
        :func:`shipgym.sysid.families.base.window_starts` of the record's time and the
        scoring window); each window ends where the next starts.

    Returns
    -------
    KinematicConsistency

    Raises
    ------
    ValueError
        For window starts that are not increasing indices of the record beginning at 0, or a
        window of fewer than two samples.
    """
    t = record.time
    starts = np.asarray(starts)
    if (
        starts.ndim != 1
        or starts.size == 0
        or not np.issubdtype(starts.dtype, np.integer)
        or starts[0] != 0
        or np.any(np.diff(starts) < 2)
        or starts[-1] > t.size - 2
    ):
        raise ValueError(
            "starts must be increasing sample indices from 0, each window at least two samples "
            f"long, within the record's {t.size} samples; got {starts!r}"
        )
    ends = np.append(starts[1:], t.size)
    track = all(getattr(record, k) is not None for k in ("x", "y", "u", "v"))
    heading_rms, yaw_scale, position_rms, speed_scale = [], [], [], []
    for i0, i1 in zip(starts, ends, strict=True):
        tt, psi = t[i0:i1], record.psi[i0:i1]
        turned = cumulative_trapezoid(record.r[i0:i1], tt, initial=0.0)
        change = psi - psi[0]
        heading_rms.append(math.sqrt(float(np.mean((turned - change)[1:] ** 2))))
        big = float(np.max(np.abs(change))) >= MIN_TURN
        yaw_scale.append(_scale(turned, change) if big else math.nan)
        if track:
            c, s = np.cos(psi), np.sin(psi)
            u, v = record.u[i0:i1], record.v[i0:i1]
            north = cumulative_trapezoid(c * u - s * v, tt, initial=0.0)
            east = cumulative_trapezoid(s * u + c * v, tt, initial=0.0)
            dn, de = record.x[i0:i1] - record.x[i0], record.y[i0:i1] - record.y[i0]
            position_rms.append(
                math.sqrt(float(np.mean(((north - dn) ** 2 + (east - de) ** 2)[1:])))
            )
            speed_scale.append(_scale(np.concatenate((north, east)), np.concatenate((dn, de))))
    return KinematicConsistency(
        starts=starts,
        heading_rms=np.array(heading_rms),
        position_rms=np.array(position_rms) if track else None,
        yaw_rate_scale=np.array(yaw_scale),
        speed_scale=np.array(speed_scale) if track else None,
        samples=ends - starts - 1,
    )

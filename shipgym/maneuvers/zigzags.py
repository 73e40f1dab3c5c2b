"""The zigzag a/b trial (Kempf's Z-manoeuvre; seed 000 "zigzag autopilot").

Definitions of ITTC and IMO MSC/Circ.1053 (Explanatory Notes to MSC.137(76)): rudder to ``a``
(first execute); when the heading change ``psi - psi0`` reaches ``b`` the rudder is reversed
to ``-a`` (second execute), when it reaches ``-b`` back to ``a``, and so on. The overshoot
after each reversal is the heading excursion beyond the check heading ``+-b`` before the swing
stops (``r`` changes sign). Initial turning time: first to second execute. Time to check yaw:
second execute to the first heading peak. Period: mean time between every other reversal (one
full heading cycle). The reversal is applied at the integration step nearest to the crossing
(predicted with the current yaw rate), so the switching error is at most ``|r| dt / 2``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from shipgym.maneuvers._common import (
    ModelLike,
    Rig,
    Run,
    TimeSeries,
    json_deg,
    json_num,
    side_sign,
    wind_json,
)
from shipgym.maneuvers.particulars import ShipParticulars
from shipgym.models.seaway_options import Wind

__all__ = ["ZigZagResult", "zigzag"]


@dataclass(frozen=True, eq=False)
class ZigZagResult:
    """A simulated zigzag ``a/b`` trial (angles in rad, times in s).

    Attributes
    ----------
    model : str
        Model name.
    particulars : ShipParticulars
        Length and speed of the ship.
    approach_speed : float
        Speed at the first execute [m/s].
    rudder : float
        Rudder angle ``a`` [rad].
    heading_check : float
        Heading change ``b`` [rad] at which the rudder is reversed.
    first : str
        ``"starboard"`` or ``"port"``: side of the first rudder execute.
    series : TimeSeries
        Time histories.
    execute_times : tuple of float
        Times of the rudder reversals (second, third, ... execute) [s].
    overshoots : tuple of float
        Overshoot angle after each reversal [rad] (NaN if the swing was not checked).
    overshoot_times : tuple of float
        Times of the heading peaks [s].
    initial_turning_time : float
        First to second execute [s].
    time_to_check_yaw : float
        Second execute to the first heading peak [s].
    period : float
        Mean time between every other reversal [s] (NaN with fewer than three reversals).
    completed : bool
        All requested reversals happened and every swing was checked.
    wind : Wind or None
        The true wind of the trial (:func:`zigzag`'s ``wind``), None in calm air.
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    rudder: float
    heading_check: float
    first: str
    series: TimeSeries
    execute_times: tuple[float, ...]
    overshoots: tuple[float, ...]
    overshoot_times: tuple[float, ...]
    initial_turning_time: float
    time_to_check_yaw: float
    period: float
    completed: bool
    dt: float
    wind: Wind | None = None

    @property
    def overshoots_deg(self) -> tuple[float, ...]:
        """Overshoot angles [deg]."""
        return tuple(math.degrees(o) for o in self.overshoots)

    @property
    def label(self) -> str:
        """``"a/b"`` in degrees, e.g. ``"20/20"``."""
        return f"{math.degrees(self.rudder):g}/{math.degrees(self.heading_check):g}"

    def to_dict(self, include_series: bool = True) -> dict[str, Any]:
        """Metrics (and time series) for JSON; degrees in ``*_deg`` keys."""
        d = {
            "manoeuvre": "zigzag",
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": self.particulars.length,
            "approach_speed_m_s": json_num(self.approach_speed),
            "length_over_speed_s": json_num(self.particulars.length_over_speed),
            "dt_s": self.dt,
            "rudder_deg": json_deg(self.rudder),
            "heading_check_deg": json_deg(self.heading_check),
            "first": self.first,
            "completed": self.completed,
            "overshoots_deg": [json_deg(o) for o in self.overshoots],
            "overshoot_times_s": [json_num(t) for t in self.overshoot_times],
            "execute_times_s": [json_num(t) for t in self.execute_times],
            "initial_turning_time_s": json_num(self.initial_turning_time),
            "time_to_check_yaw_s": json_num(self.time_to_check_yaw),
            "period_s": json_num(self.period),
            "wind": wind_json(self.wind),
        }
        if include_series:
            d["series"] = self.series.to_dict()
        return d


class _ZigZagPilot:
    """Zigzag logic of seed 000 on the unwrapped heading change, nearest-step switching."""

    def __init__(self, rig: Rig, a: float, b: float, sign0: float, n_max: int) -> None:
        self.rig, self.a, self.b = rig, a, b
        self.sign = sign0
        self.psi0 = float(rig.x0[rig.ipsi])
        self.executes: list[float] = []
        self.n_max = n_max

    def __call__(self, t: float, x: np.ndarray) -> float:
        if len(self.executes) < self.n_max:
            # heading change predicted at the middle of the coming step
            h = x[self.rig.ipsi] - self.psi0 + 0.5 * self.rig.dt * x[self.rig.ir]
            if self.sign * h >= self.b:
                self.sign = -self.sign
                self.executes.append(t)
        return self.sign * self.a


def _peak_after(
    time: np.ndarray, h: np.ndarray, r: np.ndarray, t0: float, s: float
) -> tuple[int, float] | None:
    """Sample and value of the heading peak ``s h`` after ``t0`` (where ``s r`` first turns
    <= 0), refined by a parabola through three samples; None if the swing is not checked."""
    i0 = int(np.searchsorted(time, t0 - 1e-9))
    stop = np.nonzero(s * r[i0:] <= 0.0)[0]
    if len(stop) == 0:
        return None
    j = i0 + int(stop[0])
    # the extreme heading up to the stop sample (refined by a parabola through 3 samples)
    k = i0 + int(np.argmax(s * h[i0 : j + 1]))
    peak = s * h[k]
    if 0 < k < len(h) - 1:
        y0, y1, y2 = s * h[k - 1], s * h[k], s * h[k + 1]
        den = y0 - 2 * y1 + y2
        if den < 0:
            peak = y1 - 0.125 * (y2 - y0) ** 2 / den
    return k, float(peak)


def zigzag(
    model: ModelLike = "nomoto1",
    a_deg: float = 20.0,
    b_deg: float | None = None,
    first: str = "starboard",
    n_reversals: int = 4,
    dt: float | None = None,
    max_duration: float | None = None,
    wind: Mapping[str, Any] | None = None,
) -> ZigZagResult:
    """Simulate a zigzag ``a/b`` trial (Kempf's Z-manoeuvre, seed 000).

    Parameters
    ----------
    model : str or ShipModel
        Model name (default parameters) or a model built with :func:`make_model`.
    a_deg : float
        Rudder angle ``a`` [deg], in (0, 35].
    b_deg : float, optional
        Heading change ``b`` [deg] at which the rudder is reversed (default ``a_deg``).
    first : {"starboard", "port"}
        Side of the first rudder execute.
    n_reversals : int
        Rudder reversals to simulate; one overshoot is measured after each.
    dt : float, optional
        Integration step [s] (default 0.1 s).
    max_duration : float, optional
        Longest simulated time [s] (default 4000 s Nomoto, 600 s RVG).
    wind : dict, optional
        A constant true wind from the first execute on, as
        :func:`~shipgym.maneuvers.turning_circle`'s.

    Returns
    -------
    ZigZagResult
        ``completed`` is False when the swing after a reversal was never checked within
        ``max_duration`` (its overshoot is NaN), as for a strongly unstable ship.
    """
    rig = Rig(model, dt, wind)
    a = rig.check_rudder(a_deg, "zigzag rudder angle a_deg")
    b_deg = a_deg if b_deg is None else b_deg
    if not (isinstance(b_deg, int | float) and math.isfinite(b_deg) and 0 < b_deg <= 90):
        raise ValueError(f"zigzag heading change b_deg must be in (0, 90] deg, got {b_deg!r}")
    b = math.radians(b_deg)
    s0 = side_sign(first)
    if not (isinstance(n_reversals, int) and 1 <= n_reversals <= 20):
        raise ValueError(f"n_reversals must be an integer in [1, 20], got {n_reversals!r}")
    limit = _duration(max_duration, rig.settings.max_duration)
    pilot = _ZigZagPilot(rig, a, b, s0, n_reversals)
    run = Run(rig, pilot)
    chunk = min(rig.settings.chunk, 0.5 * limit)
    s_last = s0 if (n_reversals - 1) % 2 == 0 else -s0  # swing direction at the last reversal
    while run.t < limit:
        run.advance(chunk)
        if len(pilot.executes) == n_reversals:
            sim = run.result()
            h = sim["psi"] - pilot.psi0
            if _peak_after(sim.time, h, sim["r"], pilot.executes[-1], s_last) is not None:
                run.advance(0.1 * run.t)  # a margin after the last peak (for the figure)
                break
    series = rig.series(run.result())
    h = series.psi - pilot.psi0
    executes = pilot.executes[:n_reversals]
    overshoots: list[float] = []
    peak_times: list[float] = []
    for k, te in enumerate(executes):
        s = s0 if k % 2 == 0 else -s0  # swing direction at reversal k
        found = _peak_after(series.time, h, series.r, te, s)
        if found is None:
            overshoots.append(math.nan)
            peak_times.append(math.nan)
            break
        j, peak = found
        overshoots.append(float(peak - b))
        peak_times.append(float(series.time[j]))
    completed = len(executes) == n_reversals and len(overshoots) == n_reversals
    completed = completed and all(math.isfinite(o) for o in overshoots)
    # crop a little after the last measured peak
    last = [t for t in (*peak_times, *executes) if math.isfinite(t)]
    if completed and last:
        t_end = 1.06 * max(last)
        series = series.crop(int(np.searchsorted(series.time, t_end)) + 1)
    period = math.nan
    if len(executes) >= 3:
        period = float(np.mean(np.subtract(executes[2:], executes[:-2])))
    return ZigZagResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        rudder=a,
        heading_check=b,
        first=first,
        series=series,
        execute_times=tuple(float(t) for t in executes),
        overshoots=tuple(overshoots),
        overshoot_times=tuple(peak_times),
        initial_turning_time=float(executes[0]) if executes else math.nan,
        time_to_check_yaw=(peak_times[0] - executes[0] if executes and peak_times else math.nan),
        period=period,
        completed=completed,
        dt=rig.dt,
        wind=rig.wind,
    )


def _duration(value: float | None, default: float) -> float:
    if value is None:
        return default
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise ValueError(f"max_duration must be a finite time > 0 s, got {value!r}")
    return float(value)

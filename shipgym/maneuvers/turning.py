"""The turning circle and the initial turning test.

* **Turning circle** (seed 002 Fig. 1 and Table 1: approach, first, second and third phase):
  rudder to ``delta`` from straight running and held. Advance: distance along the approach
  course from the position at the rudder execute to the position where the heading has
  changed 90 deg; transfer: distance across it at 90 deg; tactical diameter: transfer at
  180 deg; steady turning diameter: least-squares (Kasa) circle through the track over one
  full turn after the yaw rate and speed have settled (third phase); speed ratio: steady
  speed / approach speed (seed 002 Table 3 gives the speed against the heading change,
  reported here every 10 deg up to 180 deg).
* **Initial turning** (IMO MSC.137(76) 5.3.2, explanatory notes MSC/Circ.1053): 10 deg rudder;
  the distance travelled along the track by the time the heading has changed 10 deg.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from shipgym.maneuvers._common import (
    ModelLike,
    Rig,
    Run,
    TimeSeries,
    crossing,
    hold_until_steady,
    json_deg,
    json_num,
    side_sign,
    value_at,
    wind_json,
)
from shipgym.maneuvers.particulars import ShipParticulars
from shipgym.models.seaway_options import Wind

__all__ = ["InitialTurningResult", "TurningResult", "initial_turning", "turning_circle"]


def _fit_circle(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Least-squares (Kasa) circle through the points: centre (x, y) and radius."""
    A = np.column_stack([2 * x, 2 * y, np.ones_like(x)])
    rhs = x * x + y * y
    (cx, cy, c), *_ = np.linalg.lstsq(A, rhs, rcond=None)
    return float(cx), float(cy), float(math.sqrt(c + cx * cx + cy * cy))


@dataclass(frozen=True, eq=False)
class TurningResult:
    """A simulated turning circle (lengths in m, angles in rad, times in s).

    Attributes
    ----------
    model, particulars, approach_speed, rudder, side, series
        As in :class:`ZigZagResult`; ``rudder`` is the (positive) rudder angle [rad].
    advance : float
        Distance along the approach course at 90 deg heading change [m].
    transfer : float
        Distance across the approach course, toward the turn, at 90 deg heading change [m].
    tactical_diameter : float
        Transfer at 180 deg heading change [m].
    steady_diameter : float
        Diameter of the least-squares circle through one full steady turn [m].
    steady_center : tuple of float
        Its centre (north, east) [m].
    steady_yaw_rate : float
        Mean yaw rate in the steady turn [rad/s] (signed: + starboard).
    steady_speed : float
        Mean speed through the water in the steady turn [m/s].
    speed_ratio : float
        ``steady_speed / approach_speed`` (1 - speed loss).
    time_to_90, time_to_180 : float
        Times of the 90 and 180 deg heading changes [s].
    points : dict
        Positions (north, east) [m] at the execute, 90 and 180 deg.
    heading_changes, speeds : numpy.ndarray
        Speed [m/s] at heading changes of 10, 20, ..., 180 deg [rad] (seed 002 Table 3).
    rudder_time, steady_time : float
        End of the first phase (rudder at its order) and start of the third (steady) phase
        (``|r - r_steady|`` < 2 % from then on) [s] (seed 002 Table 1).
    steady : bool
        Yaw rate and speed settled within the longest hold.
    drift : tuple of float
        Displacement (north, east) [m] of the ship over the fitted full steady turn: from a
        heading to the same heading one turn later. Zero in calm water; in a current or wind it
        is the drift that the classic trial correction removes from a turning circle (ITTC
        Recommended Procedure 7.5-04-01-01.2, the drift over one loop).
    drift_speed, drift_direction : float
        That drift over the turn's duration [m/s] and the direction it goes toward [rad],
        clockwise from north (NaN without drift).
    wind : Wind or None
        The true wind of the trial (:func:`turning_circle`'s ``wind``), None in calm air.
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    rudder: float
    side: str
    series: TimeSeries
    advance: float
    transfer: float
    tactical_diameter: float
    steady_diameter: float
    steady_center: tuple[float, float]
    steady_yaw_rate: float
    steady_speed: float
    speed_ratio: float
    time_to_90: float
    time_to_180: float
    points: dict[str, tuple[float, float]]
    heading_changes: np.ndarray
    speeds: np.ndarray
    rudder_time: float
    steady_time: float
    steady: bool
    dt: float
    drift: tuple[float, float] = (0.0, 0.0)
    drift_speed: float = 0.0
    drift_direction: float = math.nan
    wind: Wind | None = None

    def to_dict(self, include_series: bool = True) -> dict[str, Any]:
        """Metrics (and time series) for JSON; degrees in ``*_deg`` keys."""
        L = self.particulars.length
        d = {
            "manoeuvre": "turning_circle",
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": L,
            "approach_speed_m_s": json_num(self.approach_speed),
            "length_over_speed_s": json_num(self.particulars.length_over_speed),
            "dt_s": self.dt,
            "rudder_deg": json_deg(self.rudder),
            "side": self.side,
            "advance_m": json_num(self.advance),
            "transfer_m": json_num(self.transfer),
            "tactical_diameter_m": json_num(self.tactical_diameter),
            "steady_diameter_m": json_num(self.steady_diameter),
            "advance_L": json_num(self.advance / L),
            "transfer_L": json_num(self.transfer / L),
            "tactical_diameter_L": json_num(self.tactical_diameter / L),
            "steady_diameter_L": json_num(self.steady_diameter / L),
            "steady_yaw_rate_deg_s": json_deg(self.steady_yaw_rate),
            "steady_speed_m_s": json_num(self.steady_speed),
            "speed_ratio": json_num(self.speed_ratio),
            "speed_loss": json_num(1.0 - self.speed_ratio),
            "time_to_90_deg_s": json_num(self.time_to_90),
            "time_to_180_deg_s": json_num(self.time_to_180),
            "rudder_at_order_time_s": json_num(self.rudder_time),
            "steady_time_s": json_num(self.steady_time),
            "steady": self.steady,
            "drift_m": [json_num(self.drift[0]), json_num(self.drift[1])],
            "drift_speed_m_s": json_num(self.drift_speed),
            "drift_direction_deg": json_deg(self.drift_direction),
            "wind": wind_json(self.wind),
            "speed_vs_heading_change": {
                "heading_change_deg": [json_deg(h) for h in self.heading_changes],
                "speed_m_s": [json_num(v) for v in self.speeds],
            },
        }
        if include_series:
            d["series"] = self.series.to_dict()
        return d


def turning_circle(
    model: ModelLike = "nomoto1",
    rudder_deg: float = 35.0,
    side: str = "starboard",
    dt: float | None = None,
    wind: Mapping[str, Any] | None = None,
) -> TurningResult:
    """Simulate a turning circle with ``rudder_deg`` to ``side``.

    The rudder is put over at t = 0 from straight running and held. The run goes on until the
    heading has changed 180 deg and the yaw rate and speed have settled, and then for one
    more full turn, through which the steady turning circle is fitted.

    Parameters
    ----------
    model : str or ShipModel
        Model name or model.
    rudder_deg : float
        Rudder angle [deg], in (0, 35].
    side : {"starboard", "port"}
        Turn direction.
    dt : float, optional
        Integration step [s].
    wind : dict, optional
        A constant true wind from the first execute on: ``speed`` [m/s], ``direction`` (where
        it comes FROM [rad], clockwise from north) and ``gusts`` (default False), the env's
        ``wind`` option (:mod:`shipgym.models.seaway_options`); its drift over the steady turn is
        :attr:`TurningResult.drift`. For the Nomoto family (the Mariner), ``rvg3dof``,
        ``kvlcc2`` and a ``vmm`` with identified wind terms.

    Returns
    -------
    TurningResult

    Raises
    ------
    ValueError
        For bad arguments, or if the heading never changes 180 deg within the longest hold.
    """
    rig = Rig(model, dt, wind)
    delta = rig.check_rudder(rudder_deg, "turning circle rudder_deg")
    s = side_sign(side)
    run = Run(rig, lambda t, x: s * delta)
    psi0 = float(rig.x0[rig.ipsi])

    def turned(angle: float) -> Callable[[], bool]:
        return lambda: s * (run.x[rig.ipsi] - psi0) >= angle

    steady, _ = hold_until_steady(run, rig, extra=turned(math.pi))
    if not turned(math.pi)():
        raise ValueError(
            f"{rig.name} did not turn 180 deg within {rig.settings.max_hold:g} s "
            f"with {rudder_deg:g} deg rudder"
        )
    t_steady = run.t
    h_start = s * (run.x[rig.ipsi] - psi0)
    while s * (run.x[rig.ipsi] - psi0) < h_start + 2 * math.pi:
        run.advance(rig.settings.chunk / 5)
    series = rig.series(run.result())
    h = s * (series.psi - psi0)
    c90, c180 = crossing(h, 0.5 * math.pi), crossing(h, math.pi)
    assert c90 is not None and c180 is not None
    n0, e0 = float(series.x[0]), float(series.y[0])
    along = (series.x - n0) * math.cos(psi0) + (series.y - e0) * math.sin(psi0)
    across = s * (-(series.x - n0) * math.sin(psi0) + (series.y - e0) * math.cos(psi0))
    i_s = int(np.searchsorted(series.time, t_steady - 1e-9))
    end = crossing(h, h_start + 2 * math.pi)
    i_e = end[0] if end is not None else len(h) - 1
    cx, cy, radius = _fit_circle(series.x[i_s : i_e + 1], series.y[i_s : i_e + 1])
    # from the heading at the start of the steady turn to the same heading one turn later
    x_e, y_e, t_e = (
        (series.x[i_e], series.y[i_e], series.time[i_e])
        if end is None
        else (value_at(series.x, end), value_at(series.y, end), value_at(series.time, end))
    )
    drift = (float(x_e - series.x[i_s]), float(y_e - series.y[i_s]))
    drift_speed = math.hypot(*drift) / float(t_e - series.time[i_s])
    drift_direction = math.atan2(drift[1], drift[0]) if drift_speed > 0.0 else math.nan
    r_ss = float(np.mean(series.r[i_s : i_e + 1]))
    v_ss = float(np.mean(series.speed[i_s : i_e + 1]))
    changes = np.radians(np.arange(10.0, 181.0, 10.0))
    crossings = [crossing(h, c) for c in changes]
    speeds = np.array([math.nan if c is None else value_at(series.speed, c) for c in crossings])
    at_order = np.nonzero(np.abs(series.delta - s * delta) <= 0.01 * delta)[0]
    outside = np.nonzero(np.abs(series.r - r_ss) > 0.02 * abs(r_ss))[0]
    t_steady3 = float(series.time[min(outside[-1] + 1, len(h) - 1)]) if len(outside) else 0.0
    return TurningResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        rudder=delta,
        side=side,
        series=series,
        advance=value_at(along, c90),
        transfer=value_at(across, c90),
        tactical_diameter=value_at(across, c180),
        steady_diameter=2.0 * radius,
        steady_center=(cx, cy),
        steady_yaw_rate=r_ss,
        steady_speed=v_ss,
        speed_ratio=v_ss / rig.approach_speed,
        time_to_90=value_at(series.time, c90),
        time_to_180=value_at(series.time, c180),
        points={
            "execute": (n0, e0),
            "heading_90": (value_at(series.x, c90), value_at(series.y, c90)),
            "heading_180": (value_at(series.x, c180), value_at(series.y, c180)),
        },
        heading_changes=changes,
        speeds=speeds,
        rudder_time=float(series.time[at_order[0]]) if len(at_order) else math.nan,
        steady_time=t_steady3,
        steady=steady,
        dt=rig.dt,
        drift=drift,
        drift_speed=drift_speed,
        drift_direction=drift_direction,
        wind=rig.wind,
    )


@dataclass(frozen=True, eq=False)
class InitialTurningResult:
    """Initial turning ability: distance travelled until the heading has changed ``heading``.

    Attributes
    ----------
    model, particulars, approach_speed, rudder, side, series, wind
        As in :class:`TurningResult`.
    heading : float
        Heading change [rad] at which the distance is measured (10 deg).
    distance : float
        Distance travelled along the track from the execute [m].
    advance : float
        Distance along the approach course at that moment [m].
    time : float
        Time of the heading change [s].
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    rudder: float
    side: str
    heading: float
    distance: float
    advance: float
    time: float
    series: TimeSeries
    dt: float
    wind: Wind | None = None

    def to_dict(self, include_series: bool = False) -> dict[str, Any]:
        """Metrics (and time series) for JSON."""
        d = {
            "manoeuvre": "initial_turning",
            "model": self.model,
            "rudder_deg": json_deg(self.rudder),
            "side": self.side,
            "heading_change_deg": json_deg(self.heading),
            "distance_m": json_num(self.distance),
            "distance_L": json_num(self.distance / self.particulars.length),
            "advance_m": json_num(self.advance),
            "time_s": json_num(self.time),
            "wind": wind_json(self.wind),
        }
        if include_series:
            d["series"] = self.series.to_dict()
        return d


def initial_turning(
    model: ModelLike = "nomoto1",
    rudder_deg: float = 10.0,
    heading_deg: float = 10.0,
    side: str = "starboard",
    dt: float | None = None,
    wind: Mapping[str, Any] | None = None,
) -> InitialTurningResult:
    """Initial turning test (MSC.137(76) 5.3.2): rudder to ``rudder_deg`` until the heading
    has changed ``heading_deg``; the distance travelled along the track is measured (in a
    true ``wind`` as :func:`turning_circle`'s).

    Raises
    ------
    ValueError
        For bad arguments or if the heading change is not reached within the longest hold.
    """
    rig = Rig(model, dt, wind)
    delta = rig.check_rudder(rudder_deg, "initial turning rudder_deg")
    if not (isinstance(heading_deg, int | float) and math.isfinite(heading_deg)):
        raise ValueError(f"heading_deg must be a finite angle, got {heading_deg!r}")
    if not 0 < heading_deg <= 180:
        raise ValueError(f"heading_deg must be in (0, 180] deg, got {heading_deg!r}")
    target = math.radians(heading_deg)
    s = side_sign(side)
    run = Run(rig, lambda t, x: s * delta)
    psi0 = float(rig.x0[rig.ipsi])
    while s * (run.x[rig.ipsi] - psi0) < target:
        if run.t >= rig.settings.max_hold:
            raise ValueError(
                f"{rig.name} did not turn {heading_deg:g} deg within "
                f"{rig.settings.max_hold:g} s with {rudder_deg:g} deg rudder"
            )
        run.advance(rig.settings.chunk / 5)
    series = rig.series(run.result())
    cross = crossing(s * (series.psi - psi0), target)
    assert cross is not None
    track = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(series.x), np.diff(series.y)))])
    along = (series.x - series.x[0]) * math.cos(psi0) + (series.y - series.y[0]) * math.sin(psi0)
    i = cross[0]
    return InitialTurningResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        rudder=delta,
        side=side,
        heading=target,
        distance=value_at(track, cross),
        advance=value_at(along, cross),
        time=value_at(series.time, cross),
        series=series.crop(i + 1),
        dt=rig.dt,
        wind=rig.wind,
    )

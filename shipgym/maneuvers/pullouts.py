"""The pull-out trial: a steady turn, then rudder amidships.

Definitions of ITTC and IMO MSC/Circ.1053 (Explanatory Notes to MSC.137(76)), as for every
trial of :mod:`shipgym.maneuvers`. A directionally stable ship's yaw rate decays to zero after
the pull-out; an unstable one keeps a residual yaw rate (the height of its spiral loop).
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
    hold_until_steady,
    json_deg,
    json_num,
    side_sign,
    wind_json,
)
from shipgym.maneuvers.particulars import ShipParticulars
from shipgym.models.seaway_options import Wind

__all__ = ["PullOutResult", "pullout"]


@dataclass(frozen=True, eq=False)
class PullOutResult:
    """A pull-out trial: steady turn, then rudder amidships.

    Attributes
    ----------
    model, particulars, approach_speed, rudder, side, series, wind
        As in :class:`TurningResult`.
    pullout_time : float
        Time the rudder is returned to amidships [s].
    turn_yaw_rate : float
        Steady yaw rate of the turn before the pull-out [rad/s].
    residual_yaw_rate : float
        Yaw rate at the end (mean over the last window) [rad/s].
    decay_time : float
        Time after the pull-out for ``|r|`` to fall to ``|turn_yaw_rate| / e`` [s] (NaN if
        it never does).
    stable : bool
        ``|residual_yaw_rate| <= 0.05 |turn_yaw_rate|``: the ship is directionally stable.
    settled : bool
        The yaw rate settled within the longest hold.
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    rudder: float
    side: str
    series: TimeSeries
    pullout_time: float
    turn_yaw_rate: float
    residual_yaw_rate: float
    decay_time: float
    stable: bool
    settled: bool
    dt: float
    wind: Wind | None = None

    def to_dict(self, include_series: bool = True) -> dict[str, Any]:
        """Metrics (and time series) for JSON; degrees in ``*_deg`` keys."""
        d = {
            "manoeuvre": "pullout",
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": self.particulars.length,
            "approach_speed_m_s": json_num(self.approach_speed),
            "dt_s": self.dt,
            "rudder_deg": json_deg(self.rudder),
            "side": self.side,
            "pullout_time_s": json_num(self.pullout_time),
            "turn_yaw_rate_deg_s": json_deg(self.turn_yaw_rate),
            "residual_yaw_rate_deg_s": json_deg(self.residual_yaw_rate),
            "decay_time_s": json_num(self.decay_time),
            "stable": self.stable,
            "settled": self.settled,
            "wind": wind_json(self.wind),
        }
        if include_series:
            d["series"] = self.series.to_dict()
        return d


def pullout(
    model: ModelLike = "nomoto1",
    rudder_deg: float = 20.0,
    side: str = "starboard",
    dt: float | None = None,
    wind: Mapping[str, Any] | None = None,
) -> PullOutResult:
    """Pull-out trial: turn with ``rudder_deg`` to ``side`` until steady, then rudder 0 (in a
    true ``wind`` as :func:`~shipgym.maneuvers.turning_circle`'s).

    The yaw rate after the pull-out is followed until it settles; a residual yaw rate above
    5 % of the turning rate marks a directionally unstable ship.
    """
    rig = Rig(model, dt, wind)
    delta = rig.check_rudder(rudder_deg, "pull-out rudder_deg")
    s = side_sign(side)
    state = {"delta": s * delta}
    run = Run(rig, lambda t, x: state["delta"])
    _, turn = hold_until_steady(run, rig)
    t_pull = run.t
    state["delta"] = 0.0
    settled, after = hold_until_steady(run, rig, min_time=2 * rig.settings.chunk)
    series = rig.series(run.result())
    r_turn, r_res = float(turn[0]), float(after[0])
    i_p = int(np.searchsorted(series.time, t_pull - 1e-9))
    below = np.nonzero(np.abs(series.r[i_p:]) <= abs(r_turn) / math.e)[0]
    decay = float(series.time[i_p + below[0]] - t_pull) if len(below) else math.nan
    return PullOutResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        rudder=delta,
        side=side,
        series=series,
        pullout_time=t_pull,
        turn_yaw_rate=r_turn,
        residual_yaw_rate=r_res,
        decay_time=decay,
        stable=abs(r_res) <= 0.05 * abs(r_turn),
        settled=settled,
        dt=rig.dt,
        wind=rig.wind,
    )

"""Seed 004's path-following case on its own ship: a named scenario.

Seed 004 (TTK4190 assignment 3) steers a ship whose heading model it fitted as the
second-order Nomoto model of its eq. (6), ``K`` 0.03 1/s, ``T1`` 130 s, ``T2`` 150 s, ``T3``
320 s, with a rudder offset of 0.52 deg (the ship drifts to starboard at zero rudder), by the
PID of its eq. (7) (``Kp`` 50, ``Ki`` 0.7, ``Kd`` 350 in rad/rad, the ``-Ki`` printed there is a
sign slip: with it the loop is unstable) and the lookahead LOS with the conditional integrator
of its eq. (9)-(10), and reports a cross-track error within +-200 m once on track.

Here that ship is :data:`SEED004_SHIP` in :func:`shipgym.models.make_model` (``nomoto2``, the
Mariner's steering gear and surge model: the report gives neither, and no speed; the ship runs
at the surge model's 7.7 m/s service speed), the rudder offset enters as a constant added to
the command, and the path is :data:`SEED004_PATH`: four legs of 4.5 km with turns of 45-70 deg
in a 0.5 m/s current across the first leg. :func:`run_seed004` runs it with

* ``"seed004"``: the report's PID gains, its reference-free heading loop and a lookahead of
  :data:`SEED004_LOOKAHEAD`;
* ``"design"``: the design rule of :func:`controllers.design_model` (pole placement at the
  bandwidth the steering gear allows) and the lookahead from time-scale separation, the
  guidance loop :data:`SEPARATION` times slower than the heading loop
  (``Delta = SEPARATION U / w_n``);
* any explicit ``(omega_n, lookahead)``; :func:`tune_seed004` searches these two on a grid
  for the smallest largest straight-leg error (the tuned case).

Cross-track error is reported on the straight parts of the legs: from :data:`SETTLE_M` past a
waypoint to the next one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from controllers import HeadingAutopilot, design_model
from controllers.los import LOSGuidance
from controllers.paths import WaypointPath
from shipgym.models import Nomoto2Params, make_model

__all__ = [
    "SEED004_GAINS",
    "SEED004_PATH",
    "SEED004_SHIP",
    "Seed004Run",
    "run_seed004",
    "tune_seed004",
]

TUNE_GRID = (
    (0.02, 0.03, 0.04, 0.05, 0.07, 0.1),
    (200.0, 300.0, 450.0, 600.0, 800.0, 1100.0, 1500.0),
)
"""``omega_n`` [rad/s] x lookahead [m] of the tuned case's search (42 runs)."""

SEED004_SHIP = Nomoto2Params(K=0.03, T1=130.0, T2=150.0, T3=320.0)
"""Seed 004 eq. (6)."""
SEED004_RUDDER_OFFSET = math.radians(0.52)
"""The ship's zero-rudder drift of seed 004, as a rudder offset [rad] (starboard)."""
SEED004_GAINS = (50.0, 0.7, 350.0)
"""Seed 004 eq. (7): ``Kp``, ``Ki``, ``Kd`` (rad of rudder per rad, per rad s, per rad/s)."""
SEED004_LOOKAHEAD = 1000.0
"""Lookahead [m] for the report's gains (the report gives none; the largest tried)."""
SEED004_PATH = np.array(
    [[0.0, 0.0], [4500.0, 0.0], [7700.0, 3200.0], [7700.0, 7700.0], [3500.0, 9200.0]]
)
"""Waypoints (north, east) [m]: four legs of 4.5 km, turns of 45, 45 and 70 deg."""
CURRENT = (0.5, math.pi / 2.0)
"""Current speed [m/s] and direction it flows toward [rad] (east: across the first leg)."""
SEPARATION = 4.0
"""Guidance loop this many times slower than the heading loop in the design rule."""
SETTLE_M = 1500.0
"""Straight part of a leg: from this far [m] past its first waypoint (the last two thirds of
every leg, the same for every gain set)."""


@dataclass
class Seed004Run:
    """One run of the case.

    Attributes
    ----------
    gains : str
        ``"seed004"``, ``"design"`` or ``"omega_n=..., lookahead=..."``.
    omega_n, lookahead : float
        Heading-loop bandwidth [rad/s] (NaN for the report's fixed gains) and LOS lookahead [m].
    time, north, east, cross_track, leg : numpy.ndarray
        The trajectory, cross-track error [m] and active leg.
    straight : numpy.ndarray
        True on the straight parts of the legs.
    max_straight_m, rms_straight_m, max_m : float
        Largest and RMS cross-track error on the straights, and the largest overall [m].
    finished : bool
        Whether the last waypoint was reached within the time limit.
    """

    gains: str
    omega_n: float
    lookahead: float
    time: np.ndarray
    north: np.ndarray
    east: np.ndarray
    cross_track: np.ndarray
    leg: np.ndarray
    straight: np.ndarray
    max_straight_m: float
    rms_straight_m: float
    max_m: float
    finished: bool

    def summary(self) -> dict[str, Any]:
        """The scalar results."""
        return {k: getattr(self, k) for k in ("gains", "omega_n", "lookahead", "max_straight_m",
                                              "rms_straight_m", "max_m", "finished")}  # fmt: skip


def run_seed004(
    gains: str | tuple[float, float] = "design", *, dt: float = 1.0, max_time: float = 6000.0
) -> Seed004Run:
    """Run seed 004's path-following case (module docstring).

    Parameters
    ----------
    gains : {"design", "seed004"} or (omega_n, lookahead)
        Which heading gains and lookahead.
    dt : float
        Control and integration step [s].
    max_time : float
        Time limit [s].

    Returns
    -------
    Seed004Run
    """
    model = make_model("nomoto2", SEED004_SHIP)
    gear, surge = model.gear, model.surge
    speed = surge.service_speed
    limits = {"actuator_time_constant": gear.time_constant, "max_command": gear.max_angle,
              "max_rate": gear.max_rate}  # fmt: skip
    if gains == "seed004":
        kp, ki, kd = SEED004_GAINS
        pilot = HeadingAutopilot(kp, ki, kd, dt, max_command=gear.max_angle,
                                 max_rate=gear.max_rate)  # fmt: skip
        omega_n, lookahead, label = math.nan, SEED004_LOOKAHEAD, "seed004"
    else:
        if gains == "design":
            K, T, omega_n = design_model(SEED004_SHIP.K, SEED004_SHIP.T1, SEED004_SHIP.T2,
                                         SEED004_SHIP.T3, **limits)  # fmt: skip
            lookahead = SEPARATION * speed / omega_n
            label = "design"
        elif isinstance(gains, tuple) and len(gains) == 2:
            omega_n, lookahead = (float(g) for g in gains)
            K, T, _ = design_model(SEED004_SHIP.K, SEED004_SHIP.T1, SEED004_SHIP.T2,
                                   SEED004_SHIP.T3, omega=omega_n)  # fmt: skip
            label = f"omega_n={omega_n:g}, lookahead={lookahead:g}"
        else:
            raise ValueError(f"gains must be 'design', 'seed004' or (omega_n, lookahead), "
                             f"got {gains!r}")  # fmt: skip
        pilot = HeadingAutopilot.from_nomoto(K, T, dt, omega_n=omega_n, **limits)
    los = LOSGuidance(WaypointPath(SEED004_PATH), lookahead, design_speed=speed)
    c_speed, c_dir = CURRENT
    current = np.array([c_speed * math.cos(c_dir), c_speed * math.sin(c_dir)])
    ipsi, ir = model.index("psi"), model.index("r")
    x = np.zeros((1, model.nx))
    x[0, model.index("U")] = speed
    pilot.reset(0.0, 0.0, t=0.0)
    n = round(max_time / dt)
    out = np.full((n + 1, 5), np.nan)  # north, east, cross-track, leg, along the leg
    t = 0.0
    k = 0
    for k in range(n + 1):
        s = x[0]
        chi_d = los.update(t, (s[0], s[1]), s[ipsi], s[ir])
        leg_start = los.path.waypoint_s[los.segment]
        out[k] = (s[0], s[1], los.cross_track_error, los.segment, los.along_track - leg_start)
        if los.finished or not np.all(np.isfinite(s)):
            break
        delta = pilot.update(t, s[ipsi], s[ir], chi_d)
        x = model.step(x, [delta + SEED004_RUDDER_OFFSET, surge.service_shaft_speed], dt,
                       current)  # fmt: skip
        t += dt
    out = out[: k + 1]
    time = dt * np.arange(out.shape[0])
    leg = out[:, 3].astype(int)
    straight = out[:, 4] > SETTLE_M
    e = out[:, 2]
    on = e[straight]
    return Seed004Run(
        label, float(omega_n), float(lookahead), time, out[:, 0], out[:, 1], e, leg, straight,
        float(np.max(np.abs(on))) if on.size else math.nan,
        float(np.sqrt(np.mean(on**2))) if on.size else math.nan,
        float(np.max(np.abs(e))), bool(los.finished),
    )  # fmt: skip


def tune_seed004(grid: tuple[tuple[float, ...], tuple[float, ...]] = TUNE_GRID) -> Seed004Run:
    """The ``(omega_n, lookahead)`` of ``grid`` with the smallest largest straight-leg
    cross-track error that reaches the last waypoint (ties: the smaller RMS)."""
    runs = [run_seed004((w, d)) for w in grid[0] for d in grid[1]]
    ok = [r for r in runs if r.finished and math.isfinite(r.max_straight_m)]
    if not ok:
        raise ValueError("no gain set of the grid finishes the path")
    return min(ok, key=lambda r: (r.max_straight_m, r.rms_straight_m))

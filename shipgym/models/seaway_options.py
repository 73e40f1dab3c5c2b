"""The seaway of a batch of ships (an environment's sub-envs, a manoeuvre's ship): the ``wind``
and ``sea_state`` options, their ranges and draws, and the per-ship arrays that the compiled
step of :mod:`shipgym.models.seaway` advances.

Options (of the env's constructor, for every episode, and of ``reset(options=...)``, for the
episodes of that reset; ``None`` turns a part off; both off by default)

* ``wind``: a dict with ``speed`` (``U_10`` [m/s], in :data:`WIND_SPEED_RANGE`), ``direction``
  (where the wind comes FROM [rad], clockwise from north; drawn uniformly if left out) and
  ``gusts`` (bool, default True).
* ``sea_state``: a :class:`~shipgym.models.waves.SeaState`, or a dict with
  ``significant_height`` [m] in :data:`HEIGHT_RANGE`, ``peak_period`` [s] in
  :data:`PERIOD_RANGE`, ``direction`` (where the waves travel TOWARD [rad]; drawn uniformly if
  left out) and ``gamma`` (default 3.3, in :data:`~shipgym.models.waves.GAMMA_RANGE`).

Any number of a dict may be a pair ``(low, high)``: each episode then draws it uniformly from
that range, from the episode's seed. A sea steeper than ``H_s / lambda_p = 1/7`` is refused
(for a range: its highest waves at its shortest period). A bad value raises ``ValueError``
naming the option, the value and the range.

Draws: a reset with a seaway draws :data:`N_DRAWS` more uniform numbers from each episode's
generator, after the task's own (so a reset without one draws what it always drew): wind speed
and direction, wave height, period and direction, the seed of the ship's noise stream.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from shipgym.models import seaway as sw
from shipgym.models.rvg import GRAVITY, WATER_DENSITY
from shipgym.models.waves import GAMMA_RANGE, MAX_STEEPNESS, SeaState, reflection_factor

__all__ = [
    "HEIGHT_RANGE",
    "N_DRAWS",
    "PERIOD_RANGE",
    "WIND_SPEED_RANGE",
    "Sea",
    "SeawayArrays",
    "Wind",
    "sea_option",
    "wind_option",
]

WIND_SPEED_RANGE = (0.0, 30.0)
"""Mean wind speed ``U_10`` [m/s] of the ``wind`` option (calm to Beaufort 11)."""
HEIGHT_RANGE = (0.0, 8.0)
"""Significant wave height [m] of the ``sea_state`` option (calm to a very high sea, WMO 8)."""
PERIOD_RANGE = (2.0, 20.0)
"""Peak period [s] of the ``sea_state`` option."""
#: Angles [rad] of the direction options: 100 turns, as the current's.
ANGLE_RANGE = (-200.0 * math.pi, 200.0 * math.pi)
N_DRAWS = 6
"""Uniform numbers a reset with a seaway draws per episode."""

Value = float | tuple[float, float]


def _number(option: str, key: str, value: Any, low: float, high: float, unit: str) -> Value:
    """A number or a ``(low, high)`` pair of ``option[key]`` inside ``[low, high]``."""
    name = f"{option}[{key!r}]"
    pair = isinstance(value, tuple | list) and len(value) == 2
    items = list(value) if pair else [value]
    out = []
    for v in items:
        if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
            raise ValueError(
                f"option {name} must be a number of {unit} or a (low, high) pair, got {value!r}"
            )
        f = float(v)
        if not (math.isfinite(f) and low <= f <= high):
            raise ValueError(f"option {name} must be in [{low:g}, {high:g}] {unit}, got {value!r}")
        out.append(f)
    if pair:
        if out[0] > out[1]:
            raise ValueError(
                f"option {name} must be a (low, high) pair with low <= high, got {value!r}"
            )
        return (out[0], out[1])
    return out[0]


def _high(v: Value) -> float:
    return v[1] if isinstance(v, tuple) else v


def _low(v: Value) -> float:
    return v[0] if isinstance(v, tuple) else v


@dataclass(frozen=True)
class Wind:
    """A checked ``wind`` option (module docstring)."""

    speed: Value
    direction: Value | None
    gusts: bool


@dataclass(frozen=True)
class Sea:
    """A checked ``sea_state`` option (module docstring)."""

    significant_height: Value
    peak_period: Value
    direction: Value | None
    gamma: float


def wind_option(value: Any) -> Wind | None:
    """The checked ``wind`` option, or None (no wind)."""
    if value is None:
        return None
    if not isinstance(value, Mapping):
        raise ValueError(
            "option 'wind' must be None or a dict with 'speed' [m/s] and optionally "
            f"'direction' [rad, from] and 'gusts' [bool], got {value!r}"
        )
    unknown = set(value) - {"speed", "direction", "gusts"}
    if unknown or "speed" not in value:
        raise ValueError(
            f"option 'wind' takes the keys 'speed' (required), 'direction' and 'gusts', got "
            f"{sorted(value)}"
        )
    gusts = value.get("gusts", True)
    if not isinstance(gusts, bool | np.bool_):
        raise ValueError(f"option wind['gusts'] must be True or False, got {gusts!r}")
    direction = value.get("direction")
    return Wind(
        speed=_number("wind", "speed", value["speed"], *WIND_SPEED_RANGE, "m/s"),
        direction=None
        if direction is None
        else _number("wind", "direction", direction, *ANGLE_RANGE, "rad"),
        gusts=bool(gusts),
    )


def sea_option(value: Any) -> Sea | None:
    """The checked ``sea_state`` option, or None (calm water)."""
    if value is None:
        return None
    if isinstance(value, SeaState):
        value = {
            "significant_height": value.significant_height,
            "peak_period": value.peak_period,
            "direction": value.direction,
            "gamma": value.gamma,
        }
    if not isinstance(value, Mapping):
        raise ValueError(
            "option 'sea_state' must be None, a SeaState or a dict with 'significant_height' "
            f"[m] and 'peak_period' [s], optionally 'direction' [rad, toward] and 'gamma', "
            f"got {value!r}"
        )
    keys = {"significant_height", "peak_period", "direction", "gamma"}
    if set(value) - keys or not {"significant_height", "peak_period"} <= set(value):
        raise ValueError(
            "option 'sea_state' takes the keys 'significant_height' and 'peak_period' "
            f"(required), 'direction' and 'gamma', got {sorted(value)}"
        )
    height = _number("sea_state", "significant_height", value["significant_height"],
                     *HEIGHT_RANGE, "m")  # fmt: skip
    period = _number("sea_state", "peak_period", value["peak_period"], *PERIOD_RANGE, "s")
    gamma = _number("sea_state", "gamma", value.get("gamma", 3.3), *GAMMA_RANGE, "")
    if isinstance(gamma, tuple):
        raise ValueError(f"option sea_state['gamma'] must be one number, got {value['gamma']!r}")
    shortest = GRAVITY * _low(period) ** 2 / (2.0 * math.pi)
    if _high(height) > MAX_STEEPNESS * shortest:
        raise ValueError(
            f"option 'sea_state' is too steep: significant_height {value['significant_height']!r}"
            f" m at peak_period {value['peak_period']!r} s; expected H_s <= lambda_p / 7 = "
            f"{MAX_STEEPNESS * shortest:.3g} m at {_low(period):g} s"
        )
    direction = value.get("direction")
    return Sea(
        significant_height=height,
        peak_period=period,
        direction=None
        if direction is None
        else _number("sea_state", "direction", direction, *ANGLE_RANGE, "rad"),
        gamma=gamma,
    )


def _drawn(value: Value | None, u: np.ndarray, low: float, high: float) -> np.ndarray:
    """Each row's value: the fixed number, or a uniform draw from the pair (or ``[low,
    high)`` for None)."""
    if value is None:
        lo, hi = low, high
    elif isinstance(value, tuple):
        lo, hi = value
    else:
        return np.full(u.shape, value)
    return lo + (hi - lo) * u


@functools.lru_cache(maxsize=256)
def _drift(height: float, period: float, gamma: float, draught: float) -> float:
    """The drift factor ``rho g H_s^2 / 16`` times the reflection factor of a sea on a ship of
    draught ``draught`` (cached: a fixed sea costs once)."""
    sea = SeaState(height, period, 0.0, gamma)
    return WATER_DENSITY * GRAVITY * height**2 / 16.0 * reflection_factor(sea, draught)


class SeawayArrays:
    """The seaway of ``n`` ships of one kind (``ship``) stepped every ``dt`` seconds.

    ``on`` turns True at the first reset with a seaway and stays so (the task kernels then
    step the seaway of every row; a row reset without one has a zero seaway).
    """

    def __init__(self, n: int, ship: sw.SeawayShip, dt: float, yaw_rate_index: int) -> None:
        self.ship = ship
        self.dt = dt
        self.on = False
        self.sea = np.zeros((n, sw.N_SEA))
        self.wf = np.zeros((n, sw.N_WF))
        self.rng = np.zeros(n, dtype=np.uint64)
        self.gains = sw.wave_motion_table()
        self.tables = np.ascontiguousarray(np.vstack((ship.wind, ship.drift)))
        self.constants = ship.constants()
        self.ir = int(yaw_rate_index)

    def kernel_args(self) -> tuple[Any, ...]:
        """The seaway argument of the task kernels."""
        return (self.on, self.sea, self.wf, self.rng, self.tables, self.gains, self.constants,
                self.ir)  # fmt: skip

    def set_rows(
        self, rows: np.ndarray, wind: Wind | None, sea: Sea | None, draws: np.ndarray
    ) -> None:
        """Set the seaway of ``rows`` from the options and their ``(len(rows), N_DRAWS)``
        uniform draws (the noise streams are seeded from the last)."""
        k = len(rows)
        s = np.zeros((sw.N_SEA, k))  # the rows' parameters and states, set at once below
        w = np.zeros((sw.N_WF, k))
        s[sw.S_OMEGA_P] = s[sw.S_TURN] = 1.0  # a calm sea's process: finite
        if wind is not None:
            speed = _drawn(wind.speed, draws[:, 0], 0.0, 0.0)
            s[sw.S_WIND] = speed
            direction = _drawn(wind.direction, draws[:, 1], -math.pi, math.pi)
            w[sw.W_FROM] = direction
            s[sw.S_WIND_COS] = np.cos(direction)
            s[sw.S_WIND_SIN] = np.sin(direction)
            s[sw.S_GUST_A] = 1.0
            if wind.gusts:
                sigma, a = sw.gust_parameters(speed, self.dt)
                s[sw.S_GUST_SIGMA] = sigma
                s[sw.S_GUST_A] = a
                s[sw.S_GUST_B] = sigma * np.sqrt(1.0 - a * a)
        if sea is not None:
            heights = _drawn(sea.significant_height, draws[:, 2], 0.0, 0.0)
            periods = _drawn(sea.peak_period, draws[:, 3], 0.0, 0.0)
            s[sw.S_WAVE_DIR] = w[sw.W_WDIR] = _drawn(sea.direction, draws[:, 4], -math.pi, math.pi)
            s[sw.S_WAVE_COS] = np.cos(s[sw.S_WAVE_DIR])
            s[sw.S_WAVE_SIN] = np.sin(s[sw.S_WAVE_DIR])
            wavy: slice | np.ndarray = heights > 0.0
            if wavy.all():
                wavy = slice(None)  # (cheaper than a mask)
            else:
                heights, periods = heights[wavy], periods[wavy]
            length = self.ship.length
            omega_p = 2.0 * math.pi / periods
            lam = sw.wave_damping(sea.gamma)
            # the cell of the sea's spectrum shape in the wave-motion table
            cell = min(math.floor(sea.gamma - sw.TABLE_GAMMAS[0]), len(sw.TABLE_GAMMAS) - 2)
            if isinstance(sea.significant_height, tuple) or isinstance(sea.peak_period, tuple):
                drift = np.array([_drift(float(h), float(t), sea.gamma, self.ship.draught)
                                  for h, t in zip(heights, periods, strict=True)])  # fmt: skip
            elif heights.size:  # one sea
                drift = _drift(float(sea.significant_height), float(sea.peak_period), sea.gamma,
                               self.ship.draught)  # fmt: skip
            else:  # a flat sea
                drift = 0.0
            columns = {
                sw.S_OMEGA_P: omega_p,
                sw.S_LAMBDA: lam,
                sw.S_TURN: math.sqrt(1.0 - lam * lam),
                sw.S_HEIGHT: heights,
                sw.S_KAPPA: omega_p**2 * length / (2.0 * GRAVITY),
                sw.S_GAMMA_CELL: cell,
                sw.S_GAMMA_FRAC: sea.gamma - sw.TABLE_GAMMAS[cell],
                sw.S_DRIFT: drift,
            }
            for column, value in columns.items():
                s[column, wavy] = value
            w[sw.W_HS, wavy] = heights
            w[sw.W_TP, wavy] = periods
        self.sea[rows] = s.T
        self.wf[rows] = w.T
        self.rng[rows] = (draws[:, 5] * 2.0**53).astype(np.uint64)
        self.on = True

    def info(self, rows: slice | np.ndarray) -> dict[str, np.ndarray]:
        """The disturbance entries of ``info`` for ``rows`` (new arrays, a row per ship):
        ``wind`` (speed of the moment with its gust [m/s], direction it comes from [rad]),
        ``sea_state`` (``H_s`` [m], ``T_p`` [s], direction the waves travel to [rad]; zeros in
        calm water) and ``wave_motion`` (the wave-frequency motion added to the measured
        state: north, east [m], heading [rad])."""
        w = self.wf[rows].copy()  # (one copy; the entries are views of it, new at every call)
        return {
            "wind": w[:, sw.W_SPEED : sw.W_FROM + 1],
            "sea_state": w[:, sw.W_HS : sw.W_WDIR + 1],
            "wave_motion": w[:, sw.W_NORTH : sw.W_PSI + 1],
        }

    def row_info(self, i: int) -> dict[str, Any]:
        """:meth:`info` of row ``i`` (the single env's)."""
        w = self.wf[i].copy()
        return {
            "wind": w[sw.W_SPEED : sw.W_FROM + 1],
            "sea_state": w[sw.W_HS : sw.W_WDIR + 1],
            "wave_motion": w[sw.W_NORTH : sw.W_PSI + 1],
        }

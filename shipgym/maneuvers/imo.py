"""The IMO manoeuvring criteria: resolution MSC.137(76) section 5.3, explanatory notes
MSC/Circ.1053.

============================  ===========================================================
5.3.1 turning ability         advance <= 4.5 L, tactical diameter <= 5 L (35 deg rudder)
5.3.2 initial turning         10 deg rudder: distance travelled <= 2.5 L by the time the
                              heading has changed 10 deg
5.3.3 yaw-checking and        10/10 zigzag 1st overshoot <= 10 deg if L/U < 10 s, 20 deg
course-keeping                if L/U >= 30 s, 5 + 0.5 L/U deg in between; 2nd overshoot
                              <= 25 / 40 / 17.5 + 0.75 L/U deg; 20/20 1st overshoot
                              <= 25 deg
============================  ===========================================================

("should not exceed": a value equal to the limit passes.) Every criterion is evaluated to both
sides and the worse side counts; the table labels the 10/10 second overshoot "course-keeping"
and the first overshoots "yaw-checking". The stopping ability (5.3.4, track reach <= 15 L)
needs astern power, which these models do not have. The Standards apply to ships of 100 m and
more; for R/V Gunnerus (33.9 m) the table is informative only.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TextIO

from shipgym.maneuvers._common import (
    SIDES,
    ModelLike,
    Progress,
    Rig,
    json_num,
    side_sign,
    wind_json,
)
from shipgym.maneuvers.particulars import ShipParticulars
from shipgym.maneuvers.turning import (
    InitialTurningResult,
    TurningResult,
    initial_turning,
    turning_circle,
)
from shipgym.maneuvers.zigzags import ZigZagResult, zigzag

__all__ = [
    "IMOReport",
    "IMORow",
    "format_imo_table",
    "imo_criteria",
    "imo_rows",
    "overshoot_limits",
    "print_imo_table",
]


def overshoot_limits(length_over_speed: float) -> tuple[float, float, float]:
    """IMO MSC.137(76) 5.3.3 overshoot limits [deg] for ``L / U`` [s].

    Returns
    -------
    (float, float, float)
        10/10 first overshoot, 10/10 second overshoot, 20/20 first overshoot [deg].
    """
    q = float(length_over_speed)
    if not (math.isfinite(q) and q > 0):
        raise ValueError(f"L/U must be a finite time > 0 s, got {length_over_speed!r}")
    if q < 10.0:
        first, second = 10.0, 25.0
    elif q >= 30.0:
        first, second = 20.0, 40.0
    else:
        first, second = 5.0 + 0.5 * q, 17.5 + 0.75 * q
    return first, second, 25.0


@dataclass(frozen=True)
class IMORow:
    """One criterion of MSC.137(76): value, limit and the verdict (a report row).

    Attributes
    ----------
    criterion : str
        What is checked.
    value : float
        Worst value over the sides in ``unit`` (NaN if it could not be measured).
    limit : float
        The criterion's upper limit in ``unit``.
    unit : str
        ``"L"`` (ship lengths) or ``"deg"``.
    passed : bool
        ``value <= limit`` ("should not exceed") (a NaN value fails).
    detail : str
        Which trial and side gave the value.
    """

    criterion: str
    value: float
    limit: float
    unit: str
    passed: bool
    detail: str = ""

    def to_dict(self) -> dict[str, Any]:
        """For JSON."""
        return {
            "criterion": self.criterion,
            "value": json_num(self.value, 4),
            "limit": json_num(self.limit, 4),
            "unit": self.unit,
            "pass": self.passed,
            "detail": self.detail,
        }


def _row(criterion: str, values: list[tuple[float, str]], limit: float, unit: str) -> IMORow:
    """Worst (largest, NaN first) of ``(value, detail)`` pairs against ``limit``."""
    nan = [v for v in values if not math.isfinite(v[0])]
    value, detail = nan[0] if nan else max(values, key=lambda v: v[0])
    return IMORow(
        criterion, value, limit, unit, bool(math.isfinite(value) and value <= limit), detail
    )


def imo_rows(
    particulars: ShipParticulars,
    turning: Sequence[TurningResult] = (),
    initial: Sequence[InitialTurningResult] = (),
    zigzags: Sequence[ZigZagResult] = (),
) -> list[IMORow]:
    """The MSC.137(76) rows that the given trials allow (worst side of each).

    Turning circles count for the turning ability only at 35 deg rudder; zigzags only if
    they are 10/10 or 20/20. A zigzag that was never checked counts as NaN (fail).
    """
    L = particulars.length
    rows: list[IMORow] = []
    full = [t for t in turning if abs(math.degrees(t.rudder) - 35.0) < 1e-6]
    if full:
        rows.append(
            _row(
                "turning ability: advance (35 deg rudder)",
                [(t.advance / L, f"turning circle to {t.side}") for t in full],
                4.5,
                "L",
            )
        )
        rows.append(
            _row(
                "turning ability: tactical diameter (35 deg rudder)",
                [(t.tactical_diameter / L, f"turning circle to {t.side}") for t in full],
                5.0,
                "L",
            )
        )
    if initial:
        rows.append(
            _row(
                "initial turning: distance to 10 deg heading change (10 deg rudder)",
                [(i.distance / L, f"10 deg rudder to {i.side}") for i in initial],
                2.5,
                "L",
            )
        )
    first_lim, second_lim, first20_lim = overshoot_limits(particulars.length_over_speed)

    def zz(a: float) -> list[ZigZagResult]:
        return [
            z
            for z in zigzags
            if abs(math.degrees(z.rudder) - a) < 1e-6
            and abs(math.degrees(z.heading_check) - a) < 1e-6
        ]

    def overshoot(z: ZigZagResult, k: int) -> float:
        return z.overshoots_deg[k] if len(z.overshoots) > k else math.nan

    if z10 := zz(10.0):
        rows.append(
            _row(
                "yaw-checking: 10/10 zigzag 1st overshoot",
                [(overshoot(z, 0), f"10/10 {z.first} first") for z in z10],
                first_lim,
                "deg",
            )
        )
        rows.append(
            _row(
                "course-keeping: 10/10 zigzag 2nd overshoot",
                [(overshoot(z, 1), f"10/10 {z.first} first") for z in z10],
                second_lim,
                "deg",
            )
        )
    if z20 := zz(20.0):
        rows.append(
            _row(
                "yaw-checking: 20/20 zigzag 1st overshoot",
                [(overshoot(z, 0), f"20/20 {z.first} first") for z in z20],
                first20_lim,
                "deg",
            )
        )
    return rows


@dataclass(frozen=True, eq=False)
class IMOReport:
    """The MSC.137(76) check of one model with the trials behind it.

    Attributes
    ----------
    model : str
        Model name.
    particulars : ShipParticulars
        ``L`` and ``U``.
    rows : tuple of IMORow
        One row per criterion.
    turning, initial, zigzag_10, zigzag_20 : tuple
        The trials to each side.
    """

    model: str
    particulars: ShipParticulars
    rows: tuple[IMORow, ...]
    turning: tuple[TurningResult, ...]
    initial: tuple[InitialTurningResult, ...]
    zigzag_10: tuple[ZigZagResult, ...]
    zigzag_20: tuple[ZigZagResult, ...]

    @property
    def passed(self) -> bool:
        """All criteria met."""
        return all(row.passed for row in self.rows)

    def to_dict(self) -> dict[str, Any]:
        """Rows and the trial metrics for JSON (no time series)."""
        return {
            "standard": "IMO MSC.137(76), explanatory notes MSC/Circ.1053",
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": self.particulars.length,
            "speed_m_s": self.particulars.speed,
            "length_over_speed_s": json_num(self.particulars.length_over_speed),
            "passed": self.passed,
            "wind": wind_json(self.turning[0].wind if self.turning else None),
            "rows": [row.to_dict() for row in self.rows],
            "turning": [t.to_dict(include_series=False) for t in self.turning],
            "initial_turning": [i.to_dict() for i in self.initial],
            "zigzag_10_10": [z.to_dict(include_series=False) for z in self.zigzag_10],
            "zigzag_20_20": [z.to_dict(include_series=False) for z in self.zigzag_20],
        }


def imo_criteria(
    model: ModelLike = "nomoto1",
    sides: Sequence[str] = SIDES,
    dt: float | None = None,
    progress: Progress = None,
    wind: Mapping[str, Any] | None = None,
) -> IMOReport:
    """Run the trials of MSC.137(76) to each side and check the criteria.

    Runs a 35 deg turning circle, the 10 deg initial turning test, and 10/10 and 20/20
    zigzags (first rudder to each side); each criterion takes the worse side.

    Parameters
    ----------
    model : str or ShipModel
        Model name or model.
    sides : sequence of {"starboard", "port"}
        Sides to test (both by default).
    dt : float, optional
        Integration step [s].
    progress : callable, optional
        Called with a one-line message after each trial.
    wind : dict, optional
        A constant true wind in every trial, as :func:`~shipgym.maneuvers.turning_circle`'s
        (the criteria are for calm water: a trial in wind is corrected for it).

    Returns
    -------
    IMOReport
    """
    if not sides:
        raise ValueError(f"sides must name at least one of {SIDES}, got {sides!r}")
    for side in sides:
        side_sign(side)
    rig = Rig(model, dt, wind)
    ship = rig.model
    say = progress or (lambda msg: None)
    turning, initial, z10, z20 = [], [], [], []
    for side in sides:
        turning.append(turning_circle(ship, 35.0, side, dt=rig.dt, wind=wind))
        say(f"turning circle 35 deg to {side}: done")
        initial.append(initial_turning(ship, 10.0, 10.0, side, dt=rig.dt, wind=wind))
        say(f"initial turning 10 deg to {side}: done")
        z10.append(zigzag(ship, 10.0, 10.0, side, n_reversals=2, dt=rig.dt, wind=wind))
        say(f"zigzag 10/10 {side} first: done")
        z20.append(zigzag(ship, 20.0, 20.0, side, n_reversals=1, dt=rig.dt, wind=wind))
        say(f"zigzag 20/20 {side} first: done")
    rows = imo_rows(rig.particulars, turning, initial, z10 + z20)
    return IMOReport(
        model=rig.name,
        particulars=rig.particulars,
        rows=tuple(rows),
        turning=tuple(turning),
        initial=tuple(initial),
        zigzag_10=tuple(z10),
        zigzag_20=tuple(z20),
    )


def format_imo_table(rows: Sequence[IMORow] | IMOReport, title: str | None = None) -> str:
    """A plain-text pass/fail table of MSC.137(76) rows."""
    if isinstance(rows, IMOReport):
        p = rows.particulars
        title = title or (
            f"IMO MSC.137(76) manoeuvring criteria: {p.vessel} ({rows.model}), "
            f"L = {p.length:g} m, U = {p.speed:g} m/s, L/U = {p.length_over_speed:.1f} s"
        )
        if p.length < 100.0:
            title += "\n(the Standards apply to ships of 100 m and more: informative only)"
        rows = rows.rows
    header = ("criterion", "value", "limit", "result", "worst case")
    body = []
    for row in rows:
        value = "not checked" if not math.isfinite(row.value) else f"{row.value:.2f} {row.unit}"
        body.append(
            (
                row.criterion,
                value,
                f"<= {row.limit:.2f} {row.unit}",
                "PASS" if row.passed else "FAIL",
                row.detail,
            )
        )
    widths = [max(len(r[i]) for r in (header, *body)) for i in range(len(header))]
    lines = [title] if title else []
    lines.append("  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)).rstrip())
    lines.append("  ".join("-" * w for w in widths))
    for r in body:
        lines.append("  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip())
    if not body:
        lines.append("(no IMO criterion applies to these trials)")
    return "\n".join(lines)


def print_imo_table(
    rows: Sequence[IMORow] | IMOReport, title: str | None = None, file: TextIO | None = None
) -> None:
    """Print :func:`format_imo_table` (to ``file``, stdout by default)."""
    print(format_imo_table(rows, title), file=file)

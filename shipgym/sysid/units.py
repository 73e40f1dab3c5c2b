"""Units of a ship's own log: the channels of a record, their units and how headers spell them.

A column map (``psi=hdg:deg``, :func:`shipgym.sysid.io.table.parse_columns`), a header that
states its unit (``heading [deg]``) and :meth:`shipgym.sysid.record.Record.from_arrays` name a
channel of :data:`CHANNELS` and a unit of :data:`UNITS`; the unit's factor converts the column
to SI units and radians. ``datetime`` times are ISO-8601 strings (or numpy datetime64 values).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from datetime import UTC, datetime

import numpy as np

__all__ = [
    "CHANNELS",
    "KNOT",
    "PARAMETER_UNITS",
    "REQUIRED_INPUTS",
    "UNITS",
    "UNIT_SPELLINGS",
    "parse_numbers",
    "parse_time",
    "unit_of",
]

KNOT: float = 1852.0 / 3600.0
"""Metres per second in one knot."""

PARAMETER_UNITS: dict[str, str] = {
    "K": "1/s",
    "T": "s",
    "T1": "s",
    "T2": "s",
    "T3": "s",
    "T_d": "s",
    "tau": "s",
    "delta0": "rad",
    "b0": "rad",
    "alpha_0": "rad",
    "alpha_0_deg": "deg",
    "direction": "rad",
    "n0": "rad/s",
    "n1": "-",
    "n2": "s",
    "n3": "s^2",
    "b1": "s",
    "b2": "s^2",
    "b3": "s^3",
    "V_n": "m/s",
    "V_e": "m/s",
    "v_0": "m/s",
    "speed": "m/s",
    "pod_lift_coefficient": "N s^2/m^2",
}
"""Unit of each identified parameter that has one: the Nomoto family's and the effects' own
parameters (``"-"``: dimensionless; the 3-DOF hydrodynamic coefficients are non-dimensional and
absent). The identification report and ``shipgym identify`` print parameters with them."""

_DEG = math.pi / 180.0

#: Unit of each kind -> factor to SI (``datetime`` for time is handled apart).
_KIND_UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0, "datetime": math.nan},
    "angle": {"rad": 1.0, "deg": _DEG},
    "rate": {"rad/s": 1.0, "deg/s": _DEG, "deg/min": _DEG / 60.0},
    "speed": {"m/s": 1.0, "kn": KNOT, "km/h": 1.0 / 3.6},
    "length": {"m": 1.0, "km": 1000.0},
    "geo": {"deg": 1.0},
    "revs": {"rpm": 1.0, "rev/s": 60.0},
}

#: Channel -> kind of unit.
CHANNELS: dict[str, str] = {
    "time": "time",
    "delta": "angle",
    "psi": "angle",
    "r": "rate",
    "U": "speed",
    "u": "speed",
    "v": "speed",
    "x": "length",
    "y": "length",
    "lat": "geo",
    "lon": "geo",
    "rpm": "revs",
}

#: Channel -> accepted units and their factor to SI.
UNITS: dict[str, dict[str, float]] = {ch: _KIND_UNITS[kind] for ch, kind in CHANNELS.items()}

REQUIRED_INPUTS: tuple[str, ...] = ("time", "delta", "psi")
"""The channels a ship's own log must give (the yaw rate can be derived from the heading)."""

#: Unit spellings in headers -> the unit of :data:`UNITS`.
UNIT_SPELLINGS: dict[str, str] = {
    "s": "s",
    "sec": "s",
    "secs": "s",
    "seconds": "s",
    "ms": "ms",
    "min": "min",
    "h": "h",
    "rad": "rad",
    "radians": "rad",
    "deg": "deg",
    "degree": "deg",
    "degrees": "deg",
    "°": "deg",
    "rad/s": "rad/s",
    "rad_s": "rad/s",
    "deg/s": "deg/s",
    "deg_s": "deg/s",
    "°/s": "deg/s",
    "dps": "deg/s",
    "deg/min": "deg/min",
    "deg_min": "deg/min",
    "deg_per_s": "deg/s",
    "deg_per_sec": "deg/s",
    "deg_per_min": "deg/min",
    "rad_per_s": "rad/s",
    "rad_per_sec": "rad/s",
    "m_per_s": "m/s",
    "rev_per_s": "rev/s",
    "°/min": "deg/min",
    "m/s": "m/s",
    "m_s": "m/s",
    "kn": "kn",
    "kt": "kn",
    "kts": "kn",
    "knots": "kn",
    "km/h": "km/h",
    "km_h": "km/h",
    "kmh": "km/h",
    "m": "m",
    "km": "km",
    "rpm": "rpm",
    "rev/s": "rev/s",
    "rev_s": "rev/s",
    "iso": "datetime",
    "datetime": "datetime",
    "utc": "datetime",
}


def unit_of(channel: str, unit: str, where: str) -> str:
    """The unit of :data:`UNITS` that ``unit`` spells for ``channel`` (``ValueError`` naming
    ``where`` and the accepted units)."""
    spelled = UNIT_SPELLINGS.get(unit.strip().lower(), unit.strip())
    if spelled not in UNITS[channel]:
        raise ValueError(
            f"{where}: unit {unit!r} of channel {channel!r}; expected one of "
            f"{', '.join(UNITS[channel])}"
        )
    return spelled


def parse_time(values: Sequence[str], unit: str, where: str) -> tuple[np.ndarray, str | None]:
    """Seconds from the first sample (and its ISO time for datetimes)."""
    if unit != "datetime":
        return parse_numbers(values, where), None
    out = np.empty(len(values))
    first: datetime | None = None
    for k, text in enumerate(values):
        s = text.strip()
        if not s:
            out[k] = math.nan
            continue
        try:
            stamp = datetime.fromisoformat(s)
        except ValueError:
            raise ValueError(
                f"{where} row {k + 1}: {s!r} is not an ISO-8601 date and time (expected "
                "e.g. 2026-12-31T23:59:58.1Z)"
            ) from None
        if stamp.tzinfo is None:
            stamp = stamp.replace(tzinfo=UTC)
        if first is None:
            first = stamp
        out[k] = (stamp - first).total_seconds()
    return out, None if first is None else first.isoformat()


def parse_numbers(values: Sequence[str], where: str) -> np.ndarray:
    """Floats of text fields; empty fields and ``nan`` are NaN; text is refused."""
    try:
        return np.array([float(v) if v.strip() else math.nan for v in values], dtype=np.float64)
    except ValueError:
        for k, v in enumerate(values):
            try:
                float(v) if v.strip() else None
            except ValueError:
                bad = [x for x in values if x.strip() and not _is_number(x)]
                raise ValueError(
                    f"{where} row {k + 1}: {v.strip()!r} is not a number ({len(bad)} text "
                    "fields in the column); expected numbers (is it the right column?)"
                ) from None
    raise AssertionError("unreachable")  # pragma: no cover


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True

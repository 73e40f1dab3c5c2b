"""Synthetic NMEA 0183 logs of a simulated ship: the known truth of the NMEA reader's tests
and of the worked example (:func:`write_nmea`).

Each sentence type is written at its own rate with the talkers, noise, logger time stamps, bad
checksums and dropouts asked for, in the forms :func:`shipgym.sysid.io.nmea.load_nmea` reads
(its module docstring lists the sentences and their conventions).
"""

from __future__ import annotations

import datetime
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pynmeagps
from pynmeagps import calc_checksum

from shipgym.sysid.io.nmea import NMEA_LOGGER_STYLES
from shipgym.sysid.units import KNOT

__all__ = ["DEFAULT_RATES", "write_nmea"]

DEFAULT_RATES: Mapping[str, float] = {
    "HDT": 10.0,
    "ROT": 5.0,
    "RSA": 5.0,
    "RMC": 1.0,
    "GGA": 1.0,
    "VTG": 1.0,
    "ZDA": 1.0,
}
"""Sentence rates [Hz] that :func:`write_nmea` uses when ``rates`` is not given."""

_DEFAULT_TALKERS: Mapping[str, str] = {
    "HDT": "HE",
    "THS": "HE",
    "HDG": "HC",
    "ROT": "HE",
    "RSA": "II",
    "RMC": "GP",
    "GGA": "GP",
    "GLL": "GP",
    "VTG": "GP",
    "ZDA": "GP",
}
# order of the sentences of one instant in write_nmea: time-stamped sentences first
_WRITE_ORDER = ("ZDA", "RMC", "GGA", "GLL", "VTG", "HDT", "THS", "HDG", "ROT", "RSA")
_NOISE_KEYS = ("psi", "r", "delta", "U", "course", "xy")


# ----------------------------------------------------------------------------------------------
# writing a synthetic log
# ----------------------------------------------------------------------------------------------
def _radii(lat0_deg: float) -> tuple[float, float]:
    """Meridian and prime-vertical radii [m] of the WGS84 ellipsoid at ``lat0_deg``."""
    a = pynmeagps.WGS84_SMAJ_AXIS
    f = 1.0 / pynmeagps.WGS84_FLATTENING
    e2 = f * (2.0 - f)
    s2 = math.sin(math.radians(lat0_deg)) ** 2
    return a * (1.0 - e2) / (1.0 - e2 * s2) ** 1.5, a / math.sqrt(1.0 - e2 * s2)


def _dm(value: float, width: int) -> str:
    """Degrees as NMEA ``(d)ddmm.mmmmm``."""
    total = round(abs(value) * 60.0 * 1e5)
    deg, minutes = divmod(total, 60 * 100_000)
    return f"{deg:0{width}d}{minutes / 1e5:08.5f}"


def _optional_array(value: npt.ArrayLike | None, what: str, n: int) -> np.ndarray | None:
    return None if value is None else _array(value, what, n)


def _array(value: npt.ArrayLike, what: str, n: int) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64)
    if arr.shape != (n,):
        raise ValueError(f"{what} must have shape ({n},) like time, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(
            f"{what} has a non-finite value at sample {np.flatnonzero(~np.isfinite(arr))[0]}"
        )
    return arr


def _stamp_text(style: str, when: datetime.datetime) -> str:
    ms = when.microsecond // 1000
    if style == "iso":
        return f"{when:%Y-%m-%dT%H:%M:%S}.{ms:03d}Z "
    if style == "bracket":
        return f"[{when:%Y-%m-%d %H:%M:%S}.{ms:03d}] "
    if style == "epoch":
        return f"{when.timestamp():.3f} "
    body = f"c:{math.floor(when.timestamp())}"
    return f"\\{body}*{calc_checksum(body)}\\"


def _ew(value: float) -> str:
    return "E" if value >= 0.0 else "W"


def _sentence(
    kind: str,
    talker: str,
    when: datetime.datetime,
    v: Mapping[str, float],
    variation_deg: float,
    deviation_deg: float,
) -> str:
    """One sentence (without ``$`` and checksum) of :func:`write_nmea` from values in NMEA
    units (deg, deg/min, kn, latitude/longitude in degrees)."""
    hms = f"{when:%H%M%S}.{when.microsecond // 10000:02d}"
    if kind == "HDT":
        return f"{talker}HDT,{v['psi']:.2f},T"
    if kind == "THS":
        return f"{talker}THS,{v['psi']:.2f},A"
    if kind == "HDG":
        mag = (v["psi"] - deviation_deg - variation_deg) % 360.0
        return (
            f"{talker}HDG,{mag:.2f},{abs(deviation_deg):.2f},{_ew(deviation_deg)},"
            f"{abs(variation_deg):.2f},{_ew(variation_deg)}"
        )
    if kind == "ROT":
        return f"{talker}ROT,{v['rot']:.2f},A"
    if kind == "RSA":
        return f"{talker}RSA,{v['delta']:.2f},A,,"
    if kind == "ZDA":
        return f"{talker}ZDA,{hms},{when:%d,%m,%Y},00,00"
    kn = f"{v['sog']:.2f}" if "sog" in v else ""
    if kind == "VTG":
        kmh = f"{v['sog'] * KNOT * 3.6:.2f}" if "sog" in v else ""
        return f"{talker}VTG,{v['cog']:.2f},T,,M,{kn},N,{kmh},K,A"
    lat, lon = v["lat"], v["lon"]
    pos = f"{_dm(lat, 2)},{'N' if lat >= 0 else 'S'},{_dm(lon, 3)},{_ew(lon)}"
    if kind == "GGA":
        return f"{talker}GGA,{hms},{pos},1,10,0.9,0.0,M,40.0,M,,"
    if kind == "GLL":
        return f"{talker}GLL,{pos},{hms},A,A"
    var = f"{abs(variation_deg):.1f},{_ew(variation_deg)}" if variation_deg else ","
    return f"{talker}RMC,{hms},A,{pos},{kn},{v['cog']:.2f},{when:%d%m%y},{var},A"


def write_nmea(
    path: str | Path,
    *,
    start: datetime.datetime,
    time: npt.ArrayLike,
    psi: npt.ArrayLike,
    r: npt.ArrayLike | None = None,
    delta: npt.ArrayLike | None = None,
    U: npt.ArrayLike | None = None,
    course: npt.ArrayLike | None = None,
    x: npt.ArrayLike | None = None,
    y: npt.ArrayLike | None = None,
    lat0: float = 63.44,
    lon0: float = 10.40,
    rates: Mapping[str, float] | None = None,
    talkers: Mapping[str, str] | None = None,
    noise: Mapping[str, float] | None = None,
    seed: int = 0,
    variation_deg: float = 0.0,
    deviation_deg: float = 0.0,
    omit: Mapping[str, Sequence[tuple[float, float]]] | None = None,
    bad_checksums: Sequence[int] = (),
    logger: str | None = None,
) -> Path:
    """Write a synthetic NMEA 0183 log of a (simulated) ship, one sentence a line.

    Each sentence type is sampled at its own rate, ``t = k / rate`` [s from ``start``] within
    ``time``, with the channels interpolated linearly (``psi`` and ``course`` as continuous
    angles). Sentences of one instant are written time-stamped ones first (ZDA, RMC, GGA, GLL,
    VTG, HDT, THS, HDG, ROT, RSA). Resolution: times 0.01 s, angles and rates 0.01 deg (deg/min),
    speed 0.01 kn, positions 1e-5 arc minute.

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write.
    start : datetime.datetime
        UTC time of ``time = 0`` (a naive value is taken as UTC).
    time : array_like
        Sample times [s] from ``start``, strictly increasing.
    psi : array_like
        Heading [rad], clockwise from north (HDT, THS, HDG).
    r : array_like, optional
        Yaw rate [rad/s] (ROT).
    delta : array_like, optional
        Rudder angle [rad], starboard positive (RSA).
    U : array_like, optional
        Speed over ground [m/s] (RMC, VTG).
    course : array_like, optional
        Course over ground [rad] (RMC, VTG); ``psi`` when None (no drift).
    x, y : array_like, optional
        North and east position [m] (RMC, GGA, GLL), placed around ``lat0``, ``lon0`` on the
        WGS84 local tangent plane.
    lat0, lon0 : float
        Latitude and longitude [deg] of ``x = y = 0``.
    rates : mapping, optional
        Sentence type -> rate [Hz] (types HDT, THS, HDG, ROT, RSA, RMC, GGA, GLL, VTG, ZDA; a
        rate of 0 is not written); :data:`DEFAULT_RATES` when None. A type whose channel is not
        given is not written (ROT needs ``r``, RSA ``delta``, VTG ``U``, RMC/GGA/GLL ``x``, ``y``).
    talkers : mapping, optional
        Sentence type -> two-letter talker (defaults: HE for HDT, THS, ROT; HC for HDG; II for
        RSA; GP for the GNSS sentences).
    noise : mapping, optional
        Standard deviation of white noise added to each sentence's value, in SI units: keys
        ``psi`` [rad], ``r`` [rad/s], ``delta`` [rad], ``U`` [m/s], ``course`` [rad], ``xy`` [m].
    seed : int
        Seed of the noise.
    variation_deg, deviation_deg : float
        Magnetic variation and compass deviation [deg], E positive: HDG gives
        ``psi - deviation - variation`` with both fields; RMC gives the variation when non-zero.
    omit : mapping, optional
        Sentence type -> list of ``(t0, t1)`` [s]: sentences of that type with ``t0 <= t < t1``
        are not written (a sensor drop-out).
    bad_checksums : sequence of int
        Indices of sentences (0-based, in file order, so line ``index + 1``) written with a wrong
        checksum.
    logger : {"iso", "bracket", "epoch", "tag"}, optional
        Prefix every line with a logger time stamp: ``2026-12-31T23:59:58.100Z``,
        ``[2026-12-31 23:59:58.100]``, ``1735689598.100`` or a tag block ``\\c:1735689598*hh\\``
        (whole seconds).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        For arrays of the wrong shape or with non-finite values, a time that is not strictly
        increasing, an unknown sentence type, talker, noise key or logger style, a negative rate
        and a ``bad_checksums`` index outside the written sentences.
    """
    path = Path(path)
    t_in = np.asarray(time, dtype=np.float64)
    if t_in.ndim != 1 or t_in.size < 2 or not np.all(np.isfinite(t_in)):
        raise ValueError(f"time must be a 1-D array of >= 2 finite times in s, got {t_in.shape}")
    if np.any(np.diff(t_in) <= 0.0):
        raise ValueError("time must be strictly increasing")
    n = t_in.size
    chan = {
        "psi": np.unwrap(_array(psi, "psi", n)),
        "r": _optional_array(r, "r", n),
        "delta": _optional_array(delta, "delta", n),
        "U": _optional_array(U, "U", n),
        "course": _optional_array(course, "course", n),
        "x": _optional_array(x, "x", n),
        "y": _optional_array(y, "y", n),
    }
    if chan["course"] is None:
        chan["course"] = chan["psi"]
    else:
        chan["course"] = np.unwrap(chan["course"])
    rates = dict(DEFAULT_RATES if rates is None else rates)
    for key, rate in rates.items():
        if key not in _WRITE_ORDER:
            raise ValueError(f"unknown sentence type {key!r} in rates; expected {_WRITE_ORDER}")
        if not (math.isfinite(rate) and rate >= 0.0):
            raise ValueError(f"rate of {key} must be a finite number of Hz >= 0, got {rate!r}")
    talk = dict(_DEFAULT_TALKERS)
    for key, value in (talkers or {}).items():
        if key not in _WRITE_ORDER or not re.fullmatch(r"[A-Z][A-Z0-9]", str(value)):
            raise ValueError(
                f"talkers must map a sentence type of {_WRITE_ORDER} to two capitals, got "
                f"{key!r}: {value!r}"
            )
        talk[key] = value
    sigma = dict(noise or {})
    for key in sigma:
        if key not in _NOISE_KEYS:
            raise ValueError(f"unknown noise key {key!r}; expected one of {_NOISE_KEYS}")
    if logger is not None and logger not in NMEA_LOGGER_STYLES:
        raise ValueError(f"unknown logger style {logger!r}; expected one of {NMEA_LOGGER_STYLES}")
    if start.tzinfo is None:
        start = start.replace(tzinfo=datetime.UTC)
    start = start.astimezone(datetime.UTC)
    rng = np.random.default_rng(seed)
    m_rad, n_rad = _radii(lat0)
    needs = {
        "ROT": ("r",),
        "RSA": ("delta",),
        "VTG": ("U",),
        "RMC": ("x", "y"),
        "GGA": ("x", "y"),
        "GLL": ("x", "y"),
    }

    def sample(key: str, ts: np.ndarray, noise_key: str | None = None) -> np.ndarray:
        values = np.interp(ts, t_in, chan[key])
        std = sigma.get(noise_key or key, 0.0)
        return values + rng.normal(0.0, std, ts.size) if std > 0.0 else values

    rows: list[tuple[int, int, str]] = []  # (microsecond tick, order, text without $ and *)
    for order, kind in enumerate(_WRITE_ORDER):
        rate = rates.get(kind, 0.0)
        if rate <= 0.0 or any(chan[c] is None for c in needs.get(kind, ())):
            continue
        k = np.arange(math.ceil(t_in[0] * rate - 1e-9), math.floor(t_in[-1] * rate + 1e-9) + 1)
        ts = k / rate
        for t0, t1 in (omit or {}).get(kind, ()):
            ts = ts[(ts < t0) | (ts >= t1)]
        if ts.size == 0:
            continue
        values = {"psi": np.mod(np.degrees(sample("psi", ts)), 360.0)}  # NMEA units
        if kind == "ROT":
            values["rot"] = np.degrees(sample("r", ts)) * 60.0
        if kind == "RSA":
            values["delta"] = np.degrees(sample("delta", ts))
        if kind in ("RMC", "VTG"):
            values["cog"] = np.mod(np.degrees(sample("course", ts)), 360.0)
            if chan["U"] is not None:
                values["sog"] = np.maximum(sample("U", ts), 0.0) / KNOT
        if kind in ("RMC", "GGA", "GLL"):
            values["lat"] = lat0 + np.degrees(sample("x", ts, "xy") / m_rad)
            east = sample("y", ts, "xy") / (n_rad * math.cos(math.radians(lat0)))
            values["lon"] = lon0 + np.degrees(east)
        for i, t in enumerate(ts.tolist()):
            tick = round(t * 1e6)
            when = start + datetime.timedelta(microseconds=tick)
            one = {key: float(v[i]) for key, v in values.items()}
            text = _sentence(kind, talk[kind], when, one, variation_deg, deviation_deg)
            rows.append((tick, order, text))
    rows.sort(key=lambda row: (row[0], row[1]))
    bad = set(bad_checksums)
    if any(not (0 <= int(b) < len(rows)) for b in bad):
        raise ValueError(
            f"bad_checksums must index the {len(rows)} written sentences (0 .. {len(rows) - 1}), "
            f"got {sorted(bad)}"
        )
    with path.open("w", encoding="ascii", newline="\r\n") as fh:
        for index, (tick, _order, text) in enumerate(rows):
            checksum = calc_checksum(text)
            if index in bad:
                checksum = f"{int(checksum, 16) ^ 0x5A:02X}"
            prefix = ""
            if logger is not None:
                prefix = _stamp_text(logger, start + datetime.timedelta(microseconds=tick))
            fh.write(f"{prefix}${text}*{checksum}\n")
    return path

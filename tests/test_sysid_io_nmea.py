"""The NMEA reader on hand-written NMEA 0183 sentences of known values (not the project's writer).

Two 12 s logs at 1 Hz, each second an ``RMC`` (time, position, speed, course), an ``HDG``
(magnetic heading, deviation, variation), a ``ROT`` and an ``RSA`` sentence, with talkers the
writer does not use (``GN``, ``TI``, ``AG``, ``IN``). The NMEA conventions (IEC 61162-1):

* ``RSA``: rudder sensor angle, "relative measurement of rudder angle without units,
  '-' = bow turns to port", so starboard rudder is positive: the project's ``delta`` sign;
* ``ROT``: rate of turn [deg/min], "'-' = bow turns to port": the project's ``r`` sign
  (clockwise positive);
* ``HDG``: true heading = magnetic sensor heading + deviation + variation, easterly positive,
  westerly negative;
* latitude ``ddmm.mmmm`` N/S, longitude ``dddmm.mmmm`` E/W: south and west are negative.

A port turn in the south-western hemisphere with a westerly variation and an easterly
deviation, and a starboard turn in the north-eastern hemisphere with an easterly variation and
a westerly deviation: every sign of the reader shows in the record's values.
"""

from __future__ import annotations

import math
import warnings
from functools import reduce
from pathlib import Path

import numpy as np
import pytest

from shipgym.sysid.data import Record, SysidDataWarning, detect_format, load
from shipgym.sysid.io.nmea import load_nmea

KNOT = 1852.0 / 3600.0
NM = 1852.0  # one arc minute of latitude [m] (the WGS84 meridian arc varies by 0.5 %)


def _checksum(body: str) -> str:
    """XOR of the characters between ``$`` and ``*`` (IEC 61162-1), two hex digits."""
    return f"{reduce(lambda a, c: a ^ ord(c), body, 0):02X}"


def _line(body: str) -> str:
    return f"${body}*{_checksum(body)}"


def test_the_checksum_of_the_sentences_is_the_standards() -> None:
    """The XOR checksum above reproduces a published sentence (the GPGGA example of the
    NMEA reference, checksum 76)."""
    body = "GPGGA,092750.000,5321.6802,N,00630.3372,W,1,8,1.03,61.7,M,55.2,M,,"
    assert _line(body) == f"${body}*76"


def _dm(value_deg: float, width: int) -> str:
    minutes = abs(value_deg) * 60.0
    return f"{int(minutes // 60):0{width}d}{minutes % 60:08.5f}"


def _log(
    path: Path,
    *,
    heading_mag_deg: float,
    deviation: tuple[float, str],
    variation: tuple[float, str],
    rot_deg_min: float,
    rudder_deg: float,
    lat0_deg: float,
    lon0_deg: float,
    speed_kn: float = 5.0,
    n: int = 12,
) -> dict[str, np.ndarray]:
    """Write the log and return the truth: true heading [deg], course, north/east run [m]."""
    sign = {"E": 1.0, "W": -1.0}
    offset = sign[deviation[1]] * deviation[0] + sign[variation[1]] * variation[0]
    rate = rot_deg_min / 60.0  # deg/s
    t = np.arange(n, dtype=float)
    mag = heading_mag_deg + rate * t
    true = mag + offset
    u = speed_kn * KNOT
    # positions: the ship runs along its true heading; north and east from the first fix
    north = np.concatenate(([0.0], np.cumsum(u * np.cos(np.radians(0.5 * (true[1:] + true[:-1]))))))
    east = np.concatenate(([0.0], np.cumsum(u * np.sin(np.radians(0.5 * (true[1:] + true[:-1]))))))
    lat = lat0_deg + north / NM / 60.0
    lon = lon0_deg + east / (NM * math.cos(math.radians(lat0_deg))) / 60.0
    lines = []
    for k in range(n):
        hms = f"1000{k:02d}.00"
        pos = (
            f"{_dm(lat[k], 2)},{'N' if lat[k] >= 0 else 'S'},"
            f"{_dm(lon[k], 3)},{'E' if lon[k] >= 0 else 'W'}"
        )
        var = f"{variation[0]:.1f},{variation[1]}"
        lines += [
            _line(f"GNRMC,{hms},A,{pos},{speed_kn:.2f},{true[k] % 360:.1f},010326,{var},A"),
            _line(
                f"INHDG,{mag[k] % 360:.1f},{deviation[0]:.1f},{deviation[1]},"
                f"{variation[0]:.1f},{variation[1]}"
            ),
            _line(f"TIROT,{rot_deg_min:.1f},A"),
            _line(f"AGRSA,{rudder_deg:.1f},A,,V"),
        ]
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return {"true": true, "north": north, "east": east}


@pytest.fixture()
def port_turn_south_west(tmp_path: Path) -> tuple[Path, dict[str, np.ndarray]]:
    """Port rudder, turning to port at 30 deg/min, off Chile (33.75 S, 70.5 W); variation
    15 deg W, deviation 2 deg E: true heading = magnetic - 13 deg."""
    path = tmp_path / "port.nmea"
    truth = _log(
        path,
        heading_mag_deg=200.0,
        deviation=(2.0, "E"),
        variation=(15.0, "W"),
        rot_deg_min=-30.0,
        rudder_deg=-10.0,
        lat0_deg=-33.75,
        lon0_deg=-70.5,
    )
    return path, truth


@pytest.fixture()
def starboard_turn_north_east(tmp_path: Path) -> tuple[Path, dict[str, np.ndarray]]:
    """Starboard rudder, turning to starboard at 30 deg/min, off Trondheim (63.45 N, 10.4 E);
    variation 3 deg E, deviation 1.5 deg W: true heading = magnetic + 1.5 deg."""
    path = tmp_path / "starboard.nmea"
    truth = _log(
        path,
        heading_mag_deg=40.0,
        deviation=(1.5, "W"),
        variation=(3.0, "E"),
        rot_deg_min=30.0,
        rudder_deg=10.0,
        lat0_deg=63.45,
        lon0_deg=10.4,
    )
    return path, truth


def _read(path: Path) -> Record:
    with warnings.catch_warnings():
        warnings.simplefilter("error", SysidDataWarning)  # a clean log: nothing repaired
        return load_nmea(path)


def test_the_hand_written_logs_are_detected_as_nmea(
    port_turn_south_west: tuple[Path, dict[str, np.ndarray]],
) -> None:
    path, _ = port_turn_south_west
    assert detect_format(path) == "nmea"
    assert load(path).n == 12


def test_port_rudder_negative_rot_west_variation_south_west_hemisphere(
    port_turn_south_west: tuple[Path, dict[str, np.ndarray]],
) -> None:
    path, truth = port_turn_south_west
    rec = _read(path)
    np.testing.assert_array_equal(rec.time, np.arange(12.0))
    # RSA -10.0: bow turns to port, the project's delta = -10 deg (positive = starboard)
    np.testing.assert_allclose(rec.delta, math.radians(-10.0), rtol=0, atol=1e-12)
    # ROT -30.0 deg/min: bow turns to port, r = -0.5 deg/s (positive clockwise)
    np.testing.assert_allclose(rec.r, math.radians(-0.5), rtol=0, atol=1e-12)
    # HDG 200.0 magnetic, 2.0 E deviation, 15.0 W variation: 187.0 true, then 0.5 deg/s less
    assert rec.psi[0] == pytest.approx(math.radians(187.0), abs=1e-9)
    np.testing.assert_allclose(np.degrees(rec.psi), truth["true"], rtol=0, atol=0.051)
    # heading south-south-west (187 to 181.5 deg): x (north) falls, y (east) goes west
    assert rec.x[-1] == pytest.approx(truth["north"][-1], rel=0.01)
    assert rec.x[-1] < -25.0
    assert rec.y[-1] == pytest.approx(truth["east"][-1], abs=0.1)
    assert rec.y[-1] < 0.0
    np.testing.assert_allclose(rec.U, 5.0 * KNOT, rtol=0, atol=1e-9)
    assert rec.meta["start_time"].startswith("2026-03-01T10:00:00")


def test_starboard_rudder_positive_rot_east_variation_north_east_hemisphere(
    starboard_turn_north_east: tuple[Path, dict[str, np.ndarray]],
) -> None:
    path, truth = starboard_turn_north_east
    rec = _read(path)
    np.testing.assert_allclose(rec.delta, math.radians(10.0), rtol=0, atol=1e-12)
    np.testing.assert_allclose(rec.r, math.radians(0.5), rtol=0, atol=1e-12)
    # HDG 40.0 magnetic, 1.5 W deviation, 3.0 E variation: 41.5 true
    assert rec.psi[0] == pytest.approx(math.radians(41.5), abs=1e-9)
    np.testing.assert_allclose(np.degrees(rec.psi), truth["true"], rtol=0, atol=0.051)
    # heading north-east: both x (north) and y (east) grow
    assert rec.x[-1] == pytest.approx(truth["north"][-1], rel=0.01)
    assert rec.y[-1] == pytest.approx(truth["east"][-1], rel=0.01)
    assert rec.x[-1] > 15.0
    assert rec.y[-1] > 15.0
    # the course equals the heading: all of the speed is surge
    np.testing.assert_allclose(rec.v, 0.0, rtol=0, atol=0.01)


def test_the_rudder_and_the_turn_have_one_sign(
    port_turn_south_west: tuple[Path, dict[str, np.ndarray]],
    starboard_turn_north_east: tuple[Path, dict[str, np.ndarray]],
) -> None:
    """Positive rudder turns the ship to starboard (r > 0), as a Nomoto fit needs K > 0: the
    port log has both negative, the starboard log both positive, and the heading follows r."""
    for path, _ in (port_turn_south_west, starboard_turn_north_east):
        rec = _read(path)
        assert np.sign(rec.delta[0]) == np.sign(rec.r[0]) == np.sign(rec.psi[-1] - rec.psi[0])


def test_a_talker_the_parser_does_not_know_reads_like_a_known_one(tmp_path: Path) -> None:
    """``ZZ`` is no registered talker: its sentences are read as those of ``II``."""
    port = tmp_path / "zz.nmea"
    _log(
        port,
        heading_mag_deg=100.0,
        deviation=(0.0, "E"),
        variation=(0.0, "E"),
        rot_deg_min=-12.0,
        rudder_deg=-5.0,
        lat0_deg=10.0,
        lon0_deg=20.0,
    )
    text = port.read_text().splitlines()
    renamed = []
    for line in text:
        body = line[1:].split("*")[0]
        if body.startswith("AGRSA"):
            body = "ZZRSA" + body[5:]
        renamed.append(_line(body))
    port.write_text("\n".join(renamed) + "\n")
    rec = _read(port)
    np.testing.assert_allclose(rec.delta, math.radians(-5.0), rtol=0, atol=1e-12)
    assert any("ZZRSA" in c for c in rec.meta["conversions"])


def test_a_wrong_checksum_drops_the_sentence(tmp_path: Path) -> None:
    path = tmp_path / "bad.nmea"
    _log(
        path,
        heading_mag_deg=40.0,
        deviation=(0.0, "E"),
        variation=(0.0, "E"),
        rot_deg_min=6.0,
        rudder_deg=3.0,
        lat0_deg=0.5,
        lon0_deg=0.5,
    )
    lines = path.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("$AGRSA") and i > 20)
    lines[k] = lines[k].replace("3.0", "30.0")  # the checksum no longer fits
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(SysidDataWarning, match=rf"bad checksum \(line {k + 1}\)"):
        rec = load_nmea(path)
    np.testing.assert_allclose(rec.delta, math.radians(3.0), rtol=0, atol=1e-12)

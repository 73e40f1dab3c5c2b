"""Tests of shipgym.sysid.io.nmea: NMEA 0183 logs written from a simulated zigzag and read back.

The ship is a first-order Nomoto model (K = 0.1 1/s, T = 30 s) steered through a 10/10 zigzag
after 20 s of straight running; :func:`write_nmea` samples it at mixed rates (HDT 10 Hz, ROT and
RSA 5 Hz, RMC, GGA, VTG, ZDA 1 Hz) from 23:59:30 UTC on 31 Dec 2026, so a log of more than
30 s crosses midnight and the year.

Tolerances (read-back against the simulated truth on the 0.1 s grid): the sentences carry 0.01
deg, 0.01 deg/min, 0.01 kn and 1e-5 arc minute, so the quantisation is half of that; linear
interpolation of a channel sampled every h adds at most h^2/8 max|f''| for a smooth channel and
(rate change) * h / 4 at a corner of the rate-limited rudder.
"""

from __future__ import annotations

import datetime
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from pynmeagps import calc_checksum

from shipgym.models import Nomoto1Params, SteeringGear, make_model
from shipgym.sysid.data import Record, SysidDataWarning
from shipgym.sysid.io.nmea import NMEA_LOGGER_STYLES, load_nmea, looks_like_nmea
from shipgym.sysid.nmea_writer import DEFAULT_RATES, write_nmea

START = datetime.datetime(2026, 12, 31, 23, 59, 30, tzinfo=datetime.UTC)
KNOT = 1852.0 / 3600.0
ARCMIN_M = 1852.0  # one arc minute of latitude is about one nautical mile


@pytest.fixture(scope="module")
def ship() -> dict[str, np.ndarray]:
    """240 s of a 10/10 zigzag (starting at t = 20 s), every 0.05 s."""
    model = make_model("nomoto1", Nomoto1Params(K=0.1, T=30.0))
    order = {"delta": 0.0}
    ten = math.radians(10.0)

    def pilot(t: float, x: np.ndarray) -> list[float]:
        if t >= 20.0:
            if order["delta"] == 0.0 or x[2] < -ten:
                order["delta"] = ten
            elif x[2] > ten:
                order["delta"] = -ten
        return [order["delta"], 1.4]

    res = model.simulate([0.0, 0.0, 0.0, 7.7, 0.0, 0.0], pilot, 0.05, n_steps=4800)
    return {name: res[name] for name in ("x", "y", "psi", "U", "r", "delta")} | {"time": res.time}


def _write(path: Path, ship: dict[str, np.ndarray], until: float | None = None, **kw) -> Path:
    keep = slice(None) if until is None else ship["time"] <= until
    return write_nmea(path, start=START, **{k: v[keep] for k, v in ship.items()}, **kw)


def _load(path: Path, **kw) -> Record:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidDataWarning)
        return load_nmea(path, **kw)


def _truth(rec: Record, ship: dict[str, np.ndarray], name: str) -> np.ndarray:
    start = datetime.datetime.fromisoformat(rec.meta["start_time"])
    t = rec.time + (start - START).total_seconds()
    return np.interp(t, ship["time"], ship[name])


def test_round_trip_across_midnight_and_year(tmp_path, ship):
    path = _write(tmp_path / "voyage.nmea", ship, bad_checksums=[17])
    with pytest.warns(SysidDataWarning, match=r"1 sentence with a bad checksum \(line 18\)"):
        rec = load_nmea(path)
    assert "dropped 1 sentence with a bad checksum (line 18)" in rec.meta["repairs"]
    assert rec.meta["source"] == "nmea" and rec.meta["file"] == "voyage.nmea"
    assert rec.meta["start_time"] == "2026-12-31T23:59:30+00:00"
    assert any("1 midnight roll-over" in c for c in rec.meta["conversions"])
    # continuous time across 00:00:00 on 1 Jan 2027: one segment on the HDT grid
    assert "segments" not in rec.meta
    np.testing.assert_allclose(np.diff(rec.time), 0.1, atol=1e-9)
    assert rec.time[0] == 0.0 and rec.time[-1] == pytest.approx(240.0)

    a_lat = float(np.max(ship["U"] * np.abs(ship["r"])))  # |x''|, |y''| bound [m/s^2]
    rudder_rate = SteeringGear().max_rate
    tol = {
        "psi": math.radians(0.005) + 1e-9,
        "r": math.radians(0.005) / 60.0 + 1e-6,  # + (0.2 s)^2 / 8 max|r''| (< 1e-6 rad/s)
        "delta": math.radians(0.005) + rudder_rate * 0.2 / 4.0,
        "U": 0.005 * KNOT,
    }
    for name, atol in tol.items():
        err = np.max(np.abs(getattr(rec, name) - _truth(rec, ship, name)))
        assert err <= atol, (name, err, atol)
    pos_tol = 0.5e-5 * ARCMIN_M + a_lat / 8.0  # 1 Hz fixes: h = 1 s
    for name in ("x", "y"):
        truth = _truth(rec, ship, name)
        err = np.max(np.abs(getattr(rec, name) - (truth - truth[0])))
        assert err <= pos_tol, (name, err, pos_tol)
    # no drift in the Nomoto model: u = U, v = 0 within the course and heading resolution
    assert np.max(np.abs(rec.v)) < rec.U.max() * math.radians(0.02)
    assert rec.meta["r_source"] == "measured: HEROT rate of turn"


def test_gap_in_the_heading_splits_the_record(tmp_path, ship):
    path = _write(tmp_path / "gap.nmea", ship, omit={"HDT": [(100.0, 130.0)]})
    with pytest.warns(SysidDataWarning, match="split into 2 segments"):
        rec = load_nmea(path)
    (a0, a1), (b0, b1) = rec.meta["segments"]
    assert a0 == 0.0 and a1 == pytest.approx(99.9) and b0 == pytest.approx(130.0)
    assert b1 == pytest.approx(240.0)
    assert not np.any((rec.time > 99.95) & (rec.time < 129.95))
    # a longer gap limit bridges the hole; a given dt sets the grid
    bridged = _load(path, dt=0.2, max_gap_s=40.0)
    assert "segments" not in bridged.meta
    np.testing.assert_allclose(np.diff(bridged.time), 0.2, atol=1e-9)


def test_no_heading_is_one_clear_line(tmp_path, ship):
    rates = {k: v for k, v in DEFAULT_RATES.items() if k != "HDT"}
    path = _write(tmp_path / "nohdg.nmea", ship, until=20.0, rates=rates)
    with pytest.raises(ValueError) as info:
        load_nmea(path)
    message = str(info.value)
    assert "\n" not in message
    assert re.fullmatch(
        r"nohdg\.nmea: no heading sentence \(HDT, THS or HDG\) in \d+ sentences; found .*ROT "
        r"101.*; expected a heading to identify a model",
        message,
    )


def test_magnetic_heading_with_deviation_and_variation(tmp_path, ship):
    rates = {**DEFAULT_RATES, "HDT": 0.0, "HDG": 10.0}
    path = _write(
        tmp_path / "hdg.nmea", ship, until=100.0, rates=rates, variation_deg=-3.5,
        deviation_deg=1.2,
    )  # fmt: skip
    rec = _load(path)
    assert np.max(np.abs(rec.psi - _truth(rec, ship, "psi"))) <= math.radians(0.01)
    assert any(c.startswith("heading: HCHDG magnetic") for c in rec.meta["conversions"])
    # without variation and deviation in HDG, the RMC magnetic variation is used
    path = _write(tmp_path / "hdg2.nmea", ship, until=100.0, rates=rates, variation_deg=-3.5)
    lines = []
    for line in path.read_text().splitlines():
        if line.startswith("$HCHDG"):
            body = line[1:].split("*")[0].rsplit(",", 4)[0] + ",,,,"
            line = f"${body}*{calc_checksum(body)}"
        lines.append(line)
    path.write_text("\n".join(lines) + "\n")
    rec = _load(path)
    assert np.max(np.abs(rec.psi - _truth(rec, ship, "psi"))) <= math.radians(0.01)
    assert any("-3.5 deg from the GPRMC magnetic variation" in n for n in rec.meta["notes"])
    # with a true heading in the log as well, HDT is used and HDG named as not used
    both = _write(tmp_path / "both.nmea", ship, until=100.0, rates={**rates, "HDT": 10.0})
    rec = _load(both)
    assert any("HEHDT true heading" in c and "HDG not used" in c for c in rec.meta["conversions"])


@pytest.mark.parametrize("style", NMEA_LOGGER_STYLES)
def test_logger_time_stamps(tmp_path, ship, style):
    # no time-stamped sentence at all: the times come from the logger alone
    rates = {"HDT": 10.0, "ROT": 5.0, "RSA": 5.0}
    path = _write(tmp_path / f"{style}.log", ship, until=60.0, rates=rates, logger=style)
    head = path.read_text()[:4096]
    assert looks_like_nmea(head)
    rec = _load(path)
    assert rec.meta["start_time"] == "2026-12-31T23:59:30+00:00"
    assert any(c.startswith("time: the logger's time stamps") for c in rec.meta["conversions"])
    np.testing.assert_allclose(np.diff(rec.time), 0.1, atol=1e-6)
    assert np.max(np.abs(rec.psi - _truth(rec, ship, "psi"))) <= math.radians(0.005) + 1e-9


def test_date_sentence_after_midnight(tmp_path, ship):
    # the first date arrives at 00:00:10, after the sentences of 31 Dec
    rates = {"HDT": 10.0, "RSA": 5.0, "GGA": 1.0, "ZDA": 1.0}
    path = _write(tmp_path / "late.nmea", ship, until=60.0, rates=rates, omit={"ZDA": [(0, 40)]})
    rec = _load(path)
    assert rec.meta["start_time"] == "2026-12-31T23:59:30+00:00"
    assert rec.duration == pytest.approx(60.0)


def test_bad_lines_are_counted_never_used(tmp_path, ship):
    path = _write(tmp_path / "raw.nmea", ship, until=30.0, talkers={"HDT": "QQ"})
    lines = path.read_text().splitlines()
    lines[5] = lines[5].split("*")[0]  # a sentence without a checksum: kept
    lines.insert(9, "$HEHDT,12.3.4,T*00 garbage")  # malformed checksum field
    lines.insert(12, "noise from the serial port")
    ais = "AIVDM,1,1,,A,13aG?P0P00PD;88MD5MTDww@2<0L,0"
    lines.insert(14, f"!{ais}*{calc_checksum(ais)}")  # a sentence type that is not read
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(SysidDataWarning, match=r"2 unreadable lines .*lines 10, 13\)"):
        rec = load_nmea(path)
    notes = " | ".join(rec.meta["notes"])
    assert "1 sentence without a checksum: kept, unverified" in notes
    assert "sentence types not read: VDM 1" in notes
    assert any("QQHDT true heading" in c for c in rec.meta["conversions"])  # unknown talker


def test_optional_channel_with_a_gap_is_dropped(tmp_path, ship):
    gnss_off = {"RMC": [(50.0, 70.0)], "GGA": [(50.0, 70.0)]}
    path = _write(tmp_path / "gnss.nmea", ship, until=120.0, omit=gnss_off)
    rec = _load(path)
    assert rec.x is None and rec.y is None
    assert rec.U is not None  # VTG speed has no gap
    assert any(c.startswith("speed: GPVTG") for c in rec.meta["conversions"])
    assert any(n.startswith("position (GPGGA) covers") for n in rec.meta["notes"])
    assert "segments" not in rec.meta and rec.duration == pytest.approx(120.0)


def test_log_without_rudder_reads_with_zero_rudder(tmp_path, ship):
    rates = {k: v for k, v in DEFAULT_RATES.items() if k != "RSA"}
    path = _write(tmp_path / "norsa.nmea", ship, until=30.0, rates=rates)
    with pytest.warns(SysidDataWarning, match="no rudder sensor"):
        rec = load_nmea(path)
    assert np.all(rec.delta == 0.0)
    assert any(n.startswith("no rudder sensor") for n in rec.meta["notes"])


def test_looks_like_nmea():
    assert looks_like_nmea("$HEHDT,12.3,T*1F\r\n$HEROT,0.1,A*1B\r\n$GPGGA,1")
    assert looks_like_nmea("# logger v2\n1735689598.1 $HEHDT,12.3,T*1F\n")
    assert looks_like_nmea("[2026-12-31 23:59:58.100] $HEHDT,1,T*00\n")
    assert looks_like_nmea("\\c:1735689598*5A\\$HEHDT,1,T*00\n")
    assert not looks_like_nmea("time_s,delta_rad,psi_rad\n0,0,0\n")
    assert not looks_like_nmea("")
    assert not looks_like_nmea("t,hdg\n$HEHDT,1,T*00\n")
    # a logger's banner before the sentences
    assert looks_like_nmea("Voyage log started 2026-12-31\n" + "$HEHDT,12.3,T*1F\n" * 7)


def test_a_log_behind_a_banner_line_is_detected_and_read(tmp_path, ship):
    """A logger that writes a banner line first: the log is still detected as NMEA, and the
    reader drops and counts the banner line (nothing unreadable is used)."""
    from shipgym.sysid.data import detect_format

    plain = _write(tmp_path / "plain.nmea", ship, until=60.0)
    banner = tmp_path / "banner.nmea"
    banner.write_text("Bridge logger v3.2, voyage 17\n" + plain.read_text())
    assert detect_format(banner) == "nmea"
    rec, ref = _load(banner), _load(plain)
    np.testing.assert_array_equal(rec.psi, ref.psi)
    assert any("dropped 1 unreadable line" in r for r in rec.meta["repairs"])


def test_write_nmea_refuses_bad_arguments(tmp_path, ship):
    with pytest.raises(ValueError, match="bad_checksums must index"):
        _write(tmp_path / "a.nmea", ship, until=5.0, bad_checksums=[10_000])
    with pytest.raises(ValueError, match="unknown sentence type 'XYZ'"):
        _write(tmp_path / "b.nmea", ship, until=5.0, rates={"XYZ": 1.0})
    with pytest.raises(ValueError, match="dt must be a positive"):
        load_nmea(tmp_path / "c.nmea", dt=0.0)

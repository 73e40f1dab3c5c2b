"""A ship's own log in, an identified model out, that model in the envs and the manoeuvres.

The known truth: a record simulated from the Mariner's first-order Nomoto model with an
undeclared rudder offset (:func:`shipgym.sysid.generate_record`), written as the plain tables a
logger writes (degrees, deg/min, knots, a port-positive rudder, a compass heading in [0, 360),
its own column names, several delimiters and a decimal comma).
"""

from __future__ import annotations

import datetime
import json
import math
import warnings
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from shipgym.cli import main
from shipgym.envs.tasks import IDENTIFIED_SHIP_LENGTH
from shipgym.models import Nomoto1Params, Nomoto2Params, make_model
from shipgym.models.delay import DelayLine
from shipgym.models.model_file import load_model, nomoto_document
from shipgym.sysid import Record, generate_record, identify, load
from shipgym.sysid.data import SysidDataWarning, measured_root
from shipgym.sysid.io.table import parse_columns
from shipgym.sysid.nmea_writer import write_nmea

pytestmark = pytest.mark.xdist_group("test_user_logs")

KNOT = 1852.0 / 3600.0
COLUMNS = "time=t,delta=-rudder_port:deg,psi=hdg:deg,r=rot:deg/min,U=sog:kn"


@pytest.fixture(scope="module")
def truth() -> Record:
    """The simulated ship: Mariner nomoto1 (K 0.185 1/s, T 107.3 s), 2 deg rudder offset."""
    return generate_record("rudder_offset", dt=0.5, seed=3)


def _table(rec: Record, sep: str = ",", decimal: str = ".") -> str:
    """The record as a logger writes it: its own names, degrees, deg/min, knots, a
    port-positive rudder and a compass heading wrapped to [0, 360)."""
    cols = {
        "t": rec.time,
        "rudder_port": -np.degrees(rec.delta),
        "hdg": np.mod(np.degrees(rec.psi), 360.0),
        "rot": np.degrees(rec.r) * 60.0,
        "sog": rec.U / KNOT,
    }
    lines = ["# exported by the bridge logger", sep.join(cols)]
    for k in range(rec.n):
        row = sep.join(f"{v[k]:.9f}" for v in cols.values())
        lines.append(row.replace(".", decimal) if decimal != "." else row)
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def csv_record(truth: Record, tmp_path_factory: pytest.TempPathFactory) -> Record:
    path = tmp_path_factory.mktemp("logs") / "myship.csv"
    path.write_text(_table(truth))
    return load(path, columns=COLUMNS)


def test_a_plain_csv_with_a_column_map_imports_the_simulated_ship(
    truth: Record, csv_record: Record
) -> None:
    rec = csv_record
    np.testing.assert_allclose(rec.time, truth.time, atol=1e-9)
    # 9 decimals of degrees, deg/min and knots
    np.testing.assert_allclose(rec.delta, truth.delta, atol=1e-10)
    np.testing.assert_allclose(rec.psi - rec.psi[0], truth.psi - truth.psi[0], atol=1e-10)
    assert abs(rec.psi[0] - truth.psi[0]) % (2 * math.pi) < 1e-10
    np.testing.assert_allclose(rec.r, truth.r, atol=1e-11)
    np.testing.assert_allclose(rec.U, truth.U, atol=1e-9)
    assert rec.meta["source"] == "table" and "segments" not in rec.meta
    assert "delta = -rudder_port [deg]" in rec.meta["conversions"]


def test_the_csv_identifies_the_truth_within_two_percent(truth: Record, csv_record: Record) -> None:
    res = identify(csv_record, "nomoto1", max_effects=1)
    assert res.effect_names == ["rudder_offset"]
    true = truth.meta["truth"]["params"]
    got = res.parameters_after
    offset = -true["n0"] / true["K"]  # the record's rudder is delta_true - offset
    assert got["K"] == pytest.approx(true["K"], rel=0.02)
    assert got["T"] == pytest.approx(true["T"], rel=0.02)
    assert got["delta0"] == pytest.approx(offset, rel=0.02)
    doc = res.to_dict()["nomoto"]
    assert doc["rudder_offset_rad"] == pytest.approx(offset, rel=0.02)
    assert doc["speed_m_s"] == pytest.approx(7.7, rel=1e-3)
    # the result is a model with its offset: as a ShipModel, a fit's model and an env's ship
    ship = res.ship_model()
    assert ship.name == "norrbin" and ship.params.n0 == pytest.approx(-got["K"] * got["delta0"])
    assert res.final.model().params == ship.params
    env = gym.make("shipgym/NomotoHeading-v0", model=res)
    assert env.unwrapped.task.model.params == ship.params
    # a table states no length: the envs take a small craft's, so the option ranges are wide
    assert env.unwrapped.task.ship_length == IDENTIFIED_SHIP_LENGTH


@pytest.mark.parametrize(
    ("sep", "decimal"), [(";", ","), ("\t", "."), ("\t", ","), (" ", "."), (" ", ",")]
)
def test_delimiters_and_decimal_comma(
    truth: Record, csv_record: Record, tmp_path: Path, sep: str, decimal: str
) -> None:
    path = tmp_path / "log.txt"
    path.write_text(_table(truth, sep, decimal))
    rec = load(path, columns=COLUMNS)
    for name in ("time", "delta", "psi", "r", "U"):
        np.testing.assert_array_equal(getattr(rec, name), getattr(csv_record, name))
    assert ("decimal comma read as a decimal point" in rec.meta["conversions"]) == (decimal == ",")


@pytest.mark.parametrize("sep", [",", ";"])
def test_quoted_fields_with_a_decimal_comma(
    truth: Record, csv_record: Record, tmp_path: Path, sep: str
) -> None:
    """A spreadsheet's export: every field in double quotes, decimal commas inside them (with a
    comma as the delimiter too)."""
    rows = _table(truth, ";", ",").splitlines()
    quoted = [rows[0]] + [sep.join(f'"{f}"' for f in row.split(";")) for row in rows[1:]]
    path = tmp_path / "export.csv"
    path.write_text("\n".join(quoted) + "\n")
    rec = load(path, columns=COLUMNS)
    for name in ("time", "delta", "psi", "r", "U"):
        np.testing.assert_array_equal(getattr(rec, name), getattr(csv_record, name))
    assert "decimal comma read as a decimal point" in rec.meta["conversions"]


def test_a_windows_export_with_a_degree_sign_is_read(
    truth: Record, csv_record: Record, tmp_path: Path
) -> None:
    """A table in Windows-1252 (``°`` in a header is one byte, not UTF-8) reads as the same
    record, with a note of the encoding."""
    text = _table(truth).replace("hdg", "hdg °")
    path = tmp_path / "windows.csv"
    path.write_bytes(text.encode("cp1252"))
    rec = load(path, columns=COLUMNS.replace("psi=hdg:deg", "psi=hdg °:deg"))
    for name in ("time", "delta", "psi", "r", "U"):
        np.testing.assert_array_equal(getattr(rec, name), getattr(csv_record, name))
    assert "not UTF-8: read as Windows-1252 (code page 1252)" in rec.meta["conversions"]


def test_unit_suffixes_spelled_per_and_columns_not_read(truth: Record, tmp_path: Path) -> None:
    """``rot_deg_per_min`` is the yaw rate in deg/min; a column no channel takes is named."""
    header = "t_s,rudder_deg,heading_deg,rot_deg_per_min,engine_temp"
    lines = [header] + [
        f"{float(truth.time[k])!r},{math.degrees(truth.delta[k])!r},"
        f"{math.degrees(truth.psi[k])!r},{math.degrees(truth.r[k]) * 60.0!r},80"
        for k in range(truth.n)
    ]
    path = tmp_path / "per.csv"
    path.write_text("\n".join(lines) + "\n")
    rec = load(path)
    np.testing.assert_allclose(rec.r, truth.r, rtol=1e-12, atol=1e-15)
    assert "r = rot_deg_per_min [deg/min]" in rec.meta["conversions"]
    assert "column(s) ['engine_temp'] not read (no channel of a record)" in rec.meta["notes"]


def test_headers_that_state_their_units_need_no_column_map(tmp_path: Path) -> None:
    t = np.arange(200) * 0.5
    psi = np.radians(10.0) * np.sin(t / 20.0)
    r = np.radians(10.0) / 20.0 * np.cos(t / 20.0)
    delta = np.radians(5.0) * np.cos(t / 20.0)
    header = "t_s,rudder [deg],heading_deg,yaw_rate (deg/s),speed_kn,x,lat,lon"
    lines = [header]
    for k in range(t.size):
        # due north at 10 kn: 2.572 m per sample, 2.3e-5 deg of latitude at 63 deg N
        lat, lon = 63.0 + 2.3e-5 * k, 10.0
        lines.append(
            f"{t[k]},{math.degrees(delta[k])!r},{math.degrees(psi[k]) % 360!r},"
            f"{math.degrees(r[k])!r},{10.0},{k},{lat!r},{lon!r}"
        )
    path = tmp_path / "auto.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(SysidDataWarning, match=r"column\(s\) \['x'\] not used: no unit stated"):
        rec = load(path)
    np.testing.assert_allclose(rec.psi, psi, atol=1e-12)
    np.testing.assert_allclose(rec.r, r, atol=1e-15)
    np.testing.assert_allclose(rec.delta, delta, atol=1e-15)
    np.testing.assert_allclose(rec.U, 10.0 * KNOT, rtol=1e-12)
    # lat/lon on the local tangent plane (meridian radius 6.3896e6 m at 63 deg N)
    assert rec.x is not None and rec.y is not None
    np.testing.assert_allclose(np.diff(rec.x), math.radians(2.3e-5) * 6.3896e6, rtol=1e-3)
    np.testing.assert_allclose(rec.y, 0.0, atol=1e-9)


def test_a_header_without_units_is_not_guessed_and_the_error_shows_a_column_map(
    tmp_path: Path,
) -> None:
    path = tmp_path / "myship.csv"
    path.write_text("time,delta,psi,r,x,y,U\n0,0,0,0,0,0,7.7\n1,0,0,0,7.7,0,7.7\n")
    with pytest.raises(ValueError) as err:
        load(path)
    msg = str(err.value)
    assert "['time', 'delta', 'psi', 'r', 'x', 'y', 'U']" in msg
    assert "unit not stated" in msg and "never guessed" in msg
    assert '--columns "time=time:<s|ms|min|h|datetime>,delta=delta:<rad|deg>' in msg
    assert "U=U:<m/s|kn|km/h>" in msg


def test_gaps_split_the_record_into_segments_not_interpolated(
    truth: Record, tmp_path: Path
) -> None:
    text = _table(truth).splitlines()
    # rows 300-309 lose their values (a logger dropout); 60 s of rows 700-819 are missing
    for k in range(300, 310):
        text[2 + k] = ",".join([f"{truth.time[k]:.9f}", "", "", "", ""])
    text = text[: 2 + 700] + text[2 + 820 :]
    path = tmp_path / "gappy.csv"
    path.write_text("\n".join(text) + "\n")
    with pytest.warns(SysidDataWarning, match="split into 3 segments"):
        rec = load(path, columns=COLUMNS)
    assert rec.meta["segments"] == [[0.0, 149.5], [155.0, 349.5], [410.0, 600.0]]
    parts = rec.segments()
    assert [p.n for p in parts] == [300, 390, 381]
    # no sample inside a gap, and the yaw rate of each segment is the measured one
    assert not np.any((rec.time > 149.5) & (rec.time < 155.0))
    np.testing.assert_allclose(parts[2].r, truth.r[820:], atol=1e-11)
    # resampling never bridges a gap; slicing keeps the segments it overlaps
    assert rec.resample(1.0).meta["segments"] == [[0.0, 149.0], [155.0, 349.0], [410.0, 600.0]]
    assert rec.slice(100.0, 200.0).meta["segments"] == [[100.0, 149.5], [155.0, 200.0]]
    assert "segments" not in rec.slice(420.0, 500.0).meta
    # the one-record models fit the longest segment
    said: list[str] = []
    identify(rec, "nomoto1", max_effects=0, progress=said.append)
    assert any("3 segments" in m and "the longest, 155-349.5 s (390 samples)" in m for m in said)


def test_iso_times_and_from_arrays() -> None:
    stamps = [f"2026-12-31T23:59:{50 + k * 0.5:04.1f}Z" for k in range(20)] + [
        f"2027-01-01T00:00:{k * 0.5:04.1f}+00:00" for k in range(20)
    ]
    n = len(stamps)
    rec = Record.from_arrays(
        time=stamps,
        delta=np.full(n, 3.0),
        psi=np.linspace(350.0, 370.0, n) % 360.0,
        U=np.full(n, 10.0),
        units={"time": "datetime", "delta": "deg", "psi": "deg", "U": "kn"},
        meta={"vessel": "my ship"},
    )
    np.testing.assert_allclose(rec.time, 0.5 * np.arange(n))
    assert rec.meta["start_time"] == "2026-12-31T23:59:50+00:00"
    assert rec.meta["vessel"] == "my ship"
    np.testing.assert_allclose(rec.psi, np.radians(np.linspace(350.0, 370.0, n)), atol=1e-12)
    np.testing.assert_allclose(rec.r, np.radians(20.0 / (0.5 * (n - 1))), rtol=1e-9)
    assert rec.meta["r_source"].startswith("derived from psi")
    dt64 = np.datetime64("2026-06-01T12:00:00") + np.arange(n) * np.timedelta64(250, "ms")
    rec = Record.from_arrays(
        time=dt64, delta=np.zeros(n), psi=np.zeros(n), units={"time": "datetime"}
    )
    np.testing.assert_allclose(rec.time, 0.25 * np.arange(n))


def test_column_map_parsing() -> None:
    assert parse_columns("time=t:ms, delta=-rud:deg ,psi=H:rad,r=rot:deg/min,U=s:km/h") == {
        "time": ("t", "ms", False),
        "delta": ("rud", "deg", True),
        "psi": ("H", "rad", False),
        "r": ("rot", "deg/min", False),
        "U": ("s", "km/h", False),
    }
    assert parse_columns({"psi": "hdg [deg]:deg", "lat": "Lat"}) == {
        "psi": ("hdg [deg]", "deg", False),
        "lat": ("Lat", "deg", False),
    }
    for bad, match in (
        ("psi=hdg", r"'psi' \(column 'hdg'\) has no unit.*psi=hdg:UNIT.*rad, deg"),
        ("psi=hdg:furlongs", r"no unit"),
        ("heading=hdg:deg", r"unknown channel 'heading'.*time, delta, psi"),
        ("psi=hdg:deg,psi=h2:deg", "appears twice"),
        ("psi", r"'psi' is not channel=column\[:unit\]"),
        ("r=rot:deg", "unit 'deg' of channel 'r'; expected one of rad/s, deg/s, deg/min"),
        ("time=-t", "cannot be negated"),
    ):
        with pytest.raises(ValueError, match=match):
            parse_columns(bad)


# --------------------------------------------------------------------------------------------
# bad files: one line, exit code 2


def _write(tmp: Path, name: str, text: str) -> Path:
    path = tmp / name
    path.write_text(text)
    return path


def _bad_files(tmp: Path) -> Iterator[tuple[str, list[str], list[str]]]:
    good = "t,rudder,hdg\n" + "".join(f"{k},{k % 3},{k}\n" for k in range(20))
    cmap = "time=t,delta=rudder:deg,psi=hdg:deg"
    yield (
        "unknown column",
        [str(_write(tmp, "a.csv", good)), "--columns", "time=t,delta=helm:deg,psi=hdg:deg"],
        ["names column 'helm' for delta", "columns: ['t', 'rudder', 'hdg']"],
    )
    yield (
        "no unit stated",
        [str(_write(tmp, "b.csv", good)), "--columns", "time=t,delta=rudder,psi=hdg:deg"],
        ["'delta' (column 'rudder') has no unit", "delta=rudder:UNIT"],
    )
    text = good.replace("\n5,2,5\n", "\n5,port,5\n")
    yield (
        "a column of text",
        [str(_write(tmp, "c.csv", text)), "--columns", cmap],
        ["column 'rudder' (delta) row 6: 'port' is not a number", "expected numbers"],
    )
    text = good.replace("\n5,2,5\n", "\n3.5,2,5\n")
    yield (
        "time going backwards",
        [str(_write(tmp, "d.csv", text)), "--columns", cmap],
        ["time goes backwards at 4 -> 3.5 s in column 't' (line 7)", "expected increasing"],
    )
    t = np.arange(40.0)
    no_heading = write_nmea(
        tmp / "f.nmea",
        start=datetime.datetime(2026, 6, 1, 12, tzinfo=datetime.UTC),
        time=t, psi=0.01 * t, delta=np.zeros(40), U=np.full(40, 3.0), x=3.0 * t, y=0 * t,
        rates={"RMC": 1.0, "RSA": 1.0},
    )  # fmt: skip
    yield (
        "an NMEA log with no heading sentence",
        [str(no_heading)],
        ["no heading sentence (HDT, THS or HDG) in 80 sentences", "expected a heading"],
    )
    text = good.replace("\n5,2,5\n", "\n5,1e300,5\n").replace("\n6,0,6\n", "\n6,1e300,6\n")
    yield (
        "a rudder beyond any angle in the unit the column map states",
        [str(_write(tmp, "g.csv", text)), "--columns", cmap],
        ["'rudder' reaches", "deg as stated in the column map, so not a unit mix-up"],
    )
    lines = write_nmea(
        tmp / "h.nmea",
        start=datetime.datetime(2026, 6, 1, 12, tzinfo=datetime.UTC),
        time=t, psi=0.01 * t, delta=np.zeros(40), U=np.full(40, 3.0), x=3.0 * t, y=0 * t,
        rates={"RMC": 1.0, "HDT": 1.0},
    ).read_text().splitlines()  # fmt: skip
    # every time-stamped sentence corrupted (its checksum no longer fits)
    spoilt = [ln.replace("RMC,12", "RMC,13") for ln in lines]
    yield (
        "an NMEA log whose time sentences all fail their checksum",
        [str(_write(tmp, "h.nmea", "\n".join(spoilt) + "\n"))],
        ["found HDT 40, RMC 40 (of them dropped: 40 for a bad checksum)"],
    )
    yield (
        "fewer than two samples",
        [str(_write(tmp, "e.csv", "t,rudder,hdg\n0,1,2\n")), "--columns", cmap],
        ["1 data rows", "at least two samples"],
    )


def test_bad_files_end_with_one_line_and_exit_code_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for case, argv, needles in _bad_files(tmp_path):
        code = main(["identify", *argv, "--quiet"])
        err = capsys.readouterr().err
        lines = [ln for ln in err.splitlines() if ln.startswith("shipgym")]
        assert code == 2, case
        assert len(lines) == 1 and "Traceback" not in err, (case, err)
        assert len(lines[0]) < 600, (case, lines[0])  # no number printed in 300 digits
        for needle in needles:
            assert needle in lines[0], (case, needle, lines[0])


# --------------------------------------------------------------------------------------------
# an identified model is a model


def _fit_file(tmp: Path, **kw: float) -> Path:
    doc = nomoto_document(
        "nomoto1", {"K": 0.1, "T": 30.0}, speed=5.0, length=20.0, source="log.csv", **kw
    )
    path = tmp / "fit.json"
    path.write_text(json.dumps({"model": "nomoto1", "nomoto": doc}))
    return path


def test_the_env_from_a_model_file_reproduces_the_models_simulation(tmp_path: Path) -> None:
    path = _fit_file(tmp_path, rudder_offset=math.radians(1.5), input_delay=2.3, rudder_lag=4.0)
    ship = load_model(path)
    assert (ship.name, ship.input_delay, ship.gear.time_constant) == ("norrbin", 2.3, 4.0)
    assert ship.surge.service_speed == pytest.approx(5.0)
    env = gym.make("shipgym/NomotoHeading-v0", model=str(path))
    task = env.unwrapped.task
    assert task.ship_length == 20.0 and task.model.input_delay == 2.3
    _, info = env.reset(seed=4)
    x0, c = info["state"].copy(), task.c[0, :2].copy()  # (the current; the seaway load follows)
    actions = np.clip(1.4 * np.sin(np.arange(120) / 9.0), -1.2, 1.2).astype(np.float32)
    states = []
    for a in actions:
        states.append(env.step(np.array([a]))[4]["state"].copy())
    commands = np.column_stack(
        [ship.gear.max_angle * np.clip(actions.astype(np.float64), -1, 1), np.full(120, 1.4)]
    )
    sim = ship.simulate(x0, commands, 1.0, current=c)
    np.testing.assert_allclose(np.array(states), sim.states[1:], rtol=1e-9, atol=1e-9)
    # the vector env is the same ship, row by row, across an autoreset of the delay line
    vec = gym.make_vec(
        "shipgym/NomotoHeading-v0", num_envs=2, vectorization_mode="vector_entry_point",
        model=str(path),
    )  # fmt: skip
    vec.reset(seed=[4, 5])
    for a in actions[:20]:
        _, _, _, _, vinfo = vec.step(np.array([[a], [-a]]))
    one = gym.make("shipgym/NomotoHeading-v0", model=str(path))
    one.reset(seed=4)
    for a in actions[:20]:
        oinfo = one.step(np.array([a]))[4]
    np.testing.assert_array_equal(vinfo["state"][0], oinfo["state"])


def test_the_offset_mapping_is_the_identified_equation() -> None:
    """nomoto1 with ``delta -> delta + delta0`` is the norrbin model of the file, and
    nomoto2 the bech model; a step of the recorded rudder gives the same response."""
    t = np.arange(400) * 0.5
    for name, params in (("nomoto1", {"K": 0.1, "T": 30.0}),
                         ("nomoto2", {"K": 0.1, "T1": 30.0, "T2": 5.0, "T3": 3.0})):  # fmt: skip
        d0 = math.radians(2.0)
        ship = load_model({"nomoto": nomoto_document(name, params, rudder_offset=d0)})
        cls = Nomoto1Params if name == "nomoto1" else Nomoto2Params
        plain = make_model(name, cls(**params))
        cmd = np.column_stack([np.where(t > 20, 0.1, 0.0), np.full(t.size, 1.4)])
        x0 = np.zeros(plain.nx)
        x0[3] = 7.7
        a = ship.simulate(x0, cmd, 0.5)
        # the offset enters as a rudder bias: add it to the rudder state of the plain model
        xb = x0.copy()
        xb[ship.index("delta")] = d0  # the biased rudder from the start
        b = plain.simulate(xb, cmd + np.array([d0, 0.0]), 0.5)
        for state in ("psi", "r"):
            i = ship.index(state)
            np.testing.assert_allclose(a.states[:, i], b.states[:, i], rtol=1e-9, atol=1e-12)


def test_the_delay_is_the_identifications_shift() -> None:
    ship = make_model("nomoto1", Nomoto1Params(K=0.1, T=30.0), input_delay=2.3)
    plain = make_model("nomoto1", Nomoto1Params(K=0.1, T=30.0))
    t = np.arange(300) * 0.5
    delta = np.radians(10.0) * np.sign(np.sin(t / 15.0))
    cmd = np.column_stack([delta, np.full(t.size, 1.4)])
    shifted = cmd.copy()
    shifted[:, 0] = np.interp(t - 2.3, t, delta)  # the identification's input_delay
    x0 = np.r_[0.0, 0.0, 0.0, 7.7, 0.0, 0.0]
    np.testing.assert_allclose(
        ship.simulate(x0, cmd, 0.5).states, plain.simulate(x0, shifted, 0.5).states, atol=1e-12
    )
    line = DelayLine(1.0, 0.5, 1, 1)
    out = [line.push(np.array([[v]]))[0, 0] for v in (1.0, 2.0, 3.0, 4.0)]
    assert out == [1.0, 1.0, 1.0, 2.0]  # two steps late, the first command held before


def test_model_files_in_simulate_and_their_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _fit_file(tmp_path, rudder_offset=0.0)
    assert (
        main(["simulate", "zigzag", "--model", str(path), "--json", str(tmp_path / "z.json")]) == 0
    )
    out = capsys.readouterr().out
    assert "ship identified from log.csv (nomoto1)" in out and "L/U = 4.0 s" in out
    res = json.loads((tmp_path / "z.json").read_text())
    assert res["length_m"] == 20.0 and res["approach_speed_m_s"] == pytest.approx(5.0)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"model": "rvg3dof", "parameters": {}}))
    for model, needle in (
        (str(tmp_path / "none.json"), "does not exist"),
        (str(bad), "holds no model (a 'rvg3dof' fit"),
    ):
        assert main(["simulate", "zigzag", "--model", model]) == 2
        assert needle in capsys.readouterr().err
    with pytest.raises(ValueError, match="is not of the Nomoto family"):
        gym.make("shipgym/NomotoHeading-v0", model=make_model("rvg3dof"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert make_model(str(path)).name == "nomoto1"


USV = measured_root() / "usv_field" / "zigzag_30_inter_xy.csv"


@pytest.mark.skipif(not USV.is_file(), reason=f"{USV} not found (set SHIPGYM_MEASURED_DATA)")
def test_the_usv_field_record_through_a_column_map_is_the_usv_loaders_record() -> None:
    """The field USV's zigzag read as anyone's table (degrees, knots, lat/lon) gives the record
    of the project's own USV loader, which was checked against the source's documentation."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidDataWarning)
        mine = load(
            USV, columns="time=time,delta=rudder:deg,psi=heading:deg,U=speed:kn,lat=lat,lon=lon"
        )
        ref = load(USV, "usv")
    for name in ("time", "delta", "psi", "r", "x", "y", "U"):
        np.testing.assert_allclose(getattr(mine, name), getattr(ref, name), rtol=1e-12, atol=1e-9)


def test_log_to_model_to_autopilot_verified_in_simulation(
    truth: Record, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The whole chain on the command line: a plain CSV, its identified model file, the
    autopilot designed on it, and that autopilot steering the identified ship in the env."""
    log = tmp_path / "myship.csv"
    log.write_text(_table(truth))
    fit, gains = tmp_path / "fit.json", tmp_path / "gains.json"
    argv = ["identify", str(log), "--columns", COLUMNS, "--length", "160.93"]
    assert main([*argv, "--max-effects", "1", "--quiet", "--json", str(fit)]) == 0
    doc = json.loads(fit.read_text())["nomoto"]
    assert doc["length_m"] == 160.93 and doc["source"] == "myship.csv"
    assert doc["params"]["K"] == pytest.approx(0.185, rel=0.02)
    assert main(["design", str(fit), "--json", str(gains)]) == 0
    out = capsys.readouterr().out
    assert "delay margin" in out and f"--model {fit} --controller classic --gains" in out
    summary = tmp_path / "eval.json"
    argv = ["evaluate", "--env", "shipgym/NomotoHeading-v0", "--model", str(fit)]
    assert main([*argv, "--gains", str(gains), "--episodes", "2", "--json", str(summary)]) == 0
    result = json.loads(summary.read_text())
    metrics = result["metrics"]
    # the identified ship (offset included) is steered to each new heading: no blow-up, a small
    # overshoot, the rudder far from its limit, a heading error far below the unsteered ship's
    assert result["blown_up"] == 0
    assert metrics["overshoot_deg"] < 5.0
    assert metrics["actuator_rms"] < 0.3
    unsteered = tmp_path / "zero.json"
    argv = ["evaluate", "--env", "shipgym/NomotoHeading-v0", "--model", str(fit)]
    assert main([*argv, "--controller", "zero", "--episodes", "2", "--json", str(unsteered)]) == 0
    zero = json.loads(unsteered.read_text())["metrics"]
    assert metrics["heading_rms_deg"] < 0.5 * zero["heading_rms_deg"]
    # --model goes with the Nomoto env only; a gains file with another model's env is fine
    assert main(["evaluate", "--env", "shipgym/RVGHeading-v1", "--model", str(fit)]) == 2
    assert "sails its own ship" in capsys.readouterr().err


NMEA_RATES = {"HDT": 2.0, "RSA": 2.0, "ROT": 1.0, "RMC": 1.0, "VTG": 1.0, "GGA": 0.5, "ZDA": 0.2}


@pytest.fixture(scope="module")
def nmea_record(truth: Record, tmp_path_factory: pytest.TempPathFactory) -> Record:
    """The same ship as an NMEA 0183 log: mixed sentence rates, one bad checksum, and a start
    at 23:58:00 on New Year's Eve so the log crosses midnight into the next year."""
    path = tmp_path_factory.mktemp("logs") / "voyage.nmea"
    write_nmea(
        path,
        start=datetime.datetime(2026, 12, 31, 23, 58, 0, tzinfo=datetime.UTC),
        time=truth.time,
        psi=truth.psi,
        r=truth.r,
        delta=truth.delta,
        U=truth.U,
        x=truth.x,
        y=truth.y,
        rates=NMEA_RATES,
        bad_checksums=(100,),
    )
    with pytest.warns(SysidDataWarning, match="bad checksum"):
        return load(path)


def test_csv_and_nmea_logs_import_to_the_same_record(
    truth: Record, csv_record: Record, nmea_record: Record
) -> None:
    nmea = nmea_record
    assert nmea.meta["source"] == "nmea" and nmea.meta["start_time"].startswith("2026-12-31T23:58")
    assert any("bad checksum" in r for r in nmea.meta["repairs"])
    np.testing.assert_allclose(nmea.time, csv_record.time, atol=1e-6)  # one 0.5 s grid
    # the sentences' resolution: 0.01 deg, 0.01 deg/min, 0.01 kn (half of it by rounding)
    tol = {"psi": math.radians(0.005), "delta": math.radians(0.005)}
    off = []
    for name, atol in tol.items():
        a, b = getattr(nmea, name), getattr(csv_record, name)
        bad = np.flatnonzero(np.abs(a - b) > atol)
        # the sentence with the bad checksum is missing: its sample is interpolated
        np.testing.assert_allclose(a[bad], 0.5 * (b[bad - 1] + b[bad + 1]), atol=atol)
        off += list(bad)
    assert len(off) == 1
    whole = np.flatnonzero(np.isclose(np.mod(csv_record.time, 1.0), 0.0))  # ROT, RMC at 1 Hz
    rot = math.radians(0.005) / 60.0
    np.testing.assert_allclose(nmea.r[whole], csv_record.r[whole], atol=rot)
    np.testing.assert_allclose(nmea.U[whole], csv_record.U[whole], atol=0.005 * KNOT)
    # between the 1 Hz samples: linear interpolation of the noisy truth
    half = np.setdiff1d(np.arange(nmea.n), whole)
    expected = 0.5 * (csv_record.r[half - 1] + csv_record.r[half + 1])
    np.testing.assert_allclose(nmea.r[half], expected, atol=rot)


def test_csv_and_nmea_identify_the_same_ship(
    truth: Record, csv_record: Record, nmea_record: Record
) -> None:
    true = truth.meta["truth"]["params"]
    offset = -true["n0"] / true["K"]
    fits = [identify(rec, "nomoto1", max_effects=1) for rec in (csv_record, nmea_record)]
    for res in fits:
        assert res.effect_names == ["rudder_offset"]
        got = res.parameters_after
        assert got["K"] == pytest.approx(true["K"], rel=0.02)
        assert got["T"] == pytest.approx(true["T"], rel=0.02)
        assert got["delta0"] == pytest.approx(offset, rel=0.02)
    a, b = (f.parameters_after for f in fits)
    for key in ("K", "T", "delta0"):
        assert b[key] == pytest.approx(a[key], rel=0.02)


def test_the_worked_examples_logs_read_as_documented() -> None:
    """``examples/`` (README, "Worked example"): the CSV with its column map and the NMEA log
    with its midnight, its bad checksum and its 20 s without the gyro."""
    examples = Path(__file__).resolve().parents[1] / "examples"
    columns = (
        "time=time_utc:datetime,delta=-rudder_angle:deg,psi=gyro_heading:deg,r=rot:deg/min,"
        "U=sog:kn,lat=lat,lon=lon"
    )
    csv = load(examples / "myship.csv", columns=columns)
    assert (csv.n, csv.meta["start_time"]) == (2251, "2026-12-31T23:55:00+00:00")
    assert csv.dt == pytest.approx(0.4)
    with pytest.warns(SysidDataWarning, match="bad checksum"):
        nmea = load(examples / "voyage.nmea")
    assert nmea.meta["start_time"].startswith("2026-12-31T23:55:00")
    assert [round(b - a) for a, b in nmea.meta["segments"]] == [420, 460]
    # the two logs of one voyage agree where both have the heading
    both = nmea.time[np.searchsorted(nmea.time, csv.time[csv.time < 419.0])]
    np.testing.assert_allclose(both, csv.time[csv.time < 419.0], atol=1e-6)


def test_an_identified_gunnerus_is_a_model_file_with_its_azimuth_offset(tmp_path: Path) -> None:
    """The rvg3dof entry of a model file keeps every term of the fit and the pods' offset: the
    ship turns its pods to the order plus the offset."""
    from shipgym.models import RVGParams
    from shipgym.models.model_file import rvg_document

    fitted = replace(RVGParams.named("sea_trials"), azimuth_offset=math.radians(2.0))
    path = tmp_path / "rvg_fit.json"
    doc = rvg_document(fitted, current=(0.1, -0.2), sway_offset=0.05, source="trials.csv")
    path.write_text(json.dumps({"model": "rvg3dof", "rvg3dof": doc}))
    ship = load_model(path)
    assert (
        ship.name == "rvg3dof" and ship.params.pod_lift_coefficient == fitted.pod_lift_coefficient
    )
    np.testing.assert_array_equal(ship.params.linear_damping, fitted.linear_damping)
    assert ship.params.azimuth_offset == math.radians(2.0)
    plain = make_model("rvg3dof", replace(fitted, azimuth_offset=0.0))
    x0 = np.zeros(ship.nx)
    x0[ship.index("u")] = 5.0
    cmd = np.tile([25e3, 25e3, math.radians(10.0), math.radians(10.0)], (200, 1))
    shifted = cmd + np.array([0.0, 0.0, math.radians(2.0), math.radians(2.0)])
    np.testing.assert_array_equal(
        ship.simulate(x0, cmd, 0.5).states, plain.simulate(x0, shifted, 0.5).states
    )
    env = gym.make("shipgym/RVGHeading-v1", params=str(path))
    assert env.unwrapped.task.model.params.azimuth_offset == math.radians(2.0)
    with pytest.raises(ValueError, match="azimuth_offset must be within"):
        replace(fitted, azimuth_offset=0.2)

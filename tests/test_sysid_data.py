"""Tests of shipgym.sysid.data: loaders of the measured sources, canonical CSV, repairs."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from shipgym.sysid.data import (
    FORMATS,
    Record,
    SysidDataWarning,
    derive_yaw_rate,
    detect_format,
    load,
    load_all,
    measured_root,
)

MEASURED = measured_root()
needs_data = pytest.mark.skipif(
    not MEASURED.is_dir(),
    reason=f"measured data not found at {MEASURED} (set SHIPGYM_MEASURED_DATA)",
)

EXPECTED_FORMAT = {
    "sspa_blog_zigzag": "sspa",
    "marin_kvlcc2": "marin",
    "hsva_kvlcc2": "hsva",
    "esso_osaka_frt": "esso_osaka",
    "usv_field": "usv",
    "gunnerus_seatrials": "gunnerus",
}


def _measured_files() -> list[str]:
    if not MEASURED.is_dir():
        return []
    files = [p for p in MEASURED.rglob("*") if p.is_file() and p.suffix in (".csv", ".dat")]
    return sorted(str(p.relative_to(MEASURED)) for p in files)


FILES = _measured_files()
_CACHE: dict[str, Record] = {}


def _load(rel: str) -> Record:
    """Load a measured file once per session (warnings are expected and silenced here)."""
    if rel not in _CACHE:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SysidDataWarning)
            _CACHE[rel] = load(MEASURED / rel)
    return _CACHE[rel]


def _find(name: str) -> Record:
    return _load(next(f for f in FILES if f.endswith(name)))


# ---------------------------------------------------------------------------------------------
# every measured file
# ---------------------------------------------------------------------------------------------
@needs_data
def test_all_files_found() -> None:
    # SOURCES.md: 37 files of the five first sources + the Gunnerus sea-trial file
    assert len(FILES) == 38
    counts = {k: sum(f.startswith(k) for f in FILES) for k in EXPECTED_FORMAT}
    assert counts == {
        "sspa_blog_zigzag": 1,
        "marin_kvlcc2": 6,
        "hsva_kvlcc2": 13,
        "esso_osaka_frt": 15,
        "usv_field": 2,
        "gunnerus_seatrials": 1,
    }


@needs_data
@pytest.mark.parametrize("rel", FILES)
def test_measured_file_loads_in_canonical_form(rel: str) -> None:
    rec = _load(rel)
    fmt = EXPECTED_FORMAT[rel.split("/")[0]]
    assert detect_format(MEASURED / rel) == fmt
    assert rec.meta["source"] == fmt
    assert rec.meta["file"] == Path(rel).name
    assert rec.n > 100
    assert np.all(np.diff(rec.time) > 0)
    for name, values in rec.channels().items():
        assert values.dtype == np.float64, name
        assert values.shape == (rec.n,), name
        assert np.all(np.isfinite(values)), name
    # psi continuous: no step is a wrap, and steps agree with the yaw rate within a bound that
    # covers MARIN's 1 deg quantisation, the USV's derived r and the reported heading steps
    dpsi = np.diff(rec.psi)
    assert np.max(np.abs(dpsi)) < math.radians(20.0)
    expected = 0.5 * (rec.r[1:] + rec.r[:-1]) * np.diff(rec.time)
    assert np.max(np.abs(dpsi - expected)) < math.radians(10.0)
    # rudder sign convention: positive delta gives a starboard turn (r > 0)
    corr = np.corrcoef(rec.delta, rec.r)[0, 1]
    assert corr > 0.2, f"corr(delta, r) = {corr:.2f}: rudder sign not canonical"
    assert abs(rec.delta).max() < math.radians(45.0)
    assert rec.meta["r_source"]


@needs_data
@pytest.mark.parametrize(
    "rel",
    [
        "sspa_blog_zigzag/example_zigzag.csv",
        "hsva_kvlcc2/HSVA_CPMC_KVLCC2_Z_10_10_S.dat",
        "esso_osaka_frt/zigzag/zigzag_31-Jul-2020_13_50_28.csv",
        "usv_field/turnningdata_xy.csv",
    ],
)
def test_auto_detection_equals_explicit_format(rel: str) -> None:
    fmt = EXPECTED_FORMAT[rel.split("/")[0]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidDataWarning)
        auto, explicit = load(MEASURED / rel), load(MEASURED / rel, format=fmt)
    for name, values in auto.channels().items():
        np.testing.assert_array_equal(values, getattr(explicit, name))
    assert auto.meta == explicit.meta


@needs_data
def test_load_all_returns_every_file() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        recs = load_all(MEASURED)
    assert len(recs) == len(FILES)
    assert {r.meta["source"] for r in recs} == set(FORMATS) - {"canonical", "table", "nmea"}
    assert all(issubclass(w.category, SysidDataWarning) for w in caught)


# ---------------------------------------------------------------------------------------------
# known facts from SOURCES.md
# ---------------------------------------------------------------------------------------------
@needs_data
def test_sspa_facts() -> None:
    rec = _find("example_zigzag.csv")
    assert rec.n == 2073
    assert rec.dt == pytest.approx(0.02, abs=1e-9)
    assert rec.time[-1] == pytest.approx(41.44, abs=1e-9)
    assert rec.meta["first_rudder_order_s"] == pytest.approx(1.15, abs=0.03)
    # 0.5 deg initial rudder (source sign -0.503 deg -> canonical +0.503 deg)
    assert math.degrees(rec.meta["rudder_offset_rad"]) == pytest.approx(0.503, abs=0.01)
    assert np.max(np.abs(np.degrees(rec.psi))) == pytest.approx(41.0, abs=3.0)
    assert rec.U is not None and rec.U[:25].mean() == pytest.approx(1.74, abs=0.05)
    # zigzag 20/20
    assert np.max(np.abs(np.degrees(rec.delta))) == pytest.approx(20.0, abs=1.5)
    # derived r agrees with the source's gradient of psi (smoothing only)
    raw = np.loadtxt(MEASURED / "sspa_blog_zigzag/example_zigzag.csv", delimiter=";", skiprows=1)
    assert np.corrcoef(rec.r, raw[:, 5])[0, 1] > 0.99
    np.testing.assert_array_equal(rec.delta, -raw[:, 1])


@needs_data
@pytest.mark.parametrize(
    ("name", "rows", "first_sign"),
    [
        ("zz_10_m.dat", 3844, -1),  # 10/-10 starts with source +10 = port = canonical -10 deg
        ("zz_-10_m.dat", 4177, +1),
        ("zz_20_m.dat", 4481, -1),
        ("zz_-20_m.dat", 5057, +1),
        ("tc_35_m.dat", 15288, -1),  # source +35 turns to port
        ("tc_-35_m.dat", 15753, +1),
    ],
)
def test_marin_facts(name: str, rows: int, first_sign: int) -> None:
    rec = _find("MARIN_FREE_KVLCC2_" + name)
    assert rec.n == rows
    assert rec.dt == pytest.approx(0.135264, rel=1e-9)
    assert rec.meta["scale"] == "full"
    assert rec.U is not None and rec.U[:20].mean() == pytest.approx(8.0, abs=0.15)
    assert rec.rpm is not None and 91.0 < rec.rpm.min() and rec.rpm.max() < 92.5
    i = int(np.argmax(np.abs(rec.delta) > math.radians(5.0)))
    assert np.sign(rec.delta[i]) == first_sign
    # the first heading excursion goes the same way (a starboard rudder gives a starboard turn)
    j = int(np.argmax(np.abs(rec.psi - rec.psi[0]) > math.radians(3.0)))
    assert np.sign(rec.psi[j] - rec.psi[0]) == first_sign
    assert any("quantised" in s for s in rec.meta["repairs"])
    if name.startswith("tc"):
        # turning: steady r has the rudder's sign and the heading passes 700 deg
        assert np.sign(np.median(rec.r[3000:10000])) == first_sign
        assert np.ptp(np.degrees(rec.psi)) > 700.0


@needs_data
def test_marin_neutral_rudder_offset() -> None:
    rec = _find("MARIN_FREE_KVLCC2_zz_10_m.dat")
    # SOURCES.md: delta is about -0.8 deg (source sign) before the execution
    assert math.degrees(rec.meta["rudder_offset_rad"]) == pytest.approx(0.8, abs=0.1)


@needs_data
def test_hsva_facts() -> None:
    for rel in (f for f in FILES if f.startswith("hsva")):
        rec = _load(rel)
        assert rec.dt == pytest.approx(0.05, abs=1e-9)
        assert 1321 <= rec.n <= 4201
        assert rec.meta["scale"] == "model" and rec.meta["L"] == 7.0
        assert rec.U is not None and rec.U[0] == pytest.approx(1.178, abs=0.01)
        assert rec.rpm is not None and np.allclose(rec.rpm, 60 * 10.2295, atol=0.1)
        # body velocities: u about U, v about 0 at the start of the run
        assert rec.u is not None and rec.v is not None
        assert rec.u[0] == pytest.approx(rec.U[0], abs=0.01) and abs(rec.v[0]) < 0.01
    # "Z10°/10° starting to starboard": the first rudder and the first turn go to starboard
    for suffix, sign in (("10_10_S.dat", 1), ("10_10_P.dat", -1), ("20_10_S.dat", 1)):
        rec = _find(suffix)
        i = int(np.argmax(np.abs(rec.delta) > math.radians(5.0)))
        assert np.sign(rec.delta[i]) == sign
        j = int(np.argmax(np.abs(rec.r) > math.radians(0.5)))
        assert np.sign(rec.r[j]) == sign


@needs_data
def test_esso_facts() -> None:
    rec = _find("zigzag_31-Jul-2020_13_50_28.csv")
    assert rec.n == 2028 - 327 - 0  # 2028 rows of which 327 all-empty
    assert any("327 all-empty rows" in s for s in rec.meta["repairs"])
    rows = {
        "zigzag_31-Jul-2020_13_04_24.csv": 1403,
        "turn_14-Sep-2020_13_39_32.csv": 3646,
        "random_06-Aug-2020_16_24_25_3.csv": 7179,
    }
    for name, n in rows.items():
        r = _find(name)
        assert r.n == n
        assert r.dt == pytest.approx(0.1, abs=1e-6)
        assert r.meta["L"] == 3.0
    turn = _find("turn_14-Sep-2020_13_39_32.csv")  # +35 deg: starboard turn (MMG)
    s = turn.slice(turn.meta["manoeuvre_start_s"], turn.meta["manoeuvre_end_s"])
    assert np.median(s.delta) > math.radians(30.0)
    assert np.median(s.r) > 0.0
    # psi_hat was wrapped to [-pi, pi]: the unwrapped heading of a turning test exceeds 2 pi
    assert np.ptp(turn.psi) > 2 * np.pi
    random = _find("random_06-Aug-2020_16_24_25_3.csv")
    assert random.time[0] > 1000.0  # continues the time of one long record


def test_first_order_skips_hand_corrections_and_small_holds() -> None:
    """A rudder moved by hand (up to 12 deg, never still), then held at 5 deg for 3 s, then a
    20/20 zigzag: the first order is the zigzag's first 20 deg; a rudder never held has none."""
    from shipgym.sysid.io.esso_osaka import first_order

    t = np.arange(0.0, 100.0, 0.1)
    hand = np.radians(12.0) * np.sin(2 * np.pi * t / 7.0)
    delta = np.where(t < 30.0, hand, 0.0)
    delta[(t >= 30.0) & (t < 33.0)] = np.radians(5.0)
    delta[t >= 40.0] = np.radians(20.0) * np.sign(np.sin(2 * np.pi * (t[t >= 40.0] - 40.0) / 30.0)
                                                  + 1e-9)  # fmt: skip
    k = first_order(t, delta)
    assert t[k] == pytest.approx(40.0)
    assert first_order(t, hand) is None
    assert first_order(t[:1], delta[:1]) is None


@needs_data
def test_esso_manoeuvres_start_at_the_programmes_first_order_not_at_a_hand_correction() -> None:
    """Seven of the thirteen zigzag and turning runs have the helmsman's corrections reach
    10-12 deg before the first order (five at 0.01-0.04 m/s); each manoeuvre starts at its
    first held order, at speed."""
    from shipgym.sysid.io.esso_osaka import ORDER_LEAD_S

    orders = {"zigzag_31-Jul-2020_13_22_52.csv": 36.1, "zigzag_31-Jul-2020_13_29_19.csv": 42.6,
              "zigzag_31-Jul-2020_13_04_24.csv": 44.2, "turn_14-Oct-2020_14_29_49.csv": 110.0,
              "turn_14-Sep-2020_14_16_04.csv": 120.0}  # fmt: skip
    for name, order in orders.items():
        rec = _find(name)
        assert rec.meta["manoeuvre_start_s"] == pytest.approx(order - ORDER_LEAD_S), name
    for name in (f for f in FILES if "/zigzag/" in f or "/turning/" in f):
        rec = _load(name)
        t0, t1 = rec.meta["manoeuvre_start_s"], rec.meta["manoeuvre_end_s"]
        run = rec.slice(t0, t1)
        assert run.U[0] > 0.12, name  # under way, not gathering way from rest
        # the first order: the rudder steps to the programme's amplitude and is held there
        k = int(np.searchsorted(run.time, t0 + ORDER_LEAD_S - 1e-6))
        assert abs(run.delta[k]) >= 0.8 * np.max(np.abs(run.delta[k : k + 600])), name
        assert np.ptp(run.delta[k : k + 20]) < math.radians(0.3), name
        assert np.ptp(run.delta[:k]) > 0.0, name  # the step is in the run: it excites a turn


@needs_data
def test_usv_facts() -> None:
    zz = _find("zigzag_30_inter_xy.csv")
    assert zz.n == 420 and zz.time[-1] == pytest.approx(209.5)
    assert np.max(np.abs(np.degrees(zz.delta))) == pytest.approx(31.0, abs=3.0)
    assert "irregular_sampling" not in zz.meta
    turn = _find("turnningdata_xy.csv")
    assert turn.n == 174 and turn.meta.get("irregular_sampling") is True
    # rudder 20-26 deg to starboard: one full circle to starboard in about 88 s
    assert np.median(np.degrees(turn.delta)) > 15.0
    rate = (turn.psi[-1] - turn.psi[0]) / turn.duration
    assert math.degrees(rate) == pytest.approx(360.0 / 88.0, rel=0.25)
    # tight turn of about 12 m: the positions recomputed from lat/lon stay within ~25 m
    assert turn.x is not None and turn.y is not None
    assert np.ptp(turn.x) < 25.0 and np.ptp(turn.y) < 25.0
    u = turn.resample(0.5)
    assert np.allclose(np.diff(u.time), 0.5) and "irregular_sampling" not in u.meta


@needs_data
def test_gunnerus_facts() -> None:
    rec = _find("RVG_ManeuveringTests.csv")
    assert rec.n == 17701 and rec.dt == pytest.approx(0.5) and rec.time[-1] == 8850.0
    assert rec.azimuth is not None and rec.rpm is not None
    np.testing.assert_array_equal(rec.delta, -rec.azimuth)
    assert any("heading glitches repaired" in s for s in rec.meta["repairs"])
    azi = np.degrees(rec.azimuth)
    r_deg = np.degrees(rec.r)
    # steady turns (SOURCES.md): +20 deg azimuth: r about -3.5 deg/s; -20 deg: about +3.5 deg/s
    port = (np.abs(azi - 20.0) < 0.5) & (rec.rpm > 140)
    stbd = (np.abs(azi + 20.0) < 0.5) & (rec.rpm > 140)
    assert port.sum() > 50 and stbd.sum() > 50
    assert np.median(r_deg[port]) == pytest.approx(-3.49, abs=0.6)
    assert np.median(r_deg[stbd]) == pytest.approx(3.5, abs=0.6)
    # corrected speed: the speed from the positions is about 2 % above the file's u, v
    assert rec.x is not None and rec.y is not None and rec.U is not None
    sog = np.hypot(np.gradient(rec.x, rec.time), np.gradient(rec.y, rec.time))
    fast = rec.U > 2.0
    assert np.median(sog[fast] / rec.U[fast]) == pytest.approx(1.0, abs=0.01)


# ---------------------------------------------------------------------------------------------
# 3-DOF channels: thrust (HSVA) and apparent wind (Esso Osaka)
# ---------------------------------------------------------------------------------------------
@needs_data
def test_hsva_thrust() -> None:
    for rel in (f for f in FILES if f.startswith("hsva")):
        rec = _load(rel)
        # SOURCES.md: column 11, thrust about 40-57 N (model scale)
        assert rec.thrust is not None, rel
        assert 35.0 < rec.thrust.min() and rec.thrust.max() < 60.0, rel
        # self-propulsion point on the straight approach: about 41 N (SOURCES.md)
        assert np.mean(rec.thrust[:10]) == pytest.approx(41.5, abs=2.5), rel
        assert any("thrust" in c for c in rec.meta["conversions"])
    # more rudder, more thrust (speed loss and drift in the larger zigzags)
    assert _find("Z_35_05.dat").thrust.max() > _find("Z_05_01.dat").thrust.max() + 5.0


def _esso_raw(rel: str) -> dict[str, np.ndarray]:
    """The raw Esso columns (all-empty rows dropped, as the loader does)."""
    path = MEASURED / rel
    header = path.read_text().splitlines()[0].split(",")
    data = np.genfromtxt(path, delimiter=",", skip_header=1)
    data = data[~np.all(np.isnan(data), axis=1)]
    return {name: data[:, j] for j, name in enumerate(header)}


def _apparent_from_true(
    rec: Record, v_true: np.ndarray, dir_true: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Apparent wind (speed, angle FROM, clockwise from the bow) from the true wind (FROM,
    clockwise from x0) and the ship's velocity over ground."""
    assert rec.u is not None and rec.v is not None
    c, s = np.cos(rec.psi), np.sin(rec.psi)
    # air velocity over ground (the wind blows towards dir_true + pi) minus the ship velocity
    ax = -v_true * np.cos(dir_true) - (rec.u * c - rec.v * s)
    ay = -v_true * np.sin(dir_true) - (rec.u * s + rec.v * c)
    bx, by = ax * c + ay * s, -ax * s + ay * c  # body axes
    return np.hypot(bx, by), np.arctan2(-by, -bx)  # the wind comes FROM -(bx, by)


def _ang_err(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.mod(a - b + np.pi, 2.0 * np.pi) - np.pi


@needs_data
def test_esso_apparent_wind_matches_true_wind_and_ship_motion() -> None:
    esso = [f for f in FILES if f.startswith("esso")]
    assert len(esso) == 15
    for rel in esso:
        rec = _load(rel)
        assert rec.wind_speed is not None and rec.wind_angle is not None, rel
        assert np.all(np.isfinite(rec.wind_speed)) and np.all(np.isfinite(rec.wind_angle))
        assert np.all(rec.wind_speed >= 0.0)
        assert np.all((rec.wind_angle > -np.pi) & (rec.wind_angle <= np.pi)), rel
        assert any("apparent" in n for n in rec.meta["notes"])
        assert not any("not loaded)" in n and "wind channels" in n for n in rec.meta["notes"])
        assert any("wind_angle" in c for c in rec.meta["conversions"])
        raw = _esso_raw(rel)
        assert raw["t [s]"].size == rec.n
        speed, angle = _apparent_from_true(
            rec, raw["wind_velo_true [m/s]"], raw["wind_dir_true [rad]"]
        )
        windy = rec.wind_speed > 0.5
        assert windy.sum() > 0.5 * rec.n, rel
        err = _ang_err(angle, rec.wind_angle)[windy]
        rms_deg = math.degrees(float(np.sqrt(np.mean(err**2))))
        # measured: 0.004-0.034 deg RMS; a wrong convention gives 20-100 deg
        assert rms_deg < 0.5, f"{rel}: apparent wind angle RMS error {rms_deg:.3f} deg"
        # measured: below 0.0006 m/s RMS
        assert np.sqrt(np.mean((speed - rec.wind_speed) ** 2)) < 0.005, rel
        # the check is sensitive: the ship motion (0.1-0.4 m/s) alone shifts the angle by
        # several degrees RMS
        still = _ang_err(raw["wind_dir_true [rad]"] - rec.psi, rec.wind_angle)[windy]
        assert math.degrees(float(np.sqrt(np.mean(still**2)))) > 4.0, rel


@needs_data
def test_esso_wind_sign_convention() -> None:
    # at rest (first sample, ship speed ~0) the apparent wind is the true wind seen from the bow:
    # wind_angle = wind_dir_true - psi
    rel = next(f for f in FILES if f.endswith("zigzag_31-Jul-2020_13_04_24.csv"))
    rec, raw = _load(rel), _esso_raw(rel)
    assert rec.U is not None and rec.U[0] < 0.01 and rec.wind_angle is not None
    assert abs(_ang_err(raw["wind_dir_true [rad]"][0] - rec.psi[0], rec.wind_angle[0])) < 1e-3
    # sailing in light air (true wind below half the ship speed) the apparent wind comes from
    # ahead: |wind_angle| small (0 = head wind). Measured: 41 samples, at most 27 deg.
    rel = next(f for f in FILES if f.endswith("turn_14-Sep-2020_14_16_04.csv"))
    rec, raw = _load(rel), _esso_raw(rel)
    assert rec.U is not None and rec.wind_angle is not None
    calm = (raw["wind_velo_true [m/s]"] < 0.5 * rec.U) & (rec.U > 0.2)
    assert calm.sum() > 20
    assert np.all(np.abs(rec.wind_angle[calm]) < math.radians(45.0))


def _wind_record(n: int = 101, dt: float = 0.1) -> Record:
    rec = _synthetic(n=n, dt=dt)
    t = rec.time
    angle = np.mod(2.9 + 0.05 * t * 10.0 + np.pi, 2 * np.pi) - np.pi  # crosses +-pi
    angle[angle == -np.pi] = np.pi
    return Record(
        **rec.channels(),
        thrust=40.0 + np.sin(t),
        wind_speed=1.0 + 0.1 * t,
        wind_angle=angle,
        meta=rec.meta,
    )


def test_canonical_round_trip_of_3dof_channels(tmp_path: Path) -> None:
    rec = _wind_record()
    rec.wind_angle[3] = np.pi  # the closed end of (-pi, pi]
    rec.thrust[4] = 1.0 / 3.0
    path = rec.to_csv(tmp_path / "w.csv")
    header = next(line for line in path.read_text().splitlines() if not line.startswith("#"))
    assert header == ("time_s,delta_rad,psi_rad,r_rad_s,rpm,thrust_N,wind_speed_m_s,wind_angle_rad")
    _assert_round_trip(rec, path)
    # slicing keeps the channels
    s = rec.slice(2.0, 5.0)
    assert s.thrust is not None and s.wind_speed is not None and s.wind_angle is not None
    np.testing.assert_array_equal(
        s.wind_angle, rec.wind_angle[(rec.time >= 2.0) & (rec.time <= 5.0)]
    )


def test_resample_wraps_wind_angle() -> None:
    t = np.arange(5) * 1.0
    z = np.zeros(5)
    angle = np.array([3.0, 3.1, -3.1, -3.0, -2.9])  # crosses pi between samples 1 and 2
    rec = Record(time=t, delta=z, psi=z, r=z, wind_speed=np.ones(5), wind_angle=angle)
    res = rec.resample(0.5)
    assert res.wind_angle is not None and res.wind_speed is not None
    # halfway between 3.1 and -3.1 is +-pi (through the stern), not 0 (the bow)
    mid = res.wind_angle[3]
    assert abs(abs(mid) - np.pi) < 1e-12 and mid == np.pi
    assert np.all((res.wind_angle > -np.pi) & (res.wind_angle <= np.pi))
    np.testing.assert_allclose(res.wind_angle[::2], angle)
    np.testing.assert_allclose(res.wind_speed, 1.0)


def test_wind_channel_validation(tmp_path: Path) -> None:
    t = np.arange(5.0)
    with pytest.raises(ValueError, match=r"wrapped to \(-pi, pi\]"):
        Record(time=t, delta=t, psi=t, r=t, wind_angle=np.full(5, 4.0))
    with pytest.raises(ValueError, match=r"wrapped to \(-pi, pi\]"):
        Record(time=t, delta=t, psi=t, r=t, wind_angle=np.full(5, -np.pi))
    with pytest.raises(ValueError, match="wind_speed must be >= 0"):
        Record(time=t, delta=t, psi=t, r=t, wind_speed=np.full(5, -1.0))
    # a canonical file with an angle in [0, 2 pi) is wrapped, with a warning
    rows = "\n".join(
        f"{a!r},0.0,0.0,0.0,{b!r}"
        for a, b in zip(t.tolist(), [0.0, 1.0, 4.0, 6.0, 7.0], strict=True)
    )
    path = tmp_path / "w.csv"
    path.write_text("time_s,delta_rad,psi_rad,r_rad_s,wind_angle_rad\n" + rows + "\n")
    with pytest.warns(SysidDataWarning, match="wind_angle outside"):
        rec = load(path)
    assert rec.wind_angle is not None
    np.testing.assert_allclose(
        rec.wind_angle, [0.0, 1.0, 4.0 - 2 * np.pi, 6.0 - 2 * np.pi, 7.0 - 2 * np.pi]
    )
    assert rec.wind_angle[0] == 0.0 and rec.wind_angle[1] == 1.0  # inside: kept bit for bit


# ---------------------------------------------------------------------------------------------
# canonical CSV, slicing, resampling
# ---------------------------------------------------------------------------------------------
@needs_data
@pytest.mark.parametrize(
    "name",
    [
        "RVG_ManeuveringTests.csv",
        "MARIN_FREE_KVLCC2_zz_10_m.dat",
        "example_zigzag.csv",
        "HSVA_CPMC_KVLCC2_Z_10_10_S.dat",  # thrust
        "turn_14-Sep-2020_14_16_04.csv",  # apparent wind, angle crossing +-pi
    ],
)
def test_canonical_round_trip_of_measured(tmp_path: Path, name: str) -> None:
    rec = _find(name)
    path = rec.to_csv(tmp_path / "rec.csv")
    assert detect_format(path) == "canonical"
    _assert_round_trip(rec, path)
    assert Record.from_csv(path).meta == rec.meta


def _assert_round_trip(rec: Record, path: Path) -> None:
    """The canonical file at ``path`` reads back as ``rec``, exactly and without a warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = load(path)
    assert back.channels().keys() == rec.channels().keys()
    for key, values in rec.channels().items():
        np.testing.assert_array_equal(getattr(back, key), values)
    assert back.meta == rec.meta


def _synthetic(n: int = 200, dt: float = 0.1, **meta: object) -> Record:
    t = np.arange(n) * dt
    delta = 0.1 * np.sign(np.sin(0.3 * t))
    r = 0.05 * np.sin(0.3 * t - 0.5)
    psi = np.cumsum(r) * dt
    return Record(
        time=t,
        delta=delta,
        psi=psi,
        r=r,
        rpm=np.full(n, 100.0),
        meta={"source": "synthetic", **meta},
    )


def test_canonical_header_units_and_round_trip(tmp_path: Path) -> None:
    rec = _synthetic(notes=["a, b: c"], L=None, nested={"k": [1, 2.5]})
    path = rec.to_csv(tmp_path / "s.csv")
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# shipgym canonical")
    assert "time_s,delta_rad,psi_rad,r_rad_s,rpm" in lines
    back = Record.from_csv(path)
    for key, values in rec.channels().items():
        np.testing.assert_array_equal(getattr(back, key), values)
    assert back.meta == rec.meta
    assert back.x is None and back.azimuth is None
    # a record without the 3-DOF channels: none written, none read back
    assert back.thrust is None and back.wind_speed is None and back.wind_angle is None
    assert "thrust" not in back.channels() and "wind_angle" not in back.channels()


def test_slice_and_resample() -> None:
    rec = _synthetic()
    s = rec.slice(2.0, 5.0)
    assert s.time[0] == pytest.approx(2.0) and s.time[-1] == pytest.approx(5.0)
    assert s.meta["slice_s"] == [2.0, 5.0]
    res = rec.resample(0.25)
    assert np.allclose(np.diff(res.time), 0.25)
    np.testing.assert_allclose(res.psi, np.interp(res.time, rec.time, rec.psi))
    assert res.rpm is not None and np.all(res.rpm == 100.0)
    with pytest.raises(ValueError, match="t0 < t1"):
        rec.slice(5.0, 2.0)
    with pytest.raises(ValueError, match="positive"):
        rec.resample(-1.0)


def test_record_validation() -> None:
    t = np.arange(5.0)
    with pytest.raises(ValueError, match="strictly increasing"):
        Record(time=np.array([0.0, 1.0, 1.0, 2.0, 3.0]), delta=t, psi=t, r=t)
    with pytest.raises(ValueError, match="non-finite"):
        Record(time=t, delta=np.array([0, 1, np.nan, 0, 0.0]), psi=t, r=t)
    with pytest.raises(ValueError, match="samples"):
        Record(time=t, delta=t[:4], psi=t, r=t)
    with pytest.raises(ValueError, match="JSON"):
        Record(time=t, delta=t, psi=t, r=t, meta={"bad": object()})


def test_derive_yaw_rate_matches_savgol_and_irregular_grid() -> None:
    t = np.arange(0.0, 60.0, 0.5)
    psi = 0.3 * np.sin(0.2 * t)
    r_true = 0.06 * np.cos(0.2 * t)
    r_uniform = derive_yaw_rate(t, psi, 2.0)
    np.testing.assert_allclose(r_uniform[3:-3], r_true[3:-3], atol=5e-4)
    rng = np.random.default_rng(0)
    t_irr = np.cumsum(rng.choice([0.5, 1.0, 1.5], size=80))
    r_irr = derive_yaw_rate(t_irr, 0.3 * np.sin(0.2 * t_irr), 3.0)
    np.testing.assert_allclose(r_irr[3:-3], 0.06 * np.cos(0.2 * t_irr[3:-3]), atol=3e-3)


# ---------------------------------------------------------------------------------------------
# repaired oddities (synthetic files in each source format)
# ---------------------------------------------------------------------------------------------
def _write_canonical(
    path: Path, t: np.ndarray, psi: np.ndarray, r: np.ndarray, extra_lines: str = ""
) -> Path:
    delta = 0.1 * np.sign(np.sin(0.3 * t) + 1e-9)
    data = zip(t.tolist(), delta.tolist(), psi.tolist(), r.tolist(), strict=True)
    rows = "\n".join(f"{a!r},{b!r},{c!r},{d!r}" for a, b, c, d in data)
    path.write_text("time_s,delta_rad,psi_rad,r_rad_s\n" + rows + "\n" + extra_lines)
    return path


@pytest.mark.filterwarnings("ignore:.*multiplied by:shipgym.sysid.data.SysidDataWarning")
def test_gunnerus_wrap_glitch_repaired(tmp_path: Path) -> None:
    # heading crosses 359 -> 0 deg, and the source interpolated linearly through 180 deg
    n, dt = 120, 0.5
    t = np.arange(n) * dt
    r_deg = np.full(n, 2.0)
    psi_true = 340.0 + np.cumsum(r_deg) * dt - r_deg[0] * dt
    psi_file = np.mod(psi_true, 360.0)
    k = int(np.flatnonzero(np.diff(psi_file) < 0)[0])  # wrap between k and k+1
    psi_file[k + 1 : k + 4] = np.linspace(psi_file[k], psi_file[k + 4], 5)[1:-1]
    lines = [",tvec,N,E,phi,psi,u,v,r,Azi,RPM"]
    for i in range(n):
        lines.append(f"{i},{t[i]},{i * 2.0},{0.0},0.5,{psi_file[i]},5.0,0.1,{r_deg[i]},-10.0,170")
    path = tmp_path / "RVG_test.csv"
    path.write_text("\n".join(lines) + "\n")
    assert detect_format(path) == "gunnerus"
    with pytest.warns(SysidDataWarning, match="heading glitches repaired: 3 samples"):
        rec = load(path)
    np.testing.assert_allclose(np.degrees(rec.psi), psi_true, atol=1e-9)
    assert any("glitch" in s for s in rec.meta["repairs"])
    assert np.all(rec.delta == math.radians(10.0))


@pytest.mark.filterwarnings("ignore:.*numpy.gradient:shipgym.sysid.data.SysidDataWarning")
def test_sspa_spike_glitch_repaired(tmp_path: Path) -> None:
    t = np.arange(300) * 0.02
    r = 0.1 * np.sin(t)
    psi = np.cumsum(r) * 0.02
    psi_bad = psi.copy()
    psi_bad[150] += 1.0  # one bogus sample
    data = zip(t.tolist(), psi_bad.tolist(), r.tolist(), strict=True)
    rows = "\n".join(f"{a!r};-0.1;{a!r};0.0;{b!r};{c!r}" for a, b, c in data)
    path = tmp_path / "example_zigzag.csv"
    path.write_text("time;delta;x0;y0;psi;r\n" + rows + "\n")
    with pytest.warns(SysidDataWarning, match="heading glitches repaired: 1 samples"):
        rec = load(path, format="sspa")
    assert abs(rec.psi[150] - psi[150]) < 1e-3
    assert np.all(rec.delta == 0.1)


def test_usv_spike_without_yaw_rate_repaired(tmp_path: Path) -> None:
    t = np.arange(100) * 0.5
    heading = 10.0 + 2.0 * t
    heading[40] += 60.0
    header = "time,lon,lat,speed,heading,rudder"
    rows = [
        f"{a},{119.16 + 1e-6 * i},{26.06 + 1e-6 * i},1.0,{h},20.0"
        for i, (a, h) in enumerate(zip(t, heading, strict=True))
    ]
    path = tmp_path / "usv.csv"
    path.write_text(header + "\n" + "\n".join(rows) + "\n")
    with pytest.warns(SysidDataWarning, match="interpolated linearly"):
        rec = load(path)
    np.testing.assert_allclose(np.degrees(rec.psi), 10.0 + 2.0 * t, atol=1e-9)
    np.testing.assert_allclose(np.degrees(rec.r[5:-5]), 2.0, atol=1e-6)
    assert "derived from psi" in rec.meta["r_source"]
    assert rec.x is not None and rec.x[-1] == pytest.approx(
        99e-6 * math.pi / 180 * 6.3787e6, rel=0.01
    )


def test_trailing_empty_rows_dropped(tmp_path: Path) -> None:
    t = np.arange(50) * 0.1
    path = _write_canonical(
        tmp_path / "c.csv", t, 0.01 * t, np.full(50, 0.01), extra_lines=",,,\n,,,\n\n"
    )
    with pytest.warns(SysidDataWarning, match="3 all-empty rows"):
        rec = load(path, format="canonical")
    assert rec.n == 50
    # Esso format with ",,,," rows as in zigzag_31-Jul-2020_13_50_28.csv
    cols = [
        "t [s]",
        "x_position_mid [m]",
        "u_velo [m/s]",
        "y_position_mid [m]",
        "vm_velo [m/s]",
        "psi_hat [rad]",
        "r_angvelo [rad/s]",
        "n_prop [rps]",
        "delta_rudder [rad]",
    ]
    rows = [
        ",".join(f"{v!r}" for v in (a, 0.0, 0.3, 0.0, 0.0, 0.01 * a, 0.01, 10.0, 0.1))
        for a in t.tolist()
    ]
    esso = tmp_path / "zigzag_x.csv"
    esso.write_text(",".join(cols) + "\n" + "\n".join(rows) + "\n" + ",,,,,,,,\n" * 4)
    assert detect_format(esso) == "esso_osaka"
    with pytest.warns(SysidDataWarning, match="4 all-empty rows"):
        rec = load(esso)
    assert rec.n == 50 and rec.rpm is not None and rec.rpm[0] == 600.0


def test_quantised_time_rebuilt(tmp_path: Path) -> None:
    t_true = np.arange(100) * 0.05
    t_q = np.floor(t_true * 10.0) / 10.0  # 0.1 s resolution: every stamp repeated
    path = _write_canonical(tmp_path / "q.csv", t_q, 0.02 * t_true, np.full(100, 0.02))
    with pytest.warns(SysidDataWarning, match="quantised"):
        rec = load(path)
    assert np.all(np.diff(rec.time) > 0)
    assert rec.dt == pytest.approx(0.05, rel=1e-3)
    assert np.max(np.abs(rec.time - t_true)) < 0.1


def test_duplicate_rows_dropped(tmp_path: Path) -> None:
    t = np.arange(40) * 0.1
    t_dup = np.insert(t, 10, t[10])
    psi = np.insert(0.01 * t, 10, 0.01 * t[10])
    path = _write_canonical(tmp_path / "d.csv", t_dup, psi, np.full(41, 0.01))
    with pytest.warns(SysidDataWarning, match="duplicate rows"):
        rec = load(path)
    np.testing.assert_array_equal(rec.time, t)


def test_time_backwards_refused(tmp_path: Path) -> None:
    t = np.arange(40) * 0.1
    t[20] = 0.5
    path = _write_canonical(tmp_path / "b.csv", t, 0.01 * np.arange(40), np.full(40, 0.01))
    with pytest.raises(ValueError, match="backwards"):
        load(path)


def test_irregular_sampling_flagged(tmp_path: Path) -> None:
    t = np.cumsum(np.r_[0.0, np.tile([0.5, 1.0, 2.0], 20)])
    path = _write_canonical(tmp_path / "i.csv", t, 0.01 * t, np.full(t.size, 0.01))
    with pytest.warns(SysidDataWarning, match="irregular sampling"):
        rec = load(path)
    assert rec.meta["irregular_sampling"] is True
    np.testing.assert_array_equal(rec.time, t)  # kept as is


def test_wrapped_canonical_psi_unwrapped(tmp_path: Path) -> None:
    t = np.arange(200) * 0.1
    psi = 3.0 + 0.05 * t
    wrapped = np.mod(psi + np.pi, 2 * np.pi) - np.pi
    path = _write_canonical(tmp_path / "w.csv", t, wrapped, np.full(200, 0.05))
    with pytest.warns(SysidDataWarning, match="unwrapped"):
        rec = load(path)
    np.testing.assert_allclose(rec.psi, psi, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------------------
def test_unknown_format_lists_accepted(tmp_path: Path) -> None:
    path = tmp_path / "mystery.txt"
    path.write_text("hello\n")
    with pytest.raises(ValueError, match="accepted formats: sspa, marin, hsva"):
        load(path)
    with pytest.raises(ValueError, match=r"unknown format 'xyz'.*gunnerus"):
        load(path, format="xyz")
    # a table of unknown columns is a ship's own table: the column map is asked for
    path.write_text("a,b,c\n1,2,3\n2,3,4\n")
    with pytest.raises(ValueError, match=r"cannot map the columns \['a', 'b', 'c'\].*--columns"):
        load(path)


def test_wrong_explicit_format_names_expected_header(tmp_path: Path) -> None:
    t = np.arange(20) * 0.1
    path = _write_canonical(tmp_path / "c.csv", t, t, t)
    with pytest.raises(ValueError, match=r"'sspa'.*time;delta;x0;y0;psi;r"):
        load(path, format="sspa")
    with pytest.raises(ValueError, match=r"'marin'.*MARIN"):
        load(path, format="marin")
    with pytest.raises(ValueError, match=r"'gunnerus'.*missing column.*tvec"):
        load(path, format="gunnerus")
    with pytest.raises(ValueError, match=r"'esso_osaka'.*psi_hat"):
        load(path, format="esso_osaka")


def test_missing_column_and_empty_file(tmp_path: Path) -> None:
    path = tmp_path / "c.csv"
    path.write_text("time_s,delta_rad,r_rad_s\n0,0,0\n1,0,0\n")
    with pytest.raises(ValueError, match=r"missing column\(s\) \['psi_rad'\]"):
        load(path)
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    with pytest.raises(ValueError, match="empty"):
        load(empty)
    with pytest.raises(ValueError, match="empty"):
        load(empty, format="usv")
    header_only = tmp_path / "h.csv"
    header_only.write_text("time_s,delta_rad,psi_rad,r_rad_s\n")
    with pytest.raises(ValueError, match="no data rows"):
        load(header_only)
    with pytest.raises(ValueError, match="not a file"):
        load(tmp_path / "absent.csv")
    with pytest.raises(ValueError, match="not a folder"):
        load_all(tmp_path / "absent")


def test_partial_row_refused(tmp_path: Path) -> None:
    path = tmp_path / "p.csv"
    path.write_text("time_s,delta_rad,psi_rad,r_rad_s\n0,0,0,0\n0.1,0,,0\n0.2,0,0,0\n")
    with pytest.raises(ValueError, match="miss a value"):
        load(path)

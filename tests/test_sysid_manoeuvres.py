"""Tests of shipgym.sysid.manoeuvres: manoeuvre extraction, model replay, table and folds."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from shipgym.sysid import manoeuvres as mv
from shipgym.sysid.data import Record, SysidDataWarning, load, measured_root

# one worker runs this file: its module fixtures are built once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_sysid_manoeuvres")

MEASURED = measured_root()
GUNNERUS = MEASURED / "gunnerus_seatrials" / "RVG_ManeuveringTests.csv"
needs_data = pytest.mark.skipif(
    not GUNNERUS.is_file(), reason=f"measured data not at {GUNNERUS} (set SHIPGYM_MEASURED_DATA)"
)

DEG = math.pi / 180.0

# ----------------------------------------------------------------------------------------------
# a synthetic ship: first-order speed and yaw responses to the orders, known steady states
A_SPEED = 0.035  # steady straight speed per rpm [m/s/rpm]
C_LOSS = 1.2  # speed loss in a turn per rad of azimuth
B_YAW = 0.04  # steady r = -B_YAW * azimuth * u [rad/s]
T_U, T_R = 10.0, 5.0


def first_order_ship(
    time: np.ndarray, rpm: np.ndarray, az: np.ndarray, x0: np.ndarray
) -> np.ndarray:
    """Euler simulation of ``u' = (u_ss - u) / T_U``, ``r' = (r_ss - r) / T_R``; v = 0."""
    out = np.empty((time.size, 6))
    out[0] = x0
    out[0, 4] = 0.0
    for k in range(time.size - 1):
        h = time[k + 1] - time[k]
        x, y, psi, u, _, r = out[k]
        u_ss = A_SPEED * rpm[k] * (1.0 - C_LOSS * abs(az[k]))
        r_ss = -B_YAW * az[k] * u
        out[k + 1] = (
            x + h * u * math.cos(psi),
            y + h * u * math.sin(psi),
            psi + h * r,
            u + h * (u_ss - u) / T_U,
            0.0,
            r + h * (r_ss - r) / T_R,
        )
    return out


def synthetic_record() -> Record:
    """Straights, turns to both sides (one entered with an rpm change) and a zigzag."""
    schedule = [  # (duration [s], rpm, azimuth [deg])
        (200, 150, 0),
        (150, 150, 15),
        (150, 150, 0),
        (150, 150, -15),
        (150, 150, 0),
        *[(20, 150, 10 * (-1) ** k) for k in range(6)],
        (150, 150, 0),
        (200, 100, 0),
        (150, 80, -25),
        (150, 100, 0),
    ]
    dt = 0.5
    rpm = np.concatenate([np.full(round(d / dt), n, float) for d, n, _ in schedule])
    az = np.concatenate([np.full(round(d / dt), a * DEG) for d, _, a in schedule])
    time = dt * np.arange(rpm.size)
    x0 = np.array([0.0, 0.0, 0.3, A_SPEED * 150.0, 0.0, 0.0])
    s = first_order_ship(time, rpm, az, x0)
    return Record(
        time=time,
        delta=-az,
        psi=s[:, 2],
        r=s[:, 5],
        x=s[:, 0],
        y=s[:, 1],
        u=s[:, 3],
        v=s[:, 4],
        azimuth=az,
        rpm=rpm,
        meta={"source": "synthetic"},
    )


def lookup_simulator(record: Record):
    """A 'model' that returns the measured record at the requested (recorded) times."""
    states = np.column_stack((record.x, record.y, record.psi, record.u, record.v, record.r))

    def simulate(time, rpm, az, x0):
        idx = np.searchsorted(record.time, time)
        assert np.all(idx < record.n) and np.allclose(record.time[idx], time)
        assert np.array_equal(rpm, record.rpm[idx]) and np.array_equal(az, record.azimuth[idx])
        assert abs(x0[2] - states[idx[0], 2]) < 0.05  # x0 is the (smoothed) measured state
        return states[idx]

    return simulate


def _same(a, b, rel: float = 1e-12) -> bool:
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y, rel) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and math.isnan(a):
        return math.isnan(b)
    return a == pytest.approx(b, rel=rel, abs=1e-12)


@pytest.fixture(scope="module")
def synth() -> tuple[Record, list[mv.Manoeuvre]]:
    rec = synthetic_record()
    return rec, mv.extract_manoeuvres(rec)


@pytest.fixture(scope="module")
def trials() -> tuple[Record, list[mv.Manoeuvre]]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidDataWarning)
        rec = load(GUNNERUS)
    return rec, mv.extract_manoeuvres(rec)


# ----------------------------------------------------------------------------------------------
# synthetic record: exact steady states


def test_synthetic_extraction_finds_the_schedule(synth) -> None:
    rec, ms = synth
    kinds = [m.kind for m in ms]
    names = {m.name for m in ms}
    assert kinds.count("turn") == 3 and kinds.count("zigzag") == 1
    assert kinds.count("straight") == 6
    for m in ms:
        i0, i1 = m.span
        s0, s1 = m.settled
        assert 0 <= i0 < s0 < s1 == i1 <= rec.n and m.n_record == rec.n
    for m in (m for m in ms if m.kind == "straight"):
        assert m.quantities["U"] == pytest.approx(A_SPEED * m.quantities["rpm"], rel=1e-3)
    turns = [m for m in ms if m.kind == "turn"]
    assert [t.side for t in turns] == ["port", "starboard", "starboard"]
    for t in turns:
        q = t.quantities
        az = q["azimuth"]
        loss = 1.0 - C_LOSS * abs(az)
        assert q["U"] == pytest.approx(A_SPEED * q["rpm"] * loss, rel=3e-3)
        assert q["r"] == pytest.approx(-B_YAW * az * q["U"], rel=3e-3)
        assert q["diameter"] == pytest.approx(2.0 / (B_YAW * abs(az)), rel=3e-3)
        assert q["speed_ratio"] == pytest.approx(loss, rel=3e-3)
    # the 80-rpm turn was entered from 100 rpm: U_approach from the 100-rpm straights
    assert [len(t.reference) for t in turns] == [0, 0, 2]
    assert all(s.quantities["rpm"] == 100.0 and s.name in names for s in turns[2].reference)
    (zz,) = (m for m in ms if m.kind == "zigzag")
    assert zz.quantities["n_reversals"] == 5.0 and len(zz.quantities["overshoots"]) == 5
    assert zz.quantities["amplitude"] == pytest.approx(10 * DEG)
    assert all(0.5 * DEG < o < 10 * DEG for o in zz.quantities["overshoots"])


def test_replay_of_the_generating_model_gives_the_measured_quantities(synth) -> None:
    """Default hold times: the settled model values agree with the settled measured ones."""
    rec, ms = synth
    for m in ms:
        sim = mv.simulate_manoeuvre(m, rec, first_order_ship)
        meas = m.quantities
        keys = {"straight": ["U"], "turn": ["U", "r", "diameter", "speed_ratio"]}.get(m.kind)
        for key in keys or ["overshoot_mean", "overshoot_max"]:
            assert sim[key] == pytest.approx(meas[key], rel=3e-3), (m.name, key)


def test_instant_model_has_no_overshoot_and_the_table_reports_it(synth, tmp_path: Path) -> None:
    rec, ms = synth

    def instant(time, rpm, az, x0):
        out = np.empty((time.size, 6))
        u = A_SPEED * rpm * (1.0 - C_LOSS * np.abs(az))
        r = -B_YAW * az * u
        out[:, 3], out[:, 4], out[:, 5] = u, 0.0, r
        out[:, 2] = x0[2] + np.r_[0.0, np.cumsum(r[:-1] * np.diff(time))]
        out[:, 0] = out[:, 1] = 0.0
        return out

    rows = mv.validation_table(ms, rec, {"instant": instant, "lagged": first_order_ship})
    assert [r["name"] for r in rows] == [m.name for m in ms]
    zz = next(r for r in rows if r["kind"] == "zigzag")
    assert zz["models"]["instant"]["overshoot_max"] == pytest.approx(0.0, abs=1e-12)
    assert zz["errors"]["instant"]["overshoot_mean_deg"] == pytest.approx(
        -math.degrees(zz["measured"]["overshoot_mean"])
    )
    for row in rows:
        for err in row["errors"]["lagged"].values():
            assert abs(err) < 0.5  # % or deg or absolute ratio
    md = mv.render_markdown(rows)
    # one line per quantity: straight U; turn r, U, diameter, U/U_approach; zigzag mean, max
    per_kind = {"straight": 1, "turn": 4, "zigzag": 2}
    assert md.count("\n") == 2 + sum(per_kind[r["kind"]] for r in rows)
    assert "| instant | instant error | lagged | lagged error |" in md
    assert "r [deg/s]" in md and "mean overshoot [deg]" in md
    png = mv.plot_validation(rows, tmp_path / "validation.png")
    assert png.stat().st_size > 10_000


def test_diverging_model_gives_nan_not_an_error(synth) -> None:
    rec, ms = synth

    def broken(time, rpm, az, x0):
        return np.full((time.size, 6), np.nan)

    rows = mv.validation_table(ms, rec, {"broken": broken})
    for row in rows:
        assert all(math.isnan(v) for v in row["errors"]["broken"].values())
    assert "n/a" in mv.render_markdown(rows)


# ----------------------------------------------------------------------------------------------
# the Gunnerus sea trials against the published reference (docs/RVG_PARAMETERS.md)


@needs_data
def test_sea_trial_straight_speeds_match_the_reference(trials) -> None:
    _, ms = trials
    straights = [m for m in ms if m.kind == "straight"]
    for rpm, ref in ((110.0, 3.72), (170.0, 5.45), (195.0, 6.10)):
        speeds = [m.quantities["U"] for m in straights if abs(m.quantities["rpm"] - rpm) < 5]
        assert len(speeds) >= 3, rpm
        assert np.mean(speeds) == pytest.approx(ref, rel=0.015), rpm
        assert all(abs(s / ref - 1.0) < 0.06 for s in speeds), (rpm, speeds)


@needs_data
@pytest.mark.parametrize(
    ("az_deg", "rpm_range", "r_deg_s", "diameter_m", "ratio"),
    [
        (10, (165, 175), (2.26, 2.45), (223, 248), (0.85, 0.92)),
        (20, (160, 168), (3.47, 3.55), (122, 124), (0.71, 0.73)),
        (30, (95, 120), (2.66, 2.95), (68, 82), (0.49, 0.57)),
    ],
)
def test_sea_trial_steady_turns_match_the_reference(
    trials, az_deg, rpm_range, r_deg_s, diameter_m, ratio
) -> None:
    _, ms = trials
    turns = [
        m
        for m in ms
        if m.kind == "turn"
        and abs(abs(math.degrees(m.quantities["azimuth"])) - az_deg) < 3.5
        and rpm_range[0] <= m.quantities["rpm"] <= rpm_range[1]
    ]
    assert {t.side for t in turns} == {"port", "starboard"}
    for t in turns:
        q = t.quantities
        assert np.sign(q["r"]) == -np.sign(q["azimuth"])  # positive azimuth turns to port
        assert r_deg_s[0] - 0.05 <= abs(math.degrees(q["r"])) <= r_deg_s[1] + 0.05, t.name
        assert 0.97 * diameter_m[0] <= q["diameter"] <= 1.03 * diameter_m[1], t.name
        assert ratio[0] - 0.02 <= q["speed_ratio"] <= ratio[1] + 0.02, t.name
        assert q["diameter"] == pytest.approx(2.0 * q["U"] / abs(q["r"]))


@needs_data
def test_sea_trial_zigzags(trials) -> None:
    rec, ms = trials
    zigzags = [m for m in ms if m.kind == "zigzag"]
    assert len(zigzags) >= 3
    for z in zigzags:
        q = z.quantities
        assert q["n_reversals"] == len(q["overshoots"]) == len(z.events)
        assert len(z.events) >= mv.ZIGZAG_MIN_REVERSALS
        assert q["amplitude"] >= mv.ZIGZAG_MIN_AZ
        assert all(0.5 * DEG <= o <= 10.0 * DEG for o in q["overshoots"]), z.name
        assert q["overshoot_max"] == max(q["overshoots"])
        # each reversal is a sign change of the azimuth order
        for k in z.events:
            assert rec.azimuth[k - 1] * rec.azimuth[k] <= 0.0
    times = [rec.time[z.settled[0]] for z in zigzags]
    assert any(1500 <= t <= 2250 for t in times) and any(3300 <= t <= 4000 for t in times)
    assert any(4150 <= t <= 4550 for t in times)


@needs_data
def test_lookup_simulator_reproduces_the_measured_quantities(trials) -> None:
    rec, ms = trials
    simulate = lookup_simulator(rec)
    for m in ms:
        sim = mv.simulate_manoeuvre(m, rec, simulate, hold_s=0.0)
        assert sim.keys() == m.quantities.keys()
        for key, value in m.quantities.items():
            assert _same(value, sim[key]), (m.name, key, value, sim[key])


@needs_data
def test_table_errors_of_a_faster_lookup_model(trials) -> None:
    """A model 10 % faster than the record: +10 % speed and diameter, same r and ratio."""
    rec, ms = trials
    base = lookup_simulator(rec)

    def faster(time, rpm, az, x0):
        out = base(time, rpm, az, x0).copy()
        out[:, 3:5] *= 1.1
        return out

    picked = [next(m for m in ms if m.kind == k) for k in mv.KINDS]
    rows = mv.validation_table(picked, rec, {"fast": faster}, hold_s=0.0)
    err = {row["kind"]: row["errors"]["fast"] for row in rows}
    assert err["straight"]["speed_pct"] == pytest.approx(10.0)
    assert err["turn"]["speed_pct"] == pytest.approx(10.0)
    assert err["turn"]["diameter_pct"] == pytest.approx(10.0)
    assert err["turn"]["yaw_rate_pct"] == pytest.approx(0.0, abs=1e-9)
    assert err["turn"]["speed_ratio_abs"] == pytest.approx(0.0, abs=1e-9)
    assert err["zigzag"]["overshoot_mean_deg"] == pytest.approx(0.0, abs=1e-9)


# ----------------------------------------------------------------------------------------------
# folds


@pytest.mark.parametrize("source", ["synthetic", "trials"])
@pytest.mark.parametrize("k", [2, 3])
def test_folds_partition_the_manoeuvres_and_mask_their_spans(request, source, k) -> None:
    if source == "trials" and not GUNNERUS.is_file():
        pytest.skip(f"measured data not at {GUNNERUS} (set SHIPGYM_MEASURED_DATA)")
    rec, ms = request.getfixturevalue("synth" if source == "synthetic" else "trials")
    out = mv.folds(ms, k)
    assert len(out) == k
    names = [m.name for group, _ in out for m in group]
    assert sorted(names) == sorted(m.name for m in ms)  # each in exactly one fold
    sizes = [len(group) for group, _ in out]
    assert max(sizes) - min(sizes) <= 1
    for group, mask in out:
        expected = np.ones(rec.n, dtype=bool)
        for m in group:
            expected[m.span[0] : m.span[1]] = False
        assert mask.dtype == bool and np.array_equal(mask, expected)
        if source == "trials":
            assert {m.side for m in group if m.kind == "turn"} == {"port", "starboard"}


# ----------------------------------------------------------------------------------------------
# bad input


def test_bad_input_raises_value_error(synth) -> None:
    rec, ms = synth
    chans = rec.channels()
    for name in ("rpm", "azimuth", "u"):
        partial = Record(**{k: v for k, v in chans.items() if k != name})
        with pytest.raises(ValueError, match=name):
            mv.extract_manoeuvres(partial)
        with pytest.raises(ValueError, match="rpm, azimuth, u, r and psi"):
            mv.simulate_manoeuvre(ms[0], partial, first_order_ship)
    irregular = {k: v[np.r_[0:100, 101 : rec.n]] for k, v in chans.items()}
    with pytest.raises(ValueError, match="uniform sampling"):
        mv.extract_manoeuvres(Record(**irregular))
    with pytest.raises(ValueError, match=r"shape \("):
        mv.simulate_manoeuvre(ms[0], rec, lambda t, n, a, x0: np.zeros((t.size, 4)))
    with pytest.raises(ValueError, match="hold_s"):
        mv.simulate_manoeuvre(ms[0], rec, first_order_ship, hold_s=-1.0)
    with pytest.raises(ValueError, match="k must be"):
        mv.folds(ms, 1)
    with pytest.raises(ValueError, match="k must be"):
        mv.folds(ms, len(ms) + 1)

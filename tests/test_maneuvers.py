"""Tests of the standard manoeuvres in :mod:`shipgym.maneuvers` and ``shipgym simulate``.

Each test checks a trial against an independent reference: an adaptive ``solve_ivp``
integration with exact event switching, a closed form (steady turning diameter, the Norrbin
steady-state cubic and its fold points), a mirror symmetry, or the IMO formulas.
"""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from shipgym import maneuvers as mv
from shipgym.cli import main
from shipgym.models import NorrbinParams, SteeringGear, make_model
from shipgym.sysid.data import measured_root

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
N3 = NorrbinParams().n3
K = NorrbinParams().K


def _unstable_norrbin():
    """A directionally unstable Norrbin ship: n1 = -1 (seed 004 eq. 4 with a negative slope)."""
    return make_model("norrbin", NorrbinParams(n1=-1.0))


def _is_png(path: Path) -> bool:
    return path.is_file() and path.stat().st_size > 10_000 and path.read_bytes()[:8] == PNG_MAGIC


# --------------------------------------------------------------------------------------------
# zigzag
# --------------------------------------------------------------------------------------------
def _reference_zigzag(a: float, b: float, s0: float, n: int) -> list[float]:
    """Overshoots [deg] of ``T r' + r = K delta`` with the steering gear, by ``solve_ivp``.

    Independent of the package: own right-hand side (first-order Nomoto, rate-limited
    first-order rudder servo), the rudder reversed exactly when ``psi`` crosses ``+-b``
    (terminal events), the overshoot read at the event ``r = 0`` after each reversal.
    """
    p, gear = NorrbinParams(), SteeringGear()  # K = 0.185 1/s; nomoto1 uses T = 107.3 s
    k_gain, t_yaw = p.K, 107.3

    def rhs(t, y, dc):
        _, r, d = y
        dd = min(max((dc - d) / gear.time_constant, -gear.max_rate), gear.max_rate)
        return [r, (k_gain * d - r) / t_yaw, dd]

    opts = {"rtol": 1e-10, "atol": 1e-12, "max_step": 0.5, "method": "DOP853"}
    y, t, sign = np.zeros(3), 0.0, s0
    overshoots = []
    for k in range(n + 1):
        dc = sign * a

        def check(t, y, dc, s=sign):
            return y[0] - s * b

        check.terminal, check.direction = True, sign

        def peak(t, y, dc):
            return y[1]

        peak.terminal = k == n  # after the last reversal stop at the peak
        peak.direction = sign  # r returns through zero against the previous swing
        sol = solve_ivp(rhs, (t, t + 5000.0), y, args=(dc,), events=(check, peak), **opts)
        if k > 0:
            psi_peak = sol.y_events[1][0][0]
            overshoots.append(math.degrees(-sign * psi_peak - b))
        if k == n:
            break
        t, y = sol.t_events[0][0], sol.y_events[0][0]
        sign = -sign
    return overshoots


@pytest.mark.parametrize(("a_deg", "b_deg", "first"), [(10, 10, "starboard"), (20, 20, "port")])
def test_zigzag_overshoots_match_an_independent_event_integration(a_deg, b_deg, first) -> None:
    res = mv.zigzag("nomoto1", a_deg, b_deg, first, n_reversals=4, dt=0.02)
    s0 = 1.0 if first == "starboard" else -1.0
    ref = _reference_zigzag(math.radians(a_deg), math.radians(b_deg), s0, 4)
    assert res.completed
    # the step-nearest reversal moves the switch by at most dt / 2 (|r| dt / 2 in heading)
    np.testing.assert_allclose(res.overshoots_deg, ref, atol=0.03)
    assert len(res.execute_times) == 4
    # the heading really crosses +-b at each reversal, alternating sides
    for k, te in enumerate(res.execute_times):
        i = int(np.searchsorted(res.series.time, te))
        s = s0 if k % 2 == 0 else -s0
        assert s * math.degrees(res.series.psi[i]) == pytest.approx(b_deg, abs=0.05)
        assert np.sign(res.series.delta_c[i]) == -s
    assert res.initial_turning_time == pytest.approx(res.execute_times[0])
    assert 0 < res.time_to_check_yaw < res.execute_times[1] - res.execute_times[0]
    assert res.period == pytest.approx(
        np.mean(
            [
                res.execute_times[2] - res.execute_times[0],
                res.execute_times[3] - res.execute_times[1],
            ]
        )
    )


@pytest.mark.parametrize("model", ["norrbin", "bech", "rvg3dof"])
def test_zigzag_to_port_mirrors_starboard(model: str) -> None:
    stb = mv.zigzag(model, 20.0, n_reversals=2)
    port = mv.zigzag(model, 20.0, first="port", n_reversals=2)
    np.testing.assert_allclose(stb.overshoots, port.overshoots, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(stb.series.psi, -port.series.psi, atol=1e-9)


def test_unstable_rvg_zigzag_reports_unchecked_swing_as_nan() -> None:
    res = mv.zigzag("rvg3dof", 10.0, n_reversals=4, max_duration=300.0)
    # Known limitation (README): the RVG base model is directionally unstable and 10 deg of
    # opposite azimuth checks a developed swing slowly or not at all.
    assert not res.completed
    unchecked = [math.isnan(o) for o in res.overshoots]
    assert unchecked[-1]
    # every swing before the unchecked one was checked only after a large overshoot
    assert all(o > 90.0 for o, nan in zip(res.overshoots_deg, unchecked, strict=True) if not nan)
    d = res.to_dict(include_series=False)
    assert d["overshoots_deg"][-1] is None
    json.dumps(d, allow_nan=False)


# --------------------------------------------------------------------------------------------
# turning circle
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("model", ["nomoto1", "rvg3dof"])
def test_turning_circles_to_port_and_starboard_are_mirror_images(model: str) -> None:
    stb = mv.turning_circle(model, 35.0, "starboard")
    port = mv.turning_circle(model, 35.0, "port")
    for name in ("advance", "transfer", "tactical_diameter", "steady_diameter", "speed_ratio"):
        assert getattr(stb, name) == pytest.approx(getattr(port, name), rel=1e-9), name
    assert stb.steady_yaw_rate == pytest.approx(-port.steady_yaw_rate, rel=1e-9)
    assert stb.transfer > 0 and stb.tactical_diameter > 0
    # tracks: north equal, east negated (mirror in the approach course)
    np.testing.assert_allclose(stb.series.x, port.series.x, atol=1e-9)
    np.testing.assert_allclose(stb.series.y, -port.series.y, atol=1e-9)
    # a starboard turn stays to starboard of the approach course, apart from the small initial
    # outward "kick" of a ship with sway (the stern is pushed out first)
    assert np.all(stb.series.y >= -0.01 * stb.particulars.length)


def test_nomoto1_steady_turning_diameter_is_the_closed_form() -> None:
    res = mv.turning_circle("nomoto1", 35.0)
    delta, u = math.radians(35.0), 7.7  # K_u n = 5.5 * 1.4
    closed = 2.0 * u / (0.185 * delta)  # 2 U / r_ss with r_ss = K delta
    assert res.steady
    assert res.steady_diameter == pytest.approx(closed, rel=0.01)
    assert res.steady_yaw_rate == pytest.approx(0.185 * delta, rel=0.01)
    assert res.speed_ratio == pytest.approx(1.0, abs=1e-9)  # Nomoto: no speed loss
    # geometry of the definitions: the 90 deg point lies on the track, the tactical diameter
    # exceeds the transfer, and the heading is 90 deg there
    n90, e90 = res.points["heading_90"]
    assert res.advance == pytest.approx(n90) and res.transfer == pytest.approx(e90)
    assert res.tactical_diameter > res.transfer > 0
    assert res.time_to_180 > res.time_to_90 > res.rudder_time > 0


def test_rvg_turns_to_starboard_with_positive_equivalent_rudder_and_loses_speed() -> None:
    res = mv.turning_circle("rvg3dof", 20.0, "starboard")
    sim = res.series.simulation
    assert res.steady_yaw_rate > 0
    assert sim["alpha1"][-1] == pytest.approx(-math.radians(20.0), abs=1e-6)  # delta = -alpha
    assert res.series.delta[-1] == pytest.approx(math.radians(20.0), abs=1e-6)
    # speed falls with the heading change (seed 002 Table 3 shape) and settles far below U
    assert res.speeds[0] < res.approach_speed
    assert res.speeds[-1] < res.speeds[0]
    assert res.speed_ratio < 0.6  # the base model loses about half its speed (README)
    assert res.steady_speed == pytest.approx(res.speed_ratio * res.approach_speed)


# --------------------------------------------------------------------------------------------
# spiral and pull-out
# --------------------------------------------------------------------------------------------
def _norrbin_r(delta: float, n1: float) -> np.ndarray:
    """Real roots r of n3 r^3 + n1 r = K delta."""
    roots = np.roots([N3, 0.0, n1, -K * delta])
    return np.sort(roots[np.abs(roots.imag) < 1e-12].real)


def test_direct_spiral_of_norrbin_follows_the_steady_cubic() -> None:
    res = mv.spiral("norrbin", kind="direct")
    assert res.steady.all()
    assert not res.hysteresis and res.loop_width == 0.0
    for d, r in zip(res.rudder, res.yaw_rate, strict=True):
        (exact,) = _norrbin_r(float(d), 1.0)  # stable ship: one real root
        assert r == pytest.approx(exact, rel=2e-3, abs=3e-6)
    # the sweep went from starboard to port and back
    assert res.leg.count("down") == 15 and res.leg.count("up") == 14


def test_unstable_norrbin_direct_spiral_shows_hysteresis_and_reverse_recovers_the_s_curve():
    ship = _unstable_norrbin()
    fold = 2.0 / (3.0 * math.sqrt(3.0 * N3)) / K  # rudder at the fold points [rad]
    direct = mv.spiral(ship, kind="direct")
    assert direct.hysteresis
    # the legs disagree exactly where three steady states exist (|delta| < fold)
    assert math.radians(3.0) <= direct.loop_width + 1e-12 <= 2 * fold + math.radians(1.0)
    at_zero = [r for d, r in zip(direct.rudder, direct.yaw_rate, strict=True) if abs(d) < 1e-9]
    assert len(at_zero) == 2 and at_zero[0] * at_zero[1] < 0
    np.testing.assert_allclose(np.abs(at_zero), 1.0 / math.sqrt(N3), rtol=2e-3)
    for d, r in zip(direct.rudder, direct.yaw_rate, strict=True):  # outer (stable) branches
        roots = _norrbin_r(float(d), -1.0)
        assert r == pytest.approx(roots[np.argmin(np.abs(roots - r))], rel=2e-3, abs=3e-6)
        assert abs(r) >= 1.0 / math.sqrt(3.0 * N3)

    reverse = mv.spiral(ship, kind="reverse")
    assert reverse.steady.all() and not reverse.saturated.any()
    np.testing.assert_allclose(reverse.yaw_rate, reverse.setpoints, atol=2e-5)
    expected = (N3 * reverse.yaw_rate**3 - reverse.yaw_rate) / K
    np.testing.assert_allclose(reverse.rudder, expected, atol=math.radians(0.01))
    inner = np.abs(reverse.yaw_rate) < 1.0 / math.sqrt(3.0 * N3)  # the unstable branch
    assert inner.sum() >= 5
    assert reverse.hysteresis
    assert 0.9 * 2 * fold <= reverse.loop_width <= 2 * fold * (1 + 1e-3)


def test_pullout_residual_yaw_rate_vanishes_for_stable_and_stays_for_unstable_ships() -> None:
    stable = mv.pullout("nomoto1", 20.0)
    assert stable.settled and stable.stable
    assert abs(stable.residual_yaw_rate) < 1e-3 * abs(stable.turn_yaw_rate)
    assert stable.turn_yaw_rate == pytest.approx(0.185 * math.radians(20.0), rel=1e-3)
    # first-order decay: r falls to 1/e of the turn rate one time constant T after the rudder
    # is amidships; the rudder needs 20 / 2.32 s plus its 2 s servo lag to get there
    assert 107.3 < stable.decay_time < 107.3 + 20.0 / 2.32 + 2.0

    unstable = mv.pullout(_unstable_norrbin(), 20.0, "port")
    assert not unstable.stable
    assert unstable.residual_yaw_rate == pytest.approx(-1.0 / math.sqrt(N3), rel=2e-3)

    rvg = mv.pullout("rvg3dof", 20.0)
    assert not rvg.stable and rvg.residual_yaw_rate > 0.5 * rvg.turn_yaw_rate


# --------------------------------------------------------------------------------------------
# IMO
# --------------------------------------------------------------------------------------------
def test_overshoot_limits_follow_msc137() -> None:
    assert mv.overshoot_limits(5.0) == (10.0, 25.0, 25.0)
    assert mv.overshoot_limits(20.0) == (15.0, 32.5, 25.0)
    assert mv.overshoot_limits(45.0) == (20.0, 40.0, 25.0)
    for q in (10.0, 30.0):  # continuous at the break points
        lo, hi = mv.overshoot_limits(q - 1e-9), mv.overshoot_limits(q)
        np.testing.assert_allclose(lo, hi, atol=1e-6)
    with pytest.raises(ValueError, match="L/U"):
        mv.overshoot_limits(0.0)


def test_imo_table_rows_agree_with_the_manoeuvre_metrics() -> None:
    report = mv.imo_criteria("nomoto1")
    L = 160.93
    rows = {row.criterion.split(":")[1].strip(): row for row in report.rows}
    assert len(report.rows) == 6
    for row in report.rows:
        assert row.passed == (row.value <= row.limit)
    first, second, _ = mv.overshoot_limits(L / 7.7)
    turning = mv.turning_circle("nomoto1", 35.0, "port")
    assert rows["advance (35 deg rudder)"].value == pytest.approx(turning.advance / L)
    assert rows["advance (35 deg rudder)"].limit == 4.5
    assert rows["tactical diameter (35 deg rudder)"].value == pytest.approx(
        turning.tactical_diameter / L
    )
    initial = mv.initial_turning("nomoto1", 10.0, 10.0, "starboard")
    key = "distance to 10 deg heading change (10 deg rudder)"
    assert rows[key].value == pytest.approx(initial.distance / L)
    assert rows[key].limit == 2.5
    z10 = mv.zigzag("nomoto1", 10.0, first="starboard", n_reversals=2)
    assert rows["10/10 zigzag 1st overshoot"].value == pytest.approx(z10.overshoots_deg[0])
    assert rows["10/10 zigzag 1st overshoot"].limit == pytest.approx(first)
    assert rows["10/10 zigzag 2nd overshoot"].value == pytest.approx(z10.overshoots_deg[1])
    assert rows["10/10 zigzag 2nd overshoot"].limit == pytest.approx(second)
    z20 = mv.zigzag("nomoto1", 20.0, n_reversals=1)
    row20 = rows["20/20 zigzag 1st overshoot"]
    assert row20.value == pytest.approx(z20.overshoots_deg[0])
    # the linear model overpredicts large manoeuvres (README): 20/20 overshoot about 28 deg
    assert not row20.passed and not report.passed
    assert rows["advance (35 deg rudder)"].passed
    # distance travelled exceeds the advance but not by much for a 10 deg turn
    assert initial.advance < initial.distance < 1.01 * initial.advance
    table = mv.format_imo_table(report)
    assert table.count("PASS") == 5 and table.count("FAIL") == 1
    d = report.to_dict()
    json.dumps(d, allow_nan=False)
    assert [r["pass"] for r in d["rows"]] == [r.passed for r in report.rows]


# --------------------------------------------------------------------------------------------
# results, plots and input checks
# --------------------------------------------------------------------------------------------
def test_to_dict_uses_degrees_at_the_edge_and_plots_are_pngs(tmp_path: Path) -> None:
    zz = mv.zigzag("bech", 20.0, n_reversals=2)
    d = zz.to_dict()
    assert d["rudder_deg"] == pytest.approx(20.0)
    assert d["overshoots_deg"] == pytest.approx(list(zz.overshoots_deg), abs=1e-5)
    assert set(d["series"]) == {
        "time_s",
        "x_m",
        "y_m",
        "psi_deg",
        "r_deg_s",
        "delta_deg",
        "delta_c_deg",
        "speed_m_s",
    }
    assert max(d["series"]["delta_deg"]) == pytest.approx(20.0, abs=1e-3)
    tc = mv.turning_circle("bech", 35.0)
    po = mv.pullout("bech", 20.0)
    sp = mv.spiral("bech", rudders_deg=[10.0, 0.0, -10.0], kind="direct")
    for res in (zz, tc, po, sp):
        json.dumps(res.to_dict(), allow_nan=False)
    assert len(tc.to_dict()["series"]["time_s"]) <= 2001
    paths = [
        mv.plot_zigzag(zz, tmp_path / "zz.png"),
        mv.plot_turning_circle(tc, tmp_path / "tc.png"),
        mv.plot_pullout(po, tmp_path / "po.png"),
        mv.plot_spiral(sp, tmp_path / "sp.png"),
    ]
    assert all(_is_png(p) for p in paths)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: mv.zigzag("titanic"), "unknown model"),
        (lambda: mv.zigzag("nomoto1", 0.0), "a_deg"),
        (lambda: mv.zigzag("nomoto1", 20.0, first="north"), "side"),
        (lambda: mv.zigzag("nomoto1", 20.0, n_reversals=0), "n_reversals"),
        (lambda: mv.turning_circle("rvg3dof", 40.0), "rudder_deg"),
        (lambda: mv.turning_circle("nomoto1", float("nan")), "rudder_deg"),
        (lambda: mv.pullout("nomoto1", 20.0, dt=0.0), "dt"),
        (lambda: mv.spiral("norrbin", kind="sideways"), "kind"),
        (lambda: mv.spiral("norrbin", rudders_deg=[50.0, 0.0]), "within"),
        (lambda: mv.imo_criteria("nomoto1", sides=()), "sides"),
    ],
)
def test_bad_input_raises_value_error(call, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        call()


# --------------------------------------------------------------------------------------------
# CLI
# --------------------------------------------------------------------------------------------
def test_cli_simulate_zigzag_writes_json_and_png(tmp_path: Path, capsys) -> None:
    out_json, out_png = tmp_path / "zz.json", tmp_path / "zz.png"
    code = main(
        [
            "simulate",
            "zigzag",
            "--model",
            "nomoto1",
            "--json",
            str(out_json),
            "--plot",
            str(out_png),
        ]
    )
    assert code == 0
    stdout = capsys.readouterr().out
    assert _is_png(out_png)
    data = json.loads(out_json.read_text())
    ref = mv.zigzag("nomoto1", 20.0)
    assert data["overshoots_deg"] == pytest.approx(list(ref.overshoots_deg), abs=1e-5)
    assert data["imo"][0]["criterion"] == "yaw-checking: 20/20 zigzag 1st overshoot"
    assert data["imo"][0]["pass"] is False
    assert "20/20 zigzag 1st overshoot" in stdout and "FAIL" in stdout
    assert f"{ref.overshoots_deg[0]:.2f}" in stdout


def test_cli_simulate_turning_and_imo(tmp_path: Path, capsys) -> None:
    assert (
        main(
            [
                "simulate",
                "turning",
                "--model",
                "norrbin",
                "--side",
                "port",
                "--angle-deg",
                "35",
                "--json",
                str(tmp_path / "tc.json"),
            ]
        )
        == 0
    )
    stdout = capsys.readouterr().out
    data = json.loads((tmp_path / "tc.json").read_text())
    assert data["side"] == "port" and data["rudder_deg"] == pytest.approx(35.0)
    assert f"{data['tactical_diameter_m']:.1f} m" in stdout
    assert [r["pass"] for r in data["imo"]] == [True, True]
    assert main(["simulate", "imo", "--model", "bech", "--plot", str(tmp_path / "imo.png")]) == 0
    stdout = capsys.readouterr().out
    assert "overall:" in stdout and "10/10 zigzag 2nd overshoot" in stdout
    assert _is_png(tmp_path / "imo.png")


@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "zigzag", "--model", "titanic"],
        ["simulate", "loop", "--model", "nomoto1"],
        ["simulate", "zigzag", "--angle-deg", "50"],
        ["simulate", "zigzag", "--angle-deg", "nan"],
        ["simulate", "turning", "--kind", "direct"],
        ["simulate", "spiral", "--side", "port"],
        ["simulate", "zigzag", "--plot", "figure.pdf"],
    ],
)
def test_cli_simulate_bad_input_exits_2(argv: list[str], capsys) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "error" in err and "Traceback" not in err


# ------------------------------------------------------------------------------------------
# trial quantities of any time series (simulated or measured)


def test_zigzag_quantities_of_a_simulated_zigzag_are_its_overshoots() -> None:
    for first in ("starboard", "port"):
        z = mv.zigzag("kvlcc2", 10.0, 10.0, first=first)
        s = z.series
        q = mv.zigzag_quantities(s.time, s.psi, s.delta, math.radians(10.0))
        assert q["first"] == first and q["n_reversals"] >= 3
        np.testing.assert_allclose(
            [q["overshoot1_deg"], q["overshoot2_deg"]], np.degrees(z.overshoots[:2]), atol=0.05
        )


def test_turning_quantities_of_a_simulated_circle_are_its_advance_and_diameter() -> None:
    for side in ("starboard", "port"):
        tc = mv.turning_circle("kvlcc2", 35.0, side)
        s = tc.series
        q = mv.turning_quantities(s.time, s.x, s.y, s.psi, s.delta, s.speed)
        assert q["side"] == side
        assert q["advance"] == pytest.approx(tc.advance, rel=5e-3)
        assert q["tactical_diameter"] == pytest.approx(tc.tactical_diameter, rel=5e-3)
        assert 0.2 < q["speed_ratio"] < 0.6


def test_trial_quantities_refuse_series_without_a_trial() -> None:
    t = np.arange(10.0)
    with pytest.raises(ValueError, match="never leaves amidships"):
        mv.zigzag_quantities(t, np.zeros(10), np.zeros(10), 0.1)
    with pytest.raises(ValueError, match="one length"):
        mv.turning_quantities(t, t, t, t, t, t[:5])
    with pytest.raises(ValueError, match="check"):
        mv.zigzag_quantities(t, t, t, -1.0)


SIMMAN = measured_root()


@pytest.mark.skipif(
    not (SIMMAN / "marin_kvlcc2").is_dir(),
    reason="SIMMAN records not found (set SHIPGYM_MEASURED_DATA)",
)
def test_published_kvlcc2_turns_like_marin_and_under_predicts_its_overshoots() -> None:
    """The MMG KVLCC2 with the published coefficients (full scale) against MARIN's SIMMAN 2008
    free-running tests: its 35 deg advance and tactical diameter are within 8 % of the
    measured ones, and it under-predicts every zigzag overshoot (the known shortfall of these
    coefficients; docs/kvlcc2_simman.json holds all 17 zigzags)."""
    from shipgym.models import MMGParams
    from shipgym.models.mmg import KVLCC2_SCALE
    from shipgym.sysid import load

    ship = make_model("kvlcc2", MMGParams.kvlcc2().scaled(KVLCC2_SCALE))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tc = load(SIMMAN / "marin_kvlcc2" / "MARIN_FREE_KVLCC2_tc_-35_m.dat")
        zz = load(SIMMAN / "marin_kvlcc2" / "MARIN_FREE_KVLCC2_zz_20_m.dat")
    meas = mv.turning_quantities(tc.time, tc.x, tc.y, tc.psi, tc.delta, np.hypot(tc.u, tc.v))
    assert meas["side"] == "starboard"
    assert 2.8 < meas["advance"] / 320.0 < 3.3 and 3.0 < meas["tactical_diameter"] / 320.0 < 3.5
    sim = mv.turning_circle(ship, 35.0, "starboard")
    assert sim.advance == pytest.approx(meas["advance"], rel=0.08)
    assert sim.tactical_diameter == pytest.approx(meas["tactical_diameter"], rel=0.08)
    b = math.radians(20.0)
    mz = mv.zigzag_quantities(zz.time, zz.psi, zz.delta, b)
    z = mv.zigzag(ship, 20.0, 20.0, first=mz["first"])
    pz = mv.zigzag_quantities(z.series.time, z.series.psi, z.series.delta, b)
    assert 10.0 < mz["overshoot1_deg"] < 16.0
    assert pz["overshoot1_deg"] < mz["overshoot1_deg"]

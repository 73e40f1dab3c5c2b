"""Paths (seed 004 section 2.1) and LOS guidance (seed 004 eq. 9-10, Borhaug et al. 2008).

The LOS tests close the loop around a kinematic vehicle written here (not a ship model):
``p' = U (cos psi, sin psi) + v_c`` and ``psi' = ssa(chi_d - psi) / T``, so that the steady
states have closed forms. Closed-loop tests on the RVG model live elsewhere.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers.los import IntegralLOS, LOSGuidance
from controllers.paths import FilletPath, SplinePath, WaypointPath

L_SHAPE = [[0.0, 0.0], [300.0, 0.0], [300.0, 400.0]]
ZIGZAG = [[0.0, 0.0], [400.0, 100.0], [500.0, 500.0], [200.0, 700.0], [250.0, 1100.0]]


def _ssa(a):
    return np.mod(np.asarray(a) + np.pi, 2.0 * np.pi) - np.pi


def _simulate(guidance, p0, psi0, speed=5.0, current=(0.0, 0.0), t_end=1500.0, dt=0.5, tau=5.0):
    """Kinematic vehicle following ``guidance``; returns a dict of logged arrays."""
    p = np.array(p0, dtype=float)
    vc = np.array(current, dtype=float)
    psi, r = float(psi0), 0.0
    n = round(t_end / dt)
    log = {k: np.empty(n) for k in ("t", "n", "e", "along", "seg", "fin", "integ", "chi_p")}
    log["p"] = np.empty((n, 2))
    for k in range(n):
        t = k * dt
        chi_d = guidance.update(t, p, psi, r)
        log["t"][k], log["n"][k] = t, p[0]
        log["e"][k], log["along"][k] = guidance.cross_track_error, guidance.along_track
        log["seg"][k], log["fin"][k] = guidance.segment, guidance.finished
        log["integ"][k], log["chi_p"][k] = guidance.integrator, guidance.chi_p
        log["p"][k] = p
        r = float(_ssa(chi_d - psi)) / tau
        p = p + dt * (speed * np.array([math.cos(psi), math.sin(psi)]) + vc)
        psi += dt * r
    return log


def _brute_closest(path, pts, ds=0.02):
    s = np.linspace(0.0, path.length, int(path.length / ds) + 1)
    pp = path.point(s)
    d = np.hypot(pts[:, None, 0] - pp[None, :, 0], pts[:, None, 1] - pp[None, :, 1])
    return np.min(d, axis=1)


# ------------------------------------------------------------------------------ paths
def test_waypoint_path_length_and_geometry():
    straight = WaypointPath([[10.0, -5.0], [310.0, 395.0]])
    assert straight.length == pytest.approx(500.0)
    path = WaypointPath(L_SHAPE)
    assert path.length == pytest.approx(700.0)
    zig = WaypointPath(ZIGZAG)
    legs = np.hypot(*np.diff(np.array(ZIGZAG), axis=0).T)
    assert zig.length == pytest.approx(legs.sum())
    np.testing.assert_allclose(zig.point(zig.waypoint_s), ZIGZAG, atol=1e-9)
    # north leg then east leg; zero curvature; vectorised
    np.testing.assert_allclose(path.tangent_angle([0.0, 299.0, 301.0]), [0.0, 0.0, np.pi / 2])
    np.testing.assert_allclose(path.curvature(np.linspace(0, 700, 11)), 0.0)
    np.testing.assert_allclose(path.point(500.0), [300.0, 200.0])
    assert path.point(np.zeros((3, 4))).shape == (3, 4, 2)


def test_fillet_path_curvature_tangent_continuity_and_length():
    radius = 60.0
    path = FilletPath(ZIGZAG, radius)
    wp = np.array(ZIGZAG)
    diff = np.diff(wp, axis=0)
    legs = np.hypot(*diff.T)
    chi = np.arctan2(diff[:, 1], diff[:, 0])
    theta = _ssa(np.diff(chi))
    expected = legs.sum() - np.sum(2 * radius * np.tan(np.abs(theta) / 2) - radius * np.abs(theta))
    assert path.length == pytest.approx(expected, rel=1e-12)
    np.testing.assert_allclose(path.course_changes[1:-1], theta)

    s = np.linspace(0.0, path.length, 40001)
    ds = s[1]
    kappa = path.curvature(s)
    # only 0 (lines) and +-1/R (arcs); the arcs have the turn's sign and length R |theta|
    assert np.all(np.isclose(kappa, 0.0) | np.isclose(np.abs(kappa), 1.0 / radius))
    np.testing.assert_allclose(
        np.sum(np.abs(kappa) > 0) * ds, radius * np.sum(np.abs(theta)), rtol=1e-3
    )
    corner = path.waypoint_s[1:-1]  # arc middles
    np.testing.assert_allclose(path.curvature(corner), np.sign(theta) / radius)
    # position and tangent continuous, and the tangent is the direction of motion
    pts = path.point(s)
    step = np.diff(pts, axis=0)
    np.testing.assert_allclose(np.hypot(*step.T), ds, rtol=1e-6)
    chi_s = path.tangent_angle(s)
    assert np.max(np.abs(_ssa(np.diff(chi_s)))) <= ds / radius * (1 + 1e-9)
    chord = np.arctan2(step[:, 1], step[:, 0])
    mid_chi = chi_s[:-1] + 0.5 * _ssa(np.diff(chi_s))
    assert np.max(np.abs(_ssa(chord - mid_chi))) < 0.25 * ds / radius  # O(ds^2) at joints
    # the corner arc lies inside the corner: its middle is R (1/cos(theta/2) - 1) from it
    gap = np.hypot(*(path.point(corner) - wp[1:-1]).T)
    np.testing.assert_allclose(gap, radius * (1 / np.cos(theta / 2) - 1), rtol=1e-9)


def test_fillet_path_right_angle_closed_form():
    path = FilletPath(L_SHAPE, 100.0)  # 90 deg starboard turn
    assert path.length == pytest.approx(700.0 - 200.0 + 50.0 * np.pi)
    assert path.curvature(path.waypoint_s[1]) == pytest.approx(1.0 / 100.0)
    port = FilletPath([[0, 0], [300, 0], [300, -400]], 100.0)
    assert port.curvature(port.waypoint_s[1]) == pytest.approx(-1.0 / 100.0)


@pytest.mark.parametrize("kind", ["pchip", "cubic"])
def test_spline_passes_waypoints_and_is_arc_length_parametrised(kind):
    path = SplinePath(ZIGZAG, kind=kind)
    np.testing.assert_allclose(path.point(path.waypoint_s), ZIGZAG, atol=1e-8)
    assert path.waypoint_s[0] == 0.0 and path.waypoint_s[-1] == pytest.approx(path.length)
    assert np.all(np.diff(path.waypoint_s) > 0)
    s = np.linspace(0.0, path.length, 20001)
    pts = path.point(s)
    step = np.hypot(*np.diff(pts, axis=0).T)
    np.testing.assert_allclose(step, s[1], rtol=1e-5)  # unit speed in s
    assert np.sum(step) == pytest.approx(path.length, rel=1e-6)
    # tangent = direction of motion, curvature = d chi / ds
    chi = path.tangent_angle(s)
    chord = np.arctan2(*np.diff(pts, axis=0).T[::-1])
    assert np.max(np.abs(_ssa(chord - chi[:-1]))) < 1e-2
    dchi = _ssa(np.diff(chi)) / s[1]
    kappa = path.curvature(s)
    # PCHIP is only C1: skip the steps that straddle a waypoint (curvature jumps there)
    straddle = np.searchsorted(s, path.waypoint_s[1:-1]) - 1
    ok = np.isfinite(kappa[:-1]) & np.isfinite(kappa[1:])
    ok[np.clip(np.concatenate([straddle, straddle + 1]), 0, ok.size - 1)] = False
    np.testing.assert_allclose(dchi[ok], 0.5 * (kappa[:-1] + kappa[1:])[ok], atol=2e-4)


def test_pchip_through_collinear_points_is_straight():
    pts = [[0.0, 0.0], [30.0, 40.0], [150.0, 200.0], [240.0, 320.0]]
    path = SplinePath(pts, kind="pchip")
    assert path.length == pytest.approx(400.0, rel=1e-12)
    np.testing.assert_allclose(path.curvature(np.linspace(0, 400, 9)), 0.0, atol=1e-12)
    np.testing.assert_allclose(path.point(200.0), [120.0, 160.0])


@pytest.mark.parametrize(
    "path",
    [
        WaypointPath(ZIGZAG),
        FilletPath(ZIGZAG, 60.0),
        SplinePath(ZIGZAG, kind="pchip"),
        SplinePath(ZIGZAG, kind="cubic"),
    ],
    ids=["waypoint", "fillet", "pchip", "cubic"],
)
def test_closest_matches_brute_force(path):
    rng = np.random.default_rng(3)
    pts = rng.uniform([-150.0, -150.0], [650.0, 1250.0], size=(60, 2))
    s, e = path.closest(pts)
    d = np.hypot(*(pts - path.point(s)).T)
    brute = _brute_closest(path, pts)
    assert np.all(d <= brute + 1e-9)
    np.testing.assert_allclose(d, brute, atol=1e-2)
    # |e| <= distance; equal where the foot point is a smooth inner point (not an end and
    # not a corner of the polyline)
    assert np.all(np.abs(e) <= d + 1e-9)
    inner = (s > 1e-6) & (s < path.length - 1e-6)
    if isinstance(path, WaypointPath):
        inner &= np.min(np.abs(s[:, None] - path.waypoint_s[None, :]), axis=1) > 1e-6
    np.testing.assert_allclose(np.abs(e[inner]), d[inner], rtol=1e-6, atol=1e-6)
    # single point gives floats
    s0, e0 = path.closest(pts[0])
    assert isinstance(s0, float) and isinstance(e0, float)
    assert s0 == pytest.approx(s[0]) and e0 == pytest.approx(e[0])


def test_cross_track_sign_convention():
    north = WaypointPath([[0.0, 0.0], [1000.0, 0.0]])
    assert north.closest([500.0, 30.0]) == pytest.approx((500.0, 30.0))  # east: starboard
    assert north.closest([500.0, -30.0]) == pytest.approx((500.0, -30.0))
    east = FilletPath([[0.0, 0.0], [0.0, 1000.0]], 50.0)
    s, e = east.closest([-20.0, 400.0])  # south of an eastbound path: starboard
    assert (s, e) == pytest.approx((400.0, 20.0))
    curve = SplinePath([[0.0, 0.0], [500.0, 100.0], [1000.0, 0.0]], kind="cubic")
    assert curve.closest([500.0, 140.0])[1] > 0 > curve.closest([500.0, 60.0])[1]


def test_closest_with_hint_stays_on_its_branch():
    # a hairpin: two parallel legs 40 m apart
    path = FilletPath([[0.0, 0.0], [1000.0, 0.0], [1000.0, 40.0], [0.0, 40.0]], 20.0)
    p = [500.0, 15.0]  # 15 m from the outbound leg, 25 m from the return leg
    s_glob, e_glob = path.closest(p)
    assert s_glob == pytest.approx(500.0) and e_glob == pytest.approx(15.0)
    s_back = path.length - 500.0  # station abeam on the return leg
    s_hint, e_hint = path.closest(p, s_hint=s_back - 10.0, window=50.0)
    assert s_hint == pytest.approx(s_back) and e_hint == pytest.approx(25.0)


def test_path_input_validation():
    with pytest.raises(ValueError, match="at least two"):
        WaypointPath([[0.0, 0.0]])
    with pytest.raises(ValueError, match="shape"):
        WaypointPath([0.0, 1.0, 2.0])
    with pytest.raises(ValueError, match="not finite"):
        WaypointPath([[0.0, 0.0], [np.nan, 1.0]])
    with pytest.raises(ValueError, match="coincide"):
        SplinePath([[0.0, 0.0], [1.0, 1.0], [1.0, 1.0], [2.0, 0.0]])
    with pytest.raises(ValueError, match="numbers"):
        WaypointPath([["a", "b"], [1, 2]])
    with pytest.raises(ValueError, match="corner at waypoint 1"):
        FilletPath(L_SHAPE, 350.0)
    with pytest.raises(ValueError, match="reverses"):
        FilletPath([[0, 0], [100, 0], [50, 0]], 10.0)
    with pytest.raises(ValueError, match="turning_radius"):
        FilletPath(L_SHAPE, -1.0)
    with pytest.raises(ValueError, match="kind"):
        SplinePath(L_SHAPE, kind="linear")
    path = WaypointPath(L_SHAPE)
    with pytest.raises(ValueError, match="arc length"):
        path.point(701.0)
    with pytest.raises(ValueError, match="finite"):
        path.closest([np.inf, 0.0])


# ------------------------------------------------------------------------------ LOS
NORTH = WaypointPath([[0.0, 0.0], [20000.0, 0.0]])
U, VC, DELTA = 5.0, 1.0, 100.0  # speed, cross current to the east, lookahead


def test_los_sign_steers_back_to_the_path():
    los = LOSGuidance(NORTH, DELTA, integral=False)
    assert los.update(0.0, (100.0, 100.0)) == pytest.approx(-math.pi / 4)  # east: steer west
    assert los.update(1.0, (100.0, -50.0)) == pytest.approx(math.atan(0.5))
    assert los.cross_track_error == pytest.approx(-50.0) and los.chi_p == 0.0
    ilos = IntegralLOS(NORTH, DELTA)
    assert ilos.update(0.0, (100.0, 100.0)) == pytest.approx(-math.pi / 4)


def test_proportional_los_leaves_the_closed_form_error_in_current():
    log = _simulate(
        LOSGuidance(NORTH, DELTA, integral=False),
        (0.0, -50.0),
        0.3,
        speed=U,
        current=(0.0, VC),
        t_end=800.0,
    )
    e_ss = DELTA * VC / math.sqrt(U**2 - VC**2)
    assert log["e"][-1] == pytest.approx(e_ss, rel=0.1)
    assert np.ptp(log["e"][-100:]) < 0.01 * e_ss  # settled
    assert np.all(log["integ"] == 0.0)


@pytest.mark.parametrize(
    "make",
    [
        lambda: LOSGuidance(NORTH, DELTA),
        lambda: IntegralLOS(NORTH, DELTA),
    ],
    ids=["conditional", "ilos"],
)
def test_integral_action_removes_the_current_offset(make):
    guidance = make()
    log = _simulate(guidance, (0.0, -50.0), 0.3, speed=U, current=(0.0, VC), t_end=1500.0)
    assert np.max(np.abs(log["e"][-200:])) < 0.1
    crab = VC / math.sqrt(U**2 - VC**2)  # tan of the crab angle
    if isinstance(guidance, LOSGuidance):
        assert guidance.integrator == pytest.approx(crab, rel=1e-3)
    else:
        assert guidance.sigma * guidance.integrator / DELTA == pytest.approx(crab, rel=1e-3)


def test_conditional_integrator_freezes_beyond_e_lim_and_r_lim():
    ki = 1e-3
    los = LOSGuidance(NORTH, DELTA, ki=ki, e_lim=20.0, r_lim=0.01)
    for k in range(50):  # 30 m off: |e| > e_lim
        los.update(float(k), (10.0 * k, 30.0), 0.0, 0.0)
        assert los.integrator == 0.0 and los.integrator_mode == "frozen"
    for k in range(50, 100):  # 10 m off but turning: |r| > r_lim
        los.update(float(k), (10.0 * k, 10.0), 0.0, -0.02)
        assert los.integrator == 0.0 and los.integrator_mode == "frozen"
    los.update(100.0, (1000.0, 10.0), 0.0, 0.005)  # both conditions met: integrates
    assert los.integrator_mode == "linear"
    assert los.integrator == pytest.approx(ki * 10.0 * 1.0)
    chi = los.update(102.0, (1020.0, 10.0), 0.0, 0.0)
    assert los.integrator == pytest.approx(ki * 10.0 * 3.0)
    assert chi == pytest.approx(-math.atan(10.0 / DELTA + los.integrator))
    ablated = LOSGuidance(NORTH, DELTA, integral=False)
    for k in range(10):
        chi = ablated.update(float(k), (10.0 * k, 10.0), 0.0, 0.0)
    assert ablated.integrator == 0.0 and ablated.integrator_mode == "off"
    assert chi == pytest.approx(-math.atan(0.1))


def test_conditional_integrator_soft_saturation_and_hard_bound():
    ki, e, i_max, k1, k2 = 1e-3, 10.0, 0.3, 1.0, 2.0
    los = LOSGuidance(NORTH, DELTA, ki=ki, e_lim=50.0, i_max=i_max, k1=k1, k2=k2, i_hard=0.5)
    t, hist = 0.0, []
    for _ in range(200):
        los.update(t, (t, e), 0.0, 0.0)
        hist.append((los.integrator, los.integrator_mode))
        t += 1.0
    integ = np.array([h[0] for h in hist])
    rate = np.diff(integ)
    below = integ[:-1] <= i_max
    np.testing.assert_allclose(rate[below], ki * e)  # linear
    over = (integ[:-1] > i_max) & (integ[1:] < 0.5)
    assert over.sum() > 5
    # e_i = e / (k1 + k2 |I| / I_max) with I before the step
    np.testing.assert_allclose(rate[over], ki * e / (k1 + k2 * integ[:-1][over] / i_max))
    assert np.all(rate[over] <= ki * e / (k1 + k2) * (1 + 1e-12))
    assert rate[over][-1] < 0.8 * rate[over][0]  # slower and slower
    assert np.max(integ) == pytest.approx(0.5) and np.all(integ <= 0.5)  # hard bound
    assert any(m == "soft" for _, m in hist)
    # a negative error unwinds at the full rate even beyond I_max
    i_before = los.integrator
    los.update(t, (t, -e), 0.0, 0.0)
    assert los.integrator_mode == "linear"
    assert los.integrator == pytest.approx(i_before - ki * e)


@pytest.mark.parametrize("switching", ["circle", "along_track"])
def test_waypoint_switching_and_finished(switching):
    path = WaypointPath([[0.0, 0.0], [500.0, 0.0], [500.0, 600.0], [1200.0, 600.0]])
    radius = 60.0
    los = LOSGuidance(path, 80.0, switching=switching, acceptance_radius=radius)
    log = _simulate(los, (0.0, 20.0), 0.0, speed=5.0, t_end=600.0)
    seg = log["seg"].astype(int)
    assert set(np.unique(seg)) == {0, 1, 2}
    assert np.all(np.diff(seg) >= 0)
    wp = path.waypoints
    for k in (1, 2):
        i = int(np.argmax(seg == k))  # first sample on leg k
        p_now, p_before = log["p"][i], log["p"][i - 1]
        if switching == "circle":
            assert np.hypot(*(p_now - wp[k])) <= radius < np.hypot(*(p_before - wp[k]))
        else:
            chi = path.leg_angles[k - 1]
            u = np.array([math.cos(chi), math.sin(chi)])
            leg = path.leg_lengths[k - 1]
            assert (p_now - wp[k - 1]) @ u >= leg > (p_before - wp[k - 1]) @ u
    fin = log["fin"].astype(bool)
    assert fin[-1] and not fin[0]
    first = int(np.argmax(fin))
    assert np.all(fin[first:])  # latched
    end = log["p"][first]
    if switching == "circle":
        assert np.hypot(*(end - wp[-1])) <= radius
    else:
        assert log["along"][first] >= path.length > log["along"][first - 1]
    assert np.all(log["chi_p"][seg == 2] == 0.0)
    assert los.segment == 2
    # after the end it keeps to the extension of the last leg
    assert abs(log["e"][-1]) < 1.0


@pytest.mark.parametrize(
    "path",
    [
        FilletPath(ZIGZAG, 80.0),
        SplinePath(ZIGZAG, kind="cubic"),
    ],
    ids=["fillet", "cubic"],
)
def test_los_on_continuous_paths(path):
    los = LOSGuidance(path, 60.0, r_lim=0.005)
    log = _simulate(los, (0.0, 0.0), 0.2, speed=4.0, t_end=500.0, dt=1.0, tau=3.0)
    along = log["along"]
    assert np.all(np.diff(along[along < path.length]) >= -1e-9)  # monotone progress
    fin = log["fin"].astype(bool)
    assert fin[-1] and not fin[0]
    seg = log["seg"].astype(int)
    assert np.all(np.diff(seg) >= 0) and seg[-1] == len(ZIGZAG) - 2
    # once aligned (no current) it stays within a lookahead-and-lag sized band in the bends
    # (U / R = 0.05 rad/s against a 3 s heading lag: about Delta tan(0.15) = 9 m) and is
    # close to the path at its end (the cubic spline still curves there)
    assert np.max(np.abs(log["e"][30:])) < 15.0
    assert abs(log["e"][int(np.argmax(fin))]) < 2.0


def test_los_input_validation():
    with pytest.raises(ValueError, match="lookahead"):
        LOSGuidance(NORTH, 0.0)
    with pytest.raises(ValueError, match="switching"):
        LOSGuidance(NORTH, 100.0, switching="nearest")
    with pytest.raises(ValueError, match="k1 \\+ k2"):
        LOSGuidance(NORTH, 100.0, k1=0.2, k2=0.3)
    with pytest.raises(ValueError, match="i_hard"):
        LOSGuidance(NORTH, 100.0, i_max=0.3, i_hard=0.1)
    with pytest.raises(ValueError, match="path"):
        IntegralLOS([[0, 0], [1, 1]], 100.0)
    with pytest.raises(ValueError, match="sigma"):
        IntegralLOS(NORTH, 100.0, sigma=-1.0)
    los = LOSGuidance(NORTH, 100.0)
    los.update(5.0, (0.0, 0.0))
    with pytest.raises(ValueError, match="decrease"):
        los.update(4.0, (0.0, 0.0))
    with pytest.raises(ValueError, match="position"):
        los.update(6.0, (np.nan, 0.0))
    with pytest.raises(ValueError, match="r must be a finite number, got inf"):
        los.update(6.0, (0.0, 0.0), 0.0, np.inf)
    los.reset()
    assert los.update(0.0, (0.0, 0.0)) == 0.0 and not los.finished

"""LOS guidance and constant-bearing target tracking on a batch of ships.

Every row of a batch must give bitwise the floats of the same ship guided alone, and both must
give bitwise what the one-ship implementation gave before the laws ran on arrays.

``data/guidance_golden.npz`` holds that reference. It was made by running the scalar
implementation of commit 0868dfb (``controllers/los.py``, ``target.py``, ``paths.py`` and
``_angles.py`` of that commit, copied aside) with the constructor arguments of
:data:`LOS_CONFIGS` and :data:`CB_CONFIGS` below, one ship at a time, in closed loop around a
kinematic ship, seeded with ``numpy.random.default_rng([2804, ...])``:

* LOS: 3 ships, each on its own random :class:`WaypointPath` (3, 4 and 5 waypoints, legs of
  400-700 m, turns up to 97 degrees; ``FilletPath(..., 60)`` of the same waypoints for
  ``los_fillet``), lookahead 120 m, 100 updates at random intervals of 3.5-6.5 s (one time
  grid for the three ships). The ship sails at 5 m/s plus a random current of 0.3-1.3 m/s
  (so the integrators work and, in ``los_limits``, reach ``i_hard`` and the soft
  saturation), its heading follows ``chi_d`` with ``r = ssa(chi_d - psi) / 6 s`` clipped to
  0.04 rad/s; the guidance gets the position with 0.3 m of noise and ``r`` with 0.002 rad/s.
  The ships start near their first waypoint, pass every waypoint and most finish.
* Constant bearing: 3 ships holding 0, 50 and 200 m from a target at up to 3 m/s on a slowly
  turning course; the ship's velocity follows the command with a 15 s lag; positions with
  0.5 m of noise; updates at random intervals of 1.75-4.3 s (``cb_clock``: ``t=None``, the
  nominal 2 s). At update 20 the ship is on the target (the bearing is undefined), at 45 on a
  still target and at 70 exactly at the aim point of a still target (the course is held);
  ``cb_estimated`` and ``cb_clock`` difference the target positions.

The file stores what the guidance was given (times, positions, yaw rates, targets, initial
courses) and everything it returned and reported at each update. Nothing is regenerated here.

A batch row and its ship alone must agree bit for bit in the same run. Against the file, the
segments, flags and modes must match exactly and the floats to 1e-12. The file was made on a
CPU whose numpy computes arctangents with AVX-512 code; with AVX2 they can differ in the last
bit (measured: 45 of 300 courses 1 ulp apart).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from controllers.los import INTEGRATOR_MODES, IntegralLOS, LOSGuidance
from controllers.paths import FilletPath, SplinePath, WaypointPath
from controllers.target import ConstantBearingGuidance

GOLDEN = Path(__file__).parent / "data" / "guidance_golden.npz"

#: name: (law, keyword arguments, path kind) of the LOS runs in the golden file
LOS_CONFIGS = {
    "los_circle": (LOSGuidance, {"switching": "circle", "acceptance_radius": 60.0}, "waypoint"),
    "los_along": (LOSGuidance, {"switching": "along_track"}, "waypoint"),
    "pure_along": (LOSGuidance, {"integral": False}, "waypoint"),
    "los_limits": (
        LOSGuidance,
        {
            "ki": 4e-4,
            "i_max": 0.08,
            "i_hard": 0.12,
            "k1": 0.5,
            "k2": 1.5,
            "e_lim": 60.0,
            "r_lim": 0.01,
            "switching": "circle",
            "acceptance_radius": 80.0,
        },
        "waypoint",
    ),
    "ilos_circle": (IntegralLOS, {"switching": "circle"}, "waypoint"),
    "los_fillet": (LOSGuidance, {"r_lim": 0.02}, "fillet"),
}
#: name: (keyword arguments, target velocity given, t=None) of the constant-bearing runs
CB_CONFIGS = {
    "cb_given": ({"max_approach_speed": 2.0, "delta": 100.0, "max_speed": 6.0, "dt": 1.0}, True,
                 False),
    "cb_estimated": ({"max_approach_speed": 2.5, "delta": 80.0, "min_speed": 1.0,
                      "max_speed": 3.0, "dt": 1.0}, False, False),
    "cb_clock": ({"max_approach_speed": 1.5, "delta": 150.0, "dt": 2.0}, False, True),
}  # fmt: skip
LOS_READOUTS = ("chi_d", "e", "along", "chi_p", "chi_r", "integ", "integ_in", "seg", "fin", "mode")
CB_READOUTS = ("chi_d", "u_d", "v_d", "v_a", "aim", "range", "range_error")


@pytest.fixture(scope="module")
def golden() -> dict[str, np.ndarray]:
    with np.load(GOLDEN) as data:
        return dict(data)


def _los_paths(golden: dict[str, np.ndarray], kind: str) -> list:
    counts = golden["n_waypoints"]
    wps = [golden["waypoints"][i, : counts[i]] for i in range(counts.size)]
    if kind == "fillet":
        return [FilletPath(w, 60.0) for w in wps]
    return [WaypointPath(w) for w in wps]


def _los_readouts(g: LOSGuidance | IntegralLOS, chi: object) -> tuple:
    is_los = isinstance(g, LOSGuidance)
    return (
        chi, g.cross_track_error, g.along_track, g.chi_p, g.chi_r, g.integrator,
        g.integrator_input if is_los else np.full(np.shape(chi), np.nan),
        g.segment, g.finished,
        g.integrator_mode_code if is_los else np.full(np.shape(chi), -1),
    )  # fmt: skip


def _assert_bitwise(got: np.ndarray, want: np.ndarray, what: str) -> None:
    got = np.asarray(got)
    assert got.shape == want.shape, what
    np.testing.assert_array_equal(got, want, err_msg=what, strict=True)


def _assert_reference(got: np.ndarray, want: np.ndarray, what: str) -> None:
    """``got`` is the file's ``want``: exactly for integers and flags, to 1e-12 for floats
    (module docstring)."""
    got = np.asarray(got)
    assert got.shape == want.shape and got.dtype == want.dtype, what
    if want.dtype.kind == "f":
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12, err_msg=what)
    else:
        np.testing.assert_array_equal(got, want, err_msg=what, strict=True)


@pytest.mark.parametrize("name", list(LOS_CONFIGS))
def test_los_reproduces_the_one_ship_code_alone_and_in_a_batch(golden, name: str) -> None:
    cls, kwargs, kind = LOS_CONFIGS[name]
    t, p, r = golden[f"{name}/t"], golden[f"{name}/p"], golden[f"{name}/r"]
    paths = _los_paths(golden, kind)
    n, steps = r.shape
    alone = []
    for i in range(n):
        g = cls(paths[i], 120.0, **kwargs)
        rows = []
        for k in range(steps):
            chi = g.update(t[k], p[i, k], 0.0, r[i, k])
            assert type(chi) is float
            rows.append(_los_readouts(g, chi))
        alone.append(rows)
    batch = cls(paths, 120.0, **kwargs)
    together = [
        _los_readouts(batch, batch.update(t[k], p[:, k], 0.0, r[:, k])) for k in range(steps)
    ]
    for j, key in enumerate(LOS_READOUTS):
        want = golden[f"{name}/{key}"]
        one = np.array([[row[j] for row in rows] for rows in alone], dtype=want.dtype)
        _assert_reference(one, want, f"{name} {key}, ships alone")
        _assert_bitwise(np.stack([row[j] for row in together], axis=1).astype(want.dtype), one,
                        f"{name} {key}, batch")  # fmt: skip
    # the runs cover what they are meant to: switching, finishing, the integrator's modes
    assert np.all(golden[f"{name}/seg"][:, -1] == golden["n_waypoints"] - 2)
    assert golden[f"{name}/fin"][:, -1].any()
    if name == "los_limits":
        modes = set(golden[f"{name}/mode"].ravel().tolist())
        assert modes == {INTEGRATOR_MODES.index(m) for m in ("frozen", "soft", "linear")}
        assert np.max(np.abs(golden[f"{name}/integ"])) == 0.12  # the hard bound


@pytest.mark.parametrize("name", list(CB_CONFIGS))
def test_constant_bearing_reproduces_the_one_ship_code_alone_and_in_a_batch(
    golden, name: str
) -> None:
    kwargs, given, t_none = CB_CONFIGS[name]
    t, p, pt, vt = (golden[f"{name}/{k}"] for k in ("t", "p", "pt", "vt"))
    distance, course0 = golden[f"{name}/distance"], golden[f"{name}/course0"]
    n, steps = p.shape[:2]

    def step(g, k, rows):
        chi, u = g.update(None if t_none else t[k], p[rows, k], pt[rows, k],
                          vt[rows, k] if given else None)  # fmt: skip
        return (chi, u, g.desired_velocity, g.approach_velocity, g.aim_point, g.range,
                g.range_error)  # fmt: skip

    alone = []
    for i in range(n):
        g = ConstantBearingGuidance(distance=float(distance[i]), **kwargs)
        g.reset(course=float(course0[i]))
        alone.append([step(g, k, i) for k in range(steps)])
        assert type(alone[-1][0][0]) is float and type(alone[-1][0][1]) is float
    batch = ConstantBearingGuidance(distance=distance, **kwargs)
    batch.reset(course=course0)
    together = [step(batch, k, slice(None)) for k in range(steps)]
    for j, key in enumerate(CB_READOUTS):
        want = golden[f"{name}/{key}"]
        one = np.array([[row[j] for row in rows] for rows in alone])
        _assert_reference(one, want, f"{name} {key}, ships alone")
        _assert_bitwise(
            np.stack([row[j] for row in together], axis=1), one, f"{name} {key}, batch"
        )
    if given:  # the special updates: on the target, and the course held at the aim point
        assert np.all(golden[f"{name}/range"][:, 20] == 0.0)
        held = np.hypot(*np.moveaxis(golden[f"{name}/v_d"][:, 70], -1, 0)) == 0.0
        assert held.all()
        np.testing.assert_array_equal(
            golden[f"{name}/chi_d"][:, 70], golden[f"{name}/chi_d"][:, 69]
        )


def _random_paths(rng: np.random.Generator, counts: list[int]) -> list[WaypointPath]:
    paths = []
    for m in counts:
        heading = np.cumsum(rng.uniform(-1.5, 1.5, m - 1))
        legs = rng.uniform(100.0, 300.0, m - 1)[:, None] * np.stack(
            [np.cos(heading), np.sin(heading)], 1
        )
        paths.append(WaypointPath(np.vstack([[0.0, 0.0], np.cumsum(legs, axis=0)])))
    return paths


@pytest.mark.parametrize(
    ("cls", "kwargs"),
    [
        (LOSGuidance, {"switching": "circle", "acceptance_radius": 40.0}),
        (LOSGuidance, {"switching": "along_track", "r_lim": math.inf, "e_lim": math.inf}),
        (IntegralLOS, {"switching": "along_track"}),
    ],
    ids=["los-circle", "los-along", "ilos"],
)
def test_a_batch_equals_its_rows_run_as_batches_of_one(cls, kwargs) -> None:
    """Paths of 2 to 8 waypoints; ships along them at different paces (the ship on the path
    of 8 waypoints passes more than one waypoint in some updates), then past their ends."""
    rng = np.random.default_rng(7)
    paths = _random_paths(rng, [2, 5, 8, 3, 6])
    n = len(paths)
    steps_to_end = np.array([30, 25, 6, 20, 35])
    batch = cls(paths, 50.0, **kwargs)
    singles = [cls([path], 50.0, **kwargs) for path in paths]
    for k in range(45):
        pos = np.empty((n, 2))
        for i, path in enumerate(paths):
            s = k / steps_to_end[i] * path.length
            end, chi_end = path.waypoints[-1], path.leg_angles[-1]
            beyond = max(s - path.length, 0.0) * np.array([math.cos(chi_end), math.sin(chi_end)])
            pos[i] = (path.point(s) if s <= path.length else end + beyond) + rng.normal(0, 8, 2)
        r = rng.normal(0.0, 0.01, n)
        chi = batch.update(2.0 * k, pos, rng.normal(0.0, 1.0, n), r)
        assert chi.shape == (n,) and chi.dtype == np.float64
        for i, single in enumerate(singles):
            one = single.update(2.0 * k, pos[i : i + 1], 0.0, r[i : i + 1])
            assert one.shape == (1,)
            for got, want in zip(
                _los_readouts(batch, chi), _los_readouts(single, one), strict=True
            ):
                np.testing.assert_array_equal(np.asarray(got)[i], np.asarray(want)[0])
    last = [len(path.waypoints) - 2 for path in paths]
    reached = batch.segment == last
    assert reached.sum() >= 4 and batch.finished.tolist() == reached.tolist()
    if kwargs["switching"] == "along_track":
        assert reached.all()


def test_batch_readouts_are_arrays_and_stay_as_they_were_read() -> None:
    paths = [WaypointPath([[0.0, 0.0], [1000.0, 0.0]]), WaypointPath([[0.0, 0.0], [0.0, 500.0]])]
    los = LOSGuidance(paths, 100.0, e_lim=50.0)
    chi = los.update(0.0, [[0.0, 100.0], [10.0, 20.0]], 0.0, [0.0, 0.02])
    np.testing.assert_allclose(chi, [-math.pi / 4, math.pi / 2 + math.atan(0.1)])
    assert los.integrator_mode.tolist() == ["frozen", "frozen"]  # |e| > e_lim; |r| > r_lim
    assert los.integrator_mode_code.tolist() == [INTEGRATOR_MODES.index("frozen")] * 2
    e, seg, fin = los.cross_track_error, los.segment, los.finished
    np.testing.assert_allclose(e, [100.0, -10.0])
    assert seg.dtype.kind == "i" and fin.dtype == bool and los.path == tuple(paths)
    los.update(1.0, [[600.0, 0.0], [0.0, 600.0]], 0.0, 0.0)
    np.testing.assert_allclose(e, [100.0, -10.0])  # the earlier read-out was not overwritten
    assert not fin.any() and los.finished.tolist() == [False, True]
    assert los.integrator_mode.tolist() == ["linear", "linear"]
    # one path: Python scalars, as before
    one = LOSGuidance(paths[0], 100.0)
    assert type(one.update(0.0, (0.0, 100.0))) is float
    assert type(one.segment) is int and type(one.finished) is bool
    assert type(one.integrator_mode) is str and type(one.integrator) is float


def test_continuous_paths_in_a_batch_follow_each_ship_with_the_one_ship_code() -> None:
    zigzag = [[0.0, 0.0], [400.0, 100.0], [500.0, 500.0], [200.0, 700.0]]
    paths = [FilletPath(zigzag, 80.0), SplinePath(zigzag, kind="pchip")]
    batch = LOSGuidance(paths, 60.0)
    singles = [LOSGuidance(path, 60.0) for path in paths]
    rng = np.random.default_rng(3)
    for k in range(25):
        pos = np.array([path.point(min(40.0 * k, path.length)) for path in paths])
        pos += rng.normal(0.0, 15.0, pos.shape)
        chi = batch.update(float(k), pos, 0.0, 0.0)
        for i, single in enumerate(singles):
            assert single.update(float(k), pos[i]) == chi[i]
            assert single.along_track == batch.along_track[i]
            assert single.segment == batch.segment[i]


def test_constant_bearing_batch_rows_and_distances() -> None:
    rng = np.random.default_rng(11)
    n = 4
    distance = np.array([0.0, 25.0, 80.0, 300.0])
    batch = ConstantBearingGuidance(1.5, 90.0, distance, min_speed=0.5, max_speed=4.0)
    singles = [
        ConstantBearingGuidance(1.5, 90.0, d, min_speed=0.5, max_speed=4.0) for d in distance
    ]
    target = rng.uniform(-500.0, 500.0, (n, 2))
    ship = np.zeros((n, 2))
    for k in range(30):
        target += 2.0  # one array, moved in place between the updates
        chi, u = batch.update(float(k), ship, target)  # target velocity from the positions
        assert chi.shape == u.shape == (n,) and batch.desired_velocity.shape == (n, 2)
        for i, single in enumerate(singles):
            assert single.update(float(k), ship[i], target[i].copy()) == (chi[i], u[i])
        ship = ship + batch.desired_velocity
    np.testing.assert_allclose(batch.desired_velocity - batch.approach_velocity, 2.0)
    np.testing.assert_array_equal(batch.range_error, batch.range - distance)
    assert batch.distance.tolist() == distance.tolist() and batch.n_ships == n


def test_errors_name_the_bad_value_and_the_expected_shape() -> None:
    north = WaypointPath([[0.0, 0.0], [1000.0, 0.0]])
    with pytest.raises(ValueError, match="at least one path"):
        LOSGuidance([], 100.0)
    with pytest.raises(ValueError, match=r"path\[1\] must be a controllers.paths.Path.*got list"):
        LOSGuidance([north, [[0, 0], [1, 1]]], 100.0)
    with pytest.raises(ValueError, match=r"only WaypointPaths or only continuous.*FilletPath at 1"):
        IntegralLOS([north, FilletPath([[0, 0], [100, 0], [100, 100]], 10.0)], 100.0)
    los = LOSGuidance([north] * 4, 100.0)
    with pytest.raises(ValueError, match=r"^position has shape \(4, 3\), expected \(4, 2\)$"):
        los.update(0.0, np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"^r has shape \(3,\), expected \(4,\) or a number$"):
        los.update(0.0, np.zeros((4, 2)), 0.0, np.zeros(3))
    with pytest.raises(ValueError, match=r"^r\[2\] must be a finite number, got nan$"):
        los.update(0.0, np.zeros((4, 2)), 0.0, [0.0, 0.0, np.nan, 0.0])
    with pytest.raises(ValueError, match=r"^position\[1, 1\] must be a finite number, got inf$"):
        los.update(0.0, [[0.0, 0.0], [0.0, np.inf], [0.0, 0.0], [0.0, 0.0]])
    with pytest.raises(ValueError, match=r"^psi has shape \(2, 2\), expected \(4,\) or a number$"):
        los.update(0.0, np.zeros((4, 2)), np.zeros((2, 2)))
    with pytest.raises(
        ValueError, match=r"^position has shape \(1, 2\), expected \(2,\): the controller runs one"
    ):
        LOSGuidance(north, 100.0).update(0.0, np.zeros((1, 2)))
    with pytest.raises(ValueError, match=r"distance must be a number or a 1-D array.*\(2, 2\)"):
        ConstantBearingGuidance(1.0, 100.0, np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"^distance\[1\] must be >= 0 \[m\], got -5.0$"):
        ConstantBearingGuidance(1.0, 100.0, [10.0, -5.0])
    with pytest.raises(ValueError, match=r"^distance\[0\] must be a finite number, got nan$"):
        ConstantBearingGuidance(1.0, 100.0, [np.nan, 5.0])
    cb = ConstantBearingGuidance(1.0, 100.0, [10.0, 20.0, 30.0])
    with pytest.raises(
        ValueError, match=r"^target_position has shape \(2,\), expected \(3, 2\)$"
    ):
        cb.update(0.0, np.zeros((3, 2)), [0.0, 0.0])
    with pytest.raises(ValueError, match=r"^course has shape \(2,\), expected \(3,\) or a number$"):
        cb.reset(course=[0.0, 1.0])


def test_the_guidance_keeps_a_copy_of_the_target_position() -> None:
    """Changing the caller's array after an update leaves the velocity estimate alone."""
    cb = ConstantBearingGuidance(1.0, 100.0, [10.0, 20.0])
    ships = np.zeros((2, 2))
    target = np.array([[500.0, 0.0], [0.0, 500.0]])
    cb.update(0.0, ships, target)
    target += 3.0  # moved in place: 3 m in 1 s
    cb.update(1.0, ships, target)
    alone = ConstantBearingGuidance(1.0, 100.0, [10.0, 20.0])
    alone.update(0.0, ships, target - 3.0)
    alone.update(1.0, ships, target, np.full((2, 2), 3.0))
    np.testing.assert_array_equal(cb.desired_velocity, alone.desired_velocity)

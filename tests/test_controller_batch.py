"""The heading and speed autopilots on a batch of ships (arrays) and on one ship.

One ship is a batch of one of the same code, and every row of a batch must be, bit for bit,
what the scalar autopilot of the same ship gives. ``tests/data/controller_batch_golden.npz``
pins the numbers: it holds the inputs of every case below (:func:`make_inputs`) and the
commands and error integrals of the scalar autopilots as they were before they took arrays
(the pure-Python-float implementation), written by running :func:`run_heading` and
:func:`run_speed` of this module one ship at a time (``rows`` an ``int``) on those inputs and
saving the results under the keys ``{case}/command`` and ``{case}/integral``. The tests only
read that file; they regenerate nothing.

The cases cover each anti-windup mode, the command and rate limits, the reference model with
its rate and acceleration limits (and several substeps per step), the yaw-rate cascade of an
unstable ship, the Nomoto feed-forward, ``keep_offset``, the first update without a reset,
``t=None`` steps, zero-length steps, unwrapped headings many turns away from the setpoint,
and for the speed autopilot the drag and linear feed-forwards with a speed-dependent limit.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from controllers import (
    HeadingAutopilot,
    HeadingReferenceModel,
    SpeedAutopilot,
    linear_feedforward,
    linearised_drag_model,
    quadratic_drag_feedforward,
    ssa,
)
from controllers._angles import ssa_array

GOLDEN = Path(__file__).parent / "data" / "controller_batch_golden.npz"
SHIPS, STEPS = 3, 24
RUDDER_MAX, RUDDER_RATE = math.radians(35.0), math.radians(2.32)
AZ_MAX, AZ_RATE = math.radians(35.0), math.radians(10.0)
#: Gunnerus surge: mass with added mass [kg], damping d1 [N s/m], d2 [N s^2/m^2]
SURGE_MASS, D1, D2 = 450_000.0, 1117.6, 1671.6


def thrust_limit(u: Any) -> Any:
    """A per-pod thrust limit [N] that falls with the speed ``u`` [m/s] (array-safe)."""
    return 25_000.0 * np.minimum(np.maximum(1.0 - 0.9 * u / 8.0, 0.0), 1.0)


#: name -> (factory, options); options: "times" (False: t=None steps), "initial_reset"
#: (False: the first update starts the autopilot), "reset_command" (the actuator's command
#: given to reset), "mid_reset" (a reset with keep_offset=True half way)
HEADING_CASES: dict[str, tuple[Callable[[], HeadingAutopilot], dict[str, bool]]] = {
    "mariner_back_calculation": (
        lambda: HeadingAutopilot.from_nomoto(
            0.185, 107.3, 0.5, omega_n=0.05, max_command=RUDDER_MAX, max_rate=RUDDER_RATE
        ),
        {"reset_command": True},
    ),
    "mariner_unlimited": (
        lambda: HeadingAutopilot.from_nomoto(0.185, 107.3, 0.5, omega_n=0.05),
        {"reset_command": True},
    ),
    "mariner_conditional": (
        lambda: HeadingAutopilot.from_nomoto(
            0.185,
            107.3,
            0.5,
            omega_n=0.05,
            max_command=RUDDER_MAX,
            max_rate=RUDDER_RATE,
            anti_windup="conditional",
        ),
        {},
    ),
    "mariner_none": (
        lambda: HeadingAutopilot.from_nomoto(
            0.185,
            107.3,
            0.5,
            omega_n=0.05,
            max_command=RUDDER_MAX,
            max_rate=RUDDER_RATE,
            anti_windup="none",
        ),
        {"reset_command": True},
    ),
    "unstable_cascade": (
        lambda: HeadingAutopilot.from_nomoto(
            0.0761,
            -5.57,
            0.5,
            omega_n=0.3,
            reference_omega=0.05,
            max_turn_rate=0.02,
            max_turn_accel=0.002,
            max_command=AZ_MAX,
            max_rate=AZ_RATE,
        ),
        {"reset_command": True},
    ),
    "nomoto_feedforward_substeps": (
        lambda: HeadingAutopilot.from_nomoto(
            -0.185,
            107.3,
            0.5,
            omega_n=0.1,
            reference_omega=0.3,
            max_turn_rate=0.05,
            max_command=RUDDER_MAX,
            offset=0.01,
            nomoto_feedforward=True,
        ),
        {},
    ),
    "no_reference_first_update": (
        lambda: HeadingAutopilot(
            2.0, 0.05, 20.0, 0.5, max_command=0.5, max_rate=0.05, offset=-0.02
        ),
        {"times": False, "initial_reset": False},
    ),
    "keep_offset": (
        lambda: HeadingAutopilot.from_nomoto(
            0.185,
            107.3,
            0.5,
            omega_n=0.08,
            max_command=RUDDER_MAX,
            max_rate=RUDDER_RATE,
            offset=0.003,
        ),
        {"reset_command": True, "mid_reset": True},
    ),
}

_K_SURGE, _T_SURGE = linearised_drag_model(SURGE_MASS, D1, D2, 5.0, share=0.5)
SPEED_CASES: dict[str, tuple[Callable[[], SpeedAutopilot], dict[str, bool]]] = {
    "drag_feedforward_thrust_limit": (
        lambda: SpeedAutopilot.from_first_order(
            _K_SURGE,
            _T_SURGE,
            0.5,
            omega_n=0.1,
            feedforward=quadratic_drag_feedforward(D1, D2, share=0.5),
            min_command=0.0,
            max_command=thrust_limit,
            max_rate=3000.0,
        ),
        {},
    ),
    "linear_unlimited": (
        lambda: SpeedAutopilot(0.8, 0.2, 0.5, feedforward=linear_feedforward(2.0)),
        {"reset_command": True},
    ),
    "linear_conditional": (
        lambda: SpeedAutopilot(
            0.8,
            0.2,
            0.5,
            feedforward=linear_feedforward(0.5),
            min_command=-1.0,
            max_command=12.0,
            anti_windup="conditional",
        ),
        {"reset_command": True},
    ),
    "plain_none_first_update": (
        lambda: SpeedAutopilot(
            1.0, 0.5, 0.5, min_command=0.0, max_command=2.0, max_rate=0.1, anti_windup="none"
        ),
        {"times": False, "initial_reset": False},
    ),
}


def make_inputs(seed: int = 28, ships: int = SHIPS, steps: int = STEPS) -> dict[str, np.ndarray]:
    """Random measurement and setpoint sequences (the golden file stores the ones it used)."""
    rng = np.random.default_rng(seed)
    dt = rng.choice([0.0, 0.25, 0.5, 0.5, 1.0, 3.0], size=steps)
    turns = 2.0 * np.pi * rng.integers(-3, 4, size=(ships, steps))
    turns[-1] += 2.0 * np.pi * 1000  # a heading kept unwrapped for many turns
    psi = rng.uniform(-np.pi, np.pi, (ships, 1)) + np.cumsum(rng.normal(0, 0.05, (ships, steps)), 1)
    legs = rng.uniform(-np.pi, np.pi, (ships, steps // 8 + 1))
    psi_ref = np.repeat(legs, 8, axis=1)[:, :steps]
    psi[0] = psi_ref[0] + rng.normal(0.0, 0.01, steps)  # one ship close to its setpoint
    return {
        "t0": np.array([10.0]),
        "t": 10.0 + np.cumsum(dt),
        "psi0": rng.uniform(-np.pi, np.pi, ships),
        "r0": rng.normal(0.0, 0.01, ships),
        "command0": rng.uniform(-0.3, 0.3, ships),
        "psi": psi + turns,
        "r": rng.normal(0.0, 0.002, (ships, steps)),
        "psi_ref": psi_ref + 2.0 * np.pi * rng.integers(-2, 3, size=(ships, 1)),
        "u": np.clip(4.0 + np.cumsum(rng.normal(0.0, 0.4, (ships, steps)), 1), 0.0, 9.0),
        "u_ref": np.repeat(rng.choice([2.0, 5.0, 7.0], (ships, steps // 8 + 1)), 8, 1)[:, :steps],
        "integral0": rng.normal(0.0, 0.3, ships),
        "thrust0": rng.uniform(0.0, 1.5, ships),
    }


def run_heading(
    name: str, inputs: dict[str, np.ndarray], rows: Any, attrs: tuple[str, ...] = ("integral",)
) -> dict[str, np.ndarray]:
    """Run heading case ``name`` on ship ``rows`` (an ``int``: one ship in scalar mode; an
    index array: that batch): the returned commands (``"command"``) and the attributes
    ``attrs`` after each step, shape ``(steps,)`` or ``(steps, n)``."""
    make, opt = HEADING_CASES[name]
    pilot = make()
    times = opt.get("times", True)
    t_prev = float(inputs["t0"][0]) if times else None
    if opt.get("initial_reset", True):
        command = inputs["command0"][rows] if opt.get("reset_command") else None
        pilot.reset(inputs["psi0"][rows], inputs["r0"][rows], t=t_prev, command=command)
    out: dict[str, list[Any]] = {key: [] for key in ("command", *attrs)}
    steps = inputs["t"].size
    for k in range(steps):
        if opt.get("mid_reset") and k == steps // 2:
            psi, r = inputs["psi"][rows, k - 1], inputs["r"][rows, k - 1]
            pilot.reset(psi, r, t=t_prev, command=pilot.command, keep_offset=True)
        t = float(inputs["t"][k]) if times else None
        psi, r, ref = inputs["psi"][rows, k], inputs["r"][rows, k], inputs["psi_ref"][rows, k]
        out["command"].append(pilot.update(t, psi, r, ref))
        for key in attrs:
            out[key].append(getattr(pilot, key))
        t_prev = t
    return {key: np.array(value) for key, value in out.items()}


def run_speed(
    name: str, inputs: dict[str, np.ndarray], rows: Any, attrs: tuple[str, ...] = ("integral",)
) -> dict[str, np.ndarray]:
    """As :func:`run_heading` for the speed cases."""
    make, opt = SPEED_CASES[name]
    pilot = make()
    times = opt.get("times", True)
    if opt.get("initial_reset", True):
        command = inputs["thrust0"][rows] if opt.get("reset_command") else None
        t0 = float(inputs["t0"][0]) if times else None
        pilot.reset(t=t0, integral=inputs["integral0"][rows], command=command)
    out: dict[str, list[Any]] = {key: [] for key in ("command", *attrs)}
    for k in range(inputs["t"].size):
        t = float(inputs["t"][k]) if times else None
        out["command"].append(pilot.update(t, inputs["u"][rows, k], inputs["u_ref"][rows, k]))
        for key in attrs:
            out[key].append(getattr(pilot, key))
    return {key: np.array(value) for key, value in out.items()}


RUNNERS = {**dict.fromkeys(HEADING_CASES, run_heading), **dict.fromkeys(SPEED_CASES, run_speed)}


@pytest.fixture(scope="module")
def golden() -> dict[str, np.ndarray]:
    with np.load(GOLDEN) as data:
        return {key: data[key] for key in data.files}


def _inputs(golden: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    return {
        key.removeprefix("inputs/"): v for key, v in golden.items() if key.startswith("inputs/")
    }


@pytest.mark.parametrize("name", list(RUNNERS))
def test_one_ship_and_batch_rows_equal_the_scalar_golden(
    name: str, golden: dict[str, np.ndarray]
) -> None:
    inputs = _inputs(golden)
    ships = inputs["psi0"].size
    run = RUNNERS[name]
    batch = run(name, inputs, np.arange(ships))
    for key in ("command", "integral"):
        want = golden[f"{name}/{key}"]
        assert want.shape == (STEPS, ships)
        np.testing.assert_array_equal(batch[key], want)  # every row of the batch, bitwise
        for ship in range(ships):  # one ship in scalar mode
            np.testing.assert_array_equal(run(name, inputs, ship)[key], want[:, ship])


@pytest.mark.parametrize("name", list(RUNNERS))
def test_batch_of_n_equals_n_batches_of_one(name: str) -> None:
    inputs = make_inputs(seed=7, ships=5, steps=60)
    run = RUNNERS[name]
    attrs = ("integral", "error", "unsaturated_command")
    batch = run(name, inputs, np.arange(5), attrs)
    for ship in range(5):
        one = run(name, inputs, np.array([ship]), attrs)  # arrays of shape (1,)
        scalar = run(name, inputs, ship, attrs)
        for key, values in batch.items():
            assert one[key].shape == (60, 1)
            np.testing.assert_array_equal(one[key][:, 0], values[:, ship])
            np.testing.assert_array_equal(scalar[key], values[:, ship])


def test_ssa_array_is_bitwise_the_scalar_ssa() -> None:
    rng = np.random.default_rng(3)
    angles = np.concatenate([
        rng.uniform(-20.0, 20.0, 20_000),
        rng.normal(0.0, 1.0, 20_000) * 10.0 ** rng.integers(-20, 300, 20_000),
        np.arange(-2000, 2000) * np.pi,  # the ties of the modulo
        [0.0, -0.0, np.pi, -np.pi, 1e308, -1e308, 5e-324, -5e-324],
    ])  # fmt: skip
    wrapped = ssa_array(angles)
    scalar = np.array([ssa(a) for a in angles.tolist()])
    np.testing.assert_array_equal(wrapped.view(np.int64), scalar.view(np.int64))
    assert np.all((wrapped >= -np.pi) & (wrapped < np.pi))


def test_scalar_mode_gives_floats_and_batch_mode_arrays() -> None:
    pilot = HEADING_CASES["unstable_cascade"][0]()
    pilot.reset(0.1, 0.0, t=0.0)
    assert pilot.batch_size is None
    u = pilot.update(0.5, np.float64(0.1), 0.001, 1.0)
    assert type(u) is float
    for key in ("psi_d", "r_d", "a_d", "error", "integral", "command", "offset_estimate"):
        assert type(getattr(pilot, key)) is float, key
    assert type(pilot.reference.psi_f) is float
    pilot.reset(np.array([0.1, 0.2, 0.3]), 0.0, t=0.0)
    assert pilot.batch_size == 3
    u = pilot.update(0.5, [0.1, 0.2, 0.3], np.zeros(3), 1.0)  # one setpoint for all
    assert isinstance(u, np.ndarray) and u.shape == (3,)
    assert pilot.command.shape == pilot.reference.psi_ref.shape == (3,)
    u[:] = 99.0  # the caller's copy: the autopilot keeps its own
    assert np.all(pilot.command != 99.0)
    with pytest.raises(AttributeError, match="read-only"):
        pilot.integral = np.zeros(3)

    speed = SPEED_CASES["drag_feedforward_thrust_limit"][0]()
    speed.reset(t=0.0)  # numbers: one ship or a batch, as the next update says
    c = speed.update(0.5, np.array([3.0, 5.0]), 5.0)
    assert speed.batch_size == 2 and c.shape == (2,)
    assert speed.feedforward_command.shape == (2,)
    speed.reset(t=0.0)
    assert type(speed.update(0.5, 3.0, 5.0)) is float
    assert type(speed.integral) is float


def test_batch_agrees_with_its_ships_on_the_reference_model_alone() -> None:
    psi0, ref = np.array([0.0, 3.0, -3.0]), np.array([2.0, -3.0, 3.0])
    batch = HeadingReferenceModel(0.1, 1.0, max_turn_rate=0.02, max_turn_accel=0.001)
    batch.reset(psi0)
    ships = [HeadingReferenceModel(0.1, 1.0, max_turn_rate=0.02, max_turn_accel=0.001)
             for _ in psi0]  # fmt: skip
    for ship, p in zip(ships, psi0, strict=True):
        ship.reset(float(p))
    for k in range(200):
        h = 0.5 + 2.5 * (k % 3 == 0)  # several substeps now and then
        out = batch.update(ref, h)
        for i, ship in enumerate(ships):
            single = ship.update(float(ref[i]), h)
            assert [float(v[i]) for v in out] == list(single)


def test_keep_offset_per_ship() -> None:
    make = HEADING_CASES["keep_offset"][0]
    pilot = make()
    pilot.reset(np.zeros(2), t=0.0, command=0.0)
    for k in range(1, 30):
        pilot.update(0.5 * k, np.array([0.0, 0.0]), np.zeros(2), np.array([0.05, -0.05]))
    estimate = pilot.offset_estimate
    pilot.reset(np.zeros(2), keep_offset=True)
    assert isinstance(pilot.offset, np.ndarray)
    np.testing.assert_array_equal(pilot.offset, estimate)
    assert estimate[0] != estimate[1]
    with pytest.raises(ValueError, match=r"\(2,\).*\(3,\)"):
        pilot.reset(np.zeros(3))
    pilot.offset = 0.0  # a number again: any batch size
    pilot.reset(np.zeros(3))


def test_bad_values_are_named_with_their_index() -> None:
    pilot = HEADING_CASES["mariner_back_calculation"][0]()
    with pytest.raises(ValueError, match=r"psi\[1\] must be a finite number, got nan"):
        pilot.reset(np.array([0.0, np.nan, 0.0]))
    pilot.reset(np.zeros(3), t=0.0)
    with pytest.raises(ValueError, match=r"r\[2\] must be a finite number, got inf"):
        pilot.update(1.0, np.zeros(3), np.array([0.0, 0.0, np.inf]), 0.0)
    with pytest.raises(ValueError, match=r"psi_ref\[0\]"):
        pilot.update(1.0, np.zeros(3), np.zeros(3), [np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match="psi must be a finite number, got nan"):
        HEADING_CASES["mariner_none"][0]().update(0.0, math.nan, 0.0, 0.0)
    speed = SpeedAutopilot(1.0, 0.1, 1.0, feedforward=lambda u: np.where(u > 4.0, np.nan, u))
    speed.reset(integral=np.zeros(3))
    with pytest.raises(ValueError, match=r"feedforward\(u_ref\)\[1\] must be a finite number"):
        speed.update(0.0, np.zeros(3), np.array([1.0, 5.0, 2.0]))
    with pytest.raises(ValueError, match=r"command\[0\] must be a finite number"):
        speed.reset(command=[np.inf, 0.0])


def test_shapes_are_checked() -> None:
    pilot = HEADING_CASES["mariner_back_calculation"][0]()
    with pytest.raises(ValueError, match=r"r has shape \(4,\) but psi has shape \(3,\)"):
        pilot.reset(np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError, match=r"command has shape \(2,\) but psi has shape \(3,\)"):
        pilot.reset(np.zeros(3), command=np.zeros(2))
    with pytest.raises(ValueError, match=r"psi must be a number or a 1-D array.*\(2, 2\)"):
        pilot.reset(np.zeros((2, 2)))
    pilot.reset(np.zeros(3), t=0.0)
    with pytest.raises(ValueError, match=r"psi has shape \(4,\), expected \(3,\)"):
        pilot.update(1.0, np.zeros(4), np.zeros(3), 0.0)
    with pytest.raises(ValueError, match=r"r has shape \(\), expected \(3,\)"):
        pilot.update(1.0, np.zeros(3), 0.0, 0.0)  # measurements: one per ship
    with pytest.raises(ValueError, match=r"psi_ref has shape \(2,\), expected \(3,\) or a number"):
        pilot.update(1.0, np.zeros(3), np.zeros(3), np.zeros(2))
    pilot.reset(0.0, t=0.0)  # one ship again
    with pytest.raises(ValueError, match=r"psi has shape \(3,\), expected a number: the"):
        pilot.update(1.0, np.zeros(3), 0.0, 0.0)
    fresh = HEADING_CASES["mariner_back_calculation"][0]()  # first update: its size decides
    with pytest.raises(ValueError, match=r"r has shape \(2,\) but psi has shape \(3,\)"):
        fresh.update(0.0, np.zeros(3), np.zeros(2), 0.0)
    speed = SPEED_CASES["linear_unlimited"][0]()
    with pytest.raises(ValueError, match=r"command has shape \(3,\) but integral has shape"):
        speed.reset(integral=np.zeros(2), command=np.zeros(3))
    speed.reset(integral=np.zeros(2))
    with pytest.raises(ValueError, match=r"u has shape \(3,\), expected \(2,\)"):
        speed.update(0.0, np.zeros(3), 1.0)


def test_feedforwards_and_limits_work_on_arrays() -> None:
    u = np.array([-2.0, 0.0, 1.5, 6.0])
    drag = quadratic_drag_feedforward(D1, D2, share=0.5)
    np.testing.assert_array_equal(drag(u), [drag(float(x)) for x in u])
    lin = linear_feedforward(0.5)
    np.testing.assert_array_equal(lin(u), [lin(float(x)) for x in u])
    pilot = SpeedAutopilot(1.0, 0.1, 1.0, max_command=thrust_limit, min_command=0.0)
    np.testing.assert_array_equal(pilot.max_command(u), [pilot.max_command(float(x)) for x in u])
    assert type(pilot.max_command(3.0)) is float

"""The heading-autopilot design rule on more than one ship (controllers.design_model): the
Mariner, seed 004's ship (a slow zero: T1 + T2 - T3 < 0) and a directionally unstable Norrbin
ship (n1 < 0), each closed around the nonlinear simulation model, not the design model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers import HeadingAutopilot, design_model
from shipgym.benchmark.policies import nomoto_heading_autopilot
from shipgym.models import Nomoto2Params, NorrbinParams, make_model

SEED004 = Nomoto2Params(K=0.03, T1=130.0, T2=150.0, T3=320.0)
"""Seed 004 eq. 6: the second-order Nomoto model fitted to its ship."""


def _step(model, pilot: HeadingAutopilot, target_deg: float, duration: float, dt: float = 0.5):
    """Heading [deg] of ``model`` steered by ``pilot`` to ``target_deg`` from rest."""
    ipsi, ir = model.index("psi"), model.index("r")
    x0 = np.zeros(model.nx)
    x0[model.index("U")] = model.surge.service_speed
    pilot.reset(0.0, 0.0, t=0.0)
    shaft = model.surge.service_shaft_speed
    target = math.radians(target_deg)

    def policy(t: float, x: np.ndarray) -> list[float]:
        return [pilot.update(t, x[ipsi], x[ir], target), shaft]

    res = model.simulate(x0, policy, dt, round(duration / dt))
    return res.time, np.degrees(res["psi"])


@pytest.mark.parametrize(
    ("name", "params"),
    [
        ("nomoto1", None),
        ("nomoto2", None),
        ("nomoto2", SEED004),
        ("norrbin", NorrbinParams(n1=-1.0, n3=2.9e3)),  # directionally unstable
        ("bech", None),
    ],
)
def test_design_rule_settles_a_heading_step_on_each_ship(name: str, params) -> None:
    model = make_model(name, params)
    pilot = nomoto_heading_autopilot(model, 0.5)
    t, psi = _step(model, pilot, 20.0, 1500.0)
    settled = psi[t > 1000.0]
    assert np.all(np.abs(settled - 20.0) < 0.5), (name, settled.min(), settled.max())
    assert psi.max() < 20.0 + 8.0  # overshoot below 8 deg


def test_seed004_ship_reduction_signs() -> None:
    """T1 + T2 - T3 makes seed 004's stable ship look unstable (-40 s) and that design
    destabilises the real plant; the bandwidth match gives a stable design model."""
    model = make_model("nomoto2", SEED004)
    gear = model.gear
    limits = {"actuator_time_constant": gear.time_constant, "max_command": gear.max_angle,
              "max_rate": gear.max_rate}  # fmt: skip
    K, T, omega = design_model(SEED004.K, SEED004.T1, SEED004.T2, SEED004.T3, **limits)
    assert T > 0 and K > 0
    # matches magnitude and phase of the plant at the design bandwidth
    s = 1j * omega
    plant = SEED004.K * (1 + SEED004.T3 * s) / ((1 + SEED004.T1 * s) * (1 + SEED004.T2 * s))
    assert K / (1 + T * s) == pytest.approx(plant, rel=1e-9)
    classic = HeadingAutopilot.from_nomoto(SEED004.K, SEED004.T1 + SEED004.T2 - SEED004.T3,
                                           0.5, **limits)  # fmt: skip
    _, psi = _step(model, classic, 20.0, 1500.0)
    assert np.max(np.abs(psi - 20.0)[-200:]) > 20.0  # the classic reduction loses the ship


def test_first_order_ships_are_matched_exactly() -> None:
    K, T, _ = design_model(0.185, 107.3, n1=-2.0)
    assert (K, T) == (pytest.approx(-0.0925), pytest.approx(-53.65))
    with pytest.raises(ValueError, match="non-zero"):
        design_model(0.185, 107.3, n1=0.0)


def test_seed004_case_on_its_own_ship() -> None:
    """Seed 004's path-following case: the report's gains and the design rule finish the path;
    the tuned pair (a faster heading loop, 300 m lookahead) keeps the straight-leg cross-track
    error inside the report's +-200 m, the conservative design rule does not."""
    from shipgym.benchmark.seed004 import run_seed004

    design = run_seed004("design")
    report = run_seed004("seed004")
    tuned = run_seed004((0.07, 300.0))
    assert design.finished and report.finished and tuned.finished
    assert tuned.max_straight_m < 200.0
    assert design.max_straight_m > tuned.max_straight_m
    assert np.all(np.isfinite(tuned.cross_track))
    with pytest.raises(ValueError, match="gains"):
        run_seed004("fast")

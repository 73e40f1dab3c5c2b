"""``shipgym design``: the heading autopilot of an identified Nomoto-family ship.

The design (:func:`shipgym.benchmark.design.design_heading_autopilot`) against the pole
placement it implements, the robust reduction of a second-order ship, the margins with a rudder
delay against their closed form and python-control's Padé loop, the gains document through
``make_policy(..., gains=...)`` and ``shipgym evaluate --gains``, and the CLI's refusals.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import control
import numpy as np
import pytest

from controllers import HeadingAutopilot, default_bandwidth, design_model, pid_gains_nomoto
from controllers.heading import loop_margins
from shipgym.benchmark import evaluate, make_policy
from shipgym.benchmark.design import SETTLING_BAND, design_heading_autopilot
from shipgym.benchmark.policies import (
    NomotoHeadingGains,
    load_gains,
    nomoto_heading_autopilot,
)
from shipgym.cli import main
from shipgym.models import Nomoto1Params, Nomoto2Params, make_model
from shipgym.models.model_file import nomoto_document

ENV = "shipgym/NomotoHeading-v0"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
#: A short, fast first-order ship (a small vessel): K 0.1 1/s, T 30 s.
SMALL = Nomoto1Params(K=0.1, T=30.0)


def _quiet(_msg: str) -> None:
    pass


def _model_file(path: Path, **kw: float) -> Path:
    """A model file of the default Mariner (nomoto1) as ``shipgym identify --json`` writes."""
    doc = nomoto_document("nomoto1", {"K": 0.185, "T": 107.3}, **kw)  # type: ignore[arg-type]
    path.write_text(json.dumps({"nomoto": doc}))
    return path


@pytest.fixture(scope="module")
def small_design():
    return design_heading_autopilot(make_model("nomoto1", SMALL), zigzag=False)


def test_first_order_design_is_the_pole_placement_of_the_identified_ship(small_design) -> None:
    d = small_design
    gear = make_model("nomoto1", SMALL).gear
    assert (d.K, d.T, d.design_method, d.low_frequency_T) == (0.1, 30.0, "as identified", None)
    w = default_bandwidth(
        30.0, actuator_time_constant=gear.time_constant, max_command=gear.max_angle,
        max_rate=gear.max_rate,
    )  # fmt: skip
    assert d.omega_n == pytest.approx(w) and d.zeta == 0.8 and d.bandwidth_rule
    assert (d.kp, d.ki, d.kd) == pytest.approx(pid_gains_nomoto(0.1, 30.0, w, 0.8))
    assert d.gains["reference_omega"] == pytest.approx(w)
    # the same rule as the benchmark's classic policy
    classic = nomoto_heading_autopilot(make_model("nomoto1", SMALL), 1.0)
    assert (d.kp, d.ki, d.kd) == pytest.approx((classic.kp, classic.ki, classic.kd))


def test_first_order_design_meets_its_closed_loop_bounds(small_design) -> None:
    d = small_design
    # margins of the size the pole placement implies: the design model's loop without the
    # servo, less the servo's phase lag at the crossover (2 s servo)
    placed = HeadingAutopilot.from_nomoto(0.1, 30.0, 1.0, omega_n=d.omega_n)
    ideal = placed.design_report()
    m = d.margins
    assert d.stable and d.input_delay == 0.0
    assert m.phase_margin_deg > 45.0
    assert math.isinf(m.gain_margin_db)  # the phase never reaches -180 deg without a delay
    lag = math.degrees(math.atan(m.gain_crossover * 2.0))
    assert m.phase_margin_deg == pytest.approx(ideal.phase_margin_deg - lag, abs=3.0)
    assert m.delay_margin == pytest.approx(math.radians(m.phase_margin_deg) / m.gain_crossover)
    # the dominant closed-loop poles are the placed ones, moved a little by the servo
    pole = d.design_poles[np.argmax(d.design_poles.imag)]
    got = d.closed_loop_poles[np.argmax(d.closed_loop_poles.imag)]
    assert abs(got - pole) < 0.15 * abs(pole)
    # simulated steps on the identified ship: the step response that the placed poles and
    # the reference model at w_n give (the design model's loop, no servo), small overshoot
    placed_loop = placed.reference.transfer_function() * control.feedback(ideal.loop, 1)
    want = control.step_info(placed_loop, T=np.linspace(0.0, 3000.0, 30001))
    ten, thirty = d.steps
    for s in (ten, thirty):
        assert 0.0 <= s.overshoot_percent < 5.0
        assert s.overshoot_percent == pytest.approx(want["Overshoot"], abs=1.0)
        assert s.rise_time == pytest.approx(want["RiseTime"], rel=0.1)
        assert s.settling_time == pytest.approx(want["SettlingTime"], rel=0.1)
        assert abs(s.final_error) < SETTLING_BAND * s.step  # the integrator's slow tail
        assert s.peak_rudder < math.radians(35.0)
    # the 10 deg step stays linear: it is the linear closed loop's step response
    ls = d.linear_step
    assert ten.rise_time == pytest.approx(ls["rise_time_s"], rel=0.05)
    assert ten.overshoot_percent == pytest.approx(ls["overshoot_percent"], abs=0.5)
    assert thirty.peak_rudder > ten.peak_rudder


@pytest.mark.parametrize(
    ("T1", "T2", "T3", "word"),
    [(130.0, 150.0, 320.0, "not positive"), (60.0, 30.0, 85.0, "small")],  # seed 004 eq. 6
)
def test_second_order_ship_gets_the_robust_reduction(T1, T2, T3, word) -> None:
    ship = make_model("nomoto2", Nomoto2Params(K=0.03, T1=T1, T2=T2, T3=T3))
    d = design_heading_autopilot(ship, zigzag=False, steps_deg=(10.0,))
    gear = ship.gear
    K_e, T_e, w = design_model(
        0.03, T1, T2, T3, actuator_time_constant=gear.time_constant,
        max_command=gear.max_angle, max_rate=gear.max_rate,
    )  # fmt: skip
    assert d.design_method == "matched at the bandwidth"
    assert d.low_frequency_T == pytest.approx(T1 + T2 - T3)
    assert (d.K, d.T, d.omega_n) == pytest.approx((K_e, T_e, w))
    assert d.T > 0 and abs(d.T - d.low_frequency_T) > 0.5 * d.T  # never the naive T
    assert word in d.design_reason
    assert d.stable and d.margins.phase_margin_deg > 45.0
    assert d.steps[0].overshoot_percent < 10.0
    assert abs(d.steps[0].final_error) < SETTLING_BAND * d.steps[0].step
    if T1 + T2 - T3 < 0:  # the naive design destabilises the ship
        naive = HeadingAutopilot.from_nomoto(0.03, T1 + T2 - T3, 1.0, omega_n=w)
        loop = control.tf([naive.kd, naive.kp, naive.ki], [1.0, 0.0]) * (
            control.tf([0.03 * T3, 0.03], [T1 * T2, T1 + T2, 1.0, 0.0])
        )
        poles = control.poles(control.feedback(loop, 1))
        assert np.max(np.real(poles)) > 0


def test_a_delay_lowers_the_phase_margin_by_the_crossover_times_the_delay() -> None:
    tau = 6.0
    base = design_heading_autopilot(make_model("nomoto1", SMALL), zigzag=False, steps_deg=(10.0,))
    late = design_heading_autopilot(
        make_model("nomoto1", SMALL, input_delay=tau), zigzag=False, steps_deg=(10.0,)
    )
    assert late.input_delay == tau and (late.kp, late.ki, late.kd) == (base.kp, base.ki, base.kd)
    m0, m = base.margins, late.margins
    assert late.margins_without_delay.phase_margin_deg == pytest.approx(m0.phase_margin_deg)
    assert m.gain_crossover == pytest.approx(m0.gain_crossover)  # |e^{-jw tau}| = 1
    drop = math.degrees(m0.gain_crossover * tau)
    assert m0.phase_margin_deg - m.phase_margin_deg == pytest.approx(drop, rel=1e-6)
    assert m.delay_margin == pytest.approx(m0.delay_margin - tau, rel=1e-6)
    # the phase crossover that the delay creates, against python-control's Padé loop
    num, den = control.pade(tau, 12)
    gm, pm, _, wpc, _, _ = control.stability_margins(late.loop * control.tf(num, den))
    assert m.gain_margin_db == pytest.approx(20.0 * math.log10(gm), abs=0.05)
    assert m.phase_crossover == pytest.approx(wpc, rel=1e-3)
    assert m.phase_margin_deg == pytest.approx(pm, abs=0.05)
    # the simulation has the delay in the loop: it follows the linear loop with the delay
    step = late.steps[0]
    assert step.rise_time == pytest.approx(late.linear_step["rise_time_s"], rel=0.05)
    assert step.overshoot_percent == pytest.approx(late.linear_step["overshoot_percent"], abs=0.5)
    # beyond the delay margin the loop is unstable
    beyond = design_heading_autopilot(
        make_model("nomoto1", SMALL), input_delay=1.2 * m0.delay_margin, zigzag=False,
        steps_deg=(10.0,), duration=100.0,
    )  # fmt: skip
    assert not beyond.stable and beyond.margins.phase_margin_deg < 0
    assert "UNSTABLE" in beyond.summary()


def test_loop_margins_refuse_bad_input() -> None:
    with pytest.raises(ValueError, match="delay must be a finite number >= 0"):
        loop_margins(control.tf([1.0], [1.0, 1.0, 0.0]), -1.0)
    with pytest.raises(ValueError, match=r"SISO control\.TransferFunction"):
        loop_margins("L", 0.0)  # type: ignore[arg-type]


def test_design_refuses_a_model_that_is_not_nomoto() -> None:
    with pytest.raises(ValueError, match=r"'rvg3dof' is the 3-DOF model of R/V Gunnerus.*nomoto1"):
        design_heading_autopilot(make_model("rvg3dof"))
    with pytest.raises(ValueError, match="Nomoto-family ShipModel"):
        design_heading_autopilot("nomoto1")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="heading step"):
        design_heading_autopilot(make_model("nomoto1"), steps_deg=(0.0,), zigzag=False)


def test_rudder_offset_becomes_the_autopilot_offset(tmp_path: Path) -> None:
    from shipgym.models.model_file import load_model

    offset = math.radians(1.5)
    ship = load_model(_model_file(tmp_path / "fit.json", rudder_offset=offset))
    assert ship.name == "norrbin"
    d = design_heading_autopilot(ship, zigzag=False, steps_deg=(10.0,))
    assert d.gains["offset"] == pytest.approx(-offset)  # the rudder that holds it straight
    s = d.steps[0]
    assert abs(s.final_error) < SETTLING_BAND * s.step and s.overshoot_percent < 5.0


def test_gains_round_trip_through_the_cli_and_make_policy(tmp_path: Path, capsys) -> None:
    model = _model_file(tmp_path / "fit.json")  # the default Mariner, nomoto1
    gains, plot = tmp_path / "gains.json", tmp_path / "design.png"
    assert main(["design", str(model), "--json", str(gains), "--plot", str(plot)]) == 0
    out = capsys.readouterr().out
    assert "Kp 0.4156" in out and "phase 68.4 deg" in out and "zigzag 20/20" in out
    assert plot.read_bytes()[:8] == PNG_MAGIC and plot.stat().st_size > 20_000
    doc = json.loads(gains.read_text())
    section = load_gains(gains)
    assert section == doc["autopilot"]
    assert doc["design"]["margins"]["phase_margin_deg"] == pytest.approx(68.35, abs=0.01)
    policy = make_policy("classic", ENV, gains=gains)
    assert isinstance(policy, NomotoHeadingGains) and policy.gains == section
    assert make_policy("classic", ENV, gains=doc).gains == section  # a parsed document too
    # the Mariner's design is the classic policy's: the same episode, step for step
    ran = evaluate(ENV, policy, "classic", 1, 3, progress=_quiet)
    classic = evaluate(ENV, make_policy("classic", ENV), "classic", 1, 3, progress=_quiet)
    assert ran.returns == pytest.approx(classic.returns, rel=1e-12)
    # and through the CLI
    assert main(["evaluate", "--env", ENV, "--gains", str(gains), "--episodes", "1"]) == 0
    assert "return" in capsys.readouterr().out


def test_gains_for_another_env_or_structure_are_refused(tmp_path: Path) -> None:
    doc = design_heading_autopilot(
        make_model("nomoto1", SMALL), zigzag=False, steps_deg=(10.0,)
    ).gains_document()
    for change, match in [
        ({"env": "shipgym/RVGHeading-v1"}, "gains for env 'shipgym/RVGHeading-v1'"),
        ({"structure": "LOSGuidance"}, "structure 'LOSGuidance'"),
        ({"kind": "something else"}, "not a heading autopilot gains document"),
        ({"autopilot": {"kp": 1.0}}, "must have the keys"),
        ({"autopilot": {**doc["autopilot"], "kp": "1"}}, "autopilot kp must be a number"),
        ({"autopilot": {**doc["autopilot"], "reference_zeta": -1.0}}, "reference zeta"),
    ]:
        with pytest.raises(ValueError, match=match):
            make_policy("classic", ENV, gains={**doc, **change})
    with pytest.raises(ValueError, match="classic controller, not with 'classic-tuned'"):
        make_policy("classic-tuned", ENV, gains=doc)
    with pytest.raises(ValueError, match="another structure"):
        make_policy("classic", "shipgym/RVGHeading-v1", gains=doc)
    with pytest.raises(ValueError, match="does not exist"):
        make_policy("classic", ENV, gains=tmp_path / "none.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    with pytest.raises(ValueError, match="not readable JSON"):
        make_policy("classic", ENV, gains=bad)


def _vmm_file(path: Path) -> Path:
    from shipgym.sysid.generator import vmm_truth

    path.write_text(json.dumps({"vmm": vmm_truth().to_dict()}))
    return path


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (_vmm_file, "holds a 'vmm' model"),
        (lambda p: p, "does not exist"),
        (lambda p: (p.write_text("{not json"), p)[1], "cannot read model file"),
        (lambda p: (p.write_text('{"model": "nomoto1"}'), p)[1], "holds no model"),
    ],
    ids=["vmm", "missing", "not-json", "no-model"],
)
def test_design_cli_refuses_bad_files_in_one_line(tmp_path: Path, capsys, make, message) -> None:
    path = make(tmp_path / "fit.json")
    assert main(["design", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("shipgym: error: ") and message in err
    assert err.count("\n") == 1
    if message.startswith("holds a"):
        assert "Nomoto-family" in err and "nomoto1" in err


def test_design_refuses_a_gain_of_the_wrong_sign() -> None:
    """The fit of the decaying turn (K -923 1/s, T 1.7e7 s) designed Kp -8e-5 and a 25 h
    settling time; a ship with K <= 0 is refused, naming the sign convention."""
    for K in (-923.0, 0.0):
        with pytest.raises(ValueError, match=r"cannot design for nomoto1 with K = .* <= 0: under "
                           r"the Nomoto sign"):  # fmt: skip
            design_heading_autopilot(make_model("nomoto1", Nomoto1Params(K=K, T=1.7e7)))


@pytest.mark.parametrize(
    ("verdict", "params", "message"),
    [
        (None, {"K": -923.0, "T": 1.7e7}, r"cannot design for nomoto1 with K = -923 1/s <= 0"),
        ({"identifiable": False, "reasons": ["T = 1.7e+07 s is more than 10 times the record"]},
         {"K": 0.185, "T": 107.3}, r"is not identifiable: T = 1.7e\+07 s is more than 10 times"),
    ],
    ids=["negative-gain", "verdict"],
)
def test_design_cli_refuses_what_it_cannot_design_for(
    tmp_path: Path, capsys, verdict: dict | None, params: dict[str, float], message: str
) -> None:
    doc: dict = {"nomoto": nomoto_document("nomoto1", params)}
    if verdict is not None:
        doc["verdict"] = verdict
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(doc))
    out = tmp_path / "gains.json"
    assert main(["design", str(path), "--json", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("shipgym: error: ") and re.search(message, err), err
    assert err.count("\n") == 1
    assert not out.exists()
    # an identifiable verdict designs as before
    doc["verdict"] = {"identifiable": True, "reasons": []}
    doc["nomoto"] = nomoto_document("nomoto1", {"K": 0.1, "T": 30.0})
    path.write_text(json.dumps(doc))
    assert main(["design", str(path)]) == 0


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--env", ENV, "--controller", "zero"], "--controller classic, not"),
        (["--env", "shipgym/RVGHeading-v1"], "--gains sets the classic heading autopilot"),
        (["--env", ENV, "--ray"], "drop --ray"),
    ],
)
def test_evaluate_gains_only_with_the_classic_nomoto_policy(
    tmp_path: Path, capsys, argv: list[str], message: str
) -> None:
    gains = tmp_path / "gains.json"
    gains.write_text("{}")
    assert main(["evaluate", *argv, "--gains", str(gains), "--episodes", "1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("shipgym: error: ") and message in err and err.count("\n") == 1

"""Hostile inputs to the identification loaders and fits: each is refused with a message naming
what was wrong and what was expected, or accepted and reported (``shipgym.sysid.data``,
``shipgym.sysid.fit``, ``shipgym.sysid.engine``)."""

from __future__ import annotations

import contextlib
import io
import json
import math
import re
import warnings
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

import shipgym.sysid.ingest as data_module
from shipgym.cli import main
from shipgym.sysid import identify
from shipgym.sysid.data import Record, SysidDataWarning, load, measured_root
from shipgym.sysid.families import FAMILIES
from shipgym.sysid.families.base import Verdict, undetermined
from shipgym.sysid.families.nomoto import CONDITION_LIMIT, fit_problems
from shipgym.sysid.fit import (
    FitResult,
    excitation_problems,
    fit_equation_error,
    fit_output_error,
)

MEASURED = measured_root()
needs_data = pytest.mark.skipif(
    not MEASURED.is_dir(),
    reason=f"measured data not found at {MEASURED} (set SHIPGYM_MEASURED_DATA)",
)


def _zigzag(n: int = 801, dt: float = 0.5, seed: int = 0, K: float = 0.1) -> Record:
    """A first-order Nomoto zigzag (K 1/s, T = 30 s, 20 deg) with a little noise."""
    rng = np.random.default_rng(seed)
    t = dt * np.arange(n)
    T, amp = 30.0, math.radians(20.0)
    delta = np.empty(n)
    r = np.zeros(n)
    psi = np.zeros(n)
    side = 1.0
    for k in range(n):
        if k and side * psi[k - 1] > amp:
            side = -side
        delta[k] = side * amp
        if k:
            r[k] = r[k - 1] + dt * (K * delta[k - 1] - r[k - 1]) / T
            psi[k] = psi[k - 1] + dt * 0.5 * (r[k] + r[k - 1])
    U = np.full(n, 5.0)
    x = np.cumsum(U * dt * np.cos(psi))
    y = np.cumsum(U * dt * np.sin(psi))
    return Record(
        time=t,
        delta=delta + 1e-4 * rng.standard_normal(n),
        psi=psi + 1e-4 * rng.standard_normal(n),
        r=r + 1e-5 * rng.standard_normal(n),
        x=x,
        y=y,
        U=U,
        meta={"source": "test", "repairs": [], "notes": []},
    )


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def _load_quiet(path: Path, fmt: str | None = None) -> Record:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidDataWarning)
        return load(path, fmt)


# ---------------------------------------------------------------------------------------------
# canonical meta validated on reading
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("line", "expected"),
    [
        ("# repairs: 5", r"meta 'repairs' is a number 5; expected a JSON list of strings"),
        ('# repairs: "abc"', r"meta 'repairs' is a string \"abc\"; expected a JSON list of str"),
        ("# notes: [1, 2]", r"meta 'notes' is a list \[1, 2\]; expected a JSON list of strings"),
        ("# L: -3", r"meta 'L' is a number -3; expected the ship length in m"),
        ("# irregular_sampling: 1", r"meta 'irregular_sampling' .*; expected true or false"),
    ],
)
def test_canonical_meta_of_the_wrong_type_is_refused_naming_file_and_line(
    tmp_path: Path, line: str, expected: str
) -> None:
    path = _zigzag().to_csv(tmp_path / "rec.csv")
    key = line[2:].split(":")[0]
    lines = [ln for ln in path.read_text().splitlines() if not ln.startswith(f"# {key}:")]
    lines.insert(1, line)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"^rec\.csv line 2: " + expected):
        load(path)


def test_canonical_meta_repeated_key_refused(tmp_path: Path) -> None:
    path = _zigzag().to_csv(tmp_path / "rec.csv")
    lines = path.read_text().splitlines()
    lines.insert(1, '# source: "other"')
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"rec\.csv line \d+: meta key 'source' repeats line 2"):
        load(path)


def test_cli_bad_canonical_meta_exits_2_with_one_line(tmp_path: Path) -> None:
    path = _zigzag().to_csv(tmp_path / "rec.csv")
    text = path.read_text().replace("# repairs: []", "# repairs: 5")
    path.write_text(text)
    code, stdout, stderr = _run(["identify", str(path), "--quiet"])
    assert code == 2, stderr
    assert "Traceback" not in stderr
    errors = [ln for ln in stderr.splitlines() if "error:" in ln]
    assert len(errors) == 1 and "meta 'repairs'" in errors[0] and "line" in errors[0], stderr
    assert stdout == ""


# ---------------------------------------------------------------------------------------------
# unit checks on loading
# ---------------------------------------------------------------------------------------------
def _canonical_variant(tmp_path: Path, **channels: np.ndarray) -> Path:
    rec = _zigzag()
    return Record(**{**rec.channels(), **channels}, meta=rec.meta).to_csv(tmp_path / "rec.csv")


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (
            {"psi": lambda rec: np.degrees(rec.psi) % 360.0},
            r"column 'psi_rad' looks like degrees: it jumps from .* \(a heading wrapped at 360 "
            r"deg\).*expected radians",
        ),
        (
            {"psi": lambda rec: np.degrees(rec.psi)},
            r"heading changes 5\d\.\d+ times the integral of the yaw rate.*'psi_rad' looks like "
            r"degrees",
        ),
        (
            {"r": lambda rec: np.degrees(rec.r)},
            r"'r_rad_s' looks like deg/s",
        ),
        (
            {"time": lambda rec: 1000.0 * rec.time},
            r"column 'time_s' looks like milliseconds; expected seconds",
        ),
        (
            {"delta": lambda rec: np.degrees(rec.delta)},
            r"column 'delta_rad' reaches 20\.\d+ rad .* looks like degrees; expected radians",
        ),
        (
            {"U": lambda rec: rec.U / 0.514444},
            r"column 'U_m_s' looks like knots; expected m/s",
        ),
    ],
    ids=["psi-deg-wrapped", "psi-deg", "r-deg-s", "time-ms", "delta-deg", "U-knots"],
)
def test_canonical_unit_errors_refused_naming_the_probable_unit(
    tmp_path: Path, change: dict, expected: str
) -> None:
    rec = _zigzag()
    path = _canonical_variant(tmp_path, **{k: f(rec) for k, f in change.items()})
    with pytest.raises(ValueError, match=r"^rec\.csv: .*" + expected):
        _load_quiet(path)


def _sspa_file(
    tmp_path: Path, time: np.ndarray, psi: np.ndarray, r: np.ndarray, K: float = 0.1
) -> Path:
    rec = _zigzag(K=K)
    rows = np.column_stack([time, -rec.delta, rec.x, rec.y, psi, r])
    path = tmp_path / "sspa.csv"
    body = "\n".join(";".join(repr(float(v)) for v in row) for row in rows)
    path.write_text("time;delta;x0;y0;psi;r\n" + body + "\n")
    return path


def test_sspa_heading_in_degrees_refused(tmp_path: Path) -> None:
    rec = _zigzag(K=0.5)  # a model-scale ship: up to 10 deg/s
    psi = (np.degrees(rec.psi) + 5.0) % 360.0  # wraps 359 -> 0 as a compass does
    path = _sspa_file(tmp_path, rec.time, psi, np.gradient(psi, rec.time), K=0.5)
    with pytest.raises(
        ValueError, match=r"column 'psi' looks like degrees: it jumps from [\d.]+ to 3\d\d\."
    ):
        _load_quiet(path, "sspa")
    psi = np.degrees(rec.psi)  # no wrap: psi and r (its derivative) both in degrees
    path = _sspa_file(tmp_path, rec.time, psi, np.gradient(psi, rec.time), K=0.5)
    with pytest.raises(ValueError, match=r"'r' reaches .* deg/s, and column 'psi'.* like degrees"):
        _load_quiet(path, "sspa")


def test_sspa_time_in_milliseconds_refused_or_warned(tmp_path: Path) -> None:
    rec = _zigzag()
    # r in rad/s but time in ms: the heading changes 1000 times too slowly -> refused
    path = _sspa_file(tmp_path, 1000.0 * rec.time, rec.psi, rec.r)
    with pytest.raises(ValueError, match=r"column 'time' looks like milliseconds"):
        _load_quiet(path, "sspa")
    # r consistent with a time in ms (rad/ms): only the sample interval tells -> warned
    path = _sspa_file(tmp_path, 1000.0 * rec.time, rec.psi, rec.r / 1000.0)
    with pytest.warns(SysidDataWarning, match=r"median sample interval is 500 s .* milliseconds"):
        loaded = load(path, "sspa")
    assert any("unit check" in note for note in loaded.meta["notes"])


def test_consistent_units_load_without_unit_warnings(tmp_path: Path) -> None:
    path = _zigzag().to_csv(tmp_path / "rec.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("error", SysidDataWarning)
        rec = load(path)
    assert not any("unit check" in note for note in rec.meta["notes"])


@needs_data
def test_measured_sources_pass_the_unit_checks() -> None:
    files = sorted(p for p in MEASURED.rglob("*") if p.suffix in (".csv", ".dat"))
    assert files
    for path in files:
        rec = _load_quiet(path)
        assert not any("unit check" in note for note in rec.meta["notes"]), path.name


# ---------------------------------------------------------------------------------------------
# no excitation: not identifiable
# ---------------------------------------------------------------------------------------------
def _without(what: str) -> Record:
    rec = _zigzag()
    rng = np.random.default_rng(3)
    n = rec.n
    chans = rec.channels()
    if what == "rudder":
        chans["delta"] = 1e-3 * rng.standard_normal(n)  # noise only
    elif what == "heading":
        chans["psi"] = 0.3 + 1e-3 * rng.standard_normal(n)
        chans["r"] = 1e-4 * rng.standard_normal(n)
    else:  # all zero
        chans = {"time": rec.time, "delta": np.zeros(n), "psi": np.zeros(n), "r": np.zeros(n)}
    return Record(**chans)


NO_RUDDER = r"not identifiable: no excitation: the rudder never moves \(delta spans"
NO_HEADING = r"not identifiable: no excitation: .*the heading never changes \(psi spans"


@pytest.mark.parametrize(
    ("what", "expected"),
    [
        ("rudder", NO_RUDDER),
        ("heading", NO_HEADING),
        ("all", NO_RUDDER + r".* and the heading never changes"),
    ],
)
def test_fits_refuse_records_without_excitation(what: str, expected: str) -> None:
    rec = _without(what)
    with pytest.raises(ValueError, match=expected):
        fit_output_error(rec.time, rec.delta, rec.psi, rec.r, "nomoto1")
    with pytest.raises(ValueError, match=expected):
        fit_equation_error(rec.time, rec.delta, rec.r, "nomoto1", psi=rec.psi)
    with pytest.raises(ValueError, match=expected):
        identify(rec, "nomoto1", max_effects=0)


def test_held_rudder_refused_in_a_steady_turn_but_not_in_a_step_response() -> None:
    t = 0.5 * np.arange(801)
    rng = np.random.default_rng(4)
    steady = Record(
        time=t,
        delta=np.full(t.size, 0.2),
        psi=0.01 * t,
        r=0.01 + 1e-5 * rng.standard_normal(t.size),
    )
    with pytest.raises(ValueError, match=r"the rudder never moves and the yaw rate never change"):
        identify(steady, "nomoto1", max_effects=0)
    # a rudder held from t = 0 on a straight course: the transient identifies K and T
    step = _zigzag()
    r = 0.1 * 0.2 * (1.0 - np.exp(-step.time / 30.0))
    psi = np.concatenate(([0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(step.time))))
    fit = fit_output_error(step.time, np.full(step.n, 0.2), psi, r, "nomoto1")
    assert fit.values["T"] == pytest.approx(30.0, rel=0.05)


def test_runs_whose_rudder_never_moves_for_different_reasons_are_refused_together() -> None:
    """One run with the rudder at zero, one holding it in a steady turn: in neither does the
    rudder move, so together they identify nothing either."""
    t = 0.5 * np.arange(801)
    rng = np.random.default_rng(5)
    turning = np.cumsum(np.full(t.size, 0.005)) + 0.3 * np.sin(t / 50.0)
    still = Record(time=t, delta=np.zeros(t.size), psi=turning, r=np.gradient(turning, t))
    steady = Record(
        time=t, delta=np.full(t.size, 0.2), psi=0.01 * t,
        r=0.01 + 1e-5 * rng.standard_normal(t.size),
    )  # fmt: skip
    with pytest.raises(ValueError, match=r"the rudder moves in none of the 2 runs"):
        identify([still, steady], "vmm:martin_simple", max_effects=0)


def test_every_family_refuses_a_record_without_excitation() -> None:
    rec = _without("all")
    for model in ("nomoto2", "rvg3dof"):
        with pytest.raises(ValueError, match=NO_RUDDER):
            identify(rec, model, max_effects=0)


def test_cli_record_without_excitation_exits_2(tmp_path: Path) -> None:
    path = _without("rudder").to_csv(tmp_path / "flat.csv")
    code, stdout, stderr = _run(["identify", str(path), "--quiet", "--max-effects", "0"])
    assert code == 2, stderr
    errors = [ln for ln in stderr.splitlines() if "error:" in ln]
    assert len(errors) == 1 and "the rudder never moves" in errors[0], stderr
    assert stdout == ""


def test_excited_record_still_fits() -> None:
    rec = _zigzag()
    fit = fit_output_error(rec.time, rec.delta, rec.psi, rec.r, "nomoto1")
    assert fit.values["K"] == pytest.approx(0.1, rel=0.05)
    assert fit.values["T"] == pytest.approx(30.0, rel=0.05)


def decaying_turn(seed: int = 0) -> Record:
    """A 3.5 m model already in a turn, the rudder held at -35 deg for 200 s while the speed
    falls from 0.23 to 0.07 m/s: nomoto1 with K' = 2, T' = 1.5 scaled by U / L, so the yaw rate
    decays with the speed (-4.6 to -1.8 deg/s), not in response to the rudder."""
    L, dt = 3.5, 0.1
    t = dt * np.arange(2001)
    U = 0.07 + 0.16 * (np.exp(-t / 60.0) - math.exp(-t[-1] / 60.0)) / (1 - math.exp(-t[-1] / 60))
    delta = np.full(t.size, math.radians(-35.0))
    K, T = 2.0 * U / L, 1.5 * L / U
    r = np.empty(t.size)
    r[0] = K[0] * delta[0]
    for k in range(t.size - 1):
        r[k + 1] = r[k] + dt * (K[k] * delta[k] - r[k]) / T[k]
    psi = np.concatenate(([0.0], np.cumsum(0.5 * dt * (r[1:] + r[:-1]))))
    x = np.concatenate(([0.0], np.cumsum(dt * U[:-1] * np.cos(psi[:-1]))))
    y = np.concatenate(([0.0], np.cumsum(dt * U[:-1] * np.sin(psi[:-1]))))
    rng = np.random.default_rng(seed)
    noise = np.radians([0.05, 0.1, 0.02])[:, None] * rng.standard_normal((3, t.size))
    return Record(
        time=t, delta=delta + noise[0], psi=psi + noise[1], r=r + noise[2], x=x, y=y, U=U,
        meta={"L": L},
    )  # fmt: skip


DECAYING = r"not identifiable: no excitation: the rudder never moves and the ship is already turn"


@pytest.mark.parametrize("model", ["nomoto1", "nomoto2", "vmm:martin_simple"])
def test_decaying_turn_with_the_rudder_held_is_refused_in_every_family(model: str) -> None:
    rec = decaying_turn()
    assert math.degrees(rec.r[0]) == pytest.approx(-4.6, abs=0.1)
    assert (rec.U[0], rec.U[-1]) == pytest.approx((0.23, 0.07))
    with pytest.raises(ValueError, match=DECAYING + r".*r starts at -4.6 deg/s"):
        identify(rec, model, max_effects=0)


def test_held_rudder_from_a_straight_start_is_a_step_response() -> None:
    """The same held rudder from a straight course: the yaw rate's change is the response."""
    t = 0.5 * np.arange(801)
    r = 0.1 * 0.2 * (1.0 - np.exp(-t / 30.0))
    psi = np.concatenate(([0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(t))))
    assert excitation_problems(np.full(t.size, 0.2), psi, r) == []
    # started 60 s later, the ship already turns at 87 % of its final rate: refused
    late = slice(120, None)
    problems = excitation_problems(np.full(t.size, 0.2)[late], psi[late], r[late])
    assert [kind for kind, _ in problems] == ["rudder"]
    assert "already turning" in problems[0][1]


def _fit(values: dict[str, float], stderr: dict[str, float], condition: float = 10.0) -> FitResult:
    """A nomoto1 fit result with the given estimates (the reasons read only these)."""
    return FitResult(
        "nomoto1", None, values, stderr, np.zeros((0, 0)), tuple(stderr), np.zeros(6),
        0.0, 0.0, 1.0, "output_error", 100, info={"condition": condition},
    )  # fmt: skip


@pytest.mark.parametrize(
    ("values", "stderr", "filters", "condition", "expected"),
    [
        ({"K": 0.1, "T": 30.0}, {"K": 0.001, "T": 0.5}, None, 10.0, None),
        ({"K": 0.1, "T": 30.0}, {"K": 0.001}, None, 10.0, r"^T = 30 has no standard error$"),
        ({"K": 0.1, "T": 30.0}, {"K": 0.2, "T": 0.5}, None, 10.0,
         r"^K = 0.1 \+- 0.2: the standard error is larger than the estimate$"),
        ({"K": -923.0, "T": 30.0}, {"K": 1.0, "T": 0.5}, None, 10.0,
         r"^K = -923 1/s <= 0: with the Nomoto sign .* rudder sign is reversed$"),
        ({"K": 0.1, "T": 1.7e7}, {"K": 0.01, "T": 1e6}, None, 10.0,
         r"^T = 1.7e\+07 s is more than 10 times the record \(200 s\): .* neither K nor T$"),
        ({"K": 0.1, "T1": 30.0, "T2": 5174.0}, {"K": 0.01, "T1": 1.0}, None, 10.0,
         r"^T2 = 5174 s is more than 10 times the record"),
        ({"K": 0.1, "T": 1e-6}, {"K": 0.01, "T": 1e-7}, None, 10.0,
         r"^T = 1e-06 s is at its lower bound"),
        ({"K": 0.1, "T": 30.0}, {"K": 0.001, "T": 0.5}, {"T_d": 40.0}, 10.0,
         r"^T_d = 40 s is at a bound of its search \[0.1, 40\] s$"),
        ({"K": 0.1, "T": 30.0}, {"K": 0.001, "T": 0.5}, {"tau": 0.0}, 10.0,
         r"^tau = 0 s is at a bound of its search"),
        ({"K": 0.1, "T": 30.0}, {"K": 0.001, "T": 0.5}, None, 1.6e7,
         r"^the fit is ill-conditioned \(condition number 1.6e\+07 > 1e\+06\)"),
    ],
)
def test_each_reason_a_nomoto_fit_is_not_determined(
    values: dict[str, float],
    stderr: dict[str, float],
    filters: dict[str, float] | None,
    condition: float,
    expected: str | None,
) -> None:
    reasons = fit_problems(_fit(values, stderr, condition), 200.0, filters)
    if expected is None:
        assert reasons == []
    else:
        assert len(reasons) == 1, reasons
        assert re.search(expected, reasons[0]), reasons[0]
    assert CONDITION_LIMIT == 1e6


def test_undetermined_and_verdict() -> None:
    values = {"a": 1.0, "b": -0.5, "c": 2.0, "d": math.nan}
    stderr = {"a": 0.1, "b": 0.6, "c": math.nan, "d": 1.0}
    assert undetermined(values, stderr, ["a", "b", "c", "d", "missing"]) == [
        "b = -0.5 +- 0.6: the standard error is larger than the estimate",
        "c = 2 has no standard error",
        "d is not finite (nan)",
    ]
    assert Verdict.of([]).to_dict() == {"identifiable": True, "reasons": []}
    assert Verdict.of(["x"]) == Verdict(False, ("x",))


def _report(fit: Any, params: dict[str, float], stderr: dict[str, float]) -> dict[str, Any]:
    return {"final": fit, "parameters_after": params, "diagnostics": {"final": {"stderr": stderr}}}


def test_rvg_verdict_names_course_stability_and_effects_not_the_calibration_bounds() -> None:
    family = FAMILIES["rvg3dof"]
    values = {"sway_linear_damping": 5e4, "yaw_linear_damping": 8e6, "surge_quadratic_damping":
              100.0, "alpha_0": 0.01, "V_n": 0.2, "V_e": 0.001}  # fmt: skip
    stderr = {"sway_linear_damping": 1e3, "yaw_linear_damping": 1e5,
              "surge_quadratic_damping": 1.0, "alpha_0": 0.001, "V_n": 0.01, "V_e": 0.01}
    fit = SimpleNamespace(values=values, stderr=stderr, effects=("azimuth_offset", "current"),
                          at_bound=("surge_quadratic_damping",))  # fmt: skip
    # a calibrated value at its physical bound is a finding; a current along one axis is fine
    assert family.verdict(None, _report(fit, values, stderr)) == []
    fit.stderr = {**stderr, "yaw_linear_damping": 1e7, "alpha_0": 0.02}
    fit.at_bound = ("sway_linear_damping",)
    reasons = family.verdict(None, _report(fit, values, fit.stderr))
    assert reasons == [
        "yaw_linear_damping = 8e+06 +- 1e+07: the standard error is larger than the estimate",
        "sway_linear_damping is at a bound of its physical range",
        "effect azimuth_offset is not determined: alpha_0 = 0.01 +- 0.02: the standard error "
        "is larger than the estimate",
    ]
    nan = dict.fromkeys(stderr, math.nan)
    assert "the fit has no standard errors" in family.verdict(None, _report(fit, values, nan))[0]


def test_vmm_verdict_names_course_stability_and_conditioning() -> None:
    family = FAMILIES["vmm:martin_simple"]
    coefficients = {"Y_v": 0.0017, "Y_r": 0.16, "N_v": 0.01, "N_r": -0.04, "Y_vvv": 0.0}
    stderr = {"Y_v": 0.0093, "Y_r": 0.02, "N_v": 0.0004, "N_r": 0.005, "Y_vvv": math.nan}
    regression = SimpleNamespace(collinear={"Y_vvv": ["Y_v"]}, condition={"X": 40.0, "Y": 2e4})
    fit = SimpleNamespace(params=SimpleNamespace(coefficients=coefficients), regression=regression,
                          stderr=stderr, effects=(), values=coefficients)  # fmt: skip
    assert family.verdict(None, _report(fit, coefficients, stderr)) == [
        "Y_v = 0.0017 +- 0.0093: the standard error is larger than the estimate",
        "the Y regression is ill-conditioned (condition number 2e+04 > 1e+04): its "
        "coefficients trade for one another",
    ]
    fit.stderr = {**stderr, "Y_v": 0.001}
    regression.condition = {"Y": 500.0}
    assert family.verdict(None, _report(fit, coefficients, fit.stderr)) == []


def test_mmg_verdict_names_a_derivative_at_its_bound() -> None:
    family = FAMILIES["kvlcc2"]
    factors = {"r0": 1.0, "y_v": 2.0, "y_r": 1.1, "n_v": 0.9, "n_r": 1.0}
    stderr = {"r0": 0.01, "y_v": 0.1, "y_r": 1.5, "n_v": 0.1, "n_r": 0.1}
    fit = SimpleNamespace(factors=factors, stderr=stderr, at_bound=["y_v"])
    assert family.verdict(None, _report(fit, factors, stderr)) == [
        "factor on y_r = 1.1 +- 1.5: the standard error is larger than the estimate",
        "y_v is at a bound of its refinement (factor 2 on the published value, bounds "
        "(0.5, 2.0))",
    ]


def test_a_ship_far_slower_than_its_record_is_flagged_not_refused() -> None:
    """K 0.1 1/s and T 3000 s under 200 s of zigzag rudder: the record moves the rudder and
    turns the ship, but fixes only K / T; the result carries the verdict."""
    rec = slow_ship()
    res = identify(rec, "nomoto1", max_effects=0)
    assert not res.verdict.identifiable
    assert len(res.verdict.reasons) >= 1
    assert re.match(r"T = \d+ s is more than 10 times the record \(200 s\)", res.verdict.reasons[0])
    gain_rate = res.parameters_after["K"] / res.parameters_after["T"]
    assert gain_rate == pytest.approx(0.1 / 3000, rel=0.2)
    assert res.to_dict()["verdict"] == {"identifiable": False, "reasons": list(res.verdict.reasons)}
    # a determined ship gets an identifiable verdict
    assert identify(_zigzag(), "nomoto1", max_effects=0).verdict == Verdict(True, ())


def slow_ship(seed: int = 0) -> Record:
    """nomoto1 with K 0.1 1/s and T 3000 s: 200 s of a 20 deg rudder switched every 25 s."""
    dt, K, T = 0.5, 0.1, 3000.0
    t = dt * np.arange(401)
    delta = math.radians(20.0) * np.where((t // 25.0) % 2 == 0, 1.0, -1.0)
    r = np.zeros(t.size)
    for k in range(t.size - 1):
        r[k + 1] = r[k] + dt * (K * delta[k] - r[k]) / T
    psi = np.concatenate(([0.0], np.cumsum(0.5 * dt * (r[1:] + r[:-1]))))
    rng = np.random.default_rng(seed)
    return Record(
        time=t, delta=delta, psi=psi + math.radians(0.05) * rng.standard_normal(t.size),
        r=r + math.radians(0.01) * rng.standard_normal(t.size),
    )  # fmt: skip


def test_cli_refuses_a_decaying_turn_and_flags_an_undetermined_fit(
    tmp_path: Path,
) -> None:
    """The rudder held at -35 deg while the turning model loses speed: refused with exit 2.
    A ship far slower than its record: reported, the warning first and the verdict in the
    JSON, and ``shipgym design`` refuses that file."""
    turn = decaying_turn().to_csv(tmp_path / "turn.csv")
    argv = ["identify", str(turn), "--quiet", "--json", str(tmp_path / "t.json")]
    code, stdout, stderr = _run(argv)
    assert code == 2 and stdout == ""
    assert stderr.count("\n") == 1 and "not identifiable: no excitation: the rudder never" in stderr
    assert not (tmp_path / "t.json").exists()

    slow = slow_ship().to_csv(tmp_path / "slow.csv")
    fit = tmp_path / "slow.json"
    code, stdout, stderr = _run(["identify", str(slow), "--quiet", "--max-effects", "0",
                                 "--json", str(fit)])  # fmt: skip
    assert code == 0, stderr
    assert re.match(r"warning: not identifiable: T = \d+ s is more than 10 times", stderr)
    assert "verdict: NOT IDENTIFIABLE" in stdout and "  - T = " in stdout
    assert stdout.index("verdict:") < stdout.index("parameters:")
    doc = json.loads(fit.read_text())
    assert doc["verdict"]["identifiable"] is False
    assert doc["verdict"]["reasons"][0].startswith("T = ")
    code, stdout, stderr = _run(["design", str(fit)])
    assert code == 2 and stdout == ""
    assert re.search(r"error: .*slow\.json' is not identifiable: T = \d+ s", stderr), stderr


# ---------------------------------------------------------------------------------------------
# header: duplicated column names, byte-order mark
# ---------------------------------------------------------------------------------------------
def test_duplicated_canonical_column_refused(tmp_path: Path) -> None:
    path = _zigzag().to_csv(tmp_path / "rec.csv")
    text = path.read_text().replace(",U_m_s\n", ",psi_rad\n", 1)
    path.write_text(text)
    with pytest.raises(
        ValueError, match=r"column 'psi_rad' appears 2 times in the header \(columns 3, 7\)"
    ):
        load(path)


def test_duplicated_column_refused_in_named_header_formats(tmp_path: Path) -> None:
    path = tmp_path / "usv.csv"
    path.write_text("time,lon,lat,speed,heading,rudder,heading\n0,1,2,3,4,5,6\n1,1,2,3,4,5,6\n")
    with pytest.raises(ValueError, match=r"column 'heading' appears 2 times"):
        load(path, "usv")


def test_utf8_bom_before_canonical_header_accepted(tmp_path: Path) -> None:
    plain = _zigzag().to_csv(tmp_path / "plain.csv")
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())
    a, b = load(plain), load(bom)  # detected as canonical despite the BOM
    for name, value in a.channels().items():
        np.testing.assert_array_equal(getattr(b, name), value)
    assert b.meta == a.meta


@needs_data
@pytest.mark.parametrize(
    "rel",
    [
        "sspa_blog_zigzag/example_zigzag.csv",
        "marin_kvlcc2/MARIN_FREE_KVLCC2_zz_10_m.dat",
        "hsva_kvlcc2/HSVA_CPMC_KVLCC2_Z_10_10_S.dat",
        "esso_osaka_frt/zigzag/zigzag_31-Jul-2020_13_04_24.csv",
        "usv_field/zigzag_30_inter_xy.csv",
        "gunnerus_seatrials/RVG_ManeuveringTests.csv",
    ],
)
def test_utf8_bom_accepted_for_every_source_format(tmp_path: Path, rel: str) -> None:
    src = MEASURED / rel
    copy = tmp_path / src.parent.name / src.name  # keeps the folder name used for detection
    copy.parent.mkdir()
    copy.write_bytes(b"\xef\xbb\xbf" + src.read_bytes())
    a, b = _load_quiet(src), _load_quiet(copy)
    for name, value in a.channels().items():
        np.testing.assert_array_equal(getattr(b, name), value)


# ---------------------------------------------------------------------------------------------
# large records
# ---------------------------------------------------------------------------------------------
def test_large_record_warns_and_shows_progress(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _zigzag(n=3000).to_csv(tmp_path / "rec.csv")
    monkeypatch.setattr(data_module, "LARGE_RECORD_SAMPLES", 2000)
    monkeypatch.setattr(data_module, "PROGRESS_FILE_BYTES", 1000)
    monkeypatch.setattr(data_module, "_PARSE_CHUNK", 1000)
    err = io.StringIO()
    with (
        contextlib.redirect_stderr(err),
        pytest.warns(SysidDataWarning, match=r"rec\.csv: large record of 3,000 samples"),
    ):
        rec = load(path)  # default progress: stderr, as the file is above the size
    assert rec.n == 3000
    lines = err.getvalue().splitlines()
    assert lines[0].startswith("loading rec.csv (")
    assert any("parsed 2,000 of 3,000 rows" in ln for ln in lines), lines
    assert lines[-1].startswith("loaded rec.csv: 3,000 samples")
    seen: list[str] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidDataWarning)
        load(path, progress=seen.append)
    assert len(seen) == len(lines)


def test_small_record_is_silent(tmp_path: Path) -> None:
    path = _zigzag().to_csv(tmp_path / "rec.csv")
    err = io.StringIO()
    with contextlib.redirect_stderr(err), warnings.catch_warnings():
        warnings.simplefilter("error", SysidDataWarning)
        load(path)
    assert err.getvalue() == ""


def test_canonical_parse_has_no_per_row_python_loop(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A clean file is parsed by numpy in chunks (the row-by-row parser was about 7 times slower
    for 2 million rows); the row-by-row parser is only the fallback that names a bad line."""
    path = _zigzag().to_csv(tmp_path / "rec.csv")

    def refuse(*args: object) -> None:
        raise AssertionError("clean rows went through the row-by-row parser")

    monkeypatch.setattr(data_module, "_parse_rows_slow", refuse)
    rec = _load_quiet(path)
    np.testing.assert_array_equal(rec.psi, _zigzag().psi)


def test_partial_rows_still_named_after_the_fast_parse(tmp_path: Path) -> None:
    path = _zigzag().to_csv(tmp_path / "rec.csv")
    lines = path.read_text().splitlines()
    header = next(i for i, ln in enumerate(lines) if ln.startswith("time_s"))
    fields = lines[header + 10].split(",")
    lines[header + 10] = ",".join(fields[:-1])
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=rf"rec\.csv line {header + 11}: expected 7 fields, got 6"):
        load(path)

"""Tests of ``shipgym identify`` (:mod:`shipgym.cli`) and :mod:`shipgym.sysid.plots`."""

from __future__ import annotations

import contextlib
import io
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from matplotlib.figure import Figure

from shipgym.cli import main
from shipgym.sysid.engine import IdentificationResult
from shipgym.sysid.generator import generate_record
from shipgym.sysid.plots import MAX_WINDOW_LINES, plot_identification

# one worker runs this file: its module fixtures are built once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_sysid_cli")

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
JSON_KEYS = {
    "model",
    "parameters_before",
    "error_before",
    "effects",
    "parameters",
    "error_after",
    "window_s",
    "heldout",
    "rounds",
    "runtime_s",
    "verdict",
}
PROGRESS = re.compile(r"^\[\s*\d+\.\d s\] ", flags=re.M)


def _is_png(path: Path) -> bool:
    return path.is_file() and path.stat().st_size > 10_000 and path.read_bytes()[:8] == PNG_MAGIC


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def records(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Canonical CSVs of a 400 s zigzag with an undeclared rudder offset and of a clean one."""
    root = tmp_path_factory.mktemp("records")
    out = {}
    for name, effect in (("offset", "rudder_offset"), ("clean", None)):
        rec = generate_record(effect, maneuver="zigzag", dt=0.5, duration=400, seed=0)
        out[name] = rec.to_csv(root / f"{name}.csv")
    return out


@pytest.fixture(scope="module")
def offset_run(
    records: dict[str, Path], tmp_path_factory: pytest.TempPathFactory
) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("offset_run")
    argv = [
        "identify",
        str(records["offset"]),
        "--json",
        str(out / "result.json"),
        "--plot",
        str(out / "result.png"),
        "--max-effects",  # one round of candidates keeps the test short
        "1",
    ]
    code, stdout, stderr = _run(argv)
    return {"code": code, "out": stdout, "err": stderr, "dir": out}


def test_identify_finds_the_rudder_offset(offset_run: dict[str, Any]) -> None:
    assert offset_run["code"] == 0, offset_run["err"]
    doc = json.loads((offset_run["dir"] / "result.json").read_text())
    assert set(doc) >= JSON_KEYS
    assert doc["model"] == "nomoto1"
    assert [e["name"] for e in doc["effects"]] == ["rudder_offset"]
    for effect in doc["effects"]:
        assert set(effect) == {"name", "parameters", "evidence"}
    assert "delta0" in doc["parameters"] and "delta0" not in doc["parameters_before"]
    before, after = doc["error_before"], doc["error_after"]
    assert after["psi_rms_deg"] < 0.5 * before["psi_rms_deg"]
    for err in (before, after):
        assert {"psi_rms_deg", "r_rms_deg_s", "xy_rms_m"} <= set(err)  # the record has x, y
        assert all(math.isfinite(v) and v >= 0 for v in err.values())
    assert doc["window_s"] is None  # 400 s: one free run
    assert doc["verdict"] == {"identifiable": True, "reasons": []}
    assert _is_png(offset_run["dir"] / "result.png")
    # nothing but the two outputs (no temporary files left behind)
    assert sorted(p.name for p in offset_run["dir"].iterdir()) == ["result.json", "result.png"]


def test_identify_summary_and_progress(offset_run: dict[str, Any]) -> None:
    out, err = offset_run["out"], offset_run["err"]
    assert "model: nomoto1\nverdict: identifiable\n" in out
    assert "warning:" not in err
    assert re.search(r"psi RMS \[deg\]\s+[\d.]+\s+[\d.]+", out), out
    assert re.search(r"1\. rudder_offset: .*delta0 = -?[\d.e-]+ rad \(-?[\d.]+ deg\)", out), out
    assert re.search(r"evidence: BIC change -\d", out), out
    assert "held-out part from" in out and "runtime:" in out
    assert "wrote" in out and "result.json" in out and "result.png" in out
    # progress on stderr: one line per candidate, with the elapsed time
    assert len(PROGRESS.findall(err)) >= 6
    assert "accepted rudder_offset" in err
    assert "Traceback" not in err


def test_identify_clean_record_json_to_stdout_with_window(
    records: dict[str, Path], tmp_path: Path
) -> None:
    argv = ["identify", str(records["clean"]), "--window", "100", "--json", "-", "--quiet"]
    code, stdout, stderr = _run(argv)
    assert code == 0, stderr
    doc = json.loads(stdout)  # stdout holds the JSON only
    assert set(doc) >= JSON_KEYS
    assert doc["effects"] == []
    assert doc["window_s"] == 100.0
    assert "effects added: none" in stderr  # the summary went to stderr
    assert "4 consecutive windows of 100 s" in stderr
    assert not PROGRESS.search(stderr)  # --quiet


def _bad_cases(records: dict[str, Path], tmp: Path) -> dict[str, tuple[list[str], list[str]]]:
    short = generate_record(None, dt=0.5, duration=20, seed=0).to_csv(tmp / "short.csv")
    unknown = tmp / "notes.txt"
    unknown.write_text("hello\n")
    rec = str(records["offset"])
    return {
        "missing file": ([str(tmp / "nope.csv")], ["nope.csv", "does not exist"]),
        "unknown model": ([rec, "--model", "foo"], ["--model", "'foo'", "nomoto1"]),
        "unknown format": ([rec, "--format", "foo"], ["--format", "'foo'", "canonical"]),
        "negative window": ([rec, "--window", "-3"], ["--window", "'-3'", "[1, 1e6]"]),
        "holdout too large": ([rec, "--holdout", "0.95"], ["holdout", "0.95", "[0.1, 0.6]"]),
        "wrong format": ([rec, "--format", "sspa"], ["sspa", "header"]),
        "undetectable": ([str(unknown)], ["cannot detect the format", "--format"]),
        "too short": ([str(short)], ["too short"]),
        "plot not png": ([rec, "--plot", str(tmp / "x.jpg")], ["--plot", ".png"]),
    }


@pytest.mark.parametrize(
    "case",
    [
        "missing file",
        "unknown model",
        "unknown format",
        "negative window",
        "holdout too large",
        "wrong format",
        "undetectable",
        "too short",
        "plot not png",
    ],
)
def test_identify_bad_input_exit_2_and_no_output(
    case: str, records: dict[str, Path], tmp_path: Path
) -> None:
    args, expected = _bad_cases(records, tmp_path)[case]
    before = set(tmp_path.iterdir())
    out_json, out_png = tmp_path / "out.json", tmp_path / "out.png"
    argv = ["identify", *args, "--quiet"]
    if "--plot" not in args:
        argv += ["--plot", str(out_png)]
    code, stdout, stderr = _run([*argv, "--json", str(out_json)])
    assert code == 2, stderr
    assert "Traceback" not in stderr
    message = [line for line in stderr.splitlines() if "error:" in line]
    assert len(message) == 1, stderr  # one line names the problem
    for text in expected:
        assert text in message[0], message[0]
    assert set(tmp_path.iterdir()) == before  # no output, no temporary file
    assert stdout == ""


def test_identify_checks_the_output_directory_before_the_run(
    records: dict[str, Path], tmp_path: Path
) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    target = blocker / "runs" / "out.json"
    code, _, stderr = _run(["identify", str(records["offset"]), "--json", str(target)])
    assert code == 2
    assert "--json" in stderr and "is a file" in stderr
    assert not PROGRESS.search(stderr)  # refused before loading


def test_identify_makes_missing_output_folders(records: dict[str, Path], tmp_path: Path) -> None:
    target = tmp_path / "runs" / "fits" / "out.json"
    code, _, _ = _run(["identify", str(records["offset"]), "--json", str(target), "--quiet"])
    assert code == 0
    assert json.loads(target.read_text())["model"]


def test_identify_rvg3dof(tmp_path: Path) -> None:
    from shipgym.sysid.families.rvg import RVG_WINDOW_S

    rec = generate_record(
        None, base_model="rvg3dof", maneuver="zigzag", dt=1.0, duration=300, seed=0
    ).to_csv(tmp_path / "rvg.csv")
    out_json, out_png = tmp_path / "rvg.json", tmp_path / "rvg.png"
    # the command's output for this family; the effect loop is the library tests' business
    argv = ["identify", str(rec), "--model", "rvg3dof", "--max-effects", "0"]
    argv += ["--json", str(out_json)]
    code, stdout, stderr = _run([*argv, "--plot", str(out_png), "--quiet"])
    assert code == 0, stderr
    doc = json.loads(out_json.read_text())
    assert set(doc) >= JSON_KEYS and doc["model"] == "rvg3dof"
    assert doc["window_s"] == RVG_WINDOW_S
    for err in (doc["error_before"], doc["error_after"]):
        assert {"psi_rms_deg", "r_rms_deg_s", "xy_rms_m", "u_rms_m_s"} <= set(err)
    assert "u RMS [m/s]" in stdout
    assert _is_png(out_png)
    # the report is a model file of the identified Gunnerus
    from shipgym.models.model_file import load_model

    assert load_model(out_json).name == "rvg3dof"


# ------------------------------------------------------------------------------------------
# plot_identification
# ------------------------------------------------------------------------------------------
def _fake_result(channels: tuple[str, ...], window_s: float | None, n_windows: int = 1) -> Any:
    t = np.linspace(0.0, 200.0, 401)
    traces: dict[str, Any] = {
        "time": t,
        "split": 280,
        "window_starts": np.linspace(0, t.size, n_windows, endpoint=False).astype(int),
    }
    truth = {
        "psi": 0.5 * np.sin(0.03 * t),
        "r": 0.015 * np.cos(0.03 * t),
        "x": 5.0 * t,
        "y": 40.0 * np.sin(0.02 * t),
        "u": 5.0 + 0.1 * np.cos(0.03 * t),
    }
    for ch in channels:
        traces[ch] = {
            "measured": truth[ch],
            "before": 1.2 * truth[ch],
            "after": 1.01 * truth[ch],
        }
    errors = {"psi_rms_deg": 1.0, "r_rms_deg_s": 0.1}
    return IdentificationResult(
        model="nomoto1",
        base=None,
        final=None,
        effects=[{"name": "rudder_offset", "parameters": {}, "evidence": {}}],
        diagnostics={},
        parameters_before={},
        parameters_after={},
        error_before=errors,
        error_after={k: 0.1 * v for k, v in errors.items()},
        window_s=window_s,
        traces=traces,
    )


@pytest.mark.parametrize(
    ("channels", "n_axes"),
    [
        (("psi", "r"), 4),  # psi, r, two residual rows
        (("psi", "r", "x", "y"), 5),  # + track
        (("psi", "r", "u"), 5),  # + surge speed row
        (("psi", "r", "x", "y", "u"), 6),
    ],
)
def test_plot_identification_axes(channels: tuple[str, ...], n_axes: int) -> None:
    fig = plot_identification(_fake_result(channels, None), title="test")
    assert isinstance(fig, Figure)
    assert len(fig.axes) == n_axes
    title = fig.get_suptitle()
    assert "test" in title and "nomoto1" in title and "rudder_offset" in title
    assert "psi RMS 1 -> 0.1 deg" in title


def test_plot_identification_windows_and_file(tmp_path: Path) -> None:
    def window_lines(fig: Figure) -> int:
        return sum(1 for line in fig.axes[0].get_lines() if line.get_linestyle() == ":")

    few = plot_identification(_fake_result(("psi", "r"), 50.0, n_windows=4), tmp_path / "a.png")
    assert window_lines(few) == 3  # starts after the first
    assert _is_png(tmp_path / "a.png")
    many = plot_identification(_fake_result(("psi", "r"), 1.0, n_windows=MAX_WINDOW_LINES + 5))
    assert window_lines(many) == 0
    with pytest.raises(ValueError, match="traces"):
        plot_identification(_fake_result((), None))


@pytest.mark.parametrize("quiet", [False, True])
def test_loader_progress_lines_follow_quiet(
    records: dict[str, Path], monkeypatch: pytest.MonkeyPatch, quiet: bool
) -> None:
    """A file above the loader's progress threshold (lowered here) reports its loading on
    stderr unless ``--quiet``."""
    import shipgym.sysid.ingest

    monkeypatch.setattr(shipgym.sysid.ingest, "PROGRESS_FILE_BYTES", 0)
    argv = ["identify", str(records["clean"]), "--max-effects", "0", "--window", "none"]
    code, _, stderr = _run(argv + ["--quiet"] * quiet)
    assert code == 0, stderr
    assert ("format canonical" in stderr) is not quiet, stderr

"""Tests of the ``shipgym`` command line (:mod:`shipgym.cli`) and the demo/bench behind it."""

from __future__ import annotations

import json
import math
import re
import statistics
import subprocess
import sys
from pathlib import Path

import pytest

from shipgym.cli import SUBCOMMANDS, main
from shipgym.envs import CURRENT_ENV_IDS, ENV_IDS
from shipgym.envs.kernels import available_threads

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
REPO = Path(__file__).resolve().parents[1]


def _is_png(path: Path) -> bool:
    return path.is_file() and path.stat().st_size > 10_000 and path.read_bytes()[:8] == PNG_MAGIC


def test_demo_writes_figures_and_plausible_summary(tmp_path: Path, capsys) -> None:
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out)]) == 0
    stdout = capsys.readouterr().out
    assert _is_png(out / "zigzag.png")
    assert _is_png(out / "path_following.png")
    assert str(out / "zigzag.png") in stdout and str(out / "path_following.png") in stdout
    assert sorted(p.name for p in out.iterdir()) == ["path_following.png", "zigzag.png"]

    first, second = (
        float(v)
        for v in re.search(
            r"first overshoot ([-\d.]+) deg, second overshoot ([-\d.]+) deg", stdout
        ).groups()
    )
    # The linear first-order Mariner model's 20/20 zigzag (shipgym.maneuvers.zigzag): first
    # overshoot 28.165 deg, second 55.541 deg, printed to 0.1 deg
    assert first == pytest.approx(28.165, abs=0.05)
    assert second == pytest.approx(55.541, abs=0.05)
    assert re.search(r"completed yes", stdout), stdout
    mean_e = float(re.search(r"mean \|cross-track\| ([\d.]+) m", stdout).group(1))
    assert 0.0 < mean_e < 30.0


def test_bench_runs_and_writes_ratios(tmp_path: Path, capsys) -> None:
    out = tmp_path / "bench.json"
    plot = tmp_path / "bench.png"
    argv = [
        "bench",
        "--steps",
        "40",
        "--num-envs",
        "4",
        "--repeats",
        "3",
        "--json",
        str(out),
        "--plot",
        str(plot),
    ]
    assert main(argv) == 0
    captured = capsys.readouterr()
    report = json.loads(out.read_text())
    counts = sorted({1, available_threads()})  # one thread and one per CPU
    assert set(report["ratios"]["single"]) == set(CURRENT_ENV_IDS)
    # the envs with a vector target also without building their info, and never checked then
    lean = {"shipgym/NomotoHeading-v0", "shipgym/RVGPathFollowing-v1"}
    assert set(report["ratios"]["vector"]) == {
        f"{e} threads={t}" for e in CURRENT_ENV_IDS for t in counts
    } | {f"{e} threads={t} no info" for e in lean for t in counts}
    assert all(r["target"] is None for r in report["results"] if not r["info"])
    for kind in ("single", "vector"):
        assert all(math.isfinite(v) and v > 0 for v in report["ratios"][kind].values())
    assert report["config"]["num_envs"] == 4
    assert report["config"]["busy"] == 0
    assert _is_png(plot)
    # a table row per measurement with PASS/MISS where there is a target
    assert captured.out.count("| single env step time |") == len(CURRENT_ENV_IDS) + 1
    assert re.search(r"NomotoHeading-v0 .*\| (PASS|MISS) \|", captured.out)
    assert re.search(r"NomotoHeading-v0 \| \d, no info \|", captured.out)
    # each ratio is the median of the ratios to CartPole timed in the same round
    results = report["results"]
    reference = {r["kind"]: r["repeats"] for r in results if r["ratio"] is None}
    for r in results:
        assert len(r["repeats"]) == 3
        if r["ratio"] is not None:
            same_round = [a / b for a, b in zip(r["repeats"], reference[r["kind"]], strict=True)]
            assert r["round_ratios"] == pytest.approx(same_round, rel=1e-12)
            assert r["ratio"] == pytest.approx(statistics.median(same_round), rel=1e-12)
    # progress: a line per round, then one per measurement
    assert len(re.findall(r"^  round \d/3 done", captured.err, flags=re.M)) == 3
    n = 2 * (len(CURRENT_ENV_IDS) + 1) + (len(CURRENT_ENV_IDS) + len(lean)) * len(counts)
    n -= len(CURRENT_ENV_IDS)
    assert len(re.findall(rf"^\[\s*\d+/{n}\]", captured.err, flags=re.M)) == n


class _CountingFlag:
    """A stop flag that reads unset ``unset`` times, then set. It has only ``is_set``: a loop
    that waited on it (``wait``) or slept instead of polling would fail."""

    def __init__(self, unset: int) -> None:
        self.unset = unset
        self.polls = 0

    def is_set(self) -> bool:
        self.polls += 1
        return self.polls > self.unset


def test_busy_helper_spins_until_its_flag_is_set() -> None:
    """The loop of a ``bench --busy`` helper keeps its core busy: it only polls its stop flag
    between bursts of arithmetic, never waits on it, and returns at the first poll that finds
    it set (checked by counting the polls, so the machine's load plays no part)."""
    from shipgym.bench import _spin

    for unset in (0, 1, 5):
        flag = _CountingFlag(unset)
        _spin(flag)
        assert flag.polls == unset + 1


def test_busy_cores_start_their_helpers_and_leave_nothing_running() -> None:
    """``BusyCores`` runs one live helper process (the loop above) per core asked for, and
    each has stopped at its flag once the block ends."""
    from shipgym.bench import BusyCores

    with BusyCores(2) as busy:
        procs = list(busy._procs)
        assert len(procs) == 2 and all(p.is_alive() for p in procs)
    assert not any(p.is_alive() for p in procs)
    assert all(p.exitcode == 0 for p in procs)  # stopped by the flag, not terminated
    with BusyCores(0) as idle:
        assert idle._procs == []
    with pytest.raises(ValueError, match=r"busy must be an integer in \[0, 64\]"):
        BusyCores(-1)


def test_bench_busy_runs_both_paths_without_targets(tmp_path: Path, capsys) -> None:
    out = tmp_path / "busy.json"
    argv = ["bench", "--steps", "20", "--num-envs", "4", "--repeats", "1", "--busy", "1"]
    assert main([*argv, "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["config"]["busy"] == 1
    assert all(r["passed"] is None for r in report["results"])  # targets are for idle cores
    assert "1 busy helper processes" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "bad"),
    [
        (["demo", "--model", "foo"], "'foo'"),
        (["bench", "--steps", "0"], "'0'"),
        (["bench", "--num-envs", "many"], "'many'"),
        (["frobnicate"], "'frobnicate'"),
        # every numeric flag is bounded before the run: no traceback, no huge allocation
        (["evaluate", "--env", "shipgym/RVGHeading-v1", "--seed", "-1"], "'-1'"),
        (["evaluate", "--env", "shipgym/RVGHeading-v1", "--episodes", "1e20"], "'1e20'"),
        (["evaluate", "--env", "shipgym/RVGHeading-v1", "--episodes", "100000000000"], "[1, "),
        (["evaluate", "--env", "shipgym/RVGHeading-v1", "--max-current-speed", "1e308"], "m/s"),
        (["simulate", "zigzag", "--dt", "1e-9"], "'1e-9'"),
        (["simulate", "zigzag", "--reversals", "1000000"], "'1000000'"),
        (["identify", "x.csv", "--window", "1e-9"], "'1e-9'"),
        (["identify", "x.csv", "--max-effects", "99"], "'99'"),
        (["train", "--env", "shipgym/RVGSpeed-v1", "--algo", "ppo", "--timesteps", "1e12"], "1e12"),
        (["benchmark", "--episodes", "2000000"], "'2000000'"),
        (["benchmark", "--seed", "99999999999"], "'99999999999'"),
        (["bench", "--num-envs", "1000000000"], "'1000000000'"),
    ],
)
def test_bad_arguments_exit_2_with_a_message(argv: list[str], bad: str, capsys) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "error" in err and bad in err
    assert "Traceback" not in err


def test_bad_output_directory_is_a_clean_error(tmp_path: Path, capsys) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    assert main(["demo", "--out", str(blocker / "sub")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("shipgym: error: ") and str(blocker / "sub") in err


def test_envs_lists_every_id(capsys) -> None:
    assert main(["envs"]) == 0
    out = capsys.readouterr().out
    for env_id in ENV_IDS:
        assert env_id in out
    assert re.search(r"shipgym/NomotoHeading-v0\s+1\s+3\s+1\s", out)
    assert re.search(r"shipgym/RVGPathFollowing-v0\s+2\s+9\s+0.5\s", out)


def test_help_and_version(capsys) -> None:
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    for name in SUBCOMMANDS:
        assert name in out
    assert main(["--version"]) == 0
    assert "shipgym" in capsys.readouterr().out


@pytest.mark.parametrize("script", ["demo.py", "bench.py"])
def test_scripts_are_thin_wrappers(script: str) -> None:
    proc = subprocess.run(
        [sys.executable, str(REPO / "scripts" / script), "--help"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert f"usage: shipgym {script.removesuffix('.py')}" in proc.stdout


def test_simulate_takes_the_rvg_parameter_set(tmp_path: Path) -> None:
    """``--params sea_trials`` simulates the identified Gunnerus (a wider, stable turn at the
    same azimuth than seed 001's) and is refused for a Nomoto model."""
    import json

    diam = {}
    for name in ("seed001", "sea_trials"):
        out = tmp_path / f"{name}.json"
        argv = ["simulate", "turning", "--model", "rvg3dof", "--params", name, "--json", str(out)]
        assert main(argv) == 0
        doc = json.loads(out.read_text())
        assert doc["params"] == name
        diam[name] = doc["tactical_diameter_m"]
    assert diam["sea_trials"] != pytest.approx(diam["seed001"], rel=0.05)
    assert main(["simulate", "turning", "--params", "sea_trials"]) == 2


def _no_run(*args: object, **kwargs: object) -> None:
    raise AssertionError("the run started before its outputs were checked")


@pytest.mark.parametrize(
    ("argv", "flag", "named"),
    [
        (["bench", "--json", "/proc/x.json"], "--json", "/proc/x.json"),
        (["bench", "--json", "{tmp}/file.txt/b.json"], "--json", "file.txt"),
        (["bench", "--plot", "{tmp}"], "--plot", ".png"),
        (
            ["simulate", "zigzag", "--json", "{tmp}/ok.json", "--plot", "{tmp}/file.txt/x.png"],
            "--plot",
            "file.txt",
        ),
        (["simulate", "zigzag", "--json", "{tmp}/dir.json"], "--json", "dir.json"),
        (
            ["evaluate", "--env", "shipgym/RVGHeading-v1", "--plot", "{tmp}/file.txt"],
            "--plot",
            "file.txt",
        ),
        (
            ["evaluate", "--env", "shipgym/RVGHeading-v1", "--json", "/proc/e.json"],
            "--json",
            "/proc/e.json",
        ),
        (["benchmark", "--out", "{tmp}/file.txt/deeper"], "--out", "file.txt"),
        (["benchmark", "--plots", "/proc/figures"], "--plots", "/proc/figures"),
        (["identify", "{tmp}/file.txt", "--json", "/proc/fit.json"], "--json", "/proc/fit.json"),
        (
            ["train", "--env", "shipgym/RVGSpeed-v1", "--algo", "ppo", "--out", "/proc/agents"],
            "--out",
            "/proc/agents",
        ),
        (["demo", "--out", "/proc/demo"], "--out", "/proc/demo"),
    ],
)
def test_outputs_are_checked_before_the_run_and_nothing_is_created(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys, argv: list[str], flag: str, named: str
) -> None:
    import importlib

    for module, name in [
        ("shipgym.bench", "run_bench"),
        ("shipgym.benchmark", "evaluate"),
        ("shipgym.benchmark.runner", "run_benchmark"),
        ("shipgym.demo", "run_demo"),
        ("shipgym.maneuvers", "zigzag"),
        ("shipgym.rl.train", "train"),
    ]:
        monkeypatch.setattr(importlib.import_module(module), name, _no_run)
    (tmp_path / "dir.json").mkdir()
    (tmp_path / "file.txt").write_text("x")
    before = sorted(tmp_path.rglob("*"))
    assert main([a.replace("{tmp}", str(tmp_path)) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("shipgym: error: ") and flag in err and named in err, err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert sorted(tmp_path.rglob("*")) == before


def test_simulate_writes_both_outputs_and_no_temporary_file(tmp_path: Path, capsys) -> None:
    json_path, png = tmp_path / "ok.json", tmp_path / "ok.png"
    png.write_bytes(b"an older figure, replaced")
    argv = ["simulate", "zigzag", "--json", str(json_path), "--plot", str(png)]
    assert main(argv) == 0
    assert json.loads(json_path.read_text())["overshoots_deg"]
    assert _is_png(png)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.json", "ok.png"]


def test_a_failed_write_leaves_no_output_and_names_the_target(tmp_path: Path) -> None:
    from shipgym._io import write_atomically

    def fail(path: Path) -> None:
        path.write_text("half")
        raise OSError(28, "No space left on device")

    first, second = tmp_path / "a.json", tmp_path / "b.png"
    with pytest.raises(OSError, match=r"cannot write '.*b\.png': No space left on device"):
        write_atomically([(first, lambda p: p.write_text("{}")), (second, fail)])
    assert list(tmp_path.iterdir()) == []

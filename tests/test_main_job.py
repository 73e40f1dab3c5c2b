"""The main job talks and measures honestly: ``shipgym benchmark`` says at once what it runs and,
from a cold kernel cache, that it compiles and about how long; the PPO throughput comparison
runs only with ``--throughput`` and, when other processes shared the cores, says the machine was
busy instead of judging the ratio."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from shipgym import warmup
from shipgym.benchmark import throughput
from shipgym.benchmark.throughput import (
    BUSY,
    BUSY_SHARE,
    CARTPOLE,
    TARGET_RATIO,
    LoadMeter,
    machine_busy,
    ppo_throughput,
    throughput_table,
    verdict,
)
from shipgym.cli import build_parser, main

ENV = "shipgym/RVGSpeed-v1"


# ------------------------------------------------------------------------------------------
# the verdict and the load
# ------------------------------------------------------------------------------------------
def test_verdict_on_synthetic_loads() -> None:
    idle, busy = 0.02, 0.5  # cores used by other processes, of two
    assert verdict(0.5, TARGET_RATIO, busy, 2) == BUSY == "machine busy: not comparable"
    assert verdict(1.2, TARGET_RATIO, busy, 2) == BUSY  # not even a good ratio counts
    assert verdict(0.5, TARGET_RATIO, idle, 2) == "MISSED"
    assert verdict(TARGET_RATIO, TARGET_RATIO, idle, 2) == "met"
    assert verdict(1.2, TARGET_RATIO, None, 2) == "met"  # load unknown on this system
    # the threshold is a share of the machine: 0.5 cores of 8 is idle enough
    assert verdict(0.5, TARGET_RATIO, busy, 8) == "MISSED"
    assert machine_busy(BUSY_SHARE * 2 + 1e-9, 2) and not machine_busy(BUSY_SHARE * 2, 2)
    with pytest.raises(ValueError, match="cpus must be >= 1, got 0"):
        machine_busy(0.1, 0)


def test_load_meter_counts_the_cpu_time_of_other_processes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Over a 2 s interval the machine was busy 3 CPU seconds more (``/proc/stat``), of which
    this process used 1: the others used 1 core on average."""
    tick = os.sysconf("SC_CLK_TCK")
    stat = tmp_path / "stat"

    def write(busy_s: float, idle_s: float) -> None:
        # user nice system idle iowait irq softirq steal guest guest_nice, in ticks
        user, idle = round(busy_s * tick), round(idle_s * tick)
        stat.write_text(f"cpu  {user} 0 0 {idle} 0 0 0 0 0 0\ncpu0 1 2 3 4\n")

    clock = iter([100.0, 102.0])
    own = iter([10.0, 11.0])
    monkeypatch.setattr(throughput, "_STAT", str(stat))
    monkeypatch.setattr(throughput, "time", SimpleNamespace(perf_counter=lambda: next(clock)))
    monkeypatch.setattr(throughput, "_own_cpu_s", lambda: next(own))
    write(50.0, 500.0)
    meter = LoadMeter()
    with meter:
        write(53.0, 501.0)
    assert meter.load["other_cores"] == pytest.approx(1.0)
    # without /proc/stat: the load average less this process's own use
    monkeypatch.setattr(throughput, "_STAT", str(tmp_path / "missing"))
    monkeypatch.setattr(throughput.os, "getloadavg", lambda: (1.75, 1.0, 1.0))
    clock = iter([100.0, 102.0])
    own = iter([10.0, 11.0])
    with meter:
        pass
    assert meter.load == {"other_cores": pytest.approx(1.25), "load_avg_1min": 1.75}


def _fake_runs(
    rates: dict[str, list[float]], others: dict[str, list[float]]
) -> Any:  # a stand-in for ppo_steps_per_second
    calls: dict[str, int] = {}

    def run(env_id: str, timesteps: int, seed: int = 0, meter: LoadMeter | None = None) -> float:
        k = calls[env_id] = calls.get(env_id, -1) + 1
        assert meter is not None
        meter.load = {"other_cores": others[env_id][k], "load_avg_1min": 1.0}
        return rates[env_id][k]

    return run


def test_throughput_judges_only_runs_on_an_idle_machine(monkeypatch: pytest.MonkeyPatch) -> None:
    """Two interleaved rounds; the ratio compares the best runs, and the verdict is "machine
    busy" when other processes loaded the cores during either of the two runs compared."""
    cpus = os.cpu_count() or 1
    idle, busy = 0.0, BUSY_SHARE * cpus + 0.5
    ships = ["shipgym/A", "shipgym/B", "shipgym/C"]
    rates = {CARTPOLE: [1000.0, 900.0], ships[0]: [500.0, 950.0], ships[1]: [400.0, 300.0]}
    rates[ships[2]] = [950.0, 100.0]
    others = {CARTPOLE: [idle, busy], ships[0]: [busy, idle], ships[1]: [idle, idle]}
    others[ships[2]] = [busy, idle]
    monkeypatch.setattr(throughput, "ppo_steps_per_second", _fake_runs(rates, others))
    lines: list[str] = []
    rows = ppo_throughput(ships, timesteps=10, repeats=2, progress=lines.append)
    assert len(lines) == 8 and "other processes" in lines[0]
    by_env = {r["env"]: r for r in rows}
    assert [r["env"] for r in rows] == [CARTPOLE, *ships]
    # the best runs: CartPole's first (idle), A's second (idle), B's first (idle), C's first (busy)
    assert by_env[ships[0]]["ratio"] == 0.95 and by_env[ships[0]]["verdict"] == "met"
    assert by_env[ships[1]]["ratio"] == 0.4 and by_env[ships[1]]["verdict"] == "MISSED"
    assert by_env[ships[1]]["met"] is False and by_env[ships[0]]["met"] is True
    assert by_env[ships[2]]["machine_busy"] and by_env[ships[2]]["verdict"] == BUSY
    assert by_env[ships[2]]["met"] is None
    assert by_env[ships[2]]["other_cores"] == [busy, idle] and by_env[ships[2]]["cpus"] == cpus
    table = throughput_table(rows)
    assert table.count(BUSY) == 1 and table.count("MISSED") == 1
    assert "other processes used 0.00-" in table
    json.dumps(rows)  # the entries go to throughput.json as they are


# ------------------------------------------------------------------------------------------
# the compile estimate
# ------------------------------------------------------------------------------------------
def test_compile_estimate_from_the_measured_parts(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(warmup, "cold_parts", lambda parts=tuple(warmup.PARTS): list(parts))
    heading, models = (warmup.COLD_COMPILE_S[p] for p in ("heading", "models"))
    groups = (("heading",), ("models",))
    # two processes on two idle cores: the longer one; on one core: one after the other
    assert warmup.compile_estimate_s(groups, cpus=2, other_load=0.0) == max(heading, models)
    assert warmup.compile_estimate_s(groups, cpus=1, other_load=0.0) == heading + models
    # two other busy processes on two cores: each compiling process gets half a core
    assert warmup.compile_estimate_s(groups, cpus=2, other_load=2.0) == 2 * max(heading, models)
    every = warmup.compile_estimate_s(cpus=2, other_load=0.0)
    assert every == max(sum(warmup.COLD_COMPILE_S[p] for p in g) for g in warmup.PARALLEL_GROUPS)
    monkeypatch.setattr(warmup, "cold_parts", lambda parts=(): [p for p in parts if p != "heading"])
    assert warmup.compile_estimate_s(groups, cpus=2, other_load=0.0) == models  # heading warm
    with pytest.raises(ValueError, match="other_load must be >= 0"):
        warmup.compile_estimate_s(groups, cpus=2, other_load=-1.0)


def test_the_warm_up_parts_cover_every_env_task_once_and_envs_stands_for_them() -> None:
    from shipgym.envs import TASKS

    tasks = [t for part in warmup.ENVS for t in warmup.ENV_PARTS[part]]
    assert sorted(tasks) == sorted(TASKS)
    groups = [p for g in warmup.PARALLEL_GROUPS for p in g]
    assert sorted(groups) == sorted(warmup.PARTS)  # the test suite warms every part once
    bench = [p for g in warmup.BENCHMARK_GROUPS for p in g]
    assert sorted(bench) == sorted([*warmup.ENVS, "models"])
    # envs written out, each part once, in order
    assert warmup._expand(["models", "envs", "speed"]) == ["models", *warmup.ENVS]
    with pytest.raises(ValueError, match=r"unknown warm-up part\(s\) \['kernels'\]"):
        warmup.cold_parts(["kernels"])


# ------------------------------------------------------------------------------------------
# the command
# ------------------------------------------------------------------------------------------
def test_throughput_is_off_by_default() -> None:
    parser = build_parser()
    assert parser.parse_args(["benchmark"]).throughput is False
    assert parser.parse_args(["benchmark", "--throughput"]).throughput is True
    assert parser.parse_args(["benchmark", "--no-throughput"]).throughput is False


def test_throughput_flags_exclude_each_other(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["benchmark", "--throughput", "--no-throughput"]) == 2
    assert "not allowed with argument" in capsys.readouterr().err


def _small_benchmark(tmp_path: Path, *flags: str) -> list[str]:
    return [
        "benchmark",
        "--episodes",
        "1",
        "--env",
        ENV,
        "--controller",
        "zero",
        "--condition",
        "nominal",
        "--jobs",
        "1",
        "--out",
        str(tmp_path),
        *flags,
    ]


@pytest.fixture
def fake_throughput(monkeypatch: pytest.MonkeyPatch) -> list[tuple[Any, ...]]:
    """PPO's throughput measurement replaced by a record of its calls and two fixed rows."""
    calls: list[tuple[Any, ...]] = []

    def measure(env_ids: Any, timesteps: int = 0, **kwargs: Any) -> list[dict[str, Any]]:
        calls.append((tuple(env_ids), timesteps))
        row = {"other_cores": [1.5], "load_avg_1min": [2.0], "cpus": 2, "runs": [100.0]}
        return [
            {**row, "env": CARTPOLE, "steps_per_s": 100.0, "ratio": 1.0, "target": None,
             "machine_busy": True, "verdict": "", "met": None},
            {**row, "env": ENV, "steps_per_s": 50.0, "ratio": 0.5, "target": TARGET_RATIO,
             "machine_busy": True, "verdict": BUSY, "met": None},
        ]  # fmt: skip

    monkeypatch.setattr(throughput, "ppo_throughput", measure)
    return calls


def test_the_default_benchmark_runs_no_throughput(
    tmp_path: Path, fake_throughput: list[tuple[Any, ...]], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(_small_benchmark(tmp_path)) == 0
    out, err = capsys.readouterr()
    assert fake_throughput == [] and not (tmp_path / "throughput.json").exists()
    first = err.splitlines()[0].strip()
    assert first == (
        "shipgym benchmark: 1 evaluation of 1 episode (1 episode: 1 env, 1 controller, 1 condition)"
    )
    assert "PPO training throughput" not in out

    assert main(_small_benchmark(tmp_path, "--no-throughput")) == 0
    assert "--no-throughput is the default now" in capsys.readouterr().err
    assert fake_throughput == []


def test_throughput_flag_measures_and_reports_a_busy_machine(
    tmp_path: Path, fake_throughput: list[tuple[Any, ...]], capsys: pytest.CaptureFixture[str]
) -> None:
    argv = _small_benchmark(tmp_path, "--throughput", "--throughput-steps", "64")
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert fake_throughput == [((ENV,), 64)]
    assert "then PPO's training throughput" in err.splitlines()[0]
    assert BUSY in out and "MISSED" not in out
    rows = json.loads((tmp_path / "throughput.json").read_text())
    assert rows[1]["machine_busy"] is True and rows[1]["other_cores"] == [1.5]


def test_a_cold_cache_is_announced_and_compiled_first(
    tmp_path: Path,
    fake_throughput: list[tuple[Any, ...]],
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """With the benchmark's parts cold, the second line announces the compilation with the
    estimate, then the parts are compiled (here: a stand-in) before the first evaluation."""
    events: list[str] = []
    monkeypatch.setattr(warmup, "cold_parts", lambda parts=(): list(parts))

    def compile_parts(groups: Any, say: Any) -> bool:
        events.append(f"warm {groups}")
        return True

    monkeypatch.setattr(warmup, "warm_cache", compile_parts)
    monkeypatch.setattr(os, "getloadavg", lambda: (1.0, 1.0, 1.0))  # this process alone
    estimate = warmup.compile_estimate_s(warmup.BENCHMARK_GROUPS)
    assert main(_small_benchmark(tmp_path)) == 0
    lines = [line.strip() for line in capsys.readouterr().err.splitlines()]
    assert lines[0].startswith("shipgym benchmark: 1 evaluation")
    seconds = re.fullmatch(r"compiling the kernels \(first run only, about (\d+) s\)", lines[1])
    assert seconds and int(seconds[1]) == round(estimate, -1)
    assert lines[2].startswith("kernels compiled in ")
    assert lines[3].startswith("[1/1] ")  # then the evaluations, a line per cell
    assert events == [f"warm {warmup.BENCHMARK_GROUPS}"]

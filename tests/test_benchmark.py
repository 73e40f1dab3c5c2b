"""``shipgym benchmark`` and ``shipgym train``.

The benchmark on identical seeds and current draws for every controller and condition (stress,
mismatch, noise, delay), its JSON/CSV/figures with intervals and paired comparisons, and the
seed guard; the PPO throughput measurement; the command lines and their errors.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from shipgym.benchmark.evaluate import METRICS
from shipgym.benchmark.policies import make_policy
from shipgym.benchmark.report import render_markdown
from shipgym.benchmark.runner import (
    CONTROLLERS,
    SEAWAY_ONLY,
    STRESS_FACTOR,
    run_benchmark,
    training_max_current,
)
from shipgym.benchmark.throughput import CARTPOLE, ppo_throughput
from shipgym.cli import main
from shipgym.rl.train import BENCHMARK_SEED

# one worker runs this file: its module fixtures are built once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_benchmark")

ENV = "shipgym/RVGHeading-v1"
CONDITIONS = ("nominal", "stress", "noise", "delay")


def _quiet(line: str) -> None:
    pass


@pytest.fixture(scope="module")
def bench():
    return run_benchmark(
        episodes=3, envs=[ENV], conditions=CONDITIONS, progress=_quiet, jobs=1, keep_logs=None
    )


def test_every_controller_sees_the_same_scenarios(bench) -> None:
    # classic-wf runs at sea only (test_benchmark_seaway)
    assert bench.controllers == [n for n in CONTROLLERS if n not in SEAWAY_ONLY]
    assert bench.conditions == list(CONDITIONS)
    nominal = None
    for cond in bench.conditions:
        names = [n for n in bench.controllers if n != "zero" or cond == "nominal"]
        starts = [
            [
                (log.seed, log.reset_info["current_direction"], tuple(log.reset_info["state"]))
                for log in bench.get(ENV, name, cond).logs
            ]
            for name in names
        ]
        assert all(s == starts[0] for s in starts)
        assert [s[0] for s in starts[0]] == [BENCHMARK_SEED + k for k in range(3)]
        if cond in ("noise", "delay"):  # the same scenarios as nominal, only sensed or actuated
            assert starts[0] == nominal
        nominal = nominal or starts[0]
    # the zero baseline runs in the nominal condition only
    with pytest.raises(KeyError):
        bench.get(ENV, "zero", "stress")


def test_stress_fixes_the_current_at_one_and_a_half_the_training_maximum(bench) -> None:
    stress = STRESS_FACTOR * training_max_current(ENV)
    assert math.isclose(bench.stress_current[ENV], stress)
    nominal = bench.get(ENV, "classic", "nominal").logs
    stressed = bench.get(ENV, "classic", "stress").logs
    for a, b in zip(nominal, stressed, strict=True):
        assert a.reset_info["current_speed"] <= training_max_current(ENV)
        assert math.isclose(b.reset_info["current_speed"], stress)
        assert math.isclose(a.reset_info["current_direction"], b.reset_info["current_direction"])


def test_agents_and_the_classic_controller_beat_zero(bench) -> None:
    zero = bench.get(ENV, "zero").to_dict()["mean_return"]
    for name in ("classic", "classic-tuned", "ppo", "sac"):
        assert bench.get(ENV, name).to_dict()["mean_return"] > zero


def test_outputs_json_csv_and_table(bench, tmp_path: Path) -> None:
    entries = json.loads(bench.write_json(tmp_path / "b.json").read_text())
    cells = 5 + 4 * 3  # zero in nominal only
    assert len(entries) == cells
    for e in entries:
        assert set(METRICS[ENV]) == set(e["metrics"]) == set(e["metrics_std"])
        assert set(e["metrics_ci95"]) == set(e["per_episode"]) == set(METRICS[ENV])
        assert e["episodes"] == 3 and e["seed"] == BENCHMARK_SEED
        assert len(e["returns"]) == 3 and len(e["termination"]) == 3
        for key, values in e["per_episode"].items():
            finite = [v for v in values if np.isfinite(v)]
            assert e["metrics_defined"][key] == len(finite)
            if len(finite) >= 2:
                lo, hi = e["metrics_ci95"][key]
                assert lo <= e["metrics"][key] <= hi
                assert e["metrics"][key] == pytest.approx(np.mean(finite))
    with bench.write_csv(tmp_path / "b.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == cells * (1 + len(METRICS[ENV]))
    ppo = [r for r in rows if r["controller"] == "ppo" and r["condition"] == "nominal"]
    assert {r["metric"] for r in ppo} == {"return", *METRICS[ENV]}
    expected = bench.get(ENV, "ppo").to_dict()["metrics"]["heading_rms_deg"]
    assert math.isclose(
        float(next(r["mean"] for r in ppo if r["metric"] == "heading_rms_deg")), expected
    )
    table = bench.table()
    assert "heading_rms_deg" in table and "stress" in table and " +- " in table
    md = render_markdown(entries, None)
    name = ENV.split("/")[-1]
    # robustness rows for the four controllers run in every condition; the return against
    # classic-tuned for four controllers in nominal and three in the other three conditions
    assert md.count(f"| {name} |") == 4 + 4 + 3 * 3
    assert f"**{name}**: controller - `classic-tuned`" in md
    paired = md.split("controller - `classic-tuned`")[1]
    zero_row = next(line for line in paired.splitlines() if line.startswith("| zero | -"))
    assert zero_row.split("|")[2].strip().endswith("**worse**")  # zero's return, paired
    assert "95 % interval" in md and "robustness.png" in md


def test_parallel_cells_give_the_same_results(bench) -> None:
    """Cells in worker processes: the same evaluations, in the same order; only the first
    episode's log comes back."""
    kw = {"episodes": 3, "envs": [ENV], "conditions": ("nominal", "noise"), "progress": _quiet}
    par = run_benchmark(controllers=["classic-tuned", "ppo"], jobs=2, **kw)
    assert [(r.controller, r.condition) for r in par.results] == [
        ("classic-tuned", "nominal"), ("ppo", "nominal"), ("classic-tuned", "noise"),
        ("ppo", "noise"),
    ]  # fmt: skip
    for r in par.results:
        ref = bench.get(ENV, r.controller, r.condition)
        assert r.returns == ref.returns and r.terminations == ref.terminations
        for key in METRICS[ENV]:
            np.testing.assert_array_equal(r.values(key), ref.values(key))
        assert len(r.logs) == 1 and r.logs[0].seed == BENCHMARK_SEED
    with pytest.raises(ValueError, match="jobs"):
        run_benchmark(jobs=0, **kw)


def test_seed_guard_refuses_training_seeds() -> None:
    with pytest.raises(ValueError, match="overlap the training seeds"):
        run_benchmark(episodes=2, seed=0, envs=[ENV], controllers=["ppo"], progress=_quiet)
    with pytest.raises(ValueError, match="overlap the validation seeds"):
        run_benchmark(episodes=2, seed=100_001, envs=[ENV], controllers=["sac"], progress=_quiet)
    with pytest.raises(ValueError, match="overlap the tuning seeds"):
        run_benchmark(episodes=2, seed=14, envs=[ENV], controllers=["classic-tuned"],
                      progress=_quiet)  # fmt: skip


def test_benchmark_rejects_bad_arguments() -> None:
    with pytest.raises(ValueError, match="unknown controller"):
        run_benchmark(episodes=1, controllers=["dqn"], progress=_quiet)
    with pytest.raises(ValueError, match="unknown env"):
        run_benchmark(episodes=1, envs=["CartPole-v1"], progress=_quiet)
    with pytest.raises(ValueError, match="episodes"):
        run_benchmark(episodes=0, progress=_quiet)


def test_ppo_throughput_measures_both_in_one_run() -> None:
    rows = ppo_throughput(["shipgym/RVGSpeed-v0"], timesteps=2048, repeats=1, progress=_quiet)
    assert [r["env"] for r in rows] == [CARTPOLE, "shipgym/RVGSpeed-v0"]
    assert rows[0]["ratio"] == 1.0 and rows[0]["met"] is None
    assert all(r["steps_per_s"] > 0 and len(r["runs"]) == 1 for r in rows)
    assert math.isclose(rows[1]["ratio"], rows[1]["steps_per_s"] / rows[0]["steps_per_s"])
    # on a machine other processes share, the ratio means nothing and no verdict is given
    assert rows[1]["met"] is (None if rows[1]["machine_busy"] else rows[1]["ratio"] >= 0.9)


# ------------------------------------------------------------------------------------------
# command line
# ------------------------------------------------------------------------------------------
def test_benchmark_command_writes_table_json_csv_and_figures(tmp_path: Path, capsys) -> None:
    code = main(
        [
            "benchmark",
            "--episodes",
            "2",
            "--env",
            "shipgym/RVGSpeed-v1",
            "--out",
            str(tmp_path),
            "--quiet",
        ]
    )
    out = capsys.readouterr().out
    assert code == 0
    assert "speed_rms_m_s" in out and "sac" in out
    entries = json.loads((tmp_path / "benchmark.json").read_text())
    conditions = ("nominal", "stress", "mismatch:seed001", "noise", "delay", "seaway")
    assert {(e["controller"], e["condition"]) for e in entries} == {
        (c, k)
        for c in CONTROLLERS
        for k in conditions
        if (c != "zero" or k == "nominal") and (c not in SEAWAY_ONLY or k == "seaway")
    }
    assert (tmp_path / "benchmark.csv").stat().st_size > 0
    for name in ("metrics.png", "robustness.png", "RVGSpeed-v1.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_benchmark_command_bad_input(tmp_path: Path, capsys) -> None:
    afile = tmp_path / "x.txt"
    afile.write_text("keep me")
    assert main(["benchmark", "--out", str(afile)]) == 2
    assert "--out names a file" in capsys.readouterr().err
    assert afile.read_text() == "keep me"
    assert main(["benchmark", "--json", str(tmp_path / "b.txt"), "--out", str(tmp_path)]) == 2
    assert "--json must name a .json file" in capsys.readouterr().err
    assert main(["benchmark", "--episodes", "0"]) == 2
    assert main(["benchmark", "--seed", "3", "--env", ENV, "--controller", "ppo"]) == 2
    assert "overlap the training seeds" in capsys.readouterr().err


def test_train_and_evaluate_commands(tmp_path: Path, capsys) -> None:
    code = main(
        [
            "train",
            "--env",
            "shipgym/RVGSpeed-v0",
            "--algo",
            "ppo",
            "--timesteps",
            "64",
            "--num-envs",
            "2",
            "--eval-episodes",
            "2",
            "--out",
            str(tmp_path),
            "--quiet",
        ]
    )
    assert code == 0
    assert (tmp_path / "RVGSpeed-v0-ppo.zip").is_file()
    meta = json.loads((tmp_path / "RVGSpeed-v0-ppo.json").read_text())
    assert meta["timesteps"] >= 64 and meta["num_envs"] == 2
    capsys.readouterr()
    argv = ["evaluate", "--env", "shipgym/RVGSpeed-v0", "--controller", "ppo", "--episodes", "1"]
    assert main([*argv, "--agents", str(tmp_path), "--seed", "500"]) == 0
    assert "speed_rms_m_s" in capsys.readouterr().out
    # seeds inside the agent's own training seeds: evaluated, with a warning
    assert main([*argv, "--agents", str(tmp_path), "--seed", "0"]) == 0
    assert "warning" in capsys.readouterr().err
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main([*argv, "--agents", str(empty)]) == 1
    assert "shipgym train --env shipgym/RVGSpeed-v0 --algo ppo" in capsys.readouterr().err
    assert main(["train", "--env", "shipgym/RVGSpeed-v0", "--algo", "dqn"]) == 2


def test_evaluate_shipped_agent_from_the_command_line(capsys) -> None:
    argv = ["evaluate", "--env", ENV, "--controller", "sac", "--episodes", "2"]
    assert main([*argv, "--seed", str(BENCHMARK_SEED)]) == 0
    out = capsys.readouterr().out
    value = float(out.split("heading_rms_deg")[1].split()[0])
    assert np.isfinite(value) and value < 30.0


def test_mismatch_condition_runs_the_wrong_ship_and_gains_stay_nominal() -> None:
    """The mismatch condition steps the Bech and the Norrbin Mariner while the classic
    autopilot keeps the gains designed on the first-order Nomoto ship (as the agents keep
    their training); the Gunnerus v1 envs meet seed 001's ship, the v0 envs the sea-trial one."""
    from shipgym.benchmark.report import robustness_table
    from shipgym.benchmark.runner import MISMATCH_SHIPS
    from shipgym.envs import ENV_IDS

    nomoto = "shipgym/NomotoHeading-v0"
    res = run_benchmark(
        episodes=2, envs=[nomoto], controllers=["classic", "zero"],
        conditions=("nominal", "mismatch"), progress=_quiet,
    )  # fmt: skip
    assert res.conditions == ["nominal", "mismatch:bech", "mismatch:norrbin"]
    bech = res.get(nomoto, "classic", "mismatch:bech")
    norrbin = res.get(nomoto, "classic", "mismatch:norrbin")
    nom = res.get(nomoto, "classic", "nominal")
    assert bech.logs[0].state[0].size == 7 and nom.logs[0].state[0].size == 6  # bech: r_dot
    assert len({tuple(r.returns) for r in (bech, norrbin, nom)}) == 3
    # the gains stay those of the nominal ship: the same episodes as the autopilot designed on
    # the first-order ship sailing the Bech Mariner, not as one designed on the Bech Mariner
    from shipgym.benchmark.evaluate import evaluate

    assert make_policy("classic", nomoto).nominal == "nomoto1"
    for design, same in ((None, True), ("bech", False)):
        direct = evaluate(
            nomoto, make_policy("classic", nomoto, model=design), "classic", episodes=2,
            seed=BENCHMARK_SEED, env_kwargs={"model": "bech"}, progress=_quiet,
        )  # fmt: skip
        assert (direct.returns == bech.returns) is same, design
    # the batch that `evaluate --model bech --ray` sends designs on the ship it names
    from shipgym.benchmark.runner import EpisodeBatch, Scenario

    sailed = Scenario("nominal", env_kwargs={"model": "bech"}, design_model="bech")
    assert EpisodeBatch(nomoto, "classic", sailed, BENCHMARK_SEED, 2).run().returns == (
        direct.returns
    )
    assert set(MISMATCH_SHIPS) == set(ENV_IDS)
    assert MISMATCH_SHIPS[ENV] == {"seed001": {"params": "seed001"}}
    assert MISMATCH_SHIPS["shipgym/RVGHeading-v0"] == {"sea_trials": {"params": "sea_trials"}}
    table = "\n".join(robustness_table(res.to_list()))
    assert "| NomotoHeading-v0 | classic |" in table and "mismatch:norrbin" in table

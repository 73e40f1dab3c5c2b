"""Campaigns on Ray: ``--ray`` of ``shipgym evaluate`` and ``shipgym benchmark``.

One local Ray with 2 CPUs serves the whole module (its files in a private temporary folder that
the session removes). The results of ``--ray`` equal those of the local run exactly (the
campaign split into tasks of a few seeds), a failing episode is reported with its env,
controller, condition and seed, and bad ``--ray`` values are one-line errors. RLlib's tests are
in ``test_rllib.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from gymnasium.vector import VectorWrapper

from shipgym.benchmark.evaluate import EpisodeError, evaluate, merge_results
from shipgym.benchmark.policies import make_policy
from shipgym.benchmark.runner import EpisodeBatch, Scenario, evaluate_on_ray, run_benchmark
from shipgym.cli import main
from shipgym.cluster import parse_address, ray_session
from shipgym.rl.train import BENCHMARK_SEED

# one worker runs this file: its module fixtures are built once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_cluster")

ENV = "shipgym/RVGHeading-v1"  # the shortest episodes (600 steps)


def _quiet(line: str) -> None:
    pass


def _failing_at(seed: int, step: int) -> type[VectorWrapper]:
    """A vector wrapper raising at ``step`` of a batch that holds the episode reset with
    ``seed`` (defined in a function, so that Ray sends the class itself to the workers)."""

    class FailAt(VectorWrapper):
        def reset(self, *, seed=None, options=None):
            self.failing, self.steps = FAIL_SEED in np.atleast_1d(seed), 0
            return self.env.reset(seed=seed, options=options)

        def step(self, actions):
            self.steps += 1
            if self.failing and self.steps == step:
                raise ZeroDivisionError("injected fault")
            return self.env.step(actions)

    FAIL_SEED = seed
    return FailAt


# ---- no Ray needed ------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("argv", "bad"),
    [
        (["evaluate", "--env", ENV, "--ray", "nohost"], "'nohost': expected host:port"),
        (["evaluate", "--env", ENV, "--ray", "head:99999"], "port 99999 is not in [1, 65535]"),
        (["benchmark", "--ray", "a b:6379"], "expected host:port"),
        (["evaluate", "--env", ENV, "--ray-cpus", "2"], "--ray-cpus goes with --ray"),
        (["evaluate", "--env", ENV, "--task-episodes", "5"], "--task-episodes goes with --ray"),
        (["evaluate", "--env", ENV, "--ray", "10.0.0.1:6379", "--ray-cpus", "2"], "own CPUs"),
        (["benchmark", "--ray", "--jobs", "2"], "--jobs sets the local process pool"),
        (["evaluate", "--env", ENV, "--ray", "--ray-cpus", "0"], "--ray-cpus: must be"),
    ],
)
def test_bad_ray_flags_exit_2_with_one_line(argv: list[str], bad: str, capsys) -> None:
    """One line naming the flag (argparse's errors add a hint line: where the options are)."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert bad in err[0] and err[0].startswith("shipgym")
    assert err[1:] in ([], [f"  hint: 'shipgym {argv[0]} --help' lists the options"])


def test_unreachable_cluster_is_a_one_line_error(capsys) -> None:
    # port 1 on this machine: refused at once (checked before Ray would retry for a minute)
    assert main(["evaluate", "--env", ENV, "--ray", "127.0.0.1:1", "--episodes", "1"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "shipgym: error: cannot reach the Ray cluster at 127.0.0.1:1: Connection refused "
        "(is 'ray start --head' running there, and is port 1 open?)"
    ]


def test_parse_address_forms() -> None:
    assert parse_address(None) is None and parse_address("local") is None
    assert parse_address("auto") == "auto"
    assert parse_address("192.168.1.10:6379") == "192.168.1.10:6379"
    assert parse_address("ray://head.example.org:10001") == "ray://head.example.org:10001"
    assert parse_address("[::1]:6379") == "[::1]:6379"
    for bad in ("6379", "head:", "head:port", "[zz::1]:6379", "http://head:6379"):
        with pytest.raises(ValueError, match="bad Ray address"):
            parse_address(bad)


def test_batches_merge_to_the_run_over_all_seeds() -> None:
    """Batches of seeds merge into the evaluation of all of them (the neural policies' case,
    whose lockstep calls have fixed blocks, is the Ray evaluate test below)."""
    policy = make_policy("zero", ENV)
    whole = evaluate(ENV, policy, "zero", 4, BENCHMARK_SEED, progress=_quiet)
    parts = [
        evaluate(ENV, policy, "zero", n, BENCHMARK_SEED + s, progress=_quiet)
        for s, n in ((3, 1), (0, 1), (1, 2))
    ]
    merged = merge_results(parts)
    assert json.dumps(merged.to_dict()) == json.dumps(whole.to_dict())
    assert [log.seed for log in merged.logs] == [BENCHMARK_SEED + k for k in range(4)]
    with pytest.raises(
        ValueError, match=f"from seed {BENCHMARK_SEED + 1}, got one from seed {BENCHMARK_SEED + 3}"
    ):
        merge_results([parts[0], parts[1]])
    classic = evaluate(
        ENV, make_policy("classic", ENV), "classic", 1, BENCHMARK_SEED, progress=_quiet
    )
    with pytest.raises(ValueError, match="different evaluations"):
        merge_results([classic, parts[2]])


def test_split_keeps_the_first_logs() -> None:
    cell = EpisodeBatch(ENV, "zero", Scenario("nominal"), 10, 7, keep_logs=3)
    parts = cell.split(3)
    assert [(p.seed, p.episodes, p.keep_logs) for p in parts] == [
        (10, 3, 3),
        (13, 2, 0),
        (15, 2, 0),
    ]


def test_failing_episode_names_its_seed_without_ray() -> None:
    with pytest.raises(EpisodeError) as info:
        evaluate(ENV, make_policy("zero", ENV), "zero", 4, 100, wrappers=(_failing_at(102, 5),),
                 progress=_quiet)  # fmt: skip
    assert str(info.value).startswith(
        f"{ENV} zero (nominal): episode with seed 102 failed: ZeroDivisionError: injected fault"
    )
    assert info.value.seeds == (102,)


# ---- on one local Ray ---------------------------------------------------------------------
@pytest.fixture(scope="module")
def local_ray():
    with ray_session(num_cpus=2) as ray:
        yield ray


def test_evaluate_with_ray_equals_the_local_run(local_ray, tmp_path: Path, capsys) -> None:
    """PPO: the local run calls the network on all four episodes, each task on two."""
    argv = ["evaluate", "--env", ENV, "--controller", "ppo", "--episodes", "4"]
    argv += ["--seed", str(BENCHMARK_SEED)]
    assert main([*argv, "--json", str(tmp_path / "local.json")]) == 0
    capsys.readouterr()
    assert main([*argv, "--json", str(tmp_path / "ray.json"), "--ray", "--task-episodes", "2"]) == 0
    err = capsys.readouterr().err
    assert "2 Ray tasks of up to 2 episodes for 1 evaluation(s) on the local Ray (2 CPUs" in err
    assert "[2/2 tasks" in err and f"seeds {BENCHMARK_SEED + 2}..{BENCHMARK_SEED + 3} done" in err
    local = (tmp_path / "local.json").read_text()
    assert (tmp_path / "ray.json").read_text() == local
    assert json.loads(local)["episodes"] == 4


def test_benchmark_with_ray_equals_the_local_run(local_ray, tmp_path: Path, capsys) -> None:
    kw = dict(episodes=2, envs=[ENV], controllers=["classic", "zero"],
              conditions=["nominal", "noise"], progress=_quiet)  # fmt: skip
    local = run_benchmark(jobs=1, **kw)
    argv = ["benchmark", "--episodes", "2", "--env", ENV, "--controller", "classic"]
    argv += ["--controller", "zero", "--condition", "nominal", "--condition", "noise"]
    argv += ["--out", str(tmp_path), "--ray", "--task-episodes", "1"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "6 Ray tasks of up to 1 episodes for 3 evaluation(s)" in err
    assert "[6/6 tasks" in err and "[3/3] " in err  # each task's line, each cell's line
    assert (tmp_path / "benchmark.json").read_text() == local.write_json(
        tmp_path / "l.json"
    ).read_text()
    assert (tmp_path / "benchmark.csv").read_text() == local.write_csv(
        tmp_path / "l.csv"
    ).read_text()
    # the first episode's log came back for the trajectory figure
    assert (tmp_path / "RVGHeading-v1.png").stat().st_size > 0


def test_failing_task_is_reported_with_its_seed(local_ray, capsys) -> None:
    seed = BENCHMARK_SEED + 3
    with pytest.raises(EpisodeError) as info:
        evaluate_on_ray(ENV, "classic", 4, BENCHMARK_SEED, task_size=2, condition="faulty",
                        wrappers=(_failing_at(seed, 7),), progress=_quiet)  # fmt: skip
    message = str(info.value)
    assert message == (
        f"{ENV} classic (faulty): episode with seed {seed} failed: ZeroDivisionError: "
        "injected fault"
    )
    assert (info.value.env, info.value.controller, info.value.condition, info.value.seeds) == (
        ENV, "classic", "faulty", (seed,)
    )  # fmt: skip
    assert "worker traceback" in "".join(getattr(info.value, "__notes__", []))

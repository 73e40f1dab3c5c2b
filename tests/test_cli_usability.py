"""The ``shipgym`` command as a newcomer meets it: one-line argument errors with a hint, counts
written as users write them, help for every option, output folders made as needed, the newest
env ids and ship by default, and seed advice that matches the defaults."""

from __future__ import annotations

import argparse
import json
import re
import warnings
from pathlib import Path

import pytest

from shipgym.cli import build_parser, main

HELP_ONLY_DEFAULT = re.compile(r"^\s*\(?(default:?\s*)?%\(default\)s\)?\s*$")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["train", "--timesteps", "1e5x"], "argument --timesteps: must be an integer"),
        (["benchmark", "--episodes", "0"], "argument --episodes: must be an integer in [1,"),
        (["evaluate", "--env", "shipgym/NoSuchEnv-v0"], "argument --env: invalid choice"),
        (["simulate", "zigzag", "--model", "nope"], "argument --model: must be one of"),
        (["nosuchcommand"], "invalid choice: 'nosuchcommand'"),
    ],
)
def test_argument_errors_are_one_line_and_a_hint(argv, message, capsys) -> None:
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert captured.out == ""
    assert len(lines) == 2, captured.err  # the error, then where the options are listed
    assert message in lines[0] and lines[0].startswith("shipgym")
    command = "shipgym" if argv[0] == "nosuchcommand" else f"shipgym {argv[0]}"
    assert lines[1].strip() == f"hint: '{command} --help' lists the options"
    assert "usage:" not in captured.err


@pytest.mark.parametrize(
    ("text", "value"), [("100000", 100000), ("1e5", 100000), ("100_000", 100000), ("2.5e3", 2500)]
)
def test_counts_are_read_as_users_write_them(text: str, value: int) -> None:
    args = build_parser().parse_args(
        ["train", "--env", "shipgym/RVGHeading-v1", "--algo", "ppo", "--timesteps", text]
    )
    assert args.timesteps == value


@pytest.mark.parametrize("text", ["1.5", "1e-3", "nan", "inf", "ten", "1e20"])
def test_counts_that_are_not_whole_numbers_in_range_are_refused(text: str, capsys) -> None:
    assert main(["benchmark", "--episodes", text]) == 2
    assert f"got {text!r}" in capsys.readouterr().err


def _parsers(parser: argparse.ArgumentParser, name: str = "shipgym"):
    """Every parser under ``parser``, nested subcommands included (``shipgym data fetch``)."""
    yield name, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _parsers(sub, f"{name} {sub_name}")


def test_every_option_has_help_that_says_more_than_its_default() -> None:
    for name, parser in _parsers(build_parser()):
        assert parser.description or name == "shipgym data list", name
        assert "%%" not in parser.format_help(), name  # a literal "%%" is a formatting slip
        for action in parser._actions:
            if isinstance(action, argparse._HelpAction | argparse._VersionAction):
                continue
            flag = "/".join(action.option_strings) or action.dest
            assert action.help and not HELP_ONLY_DEFAULT.match(action.help), (name, flag)
            assert len(action.help.replace("%(default)s", "")) >= 15, (name, flag, action.help)


def test_output_folders_are_made_with_their_parents(tmp_path: Path, capsys) -> None:
    target = tmp_path / "runs" / "trials" / "zigzag.json"
    assert main(["simulate", "zigzag", "--model", "nomoto1", "--json", str(target)]) == 0
    assert json.loads(target.read_text())["manoeuvre"] == "zigzag"
    plots = tmp_path / "runs" / "episodes"
    argv = ["evaluate", "--env", "shipgym/NomotoHeading-v0", "--controller", "zero"]
    assert main([*argv, "--episodes", "1", "--plot", str(plots)]) == 0
    assert any(plots.glob("*.png"))


def test_an_output_under_a_file_is_refused_before_the_run(tmp_path: Path, capsys) -> None:
    blocker = tmp_path / "notes.txt"
    blocker.write_text("keep me")
    target = blocker / "zigzag.json"
    assert main(["simulate", "zigzag", "--model", "nomoto1", "--json", str(target)]) == 2
    err = capsys.readouterr().err
    assert "--json" in err and "is a file" in err and "overshoot" not in err
    assert blocker.read_text() == "keep me"


def _out_of_date_warnings(caught: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in caught if "out of date" in str(w.message)]


def test_envs_lists_every_id_with_its_task_and_no_warning(capsys) -> None:
    from shipgym.envs import ENV_IDS

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["envs"]) == 0
    assert _out_of_date_warnings(caught) == []
    rows = {line.split()[0]: line for line in capsys.readouterr().out.splitlines()[1:]}
    assert set(rows) == set(ENV_IDS)
    for env_id, line in rows.items():
        assert "action:" in line, line
        if env_id.startswith("shipgym/RVG"):
            ship = "sea trials" if env_id.endswith("-v1") else "seed 001"
            assert ship in line, line


def test_the_demo_runs_the_newest_env_without_a_warning() -> None:
    from shipgym.demo import PATH_ENV_ID, path_following_episode
    from shipgym.envs import CURRENT_ENV_IDS

    assert PATH_ENV_ID in CURRENT_ENV_IDS
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        episode = path_following_episode()
    assert _out_of_date_warnings(caught) == []
    # the tuned LOS and autopilots on the sea-trial Gunnerus: on the path within metres
    assert episode.completed
    assert float(abs(episode.cross_track).mean()) < 10.0


def test_project_code_names_only_the_newest_env_ids() -> None:
    """Examples, scripts and the package's own commands use the newest version of each task
    (an older id in a user-facing example makes Gymnasium warn "out of date")."""
    from shipgym.envs import CURRENT_ENV_IDS, ENV_IDS

    root = Path(__file__).resolve().parents[1]
    older = set(ENV_IDS) - set(CURRENT_ENV_IDS)
    files = [root / "shipgym" / "demo.py", *(root / "shipgym" / "cli").glob("*.py")]
    files += [*(root / "examples").rglob("*.py")]
    for path in files:
        for env_id in older:
            assert f'"{env_id}"' not in path.read_text(), (path, env_id)


def test_simulate_rvg3dof_sails_the_sea_trial_ship_and_names_it(tmp_path: Path, capsys) -> None:
    out = tmp_path / "z.json"
    assert main(["simulate", "zigzag", "--model", "rvg3dof", "--json", str(out)]) == 0
    captured = capsys.readouterr()
    assert "--params sea_trials" in captured.err
    assert "sea_trials" in captured.out
    newest = json.loads(out.read_text())
    assert newest["params"] == "sea_trials"
    argv = ["simulate", "zigzag", "--model", "rvg3dof", "--params", "seed001", "--json", str(out)]
    assert main(argv) == 0
    assert "seed001" in capsys.readouterr().out
    seed = json.loads(out.read_text())
    assert seed["params"] == "seed001"
    # two different ships: seed 001's Gunnerus overshoots the 20/20 zigzag far more
    assert seed["overshoots_deg"][0] > 3 * newest["overshoots_deg"][0]


def test_evaluating_an_agent_on_the_default_seeds_needs_no_advice(capsys) -> None:
    from shipgym.rl.train import BENCHMARK_SEED

    assert (
        build_parser().parse_args(["evaluate", "--env", "shipgym/RVGHeading-v1"]).seed
        == BENCHMARK_SEED
    )
    argv = ["evaluate", "--env", "shipgym/RVGHeading-v1", "--controller", "ppo", "--episodes", "1"]
    assert main(argv) == 0
    assert "warning" not in capsys.readouterr().err
    assert main([*argv, "--seed", "0"]) == 0  # its own training seeds: evaluated, with advice
    err = capsys.readouterr().err
    assert f"--seed {BENCHMARK_SEED}" in err and "default" in err

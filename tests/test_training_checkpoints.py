"""Training that loses nothing: checkpoints, resume, TensorBoard logs and sweeps on Ray.

Tiny trainings only (PPO, a 16-unit network, two sub-envs, 50-step episodes, a few thousand
steps, one torch thread). One interrupted training is shared by the checkpoint, resume and
TensorBoard tests; one local Ray (two CPUs) serves the sweep, whose second trial kills its
own worker once after its first checkpoint.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import signal
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
import torch
from stable_baselines3.common.callbacks import BaseCallback

from shipgym.cli import main
from shipgym.rl import checkpoints
from shipgym.rl.agents import load_agent
from shipgym.rl.sweep import HYPERPARAMETERS, load_sweep, run_sweep
from shipgym.rl.train import resume, train

# one worker runs this file: its module fixtures are built once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_training_checkpoints")

ENV = "shipgym/RVGSpeed-v1"
NAME = "RVGSpeed-v1-ppo"
TINY = {"n_steps": 64, "batch_size": 64, "n_epochs": 1, "policy_kwargs": {"net_arch": [16]}}
SHORT = {"max_episode_steps": 50}  # evaluations of 50 steps
EVAL_FREQ = 256  # two rollouts of 2 x 64 steps
INTERRUPT_AT = 3 * EVAL_FREQ  # right after the third evaluation


@pytest.fixture(scope="module", autouse=True)
def _one_torch_thread() -> Iterator[None]:
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


def _observations() -> np.ndarray:
    return np.stack([gym.make(ENV).reset(seed=s)[0] for s in range(8)])


class _Interrupt(BaseCallback):
    """Records the policy's actions on fixed observations after every evaluation (it runs
    after the evaluation callback) and raises ``KeyboardInterrupt`` at ``at`` steps."""

    def __init__(self, at: int | None, evaluated: list[int]) -> None:
        super().__init__()
        self.at = at
        self.evaluated = evaluated
        self.actions: dict[int, np.ndarray] = {}
        self.first_step: int | None = None
        self.obs = _observations()

    def _on_step(self) -> bool:
        if self.first_step is None:
            self.first_step = self.num_timesteps
        if self.evaluated and self.evaluated[-1] == self.num_timesteps:
            venv = self.training_env
            action, _ = self.model.predict(venv.normalize_obs(self.obs), deterministic=True)
            self.actions[self.num_timesteps] = action
        if self.at is not None and self.num_timesteps >= self.at:
            raise KeyboardInterrupt
        return True


@pytest.fixture(scope="module")
def interrupted(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """A training of 4096 steps interrupted (Ctrl-C) at step 768, after its third evaluation."""
    out = tmp_path_factory.mktemp("interrupted")
    evaluated: list[int] = []
    spy = _Interrupt(INTERRUPT_AT, evaluated)
    with pytest.raises(KeyboardInterrupt):
        train(
            ENV,
            "ppo",
            timesteps=4096,
            seed=5,
            out_dir=out,
            num_envs=2,
            eval_freq=EVAL_FREQ,
            eval_episodes=2,
            progress_bar=False,
            hyperparameters=TINY,
            env_kwargs=SHORT,
            callbacks=[spy],
            on_evaluation=lambda metrics: evaluated.append(metrics["timesteps"]),
        )
    return {"out": out, "actions": spy.actions, "evaluated": evaluated}


# ------------------------------------------------------------------------------------------
# checkpoints of an interrupted training
# ------------------------------------------------------------------------------------------
def test_interrupted_training_leaves_a_usable_best_and_latest_checkpoint(
    interrupted: dict[str, Any],
) -> None:
    out, actions = interrupted["out"], interrupted["actions"]
    assert interrupted["evaluated"] == [EVAL_FREQ, 2 * EVAL_FREQ, 3 * EVAL_FREQ]
    latest = checkpoints.latest_dir(out, NAME)
    record = json.loads((latest / f"{NAME}.json").read_text())
    assert record["partial"] is True
    assert record["timesteps"] == INTERRUPT_AT and record["requested_timesteps"] == 4096
    assert record["learning_curve"]["timesteps"] == interrupted["evaluated"]
    # the agent at the top of the folder is the best policy so far, with a partial record
    top = json.loads((out / f"{NAME}.json").read_text())
    assert top["partial"] is True and top["timesteps"] == top["best_timestep"]
    best_step = top["best_timestep"]
    assert top["best_validation_return"] == max(record["learning_curve"]["mean_return"])
    assert top["best_validation_return"] == record["best_validation_return"]
    # both load and act exactly as the policy did when it was saved
    obs = _observations()
    np.testing.assert_array_equal(load_agent(ENV, "ppo", out).act_batch(obs), actions[best_step])
    np.testing.assert_array_equal(
        load_agent(ENV, "ppo", latest).act_batch(obs), actions[INTERRUPT_AT]
    )
    best = checkpoints.best_dir(out, NAME)
    assert {p.name for p in best.iterdir()} == {f"{NAME}.zip", f"{NAME}.json", "vecnormalize.pkl"}
    assert not [p.name for p in out.rglob(".*.tmp*")]  # no temporary file left behind


def test_evaluate_command_runs_the_partial_agent(
    interrupted: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["evaluate", "--env", ENV, "--controller", "ppo", "--agents", str(interrupted["out"])]
    assert main([*argv, "--episodes", "1", "--seed", "2000000"]) == 0
    assert "return" in capsys.readouterr().out


@pytest.fixture(scope="module")
def resumed(interrupted: dict[str, Any], tmp_path_factory: pytest.TempPathFactory) -> dict:
    """The interrupted training (a copy) resumed to 1280 steps."""
    out = tmp_path_factory.mktemp("resumed") / "run"
    shutil.copytree(interrupted["out"], out)
    evaluated: list[int] = []
    spy = _Interrupt(None, evaluated)
    result = resume(
        out,
        timesteps=5 * EVAL_FREQ,
        progress_bar=False,
        callbacks=[spy],
        on_evaluation=lambda metrics: evaluated.append(metrics["timesteps"]),
    )
    return {"out": out, "meta": result.meta, "first_step": spy.first_step}


def test_resume_continues_the_counter_and_the_learning_curve(
    interrupted: dict[str, Any], resumed: dict[str, Any]
) -> None:
    meta = resumed["meta"]
    # the first step after resuming is the checkpoint's step plus one vector step
    assert resumed["first_step"] == INTERRUPT_AT + 2
    assert meta["resumed_at"] == [INTERRUPT_AT]
    assert meta["partial"] is False and meta["timesteps"] == 5 * EVAL_FREQ
    curve = meta["learning_curve"]
    latest = checkpoints.latest_dir(interrupted["out"], NAME) / f"{NAME}.json"
    before = json.loads(latest.read_text())["learning_curve"]
    assert curve["timesteps"] == [EVAL_FREQ * k for k in range(1, 6)]
    assert curve["mean_return"][:3] == before["mean_return"]
    assert meta["best_validation_return"] == max(curve["mean_return"])
    saved = json.loads((resumed["out"] / f"{NAME}.json").read_text())
    assert saved == meta
    assert (
        meta["wall_time_s"]
        > json.loads(
            (checkpoints.latest_dir(interrupted["out"], NAME) / f"{NAME}.json").read_text()
        )["wall_time_s"]
    )


def test_tensorboard_shows_one_run_with_both_sessions(resumed: dict[str, Any]) -> None:
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    runs = sorted((resumed["out"] / "tensorboard").iterdir())
    assert [run.name for run in runs] == [f"{NAME}_1"]
    assert len(list(runs[0].glob("events.out.tfevents.*"))) == 2  # before and after resuming
    events = EventAccumulator(str(runs[0]))
    events.Reload()
    steps = [e.step for e in events.Scalars("eval/mean_reward")]
    assert steps == resumed["meta"]["learning_curve"]["timesteps"]
    assert "train/loss" in events.Tags()["scalars"]


# ------------------------------------------------------------------------------------------
# the command: SIGTERM, resume, bad input
# ------------------------------------------------------------------------------------------
def test_sigterm_stops_the_command_with_its_checkpoint_and_resume_finishes_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "agents"
    record = checkpoints.latest_dir(out, NAME) / f"{NAME}.json"

    finished = threading.Event()

    def stop_after_first_checkpoint() -> None:
        # waits for the first checkpoint however long the machine takes to write it
        while not record.is_file():
            if finished.wait(0.02):
                return  # the command ended first: no signal (its exit code tells)
        os.kill(os.getpid(), signal.SIGTERM)

    argv = ["train", "--env", ENV, "--algo", "ppo", "--out", str(out), "--num-envs", "2"]
    argv += ["--eval-freq", "128", "--eval-episodes", "1", "--timesteps", "1000000", "--quiet"]
    watcher = threading.Thread(target=stop_after_first_checkpoint)
    watcher.start()
    try:
        code = main(argv)
    finally:
        finished.set()
        watcher.join()
    err = capsys.readouterr().err
    assert code == 130
    assert f"shipgym train --resume {out}" in err
    # the signal stopped the run at the next step, after evaluating and saving its policy
    saved = json.loads(record.read_text())
    done = saved["timesteps"]
    assert 128 < done < 1_000_000 and saved["learning_curve"]["timesteps"][-1] == done
    assert "stopping: saving the policy of this step" in err
    load_agent(ENV, "ppo", out)  # the partial agent is usable
    # a fresh run into the folder would wipe it: refused
    assert main(argv) == 2
    assert "unfinished training" in capsys.readouterr().err
    total = done + 128
    assert main(["train", "--resume", str(out), "--timesteps", str(total), "--quiet"]) == 0
    final = json.loads((out / f"{NAME}.json").read_text())
    assert final["partial"] is False and final["resumed_at"] == [done]
    assert final["timesteps"] >= total


def test_resume_refuses_bad_folders_with_one_line(
    interrupted: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def error(argv: list[str]) -> str:
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("shipgym: error: ")
        return err

    assert "holds no training checkpoint" in error(["train", "--resume", str(tmp_path)])
    assert "not a folder" in error(["train", "--resume", str(tmp_path / "missing")])
    out = str(interrupted["out"])
    other = error(["train", "--resume", out, "--env", "shipgym/RVGHeading-v1", "--algo", "ppo"])
    assert "no checkpoint of RVGHeading-v1-ppo" in other and NAME in other
    assert "--seed cannot be given" in error(["train", "--resume", out, "--seed", "3"])
    # a record that belongs to another env than its folder says
    forged = tmp_path / "forged"
    shutil.copytree(out, forged)
    path = checkpoints.latest_dir(forged, NAME) / f"{NAME}.json"
    path.write_text(json.dumps({**json.loads(path.read_text()), "env": "shipgym/RVGHeading-v1"}))
    assert "belongs to another training" in error(["train", "--resume", str(forged)])
    path.write_text("{}")
    assert "not a training record (missing name" in error(["train", "--resume", str(forged)])
    assert "--env and --algo are required" in error(["train", "--out", str(tmp_path)])


# ------------------------------------------------------------------------------------------
# sweep files
# ------------------------------------------------------------------------------------------
def _sweep_file(tmp_path: Path, text: str, name: str = "sweep.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_sweep_file_is_a_grid_of_checked_choices(tmp_path: Path) -> None:
    path = _sweep_file(
        tmp_path,
        "env: shipgym/RVGSpeed-v1\nalgo: ppo\ntimesteps: 1000\n"
        "learning_rate: [1.0e-4, 3.0e-4]\nnet_arch: [[16], [32, 32]]\ngamma: 0.99\n",
    )
    spec = load_sweep(path, seeds=[0, 1])
    labels = [f"c{k:02d}-s{seed}" for k in range(4) for seed in (0, 1)]
    assert [t.label for t in spec.trials()] == labels
    assert spec.configs()[1] == {"learning_rate": 1e-4, "net_arch": [32, 32], "gamma": 0.99}
    kwargs = spec.trials()[2].train_kwargs()
    assert kwargs["policy_kwargs"] == {"net_arch": [32, 32], "log_std_init": -0.5}
    as_json = _sweep_file(tmp_path, json.dumps({"learning_rate": [1e-3]}), "sweep.json")
    assert load_sweep(as_json, env=ENV, algo="sac").configs() == [{"learning_rate": 1e-3}]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("lr: [0.1]", "unknown key 'lr'; allowed: the settings env, algo"),
        ("learning_rate: [-1]", "learning_rate choices must each be a number > 0, got -1"),
        ("gamma: ['high']", "gamma choices must each be a number in (0, 1], got 'high'"),
        ("net_arch: [64, 64]", "net_arch takes a list of choices, each a list of layer widths"),
        ("n_steps: [64.5]", "n_steps choices must each be an integer >= 1"),
        ("tau: [0.01]", "unknown key 'tau'"),  # a SAC hyperparameter in a PPO sweep
        ("n_epochs: []", "n_epochs lists no choice"),
        ("timesteps: 0", "timesteps must be an integer >= 1"),
        ("env: CartPole-v1", "env 'CartPole-v1' is not one of"),
        ("algo: sac", "sets algo to 'sac' and --algo to 'ppo'"),
        ("- 1\n- 2", "expected a mapping"),
        ("learning_rate: [1e-3", "is not valid YAML"),
    ],
)
def test_bad_sweep_files_are_refused_naming_the_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, message: str
) -> None:
    path = _sweep_file(tmp_path, text)
    argv = ["train", "--ray", "--sweep", str(path), "--env", ENV, "--algo", "ppo"]
    assert main([*argv, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()  # refused before Ray starts


def test_every_sweepable_hyperparameter_is_one_of_the_algorithm() -> None:
    from shipgym.rl.train import DEFAULTS

    for algo, keys in HYPERPARAMETERS.items():
        for key in keys:
            assert key in DEFAULTS[algo]["hyperparameters"] or key in ("net_arch", "log_std_init")


# ------------------------------------------------------------------------------------------
# a sweep on a local Ray, one trial losing its worker once
# ------------------------------------------------------------------------------------------
class _KillWorkerOnce(BaseCallback):
    """Ends the Ray worker's process (``os._exit``) at ``at`` steps on the trial's first
    attempt, as a lost node or an out-of-memory kill would; a marker file remembers it."""

    def __init__(self, folder: Path, at: int) -> None:
        super().__init__()
        self.marker = folder / "killed-at"
        self.at = at

    def _on_step(self) -> bool:
        if self.num_timesteps >= self.at and not self.marker.exists():
            self.marker.write_text(str(self.num_timesteps))
            os._exit(1)
        return True


def _kill_second_trial(folder: Path) -> BaseCallback:
    # after the second evaluation (and checkpoint) of trial c01, before its third
    return _KillWorkerOnce(folder, 2 * EVAL_FREQ + 64 if folder.name.startswith("c01") else 10**9)


@pytest.fixture(scope="module")
def ray_local() -> Iterator[None]:
    from ray import cloudpickle

    from shipgym.cluster import ray_session

    # the workers unpickle the test's callback by value (this module is not importable there)
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    with ray_session(None, 2):
        yield
    cloudpickle.unregister_pickle_by_value(sys.modules[__name__])


@pytest.fixture(scope="module")
def sweep(ray_local: None, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    root = tmp_path_factory.mktemp("sweep")
    path = _sweep_file(
        root,
        f"env: {ENV}\nalgo: ppo\ntimesteps: {4 * EVAL_FREQ}\nnum_envs: 2\n"
        f"eval_freq: {EVAL_FREQ}\neval_episodes: 2\nn_steps: 64\nbatch_size: 64\nn_epochs: 1\n"
        "learning_rate: [3.0e-4, 1.0e-3]\nnet_arch: [[16]]\n",
    )
    spec = load_sweep(path, seeds=[7])
    lines: list[str] = []
    out = root / "out"
    result = run_sweep(spec, out, progress=lines.append, callback_factory=_kill_second_trial)
    return {"out": out, "result": result, "lines": lines}


def test_sweep_trains_each_trial_into_its_folder_and_summarises(sweep: dict[str, Any]) -> None:
    out, result = sweep["out"], sweep["result"]
    assert [row["status"] for row in result.rows] == ["done", "done"]
    for row in result.rows:
        folder = out / row["folder"]
        record = json.loads((folder / f"{NAME}.json").read_text())
        assert record["partial"] is False and record["timesteps"] == 4 * EVAL_FREQ
        assert record["seed"] == 7 and record["env_kwargs"] == {}
        lr = {"c00": 3e-4, "c01": 1e-3}[row["trial"][:3]]
        assert record["hyperparameters"]["learning_rate"] == lr
        assert record["hyperparameters"]["policy_kwargs"]["net_arch"] == [16]
        assert list((folder / "tensorboard" / f"{NAME}_1").glob("events.out.tfevents.*"))
        load_agent(ENV, "ppo", folder)
    with (out / "summary.csv").open() as fh:
        table = list(csv.DictReader(fh))
    assert {r["trial"] for r in table} == {"c00-s7", "c01-s7"}
    assert {r["learning_rate"] for r in table} == {"0.0003", "0.001"}
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary["configs"]) == 2 and summary["sweep"]["seeds"] == [7]
    assert (out / "learning_curves.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "tune").is_dir()  # Ray Tune's files stay in the output folder
    assert any(line.startswith("[2/2]") for line in sweep["lines"])


def test_a_trial_whose_worker_died_finishes_from_its_latest_checkpoint(
    sweep: dict[str, Any],
) -> None:
    rows = {row["trial"]: row for row in sweep["result"].rows}
    killed, intact = rows["c01-s7"], rows["c00-s7"]
    folder = sweep["out"] / killed["folder"]
    assert int((folder / "killed-at").read_text()) == 2 * EVAL_FREQ + 64
    # restarted from the checkpoint of its second evaluation, not from zero
    assert killed["resumed_at"] == [2 * EVAL_FREQ]
    assert killed["learning_curve"]["timesteps"] == [EVAL_FREQ * k for k in range(1, 5)]
    assert intact["resumed_at"] == []
    assert any("c01-s7: its worker failed" in line for line in sweep["lines"])


def test_train_all_installs_the_best_trial_of_each_agent(
    sweep: dict[str, Any], tmp_path: Path
) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    try:
        import train_all
    finally:
        sys.path.pop(0)
    dest = tmp_path / "agents"
    argv = ["--from-sweep", str(sweep["out"]), "--out", str(dest), "--no-report"]
    assert train_all.main(argv) == 0
    installed = json.loads((dest / f"{NAME}.json").read_text())
    best = max(sweep["result"].rows, key=lambda r: r["best_validation_return"])
    assert installed["best_validation_return"] == best["best_validation_return"]
    assert installed["selected_from"].endswith(f"trial {best['trial']}")
    source = sweep["out"] / best["folder"] / f"{NAME}.zip"
    assert (dest / f"{NAME}.zip").read_bytes() == source.read_bytes()
    assert train_all.main(["--from-sweep", str(tmp_path), "--out", str(dest)]) == 2

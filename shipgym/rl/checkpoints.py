"""Checkpoints of a training: the best and the latest state of a run, on disk as it goes.

:func:`shipgym.rl.train.train` writes, at every evaluation, into its output folder ``DIR``::

    DIR/<name>.zip, <name>.json        the agent: the best policy so far and its record
    DIR/checkpoints/<name>/best/       <name>.zip, <name>.json, vecnormalize.pkl
    DIR/checkpoints/<name>/latest/     <name>.zip, <name>.json, vecnormalize.pkl
                                       (+ replay_buffer.pkl for SAC)

Every set is written through :func:`shipgym._io.write_atomically` (temporary files beside the
targets, then ``os.replace``), so an interrupt, a crash or a killed worker leaves the previous
complete checkpoint. The record (``<name>.json``) has the schema of a finished agent's record
with ``"partial": true`` and ``timesteps`` the steps done; the agent at the top of ``DIR`` is
therefore usable by :func:`shipgym.rl.agents.load_agent` (and ``shipgym evaluate --agents
DIR``) at any moment, and ``checkpoints/<name>/latest`` is what
:func:`shipgym.rl.train.resume` (``shipgym train --resume DIR``) continues from: the model with
its optimiser state, the ``VecNormalize`` statistics and, for SAC, the replay buffer.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

from shipgym._io import write_atomically

#: Subfolder of an output folder that holds the checkpoints, one folder per agent name.
CHECKPOINTS = "checkpoints"
#: Default subfolder of an output folder for the TensorBoard runs.
TENSORBOARD = "tensorboard"
#: File of the pickled ``VecNormalize`` (observation and return statistics).
VECNORMALIZE = "vecnormalize.pkl"
#: File of SAC's pickled replay buffer in the latest checkpoint.
REPLAY_BUFFER = "replay_buffer.pkl"
#: Keys every training record has (a file without them is not a training record).
RECORD_KEYS = (
    "name",
    "env",
    "algo",
    "timesteps",
    "requested_timesteps",
    "num_envs",
    "seed",
    "hyperparameters",
    "learning_curve",
    "obs_normaliser",
)
#: Attributes of a model left out of every saved file (rebuilt from the env on loading).
MODEL_EXCLUDE = ["_last_obs", "_last_original_obs"]


def checkpoint_root(out_dir: str | Path, name: str) -> Path:
    """``out_dir/checkpoints/<name>``: the best and latest checkpoints of agent ``name``."""
    return Path(out_dir) / CHECKPOINTS / name


def best_dir(out_dir: str | Path, name: str) -> Path:
    """Folder of the best checkpoint of agent ``name`` in ``out_dir``."""
    return checkpoint_root(out_dir, name) / "best"


def latest_dir(out_dir: str | Path, name: str) -> Path:
    """Folder of the latest checkpoint of agent ``name`` in ``out_dir``."""
    return checkpoint_root(out_dir, name) / "latest"


def clear(out_dir: str | Path, name: str) -> None:
    """Remove the checkpoints of agent ``name`` (a fresh training replaces them)."""
    shutil.rmtree(checkpoint_root(out_dir, name), ignore_errors=True)


def _json_writer(record: dict[str, Any]) -> Callable[[Path], None]:
    text = json.dumps(record, indent=2) + "\n"

    def write(path: Path) -> None:
        path.write_text(text)
        path.chmod(0o644)

    return write


def write_best(
    out_dir: str | Path, name: str, model: Any, vec_normalize: Any, record: dict[str, Any]
) -> None:
    """Write the agent (``out_dir/<name>.zip`` + ``.json``) and the best checkpoint.

    Parameters
    ----------
    out_dir : path
        The training's output folder.
    name : str
        The agent's file stem (:func:`shipgym.rl.train.agent_name`).
    model : stable_baselines3 BaseAlgorithm
        The policy that just scored the best validation return.
    vec_normalize : VecNormalize
        The training env's normaliser at that moment.
    record : dict
        The agent record (with the normaliser of this policy).
    """
    out = Path(out_dir)
    folder = best_dir(out, name)
    folder.parent.mkdir(parents=True, exist_ok=True)
    save = _model_writer(model, exclude=["replay_buffer", *MODEL_EXCLUDE])
    write_atomically(
        [
            (folder / f"{name}.zip", save),
            (folder / VECNORMALIZE, vec_normalize.save),
            (folder / f"{name}.json", _json_writer(record)),
            (out / f"{name}.zip", save),
            (out / f"{name}.json", _json_writer(record)),
        ]
    )


def write_latest(
    out_dir: str | Path,
    name: str,
    model: Any,
    vec_normalize: Any,
    record: dict[str, Any],
    replay_buffer: bool,
) -> None:
    """Write the latest checkpoint: model (with optimiser), normaliser, replay buffer, record.

    The record goes last, so a record always describes files at least as new as itself.
    """
    folder = latest_dir(out_dir, name)
    folder.parent.mkdir(parents=True, exist_ok=True)
    outputs: list[tuple[Path, Callable[[Path], Any]]] = [
        (folder / f"{name}.zip", _model_writer(model, exclude=MODEL_EXCLUDE)),
        (folder / VECNORMALIZE, vec_normalize.save),
    ]
    if replay_buffer:
        outputs.append((folder / REPLAY_BUFFER, model.save_replay_buffer))
    elif (folder / REPLAY_BUFFER).exists():
        (folder / REPLAY_BUFFER).unlink()
    outputs.append((folder / f"{name}.json", _json_writer(record)))
    write_atomically(outputs)


def write_final_record(out_dir: str | Path, name: str, record: dict[str, Any]) -> None:
    """Write the finished training's record of the agent (top of ``out_dir``, best checkpoint)."""
    write_atomically(
        [
            (best_dir(out_dir, name) / f"{name}.json", _json_writer(record)),
            (Path(out_dir) / f"{name}.json", _json_writer(record)),
        ]
    )


def _model_writer(model: Any, exclude: list[str]) -> Callable[[Path], None]:
    def write(path: Path) -> None:
        model.save(path, exclude=exclude)
        path.chmod(0o644)

    return write


def read_record(path: Path) -> dict[str, Any]:
    """A training record, checked to be one.

    Raises
    ------
    ValueError
        When the file is not JSON or lacks a key of :data:`RECORD_KEYS` (naming it).
    """
    try:
        record = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path} is not a readable training record: {exc}") from None
    if not isinstance(record, dict):
        raise ValueError(f"{path} is not a training record (expected a JSON object)")
    missing = [key for key in RECORD_KEYS if key not in record]
    if missing:
        raise ValueError(f"{path} is not a training record (missing {', '.join(missing)})")
    return record


def resumable(out_dir: str | Path) -> dict[str, Path]:
    """The latest checkpoints in ``out_dir``: agent name -> its checkpoint folder."""
    root = Path(out_dir) / CHECKPOINTS
    if not root.is_dir():
        return {}
    found = {}
    for folder in sorted(root.iterdir()):
        latest = folder / "latest"
        if (latest / f"{folder.name}.json").is_file() and (latest / VECNORMALIZE).is_file():
            found[folder.name] = latest
    return found


def find_latest(
    out_dir: str | Path, env_id: str | None = None, algo: str | None = None
) -> tuple[Path, dict[str, Any]]:
    """The latest checkpoint of the training in ``out_dir`` and its record.

    Parameters
    ----------
    out_dir : path
        An output folder of :func:`shipgym.rl.train.train`.
    env_id, algo : str, optional
        Which agent, when the folder holds checkpoints of several; checked against the
        record when given.

    Raises
    ------
    ValueError
        When ``out_dir`` is not a folder, holds no checkpoint (or none of this env and
        algorithm), holds several and none was named, or the record does not match its
        folder or the named env and algorithm.
    """
    from shipgym.envs import ENV_IDS
    from shipgym.rl.train import ALGOS, agent_name

    out = Path(out_dir)
    if not out.is_dir():
        raise ValueError(f"cannot resume from {str(out)!r}: not a folder")
    found = resumable(out)
    if not found:
        raise ValueError(
            f"{str(out)!r} holds no training checkpoint (expected "
            f"{CHECKPOINTS}/<name>/latest/<name>.json and {VECNORMALIZE} in it, written by "
            "shipgym train at every evaluation)"
        )
    if env_id is not None and algo is not None:
        name = agent_name(env_id, algo)
        if name not in found:
            raise ValueError(
                f"{str(out)!r} holds no checkpoint of {name}; it holds: {', '.join(found)}"
            )
    else:
        names = [
            n
            for n in found
            if (env_id is None or n.startswith(env_id.split("/")[-1] + "-"))
            and (algo is None or n.endswith(f"-{algo}"))
        ]
        if not names:
            raise ValueError(
                f"{str(out)!r} holds no checkpoint of "
                f"{env_id or 'any env'} / {algo or 'any algorithm'}; it holds: {', '.join(found)}"
            )
        if len(names) > 1:
            raise ValueError(
                f"{str(out)!r} holds checkpoints of several agents ({', '.join(names)}); "
                "name one with --env and --algo"
            )
        name = names[0]
    folder = found[name]
    record = read_record(folder / f"{name}.json")
    if record["env"] not in ENV_IDS or record["algo"] not in ALGOS:
        raise ValueError(
            f"{folder / (name + '.json')} records env {record['env']!r} and algorithm "
            f"{record['algo']!r}; expected one of {ENV_IDS} and one of {ALGOS}"
        )
    if agent_name(record["env"], record["algo"]) != name or (
        env_id is not None and record["env"] != env_id
    ):
        raise ValueError(
            f"{folder / (name + '.json')} is the record of {record['env']} {record['algo']}, "
            f"not of {env_id or name}: the checkpoint belongs to another training"
        )
    if not (folder / f"{name}.zip").is_file():
        raise ValueError(f"the checkpoint in {folder} has a record but no {name}.zip")
    return folder, record

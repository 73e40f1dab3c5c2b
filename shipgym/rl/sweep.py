"""Training sweeps on Ray Tune: one trial per hyperparameter configuration, env, algorithm and seed.

A sweep file (YAML or JSON) names the choices; every combination is a configuration::

    env: shipgym/RVGHeading-v1      # or a list of env ids (default: --env)
    algo: ppo                       # or [ppo, sac] (default: --algo)
    timesteps: 300000               # per trial (default: --timesteps, else the shipped budget)
    learning_rate: [1.0e-4, 3.0e-4]
    gamma: [0.99, 0.995]
    net_arch: [[64, 64], [128, 128]]

Settings (:data:`SETTINGS`) take one value (``env`` and ``algo`` also a list); every other
key is a hyperparameter of :data:`HYPERPARAMETERS` with a list of choices (a single value is
one choice; ``net_arch`` choices are lists of layer widths). :func:`run_sweep` runs one Ray
Tune trial per configuration and seed, each a :func:`shipgym.rl.train.train` into its own
folder ``OUT/trials/<name>/c<k>-s<seed>`` (agent, record, checkpoints, TensorBoard run). A
trial whose worker dies (a lost node, an out-of-memory kill) is restarted by Tune and
continues from the latest checkpoint in its folder; running the same sweep into the same
folder again skips the finished trials and continues the unfinished ones. At the end the
summary table (``summary.csv``, ``summary.json``) and the learning curves of every trial
(``learning_curves.png``) are written into ``OUT``; Ray Tune's own files go to ``OUT/tune``.
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import math
import os
import shutil
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from shipgym._io import write_atomically
from shipgym.rl import checkpoints

#: Keys of a sweep file that are not hyperparameters, with what they take.
SETTINGS: dict[str, str] = {
    "env": "an env id or a list of them",
    "algo": "'ppo', 'sac' or a list of them",
    "timesteps": "an integer >= 1 (environment steps per trial)",
    "num_envs": "an integer >= 1 (training sub-envs)",
    "eval_freq": "an integer >= 1 (environment steps between evaluations)",
    "eval_episodes": "an integer >= 1 (validation episodes per evaluation)",
}


@dataclass(frozen=True)
class _Kind:
    """What a hyperparameter takes: a check and the words for the error message."""

    words: str
    check: Callable[[Any], bool]


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _integer(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


_POSITIVE = _Kind("a number > 0", lambda v: _number(v) and v > 0)
_NON_NEGATIVE = _Kind("a number >= 0", lambda v: _number(v) and v >= 0)
_FRACTION = _Kind("a number in (0, 1]", lambda v: _number(v) and 0 < v <= 1)
_UNIT = _Kind("a number in [0, 1]", lambda v: _number(v) and 0 <= v <= 1)
_COUNT = _Kind("an integer >= 1", lambda v: _integer(v) and v >= 1)
_COUNT0 = _Kind("an integer >= 0", lambda v: _integer(v) and v >= 0)
_FINITE = _Kind("a finite number", _number)
_LAYERS = _Kind(
    "a list of layer widths (integers >= 1), e.g. [64, 64]",
    lambda v: isinstance(v, list) and len(v) > 0 and all(_integer(w) and w >= 1 for w in v),
)

#: The hyperparameters a sweep may vary, per algorithm (``net_arch`` and ``log_std_init`` go
#: into the policy's ``policy_kwargs``).
HYPERPARAMETERS: dict[str, dict[str, _Kind]] = {
    "ppo": {
        "learning_rate": _POSITIVE,
        "n_steps": _COUNT,
        "batch_size": _COUNT,
        "n_epochs": _COUNT,
        "gamma": _FRACTION,
        "gae_lambda": _UNIT,
        "clip_range": _POSITIVE,
        "ent_coef": _NON_NEGATIVE,
        "net_arch": _LAYERS,
        "log_std_init": _FINITE,
    },
    "sac": {
        "learning_rate": _POSITIVE,
        "buffer_size": _COUNT,
        "batch_size": _COUNT,
        "learning_starts": _COUNT0,
        "train_freq": _COUNT,
        "gradient_steps": _COUNT,
        "gamma": _FRACTION,
        "tau": _FRACTION,
        "net_arch": _LAYERS,
    },
}
_POLICY_KWARGS = ("net_arch", "log_std_init")
#: Most trials one sweep may have (a guard against a grid that multiplies out of hand).
MAX_TRIALS = 1000


@dataclass(frozen=True)
class Trial:
    """One trial of a sweep: an agent trained with one configuration and seed."""

    env: str
    algo: str
    config: int
    hyperparameters: dict[str, Any]
    seed: int

    @property
    def name(self) -> str:
        """Agent name (:func:`shipgym.rl.train.agent_name`)."""
        from shipgym.rl.train import agent_name

        return agent_name(self.env, self.algo)

    @property
    def label(self) -> str:
        """``c<k>-s<seed>``: the configuration and seed."""
        return f"c{self.config:02d}-s{self.seed}"

    def folder(self, out: Path) -> Path:
        """The trial's own output folder."""
        return out / "trials" / self.name / self.label

    def train_kwargs(self) -> dict[str, Any]:
        """The ``hyperparameters`` argument of :func:`shipgym.rl.train.train`."""
        from shipgym.rl.train import config

        params = {k: v for k, v in self.hyperparameters.items() if k not in _POLICY_KWARGS}
        policy = {k: v for k, v in self.hyperparameters.items() if k in _POLICY_KWARGS}
        if policy:
            base = config(self.env, self.algo)["hyperparameters"].get("policy_kwargs", {})
            params["policy_kwargs"] = {**base, **policy}
        return params


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep: envs, algorithms, the grid of hyperparameter choices, seeds, budget."""

    envs: list[str]
    algos: list[str]
    grid: dict[str, list[Any]]
    seeds: list[int]
    timesteps: int | None = None
    num_envs: int | None = None
    eval_freq: int | None = None
    eval_episodes: int | None = None
    source: str | None = None

    def configs(self) -> list[dict[str, Any]]:
        """Every combination of the grid's choices (one empty configuration for no grid)."""
        keys = list(self.grid)
        return [
            dict(zip(keys, values, strict=True))
            for values in itertools.product(*self.grid.values())
        ]

    def trials(self) -> list[Trial]:
        """One trial per env, algorithm, configuration and seed."""
        return [
            Trial(env, algo, k, cfg, seed)
            for env in self.envs
            for algo in self.algos
            for k, cfg in enumerate(self.configs())
            for seed in self.seeds
        ]

    def to_dict(self) -> dict[str, Any]:
        """JSON form (``sweep.json`` in the output folder)."""
        return {
            "source": self.source,
            "envs": self.envs,
            "algos": self.algos,
            "grid": self.grid,
            "seeds": self.seeds,
            "timesteps": self.timesteps,
            "num_envs": self.num_envs,
            "eval_freq": self.eval_freq,
            "eval_episodes": self.eval_episodes,
            "configs": self.configs(),
        }


def _as_number(value: Any) -> Any:
    """``value`` as a float if it is text that reads as a finite number, else unchanged."""
    if isinstance(value, str):
        try:
            number = float(value)
        except ValueError:
            return value
        return number if math.isfinite(number) else value
    return value


def _read_file(path: Path) -> dict[str, Any]:
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"--sweep: cannot read {str(path)!r}: {exc}") from None
    if path.suffix.lower() == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ValueError(f"{path} is not valid JSON: {exc}") from None
    else:
        import yaml

        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            reason = " ".join(str(exc).split())
            raise ValueError(f"{path} is not valid YAML: {reason}") from None
    if data is None:
        data = {}
    if not isinstance(data, dict) or not all(isinstance(k, str) for k in data):
        raise ValueError(
            f"{path}: expected a mapping of settings and hyperparameter choices "
            f"(e.g. 'learning_rate: [1.0e-4, 3.0e-4]'), got {type(data).__name__}"
        )
    return data


def _pick(where: str, key: str, from_file: Any, from_flag: Any) -> Any:
    if from_file is not None and from_flag is not None and from_file != from_flag:
        raise ValueError(
            f"{where} sets {key} to {from_file!r} and --{key.replace('_', '-')} to "
            f"{from_flag!r}; give it in one place"
        )
    return from_file if from_file is not None else from_flag


def load_sweep(
    path: str | Path | None,
    env: str | None = None,
    algo: str | None = None,
    timesteps: int | None = None,
    num_envs: int | None = None,
    eval_freq: int | None = None,
    eval_episodes: int | None = None,
    seeds: Sequence[int] | None = None,
) -> SweepSpec:
    """Read and check a sweep file; the other arguments fill the settings it leaves out.

    Parameters
    ----------
    path : path, optional
        The YAML (or ``.json``) file; None for a sweep over seeds of the default
        configuration.
    env, algo, timesteps, num_envs, eval_freq, eval_episodes : optional
        Settings from the command line; a setting given both here and in the file must agree.
    seeds : sequence of int, optional
        One trial per configuration and seed (default ``[0]``).

    Raises
    ------
    ValueError
        Naming the file, the key and what it takes: an unknown key (listing the allowed
        ones), a value of the wrong type or range, an empty list of choices, no env or
        algorithm, or more than :data:`MAX_TRIALS` trials.
    """
    from shipgym.envs import ENV_IDS
    from shipgym.rl.train import ALGOS, VALIDATION_SEED

    where = "the sweep" if path is None else str(path)
    data = {} if path is None else _read_file(Path(path))

    def listed(key: str, allowed: Sequence[str], flag: Any) -> list[str]:
        given = data.get(key)
        for v in given if isinstance(given, list) else [given]:
            if given is not None and (not isinstance(v, str) or v not in allowed):
                raise ValueError(f"{where}: {key} {v!r} is not one of {', '.join(allowed)}")
        value = _pick(where, key, given, flag)
        if value is None:
            raise ValueError(f"{where}: no {key} (give '{key}:' in the file or --{key})")
        values = value if isinstance(value, list) else [value]
        if not values or len(set(values)) != len(values):
            raise ValueError(f"{where}: {key} must list distinct values, got {value!r}")
        return list(values)

    envs = listed("env", ENV_IDS, env)
    algos = listed("algo", ALGOS, algo)
    counts = {}
    for key, flag in (
        ("timesteps", timesteps),
        ("num_envs", num_envs),
        ("eval_freq", eval_freq),
        ("eval_episodes", eval_episodes),
    ):
        value = _pick(where, key, data.get(key), flag)
        if value is not None and not _COUNT.check(value):
            raise ValueError(f"{where}: {key} must be {SETTINGS[key]}, got {value!r}")
        counts[key] = value
    allowed = [k for k in HYPERPARAMETERS[algos[0]] if all(k in HYPERPARAMETERS[a] for a in algos)]
    grid: dict[str, list[Any]] = {}
    for key, value in data.items():
        if key in SETTINGS:
            continue
        if key not in allowed:
            raise ValueError(
                f"{where}: unknown key {key!r}; allowed: the settings {', '.join(SETTINGS)} and "
                f"the {'/'.join(algos)} hyperparameters {', '.join(allowed)}"
            )
        kind = HYPERPARAMETERS[algos[0]][key]
        if key == "net_arch":
            if not isinstance(value, list) or not all(isinstance(v, list) for v in value):
                raise ValueError(
                    f"{where}: net_arch takes a list of choices, each {kind.words}: "
                    f"e.g. [[64, 64], [128, 128]], got {value!r}"
                )
            choices = value
        else:
            choices = value if isinstance(value, list) else [value]
        if not choices:
            raise ValueError(f"{where}: {key} lists no choice")
        if kind not in (_COUNT, _COUNT0, _LAYERS):  # YAML 1.1 reads 1e-4 (no dot) as text
            choices = [_as_number(c) for c in choices]
        for choice in choices:
            if not kind.check(choice):
                raise ValueError(
                    f"{where}: {key} choices must each be {kind.words}, got {choice!r}"
                )
        if len({json.dumps(c) for c in choices}) != len(choices):
            raise ValueError(f"{where}: {key} repeats a choice: {choices!r}")
        grid[key] = list(choices)
    seeds = [0] if seeds is None else list(seeds)
    if not seeds:
        raise ValueError(f"{where}: no seed")
    largest = VALIDATION_SEED - 1 - (counts["num_envs"] or 16)
    for seed in seeds:
        if not _integer(seed) or not 0 <= seed <= largest:
            raise ValueError(
                f"seed {seed!r} must be an integer in [0, {largest}] (training seeds stay below "
                "the validation seeds)"
            )
    spec = SweepSpec(envs, algos, grid, seeds, source=None if path is None else str(path), **counts)
    n = len(spec.trials())
    if n > MAX_TRIALS:
        raise ValueError(f"{where}: the grid makes {n} trials, more than {MAX_TRIALS}")
    return spec


# ------------------------------------------------------------------------------------------
# the trial (runs in a Ray worker)
# ------------------------------------------------------------------------------------------
def run_trial(
    trial: dict[str, Any],
    report: Callable[[dict[str, Any]], None] | None = None,
    callbacks: Sequence[Any] = (),
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Train one trial into its folder: skip it if finished, resume it from its latest
    checkpoint if there is one, else start it.

    Parameters
    ----------
    trial : dict
        ``env``, ``algo``, ``seed``, ``hyperparameters`` (as for :func:`train`), ``folder``,
        ``timesteps``, ``num_envs``, ``eval_freq``, ``eval_episodes`` (None: defaults).
    report : callable, optional
        Called after every evaluation with its metrics (``tune.report`` in a Ray trial).
    callbacks : sequence of SB3 callbacks
        Extra callbacks of the training.
    progress : callable, optional
        Progress lines.

    Returns
    -------
    dict
        The trial's final agent record.

    Raises
    ------
    ValueError
        If the folder holds a training with other settings (another sweep's trial).
    """
    from shipgym.rl.train import agent_name, config, resume, train

    out = Path(trial["folder"])
    name = agent_name(trial["env"], trial["algo"])
    cfg = config(trial["env"], trial["algo"])
    params = {**cfg["hyperparameters"], **trial["hyperparameters"]}
    timesteps = trial["timesteps"] or cfg["timesteps"]
    latest = checkpoints.latest_dir(out, name) / f"{name}.json"
    if latest.is_file():
        record = checkpoints.read_record(latest)
        differs = [
            key
            for key, want in (
                ("env", trial["env"]),
                ("seed", trial["seed"]),
                ("hyperparameters", params),
            )
            if json.dumps(record[key], sort_keys=True) != json.dumps(want, sort_keys=True)
        ]
        if differs:
            raise ValueError(
                f"{out} holds a training with another {differs[0]} than this trial's; "
                "give the sweep a new output folder"
            )
        if not record.get("partial") and record["timesteps"] >= timesteps:
            final = checkpoints.read_record(out / f"{name}.json")
            if report is not None:
                report(
                    {
                        "timesteps": final["timesteps"],
                        "validation_return": final["final_validation_return"],
                        "best_validation_return": final["best_validation_return"],
                        "best_timestep": final["best_timestep"],
                        "final": True,
                    }
                )
            return final
        return resume(
            out,
            trial["env"],
            trial["algo"],
            timesteps=timesteps,
            progress_bar=False,
            progress=progress,
            callbacks=callbacks,
            on_evaluation=report,
        ).meta
    return train(
        trial["env"],
        trial["algo"],
        timesteps=timesteps,
        seed=trial["seed"],
        out_dir=out,
        num_envs=trial["num_envs"],
        eval_freq=trial["eval_freq"],
        eval_episodes=trial["eval_episodes"] or 16,
        progress_bar=False,
        progress=progress,
        hyperparameters=trial["hyperparameters"],
        overwrite=True,
        callbacks=callbacks,
        on_evaluation=report,
    ).meta


def _tune_trial(
    config: dict[str, Any], callback_factory: Callable[[Path], Any] | None = None
) -> None:
    """Ray Tune's function trainable: one trial, one CPU, one torch thread."""
    import torch
    from ray import tune

    torch.set_num_threads(1)
    trial = config["trial"]
    callbacks = [] if callback_factory is None else [callback_factory(Path(trial["folder"]))]
    run_trial(trial, report=tune.report, callbacks=callbacks)


# ------------------------------------------------------------------------------------------
# the sweep (runs in the driver)
# ------------------------------------------------------------------------------------------
@dataclass
class SweepResult:
    """What :func:`run_sweep` made: a row per trial, the per-configuration summary, files."""

    out: Path
    rows: list[dict[str, Any]]
    configs: list[dict[str, Any]]
    outputs: list[Path] = field(default_factory=list)

    @property
    def failed(self) -> list[dict[str, Any]]:
        """Rows of the trials that did not finish."""
        return [row for row in self.rows if row["status"] != "done"]

    def table(self) -> list[str]:
        """The summary as printable lines (best trial of each agent first)."""
        head = ("trial", "agent", "hyperparameters", "steps", "best return (step)", "final",
                "wall [s]", "resumed at", "status")  # fmt: skip
        varying = _varying(self.rows)
        body = [
            (
                row["trial"],
                row["agent"],
                _short(row["hyperparameters"], varying) or "-",
                _fmt_int(row["timesteps"]),
                "-"
                if row["best_validation_return"] is None
                else f"{row['best_validation_return']:.1f} ({_fmt_int(row['best_timestep'])})",
                "-"
                if row["final_validation_return"] is None
                else f"{row['final_validation_return']:.1f}",
                "-" if row["wall_time_s"] is None else f"{row['wall_time_s']:.0f}",
                ",".join(_fmt_int(s) for s in row["resumed_at"]) or "-",
                row["status"],
            )
            for row in self.rows
        ]
        widths = [max(len(str(r[i])) for r in [head, *body]) for i in range(len(head))]
        lines = [
            "  ".join(str(c).ljust(w) for c, w in zip(r, widths, strict=True)).rstrip()
            for r in [head, *body]
        ]
        lines.insert(1, "  ".join("-" * w for w in widths))
        return lines


def _fmt_int(value: Any) -> str:
    return "-" if value is None else f"{int(value):,}"


def _short(params: dict[str, Any], keys: Sequence[str] | None = None) -> str:
    return " ".join(
        f"{k}={json.dumps(v).replace(' ', '')}"
        for k, v in params.items()
        if keys is None or k in keys
    )


def _varying(rows: list[dict[str, Any]]) -> list[str]:
    """The hyperparameters whose value differs between the rows (the rest is fixed)."""
    keys = {k for row in rows for k in row["hyperparameters"]}
    return sorted(
        k for k in keys if len({json.dumps(r["hyperparameters"].get(k)) for r in rows}) > 1
    )


def _row(trial: Trial, out: Path, error: str | None) -> dict[str, Any]:
    folder = trial.folder(out)
    record_path = folder / f"{trial.name}.json"
    record: dict[str, Any] = {}
    if record_path.is_file():
        try:
            record = checkpoints.read_record(record_path)
        except ValueError:
            record = {}
    if record and not record.get("partial") and error is None:
        status = "done"
    elif error is not None:
        status = f"failed: {error}"
    else:
        status = "unfinished" if record else "not started"
    return {
        "trial": trial.label,
        "agent": trial.name,
        "env": trial.env,
        "algo": trial.algo,
        "config": trial.config,
        "seed": trial.seed,
        "hyperparameters": trial.hyperparameters,
        "timesteps": record.get("timesteps"),
        "requested_timesteps": record.get("requested_timesteps"),
        "best_validation_return": record.get("best_validation_return"),
        "best_timestep": record.get("best_timestep"),
        "final_validation_return": record.get("final_validation_return"),
        "wall_time_s": record.get("wall_time_s"),
        "resumed_at": record.get("resumed_at", []),
        "learning_curve": record.get("learning_curve", {"timesteps": [], "mean_return": []}),
        "status": status,
        "folder": str(folder.relative_to(out)),
    }


def _config_summary(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Mean and spread over seeds of each configuration's best validation return."""
    groups: dict[tuple[str, int], list[dict[str, Any]]] = {}
    for row in rows:
        groups.setdefault((row["agent"], row["config"]), []).append(row)
    summary = []
    for (agent, k), group in groups.items():
        best = [
            r["best_validation_return"] for r in group if r["best_validation_return"] is not None
        ]
        summary.append(
            {
                "agent": agent,
                "config": k,
                "hyperparameters": group[0]["hyperparameters"],
                "seeds": [r["seed"] for r in group],
                "mean_best_validation_return": float(np.mean(best)) if best else None,
                "std_best_validation_return": float(np.std(best)) if best else None,
            }
        )
    summary.sort(key=lambda s: (s["agent"], -(s["mean_best_validation_return"] or -math.inf)))
    return summary


def _csv_writer(rows: list[dict[str, Any]], grid_keys: list[str]) -> Callable[[Path], None]:
    columns = [
        *("trial", "agent", "env", "algo", "config", "seed"),
        *grid_keys,
        *("timesteps", "requested_timesteps", "best_validation_return", "best_timestep"),
        *("final_validation_return", "wall_time_s", "resumed_at", "status", "folder"),
    ]
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        values = {k: row[k] for k in columns if k in row and k not in grid_keys}
        values.update({k: json.dumps(row["hyperparameters"].get(k)) for k in grid_keys})
        values["resumed_at"] = " ".join(str(s) for s in row["resumed_at"])
        writer.writerow(values)
    text = buffer.getvalue()
    return lambda path: path.write_text(text)


def learning_curve_figure(rows: list[dict[str, Any]]) -> Any:
    """Validation return against environment steps of every trial, one panel per agent;
    colour by configuration, line style by seed, a ring where a trial was resumed."""
    from matplotlib.figure import Figure

    agents = sorted({row["agent"] for row in rows})
    varying = _varying(rows)
    fig = Figure(figsize=(7.0, 3.2 * len(agents)), layout="constrained")
    axes = fig.subplots(len(agents), 1, squeeze=False)[:, 0]
    styles = ["-", "--", ":", "-."]
    seeds = sorted({row["seed"] for row in rows})
    colours = [f"C{i % 10}" for i in range(max(r["config"] for r in rows) + 1)] if rows else []
    for ax, agent in zip(axes, agents, strict=True):
        for row in (r for r in rows if r["agent"] == agent):
            curve = row["learning_curve"]
            steps = np.asarray(curve["timesteps"], dtype=float)
            values = np.asarray(curve["mean_return"], dtype=float)
            label = f"{row['trial']} {_short(row['hyperparameters'], varying)}".strip()
            ax.plot(
                steps,
                values,
                styles[seeds.index(row["seed"]) % len(styles)],
                color=colours[row["config"]],
                marker=".",
                label=label,
            )
            resumed = [i for i, s in enumerate(curve["timesteps"]) if s in row["resumed_at"]]
            if resumed:
                ax.plot(
                    steps[resumed],
                    values[resumed],
                    "o",
                    mfc="none",
                    ms=10,
                    color=colours[row["config"]],
                    label=f"{row['trial']} resumed from its checkpoint",
                )
        ax.set_title(agent)
        ax.set_xlabel("environment steps")
        ax.set_ylabel("validation return")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    return fig


def _figure_writer(rows: list[dict[str, Any]]) -> Callable[[Path], None]:
    def write(path: Path) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        fig = learning_curve_figure(rows)
        FigureCanvasAgg(fig)
        fig.savefig(path, dpi=110)

    return write


def write_summary(spec: SweepSpec, out: Path, errors: dict[str, str] | None = None) -> SweepResult:
    """Read every trial's record and write ``summary.csv``, ``summary.json`` and
    ``learning_curves.png`` into ``out``."""
    errors = errors or {}
    trials = spec.trials()
    rows = [_row(t, out, errors.get(str(t.folder(out)))) for t in trials]
    rows.sort(key=lambda r: (r["agent"], -(r["best_validation_return"] or -math.inf)))
    configs = _config_summary(rows)
    summary = {"sweep": spec.to_dict(), "configs": configs, "trials": rows}
    outputs: list[tuple[Path, Callable[[Path], Any]]] = [
        (out / "summary.csv", _csv_writer(rows, list(spec.grid))),
        (out / "summary.json", lambda p: p.write_text(json.dumps(summary, indent=2) + "\n")),
        (out / "learning_curves.png", _figure_writer(rows)),
    ]
    write_atomically(outputs)
    return SweepResult(out, rows, configs, [p for p, _ in outputs])


def _progress_callback(progress: Callable[[str], None] | None, total: int) -> Any:
    from ray import tune

    class _Progress(tune.Callback):
        """Driver-side lines: each trial's evaluations, restarts and ends."""

        def __init__(self) -> None:
            self.finished = 0

        def _say(self, line: str) -> None:
            if progress is not None:
                progress(line)

        def on_trial_result(
            self, iteration: int, trials: list, trial: Any, result: dict, **info: Any
        ) -> None:
            if "timesteps" in result and not result.get("final"):
                self._say(
                    f"{trial.config['trial']['label']}: {result['timesteps']} steps, validation "
                    f"return {result['validation_return']:.1f} "
                    f"(best {result['best_validation_return']:.1f})"
                )

        def on_trial_recover(self, iteration: int, trials: list, trial: Any, **info: Any) -> None:
            self._say(
                f"{trial.config['trial']['label']}: its worker failed; restarting it from its "
                "latest checkpoint"
            )

        def on_trial_complete(self, iteration: int, trials: list, trial: Any, **info: Any) -> None:
            self.finished += 1
            self._say(f"[{self.finished}/{total}] {trial.config['trial']['label']} done")

        def on_trial_error(self, iteration: int, trials: list, trial: Any, **info: Any) -> None:
            self.finished += 1
            self._say(f"[{self.finished}/{total}] {trial.config['trial']['label']} FAILED")

    return _Progress()


def run_sweep(
    spec: SweepSpec,
    out_dir: str | Path,
    address: str | None = None,
    num_cpus: int | None = None,
    progress: Callable[[str], None] | None = None,
    max_failures: int = 3,
    callback_factory: Callable[[Path], Any] | None = None,
) -> SweepResult:
    """Run every trial of ``spec`` as a Ray Tune trial (one CPU each) and write the summary.

    Parameters
    ----------
    spec : SweepSpec
        From :func:`load_sweep`.
    out_dir : path
        Output folder: ``trials/`` (one folder per trial), ``tune/`` (Ray Tune's files),
        ``sweep.json``, ``summary.csv``, ``summary.json``, ``learning_curves.png``. On a
        cluster it must be on a filesystem every node sees.
    address : str, optional
        Ray cluster to join (:func:`shipgym.cluster.ray_session`); None starts Ray locally.
    num_cpus : int, optional
        CPUs of a local Ray.
    progress : callable, optional
        Called with a line per evaluation, restart and end of a trial.
    max_failures : int
        Restarts of a trial whose worker died or that raised (each continues from the
        trial's latest checkpoint).
    callback_factory : callable, optional
        Called in each trial with its folder; returns an extra SB3 callback of its training
        (for instrumentation; must be picklable).

    Returns
    -------
    SweepResult
    """
    from ray import tune

    from shipgym.cluster import ray_session

    out = Path(out_dir).resolve()
    out.mkdir(parents=True, exist_ok=True)
    trials = spec.trials()
    write_atomically(
        [(out / "sweep.json", lambda p: p.write_text(json.dumps(spec.to_dict(), indent=2) + "\n"))]
    )
    payload = [
        {
            "env": t.env,
            "algo": t.algo,
            "seed": t.seed,
            "hyperparameters": t.train_kwargs(),
            "folder": str(t.folder(out)),
            "label": f"{t.name}/{t.label}",
            "timesteps": spec.timesteps,
            "num_envs": spec.num_envs,
            "eval_freq": spec.eval_freq,
            "eval_episodes": spec.eval_episodes,
        }
        for t in trials
    ]
    if progress is not None:
        progress(f"sweep: {len(trials)} trials into {out / 'trials'}")
    errors: dict[str, str] = {}
    # Tune's classic console output, which verbose=0 silences (the newer one prints a box per
    # result and a TensorBoard hint into Ray's temporary folder); our progress lines remain
    os.environ.setdefault("RAY_AIR_NEW_OUTPUT", "0")
    with ray_session(address, num_cpus):
        trainable = tune.with_resources(
            tune.with_parameters(_tune_trial, callback_factory=callback_factory), {"cpu": 1}
        )
        tuner = tune.Tuner(
            trainable,
            param_space={"trial": tune.grid_search(payload)},
            tune_config=tune.TuneConfig(
                trial_name_creator=lambda t: t.config["trial"]["label"].replace("/", "-"),
                trial_dirname_creator=lambda t: t.config["trial"]["label"].replace("/", "-"),
            ),
            run_config=tune.RunConfig(
                name=time.strftime("sweep-%Y%m%d-%H%M%S"),
                storage_path=str(out / "tune"),
                failure_config=tune.FailureConfig(max_failures=max_failures),
                callbacks=[_progress_callback(progress, len(trials))],
                verbose=0,
            ),
        )
        results = tuner.fit()
        for result in results:
            if result.error is not None:
                message = " ".join(str(result.error).split())
                errors[result.config["trial"]["folder"]] = message[-300:]
    return write_summary(spec, out, errors)


# ------------------------------------------------------------------------------------------
# the best trial of each agent
# ------------------------------------------------------------------------------------------
def best_trials(sweep_dir: str | Path) -> dict[str, Path]:
    """The folder of the best finished trial of each agent in a sweep's output folder.

    "Best" is the highest ``best_validation_return`` of the trial records (read from
    ``trials/<name>/*/<name>.json``; unfinished trials are left out).

    Raises
    ------
    ValueError
        When ``sweep_dir`` holds no finished trial.
    """
    root = Path(sweep_dir) / "trials"
    best: dict[str, tuple[float, Path]] = {}
    if root.is_dir():
        for agent in sorted(p for p in root.iterdir() if p.is_dir()):
            for folder in sorted(p for p in agent.iterdir() if p.is_dir()):
                path = folder / f"{agent.name}.json"
                if not (path.is_file() and (folder / f"{agent.name}.zip").is_file()):
                    continue
                record = checkpoints.read_record(path)
                score = record.get("best_validation_return")
                if record.get("partial") or score is None:
                    continue
                if agent.name not in best or score > best[agent.name][0]:
                    best[agent.name] = (float(score), folder)
    if not best:
        raise ValueError(
            f"{sweep_dir} holds no finished sweep trial (expected "
            "trials/<name>/<trial>/<name>.json, written by shipgym train --ray --sweep)"
        )
    return {name: folder for name, (_, folder) in best.items()}


def install_agent(
    trial_dir: Path, name: str, dest: str | Path, source: str | None = None
) -> tuple[Path, Path]:
    """Copy an agent (``<name>.zip``, ``<name>.json``) from a training's output folder into
    ``dest`` atomically; with ``source`` (e.g. the sweep folder and trial) the record gains
    ``"selected_from": source``."""
    record = checkpoints.read_record(trial_dir / f"{name}.json")
    if source is not None:
        record["selected_from"] = source
    text = json.dumps(record, indent=2) + "\n"
    dest = Path(dest)
    zip_path, json_path = dest / f"{name}.zip", dest / f"{name}.json"
    write_atomically(
        [
            (zip_path, lambda p: shutil.copyfile(trial_dir / f"{name}.zip", p)),
            (json_path, lambda p: p.write_text(text)),
        ]
    )
    return zip_path, json_path

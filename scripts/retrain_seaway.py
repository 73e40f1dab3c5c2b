"""What retraining in a seaway costs and gives: PPO on ``shipgym/NomotoHeading-v0`` at sea.

    python scripts/retrain_seaway.py [--out DIR] [--timesteps N] [--episodes N] [--retrain]
                                     [--docs]

1. Trains PPO on the Nomoto heading task in the benchmark's seaway (wind and sea state of the
   ``seaway`` condition, :func:`seaway_kwargs`) with the shipped agent's configuration
   (:func:`shipgym.rl.train.config`: budget, seed, hyperparameters), into ``DIR`` (default
   ``out/seaway_retraining``), a progress line per evaluation. A finished agent of the same
   seaway and budget already in ``DIR`` is reused (``--retrain`` trains anew).
2. Evaluates the shipped (calm-trained) agent, the retrained one and the classic autopilots in
   calm water and in the seaway on the benchmark's episodes (seeds from
   :data:`~shipgym.rl.train.BENCHMARK_SEED`), with :func:`shipgym.benchmark.evaluate.evaluate`.
3. Prints the comparison table: return, the measured heading error (``heading_rms_deg``: what
   the compass shows, with the wave-frequency motion), the low-frequency heading error
   (``lf_heading_rms_deg``: RMS of ``ssa(psi_d - psi)`` with ``psi`` the low-frequency heading
   of ``info["state"]``, the part the autopilot must hold; the reward's), the rudder travel and
   reversals per minute, each a mean over the episodes with its bootstrap 95 % interval.

``--docs`` also writes the figure ``docs/seaway_retraining.png`` (the retrained agent's
learning curve beside the shipped one's; LF heading error and rudder travel of the four
agent cases) and the table block of ``docs/results/seaway_retraining.md``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ENV_ID = "shipgym/NomotoHeading-v0"
ALGO = "ppo"
#: The seaway of the Nomoto heading task when the benchmark has no ``seaway`` condition: a
#: fresh breeze (Beaufort 5) and a moderate sea (WMO sea state 4), directions drawn per episode.
FALLBACK_SEAWAY: dict[str, Any] = {
    "wind": {"speed": 9.5},
    "sea_state": {"significant_height": 2.0, "peak_period": 8.0},
}
#: Classic controllers evaluated for reference.
CLASSIC = ("classic", "classic-tuned")
METRICS = (
    "return",
    "heading_rms_deg",
    "lf_heading_rms_deg",
    "rudder_travel_deg_min",
    "rudder_reversals_min",
)
FIGURE = ROOT / "docs" / "seaway_retraining.png"
PAGE = ROOT / "docs" / "results" / "seaway_retraining.md"
PAGE_MARKER = "seaway-retraining"


def _print(line: str) -> None:
    print(line, flush=True)


def seaway_kwargs(env_id: str) -> tuple[dict[str, Any], str]:
    """The env keyword arguments of the benchmark's ``seaway`` condition on ``env_id`` and
    where they came from (the benchmark's scenario, or :data:`FALLBACK_SEAWAY`)."""
    from shipgym.benchmark import runner

    if "seaway" not in runner.CONDITIONS:
        return dict(FALLBACK_SEAWAY), "FALLBACK_SEAWAY of this script"
    (scenario,) = runner.scenarios(env_id, "seaway", 0.0)
    kwargs = {**(scenario.env_kwargs or {}), **(scenario.reset_options or {})}
    if scenario.wrappers or not {"wind", "sea_state"} <= set(kwargs):
        raise ValueError(
            f"the benchmark's seaway scenario of {env_id} is not a wind and sea_state without "
            f"wrappers (got {scenario}); this script trains in the env's wind and sea_state"
        )
    return {key: kwargs[key] for key in ("wind", "sea_state")}, "the benchmark's seaway condition"


def _finished_record(out: Path, env_kwargs: dict[str, Any], timesteps: int) -> dict | None:
    """The record of a finished agent in ``out`` trained in ``env_kwargs`` for ``timesteps``."""
    from shipgym.rl.train import agent_name

    path = out / f"{agent_name(ENV_ID, ALGO)}.json"
    if not path.is_file() or not (out / f"{agent_name(ENV_ID, ALGO)}.zip").is_file():
        return None
    record = json.loads(path.read_text(encoding="utf-8"))
    same = (
        not record.get("partial", True)
        and record.get("requested_timesteps") == timesteps
        and record.get("env_kwargs") == json.loads(json.dumps(env_kwargs))
    )
    return record if same else None


def retrain(out: Path, env_kwargs: dict[str, Any], timesteps: int, again: bool) -> dict:
    """Train PPO on :data:`ENV_ID` in ``env_kwargs`` into ``out`` (or reuse a finished one);
    the agent's record."""
    from shipgym.rl.train import train

    record = None if again else _finished_record(out, env_kwargs, timesteps)
    if record is not None:
        _print(f"reusing the finished agent in {out} ({record['wall_time_s']} s of training)")
        return record
    result = train(
        ENV_ID,
        ALGO,
        timesteps=timesteps,
        out_dir=out,
        progress_bar=False,
        progress=_print,
        env_kwargs=env_kwargs,
        tensorboard_log=False,
        overwrite=True,
    )
    return result.meta


def lf_heading_rms_deg(result: Any) -> np.ndarray:
    """Per episode: RMS of the low-frequency heading error ``ssa(psi_d - psi)`` [deg], ``psi``
    the heading of ``info["state"]`` (NaN for a blown-up episode)."""
    from shipgym.benchmark.evaluate import BLOW_UP

    out = np.full(len(result.logs), math.nan)
    for k, log in enumerate(result.logs):
        if log.termination_reason == BLOW_UP:
            continue
        psi = np.asarray(log.state, dtype=float)[:, 2]
        e = np.angle(np.exp(1j * (log.signal("heading_setpoint") - psi)))
        out[k] = math.degrees(float(np.sqrt(np.mean(e**2))))
    return out


def summary(result: Any) -> dict[str, dict[str, Any]]:
    """Mean, bootstrap 95 % interval and per-episode values of :data:`METRICS`."""
    from shipgym.benchmark.stats import bootstrap_ci

    per = {
        "return": np.asarray(result.returns, dtype=float),
        "lf_heading_rms_deg": lf_heading_rms_deg(result),
        **{k: result.values(k) for k in METRICS if k not in ("return", "lf_heading_rms_deg")},
    }
    return {
        key: {
            "mean": float(np.mean(v)),
            "ci95": [float(c) for c in bootstrap_ci(v)],
            "values": [float(x) for x in v],
        }
        for key, v in per.items()
    }


def evaluate_all(
    agents: dict[str, Path | None], sea: dict[str, Any], episodes: int, seed: int
) -> dict[tuple[str, str], dict[str, dict[str, Any]]]:
    """Summaries by (case, water) of the agents (name -> agent folder, None: shipped) and the
    classic controllers in calm water and in ``sea``."""
    from shipgym.benchmark.evaluate import evaluate
    from shipgym.benchmark.policies import make_policy

    cases: dict[str, Any] = {name: make_policy(ALGO, ENV_ID, d) for name, d in agents.items()}
    cases.update({name: make_policy(name, ENV_ID) for name in CLASSIC})
    out = {}
    for water, kwargs in (("calm", None), ("seaway", sea)):
        for name, policy in cases.items():
            start = time.perf_counter()
            result = evaluate(ENV_ID, policy, name, episodes, seed, env_kwargs=kwargs,
                              progress=lambda line: None, condition=water)  # fmt: skip
            out[name, water] = summary(result)
            mean = out[name, water]["return"]["mean"]
            _print(
                f"evaluated {name} in {water} water: {episodes} episodes in "
                f"{time.perf_counter() - start:.1f} s, return {mean:.1f}"
            )
    return out


def _cell(s: dict[str, Any]) -> str:
    lo, hi = s["ci95"]
    return f"{s['mean']:.3g} [{lo:.3g}, {hi:.3g}]"


def table(results: dict[tuple[str, str], dict[str, dict[str, Any]]]) -> str:
    """The Markdown table of ``results`` (one row per case and water)."""
    lines = [
        "| controller | water | " + " | ".join(METRICS) + " |",
        "|---|---|" + "---:|" * len(METRICS),
    ]
    for (name, water), s in sorted(results.items(), key=lambda kv: (kv[0][1], kv[0][0])):
        lines.append(f"| {name} | {water} | " + " | ".join(_cell(s[m]) for m in METRICS) + " |")
    return "\n".join(lines)


def plot(
    record: dict[str, Any],
    shipped: dict[str, Any],
    results: dict[tuple[str, str], dict[str, dict[str, Any]]],
    agents: tuple[str, str],
    path: Path,
) -> Path:
    """Learning curves (validation return, in each agent's training water) and bars of the
    LF heading error and the rudder travel of the ``agents`` in calm water and the seaway."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    ax = axes[0]
    for rec, label in ((shipped, "shipped (calm water)"), (record, "retrained (seaway)")):
        curve = rec["learning_curve"]
        ax.plot(np.asarray(curve["timesteps"]) / 1e6, curve["mean_return"], "o-", ms=3,
                label=label)  # fmt: skip
    ax.set_xlabel("environment steps [million]")
    ax.set_ylabel("validation return (own water)")
    ax.set_ylim(bottom=max(ax.get_ylim()[0], -150.0))
    ax.set_title("PPO learning curves")
    ax.legend()
    width = 0.38
    x = np.arange(len(agents))
    for ax, key, label in (
        (axes[1], "lf_heading_rms_deg", "LF heading error RMS [deg]"),
        (axes[2], "rudder_travel_deg_min", "rudder travel [deg/min]"),
    ):
        for j, water in enumerate(("calm", "seaway")):
            s = [results[name, water][key] for name in agents]
            mean = np.array([v["mean"] for v in s])
            err = np.array([[v["mean"] - v["ci95"][0], v["ci95"][1] - v["mean"]] for v in s]).T
            ax.bar(x + (j - 0.5) * width, mean, width, yerr=err, capsize=3,
                   label=f"in {water} water")  # fmt: skip
        ax.set_xticks(x, agents)
        ax.set_ylabel(label)
        ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv: list[str]) -> int:
    from shipgym.rl.agents import load_meta
    from shipgym.rl.train import BENCHMARK_SEED, config

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--out",
        type=Path,
        default=ROOT / "out" / "seaway_retraining",
        help="folder of the retrained agent (default: out/seaway_retraining)",
    )
    parser.add_argument(
        "--timesteps",
        type=int,
        default=config(ENV_ID, ALGO)["timesteps"],
        help="training steps (default: the shipped agent's budget)",
    )
    parser.add_argument(
        "--episodes",
        type=int,
        default=100,
        help="evaluation episodes per case (default: the benchmark's 100)",
    )
    parser.add_argument(
        "--retrain",
        action="store_true",
        help="train anew even if DIR holds a finished agent of this seaway",
    )
    parser.add_argument(
        "--docs",
        action="store_true",
        help=f"write {FIGURE.relative_to(ROOT)} and the table of {PAGE.relative_to(ROOT)}",
    )
    args = parser.parse_args(argv)
    if args.timesteps < 1 or args.episodes < 2:
        parser.error(
            f"--timesteps must be >= 1 and --episodes >= 2, got {args.timesteps}, {args.episodes}"
        )

    sea, source = seaway_kwargs(ENV_ID)
    _print(f"seaway ({source}): {json.dumps(sea)}")
    record = retrain(args.out, sea, args.timesteps, args.retrain)
    _print(
        f"training: {record['timesteps']} steps in {record['wall_time_s']:.0f} s "
        f"({record['steps_per_s']:.0f} steps/s on {record['machine']}), best validation "
        f"return {record['best_validation_return']:.1f} at step {record['best_timestep']}"
    )
    agents = {"ppo (shipped)": None, "ppo (seaway)": args.out}
    results = evaluate_all(agents, sea, args.episodes, BENCHMARK_SEED)
    text = table(results)
    print(text)
    if args.docs:
        from shipgym.sysid.report import update_block

        shipped = load_meta(ENV_ID, ALGO)
        _print(f"wrote {plot(record, shipped, results, tuple(agents), FIGURE)}")
        head = (
            f"{args.episodes} episodes per row, seeds {BENCHMARK_SEED}-"
            f"{BENCHMARK_SEED + args.episodes - 1}; seaway: wind {json.dumps(sea['wind'])}, "
            f"sea state {json.dumps(sea['sea_state'])} (directions drawn per episode); "
            "mean over the episodes with its bootstrap 95 % interval."
        )
        update_block(PAGE, head + "\n\n" + text, PAGE_MARKER)
        _print(f"wrote the table of {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

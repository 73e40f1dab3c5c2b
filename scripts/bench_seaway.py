"""What wind and waves cost a vector env's step: the step at sea against the step in calm water.

For every env id, a vector env of ``--num-envs`` sub-envs in calm water and one with a fresh
breeze and a moderate sea (every sub-env with its own gusts and wave motion) are made in this
process. Each of ``--repeats`` rounds times ``--steps`` steps of both, one after the other (one
fixed batch of random actions, autoreset inside the env), and the ratio of a round is the sea
step's time over the calm step's, so a change of the machine's speed between rounds cancels.
The line's ratio is the median over the rounds. ``--busy N`` runs it all while N processes keep
cores busy (as a learner, a test suite or a sweep does); ``--write`` puts the idle and busy
tables and the figure into docs/results/speed.md.

Usage::

    python scripts/bench_seaway.py                  # idle
    python scripts/bench_seaway.py --busy 2         # the cores shared
    python scripts/bench_seaway.py --write          # both, into the speed page
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import shipgym  # noqa: F401  (registers the envs)
from shipgym.bench import BusyCores
from shipgym.sysid.report import update_block

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "results" / "speed.md"
FIGURE = ROOT / "docs" / "seaway_step_cost.png"
ENV_IDS = (
    "shipgym/NomotoHeading-v0",
    "shipgym/RVGHeading-v1",
    "shipgym/RVGSpeed-v1",
    "shipgym/RVGPathFollowing-v1",
    "shipgym/RVGTargetTracking-v1",
)
#: The seaway timed: a fresh breeze with gusts and a moderate sea, directions drawn per episode.
SEAWAY = {
    "wind": {"speed": 9.5},
    "sea_state": {"significant_height": 2.0, "peak_period": 7.0},
}
TARGET = 1.5


def _env(env_id: str, num_envs: int, at_sea: bool) -> gym.vector.VectorEnv:
    env = gym.make_vec(
        env_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        **(SEAWAY if at_sea else {}),
    )
    env.reset(seed=0)
    return env


def _time(env: gym.vector.VectorEnv, actions: np.ndarray, steps: int) -> float:
    start = time.perf_counter()
    for _ in range(steps):
        env.step(actions)
    return (time.perf_counter() - start) / steps


def measure(num_envs: int, steps: int, repeats: int) -> list[dict[str, float | str]]:
    """Per env id: the calm and the sea step [s] (medians) and the median round ratio."""
    rows = []
    for env_id in ENV_IDS:
        calm, sea = _env(env_id, num_envs, False), _env(env_id, num_envs, True)
        rng = np.random.default_rng(0)
        actions = rng.uniform(-1, 1, calm.action_space.shape).astype(np.float32)
        for env in (calm, sea):  # warm-up (compiled code, caches)
            _time(env, actions, 50)
        times = [(_time(calm, actions, steps), _time(sea, actions, steps)) for _ in range(repeats)]
        rows.append(
            {
                "env": env_id.removeprefix("shipgym/"),
                "calm_us": 1e6 * statistics.median(t[0] for t in times),
                "sea_us": 1e6 * statistics.median(t[1] for t in times),
                "ratio": statistics.median(t[1] / t[0] for t in times),
            }
        )
        print(
            f"  {rows[-1]['env']:<22} calm {rows[-1]['calm_us']:8.1f} us  sea "
            f"{rows[-1]['sea_us']:8.1f} us  ratio {rows[-1]['ratio']:.2f}",
            flush=True,
        )
        calm.close()
        sea.close()
    return rows


def table(rows: list[dict[str, float | str]], num_envs: int) -> str:
    lines = [
        f"| env ({num_envs} sub-envs) | calm step [us] | at sea [us] | ratio | within {TARGET}x |",
        "|---|---:|---:|---:|:---:|",
    ]
    for r in rows:
        ok = "yes" if float(r["ratio"]) <= TARGET else "**no**"
        lines.append(
            f"| {r['env']} | {r['calm_us']:.1f} | {r['sea_us']:.1f} | {r['ratio']:.2f} | {ok} |"
        )
    return "\n".join(lines)


def plot(results: dict[str, list[dict[str, float | str]]], path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.0))
    names = [str(r["env"]) for r in next(iter(results.values()))]
    width = 0.8 / len(results)
    for k, (label, rows) in enumerate(results.items()):
        x = np.arange(len(rows)) + (k - (len(results) - 1) / 2) * width
        ax.bar(x, [float(r["ratio"]) for r in rows], width, label=label)
    ax.axhline(TARGET, color="k", ls="--", lw=1, label=f"target {TARGET}x")
    ax.set_xticks(np.arange(len(names)), names, rotation=15, fontsize=8)
    ax.set_ylabel("step at sea / calm step")
    ax.set_title("What wind and waves cost a vector env's step (median of rounds)")
    ax.legend(fontsize=7, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.22))
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--num-envs", type=int, nargs="+", default=[16, 256, 4096], help="sub-envs of a vector env"
    )
    parser.add_argument(
        "--steps", type=int, default=300, help="steps timed per round (at 256 sub-envs; "
        "fewer in proportion for larger batches)"
    )
    parser.add_argument("--repeats", type=int, default=7, help="rounds (the median is kept)")
    parser.add_argument("--busy", type=int, default=0, help="helper processes keeping cores busy")
    parser.add_argument("--write", action="store_true", help="idle and busy into the speed page")
    args = parser.parse_args()
    loads = (0, 2) if args.write else (args.busy,)
    results, tables = {}, []
    for busy in loads:
        for num_envs in args.num_envs:
            label = ("idle" if busy == 0 else f"{busy} busy processes") + f", {num_envs} sub-envs"
            print(f"{label}:", flush=True)
            steps = max(20, args.steps * 256 // num_envs)
            with BusyCores(busy):
                results[label] = measure(num_envs, steps, args.repeats)
            tables.append(f"**{label}**\n\n{table(results[label], num_envs)}")
            print(tables[-1])
    if args.write:
        figure = plot(results, FIGURE)
        blocks = ["`python scripts/bench_seaway.py --write`", *tables]
        figure_link = f"\n\n![step cost at sea](../{figure.name})"
        update_block(PAGE, "\n\n".join(blocks) + figure_link, "bench_seaway")
        print(f"wrote {PAGE} and {figure}")


if __name__ == "__main__":
    main()

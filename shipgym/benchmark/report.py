"""The README block of the benchmark: the table of ``shipgym benchmark`` and its figures.

:func:`render_markdown` turns the benchmark's JSON (a list of ``shipgym evaluate`` objects with
``condition``) and the throughput rows into Markdown; ``scripts/benchmark_readme.py`` runs the
benchmark into ``docs/benchmark/`` and writes the block between ``<!-- benchmark -->`` and
``<!-- /benchmark -->``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from shipgym.benchmark.stats import paired_difference, verdict

README_MARKER = "benchmark"


def _pm(mean: float, std: float) -> str:
    return f"{mean:.3g} ± {std:.2g}"


def robustness_table(entries: Sequence[dict[str, Any]]) -> list[str]:
    """Markdown lines: each controller's mean return per condition and its change from nominal
    (who degrades more under stress and on the wrong ship)."""
    conds = list(dict.fromkeys(e["condition"] for e in entries))
    if len(conds) < 2 or "nominal" not in conds:
        return []
    by_key = {(e["env"], e["controller"], e["condition"]): e for e in entries}
    others = [c for c in conds if c != "nominal"]
    lines = [
        "Robustness: mean return per condition, and its change from nominal.",
        "",
        "| env | controller | nominal | " + " | ".join(others) + " |",
        "|---|---|---:|" + "---:|" * len(others),
    ]
    for env_id in dict.fromkeys(e["env"] for e in entries):
        for name in dict.fromkeys(e["controller"] for e in entries if e["env"] == env_id):
            nominal = by_key.get((env_id, name, "nominal"))
            if nominal is None:
                continue
            base = nominal["mean_return"]
            cells = []
            for cond in others:
                e = by_key.get((env_id, name, cond))
                cells.append(
                    "—" if e is None else f"{e['mean_return']:.3g} ({e['mean_return'] - base:+.3g})"
                )
            lines.append(
                f"| {env_id.split('/')[-1]} | {name} | {base:.3g} | " + " | ".join(cells) + " |"
            )
    return [*lines, ""]


def paired_table(entries: Sequence[dict[str, Any]], reference: str = "classic") -> list[str]:
    """Markdown lines: each controller's return against ``reference`` on the same seeds (mean
    paired difference, bootstrap 95 % interval, verdict), nominal and stress."""
    by_key = {(e["env"], e["controller"], e["condition"]): e for e in entries}
    rows = []
    for (env_id, name, cond), e in by_key.items():
        ref = by_key.get((env_id, reference, cond))
        if name == reference or ref is None or "returns" not in e or "returns" not in ref:
            continue
        if len(e["returns"]) < 2 or len(e["returns"]) != len(ref["returns"]):
            continue
        mean, lo, hi = paired_difference(e["returns"], ref["returns"])
        rows.append(
            f"| {env_id.split('/')[-1]} | {cond} | {name} | {mean:+.3g} | "
            f"[{lo:+.3g}, {hi:+.3g}] | {verdict(lo, hi)} |"
        )
    if not rows:
        return []
    return [
        f"Return against `{reference}` on the same seeds: mean paired difference and its "
        "bootstrap 95 % interval; a controller is better or worse only where the interval "
        "excludes zero.",
        "",
        f"| env | condition | controller | return - {reference} | 95 % interval | verdict |",
        "|---|---|---|---:|---|---|",
        *rows,
        "",
    ]


def render_markdown(
    entries: Sequence[dict[str, Any]],
    throughput: Sequence[dict[str, Any]] | None,
    figure_dir: str = "docs/benchmark",
) -> str:
    """Markdown: one row per (env, controller), nominal and stress side by side."""
    envs = list(dict.fromkeys(e["env"] for e in entries))
    by_key = {(e["env"], e["controller"], e["condition"]): e for e in entries}
    first = entries[0]
    stress_speeds = {
        e["env"]: e["options"].get("current_speed") for e in entries if e["condition"] == "stress"
    }
    lines = [
        f"{first['episodes']} episodes per cell, seeds {first['seed']}-"
        f"{first['seed'] + first['episodes'] - 1} (the same initial states, setpoints, paths, "
        "targets and current directions for every controller), mean ± std over episodes. "
        "Stress: the current speed fixed at 1.5 x the training maximum ("
        + ", ".join(f"{e.split('/')[-1]} {s:g} m/s" for e, s in stress_speeds.items() if s)
        + ").",
        "",
        "| env | controller | return | return, stress | metrics | metrics, stress |",
        "|---|---|---:|---:|---|---|",
    ]
    for env_id in envs:
        for name in dict.fromkeys(e["controller"] for e in entries if e["env"] == env_id):
            cells = []
            metric_cells = []
            for cond in ("nominal", "stress"):
                e = by_key.get((env_id, name, cond))
                if e is None:
                    cells.append("—")
                    metric_cells.append("—")
                    continue
                cells.append(_pm(e["mean_return"], e["std_return"]))
                metric_cells.append(
                    ", ".join(f"{k} {_pm(v, e['metrics_std'][k])}" for k, v in e["metrics"].items())
                )
            lines.append(
                f"| {env_id.split('/')[-1]} | {name} | {cells[0]} | {cells[1]} | "
                f"{metric_cells[0]} | {metric_cells[1]} |"
            )
    lines += ["", f"![benchmark metrics]({figure_dir}/metrics.png)", ""]
    lines += robustness_table(entries)
    lines += paired_table(entries)
    if throughput:
        lines += [
            "PPO training throughput, the shipped agents' PPO settings (16 sub-envs, "
            "`n_steps` 256, batch 512, 10 epochs, 64x64 MLP, `VecNormalize`) on each env and on "
            "`CartPole-v1` (SB3's `make_vec_env`), in one process, best of interleaved runs:",
            "",
            "| env | env steps/s | ratio to CartPole | target | result |",
            "|---|---:|---:|---:|---|",
        ]
        for r in throughput:
            target = "" if r["target"] is None else f"≥ {r['target']:g}"
            verdict = "" if r["met"] is None else ("met" if r["met"] else "missed")
            lines.append(
                f"| {r['env'].split('/')[-1]} | {r['steps_per_s']:,.0f} | {r['ratio']:.2f} | "
                f"{target} | {verdict} |"
            )
        lines += ["", f"![PPO throughput]({figure_dir}/throughput.png)"]
    return "\n".join(lines)

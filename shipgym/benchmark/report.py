"""The results page of the benchmark: the tables of ``shipgym benchmark`` and its figures.

:func:`render_markdown` turns the benchmark's JSON (a list of ``shipgym evaluate`` objects with
``condition``) and the throughput rows into Markdown; ``scripts/benchmark_readme.py`` runs the
benchmark into ``docs/benchmark/`` and writes the block between ``<!-- benchmark -->`` and
``<!-- /benchmark -->`` of :data:`PAGE`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from shipgym.benchmark.stats import paired_difference, verdict

PAGE = "docs/results/benchmark.md"
"""The results page (relative to the repository) that holds the block."""
PAGE_MARKER = "benchmark"
"""Name of the block in :data:`PAGE`."""


#: The controller every other is compared with, episode by episode.
REFERENCE = "classic-tuned"


def _g(x: float) -> str:
    return f"{x:.3g}"


def _ci_cell(mean: float, ci: Sequence[float] | None, defined: int | None, episodes: int) -> str:
    if mean != mean:  # NaN: defined in no episode
        return "—"
    cell = _g(mean) + (f" [{_g(ci[0])}, {_g(ci[1])}]" if ci else "")
    if defined is not None and defined < episodes:
        cell += f" (n={defined})"
    return cell


def _blew_up(e: dict[str, Any]) -> str | None:
    """``blew up k/n`` for an evaluation with blown-up episodes (its aggregates are undefined)."""
    return f"blew up {e['blown_up']}/{e['episodes']}" if e.get("blown_up") else None


def _label(env_id: str) -> str:
    return env_id.split("/")[-1]


def metrics_tables(entries: Sequence[dict[str, Any]], condition: str = "nominal") -> list[str]:
    """Markdown lines: per env, each controller's return and engineering metrics in
    ``condition``: mean over episodes and its bootstrap 95 % interval (``n=`` where a metric is
    defined in fewer episodes, e.g. a steady-state error needs a settled episode)."""
    lines: list[str] = []
    for env_id in dict.fromkeys(e["env"] for e in entries):
        rows = [e for e in entries if e["env"] == env_id and e["condition"] == condition]
        if not rows:
            continue
        keys = list(rows[0]["metrics"])
        lines += [
            f"**{_label(env_id)}**",
            "",
            "| controller | return | " + " | ".join(keys) + " |",
            "|---|" + "---:|" * (1 + len(keys)),
        ]
        for e in rows:
            n = e["episodes"]
            if _blew_up(e):
                cells = [f"**{_blew_up(e)}**"] + ["—"] * len(keys)
            else:
                cells = [_ci_cell(e["mean_return"], e.get("return_ci95"), None, n)]
                cells += [
                    _ci_cell(e["metrics"][k], e["metrics_ci95"][k], e["metrics_defined"][k], n)
                    for k in keys
                ]
            lines.append(f"| {e['controller']} | " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def _paired_cell(a: Sequence[float], b: Sequence[float], higher_is_better: bool) -> str:
    # paired_difference pairs the episodes where both are defined; it needs two of them
    if np.isfinite(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)).sum() < 2:
        return "—"
    mean, lo, hi = paired_difference(a, b)
    word = verdict(lo, hi, higher_is_better)
    mark = {"better": " **better**", "worse": " **worse**"}.get(word, "")
    return f"{mean:+.3g} [{lo:+.3g}, {hi:+.3g}]{mark}"


def paired_metrics_tables(
    entries: Sequence[dict[str, Any]], reference: str = REFERENCE, condition: str = "nominal"
) -> list[str]:
    """Markdown lines: per env, each controller minus ``reference`` on the same seeds, for the
    return and every metric: mean paired difference, bootstrap 95 % interval, and a verdict
    only where the interval excludes zero."""
    from shipgym.benchmark.evaluate import HIGHER_IS_BETTER

    lines: list[str] = []
    by_key = {(e["env"], e["controller"], e["condition"]): e for e in entries}
    for env_id in dict.fromkeys(e["env"] for e in entries):
        ref = by_key.get((env_id, reference, condition))
        if ref is None or "per_episode" not in ref:
            continue
        keys = list(ref["metrics"])
        body = []
        for (env, name, cond), e in by_key.items():
            if (env, cond) != (env_id, condition) or name == reference:
                continue
            if _blew_up(e) or _blew_up(ref):
                blew = f"**{_blew_up(e) or reference + ' ' + str(_blew_up(ref))}**"
                cells = [blew] + ["—"] * len(keys)
            else:
                cells = [_paired_cell(e["returns"], ref["returns"], True)]
                cells += [
                    _paired_cell(e["per_episode"][k], ref["per_episode"][k], k in HIGHER_IS_BETTER)
                    for k in keys
                ]
            body.append(f"| {name} | " + " | ".join(cells) + " |")
        if body:
            lines += [
                f"**{_label(env_id)}**: controller - `{reference}`",
                "",
                "| controller | return | " + " | ".join(keys) + " |",
                "|---|" + "---:|" * (1 + len(keys)),
                *body,
                "",
            ]
    return lines


def robustness_table(entries: Sequence[dict[str, Any]]) -> list[str]:
    """Markdown lines: each controller's mean return per condition and its change from nominal
    (who degrades more under stress, on the wrong ship, with noisy sensors, with a delay)."""
    from shipgym.benchmark.runner import condition_order

    conds = sorted(dict.fromkeys(e["condition"] for e in entries), key=condition_order)
    if len(conds) < 2 or "nominal" not in conds:
        return []
    by_key = {(e["env"], e["controller"], e["condition"]): e for e in entries}
    others = [c for c in conds if c != "nominal"]
    lines = [
        "| env | controller | nominal | " + " | ".join(others) + " |",
        "|---|---|---:|" + "---:|" * len(others),
    ]
    for env_id in dict.fromkeys(e["env"] for e in entries):
        for name in dict.fromkeys(e["controller"] for e in entries if e["env"] == env_id):
            nominal = by_key.get((env_id, name, "nominal"))
            if nominal is None or not any((env_id, name, c) in by_key for c in others):
                continue
            base = nominal["mean_return"]
            cells = []
            for cond in others:
                e = by_key.get((env_id, name, cond))
                if e is None:
                    cells.append("—")
                elif _blew_up(e):
                    cells.append(f"**{_blew_up(e)}**")
                elif _blew_up(nominal):
                    cells.append(f"{e['mean_return']:.3g}")
                else:
                    cells.append(f"{e['mean_return']:.3g} ({e['mean_return'] - base:+.3g})")
            first = f"**{_blew_up(nominal)}**" if _blew_up(nominal) else f"{base:.3g}"
            lines.append(f"| {_label(env_id)} | {name} | {first} | " + " | ".join(cells) + " |")
    return [*lines, ""]


def paired_table(entries: Sequence[dict[str, Any]], reference: str = REFERENCE) -> list[str]:
    """Markdown lines: each controller's return against ``reference`` on the same seeds in
    every condition (mean paired difference, bootstrap 95 % interval, verdict)."""
    by_key = {(e["env"], e["controller"], e["condition"]): e for e in entries}
    rows = []
    for (env_id, name, cond), e in by_key.items():
        ref = by_key.get((env_id, reference, cond))
        if name == reference or ref is None or "returns" not in e or "returns" not in ref:
            continue
        if len(e["returns"]) < 2 or len(e["returns"]) != len(ref["returns"]):
            continue
        if _blew_up(e) or _blew_up(ref):
            blew = _blew_up(e) or f"{reference} {_blew_up(ref)}"
            rows.append(f"| {_label(env_id)} | {cond} | {name} | **{blew}** | — | — |")
            continue
        mean, lo, hi = paired_difference(e["returns"], ref["returns"])
        rows.append(
            f"| {_label(env_id)} | {cond} | {name} | {mean:+.3g} | "
            f"[{lo:+.3g}, {hi:+.3g}] | {verdict(lo, hi)} |"
        )
    if not rows:
        return []
    return [
        f"| env | condition | controller | return - {reference} | 95 % interval | verdict |",
        "|---|---|---|---:|---|---|",
        *rows,
        "",
    ]


def seaway_error_key(env_id: str) -> str:
    """The error metric the seaway table shows for ``env_id``: the low-frequency heading error
    of the heading tasks, else the task's first metric (cross-track, speed, distance)."""
    from shipgym.benchmark.evaluate import METRICS

    keys = METRICS[env_id]
    return "lf_heading_rms_deg" if "lf_heading_rms_deg" in keys else keys[0]


#: The columns of the seaway table besides the error: what the sea costs the steering gear.
SEAWAY_KEYS = ("heading_rms_deg", "rudder_travel_deg_min", "rudder_reversals_min", "energy_mj")


def seaway_rows(entries: Sequence[dict[str, Any]], env_id: str) -> list[dict[str, Any]]:
    """Per controller of ``env_id``'s seaway condition: ``calm`` and ``seaway``, each a dict
    of ``key -> (mean, low, high)`` (bootstrap 95 % interval) for the return and the metrics,
    or None where that condition was not run. ``classic-wf``'s calm values are ``classic``'s
    (the wave filter passes a calm sea's heading through unchanged)."""
    by_key = {(e["env"], e["controller"], e["condition"]): e for e in entries}

    def stats(e: dict[str, Any] | None) -> dict[str, tuple[float, float, float]] | None:
        if e is None or _blew_up(e):
            return None
        out = {"return": (e["mean_return"], *(e.get("return_ci95") or [e["mean_return"]] * 2))}
        for k, m in e["metrics"].items():
            out[k] = (m, *(e["metrics_ci95"][k] or [m, m]))
        if "lf_heading_rms_deg" not in out and "heading_rms_deg" in out:  # calm: the same
            out["lf_heading_rms_deg"] = out["heading_rms_deg"]
        return out

    rows = []
    for (env, name, cond), e in by_key.items():
        if (env, cond) != (env_id, "seaway"):
            continue
        calm_name = "classic" if name == "classic-wf" else name
        rows.append({
            "controller": name,
            "calm": stats(by_key.get((env_id, calm_name, "nominal"))),
            "seaway": stats(e),
            "blown_up": _blew_up(e),
        })  # fmt: skip
    return rows


def seaway_table(entries: Sequence[dict[str, Any]]) -> list[str]:
    """Markdown lines: per env, each controller in the seaway condition against calm water
    (the nominal condition, same seeds): the return, the error the task is about (the
    low-frequency heading error of the heading tasks), the measured heading error, the
    rudder (azimuth) travel and reversals and the propulsion energy; calm values in
    parentheses, means over episodes."""
    lines: list[str] = []
    for env_id in dict.fromkeys(e["env"] for e in entries if e["condition"] == "seaway"):
        error = seaway_error_key(env_id)
        rows = seaway_rows(entries, env_id)
        keys = ["return", error] + [
            k for k in SEAWAY_KEYS
            if k != error and rows and rows[0]["seaway"] and k in rows[0]["seaway"]
        ]  # fmt: skip
        lines += [
            f"**{_label(env_id)}**: at sea (calm water)",
            "",
            "| controller | " + " | ".join(keys) + " |",
            "|---|" + "---:|" * len(keys),
        ]
        for r in rows:
            if r["blown_up"]:
                blew = f"| {r['controller']} | **{r['blown_up']}** |"
                lines.append(blew + " — |" * (len(keys) - 1))
                continue
            cells = []
            for k in keys:
                sea = r["seaway"][k][0]
                calm = r["calm"][k][0] if r["calm"] and k in r["calm"] else None
                cells.append(_g(sea) + (f" ({_g(calm)})" if calm is not None else ""))
            lines.append(f"| {r['controller']} | " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def render_markdown(
    entries: Sequence[dict[str, Any]],
    throughput: Sequence[dict[str, Any]] | None,
    figure_dir: str = "../benchmark",
) -> str:
    """Markdown: the nominal metrics with intervals, the paired comparison with the tuned
    classic controller, the robustness conditions and the training throughput; the figures are
    linked in ``figure_dir``, relative to the page (default: from :data:`PAGE` to
    ``docs/benchmark``)."""
    first = entries[0]
    stress_speeds = {
        e["env"]: e["options"].get("current_speed") for e in entries if e["condition"] == "stress"
    }
    lines = [
        f"{first['episodes']} episodes per cell, seeds {first['seed']}-"
        f"{first['seed'] + first['episodes'] - 1} (the same initial states, setpoints, paths, "
        "targets and current directions for every controller and condition); every mean comes "
        "with its bootstrap 95 % interval in brackets.",
        "",
        "Nominal condition:",
        "",
        *metrics_tables(entries),
        f"![benchmark metrics]({figure_dir}/metrics.png)",
        "",
    ]
    paired = paired_metrics_tables(entries)
    if paired:
        lines += [
            f"Against `{REFERENCE}`, episode by episode on the same seeds (nominal): the mean "
            "paired difference and its 95 % interval; **better** or **worse** only where the "
            "interval excludes zero (return: higher is better; metrics: lower is better but "
            "for `completed`).",
            "",
            *paired,
        ]
    robust = robustness_table(entries)
    if robust:
        lines += [
            "Robustness: mean return per condition and its change from nominal. Stress: the "
            "current speed fixed at 1.5 x the training maximum ("
            + ", ".join(f"{_label(e)} {s:g} m/s" for e, s in stress_speeds.items() if s)
            + "); mismatch: the ship named, with gains and agents made for the nominal one; "
            "noise: sensor noise at its default levels; delay: the actuator commands two "
            "control steps late.",
            "",
            *robust,
            f"![robustness]({figure_dir}/robustness.png)",
            "",
            f"Return against `{REFERENCE}` on the same seeds in every condition:",
            "",
            *paired_table(entries),
        ]
    if throughput:
        lines += [
            "PPO training throughput (`shipgym benchmark --throughput`, its last run), the "
            "shipped agents' PPO settings (16 sub-envs, `n_steps` 256, batch 512, 10 epochs, "
            "64x64 MLP, `VecNormalize`) on each env and on `CartPole-v1` (SB3's "
            "`make_vec_env`), in one process, best of interleaved runs; a row says \"machine "
            "busy: not comparable\" instead of met or missed when other processes used the "
            "cores during its timed runs:",
            "",
            "| env | env steps/s | ratio to CartPole | target | result |",
            "|---|---:|---:|---:|---|",
        ]
        for r in throughput:
            target = "" if r["target"] is None else f"≥ {r['target']:g}"
            met = "" if r["met"] is None else ("met" if r["met"] else "missed")
            verdict = r.get("verdict") or met
            lines.append(
                f"| {r['env'].split('/')[-1]} | {r['steps_per_s']:,.0f} | {r['ratio']:.2f} | "
                f"{target} | {verdict} |"
            )
        lines += ["", f"![PPO throughput]({figure_dir}/throughput.png)"]
    return "\n".join(lines)

"""Identify R/V Gunnerus from its sea trials and validate the model manoeuvre by manoeuvre.

Usage::

    python scripts/identify_gunnerus.py [--record PATH|DATASET] [--out docs] [--folds 3]
                                        [--page docs/results/gunnerus.md | --no-page]

1. Runs the identification loop (:func:`shipgym.sysid.identify`, ``rvg3dof``) from the seed-001
   base on the sea-trial record and draws its path: the held-out error after the base and after
   each accepted effect (``OUT/gunnerus_loop.png``).
2. Extracts the manoeuvres of the record (:mod:`shipgym.sysid.manoeuvres`: straight runs per
   rpm, steady turns per azimuth, zigzag-like sequences) and cross-validates by manoeuvre: the
   manoeuvres are split into ``--folds`` groups; for each group the loop's final model is fitted
   on the record without that group's manoeuvres, together with the day's current (the
   ``current`` effect's constant ``V_n, V_e``: a condition of the record, not of the ship, that
   60 s windows hardly see but steady straight runs on opposite headings do), and predicts them
   in that current. The table puts the
   measurement, the seed-001 model, the cross-validated model and the shipped sea-trial set
   (:meth:`shipgym.models.RVGParams.sea_trials`, fitted on the whole record) side by side
   (``OUT/gunnerus_manoeuvres.png``).
3. Writes ``OUT/gunnerus.json`` and ``OUT/gunnerus.md`` (which ``docs/results/gunnerus.md``
   includes from its "Every manoeuvre" on) and that page's block between ``<!-- gunnerus -->``
   and ``<!-- /gunnerus -->``, and prints the whole-record ship
   parameters (the values of ``SEA_TRIALS_VALUES`` in :mod:`shipgym.models.rvg`).

The data stay where they are; nothing is copied.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from shipgym.datasets import expand_records
from shipgym.models import RVGParams
from shipgym.models.rvg import SEA_TRIALS_VALUES
from shipgym.sysid import identify, load
from shipgym.sysid import manoeuvres as mn
from shipgym.sysid.consistency import kinematic_consistency
from shipgym.sysid.families.base import jsonable, window_starts
from shipgym.sysid.families.rvg import (
    CALIBRATED,
    RVG_WINDOW_S,
    RVGFit,
    fit_rvg,
    measured_states,
    simulate_orders,
)
from shipgym.sysid.report import relative_link, update_block

REPO = Path(__file__).resolve().parents[1]
_LOOP_CHANNELS = (("psi", "heading [deg]", math.degrees), ("r", "yaw rate [deg/s]", math.degrees),
                  ("u", "surge speed [m/s]", float), ("x", "north [m]", float))  # fmt: skip


def _simulator(params: RVGParams, current: tuple[float, float] = (0.0, 0.0)):
    def simulate(t: np.ndarray, rpm: np.ndarray, az: np.ndarray, x0: np.ndarray) -> np.ndarray:
        return simulate_orders(params, t, rpm, az, x0, current=current)

    return simulate


def plot_loop(path: list[dict[str, Any]], seed: dict[str, float], out: Path) -> None:
    """Held-out RMS per channel after the base and each accepted effect."""
    fig, axes = plt.subplots(1, len(_LOOP_CHANNELS), figsize=(13, 3.6))
    labels = ["seed 001", *(p["model"] for p in path)]
    for ax, (ch, name, conv) in zip(axes, _LOOP_CHANNELS, strict=True):
        vals = [conv(seed[ch]), *(conv(p["heldout_rms"][ch]) for p in path)]
        ax.bar(range(len(vals)), vals, color=["0.6", *(["C0"] * len(path))])
        ax.set_xticks(range(len(vals)), labels, rotation=30, ha="right", fontsize=8)
        ax.set_title(f"held-out RMS, {name}", fontsize=9)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle("Gunnerus sea trials: the identification loop's path (60 s windows, last 30 %)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


#: (kind, error key, label, target, unit): the targets on manoeuvres not used for fitting
TARGETS = (
    ("straight", "speed_pct", "straight speed", 3.0, "%"),
    ("turn", "yaw_rate_pct", "steady yaw rate", 10.0, "%"),
    ("turn", "diameter_pct", "turning diameter", 15.0, "%"),
    ("turn", "speed_ratio_abs", "speed ratio in the turn", 0.05, ""),
    ("zigzag", "overshoot_mean_deg", "zigzag overshoot (mean)", 2.0, "deg"),
    ("zigzag", "overshoot_max_deg", "zigzag overshoot (max)", 2.0, "deg"),
)


def summarise(rows: list[dict[str, Any]], models: tuple[str, ...]) -> tuple[list, str]:
    """Worst and median absolute error per quantity and model, against :data:`TARGETS`."""
    out = []
    lines = [
        "| quantity | target | " + " | ".join(f"{m}: median / worst" for m in models) + " |",
        "|---|---|" + "---|" * len(models),
    ]
    for kind, key, label, target, unit in TARGETS:
        cells = []
        entry: dict[str, Any] = {"quantity": label, "target": target, "unit": unit}
        for m in models:
            e = np.array([abs(r["errors"][m][key]) for r in rows if r["kind"] == kind])
            e = np.where(np.isfinite(e), e, np.inf)
            n_ok = int(np.sum(e <= target))
            entry[m] = {"median": float(np.median(e)), "worst": float(e.max()), "met": n_ok,
                        "of": int(e.size)}  # fmt: skip
            cells.append(f"{np.median(e):.3g} / {e.max():.3g} {unit} ({n_ok}/{e.size} met)")
        out.append(entry)
        lines.append(f"| {label} | {target:g} {unit} | " + " | ".join(cells) + " |")
    return out, "\n".join(lines)


def not_taken(res: Any) -> str:
    """The last round's candidates, none of them taken: each one's fitted coefficients (and
    the bounds they hit) and the held-out heading RMS it gives against the final model's."""
    final_psi = math.degrees(res.heldout["path"][-1]["heldout_rms"]["psi"])
    cells = []
    for name, score in (res.rounds[-1] if res.rounds else {}).items():
        if "heldout_rms" not in score:
            continue
        coef = ", ".join(
            f"{k.removeprefix('fitted_')} {v:+.3g}" for k, v in score.items()
            if k.startswith("fitted_")
        )  # fmt: skip
        bound = f", at its bound ({score['at_bound']})" if score.get("at_bound") else ""
        psi = math.degrees(score["heldout_rms"]["psi"])
        cells.append(f"`{name}` ({coef}{bound}: {psi:.2f} deg)")
    return (
        f"Not taken after the last effect (held-out heading RMS {final_psi:.2f} deg; each "
        "candidate's fitted coefficients and its held-out heading RMS): " + "; ".join(cells) + "."
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--record",
        default="gunnerus-seatrials",
        help="the sea-trial CSV, or its dataset name (shipgym data list; default: %(default)s)",
    )
    ap.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    ap.add_argument("--folds", type=int, default=3, help="cross-validation folds (>= 2)")
    ap.add_argument(
        "--page",
        default=str(REPO / "docs" / "results" / "gunnerus.md"),
        help="documentation page whose block to update",
    )
    ap.add_argument("--no-page", action="store_true", help="do not touch the page")
    args = ap.parse_args(argv)
    if args.folds < 2:
        ap.error(f"--folds must be >= 2, got {args.folds}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    def say(msg: str) -> None:
        print(msg, file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    rec = load(expand_records([args.record])[0])
    res = identify(rec, "rvg3dof", progress=lambda m: say(f"  {m}"))
    loop_s = time.perf_counter() - t0
    say(f"loop: {res.effect_names} in {loop_s:.1f} s")
    ctx_starts = window_starts(rec.time, RVG_WINDOW_S)
    held = rec.time >= rec.time[0] + res.heldout["from_s"]
    seed_sim = RVGFit(RVGParams()).simulate(rec, ctx_starts)
    meas = measured_states(rec)
    seed_rms = {}
    for ch, col in (("psi", 2), ("r", 5), ("u", 3), ("x", 0)):
        e = seed_sim[held, col] - meas[held, col]
        if ch == "psi":
            e = (e + np.pi) % (2 * np.pi) - np.pi
        seed_rms[ch] = float(np.sqrt(np.mean(e**2)))
    plot_loop(res.heldout["path"], seed_rms, out / "gunnerus_loop.png")
    # the record itself: its yaw rate and velocities integrated from each window's start
    cons = kinematic_consistency(rec, ctx_starts)
    held_w = rec.time[ctx_starts] >= rec.time[0] + res.heldout["from_s"]
    scales = cons.yaw_rate_scale[np.isfinite(cons.yaw_rate_scale)]
    consistency = {
        "heldout_heading_rms_deg": math.degrees(cons.pooled_heading_rms(held_w)),
        "heldout_median_window_deg": math.degrees(float(np.median(cons.heading_rms[held_w]))),
        "training_heading_rms_deg": math.degrees(cons.pooled_heading_rms(~held_w)),
        "heldout_position_rms_m": cons.pooled_position_rms(held_w),
        "yaw_rate_scale_5_95": [float(q) for q in np.percentile(scales, [5, 95])],
        "turning_windows": int(scales.size),
    }

    # cross-validation by manoeuvre
    ms = mn.extract_manoeuvres(rec)
    say(f"{len(ms)} manoeuvres; {args.folds}-fold cross-validation by manoeuvre")
    first = np.zeros(rec.time.size, dtype=bool)
    first[ctx_starts] = True
    rows: list[dict[str, Any]] = []
    fold_params = []
    for k, (group, mask) in enumerate(mn.folds(ms, args.folds)):
        effects = tuple(dict.fromkeys((*res.final.effects, "current")))
        fit = fit_rvg(rec, ctx_starts, mask & ~first, effects, res.final)
        fold_params.append(
            {n: fit.values[n] for n in (*CALIBRATED, *fit.values) if n in fit.values}
        )
        say(
            f"  fold {k + 1}: {len(group)} manoeuvres held out; current "
            f"({fit.current[0]:+.3f}, {fit.current[1]:+.3f}) m/s; bounds hit: {fit.at_bound}"
        )
        models = {
            "seed 001": _simulator(RVGParams()),
            "identified (cross-validated)": _simulator(fit.params, fit.current),
            "sea_trials set": _simulator(RVGParams.sea_trials()),
        }
        for row in mn.validation_table(group, rec, models):
            row["fold"] = k + 1
            rows.append(row)
    rows.sort(key=lambda r: r["t_start"])
    mn.plot_validation(rows, out / "gunnerus_manoeuvres.png")
    table = mn.render_markdown(rows)
    summary, summary_md = summarise(
        rows, ("seed 001", "identified (cross-validated)", "sea_trials set")
    )

    final = res.final
    values = {k: v for k, v in final.values.items() if k not in ("alpha_0", "V_n", "V_e", "v_0")}
    doc = {
        "record": str(args.record),
        "loop_runtime_s": loop_s,
        "identification": res.to_dict(),
        "heldout_seed001": seed_rms,
        "record_consistency": consistency,
        "at_bound": list(final.at_bound),
        "sea_trials_values": values,
        "shipped_sea_trials_values": SEA_TRIALS_VALUES,
        "folds": fold_params,
        "targets": summary,
        "manoeuvres": rows,
    }
    (out / "gunnerus.json").write_text(json.dumps(jsonable(doc), indent=1) + "\n")
    held_err = res.heldout
    lines = [
        "Loop from the seed-001 base (60 s windows from the measured state, last 30 % held "
        f"out; `python scripts/identify_gunnerus.py`, {loop_s:.0f} s): effects named "
        + (", ".join(f"`{e}`" for e in res.effect_names) or "none")
        + ".",
        "",
        not_taken(res),
        "",
        "| held-out error | seed 001 | calibrated base | identified |",
        "|---|---|---|---|",
    ]
    shown = (("psi_rms_deg", "heading RMS [deg]"), ("r_rms_deg_s", "yaw rate RMS [deg/s]"),
             ("u_rms_m_s", "speed RMS [m/s]"), ("xy_rms_m", "position RMS [m]"))  # fmt: skip
    for key, name in shown:
        a, b, c = (held_err[k][key] for k in ("error_seed001", "error_before", "error_after"))
        lines.append(f"| {name} | {a:.2f} | {b:.2f} | {c:.2f} |")
    lo, hi = consistency["yaw_rate_scale_5_95"]
    lines += [
        "",
        "The record itself (`shipgym.sysid.consistency`): its measured yaw rate, integrated "
        "from each held-out window's start, misses its measured heading by "
        f"{consistency['heldout_heading_rms_deg']:.2f} deg RMS (median window "
        f"{consistency['heldout_median_window_deg']:.2f} deg; the training windows "
        f"{consistency['training_heading_rms_deg']:.2f} deg), and its u, v integrated with the "
        f"heading miss its positions by {consistency['heldout_position_rms_m']:.1f} m. A model "
        "that predicted the measured yaw rate exactly would keep that heading error. The "
        "factor on r that fits each window's heading change (the "
        f"{consistency['turning_windows']} windows that turn 10 deg or more) ranges "
        f"{lo:.2f}-{hi:.2f} (5-95 %).",
    ]
    lines += ["", f"{len(ms)} manoeuvres extracted from the record, cross-validated by manoeuvre "
              f"({args.folds} folds: each is predicted by the final model fitted on the record "
              "without it, in the day's current fitted with it; the shipped `sea_trials` set, "
              "fitted on the whole record, in calm water): absolute errors against the "
              "targets.", "", summary_md]  # fmt: skip
    text = "\n".join(lines)

    def with_figures(page: Path) -> str:
        """The tables and the two figures, linked from ``page``."""
        figures = (("loop", "gunnerus_loop.png"), ("manoeuvres", "gunnerus_manoeuvres.png"))
        return text + "".join(
            f"\n\n![{alt}]({relative_link(out / name, page)})" for alt, name in figures
        )

    doc_path = out / "gunnerus.md"
    doc_path.write_text(
        "# R/V Gunnerus: identification and validation\n\n"
        + with_figures(doc_path)
        + "\n\n## Every manoeuvre\n\n"
        + table
        + "\n"
    )
    if not args.no_page:
        update_block(args.page, with_figures(Path(args.page)), "gunnerus")
    print(with_figures(doc_path))
    print("\nwhole-record ship parameters (SEA_TRIALS_VALUES):")
    for k, v in values.items():
        print(f"    {k!r}: {v:.5g},")
    if final.at_bound:
        print(f"at a bound: {', '.join(final.at_bound)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

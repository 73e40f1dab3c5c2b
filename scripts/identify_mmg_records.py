"""The 3-DOF identification loop on tank records it did not make: the MMG KVLCC2 with one
undeclared effect.

Usage::

    python scripts/identify_mmg_records.py [--model vmm:auto] [--seeds 6] [--effects E ...]
                                           [--n-runs 6] [--jobs 2] [--out docs]
                                           [--page docs/results/identification.md | --no-page]
                                           [--simulator shipgym|shipmmg]

    # the same runs with their motions made by ShipMMG, in its own environment:
    python -m venv --system-site-packages /tmp/shipmmg-venv
    /tmp/shipmmg-venv/bin/pip install shipmmg        # ShipMMG pins Pillow < 11: keep it apart
    /tmp/shipmmg-venv/bin/python scripts/identify_mmg_records.py --simulator shipmmg

For every effect of :data:`shipgym.sysid.generator.MMG_EFFECTS` and the clean ship, and every
seed ``0 .. seeds-1``, :func:`shipgym.sysid.generator.generate_mmg_runs` makes the runs of the
KVLCC2 L7 model (7 m) simulated by the MMG standard model (Yasukawa and Yoshimura 2015): 90-120 s
of 10/10 and 20/20 zigzags and 35 deg turns to both sides, noise on every channel, the ship's
main particulars as plain meta keys; the effect's size and direction, the headings, speeds and
lengths come from the seed. :func:`shipgym.sysid.identify` fits them with ``--model`` (default
``vmm:auto``, or ``vmm:martin_simple`` where ``vmm:auto`` is not registered) and its default
hold-out (two runs, each a manoeuvre a training run also makes: the starboard 20/20 and the
port 10/10 zigzag; a turn to each side stays in the fits). Only the records are read, never
their ``meta["truth"]``.

Printed and written per effect: how often the undeclared effect is the first one named, how
often the held-out heading RMS is at least halved (``heldout["error_before"]`` against
``heldout["error_after"]``; a base model that diverges on them counts as halved), how often
both; for the clean records how often no actuator effect
(:data:`ACTUATOR_EFFECTS`) is named. The target is at least 5 of 6 seeds for each. Beside them,
the effect's *footprint* (:func:`footprint`): the held-out heading RMS of the true hull driven
by the recorded rudder without the effect, the most that naming it can take off a perfect
model's error (the script reads the truth for it; the identification never does). For an
actuator effect and a current, also the same identification of the records with the effect
taken out (:func:`effect_removed`, from the truth): its base model's held-out heading RMS is
what the structures the loop chooses from make of the effect named exactly, and the seeds
where that is at most half the error before are counted (*halving within reach*). It is not a
strict bound: another effect can predict the held-out runs better than the true one does.
That identification costs about as much as the loop's; ``--removed-from REPORT`` takes its
results from an earlier report of the same records and model instead (it has no effects to
trace, so only a change of the base structures' fits changes it).

With ``--simulator shipmmg`` the motions come from ShipMMG instead (:func:`shipmmg_runs`; no
wind: ShipMMG has no wind loads), a cross-check that the counts are not an artefact of
shipgym's own MMG code; the footprint is still shipgym's, and the outputs and the page's block
are named ``mmg_records_shipmmg``.

Writes ``OUT/mmg_records.json``, ``OUT/mmg_records.png`` and the block between
``<!-- mmg_records -->`` and ``<!-- /mmg_records -->`` of ``docs/results/identification.md``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import replace
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import ScalarFormatter

from shipgym.models import make_model
from shipgym.models import mmg as _mmg
from shipgym.models.mmg import MMGParams
from shipgym.models.nomoto import SteeringGear
from shipgym.sysid import identify
from shipgym.sysid.data import Record
from shipgym.sysid.families.base import FAMILIES, actual_rudder
from shipgym.sysid.generator import MMG_EFFECTS, MMG_NOISE, generate_mmg_runs
from shipgym.sysid.report import replace_between_markers, update_block, write_json

REPO = Path(__file__).resolve().parents[1]
DEFAULT_MODEL = "vmm:auto"
FALLBACK_MODEL = "vmm:martin_simple"
ACTUATOR_EFFECTS = ("rudder_offset", "rudder_lag", "input_delay")
"""Effects of the rudder and its gear (a clean record must name none of them)."""
TARGET = 5
"""Seeds of six that must pass."""
CLEAN = "clean"


def _say(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def _psi(errors: dict[str, Any] | None) -> float:
    value = (errors or {}).get("psi_rms_deg")
    return float(value) if isinstance(value, int | float) else math.nan


FOOTPRINT_STEP = 0.01
"""Step [s] of the footprint's simulation (the rudder interpolated between samples)."""


def footprint(effect: str | None, seed: int, n_runs: int, held: list[str]) -> float:
    """Held-out heading RMS [deg] of the true ship that ignores the effect: the published MMG
    KVLCC2, without the effect, driven by the recorded rudder and rpm of the noise-free held-out
    runs ``held`` (by name) from their first sample; the error that a perfect model of the hull
    would make by leaving the effect out. (Its own floor, on clean records: 0.02-0.03 deg,
    the rudder's interpolation; the steering gear is made 0.004 s to follow the record.)"""
    runs = [r for r in generate_mmg_runs(effect, seed=seed, noise=False, n_runs=n_runs)
            if r.meta["file"] in held]  # fmt: skip
    model = make_model("kvlcc2", replace(MMGParams.kvlcc2(), rudder_time_constant=0.004))
    sq, n = 0.0, 0
    for r in runs:
        x0 = np.zeros(model.nx)
        for i, ch in ((_mmg.IX, r.x), (_mmg.IY, r.y), (_mmg.IPSI, r.psi), (_mmg.IU, r.u),
                      (_mmg.IV, r.v), (_mmg.IR, r.r), (_mmg.IDELTA, r.delta)):  # fmt: skip
            x0[i] = ch[0]
        t = r.time - r.time[0]
        fine = np.arange(0.0, t[-1] + 1e-9, FOOTPRINT_STEP)
        rudder = np.interp(fine[:-1] + 0.5 * FOOTPRINT_STEP, t, r.delta)
        inputs = np.column_stack([rudder, np.full(rudder.size, r.rpm[0] / 60.0)])
        psi = model.simulate(x0, inputs, FOOTPRINT_STEP).states[:, _mmg.IPSI]
        e = np.degrees(np.interp(t, fine, psi) - r.psi)
        sq, n = sq + float(e @ e), n + e.size
    return math.sqrt(sq / n) if n else math.nan


def felt_rudder(rec: Record) -> np.ndarray:
    """The rudder the ship of a made record felt: its recorded rudder under the true zero
    error, gear lag or delay (:func:`~shipgym.sysid.families.base.actual_rudder`, the KVLCC2's
    gear limits), read from ``meta["truth"]``."""
    p = MMGParams.kvlcc2()
    truth = rec.meta["truth"]
    e = truth["effect_parameters"]
    return actual_rudder(
        rec.time, rec.delta, rudder_offset=e.get("delta_0", 0.0), rudder_lag=e.get("T_delta"),
        input_delay=e.get("tau", 0.0), y0=truth["x0"][_mmg.IDELTA],
        gear=SteeringGear(max_angle=p.max_rudder, max_rate=p.rudder_rate),
    )  # fmt: skip


REMOVABLE = (*ACTUATOR_EFFECTS, "current")
"""Effects a record can be read without (:func:`effect_removed`); a wind is a force on the
hull, which no channel of a record can take back out."""


def effect_removed(runs: list[Record]) -> list[Record]:
    """The runs as they read without their undeclared effect, from their truth: the recorded
    rudder replaced by the rudder the ship felt (:func:`felt_rudder`, an actuator effect), or
    the positions and velocities made relative to the water (a current). What a model fitted
    to these predicts is what its structure makes of the effect named exactly."""
    out = []
    for rec in runs:
        truth = rec.meta["truth"]
        if truth["effect"] in ACTUATOR_EFFECTS:
            out.append(replace(rec, delta=felt_rudder(rec)))
            continue
        v_n, v_e = truth["current"]
        cp, sp = np.cos(rec.psi), np.sin(rec.psi)
        u, v = rec.u - v_n * cp - v_e * sp, rec.v + v_n * sp - v_e * cp
        t = rec.time - rec.time[0]
        out.append(replace(rec, x=rec.x - v_n * t, y=rec.y - v_e * t, u=u, v=v,
                           U=np.hypot(u, v)))  # fmt: skip
    return out


SIMULATOR_NAMES = {"shipgym": "shipgym's", "shipmmg": "ShipMMG's"}
"""Who makes the motions of the records (``--simulator``)."""

SHIPMMG_EFFECTS = ("rudder_offset", "rudder_lag", "input_delay", "current")
"""Effects the ShipMMG records can carry (ShipMMG has no wind loads)."""


def shipmmg_runs(effect: str | None, seed: int, n_runs: int) -> list[Record]:
    """The runs of :func:`generate_mmg_runs` with their motions made again by ShipMMG
    (``shipmmg.mmg_3dof.simulate``, an independent implementation of the same MMG KVLCC2, its
    parameters as in ``scripts/shipmmg_compare.py``; run in its own environment, see the usage).

    Each run keeps its recorded rudder, rpm, start and length. ShipMMG is driven by the rudder the
    ship feels (:func:`felt_rudder`); a current is added to ShipMMG's motion through the
    water (positions and body velocities over ground). Noise of :data:`MMG_NOISE` on every
    channel, from its own seeded stream. Raises ``ImportError`` without ShipMMG.
    """
    from shipmmg.mmg_3dof import simulate
    from shipmmg_compare import shipmmg_params

    p = MMGParams.kvlcc2()
    rng = np.random.default_rng([seed, 1729])
    out = []
    for rec in generate_mmg_runs(effect, seed=seed, noise=False, n_runs=n_runs):
        truth = rec.meta["truth"]
        t = rec.time
        felt = felt_rudder(rec)
        v_n, v_e = truth["current"]
        psi0 = float(rec.psi[0])
        cs, sn = math.cos(psi0), math.sin(psi0)
        sol = simulate(
            **shipmmg_params(p), time_list=list(t), δ_list=list(felt),
            nps_list=list(rec.rpm / 60.0), u0=float(rec.u[0]) - v_n * cs - v_e * sn,
            v0=float(rec.v[0]) + v_n * sn - v_e * cs, r0=float(rec.r[0]), ψ0=psi0,
            ρ=p.rho, t_eval=t, rtol=1e-8, atol=1e-8,
        )  # fmt: skip
        u_w, v_w, r, x, y, psi = sol.y[:6]
        cp, sp = np.cos(psi), np.sin(psi)
        u = u_w + v_n * cp + v_e * sp
        v = v_w - v_n * sp + v_e * cp

        def noisy(a: np.ndarray, key: str) -> np.ndarray:
            return a + rng.normal(0.0, MMG_NOISE[key], a.shape[0])

        u, v = noisy(u, "uv"), noisy(v, "uv")
        meta = {key: val for key, val in rec.meta.items() if key != "truth"}
        meta |= {"source": "shipmmg", "truth": {**truth, "simulator": "ShipMMG"}}
        out.append(Record(
            time=t, delta=noisy(rec.delta, "delta"), psi=noisy(psi, "psi"), r=noisy(r, "r"),
            x=noisy(x + v_n * (t - t[0]), "xy"), y=noisy(y + v_e * (t - t[0]), "xy"), u=u, v=v,
            U=np.hypot(u, v), rpm=noisy(rec.rpm, "rpm"), meta=meta,
        ))  # fmt: skip
    return out


def _case(task: tuple[str | None, int, str, int, str, float | None]) -> dict[str, Any]:
    """Generate one effect and seed and identify it (a process-pool task); ``removed``: the
    held-out heading RMS with the effect taken out, from an earlier report (None: fit it)."""
    effect, seed, model, n_runs, simulator, removed = task
    row: dict[str, Any] = {"effect": effect or CLEAN, "seed": seed}
    t0 = time.perf_counter()
    if simulator == "shipmmg":
        runs = shipmmg_runs(effect, seed, n_runs)
    else:
        runs = generate_mmg_runs(effect, seed=seed, n_runs=n_runs)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = identify(runs, model)
    except (ValueError, RuntimeError, np.linalg.LinAlgError) as exc:
        return row | {"error": f"{type(exc).__name__}: {exc}", "runtime_s": 0.0}
    named = res.effect_names
    sel = res.diagnostics.get("term_set_selection") or {}
    before, after = _psi(res.heldout.get("error_before")), _psi(res.heldout.get("error_after"))
    row |= {
        "named": named,
        "first": named[0] if named else None,
        "structure": sel.get("chosen"),
        # the structures the loop ran on: each one's final held-out error and effects
        "structures": {
            n: {"heldout_error": e, "effects": sel.get("final_effects", {}).get(n, [])}
            for n, e in sel.get("final_error", {}).items()
        },
        "heldout_runs": res.heldout.get("runs", []),
        "footprint_psi_deg": footprint(effect, seed, n_runs, res.heldout.get("runs", [])),
        "heldout_psi_before_deg": before,
        "heldout_psi_after_deg": after,
        # a base model that diverges on the held-out runs (no finite error) counts as halved
        "halved": bool(math.isfinite(after) and not after > 0.5 * before),
        "actuator_named": [e for e in named if e in ACTUATOR_EFFECTS],
        "effect_parameters": {e["name"]: e["parameters"] for e in res.effects},
        "runtime_s": time.perf_counter() - t0,
    }
    if effect in REMOVABLE:  # the same structures with the effect named exactly
        try:
            if removed is None:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    bound = identify(effect_removed(runs), model, max_effects=0)
                removed = _psi(bound.heldout.get("error_before"))
        except (ValueError, RuntimeError, np.linalg.LinAlgError):
            removed = math.nan
        row["removed_psi_deg"] = removed
        row["halving_within_reach"] = bool(math.isfinite(removed) and not removed > 0.5 * before)
        row["runtime_s"] = time.perf_counter() - t0
    if effect is not None:
        row["named_first"] = row["first"] == effect
        row["passed"] = row["named_first"] and row["halved"]
    else:
        row["passed"] = not row["actuator_named"]
    return row


def _median(values: list[float]) -> float:
    """Median of the finite values (NaN if none: a diverged simulation has no error)."""
    finite = [v for v in values if v is not None and math.isfinite(v)]
    return float(np.median(finite)) if finite else math.nan


def summarise(rows: list[dict[str, Any]], effects: list[str]) -> dict[str, dict[str, Any]]:
    """Counts per effect over the seeds (failed identifications count as misses)."""
    out = {}
    for effect in effects:
        mine = [r for r in rows if r["effect"] == effect]
        ok = [r for r in mine if "error" not in r]
        entry: dict[str, Any] = {
            "seeds": len(mine),
            "failed": len(mine) - len(ok),
            "passed": sum(r["passed"] for r in ok),
            "halved": sum(r["halved"] for r in ok),
            "median_before_deg": _median([r["heldout_psi_before_deg"] for r in ok]),
            "median_after_deg": _median([r["heldout_psi_after_deg"] for r in ok]),
            "median_footprint_deg": _median([r["footprint_psi_deg"] for r in ok]),
            "asymmetric_structure": sum("+" in (r.get("structure") or "") for r in ok),
        }
        if effect in REMOVABLE:
            entry["median_removed_deg"] = _median([r["removed_psi_deg"] for r in ok])
            entry["halving_within_reach"] = sum(r["halving_within_reach"] for r in ok)
        if effect == CLEAN:
            entry["no_actuator_effect"] = entry["passed"]
            entry["no_effect"] = sum(not r["named"] for r in ok)
        else:
            entry["named_first"] = sum(r["named_first"] for r in ok)
        entry["target_met"] = entry["passed"] >= math.ceil(TARGET / 6 * len(mine))
        out[effect] = entry
    return out


def _f(x: Any, fmt: str = ".2f") -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def _held(doc: dict[str, Any]) -> str:
    """The held-out runs of the identifications (the same in every one, or each set named)."""
    sets = {tuple(r.get("heldout_runs", ())) for r in doc["rows"] if "error" not in r}
    return " | ".join(", ".join(s) or "none" for s in sorted(sets)) or "none"


def render(doc: dict[str, Any]) -> str:
    """The page's block."""
    n = doc["n_seeds"]
    lines = [
        f"The 3-DOF loop (`{doc['model']}`) on runs of the KVLCC2 L7 model made by the MMG "
        f"standard model ({SIMULATOR_NAMES[doc.get('simulator', 'shipgym')]}), whose rudder and "
        f"propeller forces its polynomials do not share: {doc['n_runs']} runs of "
        "90-120 s (10/10 and 20/20 zigzags and 35 deg turns to both sides) with noise on every "
        f"channel and one undeclared effect, {n} seed{'s' if n != 1 else ''} each; held out "
        f"(the default hold-out): {_held(doc)}. "
        f"Target: at least {TARGET} of 6 seeds.",
        "",
        "| records | named first | held-out heading RMS halved | both | median held-out "
        "heading RMS before → after [deg] | the true hull ignoring the effect [deg] | "
        "the effect taken out of the records [deg] (halving within reach) | "
        "effects named (per seed) |",
        "|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    for effect, s in doc["summary"].items():
        named = "; ".join(
            ", ".join(r["named"]) or "none" if "error" not in r else "failed"
            for r in doc["rows"] if r["effect"] == effect
        )  # fmt: skip
        first = (
            f"{s['no_actuator_effect']}/{n} no actuator effect"
            if effect == CLEAN
            else f"{s['named_first']}/{n}"
        )
        both = "" if effect == CLEAN else f"{s['passed']}/{n}"
        reach = (
            f"{_f(s['median_removed_deg'])} ({s['halving_within_reach']}/{n})"
            if "halving_within_reach" in s
            else "-"
        )
        lines.append(
            f"| {effect.replace('_', ' ')} | {first} | {s['halved']}/{n} | {both} | "
            f"{_f(s['median_before_deg'])} → {_f(s['median_after_deg'])} | "
            f"{_f(s['median_footprint_deg'])} | {reach} | {named} |"
        )
    lines += [
        "",
        "Structure chosen with the turn asymmetry (`<term set>+turn_asymmetry`): "
        + ", ".join(
            f"{effect.replace('_', ' ')} {s['asymmetric_structure']}/{n}"
            for effect, s in doc["summary"].items()
        )
        + ".",
    ]
    failed = sum(s["failed"] for s in doc["summary"].values())
    if failed:
        lines += ["", f"{failed} identifications failed (see the JSON beside the figure)."]
    simulator = doc.get("simulator", "shipgym")
    flag = "" if simulator == "shipgym" else f" --simulator {simulator}"
    lines += [
        "",
        f"Made by `python scripts/identify_mmg_records.py{flag}` in {doc['runtime_s']:.0f} s.",
    ]
    return "\n".join(lines)


def plot(doc: dict[str, Any], path: Path) -> None:
    """Held-out heading RMS before and after per effect and seed; the named-first rates."""
    effects = list(doc["summary"])
    fig, axes = plt.subplots(1, 2, figsize=(14, 4.8), constrained_layout=True,
                             gridspec_kw={"width_ratios": [2, 1]})  # fmt: skip
    ax = axes[0]
    for i, effect in enumerate(effects):
        rows = [r for r in doc["rows"] if r["effect"] == effect and "error" not in r]
        for j, r in enumerate(rows):
            x = i + 0.1 * (j - (len(rows) - 1) / 2)
            b, a = r["heldout_psi_before_deg"], r["heldout_psi_after_deg"]
            ax.plot([x, x], [b, a], "-", color="0.6", lw=1)
            ax.plot(x, b, "o", mfc="white", mec="C0")
            ax.plot(x, a, "o", color="C2" if r["passed"] else "C3")
            ax.plot(x, r["footprint_psi_deg"], "x", color="0.3", ms=5)
            if "removed_psi_deg" in r:
                ax.plot(x, r["removed_psi_deg"], "v", color="C1", ms=5)
    ax.set_xticks(range(len(effects)), [e.replace("_", " ") for e in effects])
    ax.set_yscale("log")
    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.set_ylabel("held-out heading RMS [deg]")
    made = SIMULATOR_NAMES[doc.get("simulator", "shipgym")]
    ax.set_title(f"{doc['model']} on records of {made} MMG KVLCC2: each seed before and after")
    ax.legend(handles=[
        Line2D([], [], ls="", marker="o", mfc="white", mec="C0", label="before (base model)"),
        Line2D([], [], ls="", marker="o", color="C2", label="after, passed"),
        Line2D([], [], ls="", marker="o", color="C3", label="after, missed"),
        Line2D([], [], ls="", marker="x", color="0.3", label="the true hull ignoring the effect"),
        Line2D([], [], ls="", marker="v", color="C1",
               label="the base structure on the records with the effect taken out"),
    ], fontsize=8)  # fmt: skip
    ax = axes[1]
    n = doc["n_seeds"]
    x = np.arange(len(effects))
    s = doc["summary"]
    first = [s[e]["no_actuator_effect" if e == CLEAN else "named_first"] / n for e in effects]
    ax.bar(x - 0.27, first, 0.27, label="named first (clean: no actuator effect)")
    ax.bar(
        x, [s[e]["halved"] / n for e in effects], 0.27, color="C4", label="held-out error halved"
    )
    reach = [s[e].get("halving_within_reach", math.nan) / n for e in effects]
    ax.bar(x + 0.27, reach, 0.27, color="C1", alpha=0.6,
           label="halved with the effect taken out")  # fmt: skip
    ax.axhline(TARGET / 6, color="k", lw=0.8, ls="--", label=f"target {TARGET}/6")
    ax.set_xticks(x, [e.replace("_", " ") for e in effects], rotation=30)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("fraction of seeds")
    ax.legend(fontsize=8, loc="lower left")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _earlier_removed(
    ap: argparse.ArgumentParser, args: argparse.Namespace, model: str
) -> dict[tuple[str, int], float]:
    """``(effect, seed) -> removed_psi_deg`` of the report ``--removed-from`` (empty without
    it); refused, naming the difference, for a report of other records or another model."""
    if args.removed_from is None:
        return {}
    try:
        doc = json.loads(Path(args.removed_from).read_text(encoding="utf-8"))
        same = {k: doc[k] for k in ("model", "simulator", "n_runs")}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        ap.error(f"--removed-from {args.removed_from}: not an mmg_records report ({exc})")
    mine = {"model": model, "simulator": args.simulator, "n_runs": args.n_runs}
    if same != mine:
        ap.error(f"--removed-from {args.removed_from}: a report of {same}, expected {mine}")
    return {(r["effect"], r["seed"]): float(r["removed_psi_deg"]) for r in doc["rows"]
            if isinstance(r.get("removed_psi_deg"), int | float)}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default=DEFAULT_MODEL, help=f"model (default {DEFAULT_MODEL})")
    ap.add_argument("--seeds", type=int, default=6, help="seeds 0 .. N-1 (default 6)")
    kinds = [CLEAN, *MMG_EFFECTS]
    ap.add_argument("--effects", nargs="+", choices=kinds, default=None,
                    help="records to make (default all the simulator can make)")  # fmt: skip
    ap.add_argument("--simulator", choices=tuple(SIMULATOR_NAMES), default="shipgym",
                    help="who makes the motions: shipgym's MMG model (default) or ShipMMG, "
                    "in an environment that has it (usage above)")  # fmt: skip
    ap.add_argument("--n-runs", type=int, default=6, help="runs per record set (default 6)")
    ap.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    ap.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    ap.add_argument(
        "--page",
        default=str(REPO / "docs" / "results" / "identification.md"),
        help="documentation page whose block to update",
    )
    ap.add_argument("--no-page", action="store_true", help="do not touch the page")
    ap.add_argument("--removed-from", metavar="REPORT", default=None,
                    help="take the error with the effect taken out from this earlier "
                    "mmg_records JSON report of the same records and model")  # fmt: skip
    args = ap.parse_args(argv)
    if args.seeds < 1:
        ap.error(f"--seeds must be >= 1, got {args.seeds}")
    possible = kinds if args.simulator == "shipgym" else [CLEAN, *SHIPMMG_EFFECTS]
    args.effects = args.effects or possible
    if not set(args.effects) <= set(possible):
        ap.error(f"--simulator {args.simulator} makes only {', '.join(possible)}")
    if args.simulator == "shipmmg":
        try:
            import shipmmg  # noqa: F401
        except ImportError:
            ap.error("--simulator shipmmg: ShipMMG is not installed here (usage above)")
    name = "mmg_records" + ("" if args.simulator == "shipgym" else f"_{args.simulator}")
    if not args.no_page:  # before an hour of fits, not after
        try:
            text = Path(args.page).read_text(encoding="utf-8")
            replace_between_markers(text, name, "")
        except (OSError, ValueError) as exc:
            ap.error(f"--page {args.page}: {exc} (or pass --no-page)")
    model = args.model
    if model == DEFAULT_MODEL and model not in FAMILIES:
        _say(f"{DEFAULT_MODEL} is not registered; using {FALLBACK_MODEL}")
        model = FALLBACK_MODEL
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    earlier = _earlier_removed(ap, args, model)
    tasks = [(None if e == CLEAN else e, seed, model, args.n_runs, args.simulator,
              earlier.get((e, seed)))
             for e in args.effects for seed in range(args.seeds)]  # fmt: skip
    _say(f"{len(tasks)} identifications with {model} on {args.jobs} processes ...")
    t0 = time.perf_counter()
    rows = []
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = [pool.submit(_case, task) for task in tasks]
        for k, fut in enumerate(as_completed(futures)):
            r = fut.result()
            rows.append(r)
            if "error" in r:
                _say(f"  {k + 1}/{len(tasks)} {r['effect']} seed {r['seed']}: {r['error']}")
                continue
            _say(
                f"  {k + 1}/{len(tasks)} {r['effect']} seed {r['seed']}: named "
                f"{', '.join(r['named']) or 'none'}; held-out psi "
                f"{r['heldout_psi_before_deg']:.2f} -> {r['heldout_psi_after_deg']:.2f} deg "
                f"({'passed' if r['passed'] else 'missed'}, {r['runtime_s']:.0f} s)"
            )
    order = {e: i for i, e in enumerate(args.effects)}
    rows.sort(key=lambda r: (order[r["effect"]], r["seed"]))
    summary = summarise(rows, args.effects)
    doc = {
        "model": model,
        "simulator": args.simulator,
        "n_seeds": args.seeds,
        "n_runs": args.n_runs,
        "actuator_effects": list(ACTUATOR_EFFECTS),
        "target_seeds": TARGET,
        "summary": summary,
        "rows": rows,
        "runtime_s": time.perf_counter() - t0,
    }
    for effect, s in summary.items():
        what = (
            f"no actuator effect {s['no_actuator_effect']}/{s['seeds']}"
            if effect == CLEAN
            else f"named first {s['named_first']}/{s['seeds']}, both {s['passed']}/{s['seeds']}"
        )
        print(
            f"{effect:>14}: {what}, held-out heading halved {s['halved']}/{s['seeds']}, "
            f"median {_f(s['median_before_deg'])} -> {_f(s['median_after_deg'])} deg"
            + (
                f"; the effect taken out {_f(s['median_removed_deg'])} deg, halving within "
                f"reach {s['halving_within_reach']}/{s['seeds']}"
                if "halving_within_reach" in s
                else ""
            )
            + ("" if s["target_met"] else "  (target missed)")
        )
    write_json(doc, out / f"{name}.json")
    plot(doc, out / f"{name}.png")
    if not args.no_page:
        update_block(Path(args.page), render(doc), name)
    _say(f"wrote {out / name}.json and .png in {doc['runtime_s']:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

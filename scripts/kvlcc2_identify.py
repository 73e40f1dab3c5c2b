"""Seed 003's general 3-DOF models identified from the SIMMAN 2008 KVLCC2 records.

Usage::

    python scripts/kvlcc2_identify.py [--root DIR] [--out docs]
                                      [--jobs 2] [--page docs/results/kvlcc2.md | --no-page]

1. **HSVA, cross-validation across runs.** For every term set and every one of the 13 HSVA
   zigzags, the VMM is fitted on the other 12 runs (inverse-dynamics regression, then the
   output-error refinement of :mod:`shipgym.sysid.families.vmm`) with the term set's
   straight-running side force (the ``asymmetry`` effect, as the Nomoto model below has its
   rudder offset) and predicts the left-out run
   in windows of 15 ship lengths (89 s), each window's initial sway and yaw rate estimated from
   that window with the coefficients fixed. The first-order Nomoto model gets the same protocol
   (K, T and a rudder offset fitted jointly on the other runs through the package's Nomoto
   replay, each window's initial yaw rate estimated). The within-run Nomoto held-out error of
   ``scripts/identify_all.py`` (fitted on the first 70 % of the same run) is shown beside it
   when ``docs/identification.json`` has it.
2. **MARIN turning circles.** The VMM of the best HSVA term set is fitted on the other five
   MARIN runs (full scale, propeller loading from the rpm) and predicts each turning circle in
   300 s windows; the fitted model's own 35 deg turning circle gives the tactical diameter.
3. **Trial quantities.** The VMM fitted on every run of a facility runs the standard trials of
   each record (:func:`shipgym.maneuvers.zigzag`, :func:`~shipgym.maneuvers.turning_circle`),
   beside the measurement and the published-coefficient MMG model (``docs/kvlcc2_simman.json``).
4. **MARIN, every pair of zigzags held out.** ``identify MARIN_*.dat --model vmm:auto`` holds
   out the -10 and 20 deg zigzags and chooses the term set on them; each of the six pairs of
   the four zigzags is held out here in turn (the base model of every term set fitted on the
   other four runs, scored as ``vmm:auto`` scores it), so that the choice is seen not to rest
   on one split.

Writes ``OUT/kvlcc2_identify.json``, ``OUT/kvlcc2_identify.png`` and the block between
``<!-- kvlcc2_identify -->`` and ``<!-- /kvlcc2_identify -->`` of ``docs/results/kvlcc2.md``.
The data stay where they are.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix

from shipgym import maneuvers
from shipgym.datasets import measured_root
from shipgym.models import Nomoto1Params, make_model
from shipgym.sysid import identify, load
from shipgym.sysid.families import vmm as fv
from shipgym.sysid.fit import replay
from shipgym.sysid.report import update_block, write_json

sys.path.insert(0, str(Path(__file__).resolve().parent))
from kvlcc2_simman import _trial

VMM_EFFECTS = ("asymmetry",)
"""The effects of the fitted VMM: the straight-running side force of the single screw."""

REPO = Path(__file__).resolve().parents[1]
DEFAULT_ROOT = measured_root()  # $SHIPGYM_MEASURED_DATA, else where shipgym data fetch puts it
TERM_SETS = ("linear", "martin_simple", "martin", "norrbin3", "mmg_hull")
SCORE_LENGTHS = 15.0  # scoring windows in ship lengths of travel (the family's default)
MARIN_WINDOW_S = 300.0


def _say(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def _records(root: Path, folder: str, pattern: str) -> list[Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return [load(p) for p in sorted((root / folder).glob(pattern))]


# ------------------------------------------------------------------------------------------
# the 3-DOF model, fitted on some runs and predicting another


def _setup(records: list[Any], window_s: float | None) -> tuple[Any, list[Any], Any, Any]:
    template = fv.vessel_params(records[0])
    if any(r.thrust is None for r in records):
        template = replace(template, thrust_from="rps")
        records = [replace(r, thrust=None) for r in records]
    runs = fv.prepare_runs(records, template)
    speed = float(np.median(np.concatenate([np.hypot(r.states[:, 3], r.states[:, 4])
                                            for r in runs])))  # fmt: skip
    lu = template.length / speed
    score = fv._build_replay(runs, template, window_s if window_s else SCORE_LENGTHS * lu)
    shoot = fv._build_replay(runs, template, fv.REFINE_WINDOW_LENGTHS * lu)
    return template, runs, score, shoot


def _vmm_fold(task: tuple[str, str, int, str, str, float | None]) -> dict[str, Any]:
    """Fit ``term_set`` on every run but ``left``; predict ``left`` (a process-pool task)."""
    root, folder, left, pattern, term_set, window_s = task
    records = _records(Path(root), folder, pattern)
    template, runs, score, shoot = _setup(records, window_s)
    train = [i for i in range(len(runs)) if i != left]
    fit = fv.fit_vmm(runs, template, term_set, VMM_EFFECTS, rp=shoot, fit_runs=train)
    sim = fv.predict(fit, score, [left])
    m = score.run_mask([left])
    return {"term_set": term_set, "run": runs[left].name, "refined": fit.refined,
            **fv._rms(sim[m], score.measured[m])}  # fmt: skip


# ------------------------------------------------------------------------------------------
# the first-order Nomoto model under the same protocol


def _nomoto_sim(k: float, t_c: float, d0: float, t: np.ndarray, delta: np.ndarray,
                psi0: float, r0: float) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Heading and yaw rate of ``T r' + r = K (delta + delta_0)`` replaying ``delta``, through
    the package's own Nomoto replay (:func:`shipgym.sysid.fit.replay`)."""
    x0 = np.zeros(6)
    x0[2], x0[4] = psi0, r0
    states = replay("nomoto1", Nomoto1Params(K=k, T=t_c), t, delta + d0, x0)
    return states[:, 2], states[:, 4]


def _nomoto_windows(score: Any, which: list[int]) -> list[tuple[int, int, int]]:
    """(run, start, end) sample ranges (in the replay's concatenated samples) of ``which``."""
    out = []
    for w in range(score.starts.size):
        i = int(score.run_of[score.starts[w]])
        if i in which:
            out.append((i, int(score.starts[w]), int(score.ends[w])))
    return out


def _nomoto_fit(score: Any, which: list[int], theta: np.ndarray | None,
                length: float) -> tuple[np.ndarray, dict[str, float]]:  # fmt: skip
    """K, T, delta_0 (``theta`` given: fixed) and each window's initial yaw rate, fitted to
    heading and yaw rate over the windows of ``which``; returns theta and the psi/r RMS."""
    wins = _nomoto_windows(score, which)
    meas = score.measured
    delta = score.inputs[:, 0]
    t = score.t
    sig = np.array([math.radians(1.0), math.radians(0.1)])
    r_scale = fv.START_PRIOR * float(np.median(np.abs(meas[:, 3]))) / length
    n_fixed = 0 if theta is not None else 3
    sizes = [e - s for _, s, e in wins]

    def resid(x: np.ndarray) -> np.ndarray:
        k, t_c, d0 = theta if theta is not None else x[:3]
        parts = []
        for j, (_, s, e) in enumerate(wins):
            psi, r = _nomoto_sim(k, max(t_c, 1e-3), d0, t[s:e], delta[s:e], meas[s, 2],
                                 meas[s, 5] + x[n_fixed + j])  # fmt: skip
            parts.append(fv.wrap(psi[1:] - meas[s + 1 : e, 2]) / sig[0])
            parts.append((r[1:] - meas[s + 1 : e, 5]) / sig[1])
        parts.append(x[n_fixed:] / r_scale)
        return np.concatenate(parts)

    n_res = sum(2 * (n - 1) for n in sizes) + len(wins)
    sp = lil_matrix((n_res, n_fixed + len(wins)), dtype=np.int8)
    row = 0
    for j, n in enumerate(sizes):
        sp[row : row + 2 * (n - 1), :n_fixed] = 1
        sp[row : row + 2 * (n - 1), n_fixed + j] = 1
        row += 2 * (n - 1)
    sp[row + np.arange(len(wins)), n_fixed + np.arange(len(wins))] = 1
    x0 = np.concatenate(([0.05, 20.0, 0.0] if theta is None else [], np.zeros(len(wins))))
    scale = np.concatenate(([0.05, 10.0, 0.01] if theta is None else [],
                            np.full(len(wins), r_scale)))  # fmt: skip
    # (scipy's trust region with a sparse Jacobian needs at least three unknowns)
    sol = least_squares(resid, x0, x_scale=scale, jac_sparsity=sp if x0.size > 2 else None,
                        max_nfev=60)  # fmt: skip
    th = theta if theta is not None else sol.x[:3]
    e = resid(sol.x)[: n_res - len(wins)]
    psi_e, r_e = [], []
    row = 0
    for n in sizes:
        psi_e.append(e[row : row + n - 1] * sig[0])
        r_e.append(e[row + n - 1 : row + 2 * (n - 1)] * sig[1])
        row += 2 * (n - 1)
    return np.asarray(th), {
        "psi_rms_deg": math.degrees(float(np.sqrt(np.mean(np.concatenate(psi_e) ** 2)))),
        "r_rms_deg_s": math.degrees(float(np.sqrt(np.mean(np.concatenate(r_e) ** 2)))),
    }


def _nomoto_fold(task: tuple[str, str, int, str]) -> dict[str, Any]:
    root, folder, left, pattern = task
    records = _records(Path(root), folder, pattern)
    template, runs, score, _ = _setup(records, None)
    train = [i for i in range(len(runs)) if i != left]
    theta, _ = _nomoto_fit(score, train, None, template.length)
    _, err = _nomoto_fit(score, [left], theta, template.length)
    return {"run": runs[left].name, "K": theta[0], "T": theta[1], "delta_0": theta[2], **err}


# ------------------------------------------------------------------------------------------
# trials of a fitted model


def _trials_of(
    fit: Any, mmg: Any, records: list[Any], simman: dict[str, Any]
) -> list[dict[str, Any]]:
    ships = {"vmm": make_model("vmm", fit.params), "mmg_refined": make_model("kvlcc2", mmg.params)}
    rows = []
    for rec in records:
        trial = _trial(Path(rec.meta["file"]))
        if trial is None:
            continue
        ref = simman.get(rec.meta["file"], {})
        row = {"record": rec.meta["file"], **trial, "measured": ref.get("measured"),
               "mmg": ref.get("model")}  # fmt: skip
        for key, ship in ships.items():
            try:
                if trial["kind"] == "zigzag":
                    z = maneuvers.zigzag(ship, trial["a"], trial["b"],
                                         first=trial["side"] or "starboard")  # fmt: skip
                    row[key] = {"overshoot1_deg": z.overshoots_deg[0],
                                "overshoot2_deg": z.overshoots_deg[1]}  # fmt: skip
                else:
                    tc = maneuvers.turning_circle(ship, trial["a"], trial["side"])
                    row[key] = {"advance": tc.advance, "tactical_diameter": tc.tactical_diameter,
                                "speed_ratio": tc.speed_ratio}  # fmt: skip
            except (ValueError, IndexError) as exc:
                row[key] = {"error": str(exc)}
        rows.append(row)
    return rows


def _marin_pairs(marin: list[Any]) -> list[dict[str, Any]]:
    """Held-out heading RMS [deg] of the base model of every term set on each pair of MARIN
    zigzags, fitted on the other four runs as ``vmm:auto`` fits and scores it (inf: the model
    runs away on a held-out or training run)."""
    from itertools import combinations

    from shipgym.sysid.families.base import FAMILIES

    family = FAMILIES["vmm:auto"]
    ctx = family.prepare(marin, 0.3, "auto")
    zigzags = [i for i, r in enumerate(marin) if "_zz_" in r.meta["file"]]
    tasks = [(list(pair), ts) for pair in combinations(zigzags, 2) for ts in TERM_SETS]

    def score(task: tuple[list[int], str]) -> float:
        held, term_set = task
        train = [i for i in range(len(marin)) if i not in held]
        cand = family._candidate(replace(ctx, term_set=term_set, held=held, train=train), ())
        return math.degrees(cand.heldout_rms["psi"]) if cand.heldout_rms else math.inf

    with ThreadPoolExecutor(max_workers=2) as pool:  # the replay kernel releases the GIL
        psi = list(pool.map(score, tasks))
    rows: dict[tuple[int, ...], dict[str, Any]] = {}
    for (held, term_set), value in zip(tasks, psi, strict=True):
        name = " + ".join(Path(marin[i].meta["file"]).name.removeprefix("MARIN_FREE_KVLCC2_")
                          .removesuffix("_m.dat") for i in held)  # fmt: skip
        rows.setdefault(tuple(held), {"held_out": name, "psi_rms_deg": {}})
        rows[tuple(held)]["psi_rms_deg"][term_set] = value
    return list(rows.values())


def _fit_all(records: list[Any], term_set: str) -> Any:
    template, runs, _, shoot = _setup(records, None)
    return fv.fit_vmm(runs, template, term_set, VMM_EFFECTS, rp=shoot)


# ------------------------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--root", default=str(DEFAULT_ROOT), help="measured-data folder (default: %(default)s)"
    )
    ap.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    ap.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    ap.add_argument(
        "--page",
        default=str(REPO / "docs" / "results" / "kvlcc2.md"),
        help="documentation page whose block to update",
    )
    ap.add_argument("--no-page", action="store_true", help="do not touch the page")
    ap.add_argument("--folds", help="JSON file keeping the VMM fold results between runs")
    args = ap.parse_args(argv)
    root, out = Path(args.root), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    simman_path = out / "kvlcc2_simman.json"
    simman = ({r["record"]: r for r in json.loads(simman_path.read_text())}
              if simman_path.exists() else {})  # fmt: skip
    hsva = _records(root, "hsva_kvlcc2", "*.dat")
    marin = _records(root, "marin_kvlcc2", "*.dat")
    for folder, recs in (("hsva_kvlcc2", hsva), ("marin_kvlcc2", marin)):
        if not recs:
            dataset = folder.replace("_", "-")
            ap.error(
                f"no records in {root / folder}: fetch them (shipgym data fetch {dataset}) "
                "or pass --root, the folder that holds hsva_kvlcc2/ and marin_kvlcc2/"
            )
    n_h = len(hsva)

    t0 = time.perf_counter()
    _say(f"HSVA: {len(TERM_SETS)} term sets x {n_h} folds and the Nomoto folds ...")
    vmm_tasks = [(str(root), "hsva_kvlcc2", i, "*.dat", ts, None)
                 for ts in TERM_SETS for i in range(n_h)]  # fmt: skip
    nom_tasks = [(str(root), "hsva_kvlcc2", i, "*.dat") for i in range(n_h)]
    cache = Path(args.folds) if args.folds else None
    vmm_rows = json.loads(cache.read_text()) if cache and cache.exists() else []
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        if len(vmm_rows) != len(vmm_tasks):
            vmm_rows = []
            for k, row in enumerate(pool.map(_vmm_fold, vmm_tasks)):
                vmm_rows.append(row)
                _say(f"  {k + 1}/{len(vmm_tasks)} {row['term_set']} {row['run']}: "
                     f"psi {row['psi_rms_deg']:.2f} deg")  # fmt: skip
            if cache:
                cache.write_text(json.dumps(vmm_rows))
        nomoto_rows = list(pool.map(_nomoto_fold, nom_tasks))
    cv_s = time.perf_counter() - t0
    median = {ts: float(np.median([r["psi_rms_deg"] for r in vmm_rows if r["term_set"] == ts]))
              for ts in TERM_SETS}  # fmt: skip
    best = min(median, key=median.get)
    within = {}
    ident = out / "identification.json"
    if ident.exists():
        for r in json.loads(ident.read_text())["rows"]:
            if r.get("source") == "hsva" and r.get("heldout"):
                within[r["file"]] = r["heldout"]["error_after"]["psi_rms_deg"]
    hsva_rows = []
    for nom in nomoto_rows:
        v = next(r for r in vmm_rows if r["term_set"] == best and r["run"] == nom["run"])
        hsva_rows.append({"run": nom["run"], "vmm": v, "nomoto_cv": nom,
                          "nomoto_within_run": within.get(nom["run"])})  # fmt: skip
    beats = sum(r["vmm"]["psi_rms_deg"] < r["nomoto_cv"]["psi_rms_deg"] for r in hsva_rows)
    _say(f"best term set {best} (median {median[best]:.2f} deg); beats the cross-validated "
         f"Nomoto on {beats}/{n_h} runs ({cv_s:.0f} s)")  # fmt: skip

    # timing of the regression and the loop on all 13 runs
    template, runs, _, _ = _setup(hsva, None)
    t1 = time.perf_counter()
    fv.regress(runs, template, fv.TERM_SETS[best])
    regression_s = time.perf_counter() - t1
    t1 = time.perf_counter()
    loop = identify(hsva, f"vmm:{best}")
    loop_s = time.perf_counter() - t1
    _say(f"regression {regression_s:.2f} s, loop {loop_s:.1f} s, effects {loop.effect_names}")

    _say("MARIN: turning circles predicted from the other runs ...")
    marin_rows = []
    for i, rec in enumerate(marin):
        if "_tc_" not in rec.meta["file"]:
            continue
        row = _vmm_fold((str(root), "marin_kvlcc2", i, "*.dat", best, MARIN_WINDOW_S))
        others = [r for j, r in enumerate(marin) if j != i]
        fit = _fit_all(others, best)
        trial = _trial(Path(rec.meta["file"]))
        try:
            tc = maneuvers.turning_circle(make_model("vmm", fit.params), trial["a"],
                                          trial["side"])  # fmt: skip
            td_vmm, advance_vmm = tc.tactical_diameter, tc.advance
        except ValueError:  # a model fitted on the other side's turn only may run away
            td_vmm = advance_vmm = None
        meas = simman.get(rec.meta["file"], {}).get("measured", {})
        row.update(tactical_diameter_vmm=td_vmm, advance_vmm=advance_vmm,
                   tactical_diameter_measured=meas.get("tactical_diameter"),
                   advance_measured=meas.get("advance"),
                   tactical_diameter_mmg=simman.get(rec.meta["file"], {}).get("model", {})
                   .get("tactical_diameter"))  # fmt: skip
        marin_rows.append(row)
        _say(
            f"  {row['run']}: psi {row['psi_rms_deg']:.2f} deg in {MARIN_WINDOW_S:g} s windows; "
            f"TD {_f(td_vmm, '.0f')} m (measured {meas.get('tactical_diameter', 0):.0f})"
        )

    _say("MARIN: every pair of zigzags predicted from the other runs ...")
    marin_pairs = _marin_pairs(marin)
    for row in marin_pairs:
        _say(
            f"  {row['held_out']}: "
            + ", ".join(f"{k} {v:.2f}" for k, v in row["psi_rms_deg"].items())
        )

    _say("the MMG model refined on every run of each facility ...")
    mmg = {name: identify(recs, "kvlcc2", max_effects=0).final
           for name, recs in (("hsva", hsva), ("marin", marin))}  # fmt: skip
    for name, fit in mmg.items():
        _say(f"  {name}: factors {fit.factors}; at a bound: {fit.at_bound or 'none'}")
    _say("trial quantities of the models fitted on every run ...")
    trials = _trials_of(_fit_all(hsva, best), mmg["hsva"], hsva, simman) + _trials_of(
        _fit_all(marin, best), mmg["marin"], marin, simman
    )

    doc = {
        "term_sets": list(TERM_SETS),
        "median_cv_psi_rms_deg": median,
        "best_term_set": best,
        "hsva": hsva_rows,
        "hsva_all_sets": vmm_rows,
        "beats_nomoto_cv": beats,
        "regression_s": regression_s,
        "loop_s": loop_s,
        "loop_effects": loop.effect_names,
        "marin": marin_rows,
        "marin_zigzag_pairs": marin_pairs,
        "mmg_refined": {
            name: {"factors": fit.factors, "stderr": fit.stderr, "at_bound": fit.at_bound}
            for name, fit in mmg.items()
        },
        "trials": trials,
        "runtime_s": time.perf_counter() - t0,
    }
    write_json(doc, out / "kvlcc2_identify.json")
    plot(doc, out / "kvlcc2_identify.png")
    if not args.no_page:
        update_block(Path(args.page), render(doc), "kvlcc2_identify")
    _say(f"wrote {out / 'kvlcc2_identify.json'} and .png in {time.perf_counter() - t0:.0f} s")
    return 0


def _f(x: Any, fmt: str = ".1f") -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def _table_head(first: str, columns: list[str]) -> list[str]:
    """A markdown table's header and rule: ``first``, then the ``columns`` as code."""
    return ["| " + " | ".join([first, *(f"`{c}`" for c in columns)]) + " |",
            "|---|" + "---:|" * len(columns)]  # fmt: skip


def render(doc: dict[str, Any]) -> str:
    best = doc["best_term_set"]
    lines = [
        f"Cross-validation across the 13 HSVA runs (each run predicted by a model fitted on the "
        f"other 12, in windows of {SCORE_LENGTHS:g} ship lengths with each window's initial sway "
        f"and yaw rate estimated). Median heading RMS per term set: "
        + ", ".join(f"`{k}` {v:.2f} deg" for k, v in doc["median_cv_psi_rms_deg"].items())
        + f". The best, `{best}`, beats the first-order Nomoto model under the same protocol "
        f"on **{doc['beats_nomoto_cv']} of 13** runs.",
        "",
        "| run | VMM psi [deg] | u [m/s] | v [m/s] | Nomoto, other runs [deg] | Nomoto, same run "
        "(first 70 %) [deg] |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for r in doc["hsva"]:
        v = r["vmm"]
        lines.append(
            f"| {r['run'].removeprefix('HSVA_CPMC_KVLCC2_').removesuffix('.dat')} | "
            f"{v['psi_rms_deg']:.2f} | {v['u_rms_m_s']:.4f} | {v['v_rms_m_s']:.4f} | "
            f"{r['nomoto_cv']['psi_rms_deg']:.2f} | {_f(r['nomoto_within_run'], '.2f')} |"
        )
    lines += [
        "",
        f"Fitting all 13 runs: regression {doc['regression_s']:.2f} s, whole loop "
        f"{doc['loop_s']:.1f} s (effects named: {', '.join(doc['loop_effects']) or 'none'}).",
        "",
        f"MARIN turning circles, predicted by `{best}` fitted on the other five MARIN runs "
        f"({MARIN_WINDOW_S:g} s windows):",
        "",
        "| run | heading RMS [deg] | tactical diameter VMM / measured / MMG [m] |",
        "|---|---:|---:|",
    ]
    for r in doc["marin"]:
        lines.append(
            f"| {r['run'].removeprefix('MARIN_FREE_KVLCC2_').removesuffix('_m.dat')} | "
            f"{_f(r['psi_rms_deg'], '.2f')} | {_f(r['tactical_diameter_vmm'], '.0f')} / "
            f"{_f(r['tactical_diameter_measured'], '.0f')} / "
            f"{_f(r['tactical_diameter_mmg'], '.0f')} |"
        )
    away = [r for r in doc["marin"] if r["tactical_diameter_vmm"] is None
            or not math.isfinite(r["psi_rms_deg"])]  # fmt: skip
    if away:
        lines += ["", f"A dash: the model fitted without that turn runs away in it ({len(away)} "
                  f"of {len(doc['marin'])}); fitted on one side's turn only, `{best}` "
                  "extrapolates its turning terms to the other side."]  # fmt: skip
    pairs = doc.get("marin_zigzag_pairs", [])
    if pairs:
        sets = list(pairs[0]["psi_rms_deg"])
        lowest = [min(p["psi_rms_deg"], key=p["psi_rms_deg"].get) for p in pairs]
        lines += [
            "",
            "MARIN, every pair of the four zigzags held out in turn (the base model of each "
            "term set fitted on the other four runs and scored as `vmm:auto` scores it; "
            "`identify MARIN_*.dat --model vmm:auto` holds out the first pair and chooses "
            "its term set there). Held-out heading RMS [deg], a dash where the model runs away:",
            "",
            *_table_head("held out", sets),
        ]
        for p, best_ts in zip(pairs, lowest, strict=True):
            lines.append(f"| {p['held_out']} | " + " | ".join(
                (f"**{_f(v, '.2f')}**" if ts == best_ts else _f(v, ".2f"))
                for ts, v in p["psi_rms_deg"].items()) + " |")  # fmt: skip
        wins = [f"`{ts}` {lowest.count(ts)} of {len(pairs)}" for ts in sets if ts in lowest]
        lines += ["", "Lowest on a pair: " + ", ".join(wins) + "."]
    zz = [t for t in doc["trials"] if t["kind"] == "zigzag" and t.get("measured")
          and "overshoot1_deg" in t.get("vmm", {})]  # fmt: skip
    if zz:
        under_mmg = [t["measured"]["overshoot1_deg"] - t["mmg"]["overshoot1_deg"] for t in zz]
        under_vmm = [t["measured"]["overshoot1_deg"] - t["vmm"]["overshoot1_deg"] for t in zz]
        lines += [
            "",
            f"First overshoots of the {len(zz)} zigzags: the published MMG coefficients "
            f"under-predict them by a median {np.median(under_mmg):.1f} deg (max "
            f"{np.max(under_mmg):.1f}); the identified `{best}` (fitted on all runs of the "
            f"facility) misses them by a median {np.median(under_vmm):+.1f} deg "
            f"(|max| {np.max(np.abs(under_vmm)):.1f}).",
        ]
    mm = doc["mmg_refined"]
    if mm:
        zz_r = [t for t in zz if "overshoot1_deg" in t.get("mmg_refined", {})]
        under_r = [t["measured"]["overshoot1_deg"] - t["mmg_refined"]["overshoot1_deg"]
                   for t in zz_r]  # fmt: skip
        names = list(next(iter(mm.values()))["factors"])
        lines += [
            "",
            "The MMG model itself, its resistance and linear hull derivatives refined on the "
            "same runs (`shipgym identify ... --model kvlcc2`; factors on the published values "
            "with standard errors):",
            "",
            *_table_head("facility", names),
        ]
        for name, m in mm.items():
            cells = [f"{m['factors'][k]:.2f} ± {m['stderr'][k]:.3f}" for k in names]
            lines.append(f"| {name.upper()} | " + " | ".join(cells) + " |")
        if zz_r:
            bound = ", ".join(k for m in mm.values() for k in m["at_bound"]) or "none"
            lines += [
                "",
                f"Refined this way the MMG model misses the first overshoots by a median "
                f"{np.median(under_r):+.1f} deg (|max| {np.max(np.abs(under_r)):.1f}); factors "
                f"at a bound: {bound}.",
            ]
    return "\n".join(lines)


def plot(doc: dict[str, Any], path: Path) -> None:
    fig, axes = plt.subplots(1, 4, figsize=(21, 4.8), constrained_layout=True)
    ax = axes[0]
    runs = [r["run"].removeprefix("HSVA_CPMC_KVLCC2_Z_").removesuffix(".dat") for r in doc["hsva"]]
    x = np.arange(len(runs))
    ax.bar(x - 0.27, [r["vmm"]["psi_rms_deg"] for r in doc["hsva"]], 0.27,
           label=f"VMM {doc['best_term_set']}, other runs")  # fmt: skip
    ax.bar(x, [r["nomoto_cv"]["psi_rms_deg"] for r in doc["hsva"]], 0.27,
           label="Nomoto, other runs")  # fmt: skip
    ax.bar(x + 0.27, [r["nomoto_within_run"] or np.nan for r in doc["hsva"]], 0.27,
           label="Nomoto, same run (first 70 %)")  # fmt: skip
    ax.set_xticks(x, runs, rotation=60, fontsize=8)
    ax.set_ylabel("held-out heading RMS [deg]")
    ax.set_yscale("log")
    ax.set_title("HSVA KVLCC2: each run predicted")
    ax.legend(fontsize=8)
    ax = axes[1]
    zz = [t for t in doc["trials"] if t["kind"] == "zigzag" and t.get("measured")
          and "overshoot1_deg" in t.get("vmm", {})]  # fmt: skip
    meas = [t["measured"]["overshoot1_deg"] for t in zz]
    ax.plot(meas, [t["mmg"]["overshoot1_deg"] for t in zz], "o", label="MMG, published")
    ax.plot(meas, [t["vmm"]["overshoot1_deg"] for t in zz], "s",
            label=f"VMM {doc['best_term_set']}, identified")  # fmt: skip
    ax.plot(meas, [t.get("mmg_refined", {}).get("overshoot1_deg", np.nan) for t in zz], "^",
            label="MMG, derivatives refined")  # fmt: skip
    lim = max([*meas, 1.0]) * 1.15
    ax.plot([0, lim], [0, lim], "k-", lw=0.8)
    ax.set_xlabel("measured first overshoot [deg]")
    ax.set_ylabel("predicted first overshoot [deg]")
    ax.set_title("zigzag first overshoots (HSVA and MARIN)")
    ax.legend(fontsize=8)
    ax = axes[2]
    names = [r["run"].removeprefix("MARIN_FREE_KVLCC2_").removesuffix("_m.dat")
             for r in doc["marin"]]  # fmt: skip
    x = np.arange(len(names))
    ax.bar(x - 0.27, [r["tactical_diameter_measured"] or np.nan for r in doc["marin"]], 0.27,
           label="measured")  # fmt: skip
    ax.bar(x, [r["tactical_diameter_vmm"] or np.nan for r in doc["marin"]], 0.27,
           label="VMM, other runs")  # fmt: skip
    ax.bar(x + 0.27, [r["tactical_diameter_mmg"] or np.nan for r in doc["marin"]], 0.27,
           label="MMG, published")  # fmt: skip
    ax.set_xticks(x, names)
    ax.set_ylabel("tactical diameter [m]")
    ax.set_title("MARIN 35 deg turning circles")
    ax.legend(fontsize=8)
    ax = axes[3]
    pairs = doc.get("marin_zigzag_pairs", [])
    if pairs:
        sets = list(pairs[0]["psi_rms_deg"])
        x = np.arange(len(pairs))
        width = 0.8 / len(sets)
        for k, ts in enumerate(sets):
            values = [p["psi_rms_deg"][ts] for p in pairs]
            ax.bar(
                x + (k - (len(sets) - 1) / 2) * width,
                [v if math.isfinite(v) else np.nan for v in values],
                width,
                label=ts,
            )
        ax.set_xticks(x, [p["held_out"].replace(" + ", "\n") for p in pairs], fontsize=8)
        ax.set_ylabel("held-out heading RMS [deg]")
        ax.set_title("MARIN: each pair of zigzags predicted")
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())

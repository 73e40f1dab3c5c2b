"""Identification report over every measured record, and the speed benchmark of the loop.

* Every measured record: a table of the simulation error before and after, the effects found
  and the parameters, made by one script: :func:`identify_all`
  runs :func:`shipgym.sysid.engine.identify` on every record (``nomoto1``, seed 000
  ``T r' + r = K delta``, on all of them; also ``rvg3dof``, the R/V Gunnerus 3-DOF model of
  seed 001, on the records with pod channels, i.e. the Gunnerus sea trials);
  :func:`render_table` is the compact table, :func:`render_markdown` the block of the results
  page (``docs/results/identification.md``) around it
  and :func:`render_document` ``docs/identification.md`` (one section per record, all
  parameters, held-out errors, the Gunnerus seed-001 / calibrated / with-effects comparison);
  :func:`plot_summary` draws the heading errors before and after, :func:`plot_record` the
  per-record figure (:func:`shipgym.sysid.plots.plot_identification`), and
  :func:`update_block` replaces a documentation page's block between ``<!-- identification -->``
  markers (:func:`relative_link` links a page to a figure beside it).
  The script is ``scripts/identify_all.py``.
* The speed of the loop (a first-order output-error fit of 10 000 samples, the whole loop on a
  10 000-sample record, the Gunnerus record), measured by :func:`benchmark_sysid` and shown by
  :func:`format_benchmark` and :func:`plot_benchmark` (``scripts/bench_sysid.py``). Nothing
  here asserts a time.

Preparation of a record (:func:`prepare_record`): when the loader marked the manoeuvre inside a
longer run (``meta["manoeuvre_start_s"]``/``meta["manoeuvre_end_s"]``: the Esso Osaka zigzag and
turning runs start from rest under manual corrections and end coasting, SOURCES.md section 5)
the record is cut to it; every other record is identified whole. A failure of one record is
caught and written into its row (``status`` ``"failed"`` and the message), so one bad record
does not stop the report.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import math
import os
import platform
import statistics
import time
import traceback
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.sysid.data import ProgressArg, Record, load, load_all, progress_printer
from shipgym.sysid.engine import IdentificationResult, identify
from shipgym.sysid.families.base import FAMILIES, window_starts
from shipgym.sysid.units import PARAMETER_UNITS

__all__ = [
    "BENCH_GOALS",
    "DEFAULT_MODELS",
    "FIGURES",
    "PAGE_MARKER",
    "benchmark_sysid",
    "format_benchmark",
    "identify_all",
    "merge_rows",
    "model_applies",
    "plot_benchmark",
    "plot_record",
    "plot_summary",
    "prepare_record",
    "relative_link",
    "render_document",
    "render_markdown",
    "render_table",
    "replace_between_markers",
    "rvg_available",
    "update_block",
    "write_json",
]

DEFAULT_MODELS: tuple[str, ...] = ("nomoto1", "rvg3dof", "vmm:martin_simple")
"""Bases run by :func:`identify_all` by default: ``nomoto1`` on every record, ``rvg3dof`` and
the 3-DOF ``vmm:martin_simple`` on the records they apply to (:func:`model_applies`)."""

_VMM_SOURCES = ("hsva", "marin", "esso_osaka")

FIGURES: dict[str, tuple[str, str]] = {
    "sspa": ("nomoto1", "identification_sspa.png"),
    "gunnerus": ("rvg3dof", "identification_gunnerus.png"),
}
"""Per-record figures of the report: source -> (model, file name in the output folder)."""

PAGE_MARKER = "identification"
"""Name of the block of ``docs/results/identification.md``: ``<!-- identification -->`` ...
``<!-- /identification -->``."""

BENCH_GOALS: dict[str, float] = {
    "fit": 1.0,
    "loop": 10.0,
    "gunnerus": 60.0,
    "hsva_regression": 5.0,
    "hsva_loop": 60.0,
}
"""Speed goals [s]: nomoto1 output-error fit of 10 000 samples, the whole loop on a
10 000-sample record, the Gunnerus record with ``rvg3dof``, and the 3-DOF model on all 13 HSVA
KVLCC2 runs together (the inverse-dynamics regression, and the whole loop)."""

BENCH_VMM = "vmm:auto"
"""The 3-DOF model the HSVA benchmark identifies (the term set chosen by the loop)."""

BENCH_VMM_TERMS = "martin_simple"
"""The term set of the HSVA regression benchmark."""

_SOURCE_ORDER = ("sspa", "marin", "hsva", "esso_osaka", "usv", "gunnerus")
_SOURCE_LABEL = {
    "sspa": "SSPA",
    "marin": "MARIN KVLCC2",
    "hsva": "HSVA KVLCC2",
    "esso_osaka": "Esso Osaka",
    "usv": "USV",
    "gunnerus": "Gunnerus",
    "shipgym.sysid.generator": "generated",
}
_STEM_PREFIXES = ("MARIN_FREE_KVLCC2_", "HSVA_CPMC_KVLCC2_")
#: Manoeuvres of the sources whose files do not name them (SOURCES.md).
_SOURCE_MANOEUVRE = {
    "sspa": "zigzag 20/20",
    "gunnerus": "sea trials: straight runs and steady turns at 110-200 rpm, azimuth 5-33 deg",
}
_EFFECT_SHORT = {
    "rudder_offset": "offset",
    "yaw_nonlinearity": "nonlin",
    "rudder_lag": "lag",
    "input_delay": "delay",
    "current": "current",
    "second_order": "2nd order",
    "thruster_lift": "pod lift",
    "azimuth_offset": "azi offset",
    "sway_offset": "sway offset",
}
_ERROR_COLUMNS = (
    ("psi_rms_deg", "ψ RMS [deg]"),
    ("r_rms_deg_s", "r RMS [deg/s]"),
    ("xy_rms_m", "xy RMS [m]"),
    ("u_rms_m_s", "u RMS [m/s]"),
)


# ----------------------------------------------------------------------------------------------
# records and models
# ----------------------------------------------------------------------------------------------
def rvg_available() -> bool:
    """True when the ``rvg3dof`` family (:mod:`shipgym.sysid.families.rvg`) is registered."""
    return "rvg3dof" in FAMILIES


def model_applies(model: str, record: Record) -> bool:
    """Whether :func:`identify_all` runs ``model`` on ``record``.

    ``rvg3dof`` needs the pod channels (``azimuth``, ``rpm``), positions and body velocities
    (the Gunnerus sea trials and generated RVG records); the 3-DOF ``vmm:...`` models need
    positions, body velocities, thrust or rpm and a ship whose particulars are known (the
    KVLCC2 and Esso Osaka records, or ``meta["particulars"]``); every other base applies to all
    records.
    """
    if model == "rvg3dof":
        return all(getattr(record, ch) is not None for ch in ("azimuth", "rpm", "x", "y", "u"))
    if model.startswith("vmm:"):
        known = record.meta.get("source") in _VMM_SOURCES or "particulars" in record.meta
        motion = all(getattr(record, ch) is not None for ch in ("x", "y", "u", "v"))
        return known and motion and (record.thrust is not None or record.rpm is not None)
    return True


def _record_file(record: Record, index: int) -> str:
    return str(record.meta.get("file") or f"record_{index}")


def _label(source: str, file: str) -> str:
    stem = Path(file).stem
    for prefix in _STEM_PREFIXES:
        stem = stem.removeprefix(prefix)
    if source == "marin":
        stem = stem.removesuffix("_m")
    return f"{_SOURCE_LABEL.get(source, source)} {stem}".strip()


def _manoeuvre(record: Record) -> str | None:
    meta = record.meta
    source = str(meta.get("source", ""))
    if meta.get("title"):
        return str(meta["title"])
    if source in _SOURCE_MANOEUVRE:
        return _SOURCE_MANOEUVRE[source]
    name = Path(str(meta.get("file", ""))).name.lower()
    for key, what in (("zigzag", "zigzag"), ("turn", "turning circle"), ("random", "random")):
        if name.startswith(key):
            return what
    if meta.get("maneuver"):
        return str(meta["maneuver"])
    return None


def prepare_record(record: Record) -> tuple[Record, list[float] | None]:
    """The part of ``record`` to identify and its time span (None: the whole record).

    A record whose loader marked the manoeuvre (``meta["manoeuvre_start_s"]`` and
    ``meta["manoeuvre_end_s"]``) is cut to it; any other record is returned unchanged.
    """
    t0, t1 = record.meta.get("manoeuvre_start_s"), record.meta.get("manoeuvre_end_s")
    if t0 is None or t1 is None:
        return record, None
    return record.slice(float(t0), float(t1)), [float(t0), float(t1)]


def _base_row(record: Record, index: int, model: str) -> dict[str, Any]:
    source = str(record.meta.get("source", "unknown"))
    file = _record_file(record, index)
    return {
        "record": f"{source}/{file}",
        "label": _label(source, file),
        "source": source,
        "file": file,
        "vessel": record.meta.get("vessel"),
        "manoeuvre": _manoeuvre(record),
        "samples_total": record.n,
        "duration_total_s": record.duration,
        "dt_s": record.dt,
        "repairs": list(record.meta.get("repairs", [])),
        "model": model,
        "status": "pending",
        "message": None,
    }


def _fill_row(row: dict[str, Any], fitted: Record, result: IdentificationResult) -> None:
    d = result.to_dict()
    before = d.get("parameters_before") or {}
    row.update(
        {
            "status": "ok",
            "samples": fitted.n,
            "duration_s": fitted.duration,
            "error_before": d.get("error_before"),
            "error_after": d.get("error_after"),
            "heldout": d.get("heldout"),
            "effects": d.get("effects", []),
            "effect_names": [e["name"] for e in d.get("effects", [])],
            "parameters_before": before,
            "parameters_after": d.get("parameters"),
            "key_parameters": {k: before[k] for k in ("K", "T") if k in before},
            "window_s": d.get("window_s"),
            "runtime_s": d.get("runtime_s"),
            "rounds": d.get("rounds", []),
        }
    )
    seed = (
        (result.diagnostics or {}).get("seed001") if isinstance(result.diagnostics, dict) else None
    )
    if isinstance(seed, dict) and "error" in seed:  # rvg3dof: the uncalibrated seed-001 model
        row["error_seed001"] = _clean(dict(seed["error"]))


def identify_all(
    root: str | Path | None = None,
    *,
    records: Iterable[Record] | None = None,
    models: Sequence[str] | None = None,
    only: str | None = None,
    holdout: float = 0.3,
    max_effects: int = 3,
    window_s: float | str | None = "auto",
    trim: bool = True,
    progress: ProgressArg = True,
    detail: bool = False,
    on_result: Callable[[Record, IdentificationResult, dict[str, Any]], None] | None = None,
    identify_fn: Callable[..., IdentificationResult] = identify,
) -> list[dict[str, Any]]:
    """Identify every record and return one JSON-ready row per (record, model).

    Parameters
    ----------
    root : str or pathlib.Path, optional
        The measured-data folder (:func:`shipgym.datasets.measured_root`, filled by
        ``shipgym data fetch all``), read by :func:`shipgym.sysid.data.load_all`. Either
        ``root`` or ``records``.
    records : iterable of Record, optional
        Records to identify instead of loading ``root`` (e.g. canonical CSVs read with
        :func:`shipgym.sysid.data.load`); ``meta["source"]`` and ``meta["file"]`` name them.
    models : sequence of str, optional
        Bases to run (:data:`DEFAULT_MODELS` by default), each on the records it applies to
        (:func:`model_applies`). ``rvg3dof`` is reported as ``"skipped"`` while
        :mod:`shipgym.sysid.families.rvg` is not registered.
    only : str, optional
        Keep the records whose ``source/file`` contains this text (case-insensitive).
    holdout, max_effects, window_s
        Passed to :func:`shipgym.sysid.engine.identify`.
    trim : bool
        Cut records to the manoeuvre marked by their loader (:func:`prepare_record`).
    progress : callable, file or bool
        Where the per-record lines go (``True``: stderr; ``False``/None: silence). A line when a
        record starts and one when it ends (runtime, heading error, effects).
    detail : bool
        Also forward :func:`identify`'s per-candidate lines (indented).
    on_result : callable, optional
        Called as ``on_result(record, result, row)`` after each successful identification (the
        record as identified); e.g. to draw a per-record figure from ``result.traces``.
    identify_fn : callable
        The identifier (:func:`shipgym.sysid.engine.identify`; replaceable for tests).

    Returns
    -------
    list of dict
        Per row: ``record`` (``source/file``), ``label``, ``source``, ``file``, ``vessel``,
        ``manoeuvre``, ``samples_total``, ``duration_total_s``, ``dt_s``, ``repairs``,
        ``span_s`` (the cut, or None), ``model``, ``status`` (``"ok"``, ``"failed"``,
        ``"skipped"``), ``message`` (the error for failed/skipped rows), ``warnings``; for
        ``"ok"`` rows also ``samples``, ``duration_s`` (of the identified part),
        ``error_before``, ``error_after``, ``heldout``, ``effects``, ``effect_names``,
        ``parameters_before``, ``parameters_after``, ``key_parameters`` (``K``, ``T`` of the
        base fit), ``window_s``, ``runtime_s`` and ``rounds`` (see
        :meth:`IdentificationResult.to_dict`).

    Raises
    ------
    ValueError
        If neither or both of ``root`` and ``records`` are given, or ``models`` is empty.
    """
    if (root is None) == (records is None):
        raise ValueError("identify_all needs exactly one of root (a folder) or records")
    models = tuple(DEFAULT_MODELS if models is None else models)
    if not models:
        raise ValueError("models must name at least one base, e.g. ('nomoto1',)")
    say = progress_printer(progress)
    if records is None:
        with warnings.catch_warnings():  # repairs are listed in meta["repairs"]
            warnings.simplefilter("ignore")
            records = load_all(root)  # type: ignore[arg-type]
    recs = list(records)
    jobs: list[tuple[int, Record, str]] = []
    for i, rec in enumerate(recs):
        name = f"{rec.meta.get('source', 'unknown')}/{_record_file(rec, i)}"
        if only is not None and only.lower() not in name.lower():
            continue
        jobs.extend((i, rec, m) for m in models if model_applies(m, rec))
    have_rvg = rvg_available()
    rows: list[dict[str, Any]] = []
    t_all = time.perf_counter()
    for k, (i, rec, model) in enumerate(jobs, start=1):
        row = _base_row(rec, i, model)
        head = f"[{k:{len(str(len(jobs)))}d}/{len(jobs)}] {row['record']} {model}"
        fitted, span = prepare_record(rec) if trim else (rec, None)
        row["span_s"] = span
        row["warnings"] = []
        if model == "rvg3dof" and not have_rvg:
            row["status"] = "skipped"
            row["message"] = "base rvg3dof unavailable: no rvg3dof family registered"
            say(f"{head}: skipped ({row['message']})")
            rows.append(row)
            continue
        say(f"{head} ({fitted.n} samples, {fitted.duration:.0f} s) ...")
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                result = identify_fn(
                    fitted,
                    model,
                    holdout=holdout,
                    max_effects=max_effects,
                    window_s=window_s,
                    progress=(lambda msg: say(f"      {msg}")) if detail else None,
                )
            _fill_row(row, fitted, result)
        except Exception as exc:  # one record must not stop the report
            row["status"] = "failed"
            row["message"] = f"{type(exc).__name__}: {exc}"
            row["runtime_s"] = time.perf_counter() - t0
            row["traceback"] = traceback.format_exc(limit=4)
            say(f"{head}: FAILED after {row['runtime_s']:.1f} s: {row['message']}")
            rows.append(row)
            continue
        row["warnings"] = sorted({f"{w.category.__name__}: {w.message}" for w in caught})[:10]
        if on_result is not None:
            try:
                on_result(fitted, result, row)
            except Exception as exc:  # a figure must not stop the report either
                row["warnings"].append(f"on_result failed: {type(exc).__name__}: {exc}")
                say(f"{head}: on_result failed: {exc}")
        psi_b = (row["error_before"] or {}).get("psi_rms_deg")
        psi_a = (row["error_after"] or {}).get("psi_rms_deg")
        say(
            f"{head}: done in {time.perf_counter() - t0:.1f} s; psi RMS {_fmt(psi_b)} -> "
            f"{_fmt(psi_a)} deg; effects: {', '.join(row['effect_names']) or 'none'} "
            f"(elapsed {time.perf_counter() - t_all:.0f} s)"
        )
        rows.append(row)
    return rows


def _row_key(row: Mapping[str, Any]) -> tuple[int, str, int, str]:
    source = str(row.get("source", ""))
    s = _SOURCE_ORDER.index(source) if source in _SOURCE_ORDER else len(_SOURCE_ORDER)
    model = str(row.get("model", ""))
    m = DEFAULT_MODELS.index(model) if model in DEFAULT_MODELS else len(DEFAULT_MODELS)
    return s, str(row.get("file", "")), m, model


def merge_rows(
    old: Iterable[Mapping[str, Any]], new: Iterable[Mapping[str, Any]]
) -> list[dict[str, Any]]:
    """``old`` rows updated by ``new`` ones (same ``record`` and ``model``), in report order.

    Lets a partial run (``--only``) refresh some rows of an earlier full report.
    """
    merged = {(r["record"], r["model"]): dict(r) for r in old}
    merged.update({(r["record"], r["model"]): dict(r) for r in new})
    return sorted(merged.values(), key=_row_key)


# ----------------------------------------------------------------------------------------------
# Markdown
# ----------------------------------------------------------------------------------------------
def _finite(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _fmt(v: Any, digits: int = 3) -> str:
    """A number for a table: 3 significant digits, no exponent between 1e-3 and 1e4."""
    if not _finite(v):
        return "—" if v is None else str(v)
    v = float(v)
    if v == 0.0:
        return "0"
    if 1e-3 <= abs(v) < 10 ** max(digits, 4):
        if abs(v) >= 10 ** (digits - 1):
            return f"{v:.0f}"
        return f"{v:.{digits}g}"
    return f"{v:.{digits - 1}e}"


def _arrow(before: Mapping[str, Any] | None, after: Mapping[str, Any] | None, key: str) -> str:
    b = (before or {}).get(key)
    a = (after or {}).get(key)
    if b is None and a is None:
        return "—"
    return f"{_fmt(b)} → {_fmt(a)}"


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _short(text: str | None, n: int = 90) -> str:
    text = (text or "").strip().splitlines()[0] if text else ""
    return text if len(text) <= n else text[: n - 1] + "…"


def render_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """The compact Markdown table of the README (one line per record and model).

    Columns: record, model, samples, window, heading/yaw-rate/position RMS before → after over
    the whole record, heading RMS before → after on the held-out part, effects, and the base
    ``K``, ``T`` of ``nomoto1``. Failed and skipped rows keep their line with the message.
    """
    lines = [
        "| record | model | samples | window | ψ RMS [deg] | r RMS [deg/s] | xy RMS [m] "
        "| held-out ψ RMS [deg] | effects found | K [1/s] | T [s] |",
        "|---|---|---:|---:|---|---|---|---|---|---:|---:|",
    ]
    for row in rows:
        label, model = _cell(str(row.get("label", row.get("record")))), row.get("model", "")
        if row.get("status") != "ok":
            status = str(row.get("status", "?"))
            msg = _cell(_short(row.get("message")))
            n = row.get("samples_total", "")
            lines.append(
                f"| {label} | {model} | {n} | — | — | — | — | — | **{status}**: {msg} | — | — |"
            )
            continue
        eb, ea = row.get("error_before"), row.get("error_after")
        ho = row.get("heldout") or {}
        window = row.get("window_s")
        key = row.get("key_parameters") or {}
        effects = ", ".join(row.get("effect_names") or []) or "none"
        lines.append(
            f"| {label} | {model} | {row.get('samples')} "
            f"| {'—' if window is None else _fmt(window) + ' s'} "
            f"| {_arrow(eb, ea, 'psi_rms_deg')} | {_arrow(eb, ea, 'r_rms_deg_s')} "
            f"| {_arrow(eb, ea, 'xy_rms_m')} "
            f"| {_arrow(ho.get('error_before'), ho.get('error_after'), 'psi_rms_deg')} "
            f"| {effects} | {_fmt(key.get('K'))} | {_fmt(key.get('T'))} |"
        )
    return "\n".join(lines)


_TABLE_NOTES = (
    "Before: the base model fitted to the record; after: with the effects the loop accepted. "
    "ψ, r, xy: RMS simulation error over the identified record (with a window, in consecutive "
    "windows of that length, each simulated from the measured state); held-out: the last "
    "part of the record, simulated by models fitted without it. K, T: the base first-order "
    "Nomoto fit (seed 000)."
)


def render_markdown(rows: Sequence[Mapping[str, Any]], *, doc_link: str | None = None) -> str:
    """The page block: the table (:func:`render_table`), how to read it and the links."""
    ok = sum(r.get("status") == "ok" for r in rows)
    records = len({r.get("record") for r in rows})
    parts = [
        f"{_plural(records, 'record')}, {_plural(len(rows), 'identification')} ({ok} ok). "
        f"{_TABLE_NOTES}",
        "",
        render_table(rows),
    ]
    for r in rows:
        seed, ho = r.get("error_seed001"), (r.get("heldout") or {})
        if r.get("status") == "ok" and seed:
            hs, hb, ha = (ho.get(k) or {} for k in ("error_seed001", "error_before", "error_after"))
            parts += [
                "",
                f"{r.get('label')} `{r.get('model')}` against the published seed-001 model: ψ RMS "
                f"{_fmt(seed.get('psi_rms_deg'))} deg over the record; on the held-out part "
                f"(from {_fmt(ho.get('from_s'))} s) ψ RMS {_fmt(hs.get('psi_rms_deg'))} deg with "
                f"seed 001, {_fmt(hb.get('psi_rms_deg'))} deg calibrated, "
                f"{_fmt(ha.get('psi_rms_deg'))} deg with the effects "
                f"({', '.join(r.get('effect_names') or []) or 'none'}).",
            ]
    if doc_link:
        parts += ["", f"All parameters, effects and held-out errors: [{doc_link}]({doc_link})."]
    return "\n".join(parts)


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else "s")


def _param_lines(params: Mapping[str, Any] | None) -> str:
    if not params:
        return "—"
    out = []
    for k, v in params.items():
        unit = PARAMETER_UNITS.get(k, "")
        text = f"{k} = {_fmt(v, 4)}" + (f" {unit}" if unit not in ("", "-") else "")
        if unit == "rad" and _finite(v):
            text += f" ({_fmt(math.degrees(v), 3)} deg)"
        out.append(text)
    return ", ".join(out)


def _chain(parts: Sequence[Mapping[str, Any] | None], key: str) -> str:
    values = [(d or {}).get(key) for d in parts]
    if all(v is None for v in values):
        return "—"
    return " → ".join(_fmt(v) for v in values)


def _error_table(row: Mapping[str, Any]) -> list[str]:
    """Errors per channel: whole record and held-out, ``[seed 001 →] before → after``."""
    ho = row.get("heldout") or {}
    seed = "error_seed001" in row or "error_seed001" in ho
    parts = [
        (
            "whole record",
            ([row.get("error_seed001")] if seed else [])
            + [row.get("error_before"), row.get("error_after")],
        ),
        (
            f"held-out (from {_fmt(ho.get('from_s'))} s)",
            ([ho.get("error_seed001")] if seed else [])
            + [ho.get("error_before"), ho.get("error_after")],
        ),
    ]
    present = {k for _, ds in parts for d in ds for k, v in (d or {}).items() if _finite(v)}
    keys = [(k, name) for k, name in _ERROR_COLUMNS if k in present]
    keys += [(k, k) for k in sorted(present - set(dict(_ERROR_COLUMNS)))]
    what = "seed 001 → before → after" if seed else "before → after"
    lines = [
        f"| part ({what}) | " + " | ".join(name for _, name in keys) + " |",
        "|---|" + "---|" * len(keys),
    ]
    for part, ds in parts:
        lines.append(f"| {part} | " + " | ".join(_chain(ds, k) for k, _ in keys) + " |")
    return lines


def _evidence(ev: Mapping[str, Any]) -> str:
    """``key value`` pairs of an effect's evidence; nested dicts as ``key.sub``."""
    out = []
    for k, v in ev.items():
        if isinstance(v, Mapping):
            out += [f"{k}.{kk} {_fmt(vv)}" for kk, vv in v.items() if _finite(vv)]
        elif _finite(v):
            out.append(f"{k} {_fmt(v)}")
    return ", ".join(out)


def _gunnerus_text(rows: Sequence[Mapping[str, Any]]) -> list[str]:
    lines = [
        "The R/V Gunnerus sea trials (Trondheimsfjord, 27 Oct 2022; straight runs and steady "
        "turns at several rpm, with real wind, current and waves) are identified with the RVG "
        "3-DOF model of seed 001 (`rvg3dof`, the model behind the RVG environments) and, for "
        "comparison, with the first-order Nomoto model (`nomoto1`, azimuth order as rudder, "
        "`delta = -azimuth`).",
        "",
        "* *seed 001* (`rvg3dof` only): the model with the published seed-001 parameters, "
        "driven by the recorded azimuth and rpm orders, against the record; nothing fitted.",
        "* *before*: the base model fitted to the record (`rvg3dof`: its free parameters "
        "calibrated within documented ranges, see `shipgym.sysid.families.rvg`).",
        "* *after*: the base model plus the effects the residual was traced to, each accepted "
        "only if it lowers the score on the held-out part.",
        "* *held-out*: the end of the record, which no fit saw: the models are fitted on the "
        "part before it and simulated over it. That is the test of the effects.",
    ]
    for r in rows:
        if r.get("status") != "ok":
            lines += ["", f"`{r['model']}`: **{r.get('status')}**: {r.get('message')}"]
            continue
        ho = r.get("heldout") or {}
        hs, hb, ha = (ho.get(k) or {} for k in ("error_seed001", "error_before", "error_after"))
        window = r.get("window_s")
        chain = " → ".join(
            f"{_fmt(d.get('psi_rms_deg'))} deg" for d in ([hs] if hs else []) + [hb, ha]
        )
        what = "seed 001 → before → after" if hs else "before → after"
        text = (
            f"`{r['model']}`: held-out from t = {_fmt(ho.get('from_s'))} s to the end "
            f"({_fmt(r.get('duration_s'))} s); heading RMS there ({what}) {chain}, yaw rate "
            + " → ".join(_fmt(d.get("r_rms_deg_s")) for d in ([hs] if hs else []) + [hb, ha])
            + " deg/s"
        )
        if "u_rms_m_s" in hb:
            text += ", surge " + " → ".join(
                _fmt(d.get("u_rms_m_s")) for d in ([hs] if hs else []) + [hb, ha]
            )
            text += " m/s"
        text += ". " + (
            f"All errors are over consecutive {_fmt(window)} s windows, each simulated from the "
            "measured state."
            if window
            else "Errors come from one free run."
        )
        text += f" Effects: {', '.join(r.get('effect_names') or []) or 'none'}."
        lines += ["", text]
    return lines


def render_document(
    rows: Sequence[Mapping[str, Any]],
    *,
    figures: Mapping[tuple[str, str], str] | None = None,
    summary_figure: str | None = "identification.png",
    command: str = "python scripts/identify_all.py",
    config: Mapping[str, Any] | None = None,
) -> str:
    """``docs/identification.md``: the table, the figures and one section per record.

    Parameters
    ----------
    rows : sequence of dict
        Rows of :func:`identify_all`.
    figures : mapping, optional
        ``(record, model)`` (``record`` as ``source/file``) -> figure path relative to the
        document, shown in that section.
    summary_figure : str, optional
        The :func:`plot_summary` figure, relative to the document.
    command : str
        The command that produced the document.
    config : mapping, optional
        Settings shown under the title (holdout, max_effects...).
    """
    figures = dict(figures or {})
    out = [
        "# System identification of every measured record",
        "",
        f"Produced by `{command}` (`shipgym.sysid.report`). Do not edit by hand.",
        "",
    ]
    if config:
        out += ["Settings: " + ", ".join(f"{k} = `{v}`" for k, v in config.items()) + ".", ""]
    out += [_TABLE_NOTES, "", render_table(rows), ""]
    if summary_figure:
        out += [f"![heading error before and after, every record]({summary_figure})", ""]
    by_record: dict[str, list[Mapping[str, Any]]] = {}
    for r in rows:
        by_record.setdefault(str(r.get("record")), []).append(r)
    for record, group in by_record.items():
        first = group[0]
        out += [f"## {first.get('label', record)}", ""]
        facts = [
            f"file `{first.get('file')}` ({first.get('source')})",
            f"vessel: {first.get('vessel') or 'unknown'}",
            f"manoeuvre: {first.get('manoeuvre') or 'unknown'}",
            f"{first.get('samples_total')} samples, {_fmt(first.get('duration_total_s'))} s, "
            f"dt {_fmt(first.get('dt_s'))} s",
        ]
        if first.get("span_s"):
            a, b = first["span_s"]
            facts.append(f"identified on the manoeuvre t = {_fmt(a)} ... {_fmt(b)} s")
        if first.get("repairs"):
            facts.append(
                f"{len(first['repairs'])} loader repair(s): "
                + "; ".join(_short(x, 120) for x in first["repairs"])
            )
        out += [f"* {f}" for f in facts] + [""]
        if first.get("source") == "gunnerus":
            out += [*_gunnerus_text(group), ""]
        for r in group:
            out += [f"### {r.get('model')}", ""]
            if r.get("status") != "ok":
                out += [f"**{r.get('status')}**: {r.get('message')}", ""]
                continue
            window = r.get("window_s")
            out += [
                f"{r.get('samples')} samples identified in {_fmt(r.get('runtime_s'))} s; "
                + (
                    f"whole-record errors over {_fmt(window)} s windows from the measured state."
                    if window
                    else "whole-record errors from one free run."
                ),
                "",
                *_error_table(r),
                "",
                f"* parameters before: {_param_lines(r.get('parameters_before'))}",
                f"* parameters after: {_param_lines(r.get('parameters_after'))}",
            ]
            effects = r.get("effects") or []
            if effects:
                out.append("* effects, in the order accepted:")
                for i, e in enumerate(effects, start=1):
                    evid = _evidence(e.get("evidence") or {})
                    out.append(
                        f"  {i}. `{e.get('name')}`: {_param_lines(e.get('parameters'))}"
                        + (f" (evidence: {evid})" if evid else "")
                    )
            else:
                out.append("* effects: none significant")
            if r.get("warnings"):
                out.append(f"* warnings: {'; '.join(_short(w, 120) for w in r['warnings'])}")
            out.append("")
            fig = figures.get((record, str(r.get("model"))))
            if fig:
                out += [f"![{r.get('label')} {r.get('model')}]({fig})", ""]
    return "\n".join(out).rstrip() + "\n"


# ----------------------------------------------------------------------------------------------
# Marked blocks of the documentation pages
# ----------------------------------------------------------------------------------------------
def replace_between_markers(text: str, name: str, content: str) -> str:
    """Replace what lies between ``<!-- name -->`` and ``<!-- /name -->`` with ``content``.

    The markers stay; the block becomes ``content`` on its own lines, so applying the same
    content twice gives the same text.

    Raises
    ------
    ValueError
        If a marker is missing, repeated, or the closing one comes first.
    """
    start, end = f"<!-- {name} -->", f"<!-- /{name} -->"
    for marker in (start, end):
        count = text.count(marker)
        if count != 1:
            raise ValueError(
                f"expected exactly one {marker!r} in the text, found {count}; add the pair "
                f"{start} ... {end} where the block belongs"
            )
    i, j = text.index(start), text.index(end)
    if j < i:
        raise ValueError(f"{end!r} comes before {start!r}")
    return text[: i + len(start)] + "\n" + content.strip("\n") + "\n" + text[j:]


def relative_link(target: str | Path, page: str | Path) -> str:
    """The link from the Markdown page ``page`` to ``target`` (a figure, another page).

    Relative to the page's folder, with ``/`` as the separator whatever the system, as Markdown
    and Sphinx expect: ``relative_link("docs/training.png", "docs/guide/training.md")`` is
    ``"../training.png"``.
    """
    return Path(os.path.relpath(Path(target), Path(page).parent)).as_posix()


def update_block(path: str | Path, content: str, name: str = PAGE_MARKER) -> bool:
    """Rewrite the ``name`` block of the Markdown page (the README or a documentation page) at
    ``path``; True if the file changed.

    Raises
    ------
    ValueError
        If the file lacks the markers (see :func:`replace_between_markers`).
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    try:
        new = replace_between_markers(text, name, content)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
    if new == text:
        return False
    path.write_text(new, encoding="utf-8")
    return True


def write_json(obj: Any, path: str | Path) -> Path:
    """Write ``obj`` as indented JSON (NaN and inf as null); returns the path."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(_clean(obj), indent=1) + "\n", encoding="utf-8")
    return out


def _clean(obj: Any) -> Any:
    if isinstance(obj, Mapping):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


# ----------------------------------------------------------------------------------------------
# figures
# ----------------------------------------------------------------------------------------------
def _positive(v: Any) -> float | None:
    return float(v) if _finite(v) and v > 0 else None


def plot_summary(rows: Sequence[Mapping[str, Any]], path: str | Path) -> Path:
    """Heading RMS before and after per record and model (log scale), effects annotated.

    Left: over the identified record; right: over the held-out part. Grey: base model, blue:
    with the accepted effects. Failed and skipped rows are marked in red/grey text.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    n = max(len(rows), 1)
    fig = Figure(figsize=(13.5, 1.6 + 0.26 * n), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2, sharey=True)
    y = np.arange(len(rows))[::-1]
    models_per_record: dict[Any, int] = {}
    for r in rows:
        models_per_record[r.get("record")] = models_per_record.get(r.get("record"), 0) + 1
    labels = [
        f"{r.get('label', r.get('record'))}"
        + (
            f" [{r.get('model')}]"
            if r.get("model") != "nomoto1" or models_per_record[r.get("record")] > 1
            else ""
        )
        for r in rows
    ]
    titles = ("ψ RMS over the identified record [deg]", "ψ RMS on the held-out part [deg]")
    plotted = [False, False]
    has_seed = False
    for yi, r in zip(y, rows, strict=True):
        ho = r.get("heldout") or {}
        pairs = (
            (r.get("error_before"), r.get("error_after")),
            (ho.get("error_before"), ho.get("error_after")),
        )
        seeds = (r.get("error_seed001"), ho.get("error_seed001"))
        for k, (ax, (b, a)) in enumerate(zip(axes, pairs, strict=True)):
            if r.get("status") != "ok":
                if k == 0:
                    color = "#b8312f" if r.get("status") == "failed" else "#777777"
                    ax.text(
                        0.01,
                        yi,
                        f"{r.get('status')}: {_short(r.get('message'), 70)}",
                        transform=ax.get_yaxis_transform(),
                        va="center",
                        fontsize=7,
                        color=color,
                    )
                continue
            vb = _positive((b or {}).get("psi_rms_deg"))
            va = _positive((a or {}).get("psi_rms_deg"))
            if vb is not None and va is not None:
                ax.plot([vb, va], [yi, yi], color="#9fb7d6", lw=1.5, zorder=1)
            vs = _positive((seeds[k] or {}).get("psi_rms_deg"))
            if vs is not None:
                ax.plot(vs, yi, "D", color="#d9731a", ms=5, zorder=2)
                has_seed = plotted[k] = True
            if vb is not None:
                ax.plot(vb, yi, "o", color="#8a8a8a", ms=5, zorder=2)
                plotted[k] = True
            if va is not None:
                ax.plot(va, yi, "o", color="#1f5fa8", ms=5, zorder=3)
                plotted[k] = True
        if r.get("status") == "ok":
            effects = [_EFFECT_SHORT.get(e, e) for e in r.get("effect_names") or []]
            axes[1].text(
                1.01,
                yi,
                ", ".join(effects) or "none",
                transform=axes[1].get_yaxis_transform(),
                va="center",
                fontsize=7,
                clip_on=False,
            )
    for k, ax in enumerate(axes):
        if plotted[k]:
            ax.set_xscale("log")
            ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_title(titles[k], fontsize=10)
        ax.grid(True, axis="x", which="both", alpha=0.25)
        ax.set_ylim(-0.7, len(rows) - 0.3)
    axes[0].set_yticks(y, labels, fontsize=7)
    axes[1].text(1.01, 1.0, "effects found", transform=axes[1].transAxes, fontsize=8, va="bottom")
    handles = [
        Line2D([], [], marker="o", ls="", color="#8a8a8a", label="before (base model)"),
        Line2D([], [], marker="o", ls="", color="#1f5fa8", label="after (with effects)"),
    ]
    if has_seed:
        handles.insert(
            0,
            Line2D([], [], marker="D", ls="", color="#d9731a", label="seed-001 model (not fitted)"),
        )
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=9)
    fig.suptitle("System identification of the measured records: heading error before and after")
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    return out


def plot_record(
    result: IdentificationResult, path: str | Path, title: str | None = None
) -> Path | None:
    """The per-record figure by :func:`shipgym.sysid.plots.plot_identification`.

    ``title`` is the first part of the figure title (the model, effects and errors follow).

    Returns None (nothing written) while :mod:`shipgym.sysid.plots` or its
    ``plot_identification`` does not exist.
    """
    try:
        plots = importlib.import_module("shipgym.sysid.plots")
    except ImportError:
        return None
    plot_identification = getattr(plots, "plot_identification", None)
    if plot_identification is None:
        return None
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    if title is None:
        plot_identification(result, out)
    else:
        plot_identification(result, out, title=title)
    return out


# ----------------------------------------------------------------------------------------------
# speed benchmark
# ----------------------------------------------------------------------------------------------
def _median_time(fn: Callable[[], Any], repeats: int) -> tuple[list[float], Any]:
    times, last = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        last = fn()
        times.append(time.perf_counter() - t0)
    return times, last


def benchmark_sysid(
    root: str | Path | None = None,
    *,
    repeats: int = 3,
    effect: str = "rudder_lag",
    seed: int = 0,
    duration: float = 1000.0,
    gunnerus: bool = True,
    kvlcc2: bool = True,
    progress: ProgressArg = True,
) -> dict[str, Any]:
    """Time the identification against its speed goals (:data:`BENCH_GOALS`).

    * ``fit``: :func:`shipgym.sysid.fit.fit_output_error` of ``nomoto1`` on a generated
      random-rudder record of 10 001 samples (``dt = 0.1`` s, 1000 s); median of ``repeats``;
    * ``loop``: :func:`shipgym.sysid.engine.identify` (``nomoto1``) on a generated 10 001-sample
      zigzag with the effect ``effect``; median of ``repeats``;
    * ``gunnerus``: ``identify(record, "rvg3dof")`` on the Gunnerus sea trials under ``root``;
      one run (skipped with a reason when ``root`` is None, the file is missing or
      :mod:`shipgym.sysid.families.rvg` is not registered);
    * ``hsva_regression``, ``hsva_loop`` (``kvlcc2``): the 13 HSVA KVLCC2 runs under ``root``
      together: the inverse-dynamics regression of :data:`BENCH_VMM_TERMS` (loading and
      filtering included; median of ``repeats``) and the whole identification loop of
      :data:`BENCH_VMM`, the term set chosen by the loop (one run);
    * ``replays`` (a list beside ``results``, no goal): one finite-difference Jacobian's replays
      one at a time and side by side, in at least 5 interleaved rounds, and the median of the
      same-round speed-ups (:func:`_bench_replays`).

    ``duration`` [s] sets the length of the generated records (1000 s: 10 001 samples; shorter
    only for smoke tests). Each is preceded by an untimed warm-up on a short record (Numba
    compilation). Medians, every time, the ratio ``median / goal`` and the effects found are
    returned; nothing is asserted.

    Returns
    -------
    dict
        ``config``, ``system``, ``results`` (list of ``{name, description, samples,
        goal_s, times_s, median_s, ratio, met, skipped, details}``) and ``replays`` (list of
        ``{name, samples, columns, one_at_a_time_s, side_by_side_s, speedup}``).
    """
    from shipgym.sysid.fit import fit_output_error
    from shipgym.sysid.generator import generate_record

    if not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"repeats must be an integer >= 1, got {repeats!r}")
    say = progress_printer(progress)
    results: list[dict[str, Any]] = []
    t_start = time.perf_counter()

    def add(name: str, description: str, samples: int | None, times: list[float], **details: Any):
        med = statistics.median(times) if times else None
        goal = BENCH_GOALS[name]
        res = {
            "name": name,
            "description": description,
            "samples": samples,
            "goal_s": goal,
            "times_s": times,
            "median_s": med,
            "ratio": None if med is None else med / goal,
            "met": None if med is None else bool(med <= goal),
            "skipped": details.pop("skipped", None),
            "details": details,
        }
        results.append(res)
        if med is None:
            say(f"{name:9s} skipped: {res['skipped']}")
        else:
            say(
                f"{name:9s} {med:8.3f} s (median of {len(times)}; goal {goal:g} s; ratio "
                f"{med / goal:.3f}; {'met' if res['met'] else 'MISSED'}) {description}"
            )

    def fit(rec: Record) -> Any:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return fit_output_error(rec.time, rec.delta, rec.psi, rec.r, "nomoto1")

    def loop(rec: Record, base: str = "nomoto1") -> IdentificationResult:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return identify(rec, base)

    # 1. output-error fit
    say("fit: warm-up ...")
    warm = min(100.0, duration)
    fit(generate_record(None, maneuver="random", dt=0.1, duration=warm, seed=seed))
    rec = generate_record(None, maneuver="random", dt=0.1, duration=duration, seed=seed)
    times, f = _median_time(lambda: fit(rec), max(repeats, 3))
    add(
        "fit",
        "nomoto1 output-error fit (generated, random rudder)",
        rec.n,
        times,
        K=f.values.get("K"),
        T=f.values.get("T"),
    )

    # 2. whole loop with an effect
    say("loop: warm-up ...")
    loop(generate_record(effect, dt=0.1, duration=min(200.0, duration), seed=seed))
    rec = generate_record(effect, dt=0.1, duration=duration, seed=seed)
    say(f"loop: identify on {rec.n} samples with effect {effect} ({repeats} runs) ...")
    times, res = _median_time(lambda: loop(rec), repeats)
    add(
        "loop",
        f"identify loop, nomoto1 (generated zigzag + {effect})",
        rec.n,
        times,
        effect=effect,
        effects_found=res.effect_names,
    )

    # 3. the Gunnerus record with rvg3dof
    desc = "identify, rvg3dof (Gunnerus sea trials)"
    path = None if root is None else Path(root) / "gunnerus_seatrials" / "RVG_ManeuveringTests.csv"
    if not gunnerus:
        add("gunnerus", desc, None, [], skipped="not requested")
    elif path is None:
        add("gunnerus", desc, None, [], skipped="no measured-data root given")
    elif not path.is_file():
        add("gunnerus", desc, None, [], skipped=f"Gunnerus record not found ({path})")
    elif not rvg_available():
        add("gunnerus", desc, None, [], skipped="no rvg3dof family registered")
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rec = load(path, "gunnerus")
        say("gunnerus: warm-up on the first 900 s ...")
        try:
            loop(rec.slice(rec.time[0], rec.time[0] + 900.0), "rvg3dof")
        except Exception as exc:  # the warm-up only compiles; report and go on
            say(f"gunnerus: warm-up failed ({type(exc).__name__}: {exc})")
        say(f"gunnerus: identify rvg3dof on {rec.n} samples (one run) ...")
        try:
            times, res = _median_time(lambda: loop(rec, "rvg3dof"), 1)
            add("gunnerus", desc, rec.n, times, effects_found=res.effect_names)
        except Exception as exc:
            add("gunnerus", desc, rec.n, [], skipped=f"failed: {type(exc).__name__}: {exc}")

    # 4. the 3-DOF model on the 13 HSVA runs together
    folder = None if root is None else Path(root) / "hsva_kvlcc2"
    descs = {
        "hsva_regression": f"vmm:{BENCH_VMM_TERMS} regression, 13 HSVA KVLCC2 runs",
        "hsva_loop": f"identify loop, {BENCH_VMM}, 13 HSVA KVLCC2 runs",
    }
    if not kvlcc2:
        for name, desc in descs.items():
            add(name, desc, None, [], skipped="not requested")
    elif folder is None or not sorted(folder.glob("*.dat")):
        for name, desc in descs.items():
            add(name, desc, None, [], skipped=f"HSVA records not found ({folder})")
    else:
        for name, n, times, details in _bench_hsva(folder, repeats, say):
            add(name, descs[name], n, times, **details)

    # 5. a Jacobian's replays one at a time and side by side, in interleaved rounds
    replays = _bench_replays(
        None if path is None or not path.is_file() else path, duration, seed, max(repeats, 5), say
    )

    return {
        "replays": replays,
        "config": {
            "repeats": repeats,
            "effect": effect,
            "seed": seed,
            "duration_s": duration,
            "dt_s": 0.1,
            "goals_s": BENCH_GOALS,
            "statistic": "median after an untimed warm-up",
        },
        "system": _system(time.perf_counter() - t_start),
        "results": results,
    }


def _bench_hsva(
    folder: Path, repeats: int, say: Callable[[str], None]
) -> list[tuple[str, int, list[float], dict[str, Any]]]:
    """The HSVA timings of :func:`benchmark_sysid`: ``(name, samples, times, details)``."""
    from shipgym.models.vmm import TERM_SETS
    from shipgym.sysid.families import vmm as fv

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hsva = [load(p, "hsva") for p in sorted(folder.glob("*.dat"))]
    n = sum(r.n for r in hsva)
    template = fv.vessel_params(hsva[0])
    terms = TERM_SETS[BENCH_VMM_TERMS]
    say("hsva: warm-up on two runs ...")
    identify(hsva[:2], BENCH_VMM, max_effects=0)
    reg_times, _ = _median_time(
        lambda: fv.regress(fv.prepare_runs(hsva, template), template, terms), max(repeats, 3)
    )
    say(f"hsva_loop: identify {BENCH_VMM} on {n} samples (one run) ...")
    loop_times, res = _median_time(lambda: identify(hsva, BENCH_VMM), 1)
    return [
        ("hsva_regression", n, reg_times, {}),
        ("hsva_loop", n, loop_times, {"effects_found": res.effect_names}),
    ]


def _bench_replays(
    gunnerus: Path | None, duration: float, seed: int, rounds: int, say: Callable[[str], None]
) -> list[dict[str, Any]]:
    """The replays of one finite-difference Jacobian (one per free parameter), one at a time and
    side by side as the ships of one block (:mod:`shipgym.sysid.batched`), timed in
    ``rounds`` interleaved rounds: ``nomoto1`` on a generated random-rudder record (4 columns)
    and ``rvg3dof`` window by window on the Gunnerus sea trials (a generated record without
    them; 8 columns, the base fit's 6 and two effects). The speed-up is the median over the
    rounds of the ratio of the two times measured in the same round."""
    from shipgym.models import RVGParams
    from shipgym.models.integrate import NOMOTO1
    from shipgym.models.rvg import pack_rvg
    from shipgym.sysid import fit as nf
    from shipgym.sysid.families import rvg as fr
    from shipgym.sysid.generator import generate_record

    rec = generate_record(None, maneuver="random", dt=0.1, duration=duration, seed=seed)
    h, n_cmd = nf._replay_steps(rec.time, np.ones_like(rec.time))
    speed = np.ones_like(rec.time)
    p0 = nf.pack_nomoto(nf.Nomoto1Params(), nf._REPLAY_GEAR, nf._REPLAY_SURGE)
    x0 = np.zeros(6)

    def nomoto(ps: list[np.ndarray]) -> Any:
        return nf._replay_kernel(
            NOMOTO1, [x0] * len(ps), rec.delta, [0.0] * len(ps), speed, n_cmd, h, ps, rec.n
        )

    if gunnerus is not None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rvg_rec = load(gunnerus, "gunnerus")
        rvg_name = "rvg3dof, Gunnerus sea trials"
    else:
        rvg_rec = generate_record(None, dt=0.5, duration=duration, seed=seed, base_model="rvg3dof")
        rvg_name = "rvg3dof, generated record"
    starts = window_starts(rvg_rec.time, fr.RVG_WINDOW_S)
    args = (rvg_rec.time, fr.start_states(rvg_rec), rvg_rec.rpm, fr.azimuth_orders(rvg_rec), starts)
    q0 = pack_rvg(RVGParams())

    def rvg(ps: list[np.ndarray]) -> Any:
        k = len(ps)
        return fr._replay(*args, ps, [(0.0, 0.0)] * k, [0.0] * k, [0.0] * k)

    cases = [
        ("nomoto1, generated random rudder", rec.n, nomoto, p0, 4),
        (rvg_name, rvg_rec.n, rvg, q0, 8),
    ]
    out = []
    for name, samples, replay, base, columns in cases:
        # the variants a Jacobian replays: each parameter in turn nudged by a relative 1e-8
        variants = []
        for i in range(columns):
            q = base.copy()
            q[-1 - i] *= 1.0 + 1e-8
            variants.append(q)
        replay(variants[:1])  # compile
        replay(variants)
        one, side = [], []
        for r in range(rounds):
            t0 = time.perf_counter()
            for q in variants:
                replay([q])
            t1 = time.perf_counter()
            replay(variants)
            t2 = time.perf_counter()
            one.append(t1 - t0)
            side.append(t2 - t1)
            say(f"replays {name}: round {r + 1}/{rounds}: {(t1 - t0) / (t2 - t1):.2f} x")
        speedup = statistics.median(a / b for a, b in zip(one, side, strict=True))
        out.append({
            "name": name, "samples": samples, "columns": columns, "one_at_a_time_s": one,
            "side_by_side_s": side, "speedup": speedup,
        })  # fmt: skip
    return out


def _system(elapsed: float) -> dict[str, Any]:
    import scipy

    import shipgym

    try:
        import numba

        numba_version = str(numba.__version__)
    except ImportError:  # pragma: no cover - numba is a dependency
        numba_version = "n/a"
    return {
        "shipgym": shipgym.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba_version,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "elapsed_s": round(elapsed, 2),
    }


def format_benchmark(report: Mapping[str, Any]) -> str:
    """The benchmark as a Markdown table (median, goal, ratio, met)."""
    lines = [
        "| measurement | samples | median [s] | runs | goal [s] | ratio | result |",
        "|---|---:|---:|---:|---:|---:|---|",
    ]
    for r in report["results"]:
        if r["median_s"] is None:
            lines.append(
                f"| {r['description']} | — | — | 0 | {r['goal_s']:g} | — | "
                f"skipped: {_cell(str(r['skipped']))} |"
            )
            continue
        lines.append(
            f"| {r['description']} | {r['samples']} | {r['median_s']:.3f} | {len(r['times_s'])} "
            f"| {r['goal_s']:g} | {r['ratio']:.3f} | {'met' if r['met'] else 'missed'} |"
        )
    if report.get("replays"):
        lines += [
            "",
            "| a Jacobian's replays | samples | columns | one at a time [s] | side by side [s] "
            "| speed-up |",
            "|---|---:|---:|---:|---:|---:|",
        ]
        for r in report["replays"]:
            lines.append(
                f"| {r['name']} | {r['samples']} | {r['columns']} | "
                f"{statistics.median(r['one_at_a_time_s']):.3f} | "
                f"{statistics.median(r['side_by_side_s']):.3f} | {r['speedup']:.2f} x |"
            )
    return "\n".join(lines)


def _plot_replays(ax: Any, replays: list[dict[str, Any]]) -> None:
    """Speed-up of a Jacobian's replays side by side over one at a time, one bar per model."""
    y = np.arange(len(replays))[::-1]
    for yi, r in zip(y, replays, strict=True):
        ax.barh(yi, r["speedup"], height=0.55, color="#3b6ea8", zorder=2)
        ax.annotate(
            f"{r['speedup']:.2f} x ({r['columns']} replays of {r['samples']} samples)",
            xy=(r["speedup"], yi), xytext=(4, 0), textcoords="offset points", va="center",
            fontsize=9,
        )  # fmt: skip
    ax.axvline(1.0, color="black", ls="--", lw=1.2)
    ax.set_yticks(y, [r["name"] for r in replays], fontsize=8)
    ax.set_xlim(0.0, max(r["speedup"] for r in replays) * 1.6)
    ax.set_xlabel("speed-up of a Jacobian's replays side by side (median of same-round ratios)")
    ax.grid(True, axis="x", alpha=0.25)


def plot_benchmark(report: Mapping[str, Any], path: str | Path) -> Path:
    """Bar chart: median time of each measurement against its goal (log scale)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter

    rows = list(report["results"])
    replays = list(report.get("replays") or [])
    fig = Figure(
        figsize=(10, 1.6 + 0.9 * len(rows) + (1.4 + 0.6 * len(replays) if replays else 0.0)),
        dpi=110,
        layout="constrained",
    )
    FigureCanvasAgg(fig)
    if replays:
        ax, ax_r = fig.subplots(
            2, 1, height_ratios=[0.9 * len(rows) + 1.0, 0.6 * len(replays) + 0.8]
        )
        _plot_replays(ax_r, replays)
    else:
        ax = fig.subplots()
    y = np.arange(len(rows))[::-1]
    for yi, r in zip(y, rows, strict=True):
        goal = r["goal_s"]
        ax.vlines(goal, yi - 0.4, yi + 0.4, colors="black", linestyles="--", lw=1.5, zorder=3)
        if r["median_s"] is None:
            ax.text(
                goal, yi, f"  skipped: {_short(str(r['skipped']), 60)}", va="center", fontsize=8
            )
            continue
        color = "#2a8a4a" if r["met"] else "#b8312f"
        ax.barh(yi, r["median_s"], height=0.55, color=color, zorder=2)
        ax.annotate(
            f"{r['median_s']:.3g} s = {r['ratio']:.2f} x goal",
            xy=(r["median_s"], yi),
            xytext=(4, 0),
            textcoords="offset points",
            va="center",
            fontsize=9,
            zorder=4,
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
        )
    ax.set_xscale("log")
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    values = [r["median_s"] for r in rows if r["median_s"]] + [r["goal_s"] for r in rows]
    ax.set_xlim(min(values) / 3, max(values) * 8)
    names = [f"{r['description']}\n{r['samples'] or '—'} samples" for r in rows]
    ax.set_yticks(y, names, fontsize=8)
    ax.set_xlabel("wall time [s] (median)")
    ax.grid(True, axis="x", which="both", alpha=0.25)
    handles = [
        Line2D([], [], color="#2a8a4a", lw=8, label="meets goal"),
        Line2D([], [], color="#b8312f", lw=8, label="misses goal"),
        Line2D([], [], color="black", ls="--", lw=1.5, label="goal"),
    ]
    ax.legend(handles=handles, loc="lower right", fontsize=8)
    sysinfo = report.get("system", {})
    ax.set_title(
        f"shipgym.sysid speed ({sysinfo.get('cpu_count', '?')} CPUs, numba "
        f"{sysinfo.get('numba', '?')})",
        fontsize=10,
    )
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    return out

"""``shipgym identify``: fit a vessel model to a measured record and trace the residual."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from shipgym.cli._common import finite_float, float_in, int_in, output_path, write_outputs


def _window(text: str) -> float | str | None:
    """``--window``: a positive number of seconds, ``auto`` or ``none``."""
    word = text.strip().lower()
    if word in ("auto", "none"):
        return None if word == "none" else "auto"
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 1.0 <= value <= 1e6):
        raise argparse.ArgumentTypeError(
            f"must be a number of seconds in [1, 1e6], 'auto' or 'none', got {text!r}"
        )
    return value


def _format_value(name: str, value: Any, digits: int = 6, unit: bool = False) -> str:
    """``value`` with ``digits`` significant digits; angles [rad] also in degrees.

    ``unit``: append the unit of :data:`shipgym.sysid.units.PARAMETER_UNITS` (before the
    degrees).
    """
    from shipgym.sysid.units import PARAMETER_UNITS

    if value is None:
        return "n/a"
    if isinstance(value, bool) or not isinstance(value, int | float):
        return str(value)
    text = f"{value:.{digits}g}"
    known = PARAMETER_UNITS.get(name)
    if unit and known:
        text += f" {known}"
    if known == "rad" and math.isfinite(value):
        text += f" ({math.degrees(value):.4g} deg)"
    return text


def _param_label(name: str) -> str:
    from shipgym.sysid.units import PARAMETER_UNITS

    unit = PARAMETER_UNITS.get(name)
    return f"{name} [{unit}]" if unit else name


# record channel -> (unit shown, scale from SI) for per-channel evidence dicts
_CHANNEL_UNITS: dict[str, tuple[str, float]] = {
    "psi": ("deg", math.degrees(1.0)),
    "r": ("deg/s", math.degrees(1.0)),
    "u": ("m/s", 1.0),
    "v": ("m/s", 1.0),
    "x": ("m", 1.0),
    "y": ("m", 1.0),
}


def _format_pair(stem: str, before: Any, after: Any) -> str:
    """``"held-out psi RMS 3.701 -> 0.1023 deg"``; per-channel dicts give one item each."""
    from shipgym.sysid.plots import METRIC_LABELS

    where = "held-out " if stem.startswith("heldout_") else ""
    metric = stem.removeprefix("heldout_")
    if isinstance(before, dict) and isinstance(after, dict):  # {channel: value [SI]}
        items = []
        for ch in [*before, *(k for k in after if k not in before)]:
            unit, scale = _CHANNEL_UNITS.get(ch, ("", 1.0))
            b, a = before.get(ch), after.get(ch)
            b = b * scale if isinstance(b, int | float) else b
            a = a * scale if isinstance(a, int | float) else a
            items.append(
                f"{ch} {_format_value(ch, b, 4)} -> {_format_value(ch, a, 4)} {unit}".rstrip()
            )
        return f"{where}{metric.replace('_', ' ')}: " + ", ".join(items)
    label, unit = METRIC_LABELS.get(metric, (metric, ""))
    return (
        f"{where}{label} {_format_value(metric, before, 4)} -> "
        f"{_format_value(metric, after, 4)} {unit}".rstrip()
    )


def _format_evidence(evidence: dict[str, Any]) -> str:
    """One line per effect: BIC change, held-out metrics before -> after, other numbers."""
    parts = []
    done = set()
    if isinstance(evidence.get("delta_J"), int | float):
        parts.append(f"BIC change {evidence['delta_J']:+.1f}")
        done.add("delta_J")
    if isinstance(evidence.get("relative_drop"), int | float):
        parts.append(f"held-out RMS drop {100.0 * evidence['relative_drop']:.1f} %")
        done.add("relative_drop")
    for key in evidence:
        stem = key.removesuffix("_before")
        if key in done or stem == key or stem + "_after" not in evidence:
            continue
        parts.append(_format_pair(stem, evidence[key], evidence[stem + "_after"]))
        done |= {key, stem + "_after"}
    names = {"t_stat": "drift t statistic"}
    for key, value in evidence.items():
        if key not in done:
            parts.append(f"{names.get(key, key)} {_format_value(key, value, 4, unit=True)}")
    return "; ".join(parts)


def _identify_summary(result: Any, source: str) -> str:
    """The readable report of ``shipgym identify`` (the JSON holds the same numbers)."""
    from shipgym.sysid.plots import METRIC_LABELS, format_errors

    lines = [f"shipgym identify {source}", f"model: {result.model}"]
    selection = result.diagnostics.get("term_set_selection")
    if selection:  # vmm:auto: the term set kept and why
        from shipgym.sysid.families.vmm import describe_selection

        lines.append(f"term set: {describe_selection(selection)}")
    verdict = result.verdict
    if verdict.identifiable:
        lines.append("verdict: identifiable")
    else:
        lines.append("verdict: NOT IDENTIFIABLE: the record does not determine this model:")
        lines.extend(f"  - {reason}" for reason in verdict.reasons)
    starts = result.traces.get("window_starts", [0]) if result.traces else [0]
    if "run" in (result.traces or {}):
        how = "each run simulated from its measured initial state"
        if result.window_s is not None:
            how += f", in windows of {result.window_s:g} s"
    elif result.window_s is None:
        how = "one free run from the estimated initial state"
    else:
        how = (
            f"{len(starts)} consecutive windows of {result.window_s:g} s, each started from the "
            "measured state"
        )
    lines.append(f"window: {'none' if result.window_s is None else f'{result.window_s:g} s'}")
    lines.append(f"simulation error over the whole record ({how}):")
    before, after = result.error_before, result.error_after
    keys = [*before, *(k for k in after if k not in before)]
    rows = [("", "before", "after")]
    for key in keys:
        label, unit = METRIC_LABELS.get(key, (key, ""))
        rows.append(
            (
                f"{label} [{unit}]" if unit else label,
                _format_value(key, before.get(key), 4),
                _format_value(key, after.get(key), 4),
            )
        )
    lines.extend(_table(rows))
    if result.effects:
        lines.append("effects added, in order:")
        for i, effect in enumerate(result.effects, start=1):
            params = ", ".join(
                f"{k} = {_format_value(k, v, unit=True)}"
                for k, v in effect.get("parameters", {}).items()
            )
            lines.append(f"  {i}. {effect['name']}: {params}")
            evidence = dict(effect.get("evidence", {}))
            candidate = evidence.pop("candidate_parameters", None)
            lines.append(f"     evidence: {_format_evidence(evidence)}")
            if candidate and candidate != effect.get("parameters"):
                text = ", ".join(
                    f"{k} = {_format_value(k, v, 4, unit=True)}" for k, v in candidate.items()
                )
                lines.append(f"     candidate when accepted (fit on the training part): {text}")
    else:
        lines.append("effects added: none (no candidate was significant on the held-out part)")
    p_before, p_after = result.parameters_before, result.parameters_after
    stderr = ((result.diagnostics or {}).get("final") or {}).get("stderr") or {}
    lines.append("parameters:")
    rows = [("", "before", "after", "std. error")]
    for name in [*p_before, *(k for k in p_after if k not in p_before)]:
        se = stderr.get(name)
        rows.append(
            (
                _param_label(name),
                _format_value(name, p_before[name]) if name in p_before else "-",
                _format_value(name, p_after[name]) if name in p_after else "-",
                _format_value(name, se, 2) if isinstance(se, float) and math.isfinite(se) else "-",
            )
        )
    lines.extend(_table(rows))
    held = result.heldout or {}
    if held.get("error_before") is not None and held.get("error_after") is not None:
        where = (
            f"runs {', '.join(held['runs'])}"
            if "runs" in held
            else f"part from {held.get('from_s', math.nan):.1f} s"
        )
        lines.append(
            f"held-out {where} (models fitted on the rest): "
            f"{format_errors(held['error_before'], held['error_after'])}"
        )
        own = held.get("record_consistency")
        if own:
            track = f", its track by {own['xy_rms_m']:.3g} m" if "xy_rms_m" in own else ""
            lines.append(
                "  the record itself there: its yaw rate and velocities, integrated from each "
                f"window's start, miss its heading by {own['psi_rms_deg']:.3g} deg{track} (a "
                "model's heading error and its integrated yaw-rate error add up to at least "
                "this)"
            )
    final = (result.diagnostics or {}).get("final", {})
    if final.get("collinear"):
        lines.append("terms left out as collinear (pivoted QR), with the terms they follow:")
        lines.extend(f"  {k}: {', '.join(v)}" for k, v in final["collinear"].items())
    if final.get("per_run"):
        lines.append("error of the final model per run:")
        rows = [("run", "psi [deg]", "r [deg/s]", "u [m/s]", "v [m/s]")]
        keys = ("psi_rms_deg", "r_rms_deg_s", "u_rms_m_s", "v_rms_m_s")
        for run, e in final["per_run"].items():
            rows.append((run, *(f"{e[k]:.3g}" for k in keys)))
        lines.extend(_table(rows))
    for key, errors in held.items():  # further reference errors, e.g. of published parameters
        if key.startswith("error_") and key not in ("error_before", "error_after"):
            if isinstance(errors, dict):
                text = ", ".join(
                    f"{METRIC_LABELS.get(k, (k, ''))[0]} {_format_value(k, v, 4)} "
                    f"{METRIC_LABELS.get(k, (k, ''))[1]}".rstrip()
                    for k, v in errors.items()
                )
                lines.append(f"  held-out error of {key.removeprefix('error_')}: {text}")
    lines.append(f"runtime: {result.runtime_s:.1f} s")
    return "\n".join(lines)


def _table(rows: Sequence[tuple[str, ...]], indent: str = "  ") -> list[str]:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    out = []
    for r in rows:
        first = r[0].ljust(widths[0])
        rest = [c.rjust(w) for c, w in zip(r[1:], widths[1:], strict=True)]
        out.append((indent + "  ".join([first, *rest])).rstrip())
    return out


def _load_for_identify(
    path_text: str,
    fmt: str | None,
    note: Callable[[str], None],
    quiet: bool = False,
    columns: str | None = None,
    max_gap_s: float | None = None,
) -> Any:
    """Load the record; repairs (:class:`SysidDataWarning`) and other warnings become notes.

    Progress lines of a large file go to stderr unless ``quiet``."""
    import warnings

    from shipgym.sysid.data import FORMATS, detect_format, load

    path = Path(path_text)
    if not path.exists():
        raise ValueError(
            f"record file {path_text!r} does not exist (expected a measured-data file in one of "
            f"the formats {', '.join(FORMATS)}, or a dataset name: shipgym data list)"
        )
    if not path.is_file():
        raise ValueError(f"{path_text!r} is not a file (expected a measured-data record file)")
    if columns is not None:
        if fmt not in (None, "table"):
            raise ValueError(f"--columns goes with --format table, not --format {fmt}")
        fmt = "table"
    if fmt is None:
        try:
            fmt = detect_format(path)
        except ValueError as exc:
            raise ValueError(
                f"{str(exc).removesuffix(' (pass format=...)')}; pass --format"
            ) from None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        record = load(
            path,
            fmt,
            progress=False if quiet else None,
            columns=columns,
            max_gap_s=max_gap_s,
        )
    messages = [str(w.message) for w in caught]
    for msg in messages:
        note(msg)
    if fmt == "canonical":  # repairs made before the record was written are not re-warned
        for repair in record.meta.get("repairs", []):
            if not any(str(repair) in msg for msg in messages):
                note(f"repaired before it was written: {repair}")
    return record, fmt


def run(args: argparse.Namespace) -> int:
    import json
    import time
    import warnings

    import numpy as np

    from shipgym.datasets import expand_records
    from shipgym.models.vmm import VMMParams, parse_particulars
    from shipgym.sysid import identify
    from shipgym.sysid.fit import SysidWarning

    json_path = output_path(args.json, "--json")
    plot_path = output_path(args.plot, "--plot", ".png")
    report = sys.stderr if args.json == "-" else sys.stdout
    t0 = time.perf_counter()

    def note(msg: str) -> None:
        print(f"note: {msg}", file=sys.stderr, flush=True)

    def progress(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:6.1f} s] {msg}", file=sys.stderr, flush=True)

    say = (lambda _msg: None) if args.quiet else progress
    args.path = expand_records(args.path)  # dataset names -> their files
    given = None if args.particulars is None else parse_particulars(args.particulars)
    records, sources = [], []
    for path_text in args.path:
        say(f"loading {path_text} ...")
        record, fmt = _load_for_identify(
            path_text, args.format, note, args.quiet, args.columns, args.max_gap
        )
        chans = " ".join(k for k in record.channels() if k != "time")
        sources.append(
            f"{path_text} ({fmt}, {record.n} samples, {record.duration:g} s at dt "
            f"{record.dt:g} s; channels {chans})"
        )
        say(f"loaded {sources[-1]}")
        if args.length is not None:
            record.meta["L"] = args.length
        records.append(record)
    particulars = None
    if given is not None:
        if "approach_speed" not in given:  # the runs' median speed
            speeds = [r.U if r.U is not None else np.hypot(r.u, r.v) for r in records
                      if r.U is not None or (r.u is not None and r.v is not None)]  # fmt: skip
            if speeds:
                given["approach_speed"] = float(np.median(np.concatenate(speeds)))
        try:
            particulars = VMMParams.from_particulars(**given)
        except ValueError as exc:
            raise ValueError(f"--particulars: {exc}") from None
    source = sources[0] if len(sources) == 1 else f"{len(sources)} runs:\n  " + "\n  ".join(sources)
    inputs = {Path(p).resolve() for p in args.path}
    for out_path in (json_path, plot_path):
        if out_path is not None and out_path.resolve() in inputs:
            raise ValueError(f"output {str(out_path)!r} is one of the input records; refusing")
    window = {None: "none", "auto": "auto"}.get(args.window) or f"{args.window:g} s"
    say(
        f"identifying base {args.model} (holdout {args.holdout:g}, at most {args.max_effects} "
        f"effects, window {window}) ..."
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SysidWarning)
        try:
            result = identify(
                records if len(records) > 1 else records[0],
                args.model,
                holdout=args.holdout,
                max_effects=args.max_effects,
                window_s=args.window,
                progress=None if args.quiet else progress,
                particulars=particulars,
            )
        except ValueError as exc:
            raise ValueError(
                f"cannot identify {args.model} from {', '.join(args.path)}: {exc}"
            ) from exc
    for msg in dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught):
        note(msg)
    say(f"done in {result.runtime_s:.1f} s")
    if not result.verdict.identifiable:  # a flagged fit: the warning first, then the report
        print(
            f"warning: not identifiable: {'; '.join(result.verdict.reasons)} (the result is "
            "reported with this verdict; shipgym design refuses it)",
            file=sys.stderr,
            flush=True,
        )

    print(_identify_summary(result, source), file=report, flush=True)
    document = result.to_dict()
    text = json.dumps(document, indent=2, allow_nan=False) + "\n"
    outputs: list[tuple[Path, Callable[[Path], Any]]] = []
    if json_path is not None:
        outputs.append((json_path, lambda p: p.write_text(text, encoding="utf-8")))
    if plot_path is not None:
        from shipgym.sysid.plots import plot_identification

        outputs.append((plot_path, lambda p: plot_identification(result, p)))
    write_outputs(outputs, report)
    if args.json == "-":
        sys.stdout.write(text)
        sys.stdout.flush()
    return 0


def build(sub: Any) -> None:
    from shipgym.sysid.data import FORMATS
    from shipgym.sysid.families import FAMILIES

    p = sub.add_parser(
        "identify",
        help="fit a model to a measured record and add the effects its residual points to",
        description=(
            "Load a manoeuvre record (any of the measured-data formats or the canonical CSV), "
            "fit the base model by output error, then add effects of the catalogue (rudder "
            "offset, yaw nonlinearity, rudder lag, input delay, current, second order; for "
            "rvg3dof and the 3-DOF models their own catalogues) one at a time while the BIC on "
            "the held-out end of the record improves. The 3-DOF models (vmm:<term set>, seed "
            "003's general model; kvlcc2, the MMG model with refined hull derivatives) take "
            "several runs of one ship and hold every few runs out instead. Prints the "
            "simulation errors before and after (heading, yaw rate, and position / speed where "
            "recorded), the effects with their parameters and "
            "evidence, and the parameters. Progress and data-repair notes go to stderr. "
            "A record that cannot determine any model is refused with exit code 2 ('not "
            "identifiable: no excitation: ...': the rudder never moves, or is held for the "
            "whole record while the ship is already turning, or the heading never changes). "
            "A fit the record does not determine (a needed parameter without a standard error "
            "or with one larger than its estimate, a parameter at its bound, K <= 0, a time "
            "constant far beyond the record, an ill-conditioned regression) is reported with "
            'a warning first and \'verdict: {"identifiable": false, "reasons": [...]}\' '
            "in its JSON, which shipgym design refuses."
        ),
    )
    p.add_argument(
        "path",
        metavar="PATH",
        nargs="+",
        help="record file, or a dataset name (all its runs) or NAME/PATTERN (shipgym data list; "
        "e.g. marin-kvlcc2/MARIN_*zz*); several runs of one ship for the 3-DOF models "
        "vmm:<term set> (fitted on some runs, scored on the others)",
    )
    p.add_argument(
        "--format",
        default=None,
        choices=FORMATS,
        help="file format (default: detected from the header and the file name; 'table' is "
        "any delimited file whose headers state their units, 'nmea' an NMEA 0183 log)",
    )
    p.add_argument(
        "--columns",
        default=None,
        metavar="MAP",
        help="column map of your own table, e.g. 'time=t,delta=-rudder:deg,psi=hdg:deg,"
        "r=rot:deg/min,U=sog:kn' (channel=[-]column:unit; '-' negates a port-positive rudder "
        "or a counter-clockwise heading; channels time, delta, psi, r, U, u, v, x, y, lat, "
        "lon, rpm)",
    )
    p.add_argument(
        "--length",
        type=float_in(0.1, 1000.0, "m"),
        default=None,
        metavar="L",
        help="the ship's length [m], kept in the model file (the envs' option ranges and the "
        "IMO ratios of 'shipgym simulate --model FIT.json' use it); default: the record's",
    )
    p.add_argument(
        "--particulars",
        default=None,
        metavar="KEY=VALUE,...",
        help="the ship of the 3-DOF models (vmm:<term set>) by its main particulars, SI units: "
        "'length=7.0,breadth=1.27,draught=0.46,displacement=3.27,x_g=0.25,"
        "propeller_diameter=0.216' (displacement in m^3, or mass= in kg; optional rho= "
        "(1025), yaw_radius= (0.25 L), block_coefficient= (from the displacement), "
        "approach_speed= (the runs' median speed)); builds the mass, inertia and Clarke's "
        "added masses. Default: the records' own (meta lines such as '# L: 7.0', '# draft: "
        "0.46')",
    )
    p.add_argument(
        "--max-gap",
        type=float_in(1e-6, 1e6, "s"),
        default=None,
        metavar="S",
        help="table and nmea: a longer time step splits the record into segments (default: "
        "5 median steps)",
    )
    p.add_argument(
        "--model",
        default="nomoto1",
        choices=tuple(FAMILIES),
        help="the model family to fit: its base model, to which the loop adds effects "
        "(default: %(default)s)",
    )
    p.add_argument(
        "--json",
        default=None,
        metavar="OUT",
        help="write the result as JSON ('-': to stdout, the summary then goes to stderr)",
    )
    p.add_argument(
        "--plot",
        default=None,
        metavar="OUT.png",
        help="write measured vs before vs after and the residuals as a PNG",
    )
    p.add_argument(
        "--window",
        type=_window,
        default="auto",
        metavar="S|auto|none",
        help="score the errors over consecutive windows of S seconds, each started from the "
        "measured state; 'none': one free run; 'auto' (default): windows for long records",
    )
    p.add_argument(
        "--holdout",
        type=finite_float,
        default=0.3,
        metavar="FRAC",
        help="fraction kept out of the fits for scoring: the end of one record, or of several "
        "runs that many, each a manoeuvre of a kind a training run also makes "
        "(default: %(default)s)",
    )
    p.add_argument(
        "--max-effects",
        type=int_in(0, 10),
        default=3,
        metavar="N",
        help="largest number of effects to add (default: %(default)s)",
    )
    p.add_argument(
        "--quiet",
        action="store_true",
        help="no progress lines (notes, errors and the summary are still printed)",
    )
    p.set_defaults(handler=run)

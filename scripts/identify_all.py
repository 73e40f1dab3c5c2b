"""Identify every measured record; JSON, Markdown report, figures and the results page's table.

Usage::

    python scripts/identify_all.py [--root DIR] [--only SUBSTRING]
                                   [--out docs] [--page docs/results/identification.md | --no-page]
                                   [--models nomoto1,rvg3dof,vmm:martin_simple] [--fresh]
                                   [--render-only] [-v]

Runs :func:`shipgym.sysid.report.identify_all` (``nomoto1`` on every record, ``rvg3dof`` also on
the Gunnerus sea trials, the 3-DOF ``vmm:martin_simple`` on every KVLCC2 and Esso Osaka record,
each run alone: fitted on its first 70 %) with a progress line per record on stderr, then writes

* ``OUT/identification.json``: the rows (errors before/after, held-out errors, effects,
  parameters, runtimes; failures with their message);
* ``OUT/identification.md``: the table and one section per record;
* ``OUT/identification.png``: heading RMS before/after per record (log scale), effects
  annotated; ``OUT/identification_sspa.png`` and ``OUT/identification_gunnerus.png`` from
  :func:`shipgym.sysid.plots.plot_identification` (when that module exists);
* the block between ``<!-- identification -->`` and ``<!-- /identification -->`` of the results
  page ``docs/results/identification.md``, which includes ``OUT/identification.md`` below it.

With ``--only`` the new rows replace the same (record, model) rows of an existing
``identification.json`` and the others are kept (``--fresh`` starts over); the full run
(no ``--only``) always starts over. ``--render-only`` rewrites the Markdown, the summary
figure and the page's block from the JSON without identifying anything. ``-v`` also prints every
candidate effect of the loop. The data stay in ``--root``; nothing is copied.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

from shipgym.datasets import measured_root
from shipgym.sysid.data import Record
from shipgym.sysid.engine import IdentificationResult
from shipgym.sysid.report import (
    DEFAULT_MODELS,
    FIGURES,
    identify_all,
    merge_rows,
    plot_record,
    plot_summary,
    relative_link,
    render_document,
    render_markdown,
    render_table,
    update_block,
    write_json,
)

REPO = Path(__file__).resolve().parents[1]
DEFAULT_ROOT = measured_root()  # $SHIPGYM_MEASURED_DATA, else where shipgym data fetch puts it


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--root", default=str(DEFAULT_ROOT), help="measured-data folder (default: %(default)s)"
    )
    parser.add_argument("--only", help="only records whose source/file contains this text")
    parser.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    parser.add_argument(
        "--page",
        default=str(REPO / "docs" / "results" / "identification.md"),
        help="documentation page whose block to update",
    )
    parser.add_argument("--no-page", action="store_true", help="do not touch the page")
    parser.add_argument(
        "--models",
        default=",".join(DEFAULT_MODELS),
        help="comma-separated bases (rvg3dof runs only on records with pod channels, vmm:... "
        "only on records of a ship with known particulars)",
    )
    parser.add_argument("--holdout", type=float, default=0.3)
    parser.add_argument("--max-effects", type=int, default=3)
    parser.add_argument("--fresh", action="store_true", help="ignore an existing JSON (--only)")
    parser.add_argument(
        "--render-only",
        action="store_true",
        help="no identification: rewrite the Markdown, summary figure and page block from the JSON",
    )
    parser.add_argument(
        "-v", "--verbose", action="store_true", help="also print every candidate effect"
    )
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    models = tuple(m.strip() for m in args.models.split(",") if m.strip())

    figures: dict[tuple[str, str], str] = {}

    def on_result(record: Record, result: IdentificationResult, row: dict[str, Any]) -> None:
        model, name = FIGURES.get(row["source"], (None, None))
        if model != row["model"] or name is None:
            return
        path = plot_record(result, out / name, title=row["label"])
        if path is None:
            print(
                f"    figure {name} not written: shipgym.sysid.plots.plot_identification "
                "is not available",
                file=sys.stderr,
            )
            return
        figures[row["record"], row["model"]] = name
        print(f"    wrote {path}", file=sys.stderr)

    json_path = out / "identification.json"
    previous: dict[str, Any] = {}
    if json_path.is_file() and (args.render_only or (args.only and not args.fresh)):
        previous = json.loads(json_path.read_text(encoding="utf-8"))
    t0 = time.perf_counter()
    if args.render_only:
        if not previous:
            print(f"--render-only needs {json_path}", file=sys.stderr)
            return 1
        figures = _figures(previous)
        return _write(args, out, previous.get("rows", []), figures, previous["config"], 0.0)
    rows = identify_all(
        args.root,
        models=models,
        only=args.only,
        holdout=args.holdout,
        max_effects=args.max_effects,
        progress=sys.stderr,
        detail=args.verbose,
        on_result=on_result,
    )
    elapsed = time.perf_counter() - t0
    if not rows:
        print(f"no record matches --only {args.only!r}", file=sys.stderr)
        return 1

    if previous:
        rows = merge_rows(previous.get("rows", []), rows)
        kept = {k: v for k, v in _figures(previous).items() if (out / v).is_file()}
        figures = {**kept, **figures}
    config = {
        "root": os.path.relpath(args.root, REPO),
        "models": list(models),
        "holdout": args.holdout,
        "max_effects": args.max_effects,
        "window_s": "auto",
        "last_run_only": args.only,
        "last_run_s": round(elapsed, 1),
    }
    return _write(args, out, rows, figures, config, elapsed)


def _figures(document: dict[str, Any]) -> dict[tuple[str, str], str]:
    """The ``figures`` of an identification.json: ``"record|model"`` -> file name."""
    out: dict[tuple[str, str], str] = {}
    for key, name in document.get("figures", {}).items():
        record, _, model = str(key).rpartition("|")
        out[record, model] = str(name)
    return out


def _write(
    args: argparse.Namespace,
    out: Path,
    rows: list[dict[str, Any]],
    figures: dict[tuple[str, str], str],
    config: dict[str, Any],
    elapsed: float,
) -> int:
    """Write the JSON, the Markdown report, the summary figure and the page's block."""
    json_path = out / "identification.json"
    write_json(
        {
            "config": config,
            "figures": {f"{r}|{m}": v for (r, m), v in figures.items()},
            "rows": rows,
        },
        json_path,
    )
    plot_summary(rows, out / "identification.png")
    only = config.get("last_run_only")
    command = "python scripts/identify_all.py" + (f" --only {only}" if only else "")
    doc = render_document(
        rows,
        figures=figures,
        command=command,
        config={k: config[k] for k in ("models", "holdout", "max_effects", "window_s")},
    )
    (out / "identification.md").write_text(doc, encoding="utf-8")
    print(render_table(rows))
    written = [json_path, out / "identification.md", out / "identification.png"]
    written += [out / v for v in figures.values()]
    if not args.no_page:
        page = Path(args.page)
        plot = relative_link(out / "identification.png", page)
        block = render_markdown(rows) + f"\n\n![heading error before/after]({plot})"
        changed = update_block(page, block)
        written.append(page if changed else Path(f"{page} (unchanged)"))
    failed = [r for r in rows if r["status"] != "ok"]
    print(
        f"{len(rows)} identification(s) in {elapsed:.0f} s ({len(failed)} failed or skipped); "
        f"wrote {', '.join(str(p) for p in written)}",
        file=sys.stderr,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())

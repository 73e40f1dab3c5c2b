"""Speed of the system identification against its speed goals (a benchmark, not a test).

Usage::

    python scripts/bench_sysid.py [--root DIR] [--repeats 3]
                                  [--effect rudder_lag] [--no-gunnerus] [--out docs]
                                  [--page docs/results/speed.md | --no-page]

Times (median after a warm-up for Numba, see :func:`shipgym.sysid.report.benchmark_sysid`) a
``nomoto1`` output-error fit of 10 001 generated samples (goal 1 s), the whole identification
loop on a 10 001-sample generated record with one effect (goal 10 s) and ``identify`` with base
``rvg3dof`` on the Gunnerus sea trials (goal 60 s; skipped with a message while unavailable),
and the 3-DOF ``vmm:martin_simple`` on the 13 HSVA KVLCC2 runs together (regression goal 5 s,
whole loop goal 60 s); then one finite-difference Jacobian's replays of ``nomoto1`` and
``rvg3dof``, one at a time against side by side, in interleaved rounds (the speed-up, no goal).
Prints each time with its goal and ratio, writes ``OUT/bench_sysid.json`` and
``OUT/bench_sysid.png`` and, when the page has them, refreshes the block between
``<!-- bench_sysid -->`` and ``<!-- /bench_sysid -->`` of ``docs/results/speed.md``. The exit
code does not depend on the goals.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from shipgym.datasets import measured_root
from shipgym.sysid.report import (
    benchmark_sysid,
    format_benchmark,
    plot_benchmark,
    relative_link,
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
    parser.add_argument("--repeats", type=int, default=3, help="timed runs (fit: at least 3)")
    parser.add_argument("--effect", default="rudder_lag", help="effect of the loop record")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-gunnerus", action="store_true", help="skip the Gunnerus record")
    parser.add_argument("--no-kvlcc2", action="store_true", help="skip the HSVA KVLCC2 runs")
    parser.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    parser.add_argument(
        "--page",
        default=str(REPO / "docs" / "results" / "speed.md"),
        help="documentation page whose block to update",
    )
    parser.add_argument("--no-page", action="store_true", help="do not touch the page")
    args = parser.parse_args(argv)
    out = Path(args.out)
    report = benchmark_sysid(
        args.root,
        repeats=args.repeats,
        effect=args.effect,
        seed=args.seed,
        gunnerus=not args.no_gunnerus,
        kvlcc2=not args.no_kvlcc2,
        progress=sys.stderr,
    )
    table = format_benchmark(report)
    print(table)
    json_path = write_json(report, out / "bench_sysid.json")
    png_path = plot_benchmark(report, out / "bench_sysid.png")
    written = [json_path, png_path]
    if not args.no_page:
        page = Path(args.page)
        sysinfo = report["system"]
        block = (
            f"Measured with `python scripts/bench_sysid.py` ({sysinfo['cpu_count']} CPUs, "
            f"Python {sysinfo['python']}, NumPy {sysinfo['numpy']}, SciPy {sysinfo['scipy']}, "
            f"Numba {sysinfo['numba']}); medians after a warm-up:\n\n{table}\n\n"
            f"![sysid speed]({relative_link(png_path, page)})"
        )
        try:
            changed = update_block(page, block, "bench_sysid")
        except ValueError as exc:
            print(f"page not updated: {exc}", file=sys.stderr)
        else:
            written.append(page if changed else Path(f"{page} (unchanged)"))
    print(f"wrote {', '.join(str(p) for p in written)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

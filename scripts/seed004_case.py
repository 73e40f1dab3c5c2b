"""Seed 004's path-following case on its own ship: design-rule, report and tuned gains.

Usage::

    python scripts/seed004_case.py [--out docs] [--page docs/guide/controllers.md | --no-page]

Runs :func:`shipgym.benchmark.seed004.run_seed004` with the report's gains, the design rule and
the gains :func:`~shipgym.benchmark.seed004.tune_seed004` finds on its grid; writes
``OUT/seed004.json``, ``OUT/seed004.png`` (tracks and cross-track errors) and the block
between ``<!-- seed004 -->`` and ``<!-- /seed004 -->`` of ``docs/guide/controllers.md``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from shipgym.benchmark.seed004 import (
    SEED004_PATH,
    SETTLE_M,
    TUNE_GRID,
    run_seed004,
    tune_seed004,
)
from shipgym.sysid.report import relative_link, update_block, write_json

REPO = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    ap.add_argument(
        "--page",
        default=str(REPO / "docs" / "guide" / "controllers.md"),
        help="documentation page whose block to update",
    )
    ap.add_argument("--no-page", action="store_true", help="do not touch the page")
    args = ap.parse_args(argv)
    out = Path(args.out)
    runs = {"report gains (eq. 7)": run_seed004("seed004"), "design rule": run_seed004("design"),
            "tuned": tune_seed004()}  # fmt: skip
    write_json({k: r.summary() for k, r in runs.items()}, out / "seed004.json")
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(14, 5.5), constrained_layout=True)
    ax1.plot(SEED004_PATH[:, 1], SEED004_PATH[:, 0], "k--", lw=1, label="path")
    for name, r in runs.items():
        ax1.plot(r.east, r.north, label=name)
        ax2.plot(r.time, r.cross_track, label=f"{name}: max {r.max_straight_m:.0f} m on straights")
    ax2.axhspan(-200, 200, color="0.9", label="report: +-200 m")
    ax1.set_xlabel("east [m]")
    ax1.set_ylabel("north [m]")
    ax1.set_aspect("equal")
    ax1.legend(fontsize=8)
    ax1.set_title("seed 004's ship, 0.5 m/s current toward east")
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("cross-track error [m]")
    ax2.legend(fontsize=8)
    fig.savefig(out / "seed004.png", dpi=110)
    plt.close(fig)
    lines = [
        f"Measured with `python scripts/seed004_case.py`; cross-track error on the straight parts "
        f"of the legs (from {SETTLE_M:g} m past each waypoint), the report's is +-200 m once on "
        f"track. Tuned: the best of {len(TUNE_GRID[0]) * len(TUNE_GRID[1])} (bandwidth, "
        "lookahead) pairs.",
        "",
        "| gains | heading bandwidth [rad/s] | lookahead [m] | max on straights [m] | RMS on "
        "straights [m] | max overall [m] |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for name, r in runs.items():
        bw = "-" if r.omega_n != r.omega_n else f"{r.omega_n:.3f}"
        lines.append(f"| {name} | {bw} | {r.lookahead:.0f} | {r.max_straight_m:.0f} | "
                     f"{r.rms_straight_m:.0f} | {r.max_m:.0f} |")  # fmt: skip
    if not args.no_page:
        figure = relative_link(out / "seed004.png", args.page)
        block = "\n".join([*lines, "", f"![seed 004's case]({figure})"])
        update_block(Path(args.page), block, "seed004")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

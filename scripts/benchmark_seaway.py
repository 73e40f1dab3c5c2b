"""Run the benchmark's seaway condition into ``docs/benchmark/seaway/`` and write its block.

    python scripts/benchmark_seaway.py [extra shipgym benchmark arguments]

Runs ``shipgym benchmark --condition nominal --condition seaway`` on the heading and path
envs (:data:`ENVS`) with the classic controller with and without the wave filter
(``classic``, ``classic-wf``), the tuned one and the shipped PPO and SAC agents (trained in calm
water), prints the seaway table (each controller at sea against calm water on the same seeds)
and writes it, with its figure, into the block between ``<!-- seaway -->`` and
``<!-- /seaway -->`` of ``docs/results/benchmark.md``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from shipgym.benchmark.plots import plot_seaway
from shipgym.benchmark.report import PAGE, seaway_table
from shipgym.benchmark.runner import SEAWAY, SEAWAY_HEIGHT, SEAWAY_WIND_SPEED
from shipgym.cli import main as shipgym
from shipgym.envs import env_task
from shipgym.sysid.report import relative_link, update_block

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "benchmark" / "seaway"
ENVS = ("shipgym/NomotoHeading-v0", "shipgym/RVGHeading-v1", "shipgym/RVGPathFollowing-v1")
CONTROLLERS = ("classic", "classic-wf", "classic-tuned", "ppo", "sac")
MARKER = "seaway"


def main(argv: list[str]) -> int:
    args = ["benchmark", "--out", str(OUT), "--condition", "nominal", "--condition", "seaway"]
    args += [a for env in ENVS for a in ("--env", env)]
    args += [a for name in CONTROLLERS for a in ("--controller", name)]
    code = shipgym([*args, *argv])
    if code or {"-h", "--help"} & set(argv):
        return code
    entries = json.loads((OUT / "benchmark.json").read_text())
    figure = plot_seaway(entries, OUT / "seaway.png")
    first = entries[0]
    periods = ", ".join(
        f"{env.split('/')[-1]} {SEAWAY[env_task(env)]['sea_state']['peak_period']:g} s"
        for env in dict.fromkeys(e["env"] for e in entries)
    )
    table = seaway_table(entries)
    block = "\n".join([
        f"{first['episodes']} episodes per cell, seeds {first['seed']}-"
        f"{first['seed'] + first['episodes'] - 1}, the same in calm water and at sea. The sea: "
        f"JONSWAP, H_s {SEAWAY_HEIGHT:g} m (WMO sea state 4), peak period {periods}; wind "
        f"{SEAWAY_WIND_SPEED:g} m/s with gusts (Beaufort 5); both directions drawn per episode. "
        "Each cell: the mean at sea, in parentheses the mean in calm water (`classic-wf`: "
        "`classic`'s, the filter passes a calm heading through). `lf_heading_rms_deg` is the "
        "error of the ship's low-frequency heading, `heading_rms_deg` that of the measured "
        "heading (with the wave-frequency motion); travel and reversals are of the rudder "
        "(the pods' azimuth) per minute, energy the propulsion's.",
        "",
        *table,
        f"![seaway]({relative_link(figure, ROOT / PAGE)})",
    ])  # fmt: skip
    print("\n".join(table))
    update_block(ROOT / PAGE, block, MARKER)
    print(f"wrote the block {MARKER!r} of {PAGE} and {figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""Run ``shipgym benchmark`` into ``docs/benchmark/`` and write the block of its results page.

    python scripts/benchmark_readme.py [extra shipgym benchmark arguments]

The block between ``<!-- benchmark -->`` and ``<!-- /benchmark -->`` of
``docs/results/benchmark.md`` gets the tables (nominal metrics with intervals, paired
comparisons, robustness), the throughput table and the figures.
It also runs the model mismatch the other way round: the ``-v0`` Gunnerus envs, whose agents
and design-rule gains were made on seed 001's parameters, on the sea-trial ship
(``docs/benchmark/reverse.json``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from shipgym.benchmark.report import PAGE, PAGE_MARKER, render_markdown, robustness_table
from shipgym.benchmark.runner import run_benchmark
from shipgym.cli import main as shipgym
from shipgym.envs import ENV_IDS
from shipgym.sysid.report import relative_link, update_block

ROOT = Path(__file__).resolve().parents[1]
#: The Gunnerus envs whose agents were trained on seed 001's parameters.
SEED001_ENVS = tuple(e for e in ENV_IDS if e.startswith("shipgym/RVG") and e.endswith("-v0"))


def main(argv: list[str]) -> int:
    out = ROOT / "docs" / "benchmark"
    code = shipgym(["benchmark", "--out", str(out), *argv])
    if code or {"-h", "--help"} & set(argv):
        return code
    entries = json.loads((out / "benchmark.json").read_text())
    reverse = run_benchmark(
        envs=SEED001_ENVS, controllers=("classic", "ppo", "sac"), conditions=("nominal", "mismatch")
    )
    reverse.write_json(out / "reverse.json")
    throughput_path = out / "throughput.json"
    throughput = json.loads(throughput_path.read_text()) if throughput_path.is_file() else None
    page = ROOT / PAGE
    block = render_markdown(entries, throughput, figure_dir=relative_link(out, page))
    block += (
        "\n\nThe other way round: the `-v0` envs, whose agents and design-rule gains were made "
        "on seed 001's parameters, on the sea-trial ship (same seeds):\n\n"
        + "\n".join(robustness_table(reverse.to_list()))
    )
    update_block(page, block, PAGE_MARKER)
    print(f"wrote the block {PAGE_MARKER!r} of {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""Run ``shipgym benchmark`` into ``docs/benchmark/`` and write the README's benchmark block.

    python scripts/benchmark_readme.py [extra shipgym benchmark arguments]

The block between ``<!-- benchmark -->`` and ``<!-- /benchmark -->`` gets the table (nominal
and stress for every env and controller), the throughput table and the figures.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from shipgym.benchmark.report import README_MARKER, render_markdown
from shipgym.cli import main as shipgym
from shipgym.sysid.report import update_readme

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str]) -> int:
    out = ROOT / "docs" / "benchmark"
    code = shipgym(["benchmark", "--out", str(out), *argv])
    if code:
        return code
    entries = json.loads((out / "benchmark.json").read_text())
    throughput_path = out / "throughput.json"
    throughput = json.loads(throughput_path.read_text()) if throughput_path.is_file() else None
    update_readme(ROOT / "README.md", render_markdown(entries, throughput), README_MARKER)
    print(f"wrote the README block {README_MARKER!r}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""Run the speed benchmark (same as ``shipgym bench``): ``python scripts/bench.py [options]``.

The logic lives in :mod:`shipgym.bench`; this is a thin wrapper around the command line, e.g.
``python scripts/bench.py --json bench.json --plot bench.png``.
"""

import sys

from shipgym.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))

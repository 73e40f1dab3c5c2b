"""Run the shipgym demo, the same as ``shipgym demo``.

Usage: ``python scripts/demo.py [--out DIR] [--model M]``.

The logic lives in :mod:`shipgym.demo`; this is a thin wrapper around the command line.
"""

import sys

from shipgym.cli import main

if __name__ == "__main__":
    sys.exit(main(["demo", *sys.argv[1:]]))

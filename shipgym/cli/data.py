"""``shipgym data``: the measured datasets the package knows, fetched and found by name.

``list`` shows each dataset (vessel, kind, runs, size, licence, whether it is on this machine)
and the citations to give; ``fetch NAME|all`` downloads from the origin at its pinned commit (or
``--mirror``), each file checked by its SHA-256, into the user cache; ``path NAME`` prints its
folder. The registry and the lookup order are :mod:`shipgym.datasets`'.
"""

from __future__ import annotations

import argparse
import textwrap
from typing import Any


def _list(args: argparse.Namespace) -> int:
    from shipgym import datasets

    header = ("name", "vessel", "kind", "runs", "size", "licence", "fetched")
    rows = []
    for d in datasets.list_datasets():
        try:
            datasets.path(d.name)
            here = "yes"
        except FileNotFoundError:
            here = "no"
        size = datasets.format_size(d.size)
        rows.append((d.name, d.vessel, d.kind, d.runs, size, d.licence, here))
    widths = [max(len(r[i]) for r in (header, *rows)) for i in range(len(header))]
    for r in (header, *rows):
        print("  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip())
    print("\nCite, when you use them:")
    for d in datasets.list_datasets():
        note = " (non-commercial use only)" if d.non_commercial else ""
        print(f"  {d.name}{note}:")
        for line in d.citation:
            print(textwrap.fill(line, 100, initial_indent="    ", subsequent_indent="      "))
    print(
        f"\n'shipgym data fetch NAME|all' writes to {datasets.cache_dir()} (set "
        f"${datasets.DATA_DIR_ENV} to change it); ${datasets.MEASURED_DATA_ENV} names an existing "
        "copy of the whole measured folder, used in place."
    )
    return 0


def _fetch(args: argparse.Namespace) -> int:
    from shipgym import datasets

    chosen = datasets.list_datasets() if args.name == "all" else [datasets.get(args.name)]
    for d in chosen:
        folder = datasets.fetch(d.name, progress=not args.quiet, mirror=args.mirror)
        print(f"{d.name}: {folder}", flush=True)
    return 0


def _path(args: argparse.Namespace) -> int:
    from shipgym import datasets

    if args.files:
        for f in datasets.files(args.name):
            print(f)
    else:
        print(datasets.path(args.name))
    return 0


def run(args: argparse.Namespace) -> int:
    return {"list": _list, "fetch": _fetch, "path": _path}[args.action](args)


def build(sub: Any) -> None:
    from shipgym.datasets import DATASETS

    names = ", ".join(DATASETS)
    p = sub.add_parser(
        "data",
        help="list, fetch and locate the measured datasets (shipgym data fetch all)",
        description=(
            "The measured manoeuvring records the package knows, each from a public "
            "repository at a pinned commit, checked by SHA-256. 'fetch' downloads them into "
            "the user cache (or $SHIPGYM_DATA_DIR); $SHIPGYM_MEASURED_DATA names an existing "
            "copy of the whole measured folder, used in place. Commands that read records "
            "(shipgym identify, the scripts) take a dataset name, or NAME/PATTERN, as well as "
            f"a path. Datasets: {names}."
        ),
    )
    actions = p.add_subparsers(
        dest="action", metavar="ACTION", required=True, help="list, fetch or path"
    )
    actions.add_parser(
        "list",
        help="every dataset: vessel, kind, runs, size, licence, whether fetched; the citations",
        description="List the datasets, whether each is on this machine, and what to cite.",
    )
    f = actions.add_parser(
        "fetch",
        help="download a dataset (or all) into the user cache, each file checked by SHA-256",
        description=(
            "Download a dataset from its origin at the pinned commit, each file checked by its "
            "SHA-256 (a file that does not match is not kept), with a progress bar per file. "
            "Files already there are kept; a dataset found in $SHIPGYM_MEASURED_DATA is "
            "verified in place. A non-commercial licence and its citations are printed before "
            "that dataset is downloaded. Prints each dataset's folder."
        ),
    )
    f.add_argument("name", metavar="NAME", help=f"dataset name or 'all' ({names})")
    f.add_argument(
        "--mirror",
        default=None,
        metavar="DIR|URL",
        help="read the files from this local folder or URL base, laid out like the measured "
        "folder, instead of the origins (default: $SHIPGYM_DATA_MIRROR, else the origins)",
    )
    f.add_argument(
        "--quiet",
        action="store_true",
        help="no progress lines or bars (a licence notice is still printed)",
    )
    q = actions.add_parser(
        "path",
        help="print the folder of a dataset on this machine",
        description=(
            "Print the folder of a dataset ($SHIPGYM_MEASURED_DATA's copy, else the user "
            "cache); exit code 1, naming the fetch command, when it is not on this machine."
        ),
    )
    q.add_argument("name", metavar="NAME", help=f"dataset name ({names})")
    q.add_argument("--files", action="store_true", help="print its files, one per line")
    p.set_defaults(handler=run)

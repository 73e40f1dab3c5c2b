"""The published-coefficient MMG KVLCC2 against the SIMMAN 2008 free-running tests.

Usage::

    python scripts/kvlcc2_simman.py [--root DIR] [--out docs]
                                    [--page docs/results/kvlcc2.md | --no-page]

Every MARIN (full scale: zigzags +-10/10, +-20/20, turning circles +-35 deg) and HSVA (7 m model:
zigzags 5/1 ... 35/5) record is summarised by the quantities of the standard trials, measured
by :func:`shipgym.maneuvers.zigzag_quantities` and :func:`shipgym.maneuvers.turning_quantities`
from the record's own rudder, heading and track. The MMG model (``kvlcc2``, Yasukawa and
Yoshimura 2015 coefficients; the full-scale ship for MARIN) runs the same trial with
:func:`shipgym.maneuvers.zigzag` and :func:`shipgym.maneuvers.turning_circle`, and the same
functions measure it. Writes ``OUT/kvlcc2_simman.json``, ``OUT/kvlcc2_simman.png`` and the
block between ``<!-- kvlcc2_simman -->`` and ``<!-- /kvlcc2_simman -->`` of
``docs/results/kvlcc2.md``.

The data stay where they are; nothing is copied.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import warnings
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from shipgym import maneuvers
from shipgym.datasets import measured_root
from shipgym.models import MMGParams, make_model
from shipgym.models.mmg import KVLCC2_SCALE
from shipgym.sysid import load
from shipgym.sysid.report import relative_link, update_block, write_json

REPO = Path(__file__).resolve().parents[1]
DEFAULT_ROOT = measured_root()  # $SHIPGYM_MEASURED_DATA, else where shipgym data fetch puts it


def _trial(path: Path) -> dict[str, Any] | None:
    """Trial of a SIMMAN file from its name: kind, angles, first side and scale."""
    name = path.stem
    m = re.search(r"MARIN_FREE_KVLCC2_(zz|tc)_(-?\d+)_m$", name)
    if m:
        a = abs(float(m.group(2)))
        # MARIN's positive rudder turns to port; the loader flips it to starboard-positive
        side = "port" if float(m.group(2)) > 0 else "starboard"
        kind = "zigzag" if m.group(1) == "zz" else "turning"
        return {"kind": kind, "a": a, "b": a, "side": side, "full_scale": True}
    m = re.search(r"HSVA_CPMC_KVLCC2_Z_(\d+)_(\d+)(?:_([PS]))?$", name)
    if m:
        side = {"P": "port", "S": "starboard"}.get(m.group(3) or "", None)
        return {"kind": "zigzag", "a": float(m.group(1)), "b": float(m.group(2)), "side": side,
                "full_scale": False}  # fmt: skip
    return None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--root", default=str(DEFAULT_ROOT), help="measured-data folder (default: %(default)s)"
    )
    ap.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    ap.add_argument(
        "--page",
        default=str(REPO / "docs" / "results" / "kvlcc2.md"),
        help="documentation page whose block to update",
    )
    ap.add_argument("--no-page", action="store_true", help="do not touch the page")
    args = ap.parse_args(argv)
    root = Path(args.root)
    files = sorted([*root.glob("marin_kvlcc2/*.dat"), *root.glob("hsva_kvlcc2/*.dat")])
    if not files:
        print(f"no KVLCC2 records under {root}", file=sys.stderr)
        return 2
    model = MMGParams.kvlcc2()
    ships = {False: make_model("kvlcc2", model),
             True: make_model("kvlcc2", model.scaled(KVLCC2_SCALE))}  # fmt: skip
    rows: list[dict[str, Any]] = []
    for k, path in enumerate(files, 1):
        trial = _trial(path)
        if trial is None:
            continue
        print(f"[{k}/{len(files)}] {path.name}", file=sys.stderr, flush=True)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rec = load(path)
        ship = ships[trial["full_scale"]]
        length = ship.params.length
        row: dict[str, Any] = {"record": path.name, **trial, "length": length}
        if trial["kind"] == "turning":
            meas = maneuvers.turning_quantities(rec.time, rec.x, rec.y, rec.psi, rec.delta,
                                                np.hypot(rec.u, rec.v))  # fmt: skip
            sim = maneuvers.turning_circle(ship, trial["a"], trial["side"])
            s = sim.series
            mod = maneuvers.turning_quantities(s.time, s.x, s.y, s.psi, s.delta, s.speed)
        else:
            b = math.radians(trial["b"])
            meas = maneuvers.zigzag_quantities(rec.time, rec.psi, rec.delta, b)
            side = trial["side"] or meas["first"]
            row["side"] = side
            sim = maneuvers.zigzag(ship, trial["a"], trial["b"], first=side)
            s = sim.series
            mod = maneuvers.zigzag_quantities(s.time, s.psi, s.delta, b)
        row["measured"], row["model"] = meas, mod
        rows.append(row)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(rows, out / "kvlcc2_simman.json")
    md = render(rows)
    plot(rows, out / "kvlcc2_simman.png")
    print(md)
    if not args.no_page:
        figure = relative_link(out / "kvlcc2_simman.png", args.page)
        update_block(args.page, f"{md}\n\n![KVLCC2 against SIMMAN]({figure})", "kvlcc2_simman")
    return 0


def _f(x: float | None, fmt: str = ".1f") -> str:
    return "-" if x is None or not math.isfinite(x) else format(x, fmt)


def render(rows: list[dict[str, Any]]) -> str:
    """Markdown tables of the measured and predicted trial quantities."""
    zz = [r for r in rows if r["kind"] == "zigzag"]
    tc = [r for r in rows if r["kind"] == "turning"]
    lines = ["| zigzag | first | 1st overshoot measured / MMG [deg] | 2nd overshoot "
             "measured / MMG [deg] |", "|---|---|---:|---:|"]  # fmt: skip
    under = []
    for r in zz:
        m, p = r["measured"], r["model"]
        lines.append(
            f"| {r['record'].split('_')[0]} {r['a']:g}/{r['b']:g} | {r['side']} | "
            f"{_f(m['overshoot1_deg'])} / {_f(p['overshoot1_deg'])} | "
            f"{_f(m['overshoot2_deg'])} / {_f(p['overshoot2_deg'])} |"
        )
        for k in ("overshoot1_deg", "overshoot2_deg"):
            if math.isfinite(m[k]) and math.isfinite(p[k]):
                under.append(m[k] - p[k])
    lines += ["", "| turning circle | side | advance measured / MMG [L] | tactical diameter "
              "measured / MMG [L] | speed ratio measured / MMG |",
              "|---|---|---:|---:|---:|"]  # fmt: skip
    for r in tc:
        m, p, L = r["measured"], r["model"], r["length"]
        lines.append(
            f"| MARIN {r['a']:g} deg | {r['side']} | {_f(m['advance'] / L, '.2f')} / "
            f"{_f(p['advance'] / L, '.2f')} | {_f(m['tactical_diameter'] / L, '.2f')} / "
            f"{_f(p['tactical_diameter'] / L, '.2f')} | {_f(m['speed_ratio'], '.2f')} / "
            f"{_f(p['speed_ratio'], '.2f')} |"
        )
    u = np.array(under)
    head = (
        f"Measured with `python scripts/kvlcc2_simman.py`: {len(zz)} zigzags and {len(tc)} "
        f"turning circles. The published coefficients under-predict the overshoots by "
        f"{np.median(u):.1f} deg (median of {u.size}; {np.sum(u > 0)} of {u.size} under, "
        f"largest {np.max(u):.1f} deg)."
    )
    return head + "\n\n" + "\n".join(lines)


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    """Predicted against measured overshoots and turning quantities."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    ax = axes[0]
    for key, marker in (("overshoot1_deg", "o"), ("overshoot2_deg", "s")):
        m = [r["measured"][key] for r in rows if r["kind"] == "zigzag"]
        p = [r["model"][key] for r in rows if r["kind"] == "zigzag"]
        ax.scatter(m, p, marker=marker, label=f"overshoot {key[9]}")
    top = max(30.0, *(r["measured"]["overshoot2_deg"] for r in rows if r["kind"] == "zigzag"
                      if math.isfinite(r["measured"]["overshoot2_deg"])))  # fmt: skip
    ax.plot([0, top], [0, top], "k--", lw=0.8)
    ax.set_xlabel("measured [deg]")
    ax.set_ylabel("MMG, published coefficients [deg]")
    ax.set_title("zigzag overshoots (MARIN and HSVA)")
    ax.legend()
    ax.grid(alpha=0.3)
    ax = axes[1]
    labels, meas, mod = [], [], []
    for r in rows:
        if r["kind"] != "turning":
            continue
        L = r["length"]
        for k, name in (("advance", "advance"), ("tactical_diameter", "tactical D")):
            labels.append(f"{name}\n{r['side']}")
            meas.append(r["measured"][k] / L)
            mod.append(r["model"][k] / L)
    xs = np.arange(len(labels))
    ax.bar(xs - 0.2, meas, 0.4, label="measured (MARIN)")
    ax.bar(xs + 0.2, mod, 0.4, label="MMG")
    ax.set_xticks(xs, labels, fontsize=8)
    ax.set_ylabel("[L]")
    ax.set_title("35 deg turning circles")
    ax.legend()
    ax.grid(alpha=0.3, axis="y")
    fig.suptitle("KVLCC2: MMG with the published coefficients against SIMMAN 2008 free running")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())

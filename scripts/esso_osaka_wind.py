"""Identify the Esso Osaka model from its free-running tests in real wind, and check the wind it
finds against Blendermann's loads for the model's projected areas.

Usage::

    python scripts/esso_osaka_wind.py [--out docs] [--page docs/results/identification.md |
                                       --no-page]

1. Runs ``identify`` with ``vmm:auto`` (the default hold-out, the loop's progress) twice, as
   ``shipgym identify`` takes the runs: on the 9 zigzags and 4 turns (``esso-osaka/zigzag/*
   esso-osaka/turning/*``) and on the whole dataset (``esso-osaka``: with the two runs of
   random rudder orders).
2. Fits the VMM's wind terms (``X_wc, Y_ws, N_ws, N_w2``: the apparent wind's ``(V_w/U)^2``
   times ``cos g``, ``sin g``, ``sin g``, ``sin 2g``, :mod:`shipgym.models.vmm`) by least
   squares to Blendermann's (1994) loads (:func:`shipgym.models.wind.blendermann_load`) of a
   loaded tanker with the model's projected areas (SOURCES.md: frontal 0.135 m^2, lateral
   0.520 m^2, ``L_oa`` taken as ``L_pp`` 3.0 m, the lateral area's centroid at midship) over
   every apparent-wind angle, and sets them beside the identified ones; and gives each
   identified model's rudder moment arm (:func:`rudder_arm`) beside the MMG model's.
3. Writes ``OUT/esso_wind.json``, ``OUT/esso_wind.png`` (the three loads over the apparent
   wind angle, identified and Blendermann's, with the angles the runs saw) and the page's block
   between ``<!-- esso_wind -->`` and ``<!-- /esso_wind -->``.

The data stay where they are; nothing is copied.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from shipgym.datasets import expand_records
from shipgym.models.mmg import P_RUD, MMGParams, pack_mmg
from shipgym.models.vmm import VMMParams, pack_vmm, vmm_forces
from shipgym.models.wind import BLENDERMANN_COEFFICIENTS, blendermann_load
from shipgym.sysid import identify, load
from shipgym.sysid.generator import vmm_truth
from shipgym.sysid.report import relative_link, update_block, write_json

REPO = Path(__file__).resolve().parents[1]
#: The identifications: name -> the record arguments of ``shipgym identify``.
SETS = {
    "zigzags and turns": ("esso-osaka/zigzag/*", "esso-osaka/turning/*"),
    "every run": ("esso-osaka",),
}
#: The model's projected wind areas [m^2] and length [m] (SOURCES.md, Miyauchi et al. 2022).
FRONTAL_AREA, LATERAL_AREA, LENGTH = 0.135, 0.520, 3.0
SHIP_TYPE = "tanker_loaded"
WIND_TERMS = ("X_wc", "Y_ws", "N_ws", "N_w2")
_ANGLES = np.radians(np.arange(-180.0, 180.5, 2.5))


def _say(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def blendermann_loads(rho: float, length: float) -> np.ndarray:
    """``(3, n)`` Blendermann's ``X', Y', N'`` at :data:`_ANGLES`, per unit ``(V_w / U)^2``
    (the prime system of the VMM: forces over ``rho/2 L^2 U^2``, the moment over ``rho/2 L^3
    U^2``)."""
    args = (FRONTAL_AREA, LATERAL_AREA, 0.0, LENGTH, *BLENDERMANN_COEFFICIENTS[SHIP_TYPE])
    loads = np.array([blendermann_load(1.0, a, *args) for a in _ANGLES]).T
    q = 0.5 * rho * length * length
    return loads / np.array([[q], [q], [q * length]])


def _unit_loads(term: str, g: np.ndarray) -> np.ndarray:
    """``(3, n)`` ``X', Y', N'`` of the VMM's wind term ``term`` with coefficient 1 at the
    apparent wind angles ``g``, per unit ``(V_w / U)^2``: the model's own forces
    (:func:`shipgym.models.vmm.vmm_forces`) in straight running at the approach speed, in a
    wind of that speed, over ``rho/2 L^2 U^2`` (``rho/2 L^3 U^2`` for the moment)."""
    params = vmm_truth().with_coefficients({term: 1.0})
    packed, u = pack_vmm(params), params.approach_speed
    loads = np.array([vmm_forces(u, 0.0, 0.0, 0.0, 0.0, u, a, packed) for a in g]).T
    q = 0.5 * params.rho * params.length**2 * u * u
    return loads / np.array([[q], [q], [q * params.length]])


def vmm_loads(terms: dict[str, float], g: np.ndarray = _ANGLES) -> np.ndarray:
    """``(3, n)`` the VMM wind terms' ``X', Y', N'`` per unit ``(V_w / U)^2``."""
    return sum(v * _unit_loads(k, g) for k, v in terms.items())


def fit_wind_terms(loads: np.ndarray) -> dict[str, float]:
    """The VMM wind terms that fit ``loads`` (``(3, n)`` at :data:`_ANGLES`) best, each
    equation by least squares on its own terms."""
    out: dict[str, float] = {}
    for eq, names in ((0, ("X_wc",)), (1, ("Y_ws",)), (2, ("N_ws", "N_w2"))):
        a = np.column_stack([_unit_loads(k, _ANGLES)[eq] for k in names])
        sol = np.linalg.lstsq(a, loads[eq], rcond=None)[0]
        out |= {k: float(v) for k, v in zip(names, sol, strict=True)}
    return out


def rudder_arm(params: VMMParams) -> float:
    """The identified model's rudder moment over its side force, in ship lengths: ``dN / (L
    dY)`` for the rudder from -2 to +2 deg in straight running at the approach speed and
    thrust (every rudder term, its slipstream's too)."""
    packed = pack_vmm(params)
    u, thrust, d = params.approach_speed, params.approach_thrust(), math.radians(2.0)
    hi, lo = (np.array(vmm_forces(u, 0.0, 0.0, s * d, thrust, 0.0, 0.0, packed)) for s in (1, -1))
    return float((hi[2] - lo[2]) / ((hi[1] - lo[1]) * params.length))


def mmg_rudder_arm() -> float:
    """The MMG KVLCC2's rudder moment over its side force, in ship lengths: ``(x_R + a_H x_H) /
    (1 + a_H)`` (Yasukawa and Yoshimura 2015, a VLCC of the Esso Osaka's form), as the MMG
    model packs it (:func:`shipgym.models.mmg.pack_mmg`)."""
    m = MMGParams.kvlcc2()
    p = pack_mmg(m)
    return float(p[P_RUD + 9] / (p[P_RUD + 8] * m.length))


def identify_set(records: tuple[str, ...]) -> tuple[dict[str, Any], list[Any]]:
    """One identification's summary (wind terms, errors, rudder arm) and its runs."""
    files = expand_records(records)
    _say(f"{len(files)} runs ({' '.join(records)}) ...")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        runs = [load(f) for f in files]
        result = identify(runs, "vmm:auto", progress=lambda m: _say(f"  {m}"))
    report = result.to_dict()
    wind = next((e for e in report["effects"] if e["name"] == "wind"), None)
    held = report["heldout"]
    part = {
        "command": f"shipgym identify {' '.join(records)} --model vmm:auto",
        "runs": [Path(f).name for f in files],
        "term_set": report["term_set_selection"]["chosen"],
        "effects": [e["name"] for e in report["effects"]],
        "heldout_runs": held["runs"],
        "heldout_before": held["error_before"],
        "heldout_after": held["error_after"],
        "record_heading_deg": held["record_consistency"]["psi_rms_deg"],
        "window_s": report["window_s"],
        "identified": wind["parameters"] if wind else None,
        "identified_training": wind["evidence"]["candidate_parameters"] if wind else None,
        "rudder_arm_L": rudder_arm(VMMParams.from_dict(report["vmm"])),
        "rho": report["vmm"]["rho"],
        "length": report["vmm"]["length"],
    }
    return part, runs


def _angles_seen(runs: list[Any]) -> np.ndarray:
    """The apparent-wind angles [rad] of every run's manoeuvre."""
    out = []
    for rec in runs:
        t0, t1 = rec.meta.get("manoeuvre_start_s"), rec.meta.get("manoeuvre_end_s")
        part = rec.slice(t0, t1) if t0 is not None and t1 is not None else rec
        out.append(part.wind_angle)
    return np.concatenate(out)


def plot(doc: dict[str, Any], seen: np.ndarray, path: Path) -> None:
    """The three wind loads over the apparent-wind angle: each identification's and
    Blendermann's, over a histogram of the angles ``seen`` [rad]."""
    deg = np.degrees(_ANGLES)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), sharex=True)
    curves = [(f"identified, {name}", part["identified"], colour, "-")
              for (name, part), colour in zip(doc["sets"].items(), ("C0", "C2"), strict=True)
              if part["identified"]]  # fmt: skip
    curves += [
        ("Blendermann, loaded tanker", None, "k", "-"),
        ("its best fit by the VMM's terms", doc["blendermann_terms"], "k", "--"),
    ]
    bl = np.array(doc["blendermann_loads"])
    for i, (ax, name) in enumerate(zip(axes, ("X'", "Y'", "N'"), strict=True)):
        for label, terms, colour, style in curves:
            y = bl[i] if terms is None else vmm_loads(terms)[i]
            ax.plot(deg, 1e5 * y, color=colour, ls=style, label=label)
        ax.axhline(0.0, color="0.8", lw=0.8)
        ax.set_title(f"{name} per unit (V_w/U)^2 [1e-5]")
        ax.set_xlabel("apparent wind from [deg, clockwise from the bow]")
        hist = ax.twinx()
        hist.hist(np.degrees(seen), bins=np.arange(-180, 181, 10), color="C1", alpha=0.2)
        hist.set_yticks([])
    axes[1].legend(fontsize=8, loc="upper right")
    axes[0].set_xticks(range(-180, 181, 90))
    title = ("Esso Osaka model in real wind: the wind loads vmm:auto identifies against "
             "Blendermann's (orange: the apparent wind angles of every run)")  # fmt: skip
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _errors(part: dict[str, Any]) -> str:
    e0, e1 = part["heldout_before"], part["heldout_after"]
    return (
        f"heading {e0['psi_rms_deg']:.1f} -> {e1['psi_rms_deg']:.1f} deg, yaw rate "
        f"{e0['r_rms_deg_s']:.2f} -> {e1['r_rms_deg_s']:.2f} deg/s, surge "
        f"{e0['u_rms_m_s']:.3f} -> {e1['u_rms_m_s']:.3f} m/s, sway {e0['v_rms_m_s']:.3f} -> "
        f"{e1['v_rms_m_s']:.3f} m/s"
    )


def render(doc: dict[str, Any], figure: str) -> str:
    """The page's block: each identification, the wind terms beside Blendermann's, the figure."""
    lines = [f"`python scripts/esso_osaka_wind.py` ({doc['runtime_s']:.0f} s), two identifications "
             "with the default hold-out:", ""]  # fmt: skip
    for name, part in doc["sets"].items():
        lines.append(
            f"- **{name}** (`{part['command']}`, {len(part['runs'])} runs): structure "
            f"`{part['term_set']}`, effects named {', '.join(part['effects']) or 'none'}; "
            f"held-out runs {', '.join(part['heldout_runs'])}: {_errors(part)} (windows of "
            f"{part['window_s']:.0f} s; the record's own yaw rate, integrated, misses its "
            f"heading by {part['record_heading_deg']:.2f} deg there); the rudder's moment arm "
            f"{part['rudder_arm_L']:.2f} L."
        )
    names = list(doc["sets"])
    lines += [
        "",
        "| wind term | "
        + " | ".join(f"{n}: all runs | {n}: training runs" for n in names)
        + " | Blendermann's, fitted by the term |",
        "|---|" + "---:|" * (2 * len(names) + 1),
    ]
    for k in WIND_TERMS:
        c = doc["blendermann_terms"][k]
        cells = []
        for n in names:
            part = doc["sets"][n]
            for key in ("identified", "identified_training"):
                v = part[key][k] if part[key] else None
                ratio = f" ({v / c:.2f} x)" if v is not None and k != "N_ws" else ""
                cells.append("-" if v is None else f"{v:.3g}{ratio}")
        lines.append(f"| `{k}` | " + " | ".join(cells) + f" | {c:.3g} |")
    lines += [
        "",
        f"The MMG model's rudder moment arm, `(x_R + a_H x_H) / (1 + a_H)` of the KVLCC2: "
        f"{doc['mmg_rudder_arm_L']:.2f} L.",
        "",
        f"![Esso Osaka's wind loads, identified and Blendermann's]({figure})",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    ap.add_argument("--page", default=str(REPO / "docs" / "results" / "identification.md"))
    ap.add_argument("--no-page", action="store_true", help="do not touch the page")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    sets = {}
    for name, records in SETS.items():
        sets[name], runs = identify_set(records)
    seen = _angles_seen(runs)  # the last set, "every run", holds all of them
    first = next(iter(sets.values()))
    bl = blendermann_loads(float(first["rho"]), float(first["length"]))
    doc = {
        "sets": sets,
        "blendermann": {
            "ship_type": SHIP_TYPE,
            "frontal_area_m2": FRONTAL_AREA,
            "lateral_area_m2": LATERAL_AREA,
            "length_m": LENGTH,
            "centre_m": 0.0,
        },
        "blendermann_terms": fit_wind_terms(bl),
        "blendermann_loads": bl.tolist(),
        "angles_deg": np.degrees(_ANGLES).tolist(),
        "mmg_rudder_arm_L": mmg_rudder_arm(),
    }
    doc["runtime_s"] = time.perf_counter() - t0
    out = Path(args.out)
    write_json(doc, out / "esso_wind.json")
    figure = out / "esso_wind.png"
    plot(doc, seen, figure)
    text = render(doc, relative_link(figure, args.page))
    print(text)
    if not args.no_page:
        update_block(args.page, text, "esso_wind")
    _say(f"wrote {out / 'esso_wind.json'}, {figure} in {doc['runtime_s']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

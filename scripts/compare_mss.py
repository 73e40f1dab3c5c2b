"""Check shipgym's wind loads, wave spectrum and encounter frequency against Fossen's MSS.

Usage::

    # 1. record MSS's numbers (needs GNU Octave and the folder LIBRARY/environment of an MSS
    #    checkout, https://github.com/cybergalactic/MSS, MIT licence; nothing of MSS is copied)
    python scripts/compare_mss.py --reference --mss-path MSS/LIBRARY/environment \\
        [--mss-commit HASH]
    # 2. compare (no Octave needed): table, figure and the page's block
    python scripts/compare_mss.py [--out docs] [--page docs/guide/seaway.md | --no-page]

Step 1 writes an Octave script that calls MSS's own functions, runs it with ``octave-cli`` and
writes ``OUT/mss_reference.json``: MSS's outputs, the inputs, the MSS commit, the Octave
version and the script itself, so that anyone can run the same calls again. Step 2 evaluates
shipgym's functions on the recorded inputs and prints both and their differences, writes
``OUT/mss_comparison.png`` and the block between ``<!-- mss_comparison -->`` and
``<!-- /mss_comparison -->`` of the page.

The functions compared (T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion
Control*, 2nd ed., Wiley 2021, sections 10.1 and 10.2, and their MSS implementations):

* ``isherwood72.m`` and :func:`shipgym.models.wind.isherwood_load` on the Mariner's wind data
  (:data:`shipgym.models.wind.MARINER_WIND`);
* ``blendermann94.m`` (ship type 13, research vessel) and
  :func:`shipgym.models.wind.blendermann_load` on the R/V Gunnerus's
  (:data:`shipgym.models.wind.GUNNERUS_WIND`);
* ``waveSpectrum.m`` (type 7, JONSWAP with ``H_s``, ``omega_0`` and ``gamma``; ``wavespec.m``
  is its obsolete alias) and :func:`shipgym.models.waves.jonswap_spectrum`;
* ``encounter.m`` and :func:`shipgym.models.waves.encounter_frequency`.

Conventions. MSS's relative wind angle ``gamma_r`` is ``-atan2(v_r, u_r)`` of the ship's
velocity relative to the air: ``0`` head wind and positive for a wind from PORT (its ``Y`` is
``C_Dt sin(gamma_r) > 0``, to starboard, on ``0 < gamma_r < pi``). shipgym's angle ``g`` is where
the wind comes from, clockwise from the bow, positive from STARBOARD: ``g = -gamma_r``. Both
give ``X`` forward, ``Y`` to starboard and ``N`` clockwise seen from above (Fossen's body axes),
in air of density 1.224 kg/m^3. ``blendermann94.m`` uses its ``sL`` in the yaw moment
(``C_N = (sL / Loa - 0.18 (gamma_r - pi/2)) C_Y``) and ``sH`` only in the roll moment, although
its header describes ``sH`` as the horizontal distance: the centroid's distance forward of
midship goes into ``sL`` (as MSS's ``exWindForce.m`` does); its formula is written for
``0 <= gamma_r <= pi`` (the range of ``exWindForce.m``) and is not odd in ``gamma_r`` beyond,
while shipgym mirrors it so that the moment of a port/starboard-symmetric ship is odd: the yaw
moments are compared on ``0 <= gamma_r <= pi``, and the difference beyond is shown apart. The
encounter angle of both is ``0`` in following seas and ``pi`` in head seas, with ``g = 9.81``.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from shipgym.models.waves import encounter_frequency, jonswap_spectrum
from shipgym.models.wind import (
    BLENDERMANN_COEFFICIENTS,
    GUNNERUS_WIND,
    MARINER_WIND,
    RHO_AIR,
    blendermann_load,
    isherwood_load,
)
from shipgym.sysid.report import relative_link, update_block, write_json

REPO = Path(__file__).resolve().parents[1]
MARKER = "mss_comparison"

WIND_SPEED = 10.0
"""Relative wind speed ``V_r`` [m/s] of both wind-load comparisons."""
WIND_ANGLES_DEG = tuple(range(-180, 181, 5))
"""MSS's ``gamma_r`` [deg]: every 5 deg, between Isherwood's tabulated 10 deg steps too."""
TABLE_ANGLES_DEG = (0, 30, 60, 90, 120, 150, 180)
"""The angles of the printed table."""
BLENDERMANN_VESSEL = 13
"""MSS ``blendermann94.m`` ship type: research vessel."""
GUNNERUS_CENTROID_HEIGHT = 3.0
"""``sH`` [m] of ``blendermann94.m``: the height of the lateral area's centroid (assumed); it
enters only MSS's roll moment, which neither side compares."""
SEA_STATES = ((2.0, 7.0, 3.3), (4.0, 10.0, 1.0), (1.0, 5.0, 7.0))
"""``(H_s [m], T_p [s], gamma)``: JONSWAP, Pierson-Moskowitz (``gamma = 1``) and the steepest
peak shipgym takes (``gamma = 7``)."""
SPECTRUM_OMEGA = tuple(round(0.1 + 0.05 * k, 2) for k in range(49))
"""Wave frequencies [rad/s] of the spectra: 0.1 ... 2.5."""
ENCOUNTER_SPEEDS = (5.0, 10.0)
"""Ship speeds ``U`` [m/s]."""
ENCOUNTER_ANGLES_DEG = (0, 45, 90, 135, 180, -90)
"""Encounter angles [deg] (0 following seas, 180 head seas)."""
ENCOUNTER_OMEGA = (0.3, 0.6, 0.9, 1.2)
"""Wave frequencies [rad/s] of the encounter frequency."""

MSS_FILES = ("isherwood72.m", "blendermann94.m", "waveSpectrum.m", "encounter.m")


def _vector(values: Any) -> str:
    """An Octave row vector of ``values``, each float written so that it reads back exactly."""
    return "[" + " ".join(repr(float(v)) for v in values) + "]"


def octave_script() -> str:
    """The Octave script that calls MSS's functions on the compared inputs and prints JSON."""
    m = MARINER_WIND
    g = GUNNERUS_WIND
    return "\n".join(
        [
            "% MSS reference values of shipgym's scripts/compare_mss.py (written by it)",
            f"gamma_r = deg2rad({_vector(WIND_ANGLES_DEG)});  % relative wind angle [rad]",
            f"V_r = {WIND_SPEED!r};",
            "% Isherwood (1972), the Mariner (shipgym.models.wind.MARINER_WIND)",
            f"Loa = {m.length_overall!r}; B = {m.beam!r}; ALw = {m.lateral_area!r};",
            f"AFw = {m.frontal_area!r}; A_SS = {m.superstructure_area!r}; S = {m.perimeter!r};",
            f"C = {m.centroid!r}; M = {m.masts!r};",
            "tau = zeros(3, numel(gamma_r));",
            "for k = 1:numel(gamma_r)",
            "  tau(:, k) = isherwood72(gamma_r(k), V_r, Loa, B, ALw, AFw, A_SS, S, C, M);",
            "end",
            "out.isherwood72.gamma_r = gamma_r;",
            "out.isherwood72.X = tau(1, :); out.isherwood72.Y = tau(2, :);",
            "out.isherwood72.N = tau(3, :);",
            "% Blendermann (1994), research vessel, the R/V Gunnerus (GUNNERUS_WIND)",
            f"AFw = {g.frontal_area!r}; ALw = {g.lateral_area!r}; Loa = {g.length_overall!r};",
            f"sL = {g.centre!r}; sH = {GUNNERUS_CENTROID_HEIGHT!r};",
            f"vessel_no = {BLENDERMANN_VESSEL};",
            "tau = blendermann94(gamma_r(:), V_r, AFw, ALw, sH, sL, Loa, vessel_no);",
            "out.blendermann94.gamma_r = gamma_r;",
            "out.blendermann94.X = tau(1, :); out.blendermann94.Y = tau(2, :);",
            "out.blendermann94.N = tau(3, :);",
            "% JONSWAP (type 7: Hs, w0, gamma)",
            f"W = {_vector(SPECTRUM_OMEGA)};",
            f"sea = [{'; '.join(' '.join(repr(float(v)) for v in s) for s in SEA_STATES)}];",
            "out.waveSpectrum.W = W;",
            "out.waveSpectrum.S = zeros(rows(sea), numel(W));",
            "for k = 1:rows(sea)",
            "  out.waveSpectrum.S(k, :) = "
            "waveSpectrum(7, [sea(k, 1), 2*pi/sea(k, 2), sea(k, 3)], W, 0)';",
            "end",
            "% encounter frequency",
            f"U = {_vector(ENCOUNTER_SPEEDS)};",
            f"chi = deg2rad({_vector(ENCOUNTER_ANGLES_DEG)});",
            f"Omega = {_vector(ENCOUNTER_OMEGA)};",
            "out.encounter.Omega_e = zeros(numel(U) * numel(chi), numel(Omega));",
            "for i = 1:numel(U)",
            "  for j = 1:numel(chi)",
            "    out.encounter.Omega_e((i - 1) * numel(chi) + j, :) = "
            "encounter(chi(j), U(i), Omega);",
            "  end",
            "end",
            "printf('%s\\n', jsonencode(out));",
        ]
    )


def _rows(values: Any) -> list[list[float]]:
    """A matrix of Octave's JSON as a list of rows (a one-row matrix arrives as a flat list)."""
    arr = np.atleast_2d(np.asarray(values, dtype=float))
    return arr.tolist()


def record_reference(mss_path: Path, commit: str, out: Path) -> Path:
    """Run MSS's functions in ``mss_path`` with Octave and write the reference JSON."""
    missing = [f for f in MSS_FILES if not (mss_path / f).is_file()]
    if missing:
        raise ValueError(f"--mss-path {mss_path} lacks {missing}: give MSS/LIBRARY/environment")
    octave = shutil.which("octave-cli") or shutil.which("octave")
    if octave is None:
        raise RuntimeError("GNU Octave is not installed (e.g. apt-get install octave-cli)")
    script = octave_script()
    with tempfile.TemporaryDirectory() as tmp:
        driver = Path(tmp) / "mss_reference.m"
        driver.write_text(script + "\n", encoding="utf-8")
        command = [octave, "--no-gui", "--norc", "--quiet", "--path", str(mss_path), str(driver)]
        proc = subprocess.run(command, capture_output=True, text=True, check=True)
    version = subprocess.run(
        [octave, "--version"], capture_output=True, text=True, check=True
    ).stdout.splitlines()[0]
    res = json.loads(proc.stdout.strip().splitlines()[-1])
    doc = {
        "source": {
            "name": "MSS (Marine Systems Simulator), T. I. Fossen",
            "repository": "https://github.com/cybergalactic/MSS",
            "licence": "MIT",
            "commit": commit,
            "files": [f"LIBRARY/environment/{f}" for f in MSS_FILES],
        },
        "octave": {
            "version": version,
            "command": "octave-cli --no-gui --norc --quiet --path MSS/LIBRARY/environment "
            "mss_reference.m",
            "script": script.splitlines(),
            "regenerate": "python scripts/compare_mss.py --reference "
            "--mss-path MSS/LIBRARY/environment --mss-commit HASH",
        },
        "inputs": {
            "V_r": WIND_SPEED,
            "mariner": {
                "Loa": MARINER_WIND.length_overall,
                "B": MARINER_WIND.beam,
                "ALw": MARINER_WIND.lateral_area,
                "AFw": MARINER_WIND.frontal_area,
                "A_SS": MARINER_WIND.superstructure_area,
                "S": MARINER_WIND.perimeter,
                "C": MARINER_WIND.centroid,
                "M": MARINER_WIND.masts,
            },
            "gunnerus": {
                "AFw": GUNNERUS_WIND.frontal_area,
                "ALw": GUNNERUS_WIND.lateral_area,
                "sH": GUNNERUS_CENTROID_HEIGHT,
                "sL": GUNNERUS_WIND.centre,
                "Loa": GUNNERUS_WIND.length_overall,
                "vessel_no": BLENDERMANN_VESSEL,
            },
            "sea_states": [list(s) for s in SEA_STATES],
            "encounter": {
                "U": list(ENCOUNTER_SPEEDS),
                "chi_deg": list(ENCOUNTER_ANGLES_DEG),
                "Omega": list(ENCOUNTER_OMEGA),
            },
        },
        "isherwood72": {k: np.ravel(res["isherwood72"][k]).tolist() for k in "XYN"}
        | {"gamma_r": np.ravel(res["isherwood72"]["gamma_r"]).tolist()},
        "blendermann94": {k: np.ravel(res["blendermann94"][k]).tolist() for k in "XYN"}
        | {"gamma_r": np.ravel(res["blendermann94"]["gamma_r"]).tolist()},
        "waveSpectrum": {
            "W": np.ravel(res["waveSpectrum"]["W"]).tolist(),
            "S": _rows(res["waveSpectrum"]["S"]),
        },
        "encounter": {"Omega_e": _rows(res["encounter"]["Omega_e"])},
    }
    return write_json(doc, out)


def package_values(ref: dict[str, Any]) -> dict[str, Any]:
    """shipgym's values on the inputs of the reference ``ref`` (its JSON, loaded).

    Returns the same keys and shapes as MSS's: ``isherwood72`` and ``blendermann94`` with
    ``X``, ``Y``, ``N`` per ``gamma_r`` (shipgym's wind angle ``-gamma_r``), ``waveSpectrum``
    ``S`` per sea state and frequency, ``encounter`` ``Omega_e`` per speed and angle (rows)
    and frequency.
    """
    inp = ref["inputs"]
    m = inp["mariner"]
    g = inp["gunnerus"]
    speed = float(inp["V_r"])
    mariner = (m["Loa"], m["B"], m["ALw"], m["AFw"], m["A_SS"], m["S"], m["C"], m["M"])
    gunnerus = (g["AFw"], g["ALw"], g["sL"], g["Loa"], *_blendermann_row(g["vessel_no"]))
    out: dict[str, Any] = {}
    for name, load, args in (
        ("isherwood72", isherwood_load, mariner),
        ("blendermann94", blendermann_load, gunnerus),
    ):
        gam = np.asarray(ref[name]["gamma_r"], dtype=float)
        xyn = np.array([load(speed, -a, *(float(v) for v in args)) for a in gam])
        out[name] = {"gamma_r": gam, "X": xyn[:, 0], "Y": xyn[:, 1], "N": xyn[:, 2]}
    w = np.asarray(ref["waveSpectrum"]["W"], dtype=float)
    out["waveSpectrum"] = {
        "W": w,
        "S": np.array([jonswap_spectrum(w, hs, tp, gm) for hs, tp, gm in inp["sea_states"]]),
    }
    enc = inp["encounter"]
    omega = np.asarray(enc["Omega"], dtype=float)
    out["encounter"] = {
        "Omega_e": np.array(
            [
                encounter_frequency(omega, u, math.radians(chi))
                for u in enc["U"]
                for chi in enc["chi_deg"]
            ]
        )
    }
    return out


def _blendermann_row(vessel_no: int) -> tuple[float, float, float, float]:
    """shipgym's coefficients of MSS's ship type ``vessel_no`` (those shipgym carries)."""
    types = {13: "research_vessel", 15: "tanker_loaded", 16: "tanker_ballast"}
    if vessel_no not in types:
        raise ValueError(f"vessel_no must be one of {sorted(types)}, got {vessel_no!r}")
    return BLENDERMANN_COEFFICIENTS[types[vessel_no]]


def comparisons(ref: dict[str, Any], pkg: dict[str, Any]) -> list[dict[str, Any]]:
    """Per compared quantity: MSS's and shipgym's arrays, where they are compared, the largest
    absolute difference and that difference over the quantity's largest magnitude."""
    rows = []
    for name in ("isherwood72", "blendermann94"):
        gam = np.asarray(ref[name]["gamma_r"], dtype=float)
        for k, unit in (("X", "N"), ("Y", "N"), ("N", "N m")):
            mask = np.ones(gam.shape, bool)
            if name == "blendermann94" and k == "N":
                mask = gam >= 0.0  # MSS's formula is written for 0 <= gamma_r <= pi
            rows.append(_row(f"{name} {k}", unit, ref[name][k], pkg[name][k], mask))
            if not mask.all():
                rows.append(
                    _row(f"{name} {k}, gamma_r < 0", unit, ref[name][k], pkg[name][k], ~mask)
                )
    rows.append(
        _row("waveSpectrum (JONSWAP)", "m^2 s", ref["waveSpectrum"]["S"], pkg["waveSpectrum"]["S"])
    )
    rows.append(
        _row("encounter", "rad/s", ref["encounter"]["Omega_e"], pkg["encounter"]["Omega_e"])
    )
    return rows


def _row(
    name: str, unit: str, mss: Any, ours: Any, mask: np.ndarray | None = None
) -> dict[str, Any]:
    a = np.asarray(mss, dtype=float)
    b = np.asarray(ours, dtype=float)
    if mask is None:
        mask = np.ones(a.shape, bool)
    diff = np.abs(a - b)[mask]
    scale = float(np.abs(a).max())
    return {
        "quantity": name,
        "unit": unit,
        "points": int(mask.sum()),
        "max_abs": float(np.abs(a[mask]).max()),
        "max_diff": float(diff.max()),
        "rel_diff": float(diff.max() / scale),
        "compared": not name.endswith("gamma_r < 0"),
    }


def _wind_table(ref: dict[str, Any], pkg: dict[str, Any], name: str) -> list[str]:
    gam = np.rad2deg(np.asarray(ref[name]["gamma_r"], dtype=float))
    lines = [
        "| `gamma_r` (MSS) [deg] | shipgym `g` [deg] | X MSS [kN] | X shipgym [kN] "
        "| Y MSS [kN] | Y shipgym [kN] | N MSS [kN m] | N shipgym [kN m] |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for deg in TABLE_ANGLES_DEG:
        i = int(np.argmin(np.abs(gam - deg)))
        cells = [f"{deg:d}", f"{-deg:d}"]
        for k in "XYN":
            cells += [f"{ref[name][k][i] / 1e3:.4g}", f"{pkg[name][k][i] / 1e3:.4g}"]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def summary_table(rows: list[dict[str, Any]]) -> list[str]:
    lines = [
        "| quantity | points | largest value | largest difference | difference / largest |",
        "|---|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['quantity']} | {r['points']} | {r['max_abs']:.4g} {r['unit']} "
            f"| {r['max_diff']:.2g} {r['unit']} | {r['rel_diff']:.1e} |"
        )
    return lines


def figure(ref: dict[str, Any], pkg: dict[str, Any], path: Path) -> None:
    """Wind coefficients against shipgym's wind angle (MSS markers, shipgym lines) and the
    spectra."""
    inp = ref["inputs"]
    m = inp["mariner"]
    g = inp["gunnerus"]
    q = 0.5 * RHO_AIR * float(inp["V_r"]) ** 2
    scales = {
        "isherwood72": (q * m["AFw"], q * m["ALw"], q * m["ALw"] * m["Loa"]),
        "blendermann94": (q * g["AFw"], q * g["ALw"], q * g["ALw"] * g["Loa"]),
    }
    labels = {"isherwood72": "Mariner, Isherwood", "blendermann94": "Gunnerus, Blendermann"}
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    for ax, k, title in zip(axes.flat, "XYN", ("$C_X$", "$C_Y$", "$C_N$"), strict=False):
        for name, colour in (("isherwood72", "C0"), ("blendermann94", "C1")):
            angle = -np.rad2deg(np.asarray(ref[name]["gamma_r"], dtype=float))
            order = np.argsort(angle)
            s = scales[name]["XYN".index(k)]
            ax.plot(angle[order], np.asarray(pkg[name][k])[order] / s, "-", color=colour,
                    label=f"{labels[name]}: shipgym")  # fmt: skip
            mss = np.asarray(ref[name][k]) / s
            inside = np.ones(angle.shape, bool)
            if name == "blendermann94" and k == "N":
                inside = angle <= 0.0  # MSS's formula is written for 0 <= gamma_r <= pi
                ax.plot(angle[~inside], mss[~inside], "x", ms=4, color=colour,
                        label="MSS beyond its 0 ... 180 deg")  # fmt: skip
            ax.plot(angle[inside], mss[inside], "o", mfc="none", ms=5, color=colour,
                    label=f"{labels[name]}: MSS")  # fmt: skip
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.set_xticks(range(-180, 181, 60))
        ax.set_xlabel("wind from [deg off the bow, + starboard]")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    beyond = [h for h in axes[1, 0].get_lines() if h.get_label().startswith("MSS beyond")]
    axes[1, 0].legend(handles=beyond, fontsize=8)
    ax = axes[1, 1]
    w = np.asarray(ref["waveSpectrum"]["W"], dtype=float)
    for i, (hs, tp, gm) in enumerate(inp["sea_states"]):
        ax.plot(w, pkg["waveSpectrum"]["S"][i], "-", color=f"C{i}",
                label=f"$H_s$ {hs:g} m, $T_p$ {tp:g} s, $\\gamma$ {gm:g}")  # fmt: skip
        ax.plot(w, ref["waveSpectrum"]["S"][i], "o", mfc="none", ms=4, color=f"C{i}")
    ax.set_xlabel("$\\omega$ [rad/s]")
    ax.set_ylabel("$S(\\omega)$ [m$^2$ s]")
    ax.set_title("JONSWAP (lines shipgym, circles MSS)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle(f"shipgym against MSS (commit {ref['source']['commit'][:10]}), "
                 f"wind {inp['V_r']:g} m/s")  # fmt: skip
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def page_block(
    ref: dict[str, Any], pkg: dict[str, Any], rows: list[dict[str, Any]], fig: Path, page: Path
) -> str:
    """The Markdown block of the page: the summary, the two wind tables and the figure."""
    pkg_rows = "\n".join(summary_table(rows))
    return "\n".join(
        [
            f"MSS commit `{ref['source']['commit']}`, run with {ref['octave']['version']}; "
            f"wind {ref['inputs']['V_r']:g} m/s, `gamma_r` every 5 deg.",
            "",
            pkg_rows,
            "",
            "The Mariner (Isherwood):",
            "",
            *_wind_table(ref, pkg, "isherwood72"),
            "",
            "The R/V Gunnerus (Blendermann, research vessel):",
            "",
            *_wind_table(ref, pkg, "blendermann94"),
            "",
            f"![shipgym against MSS]({relative_link(fig, page)})",
        ]
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    ap.add_argument("--reference", action="store_true", help="record MSS's numbers with Octave")
    ap.add_argument("--mss-path", help="MSS's LIBRARY/environment folder (with --reference)")
    ap.add_argument("--mss-commit", help="the MSS commit of --mss-path (default: git's HEAD)")
    ap.add_argument("--page", default=str(REPO / "docs" / "guide" / "seaway.md"),
                    help="page whose block to update (default: %(default)s)")  # fmt: skip
    ap.add_argument("--no-page", action="store_true", help="do not touch the page")
    args = ap.parse_args(argv)
    out = Path(args.out)
    ref_path = out / "mss_reference.json"
    if args.reference:
        if not args.mss_path:
            ap.error("--reference needs --mss-path")
        mss = Path(args.mss_path)
        commit = args.mss_commit or subprocess.run(
            ["git", "-C", str(mss), "rev-parse", "HEAD"], capture_output=True, text=True,
            check=True,
        ).stdout.strip()  # fmt: skip
        print(f"wrote {record_reference(mss, commit, ref_path)}")
    ref = json.loads(ref_path.read_text(encoding="utf-8"))
    pkg = package_values(ref)
    rows = comparisons(ref, pkg)
    for name in ("isherwood72", "blendermann94"):
        print(f"\n{name} at V_r = {ref['inputs']['V_r']:g} m/s")
        print("\n".join(_wind_table(ref, pkg, name)))
    print()
    print("\n".join(summary_table(rows)))
    fig = out / "mss_comparison.png"
    figure(ref, pkg, fig)
    print(f"wrote {fig}")
    if not args.no_page:
        page = Path(args.page)
        if update_block(page, page_block(ref, pkg, rows, fig, page), MARKER):
            print(f"updated {page}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Fit the pod normal-force form of the RVG model to the Kongsberg pod data.

The Kongsberg azimuth-pod FMU ("PMAzimuth.fmu", run by M. Kanazawa; NTNU-MCS/MCSim_python
``lib/testing/RVG_fmu_thruster_dataset_maneuvering.csv``, commit 861fd47a) tabulates the surge
and side force of ONE Gunnerus pod against ship speed, sway speed, azimuth and rpm (propeller
diameter 1.9 m, rho 1025). ``POINTS`` below are 47 of its rows (r = 0). This script fits the
two coefficients of the pod model of :mod:`shipgym.models.rvg` (normal force ``c_L`` and
slipstream fraction ``k_s``) by least squares, evaluating the force through the model's own
kernel (the difference of the derivative with and without the pods), and writes
``docs/pod_fmu.json`` and ``docs/pod_fmu.png`` (model vs FMU per point)::

    python scripts/pod_fmu_fit.py [--out docs]
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import least_squares

from shipgym.models import RVGParams, make_model
from shipgym.models.rvg import IT1, IT2, pack_rvg, pod_thrusts

# u [m/s], v [m/s], azimuth [deg], rpm, Fx [kN], Fy [kN] of one pod (Kongsberg FMU)
POINTS = [
    (2, 0, 0, 180, 71.9, 0.0), (2, 0, 4, 180, 70.4, 8.5), (2, 0, 10, 180, 68.3, 21.3),
    (2, 0, 20, 180, 61.4, 44.0), (2, 0, 30, 180, 56.0, 59.0),
    (4, 0, 0, 180, 47.5, 0.0), (4, 0, 4, 180, 45.0, 11.6), (4, 0, 10, 180, 41.2, 29.1),
    (4, 0, 20, 180, 30.7, 57.2), (4, 0, 30, 180, 20.8, 76.9),
    (5, 0, 0, 150, 17.5, 0.0), (5, 0, 4, 150, 14.6, 11.2), (5, 0, 10, 150, 10.2, 28.0),
    (5, 0, 20, 150, 0.0, 50.6), (5, 0, 30, 150, -14.2, 71.4),
    (5, 0, 0, 180, 36.3, 0.0), (5, 0, 4, 180, 33.0, 13.7), (5, 0, 10, 180, 27.9, 34.3),
    (5, 0, 20, 180, 15.4, 64.7), (5, 0, 30, 180, 0.9, 88.9),
    (5, 0, 0, 220, 69.5, 0.0), (5, 0, 4, 220, 65.6, 17.6), (5, 0, 10, 220, 59.7, 44.1),
    (5, 0, 20, 220, 43.8, 86.4), (5, 0, 30, 220, 28.5, 116.4),
    (6, 0, 0, 180, 25.2, 0.0), (6, 0, 4, 180, 21.0, 16.1), (6, 0, 10, 180, 14.6, 40.3),
    (6, 0, 20, 180, 0.0, 72.9), (6, 0, 30, 180, -20.5, 102.8),
    (6.5, 0, 0, 180, 19.4, 0.0), (6.5, 0, 4, 180, 14.8, 17.5), (6.5, 0, 10, 180, 7.9, 43.6),
    (6.5, 0, 20, 180, -7.7, 77.2), (6.5, 0, 30, 180, -31.8, 110.6),
    (5, 0.5, 0, 180, 33.0, -16.4), (5, 0.5, 10, 180, 30.8, 17.9), (5, 0.5, 20, 180, 18.9, 51.3),
    (5, 0.5, 30, 180, 0.2, 76.7), (5, 1, 0, 180, 32.7, -33.6), (5, 1, 10, 180, 34.3, 2.2),
    (5, 1, 20, 180, 21.3, 35.1), (5, 1, 30, 180, 3.6, 64.0), (5, 2, 0, 180, 32.8, -64.9),
    (5, 2, 10, 180, 35.6, -32.1), (5, 2, 20, 180, 30.7, 5.2), (5, 2, 30, 180, 11.6, 36.9),
]  # fmt: skip


def pod_force(params: RVGParams, u: float, v: float, alpha: float, rpm: float) -> np.ndarray:
    """Surge and side force [N] of one pod through the model's kernel (``r = 0``)."""
    x = np.array([0.0, 0.0, 0.0, u, v, 0.0, 0.0, 0.0, alpha, alpha])
    x[IT1], x[IT2] = pod_thrusts(rpm, x, np.zeros(2), pack_rvg(params))
    with_pods = make_model("rvg3dof", params).deriv(x, [x[IT1], x[IT2], alpha, alpha])[0, 3:6]
    bare = replace(params, pod_lift_coefficient=0.0)
    x0 = x.copy()
    x0[IT1] = x0[IT2] = 0.0
    hull = make_model("rvg3dof", bare).deriv(x0, [0.0, 0.0, alpha, alpha])[0, 3:6]
    return (params.mass_matrix @ (with_pods - hull))[:2] / 2.0


def fit(points: list[tuple[float, ...]]) -> tuple[float, float, np.ndarray]:
    """``(c_L, k_s, residuals [kN])`` of the least-squares fit."""

    def res(th: np.ndarray) -> np.ndarray:
        p = RVGParams(pod_lift_coefficient=th[0] * 1e3, pod_slipstream=th[1])
        out = [
            pod_force(p, u, v, math.radians(a), n) / 1e3 - (fx, fy) for u, v, a, n, fx, fy in points
        ]
        return np.concatenate(out)

    sol = least_squares(res, [6.0, 0.2], bounds=([0.0, 0.0], [30.0, 2.0]))
    return sol.x[0] * 1e3, sol.x[1], sol.fun.reshape(-1, 2)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="docs", help="output folder (default: %(default)s)")
    out = Path(ap.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)
    c_l, k_s, r = fit(POINTS)
    rms = np.sqrt(np.mean(r**2, axis=0))
    seed = np.array([pod_force(RVGParams(), u, v, math.radians(a), n) / 1e3
                     for u, v, a, n, *_ in POINTS])  # fmt: skip
    meas = np.array([(fx, fy) for *_, fx, fy in POINTS])
    rms_seed = np.sqrt(np.mean((seed - meas) ** 2, axis=0))
    print(f"c_L = {c_l:.4g} N s^2/m^2, k_s = {k_s:.3f}")
    print(f"RMS error over {len(POINTS)} points: Fx {rms[0]:.2f} kN, Fy {rms[1]:.2f} kN "
          f"(seed 001 without pod lift: Fx {rms_seed[0]:.2f}, Fy {rms_seed[1]:.2f})")  # fmt: skip
    doc = {"pod_lift_coefficient": c_l, "pod_slipstream": k_s, "points": len(POINTS),
           "rms_kN": {"Fx": rms[0], "Fy": rms[1]},
           "rms_kN_seed001": {"Fx": rms_seed[0], "Fy": rms_seed[1]}}  # fmt: skip
    (out / "pod_fmu.json").write_text(json.dumps(doc, indent=1) + "\n")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    fitted = meas + r
    for k, (ax, name) in enumerate(zip(axes, ("surge force Fx", "side force Fy"), strict=True)):
        lim = [meas[:, k].min() - 5, meas[:, k].max() + 5]
        ax.plot(lim, lim, "k:", lw=1)
        ax.plot(meas[:, k], seed[:, k], "x", color="0.6", label="seed 001 (no pod lift)")
        ax.plot(meas[:, k], fitted[:, k], "o", mfc="none", label="shipgym pod model (fit)")
        ax.set(xlabel=f"Kongsberg FMU {name} [kN]", ylabel=f"model {name} [kN]", title=name)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
    fig.suptitle(f"One Gunnerus pod, {len(POINTS)} points: c_L {c_l:.3g}, k_s {k_s:.3f}")
    fig.tight_layout()
    fig.savefig(out / "pod_fmu.png", dpi=110)
    print(f"wrote {out / 'pod_fmu.json'} and {out / 'pod_fmu.png'}")


if __name__ == "__main__":
    main()

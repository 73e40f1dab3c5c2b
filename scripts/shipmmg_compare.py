"""Compare shipgym's MMG KVLCC2 with ShipMMG, an independent MMG implementation.

Usage::

    python -m venv --system-site-packages /tmp/shipmmg-venv
    /tmp/shipmmg-venv/bin/pip install shipmmg        # ShipMMG pins Pillow < 11: keep it apart
    /tmp/shipmmg-venv/bin/python scripts/shipmmg_compare.py [--out docs]

Both models get the same rudder angle history and propeller speed from the same initial state
(the 7 m KVLCC2 at the SIMMAN 2008 speed, 1.179 m/s, propeller at shipgym's self-propulsion
point), so only the physics differs: the rudder history is shipgym's own steering-gear output
of a 35 deg turning circle and of the 10/10 and 20/20 zigzags (rudder rate 15.7 deg/s, the
full-scale 2.32 deg/s Froude-scaled), handed to ShipMMG as its ``delta_list``. Both trajectories
are measured by one function (advance and tactical diameter in ship lengths; zigzag overshoots
as the heading excursion beyond the check heading between rudder reversals).

shipgym runs four ways: the paper's equations (Yasukawa and Yoshimura 2015), each of ShipMMG's
two departures from it switched on alone (``MMGParams.wake_formula="shipmmg"``,
``MMGParams.speed_at_cg=True``), and both. Writes ``OUT/shipmmg.json`` (read by the tests) and
``OUT/shipmmg.png``, and prints the table.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import replace
from importlib import metadata
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from shipgym import maneuvers
from shipgym.models import MMGParams, make_model
from shipgym.models.mmg import KVLCC2_SIMMAN_SPEED

REPO = Path(__file__).resolve().parents[1]
DT = 0.01  # [s] shipgym's RK4 step and the common sampling of both trajectories
VARIANTS = {
    "shipgym (paper)": {},
    "shipgym, ShipMMG wake": {"wake_formula": "shipmmg"},
    "shipgym, ShipMMG U and beta at G": {"speed_at_cg": True},
    "shipgym, both": {"wake_formula": "shipmmg", "speed_at_cg": True},
}


def shipmmg_params(p: MMGParams) -> dict[str, float]:
    """ShipMMG's keyword arguments for the ship ``p`` (dimensional as ShipMMG wants them)."""
    m_x, m_y, j_z = p.added_masses
    return dict(
        L_pp=p.length, B=p.breadth, d=p.draught, x_G=p.x_g, D_p=p.propeller_diameter, m=p.mass,
        I_zG=p.yaw_inertia, A_R=p.rudder_area, η=p.propeller_diameter / p.rudder_height,
        m_x=m_x, m_y=m_y, J_z=j_z, f_α=p.f_alpha, ε=p.epsilon, t_R=p.t_r,
        x_R=p.x_r * p.length, a_H=p.a_h, x_H=p.x_h * p.length, γ_R_minus=p.gamma_minus,
        γ_R_plus=p.gamma_plus, l_R=p.l_r, κ=p.kappa, t_P=p.t_p, w_P0=p.w_p0, x_P=p.x_p,
        k_0=p.k0, k_1=p.k1, k_2=p.k2, R_0_dash=p.r0, X_vv_dash=p.x_vv, X_vr_dash=p.x_vr,
        X_rr_dash=p.x_rr, X_vvvv_dash=p.x_vvvv, Y_v_dash=p.y_v, Y_r_dash=p.y_r,
        Y_vvv_dash=p.y_vvv, Y_vvr_dash=p.y_vvr, Y_vrr_dash=p.y_vrr, Y_rrr_dash=p.y_rrr,
        N_v_dash=p.n_v, N_r_dash=p.n_r, N_vvv_dash=p.n_vvv, N_vvr_dash=p.n_vvr,
        N_vrr_dash=p.n_vrr, N_rrr_dash=p.n_rrr,
    )  # fmt: skip


def run_shipmmg(p: MMGParams, t: np.ndarray, delta: np.ndarray, n: float) -> np.ndarray:
    """ShipMMG's trajectory ``(len(t), 4)``: x, y, psi, delta (``solve_ivp`` RK45, tight;
    ShipMMG's state is ``u, v, r, x, y, psi, delta, n``)."""
    from shipmmg.mmg_3dof import simulate

    sol = simulate(
        **shipmmg_params(p), time_list=list(t), δ_list=list(delta),
        nps_list=[n] * t.size, u0=KVLCC2_SIMMAN_SPEED, ρ=p.rho, t_eval=t, rtol=1e-9, atol=1e-9,
    )  # fmt: skip
    x, y, psi, dlt = sol.y[3:7]
    return np.column_stack((x, y, psi, dlt))


def run_shipgym(p: MMGParams, t: np.ndarray, delta: np.ndarray, n: float) -> np.ndarray:
    """shipgym's trajectory with the rudder angle held to ``delta`` (a steering gear 20 times
    faster than the step, so the rudder follows the given history)."""
    ship = make_model("kvlcc2", replace(p, rudder_time_constant=DT / 2.0, rudder_rate=10.0))
    x0 = np.zeros(ship.nx)
    x0[ship.index("u")] = KVLCC2_SIMMAN_SPEED
    x0[ship.index("delta")] = delta[0]
    # command the next sample: the fast gear reaches it within the step
    cmd = np.column_stack((np.r_[delta[1:], delta[-1]], np.full(t.size, n)))[:-1]
    res = ship.simulate(x0, cmd, DT)
    return np.column_stack((res["x"], res["y"], res["psi"], res["delta"]))


def turning_metrics(traj: np.ndarray, length: float) -> dict[str, float]:
    """Advance and tactical diameter [L] of a starboard turn from ``(x, y, psi, delta)``."""
    x, y, psi = traj[:, 0], traj[:, 1], traj[:, 2] - traj[0, 2]
    i90 = int(np.argmax(psi >= math.pi / 2))
    i180 = int(np.argmax(psi >= math.pi))
    if psi[i90] < math.pi / 2 or psi[i180] < math.pi:
        return {"advance_L": math.nan, "tactical_diameter_L": math.nan}
    a = float(np.interp(math.pi / 2, psi[i90 - 1 : i90 + 1], x[i90 - 1 : i90 + 1]))
    td = float(np.interp(math.pi, psi[i180 - 1 : i180 + 1], y[i180 - 1 : i180 + 1]))
    return {"advance_L": a / length, "tactical_diameter_L": td / length}


def zigzag_metrics(traj: np.ndarray, reversals: np.ndarray, check: float) -> dict[str, float]:
    """First and second overshoot [deg]: after each rudder reversal, the heading excursion
    beyond the check heading until the next reversal."""
    psi = traj[:, 2] - traj[0, 2]
    out = {}
    for k, name in enumerate(("overshoot1_deg", "overshoot2_deg")):
        i0, i1 = reversals[k], reversals[k + 1]
        side = 1.0 if k % 2 == 0 else -1.0  # first reversal at +check (a starboard first swing)
        out[name] = math.degrees(float(np.max(side * psi[i0:i1])) - check)
    return out


def cases(p: MMGParams) -> list[dict[str, Any]]:
    """shipgym's own turning circle and zigzags: their rudder histories and the metric."""
    out = []
    turn = maneuvers.turning_circle(make_model("kvlcc2", p), 35.0, dt=DT)
    t = turn.series.time
    out.append({"name": "turning circle 35 deg", "t": t, "delta": turn.series.delta,
                "metric": lambda tr: turning_metrics(tr, p.length)})  # fmt: skip
    for a in (10.0, 20.0):
        z = maneuvers.zigzag(make_model("kvlcc2", p), a, a, dt=DT)
        t = z.series.time
        rev = np.searchsorted(t, np.asarray(z.execute_times[:3]))
        check = math.radians(a)
        out.append({"name": f"zigzag {a:g}/{a:g}", "t": t, "delta": z.series.delta,
                    "metric": lambda tr, rev=rev, b=check: zigzag_metrics(tr, rev, b)})  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(REPO / "docs"), help="output folder")
    args = ap.parse_args(argv)
    try:
        version = metadata.version("shipmmg")
    except metadata.PackageNotFoundError:
        print("shipmmg is not installed: see the usage in this script's docstring",
              file=sys.stderr)  # fmt: skip
        return 2
    p = MMGParams.kvlcc2()
    n = p.self_propulsion_rps(KVLCC2_SIMMAN_SPEED)
    rows = []
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for ax, case in zip(axes, cases(p), strict=True):
        t, delta = case["t"], case["delta"]
        print(f"{case['name']}: ShipMMG ...", file=sys.stderr, flush=True)
        ref = run_shipmmg(p, t, delta, n)
        row: dict[str, Any] = {"case": case["name"], "ShipMMG": case["metric"](ref)}
        sims = {"ShipMMG": ref}
        for label, kw in VARIANTS.items():
            sim = run_shipgym(replace(p, **kw), t, delta, n)
            sims[label] = sim
            row[label] = case["metric"](sim)
            row[label]["max_heading_difference_deg"] = math.degrees(
                float(np.max(np.abs(sim[:, 2] - ref[:, 2])))
            )
        rows.append(row)
        for label, sim in sims.items():
            if case["name"].startswith("turning"):
                ax.plot(sim[:, 1] / p.length, sim[:, 0] / p.length, label=label)
                ax.set_xlabel("east [L]")
                ax.set_ylabel("north [L]")
                ax.set_aspect("equal")
            else:
                ax.plot(t, np.degrees(sim[:, 2]), label=label)
                ax.set_xlabel("time [s]")
                ax.set_ylabel("heading [deg]")
        ax.set_title(case["name"])
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"KVLCC2 (7 m, MMG): shipgym against ShipMMG {version} on the same rudder history")
    fig.tight_layout()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "shipmmg.png", dpi=110)
    doc = {"shipmmg_version": version, "propeller_rps": n, "dt": DT, "rows": rows}
    (out / "shipmmg.json").write_text(json.dumps(doc, indent=1) + "\n")
    for row in rows:
        print(row["case"])
        for label in ("ShipMMG", *VARIANTS):
            vals = ", ".join(f"{k} {v:.3f}" for k, v in row[label].items())
            print(f"  {label:34s} {vals}")
    print(f"wrote {out / 'shipmmg.json'} and {out / 'shipmmg.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""The worked example "your ship, your data": a ship's own logs -> model -> autopilot -> verified.

Usage::

    python scripts/user_log_example.py [--regenerate] [--out docs/user_log]

The example logs in ``examples/`` come from a simulated 45 m coastal vessel whose truth is known
(:data:`TRUTH`: first-order Nomoto, K' = 2.0, T' = 2.5 at 6 m/s, a 1.5 deg rudder offset, the
default steering gear), sailed through 20/20 and 10/10 zigzags and a stretch of random rudder,
with sensor noise:

* ``examples/myship.csv``: what a bridge logger exports: UTC times, a port-positive rudder
  indicator in degrees, the gyro heading in [0, 360), rate of turn in deg/min, speed over
  ground in knots, latitude and longitude;
* ``examples/voyage.nmea``: the same voyage as NMEA 0183 at mixed rates (HDT 5 Hz, ROT and RSA
  2 Hz, RMC, GGA, VTG and ZDA 1 Hz), starting at 23:55 UTC on 31 December (the log crosses
  midnight into the new year), with one bad checksum and the gyro silent for 20 s (two
  segments).

``--regenerate`` writes them again (same seed, same files). Then the script runs the chain
with the ``shipgym`` command, as a user would: ``identify`` on both logs, ``design`` on the
model identified from the CSV, ``evaluate`` of that autopilot on the identified ship, and the
same autopilot on the true ship (the check no user can make, and the reason for a known truth).
It writes the JSON and figures into ``--out`` and ``OUT/user_log.json`` with the truth against
both identifications.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

from shipgym.models.model_file import load_model, nomoto_document
from shipgym.sysid.nmea_writer import write_nmea

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
KNOT = 1852.0 / 3600.0
L, U = 45.0, 6.0
#: The simulated ship (a model file document, so the truth is built as users' models are).
TRUTH = nomoto_document(
    "nomoto1",
    {"K": 2.0 * U / L, "T": 2.5 * L / U},
    rudder_offset=math.radians(1.5),
    speed=U,
    length=L,
    source="the worked example's truth",
)
COLUMNS = (
    "time=time_utc:datetime,delta=-rudder_angle:deg,psi=gyro_heading:deg,r=rot:deg/min,"
    "U=sog:kn,lat=lat,lon=lon"
)
DT = 0.2
RATES = {"HDT": 5.0, "ROT": 2.0, "RSA": 2.0, "RMC": 1.0, "GGA": 1.0, "VTG": 1.0, "ZDA": 1.0}
NOISE = {
    "psi": math.radians(0.1),
    "r": math.radians(1.0 / 60),
    "delta": math.radians(0.1),
    "U": 0.05 * KNOT,
    "xy": 1.0,
}
DURATION = 900.0
START = datetime.datetime(2026, 12, 31, 23, 55, 0, tzinfo=datetime.UTC)
LAT0, LON0 = 63.44, 10.40
#: The design rule's bandwidth (0.059 rad/s here) is set by the rudder's full-scale slew time and
#: settles in five minutes; this one settles in 40 s with 49 deg of phase margin and 12 deg of
#: rudder for a 30 deg step (``shipgym design FIT --bandwidth W``).
FASTER_BANDWIDTH = 0.15


def _voyage(seed: int = 7) -> dict[str, np.ndarray]:
    """The true ship through 20/20 and 10/10 zigzags and random rudder (SI channels)."""
    ship = load_model({"nomoto": TRUTH})
    rng = np.random.default_rng(seed)
    n = round(DURATION / DT)
    ipsi = ship.index("psi")
    random_rudder = np.repeat(rng.uniform(-20, 20, n // 100 + 1), 100)
    state = {"side": 1.0, "psi0": None}

    def policy(t: float, x: np.ndarray) -> np.ndarray:
        if state["psi0"] is None:
            state["psi0"] = x[ipsi]
        a = 20.0 if t < 300 else 10.0
        if t < 600:
            turned = math.degrees(x[ipsi] - state["psi0"])
            if state["side"] * turned > a:
                state["side"] = -state["side"]
            rudder = state["side"] * a
        else:
            rudder = random_rudder[int(t / DT)]
        return np.array([math.radians(rudder), ship.surge.service_shaft_speed])

    x0 = np.zeros(ship.nx)
    x0[ship.index("U")] = U
    x0[ipsi] = math.radians(40.0)
    sim = ship.simulate(x0, policy, DT, n)
    return {
        "time": sim.time,
        "psi": sim["psi"],
        "r": sim["r"],
        "delta": sim["delta"],
        "U": sim["U"],
        "x": sim["x"],
        "y": sim["y"],
    }


def regenerate() -> None:
    """Write ``examples/myship.csv`` and ``examples/voyage.nmea``."""
    v = _voyage()
    rng = np.random.default_rng(11)
    EXAMPLES.mkdir(exist_ok=True)
    # the CSV, every 0.4 s (every second simulation step)
    k = np.arange(0, v["time"].size, 2)
    m_rad, n_rad = 6.3897e6, 6.3951e6  # WGS84 radii at 63.44 deg N
    lat = LAT0 + np.degrees(v["x"][k] / m_rad) + rng.normal(0, 1e-6, k.size)
    lon = LON0 + np.degrees(v["y"][k] / (n_rad * math.cos(math.radians(LAT0))))
    lon += rng.normal(0, 2e-6, k.size)
    lines = ["time_utc,rudder_angle,gyro_heading,rot,sog,lat,lon"]
    for j, i in enumerate(k):
        when = START + datetime.timedelta(seconds=float(v["time"][i]))
        lines.append(
            f"{when:%Y-%m-%dT%H:%M:%S.%f}"[:-5]
            + "Z,"
            + f"{-math.degrees(v['delta'][i]) + rng.normal(0, 0.1):.2f},"
            + f"{(math.degrees(v['psi'][i]) + rng.normal(0, 0.1)) % 360.0:.2f},"
            + f"{math.degrees(v['r'][i]) * 60 + rng.normal(0, 1.0):.1f},"
            + f"{v['U'][i] / KNOT + rng.normal(0, 0.05):.2f},"
            + f"{lat[j]:.7f},{lon[j]:.7f}"
        )
    (EXAMPLES / "myship.csv").write_text("\n".join(lines) + "\n")
    write_nmea(
        EXAMPLES / "voyage.nmea",
        start=START,
        time=v["time"],
        psi=v["psi"],
        r=v["r"],
        delta=v["delta"],
        U=v["U"],
        x=v["x"],
        y=v["y"],
        lat0=LAT0,
        lon0=LON0,
        rates={
            "HDT": 5.0,
            "ROT": 2.0,
            "RSA": 2.0,
            "RMC": 1.0,
            "GGA": 1.0,
            "VTG": 1.0,
            "ZDA": 1.0,
        },
        noise={
            "psi": math.radians(0.1),
            "r": math.radians(1.0 / 60),
            "delta": math.radians(0.1),
            "U": 0.05 * KNOT,
            "xy": 1.0,
        },
        omit={"HDT": [(420.0, 440.0)]},
        bad_checksums=(1234,),
        seed=5,
    )


def _shipgym(*args: str) -> str:
    print("$ shipgym " + " ".join(args), flush=True)
    out = subprocess.run(
        [sys.executable, "-m", "shipgym.cli", *args],
        cwd=REPO,
        check=True,
        capture_output=True,
        text=True,
    )
    print(out.stdout, end="", flush=True)
    return out.stdout


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--regenerate", action="store_true", help="write the example logs again")
    ap.add_argument("--out", default="docs/user_log", help="output folder (repository-relative)")
    ap.add_argument("--episodes", type=int, default=20, help="evaluation episodes")
    args = ap.parse_args(argv)
    if args.regenerate:
        regenerate()
    out = Path(args.out)
    (REPO / out).mkdir(parents=True, exist_ok=True)
    csv_fit, nmea_fit = out / "myship_fit.json", out / "voyage_fit.json"
    common = ["--length", str(L), "--quiet", "--json"]
    _shipgym("identify", "examples/myship.csv", "--columns", COLUMNS, *common, str(csv_fit),
             "--plot", str(out / "myship_identify.png"))  # fmt: skip
    _shipgym("identify", "examples/voyage.nmea", *common, str(nmea_fit),
             "--plot", str(out / "voyage_identify.png"))  # fmt: skip
    designs = {"rule": [], "faster": ["--bandwidth", str(FASTER_BANDWIDTH)]}
    truth_file = out / "truth.json"
    (REPO / truth_file).write_text(json.dumps({"nomoto": TRUTH}, indent=1) + "\n")
    evals: dict[str, dict[str, object]] = {}
    for name, extra in designs.items():
        gains = out / f"gains_{name}.json"
        _shipgym("design", str(csv_fit), *extra, "--json", str(gains),
                 "--plot", str(out / f"design_{name}.png"))  # fmt: skip
        for label, ship in (("identified", csv_fit), ("true", truth_file)):
            target = out / f"evaluate_{name}_{label}.json"
            run = ["--gains", str(gains), "--episodes", str(args.episodes), "--json", str(target)]
            _shipgym("evaluate", "--env", "shipgym/NomotoHeading-v0", "--model", str(ship), *run)
            evals[f"{name} on the {label} ship"] = json.loads((REPO / target).read_text())
    fits = {
        name: json.loads((REPO / path).read_text())
        for name, path in (("csv", csv_fit), ("nmea", nmea_fit))
    }
    summary = {
        "truth": {**TRUTH["params"], "delta0_deg": math.degrees(TRUTH["rudder_offset_rad"])},
        **{
            name: {
                "effects": [e["name"] for e in fit["effects"]],
                **{k: v for k, v in fit["nomoto"]["params"].items()},
                "delta0_deg": math.degrees(fit["nomoto"]["rudder_offset_rad"]),
                "psi_rms_deg_after": fit["error_after"]["psi_rms_deg"],
            }
            for name, fit in fits.items()
        },
        "gains": {
            name: json.loads((REPO / out / f"gains_{name}.json").read_text()) for name in designs
        },
        "evaluation": {k: {"return": v["mean_return"], **v["metrics"]} for k, v in evals.items()},
    }
    (REPO / out / "user_log.json").write_text(json.dumps(summary, indent=1) + "\n")
    print(json.dumps({k: summary[k] for k in ("truth", "csv", "nmea")}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

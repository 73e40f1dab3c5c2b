"""A user's ship by its main particulars: VMMParams.from_particulars, the --particulars text,
the particulars as meta lines of a record file, and ``shipgym identify --particulars``.

The 7 m tanker model of the examples: L = 7.0 m, B = 1.27 m, T = 0.46 m, displacement
3.27 m^3, x_G = 0.25 m, D = 0.216 m, sea water 1025 kg/m^3. By hand:

* mass = 1025 * 3.27 = 3351.75 kg;
* C_b = 3.27 / (7.0 * 1.27 * 0.46) = 3.27 / 4.0894 = 0.79963;
* yaw radius 0.25 L = 1.75 m, I_z = 3351.75 * 1.75^2 = 10264.734375 kg m^2;
* Clarke, Gedling and Hine (1982), prime (over rho/2 L^3, L^4, L^5), T/L = 0.065714,
  B/L = 0.181429, B/T = 2.760870:
  Y_v' = -pi (T/L)^2 (1 + 0.16 C_b B/T - 5.1 (B/L)^2),
  Y_r' = -pi (T/L)^2 (0.67 B/L - 0.0033 (B/T)^2),
  N_v' = -pi (T/L)^2 (1.1 B/L - 0.041 B/T),
  N_r' = -pi (T/L)^2 (1/12 + 0.017 C_b B/T - 0.33 B/L),
  X_u' = -0.05 m' with m' = 2 C_b (B/L) (T/L).
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from shipgym.cli import main
from shipgym.models.vmm import VMMParams, find_particulars, parse_particulars
from shipgym.sysid import identify
from shipgym.sysid.data import Record, SysidDataWarning, load
from shipgym.sysid.families.vmm import vessel_params
from shipgym.sysid.generator import generate_vmm_runs

TEXT = "length=7.0,breadth=1.27,draught=0.46,displacement=3.27,x_g=0.25,propeller_diameter=0.216"
META_LINES = [
    "# L: 7.0",
    "# B: 1.27",
    "# draft: 0.46",
    "# displacement_m3: 3.27",
    "# x_G: 0.25",
    "# propeller_diameter: 0.216",
]


def test_from_particulars_against_the_hand_computed_values() -> None:
    p = VMMParams.from_particulars(**parse_particulars(TEXT))
    assert p.mass == pytest.approx(3351.75, rel=1e-12)
    assert p.yaw_inertia == pytest.approx(10264.734375, rel=1e-12)
    assert (p.length, p.breadth, p.draught, p.x_g) == (7.0, 1.27, 0.46, 0.25)
    assert p.propeller_diameter == 0.216
    assert p.rho == 1025.0
    assert p.coefficients == {}
    cb = 3.27 / (7.0 * 1.27 * 0.46)
    assert cb == pytest.approx(0.79963, abs=1e-5)
    k = -math.pi * (0.46 / 7.0) ** 2
    assert k == pytest.approx(-0.0135665, rel=1e-5)
    bl, bt = 1.27 / 7.0, 1.27 / 0.46
    expected = {
        "Y_vdot": k * (1.0 + 0.16 * cb * bt - 5.1 * bl**2),
        "Y_rdot": k * (0.67 * bl - 0.0033 * bt**2),
        "N_vdot": k * (1.1 * bl - 0.041 * bt),
        "N_rdot": k * (1.0 / 12.0 + 0.017 * cb * bt - 0.33 * bl),
        "X_udot": -0.05 * 2.0 * cb * bl * (0.46 / 7.0),
    }
    for key, value in expected.items():
        assert p.added[key] == pytest.approx(value, rel=1e-12), key
    assert p.added["Y_vdot"] == pytest.approx(-0.0160812, rel=1e-5)
    # defaults: approach Froude number 0.15, the IMO rudder rate scaled to 7 m (15.7 deg/s)
    assert p.approach_speed == pytest.approx(0.15 * math.sqrt(9.81 * 7.0))
    assert math.degrees(p.rudder_rate) == pytest.approx(65.0 / 28.0 * math.sqrt(320.0 / 7.0))


def test_mass_instead_of_displacement_and_the_optional_particulars() -> None:
    by_volume = VMMParams.from_particulars(**parse_particulars(TEXT))
    by_mass = VMMParams.from_particulars(
        **parse_particulars(TEXT.replace("displacement=3.27", "mass=3351.75"))
    )
    assert by_mass.mass == by_volume.mass
    assert by_mass.added == pytest.approx(by_volume.added, rel=1e-12)
    fresh = VMMParams.from_particulars(
        **parse_particulars(
            TEXT + ",rho=1000,yaw_radius=2.0,block_coefficient=0.8,approach_speed=1.2"
        )
    )
    assert fresh.mass == pytest.approx(3270.0)
    assert fresh.yaw_inertia == pytest.approx(3270.0 * 4.0)
    assert fresh.approach_speed == 1.2
    cb = 0.8
    k = -math.pi * (0.46 / 7.0) ** 2
    assert fresh.added["N_rdot"] == pytest.approx(
        k * (1.0 / 12.0 + 0.017 * cb * 1.27 / 0.46 - 0.33 * 1.27 / 7.0), rel=1e-12
    )


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"length": -7.0}, r"particular length must be > 0"),
        ({"breadth": math.nan}, r"particular breadth must be a finite number"),
        ({"draught": 8.0}, r"particular draught must be in \(0, 7\]"),
        ({"x_g": 3.6}, r"particular x_g must be a finite number within the hull, \|x_g\| < L/2"),
        ({"x_g": -4.0}, r"particular x_g must be .* within the hull"),
        ({"displacement": 3270.0}, r"block coefficient .* = 800 .*m\^3 \(not tonnes or kg\)"),
        ({"displacement": None}, r"displacement \(volume \[m\^3\]\) or mass \[kg\], exactly one"),
        ({"mass": 3351.75}, r"exactly one of them"),
        ({"rho": 1.025}, r"particular rho must be in \(950, 1100\]"),
        ({"yaw_radius": 4.0}, r"particular yaw_radius must be in \(0, 3.5\]"),
        ({"block_coefficient": 1.2}, r"particular block_coefficient must be in \(0, 1\]"),
        ({"propeller_diameter": 0.0}, r"particular propeller_diameter must be in \(0, 1.27\]"),
        ({"approach_speed": math.inf}, r"particular approach_speed must be a finite number"),
    ],
)
def test_every_particular_is_validated(change: dict, message: str) -> None:
    given = {**parse_particulars(TEXT), **change}
    with pytest.raises(ValueError, match=message):
        VMMParams.from_particulars(**given)


def test_the_particulars_text_and_its_errors() -> None:
    assert parse_particulars(TEXT + ", rho = 1000 ,") == {
        "length": 7.0,
        "breadth": 1.27,
        "draught": 0.46,
        "displacement": 3.27,
        "x_g": 0.25,
        "propeller_diameter": 0.216,
        "rho": 1000.0,
    }
    with pytest.raises(ValueError, match=r"--particulars misses the particular\(s\) x_g;"):
        parse_particulars(TEXT.replace(",x_g=0.25", ""))
    with pytest.raises(
        ValueError, match=r"--particulars misses the particular\(s\) draught, displacement \(or"
    ):
        parse_particulars("length=7,breadth=1.27,x_g=0")
    with pytest.raises(
        ValueError, match=r"unknown key 'L'; known keys: length, breadth, draught, displacement"
    ):
        parse_particulars("L=7.0," + TEXT)
    with pytest.raises(ValueError, match=r"--particulars: draught='0.46m' is not a number"):
        parse_particulars(TEXT.replace("0.46", "0.46m"))
    with pytest.raises(ValueError, match=r"key 'length' given twice"):
        parse_particulars(TEXT + ",length=7")
    with pytest.raises(ValueError, match=r"entry 'breadth' is not key=value"):
        parse_particulars("length=7,breadth")


def _record(n: int = 200) -> Record:
    """Straight running with a little rudder: channels enough for the particulars."""
    t = 0.1 * np.arange(n)
    return Record(
        time=t,
        delta=0.05 * np.sin(0.3 * t),
        psi=0.01 * np.sin(0.3 * t),
        r=0.003 * np.cos(0.3 * t),
        x=1.2 * t,
        y=np.zeros(n),
        u=np.full(n, 1.2),
        v=np.zeros(n),
        U=np.full(n, 1.2),
        meta={"source": "tank", "vessel": "tanker model"},
    )


def test_meta_lines_of_a_canonical_file_give_the_particulars(tmp_path: Path) -> None:
    path = _record().to_csv(tmp_path / "run.csv")
    lines = path.read_text().splitlines()
    path.write_text("\n".join([lines[0], *META_LINES, *lines[1:]]) + "\n")
    rec = load(path)
    assert rec.meta["draft"] == 0.46 and rec.meta["x_G"] == 0.25
    got = vessel_params(rec)
    want = VMMParams.from_particulars(**parse_particulars(TEXT), approach_speed=1.2)
    assert got.to_dict() == {**want.to_dict(), "name": "tanker model"}
    assert got.approach_speed == 1.2  # the record's median speed


def test_meta_lines_of_a_table_give_the_particulars(tmp_path: Path) -> None:
    rec = _record()
    path = tmp_path / "run.csv"
    rows = [f"{a:.3f},{math.degrees(b):.6f},{math.degrees(c):.6f},{d:.4f}"
            for a, b, c, d in zip(rec.time, rec.delta, rec.psi, rec.U, strict=True)]  # fmt: skip
    spelled = [
        *("# length: 7.0", "# breadth: 1.27", "# draught: 0.46", "# mass: 3351.75"),
        *("# x_g: 0.25", "# vessel: tanker model", "# exported by the tank's logger"),
    ]
    path.write_text("\n".join([*spelled, "time_s,rudder_deg,heading_deg,speed_m_s", *rows]) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidDataWarning)
        table = load(path)
    assert table.meta["source"] == "table"
    assert table.meta["length"] == 7.0 and table.meta["mass"] == 3351.75
    assert table.meta["vessel"] == "tanker model"
    assert find_particulars(table.meta) == {
        "length": 7.0,
        "breadth": 1.27,
        "draught": 0.46,
        "mass": 3351.75,
        "x_g": 0.25,
    }
    p = vessel_params(table)
    assert p.mass == 3351.75 and p.name == "tanker model"
    assert p.yaw_inertia == pytest.approx(10264.734375)
    assert p.approach_speed == pytest.approx(1.2)


def test_a_table_meta_line_may_not_set_what_the_loader_writes(tmp_path: Path) -> None:
    path = tmp_path / "run.csv"
    path.write_text("# L: 7\n# source: mine\ntime_s,rudder_deg,heading_deg\n0,0,0\n1,0,0\n2,0,0\n")
    with pytest.raises(ValueError, match=r"run.csv line 2: meta key 'source' is written by"):
        load(path)
    path.write_text("# L: -7\ntime_s,rudder_deg,heading_deg\n0,0,0\n1,0,0\n2,0,0\n")
    with pytest.raises(ValueError, match=r"line 1: meta L = '-7'; expected the ship length in m"):
        load(path)


def test_an_incomplete_record_names_the_flag_and_the_missing_particulars() -> None:
    rec = _record()
    rec.meta.update({"L": 7.0, "B": 1.27, "draft": 0.46})
    with pytest.raises(ValueError) as err:
        vessel_params(rec)
    text = str(err.value)
    assert "--particulars" in text
    assert "the record states length, breadth, draught; missing x_g, displacement (or mass)" in (
        text
    )
    rec.meta.update({"x_G": 0.25, "displacement": 3.27, "mass": 3000.0})
    with pytest.raises(ValueError, match="exactly one of them"):
        vessel_params(rec)
    rec.meta.pop("mass")
    rec.meta["length"] = 7.5
    with pytest.raises(ValueError, match=r"meta 'length' = 7.5 and 'L' = 7 state the length L"):
        vessel_params(rec)


def test_particulars_go_only_to_the_families_that_take_them() -> None:
    with pytest.raises(ValueError, match=r"model 'nomoto1' takes no particulars"):
        identify(_record(), "nomoto1", particulars=VMMParams.from_particulars(
            **parse_particulars(TEXT)))  # fmt: skip


@pytest.fixture(scope="module")
def tank_runs(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    """Two generated 3-DOF runs written as canonical CSV without their particulars."""
    folder = tmp_path_factory.mktemp("tank")
    files = []
    for k, run in enumerate(generate_vmm_runs(None, n_runs=2, seed=0, dt=0.2)):
        meta = {key: v for key, v in run.meta.items() if key not in ("particulars", "truth")}
        files.append(str(replace(run, meta=meta).to_csv(folder / f"run{k}.csv")))
    return files


def test_identify_takes_the_ship_by_the_particulars_flag(
    tank_runs: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    base = ["identify", *tank_runs, "--model", "vmm:martin_simple", "--max-effects", "0"]
    assert main([*base, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "--particulars" in err and "missing breadth, draught, x_g, displacement" in err
    flag = ("length=7.0,breadth=1.2688,draught=0.455,mass=3272,x_g=0.2436,"
            "propeller_diameter=0.204,rho=1000")  # fmt: skip
    out = tmp_path / "fit.json"
    assert main([*base, "--quiet", "--particulars", flag, "--json", str(out)]) == 0
    ship = json.loads(out.read_text())["vmm"]
    assert ship["mass"] == 3272.0
    assert ship["yaw_inertia"] == pytest.approx(3272.0 * (0.25 * 7.0) ** 2)
    speeds = np.concatenate([load(f).U for f in tank_runs])
    assert ship["approach_speed"] == pytest.approx(float(np.median(speeds)))
    assert main([*base, "--quiet", "--particulars", flag.replace(",x_g=0.2436", "")]) == 2
    assert "--particulars misses the particular(s) x_g" in capsys.readouterr().err

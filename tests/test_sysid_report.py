"""Tests of the identification report over many records (shipgym.sysid.report)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from shipgym.sysid import report
from shipgym.sysid.data import Record, load, measured_root
from shipgym.sysid.generator import generate_record
from shipgym.sysid.report import (
    benchmark_sysid,
    format_benchmark,
    identify_all,
    merge_rows,
    model_applies,
    plot_benchmark,
    plot_summary,
    prepare_record,
    render_document,
    render_markdown,
    render_table,
    replace_between_markers,
    update_block,
    write_json,
)

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _ok_row() -> dict[str, Any]:
    return {
        "record": "sspa/example_zigzag.csv",
        "label": "SSPA example_zigzag",
        "source": "sspa",
        "file": "example_zigzag.csv",
        "vessel": "unknown SSPA ship model",
        "manoeuvre": "zigzag 20/20",
        "samples_total": 2073,
        "duration_total_s": 41.44,
        "dt_s": 0.02,
        "repairs": [],
        "span_s": None,
        "model": "nomoto1",
        "status": "ok",
        "message": None,
        "samples": 2073,
        "duration_s": 41.44,
        "error_before": {"psi_rms_deg": 3.7889, "r_rms_deg_s": 0.68354, "xy_rms_m": 1.4476},
        "error_after": {"psi_rms_deg": 0.44806, "r_rms_deg_s": 0.31013, "xy_rms_m": 0.47551},
        "heldout": {
            "from_s": 29.02,
            "error_before": {"psi_rms_deg": 0.71440, "r_rms_deg_s": 0.29946},
            "error_after": {"psi_rms_deg": 0.24188, "r_rms_deg_s": 0.28178},
        },
        "effects": [
            {
                "name": "rudder_offset",
                "parameters": {"K": 0.747, "T": 1.6237, "delta0": -0.0056850},
                "evidence": {"delta_J": -1620.2, "heldout_psi_rms_deg_after": 0.2495},
            },
            {
                "name": "current",
                "parameters": {"V_n": 0.012439, "V_e": -0.0033817, "speed": 0.012891},
                "evidence": {"delta_J": -592.98, "t_stat": 10.24},
            },
        ],
        "effect_names": ["rudder_offset", "current"],
        "parameters_before": {"K": 0.73966, "T": 1.58489},
        "parameters_after": {"K": 0.747, "T": 1.6237, "delta0": -0.005685, "V_n": 0.012439},
        "key_parameters": {"K": 0.73966, "T": 1.58489},
        "window_s": None,
        "runtime_s": 50.8,
        "warnings": [],
    }


def _rows() -> list[dict[str, Any]]:
    failed = {
        "record": "usv/turnningdata_xy.csv",
        "label": "USV turnningdata_xy",
        "source": "usv",
        "file": "turnningdata_xy.csv",
        "samples_total": 174,
        "duration_total_s": 125.5,
        "dt_s": 0.5,
        "repairs": ["a repair"],
        "span_s": None,
        "model": "nomoto1",
        "status": "failed",
        "message": "ValueError: record too short to split: 30 samples",
    }
    gunnerus_n = {
        **_ok_row(),
        "record": "gunnerus/RVG_ManeuveringTests.csv",
        "label": "Gunnerus RVG_ManeuveringTests",
        "source": "gunnerus",
        "file": "RVG_ManeuveringTests.csv",
        "samples": 17701,
        "duration_s": 8850.0,
        "window_s": 300.0,
        "effects": [],
        "effect_names": [],
        "error_after": {"psi_rms_deg": 3.7889, "r_rms_deg_s": 0.68354, "xy_rms_m": 1.4476},
        "heldout": {
            "from_s": 6195.0,
            "error_before": {"psi_rms_deg": 12.5, "r_rms_deg_s": 0.4},
            "error_after": {"psi_rms_deg": 12.5, "r_rms_deg_s": 0.4},
        },
    }
    gunnerus_rvg = {
        **gunnerus_n,
        "model": "rvg3dof",
        "window_s": 60.0,
        "error_seed001": {"psi_rms_deg": 41.0, "r_rms_deg_s": 1.5, "xy_rms_m": 80.0},
        "error_before": {"psi_rms_deg": 6.0, "r_rms_deg_s": 0.5, "xy_rms_m": 20.0},
        "error_after": {"psi_rms_deg": 4.0, "r_rms_deg_s": 0.3, "xy_rms_m": 9.0},
        "heldout": {
            "from_s": 6180.0,
            "error_seed001": {"psi_rms_deg": 44.0, "r_rms_deg_s": 1.6, "u_rms_m_s": 1.2},
            "error_before": {"psi_rms_deg": 7.0, "r_rms_deg_s": 0.6, "u_rms_m_s": 0.5},
            "error_after": {"psi_rms_deg": 5.0, "r_rms_deg_s": 0.4, "u_rms_m_s": 0.3},
        },
        "effects": [
            {
                "name": "current",
                "parameters": {"V_n": 0.1, "V_e": -0.2, "speed": 0.2236},
                "evidence": {"delta_J": -900.0, "heldout_rms_before": {"psi": 0.12, "r": 0.01}},
            }
        ],
        "effect_names": ["current"],
        "parameters_before": {"bollard_thrust": 1.3},
        "parameters_after": {"bollard_thrust": 1.2, "V_n": 0.1, "V_e": -0.2},
        "key_parameters": {},
    }
    skipped = {
        "record": "shipgym.sysid.generator/rvg.csv",
        "label": "generated rvg",
        "source": "shipgym.sysid.generator",
        "file": "rvg.csv",
        "samples_total": 1201,
        "model": "rvg3dof",
        "status": "skipped",
        "message": "base rvg3dof unavailable: no rvg3dof family registered",
    }
    return [_ok_row(), failed, gunnerus_n, gunnerus_rvg, skipped]


# ----------------------------------------------------------------------------------------------
# Markdown


def test_render_table_formats_numbers_effects_and_failures() -> None:
    table = render_table(_rows())
    lines = table.splitlines()
    assert len(lines) == 2 + 5
    assert lines[0].startswith("| record | model | samples | window | ψ RMS [deg]")
    sspa = lines[2]
    cells = [c.strip() for c in sspa.strip("|").split("|")]
    assert cells[:4] == ["SSPA example_zigzag", "nomoto1", "2073", "—"]
    assert cells[4] == "3.79 → 0.448"  # psi, 3 significant digits
    assert cells[5] == "0.684 → 0.31"  # r
    assert cells[6] == "1.45 → 0.476"  # xy
    assert cells[7] == "0.714 → 0.242"  # held-out psi
    assert cells[8] == "rudder_offset, current"
    assert cells[9:] == ["0.74", "1.58"]  # base K [1/s], T [s] (seed 000: 0.74, 1.6)
    assert "**failed**: ValueError: record too short to split" in lines[3]
    assert "| 300 s |" in lines[4] and "| none |" in lines[4]  # windowed, no effect
    assert "| Gunnerus RVG_ManeuveringTests | rvg3dof | 17701 | 60 s | 6 → 4 |" in lines[5]
    assert lines[5].endswith("| current | — | — |")  # no K, T for the RVG model
    assert "**skipped**: base rvg3dof unavailable" in lines[6]
    assert all(line.count("|") == lines[0].count("|") for line in lines)


def test_render_markdown_and_document() -> None:
    rows = _rows()
    block = render_markdown(rows, doc_link="docs/identification.md")
    assert block.startswith("4 records, 5 identifications (3 ok).")
    assert (
        "Gunnerus RVG_ManeuveringTests `rvg3dof` against the published seed-001 model: ψ RMS 41 "
        "deg over the record; on the held-out part (from 6180 s) ψ RMS 44 deg with seed 001, "
        "7 deg calibrated, 5 deg with the effects (current)."
    ) in block
    assert render_table(rows) in block
    assert "[docs/identification.md](docs/identification.md)" in block

    doc = render_document(
        rows,
        figures={("sspa/example_zigzag.csv", "nomoto1"): "identification_sspa.png"},
        config={"holdout": 0.3},
    )
    assert doc.startswith("# System identification of every measured record")
    assert "Settings: holdout = `0.3`." in doc
    assert render_table(rows) in doc
    for heading in ("## SSPA example_zigzag", "## USV turnningdata_xy", "### rvg3dof"):
        assert heading in doc
    # all parameters with units, the rudder offset also in degrees, evidence and held-out part
    assert "K = 0.7397 1/s, T = 1.585 s" in doc
    assert f"delta0 = -0.005685 rad ({math.degrees(-0.005685):.3g} deg)" in doc
    assert "1. `rudder_offset`:" in doc and "2. `current`: V_n = 0.01244 m/s" in doc
    assert "t_stat 10.2" in doc
    assert "| held-out (from 29 s) | 0.714 → 0.242 | 0.299 → 0.282 |" in doc
    assert "![SSPA example_zigzag nomoto1](identification_sspa.png)" in doc
    assert "1 loader repair(s): a repair" in doc
    # the Gunnerus section explains before/after on the held-out part, failures included
    assert "`nomoto1`: held-out from t = 6195 s to the end (8850 s)" in doc
    assert "over consecutive 300 s windows" in doc
    assert (
        "`rvg3dof`: held-out from t = 6180 s to the end (8850 s); heading RMS there (seed 001 → "
        "before → after) 44 deg → 7 deg → 5 deg, yaw rate 1.6 → 0.6 → 0.4 deg/s, surge "
        "1.2 → 0.5 → 0.3 m/s."
    ) in doc
    assert "| part (seed 001 → before → after) | ψ RMS [deg] |" in doc
    assert "| whole record | 41 → 6 → 4 | 1.5 → 0.5 → 0.3 | 80 → 20 → 9 | — |" in doc
    assert "heldout_rms_before.psi 0.12" in doc  # nested evidence flattened
    assert "## generated rvg" in doc and "**skipped**: base rvg3dof unavailable" in doc
    assert "**failed**: ValueError: record too short" in doc


def test_merge_rows_replaces_same_record_and_model() -> None:
    rows = _rows()
    new = {**rows[0], "runtime_s": 1.0}
    merged = merge_rows(rows, [new])
    assert len(merged) == len(rows)
    assert [r["source"] for r in merged][:4] == ["sspa", "usv", "gunnerus", "gunnerus"]
    assert merged[0]["runtime_s"] == 1.0
    assert [r["model"] for r in merged[2:4]] == ["nomoto1", "rvg3dof"]
    assert merge_rows([], list(reversed(rows))) == merge_rows(rows, [])


# ----------------------------------------------------------------------------------------------
# README block


def test_replace_between_markers_is_idempotent_and_strict(tmp_path: Path) -> None:
    text = "# Title\n\nintro\n<!-- identification -->\nold table\n<!-- /identification -->\nend\n"
    once = replace_between_markers(text, "identification", "| a |\n|---|\n")
    assert once == "# Title\n\nintro\n<!-- identification -->\n| a |\n|---|\n" + (
        "<!-- /identification -->\nend\n"
    )
    assert replace_between_markers(once, "identification", "| a |\n|---|\n") == once
    with pytest.raises(ValueError, match=r"exactly one '<!-- identification -->'.*found 0"):
        replace_between_markers("no markers\n", "identification", "x")
    with pytest.raises(ValueError, match="found 2"):
        replace_between_markers(text + "<!-- identification -->", "identification", "x")
    with pytest.raises(ValueError, match="comes before"):
        replace_between_markers(
            "<!-- /identification -->\n<!-- identification -->\n", "identification", "x"
        )

    readme = tmp_path / "README.md"
    readme.write_text(text)
    assert update_block(readme, "new") is True
    assert update_block(readme, "new") is False
    assert readme.read_text().count("new") == 1 and "old table" not in readme.read_text()
    bare = tmp_path / "BARE.md"
    bare.write_text("# nothing\n")
    with pytest.raises(ValueError, match=r"BARE\.md: expected exactly one"):
        update_block(bare, "new")
    assert bare.read_text() == "# nothing\n"


# ----------------------------------------------------------------------------------------------
# identify_all


def _csv_records(tmp_path: Path) -> list[Record]:
    rec = generate_record("rudder_offset", dt=1.0, duration=300.0, seed=0)
    rec = Record(**rec.channels(), meta={**rec.meta, "file": "offset.csv"})
    short = Record(
        **{k: v[:30] for k, v in rec.channels().items()}, meta={**rec.meta, "file": "short.csv"}
    )
    for r in (rec, short):
        r.to_csv(tmp_path / r.meta["file"])
    return [load(p) for p in sorted(tmp_path.glob("*.csv"))]


def test_identify_all_on_canonical_csvs(tmp_path: Path) -> None:
    records = _csv_records(tmp_path)
    lines: list[str] = []
    seen: list[tuple[str, list[str]]] = []
    rows = identify_all(
        records=records,
        max_effects=1,
        progress=lines.append,
        on_result=lambda rec, res, row: seen.append((row["record"], res.effect_names)),
    )
    # nomoto1 on both; rvg3dof applies to neither (no pod channels)
    assert [(r["file"], r["model"], r["status"]) for r in rows] == [
        ("offset.csv", "nomoto1", "ok"),
        ("short.csv", "nomoto1", "failed"),
    ]
    ok, failed = rows
    assert ok["record"] == "shipgym.sysid.generator/offset.csv"
    assert ok["samples"] == 301 and ok["span_s"] is None
    assert ok["effect_names"] == ["rudder_offset"]
    assert abs(ok["effects"][0]["parameters"]["delta0"]) == pytest.approx(math.radians(2), rel=0.3)
    assert ok["error_after"]["psi_rms_deg"] < ok["error_before"]["psi_rms_deg"]
    assert ok["heldout"]["from_s"] == pytest.approx(210.0, abs=1.0)
    assert set(ok["key_parameters"]) == {"K", "T"}
    assert ok["runtime_s"] > 0.0
    assert "record too short to split" in failed["message"]
    assert failed["message"].startswith("ValueError:")
    assert seen == [("shipgym.sysid.generator/offset.csv", ["rudder_offset"])]
    assert lines[0].startswith("[1/2] shipgym.sysid.generator/offset.csv nomoto1 (301 samples")
    assert any("done in" in m and "effects: rudder_offset" in m for m in lines)
    assert any(m.startswith("[2/2]") and "FAILED" in m for m in lines)
    # the rows are JSON and render
    path = write_json({"rows": rows}, tmp_path / "out" / "identification.json")
    assert json.loads(path.read_text())["rows"][0]["effect_names"] == ["rudder_offset"]
    assert "rudder_offset" in render_table(rows)

    only = identify_all(records=records, only="SHORT", progress=False)
    assert [r["file"] for r in only] == ["short.csv"]
    with pytest.raises(ValueError, match="exactly one of root"):
        identify_all(progress=False)
    with pytest.raises(ValueError, match="models"):
        identify_all(records=records, models=(), progress=False)


def test_rvg3dof_applies_to_pod_records_and_is_skipped_when_unavailable(monkeypatch) -> None:
    rvg = generate_record(None, base_model="rvg3dof", dt=1.0, duration=200.0)
    nomoto = generate_record(None, dt=1.0, duration=200.0)
    assert model_applies("rvg3dof", rvg) and not model_applies("rvg3dof", nomoto)
    assert model_applies("nomoto1", rvg) and model_applies("nomoto1", nomoto)

    def never(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("identify must not run for a skipped base")

    monkeypatch.setattr(report, "rvg_available", lambda: False)
    rows = identify_all(
        records=[rvg, nomoto], models=("rvg3dof",), progress=False, identify_fn=never
    )
    assert len(rows) == 1
    assert rows[0]["status"] == "skipped" and "rvg3dof family" in rows[0]["message"]


def test_prepare_record_cuts_to_the_marked_manoeuvre() -> None:
    t = np.arange(0.0, 100.0, 0.5)
    z = np.zeros_like(t)
    rec = Record(t, z, z, z, meta={"manoeuvre_start_s": 10.0, "manoeuvre_end_s": 60.0})
    cut, span = prepare_record(rec)
    assert span == [10.0, 60.0]
    assert cut.time[0] == 10.0 and cut.time[-1] == 60.0
    plain = Record(t, z, z, z)
    assert prepare_record(plain) == (plain, None)


# ----------------------------------------------------------------------------------------------
# figures and benchmark formatting


def test_plot_summary_writes_png(tmp_path: Path) -> None:
    path = plot_summary(_rows(), tmp_path / "identification.png")
    assert path.read_bytes()[:8] == PNG_MAGIC and path.stat().st_size > 10_000


def test_benchmark_table_and_plot(tmp_path: Path) -> None:
    rep = {
        "system": {"cpu_count": 2, "numba": "0.0"},
        "results": [
            {
                "name": "fit",
                "description": "nomoto1 output-error fit",
                "samples": 10001,
                "goal_s": 1.0,
                "times_s": [0.4, 0.5, 0.45],
                "median_s": 0.45,
                "ratio": 0.45,
                "met": True,
                "skipped": None,
            },
            {
                "name": "loop",
                "description": "identify loop",
                "samples": 10001,
                "goal_s": 10.0,
                "times_s": [25.0],
                "median_s": 25.0,
                "ratio": 2.5,
                "met": False,
                "skipped": None,
            },
            {
                "name": "gunnerus",
                "description": "identify rvg3dof",
                "samples": None,
                "goal_s": 60.0,
                "times_s": [],
                "median_s": None,
                "ratio": None,
                "met": None,
                "skipped": "no rvg3dof family registered",
            },
        ],
    }
    rep["replays"] = [
        {
            "name": "rvg3dof, Gunnerus sea trials", "samples": 17701, "columns": 8,
            "one_at_a_time_s": [1.0, 1.2, 0.9], "side_by_side_s": [0.25, 0.4, 0.3],
            "speedup": 3.0,
        }
    ]  # fmt: skip
    table = format_benchmark(rep)
    assert "| rvg3dof, Gunnerus sea trials | 17701 | 8 | 1.000 | 0.300 | 3.00 x |" in table
    assert "| nomoto1 output-error fit | 10001 | 0.450 | 3 | 1 | 0.450 | met |" in table
    assert "| identify loop | 10001 | 25.000 | 1 | 10 | 2.500 | missed |" in table
    assert "skipped: no rvg3dof family registered" in table
    path = plot_benchmark(rep, tmp_path / "bench_sysid.png")
    assert path.read_bytes()[:8] == PNG_MAGIC


def test_benchmark_sysid_smoke() -> None:
    lines: list[str] = []
    rep = benchmark_sysid(None, repeats=1, duration=20.0, progress=lines.append)
    fit, loop, gunnerus, hsva_regression, hsva_loop = rep["results"]
    assert hsva_regression["skipped"] == hsva_loop["skipped"] == "HSVA records not found (None)"
    assert (fit["name"], fit["samples"], len(fit["times_s"])) == ("fit", 201, 3)
    assert loop["samples"] == 201 and loop["details"]["effect"] == "rudder_lag"
    for r in (fit, loop):
        assert r["median_s"] > 0.0 and r["ratio"] == pytest.approx(r["median_s"] / r["goal_s"])
    assert gunnerus["median_s"] is None and gunnerus["skipped"] == "no measured-data root given"
    assert rep["config"]["duration_s"] == 20.0
    assert any(m.startswith("fit ") and "goal 1 s" in m for m in lines)
    nomoto, rvg = rep["replays"]
    assert (nomoto["columns"], rvg["columns"]) == (4, 8)
    assert rvg["name"] == "rvg3dof, generated record"  # no measured-data root
    for r in (nomoto, rvg):
        assert len(r["one_at_a_time_s"]) == len(r["side_by_side_s"]) == 5
        ratios = [a / b for a, b in zip(r["one_at_a_time_s"], r["side_by_side_s"], strict=True)]
        assert r["speedup"] == pytest.approx(sorted(ratios)[2])
    assert sum(m.startswith("replays ") for m in lines) == 10
    json.dumps(rep)


MEASURED = measured_root()


@pytest.mark.skipif(
    not MEASURED.is_dir(),
    reason=f"measured data not found at {MEASURED} (set SHIPGYM_MEASURED_DATA)",
)
def test_identify_all_reads_the_measured_root() -> None:
    rows = identify_all(MEASURED, only="esso_osaka/zigzag_31-Jul-2020_13_57", max_effects=0)
    # nomoto1 on every record, the 3-DOF model on a ship whose particulars are known
    assert [r["model"] for r in rows] == ["nomoto1", "vmm:martin_simple"]
    row, row3 = rows
    assert row3["status"] == "ok", row3.get("message")
    assert "X_T" in row3["parameters_after"]
    assert row["status"] == "ok", row.get("message")
    assert row["label"] == "Esso Osaka zigzag_31-Jul-2020_13_57_45"
    assert row["manoeuvre"] == "zigzag"
    # cut to the manoeuvre marked by the loader (starts from rest, ends coasting): from 5 s
    # before the step of the first order to 19.5 deg (the hand had the rudder at 10-12 deg)
    assert row["span_s"] == pytest.approx([21.5, 112.2])
    assert row["samples"] < row["samples_total"]
    assert row["effects"] == [] and row["error_after"] == row["error_before"]
    assert row["key_parameters"]["K"] > 0.0  # starboard-positive rudder: K > 0

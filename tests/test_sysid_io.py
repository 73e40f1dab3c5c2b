"""The loader registry and format detection (shipgym.sysid.io)."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import shipgym.sysid.io as sysid_io
from shipgym.sysid.data import FORMATS, Record, SysidDataWarning, detect_format, load
from shipgym.sysid.io.registry import REGISTRY, SourceFormat, register


def _table(path: Path, header: str, n: int = 40) -> Path:
    """A 10/10 zigzag-like table: rudder +-10 deg, heading following at 1 deg/s, 0.5 s steps."""
    t = 0.5 * np.arange(n)
    rudder = np.where((t // 5) % 2 == 0, 10.0, -10.0)
    heading = 30.0 + np.cumsum(np.where(rudder > 0, 0.5, -0.5)) - 0.5
    rate = np.where(rudder > 0, 1.0, -1.0)
    rows = [f"{a:g},{b:g},{c:g},{d:g}" for a, b, c, d in zip(t, rudder, heading, rate, strict=True)]
    path.write_text(header + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path


def test_a_table_whose_first_column_is_time_s_goes_to_the_table_loader(tmp_path: Path) -> None:
    path = _table(tmp_path / "run.csv", "time_s,rudder_deg,heading_deg,yaw_rate_deg_s")
    assert detect_format(path) == "table"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidDataWarning)
        rec = load(path)
    assert rec.meta["source"] == "table"
    assert rec.delta[0] == pytest.approx(math.radians(10.0))
    assert rec.psi[0] == pytest.approx(math.radians(30.0))
    np.testing.assert_allclose(np.abs(rec.r), math.radians(1.0))


def test_any_first_column_of_a_plain_table_goes_to_the_table_loader(tmp_path: Path) -> None:
    for first in ("t_s", "time [s]", "elapsed_s", "x"):
        path = _table(tmp_path / "run.csv", f"{first},rudder_deg,heading_deg,r_deg_s")
        assert detect_format(path) == "table", first


def test_canonical_files_are_still_canonical(tmp_path: Path) -> None:
    """With the magic line, or with only canonical columns after ``#`` meta lines."""
    t = np.arange(20) * 0.5
    rec = Record(time=t, delta=0.1 * np.sin(t), psi=0.01 * t, r=np.full(20, 0.01))
    path = rec.to_csv(tmp_path / "rec.csv")
    assert detect_format(path) == "canonical"
    lines = path.read_text().splitlines()
    bare = tmp_path / "bare.csv"
    bare.write_text("\n".join(["# L: 7.0", *lines[1:]]) + "\n")
    assert detect_format(bare) == "canonical"
    assert load(bare).meta["L"] == 7.0


def test_every_format_is_registered_once_with_its_module() -> None:
    assert FORMATS == tuple(REGISTRY) == sysid_io.FORMATS
    assert FORMATS == (
        "sspa",
        "marin",
        "hsva",
        "esso_osaka",
        "usv",
        "gunnerus",
        "canonical",
        "nmea",
        "table",
    )
    assert [f.name for f in REGISTRY.values() if f.fallback] == ["nmea", "table"]
    with pytest.raises(ValueError, match="format 'table' is registered already"):
        register(REGISTRY["table"])


def test_a_registered_format_is_detected_and_loaded(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A format of one's own: a header sniffer and a loader, asked before the fallbacks."""

    def load_mine(path: Path, say: object) -> Record:
        values = np.loadtxt(path, skiprows=1)
        return Record(time=values[:, 0], delta=values[:, 1], psi=values[:, 2], r=values[:, 3])

    mine = SourceFormat("mine", load_mine, lambda head: head.startswith("MINE"))
    monkeypatch.setitem(REGISTRY, "mine", mine)
    path = tmp_path / "a.txt"
    path.write_text("MINE v1\n0 0 0 0\n1 0.1 0.01 0.01\n2 0.1 0.02 0.01\n")
    assert detect_format(path) == "mine"
    assert load(path).n == 3


def test_options_go_only_to_the_formats_that_take_them(tmp_path: Path) -> None:
    t = np.arange(20) * 0.5
    path = Record(time=t, delta=0.1 * np.sin(t), psi=0.01 * t, r=np.full(20, 0.01)).to_csv(
        tmp_path / "rec.csv"
    )
    with pytest.raises(ValueError, match="max_gap_s applies to the formats nmea and table"):
        load(path, max_gap_s=2.0)
    with pytest.raises(ValueError, match="unknown format 'xls'; accepted formats: sspa, marin"):
        load(path, "xls")

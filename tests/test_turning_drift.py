"""The drift of a turning circle over its steady turn (the classic trial correction for wind
and current) and ``shipgym simulate ... --wind``."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import pytest

from shipgym import maneuvers as mv
from shipgym.cli import main
from shipgym.models import make_model


def _kvlcc2_in_wind(speed: float, from_deg: float):
    params = make_model("kvlcc2").params
    wind = dataclasses.replace(params, wind_speed=speed, wind_direction=math.radians(from_deg))
    return make_model("kvlcc2", wind)


@pytest.mark.parametrize("model", ["kvlcc2", "nomoto1"])
def test_a_turn_in_calm_water_closes(model: str) -> None:
    res = mv.turning_circle(model, 35.0)
    assert math.hypot(*res.drift) < 1e-3 * res.particulars.length


def test_the_wind_drifts_the_turn_downwind_and_grows_with_its_square() -> None:
    offsets: dict[float, list[float]] = {1.0: [], 2.0: []}
    for from_deg in (0.0, 90.0, 225.0):
        light, fresh = (mv.turning_circle(_kvlcc2_in_wind(v, from_deg), 35.0) for v in (1.0, 2.0))
        downwind = math.radians(from_deg + 180.0)
        for speed, res in ((1.0, light), (2.0, fresh)):
            off = math.remainder(res.drift_direction - downwind, 2 * math.pi)
            assert abs(off) < math.radians(45.0), math.degrees(res.drift_direction)
            offsets[speed].append(off)
        # the wind load grows with the square of the apparent wind: twice the wind, about four
        # times the drift (less: the drift itself takes some of the wind)
        assert 3.0 < math.hypot(*fresh.drift) / math.hypot(*light.drift) < 4.5
    # at a given wind speed the drift leans the same way off downwind whichever way the wind
    # blows (24-33 deg here: the ship is slower with its bow into the wind than before it)
    for off in offsets.values():
        assert max(off) - min(off) < math.radians(4.0)


def test_simulate_turning_in_wind_reports_the_drift(tmp_path: Path, capsys) -> None:
    out = tmp_path / "turn.json"
    argv = ["simulate", "turning", "--model", "kvlcc2", "--wind", "2,90", "--json", str(out)]
    assert main(argv) == 0
    assert "drift over the steady turn" in capsys.readouterr().out
    doc = json.loads(out.read_text())
    expected = mv.turning_circle(_kvlcc2_in_wind(2.0, 90.0), 35.0)
    assert doc["drift_m"] == pytest.approx(list(expected.drift), rel=1e-5)
    assert doc["drift_speed_m_s"] > 0.0


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--model", "kvlcc2", "--wind", "5"], "must be SPEED,DIR"),
        (["--model", "kvlcc2", "--wind=-1,90"], "[0, 30] m/s"),
    ],
)
def test_bad_wind_is_refused_in_one_line(argv: list[str], message: str, capsys) -> None:
    assert main(["simulate", "turning", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err

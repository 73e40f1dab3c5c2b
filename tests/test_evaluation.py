"""Closed-loop behaviour of the classic controllers on the environments, and ``shipgym evaluate``.

Issue 3, section 4: LOS with the conditional integrator in a cross current (with its
ablation), the Gunnerus heading autopilot in current, target tracking, and the classic
controller beating the ``zero`` baseline on every env.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from shipgym.benchmark import evaluate, make_policy
from shipgym.benchmark.policies import (
    RVGHeadingClassic,
    RVGPathClassic,
    RVGTargetClassic,
)
from shipgym.cli import main
from shipgym.envs import CURRENT_ENV_IDS, ENV_IDS, env_task
from shipgym.models.rvg import LPP, SERVICE_SPEED


def _quiet(line: str) -> None:
    pass


def _straight_run(integral: bool) -> tuple[np.ndarray, np.ndarray]:
    """The Gunnerus on a 3.5 km northbound leg in a 0.5 m/s current toward the east."""
    options = {
        "waypoints": [[0.0, 0.0], [3500.0, 0.0]],
        "current_speed": 0.5,
        "current_direction": math.pi / 2,
        "initial_state": {"psi": 0.0, "u": SERVICE_SPEED, "T1": 25e3, "T2": 25e3},
    }
    policy = RVGPathClassic(integral=integral)  # the classic controller, lookahead 3 L
    result = evaluate(
        "shipgym/RVGPathFollowing-v0",
        policy,
        "classic",
        1,
        0,
        reset_options=options,
        progress=_quiet,
    )
    log = result.logs[0]
    return np.asarray(log.time), log.signal("cross_track_error")


def test_los_conditional_integrator_removes_the_cross_track_error_in_current() -> None:
    t, e = _straight_run(integral=True)
    steady = np.abs(e[t > t[-1] - 150.0])
    assert steady.mean() < 0.5
    assert steady.max() < 1.0
    # the ablation: the same LOS without the integrator keeps a steady error
    t0, e0 = _straight_run(integral=False)
    steady0 = np.abs(e0[t0 > t0[-1] - 150.0])
    assert steady0.min() > 2.0
    # and the error it keeps is the crab-angle error of proportional LOS, e = Delta tan(beta)
    beta = math.asin(0.5 / SERVICE_SPEED)
    assert steady0.mean() == pytest.approx(
        RVGPathClassic.DESIGN["lookahead_lengths"] * LPP * math.tan(beta), rel=0.05
    )


@pytest.mark.parametrize("direction_deg", [0.0, 90.0, 180.0, 270.0])
def test_rvg_heading_autopilot_30_deg_step_in_current(direction_deg: float) -> None:
    step = math.radians(30.0)
    options = {
        "setpoints": [step],
        "current_speed": 0.5,
        "current_direction": math.radians(direction_deg),
        "initial_state": {"psi": 0.0, "u": SERVICE_SPEED, "T1": 25e3, "T2": 25e3},
    }
    result = evaluate(
        "shipgym/RVGHeading-v0",
        RVGHeadingClassic(),
        "classic",
        1,
        0,
        reset_options=options,
        progress=_quiet,
    )
    log = result.logs[0]
    t = np.asarray(log.time)
    error_deg = np.degrees(log.signal("heading_error"))  # setpoint minus heading
    overshoot = max(0.0, -float(error_deg.min()))
    outside = np.flatnonzero(np.abs(error_deg) > 2.0)
    settled_at = t[outside[-1] + 1] if outside.size else 0.0
    assert overshoot < 5.0
    assert settled_at < 120.0


def test_target_tracking_closes_and_holds_the_distance() -> None:
    options = {
        "target_position": [500.0, 400.0],
        "target_velocity": [0.0, 2.0],  # east at 2 m/s
        "distance": 50.0,
        "current_speed": 0.3,
        "current_direction": math.radians(45.0),
        "initial_state": {"psi": 0.0, "u": SERVICE_SPEED, "T1": 25e3, "T2": 25e3},
    }
    result = evaluate(
        "shipgym/RVGTargetTracking-v0",
        RVGTargetClassic(),
        "classic",
        1,
        0,
        reset_options=options,
        progress=_quiet,
    )
    log = result.logs[0]
    t = np.asarray(log.time)
    distance = log.signal("distance")
    assert distance[0] > 500.0
    intercept = result.per_episode[0]["time_to_intercept_s"]
    assert intercept < 500.0  # 640 m away, closing at about 1.5 m/s
    held = distance[t > intercept + 100.0]
    assert held.size > 100
    assert np.all(np.abs(held - 50.0) < 5.0)  # within 10 % of the set distance
    assert distance.min() > 25.0  # never on a collision course


#: For each env: (metric, classic must be below this fraction of zero's value).
_MARGIN = {
    "NomotoHeading": ("heading_rms_deg", 0.7),
    "RVGHeading": ("heading_rms_deg", 0.5),
    "RVGSpeed": ("speed_rms_m_s", 0.5),
    "RVGPathFollowing": ("cross_track_rms_m", 0.7),
    "RVGTargetTracking": ("distance_error_rms_m", 0.3),
}


#: (env, controller): the design rule on every env but one, and the tuned gains on the newest
#: version of each. (The design rule on the sea-trial Gunnerus's target tracking is the
#: exception the README reports: its turn-rate-limited heading loop has too little authority
#: at the low thrust of the approach.)
_BEATS_ZERO = [(e, "classic") for e in ENV_IDS if e != "shipgym/RVGTargetTracking-v1"] + [
    (e, "classic-tuned") for e in CURRENT_ENV_IDS
]


@pytest.mark.parametrize(("env_id", "controller"), _BEATS_ZERO)
def test_classic_beats_zero_by_a_wide_margin(env_id: str, controller: str) -> None:
    policy = make_policy(controller, env_id)
    classic = evaluate(env_id, policy, controller, 3, 500, progress=_quiet)
    zero = evaluate(env_id, make_policy("zero", env_id), "zero", 3, 500, progress=_quiet)
    metric, fraction = _MARGIN[env_task(env_id)]
    assert classic.metrics[metric] < fraction * zero.metrics[metric]
    c, z = classic.to_dict(), zero.to_dict()
    assert c["mean_return"] > z["mean_return"] + 2 * max(c["std_return"], 1.0)
    if env_task(env_id) == "RVGPathFollowing":
        assert classic.metrics["completed"] > zero.metrics["completed"]


def test_same_seeds_give_every_controller_the_same_scenarios() -> None:
    env_id = "shipgym/RVGPathFollowing-v0"
    a = evaluate(env_id, make_policy("classic", env_id), "classic", 2, 7, progress=_quiet)
    b = evaluate(env_id, make_policy("zero", env_id), "zero", 2, 7, progress=_quiet)
    for la, lb in zip(a.logs, b.logs, strict=True):
        assert np.array_equal(la.extras["waypoints"], lb.extras["waypoints"])
        assert la.reset_info["current_speed"] == lb.reset_info["current_speed"]
        assert np.array_equal(la.reset_info["state"], lb.reset_info["state"])


def test_evaluate_command_writes_json_and_plots(tmp_path: Path) -> None:
    out = tmp_path / "eval.json"
    plots = tmp_path / "plots"
    code = main(
        [
            "evaluate",
            "--env",
            "shipgym/RVGSpeed-v0",
            "--controller",
            "classic",
            "--episodes",
            "2",
            "--seed",
            "3",
            "--json",
            str(out),
            "--plot",
            str(plots),
        ]
    )
    assert code == 0
    summary = json.loads(out.read_text())
    assert summary["env"] == "shipgym/RVGSpeed-v0"
    assert summary["controller"] == "classic"
    assert summary["episodes"] == 2
    assert set(summary) >= {"mean_return", "std_return", "metrics"}
    assert set(summary["metrics"]) == {
        "speed_rms_m_s",
        "settling_time_s",
        "steady_state_m_s",
        "energy_mj",
    }
    assert len(list(plots.glob("*.png"))) == 2


def test_evaluate_rejects_bad_input(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["evaluate", "--env", "shipgym/RVGSpeed-v0", "--controller", "pid"]) == 2
    assert "pid" in capsys.readouterr().err
    assert main(["evaluate", "--env", "nope", "--episodes", "1"]) == 2
    with pytest.raises(ValueError, match="episodes"):
        evaluate("shipgym/RVGSpeed-v0", make_policy("zero", "shipgym/RVGSpeed-v0"), "zero", 0)
    with pytest.raises(ValueError, match="unknown controller"):
        make_policy("dqn", "shipgym/RVGSpeed-v0")


def test_engineering_metrics_against_hand_computed_signals() -> None:
    """Settling time, steady-state error and rudder wear of made-up signals."""
    from shipgym.benchmark.evaluate import HEADING_BAND, _settling, _wear

    dt = 1.0
    setpoint = np.array([0.0] * 10 + [1.0] * 10)
    error = np.zeros(20)
    error[10:14] = [1.0, 0.5, 0.1, 2.0 * HEADING_BAND]  # leaves the band last at sample 13
    error[14:] = 0.01
    settle, ss = _settling(error, setpoint, HEADING_BAND, dt)
    assert settle == pytest.approx((0.0 + 4.0) / 2.0)  # segment 1 settled at once
    assert ss == pytest.approx(np.sqrt(np.mean(np.r_[np.zeros(10), np.full(6, 0.01)] ** 2)))
    # a rudder that swings +-10 deg every minute: 40 deg of travel and 2 reversals per minute
    angle = np.radians(np.r_[np.linspace(0, 10, 16), np.linspace(10, -10, 31)[1:],
                             np.linspace(-10, 0, 16)[1:]])  # fmt: skip
    wear = _wear(angle, 1.0)
    minutes = angle.size / 60.0
    assert wear["rudder_travel_deg_min"] == pytest.approx(40.0 / minutes)
    assert wear["rudder_reversals_min"] == pytest.approx(2.0 / minutes)


class _BlowUpOnOddSeeds:
    """Vector wrapper factory: the ships' states turn non-finite before step 3 of odd-seeded
    episodes (what a diverging integration leaves), so the env ends them as numerical
    blow-ups while the even-seeded episodes beside them go on."""

    def __call__(self, env):
        from gymnasium.vector import VectorWrapper

        class BlowUp(VectorWrapper):
            def reset(self, *, seed=None, options=None):
                self.blow = np.asarray(seed) % 2 == 1
                self.steps = 0
                return super().reset(seed=seed, options=options)

            def step(self, actions):
                self.steps += 1
                if self.steps == 3:
                    self.env.unwrapped.task.x[self.blow, :] = np.nan
                return super().step(actions)

        return BlowUp(env)


def test_blown_up_episodes_are_counted_flagged_and_never_look_good(tmp_path: Path) -> None:
    from shipgym.benchmark.plots import episode_figures
    from shipgym.benchmark.report import metrics_tables, paired_table
    from shipgym.benchmark.runner import _cell

    env_id = "shipgym/RVGTargetTracking-v1"
    result = evaluate(
        env_id,
        make_policy("classic", env_id),
        "classic",
        episodes=4,
        seed=10,
        progress=_quiet,
        wrappers=[_BlowUpOnOddSeeds()],
    )
    assert result.blown_up == 2
    assert result.terminations[1] == result.terminations[3] == "numerical_blow_up"
    assert result.lengths[1] == result.lengths[3] == 3
    assert result.lengths[0] > 3 and result.terminations[0] != "numerical_blow_up"
    d = result.to_dict()
    assert d["blown_up"] == 2 and d["length"] == result.lengths
    # no aggregate of a cell with a blow-up is a number (it would reward blowing up)
    assert math.isnan(d["mean_return"]) and d["return_ci95"] is None
    assert all(math.isnan(v) for v in d["metrics"].values())
    assert all(ci is None for ci in d["metrics_ci95"].values())
    assert math.isnan(d["returns"][1]) and math.isfinite(d["returns"][0])
    assert all(math.isnan(d["per_episode"][k][1]) for k in d["per_episode"])
    assert _cell(result, "return") == "blew up 2/4"
    table = "\n".join(metrics_tables([d]))
    assert "blew up 2/4" in table and "nan" not in table.lower()
    clean = evaluate(env_id, make_policy("zero", env_id), "zero", episodes=4, seed=10,
                     progress=_quiet)  # fmt: skip
    ref = {**clean.to_dict(), "controller": "classic-tuned"}
    assert "blew up 2/4" in "\n".join(paired_table([d, ref]))
    # the episode figure says so
    path, write = episode_figures(result, tmp_path, max_episodes=2)[1]
    write(path)
    assert path.stat().st_size > 10_000

"""Kinematic consistency of a record (:mod:`shipgym.sysid.consistency`): a simulated record's
rates integrate to its heading and track; a scale error on a rate channel is found as that
factor; sensor noise leaves the floor that integrated white noise predicts."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from shipgym.sysid import identify
from shipgym.sysid.consistency import kinematic_consistency
from shipgym.sysid.families.base import window_starts
from shipgym.sysid.generator import MMG_NOISE, generate_mmg_runs, generate_record

WINDOW_S = 60.0


@pytest.fixture(scope="module")
def quiet_runs():
    return generate_mmg_runs(None, noise=False, n_runs=2, seed=1)


def _check(rec):
    return kinematic_consistency(rec, window_starts(rec.time, WINDOW_S))


def test_simulated_rates_integrate_to_the_heading_and_track(quiet_runs) -> None:
    """Noise-free MMG runs (a zigzag and a turn, 0.1 s samples): the integrated yaw rate meets
    the heading within 0.01 deg and the integrated velocities the track within 5 mm; the scales
    are 1 (the turn's every window, the zigzag's where it turns 10 deg)."""
    for rec in quiet_runs:
        c = _check(rec)
        assert c.heading_rms.size == c.samples.size == window_starts(rec.time, WINDOW_S).size
        assert np.max(c.heading_rms) < math.radians(0.01)
        assert np.max(c.position_rms) < 0.005
        turned = np.isfinite(c.yaw_rate_scale)
        assert turned.any()
        np.testing.assert_allclose(c.yaw_rate_scale[turned], 1.0, atol=1e-3)
        np.testing.assert_allclose(c.speed_scale, 1.0, atol=1e-3)


def test_a_scale_error_on_a_rate_channel_is_found_as_that_factor(quiet_runs) -> None:
    """The yaw rate read 10 % high and the speeds 2 % low (knots converted with the wrong
    factor): the scales are 1/1.1 and 1/0.98, and the heading misses by a tenth of what the yaw
    rate turns (a closed form: the integral of 1.1 r less the heading change is 0.1 of it)."""
    rec = quiet_runs[1]  # the 35 deg turn
    bad = replace(rec, r=1.1 * rec.r, u=0.98 * rec.u, v=0.98 * rec.v)
    c, good = _check(bad), _check(rec)
    np.testing.assert_allclose(c.yaw_rate_scale, 1.0 / 1.1, rtol=1e-3)
    np.testing.assert_allclose(c.speed_scale, 1.0 / 0.98, rtol=1e-3)
    for i0, i1, rms in zip(c.starts, np.append(c.starts[1:], rec.time.size), c.heading_rms,
                           strict=True):  # fmt: skip
        change = rec.psi[i0 + 1 : i1] - rec.psi[i0]
        assert rms == pytest.approx(0.1 * math.sqrt(np.mean(change**2)), rel=0.01)
    assert c.pooled_heading_rms() > 100.0 * good.pooled_heading_rms()


def test_noise_leaves_the_floor_of_integrated_white_noise() -> None:
    """With the generator's white noise (heading 0.1 deg, yaw rate 0.05 deg/s at 0.1 s), the
    pooled heading miss is the integrated noise: its mean square over a window of T seconds is
    twice the heading's variance (the sample and the window's start) plus the yaw rate's
    variance times dt T / 2 (a random walk's, averaged over the window): within 12 %."""
    runs = generate_mmg_runs(None, noise=True, n_runs=6, seed=2)
    s_psi, s_r = MMG_NOISE["psi"], MMG_NOISE["r"]
    sq, expected, n = 0.0, 0.0, 0
    for rec in runs:
        c = _check(rec)
        dt = float(np.median(np.diff(rec.time)))
        sq += float(np.sum(c.samples * c.heading_rms**2))
        span = c.samples * dt
        expected += float(np.sum(c.samples * (2.0 * s_psi**2 + s_r**2 * dt * span / 2.0)))
        n += int(np.sum(c.samples))
    assert math.sqrt(sq / n) == pytest.approx(math.sqrt(expected / n), rel=0.12)


def test_pooled_over_chosen_windows_and_without_a_track(quiet_runs) -> None:
    """Pooling weighs each window by its samples; a record without positions has no track
    figures; bad window starts are refused with what was expected."""
    rec = replace(quiet_runs[1], r=1.05 * quiet_runs[1].r)
    c = _check(rec)
    w = np.arange(c.heading_rms.size)
    manual = math.sqrt(np.sum(c.samples * c.heading_rms**2) / np.sum(c.samples))
    assert c.pooled_heading_rms() == pytest.approx(manual)
    assert c.pooled_heading_rms(w[-1:]) == pytest.approx(c.heading_rms[-1])
    assert c.pooled_heading_rms(w == 0) == pytest.approx(c.heading_rms[0])
    bare = _check(replace(rec, x=None, y=None, u=None, v=None, U=None))
    assert bare.position_rms is None and bare.speed_scale is None
    assert math.isnan(bare.pooled_position_rms())
    np.testing.assert_array_equal(bare.heading_rms, c.heading_rms)
    for starts in ([1, 50], [0, 50, 51], [0, rec.time.size - 1], [0.0, 50.0], []):
        with pytest.raises(ValueError, match="starts must be increasing sample indices from 0"):
            kinematic_consistency(rec, np.array(starts))


def test_identify_reports_the_held_out_windows_consistency() -> None:
    """``identify`` reports the record's own consistency over its held-out windows: the pooled
    consistency of exactly those windows. A yaw-rate sensor reading 10 % high raises it to a
    tenth of the heading the held-out windows turn through; a free run (no windows) has
    none."""
    rec = generate_record(None, maneuver="zigzag", seed=3)
    for r_scale in (1.0, 1.1):
        bad = replace(rec, r=r_scale * rec.r)
        res = identify(bad, "nomoto1", window_s=100.0, max_effects=0)
        starts = np.asarray(res.traces["window_starts"])
        c = kinematic_consistency(bad, starts)
        held = c.starts >= res.traces["split"]
        floor = res.heldout["record_consistency"]
        assert floor["psi_rms_deg"] == pytest.approx(
            math.degrees(c.pooled_heading_rms(held)), rel=1e-12
        )
        if r_scale == 1.0:
            assert floor["psi_rms_deg"] < 0.5
        else:
            turned = [bad.psi[i0 + 1 : i1] - bad.psi[i0] for i0, i1 in
                      zip(starts, np.append(starts[1:], bad.n), strict=True)
                      if i0 >= res.traces["split"]]  # fmt: skip
            tenth = 0.1 * math.sqrt(np.mean(np.concatenate(turned) ** 2))
            assert floor["psi_rms_deg"] == pytest.approx(math.degrees(tenth), rel=0.1)
    free = identify(rec, "nomoto1", window_s=None, max_effects=0)
    assert "record_consistency" not in free.heldout

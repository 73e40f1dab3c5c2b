"""Batched task kernels: action mapping, one RK4 step, observations, rewards, terminations.

One kernel per task family, looping over the rows of a batch. The single environment calls
it with one row and the vector environment with many, so both run the same code and the same
physics (:func:`shipgym.models.integrate.rk4_block`). Each kernel loops over blocks of rows:
it maps a block's actions and integrates its rows at once (the SIMD block step), then computes
each row's observation, reward and termination while the block is in cache. A row's result
does not depend on the other rows of the call, so the vector env steps a large batch on
several threads by calling the kernel on a contiguous part of the rows from each
(:func:`run_threaded`; the kernels release the GIL), with bit-identical results.
The speed, path and target tasks sail the R/V Gunnerus alone: their kernels step it by its
model id as a constant, so the other models' code is not compiled into them (12 % faster steps,
a fifth less compile time, than with the model chosen at run time), and they refuse another.
Conventions: NED, heading clockwise from north, SI units and radians; the normalised action
``a`` is clipped to [-1, 1] and mapped to the model input by ``u = u0 + B a``.

At sea (:mod:`shipgym.models.seaway`) a kernel takes the seaway of its rows (``sw``) and their
measured states ``xm``: after each block's step (or at a reset) the seaway sets the block's
measured states and its load of the next step; the observations are formed from ``xm``, the
rewards, terminations and task logic from ``x``. In calm water ``sw[0]`` is False and ``xm``
is ``x`` itself, so nothing changes.

Every task kernel returns the first row whose action is not finite (then nothing was
stepped), or -1. It takes ``advance`` and ``rows`` first: ``advance=True`` steps the whole
batch, ``False`` only computes the observations of the current state (after a reset); either
way only the rows listed in ``rows`` get new observations, rewards, flags and ``reason``
(0 running, 1 numerical blow-up, 2 success, 3 failure). Observations are clipped to the
observation-space bounds. A row whose state is no longer finite after the step, or whose
observation or reward cannot be computed from it (a NaN from an overflow, say a finite position
of 1e308), keeps its previous observation, gets reward 0 and terminates with reason 1: an
observation is always finite and inside the observation space. Every reward is bounded by
construction (each kernel's docstring gives the bounds; the tasks' ``reward_bounds``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from numba.core.dispatcher import Dispatcher

from shipgym.models._jit import kernel, row_kernel
from shipgym.models.angles import ssa_scalar
from shipgym.models.integrate import (
    BLOCK,
    RVG3DOF,
    STATE_COUNTS,
    block_work,
    gather_rows,
    rk4_block,
    rk4_block_of,
    rk4_block_rvg,
    scatter_rows,
)
from shipgym.models.rvg import P_TBOLL
from shipgym.models.seaway import seaway_block
from shipgym.models.vmath import sincos

RUNNING, BLOW_UP, SUCCESS, FAILURE = 0, 1, 2, 3
#: Batches at least this large are split over the threads of :func:`run_threaded`.
THREADED_MIN_ROWS = 64
REASONS = ("running", "numerical_blow_up", "success", "failure")


@kernel
def first_nonfinite_row(a):
    """Index of the first row of ``a`` holding a NaN or infinity, or -1."""
    finite = True
    for v in a.ravel():  # (a loop without an early exit: SIMD code)
        finite &= math.isfinite(v)
    if finite:
        return -1
    for i in range(a.shape[0]):
        for k in range(a.shape[1]):
            if not math.isfinite(a[i, k]):
                return i
    return -1


@row_kernel
def _require_rvg(model_id):
    """Refuse a ship other than the R/V Gunnerus in the kernels of the Gunnerus tasks."""
    if model_id != RVG3DOF:
        raise ValueError("the speed, path and target tasks sail the R/V Gunnerus (rvg3dof)")


# The loops over a row's states, inputs, actions and observations have their counts as
# compile-time constants (the Gunnerus tasks' own, and each ship family's in the heading task):
# a loop of a few iterations whose count is known at run time only is not unrolled, and keeps
# the row logic from compiling to straight-line code (with the rows' new observations written
# once, the NomotoHeading task kernel 82-85 -> 56-59 ns per sub-env).
#: States and inputs of the R/V Gunnerus.
NX_RVG, NU_RVG = STATE_COUNTS[RVG3DOF], 4
#: (actions, observations) of the Gunnerus tasks' kernels: their tasks' ``act_dim, obs_dim``.
SPEED_DIMS, PATH_DIMS, TARGET_DIMS = (1, 4), (2, 9), (2, 10)
#: (states, inputs, actions, observations) of the ship families the heading task sails: a
#: first- and a second-order Nomoto-family ship and the Gunnerus (another count runs the same
#: code with its counts known at run time only).
FIRST_ORDER, SECOND_ORDER, GUNNERUS = (6, 2, 1, 3), (7, 2, 1, 3), (NX_RVG, NU_RVG, 1, 5)
HEADING_DIMS = (FIRST_ORDER, SECOND_ORDER, GUNNERUS)


@row_kernel
def _map_and_gather(x, u, c, a, u0, B, steps, rows, start, n, work, nx, nu, na):
    """Clip the actions of rows ``rows[start .. start + n - 1]`` (``na`` each) to [-1, 1], map
    them to inputs (``u = u0 + B a``), count their step and copy the rows into the block work
    arrays ``work`` (:func:`~shipgym.models.integrate.block_work`) for the RK4 step."""
    for j in range(start, start + n):
        i = rows[j]
        for k in range(na):
            a[i, k] = min(max(a[i, k], -1.0), 1.0)
        for q in range(nu):
            acc = u0[q]
            for k in range(na):
                acc += B[q, k] * a[i, k]
            u[i, q] = acc
        steps[i] += 1
    gather_rows(x, u, c, rows, start, n, work[0], work[1], work[2], nx, nu)


@row_kernel
def _advance_block(x, u, p, c, dt, a, u0, B, steps, rows, start, n, work, na):
    """:func:`_map_and_gather`, one RK4 step of the block by the Gunnerus's own RK4
    (:func:`~shipgym.models.integrate.rk4_block_rvg`) and the states copied back, for a
    Gunnerus task with ``na`` actions."""
    _map_and_gather(x, u, c, a, u0, B, steps, rows, start, n, work, NX_RVG, NU_RVG, na)
    rk4_block_of(rk4_block_rvg, RVG3DOF, work[0], work[1], p, work[2], dt, n, work[3])
    scatter_rows(work[0], rows, start, n, x, NX_RVG)


# The row logic of the task kernels works a block of rows at a time: a helper that takes arrays
# costs reference counting at every call, once per block here rather than once per row.


@row_kernel
def _begin_block(x, a, rows, start, n, ok, cost, rew, term, reason, nx, na):
    """Start the row logic of rows ``rows[start .. start + n - 1]`` (``nx`` states, ``na``
    actions): clear their flags and keep the squared norm of their actions in ``cost``;
    ``ok[b]`` False (and the row terminated with a blow-up) where the state of the ``b``-th is
    not finite."""
    for b in range(n):
        i = rows[start + b]
        reason[i] = RUNNING
        term[i] = False
        s = 0.0
        for k in range(na):
            s += a[i, k] * a[i, k]
        cost[b] = s
        finite = True
        for j in range(nx):
            finite &= math.isfinite(x[i, j])
        ok[b] = finite
        if not finite:
            rew[i] = 0.0
            term[i] = True
            reason[i] = BLOW_UP


@row_kernel
def _finish_block(obs, rows, start, n, ok, lo, hi, new, rew, term, reason, nobs):
    """Write the ``nobs`` new observations ``new`` of the block's rows (those with ``ok``) into
    ``obs``, clipped to the observation-space bounds.

    A NaN in the new observation or the reward (a finite state whose observation overflowed)
    ends the row as a blow-up: it keeps the observation it had before, reward 0.
    """
    for b in range(n):
        if not ok[b]:
            continue
        i = rows[start + b]
        bad = math.isnan(rew[i])
        for k in range(nobs):
            bad |= math.isnan(new[b, k])
        if bad:
            rew[i] = 0.0
            term[i] = True
            reason[i] = BLOW_UP
        else:
            for k in range(nobs):
                obs[i, k] = min(max(new[b, k], lo[k]), hi[k])


@row_kernel
def _row_work(obs_dim):
    """Scratch of the row logic of one block: ``ok``, the new observations and ``cost``."""
    return np.empty(BLOCK, dtype=np.bool_), np.empty((BLOCK, obs_dim)), np.empty(BLOCK)


@row_kernel
def _seaway(sw, rows, start, n, x, c, xm, dt, advance):
    """The seaway of the block's rows after their step (or at a reset):
    :func:`~shipgym.models.seaway.seaway_block` sets their measured states ``xm`` and their
    load of the next step; nothing without a seaway (``sw[0]`` False, ``xm`` is ``x``)."""
    if sw[0]:
        seaway_block(rows, start, n, x, c, xm, sw[1], sw[2], sw[3], sw[4], sw[5], sw[6], sw[7],
                     dt, advance)  # fmt: skip


def _heading(
    advance,
    rows,
    model_id,
    x,
    u,
    p,
    c,
    sw,
    xm,
    dt,
    a,
    u0,
    B,
    ipsi,
    obs_idx,
    schedule,
    hold_steps,
    steps,
    obs,
    rew,
    term,
    reason,
    obs_lo,
    obs_hi,
):
    """Heading task: hold ``schedule[i, steps[i] // hold_steps]``.

    Observation ``[ssa(psi_d - psi), x[obs_idx]...]``; reward
    ``-|psi_d - psi| / pi - 0.05 |a|^2``, in ``[-1 - 0.05 n_a, 0]`` (``n_a`` actions).
    """
    if advance:
        bad = first_nonfinite_row(a)
        if bad >= 0:
            return bad
    dims = (x.shape[1], u.shape[1], a.shape[1], obs.shape[1])
    family = -1  # the ship family of HEADING_DIMS whose counts are compile-time constants
    for f in range(len(HEADING_DIMS)):
        if dims == HEADING_DIMS[f]:
            family = f
    last = schedule.shape[1] - 1
    n_rows = rows.shape[0]
    work = block_work(x.shape[1], u.shape[1], n_rows)
    ok, new, cost = _row_work(obs.shape[1])
    for start in range(0, n_rows, BLOCK):
        m = min(BLOCK, n_rows - start)
        if advance:  # one RK4 call site, between the copies of each family
            if family == 0:
                _map_and_gather(x, u, c, a, u0, B, steps, rows, start, m, work,
                                FIRST_ORDER[0], FIRST_ORDER[1], FIRST_ORDER[2])  # fmt: skip
            elif family == 1:
                _map_and_gather(x, u, c, a, u0, B, steps, rows, start, m, work,
                                SECOND_ORDER[0], SECOND_ORDER[1], SECOND_ORDER[2])  # fmt: skip
            elif family == 2:
                _map_and_gather(x, u, c, a, u0, B, steps, rows, start, m, work,
                                GUNNERUS[0], GUNNERUS[1], GUNNERUS[2])  # fmt: skip
            else:
                _map_and_gather(x, u, c, a, u0, B, steps, rows, start, m, work,
                                dims[0], dims[1], dims[2])  # fmt: skip
            rk4_block_of(rk4_block, model_id, work[0], work[1], p, work[2], dt, m,
                         work[3])  # fmt: skip
            if family == 0:
                scatter_rows(work[0], rows, start, m, x, FIRST_ORDER[0])
            elif family == 1:
                scatter_rows(work[0], rows, start, m, x, SECOND_ORDER[0])
            elif family == 2:
                scatter_rows(work[0], rows, start, m, x, GUNNERUS[0])
            else:
                scatter_rows(work[0], rows, start, m, x, dims[0])
        _seaway(sw, rows, start, m, x, c, xm, dt, advance)
        if family == 0:
            _begin_block(x, a, rows, start, m, ok, cost, rew, term, reason,
                         FIRST_ORDER[0], FIRST_ORDER[2])  # fmt: skip
        elif family == 1:
            _begin_block(x, a, rows, start, m, ok, cost, rew, term, reason,
                         SECOND_ORDER[0], SECOND_ORDER[2])  # fmt: skip
        elif family == 2:
            _begin_block(x, a, rows, start, m, ok, cost, rew, term, reason,
                         GUNNERUS[0], GUNNERUS[2])  # fmt: skip
        else:
            _begin_block(x, a, rows, start, m, ok, cost, rew, term, reason, dims[0], dims[2])
        for b in range(m):
            if ok[b]:
                i = rows[start + b]
                setpoint = schedule[i, min(steps[i] // hold_steps, last)]
                e = ssa_scalar(setpoint - xm[i, ipsi])  # as measured
                new[b, 0] = e
                for k in range(obs_idx.shape[0]):
                    new[b, 1 + k] = xm[i, obs_idx[k]]
                if sw[0]:  # the reward is the low-frequency heading's
                    e = ssa_scalar(setpoint - x[i, ipsi])
                rew[i] = -abs(e) / math.pi - 0.05 * cost[b]
        if family == 0:
            _finish_block(obs, rows, start, m, ok, obs_lo, obs_hi, new, rew, term, reason,
                          FIRST_ORDER[3])  # fmt: skip
        elif family == 1:
            _finish_block(obs, rows, start, m, ok, obs_lo, obs_hi, new, rew, term, reason,
                          SECOND_ORDER[3])  # fmt: skip
        elif family == 2:
            _finish_block(obs, rows, start, m, ok, obs_lo, obs_hi, new, rew, term, reason,
                          GUNNERUS[3])  # fmt: skip
        else:
            _finish_block(obs, rows, start, m, ok, obs_lo, obs_hi, new, rew, term, reason, dims[3])
    return -1


def _speed(
    advance,
    rows,
    model_id,
    x,
    u,
    p,
    c,
    sw,
    xm,
    dt,
    a,
    u0,
    B,
    schedule,
    hold_steps,
    steps,
    obs,
    rew,
    term,
    reason,
    obs_lo,
    obs_hi,
):
    """RVG speed task: hold the speed through the water ``u_r`` at the scheduled setpoint.

    Observation ``[u_d - u_r, u_r, T_1 / T_bollard, u_d]``; reward
    ``-|u_d - u_r| / 2 - 0.05 (T_1 / T_bollard)^2`` with the speed error and the thrust fraction
    clipped to their observation bounds (+-25 m/s, [0, 1]), so in ``[-12.55, 0]``.
    """
    _require_rvg(model_id)
    na, nobs = SPEED_DIMS
    if advance:
        bad = first_nonfinite_row(a)
        if bad >= 0:
            return bad
    n_sp = schedule.shape[1]
    tb = p[P_TBOLL]
    n_rows = rows.shape[0]
    work = block_work(x.shape[1], u.shape[1], n_rows)
    ok, new, cost = _row_work(obs.shape[1])
    for start in range(0, n_rows, BLOCK):
        m = min(BLOCK, n_rows - start)
        if advance:
            _advance_block(x, u, p, c, dt, a, u0, B, steps, rows, start, m, work, na)
        _seaway(sw, rows, start, m, x, c, xm, dt, advance)
        _begin_block(x, a, rows, start, m, ok, cost, rew, term, reason, NX_RVG, na)
        for b in range(m):
            if ok[b]:
                i = rows[start + b]
                psi = x[i, 2]
                ur = x[i, 3] - (c[i, 0] * math.cos(psi) + c[i, 1] * math.sin(psi))
                ud = schedule[i, min(steps[i] // hold_steps, n_sp - 1)]
                frac = x[i, 6] / tb
                new[b, 0] = ud - ur
                new[b, 1] = ur
                new[b, 2] = frac
                new[b, 3] = ud
                e = min(max(ud - ur, obs_lo[0]), obs_hi[0])
                f = min(max(frac, obs_lo[2]), obs_hi[2])
                rew[i] = -abs(e) / 2.0 - 0.05 * f * f
        _finish_block(obs, rows, start, m, ok, obs_lo, obs_hi, new, rew, term, reason, nobs)
    return -1


@row_kernel
def path_geometry(px, py, xk, yk, cs, sn, length):
    """Cross-track error and along-track distance left on a leg from ``(x_k, y_k)`` of course
    ``chi_p`` (``cs, sn = cos chi_p, sin chi_p``) and ``length`` [m].

    ``e = -(x - x_k) sin(chi_p) + (y - y_k) cos(chi_p)`` is positive when the ship is to the
    right (starboard side) of the path (Fossen 2011, eq. 10.55).
    """
    dn = px - xk
    de = py - yk
    return -dn * sn + de * cs, length - (dn * cs + de * sn)


@row_kernel
def on_leg(x, i, k, tangent, leg_length):
    """:func:`path_geometry` of row ``i`` of the states ``x`` on its leg ``k`` (the path
    tables of :func:`set_path_legs`)."""
    return path_geometry(
        x[i, 0],
        x[i, 1],
        tangent[i, k, 0],
        tangent[i, k, 1],
        tangent[i, k, 2],
        tangent[i, k, 3],
        leg_length[i, k],
    )


def _path(
    advance,
    rows,
    model_id,
    x,
    u,
    p,
    c,
    sw,
    xm,
    dt,
    a,
    u0,
    B,
    tangent,
    leg_length,
    leg_angle,
    turn,
    n_wp,
    seg,
    accept_radius,
    max_cross_track,
    ref_speed,
    steps,
    obs,
    rew,
    term,
    reason,
    obs_lo,
    obs_hi,
):
    """RVG path following along straight legs between waypoints.

    The active leg switches when the ship is within ``accept_radius`` of its end waypoint or has
    passed it along the track. Observation ``[e, ssa(chi_p - psi), s_left, turn, u, v, r,
    alpha_1, T_1 / T_bollard]``. Reward per step ``0.5 clip(progress / (ref_speed dt), -1, 1)
    + 0.5 exp(-(e / 25 m)^2) - 0.1 |chi_p - psi| / pi - 0.05 |a|^2`` (at most 1, positive while
    on the path and making way, so ending an episode early never pays, and at least
    ``-0.6 - 0.05 n_a``); +20 on reaching the last waypoint, -20 when ``|e| > max_cross_track``.
    """
    _require_rvg(model_id)
    na, nobs = PATH_DIMS
    if advance:
        bad = first_nonfinite_row(a)
        if bad >= 0:
            return bad
    tb = p[P_TBOLL]
    n_rows = rows.shape[0]
    work = block_work(x.shape[1], u.shape[1], n_rows)
    ok, new, cost = _row_work(obs.shape[1])
    s_before = np.empty(BLOCK)
    for start in range(0, n_rows, BLOCK):
        m = min(BLOCK, n_rows - start)
        for b in range(m):  # along-track distance left before the step
            i = rows[start + b]
            k = seg[i]
            s_before[b] = on_leg(x, i, k, tangent, leg_length)[1]
        if advance:
            _advance_block(x, u, p, c, dt, a, u0, B, steps, rows, start, m, work, na)
        _seaway(sw, rows, start, m, x, c, xm, dt, advance)
        _begin_block(x, a, rows, start, m, ok, cost, rew, term, reason, NX_RVG, na)
        for b in range(m):
            if not ok[b]:
                continue
            i = rows[start + b]
            k = seg[i]
            e, s_left = on_leg(x, i, k, tangent, leg_length)
            progress = s_before[b] - s_left
            # within the acceptance radius of the leg's end, compared squared (no hypot call)
            dn_end = x[i, 0] - tangent[i, k + 1, 0]
            de_end = x[i, 1] - tangent[i, k + 1, 1]
            bonus = 0.0
            if dn_end * dn_end + de_end * de_end < accept_radius * accept_radius or s_left < 0.0:
                if k + 2 < n_wp[i]:
                    k += 1
                    seg[i] = k
                    e, s_left = on_leg(x, i, k, tangent, leg_length)
                else:
                    term[i] = True
                    reason[i] = SUCCESS
                    bonus = 20.0
            if abs(e) > max_cross_track:
                term[i] = True
                reason[i] = FAILURE
                bonus = -20.0
            chi_err = ssa_scalar(leg_angle[i, k] - x[i, 2])
            e_m, s_m, chi_m = e, s_left, chi_err  # as measured
            if sw[0]:
                e_m, s_m = on_leg(xm, i, k, tangent, leg_length)
                chi_m = ssa_scalar(leg_angle[i, k] - xm[i, 2])
            new[b, 0] = e_m
            new[b, 1] = chi_m
            new[b, 2] = s_m
            new[b, 3] = turn[i, k]
            new[b, 4] = x[i, 3]
            new[b, 5] = x[i, 4]
            new[b, 6] = xm[i, 5]
            new[b, 7] = x[i, 8]
            new[b, 8] = x[i, 6] / tb
            rew[i] = (
                0.5 * min(max(progress / (ref_speed * dt), -1.0), 1.0)
                + 0.5 * math.exp(-((e / 25.0) ** 2))
                - 0.1 * abs(chi_err) / math.pi
                - 0.05 * cost[b]
                + bonus
            )
        _finish_block(obs, rows, start, m, ok, obs_lo, obs_hi, new, rew, term, reason, nobs)
    return -1


def _target(
    advance,
    rows,
    model_id,
    x,
    u,
    p,
    c,
    sw,
    xm,
    dt,
    a,
    u0,
    B,
    target,
    target_vel,
    distance,
    max_distance,
    steps,
    obs,
    rew,
    term,
    reason,
    obs_lo,
    obs_hi,
):
    """RVG target tracking: close on a target moving at constant velocity and hold ``distance``.

    Observation ``[dx_b, dy_b, dvx_b, dvy_b, |p_t - p| - d_set, u, v, r, alpha_1, T_1 / T_b]``
    with the target's relative position and velocity in the body frame. Reward
    ``1 - min(|d - d_set| / 100, 2) - 0.05 |a|^2`` (positive within 100 m of the set distance,
    at least ``-1 - 0.05 n_a``); -20 and termination when the distance exceeds ``max_distance``.
    """
    _require_rvg(model_id)
    na, nobs = TARGET_DIMS
    if advance:
        bad = first_nonfinite_row(a)
        if bad >= 0:
            return bad
    tb = p[P_TBOLL]
    n_rows = rows.shape[0]
    work = block_work(x.shape[1], u.shape[1], n_rows)
    ok, new, cost = _row_work(obs.shape[1])
    for start in range(0, n_rows, BLOCK):
        m = min(BLOCK, n_rows - start)
        if advance:
            _advance_block(x, u, p, c, dt, a, u0, B, steps, rows, start, m, work, na)
            for b in range(m):
                i = rows[start + b]
                target[i, 0] += target_vel[i, 0] * dt
                target[i, 1] += target_vel[i, 1] * dt
        _seaway(sw, rows, start, m, x, c, xm, dt, advance)
        _begin_block(x, a, rows, start, m, ok, cost, rew, term, reason, NX_RVG, na)
        for b in range(m):
            if not ok[b]:
                continue
            i = rows[start + b]
            sn, cs = sincos(x[i, 2])
            vn = cs * x[i, 3] - sn * x[i, 4]  # ship velocity over ground, NED
            ve = sn * x[i, 3] + cs * x[i, 4]
            rvn = target_vel[i, 0] - vn
            rve = target_vel[i, 1] - ve
            d = math.hypot(target[i, 0] - x[i, 0], target[i, 1] - x[i, 1])
            err = d - distance[i]
            # as measured: the position and heading with the wave-frequency motion
            sn, cs = sincos(xm[i, 2])
            dn = target[i, 0] - xm[i, 0]
            de = target[i, 1] - xm[i, 1]
            new[b, 0] = cs * dn + sn * de
            new[b, 1] = -sn * dn + cs * de
            new[b, 2] = cs * rvn + sn * rve
            new[b, 3] = -sn * rvn + cs * rve
            new[b, 4] = math.hypot(dn, de) - distance[i] if sw[0] else err
            new[b, 5] = x[i, 3]
            new[b, 6] = x[i, 4]
            new[b, 7] = xm[i, 5]
            new[b, 8] = x[i, 8]
            new[b, 9] = x[i, 6] / tb
            rew[i] = 1.0 - min(abs(err) / 100.0, 2.0) - 0.05 * cost[b]
            if d > max_distance:
                term[i] = True
                reason[i] = FAILURE
                rew[i] -= 20.0
        _finish_block(obs, rows, start, m, ok, obs_lo, obs_hi, new, rew, term, reason, nobs)
    return -1


@kernel
def set_path_legs(rows, path, n_wp, tangent, leg_length, leg_angle, turn, row_n_wp, seg):
    """Set the path tables of ``rows`` (at a reset): row ``rows[k]`` follows the first
    ``n_wp[k]`` of the waypoints ``path[k]`` (north, east) [m], on its first leg.

    ``tangent[i, j]`` holds waypoint ``j`` (the last one repeated up to ``path.shape[1]``,
    zero after) and the cosine and sine of the course of leg ``j``, from waypoint ``j`` to
    ``j + 1``; ``leg_length``, ``leg_angle`` (the course, rad) and ``turn`` (the course change
    at the end of the leg) of each leg; zero after the last leg.
    """
    m = path.shape[1]
    for k in range(rows.shape[0]):
        i = rows[k]
        last = n_wp[k] - 1
        for j in range(tangent.shape[1]):
            q = min(j, last)
            tangent[i, j, 0] = path[k, q, 0] if j < m else 0.0
            tangent[i, j, 1] = path[k, q, 1] if j < m else 0.0
            tangent[i, j, 2] = tangent[i, j, 3] = 0.0
        for j in range(leg_length.shape[1]):
            leg_length[i, j] = leg_angle[i, j] = turn[i, j] = 0.0
        for j in range(last):
            dn = path[k, j + 1, 0] - path[k, j, 0]
            de = path[k, j + 1, 1] - path[k, j, 1]
            chi = math.atan2(de, dn)
            tangent[i, j, 2] = math.cos(chi)
            tangent[i, j, 3] = math.sin(chi)
            leg_length[i, j] = math.hypot(dn, de)
            leg_angle[i, j] = chi
            if j > 0:
                turn[i, j - 1] = ssa_scalar(chi - leg_angle[i, j - 1])
        row_n_wp[i] = n_wp[k]
        seg[i] = 0


#: The task kernel of each task family.
KERNELS = {
    name: kernel(func)
    for name, func in (
        ("heading", _heading),
        ("speed", _speed),
        ("path", _path),
        ("target", _target),
    )
}


def compiled_call(task_kernel: Callable[..., int], args: tuple[Any, ...]) -> Callable[..., int]:
    """The compiled machine code that ``task_kernel(*args)`` runs, to be called with arguments
    of exactly those types: it skips Numba's type dispatch, about 1 us of a 22-argument call
    (an env's step holds its arguments for good and calls its kernel every step). Anything
    that is not a compiled kernel (a threaded call) is returned as it is."""
    if not isinstance(task_kernel, Dispatcher):
        return task_kernel
    return task_kernel.compile(tuple(task_kernel.typeof_pyval(arg) for arg in args))


def available_threads() -> int:
    """Threads a batch can be stepped on: the CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


_POOL: list[ThreadPoolExecutor] = []
# a forked child has none of the pool's threads: it makes its own pool when it needs one
os.register_at_fork(after_in_child=_POOL.clear)


def run_threaded(
    task_kernel: Callable[..., int], threads: int, advance: bool, rows: np.ndarray, *args: object
) -> int:
    """Call ``task_kernel`` on ``threads`` contiguous parts of ``rows`` at once: the calling
    thread steps the first part, threads of a shared pool the others.

    The result is bitwise that of one call on all rows (each row's result depends on that row
    only). Returns the kernel's result: the first row whose action is not finite (every part
    checks all actions, so then no part steps), or -1.
    """
    if not _POOL:
        _POOL.append(ThreadPoolExecutor(available_threads(), thread_name_prefix="shipgym-step"))
    parts = np.array_split(rows, threads)
    futures = [_POOL[0].submit(task_kernel, advance, part, *args) for part in parts[1:]]
    bad = [task_kernel(advance, parts[0], *args)] + [f.result() for f in futures]
    return max(bad)

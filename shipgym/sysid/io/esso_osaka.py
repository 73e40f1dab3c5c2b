"""Esso Osaka free-running model tests (Osaka Univ., Inukai pond, ``esso_osaka_frt``).

Comma-separated with unit-stating headers (``t [s]``, ``psi_hat [rad]`` ...; SOURCES.md).
Conversions: the MMG convention is already starboard-positive (no flip); ``psi_hat`` unwrapped;
``rpm = 60 n``; trailing all-empty rows dropped. Apparent wind from
``wind_velo_relative_mid`` / ``wind_dir_relative_mid``: the source angle is already "from",
clockwise from the bow (verified against the true wind and the ship motion, residual below 0.04
deg RMS), only wrapped from [0, 2 pi) to (-pi, pi]. Zigzag and turning runs start from rest and
end coasting: ``meta["manoeuvre_start_s"]`` (:data:`ORDER_LEAD_S` before the programme's first
rudder order, :func:`first_order`) .. ``meta["manoeuvre_end_s"]`` (the last sample with the
propeller turning) mark the manoeuvre.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from shipgym.sysid.ingest import (
    base_meta,
    check_units,
    flag_irregular,
    read_columns,
    read_lines,
    repair_heading,
    silent,
    wrap_angle,
)
from shipgym.sysid.io.registry import SourceFormat
from shipgym.sysid.record import Record

__all__ = [
    "FORMAT",
    "ORDER_FRACTION",
    "ORDER_HOLD_S",
    "ORDER_LEAD_S",
    "ORDER_MIN_ANGLE",
    "ORDER_TOLERANCE",
    "by_path",
    "first_order",
    "load_esso_osaka",
    "sniff",
]

_ESSO_COLS = [
    "t [s]",
    "x_position_mid [m]",
    "u_velo [m/s]",
    "y_position_mid [m]",
    "vm_velo [m/s]",
    "psi_hat [rad]",
    "r_angvelo [rad/s]",
    "n_prop [rps]",
    "delta_rudder [rad]",
]
_ESSO_WIND_COLS = ["wind_velo_relative_mid [m/s]", "wind_dir_relative_mid [rad]"]

ORDER_HOLD_S = 2.0
"""A rudder order is held this long [s] within :data:`ORDER_TOLERANCE` (a hand on the tiller
is not)."""
ORDER_TOLERANCE = math.radians(0.25)
"""How far [rad] a held rudder order may wander (the rudder log's resolution is 0.2-0.4 deg)."""
ORDER_LEAD_S = 5.0
"""The manoeuvre starts this long [s] before its first order: the rudder's step is the
excitation (a turning circle's only one), so the approach just before it is part of the run."""
ORDER_MIN_ANGLE = math.radians(5.0)
"""A held rudder below this [rad] is a trim, not an order."""
ORDER_FRACTION = 0.8
"""The programme's orders are held at the run's largest held rudder angle; a held angle below
this fraction of it is a correction during the approach."""


def first_order(t: np.ndarray, delta: np.ndarray) -> int | None:
    """Index of a zigzag's or turn's first rudder order: the first sample from which the rudder
    is held (:data:`ORDER_HOLD_S` within :data:`ORDER_TOLERANCE`, at :data:`ORDER_MIN_ANGLE` or
    more) at :data:`ORDER_FRACTION` or more of the run's largest held angle; None without a held
    order.

    The runs start from rest, the helmsman correcting the course by hand while the ship
    gathers way: corrections reach 10-12 deg on seven of the thirteen runs (five of them at
    0.01-0.04 m/s), but move all the time, where the programme steps the rudder to each order
    and holds it for seconds."""
    if t.size < 2:
        return None
    n = max(round(ORDER_HOLD_S / float(np.median(np.diff(t)))), 1)
    if delta.size < n:
        return None
    windows = np.lib.stride_tricks.sliding_window_view(delta, n)
    held = np.all(np.abs(windows - windows[:, :1]) <= ORDER_TOLERANCE, axis=1)
    held &= np.abs(windows[:, 0]) >= ORDER_MIN_ANGLE
    k = np.flatnonzero(held)
    if not k.size:
        return None
    return int(k[np.abs(delta[k]) >= ORDER_FRACTION * np.abs(delta[k]).max()][0])


def load_esso_osaka(path: Path, say: Callable[[str], None] = silent) -> Record:
    """Read one esso_osaka file (module docstring); ``say`` takes progress lines."""
    lines = read_lines(path)
    meta = base_meta(
        path,
        "esso_osaka",
        vessel="Esso Osaka VLCC model (Osaka Univ., Inukai pond)",
        L=3.0,
        scale="model",
        frame="pond frame O0-x0y0 (right-handed, z down); psi clockwise from x0",
        licence="CC BY-NC 4.0 (cite Wakita et al. 2022; Miyauchi et al. 2022)",
    )
    t, data, ix = read_columns(path, "esso_osaka", lines, ",", _ESSO_COLS, "t [s]", meta, say,
                               optional=_ESSO_WIND_COLS)  # fmt: skip
    has_wind = all(c in ix for c in _ESSO_WIND_COLS)
    r = data[:, ix["r_angvelo [rad/s]"]]
    delta = data[:, ix["delta_rudder [rad]"]]
    check_units(
        t,
        data[:, ix["psi_hat [rad]"]],
        r,
        delta,
        meta,
        names={
            "time": "t [s]",
            "psi": "psi_hat [rad]",
            "r": "r_angvelo [rad/s]",
            "delta": "delta_rudder [rad]",
        },
    )
    psi = repair_heading(t, data[:, ix["psi_hat [rad]"]], r, meta)
    n_prop = data[:, ix["n_prop [rps]"]]
    u, v = data[:, ix["u_velo [m/s]"]], data[:, ix["vm_velo [m/s]"]]
    meta["conversions"] += ["none for delta (MMG: positive = starboard turn)", "rpm = 60 * n"]
    meta["r_source"] = "measured"
    wind_speed = wind_angle = None
    if has_wind:
        wind_speed = data[:, ix["wind_velo_relative_mid [m/s]"]]
        wind_angle = wrap_angle(data[:, ix["wind_dir_relative_mid [rad]"]])
        meta["conversions"].append(
            "wind_speed = wind_velo_relative_mid; wind_angle = wind_dir_relative_mid wrapped from"
            " [0, 2 pi) to (-pi, pi]: the source angle is already the apparent wind direction"
            " the wind comes FROM, clockwise from the bow (verified: apparent wind rebuilt from"
            " wind_velo_true / wind_dir_true (from, clockwise from x0) minus the ship velocity"
            " u, v rotated by psi matches within 0.04 deg RMS and 0.001 m/s RMS)"
        )
        meta["notes"].append(
            "real wind of the order of the ship speed or larger; the apparent (relative) wind at"
            " midship is loaded as wind_speed, wind_angle (true wind not loaded)"
        )
    else:
        meta["notes"].append(
            "real wind of the order of the ship speed (no apparent-wind columns in this file)"
        )
    kind = path.parent.name
    if kind in ("zigzag", "turning") or path.name.startswith(("zigzag", "turn")):
        first = first_order(t, delta)
        running = np.flatnonzero(n_prop > 0)
        if first is not None and running.size and running[-1] > first:
            meta["manoeuvre_start_s"] = max(float(t[first]) - ORDER_LEAD_S, float(t[0]))
            meta["manoeuvre_end_s"] = float(t[running[-1]])
            meta["notes"].append(
                "starts from rest with manual corrections and ends coasting: cut to "
                f"[manoeuvre_start_s, manoeuvre_end_s] ({ORDER_LEAD_S:g} s before the "
                "programme's first rudder order .. last n > 0) before fitting"
            )
    flag_irregular(t, meta)
    return Record(
        time=t,
        delta=delta,
        psi=psi,
        r=r,
        x=data[:, ix["x_position_mid [m]"]],
        y=data[:, ix["y_position_mid [m]"]],
        u=u,
        v=v,
        U=np.hypot(u, v),
        rpm=60.0 * n_prop,
        wind_speed=wind_speed,
        wind_angle=wind_angle,
        meta=meta,
    )


def sniff(head: str) -> bool:
    """A header starting ``t [s],`` with a ``psi_hat`` column."""
    first = head.splitlines()[0] if head.strip() else ""
    return first.startswith("t [s],") and "psi_hat" in first


def by_path(path: Path) -> bool:
    """Files two folders below ``esso_osaka_frt``."""
    return path.parent.parent.name.lower() == "esso_osaka_frt"


FORMAT = SourceFormat("esso_osaka", load_esso_osaka, sniff, by_path)
"""The esso_osaka format of :func:`shipgym.sysid.io.load`."""

"""Model files: an identified ship as a model the rest of the package takes.

``shipgym identify ... --json fit.json`` writes the fitted model into its report under one key
per family, and :func:`load_model` builds the :class:`ShipModel` from it; so do
``make_model("fit.json")``, the envs' ``model="fit.json"``, ``shipgym simulate|evaluate --model
fit.json`` and ``shipgym design fit.json``:

* ``"nomoto"`` (the Nomoto family, seed 000/002/004; written by :func:`nomoto_document`)::

    {"model": "nomoto1", "params": {"K": 0.1, "T": 30.0}, "rudder_offset_rad": 0.0087,
     "input_delay_s": 0.0, "steering_gear": {"time_constant": 2.0, "max_angle": 0.61,
     "max_rate": 0.0405, "identified": false}, "surge": {"gain": 5.5, ...},
     "speed_m_s": 7.7, "length_m": null, "current_m_s": [0.1, -0.05], "source": "log.csv"}

  Every identified effect is part of the model: the rudder offset ``delta0`` of ``nomoto1`` and
  ``nomoto2`` becomes the bias of their nonlinear relatives with the nonlinear terms zero (a
  ``norrbin`` model with ``n0 = -K delta0``, ``n1 = 1``, ``n2 = n3 = 0``; a ``bech`` model with
  ``b0 = -delta0``, ``b1 = 1 / K``, ``b2 = b3 = 0``: the same equations); ``norrbin``/``bech``
  keep their own ``n0``/``b0`` and nonlinear terms; an identified rudder lag ``T_d`` is the
  steering gear's time constant (the identification models it as the project's
  :class:`SteeringGear`, default limits); an input delay is the model's ``input_delay``. Without
  an identified lag the record's rudder was the actual angle, so the default steering gear is
  used (``"identified": false``). The surge model is scaled so that the service speed is the
  record's median speed (``speed_m_s``; the default 7.7 m/s without a speed channel). The
  identified current is a property of the record, kept for information and not part of the
  ship.
* ``"rvg3dof"`` (the R/V Gunnerus 3-DOF model of seed 001; written by :func:`rvg_document`):
  the :class:`RVGParams` fields of the fit (matrices as nested lists) with its calibrated values
  and effect terms (pod lift, slipstream, wave resistance, ...) and the identified azimuth offset
  as ``azimuth_offset`` (the pods turn to the order plus it); the record's current and sway
  offset (a log or antenna misalignment) are kept for information, ``current_m_s`` and
  ``sway_offset_m_s``. The RVG envs take it as ``params="fit.json"``.
* ``"vmm"`` (seed 003's general 3-DOF model, :meth:`VMMParams.load`; an identified rudder zero
  error is its ``rudder_offset``, a steering-gear lag its ``rudder_time_constant`` with
  ``direct_rudder`` false, a transport delay ``input_delay_s``, the model's ``input_delay``) and
  ``"kvlcc2"`` (the MMG model with refined derivatives, :class:`MMGParams` fields).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import asdict, fields
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.models.base import NOMOTO_MODEL_NAMES, ShipModel, make_model
from shipgym.models.mmg import MMGParams
from shipgym.models.nomoto import (
    BechParams,
    Nomoto1Params,
    Nomoto2Params,
    NorrbinParams,
    SteeringGear,
    SurgeModel,
)
from shipgym.models.rvg import RVGParams
from shipgym.models.vmm import VMMParams

__all__ = [
    "MODEL_FILE_KEYS",
    "is_model_file",
    "load_model",
    "model_info",
    "nomoto_document",
    "rvg_document",
    "with_rudder_offset",
]

MODEL_FILE_KEYS: tuple[str, ...] = ("nomoto", "rvg3dof", "vmm", "kvlcc2")
"""The family keys of a model file."""

_YAW_PARAMS = {
    "nomoto1": Nomoto1Params,
    "nomoto2": Nomoto2Params,
    "norrbin": NorrbinParams,
    "bech": BechParams,
}


def is_model_file(name: Any) -> bool:
    """Whether ``name`` names a model file rather than a model (a path ending in ``.json``)."""
    return isinstance(name, os.PathLike) or (
        isinstance(name, str) and name.lower().endswith(".json")
    )


def nomoto_document(
    model: str,
    params: Mapping[str, float],
    *,
    rudder_offset: float = 0.0,
    rudder_lag: float | None = None,
    input_delay: float = 0.0,
    speed: float | None = None,
    length: float | None = None,
    current: tuple[float, float] | None = None,
    source: str = "",
) -> dict[str, Any]:
    """The ``"nomoto"`` entry of a model file (module docstring).

    Parameters
    ----------
    model : {"nomoto1", "nomoto2", "norrbin", "bech"}
        The identified yaw model.
    params : mapping
        Its parameters (the fields of :class:`Nomoto1Params` etc.).
    rudder_offset : float
        Identified rudder offset ``delta0`` [rad] (nomoto1/nomoto2: ``delta -> delta +
        delta0``).
    rudder_lag : float, optional
        Identified steering-gear time constant ``T_d`` [s]; None: not identified.
    input_delay : float
        Identified delay ``tau`` [s] of the rudder.
    speed, length : float, optional
        The record's median speed [m/s] and the ship's length [m], where known.
    current : tuple of float, optional
        Identified drift ``(V_n, V_e)`` [m/s] of the record.
    source : str
        The record it was identified from.
    """
    cls = _YAW_PARAMS[model]
    yaw = {f.name: float(params[f.name]) for f in fields(cls) if f.name in params}
    gear = SteeringGear() if rudder_lag is None else SteeringGear(time_constant=rudder_lag)
    return {
        "model": model,
        "params": yaw,
        "rudder_offset_rad": float(rudder_offset),
        "input_delay_s": float(input_delay),
        "steering_gear": asdict(gear) | {"identified": rudder_lag is not None},
        "surge": asdict(_surge(speed)),
        "speed_m_s": None if speed is None else float(speed),
        "length_m": None if length is None else float(length),
        "current_m_s": None if current is None else [float(current[0]), float(current[1])],
        "source": source,
    }


def rvg_document(
    params: RVGParams,
    *,
    current: tuple[float, float] = (0.0, 0.0),
    sway_offset: float = 0.0,
    source: str = "",
) -> dict[str, Any]:
    """The ``"rvg3dof"`` entry of a model file (module docstring)."""
    doc: dict[str, Any] = {}
    for f in fields(RVGParams):
        value = getattr(params, f.name)
        doc[f.name] = value.tolist() if isinstance(value, np.ndarray) else value
    doc["pod_x"], doc["pod_y"] = list(params.pod_x), list(params.pod_y)
    doc.update(
        current_m_s=[float(current[0]), float(current[1])],
        sway_offset_m_s=float(sway_offset),
        source=source,
    )
    return doc


def _rvg(doc: Mapping[str, Any], where: str) -> ShipModel:
    names = {f.name for f in fields(RVGParams)}
    kw = {k: v for k, v in doc.items() if k in names}
    for key in ("pod_x", "pod_y"):
        if key in kw:
            kw[key] = tuple(kw[key])
    try:
        params = RVGParams(**kw)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"{where}: its 'rvg3dof' entry is not an RVG parameter set: {exc}"
        ) from None
    return make_model("rvg3dof", params)


def _surge(speed: float | None) -> SurgeModel:
    """The default surge model, its gain scaled to hold ``speed`` at the service shaft speed."""
    default = SurgeModel()
    if speed is None or not (math.isfinite(speed) and speed > 0):
        return default
    return SurgeModel(
        gain=speed / default.service_shaft_speed,
        time_constant=default.time_constant,
        service_shaft_speed=default.service_shaft_speed,
        max_shaft_speed=default.max_shaft_speed,
    )


def _read(source: str | os.PathLike[str] | Mapping[str, Any]) -> tuple[dict[str, Any], str]:
    if isinstance(source, Mapping):
        return dict(source), "model document"
    path = Path(source)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ValueError(
            f"model file {str(path)!r} does not exist (expected the JSON of shipgym identify "
            "--json)"
        ) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"cannot read model file {str(path)!r}: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError(f"model file {str(path)!r} holds no JSON object")
    return data, repr(str(path))


def _nomoto(doc: Mapping[str, Any], where: str) -> ShipModel:
    try:
        name = doc["model"]
        cls = _YAW_PARAMS[name]
        params = dict(doc["params"])
        offset = float(doc.get("rudder_offset_rad") or 0.0)
        delay = float(doc.get("input_delay_s") or 0.0)
        gear_doc = dict(doc.get("steering_gear") or {})
        gear_doc.pop("identified", None)
        gear = SteeringGear(**gear_doc)
        surge = SurgeModel(**(doc.get("surge") or {}))
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(
            f"{where}: its 'nomoto' entry is not a Nomoto-family model ({type(exc).__name__}: "
            f"{exc}); expected model, params, steering_gear, surge as shipgym identify writes"
        ) from None
    try:
        yaw = cls(**params)
    except TypeError as exc:
        raise ValueError(f"{where}: parameters of {name} {params}: {exc}") from None
    try:
        name, yaw = with_rudder_offset(name, yaw, offset)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    return make_model(name, yaw, gear=gear, surge=surge, input_delay=delay)


def with_rudder_offset(name: str, yaw: Any, offset: float) -> tuple[str, Any]:
    """The yaw model that responds to ``delta + offset`` as ``(name, params)``: for
    ``nomoto1`` and ``nomoto2`` the bias of the same equation (a ``norrbin`` model with
    ``n0 = -K offset``, ``n1 = 1``, ``n2 = n3 = 0``; a ``bech`` model with ``b0 = -offset``,
    ``b1 = 1 / K``, ``b2 = b3 = 0``); unchanged without an offset.

    Raises
    ------
    ValueError
        For an offset of a ``norrbin`` or ``bech`` model, which carries it in ``n0``/``b0``.
    """
    if not offset:
        return name, yaw
    if name == "nomoto1":
        return "norrbin", NorrbinParams(K=yaw.K, T=yaw.T, n0=-yaw.K * offset, n1=1.0, n2=0.0,
                                        n3=0.0)  # fmt: skip
    if name == "nomoto2":
        return "bech", BechParams(K=yaw.K, T1=yaw.T1, T2=yaw.T2, T3=yaw.T3, b0=-offset,
                                  b1=1.0 / yaw.K, b2=0.0, b3=0.0)  # fmt: skip
    bias = "n0" if name == "norrbin" else "b0"
    raise ValueError(
        f"a {name} model carries its rudder offset in its bias ({bias}); expected an offset of "
        f"0, got {offset!r}"
    )


def load_model(source: str | os.PathLike[str] | Mapping[str, Any]) -> ShipModel:
    """The :class:`ShipModel` of a model file (module docstring) or its parsed JSON.

    Raises
    ------
    ValueError
        For a missing or unreadable file, or one that holds no model (naming the keys found
        and the ones expected).
    """
    data, where = _read(source)
    if isinstance(data.get("nomoto"), Mapping):
        return _nomoto(data["nomoto"], where)
    if isinstance(data.get("rvg3dof"), Mapping):
        return _rvg(data["rvg3dof"], where)
    if isinstance(data.get("vmm"), Mapping):
        vmm = {k: v for k, v in data["vmm"].items() if k not in ("current", "input_delay_s")}
        delay = float(data["vmm"].get("input_delay_s") or 0.0)
        return make_model("vmm", VMMParams.from_dict(vmm), input_delay=delay)
    if isinstance(data.get("kvlcc2"), Mapping):
        names = {f.name for f in fields(MMGParams)}
        delay = float(data["kvlcc2"].get("input_delay_s") or 0.0)
        return make_model("kvlcc2", MMGParams(**{
            k: v for k, v in data["kvlcc2"].items() if k in names
        }), input_delay=delay)  # fmt: skip
    model = data.get("model")
    hint = (
        f" (a {model!r} fit; its model is not written to a model file)"
        if isinstance(model, str)
        else ""
    )
    raise ValueError(
        f"{where} holds no model{hint}: expected one of the keys {MODEL_FILE_KEYS} as "
        f"shipgym identify --json writes them, found {sorted(data)[:12]}"
    )


def model_info(source: str | os.PathLike[str] | Mapping[str, Any]) -> dict[str, Any]:
    """The model file's own description of its ship: the ``"nomoto"`` entry (identified
    model, parameters, offset, delay, speed, length), or ``{"model": <family key>}``."""
    data, where = _read(source)
    for key in MODEL_FILE_KEYS:
        if isinstance(data.get(key), Mapping):
            return dict(data[key]) if key == "nomoto" else {"model": key}
    raise ValueError(f"{where} holds no model: expected one of the keys {MODEL_FILE_KEYS}")


assert set(_YAW_PARAMS) == set(NOMOTO_MODEL_NAMES)

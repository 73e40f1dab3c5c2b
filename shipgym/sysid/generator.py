"""Synthetic manoeuvring records with one undeclared effect, for testing identification tools.

Issue 4 section 5 asks for "the project's own generator of records with one undeclared effect":
a record that looks like a measured one (:class:`shipgym.sysid.data.Record`, canonical units and
sign convention) but whose ship deviates from the base model, the first-order Nomoto ship
``T r' + r = K delta`` (seed 000, seed 004 eq. 2) with the Mariner defaults of
:mod:`shipgym.models` (``K = 0.185 1/s``, ``T = 107.3 s``, service speed 7.7 m/s, steering gear
``T_delta = 2 s``, 35 deg, 2.32 deg/s), in exactly one documented way. Every record is simulated
through :mod:`shipgym.models` (:meth:`ShipModel.simulate` with the manoeuvre as a controller
callback ``(t, x) -> [delta_c, n]``); no model equation is written here.

Effects (:data:`EFFECTS`; ``magnitude`` is in the unit given, the default in brackets):

=================== ===========================================================================
effect              definition
=================== ===========================================================================
``rudder_offset``   The rudder needed for straight running is ``delta_0`` [rad] (2 deg): the
                    true ship is Norrbin's model (seed 002 eq. 1) with the same K, T and
                    ``n0 = K delta_0``, ``n1 = 1``, ``n2 = n3 = 0``, i.e.
                    ``T r' + r = K (delta - delta_0)``. The recorded rudder is the steering-gear
                    state; it does NOT contain the offset.
``yaw_nonlinearity`` Norrbin cubic term: the true ship is ``T r' + n3 r^3 + r = K delta``
                    (seed 002 eq. 1, seed 004 eq. 4) with ``n3`` [s^2] (2.9e3, the shipgym
                    default), ``n0 = n2 = 0``, ``n1 = 1``.
``rudder_lag``      The recorded rudder is the COMMAND ``delta_c``, while the actual rudder
                    follows it through a slow gear: first-order time constant ``T_delta`` [s]
                    (8 s) with the default angle and rate limits (seed 002 eq. 2).
``input_delay``     The recorded rudder leads the rudder the ship feels by a pure delay
                    ``tau`` [s] (3 s, rounded to the internal step): the ship responds to
                    ``delta(t - tau)`` where ``delta`` is the recorded gear angle (as if the
                    rudder log's clock were ``tau`` ahead, or a transport delay between the
                    measured angle and the hydrodynamic force). In the zigzag the controller
                    acts on the measured heading, so its switching is delayed too.
``current``         A constant irrotational current of speed ``V_c`` [m/s] (0.5 m/s) toward a
                    direction drawn from the seed (uniform on [0, 2 pi)), entering only the
                    kinematics ``x' = U cos psi + V_n``, ``y' = U sin psi + V_e``. A Nomoto
                    model's yaw is unaffected by a uniform current, so only position-based
                    criteria (dead reckoning against the recorded track) can see it.
``second_order``    The true ship is the second-order Nomoto model (seed 004 eq. 1) with the
                    Mariner ``K = 0.185``, ``T2`` [s] (7.8 s), ``T3 = 18.5 s`` and
                    ``T1 = T + T3 - T2`` (118 s), so its first-order equivalent
                    ``T1 + T2 - T3`` equals the base ``T``.
=================== ===========================================================================

Manoeuvres:

* ``"zigzag"``: a 20/20 zigzag (IMO style, ``ZIGZAG_ANGLE``): the command starts at +20 deg
  (starboard) and switches sign each time the heading passes +-20 deg from the initial heading
  (simple switching rule on the true heading).
* ``"random"``: a piecewise-constant random rudder command, amplitudes uniform in
  ``[-RANDOM_MAX_RUDDER, RANDOM_MAX_RUDDER]`` (25 deg), hold times uniform in
  ``RANDOM_HOLD`` (15 to 60 s), drawn from the seed.

The shaft speed is the service shaft speed throughout (``U`` stays at 7.7 m/s: the Nomoto models
have no speed loss in turns). The simulation runs with a fine step ``h = dt / ceil(dt / 0.1)``
(at most 0.1 s) and is sampled every ``dt``.

Sensor noise (``noise=True``; :data:`NOISE`, white Gaussian, independent per sample and channel):
heading 0.1 deg, yaw rate 0.02 deg/s, rudder 0.1 deg, positions 1 m, speed 0.02 m/s. The noise
draws come from their own random stream, so ``noise=False`` gives the same trajectory. The
rudder noise is an errors-in-variables disturbance for a fit that replays the recorded rudder:
through ``K / (s (1 + T s))`` it makes the replayed heading wander slowly, so the psi residual of
a correct output-error fit of a clean 600 s record is 1.0 to 1.1 times the heading noise at
``dt = 0.1 s`` and up to about 2 times at ``dt = 1 s`` (the r residual stays at its noise level).

The ground truth (true model name and parameters, gear, surge, current, base model, the effect
and its parameters, the realised delay...) is stored in ``record.meta["truth"]``. It is there
for tests and benchmarks only: **an identifier or diagnostic must not read it**; nothing else in
the record (channels or the other meta keys) depends on which effect was applied, apart from the
effect's influence on the signals.
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any, Literal

import numpy as np

from shipgym.models import (
    Nomoto1Params,
    Nomoto2Params,
    NorrbinParams,
    SteeringGear,
    SurgeModel,
    make_model,
)
from shipgym.models.nomoto import IDELTA, IPSI, IR, IU, IX, IY
from shipgym.sysid.data import Record

__all__ = [
    "BASE_MODELS",
    "EFFECTS",
    "EFFECT_DEFAULTS",
    "MANEUVERS",
    "NOISE",
    "generate_record",
]

EFFECTS: tuple[str, ...] = (
    "rudder_offset",
    "yaw_nonlinearity",
    "rudder_lag",
    "input_delay",
    "current",
    "second_order",
)
"""Catalogue of the undeclared effects (see the module docstring)."""

EFFECT_DEFAULTS: dict[str, float] = {
    "rudder_offset": math.radians(2.0),  # delta_0 [rad]
    "yaw_nonlinearity": 2.9e3,  # n3 [s^2]
    "rudder_lag": 8.0,  # gear time constant [s]
    "input_delay": 3.0,  # tau [s]
    "current": 0.5,  # current speed [m/s]
    "second_order": 7.8,  # T2 [s]
}
"""Default ``magnitude`` of each effect, in the unit of the module docstring's table."""

MANEUVERS: tuple[str, ...] = ("zigzag", "random")
"""Accepted values of ``maneuver``."""

BASE_MODELS: tuple[str, ...] = ("nomoto1",)
"""Base models the effects are defined against (only the first-order Nomoto ship)."""

NOISE: dict[str, float] = {
    "psi": math.radians(0.1),  # rad
    "r": math.radians(0.02),  # rad/s
    "delta": math.radians(0.1),  # rad
    "xy": 1.0,  # m
    "U": 0.02,  # m/s
}
"""Standard deviations of the Gaussian sensor noise (``noise=True``)."""

ZIGZAG_ANGLE = math.radians(20.0)
"""Rudder and heading-switch angle [rad] of the zigzag (20/20)."""

RANDOM_MAX_RUDDER = math.radians(25.0)
"""Largest random rudder command [rad]."""

RANDOM_HOLD = (15.0, 60.0)
"""Range [s] of the random hold times."""

DEFAULT_DURATION = 600.0
"""Default record length [s]."""

_MAX_FINE_STEP = 0.1


def _check_inputs(
    effect: str | None,
    maneuver: str,
    dt: float,
    duration: float | None,
    base_model: str,
    magnitude: float | None,
) -> tuple[float, float, float | None]:
    if effect is not None and effect not in EFFECTS:
        raise ValueError(f"unknown effect {effect!r}; expected None or one of {EFFECTS}")
    if maneuver not in MANEUVERS:
        raise ValueError(f"unknown maneuver {maneuver!r}; expected one of {MANEUVERS}")
    if base_model not in BASE_MODELS:
        raise ValueError(f"unsupported base_model {base_model!r}; expected one of {BASE_MODELS}")
    try:
        dt = float(dt)
    except (TypeError, ValueError):
        raise ValueError(f"dt must be a number of seconds, got {dt!r}") from None
    if not (math.isfinite(dt) and 0.0 < dt <= 10.0):
        raise ValueError(f"dt must be a sampling interval in (0, 10] s, got {dt!r}")
    dur = DEFAULT_DURATION if duration is None else duration
    try:
        dur = float(dur)
    except (TypeError, ValueError):
        raise ValueError(f"duration must be a number of seconds, got {duration!r}") from None
    if not (math.isfinite(dur) and dur >= 10.0 * dt):
        raise ValueError(f"duration must be finite and at least 10 dt = {10 * dt:g} s, got {dur!r}")
    if magnitude is not None:
        if effect is None:
            raise ValueError("magnitude is only meaningful with an effect; got effect=None")
        try:
            magnitude = float(magnitude)
        except (TypeError, ValueError):
            raise ValueError(f"magnitude must be a number, got {magnitude!r}") from None
        if not math.isfinite(magnitude):
            raise ValueError(f"magnitude must be finite, got {magnitude!r}")
        if effect in ("rudder_lag", "second_order") and magnitude <= 0.0:
            raise ValueError(f"magnitude of {effect!r} is a time constant and must be > 0 s")
        if effect in ("input_delay", "current", "yaw_nonlinearity") and magnitude < 0.0:
            raise ValueError(f"magnitude of {effect!r} must be >= 0, got {magnitude!r}")
        if effect == "second_order" and magnitude >= Nomoto1Params().T + Nomoto2Params().T3:
            raise ValueError(
                f"magnitude (T2) of 'second_order' must be < T + T3 = "
                f"{Nomoto1Params().T + Nomoto2Params().T3:g} s so that T1 > 0"
            )
    return dt, dur, magnitude


def _random_command(rng: np.random.Generator, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """Switch times and levels of a piecewise-constant random rudder command."""
    times = [0.0]
    levels = [float(rng.uniform(-RANDOM_MAX_RUDDER, RANDOM_MAX_RUDDER))]
    while times[-1] <= t_end:
        times.append(times[-1] + float(rng.uniform(*RANDOM_HOLD)))
        levels.append(float(rng.uniform(-RANDOM_MAX_RUDDER, RANDOM_MAX_RUDDER)))
    return np.array(times), np.array(levels)


def generate_record(
    effect: str | None = None,
    *,
    maneuver: Literal["zigzag", "random"] = "zigzag",
    dt: float = 0.5,
    duration: float | None = None,
    noise: bool = True,
    seed: int = 0,
    base_model: str = "nomoto1",
    magnitude: float | None = None,
) -> Record:
    """Simulate a manoeuvre of the Mariner Nomoto ship with at most one undeclared effect.

    Parameters
    ----------
    effect : str or None
        One of :data:`EFFECTS` (see the module docstring), or None for a clean first-order
        Nomoto ship.
    maneuver : {"zigzag", "random"}
        20/20 zigzag on the heading, or a random piecewise-constant rudder command.
    dt : float
        Sampling interval [s] of the record, in (0, 10].
    duration : float, optional
        Record length [s] (default 600 s); at least ``10 dt``.
    noise : bool
        Add Gaussian sensor noise (:data:`NOISE`) to every recorded channel.
    seed : int
        Seed of the random manoeuvre, the current direction and the noise (reproducible).
    base_model : str
        The model the effect deviates from; only ``"nomoto1"`` (:data:`BASE_MODELS`).
    magnitude : float, optional
        Size of the effect in its unit (:data:`EFFECT_DEFAULTS` by default).

    Returns
    -------
    Record
        ``time`` (``k dt``), ``delta`` (measured rudder: the gear state, or the command for
        ``rudder_lag``), ``psi``, ``r``, ``x``, ``y`` (north/east from the start), ``U``.
        ``meta["truth"]`` holds the ground truth, for tests only: identifiers must not read it.

    Raises
    ------
    ValueError
        For an unknown effect, manoeuvre or base model, or a bad ``dt``, ``duration`` or
        ``magnitude``.
    """
    dt, dur, magnitude = _check_inputs(effect, maneuver, dt, duration, base_model, magnitude)
    if effect is not None and magnitude is None:
        magnitude = EFFECT_DEFAULTS[effect]
    seq = np.random.SeedSequence(int(seed))
    rng_man, rng_cur, rng_noise = (np.random.default_rng(s) for s in seq.spawn(3))

    m = max(1, math.ceil(dt / _MAX_FINE_STEP - 1e-9))
    h = dt / m
    n_samples = math.floor(dur / dt + 1e-9) + 1
    n_fine = (n_samples - 1) * m

    base = Nomoto1Params()
    gear = SteeringGear()
    surge = SurgeModel()
    name, params = "nomoto1", base
    current = np.zeros(2)
    effect_params: dict[str, Any] = {}
    delay_steps = 0
    if effect == "rudder_offset":
        assert magnitude is not None
        name = "norrbin"
        params = NorrbinParams(K=base.K, T=base.T, n0=base.K * magnitude, n1=1.0, n2=0.0, n3=0.0)
        effect_params = {"delta_0": magnitude, "n0": params.n0}
    elif effect == "yaw_nonlinearity":
        assert magnitude is not None
        name = "norrbin"
        params = NorrbinParams(K=base.K, T=base.T, n0=0.0, n1=1.0, n2=0.0, n3=magnitude)
        effect_params = {"n3": magnitude}
    elif effect == "rudder_lag":
        assert magnitude is not None
        gear = SteeringGear(time_constant=magnitude)
        effect_params = {"gear_time_constant": magnitude}
    elif effect == "input_delay":
        assert magnitude is not None
        delay_steps = round(magnitude / h)
        effect_params = {"tau": delay_steps * h, "tau_requested": magnitude}
    elif effect == "current":
        assert magnitude is not None
        direction = float(rng_cur.uniform(0.0, 2.0 * math.pi))
        current = magnitude * np.array([math.cos(direction), math.sin(direction)])
        effect_params = {
            "speed": magnitude,
            "direction": direction,
            "V_n": float(current[0]),
            "V_e": float(current[1]),
        }
    elif effect == "second_order":
        assert magnitude is not None
        d2 = Nomoto2Params()
        name = "nomoto2"
        params = Nomoto2Params(K=base.K, T1=base.T + d2.T3 - magnitude, T2=magnitude, T3=d2.T3)
        effect_params = {"T1": params.T1, "T2": params.T2, "T3": params.T3}

    model = make_model(name, params, gear=gear, surge=surge)
    x0 = np.zeros(model.nx)
    x0[IU] = surge.service_speed
    n_shaft = surge.service_shaft_speed

    # The manoeuvre decides the command delta_c(t) from the state; with an input delay the
    # model receives delta_c(t - tau) and the recorded gear angle is the state tau later.
    commands: list[float] = []
    if maneuver == "zigzag":
        sign = [1.0]

        def decide(t: float, x: np.ndarray) -> float:
            dpsi = x[IPSI] - x0[IPSI]
            if sign[0] > 0 and dpsi >= ZIGZAG_ANGLE:
                sign[0] = -1.0
            elif sign[0] < 0 and dpsi <= -ZIGZAG_ANGLE:
                sign[0] = 1.0
            return sign[0] * ZIGZAG_ANGLE

    else:
        switch_t, levels = _random_command(rng_man, (n_fine + delay_steps + 1) * h)

        def decide(t: float, x: np.ndarray) -> float:
            return float(levels[np.searchsorted(switch_t, t + 1e-9 * h, side="right") - 1])

    def controller(t: float, x: np.ndarray) -> list[float]:
        commands.append(decide(t, x))
        k = len(commands) - 1 - delay_steps
        return [commands[k] if k >= 0 else 0.0, n_shaft]

    total = n_fine + delay_steps + 1
    sim = model.simulate(x0, controller, h, n_steps=total, current=current)
    idx = np.arange(n_samples) * m
    states = sim.states[idx]
    if effect == "rudder_lag":
        delta = np.asarray(commands)[idx]
    else:
        delta = sim.states[idx + delay_steps, IDELTA]
    time = idx * h
    psi, r = states[:, IPSI], states[:, IR]
    x, y, U = states[:, IX], states[:, IY], states[:, IU]
    if noise:
        n = n_samples
        delta = delta + NOISE["delta"] * rng_noise.standard_normal(n)
        psi = psi + NOISE["psi"] * rng_noise.standard_normal(n)
        r = r + NOISE["r"] * rng_noise.standard_normal(n)
        x = x + NOISE["xy"] * rng_noise.standard_normal(n)
        y = y + NOISE["xy"] * rng_noise.standard_normal(n)
        U = U + NOISE["U"] * rng_noise.standard_normal(n)

    truth = {
        "model": name,
        "params": asdict(params),
        "gear": asdict(gear),
        "surge": asdict(surge),
        "current": current.tolist(),
        "x0": x0.tolist(),
        "base_model": base_model,
        "base_params": asdict(base),
        "effect": effect,
        "effect_params": effect_params,
        "magnitude": magnitude,
        "fine_step": h,
    }
    meta = {
        "source": "shipgym.sysid.generator",
        "vessel": "Mariner class cargo ship (Nomoto family defaults)",
        "L": 160.93,
        "scale": "full",
        "frame": "x north, y east [m] from the start position",
        "r_source": "measured",
        "maneuver": maneuver,
        "dt": dt,
        "seed": int(seed),
        "noise": dict(NOISE) if noise else None,
        "conversions": [],
        "repairs": [],
        "notes": [
            "synthetic record; meta['truth'] is the ground truth for tests only and must not be "
            "read by an identifier"
        ],
        "truth": truth,
    }
    return Record(time=time, delta=delta, psi=psi, r=r, x=x, y=y, U=U, meta=meta)

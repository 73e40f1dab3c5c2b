"""Synthetic manoeuvring records with one undeclared effect, for testing identification tools.

The known truth of identification tests:
a record that looks like a measured one (:class:`shipgym.sysid.data.Record`, canonical units and
sign convention) but whose ship deviates from a base model (:data:`BASE_MODELS`) in exactly one
documented way. Every record is simulated through :mod:`shipgym.models`
(:meth:`ShipModel.simulate` with the manoeuvre as a controller callback); no model equation is
written here. Two base models:

* ``"nomoto1"``: the first-order Nomoto ship ``T r' + r = K delta`` (seed 000, seed 004 eq. 2)
  with the Mariner defaults of :mod:`shipgym.models` (``K = 0.185 1/s``, ``T = 107.3 s``, service
  speed 7.7 m/s, steering gear ``T_delta = 2 s``, 35 deg, 2.32 deg/s); controller
  ``(t, x) -> [delta_c, n]``.
* ``"rvg3dof"``: the R/V Gunnerus 3-DOF model (seed 001 eq. 5-20, :mod:`shipgym.models.rvg`)
  with the :class:`~shipgym.models.RVGParams` defaults (pods: first-order thrust and azimuth,
  eq. 18; pod loads, eq. 19-20), producing Gunnerus-like records (section 6 of
  ``data/measured/SOURCES.md``); controller ``(t, x) -> [T_c, T_c, alpha_c, alpha_c]``.

Effects of the ``"nomoto1"`` base (:data:`EFFECTS_BY_BASE`; ``magnitude`` is in the unit given,
the default in brackets):

==================== ===========================================================================
effect               definition
==================== ===========================================================================
``rudder_offset``    The rudder needed for straight running is ``delta_0`` [rad] (2 deg): the
                     true ship is Norrbin's model (seed 002 eq. 1) with the same K, T and
                     ``n0 = K delta_0``, ``n1 = 1``, ``n2 = n3 = 0``, i.e.
                     ``T r' + r = K (delta - delta_0)``. The recorded rudder is the steering-gear
                     state; it does NOT contain the offset.
``yaw_nonlinearity`` Norrbin cubic term: the true ship is ``T r' + n3 r^3 + r = K delta``
                     (seed 002 eq. 1, seed 004 eq. 4) with ``n3`` [s^2] (2.9e3, the shipgym
                     default), ``n0 = n2 = 0``, ``n1 = 1``.
``rudder_lag``       The recorded rudder is the COMMAND ``delta_c``, while the actual rudder
                     follows it through a slow gear: first-order time constant ``T_delta`` [s]
                     (8 s) with the default angle and rate limits (seed 002 eq. 2).
``input_delay``      The recorded rudder leads the rudder the ship feels by a pure delay
                     ``tau`` [s] (3 s, rounded to the internal step): the ship responds to
                     ``delta(t - tau)`` where ``delta`` is the recorded gear angle (as if the
                     rudder log's clock were ``tau`` ahead, or a transport delay between the
                     measured angle and the hydrodynamic force). In the zigzag the controller
                     acts on the measured heading, so its switching is delayed too.
``current``          A constant irrotational current of speed ``V_c`` [m/s] (0.5 m/s) toward a
                     direction drawn from the seed (uniform on [0, 2 pi)), entering only the
                     kinematics ``x' = U cos psi + V_n``, ``y' = U sin psi + V_e``. A Nomoto
                     model's yaw is unaffected by a uniform current, so only position-based
                     criteria (dead reckoning against the recorded track) can see it.
``second_order``     The true ship is the second-order Nomoto model (seed 004 eq. 1) with the
                     Mariner ``K = 0.185``, ``T2`` [s] (7.8 s), ``T3 = 18.5 s`` and
                     ``T1 = T + T3 - T2`` (118 s), so its first-order equivalent
                     ``T1 + T2 - T3`` equals the base ``T``.
==================== ===========================================================================

Effects of the ``"rvg3dof"`` base (the clean ship, ``effect=None``, is seed 001's model: no pod
lift, no offset, no current):

=================== ===========================================================================
effect              definition
=================== ===========================================================================
``thruster_lift``   The pods are foils: the true ship has ``RVGParams(pod_lift_coefficient=
                    c_L, pod_slipstream=POD_SLIPSTREAM_FMU)`` with ``c_L`` [N s^2/m^2]
                    (``POD_LIFT_COEFFICIENT_FMU``, about 5.2e3, the fit to the Kongsberg pod
                    data), i.e. each pod adds the normal force from its own inflow that seed 001
                    eq. (19) leaves out (:mod:`shipgym.models.rvg`). It grows with the square
                    of the speed, unlike the thrust side force ``T sin(alpha)``, and damps sway
                    and yaw.
``azimuth_offset``  The pods' actual azimuth command is the recorded command plus ``alpha_0``
                    [rad] (2 deg) on both pods (an encoder or calibration bias; ``|alpha_0|``
                    below 90 deg). The recorded azimuth does NOT contain the offset; a
                    positive ``alpha_0`` turns the ship to port on a zero command.
``current``         A constant irrotational current of speed ``V_c`` [m/s] (0.5 m/s) toward a
                    direction drawn from the seed as for ``nomoto1``, passed to the model
                    (seed 001 eq. 7-12: it enters the kinetics through the relative velocity
                    ``nu_r = nu - nu_c`` and the propeller law through ``u_r``). The recorded
                    ``u``, ``v`` are ground velocities, as in the sea trial.
``sway_offset``     The recorded transverse speed carries an offset ``v_0`` [m/s] (0.2 m/s):
                    a speed-log or GNSS-antenna misalignment, as the Gunnerus record's
                    +0.2 m/s on straight runs on every heading (SOURCES.md oddity 3). The
                    ship is the clean one; only the recorded ``v`` (and ``U``) differ.
``wave_resistance`` The hull makes waves: the true ship has ``RVGParams(wave_resistance=c_w)``
                    (0.1), the resistance ``c_w Fn^2 rho/2 S u^2`` that grows faster than the
                    seed's ``u^2`` drag (:mod:`shipgym.models.rvg`): slower at high rpm.
=================== ===========================================================================

Manoeuvres (``maneuver``):

* ``"zigzag"``: a 20/20 zigzag (IMO style, ``ZIGZAG_ANGLE``): the command starts at +20 deg
  (starboard) and switches sign each time the heading passes +-20 deg from the initial heading
  (simple switching rule on the true heading). For ``rvg3dof`` the command is the pods' azimuth
  with their own sign, ``azimuth = -delta`` (it starts at -20 deg, a starboard turn), at a
  constant ``RVG_ZIGZAG_RPM`` (170 rpm). Seed 001's ship steers weakly: the clean 20/20 zigzag
  overshoots by about 37 deg (97 deg the first time) at about 3.6 m/s; with the default foil
  lift by about 18 deg.
* ``"random"``: a piecewise-constant random rudder (``nomoto1``) or azimuth (``rvg3dof``)
  command, levels uniform in ``[-RANDOM_MAX_RUDDER, RANDOM_MAX_RUDDER]`` (25 deg), hold times
  uniform in ``RANDOM_HOLD`` (15 to 60 s), drawn from the seed. For ``rvg3dof`` the rpm command
  is piecewise constant too, on the levels ``RVG_RPM_LEVELS`` (110, 140, 170, 195 rpm: the
  first drawn uniformly, each later one uniformly among the other three), each held a time
  uniform in ``RVG_RPM_HOLD`` (60 to 180 s), from its own random stream: the speed variation is
  what separates the foil lift (``~ u_r^2``) from the thrust side force.

``nomoto1``: the shaft speed is the service shaft speed throughout (``U`` stays at 7.7 m/s: the
Nomoto models have no speed loss in turns). ``rvg3dof``: the record carries the COMMANDS, like
the Gunnerus sea trial: ``azimuth`` [rad, positive turns to port], ``delta = -azimuth`` and
``rpm`` [rev/min]; at every fine step the rpm command is turned into the per-pod thrust command
``T_c = pod_thrust(rpm, u_r)`` (the project's propeller law, :func:`shipgym.models.rvg.pod_thrust`,
with ``u_r`` the body surge minus the body-frame current component, seed 001 eq. 8), and the pods
follow ``[T_c, T_c, alpha_c, alpha_c]`` through their first-order dynamics (eq. 18). The ship
starts in steady straight running at the initial rpm command with heading 0 and the pods at zero
azimuth: the steady relative surge speed ``u_0`` is the root of the model's surge acceleration
(:meth:`ShipModel.deriv`, ``brentq``) with the thrust states at ``pod_thrust(rpm, u_0)``; with a
current, the ground velocity is ``[u_0, 0]`` plus the body-frame current, so the ship starts
steady in the water. Default durations: :data:`DEFAULT_DURATIONS` (600 s for ``nomoto1``, 1200 s
for ``rvg3dof``). The simulation runs with a fine step ``h = dt / ceil(dt / 0.1)`` (at most
0.1 s) and is sampled every ``dt``.

Sensor noise (``noise=True``; :data:`NOISE`, white Gaussian, independent per sample and channel):
heading 0.1 deg, yaw rate 0.02 deg/s, positions 1 m; ``nomoto1``: rudder 0.1 deg, speed
0.02 m/s; ``rvg3dof``: body velocities ``u``, ``v`` 0.02 m/s each (``U = hypot(u, v)`` is
computed from the noisy ``u``, ``v``, as the sea-trial loader does) and NO noise on the commands
``azimuth``, ``delta``, ``rpm``. The noise draws come from their own random stream, so
``noise=False`` gives the same trajectory. The ``nomoto1`` rudder noise is an
errors-in-variables disturbance for a fit that replays the recorded rudder: through
``K / (s (1 + T s))`` it makes the replayed heading wander slowly, so the psi residual of a
correct output-error fit of a clean 600 s record is 1.0 to 1.1 times the heading noise at
``dt = 0.1 s`` and up to about 2 times at ``dt = 1 s`` (the r residual stays at its noise
level).

The ground truth (true model name and parameters, gear, surge, current, initial state, base
model, the effect and its parameters, the realised delay...) is stored in
``record.meta["truth"]`` (for ``rvg3dof`` the :class:`~shipgym.models.RVGParams` as a plain dict
with lists for the matrices, ``gear = surge = None``, and the steady relative surge speed
``u_0``). It is there
for tests and benchmarks only: **an identifier or diagnostic must not read it**; nothing else in
the record (channels or the other meta keys) depends on which effect was applied, apart from the
effect's influence on the signals.

Several runs of one 3-DOF ship, for the multi-run families (``vmm:<term set>``):
:func:`generate_vmm_runs` simulates a known VMM (its own polynomials, with ``current``, ``wind``
or ``rudder_slipstream``); :func:`generate_mmg_runs` simulates the KVLCC2 L7 tank model with the
MMG standard model (Yasukawa and Yoshimura 2015, :mod:`shipgym.models.mmg`), whose rudder and
propeller forces the VMM polynomials do not share (the ``mmg_hull`` term set holds its hull
polynomial), with one of ``rudder_offset``, ``rudder_lag``, ``input_delay``,
``current`` and ``wind`` (Blendermann's loads, :mod:`shipgym.models.wind`), as short runs as a
tank gives, noise on every channel and the ship's main particulars as plain meta keys.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from typing import Any, Literal

import numpy as np
from scipy.optimize import brentq

from shipgym.models import (
    MMGParams,
    Nomoto1Params,
    Nomoto2Params,
    NorrbinParams,
    RVGParams,
    ShipModel,
    SteeringGear,
    SurgeModel,
    make_model,
)
from shipgym.models import mmg as _mmg
from shipgym.models import rvg as _rvg
from shipgym.models.mmg import KVLCC2_SIMMAN_SPEED
from shipgym.models.nomoto import IDELTA, IPSI, IR, IU, IX, IY
from shipgym.models.wind import apparent_wind
from shipgym.sysid.data import Record, wrap_angle

__all__ = [
    "BASE_MODELS",
    "DEFAULT_DURATIONS",
    "EFFECTS",
    "EFFECTS_BY_BASE",
    "EFFECT_DEFAULTS",
    "MANEUVERS",
    "MMG_APPROACH",
    "MMG_DURATION",
    "MMG_EFFECTS",
    "MMG_EFFECT_RANGES",
    "MMG_NOISE",
    "MMG_RUNS",
    "MMG_SPEED_SPREAD",
    "NOISE",
    "RVG_RPM_HOLD",
    "RVG_RPM_LEVELS",
    "RVG_ZIGZAG_RPM",
    "VMM_EFFECTS",
    "VMM_NOISE",
    "VMM_RUNS",
    "generate_mmg_runs",
    "generate_record",
    "generate_vmm_runs",
    "vmm_truth",
]

BASE_MODELS: tuple[str, ...] = ("nomoto1", "rvg3dof")
"""Base models the effects are defined against: the first-order Nomoto ship and the R/V
Gunnerus 3-DOF model."""

EFFECTS_BY_BASE: dict[str, tuple[str, ...]] = {
    "nomoto1": (
        "rudder_offset",
        "yaw_nonlinearity",
        "rudder_lag",
        "input_delay",
        "current",
        "second_order",
    ),
    "rvg3dof": ("thruster_lift", "azimuth_offset", "current", "sway_offset", "wave_resistance"),
}
"""The undeclared effects defined for each base model (see the module docstring)."""

EFFECTS: tuple[str, ...] = tuple(
    dict.fromkeys(e for base in BASE_MODELS for e in EFFECTS_BY_BASE[base])
)
"""Catalogue of all undeclared effects (the union over :data:`EFFECTS_BY_BASE`, ``nomoto1``'s
first)."""

EFFECT_DEFAULTS: dict[str, float] = {
    "rudder_offset": math.radians(2.0),  # delta_0 [rad]
    "yaw_nonlinearity": 2.9e3,  # n3 [s^2]
    "rudder_lag": 8.0,  # gear time constant [s]
    "input_delay": 3.0,  # tau [s]
    "current": 0.5,  # current speed [m/s]
    "second_order": 7.8,  # T2 [s]
    "thruster_lift": _rvg.POD_LIFT_COEFFICIENT_FMU,  # c_L [N s^2/m^2]
    "azimuth_offset": math.radians(2.0),  # alpha_0 [rad]
    "sway_offset": 0.2,  # v_0 [m/s]
    "wave_resistance": 0.1,  # c_w [-] (the generated ship tops at Fn 0.29: a smaller c_w is
    # within what the calibrated u^2 drag absorbs over its speed range)
}
"""Default ``magnitude`` of each effect, in the unit of the module docstring's tables."""

MANEUVERS: tuple[str, ...] = ("zigzag", "random")
"""Accepted values of ``maneuver``."""

NOISE: dict[str, float] = {
    "psi": math.radians(0.1),  # rad
    "r": math.radians(0.02),  # rad/s
    "delta": math.radians(0.1),  # rad (nomoto1 only: the RVG commands carry no noise)
    "xy": 1.0,  # m
    "U": 0.02,  # m/s (nomoto1)
    "uv": 0.02,  # m/s, each of the body velocities u, v (rvg3dof)
}
"""Standard deviations of the Gaussian sensor noise (``noise=True``)."""

_NOISE_KEYS = {"nomoto1": ("psi", "r", "delta", "xy", "U"), "rvg3dof": ("psi", "r", "xy", "uv")}

ZIGZAG_ANGLE = math.radians(20.0)
"""Rudder (or azimuth) and heading-switch angle [rad] of the zigzag (20/20)."""

RANDOM_MAX_RUDDER = math.radians(25.0)
"""Largest random rudder (or azimuth) command [rad]."""

RANDOM_HOLD = (15.0, 60.0)
"""Range [s] of the random hold times."""

DEFAULT_DURATION = 600.0
"""Default record length [s] of the ``nomoto1`` base."""

DEFAULT_DURATIONS: dict[str, float] = {"nomoto1": DEFAULT_DURATION, "rvg3dof": 1200.0}
"""Default record length [s] per base model."""

RVG_ZIGZAG_RPM = 170.0
"""Constant rpm command [rev/min] of the RVG zigzag (the sea trial's turning rpm)."""

RVG_RPM_LEVELS: tuple[float, ...] = (110.0, 140.0, 170.0, 195.0)
"""rpm command levels [rev/min] of the RVG random manoeuvre (195 is the sea trial's cap)."""

RVG_RPM_HOLD = (60.0, 180.0)
"""Range [s] of the hold times of the RVG random rpm command."""

_MAX_FINE_STEP = 0.1


def _check_inputs(
    effect: str | None,
    maneuver: str,
    dt: float,
    duration: float | None,
    base_model: str,
    magnitude: float | None,
) -> tuple[float, float, float | None]:
    if base_model not in BASE_MODELS:
        raise ValueError(f"unsupported base_model {base_model!r}; expected one of {BASE_MODELS}")
    valid = EFFECTS_BY_BASE[base_model]
    if effect is not None and effect not in valid:
        kind = "is not defined" if effect in EFFECTS else "is unknown"
        raise ValueError(
            f"effect {effect!r} {kind} for base_model {base_model!r}; expected None or one of "
            f"{valid}"
        )
    if maneuver not in MANEUVERS:
        raise ValueError(f"unknown maneuver {maneuver!r}; expected one of {MANEUVERS}")
    try:
        dt = float(dt)
    except (TypeError, ValueError):
        raise ValueError(f"dt must be a number of seconds, got {dt!r}") from None
    if not (math.isfinite(dt) and 0.0 < dt <= 10.0):
        raise ValueError(f"dt must be a sampling interval in (0, 10] s, got {dt!r}")
    dur = DEFAULT_DURATIONS[base_model] if duration is None else duration
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
        if (
            effect
            in ("input_delay", "current", "yaw_nonlinearity", "thruster_lift", "wave_resistance")
            and magnitude < 0.0
        ):
            raise ValueError(f"magnitude of {effect!r} must be >= 0, got {magnitude!r}")
        if effect == "second_order" and magnitude >= Nomoto1Params().T + Nomoto2Params().T3:
            raise ValueError(
                f"magnitude (T2) of 'second_order' must be < T + T3 = "
                f"{Nomoto1Params().T + Nomoto2Params().T3:g} s so that T1 > 0"
            )
        if effect == "azimuth_offset" and not abs(magnitude) < 0.5 * math.pi:
            raise ValueError(
                f"magnitude (alpha_0) of 'azimuth_offset' must be an angle in (-pi/2, pi/2) rad "
                f"so that the pods still push ahead, got {magnitude!r}"
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


def _random_rpm(rng: np.random.Generator, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """Switch times and levels of the piecewise-constant random rpm command of the RVG.

    Each switch moves to one of the other levels (uniformly), so every hold is a real change.
    """
    times = [0.0]
    levels = [float(rng.choice(RVG_RPM_LEVELS))]
    while times[-1] <= t_end:
        times.append(times[-1] + float(rng.uniform(*RVG_RPM_HOLD)))
        others = [level for level in RVG_RPM_LEVELS if level != levels[-1]]
        levels.append(float(rng.choice(others)))
    return np.array(times), np.array(levels)


def _draw_current(rng: np.random.Generator, speed: float) -> tuple[np.ndarray, dict[str, Any]]:
    """Current of ``speed`` [m/s] toward a direction uniform on [0, 2 pi), and its description."""
    direction = float(rng.uniform(0.0, 2.0 * math.pi))
    current = speed * np.array([math.cos(direction), math.sin(direction)])
    return current, {
        "speed": speed,
        "direction": direction,
        "V_n": float(current[0]),
        "V_e": float(current[1]),
    }


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
    """Simulate a manoeuvre of a base ship (Mariner Nomoto or R/V Gunnerus) with at most one
    undeclared effect.

    Parameters
    ----------
    effect : str or None
        One of ``EFFECTS_BY_BASE[base_model]`` (see the module docstring), or None for the clean
        base ship.
    maneuver : {"zigzag", "random"}
        20/20 zigzag on the heading, or a random piecewise-constant rudder (azimuth and rpm for
        ``rvg3dof``) command.
    dt : float
        Sampling interval [s] of the record, in (0, 10].
    duration : float, optional
        Record length [s] (default :data:`DEFAULT_DURATIONS`: 600 s for ``nomoto1``, 1200 s for
        ``rvg3dof``); at least ``10 dt``.
    noise : bool
        Add Gaussian sensor noise (:data:`NOISE`) to every recorded measurement channel (not to
        the RVG commands ``azimuth``, ``delta``, ``rpm``).
    seed : int
        Seed of the random manoeuvre, the current direction and the noise (reproducible).
    base_model : {"nomoto1", "rvg3dof"}
        The model the effect deviates from (:data:`BASE_MODELS`).
    magnitude : float, optional
        Size of the effect in its unit (:data:`EFFECT_DEFAULTS` by default).

    Returns
    -------
    Record
        ``nomoto1``: ``time`` (``k dt``), ``delta`` (measured rudder: the gear state, or the
        command for ``rudder_lag``), ``psi``, ``r``, ``x``, ``y`` (north/east from the start),
        ``U``. ``rvg3dof``: ``time``, ``azimuth`` (command [rad], positive turns to port),
        ``delta = -azimuth``, ``rpm`` (command [rev/min]), ``psi``, ``r``, ``x``, ``y``, ``u``,
        ``v`` (body velocities over ground), ``U = hypot(u, v)``. ``meta["truth"]`` holds the
        ground truth, for tests only: identifiers must not read it.

    Raises
    ------
    ValueError
        For an unknown base model or manoeuvre, an effect not defined for the base model, or a
        bad ``dt``, ``duration`` or ``magnitude``.
    """
    dt, dur, magnitude = _check_inputs(effect, maneuver, dt, duration, base_model, magnitude)
    if effect is not None and magnitude is None:
        magnitude = EFFECT_DEFAULTS[effect]
    if base_model == "rvg3dof":
        return _rvg_record(effect, maneuver, dt, dur, noise, seed, magnitude)
    return _nomoto_record(effect, maneuver, dt, dur, noise, seed, magnitude)


def _nomoto_record(
    effect: str | None,
    maneuver: str,
    dt: float,
    dur: float,
    noise: bool,
    seed: int,
    magnitude: float | None,
) -> Record:
    """The ``nomoto1`` branch of :func:`generate_record` (inputs already checked)."""
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
        current, effect_params = _draw_current(rng_cur, magnitude)
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
        "base_model": "nomoto1",
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
        "noise": {k: NOISE[k] for k in _NOISE_KEYS["nomoto1"]} if noise else None,
        "conversions": [],
        "repairs": [],
        "notes": [
            "synthetic record; meta['truth'] is the ground truth for tests only and must not be "
            "read by an identifier"
        ],
        "truth": truth,
    }
    return Record(time=time, delta=delta, psi=psi, r=r, x=x, y=y, U=U, meta=meta)


def _rvg_params_dict(params: RVGParams) -> dict[str, Any]:
    """``RVGParams`` as a plain JSON-able dict (matrices as nested lists)."""
    return {
        k: (v.tolist() if isinstance(v, np.ndarray) else list(v) if isinstance(v, tuple) else v)
        for k, v in asdict(params).items()
    }


def _rvg_steady_surge(model: ShipModel, rpm: float) -> float:
    """Relative surge speed [m/s] of steady straight running at ``rpm`` in calm water.

    The root of the model's surge acceleration with zero azimuth, ``v = r = 0`` and both thrust
    states (and commands) at ``pod_thrust(rpm, u)`` (module docstring).
    """
    p = model.p
    x = np.zeros(model.nx)

    def surge_acceleration(u: float) -> float:
        thrust = _rvg.pod_thrust(rpm, u, p)
        x[_rvg.IU] = u
        x[_rvg.IT1] = x[_rvg.IT2] = thrust
        return float(model.deriv(x, [thrust, thrust, 0.0, 0.0])[0, _rvg.IU])

    # the thrust, hence the acceleration, is > 0 at rest and 0 at the thrust-limit speed
    return float(brentq(surge_acceleration, 0.0, model.params.thrust_zero_speed, xtol=1e-13))


def _rvg_record(
    effect: str | None,
    maneuver: str,
    dt: float,
    dur: float,
    noise: bool,
    seed: int,
    magnitude: float | None,
) -> Record:
    """The ``rvg3dof`` branch of :func:`generate_record` (inputs already checked)."""
    seq = np.random.SeedSequence(int(seed))
    # the first three streams as for nomoto1 (azimuth as the rudder, current, noise), then rpm
    rng_man, rng_cur, rng_noise, rng_rpm = (np.random.default_rng(s) for s in seq.spawn(4))

    m = max(1, math.ceil(dt / _MAX_FINE_STEP - 1e-9))
    h = dt / m
    n_samples = math.floor(dur / dt + 1e-9) + 1
    n_fine = (n_samples - 1) * m

    base = RVGParams()
    params = base
    current = np.zeros(2)
    alpha_0 = 0.0
    effect_params: dict[str, Any] = {}
    if effect == "thruster_lift":
        assert magnitude is not None
        params = RVGParams(pod_lift_coefficient=magnitude, pod_slipstream=_rvg.POD_SLIPSTREAM_FMU)
        effect_params = {"c_L": magnitude}
    elif effect == "azimuth_offset":
        assert magnitude is not None
        alpha_0 = magnitude
        effect_params = {"alpha_0": magnitude}
    elif effect == "current":
        assert magnitude is not None
        current, effect_params = _draw_current(rng_cur, magnitude)
    elif effect == "sway_offset":
        assert magnitude is not None
        effect_params = {"v_0": magnitude}
    elif effect == "wave_resistance":
        assert magnitude is not None
        params = RVGParams(wave_resistance=magnitude)
        effect_params = {"c_w": magnitude}
    model = make_model("rvg3dof", params)
    p = model.p
    t_end = (n_fine + 1) * h

    # The manoeuvre decides the azimuth and rpm COMMANDS (the recorded channels) from the state.
    azimuth_cmd: Callable[[float, np.ndarray], float]
    rpm_cmd: Callable[[float], float]
    if maneuver == "zigzag":
        sign = [1.0]  # sign of delta = -azimuth: starts with a starboard turn

        def azimuth_cmd(t: float, x: np.ndarray) -> float:
            dpsi = x[_rvg.IPSI]  # the initial heading is 0
            if sign[0] > 0 and dpsi >= ZIGZAG_ANGLE:
                sign[0] = -1.0
            elif sign[0] < 0 and dpsi <= -ZIGZAG_ANGLE:
                sign[0] = 1.0
            return -sign[0] * ZIGZAG_ANGLE

        def rpm_cmd(t: float) -> float:
            return RVG_ZIGZAG_RPM

    else:
        az_t, az_levels = _random_command(rng_man, t_end)
        rpm_t, rpm_levels = _random_rpm(rng_rpm, t_end)

        def azimuth_cmd(t: float, x: np.ndarray) -> float:
            return float(az_levels[np.searchsorted(az_t, t + 1e-9 * h, side="right") - 1])

        def rpm_cmd(t: float) -> float:
            return float(rpm_levels[np.searchsorted(rpm_t, t + 1e-9 * h, side="right") - 1])

    # steady straight running at the initial rpm, steady in the water (see module docstring)
    rpm0 = rpm_cmd(0.0)
    u_r0 = _rvg_steady_surge(model, rpm0)
    thrust0 = _rvg.pod_thrust(rpm0, u_r0, p)
    x0 = np.zeros(model.nx)
    x0[_rvg.IU] = u_r0 + current[0]  # body-frame current at psi = 0 is (V_n, V_e)
    x0[_rvg.IV] = current[1]
    x0[_rvg.IT1] = x0[_rvg.IT2] = thrust0

    azimuths: list[float] = []
    rpms: list[float] = []

    def controller(t: float, x: np.ndarray) -> list[float]:
        azimuth = azimuth_cmd(t, x)
        rpm = rpm_cmd(t)
        azimuths.append(azimuth)
        rpms.append(rpm)
        t1, t2 = _rvg.pod_thrusts(rpm, x, current, p)  # at each pod's axial inflow
        alpha = azimuth + alpha_0
        return [t1, t2, alpha, alpha]

    sim = model.simulate(x0, controller, h, n_steps=n_fine + 1, current=current)
    idx = np.arange(n_samples) * m
    states = sim.states[idx]
    time = idx * h
    azimuth = np.asarray(azimuths)[idx]
    rpm = np.asarray(rpms)[idx]
    psi, r = states[:, _rvg.IPSI], states[:, _rvg.IR]
    x, y = states[:, _rvg.IX], states[:, _rvg.IY]
    u, v = states[:, _rvg.IU], states[:, _rvg.IV]
    if effect == "sway_offset":
        v = v + effect_params["v_0"]
    if noise:
        n = n_samples
        psi = psi + NOISE["psi"] * rng_noise.standard_normal(n)
        r = r + NOISE["r"] * rng_noise.standard_normal(n)
        x = x + NOISE["xy"] * rng_noise.standard_normal(n)
        y = y + NOISE["xy"] * rng_noise.standard_normal(n)
        u = u + NOISE["uv"] * rng_noise.standard_normal(n)
        v = v + NOISE["uv"] * rng_noise.standard_normal(n)

    truth = {
        "model": "rvg3dof",
        "params": _rvg_params_dict(params),
        "gear": None,
        "surge": None,
        "current": current.tolist(),
        "x0": x0.tolist(),
        "steady_relative_surge": u_r0,
        "rpm_law": "shipgym.models.rvg.pod_thrusts(rpm, x, current)",
        "base_model": "rvg3dof",
        "base_params": _rvg_params_dict(base),
        "effect": effect,
        "effect_params": effect_params,
        "magnitude": magnitude,
        "fine_step": h,
    }
    meta = {
        "source": "shipgym.sysid.generator",
        "vessel": "R/V Gunnerus (RVG 3-DOF model, seed 001)",
        "L": _rvg.LPP,
        "scale": "full",
        "frame": "x north, y east [m] from the start position",
        "r_source": "measured",
        "maneuver": maneuver,
        "dt": dt,
        "seed": int(seed),
        "noise": {k: NOISE[k] for k in _NOISE_KEYS["rvg3dof"]} if noise else None,
        "conversions": [
            "delta = -azimuth (both pods steer together; positive azimuth turns to port)"
        ],
        "repairs": [],
        "notes": [
            "synthetic record; meta['truth'] is the ground truth for tests only and must not be "
            "read by an identifier",
            "azimuth and rpm are commands (orders) of both pods, noise-free: the pods lag them",
            "u, v are body-frame velocities over ground (include current); U = hypot(u, v)",
        ],
        "truth": truth,
    }
    return Record(
        time=time,
        delta=-azimuth,
        psi=psi,
        r=r,
        x=x,
        y=y,
        u=u,
        v=v,
        U=np.hypot(u, v),
        azimuth=azimuth,
        rpm=rpm,
        meta=meta,
    )


# --------------------------------------------------------------------------------------------
# 3-DOF model tests: several runs of one ship (shared by the VMM and MMG generators)


def _check_runs_arguments(
    effect: str | None,
    effects: tuple[str, ...],
    n_runs: Any,
    max_runs: int,
    dt: Any,
    seed: Any,
    magnitude: Any,
) -> None:
    """``ValueError`` for an argument of :func:`generate_vmm_runs` or :func:`generate_mmg_runs`
    outside what it accepts (``effects``: the generator's effects; ``max_runs``: the length of
    its run programme)."""
    if effect is not None and effect not in effects:
        raise ValueError(f"unknown effect {effect!r}; expected None or one of {effects}")
    if not (isinstance(n_runs, int) and not isinstance(n_runs, bool) and 1 <= n_runs <= max_runs):
        raise ValueError(f"n_runs must be an integer in [1, {max_runs}], got {n_runs!r}")
    if not (
        isinstance(dt, int | float) and not isinstance(dt, bool) and math.isfinite(dt)
        and 0.01 <= dt <= 0.5
    ):  # fmt: skip
        raise ValueError(f"dt must be in [0.01, 0.5] s, got {dt!r}")
    if not (isinstance(seed, int | np.integer) and not isinstance(seed, bool) and seed >= 0):
        raise ValueError(f"seed must be an integer >= 0, got {seed!r}")
    if not (
        isinstance(magnitude, int | float) and not isinstance(magnitude, bool)
        and math.isfinite(magnitude) and magnitude > 0
    ):  # fmt: skip
        raise ValueError(f"magnitude must be a finite number > 0, got {magnitude!r}")


def _noisy(rng: np.random.Generator, on: bool, sigma: float, a: np.ndarray) -> np.ndarray:
    """``a`` plus white Gaussian noise of standard deviation ``sigma`` when ``on``."""
    return a + rng.normal(0.0, sigma, a.shape[0]) if on else a


@dataclass
class _RudderProgramme:
    """The rudder command of one run of a 3-DOF run programme (:data:`VMM_RUNS`,
    :data:`MMG_RUNS`), called with the time and the true heading at every fine step.

    Zero before ``start`` [s]; then a zigzag of ``angle`` [rad] that starts to the side
    ``sign`` (+1 starboard) and switches each time the heading passes ``+-b`` deg from
    ``psi0``; a turn of ``angle`` to the side ``sign`` held until ``b`` s before
    ``duration``, then amidships; or the piecewise-constant ``levels`` (switch times, levels).
    """

    kind: str
    angle: float
    b: float
    sign: float
    duration: float
    psi0: float = 0.0
    start: float = 0.0
    levels: tuple[np.ndarray, np.ndarray] | None = None

    def __call__(self, t: float, psi: float) -> float:
        if t < self.start:
            return 0.0
        if self.kind == "zigzag":
            psi_deg = math.degrees(psi - self.psi0)
            if self.sign > 0 and psi_deg > self.b:
                self.sign = -1.0
            elif self.sign < 0 and psi_deg < -self.b:
                self.sign = 1.0
            return self.sign * self.angle
        if self.kind == "turning":
            return self.sign * self.angle if t < self.duration - self.b else 0.0
        assert self.levels is not None
        times, levels = self.levels
        return float(levels[np.searchsorted(times, t, side="right") - 1])


def _fine_step(dt: float) -> tuple[float, int]:
    """Integration step ``h <= 0.05 s`` that divides the sampling interval ``dt``, and the
    number of steps per sample."""
    h = dt / max(1, math.ceil(dt / 0.05 - 1e-9))
    return h, round(dt / h)


VMM_EFFECTS: tuple[str, ...] = ("current", "wind", "rudder_slipstream")
"""Undeclared effects of :func:`generate_vmm_runs` (the identification effects of
:mod:`shipgym.sysid.families.vmm` that change the motions)."""

VMM_EFFECT_TERMS: dict[str, dict[str, float]] = {
    # apparent wind on a model at about 3 m/s relative wind: a side force of 20-30 % of the
    # rudder's at 10 deg (Esso Osaka in the pond: wind 1.3-2.3 m/s, ship 0.2-0.55 m/s)
    "wind": {"X_wc": -8e-6, "Y_ws": -2e-5, "N_w2": -3e-6},
    # the rudder in the slipstream (the HSVA KVLCC2 fit of martin_simple: Y_Td -1.1, N_Td 0.45)
    "rudder_slipstream": {"Y_Td": -1.0, "N_Td": 0.45},
}
"""Terms (prime coefficients at ``magnitude`` 1) of the effects that are terms."""

VMM_CURRENT_SPEED = 0.1
"""Default current [m/s] of :func:`generate_vmm_runs` (8 % of the 7 m model's speed)."""

VMM_TRUE_WIND_SPEED = 3.0
"""True wind speed [m/s] of :func:`generate_vmm_runs` (its direction is drawn from the seed)."""

VMM_NOISE: dict[str, float] = {
    "psi": math.radians(0.1),
    "r": math.radians(0.05),
    "uv": 0.003,
    "xy": 0.01,
    "thrust": 0.5,
    "wind_speed": 0.1,
    "wind_angle": math.radians(2.0),
}
"""Standard deviations of the sensor noise of :func:`generate_vmm_runs`."""

#: The run programme: (kind, rudder angle [deg], switch heading [deg] or hold [s], side).
VMM_RUNS: tuple[tuple[str, float, float, float], ...] = (
    ("zigzag", 10.0, 10.0, 1.0),
    ("zigzag", 20.0, 20.0, -1.0),
    ("turning", 35.0, 60.0, 1.0),
    ("zigzag", 30.0, 5.0, -1.0),
    ("random", 25.0, 12.0, 1.0),
    ("zigzag", 20.0, 10.0, 1.0),
    ("turning", 25.0, 60.0, -1.0),
    ("random", 30.0, 8.0, -1.0),
)


def vmm_truth() -> Any:
    """The known ship of :func:`generate_vmm_runs`: the 7 m KVLCC2's particulars with a
    stable linear term set (hull derivatives of Yasukawa and Yoshimura 2015 in the seed's
    prime system, ``N_r`` raised to make it course-stable; rudder and thrust terms of the HSVA
    fits)."""
    from shipgym.sysid.families.vmm import kvlcc2_particulars

    template = kvlcc2_particulars()
    coefficients = {
        "X_u": -0.0011, "X_v": 0.0, "X_r": 0.0, "X_d": 0.0, "X_T": 0.78,
        "Y_u": 0.0, "Y_v": -0.0205, "Y_r": 0.0054, "Y_d": -0.0032,
        "N_u": 0.0, "N_v": -0.0089, "N_r": -0.008, "N_d": 0.0015,
    }  # fmt: skip
    return template.with_coefficients(coefficients, name="generated KVLCC2-like ship")


def generate_vmm_runs(
    effect: str | None = None,
    *,
    n_runs: int = 6,
    dt: float = 0.1,
    noise: bool = True,
    seed: int = 0,
    magnitude: float = 1.0,
) -> list[Record]:
    """Several runs of the known 3-DOF ship of :func:`vmm_truth` with at most one undeclared
    effect: zigzags, turning circles and random rudder, in the order of :data:`VMM_RUNS`.

    Each run starts at the approach speed on a straight course and is simulated through
    :func:`shipgym.models.make_model` ``("vmm", ...)`` with the manoeuvre as a controller. The
    propeller runs at constant revolutions: its thrust rises as the ship slows,
    ``T = T_0 (1.3 - 0.3 u / U_0)``, recorded in ``thrust``.

    Parameters
    ----------
    effect : {"current", "wind", "rudder_slipstream"} or None
        ``current``: a constant current of :data:`VMM_CURRENT_SPEED` x ``magnitude`` toward a
        direction drawn from the seed; ``wind``: a true wind of :data:`VMM_TRUE_WIND_SPEED` from
        a direction drawn from the seed, with the terms of :data:`VMM_EFFECT_TERMS` x
        ``magnitude`` (the records carry the apparent wind,
        :func:`shipgym.models.wind.apparent_wind`); ``rudder_slipstream``: its terms x
        ``magnitude``.
    n_runs : int
        Number of runs (1 .. 8).
    dt : float
        Sampling interval [s] (0.01 .. 0.5; the 7 m model's ``L / U`` is 5.9 s).
    noise : bool
        Add the sensor noise :data:`VMM_NOISE`.
    seed : int
        Seed (>= 0) of the current direction, the random rudder and the noise.
    magnitude : float
        Size of the effect relative to its default (> 0).

    Returns
    -------
    list of Record
        ``time, delta, psi, r, x, y, u, v, U, thrust`` (and ``wind_speed``, ``wind_angle``
        with ``effect="wind"``); ``meta["particulars"]`` holds the ship (no coefficients) so
        that identification can read it, ``meta["truth"]`` the true model and effect, for
        tests only.

    Raises
    ------
    ValueError
        For an unknown effect, or an ``n_runs``, ``dt``, ``seed`` or ``magnitude`` out of range.
    """
    _check_runs_arguments(effect, VMM_EFFECTS, n_runs, len(VMM_RUNS), dt, seed, magnitude)
    rng_cur, rng_man, rng_noise = (
        np.random.default_rng(s) for s in np.random.SeedSequence(int(seed)).spawn(3)
    )
    truth = vmm_truth()
    coefficients = dict(truth.coefficients)
    current = np.zeros(2)
    effect_params: dict[str, Any] = {}
    if effect == "current":
        current, effect_params = _draw_current(rng_cur, VMM_CURRENT_SPEED * magnitude)
    elif effect is not None:
        effect_params = {k: v * magnitude for k, v in VMM_EFFECT_TERMS[effect].items()}
        coefficients.update(effect_params)
    ship = truth.with_coefficients(coefficients)
    model = make_model("vmm", ship)
    u0 = ship.approach_speed
    thrust0 = truth.approach_thrust()
    wind_true = effect == "wind"
    w_speed = VMM_TRUE_WIND_SPEED
    w_from = float(rng_cur.uniform(0.0, 2.0 * math.pi)) if wind_true else 0.0
    if wind_true:
        effect_params["wind_from"] = w_from
    particulars = {k: v for k, v in truth.to_dict().items() if k != "coefficients"}
    h, every = _fine_step(dt)
    records = []
    for k, (kind, angle_deg, b, side) in enumerate(VMM_RUNS[:n_runs]):
        angle = math.radians(angle_deg)
        duration = 150.0 if kind != "turning" else 120.0
        n_fine = round(duration / h)
        levels = None
        if kind == "random":
            times = np.arange(0.0, duration + b, b)
            levels = (times, rng_man.uniform(-angle, angle, times.size))
        rudder = _RudderProgramme(kind, angle, b, side, duration, levels=levels)

        def apparent(x: np.ndarray) -> tuple[float, float]:
            if not wind_true:
                return 0.0, 0.0
            return apparent_wind(w_speed, w_from, x[2], x[3], x[4])

        def controller(t: float, x: np.ndarray, rudder: _RudderProgramme = rudder) -> np.ndarray:
            thrust = thrust0 * (1.3 - 0.3 * x[3] / u0)
            return np.array([rudder(t, x[2]), thrust, *apparent(x)])

        x0 = np.zeros(7)
        x0[3] = u0
        res = model.simulate(x0, controller, h, n_fine, current=current)
        sel = slice(None, None, every)
        st = res.states[sel]
        inp = np.vstack((res.inputs, res.inputs[-1:]))[sel]

        def noisy(a: np.ndarray, key: str) -> np.ndarray:
            return _noisy(rng_noise, noise, VMM_NOISE[key], a)

        u, v = noisy(st[:, 3], "uv"), noisy(st[:, 4], "uv")
        extra: dict[str, np.ndarray] = {}
        if wind_true:
            extra["wind_speed"] = np.abs(noisy(inp[:, 2], "wind_speed"))
            angle_noisy = noisy(inp[:, 3], "wind_angle")
            extra["wind_angle"] = wrap_angle(angle_noisy)
        records.append(
            Record(
                time=res.time[sel],
                delta=st[:, 6],
                psi=noisy(st[:, 2], "psi"),
                r=noisy(st[:, 5], "r"),
                x=noisy(st[:, 0], "xy"),
                y=noisy(st[:, 1], "xy"),
                u=u,
                v=v,
                U=np.hypot(u, v),
                thrust=noisy(inp[:, 1], "thrust"),
                **extra,
                meta={
                    "source": "generated",
                    "file": f"generated run {k + 1} ({kind} {angle_deg:g})",
                    "vessel": ship.name,
                    "L": ship.length,
                    "scale": "model",
                    "particulars": particulars,
                    "truth": {
                        "coefficients": coefficients,
                        "effect": effect,
                        "effect_parameters": effect_params,
                    },
                },
            )
        )
    return records


# --------------------------------------------------------------------------------------------
# 3-DOF model tests: runs of the MMG KVLCC2, whose rudder and propeller the VMM does not share


MMG_EFFECTS: tuple[str, ...] = ("rudder_offset", "rudder_lag", "input_delay", "current", "wind")
"""Undeclared effects of :func:`generate_mmg_runs`."""

MMG_EFFECT_RANGES: dict[str, tuple[float, float]] = {
    "rudder_offset": (math.radians(1.0), math.radians(2.0)),  # |delta_0| [rad]; sign drawn
    "rudder_lag": (1.0, 1.4),  # steering-gear time constant [s]
    "input_delay": (0.6, 1.0),  # tau [s]
    "current": (0.04, 0.08),  # current speed over the approach speed [-]
    "wind": (2.0, 3.0),  # true wind speed [m/s] (14 to 20 m/s at full scale)
}
"""Range of each effect's size at ``magnitude`` 1 (drawn uniformly from the seed, then
multiplied by ``magnitude``), in the unit given."""

#: The run programme: (kind, rudder angle [deg], switch heading [deg] or hold [s], side). The
#: two 20/20 zigzags are third and sixth, the runs ``identify``'s default hold-out (every
#: third run) keeps out.
MMG_RUNS: tuple[tuple[str, float, float, float], ...] = (
    ("zigzag", 10.0, 10.0, 1.0),
    ("turning", 35.0, 0.0, 1.0),
    ("zigzag", 20.0, 20.0, 1.0),
    ("zigzag", 10.0, 10.0, -1.0),
    ("turning", 35.0, 0.0, -1.0),
    ("zigzag", 20.0, 20.0, -1.0),
    ("zigzag", 15.0, 15.0, 1.0),
    ("zigzag", 25.0, 5.0, -1.0),
)

MMG_DURATION = (90.0, 120.0)
"""Range [s] of the length of each run (drawn per run)."""

MMG_APPROACH = (2.0, 5.0)
"""Range [s] of the straight approach before the rudder is put over (drawn per run)."""

MMG_SPEED_SPREAD = 0.03
"""Relative spread of each run's approach speed about the SIMMAN speed (drawn per run)."""

MMG_NOISE: dict[str, float] = {
    **{k: VMM_NOISE[k] for k in ("psi", "r", "uv", "xy", "wind_speed", "wind_angle")},
    "delta": math.radians(0.1),
    "rpm": 1.0,
}
"""Standard deviations of the sensor noise of :func:`generate_mmg_runs` (``rpm`` in rev/min,
the others as :data:`VMM_NOISE`; ``delta`` [rad])."""


def generate_mmg_runs(
    effect: str | None = None,
    *,
    n_runs: int = 6,
    dt: float = 0.1,
    noise: bool = True,
    seed: int = 0,
    magnitude: float = 1.0,
) -> list[Record]:
    """Tank runs of the KVLCC2 L7 model (7 m) simulated by the MMG standard model with at most
    one undeclared effect: zigzags and turning circles, in the order of :data:`MMG_RUNS`.

    The ship is :func:`shipgym.models.make_model` ``("kvlcc2")`` (:mod:`shipgym.models.mmg`:
    Yasukawa and Yoshimura 2015), whose hull, propeller and rudder forces are not the VMM
    polynomials. Each run starts in straight running at an approach speed within
    :data:`MMG_SPEED_SPREAD` of the SIMMAN speed (1.179 m/s) on a heading drawn from the seed,
    with the propeller at that speed's self-propulsion revolutions, held constant (recorded as
    ``rpm``; the thrust is not recorded), runs straight for :data:`MMG_APPROACH` s, then puts
    the rudder over; each run lasts :data:`MMG_DURATION` s. The zigzags switch on the true
    heading relative to the initial one.

    Effects (their size drawn once per call from :data:`MMG_EFFECT_RANGES`, times
    ``magnitude``):

    * ``rudder_offset``: the actual rudder is the recorded one plus ``delta_0`` (sign drawn
      too): the gear is ordered the programme's command plus ``delta_0``, and the record holds
      the gear's angle less ``delta_0``.
    * ``rudder_lag``: a slow steering gear, first-order with time constant ``T_delta``
      (``MMGParams.rudder_time_constant``; the model's own is 0.05 s, inside its 15.7 deg/s
      rate limit), and the record holds the COMMAND. Without it the record holds the actual
      rudder angle.
    * ``input_delay``: the recorded rudder leads the actual one by ``tau`` (rounded to the
      integration step): the gear is ordered the command ``tau`` late and the record holds
      the gear's angle ``tau`` ahead.
    * ``current``: a constant current toward a direction drawn from the seed, of the given
      fraction of the approach speed; the ship starts steady in the water.
    * ``wind``: a constant true wind from a direction drawn from the seed, with Blendermann's
      loads on the KVLCC2's estimated wind areas (``MMGParams.wind_speed``,
      :mod:`shipgym.models.wind`); the records carry the apparent wind at the ship,
      ``wind_speed`` and ``wind_angle`` (the direction it comes from, clockwise from the bow).

    Parameters
    ----------
    effect : {"rudder_offset", "rudder_lag", "input_delay", "current", "wind"} or None
        The undeclared effect (None: the clean ship).
    n_runs : int
        Number of runs (1 .. 8; the default 6 are two each of 10/10 and 20/20 zigzags and
        35 deg turns, to both sides).
    dt : float
        Sampling interval [s] (0.01 .. 0.5).
    noise : bool
        Add the sensor noise :data:`MMG_NOISE` to every channel (its draws come from their own
        random stream: ``noise=False`` gives the same motions).
    seed : int
        Seed (>= 0) of the effect's size and direction, the runs' headings, speeds, approach
        and lengths, and the noise.
    magnitude : float
        Size of the effect relative to its range (> 0).

    Returns
    -------
    list of Record
        ``time, delta, psi, r, x, y, u, v, U, rpm`` (and ``wind_speed``, ``wind_angle`` with
        ``effect="wind"``); ``x, y`` north and east of the start, ``u, v`` over ground. The meta
        states the ship's main particulars as plain keys (``L``, ``B``, ``draft``,
        ``displacement_m3``, ``x_G``, ``propeller_diameter`` [m, m^3], ``rho`` [kg/m^3]);
        ``meta["truth"]`` holds the true model, effect and its parameters, for tests only: an
        identifier must not read it.

    Raises
    ------
    ValueError
        For an unknown effect, or an ``n_runs``, ``dt``, ``seed`` or ``magnitude`` out of range.
    """
    _check_runs_arguments(effect, MMG_EFFECTS, n_runs, len(MMG_RUNS), dt, seed, magnitude)
    rng_effect, rng_programme, rng_noise = (
        np.random.default_rng(s) for s in np.random.SeedSequence(int(seed)).spawn(3)
    )
    base = MMGParams.kvlcc2()
    params = base
    current = np.zeros(2)
    effect_params: dict[str, Any] = {}
    offset = 0.0
    delay_steps = 0
    h, every = _fine_step(dt)
    if effect is not None:
        size = magnitude * float(rng_effect.uniform(*MMG_EFFECT_RANGES[effect]))
        if effect == "rudder_offset":
            offset = size * float(rng_effect.choice([-1.0, 1.0]))
            effect_params = {"delta_0": offset}
        elif effect == "rudder_lag":
            params = replace(base, rudder_time_constant=size)
            effect_params = {"T_delta": size}
        elif effect == "input_delay":
            delay_steps = max(1, round(size / h))
            effect_params = {"tau": delay_steps * h, "tau_requested": size}
        elif effect == "current":
            current, effect_params = _draw_current(rng_effect, size * KVLCC2_SIMMAN_SPEED)
        else:
            direction = float(rng_effect.uniform(0.0, 2.0 * math.pi))
            params = replace(base, wind_speed=size, wind_direction=direction)
            effect_params = {"speed": size, "direction": direction}
    model = make_model("kvlcc2", params)
    meta_ship = {
        "vessel": "KVLCC2 L7 model (MMG standard model, Yasukawa and Yoshimura 2015)",
        "L": base.length,
        "B": base.breadth,
        "draft": base.draught,
        "displacement_m3": base.displacement,
        "x_G": base.x_g,
        "propeller_diameter": base.propeller_diameter,
        "rho": base.rho,
    }
    records = []
    for k, (kind, angle_deg, b, side) in enumerate(MMG_RUNS[:n_runs]):
        duration = float(rng_programme.uniform(*MMG_DURATION))
        start = float(rng_programme.uniform(*MMG_APPROACH))
        psi0 = float(rng_programme.uniform(0.0, 2.0 * math.pi))
        speed = KVLCC2_SIMMAN_SPEED * (1.0 + float(rng_programme.uniform(-1.0, 1.0))
                                       * MMG_SPEED_SPREAD)  # fmt: skip
        rps = base.self_propulsion_rps(speed)  # the calm-water set-point of the tank
        n_samples = math.floor(duration / dt + 1e-9) + 1
        n_fine = (n_samples - 1) * every
        rudder = _RudderProgramme(kind, math.radians(angle_deg), b, side, math.inf, psi0, start)
        commands: list[float] = []

        def controller(
            t: float, x: np.ndarray, rudder: _RudderProgramme = rudder,
            commands: list[float] = commands, rps: float = rps,
        ) -> list[float]:  # fmt: skip
            commands.append(rudder(t, x[_mmg.IPSI]))
            j = len(commands) - 1 - delay_steps
            return [(commands[j] if j >= 0 else 0.0) + offset, rps]

        x0 = np.zeros(model.nx)
        x0[_mmg.IPSI] = psi0
        cs, sn = math.cos(psi0), math.sin(psi0)
        x0[_mmg.IU] = speed + current[0] * cs + current[1] * sn  # steady in the water
        x0[_mmg.IV] = -current[0] * sn + current[1] * cs
        x0[_mmg.IDELTA] = offset
        res = model.simulate(x0, controller, h, n_fine + delay_steps + 1, current=current)
        idx = np.arange(n_samples) * every
        st = res.states[idx]
        if effect == "rudder_lag":
            delta = np.asarray(commands)[idx]
        else:
            delta = res.states[idx + delay_steps, _mmg.IDELTA] - offset

        def noisy(a: np.ndarray, key: str) -> np.ndarray:
            return _noisy(rng_noise, noise, MMG_NOISE[key], a)

        u, v = noisy(st[:, _mmg.IU], "uv"), noisy(st[:, _mmg.IV], "uv")
        extra: dict[str, np.ndarray] = {}
        if effect == "wind":
            apparent = np.array([
                apparent_wind(params.wind_speed, params.wind_direction, s[_mmg.IPSI], s[_mmg.IU],
                              s[_mmg.IV])
                for s in st
            ])  # fmt: skip
            extra["wind_speed"] = np.abs(noisy(apparent[:, 0], "wind_speed"))
            extra["wind_angle"] = wrap_angle(noisy(apparent[:, 1], "wind_angle"))
        label = f"{kind} {angle_deg:g}" + (f"/{b:g}" if kind == "zigzag" else "")
        records.append(
            Record(
                time=idx * h,
                delta=noisy(delta, "delta"),
                psi=noisy(st[:, _mmg.IPSI], "psi"),
                r=noisy(st[:, _mmg.IR], "r"),
                x=noisy(st[:, _mmg.IX], "xy"),
                y=noisy(st[:, _mmg.IY], "xy"),
                u=u,
                v=v,
                U=np.hypot(u, v),
                rpm=noisy(np.full(n_samples, 60.0 * rps), "rpm"),
                **extra,
                meta={
                    "source": "generated",
                    "file": f"MMG run {k + 1} ({label} {'starboard' if side > 0 else 'port'})",
                    **meta_ship,
                    "scale": "model",
                    "frame": "x north, y east [m] from the start position",
                    "r_source": "measured",
                    "maneuver": kind,
                    "dt": dt,
                    "seed": int(seed),
                    "noise": dict(MMG_NOISE) if noise else None,
                    "notes": [
                        "synthetic record; meta['truth'] is the ground truth for tests only and "
                        "must not be read by an identifier"
                    ],
                    "truth": {
                        "model": "kvlcc2",
                        "params": asdict(params),
                        "current": current.tolist(),
                        "effect": effect,
                        "effect_parameters": effect_params,
                        "magnitude": magnitude,
                        "x0": x0.tolist(),
                        "rps": rps,
                        "approach_s": start,
                        "fine_step": h,
                    },
                },
            )
        )
    return records

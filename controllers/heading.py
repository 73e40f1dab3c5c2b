r"""PID heading autopilot with a third-order reference model (seed 004 eq. 6-7, Fossen 2011).

Plant used for the design: the first-order Nomoto model with the heading as output,

.. math:: \frac{\psi}{\delta}(s) = \frac{K}{s (1 + T s)}
          \quad\Leftrightarrow\quad T \dot r + r = K \delta, \; \dot\psi = r,

where ``delta`` is the steering command: the rudder angle of a conventional ship (``K > 0``:
positive rudder turns to starboard) or the common azimuth of the aft pods of R/V Gunnerus
(whose high-frequency gain ``K / T`` is negative: positive azimuth turns to port). ``T < 0``
describes a directionally unstable ship.

Control law (seed 004 eq. 7 with the reference model's yaw rate fed forward)::

    e       = ssa(psi_d - psi)                                  heading error [rad]
    delta_c = Kp e + Ki integral(e dt) - Kd (r - r_d) + b0 [+ (T a_d + r_d) / K]

(seed 004 prints its eq. 7 with ``- Ki integral``: with the heading error ``e`` defined as here
that integral pushes the ship away from the setpoint and the loop is unstable; ``+ Ki`` is
right, a sign slip of the report's printing, not of its design), followed by the actuator
limits ``|delta_c| <= max_command`` and
``|d delta_c / dt| <= max_rate``. ``b0`` is a constant rudder offset (seed 004 eq. 7); the
integrator removes any remaining constant offset (a current, a bias ``n0``). The bracketed
Nomoto feed-forward is optional. Anti-windup (``anti_windup``): the integrator is frozen while
the command is limited (by angle or rate) and the error would drive it further into the limit
(conditional integration), and by default it is also driven back by the excess
``u - u_lim`` with the tracking time ``T_t = sqrt(T_i T_d)`` (back-calculation, Åström).
The command is in the units of the plant input: rad for a rudder or an azimuth, N m for a
yaw-moment command that a thrust allocation turns into pod angles.

Pole placement (Fossen 2011, *Handbook of Marine Craft Hydrodynamics and Motion Control*, the
PID pole-placement algorithm for the Nomoto heading model, "Fossen's method"): with the PID
above the
closed loop of the Nomoto plant has the characteristic polynomial

.. math:: T s^3 + (1 + K K_d) s^2 + K K_p s + K K_i = 0 .

``method="exact"`` (default) makes it equal to ``T (s^2 + 2 zeta w_n s + w_n^2)(s + w_n/10)``:

.. math:: K_p = \frac{T (w_n^2 + 2 \zeta w_n p)}{K}, \quad
          K_d = \frac{T (2 \zeta w_n + p) - 1}{K}, \quad
          K_i = \frac{T w_n^2 p}{K}, \qquad p = w_n / 10,

so the closed-loop poles are exactly ``-zeta w_n +- j w_n sqrt(1 - zeta^2)`` and ``-w_n/10``.
``method="fossen"`` uses the textbook formulas ``K_p = w_n^2 T / K``,
``K_d = (2 zeta w_n T - 1) / K``, ``K_i = w_n^3 T / (10 K)`` (the PD design with a slow
integrator added: the dominant poles then move slightly). Both hold for any signs of ``K`` and
``T``; :meth:`HeadingAutopilot.design_report` checks the resulting loop with python-control.

Margins with a rudder transport delay ``tau`` (:func:`loop_margins`): ``|e^{-j w tau}| = 1``, so
the gain crossover ``w_c`` of ``L = C P`` stays where it is and the phase margin drops by
``w_c tau``, ``PM_tau = PM_0 - w_c tau``; the delay margin is ``PM_tau / w_c`` (Åström and
Murray, *Feedback Systems*, the phase margin and time delays). The phase crossovers move and
are searched on the exact frequency response.

Reference model (Fossen 2011, reference models for trajectory generation): a first-order
low-pass in cascade with a
mass-spring-damper,

.. math:: \psi_d^{(3)} + (2\zeta_r + 1) w_r \ddot\psi_d + (2\zeta_r + 1) w_r^2 \dot\psi_d
          + w_r^3 \psi_d = w_r^3 \psi_{ref},

integrated as ``psi_f' = w_r (psi_ref - psi_f)``, ``a_d = w_r^2 (psi_f - psi_d) - 2 zeta_r
w_r r_d`` (saturated to ``max_turn_accel``), ``r_d' = a_d`` (saturated to ``max_turn_rate``),
``psi_d' = r_d``, with Heun (second-order Runge-Kutta) substeps of at most ``0.02 / w_r``
seconds (the low-pass stage exactly). The yaw-rate limit ``max_turn_rate`` keeps a
directionally unstable ship (R/V Gunnerus) from being asked for a turn rate it cannot check.
Angles are unwrapped inside: a new setpoint is reached the short way (relative to the
previous setpoint).

Batches: :class:`HeadingAutopilot` and :class:`HeadingReferenceModel` run a batch of ships
with the same gains and limits. Their states are arrays ``(n,)``, one entry per ship, and one
ship is a batch of one of the same code: reset with numbers, they take numbers and return
floats; reset with arrays ``(n,)``, they take and return arrays. Every operation is
elementwise in the order of the scalar law above, so each ship of a batch gets, bit for bit,
the numbers it gets alone.

R/V Gunnerus (shipgym ``rvg3dof`` at 5.14 m/s, azimuth of both pods as the command): the
linearised sway-yaw model has an unstable pole at +0.18 1/s and an initial yaw acceleration
of -0.0137 rad/s^2 per rad of azimuth, i.e. ``T = -5.57 s`` and ``K = 0.076 1/s``
(``K / T < 0``: positive azimuth turns to port). Settings that hold 30 to 150 deg steps
without overshoot in the nonlinear model: ``omega_n = 0.3``, ``reference_omega = 0.05``,
``max_turn_rate = 0.02``, ``max_command = 35 deg``, ``max_rate = 10 deg/s``; a faster
reference model lets the ship swing past 0.04 rad/s, a turn that full opposite azimuth
checks only after tens of degrees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike

from controllers._angles import (
    BatchValue,
    StepClock,
    anti_windup_mode,
    batch_size,
    batch_value,
    bounds,
    clip,
    constant,
    finite,
    finite_batch,
    integrate_with_anti_windup,
    nonnegative,
    optional_limit,
    positive,
    rate_limit,
    ssa_array,
    tracking_time,
    unwrap_towards,
)

if TYPE_CHECKING:  # python-control is imported where a design is checked: 1 s of import
    import control

__all__ = [
    "HeadingAutopilot",
    "HeadingDesignReport",
    "HeadingReferenceModel",
    "LoopMargins",
    "default_bandwidth",
    "design_model",
    "loop_margins",
    "pid_gains_nomoto",
]

#: Longest reference-model substep as a fraction of ``1 / w_r`` (Heun's method: within 1e-4 of
#: the exact step response; finer substeps cost time in every control step for nothing).
_REF_SUBSTEP = 0.1


def pid_gains_nomoto(
    K: float,
    T: float,
    omega_n: float,
    zeta: float = 0.8,
    *,
    method: Literal["exact", "fossen"] = "exact",
    integral_ratio: float = 0.1,
) -> tuple[float, float, float]:
    """PID gains ``(Kp, Ki, Kd)`` by pole placement on the Nomoto model ``K / (s (1 + T s))``.

    Parameters
    ----------
    K : float
        Nomoto gain [1/s] (non-zero, either sign).
    T : float
        Nomoto time constant [s] (non-zero; negative for a directionally unstable ship).
    omega_n : float
        Natural frequency [rad/s] of the dominant closed-loop poles.
    zeta : float
        Relative damping of the dominant poles (> 0).
    method : {"exact", "fossen"}
        ``"exact"`` places the poles exactly at ``-zeta w_n +- j w_n sqrt(1 - zeta^2)`` and
        ``-integral_ratio w_n``; ``"fossen"`` uses Fossen's formulas (module docstring).
    integral_ratio : float
        The integrator pole (exact) or ``Ki / (w_n Kp)`` (fossen), 0.1 by default; 0 gives a PD.

    Returns
    -------
    tuple of float
        ``(Kp, Ki, Kd)`` in [command/rad, command/(rad s), command s/rad].

    Raises
    ------
    ValueError
        For ``K`` or ``T`` zero or not finite, ``omega_n`` or ``zeta`` not > 0, or an
        unknown method.
    """
    K = finite("K", K)
    T = finite("T", T)
    if K == 0:
        raise ValueError("Nomoto gain K must be non-zero, got 0")
    if T == 0:
        raise ValueError("Nomoto time constant T must be non-zero, got 0")
    wn = positive("omega_n", omega_n)
    zeta = positive("zeta", zeta)
    ratio = nonnegative("integral_ratio", integral_ratio)
    if method == "exact":
        p = ratio * wn
        kp = T * (wn * wn + 2.0 * zeta * wn * p) / K
        kd = (T * (2.0 * zeta * wn + p) - 1.0) / K
        ki = T * wn * wn * p / K
    elif method == "fossen":
        kp = wn * wn * T / K
        kd = (2.0 * zeta * wn * T - 1.0) / K
        ki = ratio * wn * kp
    else:
        raise ValueError(f"method must be 'exact' or 'fossen', got {method!r}")
    return kp, ki, kd


def default_bandwidth(
    T: float,
    *,
    actuator_time_constant: float | None = None,
    max_command: float | None = None,
    max_rate: float | None = None,
) -> float:
    """Default natural frequency ``w_n`` [rad/s] for :meth:`HeadingAutopilot.from_nomoto`.

    Fossen's rule for the bandwidth is ``1 / |T| < w_b < 1 / T_a``: faster than the ship's
    yaw time constant, slower than the actuator. The actuator time ``T_a`` is the larger of
    its time constant and its full-scale slew time ``max_command / max_rate`` (a large
    heading change is limited by how fast the rudder can swing, not by the servo's time
    constant). The default is the geometric mean ``w_n = sqrt(1 / (|T| T_a))``, the middle
    of that band on a logarithmic scale; without actuator data ``T_a = |T| / 100``. For a
    directionally unstable ship (``T < 0``) the loop must outrun the divergence rate
    ``1 / |T|``, so ``w_n`` is at least ``2 / |T|``.

    Examples: the Mariner (``T = 107.3 s``, 2 s servo, 35 deg at 2.32 deg/s, so
    ``T_a = 15.1 s``) gets ``w_n = 0.025 rad/s``.
    """
    T = finite("T", T)
    if T == 0:
        raise ValueError("Nomoto time constant T must be non-zero, got 0")
    ta = 0.0
    if actuator_time_constant is not None:
        ta = nonnegative("actuator_time_constant", actuator_time_constant)
    umax = optional_limit("max_command", max_command)
    rmax = optional_limit("max_rate", max_rate)
    if math.isfinite(umax) and math.isfinite(rmax):
        ta = max(ta, umax / rmax)
    if ta == 0.0:
        ta = abs(T) / 100.0
    wn = math.sqrt(1.0 / (abs(T) * ta))
    if T < 0:
        wn = max(wn, 2.0 / abs(T))
    return wn


def design_model(
    K: float,
    T1: float,
    T2: float = 0.0,
    T3: float = 0.0,
    *,
    n1: float = 1.0,
    omega: float | None = None,
    **bandwidth: float | None,
) -> tuple[float, float, float]:
    """First-order Nomoto ``(K_e, T_e)`` to design a heading autopilot for any linear Nomoto
    ship, and the design bandwidth ``w`` [rad/s].

    The ship's yaw-rate response to the rudder, linearised about straight running, is

    .. math:: \\frac{r}{\\delta}(s) = \\frac{K (1 + T_3 s)}{T_1 T_2 s^2 + (T_1 + T_2) s + n_1}

    (first-order Nomoto: ``T2 = T3 = 0``; Norrbin's ``T r' + n_1 r + ... = K delta`` with ``T1 =
    T``, which for ``n_1 < 0`` is a directionally unstable ship; second-order Nomoto and Bech
    with ``n_1 = 1`` and ``n_1 = K b_1``). A first-order model ``K_e / (1 + T_e s)`` that
    matches it **at the design bandwidth** is found from the complex response there:
    ``1 / H(jw) = (1 + j w T_e) / K_e``, so ``K_e = 1 / Re(1/H)`` and
    ``T_e = Im(1/H) / (w Re(1/H))``; ``w`` is :func:`default_bandwidth` of ``T_e`` and the
    actuator data in ``bandwidth`` (``actuator_time_constant``, ``max_command``, ``max_rate``)
    unless given, found by a fixed-point iteration. For the first-order ship the match is exact
    (``K / n_1``, ``T / n_1``) at every frequency.

    The classic reduction ``T = T_1 + T_2 - T_3`` matches the low-frequency expansion only, and
    fails where the zero is slow: seed 004's ship (eq. 6: ``K`` 0.03, ``T_1`` 130 s, ``T_2`` 150
    s, ``T_3`` 320 s) gets ``T = -40 s``, a stable ship designed as an unstable one, and that
    pole-placement design destabilises the real plant. With the Mariner's steering gear, at its
    bandwidth (0.028 rad/s) the ship behaves as ``K_e`` 0.044 1/s, ``T_e`` 87 s.

    Returns
    -------
    tuple of float
        ``(K_e, T_e, w)``.
    """
    K = finite("K", K)
    T1 = finite("T1", T1)
    T2 = nonnegative("T2", T2)
    T3 = finite("T3", T3)
    n1 = finite("n1", n1)
    if K == 0 or T1 == 0 or n1 == 0:
        raise ValueError(f"K, T1 and n1 must be non-zero, got K={K}, T1={T1}, n1={n1}")
    if T2 == 0.0 and T3 == 0.0:
        K_e, T_e = K / n1, T1 / n1
        w = omega if omega is not None else default_bandwidth(T_e, **bandwidth)
        return K_e, T_e, float(w)

    def at(w: float) -> tuple[float, float]:
        s = 1j * w
        inv = (T1 * T2 * s * s + (T1 + T2) * s + n1) / (K * (1.0 + T3 * s))
        return 1.0 / inv.real, inv.imag / (w * inv.real)

    T_e = T1 + T2 - T3 if T1 + T2 - T3 != 0 else T1
    w = omega if omega is not None else default_bandwidth(T_e, **bandwidth)
    for _ in range(50 if omega is None else 1):
        K_e, T_e = at(w)
        if omega is not None:
            break
        w_new = default_bandwidth(T_e, **bandwidth)
        if abs(w_new - w) <= 1e-9 * w:
            break
        w = w_new
    return float(K_e), float(T_e), float(w)


@dataclass(frozen=True)
class LoopMargins:
    """Stability margins of an open loop ``L(s) e^{-s tau}`` (see :func:`loop_margins`).

    Attributes
    ----------
    gain_margin_db : float
        Gain margin [dB] at the phase crossover closest to instability (``inf`` when the
        phase never crosses -180 deg; negative: a *lower* gain margin, as for an open-loop
        unstable plant).
    phase_margin_deg : float
        Phase margin [deg] with the delay, the smallest over the gain crossovers (``inf``
        when ``|L|`` never crosses 1).
    gain_crossover : float
        Frequency [rad/s] of that phase margin (``nan`` if none).
    phase_crossover : float
        Frequency [rad/s] of that gain margin (``nan`` if none).
    delay_margin : float
        Further input delay [s], on top of ``delay``, that brings a phase margin to zero:
        the least ``PM_i / w_i`` over the gain crossovers (0 when a phase margin is
        already negative, ``inf`` without a crossover).
    delay : float
        The input delay ``tau`` [s] in the loop.
    """

    gain_margin_db: float
    phase_margin_deg: float
    gain_crossover: float
    phase_crossover: float
    delay_margin: float
    delay: float

    def to_dict(self) -> dict[str, float | None]:
        """JSON-ready values (non-finite numbers as ``None``)."""
        return {
            key: (value if math.isfinite(value) else None)
            for key, value in (
                ("gain_margin_db", self.gain_margin_db),
                ("phase_margin_deg", self.phase_margin_deg),
                ("gain_crossover_rad_s", self.gain_crossover),
                ("phase_crossover_rad_s", self.phase_crossover),
                ("delay_margin_s", self.delay_margin),
                ("delay_s", self.delay),
            )
        }


def _phase_crossovers(loop: control.TransferFunction, tau: float) -> np.ndarray:
    """Every frequency [rad/s] where the phase of ``L(jw) e^{-jw tau}`` is -180 deg (mod
    360), on a grid spanning the loop's poles and zeros, refined by Brent's method."""
    import control
    from scipy.optimize import brentq

    corners = np.abs(np.concatenate([control.poles(loop), control.zeros(loop)]))
    corners = corners[corners > 0]
    lo = 1e-3 * (corners.min() if corners.size else 1.0)
    hi = 1e3 * (corners.max() if corners.size else 1.0)
    hi = max(hi, 20.0 * math.pi / tau) if tau > 0 else hi
    w = np.logspace(math.log10(lo), math.log10(hi), 8000)
    phase = np.unwrap(np.angle(loop(1j * w))) - w * tau
    turns = np.floor((phase + math.pi) / (2.0 * math.pi))
    found = []
    for i in np.nonzero(np.diff(turns) != 0)[0]:
        target = (max(turns[i], turns[i + 1])) * 2.0 * math.pi - math.pi
        p0, p1, w0, w1 = phase[i], phase[i + 1], w[i], w[i + 1]

        def excess(x: float, p0: float = p0, p1: float = p1, w0: float = w0, w1: float = w1,
                   target: float = target) -> float:  # fmt: skip
            guess = p0 + (p1 - p0) * (x - w0) / (w1 - w0)
            raw = float(np.angle(loop(1j * x))) - x * tau
            return raw + 2.0 * math.pi * round((guess - raw) / (2.0 * math.pi)) - target

        try:
            found.append(brentq(excess, w0, w1, xtol=1e-12 * w1))
        except ValueError:  # a jump of the wrapped phase, not a crossing
            continue
    return np.array(found)


def loop_margins(loop: control.TransferFunction, delay: float = 0.0) -> LoopMargins:
    """Gain, phase and delay margins of ``L(s) e^{-s tau}``, the delay taken exactly.

    A pure delay has ``|e^{-j w tau}| = 1`` and phase ``-w tau``, so the gain crossovers
    ``|L(j w_c)| = 1`` are those of ``L`` (python-control's :func:`control.stability_margins`)
    and each phase margin is that of ``L`` less ``w_c tau``:

    .. math:: PM_\\tau = PM_0 - \\omega_c \\tau, \\qquad
              \\tau_{margin} = PM_\\tau / \\omega_c \\;[\\mathrm{rad} / (\\mathrm{rad/s})].

    The phase crossovers move with the delay: without one they are python-control's; with
    one, the frequencies where ``arg L(j w) - w tau = -180 deg (mod 360)`` are searched on a
    logarithmic grid and refined (:func:`scipy.optimize.brentq`); the gain margin is
    ``1 / |L|`` there, the crossover closest to 0 dB.

    Parameters
    ----------
    loop : control.TransferFunction
        The delay-free open loop ``L = C P`` (SISO).
    delay : float
        Input delay ``tau`` [s] >= 0.

    Returns
    -------
    LoopMargins

    Raises
    ------
    ValueError
        For a loop that is not a SISO transfer function or a delay that is not a finite
        number >= 0.
    """
    import control

    if not isinstance(loop, control.TransferFunction) or loop.ninputs != 1 or loop.noutputs != 1:
        raise ValueError(f"loop must be a SISO control.TransferFunction, got {loop!r}")
    tau = nonnegative("delay", delay)
    gm, _pm, _sm, wpc, wgc, _wms = control.stability_margins(loop, returnall=True)
    wgc = np.asarray(wgc, dtype=float)
    if wgc.size:
        lag = np.angle(loop(1j * wgc)) - wgc * tau  # rad
        margins = np.mod(lag + 2.0 * math.pi, 2.0 * math.pi) - math.pi  # 180 + phase, wrapped
        i = int(np.argmin(margins))
        pm = math.degrees(float(margins[i]))
        w_c = float(wgc[i])
        delay_margin = float(np.min(np.maximum(margins, 0.0) / wgc))
    else:
        pm, w_c, delay_margin = math.inf, math.nan, math.inf
    if tau > 0:
        wpc = _phase_crossovers(loop, tau)
        ratio = 1.0 / np.abs(loop(1j * wpc)) if wpc.size else np.empty(0)
    else:
        wpc, ratio = np.asarray(wpc, dtype=float), np.asarray(gm, dtype=float)
    keep = np.isfinite(ratio) & (ratio > 0)
    if np.any(keep):
        db = 20.0 * np.log10(ratio[keep])
        j = int(np.argmin(np.abs(db)))
        gm_db, w_pc = float(db[j]), float(wpc[keep][j])
    else:
        gm_db, w_pc = math.inf, math.nan
    return LoopMargins(gm_db, pm, w_c, w_pc, delay_margin, tau)


@dataclass(frozen=True, eq=False)
class HeadingDesignReport:
    """Closed-loop check of a heading autopilot design (python-control).

    Attributes
    ----------
    kp, ki, kd : float
        PID gains.
    omega_n, zeta : float or None
        Requested natural frequency [rad/s] and damping (``None`` for hand-set gains).
    design_poles : numpy.ndarray
        The poles that the pole placement asked for: the dominant pair and the integrator
        pole (empty for hand-set gains).
    closed_loop_poles : numpy.ndarray
        Poles of ``L / (1 + L)`` with the plant used (sorted by real part, slowest first).
    stable : bool
        All closed-loop poles in the open left half plane.
    gain_margin : float
        Gain margin (ratio; ``inf`` when the phase never crosses -180 deg). For an
        open-loop unstable plant a ratio below 1 is a *lower* gain margin.
    phase_margin_deg : float
        Phase margin [deg].
    gain_crossover : float
        Frequency [rad/s] where ``|L| = 1`` (``nan`` if none).
    phase_crossover : float
        Frequency [rad/s] where the phase of ``L`` is -180 deg (``nan`` if none).
    plant, controller, loop : control.TransferFunction
        ``psi / delta_c``, ``C(s) = Kp + Ki / s + Kd s`` and ``L = C P``.
    """

    kp: float
    ki: float
    kd: float
    omega_n: float | None
    zeta: float | None
    design_poles: np.ndarray
    closed_loop_poles: np.ndarray
    stable: bool
    gain_margin: float
    phase_margin_deg: float
    gain_crossover: float
    phase_crossover: float
    plant: control.TransferFunction
    controller: control.TransferFunction
    loop: control.TransferFunction


class HeadingReferenceModel:
    """Third-order heading reference model with rate and acceleration limits, for one ship or
    a batch of ships.

    Parameters
    ----------
    omega : float
        Reference-model natural frequency ``w_r`` [rad/s].
    zeta : float
        Reference-model damping ``zeta_r`` (1 is critically damped, no overshoot).
    max_turn_rate : float, optional
        Limit on ``|r_d|`` [rad/s]; none by default.
    max_turn_accel : float, optional
        Limit on ``|a_d|`` [rad/s^2]; none by default.

    Attributes
    ----------
    psi_d, r_d, a_d : float or numpy.ndarray
        Desired heading [rad, unwrapped], yaw rate [rad/s] and yaw acceleration [rad/s^2]:
        floats for one ship (reset with numbers), arrays ``(n,)`` for a batch.
    psi_f : float or numpy.ndarray
        The low-pass-filtered setpoint [rad, unwrapped].
    psi_ref : float or numpy.ndarray
        The last setpoint [rad], unwrapped next to the one before.
    batch_size : int or None
        Ships in the batch; ``None`` for one ship (scalar mode).
    """

    psi_d = BatchValue("Desired heading [rad, unwrapped].")
    r_d = BatchValue("Desired yaw rate [rad/s].")
    a_d = BatchValue("Desired yaw acceleration [rad/s^2].")
    psi_f = BatchValue("Low-pass-filtered setpoint [rad, unwrapped].")
    psi_ref = BatchValue("Last setpoint [rad, unwrapped next to the one before].")

    def __init__(
        self,
        omega: float,
        zeta: float = 1.0,
        *,
        max_turn_rate: float | None = None,
        max_turn_accel: float | None = None,
    ) -> None:
        self.omega = positive("reference omega", omega)
        self.zeta = positive("reference zeta", zeta)
        self.max_turn_rate = optional_limit("max_turn_rate", max_turn_rate)
        self.max_turn_accel = optional_limit("max_turn_accel", max_turn_accel)
        self.reset(0.0)

    def reset(self, psi: ArrayLike, r: ArrayLike = 0.0) -> None:
        """Start at heading ``psi`` [rad] turning at ``r`` [rad/s] (clipped to the rate limit).

        Numbers start one ship (scalar mode); arrays of shape ``(n,)`` a batch of ``n`` ships
        (a number for ``r`` is then every ship's).
        """
        n = batch_size(psi=psi, r=r)
        self._start(finite_batch("psi", psi, n), finite_batch("r", r, n), n)

    def _start(self, psi: np.ndarray, r: np.ndarray, n: int | None) -> None:
        """:meth:`reset` with checked ``(n,)`` arrays (``(1,)`` and ``n = None``: one ship)."""
        self.batch_size = n
        self._psi_d = self._psi_f = self._psi_ref = psi
        self._r_d = clip(r, *bounds(-self.max_turn_rate, self.max_turn_rate))
        self._a_d = np.zeros(psi.shape)

    def update(
        self, psi_ref: ArrayLike, h: float
    ) -> tuple[float | np.ndarray, float | np.ndarray, float | np.ndarray]:
        """Advance ``h`` seconds towards ``psi_ref`` [rad]; return ``(psi_d, r_d, a_d)``.

        ``psi_ref`` is unwrapped next to the previous setpoint, so the model turns the short
        way; ``psi_d`` is returned unwrapped (wrap it with ``ssa`` for display). For a batch,
        ``psi_ref`` is an array ``(n,)`` or one setpoint for all, and the results are arrays.
        """
        ref = finite_batch("psi_ref", psi_ref, self.batch_size)
        psi_d, r_d, a_d = self._advance(ref, nonnegative("h", h))
        n = self.batch_size
        return batch_value(psi_d, n), batch_value(r_d, n), batch_value(a_d, n)

    def _advance(self, psi_ref: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`update` with a checked setpoint array; returns the new state arrays."""
        self._psi_ref = ref = unwrap_towards(self._psi_ref, psi_ref)
        w, z = self.omega, self.zeta
        rmax, amax = self.max_turn_rate, self.max_turn_accel
        n = max(1, math.ceil(h * w / _REF_SUBSTEP))
        hs = h / n
        # the numbers of the law as 0-d arrays (faster with small batches, the same values)
        decay, half_step = constant(math.exp(-w * hs)), constant(0.5 * hs)
        w2, c, hs = constant(w * w), constant(2.0 * z * w), constant(hs)
        rate, accel = bounds(-rmax, rmax), bounds(-amax, amax)
        psi_d, r_d, psi_f = self._psi_d, self._r_d, self._psi_f
        for _ in range(n):  # Heun's method (2nd order); psi_f is integrated exactly
            a1 = clip(w2 * (psi_f - psi_d) - c * r_d, *accel)
            psi_f = ref + (psi_f - ref) * decay
            r_p = clip(r_d + hs * a1, *rate)
            a2 = clip(w2 * (psi_f - psi_d - hs * r_d) - c * r_p, *accel)
            psi_d = psi_d + half_step * (r_d + r_p)
            r_d = clip(r_d + half_step * (a1 + a2), *rate)
        a = clip(w2 * (psi_f - psi_d) - c * r_d, *accel)
        if rate[1] is not None:  # held at the rate limit
            np.copyto(a, 0.0, where=(np.abs(r_d) >= rate[1]) & (a * r_d > 0.0))
        self._psi_d, self._r_d, self._psi_f, self._a_d = psi_d, r_d, psi_f, a
        return psi_d, r_d, a

    def transfer_function(self) -> control.TransferFunction:
        """``psi_d / psi_ref = w^3 / (s^3 + (2 zeta + 1) w s^2 + (2 zeta + 1) w^2 s + w^3)``."""
        import control

        w, z = self.omega, self.zeta
        return control.tf([w**3], [1.0, (2 * z + 1) * w, (2 * z + 1) * w * w, w**3])


class HeadingAutopilot:
    """PID heading autopilot tracking a reference model (module docstring for the equations),
    for one ship or a batch of ships with the same gains and limits.

    Parameters
    ----------
    kp, ki, kd : float
        PID gains [command/rad, command/(rad s), command s/rad]. Their signs follow the
        plant: all negative for a positive-azimuth-turns-to-port vessel with ``T > 0``.
    dt : float
        Nominal sample time [s] (used when :meth:`update` gets ``t=None``).
    reference_omega : float, optional
        Reference-model frequency ``w_r`` [rad/s]; ``None`` disables the reference model
        (``psi_d = psi_ref``, ``r_d = 0``).
    reference_zeta : float
        Reference-model damping (1).
    max_turn_rate, max_turn_accel : float, optional
        Limits [rad/s, rad/s^2] of the reference model's ``r_d`` and ``a_d``.
    max_command : float, optional
        Command limit (e.g. 35 deg of rudder, in rad); none by default.
    max_rate : float, optional
        Command rate limit [command unit/s]; none by default.
    offset : float
        Constant command offset ``b0`` (seed 004 eq. 7).
    anti_windup : {"conditional", "back_calculation", "none"} or bool
        ``"back_calculation"`` (default, or ``True``): the integrator is frozen while the
        command is limited and the error pushes it further into the limit, and it is driven
        back by the excess,
        ``integral' = e + (u_lim - u) / (ki T_t)`` with ``T_t = sqrt(T_i T_d)``
        (``T_i = kp / ki``, ``T_d = kd / kp``). ``"conditional"``: only frozen (conditional
        integration). ``"none"`` (or ``False``) integrates always (for comparison).
    nomoto : tuple of float, optional
        ``(K, T)`` of the plant: needed for :meth:`design_report` without a plant and for
        the Nomoto feed-forward.
    nomoto_feedforward : bool
        Add ``(T a_d + r_d) / K`` to the command (needs ``nomoto``).
    omega_n, zeta : float, optional
        The design values (recorded for :meth:`design_report`).

    Attributes
    ----------
    psi_d, r_d, a_d : float or numpy.ndarray
        Last reference heading [rad, wrapped to [-pi, pi)], yaw rate, acceleration.
    error : float or numpy.ndarray
        Last heading error ``ssa(psi_d - psi)`` [rad].
    integral : float or numpy.ndarray
        Heading-error integral [rad s]; the integral term is ``ki * integral``.
    command : float or numpy.ndarray
        Last command (rad, or the plant's input unit) after the limits (``nan`` before the
        first command when :meth:`reset` got none).
    unsaturated_command : float or numpy.ndarray
        Last command before the limits.
    offset : float or numpy.ndarray
        The command offset ``b0``; one per ship after ``reset(..., keep_offset=True)`` of a
        batch.
    batch_size : int or None
        Ships in the batch; ``None`` for one ship (scalar mode).

    Notes
    -----
    The states are arrays of shape ``(n,)``, one entry per ship; one ship is a batch of one
    of the same code. :meth:`reset` with numbers (scalar mode) makes the states read as floats
    and :meth:`update` take numbers and return a float; :meth:`reset` with arrays of shape
    ``(n,)`` makes them read as arrays and :meth:`update` take and return arrays. Each ship of
    a batch gets exactly the numbers it would get alone.
    """

    psi_d = BatchValue("Last reference heading [rad, wrapped to [-pi, pi)].")
    r_d = BatchValue("Last reference yaw rate [rad/s].")
    a_d = BatchValue("Last reference yaw acceleration [rad/s^2].")
    error = BatchValue("Last heading error ``ssa(psi_d - psi)`` [rad].")
    integral = BatchValue("Heading-error integral [rad s].")
    command = BatchValue("Last command after the limits.")
    unsaturated_command = BatchValue("Last command before the limits.")

    def __init__(
        self,
        kp: float,
        ki: float,
        kd: float,
        dt: float,
        *,
        reference_omega: float | None = None,
        reference_zeta: float = 1.0,
        max_turn_rate: float | None = None,
        max_turn_accel: float | None = None,
        max_command: float | None = None,
        max_rate: float | None = None,
        offset: float = 0.0,
        anti_windup: str | bool = "back_calculation",
        nomoto: tuple[float, float] | None = None,
        nomoto_feedforward: bool = False,
        omega_n: float | None = None,
        zeta: float | None = None,
    ) -> None:
        self.kp = finite("kp", kp)
        self.ki = finite("ki", ki)
        self.kd = finite("kd", kd)
        self._clock = StepClock(dt)
        self.dt = self._clock.dt
        self.reference: HeadingReferenceModel | None = None
        if reference_omega is not None:
            self.reference = HeadingReferenceModel(
                reference_omega,
                reference_zeta,
                max_turn_rate=max_turn_rate,
                max_turn_accel=max_turn_accel,
            )
        elif max_turn_rate is not None or max_turn_accel is not None:
            raise ValueError("max_turn_rate and max_turn_accel need a reference model")
        self.max_command = optional_limit("max_command", max_command)
        self.max_rate = optional_limit("max_rate", max_rate)
        #: Limit [rad/s] on the yaw rate the heading loop may ask for (see :meth:`update`).
        self.max_turn_rate = optional_limit("max_turn_rate", max_turn_rate)
        self.offset = finite("offset", offset)
        self.anti_windup = anti_windup_mode(anti_windup)
        #: Back-calculation tracking time ``T_t`` [s].
        self.tracking_time = tracking_time(self.kp, self.ki, self.kd)
        if nomoto is not None:
            try:
                k_, t_ = nomoto
            except (TypeError, ValueError):
                raise ValueError(f"nomoto must be a pair (K, T), got {nomoto!r}") from None
            k_, t_ = finite("nomoto K", k_), finite("nomoto T", t_)
            if k_ == 0 or t_ == 0:
                raise ValueError(f"nomoto (K, T) must both be non-zero, got {nomoto!r}")
            self.nomoto: tuple[float, float] | None = (k_, t_)
        else:
            self.nomoto = None
        if nomoto_feedforward and self.nomoto is None:
            raise ValueError("nomoto_feedforward=True needs nomoto=(K, T)")
        self.nomoto_feedforward = bool(nomoto_feedforward)
        self.omega_n = None if omega_n is None else positive("omega_n", omega_n)
        self.zeta = None if zeta is None else positive("zeta", zeta)
        #: Poles asked for by :meth:`from_nomoto` (exact for ``method="exact"``).
        self.design_poles = np.empty(0, dtype=complex)
        #: Servo time constant [s] that :meth:`design_report` adds to the Nomoto plant.
        self.actuator_time_constant = 0.0
        self._initialised = False
        self.reset(0.0)
        self._initialised = False

    # ------------------------------------------------------------------------------------
    @classmethod
    def from_nomoto(
        cls,
        K: float,
        T: float,
        dt: float,
        *,
        omega_n: float | None = None,
        zeta: float = 0.8,
        method: Literal["exact", "fossen"] = "exact",
        integral_ratio: float = 0.1,
        reference_omega: float | None = None,
        reference_zeta: float = 1.0,
        actuator_time_constant: float | None = None,
        max_turn_rate: float | None = None,
        max_turn_accel: float | None = None,
        max_command: float | None = None,
        max_rate: float | None = None,
        offset: float = 0.0,
        anti_windup: str | bool = "back_calculation",
        nomoto_feedforward: bool = False,
    ) -> HeadingAutopilot:
        """Design by pole placement on ``psi / delta = K / (s (1 + T s))``.

        Parameters
        ----------
        K, T : float
            Nomoto gain [1/s] and time constant [s] of the command-to-yaw-rate response
            (non-zero, any signs).
        dt : float
            Sample time [s].
        omega_n : float, optional
            Closed-loop natural frequency [rad/s]; :func:`default_bandwidth` of ``T`` and the
            actuator data (``actuator_time_constant``, ``max_command``, ``max_rate``) if
            omitted.
        zeta : float
            Closed-loop damping (0.8).
        method, integral_ratio
            See :func:`pid_gains_nomoto`.
        reference_omega : float, optional
            Reference-model frequency; ``omega_n`` by default (no faster than the loop that
            tracks it). ``0`` disables the reference model.
        actuator_time_constant : float, optional
            Servo time constant [s]: used by the default ``omega_n`` and kept for
            :meth:`design_report`.
        Other parameters
            As in :class:`HeadingAutopilot`.
        """
        if omega_n is None:
            omega_n = default_bandwidth(
                T,
                actuator_time_constant=actuator_time_constant,
                max_command=max_command,
                max_rate=max_rate,
            )
        kp, ki, kd = pid_gains_nomoto(
            K, T, omega_n, zeta, method=method, integral_ratio=integral_ratio
        )
        if reference_omega is None:
            ref: float | None = omega_n
        elif reference_omega == 0:
            ref = None
        else:
            ref = reference_omega
        pilot = cls(
            kp,
            ki,
            kd,
            dt,
            reference_omega=ref,
            reference_zeta=reference_zeta,
            max_turn_rate=max_turn_rate,
            max_turn_accel=max_turn_accel,
            max_command=max_command,
            max_rate=max_rate,
            offset=offset,
            anti_windup=anti_windup,
            nomoto=(K, T),
            nomoto_feedforward=nomoto_feedforward,
            omega_n=omega_n,
            zeta=zeta,
        )
        wn = float(omega_n)
        wd = wn * np.sqrt(complex(1.0 - zeta * zeta))
        poles = [-zeta * wn + 1j * wd, -zeta * wn - 1j * wd]
        if integral_ratio > 0:
            poles.append(complex(-integral_ratio * wn))
        pilot.design_poles = np.array(poles, dtype=complex)
        if actuator_time_constant is not None:
            pilot.actuator_time_constant = nonnegative(
                "actuator_time_constant", actuator_time_constant
            )
        return pilot

    # ------------------------------------------------------------------------------------
    def reset(
        self,
        psi: ArrayLike,
        r: ArrayLike = 0.0,
        *,
        t: float | None = None,
        command: ArrayLike | None = None,
        keep_offset: bool = False,
    ) -> None:
        """Restart at heading ``psi`` [rad] and yaw rate ``r`` [rad/s].

        Numbers restart one ship (scalar mode); arrays of shape ``(n,)`` a batch of ``n``
        ships (a number for ``r`` or ``command`` is then every ship's).

        Parameters
        ----------
        psi, r : float or array_like
            Measured heading and yaw rate; the reference model starts there.
        t : float, optional
            Time [s] of this state (one for the batch); the next :meth:`update` integrates
            from it.
        command : float or array_like, optional
            The actuator's present command, the start of the rate limiter; without it
            the first command is not rate limited.
        keep_offset : bool
            Move the integral term into the offset (``b0 += ki * integral``) instead of
            forgetting it: the learned rudder offset is kept for the next manoeuvre (for a
            batch, one offset per ship, and the batch must keep its size).

        Raises
        ------
        ValueError
            For a value that is not finite (an array names the index of the first bad
            entry), arrays of different lengths, or a batch size that does not match the
            offsets kept per ship.
        """
        n = batch_size(psi=psi, r=r, command=command)
        psi_a = finite_batch("psi", psi, n)
        r_a = finite_batch("r", r, n)
        cmd = np.full(psi_a.shape, math.nan)
        if command is not None:
            cmd = finite_batch("command", command, n)
        offset = self.offset
        if keep_offset:
            offset = offset + self.ki * self._integral
        if np.ndim(offset) != 0 and np.shape(offset) != psi_a.shape:
            raise ValueError(
                f"offset has shape {np.shape(offset)} (one per ship, kept by keep_offset=True) "
                f"but the reset is for shape {psi_a.shape}; set offset to a number to start a "
                "batch of another size"
            )
        if keep_offset:
            self.offset = float(offset[0]) if n is None else offset
        self._integral = np.zeros(psi_a.shape)
        if self.reference is not None:
            self.reference._start(psi_a, r_a, n)
            self._r_d = self.reference._r_d
        else:
            self._r_d = np.zeros(psi_a.shape)
        self._psi_d = ssa_array(psi_a)
        self._a_d = self._error = np.zeros(psi_a.shape)
        self._command = self._unsaturated_command = cmd
        self._clock.reset(t)
        self.batch_size = n
        self._initialised = True

    @property
    def offset_estimate(self) -> float | np.ndarray:
        """Estimated constant command offset: ``b0 + ki * integral`` (one per ship).

        At a steady straight course the integral term settles at whatever constant command
        the disturbances (rudder bias, current, wind) require; this is that estimate.
        """
        return batch_value(self.offset + self.ki * self._integral, self.batch_size)

    def update(
        self, t: float | None, psi: ArrayLike, r: ArrayLike, psi_ref: ArrayLike
    ) -> float | np.ndarray:
        """One controller step; returns the steering command.

        Parameters
        ----------
        t : float or None
            Sample time [s] of the whole batch; the step is the difference to the previous
            ``t`` (``dt`` when ``None``). The first call after construction resets at the
            measured state (and takes the batch size from ``psi``).
        psi : float or array_like
            Measured heading [rad] (any wrapping): a number for one ship, an array ``(n,)``
            for a batch.
        r : float or array_like
            Measured yaw rate [rad/s], as ``psi``.
        psi_ref : float or array_like
            Heading setpoint [rad] (any wrapping; reached the short way); for a batch an
            array ``(n,)`` or one setpoint for every ship.

        Returns
        -------
        float or numpy.ndarray
            Steering command (rad for a rudder or azimuth) within ``max_command`` and the
            rate limit: a float for one ship, an array ``(n,)`` for a batch.

        Raises
        ------
        ValueError
            For a value that is not finite (an array names the index), a shape that is not
            the batch's (naming both shapes), or a time that goes backwards.
        """
        n = self.batch_size if self._initialised else batch_size(psi=psi, r=r, psi_ref=psi_ref)
        psi_a = finite_batch("psi", psi, n, broadcast=False)
        r_a = finite_batch("r", r, n, broadcast=False)
        ref = finite_batch("psi_ref", psi_ref, n)
        if not self._initialised:
            self.reset(psi, r)
        h = self._clock.step(t)
        if self.reference is not None:
            psi_d, r_d, a_d = self.reference._advance(ref, h)
        else:
            psi_d, r_d, a_d = ref, self._r_d, self._a_d  # r_d = a_d = 0
        # the gains as 0-d arrays (faster with small batches, the same values)
        kp, ki, kd, offset = constant(self.kp), constant(self.ki), constant(self.kd), self.offset
        offset = np.asarray(offset, dtype=np.float64)
        e = ssa_array(psi_d - psi_a)
        heading_part = kp * e + ki * self._integral
        u = heading_part - kd * (r_a - r_d) + offset
        u_applied = u
        if math.isfinite(self.max_turn_rate) and self.kd != 0.0:
            # The PID as a cascade: u = -Kd (r - r_cmd) + b0 with the yaw-rate demand
            # r_cmd = r_d + (Kp e + Ki int e) / Kd. Clipping r_cmd keeps a large heading
            # error from asking for a turn the ship cannot check (an unstable ship).
            r_cmd = r_d + heading_part / kd
            r_lim = clip(r_cmd, *bounds(-self.max_turn_rate, self.max_turn_rate))
            u_applied = constant(-self.kd) * (r_a - r_lim) + offset
        if self.nomoto_feedforward and self.nomoto is not None:
            K, T = constant(self.nomoto[0]), constant(self.nomoto[1])
            feedforward = (T * a_d + r_d) / K
            u = u + feedforward
            u_applied = u_applied + feedforward
        u_lim = clip(u_applied, *bounds(-self.max_command, self.max_command))
        if math.isfinite(self.max_rate):
            u_lim = rate_limit(u_lim, self._command, self.max_rate * h)
        self._integral = integrate_with_anti_windup(
            self._integral, e, h, self.ki, u - u_lim, self.anti_windup, self.tracking_time
        )
        self._psi_d, self._r_d, self._a_d = ssa_array(psi_d), r_d, a_d
        self._error = e
        self._unsaturated_command = u
        self._command = u_lim
        return batch_value(u_lim, n)

    # ------------------------------------------------------------------------------------
    def design_report(
        self,
        plant: control.TransferFunction | None = None,
        *,
        actuator_time_constant: float | None = None,
    ) -> HeadingDesignReport:
        """Check the closed loop with python-control.

        Parameters
        ----------
        plant : control.TransferFunction, optional
            ``psi / delta_c``; by default the Nomoto model ``K / (s (1 + T s))`` of
            ``nomoto`` (in series with ``1 / (1 + T_a s)`` if ``actuator_time_constant``).
            Pass any linear model (e.g. a linearised 3-DOF model with an integrator).
        actuator_time_constant : float, optional
            ``T_a`` [s] of a first-order actuator added to the default plant; the one given
            to :meth:`from_nomoto` (or none) by default.

        Returns
        -------
        HeadingDesignReport

        Raises
        ------
        ValueError
            Without a plant when the autopilot has no ``nomoto`` model.
        """
        import control

        if actuator_time_constant is None:
            actuator_time_constant = self.actuator_time_constant
        ta = nonnegative("actuator_time_constant", actuator_time_constant)
        if plant is None:
            if self.nomoto is None:
                raise ValueError("design_report needs a plant or an autopilot with nomoto=(K, T)")
            K, T = self.nomoto
            plant = control.tf([K], [T, 1.0, 0.0])
            if ta > 0:
                plant = plant * control.tf([1.0], [ta, 1.0])
        elif not isinstance(plant, control.TransferFunction):
            raise ValueError(f"plant must be a control.TransferFunction, got {type(plant)!r}")
        controller = control.tf([self.kd, self.kp, self.ki], [1.0, 0.0])
        loop = controller * plant
        closed = control.feedback(loop, 1)
        poles = np.asarray(control.poles(closed), dtype=complex)
        poles = poles[np.argsort(-poles.real)]
        stable = bool(np.all(poles.real < 0))
        gm, pm, _sm, wpc, wgc, _wms = control.stability_margins(loop)
        design = self.design_poles.copy()
        return HeadingDesignReport(
            kp=self.kp,
            ki=self.ki,
            kd=self.kd,
            omega_n=self.omega_n,
            zeta=self.zeta,
            design_poles=design,
            closed_loop_poles=poles,
            stable=stable,
            gain_margin=float(gm),
            phase_margin_deg=float(pm),
            gain_crossover=float(wgc),
            phase_crossover=float(wpc),
            plant=plant,
            controller=controller,
            loop=loop,
        )

"""Nomoto-family heading models with steering gear, surge speed and current kinematics.

Four yaw models share one state layout and one set of actuator/kinematic equations:

* ``nomoto1``: first-order Nomoto, ``T r' + r = K delta`` (seed 004 eq. 2, seed 000).
* ``nomoto2``: second-order Nomoto, ``T1 T2 r'' + (T1 + T2) r' + r = K (delta + T3 delta')``
  (seed 004 eq. 1).
* ``norrbin``: Norrbin's nonlinear first order,
  ``T r' + n3 r^3 + n2 r|r| + n1 r + n0 = K delta`` (seed 002 eq. 1-3, seed 004 eq. 4).
* ``bech``: Bech's nonlinear second order,
  ``T1 T2 r'' + (T1 + T2) r' + K H_B(r) = K (delta + T3 delta')`` with
  ``H_B(r) = b3 r^3 + b2 r|r| + b1 r + b0`` (seed 004 eq. 3).

The quadratic terms use ``r|r|`` (odd, as in Fossen 2011 section 7.2) rather than the ``r^2`` of
the seeds, so a ship that is symmetric in the linear term stays mirror-symmetric; ``n2``/``b2``
then model a port/starboard asymmetry with a sign that follows the turn.

Steering gear (seed 002 eq. 2): ``delta' = sat_rate((sat_angle(delta_c) - delta) / T_delta)``.
Surge (seed 004 eq. 8): ``U' = (K_u n - U) / T_u`` with ``n`` the shaft speed [rev/s].
Kinematics with a constant irrotational current (north/east components ``V_n, V_e``):
``x' = U cos(psi) + V_n``, ``y' = U sin(psi) + V_e``, ``psi' = r``. ``U`` is the speed
through the water along the heading (sway is neglected in these models).

State ``[x, y, psi, U, r, delta]`` (+ ``r_dot`` for the second-order models) in
[m, m, rad, m/s, rad/s, rad, rad/s^2]; input ``[delta_c, n]`` in [rad, rev/s]. Positive
rudder gives a positive (starboard) yaw rate, so ``K > 0``.

Default parameters: the Mariner class cargo ship (L = 160.93 m, U = 7.7 m/s; Fossen 1994,
*Guidance and Control of Ocean Vehicles*, section 2.2: K = 0.185 1/s, T1 = 118 s, T2 = 7.8 s,
T3 = 18.5 s, so the first-order T = T1 + T2 - T3 = 107.3 s). The nonlinear coefficients are
chosen so that the steady turning rate at 35 deg rudder is 0.030 rad/s (steady turning diameter
about 3.2 L, a typical value for this hull form) instead of the linear model's 0.113 rad/s.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from shipgym.models._jit import param, simd_kernel
from shipgym.models.vmath import sincos

# Shared state and input indices of the Nomoto family.
IX, IY, IPSI, IU, IR, IDELTA, IRDOT = 0, 1, 2, 3, 4, 5, 6
FIRST_ORDER_STATES = ("x", "y", "psi", "U", "r", "delta")
SECOND_ORDER_STATES = (*FIRST_ORDER_STATES, "r_dot")
NOMOTO_INPUTS = ("delta_c", "n")


def _check_positive(obj: object, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise ValueError(
                f"{type(obj).__name__}.{name} must be a finite number > 0, got {value!r}"
            )


def _check_finite(obj: object) -> None:
    for name, value in asdict(obj).items():  # type: ignore[call-overload]
        if not (isinstance(value, int | float) and math.isfinite(value)):
            raise ValueError(f"{type(obj).__name__}.{name} must be a finite number, got {value!r}")


@dataclass(frozen=True)
class SteeringGear:
    """First-order rudder servo with angle and rate limits (seed 002 eq. 2).

    Attributes
    ----------
    time_constant : float
        Servo time constant ``T_delta`` [s].
    max_angle : float
        Rudder angle limit [rad] (35 deg by default).
    max_rate : float
        Rudder rate limit [rad/s] (IMO: 35 deg to 30 deg the other side in 28 s, 2.32 deg/s).
    """

    time_constant: float = 2.0
    max_angle: float = math.radians(35.0)
    max_rate: float = math.radians(2.32)

    def __post_init__(self) -> None:
        _check_positive(self, "time_constant", "max_angle", "max_rate")


@dataclass(frozen=True)
class SurgeModel:
    """First-order surge speed response to shaft speed (seed 004 eq. 8).

    Attributes
    ----------
    gain : float
        ``K_u`` [m/s per rev/s]: steady speed per unit shaft speed.
    time_constant : float
        ``T_u`` [s].
    service_shaft_speed : float
        Shaft speed [rev/s] that gives the service speed.
    max_shaft_speed : float
        Largest shaft speed [rev/s] a command may ask for.
    """

    gain: float = 5.5
    time_constant: float = 150.0
    service_shaft_speed: float = 1.4
    max_shaft_speed: float = 1.8

    def __post_init__(self) -> None:
        _check_positive(self, "gain", "time_constant", "service_shaft_speed", "max_shaft_speed")

    @property
    def service_speed(self) -> float:
        """Steady speed [m/s] at the service shaft speed."""
        return self.gain * self.service_shaft_speed


@dataclass(frozen=True)
class Nomoto1Params:
    """First-order Nomoto ``r/delta = K / (1 + T s)``.

    Attributes
    ----------
    K : float
        Gain [1/s].
    T : float
        Time constant [s].
    """

    K: float = 0.185
    T: float = 107.3

    def __post_init__(self) -> None:
        _check_finite(self)
        _check_positive(self, "T")

    def coefficients(self) -> tuple[float, ...]:
        """Yaw coefficients in kernel order."""
        return (self.K, self.T)


@dataclass(frozen=True)
class Nomoto2Params:
    """Second-order Nomoto ``r/delta = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s))``.

    Attributes
    ----------
    K : float
        Gain [1/s].
    T1, T2, T3 : float
        Time constants [s].
    """

    K: float = 0.185
    T1: float = 118.0
    T2: float = 7.8
    T3: float = 18.5

    def __post_init__(self) -> None:
        _check_finite(self)
        _check_positive(self, "T1", "T2")

    def coefficients(self) -> tuple[float, ...]:
        """Yaw coefficients in kernel order."""
        return (self.K, self.T1, self.T2, self.T3)


@dataclass(frozen=True)
class NorrbinParams:
    """Norrbin ``T r' + n3 r^3 + n2 r|r| + n1 r + n0 = K delta``.

    Attributes
    ----------
    K : float
        Gain [1/s].
    T : float
        Time constant [s].
    n0 : float
        Bias [rad/s] (a rudder offset of ``n0 / K`` rad).
    n1 : float
        Linear coefficient [-] (1 for a course-stable ship, -1 for an unstable one).
    n2 : float
        Quadratic coefficient [s].
    n3 : float
        Cubic coefficient [s^2].
    """

    K: float = 0.185
    T: float = 107.3
    n0: float = 0.0
    n1: float = 1.0
    n2: float = 0.0
    n3: float = 2.9e3

    def __post_init__(self) -> None:
        _check_finite(self)
        _check_positive(self, "T")

    def coefficients(self) -> tuple[float, ...]:
        """Yaw coefficients in kernel order."""
        return (self.K, self.T, self.n0, self.n1, self.n2, self.n3)


@dataclass(frozen=True)
class BechParams:
    """Bech ``T1 T2 r'' + (T1 + T2) r' + K H_B(r) = K (delta + T3 delta')``.

    ``H_B(r) = b3 r^3 + b2 r|r| + b1 r + b0`` [rad]; its inverse is the steady delta-r (spiral)
    curve. ``b1 = 1 / K`` makes the linear part equal to the second-order Nomoto model.

    Attributes
    ----------
    K : float
        Gain [1/s].
    T1, T2, T3 : float
        Time constants [s].
    b0 : float
        Rudder offset [rad].
    b1 : float
        Linear coefficient [s].
    b2 : float
        Quadratic coefficient [s^2].
    b3 : float
        Cubic coefficient [s^3].
    """

    K: float = 0.185
    T1: float = 118.0
    T2: float = 7.8
    T3: float = 18.5
    b0: float = 0.0
    b1: float = 1.0 / 0.185
    b2: float = 0.0
    b3: float = 2.9e3 / 0.185

    def __post_init__(self) -> None:
        _check_finite(self)
        _check_positive(self, "T1", "T2")

    def coefficients(self) -> tuple[float, ...]:
        """Yaw coefficients in kernel order."""
        return (self.K, self.T1, self.T2, self.T3, self.b0, self.b1, self.b2, self.b3)


# Parameter vector layout shared by the family: actuator and surge first, yaw coefficients after.
P_DMAX, P_DRATE, P_TDELTA, P_KU, P_TU = 0, 1, 2, 3, 4
P_YAW = 5


def pack_nomoto(
    yaw: Nomoto1Params | Nomoto2Params | NorrbinParams | BechParams,
    gear: SteeringGear,
    surge: SurgeModel,
) -> np.ndarray:
    """Parameter vector that the Nomoto-family kernels read."""
    head = (gear.max_angle, gear.max_rate, gear.time_constant, surge.gain, surge.time_constant)
    return np.array(head + yaw.coefficients(), dtype=np.float64)


@simd_kernel
def _actuators_and_kinematics(X, U, p, C, b):
    """Steering gear, surge and position kinematics of ship ``b`` of a block: returns
    ``(x', y', psi', U', delta')``.

    The model functions here take a block of ships column by column (``X`` states x ships,
    ``U`` inputs x ships, ``C`` the disturbances x ships: current north and east, then the
    seaway's equivalent rudder angle ``delta_w`` and leeway ``v_w`` (:mod:`shipgym.models.seaway`),
    ``K`` the derivative), as
    :func:`shipgym.models.integrate.rk4_block` steps them; one ship is a block of one. ``p`` is
    the packed parameter vector shared by the block, or a table of them with a column per ship
    (:func:`shipgym.models._jit.param`).
    Straight-line code (the sine and cosine of :mod:`shipgym.models.vmath`) that reads every
    input before it writes, so a loop over the ships compiles to SIMD code.
    """
    dmax = param(p, P_DMAX, b)
    rate = param(p, P_DRATE, b)
    dc = min(max(U[0, b], -dmax), dmax)
    ddot = min(max((dc - X[IDELTA, b]) / param(p, P_TDELTA, b), -rate), rate)
    sn, cs = sincos(X[IPSI, b])
    speed = X[IU, b]
    leeway = C[3, b]
    return (
        speed * cs - leeway * sn + C[0, b],
        speed * sn + leeway * cs + C[1, b],
        X[IR, b],
        (param(p, P_KU, b) * U[1, b] - speed) / param(p, P_TU, b),
        ddot,
    )


@simd_kernel
def _store(K, b, xd, yd, psid, ud, ddot):
    """Write the common derivatives of ship ``b`` (after every read of the model function)."""
    K[IX, b] = xd
    K[IY, b] = yd
    K[IPSI, b] = psid
    K[IU, b] = ud
    K[IDELTA, b] = ddot


@simd_kernel
def nomoto1_col(X, U, p, C, K, b):
    """First-order Nomoto derivative (seed 004 eq. 2) of ship ``b`` of a block."""
    xd, yd, psid, ud, ddot = _actuators_and_kinematics(X, U, p, C, b)
    gain, T = param(p, P_YAW, b), param(p, P_YAW + 1, b)
    rd = (gain * (X[IDELTA, b] + C[2, b]) - X[IR, b]) / T
    _store(K, b, xd, yd, psid, ud, ddot)
    K[IR, b] = rd


@simd_kernel
def norrbin_col(X, U, p, C, K, b):
    """Norrbin derivative (seed 002 eq. 1-3, seed 004 eq. 4) of ship ``b`` of a block."""
    xd, yd, psid, ud, ddot = _actuators_and_kinematics(X, U, p, C, b)
    gain, T = param(p, P_YAW, b), param(p, P_YAW + 1, b)
    n0, n1, n2, n3 = (
        param(p, P_YAW + 2, b),
        param(p, P_YAW + 3, b),
        param(p, P_YAW + 4, b),
        param(p, P_YAW + 5, b),
    )
    r = X[IR, b]
    hn = n3 * r * r * r + n2 * r * abs(r) + n1 * r + n0
    rd = (gain * (X[IDELTA, b] + C[2, b]) - hn) / T
    _store(K, b, xd, yd, psid, ud, ddot)
    K[IR, b] = rd


@simd_kernel
def nomoto2_col(X, U, p, C, K, b):
    """Second-order Nomoto derivative (seed 004 eq. 1) of ship ``b`` of a block."""
    xd, yd, psid, ud, ddot = _actuators_and_kinematics(X, U, p, C, b)
    gain, T1, T2, T3 = (
        param(p, P_YAW, b),
        param(p, P_YAW + 1, b),
        param(p, P_YAW + 2, b),
        param(p, P_YAW + 3, b),
    )
    rdot = X[IRDOT, b]
    rdd = (gain * (X[IDELTA, b] + C[2, b] + T3 * ddot) - (T1 + T2) * rdot - X[IR, b]) / (T1 * T2)
    _store(K, b, xd, yd, psid, ud, ddot)
    K[IR, b] = rdot
    K[IRDOT, b] = rdd


@simd_kernel
def bech_col(X, U, p, C, K, b):
    """Bech derivative (seed 004 eq. 3) of ship ``b`` of a block."""
    xd, yd, psid, ud, ddot = _actuators_and_kinematics(X, U, p, C, b)
    gain, T1, T2, T3 = (
        param(p, P_YAW, b),
        param(p, P_YAW + 1, b),
        param(p, P_YAW + 2, b),
        param(p, P_YAW + 3, b),
    )
    b0, b1, b2, b3 = (
        param(p, P_YAW + 4, b),
        param(p, P_YAW + 5, b),
        param(p, P_YAW + 6, b),
        param(p, P_YAW + 7, b),
    )
    r = X[IR, b]
    rdot = X[IRDOT, b]
    hb = b3 * r * r * r + b2 * r * abs(r) + b1 * r + b0
    rdd = (gain * (X[IDELTA, b] + C[2, b] + T3 * ddot) - (T1 + T2) * rdot - gain * hb) / (T1 * T2)
    _store(K, b, xd, yd, psid, ud, ddot)
    K[IR, b] = rdot
    K[IRDOT, b] = rdd

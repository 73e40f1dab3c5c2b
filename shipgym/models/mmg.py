"""The MMG standard manoeuvring model (Yasukawa and Yoshimura 2015) and the KVLCC2.

The 3-DOF model of the Japan Society of Naval Architects and Ocean Engineers' manoeuvring
modelling group (MMG), as standardised by H. Yasukawa and Y. Yoshimura, "Introduction of MMG
standard method for ship maneuvering predictions", J. Mar. Sci. Technol. 20 (2015) 37-52, with
the hull (H), propeller (P) and rudder (R) forces written separately. Equation numbers below are
the paper's. It is the physics-based special case of seed 003's general 3-DOF system.

Motion (eq. 4), origin at midship, ``x_G`` the centre of gravity forward of it, ``v`` the sway
velocity at midship::

    (m + m_x) u' - (m + m_y) v r - x_G m r^2 = X_H + X_R + X_P
    (m + m_y) v' + (m + m_x) u r + x_G m r'  = Y_H + Y_R
    (I_zG + x_G^2 m + J_z) r' + x_G m (v' + u r) = N_H + N_R

Hull (eq. 7-10), with ``U = sqrt(u^2 + v^2)``, ``v' = v / U``, ``r' = r L / U``::

    X_H = rho/2 L d U^2 (-R'_0 + X'_vv v'^2 + X'_vr v' r' + X'_rr r'^2 + X'_vvvv v'^4)
    Y_H = rho/2 L d U^2 (Y'_v v' + Y'_r r' + Y'_vvv v'^3 + Y'_vvr v'^2 r' + Y'_vrr v' r'^2
                         + Y'_rrr r'^3)
    N_H = rho/2 L^2 d U^2 (N'_v v' + ... the same terms)

Propeller (eq. 13-16): ``X_P = (1 - t_P) rho n^2 D^4 K_T(J)``, ``K_T = k_0 + k_1 J + k_2 J^2``,
``J = u (1 - w_P) / (n D)``, with the wake fraction in manoeuvring
``(1 - w_P) / (1 - w_P0) = 1 + (1 - exp(-C_1 |beta_P|)) (C_2 - 1)``, ``beta_P = beta - x'_P r'``,
``beta = atan2(-v, u)`` (``C_2`` takes one value for ``beta_P > 0`` and another below).

Rudder (eq. 33-46)::

    X_R = -(1 - t_R) F_N sin(delta),  Y_R = -(1 + a_H) F_N cos(delta),
    N_R = -(x_R + a_H x_H) F_N cos(delta),  F_N = rho/2 A_R U_R^2 f_alpha sin(alpha_R)
    alpha_R = delta - atan2(v_R, u_R),  v_R = U gamma_R (beta - l'_R r')
    u_R = eps u (1 - w_P) sqrt(eta (1 + kappa (sqrt(1 + 8 K_T / (pi J^2)) - 1))^2 + 1 - eta)

``eta = D / H_R``; ``gamma_R`` takes one value for ``beta_R < 0`` and another above. The
propeller-slipstream factor is evaluated as ``u_p sqrt(1 + 8 K_T / (pi J^2)) = sqrt(u_p^2 +
8 K_T n^2 D^2 / pi)`` with ``u_p = u (1 - w_P)``, which has no singularity at ``J = 0``.

Wind (not in the paper; off by default, ``wind_speed = 0``): a constant true wind adds
Blendermann's (1994) loads ``X_w``, ``Y_w``, ``N_w`` of the apparent wind
(:mod:`shipgym.models.wind`: the true wind less the ship's velocity over ground) to the right
of eq. 4, inside the derivative, so RK4 integrates them with the motion. The ship's wind data
(``wind_*`` fields, ``length_overall``) default to an estimate for the KVLCC2 (below).

Sign convention: a positive rudder angle turns the ship to starboard (``r > 0``), as the Nomoto
models (``N_R > 0`` for ``delta > 0`` since ``x_R + a_H x_H < 0``).

Steering gear: ``delta' = sat_rate((sat(delta_c) - delta) / T_delta)``, limited to
``max_rudder`` and ``rudder_rate``. Current: constant and irrotational, in the hydrodynamics
through the velocities relative to the water (``nu_r = nu - nu_c``); for such a current
``M nu' + C(nu) nu = M nu_r' + C(nu_r) nu_r`` with ``nu' = nu_r' + [r v_c, -r u_c, 0]`` (Fossen
2011, property 10.1), so the motion equations above are solved for ``nu_r'``.

State ``[x, y, psi, u, v, r, delta]`` in [m, m, rad, m/s, m/s, rad/s, rad] (``x, y`` of midship,
``u, v`` over ground at midship); input ``[delta_c, n]`` in [rad, 1/s] (propeller revolutions
per second).

The KVLCC2 set (:meth:`MMGParams.kvlcc2`) is the 1/45.7 model (L7, 7 m) of Yasukawa and
Yoshimura (2015, Tables 1-4) at the SIMMAN 2008 conditions (``Fn`` 0.142, ``U_0`` = 1.179
m/s), as also used by the independent ShipMMG package (``tests/test_mmg_3dof.py``).

The KVLCC2's wind areas are an estimate: the KVLCC2 is defined as a hull form, without a
superstructure. From its main particulars (SIMMAN 2008: ``L_pp`` 320 m, waterline length
325.5 m, ``B`` 58 m, depth 30 m, draught 20.8 m, so 9.2 m of freeboard) and an assumed
accommodation block aft, typical of a VLCC (40 m wide, 25 m long, 20 m above the deck, its
centre 137.5 m aft of midship), at full scale: ``A_F = 58 x 9.2 + 40 x 20 = 1334 m^2``,
``A_L = 325.5 x 9.2 + 25 x 20 = 3495 m^2``, the centroid of ``A_L`` ``s_L = -137.5 x 500 /
A_L = -19.7 m`` (the hull's share centred at midship), and ``L_oa`` taken as the waterline
length; the 7 m model's are these over ``KVLCC2_SCALE^2`` and ``KVLCC2_SCALE``. Blendermann's
coefficients are those of a loaded tanker (:data:`shipgym.models.wind.BLENDERMANN_COEFFICIENTS`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from shipgym.models._jit import kernel, row_kernel
from shipgym.models.kinematics import relative_motion, steering_gear
from shipgym.models.wind import BLENDERMANN_COEFFICIENTS, apparent_wind, blendermann_load

MMG_STATES = ("x", "y", "psi", "u", "v", "r", "delta")
MMG_INPUTS = ("delta_c", "n")
MMG_PARAMETER_SETS = ("kvlcc2",)
"""Names of the shipped MMG parameter sets (:meth:`MMGParams.named`)."""
IX, IY, IPSI, IU, IV, IR, IDELTA = range(7)
WAKE_FORMULAS = ("paper", "shipmmg")
"""Wake-in-manoeuvring formulas of :class:`MMGParams` (``wake_formula``)."""

KVLCC2_SCALE = 320.0 / 7.0
"""Full-scale (L_pp 320 m) over model-scale (7 m) length of the KVLCC2 L7 model."""
KVLCC2_SIMMAN_SPEED = 1.179
"""Approach speed [m/s] of the SIMMAN 2008 KVLCC2 L7 free-running tests (``Fn`` 0.142)."""
KVLCC2_FREEBOARD = 30.0 - 20.8
"""Freeboard [m] of the full-scale KVLCC2 (depth 30 m, draught 20.8 m)."""
KVLCC2_WIND_AREAS = (58.0 * KVLCC2_FREEBOARD + 40.0 * 20.0, 325.5 * KVLCC2_FREEBOARD + 25.0 * 20.0)
"""Estimated frontal and lateral projected wind areas ``A_F``, ``A_L`` [m^2] of the full-scale
KVLCC2: hull above the waterline plus an assumed accommodation block (module docstring)."""
KVLCC2_WIND_CENTRE = -137.5 * 25.0 * 20.0 / KVLCC2_WIND_AREAS[1]
"""Estimated ``s_L`` [m]: centroid of the full-scale KVLCC2's lateral wind area forward of
midship (module docstring)."""
KVLCC2_LENGTH_OVERALL = 325.5
"""``L_oa`` [m] of the wind loads of the full-scale KVLCC2 (its waterline length)."""
RUDDER_RATE_FULL_SCALE = math.radians(2.32)
"""Rudder rate [rad/s] of the full-scale KVLCC2 (SIMMAN 2008), ``sqrt(320 / 7)`` times faster
on the model (Froude scaling of time): 15.7 deg/s."""


@dataclass(frozen=True, eq=False)
class MMGParams:
    """Parameters of the MMG standard model (module docstring); KVLCC2 L7 by default.

    Lengths in [m], masses in [kg], the hydrodynamic derivatives non-dimensional (prime system
    of the paper: forces over ``rho/2 L d U^2``, moments over ``rho/2 L^2 d U^2``).

    Attributes
    ----------
    rho : float
        Water density [kg/m^3].
    length, breadth, draught : float
        ``L_pp``, ``B``, ``d`` [m].
    displacement : float
        Displacement volume ``nabla`` [m^3]; ``m = rho nabla``.
    x_g : float
        Centre of gravity forward of midship [m].
    gyration : float
        Radius of gyration in yaw over ``L_pp`` (``I_zG = m (gyration L)^2``).
    m_x, m_y, j_z : float
        Added masses and added moment ``m'_x``, ``m'_y`` (over ``rho/2 L^2 d``), ``J'_z``
        (over ``rho/2 L^4 d``).
    r0, x_vv, x_vr, x_rr, x_vvvv : float
        Surge resistance and hull surge derivatives.
    y_v, y_r, y_vvv, y_vvr, y_vrr, y_rrr : float
        Hull sway derivatives.
    n_v, n_r, n_vvv, n_vvr, n_vrr, n_rrr : float
        Hull yaw derivatives.
    propeller_diameter : float
        ``D_P`` [m].
    t_p, w_p0 : float
        Thrust deduction and straight-running wake fraction.
    k0, k1, k2 : float
        Open-water thrust coefficient ``K_T(J) = k0 + k1 J + k2 J^2``.
    x_p : float
        Longitudinal position of the propeller over ``L_pp`` (``x'_P``).
    c1, c2_plus, c2_minus : float
        Wake-in-manoeuvring constants ``C_1`` and ``C_2`` (``beta_P > 0`` and ``<= 0``).
    rudder_area, rudder_height : float
        ``A_R`` [m^2], ``H_R`` [m].
    t_r, a_h, x_h : float
        Steering resistance deduction ``t_R``, rudder force increase ``a_H`` and its position
        ``x'_H`` (over ``L_pp``).
    x_r : float
        Rudder position over ``L_pp`` (``x'_R``).
    epsilon, kappa, f_alpha : float
        Wake ratio ``epsilon`` at the rudder, propeller-slipstream constant ``kappa`` and
        rudder lift gradient ``f_alpha`` [1/rad].
    gamma_minus, gamma_plus : float
        Flow-straightening coefficient ``gamma_R`` for ``beta_R < 0`` and ``>= 0``.
    l_r : float
        Effective longitudinal position of the rudder over ``L_pp`` (``l'_R``).
    max_rudder, rudder_rate : float
        Rudder limits [rad, rad/s].
    rudder_time_constant : float
        Steering gear time constant ``T_delta`` [s] inside the rate limit.
    wake_formula : {"paper", "shipmmg"}
        Wake fraction in manoeuvring: the paper's eq. 16 (``C_1``, ``C_2``) or ShipMMG's
        ``w_P = w_P0 exp(-4 beta_P^2)``.
    speed_at_cg : bool
        ShipMMG's ``U = sqrt(u^2 + (v - x_G r)^2)`` and ``beta = asin(-(v - x_G r) / U)``
        instead of the paper's velocities at midship (``v' = v / U`` in both).
    wind_speed : float
        True wind speed [m/s], constant (>= 0; 0, the default: no wind).
    wind_direction : float
        Direction the true wind comes from [rad], clockwise from north (the earth x axis).
    wind_frontal_area, wind_lateral_area : float
        Frontal and lateral projected wind areas ``A_F``, ``A_L`` [m^2] (module docstring:
        the KVLCC2's are an estimate).
    wind_area_centre : float
        ``s_L`` [m]: centroid of ``A_L`` forward of midship.
    length_overall : float
        ``L_oa`` [m] of the wind loads.
    wind_ship_type : str
        Blendermann's ship type, a key of
        :data:`shipgym.models.wind.BLENDERMANN_COEFFICIENTS`.
    name : str
        Name of the set.
    """

    rho: float = 1025.0
    length: float = 7.0
    breadth: float = 1.27
    draught: float = 0.46
    displacement: float = 3.27
    x_g: float = 0.035 * 7.0
    gyration: float = 0.25
    m_x: float = 0.022
    m_y: float = 0.223
    j_z: float = 0.011
    r0: float = 0.022
    x_vv: float = -0.040
    x_vr: float = 0.002
    x_rr: float = 0.011
    x_vvvv: float = 0.771
    y_v: float = -0.315
    y_r: float = 0.083
    y_vvv: float = -1.607
    y_vvr: float = 0.379
    y_vrr: float = -0.391
    y_rrr: float = 0.008
    n_v: float = -0.137
    n_r: float = -0.049
    n_vvv: float = -0.030
    n_vvr: float = -0.294
    n_vrr: float = 0.055
    n_rrr: float = -0.013
    propeller_diameter: float = 0.216
    t_p: float = 0.220
    w_p0: float = 0.40
    k0: float = 0.2931
    k1: float = -0.2753
    k2: float = -0.1385
    x_p: float = -0.48
    c1: float = 2.0
    c2_plus: float = 1.6
    c2_minus: float = 1.1
    rudder_area: float = 0.0539
    rudder_height: float = 0.345
    t_r: float = 0.387
    a_h: float = 0.312
    x_h: float = -0.464
    x_r: float = -0.5
    epsilon: float = 1.09
    kappa: float = 0.50
    f_alpha: float = 2.747
    gamma_minus: float = 0.395
    gamma_plus: float = 0.640
    l_r: float = -0.710
    max_rudder: float = math.radians(35.0)
    rudder_rate: float = RUDDER_RATE_FULL_SCALE * math.sqrt(KVLCC2_SCALE)
    rudder_time_constant: float = 0.05
    wake_formula: str = "paper"
    speed_at_cg: bool = False
    wind_speed: float = 0.0
    wind_direction: float = 0.0
    wind_frontal_area: float = KVLCC2_WIND_AREAS[0] / KVLCC2_SCALE**2
    wind_lateral_area: float = KVLCC2_WIND_AREAS[1] / KVLCC2_SCALE**2
    wind_area_centre: float = KVLCC2_WIND_CENTRE / KVLCC2_SCALE
    length_overall: float = KVLCC2_LENGTH_OVERALL / KVLCC2_SCALE
    wind_ship_type: str = "tanker_loaded"
    name: str = "kvlcc2"

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in ("name", "wake_formula", "speed_at_cg", "wind_ship_type"):
                continue
            if not (isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)):
                raise ValueError(f"MMGParams.{f.name} must be a finite number, got {v!r}")
        if self.wake_formula not in WAKE_FORMULAS:
            raise ValueError(
                f"MMGParams.wake_formula must be one of {WAKE_FORMULAS}, got {self.wake_formula!r}"
            )
        if not isinstance(self.speed_at_cg, bool):
            raise ValueError(f"MMGParams.speed_at_cg must be a bool, got {self.speed_at_cg!r}")
        if self.wind_ship_type not in BLENDERMANN_COEFFICIENTS:
            raise ValueError(
                f"MMGParams.wind_ship_type must be one of {tuple(BLENDERMANN_COEFFICIENTS)}, "
                f"got {self.wind_ship_type!r}"
            )
        if self.wind_speed < 0.0:
            raise ValueError(f"MMGParams.wind_speed must be >= 0 m/s, got {self.wind_speed!r}")
        positive = ("rho", "length", "breadth", "draught", "displacement", "gyration",
                    "propeller_diameter", "rudder_area", "rudder_height", "max_rudder",
                    "rudder_rate", "rudder_time_constant", "wind_frontal_area",
                    "wind_lateral_area", "length_overall")  # fmt: skip
        for k in positive:
            if getattr(self, k) <= 0.0:
                raise ValueError(f"MMGParams.{k} must be > 0, got {getattr(self, k)!r}")

    @classmethod
    def kvlcc2(cls) -> MMGParams:
        """The KVLCC2 L7 model of Yasukawa and Yoshimura (2015) (the defaults)."""
        return cls()

    @classmethod
    def named(cls, name: str) -> MMGParams:
        """A shipped parameter set by name (:data:`MMG_PARAMETER_SETS`)."""
        if name == "kvlcc2":
            return cls.kvlcc2()
        raise ValueError(
            f"unknown MMG parameter set {name!r}; expected one of {MMG_PARAMETER_SETS}"
        )

    @property
    def mass(self) -> float:
        """``m = rho nabla`` [kg]."""
        return self.rho * self.displacement

    @property
    def added_masses(self) -> tuple[float, float, float]:
        """``m_x``, ``m_y`` [kg] and ``J_z`` [kg m^2] from the prime values."""
        half_l2d = 0.5 * self.rho * self.length**2 * self.draught
        return self.m_x * half_l2d, self.m_y * half_l2d, self.j_z * half_l2d * self.length**2

    @property
    def yaw_inertia(self) -> float:
        """``I_zG = m (gyration L)^2`` [kg m^2]."""
        return self.mass * (self.gyration * self.length) ** 2

    @property
    def approach_speed(self) -> float:
        """Trial speed [m/s]: the SIMMAN approach speed, Froude-scaled to this ship's length."""
        return KVLCC2_SIMMAN_SPEED * math.sqrt(self.length / 7.0)

    def scaled(self, factor: float) -> MMGParams:
        """The geometrically similar ship ``factor`` times longer (Froude scaling: lengths x
        ``factor``, volumes x ``factor^3``, rudder rate / ``sqrt(factor)``; the non-dimensional
        derivatives are kept; the wind areas x ``factor^2`` and the wind speed x
        ``sqrt(factor)``). ``kvlcc2().scaled(KVLCC2_SCALE)`` is the full-scale ship."""
        if not (isinstance(factor, int | float) and math.isfinite(factor) and factor > 0):
            raise ValueError(f"scale factor must be a finite number > 0, got {factor!r}")
        return replace(
            self,
            length=self.length * factor,
            breadth=self.breadth * factor,
            draught=self.draught * factor,
            displacement=self.displacement * factor**3,
            x_g=self.x_g * factor,
            propeller_diameter=self.propeller_diameter * factor,
            rudder_area=self.rudder_area * factor**2,
            rudder_height=self.rudder_height * factor,
            rudder_rate=self.rudder_rate / math.sqrt(factor),
            rudder_time_constant=self.rudder_time_constant * math.sqrt(factor),
            wind_speed=self.wind_speed * math.sqrt(factor),
            wind_frontal_area=self.wind_frontal_area * factor**2,
            wind_lateral_area=self.wind_lateral_area * factor**2,
            wind_area_centre=self.wind_area_centre * factor,
            length_overall=self.length_overall * factor,
        )

    def self_propulsion_rps(self, u: float) -> float:
        """Propeller revolutions [1/s] that hold straight running at ``u`` [m/s] (the model's
        own self-propulsion point: thrust balances ``R'_0``), from :func:`mmg_row`."""
        from scipy.optimize import brentq

        if not (math.isfinite(u) and u > 0.0):
            raise ValueError(f"speed must be a finite number > 0 m/s, got {u!r}")
        p = pack_mmg(self)

        def surge(n: float) -> float:
            return float(_straight_surge_acceleration(u, n, p))

        hi = 1.0
        while surge(hi) < 0.0:
            hi *= 2.0
            if hi > 1e4:
                raise ValueError(f"no propeller speed holds {u!r} m/s with these parameters")
        return float(brentq(surge, 1e-6, hi, xtol=1e-12))


P_MU, P_MV, P_MVR, P_MR = 0, 1, 2, 3  # m + m_x, m + m_y, x_G m, I_zG + x_G^2 m + J_z
P_INV = 4  # inverse of the 2x2 sway-yaw mass matrix (4 entries)
P_XG_BETA = 8  # x_G with ShipMMG's U and beta at G (``speed_at_cg``), else 0
P_QX, P_QN = 9, 10  # rho/2 L d, rho/2 L^2 d
P_L = 11
P_HULL = 12  # r0, x_vv, x_vr, x_rr, x_vvvv, y_v..y_rrr (6), n_v..n_rrr (6): 17 entries
P_PROP = 29  # rho D^4 (1 - t_P), D, 1 - w_P0, k0, k1, k2, x'_P, C_1, C_2+, C_2-
P_RUD = 39  # rho/2 A_R f_alpha, eta, eps, kappa, gamma-, gamma+, l'_R, 1 - t_R, 1 + a_H,
#            x_R + a_H x_H [m]
P_GEAR = 49  # max rudder, rate, 1 / T_delta
P_WAKE_SHIPMMG = 52  # 1.0 for ShipMMG's wake formula, else 0.0
P_WIND = 53  # true wind speed, its direction (from), A_F, A_L, s_L, L_oa, C_Dt, C_Dl,AF bow,
#              C_Dl,AF stern, delta (Blendermann)
P_SIZE = 63


def pack_mmg(params: MMGParams) -> np.ndarray:
    """Parameter vector that :func:`mmg_row` reads."""
    q = params
    p = np.zeros(P_SIZE)
    m = q.mass
    mx, my, jz = q.added_masses
    p[P_MU] = m + mx
    p[P_MV] = m + my
    p[P_MVR] = q.x_g * m
    p[P_MR] = q.yaw_inertia + q.x_g**2 * m + jz
    a = np.array([[p[P_MV], p[P_MVR]], [p[P_MVR], p[P_MR]]])
    p[P_INV : P_INV + 4] = np.linalg.inv(a).ravel()
    p[P_XG_BETA] = q.x_g if q.speed_at_cg else 0.0
    p[P_QX] = 0.5 * q.rho * q.length * q.draught
    p[P_QN] = 0.5 * q.rho * q.length**2 * q.draught
    p[P_L] = q.length
    p[P_HULL : P_HULL + 17] = (
        q.r0, q.x_vv, q.x_vr, q.x_rr, q.x_vvvv,
        q.y_v, q.y_r, q.y_vvv, q.y_vvr, q.y_vrr, q.y_rrr,
        q.n_v, q.n_r, q.n_vvv, q.n_vvr, q.n_vrr, q.n_rrr,
    )  # fmt: skip
    p[P_PROP : P_PROP + 10] = (
        q.rho * q.propeller_diameter**4 * (1.0 - q.t_p), q.propeller_diameter, 1.0 - q.w_p0,
        q.k0, q.k1, q.k2, q.x_p, q.c1, q.c2_plus, q.c2_minus,
    )  # fmt: skip
    p[P_RUD : P_RUD + 10] = (
        0.5 * q.rho * q.rudder_area * q.f_alpha, q.propeller_diameter / q.rudder_height,
        q.epsilon, q.kappa, q.gamma_minus, q.gamma_plus, q.l_r, 1.0 - q.t_r, 1.0 + q.a_h,
        (q.x_r + q.a_h * q.x_h) * q.length,
    )  # fmt: skip
    p[P_GEAR : P_GEAR + 3] = (q.max_rudder, q.rudder_rate, 1.0 / q.rudder_time_constant)
    p[P_WAKE_SHIPMMG] = 1.0 if q.wake_formula == "shipmmg" else 0.0
    p[P_WIND : P_WIND + 6] = (
        q.wind_speed, q.wind_direction, q.wind_frontal_area, q.wind_lateral_area,
        q.wind_area_centre, q.length_overall,
    )  # fmt: skip
    p[P_WIND + 6 : P_WIND + 10] = BLENDERMANN_COEFFICIENTS[q.wind_ship_type]
    return p


@row_kernel
def mmg_row(x, u, p, c, out):
    """MMG standard model derivative (Yasukawa and Yoshimura 2015 eq. 4-46), with the wind
    loads of :mod:`shipgym.models.wind` when the true wind is not zero."""
    r = x[IR]
    delta = x[IDELTA]
    # velocities relative to the water
    ur, vr, uc, vc = relative_motion(x, c, out)
    # U and beta at midship (the paper) or, with ShipMMG's formulas, at the centre of gravity
    vb = vr - p[P_XG_BETA] * r
    big_u = math.sqrt(ur * ur + vb * vb)
    length = p[P_L]
    if big_u > 1e-9:
        vp = vr / big_u
        rp = r * length / big_u
    else:
        vp = 0.0
        rp = 0.0
    beta = math.atan2(-vb, ur)
    u2 = big_u * big_u
    # hull (eq. 7-10)
    h = P_HULL
    xh = p[P_QX] * u2 * (
        -p[h] + p[h + 1] * vp * vp + p[h + 2] * vp * rp + p[h + 3] * rp * rp
        + p[h + 4] * vp * vp * vp * vp
    )  # fmt: skip
    yh = p[P_QX] * u2 * (
        p[h + 5] * vp + p[h + 6] * rp + p[h + 7] * vp * vp * vp + p[h + 8] * vp * vp * rp
        + p[h + 9] * vp * rp * rp + p[h + 10] * rp * rp * rp
    )  # fmt: skip
    nh = p[P_QN] * u2 * (
        p[h + 11] * vp + p[h + 12] * rp + p[h + 13] * vp * vp * vp + p[h + 14] * vp * vp * rp
        + p[h + 15] * vp * rp * rp + p[h + 16] * rp * rp * rp
    )  # fmt: skip
    # propeller (eq. 13-16)
    k = P_PROP
    n = u[1]
    dp = p[k + 1]
    beta_p = beta - p[k + 6] * rp
    if p[P_WAKE_SHIPMMG] != 0.0:
        one_minus_w = 1.0 - (1.0 - p[k + 2]) * math.exp(-4.0 * beta_p * beta_p)
    else:
        c2 = p[k + 8] if beta_p > 0.0 else p[k + 9]
        one_minus_w = p[k + 2] * (1.0 + (1.0 - math.exp(-p[k + 7] * abs(beta_p))) * (c2 - 1.0))
    u_p = ur * one_minus_w  # propeller advance speed
    nd = n * dp
    kt = 0.0
    if nd > 0.0:
        j = u_p / nd
        kt = p[k + 3] + p[k + 4] * j + p[k + 5] * j * j
    xp = p[k] * n * n * kt
    # rudder (eq. 33-46)
    g = P_RUD
    eta = p[g + 1]
    # u_p sqrt(1 + 8 K_T / (pi J^2)) = sqrt(u_p^2 + 8 K_T (n D)^2 / pi)
    slip = math.sqrt(max(u_p * u_p + 8.0 * kt * nd * nd / math.pi, 0.0))
    inner = u_p + p[g + 3] * (slip - u_p)
    u_rud = p[g + 2] * math.sqrt(eta * inner * inner + (1.0 - eta) * u_p * u_p)
    beta_r = beta - p[g + 6] * rp
    gamma = p[g + 4] if beta_r < 0.0 else p[g + 5]
    v_rud = big_u * gamma * beta_r
    alpha_r = delta - math.atan2(v_rud, u_rud)
    fn = p[g] * (u_rud * u_rud + v_rud * v_rud) * math.sin(alpha_r)
    cd = math.cos(delta)
    xr = -p[g + 7] * fn * math.sin(delta)
    yr = -p[g + 8] * fn * cd
    nr = -p[g + 9] * fn * cd
    # motion (eq. 4), solved for the relative accelerations
    xgm = p[P_MVR]
    bx = xh + xr + xp + p[P_MV] * vr * r + xgm * r * r
    by = yh + yr - p[P_MU] * ur * r
    bn = nh + nr - xgm * ur * r
    w = P_WIND
    if p[w] != 0.0:  # wind (Blendermann 1994) of the apparent wind over ground
        va, g = apparent_wind(p[w], p[w + 1], x[IPSI], x[IU], x[IV])
        xw, yw, nw = blendermann_load(va, g, p[w + 2], p[w + 3], p[w + 4], p[w + 5], p[w + 6],
                                      p[w + 7], p[w + 8], p[w + 9])  # fmt: skip
        bx += xw
        by += yw
        bn += nw
    out[IU] = bx / p[P_MU] + r * vc
    out[IV] = p[P_INV] * by + p[P_INV + 1] * bn - r * uc
    out[IR] = p[P_INV + 2] * by + p[P_INV + 3] * bn
    out[IDELTA] = steering_gear(delta, u[0], p[P_GEAR], p[P_GEAR + 1], p[P_GEAR + 2])


@kernel
def _straight_surge_acceleration(u, n, p):  # pragma: no cover - jit
    """``u'`` [m/s^2] of :func:`mmg_row` running straight at ``u`` with the propeller at ``n``
    and the rudder amidships, in the wind of ``p`` (none: calm water)."""
    x = np.zeros(7)
    x[IU] = u
    inputs = np.array([0.0, n])
    out = np.empty(7)
    mmg_row(x, inputs, p, np.zeros(2), out)
    return out[IU]

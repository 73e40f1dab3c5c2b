"""R/V Gunnerus (RVG) 3-DOF manoeuvring model with two azimuth pods (seed 001 eq. 5-20).

Kinematics (eq. 5-6): ``eta' = R_z(psi) nu`` with ``eta = [x, y, psi]``, ``nu = [u, v, r]``.

Current (eq. 7-9): earth-frame ``nu_c^n = V_c [cos beta_c, sin beta_c, 0]``, body-frame
``nu_c = R_z(psi)^T nu_c^n`` and ``nu_c' = [r v_c, -r u_c, 0]``.

Kinetics (eq. 10-12), with ``nu_r = nu - nu_c``::

    nu' = (M_rb + M_a)^-1 (F - C_rb(nu) nu - C_a(nu_r) nu_r - D(nu_r) nu_r + M_a nu_c')

Coriolis (eq. 14) in the skew-symmetric form ``C(nu)`` with
``C[0,2] = -C[2,0] = -(m22 v + (m23 + m32) r / 2)`` and ``C[1,2] = -C[2,1] = m11 u``. (The seed's
text prints ``m22 u`` in ``C[2,0]``; that breaks skew-symmetry and is a typo, Fossen 2011 eq. 6.43.)
Damping (eq. 15): ``D(nu_r) = D_l + D_u |u_r| + D_v |v_r| + D_r |r|``.

Pods (eq. 18-20): first-order thrust and azimuth, ``T' = (sat(T_c) - T) / tau_T`` and
``alpha' = sat_rate((sat(alpha_c) + alpha_0 - alpha) / tau_alpha)`` (``alpha_0``: an identified
azimuth offset, 0 in seed 001). The azimuth order ``alpha_c`` is what a record logs; the pods
follow it through this servo, whose time constant ``tau_alpha`` the source calls "a pure guess"
(1 s): the identification's ``rudder_lag`` effect (the shared steering-gear cause on the pods)
fits it within :data:`AZIMUTH_TIME_CONSTANT_RANGE`. Each pod at ``(x_t, y_t)`` gives
``F = T [cos a, sin a, -y_t cos a + x_t sin a]``, so positive azimuth on aft pods turns the ship
to port. Thrust is limited to ``[0, T_bollard (1 - u_r / u_0)]``, a fit to the Kongsberg pod at
200 rpm (RVG_PARAMETERS.md).

Thrust asymmetry: at one order the two pods need not deliver the same thrust (a shaft speed off
its order, since thrust goes as ``n^2`` a 1 % rpm error is 2 % thrust; propellers in different
condition). The port pod delivers ``(1 + eps) T_1`` and the starboard pod ``(1 - eps) T_2`` of
their thrust states, in the forces above and in the slipstream of the pod foil force below
(``eps = 0`` in seed 001). At zero azimuth it adds the yaw moment ``eps (T_1 + T_2) |y_t|``
(``|y_t|`` = 2.7 m; positive ``eps`` turns the ship to starboard), which grows with thrust as
an azimuth offset's moment does not; at azimuths ``alpha_1``, ``alpha_2`` it adds the surge
and side forces ``eps (T_1 [cos, sin] alpha_1 - T_2 [cos, sin] alpha_2)`` and the yaw moment of
their lever arms (with both pods at one azimuth the forces cancel and the moment is
``eps (T_1 + T_2) |y_t| cos alpha``), and through the slipstream a difference of the pods'
normal forces.

Pod foil lift (the "rudder" loads that seed 001 says eq. 19 leaves out). The pods' struts are
foils; as the MMG rudder (Yasukawa and Yoshimura 2015, eq. 33-42) each makes a force normal to
its chord from the pod's own inflow ``u_p = u_r - y_t r``, ``v_p = v_r + x_t r`` (drift angle
``beta_p = atan2(v_p, u_p)``) ::

    F_N = c_L q sin(a_e),   q = u_p^2 + v_p^2 + k_s 8 T / (rho pi D^2),   a_e = sat(alpha - beta_p)

``F += F_N [-sin alpha, cos alpha, x_t cos alpha + y_t sin alpha]``. ``a_e`` is the angle of
attack limited at the stall angle, ``q`` the dynamic pressure over ``rho / 2`` with a fraction
``k_s`` of the far-wake slipstream of momentum theory. The normal force acts with the thrust's
``T sin(alpha)``, brakes the ship when the pod is swung across the flow (``-F_N sin alpha``)
and, because it depends on ``v_p``, damps sway and yaw like a skeg (``dY/dv = -2 c_L u`` over both
pods, three times the seed's linear sway damping at service speed). The propeller sees the
inflow along the pod's axis, ``u_a = (1 - w)(u_p cos alpha + v_p sin alpha)``
(:func:`pod_thrusts_col`). ``c_L = 0`` by default, which is seed 001's model. Fitted to the
Kongsberg pod FMU table of MCSim_python (one pod, 47 points at 0-6.5 m/s, 150-220 rpm, 0-30 deg,
v 0-2 m/s: ``POD_LIFT_COEFFICIENT_FMU``, ``POD_SLIPSTREAM_FMU``, ``D = 1.9`` m) the form
reproduces the pod's surge and side forces to 2.9 and 2.3 kN RMS (forces up to 116 kN).
``POD_LIFT_COEFFICIENT_THRUSTER_DATA`` is the simpler value implied by its one point (34.3 kN
side force at 5 m/s, 180 rpm, 10 deg, less ``T sin(alpha)``, without slipstream).

Propeller-hull interaction (MMG, Yasukawa and Yoshimura 2015 eq. 25-28): the pods push the hull
with ``(1 - t) T`` (thrust deduction ``t``) and their propellers see the advance speed
``(1 - w) u_r`` (wake fraction ``w``, in :func:`pod_thrust` and the thrust limit); both 0 in
seed 001.

Turning speed loss and cross-flow damping (Fossen 2011 ch. 6.4, Yasukawa and Yoshimura 2015 eq.
9): the surge force gains ``X_vv v_r^2 + X_vr v_r r + X_rr r^2`` (zero in seed 001) and sway and
yaw gain the cross terms of the strip-theory cross-flow drag ::

    Y_cf = -rho/2 T C_cf int |v_r + x r| (v_r + x r) dx,   N_cf = -rho/2 T C_cf int x |..| (..) dx

over the hull (``x`` from the aft to the forward perpendicular) less its pure ``|v|v`` and
``|r|r`` parts, which the seed's quadratic damping ``D_v``, ``D_r`` already holds: the terms
``Y_|v|r``, ``Y_|r|v``, ``N_|v|v``, ``N_|r|v`` ... that couple sway and yaw. ``C_cf = 0`` in
seed 001.

Wave-making resistance (Molland, Turnock and Hudson 2017, ch. 4): the seed's surge drag
``X_u u + X_|u|u |u| u`` grows as ``u^2``; a ship of 34 m at 3.5-6.5 m/s runs at Froude numbers
``Fn = u / sqrt(g L)`` of 0.2-0.36, where the wave resistance coefficient rises about as
``Fn^2``. The term ``R_w = c_w Fn^2 rho/2 S u_r^2 = c_w rho S |u_r| u_r^3 / (2 g L)`` with the
wetted surface ``S`` of Denny and Mumford (``WETTED_SURFACE``) adds it (``c_w = 0`` in seed 001).

State ``[x, y, psi, u, v, r, T_1, T_2, alpha_1, alpha_2]`` in [m, m, rad, m/s, m/s, rad/s, N, N,
rad, rad]; input ``[T_1c, T_2c, alpha_1c, alpha_2c]``. Pod 1 is port (y < 0), pod 2 starboard.

With zero thrust the relative-velocity dynamics are ``M nu_r' + (C_rb + C_a)(nu_r) nu_r +
D nu_r = 0`` for an irrotational current (Fossen 2011 property 8.1 holds for eq. 14), so with a
symmetric ``M`` the kinetic energy relative to the water, ``nu_r^T M nu_r / 2``, never grows.

The compiled per-ship functions here (:func:`rvg_col`, :func:`pod_thrust`,
:func:`pod_thrusts_col`, :func:`pod_thrusts`) take their arrays unchecked: ``p`` must be
:func:`pack_rvg`'s output (or a table of such columns) and ``X`` a block of full states. From
Python, :class:`shipgym.models.ShipModel` checks its arguments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from shipgym.models._jit import param, row_kernel, simd_kernel
from shipgym.models.kinematics import body_current
from shipgym.models.vmath import sincos

RVG_PARAMETER_SETS = ("seed001", "sea_trials")
"""Names of the shipped parameter sets (:meth:`RVGParams.named`)."""
NEWEST_RVG_PARAMETERS = "sea_trials"
"""The newest, validated parameter set: the one the ``-v1`` envs and ``shipgym simulate`` use."""
RVG_STATES = ("x", "y", "psi", "u", "v", "r", "T1", "T2", "alpha1", "alpha2")
RVG_INPUTS = ("T1_c", "T2_c", "alpha1_c", "alpha2_c")
IX, IY, IPSI, IU, IV, IR, IT1, IT2, IA1, IA2 = range(10)

LPP = 33.9  # [m], seed 001 Table 1
DRAUGHT = 2.7  # [m], seed 001 Table 1
VERES_DRAUGHT = 2.786  # [m], the draught of the VERES run behind the damping (RVG_PARAMETERS.md)
BREADTH = 9.6  # [m], seed 001 Table 1
SERVICE_SPEED = 5.144  # [m/s], 10 kn (RVG_PARAMETERS.md)
CG_FORWARD_OF_AP = 15.56  # [m], the body origin (RVG_PARAMETERS.md "Frame and units")
WATER_DENSITY = 1025.0  # [kg/m^3], sea water (the new terms; the seed's damping used 1000)
PROPELLER_DIAMETER = 1.9  # [m], pod propellers (the Kongsberg pod FMU's setting, MCSim_python)
POD_STALL_ANGLE = math.radians(35.0)
"""Angle of attack [rad] beyond which the pod's normal force stops growing. The Kongsberg pod
data show no stall up to 30 deg (their range); low-aspect-ratio rudders stall at 30-40 deg
(Molland and Turnock 2007, ch. 3)."""
POD_LIFT_COEFFICIENT_FMU = 5.22e3
"""``c_L`` [N s^2/m^2] of the least-squares fit of the normal-force form to the Kongsberg pod FMU
table (``scripts/pod_fmu_fit.py``)."""
POD_SLIPSTREAM_FMU = 0.153
"""``k_s`` [-] of the same fit: the fraction of the far-wake slipstream dynamic pressure the
strut sees (the thruster_lift effect keeps it fixed and fits ``c_L``)."""

THRUST_ASYMMETRY_MAX = 0.1
"""Largest ``|eps|`` [-] of the thrust asymmetry: one pod 22 % stronger than the other, a shaft
speed 10 % off the other's at one order (thrust goes as ``n^2``); far beyond a shaft-speed
governor's error (about 1 %), which leaves room for propellers in different condition."""

AZIMUTH_TIME_CONSTANT_RANGE = (0.5, 9.0)
"""Physical range [s] of the pods' azimuth servo time constant ``tau_alpha``. Azimuth drives
slew at about 10 deg/s (the source's rate limit; class rules ask for at least 1.5 rev/min,
9 deg/s, and a swing from one side to the other, +-35 deg, at an average of at least 0.4
rev/min, 2.4 deg/s, at full speed ahead: Lloyd's Register, azimuthing thrusters). A first-order
servo reaches 95 % of that 70 deg swing in ``3 tau_alpha``, so the rule holds up to 9.2 s: the
ceiling. The floor is the trials' 0.5 s sample step, below which a record cannot tell a servo
from none (and the screening replay's 1 s RK4 steps stay stable, ``h / tau_alpha < 2.8``)."""

GRAVITY = 9.81  # [m/s^2]
_DISPLACEMENT_VOLUME = 574_127.69 / WATER_DENSITY  # [m^3], of the seed-001 mass
BLOCK_COEFFICIENT = _DISPLACEMENT_VOLUME / (LPP * BREADTH * DRAUGHT)
"""``C_B`` [-] of the seed-001 displacement on Lpp x B x T (0.64)."""
THRUST_DEDUCTION_HOLTROP = 0.325 * BLOCK_COEFFICIENT - 0.1885 * PROPELLER_DIAMETER / math.sqrt(
    BREADTH * DRAUGHT
)
"""Thrust deduction ``t`` [-] of twin-screw ships by Holtrop and Mennen (1982, eq. for twin
screws: ``t = 0.325 C_B - 0.1885 D / sqrt(B T)``), 0.137 for the Gunnerus. A record without a
thrust or shaft-speed measurement (the Gunnerus trials log the rpm *order*) fixes only the
thrust on the hull, ``T (1 - t)``: ``t`` is then taken from this formula and the thrust level
is identified (``propeller_hull_interaction`` fits the wake fraction)."""
WETTED_SURFACE = 1.7 * LPP * DRAUGHT + _DISPLACEMENT_VOLUME / DRAUGHT
"""Wetted hull surface ``S`` [m^2] by Denny and Mumford's formula ``1.7 L T + V / T`` (363 m^2;
Molland, Turnock and Hudson 2017, ch. 10), the area of the wave-making resistance term."""

#: Gauss-Legendre nodes and weights on [-1, 1] for the cross-flow drag integral over the hull.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)

_D_V = 0.5 * 0.5 * LPP * VERES_DRAUGHT * 1000.0  # 23 611.35, RVG_PARAMETERS.md
#: Yaw quadratic damping ``D_r[2,2]`` [N m s^2] of the seed-001 set. The source writes it as
#: 0.75 D_v L^4 / 64 = 3.6543e8, which has one length too many (N m s^2 * m); the
#: cross-flow-consistent integral D_v L^3 / 32 (sway drag times x|x| over a hull of length L
#: about its middle) is 2.87e7 (``YAW_QUADRATIC_DAMPING_CROSSFLOW``). The seed-001 set keeps the
#: source's *number*: it is what the published MCSim model simulates with. It does not make that
#: model agree with the sea trials: without pod lift the hull is directionally unstable (sway-yaw
#: eigenvalue +0.18 1/s at 5.2 m/s) and turns 2.8 deg/s at 10 deg azimuth (diameter 159 m)
#: against the settled 2.26-2.45 deg/s (223-248 m) of the trials. The sea-trial set
#: (:meth:`RVGParams.sea_trials`) identifies it between the two readings.
YAW_QUADRATIC_DAMPING = 3.6543e8
YAW_QUADRATIC_DAMPING_CROSSFLOW = _D_V * LPP**3 / 32.0

#: Pod foil lift coefficient [N s^2/m^2] implied by the Kongsberg pod data (RVG_PARAMETERS.md):
#: 34.3 kN side force at u = 5 m/s, 180 rpm, 10 deg azimuth, less T sin(alpha) = 35.6 kN x
#: sin(10 deg) from :func:`pod_thrust`, over u^2 sin(10 deg). Not in seed 001 (default 0).
POD_LIFT_COEFFICIENT_THRUSTER_DATA = (
    34.3e3 - 121.7e3 * (0.9**2 - 0.9 * 5.0 / 8.7) * math.sin(math.radians(10.0))
) / (25.0 * math.sin(math.radians(10.0)))


#: Ship parameters identified from the Gunnerus sea trials of 27 Oct 2022 (``python
#: scripts/identify_gunnerus.py``: the identification loop from the seed-001 base names the pod
#: normal force and the wave-making resistance, in that order; whole-record windowed
#: output-error fit, see docs/gunnerus.md). Values not listed are the seed-001 ones. Two
#: calibrated values end at their documented bounds: findings, reported in the README ("Known
#: limitations"), not results.
SEA_TRIALS_VALUES: dict[str, float] = {
    # x0.70 of the Kongsberg table: the thrust on the hull at the rpm order (no thrust deduction
    # in this set); MCSim's manoeuvring model uses C_t 2.2, x0.72
    "bollard_thrust": 8.5063e4,
    "surge_quadratic_damping": 417.9,  # x0.25: the ITTC-57 friction floor of the range
    "sway_linear_damping": 8.9333e4,  # x4.0 (MCSim's calibrated 4-DOF set: x7.5)
    "yaw_linear_damping": 2.6522e6,  # x1.36
    "sway_quadratic_damping": 9.4445e4,  # x4.0 (cross-flow C_D 2.0): the range's ceiling
    "yaw_quadratic_damping": 8.0523e7,  # between 2.87e7 and 3.65e8
    "pod_lift_coefficient": 4105.6,  # 0.79 x the Kongsberg pod FMU fit
    "wave_resistance": 0.027283,  # c_w: C_w = 3.0e-3 at Fn 0.33 (6.1 m/s)
}


def _m3(rows: tuple[tuple[float, float, float], ...]) -> np.ndarray:
    return np.array(rows, dtype=np.float64)


@dataclass(frozen=True, eq=False)
class RVGParams:
    """Gunnerus parameter set (MCSim "revised" set of 2022-10-31; see RVG_PARAMETERS.md).

    Matrices are 3x3 in the order (surge, sway, yaw), SI units (kg, kg m, kg m^2; N s/m, ...).

    Attributes
    ----------
    mass : float
        Ship mass [kg] (ShipX/VERES, 574 127.69 kg).
    yaw_inertia : float
        ``I_z`` [kg m^2] (radius of gyration 0.25 Lpp: 4.1237e7).
    added_mass : numpy.ndarray
        ``M_a`` [kg, kg m, kg m^2]. VERES gives a non-symmetric matrix (off-diagonals -473 277.78
        and -571 162.06); we use the symmetric mean -522 220 in both places, so the model is
        passive (energy never created by the hull) as an ideal-fluid added mass must be.
    linear_damping : numpy.ndarray
        ``D_l`` (0.05/0.2/0.2 x the VERES viscous values).
    surge_quadratic_damping, sway_quadratic_damping, yaw_quadratic_damping : float
        Diagonal entries of ``D_u``, ``D_v``, ``D_r`` (1 671.60; 23 611.35; see
        ``YAW_QUADRATIC_DAMPING`` for the deliberate choice of 3.6543e8).
    pod_x, pod_y : tuple of float
        Pod positions [m] relative to the CG, port pod first (-15.56, -2.7) and (-15.56, 2.7).
    thrust_time_constant, azimuth_time_constant : float
        Actuator time constants [s] (1 s, "a pure guess" in the source). The azimuth one is
        the pods' servo between the logged order and their angle (the identification's
        ``rudder_lag`` effect, within ``AZIMUTH_TIME_CONSTANT_RANGE``).
    azimuth_max_rate : float
        [rad/s] (10 deg/s).
    azimuth_max : float
        Azimuth angle limit [rad] for commands (the pods can turn 360 deg; 180 deg by default).
    bollard_thrust : float
        Per-pod thrust limit at zero speed [N] (121.7 kN at 200 rpm).
    thrust_zero_speed : float
        Relative surge speed [m/s] where the thrust limit falls to zero (8.7 m/s).
    service_thrust : float
        Per-pod thrust [N] that holds the 10 kn service speed in calm water (25 kN).
    pod_lift_coefficient : float
        Foil lift ``c_L`` [N s^2/m^2] per pod; 0 (seed 001 eq. 19) by default, see
        ``POD_LIFT_COEFFICIENT_THRUSTER_DATA``.
    reference_rpm : float
        Shaft speed [rpm] at which ``bollard_thrust`` is reached (200 rpm), for :func:`pod_thrust`.
    pod_stall_angle : float
        Angle of attack [rad] beyond which the pod lift stays at its stall value (30 deg).
    pod_slipstream : float
        Fraction ``k_s`` [-] of the propeller slipstream's far-wake dynamic pressure seen by
        the strut (0 in seed 001; ``POD_SLIPSTREAM_AT_STRUT`` with the lift effect).
    propeller_diameter : float
        Pod propeller diameter ``D`` [m] (for the slipstream).
    thrust_deduction, wake_fraction : float
        ``t`` and ``w`` [-] of the propeller-hull interaction (0 in seed 001).
    surge_vv, surge_vr, surge_rr : float
        ``X_vv`` [kg/m], ``X_vr`` [kg], ``X_rr`` [kg m] of the turning speed loss (0 in seed 001).
    crossflow_coefficient : float
        ``C_cf`` [-], the cross-flow drag coefficient of the sway-yaw cross terms (0 in seed 001).
    wave_resistance : float
        ``c_w`` [-] of the wave-making resistance ``R_w = c_w Fn^2 rho/2 S u_r^2`` with
        ``Fn = u_r / sqrt(g L)`` (0 in seed 001): the resistance that rises faster than ``u^2``
        from Froude number 0.2 on (the trials run at 0.20-0.34).
    azimuth_offset : float
        ``alpha_0`` [rad]: the pods' real azimuth is the order plus this (a misaligned pod zero,
        the identification's ``azimuth_offset`` effect; 0 in seed 001), within +-5 deg.
    thrust_asymmetry : float
        ``eps`` [-]: the port pod delivers ``(1 + eps)`` and the starboard pod ``(1 - eps)`` of
        its thrust state (unequal thrust of the two pods at one order, the identification's
        ``thrust_asymmetry`` effect; 0 in seed 001), within ``+-THRUST_ASYMMETRY_MAX``.
        Positive ``eps`` turns the ship to starboard.
    name : str
        Name of the parameter set (``"seed001"``; :meth:`sea_trials` gives ``"sea_trials"``).
    """

    mass: float = 574_127.69
    yaw_inertia: float = 4.1237e7
    added_mass: np.ndarray = field(
        default_factory=lambda: _m3(
            ((26_599.25, 0.0, 0.0), (0.0, 132_619.44, -522_220.0), (0.0, -522_220.0, 13_320_142.0))
        )
    )
    linear_damping: np.ndarray = field(
        default_factory=lambda: np.diag([1_117.598, 22_288.64, 1_949_686.6])
    )
    surge_quadratic_damping: float = 0.5 * 0.125 * BREADTH * VERES_DRAUGHT * 1000.0
    sway_quadratic_damping: float = _D_V
    yaw_quadratic_damping: float = YAW_QUADRATIC_DAMPING
    pod_x: tuple[float, float] = (-15.56, -15.56)
    pod_y: tuple[float, float] = (-2.7, 2.7)
    thrust_time_constant: float = 1.0
    azimuth_time_constant: float = 1.0
    azimuth_max_rate: float = math.radians(10.0)
    azimuth_max: float = math.pi
    bollard_thrust: float = 121.7e3
    thrust_zero_speed: float = 8.7
    service_thrust: float = 25.0e3
    pod_lift_coefficient: float = 0.0
    reference_rpm: float = 200.0
    pod_stall_angle: float = POD_STALL_ANGLE
    pod_slipstream: float = 0.0
    propeller_diameter: float = PROPELLER_DIAMETER
    thrust_deduction: float = 0.0
    wake_fraction: float = 0.0
    surge_vv: float = 0.0
    surge_vr: float = 0.0
    surge_rr: float = 0.0
    crossflow_coefficient: float = 0.0
    wave_resistance: float = 0.0
    azimuth_offset: float = 0.0
    thrust_asymmetry: float = 0.0
    name: str = "seed001"

    def __post_init__(self) -> None:
        for name in ("added_mass", "linear_damping"):
            value = np.asarray(getattr(self, name), dtype=np.float64)
            if value.shape != (3, 3) or not np.all(np.isfinite(value)):
                raise ValueError(f"RVGParams.{name} must be a finite 3x3 matrix, got {value!r}")
            value = value.copy()
            value.flags.writeable = False
            object.__setattr__(self, name, value)
        for name in (
            "mass",
            "yaw_inertia",
            "thrust_time_constant",
            "azimuth_time_constant",
            "azimuth_max_rate",
            "azimuth_max",
            "bollard_thrust",
            "thrust_zero_speed",
            "reference_rpm",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"RVGParams.{name} must be a finite number > 0, got {value!r}")
        for name in (
            "pod_lift_coefficient",
            "pod_slipstream",
            "crossflow_coefficient",
            "wave_resistance",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"RVGParams.{name} must be a finite number >= 0, got {value!r}")
        value = self.propeller_diameter
        if not (math.isfinite(value) and value > 0):
            raise ValueError(
                f"RVGParams.propeller_diameter must be a finite number > 0, got {value!r}"
            )
        value = self.pod_stall_angle
        if not (math.isfinite(value) and 0.0 < value < 0.5 * math.pi):
            raise ValueError(
                f"RVGParams.pod_stall_angle must be an angle in (0, pi/2) rad, got {value!r}"
            )
        for name in ("thrust_deduction", "wake_fraction"):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0.0 <= value < 1.0):
                raise ValueError(f"RVGParams.{name} must be a fraction in [0, 1), got {value!r}")
        for name in ("surge_vv", "surge_vr", "surge_rr"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"RVGParams.{name} must be finite, got {getattr(self, name)!r}")
        if not (
            math.isfinite(self.thrust_asymmetry)
            and abs(self.thrust_asymmetry) <= THRUST_ASYMMETRY_MAX
        ):
            raise ValueError(
                f"RVGParams.thrust_asymmetry must be within +-{THRUST_ASYMMETRY_MAX:g}, got "
                f"{self.thrust_asymmetry!r}"
            )
        if not (math.isfinite(self.azimuth_offset) and abs(self.azimuth_offset) <= math.radians(5)):
            raise ValueError(
                f"RVGParams.azimuth_offset must be within +-5 deg (+-0.0873 rad), got "
                f"{self.azimuth_offset!r}"
            )

    @classmethod
    def sea_trials(cls) -> RVGParams:
        """The parameter set identified from the Gunnerus sea trials (``SEA_TRIALS_VALUES``).

        Seed 001's model with the effects the identification loop named (pod normal force with
        slipstream fraction ``POD_SLIPSTREAM_FMU``, wave-making resistance) and the calibrated
        guesses of the seed within their documented ranges, the bollard thrust among them
        (README, "The real Gunnerus", and docs/gunnerus.md for the manoeuvres). Its
        ``service_thrust`` is the pod thrust that holds the service speed in this set
        (:meth:`straight_resistance`).
        """
        v = SEA_TRIALS_VALUES
        seed = cls()
        dl = seed.linear_damping.copy()
        dl[1, 1] = v["sway_linear_damping"]
        dl[2, 2] = v["yaw_linear_damping"]
        fitted = cls(
            linear_damping=dl,
            pod_slipstream=POD_SLIPSTREAM_FMU,
            name="sea_trials",
            **{k: val for k, val in v.items() if not k.endswith("_linear_damping")},
        )
        return replace(fitted, service_thrust=fitted.straight_thrust(SERVICE_SPEED))

    def straight_thrust(self, u: float) -> float:
        """Thrust [N] of each pod that holds straight running at ``u`` [m/s] in calm water:
        half the :meth:`straight_resistance`, raised by the thrust deduction."""
        return self.straight_resistance(u) / (2.0 * (1.0 - self.thrust_deduction))

    def straight_resistance(self, u: float) -> float:
        """Surge resistance [N] of straight running at ``u`` [m/s] in calm water: the linear,
        quadratic and wave-making terms of the surge damping."""
        fn2 = u * u / (GRAVITY * LPP)
        return (
            self.linear_damping[0, 0] * u
            + (self.surge_quadratic_damping + self.wave_resistance * fn2 * 0.5 * WATER_DENSITY
               * WETTED_SURFACE) * abs(u) * u
        )  # fmt: skip

    @classmethod
    def named(cls, name: str) -> RVGParams:
        """A shipped parameter set by name: ``"seed001"`` or ``"sea_trials"``."""
        if name == "seed001":
            return cls()
        if name == "sea_trials":
            return cls.sea_trials()
        raise ValueError(
            f"unknown RVG parameter set {name!r}; expected one of {RVG_PARAMETER_SETS}"
        )

    @property
    def rigid_body_mass(self) -> np.ndarray:
        """``M_rb = diag(m, m, I_z)`` (origin at the CG)."""
        return np.diag([self.mass, self.mass, self.yaw_inertia])

    @property
    def mass_matrix(self) -> np.ndarray:
        """``M = M_rb + M_a``."""
        return self.rigid_body_mass + self.added_mass

    def max_thrust(self, relative_surge: float | np.ndarray) -> float | np.ndarray:
        """Per-pod thrust limit [N] at relative surge speed ``u_r`` [m/s] (advance speed
        ``(1 - w) u_r``); a float, or an array for an array of speeds."""
        ua = (1.0 - self.wake_fraction) * relative_surge
        factor = np.minimum(np.maximum(1.0 - ua / self.thrust_zero_speed, 0.0), 1.0)
        limit = self.bollard_thrust * factor
        return limit if np.ndim(limit) else float(limit)


# Parameter-vector layout for the kernel.
P_MINV, P_MA, P_DL = 0, 9, 18
P_MRB = 27  # m11, m22, (m23 + m32) / 2 of M_rb
P_MA_C = 30  # a11, a22, (a23 + a32) / 2 of M_a, for C_a
P_DQ = 33  # D_u[0,0], D_v[1,1], D_r[2,2]
P_POD = 36  # x1, y1, x2, y2
P_INV_TAU_T, P_INV_TAU_A, P_ARATE, P_AMAX, P_TBOLL, P_INV_U0 = (
    40,
    41,
    42,
    43,
    44,
    45,
)  # 1/x saves divisions
P_LIFT, P_INV_NREF = 46, 47
P_SIN_STALL, P_SLIP, P_HULL_T, P_ADV = 48, 49, 50, 51  # sin(stall), k_s 8/(rho pi D^2), 1-t, 1-w
P_XVV, P_XVR, P_XRR, P_CF = 52, 53, 54, 55  # surge terms; rho/2 T C_cf
P_XW = 56  # rho S c_w / (2 g L) of the wave-making resistance
P_CF_X = 57  # 12 Gauss-Legendre stations x [m] along the hull
P_CF_W = P_CF_X + _GL_X.size  # and their weights [m]
P_AOFF = P_CF_W + _GL_X.size  # azimuth offset alpha_0 [rad]
P_TASYM = P_AOFF + 1  # thrust asymmetry eps [-]
P_SIZE = P_TASYM + 1


def pack_rvg(params: RVGParams) -> np.ndarray:
    """Parameter vector that :func:`rvg_col` reads."""
    p = np.zeros(P_SIZE)
    M = params.mass_matrix
    Mrb = params.rigid_body_mass
    Ma = params.added_mass
    p[P_MINV : P_MINV + 9] = np.linalg.inv(M).ravel()
    p[P_MA : P_MA + 9] = Ma.ravel()
    p[P_DL : P_DL + 9] = params.linear_damping.ravel()
    p[P_MRB : P_MRB + 3] = (Mrb[0, 0], Mrb[1, 1], 0.5 * (Mrb[1, 2] + Mrb[2, 1]))
    p[P_MA_C : P_MA_C + 3] = (Ma[0, 0], Ma[1, 1], 0.5 * (Ma[1, 2] + Ma[2, 1]))
    p[P_DQ : P_DQ + 3] = (
        params.surge_quadratic_damping,
        params.sway_quadratic_damping,
        params.yaw_quadratic_damping,
    )
    p[P_POD : P_POD + 4] = (params.pod_x[0], params.pod_y[0], params.pod_x[1], params.pod_y[1])
    p[P_INV_TAU_T] = 1.0 / params.thrust_time_constant
    p[P_INV_TAU_A] = 1.0 / params.azimuth_time_constant
    p[P_ARATE] = params.azimuth_max_rate
    p[P_AMAX] = params.azimuth_max
    p[P_TBOLL] = params.bollard_thrust
    p[P_INV_U0] = 1.0 / params.thrust_zero_speed
    p[P_LIFT] = params.pod_lift_coefficient
    p[P_INV_NREF] = 1.0 / params.reference_rpm
    p[P_SIN_STALL] = math.sin(params.pod_stall_angle)
    p[P_SLIP] = (
        params.pod_slipstream * 8.0 / (WATER_DENSITY * math.pi * params.propeller_diameter**2)
    )
    p[P_HULL_T] = 1.0 - params.thrust_deduction
    p[P_ADV] = 1.0 - params.wake_fraction
    p[P_XVV], p[P_XVR], p[P_XRR] = params.surge_vv, params.surge_vr, params.surge_rr
    p[P_XW] = WATER_DENSITY * WETTED_SURFACE * params.wave_resistance / (2.0 * GRAVITY * LPP)
    half = 0.5 * LPP
    p[P_CF] = 0.5 * WATER_DENSITY * DRAUGHT * params.crossflow_coefficient
    p[P_CF_X : P_CF_X + _GL_X.size] = (LPP - CG_FORWARD_OF_AP - half) + half * _GL_X
    p[P_CF_W : P_CF_W + _GL_X.size] = half * _GL_W
    p[P_AOFF] = params.azimuth_offset
    p[P_TASYM] = params.thrust_asymmetry
    return p


@simd_kernel
def pod_thrust(rpm, ur, p, b=0):
    """Propeller law: thrust [N] of one pod at shaft speed ``rpm`` and relative surge ``ur``.

    ``T = T_bollard (s^2 - s (1 - w) u_r / u_0)``, ``s = rpm / n_ref``, floored at 0 (module
    docstring); ``ur`` is the inflow along the pod's axis (:func:`pod_thrusts_col`), which straight
    ahead is the relative surge speed. ``p`` and ``b`` as in :func:`rvg_col` (``p`` the packed
    parameters, or a table with a column per ship, ``b`` the ship).
    """
    s = abs(rpm) * param(p, P_INV_NREF, b)
    adv = param(p, P_ADV, b)
    return max(param(p, P_TBOLL, b) * (s * s - s * adv * ur * param(p, P_INV_U0, b)), 0.0)


@simd_kernel
def pod_thrusts_col(rpm, X, C, p, b):
    """Thrusts [N] of both pods of ship ``b`` of a block (``X`` states x ships, ``C``
    north/east current x ships, ``p`` as in :func:`rvg_col`) at shaft speed ``rpm``.

    The propeller law :func:`pod_thrust` at each pod's axial inflow ``u_p cos alpha + v_p sin
    alpha`` (module docstring), before the wake fraction. Straight-line code with the sine and
    cosine of :mod:`shipgym.models.vmath`, so that a loop over the ships of a block compiles to
    SIMD code.
    """
    sn, cs = sincos(X[IPSI, b])
    uc, vc = body_current((C[0, b], C[1, b]), cs, sn)
    ur = X[IU, b] - uc
    vr = X[IV, b] - vc
    r = X[IR, b]
    sa1, ca1 = sincos(X[IA1, b])
    sa2, ca2 = sincos(X[IA2, b])
    in1 = (ur - param(p, P_POD + 1, b) * r) * ca1 + (vr + param(p, P_POD, b) * r) * sa1
    in2 = (ur - param(p, P_POD + 3, b) * r) * ca2 + (vr + param(p, P_POD + 2, b) * r) * sa2
    return pod_thrust(rpm, in1, p, b), pod_thrust(rpm, in2, p, b)


@row_kernel
def pod_thrusts(rpm, x, c, p):
    """:func:`pod_thrusts_col` of one ship: state ``x`` (1-D), current ``c = (V_n, V_e)``."""
    X = np.empty((x.shape[0], 1))
    for j in range(x.shape[0]):
        X[j, 0] = x[j]
    C = np.empty((2, 1))
    C[0, 0] = c[0]
    C[1, 0] = c[1]
    return pod_thrusts_col(rpm, X, C, p, 0)


@simd_kernel
def rvg_col(X, U, p, C, K, b):
    """RVG 3-DOF derivative (seed 001 eq. 5-20) of ship ``b`` of a block, written into ``K``.

    ``X`` (states x ships), ``U`` (inputs x ships), ``C`` (disturbances x ships: current north
    and east, then the seaway's surge and sway force [N] and yaw moment [N m] about the origin,
    :mod:`shipgym.models.seaway`) and ``K``
    hold a block of ships column by column (:func:`shipgym.models.integrate.rk4_block`); one
    ship is a block of one. ``p`` is :func:`pack_rvg`'s vector, shared by the block, or a table
    of such vectors with a column per ship (:func:`shipgym.models._jit.param`). The function is
    straight-line arithmetic, its sines, cosines and arctangents those of
    :mod:`shipgym.models.vmath`, so a loop over the ships of a block compiles to SIMD code. The
    terms that are zero in seed 001 (pod lift, turning speed loss, wave resistance) are computed
    whatever their coefficient; the cross-flow integral, the one term with a loop of its own, is
    added by :func:`rvg_crossflow_col` after this function when its coefficient is not zero
    (``block_rhs`` calls both), so that this loop stays straight-line code.
    """
    sn, cs = sincos(X[IPSI, b])
    uu = X[IU, b]
    vv = X[IV, b]
    r = X[IR, b]
    # eq. (8)-(10)
    cn = C[0, b]
    ce = C[1, b]
    uc = cn * cs + ce * sn
    vc = -cn * sn + ce * cs
    ur = uu - uc
    vr = vv - vc
    # eq. (19)-(20), summed over both pods
    sa1, ca1 = sincos(X[IA1, b])
    sa2, ca2 = sincos(X[IA2, b])
    # the thrust the pods deliver: port (1 + eps), starboard (1 - eps) of their thrust state
    eps = param(p, P_TASYM, b)
    th1 = X[IT1, b] * (1.0 + eps)
    th2 = X[IT2, b] * (1.0 - eps)
    x1, y1, x2, y2 = (
        param(p, P_POD, b),
        param(p, P_POD + 1, b),
        param(p, P_POD + 2, b),
        param(p, P_POD + 3, b),
    )
    t1 = th1 * param(p, P_HULL_T, b)  # thrust on the hull, (1 - t) T
    t2 = th2 * param(p, P_HULL_T, b)
    # the pods' forces plus the seaway's load (wind, wave drift; :mod:`shipgym.models.seaway`)
    fx = t1 * ca1 + t2 * ca2 + C[2, b]
    fy = t1 * sa1 + t2 * sa2 + C[3, b]
    fn = t1 * (-y1 * ca1 + x1 * sa1) + t2 * (-y2 * ca2 + x2 * sa2) + C[4, b]
    # pod foil normal force from each pod's own inflow (module docstring; zero in seed 001)
    lift, slip, sin_stall = param(p, P_LIFT, b), param(p, P_SLIP, b), param(p, P_SIN_STALL, b)
    n1 = lift * _pod_normal(ur - y1 * r, vr + x1 * r, sa1, ca1, th1, slip, sin_stall)
    n2 = lift * _pod_normal(ur - y2 * r, vr + x2 * r, sa2, ca2, th2, slip, sin_stall)
    fx -= n1 * sa1 + n2 * sa2
    fy += n1 * ca1 + n2 * ca2
    fn += n1 * (x1 * ca1 + y1 * sa1) + n2 * (x2 * ca2 + y2 * sa2)
    # eq. (14): C_rb(nu) nu and C_a(nu_r) nu_r
    m11, m22, m23 = param(p, P_MRB, b), param(p, P_MRB + 1, b), param(p, P_MRB + 2, b)
    a11, a22, a23 = param(p, P_MA_C, b), param(p, P_MA_C + 1, b), param(p, P_MA_C + 2, b)
    c_rb0 = -(m22 * vv + m23 * r) * r
    c_rb1 = m11 * uu * r
    c_rb2 = (m22 * vv + m23 * r) * uu - m11 * uu * vv
    c_a0 = -(a22 * vr + a23 * r) * r
    c_a1 = a11 * ur * r
    c_a2 = (a22 * vr + a23 * r) * ur - a11 * ur * vr
    # eq. (15): D(nu_r) nu_r
    d0 = (
        param(p, P_DL, b) * ur
        + param(p, P_DL + 1, b) * vr
        + param(p, P_DL + 2, b) * r
        + param(p, P_DQ, b) * abs(ur) * ur
    )
    d1 = (
        param(p, P_DL + 3, b) * ur
        + param(p, P_DL + 4, b) * vr
        + param(p, P_DL + 5, b) * r
        + param(p, P_DQ + 1, b) * abs(vr) * vr
    )
    d2 = (
        param(p, P_DL + 6, b) * ur
        + param(p, P_DL + 7, b) * vr
        + param(p, P_DL + 8, b) * r
        + param(p, P_DQ + 2, b) * abs(r) * r
    )
    # turning speed loss X_vv v^2 + X_vr v r + X_rr r^2 (zero in seed 001)
    d0 -= param(p, P_XVV, b) * vr * vr + param(p, P_XVR, b) * vr * r + param(p, P_XRR, b) * r * r
    # wave-making resistance c_w Fn^2 rho/2 S |u_r| u_r (zero in seed 001)
    d0 += param(p, P_XW, b) * ur * ur * abs(ur) * ur
    # sway-yaw cross terms of the cross-flow drag integral (zero in seed 001)
    # the sway-yaw cross terms of the cross-flow drag: rvg_crossflow_col, when not zero
    # eq. (9): nu_c' = [r v_c, -r u_c, 0]; M_a nu_c'
    ncd0 = r * vc
    ncd1 = -r * uc
    ma0 = param(p, P_MA, b) * ncd0 + param(p, P_MA + 1, b) * ncd1
    ma1 = param(p, P_MA + 3, b) * ncd0 + param(p, P_MA + 4, b) * ncd1
    ma2 = param(p, P_MA + 6, b) * ncd0 + param(p, P_MA + 7, b) * ncd1
    # eq. (12)
    b0 = fx - c_rb0 - c_a0 - d0 + ma0
    b1 = fy - c_rb1 - c_a1 - d1 + ma1
    b2 = fn - c_rb2 - c_a2 - d2 + ma2
    du = param(p, P_MINV, b) * b0 + param(p, P_MINV + 1, b) * b1 + param(p, P_MINV + 2, b) * b2
    dv = param(p, P_MINV + 3, b) * b0 + param(p, P_MINV + 4, b) * b1 + param(p, P_MINV + 5, b) * b2
    dr = param(p, P_MINV + 6, b) * b0 + param(p, P_MINV + 7, b) * b1 + param(p, P_MINV + 8, b) * b2
    # first-order pod thrust and azimuth dynamics with limits (eq. 18)
    tmax = param(p, P_TBOLL, b) * min(
        max(1.0 - param(p, P_ADV, b) * ur * param(p, P_INV_U0, b), 0.0), 1.0
    )
    amax = param(p, P_AMAX, b)
    rate = param(p, P_ARATE, b)
    inv_tau_t = param(p, P_INV_TAU_T, b)
    inv_tau_a = param(p, P_INV_TAU_A, b)
    dt1 = (min(max(U[0, b], 0.0), tmax) - X[IT1, b]) * inv_tau_t
    dt2 = (min(max(U[1, b], 0.0), tmax) - X[IT2, b]) * inv_tau_t
    aoff = param(p, P_AOFF, b)  # the pods turn to the order plus their offset
    da1 = min(max((min(max(U[2, b], -amax), amax) + aoff - X[IA1, b]) * inv_tau_a, -rate), rate)
    da2 = min(max((min(max(U[3, b], -amax), amax) + aoff - X[IA2, b]) * inv_tau_a, -rate), rate)
    # every write after every read (the loop over the ships then compiles to SIMD code)
    K[IX, b] = cs * uu - sn * vv  # eq. (6)
    K[IY, b] = sn * uu + cs * vv
    K[IPSI, b] = r
    K[IU, b] = du
    K[IV, b] = dv
    K[IR, b] = dr
    K[IT1, b] = dt1
    K[IT2, b] = dt2
    K[IA1, b] = da1
    K[IA2, b] = da2


@row_kernel
def _pod_normal(up, vp, sa, ca, thrust, slip, sin_stall):
    """Foil normal force per unit lift coefficient of a pod at azimuth ``alpha`` (``sa``, ``ca``)
    in the inflow ``(up, vp)`` [m/s] at the pod, with its slipstream at ``thrust`` (``slip`` the
    slipstream factor ``k_s``, ``sin_stall`` the sine of the stall angle, which is below 90 deg).

    ``q sin(clip(alpha - beta_p, +-stall))`` with ``q = |v_p|^2 + k_s max(T, 0)`` and the
    inflow angle ``beta_p``; a flow from astern turns the foil's angle by pi (module
    docstring). Zero without inflow.

    No angle is formed: the sine ``s`` and cosine ``c`` of ``alpha - beta_p`` follow from the
    inflow direction, and for a stall angle below 90 deg the stalled, turned sine is ``s`` (flow
    from ahead, ``c >= 0``) or ``-s`` (from astern, the angle turned by pi) while
    ``|s| < sin(stall)``, and ``sin(stall)`` with the sign of ``s`` beyond. Straight-line code
    (one square root, one division, selects), for SIMD.
    """
    vv2 = up * up + vp * vp
    q = vv2 + slip * max(thrust, 0.0)
    moving = vv2 > 0.0  # without inflow beta_p = 0
    inv = 1.0 / math.sqrt(vv2) if moving else 1.0
    cb = up * inv if moving else 1.0
    sb = vp * inv if moving else 0.0
    s = sa * cb - ca * sb  # sin(alpha - beta_p)
    c = ca * cb + sa * sb  # cos(alpha - beta_p)
    turned = s if c >= 0.0 else -s
    s_aoa = turned if abs(s) < sin_stall else math.copysign(sin_stall, s)
    return q * s_aoa if q > 0.0 else 0.0


@simd_kernel
def rvg_crossflow_col(X, p, C, K, b):
    """Add the sway-yaw cross terms of the cross-flow drag integral (zero in seed 001) to the
    derivative ``K`` of ship ``b`` that :func:`rvg_col` wrote.

    ``Y_cf = c int (|v_r + x r| (v_r + x r) - |v_r| v_r - |x r| x r) dx``, ``N_cf`` the same
    weighted by ``x``, over Gauss-Legendre stations along the hull; they enter the derivative
    through ``M^-1`` as the other damping forces do (eq. 12, 15).
    """
    sn, cs = sincos(X[IPSI, b])
    r = X[IR, b]
    vr = X[IV, b] - (-C[0, b] * sn + C[1, b] * cs)
    cf_y = 0.0
    cf_n = 0.0
    vq = abs(vr) * vr
    for j in range(P_CF_W - P_CF_X):
        xs = param(p, P_CF_X + j, b)
        xr = xs * r
        s = vr + xr
        f = (abs(s) * s - vq - abs(xr) * xr) * param(p, P_CF_W + j, b)
        cf_y += f
        cf_n += f * xs
    dy = param(p, P_CF, b) * cf_y
    dn = param(p, P_CF, b) * cf_n
    du = param(p, P_MINV + 1, b) * dy + param(p, P_MINV + 2, b) * dn
    dv = param(p, P_MINV + 4, b) * dy + param(p, P_MINV + 5, b) * dn
    dr = param(p, P_MINV + 7, b) * dy + param(p, P_MINV + 8, b) * dn
    K[IU, b] -= du
    K[IV, b] -= dv
    K[IR, b] -= dr

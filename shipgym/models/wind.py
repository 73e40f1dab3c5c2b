"""Wind: gusts from a standard gust spectrum, the apparent wind and the wind loads on a ship.

**Blendermann (1994)** wind loads on a ship's above-water hull and superstructure.
W. Blendermann, "Parameter identification of wind loads on ships", J. Wind Eng. Ind.
Aerodyn. 51 (1994) 339-351, as given by T. I. Fossen, *Handbook of Marine Craft Hydrodynamics
and Motion Control*, 2nd ed., Wiley 2021, section 10.1, and implemented in Fossen's Marine
Systems Simulator (MSS, ``blendermann94.m``, whose table of coefficients per ship type gives
the rows of :data:`BLENDERMANN_COEFFICIENTS`). With the apparent wind of speed ``V_a``
coming from the angle ``g`` off the bow (the project's convention, :mod:`shipgym.sysid.data`:
``g = 0`` head wind, ``+pi/2`` wind from starboard), ``rho_a`` the density of air, ``A_F``,
``A_L`` the frontal and lateral projected wind areas, ``L_oa`` the length overall and ``s_L``
the horizontal distance of the centroid of ``A_L`` forward of midship::

    X_w = 1/2 rho_a V_a^2 A_F C_X,   Y_w = 1/2 rho_a V_a^2 A_L C_Y,
    N_w = 1/2 rho_a V_a^2 A_L L_oa C_N
    C_X = -C_Dl,AF cos(g) / D,   C_Y = -C_Dt sin(g) / D,
    C_N = (s_L / L_oa - 0.18 (|g| - pi/2)) C_Y,
    D = 1 - delta/2 (1 - C_Dl / C_Dt) sin^2(2 g),   C_Dl = C_Dl,AF A_F / A_L,

with ``C_Dl,AF`` its bow value for ``|g| <= pi/2`` and its stern value beyond; ``X`` forward,
``Y`` to starboard, ``N`` clockwise about midship. Fossen's relative wind angle is ``-g``
(``gamma_rw = -atan2(v_rw, u_rw)`` of the ship's velocity relative to the air), so his ``C_Y =
C_Dt sin(gamma_rw)`` is the ``C_Y`` above: the wind pushes the ship to leeward. His yaw
coefficient is written for the port half plane, ``gamma_rw`` in ``[0, pi]``; the ``|g|`` above
is its mirror image for winds from starboard, so that ``N_w`` is odd in ``g``: a wind on the
bow turns the bow to leeward, one on the quarter the stern. Roll (Blendermann's ``kappa``) is
not modelled. :data:`GUNNERUS_WIND` holds the R/V Gunnerus's (estimated) wind data for the
research-vessel row.

**Isherwood (1972)** wind loads on merchant ships (:func:`isherwood_load`). R. M. Isherwood,
"Wind resistance of merchant ships", Trans. RINA 115 (1973) 327-338: multiple regressions of
wind-tunnel tests, tabulated at 10 deg steps of the wind angle ``0 ... 180 deg`` (the tables
of :data:`ISHERWOOD_CX`, :data:`ISHERWOOD_CY`, :data:`ISHERWOOD_CN`; the same numbers as
MSS ``isherwood72.m`` and Fossen 2021 section 10.1). With ``|g|`` in degrees, the coefficients
interpolated linearly between the tabulated angles, and the ship's length overall ``L_oa``,
beam ``B``, lateral and frontal projected areas ``A_L``, ``A_F``, lateral area of the
superstructure ``A_SS``, perimeter ``S`` of the lateral projection (less the waterline and
slender bodies such as masts), distance ``C`` of the centroid of ``A_L`` from the bow and
number ``M`` of distinct groups of masts or king posts::

    R_X = A0 + A1 2 A_L / L_oa^2 + A2 2 A_F / B^2 + A3 L_oa / B + A4 S / L_oa
          + A5 C / L_oa + A6 M
    R_Y = B0 + B1 2 A_L / L_oa^2 + B2 2 A_F / B^2 + B3 L_oa / B + B4 S / L_oa
          + B5 C / L_oa + B6 A_SS / A_L
    R_N = C0 + C1 2 A_L / L_oa^2 + C2 2 A_F / B^2 + C3 L_oa / B + C4 S / L_oa
          + C5 C / L_oa
    C_X = -R_X,   C_Y = -sign(g) R_Y,   C_N = -sign(g) R_N,

and ``X_w``, ``Y_w``, ``N_w`` as above (``N_w`` about midship, ``A_F`` the frontal area of the
``X_w`` formula). Isherwood's ``R_X`` is a resistance (positive aft in a head wind), his
``R_Y``, ``R_N`` are positive for a wind on the port side pushing the ship to starboard and
turning its bow to starboard (leeward); mirrored to the project's signs here (the wind from
starboard, ``g > 0``, pushes to port): ``X_w`` even in ``g``, ``Y_w`` and ``N_w`` odd.
:data:`MARINER_WIND` holds the (estimated) above-water particulars of the Mariner class cargo
ship of the Nomoto family.

**Nomoto family** (:func:`mariner_nomoto_wind`). The Nomoto models have no sway and no
moment equation: ``T r' + r = K delta`` is the yaw equation ``(I_z - N_rdot) r' - N_r r =
N_delta delta`` divided by ``-N_r``. A wind moment ``N_w`` on its right enters as the rudder
angle that makes the same moment, the *equivalent rudder angle* ``delta_w = N_w / N_delta``:
``T r' + r = K (delta + delta_w)`` (and likewise in the second-order and nonlinear models,
where ``delta`` appears). The Mariner's ``N_delta = N'_delta 1/2 rho U^2 L^3`` is its
nondimensional rudder moment derivative ``|N'_delta| = 139e-5`` of the prime system (forces
over ``1/2 rho U^2 L^2``, moments over ``1/2 rho U^2 L^3``, ``rho`` the density of sea water,
``U`` the ship's speed, ``L = 160.93 m``; M. S. Chislett and J. Stroem-Tejsen, "Planar motion
mechanism tests and full-scale steering and manoeuvring predictions for a Mariner class
vessel", Hydro- og Aerodynamisk Laboratorium, Lyngby, Report Hy-5, 1965, as tabulated in MSS
``mariner.m``; positive: a positive rudder turns the ship to starboard, the Nomoto sign). The
wind's sway force makes the ship drift to leeward; without a sway equation it enters the
kinematics as the steady leeway ``v_w = Y_w / (-Y_v)``, ``Y_v = Y'_v 1/2 rho U L^2`` with
``Y'_v = -1160e-5`` (same source), a sway velocity added to the ship's over ground
(``x' += -v_w sin(psi)``, ``y' += v_w cos(psi)``). Both neglect the sway-yaw coupling of the
wind's loads (the yaw moment of the leeway and the sway force of ``delta_w``): first-order
estimates for a ship at speed, as the Nomoto models are.

**Gusts** (:func:`wind_gusts`): the wind speed fluctuates about its mean with a standard gust
spectrum, one-sided in the frequency ``f`` [Hz], ``S(f)`` in ``(m/s)^2/Hz`` (the spectrum in
``omega = 2 pi f`` [rad/s] is ``S(omega / (2 pi)) / (2 pi)``), ``U_10`` the 1-hour mean wind
speed 10 m above the sea:

* NORSOK N-003 (2007), *Actions and action effects* (the Froya spectrum; also DNV-RP-C205
  and Fossen 2021 section 10.1.3), :func:`norsok_spectrum`, at height ``z``::

      S(f) = 320 (U_10 / 10)^2 (z / 10)^0.45 / (1 + x^n)^(5 / (3 n)),
      x = 172 f (z / 10)^(2/3) (U_10 / 10)^(-3/4),   n = 0.468

  (``U_10`` in m/s, ``z`` in m, ``f`` in Hz).
* Harris (1971), R. I. Harris, "The nature of the wind", Proc. Seminar on the Modern Design of
  Wind-Sensitive Structures, CIRIA, London 1971, in the form of Fossen 2011 (*Handbook*, 1st
  ed., section 8.1.2) and API RP 2A, :func:`harris_spectrum`::

      S(f) = 4 kappa L U_10 / (2 + x^2)^(5/6),   x = L f / U_10,

  with the surface drag coefficient ``kappa = 0.0026`` and the length scale ``L = 1800 m``.

A record is a sum of harmonics with random phases (Fossen 2021 section 10.1.3, as MSS and
Shinozuka's spectral representation): ``V(t) = U + sum_k a_k cos(2 pi f_k t + phi_k)``,
``a_k = sqrt(2 S(f_k) df_k)``, over bins whose edges are spaced logarithmically from
``1 / duration`` (slower changes are part of the record's mean) to the Nyquist frequency
``1 / (2 dt)``, each harmonic at a frequency drawn uniformly inside its bin (so the harmonics
are not commensurate and the record does not repeat itself) and a phase drawn uniformly in
``[0, 2 pi)``, both from :func:`numpy.random.default_rng` of the seed. The mean
of the harmonics over the record is removed, so that the record's mean is ``U`` exactly.

The apparent wind at the ship (:func:`apparent_wind`) is the true wind, constant over the
earth, less the ship's velocity over ground; the yaw rate's share is neglected.

The loads are compiled per-ship building blocks that model kernels inline
(:mod:`shipgym.models.mmg`), like :mod:`shipgym.models.kinematics`: they take their arguments
unchecked. From Python, :class:`shipgym.models.MMGParams` checks the wind and the ship's wind
data before any kernel sees them, the ships' wind data (:class:`IsherwoodShip`,
:class:`BlendermannShip`) check themselves, and the gust functions check their arguments.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import astuple, dataclass
from typing import Any

import numpy as np

from shipgym.models._checks import count, positive_number, real_array, require_finite, step_size
from shipgym.models._jit import row_kernel

__all__ = [
    "BLENDERMANN_COEFFICIENTS",
    "GUNNERUS_WIND",
    "GUST_SPECTRA",
    "ISHERWOOD_CN",
    "ISHERWOOD_CX",
    "ISHERWOOD_CY",
    "MARINER_WIND",
    "RHO_AIR",
    "BlendermannShip",
    "IsherwoodShip",
    "apparent_wind",
    "blendermann_load",
    "harris_spectrum",
    "isherwood_coefficients",
    "isherwood_load",
    "mariner_nomoto_wind",
    "norsok_spectrum",
    "wind_gusts",
]

RHO_AIR = 1.224
"""Density of air [kg/m^3] (the value of MSS ``blendermann94.m``)."""

BLENDERMANN_COEFFICIENTS: dict[str, tuple[float, float, float, float]] = {
    "tanker_loaded": (0.70, 0.90, 0.55, 0.40),
    "tanker_ballast": (0.70, 0.75, 0.55, 0.40),
    "research_vessel": (0.85, 0.55, 0.65, 0.60),
}
"""Blendermann's coefficients ``(C_Dt, C_Dl,AF bow, C_Dl,AF stern, delta)`` by ship type
(Blendermann 1994; Fossen 2021, section 10.1; MSS ``blendermann94.m``,
ship types 15 and 16 for the tankers, 13 for the research vessel)."""


@row_kernel
def apparent_wind(
    speed: float, direction: float, psi: float, u: float, v: float
) -> tuple[float, float]:
    """Apparent wind at a ship moving through a constant true wind.

    Parameters
    ----------
    speed : float
        True wind speed [m/s].
    direction : float
        Direction the true wind comes FROM [rad], clockwise from north (the earth x axis).
    psi : float
        Heading [rad], clockwise from north.
    u, v : float
        Surge and sway velocity over ground [m/s] (body axes, ``v`` to starboard).

    Returns
    -------
    speed, angle : float
        Apparent wind speed [m/s] and the angle it comes from [rad], clockwise from the bow in
        ``[-pi, pi]`` (``0``: from ahead, ``+pi/2``: from starboard).
    """
    # velocity of the air over ground (blowing towards ``direction + pi``), in body axes,
    # less the ship's own velocity
    wn = -speed * math.cos(direction)
    we = -speed * math.sin(direction)
    cs = math.cos(psi)
    sn = math.sin(psi)
    ax = wn * cs + we * sn - u
    ay = -wn * sn + we * cs - v
    return math.hypot(ax, ay), math.atan2(-ay, -ax)


@row_kernel
def blendermann_load(
    speed: float,
    angle: float,
    frontal_area: float,
    lateral_area: float,
    centre: float,
    length_overall: float,
    cdt: float,
    cdl_bow: float,
    cdl_stern: float,
    delta: float,
) -> tuple[float, float, float]:
    """Blendermann's wind force and moment on a ship (module docstring).

    Parameters
    ----------
    speed : float
        Apparent wind speed ``V_a`` [m/s].
    angle : float
        Apparent wind angle ``g`` [rad]: the direction the wind comes from, clockwise from the
        bow (``0`` head wind, ``+pi/2`` from starboard), in ``[-pi, pi]``.
    frontal_area, lateral_area : float
        Frontal and lateral projected wind areas ``A_F``, ``A_L`` [m^2].
    centre : float
        ``s_L`` [m]: horizontal distance of the centroid of ``A_L`` forward of midship.
    length_overall : float
        ``L_oa`` [m].
    cdt, cdl_bow, cdl_stern, delta : float
        Blendermann's coefficients of the ship type (:data:`BLENDERMANN_COEFFICIENTS`).

    Returns
    -------
    X, Y, N : float
        Surge force (forward) and sway force (to starboard) [N], yaw moment about midship
        (clockwise) [N m], of air of density :data:`RHO_AIR`.
    """
    q = 0.5 * RHO_AIR * speed * speed
    g = abs(angle)
    cdl_af = cdl_bow if g <= 0.5 * math.pi else cdl_stern
    cdl = cdl_af * frontal_area / lateral_area
    s2 = math.sin(2.0 * angle)
    den = 1.0 - 0.5 * delta * (1.0 - cdl / cdt) * s2 * s2
    cx = -cdl_af * math.cos(angle) / den
    cy = -cdt * math.sin(angle) / den
    cn = (centre / length_overall - 0.18 * (g - 0.5 * math.pi)) * cy
    return (
        q * frontal_area * cx,
        q * lateral_area * cy,
        q * lateral_area * length_overall * cn,
    )


# ---------------------------------------------------------------------------------------------
# Isherwood (1972)

ISHERWOOD_CX = np.array(
    [
        [2.152, -5.00, 0.243, -0.164, 0.0, 0.0, 0.0],
        [1.714, -3.33, 0.145, -0.121, 0.0, 0.0, 0.0],
        [1.818, -3.97, 0.211, -0.143, 0.0, 0.0, 0.033],
        [1.965, -4.81, 0.243, -0.154, 0.0, 0.0, 0.041],
        [2.333, -5.99, 0.247, -0.190, 0.0, 0.0, 0.042],
        [1.726, -6.54, 0.189, -0.173, 0.348, 0.0, 0.048],
        [0.913, -4.68, 0.0, -0.104, 0.482, 0.0, 0.052],
        [0.457, -2.88, 0.0, -0.068, 0.346, 0.0, 0.043],
        [0.341, -0.91, 0.0, -0.031, 0.0, 0.0, 0.032],
        [0.355, 0.0, 0.0, 0.0, -0.247, 0.0, 0.018],
        [0.601, 0.0, 0.0, 0.0, -0.372, 0.0, -0.020],
        [0.651, 1.29, 0.0, 0.0, -0.582, 0.0, -0.031],
        [0.564, 2.54, 0.0, 0.0, -0.748, 0.0, -0.024],
        [-0.142, 3.58, 0.0, 0.047, -0.700, 0.0, -0.028],
        [-0.677, 3.64, 0.0, 0.069, -0.529, 0.0, -0.032],
        [-0.723, 3.14, 0.0, 0.064, -0.475, 0.0, -0.032],
        [-2.148, 2.56, 0.0, 0.081, 0.0, 1.27, -0.027],
        [-2.707, 3.97, -0.175, 0.126, 0.0, 1.81, 0.0],
        [-2.529, 3.76, -0.174, 0.128, 0.0, 1.55, 0.0],
    ]
)
"""Isherwood's (1972) coefficients ``A0`` to ``A6`` of the longitudinal force, a row per wind angle
``0, 10, ..., 180 deg`` (R. M. Isherwood, "Wind resistance of merchant ships", Trans. RINA 115
(1973) 327-338, table of ``A_i``; the numbers as given in MSS ``isherwood72.m``; blanks of the
table are 0)."""

ISHERWOOD_CY = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.096, 0.22, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.176, 0.71, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.225, 1.38, 0.0, 0.023, 0.0, -0.29, 0.0],
        [0.329, 1.82, 0.0, 0.043, 0.0, -0.59, 0.0],
        [1.164, 1.26, 0.121, 0.0, -0.242, -0.95, 0.0],
        [1.163, 0.96, 0.101, 0.0, -0.177, -0.88, 0.0],
        [0.916, 0.53, 0.069, 0.0, 0.0, -0.65, 0.0],
        [0.844, 0.55, 0.082, 0.0, 0.0, -0.54, 0.0],
        [0.889, 0.0, 0.138, 0.0, 0.0, -0.66, 0.0],
        [0.799, 0.0, 0.155, 0.0, 0.0, -0.55, 0.0],
        [0.797, 0.0, 0.151, 0.0, 0.0, -0.55, 0.0],
        [0.996, 0.0, 0.184, 0.0, -0.212, -0.66, 0.34],
        [1.014, 0.0, 0.191, 0.0, -0.280, -0.69, 0.44],
        [0.784, 0.0, 0.166, 0.0, -0.209, -0.53, 0.38],
        [0.536, 0.0, 0.176, -0.029, -0.163, 0.0, 0.27],
        [0.251, 0.0, 0.106, -0.022, 0.0, 0.0, 0.0],
        [0.125, 0.0, 0.046, -0.012, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ]
)
"""Isherwood's (1972) coefficients ``B0`` to ``B6`` of the lateral force, a row per wind angle
``0, 10, ..., 180 deg`` (Isherwood 1973, table of ``B_i``; as in MSS ``isherwood72.m``)."""

ISHERWOOD_CN = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0596, 0.061, 0.0, 0.0, 0.0, -0.074],
        [0.1106, 0.204, 0.0, 0.0, 0.0, -0.170],
        [0.2258, 0.245, 0.0, 0.0, 0.0, -0.380],
        [0.2017, 0.457, 0.0, 0.0067, 0.0, -0.472],
        [0.1759, 0.573, 0.0, 0.0118, 0.0, -0.523],
        [0.1925, 0.480, 0.0, 0.0115, 0.0, -0.546],
        [0.2133, 0.315, 0.0, 0.0081, 0.0, -0.526],
        [0.1827, 0.254, 0.0, 0.0053, 0.0, -0.443],
        [0.2627, 0.0, 0.0, 0.0, 0.0, -0.508],
        [0.2102, 0.0, -0.0195, 0.0, 0.0335, -0.492],
        [0.1567, 0.0, -0.0258, 0.0, 0.0497, -0.457],
        [0.0801, 0.0, -0.0311, 0.0, 0.0740, -0.396],
        [-0.0189, 0.0, -0.0488, 0.0101, 0.1128, -0.420],
        [0.0256, 0.0, -0.0422, 0.0100, 0.0889, -0.463],
        [0.0552, 0.0, -0.0381, 0.0109, 0.0689, -0.476],
        [0.0881, 0.0, -0.0306, 0.0091, 0.0366, -0.415],
        [0.0851, 0.0, -0.0122, 0.0025, 0.0, -0.220],
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ]
)
"""Isherwood's (1972) coefficients ``C0`` to ``C5`` of the yaw moment, a row per wind angle
``0, 10, ..., 180 deg`` (Isherwood 1973, table of ``C_i``; as in MSS ``isherwood72.m``)."""

_ISHERWOOD_STEP = math.radians(10.0)


@row_kernel
def isherwood_coefficients(
    angle: float,
    length_overall: float,
    beam: float,
    lateral_area: float,
    frontal_area: float,
    superstructure_area: float,
    perimeter: float,
    centroid: float,
    masts: float,
) -> tuple[float, float, float]:
    """Isherwood's wind coefficients ``C_X``, ``C_Y``, ``C_N`` (module docstring).

    Parameters
    ----------
    angle : float
        Apparent wind angle ``g`` [rad], clockwise from the bow (``0`` head wind, ``+pi/2``
        from starboard), in ``[-pi, pi]``.
    length_overall, beam : float
        ``L_oa``, ``B`` [m].
    lateral_area, frontal_area, superstructure_area : float
        ``A_L``, ``A_F``, ``A_SS`` [m^2].
    perimeter : float
        ``S`` [m]: perimeter of the lateral projection less the waterline and slender bodies.
    centroid : float
        ``C`` [m]: distance of the centroid of ``A_L`` from the bow.
    masts : float
        ``M``: number of distinct groups of masts or king posts.

    Returns
    -------
    C_X, C_Y, C_N : float
        ``X_w / (q A_F)`` (forward), ``Y_w / (q A_L)`` (to starboard), ``N_w / (q A_L L_oa)``
        (clockwise), ``q = 1/2 rho_a V_a^2``.
    """
    g = min(abs(angle), math.pi)
    s = g / _ISHERWOOD_STEP
    i = min(int(s), 17)
    w = s - i
    r1 = 2.0 * lateral_area / (length_overall * length_overall)
    r2 = 2.0 * frontal_area / (beam * beam)
    r3 = length_overall / beam
    r4 = perimeter / length_overall
    r5 = centroid / length_overall
    rx = 0.0
    ry = 0.0
    rn = 0.0
    for j in (i, i + 1):
        wj = 1.0 - w if j == i else w
        a = ISHERWOOD_CX[j]
        b = ISHERWOOD_CY[j]
        c = ISHERWOOD_CN[j]
        rx += wj * (a[0] + a[1] * r1 + a[2] * r2 + a[3] * r3 + a[4] * r4 + a[5] * r5 + a[6] * masts)
        ry += wj * (
            b[0] + b[1] * r1 + b[2] * r2 + b[3] * r3 + b[4] * r4 + b[5] * r5
            + b[6] * superstructure_area / lateral_area
        )  # fmt: skip
        rn += wj * (c[0] + c[1] * r1 + c[2] * r2 + c[3] * r3 + c[4] * r4 + c[5] * r5)
    side = -1.0 if angle > 0.0 else (1.0 if angle < 0.0 else 0.0)
    return -rx, side * ry, side * rn


@row_kernel
def isherwood_load(
    speed: float,
    angle: float,
    length_overall: float,
    beam: float,
    lateral_area: float,
    frontal_area: float,
    superstructure_area: float,
    perimeter: float,
    centroid: float,
    masts: float,
) -> tuple[float, float, float]:
    """Isherwood's wind force and moment on a merchant ship (module docstring).

    Parameters
    ----------
    speed : float
        Apparent wind speed ``V_a`` [m/s].
    angle : float
        Apparent wind angle ``g`` [rad] (:func:`isherwood_coefficients`).
    length_overall, beam, lateral_area, frontal_area, superstructure_area : float
        The ship's above-water particulars (:func:`isherwood_coefficients`; in this order with
        the next three: :meth:`IsherwoodShip.args`).
    perimeter, centroid, masts : float
        ``S`` [m], ``C`` [m], ``M`` (:func:`isherwood_coefficients`).

    Returns
    -------
    X, Y, N : float
        Surge force (forward) and sway force (to starboard) [N], yaw moment about midship
        (clockwise) [N m], of air of density :data:`RHO_AIR`.
    """
    cx, cy, cn = isherwood_coefficients(
        angle, length_overall, beam, lateral_area, frontal_area, superstructure_area,
        perimeter, centroid, masts,
    )  # fmt: skip
    q = 0.5 * RHO_AIR * speed * speed
    return (
        q * frontal_area * cx,
        q * lateral_area * cy,
        q * lateral_area * length_overall * cn,
    )


def _check_positive_fields(obj: object) -> None:
    for name, value in vars(obj).items():
        if isinstance(value, str):
            continue
        positive_number(value, f"{type(obj).__name__}.{name}")


@dataclass(frozen=True)
class IsherwoodShip:
    """A merchant ship's above-water particulars for Isherwood's wind loads.

    Attributes
    ----------
    length_overall : float
        ``L_oa`` [m].
    beam : float
        ``B`` [m].
    lateral_area : float
        Lateral projected wind area ``A_L`` [m^2].
    frontal_area : float
        Frontal (transverse) projected wind area ``A_F`` [m^2].
    superstructure_area : float
        Lateral projected area of the superstructure ``A_SS`` [m^2].
    perimeter : float
        ``S`` [m]: perimeter of the lateral projection less the waterline and slender bodies
        such as masts and ventilators.
    centroid : float
        ``C`` [m]: distance of the centroid of ``A_L`` from the bow.
    masts : float
        ``M``: number of distinct groups of masts or king posts seen in the lateral projection
        (king posts close against the bridge front not counted).
    """

    length_overall: float
    beam: float
    lateral_area: float
    frontal_area: float
    superstructure_area: float
    perimeter: float
    centroid: float
    masts: float

    def __post_init__(self) -> None:
        _check_positive_fields(self)

    def args(self) -> tuple[float, ...]:
        """The particulars in the argument order of :func:`isherwood_load`."""
        return tuple(float(v) for v in astuple(self))


# The Mariner's above-water particulars (estimated): length overall 564 ft (171.9 m) and beam
# 76 ft (23.17 m) of the C4-S-1a design; house and engine room amidships with four hatches
# forward and two aft. Assumed: freeboard 5.3 m (depth about 13.5 m, draught 8.2 m), a
# forecastle 30 m long and 2.5 m high, a three-tier house of 2.6 m tiers 45 m long and 20 m wide
# with a wheelhouse 15 m long and 16 m wide on top and a funnel 10 m long and 6 m high, all
# centred 94.5 m from the bow (0.55 L_oa).
_MARINER_LOA = 171.9
_MARINER_FREEBOARD = 5.3
_MARINER_HULL = _MARINER_LOA * _MARINER_FREEBOARD + 30.0 * 2.5
_MARINER_SUPERSTRUCTURE = 45.0 * 7.8 + 15.0 * 2.6 + 10.0 * 6.0

MARINER_WIND = IsherwoodShip(
    length_overall=_MARINER_LOA,
    beam=23.17,
    lateral_area=_MARINER_HULL + _MARINER_SUPERSTRUCTURE,
    frontal_area=23.17 * _MARINER_FREEBOARD + 20.0 * 7.8 + 16.0 * 2.6,
    superstructure_area=_MARINER_SUPERSTRUCTURE,
    perimeter=_MARINER_LOA + 2.0 * _MARINER_FREEBOARD + 2.5 + 2.0 * (7.8 + 2.6) + 2.0 * 6.0,
    centroid=(
        _MARINER_LOA * _MARINER_FREEBOARD * 0.5 * _MARINER_LOA + 30.0 * 2.5 * 15.0
        + _MARINER_SUPERSTRUCTURE * 94.5
    ) / (_MARINER_HULL + _MARINER_SUPERSTRUCTURE),
    masts=3.0,
)  # fmt: skip
"""Above-water particulars of the Mariner class cargo ship (C4-S-1a) for Isherwood's loads.

Only ``L_oa`` = 171.9 m (564 ft) and ``B`` = 23.17 m (76 ft; Fossen 1994 section 2.2) are
published; no source found gives the Mariner's wind areas, so the rest is an estimate from
the design's layout (house and engine room amidships, four hatches forward and two aft) with
assumed dimensions: freeboard 5.3 m (depth about 13.5 m less a draught of 8.2 m); a
forecastle 30 m long, 2.5 m high; a three-tier house (2.6 m a tier) 45 m long, 20 m wide, with
a wheelhouse 15 m long, 16 m wide, and a funnel 10 m long, 6 m high, all centred 94.5 m from
the bow. So ``A_L`` = 171.9 x 5.3 + 30 x 2.5 + ``A_SS`` = 1436 m^2 with ``A_SS`` = 45 x 7.8 +
15 x 2.6 + 10 x 6 = 450 m^2; ``A_F`` = 23.17 x 5.3 + 20 x 7.8 + 16 x 2.6 = 320 m^2; ``S``
(deck line, stem, stern, forecastle break, house, wheelhouse and funnel sides) = 218 m;
``C`` = 84.9 m (each part's area at its centre); ``M`` = 3 (a foremast and two groups of king
posts, assumed). The ratios (``2 A_L / L_oa^2`` = 0.097, ``2 A_F / B^2`` = 1.19, ``L_oa / B``
= 7.4, ``C / L_oa`` = 0.49) are those of a typical general cargo ship of Isherwood's data."""


# ---------------------------------------------------------------------------------------------
# Blendermann (1994) for the R/V Gunnerus


@dataclass(frozen=True)
class BlendermannShip:
    """A ship's wind data for Blendermann's wind loads (:func:`blendermann_load`).

    Attributes
    ----------
    frontal_area, lateral_area : float
        Frontal and lateral projected wind areas ``A_F``, ``A_L`` [m^2].
    centre : float
        ``s_L`` [m]: horizontal distance of the centroid of ``A_L`` forward of midship.
    length_overall : float
        ``L_oa`` [m].
    ship_type : str
        A key of :data:`BLENDERMANN_COEFFICIENTS`.
    """

    frontal_area: float
    lateral_area: float
    centre: float
    length_overall: float
    ship_type: str

    def __post_init__(self) -> None:
        if self.ship_type not in BLENDERMANN_COEFFICIENTS:
            raise ValueError(
                f"BlendermannShip.ship_type must be one of {tuple(BLENDERMANN_COEFFICIENTS)}, "
                f"got {self.ship_type!r}"
            )
        for name in ("frontal_area", "lateral_area", "length_overall"):
            positive_number(getattr(self, name), f"BlendermannShip.{name}")
        c = self.centre
        if not (isinstance(c, int | float) and math.isfinite(c) and abs(c) < self.length_overall):
            raise ValueError(
                "BlendermannShip.centre must be a finite number of metres inside "
                f"(-length_overall, length_overall), got {c!r}"
            )

    def args(self) -> tuple[float, ...]:
        """``(A_F, A_L, s_L, L_oa, C_Dt, C_Dl,AF bow, C_Dl,AF stern, delta)``: the arguments of
        :func:`blendermann_load` after the wind speed and angle."""
        return (
            float(self.frontal_area),
            float(self.lateral_area),
            float(self.centre),
            float(self.length_overall),
            *BLENDERMANN_COEFFICIENTS[self.ship_type],
        )


# R/V Gunnerus (estimated): L_oa 36.25 m and B 9.6 m (NTNU's particulars since the 2019
# lengthening), depth 4.2 m and draught 2.7 m; assumed bulwark 1.0 m, a two-tier deckhouse
# (2.6 m a tier) 18 m long and 9 m wide centred 8 m forward of midship, a wheelhouse 9 m long,
# 8 m wide, 2.6 m high centred 10 m forward of midship.
_GUNNERUS_HULL_HEIGHT = 4.2 - 2.7 + 1.0
_GUNNERUS_HOUSE = 18.0 * 5.2
_GUNNERUS_WHEELHOUSE = 9.0 * 2.6
_GUNNERUS_LATERAL = 36.25 * _GUNNERUS_HULL_HEIGHT + _GUNNERUS_HOUSE + _GUNNERUS_WHEELHOUSE

GUNNERUS_WIND = BlendermannShip(
    frontal_area=9.6 * _GUNNERUS_HULL_HEIGHT + 9.0 * 5.2 + 8.0 * 2.6,
    lateral_area=_GUNNERUS_LATERAL,
    centre=(8.0 * _GUNNERUS_HOUSE + 10.0 * _GUNNERUS_WHEELHOUSE) / _GUNNERUS_LATERAL,
    length_overall=36.25,
    ship_type="research_vessel",
)
"""Wind data of the R/V Gunnerus for Blendermann's research-vessel coefficients.

Published (NTNU; the ship since its 2019 lengthening): ``L_oa`` = 36.25 m, ``B`` = 9.6 m,
depth 4.2 m, draught 2.7 m. The projected wind areas are not published: they are estimated
from these and an assumed layout of the general arrangement (superstructure forward, open
working deck aft): a bulwark 1.0 m high on the 1.5 m freeboard; a two-tier deckhouse (2.6 m a
tier) 18 m long, 9 m wide, centred 8 m forward of midship; a wheelhouse 9 m long, 8 m wide,
2.6 m high, centred 10 m forward of midship (masts and the stern A-frame, slender, left out).
So ``A_L`` = 36.25 x 2.5 + 18 x 5.2 + 9 x 2.6 = 207.6 m^2, ``A_F`` = 9.6 x 2.5 + 9 x 5.2 +
8 x 2.6 = 91.6 m^2 and ``s_L`` = (8 x 93.6 + 10 x 23.4) / 207.6 = 4.7 m (the hull's share
centred at midship)."""


# ---------------------------------------------------------------------------------------------
# The Nomoto family

RHO_WATER = 1025.0
"""Density of sea water [kg/m^3] of the Mariner's prime system."""
MARINER_LENGTH = 160.93
"""``L`` [m]: the Mariner's length between perpendiculars, the length of its prime system."""
MARINER_N_DELTA = 139e-5
"""``N'_delta``: the Mariner's nondimensional rudder yaw moment derivative (Chislett and
Stroem-Tejsen 1965, MSS ``mariner.m``), with the Nomoto sign (a positive rudder angle turns the
ship to starboard)."""
MARINER_Y_V = -1160e-5
"""``Y'_v``: the Mariner's nondimensional sway damping derivative (same source)."""
_MARINER_ARGS = MARINER_WIND.args()  # plain floats, constants of the compiled kernel


@row_kernel
def mariner_nomoto_wind(speed: float, angle: float, ship_speed: float) -> tuple[float, float]:
    """The wind on the Mariner of the Nomoto family: equivalent rudder angle and leeway.

    Isherwood's loads on :data:`MARINER_WIND`, mapped to the Nomoto models (module docstring):
    ``delta_w = N_w / (N'_delta 1/2 rho U^2 L^3)`` and ``v_w = Y_w / (-Y'_v 1/2 rho U L^2)``.

    Parameters
    ----------
    speed : float
        Apparent wind speed ``V_a`` [m/s].
    angle : float
        Apparent wind angle ``g`` [rad] (``0`` head wind, ``+pi/2`` from starboard).
    ship_speed : float
        The ship's speed through the water ``U`` [m/s] (> 0).

    Returns
    -------
    delta_w : float
        Equivalent rudder angle [rad] to add to the rudder angle of the yaw equation
        (positive: the wind turns the ship to starboard).
    v_w : float
        Steady leeway [m/s], a sway velocity to starboard to add to the kinematics.
    """
    a = _MARINER_ARGS
    _, y, n = isherwood_load(speed, angle, a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7])
    q = 0.5 * RHO_WATER * ship_speed * MARINER_LENGTH * MARINER_LENGTH
    return n / (MARINER_N_DELTA * q * ship_speed * MARINER_LENGTH), y / (-MARINER_Y_V * q)


# ---------------------------------------------------------------------------------------------
# Gusts


def _spectrum_inputs(frequency: Any, mean_speed: Any) -> tuple[np.ndarray, float]:
    f = real_array(frequency, "frequency")
    require_finite(f, "frequency")
    if (f < 0.0).any():
        raise ValueError(
            f"frequency must be >= 0 Hz, got {float(f[np.argmin(f)] if f.ndim else f)!r}"
        )
    return f, positive_number(mean_speed, "mean_speed", expected="a finite speed > 0 m/s")


def norsok_spectrum(frequency: Any, mean_speed: float, height: float = 10.0) -> np.ndarray:
    """The NORSOK N-003 (2007) wind gust spectrum (module docstring).

    Parameters
    ----------
    frequency : array_like
        Frequencies ``f`` [Hz] (>= 0).
    mean_speed : float
        ``U_10`` [m/s]: the 1-hour mean wind speed 10 m above the sea (> 0).
    height : float
        ``z`` [m]: height above the sea (> 0; 10 m by default).

    Returns
    -------
    numpy.ndarray
        One-sided ``S(f)`` [(m/s)^2/Hz], the shape of ``frequency``.
    """
    f, u10 = _spectrum_inputs(frequency, mean_speed)
    z = positive_number(height, "height", expected="a finite height > 0 m")
    n = 0.468
    x = 172.0 * f * (z / 10.0) ** (2.0 / 3.0) * (u10 / 10.0) ** -0.75
    return 320.0 * (u10 / 10.0) ** 2 * (z / 10.0) ** 0.45 / (1.0 + x**n) ** (5.0 / (3.0 * n))


def harris_spectrum(
    frequency: Any,
    mean_speed: float,
    drag_coefficient: float = 0.0026,
    length_scale: float = 1800.0,
) -> np.ndarray:
    """The Harris (1971) wind gust spectrum (module docstring).

    Parameters
    ----------
    frequency : array_like
        Frequencies ``f`` [Hz] (>= 0).
    mean_speed : float
        ``U_10`` [m/s]: the mean wind speed 10 m above the sea (> 0).
    drag_coefficient : float
        Surface drag coefficient ``kappa`` (> 0; 0.0026 by default).
    length_scale : float
        ``L`` [m] (> 0; 1800 m by default).

    Returns
    -------
    numpy.ndarray
        One-sided ``S(f)`` [(m/s)^2/Hz], the shape of ``frequency``.
    """
    f, u10 = _spectrum_inputs(frequency, mean_speed)
    kappa = positive_number(drag_coefficient, "drag_coefficient")
    scale = positive_number(length_scale, "length_scale", expected="a finite length > 0 m")
    x = scale * f / u10
    return 4.0 * kappa * scale * u10 / (2.0 + x * x) ** (5.0 / 6.0)


GUST_SPECTRA = {"norsok": norsok_spectrum, "harris": harris_spectrum}
"""Gust spectra of :func:`wind_gusts` by name."""


def wind_gusts(
    mean_speed: float,
    duration: float,
    dt: float,
    seed: int,
    spectrum: str = "norsok",
    components: int = 1000,
    **spectrum_options: float,
) -> np.ndarray:
    """A seeded record of the wind speed with gusts (module docstring, "Gusts").

    Parameters
    ----------
    mean_speed : float
        ``U_10`` [m/s]: mean wind speed (>= 0), the mean of the record; 0 gives calm air.
    duration : float
        Length of the record [s] (> 0, at least two steps).
    dt : float
        Sample interval [s] (> 0).
    seed : int
        Seed of :func:`numpy.random.default_rng`: the same seed gives the same record.
    spectrum : str
        A key of :data:`GUST_SPECTRA` (``"norsok"`` or ``"harris"``).
    components : int
        Number of harmonics (1 ... 100000; 1000 by default).
    **spectrum_options : float
        Passed to the spectrum (``height`` of :func:`norsok_spectrum`, ``drag_coefficient``
        and ``length_scale`` of :func:`harris_spectrum`).

    Returns
    -------
    numpy.ndarray
        Wind speed [m/s] at ``t = 0, dt, 2 dt, ...`` below ``duration``.
    """
    if spectrum not in GUST_SPECTRA:
        raise ValueError(f"spectrum must be one of {tuple(GUST_SPECTRA)}, got {spectrum!r}")
    if isinstance(mean_speed, bool | np.bool_) or not isinstance(mean_speed, numbers.Real):
        raise TypeError(f"mean_speed must be a real number of m/s, got {mean_speed!r}")
    u = float(mean_speed)
    if not (math.isfinite(u) and u >= 0.0):
        raise ValueError(f"mean_speed must be a finite speed >= 0 m/s, got {u!r}")
    h = step_size(dt)
    length = positive_number(duration, "duration", expected="a finite duration > 0 s")
    samples = math.ceil(length / h - 1e-9)
    if samples < 2:
        raise ValueError(f"duration must be at least two steps of dt = {h!r} s, got {length!r}")
    k = count(components, "components", 1, 100_000)
    if isinstance(seed, bool | np.bool_) or not isinstance(seed, numbers.Integral):
        raise TypeError(f"seed must be an integer, got {seed!r}")
    GUST_SPECTRA[spectrum](0.0, 1.0, **spectrum_options)  # refuse bad options before any work
    if u == 0.0:
        return np.zeros(samples)
    rng = np.random.default_rng(seed)
    edges = np.geomspace(1.0 / (samples * h), 0.5 / h, k + 1)
    freq = edges[:-1] + rng.random(k) * np.diff(edges)
    phase = rng.uniform(0.0, 2.0 * np.pi, k)
    amplitude = np.sqrt(2.0 * GUST_SPECTRA[spectrum](freq, u, **spectrum_options) * np.diff(edges))
    omega = 2.0 * np.pi * freq
    t = np.arange(samples) * h
    gust = np.empty(samples)
    chunk = max(1, 2_000_000 // k)
    for start in range(0, samples, chunk):
        tc = t[start : start + chunk]
        gust[start : start + chunk] = np.cos(np.outer(tc, omega) + phase) @ amplitude
    return u + (gust - gust.mean())

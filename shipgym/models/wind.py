"""Wind loads on a merchant ship's above-water hull and superstructure (Blendermann 1994).

W. Blendermann, "Parameter identification of wind loads on ships", J. Wind Eng. Ind.
Aerodyn. 51 (1994) 339-351, as given by T. I. Fossen, *Handbook of Marine Craft Hydrodynamics
and Motion Control*, 2nd ed., Wiley 2021, section 10.1, and implemented in Fossen's Marine
Systems Simulator (MSS, ``blendermann94.m``, whose table of coefficients per ship type gives
the tanker rows of :data:`BLENDERMANN_COEFFICIENTS`). With the apparent wind of speed ``V_a``
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
not modelled.

The apparent wind at the ship (:func:`apparent_wind`) is the true wind, constant over the
earth, less the ship's velocity over ground; the yaw rate's share is neglected.

These are compiled per-ship building blocks that model kernels inline
(:mod:`shipgym.models.mmg`), like :mod:`shipgym.models.kinematics`: they take their arguments
unchecked. From Python, :class:`shipgym.models.MMGParams` checks the wind and the ship's wind
data before any kernel sees them.
"""

from __future__ import annotations

import math

from shipgym.models._jit import row_kernel

__all__ = ["BLENDERMANN_COEFFICIENTS", "RHO_AIR", "apparent_wind", "blendermann_load"]

RHO_AIR = 1.224
"""Density of air [kg/m^3] (the value of MSS ``blendermann94.m``)."""

BLENDERMANN_COEFFICIENTS: dict[str, tuple[float, float, float, float]] = {
    "tanker_loaded": (0.70, 0.90, 0.55, 0.40),
    "tanker_ballast": (0.70, 0.75, 0.55, 0.40),
}
"""Blendermann's coefficients ``(C_Dt, C_Dl,AF bow, C_Dl,AF stern, delta)`` by ship type
(Blendermann 1994; Fossen 2021, section 10.1; MSS ``blendermann94.m``, ship types 15 and 16)."""


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

"""Planar 3-DOF kinematics and the current in the body frame (seed 001 eq. 5-9).

Shared by the 3-DOF models (:mod:`shipgym.models.rvg`, :mod:`shipgym.models.mmg`), whose states
begin ``[x, y, psi, u, v, r]``: ``eta' = R_z(psi) nu`` (eq. 6) and the body-frame current
``nu_c = R_z(psi)^T [V_n, V_e, 0]`` (eq. 8) of the constant, irrotational current of
:mod:`shipgym.models.current`.
"""

from __future__ import annotations

from shipgym.models._jit import row_kernel


@row_kernel
def planar_kinematics(u, v, r, cs, sn, out):
    """``x' = u cos(psi) - v sin(psi)``, ``y' = u sin(psi) + v cos(psi)``, ``psi' = r`` into
    ``out[0:3]`` (``cs``, ``sn`` the cosine and sine of the heading)."""
    out[0] = cs * u - sn * v
    out[1] = sn * u + cs * v
    out[2] = r


@row_kernel
def body_current(c, cs, sn):
    """The current ``(u_c, v_c)`` [m/s] in the body frame of a ship heading ``psi`` (``cs``,
    ``sn`` its cosine and sine) from its north/east components ``c``."""
    return c[0] * cs + c[1] * sn, -c[0] * sn + c[1] * cs

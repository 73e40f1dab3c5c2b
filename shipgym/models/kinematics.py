"""Planar 3-DOF kinematics, the current in the body frame and the rudder's steering gear.

Shared by the 3-DOF models (:mod:`shipgym.models.rvg`, :mod:`shipgym.models.mmg`,
:mod:`shipgym.models.vmm`), whose states begin ``[x, y, psi, u, v, r]``: ``eta' = R_z(psi) nu``
(seed 001 eq. 6) and the body-frame current ``nu_c = R_z(psi)^T [V_n, V_e, 0]`` (eq. 8) of the
constant, irrotational current of :mod:`shipgym.models.current`; and the steering gear of the
model-test ships (a first-order rudder inside angle and rate limits, seed 002 eq. 2).

These are compiled per-ship building blocks that the model kernels inline; they take their
arguments unchecked (Numba does no bounds checking), so they are for compiled code. From Python
use :class:`shipgym.models.ShipModel`, whose methods check shapes and values first.
"""

from __future__ import annotations

import math

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


@row_kernel
def relative_motion(x, c, out):
    """Planar kinematics of the state ``x`` into ``out[0:3]``; returns ``(u_r, v_r, u_c, v_c)``,
    the velocities relative to the water and the current, both in the body frame."""
    psi = x[2]
    cs = math.cos(psi)
    sn = math.sin(psi)
    planar_kinematics(x[3], x[4], x[5], cs, sn, out)
    uc, vc = body_current(c, cs, sn)
    return x[3] - uc, x[4] - vc, uc, vc


@row_kernel
def steering_gear(delta, command, max_angle, max_rate, inv_time_constant):
    """Rudder rate ``delta'`` [rad/s] towards the command, limited in angle and rate."""
    dc = min(max(command, -max_angle), max_angle)
    return min(max((dc - delta) * inv_time_constant, -max_rate), max_rate)

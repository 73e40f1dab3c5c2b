"""The one state derivative dispatcher and the one fixed-step RK4 integrator.

``rhs(model_id, x, u, p, c, out)`` evaluates the batched state derivative
``x' = f(x, u, p, c)`` for a batch of ships (``x`` of shape ``(n, nx)``, ``u`` of shape
``(n, nu)``, ``c`` the ``(n, 2)`` north/east current) by calling the model's row kernel.
``rk4_step`` advances the batch in place by one classic fourth-order Runge-Kutta step with
the input and current held over the step (seed 001 eq. 2). Every user of a model, the
environments, the manoeuvres and identification, integrates through these two functions.
"""

from __future__ import annotations

import numpy as np

from shipgym.models._jit import kernel
from shipgym.models.nomoto import bech_row, nomoto1_row, nomoto2_row, norrbin_row
from shipgym.models.rvg import rvg_row

NOMOTO1, NOMOTO2, NORRBIN, BECH, RVG3DOF = 0, 1, 2, 3, 4


@kernel
def rhs(model_id, x, u, p, c, out):  # noqa: ANN001, ANN201
    """Batched state derivative of model ``model_id``, written into ``out``."""
    for i in range(x.shape[0]):
        if model_id == NOMOTO1:
            nomoto1_row(x, u, p, c, out, i)
        elif model_id == NOMOTO2:
            nomoto2_row(x, u, p, c, out, i)
        elif model_id == NORRBIN:
            norrbin_row(x, u, p, c, out, i)
        elif model_id == BECH:
            bech_row(x, u, p, c, out, i)
        else:
            rvg_row(x, u, p, c, out, i)


@kernel
def _axpy(x, a, k, out):  # noqa: ANN001, ANN202
    """``out = x + a k`` elementwise."""
    n, m = x.shape
    for i in range(n):
        for j in range(m):
            out[i, j] = x[i, j] + a * k[i, j]


@kernel
def rk4_step(model_id, x, u, p, c, h):  # noqa: ANN001, ANN201
    """Advance ``x`` in place by one RK4 step of length ``h`` [s]."""
    k1 = np.empty_like(x)
    k2 = np.empty_like(x)
    k3 = np.empty_like(x)
    k4 = np.empty_like(x)
    t = np.empty_like(x)
    rhs(model_id, x, u, p, c, k1)
    _axpy(x, 0.5 * h, k1, t)
    rhs(model_id, t, u, p, c, k2)
    _axpy(x, 0.5 * h, k2, t)
    rhs(model_id, t, u, p, c, k3)
    _axpy(x, h, k3, t)
    rhs(model_id, t, u, p, c, k4)
    n, m = x.shape
    w = h / 6.0
    for i in range(n):
        for j in range(m):
            x[i, j] += w * (k1[i, j] + 2.0 * k2[i, j] + 2.0 * k3[i, j] + k4[i, j])

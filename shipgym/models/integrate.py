"""The one state derivative dispatcher and the one fixed-step RK4 integrator.

``rhs(model_id, x, u, p, c, out)`` evaluates the batched state derivative
``x' = f(x, u, p, c)`` for a batch of ships (``x`` of shape ``(n, nx)``, ``u`` of shape
``(n, nu)``, ``c`` the ``(n, 2)`` north/east current) by calling the model's per-ship kernel.
``rk4_step`` advances the batch in place by one classic fourth-order Runge-Kutta step with
the input and current held over the step (seed 001 eq. 2). Every user of a model, the
environments, the manoeuvres and identification, integrates through these functions.

Both run ship by ship through ``rk4_stages``, whose four stages use small work vectors that
stay in the CPU cache; the environments' kernels call ``rk4_row`` (the same stages over the
environment models' derivative ``row_rhs``) inside their own row loops, so they do not compile
the 3-DOF model-test models (MMG, VMM), which no environment uses (it would add 40 % to their
compile time).
"""

from __future__ import annotations

import numpy as np

from shipgym.models._jit import kernel, row_kernel
from shipgym.models.mmg import mmg_row
from shipgym.models.nomoto import bech_row, nomoto1_row, nomoto2_row, norrbin_row
from shipgym.models.rvg import rvg_row
from shipgym.models.vmm import vmm_row

NOMOTO1, NOMOTO2, NORRBIN, BECH, RVG3DOF, KVLCC2, VMM = 0, 1, 2, 3, 4, 5, 6


@row_kernel
def row_rhs(model_id, x, u, p, c, out):
    """State derivative of one ship (1-D ``x``, ``u``, ``c``) of an environment model (the
    Nomoto family and the RVG) written into ``out``."""
    if model_id == NOMOTO1:
        nomoto1_row(x, u, p, c, out)
    elif model_id == NOMOTO2:
        nomoto2_row(x, u, p, c, out)
    elif model_id == NORRBIN:
        norrbin_row(x, u, p, c, out)
    elif model_id == BECH:
        bech_row(x, u, p, c, out)
    else:
        rvg_row(x, u, p, c, out)


@row_kernel
def row_rhs_all(model_id, x, u, p, c, out):
    """State derivative of one ship of any model: :func:`row_rhs`, the MMG model and the
    general VMM."""
    if model_id == KVLCC2:
        mmg_row(x, u, p, c, out)
    elif model_id == VMM:
        vmm_row(x, u, p, c, out)
    else:
        row_rhs(model_id, x, u, p, c, out)


@kernel
def rhs(model_id, x, u, p, c, out):
    """Batched state derivative of model ``model_id``, written into ``out``."""
    for i in range(x.shape[0]):
        row_rhs_all(model_id, x[i], u[i], p, c[i], out[i])


@row_kernel
def rk4_stages(deriv, model_id, x, u, p, c, h, i, k1, k2, k3, k4, t):
    """Advance row ``i`` of ``x`` in place by one classic RK4 step of ``h`` [s] of the
    derivative ``deriv`` (:func:`row_rhs` or :func:`row_rhs_all`).

    ``k1`` to ``k4`` and ``t`` are scratch vectors of length nx (the slopes and the stage state).
    """
    m = x.shape[1]
    xi = x[i]
    ui = u[i]
    ci = c[i]
    for j in range(m):
        t[j] = xi[j]
    # one call site for the four stages: the derivative is inlined once, not four times
    # (compile time and code size grow with every inlined copy of every model)
    for s in range(4):
        k = k1 if s == 0 else k2 if s == 1 else k3 if s == 2 else k4
        deriv(model_id, t, ui, p, ci, k)
        if s < 3:
            a = h if s == 2 else 0.5 * h
            for j in range(m):
                t[j] = xi[j] + a * k[j]
    for j in range(m):
        xi[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])


@row_kernel
def rk4_row(model_id, x, u, p, c, h, i, k1, k2, k3, k4, t):
    """:func:`rk4_stages` of an environment model (:func:`row_rhs`): the environments' and the
    identification's kernels inline it without the models no environment uses."""
    rk4_stages(row_rhs, model_id, x, u, p, c, h, i, k1, k2, k3, k4, t)


#: Batches at least this large are stepped by the parallel compilation of the env kernels.
PARALLEL_MIN_ROWS = 64


@kernel
def rk4_step(model_id, x, u, p, c, h):
    """Advance every row of ``x`` in place by one RK4 step of length ``h`` [s]."""
    work = np.empty((5, x.shape[1]))
    k1, k2, k3, k4, t = work[0], work[1], work[2], work[3], work[4]
    for i in range(x.shape[0]):
        rk4_stages(row_rhs_all, model_id, x, u, p, c, h, i, k1, k2, k3, k4, t)

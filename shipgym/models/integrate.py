"""The one state derivative dispatcher and the one fixed-step RK4 integrator.

``rhs(model_id, x, u, p, c, out)`` evaluates the batched state derivative
``x' = f(x, u, p, c)`` for a batch of ships (``x`` of shape ``(n, nx)``, ``u`` of shape
``(n, nu)``, ``c`` the ``(n, 2)`` north/east current) with the model's one derivative.

The blocks of the environment models carry :data:`NC` disturbance rows per ship (``C``): the
north/east current and the external load of the seaway (:mod:`shipgym.models.seaway`), held
over the step like the current: for the R/V Gunnerus the surge and sway forces [N] and the yaw
moment [N m] about its origin, for the Nomoto family the equivalent rudder angle [rad] and the
leeway [m/s] (seed 003 eq. 1's ``tau_wind + tau_wave``). A batch of rows with only the two
current columns (every user but the environments) gathers into a block with a zero load.
``rk4_step`` advances the batch in place by one classic fourth-order Runge-Kutta step with
the input and current held over the step (seed 001 eq. 2). Every user of a model, the
environments, the manoeuvres and identification, integrates through their compiled kernels
(``rhs_kernel``, ``rk4_step_kernel``, ``rk4_block``); ``rhs`` and ``rk4_step``
are the same kernels behind argument checks, for calls from Python.

Block kernels
-------------
The environment models (the Nomoto family and the R/V Gunnerus) are stepped a block of ships at
a time (:data:`BLOCK` ships, states x ships, :func:`rk4_block`): each model's derivative is one
per-ship function of a column of the block (``nomoto1_col``, ..., ``rvg_col``), written as
straight-line code with the sine, cosine and arctangent of :mod:`shipgym.models.vmath`, and the
loop over the ships of a block compiles to SIMD instructions. The model is chosen once per
block (:func:`block_rhs`), not once per ship and stage. One ship is a block of one (the
identification's replays hold their ship as a ``(nx, 1)`` block), so every user of a model
runs the same function and a ship's result does not depend on the batch it is in. A batch
held as rows (the envs, :func:`rk4_step_kernel`) is stepped block by block: gathered into a
block (:func:`gather_rows`), stepped (:func:`rk4_block_of`: a full block and a block of one with
their width as a compile-time constant; the Gunnerus tasks by :func:`rk4_block_rvg`, which holds
no other model's code) and scattered back (:func:`scatter_rows`); :func:`rk4_rows` does all
three. The model-test models (MMG,
VMM), which no environment uses, keep their per-ship functions and :func:`rk4_stages`.

Checked and unchecked entry points
----------------------------------
Numba does no bounds checking. ``rhs`` and ``rk4_step`` are the Python entry points: they check
the model id, the rows and columns of every array against the model, the parameter vector's
length and that everything is finite, then call the compiled ``rhs_kernel`` and
``rk4_step_kernel``. Those, and the block and per-ship functions, take
their arguments as they are: they are for compiled callers and for code that has already
checked the arrays (:class:`shipgym.models.ShipModel`).

Stability of the fixed step
---------------------------
RK4 applied to ``x' = lambda x`` multiplies ``x`` by ``R(h lambda)`` per step,
``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24``. A decaying mode is reproduced only while
``|R(h lambda)| <= 1``: on the negative real axis up to ``h |lambda| = 2.785``, on the imaginary
axis up to ``2 sqrt(2)``. Beyond that the step does not give a rough answer but a wrong one that
grows exponentially. :func:`rk4_stable_step` is the largest step that keeps every decaying
eigenvalue of a linearisation inside that region.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from shipgym.models import mmg, nomoto, rvg, vmm
from shipgym.models._checks import real_array, require_finite, shape_error, step_size
from shipgym.models._jit import kernel, param_nonzero, row_kernel
from shipgym.models.mmg import mmg_row
from shipgym.models.nomoto import bech_col, nomoto1_col, nomoto2_col, norrbin_col
from shipgym.models.rvg import P_CF, rvg_col, rvg_crossflow_col
from shipgym.models.vmm import vmm_row

NOMOTO1, NOMOTO2, NORRBIN, BECH, RVG3DOF, KVLCC2, VMM = 0, 1, 2, 3, 4, 5, 6
MODEL_IDS = {"nomoto1": 0, "nomoto2": 1, "norrbin": 2, "bech": 3, "rvg3dof": 4, "kvlcc2": 5,
             "vmm": 6}  # fmt: skip
"""Model id of each model name (the ``model_id`` argument of the kernels)."""
_NAMES = tuple(MODEL_IDS)
#: states and inputs of each model id
STATE_COUNTS = (
    len(nomoto.FIRST_ORDER_STATES), len(nomoto.SECOND_ORDER_STATES),
    len(nomoto.FIRST_ORDER_STATES), len(nomoto.SECOND_ORDER_STATES),
    len(rvg.RVG_STATES), len(mmg.MMG_STATES), len(vmm.VMM_STATES),
)  # fmt: skip
INPUT_COUNTS = (
    *(len(nomoto.NOMOTO_INPUTS),) * 4, len(rvg.RVG_INPUTS), len(mmg.MMG_INPUTS),
    len(vmm.VMM_INPUTS),
)  # fmt: skip
#: packed parameters of each model id (the VMM's length depends on its terms: -1)
_PARAMETER_COUNTS = (
    *(nomoto.P_YAW + len(cls().coefficients()) for cls in (
        nomoto.Nomoto1Params, nomoto.Nomoto2Params, nomoto.NorrbinParams, nomoto.BechParams
    )),
    rvg.P_SIZE, mmg.P_SIZE, -1,
)  # fmt: skip


#: Disturbance rows of a block (``C``): current north, east; load X, Y, N (module docstring).
NC = 5

#: Ships per block of :func:`rk4_block` in the batch kernels (a block's work arrays stay in
#: the first-level cache; a multiple of the SIMD width).
BLOCK = 32
#: Ships a loop over a block steps at once with AVX-512 (float64), a multiple of AVX2's 4: a
#: block whose width is a multiple of it runs in whole vectors, without a scalar remainder.
SIMD_LANES = 8


@row_kernel
def _cols(col, X, U, p, C, K, n):
    """Derivative of ships ``range(n)`` of a block by the per-ship model function ``col``
    (``nomoto1_col``, ...): a loop of straight-line code that compiles to SIMD instructions."""
    for b in range(n):
        col(X, U, p, C, K, b)


@row_kernel
def _rvg_cols(col, X, U, p, C, K, n):
    """:func:`_cols` of the RVG (``col`` is ``rvg_col``), and the cross-flow terms in a loop of
    their own where their coefficient is not zero."""
    _cols(col, X, U, p, C, K, n)
    if param_nonzero(p, P_CF, n):
        for b in range(n):
            rvg_crossflow_col(X, p, C, K, b)


@row_kernel
def block_rhs(model_id, X, U, p, C, K, n):
    """State derivative of ships ``range(n)`` of a block (columns of ``X``, ``U``, ``C``) of an
    environment model (the Nomoto family and the RVG), written into ``K``.

    The model is chosen once per block; each model's loop over the ships is straight-line
    code that compiles to SIMD instructions.
    """
    if model_id == NOMOTO1:
        _cols(nomoto1_col, X, U, p, C, K, n)
    elif model_id == NOMOTO2:
        _cols(nomoto2_col, X, U, p, C, K, n)
    elif model_id == NORRBIN:
        _cols(norrbin_col, X, U, p, C, K, n)
    elif model_id == BECH:
        _cols(bech_col, X, U, p, C, K, n)
    else:
        _rvg_cols(rvg_col, X, U, p, C, K, n)


@row_kernel
def _rk4(block_deriv, model, nx, X, U, p, C, h, n, W):
    """The RK4 step of :func:`rk4_block` with the block derivative
    ``block_deriv(model, X, U, p, C, K, n)`` of ships with ``nx`` states (``model`` is a model
    id for :func:`block_rhs`, a per-ship model function for :func:`_cols`)."""
    K = W[0]
    A = W[1]
    T = W[2]
    for j in range(nx):
        for b in range(n):
            T[j, b] = X[j, b]
    for s in range(4):
        block_deriv(model, T, U, p, C, K, n)
        if s == 0:
            for j in range(nx):
                for b in range(n):
                    A[j, b] = K[j, b]
                    T[j, b] = X[j, b] + 0.5 * h * K[j, b]
        elif s < 3:
            a = h if s == 2 else 0.5 * h
            for j in range(nx):
                for b in range(n):
                    A[j, b] += 2.0 * K[j, b]
                    T[j, b] = X[j, b] + a * K[j, b]
        else:
            for j in range(nx):
                for b in range(n):
                    X[j, b] += h / 6.0 * (A[j, b] + K[j, b])


@row_kernel
def rk4_block(model_id, X, U, p, C, h, n, W):
    """Advance ships ``range(n)`` of the block ``X`` (states x ships) in place by one classic
    RK4 step of ``h`` [s] with the inputs ``U`` and current ``C`` held (seed 001 eq. 2).

    ``W`` is scratch of shape ``(3, nx, >= n)``: the slope of a stage, the running sum
    ``k1 + 2 k2 + 2 k3`` and the stage state. One call site of the derivative for the four
    stages (compile time and code size grow with every inlined copy of a model), and the same
    arrays at every stage (a loop over differing arrays does not vectorise as well).
    """
    _rk4(block_rhs, model_id, X.shape[0], X, U, p, C, h, n, W)


@row_kernel
def rk4_block_nomoto(col, X, U, p, C, h, n, W):
    """:func:`rk4_block` of one Nomoto-family model, given by its per-ship function ``col``
    (``nomoto1_col``, ``nomoto2_col``, ``norrbin_col``, ``bech_col``): no other model's code to
    compile (the identification's replays, which fit one model at a time)."""
    _rk4(_cols, col, X.shape[0], X, U, p, C, h, n, W)


_NX_RVG = STATE_COUNTS[RVG3DOF]


@row_kernel
def rk4_block_rvg(model_id, X, U, p, C, h, n, W):
    """:func:`rk4_block` of the R/V Gunnerus alone: no other model's code to compile, and its
    number of states a compile-time constant (``model_id`` is not read)."""
    _rk4(_rvg_cols, rvg_col, _NX_RVG, X, U, p, C, h, n, W)


@row_kernel
def block_work(nx, nu, n):
    """Work arrays of one block for a batch of ``n`` ships: states, inputs, disturbances (ships
    as columns; :data:`NC` rows) and the RK4 scratch of :func:`rk4_block`, ``min(n, BLOCK)``
    ships wide."""
    m = max(min(n, BLOCK), 1)
    return (np.empty((nx, m)), np.empty((nu, m)), np.empty((NC, m)), np.empty((3, nx, m)))


def disturbance_block(current: np.ndarray) -> np.ndarray:
    """The block of disturbances (:data:`NC` rows, ships as columns, C-contiguous) of ships with
    the north/east currents ``current`` (``(n, 2)``) and no seaway load."""
    block = np.zeros((NC, current.shape[0]))
    block[:2] = current.T
    return block


@row_kernel
def _gather(x, u, c, rows, start, n, XB, UB, CB, nx, nu):
    for b in range(n):
        i = rows[start + b]
        for j in range(nx):
            XB[j, b] = x[i, j]
        for j in range(nu):
            UB[j, b] = u[i, j]
        for j in range(NC):  # a batch with the current alone gets a zero load
            CB[j, b] = c[i, j] if j < c.shape[1] else 0.0


@row_kernel
def _scatter(XB, rows, start, n, x, nx):
    for b in range(n):
        i = rows[start + b]
        for j in range(nx):
            x[i, j] = XB[j, b]


# The copies into and out of a block have the width of a full block and of a block of one as a
# compile-time constant, as the RK4 step has (rk4_block_of): a loop of a width known at run
# time only costs tens of ns to set up, as much as a single env's whole step of one ship.


@row_kernel
def gather_rows(x, u, c, rows, start, n, XB, UB, CB, nx, nu):
    """Copy ships ``rows[start:start + n]`` of the batch (ships as rows; ``nx`` states,
    ``nu`` inputs) into a block."""
    if n == BLOCK:
        _gather(x, u, c, rows, start, BLOCK, XB, UB, CB, nx, nu)
    elif n == 1:
        _gather(x, u, c, rows, start, 1, XB, UB, CB, nx, nu)
    else:
        _gather(x, u, c, rows, start, n, XB, UB, CB, nx, nu)


@row_kernel
def scatter_rows(XB, rows, start, n, x, nx):
    """Copy the block's ``nx`` states back to rows ``rows[start:start + n]`` of ``x``."""
    if n == BLOCK:
        _scatter(XB, rows, start, BLOCK, x, nx)
    elif n == 1:
        _scatter(XB, rows, start, 1, x, nx)
    else:
        _scatter(XB, rows, start, n, x, nx)


@row_kernel
def rk4_block_of(step, model_id, X, U, p, C, h, n, W):
    """One RK4 step of ships ``range(n)`` of a block by ``step`` (:func:`rk4_block`, or
    :func:`rk4_block_rvg` where the ship is the R/V Gunnerus), with the width of a full block
    and of a block of one as compile-time constants.

    A full block of :data:`BLOCK` ships is stepped with a known trip count: no remainder loops
    and no run-time checks at every loop (1.2 x faster for the RVG, 1.8 x for a Nomoto model,
    than the same step with the width known at run time only, which the last, partial block of
    a batch keeps). So is a block of one ship (the single env's step): a loop whose width is
    known at run time only costs about 60 ns to set up, more than one ship's derivative.
    """
    if n == BLOCK:
        step(model_id, X, U, p, C, h, BLOCK, W)
    elif n == 1:
        step(model_id, X, U, p, C, h, 1, W)
    else:
        step(model_id, X, U, p, C, h, n, W)


@row_kernel
def rk4_rows(step, model_id, x, u, p, c, h, rows, start, n, work):
    """One RK4 step of ships ``rows[start:start + n]`` of a batch (ships as rows): copied
    into the block work arrays ``work`` (:func:`block_work`), stepped by :func:`rk4_block_of`
    and copied back."""
    XB, UB, CB, W = work
    nx, nu = x.shape[1], u.shape[1]
    gather_rows(x, u, c, rows, start, n, XB, UB, CB, nx, nu)
    rk4_block_of(step, model_id, XB, UB, p, CB, h, n, W)
    scatter_rows(XB, rows, start, n, x, nx)


@row_kernel
def model_test_row(model_id, x, u, p, c, out):
    """State derivative of one ship (1-D ``x``, ``u``, ``c``) of a model-test model: the MMG
    model or the general VMM."""
    if model_id == KVLCC2:
        mmg_row(x, u, p, c, out)
    else:
        vmm_row(x, u, p, c, out)


@kernel
def rhs_kernel(model_id, x, u, p, c, out):
    """Batched state derivative of model ``model_id``, written into ``out`` (unchecked: see
    :func:`rhs`)."""
    n = x.shape[0]
    if model_id < KVLCC2:
        rows = np.arange(n)
        XB, UB, CB, W = block_work(x.shape[1], u.shape[1], n)
        KB = W[0]
        for start in range(0, n, BLOCK):
            m = min(BLOCK, n - start)
            gather_rows(x, u, c, rows, start, m, XB, UB, CB, x.shape[1], u.shape[1])
            block_rhs(model_id, XB, UB, p, CB, KB, m)
            scatter_rows(KB, rows, start, m, out, x.shape[1])
    else:
        for i in range(n):
            model_test_row(model_id, x[i], u[i], p, c[i], out[i])


@row_kernel
def rk4_stages(deriv, model_id, x, u, p, c, h, i, k1, k2, k3, k4, t):
    """Advance row ``i`` of ``x`` in place by one classic RK4 step of ``h`` [s] of the per-ship
    derivative ``deriv(model_id, x_i, u_i, p, c_i, out)`` (the model-test models, which run
    one ship at a time).

    ``k1`` to ``k4`` and ``t`` are scratch vectors of length nx (the slopes and the stage state).
    """
    m = x.shape[1]
    xi = x[i]
    ui = u[i]
    ci = c[i]
    for j in range(m):
        t[j] = xi[j]
    for s in range(4):
        k = k1 if s == 0 else k2 if s == 1 else k3 if s == 2 else k4
        deriv(model_id, t, ui, p, ci, k)
        if s < 3:
            a = h if s == 2 else 0.5 * h
            for j in range(m):
                t[j] = xi[j] + a * k[j]
    for j in range(m):
        xi[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])


@kernel
def rk4_step_kernel(model_id, x, u, p, c, h):
    """Advance every row of ``x`` in place by one RK4 step of length ``h`` [s] (unchecked: see
    :func:`rk4_step`)."""
    n = x.shape[0]
    if model_id < KVLCC2:
        rows = np.arange(n)
        work = block_work(x.shape[1], u.shape[1], n)
        for start in range(0, n, BLOCK):
            m = min(BLOCK, n - start)
            rk4_rows(rk4_block, model_id, x, u, p, c, h, rows, start, m, work)
    else:
        work = np.empty((5, x.shape[1]))
        k1, k2, k3, k4, t = work[0], work[1], work[2], work[3], work[4]
        for i in range(n):
            rk4_stages(model_test_row, model_id, x, u, p, c, h, i, k1, k2, k3, k4, t)


def check_parameters(model_id: int, p: np.ndarray) -> None:
    """``ValueError`` unless ``p`` is a finite parameter vector of the length model ``model_id``
    reads (the output of the model's ``pack_*`` function)."""
    name = _NAMES[model_id]
    if p.ndim != 1:
        raise shape_error(f"p of model {name!r}", "(n_parameters,)", p.shape)
    if model_id == VMM:
        vmm.check_packed(p)
    elif p.size != _PARAMETER_COUNTS[model_id]:
        raise ValueError(
            f"p of model {name!r} must have {_PARAMETER_COUNTS[model_id]} entries (its pack_* "
            f"function's output), got {p.size}"
        )
    require_finite(p, f"p of model {name!r}")


def _kernel_args(
    model_id: Any, x: Any, u: Any, p: Any, c: Any
) -> tuple[int, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The checked arguments of :func:`rhs` and :func:`rk4_step` (``x`` must already be a
    writable float64 array: both write into arrays the caller owns)."""
    if (
        isinstance(model_id, bool)
        or not isinstance(model_id, int | np.integer)
        or not (0 <= model_id < len(_NAMES))
    ):
        raise ValueError(f"model_id must be one of {dict(enumerate(_NAMES))}, got {model_id!r}")
    model_id = int(model_id)
    nx, nu = STATE_COUNTS[model_id], INPUT_COUNTS[model_id]
    if not (
        type(x) is np.ndarray and x.dtype == np.float64 and x.flags.writeable
        and x.flags.c_contiguous
    ):  # fmt: skip
        raise TypeError(
            "x must be a writable float64 array in C order (the kernels write into it), got "
            f"{type(x).__name__}" + (f" of dtype {x.dtype}" if isinstance(x, np.ndarray) else "")
        )
    if x.ndim != 2 or x.shape[1] != nx:
        raise shape_error("x", f"(n, {nx})", x.shape, f" for model {_NAMES[model_id]!r}")
    n = x.shape[0]
    u = np.ascontiguousarray(real_array(u, "u"))
    if u.shape != (n, nu):
        raise shape_error("u", f"({n}, {nu})", u.shape, " (one input row per state row)")
    c = np.ascontiguousarray(real_array(c, "c"))
    if c.shape != (n, 2):
        raise shape_error("c", f"({n}, 2)", c.shape, " (north/east current per state row)")
    p = real_array(p, "p")
    check_parameters(model_id, p)
    if p.flags.writeable:  # the kernels are compiled for a read-only parameter vector
        p = p.view()
        p.flags.writeable = False
    for arr, name in ((x, "x"), (u, "u"), (c, "c")):
        require_finite(arr, name)
    return model_id, x, u, p, c


def rhs(model_id: int, x: np.ndarray, u: Any, p: Any, c: Any, out: np.ndarray) -> None:
    """Batched state derivative ``out = f(x, u, p, c)`` of model ``model_id``, checked.

    Parameters
    ----------
    model_id : int
        :data:`MODEL_IDS` value of the model.
    x : numpy.ndarray
        States, float64 ``(n, nx)``.
    u : array_like
        Inputs ``(n, nu)``.
    p : array_like
        The model's packed parameters (``pack_nomoto``, ``pack_rvg``, ``pack_mmg``,
        ``pack_vmm``).
    c : array_like
        North/east current [m/s], ``(n, 2)``.
    out : numpy.ndarray
        Writable float64 ``(n, nx)`` array that receives ``x'``.

    Raises
    ------
    TypeError, ValueError
        Naming the argument whose type, shape or values do not fit the model.
    """
    model_id, x, u, p, c = _kernel_args(model_id, np.ascontiguousarray(real_array(x, "x")),
                                        u, p, c)  # fmt: skip
    if not (
        type(out) is np.ndarray and out.dtype == np.float64 and out.flags.writeable
        and out.flags.c_contiguous and out.shape == x.shape
    ):  # fmt: skip
        got = out.shape if isinstance(out, np.ndarray) else type(out).__name__
        raise ValueError(
            f"out must have shape {x.shape} (writable float64, C order) like x, got {got}"
        )
    rhs_kernel(model_id, x, u, p, c, out)


def rk4_step(model_id: int, x: np.ndarray, u: Any, p: Any, c: Any, h: float) -> None:
    """Advance every row of ``x`` in place by one RK4 step of ``h`` [s], checked.

    The arguments are those of :func:`rhs` (``x`` a writable float64 ``(n, nx)`` array in C
    order, updated in place); ``h`` is a finite step > 0 s. The step is not checked against
    the model's stable step here (:meth:`shipgym.models.ShipModel.step` checks it against the
    stable step at rest, :meth:`~shipgym.models.ShipModel.stable_step`).

    Raises
    ------
    TypeError, ValueError
        Naming the argument whose type, shape or values do not fit the model.
    """
    h = step_size(h)
    model_id, x, u, p, c = _kernel_args(model_id, x, u, p, c)
    rk4_step_kernel(model_id, x, u, p, c, h)


def rk4_amplification(z: np.ndarray) -> np.ndarray:
    """RK4's growth per step, ``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24`` at ``z = h lambda``."""
    return 1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0)))


_RAY = np.linspace(0.0, 3.0, 301)[1:]  # the RK4 region lies inside |z| < 2.97


def rk4_stable_step(eigenvalues: Any) -> float:
    """Largest step [s] for which RK4 keeps every decaying mode ``eigenvalues`` [1/s] decaying.

    For each eigenvalue ``lambda`` with ``Re(lambda) <= 0`` (growing modes grow in the physics
    too, zero ones are integrators such as position and heading) the largest ``h`` with
    ``|R(s lambda)| <= 1`` for all ``s <= h`` (module docstring); the minimum over the
    eigenvalues, ``inf`` when no eigenvalue limits the step. Purely real: ``2.785 / |lambda|``.

    Raises
    ------
    ValueError
        For a NaN or infinite eigenvalue.
    """
    lam = np.asarray(eigenvalues, dtype=np.complex128).ravel()
    if not np.isfinite(lam).all():
        raise ValueError(f"eigenvalues must be finite, got {lam[~np.isfinite(lam)][0]!r}")
    mag = np.abs(lam)
    if mag.size == 0 or mag.max() == 0.0:
        return math.inf
    keep = (mag > 1e-9 * mag.max()) & (lam.real <= 1e-9 * mag)
    if not keep.any():
        return math.inf
    d = lam[keep] / mag[keep]
    tol = 1.0 + 1e-9
    bad = np.abs(rk4_amplification(_RAY[None, :] * d[:, None])) > tol
    has = bad.any(axis=1)
    first = bad.argmax(axis=1)
    hi = _RAY[first]
    lo = np.where(first > 0, _RAY[np.maximum(first - 1, 0)], 0.0)
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        out = np.abs(rk4_amplification(mid * d)) > tol
        hi = np.where(out, mid, hi)
        lo = np.where(out, lo, mid)
    limits = np.where(has, lo, np.inf) / mag[keep]
    return float(limits.min())

"""Sine, cosine and arctangent as straight-line arithmetic, so that batch loops vectorise.

The physics kernels loop over a block of ships (:mod:`shipgym.models.integrate`). A call to the
C library's ``sin``, ``cos`` or ``atan2`` inside such a loop keeps the compiler from turning
it into SIMD code (there is no vector maths library behind Numba here), and those calls would
dominate the step. These functions are plain polynomials and selects, inlined into the
caller, so the loop over ships compiles to vector instructions; they are also used by the
single ship, which is a block of one, so every user of a model gets the same numbers.

Accuracy: within 2 units in the last place of the C library's results for ``|x| < 1e5``
(checked in the tests over the whole range the models meet: headings of many turns, pod and
rudder angles), NaN for NaN and infinite arguments (where ``math.sin`` would raise).

* :func:`sincos`: Cody-Waite reduction by ``pi/2`` in three parts (the constants of fdlibm's
  ``__ieee754_rem_pio2``, exact products for ``|k| < 2^20``) and fdlibm's minimax kernels
  ``__kernel_sin``/``__kernel_cos`` on ``[-pi/4, pi/4]``; quadrant by selects. Beyond
  ``|x| ~ 1e6`` rad the reduction loses digits (the C library switches to Payne-Hanek there);
  no ship state reaches it.
* :func:`atan2`: Cephes' ``atan`` (rational approximation after reduction to ``|t| <= 0.66``
  with ``tan(3 pi/8)`` and ``pi/4`` splits) and the quadrant rules of C's ``atan2`` for finite
  arguments.
"""

from __future__ import annotations

import math

from shipgym.models._jit import row_kernel

# Cody-Waite pi/2: fdlibm's pio2_1 (33 bits) and its tail, pio2_2 (33 bits) and its tail
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
_INV_PIO2 = 6.36619772367581382433e-01
#: ``(v + _ROUND) - _ROUND`` rounds ``|v| < 2^51`` to the nearest integer (no library call)
_ROUND = 6755399441055744.0

# fdlibm __kernel_sin / __kernel_cos on [-pi/4, pi/4]
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11


@row_kernel
def sincos(x):
    """``(sin(x), cos(x))`` of a float [rad] without a library call (module docstring)."""
    k = (x * _INV_PIO2 + _ROUND) - _ROUND  # nearest multiple of pi/2, as a float
    # fdlibm's two-step reduction, both steps always (no branch): y = x - k pi/2
    t = x - k * _PIO2_1
    w = k * _PIO2_2
    r = t - w
    w = k * _PIO2_2T - ((t - r) - w)
    y = r - w
    z = y * y
    s = y + y * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    hz = 0.5 * z
    wc = 1.0 - hz
    poly = _C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6))))
    c = wc + (((1.0 - wc) - hz) + z * z * poly)
    # quadrant k mod 4 = 2 hi + odd, applied by exact multiplications by 0 and +-1 rather than
    # branches (branches in the loop body keep it from vectorising); NaN for NaN or inf
    m = k - 4.0 * ((0.25 * k - 0.375 + _ROUND) - _ROUND)
    hi = (0.5 * m - 0.25 + _ROUND) - _ROUND
    odd = m - 2.0 * hi
    sign = 1.0 - 2.0 * hi
    sin_x = (s * (1.0 - odd) + c * odd) * sign
    cos_x = (c * (1.0 - odd) - s * odd) * sign
    return sin_x, cos_x


# Cephes atan: tan(3 pi/8), the low bits of pi/2, and the rational approximation on |t| <= 0.66
_T3P8 = 2.41421356237309504880
_MOREBITS = 6.123233995736765886130e-17
_P0, _P1, _P2, _P3, _P4 = (
    -8.750608600031904122785e-1, -1.615753718733365076637e1, -7.500855792314704667340e1,
    -1.228866684490136173410e2, -6.485021904942025371773e1,
)  # fmt: skip
_Q0, _Q1, _Q2, _Q3, _Q4 = (
    2.485846490142306297962e1, 1.650270098316988542046e2, 4.328810604912902668951e2,
    4.853903996359136964868e2, 1.945506571482613964425e2,
)  # fmt: skip


@row_kernel
def atan_positive(a):
    """``atan(a)`` for ``a >= 0`` (including ``inf``), without a library call."""
    big = a > _T3P8
    mid = a > 0.66
    t = -1.0 / a if big else (a - 1.0) / (a + 1.0) if mid else a
    base = 0.5 * math.pi if big else 0.25 * math.pi if mid else 0.0
    extra = _MOREBITS if big else 0.5 * _MOREBITS if mid else 0.0
    z = t * t
    num = (((_P0 * z + _P1) * z + _P2) * z + _P3) * z + _P4
    den = ((((z + _Q0) * z + _Q1) * z + _Q2) * z + _Q3) * z + _Q4
    return base + ((t * (z * num / den) + t) + extra)


@row_kernel
def atan2(y, x):
    """``atan2(y, x)`` [rad] in ``[-pi, pi]`` for finite ``y``, ``x`` (C's quadrant rules,
    signed zeros included), without a library call."""
    ay = abs(y)
    ax = abs(x)
    a = atan_positive(ay / ax if ay != 0.0 else 0.0)  # ay / 0 = inf: pi/2
    left = x < 0.0 or (x == 0.0 and math.copysign(1.0, x) < 0.0)
    return math.copysign(math.pi - a if left else a, y)

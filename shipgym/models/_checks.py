"""Argument checks shared by every Python entry point of :mod:`shipgym.models`.

Numba kernels do no bounds checking: a kernel handed an array with too few rows reads (or
writes) past it, and NaN or infinite values flow through the physics without a word. Every
public function that hands arrays to a kernel therefore converts and checks them here first, in
Python, and raises ``TypeError`` (not real numbers) or ``ValueError`` (wrong shape, not finite,
out of range) with a message that names the argument, what it was and what was expected.

Pure Python and NumPy: nothing here is compiled.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from typing import Any

import numpy as np

#: dtype kinds that hold real numbers (signed and unsigned integers, floats); ``bool`` is not
#: one of them: a boolean state, input or current is a bug, not a value.
_REAL_KINDS = frozenset("iuf")


def real_array(value: Any, name: str) -> np.ndarray:
    """``value`` as a float64 array (a view when it already is one).

    Raises
    ------
    TypeError
        When ``value`` does not hold real numbers (bool, complex, strings, objects that are not
        numbers).
    """
    if type(value) is np.ndarray and value.dtype == np.float64:
        return value
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError, OverflowError) as exc:  # ragged lists, huge ints
        raise TypeError(
            f"{name} must be an array of real numbers, got {type(value).__name__} ({exc})"
        ) from None
    kind = arr.dtype.kind
    if kind in _REAL_KINDS:
        return arr.astype(np.float64, copy=False)
    if kind == "O":
        try:
            return arr.astype(np.float64)
        except (TypeError, ValueError, OverflowError):
            pass
    raise TypeError(
        f"{name} must be an array of real numbers, got dtype {arr.dtype} ({short_repr(value)})"
    )


def require_finite(arr: np.ndarray, name: str, columns: Sequence[str] | None = None) -> None:
    """``ValueError`` naming the first NaN or infinite entry of ``arr`` (and its column)."""
    if np.isfinite(arr).all():
        return
    index = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
    where = f"index {index if len(index) != 1 else index[0]}"
    if arr.ndim == 2 and arr.shape[0] > 1:
        where = f"row {index[0]}, column {index[1]}"
    if columns is not None and arr.ndim >= 1 and len(columns) == arr.shape[-1]:
        where += f" ({columns[index[-1]]!r})"
    raise ValueError(f"{name} must be finite, got {arr[index]!r} at {where}")


def step_size(dt: Any, name: str = "dt") -> float:
    """A time step as a float: a real number, finite and > 0 [s].

    Raises
    ------
    TypeError
        When ``dt`` is not a real number (a string, ``None``, a bool, an array of more than
        one value).
    ValueError
        When it is NaN, infinite, zero or negative.
    """
    if type(dt) is float and 0.0 < dt < math.inf:  # the usual case, fast
        return dt
    if isinstance(dt, np.ndarray) and dt.ndim == 0 and dt.dtype.kind in _REAL_KINDS:
        dt = dt.item()
    return positive_number(dt, name, "a real number of seconds", "a finite step > 0 s")


def positive_number(
    value: Any,
    name: str,
    kind: str = "a real number",
    expected: str = "a finite number > 0",
) -> float:
    """A real, finite number > 0 as a float: ``TypeError`` ``"<name> must be <kind>"``
    otherwise, ``ValueError`` ``"<name> must be <expected>"`` for NaN, inf, zero or less."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be {kind}, got {short_repr(value)}")
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{name} must be {expected}, got {v!r}")
    return v


def count(value: Any, name: str, minimum: int, maximum: int) -> int:
    """An integer in ``[minimum, maximum]`` (``TypeError`` for a non-integer)."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {short_repr(value)}")
    n = int(value)
    if not minimum <= n <= maximum:
        raise ValueError(f"{name} must be an integer in [{minimum}, {maximum}], got {n}")
    return n


def shape_error(name: str, expected: str, got: tuple[int, ...], hint: str = "") -> ValueError:
    """The one wording of a shape mismatch: ``"<name> must have shape <expected>, got <got>"``."""
    return ValueError(f"{name} must have shape {expected}{hint}, got {got}")


def short_repr(value: Any) -> str:
    """``repr(value)``, cut to 60 characters for an error message."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."

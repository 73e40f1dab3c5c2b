"""One PCG64 random stream per sub-env, drawn for many sub-envs in one compiled pass.

Sub-env ``i`` of a vector env reset with seed ``s`` must draw exactly what a single env reset
with seed ``s + i`` draws from Gymnasium's ``np_random(s + i)`` (a NumPy ``Generator`` on a
``PCG64`` bit generator), as ``SyncVectorEnv`` does. Holding one ``Generator`` per sub-env
makes every autoreset a Python loop over the rows being reset. :class:`RowStreams` holds the
same PCG64 states as arrays and advances any set of rows in one compiled loop, producing the
numbers ``Generator.random`` produces, bit for bit.

PCG64 (O'Neill 2014, NumPy's default): a 128-bit linear congruential state
``s <- s * M + inc (mod 2^128)`` with NumPy's multiplier ``M``, output ``rotr64(hi ^ lo,
hi >> 58)`` of the new state (XSL-RR); ``random()`` is ``(out >> 11) * 2^-53``. The 128-bit
arithmetic is done in 64-bit halves.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from gymnasium.utils import seeding

from shipgym.models._jit import kernel, row_kernel

_MASK64 = (1 << 64) - 1
_MULT = 0x2360ED051FC65DA44385DF649FCCF645  # NumPy's PCG64 multiplier
_MULT_HI = np.uint64(_MULT >> 64)
_MULT_LO = np.uint64(_MULT & _MASK64)
_M32 = np.uint64(0xFFFFFFFF)
_S32 = np.uint64(32)
_S11 = np.uint64(11)
_S58 = np.uint64(58)
_S64 = np.uint64(64)
_ONE = np.uint64(1)
_SCALE = 1.0 / 9007199254740992.0  # 2^-53


@row_kernel
def _mul_hi(a, b):
    """High 64 bits of the 128-bit product of two uint64."""
    a_lo = a & _M32
    a_hi = a >> _S32
    b_lo = b & _M32
    b_hi = b >> _S32
    lo_lo = a_lo * b_lo
    hi_lo = a_hi * b_lo
    lo_hi = a_lo * b_hi
    hi_hi = a_hi * b_hi
    cross = (lo_lo >> _S32) + (hi_lo & _M32) + lo_hi
    return (hi_lo >> _S32) + (cross >> _S32) + hi_hi


@kernel
def _draw(state, rows, out):
    """Advance the streams of ``rows`` and fill ``out[k, :]`` from the stream of ``rows[k]``."""
    for k in range(rows.shape[0]):
        i = rows[k]
        hi = state[i, 0]
        lo = state[i, 1]
        inc_hi = state[i, 2]
        inc_lo = state[i, 3]
        for j in range(out.shape[1]):
            # s * M + inc, mod 2^128
            new_lo = lo * _MULT_LO
            new_hi = _mul_hi(lo, _MULT_LO) + lo * _MULT_HI + hi * _MULT_LO
            lo = new_lo + inc_lo
            hi = new_hi + inc_hi + (_ONE if lo < new_lo else np.uint64(0))
            x = hi ^ lo
            rot = hi >> _S58
            word = (x >> rot) | (x << ((_S64 - rot) & np.uint64(63)))
            out[k, j] = np.float64(word >> _S11) * _SCALE
        state[i, 0] = hi
        state[i, 1] = lo


class RowStreams:
    """The PCG64 streams of ``n`` sub-envs.

    Parameters
    ----------
    n : int
        Number of streams (sub-envs).
    seeds : sequence of int or None, optional
        Seed of each stream, as for Gymnasium's ``np_random``; default (or a ``None`` entry)
        fresh entropy.
    """

    def __init__(self, n: int, seeds: Sequence[int | None] | None = None) -> None:
        self.state = np.zeros((n, 4), dtype=np.uint64)
        self.seed([None] * n if seeds is None else seeds)

    def seed(self, seeds: Sequence[int | None]) -> None:
        """Seed stream ``i`` as Gymnasium's ``np_random(seeds[i])`` is seeded."""
        if len(seeds) != self.state.shape[0]:
            raise ValueError(f"seed list must have {self.state.shape[0]} entries, got {len(seeds)}")
        for i, s in enumerate(seeds):
            self.set_generator(i, seeding.np_random(s)[0])

    def set_generator(self, i: int, generator: np.random.Generator) -> None:
        """Continue stream ``i`` from the current state of a PCG64 ``generator``."""
        st = generator.bit_generator.state
        if st["bit_generator"] != "PCG64":
            raise ValueError(f"stream {i}: expected a PCG64 generator, got {st['bit_generator']}")
        value, inc = st["state"]["state"], st["state"]["inc"]
        self.state[i] = (value >> 64, value & _MASK64, inc >> 64, inc & _MASK64)

    def generator(self, i: int) -> np.random.Generator:
        """A NumPy ``Generator`` that continues stream ``i`` (a copy: drawing from it does not
        advance the stream)."""
        hi, lo, inc_hi, inc_lo = (int(v) for v in self.state[i])
        bit = np.random.PCG64()
        bit.state = {
            "bit_generator": "PCG64",
            "state": {"state": (hi << 64) | lo, "inc": (inc_hi << 64) | inc_lo},
            "has_uint32": 0,
            "uinteger": 0,
        }
        return np.random.Generator(bit)

    def random(self, rows: np.ndarray, size: int) -> np.ndarray:
        """``(len(rows), size)`` uniform numbers in [0, 1): row ``k`` is what
        ``Generator.random(size)`` of stream ``rows[k]`` gives, and the streams advance."""
        out = np.empty((len(rows), size))
        _draw(self.state, np.asarray(rows, dtype=np.int64), out)
        return out

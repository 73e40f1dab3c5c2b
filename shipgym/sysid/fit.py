"""Batch identification of the Nomoto-family yaw models from a manoeuvre record.

Every function takes plain arrays ``(t, delta, psi, r)`` (and optionally ``U``) in the project's
units and sign convention: time [s], rudder ``delta`` [rad, positive gives a starboard turn],
heading ``psi`` [rad], yaw rate ``r`` [rad/s], speed ``U`` [m/s]. They therefore work on any
record (a ``shipgym.sysid`` data record, a simulated :class:`shipgym.models.SimulationResult`,
or columns read by hand) without importing a loader.

Two estimators are offered.

**Equation error** (seed 000, linear least squares on the model's regression form). With
``r'``, ``r''`` and ``delta'`` from a Savitzky-Golay smoothing differentiator
(:func:`scipy.signal.savgol_filter`, cubic, ``window`` samples, the same filter applied to every
signal so that the linear equations still hold exactly for the filtered signals):

* ``nomoto1`` (seed 000, ``K delta = r + T r'``): ``r' = b delta + a r [+ c]``,
  ``T = -1/a``, ``K = b T``, rudder offset ``delta0 = c / b``;
* ``nomoto2`` (seed 004 eq. 1, seed 000 with ``T2``):
  ``r'' = c1 r' + c0 r + cd delta + cdd delta' [+ c]``, ``T1 T2 = -1/c0``,
  ``T1 + T2 = -c1 T1 T2``, ``K = cd T1 T2``, ``T3 = cdd / cd``, ``delta0 = c / cd``;
* ``norrbin`` (seed 002 eq. 4-5, ``r' = a3 r^3 + a2 r|r| + a1 r + a0 + b delta``):
  ``a_i = -n_i / T``, ``b = K / T`` with the normalisation ``|n1| = 1``, so ``T = 1/|a1|``,
  ``n1 = -sign(a1)``, ``n_i = -a_i T``, ``K = b T`` (``a0``, i.e. ``n0``, only with ``bias``);
* ``bech`` (seed 004 eq. 3): ``r'' = c1 r' + h0 + h1 r + h2 r|r| + h3 r^3 + cd delta
  + cdd delta'`` with ``h_i = -K b_i / (T1 T2)`` and the normalisation ``K b1 = ±1`` (so
  ``b1 = 1/K`` reproduces the second-order Nomoto model), ``T1 T2 = 1/|h1|``.

The quadratic terms use ``r|r|`` as :mod:`shipgym.models.nomoto` does (the seeds write
``r^2``). Standard errors of the regression coefficients are ``s^2 (X^T X)^-1`` with ``s^2``
the residual variance, mapped to the physical parameters by the delta method (numerical
Jacobian of the map). They assume white equation errors; the differentiated signals are
coloured by the filter, so they are optimistic, and noise on ``r`` biases equation-error
estimates (errors in variables). Use the output-error fit for final values.

**Output error** (simulation error, seed 000 "simulate with the estimated coefficients"):
:func:`scipy.optimize.least_squares` on the free-run simulation that replays the recorded
rudder, with residuals on ``psi`` (wrapped with the smallest signed angle) and ``r``, each
divided by its noise level; the initial heading and yaw rate (and ``r'`` for the second-order
models) are free parameters. The fit starts from the equation-error estimate, then re-weights
once with the per-channel residual RMS (maximum likelihood for Gaussian noise of unknown
variance per channel). Standard errors are ``s^2 (J^T J)^-1`` at the optimum; they hold for
white measurement noise and are optimistic when the residual is dominated by model error.

**Excitation.** Both fits (and :func:`shipgym.sysid.engine.identify`, for every model family)
refuse a record whose rudder never moves (stays at zero, or is held for the whole record while
the ship is already turning: a steady or decaying turn) or whose heading never changes
(:func:`check_excitation`: spread between the 1st and 99th percentiles above
:data:`RUDDER_EXCITATION` / :data:`HEADING_EXCITATION` and above 6 times the noise estimated
from second differences; a held rudder only with a straight start,
:data:`STRAIGHT_START_FRACTION`) with ``ValueError("not identifiable: no excitation: ...")``:
without input or response the gain and time constant are not identifiable and the optimiser returns
meaningless values (T of 1e9 s, K of 1e-40 1/s).

**Rudder replay through the shared kernels.** The simulation runs
:func:`shipgym.models.integrate.rk4_block` (the one model kernel and RK4 integrator) in a
loop over the record, compiled once per model so that the model dispatch folds away. At each
sample the rudder state is set to the recorded ``delta[k]`` and the steering gear is given a
time constant of ``1e6`` s, no angle or rate limit and the command
``delta[k] + T_delta (delta[k+1] - delta[k]) / h``, so inside each step the rudder follows
the straight line between the samples (first-order hold, relative error below ``h / 1e6``)
and ``delta'`` (used by the ``T3`` term) is the slope of the record. The speed ``U`` is held
at the recorded value the same way (surge gain 1, time constant ``1e6`` s); it does not
affect the yaw models. Irregular sampling is handled (the step is ``t[k+1] - t[k]``). The
fitted :meth:`FitResult.model` uses the real (given) gear and surge.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares
from scipy.signal import savgol_filter

from shipgym.models import (
    BechParams,
    Nomoto1Params,
    Nomoto2Params,
    NorrbinParams,
    ShipModel,
    SteeringGear,
    SurgeModel,
    make_model,
)
from shipgym.models._jit import kernel, row_kernel
from shipgym.models.base import MODEL_NAMES
from shipgym.models.integrate import BECH, NC, NOMOTO1, NOMOTO2, NORRBIN, rk4_block_nomoto
from shipgym.models.model_file import with_rudder_offset
from shipgym.models.nomoto import (
    IDELTA,
    IPSI,
    IR,
    IRDOT,
    IU,
    P_YAW,
    bech_col,
    nomoto1_col,
    nomoto2_col,
    norrbin_col,
    pack_nomoto,
)
from shipgym.sysid.batched import SideBySide, lanes

__all__ = [
    "FIT_MODELS",
    "HEADING_EXCITATION",
    "RUDDER_EXCITATION",
    "STRAIGHT_START_FRACTION",
    "TIME_CONSTANT_FLOOR",
    "YAW_RATE_EXCITATION",
    "FitResult",
    "SysidWarning",
    "check_excitation",
    "condition_number",
    "excitation_problems",
    "fit_equation_error",
    "fit_output_error",
    "no_excitation_error",
    "regression_data",
    "regression_to_params",
    "replay",
]

FIT_MODELS = ("nomoto1", "nomoto2", "norrbin", "bech")
_PARAM_CLASS: dict[str, type] = {
    "nomoto1": Nomoto1Params,
    "nomoto2": Nomoto2Params,
    "norrbin": NorrbinParams,
    "bech": BechParams,
}
_SECOND_ORDER = ("nomoto2", "bech")
#: Steering-gear and surge time constant [s] of the replay (see the module docstring).
_REPLAY_TC = 1.0e6
_REPLAY_GEAR = SteeringGear(time_constant=_REPLAY_TC, max_angle=1.0e12, max_rate=1.0e12)
_REPLAY_SURGE = SurgeModel(gain=1.0, time_constant=_REPLAY_TC)


class SysidWarning(UserWarning):
    """A record was repaired (e.g. resampled) before fitting."""


# --------------------------------------------------------------------------------------------
# input checks


def _as_1d(name: str, a: npt.ArrayLike, n: int | None = None) -> np.ndarray:
    arr = np.asarray(a, dtype=np.float64)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got shape {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(f"{name} must have the same length as t ({n}), got {arr.shape[0]}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or infinite values; drop or repair those samples")
    return arr


def _check_time(t: npt.ArrayLike, min_samples: int) -> np.ndarray:
    t = _as_1d("t", t)
    if t.shape[0] < min_samples:
        raise ValueError(f"need at least {min_samples} samples, got {t.shape[0]}")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t must be strictly increasing (time [s])")
    return t


RUDDER_EXCITATION: float = math.radians(0.2)
"""Smallest rudder spread [rad] (1st to 99th percentile, and 6 times the noise) that counts as
a moving rudder; below it the yaw dynamics are not identifiable (no input)."""

HEADING_EXCITATION: float = math.radians(0.5)
"""Smallest heading spread [rad] (1st to 99th percentile, and 6 times the noise) that counts as
a turning ship; below it the yaw dynamics are not identifiable (no response)."""

YAW_RATE_EXCITATION: float = math.radians(0.05)
"""Smallest yaw-rate spread [rad/s] that counts as a response when no heading is given."""

STRAIGHT_START_FRACTION: float = 0.2
"""A rudder held for a whole record identifies the yaw model only as the step response of a
ship that starts on a straight course: its initial yaw rate within this fraction of the yaw
rate's spread of zero. A ship already turning when the record starts (a steady turn, or a turn
whose yaw rate decays as the ship loses speed) shows no response to the rudder."""


def _spread_and_noise(a: np.ndarray) -> tuple[float, float]:
    """Spread (1st to 99th percentile) and white-noise level (from second differences)."""
    lo, hi = np.percentile(a, [1.0, 99.0])
    if a.size < 5:
        return float(hi - lo), 0.0
    d2 = np.diff(a, 2)
    noise = 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / math.sqrt(6.0)
    return float(hi - lo), noise


def excitation_problems(
    delta: npt.ArrayLike, psi: npt.ArrayLike | None = None, r: npt.ArrayLike | None = None
) -> list[tuple[str, str]]:
    """What is missing for a yaw model to be identifiable from a record (empty: nothing).

    The rudder must move (spread above :data:`RUDDER_EXCITATION` and above 6 times its noise;
    a rudder held away from zero is enough only for a step response from a straight course:
    the yaw rate changes and starts within :data:`STRAIGHT_START_FRACTION` of its spread of
    zero, as after a rudder step; not in a steady turn, nor in a turn already under way whose
    yaw rate changes with the speed) and the ship must turn (heading spread
    above :data:`HEADING_EXCITATION`, or without a heading the yaw-rate spread above
    :data:`YAW_RATE_EXCITATION`, again above 6 times the noise). Without either no fit can
    tell the gain from the time constant: it returns meaningless numbers (T of 1e9 s, K of
    1e-40 1/s).

    Parameters
    ----------
    delta : array_like
        Rudder [rad].
    psi, r : array_like, optional
        Heading [rad] and yaw rate [rad/s].

    Returns
    -------
    list of (str, str)
        One ``(kind, phrase)`` per missing excitation: kind ``"rudder"`` (the rudder never
        moves, or is held in a steady or decaying turn) or ``"turn"`` (the heading, or the yaw rate,
        never changes), and a phrase such as ``"the rudder never moves (...)"``.
    """
    out = []
    d = np.asarray(delta, dtype=np.float64)
    if d.size:
        spread, noise = _spread_and_noise(d)
        limit = max(RUDDER_EXCITATION, 6.0 * noise)
        if not spread > limit:
            level = float(np.median(d))
            held = (
                f"delta spans {math.degrees(spread):.3g} deg between its 1st and 99th "
                f"percentiles around {math.degrees(level):.3g} deg; needs more than "
                f"{math.degrees(RUDDER_EXCITATION):.3g} deg"
                + (f" and 6 times its noise {math.degrees(noise):.3g} deg" if noise else "")
            )
            if abs(level) <= limit:  # no input at all
                out.append(("rudder", f"the rudder never moves ({held})"))
            elif r is not None:  # a held rudder identifies the model only through a transient
                r_arr = np.asarray(r, dtype=np.float64)
                r_spread, r_noise = _spread_and_noise(r_arr)
                r_start = float(np.median(r_arr[: max(5, r_arr.size // 50)]))
                if not r_spread > max(YAW_RATE_EXCITATION, 6.0 * r_noise):
                    out.append(
                        (
                            "rudder",
                            f"the rudder never moves and the yaw rate never changes (a steady "
                            f"turn: {held}; r spans {math.degrees(r_spread):.3g} deg/s, needs "
                            f"more than {math.degrees(YAW_RATE_EXCITATION):.3g} deg/s)",
                        )
                    )
                elif abs(r_start) > STRAIGHT_START_FRACTION * r_spread + 3.0 * r_noise:
                    out.append(
                        (
                            "rudder",
                            f"the rudder never moves and the ship is already turning when the "
                            f"record starts (a steady or decaying turn: {held}; r starts at "
                            f"{math.degrees(r_start):.3g} deg/s and spans "
                            f"{math.degrees(r_spread):.3g} deg/s: its change is not a response "
                            f"to the rudder; a held rudder identifies a ship only from a "
                            f"straight start, within {STRAIGHT_START_FRACTION:g} of that span of "
                            f"zero)",
                        )
                    )
    checks = []
    if psi is not None:
        checks.append(("heading never changes", "psi", psi, HEADING_EXCITATION, "deg"))
    elif r is not None:
        checks.append(("yaw rate never changes", "r", r, YAW_RATE_EXCITATION, "deg/s"))
    for what, name, values, floor, unit in checks:
        arr = np.asarray(values, dtype=np.float64)
        if arr.size == 0:
            continue
        spread, noise = _spread_and_noise(arr)
        if not spread > max(floor, 6.0 * noise):
            text = (
                f"the {what} ({name} spans {math.degrees(spread):.3g} {unit} between its 1st and"
                f" 99th percentiles; needs more than {math.degrees(floor):.3g} {unit}"
                + (f" and 6 times its noise {math.degrees(noise):.3g} {unit}" if noise else "")
                + ")"
            )
            out.append(("turn", text))
    return out


def check_excitation(
    delta: npt.ArrayLike, psi: npt.ArrayLike | None = None, r: npt.ArrayLike | None = None
) -> None:
    """Raise when a record cannot identify a yaw model (see :func:`excitation_problems`).

    Raises
    ------
    ValueError
        ``"not identifiable: no excitation: the rudder never moves (...)"`` naming every
        missing excitation.
    """
    problems = excitation_problems(delta, psi, r)
    if problems:
        raise no_excitation_error([text for _, text in problems])


_check_excitation = check_excitation  # for functions with a ``check_excitation`` flag


def no_excitation_error(problems: Sequence[str]) -> ValueError:
    """The error for a record without excitation, naming each of ``problems``."""
    return ValueError(
        "not identifiable: no excitation: "
        + " and ".join(problems)
        + "; expected a manoeuvre that moves the rudder and turns the ship (zigzag, turning"
        " circle, pull-out or random rudder)"
    )


def _check_model(model: str) -> str:
    if model not in FIT_MODELS:
        raise ValueError(f"unknown model {model!r}; expected one of {FIT_MODELS}")
    return model


def _uniform(t: np.ndarray, *signals: np.ndarray) -> tuple[np.ndarray, ...]:
    """Return ``t`` and ``signals`` on a uniform grid (warns when it has to resample)."""
    h = np.diff(t)
    dt = float(np.median(h))
    if np.max(np.abs(h - dt)) <= 1e-3 * dt:
        return (t, *signals)
    n = round((t[-1] - t[0]) / dt) + 1
    tu = t[0] + dt * np.arange(n)
    tu = tu[tu <= t[-1] + 1e-9 * dt]
    warnings.warn(
        f"irregular sampling (steps {h.min():.4g}..{h.max():.4g} s): linearly resampled to a "
        f"uniform {dt:.4g} s grid for the smoothing differentiator",
        SysidWarning,
        stacklevel=3,
    )
    return (tu, *(np.interp(tu, t, s) for s in signals))


# --------------------------------------------------------------------------------------------
# result


@dataclass
class FitResult:
    """Result of a yaw-model fit.

    Attributes
    ----------
    model_name : str
        ``"nomoto1"``, ``"nomoto2"``, ``"norrbin"`` or ``"bech"``.
    params : dataclass
        Fitted parameters (:class:`~shipgym.models.Nomoto1Params` etc.).
    values : dict
        Every estimated quantity by name: the model parameters, ``delta0`` (rudder offset [rad],
        nomoto1/nomoto2 with ``bias``) and, for output error, the initial state ``psi0``,
        ``r0`` (and ``r_dot0``).
    stderr : dict
        Standard errors of the entries of ``values`` (fixed quantities are absent).
    covariance : numpy.ndarray
        Covariance of the free quantities in the order of ``free``.
    free : tuple of str
        Names of the free quantities (the order of ``covariance``).
    x0 : numpy.ndarray
        Initial state estimate in the model's state layout (``x = y = 0``).
    rms_psi, rms_r : float
        RMS [rad, rad/s] of the free-run simulation error (replayed rudder, initial state
        ``x0``) over the record.
    r2 : float
        Coefficient of determination of the simulated ``r``.
    method : str
        ``"equation_error"`` or ``"output_error"``.
    n_samples : int
        Samples used.
    delta0 : float
        Rudder offset [rad] added to the recorded rudder (0 unless fitted).
    gear, surge : SteeringGear, SurgeModel
        Actuator models used by :meth:`model` (not identified here).
    info : dict
        Method details (regression R^2, window, optimiser status, weights...).
    """

    model_name: str
    params: Any
    values: dict[str, float]
    stderr: dict[str, float]
    covariance: np.ndarray
    free: tuple[str, ...]
    x0: np.ndarray
    rms_psi: float
    rms_r: float
    r2: float
    method: str
    n_samples: int
    delta0: float = 0.0
    gear: SteeringGear = field(default_factory=SteeringGear)
    surge: SurgeModel = field(default_factory=SurgeModel)
    info: dict[str, Any] = field(default_factory=dict)

    def model(self) -> ShipModel:
        """The fitted model, ``make_model(name, params, gear=..., surge=...)``, its rudder offset
        ``delta0`` included as the bias of the same equation
        (:func:`shipgym.models.model_file.with_rudder_offset`)."""
        name, params = with_rudder_offset(self.model_name, self.params, self.delta0)
        return make_model(name, params, gear=self.gear, surge=self.surge)

    def summary(self) -> str:
        """One line per estimate: ``name = value ± stderr``."""
        lines = [f"{self.model_name} ({self.method}, {self.n_samples} samples)"]
        for name, value in self.values.items():
            se = self.stderr.get(name)
            tail = f" ± {se:.4g}" if se is not None else " (fixed)"
            lines.append(f"  {name} = {value:.6g}{tail}")
        lines.append(f"  rms psi = {self.rms_psi:.4g} rad, rms r = {self.rms_r:.4g} rad/s")
        lines.append(f"  R^2(r) = {self.r2:.4f}")
        return "\n".join(lines)


# --------------------------------------------------------------------------------------------
# replay simulation through the shared kernels


@row_kernel
def _replay_loop(col, width, X0, delta, d0, speed, n_cmd, h, P, out):  # pragma: no cover
    nx = X0.shape[0]
    x = np.empty((nx, width))  # the variants as a block of ships (states x ships)
    u = np.zeros((2, width))
    c = np.zeros((NC, width))  # no current, no seaway load
    work = np.empty((3, nx, width))
    for b in range(width):
        for j in range(nx):
            x[j, b] = X0[j, b]
            out[0, b, j] = x[j, b]
    for k in range(h.shape[0]):
        for b in range(width):
            dl = delta[k] + d0[b]
            x[IDELTA, b] = dl
            x[IU, b] = speed[k]
            u[0, b] = dl + _REPLAY_TC * ((delta[k + 1] + d0[b]) - dl) / h[k]
            u[1, b] = n_cmd[k]
        rk4_block_nomoto(col, x, u, P, c, h[k], width, work)
        for b in range(width):
            for j in range(nx):
                out[k + 1, b, j] = x[j, b]


@row_kernel
def _replay_variants(col, X0, delta, d0, speed, n_cmd, h, P, out):  # pragma: no cover
    """One variant as a block of one (its width a compile-time constant), several as one
    block whose loops over the variants compile to SIMD code."""
    if P.shape[1] == 1:
        _replay_loop(col, 1, X0, delta, d0, speed, n_cmd, h, P, out)
    else:
        _replay_loop(col, P.shape[1], X0, delta, d0, speed, n_cmd, h, P, out)


# One compilation of the loop per model, with that model's code alone
# (:func:`~shipgym.models.integrate.rk4_block_nomoto`): about three times faster than the
# replay with the model id as a run-time argument (same arithmetic, identical results), and
# no other model's code to compile. Each is compiled on first use.
@kernel
def _replay_nomoto1(X0, delta, d0, speed, n_cmd, h, P, out):  # pragma: no cover - jit
    _replay_variants(nomoto1_col, X0, delta, d0, speed, n_cmd, h, P, out)


@kernel
def _replay_nomoto2(X0, delta, d0, speed, n_cmd, h, P, out):  # pragma: no cover - jit
    _replay_variants(nomoto2_col, X0, delta, d0, speed, n_cmd, h, P, out)


@kernel
def _replay_norrbin(X0, delta, d0, speed, n_cmd, h, P, out):  # pragma: no cover - jit
    _replay_variants(norrbin_col, X0, delta, d0, speed, n_cmd, h, P, out)


@kernel
def _replay_bech(X0, delta, d0, speed, n_cmd, h, P, out):  # pragma: no cover - jit
    _replay_variants(bech_col, X0, delta, d0, speed, n_cmd, h, P, out)


_REPLAY_KERNELS = {
    NOMOTO1: _replay_nomoto1,
    NOMOTO2: _replay_nomoto2,
    NORRBIN: _replay_norrbin,
    BECH: _replay_bech,
}


def _replay_kernel(
    model_id: int,
    x0: Sequence[np.ndarray],
    delta: np.ndarray,
    d0: Sequence[float],
    speed: np.ndarray,
    n_cmd: np.ndarray,
    h: np.ndarray,
    p: Sequence[np.ndarray],
    t_len: int,
) -> np.ndarray:
    """Replay the rudder ``delta`` with variants of the model ``model_id``: variant ``b``
    starts from ``x0[b]``, has the packed parameters ``p[b]`` and the rudder offset ``d0[b]``.
    Returns the states ``(t_len, variants, nx)``.

    At step ``k`` the rudder and speed states are set to ``delta[k] + d0``, ``speed[k]`` and
    the commands to the rudder's first-order lead ``dc`` and ``n_cmd[k]`` (module docstring),
    then one RK4 step of ``h[k]`` is taken by :func:`shipgym.models.integrate.rk4_block_nomoto`, all
    the variants as the ships of one block (padded to whole SIMD vectors,
    :func:`shipgym.sysid.batched.lanes`).
    """
    pick = lanes(len(p))
    P = np.ascontiguousarray(np.column_stack(p)[:, pick])
    P.flags.writeable = False
    X0 = np.ascontiguousarray(np.column_stack(x0)[:, pick])
    out = np.empty((t_len, pick.size, X0.shape[0]))
    d0s = np.asarray(d0, dtype=np.float64)[pick]
    # contiguous, as the kernel is compiled (a thinned record's rudder is a strided view)
    delta, speed, n_cmd, h = (np.ascontiguousarray(a) for a in (delta, speed, n_cmd, h))
    _REPLAY_KERNELS[model_id](X0, delta, d0s, speed, n_cmd, h, P, out)
    return out[:, : len(p)]


def _replay_steps(t: np.ndarray, speed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The replay's steps ``h`` [s] and the surge model's command for the recorded speed (its
    first-order lead, as the rudder's in :func:`_replay_loop`)."""
    h = np.diff(t)
    return h, speed[:-1] + _REPLAY_TC * np.diff(speed) / h


def replay(
    model_name: str,
    params: Any,
    t: npt.ArrayLike,
    delta: npt.ArrayLike,
    x0: npt.ArrayLike,
    U: npt.ArrayLike | float = 1.0,
) -> np.ndarray:
    """Free-run simulation of a yaw model that replays a recorded rudder.

    Parameters
    ----------
    model_name : str
        One of ``FIT_MODELS``.
    params : dataclass
        The model's parameters.
    t, delta : array_like
        Sample times [s] (strictly increasing, may be irregular) and rudder [rad].
    x0 : array_like
        Initial state in the model's layout (its ``delta`` and ``U`` entries are overwritten by
        the record).
    U : array_like or float
        Speed [m/s] (a constant or one value per sample); only the positions depend on it.

    Returns
    -------
    numpy.ndarray
        States, shape ``(len(t), nx)``; the rudder column is the record (first-order hold).
    """
    model_name = _check_model(model_name)
    t = _check_time(t, 2)
    delta = _as_1d("delta", delta, t.shape[0])
    speed = np.broadcast_to(np.asarray(U, dtype=np.float64), t.shape).astype(np.float64)
    if not np.all(np.isfinite(speed)):
        raise ValueError("U contains NaN or infinite values")
    nx = 7 if model_name in _SECOND_ORDER else 6
    x0 = np.asarray(x0, dtype=np.float64)
    if x0.shape != (nx,):
        raise ValueError(f"x0 must have shape ({nx},) for {model_name!r}, got {x0.shape}")
    p = pack_nomoto(params, _REPLAY_GEAR, _REPLAY_SURGE)
    p.flags.writeable = False
    return _replay_arrays(MODEL_NAMES.index(model_name), p, x0, t, delta, speed)


def _replay_arrays(
    model_id: int,
    p: np.ndarray,
    x0: np.ndarray,
    t: np.ndarray,
    delta: np.ndarray,
    speed: np.ndarray,
) -> np.ndarray:
    h, n_cmd = _replay_steps(t, speed)
    return _replay_kernel(model_id, [x0], delta, [0.0], speed, n_cmd, h, [p], t.shape[0])[:, 0]


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2.0 * np.pi) - np.pi


# --------------------------------------------------------------------------------------------
# equation error


@dataclass(frozen=True)
class RegressionData:
    """Regression form ``y = X theta`` of a yaw model over a record.

    Attributes
    ----------
    t, y, X : numpy.ndarray
        Sample times, target (``r'`` or ``r''``) and regressors (one column per name).
    names : tuple of str
        Regressor names.
    model : str
        Model name.
    bias : bool
        Whether a constant (rudder offset / ``n0`` / ``b0``) column is included.
    """

    t: np.ndarray
    y: np.ndarray
    X: np.ndarray
    names: tuple[str, ...]
    model: str
    bias: bool


def regression_data(
    t: npt.ArrayLike,
    delta: npt.ArrayLike,
    r: npt.ArrayLike,
    model: str = "nomoto1",
    *,
    bias: bool = False,
    window: int = 11,
    polyorder: int = 3,
    trim: bool = True,
) -> RegressionData:
    """Regressors of the equation-error form of ``model`` (see the module docstring).

    Parameters
    ----------
    t, delta, r : array_like
        Time [s], rudder [rad, + = starboard turn], yaw rate [rad/s]. Irregular sampling is
        resampled to the median step with a :class:`SysidWarning`.
    model : str
        One of ``FIT_MODELS``.
    bias : bool
        Add a constant regressor (rudder offset; ``n0`` for Norrbin, ``b0`` for Bech).
    window : int
        Savitzky-Golay window [samples], odd, > ``polyorder``; the filter smooths over
        ``window * dt`` seconds, which should be short against the yaw time constants.
    polyorder : int
        Savitzky-Golay polynomial order (3: exact for cubic pieces).
    trim : bool
        Drop ``window // 2`` samples at each end, where the filter extrapolates.

    Returns
    -------
    RegressionData
    """
    model = _check_model(model)
    t = _check_time(t, 3)
    delta = _as_1d("delta", delta, t.shape[0])
    r = _as_1d("r", r, t.shape[0])
    if not (isinstance(window, int | np.integer) and window % 2 == 1 and window > polyorder):
        raise ValueError(f"window must be an odd integer > polyorder={polyorder}, got {window!r}")
    if not (isinstance(polyorder, int | np.integer) and polyorder >= 2):
        raise ValueError(f"polyorder must be an integer >= 2, got {polyorder!r}")
    t, delta, r = _uniform(t, delta, r)
    n_min = window + 2 * (window // 2) + 5
    if t.shape[0] < n_min:
        raise ValueError(f"need at least {n_min} samples for window={window}, got {t.shape[0]}")
    dt = float(t[1] - t[0])

    def sg(x: np.ndarray, d: int) -> np.ndarray:
        return savgol_filter(x, window, polyorder, deriv=d, delta=dt)

    rs, r1, r2 = sg(r, 0), sg(r, 1), sg(r, 2)
    ds, d1 = sg(delta, 0), sg(delta, 1)
    one = np.ones_like(t)
    if model == "nomoto1":
        y, cols, names = r1, [ds, rs], ["delta", "r"]
    elif model == "norrbin":
        y = r1
        cols, names = [ds, rs, rs * np.abs(rs), rs**3], ["delta", "r", "r|r|", "r^3"]
    elif model == "nomoto2":
        y, cols, names = r2, [r1, rs, ds, d1], ["r_dot", "r", "delta", "delta_dot"]
    else:
        y = r2
        cols = [r1, rs, rs * np.abs(rs), rs**3, ds, d1]
        names = ["r_dot", "r", "r|r|", "r^3", "delta", "delta_dot"]
    if bias:
        cols.append(one)
        names.append("1")
    X = np.column_stack(cols)
    sl = slice(window // 2, t.shape[0] - window // 2) if trim else slice(None)
    return RegressionData(t[sl], y[sl], X[sl], tuple(names), model, bias)


def regression_to_params(
    model: str, theta: npt.ArrayLike, names: tuple[str, ...]
) -> tuple[Any, dict[str, float]]:
    """Map regression coefficients to the physical parameters.

    Parameters
    ----------
    model : str
        One of ``FIT_MODELS``.
    theta : array_like
        Coefficients in the order of ``names`` (from :func:`regression_data`).
    names : tuple of str
        Regressor names.

    Returns
    -------
    params : dataclass
        The model's parameter dataclass.
    values : dict
        Physical values by name (including ``delta0`` for nomoto1/nomoto2 with a bias).

    Raises
    ------
    ValueError
        When the coefficients do not describe a valid model (e.g. ``T <= 0`` or complex
        ``T1``, ``T2``).
    """
    c = dict(zip(names, np.asarray(theta, dtype=np.float64), strict=True))
    bias = c.get("1", 0.0)
    values: dict[str, float] = {}
    if model == "nomoto1":
        if c["r"] >= 0:
            raise ValueError(
                f"fitted r coefficient {c['r']:.4g} >= 0 gives T <= 0 (course-unstable or "
                "unidentifiable record); try the norrbin model"
            )
        T = -1.0 / c["r"]
        values = {"K": c["delta"] * T, "T": T}
        if "1" in c:
            values["delta0"] = bias / c["delta"]
        return Nomoto1Params(values["K"], values["T"]), values
    if model == "norrbin":
        if c["r"] == 0:
            raise ValueError("fitted linear coefficient a1 = 0: T is not identifiable")
        T = 1.0 / abs(c["r"])
        values = {
            "K": c["delta"] * T,
            "T": T,
            "n0": -bias * T,
            "n1": -math.copysign(1.0, c["r"]),
            "n2": -c["r|r|"] * T,
            "n3": -c["r^3"] * T,
        }
        return NorrbinParams(**values), values
    # second-order models
    lin = c["r"]
    if model == "nomoto2" and lin >= 0:
        raise ValueError(f"fitted r coefficient {lin:.4g} >= 0 gives T1 T2 <= 0")
    if lin == 0:
        raise ValueError("fitted linear coefficient is 0: T1 T2 is not identifiable")
    prod = 1.0 / abs(lin)
    total = -c["r_dot"] * prod
    disc = total**2 - 4.0 * prod
    if total <= 0 or disc < 0:
        raise ValueError(
            f"fitted T1 + T2 = {total:.4g} s, T1 T2 = {prod:.4g} s^2 have no positive real "
            "roots (oscillatory or unstable r'-r dynamics)"
        )
    T1 = 0.5 * (total + math.sqrt(disc))
    T2 = 0.5 * (total - math.sqrt(disc))
    K = c["delta"] * prod
    T3 = c["delta_dot"] / c["delta"]
    if model == "nomoto2":
        values = {"K": K, "T1": T1, "T2": T2, "T3": T3}
        params = Nomoto2Params(**values)
        if "1" in c:
            values["delta0"] = bias / c["delta"]
        return params, values
    sgn = -math.copysign(1.0, lin)  # K b1
    values = {
        "K": K,
        "T1": T1,
        "T2": T2,
        "T3": T3,
        "b0": -bias * prod / K,
        "b1": sgn / K,
        "b2": -c["r|r|"] * prod / K,
        "b3": -c["r^3"] * prod / K,
    }
    return BechParams(**values), values


def _scaled_inverse(J: np.ndarray) -> np.ndarray:
    """``(J^T J)^-1`` computed with unit-norm columns (the parameters differ by many decades)."""
    scale = np.linalg.norm(J, axis=0)
    scale[scale == 0] = 1.0
    Js = J / scale
    return np.linalg.pinv(Js.T @ Js) / np.outer(scale, scale)


def condition_number(J: np.ndarray) -> float:
    """Condition number of ``J`` with unit-norm columns (``inf`` when singular): how nearly
    the fitted quantities trade for one another, whatever their units."""
    scale = np.linalg.norm(J, axis=0)
    scale[scale == 0] = 1.0
    sv = np.linalg.svd(J / scale, compute_uv=False)
    return float(sv[0] / sv[-1]) if sv.size and sv[-1] > 0 else math.inf


def _delta_method(
    fun: Callable[[np.ndarray], dict[str, float]], theta: np.ndarray, cov: np.ndarray
) -> tuple[dict[str, float], np.ndarray, list[str]]:
    """Standard errors of ``fun(theta)`` by a central-difference Jacobian."""
    base = fun(theta)
    keys = list(base)
    J = np.zeros((len(keys), theta.size))
    for j in range(theta.size):
        hj = 1e-6 * max(abs(theta[j]), 1e-12)
        tp, tm = theta.copy(), theta.copy()
        tp[j] += hj
        tm[j] -= hj
        fp, fm = fun(tp), fun(tm)
        J[:, j] = [(fp[k] - fm[k]) / (2 * hj) for k in keys]
    cov_out = J @ cov @ J.T
    return {k: math.sqrt(max(cov_out[i, i], 0.0)) for i, k in enumerate(keys)}, cov_out, keys


def fit_equation_error(
    t: npt.ArrayLike,
    delta: npt.ArrayLike,
    r: npt.ArrayLike,
    model: str = "nomoto1",
    *,
    psi: npt.ArrayLike | None = None,
    U: npt.ArrayLike | float | None = None,
    bias: bool = False,
    window: int = 11,
    polyorder: int = 3,
    gear: SteeringGear | None = None,
    surge: SurgeModel | None = None,
) -> FitResult:
    """Equation-error (linear least squares) fit of a yaw model (seed 000, seed 002 eq. 4-5).

    Parameters
    ----------
    t, delta, r : array_like
        Time [s], rudder [rad, positive = starboard turn], yaw rate [rad/s] of one record.
    model : {"nomoto1", "nomoto2", "norrbin", "bech"}
        Model to fit.
    psi : array_like, optional
        Heading [rad]: used to report the simulation RMS (``rms_psi`` is NaN without it) and
        to refuse a record whose heading never changes.
    U : array_like or float, optional
        Speed [m/s] for the replay (positions only).
    bias : bool
        Include a constant regressor (rudder offset ``delta0``, or ``n0``/``b0``).
    window, polyorder : int
        Savitzky-Golay differentiator settings (see :func:`regression_data`).
    gear, surge : SteeringGear, SurgeModel, optional
        Actuators of the returned model (defaults otherwise).

    Returns
    -------
    FitResult
        ``info`` holds the regression coefficients, their standard errors and the regression
        ``R^2`` (of ``r'`` or ``r''``); ``x0`` is the smoothed first sample of the record.

    Raises
    ------
    ValueError
        For bad input or coefficients that do not map to a valid model.
    """
    reg = regression_data(  # checks the model, time, lengths, values and window first
        t, delta, r, model, bias=bias, window=window, polyorder=polyorder, trim=True
    )
    check_excitation(
        _as_1d("delta", delta), None if psi is None else _as_1d("psi", psi), _as_1d("r", r)
    )
    X, y = reg.X, reg.y
    n, m = X.shape
    if n <= m:
        raise ValueError(f"need more samples ({n}) than regressors ({m})")
    theta, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ theta
    s2 = float(resid @ resid) / (n - m)
    cov_theta = s2 * _scaled_inverse(X)
    if np.linalg.matrix_rank(X) < m:
        raise ValueError(
            f"regressors {reg.names} are linearly dependent on this record (not enough "
            "excitation, e.g. a constant rudder); use a richer manoeuvre or fewer terms"
        )
    params, values = regression_to_params(model, theta, reg.names)

    def mapped(th: np.ndarray) -> dict[str, float]:
        vals = regression_to_params(model, th, reg.names)[1]
        return {k: v for k, v in vals.items() if k not in ("n1", "b1")}

    stderr, cov, free = _delta_method(mapped, theta, cov_theta)
    if model == "bech":
        stderr["b1"] = values["b1"] / values["K"] * stderr["K"] if values["K"] else math.nan
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    info = {
        "theta": dict(zip(reg.names, theta.tolist(), strict=True)),
        "theta_stderr": dict(zip(reg.names, np.sqrt(np.diag(cov_theta)).tolist(), strict=True)),
        "regression_r2": 1.0 - float(resid @ resid) / ss_tot if ss_tot > 0 else math.nan,
        "window": window,
        "polyorder": polyorder,
    }
    # initial state from the smoothed record, then free-run evaluation
    t_arr = _check_time(t, 3)
    delta_arr = _as_1d("delta", delta, t_arr.shape[0])
    r_arr = _as_1d("r", r, t_arr.shape[0])
    psi_arr = None if psi is None else _as_1d("psi", psi, t_arr.shape[0])
    delta0 = values.get("delta0", 0.0)
    x0 = _initial_state(model, t_arr, r_arr, psi_arr, window, polyorder)
    result = FitResult(
        model_name=model,
        params=params,
        values=values,
        stderr=stderr,
        covariance=cov,
        free=tuple(free),
        x0=x0,
        rms_psi=math.nan,
        rms_r=math.nan,
        r2=math.nan,
        method="equation_error",
        n_samples=int(n),
        delta0=delta0,
        gear=gear or SteeringGear(),
        surge=surge or SurgeModel(),
        info=info,
    )
    _evaluate(result, t_arr, delta_arr, psi_arr, r_arr, _speed(U, t_arr))
    return result


def _speed(U: npt.ArrayLike | float | None, t: np.ndarray) -> np.ndarray:
    if U is None:
        return np.ones_like(t)
    speed = np.broadcast_to(np.asarray(U, dtype=np.float64), t.shape).astype(np.float64)
    if not np.all(np.isfinite(speed)):
        raise ValueError("U contains NaN or infinite values")
    return speed


def _initial_state(
    model: str,
    t: np.ndarray,
    r: np.ndarray,
    psi: np.ndarray | None,
    window: int,
    polyorder: int,
) -> np.ndarray:
    nx = 7 if model in _SECOND_ORDER else 6
    x0 = np.zeros(nx)
    w = min(window, t.shape[0] - (1 - t.shape[0] % 2))
    if w > polyorder and w >= 3:
        dt = float(np.median(np.diff(t)))
        x0[IR] = savgol_filter(r, w, polyorder, mode="interp")[0]
        if nx == 7:
            x0[IRDOT] = savgol_filter(r, w, polyorder, deriv=1, delta=dt, mode="interp")[0]
    else:
        x0[IR] = r[0]
    x0[IPSI] = psi[0] if psi is not None else 0.0
    return x0


def _evaluate(
    result: FitResult,
    t: np.ndarray,
    delta: np.ndarray,
    psi: np.ndarray | None,
    r: np.ndarray,
    speed: np.ndarray,
) -> None:
    p = pack_nomoto(result.params, _REPLAY_GEAR, _REPLAY_SURGE)
    p.flags.writeable = False
    sim = _replay_arrays(
        MODEL_NAMES.index(result.model_name), p, result.x0, t, delta + result.delta0, speed
    )
    er = sim[:, IR] - r
    result.rms_r = float(np.sqrt(np.mean(er**2)))
    ss_tot = float(np.sum((r - r.mean()) ** 2))
    result.r2 = 1.0 - float(er @ er) / ss_tot if ss_tot > 0 else math.nan
    if psi is not None:
        result.rms_psi = float(np.sqrt(np.mean(_wrap(sim[:, IPSI] - psi) ** 2)))


# --------------------------------------------------------------------------------------------
# output error


def _start_values(
    model: str,
    t: np.ndarray,
    delta: np.ndarray,
    psi: np.ndarray,
    r: np.ndarray,
    bias: bool,
    window: int,
) -> tuple[Any, float]:
    """Equation-error start of the output-error fit.

    For ``bech`` the direct regression on ``r''`` is often poor (``T1 T2`` comes from the small
    linear term), so a second candidate combines the nomoto2 time constants with the Norrbin
    manoeuvring polynomial (``b_i = n_i / K``); for ``nomoto2`` a nomoto1 fit with a short
    ``T2`` is a second candidate. The candidate with the smaller free-run ``r`` error is used.
    """
    candidates: list[FitResult] = []

    def attempt(name: str) -> FitResult | None:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", SysidWarning)
                return fit_equation_error(t, delta, r, name, psi=psi, bias=bias, window=window)
        except ValueError:
            return None

    def add(params: Any, delta0: float) -> None:
        """A start built from other fits, scored by its free-run error like the direct one."""
        cand = FitResult(
            model,
            params,
            {},
            {},
            np.zeros((0, 0)),
            (),
            _initial_state(model, t, r, psi, window, 3),
            math.nan,
            math.nan,
            math.nan,
            "equation_error",
            t.shape[0],
            delta0,
        )
        _evaluate(cand, t, delta, psi, r, np.ones_like(t))
        candidates.append(cand)

    direct = attempt(model)
    if direct is not None:
        candidates.append(direct)
    if model in _SECOND_ORDER:
        first = attempt("nomoto1" if model == "nomoto2" else "norrbin")
        lin = attempt("nomoto2") if model == "bech" else None
        if first is not None:
            v = first.values
            T1, T2 = (lin.values["T1"], lin.values["T2"]) if lin else (v["T"], 0.05 * v["T"])
            T3 = lin.values["T3"] if lin else 0.05 * v["T"]
            if model == "nomoto2":
                params: Any = Nomoto2Params(v["K"], T1 + T2, T2, T3 + T2)
            else:
                K = v["K"]
                params = BechParams(
                    K, T1, T2, T3, v["n0"] / K, v["n1"] / K, v["n2"] / K, v["n3"] / K
                )
            add(params, first.delta0)
    if model in ("norrbin", "bech"):
        # the linear model with the nonlinear terms off: a stable start, where the direct
        # regression may land on the wrong sign of n1 (an unstable-ship branch)
        lin_fit = attempt("nomoto1" if model == "norrbin" else "nomoto2")
        if lin_fit is not None:
            v = lin_fit.values
            if model == "norrbin":
                params = NorrbinParams(v["K"], v["T"], 0.0, 1.0, 0.0, 0.0)
            else:
                params = BechParams(v["K"], v["T1"], v["T2"], v["T3"], 0.0, 1.0 / v["K"], 0.0, 0.0)
            add(params, lin_fit.delta0)
    if not candidates:
        return _PARAM_CLASS[model](), 0.0
    best = min(candidates, key=lambda c: c.rms_r if math.isfinite(c.rms_r) else math.inf)
    return best.params, best.delta0


TIME_CONSTANT_FLOOR = 1e-6
"""Lower bound [s] of the time constants ``T``, ``T1``, ``T2`` in the output-error fit."""
_LOWER = dict.fromkeys(("T", "T1", "T2"), TIME_CONSTANT_FLOOR)


def fit_output_error(
    t: npt.ArrayLike,
    delta: npt.ArrayLike,
    psi: npt.ArrayLike,
    r: npt.ArrayLike,
    model: str = "nomoto1",
    *,
    U: npt.ArrayLike | float | None = None,
    x0: npt.ArrayLike | None = None,
    init: Any | None = None,
    init_delta0: float = 0.0,
    bias: bool = False,
    estimate_psi0: bool = True,
    estimate_r0: bool = True,
    sigma: tuple[float, float] | None = None,
    reweight: bool = True,
    window: int = 11,
    gear: SteeringGear | None = None,
    surge: SurgeModel | None = None,
    max_nfev: int | None = None,
    check_excitation: bool = True,
) -> FitResult:
    """Output-error (simulation-error) fit of a yaw model that also estimates the initial state.

    Parameters
    ----------
    t, delta, psi, r : array_like
        Time [s] (strictly increasing, irregular allowed), rudder [rad, positive = starboard
        turn], heading [rad] and yaw rate [rad/s] of one record.
    model : {"nomoto1", "nomoto2", "norrbin", "bech"}
        Model to fit.
    U : array_like or float, optional
        Recorded or constant speed [m/s] (positions only; the yaw models do not use it).
    x0 : array_like, optional
        Initial state guess in the model's layout; by default the smoothed first sample.
    init : dataclass, optional
        Starting parameters; by default the equation-error estimate (falling back to the
        model's defaults if that fails).
    init_delta0 : float
        Starting rudder offset [rad] with ``init`` (``bias`` fits of nomoto1/nomoto2, e.g. a
        warm start from an earlier :attr:`FitResult.delta0`); without ``init`` the
        equation-error estimate is used.
    bias : bool
        Also fit a rudder offset (``delta0`` for nomoto1/nomoto2, ``n0``/``b0`` otherwise).
    estimate_psi0, estimate_r0 : bool
        Free initial heading / yaw rate (and ``r_dot0`` for the second-order models with
        ``estimate_r0``).
    sigma : (float, float), optional
        Noise levels of psi [rad] and r [rad/s] dividing the residuals. By default the
        per-channel residual RMS of a first fit (``reweight``) or the signals' standard
        deviations.
    reweight : bool
        Refit once with ``sigma`` set to the per-channel residual RMS (ignored if ``sigma``
        is given).
    window : int
        Savitzky-Golay window of the equation-error start and initial-state guess.
    gear, surge : SteeringGear, SurgeModel, optional
        Actuators of the returned model.
    max_nfev : int, optional
        Budget of :func:`scipy.optimize.least_squares`.
    check_excitation : bool
        Refuse a record without excitation first (:func:`check_excitation`). Searches that
        fit many candidates to one record, already checked, pass False.

    Returns
    -------
    FitResult
        ``info`` holds the weights, the optimiser status, the number of evaluations and the
        ``condition`` number of the column-normalised Jacobian (:func:`condition_number`).

    Raises
    ------
    ValueError
        For bad input.
    """
    model = _check_model(model)
    t = _check_time(t, 8)
    n = t.shape[0]
    delta = _as_1d("delta", delta, n)
    psi = _as_1d("psi", psi, n)
    r = _as_1d("r", r, n)
    if check_excitation:
        _check_excitation(delta, psi, r)
    speed = _speed(U, t)
    cls = _PARAM_CLASS[model]
    if init is not None and not isinstance(init, cls):
        raise ValueError(f"init for {model!r} must be {cls.__name__}, got {type(init).__name__}")
    if sigma is not None:
        sigma = (float(sigma[0]), float(sigma[1]))
        if not all(math.isfinite(s) and s > 0 for s in sigma):
            raise ValueError(f"sigma must be two finite noise levels > 0, got {sigma!r}")
    nx = 7 if model in _SECOND_ORDER else 6
    if x0 is None:
        x_start = _initial_state(model, t, r, psi, window, 3)
    else:
        x_start = np.asarray(x0, dtype=np.float64)
        if x_start.shape != (nx,) or not np.all(np.isfinite(x_start)):
            raise ValueError(f"x0 must be a finite ({nx},) state for {model!r}, got {x0!r}")
    if not math.isfinite(init_delta0):
        raise ValueError(f"init_delta0 must be a finite rudder offset [rad], got {init_delta0!r}")
    delta0_start = float(init_delta0)
    if init is None:
        init, delta0_start = _start_values(model, t, delta, psi, r, bias, window)
    # free-parameter layout
    pvals = {f.name: float(getattr(init, f.name)) for f in fields(cls)}
    fixed = {"norrbin": ("n1",), "bech": ("b1",)}.get(model, ())
    if not bias:
        fixed += {"norrbin": ("n0",), "bech": ("b0",)}.get(model, ())
        if model == "norrbin":
            pvals["n0"] = 0.0
        if model == "bech":
            pvals["b0"] = 0.0
    kb1 = math.copysign(1.0, pvals.get("K", 1.0) * pvals.get("b1", 1.0))
    names = [k for k in pvals if k not in fixed]
    start = [pvals[k] for k in names]
    if bias and model in ("nomoto1", "nomoto2"):
        names.append("delta0")
        start.append(delta0_start)
    if estimate_psi0:
        names.append("psi0")
        start.append(x_start[IPSI])
    if estimate_r0:
        names.append("r0")
        start.append(x_start[IR])
        if nx == 7:
            names.append("r_dot0")
            start.append(x_start[IRDOT])
    lower = np.array([_LOWER.get(k, -np.inf) for k in names])
    floor = np.where(np.isfinite(lower), 1e-3, -np.inf)
    theta0 = np.maximum(np.array(start, dtype=np.float64), floor)
    model_id = MODEL_NAMES.index(model)
    idx = {k: i for i, k in enumerate(names)}

    def unpack(theta: np.ndarray) -> tuple[dict[str, float], np.ndarray, float]:
        vals = dict(pvals)
        for k in pvals:
            if k in idx:
                vals[k] = float(theta[idx[k]])
        if model == "bech":
            vals["b1"] = kb1 / vals["K"] if vals["K"] != 0 else 0.0
        x = x_start.copy()
        if "psi0" in idx:
            x[IPSI] = theta[idx["psi0"]]
        if "r0" in idx:
            x[IR] = theta[idx["r0"]]
        if "r_dot0" in idx:
            x[IRDOT] = theta[idx["r_dot0"]]
        d0 = float(theta[idx["delta0"]]) if "delta0" in idx else 0.0
        return vals, x, d0

    h, n_cmd = _replay_steps(t, speed)
    # actuator/surge head of the parameter vector (layout owned by ``pack_nomoto``); the yaw
    # coefficients follow, unvalidated, since the optimiser may probe any values
    head = pack_nomoto(cls(), _REPLAY_GEAR, _REPLAY_SURGE)[:P_YAW]

    def variants(thetas: np.ndarray) -> np.ndarray:
        """Replays ``(n, len(thetas), nx)`` of the model at each row of ``thetas``, side by
        side."""
        parts = [unpack(theta) for theta in thetas]
        packed = [np.concatenate((head, [v[f.name] for f in fields(cls)])) for v, _, _ in parts]
        return _replay_kernel(
            model_id, [x for _, x, _ in parts], delta, [d0 for _, _, d0 in parts], speed,
            n_cmd, h, packed, n,
        )  # fmt: skip

    def simulate(theta: np.ndarray) -> np.ndarray:
        return variants(theta[None, :])[:, 0]

    w = (
        [1.0 / s for s in sigma]
        if sigma is not None
        else [1.0 / max(float(np.std(psi)), 1e-6), 1.0 / max(float(np.std(r)), 1e-9)]
    )

    def residuals_of(thetas: np.ndarray) -> np.ndarray:
        """Residuals ``(len(thetas), 2 n)``: weighted heading then yaw-rate errors, all
        ``1e6`` for a variant with a non-finite one."""
        sims = variants(thetas)
        with np.errstate(invalid="ignore", over="ignore"):  # a diverged replay: 1e6 below
            res = np.concatenate(
                (
                    w[0] * _wrap(sims[:, :, IPSI] - psi[:, None]),
                    w[1] * (sims[:, :, IR] - r[:, None]),
                )
            ).T.copy()
        res[~np.isfinite(res).all(axis=1)] = 1e6
        return res

    def residuals(theta: np.ndarray) -> np.ndarray:
        return residuals_of(theta[None, :])[0]

    bounds = (lower, np.full(len(names), np.inf))
    side_by_side = SideBySide(residuals_of, (nx + 2) * n * 8)  # states and residuals
    sol = least_squares(
        residuals, theta0, bounds=bounds, x_scale="jac", method="trf", max_nfev=max_nfev,
        workers=side_by_side,
    )  # fmt: skip
    nfev = sol.nfev
    if sigma is None and reweight:
        sim = simulate(sol.x)
        s_psi = float(np.sqrt(np.mean(_wrap(sim[:, IPSI] - psi) ** 2)))
        s_r = float(np.sqrt(np.mean((sim[:, IR] - r) ** 2)))
        w = [1.0 / max(s_psi, 1e-12), 1.0 / max(s_r, 1e-15)]
        sol = least_squares(
            residuals, sol.x, bounds=bounds, x_scale="jac", method="trf", max_nfev=max_nfev,
            workers=side_by_side,
        )  # fmt: skip
        nfev += sol.nfev
    J = sol.jac
    dof = max(2 * n - len(names), 1)
    s2 = 2.0 * float(sol.cost) / dof
    cov = s2 * _scaled_inverse(J)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    vals, x_fit, d0 = unpack(sol.x)
    params = cls(**vals)
    values = dict(vals)
    stderr = {k: float(se[idx[k]]) for k in names}
    for k in names:
        values[k] = float(sol.x[idx[k]])
    if model == "bech":
        stderr["b1"] = abs(vals["b1"] / vals["K"]) * stderr["K"]
    if not sol.success:
        warnings.warn(
            f"output-error fit did not converge: {sol.message}", SysidWarning, stacklevel=2
        )
    result = FitResult(
        model_name=model,
        params=params,
        values=values,
        stderr=stderr,
        covariance=cov,
        free=tuple(names),
        x0=x_fit,
        rms_psi=math.nan,
        rms_r=math.nan,
        r2=math.nan,
        method="output_error",
        n_samples=n,
        delta0=d0,
        gear=gear or SteeringGear(),
        surge=surge or SurgeModel(),
        info={
            "weights": tuple(w),
            "status": int(sol.status),
            "message": str(sol.message),
            "nfev": int(nfev),
            "s2": s2,
            "condition": condition_number(J),
        },
    )
    _evaluate(result, t, delta, psi, r, speed)
    return result

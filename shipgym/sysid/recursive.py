"""Recursive identification: least squares with forgetting and the adaptive backstepping
identifier of seed 002.

Functions take plain arrays ``(t, delta, r)`` in the project's units and sign convention
(time [s], rudder [rad, positive gives a starboard turn], yaw rate [rad/s]) so they work on any
record.

**Recursive least squares** (exponential forgetting ``lambda``) on the equation-error
regression of :mod:`shipgym.sysid.fit` (``r' = b delta + a r`` for nomoto1, seed 000; seed 002
eq. 4-5 for norrbin)::

    k     = P phi / (lambda + phi^T P phi)
    theta = theta + k (y - phi^T theta)
    P     = (P - k phi^T P) / lambda

The asymptotic memory is ``1 / (1 - lambda)`` samples.

**Adaptive backstepping identifier** (seed 002 sections 3-4). The ship obeys the Norrbin
equation in the form of seed 002 eq. (4)-(5) (with ``r|r|`` for ``r^2`` as in
:mod:`shipgym.models.nomoto`)::

    r' = a0 + a1 r + a2 r|r| + a3 r^3 + b delta = theta^T phi(r, delta),
    a_i = -n_i / T,  b = K / T.

The measured yaw rate is the "desired" trajectory ``r_d(t)`` (seed 002 eq. 7 for the Ro-Ro
turning test) and ``r`` is the yaw rate of an identification model driven by the recorded
rudder and by the stabilising function of eq. (10), with ``beta_1(z1) = z1^2`` (eq. 26.a)::

    z1    = r - r_d                                        (eq. 8.a)
    beta  = r_d' - [K1 + beta_1(z1)] z1                     (eq. 10)
    r'    = alpha = theta_hat^T phi(r_d, delta) - [K1 + beta_1(z1)] z1
    z2    = alpha - beta = theta_hat^T phi - r_d' = -theta_tilde^T phi     (eq. 8.b)
    z1'   = -[K1 + beta_1(z1)] z1 + z2                      (eq. 22)

With ``V = z1^2 / 2 + sum_i theta_tilde_i^2 / (2 gamma_i)`` (eq. 11, 15) the per-parameter
("more restrictive", eq. 18.b) update law ``theta_hat_i' = -gamma_i phi_i z1`` gives
``V' = -[K1 + z1^2] z1^2 <= 0`` (eq. 21 with the second step absent), so ``z1 -> 0`` and, with
a persistently exciting record, ``theta_hat -> theta`` (LaSalle).

*Where the seed is incomplete and how it is completed.* Seed 002 writes the state equations
(6.a-b) as a double integrator ``r' = alpha``, ``alpha' = sum a_i r^i + b delta``, which
contradicts its own eq. (4) (``r' = sum a_i r^i + b delta``), and its second step (eqs. 13,
19-20, 25, 27) computes a *rudder command* ``delta`` that makes a plant with known true
parameters track ``r_d``; eq. (19) is garbled and the gains of Table 5 were tuned by an
unspecified Fletcher-Reeves optimisation against known true values. For identification from a
record the rudder is given (35 deg in the turning test), so this implementation uses the
consistent first-order form (4), keeps the backstepping variables ``z1``, ``beta``, ``z2``
and the stabilising function with ``beta_1 = z1^2`` as written, and uses ``z1`` (measurable
without differentiating the record) as the tuning function of the update law: a standard
Lyapunov (series-parallel) adaptive identifier (Krstić, Kanellakopoulos and Kokotović 1995,
ch. 5). ``z2`` is reported as a diagnostic when ``r_d'`` is known. The integration is
semi-implicit Euler (implicit in the stabilising term), the seed's backward Euler with
``dt = 0.1 s`` being the model for it. Parameters are adapted in normalised form
(``r / r_scale``, ``delta / delta_scale``) so that one gain ``gamma`` suits all of them; the
record may be presented several times (``passes``) to accumulate excitation.

Seed 002 eq. (7): ``r_d(t) = -0.22815e-6 t^4 + 7.433e-5 t^3 - 6.7401e-3 t^2 + 0.2319 t
- 0.4611`` [deg/s], the first three phases of the 35 deg turning test of the Ro-Ro ship of
Table 2 (Izar 2001, 188.3 m, 22.68 kn). The polynomial fits the rise to the steady turn and
is used here up to ``t = 40 s``, past its local maximum near 31 s (beyond about 48 s the
quartic grows without bound).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from shipgym.models import NorrbinParams, SteeringGear
from shipgym.sysid.fit import regression_data, regression_to_params

__all__ = [
    "RO_RO_RUDDER",
    "BacksteppingIdentifier",
    "BacksteppingResult",
    "RLSTrajectory",
    "RecursiveLeastSquares",
    "ro_ro_turning_rd",
    "ro_ro_turning_rudder",
    "run_rls",
]

#: Rudder angle of the seed 002 turning test [rad].
RO_RO_RUDDER = math.radians(35.0)
#: Polynomial coefficients of seed 002 eq. (7), highest power first, r_d in deg/s.
_EQ7 = (-0.22815e-6, 7.433e-5, -6.7401e-3, 0.2319, -0.4611)


def ro_ro_turning_rd(t: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Desired yaw rate of seed 002 eq. (7) and its derivative, converted to SI.

    Parameters
    ----------
    t : array_like
        Time since the rudder order [s].

    Returns
    -------
    r_d, r_d_dot : numpy.ndarray
        Yaw rate [rad/s] and yaw acceleration [rad/s^2].
    """
    t = np.asarray(t, dtype=np.float64)
    poly = np.poly1d(_EQ7)
    return np.deg2rad(poly(t)), np.deg2rad(poly.deriv()(t))


def ro_ro_turning_rudder(t: npt.ArrayLike, rate: float = math.radians(130.0 / 56.0)) -> np.ndarray:
    """Rudder of the seed 002 turning test: 0 to 35 deg at the steering-gear rate.

    Table 2: hard over to hard over (2 x 65 deg) in 56 s, i.e. 2.32 deg/s.

    Parameters
    ----------
    t : array_like
        Time since the rudder order [s].
    rate : float
        Rudder rate [rad/s].

    Returns
    -------
    numpy.ndarray
        Rudder angle [rad].
    """
    t = np.asarray(t, dtype=np.float64)
    return np.minimum(rate * np.maximum(t, 0.0), RO_RO_RUDDER)


# ------------------------------------------------------------------------------------------
# recursive least squares


class RecursiveLeastSquares:
    """Recursive least squares with exponential forgetting.

    Parameters
    ----------
    n_params : int
        Number of parameters.
    forgetting : float
        Forgetting factor ``lambda`` in (0, 1]; 1 is ordinary (growing-memory) least squares.
    P0 : float or array_like
        Initial covariance (a scalar times the identity, or an ``(n, n)`` matrix): large means
        little confidence in ``theta0``.
    theta0 : array_like, optional
        Initial estimate (zeros by default).
    """

    def __init__(
        self,
        n_params: int,
        forgetting: float = 0.99,
        P0: float | npt.ArrayLike = 1e6,
        theta0: npt.ArrayLike | None = None,
    ) -> None:
        if not (isinstance(n_params, int | np.integer) and n_params >= 1):
            raise ValueError(f"n_params must be an integer >= 1, got {n_params!r}")
        if not (0.0 < forgetting <= 1.0):
            raise ValueError(f"forgetting must be in (0, 1], got {forgetting!r}")
        P = np.asarray(P0, dtype=np.float64)
        if P.ndim == 0:
            if not (math.isfinite(float(P)) and P > 0):
                raise ValueError(f"P0 must be a positive finite scalar or matrix, got {P0!r}")
            P = float(P) * np.eye(n_params)
        if P.shape != (n_params, n_params) or not np.all(np.isfinite(P)):
            raise ValueError(f"P0 must be ({n_params}, {n_params}), got shape {P.shape}")
        self.n_params = int(n_params)
        self.forgetting = float(forgetting)
        self.P = P.copy()
        self.theta = (
            np.zeros(n_params) if theta0 is None else np.asarray(theta0, dtype=np.float64).copy()
        )
        if self.theta.shape != (n_params,):
            raise ValueError(f"theta0 must have shape ({n_params},), got {self.theta.shape}")

    def update(self, phi: npt.ArrayLike, y: float) -> np.ndarray:
        """Add one observation ``y = phi^T theta + e`` and return the new estimate.

        Parameters
        ----------
        phi : array_like
            Regressor, shape ``(n_params,)``.
        y : float
            Observation.

        Returns
        -------
        numpy.ndarray
            A copy of the updated ``theta``.
        """
        phi = np.asarray(phi, dtype=np.float64)
        if phi.shape != (self.n_params,):
            raise ValueError(f"phi must have shape ({self.n_params},), got {phi.shape}")
        if not (np.all(np.isfinite(phi)) and math.isfinite(float(y))):
            raise ValueError("phi and y must be finite")
        Pphi = self.P @ phi
        gain = Pphi / (self.forgetting + phi @ Pphi)
        self.theta = self.theta + gain * (float(y) - phi @ self.theta)
        self.P = (self.P - np.outer(gain, Pphi)) / self.forgetting
        self.P = 0.5 * (self.P + self.P.T)
        return self.theta.copy()


@dataclass
class RLSTrajectory:
    """Parameter trajectories of :func:`run_rls`.

    Attributes
    ----------
    t : numpy.ndarray
        Sample times [s] (the regression samples).
    theta : numpy.ndarray
        Regression coefficients, shape ``(n, p)``.
    names : tuple of str
        Regressor names.
    params : dict of numpy.ndarray
        Physical parameters per sample (``K``, ``T``, ... ; NaN while they are invalid).
    """

    t: np.ndarray
    theta: np.ndarray
    names: tuple[str, ...]
    params: dict[str, np.ndarray] = field(default_factory=dict)


def run_rls(
    t: npt.ArrayLike,
    delta: npt.ArrayLike,
    r: npt.ArrayLike,
    model: str = "nomoto1",
    *,
    forgetting: float = 0.99,
    P0: float = 1e6,
    bias: bool = False,
    window: int = 11,
) -> RLSTrajectory:
    """Run recursive least squares over a record for a nomoto1 or Norrbin regression.

    Parameters
    ----------
    t, delta, r : array_like
        Time [s], rudder [rad, positive = starboard turn], yaw rate [rad/s].
    model : {"nomoto1", "norrbin"}
        Regression form (see :func:`shipgym.sysid.fit.regression_data`).
    forgetting : float
        Forgetting factor.
    P0 : float
        Initial covariance scale.
    bias : bool
        Constant regressor (rudder offset / ``n0``).
    window : int
        Savitzky-Golay window [samples] for ``r'``.

    Returns
    -------
    RLSTrajectory
    """
    if model not in ("nomoto1", "norrbin"):
        raise ValueError(f"run_rls supports 'nomoto1' and 'norrbin', got {model!r}")
    reg = regression_data(t, delta, r, model, bias=bias, window=window)
    rls = RecursiveLeastSquares(reg.X.shape[1], forgetting=forgetting, P0=P0)
    theta = np.empty_like(reg.X)
    for k in range(reg.X.shape[0]):
        theta[k] = rls.update(reg.X[k], reg.y[k])
    params: dict[str, np.ndarray] = {}
    for k in range(theta.shape[0]):
        try:
            values = regression_to_params(model, theta[k], reg.names)[1]
        except ValueError:
            values = {}
        for name, value in values.items():
            params.setdefault(name, np.full(theta.shape[0], np.nan))[k] = value
    return RLSTrajectory(reg.t, theta, reg.names, params)


# ------------------------------------------------------------------------------------------
# adaptive backstepping identifier (seed 002)


@dataclass
class BacksteppingResult:
    """Trajectories and final estimate of :class:`BacksteppingIdentifier`.

    Attributes
    ----------
    t : numpy.ndarray
        Time of the last pass [s].
    r : numpy.ndarray
        Identification-model yaw rate of the last pass [rad/s].
    z1 : numpy.ndarray
        ``r - r_d`` over all passes [rad/s].
    z2 : numpy.ndarray
        ``alpha - beta(z1)`` over all passes [rad/s^2] (NaN when ``r_d'`` was not given).
    theta : numpy.ndarray
        ``[a0, a1, a2, a3, b]`` over all passes, shape ``(passes * n, 5)`` (SI units).
    a : numpy.ndarray
        Final ``a0..a3`` (seed 002 eq. 4-5) [1/s^2 ... s/... in SI].
    b : float
        Final ``b = K / T`` [1/s^2].
    params : NorrbinParams
        Final estimate as Norrbin parameters with ``|n1| = 1``.
    """

    t: np.ndarray
    r: np.ndarray
    z1: np.ndarray
    z2: np.ndarray
    theta: np.ndarray
    a: np.ndarray
    b: float
    params: NorrbinParams


class BacksteppingIdentifier:
    """Adaptive backstepping identifier of the Norrbin model (seed 002, see module docstring).

    Parameters
    ----------
    K1 : float
        Gain of the stabilising function, eq. (10) [1/s].
    gamma : float or array_like
        Adaptation gains ``gamma_i`` of ``[a0, a1, a2, a3, b]`` in normalised units [1/s]
        (scalar or five values; 0 freezes a parameter).
    r_scale, delta_scale : float, optional
        Normalisation of ``r`` and ``delta`` (default: the record's largest magnitudes).
    theta0 : array_like, optional
        Initial ``[a0, a1, a2, a3, b]`` in SI units (zeros by default, except ``b``).
    b : float, optional
        Known ``b = K / T`` [1/s^2]; when given it is fixed (its gain is set to 0). A constant
        rudder cannot separate ``b`` from ``a0``.
    fit_a0 : bool
        Adapt the bias ``a0`` (seed 002 keeps it for environmental disturbances).
    """

    def __init__(
        self,
        K1: float = 1.0,
        gamma: float | npt.ArrayLike = 1.0,
        *,
        r_scale: float | None = None,
        delta_scale: float | None = None,
        theta0: npt.ArrayLike | None = None,
        b: float | None = None,
        fit_a0: bool = True,
    ) -> None:
        if not (math.isfinite(K1) and K1 > 0):
            raise ValueError(f"K1 must be a finite gain > 0 [1/s], got {K1!r}")
        g = np.broadcast_to(np.asarray(gamma, dtype=np.float64), (5,)).copy()
        if not np.all(np.isfinite(g)) or np.any(g < 0):
            raise ValueError(f"gamma must be finite and >= 0 (five values or one), got {gamma!r}")
        for name, value in (("r_scale", r_scale), ("delta_scale", delta_scale)):
            if value is not None and not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be > 0, got {value!r}")
        if b is not None:
            if not math.isfinite(b):
                raise ValueError(f"b must be finite, got {b!r}")
            g[4] = 0.0
        if not fit_a0:
            g[0] = 0.0
        self.K1 = float(K1)
        self.gamma = g
        self.r_scale = r_scale
        self.delta_scale = delta_scale
        self.theta0 = None if theta0 is None else np.asarray(theta0, dtype=np.float64)
        if self.theta0 is not None and self.theta0.shape != (5,):
            raise ValueError(f"theta0 must be [a0, a1, a2, a3, b], got shape {self.theta0.shape}")
        self.b = b

    def run(
        self,
        t: npt.ArrayLike,
        delta: npt.ArrayLike,
        r_d: npt.ArrayLike,
        r_d_dot: npt.ArrayLike | None = None,
        passes: int = 1,
    ) -> BacksteppingResult:
        """Identify over a record (presented ``passes`` times).

        Parameters
        ----------
        t : array_like
            Time [s], strictly increasing.
        delta : array_like
            Rudder [rad, positive = starboard turn].
        r_d : array_like
            Measured (desired) yaw rate [rad/s].
        r_d_dot : array_like, optional
            Its derivative [rad/s^2], only for the ``z2`` diagnostic.
        passes : int
            Presentations of the record; the model restarts at ``r_d[0]`` each time, the
            estimates carry over.

        Returns
        -------
        BacksteppingResult
        """
        t = np.asarray(t, dtype=np.float64)
        if t.ndim != 1 or t.shape[0] < 3 or np.any(np.diff(t) <= 0):
            raise ValueError("t must be a strictly increasing 1-D array with >= 3 samples")
        n = t.shape[0]
        arrays = []
        for name, a in (("delta", delta), ("r_d", r_d), ("r_d_dot", r_d_dot)):
            if a is None:
                arrays.append(None)
                continue
            arr = np.asarray(a, dtype=np.float64)
            if arr.shape != (n,) or not np.all(np.isfinite(arr)):
                raise ValueError(f"{name} must be a finite 1-D array of length {n}")
            arrays.append(arr)
        dl, rd, rdd = arrays
        assert dl is not None and rd is not None
        if not (isinstance(passes, int | np.integer) and passes >= 1):
            raise ValueError(f"passes must be an integer >= 1, got {passes!r}")
        rs = self.r_scale or max(float(np.max(np.abs(rd))), 1e-9)
        ds = self.delta_scale or max(float(np.max(np.abs(dl))), 1e-9)
        unscale = np.array([1.0, 1.0 / rs, 1.0 / rs**2, 1.0 / rs**3, 1.0 / ds])
        theta_si = np.zeros(5) if self.theta0 is None else self.theta0.copy()
        if self.b is not None:
            theta_si[4] = self.b
        th = theta_si / unscale  # normalised estimate
        x = rd / rs
        phi_all = np.column_stack((np.ones(n), x, x * np.abs(x), x**3, dl / ds))
        h = np.diff(t)
        z1_all = np.empty(passes * n)
        z2_all = np.full(passes * n, np.nan)
        theta_all = np.empty((passes * n, 5))
        r_model = np.empty(n)
        for p in range(passes):
            r = rd[0]
            for k in range(n):
                i = p * n + k
                z1 = r - rd[k]
                phi = phi_all[k]
                alpha_hat = float(phi @ th)
                if rdd is not None:
                    z2_all[i] = alpha_hat - rdd[k]
                z1_all[i] = z1
                theta_all[i] = th * unscale
                r_model[k] = r
                if k == n - 1:
                    break
                gain = self.K1 + z1 * z1  # K1 + beta_1(z1), eq. (10), (26.a)
                hk = h[k]
                r = (r + hk * alpha_hat + hk * gain * rd[k + 1]) / (1.0 + hk * gain)
                z1_next = r - rd[k + 1]
                th = th - hk * self.gamma * phi * z1_next  # eq. (18.b) with z1 as tuning fn
        theta_si = th * unscale
        a = theta_si[:4]
        b = float(theta_si[4])
        try:
            params = regression_to_params(
                "norrbin", np.r_[b, a[1:], a[0]], ("delta", "r", "r|r|", "r^3", "1")
            )[0]
        except ValueError as exc:
            raise ValueError(f"identifier did not give a valid Norrbin model: {exc}") from None
        return BacksteppingResult(t, r_model, z1_all, z2_all, theta_all, a, b, params)


def ro_ro_gear() -> SteeringGear:
    """Steering gear of the Ro-Ro ship of seed 002 Table 2 (65 deg, 130 deg in 56 s)."""
    return SteeringGear(
        time_constant=1.0, max_angle=math.radians(65.0), max_rate=math.radians(130.0 / 56.0)
    )

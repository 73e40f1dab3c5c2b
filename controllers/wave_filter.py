r"""Wave filter for heading autopilots: a Kalman filter that separates the low-frequency heading
from the wave-frequency motion (Fossen 2021, *Handbook of Marine Craft Hydrodynamics and Motion
Control*, 2nd ed., sections 10.2.3 and 13.3; Fossen & Perez 2009, IEEE Control Systems
Magazine 29(6)).

In a seaway the measured heading is the sum of the ship's low-frequency (LF) heading and the
first-order wave-frequency (WF) motion. An autopilot fed the measured heading chases the waves:
its rudder moves at the wave frequency, which wears the steering gear and costs fuel without
changing the LF course. The filter estimates the LF heading and yaw rate from the model

.. math::

    \dot\xi_1 = \xi_2, \quad
    \dot\xi_2 = -\omega_0^2 \xi_1 - 2 \lambda \omega_0 \xi_2 + K_w w_w
        \qquad \text{(linear wave response model: } \psi_w = \xi_2,\
        h(s) = \frac{K_w s}{s^2 + 2 \lambda \omega_0 s + \omega_0^2} \text{)}

    \dot\psi = r, \quad T \dot r + r = K (\delta + b + w_r), \quad \dot b = w_b,
    \qquad y = \psi + \psi_w + v,

the first-order Nomoto ship with a slowly varying rudder bias ``b`` (current, wind, a rudder
offset: what the autopilot's integrator would otherwise take). The filter is the steady-state
Kalman filter of this model discretised exactly at the autopilot's step (zero-order hold on
the rudder, Van Loan's method for the process noise), its gain from the discrete algebraic
Riccati equation.

Design rule (Fossen 2021, section 13.3): ``omega_0`` is the peak frequency of the waves as the
ship meets them (the encounter frequency of the spectrum's peak), ``lambda = 0.1``; ``K_w`` is
set so that the model's WF heading has the standard deviation ``wave_heading_std`` expected in
the sea state (for the model above, ``Var psi_w = K_w^2 / (4 lambda omega_0)``); the compass
noise ``v`` has the standard deviation ``compass_std``. The LF process noise ``w_r`` is a
rudder-equivalent disturbance (``rudder_noise``, rad per sqrt(s); 0.1 deg per sqrt(s) by default)
and the bias drift ``w_b`` a slow random walk (``bias_noise``, rad per sqrt(s)): small, so that
the LF estimate follows the ship's own dynamics and leaves the waves to the wave model. Stated in
rudder units, the same defaults suit any ship whose Nomoto model is given. Switched off, the
autopilot gets the measured heading and yaw rate unchanged.

All updates work on a batch of ships (arrays of shape ``(n,)``), as the other controllers do;
one ship is a batch of one. The ships share the Nomoto model and the noise levels; the wave
model may be each ship's own (``peak_frequency`` and ``wave_heading_std`` arrays of shape
``(n,)``), and :meth:`WaveFilter.retune` designs it anew for some ships while their
estimates run on: the gain scheduling of a filter whose encounter frequency moves with the
ship's heading and speed (Fossen 2021, section 13.3). The ship may be directionally unstable
(``T < 0``): the Kalman filter of an unstable but observable model is stable all the same.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike

from controllers._angles import finite, positive, ssa_array

__all__ = ["WaveFilter"]

#: Relative damping of the linear wave response model (Fossen 2021, section 10.2.3).
WAVE_DAMPING = 0.1


class WaveFilter:
    """Steady-state Kalman wave filter on the first-order Nomoto model (module docstring).

    Parameters
    ----------
    K, T : float
        Nomoto gain [1/s] and time constant [s] of the ship (both non-zero; ``T < 0`` for a
        directionally unstable ship).
    dt : float
        Step of :meth:`update` [s].
    peak_frequency : float or array_like
        Encounter peak frequency of the waves ``omega_0`` [rad/s]: one for every ship, or one
        per ship (shape ``(n,)``).
    wave_heading_std : float or array_like
        Standard deviation of the wave-frequency heading motion [rad] the filter expects: one
        for every ship, or one per ship (broadcast with ``peak_frequency``).
    compass_std : float
        Standard deviation of the heading measurement noise [rad].
    rudder_noise : float
        Intensity of the LF process noise as a rudder-equivalent disturbance [rad per
        sqrt(s)]: smaller gives a smoother LF estimate (less wave motion reaches the
        rudder), larger a faster one.
    bias_noise : float
        Intensity of the rudder-bias drift [rad per sqrt(s)].
    wave_damping : float
        Relative damping ``lambda`` of the wave model.

    Attributes
    ----------
    gain, transition, input : numpy.ndarray
        The Kalman gain ``(5,)``, the one-step transition ``(5, 5)`` and the rudder's input
        ``(5,)`` of the states ``(xi_1, psi_w, psi, r, b)``; with a wave model per ship, one
        per ship (a leading axis of ``n``).

    Raises
    ------
    ValueError
        For a parameter that is not a finite positive number (``K`` and ``T``: non-zero), or
        per-ship arrays of different lengths.
    """

    def __init__(
        self,
        K: float,
        T: float,
        dt: float,
        peak_frequency: ArrayLike,
        wave_heading_std: ArrayLike,
        compass_std: float = math.radians(0.2),
        rudder_noise: float = math.radians(0.1),
        bias_noise: float = 1e-4,
        wave_damping: float = WAVE_DAMPING,
    ) -> None:
        self._ship = (
            _nonzero("K", K),
            _nonzero("T", T),
            positive("dt", dt),
            positive("compass_std", compass_std),
            positive("rudder_noise", rudder_noise),
            positive("bias_noise", bias_noise),
            positive("wave_damping", wave_damping),
        )
        self.dt = self._ship[2]
        w0, sigma = _wave_model(peak_frequency, wave_heading_std)
        if w0.ndim == 0:
            self.transition, self.input, self.gain = _design(*self._ship, float(w0), float(sigma))
        else:
            self.transition = np.empty((w0.size, 5, 5))
            self.input = np.empty((w0.size, 5))
            self.gain = np.empty((w0.size, 5))
            self.retune(np.arange(w0.size), w0, sigma)
        self._x: np.ndarray | None = None

    @property
    def ships(self) -> int | None:
        """The ships of a filter with a wave model per ship; ``None`` for one model for all."""
        return None if self.gain.ndim == 1 else self.gain.shape[0]

    def retune(
        self, rows: ArrayLike, peak_frequency: ArrayLike, wave_heading_std: ArrayLike
    ) -> None:
        """Design the wave model of ships ``rows`` anew (a filter with a wave model per ship):
        encounter peak frequency [rad/s] and WF heading standard deviation [rad] of each, or
        one for all of them. Their estimates go on from where they are."""
        if self.ships is None:
            raise ValueError(
                "retune needs a filter with a wave model per ship (peak_frequency and "
                "wave_heading_std arrays of shape (n,)), got one made with one for all ships"
            )
        rows = np.atleast_1d(np.asarray(rows, dtype=np.int64))
        w0, sigma = _wave_model(peak_frequency, wave_heading_std)
        w0, sigma = np.broadcast_to(w0, rows.shape), np.broadcast_to(sigma, rows.shape)
        for i, w, s in zip(rows.tolist(), w0.tolist(), sigma.tolist(), strict=True):
            self.transition[i], self.input[i], self.gain[i] = _design(*self._ship, w, s)

    def reset(self, psi: ArrayLike, r: ArrayLike = 0.0) -> None:
        """Start the estimates at heading ``psi`` [rad] and yaw rate ``r`` [rad/s] (arrays for
        a batch), with no wave motion and no bias."""
        psi = np.atleast_1d(np.asarray(psi, dtype=float))
        if self.ships is not None and psi.shape != (self.ships,):
            raise ValueError(
                f"psi must have one heading per ship, shape ({self.ships},), got {psi.shape}"
            )
        x = np.zeros((psi.shape[0], 5))
        x[:, 2] = psi
        x[:, 3] = np.broadcast_to(np.asarray(r, dtype=float), psi.shape)
        self._x = x

    def update(self, psi_measured: ArrayLike, delta: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """One step: the measured heading [rad] now and the rudder [rad] applied over the step
        just ended; returns the LF heading (wrapped to [-pi, pi)) and yaw rate estimates."""
        if self._x is None:
            raise RuntimeError("WaveFilter.update before reset")
        delta = np.asarray(delta, dtype=float)[..., None]
        x = np.matmul(self.transition, self._x[..., None])[..., 0] + delta * self.input
        innovation = ssa_array(np.asarray(psi_measured, dtype=float) - x[:, 1] - x[:, 2])
        x += innovation[:, None] * self.gain
        self._x = x
        return ssa_array(x[:, 2]), x[:, 3].copy()

    @property
    def bias(self) -> np.ndarray:
        """The rudder-bias estimate [rad] of each ship."""
        if self._x is None:
            raise RuntimeError("WaveFilter.bias before reset")
        return self._x[:, 4].copy()


def _nonzero(name: str, value: Any) -> float:
    f = finite(name, value)
    if f == 0.0:
        raise ValueError(f"{name} must be a finite, non-zero number, got {value!r}")
    return f


def _wave_model(peak_frequency: ArrayLike, wave_heading_std: ArrayLike) -> tuple[np.ndarray, ...]:
    """``peak_frequency`` and ``wave_heading_std`` checked (finite, > 0) and broadcast: 0-d
    arrays for one wave model, ``(n,)`` arrays for one per ship."""
    out = []
    for name, value in (("peak_frequency", peak_frequency), ("wave_heading_std", wave_heading_std)):
        try:
            a = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be a finite number > 0 or an array of them, got "
                             f"{value!r}") from None  # fmt: skip
        if a.ndim > 1 or not np.all(np.isfinite(a) & (a > 0)) or a.size == 0:
            raise ValueError(
                f"{name} must be a finite number > 0 or a (n,) array of them, got {value!r}"
            )
        out.append(a)
    try:
        w0, sigma = np.broadcast_arrays(*out)
    except ValueError:
        raise ValueError(
            f"peak_frequency and wave_heading_std must have one value per ship each, got shapes "
            f"{out[0].shape} and {out[1].shape}"
        ) from None
    return w0, sigma


@functools.lru_cache(maxsize=4096)
def _design(
    K: float,
    T: float,
    dt: float,
    compass_std: float,
    rudder_noise: float,
    bias_noise: float,
    lam: float,
    w0: float,
    sigma: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The transition, rudder input and steady-state Kalman gain of one design (module
    docstring): Van Loan's discretisation, zero-order hold on the rudder, the DARE."""
    k_w = sigma * math.sqrt(4.0 * lam * w0)
    a = np.array(
        [
            [0.0, 1.0, 0.0, 0.0, 0.0],
            [-(w0**2), -2.0 * lam * w0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, -1.0 / T, K / T],
            [0.0, 0.0, 0.0, 0.0, 0.0],
        ]
    )
    b = np.array([0.0, 0.0, 0.0, K / T, 0.0])
    g = np.diag([0.0, k_w, 0.0, abs(K / T) * rudder_noise, bias_noise])
    n = 5
    # Van Loan: the discrete transition and process-noise covariance of one step
    van = np.zeros((2 * n, 2 * n))
    van[:n, :n] = -a
    van[:n, n:] = g @ g.T
    van[n:, n:] = a.T
    e = scipy.linalg.expm(van * dt)
    phi = e[n:, n:].T
    q = phi @ e[:n, n:]
    # zero-order hold on the rudder
    hold = np.zeros((n + 1, n + 1))
    hold[:n, :n] = a
    hold[:n, n] = b
    gamma = scipy.linalg.expm(hold * dt)[:n, n]
    c = np.array([[0.0, 1.0, 1.0, 0.0, 0.0]])
    r = np.array([[compass_std**2]])
    p = scipy.linalg.solve_discrete_are(phi.T, c.T, 0.5 * (q + q.T), r)
    gain = (p @ c.T / (c @ p @ c.T + r)[0, 0])[:, 0]
    for arr in (phi, gamma, gain):
        arr.setflags(write=False)  # cached: shared by every filter of this design
    return phi, gamma, gain

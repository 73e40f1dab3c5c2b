"""Waves: a sea state, its spectrum, the encounter frequency, a seeded sea surface, the linear
wave-frequency response model and the mean wave drift force.

Sea state and direction
    A long-crested, deep-water sea of significant wave height ``H_s`` [m], peak period ``T_p``
    [s] and peak enhancement ``gamma`` [-] travelling TOWARD the direction ``beta_w`` [rad],
    clockwise from north (NED), the convention of the current (:mod:`shipgym.models.current`)
    and of Fossen's wave direction. Met-ocean reports give the direction waves come FROM: that
    is ``beta_w + pi``. Relative to a ship of heading ``psi`` the waves meet the hull at the
    encounter angle ``beta = beta_w - psi`` (wrapped to ``[-pi, pi)``): ``beta = 0`` following
    seas, ``+pi/2`` beam seas travelling to starboard (coming from port), ``-pi`` (``pi``) head
    seas (Fossen 2021, section 10.2, and MSS ``encounter.m``).

Spectrum (DNV-RP-C205, Environmental conditions and environmental loads, 2010/2019, section
3.5.5), one-sided in angular frequency ``omega`` [rad/s], ``omega_p = 2 pi / T_p``::

    S_PM(omega) = 5/16 H_s^2 omega_p^4 omega^-5 exp(-5/4 (omega / omega_p)^-4)
    S_J(omega)  = A_gamma S_PM(omega) gamma^exp(-1/2 ((omega - omega_p) / (s omega_p))^2)
    A_gamma = 1 - 0.287 ln(gamma),  s = 0.07 for omega <= omega_p, 0.09 above,

Pierson-Moskowitz being JONSWAP with ``gamma = 1``. Both peak at ``omega_p`` with the value
``A_gamma gamma 5/16 H_s^2 exp(-5/4) / omega_p``; the zeroth moment ``m0 = int S d omega`` is
``H_s^2 / 16`` within 0.3 % for ``1 <= gamma <= 5`` (1.8 % low at ``gamma = 7``: ``A_gamma``
is DNV's approximate normalisation).

Encounter frequency (Fossen 2021, section 10.2; deep water, ``U`` the ship's speed)::

    omega_e = omega - omega^2 U cos(beta) / g

higher than ``omega`` in head seas, lower in following seas, and negative when a following
sea is overtaken (the observed frequency is then ``|omega_e|``).

Sea surface (linear superposition; Faltinsen, *Sea loads on ships and offshore structures*,
Cambridge 1990, chapter 2; Fossen 2021, section 10.2)::

    zeta(x, y, t) = sum_k A_k cos(omega_k t - k_k (x cos beta_w + y sin beta_w) + eps_k),
    A_k = sqrt(2 S(omega_k) d omega),  k_k = omega_k^2 / g,

with ``x`` north and ``y`` east, the band ``[omega_min, omega_max]`` cut into ``N`` equal
intervals of width ``d omega``, each ``omega_k`` drawn uniformly inside its interval and
``eps_k`` uniform in ``[0, 2 pi)``. Equally spaced frequencies would repeat the record after
``2 pi / d omega``; random frequencies within the intervals do not (Faltinsen 1990, chapter 2).

Wave-frequency motion: Fossen's linear approximation of the wave spectrum (Fossen 2021,
section 10.2, "linear wave response approximation"; MSS ``exLinspec.m``), a second-order
filter driven by white noise ``w``::

    h(s) = K_w s / (s^2 + 2 lambda omega_0 s + omega_0^2),   K_w = 2 lambda omega_0 sigma,
    x1' = x2,   x2' = -omega_0^2 x1 - 2 lambda omega_0 x2 + K_w w,   y = x2,

with ``sigma = sqrt(max S) = sqrt(S(omega_p))``, so ``|h(j omega_0)|^2 = sigma^2`` is the
spectrum's peak, ``lambda`` fitted to the spectrum by least squares (about 0.26 for
Pierson-Moskowitz, 0.10 for JONSWAP with ``gamma = 3.3``) and ``omega_0 = |omega_e(omega_p)|``
the encounter peak frequency. The white noise has intensity ``pi`` (``E[w(t) w(t')] = pi
delta(t - t')``), so that ``|h(j omega)|^2`` is the one-sided spectrum of ``y`` in the
convention of ``S`` and ``var(y) = int_0^inf |h|^2 d omega = pi lambda omega_0 sigma^2``. The
discrete step is exact in distribution (Van Loan 1978, "Computing integrals involving the
matrix exponential", IEEE TAC 23(3)): ``x_{k+1} = A_d x_k + B_d n_k``, ``A_d = exp(A dt)``,
``B_d B_d^T = int_0^dt exp(A t) E pi E^T exp(A^T t) dt``, ``n_k`` standard normal.

Mean wave drift force (Faltinsen 1990, chapter 5, from Faltinsen, Minsaas, Liapis and
Skjordal 1980, "Prediction of resistance and propulsion of a ship in a seaway", 13th Symp.
Naval Hydrodynamics): in regular waves of amplitude ``zeta_a`` much shorter than the ship's
draught and beam, a wall-sided hull reflects the waves totally from its lit waterline ``L_1``::

    F_i = 1/2 rho g zeta_a^2 int_{L_1} sin^2(theta + beta) n_i dl,   i = 1, 2, 6,

``theta`` the angle of the waterline's tangent to the ship's x axis, ``n`` its normal into
the hull (``n_6 = x n_2 - y n_1``). ``sin^2(theta + beta)`` is the squared component of the
wave direction along that normal: an infinite wall in normal incidence takes ``1/2 rho g
zeta_a^2`` per metre, in the direction the waves travel. In irregular seas the coefficient,
constant in this short-wave limit, multiplies ``2 int S d omega = H_s^2 / 8`` (Faltinsen 1990,
chapter 5): ``F_i = rho g H_s^2 / 16 int_{L_1} sin^2(theta + beta) n_i dl``. Limits: convex
wall-sided waterline, zero forward speed, short waves; longer waves pass the hull partly
unreflected, so this is an upper bound of the drift force at realistic ``T_p``.

Reflection of longer waves (Ursell 1947, "The effect of a fixed vertical barrier on surface
waves in deep water", Proc. Cambridge Phil. Soc. 43): a fixed vertical wall reaching a depth
``d`` below the surface reflects the share ``R(kd)`` of a deep-water wave's amplitude::

    R(kd) = pi I_1(kd) / sqrt(pi^2 I_1(kd)^2 + K_1(kd)^2),

``I_1``, ``K_1`` the modified Bessel functions; ``R -> 1`` in short waves, ``R -> 0`` in long
ones. The drift force goes with the reflected energy, ``R^2``: in a sea,
:func:`reflection_factor` weights ``R(k d)^2`` by the spectrum (``d`` the ship's draught), the
factor by which the seaway of the environments (:mod:`shipgym.models.seaway`) scales
:func:`mean_drift_force`'s short-wave limit.
"""

from __future__ import annotations

import functools
import math
import numbers
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from shipgym.models._checks import real_array, require_finite, step_size
from shipgym.models.angles import ssa
from shipgym.models.rvg import GRAVITY, WATER_DENSITY

__all__ = [
    "GAMMA_RANGE",
    "MAX_STEEPNESS",
    "SeaRealisation",
    "SeaState",
    "WaveResponseModel",
    "box_waterline",
    "encounter_angle",
    "encounter_frequency",
    "fit_wave_response",
    "jonswap_spectrum",
    "mean_drift_force",
    "pierson_moskowitz_spectrum",
    "realise_sea",
    "reflection_factor",
    "wave_response_model",
]

MAX_STEEPNESS = 1.0 / 7.0
"""Largest sea steepness ``H_s / lambda_p`` [-], ``lambda_p = g T_p^2 / (2 pi)`` the deep-water
length of the peak wave: Stokes's limiting steepness of a regular wave (``H / lambda`` = 0.142);
no sea is steeper."""

GAMMA_RANGE = (1.0, 7.0)
"""Range of the JONSWAP peak enhancement ``gamma`` [-] (DNV-RP-C205, section 3.5.5)."""

_FIT_BAND = 4.0
"""The damping ``lambda`` is fitted on ``omega / omega_p`` in ``(0, 4]`` (MSS ``exLinspec.m``
fits on ``(0, 3.75 omega_p]``)."""

_FIT_POINTS = 400
_FIT_BOUNDS = (0.01, 1.0)
"""Bracket of the fitted damping ``lambda`` [-]."""


def _finite(value: Any, name: str) -> float:
    """``value`` as a finite float: ``TypeError`` for a non-real, ``ValueError`` otherwise."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {v!r}")
    return v


@dataclass(frozen=True)
class SeaState:
    """A long-crested, deep-water sea (module docstring).

    Attributes
    ----------
    significant_height : float
        Significant wave height ``H_s`` [m], > 0 and at most :data:`MAX_STEEPNESS` times the
        peak wave length ``g T_p^2 / (2 pi)``.
    peak_period : float
        Peak period ``T_p`` [s], > 0.
    direction : float
        Direction the waves travel TOWARD, ``beta_w`` [rad], clockwise from north (like the
        current's; the direction they come from is ``beta_w + pi``).
    gamma : float
        JONSWAP peak enhancement factor [-] in :data:`GAMMA_RANGE`; 1 gives Pierson-Moskowitz.
    """

    significant_height: float
    peak_period: float
    direction: float
    gamma: float = 3.3

    def __post_init__(self) -> None:
        hs = _finite(self.significant_height, "SeaState.significant_height")
        tp = _finite(self.peak_period, "SeaState.peak_period")
        _finite(self.direction, "SeaState.direction")
        gamma = _finite(self.gamma, "SeaState.gamma")
        if hs <= 0.0:
            raise ValueError(f"SeaState.significant_height must be > 0 m, got {hs!r}")
        if tp <= 0.0:
            raise ValueError(f"SeaState.peak_period must be > 0 s, got {tp!r}")
        if not GAMMA_RANGE[0] <= gamma <= GAMMA_RANGE[1]:
            raise ValueError(f"SeaState.gamma must be in [1, 7], got {gamma!r}")
        steepness = hs / self.peak_wavelength
        if steepness > MAX_STEEPNESS:
            raise ValueError(
                f"SeaState.significant_height {hs!r} m is too steep for peak_period {tp!r} s: "
                f"H_s / lambda_p = {steepness:.3f}, expected at most 1/7 (H_s <= "
                f"{MAX_STEEPNESS * self.peak_wavelength:.3g} m)"
            )

    @property
    def peak_frequency(self) -> float:
        """``omega_p = 2 pi / T_p`` [rad/s]."""
        return 2.0 * math.pi / self.peak_period

    @property
    def peak_wavelength(self) -> float:
        """Deep-water length of the peak wave, ``g T_p^2 / (2 pi)`` [m]."""
        return GRAVITY * self.peak_period**2 / (2.0 * math.pi)

    @property
    def peak_density(self) -> float:
        """``max S = S(omega_p) = A_gamma gamma 5/16 H_s^2 exp(-5/4) / omega_p`` [m^2 s/rad]."""
        a_gamma = 1.0 - 0.287 * math.log(self.gamma)
        return (
            a_gamma
            * self.gamma
            * 5.0
            / 16.0
            * self.significant_height**2
            * math.exp(-1.25)
            / self.peak_frequency
        )

    def spectrum(self, omega: npt.ArrayLike) -> np.ndarray:
        """The sea's JONSWAP spectrum ``S(omega)`` [m^2 s/rad] (:func:`jonswap_spectrum`)."""
        return jonswap_spectrum(omega, self.significant_height, self.peak_period, self.gamma)


def _frequencies(omega: npt.ArrayLike, name: str = "omega") -> np.ndarray:
    w = real_array(omega, name)
    require_finite(w, name)
    if (w < 0.0).any():
        raise ValueError(f"{name} must be >= 0 rad/s, got {float(w[w < 0.0].flat[0])!r}")
    return w


def jonswap_spectrum(
    omega: npt.ArrayLike, significant_height: float, peak_period: float, gamma: float = 3.3
) -> np.ndarray:
    """JONSWAP wave spectrum (DNV-RP-C205, section 3.5.5; module docstring).

    Parameters
    ----------
    omega : array_like
        Angular frequencies [rad/s], finite and >= 0.
    significant_height : float
        ``H_s`` [m].
    peak_period : float
        ``T_p`` [s].
    gamma : float
        Peak enhancement factor [-] in ``[1, 7]``.

    Returns
    -------
    numpy.ndarray
        One-sided spectral density ``S(omega)`` [m^2 s/rad], shape of ``omega`` (0 at 0).

    Raises
    ------
    ValueError
        For a frequency that is negative or not finite, or a sea state :class:`SeaState`
        refuses.
    """
    sea = SeaState(significant_height, peak_period, 0.0, gamma)
    w = _frequencies(omega)
    wp = sea.peak_frequency
    out = np.zeros_like(w)
    pos = w > 0.0
    x = w[pos] / wp
    s = np.where(x <= 1.0, 0.07, 0.09)
    pm = 5.0 / 16.0 * significant_height**2 / wp * x**-5 * np.exp(-1.25 * x**-4)
    a_gamma = 1.0 - 0.287 * math.log(gamma)
    out[pos] = a_gamma * pm * gamma ** np.exp(-0.5 * ((x - 1.0) / s) ** 2)
    return out


def pierson_moskowitz_spectrum(
    omega: npt.ArrayLike, significant_height: float, peak_period: float
) -> np.ndarray:
    """Pierson-Moskowitz spectrum: :func:`jonswap_spectrum` with ``gamma = 1`` (DNV-RP-C205,
    section 3.5.5) [m^2 s/rad]."""
    return jonswap_spectrum(omega, significant_height, peak_period, 1.0)


def encounter_angle(wave_direction: npt.ArrayLike, heading: npt.ArrayLike) -> np.ndarray:
    """Encounter angle ``beta = beta_w - psi`` wrapped to ``[-pi, pi)`` [rad].

    ``0`` following seas, ``+pi/2`` waves travelling to starboard (beam seas from port),
    ``-pi`` head seas (Fossen 2021, section 10.2).

    Parameters
    ----------
    wave_direction : array_like
        Direction the waves travel toward, ``beta_w`` [rad], clockwise from north.
    heading : array_like
        Ship heading ``psi`` [rad], clockwise from north; broadcast with ``wave_direction``.
    """
    return ssa(real_array(wave_direction, "wave direction") - real_array(heading, "heading"))


def encounter_frequency(
    omega: npt.ArrayLike, speed: npt.ArrayLike, encounter_angle: npt.ArrayLike
) -> np.ndarray:
    """Encounter frequency ``omega_e = omega - omega^2 U cos(beta) / g`` in deep water.

    Parameters
    ----------
    omega : array_like
        Wave frequencies [rad/s], finite and >= 0.
    speed : array_like
        Ship speed ``U`` [m/s] (negative going astern).
    encounter_angle : array_like
        ``beta`` [rad]: 0 following seas, ``pi`` head seas (:func:`encounter_angle`).

    Returns
    -------
    numpy.ndarray
        ``omega_e`` [rad/s], the broadcast shape; signed (negative when the ship overtakes
        following waves; the observed frequency is its absolute value).

    Raises
    ------
    ValueError
        For a negative or non-finite frequency, or a non-finite speed or angle.
    """
    w = _frequencies(omega)
    u = real_array(speed, "speed")
    beta = real_array(encounter_angle, "encounter angle")
    require_finite(u, "speed")
    require_finite(beta, "encounter angle")
    return w - w * w * u * np.cos(beta) / GRAVITY


@dataclass(frozen=True, eq=False)
class SeaRealisation:
    """One seeded realisation of a sea's surface (:func:`realise_sea`).

    Attributes
    ----------
    frequencies : numpy.ndarray
        ``omega_k`` [rad/s], shape ``(N,)``.
    amplitudes : numpy.ndarray
        ``A_k = sqrt(2 S(omega_k) d omega)`` [m].
    phases : numpy.ndarray
        ``eps_k`` [rad] in ``[0, 2 pi)``.
    direction : float
        Direction of travel ``beta_w`` [rad], clockwise from north.
    """

    frequencies: np.ndarray
    amplitudes: np.ndarray
    phases: np.ndarray
    direction: float

    @property
    def wavenumbers(self) -> np.ndarray:
        """Deep-water wave numbers ``k_k = omega_k^2 / g`` [rad/m]."""
        return self.frequencies**2 / GRAVITY

    def elevation(
        self, t: npt.ArrayLike, north: npt.ArrayLike = 0.0, east: npt.ArrayLike = 0.0
    ) -> np.ndarray:
        """Surface elevation ``zeta(x, y, t)`` [m] (upward) at the earth-fixed position
        ``(north, east)`` [m] and time ``t`` [s]; the three broadcast together (a moving ship
        passes its track's positions with the times)."""
        tt = real_array(t, "t")
        x = real_array(north, "north")
        y = real_array(east, "east")
        for arr, name in ((tt, "t"), (x, "north"), (y, "east")):
            require_finite(arr, name)
        try:
            tt, x, y = np.broadcast_arrays(tt, x, y)
        except ValueError:
            raise ValueError(
                f"t, north and east must broadcast to one shape, got {tt.shape}, {x.shape} and "
                f"{y.shape}"
            ) from None
        along = x * math.cos(self.direction) + y * math.sin(self.direction)
        zeta = np.zeros(tt.shape)
        for w, k, a, eps in zip(
            self.frequencies, self.wavenumbers, self.amplitudes, self.phases, strict=True
        ):
            zeta += a * np.cos(w * tt - k * along + eps)
        return zeta


def realise_sea(
    sea_state: SeaState,
    seed: int | np.random.Generator | None,
    n_components: int = 1000,
    band: tuple[float, float] = (0.5, 5.0),
) -> SeaRealisation:
    """A seeded realisation of ``sea_state``'s surface as a sum of regular waves.

    Parameters
    ----------
    sea_state : SeaState
        The sea.
    seed : int, numpy.random.Generator or None
        Seed of :func:`numpy.random.default_rng` (a generator is used as it is): the same seed
        gives the same sea.
    n_components : int
        ``N``, the number of regular waves (>= 1). The record's spectrum is resolved to the
        interval width ``(omega_max - omega_min) / N``: a Welch estimate finer than that sees
        the single waves as lines.
    band : tuple of float
        ``(omega_min, omega_max) / omega_p``, the frequency band [-] cut into ``N`` intervals;
        the default ``(0.5, 5)`` holds all but 0.2 % of the energy. Sample the record faster
        than ``pi / omega_max`` to avoid aliasing.

    Returns
    -------
    SeaRealisation
        Random frequencies within each interval and random phases (module docstring).

    Raises
    ------
    ValueError
        For ``n_components < 1`` or a band that is not ``0 <= low < high``.
    """
    if not isinstance(sea_state, SeaState):
        raise TypeError(f"sea_state must be a SeaState, got {type(sea_state).__name__}")
    if isinstance(n_components, bool) or not isinstance(n_components, numbers.Integral):
        raise TypeError(f"n_components must be an integer, got {n_components!r}")
    if n_components < 1:
        raise ValueError(f"n_components must be >= 1, got {n_components}")
    low, high = (_finite(b, "band") for b in band)
    if not 0.0 <= low < high:
        raise ValueError(f"band must be (low, high) with 0 <= low < high, got {band!r}")
    rng = np.random.default_rng(seed)
    wp = sea_state.peak_frequency
    dw = (high - low) * wp / n_components
    edges = low * wp + dw * np.arange(n_components)
    frequencies = edges + dw * rng.random(n_components)
    phases = 2.0 * math.pi * rng.random(n_components)
    amplitudes = np.sqrt(2.0 * sea_state.spectrum(frequencies) * dw)
    return SeaRealisation(frequencies, amplitudes, phases, float(sea_state.direction))


def fit_wave_response(sea_state: SeaState) -> tuple[float, float]:
    """Damping ``lambda`` [-] and gain ``sigma = sqrt(max S)`` [m sqrt(s/rad)] of Fossen's
    linear wave response model fitted to the sea's spectrum (module docstring).

    ``lambda`` minimises ``sum (|h(j omega)|^2 - S(omega))^2`` over ``omega / omega_p`` in
    ``(0, 4]`` with ``omega_0 = omega_p`` (MSS ``exLinspec.m``). It depends on ``gamma``
    alone, ``S(omega) / S(omega_p)`` being a function of ``omega / omega_p``: it is fitted once
    per ``gamma``.
    """
    return _fitted_damping(float(sea_state.gamma)), math.sqrt(sea_state.peak_density)


@functools.lru_cache(maxsize=64)
def _fitted_damping(gamma: float) -> float:
    """The least-squares ``lambda`` of :func:`fit_wave_response` on the unit sea (``H_s`` 1 m,
    ``omega_p`` 1 rad/s) of peak enhancement ``gamma``."""
    unit = SeaState(1.0, 2.0 * math.pi, 0.0, gamma)
    sigma2 = unit.peak_density
    w = np.linspace(_FIT_BAND / _FIT_POINTS, _FIT_BAND, _FIT_POINTS)
    target = unit.spectrum(w)

    def residual(lam: float) -> float:
        return float(np.sum((_linear_psd(w, 1.0, lam, sigma2) - target) ** 2))

    from scipy.optimize import minimize_scalar  # here: importing shipgym stays light

    fit = minimize_scalar(
        residual, bounds=_FIT_BOUNDS, method="bounded", options={"xatol": 1e-7}
    )
    return float(fit.x)


def _linear_psd(w: np.ndarray, w0: float, lam: float, sigma2: float) -> np.ndarray:
    """``|h(j omega)|^2 = 4 (lambda omega_0 sigma)^2 omega^2 / ((omega_0^2 - omega^2)^2 +
    4 (lambda omega_0 omega)^2)``."""
    c = 2.0 * lam * w0
    return c * c * sigma2 * w * w / ((w0 * w0 - w * w) ** 2 + (c * w) ** 2)


@dataclass(frozen=True, eq=False)
class WaveResponseModel:
    """Fossen's linear wave response model, discretised (module docstring).

    State ``x = (x1, x2)`` with output ``y = x2`` (the wave-frequency elevation [m]; scale it
    for a motion). Build it with :func:`wave_response_model`.

    Attributes
    ----------
    natural_frequency : float
        ``omega_0`` [rad/s], the encounter peak frequency.
    damping : float
        ``lambda`` [-].
    sigma : float
        ``sqrt(max S)`` [m sqrt(s/rad)].
    dt : float
        Time step [s].
    transition : numpy.ndarray
        ``A_d = exp(A dt)``, shape ``(2, 2)``.
    noise_gain : numpy.ndarray
        ``B_d``, shape ``(2, 2)``: the step's noise is ``B_d n``, ``n`` standard normal.
    """

    natural_frequency: float
    damping: float
    sigma: float
    dt: float
    transition: np.ndarray = field(repr=False)
    noise_gain: np.ndarray = field(repr=False)

    @property
    def gain(self) -> float:
        """``K_w = 2 lambda omega_0 sigma``."""
        return 2.0 * self.damping * self.natural_frequency * self.sigma

    @property
    def variance(self) -> float:
        """Stationary variance of ``y``, ``pi lambda omega_0 sigma^2`` [m^2]."""
        return math.pi * self.damping * self.natural_frequency * self.sigma**2

    def psd(self, omega: npt.ArrayLike) -> np.ndarray:
        """``|h(j omega)|^2`` [m^2 s/rad], the one-sided spectrum of ``y``."""
        return _linear_psd(_frequencies(omega), self.natural_frequency, self.damping, self.sigma**2)

    def step(self, state: npt.ArrayLike, noise: npt.ArrayLike) -> np.ndarray:
        """One step ``x_{k+1} = A_d x_k + B_d n_k`` of states of shape ``(..., 2)`` with standard
        normal ``noise`` of the same shape; the output is ``[..., 1]``."""
        x = real_array(state, "state")
        n = real_array(noise, "noise")
        if x.shape[-1:] != (2,) or n.shape != x.shape:
            raise ValueError(
                f"state and noise must have one shape (..., 2), got {x.shape} and {n.shape}"
            )
        return x @ self.transition.T + n @ self.noise_gain.T

    def simulate(
        self, n_steps: int, seed: int | np.random.Generator | None, state: npt.ArrayLike = (0, 0)
    ) -> np.ndarray:
        """Outputs ``y_1 ... y_n`` [m] of ``n_steps`` steps from ``state``, the noise drawn
        from :func:`numpy.random.default_rng` of ``seed``."""
        if isinstance(n_steps, bool) or not isinstance(n_steps, numbers.Integral):
            raise TypeError(f"n_steps must be an integer, got {n_steps!r}")
        if n_steps < 0:
            raise ValueError(f"n_steps must be >= 0, got {n_steps}")
        noise = np.random.default_rng(seed).standard_normal((n_steps, 2)) @ self.noise_gain.T
        x = real_array(state, "state")
        if x.shape != (2,):
            raise ValueError(f"state must have shape (2,), got {x.shape}")
        out = np.empty(n_steps)
        a = self.transition
        for k in range(n_steps):
            x = a @ x + noise[k]
            out[k] = x[1]
        return out


def wave_response_model(
    sea_state: SeaState, dt: float, speed: float = 0.0, heading: float = 0.0
) -> WaveResponseModel:
    """Fossen's linear wave response model of ``sea_state`` met at ``speed`` and ``heading``,
    discretised exactly with step ``dt`` (module docstring).

    Parameters
    ----------
    sea_state : SeaState
        The sea; ``lambda`` and ``sigma`` from :func:`fit_wave_response`.
    dt : float
        Time step [s], > 0.
    speed : float
        Ship speed ``U`` [m/s].
    heading : float
        Ship heading ``psi`` [rad], clockwise from north.

    Returns
    -------
    WaveResponseModel
        With ``omega_0 = |omega_e(omega_p, U, beta_w - psi)|``.
    """
    if not isinstance(sea_state, SeaState):
        raise TypeError(f"sea_state must be a SeaState, got {type(sea_state).__name__}")
    h = step_size(dt)
    beta = encounter_angle(sea_state.direction, _finite(heading, "heading"))
    w0 = abs(float(encounter_frequency(sea_state.peak_frequency, _finite(speed, "speed"), beta)))
    lam, sigma = fit_wave_response(sea_state)
    k_w = 2.0 * lam * w0 * sigma
    a = np.array([[0.0, 1.0], [-w0 * w0, -2.0 * lam * w0]])
    q = np.array([[0.0, 0.0], [0.0, math.pi * k_w * k_w]])
    # Van Loan (1978): exp([[-A, Q], [0, A^T]] dt) = [[., F12], [0, F22]], A_d = F22^T,
    # Q_d = A_d F12
    from scipy.linalg import expm  # here: importing shipgym stays light

    m = expm(np.block([[-a, q], [np.zeros((2, 2)), a.T]]) * h)
    a_d = m[2:, 2:].T
    q_d = a_d @ m[:2, 2:]
    vals, vecs = np.linalg.eigh(0.5 * (q_d + q_d.T))
    b_d = vecs * np.sqrt(np.clip(vals, 0.0, None))
    for arr in (a_d, b_d):
        arr.flags.writeable = False
    return WaveResponseModel(w0, lam, sigma, h, a_d, b_d)


def box_waterline(length: float, beam: float) -> np.ndarray:
    """Rectangular waterline ``length x beam`` [m] centred on midship: vertices ``(x, y)``
    (x forward, y starboard), shape ``(4, 2)``, for :func:`mean_drift_force`."""
    half_l = 0.5 * _positive(length, "length")
    half_b = 0.5 * _positive(beam, "beam")
    return np.array([[-half_l, -half_b], [half_l, -half_b], [half_l, half_b], [-half_l, half_b]])


def _positive(value: Any, name: str) -> float:
    v = _finite(value, name)
    if v <= 0.0:
        raise ValueError(f"{name} must be > 0 m, got {v!r}")
    return v


def mean_drift_force(
    sea_state: SeaState,
    heading: npt.ArrayLike,
    waterline: npt.ArrayLike,
    rho: float = WATER_DENSITY,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean wave drift force and moment on a wall-sided hull in short waves (Faltinsen 1990,
    chapter 5; module docstring).

    Parameters
    ----------
    sea_state : SeaState
        The sea.
    heading : array_like
        Ship heading ``psi`` [rad], clockwise from north.
    waterline : array_like
        Vertices ``(x, y)`` [m] of a convex waterline polygon in body axes about the point of
        the moment (x forward, y starboard), shape ``(m, 2)``, ``m >= 3``, either orientation
        (:func:`box_waterline`).
    rho : float
        Water density [kg/m^3].

    Returns
    -------
    X, Y, N : numpy.ndarray
        Surge (forward) and sway (starboard) force [N] and yaw moment (clockwise) [N m], shape
        of ``heading``. For a box ``L x B``, ``C = rho g H_s^2 / 16`` and ``beta`` the
        encounter angle: ``X = C B cos(beta) |cos(beta)|``, ``Y = C L sin(beta) |sin(beta)|``,
        ``N = 0``.

    Raises
    ------
    ValueError
        For a waterline that is not a convex polygon of at least 3 distinct vertices, a
        non-finite heading or a density that is not > 0.
    """
    if not isinstance(sea_state, SeaState):
        raise TypeError(f"sea_state must be a SeaState, got {type(sea_state).__name__}")
    rho = _finite(rho, "rho")
    if rho <= 0.0:
        raise ValueError(f"rho must be > 0 kg/m^3, got {rho!r}")
    psi = real_array(heading, "heading")
    require_finite(psi, "heading")
    p = real_array(waterline, "waterline")
    require_finite(p, "waterline")
    if p.ndim != 2 or p.shape[0] < 3 or p.shape[1] != 2:
        raise ValueError(f"waterline must have shape (m, 2) with m >= 3, got {p.shape}")
    d = np.roll(p, -1, axis=0) - p
    lengths = np.hypot(d[:, 0], d[:, 1])
    if (lengths == 0.0).any():
        raise ValueError("waterline must not repeat a vertex, got two equal successive vertices")
    turns = d[:, 0] * np.roll(d, -1, axis=0)[:, 1] - d[:, 1] * np.roll(d, -1, axis=0)[:, 0]
    if not ((turns >= 0.0).all() or (turns <= 0.0).all()) or not turns.any():
        raise ValueError("waterline must be a convex polygon (its vertices in order)")
    orientation = 1.0 if turns.sum() > 0.0 else -1.0
    # outward normals of the edges; the force per metre on a lit edge is C cos^2 (-n), at
    # its midpoint
    nx = orientation * d[:, 1] / lengths
    ny = -orientation * d[:, 0] / lengths
    mid = p + 0.5 * d
    beta = encounter_angle(sea_state.direction, psi)[..., None]
    cos_in = nx * np.cos(beta) + ny * np.sin(beta)
    lit = np.where(cos_in < 0.0, cos_in * cos_in * lengths, 0.0)
    c = rho * GRAVITY * sea_state.significant_height**2 / 16.0
    fx = -c * np.sum(lit * nx, axis=-1)
    fy = -c * np.sum(lit * ny, axis=-1)
    n = -c * np.sum(lit * (mid[:, 0] * ny - mid[:, 1] * nx), axis=-1)
    return fx, fy, n


def reflection_factor(sea_state: SeaState, draught: float, points: int = 400) -> float:
    """Spectral mean of the squared reflection coefficient ``R(k d)^2`` of Ursell's barrier
    (module docstring): ``int S(omega) R^2 d omega / int S(omega) d omega``, the share of
    :func:`mean_drift_force`'s short-wave limit that a hull of draught ``d`` meets in the sea.

    Parameters
    ----------
    sea_state : SeaState
        The sea.
    draught : float
        ``d`` [m] (> 0).
    points : int
        Frequencies of the quadrature over ``(0, 5 omega_p]`` (the spectrum above holds less
        than 0.1 % of ``m0``).

    Returns
    -------
    float
        In ``(0, 1)``: near 1 when the peak wave is short against the draught, small when it
        is long.
    """
    if not isinstance(sea_state, SeaState):
        raise TypeError(f"sea_state must be a SeaState, got {type(sea_state).__name__}")
    d = _positive(draught, "draught")
    w = np.linspace(5.0 * sea_state.peak_frequency / points, 5.0 * sea_state.peak_frequency, points)
    spectrum = sea_state.spectrum(w)
    x = np.minimum(w * w / GRAVITY * d, 200.0)
    # R^2 = 1 / (1 + (K_1 / (pi I_1))^2), with the exponentially scaled Bessel functions
    from scipy.special import i1e, k1e  # here: importing shipgym stays light

    ratio = k1e(x) / (math.pi * i1e(x)) * np.exp(-2.0 * x)
    return float(np.sum(spectrum / (1.0 + ratio * ratio)) / np.sum(spectrum))

"""The seaway of the environments: wind and waves as disturbances of the ship models, per
ship and step (seed 003 eq. 1: ``tau_wind`` and ``tau_wave``; Fossen 2021, chapter 10).

Every part is the package's one function for it (:mod:`shipgym.models.wind`,
:mod:`shipgym.models.waves`); this module tabulates them for a ship and evaluates them in the
compiled step of every environment, for a batch of ships at once. A ship's seaway is drawn
from its episode's seed, so an episode's wind and sea are a function of that seed.

Loads
    Held over the RK4 step like the current (rows 2-4 of the block's disturbances,
    :data:`shipgym.models.integrate.NC`).

    * Wind: the mean wind ``U_10`` [m/s] from ``beta_wind`` (the direction it comes FROM,
      clockwise from north, the meteorological convention) plus gusts ``g(t)``; the apparent
      wind from the ship's velocity over ground (:func:`~shipgym.models.wind.apparent_wind`);
      the load ``q C(gamma)`` with ``q = 1/2 rho_a V_a^2`` and the coefficients of the ship
      tabulated every :data:`ANGLE_STEP` of the apparent angle ``gamma`` from the published
      model: Isherwood (1972) for the Mariner of the Nomoto family
      (:func:`~shipgym.models.wind.isherwood_load`, :data:`~shipgym.models.wind.MARINER_WIND`),
      Blendermann (1994) for the R/V Gunnerus (:func:`~shipgym.models.wind.blendermann_load`,
      :data:`~shipgym.models.wind.GUNNERUS_WIND`).
    * Gusts: a first-order Gauss-Markov process with the variance and the integral time scale
      of the NORSOK N-003 spectrum (``S(0) = 4 sigma^2 T``, both matched exactly)::

          sigma^2 = 320 (U_10 / 10)^2.75 I / 172,   T = 172 / (4 I) (U_10 / 10)^-0.75,
          I = int_0^inf (1 + x^n)^(-5 / (3 n)) dx = Gamma(1/n) Gamma(2/(3n)) / (n Gamma(5/(3n)))
            = 0.5672  (n = 0.468),

      ``g_{k+1} = a g_k + sigma sqrt(1 - a^2) n_k``, ``a = exp(-dt / T)``. (At 10 m/s: sigma =
      1.03 m/s, T = 76 s.) Its spectrum falls as ``f^-2`` where NORSOK's falls as ``f^-5/3``:
      the full spectrum is :func:`~shipgym.models.wind.wind_gusts`'s.
    * Mean wave drift: Faltinsen's short-wave drift on the ship's waterline (a box ``L x B``,
      :func:`~shipgym.models.waves.mean_drift_force`) tabulated over the encounter angle,
      times :func:`~shipgym.models.waves.reflection_factor` (Ursell's reflection of waves
      longer than the draught), ``rho g H_s^2 / 16`` in all.
    * The Nomoto family has no sway or surge equation: its load is the equivalent rudder angle
      and the leeway of :func:`~shipgym.models.wind.mariner_nomoto_wind`,
      ``delta_w = N / (N'_delta 1/2 rho U^2 L^3)``, ``v_w = Y / (-Y'_v 1/2 rho U L^2)``, with
      ``U`` at least :data:`MIN_NOMOTO_SPEED`; its surge force is left out.

Wave-frequency motion
    Added to the measured heading, yaw rate and position; the physics integrates the
    low-frequency motion alone (Fossen 2021, section 10.2.4). A ship in long-crested waves of
    frequency ``omega`` and amplitude ``zeta_a`` at encounter angle ``beta`` is taken to
    follow the water surface's horizontal orbital motion averaged over its length ``L`` (the
    Froude-Krylov, long-wave limit: a body small against the wave moves with the water; its
    length filters waves shorter than itself). With ``q = k
    cos(beta)``, ``k = omega^2 / g`` and ``a = L / 2``, the displacement along the wave
    direction and the yaw angle (the least-squares rotation of the sway displacement along
    the hull) per unit amplitude are::

        xi / zeta_a  = sin(q a) / (q a),
        psi / zeta_a = 12 sin(beta) / L^3 * 2 (sin(q a) / q^2 - a cos(q a) / q),

    the yaw in quadrature with the displacement (``-> k sin(beta) cos(beta)``, half the wave
    slope at 45 deg, in long waves). With ``q a = s x^2``, ``x = omega / omega_p`` and
    ``s = kappa cos(beta)``, ``kappa = omega_p^2 L / (2 g)``, the yaw is ``6 sin(beta) / L``
    times the spherical Bessel function ``j1(q a)``, and the spectral RMS of both per metre
    of ``sigma_zeta = H_s / 4`` are ``G_xi = 4 F_xi(s)`` and ``G_psi = 4 (6 / L) sin(beta)
    F_psi(s)``: the factors ``F`` depend on the spectrum's shape ``gamma`` and on ``s`` alone,
    so one table serves every ship and sea (:func:`wave_motion_factors`,
    :func:`wave_motion_table`; :func:`wave_motion_gains` over ``beta``). The time
    series is one unit-variance AR(2) process per ship with the poles of Fossen's linear
    wave response model (:mod:`shipgym.models.waves`) at the encounter peak frequency
    ``omega_e = |omega_p - omega_p^2 U cos(beta) / g|`` of the moment (at least
    :data:`MIN_ENCOUNTER_FREQUENCY`), and its damping ``lambda``::

        y_{k+1} = 2 rho cos(theta) y_k - rho^2 y_{k-1} + s n_k,
        rho = exp(-lambda omega_e dt),  theta = omega_e sqrt(1 - lambda^2) dt,
        s^2 = (1 - rho^2) ((1 + rho^2)^2 - 4 rho^2 cos^2 theta) / (1 + rho^2),

    so that ``var(y) = 1``; the displacement is ``sigma_zeta G_xi y``, the yaw ``sigma_zeta
    G_psi y_q`` with the quadrature ``y_q = (rho y_{k-1} - y_k cos theta) / sin(theta)`` and
    the WF yaw rate ``sigma_zeta G_psi omega_e y``.

Noise
    Each ship's white noise comes from its own SplitMix64 stream (Steele, Lea and Flood 2014),
    seeded from its episode's draws, one draw a step: its high and low 32 bits are two
    unit-variance uniform numbers ``sqrt(12) (u - 1/2)``,
    which the slow filters above turn into Gaussian processes (central limit). A ship's
    disturbances do not depend on the other ships of its batch.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from shipgym.models import wind as _wind
from shipgym.models._jit import kernel, row_kernel
from shipgym.models.integrate import BLOCK
from shipgym.models.rvg import CG_FORWARD_OF_AP, DRAUGHT, GRAVITY, LPP, WATER_DENSITY
from shipgym.models.vmath import atan2, sincos
from shipgym.models.waves import SeaState, box_waterline, fit_wave_response, mean_drift_force

__all__ = [
    "ANGLE_STEP",
    "MIN_ENCOUNTER_FREQUENCY",
    "MIN_NOMOTO_SPEED",
    "SeawayShip",
    "gunnerus_seaway",
    "gust_parameters",
    "mariner_seaway",
    "seaway_block",
    "start_rows",
    "wave_damping",
    "wave_motion_factors",
    "wave_motion_gains",
    "wave_motion_table",
]

ANGLE_STEP = math.radians(2.0)
"""Spacing [rad] of the tables of wind and drift coefficients over the angle."""
_ANGLES = np.linspace(-math.pi, math.pi, round(2.0 * math.pi / ANGLE_STEP) + 1)
#: Encounter angles [rad] of :func:`wave_motion_gains` (every 10 deg).
GAIN_ANGLES = np.linspace(-math.pi, math.pi, 37)
WAVE_MOTION_STEP = 0.05
"""Spacing of :func:`wave_motion_table` in ``u = sqrt(|s|)``."""
#: Its last ``u`` (``|s| = 100``: waves a hundredth of the ship's length).
_LAST_U = 10.0
#: Spectrum shapes ``gamma`` of :func:`wave_motion_table`.
TABLE_GAMMAS = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0)
_LAST_U_CELL = round(_LAST_U / WAVE_MOTION_STEP) - 1.0
MIN_ENCOUNTER_FREQUENCY = 0.05
"""Lowest encounter frequency [rad/s] of the wave-frequency motion (a following sea that the
ship nearly rides)."""
MIN_NOMOTO_SPEED = 1.0
"""Lowest speed [m/s] at which a Nomoto-family ship's load becomes a rudder angle and leeway."""

_NORSOK_N = 0.468
#: ``int_0^inf (1 + x^n)^(-5 / (3 n)) dx`` of NORSOK's spectrum in closed form (substituting
#: ``t = x^n`` makes it Euler's beta integral): ``B(1/n, 5/(3n) - 1/n) / n``.
_NORSOK_INTEGRAL = (
    math.gamma(1.0 / _NORSOK_N) * math.gamma(2.0 / (3.0 * _NORSOK_N))
    / (_NORSOK_N * math.gamma(5.0 / (3.0 * _NORSOK_N)))
)  # fmt: skip

#: Kinds of ship of the compiled step: how the load enters the model.
NOMOTO_KIND, THREE_DOF_KIND = 0, 1


@dataclass(frozen=True, eq=False)
class SeawayShip:
    """What the seaway needs to know of a ship.

    Attributes
    ----------
    name : str
        The ship.
    kind : int
        :data:`NOMOTO_KIND` (the load becomes an equivalent rudder angle and leeway) or
        :data:`THREE_DOF_KIND` (surge and sway force, yaw moment).
    length, beam, draught : float
        Waterline length, beam and draught [m] (wave motion and drift).
    wind : numpy.ndarray
        ``(3, m)`` wind load ``X, Y, N`` per unit dynamic pressure [m^2, m^2, m^3] at the
        apparent angles ``-pi, -pi + ANGLE_STEP, ..., pi``, the moment about the model's origin.
    drift : numpy.ndarray
        ``(3, m)`` mean drift ``X, Y, N`` per unit ``rho g H_s^2 / 16`` [m, m, m^2] at the
        encounter angles of ``wind``, about the model's origin (short-wave limit).
    nomoto : tuple of float
        ``(N'_delta, Y'_v, L)`` of the Nomoto family's conversion; zeros for a 3-DOF ship.
    """

    name: str
    kind: int
    length: float
    beam: float
    draught: float
    wind: np.ndarray = field(repr=False)
    drift: np.ndarray = field(repr=False)
    nomoto: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def constants(self) -> np.ndarray:
        """``[kind, N'_delta, Y'_v, L, 6 / length]``: the ship's constants of the compiled
        step (the last the yaw per unit ``j1`` of the wave-frequency motion)."""
        return np.array([float(self.kind), *self.nomoto, 6.0 / self.length], dtype=np.float64)


def _unit_drift(length: float, beam: float, origin_aft_of_midship: float) -> np.ndarray:
    """Drift per unit ``rho g H_s^2 / 16`` over :data:`_ANGLES`, moment about the origin."""
    unit_sea = SeaState(4.0, 20.0, 0.0)  # H_s^2 / 16 = 1; the short-wave limit has no T_p
    fx, fy, n = mean_drift_force(unit_sea, -_ANGLES, box_waterline(length, beam), rho=1.0)
    scale = 1.0 / GRAVITY
    return np.stack((fx, fy, n + origin_aft_of_midship * fy)) * scale


def _unit_wind(load, args: tuple[float, ...], origin_aft_of_midship: float) -> np.ndarray:
    """Wind load per unit dynamic pressure over :data:`_ANGLES`, moment about the origin."""
    speed = math.sqrt(2.0 / _wind.RHO_AIR)  # q = 1 Pa
    table = np.array([load(speed, float(g), *args) for g in _ANGLES]).T
    table[2] += origin_aft_of_midship * table[1]
    return table


@functools.cache
def mariner_seaway() -> SeawayShip:
    """The Mariner of the Nomoto family: Isherwood's wind loads on
    :data:`~shipgym.models.wind.MARINER_WIND`, a box waterline ``L_pp x B``."""
    length, beam = _wind.MARINER_LENGTH, _wind.MARINER_WIND.beam
    return SeawayShip(
        name="Mariner (Nomoto family)",
        kind=NOMOTO_KIND,
        length=length,
        beam=beam,
        draught=8.23,  # 27 ft, the C4-S-1a design draught (estimated)
        wind=_unit_wind(_wind.isherwood_load, _wind.MARINER_WIND.args(), 0.0),
        drift=_unit_drift(length, beam, 0.0),
        nomoto=(_wind.MARINER_N_DELTA, _wind.MARINER_Y_V, _wind.MARINER_LENGTH),
    )


@functools.cache
def gunnerus_seaway() -> SeawayShip:
    """The R/V Gunnerus: Blendermann's research-vessel wind loads on
    :data:`~shipgym.models.wind.GUNNERUS_WIND`, a box waterline ``L_pp x B``, moments about
    the model's origin."""
    # midship (half Lpp forward of the aft perpendicular) lies this far forward of the origin
    arm = 0.5 * LPP - CG_FORWARD_OF_AP
    beam = 9.6
    return SeawayShip(
        name="R/V Gunnerus",
        kind=THREE_DOF_KIND,
        length=LPP,
        beam=beam,
        draught=DRAUGHT,
        wind=_unit_wind(_wind.blendermann_load, _wind.GUNNERUS_WIND.args(), arm),
        drift=_unit_drift(LPP, beam, arm),
    )


def gust_parameters(mean_speed: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Standard deviation ``sigma`` [m/s] and step coefficient ``a = exp(-dt / T)`` of the
    gust process at mean wind speeds ``mean_speed`` (module docstring; no gusts in calm air)."""
    u = np.asarray(mean_speed, dtype=np.float64) / 10.0
    calm = u <= 0.0
    u = np.where(calm, 1.0, u)
    sigma = np.sqrt(320.0 * u**2.75 * _NORSOK_INTEGRAL / 172.0)
    scale = 172.0 / (4.0 * _NORSOK_INTEGRAL) * u**-0.75
    return np.where(calm, 0.0, sigma), np.where(calm, 1.0, np.exp(-dt / scale))


def wave_motion_factors(gamma: float, s: np.ndarray, points: int = 200) -> np.ndarray:
    """``(2, len(s))`` spectral RMS factors ``F_xi(s)`` and ``F_psi(s)`` of the wave-frequency
    displacement and yaw (module docstring) in a sea of spectrum shape ``gamma``, at
    ``s = kappa cos(beta)``, ``kappa = omega_p^2 L / (2 g)``.

    With ``x = omega / omega_p`` and the sea's normalised spectrum ``w(x)`` (a function of
    ``gamma`` alone)::

        F_xi(s)  = sqrt(sum w(x) sinc(s x^2)^2),
        F_psi(s) = sign(s) sqrt(sum w(x) j1(s x^2)^2),

    ``sinc(z) = sin(z) / z`` and ``j1(z) = sin(z) / z^2 - cos(z) / z`` (the spherical Bessel
    function). The yaw's sign is the long-wave limit's (``sin 2 beta``).
    """
    sea = SeaState(1.0, 2.0 * math.pi, 0.0, gamma)  # omega_p = 1: w is the frequency ratio x
    x = np.linspace(4.0 / points, 4.0, points)
    weight = sea.spectrum(x)
    weight = weight / weight.sum()
    s = np.asarray(s, dtype=np.float64)
    z = (x * x)[:, None] * s.ravel()[None, :]
    small = np.abs(z) < 1e-6
    safe = np.where(small, 1.0, z)
    sinc = np.where(small, 1.0, np.sin(safe) / safe)
    j1 = np.where(small, z / 3.0, np.sin(safe) / safe**2 - np.cos(safe) / safe)
    factors = np.stack((np.sqrt(weight @ (sinc * sinc)), np.sqrt(weight @ (j1 * j1))))
    factors[1] *= np.sign(s.ravel())
    return factors.reshape((2, *s.shape))


def wave_motion_gains(sea_state: SeaState, length: float, points: int = 200) -> np.ndarray:
    """``(2, 37)`` RMS displacement along the wave direction and signed RMS yaw per metre of
    ``sigma_zeta`` [m/m, rad/m] over the encounter angles :data:`GAIN_ANGLES` (module
    docstring), for a ship of waterline length ``length`` [m] in ``sea_state``: ``4 F_xi`` and
    ``4 (6 / L) sin(beta) F_psi`` of :func:`wave_motion_factors`.
    """
    kappa = sea_state.peak_frequency**2 * length / (2.0 * GRAVITY)
    factors = wave_motion_factors(sea_state.gamma, kappa * np.cos(GAIN_ANGLES), points)
    return 4.0 * np.stack((factors[0], 6.0 / length * np.sin(GAIN_ANGLES) * factors[1]))


@functools.cache
def wave_motion_table() -> np.ndarray:
    """``(2, 7, n)`` :func:`wave_motion_factors` ``F_xi``, ``F_psi`` of the compiled step: at
    the spectrum shapes ``gamma = 1, 2, ..., 7`` and at ``|s| = u^2`` for ``u = 0,``
    :data:`WAVE_MOTION_STEP` ``, ..., 10`` (``|s|`` up to 100: waves a hundredth of the ship's
    length), interpolated linearly in ``u`` and ``gamma`` (to 0.2 % of ``F_xi``'s and 0.4 % of
    ``F_psi``'s largest value); beyond ``|s| = 100`` the last value."""
    u = np.arange(round(_LAST_U / WAVE_MOTION_STEP) + 1) * WAVE_MOTION_STEP
    return np.ascontiguousarray(
        np.stack([wave_motion_factors(gamma, u * u) for gamma in TABLE_GAMMAS], axis=1)
    )


@functools.cache
def wave_damping(gamma: float) -> float:
    """Fossen's fitted damping ``lambda`` of the sea's spectrum shape ``gamma``."""
    return fit_wave_response(SeaState(1.0, 10.0, 0.0, gamma))[0]


# ---------------------------------------------------------------------------------------------
# The compiled step. Per ship: ``sea[i]`` its parameters (column names below), ``wf[i]`` its
# states, ``rng[i]`` its noise stream; ``tables`` the ship's wind and drift tables (6, m),
# ``gains`` the wave-motion factors of every ship and sea (:func:`wave_motion_table`), ``ship``
# the ship's constants.

#: Columns of a ship's seaway parameters (set at a reset).
(S_WIND, S_WIND_COS, S_WIND_SIN, S_GUST_SIGMA, S_GUST_A, S_GUST_B, S_WAVE_COS, S_WAVE_SIN,
 S_OMEGA_P, S_LAMBDA, S_TURN, S_HEIGHT, S_KAPPA, S_GAMMA_CELL, S_GAMMA_FRAC, S_DRIFT,
 S_WAVE_DIR) = range(17)  # fmt: skip
N_SEA = 17
#: Columns of a ship's seaway states: gust, the AR(2) process now and before, the wave motion
#: (north, east, heading, yaw rate), the wind speed of the moment and, beside it for the
#: ``info`` of the envs (one copy), the direction the wind comes from and the sea state
#: (``H_s``, ``T_p``, direction).
W_GUST, W_Y, W_Y_PREV, W_NORTH, W_EAST, W_PSI, W_R, W_SPEED, W_FROM, W_HS, W_TP, W_WDIR = range(12)
N_WF = 12
#: Largest ``lambda omega_e dt`` of the AR(2) process (its pole radius at least exp(-1.5)).
_MAX_DECAY = 1.5

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S32 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(32)
_LOW32 = np.uint64(0xFFFFFFFF)
_TO_UNIT = 1.0 / 4294967296.0
#: ``1 / k!``, the Taylor coefficients of the exponential
_E0, _E1, _E2, _E3, _E4, _E5, _E6, _E7, _E8, _E9, _E10 = (
    1.0 / math.factorial(k) for k in range(11)
)
_SQRT12 = math.sqrt(12.0)
_TWO_PI = 2.0 * math.pi
#: ``(v + _ROUND) - _ROUND`` rounds ``|v| < 2^51`` to the nearest integer (no library call)
_ROUND = 6755399441055744.0


@row_kernel
def noise(rng, i):
    """The next two unit-variance uniform numbers of ship ``i``'s SplitMix64 stream ``rng[i]``
    (the high and the low 32 bits of one draw)."""
    z = rng[i] + _GOLDEN
    rng[i] = z
    z = (z ^ (z >> _S30)) * _MIX1
    z = (z ^ (z >> _S27)) * _MIX2
    z = z ^ (z >> _S31)
    hi = np.float64(z >> _S32) * _TO_UNIT
    lo = np.float64(z & _LOW32) * _TO_UNIT
    return _SQRT12 * (hi - 0.5), _SQRT12 * (lo - 0.5)


@row_kernel
def normal(rng, i):
    """A standard normal number from ship ``i``'s stream (Box-Muller; for the resets)."""
    n1, n2 = noise(rng, i)
    u1 = n1 / _SQRT12 + 0.5
    u2 = n2 / _SQRT12 + 0.5
    return math.sqrt(-2.0 * math.log(1.0 - u1)) * math.cos(_TWO_PI * u2)


@row_kernel
def _exp_neg(z):
    """``exp(-z)`` for ``0 <= z <= 1.5`` to 1e-12 relative, straight-line (the Taylor series of
    ``exp(-z / 4)`` to the 10th power, squared twice)."""
    q = -0.25 * z
    e = _E0 + q * (_E1 + q * (_E2 + q * (_E3 + q * (_E4 + q * (_E5 + q * (_E6 + q * (
        _E7 + q * (_E8 + q * (_E9 + q * _E10)))))))))  # fmt: skip
    e *= e
    return e * e


@row_kernel
def ar2_coefficients(lam, turn, we, dt):
    """``(rho, cos theta, sin theta, s)`` of the unit-variance AR(2) wave process (module
    docstring) of damping ``lam`` (``turn = sqrt(1 - lam^2)``) at the encounter frequency
    ``we`` [rad/s], step ``dt`` [s]."""
    rho = _exp_neg(min(lam * we * dt, _MAX_DECAY))
    st, ct = sincos(min(we * turn * dt, 3.0))
    r2 = rho * rho
    p2 = 1.0 + r2
    return rho, ct, st, math.sqrt((1.0 - r2) * (p2 * p2 - 4.0 * r2 * ct * ct) / p2)


@row_kernel
def encounter_peak(wp, speed, cos_beta):
    """``|omega_p - omega_p^2 U cos(beta) / g|``, at least MIN_ENCOUNTER_FREQUENCY [rad/s]."""
    return max(abs(wp - wp * wp * speed * cos_beta / GRAVITY), MIN_ENCOUNTER_FREQUENCY)


@row_kernel
def _cell(angle, cells):
    """Cell (as a float) and fraction of ``angle`` [rad] (any number of turns) on a grid of
    ``cells`` equal cells over ``[-pi, pi]``."""
    t = (angle + math.pi) * (1.0 / _TWO_PI)
    # floors by rounding t - 1/2 (a select-free form that vectorises; math.floor does not): an
    # integer t may floor to t - 1, with the fraction 1 instead of 0, the same point
    t = (t - ((t - 0.5 + _ROUND) - _ROUND)) * cells  # the fraction of a turn, in cells
    k = min(max((t - 0.5 + _ROUND) - _ROUND, 0.0), cells - 1.0)
    return k, t - k


@row_kernel
def _bilerp(table, row, j, g, k, f):
    """``table[row]`` at the float cells ``j + g`` (axis 1) and ``k + f`` (axis 2)."""
    a, c = int(j), int(k)
    lo = table[row, a, c] + f * (table[row, a, c + 1] - table[row, a, c])
    hi = table[row, a + 1, c] + f * (table[row, a + 1, c + 1] - table[row, a + 1, c])
    return lo + g * (hi - lo)


@row_kernel
def _lerp(table, row, k, f):
    """``table[row]`` between cells ``k`` (a float from :func:`_cell`) and ``k + 1``."""
    j = int(k)
    return table[row, j] + f * (table[row, j + 1] - table[row, j])


# The seaway of a block of ships in three passes. A loop over ships vectorises (SIMD code) only
# if it reads and writes the columns of a small table of constant shape (so that its rows
# cannot overlap) by the ship's place in the block: it must not gather (a row chosen by
# ``rows``, a table cell chosen by an angle). So: gather each ship's numbers into the columns
# of ``work``; compute the sines, cosines, arctangents, square roots and the AR(2)
# coefficients of every ship in one loop of straight-line arithmetic (the long chains of
# dependent operations that one ship at a time waits on); then look the tables up and scatter.
(_PSI, _U, _V, _CN, _CE, _WCOS, _WSIN, _WDIR, _WP, _LAM, _TURN, _KAPPA, _WIND, _WINDC, _WINDS,
 _GA, _GB, _G, _Y, _YP, _N1, _N2, _WE, _QUAD, _KU, _FU, _YAW_DIR, _KB, _FB, _KW, _FW, _Q,
 _SPEED, _TO_RUDDER, _TO_LEEWAY) = range(35)  # fmt: skip
_WORK_ROWS = 35


@row_kernel
def _gather(rows, start, n, x, c, sea, wf, rng, advance, work):
    """Copy the block's ships' numbers into the columns of ``work`` and draw their noise."""
    for b in range(n):
        i = rows[start + b]
        work[_PSI, b] = x[i, 2]
        work[_U, b] = x[i, 3]
        work[_V, b] = x[i, 4]
        work[_CN, b] = c[i, 0]
        work[_CE, b] = c[i, 1]
        work[_WCOS, b] = sea[i, S_WAVE_COS]
        work[_WSIN, b] = sea[i, S_WAVE_SIN]
        work[_WDIR, b] = sea[i, S_WAVE_DIR]
        work[_WP, b] = sea[i, S_OMEGA_P]
        work[_LAM, b] = sea[i, S_LAMBDA]
        work[_TURN, b] = sea[i, S_TURN]
        work[_KAPPA, b] = sea[i, S_KAPPA]
        work[_WIND, b] = sea[i, S_WIND]
        work[_WINDC, b] = sea[i, S_WIND_COS]
        work[_WINDS, b] = sea[i, S_WIND_SIN]
        work[_GA, b] = sea[i, S_GUST_A]
        work[_GB, b] = sea[i, S_GUST_B]
        work[_G, b] = wf[i, W_GUST]
        work[_Y, b] = wf[i, W_Y]
        work[_YP, b] = wf[i, W_Y_PREV]
        work[_N1, b], work[_N2, b] = noise(rng, i) if advance else (0.0, 0.0)


@row_kernel
def _motion(n, ship, dt, advance, cells, work):
    """Every ship's wave process, gust, apparent wind and the table cells of its encounter and
    apparent wind angles (``cells`` of the load tables), and the wave-motion table's cell:
    straight-line code on ``work``."""
    keep = 1.0 if advance else 0.0
    nomoto = ship[0] == NOMOTO_KIND
    three_dof = 0.0 if nomoto else 1.0
    if nomoto:  # (the constants of the equivalent rudder angle and the leeway)
        rudder_per_load = 1.0 / (ship[1] * ship[3])
        leeway_per_load = -1.0 / ship[2]
    for b in range(n):
        sn, cs = sincos(work[_PSI, b])
        cn = work[_CN, b]
        ce = work[_CE, b]
        uc = cn * cs + ce * sn
        vc = -cn * sn + ce * cs
        # the AR(2) wave process at the encounter frequency of the moment
        ur = work[_U, b] - three_dof * uc  # a 3-DOF ship's surge is over ground
        cos_beta = work[_WCOS, b] * cs + work[_WSIN, b] * sn
        we = encounter_peak(work[_WP, b], ur, cos_beta)
        rho, ct, st, s = ar2_coefficients(work[_LAM, b], work[_TURN, b], we, dt)
        y0 = work[_Y, b]
        yp0 = work[_YP, b]
        y = keep * (2.0 * rho * ct * y0 - rho * rho * yp0 + s * work[_N1, b]) + (1.0 - keep) * y0
        yp = keep * y0 + (1.0 - keep) * yp0
        # the gust and the apparent wind (shipgym.models.wind.apparent_wind); none in calm air
        mean = work[_WIND, b]
        on = 1.0 if mean > 0.0 else 0.0
        g0 = work[_G, b]
        g = keep * (work[_GA, b] * g0 + work[_GB, b] * work[_N2, b]) + (1.0 - keep) * g0
        speed = on * max(mean + g, 0.0)
        ug = work[_U, b] + (1.0 - three_dof) * uc  # over ground: a Nomoto ship along its heading
        vg = three_dof * work[_V, b] + (1.0 - three_dof) * vc
        cw = work[_WINDC, b]
        sw = work[_WINDS, b]
        ax = -speed * (cw * cs + sw * sn) - ug
        ay = -speed * (-cw * sn + sw * cs) - vg
        work[_Y, b] = y
        work[_YP, b] = yp
        work[_G, b] = g
        work[_SPEED, b] = speed
        work[_WE, b] = we
        work[_QUAD, b] = (rho * yp - y * ct) / st
        beta = work[_WDIR, b] - work[_PSI, b]
        sin_beta = work[_WSIN, b] * cs - work[_WCOS, b] * sn
        work[_YAW_DIR, b] = sin_beta if cos_beta >= 0.0 else -sin_beta  # sin(beta) sign(s)
        t = math.sqrt(work[_KAPPA, b] * abs(cos_beta)) * (1.0 / WAVE_MOTION_STEP)
        k = min(max((t - 0.5 + _ROUND) - _ROUND, 0.0), _LAST_U_CELL)  # floor(t) (see _cell)
        work[_KU, b] = k
        work[_FU, b] = min(t - k, 1.0)
        work[_KB, b], work[_FB, b] = _cell(beta, cells)
        work[_KW, b], work[_FW, b] = _cell(atan2(-ay, -ax), cells)
        work[_Q, b] = on * 0.5 * _wind.RHO_AIR * (ax * ax + ay * ay)
        if nomoto:  # the factors of the equivalent rudder angle and the leeway
            u = max(work[_U, b], MIN_NOMOTO_SPEED)
            per_qu = 1.0 / (0.5 * WATER_DENSITY * u * u * ship[3] * ship[3])  # 1 / (qw u)
            work[_TO_RUDDER, b] = rudder_per_load * per_qu
            work[_TO_LEEWAY, b] = leeway_per_load * u * per_qu


@row_kernel
def _loads(rows, start, n, x, c, xm, sea, wf, tables, gains, ship, ir, work):
    """Look the block's ships' wave-motion factors, drift and wind coefficients up, and write
    their states, loads and measured states."""
    nomoto = ship[0] == NOMOTO_KIND
    for b in range(n):
        i = rows[start + b]
        y = work[_Y, b]
        kb, fb, kw, fw = work[_KB, b], work[_FB, b], work[_KW, b], work[_FW, b]
        jg, fg, ku, fu = sea[i, S_GAMMA_CELL], sea[i, S_GAMMA_FRAC], work[_KU, b], work[_FU, b]
        height = sea[i, S_HEIGHT]
        xi = height * _bilerp(gains, 0, jg, fg, ku, fu) * y
        gy = height * ship[4] * work[_YAW_DIR, b] * _bilerp(gains, 1, jg, fg, ku, fu)
        north = xi * work[_WCOS, b]
        east = xi * work[_WSIN, b]
        psi_w = gy * work[_QUAD, b]
        r_w = gy * work[_WE, b] * y
        drift = sea[i, S_DRIFT]
        q = work[_Q, b]
        fy = drift * _lerp(tables, 4, kb, fb) + q * _lerp(tables, 1, kw, fw)
        fn = drift * _lerp(tables, 5, kb, fb) + q * _lerp(tables, 2, kw, fw)
        if nomoto:  # the equivalent rudder angle and the leeway (no surge equation)
            fx, fy, fn = fn * work[_TO_RUDDER, b], fy * work[_TO_LEEWAY, b], 0.0
        else:
            fx = drift * _lerp(tables, 3, kb, fb) + q * _lerp(tables, 0, kw, fw)
        wf[i, W_Y] = y
        wf[i, W_Y_PREV] = work[_YP, b]
        wf[i, W_GUST] = work[_G, b]
        wf[i, W_SPEED] = work[_SPEED, b]
        wf[i, W_NORTH] = north
        wf[i, W_EAST] = east
        wf[i, W_PSI] = psi_w
        wf[i, W_R] = r_w
        c[i, 2] = fx
        c[i, 3] = fy
        c[i, 4] = fn
        for j in range(x.shape[1]):
            xm[i, j] = x[i, j]
        xm[i, 0] += north
        xm[i, 1] += east
        xm[i, 2] += psi_w
        xm[i, ir] += r_w


@row_kernel
def seaway_block(rows, start, n, x, c, xm, sea, wf, rng, tables, gains, ship, ir, dt, advance):
    """The seaway of ships ``rows[start:start + n]`` (``n <= BLOCK``) after a step
    (``advance``) or at a reset (module docstring).

    Advances their wave processes and gusts on a step; sets their measured states ``xm``
    (``x`` plus the wave-frequency motion: north, east, heading and, at ``ir``, yaw rate) and
    their loads of the coming step, ``c[:, 2:5]``, from the states now. ``sea``, ``wf`` and
    ``rng`` are the ships' parameters, states and noise streams, ``tables`` the ship's wind
    and drift coefficients (6 rows), ``gains`` :func:`wave_motion_table`, ``ship`` its
    :meth:`SeawayShip.constants`. A ship's result does not depend on the others'.
    """
    if n > BLOCK:
        raise ValueError("seaway_block takes at most BLOCK ships at a time")
    work = np.empty((_WORK_ROWS, BLOCK))  # its row stride a constant: the passes vectorise
    _gather(rows, start, n, x, c, sea, wf, rng, advance, work)
    _motion(n, ship, dt, advance, tables.shape[1] - 1.0, work)
    _loads(rows, start, n, x, c, xm, sea, wf, tables, gains, ship, ir, work)


@kernel
def start_rows(rows, x, c, sea, wf, rng, dt):
    """Start the gusts and the AR(2) wave process of each ship of ``rows`` (at a reset) in
    their stationary distribution."""
    for i in rows:
        wf[i, W_GUST] = sea[i, S_GUST_SIGMA] * normal(rng, i)
        sn, cs = sincos(x[i, 2])
        ur = x[i, 3]
        if x.shape[1] > 7:  # a 3-DOF ship's surge is over ground
            ur -= c[i, 0] * cs + c[i, 1] * sn
        cos_beta = sea[i, S_WAVE_COS] * cs + sea[i, S_WAVE_SIN] * sn
        we = encounter_peak(sea[i, S_OMEGA_P], ur, cos_beta)
        rho, ct, _, _ = ar2_coefficients(sea[i, S_LAMBDA], sea[i, S_TURN], we, dt)
        lag1 = 2.0 * rho * ct / (1.0 + rho * rho)  # the lag-one correlation
        y = normal(rng, i)
        wf[i, W_Y] = y
        wf[i, W_Y_PREV] = lag1 * y + math.sqrt(max(1.0 - lag1 * lag1, 0.0)) * normal(rng, i)

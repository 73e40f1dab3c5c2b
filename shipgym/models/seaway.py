"""The seaway of the environments: wind and waves as disturbances of the ship models, per
ship and step (seed 003 eq. 1: ``tau_wind`` and ``tau_wave``; Fossen 2021, chapter 10).

Every part is the package's one function for it (:mod:`shipgym.models.wind`,
:mod:`shipgym.models.waves`); this module tabulates them for a ship and evaluates them in the
compiled step of every environment, for a batch of ships at once. A ship's seaway is drawn
from its episode's seed, so an episode's wind and sea are a function of that seed.

Loads (held over the RK4 step like the current, rows 2-4 of the block's disturbances,
:data:`shipgym.models.integrate.NC`)
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
          I = int_0^inf (1 + x^0.468)^(-5 / (3 x 0.468)) dx = 0.5672,

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

Wave-frequency motion (added to the measured heading, yaw rate and position; the physics
integrates the low-frequency motion alone, Fossen 2021 section 10.2.4)
    A ship in long-crested waves of frequency ``omega`` and amplitude ``zeta_a`` at encounter
    angle ``beta`` is taken to follow the water surface's horizontal orbital motion averaged
    over its length ``L`` (the Froude-Krylov, long-wave limit: a body small against the
    wave moves with the water; its length filters waves shorter than itself). With ``q = k
    cos(beta)``, ``k = omega^2 / g`` and ``a = L / 2``, the displacement along the wave
    direction and the yaw angle (the least-squares rotation of the sway displacement along
    the hull) per unit amplitude are::

        xi / zeta_a  = sin(q a) / (q a),
        psi / zeta_a = 12 sin(beta) / L^3 * 2 (sin(q a) / q^2 - a cos(q a) / q),

    the yaw in quadrature with the displacement (``-> k sin(beta) cos(beta)``, half the wave
    slope at 45 deg, in long waves). Their spectral RMS per metre of ``sigma_zeta = H_s / 4``
    is tabulated over ``beta`` for each ship's sea (:func:`wave_motion_gains`). The time
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
    seeded from its episode's draws: unit-variance uniform numbers ``sqrt(12) (u - 1/2)``,
    which the slow filters above turn into Gaussian processes (central limit). A ship's
    disturbances do not depend on the other ships of its batch.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
import scipy.integrate

from shipgym.models import wind as _wind
from shipgym.models._jit import kernel, row_kernel
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
    "wave_motion_gains",
]

ANGLE_STEP = math.radians(2.0)
"""Spacing [rad] of the tables of wind and drift coefficients over the angle."""
_ANGLES = np.linspace(-math.pi, math.pi, round(2.0 * math.pi / ANGLE_STEP) + 1)
#: Encounter angles [rad] of the wave-motion gain tables (every 10 deg).
GAIN_ANGLES = np.linspace(-math.pi, math.pi, 37)
MIN_ENCOUNTER_FREQUENCY = 0.05
"""Lowest encounter frequency [rad/s] of the wave-frequency motion (a following sea that the
ship nearly rides)."""
MIN_NOMOTO_SPEED = 1.0
"""Lowest speed [m/s] at which a Nomoto-family ship's load becomes a rudder angle and leeway."""

_NORSOK_N = 0.468
_NORSOK_INTEGRAL = scipy.integrate.quad(
    lambda x: (1.0 + x**_NORSOK_N) ** (-5.0 / (3.0 * _NORSOK_N)), 0.0, np.inf, limit=500
)[0]

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
        """``[kind, N'_delta, Y'_v, L]``: the ship's constants of the compiled step."""
        return np.array([float(self.kind), *self.nomoto], dtype=np.float64)


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


def wave_motion_gains(sea_state: SeaState, length: float, points: int = 200) -> np.ndarray:
    """``(2, 37)`` RMS displacement along the wave direction and signed RMS yaw per metre of
    ``sigma_zeta`` [m/m, rad/m] over the encounter angles :data:`GAIN_ANGLES` (module
    docstring), for a ship of waterline length ``length`` [m] in ``sea_state``.

    The yaw's sign is that of its in-phase part with the long-wave limit (``sin 2 beta``).
    """
    wp = sea_state.peak_frequency
    w = np.linspace(4.0 * wp / points, 4.0 * wp, points)
    weight = sea_state.spectrum(w)
    weight = weight / weight.sum()
    a = 0.5 * length
    q = (w * w / GRAVITY)[:, None] * np.cos(GAIN_ANGLES)[None, :]
    qa = q * a
    small = np.abs(qa) < 1e-6
    safe = np.where(small, 1.0, q)
    xi = np.where(small, 1.0, np.sin(qa) / np.where(small, 1.0, qa))
    moment = np.where(small, q * a**3 / 1.5, 2.0 * (np.sin(qa) / safe**2 - a * np.cos(qa) / safe))
    yaw = 12.0 / length**3 * np.sin(GAIN_ANGLES)[None, :] * moment
    rms_xi = np.sqrt(weight @ (xi * xi))
    rms_yaw = np.sqrt(weight @ (yaw * yaw)) * np.sign(weight @ yaw)
    return 4.0 * np.stack((rms_xi, rms_yaw))  # per metre of H_s / 4


def wave_damping(gamma: float) -> float:
    """Fossen's fitted damping ``lambda`` of the sea's spectrum shape ``gamma``."""
    return fit_wave_response(SeaState(1.0, 10.0, 0.0, gamma))[0]


# ---------------------------------------------------------------------------------------------
# The compiled step. Per ship: ``sea[i]`` its parameters (column names below), ``wf[i]`` its
# states, ``rng[i]`` its noise stream; ``tables`` the ship's wind and drift tables (6, m),
# ``gains[i]`` its wave-motion gains (2, 37), ``ship`` its constants.

#: Columns of a ship's seaway parameters (set at a reset).
(S_WIND, S_WIND_FROM, S_WIND_COS, S_WIND_SIN, S_GUST_SIGMA, S_GUST_A, S_GUST_B, S_WAVE_COS,
 S_WAVE_SIN, S_OMEGA_P, S_LAMBDA, S_SIGMA_ZETA, S_DRIFT, S_HS, S_TP,
 S_WAVE_DIR) = range(16)  # fmt: skip
N_SEA = 16
#: Columns of a ship's seaway states: gust, the AR(2) process now and before, the wave motion
#: (north, east, heading, yaw rate), the wind speed of the moment, and the AR(2) coefficients
#: with the encounter frequency they were made for.
#: Then the encounter angle they and the wave-motion gains and drift were looked up at, the
#: gains and the drift load.
(W_GUST, W_Y, W_Y_PREV, W_NORTH, W_EAST, W_PSI, W_R, W_SPEED, W_WE, W_RHO, W_COS, W_SIN,
 W_S, W_BETA, W_GXI, W_GPSI, W_DX, W_DY, W_DN) = range(19)  # fmt: skip
N_WF = 19
#: Relative change of the encounter frequency that remakes a ship's AR(2) coefficients.
RETUNE = 0.005
#: Change of the encounter angle [rad] (0.25 deg) that looks its wave-motion gains and drift
#: up again (tables every 10 and 2 deg: a step costs a fifth less than looking up each time).
RETUNE_ANGLE = math.radians(0.25)

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)
_SQRT12 = math.sqrt(12.0)
_TWO_PI = 2.0 * math.pi


@row_kernel
def noise(rng, i):
    """The next unit-variance uniform number of ship ``i``'s SplitMix64 stream ``rng[i]``."""
    z = rng[i] + _GOLDEN
    rng[i] = z
    z = (z ^ (z >> _S30)) * _MIX1
    z = (z ^ (z >> _S27)) * _MIX2
    z = z ^ (z >> _S31)
    return _SQRT12 * (np.float64(z >> _S11) * (1.0 / 9007199254740992.0) - 0.5)


@row_kernel
def normal(rng, i):
    """A standard normal number from ship ``i``'s stream (Box-Muller; for the resets)."""
    u1 = noise(rng, i) / _SQRT12 + 0.5
    u2 = noise(rng, i) / _SQRT12 + 0.5
    return math.sqrt(-2.0 * math.log(1.0 - u1)) * math.cos(_TWO_PI * u2)


@row_kernel
def _cell(angle, cells):
    """Cell ``k`` and fraction ``f`` of ``angle`` (wrapped to ``[-pi, pi)``) on a grid of
    ``cells`` equal cells over ``[-pi, pi]``."""
    t = (angle + math.pi) * (cells / _TWO_PI)
    t -= cells * math.floor(t / cells)  # wrapped
    k = min(int(t), cells - 1)
    return k, t - k


@row_kernel
def _ar2(sea, wf, i, we, dt):
    """Remake ship ``i``'s AR(2) coefficients for the encounter frequency ``we``."""
    lam = sea[i, S_LAMBDA]
    rho = math.exp(-lam * we * dt)
    theta = min(we * math.sqrt(1.0 - lam * lam) * dt, 3.0)
    st, ct = sincos(theta)
    r2 = rho * rho
    wf[i, W_WE] = we
    wf[i, W_RHO] = rho
    wf[i, W_COS] = ct
    wf[i, W_SIN] = st
    wf[i, W_S] = math.sqrt((1.0 - r2) * ((1.0 + r2) ** 2 - 4.0 * r2 * ct * ct) / (1.0 + r2))


@row_kernel
def _look_up(sea, wf, tables, gains, i, beta):
    """Look ship ``i``'s wave-motion gains (times ``sigma_zeta``) and drift load up at the
    encounter angle ``beta``."""
    wf[i, W_BETA] = beta
    k, f = _cell(beta, gains.shape[2] - 1)
    sz = sea[i, S_SIGMA_ZETA]
    wf[i, W_GXI] = sz * (gains[i, 0, k] + f * (gains[i, 0, k + 1] - gains[i, 0, k]))
    wf[i, W_GPSI] = sz * (gains[i, 1, k] + f * (gains[i, 1, k + 1] - gains[i, 1, k]))
    k, f = _cell(beta, tables.shape[1] - 1)
    drift = sea[i, S_DRIFT]
    wf[i, W_DX] = drift * (tables[3, k] + f * (tables[3, k + 1] - tables[3, k]))
    wf[i, W_DY] = drift * (tables[4, k] + f * (tables[4, k + 1] - tables[4, k]))
    wf[i, W_DN] = drift * (tables[5, k] + f * (tables[5, k + 1] - tables[5, k]))


@row_kernel
def _encounter(sea, x, c, i, sn, cs):
    """Ship ``i``'s encounter peak frequency now (at least MIN_ENCOUNTER_FREQUENCY)."""
    cb = sea[i, S_WAVE_COS] * cs + sea[i, S_WAVE_SIN] * sn  # cos(beta_w - psi)
    ur = x[i, 3]
    if x.shape[1] > 7:  # a 3-DOF ship's surge is over ground: its speed through the water
        ur -= c[i, 0] * cs + c[i, 1] * sn
    wp = sea[i, S_OMEGA_P]
    return max(abs(wp - wp * wp * ur * cb / GRAVITY), MIN_ENCOUNTER_FREQUENCY)


@row_kernel
def _block_angles(rows, start, n, x, c, sea, wf, rng, ship, advance, work):
    """The first passes of :func:`seaway_block`: each ship's heading's sine and cosine, its
    gust, and the apparent wind's dynamic pressure and angle, into ``work``. Loops of
    straight-line code over the ships (SIMD code: the sine, cosine and arctangent are long
    chains of dependent operations that one ship at a time would wait for)."""
    for b in range(n):
        sn, cs = sincos(x[rows[start + b], 2])
        work[0, b] = sn
        work[1, b] = cs
    for b in range(n):  # the gusts (a stream per ship)
        i = rows[start + b]
        g = wf[i, W_GUST]
        if advance and sea[i, S_WIND] > 0.0:
            g = sea[i, S_GUST_A] * g + sea[i, S_GUST_B] * noise(rng, i)
        work[2, b] = g
    nomoto = ship[0] == NOMOTO_KIND
    for b in range(n):
        i = rows[start + b]
        sn = work[0, b]
        cs = work[1, b]
        mean = sea[i, S_WIND]
        speed = max(mean + work[2, b], 0.0) if mean > 0.0 else 0.0
        uc = c[i, 0] * cs + c[i, 1] * sn
        vc = -c[i, 0] * sn + c[i, 1] * cs
        # over ground: a Nomoto ship along its heading plus the current
        ug = x[i, 3] + uc if nomoto else x[i, 3]
        vg = vc if nomoto else x[i, 4]
        # the apparent wind (shipgym.models.wind.apparent_wind)
        cw = sea[i, S_WIND_COS]
        sw = sea[i, S_WIND_SIN]
        ax = -speed * (cw * cs + sw * sn) - ug
        ay = -speed * (-cw * sn + sw * cs) - vg
        work[3, b] = speed
        work[4, b] = 0.5 * _wind.RHO_AIR * (ax * ax + ay * ay) if mean > 0.0 else 0.0
        work[5, b] = atan2(-ay, -ax)


@row_kernel
def seaway_block(rows, start, n, x, c, xm, sea, wf, rng, tables, gains, ship, ir, dt, advance):
    """The seaway of ships ``rows[start:start + n]`` after a step (``advance``) or at a reset
    (module docstring).

    Advances their wave processes and gusts on a step; sets their measured states ``xm``
    (``x`` plus the wave-frequency motion: north, east, heading and, at ``ir``, yaw rate) and
    their loads of the coming step, ``c[:, 2:5]``, from the states now. ``sea``, ``wf`` and
    ``rng`` are the ships' parameters, states and noise streams, ``tables`` the ship's wind
    and drift coefficients (6 rows), ``gains`` the ships' wave-motion gains, ``ship`` its
    :meth:`SeawayShip.constants`. A ship's result does not depend on the others'.
    """
    work = np.empty((6, n))
    _block_angles(rows, start, n, x, c, sea, wf, rng, ship, advance, work)
    nomoto = ship[0] == NOMOTO_KIND
    cells = tables.shape[1] - 1
    for b in range(n):
        i = rows[start + b]
        sn = work[0, b]
        cs = work[1, b]
        beta = sea[i, S_WAVE_DIR] - x[i, 2]
        we = _encounter(sea, x, c, i, sn, cs)
        if abs(we - wf[i, W_WE]) > RETUNE * we:
            _ar2(sea, wf, i, we, dt)
        if abs(beta - wf[i, W_BETA]) > RETUNE_ANGLE:
            _look_up(sea, wf, tables, gains, i, beta)
        rho = wf[i, W_RHO]
        ct = wf[i, W_COS]
        y = wf[i, W_Y]
        yp = wf[i, W_Y_PREV]
        if advance:
            y, yp = 2.0 * rho * ct * y - rho * rho * yp + wf[i, W_S] * noise(rng, i), y
        quad = (rho * yp - y * ct) / wf[i, W_SIN]
        north = wf[i, W_GXI] * y * sea[i, S_WAVE_COS]
        east = wf[i, W_GXI] * y * sea[i, S_WAVE_SIN]
        psi_w = wf[i, W_GPSI] * quad
        r_w = wf[i, W_GPSI] * wf[i, W_WE] * y
        # the load of the coming step: wind (none in calm air) and mean wave drift
        q = work[4, b]
        k, f = _cell(work[5, b], cells)
        fx = wf[i, W_DX] + q * (tables[0, k] + f * (tables[0, k + 1] - tables[0, k]))
        fy = wf[i, W_DY] + q * (tables[1, k] + f * (tables[1, k + 1] - tables[1, k]))
        fn = wf[i, W_DN] + q * (tables[2, k] + f * (tables[2, k + 1] - tables[2, k]))
        if nomoto:
            u = max(x[i, 3], MIN_NOMOTO_SPEED)
            length = ship[3]
            qw = 0.5 * WATER_DENSITY * u * length * length
            fx, fy, fn = fn / (ship[1] * qw * u * length), fy / (-ship[2] * qw), 0.0
        wf[i, W_Y] = y
        wf[i, W_Y_PREV] = yp
        wf[i, W_GUST] = work[2, b]
        wf[i, W_SPEED] = work[3, b]
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


@kernel
def start_rows(rows, x, c, sea, wf, rng, dt):
    """Start the gusts and the AR(2) wave process of each ship of ``rows`` (at a reset) in
    their stationary distribution."""
    for i in rows:
        wf[i, W_BETA] = math.inf  # looked up at the first step
        wf[i, W_GUST] = sea[i, S_GUST_SIGMA] * normal(rng, i)
        sn, cs = sincos(x[i, 2])
        _ar2(sea, wf, i, _encounter(sea, x, c, i, sn, cs), dt)
        rho = wf[i, W_RHO]
        lag1 = 2.0 * rho * wf[i, W_COS] / (1.0 + rho * rho)  # the lag-one correlation
        y = normal(rng, i)
        wf[i, W_Y] = y
        wf[i, W_Y_PREV] = lag1 * y + math.sqrt(max(1.0 - lag1 * lag1, 0.0)) * normal(rng, i)

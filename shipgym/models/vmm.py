"""Seed 003's general 3-DOF vessel manoeuvring model (VMM) with polynomial hydrodynamics.

The general manoeuvring model of seed 003 (Fossen 2021; Alexandersson's "Vessel Manoeuvring
Models"), of which the Abkowitz, Norrbin and the seed's simplified models are special cases::

    (M_RB + M_A) nu' + C_RB(nu) nu + C_A(nu_r) nu_r = [X_D, Y_D, N_D](u, v, r, delta, thrust)

with ``nu = [u, v, r]`` at the origin (midship), the centre of gravity ``x_G`` forward of it::

    M_RB = [[m, 0, 0], [0, m, m x_G], [0, m x_G, I_z]]
    M_A  = -[[X_u', 0, 0], [0, Y_v', Y_r'], [0, N_v', N_r']]       (dotted derivatives)
    C_RB nu = [-m (v r + x_G r^2), m u r, m x_G u r]
    C_A nu  = [(Y_v' v + Y_r' r) r, -X_u' u r, -(Y_v' v + Y_r' r) u + X_u' u v]

(the seed's ``eq_system`` with ``C_A`` written out; ``include_c_a=False`` lumps it into the
hydrodynamic polynomials, as the seed's printed system does). Solved for the accelerations by
the inverse of the constant mass matrix (the seed's ``S`` is its determinant).

Hydrodynamics: the prime system
-------------------------------
``X_D``, ``Y_D``, ``N_D`` are sums of named terms, each a non-dimensional coefficient times a
monomial of the primed motions (Norrbin's prime system, as in the seed's code): with the
instantaneous speed through the water ``U = sqrt(u_r^2 + v_r^2)``::

    u' = u_r / U,  v' = v_r / U,  r' = r L / U,  T' = T / (rho/2 L^2 U^2)
    X_D = rho/2 L^2 U^2 sum_k X_k m_k(u', v', r', delta, T', ...),  N_D = rho/2 L^3 U^2 (...)

so the coefficients are the same for the model and the full-scale ship (Froude scaling keeps
every primed quantity; :meth:`VMMParams.scaled` scales the particulars only). A term's name is
its equation and its factors: ``Y_vvr`` is ``Y_vvr v'^2 r'``; the factors are ``u v r d T``
(``d`` the rudder angle, ``T`` the thrust), ``|v| |r| |d|`` (moduli, Norrbin's terms), the
apparent-wind factors ``wc ws w2`` (``(V_w / U)^2`` times ``cos(g)``, ``sin(g)``, ``sin(2 g)``
of the apparent wind angle ``g``, wind from ahead ``g = 0``, from starboard ``+pi/2``) and
``0`` for a constant. Below :data:`MIN_SPEED_FRACTION` of the approach speed the primes use
that floor (a polynomial model in the prime system is singular at ``U = 0``).

Named term sets (:data:`TERM_SETS`): ``linear``; ``abkowitz`` (Abkowitz's third-order Taylor
expansion with thrust, the seed's AVMM), ``martin`` and ``martin_simple`` (the seed's simplified
models; the latter is its MAVMM), as in the seed author's ``VesselManoeuvringModels``
(``vmm_linear``, ``vmm_abkowitz``, ``vmm_martin``, ``vmm_martin_simple``); ``norrbin3``
(Norrbin's second-order modulus terms); ``mmg_hull``, ``martin_simple`` with the hull
polynomial of the MMG standard method (Yasukawa and Yoshimura 2015 eq. 7-9: ``X_vv v'^2``,
``X_vvvv v'^4`` and the cubic sway and yaw terms ``vvv, vvr, vrr, rrr`` of ``Y`` and ``N``;
the MMG coefficients, scaled by ``d / L`` for the VMM's ``L^2`` reference area, are values of
these terms). The author's ``linear`` set has no thrust term and
linearised rigid-body equations; here it keeps ``X_T T'`` (without it no straight-running
equilibrium exists) and the full rigid-body terms.

Thrust is an input, as in the seed's model tests: the measured propeller thrust [N], or, for a
record with propeller revolutions only, the propeller loading ``rho D^4 n |n|`` [N]
(:func:`propeller_loading`; the mean ``K_T (1 - t)`` is then part of ``X_T``).

One derivative (:func:`vmm_row`) serves every term set: the terms are rows of a coefficient
table packed into the parameter vector (:func:`pack_vmm`), read by one loop; nothing is
generated per term set. Current: constant and irrotational, the hydrodynamics in the velocities
relative to the water as in :mod:`shipgym.models.mmg`. Steering gear as in the MMG model; with
``direct_rudder`` the rudder state is not integrated and the input is the rudder angle itself
(the measured rudder of a record, as the seed's identification uses it).

State ``[x, y, psi, u, v, r, delta]`` [m, m, rad, m/s, m/s, rad/s, rad]; input
``[delta_c, thrust, wind_speed, wind_angle]`` [rad, N, m/s, rad] (the apparent wind).

The compiled per-ship functions (:func:`vmm_row`, :func:`vmm_forces`, :func:`prime_factors`,
:func:`monomial`) take their arrays unchecked (they run inside other kernels); from Python use
:class:`shipgym.models.ShipModel` or :func:`term_monomials`, which check their arguments.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.models._checks import positive_number, real_array, require_finite, shape_error
from shipgym.models._jit import kernel, row_kernel
from shipgym.models.kinematics import relative_motion, steering_gear

__all__ = [
    "DEFAULT_FROUDE_NUMBER",
    "FACTORS",
    "IMO_RATE_LENGTH",
    "IMO_RUDDER_RATE",
    "MIN_SPEED_FRACTION",
    "PARTICULARS",
    "PARTICULAR_SPELLINGS",
    "TERM_SETS",
    "VMM_INPUTS",
    "VMM_STATES",
    "VMMParams",
    "check_packed",
    "clarke_added_masses",
    "find_particulars",
    "pack_vmm",
    "parse_particulars",
    "parse_term",
    "propeller_loading",
    "term_matrix",
    "term_monomials",
    "vmm_row",
]

VMM_STATES = ("x", "y", "psi", "u", "v", "r", "delta")
VMM_INPUTS = ("delta_c", "thrust", "wind_speed", "wind_angle")
IX, IY, IPSI, IU, IV, IR, IDELTA = range(7)

FACTORS = ("u", "v", "r", "d", "T", "|v|", "|r|", "|d|", "wc", "ws", "w2")
"""Factors of a term name, in the order of the packed exponents."""
N_FACTORS = len(FACTORS)
_TOKEN = re.compile(r"\|[vrd]\||w[cs2]|[uvrdT0]")

MIN_SPEED_FRACTION = 0.1
"""Floor of ``U`` in the primes, as a fraction of the approach speed."""

_X = ("X_u", "X_uu", "X_rr", "X_vr", "X_dd", "X_T")
TERM_SETS: dict[str, tuple[str, ...]] = {
    "linear": (
        "X_u", "X_v", "X_r", "X_d", "X_T",
        "Y_u", "Y_v", "Y_r", "Y_d",
        "N_u", "N_v", "N_r", "N_d",
    ),
    "abkowitz": (
        "X_u", "X_uu", "X_uuu", "X_vv", "X_rr", "X_vr", "X_dd", "X_udd", "X_vd", "X_uvd",
        "X_uvv", "X_urr", "X_uvr", "X_rd", "X_urd", "X_T",
        *(f"{e}_{t}" for e in "YN" for t in (
            "v", "r", "vvv", "vvr", "rrr", "vrr", "uuv", "uur", "uv", "ur", "d", "ddd", "ud",
            "uud", "vdd", "vvd", "rdd", "rrd", "vrd", "Td", "T", "0", "0u", "0uu",
        )),
    ),
    "martin": (
        "X_u", "X_uu", "X_rr", "X_vr", "X_dd", "X_vd", "X_T",
        *(f"{e}_{t}" for e in "YN" for t in ("v", "r", "u", "uv", "ur", "d", "vdd", "rdd")),
    ),
    "martin_simple": (
        *_X,
        *(f"{e}_{t}" for e in "YN" for t in ("v", "r", "u", "ur", "d", "Td", "T", "vvd")),
    ),
    "mmg_hull": (
        *_X, "X_vv", "X_vvvv",
        *(f"{e}_{t}" for e in "YN" for t in (
            "v", "r", "vvv", "vvr", "vrr", "rrr", "u", "ur", "d", "Td", "T", "vvd",
        )),
    ),
    "norrbin3": (
        "X_u", "X_uu", "X_vv", "X_vr", "X_rr", "X_dd", "X_T",
        *(f"{e}_{t}" for e in "YN" for t in ("u", "v", "r", "d", "v|v|", "|v|r", "v|r|", "r|r|")),
    ),
}  # fmt: skip
"""Named term sets (module docstring)."""


def parse_term(name: str) -> tuple[int, np.ndarray]:
    """Equation (0 X, 1 Y, 2 N) and factor exponents of a term name such as ``"Y_vvr"``.

    Raises
    ------
    ValueError
        For a name that is not ``X_``, ``Y_`` or ``N_`` followed by factors of :data:`FACTORS`
        (or ``0``).
    """
    if not isinstance(name, str) or len(name) < 3 or name[:2] not in ("X_", "Y_", "N_"):
        raise ValueError(
            f"term {name!r} must be X_, Y_ or N_ followed by factors {FACTORS} (e.g. 'Y_vvr')"
        )
    body = name[2:]
    tokens = _TOKEN.findall(body)
    if "".join(tokens) != body or ("0" in tokens and len(tokens) > 1 and tokens[0] != "0"):
        raise ValueError(f"term {name!r}: cannot read {body!r} as factors {FACTORS} (or 0)")
    e = np.zeros(N_FACTORS)
    for tok in tokens:
        if tok != "0":
            e[FACTORS.index(tok)] += 1
    return "XYN".index(name[0]), e


def term_matrix(names: Sequence[str]) -> np.ndarray:
    """``(n, 1 + N_FACTORS)`` table of equation index and exponents of the terms ``names``."""
    out = np.zeros((len(names), 1 + N_FACTORS))
    for k, name in enumerate(names):
        eq, e = parse_term(name)
        out[k, 0] = eq
        out[k, 1:] = e
    return out


def propeller_loading(rps: np.ndarray, diameter: float, rho: float) -> np.ndarray:
    """``rho D^4 n |n|`` [N]: the thrust input of a record with propeller revolutions only.

    Raises
    ------
    TypeError, ValueError
        For revolutions that are not finite real numbers, or a diameter or density that is not
        a finite number > 0.
    """
    n = real_array(rps, "rps")
    require_finite(n, "rps")
    diameter = positive_number(diameter, "diameter")
    rho = positive_number(rho, "rho")
    with np.errstate(over="ignore", invalid="ignore"):  # inf, never OverflowError
        # no revolutions give no thrust however large D^4 is (never inf * 0 = NaN)
        loading = np.where(n == 0.0, 0.0, rho * np.float64(diameter) ** 4 * (n * np.abs(n)))
    require_finite(loading, "propeller loading rho D^4 n |n| (too large)")
    return loading


def clarke_added_masses(
    length: float, breadth: float, draught: float, block_coefficient: float
) -> dict[str, float]:
    """Prime added masses of Clarke, Gedling and Hine (1982) (sway/yaw) and Xu' = -0.05 m'.

    Returns ``{"X_udot", "Y_vdot", "Y_rdot", "N_vdot", "N_rdot"}`` in the prime system
    (forces over ``rho/2 L^3``, moments over ``rho/2 L^4`` and ``rho/2 L^5``). The surge value
    is the usual 5 % of the mass of a full-form ship (Clarke gives no surge formula).
    """
    t_l, b_l, b_t, cb = draught / length, breadth / length, breadth / draught, block_coefficient
    k = -math.pi * t_l**2
    mass_prime = 2.0 * cb * b_l * t_l  # rho L B T Cb / (rho/2 L^3)
    return {
        "X_udot": -0.05 * mass_prime,
        "Y_vdot": k * (1.0 + 0.16 * cb * b_t - 5.1 * b_l**2),
        "Y_rdot": k * (0.67 * b_l - 0.0033 * b_t**2),
        "N_vdot": k * (1.1 * b_l - 0.041 * b_t),
        "N_rdot": k * (1.0 / 12.0 + 0.017 * cb * b_t - 0.33 * b_l),
    }


PARTICULARS: dict[str, str] = {
    "length": "length L [m]",
    "breadth": "breadth B [m]",
    "draught": "draught T [m]",
    "displacement": "displacement volume [m^3] (or mass)",
    "mass": "mass [kg] (or displacement)",
    "x_g": "centre of gravity forward of midship [m]",
    "propeller_diameter": "propeller diameter [m] (optional)",
    "rho": "water density [kg/m^3] (optional, 1025)",
    "yaw_radius": "yaw radius of gyration [m] (optional, 0.25 L)",
    "block_coefficient": "block coefficient (optional, displacement / (L B T))",
    "approach_speed": "approach speed [m/s] (optional)",
}
"""The main particulars of :meth:`VMMParams.from_particulars` (the keys of
:func:`parse_particulars`) and what each is, in SI units."""

_REQUIRED_PARTICULARS = ("length", "breadth", "draught", "x_g")

PARTICULAR_SPELLINGS: dict[str, tuple[str, ...]] = {
    "length": ("length", "L", "Lpp", "LPP", "L_pp", "length_m"),
    "breadth": ("breadth", "B", "beam", "breadth_m"),
    "draught": ("draught", "draft", "draught_m", "draft_m"),
    "displacement": ("displacement", "displacement_m3", "volume", "nabla"),
    "mass": ("mass", "mass_kg"),
    "x_g": ("x_g", "x_G", "xG", "x_g_m"),
    "propeller_diameter": ("propeller_diameter", "D_p", "Dp", "propeller_diameter_m"),
    "rho": ("rho", "water_density"),
    "yaw_radius": ("yaw_radius", "yaw_radius_m"),
    "block_coefficient": ("block_coefficient", "C_b", "Cb", "CB"),
    "approach_speed": ("approach_speed", "U0", "U_0", "approach_speed_m_s"),
}
"""Meta keys of a record (``# L: 7.0`` lines of its file) that state each particular
(:func:`find_particulars`)."""

DEFAULT_FROUDE_NUMBER = 0.15
"""Approach Froude number ``U / sqrt(g L)`` of :meth:`VMMParams.from_particulars` when no
approach speed is given (KVLCC2 model trials: 0.142)."""

IMO_RUDDER_RATE = math.radians(65.0 / 28.0)
"""IMO minimum rudder rate [rad/s] (35 deg to 30 deg the other side in 28 s, SOLAS II-1/29) of
a :data:`IMO_RATE_LENGTH` ship: the default steering gear of
:meth:`VMMParams.from_particulars`, Froude-scaled to the ship's length."""

IMO_RATE_LENGTH = 320.0
"""Length [m] at which :data:`IMO_RUDDER_RATE` is taken (a large tanker; a 7 m model of it
then steers at 15.7 deg/s, as the KVLCC2 model does)."""

_GRAVITY = 9.81


def parse_particulars(text: str) -> dict[str, float]:
    """The particulars of ``"length=7.0,breadth=1.27,draught=0.46,displacement=3.27,..."``.

    Parameters
    ----------
    text : str
        Comma-separated ``key=value`` pairs, keys of :data:`PARTICULARS` (SI units: m, m^3,
        kg, kg/m^3, m/s); ``length, breadth, draught, x_g`` and ``displacement`` or ``mass``
        are required.

    Returns
    -------
    dict
        Key -> value, for :meth:`VMMParams.from_particulars` (``**``).

    Raises
    ------
    ValueError
        For an entry that is not ``key=number``, an unknown or repeated key (naming the known
        ones) or a missing particular (naming ``--particulars`` and the missing keys).
    """
    if not isinstance(text, str):
        raise ValueError(f"particulars must be a text of key=value pairs, got {text!r}")
    out: dict[str, float] = {}
    for part in text.split(","):
        if not part.strip():
            continue
        key, sep, value = part.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ValueError(
                f"--particulars entry {part.strip()!r} is not key=value (e.g. 'length=7.0')"
            )
        if key not in PARTICULARS:
            raise ValueError(
                f"--particulars: unknown key {key!r}; known keys: {', '.join(PARTICULARS)}"
            )
        if key in out:
            raise ValueError(f"--particulars: key {key!r} given twice")
        try:
            out[key] = float(value)
        except ValueError:
            raise ValueError(
                f"--particulars: {key}={value.strip()!r} is not a number (SI units: "
                f"{PARTICULARS[key]})"
            ) from None
    _require_particulars(out, "--particulars")
    return out


def _require_particulars(found: Mapping[str, Any], where: str) -> None:
    """``ValueError`` naming ``where`` and the particulars missing from ``found``."""
    missing = [k for k in _REQUIRED_PARTICULARS if k not in found]
    if "displacement" not in found and "mass" not in found:
        missing.append("displacement (or mass)")
    if missing:
        raise ValueError(
            f"{where} misses the particular(s) {', '.join(missing)}; expected e.g. "
            '--particulars "length=7.0,breadth=1.27,draught=0.46,displacement=3.27,x_g=0.25,'
            'propeller_diameter=0.216" (SI units: m, m^3)'
        )


def find_particulars(meta: Mapping[str, Any]) -> dict[str, float]:
    """The particulars a record's meta states (any spelling of :data:`PARTICULAR_SPELLINGS`).

    Returns
    -------
    dict
        Key of :data:`PARTICULARS` -> value, for the particulars found (possibly none).

    Raises
    ------
    ValueError
        For a value that is not a finite number, or two spellings of one particular with
        different values.
    """
    out: dict[str, float] = {}
    source: dict[str, str] = {}
    for key, spellings in PARTICULAR_SPELLINGS.items():
        for name in spellings:
            value = meta.get(name)
            if value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(
                    f"meta {name!r} = {value!r} is not a number; expected the {PARTICULARS[key]}"
                )
            if key in out and out[key] != float(value):
                raise ValueError(
                    f"meta {source[key]!r} = {out[key]:g} and {name!r} = {value:g} state the "
                    f"{PARTICULARS[key]} twice with different values"
                )
            out[key], source[key] = float(value), name
    return out


def _particular(value: Any, key: str, lo: float = 0.0, hi: float = math.inf) -> float:
    """``value`` as a float in ``(lo, hi]``, else a ``ValueError`` naming ``key``."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"particular {key} must be a finite number, got {value!r}")
    if not lo < value <= hi:
        bound = f"in ({lo:g}, {hi:g}]" if math.isfinite(hi) else f"> {lo:g}"
        raise ValueError(f"particular {key} must be {bound} ({PARTICULARS[key]}), got {value!r}")
    return float(value)


@dataclass(frozen=True, eq=False)
class VMMParams:
    """A vessel manoeuvring model: particulars, added masses and hydrodynamic coefficients.

    Attributes
    ----------
    coefficients : mapping
        Term name -> prime coefficient (module docstring); the model's term set.
    length, breadth, draught : float
        ``L``, ``B``, ``T`` [m].
    mass : float
        ``m`` [kg].
    x_g : float
        Centre of gravity forward of the origin (midship) [m].
    yaw_inertia : float
        ``I_z`` about the centre of gravity [kg m^2] (the origin's is ``I_z + m x_G^2``).
    added : mapping
        Prime added masses ``X_udot, Y_vdot, Y_rdot, N_vdot, N_rdot`` (the seed's prime
        system: over ``rho/2 L^3``, ``rho/2 L^4`` and ``rho/2 L^5``; negative).
    approach_speed : float
        Trial speed ``U_0`` [m/s] (manoeuvres; the floor of ``U`` in the primes).
    propeller_diameter : float
        ``D`` [m] (the loading ``rho D^4 n |n|`` of records without thrust).
    rho : float
        Water density [kg/m^3].
    max_rudder, rudder_rate, rudder_time_constant : float
        Steering gear [rad, rad/s, s].
    include_c_a : bool
        Write the added-mass Coriolis terms ``C_A`` out (True) or leave them to the
        polynomials.
    direct_rudder : bool
        The input ``delta_c`` is the rudder angle (no steering gear).
    rudder_offset : float
        Zero error of the rudder order [rad]: the gear (or, with ``direct_rudder``, the hull)
        sees ``delta_c + rudder_offset`` (the ``rudder_offset`` cause of
        :data:`shipgym.sysid.families.base.CAUSES`).
    thrust_from : {"thrust", "rps"}
        What the thrust input of the fitted records was (the measured thrust, or the loading
        ``rho D^4 n |n|``).
    name : str
        Name of the model.
    """

    coefficients: Mapping[str, float]
    length: float
    breadth: float
    draught: float
    mass: float
    x_g: float
    yaw_inertia: float
    added: Mapping[str, float]
    approach_speed: float
    propeller_diameter: float = 0.0
    rho: float = 1025.0
    max_rudder: float = math.radians(35.0)
    rudder_rate: float = math.radians(15.8)
    rudder_time_constant: float = 0.05
    include_c_a: bool = True
    direct_rudder: bool = False
    rudder_offset: float = 0.0
    thrust_from: str = "thrust"
    name: str = "vmm"
    terms: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        coeffs = {str(k): float(v) for k, v in dict(self.coefficients).items()}
        object.__setattr__(self, "coefficients", coeffs)
        object.__setattr__(self, "terms", term_matrix(list(coeffs)))
        for k, v in coeffs.items():
            if not math.isfinite(v):
                raise ValueError(f"VMMParams coefficient {k} must be finite, got {v!r}")
        for k in ("length", "breadth", "draught", "mass", "yaw_inertia", "approach_speed",
                  "rho", "max_rudder", "rudder_rate", "rudder_time_constant"):  # fmt: skip
            v = getattr(self, k)
            if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
                raise ValueError(f"VMMParams.{k} must be a finite number > 0, got {v!r}")
        added = {k: float(dict(self.added).get(k, 0.0)) for k in _ADDED}
        object.__setattr__(self, "added", added)
        if not (isinstance(self.rudder_offset, int | float) and abs(self.rudder_offset) < 0.5):
            raise ValueError(
                f"VMMParams.rudder_offset must be a finite angle in (-0.5, 0.5) rad, got "
                f"{self.rudder_offset!r}"
            )
        if self.thrust_from not in ("thrust", "rps"):
            raise ValueError(f"thrust_from must be 'thrust' or 'rps', got {self.thrust_from!r}")

    @property
    def term_names(self) -> tuple[str, ...]:
        """The model's terms, in order."""
        return tuple(self.coefficients)

    def with_coefficients(self, coefficients: Mapping[str, float], **changes: Any) -> VMMParams:
        """A copy with other coefficients (and any other field changed)."""
        return replace(self, coefficients=dict(coefficients), **changes)

    def scaled(self, factor: float) -> VMMParams:
        """The geometrically similar ship ``factor`` times longer (Froude scaling; the prime
        coefficients are kept)."""
        if not (isinstance(factor, int | float) and math.isfinite(factor) and factor > 0):
            raise ValueError(f"scale factor must be a finite number > 0, got {factor!r}")
        s = math.sqrt(factor)
        return replace(
            self,
            length=self.length * factor,
            breadth=self.breadth * factor,
            draught=self.draught * factor,
            mass=self.mass * factor**3,
            x_g=self.x_g * factor,
            yaw_inertia=self.yaw_inertia * factor**5,
            approach_speed=self.approach_speed * s,
            propeller_diameter=self.propeller_diameter * factor,
            rudder_rate=self.rudder_rate / s,
            rudder_time_constant=self.rudder_time_constant * s,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description (:meth:`from_dict` reads it back)."""
        keys = (*_REQUIRED_KEYS, *_OPTIONAL_KEYS)
        out: dict[str, Any] = {k: getattr(self, k) for k in keys}
        out["coefficients"] = dict(self.coefficients)
        out["added"] = dict(self.added)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> VMMParams:
        """The model described by :meth:`to_dict` (``ValueError`` naming a missing key)."""
        try:
            return cls(**{k: data[k] for k in _REQUIRED_KEYS}, **{
                k: data[k] for k in _OPTIONAL_KEYS if k in data
            })  # fmt: skip
        except KeyError as exc:
            raise ValueError(
                f"a VMM description needs the keys {_REQUIRED_KEYS}; missing {exc}"
            ) from None

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> VMMParams:
        """The model in a JSON file: :meth:`to_dict`, or the ``"vmm"`` entry of a
        ``shipgym identify --model vmm:... --json`` report."""
        p = Path(path)
        try:
            data = json.loads(p.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise ValueError(f"cannot read a VMM from {str(p)!r}: {exc}") from None
        if isinstance(data, dict) and isinstance(data.get("vmm"), dict):
            data = data["vmm"]
        if not isinstance(data, dict):
            raise ValueError(f"{str(p)!r} holds no VMM description (a JSON object)")
        return cls.from_dict(
            {k: v for k, v in data.items() if k not in ("current", "input_delay_s")}
        )

    @classmethod
    def from_particulars(
        cls,
        *,
        length: float,
        breadth: float,
        draught: float,
        x_g: float,
        displacement: float | None = None,
        mass: float | None = None,
        propeller_diameter: float | None = None,
        rho: float = 1025.0,
        yaw_radius: float | None = None,
        block_coefficient: float | None = None,
        approach_speed: float | None = None,
        name: str = "ship",
    ) -> VMMParams:
        """The ship (no coefficients) from its main particulars, as a naval architect states
        them.

        ``mass = rho * displacement`` (or the displacement ``mass / rho``), the yaw inertia
        about the centre of gravity ``I_z = mass * yaw_radius^2``, the added masses of Clarke,
        Gedling and Hine (1982) (:func:`clarke_added_masses`) at the block coefficient
        ``C_b = displacement / (L B T)`` unless given. Steering gear: the IMO minimum rate
        (:data:`IMO_RUDDER_RATE`) Froude-scaled to ``length``, 35 deg maximum.

        Parameters
        ----------
        length, breadth, draught : float
            ``L``, ``B``, ``T`` [m], > 0 (``B`` and ``T`` less than ``L``).
        x_g : float
            Centre of gravity forward of midship [m], within the hull (``|x_g| < L / 2``).
        displacement, mass : float
            Displacement volume [m^3] or mass [kg]: exactly one of them, > 0.
        propeller_diameter : float, optional
            ``D`` [m], > 0; needed for records with propeller revolutions but no thrust.
        rho : float
            Water density [kg/m^3], in [950, 1100].
        yaw_radius : float, optional
            Yaw radius of gyration [m] in ``(0, L / 2]``; 0.25 L by default.
        block_coefficient : float, optional
            ``C_b`` in (0, 1]; ``displacement / (L B T)`` by default (which must be in (0, 1]).
        approach_speed : float, optional
            Trial speed [m/s] > 0 (the floor of the speed in the prime system and the start of
            simulations); by default :data:`DEFAULT_FROUDE_NUMBER` ``* sqrt(g L)``: give the
            measured one (``shipgym identify --particulars`` takes the runs' median speed).
        name : str
            The ship's name.

        Raises
        ------
        ValueError
            Naming the particular that is missing, not a finite number, or out of its range.
        """
        length = _particular(length, "length")
        breadth = _particular(breadth, "breadth", hi=length)
        draught = _particular(draught, "draught", hi=length)
        rho = _particular(rho, "rho", 950.0, 1100.0)
        if (displacement is None) == (mass is None):
            raise ValueError(
                "particulars need displacement (volume [m^3]) or mass [kg], exactly one of "
                f"them; got displacement={displacement!r}, mass={mass!r}"
            )
        if mass is None:
            volume = _particular(displacement, "displacement")
            mass = rho * volume
        else:
            mass = _particular(mass, "mass")
            volume = mass / rho
        box = length * breadth * draught
        if block_coefficient is None:
            block_coefficient = volume / box
            if not 0.0 < block_coefficient <= 1.0:
                raise ValueError(
                    f"particular displacement {volume:g} m^3 gives a block coefficient "
                    f"displacement / (L B T) = {block_coefficient:.3g} for L B T = {box:g} m^3; "
                    "expected it in (0, 1]: is the displacement a volume in m^3 (not tonnes or "
                    "kg)?"
                )
        else:
            block_coefficient = _particular(block_coefficient, "block_coefficient", hi=1.0)
        half = 0.5 * length
        if isinstance(x_g, bool) or not isinstance(x_g, int | float) or not abs(x_g) < half:
            raise ValueError(
                f"particular x_g must be a finite number within the hull, |x_g| < L/2 = "
                f"{half:g} m ({PARTICULARS['x_g']}), got {x_g!r}"
            )
        yaw_radius = _particular(
            0.25 * length if yaw_radius is None else yaw_radius, "yaw_radius", hi=half
        )
        diameter = (
            0.0
            if propeller_diameter is None
            else _particular(propeller_diameter, "propeller_diameter", hi=breadth)
        )
        speed = (
            DEFAULT_FROUDE_NUMBER * math.sqrt(_GRAVITY * length)
            if approach_speed is None
            else _particular(approach_speed, "approach_speed")
        )
        return cls(
            coefficients={},
            length=length,
            breadth=breadth,
            draught=draught,
            mass=mass,
            x_g=float(x_g),
            yaw_inertia=mass * yaw_radius**2,
            added=clarke_added_masses(length, breadth, draught, block_coefficient),
            approach_speed=speed,
            propeller_diameter=diameter,
            rho=rho,
            rudder_rate=IMO_RUDDER_RATE * math.sqrt(IMO_RATE_LENGTH / length),
            name=str(name),
        )

    def approach_thrust(self) -> float:
        """Thrust input [N] that holds straight running at the approach speed (from
        :func:`vmm_row`)."""
        from scipy.optimize import brentq

        p = pack_vmm(replace(self, direct_rudder=True))
        x = np.zeros(7)
        x[IU] = self.approach_speed
        out = np.empty(7)
        c = np.zeros(2)

        def surge(thrust: float) -> float:
            vmm_row(x, np.array([0.0, thrust, 0.0, 0.0]), p, c, out)
            return float(out[IU])

        q = 0.5 * self.rho * self.length**2 * self.approach_speed**2
        lo, hi = -10.0 * q, 10.0 * q
        if surge(lo) * surge(hi) > 0:
            raise ValueError("no thrust holds the approach speed with these coefficients")
        return float(brentq(surge, lo, hi, xtol=1e-9 * q))

    def straight_course(self) -> tuple[float, float, float]:
        """The rudder, sway and thrust that hold a straight course at the approach speed.

        The steady state with no yaw rate (:func:`vmm_row`: ``du = dv = dr = 0`` at ``r = 0``,
        ``u`` the approach speed), solved for the rudder order, the sway velocity and the
        thrust input from ``(0, 0,`` :meth:`approach_thrust` ``)``. A mirror-symmetric ship
        holds its course with the rudder amidships and no drift; a straight-running side force
        and yaw moment (the terms of ``Y_0, N_0``, ``Y_T, N_T`` ...) need a rudder, which a
        rudder zero error of minus that angle would need too.

        Returns
        -------
        delta, v, thrust : float
            Rudder order [rad], sway velocity [m/s] and thrust input.

        Raises
        ------
        ValueError
            When no steady straight course is found with the rudder within its limit.
        """
        from scipy.optimize import root

        p = pack_vmm(replace(self, direct_rudder=True))
        q = 0.5 * self.rho * self.length**2 * self.approach_speed**2
        x = np.zeros(7)
        x[IU] = self.approach_speed
        out = np.empty(7)
        c = np.zeros(2)

        def steady(z: np.ndarray) -> np.ndarray:
            x[IV] = z[1] * self.approach_speed
            vmm_row(x, np.array([z[0], z[2] * q, 0.0, 0.0]), p, c, out)
            return np.array([out[IU], out[IV], out[IR] * self.length]) / self.approach_speed

        sol = root(steady, np.array([0.0, 0.0, self.approach_thrust() / q]), method="hybr")
        delta, v_prime, thrust = (float(z) for z in sol.x)
        where = f"no straight course at {self.approach_speed:g} m/s"
        if not sol.success:
            raise ValueError(f"{where}: the steady state was not found ({sol.message})")
        if abs(delta) > self.max_rudder:
            raise ValueError(
                f"{where} with the rudder within its limit: it would take "
                f"{math.degrees(delta):.3g} deg, the limit is {math.degrees(self.max_rudder):g} deg"
            )
        return delta, v_prime * self.approach_speed, thrust * q


_ADDED = ("X_udot", "Y_vdot", "Y_rdot", "N_vdot", "N_rdot")
_REQUIRED_KEYS = ("coefficients", "length", "breadth", "draught", "mass", "x_g",
                  "yaw_inertia", "added", "approach_speed")  # fmt: skip
_OPTIONAL_KEYS = (
    "propeller_diameter", "rho", "max_rudder", "rudder_rate",
    "rudder_time_constant", "include_c_a", "direct_rudder", "rudder_offset", "thrust_from",
    "name",
)  # fmt: skip

# packed layout
P_MU = 0  # m - X_udot
P_INV = 1  # inverse of the 2x2 sway-yaw mass matrix (4 entries)
P_M, P_MXG = 5, 6  # m, m x_G
P_XUD, P_YVD, P_YRD = 7, 8, 9  # dimensional X_udot, Y_vdot, Y_rdot (C_A; 0 if not included)
P_QX, P_QN, P_L = 10, 11, 12  # rho/2 L^2, rho/2 L^3, L
P_UMIN = 13
P_GEAR = 14  # max rudder, rate, 1 / T_delta, direct (1.0) or not
P_NTERMS = 18
P_OFFSET = 19  # rudder zero error
P_TERMS = 20  # then per term: coefficient, equation, exponents (N_FACTORS)
TERM_WIDTH = 2 + N_FACTORS


def pack_vmm(params: VMMParams) -> np.ndarray:
    """Parameter vector that :func:`vmm_row` reads (the coefficient table at the end)."""
    q = params
    half_rho = 0.5 * q.rho
    a = q.added
    xud = a["X_udot"] * half_rho * q.length**3
    yvd = a["Y_vdot"] * half_rho * q.length**3
    yrd = a["Y_rdot"] * half_rho * q.length**4
    nvd = a["N_vdot"] * half_rho * q.length**4
    nrd = a["N_rdot"] * half_rho * q.length**5
    m, mxg = q.mass, q.mass * q.x_g
    iz0 = q.yaw_inertia + m * q.x_g**2
    n_terms = len(q.coefficients)
    p = np.zeros(P_TERMS + TERM_WIDTH * n_terms)
    p[P_MU] = m - xud
    mat = np.array([[m - yvd, mxg - yrd], [mxg - nvd, iz0 - nrd]])
    p[P_INV : P_INV + 4] = np.linalg.inv(mat).ravel()
    p[P_M], p[P_MXG] = m, mxg
    if q.include_c_a:
        p[P_XUD], p[P_YVD], p[P_YRD] = xud, yvd, yrd
    p[P_QX], p[P_QN], p[P_L] = half_rho * q.length**2, half_rho * q.length**3, q.length
    p[P_UMIN] = MIN_SPEED_FRACTION * q.approach_speed
    p[P_GEAR : P_GEAR + 4] = (
        q.max_rudder, q.rudder_rate, 1.0 / q.rudder_time_constant, float(q.direct_rudder),
    )  # fmt: skip
    p[P_NTERMS] = n_terms
    p[P_OFFSET] = q.rudder_offset
    block = p[P_TERMS:].reshape(n_terms, TERM_WIDTH)
    block[:, 0] = list(q.coefficients.values())
    block[:, 1:] = q.terms
    return p


@row_kernel
def prime_factors(u_r, v_r, r, delta, thrust, wind_speed, wind_angle, p):
    """The factors of the terms (:data:`FACTORS`, prime system) and ``U^2`` [m^2/s^2]."""
    big_u = max(math.sqrt(u_r * u_r + v_r * v_r), p[P_UMIN])
    vp = v_r / big_u
    rp = r * p[P_L] / big_u
    u2 = big_u * big_u
    w2 = wind_speed * wind_speed / u2
    f = (
        u_r / big_u, vp, rp, delta, thrust / (p[P_QX] * u2), abs(vp), abs(rp), abs(delta),
        w2 * math.cos(wind_angle), w2 * math.sin(wind_angle), w2 * math.sin(2.0 * wind_angle),
    )  # fmt: skip
    return f, u2


@row_kernel
def monomial(p, k, f):
    """The monomial of term ``k`` of ``p`` at the factors ``f`` (without its coefficient)."""
    b = P_TERMS + TERM_WIDTH * k
    val = 1.0
    for j in range(N_FACTORS):
        for _ in range(int(p[b + 2 + j])):
            val *= f[j]
    return val


@row_kernel
def vmm_forces(u_r, v_r, r, delta, thrust, wind_speed, wind_angle, p):
    """``(X_D, Y_D, N_D)`` [N, N, N m] of the terms packed in ``p``."""
    f, u2 = prime_factors(u_r, v_r, r, delta, thrust, wind_speed, wind_angle, p)
    sx = 0.0
    sy = 0.0
    sn = 0.0
    for k in range(int(p[P_NTERMS])):
        b = P_TERMS + TERM_WIDTH * k
        val = p[b] * monomial(p, k, f)
        eq = p[b + 1]
        if eq == 0.0:
            sx += val
        elif eq == 1.0:
            sy += val
        else:
            sn += val
    return p[P_QX] * u2 * sx, p[P_QX] * u2 * sy, p[P_QN] * u2 * sn


def check_packed(p: np.ndarray) -> None:
    """``ValueError`` unless ``p`` has the layout :func:`pack_vmm` writes: the header, then
    ``p[P_NTERMS]`` rows of coefficient, equation (0, 1, 2) and small whole exponents."""
    n = p[P_NTERMS] if p.ndim == 1 and p.size > P_NTERMS else -1.0
    ok = math.isfinite(n) and n >= 0 and n == int(n) and p.size == P_TERMS + TERM_WIDTH * int(n)
    if ok:
        table = p[P_TERMS:].reshape(int(n), TERM_WIDTH)
        exps = table[:, 2:]
        ok = bool(
            np.isin(table[:, 1], (0.0, 1.0, 2.0)).all()
            and ((exps >= 0) & (exps <= 16) & (exps == np.round(exps))).all()
        )
    if not ok:
        raise ValueError(
            f"p of model 'vmm' must be the output of pack_vmm ({P_TERMS} header entries, then "
            f"{TERM_WIDTH} per term); got {p.size} entries that do not have that layout"
        )


def term_monomials(
    x: np.ndarray, inputs: np.ndarray, p: np.ndarray, c: np.ndarray, out: np.ndarray,
    u2: np.ndarray,
) -> None:  # fmt: skip
    """Regressors of the identification: the monomial of every packed term at every row of
    states ``x`` ``(n, >= 6)`` and inputs ``(n, 4)`` into ``out`` ``(n, n_terms)``, and
    ``U^2`` into ``u2`` ``(n,)`` (the same prime system as :func:`vmm_forces`); ``c`` is the
    north/east current ``(2,)`` [m/s] and ``p`` the output of :func:`pack_vmm`.

    Raises
    ------
    TypeError, ValueError
        Naming the argument whose type, shape or values do not fit.
    """
    x = np.ascontiguousarray(real_array(x, "x"))
    if x.ndim != 2 or x.shape[1] < 6:
        raise shape_error("x", "(n, >= 6)", x.shape, " (states x, y, psi, u, v, r, ...)")
    n = x.shape[0]
    inputs = np.ascontiguousarray(real_array(inputs, "inputs"))
    if inputs.shape != (n, 4):
        raise shape_error("inputs", f"({n}, 4)", inputs.shape, f" {VMM_INPUTS} per row of x")
    c = np.ascontiguousarray(real_array(c, "current"))
    if c.shape != (2,):
        raise shape_error("current", "(2,)", c.shape, " (north/east [m/s])")
    p = np.ascontiguousarray(real_array(p, "p"))
    check_packed(p)
    require_finite(p, "p of model 'vmm'")
    for arr, name in ((x, "x"), (inputs, "inputs"), (c, "current")):
        require_finite(arr, name)
    for arr, name, shape in ((out, "out", (n, int(p[P_NTERMS]))), (u2, "u2", (n,))):
        if not (
            type(arr) is np.ndarray and arr.dtype == np.float64 and arr.flags.writeable
            and arr.flags.c_contiguous and arr.shape == shape
        ):  # fmt: skip
            got = arr.shape if isinstance(arr, np.ndarray) else type(arr).__name__
            raise shape_error(name, str(shape), got, " (writable float64, C order)")
    term_monomials_kernel(x, inputs, p, c, out, u2)
    if not (np.isfinite(out).all() and np.isfinite(u2).all()):
        i = int(np.argwhere(~(np.isfinite(out).all(axis=1) & np.isfinite(u2)))[0, 0])
        raise ValueError(
            f"the regressors are not finite at row {i}: the state, input or current is beyond "
            "what the model can evaluate"
        )


@kernel
def term_monomials_kernel(x, inputs, p, c, out, u2):  # pragma: no cover - jit
    """:func:`term_monomials` without its checks."""
    scratch = np.empty(3)
    for i in range(x.shape[0]):
        ur, vr, _, _ = relative_motion(x[i], c, scratch)
        u = inputs[i]
        f, u2[i] = prime_factors(ur, vr, x[i, IR], u[0], u[1], u[2], u[3], p)
        for k in range(out.shape[1]):
            out[i, k] = monomial(p, k, f)


@row_kernel
def vmm_row(x, u, p, c, out):
    """State derivative of the VMM (module docstring; seed 003 ``eq_system``)."""
    ur, vr, uc, vc = relative_motion(x, c, out)
    r = x[IR]
    g = P_GEAR
    order = u[0] + p[P_OFFSET]
    if p[g + 3] != 0.0:
        delta = order
        out[IDELTA] = 0.0
    else:
        delta = x[IDELTA]
        out[IDELTA] = steering_gear(delta, order, p[g], p[g + 1], p[g + 2])
    fx, fy, fn = vmm_forces(ur, vr, r, delta, u[1], u[2], u[3], p)
    m = p[P_M]
    mxg = p[P_MXG]
    xud = p[P_XUD]
    lin = p[P_YVD] * vr + p[P_YRD] * r  # Y_vdot v + Y_rdot r (C_A)
    bx = fx + m * vr * r + mxg * r * r - lin * r
    by = fy - m * ur * r + xud * ur * r
    bn = fn - mxg * ur * r + lin * ur - xud * ur * vr
    out[IU] = bx / p[P_MU] + r * vc
    out[IV] = p[P_INV] * by + p[P_INV + 1] * bn - r * uc
    out[IR] = p[P_INV + 2] * by + p[P_INV + 3] * bn

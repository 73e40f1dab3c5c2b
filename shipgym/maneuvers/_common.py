"""The test rig shared by every trial: set a model up, drive it, record its time histories.

A model of :mod:`shipgym.models` is put on the rig described in :mod:`shipgym.maneuvers`
(approach state, equivalent rudder, shaft speed or thrust, step and hold settings) by
:class:`Rig`, simulated in chunks with a controller callback on one global clock by
:class:`Run` (:meth:`ShipModel.simulate <shipgym.models.ShipModel.simulate>`, no physics
copied), held until steady by :func:`hold_until_steady`, and recorded as a
:class:`TimeSeries`. A model-test ship of any length (``kvlcc2``, ``vmm``) gets the rig of the
7 m KVLCC2 Froude-scaled (times by ``sqrt(L / 7 m)``, yaw rates by its inverse).

A trial in wind (``wind``, the env's ``wind`` option of :mod:`shipgym.models.seaway_options`
with one speed and direction) runs the same physics as the envs: the Nomoto family (the
Mariner) and the R/V Gunnerus through the seaway's load
(:func:`shipgym.models.seaway.seaway_block` on a
:class:`~shipgym.models.seaway_options.SeawayArrays` of the trial's ship, the load of each step
from the state at its start,
:meth:`ShipModel.simulate <shipgym.models.ShipModel.simulate>`'s ``load``),
``kvlcc2`` through its MMG model's wind (``MMGParams.wind_speed``, ``wind_direction``) and a
``vmm`` with identified wind terms through its apparent-wind inputs
(:func:`shipgym.models.wind.apparent_wind` of the state at the start of each step). The wind
sets in at the first execute on the approach state of calm water (the KVLCC2's propeller at
the self-propulsion point of its MMG model in the wind on the approach heading).

A private module: the trial modules of :mod:`shipgym.maneuvers` import it; users import
:class:`TimeSeries` and :data:`SIDES` from the package.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from shipgym.maneuvers.particulars import PARTICULARS, ShipParticulars
from shipgym.models import MODEL_NAMES, NOMOTO_MODEL_NAMES, ShipModel, SimulationResult, make_model
from shipgym.models import seaway as sw
from shipgym.models.integrate import NC
from shipgym.models.model_file import is_model_file, model_info
from shipgym.models.seaway_options import N_DRAWS, SeawayArrays, Wind, wind_option
from shipgym.models.vmm import FACTORS
from shipgym.models.wind import apparent_wind

# published as shipgym.maneuvers.SIDES
SIDES = ("starboard", "port")
#: A model name, the path of a model file, or a built model.
ModelLike = str | os.PathLike[str] | ShipModel
#: A callback given one-line progress messages (or None).
Progress = Callable[[str], None] | None
_KVLCC2 = PARTICULARS["kvlcc2"]


def json_num(value: float | None, digits: int = 6) -> float | None:
    """JSON-friendly float (``None`` for NaN or infinity)."""
    if value is None or not math.isfinite(value):
        return None
    return round(float(value), digits)


def json_deg(value: float) -> float | None:
    """JSON-friendly degrees of an angle [rad] (``None`` for NaN or infinity)."""
    return json_num(math.degrees(value)) if math.isfinite(value) else None


#: Seed of the noise stream of a trial's gusts (one realisation, the same in every run).
GUST_SEED = 0
#: The apparent-wind factors of a VMM's terms (:data:`shipgym.models.vmm.FACTORS`).
_WIND_FACTORS = [FACTORS.index(f) for f in ("wc", "ws", "w2")]


def trial_wind(wind: Mapping[str, Any] | None) -> Wind | None:
    """The checked wind of a trial, or None (calm air).

    ``wind`` is the env's ``wind`` option (:func:`shipgym.models.seaway_options.wind_option`):
    ``speed`` [m/s] and ``direction`` (where the wind comes FROM [rad], clockwise from north),
    both one number here (a trial draws nothing), and ``gusts`` (default False in a trial: a
    constant true wind is what the trial correction assumes).
    """
    if wind is None:
        return None
    if not isinstance(wind, Mapping) or "direction" not in wind:
        raise ValueError(
            "a trial's wind must be a dict with 'speed' [m/s], 'direction' [rad, where it comes "
            f"from] and optionally 'gusts' [bool], got {wind!r}"
        )
    checked = wind_option({"gusts": False, **wind})
    assert checked is not None
    if isinstance(checked.speed, tuple) or isinstance(checked.direction, tuple):
        raise ValueError(
            f"a trial's wind is one speed and one direction, not a range, got {wind!r}"
        )
    return checked


def wind_json(wind: Wind | None) -> dict[str, Any] | None:
    """A trial's wind for JSON (``None`` in calm air)."""
    if wind is None:
        return None
    return {
        "speed_m_s": json_num(float(wind.speed)),  # type: ignore[arg-type]
        "from_deg": json_num(math.degrees(float(wind.direction)) % 360.0),  # type: ignore[arg-type]
        "gusts": wind.gusts,
    }


def wind_text(wind: Wind | None) -> str:
    """A trial's wind in words, e.g. ``"true wind 15 m/s from 090 deg"`` (empty in calm air)."""
    if wind is None:
        return ""
    w = wind_json(wind)
    assert w is not None
    gusts = ", gusts" if wind.gusts else ""
    return f"true wind {w['speed_m_s']:g} m/s from {w['from_deg']:05.1f} deg{gusts}"


@dataclass(frozen=True)
class _RigSettings:
    dt: float  # default integration step [s]
    chunk: float  # window [s] of the steady-state test and of the stop checks
    max_hold: float  # longest hold [s] of one steady condition
    max_duration: float  # longest zigzag / pull-out [s]
    kp: float  # yaw-rate PI of the reverse spiral [rad of rudder per rad/s]
    ti: float  # its integral time [s]
    spiral_rudders_deg: tuple[float, ...]  # one leg of the direct spiral
    spiral_yaw_rate: float  # largest |r| [rad/s] of the reverse spiral


def _down_leg(*angles: float) -> tuple[float, ...]:
    """Direct-spiral leg from starboard to port: ``angles``, 0, then the mirrored angles."""
    return (*angles, 0.0, *(-a for a in reversed(angles)))


_NOMOTO_RIG = _RigSettings(
    dt=0.1,
    chunk=50.0,
    max_hold=4000.0,
    max_duration=4000.0,
    kp=20.0,
    ti=40.0,
    spiral_rudders_deg=_down_leg(20.0, 15.0, 10.0, 5.0, 3.0, 2.0, 1.0),
    spiral_yaw_rate=0.025,
)
_RIGS: dict[str, _RigSettings] = {
    # the linear models turn 3.7 times faster at large rudder: a wider reverse spiral
    "nomoto1": replace(_NOMOTO_RIG, spiral_yaw_rate=0.06),
    "nomoto2": replace(_NOMOTO_RIG, spiral_yaw_rate=0.06),
    "norrbin": _NOMOTO_RIG,
    "bech": _NOMOTO_RIG,
    "rvg3dof": _RigSettings(
        dt=0.1,
        chunk=10.0,
        max_hold=600.0,
        max_duration=600.0,
        kp=30.0,
        ti=10.0,
        # the RVG's instability loop spans about +-26 deg of equivalent rudder
        spiral_rudders_deg=_down_leg(30.0, 25.0, 20.0, 15.0, 10.0, 5.0, 2.0),
        spiral_yaw_rate=0.08,
    ),
    # the 7 m model: one ship length in 5.9 s, rudder at 15.7 deg/s
    "kvlcc2": _RigSettings(
        dt=0.05,
        chunk=10.0,
        max_hold=600.0,
        max_duration=600.0,
        kp=30.0,
        ti=10.0,
        spiral_rudders_deg=_down_leg(20.0, 15.0, 10.0, 5.0, 3.0, 2.0, 1.0),
        spiral_yaw_rate=0.05,
    ),
}


def _identified_particulars(ship: ShipModel, info: dict[str, Any]) -> ShipParticulars | None:
    """The particulars of an identified Nomoto-family ship (None for the 3-DOF families, whose
    parameters carry their own): its length from the model file (NaN when the record did not
    state it: the ratios to L are then not computed), a beam of L / 6 for the plots, and the
    service speed of its surge model."""
    if ship.surge is None:
        return None
    length = info.get("length_m")
    L = float(length) if length else math.nan
    source = info.get("source") or "a record"
    return ShipParticulars(
        f"ship identified from {source} ({info.get('model', ship.name)})",
        L,
        L / 6.0,
        ship.surge.service_speed,
    )


@dataclass(frozen=True, eq=False)
class TimeSeries:
    """Time histories of a trial (SI units, radians).

    Attributes
    ----------
    time : numpy.ndarray
        Time [s] from the first rudder execute.
    x, y : numpy.ndarray
        North and east position [m] (start at the origin).
    psi : numpy.ndarray
        Heading [rad], not wrapped (the heading change is ``psi - psi[0]``).
    r : numpy.ndarray
        Yaw rate [rad/s].
    delta : numpy.ndarray
        Equivalent rudder angle [rad] (RVG: minus the mean pod azimuth).
    delta_c : numpy.ndarray
        Equivalent rudder command [rad] held over each step (the last value repeated).
    speed : numpy.ndarray
        Speed through the water [m/s].
    simulation : SimulationResult
        The full model trajectory (all states and inputs).
    """

    time: np.ndarray
    x: np.ndarray
    y: np.ndarray
    psi: np.ndarray
    r: np.ndarray
    delta: np.ndarray
    delta_c: np.ndarray
    speed: np.ndarray
    simulation: SimulationResult = field(repr=False)

    def crop(self, end: int) -> TimeSeries:
        """The first ``end`` samples."""
        sim = self.simulation
        sim = SimulationResult(
            sim.time[:end],
            sim.states[:end],
            sim.inputs[: max(end - 1, 0)],
            sim.state_names,
            sim.input_names,
        )
        return TimeSeries(
            self.time[:end],
            self.x[:end],
            self.y[:end],
            self.psi[:end],
            self.r[:end],
            self.delta[:end],
            self.delta_c[:end],
            self.speed[:end],
            sim,
        )

    def to_dict(self, max_points: int | None = 2000) -> dict[str, list[float | None]]:
        """Columns for JSON (degrees in ``*_deg`` keys), thinned to at most ``max_points``."""
        n = len(self.time)
        stride = 1 if not max_points or n <= max_points else math.ceil(n / max_points)
        idx = np.unique(np.append(np.arange(0, n, stride), n - 1))

        def col(a: np.ndarray, scale: float = 1.0) -> list[float | None]:
            return [json_num(float(v) * scale) for v in a[idx]]

        d = 180.0 / math.pi
        return {
            "time_s": col(self.time),
            "x_m": col(self.x),
            "y_m": col(self.y),
            "psi_deg": col(self.psi, d),
            "r_deg_s": col(self.r, d),
            "delta_deg": col(self.delta, d),
            "delta_c_deg": col(self.delta_c, d),
            "speed_m_s": col(self.speed),
        }


class Rig:
    """One model set up for the trials: approach state, rudder mapping, speed, settings."""

    def __init__(
        self, model: ModelLike, dt: float | None, wind: Mapping[str, Any] | None = None
    ) -> None:
        identified: ShipParticulars | None = None
        from_file = False
        if isinstance(model, ShipModel):
            ship = model
        elif is_model_file(model):
            ship = make_model(model)
            from_file = True
            identified = _identified_particulars(ship, model_info(model))
        elif isinstance(model, str):
            ship = make_model(model)  # raises ValueError for an unknown name
        else:
            raise ValueError(
                f"model must be a model name {MODEL_NAMES}, a model file FIT.json or a "
                f"ShipModel, got {model!r}"
            )
        #: the model as given (calm air); ``ship`` is the one sailed
        self.model = ship
        self.name = ship.name
        self.wind = trial_wind(wind)
        #: the seaway's ship of a wind load (the Nomoto family, the Gunnerus), else None
        self.seaway_ship: sw.SeawayShip | None = None
        self.ship = ship if self.wind is None else self._in_wind(ship, self.wind, from_file)
        if identified is not None:
            self.particulars = identified
        elif ship.name == "kvlcc2":
            p = ship.params
            vessel = f"KVLCC2 ({p.length:g} m)" if p.length != _KVLCC2.length else _KVLCC2.vessel
            self.particulars = ShipParticulars(vessel, p.length, p.breadth, p.approach_speed)
        elif ship.name == "vmm":
            p = ship.params
            self.particulars = ShipParticulars(p.name, p.length, p.breadth, p.approach_speed)
        elif ship.name == "rvg3dof":
            # the Gunnerus has two shipped parameter sets: every output names the one sailed
            gunnerus = PARTICULARS["rvg3dof"]
            vessel = f"{gunnerus.vessel}, parameter set {ship.params.name}"
            self.particulars = replace(gunnerus, vessel=vessel)
        else:
            self.particulars = PARTICULARS[ship.name]
        if ship.name in ("kvlcc2", "vmm"):
            # a model-test ship of any length: the 7 m KVLCC2's rig, Froude-scaled
            k = math.sqrt(self.particulars.length / _KVLCC2.length)
            st = _RIGS["kvlcc2"]
            self.settings = replace(
                st, dt=st.dt * k, chunk=st.chunk * k, max_hold=st.max_hold * k,
                max_duration=st.max_duration * k, ti=st.ti * k,
                kp=st.kp * k, spiral_yaw_rate=st.spiral_yaw_rate / k,
            )  # fmt: skip
        else:
            self.settings = _RIGS[ship.name]
        step = self.settings.dt if dt is None else dt
        if not (isinstance(step, int | float) and math.isfinite(step) and 0 < step <= 1.0):
            raise ValueError(f"dt must be a step in (0, 1] s, got {dt!r}")
        self.dt = float(step)
        self.ipsi = ship.index("psi")
        self.ir = ship.index("r")
        self.x0 = np.zeros(ship.nx)
        if ship.name == "rvg3dof":
            p = ship.params
            self.thrust = float(p.service_thrust)
            self.max_rudder = math.radians(35.0)
            self.x0[ship.index("T1")] = self.x0[ship.index("T2")] = self.thrust
            self.x0[ship.index("u")] = self._rvg_straight_speed()
            self._iu, self._iv = ship.index("u"), ship.index("v")
            self._ia = (ship.index("alpha1"), ship.index("alpha2"))
        elif ship.name in ("kvlcc2", "vmm"):
            p = self.ship.params
            self.max_rudder = float(p.max_rudder)
            # the propeller at the self-propulsion point (kvlcc2: rps, with its MMG wind on the
            # approach heading; vmm: the thrust input)
            self.shaft = (
                p.self_propulsion_rps(self.particulars.speed)
                if ship.name == "kvlcc2"
                else p.approach_thrust()
            )
            self.x0[ship.index("u")] = self.particulars.speed
            self._iu, self._iv = ship.index("u"), ship.index("v")
            self._idelta = ship.index("delta")
        else:
            assert ship.surge is not None and ship.gear is not None
            self.shaft = float(ship.surge.service_shaft_speed)
            self.max_rudder = float(ship.gear.max_angle)
            self.x0[ship.index("U")] = ship.surge.service_speed
            self._iU, self._idelta = ship.index("U"), ship.index("delta")

    def _in_wind(self, ship: ShipModel, wind: Wind, from_file: bool) -> ShipModel:
        """The ship to sail in ``wind``: how each model takes it (module docstring)."""
        name = ship.name
        if name in NOMOTO_MODEL_NAMES or name == "rvg3dof":
            if from_file and name != "rvg3dof":
                raise ValueError(
                    "wind: the wind areas are known for the Mariner of the Nomoto family and "
                    f"the R/V Gunnerus, not for a {name!r} ship identified from a record"
                )
            self.seaway_ship = sw.gunnerus_seaway() if name == "rvg3dof" else sw.mariner_seaway()
            return ship
        if wind.gusts:
            raise ValueError(
                "wind: gusts are modelled for the Nomoto family and rvg3dof (the seaway), not "
                f"for {name!r}"
            )
        if name == "kvlcc2":
            if ship.params.wind_speed > 0.0:
                raise ValueError(
                    f"wind: this kvlcc2 already sails in a wind of {ship.params.wind_speed:g} "
                    "m/s (MMGParams.wind_speed); give the wind once"
                )
            params = replace(ship.params, wind_speed=wind.speed, wind_direction=wind.direction)
            return ShipModel(name, params, input_delay=ship.input_delay)
        if not ship.params.terms[:, [1 + k for k in _WIND_FACTORS]].any():
            raise ValueError(
                f"wind: the vmm {ship.params.name!r} has no identified wind terms (factors wc, "
                "ws, w2, e.g. X_wc, Y_ws, N_ws: the 'wind' effect of an identification with a "
                "measured wind)"
            )
        return ship

    def wind_load(self) -> Callable[[float, np.ndarray], np.ndarray] | None:
        """A new run's wind load for :meth:`ShipModel.simulate
        <shipgym.models.ShipModel.simulate>` (None: the model takes no load)."""
        return None if self.seaway_ship is None else _WindLoad(self)

    def _rvg_straight_speed(self) -> float:
        """Surge speed [m/s] at which the service thrust balances the resistance."""
        from scipy.optimize import brentq

        x = self.x0.copy()
        u_cmd = self.command(0.0)
        iu = self.ship.index("u")

        def surge_acc(u: float) -> float:
            x[iu] = u
            return float(self.ship.deriv(x, u_cmd)[0, iu])

        return float(brentq(surge_acc, 0.1, 8.0, xtol=1e-12))

    def command(self, delta: float, x: np.ndarray | None = None) -> np.ndarray:
        """Model input for an equivalent rudder command ``delta`` [rad] (+ = starboard) at the
        state ``x`` (a vmm in wind: the apparent wind of ``x``; calm air without ``x``)."""
        if self.name == "rvg3dof":
            return np.array([self.thrust, self.thrust, -delta, -delta])
        if self.name == "vmm":
            if self.wind is None or x is None:
                return np.array([delta, self.shaft, 0.0, 0.0])
            speed, angle = apparent_wind(
                float(self.wind.speed), float(self.wind.direction),  # type: ignore[arg-type]
                x[self.ipsi], x[self._iu], x[self._iv],
            )  # fmt: skip
            return np.array([delta, self.shaft, speed, angle])
        return np.array([delta, self.shaft])

    def series(self, sim: SimulationResult) -> TimeSeries:
        """The trial's time histories of a simulation on this rig."""
        s = sim.states
        cmd = self.rudder_command(sim.inputs) if len(sim.inputs) else np.zeros(1)
        return TimeSeries(
            time=sim.time,
            x=s[:, self.ship.index("x")],
            y=s[:, self.ship.index("y")],
            psi=s[:, self.ipsi],
            r=s[:, self.ir],
            delta=self.rudder(s),
            delta_c=np.append(cmd, cmd[-1]),
            speed=self.speed(s),
            simulation=sim,
        )

    def rudder(self, states: np.ndarray) -> np.ndarray:
        """Equivalent rudder angle [rad] (for the RVG minus the mean pod azimuth)."""
        if self.name == "rvg3dof":
            return -0.5 * (states[:, self._ia[0]] + states[:, self._ia[1]])
        return states[:, self._idelta]

    def rudder_command(self, inputs: np.ndarray) -> np.ndarray:
        """Equivalent rudder command [rad] of each input row."""
        if self.name == "rvg3dof":
            return -0.5 * (inputs[:, 2] + inputs[:, 3])
        return inputs[:, 0]

    def speed(self, states: np.ndarray) -> np.ndarray:
        """Speed through the water [m/s] (``sqrt(u^2 + v^2)`` for the 3-DOF models)."""
        if self.name in ("rvg3dof", "kvlcc2", "vmm"):
            return np.hypot(states[:, self._iu], states[:, self._iv])
        return states[:, self._iU]

    @property
    def approach_speed(self) -> float:
        """Speed through the water [m/s] of the approach state."""
        return float(self.speed(self.x0[None])[0])

    def check_rudder(self, value_deg: float, what: str, allow_zero: bool = False) -> float:
        """Validate a rudder angle in degrees; returns radians."""
        limit = math.degrees(self.max_rudder)
        ok = isinstance(value_deg, int | float) and math.isfinite(value_deg)
        if ok:
            ok = (0 <= value_deg if allow_zero else 0 < value_deg) and value_deg <= limit + 1e-9
        if not ok:
            low = "[0" if allow_zero else "(0"
            raise ValueError(
                f"{what} must be in {low}, {limit:g}] deg for {self.name}, got {value_deg!r}"
            )
        return math.radians(value_deg)


def side_sign(side: str) -> float:
    """+1 for ``"starboard"``, -1 for ``"port"``; ValueError for any other side."""
    if side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}, got {side!r}")
    return 1.0 if side == "starboard" else -1.0


class _WindLoad:
    """The wind load of one run of a ship of the seaway (module docstring): the env's seaway
    arrays of one ship with the trial's wind, stepped by the seaway's one function; called by
    :meth:`ShipModel.simulate <shipgym.models.ShipModel.simulate>` at the start of each step."""

    def __init__(self, rig: Rig) -> None:
        assert rig.seaway_ship is not None
        self.arrays = SeawayArrays(1, rig.seaway_ship, rig.dt, rig.ir)
        self.rows = np.zeros(1, dtype=np.int64)
        self.x = rig.x0[None].copy()
        self.xm = self.x.copy()
        self.c = np.zeros((1, NC))
        draws = np.random.default_rng(GUST_SEED).random((1, N_DRAWS))  # seeds the gusts
        a = self.arrays
        a.set_rows(self.rows, rig.wind, None, draws)
        sw.start_rows(self.rows, self.x, self.c, a.sea, a.wf, a.rng, rig.dt)
        self.started = False  # the first call sets the first step's load (no gust step)

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        """The load of the step from ``x`` (rows 2-4 of the disturbances)."""
        self.x[0] = x
        a = self.arrays
        sw.seaway_block(self.rows, 0, 1, self.x, self.c, self.xm, a.sea, a.wf, a.rng, a.tables,
                        a.gains, a.constants, a.ir, a.dt, self.started)  # fmt: skip
        self.started = True
        return self.c[0, 2:]


class Run:
    """Closed-loop simulation in chunks with a global clock (the model's ``simulate``)."""

    def __init__(self, rig: Rig, controller: Callable[[float, np.ndarray], float]) -> None:
        self.rig = rig
        self.controller = controller
        self.load = rig.wind_load()
        self.t = 0.0
        self.x = rig.x0.copy()
        self._t: list[np.ndarray] = [np.zeros(1)]
        self._x: list[np.ndarray] = [rig.x0[None].copy()]
        self._u: list[np.ndarray] = []

    def advance(self, duration: float) -> np.ndarray:
        """Simulate ``duration`` seconds more; returns the new states ``(n, nx)``."""
        rig = self.rig
        n = max(1, round(duration / rig.dt))
        k0 = round(self.t / rig.dt)

        def policy(t: float, x: np.ndarray) -> np.ndarray:
            return rig.command(self.controller((k0 + round(t / rig.dt)) * rig.dt, x), x)

        res = rig.ship.simulate(self.x, policy, rig.dt, n, load=self.load)
        times = (k0 + np.arange(1, n + 1)) * rig.dt
        self._t.append(times)
        self._x.append(res.states[1:])
        self._u.append(res.inputs)
        self.t = float(times[-1])
        self.x = res.states[-1].copy()
        return res.states[1:]

    def result(self) -> SimulationResult:
        """The whole run so far: every sample from the approach state on."""
        ship = self.rig.ship
        return SimulationResult(
            np.concatenate(self._t),
            np.concatenate(self._x),
            np.concatenate(self._u) if self._u else np.zeros((0, ship.nu)),
            ship.state_names,
            ship.input_names,
        )


def hold_until_steady(
    run: Run,
    rig: Rig,
    min_time: float = 0.0,
    extra: Callable[[], bool] | None = None,
    rtol: float = 2e-4,
    atol_r: float = 2e-6,
    atol_speed: float = 1e-3,
    atol_rudder: float = 1e-4,
) -> tuple[bool, np.ndarray]:
    """Advance in windows of ``chunk`` until the window means of r, speed and rudder settle.

    Returns ``(steady, [mean r, mean speed, mean rudder])`` of the last window.
    """
    start = run.t
    prev: np.ndarray | None = None
    tol = np.array([atol_r, atol_speed, atol_rudder])
    while True:
        states = run.advance(rig.settings.chunk)
        cur = np.array(
            [
                np.mean(states[:, rig.ir]),
                np.mean(rig.speed(states)),
                np.mean(rig.rudder(states)),
            ]
        )
        elapsed = run.t - start
        if (
            prev is not None
            and elapsed >= min_time
            and np.all(np.abs(cur - prev) <= tol + rtol * np.abs(cur))
            and (extra is None or extra())
        ):
            return True, cur
        if elapsed >= rig.settings.max_hold:
            return False, cur
        prev = cur


def crossing(h: np.ndarray, target: float) -> tuple[int, float] | None:
    """First sample ``i`` with ``h[i] >= target`` and the fraction ``w`` back to ``i - 1``."""
    idx = np.nonzero(h >= target)[0]
    if len(idx) == 0:
        return None
    i = int(idx[0])
    if i == 0:
        return 0, 1.0
    w = (target - h[i - 1]) / (h[i] - h[i - 1])
    return i, float(w)


def value_at(values: np.ndarray, cross: tuple[int, float]) -> float:
    """``values`` interpolated linearly at a :func:`crossing` ``(i, w)``."""
    i, w = cross
    if i == 0:
        return float(values[0])
    return float(values[i - 1] + w * (values[i] - values[i - 1]))

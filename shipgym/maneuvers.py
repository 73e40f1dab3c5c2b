"""Standard manoeuvring trials: zigzag, turning circle, pull-out, spiral and the IMO criteria.

Every trial runs on every model of :mod:`shipgym.models` (``nomoto1``, ``nomoto2``, ``norrbin``,
``bech``, ``rvg3dof``, ``kvlcc2``) through
:meth:`ShipModel.simulate <shipgym.models.ShipModel.simulate>` with a controller callback; no
physics is copied here. The ship starts on a straight course
(heading north, ``psi0 = 0``) at its service speed in calm water, and the trial's "rudder" is:

* **Nomoto family**: the rudder command ``delta_c`` through the steering gear (35 deg,
  2.32 deg/s, 2 s), shaft speed held at its service value. Positive rudder turns to starboard.
* **R/V Gunnerus** (``rvg3dof``): the common azimuth of both pods, each at its service thrust
  (25 kN), through the pod servos (1 s, 10 deg/s). A positive azimuth on the aft pods turns
  the ship to port (seed 001 eq. 19-20), so the trials use the *equivalent rudder*
  ``delta_equivalent = -azimuth``: a positive "rudder" is a starboard turn for every model.
* **KVLCC2** (``kvlcc2``, the MMG standard model of the 7 m model): the rudder command through
  its steering gear (35 deg, 15.7 deg/s: the full-scale 2.32 deg/s Froude-scaled), the
  propeller at the model's self-propulsion point at the SIMMAN 2008 approach speed, 1.179 m/s.

Trials (definitions of ITTC and IMO MSC/Circ.1053, Explanatory Notes to MSC.137(76)):

* **Zigzag a/b** (Kempf's Z-manoeuvre; seed 000 "zigzag autopilot"): rudder to ``a`` (first
  execute); when the heading change ``psi - psi0`` reaches ``b`` the rudder is reversed to
  ``-a`` (second execute), when it reaches ``-b`` back to ``a``, and so on. The overshoot
  after each reversal is the heading excursion beyond the check heading ``+-b`` before the
  swing stops (``r`` changes sign). Initial turning time: first to second execute. Time to
  check yaw: second execute to the first heading peak. Period: mean time between every
  other reversal (one full heading cycle). The reversal is applied at the integration step
  nearest to the crossing (predicted with the current yaw rate), so the switching error is
  at most ``|r| dt / 2``.
* **Turning circle** (seed 002 Fig. 1 and Table 1: approach, first, second and third phase):
  rudder to ``delta`` from straight running and held. Advance: distance along the approach
  course from the position at the rudder execute to the position where the heading has
  changed 90 deg; transfer: distance across it at 90 deg; tactical diameter: transfer at
  180 deg; steady turning diameter: least-squares circle through the track over one full
  turn after the yaw rate and speed have settled (third phase); speed ratio: steady speed /
  approach speed (seed 002 Table 3 gives the speed against the heading change, reported here
  every 10 deg up to 180 deg).
* **Pull-out**: steady turn, then rudder amidships. A directionally stable ship's yaw rate
  decays to zero; an unstable one keeps a residual yaw rate (the height of its spiral loop).
* **Spiral** (seed 002 introduction; seed 004 section 1.1 and Fig. 1, the delta-r plot):
  *direct* (Dieudonné): the rudder is held at each angle of a sequence from starboard to
  port and back and the steady yaw rate recorded; an unstable ship shows a hysteresis loop.
  *Reverse* (Bech): a yaw-rate controller (PI on ``r``) holds ``r`` at each setpoint and the
  mean rudder needed is recorded; this traces the whole S-shaped curve, including the
  unstable branch inside the loop. For the Norrbin model the steady curve is
  ``n3 r^3 + n2 r|r| + n1 r + n0 = K delta`` (seed 002 eq. 1-3, seed 004 eq. 4).
* **IMO criteria** (resolution MSC.137(76) section 5.3, explanatory notes MSC/Circ.1053):

  ============================  ===========================================================
  5.3.1 turning ability         advance <= 4.5 L, tactical diameter <= 5 L (35 deg rudder)
  5.3.2 initial turning         10 deg rudder: distance travelled <= 2.5 L by the time the
                                heading has changed 10 deg
  5.3.3 yaw-checking and        10/10 zigzag 1st overshoot <= 10 deg if L/U < 10 s, 20 deg
  course-keeping                if L/U >= 30 s, 5 + 0.5 L/U deg in between; 2nd overshoot
                                <= 25 / 40 / 17.5 + 0.75 L/U deg; 20/20 1st overshoot
                                <= 25 deg
  ============================  ===========================================================

  ("should not exceed": a value equal to the limit passes.) Every criterion is evaluated to
  both sides and the worse side counts; the table labels the 10/10 second overshoot
  "course-keeping" and the first overshoots "yaw-checking". The stopping ability (5.3.4,
  track reach <= 15 L) needs astern power, which these models do not have. The
  Standards apply to ships of 100 m and more; for R/V Gunnerus (33.9 m) the table is
  informative only.

Ship length and approach speed are in :data:`PARTICULARS` (Mariner L = 160.93 m,
U = 7.7 m/s; R/V Gunnerus L = 33.9 m, U = 5.144 m/s). Inside everything is SI and radians;
degrees appear only in ``to_dict()`` keys named ``*_deg``, in the IMO table and in plots.
Plots are written with :class:`matplotlib.figure.Figure` and the Agg canvas (no pyplot state).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from shipgym.models import MODEL_NAMES, ShipModel, SimulationResult, make_model
from shipgym.models.model_file import is_model_file, model_info

__all__ = [
    "PARTICULARS",
    "SIDES",
    "IMOReport",
    "IMORow",
    "InitialTurningResult",
    "PullOutResult",
    "ShipParticulars",
    "SpiralResult",
    "TimeSeries",
    "TurningResult",
    "ZigZagResult",
    "format_imo_table",
    "imo_criteria",
    "imo_rows",
    "initial_turning",
    "overshoot_limits",
    "plot_imo",
    "plot_pullout",
    "plot_spiral",
    "plot_turning_circle",
    "plot_zigzag",
    "print_imo_table",
    "pullout",
    "spiral",
    "turning_circle",
    "turning_quantities",
    "zigzag",
    "zigzag_quantities",
]

SIDES = ("starboard", "port")
ModelLike = str | os.PathLike[str] | ShipModel
Progress = Callable[[str], None] | None

_BLUE, _ORANGE, _GREEN, _RED, _GREY, _PURPLE = (
    "#1f5fa8",
    "#d9731a",
    "#2a8a4a",
    "#b8312f",
    "#6b6b6b",
    "#7b4fa0",
)
_MODEL_LABELS = {
    "nomoto1": "first-order Nomoto",
    "nomoto2": "second-order Nomoto",
    "norrbin": "Norrbin",
    "bech": "Bech",
    "rvg3dof": "3-DOF MCSim",
    "kvlcc2": "MMG KVLCC2",
    "vmm": "VMM",
}


# ------------------------------------------------------------------------------------------
# ship particulars and the per-model test rig
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ShipParticulars:
    """Main particulars used to scale the trials and the IMO criteria.

    Attributes
    ----------
    vessel : str
        Name of the ship.
    length : float
        Length between perpendiculars ``L`` [m].
    beam : float
        Breadth [m] (plots only).
    speed : float
        Trial (service) speed ``U`` [m/s] of the IMO ratio ``L / U``.
    """

    vessel: str
    length: float
    beam: float
    speed: float

    @property
    def length_over_speed(self) -> float:
        """``L / U`` [s], the time to travel one ship length."""
        return self.length / self.speed


_MARINER = ShipParticulars("Mariner class cargo ship", 160.93, 23.17, 7.7)
_GUNNERUS = ShipParticulars("R/V Gunnerus", 33.9, 9.6, 5.144)
_KVLCC2 = ShipParticulars("KVLCC2 (7 m model)", 7.0, 1.27, 1.179)
#: Model name -> ship particulars (Mariner: Fossen 1994 section 2.2; Gunnerus: seed 001;
#: KVLCC2: the L7 model at the SIMMAN 2008 speed, Yasukawa and Yoshimura 2015).
PARTICULARS: dict[str, ShipParticulars] = {
    "nomoto1": _MARINER,
    "nomoto2": _MARINER,
    "norrbin": _MARINER,
    "bech": _MARINER,
    "rvg3dof": _GUNNERUS,
    "kvlcc2": _KVLCC2,
}


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


class _Rig:
    """One model set up for the trials: approach state, rudder mapping, speed, settings."""

    def __init__(self, model: ModelLike, dt: float | None) -> None:
        identified: ShipParticulars | None = None
        if isinstance(model, ShipModel):
            ship = model
        elif is_model_file(model):
            ship = make_model(model)
            identified = _identified_particulars(ship, model_info(model))
        elif isinstance(model, str):
            ship = make_model(model)  # raises ValueError for an unknown name
        else:
            raise ValueError(
                f"model must be a model name {MODEL_NAMES}, a model file FIT.json or a "
                f"ShipModel, got {model!r}"
            )
        self.ship = ship
        self.name = ship.name
        if identified is not None:
            self.particulars = identified
        elif ship.name == "kvlcc2":
            p = ship.params
            vessel = f"KVLCC2 ({p.length:g} m)" if p.length != _KVLCC2.length else _KVLCC2.vessel
            self.particulars = ShipParticulars(vessel, p.length, p.breadth, p.approach_speed)
        elif ship.name == "vmm":
            p = ship.params
            self.particulars = ShipParticulars(p.name, p.length, p.breadth, p.approach_speed)
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
            p = ship.params
            self.max_rudder = float(p.max_rudder)
            # the propeller at the self-propulsion point (kvlcc2: rps; vmm: the thrust input)
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

    def command(self, delta: float) -> np.ndarray:
        """Model input for an equivalent rudder command ``delta`` [rad] (+ = starboard)."""
        if self.name == "rvg3dof":
            return np.array([self.thrust, self.thrust, -delta, -delta])
        if self.name == "vmm":
            return np.array([delta, self.shaft, 0.0, 0.0])
        return np.array([delta, self.shaft])

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


def _side_sign(side: str) -> float:
    if side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}, got {side!r}")
    return 1.0 if side == "starboard" else -1.0


class _Run:
    """Closed-loop simulation in chunks with a global clock (the model's ``simulate``)."""

    def __init__(self, rig: _Rig, controller: Callable[[float, np.ndarray], float]) -> None:
        self.rig = rig
        self.controller = controller
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
            return rig.command(self.controller((k0 + round(t / rig.dt)) * rig.dt, x))

        res = rig.ship.simulate(self.x, policy, rig.dt, n)
        times = (k0 + np.arange(1, n + 1)) * rig.dt
        self._t.append(times)
        self._x.append(res.states[1:])
        self._u.append(res.inputs)
        self.t = float(times[-1])
        self.x = res.states[-1].copy()
        return res.states[1:]

    def result(self) -> SimulationResult:
        ship = self.rig.ship
        return SimulationResult(
            np.concatenate(self._t),
            np.concatenate(self._x),
            np.concatenate(self._u) if self._u else np.zeros((0, ship.nu)),
            ship.state_names,
            ship.input_names,
        )


def _hold_until_steady(
    run: _Run,
    rig: _Rig,
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


# ------------------------------------------------------------------------------------------
# results
# ------------------------------------------------------------------------------------------
def _num(value: float | None, digits: int = 6) -> float | None:
    """JSON-friendly float (``None`` for NaN or infinity)."""
    if value is None or not math.isfinite(value):
        return None
    return round(float(value), digits)


def _deg(value: float) -> float | None:
    return _num(math.degrees(value)) if math.isfinite(value) else None


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

    @classmethod
    def _from(cls, rig: _Rig, sim: SimulationResult) -> TimeSeries:
        s = sim.states
        cmd = rig.rudder_command(sim.inputs) if len(sim.inputs) else np.zeros(1)
        return cls(
            time=sim.time,
            x=s[:, rig.ship.index("x")],
            y=s[:, rig.ship.index("y")],
            psi=s[:, rig.ipsi],
            r=s[:, rig.ir],
            delta=rig.rudder(s),
            delta_c=np.append(cmd, cmd[-1]),
            speed=rig.speed(s),
            simulation=sim,
        )

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
            return [_num(float(v) * scale) for v in a[idx]]

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


def _header(rig: _Rig, manoeuvre: str) -> dict[str, Any]:
    p = rig.particulars
    return {
        "manoeuvre": manoeuvre,
        "model": rig.name,
        "vessel": p.vessel,
        "length_m": p.length,
        "approach_speed_m_s": _num(rig.approach_speed),
        "length_over_speed_s": _num(p.length_over_speed),
        "dt_s": rig.dt,
    }


@dataclass(frozen=True, eq=False)
class ZigZagResult:
    """A simulated zigzag ``a/b`` trial (angles in rad, times in s).

    Attributes
    ----------
    model : str
        Model name.
    particulars : ShipParticulars
        Length and speed of the ship.
    approach_speed : float
        Speed at the first execute [m/s].
    rudder : float
        Rudder angle ``a`` [rad].
    heading_check : float
        Heading change ``b`` [rad] at which the rudder is reversed.
    first : str
        ``"starboard"`` or ``"port"``: side of the first rudder execute.
    series : TimeSeries
        Time histories.
    execute_times : tuple of float
        Times of the rudder reversals (second, third, ... execute) [s].
    overshoots : tuple of float
        Overshoot angle after each reversal [rad] (NaN if the swing was not checked).
    overshoot_times : tuple of float
        Times of the heading peaks [s].
    initial_turning_time : float
        First to second execute [s].
    time_to_check_yaw : float
        Second execute to the first heading peak [s].
    period : float
        Mean time between every other reversal [s] (NaN with fewer than three reversals).
    completed : bool
        All requested reversals happened and every swing was checked.
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    rudder: float
    heading_check: float
    first: str
    series: TimeSeries
    execute_times: tuple[float, ...]
    overshoots: tuple[float, ...]
    overshoot_times: tuple[float, ...]
    initial_turning_time: float
    time_to_check_yaw: float
    period: float
    completed: bool
    dt: float

    @property
    def overshoots_deg(self) -> tuple[float, ...]:
        """Overshoot angles [deg]."""
        return tuple(math.degrees(o) for o in self.overshoots)

    @property
    def label(self) -> str:
        """``"a/b"`` in degrees, e.g. ``"20/20"``."""
        return f"{math.degrees(self.rudder):g}/{math.degrees(self.heading_check):g}"

    def to_dict(self, include_series: bool = True) -> dict[str, Any]:
        """Metrics (and time series) for JSON; degrees in ``*_deg`` keys."""
        d = {
            "manoeuvre": "zigzag",
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": self.particulars.length,
            "approach_speed_m_s": _num(self.approach_speed),
            "length_over_speed_s": _num(self.particulars.length_over_speed),
            "dt_s": self.dt,
            "rudder_deg": _deg(self.rudder),
            "heading_check_deg": _deg(self.heading_check),
            "first": self.first,
            "completed": self.completed,
            "overshoots_deg": [_deg(o) for o in self.overshoots],
            "overshoot_times_s": [_num(t) for t in self.overshoot_times],
            "execute_times_s": [_num(t) for t in self.execute_times],
            "initial_turning_time_s": _num(self.initial_turning_time),
            "time_to_check_yaw_s": _num(self.time_to_check_yaw),
            "period_s": _num(self.period),
        }
        if include_series:
            d["series"] = self.series.to_dict()
        return d


class _ZigZagPilot:
    """Zigzag logic of seed 000 on the unwrapped heading change, nearest-step switching."""

    def __init__(self, rig: _Rig, a: float, b: float, sign0: float, n_max: int) -> None:
        self.rig, self.a, self.b = rig, a, b
        self.sign = sign0
        self.psi0 = float(rig.x0[rig.ipsi])
        self.executes: list[float] = []
        self.n_max = n_max

    def __call__(self, t: float, x: np.ndarray) -> float:
        if len(self.executes) < self.n_max:
            # heading change predicted at the middle of the coming step
            h = x[self.rig.ipsi] - self.psi0 + 0.5 * self.rig.dt * x[self.rig.ir]
            if self.sign * h >= self.b:
                self.sign = -self.sign
                self.executes.append(t)
        return self.sign * self.a


def _peak_after(
    time: np.ndarray, h: np.ndarray, r: np.ndarray, t0: float, s: float
) -> tuple[int, float] | None:
    """Sample and value of the heading peak ``s h`` after ``t0`` (where ``s r`` first turns
    <= 0), refined by a parabola through three samples; None if the swing is not checked."""
    i0 = int(np.searchsorted(time, t0 - 1e-9))
    stop = np.nonzero(s * r[i0:] <= 0.0)[0]
    if len(stop) == 0:
        return None
    j = i0 + int(stop[0])
    # the extreme heading up to the stop sample (refined by a parabola through 3 samples)
    k = i0 + int(np.argmax(s * h[i0 : j + 1]))
    peak = s * h[k]
    if 0 < k < len(h) - 1:
        y0, y1, y2 = s * h[k - 1], s * h[k], s * h[k + 1]
        den = y0 - 2 * y1 + y2
        if den < 0:
            peak = y1 - 0.125 * (y2 - y0) ** 2 / den
    return k, float(peak)


def zigzag(
    model: ModelLike = "nomoto1",
    a_deg: float = 20.0,
    b_deg: float | None = None,
    first: str = "starboard",
    n_reversals: int = 4,
    dt: float | None = None,
    max_duration: float | None = None,
) -> ZigZagResult:
    """Simulate a zigzag ``a/b`` trial (Kempf's Z-manoeuvre, seed 000).

    Parameters
    ----------
    model : str or ShipModel
        Model name (default parameters) or a model built with :func:`make_model`.
    a_deg : float
        Rudder angle ``a`` [deg], in (0, 35].
    b_deg : float, optional
        Heading change ``b`` [deg] at which the rudder is reversed (default ``a_deg``).
    first : {"starboard", "port"}
        Side of the first rudder execute.
    n_reversals : int
        Rudder reversals to simulate; one overshoot is measured after each.
    dt : float, optional
        Integration step [s] (default 0.1 s).
    max_duration : float, optional
        Longest simulated time [s] (default 4000 s Nomoto, 600 s RVG).

    Returns
    -------
    ZigZagResult
        ``completed`` is False when the swing after a reversal was never checked within
        ``max_duration`` (its overshoot is NaN), as for a strongly unstable ship.
    """
    rig = _Rig(model, dt)
    a = rig.check_rudder(a_deg, "zigzag rudder angle a_deg")
    b_deg = a_deg if b_deg is None else b_deg
    if not (isinstance(b_deg, int | float) and math.isfinite(b_deg) and 0 < b_deg <= 90):
        raise ValueError(f"zigzag heading change b_deg must be in (0, 90] deg, got {b_deg!r}")
    b = math.radians(b_deg)
    s0 = _side_sign(first)
    if not (isinstance(n_reversals, int) and 1 <= n_reversals <= 20):
        raise ValueError(f"n_reversals must be an integer in [1, 20], got {n_reversals!r}")
    limit = _duration(max_duration, rig.settings.max_duration)
    pilot = _ZigZagPilot(rig, a, b, s0, n_reversals)
    run = _Run(rig, pilot)
    chunk = min(rig.settings.chunk, 0.5 * limit)
    s_last = s0 if (n_reversals - 1) % 2 == 0 else -s0  # swing direction at the last reversal
    while run.t < limit:
        run.advance(chunk)
        if len(pilot.executes) == n_reversals:
            sim = run.result()
            h = sim["psi"] - pilot.psi0
            if _peak_after(sim.time, h, sim["r"], pilot.executes[-1], s_last) is not None:
                run.advance(0.1 * run.t)  # a margin after the last peak (for the figure)
                break
    series = TimeSeries._from(rig, run.result())
    h = series.psi - pilot.psi0
    executes = pilot.executes[:n_reversals]
    overshoots: list[float] = []
    peak_times: list[float] = []
    for k, te in enumerate(executes):
        s = s0 if k % 2 == 0 else -s0  # swing direction at reversal k
        found = _peak_after(series.time, h, series.r, te, s)
        if found is None:
            overshoots.append(math.nan)
            peak_times.append(math.nan)
            break
        j, peak = found
        overshoots.append(float(peak - b))
        peak_times.append(float(series.time[j]))
    completed = len(executes) == n_reversals and len(overshoots) == n_reversals
    completed = completed and all(math.isfinite(o) for o in overshoots)
    # crop a little after the last measured peak
    last = [t for t in (*peak_times, *executes) if math.isfinite(t)]
    if completed and last:
        t_end = 1.06 * max(last)
        series = series.crop(int(np.searchsorted(series.time, t_end)) + 1)
    period = math.nan
    if len(executes) >= 3:
        period = float(np.mean(np.subtract(executes[2:], executes[:-2])))
    return ZigZagResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        rudder=a,
        heading_check=b,
        first=first,
        series=series,
        execute_times=tuple(float(t) for t in executes),
        overshoots=tuple(overshoots),
        overshoot_times=tuple(peak_times),
        initial_turning_time=float(executes[0]) if executes else math.nan,
        time_to_check_yaw=(peak_times[0] - executes[0] if executes and peak_times else math.nan),
        period=period,
        completed=completed,
        dt=rig.dt,
    )


def _duration(value: float | None, default: float) -> float:
    if value is None:
        return default
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise ValueError(f"max_duration must be a finite time > 0 s, got {value!r}")
    return float(value)


# ------------------------------------------------------------------------------------------
# turning circle and initial turning
# ------------------------------------------------------------------------------------------
def _crossing(h: np.ndarray, target: float) -> tuple[int, float] | None:
    """First sample ``i`` with ``h[i] >= target`` and the fraction ``w`` back to ``i - 1``."""
    idx = np.nonzero(h >= target)[0]
    if len(idx) == 0:
        return None
    i = int(idx[0])
    if i == 0:
        return 0, 1.0
    w = (target - h[i - 1]) / (h[i] - h[i - 1])
    return i, float(w)


def _at(values: np.ndarray, cross: tuple[int, float]) -> float:
    i, w = cross
    if i == 0:
        return float(values[0])
    return float(values[i - 1] + w * (values[i] - values[i - 1]))


def _fit_circle(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Least-squares (Kasa) circle through the points: centre (x, y) and radius."""
    A = np.column_stack([2 * x, 2 * y, np.ones_like(x)])
    rhs = x * x + y * y
    (cx, cy, c), *_ = np.linalg.lstsq(A, rhs, rcond=None)
    return float(cx), float(cy), float(math.sqrt(c + cx * cx + cy * cy))


@dataclass(frozen=True, eq=False)
class TurningResult:
    """A simulated turning circle (lengths in m, angles in rad, times in s).

    Attributes
    ----------
    model, particulars, approach_speed, rudder, side, series
        As in :class:`ZigZagResult`; ``rudder`` is the (positive) rudder angle [rad].
    advance : float
        Distance along the approach course at 90 deg heading change [m].
    transfer : float
        Distance across the approach course, toward the turn, at 90 deg heading change [m].
    tactical_diameter : float
        Transfer at 180 deg heading change [m].
    steady_diameter : float
        Diameter of the least-squares circle through one full steady turn [m].
    steady_center : tuple of float
        Its centre (north, east) [m].
    steady_yaw_rate : float
        Mean yaw rate in the steady turn [rad/s] (signed: + starboard).
    steady_speed : float
        Mean speed through the water in the steady turn [m/s].
    speed_ratio : float
        ``steady_speed / approach_speed`` (1 - speed loss).
    time_to_90, time_to_180 : float
        Times of the 90 and 180 deg heading changes [s].
    points : dict
        Positions (north, east) [m] at the execute, 90 and 180 deg.
    heading_changes, speeds : numpy.ndarray
        Speed [m/s] at heading changes of 10, 20, ..., 180 deg [rad] (seed 002 Table 3).
    rudder_time, steady_time : float
        End of the first phase (rudder at its order) and start of the third (steady) phase
        (|r - r_steady| < 2 % from then on) [s] (seed 002 Table 1).
    steady : bool
        Yaw rate and speed settled within the longest hold.
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    rudder: float
    side: str
    series: TimeSeries
    advance: float
    transfer: float
    tactical_diameter: float
    steady_diameter: float
    steady_center: tuple[float, float]
    steady_yaw_rate: float
    steady_speed: float
    speed_ratio: float
    time_to_90: float
    time_to_180: float
    points: dict[str, tuple[float, float]]
    heading_changes: np.ndarray
    speeds: np.ndarray
    rudder_time: float
    steady_time: float
    steady: bool
    dt: float

    def to_dict(self, include_series: bool = True) -> dict[str, Any]:
        """Metrics (and time series) for JSON; degrees in ``*_deg`` keys."""
        L = self.particulars.length
        d = {
            "manoeuvre": "turning_circle",
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": L,
            "approach_speed_m_s": _num(self.approach_speed),
            "length_over_speed_s": _num(self.particulars.length_over_speed),
            "dt_s": self.dt,
            "rudder_deg": _deg(self.rudder),
            "side": self.side,
            "advance_m": _num(self.advance),
            "transfer_m": _num(self.transfer),
            "tactical_diameter_m": _num(self.tactical_diameter),
            "steady_diameter_m": _num(self.steady_diameter),
            "advance_L": _num(self.advance / L),
            "transfer_L": _num(self.transfer / L),
            "tactical_diameter_L": _num(self.tactical_diameter / L),
            "steady_diameter_L": _num(self.steady_diameter / L),
            "steady_yaw_rate_deg_s": _deg(self.steady_yaw_rate),
            "steady_speed_m_s": _num(self.steady_speed),
            "speed_ratio": _num(self.speed_ratio),
            "speed_loss": _num(1.0 - self.speed_ratio),
            "time_to_90_deg_s": _num(self.time_to_90),
            "time_to_180_deg_s": _num(self.time_to_180),
            "rudder_at_order_time_s": _num(self.rudder_time),
            "steady_time_s": _num(self.steady_time),
            "steady": self.steady,
            "speed_vs_heading_change": {
                "heading_change_deg": [_deg(h) for h in self.heading_changes],
                "speed_m_s": [_num(v) for v in self.speeds],
            },
        }
        if include_series:
            d["series"] = self.series.to_dict()
        return d


def turning_circle(
    model: ModelLike = "nomoto1",
    rudder_deg: float = 35.0,
    side: str = "starboard",
    dt: float | None = None,
) -> TurningResult:
    """Simulate a turning circle with ``rudder_deg`` to ``side``.

    The rudder is put over at t = 0 from straight running and held. The run goes on until the
    heading has changed 180 deg and the yaw rate and speed have settled, and then for one
    more full turn, through which the steady turning circle is fitted.

    Parameters
    ----------
    model : str or ShipModel
        Model name or model.
    rudder_deg : float
        Rudder angle [deg], in (0, 35].
    side : {"starboard", "port"}
        Turn direction.
    dt : float, optional
        Integration step [s].

    Returns
    -------
    TurningResult

    Raises
    ------
    ValueError
        For bad arguments, or if the heading never changes 180 deg within the longest hold.
    """
    rig = _Rig(model, dt)
    delta = rig.check_rudder(rudder_deg, "turning circle rudder_deg")
    s = _side_sign(side)
    run = _Run(rig, lambda t, x: s * delta)
    psi0 = float(rig.x0[rig.ipsi])

    def turned(angle: float) -> Callable[[], bool]:
        return lambda: s * (run.x[rig.ipsi] - psi0) >= angle

    steady, _ = _hold_until_steady(run, rig, extra=turned(math.pi))
    if not turned(math.pi)():
        raise ValueError(
            f"{rig.name} did not turn 180 deg within {rig.settings.max_hold:g} s "
            f"with {rudder_deg:g} deg rudder"
        )
    t_steady = run.t
    h_start = s * (run.x[rig.ipsi] - psi0)
    while s * (run.x[rig.ipsi] - psi0) < h_start + 2 * math.pi:
        run.advance(rig.settings.chunk / 5)
    series = TimeSeries._from(rig, run.result())
    h = s * (series.psi - psi0)
    c90, c180 = _crossing(h, 0.5 * math.pi), _crossing(h, math.pi)
    assert c90 is not None and c180 is not None
    n0, e0 = float(series.x[0]), float(series.y[0])
    along = (series.x - n0) * math.cos(psi0) + (series.y - e0) * math.sin(psi0)
    across = s * (-(series.x - n0) * math.sin(psi0) + (series.y - e0) * math.cos(psi0))
    i_s = int(np.searchsorted(series.time, t_steady - 1e-9))
    end = _crossing(h, h_start + 2 * math.pi)
    i_e = end[0] if end is not None else len(h) - 1
    cx, cy, radius = _fit_circle(series.x[i_s : i_e + 1], series.y[i_s : i_e + 1])
    r_ss = float(np.mean(series.r[i_s : i_e + 1]))
    v_ss = float(np.mean(series.speed[i_s : i_e + 1]))
    changes = np.radians(np.arange(10.0, 181.0, 10.0))
    crossings = [_crossing(h, c) for c in changes]
    speeds = np.array([math.nan if c is None else _at(series.speed, c) for c in crossings])
    at_order = np.nonzero(np.abs(series.delta - s * delta) <= 0.01 * delta)[0]
    outside = np.nonzero(np.abs(series.r - r_ss) > 0.02 * abs(r_ss))[0]
    t_steady3 = float(series.time[min(outside[-1] + 1, len(h) - 1)]) if len(outside) else 0.0
    return TurningResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        rudder=delta,
        side=side,
        series=series,
        advance=_at(along, c90),
        transfer=_at(across, c90),
        tactical_diameter=_at(across, c180),
        steady_diameter=2.0 * radius,
        steady_center=(cx, cy),
        steady_yaw_rate=r_ss,
        steady_speed=v_ss,
        speed_ratio=v_ss / rig.approach_speed,
        time_to_90=_at(series.time, c90),
        time_to_180=_at(series.time, c180),
        points={
            "execute": (n0, e0),
            "heading_90": (_at(series.x, c90), _at(series.y, c90)),
            "heading_180": (_at(series.x, c180), _at(series.y, c180)),
        },
        heading_changes=changes,
        speeds=speeds,
        rudder_time=float(series.time[at_order[0]]) if len(at_order) else math.nan,
        steady_time=t_steady3,
        steady=steady,
        dt=rig.dt,
    )


@dataclass(frozen=True, eq=False)
class InitialTurningResult:
    """Initial turning ability: distance travelled until the heading has changed ``heading``.

    Attributes
    ----------
    model, particulars, approach_speed, rudder, side, series
        As in :class:`TurningResult`.
    heading : float
        Heading change [rad] at which the distance is measured (10 deg).
    distance : float
        Distance travelled along the track from the execute [m].
    advance : float
        Distance along the approach course at that moment [m].
    time : float
        Time of the heading change [s].
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    rudder: float
    side: str
    heading: float
    distance: float
    advance: float
    time: float
    series: TimeSeries
    dt: float

    def to_dict(self, include_series: bool = False) -> dict[str, Any]:
        """Metrics (and time series) for JSON."""
        d = {
            "manoeuvre": "initial_turning",
            "model": self.model,
            "rudder_deg": _deg(self.rudder),
            "side": self.side,
            "heading_change_deg": _deg(self.heading),
            "distance_m": _num(self.distance),
            "distance_L": _num(self.distance / self.particulars.length),
            "advance_m": _num(self.advance),
            "time_s": _num(self.time),
        }
        if include_series:
            d["series"] = self.series.to_dict()
        return d


def initial_turning(
    model: ModelLike = "nomoto1",
    rudder_deg: float = 10.0,
    heading_deg: float = 10.0,
    side: str = "starboard",
    dt: float | None = None,
) -> InitialTurningResult:
    """Initial turning test (MSC.137(76) 5.3.2): rudder to ``rudder_deg`` until the heading
    has changed ``heading_deg``; the distance travelled along the track is measured.

    Raises
    ------
    ValueError
        For bad arguments or if the heading change is not reached within the longest hold.
    """
    rig = _Rig(model, dt)
    delta = rig.check_rudder(rudder_deg, "initial turning rudder_deg")
    if not (isinstance(heading_deg, int | float) and math.isfinite(heading_deg)):
        raise ValueError(f"heading_deg must be a finite angle, got {heading_deg!r}")
    if not 0 < heading_deg <= 180:
        raise ValueError(f"heading_deg must be in (0, 180] deg, got {heading_deg!r}")
    target = math.radians(heading_deg)
    s = _side_sign(side)
    run = _Run(rig, lambda t, x: s * delta)
    psi0 = float(rig.x0[rig.ipsi])
    while s * (run.x[rig.ipsi] - psi0) < target:
        if run.t >= rig.settings.max_hold:
            raise ValueError(
                f"{rig.name} did not turn {heading_deg:g} deg within "
                f"{rig.settings.max_hold:g} s with {rudder_deg:g} deg rudder"
            )
        run.advance(rig.settings.chunk / 5)
    series = TimeSeries._from(rig, run.result())
    cross = _crossing(s * (series.psi - psi0), target)
    assert cross is not None
    track = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(series.x), np.diff(series.y)))])
    along = (series.x - series.x[0]) * math.cos(psi0) + (series.y - series.y[0]) * math.sin(psi0)
    i = cross[0]
    return InitialTurningResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        rudder=delta,
        side=side,
        heading=target,
        distance=_at(track, cross),
        advance=_at(along, cross),
        time=_at(series.time, cross),
        series=series.crop(i + 1),
        dt=rig.dt,
    )


# ------------------------------------------------------------------------------------------
# pull-out
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class PullOutResult:
    """A pull-out trial: steady turn, then rudder amidships.

    Attributes
    ----------
    model, particulars, approach_speed, rudder, side, series
        As in :class:`TurningResult`.
    pullout_time : float
        Time the rudder is returned to amidships [s].
    turn_yaw_rate : float
        Steady yaw rate of the turn before the pull-out [rad/s].
    residual_yaw_rate : float
        Yaw rate at the end (mean over the last window) [rad/s].
    decay_time : float
        Time after the pull-out for ``|r|`` to fall to ``|turn_yaw_rate| / e`` [s] (NaN if
        it never does).
    stable : bool
        ``|residual_yaw_rate| <= 0.05 |turn_yaw_rate|``: the ship is directionally stable.
    settled : bool
        The yaw rate settled within the longest hold.
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    rudder: float
    side: str
    series: TimeSeries
    pullout_time: float
    turn_yaw_rate: float
    residual_yaw_rate: float
    decay_time: float
    stable: bool
    settled: bool
    dt: float

    def to_dict(self, include_series: bool = True) -> dict[str, Any]:
        """Metrics (and time series) for JSON; degrees in ``*_deg`` keys."""
        d = {
            "manoeuvre": "pullout",
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": self.particulars.length,
            "approach_speed_m_s": _num(self.approach_speed),
            "dt_s": self.dt,
            "rudder_deg": _deg(self.rudder),
            "side": self.side,
            "pullout_time_s": _num(self.pullout_time),
            "turn_yaw_rate_deg_s": _deg(self.turn_yaw_rate),
            "residual_yaw_rate_deg_s": _deg(self.residual_yaw_rate),
            "decay_time_s": _num(self.decay_time),
            "stable": self.stable,
            "settled": self.settled,
        }
        if include_series:
            d["series"] = self.series.to_dict()
        return d


def pullout(
    model: ModelLike = "nomoto1",
    rudder_deg: float = 20.0,
    side: str = "starboard",
    dt: float | None = None,
) -> PullOutResult:
    """Pull-out trial: turn with ``rudder_deg`` to ``side`` until steady, then rudder 0.

    The yaw rate after the pull-out is followed until it settles; a residual yaw rate above
    5 % of the turning rate marks a directionally unstable ship.
    """
    rig = _Rig(model, dt)
    delta = rig.check_rudder(rudder_deg, "pull-out rudder_deg")
    s = _side_sign(side)
    state = {"delta": s * delta}
    run = _Run(rig, lambda t, x: state["delta"])
    _, turn = _hold_until_steady(run, rig)
    t_pull = run.t
    state["delta"] = 0.0
    settled, after = _hold_until_steady(run, rig, min_time=2 * rig.settings.chunk)
    series = TimeSeries._from(rig, run.result())
    r_turn, r_res = float(turn[0]), float(after[0])
    i_p = int(np.searchsorted(series.time, t_pull - 1e-9))
    below = np.nonzero(np.abs(series.r[i_p:]) <= abs(r_turn) / math.e)[0]
    decay = float(series.time[i_p + below[0]] - t_pull) if len(below) else math.nan
    return PullOutResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        rudder=delta,
        side=side,
        series=series,
        pullout_time=t_pull,
        turn_yaw_rate=r_turn,
        residual_yaw_rate=r_res,
        decay_time=decay,
        stable=abs(r_res) <= 0.05 * abs(r_turn),
        settled=settled,
        dt=rig.dt,
    )


# ------------------------------------------------------------------------------------------
# spiral
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SpiralResult:
    """A direct or reverse spiral: the steady delta-r curve (seed 004 Fig. 1).

    Attributes
    ----------
    model, particulars, approach_speed, series
        As in :class:`ZigZagResult`.
    kind : str
        ``"direct"`` (Dieudonné) or ``"reverse"`` (Bech).
    rudder : numpy.ndarray
        Steady (mean) rudder angle of each point [rad].
    yaw_rate : numpy.ndarray
        Steady (mean) yaw rate of each point [rad/s].
    speed : numpy.ndarray
        Steady (mean) speed [m/s].
    leg : tuple of str
        ``"down"`` (starboard to port) or ``"up"`` (back) for each point.
    setpoints : numpy.ndarray or None
        Yaw-rate setpoints [rad/s] of the reverse spiral.
    steady : numpy.ndarray
        Whether each point settled within the longest hold.
    saturated : numpy.ndarray
        Reverse spiral: the rudder hit its limit (the point is not on the curve).
    hysteresis : bool
        Direct: the down and up legs give yaw rates of opposite sign at one rudder angle.
        Reverse: the rudder needed decreases with the yaw rate somewhere (an S-curve).
        Either means the ship is directionally unstable.
    loop_width : float
        Width of the hysteresis loop in rudder angle [rad] (0 if none). Direct: the span of
        the rudder angles at which the legs disagree (at the resolution of the sequence);
        reverse: the rudder span of the unstable (negative-slope) branch.
    """

    model: str
    particulars: ShipParticulars
    approach_speed: float
    kind: str
    rudder: np.ndarray
    yaw_rate: np.ndarray
    speed: np.ndarray
    leg: tuple[str, ...]
    setpoints: np.ndarray | None
    steady: np.ndarray
    saturated: np.ndarray
    hysteresis: bool
    loop_width: float
    series: TimeSeries
    dt: float

    def to_dict(self, include_series: bool = False) -> dict[str, Any]:
        """The delta-r points for JSON; degrees in ``*_deg`` keys."""
        d: dict[str, Any] = {
            "manoeuvre": "spiral",
            "kind": self.kind,
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": self.particulars.length,
            "approach_speed_m_s": _num(self.approach_speed),
            "dt_s": self.dt,
            "rudder_deg": [_deg(v) for v in self.rudder],
            "yaw_rate_deg_s": [_deg(v) for v in self.yaw_rate],
            "speed_m_s": [_num(v) for v in self.speed],
            "leg": list(self.leg),
            "steady": [bool(v) for v in self.steady],
            "saturated": [bool(v) for v in self.saturated],
            "hysteresis": self.hysteresis,
            "loop_width_deg": _deg(self.loop_width),
        }
        if self.setpoints is not None:
            d["yaw_rate_setpoint_deg_s"] = [_deg(v) for v in self.setpoints]
        if include_series:
            d["series"] = self.series.to_dict()
        return d


class _YawRatePI:
    """PI yaw-rate controller with conditional integration (anti-windup) for the reverse
    spiral: ``delta_c = kp (r_d - r) + ki int (r_d - r) dt``, saturated at the rudder limit."""

    def __init__(self, rig: _Rig) -> None:
        self.rig = rig
        self.kp = rig.settings.kp
        self.ki = rig.settings.kp / rig.settings.ti
        self.setpoint = 0.0
        self.integral = 0.0

    def __call__(self, t: float, x: np.ndarray) -> float:
        e = self.setpoint - x[self.rig.ir]
        limit = self.rig.max_rudder
        unsat = self.kp * e + self.integral
        if abs(unsat) < limit or unsat * e < 0:
            self.integral += self.ki * e * self.rig.dt
            self.integral = min(max(self.integral, -limit), limit)
        return min(max(self.kp * e + self.integral, -limit), limit)


def _monotonic_loop(r: np.ndarray, delta: np.ndarray) -> tuple[bool, float]:
    """Negative-slope (unstable) branch of delta(r): exists? and its rudder span."""
    dd = delta[np.argsort(r)]
    slope = np.diff(dd)
    neg = np.nonzero(slope < -1e-9 * max(1.0, float(np.max(np.abs(dd)))))[0]
    if len(neg) == 0:
        return False, 0.0
    ends = np.concatenate([dd[neg], dd[neg + 1]])
    return True, float(np.max(ends) - np.min(ends))


def spiral(
    model: ModelLike = "norrbin",
    rudders_deg: Sequence[float] | None = None,
    kind: str = "direct",
    yaw_rates_deg_s: Sequence[float] | None = None,
    return_leg: bool = True,
    dt: float | None = None,
    progress: Progress = None,
) -> SpiralResult:
    """Direct (Dieudonné) or reverse (Bech) spiral: the steady delta-r curve.

    Parameters
    ----------
    model : str or ShipModel
        Model name or model.
    rudders_deg : sequence of float, optional
        Direct spiral: rudder angles [deg] from starboard to port (default 20, 15, 10, 5, 3,
        2, 1, 0, -1, ..., -20 for the Mariner models); with ``return_leg`` the sequence is
        run back again, so that an unstable ship shows its hysteresis loop.
    kind : {"direct", "reverse"}
        Trial.
    yaw_rates_deg_s : sequence of float, optional
        Reverse spiral: yaw-rate setpoints [deg/s] (default 21 values from +r_max to
        -r_max, 1.43 deg/s for the Mariner models and 4.6 deg/s for the RVG).
    return_leg : bool
        Direct spiral: run the sequence back from port to starboard.
    dt : float, optional
        Integration step [s].
    progress : callable, optional
        Called with a one-line message after each point.

    Returns
    -------
    SpiralResult
    """
    rig = _Rig(model, dt)
    if kind not in ("direct", "reverse"):
        raise ValueError(f"spiral kind must be 'direct' or 'reverse', got {kind!r}")
    limit_deg = math.degrees(rig.max_rudder)
    if kind == "direct":
        seq = rig.settings.spiral_rudders_deg if rudders_deg is None else tuple(rudders_deg)
        if len(seq) < 2:
            raise ValueError(f"rudders_deg needs at least 2 angles, got {seq!r}")
        for v in seq:
            if not (isinstance(v, int | float) and math.isfinite(v) and abs(v) <= limit_deg):
                raise ValueError(
                    f"spiral rudder angles must be finite and within +-{limit_deg:g} deg, got {v!r}"
                )
        targets = [math.radians(v) for v in seq]
        legs = ["down"] * len(seq)
        if return_leg:
            targets += targets[-2::-1]
            legs += ["up"] * (len(seq) - 1)
        hold = {"delta": targets[0]}
        run = _Run(rig, lambda t, x: hold["delta"])
        setpoints = None
    else:
        if yaw_rates_deg_s is None:
            r_max = rig.settings.spiral_yaw_rate
            targets = list(np.linspace(r_max, -r_max, 21))
        else:
            targets = []
            for v in yaw_rates_deg_s:
                if not (isinstance(v, int | float) and math.isfinite(v) and abs(v) <= 30):
                    raise ValueError(
                        f"yaw-rate setpoints must be finite and within +-30 deg/s, got {v!r}"
                    )
                targets.append(math.radians(v))
            if len(targets) < 2:
                raise ValueError(f"yaw_rates_deg_s needs at least 2 values, got {targets!r}")
        legs = ["down"] * len(targets)
        pi = _YawRatePI(rig)
        run = _Run(rig, pi)
        setpoints = np.array(targets, dtype=float)
    rows = []
    for k, target in enumerate(targets):
        if kind == "direct":
            hold["delta"] = target
        else:
            pi.setpoint = target
        ok, mean = _hold_until_steady(run, rig, min_time=2 * rig.settings.chunk)
        rows.append((*mean, ok))
        if progress is not None:
            what = (
                f"rudder {math.degrees(target):+6.2f} deg"
                if kind == "direct"
                else f"r_d {math.degrees(target):+6.3f} deg/s"
            )
            progress(
                f"{kind} spiral {k + 1}/{len(targets)}: {what} -> r {math.degrees(mean[0]):+.3f} "
                f"deg/s, rudder {math.degrees(mean[2]):+.2f} deg" + ("" if ok else " (not settled)")
            )
    arr = np.array([row[:3] for row in rows])
    r_ss, v_ss, d_ss = arr[:, 0], arr[:, 1], arr[:, 2]
    steady = np.array([row[3] for row in rows], dtype=bool)
    if kind == "direct":
        saturated = np.zeros(len(rows), dtype=bool)
        tol = max(1e-4, 0.02 * float(np.max(np.abs(r_ss))))
        down = {round(d, 9): r for d, r, g in zip(targets, r_ss, legs, strict=True) if g == "down"}
        split = [
            d
            for d, r, g in zip(targets, r_ss, legs, strict=True)
            if g == "up"
            and round(d, 9) in down
            and abs(down[round(d, 9)] - r) > tol
            and down[round(d, 9)] * r < 0
        ]
        hysteresis = bool(split)
        width = float(max(split) - min(split)) if split else 0.0
    else:
        saturated = np.abs(d_ss) >= 0.99 * rig.max_rudder
        ok = ~saturated
        hysteresis, width = _monotonic_loop(r_ss[ok], d_ss[ok])
    return SpiralResult(
        model=rig.name,
        particulars=rig.particulars,
        approach_speed=rig.approach_speed,
        kind=kind,
        rudder=d_ss,
        yaw_rate=r_ss,
        speed=v_ss,
        leg=tuple(legs),
        setpoints=setpoints,
        steady=steady,
        saturated=saturated,
        hysteresis=hysteresis,
        loop_width=width,
        series=TimeSeries._from(rig, run.result()),
        dt=rig.dt,
    )


# ------------------------------------------------------------------------------------------
# IMO MSC.137(76)
# ------------------------------------------------------------------------------------------
# ------------------------------------------------------------------------------------------
# trial quantities of any time series: a simulation or a measured record
# ------------------------------------------------------------------------------------------
def _execute(delta: np.ndarray) -> tuple[int, float, float]:
    """First rudder execute, the rudder threshold of the trial and the side of the first
    rudder (+1 starboard): the rudder reaches 20 % of its largest angle (at least 0.5 deg)
    first at some sample; the execute is the start of that ramp, where the rudder began to move
    away from its initial angle."""
    if delta.size == 0 or not np.all(np.isfinite(delta)):
        raise ValueError("delta must be a non-empty series of finite rudder angles [rad]")
    thr = max(math.radians(0.5), 0.2 * float(np.max(np.abs(delta))))
    hits = np.flatnonzero(np.abs(delta) >= thr)
    if hits.size == 0:
        raise ValueError("the rudder never leaves amidships: no trial in this series")
    k = int(hits[0])
    side = float(np.sign(delta[k]))
    d0 = delta[0]
    while k > 0 and abs(delta[k - 1] - d0) < abs(delta[k] - d0):
        k -= 1
    return k, thr, side


def _series(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    out = tuple(np.asarray(a, dtype=np.float64) for a in arrays)
    n = out[0].size
    if any(a.shape != (n,) for a in out) or n < 3:
        shapes = [a.shape for a in out]
        raise ValueError(f"the series must be 1-D and of one length >= 3, got {shapes}")
    return out


def zigzag_quantities(
    time: np.ndarray, psi: np.ndarray, delta: np.ndarray, check: float
) -> dict[str, Any]:
    """Overshoots of a zigzag from its time series, simulated or measured.

    The first execute is the start of the first rudder ramp that reaches 20 % of the largest
    angle; the heading change ``h = psi - psi_0`` counts from the heading there. After each
    rudder reversal (the rudder crossing amidships) the overshoot is the heading excursion
    beyond the check heading ``check`` in the direction the ship was turning, up to the next
    reversal or, after the last one, to the end of the series if the heading has peaked
    (ITTC; the same definition as :func:`zigzag`). A reversal is the rudder reaching the
    execute threshold on the other side, timed from its last crossing of amidships.

    Parameters
    ----------
    time, psi, delta : numpy.ndarray
        Time [s], unwrapped heading [rad] and rudder angle [rad] (positive to starboard).
    check : float
        Heading change ``b`` [rad] of the trial.

    Returns
    -------
    dict
        ``first`` ("starboard" or "port"), ``n_reversals``, ``overshoot1_deg`` and
        ``overshoot2_deg`` (NaN when the record stops before the swing is checked),
        ``reversal_times`` [s].
    """
    time, psi, delta = _series(time, psi, delta)
    if not (math.isfinite(check) and check > 0.0):
        raise ValueError(f"check must be a heading change > 0 rad, got {check!r}")
    i0, thr, side = _execute(delta)
    h = psi - psi[i0]
    # a reversal: the rudder reaches the threshold on the other side; it counts from the last
    # crossing of amidships before that (noise around zero makes no reversal)
    rev = []
    current = side
    for k in range(i0, delta.size):
        if np.sign(delta[k]) == -current and abs(delta[k]) >= thr:
            m = k
            while m > i0 and np.sign(delta[m - 1]) == -current:
                m -= 1
            rev.append(m)
            current = -current
    shoots = []
    for j in range(2):
        d = side if j % 2 == 0 else -side  # the side the ship turned to before reversal j
        if j < len(rev):
            # up to the next reversal, or to the end when the heading has peaked before it
            swing = d * h[rev[j] : rev[j + 1] if j + 1 < len(rev) else h.size]
            peak = int(np.argmax(swing))
            checked = j + 1 < len(rev) or peak < swing.size - 1
            shoots.append(math.degrees(float(swing[peak]) - check) if checked else math.nan)
        else:
            shoots.append(math.nan)
    return {
        "first": "starboard" if side > 0 else "port",
        "n_reversals": len(rev),
        "overshoot1_deg": shoots[0],
        "overshoot2_deg": shoots[1],
        "reversal_times": [float(time[k]) for k in rev],
        "rudder_threshold_deg": math.degrees(thr),
    }


def turning_quantities(
    time: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    psi: np.ndarray,
    delta: np.ndarray,
    speed: np.ndarray,
) -> dict[str, Any]:
    """Advance, transfer, tactical diameter and speed loss of a turning circle from its time
    series, simulated or measured.

    The execute is the start of the first rudder ramp that reaches 20 % of the largest angle;
    distances are measured from the position there along and across the heading there.
    Advance and transfer at 90 deg of heading change, the tactical diameter (across) at 180 deg,
    the speed ratio is the mean speed between 360 and 720 deg of heading change (or from 270 deg
    to the end when the record turns less) over the mean speed of the last 10 s before the
    execute (its speed when there are none).

    Parameters
    ----------
    time, x, y, psi, delta, speed : numpy.ndarray
        Time [s], north and east position [m], unwrapped heading [rad], rudder angle [rad]
        (positive to starboard) and speed [m/s].

    Returns
    -------
    dict
        ``side``, ``advance``, ``transfer``, ``tactical_diameter`` [m] (NaN when not reached),
        ``approach_speed`` [m/s] and ``speed_ratio``.
    """
    time, x, y, psi, delta, speed = _series(time, x, y, psi, delta, speed)
    i0, _, side = _execute(delta)
    h = side * (psi[i0:] - psi[i0])
    c, s = math.cos(psi[i0]), math.sin(psi[i0])
    dx, dy = x[i0:] - x[i0], y[i0:] - y[i0]
    along = dx * c + dy * s
    across = side * (-dx * s + dy * c)

    def at(values: np.ndarray, angle: float) -> float:
        k = np.flatnonzero(h >= angle)
        if k.size == 0 or k[0] == 0:
            return math.nan
        j = int(k[0])
        return float(np.interp(angle, h[j - 1 : j + 1], values[j - 1 : j + 1]))

    before = (time >= time[i0] - 10.0) & (np.arange(time.size) < i0)
    u0 = float(np.mean(speed[before])) if np.any(before) else float(speed[i0])
    turned = speed[i0:][(h >= 2 * math.pi) & (h <= 4 * math.pi)]
    if turned.size == 0:
        turned = speed[i0:][h >= 1.5 * math.pi]
    return {
        "side": "starboard" if side > 0 else "port",
        "advance": at(along, math.pi / 2),
        "transfer": at(across, math.pi / 2),
        "tactical_diameter": at(across, math.pi),
        "approach_speed": u0,
        "speed_ratio": float(np.mean(turned)) / u0 if turned.size else math.nan,
    }


def overshoot_limits(length_over_speed: float) -> tuple[float, float, float]:
    """IMO MSC.137(76) 5.3.3 overshoot limits [deg] for ``L / U`` [s].

    Returns
    -------
    (float, float, float)
        10/10 first overshoot, 10/10 second overshoot, 20/20 first overshoot [deg].
    """
    q = float(length_over_speed)
    if not (math.isfinite(q) and q > 0):
        raise ValueError(f"L/U must be a finite time > 0 s, got {length_over_speed!r}")
    if q < 10.0:
        first, second = 10.0, 25.0
    elif q >= 30.0:
        first, second = 20.0, 40.0
    else:
        first, second = 5.0 + 0.5 * q, 17.5 + 0.75 * q
    return first, second, 25.0


@dataclass(frozen=True)
class IMORow:
    """One criterion of MSC.137(76): value, limit and the verdict (a report row).

    Attributes
    ----------
    criterion : str
        What is checked.
    value : float
        Worst value over the sides in ``unit`` (NaN if it could not be measured).
    limit : float
        The criterion's upper limit in ``unit``.
    unit : str
        ``"L"`` (ship lengths) or ``"deg"``.
    passed : bool
        ``value <= limit`` ("should not exceed") (a NaN value fails).
    detail : str
        Which trial and side gave the value.
    """

    criterion: str
    value: float
    limit: float
    unit: str
    passed: bool
    detail: str = ""

    def to_dict(self) -> dict[str, Any]:
        """For JSON."""
        return {
            "criterion": self.criterion,
            "value": _num(self.value, 4),
            "limit": _num(self.limit, 4),
            "unit": self.unit,
            "pass": self.passed,
            "detail": self.detail,
        }


def _row(criterion: str, values: list[tuple[float, str]], limit: float, unit: str) -> IMORow:
    """Worst (largest, NaN first) of ``(value, detail)`` pairs against ``limit``."""
    nan = [v for v in values if not math.isfinite(v[0])]
    value, detail = nan[0] if nan else max(values, key=lambda v: v[0])
    return IMORow(
        criterion, value, limit, unit, bool(math.isfinite(value) and value <= limit), detail
    )


def imo_rows(
    particulars: ShipParticulars,
    turning: Sequence[TurningResult] = (),
    initial: Sequence[InitialTurningResult] = (),
    zigzags: Sequence[ZigZagResult] = (),
) -> list[IMORow]:
    """The MSC.137(76) rows that the given trials allow (worst side of each).

    Turning circles count for the turning ability only at 35 deg rudder; zigzags only if
    they are 10/10 or 20/20. A zigzag that was never checked counts as NaN (fail).
    """
    L = particulars.length
    rows: list[IMORow] = []
    full = [t for t in turning if abs(math.degrees(t.rudder) - 35.0) < 1e-6]
    if full:
        rows.append(
            _row(
                "turning ability: advance (35 deg rudder)",
                [(t.advance / L, f"turning circle to {t.side}") for t in full],
                4.5,
                "L",
            )
        )
        rows.append(
            _row(
                "turning ability: tactical diameter (35 deg rudder)",
                [(t.tactical_diameter / L, f"turning circle to {t.side}") for t in full],
                5.0,
                "L",
            )
        )
    if initial:
        rows.append(
            _row(
                "initial turning: distance to 10 deg heading change (10 deg rudder)",
                [(i.distance / L, f"10 deg rudder to {i.side}") for i in initial],
                2.5,
                "L",
            )
        )
    first_lim, second_lim, first20_lim = overshoot_limits(particulars.length_over_speed)

    def zz(a: float) -> list[ZigZagResult]:
        return [
            z
            for z in zigzags
            if abs(math.degrees(z.rudder) - a) < 1e-6
            and abs(math.degrees(z.heading_check) - a) < 1e-6
        ]

    def overshoot(z: ZigZagResult, k: int) -> float:
        return z.overshoots_deg[k] if len(z.overshoots) > k else math.nan

    if z10 := zz(10.0):
        rows.append(
            _row(
                "yaw-checking: 10/10 zigzag 1st overshoot",
                [(overshoot(z, 0), f"10/10 {z.first} first") for z in z10],
                first_lim,
                "deg",
            )
        )
        rows.append(
            _row(
                "course-keeping: 10/10 zigzag 2nd overshoot",
                [(overshoot(z, 1), f"10/10 {z.first} first") for z in z10],
                second_lim,
                "deg",
            )
        )
    if z20 := zz(20.0):
        rows.append(
            _row(
                "yaw-checking: 20/20 zigzag 1st overshoot",
                [(overshoot(z, 0), f"20/20 {z.first} first") for z in z20],
                first20_lim,
                "deg",
            )
        )
    return rows


@dataclass(frozen=True, eq=False)
class IMOReport:
    """The MSC.137(76) check of one model with the trials behind it.

    Attributes
    ----------
    model : str
        Model name.
    particulars : ShipParticulars
        ``L`` and ``U``.
    rows : tuple of IMORow
        One row per criterion.
    turning, initial, zigzag_10, zigzag_20 : tuple
        The trials to each side.
    """

    model: str
    particulars: ShipParticulars
    rows: tuple[IMORow, ...]
    turning: tuple[TurningResult, ...]
    initial: tuple[InitialTurningResult, ...]
    zigzag_10: tuple[ZigZagResult, ...]
    zigzag_20: tuple[ZigZagResult, ...]

    @property
    def passed(self) -> bool:
        """All criteria met."""
        return all(row.passed for row in self.rows)

    def to_dict(self) -> dict[str, Any]:
        """Rows and the trial metrics for JSON (no time series)."""
        return {
            "standard": "IMO MSC.137(76), explanatory notes MSC/Circ.1053",
            "model": self.model,
            "vessel": self.particulars.vessel,
            "length_m": self.particulars.length,
            "speed_m_s": self.particulars.speed,
            "length_over_speed_s": _num(self.particulars.length_over_speed),
            "passed": self.passed,
            "rows": [row.to_dict() for row in self.rows],
            "turning": [t.to_dict(include_series=False) for t in self.turning],
            "initial_turning": [i.to_dict() for i in self.initial],
            "zigzag_10_10": [z.to_dict(include_series=False) for z in self.zigzag_10],
            "zigzag_20_20": [z.to_dict(include_series=False) for z in self.zigzag_20],
        }


def imo_criteria(
    model: ModelLike = "nomoto1",
    sides: Sequence[str] = SIDES,
    dt: float | None = None,
    progress: Progress = None,
) -> IMOReport:
    """Run the trials of MSC.137(76) to each side and check the criteria.

    Runs a 35 deg turning circle, the 10 deg initial turning test, and 10/10 and 20/20
    zigzags (first rudder to each side); each criterion takes the worse side.

    Parameters
    ----------
    model : str or ShipModel
        Model name or model.
    sides : sequence of {"starboard", "port"}
        Sides to test (both by default).
    dt : float, optional
        Integration step [s].
    progress : callable, optional
        Called with a one-line message after each trial.

    Returns
    -------
    IMOReport
    """
    if not sides:
        raise ValueError(f"sides must name at least one of {SIDES}, got {sides!r}")
    for side in sides:
        _side_sign(side)
    rig = _Rig(model, dt)
    ship = rig.ship
    say = progress or (lambda msg: None)
    turning, initial, z10, z20 = [], [], [], []
    for side in sides:
        turning.append(turning_circle(ship, 35.0, side, dt=rig.dt))
        say(f"turning circle 35 deg to {side}: done")
        initial.append(initial_turning(ship, 10.0, 10.0, side, dt=rig.dt))
        say(f"initial turning 10 deg to {side}: done")
        z10.append(zigzag(ship, 10.0, 10.0, side, n_reversals=2, dt=rig.dt))
        say(f"zigzag 10/10 {side} first: done")
        z20.append(zigzag(ship, 20.0, 20.0, side, n_reversals=1, dt=rig.dt))
        say(f"zigzag 20/20 {side} first: done")
    rows = imo_rows(rig.particulars, turning, initial, z10 + z20)
    return IMOReport(
        model=rig.name,
        particulars=rig.particulars,
        rows=tuple(rows),
        turning=tuple(turning),
        initial=tuple(initial),
        zigzag_10=tuple(z10),
        zigzag_20=tuple(z20),
    )


def format_imo_table(rows: Sequence[IMORow] | IMOReport, title: str | None = None) -> str:
    """A plain-text pass/fail table of MSC.137(76) rows."""
    if isinstance(rows, IMOReport):
        p = rows.particulars
        title = title or (
            f"IMO MSC.137(76) manoeuvring criteria: {p.vessel} ({rows.model}), "
            f"L = {p.length:g} m, U = {p.speed:g} m/s, L/U = {p.length_over_speed:.1f} s"
        )
        if p.length < 100.0:
            title += "\n(the Standards apply to ships of 100 m and more: informative only)"
        rows = rows.rows
    header = ("criterion", "value", "limit", "result", "worst case")
    body = []
    for row in rows:
        value = "not checked" if not math.isfinite(row.value) else f"{row.value:.2f} {row.unit}"
        body.append(
            (
                row.criterion,
                value,
                f"<= {row.limit:.2f} {row.unit}",
                "PASS" if row.passed else "FAIL",
                row.detail,
            )
        )
    widths = [max(len(r[i]) for r in (header, *body)) for i in range(len(header))]
    lines = [title] if title else []
    lines.append("  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)).rstrip())
    lines.append("  ".join("-" * w for w in widths))
    for r in body:
        lines.append("  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip())
    if not body:
        lines.append("(no IMO criterion applies to these trials)")
    return "\n".join(lines)


def print_imo_table(
    rows: Sequence[IMORow] | IMOReport, title: str | None = None, file: TextIO | None = None
) -> None:
    """Print :func:`format_imo_table` (to ``file``, stdout by default)."""
    print(format_imo_table(rows, title), file=file)


# ------------------------------------------------------------------------------------------
# plots
# ------------------------------------------------------------------------------------------
def _new_figure(size: tuple[float, float]) -> Figure:
    fig = Figure(figsize=size, dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _title(model: str, particulars: ShipParticulars, what: str) -> str:
    return f"{what}: {particulars.vessel}, {_MODEL_LABELS.get(model, model)} model ({model})"


def _save(fig: Figure, path: str | Path) -> Path:
    out = Path(path)
    fig.savefig(out)
    return out


def _rudder_label(model: str) -> str:
    if model == "rvg3dof":
        return r"equivalent rudder $\delta = -\alpha$"
    return r"rudder angle $\delta$"


def plot_zigzag(result: ZigZagResult, path: str | Path) -> Path:
    """Heading change and rudder angle against time with the overshoots marked; a PNG.

    When the heading change dwarfs the rudder angle (an unstable ship), the rudder is drawn
    on its own axis at the right. A swing that was never checked is shown until it has gone a
    full circle beyond the check heading.
    """
    sr = result.series
    t = sr.time
    h = np.degrees(sr.psi - sr.psi[0])
    delta = np.degrees(sr.delta)
    cmd = np.degrees(sr.delta_c)
    a, b = math.degrees(result.rudder), math.degrees(result.heading_check)
    s0 = _side_sign(result.first)
    n = len(t)
    if not result.completed and result.execute_times:
        k = len(result.overshoots) - 1 if result.overshoots else 0
        s_k = s0 if k % 2 == 0 else -s0
        t_k = result.execute_times[min(k, len(result.execute_times) - 1)]
        beyond = np.nonzero((t >= t_k) & (s_k * h - b > 360.0))[0]
        if len(beyond):
            n = min(n, int(beyond[0]) + 1)
    t, h, delta, cmd = t[:n], h[:n], delta[:n], cmd[:n]

    fig = _new_figure((10.5, 5.8))
    ax = fig.add_subplot()
    span = max(float(np.max(np.abs(h))), a, b)
    separate = span > 3.0 * max(a, b)
    ax_d = ax.twinx() if separate else ax
    ax.axhline(0.0, color="black", lw=0.6)
    for level in (b, -b):
        ax.axhline(level, color=_GREY, lw=0.8, ls=":")
    ax.plot(t, h, color=_BLUE, lw=2.0, label=r"heading change $\psi - \psi_0$", zorder=3)
    rudder = _rudder_label(result.model) + (" (right axis)" if separate else "")
    ax_d.plot(t, cmd, color=_ORANGE, lw=1.0, ls="--", alpha=0.8, label=r"rudder command $\delta_c$")
    ax_d.plot(t, delta, color=_ORANGE, lw=1.8, label=rudder)
    for i, te in enumerate(result.execute_times):
        ax.axvline(te, color=_GREY, lw=0.6, alpha=0.6, label="rudder reversal" if i == 0 else None)
    for k, (ov, tp) in enumerate(zip(result.overshoots_deg, result.overshoot_times, strict=True)):
        if not math.isfinite(ov):
            continue
        s = s0 if k % 2 == 0 else -s0
        check = s * b
        peak = check + s * ov
        ax.annotate(
            "",
            xy=(tp, peak),
            xytext=(tp, check),
            arrowprops={"arrowstyle": "<->", "color": _RED, "lw": 1.3, "shrinkA": 0, "shrinkB": 0},
        )
        ax.plot([tp], [peak], "o", color=_RED, ms=4)
        ordinal = ("1st", "2nd", "3rd")[k] if k < 3 else f"{k + 1}th"
        near_end = tp > t[0] + 0.85 * (t[-1] - t[0])
        ax.annotate(
            f"{ordinal} overshoot\n{ov:.1f}°",
            xy=(tp, peak),
            xytext=(-7 if near_end else 7, 5 * s),
            textcoords="offset points",
            ha="right" if near_end else "left",
            va="bottom" if s > 0 else "top",
            fontsize=9,
            color=_RED,
        )
    ax.set_ylim(-1.3 * span, 1.3 * span)
    if separate:
        ax_d.set_ylim(-1.3 * 3.0 * a, 1.3 * 3.0 * a)
        ax_d.set_ylabel("rudder angle [deg]", color=_ORANGE)
        ax_d.tick_params(axis="y", colors=_ORANGE)
    ax.set_xlim(t[0], t[-1])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("heading change [deg]" if separate else "angle [deg]")
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if separate:
        h2, l2 = ax_d.get_legend_handles_labels()
        handles, labels = handles + h2, labels + l2
    ax.legend(handles, labels, loc="lower left", fontsize=8.5, framealpha=0.92, ncols=2)
    for level in (b, -b):
        ax.annotate(
            f"check {level:+g}°",
            xy=(1.0, level),
            xycoords=("axes fraction", "data"),
            xytext=(-4, 2 if level > 0 else -2),
            textcoords="offset points",
            ha="right",
            va="bottom" if level > 0 else "top",
            fontsize=7.5,
            color=_GREY,
        )
    lines = [
        f"initial turning time {result.initial_turning_time:.1f} s",
        f"time to check yaw {result.time_to_check_yaw:.1f} s",
    ]
    if math.isfinite(result.period):
        lines.append(f"period {result.period:.1f} s")
    if not result.completed:
        lines.append("last swing NOT checked: the ship keeps turning")
    ax.text(
        0.99,
        0.98,
        "\n".join(lines),
        transform=ax.transAxes,
        ha="right",
        va="top",
        fontsize=8.5,
        bbox={"boxstyle": "round,pad=0.35", "fc": "white", "ec": _GREY, "alpha": 0.92},
        zorder=10,
    )
    ax.set_title(
        _title(result.model, result.particulars, f"Zigzag {result.label} ({result.first} first)")
        + f", U = {result.approach_speed:.2f} m/s",
        fontsize=11,
    )
    return _save(fig, path)


def _hull(north: float, east: float, psi: float, length: float, beam: float) -> np.ndarray:
    """Plan-view hull outline, columns (east, north)."""
    fwd = np.array([0.5, 0.3, -0.45, -0.5, -0.5, -0.45, 0.3]) * length
    stb = np.array([0.0, 0.5, 0.5, 0.4, -0.4, -0.5, -0.5]) * beam
    c, s = math.cos(psi), math.sin(psi)
    return np.column_stack([east + fwd * s + stb * c, north + fwd * c - stb * s])


def _dimension(
    ax: Any,
    p0: tuple[float, float],
    p1: tuple[float, float],
    text: str,
    color: str,
    offset: tuple[float, float] = (0, 0),
    rotation: float = 0.0,
) -> None:
    """A two-headed dimension arrow between (east, north) points with a label."""
    ax.annotate(
        "",
        xy=p1,
        xytext=p0,
        arrowprops={
            "arrowstyle": "<|-|>",
            "color": color,
            "lw": 1.4,
            "shrinkA": 0,
            "shrinkB": 0,
            "mutation_scale": 10,
        },
        zorder=6,
    )
    mid = (0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1]))
    ax.annotate(
        text,
        xy=mid,
        xytext=offset,
        textcoords="offset points",
        ha="center",
        va="center",
        rotation=rotation,
        fontsize=9,
        color=color,
        fontweight="bold",
        bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
        zorder=7,
    )


def plot_turning_circle(result: TurningResult, path: str | Path) -> Path:
    """Track with advance, transfer, tactical and steady diameter; r, speed, rudder vs time."""
    sr = result.series
    L = result.particulars.length
    s = _side_sign(result.side)
    east, north = sr.y, sr.x
    h = s * (sr.psi - sr.psi[0])
    fig = _new_figure((13.0, 6.8))
    grid = fig.add_gridspec(3, 2, width_ratios=(1.25, 1.0))
    ax = fig.add_subplot(grid[:, 0])
    ax_r = fig.add_subplot(grid[0, 1])
    ax_v = fig.add_subplot(grid[1, 1], sharex=ax_r)
    ax_d = fig.add_subplot(grid[2, 1], sharex=ax_r)

    # --- track ---------------------------------------------------------------------------
    first = np.nonzero(h <= 2 * math.pi)[0]
    n_first = int(first[-1]) + 1 if len(first) else len(h)
    ax.plot(
        east[n_first - 1 :],
        north[n_first - 1 :],
        color=_BLUE,
        lw=0.8,
        alpha=0.35,
        label="track after the first 360°",
    )
    ax.plot(east[:n_first], north[:n_first], color=_BLUE, lw=2.0, label="track (first 360°)")
    cn, ce = result.steady_center
    ax.add_patch(
        Circle(
            (ce, cn),
            0.5 * result.steady_diameter,
            fill=False,
            ec=_PURPLE,
            lw=1.3,
            ls="--",
            zorder=4,
        )
    )
    ax.plot(
        [],
        [],
        color=_PURPLE,
        lw=1.3,
        ls="--",
        label=f"steady circle, D = {result.steady_diameter:.0f} m "
        f"({result.steady_diameter / L:.2f} L)",
    )
    hull_len, hull_beam = L, result.particulars.beam
    for target in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi):
        cross = _crossing(h, target)
        if cross is None:
            continue
        poly = _hull(_at(north, cross), _at(east, cross), _at(sr.psi, cross), hull_len, hull_beam)
        ax.add_patch(
            Polygon(poly, closed=True, fc="#e3e9f2", ec="#8aa6c9", lw=0.8, alpha=0.7, zorder=1.5)
        )
    ax.plot(
        [],
        [],
        marker=(5, 0, 0),
        ls="none",
        mfc="#e3e9f2",
        mec="#8aa6c9",
        label="hull (true scale) at 0, 90, 180, 270°",
    )
    n0, e0 = result.points["execute"]
    n90, e90 = result.points["heading_90"]
    n180, e180 = result.points["heading_180"]
    # approach course line
    extent = max(result.advance, result.tactical_diameter, result.steady_diameter, L)
    ax.plot(
        [e0, e0],
        [n0 - 0.35 * extent, n0 + 1.15 * result.advance],
        color=_GREY,
        lw=0.8,
        ls="-.",
        zorder=1,
    )
    ax.plot(
        [e0, e0], [n0 - 0.35 * extent, n0], color=_GREY, lw=2.0, zorder=2, label="approach course"
    )
    ax.plot([e0], [n0], "o", color=_GREEN, ms=7, zorder=8, label="rudder execute")
    for (n_, e_), lab in (((n90, e90), "90°"), ((n180, e180), "180°")):
        ax.plot([e_], [n_], "D", color=_RED, ms=5, zorder=8)
        ax.annotate(
            lab,
            xy=(e_, n_),
            xytext=(6 * s, 6),
            textcoords="offset points",
            fontsize=8.5,
            color=_RED,
            ha="left" if s > 0 else "right",
        )
    # advance: along the approach course, at the 90 deg point's lateral offset (outside)
    pad = 0.12 * extent
    e_adv = e0 - s * pad
    ax.plot([e_adv - s * 0.03 * extent, e90], [n90, n90], color=_RED, lw=0.6, ls=":")
    _dimension(
        ax,
        (e_adv, n0),
        (e_adv, n90),
        f"advance\n{result.advance:.0f} m\n{result.advance / L:.2f} L",
        _RED,
        offset=(-34 * s, 0),
    )
    # transfer: across, at the 90 deg point's north
    n_tr = n90 + pad
    ax.plot([e90, e90], [n90, n_tr + 0.03 * extent], color=_RED, lw=0.6, ls=":")
    _dimension(
        ax,
        (e0, n_tr),
        (e90, n_tr),
        f"transfer {result.transfer:.0f} m ({result.transfer / L:.2f} L)",
        _RED,
        offset=(0, 11),
    )
    # tactical diameter: across at the 180 deg point, below the track
    n_td = min(float(np.min(north[:n_first])), n180) - pad
    ax.plot([e180, e180], [n180, n_td - 0.03 * extent], color=_ORANGE, lw=0.6, ls=":")
    ax.plot([e0, e0], [n0, n_td - 0.03 * extent], color=_ORANGE, lw=0.6, ls=":")
    _dimension(
        ax,
        (e0, n_td),
        (e180, n_td),
        f"tactical diameter {result.tactical_diameter:.0f} m"
        f" ({result.tactical_diameter / L:.2f} L)",
        _ORANGE,
        offset=(0, -11),
    )
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.09), ncols=3, fontsize=8, framealpha=0.92)
    ax.margins(0.08)
    ax.set_title(
        f"{math.degrees(result.rudder):g}° rudder to {result.side}, approach "
        f"{result.approach_speed:.2f} m/s, L = {L:g} m",
        fontsize=10,
    )

    # --- time histories (seed 002 phases) -------------------------------------------------
    t = sr.time
    t_end = min(t[-1], max(3.0 * result.steady_time, result.time_to_180 * 2.5, 60.0))
    for axis in (ax_r, ax_v, ax_d):
        axis.axvspan(0.0, result.rudder_time, color=_ORANGE, alpha=0.10, lw=0)
        axis.axvspan(result.rudder_time, result.steady_time, color=_BLUE, alpha=0.06, lw=0)
        axis.axvspan(result.steady_time, t_end, color=_GREEN, alpha=0.08, lw=0)
        axis.grid(True, alpha=0.3)
    ax_r.plot(t, np.degrees(sr.r), color=_BLUE, lw=1.6)
    ax_r.axhline(math.degrees(result.steady_yaw_rate), color=_GREY, lw=0.8, ls="--")
    ax_r.set_ylabel("yaw rate r\n[deg/s]")
    for t0_, t1_, lab in (
        (0.0, result.rudder_time, "1st"),
        (result.rudder_time, result.steady_time, "2nd phase"),
        (result.steady_time, t_end, "3rd phase (steady)"),
    ):
        if t1_ - t0_ < 0.06 * t_end * (len(lab) / 3):
            continue  # too narrow for its label
        x_ = 0.5 * (t0_ + t1_)
        ax_r.annotate(
            lab,
            xy=(x_, 0.1 if s > 0 else 0.9),
            xycoords=("data", "axes fraction"),
            ha="center",
            va="center",
            fontsize=8,
            color=_GREY,
        )
    ax_v.plot(t, sr.speed, color=_GREEN, lw=1.6)
    ax_v.axhline(result.approach_speed, color=_GREY, lw=0.8, ls="--")
    ax_v.set_ylabel("speed [m/s]")
    ax_v.set_title(
        f"steady speed {result.steady_speed:.2f} m/s = {100 * result.speed_ratio:.0f} % of "
        f"approach, steady r = {math.degrees(result.steady_yaw_rate):+.2f} deg/s",
        fontsize=9,
    )
    ax_v.set_ylim(0.0, 1.1 * max(result.approach_speed, float(np.max(sr.speed))))
    ax_d.plot(t, np.degrees(sr.delta), color=_ORANGE, lw=1.6)
    ax_d.set_ylabel(
        _rudder_label(result.model).replace("equivalent rudder", "equiv. rudder") + "\n[deg]"
    )
    ax_d.set_xlabel("time [s]")
    ax_r.set_xlim(0.0, t_end)
    for axis in (ax_r, ax_v):
        axis.tick_params(labelbottom=False)
    ax_r.set_title("phases (seed 002): 1st rudder moving, 2nd transient, 3rd steady", fontsize=9)
    fig.suptitle(_title(result.model, result.particulars, "Turning circle"), fontsize=11.5)
    return _save(fig, path)


def plot_pullout(result: PullOutResult, path: str | Path) -> Path:
    """Yaw rate (and rudder) against time around the pull-out; a PNG."""
    sr = result.series
    t = sr.time
    fig = _new_figure((10.5, 6.0))
    grid = fig.add_gridspec(2, 1, height_ratios=(2.2, 1.0))
    ax = fig.add_subplot(grid[0])
    ax_d = fig.add_subplot(grid[1], sharex=ax)
    r = np.degrees(sr.r)
    ax.axhline(0.0, color="black", lw=0.6)
    ax.axvline(result.pullout_time, color=_GREY, lw=1.0, ls="--")
    ax.plot(t, r, color=_BLUE, lw=1.8, label="yaw rate r")
    ax.axhline(
        math.degrees(result.turn_yaw_rate),
        color=_GREY,
        lw=0.8,
        ls=":",
        label=f"steady turn {math.degrees(result.turn_yaw_rate):+.3f} deg/s",
    )
    res = math.degrees(result.residual_yaw_rate)
    ax.axhline(res, color=_RED, lw=1.2, ls="--", label=f"residual {res:+.4f} deg/s")
    ax.annotate(
        "rudder amidships",
        xy=(result.pullout_time, 0.0),
        xytext=(5, 8),
        textcoords="offset points",
        fontsize=8.5,
        color=_GREY,
    )
    verdict = (
        "stable: r decays to zero" if result.stable else "UNSTABLE: residual yaw rate (spiral loop)"
    )
    extra = (
        f", decay to 1/e in {result.decay_time:.0f} s"
        if result.stable and math.isfinite(result.decay_time)
        else ""
    )
    ax.set_title(
        _title(
            result.model,
            result.particulars,
            f"Pull-out after {math.degrees(result.rudder):g}° to {result.side}",
        )
        + f"\n{verdict}{extra}",
        fontsize=11,
    )
    ax.set_ylabel("yaw rate r [deg/s]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8.5, framealpha=0.92)
    ax.tick_params(labelbottom=False)
    ax_d.axhline(0.0, color="black", lw=0.6)
    ax_d.axvline(result.pullout_time, color=_GREY, lw=1.0, ls="--")
    ax_d.plot(t, np.degrees(sr.delta), color=_ORANGE, lw=1.6)
    ax_d.set_ylabel(
        _rudder_label(result.model).replace("equivalent rudder", "equiv. rudder") + "\n[deg]"
    )
    ax_d.set_xlabel("time [s]")
    ax_d.grid(True, alpha=0.3)
    ax.set_xlim(t[0], t[-1])
    return _save(fig, path)


def plot_spiral(results: SpiralResult | Sequence[SpiralResult], path: str | Path) -> Path:
    """The steady delta-r curve of one or more spirals (seed 004 Fig. 1); a PNG."""
    items = [results] if isinstance(results, SpiralResult) else list(results)
    if not items:
        raise ValueError("plot_spiral needs at least one SpiralResult")
    fig = _new_figure((9.0, 6.6))
    ax = fig.add_subplot()
    ax.axhline(0.0, color="black", lw=0.6)
    ax.axvline(0.0, color="black", lw=0.6)
    notes = []
    for res in items:
        d, r = np.degrees(res.rudder), np.degrees(res.yaw_rate)
        if res.kind == "direct":
            for leg, color, marker, name in (
                ("down", _BLUE, "v", "starboard to port"),
                ("up", _ORANGE, "^", "port to starboard"),
            ):
                m = np.array([g == leg for g in res.leg])
                if not m.any():
                    continue
                ax.plot(
                    d[m],
                    r[m],
                    color=color,
                    lw=1.2,
                    marker=marker,
                    ms=6,
                    alpha=0.9,
                    label=f"direct spiral (Dieudonné), {name}",
                )
            bad = ~res.steady
            if bad.any():
                ax.plot(d[bad], r[bad], "x", color=_RED, ms=8, label="not settled")
        else:
            ok = ~res.saturated
            order = np.argsort(r)
            ok_o = ok[order]
            ax.plot(
                d[order][ok_o],
                r[order][ok_o],
                color=_GREEN,
                lw=1.4,
                marker="o",
                ms=5,
                mfc="white",
                label="reverse spiral (Bech), PI on r",
            )
            if (~ok).any():
                ax.plot(d[~ok], r[~ok], "s", color=_GREY, ms=5, label="rudder saturated")
        notes.append(
            f"{res.kind}: "
            + (
                f"hysteresis, loop width ≈ {math.degrees(res.loop_width):.1f}°"
                if res.hysteresis
                else "no hysteresis (stable)"
            )
        )
    if any(res.hysteresis for res in items):
        widths = [res for res in items if res.hysteresis]
        w = max(math.degrees(res.loop_width) for res in widths)
        ax.axvspan(
            -0.5 * w, 0.5 * w, color=_RED, alpha=0.06, lw=0, label="instability loop (width)"
        )
    ax.set_xlabel(
        r"rudder angle $\delta$ [deg]"
        + ("  (equivalent: minus the pod azimuth)" if items[0].model == "rvg3dof" else "")
    )
    ax.set_ylabel("steady yaw rate r [deg/s]  (+ = starboard)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8.5, framealpha=0.92)
    ax.text(
        0.99,
        0.02,
        "\n".join(notes),
        transform=ax.transAxes,
        ha="right",
        va="bottom",
        fontsize=8.5,
        bbox={"boxstyle": "round,pad=0.35", "fc": "white", "ec": _GREY, "alpha": 0.92},
    )
    res0 = items[0]
    ax.set_title(
        _title(res0.model, res0.particulars, "Spiral test, the δ-r curve")
        + f"\napproach {res0.approach_speed:.2f} m/s",
        fontsize=11,
    )
    return _save(fig, path)


def plot_imo(report: IMOReport, path: str | Path) -> Path:
    """Each MSC.137(76) criterion as value / limit (bar), pass below 1; a PNG."""
    rows = list(report.rows)
    fig = _new_figure((10.5, 0.65 * len(rows) + 2.2))
    ax = fig.add_subplot()
    ratios = [row.value / row.limit if math.isfinite(row.value) else math.nan for row in rows]
    cap = 2.0  # bars beyond twice the limit are cut and marked "off scale"
    y = np.arange(len(rows))[::-1]
    for yi, row, q in zip(y, rows, ratios, strict=True):
        color = _GREEN if row.passed else _RED
        off = not math.isfinite(q) or q > cap
        width = cap if off else q
        ax.barh(yi, width, color=color, alpha=0.75, height=0.6, ec=color)
        if off:
            ax.plot([cap], [yi], marker=">", color=color, ms=9, clip_on=False)
        value = "not checked" if not math.isfinite(row.value) else f"{row.value:.2f} {row.unit}"
        scale = f" = {q:.1f} x" if math.isfinite(q) and q > cap else " vs"
        ax.annotate(
            f"{value}{scale} limit {row.limit:.2f} {row.unit}: {'PASS' if row.passed else 'FAIL'}",
            xy=(width, yi),
            xytext=(8, 0),
            textcoords="offset points",
            va="center",
            fontsize=8.5,
            color="black",
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
        )
    ax.axvline(1.0, color="black", lw=1.2, ls="--", zorder=0)
    ax.set_yticks(y, [row.criterion.replace(": ", ":\n", 1) for row in rows], fontsize=9)
    ax.set_xlim(0.0, 3.5)
    ax.set_xlabel("value / IMO limit  (pass < 1)")
    ax.grid(True, axis="x", alpha=0.3)
    p = report.particulars
    note = "" if p.length >= 100.0 else " (L < 100 m: informative only)"
    fig.suptitle(
        f"IMO MSC.137(76): {p.vessel} ({report.model}), L = {p.length:g} m, U = {p.speed:g} m/s, "
        f"L/U = {p.length_over_speed:.1f} s{note}\noverall: "
        f"{'PASS' if report.passed else 'FAIL'} (worst of starboard and port)",
        fontsize=10.5,
    )
    return _save(fig, path)

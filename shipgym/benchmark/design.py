r"""Heading autopilot for an identified Nomoto-family ship, verified in simulation.

``shipgym design MODEL.json`` and :func:`design_heading_autopilot`: given a Nomoto-family
:class:`~shipgym.models.ShipModel` (``nomoto1``, ``nomoto2``, ``norrbin``, ``bech``; e.g. the
one ``shipgym identify --json`` fitted), design the heading autopilot by the same rule as the
classic policy of ``shipgym/NomotoHeading-v0``
(:func:`shipgym.benchmark.policies.nomoto_heading_autopilot`) and check it.

Design (seed 004 eq. 7; Fossen 2011, the PID pole placement for the Nomoto model):

1. The ship's yaw response linearised about straight running
   (:func:`~shipgym.benchmark.policies.nomoto_linear_yaw`),

   .. math:: \frac{r}{\delta}(s) = \frac{K (1 + T_3 s)}{T_1 T_2 s^2 + (T_1 + T_2) s + n_1}

   (first-order Nomoto and Norrbin: ``T2 = T3 = 0``; Bech: ``n1 = K b1``).
2. The first-order design model ``K_e / (1 + T_e s)`` (:func:`controllers.design_model`): the
   identified ``K / n1``, ``T / n1`` of a first-order ship; for a second-order ship the model
   that matches the response **at the design bandwidth**, never the low-frequency reduction
   ``T = (T1 + T2) / n1 - T3``, which is small or negative when the zero is slow (seed 004's
   ship, eq. 6, gets ``T = -40 s``: a stable ship designed as an unstable one).
3. The bandwidth (:func:`controllers.default_bandwidth`, Fossen's rule
   ``1 / |T_e| < w_n < 1 / T_a``): ``w_n = sqrt(1 / (|T_e| T_a))`` with ``T_a`` the larger of
   the steering gear's time constant and its full-scale slew time ``max_angle / max_rate``,
   found together with the matched model by a fixed-point iteration; damping ``zeta`` 0.8.
4. The PID gains by exact pole placement (:func:`controllers.pid_gains_nomoto`: poles at
   ``-zeta w_n +- j w_n sqrt(1 - zeta^2)`` and ``-w_n / 10`` for the design model), the
   third-order reference model at ``w_n``, the gear's limits as the command limits and the
   rudder trim (``n0 / K`` of Norrbin's model, ``b0`` of Bech's) as the offset ``b0``.

A ship the design cannot serve is refused (``ValueError`` naming why): a gain ``K <= 0`` (under
the Nomoto sign a positive rudder gives a positive yaw rate, so ``K > 0``; a fit with ``K <= 0``
found no rudder response or the record's rudder sign is reversed, and pole placement on it
gives gains of the wrong sign), or non-finite parameters. ``shipgym design`` also refuses an
identification whose verdict is "not identifiable".

Verification:

* Margins of the open loop ``L(s) e^{-s tau}``, ``L = C(s) P(s)`` with
  ``C = K_p + K_i / s + K_d s`` and the identified ship's linear plant
  ``P = r/delta / (s (1 + T_delta s))`` behind the steering gear's time constant and the
  rudder's transport delay ``tau`` (the model's ``input_delay``):
  :func:`controllers.heading.loop_margins` (python-control's crossovers, the delay exactly:
  ``PM_tau = PM_0 - w_c tau``, delay margin ``PM_tau / w_c``). Closed-loop stability with the
  delay from an order-8 Padé approximant (:func:`control.pade`).
* The linear step response ``psi / psi_ref`` (reference model times ``L / (1 + L)``) by
  :func:`control.step_info`.
* Heading steps (10 and 30 deg by default) from straight running at the service speed,
  simulated on the identified (nonlinear) model with :meth:`ShipModel.simulate` and the
  autopilot built from the gains document in the loop
  (:func:`~shipgym.benchmark.policies.heading_autopilot_from_gains`, the object that
  ``shipgym evaluate --gains`` runs): rise time (10 to 90 %), overshoot, 2 % settling time,
  peak rudder and yaw rate.
* The open-loop ship's 20/20 zigzag (:func:`shipgym.maneuvers.zigzag`).

Angles are radians and times seconds inside; ``to_dict`` and the table name degrees ``_deg``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import control
import numpy as np

from controllers import HeadingAutopilot, design_model
from controllers.heading import LoopMargins, loop_margins
from shipgym.benchmark.policies import (
    heading_autopilot_from_gains,
    heading_gains_document,
    nomoto_linear_yaw,
    steering_limits,
)
from shipgym.models import NOMOTO_MODEL_NAMES, ShipModel

if TYPE_CHECKING:
    from shipgym.maneuvers import ZigZagResult

__all__ = [
    "HeadingAutopilotDesign",
    "StepResponse",
    "check_designable",
    "design_heading_autopilot",
    "plot_heading_design",
]

#: Order of the Padé approximant of the delay in the closed-loop poles and the linear step.
PADE_ORDER = 8
#: Settling band of the step responses (fraction of the step).
SETTLING_BAND = 0.02
#: What the other models of :data:`shipgym.models.MODEL_NAMES` are (for the refusal).
_NOT_NOMOTO = {
    "rvg3dof": "the 3-DOF model of R/V Gunnerus",
    "kvlcc2": "a 3-DOF MMG manoeuvring model",
    "vmm": "a 3-DOF VMM manoeuvring model",
}


@dataclass(frozen=True, eq=False)
class StepResponse:
    """A simulated closed-loop heading step from straight running (SI units, radians).

    Attributes
    ----------
    step : float
        Heading change asked for [rad].
    time : numpy.ndarray
        Time [s].
    psi, psi_d, r, delta, delta_c : numpy.ndarray
        Heading [rad, from 0], the reference model's heading [rad], yaw rate [rad/s], rudder
        angle and rudder command [rad] (the command held over each step, the last repeated).
    rise_time : float
        From 10 % to 90 % of the step [s] (``nan`` if never reached).
    overshoot : float
        Heading beyond the step [rad] (>= 0).
    settling_time : float
        Time [s] after which the heading stays within 2 % of the step (``nan`` if it does
        not within the run).
    peak_rudder : float
        Largest ``|delta|`` [rad].
    peak_yaw_rate : float
        Largest ``|r|`` [rad/s].
    final_error : float
        ``step - psi`` at the end [rad].
    """

    step: float
    time: np.ndarray
    psi: np.ndarray
    psi_d: np.ndarray
    r: np.ndarray
    delta: np.ndarray
    delta_c: np.ndarray
    rise_time: float
    overshoot: float
    settling_time: float
    peak_rudder: float
    peak_yaw_rate: float
    final_error: float

    @property
    def overshoot_percent(self) -> float:
        """Overshoot as a percentage of the step."""
        return 100.0 * self.overshoot / abs(self.step)

    def to_dict(self) -> dict[str, float | None]:
        """Metrics for JSON (degrees in ``*_deg`` keys, ``None`` for not reached)."""
        return {
            "step_deg": _num(round(math.degrees(self.step), 9)),
            "rise_time_s": _num(self.rise_time),
            "overshoot_deg": _num(math.degrees(self.overshoot)),
            "overshoot_percent": _num(self.overshoot_percent),
            "settling_time_s": _num(self.settling_time),
            "peak_rudder_deg": _num(math.degrees(self.peak_rudder)),
            "peak_yaw_rate_deg_s": _num(math.degrees(self.peak_yaw_rate)),
            "final_error_deg": _num(math.degrees(self.final_error)),
            "duration_s": _num(float(self.time[-1])),
        }


@dataclass(frozen=True, eq=False)
class HeadingAutopilotDesign:
    """The heading autopilot of a Nomoto-family ship and its verification.

    Attributes
    ----------
    model : str
        The ship's model name.
    ship_parameters : dict
        Its yaw parameters (the model's parameter dataclass as a dict).
    gear : dict
        ``actuator_time_constant`` [s], ``max_command`` [rad], ``max_rate`` [rad/s].
    input_delay : float
        Transport delay [s] of the rudder command in the loop.
    K, T : float
        The first-order design model [1/s, s].
    design_method : str
        ``"as identified"`` (first-order ship) or ``"matched at the bandwidth"``.
    design_reason : str
        Why these ``K``, ``T`` (one sentence).
    low_frequency_T : float or None
        ``(T1 + T2) / n1 - T3`` of a second-order ship [s] (not used: the reason says why).
    omega_n, zeta : float
        Closed-loop natural frequency [rad/s] and damping.
    bandwidth_rule : bool
        ``omega_n`` from :func:`controllers.default_bandwidth` (not given).
    autopilot : controllers.HeadingAutopilot
        The designed autopilot (its :attr:`gains` are what the gains document holds).
    gains : dict
        The ``autopilot`` section of the gains document.
    design_poles, closed_loop_poles : numpy.ndarray
        The poles the pole placement asked for (design model) and those of the identified
        ship's linear loop without the delay (slowest first).
    stable : bool
        The linear closed loop with the delay (Padé) is stable.
    margins, margins_without_delay : LoopMargins
        Margins of the open loop with and without the input delay.
    loop : control.TransferFunction
        The delay-free open loop ``L = C P``.
    linear_step : dict
        ``rise_time_s``, ``settling_time_s``, ``overshoot_percent`` of the linear closed loop
        from ``psi_ref`` (reference model, delay by Padé); ``None`` values when unstable.
    steps : tuple of StepResponse
        The simulated heading steps.
    zigzag : shipgym.maneuvers.ZigZagResult or None
        The open-loop 20/20 zigzag (``None`` if not run).
    dt : float
        Step [s] of the simulations and sample time of the autopilot in them.
    notes : tuple of str
        Warnings and remarks (a small margin, a delay the simulation could not apply, ...).
    """

    model: str
    ship_parameters: dict[str, float]
    gear: dict[str, float]
    input_delay: float
    K: float
    T: float
    design_method: str
    design_reason: str
    low_frequency_T: float | None
    omega_n: float
    zeta: float
    bandwidth_rule: bool
    autopilot: HeadingAutopilot
    gains: dict[str, Any]
    design_poles: np.ndarray
    closed_loop_poles: np.ndarray
    stable: bool
    margins: LoopMargins
    margins_without_delay: LoopMargins
    loop: control.TransferFunction
    linear_step: dict[str, float | None]
    steps: tuple[StepResponse, ...]
    zigzag: ZigZagResult | None
    dt: float
    notes: tuple[str, ...] = field(default=())

    @property
    def kp(self) -> float:
        """Proportional gain [rad/rad]."""
        return self.autopilot.kp

    @property
    def ki(self) -> float:
        """Integral gain [rad/(rad s)]."""
        return self.autopilot.ki

    @property
    def kd(self) -> float:
        """Derivative (yaw-rate) gain [rad s/rad]."""
        return self.autopilot.kd

    def to_dict(self) -> dict[str, Any]:
        """The design as JSON-ready values (degrees in ``*_deg`` keys, ``None`` for non-finite
        numbers); the time series are in the figure, not here."""
        zz = None
        if self.zigzag is not None:
            zz = self.zigzag.to_dict(include_series=False)
            for key in ("vessel", "length_m", "length_over_speed_s"):
                zz.pop(key, None)  # the maneuver rig's particulars, not the identified ship's
        return {
            "model": self.model,
            "ship_parameters": {k: _num(v) for k, v in self.ship_parameters.items()},
            "gear": {
                "time_constant_s": self.gear["actuator_time_constant"],
                "max_angle_deg": math.degrees(self.gear["max_command"]),
                "max_rate_deg_s": math.degrees(self.gear["max_rate"]),
            },
            "input_delay_s": self.input_delay,
            "design_model": {
                "K_1_s": self.K,
                "T_s": self.T,
                "method": self.design_method,
                "low_frequency_T_s": _num(self.low_frequency_T),
                "reason": self.design_reason,
            },
            "omega_n_rad_s": self.omega_n,
            "zeta": self.zeta,
            "bandwidth": "rule" if self.bandwidth_rule else "given",
            "kp": self.kp,
            "ki": self.ki,
            "kd": self.kd,
            "reference_omega_rad_s": _num(self.gains["reference_omega"]),
            "design_poles": _poles(self.design_poles),
            "closed_loop_poles": _poles(self.closed_loop_poles),
            "stable": self.stable,
            "margins": self.margins.to_dict(),
            "margins_without_delay": self.margins_without_delay.to_dict(),
            "linear_step": dict(self.linear_step),
            "steps": [s.to_dict() for s in self.steps],
            "zigzag": zz,
            "dt_s": self.dt,
            "notes": list(self.notes),
        }

    def gains_document(self) -> dict[str, Any]:
        """The gains document (``shipgym design --json``) that ``shipgym evaluate --env
        shipgym/NomotoHeading-v0 --controller classic --gains FILE`` runs, with this design as
        its informative ``design`` section."""
        return heading_gains_document(self.autopilot, design=self.to_dict())

    def summary(self) -> str:
        """The gains, margins and step / zigzag metrics as a short table (``shipgym design``)."""
        deg = math.degrees
        p = ", ".join(f"{k} {v:.6g}" for k, v in self.ship_parameters.items())
        g = self.gear
        m = self.margins
        lines = [
            f"heading autopilot for {self.model} ({p})",
            f"  steering gear {deg(g['max_command']):.3g} deg, {deg(g['max_rate']):.3g} deg/s, "
            f"{g['actuator_time_constant']:.3g} s; input delay {self.input_delay:.3g} s",
            f"  design model   K {self.K:.4g} 1/s, T {self.T:.4g} s ({self.design_method})",
            f"  bandwidth      omega_n {self.omega_n:.4g} rad/s "
            f"({'rule' if self.bandwidth_rule else 'given'}), damping {self.zeta:.3g}, "
            f"reference model {_fmt(self.gains['reference_omega'], '.4g')} rad/s",
            f"  gains          Kp {self.kp:.4g}  Ki {self.ki:.4g} 1/s  Kd {self.kd:.4g} s"
            + (f"  offset {deg(self.gains['offset']):.3g} deg" if self.gains["offset"] else ""),
            f"  margins        gain {_fmt(m.gain_margin_db, '.3g')} dB"
            + (f" at {m.phase_crossover:.3g} rad/s" if math.isfinite(m.phase_crossover) else "")
            + f", phase {_fmt(m.phase_margin_deg, '.3g')} deg at "
            f"{_fmt(m.gain_crossover, '.3g')} rad/s, delay margin "
            f"{_fmt(m.delay_margin, '.3g')} s{'' if self.stable else '  UNSTABLE'}",
            "  step [deg]   rise [s]   overshoot [deg]   settling [s]   peak rudder [deg]",
        ]
        for s in self.steps:
            lines.append(
                f"  {deg(s.step):10.3g}   {_fmt(s.rise_time, '8.1f')}   "
                f"{deg(s.overshoot):15.2f}   {_fmt(s.settling_time, '12.1f')}   "
                f"{deg(s.peak_rudder):17.1f}"
            )
        ls = self.linear_step
        lines.append(
            f"  linear loop: rise {_fmt(ls['rise_time_s'], '.1f')} s, overshoot "
            f"{_fmt(ls['overshoot_percent'], '.2f')} %, settling "
            f"{_fmt(ls['settling_time_s'], '.1f')} s"
        )
        if self.zigzag is not None:
            z = self.zigzag
            over = ", ".join(_fmt(o, ".1f") for o in z.overshoots_deg[:2])
            lines.append(
                f"  zigzag {z.label} (open loop): overshoots {over} deg, initial turning time "
                f"{_fmt(z.initial_turning_time, '.1f')} s, period {_fmt(z.period, '.1f')} s"
                + ("" if z.completed else ", swing NOT checked")
            )
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def _num(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _fmt(value: float | None, spec: str) -> str:
    """``value`` formatted by ``spec``; ``-`` for none or NaN, ``inf`` for infinity."""
    if value is None or not math.isfinite(value):
        width = spec.rstrip("efgdEG%").split(".")[0]
        text = "-" if value is None or math.isnan(value) else ("inf" if value > 0 else "-inf")
        return format(text, f">{width}" if width else "")
    return format(value, spec)


def _poles(poles: np.ndarray) -> list[list[float]]:
    """Poles as ``[re, im]`` pairs (JSON has no complex numbers)."""
    return [[float(p.real), float(p.imag)] for p in poles]


def _check_model(model: Any) -> None:
    names = ", ".join(NOMOTO_MODEL_NAMES)
    if not isinstance(model, ShipModel):
        raise ValueError(
            f"the heading autopilot design takes a Nomoto-family ShipModel ({names}), "
            f"got {type(model).__name__}"
        )
    if model.name not in NOMOTO_MODEL_NAMES:
        what = _NOT_NOMOTO.get(model.name, "not a Nomoto-family model")
        raise ValueError(
            f"model {model.name!r} is {what}; the heading autopilot design takes a "
            f"Nomoto-family model ({names})"
        )


def check_designable(model: ShipModel) -> None:
    """Refuse a ship the design cannot serve (module docstring): not a Nomoto-family
    :class:`ShipModel`, non-finite parameters of its linear yaw response, or ``K <= 0``.

    Raises
    ------
    ValueError
        Naming the model and why.
    """
    _check_model(model)
    name = model.name
    values = dict(zip(("K", "T1", "T2", "T3", "n1"), nomoto_linear_yaw(model), strict=True))
    bad = [f"{k} = {v}" for k, v in values.items() if not math.isfinite(v)]
    if bad:
        raise ValueError(f"cannot design for {name}: non-finite parameters {', '.join(bad)}")
    K = values["K"]
    if K <= 0.0:
        raise ValueError(
            f"cannot design for {name} with K = {K:.4g} 1/s <= 0: under the Nomoto sign (a "
            "positive rudder gives a positive yaw rate) a ship has K > 0; an identification "
            "with K <= 0 found no rudder response (or the record's rudder sign is reversed), "
            "and the autopilot designed on it would steer the wrong way; identify the ship "
            "from a record that moves the rudder (zigzag, pull-out, random rudder)"
        )


def _trim(model: ShipModel) -> float:
    """Rudder angle [rad] that holds the ship straight (its rudder offset)."""
    y = model.params
    if model.name == "norrbin":
        trim = y.n0 / y.K
    elif model.name == "bech":
        trim = y.b0
    else:
        trim = 0.0
    assert model.gear is not None
    if abs(trim) >= model.gear.max_angle:
        raise ValueError(
            f"the ship needs {math.degrees(trim):.3g} deg of rudder to go straight, beyond its "
            f"{math.degrees(model.gear.max_angle):.3g} deg rudder limit"
        )
    return float(trim)


def _plant(
    K: float, T1: float, T2: float, T3: float, n1: float, ta: float
) -> control.TransferFunction:
    """``psi / delta_c`` of the linear ship behind a first-order steering gear."""
    yaw = control.tf([K * T3, K], [T1 * T2, T1 + T2, n1]) if T2 or T3 else control.tf([K], [T1, n1])
    return yaw * control.tf([1.0], [1.0, 0.0]) * control.tf([1.0], [ta, 1.0])


def _pade(tau: float) -> control.TransferFunction:
    if tau == 0.0:
        return control.tf([1.0], [1.0])
    num, den = control.pade(tau, PADE_ORDER)
    return control.tf(num, den)


def _design_reason(
    name: str,
    K: float,
    T1: float,
    T2: float,
    T3: float,
    n1: float,
    K_e: float,
    T_e: float,
    w: float,
) -> tuple[str, str, float | None]:
    """``(method, reason, low-frequency T)`` of the design model."""
    if T2 == 0.0 and T3 == 0.0:
        if n1 == 1.0:
            return "as identified", "the first-order model as identified: K_e = K, T_e = T", None
        return (
            "as identified",
            f"the linear part of Norrbin's model (n1 = {n1:.4g}): K_e = K / n1, T_e = T / n1",
            None,
        )
    t_low = (T1 + T2) / n1 - T3
    if t_low <= 0.0:
        why = (
            f"the low-frequency reduction (T1 + T2) / n1 - T3 = {t_low:.4g} s is not positive: "
            + (
                "it would design this stable ship as an unstable one"
                if n1 > 0
                else "its sign says nothing about the ship at the bandwidth"
            )
        )
    elif t_low < 0.5 * abs(T_e) or t_low < 0.25 * T1:
        why = (
            f"the low-frequency reduction (T1 + T2) / n1 - T3 = {t_low:.4g} s is small: the slow "
            "zero cancels most of the ship's lag there, not at the bandwidth"
        )
    else:
        why = (
            f"the low-frequency reduction (T1 + T2) / n1 - T3 = {t_low:.4g} s matches the "
            "response only well below the bandwidth"
        )
    reason = (
        f"{name}: the first-order model with the ship's response at the design bandwidth "
        f"{w:.4g} rad/s (K_e {K_e:.4g} 1/s, T_e {T_e:.4g} s); {why}"
    )
    return "matched at the bandwidth", reason, t_low


def _step_metrics(time: np.ndarray, psi: np.ndarray, step: float) -> tuple[float, ...]:
    """``(rise time, overshoot, settling time, final error)`` of a heading step."""
    y = psi / step
    above10, above90 = np.nonzero(y >= 0.1)[0], np.nonzero(y >= 0.9)[0]
    rise = float(time[above90[0]] - time[above10[0]]) if above90.size else math.nan
    overshoot = max(0.0, float(np.max(y)) - 1.0) * abs(step)
    outside = np.nonzero(np.abs(y - 1.0) > SETTLING_BAND)[0]
    if outside.size == 0:
        settling = 0.0
    elif outside[-1] == len(y) - 1:
        settling = math.nan  # not settled within the run
    else:
        settling = float(time[outside[-1] + 1])
    return rise, overshoot, settling, float(step - psi[-1])


def _simulate_step(
    model: ShipModel,
    gains: dict[str, Any],
    step: float,
    dt: float,
    n_steps: int,
    trim: float,
) -> StepResponse:
    """A heading step with the autopilot of ``gains`` in the loop (the model's
    ``input_delay`` applied by :meth:`ShipModel.simulate`)."""
    assert model.gear is not None and model.surge is not None
    ipsi, ir, idelta = model.index("psi"), model.index("r"), model.index("delta")
    x0 = np.zeros(model.nx)
    x0[model.index("U")] = model.surge.service_speed
    x0[idelta] = trim
    shaft = model.surge.service_shaft_speed
    pilot = heading_autopilot_from_gains(
        gains, dt, max_command=model.gear.max_angle, max_rate=model.gear.max_rate
    )
    pilot.reset(0.0, 0.0, t=0.0, command=trim)
    psi_d = np.zeros(n_steps + 1)

    def policy(t: float, x: np.ndarray) -> np.ndarray:
        k = round(t / dt)
        command = pilot.update(t, x[ipsi], x[ir], step)
        psi_d[k + 1] = pilot.reference.psi_d if pilot.reference is not None else step
        return np.array([command, shaft])

    sim = model.simulate(x0, policy, dt, n_steps)
    psi = sim["psi"]
    rise, overshoot, settling, final = _step_metrics(sim.time, psi, step)
    delta_c = np.append(sim.inputs[:, 0], sim.inputs[-1, 0])
    return StepResponse(
        step=step,
        time=sim.time,
        psi=psi,
        psi_d=psi_d,
        r=sim["r"],
        delta=sim["delta"],
        delta_c=delta_c,
        rise_time=rise,
        overshoot=overshoot,
        settling_time=settling,
        peak_rudder=float(np.max(np.abs(sim["delta"]))),
        peak_yaw_rate=float(np.max(np.abs(sim["r"]))),
        final_error=final,
    )


def _linear_step(
    loop: control.TransferFunction, pilot: HeadingAutopilot, tau: float, duration: float
) -> dict[str, float | None]:
    closed = control.feedback(loop * _pade(tau), 1)
    if pilot.reference is not None:
        closed = pilot.reference.transfer_function() * closed
    empty: dict[str, float | None] = dict.fromkeys(
        ("rise_time_s", "settling_time_s", "overshoot_percent")
    )
    if not np.all(np.real(control.poles(closed)) < 0):
        return empty
    t = np.linspace(0.0, duration, 4001)
    info = control.step_info(closed, T=t, SettlingTimeThreshold=SETTLING_BAND)
    return {
        "rise_time_s": _num(float(info["RiseTime"])),
        "settling_time_s": _num(float(info["SettlingTime"])),
        "overshoot_percent": _num(float(info["Overshoot"])),
    }


def _with_delay(model: ShipModel, input_delay: float | None) -> ShipModel:
    """``model``, or a copy with the rudder delay ``input_delay`` [s] when one is given (the
    simulations apply it through :meth:`ShipModel.simulate`)."""
    if input_delay is None:
        return model
    if isinstance(input_delay, bool) or not isinstance(input_delay, int | float):
        raise ValueError(f"input_delay must be a finite time >= 0 s, got {input_delay!r}")
    return dataclasses.replace(model, input_delay=input_delay)


def design_heading_autopilot(
    model: ShipModel,
    *,
    omega_n: float | None = None,
    zeta: float = 0.8,
    reference_ratio: float = 1.0,
    input_delay: float | None = None,
    steps_deg: Sequence[float] = (10.0, 30.0),
    zigzag: bool = True,
    dt: float | None = None,
    duration: float | None = None,
) -> HeadingAutopilotDesign:
    """Design the heading autopilot of a Nomoto-family ship and verify it (module docstring).

    Parameters
    ----------
    model : ShipModel
        ``nomoto1``, ``nomoto2``, ``norrbin`` or ``bech`` with its steering gear and surge
        model, e.g. :func:`shipgym.models.model_file.load_model` of a ``shipgym identify
        --json`` file (its ``input_delay`` is the identified rudder delay).
    omega_n : float, optional
        Closed-loop natural frequency [rad/s]; Fossen's rule from the steering gear and the
        ship by default (:func:`controllers.default_bandwidth`).
    zeta : float
        Closed-loop damping (0.8).
    reference_ratio : float
        Reference-model frequency as a multiple of ``omega_n`` (1; 0: no reference model).
    input_delay : float, optional
        Transport delay [s] of the rudder command; the model's :attr:`ShipModel.input_delay`
        by default.
    steps_deg : sequence of float
        Heading steps [deg] to simulate (non-zero, at most 180 in size).
    zigzag : bool
        Simulate the open-loop 20/20 zigzag.
    dt : float, optional
        Step [s] of the simulations and sample time of the autopilot: ``min(1, 0.1 / omega_n)``
        and at most half the model's stable step by default.
    duration : float, optional
        Length [s] of each step simulation; ``20 / (zeta omega_n)`` (at least 200 s) by
        default.

    Returns
    -------
    HeadingAutopilotDesign

    Raises
    ------
    ValueError
        For a model that is not a Nomoto-family :class:`ShipModel`, a gain ``K <= 0`` or
        non-finite parameters, bad design values, a ship that cannot hold a straight course
        within its rudder limit, or steps that are zero or beyond 180 deg.
    """
    check_designable(model)
    for name, value in (("omega_n", omega_n), ("zeta", zeta)):
        ok = value is None and name == "omega_n"
        ok = ok or (isinstance(value, int | float) and math.isfinite(value) and value > 0)
        if not ok:
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    model = _with_delay(model, input_delay)
    assert model.gear is not None and model.surge is not None
    tau = model.input_delay
    K, T1, T2, T3, n1 = nomoto_linear_yaw(model)
    limits = steering_limits(model)
    try:
        K_e, T_e, w = design_model(K, T1, T2, T3, n1=n1, omega=omega_n, **limits)
    except ValueError as exc:
        raise ValueError(f"no first-order design model for {model.name}: {exc}") from None
    method, reason, t_low = _design_reason(model.name, K, T1, T2, T3, n1, K_e, T_e, w)
    trim = _trim(model)
    pilot = HeadingAutopilot.from_nomoto(
        K_e,
        T_e,
        1.0,
        omega_n=w,
        zeta=zeta,
        reference_omega=reference_ratio * w,
        offset=trim,
        **limits,
    )
    gains = heading_gains_document(pilot)["autopilot"]

    loop = control.tf([pilot.kd, pilot.kp, pilot.ki], [1.0, 0.0]) * _plant(
        K, T1, T2, T3, n1, limits["actuator_time_constant"]
    )
    margins = loop_margins(loop, tau)
    margins0 = loop_margins(loop, 0.0) if tau > 0 else margins
    poles = np.asarray(control.poles(control.feedback(loop, 1)), dtype=complex)
    poles = poles[np.argsort(-poles.real)]
    delayed_poles = np.asarray(control.poles(control.feedback(loop * _pade(tau), 1)))
    stable = bool(np.all(delayed_poles.real < 0))

    if dt is None:
        stable_step = model.stable_step(np.zeros(model.nx), np.zeros(model.nu))
        dt = min(1.0, 0.1 / w, 0.5 * stable_step)
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a step > 0 s, got {dt!r}")
    if duration is None:
        duration = max(200.0, 20.0 / (zeta * w))
    if not (isinstance(duration, int | float) and math.isfinite(duration) and duration > dt):
        raise ValueError(f"duration must be a time longer than dt = {dt:g} s, got {duration!r}")
    n_steps = math.ceil(duration / dt)

    steps = []
    for a in steps_deg:
        if not (isinstance(a, int | float) and math.isfinite(a) and 0 < abs(a) <= 180):
            raise ValueError(f"a heading step must be in [-180, 180] deg and non-zero, got {a!r}")
        steps.append(_simulate_step(model, gains, math.radians(a), dt, n_steps, trim))

    zz = None
    if zigzag:
        from shipgym.maneuvers import zigzag as run_zigzag

        zz = run_zigzag(model, 20.0, 20.0, "starboard", 4)

    notes = []
    if not stable:
        notes.append("the linear closed loop is UNSTABLE: lower the bandwidth or check the model")
    elif margins.phase_margin_deg < 30.0:
        notes.append(
            f"phase margin {margins.phase_margin_deg:.3g} deg is below 30 deg: lower the bandwidth"
        )
    for s in steps:
        if s.peak_rudder >= model.gear.max_angle - 1e-6:
            notes.append(
                f"the {math.degrees(s.step):g} deg step uses the full rudder "
                f"({math.degrees(model.gear.max_angle):.3g} deg)"
            )
        if not math.isfinite(s.settling_time):
            notes.append(
                f"the {math.degrees(s.step):g} deg step does not settle within {duration:g} s"
            )

    return HeadingAutopilotDesign(
        model=model.name,
        ship_parameters={k: float(v) for k, v in dataclasses.asdict(model.params).items()},
        gear=limits,
        input_delay=tau,
        K=float(K_e),
        T=float(T_e),
        design_method=method,
        design_reason=reason,
        low_frequency_T=t_low,
        omega_n=float(w),
        zeta=float(zeta),
        bandwidth_rule=omega_n is None,
        autopilot=pilot,
        gains=gains,
        design_poles=pilot.design_poles.copy(),
        closed_loop_poles=poles,
        stable=stable,
        margins=margins,
        margins_without_delay=margins0,
        loop=loop,
        linear_step=_linear_step(loop, pilot, tau, 2.0 * duration),
        steps=tuple(steps),
        zigzag=zz,
        dt=float(dt),
        notes=tuple(notes),
    )


def plot_heading_design(design: HeadingAutopilotDesign, path: str | Path) -> Path:
    """The step responses (heading and reference), their rudder, and the open-loop zigzag,
    as a PNG (matplotlib, Agg canvas)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    deg = np.degrees
    rows = 3 if design.zigzag is not None else 2
    fig = Figure(figsize=(10.5, 3.0 * rows + 0.6), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, 1)
    colours = ("#1f5fa8", "#d9731a", "#2a8a4a", "#b8312f", "#7b4fa0")
    ax_h, ax_d = axes[0], axes[1]
    limit = deg(design.gear["max_command"])
    for i, s in enumerate(design.steps):
        c = colours[i % len(colours)]
        label = f"{deg(s.step):g} deg step"
        scale = 100.0 / s.step
        lw = 1.8 + 1.2 * (len(design.steps) - 1 - i)  # the curves of a linear loop coincide
        ax_h.plot(s.time, s.psi * scale, color=c, lw=lw, label=f"{label}: heading")
        ax_h.plot(s.time, s.psi_d * scale, color=c, lw=1.0, ls="--", label="reference model")
        if math.isfinite(s.settling_time):
            ax_h.axvline(s.settling_time, color=c, lw=0.8, alpha=0.6)
        ax_d.plot(s.time, deg(s.delta), color=c, lw=1.6, label=f"{label}: rudder")
        ax_d.plot(s.time, deg(s.delta_c), color=c, lw=0.8, ls="--", alpha=0.8, label="command")
    for level in (100.0 * (1.0 - SETTLING_BAND), 100.0 * (1.0 + SETTLING_BAND)):
        ax_h.axhline(level, color="#6b6b6b", lw=0.8, ls=":")
    peak = max((deg(s.peak_rudder) for s in design.steps), default=0.0)
    if peak > limit / 3.0:  # the limit is in view only when the rudder comes near it
        for level in (limit, -limit):
            ax_d.axhline(level, color="#6b6b6b", lw=0.8, ls=":")
    settled = [s.settling_time for s in design.steps if math.isfinite(s.settling_time)]
    if design.steps:
        end = float(design.steps[0].time[-1])
        if len(settled) == len(design.steps):
            end = min(end, max(2.0 * max(settled), 0.2 * end))
        for ax in (ax_h, ax_d):
            ax.set_xlim(0.0, end)
    m = design.margins
    ax_h.set_title(
        f"Heading autopilot for {design.model}: Kp {design.kp:.3g}, Ki {design.ki:.3g} 1/s, "
        f"Kd {design.kd:.3g} s; omega_n {design.omega_n:.3g} rad/s, zeta {design.zeta:.2g}; "
        f"PM {_fmt(m.phase_margin_deg, '.3g')} deg, GM {_fmt(m.gain_margin_db, '.3g')} dB, "
        f"delay {design.input_delay:.3g} s",
        fontsize=10,
    )
    ax_h.set_ylabel(f"heading [% of the step, {SETTLING_BAND:.0%} band]")
    ax_d.set_ylabel(f"rudder [deg] (limit {limit:.3g})")
    for ax in (ax_h, ax_d):
        ax.set_xlabel("time [s]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, ncols=2, loc="best")
    if design.zigzag is not None:
        z = design.zigzag
        sr = z.series
        ax_z = axes[2]
        ax_z.plot(
            sr.time, deg(sr.psi - sr.psi[0]), color=colours[0], lw=1.8, label="heading change"
        )
        ax_z.plot(sr.time, deg(sr.delta), color=colours[1], lw=1.4, label="rudder")
        for level in (deg(z.heading_check), -deg(z.heading_check)):
            ax_z.axhline(level, color="#6b6b6b", lw=0.8, ls=":")
        over = ", ".join(_fmt(o, ".1f") for o in z.overshoots_deg[:2])
        ax_z.set_title(
            f"Open-loop zigzag {z.label}: overshoots {over} deg, period {_fmt(z.period, '.0f')} s",
            fontsize=10,
        )
        ax_z.set_xlabel("time [s]")
        ax_z.set_ylabel("angle [deg]")
        ax_z.grid(True, alpha=0.3)
        ax_z.legend(fontsize=8, loc="best")
    out = Path(path)
    fig.savefig(out)
    return out

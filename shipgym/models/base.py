"""Ship models as objects: a name, parameters, state/input names and the shared kernels.

A :class:`ShipModel` couples one derivative kernel (``shipgym.models.integrate.rhs_kernel``) with
its packed parameters, and offers the batched derivative, one RK4 step and whole-trajectory
simulation as a :class:`SimulationResult` (time, states and inputs with names, like a
python-control response object).

Every method checks its arguments in Python before a compiled kernel sees them (the kernels do
no bounds checking): shapes against the model's states and inputs, real numbers (``TypeError``
otherwise), finite values, a finite step > 0 within the model's stable RK4 step (``ValueError``
naming the argument, what it was and what was expected). See :class:`ShipModel`, Notes.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from shipgym.models import integrate
from shipgym.models._checks import (
    count,
    positive_number,
    real_array,
    require_finite,
    shape_error,
    short_repr,
    step_size,
)
from shipgym.models.current import Current
from shipgym.models.delay import DelayLine
from shipgym.models.mmg import MMG_INPUTS, MMG_STATES, MMGParams, pack_mmg
from shipgym.models.nomoto import (
    FIRST_ORDER_STATES,
    NOMOTO_INPUTS,
    SECOND_ORDER_STATES,
    BechParams,
    Nomoto1Params,
    Nomoto2Params,
    NorrbinParams,
    SteeringGear,
    SurgeModel,
    pack_nomoto,
)
from shipgym.models.rvg import RVG_INPUTS, RVG_STATES, RVGParams, pack_rvg
from shipgym.models.vmm import VMM_INPUTS, VMM_STATES, VMMParams, pack_vmm

MODEL_NAMES = ("nomoto1", "nomoto2", "norrbin", "bech", "rvg3dof", "kvlcc2", "vmm")
NOMOTO_MODEL_NAMES = MODEL_NAMES[:4]


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Trajectory of a simulation.

    Attributes
    ----------
    time : numpy.ndarray
        Sample times [s], shape ``(n_steps + 1,)``.
    states : numpy.ndarray
        States at those times, shape ``(n_steps + 1, nx)``.
    inputs : numpy.ndarray
        Input held over each step, shape ``(n_steps, nu)``.
    state_names, input_names : tuple of str
        Column names.
    """

    time: np.ndarray
    states: np.ndarray
    inputs: np.ndarray
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]

    def __getitem__(self, name: str) -> np.ndarray:
        """Column of the states or the inputs by name, e.g. ``result["psi"]``."""
        if name in self.state_names:
            return self.states[:, self.state_names.index(name)]
        if name in self.input_names:
            return self.inputs[:, self.input_names.index(name)]
        raise KeyError(
            f"no signal {name!r}; states are {self.state_names}, inputs are {self.input_names}"
        )


MAX_STEPS = 100_000_000
"""Most steps one :meth:`ShipModel.simulate` call takes (its result alone would be gigabytes)."""


def _round_down(value: float) -> float:
    """``value`` rounded down to three significant digits (a step that is safely inside)."""
    if not value > 0.0:
        return 0.0
    scale = 10.0 ** (math.floor(math.log10(value)) - 2)
    return math.floor(value / scale + 1e-9) * scale


@dataclass(frozen=True, eq=False)
class ShipModel:
    """One vessel model: parameters plus the shared derivative and integrator.

    Use :func:`make_model` to build one by name.

    Attributes
    ----------
    name : str
        One of ``MODEL_NAMES``.
    params : object
        The model's parameter dataclass (yaw parameters for the Nomoto family).
    gear, surge : SteeringGear, SurgeModel or None
        Actuator and speed models of the Nomoto family (``None`` for the 3-DOF models).
    input_delay : float
        Transport delay [s] of the rudder command (Nomoto family; 0 for the others), an
        identified effect: :meth:`simulate` and the envs apply it
        (:class:`~shipgym.models.delay.DelayLine`); :meth:`step`, :meth:`deriv` and
        :meth:`linearize` are the delay-free dynamics.

    Notes
    -----
    **Checks.** States, inputs and currents must be real numbers (``TypeError`` for bool,
    complex, strings, objects) of the model's shape and finite; ``dt`` a real, finite number > 0
    (``ValueError`` naming what was wrong). A policy given to :meth:`simulate` must return a
    finite input of shape ``(nu,)``.

    A fixed-step RK4 beyond its stability limit does not give a rough answer but one that grows
    without bound (NaN or 1e235 after a while), so a step beyond the limit is refused, not
    warned about: :meth:`simulate` and :meth:`step` raise ``ValueError("dt=5 s is beyond the
    stable RK4 step of model 'rvg3dof' (about 2.79 s); use dt <= 2.78")``. The limit is
    :meth:`stable_step`, from the eigenvalues of the linearisation; :meth:`simulate` and
    :meth:`step` check ``dt`` against the model's stable step at rest, computed once per model
    (so checking costs nothing per call; a simulation run as many short pieces, such as a
    spiral manoeuvre, pays no linearisation per piece). The
    fastest modes of the shipped models are their actuators: 5.57 s for the Nomoto family
    (steering gear, 2 s), 2.79 s for the RVG (pods, 1 s), 0.139 s for the 7 m KVLCC2 (rudder,
    0.05 s). A state that still becomes non-finite (an input that drives the model out of its
    range, a stiffer state later in a run) raises ``ValueError`` naming the time and, when that
    is the cause, the stable step there, instead of returning NaN.
    """

    name: str
    params: Any
    gear: SteeringGear | None = None
    surge: SurgeModel | None = None
    input_delay: float = 0.0
    model_id: int = field(init=False)
    p: np.ndarray = field(init=False, repr=False)
    state_names: tuple[str, ...] = field(init=False)
    input_names: tuple[str, ...] = field(init=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        if not isinstance(self.name, str) or self.name not in MODEL_NAMES:
            raise ValueError(f"unknown model {self.name!r}; expected one of {MODEL_NAMES}")
        if self.name == "rvg3dof":
            set_(self, "p", pack_rvg(self.params))
            set_(self, "state_names", RVG_STATES)
            set_(self, "input_names", RVG_INPUTS)
        elif self.name == "kvlcc2":
            set_(self, "p", pack_mmg(self.params))
            set_(self, "state_names", MMG_STATES)
            set_(self, "input_names", MMG_INPUTS)
        elif self.name == "vmm":
            set_(self, "p", pack_vmm(self.params))
            set_(self, "state_names", VMM_STATES)
            set_(self, "input_names", VMM_INPUTS)
        else:
            _check_actuators(self.gear, self.surge, required=True)
            set_(self, "p", pack_nomoto(self.params, self.gear, self.surge))
            second = self.name in ("nomoto2", "bech")
            set_(self, "state_names", SECOND_ORDER_STATES if second else FIRST_ORDER_STATES)
            set_(self, "input_names", NOMOTO_INPUTS)
        delay = self.input_delay
        if not (
            isinstance(delay, int | float)
            and not isinstance(delay, bool)
            and math.isfinite(delay)
            and delay >= 0.0
        ):
            raise ValueError(f"input_delay must be a finite time >= 0 s, got {delay!r}")
        if delay and self.name not in (*NOMOTO_MODEL_NAMES, "vmm", "kvlcc2"):
            raise ValueError(
                f"input_delay applies to the rudder command of the Nomoto family "
                f"{NOMOTO_MODEL_NAMES} and the 3-DOF models vmm and kvlcc2, not to model "
                f"{self.name!r}"
            )
        set_(self, "input_delay", float(delay))
        set_(self, "model_id", integrate.MODEL_IDS[self.name])
        integrate.check_parameters(self.model_id, self.p)
        self.p.flags.writeable = False

    def __setstate__(self, state: dict[str, Any]) -> None:
        # Unpickled arrays come back writable; the kernels are compiled for a read-only ``p``.
        self.__dict__.update(state)
        self.p.flags.writeable = False

    @property
    def nx(self) -> int:
        """Number of states."""
        return len(self.state_names)

    @property
    def nu(self) -> int:
        """Number of inputs."""
        return len(self.input_names)

    def index(self, name: str) -> int:
        """Column of state ``name``."""
        try:
            return self.state_names.index(name)
        except ValueError:
            raise KeyError(
                f"model {self.name!r} has no state {name!r}; states: {self.state_names}"
            ) from None

    # ---------------------------------------------------------------------------------------
    # argument checks (Python, before any kernel)
    # ---------------------------------------------------------------------------------------

    def _currents(self, current: Any, n: int) -> np.ndarray:
        if current is None:
            return np.zeros((n, 2))
        if isinstance(current, Current):
            current = current.ned
        c = np.array(real_array(current, "current"), dtype=np.float64, order="C", ndmin=2)
        if c.shape == (1, 2) and n != 1:
            c = np.repeat(c, n, axis=0)
        if c.shape != (n, 2):
            raise ValueError(f"current must be (n, 2) north/east [m/s] with n={n}, got {c.shape}")
        require_finite(c, "current", ("north", "east"))
        return c

    def _batch(
        self,
        x: npt.ArrayLike,
        u: npt.ArrayLike,
        current: npt.ArrayLike | Current | None,
        finite_x: bool = True,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Checked ``(n, nx)`` states (a copy), ``(n, nu)`` inputs and ``(n, 2)`` currents
        (``finite_x=False``: the caller checks the states' finiteness itself)."""
        x = np.array(real_array(x, "state x"), dtype=np.float64, order="C", ndmin=2)
        if x.ndim != 2 or x.shape[1] != self.nx:
            raise ValueError(
                f"state must have shape (n, {self.nx}) {self.state_names}, got {x.shape}"
            )
        n = x.shape[0]
        u = np.array(real_array(u, "input u"), dtype=np.float64, order="C", ndmin=2)
        if u.shape == (1, self.nu) and n != 1:
            u = np.repeat(u, n, axis=0)
        if u.shape != (n, self.nu):
            raise ValueError(
                f"input must have shape ({n}, {self.nu}) {self.input_names}, got {u.shape}"
            )
        c = self._currents(current, n)
        if finite_x:
            require_finite(x, "state x", self.state_names)
        require_finite(u, "input u", self.input_names)
        return x, u, c

    def _single(
        self, value: Any, name: str, width: int, names: tuple[str, ...], hint: str = ""
    ) -> np.ndarray:
        """One ship's state or input as a checked ``(1, width)`` copy."""
        arr = np.array(real_array(value, name), dtype=np.float64, order="C")
        if arr.shape == (width,):
            arr = arr[None]
        elif arr.shape != (1, width):
            raise shape_error(name, f"({width},)", arr.shape, f" {names}{hint}")
        require_finite(arr[0], name, names)
        return arr

    # ---------------------------------------------------------------------------------------
    # the derivative, its Jacobians and the stable step
    # ---------------------------------------------------------------------------------------

    def deriv(
        self, x: npt.ArrayLike, u: npt.ArrayLike, current: npt.ArrayLike | None = None
    ) -> np.ndarray:
        """Batched state derivative ``f(x, u, p, current)``.

        Parameters
        ----------
        x : array_like
            States, shape ``(n, nx)`` (or ``(nx,)`` for one ship).
        u : array_like
            Inputs, shape ``(n, nu)`` or ``(nu,)``.
        current : array_like or Current, optional
            North/east current [m/s], shape ``(n, 2)`` or ``(2,)``; none by default.

        Returns
        -------
        numpy.ndarray
            ``x'``, shape ``(n, nx)``.

        Raises
        ------
        TypeError, ValueError
            For arguments that are not real, of the wrong shape or not finite, and when the
            derivative is not finite (a state or input beyond what the model can evaluate).
        """
        xb, ub, cb = self._batch(x, u, current)
        out = np.empty_like(xb)
        integrate.rhs_kernel(self.model_id, xb, ub, self.p, cb, out)
        if not np.isfinite(out).all():
            i = int(np.argwhere(~np.isfinite(out))[0, 0])
            raise ValueError(
                f"the derivative is not finite at row {i}: state {short_repr(xb[i].tolist())}, "
                f"input {short_repr(ub[i].tolist())} are beyond what model {self.name!r} can "
                "evaluate"
            )
        return out

    def _jacobians(
        self, xb: np.ndarray, ub: np.ndarray, cb: np.ndarray, eps: float, inputs: bool
    ) -> np.ndarray:
        """``(n, nx, nx [+ nu])`` central-difference Jacobians ``[df/dx, df/du]`` of each row."""
        n, nx = xb.shape
        n_cols = nx + (self.nu if inputs else 0)
        base = np.concatenate((xb, ub), axis=1)[:, :n_cols]
        h = eps * np.maximum(1.0, np.abs(base))  # (n, n_cols)
        z = np.repeat(np.concatenate((xb, ub), axis=1)[:, None, :], 2 * n_cols, axis=1)
        cols = np.arange(n_cols)
        z[:, 2 * cols, cols] += h
        z[:, 2 * cols + 1, cols] -= h
        z = z.reshape(n * 2 * n_cols, nx + self.nu)
        zx = np.ascontiguousarray(z[:, :nx])
        zu = np.ascontiguousarray(z[:, nx:])
        c = np.repeat(cb, 2 * n_cols, axis=0)
        f = np.empty_like(zx)
        integrate.rhs_kernel(self.model_id, zx, zu, self.p, c, f)
        f = f.reshape(n, 2 * n_cols, nx)
        return np.swapaxes((f[:, 0::2] - f[:, 1::2]) / (2.0 * h[:, :, None]), 1, 2)

    def linearize(
        self,
        x0: npt.ArrayLike,
        u0: npt.ArrayLike,
        current: npt.ArrayLike | None = None,
        eps: float = 1e-6,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Jacobians ``A = df/dx`` and ``B = df/du`` at ``(x0, u0)`` by central differences.

        Parameters
        ----------
        x0 : array_like
            State, shape ``(nx,)``.
        u0 : array_like
            Input, shape ``(nu,)``.
        current : array_like or Current, optional
            North/east current [m/s], shape ``(2,)``.
        eps : float
            Relative perturbation (scaled by ``max(1, |value|)`` per entry), finite and > 0.

        Returns
        -------
        A, B : numpy.ndarray
            Shapes ``(nx, nx)`` and ``(nx, nu)``.

        Raises
        ------
        TypeError, ValueError
            For arguments that are not real, of the wrong shape or not finite, and when the
            Jacobian is not finite.
        """
        x = self._single(x0, "x0", self.nx, self.state_names)
        u = self._single(u0, "u0", self.nu, self.input_names)
        c = self._currents(current, 1)
        eps = positive_number(eps, "eps")
        with np.errstate(all="ignore"):  # an overflow shows as a non-finite Jacobian
            jac = self._jacobians(x, u, c, eps, inputs=True)[0]
        if not np.isfinite(jac).all():
            raise ValueError(
                f"the Jacobian of model {self.name!r} is not finite at "
                f"x0={short_repr(x[0].tolist())}, u0={short_repr(u[0].tolist())}: the state or "
                "input is beyond what it can evaluate"
            )
        return jac[:, : self.nx], jac[:, self.nx :]

    def stable_step(
        self, x: npt.ArrayLike, u: npt.ArrayLike, current: npt.ArrayLike | None = None
    ) -> float:
        """Largest RK4 step [s] that is stable at ``(x, u)``.

        The step :func:`~shipgym.models.integrate.rk4_stable_step` of the eigenvalues of
        ``df/dx`` (:meth:`linearize`) at each row of the batch and at rest (zero state, input
        and current), the smallest of them. Rest counts because a rate-limited actuator (a
        steering gear turning at its rate limit) hides its own fast mode from the linearisation
        at that state, and it returns to its linear range as soon as it reaches the command; at
        rest every actuator is in its linear range.

        ``inf`` when no decaying mode limits the step. The fastest modes of the shipped models
        are their actuators (class docstring), so the value hardly changes with the state.
        """
        xb, ub, cb = self._batch(x, u, current)
        return self._stable_step(xb, ub, cb)

    def _linear_stable_step(self, xb: np.ndarray, ub: np.ndarray, cb: np.ndarray) -> float:
        """:func:`rk4_stable_step` of the Jacobians at the rows (``inf`` where not finite)."""
        if xb.shape[0] == 0:
            return math.inf
        with np.errstate(all="ignore"):
            a = self._jacobians(xb, ub, cb, 1e-6, inputs=False)
        if not np.isfinite(a).all():
            return math.inf
        return integrate.rk4_stable_step(np.linalg.eigvals(a))

    def _stable_step(self, xb: np.ndarray, ub: np.ndarray, cb: np.ndarray) -> float:
        return min(self._linear_stable_step(xb, ub, cb), self._rest_stable_step())

    def _rest_stable_step(self) -> float:
        """The stable step at rest (zero state, input and current), computed once."""
        value = self.__dict__.get("_rest_step")
        if value is None:
            zero_x, zero_u = np.zeros((1, self.nx)), np.zeros((1, self.nu))
            value = self._linear_stable_step(zero_x, zero_u, np.zeros((1, 2)))
            object.__setattr__(self, "_rest_step", value)
        return value

    def _beyond(self, dt: float, limit: float) -> str:
        return (
            f"dt={dt:g} s is beyond the stable RK4 step of model {self.name!r} (about "
            f"{limit:.3g} s); use dt <= {_round_down(limit):.3g}"
        )

    def _not_finite(
        self, dt: float, when: str, x: np.ndarray, u: np.ndarray, c: np.ndarray
    ) -> ValueError:
        """The error for a state that became non-finite in the step from ``x`` (one row)."""
        message = f"the state of model {self.name!r} is not finite after the step {when}"
        try:
            limit = self._stable_step(x[None], u[None], c[None])
        except (ValueError, np.linalg.LinAlgError):
            limit = math.inf
        if dt > limit:
            return ValueError(f"{message}: {self._beyond(dt, limit)}")
        return ValueError(
            f"{message}: the state before it, {short_repr(x.tolist())}, with input "
            f"{short_repr(u.tolist())} is beyond what the model can evaluate"
        )

    # ---------------------------------------------------------------------------------------
    # integration
    # ---------------------------------------------------------------------------------------

    def step(
        self, x: npt.ArrayLike, u: npt.ArrayLike, dt: float, current: npt.ArrayLike | None = None
    ) -> np.ndarray:
        """One RK4 step of ``dt`` [s] from ``x`` (returns a new ``(n, nx)`` array).

        Parameters
        ----------
        x, u, current
            As in :meth:`deriv`.
        dt : float
            Step [s]: finite, > 0 and within the model's stable step at rest (:meth:`stable_step`
            is never larger; the state's own limit is not computed here, on the hot path: a
            state that becomes non-finite raises instead).

        Raises
        ------
        TypeError, ValueError
            For bad arguments (class docstring, Notes), a step beyond the stable RK4 step
            and a state that is not finite after the step.
        """
        h = step_size(dt)
        # a NaN or inf in x stays in the result, which is checked after the step (one check
        # less on this hot path); the inputs are checked before (a limiter can hide a NaN)
        xb, ub, cb = self._batch(x, u, current, finite_x=False)
        if h > self._rest_stable_step():  # stable_step is never larger
            raise ValueError(self._beyond(h, self._rest_stable_step()))
        integrate.rk4_step_kernel(self.model_id, xb, ub, self.p, cb, h)
        if not np.isfinite(xb).all():
            i = int(np.argwhere(~np.isfinite(xb))[0, 0])
            x0, _, _ = self._batch(x, u, current)  # raises for a non-finite state x
            raise self._not_finite(h, f"of dt={h:g} s (row {i})", x0[i], ub[i], cb[i])
        return xb

    def _policy_input(self, value: Any, t: float) -> np.ndarray:
        try:
            arr = real_array(value, "policy output")
        except TypeError:
            arr = None
        if (
            arr is None
            or arr.shape not in ((self.nu,), (1, self.nu))
            or not (np.isfinite(arr).all())
        ):
            got = "" if arr is None else f" (shape {arr.shape})"
            raise ValueError(
                f"the policy must return an array of shape ({self.nu},) {self.input_names} of "
                f"finite numbers; at t={t:g} s it returned {type(value).__name__} "
                f"{short_repr(value)}{got}"
            )
        return arr.reshape(self.nu)

    def _load(self, value: Any, t: float) -> np.ndarray:
        """A load callback's output as a checked ``(3,)`` array."""
        try:
            arr = real_array(value, "load")
        except TypeError:
            arr = None
        if arr is None or arr.shape != (integrate.NC - 2,) or not np.isfinite(arr).all():
            raise ValueError(
                f"the load must return an array of shape ({integrate.NC - 2},) of finite "
                f"numbers; at t={t:g} s it returned {type(value).__name__} {short_repr(value)}"
            )
        return arr

    def simulate(
        self,
        x0: npt.ArrayLike,
        inputs: npt.ArrayLike | Callable[[float, np.ndarray], npt.ArrayLike],
        dt: float,
        n_steps: int | None = None,
        current: npt.ArrayLike | None = None,
        load: Callable[[float, np.ndarray], npt.ArrayLike] | None = None,
    ) -> SimulationResult:
        """Simulate one ship with fixed-step RK4.

        Parameters
        ----------
        x0 : array_like
            Initial state, shape ``(nx,)`` (one ship; :meth:`step` takes a batch).
        inputs : array_like or callable
            Either an ``(n_steps, nu)`` array of inputs held over each step, or a function
            ``(t, x) -> u`` called at the start of each step (a controller in the loop) that
            returns a finite input of shape ``(nu,)``. With an :attr:`input_delay` these are
            the commands; the rudder command reaches the ship late
            (:class:`~shipgym.models.delay.DelayLine`), and the result's ``inputs`` are the
            commands.
        dt : float
            Step [s]: finite, > 0 and within the model's stable step at rest
            (:meth:`stable_step`).
        n_steps : int, optional
            Number of steps (at most :data:`MAX_STEPS`); required when ``inputs`` is a
            callable.
        current : array_like or Current, optional
            North/east current [m/s], shape ``(2,)``.
        load : callable, optional
            ``(t, x) -> (3,)``: the external load of the coming step from the state ``x`` at
            its start (after the policy), held over the step like the current: rows 2-4 of the
            disturbances (:data:`shipgym.models.integrate.NC`), for ``rvg3dof`` the surge and
            sway force [N] and the yaw moment [N m] about its origin, for the Nomoto family the
            equivalent rudder angle [rad] and the leeway [m/s] (the third entry unused). The
            seaway's load is :func:`shipgym.models.seaway.seaway_block`'s. The Nomoto family
            and ``rvg3dof`` only (``kvlcc2`` takes its wind in its parameters, ``vmm`` in its
            inputs).

        Returns
        -------
        SimulationResult

        Raises
        ------
        TypeError, ValueError
            For bad arguments (class docstring, Notes), a policy output that is not a finite
            ``(nu,)`` input, a load that is not a finite ``(3,)`` array, a step beyond the
            stable RK4 step and a state that becomes non-finite (naming the time).
        """
        dt = step_size(dt)
        x = self._single(
            x0, "x0", self.nx, self.state_names,
            ": one ship's state (simulate runs one ship; step() takes a batch)",
        )  # fmt: skip
        c = self._currents(current, 1)
        if load is not None:
            if self.model_id >= integrate.KVLCC2:
                raise ValueError(
                    f"load applies to the Nomoto family and rvg3dof, not to model {self.name!r} "
                    "(kvlcc2 takes its wind in its parameters, vmm in its inputs)"
                )
            c = np.concatenate((c, np.zeros((1, integrate.NC - 2))), axis=1)
        if callable(inputs):
            if n_steps is None:
                raise ValueError("n_steps must be >= 1 when inputs is a function, got None")
            n_steps = count(n_steps, "n_steps", 1, MAX_STEPS)
            u_seq = np.zeros((n_steps, self.nu))
            policy = inputs
        else:
            u_seq = np.array(real_array(inputs, "inputs"), dtype=np.float64, order="C", ndmin=2)
            if u_seq.ndim != 2 or u_seq.shape[1] != self.nu:
                raise shape_error(
                    "inputs", f"(n_steps, {self.nu})", u_seq.shape, f" {self.input_names}"
                )
            if n_steps is None:
                n_steps = u_seq.shape[0]
            elif count(n_steps, "n_steps", 0, MAX_STEPS) != u_seq.shape[0]:
                raise ValueError(f"n_steps={n_steps} but inputs has {u_seq.shape[0]} rows")
            if n_steps > MAX_STEPS:
                raise ValueError(f"inputs must have at most {MAX_STEPS} rows, got {n_steps}")
            require_finite(u_seq, "inputs", self.input_names)
            policy = None
        if dt > self._rest_stable_step():  # stable_step is never larger
            raise ValueError(self._beyond(dt, self._rest_stable_step()))
        states = np.empty((n_steps + 1, self.nx))
        states[0] = x[0]
        with np.errstate(over="ignore"):
            time = np.arange(n_steps + 1) * dt
        if not math.isfinite(time[-1]):
            raise ValueError(f"dt * n_steps must be a finite time, got {dt!r} s * {n_steps}")
        u = np.empty((1, self.nu))
        delay = DelayLine(self.input_delay, dt, 1, 1) if self.input_delay else None
        for k in range(n_steps):
            if policy is not None:
                if k > 0 and not np.isfinite(x).all():
                    raise self._not_finite(
                        dt, f"to t={time[k]:g} s (dt={dt:g} s)", states[k - 1], u_seq[k - 1], c[0]
                    )
                u_seq[k] = self._policy_input(policy(time[k], x[0].copy()), time[k])
            u[0] = u_seq[k]
            if delay is not None:
                u[0, 0] = delay.push(u[:, :1])[0, 0]
            if load is not None:
                c[0, 2:] = self._load(load(time[k], x[0].copy()), time[k])
            integrate.rk4_step_kernel(self.model_id, x, u, self.p, c, dt)
            states[k + 1] = x[0]
        if not np.isfinite(states).all():
            k = int(np.argwhere(~np.isfinite(states))[0, 0])
            raise self._not_finite(
                dt, f"to t={time[k]:g} s (dt={dt:g} s)", states[k - 1], u_seq[k - 1], c[0]
            )
        return SimulationResult(time, states, u_seq, self.state_names, self.input_names)


def _check_actuators(gear: Any, surge: Any, required: bool) -> None:
    """``TypeError`` for a steering gear or surge model of the wrong type."""
    for value, cls, label in ((gear, SteeringGear, "gear"), (surge, SurgeModel, "surge")):
        if (value is not None or required) and not isinstance(value, cls):
            raise TypeError(f"{label} must be a {cls.__name__}, got {short_repr(value)}")


_DEFAULT_YAW = {
    "nomoto1": Nomoto1Params,
    "nomoto2": Nomoto2Params,
    "norrbin": NorrbinParams,
    "bech": BechParams,
}


def make_model(
    name: str,
    params: Any | None = None,
    gear: SteeringGear | None = None,
    surge: SurgeModel | None = None,
    input_delay: float = 0.0,
) -> ShipModel:
    """Build a model by name with default (documented) or given parameters.

    Parameters
    ----------
    name : {"nomoto1", "nomoto2", "norrbin", "bech", "rvg3dof", "kvlcc2", "vmm"} or path
        Model name (``kvlcc2``: the MMG standard model, :mod:`shipgym.models.mmg`; ``vmm``:
        seed 003's general model, :mod:`shipgym.models.vmm`), or the path of a model file
        ending in ``.json`` (``shipgym identify --json``; :func:`shipgym.models.model_file.
        load_model`), which takes no further arguments.
    params : dataclass or str, optional
        Parameters of the right type (e.g. :class:`Nomoto1Params`, :class:`MMGParams`);
        defaults otherwise. For ``rvg3dof`` also the name of a shipped set (``"seed001"``,
        ``"sea_trials"``: :meth:`RVGParams.named`) or the model file of its identification,
        for ``kvlcc2`` ``"kvlcc2"``; ``vmm`` needs :class:`VMMParams` or the path of a fitted
        model's JSON (:meth:`VMMParams.load`).
    gear, surge : SteeringGear, SurgeModel, optional
        Steering gear and surge model of the Nomoto family.
    input_delay : float
        Transport delay [s] of the rudder command (Nomoto family).

    Returns
    -------
    ShipModel

    Raises
    ------
    TypeError
        For a name that is not a string, or a ``gear`` or ``surge`` of the wrong type (both are
        ignored by the 3-DOF models).
    ValueError
        For an unknown name or parameters of the wrong type.
    """
    from shipgym.models.model_file import is_model_file, load_model

    if is_model_file(name):
        if params is not None or gear is not None or surge is not None or input_delay:
            raise ValueError(f"a model file ({str(name)!r}) takes no further model arguments")
        return load_model(name)
    if not isinstance(name, str):
        raise TypeError(f"model name must be a str, one of {MODEL_NAMES}, got {short_repr(name)}")
    if name not in MODEL_NAMES:
        raise ValueError(
            f"unknown model {name!r}; expected one of {MODEL_NAMES} or a model file FIT.json"
        )
    _check_actuators(gear, surge, required=False)
    if name == "vmm":
        if isinstance(params, str | os.PathLike):
            params = VMMParams.load(params)
        if not isinstance(params, VMMParams):
            raise ValueError(
                "model 'vmm' takes VMMParams or the path of a fitted model's JSON "
                f"(shipgym identify --model vmm:... --json FILE), got {type(params).__name__}"
            )
        return ShipModel(name, params, input_delay=input_delay)
    three_dof = {"rvg3dof": RVGParams, "kvlcc2": MMGParams}
    expected = three_dof.get(name) or _DEFAULT_YAW[name]
    if name == "rvg3dof" and is_model_file(params):  # an identified Gunnerus
        ship = load_model(params)
        if ship.name != "rvg3dof":
            raise ValueError(
                f"{str(params)!r} holds a {ship.name!r} model; rvg3dof takes a model file of "
                "shipgym identify --model rvg3dof --json"
            )
        params = ship.params
    if isinstance(params, str):
        if name not in three_dof:
            raise ValueError(
                f"a parameter set name ({params!r}) selects a shipped set of "
                f"{' or '.join(three_dof)} only; model {name!r} takes {expected.__name__}"
            )
        params = expected.named(params)
    if params is None:
        params = expected()
    elif not isinstance(params, expected):
        raise ValueError(f"model {name!r} takes {expected.__name__}, got {type(params).__name__}")
    if name in three_dof:
        if input_delay and name == "rvg3dof":
            raise ValueError(f"input_delay applies to a rudder order, not to {name!r}'s pods")
        return ShipModel(name, params, input_delay=input_delay)
    return ShipModel(name, params, gear or SteeringGear(), surge or SurgeModel(), input_delay)

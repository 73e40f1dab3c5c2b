"""Ship models as objects: a name, parameters, state/input names and the shared kernels.

A :class:`ShipModel` couples one derivative kernel (``shipgym.models.integrate.rhs``) with
its packed parameters, and offers the batched derivative, one RK4 step and whole-trajectory
simulation as a :class:`SimulationResult` (time, states and inputs with names, like a
python-control response object).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from shipgym.models import integrate
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
    """

    name: str
    params: Any
    gear: SteeringGear | None = None
    surge: SurgeModel | None = None
    model_id: int = field(init=False)
    p: np.ndarray = field(init=False, repr=False)
    state_names: tuple[str, ...] = field(init=False)
    input_names: tuple[str, ...] = field(init=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
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
            assert self.gear is not None and self.surge is not None
            set_(self, "p", pack_nomoto(self.params, self.gear, self.surge))
            second = self.name in ("nomoto2", "bech")
            set_(self, "state_names", SECOND_ORDER_STATES if second else FIRST_ORDER_STATES)
            set_(self, "input_names", NOMOTO_INPUTS)
        set_(self, "model_id", MODEL_NAMES.index(self.name))
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

    def _batch(self, x: npt.ArrayLike, u: npt.ArrayLike, current: npt.ArrayLike | None):
        x = np.array(x, dtype=np.float64, ndmin=2)
        u = np.array(u, dtype=np.float64, ndmin=2)
        if x.ndim != 2 or x.shape[1] != self.nx:
            raise ValueError(
                f"state must have shape (n, {self.nx}) {self.state_names}, got {x.shape}"
            )
        n = x.shape[0]
        if u.shape == (1, self.nu) and n > 1:
            u = np.repeat(u, n, axis=0)
        if u.shape != (n, self.nu):
            raise ValueError(
                f"input must have shape ({n}, {self.nu}) {self.input_names}, got {u.shape}"
            )
        if current is None:
            c = np.zeros((n, 2))
        else:
            c = np.array(current, dtype=np.float64, ndmin=2)
            if c.shape == (1, 2) and n > 1:
                c = np.repeat(c, n, axis=0)
            if c.shape != (n, 2):
                raise ValueError(
                    f"current must be (n, 2) north/east [m/s] with n={n}, got {c.shape}"
                )
        return x, u, c

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
        current : array_like, optional
            North/east current [m/s], shape ``(n, 2)`` or ``(2,)``; none by default.

        Returns
        -------
        numpy.ndarray
            ``x'``, shape ``(n, nx)``.
        """
        xb, ub, cb = self._batch(x, u, current)
        out = np.empty_like(xb)
        integrate.rhs(self.model_id, xb, ub, self.p, cb, out)
        return out

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
        current : array_like, optional
            North/east current [m/s].
        eps : float
            Relative perturbation (scaled by ``max(1, |value|)`` per entry).

        Returns
        -------
        A, B : numpy.ndarray
            Shapes ``(nx, nx)`` and ``(nx, nu)``.
        """
        x0b, u0b, _ = self._batch(x0, u0, current)
        n_cols = self.nx + self.nu
        z = np.tile(np.concatenate((x0b[0], u0b[0])), (2 * n_cols, 1))
        h = eps * np.maximum(1.0, np.abs(z[0]))
        for k in range(n_cols):
            z[2 * k, k] += h[k]
            z[2 * k + 1, k] -= h[k]
        _, _, c = self._batch(z[:, : self.nx], z[:, self.nx :], current)
        f = self.deriv(z[:, : self.nx], z[:, self.nx :], c)
        jac = ((f[0::2] - f[1::2]) / (2.0 * h[:, None])).T
        return jac[:, : self.nx], jac[:, self.nx :]

    def step(
        self, x: npt.ArrayLike, u: npt.ArrayLike, dt: float, current: npt.ArrayLike | None = None
    ) -> np.ndarray:
        """One RK4 step of ``dt`` [s] from ``x`` (returns a new ``(n, nx)`` array)."""
        xb, ub, cb = self._batch(x, u, current)
        xb = xb.copy()
        integrate.rk4_step(self.model_id, xb, ub, self.p, cb, float(dt))
        return xb

    def simulate(
        self,
        x0: npt.ArrayLike,
        inputs: npt.ArrayLike | Callable[[float, np.ndarray], npt.ArrayLike],
        dt: float,
        n_steps: int | None = None,
        current: npt.ArrayLike | None = None,
    ) -> SimulationResult:
        """Simulate one ship with fixed-step RK4.

        Parameters
        ----------
        x0 : array_like
            Initial state, shape ``(nx,)``.
        inputs : array_like or callable
            Either an ``(n_steps, nu)`` array of inputs held over each step, or a function
            ``(t, x) -> u`` called at the start of each step (a controller in the loop).
        dt : float
            Step [s].
        n_steps : int, optional
            Number of steps; required when ``inputs`` is a callable.
        current : array_like, optional
            North/east current [m/s], shape ``(2,)``.

        Returns
        -------
        SimulationResult
        """
        if not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be a finite step > 0 s, got {dt!r}")
        if callable(inputs):
            if n_steps is None or n_steps < 1:
                raise ValueError(f"n_steps must be >= 1 when inputs is a function, got {n_steps!r}")
            u_seq = np.zeros((n_steps, self.nu))
            policy = inputs
        else:
            u_seq = np.array(inputs, dtype=np.float64, ndmin=2)
            if u_seq.shape[1] != self.nu:
                raise ValueError(f"inputs must have shape (n_steps, {self.nu}), got {u_seq.shape}")
            n_steps = u_seq.shape[0] if n_steps is None else n_steps
            if n_steps != u_seq.shape[0]:
                raise ValueError(f"n_steps={n_steps} but inputs has {u_seq.shape[0]} rows")
            policy = None
        x, _, c = self._batch(x0, np.zeros(self.nu), current)
        x = x.copy()
        states = np.empty((n_steps + 1, self.nx))
        states[0] = x[0]
        time = np.arange(n_steps + 1) * dt
        u = np.empty((1, self.nu))
        for k in range(n_steps):
            if policy is not None:
                u_seq[k] = np.asarray(policy(time[k], x[0].copy()), dtype=np.float64)
            u[0] = u_seq[k]
            integrate.rk4_step(self.model_id, x, u, self.p, c, dt)
            states[k + 1] = x[0]
        return SimulationResult(time, states, u_seq, self.state_names, self.input_names)


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
) -> ShipModel:
    """Build a model by name with default (documented) or given parameters.

    Parameters
    ----------
    name : {"nomoto1", "nomoto2", "norrbin", "bech", "rvg3dof", "kvlcc2", "vmm"}
        Model name (``kvlcc2``: the MMG standard model, :mod:`shipgym.models.mmg`; ``vmm``:
        seed 003's general model, :mod:`shipgym.models.vmm`).
    params : dataclass or str, optional
        Parameters of the right type (e.g. :class:`Nomoto1Params`, :class:`MMGParams`);
        defaults otherwise. For ``rvg3dof`` also the name of a shipped set (``"seed001"``,
        ``"sea_trials"``: :meth:`RVGParams.named`), for ``kvlcc2`` ``"kvlcc2"``; ``vmm`` needs
        :class:`VMMParams` or the path of a fitted model's JSON (:meth:`VMMParams.load`).
    gear, surge : SteeringGear, SurgeModel, optional
        Steering gear and surge model of the Nomoto family.

    Returns
    -------
    ShipModel

    Raises
    ------
    ValueError
        For an unknown name or parameters of the wrong type.
    """
    if name not in MODEL_NAMES:
        raise ValueError(f"unknown model {name!r}; expected one of {MODEL_NAMES}")
    if name == "vmm":
        if isinstance(params, str | os.PathLike):
            params = VMMParams.load(params)
        if not isinstance(params, VMMParams):
            raise ValueError(
                "model 'vmm' takes VMMParams or the path of a fitted model's JSON "
                f"(shipgym identify --model vmm:... --json FILE), got {type(params).__name__}"
            )
        return ShipModel(name, params)
    three_dof = {"rvg3dof": RVGParams, "kvlcc2": MMGParams}
    expected = three_dof.get(name) or _DEFAULT_YAW[name]
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
        return ShipModel(name, params)
    return ShipModel(name, params, gear or SteeringGear(), surge or SurgeModel())

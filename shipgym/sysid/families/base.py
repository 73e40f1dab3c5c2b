"""The model-family interface of the identification engine, and the helpers every family shares.

A *family* is a vessel model that :func:`shipgym.sysid.engine.identify` can fit to a record and
augment with named *effects*. It says which parameters it has and which are free (with bounds
and the reason for them), how to replay a record window by window through the shared kernel of
:mod:`shipgym.models`, and which effects of its catalogue can augment it (:class:`Effect`: the
term, its parameters with bounds, its source). The engine runs one loop over any family:

1. ``prepare``: check the record, cut it into a training and a held-out part;
2. ``fit_base``: fit the base model on the training part, score it on the held-out part;
3. for every catalogue effect not yet in the model, ``try_effect`` fits the augmented model on
   the training part and scores it on the held-out part; ``compare`` and ``significant`` decide
   (held-out BIC drop and a minimum relative drop of the held-out error, :data:`BIC_MARGIN`);
4. ``choose`` picks the best significant candidate (parsimony among near-ties), ``accept``
   makes it the current model, and the loop repeats;
5. ``finish``: whole-record fits, errors, diagnostics and traces of the base and final models;
6. ``verdict``: the reasons the record does not determine the final model (:class:`Verdict`;
   shared checks :func:`undetermined` and :meth:`ModelFamily.verdict`, each family its own).

Families register themselves in :data:`FAMILIES` under their model names (the ``--model`` of
``shipgym identify``); a new family is one new module and one :func:`register` call.

Causes shared by the families
-----------------------------
An effect whose physics does not depend on the hull model (a rudder zero error, a steering gear
that lags the recorded rudder, a transport delay, a current, the wind) is defined once in
:data:`CAUSES`; a family says which of them it can represent (:func:`causes`) and adds its own
hull-specific ones. The actuator causes act on the recorded rudder before any model sees it,
through one function every family uses (:func:`actual_rudder`: :func:`shift` for the delay,
:func:`lag_filter` for the steering gear, seed 002 eq. 2), and the fitted models simulate them
the same way (:class:`shipgym.models.SteeringGear`, :class:`shipgym.models.delay.DelayLine`).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from shipgym.models import Nomoto1Params, SteeringGear, make_model
from shipgym.models._jit import kernel
from shipgym.models.integrate import NC, rk4_block_nomoto
from shipgym.models.nomoto import IDELTA, nomoto1_col
from shipgym.sysid.data import Record

__all__ = [
    "ACTUATOR_CAUSES",
    "BIC_MARGIN",
    "CAUSES",
    "FAMILIES",
    "TIE_FRACTION",
    "Candidate",
    "Effect",
    "ModelFamily",
    "Verdict",
    "actual_rudder",
    "bic",
    "causes",
    "errors",
    "get_family",
    "holdout_runs",
    "jsonable",
    "lag_filter",
    "ljung_box",
    "manoeuvre_kind",
    "register",
    "shift",
    "undetermined",
    "window_starts",
    "wrap",
    "xcorr",
]

BIC_MARGIN = 10.0
"""Required decrease of the held-out BIC ``J`` to accept an effect (every family)."""

TIE_FRACTION = 0.02
"""Candidates whose BIC change is within this fraction of the best are tied (parsimony)."""


@dataclass(frozen=True)
class Effect:
    """A named augmentation of a model family.

    Attributes
    ----------
    name : str
        Catalogue name (``"thruster_lift"``, ``"rudder_lag"`` ...).
    term : str
        The term it adds, as an equation (for reports and docs).
    parameters : tuple of str
        Its parameters, SI units and radians.
    bounds : mapping
        ``parameter -> (low, high)`` physical bounds of the fit.
    source : str
        Where the term and its bounds come from.
    """

    name: str
    term: str
    parameters: tuple[str, ...]
    bounds: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    source: str = ""

    @property
    def n_added(self) -> int:
        """Number of parameters the effect adds (the parsimony rule counts these)."""
        return len(self.parameters)


LAG_BOUNDS = (0.1, 40.0)
"""Bounds [s] of an identified steering-gear time constant ``T_d``."""

DELAY_BOUNDS = (0.0, 15.0)
"""Bounds [s] of an identified input delay ``tau``."""

RUDDER_OFFSET_BOUNDS = (-math.radians(5.0), math.radians(5.0))
"""Bounds [rad] of an identified rudder zero error ``delta0``."""

CAUSES: dict[str, Effect] = {
    e.name: e
    for e in (
        Effect(
            "rudder_offset",
            "delta = delta_recorded + delta0",
            ("delta0",),
            {"delta0": RUDDER_OFFSET_BOUNDS},
            "a rudder zero error (indicator or feedback misaligned); seed 000 (regression "
            "constant c, delta0 = c / b); seed 002 eq. 4",
        ),
        Effect(
            "rudder_lag",
            "T_d delta' + delta = delta_recorded (the ship's angle and rate limits)",
            ("T_d",),
            {"T_d": LAG_BOUNDS},
            "seed 002 eq. 2: the recorded rudder is the order of a first-order steering gear "
            "(shipgym.models.SteeringGear)",
        ),
        Effect(
            "input_delay",
            "delta(t) = delta_recorded(t - tau)",
            ("tau",),
            {"tau": DELAY_BOUNDS},
            "a transport delay between the rudder log and the ship (logging, hydraulics)",
        ),
        Effect(
            "current",
            "nu_r = nu - R(psi)^T [V_n, V_e, 0]",
            ("V_n", "V_e"),
            {"V_n": (-2.0, 2.0), "V_e": (-2.0, 2.0)},
            "a steady, uniform, irrotational current: seed 001 eq. 7-12, seed 003 eq_nu_r",
        ),
        Effect(
            "wind",
            "X_wc (V_w/U)^2 cos g, Y_ws (V_w/U)^2 sin g, "
            "N_ws (V_w/U)^2 sin g + N_w2 (V_w/U)^2 sin 2g",
            ("X_wc", "Y_ws", "N_ws", "N_w2"),
            {},
            "apparent-wind loads with the angular forms of Isherwood (1972) and Fossen (2011, "
            "eq. 8.23); the yaw moment's sin g part is the lateral area's centre off midship "
            "(Blendermann 1994: N = (s_L / L - 0.18 (g - pi/2)) C_Y); needs the record's wind "
            "channels",
        ),
    )
}
"""Causes whose physics does not depend on the hull model, each defined once (module
docstring); a family takes those it can represent with :func:`causes`."""

ACTUATOR_CAUSES: tuple[str, ...] = ("rudder_offset", "rudder_lag", "input_delay")
"""The causes that act on the recorded rudder (:func:`actual_rudder`)."""


def causes(*names: str, **representations: Mapping[str, Any]) -> dict[str, Effect]:
    """The shared definitions of ``names`` for a family's catalogue, in that order.

    ``representations`` maps a cause to the fields a family writes differently (its own term or
    parameter names for the same physics, e.g. the Norrbin model's rudder offset as a yaw bias
    ``n0``), applied with :func:`dataclasses.replace`.
    """
    unknown = [n for n in (*names, *representations) if n not in CAUSES]
    if unknown:
        raise ValueError(f"unknown causes {unknown}; expected some of {tuple(CAUSES)}")
    return {n: replace(CAUSES[n], **representations.get(n, {})) for n in names}


@dataclass
class Candidate:
    """A model fitted on the training part and scored on the held-out part.

    Attributes
    ----------
    effects : tuple of str
        The effects in the model, in the order they were accepted.
    fitted : object
        The family's fit (whatever its ``finish`` and ``effect_parameters`` read).
    J : float
        Held-out BIC (``inf`` for a diverging prediction).
    heldout_error : float
        The held-out error the relative-drop guard compares (a family's choice of channels).
    heldout_rms : dict
        Held-out RMS of each scored channel, for the evidence of accepted effects.
    extra : dict
        Anything else a family wants to carry (test statistics, scores of side channels).
    """

    effects: tuple[str, ...]
    fitted: Any
    J: float
    heldout_error: float
    heldout_rms: dict[str, float] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Verdict:
    """Whether an identification determines its model.

    Attributes
    ----------
    identifiable : bool
        True when no reason was found.
    reasons : tuple of str
        Why the record does not determine the fitted model, one sentence each (a parameter the
        model needs without a standard error or with one larger than its estimate, a parameter
        at its bound, a gain of the wrong sign, a time constant far beyond the record, an
        ill-conditioned regression: each family's :meth:`ModelFamily.verdict`).
    """

    identifiable: bool = True
    reasons: tuple[str, ...] = ()

    @classmethod
    def of(cls, reasons: Iterable[str]) -> Verdict:
        """The verdict of ``reasons`` (identifiable when there are none)."""
        found = tuple(reasons)
        return cls(not found, found)

    def to_dict(self) -> dict[str, Any]:
        """``{"identifiable": bool, "reasons": [str, ...]}`` (the JSON of ``shipgym identify``)."""
        return {"identifiable": self.identifiable, "reasons": list(self.reasons)}


def undetermined(
    values: Mapping[str, float], stderr: Mapping[str, float], names: Iterable[str]
) -> list[str]:
    """Reasons the parameters ``names`` of a fit are not determined by their standard errors.

    A parameter of ``values`` among ``names`` without a finite standard error in ``stderr``, or
    with one larger than the size of its estimate (a 68 % interval that includes zero, or the
    other sign), is named with its value; ``names`` absent from ``values`` are skipped.
    """
    out = []
    for name in names:
        if name not in values:
            continue
        v, se = values[name], stderr.get(name)
        if not math.isfinite(v):
            out.append(f"{name} is not finite ({v})")
        elif se is None or not math.isfinite(se):
            out.append(f"{name} = {v:.4g} has no standard error")
        elif se > abs(v):
            out.append(
                f"{name} = {v:.4g} +- {se:.3g}: the standard error is larger than the estimate"
            )
    return out


class ModelFamily(ABC):
    """A model the identification engine can fit and augment (module docstring).

    Subclasses set :attr:`name`, :attr:`catalogue` and :attr:`min_relative_drop` and implement
    the abstract methods; the defaults of :meth:`compare`, :meth:`significant`, :meth:`choose`
    and :meth:`accept` are the engine's criterion.
    """

    name: str = ""
    #: Effects that can augment this family, by name.
    catalogue: Mapping[str, Effect] = {}
    #: Required relative drop of the held-out error to accept an effect.
    min_relative_drop: float = 0.2
    #: Default scoring window [s] (None: one free run over the record).
    default_window_s: float | None = None
    #: True when ``try_effect`` calls share no state, so the engine may run them in threads.
    concurrent_candidates: bool = False
    #: True when ``prepare`` takes a list of runs of one ship (cross-validation across runs).
    multi_run: bool = False

    def resolve_window(self, window_s: float | str | None, duration: float) -> float | None:
        """The scoring window [s] for ``window_s`` (``"auto"``: :attr:`default_window_s`)."""
        if window_s == "auto":
            return self.default_window_s
        if window_s is None:
            return None
        if isinstance(window_s, bool) or not isinstance(window_s, int | float):
            raise ValueError(
                f"window_s must be a number of seconds, 'auto' or None, got {window_s!r}"
            )
        if not (math.isfinite(window_s) and window_s > 0):
            raise ValueError(f"window_s must be a positive number of seconds, got {window_s!r}")
        return float(window_s)

    @abstractmethod
    def prepare(self, record: Record | list[Record], holdout: float, window_s: float | None) -> Any:
        """Check ``record`` (``ValueError`` naming what is missing) and split it; returns the
        context every other method receives. A :attr:`multi_run` family gets a list of runs."""

    @abstractmethod
    def fit_base(self, ctx: Any, say: Callable[[str], None]) -> Candidate:
        """The base model fitted on the training part, scored on the held-out part."""

    def fit_bases(self, ctx: Any, say: Callable[[str], None]) -> list[tuple[Any, Candidate]]:
        """The base models the loop starts from, each with its context, best first: by
        default :meth:`fit_base` alone. A family that chooses its structure may start the loop
        from several (a flexible structure can take up an effect the catalogue names); which
        start's final model is kept is :meth:`choose_start`'s choice."""
        return [(ctx, self.fit_base(ctx, say))]

    def choose_start(
        self,
        outcomes: Sequence[tuple[Any, Candidate, Candidate]],
        say: Callable[[str], None],
    ) -> int:
        """Which of several starts (``(ctx, base, final)`` per start of :meth:`fit_bases`) to
        keep: by default the one whose final model predicts the held-out part best."""
        return min(range(len(outcomes)), key=lambda k: outcomes[k][2].heldout_error)

    def candidates(self, current: Candidate) -> Iterable[str]:
        """Catalogue effects that can still be added to ``current``."""
        return [e for e in self.catalogue if e not in current.effects]

    @abstractmethod
    def try_effect(self, ctx: Any, current: Candidate, name: str) -> Candidate:
        """``current`` augmented by effect ``name``, fitted and scored (may raise
        ``ValueError``, reported as a failed candidate)."""

    def compare(self, current: Candidate, cand: Candidate, name: str) -> tuple[float, float]:
        """``(delta_J, relative_drop)`` of ``cand`` against ``current``."""
        if not math.isfinite(cand.J):
            return math.inf, -math.inf
        if not math.isfinite(current.J):  # any finite candidate beats a diverging model
            return -math.inf, 1.0
        drop = 1.0 - cand.heldout_error / max(current.heldout_error, 1e-300)
        return cand.J - current.J, drop

    def significant(self, cand: Candidate, name: str, delta_j: float, drop: float) -> bool:
        """The engine's criterion: the BIC drops by :data:`BIC_MARGIN` and the held-out error
        by :attr:`min_relative_drop`, and no parameter of the effect ended at a bound of its
        fit (``cand.extra["at_bound"]``, set by the family: the bound, not the record, chose
        its value)."""
        if cand.extra.get("at_bound"):
            return False
        return bool(delta_j < -BIC_MARGIN and drop > self.min_relative_drop)

    def choose(self, good: Mapping[str, tuple[Candidate, float]]) -> str:
        """The effect to accept among the significant ``name -> (candidate, delta_J)``.

        The most negative ``delta_J`` wins; candidates within :data:`TIE_FRACTION` of it are
        tied and the one adding the fewest parameters wins (a correlated simulation residual
        makes small BIC differences moot). Against a current model whose held-out prediction
        diverges every finite candidate has ``delta_J = -inf``: the lowest held-out BIC of
        its own wins then.
        """
        best = min(good, key=lambda k: (good[k][1], good[k][0].J))
        if not math.isfinite(good[best][1]):
            return best
        tied = [k for k in good if good[k][1] <= (1.0 - TIE_FRACTION) * good[best][1]]
        return min(tied, key=lambda k: (self.catalogue[k].n_added, good[k][1]))

    def accept(self, ctx: Any, current: Candidate, cand: Candidate, name: str) -> Candidate:
        """The new current model after accepting ``name`` (by default ``cand`` itself)."""
        return cand

    @abstractmethod
    def effect_parameters(self, fitted: Any, name: str) -> dict[str, float]:
        """The fitted parameters of effect ``name`` (SI units; derived ones may be added)."""

    @abstractmethod
    def finish(
        self, ctx: Any, base: Candidate, final: Candidate, say: Callable[[str], None]
    ) -> dict[str, Any]:
        """Whole-record report of the base and final models: the keyword arguments ``base``,
        ``final``, ``diagnostics``, ``parameters_before``, ``parameters_after``,
        ``error_before``, ``error_after``, ``heldout`` and ``traces`` of
        :class:`shipgym.sysid.engine.IdentificationResult` (effects' parameters updated to the
        whole-record fit under ``effect_parameters``: ``name -> dict``)."""

    def verdict(self, ctx: Any, report: Mapping[str, Any]) -> list[str]:
        """Reasons the final whole-record fit does not determine the model (empty: it does).

        ``report`` is what :meth:`finish` returned. The default checks what every family
        reports: each final parameter is finite, and the standard errors under
        ``report["diagnostics"]["final"]["stderr"]``, where a family gives them, are not all
        missing. A family states its own checks (the parameters its model needs, their bounds,
        its regression's conditioning) by overriding this method.
        """
        params = report.get("parameters_after") or {}
        out = [f"{k} is not finite ({v})" for k, v in params.items() if not math.isfinite(v)]
        final = (report.get("diagnostics") or {}).get("final") or {}
        stderr = final.get("stderr")
        if stderr is not None and not any(
            isinstance(v, int | float) and math.isfinite(v) for v in stderr.values()
        ):
            out.append("the fit has no standard errors (its Jacobian is singular)")
        return out


FAMILIES: dict[str, ModelFamily] = {}
"""Model name -> family (filled by :mod:`shipgym.sysid.families`)."""


def register(family: ModelFamily, *names: str) -> ModelFamily:
    """Register ``family`` under ``names`` (default: its :attr:`~ModelFamily.name`)."""
    for n in names or (family.name,):
        FAMILIES[n] = family
    return family


def get_family(model: str) -> ModelFamily:
    """The registered family of ``model`` (``ValueError`` listing the known names)."""
    try:
        return FAMILIES[model]
    except (KeyError, TypeError):
        raise ValueError(
            f"unsupported model {model!r}; expected one of {tuple(FAMILIES)}"
        ) from None


# --------------------------------------------------------------------------------------------
# helpers every family shares


def wrap(a: np.ndarray) -> np.ndarray:
    """Smallest signed angle [rad] of ``a``."""
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def window_starts(t: np.ndarray, window_s: float | None) -> np.ndarray:
    """Start indices of consecutive windows of ``window_s`` seconds (one window if None).

    A last window shorter than half ``window_s`` is merged into the one before.
    """
    if window_s is None:
        return np.array([0])
    edges = t[0] + window_s * np.arange(math.ceil((t[-1] - t[0]) / window_s))
    starts = np.unique(np.searchsorted(t, edges - 1e-9 * window_s))
    if starts.size > 1 and t[-1] - t[starts[-1]] < 0.5 * window_s:
        starts = starts[:-1]
    return starts


MANOEUVRE_STEP_DEG = 5.0
"""Rudder amplitudes within this many degrees of each other are one kind of manoeuvre (a 20/5
and a 20/10 zigzag are alike; a 10/10 and a 20/20 zigzag are not)."""


def manoeuvre_kind(delta: np.ndarray) -> tuple[bool, int, int]:
    """The kind of manoeuvre a recorded rudder makes: whether it reverses (a zigzag or a random
    manoeuvre, against a turn or a pull-out), its amplitude in steps of
    :data:`MANOEUVRE_STEP_DEG` (the 98th percentile of ``|delta|``, robust to a spike) and, for
    a run that does not reverse, the side of its rudder (the sign of its median; 0 for one that
    reverses). A turn to port and a turn to starboard are two kinds: a ship's port/starboard
    difference (a single-screw hull's, a rudder zero error's) shows only between the two."""
    d = np.asarray(delta, dtype=np.float64)
    d = d[np.isfinite(d)]
    if d.size == 0:
        return False, 0, 0
    amplitude = float(np.percentile(np.abs(d), 98.0))
    reverses = bool(d.max() > 0.3 * amplitude and d.min() < -0.3 * amplitude)
    side = 0 if reverses else int(np.sign(np.median(d)))
    return reverses, round(math.degrees(amplitude) / MANOEUVRE_STEP_DEG), side


def holdout_runs(
    deltas: list[np.ndarray], holdout: float, names: list[str] | None = None
) -> tuple[list[int], list[str]]:
    """The runs held out of the fits and used for scoring, when several runs are identified
    together: ``n // round(1 / holdout)`` of them (at least one), each a manoeuvre of a kind
    (:func:`manoeuvre_kind`) that a training run also makes, so that the score measures how
    the model predicts manoeuvres like those it was fitted on, not an extrapolation to a rudder
    amplitude or a turning side it never saw (whatever order the files come in: a turn is held
    out only if another turn to its side stays in the fits).

    The runs are taken in this order of preference: every ``round(1 / holdout)``-th run, then
    the others from the last; a run is held out when another run of its kind stays in the
    training set. When too few runs have a partner (every manoeuvre made once), the rest come
    from that order all the same, and a note names them.

    Parameters
    ----------
    deltas : list of ndarray
        The recorded rudder angle [rad] of every run.
    holdout : float
        Fraction of the runs to hold out (the ``holdout`` of
        :func:`~shipgym.sysid.engine.identify`).
    names : list of str, optional
        The runs' names, for the notes (default: their indices).

    Returns
    -------
    held : list of int
        Indices of the held-out runs, ascending.
    notes : list of str
        One line per held-out run whose kind no training run makes.
    """
    n = len(deltas)
    k = max(2, round(1.0 / holdout))
    n_held = max(1, n // k)
    kinds = [manoeuvre_kind(d) for d in deltas]
    order = [i for i in range(n) if i % k == k - 1]
    order += [i for i in reversed(range(n)) if i not in order]
    held: list[int] = []
    for i in order:
        if len(held) < n_held and any(
            kinds[j] == kinds[i] for j in range(n) if j != i and j not in held
        ):
            held.append(i)
    notes = []
    for i in order:
        if len(held) >= n_held:
            break
        if i not in held:
            held.append(i)
            reverses, steps, side = kinds[i]
            amplitude = steps * MANOEUVRE_STEP_DEG
            if reverses:
                kind = f"zigzag, rudder about {amplitude:g}"
            else:
                kind = f"turn, rudder about {side * amplitude:+g}"
            notes.append(
                f"held-out run {names[i] if names else i} ({kind} deg) is the only one of its "
                "kind: its score is an extrapolation"
            )
    return sorted(held), notes


def bic(rss: Mapping[str, float], n: int, k: int) -> float:
    """Gaussian (unknown-variance) BIC ``sum_ch n log(RSS_ch / n) + k log(n_ch n)``."""
    return sum(n * math.log(max(s, 1e-30) / n) for s in rss.values()) + k * math.log(
        max(len(rss), 1) * n
    )


def errors(
    rec: Record, sim: Mapping[str, np.ndarray], sl: slice | np.ndarray = slice(None)
) -> dict[str, float]:
    """RMS errors of simulated channels against the record over the samples ``sl``.

    ``sim`` maps channel names (``psi``, ``r`` and optionally ``x``, ``y``, ``u``) to simulated
    series: ``psi_rms_deg``, ``r_rms_deg_s``, ``xy_rms_m`` (distance), ``u_rms_m_s``.
    """
    e_psi = wrap(sim["psi"][sl] - rec.psi[sl])
    out = {
        "psi_rms_deg": math.degrees(float(np.sqrt(np.mean(e_psi**2)))),
        "r_rms_deg_s": math.degrees(float(np.sqrt(np.mean((sim["r"][sl] - rec.r[sl]) ** 2)))),
    }
    if "x" in sim and rec.x is not None and rec.y is not None:
        d2 = (sim["x"][sl] - rec.x[sl]) ** 2 + (sim["y"][sl] - rec.y[sl]) ** 2
        out["xy_rms_m"] = float(np.sqrt(np.mean(d2)))
    if "u" in sim and rec.u is not None:
        out["u_rms_m_s"] = float(np.sqrt(np.mean((sim["u"][sl] - rec.u[sl]) ** 2)))
    return out


def ljung_box(e: np.ndarray, lags: int) -> float:
    """Ljung-Box ``Q`` of the residual ``e`` over ``lags`` lags (chi-square under whiteness)."""
    e = e - e.mean()
    n = e.size
    d = float(e @ e)
    if d <= 0:
        return 0.0
    q = 0.0
    for k in range(1, min(lags, n - 1) + 1):
        rho = float(e[k:] @ e[:-k]) / d
        q += rho * rho / (n - k)
    return n * (n + 2) * q


def xcorr(e: np.ndarray, u: np.ndarray, lag: int) -> float:
    """Normalised cross-correlation of ``e(t)`` with ``u(t - lag)``."""
    e = e - e.mean()
    u = u - u.mean()
    den = math.sqrt(float(e @ e) * float(u @ u))
    if den <= 0 or lag >= e.size:
        return 0.0
    return float(e[lag:] @ u[: e.size - lag]) / den


def jsonable(obj: Any) -> Any:
    """Plain-Python copy of nested dicts/lists of numbers (NaN and inf become None)."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, bool | np.bool_):
        return bool(obj)
    if isinstance(obj, int | np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        return float(obj) if math.isfinite(obj) else None
    return obj


# --------------------------------------------------------------------------------------------
# the recorded rudder and the rudder the ship feels


@kernel
def _gear_kernel(x0, cmd, p, h, out):  # pragma: no cover - jit
    """:meth:`ShipModel.simulate` of a ``nomoto1`` model with inputs ``(cmd[k], 0)``, compiled.

    The same RK4 steps (:func:`shipgym.models.integrate.rk4_block_nomoto`, no current); writes the
    rudder state ``x[IDELTA]`` at every step into ``out`` (length ``cmd.size + 1``).
    """
    nx = x0.shape[0]
    x = np.empty((nx, 1))  # a block of one ship (states x ships)
    for j in range(nx):
        x[j, 0] = x0[j]
    u = np.zeros((2, 1))
    c = np.zeros((NC, 1))  # no current, no seaway load
    work = np.empty((3, nx, 1))
    out[0] = x[IDELTA, 0]
    for k in range(cmd.shape[0]):
        u[0, 0] = cmd[k]
        rk4_block_nomoto(nomoto1_col, x, u, p, c, h, 1, work)
        out[k + 1] = x[IDELTA, 0]


def lag_filter(
    t: np.ndarray,
    u: np.ndarray,
    T_d: float,
    y0: float | None = None,
    gear: SteeringGear | None = None,
) -> np.ndarray:
    """The recorded rudder ``u`` as a command through the project's steering gear.

    :class:`shipgym.models.SteeringGear` with time constant ``T_d`` and the angle and rate
    limits of ``gear`` (default 35 deg, 2.32 deg/s, seed 002 eq. 2), simulated with the steps
    of :meth:`ShipModel.simulate` (compiled) on a fine grid (step at most 0.1 s, the command held
    over each step) and read back at ``t``.

    Parameters
    ----------
    t : numpy.ndarray
        Sample times [s].
    u : numpy.ndarray
        Recorded rudder [rad], the gear's command.
    T_d : float
        Gear time constant [s].
    y0 : float, optional
        Initial actual rudder [rad] (``u[0]`` by default).
    gear : SteeringGear, optional
        The ship's angle and rate limits (its time constant is replaced by ``T_d``).

    Returns
    -------
    numpy.ndarray
        The actual rudder [rad] at ``t``.
    """
    dt = float(np.median(np.diff(t)))
    m = max(1, math.ceil(dt / 0.1 - 1e-9))
    h = dt / m
    n = max(1, math.ceil((t[-1] - t[0]) / h - 1e-9))
    tf = t[0] + h * np.arange(n + 1)
    gear = replace(gear or SteeringGear(), time_constant=T_d)
    model = make_model("nomoto1", Nomoto1Params(), gear=gear)
    x0 = np.zeros(model.nx)
    x0[IDELTA] = u[0] if y0 is None else y0
    rudder = np.empty(n + 1)
    _gear_kernel(x0, np.interp(tf[:-1], t, u), model.p, h, rudder)
    return np.interp(t, tf, rudder)


def shift(t: np.ndarray, u: np.ndarray, tau: float) -> np.ndarray:
    """``u(t - tau)`` by linear interpolation, the first sample held before the start (the
    :class:`shipgym.models.delay.DelayLine` of a simulated ship)."""
    return np.interp(t - tau, t, u, left=u[0])


def actual_rudder(
    t: np.ndarray,
    delta: np.ndarray,
    *,
    rudder_offset: float = 0.0,
    rudder_lag: float | None = None,
    input_delay: float = 0.0,
    gear: SteeringGear | None = None,
    y0: float | None = None,
) -> np.ndarray:
    """The rudder the ship feels, from the recorded one, under the actuator causes.

    The recorded rudder is delayed by ``input_delay`` (:func:`shift`), passed as the order of a
    steering gear of time constant ``rudder_lag`` (:func:`lag_filter`, with ``gear``'s limits
    and initial angle ``y0``) and shifted by the zero error ``rudder_offset``, in that order (a
    simulated ship: :class:`~shipgym.models.delay.DelayLine`, then its gear, the offset on its
    order).

    Parameters
    ----------
    t, delta : numpy.ndarray
        Sample times [s] and recorded rudder [rad].
    rudder_offset : float
        Zero error ``delta0`` [rad].
    rudder_lag : float, optional
        Gear time constant ``T_d`` [s] (None: the record is the actual angle).
    input_delay : float
        Delay ``tau`` [s] (>= 0).
    gear : SteeringGear, optional
        Angle and rate limits of the ship's gear.
    y0 : float, optional
        Initial actual rudder of the lag [rad].

    Returns
    -------
    numpy.ndarray
    """
    d = np.asarray(delta, dtype=np.float64)
    if input_delay > 0.0:
        d = shift(t, d, input_delay)
    if rudder_offset:
        d = d + rudder_offset
    if rudder_lag is not None and rudder_lag > 0.0:
        d = lag_filter(t, d, rudder_lag, y0, gear)
    return d

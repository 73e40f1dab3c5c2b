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
5. ``finish``: whole-record fits, errors, diagnostics and traces of the base and final models.

Families register themselves in :data:`FAMILIES` under their model names (the ``--model`` of
``shipgym identify``); a new family is one new module and one :func:`register` call.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from shipgym.sysid.data import Record

__all__ = [
    "BIC_MARGIN",
    "FAMILIES",
    "TIE_FRACTION",
    "Candidate",
    "Effect",
    "ModelFamily",
    "bic",
    "errors",
    "get_family",
    "jsonable",
    "ljung_box",
    "register",
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
        by :attr:`min_relative_drop`."""
        return bool(delta_j < -BIC_MARGIN and drop > self.min_relative_drop)

    def choose(self, good: Mapping[str, tuple[Candidate, float]]) -> str:
        """The effect to accept among the significant ``name -> (candidate, delta_J)``.

        The most negative ``delta_J`` wins; candidates within :data:`TIE_FRACTION` of it are
        tied and the one adding the fewest parameters wins (a correlated simulation residual
        makes small BIC differences moot).
        """
        best = min(good, key=lambda k: good[k][1])
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

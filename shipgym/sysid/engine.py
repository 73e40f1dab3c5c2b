"""The identification engine: one loop that traces a record's residual to named effects.

For any registered model family (:mod:`shipgym.sysid.families.base`: the Nomoto family,
seed 000/002/004, and the R/V Gunnerus 3-DOF model, seed 001), :func:`identify`

1. fits the base model on the training part of the record (its first ``1 - holdout``) and
   scores it on the held-out part;
2. for each effect of the family's catalogue not yet in the model, fits the augmented model on
   the training part and scores it on the held-out part;
3. accepts the best candidate when its held-out BIC drops by more than
   :data:`~shipgym.sysid.families.base.BIC_MARGIN` **and** its held-out error drops by more than
   the family's ``min_relative_drop`` (a guard against the strongly correlated simulation
   residual, which makes the sample count overstate the information); among candidates within
   :data:`~shipgym.sysid.families.base.TIE_FRACTION` of the best BIC change the one with the
   fewest parameters wins;
4. repeats until no candidate is significant or ``max_effects`` are in, then reports the
   whole-record fits of the base and the final model (:class:`IdentificationResult`), each
   accepted effect with the parameters of the whole-record fit where the family refits them
   (the training-part fit it was accepted with is kept as its evidence, a candidate);
5. judges whether the record determines the final model (the family's
   :meth:`~shipgym.sysid.families.base.ModelFamily.verdict`: standard errors, bounds, signs,
   time constants against the record, conditioning) and reports it as
   :attr:`IdentificationResult.verdict`.

A record without excitation (the rudder never moves, or is held for the whole record while the
ship is already turning; the heading never changes) is refused before any fit
(:func:`~shipgym.sysid.fit.excitation_problems`).

The held-out BIC of ``n`` samples and per-channel residual sums of squares ``RSS_ch`` is the
Gaussian (unknown-variance) ``J = sum_ch n log(RSS_ch / n) + k log(n_ch n)`` with ``k`` the
number of fitted parameters. Every family's specifics (which channels, how a window is replayed,
the effects' terms) live in its module under :mod:`shipgym.sysid.families`.
"""

from __future__ import annotations

import copy
import math
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from shipgym.models import ShipModel, VMMParams
from shipgym.models.model_file import load_model
from shipgym.sysid.consistency import KinematicConsistency, kinematic_consistency
from shipgym.sysid.data import Record
from shipgym.sysid.families.base import (
    Candidate,
    ModelFamily,
    Verdict,
    get_family,
    jsonable,
    window_starts,
)
from shipgym.sysid.fit import excitation_problems, no_excitation_error

__all__ = ["IdentificationResult", "identify"]


@dataclass
class IdentificationResult:
    """Outcome of :func:`identify`.

    Attributes
    ----------
    model : str
        The base model (``"nomoto1"`` ... ``"rvg3dof"``).
    base, final : object
        Whole-record fits of the base and final models (the family's fit object:
        :class:`~shipgym.sysid.fit.FitResult` for the Nomoto family,
        :class:`~shipgym.sysid.families.rvg.RVGFit` for ``rvg3dof``).
    effects : list of dict
        Accepted effects in order: ``{"name", "parameters", "evidence"}``: ``parameters`` of
        the final whole-record fit where the family refits them; ``evidence`` holds the
        held-out scores before/after, the BIC change and, under ``candidate_parameters``, the
        parameters of the training-part fit the effect was accepted with (a candidate, not a
        result).
    diagnostics : dict
        Residual analysis of the base fit under ``"base"`` and of the final fit under
        ``"final"``.
    parameters_before, parameters_after : dict
        Estimated parameters of the base and final models (the effects' own parameters
        included).
    error_before, error_after : dict
        Simulation error of the base and final models over the whole record: ``psi_rms_deg``,
        ``r_rms_deg_s`` and, where the record has them, ``xy_rms_m`` and ``u_rms_m_s``. With
        ``window_s`` the record is cut into consecutive windows, each simulated from the
        measured state; otherwise one free run from the estimated initial state.
    window_s : float or None
        Scoring window [s] (None: whole-record free run).
    heldout : dict
        ``from_s`` (start of the held-out part, seconds from the record start),
        ``error_before`` and ``error_after``: the same errors over the held-out part for the
        models fitted on the training part only; ``path``: the held-out error after the base
        and after each accepted effect; ``record_consistency``: what the record's own yaw rate
        (and velocities) miss of its heading (and track) in the held-out windows, integrated
        from each window's measured start (``psi_rms_deg``, ``xy_rms_m``;
        :mod:`shipgym.sysid.consistency`: a model's heading error and its integrated yaw-rate
        error there add up to at least it), where the windows are known.
    traces : dict
        ``time``, ``split`` (first held-out index), ``window_starts`` (indices) and, per channel,
        ``{"measured", "before", "after"}`` arrays of the whole-record simulations.
    rounds : list of dict
        Every candidate's score per round (for inspection).
    runtime_s : float
        Wall time.
    model_file : dict
        The fitted model as a document the rest of the package reads (``{"vmm": ...}`` for
        the 3-DOF models: :meth:`shipgym.models.VMMParams.load`); empty for the others.
    verdict : Verdict
        Whether the record determines the final model, and if not why (the family's
        :meth:`~shipgym.sysid.families.base.ModelFamily.verdict`).
    """

    model: str
    base: Any
    final: Any
    effects: list[dict[str, Any]]
    diagnostics: dict[str, Any]
    parameters_before: dict[str, float]
    parameters_after: dict[str, float]
    error_before: dict[str, float]
    error_after: dict[str, float]
    window_s: float | None = None
    heldout: dict[str, Any] = field(default_factory=dict)
    traces: dict[str, Any] = field(default_factory=dict)
    rounds: list[dict[str, Any]] = field(default_factory=list)
    runtime_s: float = 0.0
    model_file: dict[str, Any] = field(default_factory=dict)
    verdict: Verdict = field(default_factory=Verdict)

    def ship_model(self) -> ShipModel:
        """The identified ship with its effects (:func:`shipgym.models.model_file.
        load_model` of :attr:`model_file`); the envs take this result as ``model=`` too.

        Raises
        ------
        ValueError
            For a family that writes no model file (``rvg3dof``).
        """
        if not self.model_file:
            raise ValueError(f"a {self.model!r} identification writes no model file")
        return load_model(self.model_file)

    @property
    def effect_names(self) -> list[str]:
        """Names of the accepted effects, in order."""
        return [e["name"] for e in self.effects]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (the ``shipgym identify --json`` document).

        Keys: ``model``, ``parameters_before``, ``error_before``, ``effects`` (``{name,
        parameters, evidence}`` in order), ``parameters``, ``error_after``, ``window_s``,
        ``heldout``, ``rounds``, ``runtime_s``, ``verdict`` (``{"identifiable": bool,
        "reasons": [str, ...]}``) and the entries of :attr:`model_file`. Non-finite numbers
        become ``null``.
        """
        return jsonable(
            {
                **self.model_file,
                "model": self.model,
                "parameters_before": self.parameters_before,
                "error_before": self.error_before,
                "effects": self.effects,
                "parameters": self.parameters_after,
                "error_after": self.error_after,
                "window_s": self.window_s,
                "heldout": self.heldout,
                "rounds": self.rounds,
                "runtime_s": self.runtime_s,
                "verdict": self.verdict.to_dict(),
            }
        )


def _try(family: ModelFamily, ctx: Any, current: Candidate, name: str) -> Candidate | Exception:
    """``family.try_effect``, with a failed fit returned as its exception."""
    try:
        return family.try_effect(ctx, current, name)
    except (ValueError, np.linalg.LinAlgError) as exc:
        return exc


def _check_excitation(runs: Sequence[Record]) -> None:
    """Refuse records from which no model is identifiable (every family's fit goes through here).

    The rudder must move and the heading must change (:func:`~shipgym.sysid.fit.
    excitation_problems`); with several runs, in at least one of them (a straight run beside
    manoeuvres is fine).
    """
    per_run = [excitation_problems(rec.delta, rec.psi, rec.r) for rec in runs]
    common = set.intersection(*({kind for kind, _ in problems} for problems in per_run))
    if not common:
        return
    if len(runs) == 1:
        raise no_excitation_error([text for kind, text in per_run[0] if kind in common])
    words = {"rudder": "the rudder moves", "turn": "the ship turns"}
    raise no_excitation_error(
        [f"{words[kind]} in none of the {len(runs)} runs" for kind in sorted(common)]
    )


def _split_segments(
    runs: list[Record], multi_run: bool, say: Callable[[str], None]
) -> list[Record]:
    """Records split at their gaps (``meta["segments"]``): every segment a run for a family
    that takes several runs, else the longest segment (said)."""
    out: list[Record] = []
    for rec in runs:
        parts = rec.segments()
        if len(parts) == 1 or multi_run:
            out += parts
            continue
        longest = max(parts, key=lambda p: p.duration)
        say(
            f"{rec.meta.get('file') or 'record'} has {len(parts)} segments between gaps; this "
            f"model is fitted to one stretch: the longest, {longest.time[0]:g}-"
            f"{longest.time[-1]:g} s ({longest.n} samples)"
        )
        out.append(longest)
    return out


def _record_consistency(
    runs: Sequence[Record], report: dict[str, Any], window: float | None
) -> dict[str, float] | None:
    """What the records' own rates miss of their heading and track in the held-out windows
    (:func:`~shipgym.sysid.consistency.kinematic_consistency`, each window from its measured
    start): ``psi_rms_deg`` and, with positions and velocities, ``xy_rms_m``; None when the
    held-out windows are not known."""
    held = report.get("heldout") or {}
    traces = report.get("traces") or {}
    parts: list[tuple[KinematicConsistency, np.ndarray]] = []  # (a record, its held windows)
    try:
        if "run_indices" in held:  # several runs: the held-out ones, each cut into windows
            for i in held["run_indices"]:
                rec = runs[i]
                check = kinematic_consistency(rec, window_starts(rec.time, window))
                parts.append((check, np.ones(check.starts.size, dtype=bool)))
        elif "split" in traces and "window_starts" in traces:
            check = kinematic_consistency(runs[0], np.asarray(traces["window_starts"]))
            parts.append((check, check.starts >= traces["split"]))
    except ValueError:  # windows too short to compare
        return None
    parts = [(check, w) for check, w in parts if w.any()]
    if not parts:
        return None
    n = sum(int(np.sum(check.samples[w])) for check, w in parts)
    out = {
        "psi_rms_deg": math.degrees(math.sqrt(sum(
            check.pooled_heading_rms(w) ** 2 * np.sum(check.samples[w]) for check, w in parts
        ) / n)),
    }  # fmt: skip
    if all(check.position_rms is not None for check, _ in parts):
        out["xy_rms_m"] = math.sqrt(sum(
            check.pooled_position_rms(w) ** 2 * np.sum(check.samples[w]) for check, w in parts
        ) / n)  # fmt: skip
    return out


@dataclass
class _Trace:
    """One run of the loop from a base model: the accepted effects and every round's scores."""

    base: Candidate
    current: Candidate
    effects: list[dict[str, Any]]
    rounds: list[dict[str, Any]]
    path: list[dict[str, Any]]


def _trace_effects(
    family: ModelFamily, ctx: Any, base: Candidate, max_effects: int, say: Callable[[str], None]
) -> _Trace:
    """Steps 2-4 of the loop (module docstring) from ``base``."""
    current = base
    path: list[dict[str, Any]] = [{"model": family.name, "heldout_rms": dict(base.heldout_rms)}]
    effects: list[dict[str, Any]] = []
    rounds: list[dict[str, Any]] = []
    while len(effects) < max_effects:
        scored: dict[str, dict[str, Any]] = {}
        good: dict[str, tuple[Candidate, float]] = {}
        names = list(family.candidates(current))
        t0 = time.perf_counter()
        if family.concurrent_candidates and len(names) > 1:
            with ThreadPoolExecutor(max_workers=min(len(names), os.cpu_count() or 1)) as pool:
                outcomes = list(pool.map(lambda n, c=current: _try(family, ctx, c, n), names))
        else:
            outcomes = [_try(family, ctx, current, n) for n in names]
        for name, cand in zip(names, outcomes, strict=True):
            if isinstance(cand, Exception):
                say(f"  {name}: fit failed ({cand})")
                scored[name] = {
                    "delta_J": math.inf,
                    "relative_drop": -math.inf,
                    "significant": False,
                    "error": str(cand),
                }
                continue
            dj, drop = family.compare(current, cand, name)
            ok = family.significant(cand, name, dj, drop)
            scored[name] = {  # the family's scalar extras, never over the engine's own keys
                **{k: v for k, v in cand.extra.items() if isinstance(v, int | float | str)},
                "delta_J": dj,
                "relative_drop": drop,
                "significant": ok,
                "heldout_rms": dict(cand.heldout_rms),
            }
            if ok:
                good[name] = (cand, dj)
            say(f"  {name}: dJ {dj:.1f}, held-out drop {100 * drop:.1f} %, significant {ok}")
        say(f"  ({len(names)} candidates in {time.perf_counter() - t0:.1f} s)")
        rounds.append(scored)
        if not good:
            break
        best = family.choose(good)
        cand = good[best][0]
        before = dict(current.heldout_rms)
        current = family.accept(ctx, current, cand, best)
        # a family's own evidence: its extras named ``evidence_<key>``, reported as ``<key>``
        evidence = {
            k.removeprefix("evidence_"): v
            for k, v in cand.extra.items()
            if k.startswith("evidence_")
        }
        evidence.update(
            delta_J=scored[best]["delta_J"],
            relative_drop=scored[best]["relative_drop"],
            heldout_rms_before=before,
            heldout_rms_after=dict(current.heldout_rms),
        )
        effects.append(
            {
                "name": best,
                "parameters": family.effect_parameters(current.fitted, best),
                "evidence": evidence,
            }
        )
        path.append({"model": f"+ {best}", "heldout_rms": dict(current.heldout_rms)})
        say(f"accepted {best}")

    return _Trace(base, current, effects, rounds, path)


@threadpool_limits.wrap(limits=1, user_api="blas")  # the fits run side by side (pyproject)
def identify(
    record: Record | Sequence[Record],
    model: str | ModelFamily = "nomoto1",
    *,
    holdout: float = 0.3,
    max_effects: int = 3,
    window_s: float | str | None = "auto",
    progress: Callable[[str], None] | None = None,
    particulars: VMMParams | None = None,
) -> IdentificationResult:
    """Fit a base model, then add catalogue effects while the held-out score improves.

    Parameters
    ----------
    record : Record or sequence of Record
        A manoeuvre record, or several runs of one ship for a family that cross-validates
        across runs (``vmm:<term set>``: fitted on some runs, scored on the others). The
        Nomoto family needs ``time``, ``delta``, ``psi``, ``r`` (``x``, ``y`` and a speed
        enable its ``current`` effect); ``rvg3dof`` needs ``rpm``, the azimuth order,
        positions and speeds, as in the Gunnerus sea trials; ``vmm:...`` positions, body
        velocities and thrust or rpm.
    model : str or ModelFamily
        A registered model name (``"nomoto1"``, ``"nomoto2"``, ``"norrbin"``, ``"bech"``,
        ``"rvg3dof"``, ``"vmm:linear"``, ``"vmm:abkowitz"``, ``"vmm:martin"``,
        ``"vmm:martin_simple"``, ``"vmm:norrbin3"``) or a family object.
    holdout : float
        Fraction of the record (its end) kept out of the fits and used for scoring, in
        ``[0.1, 0.6]``; with several runs, that fraction of the runs, each a manoeuvre of a kind
        that a training run also makes (:func:`~shipgym.sysid.families.base.holdout_runs`).
    max_effects : int
        Largest number of effects to add (>= 0).
    window_s : float, "auto" or None
        Score and report in consecutive windows of this many seconds, each simulated from the
        measured state (``"auto"``: the family's default); None: one free run.
    progress : callable, optional
        Called with a one-line message per fit.
    particulars : VMMParams, optional
        The ship of the 3-DOF models (``vmm:<term set>``, ``kvlcc2``): mass, inertia,
        ``x_G``, added masses, e.g. :meth:`VMMParams.from_particulars
        <shipgym.models.vmm.VMMParams.from_particulars>`; by default the family reads them
        from the records (:func:`~shipgym.sysid.families.vmm.vessel_params`). Refused for a
        family that takes none.

    Returns
    -------
    IdentificationResult

    Raises
    ------
    ValueError
        For a bad ``model``, ``holdout``, ``max_effects`` or ``window_s``, a record too short
        to split or lacking the channels the model needs, or a record without excitation
        (``"not identifiable: no excitation: the rudder never moves ..."``: the rudder never
        moves or the heading never changes, in every run).
    """
    t_start = time.perf_counter()
    family = model if isinstance(model, ModelFamily) else get_family(model)
    if particulars is not None:
        if not hasattr(family, "particulars"):
            raise ValueError(
                f"model {family.name!r} takes no particulars; they go with the 3-DOF models "
                "vmm:<term set> and kvlcc2"
            )
        if not isinstance(particulars, VMMParams):
            raise ValueError(
                "particulars must be a shipgym.models.VMMParams (VMMParams.from_particulars"
                f"(...)), got {type(particulars).__name__}"
            )
        family = copy.copy(family)  # the registered family keeps reading the records
        family.particulars = particulars
    runs = list(record) if isinstance(record, list | tuple) else [record]
    for rec in runs:
        if not isinstance(rec, Record):
            raise ValueError(
                f"record must be a shipgym.sysid.data.Record, got {type(rec).__name__}"
            )
    if not runs:
        raise ValueError("identify needs at least one record")
    say = progress or (lambda _msg: None)
    runs = _split_segments(runs, family.multi_run, say)
    if len(runs) > 1 and not family.multi_run:
        raise ValueError(
            f"model {family.name!r} is fitted to one record at a time, got {len(runs)}; the "
            "3-DOF models vmm:<term set> take several runs of one ship"
        )
    model_name = model if isinstance(model, str) else family.name
    if not (
        isinstance(holdout, int | float)
        and not isinstance(holdout, bool)
        and 0.1 <= float(holdout) <= 0.6
    ):
        raise ValueError(f"holdout must be a fraction in [0.1, 0.6], got {holdout!r}")
    if not (
        isinstance(max_effects, int) and not isinstance(max_effects, bool) and max_effects >= 0
    ):
        raise ValueError(f"max_effects must be an integer >= 0, got {max_effects!r}")
    _check_excitation(runs)
    window = family.resolve_window(window_s, max(float(r.time[-1] - r.time[0]) for r in runs))
    ctx = family.prepare(runs if family.multi_run else runs[0], float(holdout), window)
    window = getattr(ctx, "window_s", window)  # a family may resolve "auto" from the record

    t0 = time.perf_counter()
    starts = family.fit_bases(ctx, say)
    say(f"base {family.name}: held-out error {starts[0][1].heldout_error:.4g} "
        f"({time.perf_counter() - t0:.1f} s)")  # fmt: skip
    traced = []
    for c, b in starts:
        if len(starts) > 1:
            say(f"effects on {b.extra.get('structure', f'start {len(traced) + 1}')}")
        traced.append(_trace_effects(family, c, b, max_effects, say))
    outcomes = [(c, t.base, t.current) for (c, _), t in zip(starts, traced, strict=True)]
    best = family.choose_start(outcomes, say)
    ctx, trace = starts[best][0], traced[best]
    base, current, effects = trace.base, trace.current, trace.effects
    rounds, path = trace.rounds, trace.path

    report = family.finish(ctx, base, current, say)
    final_params = report.pop("effect_parameters", None) or {}
    for e in effects:
        if e["name"] in final_params:  # the training-part fit is a candidate, kept as evidence
            e["evidence"]["candidate_parameters"] = e["parameters"]
            e["parameters"] = final_params[e["name"]]
    verdict = Verdict.of(family.verdict(ctx, report))
    if not verdict.identifiable:
        say("not identifiable: " + "; ".join(verdict.reasons))
    report["heldout"]["path"] = path
    consistency = _record_consistency(runs, report, window)
    if consistency is not None:
        report["heldout"]["record_consistency"] = consistency
    return IdentificationResult(
        model=model_name,
        effects=effects,
        window_s=window,
        rounds=rounds,
        runtime_s=time.perf_counter() - t_start,
        verdict=verdict,
        **report,
    )

"""System identification from measured manoeuvring data.

* ``shipgym.sysid.record``: the canonical :class:`Record`, its CSV and the pipeline of arrays in
  any units; ``shipgym.sysid.io``: the loaders, one module per source or kind of file, and
  their registry (:func:`load`, :func:`detect_format`); ``shipgym.sysid.ingest``: the steps
  every loader shares (unit checks, repairs); ``shipgym.sysid.data`` gathers their names.
* ``shipgym.sysid.consistency``: whether a record's rate channels integrate to its heading and
  track (what a model fitted to both must miss of one or the other).
* ``shipgym.sysid.fit``: equation-error and output-error fits of the Nomoto-family models with
  standard errors (seed 000, seed 002 eq. 4-5, seed 004 eq. 1-4).
* ``shipgym.sysid.recursive``: recursive least squares with forgetting and the adaptive
  backstepping identifier of seed 002.
* ``shipgym.sysid.engine``: the identification loop (:func:`identify`): a base model, then the
  effects of its family's catalogue while the held-out score improves.
* ``shipgym.sysid.families``: the model families of the loop (``nomoto``: the Nomoto family
  and :func:`residual_diagnostics`; ``rvg``: the R/V Gunnerus 3-DOF model), registered by model
  name.
* ``shipgym.sysid.generator``: synthetic records with one undeclared effect of the catalogue,
  the known truth for testing identification.
"""

import shipgym.sysid.families  # noqa: F401 (registers the model families of identify)
from shipgym.sysid.data import (
    FORMATS,
    Record,
    SysidDataWarning,
    derive_yaw_rate,
    detect_format,
    load,
    load_all,
)
from shipgym.sysid.engine import IdentificationResult, identify
from shipgym.sysid.families.nomoto import residual_diagnostics
from shipgym.sysid.fit import FitResult, fit_equation_error, fit_output_error
from shipgym.sysid.generator import EFFECTS, generate_record
from shipgym.sysid.recursive import BacksteppingIdentifier, RecursiveLeastSquares, run_rls

__all__ = [
    "EFFECTS",
    "FORMATS",
    "BacksteppingIdentifier",
    "FitResult",
    "IdentificationResult",
    "Record",
    "RecursiveLeastSquares",
    "SysidDataWarning",
    "derive_yaw_rate",
    "detect_format",
    "fit_equation_error",
    "fit_output_error",
    "generate_record",
    "identify",
    "load",
    "load_all",
    "residual_diagnostics",
    "run_rls",
]

"""System identification from measured manoeuvring data (issue 4).

* ``shipgym.sysid.data``: the canonical :class:`Record` and the loaders of the measured sources.
* ``shipgym.sysid.fit``: equation-error and output-error fits of the Nomoto-family models with
  standard errors (seed 000, seed 002 eq. 4-5, seed 004 eq. 1-4).
* ``shipgym.sysid.recursive``: recursive least squares with forgetting and the adaptive
  backstepping identifier of seed 002.
* ``shipgym.sysid.effects``: residual diagnosis and the effect-catalogue loop
  (:func:`identify`) for the Nomoto family.
* ``shipgym.sysid.generator``: synthetic records with one undeclared effect of the catalogue,
  the known truth for testing identification.
"""

from shipgym.sysid.data import (
    FORMATS,
    Record,
    SysidDataWarning,
    derive_yaw_rate,
    detect_format,
    load,
    load_all,
)
from shipgym.sysid.effects import IdentificationResult, identify, residual_diagnostics
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

"""Measured manoeuvring data in one import: the canonical record and the loaders.

The names of the record type and of the loaders, gathered where the rest of the package and its
users import them:

* :class:`Record` and its canonical CSV: :mod:`shipgym.sysid.record`;
* :func:`load`, :func:`detect_format`, :data:`FORMATS`, :func:`load_all`,
  :func:`measured_root`: the loaders, one module per source, and their registry
  (:mod:`shipgym.sysid.io`);
* :class:`SysidDataWarning`, :func:`derive_yaw_rate`, :func:`wrap_angle`, the repair
  tolerances and the progress printers: the steps every loader shares
  (:mod:`shipgym.sysid.ingest`, whose docstring gives the repair and unit-check rules).
"""

from shipgym.sysid.ingest import (
    HEADING_GLITCH_TOL,
    HEADING_SPIKE_TOL,
    LARGE_RECORD_SAMPLES,
    PROGRESS_FILE_BYTES,
    ProgressArg,
    SysidDataWarning,
    derive_yaw_rate,
    progress_printer,
    wrap_angle,
)
from shipgym.sysid.io import (
    FORMATS,
    MEASURED_DATA_ENV,
    detect_format,
    load,
    load_all,
    measured_root,
)
from shipgym.sysid.record import Record

__all__ = [
    "FORMATS",
    "HEADING_GLITCH_TOL",
    "HEADING_SPIKE_TOL",
    "LARGE_RECORD_SAMPLES",
    "MEASURED_DATA_ENV",
    "PROGRESS_FILE_BYTES",
    "ProgressArg",
    "Record",
    "SysidDataWarning",
    "derive_yaw_rate",
    "detect_format",
    "load",
    "load_all",
    "measured_root",
    "progress_printer",
    "wrap_angle",
]

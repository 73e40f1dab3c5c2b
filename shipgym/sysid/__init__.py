"""System identification from measured manoeuvring data (issue 4).

``shipgym.sysid.data``: the canonical :class:`Record` and the loaders of the measured sources.
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

__all__ = [
    "FORMATS",
    "Record",
    "SysidDataWarning",
    "derive_yaw_rate",
    "detect_format",
    "load",
    "load_all",
]

"""Loaders of manoeuvre records: one module per source or kind of file, and a registry.

:func:`load` reads a file of any registered format into a canonical
:class:`~shipgym.sysid.record.Record` (its format detected by :func:`detect_format` unless
given); :data:`FORMATS` names the formats. Each format is a
:class:`~shipgym.sysid.io.registry.SourceFormat` (loader, header sniffer, path test) in
:data:`~shipgym.sysid.io.registry.REGISTRY`; :func:`~shipgym.sysid.io.registry.register` adds
one. The steps every loader shares (reading text, parsing numbers, unit checks, repairs) are in
:mod:`shipgym.sysid.ingest`; the record itself, its canonical CSV and the pipeline of arrays in
any units in :mod:`shipgym.sysid.record`. No loader imports another.

=========== ===================================== ==============================================
format      module                                what
=========== ===================================== ==============================================
sspa        :mod:`shipgym.sysid.io.sspa`          SSPA blog zigzag (model scale)
marin       :mod:`shipgym.sysid.io.marin`         MARIN KVLCC2 free running (full scale)
hsva        :mod:`shipgym.sysid.io.hsva`          HSVA KVLCC2 model tests (model scale)
esso_osaka  :mod:`shipgym.sysid.io.esso_osaka`    Esso Osaka free-running model tests
usv         :mod:`shipgym.sysid.io.usv`           USV field tests
gunnerus    :mod:`shipgym.sysid.io.gunnerus`      R/V Gunnerus sea trials
canonical   :mod:`shipgym.sysid.io.canonical`     the record's own CSV (:meth:`Record.to_csv`)
nmea        :mod:`shipgym.sysid.io.nmea`          NMEA 0183 logs of a ship's own sensors
table       :mod:`shipgym.sysid.io.table`         any delimited table with a column map or
                                                  headers that state their units
=========== ===================================== ==============================================

Every source is converted to the record's units and sign convention (positive rudder turns the
ship to starboard, heading clockwise from north); each module's docstring gives its
conversions.
"""

from shipgym.sysid.io import (
    canonical,
    esso_osaka,
    gunnerus,
    hsva,
    marin,
    nmea,
    sspa,
    table,
    usv,
)
from shipgym.sysid.io.measured import MEASURED_DATA_ENV, load_all, measured_root
from shipgym.sysid.io.registry import REGISTRY, SourceFormat, detect_format, load, register

__all__ = [
    "FORMATS",
    "MEASURED_DATA_ENV",
    "REGISTRY",
    "SourceFormat",
    "detect_format",
    "load",
    "load_all",
    "measured_root",
    "register",
]

for _module in (sspa, marin, hsva, esso_osaka, usv, gunnerus, canonical, nmea, table):
    register(_module.FORMAT)

FORMATS: tuple[str, ...] = tuple(REGISTRY)
"""The built-in formats of :func:`load`, in the order detection asks them: the six measured
sources, the canonical CSV, NMEA 0183 logs and any delimited ``table``."""

"""Model families of the identification engine (:mod:`shipgym.sysid.engine`).

Importing this package registers every family in
:data:`shipgym.sysid.families.base.FAMILIES`: the Nomoto family (``nomoto1``, ``nomoto2``,
``norrbin``, ``bech``; :mod:`.nomoto`) the R/V Gunnerus 3-DOF model (``rvg3dof``;
:mod:`.rvg`) and seed 003's general 3-DOF models of several runs (``vmm:<term set>``;
:mod:`.vmm`).
"""

from shipgym.sysid.families import nomoto, rvg, vmm
from shipgym.sysid.families.base import FAMILIES, Candidate, Effect, ModelFamily, get_family

__all__ = ["FAMILIES", "Candidate", "Effect", "ModelFamily", "get_family", "nomoto", "rvg", "vmm"]

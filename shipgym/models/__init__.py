"""Pure vessel dynamics: parameters, batched state derivatives, actuators, current, RK4.

Every model is one Numba kernel shared by all users; see :mod:`shipgym.models.integrate`.

The Python API (:func:`make_model`, the :class:`ShipModel` methods, ``integrate.rhs`` and
``integrate.rk4_step``, ``vmm.term_monomials``, :func:`current_ned`, :func:`ssa`) checks its
arguments before any kernel sees them and raises ``TypeError`` or ``ValueError`` naming what was
wrong and what was expected; it never returns NaN from finite input. The compiled per-ship
kernels (``*_col``, ``*_row``, ``rk4_block``, ``rk4_stages``, the kinematics helpers) are for
compiled code and take their arguments unchecked.
"""

from shipgym.models.angles import ssa
from shipgym.models.base import (
    MODEL_NAMES,
    NOMOTO_MODEL_NAMES,
    ShipModel,
    SimulationResult,
    make_model,
)
from shipgym.models.current import Current, current_ned
from shipgym.models.mmg import MMGParams
from shipgym.models.nomoto import (
    BechParams,
    Nomoto1Params,
    Nomoto2Params,
    NorrbinParams,
    SteeringGear,
    SurgeModel,
)
from shipgym.models.rvg import RVGParams
from shipgym.models.vmm import VMMParams

__all__ = [
    "MODEL_NAMES",
    "NOMOTO_MODEL_NAMES",
    "BechParams",
    "Current",
    "MMGParams",
    "Nomoto1Params",
    "Nomoto2Params",
    "NorrbinParams",
    "RVGParams",
    "ShipModel",
    "SimulationResult",
    "SteeringGear",
    "SurgeModel",
    "VMMParams",
    "current_ned",
    "make_model",
    "ssa",
]

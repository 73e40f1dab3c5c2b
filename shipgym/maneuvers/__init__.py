"""Standard manoeuvring trials: zigzag, turning circle, pull-out, spiral and the IMO criteria.

Every trial runs on every model of :mod:`shipgym.models` (``nomoto1``, ``nomoto2``, ``norrbin``,
``bech``, ``rvg3dof``, ``kvlcc2``, ``vmm`` and an identified model file) through
:meth:`ShipModel.simulate <shipgym.models.ShipModel.simulate>` with a controller callback; no
physics is copied here. The ship starts on a straight course
(heading north, ``psi0 = 0``) at its service speed in calm water, and the trial's "rudder" is:

* **Nomoto family**: the rudder command ``delta_c`` through the steering gear (35 deg,
  2.32 deg/s, 2 s), shaft speed held at its service value. Positive rudder turns to starboard.
* **R/V Gunnerus** (``rvg3dof``): the common azimuth of both pods, each at its service thrust
  (25 kN), through the pod servos (1 s, 10 deg/s). A positive azimuth on the aft pods turns
  the ship to port (seed 001 eq. 19-20), so the trials use the *equivalent rudder*
  ``delta_equivalent = -azimuth``: a positive "rudder" is a starboard turn for every model.
* **KVLCC2** (``kvlcc2``, the MMG standard model of the 7 m model): the rudder command through
  its steering gear (35 deg, 15.7 deg/s: the full-scale 2.32 deg/s Froude-scaled), the
  propeller at the model's self-propulsion point at the SIMMAN 2008 approach speed, 1.179 m/s.
  A model-test ship of any other length (``kvlcc2``, ``vmm``) runs on this rig Froude-scaled.

The trials follow the definitions of ITTC and IMO MSC/Circ.1053 (Explanatory Notes to
MSC.137(76)); each module of this package states the definitions it implements:

* ``zigzags``: the zigzag a/b (Kempf's Z-manoeuvre; seed 000), :func:`zigzag`.
* ``turning``: the turning circle (seed 002 Fig. 1, Tables 1 and 3), :func:`turning_circle`,
  and the initial turning test (MSC.137(76) 5.3.2), :func:`initial_turning`.
* ``pullouts``: the pull-out, :func:`pullout`.
* ``spirals``: the direct (Dieudonné) and reverse (Bech) spiral (seed 002; seed 004 Fig. 1),
  :func:`spiral`.
* ``imo``: the criteria of MSC.137(76) section 5.3, :func:`imo_criteria`, :func:`imo_rows`,
  :func:`overshoot_limits` and the table, :func:`format_imo_table`.
* ``measure``: the trial quantities of any time series, simulated or measured,
  :func:`zigzag_quantities` and :func:`turning_quantities`.
* ``plots``: a figure of each trial, :func:`plot_zigzag`, :func:`plot_turning_circle`,
  :func:`plot_pullout`, :func:`plot_spiral` and :func:`plot_imo`.
* ``particulars``: the length, beam and trial speed of each ship, :data:`PARTICULARS`.

Every name is imported from this package (``from shipgym.maneuvers import zigzag``).
Ship length and approach speed are in :data:`PARTICULARS` (Mariner L = 160.93 m,
U = 7.7 m/s; R/V Gunnerus L = 33.9 m, U = 5.144 m/s). Inside everything is SI and radians;
degrees appear only in ``to_dict()`` keys named ``*_deg``, in the IMO table and in plots.
Plots are written with :class:`matplotlib.figure.Figure` and the Agg canvas (no pyplot state).
"""

from __future__ import annotations

from shipgym.maneuvers import _common, particulars
from shipgym.maneuvers._common import ModelLike as ModelLike
from shipgym.maneuvers._common import Progress as Progress
from shipgym.maneuvers._common import TimeSeries
from shipgym.maneuvers.imo import (
    IMOReport,
    IMORow,
    format_imo_table,
    imo_criteria,
    imo_rows,
    overshoot_limits,
    print_imo_table,
)
from shipgym.maneuvers.measure import turning_quantities, zigzag_quantities
from shipgym.maneuvers.particulars import ShipParticulars
from shipgym.maneuvers.plots import (
    plot_imo,
    plot_pullout,
    plot_spiral,
    plot_turning_circle,
    plot_zigzag,
)
from shipgym.maneuvers.pullouts import PullOutResult, pullout
from shipgym.maneuvers.spirals import SpiralResult, spiral
from shipgym.maneuvers.turning import (
    InitialTurningResult,
    TurningResult,
    initial_turning,
    turning_circle,
)
from shipgym.maneuvers.zigzags import ZigZagResult, zigzag

#: Model name -> ship particulars (Mariner: Fossen 1994 section 2.2; Gunnerus: seed 001;
#: KVLCC2: the L7 model at the SIMMAN 2008 speed, Yasukawa and Yoshimura 2015).
PARTICULARS = particulars.PARTICULARS
#: The two sides of a trial, ``("starboard", "port")``: of the first rudder execute or the turn.
SIDES = _common.SIDES

__all__ = [
    "PARTICULARS",
    "SIDES",
    "IMOReport",
    "IMORow",
    "InitialTurningResult",
    "PullOutResult",
    "ShipParticulars",
    "SpiralResult",
    "TimeSeries",
    "TurningResult",
    "ZigZagResult",
    "format_imo_table",
    "imo_criteria",
    "imo_rows",
    "initial_turning",
    "overshoot_limits",
    "plot_imo",
    "plot_pullout",
    "plot_spiral",
    "plot_turning_circle",
    "plot_zigzag",
    "print_imo_table",
    "pullout",
    "spiral",
    "turning_circle",
    "turning_quantities",
    "zigzag",
    "zigzag_quantities",
]

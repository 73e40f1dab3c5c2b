"""Main particulars of the trial ships: length, beam and trial speed.

The length ``L`` and the trial (service) speed ``U`` scale the trials (distances in ship
lengths) and set the IMO ratio ``L / U`` of the overshoot limits (MSC.137(76) 5.3.3). Sources:
Mariner class cargo ship, Fossen 1994 section 2.2; R/V Gunnerus, seed 001; KVLCC2, the L7
model at the SIMMAN 2008 approach speed (Yasukawa and Yoshimura 2015).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["PARTICULARS", "ShipParticulars"]


@dataclass(frozen=True)
class ShipParticulars:
    """Main particulars used to scale the trials and the IMO criteria.

    Attributes
    ----------
    vessel : str
        Name of the ship.
    length : float
        Length between perpendiculars ``L`` [m].
    beam : float
        Breadth [m] (plots only).
    speed : float
        Trial (service) speed ``U`` [m/s] of the IMO ratio ``L / U``.
    """

    vessel: str
    length: float
    beam: float
    speed: float

    @property
    def length_over_speed(self) -> float:
        """``L / U`` [s], the time to travel one ship length."""
        return self.length / self.speed


_MARINER = ShipParticulars("Mariner class cargo ship", 160.93, 23.17, 7.7)
_GUNNERUS = ShipParticulars("R/V Gunnerus", 33.9, 9.6, 5.144)
_KVLCC2 = ShipParticulars("KVLCC2 (7 m model)", 7.0, 1.27, 1.179)
# published with its sources as shipgym.maneuvers.PARTICULARS
PARTICULARS: dict[str, ShipParticulars] = {
    "nomoto1": _MARINER,
    "nomoto2": _MARINER,
    "norrbin": _MARINER,
    "bech": _MARINER,
    "rvg3dof": _GUNNERUS,
    "kvlcc2": _KVLCC2,
}

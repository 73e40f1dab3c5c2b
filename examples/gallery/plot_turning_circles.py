"""
Turning circles of the models
=============================

A 35 deg turning circle to starboard of the Mariner under three of its yaw models. The steady
yaw rate of the linear first-order Nomoto model grows in proportion to the rudder, so at full
rudder it turns on the tightest circle; the cubic yaw terms of Norrbin's and Bech's models
limit the yaw rate at large rudder angles and widen it. Tracks in ship lengths, as the IMO
criteria measure them (advance at most 4.5 L, tactical diameter at most 5 L); the plot shows
the first full turn.
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgym.maneuvers import turning_circle

fig, ax = plt.subplots(figsize=(6, 6), layout="constrained")
for model in ("nomoto1", "norrbin", "bech"):
    result = turning_circle(model, rudder_deg=35.0)
    length = result.particulars.length
    series = result.series
    first_turn = np.abs(series.psi - series.psi[0]) <= 2.0 * np.pi  # the first full turn
    ax.plot(series.y[first_turn] / length, series.x[first_turn] / length, label=model)
    print(
        f"{model:8s} advance {result.advance / length:.2f} L, "
        f"tactical diameter {result.tactical_diameter / length:.2f} L, "
        f"steady diameter {result.steady_diameter / length:.2f} L"
    )
ax.set_aspect("equal")
ax.set_xlabel("east [ship lengths]")
ax.set_ylabel("north [ship lengths]")
ax.set_title("35 deg turning circle to starboard, Mariner")
ax.legend()
plt.show()

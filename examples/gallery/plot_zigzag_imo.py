"""
Zigzag trial and the IMO manoeuvring criteria
=============================================

The 20/20 zigzag (Kempf's Z-manoeuvre) on the nonlinear Mariner model (Bech's), then every
trial of IMO resolution MSC.137(76) (turning circle, initial turning, 10/10 and 20/20 zigzags,
to both sides) and the table of criteria. Angles are radians inside the results; the table
and the plot show degrees.
"""

import matplotlib.pyplot as plt
import numpy as np

from shipgym.maneuvers import format_imo_table, imo_criteria, zigzag

# %%
# The zigzag: the rudder goes to 20 deg starboard and is reversed each time the heading has
# changed 20 deg; the overshoots are measured after each reversal.
result = zigzag("bech", a_deg=20.0)
print("overshoots [deg]:", np.round(np.degrees(result.overshoots), 2))
print(f"initial turning time {result.initial_turning_time:.1f} s")

series = result.series
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
ax.plot(series.time, np.degrees(series.psi - series.psi[0]), label="heading change")
ax.plot(series.time, np.degrees(series.delta), label="rudder angle")
ax.axhline(20.0, color="k", ls=":", lw=0.8)
ax.axhline(-20.0, color="k", ls=":", lw=0.8)
ax.set_xlabel("time from the first execute [s]")
ax.set_ylabel("[deg]")
ax.legend(loc="lower right")
ax.set_title("20/20 zigzag, Mariner (Bech model)")
plt.show()

# %%
# The IMO check: each criterion takes the worse side.
report = imo_criteria("bech")
print(format_imo_table(report))
print("all criteria met:", report.passed)

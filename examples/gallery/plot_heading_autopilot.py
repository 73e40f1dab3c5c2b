"""
Heading autopilot on an environment
===================================

A PID heading autopilot designed by pole placement on the first-order Nomoto model of the
Mariner (:meth:`controllers.HeadingAutopilot.from_nomoto`) steers the
``shipgym/NomotoHeading-v0`` environment through a 30 deg course change. The controller takes
measurements (heading, yaw rate) and returns a rudder angle in radians; the environment takes
that angle as a fraction of its 35 deg limit.
"""

import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np

import shipgym  # noqa: F401  (registers the environments)
from controllers import HeadingAutopilot
from shipgym.models import Nomoto1Params

# %%
# The design model: the Mariner's first-order Nomoto gain and time constant, the loop at
# 1 s steps like the environment, the command limited to the rudder's 35 deg.
ship = Nomoto1Params()
max_rudder = np.radians(35.0)
pilot = HeadingAutopilot.from_nomoto(ship.K, ship.T, dt=1.0, max_command=max_rudder)
print(f"K = {ship.K} 1/s, T = {ship.T} s")

# %%
# One episode in calm water: start on north, then hold a heading of 30 deg. The heading and
# yaw rate come from ``info["state"]`` (names in ``env.unwrapped.state_names``).
env = gym.make("shipgym/NomotoHeading-v0")
setpoint = np.radians(30.0)
obs, info = env.reset(
    seed=0,
    options={"current_speed": 0.0, "initial_state": {"psi": 0.0}, "setpoints": [setpoint]},
)
names = env.unwrapped.state_names
i_psi, i_r, i_delta = names.index("psi"), names.index("r"), names.index("delta")
pilot.reset(0.0, 0.0)
t, psi, rudder, rewards = [], [], [], []
for k in range(400):
    state = info["state"]
    command = pilot.update(float(k), state[i_psi], state[i_r], setpoint)
    obs, reward, terminated, truncated, info = env.step(np.array([command / max_rudder]))
    t.append(k + 1.0)
    psi.append(info["state"][i_psi])
    rudder.append(info["state"][i_delta])
    rewards.append(reward)
env.close()
psi = np.degrees(psi)
overshoot = psi.max() - 30.0
print(f"overshoot {overshoot:.2f} deg, mean reward {np.mean(rewards):.4f}")

# %%
# The response: the reference model shapes the turn, so the heading reaches 30 deg with a
# small overshoot and the rudder stays within its limits.
fig, (ax_psi, ax_delta) = plt.subplots(2, 1, sharex=True, figsize=(7, 5), layout="constrained")
ax_psi.plot(t, psi, label="heading")
ax_psi.axhline(30.0, color="k", ls="--", lw=0.8, label="setpoint")
ax_psi.set_ylabel("heading [deg]")
ax_psi.legend()
ax_delta.plot(t, np.degrees(rudder), color="tab:red")
ax_delta.set_ylabel("rudder angle [deg]")
ax_delta.set_xlabel("time [s]")
fig.suptitle("NomotoHeading-v0 with a pole-placement PID autopilot")
plt.show()

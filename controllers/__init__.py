"""Classic autopilots and guidance laws (independent of shipgym.envs)."""

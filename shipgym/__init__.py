"""shipgym: ship manoeuvring environments, vessel models, classic control and identification.

``import shipgym`` registers the Gymnasium environments (see :mod:`shipgym.envs`).
"""

from shipgym.envs import CURRENT_ENV_IDS, ENV_IDS, register_envs

__version__ = "0.1.0"

register_envs()

__all__ = ["CURRENT_ENV_IDS", "ENV_IDS", "__version__", "register_envs"]

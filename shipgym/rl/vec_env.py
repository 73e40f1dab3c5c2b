"""stable-baselines3 ``VecEnv`` adapter over shipgym's NumPy-batched vector envs.

SB3 steps its environments through :class:`stable_baselines3.common.vec_env.VecEnv`. Its own
``DummyVecEnv`` loops over single envs in Python and ``SubprocVecEnv`` starts a process per env;
:class:`ShipgymVecEnv` instead drives one :class:`shipgym.envs.core.ShipVectorEnv`, so one
kernel call steps every sub-env. The vector env runs with same-step autoreset
(``AutoresetMode.SAME_STEP``), which is SB3's contract: the observation after a finished
episode is the new episode's first one, the finished episode's last observation is in
``infos[i]["terminal_observation"]``, and ``infos[i]["TimeLimit.truncated"]`` says the episode
was cut by the time limit (so SB3 bootstraps its value). The vector env's own ``info`` (state,
current, task metrics, ``final_info``) is not copied into SB3's per-env dicts: that would cost
a Python dict per sub-env per step. So the adapter has the vector env skip building it
(``step_info=False``): a third less time per step with 8 sub-envs.

Seeding follows SB3: ``seed(s)`` makes the next ``reset()`` seed sub-env ``i`` with ``s + i``,
which is the scenario of a single env reset with seed ``s + i``. With ``fixed_seed=s`` every
``reset()`` reseeds that way, so an evaluation env shows the same episodes at every evaluation.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env.base_vec_env import VecEnv, VecEnvIndices, VecEnvStepReturn

import shipgym  # noqa: F401  (registers the environments)
from shipgym.envs import ENV_IDS


class ShipgymVecEnv(VecEnv):
    """``num_envs`` sub-envs of ``env_id`` stepped by one batched kernel, as an SB3 ``VecEnv``.

    Parameters
    ----------
    env_id : str
        One of :data:`shipgym.envs.ENV_IDS`.
    num_envs : int
        Number of sub-envs (>= 1).
    fixed_seed : int, optional
        If given, every ``reset()`` seeds sub-env ``i`` with ``fixed_seed + i``.
    reset_options : dict, optional
        Options for every reset the caller makes, e.g. a current; SB3's ``set_options``
        overrides them for the next reset. Autoresets draw fresh scenarios unless
        ``keep_options``.
    keep_options : bool
        If True, every autoreset uses the options of the last reset too (the vector env's
        ``keep_options``), so every episode of the run has e.g. the given current.
    **env_kwargs
        Keyword arguments of the env (e.g. ``max_current_speed``).

    Notes
    -----
    The adapter records no episode statistics of its own. SB3 reads episode returns and
    lengths from a ``Monitor`` (``info["episode"]``): wrap the adapter in SB3's
    :class:`~stable_baselines3.common.vec_env.VecMonitor` wherever they are read, for
    ``evaluate_policy``, the ``rollout/ep_rew_mean`` of training logs and ``EvalCallback``.
    Bare, ``evaluate_policy`` warns that the env is not wrapped with a ``Monitor`` and
    returns no episode reward it could check.

    Examples
    --------
    Evaluate a policy on 4 sub-envs, every evaluation on the same episodes (seeds 100 to 103):

    >>> from stable_baselines3 import PPO
    >>> from stable_baselines3.common.evaluation import evaluate_policy
    >>> from stable_baselines3.common.vec_env import VecMonitor
    >>> from shipgym.rl.vec_env import ShipgymVecEnv
    >>> env = VecMonitor(ShipgymVecEnv("shipgym/RVGHeading-v1", num_envs=4, fixed_seed=100))
    >>> model = PPO("MlpPolicy", env, seed=0)
    >>> returns, lengths = evaluate_policy(model, env, n_eval_episodes=4,
    ...                                    return_episode_rewards=True)
    >>> [int(n) for n in lengths]  # every episode ran to the time limit
    [600, 600, 600, 600]

    ``returns[i]`` is the sum of the rewards of an episode: with ``fixed_seed``, that of a
    single env ``gymnasium.make("shipgym/RVGHeading-v1")`` reset with seed ``100 + i`` and
    stepped with the same actions. Training wraps it the same way, with ``VecNormalize``
    outside the ``VecMonitor`` (so the monitor sums the unnormalised rewards).
    """

    def __init__(
        self,
        env_id: str,
        num_envs: int = 16,
        fixed_seed: int | None = None,
        reset_options: dict[str, Any] | None = None,
        keep_options: bool = False,
        **env_kwargs: Any,
    ) -> None:
        if env_id not in ENV_IDS:
            raise ValueError(f"unknown env {env_id!r}; expected one of {ENV_IDS}")
        if not isinstance(num_envs, int | np.integer) or num_envs < 1:
            raise ValueError(f"num_envs must be an integer >= 1, got {num_envs!r}")
        self.env_id = env_id
        self.venv = gym.make_vec(
            env_id,
            num_envs=int(num_envs),
            vectorization_mode="vector_entry_point",
            autoreset_mode=AutoresetMode.SAME_STEP,
            keep_options=keep_options,
            step_info=False,
            **env_kwargs,
        )
        self.fixed_seed = fixed_seed
        self.reset_options = dict(reset_options or {})
        super().__init__(
            int(num_envs), self.venv.single_observation_space, self.venv.single_action_space
        )
        self._actions: np.ndarray | None = None

    def reset(self) -> np.ndarray:
        seed = self._seeds[0] if self._seeds[0] is not None else self.fixed_seed
        options = self._options[0] or self.reset_options  # SB3's set_options() first
        obs, _ = self.venv.reset(seed=seed, options=options or None)
        self._reset_seeds()
        self._reset_options()
        self.reset_infos = [{} for _ in range(self.num_envs)]
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> VecEnvStepReturn:
        obs, rewards, terminated, truncated, info = self.venv.step(self._actions)
        dones = terminated | truncated
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for i in np.flatnonzero(dones):
            infos[i]["terminal_observation"] = info["final_obs"][i]
            infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return obs, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        self.venv.close()

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        value = getattr(self.venv, attr_name)
        return [value for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        setattr(self.venv, attr_name, value)

    def env_method(
        self,
        method_name: str,
        *method_args: Any,
        indices: VecEnvIndices = None,
        **method_kwargs: Any,
    ) -> list[Any]:
        result = getattr(self.venv, method_name)(*method_args, **method_kwargs)
        return [result for _ in self._get_indices(indices)]

    def env_is_wrapped(
        self, wrapper_class: type[gym.Wrapper], indices: VecEnvIndices = None
    ) -> list[bool]:
        return [False for _ in self._get_indices(indices)]

    def get_images(self) -> Sequence[np.ndarray | None]:
        return [None for _ in range(self.num_envs)]

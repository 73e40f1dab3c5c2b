"""The trained agents shipgym ships, and the policy adapter that runs them in evaluations.

Each agent is a stable-baselines3 ``.zip`` with a JSON record beside it (written by
:func:`shipgym.rl.train.train`): budget, seeds, wall time, hyperparameters, learning curve and
the observation normaliser the policy was trained behind. :func:`load_agent` returns an
:class:`AgentPolicy`, which normalises the observation exactly as SB3's ``VecNormalize`` did
in training (``clip((obs - mean) / sqrt(var + eps), -clip, clip)``) and acts
deterministically, with the ``reset``/``act`` interface of every policy of
:func:`shipgym.benchmark.evaluate`.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.rl.train import ALGOS, agent_name

#: Folder of the shipped agents.
AGENT_DIR = Path(__file__).resolve().parent / "agents"


def _import_sb3() -> Any:
    try:
        import stable_baselines3
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise ImportError(
            "the RL agents need stable-baselines3 and torch: pip install 'shipgym[rl]'"
        ) from exc
    return stable_baselines3


def agent_files(env_id: str, algo: str, directory: str | Path | None = None) -> tuple[Path, Path]:
    """Paths of the ``.zip`` and ``.json`` of an agent (shipped ones by default)."""
    if algo not in ALGOS:
        raise ValueError(f"unknown algorithm {algo!r}; expected one of {ALGOS}")
    folder = AGENT_DIR if directory is None else Path(directory)
    stem = agent_name(env_id, algo)
    return folder / f"{stem}.zip", folder / f"{stem}.json"


def load_meta(env_id: str, algo: str, directory: str | Path | None = None) -> dict[str, Any]:
    """The JSON record of an agent."""
    _, meta_path = agent_files(env_id, algo, directory)
    if not meta_path.is_file():
        raise FileNotFoundError(
            f"no {algo} agent for {env_id} in {meta_path.parent} (missing {meta_path.name}); "
            f"train one with: shipgym train --env {env_id} --algo {algo} --out DIR"
        )
    return json.loads(meta_path.read_text())


class AgentPolicy:
    """A trained SB3 agent as an evaluation policy (deterministic actions).

    Parameters
    ----------
    model : stable_baselines3 BaseAlgorithm
        The loaded agent.
    meta : dict
        Its JSON record (needs ``obs_normaliser``).
    """

    def __init__(self, model: Any, meta: dict[str, Any]) -> None:
        norm = meta["obs_normaliser"]
        self.model = model
        self.meta = meta
        # evaluation only: eval mode once, not at every call as ``predict`` switches it
        model.policy.set_training_mode(False)
        self._layers = self._mlp_layers(model.policy)
        self.mean = np.asarray(norm["mean"], dtype=np.float64)
        self.scale = 1.0 / np.sqrt(np.asarray(norm["var"], dtype=np.float64) + norm["epsilon"])
        self.clip = float(norm["clip"])
        expected = model.observation_space.shape
        if self.mean.shape != expected:
            raise ValueError(
                f"{meta.get('name', 'agent')}: normaliser of shape {self.mean.shape} does not "
                f"match the policy's observation shape {expected}"
            )

    def normalise(self, obs: np.ndarray) -> np.ndarray:
        """The observation as the policy saw it in training."""
        z = (np.asarray(obs, dtype=np.float64) - self.mean) * self.scale
        return np.clip(z, -self.clip, self.clip).astype(np.float32)

    def _deterministic(self, obs: Any) -> Any:
        """The policy network's deterministic action tensor for an observation tensor.

        For the MLP policies SB3 builds (a flattening feature extractor, ``Linear`` layers with
        ``Tanh`` or ``ReLU``): the mean of the Gaussian head, PPO's ``action_net`` output or
        SAC's ``mu`` squashed by tanh, computed layer by layer with the same torch operations
        the modules run (:attr:`_layers`), so the very tensors SB3's ``_predict`` returns
        through its action distribution; without the distribution and the modules' call
        machinery, which took twice the network's own time on a block of 64 rows. Another
        policy runs SB3's ``_predict``.
        """
        import torch

        if self._layers is None:
            return self.model.policy._predict(obs, deterministic=True)
        x = obs
        for kind, layer in self._layers:
            if kind == "linear":
                x = torch.nn.functional.linear(x, layer.weight, layer.bias)
            elif kind == "relu":
                x = torch.relu(x)
            else:
                x = torch.tanh(x)
        return x

    @staticmethod
    def _mlp_layers(policy: Any) -> list[tuple[str, Any]] | None:
        """The deterministic action path of an SB3 MLP policy as ``(kind, module)`` pairs
        (``"linear"``, ``"tanh"``, ``"relu"``), or None for any other policy."""
        from stable_baselines3.common.distributions import DiagGaussianDistribution
        from stable_baselines3.common.torch_layers import FlattenExtractor
        from torch import nn

        actor = getattr(policy, "actor", None)
        if actor is not None and hasattr(actor, "mu") and not actor.use_sde:  # SAC
            extractor, body = actor.features_extractor, actor.latent_pi
            head, squash = actor.mu, True
        elif hasattr(policy, "action_net") and isinstance(
            getattr(policy, "action_dist", None), DiagGaussianDistribution
        ):  # PPO, A2C
            extractor, body = policy.pi_features_extractor, policy.mlp_extractor.policy_net
            head, squash = policy.action_net, False
        else:
            return None
        kinds = {nn.Linear: "linear", nn.Tanh: "tanh", nn.ReLU: "relu"}
        modules = [*body, head] if isinstance(body, nn.Sequential) else None
        if not isinstance(extractor, FlattenExtractor) or modules is None:
            return None
        if any(type(m) not in kinds for m in modules):
            return None
        layers = [(kinds[type(m)], m) for m in modules]
        return [*layers, ("tanh", None)] if squash else layers

    def act_batch(self, obs: np.ndarray) -> np.ndarray:
        """Deterministic actions for a batch of observations, shape ``(n, act_dim)``.

        The arithmetic of SB3's ``policy.predict`` (the same network, clipping or
        unsquashing; :meth:`_deterministic`), without its per-call switch to evaluation mode,
        which walks every module of the network.
        """
        import torch

        policy = self.model.policy
        # (the float32 array as it is: what SB3's obs_to_tensor makes of a Box observation)
        obs_tensor = torch.from_numpy(self.normalise(obs).reshape(-1, *self.mean.shape))
        with torch.no_grad():
            actions = self._deterministic(obs_tensor)
        actions = actions.cpu().numpy().reshape((-1, *policy.action_space.shape))
        if policy.squash_output:
            actions = policy.unscale_action(actions)
        else:
            actions = np.clip(actions, policy.action_space.low, policy.action_space.high)
        return np.asarray(actions, dtype=np.float32)

    def reset(self, env: Any, obs: np.ndarray, info: dict[str, Any]) -> None:
        """Nothing to reset: the policy is memoryless."""

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """Deterministic action for one observation."""
        return self.act_batch(obs[None, :])[0]


def load_agent(env_id: str, algo: str, directory: str | Path | None = None) -> AgentPolicy:
    """Load the ``algo`` agent of ``env_id`` (shipped, or from ``directory``).

    Raises
    ------
    FileNotFoundError
        When the agent's files are missing (the message says how to train one).
    ImportError
        When stable-baselines3 is not installed.
    """
    meta = load_meta(env_id, algo, directory)
    model_path, _ = agent_files(env_id, algo, directory)
    if not model_path.is_file():
        raise FileNotFoundError(
            f"{model_path} is missing (its record {model_path.stem}.json is there)"
        )
    if meta.get("env") != env_id or meta.get("algo") != algo:
        raise ValueError(
            f"{model_path.with_suffix('.json')} records env {meta.get('env')!r} and algorithm "
            f"{meta.get('algo')!r}, expected {env_id!r} and {algo!r}"
        )
    sb3 = _import_sb3()
    cls = {"ppo": sb3.PPO, "sac": sb3.SAC}[algo]
    model = cls.load(model_path, device="cpu")
    return AgentPolicy(model, meta)

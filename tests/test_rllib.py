"""The envs under RLlib (the ``rllib`` extra; the whole file skips without it).

RLlib pins an older Gymnasium than the one the rest of the suite runs on, so the test extra
leaves it out and CI runs this file in a venv of its own (``pip install ".[rllib]"``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from shipgym.cluster import ray_session

pytest.importorskip("ray.rllib", reason="RLlib is not installed (pip install 'shipgym[rllib]')")

# one worker runs this file: its local Ray is started once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_rllib")


@pytest.fixture(scope="module")
def local_ray(tmp_path_factory: pytest.TempPathFactory):
    # RLlib builds torch optimisers in the driver and in Ray's workers, which makes torch
    # create its compiler cache folder (by default torchinductor_<user> in the temporary
    # directory); the workers inherit this variable from the driver when Ray starts
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("TORCHINDUCTOR_CACHE_DIR", str(tmp_path_factory.mktemp("torchinductor")))
        with ray_session(num_cpus=2) as ray:
            yield ray


def test_rllib_remote_env_runner_makes_the_env_from_the_prefixed_id(
    local_ray, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """RLlib's env runners are fresh processes that never import shipgym: the id with its module
    prefix (``shipgym:``) imports it there; one PPO iteration on one remote runner."""
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.tune.trainable import trainable

    # an algorithm outside Tune logs into ~/ray_results: keep the test's folder there instead
    monkeypatch.setattr(trainable, "DEFAULT_STORAGE_PATH", str(tmp_path))

    config = (
        PPOConfig()
        .environment("shipgym:shipgym/NomotoHeading-v0")
        .env_runners(num_env_runners=1, num_envs_per_env_runner=1, rollout_fragment_length=64)
        .training(train_batch_size_per_learner=64, minibatch_size=32, num_epochs=1)
        .rl_module(model_config={"fcnet_hiddens": [16]})
        .debugging(seed=0)
    )
    algo = config.build_algo()
    try:
        result = algo.train()
    finally:
        algo.stop()
    runners = result["env_runners"]
    assert runners["num_env_steps_sampled_lifetime"] >= 64
    assert result["num_env_steps_sampled_lifetime"] >= 64

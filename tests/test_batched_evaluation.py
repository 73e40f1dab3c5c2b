"""Batched evaluation gives the numbers of the episode-by-episode evaluation it replaced.

``tests/data/benchmark_cells_reference.json`` holds, for every cell of the default benchmark
(each env, controller and condition), the per-episode returns, metrics, lengths and
termination reasons of the first four benchmark seeds as the evaluation of commit 0868dfb
computed them: one single env (``gymnasium.make``) stepped episode after episode, the classic
controllers on Python floats, one ``info`` dict logged per step. It was written by running
``_cell_batch(...).run()`` of ``shipgym.benchmark.runner`` for every cell at that commit and
keeping ``to_dict()``'s ``returns``, ``per_episode``, ``termination`` and ``length``.

The terminations must match exactly, and the lengths, returns and metrics bit for bit, as
they do on the CPU the reference was made on. On another CPU numpy's vectorised sines and
arctangents (its SIMD dispatch: AVX-512 there, AVX2 on another machine) can differ in the last
bit, and over a closed-loop episode of the path-following task under the classic LOS
controllers that bit grows. Measured on an AVX2 machine: every other cell bit for bit, and in 6
of the 21 path-following cells the returns up to 0.54 % off and the lengths up to 7 of 800
steps. A cell whose returns are not bitwise the reference's must still have its terminations,
its returns within 1 % and its lengths within 1 %; its metrics are then not compared.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from shipgym.benchmark.runner import STRESS_FACTOR, _cell_batch, training_max_current
from shipgym.envs import CURRENT_ENV_IDS
from shipgym.rl.train import BENCHMARK_SEED

REFERENCE = json.loads(
    (Path(__file__).parent / "data" / "benchmark_cells_reference.json").read_text()
)["cells"]
EPISODES = len(REFERENCE[0]["returns"])
PORTABLE_RTOL = 1e-2
"""Relative tolerance of the returns and lengths across CPUs (module docstring)."""


def _same(got: list[float], want: list[float], what: str, rtol: float = 0.0) -> bool:
    """Whether ``got`` is bitwise ``want``; fails unless it is within ``rtol`` of it."""
    got_a = np.asarray(got, dtype=float)
    want_a = np.asarray(want, dtype=float)
    assert got_a.shape == want_a.shape, what
    assert np.array_equal(np.isnan(got_a), np.isnan(want_a)), what
    assert np.allclose(got_a, want_a, rtol=rtol, atol=0.0, equal_nan=True), (
        f"{what}: {got_a.tolist()} != {want_a.tolist()}"
    )
    return bool(np.array_equal(got_a, want_a, equal_nan=True))


@pytest.mark.parametrize("env_id", CURRENT_ENV_IDS)
def test_every_benchmark_cell_gives_the_reference_numbers(env_id: str) -> None:
    stress = STRESS_FACTOR * training_max_current(env_id)
    cells = [c for c in REFERENCE if c["env"] == env_id]
    assert cells
    for ref in cells:
        label = ref["condition"]
        result = _cell_batch(
            env_id, label.split(":")[0], label, stress, ref["controller"], EPISODES,
            BENCHMARK_SEED, None, 0,
        ).run()  # fmt: skip
        what = f"{env_id} {ref['controller']} {label}"
        assert result.terminations == ref["termination"], what
        if _same(result.returns, ref["returns"], f"{what} returns", PORTABLE_RTOL):
            assert result.lengths == ref["length"], what
            for key, values in ref["per_episode"].items():
                _same(result.values(key).tolist(), values, f"{what} {key}")
        else:  # another CPU's last bits (module docstring)
            _same(result.lengths, ref["length"], f"{what} lengths", PORTABLE_RTOL)
        assert not any(math.isnan(r) for r in result.returns) or result.blown_up, what


class _OneAtATime:
    """Hides a policy's batch methods: :func:`evaluate` runs its episodes one by one through
    ``reset``/``act`` (for a classic policy: its controllers as a batch of one ship)."""

    def __init__(self, policy: object) -> None:
        self.policy = policy

    def reset(self, env, obs, info) -> None:
        self.policy.reset(env, obs, info)

    def act(self, obs, info):
        return self.policy.act(obs, info)


@pytest.mark.parametrize("env_id", ["shipgym/RVGPathFollowing-v1", "shipgym/RVGTargetTracking-v1"])
def test_a_classic_policy_one_ship_at_a_time_gives_the_batch_numbers(env_id: str) -> None:
    from shipgym.benchmark import evaluate, make_policy

    batch = evaluate(env_id, make_policy("classic", env_id), "classic", 3, BENCHMARK_SEED,
                     progress=lambda line: None)  # fmt: skip
    alone = evaluate(env_id, _OneAtATime(make_policy("classic", env_id)), "classic", 3,
                     BENCHMARK_SEED, progress=lambda line: None)  # fmt: skip
    assert alone.lengths == batch.lengths
    assert alone.returns == batch.returns  # bitwise: the same controllers, one row at a time
    for key in batch.per_episode[0]:
        _same(alone.values(key).tolist(), batch.values(key).tolist(), key)


def test_an_agent_one_episode_at_a_time_gives_the_lockstep_numbers() -> None:
    from shipgym.benchmark import evaluate
    from shipgym.rl.agents import load_agent

    env_id = "shipgym/RVGPathFollowing-v0"  # episodes of different lengths (early ends)
    agent = load_agent(env_id, "ppo")
    batched = evaluate(env_id, agent, "ppo", 3, BENCHMARK_SEED, progress=lambda line: None)
    single = evaluate(env_id, _OneAtATime(agent), "ppo", 3, BENCHMARK_SEED,
                      progress=lambda line: None)  # fmt: skip
    assert [log.seed for log in batched.logs] == [BENCHMARK_SEED + k for k in range(3)]
    assert [log.steps for log in batched.logs] == [log.steps for log in single.logs]
    # a block of 64 rows against a block holding one row: matrix kernels may round differently
    np.testing.assert_allclose(batched.returns, single.returns, rtol=1e-4)


class _FailsOnRow:
    """A memoryless policy whose network fails on the row of one seed (``s % 64``)."""

    def __init__(self, seed: int) -> None:
        self.row = seed % 64

    def reset(self, env, obs, info) -> None:
        self.act_dim = env.action_space.shape[-1]

    def act_batch(self, obs: np.ndarray) -> np.ndarray:
        if np.any(obs[self.row] != 0.0):
            raise RuntimeError("bad row")
        return np.zeros((len(obs), self.act_dim), dtype=np.float32)


def test_a_failing_batched_policy_names_the_episode_it_failed_on() -> None:
    from shipgym.benchmark import evaluate
    from shipgym.benchmark.evaluate import EpisodeError

    with pytest.raises(EpisodeError) as info:
        evaluate("shipgym/RVGHeading-v1", _FailsOnRow(102), "custom", 5, 100,
                 progress=lambda line: None)  # fmt: skip
    assert info.value.seeds == (102,)
    assert "episode with seed 102 failed: RuntimeError: bad row" in str(info.value)

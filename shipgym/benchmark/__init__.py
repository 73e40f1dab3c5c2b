"""Evaluation of controllers on the shipgym environments: scenarios, metrics and the benchmark.

:func:`~shipgym.benchmark.evaluate.evaluate` runs any policy (the classic controllers of
:mod:`controllers`, the trained PPO/SAC agents of :mod:`shipgym.rl`, the neutral ``zero``
command) on identical seeds and current draws and reports the metrics of ``shipgym evaluate``;
:func:`~shipgym.benchmark.runner.run_benchmark` does so for every env, controller and
condition (``shipgym benchmark``).
"""

from shipgym.benchmark.evaluate import EpisodeLog, EvaluationResult, evaluate
from shipgym.benchmark.policies import POLICIES, make_policy

__all__ = ["POLICIES", "EpisodeLog", "EvaluationResult", "evaluate", "make_policy"]

"""Evaluation of controllers on the shipgym environments: scenarios, metrics and the runner.

:func:`~shipgym.benchmark.evaluate.evaluate` runs any policy (the classic controllers of
:mod:`controllers`, the neutral ``zero`` command, later the RL agents) on identical seeds and
current draws and reports the metrics of ``shipgym evaluate``.
"""

from shipgym.benchmark.evaluate import EpisodeLog, EvaluationResult, evaluate
from shipgym.benchmark.policies import POLICIES, make_policy

__all__ = ["POLICIES", "EpisodeLog", "EvaluationResult", "evaluate", "make_policy"]

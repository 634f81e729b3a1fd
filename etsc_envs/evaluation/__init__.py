"""The benchmark: scenario sets run in batch or episode by episode, their statistics with 95 %
intervals, the verdicts of one comparison, and the leaderboard as data.

* :func:`evaluate` and :class:`Evaluation` (:mod:`~etsc_envs.evaluation.run`): any trigger
  on the protocol's scenario sets, compared with the paper's rule on the same scenarios;
* :func:`leaderboard` (:mod:`~etsc_envs.evaluation.leaderboard`): the rows of
  ``docs/leaderboard.md``;
* :func:`~etsc_envs.evaluation.verdict.compare`: every verdict the suite prints;
* the pieces they run on: :mod:`~etsc_envs.evaluation.batch` (a set in one native vector
  env), :mod:`~etsc_envs.evaluation.episodes` (one episode and its record),
  :mod:`~etsc_envs.evaluation.policy_specs` (``--policy`` specs),
  :mod:`~etsc_envs.evaluation.statistics` (SciPy and rliable intervals),
  :mod:`~etsc_envs.evaluation.progress` and :mod:`~etsc_envs.evaluation.arguments`.
"""

from etsc_envs.evaluation.leaderboard import LeaderboardRow, SetMeasure, leaderboard
from etsc_envs.evaluation.run import Evaluation, EvaluationInterrupted, evaluate
from etsc_envs.evaluation.verdict import Verdict, compare

__all__ = [
    "Evaluation",
    "EvaluationInterrupted",
    "LeaderboardRow",
    "SetMeasure",
    "Verdict",
    "compare",
    "evaluate",
    "leaderboard",
]

"""Judging on the protocol's scenario sets: verdicts against the paper's rule and the clock
(:mod:`~agents.judge.results`), fronts (:mod:`~agents.judge.pareto`,
:mod:`~agents.judge.front`), learning curves and the leaderboard."""

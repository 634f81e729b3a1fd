"""Learning triggers for the etsc-envs environments, one sub-package per job.

- :mod:`agents.train`: Stable-Baselines3 training of transmit/hold and self-triggered policies
  (``python -m agents.train --config configs/train/NAME.yaml``; keys in
  :mod:`agents.train.config`), with elapsed-time discounting, the validation callback and
  the vector-env adapter.
- :mod:`agents.search`: CMA-ES over a paper's parametric trigger family
  (``python -m agents.search --config configs/search/NAME.yaml``).
- :mod:`agents.sweep`: fronts over penalties and seeds on Ray Tune or in worker processes
  (``python -m agents.sweep --config configs/sweeps/NAME.yaml``).
- :mod:`agents.judge`: judging on the protocol's scenario sets: verdicts
  (``python -m agents.results``), fronts, learning curves and the leaderboard
  (``python -m agents.leaderboard``).
- :mod:`agents.bench`: throughput benchmarks of decisions and of judging.
"""

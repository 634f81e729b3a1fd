"""Stable-Baselines3 training of trigger policies (``python -m agents.train``).

:mod:`~agents.train.training` runs a config (:mod:`~agents.train.config`) and writes models
that ``python -m baselines.evaluate ENV_ID --policy sb3:PATH`` loads.
"""

"""Stable-Baselines3 training of learned trigger policies for the etsc-envs environments.

``python -m agents.train --config configs/train/NAME.yaml`` trains one model from a YAML config
(see :mod:`agents.config` for its keys) and saves a plain SB3 zip that
``python -m baselines.evaluate ENV_ID --policy sb3:PATH_TO_ZIP`` can load.
"""

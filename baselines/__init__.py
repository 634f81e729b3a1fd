"""The evaluation and reproduction commands, run from the checkout (``python -m
baselines.evaluate``); the reference trigger policies they run live in
:mod:`etsc_envs.triggers`, installed with the package."""

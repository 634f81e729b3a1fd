"""Barrier-triggered orbit keeping near asteroid Itokawa in polyhedral gravity (paper 003).

The environment is :class:`etsc_envs.asteroid.env.AsteroidOrbitKeepingEnv`; the package
imports nothing itself, so that ``python -m etsc_envs.asteroid.shape`` and
``python -m etsc_envs.asteroid.gravity_grid`` run their modules cleanly.
"""

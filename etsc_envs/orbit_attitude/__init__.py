"""Coupled orbit-attitude tracking with an ESO-based event-triggered controller (paper 000,
Zhang, Biggs, Ye, Sun, IEEE TAES 2019)."""

from etsc_envs.orbit_attitude.env import OrbitAttitudeTrackingEnv
from etsc_envs.orbit_attitude.params import OrbitAttitudeParams

__all__ = ["OrbitAttitudeParams", "OrbitAttitudeTrackingEnv"]

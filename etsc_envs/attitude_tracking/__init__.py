"""Rigid-spacecraft attitude tracking with an event-triggered ESO (paper 002, Cai et al. 2019)."""

from etsc_envs.attitude_tracking.env import AttitudeTrackingEnv
from etsc_envs.attitude_tracking.params import AttitudeTrackingParams

__all__ = ["AttitudeTrackingEnv", "AttitudeTrackingParams"]

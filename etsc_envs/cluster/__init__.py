"""Attitude containment of a microsatellite cluster under directed topology, with one
event-triggered adaptive sliding-mode controller per follower (paper 001)."""

from etsc_envs.cluster.env import ClusterContainmentCentralEnv
from etsc_envs.cluster.parallel_env import ClusterContainmentEnv
from etsc_envs.cluster.params import ClusterContainmentParams

__all__ = ["ClusterContainmentCentralEnv", "ClusterContainmentEnv", "ClusterContainmentParams"]

"""Reference trigger policies: the papers' own triggering rules (one module per problem, looked
up by environment id in :data:`PAPER_TRIGGERS`) and the time-triggered references
:class:`AlwaysPolicy` and :class:`PeriodicPolicy`.

Every policy answers like a Stable-Baselines3 model, ``predict(obs, state=None,
episode_start=None, deterministic=True) -> (action, state)``::

    import gymnasium as gym
    from etsc_envs.triggers import PAPER_TRIGGERS

    env = gym.make("etsc_envs:etsc/AttitudeTracking-v0")
    trigger = PAPER_TRIGGERS["etsc/AttitudeTracking-v0"](
        env.observation_space, env.action_space, observation_names=env.unwrapped.observation_names
    )
"""

from __future__ import annotations

from etsc_envs.triggers.asteroid import AsteroidOrbitKeepingTrigger
from etsc_envs.triggers.attitude_tracking import AttitudeTrackingTrigger
from etsc_envs.triggers.base import AlwaysPolicy, PeriodicPolicy, TriggerPolicy
from etsc_envs.triggers.cluster import ClusterContainmentTrigger
from etsc_envs.triggers.inner_formation import InnerFormationTrigger
from etsc_envs.triggers.orbit_attitude import OrbitAttitudeTrigger

PAPER_TRIGGERS = {
    "etsc/AttitudeTracking-v0": AttitudeTrackingTrigger,
    "etsc/OrbitAttitudeTracking-v0": OrbitAttitudeTrigger,
    "etsc/ClusterContainment-v0": ClusterContainmentTrigger,
    "etsc/ClusterContainmentCentral-v0": ClusterContainmentTrigger,
    "etsc/InnerFormation-v0": InnerFormationTrigger,
    "etsc/AsteroidOrbitKeeping-v0": AsteroidOrbitKeepingTrigger,
}
"""Environment id → the paper's trigger policy class."""

__all__ = [
    "PAPER_TRIGGERS",
    "AlwaysPolicy",
    "AsteroidOrbitKeepingTrigger",
    "AttitudeTrackingTrigger",
    "ClusterContainmentTrigger",
    "InnerFormationTrigger",
    "OrbitAttitudeTrigger",
    "PeriodicPolicy",
    "TriggerPolicy",
]

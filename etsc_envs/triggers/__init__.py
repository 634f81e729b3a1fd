"""Reference trigger policies: the papers' own triggering rules (one module per problem), the
time-triggered references :class:`AlwaysPolicy` and :class:`PeriodicPolicy` (compiled:
:class:`ClockTrigger`; a clock that changes its period once: :class:`SwitchedPeriodicPolicy`),
and other event rules on the same signals (:class:`InnerFormationErrorTimeTrigger`).

Which rule, thresholds and shield belong to an environment id is written in its paper's record
(``etsc_envs/<problem>/paper.py``), looked up with :func:`etsc_envs.papers.paper_of`; the
records import the trigger modules, never the other way round.

Every policy answers like a Stable-Baselines3 model, ``predict(obs, state=None,
episode_start=None, deterministic=True) -> (action, state)``::

    import gymnasium as gym
    from etsc_envs.papers import paper_of

    env = gym.make("etsc_envs:etsc/AttitudeTracking-v0")
    trigger = paper_of("etsc/AttitudeTracking-v0").trigger(
        env.observation_space, env.action_space, observation_names=env.unwrapped.observation_names
    )
"""

from __future__ import annotations

from etsc_envs.triggers.asteroid import AsteroidOrbitKeepingTrigger, AsteroidShield
from etsc_envs.triggers.attitude_tracking import AttitudeTrackingTrigger
from etsc_envs.triggers.base import (
    AlwaysPolicy,
    ClockTrigger,
    PeriodicPolicy,
    SwitchedPeriodicPolicy,
    TriggerPolicy,
)
from etsc_envs.triggers.cluster import ClusterContainmentTrigger
from etsc_envs.triggers.inner_formation import (
    InnerFormationErrorTimeTrigger,
    InnerFormationShield,
    InnerFormationTrigger,
)
from etsc_envs.triggers.orbit_attitude import OrbitAttitudeTrigger

__all__ = [
    "AlwaysPolicy",
    "AsteroidOrbitKeepingTrigger",
    "AsteroidShield",
    "AttitudeTrackingTrigger",
    "ClockTrigger",
    "ClusterContainmentTrigger",
    "InnerFormationErrorTimeTrigger",
    "InnerFormationShield",
    "InnerFormationTrigger",
    "OrbitAttitudeTrigger",
    "PeriodicPolicy",
    "SwitchedPeriodicPolicy",
    "TriggerPolicy",
]

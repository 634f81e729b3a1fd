"""Reference trigger policies: the papers' own triggering rules (one module per problem, looked
up by environment id in :data:`PAPER_TRIGGERS`), the time-triggered references
:class:`AlwaysPolicy` and :class:`PeriodicPolicy` (compiled: :class:`ClockTrigger`; a clock
that changes its period once: :class:`SwitchedPeriodicPolicy`), and other
event rules on the same signals (:data:`ERROR_TIME_TRIGGERS`); :data:`RULE_FAMILIES` names
each family of rules.

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

from collections.abc import Callable

from etsc_envs.triggers.asteroid import PAPER_ALPHA, AsteroidOrbitKeepingTrigger, AsteroidShield
from etsc_envs.triggers.attitude_tracking import PAPER_PSI, AttitudeTrackingTrigger
from etsc_envs.triggers.base import (
    AlwaysPolicy,
    ClockTrigger,
    PeriodicPolicy,
    SwitchedPeriodicPolicy,
    TriggerPolicy,
)
from etsc_envs.triggers.cluster import PAPER_C, ClusterContainmentTrigger
from etsc_envs.triggers.inner_formation import (
    InnerFormationErrorTimeTrigger,
    InnerFormationShield,
    InnerFormationTrigger,
    default_error_time_thresholds,
)
from etsc_envs.triggers.orbit_attitude import PAPER_GAMMA, OrbitAttitudeTrigger

PAPER_TRIGGERS = {
    "etsc/AttitudeTracking-v0": AttitudeTrackingTrigger,
    "etsc/OrbitAttitudeTracking-v0": OrbitAttitudeTrigger,
    "etsc/ClusterContainment-v0": ClusterContainmentTrigger,
    "etsc/ClusterContainmentCentral-v0": ClusterContainmentTrigger,
    "etsc/InnerFormation-v0": InnerFormationTrigger,
    "etsc/AsteroidOrbitKeeping-v0": AsteroidOrbitKeepingTrigger,
}
"""Environment id → the paper's trigger policy class."""


PAPER_THRESHOLDS: dict[str, Callable[[], dict[str, float]]] = {
    "etsc/AttitudeTracking-v0": lambda: {"psi": PAPER_PSI},
    "etsc/OrbitAttitudeTracking-v0": lambda: {"gamma1": PAPER_GAMMA[0], "gamma2": PAPER_GAMMA[1]},
    "etsc/ClusterContainment-v0": lambda: {"c": PAPER_C},
    "etsc/ClusterContainmentCentral-v0": lambda: {"c": PAPER_C},
    "etsc/InnerFormation-v0": InnerFormationTrigger.paper_thresholds,
    "etsc/AsteroidOrbitKeeping-v0": lambda: {"alpha": PAPER_ALPHA},
}
"""Environment id → the keywords of its paper trigger that set how much error it tolerates
before transmitting, at the paper's values (a larger value waits longer; paper 003 nonetheless
fires more bursts with a larger α: a later burst meets a larger drift, and its saturated
correction overshoots, docs/results.md)."""

FAMILY_CLASSES = {
    trigger.__name__: trigger
    for trigger in (
        AttitudeTrackingTrigger,
        OrbitAttitudeTrigger,
        ClusterContainmentTrigger,
        InnerFormationTrigger,
        AsteroidOrbitKeepingTrigger,
    )
}
"""The paper trigger classes whose parametric families exist (:mod:`etsc_envs.triggers.family`),
by class name (a learned trigger file names its family so)."""

ERROR_TIME_TRIGGERS = {"etsc/InnerFormation-v0": InnerFormationErrorTimeTrigger}
"""Environment id → its error-time rule: a channel transmits when its sampling error times the
time since its last transmission passes a threshold (:class:`InnerFormationErrorTimeTrigger`
says why), on the ids whose observation carries a per-channel sampling error."""


def _inner_formation_error_time_thresholds() -> dict[str, float]:
    area1, area2, area3 = default_error_time_thresholds()
    return {"area1": float(area1), "area2": float(area2), "area3": float(area3)}


ERROR_TIME_THRESHOLDS: dict[str, Callable[[], dict[str, float]]] = {
    "etsc/InnerFormation-v0": _inner_formation_error_time_thresholds,
}
"""Environment id → the threshold keywords of its error-time rule at their defaults."""

RULE_FAMILIES = {
    "paper": (PAPER_TRIGGERS, PAPER_THRESHOLDS),
    "error_time": (ERROR_TIME_TRIGGERS, ERROR_TIME_THRESHOLDS),
}
"""Rule name → (environment id → trigger class, environment id → its threshold keywords): the
event rules whose thresholds a self-triggered decision set scales
(:class:`baselines.self_triggered.DecisionSet`'s ``rule``) and :mod:`baselines.evaluate` runs
(``--policy paper`` or ``--policy error_time``)."""

PAPER_SHIELDS = {
    "etsc/InnerFormation-v0": InnerFormationShield,
    "etsc/AsteroidOrbitKeeping-v0": AsteroidShield,
}
"""Environment id → the class of its shield (:class:`InnerFormationShield`'s interface): the
ids whose papers give a condition under which a hold is unsafe."""

__all__ = [
    "ERROR_TIME_THRESHOLDS",
    "ERROR_TIME_TRIGGERS",
    "FAMILY_CLASSES",
    "PAPER_SHIELDS",
    "PAPER_THRESHOLDS",
    "PAPER_TRIGGERS",
    "RULE_FAMILIES",
    "AlwaysPolicy",
    "AsteroidOrbitKeepingTrigger",
    "AsteroidShield",
    "AttitudeTrackingTrigger",
    "ClockTrigger",
    "ClusterContainmentTrigger",
    "InnerFormationErrorTimeTrigger",
    "InnerFormationTrigger",
    "OrbitAttitudeTrigger",
    "PeriodicPolicy",
    "SwitchedPeriodicPolicy",
    "TriggerPolicy",
]

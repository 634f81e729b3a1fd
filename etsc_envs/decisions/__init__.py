"""Self-triggered decisions: at a decision instant an agent chooses how the next interval
transmits, from a decision set that is data (:mod:`~etsc_envs.decisions.actions`: holds of
given lengths and trigger actions, each a rule's parametric family at a point θ; saved as
versioned JSON beside a model). :mod:`~etsc_envs.decisions.schedule` runs a set's semantics
instant by instant, :mod:`~etsc_envs.decisions.wrappers` trains on it (Gymnasium and
PettingZoo ids) and :mod:`~etsc_envs.decisions.policy` deploys a trained model as a
transmit/hold policy::

    import gymnasium as gym
    from etsc_envs.decisions import DecisionSet, SelfTriggeredPolicy

    env = gym.make("etsc_envs:etsc/AttitudeTracking-v0")
    decisions = DecisionSet.load("runs/attitude_tracking_self_triggered/model.zip")
    policy = SelfTriggeredPolicy.for_env(model, decisions, env)  # model: SB3's predict
"""

from etsc_envs.decisions.actions import (
    DECISIONS_SUFFIX,
    DecisionSet,
    Hold,
    TriggerAction,
    decision_set_path,
)
from etsc_envs.decisions.policy import FixedDecision, SelfTriggeredPolicy
from etsc_envs.decisions.schedule import IntervalSchedule, run_decision_interval
from etsc_envs.decisions.wrappers import (
    FollowerDecisionEnv,
    SelfTriggeredWrapper,
    make_decision_env,
)

__all__ = [
    "DECISIONS_SUFFIX",
    "DecisionSet",
    "FixedDecision",
    "FollowerDecisionEnv",
    "Hold",
    "IntervalSchedule",
    "SelfTriggeredPolicy",
    "SelfTriggeredWrapper",
    "TriggerAction",
    "decision_set_path",
    "make_decision_env",
    "run_decision_interval",
]

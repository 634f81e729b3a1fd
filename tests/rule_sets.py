"""Decision sets of the tests, built from a few numbers: holds of 1, 2, 4, ... instants, then
one trigger action per factor f, the rule's family with its scaled thresholds times f
(:func:`rule_set`); and the wrappers, config blocks and training config that take such a
set."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import gymnasium as gym

from etsc_envs.decisions import (
    DecisionSet,
    FollowerDecisionEnv,
    Hold,
    SelfTriggeredPolicy,
    SelfTriggeredWrapper,
    TriggerAction,
)
from etsc_envs.decisions.actions import MAX_INSTANTS
from etsc_envs.papers import rule_of
from etsc_envs.triggers.family import FamilyPoint

ATTITUDE = "etsc/AttitudeTracking-v0"

PerFactor = int | Sequence[int | None] | None
"""One value for every trigger action, one per factor, or none."""


def _per_factor(value: PerFactor, count: int) -> list[int | None]:
    if isinstance(value, Sequence):
        assert len(value) == count, f"one value per factor, got {value!r}"
        return list(value)
    return [value] * count


def rule_set(
    env_id: str,
    max_exponent: int = 10,
    holds: Sequence[int] | None = None,
    factors: Sequence[float] = (0.5, 1.0, 2.0, 4.0),
    rule: str = "paper",
    cap: PerFactor = None,
    send_first: bool = False,
    floor: PerFactor = None,
    channel_heartbeat: PerFactor = None,
    thresholds: Mapping[str, float] | None = None,
    shield_multiple: float | None = None,
) -> DecisionSet:
    """Holds of 2^0 .. 2^``max_exponent`` instants (or of ``holds``), then ``rule``'s family at
    each factor f of ``factors`` (every threshold the rule's "× f" scales, times f), capped at
    ``cap`` (default: the longest hold), with a ``floor`` or a ``channel_heartbeat`` in
    instants, sent first with ``send_first`` or a floor (without holds the cap defaults to the
    longest interval an action may ask for); ``thresholds`` sets other thresholds
    of the rule to these values (their factors of the paper's)."""
    lengths = list(holds) if holds is not None else [2**j for j in range(max_exponent + 1)]
    groups = TriggerAction(rule=rule).scaled_groups(env_id)
    trigger = rule_of(env_id, rule).trigger
    paper = trigger.paper_thresholds()
    own = {kws[0]: group for group, kws in trigger.threshold_groups.items() if len(kws) == 1}
    fixed = {own[name]: value / paper[name] for name, value in (thresholds or {}).items()}
    actions: list[Hold | TriggerAction] = [Hold(length) for length in lengths]
    longest = lengths[-1] if lengths else MAX_INSTANTS
    count = len(factors)
    for factor, limit, least, beat in zip(
        factors,
        _per_factor(cap, count),
        _per_factor(floor, count),
        _per_factor(channel_heartbeat, count),
        strict=True,
    ):
        point = FamilyPoint(
            factors={**{group: float(factor) for group in groups}, **fixed},
            floor_instants=0.0 if least is None else least,
            heartbeat_instants=math.inf if beat is None else beat,
        )
        first = send_first or least is not None
        actions.append(TriggerAction(point, rule, longest if limit is None else limit, first))
    return DecisionSet(env_id, tuple(actions), shield_multiple)


def rule_wrapper(env: gym.Env, gamma: float = 0.99, **numbers: Any) -> SelfTriggeredWrapper:
    """:class:`SelfTriggeredWrapper` over ``env`` with the :func:`rule_set` of ``numbers``."""
    assert env.spec is not None
    return SelfTriggeredWrapper(env, rule_set(env.spec.id, **numbers), gamma=gamma)


def rule_follower(
    env_id: str, env_kwargs: dict[str, Any] | None = None, gamma: float = 0.99, **numbers: Any
) -> FollowerDecisionEnv:
    """:class:`FollowerDecisionEnv` of ``env_id`` with the :func:`rule_set` of ``numbers``."""
    return FollowerDecisionEnv(env_id, rule_set(env_id, **numbers), env_kwargs, gamma=gamma)


def rule_block(env_id: str, **numbers: Any) -> dict[str, Any]:
    """A training config's ``decisions:`` block, the set's own form, of the :func:`rule_set`
    of ``numbers`` for ``env_id``."""
    data = rule_set(env_id, **numbers).to_json()
    return {"shield_multiple": data["shield_multiple"], "actions": data["actions"]}


BASE_CONFIG = {
    "env_id": ATTITUDE,
    "env_kwargs": {"horizon_s": 0.3},
    "algorithm": "PPO",
    "policy": "MlpPolicy",
    "total_timesteps": 32,
    "decisions": rule_block(ATTITUDE, max_exponent=3, factors=[1.0, 4.0]),
}
"""A training config of self-triggered decisions in paper 002 (``out_dir`` to be added)."""


def deployed_policy(model: Any, source: Any, env: Any) -> SelfTriggeredPolicy:
    """``model`` deployed with the decision set of ``source`` (a wrapper, or a set) on ``env``."""
    decisions = getattr(source, "decisions", source)
    return SelfTriggeredPolicy.for_env(model, decisions, env)


def factors_of(decisions: Any) -> tuple[float | None, ...]:
    """The factor f of each trigger action of ``decisions``."""
    return tuple(decisions.actions[i].factor(decisions.env_id) for i in decisions.trigger_indices)


def caps_of(decisions: Any) -> tuple[int, ...]:
    """The cap of each trigger action of ``decisions``."""
    return tuple(decisions.actions[i].cap for i in decisions.trigger_indices)

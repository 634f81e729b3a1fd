"""Decision sets written in version 1's keywords (``max_exponent``, ``factors``, ``rule_cap``,
``rule_heartbeat``, ``rule_floor``, ...), read through :func:`etsc_envs.decisions.decision_set_v1`
into the wrappers that take a set, and into a training config's ``decisions:`` block: the tests of
those keywords' decisions keep their form."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from etsc_envs.decisions import (
    FollowerDecisionEnv,
    SelfTriggeredPolicy,
    SelfTriggeredWrapper,
    decision_set_v1,
)


def v1_wrapper(env: gym.Env, gamma: float = 0.99, **keywords: Any) -> SelfTriggeredWrapper:
    """:class:`SelfTriggeredWrapper` over ``env`` with the set of version-1 ``keywords``."""
    assert env.spec is not None
    return SelfTriggeredWrapper(env, decision_set_v1(env.spec.id, **keywords), gamma=gamma)


def v1_follower(
    env_id: str,
    env_kwargs: dict[str, Any] | None = None,
    gamma: float = 0.99,
    teammate_decision: str | None = None,
    **keywords: Any,
) -> FollowerDecisionEnv:
    """:class:`FollowerDecisionEnv` of ``env_id`` with the set of version-1 ``keywords``."""
    return FollowerDecisionEnv(
        env_id,
        decision_set_v1(env_id, **keywords),
        env_kwargs,
        gamma=gamma,
        teammate_decision=teammate_decision,
    )


def v1_block(env_id: str, **keywords: Any) -> dict[str, Any]:
    """A training config's ``decisions:`` block, the set's own form, of the set of version-1
    ``keywords`` for ``env_id``."""
    data = decision_set_v1(env_id, **keywords).to_json()
    return {"shield_multiple": data["shield_multiple"], "actions": data["actions"]}


def deployed_policy(model: Any, source: Any, env: Any) -> SelfTriggeredPolicy:
    """``model`` deployed with the decision set of ``source`` (a wrapper, or a set) on ``env``."""
    decisions = getattr(source, "decisions", source)
    return SelfTriggeredPolicy.for_env(model, decisions, env)


def factors_of(decisions: Any) -> tuple[float | None, ...]:
    """The factor f of each trigger action of ``decisions`` (version 1's ``factors``)."""
    return tuple(decisions.actions[i].factor(decisions.env_id) for i in decisions.trigger_indices)


def caps_of(decisions: Any) -> tuple[int, ...]:
    """The cap of each trigger action of ``decisions`` (version 1's ``caps``)."""
    return tuple(decisions.actions[i].cap for i in decisions.trigger_indices)

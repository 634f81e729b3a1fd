"""Choose the decision a self-triggered learner starts from, per transmission penalty.

Every action of a :class:`~baselines.self_triggered.DecisionSet` taken at every decision is a
baseline of its own: "hold 2^j" is the clock every 2^j instants, "paper × f" the paper's rule
at f times its threshold (with a heartbeat or a floor where the set pairs them). Which of
them a learner should start from depends on the price of a transmission: the reward of an
episode is ``-Σ cost / cost_scale - λ · transmissions``, so a larger λ favours a sparser
baseline. :func:`select_decision` runs each candidate decision, always taken, on the
protocol's **validation** scenarios (never the test set) with the training env's keywords,
λ among them, and picks the one whose mean return is highest: the best member of the policy
class's fixed decisions at that λ. A front trained from a sweep of λ (``imitation_decision:
best``, :mod:`agents.config`) then starts each λ from its own baseline instead of one label
shared by every λ, so its points move along the transmission axis with λ.

A decision that equals a stand-alone trigger when always taken (:func:`stand_alone_spec`:
"hold N" is the clock every N instants, a plain "paper × f" the rule at f times its
threshold) runs as that trigger, inside the compiled loop (:mod:`baselines.batch`); the others
(a heartbeat, a floor, any action of a shielded set) run through the deployed transmit/hold
policy, one Python call per instant. ``tests/test_decision_selection.py`` checks that both
paths give the same records.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from agents.evaluation import deployment, set_summary
from agents.imitation import FixedDecision
from baselines.batch import run_batch
from baselines.cli import EpisodeSetup, episode_setup
from baselines.self_triggered import DecisionSet, IntervalSchedule, SelfTriggeredPolicy
from etsc_envs.protocol import scenario_set
from etsc_envs.triggers import RULE_FAMILIES

BEST_DECISION = "best"
"""The ``imitation_decision`` that asks :func:`select_decision` to choose per config."""


def stand_alone_spec(decisions: DecisionSet, action: int) -> tuple[str, dict[str, Any]] | None:
    """The stand-alone trigger (``--policy`` name and arguments) whose every action equals
    always taking ``action`` of ``decisions``, where there is one: "hold N" sends every channel
    every N instants from the first (``periodic``, ``every=N``); "paper × f" without a
    heartbeat or a floor lets the rule at f times its threshold decide every instant, the
    decision instants included, and a capped interval hands over to the same rule (the rule
    named by the set, its thresholds scaled). ``None`` for a rule action with a heartbeat or a
    floor (a forced transmission at each decision instant, which no stand-alone trigger of the
    suite sends) and for every action of a shielded set (the shield may replace a choice)."""
    if decisions.shield_multiple is not None:
        return None
    if action < decisions.n_holds:
        return "periodic", {"every": int(decisions.hold_steps[action])}
    if decisions.rule_sends_first:
        return None
    factor = decisions.factors[action - decisions.n_holds]
    thresholds = RULE_FAMILIES[decisions.rule][1][decisions.env_id]()
    return decisions.rule, {name: factor * value for name, value in thresholds.items()}


def constant_decision_policy(
    setup: EpisodeSetup,
    deployed: tuple[IntervalSchedule, gym.Space, gym.Space],
    decisions: DecisionSet,
    action: int,
) -> Any:
    """A transmit/hold policy that always takes ``action`` of ``decisions``: its stand-alone
    trigger where :func:`stand_alone_spec` names one, else the deployed decision policy
    (``deployed``: :func:`agents.evaluation.deployment`'s schedule and spaces)."""
    spec = stand_alone_spec(decisions, action)
    if spec is None:
        return SelfTriggeredPolicy(FixedDecision(action), *deployed)
    return setup.make_policy(*spec)


def select_decision(
    env_id: str,
    env_kwargs: dict[str, Any],
    decisions: DecisionSet,
    set_size: int,
    candidates: list[str] | None = None,
) -> dict[str, Any]:
    """The decision of ``decisions`` with the highest mean return over the first
    ``set_size`` validation scenarios when taken at every decision, among ``candidates``
    (labels; ``None``: every action of the set).

    ``env_kwargs`` are the training env's (the set's ``randomize`` replaces theirs); the
    return is the env's reward summed over the episode, so it prices transmissions at the
    env's ``transmission_penalty``. Ties go to the earlier candidate. Returns ``{"chosen":
    label, "scenarios": the set described, "candidates": {label: set summary}}`` (each summary
    :func:`agents.evaluation.set_summary`'s); ``ValueError`` naming ``imitation_candidates``
    for a label the set lacks.
    """
    labels = (
        [decisions.label(action) for action in range(decisions.action_space.n)]
        if candidates is None
        else list(candidates)
    )
    if not labels:
        raise ValueError("imitation_candidates: name at least one decision")
    try:
        actions = [decisions.action(label) for label in labels]
    except ValueError as error:
        raise ValueError(f"imitation_candidates: {error}") from None
    scenarios = scenario_set("validation", set_size)
    base = {key: value for key, value in env_kwargs.items() if key != "randomize"}
    kwargs = scenarios.env_kwargs(base)
    deployed = deployment(env_id, kwargs, decisions)
    setup = episode_setup(env_id, kwargs)
    try:
        policies = [
            constant_decision_policy(setup, deployed, decisions, action) for action in actions
        ]
    finally:
        setup.env.close()
    summaries = {
        label: set_summary(run_batch(env_id, policy, scenarios.seeds, kwargs))
        for label, policy in zip(labels, policies, strict=True)
    }
    chosen = max(labels, key=lambda label: summaries[label]["return"])
    return {"chosen": chosen, "scenarios": scenarios.describe(), "candidates": summaries}

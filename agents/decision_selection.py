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
"""

from __future__ import annotations

from typing import Any

from agents.evaluation import deployment, set_summary
from agents.imitation import FixedDecision
from baselines.batch import run_batch
from baselines.self_triggered import DecisionSet, SelfTriggeredPolicy
from etsc_envs.protocol import scenario_set

BEST_DECISION = "best"
"""The ``imitation_decision`` that asks :func:`select_decision` to choose per config."""


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
    summaries = {
        label: set_summary(
            run_batch(
                env_id,
                SelfTriggeredPolicy(FixedDecision(action), *deployed),
                scenarios.seeds,
                kwargs,
            )
        )
        for label, action in zip(labels, actions, strict=True)
    }
    chosen = max(labels, key=lambda label: summaries[label]["return"])
    return {"chosen": chosen, "scenarios": scenarios.describe(), "candidates": summaries}

"""Choose the decision a self-triggered learner starts from, per transmission penalty.

Every action of a :class:`~etsc_envs.decisions.DecisionSet` taken at every decision is a
baseline of its own: "hold 2^j" is the clock every 2^j instants, "paper × f" the paper's rule
at f times its threshold (with a heartbeat or a floor where the set pairs them). Which of
them a learner should start from depends on the price of a transmission: the reward of an
episode is ``-Σ cost / cost_scale - λ · transmissions``, so a larger λ favours a sparser
baseline. :func:`select_decision` runs each candidate decision, always taken, on the
protocol's **validation** scenarios (never the test set) with the training env's keywords,
λ among them, and picks the one whose mean return is highest: the best member of the policy
class's fixed decisions at that λ. A front trained from a sweep of λ (``start_from.decision:
best``, :mod:`agents.train.config`) then starts each λ from its own baseline instead of one label
shared by every λ, so its points move along the transmission axis with λ.

A decision that equals a stand-alone trigger when always taken (:func:`stand_alone_spec`:
"hold N" is the clock every N instants, a plain "paper × f" the rule at f times its
threshold) runs as that trigger, inside the compiled loop (:mod:`etsc_envs.evaluation.batch`); the
others (a heartbeat, a floor, any action of a shielded set) run through the deployed transmit/hold
policy, one Python call per instant. ``tests/test_decision_selection.py`` checks that both
paths give the same records.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from agents.train.validation_callback import deployment, set_summary
from etsc_envs.core.files import atomic_write_text
from etsc_envs.decisions import DecisionSet, FixedDecision, Hold, SelfTriggeredPolicy
from etsc_envs.evaluation.batch import run_batch
from etsc_envs.evaluation.episodes import to_jsonable
from etsc_envs.evaluation.policy_specs import EpisodeSetup, episode_setup
from etsc_envs.protocol import scenario_set
from etsc_envs.triggers.family import FamilyPoint, scaled_thresholds

BEST_DECISION = "best"
"""The ``start_from.decision`` that asks :func:`select_decision` to choose per config."""


def stand_alone_spec(decisions: DecisionSet, action: int) -> tuple[str, dict[str, Any]] | None:
    """The stand-alone trigger (``--policy`` name and arguments) whose every action equals
    always taking ``action`` of ``decisions``, where there is one: a hold of N sends every
    channel every N instants from the first (``periodic``, ``every=N``); a trigger action that
    does not send first, whose point is its rule's thresholds scaled (with a heartbeat per
    channel if it has one: ``channel_heartbeat=H``), lets that rule decide every instant, the
    decision instants included, and a capped interval hands over to the same rule. ``None`` for
    other trigger actions (their stand-alone forms answer in Python every instant as the
    decision policy does, so there is nothing to gain) and for every action of a shielded set
    (the shield may replace a choice)."""
    if decisions.shield_multiple is not None:
        return None
    chosen = decisions.actions[action]
    if isinstance(chosen, Hold):
        return "periodic", {"every": chosen.instants}
    point = chosen.point
    plain = FamilyPoint(point.factors, heartbeat_instants=point.heartbeat_instants)
    if chosen.send_first or point != plain:
        return None
    trigger = chosen.trigger_class(decisions.env_id)
    thresholds = scaled_thresholds(trigger, point.factors)
    named = {kw for group in point.factors for kw in trigger.threshold_groups[group]}
    arguments: dict[str, Any] = {
        **{kw: value for kw, value in thresholds.items() if kw in named},
        **chosen.keywords,
    }
    if math.isfinite(point.heartbeat_instants):
        arguments["channel_heartbeat"] = int(point.heartbeat_instants)
    return chosen.rule, arguments


def constant_decision_policy(
    setup: EpisodeSetup,
    deployed: tuple[Any, ...],
    decisions: DecisionSet,
    action: int,
) -> Any:
    """A transmit/hold policy that always takes ``action`` of ``decisions``: its stand-alone
    trigger where :func:`stand_alone_spec` names one, else the deployed decision policy
    (``deployed``: :func:`agents.train.validation_callback.deployment`'s set and spaces)."""
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
    cache_dir: str | Path | None = None,
) -> dict[str, Any]:
    """The decision of ``decisions`` with the highest mean return over the first
    ``set_size`` validation scenarios when taken at every decision, among ``candidates``
    (labels; ``None``: every action of the set).

    ``env_kwargs`` are the training env's (the set's ``randomize`` replaces theirs). The
    return is the env's reward summed over the episode, ``-Σ cost / cost_scale - λ ·
    (channels sent)`` (failures charge the same whatever λ): the candidates run once with no
    price on a transmission, and each one's return at the env's λ is that return less λ times
    its transmissions. Runs that differ in λ alone (a front's trials) may therefore share the
    candidates' runs through ``cache_dir``: a folder holding one JSON file per env (less its
    λ), decision set, scenario set and candidate list, written by the first run that needs it.
    Ties go to the earlier candidate. Returns ``{"chosen": label, "transmission_penalty": λ,
    "scenarios": the set described, "candidates": {label: set summary at λ}}`` (each summary
    :func:`agents.train.validation_callback.set_summary`'s); ``ValueError`` naming
    ``start_from.candidates`` for a label the set lacks.
    """
    labels = (
        [decisions.label(action) for action in range(decisions.action_space.n)]
        if candidates is None
        else list(candidates)
    )
    if not labels:
        raise ValueError("start_from.candidates: name at least one decision")
    try:
        actions = [decisions.action(label) for label in labels]
    except ValueError as error:
        raise ValueError(f"start_from.candidates: {error}") from None
    scenarios = scenario_set("validation", set_size)
    base = {key: value for key, value in env_kwargs.items() if key != "randomize"}
    penalty = transmission_penalty(env_id, scenarios.env_kwargs(base))
    free = scenarios.env_kwargs({**base, "transmission_penalty": 0.0})
    key = {
        "env_id": env_id,
        "env_kwargs": dict(free),
        "decisions": asdict(decisions),
        "scenarios": scenarios.describe(),
        "candidates": labels,
    }
    cached = _cache_file(cache_dir, key)
    if cached is not None and cached.is_file():
        unpriced = json.loads(cached.read_text(encoding="utf-8"))["candidates"]
    else:
        unpriced = _run_candidates(env_id, free, decisions, scenarios.seeds, labels, actions)
        if cached is not None:
            cached.parent.mkdir(parents=True, exist_ok=True)
            record = {"key": key, "candidates": unpriced}
            atomic_write_text(cached, json.dumps(to_jsonable(record), indent=2) + "\n")
    summaries = {
        label: {**summary, "return": summary["return"] - penalty * summary["transmissions"]}
        for label, summary in unpriced.items()
    }
    chosen = max(labels, key=lambda label: summaries[label]["return"])
    return {
        "chosen": chosen,
        "transmission_penalty": penalty,
        "scenarios": scenarios.describe(),
        "candidates": summaries,
    }


def transmission_penalty(env_id: str, env_kwargs: dict[str, Any]) -> float:
    """λ of ``env_id`` built with ``env_kwargs`` (the env's default where they do not set it)."""
    setup = episode_setup(env_id, env_kwargs)
    try:
        env = setup.env.unwrapped
        return float(getattr(env, "loop", env).transmission_penalty)
    finally:
        setup.env.close()


def _cache_file(cache_dir: str | Path | None, key: dict[str, Any]) -> Path | None:
    """Where the unpriced runs of ``key`` live in ``cache_dir`` (``None``: no cache)."""
    if cache_dir is None:
        return None
    text = json.dumps(to_jsonable(key), sort_keys=True)
    return Path(cache_dir) / f"{hashlib.sha256(text.encode()).hexdigest()[:16]}.json"


def _run_candidates(
    env_id: str,
    env_kwargs: dict[str, Any],
    decisions: DecisionSet,
    seeds: Sequence[int],
    labels: list[str],
    actions: list[int],
) -> dict[str, dict[str, Any]]:
    """Each candidate decision, always taken, on ``seeds``: its set summary."""
    setup = episode_setup(env_id, env_kwargs)
    try:
        deployed = deployment(setup, decisions)
        policies = [
            constant_decision_policy(setup, deployed, decisions, action) for action in actions
        ]
    finally:
        setup.env.close()
    return {
        label: set_summary(run_batch(env_id, policy, seeds, env_kwargs))
        for label, policy in zip(labels, policies, strict=True)
    }

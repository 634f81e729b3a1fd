"""A self-triggered decision set as data: a list of actions, and its versioned JSON form.

An action is chosen at a decision instant and decides how the next interval transmits:

* :class:`Hold` ``(instants=N)``: every channel transmits at the decision instant, the next
  N - 1 instants hold; the next decision comes N instants later. Always choosing it is
  ``periodic every=N``.
* :class:`TriggerAction`: a trigger decides every instant of the interval, the decision
  instant included: the family of the id's rule ``rule`` (``paper``, or ``error_time`` where
  the paper has one) at the point θ ``point``
  (:class:`~etsc_envs.triggers.family.FamilyPoint`: the rule's thresholds scaled per group,
  a floor τ_min and a heartbeat per channel τ_max in instants, a time exponent, a
  state-dependent network). With ``send_first`` every channel transmits at the decision
  instant. The interval ends just before a later instant at which the trigger fires (on any
  channel), after ``cap`` instants, or with the episode. Always choosing the paper's rule at
  factor 1 is the paper's trigger; with ``send_first`` and a cap H it is the rule paired with
  a heartbeat of H instants (:class:`~etsc_envs.triggers.base.HeartbeatPolicy`); with
  ``send_first`` and a floor F it is the rule gating a clock (a minimum inter-event time of F
  instants).

A :class:`DecisionSet` holds the actions (action ``i`` of the agent is ``actions[i]``) and the
set-level shield: where the id's paper has one (:attr:`etsc_envs.core.paper.Paper.shield`) and
``shield_multiple`` is set, an unsafe action is masked and an unsafe choice replaced
(:class:`~etsc_envs.decisions.schedule.IntervalSchedule`).

Saved beside a model ``NAME.zip`` as ``NAME_decisions.json`` (:meth:`DecisionSet.save`), in
the JSON form::

    {"format": "etsc-envs/decision-set", "version": 2, "env_id": "etsc/AttitudeTracking-v0",
     "shield_multiple": null,
     "actions": [{"kind": "hold", "instants": 1}, ...,
                 {"kind": "trigger", "rule": "paper", "point": {"factors": {"psi": 8.0}},
                  "cap": 384, "send_first": true}]}

A ``point`` lists only the keys of :class:`~etsc_envs.triggers.family.FamilyPoint` that differ
from the paper's rule.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs.core.files import atomic_write_text
from etsc_envs.core.json_files import read_json_file
from etsc_envs.core.paper import RULE_NAMES
from etsc_envs.papers import PAPERS, paper_of, rule_of
from etsc_envs.triggers.base import RuleTrigger
from etsc_envs.triggers.family import FamilyPoint, family_trigger, scaled_thresholds

FORMAT = "etsc-envs/decision-set"
"""The ``format`` key of a decision set's JSON form."""
FORMAT_VERSION = 2

MAX_INSTANTS = 2**20
"""The longest hold or interval an action may ask for, in sampling instants."""

DECISIONS_SUFFIX = "_decisions.json"
"""A self-triggered model ``NAME.zip`` keeps its decision set in ``NAME_decisions.json``."""


def decision_set_path(model_path: str | Path) -> Path:
    """Where the decision set of the model saved at ``model_path`` lives."""
    model_path = Path(model_path)
    return model_path.with_name(model_path.stem + DECISIONS_SUFFIX)


def _instants(name: str, value: Any) -> int:
    """``value`` as a count of sampling instants in 1..:data:`MAX_INSTANTS`; ``ValueError``
    naming ``name`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise ValueError(f"{name} must be an integer in 1..{MAX_INSTANTS}, got {value!r}")
    if not 1 <= value <= MAX_INSTANTS:
        raise ValueError(f"{name} must be an integer in 1..{MAX_INSTANTS}, got {value!r}")
    return int(value)


@dataclass(frozen=True)
class Hold:
    """Transmit every channel now, hold the next ``instants`` - 1 instants.

    Args:
        instants: the interval's length in sampling instants (an integer in 1..2^20).
    """

    instants: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "instants", _instants("hold instants", self.instants))

    def label(self, env_id: str) -> str:
        """``hold N``."""
        return f"hold {self.instants}"

    def to_json(self) -> dict[str, Any]:
        return {"kind": "hold", "instants": self.instants}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Hold:
        _require_keys("hold", data, {"kind", "instants"}, {"instants"})
        return cls(data["instants"])


@dataclass(frozen=True)
class TriggerAction:
    """Let the family of the id's rule ``rule`` at ``point`` decide until it fires again (see
    the module's description).

    Args:
        point: θ, the family's point (:class:`~etsc_envs.triggers.family.FamilyPoint`).
        rule: the rule whose family decides (:data:`etsc_envs.core.paper.RULE_NAMES`).
        cap: the interval's longest length in sampling instants (an integer in 1..2^20).
        send_first: whether every channel transmits at the decision instant.
    """

    point: FamilyPoint = field(default_factory=FamilyPoint)
    rule: str = "paper"
    cap: int = MAX_INSTANTS
    send_first: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.point, FamilyPoint):
            raise ValueError(f"point must be a FamilyPoint, got {type(self.point).__name__}")
        if self.rule not in RULE_NAMES:
            raise ValueError(f"rule must be one of {list(RULE_NAMES)}, got {self.rule!r}")
        object.__setattr__(self, "cap", _instants("cap", self.cap))
        if not isinstance(self.send_first, bool):
            raise ValueError(f"send_first must be true or false, got {self.send_first!r}")

    def trigger_class(self, env_id: str) -> type[RuleTrigger]:
        """The class of the rule whose family this action runs (``ValueError`` naming ``rule``
        where ``env_id``'s paper has no such rule)."""
        trigger = rule_of(env_id, self.rule).trigger
        if not issubclass(trigger, RuleTrigger):
            raise ValueError(f"rule: the {self.rule} rule of {env_id} has no family")
        return trigger

    def scaled_groups(self, env_id: str) -> tuple[str, ...]:
        """The factor names of the rule's thresholds
        (:attr:`~etsc_envs.core.paper.Rule.thresholds`): those a "rule × f" scales."""
        trigger = self.trigger_class(env_id)
        thresholds = set(rule_of(env_id, self.rule).thresholds())
        return tuple(
            group
            for group, keywords in trigger.threshold_groups.items()
            if set(keywords) <= thresholds
        )

    def factor(self, env_id: str) -> float | None:
        """f where the point scales every threshold of the rule by the same f, else ``None``."""
        factors = {self.point.factors.get(group, 1.0) for group in self.scaled_groups(env_id)}
        return factors.pop() if len(factors) == 1 else None

    def check(self, env_id: str) -> None:
        """``ValueError`` naming the field where this action does not fit ``env_id``: its
        rule, its point's factors."""
        scaled_thresholds(self.trigger_class(env_id), self.point.factors)

    def label(self, env_id: str) -> str:
        """The action in words: ``paper x2``, ``paper x2, heartbeat 384`` (sent first, capped),
        ``paper x4, floor 64``, ``paper x1, channel heartbeat 256``, ``error_time x2``; a
        point's other parameters follow (``exponent 1``, ``first instant``, ``modulated``,
        ``coupled (1, 0.5, 2) κ 1, all channels``).
        Factors of thresholds the rule's "× f" leaves alone (000's a1, a2) are not named."""
        point = self.point
        factor = self.factor(env_id)
        if factor is not None:
            text = f"{self.rule} x{factor:g}"
        else:
            scaled = ", ".join(
                f"{group} x{point.factors.get(group, 1.0):g}"
                for group in self.scaled_groups(env_id)
            )
            text = f"{self.rule} {scaled}"
        if point.exponent != 0.0:
            text = f"{text}, exponent {point.exponent:g}"
        if point.floor_instants > 0.0:
            text = f"{text}, floor {point.floor_instants:g}"
        if math.isfinite(point.heartbeat_instants):
            text = f"{text}, channel heartbeat {point.heartbeat_instants:g}"
        if point.first_instant:
            text = f"{text}, first instant"
        if point.modulation is not None:
            text = f"{text}, modulated"
        if point.coupling is not None:
            coupling = point.coupling
            weights = ", ".join(f"{weight:g}" for weight in coupling.weights)
            text = f"{text}, coupled ({weights}) κ {coupling.strength:g}"
            if coupling.refresh_all:
                text = f"{text}, all channels"
        if self.send_first and point.floor_instants == 0.0:
            text = f"{text}, heartbeat {self.cap}"
        return text

    def trigger(
        self,
        env_id: str,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        sampling_period_s: float,
    ) -> RuleTrigger:
        """The family's trigger at this action's point, for an env of these spaces."""
        return family_trigger(
            self.trigger_class(env_id),
            self.point,
            {},
            observation_space,
            action_space,
            observation_names,
            sampling_period_s,
        )

    def to_json(self) -> dict[str, Any]:
        default = FamilyPoint().to_json()
        point = {key: value for key, value in self.point.to_json().items() if value != default[key]}
        return {
            "kind": "trigger",
            "rule": self.rule,
            "point": point,
            "cap": self.cap,
            "send_first": self.send_first,
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> TriggerAction:
        _require_keys("trigger", data, {"kind", "rule", "point", "cap", "send_first"}, set())
        return cls(
            point=FamilyPoint.from_json(data.get("point", {})),
            rule=data.get("rule", "paper"),
            cap=data.get("cap", MAX_INSTANTS),
            send_first=data.get("send_first", False),
        )


Action = Hold | TriggerAction
"""An action of a decision set."""

ACTION_KINDS: dict[str, type[Hold] | type[TriggerAction]] = {
    "hold": Hold,
    "trigger": TriggerAction,
}
"""The ``kind`` of an action's JSON form → its class."""


def _require_keys(what: str, data: Any, allowed: set[str], required: set[str]) -> None:
    if not isinstance(data, Mapping):
        raise ValueError(f"a {what} action must be a mapping, got {data!r}")
    unknown = sorted(set(data) - allowed)
    missing = sorted(required - set(data))
    if unknown or missing:
        raise ValueError(
            f"a {what} action takes the keys {sorted(allowed)} ({sorted(required)} required); "
            f"got unknown {unknown}, missing {missing}"
        )


def action_from_json(data: Any) -> Action:
    """The action of the JSON form ``data`` (its ``kind`` one of :data:`ACTION_KINDS`)."""
    kind = data.get("kind") if isinstance(data, Mapping) else None
    if kind not in ACTION_KINDS:
        raise ValueError(f"an action's kind must be one of {sorted(ACTION_KINDS)}, got {data!r}")
    return ACTION_KINDS[kind].from_json(data)


@dataclass(frozen=True)
class DecisionSet:
    """The actions of a self-triggered agent in ``env_id`` and the set's shield.

    Args:
        env_id: the transmit/hold id the decisions act in.
        actions: the actions, in the agent's order (:class:`Hold`, :class:`TriggerAction`);
            where two share a label (a cap is not in the label), :meth:`action`
            names the first.
        shield_multiple: the shield's bound (for 004, sampling errors within this many Π),
            or ``None`` for no shield; with one, the set needs a hold, and its trigger actions
            are the paper's rule at one factor without a floor.
    """

    env_id: str
    actions: tuple[Action, ...]
    shield_multiple: float | None = None

    def __post_init__(self) -> None:
        paper = paper_of(self.env_id)
        actions = tuple(self.actions) if isinstance(self.actions, list | tuple) else None
        if not actions or not all(isinstance(a, Hold | TriggerAction) for a in actions):
            raise ValueError(
                f"actions must be a non-empty list of Hold and TriggerAction, got {self.actions!r}"
            )
        object.__setattr__(self, "actions", actions)
        for index, action in enumerate(actions):
            if isinstance(action, TriggerAction):
                try:
                    action.check(self.env_id)
                except ValueError as error:
                    raise ValueError(f"actions[{index}]: {error}") from None
        labels = self.labels
        if self.shield_multiple is None:
            return
        multiple = self.shield_multiple
        if isinstance(multiple, bool) or not isinstance(multiple, int | float):
            raise ValueError(f"shield_multiple must be a number > 0 or null, got {multiple!r}")
        object.__setattr__(self, "shield_multiple", float(multiple))
        if paper.shield is None:
            shielded = sorted(i for p in PAPERS if p.shield is not None for i in p.ids)
            raise ValueError(
                f"shield_multiple: no shield for {self.env_id}; shields exist for {shielded}"
            )
        if not self.hold_indices:
            raise ValueError("shield_multiple: a shielded set needs a hold action")
        for index in self.trigger_indices:
            action = actions[index]
            assert isinstance(action, TriggerAction)
            plain = action.rule == "paper" and action.point.floor_instants == 0.0
            if not plain or action.factor(self.env_id) is None:
                raise ValueError(
                    f"shield_multiple: the shield bounds the paper rule's factor; actions[{index}] "
                    f"({labels[index]}) is not the paper's rule at one factor without a floor"
                )

    @property
    def labels(self) -> list[str]:
        return [action.label(self.env_id) for action in self.actions]

    @property
    def n_actions(self) -> int:
        return len(self.actions)

    @property
    def action_space(self) -> gym.spaces.Discrete:
        return gym.spaces.Discrete(len(self.actions))

    @property
    def hold_indices(self) -> tuple[int, ...]:
        return tuple(i for i, action in enumerate(self.actions) if isinstance(action, Hold))

    @property
    def trigger_indices(self) -> tuple[int, ...]:
        return tuple(i for i, a in enumerate(self.actions) if isinstance(a, TriggerAction))

    def label(self, action: int) -> str:
        """Action ``action`` in words (:meth:`Hold.label`, :meth:`TriggerAction.label`)."""
        return self.actions[action].label(self.env_id)

    def action(self, label: str) -> int:
        """The action :meth:`label` names ``label``; ``ValueError`` listing the labels if none."""
        labels = self.labels
        if label not in labels:
            raise ValueError(f"{label!r} is not a decision of this set; its decisions: {labels}")
        return labels.index(label)

    def require_action(self, action: Any) -> int:
        """``action`` (a scalar or a one-element array) as an action of the set; ``ValueError``
        naming it and the set's actions otherwise."""
        given = np.asarray(action).reshape(-1)
        if given.size != 1 or not self.action_space.contains(np.int64(given[0])):
            raise ValueError(f"action must be one integer in {self.action_space}, got {action!r}")
        return int(given[0])

    def to_json(self) -> dict[str, Any]:
        return {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "env_id": self.env_id,
            "shield_multiple": self.shield_multiple,
            "actions": [action.to_json() for action in self.actions],
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any], env_id: str | None = None) -> DecisionSet:
        """The set of the version-2 JSON form ``data``; ``env_id`` where ``data`` leaves it out
        (a training config's ``decisions:`` block), else it must agree."""
        if not isinstance(data, Mapping):
            raise ValueError(f"a decision set must be a mapping, got {data!r}")
        allowed = {"format", "version", "env_id", "shield_multiple", "actions"}
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise ValueError(f"decision set: unknown keys {unknown}; allowed {sorted(allowed)}")
        if data.get("format", FORMAT) != FORMAT or data.get("version", FORMAT_VERSION) != 2:
            raise ValueError(
                f"decision set: format {data.get('format')!r} version {data.get('version')!r}; "
                f"this reads {FORMAT!r} version {FORMAT_VERSION}"
            )
        given = data.get("env_id", env_id)
        if given is None or (env_id is not None and given != env_id):
            raise ValueError(f"decision set: env_id {given!r} (for {env_id!r})")
        actions = data.get("actions")
        if not isinstance(actions, list):
            raise ValueError(f"decision set: actions must be a list, got {actions!r}")
        parsed = []
        for index, action in enumerate(actions):
            try:
                parsed.append(action_from_json(action))
            except ValueError as error:
                raise ValueError(f"actions[{index}]: {error}") from None
        return cls(str(given), tuple(parsed), data.get("shield_multiple"))

    def save(self, model_path: str | Path) -> Path:
        """Write the set beside the model saved at ``model_path`` (:func:`decision_set_path`)."""
        path = decision_set_path(model_path)
        atomic_write_text(path, json.dumps(self.to_json(), indent=2) + "\n")
        return path

    @classmethod
    def load(cls, model_path: str | Path) -> DecisionSet:
        """The set saved beside ``model_path``; ``ValueError`` naming the file if it is
        unreadable."""
        path = decision_set_path(model_path)
        try:
            return cls.from_json(read_json_file(path))
        except (ValueError, TypeError, KeyError) as error:
            raise ValueError(f"decision set {path} is not readable ({error})") from None

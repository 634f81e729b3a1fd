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
  state-dependent network), with the trigger's other keywords ``keywords`` (paper 001's ν).
  With ``send_first`` every channel transmits at the decision instant. The interval ends just
  before a later instant at which the trigger fires (on any channel), after ``cap`` instants,
  or with the episode. Always choosing the paper's rule at factor 1 is the paper's trigger;
  with ``send_first`` and a cap H it is the rule paired with a heartbeat of H instants
  (:class:`~etsc_envs.triggers.base.HeartbeatPolicy`); with ``send_first`` and a floor F it is
  the rule gating a clock (a minimum inter-event time of F instants).

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
from the paper's rule. :func:`read_decision_set` also reads the files of version 1 (the
twelve keywords ``max_exponent``, ``factors``, ``rule_cap``, ``rule_heartbeat``, ``rule_floor``,
``rule_channel_heartbeat``, ``rule_keywords``, ``holds``, ... without a ``format`` key) into
the actions that take the same decisions (:func:`read_v1`).
"""

from __future__ import annotations

import inspect
import itertools
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs.core.files import atomic_write_text
from etsc_envs.core.paper import RULE_NAMES
from etsc_envs.papers import PAPERS, paper_of, rule_of
from etsc_envs.triggers.base import RuleTrigger
from etsc_envs.triggers.family import (
    FamilyPoint,
    LearnedTrigger,
    family_trigger,
    scaled_thresholds,
)

FORMAT = "etsc-envs/decision-set"
"""The ``format`` key of a decision set's JSON form."""
FORMAT_VERSION = 2

MAX_INSTANTS = 2**20
"""The longest hold or interval an action may ask for, in sampling instants."""

DECISIONS_SUFFIX = "_decisions.json"
"""A self-triggered model ``NAME.zip`` keeps its decision set in ``NAME_decisions.json``."""

DEFAULT_MAX_EXPONENT = 10
"""Version 1's longest hold by default: 2^10 = 1024 sampling instants."""


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
        keywords: the rule trigger's keywords besides its thresholds (paper 001's ν), fixed.
        cap: the interval's longest length in sampling instants (an integer in 1..2^20).
        send_first: whether every channel transmits at the decision instant.
    """

    point: FamilyPoint = field(default_factory=FamilyPoint)
    rule: str = "paper"
    keywords: Mapping[str, float] = field(default_factory=dict)
    cap: int = MAX_INSTANTS
    send_first: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.point, FamilyPoint):
            raise ValueError(f"point must be a FamilyPoint, got {type(self.point).__name__}")
        if self.rule not in RULE_NAMES:
            raise ValueError(f"rule must be one of {list(RULE_NAMES)}, got {self.rule!r}")
        keywords = self.keywords
        if not isinstance(keywords, Mapping) or not all(isinstance(k, str) for k in keywords):
            raise ValueError(f"keywords must map keyword names to numbers, got {keywords!r}")
        checked = {}
        for name, value in keywords.items():
            if (
                isinstance(value, bool)
                or not isinstance(value, int | float)
                or not np.isfinite(value)
            ):
                raise ValueError(f"keywords.{name} must be a finite number, got {value!r}")
            checked[name] = float(value)
        object.__setattr__(self, "keywords", checked)
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
        rule, its point's factors, its keywords."""
        trigger = self.trigger_class(env_id)
        scaled_thresholds(trigger, self.point.factors)
        thresholds = {kw for keywords in trigger.threshold_groups.values() for kw in keywords}
        allowed = _keywords_besides(trigger, thresholds)
        unknown = sorted(set(self.keywords) - set(allowed))
        if unknown:
            raise ValueError(
                f"keywords: {unknown} are not keywords of the {self.rule} rule of {env_id} "
                f"besides its thresholds (those are point.factors); allowed: {allowed}"
            )

    def label(self, env_id: str) -> str:
        """The action in words: ``paper x2``, ``paper x2, heartbeat 384`` (sent first, capped),
        ``paper x4, floor 64``, ``paper x1, channel heartbeat 256``, ``error_time x2``; a
        point's other parameters follow (``exponent 1``, ``first instant``, ``modulated``).
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
            self.keywords,
            observation_space,
            action_space,
            observation_names,
            sampling_period_s,
        )

    def to_json(self) -> dict[str, Any]:
        default = FamilyPoint().to_json()
        point = {key: value for key, value in self.point.to_json().items() if value != default[key]}
        data: dict[str, Any] = {"kind": "trigger", "rule": self.rule, "point": point}
        if self.keywords:
            data["keywords"] = dict(self.keywords)
        return {**data, "cap": self.cap, "send_first": self.send_first}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> TriggerAction:
        _require_keys(
            "trigger", data, {"kind", "rule", "point", "keywords", "cap", "send_first"}, set()
        )
        point = data.get("point", {})
        if not isinstance(point, Mapping):
            raise ValueError(f"point must be a mapping of FamilyPoint keys, got {point!r}")
        return cls(
            point=FamilyPoint.from_json(point),
            rule=data.get("rule", "paper"),
            keywords=dict(data.get("keywords") or {}),
            cap=data.get("cap", MAX_INSTANTS),
            send_first=data.get("send_first", False),
        )

    @classmethod
    def from_learned(
        cls, learned: LearnedTrigger, cap: int = MAX_INSTANTS, send_first: bool = False
    ) -> TriggerAction:
        """The action that lets the learned trigger ``learned`` (a ``learned:`` file) decide
        (``ValueError`` where its family is none of its id's rules)."""
        rules = paper_of(learned.env_id).rules
        names = [name for name, rule in rules.items() if rule.trigger.__name__ == learned.family]
        if not names:
            raise ValueError(
                f"learned trigger: the family {learned.family!r} is no rule of {learned.env_id}"
            )
        return cls(learned.point, names[0], dict(learned.keywords), cap, send_first)


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
            where two share a label (version 1's caps are not in labels), :meth:`action`
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
        """The set saved beside ``model_path`` (either version); ``ValueError`` naming the
        file if it is unreadable."""
        path = decision_set_path(model_path)
        try:
            return read_decision_set(json.loads(path.read_text()))
        except (OSError, ValueError, TypeError, KeyError) as error:
            raise ValueError(f"decision set {path} is not readable ({error})") from None


def read_decision_set(data: Mapping[str, Any], env_id: str | None = None) -> DecisionSet:
    """The set of ``data``: the version-2 form (:meth:`DecisionSet.from_json`) where it has a
    ``format`` key or ``actions``, else version 1's keywords (:func:`read_v1`). ``env_id``
    where ``data`` leaves it out (a training config's block)."""
    if not isinstance(data, Mapping):
        raise ValueError(f"a decision set must be a mapping, got {data!r}")
    if "format" in data or "actions" in data:
        return DecisionSet.from_json(data, env_id)
    record = dict(data)
    if env_id is not None and record.setdefault("env_id", env_id) != env_id:
        raise ValueError(f"decision set: env_id {record['env_id']!r} (for {env_id!r})")
    return read_v1(record)


V1_KEYS = (
    "env_id",
    "max_exponent",
    "factors",
    "shield_multiple",
    "sampling_period_s",
    "rule_cap",
    "rule_heartbeat",
    "rule",
    "rule_floor",
    "rule_channel_heartbeat",
    "rule_keywords",
    "holds",
    "version",
)
"""The keys of a version-1 decision set."""


def _per_factor(record: Mapping[str, Any], name: str, entry: str, n: int) -> tuple[Any, ...]:
    """Version 1's ``name``: a list of one ``entry`` per factor, or one value for all."""
    value = record.get(name)
    if isinstance(value, list | tuple):
        if len(value) != n:
            raise ValueError(
                f"{name}: a list needs one {entry} per factor ({n}), got {list(value)!r}"
            )
        return tuple(value)
    return (value,) * n


def _v1_bound(name: str, value: Any, listed: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= MAX_INSTANTS:
        raise ValueError(
            f"{name} must be an integer in 1..{MAX_INSTANTS}, a list of them (one per factor) "
            f"or None, got {listed!r}"
        )
    return value


def read_v1(record: Mapping[str, Any]) -> DecisionSet:
    """The actions a version-1 decision set (its keywords, see :data:`V1_KEYS`) offers, in its
    order: the holds (``holds``, else 1, 2, 4, ..., 2^``max_exponent``), then one trigger
    action per factor f of ``factors`` (default: the paper's
    :attr:`~etsc_envs.core.paper.Paper.factors`), the family of ``rule`` with the rule's
    thresholds scaled by f, ``rule_keywords`` that are thresholds as their factors (others as
    keywords), ``rule_floor`` as the point's floor and ``rule_channel_heartbeat`` as its
    heartbeat per channel (one per factor where a list), ``rule_cap`` as the cap (default:
    the longest hold), sending first with ``rule_heartbeat`` or a floor. ``sampling_period_s``
    is the env's and is not kept. ``ValueError`` naming the keyword for a bad one."""
    unknown = sorted(set(record) - set(V1_KEYS))
    if unknown:
        raise ValueError(f"decision set: {unknown} are not among {list(V1_KEYS)}")
    if record.get("version", 1) != 1:
        raise ValueError(f"decision set: version {record.get('version')!r} without a format key")
    env_id = record.get("env_id")
    paper = paper_of(str(env_id))
    if record.get("holds") is not None:
        holds = record["holds"]
        lengths = list(holds) if isinstance(holds, list | tuple) else []
        integers = all(
            not isinstance(n, bool) and isinstance(n, int) and 1 <= n <= MAX_INSTANTS
            for n in lengths
        )
        if not lengths or not integers or any(b <= a for a, b in itertools.pairwise(lengths)):
            raise ValueError(
                f"holds must be a non-empty ascending list of distinct integers in "
                f"1..{MAX_INSTANTS} (hold lengths in instants) or None, got {holds!r}"
            )
    else:
        exponent = record.get("max_exponent", DEFAULT_MAX_EXPONENT)
        if isinstance(exponent, bool) or not isinstance(exponent, int) or not 0 <= exponent <= 20:
            raise ValueError(f"max_exponent must be an integer in 0..20, got {exponent!r}")
        lengths = [2**j for j in range(exponent + 1)]
    given = record.get("factors")
    factors = paper.factors if given is None else tuple(given)
    if not all(
        not isinstance(f, bool) and isinstance(f, int | float) and np.isfinite(f) and f > 0.0
        for f in factors
    ):
        raise ValueError(f"factors must be finite numbers > 0, got {given!r}")
    n = len(factors)
    if record.get("rule_cap") is not None and not isinstance(record["rule_cap"], list | tuple):
        _v1_bound("rule_cap", record["rule_cap"], record["rule_cap"])
    caps = tuple(
        lengths[-1] if cap is None else _v1_bound("rule_cap", cap, record.get("rule_cap"))
        for cap in _per_factor(record, "rule_cap", "cap", n)
    )
    heartbeat = record.get("rule_heartbeat", False)
    if not isinstance(heartbeat, bool):
        raise ValueError(f"rule_heartbeat must be true or false, got {heartbeat!r}")
    floors = _per_factor(record, "rule_floor", "floor", n)
    for floor, cap in zip(floors, caps, strict=True):
        if record.get("rule_floor") is None:
            break
        _v1_bound("rule_floor", floor, record.get("rule_floor"))
        if floor > cap:
            raise ValueError(
                f"rule_floor ({floor}) must be at most its factor's longest rule interval "
                f"({cap}: rule_cap, else the longest hold)"
            )
    beats = _per_factor(record, "rule_channel_heartbeat", "heartbeat", n)
    for beat in beats:
        if beat is not None:
            _v1_bound("rule_channel_heartbeat", beat, record.get("rule_channel_heartbeat"))
    if record.get("rule_channel_heartbeat") is not None and record.get("rule_floor") is not None:
        raise ValueError(
            "rule_channel_heartbeat and rule_floor: a set takes one of the two, got "
            f"{record['rule_channel_heartbeat']!r} and {record['rule_floor']!r}"
        )
    rule = record.get("rule", "paper")
    if rule not in RULE_NAMES:
        raise ValueError(f"rule must be one of {list(RULE_NAMES)}, got {rule!r}")
    if rule not in paper.rules:
        raise ValueError(f"rule: no {rule} rule for {env_id}")
    extra_factors, keywords = _v1_rule_keywords(str(env_id), rule, record.get("rule_keywords"))
    shield = record.get("shield_multiple")
    if shield is not None and (rule != "paper" or record.get("rule_floor") is not None):
        raise ValueError(
            f"shield_multiple: the shield bounds the paper rule's factors, not a floor's holds or "
            f"another rule; a set with rule {rule!r} and rule_floor {record.get('rule_floor')!r} "
            f"must have shield_multiple null"
        )
    groups = TriggerAction(rule=rule).scaled_groups(str(env_id))
    actions: list[Action] = [Hold(length) for length in lengths]
    for factor, cap, floor, beat in zip(factors, caps, floors, beats, strict=True):
        try:
            point = FamilyPoint(
                factors={**{group: float(factor) for group in groups}, **extra_factors},
                floor_instants=0.0 if floor is None else floor,
                heartbeat_instants=math.inf if beat is None else beat,
            )
            action = TriggerAction(point, rule, keywords, cap, heartbeat or floor is not None)
            action.check(str(env_id))
        except ValueError as error:
            given_keywords = record.get("rule_keywords")
            with_keywords = f" with rule_keywords {dict(given_keywords)}" if given_keywords else ""
            raise ValueError(
                f"factors: {factor:g} x the {rule} rule's threshold{with_keywords}: {error}"
            ) from None
        actions.append(action)
    return DecisionSet(str(env_id), tuple(actions), shield)


def _keywords_besides(trigger: type[RuleTrigger], excluded: set[str]) -> list[str]:
    """The keyword arguments with defaults of ``trigger``'s constructor, ``excluded`` left out,
    sorted."""
    return sorted(
        name
        for name, parameter in inspect.signature(trigger).parameters.items()
        if parameter.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD
        and parameter.default is not inspect.Parameter.empty
        and name not in excluded
    )


def _v1_rule_keywords(
    env_id: str, rule: str, given: Any
) -> tuple[dict[str, float], dict[str, float]]:
    """Version 1's ``rule_keywords`` as a point's factors (a threshold keyword of a group of
    its own, given as a value: its factor, whose product with the paper's value gives the
    value back exactly) and the trigger's other keywords."""
    if given is None:
        return {}, {}
    trigger = TriggerAction(rule=rule).trigger_class(env_id)
    scaled = {
        kw
        for group in TriggerAction(rule=rule).scaled_groups(env_id)
        for kw in trigger.threshold_groups[group]
    }
    if not isinstance(given, Mapping) or not all(isinstance(k, str) for k in given):
        raise ValueError(
            f"rule_keywords must map keyword names to numbers or be None, got {given!r}"
        )
    paper = trigger.paper_thresholds()
    own_group = {kws[0]: group for group, kws in trigger.threshold_groups.items() if len(kws) == 1}
    allowed = _keywords_besides(trigger, scaled)
    unknown = sorted(set(given) - set(allowed))
    if unknown:
        raise ValueError(
            f"rule_keywords: {unknown} are not keywords of the {rule} rule of {env_id} that "
            f"the factors leave alone; allowed: {allowed}"
        )
    factors, keywords = {}, {}
    for name, value in given.items():
        if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
            raise ValueError(f"rule_keywords: {name} must be a finite number, got {value!r}")
        if name not in own_group:
            keywords[name] = float(value)
            continue
        if value <= 0.0:
            raise ValueError(f"rule_keywords {dict(given)}: {name} must be > 0, got {value!r}")
        factor = float(value) / paper[name]
        if paper[name] * factor != float(value):
            raise ValueError(
                f"rule_keywords: {name} = {value!r} is not the paper's {paper[name]!r} times "
                "a factor exactly; write the set in version 2 with that factor"
            )
        factors[own_group[name]] = factor
    return factors, keywords


def decision_set_v1(env_id: str, **keywords: Any) -> DecisionSet:
    """The set of version 1's keywords ``keywords`` for ``env_id`` (:func:`read_v1`)."""
    return read_v1({"env_id": env_id, **keywords})

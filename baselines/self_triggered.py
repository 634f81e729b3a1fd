"""Self-triggered decisions: choose, at a decision instant, how the next interval transmits.

An action of :class:`DecisionSet` is one of

* **hold 2^j** (j = 0 .. k): transmit every channel at the decision instant, hold the next
  2^j - 1 instants; the next decision comes 2^j instants later. Always choosing it is
  ``periodic every=2^j``.
* **paper × f**: the paper's trigger with its threshold keywords (its paper record's
  :attr:`~etsc_envs.core.paper.Paper.rule`) scaled by f decides every instant, the
  decision instant included; the interval ends just before a later instant at which it fires
  (on any channel), after 2^k instants (or the set's ``rule_cap``, which may give each factor
  its own), or with the episode.
  Always choosing f = 1 is the paper's trigger. A set whose ``rule`` is ``error_time`` offers
  the id's error-time rule (:attr:`~etsc_envs.core.paper.Paper.error_time`) the same way,
  labelled **error_time × f**.
* **paper × f, heartbeat H** (a set with ``rule_heartbeat``, H its ``rule_cap``, or the factor's
  own cap where ``rule_cap`` is a list): as paper × f,
  but every channel transmits at the decision instant. The interval ends just before the rule
  fires or H instants after that transmission, so always choosing it is the rule paired with a
  heartbeat of H instants (:class:`~etsc_envs.triggers.base.HeartbeatPolicy`; on a
  multi-channel id, an instant at which the rule fires on some channel sends every channel).
* **paper × f, floor F** (a set with ``rule_floor`` F, or with one floor per factor): every
  channel transmits at the decision instant, holds the next F - 1 instants, and from then on
  the rule decides; the interval ends just before an instant at which it fires (or after
  ``rule_cap``). Always choosing it is the rule gating a clock: transmit when the rule fires
  and F instants have passed since the last transmission
  (:func:`~etsc_envs.triggers.base.floored_trigger_class`, a minimum inter-event time; on a
  multi-channel id every channel transmits at the decision instant).
* **paper × f, channel heartbeat H** (a set with ``rule_channel_heartbeat``, one H per factor
  or ``None`` for none): as paper × f, with the rule replaced by the rule paired with a
  heartbeat per channel (:func:`~etsc_envs.triggers.base.channel_heartbeat_trigger_class`): a
  channel also transmits once H instants have passed since its own last transmission, and
  that sends it alone. Always choosing it is that trigger; on the central cluster it is the
  trigger of the decentralised cluster's "paper × f, heartbeat H" run by every follower at
  once.

A multi-channel id (``MultiBinary``: 004, the central cluster) shares one interval: a hold
sends every channel, the paper's rule sends the channels it names. :class:`IntervalSchedule`
runs these semantics one instant at a time for a batch of rows; the training wrapper
(:class:`agents.train.decisions.SelfTriggeredWrapper`) and the deployed transmit/hold policy
(:class:`SelfTriggeredPolicy`) both drive it, so they take the same decisions. Where the id has
a shield (:attr:`~etsc_envs.core.paper.Paper.shield`) and a ``shield_multiple`` is set, unsafe
actions are masked (:meth:`IntervalSchedule.masks`) and an unsafe choice is replaced by the
longest safe action of its kind below it, or by hold 1, which is always safe.

A model trained on the wrapper is saved with its decision set in ``NAME_decisions.json``
beside ``NAME.zip`` (:meth:`DecisionSet.save`); ``--policy sb3:NAME.zip`` then loads it through
:func:`load_self_triggered`.
"""

from __future__ import annotations

import inspect
import itertools
import json
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from baselines.policies import load_sb3, takes_action_masks
from etsc_envs.core.files import atomic_write_text
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.paper import RULE_NAMES
from etsc_envs.papers import PAPER_IDS, ids_with_rule, paper_of, rule_of
from etsc_envs.triggers.base import (
    batched_observations,
    instants_seconds,
    timed_rule_class,
    transmit_bits,
)

DEFAULT_MAX_EXPONENT = 10
"""Longest hold 2^10 = 1024 sampling instants."""

DECISIONS_SUFFIX = "_decisions.json"
"""A self-triggered model ``NAME.zip`` keeps its decision set in ``NAME_decisions.json``."""


def decision_set_path(model_path: str | Path) -> Path:
    """Where the decision set of the model saved at ``model_path`` lives."""
    model_path = Path(model_path)
    return model_path.with_name(model_path.stem + DECISIONS_SUFFIX)


@dataclass(frozen=True)
class DecisionSet:
    """The actions of a self-triggered agent (see the module's description).

    Args:
        env_id: the transmit/hold id the decisions act in.
        max_exponent: k, the longest hold is 2^k sampling instants (an integer >= 0).
        factors: the scalings f > 0 of the paper's threshold, one action each (``None``: the
            id's default, its paper record's :attr:`~etsc_envs.core.paper.Paper.factors`).
        shield_multiple: the shield's bound (for 004, sampling errors within this many Π), or
            ``None`` for no shield.
        sampling_period_s: the env's sampling period (s), which the shield converts holds
            with; needed with ``shield_multiple``.
        rule_cap: the longest "paper × f" interval in instants (an integer in 1..2^20), a
            list of one such cap per factor (with ``rule_heartbeat``, a heartbeat per factor),
            or ``None`` for 2^k.
        rule_heartbeat: whether a "paper × f" interval transmits every channel at its decision
            instant, making it "paper × f, heartbeat ``rule_cap``" (see the module's
            description).
        rule_floor: the floor F of "paper × f, floor F" actions (an integer in 1..2^20, at most
            ``rule_cap``; needs ``sampling_period_s``), a list of one such floor per factor
            (the rule actions then pair each factor with its own floor), or ``None`` for none.
        rule: the family of the rule actions (:data:`etsc_envs.core.paper.RULE_NAMES`):
            ``paper`` (the paper's trigger) or ``error_time`` (the id's error-time rule, which
            the shield does not cover); it names them (``paper x2``, ``error_time x2``).
        rule_keywords: further keyword arguments of the rule's trigger, the same for every
            rule action and not scaled by ``factors`` (for 000, eq. (21)'s relative thresholds
            ``a1``, ``a2``), or ``None`` for the trigger's defaults. The names must be the
            trigger's keywords other than the thresholds ``factors`` scales.
        holds: the hold actions' lengths in instants (distinct integers in 1..2^20, ascending),
            replacing 1, 2, 4, ..., 2^k (``max_exponent`` is then unused), or ``None``: a set
            can then offer the clocks of a periodic sweep that are not powers of two (every 5,
            10, 20 instants).
    """

    env_id: str
    max_exponent: int = DEFAULT_MAX_EXPONENT
    factors: tuple[float, ...] | None = None
    shield_multiple: float | None = None
    sampling_period_s: float | None = None
    rule_cap: int | tuple[int, ...] | None = None
    rule_heartbeat: bool = False
    rule: str = "paper"
    rule_floor: int | tuple[int, ...] | None = None
    rule_channel_heartbeat: int | tuple[int | None, ...] | None = None
    rule_keywords: dict[str, float] | None = None
    holds: tuple[int, ...] | None = None

    def __post_init__(self) -> None:
        if self.env_id not in PAPER_IDS:
            raise ValueError(f"env_id: no paper trigger for {self.env_id!r}")
        exponent = self.max_exponent
        if isinstance(exponent, bool) or not isinstance(exponent, int) or not 0 <= exponent <= 20:
            raise ValueError(f"max_exponent must be an integer in 0..20, got {exponent!r}")
        if self.holds is not None:
            object.__setattr__(self, "holds", checked_holds(self.holds))
        given = paper_of(self.env_id).factors if self.factors is None else self.factors
        factors = tuple(float(f) for f in given)
        if not all(np.isfinite(f) and f > 0.0 for f in factors):
            raise ValueError(f"factors must be finite numbers > 0, got {self.factors!r}")
        object.__setattr__(self, "factors", factors)
        self._per_factor("rule_cap", "cap", len(factors))
        given_caps = self.rule_cap if isinstance(self.rule_cap, tuple) else (self.rule_cap,)
        for cap in () if self.rule_cap is None else given_caps:
            if isinstance(cap, bool) or not isinstance(cap, int) or not 1 <= cap <= 2**20:
                raise ValueError(
                    f"rule_cap must be an integer in 1..{2**20}, a list of them (one per "
                    f"factor) or None, got {self.rule_cap!r}"
                )
        if not isinstance(self.rule_heartbeat, bool):
            raise ValueError(f"rule_heartbeat must be true or false, got {self.rule_heartbeat!r}")
        self._per_factor("rule_floor", "floor", len(factors))
        floored = () if self.rule_floor is None else zip(self.floors, self.caps, strict=True)
        for floor, cap in floored:
            if isinstance(floor, bool) or not isinstance(floor, int) or not 1 <= floor <= 2**20:
                raise ValueError(
                    f"rule_floor must be an integer in 1..{2**20}, a list of them (one per "
                    f"factor) or None, got {self.rule_floor!r}"
                )
            if floor > cap:
                raise ValueError(
                    f"rule_floor ({floor}) must be at most its factor's longest rule interval "
                    f"({cap}: rule_cap, else the longest hold)"
                )
            if self.sampling_period_s is None:
                raise ValueError("sampling_period_s must be given with rule_floor")
        self._per_factor("rule_channel_heartbeat", "heartbeat", len(factors))
        given_heartbeats = () if self.rule_channel_heartbeat is None else self.channel_heartbeats
        for heartbeat in given_heartbeats:
            if heartbeat is None and isinstance(self.rule_channel_heartbeat, tuple):
                continue
            if (
                isinstance(heartbeat, bool)
                or not isinstance(heartbeat, int)
                or not 1 <= heartbeat <= 2**20
            ):
                raise ValueError(
                    f"rule_channel_heartbeat must be an integer in 1..{2**20}, a list of them "
                    f"or None (one per factor) or None, got {self.rule_channel_heartbeat!r}"
                )
        if self.rule_channel_heartbeat is not None:
            if self.rule_floor is not None:
                raise ValueError(
                    "rule_channel_heartbeat and rule_floor: a set takes one of the two, got "
                    f"{self.rule_channel_heartbeat!r} and {self.rule_floor!r}"
                )
            if self.sampling_period_s is None:
                raise ValueError("sampling_period_s must be given with rule_channel_heartbeat")
        if self.rule not in RULE_NAMES:
            raise ValueError(f"rule must be one of {sorted(RULE_NAMES)}, got {self.rule!r}")
        if self.rule not in paper_of(self.env_id).rules:
            raise ValueError(
                f"rule: no {self.rule} rule for {self.env_id}; it exists for "
                f"{ids_with_rule(self.rule)}"
            )
        if self.rule_keywords is not None:
            checked = checked_rule_keywords(self.env_id, self.rule, self.rule_keywords)
            object.__setattr__(self, "rule_keywords", checked)
        if self.shield_multiple is None:
            return
        if self.rule != "paper" or self.rule_floor is not None:
            raise ValueError(
                f"shield_multiple: the shield bounds the paper rule's factors, not a floor's "
                f"holds or another rule; a set with rule {self.rule!r} and rule_floor "
                f"{self.rule_floor!r} must have shield_multiple null"
            )
        if paper_of(self.env_id).shield is None:
            shielded = [env_id for env_id in PAPER_IDS if paper_of(env_id).shield is not None]
            raise ValueError(
                f"shield_multiple: no shield for {self.env_id}; shields exist for {shielded}"
            )
        if self.sampling_period_s is None:
            raise ValueError("sampling_period_s must be given with shield_multiple")

    def _per_factor(self, name: str, entry: str, n_factors: int) -> None:
        """Store the keyword ``name`` as a tuple if it is a list, which needs one ``entry`` per
        factor."""
        value = getattr(self, name)
        if isinstance(value, list | tuple):
            if len(value) != n_factors:
                raise ValueError(
                    f"{name}: a list needs one {entry} per factor ({n_factors}), got "
                    f"{list(value)!r}"
                )
            object.__setattr__(self, name, tuple(value))

    @property
    def hold_steps(self) -> np.ndarray:
        """Sampling instants of each hold action: ``holds``, else 1, 2, 4, ..., 2^k."""
        if self.holds is not None:
            return np.array(self.holds)
        return 2 ** np.arange(self.max_exponent + 1)

    @property
    def caps(self) -> tuple[int, ...]:
        """The longest interval of each rule action in instants, in the order of ``factors``:
        its ``rule_cap``, else the longest hold."""
        if isinstance(self.rule_cap, tuple):
            return self.rule_cap
        cap = int(self.hold_steps[-1]) if self.rule_cap is None else self.rule_cap
        return (cap,) * len(self.factors)

    @property
    def n_holds(self) -> int:
        return len(self.hold_steps)

    @property
    def action_space(self) -> gym.spaces.Discrete:
        """Holds first (ascending), then the factors (in the given order)."""
        return gym.spaces.Discrete(self.n_holds + len(self.factors))

    def label(self, action: int) -> str:
        """``action`` in words (``hold 8``, ``paper x2``, ``paper x2, heartbeat 384``,
        ``paper x1, channel heartbeat 256``, ``error_time x2``)."""
        if action < self.n_holds:
            return f"hold {int(self.hold_steps[action])}"
        index = action - self.n_holds
        label = f"{self.rule} x{self.factors[index]:g}"
        if self.floors[index] is not None:
            label = f"{label}, floor {self.floors[index]}"
        if self.channel_heartbeats[index] is not None:
            label = f"{label}, channel heartbeat {self.channel_heartbeats[index]}"
        return f"{label}, heartbeat {self.caps[index]}" if self.rule_heartbeat else label

    @property
    def floors(self) -> tuple[int | None, ...]:
        """The floor of each rule action, in the order of ``factors`` (``None``: no floor)."""
        if isinstance(self.rule_floor, tuple):
            return self.rule_floor
        return (self.rule_floor,) * len(self.factors)

    @property
    def channel_heartbeats(self) -> tuple[int | None, ...]:
        """The heartbeat per channel of each rule action, in the order of ``factors``
        (``None``: none)."""
        if isinstance(self.rule_channel_heartbeat, tuple):
            return self.rule_channel_heartbeat
        return (self.rule_channel_heartbeat,) * len(self.factors)

    @property
    def rule_sends_first(self) -> bool:
        """Whether a rule interval transmits every channel at its decision instant (with a
        heartbeat or a floor)."""
        return self.rule_heartbeat or self.rule_floor is not None

    def action(self, label: str) -> int:
        """The action :meth:`label` names ``label``; ``ValueError`` listing the labels if none."""
        labels = [self.label(action) for action in range(self.action_space.n)]
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

    def save(self, model_path: str | Path) -> Path:
        """Write the set beside the model saved at ``model_path`` (:func:`decision_set_path`)."""
        path = decision_set_path(model_path)
        atomic_write_text(path, json.dumps(asdict(self), indent=2) + "\n")
        return path

    @classmethod
    def load(cls, model_path: str | Path) -> DecisionSet:
        """The set saved beside ``model_path``; ``ValueError`` naming the file if unreadable."""
        path = decision_set_path(model_path)
        try:
            record = json.loads(path.read_text())
            record["factors"] = tuple(record["factors"])
            return cls(**record)
        except (OSError, ValueError, TypeError, KeyError) as error:
            raise ValueError(f"decision set {path} is not readable ({error})") from None


def checked_holds(holds: Any) -> tuple[int, ...]:
    """``holds`` as a tuple of hold lengths, or ``ValueError`` naming ``holds`` unless it is a
    non-empty ascending list of distinct integers in 1..2^20."""
    lengths = list(holds) if isinstance(holds, list | tuple) else []
    integers = all(
        not isinstance(n, bool) and isinstance(n, int) and 1 <= n <= 2**20 for n in lengths
    )
    if not lengths or not integers or any(b <= a for a, b in itertools.pairwise(lengths)):
        raise ValueError(
            f"holds must be a non-empty ascending list of distinct integers in 1..{2**20} "
            f"(hold lengths in instants) or None, got {holds!r}"
        )
    return tuple(int(n) for n in lengths)


def checked_rule_keywords(env_id: str, rule: str, keywords: Any) -> dict[str, float]:
    """``keywords`` as a dict of finite numbers whose names the ``rule`` trigger of ``env_id``
    takes besides its scaled thresholds (:func:`scaled_thresholds`); ``ValueError`` naming
    ``rule_keywords`` and the allowed names otherwise. The values' ranges are the trigger's to
    check when it is built."""
    scaled = set(rule_of(env_id, rule).thresholds())
    parameters = inspect.signature(rule_of(env_id, rule).trigger).parameters
    allowed = sorted(
        name
        for name, parameter in parameters.items()
        if parameter.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD
        and parameter.default is not inspect.Parameter.empty
        and name not in scaled
    )
    if not isinstance(keywords, Mapping) or not all(isinstance(k, str) for k in keywords):
        raise ValueError(
            f"rule_keywords must map keyword names to numbers (names among {allowed}) or be "
            f"None, got {keywords!r}"
        )
    unknown = sorted(set(keywords) - set(allowed))
    if unknown:
        raise ValueError(
            f"rule_keywords: {unknown} are not keywords of the {rule} rule of {env_id} that "
            f"the factors leave alone; allowed: {allowed}"
        )
    checked = {}
    for name, value in keywords.items():
        if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
            raise ValueError(f"rule_keywords: {name} must be a finite number, got {value!r}")
        checked[name] = float(value)
    return checked


def scaled_thresholds(env_id: str, factor: float, rule: str = "paper") -> dict[str, float]:
    """The threshold keywords of ``env_id``'s ``rule`` trigger
    (:func:`~etsc_envs.papers.rule_of`) at ``factor`` times their default values."""
    thresholds = rule_of(env_id, rule).thresholds()
    return {name: factor * value for name, value in thresholds.items()}


def rule_arguments(
    env_id: str,
    factor: float,
    rule: str = "paper",
    rule_keywords: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """The keywords of ``env_id``'s ``rule`` trigger for a "``rule`` × ``factor``" action:
    its thresholds scaled by ``factor`` (:func:`scaled_thresholds`) and ``rule_keywords``
    (not scaled) beside them."""
    return {**scaled_thresholds(env_id, factor, rule), **(rule_keywords or {})}


def scaled_rule_trigger(
    env_id: str,
    factor: float,
    observation_space: gym.Space,
    action_space: gym.Space,
    observation_names: tuple[str, ...],
    rule: str = "paper",
    floor_s: float | None = None,
    heartbeat_s: float | None = None,
    rule_keywords: Mapping[str, float] | None = None,
) -> Any:
    """The ``rule`` trigger of ``env_id`` (:func:`~etsc_envs.papers.rule_of`) with its
    threshold keywords scaled by ``factor`` and ``rule_keywords`` (not scaled) added, with a
    floor of ``floor_s`` seconds (:func:`~etsc_envs.triggers.base.floored_trigger_class`) or a
    heartbeat per channel of ``heartbeat_s`` seconds
    (:func:`~etsc_envs.triggers.base.channel_heartbeat_trigger_class`) if given (not both);
    ``ValueError`` naming ``factors`` (and ``rule_keywords`` where given) when the values leave
    the trigger's range."""
    trigger_class, bound = timed_rule_class(rule_of(env_id, rule).trigger, floor_s, heartbeat_s)
    keywords = {**rule_arguments(env_id, factor, rule, rule_keywords), **bound}
    try:
        return trigger_class(observation_space, action_space, observation_names, **keywords)
    except ValueError as error:
        given = f" with rule_keywords {dict(rule_keywords)}" if rule_keywords else ""
        raise ValueError(
            f"factors: {factor:g} x the {rule} rule's threshold{given}: {error}"
        ) from None


class IntervalSchedule:
    """The per-instant semantics of a :class:`DecisionSet` for a batch of rows.

    A row's state is ``(action, elapsed)``: the interval's action and the instants it has run.

    Args:
        decisions: the decision set.
        observation_space, action_space: the transmit/hold env's spaces.
        observation_names: its ``observation_names``.
    """

    def __init__(
        self,
        decisions: DecisionSet,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
    ) -> None:
        self.decisions = decisions
        self.n_bits = transmit_bits(action_space)
        self.rule_caps = np.array((*decisions.caps, 0))  # padded: a set may have no rule action
        period_s = decisions.sampling_period_s
        self.triggers = [
            scaled_rule_trigger(
                decisions.env_id,
                factor,
                observation_space,
                action_space,
                observation_names,
                decisions.rule,
                *(
                    None if instants is None else instants_seconds(instants, period_s)
                    for instants in (floor, heartbeat)
                ),
                decisions.rule_keywords,
            )
            for factor, floor, heartbeat in zip(
                decisions.factors, decisions.floors, decisions.channel_heartbeats, strict=True
            )
        ]
        shield = paper_of(decisions.env_id).shield
        self.shield = (
            None
            if decisions.shield_multiple is None or shield is None
            else shield(observation_names, decisions.sampling_period_s, decisions.shield_multiple)
        )

    def masks(self, obs: np.ndarray) -> np.ndarray:
        """Allowed actions at decision instants with observations ``obs``: ``(batch, n)``."""
        decisions = self.decisions
        if self.shield is None:
            return np.ones((len(obs), decisions.action_space.n), dtype=bool)
        holds = self.shield.allowed_holds(obs, decisions.hold_steps)
        factors = np.broadcast_to(
            self.shield.allowed_factors(np.array(decisions.factors)),
            (len(obs), len(decisions.factors)),
        )
        return np.concatenate([holds, factors], axis=1)

    def shielded(self, actions: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """``actions`` with each unsafe one replaced by the longest safe action of its kind
        below it, or by hold 1 (action 0) where there is none."""
        actions = np.asarray(actions, dtype=np.int64).reshape(-1)
        if self.shield is None:
            return actions
        allowed = self.masks(obs)
        n_holds = self.decisions.n_holds
        replaced = actions.copy()
        for row in np.flatnonzero(~allowed[np.arange(len(actions)), actions]):
            first = 0 if actions[row] < n_holds else n_holds
            safe = np.flatnonzero(allowed[row, first : actions[row]])
            replaced[row] = first + safe[-1] if len(safe) else 0
        return replaced

    def start(self, actions: np.ndarray) -> np.ndarray:
        """The state of rows starting an interval with ``actions``."""
        actions = np.asarray(actions, dtype=np.int64).reshape(-1)
        return np.stack([actions, np.zeros_like(actions)], axis=1)

    def _rule_fires(self, obs: np.ndarray, state: np.ndarray) -> np.ndarray:
        """The scaled paper triggers' decisions on the rows following one; other rows False."""
        shape = (len(obs),) if self.n_bits is None else (len(obs), self.n_bits)
        fires = np.zeros(shape, dtype=bool)
        for index, trigger in enumerate(self.triggers):
            rows = state[:, 0] == self.decisions.n_holds + index
            if rows.any():
                fires[rows] = trigger.transmit(obs[rows], None)[0]
        return fires

    def interval_over(self, obs: np.ndarray, state: np.ndarray) -> np.ndarray:
        """Whether each row's interval has ended before the instant of ``obs``."""
        decisions = self.decisions
        action, elapsed = state[:, 0], state[:, 1]
        holding = action < decisions.n_holds
        hold_length = decisions.hold_steps[np.minimum(action, decisions.n_holds - 1)]
        cap = self.rule_caps[np.clip(action - decisions.n_holds, 0, len(decisions.caps))]
        fires = self._rule_fires(obs, state)
        if fires.ndim == 2:
            fires = fires.any(axis=1)
        rule_over = (elapsed >= cap) | ((elapsed >= 1) & fires)
        return np.where(holding, elapsed >= hold_length, rule_over)

    def unconditional_holds(self, state: np.ndarray) -> np.ndarray:
        """Per row, the instants from the current one on that hold whatever is observed: the
        rest of a hold interval after its transmission; 0 elsewhere."""
        action, elapsed = state[:, 0], state[:, 1]
        holding = (action < self.decisions.n_holds) & (elapsed >= 1)
        length = self.decisions.hold_steps[np.minimum(action, self.decisions.n_holds - 1)]
        return np.where(holding, length - elapsed, 0)

    def transmit(self, obs: np.ndarray, state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each row's transmit decision at the instant of ``obs`` (booleans, one column per
        channel for ``MultiBinary``) and the state after it."""
        sends_first = (state[:, 0] < self.decisions.n_holds) | self.decisions.rule_sends_first
        first = sends_first & (state[:, 1] == 0)
        decision = self._rule_fires(obs, state)
        decision[first] = True
        return decision, state + np.array([0, 1])


def run_decision_interval(
    loop: EventTriggeredEnv,
    schedule: IntervalSchedule,
    action: int,
    observation: np.ndarray,
    gamma: float = 1.0,
) -> tuple[np.ndarray, float, bool, bool, dict[str, Any], int]:
    """The interval of ``action``, chosen at the instant of ``observation``, in one compiled
    call of ``loop`` (the loop env, at that instant):
    a hold transmits as :meth:`IntervalSchedule.transmit` says and holds the rest of its
    instants (:meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_interval`), a rule action
    lets its scaled trigger decide inside the loop until it fires again
    (:meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_rule_interval`). The episode ends
    as under :class:`SelfTriggeredPolicy` stepping the same instants one by one. Returns
    ``(observation, sum_k gamma**k * reward_k, terminated, truncated, info, instants run)``."""
    decisions = schedule.decisions
    following = action - decisions.n_holds
    if following >= 0:
        return loop.run_rule_interval(
            schedule.triggers[following],
            decisions.caps[following],
            gamma,
            send_first=decisions.rule_sends_first,
        )
    decision, _ = schedule.transmit(observation[None], schedule.start(np.array([action])))
    return loop.run_interval(decision[0].astype(np.int64), int(decisions.hold_steps[action]), gamma)


class SelfTriggeredPolicy:
    """A model trained on self-triggered decisions, deployed as a transmit/hold policy.

    ``predict`` follows Stable-Baselines3's convention; its recurrent ``state`` holds each
    row's ``(action, elapsed)`` (:class:`IntervalSchedule`). At a row's decision instant (its
    episode start, or its interval's end) the model picks the next action, masked by the
    shield if the set has one (``action_masks`` is passed to a model that takes it, such as
    ``MaskablePPO``; any other model's unsafe choice is replaced).

    Args:
        model: anything with an SB3-style ``predict`` over the decision set's actions.
        schedule: the decision set's schedule for the transmit/hold env.
        observation_space, action_space: the transmit/hold env's spaces.
    """

    def __init__(
        self,
        model: Any,
        schedule: IntervalSchedule,
        observation_space: gym.Space,
        action_space: gym.Space,
    ) -> None:
        self.model = model
        self.schedule = schedule
        self.observation_space = observation_space
        self.action_space = action_space

    def choose(self, obs: np.ndarray, deterministic: bool = True) -> np.ndarray:
        """The model's (shielded) actions at decision instants with observations ``obs``."""
        if self.schedule.shield is not None and takes_action_masks(self.model):
            masks = self.schedule.masks(obs)
            actions, _ = self.model.predict(obs, deterministic=deterministic, action_masks=masks)
        else:
            actions, _ = self.model.predict(obs, deterministic=deterministic)
        return self.schedule.shielded(actions, obs)

    def predict(
        self,
        observation: np.ndarray,
        state: np.ndarray | None = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Transmit decision(s) for ``observation``, and the rows' interval state."""
        obs, single = batched_observations(observation, self.observation_space)
        if state is None:
            state, deciding = self.schedule.start(np.zeros(len(obs))), np.ones(len(obs), bool)
        else:
            state = np.array(state, dtype=np.int64)
            deciding = self.schedule.interval_over(obs, state)
        if episode_start is not None:
            deciding |= np.asarray(episode_start, dtype=bool).reshape(-1)
        if deciding.any():
            state[deciding] = self.schedule.start(self.choose(obs[deciding], deterministic))
        decision, state = self.schedule.transmit(obs, state)
        action = decision.astype(np.int64)
        return (action[0] if single else action), state


def load_self_triggered(
    path: str | Path,
    observation_space: gym.Space,
    action_space: gym.Space,
    observation_names: tuple[str, ...],
    env_id: str,
) -> SelfTriggeredPolicy:
    """The model saved at ``path`` with its decision set beside it, deployed as a transmit/hold
    policy for ``env_id``; ``ValueError`` if the set was made for another id or the model does
    not fit its observations and actions."""
    decisions = DecisionSet.load(path)
    if decisions.env_id != env_id:
        raise ValueError(
            f"sb3 model {path} takes self-triggered decisions in {decisions.env_id}, "
            f"not in {env_id}"
        )
    model = load_sb3(
        path,
        observation_space=observation_space,
        action_space=decisions.action_space,
        env_id=f"{env_id} (self-triggered, {decisions.action_space.n} actions)",
    )
    schedule = IntervalSchedule(decisions, observation_space, action_space, observation_names)
    return SelfTriggeredPolicy(model, schedule, observation_space, action_space)

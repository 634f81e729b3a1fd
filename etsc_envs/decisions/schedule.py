"""The per-instant semantics of a decision set (:mod:`etsc_envs.decisions.actions`) for a batch
of rows, and one interval run in a compiled call of the loop env.

A multi-channel id (``MultiBinary``: 004, the central cluster) shares one interval: a hold
sends every channel, a trigger sends the channels it names. :class:`IntervalSchedule` is driven
alike by the training wrappers (:mod:`etsc_envs.decisions.wrappers`) and the deployed
transmit/hold policy (:class:`~etsc_envs.decisions.policy.SelfTriggeredPolicy`), so they take
the same decisions. Where the set has a shield, unsafe actions are masked
(:meth:`IntervalSchedule.masks`) and an unsafe choice is replaced by the nearest safe action of
its kind before it in the set, or by the set's first hold.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.decisions.actions import DecisionSet, Hold, TriggerAction
from etsc_envs.papers import paper_of
from etsc_envs.triggers.base import RuleTrigger, transmit_bits


class IntervalSchedule:
    """The per-instant semantics of a :class:`~etsc_envs.decisions.actions.DecisionSet`.

    A row's state is ``(action, elapsed)``: the interval's action and the instants it has run.

    Args:
        decisions: the decision set.
        observation_space, action_space: the transmit/hold env's spaces (one agent's for a
            PettingZoo id).
        observation_names: its observation names.
        sampling_period_s: its sampling period (s), which the triggers' floors and heartbeats
            and the shield's holds are converted with.
    """

    def __init__(
        self,
        decisions: DecisionSet,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        sampling_period_s: float,
    ) -> None:
        self.decisions = decisions
        self.n_bits = transmit_bits(action_space)
        actions = decisions.actions
        self.is_hold = np.array([isinstance(a, Hold) for a in actions])
        self.lengths = np.array([a.instants if isinstance(a, Hold) else 0 for a in actions])
        self.caps = np.array([a.cap if isinstance(a, TriggerAction) else 0 for a in actions])
        self.sends_first = np.array(
            [
                isinstance(a, Hold) or (isinstance(a, TriggerAction) and a.send_first)
                for a in actions
            ]
        )
        self.triggers: dict[int, RuleTrigger] = {}
        for index in decisions.trigger_indices:
            action = actions[index]
            assert isinstance(action, TriggerAction)
            try:
                self.triggers[index] = action.trigger(
                    decisions.env_id,
                    observation_space,
                    action_space,
                    tuple(observation_names),
                    sampling_period_s,
                )
            except ValueError as error:
                raise ValueError(f"actions[{index}] ({decisions.label(index)}): {error}") from None
        self.holds = np.array(decisions.hold_indices, dtype=np.int64)
        self.rules = np.array(decisions.trigger_indices, dtype=np.int64)
        shield = paper_of(decisions.env_id).shield
        self.shield = (
            None
            if decisions.shield_multiple is None or shield is None
            else shield(observation_names, sampling_period_s, decisions.shield_multiple)
        )
        self.rules_allowed = (
            np.ones(len(self.rules), dtype=bool)
            if self.shield is None
            else self.shield.allowed_factors(self._rule_factors())
        )
        """Whether each trigger action's scaled rule is safe: a property of the set, not of
        the observation, so it is computed once (its thresholds come from the paper's design)."""

    def _rule_factors(self) -> np.ndarray:
        """Each trigger action's common threshold factor (NaN where it has none)."""
        factors = []
        for index in self.rules:
            action = self.decisions.actions[index]
            assert isinstance(action, TriggerAction)
            factor = action.factor(self.decisions.env_id)
            factors.append(np.nan if factor is None else factor)
        return np.array(factors, dtype=float)

    def masks(self, obs: np.ndarray) -> np.ndarray:
        """Allowed actions at decision instants with observations ``obs``: ``(batch, n)``."""
        n = self.decisions.n_actions
        allowed = np.ones((len(obs), n), dtype=bool)
        if self.shield is None:
            return allowed
        allowed[:, self.holds] = self.shield.allowed_holds(obs, self.lengths[self.holds])
        allowed[:, self.rules] = self.rules_allowed
        return allowed

    def shielded(self, actions: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """``actions`` with each unsafe one replaced by the nearest safe action of its kind
        before it in the set, or by the set's first hold where there is none."""
        actions = np.asarray(actions, dtype=np.int64).reshape(-1)
        if self.shield is None:
            return actions
        allowed = self.masks(obs)
        replaced = actions.copy()
        for row in np.flatnonzero(~allowed[np.arange(len(actions)), actions]):
            kind = self.holds if self.is_hold[actions[row]] else self.rules
            earlier = kind[(kind < actions[row]) & allowed[row, kind]]
            replaced[row] = earlier[-1] if len(earlier) else self.holds[0]
        return replaced

    def start(self, actions: np.ndarray) -> np.ndarray:
        """The state of rows starting an interval with ``actions``."""
        actions = np.asarray(actions, dtype=np.int64).reshape(-1)
        return np.stack([actions, np.zeros_like(actions)], axis=1)

    def _rule_fires(self, obs: np.ndarray, state: np.ndarray) -> np.ndarray:
        """The triggers' decisions on the rows following one; other rows False."""
        shape = (len(obs),) if self.n_bits is None else (len(obs), self.n_bits)
        fires = np.zeros(shape, dtype=bool)
        for index, trigger in self.triggers.items():
            rows = state[:, 0] == index
            if rows.any():
                fires[rows] = trigger.transmit(obs[rows], None)[0]
        return fires

    def interval_over(self, obs: np.ndarray, state: np.ndarray) -> np.ndarray:
        """Whether each row's interval has ended before the instant of ``obs``."""
        action, elapsed = state[:, 0], state[:, 1]
        fires = self._rule_fires(obs, state)
        if fires.ndim == 2:
            fires = fires.any(axis=1)
        rule_over = (elapsed >= self.caps[action]) | ((elapsed >= 1) & fires)
        return np.where(self.is_hold[action], elapsed >= self.lengths[action], rule_over)

    def unconditional_holds(self, state: np.ndarray) -> np.ndarray:
        """Per row, the instants from the current one on that hold whatever is observed: the
        rest of a hold interval after its transmission; 0 elsewhere."""
        action, elapsed = state[:, 0], state[:, 1]
        holding = self.is_hold[action] & (elapsed >= 1)
        return np.where(holding, self.lengths[action] - elapsed, 0)

    def transmit(self, obs: np.ndarray, state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each row's transmit decision at the instant of ``obs`` (booleans, one column per
        channel for ``MultiBinary``) and the state after it."""
        first = self.sends_first[state[:, 0]] & (state[:, 1] == 0)
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
    call of ``loop`` (the loop env, at that instant): a hold transmits as
    :meth:`IntervalSchedule.transmit` says and holds the rest of its instants
    (:meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_interval`), a trigger action lets its
    trigger decide inside the loop until it fires again
    (:meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_rule_interval`). The episode ends as
    under :class:`~etsc_envs.decisions.policy.SelfTriggeredPolicy` stepping the same instants
    one by one. Returns ``(observation, sum_k gamma**k * reward_k, terminated, truncated, info,
    instants run)``."""
    chosen = schedule.decisions.actions[action]
    if isinstance(chosen, TriggerAction):
        return loop.run_rule_interval(
            schedule.triggers[action], chosen.cap, gamma, send_first=chosen.send_first
        )
    decision, _ = schedule.transmit(observation[None], schedule.start(np.array([action])))
    return loop.run_interval(decision[0].astype(np.int64), chosen.instants, gamma)

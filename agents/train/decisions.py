"""Self-triggered decisions as a Gymnasium wrapper over a transmit/hold env, for training.

One step of :class:`SelfTriggeredWrapper` is one decision of :mod:`baselines.self_triggered`:
hold 2^j instants after transmitting now, or hand the interval to the paper's trigger with its
threshold scaled by f. The wrapper runs the interval on the unchanged env and returns the
observation of the next decision instant. The interval runs in one compiled call
(:func:`~baselines.self_triggered.run_decision_interval`: a hold's instants, or a "follow the
paper" interval whose rule's compiled kernel decides each instant inside the loop) when only
``gym.make``'s order-enforcing and passive-checker wrappers lie between the wrapper and the
loop env (neither acts on a step once the env is reset and its first step checked); under any
other wrapper (``TimeLimit``, say) every instant goes through ``env.step``, the rule deciding
in Python. Its reward is the interval's rewards discounted within it, ``sum_i gamma**i *
r_i`` over the ``n`` instants it ran, and ``info["elapsed_steps"] = n``, so that an algorithm
discounting the next decision by ``gamma**n`` keeps the meaning of
the per-instant return: Stable-Baselines3 discounts every decision by one constant ``gamma``
unless it trains with the buffers and callback of :mod:`agents.train.elapsed_discount` and the same
``gamma`` as the wrapper's. ``action_masks()`` gives the
shield's mask for sb3-contrib's ``MaskablePPO``; an unsafe action given anyway is replaced as
:meth:`~baselines.self_triggered.IntervalSchedule.shielded` says (``info["action"]`` is the one
run). A model trained here deploys as a transmit/hold policy once its decision set is saved
beside it (``wrapper.decisions.save(model_path)``). A PettingZoo id's agents take their
decisions apart, in :class:`agents.train.follower_decisions.FollowerDecisionEnv`;
:func:`make_decision_env` builds whichever of the two an id takes.
"""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium.wrappers import OrderEnforcing, PassiveEnvChecker

import etsc_envs
from agents.train.follower_decisions import FollowerDecisionEnv
from baselines.self_triggered import (
    DEFAULT_MAX_EXPONENT,
    DecisionSet,
    IntervalSchedule,
    run_decision_interval,
)
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.validation import require_discount

STEP_TRANSPARENT_WRAPPERS = (OrderEnforcing, PassiveEnvChecker)
"""Wrappers of ``gym.make`` that a compiled interval may bypass: after ``reset`` neither changes
a step (the checker only inspects the first step that reaches it)."""


def interval_env(env: gym.Env) -> EventTriggeredEnv | None:
    """The loop env under ``env`` if only :data:`STEP_TRANSPARENT_WRAPPERS` (exactly those
    classes) wrap it, so that its compiled intervals equal stepping ``env``; ``None`` otherwise."""
    while isinstance(env, gym.Wrapper):
        if type(env) not in STEP_TRANSPARENT_WRAPPERS:
            return None
        env = env.env
    return env if isinstance(env, EventTriggeredEnv) else None


class SelfTriggeredWrapper(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Decisions over intervals of a transmit/hold env built by ``gym.make`` (its id names the
    paper trigger; Gymnasium ids only: a PettingZoo id's agents decide in
    :class:`~agents.train.follower_decisions.FollowerDecisionEnv`).

    Args:
        env: the transmit/hold env.
        max_exponent: the longest hold is 2^max_exponent instants.
        factors: scalings of the paper's threshold offered as actions (default per id: its
            paper record's :attr:`~etsc_envs.core.paper.Paper.factors`).
        shield_multiple: the shield's bound, or ``None`` for no shield (ids with a shield:
            those whose record has a :attr:`~etsc_envs.core.paper.Paper.shield`).
        gamma: the per-instant discount within an interval (in (0, 1]); the algorithm's
            ``gamma`` when it discounts by elapsed instants.
        rule_cap: the longest "paper × f" interval in instants, or one per factor (a list;
            ``None``: 2^max_exponent).
        rule_heartbeat: whether "paper × f" intervals transmit at their decision instant
            (the rule paired with a heartbeat of ``rule_cap`` instants, its factor's own where
            it is a list).
        rule: the family of the rule actions, ``paper`` or ``error_time``
            (:class:`~baselines.self_triggered.DecisionSet`).
        rule_floor: the floor of "paper × f, floor F" actions in instants, one floor per
            factor (a list), or ``None``.
        rule_channel_heartbeat: the heartbeat per channel of "paper × f, channel heartbeat H"
            actions in instants, one per factor (a list, ``None`` for none), or ``None``.
        rule_keywords: further keywords of the rule's trigger, not scaled by the factors (for
            000, ``a1`` and ``a2``), or ``None``.
        holds: the hold actions' lengths in instants, replacing 1, 2, ..., 2^max_exponent
            (ascending), or ``None``.
    """

    def __init__(
        self,
        env: gym.Env,
        max_exponent: int = DEFAULT_MAX_EXPONENT,
        factors: tuple[float, ...] | None = None,
        shield_multiple: float | None = None,
        gamma: float = 0.99,
        rule_cap: int | None = None,
        rule_heartbeat: bool = False,
        rule: str = "paper",
        rule_floor: int | list[int] | tuple[int, ...] | None = None,
        rule_channel_heartbeat: int | list[int | None] | tuple[int | None, ...] | None = None,
        rule_keywords: dict[str, float] | None = None,
        holds: list[int] | tuple[int, ...] | None = None,
    ) -> None:
        gym.utils.RecordConstructorArgs.__init__(
            self,
            max_exponent=max_exponent,
            factors=factors,
            shield_multiple=shield_multiple,
            gamma=gamma,
            rule_cap=rule_cap,
            rule_heartbeat=rule_heartbeat,
            rule=rule,
            rule_floor=rule_floor,
            rule_channel_heartbeat=rule_channel_heartbeat,
            rule_keywords=rule_keywords,
            holds=holds,
        )
        gym.Wrapper.__init__(self, env)
        if env.spec is None:
            raise ValueError("env must be made by gym.make (its id names the paper trigger)")
        self.gamma = require_discount("gamma", gamma)
        unwrapped = env.unwrapped
        self.decisions = DecisionSet(
            env.spec.id,
            max_exponent=max_exponent,
            factors=factors,
            shield_multiple=shield_multiple,
            sampling_period_s=float(unwrapped.params.sampling_period_s),
            rule_cap=rule_cap,
            rule_heartbeat=rule_heartbeat,
            rule=rule,
            rule_floor=rule_floor,
            rule_channel_heartbeat=rule_channel_heartbeat,
            rule_keywords=rule_keywords,
            holds=holds,
        )
        self.schedule = IntervalSchedule(
            self.decisions, env.observation_space, env.action_space, unwrapped.observation_names
        )
        self.action_space = self.decisions.action_space
        self._observation: np.ndarray | None = None
        self._hold_action = np.zeros(env.action_space.shape, dtype=np.int64)
        self._loop = interval_env(env)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        observation, info = self.env.reset(seed=seed, options=options)
        self._observation = observation
        return observation, info

    def action_masks(self) -> np.ndarray:
        """The shield's allowed actions at the current decision instant (all without one)."""
        if self._observation is None:
            raise gym.error.ResetNeeded("call reset() before action_masks()")
        return self.schedule.masks(self._observation[None])[0]

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        """Run one interval; ``info`` is the last instant's, with ``elapsed_steps``, ``action``
        (the action run) and ``shielded`` (whether the shield replaced the one given)."""
        if self._observation is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        given = self.decisions.require_action(action)
        obs = self._observation[None]
        chosen = self.schedule.shielded(np.array([given]), obs)
        if self._loop is not None:
            observation, total, terminated, truncated, info, steps = run_decision_interval(
                self._loop, self.schedule, int(chosen[0]), self._observation, self.gamma
            )
        else:
            observation, total, terminated, truncated, info, steps = self._run_schedule(chosen)
        self._observation = observation
        info = {
            **info,
            "elapsed_steps": steps,
            "action": int(chosen[0]),
            "shielded": bool(chosen[0] != given),
        }
        return observation, total, terminated, truncated, info

    def _run_schedule(
        self, chosen: np.ndarray
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any], int]:
        """The interval of action ``chosen`` (one row) instant by instant through
        :class:`~baselines.self_triggered.IntervalSchedule` and ``env.step`` (where
        :func:`interval_env` finds no loop env to run it in compiled calls): :meth:`_run`'s
        return over the whole interval."""
        obs = self._observation[None]
        state = self.schedule.start(chosen)
        total, steps = 0.0, 0
        while True:
            decision, state = self.schedule.transmit(obs, state)
            held = int(self.schedule.unconditional_holds(state)[0])
            observation, reward, terminated, truncated, info, run = self._run(
                decision[0].astype(np.int64), 1 + held
            )
            total += self.gamma**steps * reward
            steps += run
            state = state + np.array([0, held])
            obs = observation[None]
            if terminated or truncated or self.schedule.interval_over(obs, state)[0]:
                return observation, total, terminated, truncated, info, steps

    def _run(
        self, first_action: np.ndarray, instants: int
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any], int]:
        """``first_action`` then holds, for ``instants`` instants or to the episode's end,
        through ``env.step``: ``(observation, sum_k gamma**k * reward_k, terminated, truncated,
        info, instants run)``."""
        action, total = first_action, 0.0
        for instant in range(instants):
            observation, reward, terminated, truncated, info = self.env.step(action)
            total += self.gamma**instant * float(reward)
            action = self._hold_action
            if terminated or truncated:
                break
        return observation, total, terminated, truncated, info, instant + 1


def make_decision_env(
    env_id: str,
    env_kwargs: dict[str, Any],
    decisions: dict[str, Any],
    gamma: float = 0.99,
    teammate_decision: str | None = None,
) -> SelfTriggeredWrapper | FollowerDecisionEnv:
    """Self-triggered decisions in ``env_id`` built with ``env_kwargs``: a
    :class:`SelfTriggeredWrapper` over ``gym.make`` for a Gymnasium id, one agent's
    :class:`~agents.train.follower_decisions.FollowerDecisionEnv` for a PettingZoo id (its teammates
    taking ``teammate_decision`` until they follow a model; ``None``: the paper's rule).
    ``decisions`` holds the decision set's keywords."""
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        return FollowerDecisionEnv(
            env_id, env_kwargs, gamma=gamma, teammate_decision=teammate_decision, **decisions
        )
    return SelfTriggeredWrapper(gym.make(env_id, **env_kwargs), gamma=gamma, **decisions)

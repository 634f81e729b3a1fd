"""Self-triggered decisions as Gymnasium envs, for training.

One step of :class:`SelfTriggeredWrapper` is one decision of a
:class:`~etsc_envs.decisions.actions.DecisionSet`: hold N instants after transmitting now, or
hand the interval to a trigger action. The wrapper runs the interval on the unchanged
transmit/hold env and returns the observation of the next decision instant. The interval runs
in one compiled call (:func:`~etsc_envs.decisions.schedule.run_decision_interval`: a hold's
instants, or a trigger action whose compiled kernel decides each instant inside the loop) when
only ``gym.make``'s order-enforcing and passive-checker wrappers lie between the wrapper and the
loop env (neither acts on a step once the env is reset and its first step checked); under any
other wrapper (``TimeLimit``, say) every instant goes through ``env.step``, the trigger deciding
in Python. Its reward is the interval's rewards discounted within it, ``sum_i gamma**i * r_i``
over the ``n`` instants it ran, and ``info["elapsed_steps"] = n``, so that an algorithm
discounting the next decision by ``gamma**n`` keeps the meaning of the per-instant return.
``action_masks()`` gives the shield's mask for sb3-contrib's ``MaskablePPO``; an unsafe action
given anyway is replaced as :meth:`~etsc_envs.decisions.schedule.IntervalSchedule.shielded`
says (``info["action"]`` is the one run). A model trained here deploys as a transmit/hold
policy (:class:`~etsc_envs.decisions.policy.SelfTriggeredPolicy`) once its decision set is
saved beside it (``wrapper.decisions.save(model_path)``).

A PettingZoo id's agents take their decisions apart, in :class:`FollowerDecisionEnv`: the
decentralised cluster (paper 001) trained with parameter sharing. Every follower runs its own
interval on its own observation (hold N on its own channel, or the trigger on its own error),
so the followers' decision instants do not coincide. One step is one decision of one follower,
the *learner* (drawn afresh at every reset, so that one policy learns every follower's place);
the other followers take their decisions from the shared policy at their own decision instants
(:meth:`FollowerDecisionEnv.follow_model`: the model being trained, deterministic, through its
current observation statistics; before that, the rule at its own thresholds:
:func:`default_teammate_action`). The step runs the shared loop
instant by instant until the learner's interval ends, and pays the learner its own channel's
rewards discounted within the interval. Deployed, the model is a
:class:`~etsc_envs.decisions.policy.SelfTriggeredPolicy` serving every agent of the PettingZoo
env (one row of interval state per agent): when the learner acts as the model does, a training
episode is that evaluation episode, step for step (``tests/test_follower_decisions.py``).
:func:`make_decision_env` builds whichever of the two an id takes.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, SupportsFloat, cast

import gymnasium as gym
import numpy as np
from gymnasium.wrappers import OrderEnforcing, PassiveEnvChecker

from etsc_envs import registry
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.multi_agent import agent_observation_index
from etsc_envs.core.validation import require_discount
from etsc_envs.decisions.actions import DecisionSet, TriggerAction
from etsc_envs.decisions.policy import FixedDecision, SelfTriggeredPolicy
from etsc_envs.decisions.schedule import IntervalSchedule, run_decision_interval
from etsc_envs.sb3_models import NormalizedModel

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
    """Decisions over intervals of a transmit/hold env built by ``gym.make`` (Gymnasium ids;
    a PettingZoo id's agents decide in :class:`FollowerDecisionEnv`).

    Args:
        env: the transmit/hold env.
        decisions: the decision set (made for ``env``'s id).
        gamma: the per-instant discount within an interval (in (0, 1]); the algorithm's
            ``gamma`` when it discounts by elapsed instants.
    """

    def __init__(self, env: gym.Env, decisions: DecisionSet, gamma: float = 0.99) -> None:
        gym.utils.RecordConstructorArgs.__init__(self, decisions=decisions, gamma=gamma)
        gym.Wrapper.__init__(self, env)
        if env.spec is None:
            raise ValueError("env must be made by gym.make (its id names the paper trigger)")
        if not isinstance(decisions, DecisionSet) or decisions.env_id != env.spec.id:
            raise ValueError(
                f"decisions must be a DecisionSet for {env.spec.id}, got {decisions!r}"
            )
        self.gamma = require_discount("gamma", gamma)
        unwrapped = cast(Any, env.unwrapped)
        self.decisions = decisions
        self.schedule = IntervalSchedule(
            decisions,
            env.observation_space,
            env.action_space,
            unwrapped.observation_names,
            float(unwrapped.params.sampling_period_s),
        )
        self.action_space = decisions.action_space
        self._observation: np.ndarray | None = None
        self._hold_action = np.zeros(env.action_space.shape or (), dtype=np.int64)
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
        :class:`~etsc_envs.decisions.schedule.IntervalSchedule` and ``env.step`` (where
        :func:`interval_env` finds no loop env to run it in compiled calls): :meth:`_run`'s
        return over the whole interval."""
        assert self._observation is not None  # step() checked
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
        action, total, instant = first_action, 0.0, 0
        while True:
            observation, reward, terminated, truncated, info = self.env.step(action)
            total += self.gamma**instant * float(reward)
            action = self._hold_action
            instant += 1
            if terminated or truncated or instant >= instants:
                return observation, total, terminated, truncated, info, instant


def default_teammate_action(decisions: DecisionSet) -> int:
    """The teammates' decision until :meth:`FollowerDecisionEnv.follow_model`: the first
    trigger action at the rule's own thresholds (factor 1), else the set's first trigger
    action, else its first action."""
    triggers = decisions.trigger_indices
    for index in triggers:
        action = decisions.actions[index]
        assert isinstance(action, TriggerAction)
        if action.factor(decisions.env_id) == 1.0:
            return index
    return triggers[0] if triggers else 0


class FollowerDecisionEnv(gym.Env):
    """One agent's self-triggered decisions in a PettingZoo id of etsc-envs (see the module's
    description).

    Args:
        env_id: the PettingZoo id (:data:`etsc_envs.PETTINGZOO_ENV_IDS`).
        decisions: the decision set (made for ``env_id``).
        env_kwargs: the id's keyword arguments.
        gamma: the per-instant discount within an interval (in (0, 1]).
    """

    metadata: dict[str, Any] = {"render_modes": []}  # noqa: RUF012 (Gymnasium's own form)

    def __init__(
        self,
        env_id: str,
        decisions: DecisionSet,
        env_kwargs: dict[str, Any] | None = None,
        gamma: float = 0.99,
    ) -> None:
        if env_id not in registry.PETTINGZOO_ENV_IDS:
            raise ValueError(
                f"env_id: {env_id!r} is not a PettingZoo id; known: "
                f"{sorted(registry.PETTINGZOO_ENV_IDS)}"
            )
        if not isinstance(decisions, DecisionSet) or decisions.env_id != env_id:
            raise ValueError(f"decisions must be a DecisionSet for {env_id}, got {decisions!r}")
        self.gamma = require_discount("gamma", gamma)
        self.parallel_env = registry.make_parallel(env_id, **(env_kwargs or {}))
        self.loop = cast(Any, self.parallel_env.unwrapped).loop
        self.agent_index = agent_observation_index(self.loop)
        self.decisions = decisions
        teammates = SelfTriggeredPolicy.for_env(
            FixedDecision(default_teammate_action(decisions)), decisions, self.parallel_env
        )
        self.teammates = teammates
        self.schedule = teammates.schedule
        self.observation_space = teammates.observation_space
        self.action_space = decisions.action_space
        self.n_agents = len(self.parallel_env.possible_agents)
        self.learner = 0
        self._observations: np.ndarray | None = None
        self._state = np.zeros((self.n_agents, 2), dtype=np.int64)
        self._deciding = np.ones(self.n_agents, dtype=bool)

    def follow_model(self, model: Any) -> None:
        """From now on the teammates decide as ``model`` does (a self-triggered model being
        trained, read deterministically through its live observation statistics)."""
        normalization = model.get_vec_normalize_env()
        reader = (
            model if normalization is None else NormalizedModel(model, normalization, freeze=False)
        )
        self.teammates = SelfTriggeredPolicy.for_env(reader, self.decisions, self.parallel_env)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """A new episode of the shared loop, with a learner drawn uniformly among the agents."""
        super().reset(seed=seed)
        observation, info = self.loop.reset(seed=seed, options=options)
        self.learner = int(self.np_random.integers(self.n_agents))
        observations = self._observations = observation[self.agent_index]
        self._deciding = np.ones(self.n_agents, dtype=bool)
        return observations[self.learner].copy(), {**info, "learner": self.learner}

    def action_masks(self) -> np.ndarray:
        """The shield's allowed actions at the learner's decision instant (all without one)."""
        if self._observations is None:
            raise gym.error.ResetNeeded("call reset() before action_masks()")
        return self.schedule.masks(self._observations[self.learner][None])[0]

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        """Run the learner's interval of ``action``; ``info`` is the last instant's, with
        ``elapsed_steps``, ``action`` (the action run), ``shielded`` and ``learner``."""
        if self._observations is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        given = self.decisions.require_action(action)
        learner = self.learner
        chosen = int(
            self.schedule.shielded(np.array([given]), self._observations[learner][None])[0]
        )
        self._state[learner] = self.schedule.start(np.array([chosen]))[0]
        total, steps = 0.0, 0
        observations = self._observations
        while True:
            self._start_teammates(observations)
            bits, self._state = self.schedule.transmit(observations, self._state)
            observation, _, terminated, truncated, info = self.loop.step(bits.astype(np.int64))
            total += self.gamma**steps * float(self.loop.channel_rewards[learner])
            steps += 1
            observations = self._observations = observation[self.agent_index]
            if terminated or truncated:
                break
            self._deciding = self.schedule.interval_over(observations, self._state)
            if self._deciding[learner]:
                break
        info = {
            **info,
            "elapsed_steps": steps,
            "action": chosen,
            "shielded": chosen != given,
            "learner": learner,
        }
        return observations[learner].copy(), total, terminated, truncated, info

    def _start_teammates(self, observations: np.ndarray) -> None:
        """Start the next interval of every teammate whose interval has ended (at
        ``observations``, the agents')."""
        deciding = self._deciding
        deciding[self.learner] = False
        if deciding.any():
            actions = self.teammates.choose(observations[deciding])
            self._state[deciding] = self.schedule.start(actions)
            deciding[:] = False

    def close(self) -> None:
        self.parallel_env.close()


def make_decision_env(
    env_id: str,
    env_kwargs: dict[str, Any],
    decisions: DecisionSet | Mapping[str, Any],
    gamma: float = 0.99,
) -> SelfTriggeredWrapper | FollowerDecisionEnv:
    """Self-triggered decisions in ``env_id`` built with ``env_kwargs``: a
    :class:`SelfTriggeredWrapper` over ``gym.make`` for a Gymnasium id, one agent's
    :class:`FollowerDecisionEnv` for a PettingZoo id. ``decisions`` is the set or its JSON
    form (:meth:`~etsc_envs.decisions.actions.DecisionSet.from_json`)."""
    if not isinstance(decisions, DecisionSet):
        decisions = DecisionSet.from_json(decisions, env_id)
    if env_id in registry.PETTINGZOO_ENV_IDS:
        return FollowerDecisionEnv(env_id, decisions, env_kwargs, gamma=gamma)
    return SelfTriggeredWrapper(gym.make(env_id, **env_kwargs), decisions, gamma=gamma)

"""Self-triggered decisions for one agent of a PettingZoo id, its teammates following the shared
policy: the decentralised cluster (paper 001) trained with parameter sharing.

Every follower of ``etsc/ClusterContainment-v0`` runs its own interval of a
:class:`~baselines.self_triggered.DecisionSet` on its own observation (hold 2^j on its own
channel, or eq. (15)'s rule at c × f on its own error), so the followers' decision instants do
not coincide. One step of :class:`FollowerDecisionEnv` is one decision of one follower, the
*learner* (drawn afresh at every reset, so that one policy learns every follower's place); the
other followers take their decisions from the shared policy at their own decision instants
(:meth:`FollowerDecisionEnv.follow_model`: the model being trained, deterministic, through its
current observation statistics; before that, one fixed decision). The step runs the shared loop
instant by instant until the learner's interval ends, and pays the learner its own channel's
rewards discounted within the interval (``sum_i gamma**i * r_i``, ``info["elapsed_steps"] =
n``: the convention of :class:`agents.train.decisions.SelfTriggeredWrapper`).

Deployed, the model is a :class:`~baselines.self_triggered.SelfTriggeredPolicy` serving every
agent of the PettingZoo env (one row of interval state per agent), as ``baselines.evaluate
--policy sb3:`` runs it: when the learner acts as the model does, a training episode is that
evaluation episode, step for step (``tests/test_follower_decisions.py``).
"""

from __future__ import annotations

from typing import Any, ClassVar, SupportsFloat

import gymnasium as gym
import numpy as np

import etsc_envs
from agents.train.imitation import FixedDecision
from baselines.policies import NormalizedModel
from baselines.self_triggered import (
    DEFAULT_MAX_EXPONENT,
    DecisionSet,
    IntervalSchedule,
    SelfTriggeredPolicy,
)
from etsc_envs.core.multi_agent import agent_observation_index
from etsc_envs.core.validation import require_discount


def default_teammate_action(decisions: DecisionSet) -> int:
    """The teammates' decision until :meth:`FollowerDecisionEnv.follow_model` when none is
    named: the rule action at the paper's own threshold (factor 1, with the set's heartbeat or
    floor where it pairs one), else the set's first rule action, else hold 1."""
    factors = decisions.factors
    index = factors.index(1.0) if 1.0 in factors else 0
    return decisions.n_holds + index if factors else 0


class FollowerDecisionEnv(gym.Env):
    """One agent's self-triggered decisions in a PettingZoo id of etsc-envs (see the module's
    description).

    Args:
        env_id: the PettingZoo id (:data:`etsc_envs.PETTINGZOO_ENV_IDS`).
        env_kwargs: its keyword arguments.
        max_exponent, factors, shield_multiple, rule_cap, rule_heartbeat, rule, rule_floor,
            rule_channel_heartbeat, rule_keywords, holds: the decision set's
            (:class:`~baselines.self_triggered.DecisionSet`; ``factors`` ``None``: the id's
            default).
        gamma: the per-instant discount within an interval (in (0, 1]).
        teammate_decision: the label of the teammates' decision until :meth:`follow_model`
            (``None``: :func:`default_teammate_action`).
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": []}

    def __init__(
        self,
        env_id: str,
        env_kwargs: dict[str, Any] | None = None,
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
        teammate_decision: str | None = None,
    ) -> None:
        if env_id not in etsc_envs.PETTINGZOO_ENV_IDS:
            raise ValueError(
                f"env_id: {env_id!r} is not a PettingZoo id; known: "
                f"{sorted(etsc_envs.PETTINGZOO_ENV_IDS)}"
            )
        self.gamma = require_discount("gamma", gamma)
        self.parallel_env = etsc_envs.make_parallel(env_id, **(env_kwargs or {}))
        self.loop = self.parallel_env.unwrapped.loop
        self.agent_index = agent_observation_index(self.loop)
        agent = self.parallel_env.possible_agents[0]
        agent_observations = self.parallel_env.observation_space(agent)
        agent_actions = self.parallel_env.action_space(agent)
        self.decisions = DecisionSet(
            env_id,
            max_exponent=max_exponent,
            factors=factors,
            shield_multiple=shield_multiple,
            sampling_period_s=float(self.loop.params.sampling_period_s),
            rule_cap=rule_cap,
            rule_heartbeat=rule_heartbeat,
            rule=rule,
            rule_floor=rule_floor,
            rule_channel_heartbeat=rule_channel_heartbeat,
            rule_keywords=rule_keywords,
            holds=holds,
        )
        self.schedule = IntervalSchedule(
            self.decisions,
            agent_observations,
            agent_actions,
            self.parallel_env.unwrapped.agent_observation_names,
        )
        self.observation_space = agent_observations
        self.action_space = self.decisions.action_space
        self.n_agents = len(self.parallel_env.possible_agents)
        self.teammates = SelfTriggeredPolicy(
            FixedDecision(
                default_teammate_action(self.decisions)
                if teammate_decision is None
                else self.decisions.action(teammate_decision)
            ),
            self.schedule,
            agent_observations,
            agent_actions,
        )
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
        self.teammates = SelfTriggeredPolicy(
            reader,
            self.schedule,
            self.teammates.observation_space,
            self.teammates.action_space,
        )

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """A new episode of the shared loop, with a learner drawn uniformly among the agents."""
        super().reset(seed=seed)
        observation, info = self.loop.reset(seed=seed, options=options)
        self.learner = int(self.np_random.integers(self.n_agents))
        self._observations = observation[self.agent_index]
        self._deciding = np.ones(self.n_agents, dtype=bool)
        return self._observations[self.learner].copy(), {**info, "learner": self.learner}

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
        while True:
            self._start_teammates()
            bits, self._state = self.schedule.transmit(self._observations, self._state)
            observation, _, terminated, truncated, info = self.loop.step(bits.astype(np.int64))
            total += self.gamma**steps * float(self.loop.channel_rewards[learner])
            steps += 1
            self._observations = observation[self.agent_index]
            if terminated or truncated:
                break
            self._deciding = self.schedule.interval_over(self._observations, self._state)
            if self._deciding[learner]:
                break
        info = {
            **info,
            "elapsed_steps": steps,
            "action": chosen,
            "shielded": chosen != given,
            "learner": learner,
        }
        return self._observations[learner].copy(), total, terminated, truncated, info

    def _start_teammates(self) -> None:
        """Start the next interval of every teammate whose interval has ended."""
        deciding = self._deciding
        deciding[self.learner] = False
        if deciding.any():
            actions = self.teammates.choose(self._observations[deciding])
            self._state[deciding] = self.schedule.start(actions)
            deciding[:] = False

    def close(self) -> None:
        self.parallel_env.close()

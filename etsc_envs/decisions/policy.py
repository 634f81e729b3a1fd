"""A model trained on self-triggered decisions, deployed as a transmit/hold policy.

:class:`SelfTriggeredPolicy` takes an already loaded model (anything with an SB3-style
``predict`` over the decision set's actions) and the decision set; a loader of shipped models
reads the set beside the model (:meth:`~etsc_envs.decisions.actions.DecisionSet.load`) and
builds it with :meth:`SelfTriggeredPolicy.for_env`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs.core.multi_agent import CLOCK_NAME
from etsc_envs.decisions.actions import DecisionSet, decision_set_path
from etsc_envs.decisions.schedule import IntervalSchedule
from etsc_envs.sb3_models import env_id_of, load_sb3, takes_action_masks
from etsc_envs.triggers.base import batched_observations, policy_interface


class FixedDecision:
    """One decision, always (SB3's ``predict``): the teammates of a learner before they follow
    its model (:class:`~etsc_envs.decisions.FollowerDecisionEnv`), and a constant-decision
    policy."""

    def __init__(self, action: int) -> None:
        self.action = int(action)

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        return np.full(len(observation), self.action, dtype=np.int64), state


class SelfTriggeredPolicy:
    """A model trained on self-triggered decisions, deployed as a transmit/hold policy.

    ``predict`` follows Stable-Baselines3's convention; its recurrent ``state`` holds each
    row's ``(action, elapsed)`` (:class:`~etsc_envs.decisions.schedule.IntervalSchedule`). At a
    row's decision instant (its episode start, or its interval's end) the model picks the next
    action, masked by the shield if the set has one (``action_masks`` is passed to a model that
    takes it, such as ``MaskablePPO``; any other model's unsafe choice is replaced).

    Called without ``state`` (``action, _ = policy.predict(obs)``), the policy continues the
    state its previous call returned, so that the calls take the same actions as calls passing
    the state back. A row continues when the previous call had as many rows, ``episode_start``
    does not mark it, and its observation follows that call's: every
    ``time_since_transmission_s`` entry is one sampling period (the channel transmitted) or the
    previous value plus one period (it held, or refused a transmission). Any other row starts
    an interval at this instant: the first call, a reset's observation (every entry 0), an
    observation of another env or episode. One policy called without ``state`` therefore
    serves one sequence of observations (one env, or one batch of rows); for envs stepped
    alternately, pass each one's ``state`` back.

    Args:
        model: anything with an SB3-style ``predict`` over the decision set's actions.
        decisions: the decision set.
        observation_space, action_space: the transmit/hold env's spaces (one agent's for a
            PettingZoo id, whose agents the policy then serves as rows).
        observation_names: its observation names.
        sampling_period_s: its sampling period (s).
    """

    def __init__(
        self,
        model: Any,
        decisions: DecisionSet,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        sampling_period_s: float,
    ) -> None:
        self.model = model
        self.decisions = decisions
        self.schedule = IntervalSchedule(
            decisions, observation_space, action_space, observation_names, sampling_period_s
        )
        self.observation_space = observation_space
        self.action_space = action_space
        self.sampling_period_s = float(sampling_period_s)
        self.clock_columns = np.array(
            [i for i, name in enumerate(observation_names) if name.startswith(CLOCK_NAME)]
        )
        if not len(self.clock_columns):
            raise ValueError(f"observation_names: no {CLOCK_NAME} entry in {observation_names}")
        self._last_state: np.ndarray | None = None
        self._last_clocks: np.ndarray | None = None

    @classmethod
    def for_env(cls, model: Any, decisions: DecisionSet, env: Any) -> SelfTriggeredPolicy:
        """The policy for ``env``: a Gymnasium env of the suite, or a PettingZoo parallel env
        (one row of interval state per agent, queried with their observations stacked)."""
        return cls(model, decisions, *policy_interface(env))

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
        """Transmit decision(s) for ``observation``, and the rows' interval state (without
        ``state``, the previous call's where the rows continue it: see the class)."""
        obs, single = batched_observations(observation, self.observation_space)
        clocks = obs[:, self.clock_columns].astype(float)
        starting = np.zeros(len(obs), dtype=bool)
        if state is None:
            state, starting = self._remembered_state(clocks)
        else:
            state = np.array(state, dtype=np.int64)
        if episode_start is not None:
            starting |= np.asarray(episode_start, dtype=bool).reshape(-1)
        deciding = starting | self.schedule.interval_over(obs, state)
        if deciding.any():
            state[deciding] = self.schedule.start(self.choose(obs[deciding], deterministic))
        decision, state = self.schedule.transmit(obs, state)
        self._last_state, self._last_clocks = state, clocks
        action = decision.astype(np.int64)
        return (action[0] if single else action), state

    def _remembered_state(self, clocks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The state of the previous call for rows whose clocks ``clocks`` follow its (see the
        class), a fresh one elsewhere, and which rows start afresh."""
        last_state, last_clocks = self._last_state, self._last_clocks
        if last_state is None or last_clocks is None or len(last_state) != len(clocks):
            return self.schedule.start(np.zeros(len(clocks))), np.ones(len(clocks), dtype=bool)
        period = self.sampling_period_s
        transmitted = np.abs(clocks - period) <= period / 2
        held = np.abs(clocks - (last_clocks + period)) <= period / 2
        starting = np.asarray(~(transmitted | held).all(axis=1), dtype=bool)
        state = last_state.copy()
        state[starting] = self.schedule.start(np.zeros(int(starting.sum())))
        return state, starting


def sb3_policy(
    path: str | Path,
    observation_space: gym.Space,
    action_space: gym.Space,
    observation_names: tuple[str, ...],
    sampling_period_s: float,
    env_id: str,
) -> Any:
    """The Stable-Baselines3 model saved at ``path`` as a transmit/hold policy for an env of
    ``env_id`` with these spaces, observation names and sampling period (one agent's, for a
    PettingZoo id).

    A model with a decision set beside it (``NAME_decisions.json``,
    :func:`~etsc_envs.decisions.decision_set_path`) took self-triggered decisions: it is loaded
    for the set's actions and deployed as a
    :class:`~etsc_envs.decisions.SelfTriggeredPolicy`; ``ValueError`` if the set was made
    for another id. Any other model is :func:`~etsc_envs.sb3_models.load_sb3` for the env's
    spaces."""
    if not decision_set_path(path).is_file():
        return load_sb3(
            path, observation_space=observation_space, action_space=action_space, env_id=env_id
        )
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
        env_id=f"{env_id} (self-triggered, {decisions.n_actions} actions)",
    )
    return SelfTriggeredPolicy(
        model, decisions, observation_space, action_space, observation_names, sampling_period_s
    )


def load_sb3_policy(path: str | Path, env: Any) -> Any:
    """The Stable-Baselines3 model saved at ``path`` as a trigger policy for ``env`` (a
    Gymnasium env of this package, or a PettingZoo parallel env, whose agents then share it,
    queried with their observations stacked): :func:`sb3_policy` with the env's spaces,
    observation names, sampling period and id (:func:`~etsc_envs.sb3_models.env_id_of`).
    ``ValueError`` naming the model and both envs when it was trained for other spaces."""
    env_id = env_id_of(env)  # first: an env not of the suite is refused by name
    return sb3_policy(path, *policy_interface(env), env_id)

"""PettingZoo view of a multi-channel event-triggered loop: one agent per channel.

A problem whose paper triggers several channels separately (one per spacecraft of a
formation, say) writes its closed loop once, as an
:class:`~etsc_envs.core.loop_env.EventTriggeredEnv` with ``n_channels = N`` (a
``MultiBinary(N)`` Gymnasium env for a central trigger), and gets the decentralised
multi-agent form from :class:`EventTriggeredParallelEnv`, which shares that loop: the agents'
transmit bits are gathered into the loop's action, each agent observes its own block of the
loop's observation plus its own transmission clock, and is paid its own channel's reward.

What the loop must provide (a :class:`MultiAgentLoop`, besides the :class:`EventTriggeredEnv`
API):

* ``agent_names``: one name per channel, in channel order;
* ``agent_feature_names``: the names of one agent's features; the loop's observation starts
  with every agent's features, agent after agent, named by :func:`agent_major_names`.

The compiled step already splits every step by channel (:mod:`etsc_envs.core.compiled_loop`):
agent i's reward is ``-(cost_i + failure share)/cost_scale - transmission_penalty * sent_i``,
where ``sent_i`` counts a transmission the loop accepted and a failure charges each agent
``failure_cost / N`` per step cut from the horizon, so the agents' rewards always sum to the
central env's reward.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np
from pettingzoo import ParallelEnv

from etsc_envs.core.compiled_loop import LoopArrays
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.metrics import interevent_summary
from etsc_envs.core.render import RENDER_MODES, RenderModes
from etsc_envs.core.validation import require_reset_options

CLOCK_NAME = "time_since_transmission_s"


def agent_major_names(feature_names: tuple[str, ...], n_agents: int) -> tuple[str, ...]:
    """``name_i`` for every agent ``i`` and feature ``name``, agent after agent."""
    return tuple(f"{name}_{i}" for i in range(n_agents) for name in feature_names)


def agent_metrics(
    arrays: LoopArrays, steps: int, agent_names: tuple[str, ...]
) -> dict[str, dict[str, Any]]:
    """Communication record of each agent's channel in the loop ``arrays`` (one row):
    ``transmissions``, ``transmission_rate`` (per sampling instant), ``mean_interevent_s``
    and ``min_interevent_s``."""
    record = {}
    for index, name in enumerate(agent_names):
        transmissions = int(arrays.transmissions[0, index])
        mean_s, min_s = interevent_summary(
            arrays.transmissions[0, index],
            arrays.interevent_sum_s[0, index],
            arrays.interevent_min_s[0, index],
        )
        record[name] = {
            "transmissions": transmissions,
            "transmission_rate": transmissions / steps if steps else 0.0,
            "mean_interevent_s": mean_s,
            "min_interevent_s": min_s,
        }
    return record


class MultiAgentLoop(EventTriggeredEnv):
    """A closed loop with one agent per channel, which :class:`EventTriggeredParallelEnv`
    shares: a subclass sets :attr:`agent_names` and :attr:`agent_feature_names` in its
    constructor (see the module docstring)."""

    agent_names: tuple[str, ...]
    """One name per channel, in channel order."""
    agent_feature_names: tuple[str, ...]
    """The names of one agent's features."""


def agent_observation_index(loop: MultiAgentLoop) -> np.ndarray:
    """Where each agent's observation sits in the loop's: row ``i`` holds the positions of
    agent ``i``'s features followed by its transmission clock (``ValueError`` if the loop does
    not provide what the module docstring asks)."""
    n_agents = loop.n_channels
    feature_names = tuple(loop.agent_feature_names)
    n_features = len(feature_names)
    if len(loop.agent_names) != n_agents:
        raise ValueError(f"loop.agent_names must name {n_agents} agents (one per channel)")
    if loop.observation_names[: n_agents * n_features] != agent_major_names(
        feature_names, n_agents
    ):
        raise ValueError("the loop's observation must start with agent_major_names(...)")
    clock_start = len(loop.observation_names) - n_agents
    return np.array(
        [[*range(i * n_features, (i + 1) * n_features), clock_start + i] for i in range(n_agents)]
    )


class EventTriggeredParallelEnv(ParallelEnv):
    """Decentralised transmit-or-hold decisions over one shared multi-channel loop.

    Args:
        loop: the shared closed loop (see the module docstring for what it must provide); its
            ``render_mode`` is the env's, and :meth:`render` draws the loop.
        max_cycles: truncate every episode after this many steps (PettingZoo's keyword;
            ``None``: at the loop's horizon only).

    Agents: ``loop.agent_names``. Each acts with ``Discrete(2)`` (1 transmits its channel) and
    observes ``agent_observation_names``: its features followed by
    ``time_since_transmission_s``. ``state()`` is the loop's whole observation. All agents
    end together: terminated on a failure of the loop (``infos[agent]["failure"]``), truncated
    at the horizon or after ``max_cycles`` steps; the last infos also hold ``episode_metrics``.
    """

    # Not a ClassVar: ParallelEnv declares metadata an instance attribute.
    metadata: dict[str, Any] = {  # noqa: RUF012
        "name": "event_triggered_parallel_v0",
        "render_modes": RenderModes(RENDER_MODES),
        "render_fps": 10,
        "is_parallelizable": True,
    }

    def __init__(self, loop: MultiAgentLoop, max_cycles: int | None = None) -> None:
        if max_cycles is not None and (
            isinstance(max_cycles, bool) or not isinstance(max_cycles, int) or max_cycles < 1
        ):
            raise ValueError(f"max_cycles must be None or an integer >= 1, got {max_cycles!r}")
        self.loop = loop
        self.max_cycles = max_cycles
        self.possible_agents = list(loop.agent_names)
        self.agents: list[str] = []
        self.render_mode = loop.render_mode
        self.agent_observation_names = (*loop.agent_feature_names, CLOCK_NAME)
        self._index = agent_observation_index(loop)
        box = loop.observation_space
        if not isinstance(box, gym.spaces.Box):
            raise TypeError(f"loop.observation_space must be a Box, got {box}")
        self._observation_spaces = {
            agent: gym.spaces.Box(box.low[rows], box.high[rows], dtype=np.float32)
            for agent, rows in zip(self.possible_agents, self._index, strict=True)
        }
        self._action_spaces = {agent: gym.spaces.Discrete(2) for agent in self.possible_agents}
        self.state_space = box
        self._state = np.zeros(box.shape, dtype=np.float32)

    # ----------------------------------------------------------------- spaces
    def observation_space(self, agent: str) -> gym.spaces.Box:
        return self._observation_spaces[agent]

    def action_space(self, agent: str) -> gym.spaces.Discrete:
        return self._action_spaces[agent]

    def observation_index(self, name: str) -> int:
        """Position of the named component in every agent's observation."""
        return self.agent_observation_names.index(name)

    # ----------------------------------------------------------------- PettingZoo API
    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, dict[str, Any]]]:
        observation, _ = self.loop.reset(seed=seed, options=self._loop_options(options))
        self.agents = list(self.possible_agents)
        infos = {agent: self.loop.reset_info() for agent in self.agents}
        return self._split(observation), infos

    def step(self, actions: dict[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        if not self.agents:
            raise RuntimeError("step() called after the episode ended; call reset() first")
        bits = self._bits(actions)
        loop = self.loop
        observation, _, terminated, truncated, info = loop.step(bits)
        if not (terminated or truncated) and self.max_cycles is not None:
            truncated = loop.step_index >= self.max_cycles
            if truncated:
                info["episode_metrics"] = loop.episode_metrics()
        sent = loop.arrays.sent[0]
        costs = loop.channel_costs
        rewards = loop.channel_rewards
        observations = self._split(observation)
        names = self.possible_agents
        infos = {}
        for i, agent in enumerate(names):
            agent_info = {
                "transmitted": int(sent[i]),
                "transmissions": int(loop.transmissions[i]),
                "time_s": info["time_s"],
                "cost": float(costs[i]),
            }
            for key in ("failure", "episode_metrics"):
                if key in info:
                    agent_info[key] = info[key]
            infos[agent] = agent_info
        self.agents = [] if terminated or truncated else self.agents
        return (
            observations,
            {agent: float(rewards[i]) for i, agent in enumerate(names)},
            dict.fromkeys(names, bool(terminated)),
            dict.fromkeys(names, bool(truncated)),
            infos,
        )

    def state(self) -> np.ndarray:
        """The loop's whole observation at the current instant (every agent's view)."""
        return self._state.copy()

    def render(self) -> np.ndarray | None:
        """The loop's frame (``render_mode="rgb_array"``): the accuracy cost and every agent's
        transmission instants so far."""
        return self.loop.render()

    def close(self) -> None:
        self.loop.close()

    # ----------------------------------------------------------------- extras
    def episode_metrics(self) -> dict[str, Any]:
        """The loop's episode record so far (common keys, the paper's and per-agent ones)."""
        return self.loop.episode_metrics()

    def state_dict(self) -> dict[str, np.ndarray]:
        """Named copies of the loop's signals (for plots and tests)."""
        return self.loop.state_dict()

    @property
    def time_s(self) -> float:
        """Simulated time of the current sampling instant."""
        return self.loop.time_s

    @property
    def n_steps(self) -> int:
        """Sampling instants in a full episode."""
        return self.loop.n_steps

    # ----------------------------------------------------------------- internals
    def _loop_options(self, options: Any) -> dict[str, Any]:
        """The loop's reset options among ``options``. A non-mapping is refused; unknown keys
        are dropped with a warning naming them rather than refused, because PettingZoo's own
        API tests (``parallel_api_test``, ``api_test``) reset with ``options={"options": 1}``."""
        allowed = self.loop.reset_options
        if not isinstance(options, dict):
            return require_reset_options(options, allowed)
        unknown = sorted(str(key) for key in options if key not in allowed)
        if unknown:
            warnings.warn(
                f"options: unknown key(s) {unknown} ignored; this environment's reset takes "
                f"{list(allowed) or 'no options'}",
                stacklevel=3,
            )
        return {key: value for key, value in options.items() if key in allowed}

    def _split(self, observation: np.ndarray) -> dict[str, np.ndarray]:
        self._state = observation
        blocks = observation[self._index]
        return {agent: blocks[i] for i, agent in enumerate(self.possible_agents)}

    def _bits(self, actions: dict[str, Any]) -> np.ndarray:
        """One 0/1 per agent, or ``ValueError`` naming the agent or action that is wrong."""
        names = self.possible_agents
        if not isinstance(actions, Mapping):
            raise ValueError(
                f"actions must be a dict of one action, 0 (hold) or 1 (transmit), per live agent "
                f"({', '.join(names)}), got {actions!r}"
            )
        if len(actions) != len(names) or any(agent not in actions for agent in names):
            missing = [agent for agent in names if agent not in actions]
            unknown = sorted(set(actions) - set(names))
            raise ValueError(
                f"actions must hold one entry per live agent; missing {missing}, unknown {unknown}"
            )
        values = [actions[agent] for agent in names]
        try:
            bits = np.array(values)
        except ValueError:  # ragged: some action is not a scalar
            bits = np.zeros(0)
        if (
            bits.shape != (len(names),)
            or bits.dtype.kind not in "biuf"
            or not np.all((bits == 0) | (bits == 1))
        ):
            for agent, value in zip(names, values, strict=True):
                if np.ndim(value) != 0 or isinstance(value, str) or value not in (0, 1):
                    raise ValueError(
                        f"action of {agent} must be 0 (hold) or 1 (transmit), got {value!r}"
                    )
        return bits.astype(np.int64)

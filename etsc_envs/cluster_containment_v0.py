"""PettingZoo module of ``etsc/ClusterContainment-v0`` (paper 001), in PettingZoo's convention.

    from etsc_envs import cluster_containment_v0

    env = cluster_containment_v0.parallel_env()      # ParallelEnv, one agent per follower
    env = cluster_containment_v0.env()               # AEC form (order-enforcing, bounds-checked)
    env = cluster_containment_v0.raw_env()           # AEC form without wrappers

Every function takes the keyword arguments of
:class:`etsc_envs.cluster.parallel_env.ClusterContainmentEnv`.
"""

from __future__ import annotations

from typing import Any

from pettingzoo import AECEnv
from pettingzoo.utils import wrappers
from pettingzoo.utils.conversions import parallel_to_aec_wrapper

from etsc_envs.cluster.parallel_env import ClusterContainmentEnv


def parallel_env(**kwargs: Any) -> ClusterContainmentEnv:
    """The decentralised environment as a PettingZoo ``ParallelEnv``."""
    return ClusterContainmentEnv(**kwargs)


def raw_env(**kwargs: Any) -> AECEnv:
    """The same environment in PettingZoo's agent-environment-cycle form, unwrapped."""
    return parallel_to_aec_wrapper(parallel_env(**kwargs))


def env(**kwargs: Any) -> AECEnv:
    """The AEC form with PettingZoo's usual wrappers (action bounds, call order)."""
    return wrappers.OrderEnforcingWrapper(ActionChecked(raw_env(**kwargs)))


class ActionChecked(wrappers.AssertOutOfBoundsWrapper):
    """PettingZoo's bounds check, refusing an action outside the agent's space with one
    ``ValueError`` line naming the agent and the actions it takes (not a bare assertion)."""

    def step(self, action: Any) -> None:
        agent = self.agent_selection
        done = self.terminations[agent] or self.truncations[agent]
        if not (action is None and done) and not self.action_space(agent).contains(action):
            allowed = "None (its episode is over)" if done else "0 (hold) or 1 (transmit)"
            raise ValueError(f"action of {agent} must be {allowed}, got {action!r}")
        super().step(action)

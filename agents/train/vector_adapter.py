"""Stable-Baselines3 on a Gymnasium vector environment.

SB3 trains on its own ``VecEnv`` interface, not on a ``gymnasium.vector.VectorEnv``. The two
differ in three ways this adapter bridges: SB3 resets a finished sub-environment in the same
step and wants its last observation in ``info["terminal_observation"]`` (the vector env must
therefore run with ``autoreset_mode="same_step"``, whose ``final_obs``/``final_info`` carry the
same); SB3 wants one info dict per sub-environment (with ``TimeLimit.truncated`` for a horizon
cut) instead of batched arrays; and SB3's ``reset()`` returns only observations and takes its
seeds from ``seed()``. Make one with :func:`make_sb3_vec_env`.

A PettingZoo id is trained with parameter sharing: :class:`SharedPolicyVecEnv` (made by
:func:`make_shared_policy_vec_env`) presents every agent of every copy of the shared loop as one
SB3 sub-environment, so one policy learns from all agents' experience and serves each of them
with its own observation, as ``python -m baselines.evaluate`` runs it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from stable_baselines3.common.vec_env import VecEnv

import etsc_envs
from etsc_envs.core.multi_agent import agent_observation_index


def unbatch_info(infos: dict[str, Any], index: int) -> dict[str, Any]:
    """Sub-environment ``index``'s entries of a batched vector-env info (``_key`` masks say
    which sub-environments have a key; nested dicts are unbatched recursively)."""
    single: dict[str, Any] = {}
    for key, value in infos.items():
        if key.startswith("_"):
            continue
        mask = infos.get(f"_{key}")
        if mask is not None and not mask[index]:
            continue
        if isinstance(value, dict):
            single[key] = unbatch_info(value, index)
        else:
            entry = value[index]
            single[key] = entry.item() if isinstance(entry, np.generic) else entry
    return single


class _VectorEnvView(VecEnv):
    """What both SB3 views of a same-step vector env share: the autoreset check, ``close``,
    and attribute access (``get_attr``, ``set_attr``, ``env_method``) on the objects
    :meth:`_targets` names for the chosen SB3 sub-environments."""

    def __init__(
        self,
        vector_env: VectorEnv,
        num_envs: int,
        observation_space: gym.Space,
        action_space: gym.Space,
    ) -> None:
        mode = vector_env.metadata.get("autoreset_mode")
        if mode != AutoresetMode.SAME_STEP:
            raise ValueError(
                "vector_env must autoreset in the same step (autoreset_mode='same_step'), "
                f"got {mode!r}"
            )
        self.vector_env = vector_env
        super().__init__(num_envs, observation_space, action_space)
        self._actions: np.ndarray | None = None

    def close(self) -> None:
        self.vector_env.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(target, attr_name) for target in self._targets(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        for target in self._targets(indices):
            setattr(target, attr_name, value)

    def env_method(
        self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any
    ) -> list[Any]:
        return [
            getattr(target, method_name)(*method_args, **method_kwargs)
            for target in self._targets(indices)
        ]

    def env_is_wrapped(self, wrapper_class: type[gym.Wrapper], indices: Any = None) -> list[bool]:
        return [False] * len(self._get_indices(indices))

    def get_images(self) -> Sequence[np.ndarray | None]:
        return [None] * self.num_envs

    def _targets(self, indices: Any) -> list[Any]:
        """The object each chosen SB3 sub-environment's attributes live on."""
        raise NotImplementedError


class SB3VecEnvAdapter(_VectorEnvView):
    """SB3 ``VecEnv`` view of a Gymnasium ``VectorEnv`` that autoresets in the same step.

    Args:
        vector_env: the vector environment (``metadata["autoreset_mode"]`` must be
            ``AutoresetMode.SAME_STEP``).

    Attribute access (``get_attr``, ``set_attr``, ``env_method``) reaches the sub-environments
    of a native vector env (its ``envs``) and the vector env itself otherwise.
    """

    def __init__(self, vector_env: VectorEnv) -> None:
        super().__init__(
            vector_env,
            vector_env.num_envs,
            vector_env.single_observation_space,
            vector_env.single_action_space,
        )

    # ----------------------------------------------------------------- VecEnv API
    def reset(self) -> np.ndarray:
        seeds = self._seeds if any(seed is not None for seed in self._seeds) else None
        options = self._options[0] if self._options and self._options[0] else None
        observations, infos = self.vector_env.reset(seed=seeds, options=options)
        self.reset_infos = [unbatch_info(infos, index) for index in range(self.num_envs)]
        self._reset_seeds()
        self._reset_options()
        return observations

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        observations, rewards, terminated, truncated, infos = self.vector_env.step(self._actions)
        dones = terminated | truncated
        step_infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for index in np.flatnonzero(dones):
            info = unbatch_info(infos.get("final_info", {}), index)
            info["terminal_observation"] = infos["final_obs"][index]
            info["TimeLimit.truncated"] = bool(truncated[index] and not terminated[index])
            step_infos[index] = info
        return observations, rewards.astype(np.float32), dones, step_infos

    # ----------------------------------------------------------------- internals
    def _targets(self, indices: Any) -> list[Any]:
        envs = getattr(self.vector_env, "envs", None)
        chosen: Iterable[int] = self._get_indices(indices)
        if envs is None:
            return [self.vector_env for _ in chosen]
        return [envs[index] for index in chosen]


def _same_step_vector_env(env_id: str, num_envs: int, **env_kwargs: Any) -> VectorEnv:
    """The native vector env of the Gymnasium id ``env_id``, autoresetting in the same step."""
    return gym.make_vec(
        env_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        autoreset_mode=AutoresetMode.SAME_STEP,
        **env_kwargs,
    )


def make_sb3_vec_env(env_id: str, num_envs: int, **env_kwargs: Any) -> SB3VecEnvAdapter:
    """``num_envs`` copies of ``env_id`` as one SB3 ``VecEnv``: the id's native vector env
    (same-step autoreset) behind :class:`SB3VecEnvAdapter`."""
    return SB3VecEnvAdapter(_same_step_vector_env(env_id, num_envs, **env_kwargs))


class SharedPolicyVecEnv(_VectorEnvView):
    """SB3 ``VecEnv`` in which every agent of a multi-channel loop is one sub-environment.

    Args:
        vector_env: the native vector env of the loop (same-step autoreset), ``R`` rows of
            ``N`` channels each.

    Sub-environment ``r * N + i`` is agent ``i`` of row ``r``. It observes what the agent of
    :class:`~etsc_envs.core.multi_agent.EventTriggeredParallelEnv` observes (its features and
    its transmission clock), acts with ``Discrete(2)`` on its own channel, and is paid its
    channel's reward. All agents of a row end together; ``info["episode_metrics"]`` of the
    row's episode is reported once, with agent 0. ``seed(s)`` seeds row ``r`` with ``s + r``.
    """

    def __init__(self, vector_env: VectorEnv) -> None:
        loop = vector_env.envs[0]
        self.index = agent_observation_index(loop)
        self.n_agents, self.n_rows = loop.n_channels, vector_env.num_envs
        box = vector_env.single_observation_space
        rows = self.index[0]
        super().__init__(
            vector_env,
            self.n_rows * self.n_agents,
            gym.spaces.Box(box.low[rows], box.high[rows], dtype=np.float32),
            gym.spaces.Discrete(2),
        )

    def reset(self) -> np.ndarray:
        seeds = self._seeds[: self.n_rows]
        row_seeds = seeds if any(seed is not None for seed in seeds) else None
        observations, infos = self.vector_env.reset(seed=row_seeds)
        self.reset_infos = [
            unbatch_info(infos, index // self.n_agents) for index in range(self.num_envs)
        ]
        self._reset_seeds()
        self._reset_options()
        return self._agent_observations(observations)

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions).reshape(self.n_rows, self.n_agents)

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        observations, _, terminated, truncated, infos = self.vector_env.step(self._actions)
        rewards = self.vector_env.channel_rewards.reshape(-1).astype(np.float32)
        dones = np.repeat(terminated | truncated, self.n_agents)
        step_infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for row in np.flatnonzero(terminated | truncated):
            row_info = unbatch_info(infos.get("final_info", {}), row)
            final_observations = self._agent_observations(infos["final_obs"][row][None])
            cut = bool(truncated[row] and not terminated[row])
            for agent in range(self.n_agents):
                info = {
                    "terminal_observation": final_observations[agent],
                    "TimeLimit.truncated": cut,
                }
                if "failure" in row_info:
                    info["failure"] = row_info["failure"]
                if agent == 0 and "episode_metrics" in row_info:
                    info["episode_metrics"] = row_info["episode_metrics"]
                step_infos[row * self.n_agents + agent] = info
        return self._agent_observations(observations), rewards, dones, step_infos

    def _agent_observations(self, observations: np.ndarray) -> np.ndarray:
        """``(rows, loop observation)`` → ``(rows * N, agent observation)``, agent-minor."""
        return observations[:, self.index].reshape(-1, self.index.shape[1])

    def _targets(self, indices: Any) -> list[Any]:
        """The loop (sub-environment of the vector env) each chosen agent belongs to."""
        chosen = self._get_indices(indices)
        return [self.vector_env.envs[index // self.n_agents] for index in chosen]


def make_shared_policy_vec_env(env_id: str, num_envs: int, **env_kwargs: Any) -> SharedPolicyVecEnv:
    """Every agent of ``num_envs`` copies of the PettingZoo id ``env_id`` as one SB3 ``VecEnv``
    (``num_envs * N`` sub-environments) over the native vector env of its shared loop."""
    if env_id not in etsc_envs.PETTINGZOO_LOOP_IDS:
        raise ValueError(
            f"{env_id!r} is not a PettingZoo id; known: {sorted(etsc_envs.PETTINGZOO_LOOP_IDS)}"
        )
    loop_id = etsc_envs.PETTINGZOO_LOOP_IDS[env_id]
    return SharedPolicyVecEnv(_same_step_vector_env(loop_id, num_envs, **env_kwargs))

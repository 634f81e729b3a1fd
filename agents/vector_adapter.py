"""Stable-Baselines3 on a Gymnasium vector environment.

SB3 trains on its own ``VecEnv`` interface, not on a ``gymnasium.vector.VectorEnv``. The two
differ in three ways this adapter bridges: SB3 resets a finished sub-environment in the same
step and wants its last observation in ``info["terminal_observation"]`` (the vector env must
therefore run with ``autoreset_mode="same_step"``, whose ``final_obs``/``final_info`` carry the
same); SB3 wants one info dict per sub-environment (with ``TimeLimit.truncated`` for a horizon
cut) instead of batched arrays; and SB3's ``reset()`` returns only observations and takes its
seeds from ``seed()``. Make one with :func:`make_sb3_vec_env`.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from stable_baselines3.common.vec_env import VecEnv

import etsc_envs  # noqa: F401  (registers the ids)


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


class SB3VecEnvAdapter(VecEnv):
    """SB3 ``VecEnv`` view of a Gymnasium ``VectorEnv`` that autoresets in the same step.

    Args:
        vector_env: the vector environment (``metadata["autoreset_mode"]`` must be
            ``AutoresetMode.SAME_STEP``).

    Attribute access (``get_attr``, ``set_attr``, ``env_method``) reaches the sub-environments
    of a native vector env (its ``envs``) and the vector env itself otherwise.
    """

    def __init__(self, vector_env: VectorEnv) -> None:
        mode = vector_env.metadata.get("autoreset_mode")
        if mode != AutoresetMode.SAME_STEP:
            raise ValueError(
                "vector_env must autoreset in the same step (autoreset_mode='same_step'), "
                f"got {mode!r}"
            )
        self.vector_env = vector_env
        super().__init__(
            vector_env.num_envs,
            vector_env.single_observation_space,
            vector_env.single_action_space,
        )
        self._actions: np.ndarray | None = None

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

    # ----------------------------------------------------------------- internals
    def _targets(self, indices: Any) -> list[Any]:
        envs = getattr(self.vector_env, "envs", None)
        chosen: Iterable[int] = self._get_indices(indices)
        if envs is None:
            return [self.vector_env for _ in chosen]
        return [envs[index] for index in chosen]


def make_sb3_vec_env(env_id: str, num_envs: int, **env_kwargs: Any) -> SB3VecEnvAdapter:
    """``num_envs`` copies of ``env_id`` as one SB3 ``VecEnv``: the id's native vector env
    (same-step autoreset) behind :class:`SB3VecEnvAdapter`."""
    vector_env = gym.make_vec(
        env_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        autoreset_mode=AutoresetMode.SAME_STEP,
        **env_kwargs,
    )
    return SB3VecEnvAdapter(vector_env)

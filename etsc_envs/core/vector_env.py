"""Native vector environments: many closed loops of one problem stepped in one compiled call.

:class:`EventTriggeredVectorEnv` builds ``num_envs`` single environments of its
``single_env_class`` and binds each to one row of a shared batch of loop arrays
(:mod:`etsc_envs.core.compiled_loop`). A step is one call of the problem's compiled loop step
over all rows (spread over the cores for large batches); resets run each sub-environment's own
Python reset on its row, so sub-environment ``j`` reset with seed ``s + j`` follows exactly
the single environment reset with that seed. Registered as the ids' ``vector_entry_point``::

    envs = gym.make_vec("etsc/AttitudeTracking-v0", num_envs=256,
                        vectorization_mode="vector_entry_point", transmission_penalty=0.05)

The Gymnasium conventions of ``CartPoleVectorEnv`` hold: ``single_observation_space`` and
``single_action_space``, info arrays with ``_key`` masks, and autoreset by default at the next
step (``autoreset_mode="same_step"`` resets in the step that ends an episode and reports
``final_obs`` / ``final_info``; ``"disabled"`` leaves resets to ``reset(options={"reset_mask":
...})``). At the end of an episode the info also holds ``failure`` (if any) and
``episode_metrics`` for that sub-environment.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from typing import Any, ClassVar

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from etsc_envs.core.compiled_loop import (
    allocate_loop_arrays,
    compiled_entry,
    loop_rows,
    loop_rule_interval,
)
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.render import RENDER_FPS
from etsc_envs.core.validation import (
    require_choice,
    require_reset_options,
    require_rule_trigger,
)

ROWS_PER_THREAD_MIN = 8
"""A batch gets one more thread for every this many rows, up to one per available core
(threads cost more than they save on a few rows)."""


def _autoreset_mode(value: AutoresetMode | str) -> AutoresetMode:
    """The mode named by ``value`` (an :class:`AutoresetMode`, its value such as
    ``"SameStep"``, or its name such as ``"same_step"``), or ``ValueError``."""
    for mode in AutoresetMode:
        if value in (mode, mode.value) or str(value).upper() == mode.name:
            return mode
    allowed = [mode.name.lower() for mode in AutoresetMode]
    raise ValueError(f"autoreset_mode must be one of {allowed}, got {value!r}")


def available_cores() -> list[int]:
    """The cores this process may run on (its affinity where the platform has one)."""
    if hasattr(os, "sched_getaffinity"):
        return sorted(os.sched_getaffinity(0))
    return list(range(os.cpu_count() or 1))


def _worker_count(num_envs: int) -> int:
    """Threads that step a batch of ``num_envs`` rows."""
    return max(1, min(len(available_cores()), num_envs // ROWS_PER_THREAD_MIN))


def _row_chunks(num_envs: int, workers: int) -> list[tuple[int, int]]:
    """``workers`` contiguous ``(start, stop)`` row ranges covering ``num_envs`` rows."""
    bounds = np.linspace(0, num_envs, workers + 1).round().astype(int)
    return [(int(bounds[k]), int(bounds[k + 1])) for k in range(workers)]


VECTOR_RENDER_MODES = ("rgb_array",)
"""The render modes of a vector environment besides ``None``."""


class EventTriggeredVectorEnv(VectorEnv):
    """``num_envs`` environments of ``single_env_class`` stepped together.

    Args:
        num_envs: number of sub-environments (>= 1).
        autoreset_mode: ``"next_step"`` (default), ``"same_step"`` or ``"disabled"`` (or the
            :class:`gymnasium.vector.AutoresetMode` itself).
        render_mode: ``None`` or ``"rgb_array"``: :meth:`render` then returns one frame per
            sub-environment (see :meth:`EventTriggeredEnv.render`); ``"human"`` (a window per
            sub-environment) is refused.
        **env_kwargs: passed to every sub-environment's constructor.

    Subclasses set ``single_env_class``; ``envs`` holds the sub-environments (for their
    ``episode_metrics()``, ``state_dict()`` and parameters).
    """

    # Not a ClassVar: VectorEnv declares metadata an instance attribute.
    metadata: dict[str, Any] = {  # noqa: RUF012
        "render_modes": list(VECTOR_RENDER_MODES),
        "render_fps": RENDER_FPS,
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }
    single_env_class: ClassVar[type[EventTriggeredEnv]]

    def __init__(
        self,
        num_envs: int = 1,
        *,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        render_mode: str | None = None,
        **env_kwargs: Any,
    ) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer):
            raise ValueError(f"num_envs must be an integer >= 1, got {num_envs!r}")
        if num_envs < 1:
            raise ValueError(f"num_envs must be an integer >= 1, got {num_envs}")
        require_choice("render_mode", render_mode, (None, *VECTOR_RENDER_MODES))
        mode = _autoreset_mode(autoreset_mode)
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        self.autoreset_mode = mode
        self.num_envs = int(num_envs)
        self.envs = [
            self.single_env_class(render_mode=render_mode, **env_kwargs)
            for _ in range(self.num_envs)
        ]
        first = self.envs[0]
        self.arrays = allocate_loop_arrays(self.num_envs, *first.loop_shape)
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = first.render_mode
        self._bind_rows()
        self._actions = np.zeros((self.num_envs, first.n_channels), dtype=np.int64)
        self._needs_reset = np.ones(self.num_envs, dtype=bool)
        self.channel_rewards = np.zeros((self.num_envs, first.n_channels))
        """Each sub-environment's reward split by channel at the last step (taken before a
        same-step reset), for training one policy per channel."""

    def _bind_rows(self) -> None:
        """Bind each sub-environment to its row of :attr:`arrays` and split the rows among the
        stepping threads."""
        for index, env in enumerate(self.envs):
            env.bind(loop_rows(self.arrays, index, index + 1))
        self._chunks = _row_chunks(self.num_envs, _worker_count(self.num_envs))
        self._pool = ThreadPoolExecutor(len(self._chunks)) if len(self._chunks) > 1 else None
        self._chunk_arrays = [loop_rows(self.arrays, *chunk) for chunk in self._chunks]
        self._loop_step_entry = None
        self._rule_interval_entries: dict[Any, Any] = {}

    def __getstate__(self) -> dict[str, Any]:
        """Everything but the thread pool, the compiled entry point and the row views (pickle
        would copy a view as an array of its own), rebuilt by :meth:`__setstate__`."""
        state = self.__dict__.copy()
        for name in (
            "_pool",
            "_loop_step_entry",
            "_rule_interval_entries",
            "_chunks",
            "_chunk_arrays",
        ):
            state.pop(name, None)
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._bind_rows()

    # ----------------------------------------------------------------- Gymnasium API
    def reset(
        self,
        *,
        seed: int | list[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset every sub-environment (or those of ``options["reset_mask"]``).

        ``seed``: ``None``, an int ``s`` (sub-environment ``j`` gets ``s + j``) or one seed per
        sub-environment. Other ``options`` are passed to every sub-environment's reset.
        """
        seeds = self._seeds(seed)
        if isinstance(seed, int):
            super().reset(seed=seed)
        env_options = require_reset_options(
            options, ("reset_mask", *self.single_env_class.reset_options)
        )
        mask = np.asarray(env_options.pop("reset_mask", np.ones(self.num_envs, dtype=bool)))
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_:
            raise ValueError(
                f"options['reset_mask'] must be a bool array of shape ({self.num_envs},), "
                f"got {mask!r}"
            )
        infos: dict[str, Any] = {}
        for index in np.flatnonzero(mask).tolist():
            _, info = self.envs[index].reset(seed=seeds[index], options=env_options or None)
            infos = self._add_info(infos, info, index)
        self._needs_reset[mask] = False
        return self.arrays.observation.copy(), infos

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        self._actions[:] = self._transmit_bits(actions)
        arrays = self.arrays
        first = self.envs[0]
        resetting = self._needs_reset.copy()
        if resetting.any():
            if self.autoreset_mode != AutoresetMode.NEXT_STEP:
                ended = np.flatnonzero(resetting).tolist()
                raise RuntimeError(
                    f"step() called on sub-environments {ended} whose episode ended; "
                    "reset them first (reset(options={'reset_mask': ...}))"
                )
            for index in np.flatnonzero(resetting):
                self.envs[index].reset()
        self._advance_rows(~resetting)
        if self.render_mode is not None:
            for index in np.flatnonzero(~resetting):
                self.envs[index].trace_step()
        terminated = arrays.failure_code != 0
        truncated = ~terminated & (arrays.step_index >= first.n_steps)
        ended = terminated | truncated
        rewards = arrays.reward.copy()
        self.channel_rewards = arrays.channel_rewards.copy()
        infos: dict[str, Any] = {}
        for index in np.flatnonzero(ended).tolist():
            env = self.envs[index]
            end_info = env.step_info(True)
            if self.autoreset_mode == AutoresetMode.SAME_STEP:
                final = {"final_obs": arrays.observation[index].copy(), "final_info": end_info}
                infos = self._add_info(infos, final, index)
                env.reset()
            else:
                extras = {
                    key: end_info[key] for key in ("failure", "episode_metrics") if key in end_info
                }
                infos = self._add_info(infos, extras, index)
        if self.autoreset_mode == AutoresetMode.SAME_STEP:
            self._needs_reset[:] = False
        else:
            self._needs_reset = ended
        infos.update(self._step_infos())
        return arrays.observation.copy(), rewards, terminated, truncated, infos

    def run_rule(
        self,
        trigger: Any,
        instants: int,
        returns: np.ndarray,
        channel_returns: np.ndarray,
    ) -> np.ndarray:
        """Advance every sub-environment whose episode runs by up to ``instants`` sampling
        instants, each decided by a paper's triggering rule, in one compiled call per stepping
        thread (:func:`~etsc_envs.core.compiled_loop.loop_rule_interval`): exactly the
        :meth:`step` calls with the trigger's decisions, without a Python call per instant.

        ``trigger`` is a :class:`~etsc_envs.triggers.base.RuleTrigger` for the single env's
        observations. Each row's rewards are added to ``returns`` (``(num_envs,)``) and its
        per-channel rewards to ``channel_returns`` (``(num_envs, C)``). A sub-environment stops
        where its episode ends; like :meth:`step`, the next step resets it. Returns the
        instants each row ran.
        """
        first = self.envs[0]
        require_rule_trigger("trigger", trigger, first.n_channels)
        instants = int(instants)
        active = ~self._needs_reset
        steps_run = np.zeros(self.num_envs, dtype=np.int64)
        step_costs = np.zeros((self.num_envs, instants))
        step_sent = np.zeros((self.num_envs, instants, first.n_channels), dtype=np.int64)
        start_index = self.arrays.step_index.copy()
        rule = type(trigger).rule

        def arguments(chunk: int) -> tuple[Any, ...]:
            start, stop = self._chunks[chunk]
            return (
                active[start:stop],
                self._chunk_arrays[chunk],
                first.constants,
                first.sampling_period_s,
                first.n_steps,
                first.cost_scale,
                first.transmission_penalty,
                first.failure_cost,
                trigger.rule_indices,
                trigger.rule_parameters,
                instants,
                False,
                False,
                1.0,
                self._actions[start:stop],
                returns[start:stop],
                channel_returns[start:stop],
                steps_run[start:stop],
                step_costs[start:stop],
                step_sent[start:stop],
            )

        entry = self._rule_interval_entries.get(rule)
        if entry is None:
            function = loop_rule_interval(first.loop_step, rule)
            entry = self._rule_interval_entries[rule] = compiled_entry(function, *arguments(0))
        self._run_chunks(lambda chunk: entry(*arguments(chunk)))
        arrays = self.arrays
        self._needs_reset |= active & (
            (arrays.failure_code != 0) | (arrays.step_index >= first.n_steps)
        )
        if self.render_mode is not None:
            for row in np.flatnonzero(active):
                self.envs[row].trace_interval(
                    int(start_index[row]), step_costs[row, : steps_run[row]], step_sent[row]
                )
        return steps_run

    def step_rows(
        self, actions: Any, rows: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """One sampling instant of the sub-environments ``rows`` (a boolean mask) alone, with
        their entries of ``actions`` (:meth:`step`'s shape; the other rows' are ignored), compiled,
        on the calling thread, for a caller that moves each row on its own schedule (self-triggered
        decisions): each stepped row ends exactly as after its sub-environment's ``step``, the
        others stay where they are. No autoreset and no info; ``RuntimeError`` if a stepped
        row's episode has ended or was never reset. Returns ``(observations, rewards,
        terminated, truncated)`` of every row (rewards 0 and both flags ``False`` for the rows
        not stepped); :attr:`channel_rewards` holds the stepped rows' per-channel rewards."""
        rows = np.asarray(rows, dtype=bool).reshape(self.num_envs)
        arrays = self.arrays
        n_steps = self.envs[0].n_steps
        unready = rows & (
            self._needs_reset | (arrays.failure_code != 0) | (arrays.step_index >= n_steps)
        )
        if unready.any():
            raise RuntimeError(
                f"step_rows() called on sub-environments {np.flatnonzero(unready).tolist()} "
                "whose episode ended or was never reset; reset them first"
            )
        self._actions[rows] = self._transmit_bits(actions)[rows]
        self._advance_rows(rows, threaded=False)
        if self.render_mode is not None:
            for index in np.flatnonzero(rows):
                self.envs[index].trace_step()
        terminated = rows & (arrays.failure_code != 0)
        truncated = rows & ~terminated & (arrays.step_index >= n_steps)
        self._needs_reset |= terminated | truncated
        self.channel_rewards = np.where(rows[:, None], arrays.channel_rewards, 0.0)
        rewards = np.where(rows, arrays.reward, 0.0)
        return arrays.observation.copy(), rewards, terminated, truncated

    def render(self) -> tuple[np.ndarray | None, ...] | None:
        """One frame per sub-environment with ``render_mode="rgb_array"``, else ``None``."""
        if self.render_mode is None:
            return None
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the stepping threads and close the sub-environments (neither exists yet when
        the constructor refused its arguments and ``__del__`` closes the half-made object)."""
        pool = getattr(self, "_pool", None)
        if pool is not None:
            pool.shutdown()
        for env in getattr(self, "envs", ()):
            env.close()

    # ----------------------------------------------------------------- internals
    def _advance_rows(self, active: np.ndarray, threaded: bool = True) -> None:
        """One compiled loop step of the ``active`` rows, each thread on its own row range
        (all ranges on this thread unless ``threaded``: for a few rows of the batch, the
        hand-off to the stepping threads costs more than it saves)."""
        first = self.envs[0]

        def arguments(chunk: int) -> tuple[Any, ...]:
            start, stop = self._chunks[chunk]
            return (
                self._actions[start:stop],
                active[start:stop],
                self._chunk_arrays[chunk],
                first.constants,
                first.sampling_period_s,
                first.n_steps,
                first.cost_scale,
                first.transmission_penalty,
                first.failure_cost,
            )

        if self._loop_step_entry is None:
            self._loop_step_entry = compiled_entry(first.loop_step, *arguments(0))
        entry = self._loop_step_entry

        if threaded:
            self._run_chunks(lambda chunk: entry(*arguments(chunk)))
        else:
            for chunk in range(len(self._chunks)):
                entry(*arguments(chunk))

    def _run_chunks(self, work: Any) -> None:
        """``work(chunk)`` for every row range, each on its own stepping thread."""
        if self._pool is None:
            work(0)
            return
        others = [self._pool.submit(work, c) for c in range(1, len(self._chunks))]
        work(0)
        for future in others:
            future.result()

    def _step_infos(self) -> dict[str, np.ndarray]:
        """The per-step info keys of every sub-environment, batched (all present)."""
        arrays = self.arrays
        present = np.ones(self.num_envs, dtype=bool)
        values = {
            "transmitted": arrays.sent_count.copy(),
            "transmissions": arrays.transmission_count.copy(),
            "time_s": arrays.step_index * self.envs[0].sampling_period_s,
            "cost": arrays.cost.copy(),
        }
        infos: dict[str, np.ndarray] = {}
        for key, value in values.items():
            infos[key] = value
            infos[f"_{key}"] = present
        return infos

    def _seeds(self, seed: int | list[int | None] | None) -> list[int | None]:
        """One seed per sub-environment, or ``ValueError``."""
        if seed is None:
            return [None] * self.num_envs
        if isinstance(seed, bool):
            raise ValueError(f"seed must be None, an int or {self.num_envs} seeds, got {seed!r}")
        if isinstance(seed, int | np.integer):
            return [int(seed) + index for index in range(self.num_envs)]
        seeds = list(seed)
        if len(seeds) != self.num_envs:
            raise ValueError(
                f"seed must be None, an int or {self.num_envs} seeds (one per sub-environment), "
                f"got {len(seeds)}"
            )
        return seeds

    def _transmit_bits(self, actions: Any) -> np.ndarray:
        """The actions as an ``(num_envs, n_channels)`` array of 0/1, or ``ValueError``."""
        bits = np.asarray(actions)
        n_channels = self._actions.shape[1]
        shape = (self.num_envs,) if n_channels == 1 else (self.num_envs, n_channels)
        if bits.shape not in (shape, (self.num_envs, n_channels)) or not np.all(
            (bits == 0) | (bits == 1)
        ):
            raise ValueError(
                f"actions must be an array of shape {shape} holding 0 (hold) or 1 (transmit), "
                f"got shape {bits.shape}"
            )
        return bits.reshape(self.num_envs, n_channels)

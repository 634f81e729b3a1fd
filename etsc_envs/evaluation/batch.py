"""Batch evaluation: every scenario of a set in one native vector env, one batched ``predict``
per sampling instant.

A set of ``K`` scenarios (seeds) runs as the ``K`` sub-environments of the id's native vector
env (:mod:`etsc_envs.core.vector_env`), all stepped in one compiled call, and the policy is
asked once per instant for the whole batch — for a PettingZoo id, once for every agent of
every copy (``K × N`` observations, agent-minor, the layout of
:class:`agents.train.vector_adapter.SharedPolicyVecEnv`). Sub-environment ``j`` reset with seed
``s_j`` is the single environment reset with ``s_j`` (the vector env's contract), so a
scenario's record here equals :func:`etsc_envs.evaluation.episodes.run_episode`'s (or
:func:`~etsc_envs.evaluation.episodes.run_parallel_episode`'s) for the same seed, key for key; only
``wall_time_s`` differs: it is the batch's wall time divided by ``K``. ``tests/test_batch.py``
compares the two paths for every id.

A self-triggered model (:class:`~etsc_envs.decisions.SelfTriggeredPolicy`, Gymnasium ids)
runs decision by decision instead: the model is asked once per decision for the rows still
running, and each row's interval (a hold, or a rule deciding until it fires) runs in one
compiled call of its own sub-environment
(:func:`~etsc_envs.decisions.run_decision_interval`), but for holds of one instant, which the
rows that chose one run together in one call of the vector env. The episode is the one the policy
gives stepped instant by instant, so every record's metrics are equal; only ``return`` may
differ in its last bits, summed interval by interval (``tests/test_batch.py``).

A sub-environment whose episode fails before the horizon is left to the vector env's
next-step autoreset and ignored from then on; the batch ends when every scenario has ended
once (all together at the horizon unless they fail).

:func:`run_batch_in_processes` splits the seeds into ``n`` contiguous parts, each run by a
spawned worker process pinned to one core that builds the policy from its command-line spec
and steps its own vector env alone: on a machine of ``n`` cores this saves the per-instant
hand-off between stepping threads (about 80 µs an instant, measured on paper 000's 64-row set)
and runs the policy's ``predict`` in parallel too. Rows never interact, so the records are
those of :func:`run_batch` (``tests/test_batch.py``); ``wall_time_s`` is each part's wall time
divided by its rows. Workers are spawned, not forked: a fork of a process whose PyTorch had
started its OpenMP threads deadlocks in the child's first matrix product. A worker dies with
its parent (:func:`die_with_parent`): a killed evaluation leaves no worker stepping on.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode

import etsc_envs
from etsc_envs.core.multi_agent import agent_observation_index
from etsc_envs.core.vector_env import available_cores
from etsc_envs.decisions import SelfTriggeredPolicy, run_decision_interval
from etsc_envs.evaluation.episodes import instants_bar
from etsc_envs.triggers.base import RuleTrigger

PARENT_WATCH_S = 1.0
"""Seconds between a worker's checks that its parent lives, where the system cannot kill it
with its parent."""

PR_SET_PDEATHSIG = 1
"""Linux's ``prctl`` option: the signal a process gets when its parent dies."""

PROGRESS_EVERY = 1000
"""Sampling instants between progress-bar updates."""

ROWS_PER_PROCESS_MIN = 16
""":func:`process_count` gives a set one more worker process for every this many scenarios."""


def process_count(n_scenarios: int) -> int:
    """Worker processes worth starting for a set of ``n_scenarios``: one per available core,
    at most one per :data:`ROWS_PER_PROCESS_MIN` scenarios."""
    return max(1, min(len(available_cores()), n_scenarios // ROWS_PER_PROCESS_MIN))


def _vector_env(env_id: str, num_envs: int, env_args: dict[str, Any]) -> Any:
    """The native vector env of ``env_id`` (of the shared loop for a PettingZoo id)."""
    loop_id = etsc_envs.PETTINGZOO_LOOP_IDS.get(env_id, env_id)
    if loop_id not in etsc_envs.VECTOR_ENTRY_POINTS:
        raise ValueError(f"no native vector env for {env_id!r}")
    return gym.make_vec(
        loop_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        autoreset_mode=AutoresetMode.NEXT_STEP,
        **env_args,
    ).unwrapped


def run_batch(
    env_id: str,
    policy: Any,
    seeds: Sequence[int],
    env_args: dict[str, Any] | None = None,
    *,
    progress: bool = False,
    description: str = "",
) -> list[dict[str, Any]]:
    """One episode per seed of ``seeds``, all at once; the records of the design page in seed
    order (for a PettingZoo id with each agent's values under ``agents``).

    Args:
        env_id: a Gymnasium or PettingZoo id of the suite.
        policy: anything with an SB3-style batched ``predict`` (for a PettingZoo id, one policy
            for every agent, as :func:`etsc_envs.evaluation.policy_specs.make_agent_policy` builds).
        seeds: the reset seed of each scenario.
        env_args: keywords of every scenario's env.
        progress: show a progress bar over the sampling instants.
    """
    seeds = [int(seed) for seed in seeds]
    if not seeds:
        raise ValueError("seeds must name at least one scenario")
    vector_env = _vector_env(env_id, len(seeds), dict(env_args or {}))
    try:
        return _run(env_id, vector_env, policy, seeds, progress, description)
    finally:
        vector_env.close()


def run_batch_in_processes(
    env_id: str,
    policy_spec: str,
    policy_args: dict[str, Any],
    seeds: Sequence[int],
    env_args: dict[str, Any] | None = None,
    *,
    processes: int,
    progress: bool = False,
    description: str = "",
) -> list[dict[str, Any]]:
    """:func:`run_batch` of the policy named by ``policy_spec`` (a ``--policy`` of
    :mod:`baselines.evaluate`) with ``policy_args``, the seeds split among ``processes``
    spawned workers (see the module docstring); the records in seed order."""
    seeds = [int(seed) for seed in seeds]
    if isinstance(processes, bool) or not isinstance(processes, int) or processes < 1:
        raise ValueError(f"processes must be an integer >= 1, got {processes!r}")
    parts = [part.tolist() for part in np.array_split(np.array(seeds), processes) if part.size]
    cores = available_cores()
    work = (env_id, policy_spec, dict(policy_args), dict(env_args or {}), description)
    with ProcessPoolExecutor(
        len(parts),
        mp_context=multiprocessing.get_context("spawn"),
        initializer=die_with_parent,
        initargs=(os.getpid(),),
    ) as pool:
        futures = [
            pool.submit(_run_part, work, part, cores[index % len(cores)], progress and index == 0)
            for index, part in enumerate(parts)
        ]
        return [record for future in futures for record in future.result()]


def die_with_parent(parent: int) -> None:
    """Make this worker process end when the process ``parent`` does (a ``ProcessPoolExecutor``
    initializer): on Linux the kernel sends it SIGKILL (``prctl(PR_SET_PDEATHSIG)``), elsewhere
    a daemon thread exits it once its parent is gone, checking every :data:`PARENT_WATCH_S`."""
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
            if os.getppid() != parent:  # the parent died before the call
                os._exit(1)
            return

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_WATCH_S)
        os._exit(1)

    threading.Thread(target=watch, name="parent-watch", daemon=True).start()


def _run_part(
    work: tuple[str, str, dict[str, Any], dict[str, Any], str],
    seeds: list[int],
    core: int,
    progress: bool,
) -> list[dict[str, Any]]:
    """One worker's share of :func:`run_batch_in_processes`, on ``core`` alone (so that its
    vector env steps with one thread and PyTorch with one)."""
    from etsc_envs.evaluation.arguments import limit_torch_threads
    from etsc_envs.evaluation.policy_specs import episode_setup

    env_id, policy_spec, policy_args, env_args, description = work
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {core})
    limit_torch_threads()
    setup = episode_setup(env_id, env_args)
    policy = setup.make_policy(policy_spec, policy_args)
    setup.env.close()
    return run_batch(env_id, policy, seeds, env_args, progress=progress, description=description)


def _run(
    env_id: str,
    vector_env: Any,
    policy: Any,
    seeds: list[int],
    progress: bool,
    description: str,
) -> list[dict[str, Any]]:
    """:func:`run_batch` on an open vector env."""
    rows = len(seeds)
    loop = vector_env.envs[0]
    multi_agent = env_id in etsc_envs.PETTINGZOO_ENV_IDS
    agent_index = agent_observation_index(loop) if multi_agent else None
    n_agents = loop.n_channels if multi_agent else 1

    started = time.perf_counter()
    observations, _ = vector_env.reset(seed=seeds)
    returns = np.zeros((rows, n_agents))
    if isinstance(policy, RuleTrigger):
        _run_rule(vector_env, policy, returns, multi_agent, progress, description)
        ended_metrics = [env.episode_metrics() for env in vector_env.envs]
    elif isinstance(policy, SelfTriggeredPolicy) and not multi_agent:
        ended_metrics = _run_decisions(
            vector_env, policy, observations, returns, progress, description
        )
    else:
        ended_metrics = _run_predict(
            vector_env, policy, observations, returns, agent_index, progress, description
        )
    wall_time_s = (time.perf_counter() - started) / rows
    names = tuple(getattr(loop, "agent_names", ()))
    records = []
    for row, seed in enumerate(seeds):
        metrics = ended_metrics[row]
        record = {
            "seed": seed,
            "wall_time_s": wall_time_s,
            "return": float(returns[row].sum()) if multi_agent else float(returns[row, 0]),
            **metrics,
        }
        if multi_agent:
            agent_metrics = metrics.get("agents", {})
            record["agents"] = {
                agent: {"return": float(returns[row, i]), **agent_metrics.get(agent, {})}
                for i, agent in enumerate(names)
            }
        records.append(record)
    return records


def _run_rule(
    vector_env: Any,
    trigger: RuleTrigger,
    returns: np.ndarray,
    multi_agent: bool,
    progress: bool,
    description: str,
) -> None:
    """Every row's whole episode under a paper's rule, :data:`PROGRESS_EVERY` instants per
    compiled call (:meth:`~etsc_envs.core.vector_env.EventTriggeredVectorEnv.run_rule`): the
    decisions and records of the per-instant loop of :func:`_run`, without its Python call per
    instant. Adds each row's return (per agent for a PettingZoo id) to ``returns``."""
    loop = vector_env.envs[0]
    if multi_agent:  # the agents' rule, read from the loop's joint observation
        trigger = trigger.for_observations(
            loop.observation_space, loop.action_space, loop.observation_names
        )
    totals = np.zeros(vector_env.num_envs)
    channel_totals = np.zeros((vector_env.num_envs, loop.n_channels))
    with instants_bar(loop.n_steps, progress, description) as bar:
        while True:
            steps_run = vector_env.run_rule(trigger, PROGRESS_EVERY, totals, channel_totals)
            bar.update(int(steps_run.max()))
            if not steps_run.any():
                break
    if multi_agent:
        returns += channel_totals
    else:
        returns[:, 0] += totals


def _run_decisions(
    vector_env: Any,
    policy: SelfTriggeredPolicy,
    observations: np.ndarray,
    returns: np.ndarray,
    progress: bool,
    description: str,
) -> list[dict[str, Any]]:
    """Every row's episode from ``observations`` (just after the reset) decision by decision:
    one batched choice of the model for the rows still running, then each row's interval, the
    episode :class:`~etsc_envs.decisions.SelfTriggeredPolicy` runs instant by instant. The
    rows that chose a hold of one instant step together in one compiled call
    (:meth:`~etsc_envs.core.vector_env.EventTriggeredVectorEnv.step_rows`); every other row
    runs its interval in one compiled call of its own sub-environment
    (:func:`~etsc_envs.decisions.run_decision_interval`). Adds each row's return to
    ``returns`` and returns each row's episode metrics."""
    rows = vector_env.num_envs
    loops = vector_env.envs
    schedule = policy.schedule
    one_instant = schedule.is_hold & (schedule.lengths == 1)
    observations = np.array(observations)
    running = np.ones(rows, dtype=bool)
    ended_metrics: list[dict[str, Any]] = [{} for _ in range(rows)]
    shown = 0
    with instants_bar(loops[0].n_steps, progress, description) as bar:
        while running.any():
            deciding = np.flatnonzero(running)
            actions = policy.choose(observations[deciding])
            stepped = np.zeros(rows, dtype=bool)
            stepped[deciding[one_instant[actions]]] = True
            if stepped.any():
                chosen = actions[one_instant[actions]]
                decision, _ = schedule.transmit(observations[stepped], schedule.start(chosen))
                bits = np.zeros((rows, loops[0].n_channels), dtype=np.int64)
                bits[stepped] = decision.reshape(len(chosen), -1)
                stepped_observations, rewards, terminated, truncated = vector_env.step_rows(
                    bits, stepped
                )
                observations[stepped] = stepped_observations[stepped]
                returns[stepped, 0] += rewards[stepped]
                for row in np.flatnonzero(terminated | truncated):
                    running[row] = False
                    ended_metrics[row] = loops[row].episode_metrics()
            for row, action in zip(deciding, actions, strict=True):
                if stepped[row]:
                    continue
                observation, total, terminated_row, truncated_row, _, _ = run_decision_interval(
                    loops[row], schedule, int(action), observations[row]
                )
                observations[row] = observation
                returns[row, 0] += total
                if terminated_row or truncated_row:
                    running[row] = False
                    ended_metrics[row] = loops[row].episode_metrics()
            if progress:
                furthest = max(loop.step_index for loop in loops)
                bar.update(furthest - shown)
                shown = furthest
    return ended_metrics


def _run_predict(
    vector_env: Any,
    policy: Any,
    observations: np.ndarray,
    returns: np.ndarray,
    agent_index: np.ndarray | None,
    progress: bool,
    description: str,
) -> list[dict[str, Any]]:
    """Every row's episode from ``observations`` (just after the reset), one batched
    ``predict`` per instant (for a PettingZoo id, with ``agent_index`` gathering each agent's
    observation); adds each row's return (per agent for a PettingZoo id) to ``returns`` and
    returns each row's episode metrics, taken at the step that ends it."""
    rows = vector_env.num_envs
    loop = vector_env.envs[0]
    multi_agent = agent_index is not None
    n_agents = returns.shape[1]
    running = np.ones(rows, dtype=bool)
    ended_metrics: list[dict[str, Any]] = [{} for _ in range(rows)]
    state, episode_start = None, np.ones(rows * n_agents, dtype=bool)
    not_started = np.zeros(rows * n_agents, dtype=bool)
    steps = 0
    with instants_bar(loop.n_steps, progress, description) as bar:
        while running.any():
            policy_input = (
                observations[:, agent_index].reshape(rows * n_agents, -1)
                if multi_agent
                else observations
            )
            actions, state = policy.predict(
                policy_input, state=state, episode_start=episode_start, deterministic=True
            )
            episode_start = not_started
            actions = np.asarray(actions).reshape(rows, -1) if multi_agent else actions
            observations, rewards, terminated, truncated, _ = vector_env.step(actions)
            if multi_agent:
                returns[running] += vector_env.channel_rewards[running]
            else:
                returns[running, 0] += rewards[running]
            for row in np.flatnonzero(running & (terminated | truncated)):
                ended_metrics[row] = vector_env.envs[row].episode_metrics()
                running[row] = False
            steps += 1
            if steps % PROGRESS_EVERY == 0:
                bar.update(PROGRESS_EVERY)
    return ended_metrics

"""Run trigger policies on environments and collect the design page's episode records."""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

import etsc_envs  # noqa: F401  (registers the environment ids)
from etsc_envs.evaluation.progress import JobBar, current_job


def window_edges(edges_s: Sequence[float]) -> tuple[float, ...]:
    """``edges_s`` checked as the edges of time windows: at least two finite numbers >= 0 (s),
    strictly increasing (``ValueError`` naming ``windows_s`` otherwise)."""
    try:
        edges = tuple(float(edge) for edge in edges_s)
    except (TypeError, ValueError):
        raise ValueError(f"windows_s must be a list of numbers (s), got {edges_s!r}") from None
    if (
        len(edges) < 2
        or not all(np.isfinite(edge) and edge >= 0.0 for edge in edges)
        or any(later <= earlier for earlier, later in itertools.pairwise(edges))
    ):
        raise ValueError(
            "windows_s must be at least two finite times >= 0 (s), strictly increasing, "
            f"got {list(edges_s)!r}"
        )
    return edges


@dataclass
class EpisodeTrace:
    """Signals of one episode for plots: per-step time, cost and channels sent, transmission
    instants, and states sampled by the environment's ``state_dict``."""

    time_s: list[float] = field(default_factory=list)
    cost: list[float] = field(default_factory=list)
    sent: list[int] = field(default_factory=list)
    transmission_times_s: list[float] = field(default_factory=list)
    transmission_actions: list[np.ndarray] = field(default_factory=list)
    samples: list[dict[str, np.ndarray]] = field(default_factory=list)

    def window_totals(self, edges_s: Sequence[float]) -> list[dict[str, float]]:
        """The episode split by time: for each window ``[a, b)`` of consecutive ``edges_s``,
        the summed per-step cost (``info["cost"]``, summed over agents for a PettingZoo id) and
        the channels sent (``info["transmitted"]``) of the steps that start in it (a step runs
        from the previous step's ``time_s``, the first from 0). Windows that cover the episode
        add up to its ``mean_cost`` × ``steps`` and its ``transmissions``."""
        edges = window_edges(edges_s)
        ends = np.asarray(self.time_s, dtype=float)
        starts = np.concatenate([[0.0], ends[:-1]])
        cost = np.asarray(self.cost, dtype=float)
        sent = np.asarray(self.sent, dtype=np.int64)
        totals = []
        for start, end in itertools.pairwise(edges):
            inside = (starts >= start) & (starts < end)
            totals.append(
                {
                    "from_s": start,
                    "to_s": end,
                    "cost": float(cost[inside].sum()),
                    "transmissions": int(sent[inside].sum()),
                }
            )
        return totals

    def channel_transmission_times(self, channel: int) -> np.ndarray:
        """Transmission instants of one channel of a ``MultiBinary`` action."""
        sent = np.array([bool(np.ravel(action)[channel]) for action in self.transmission_actions])
        return np.asarray(self.transmission_times_s)[sent] if len(sent) else np.zeros(0)

    def sampled(self, name: str) -> np.ndarray:
        """The sampled signal ``name`` as an array with time along the first axis."""
        return np.array([sample[name] for sample in self.samples])


def instants_bar(total: int | None, progress: bool, description: str) -> tqdm | JobBar:
    """A progress bar over ``total`` sampling instants (hidden unless ``progress``), for one
    episode here and for a batch of them in :mod:`etsc_envs.evaluation.batch`; inside an open
    :class:`~etsc_envs.evaluation.progress.JobProgress`, the job's own bar counts the instants
    instead."""
    job = current_job()
    if job is not None:
        return JobBar(job)
    return tqdm(
        total=total,
        disable=not progress,
        desc=description,
        unit="step",
        leave=False,
        mininterval=0.5,
    )


def run_episode(
    env: gym.Env,
    policy: Any,
    seed: int | None = None,
    *,
    sample_every: int | None = None,
    progress: bool = False,
    description: str = "",
) -> tuple[dict[str, Any], EpisodeTrace]:
    """Run one episode of ``policy`` (anything with an SB3-style ``predict``) on ``env``.

    Args:
        sample_every: if set, store ``env.unwrapped.state_dict()`` every that many steps.
        progress: show a progress bar over the episode's sampling instants.

    Returns the episode record (common keys of the design page plus the paper's metrics) and
    the trace.
    """
    trace = EpisodeTrace()
    unwrapped: Any = env.unwrapped
    sampler: Callable | None = getattr(unwrapped, "state_dict", None) if sample_every else None
    obs, _ = env.reset(seed=seed)
    state, episode_start = None, np.ones(1, dtype=bool)
    total_return, steps = 0.0, 0
    bar = instants_bar(getattr(unwrapped, "n_steps", None), progress, description)
    started = time.perf_counter()
    if sampler is not None:
        trace.samples.append(sampler())
    while True:
        action, state = policy.predict(
            obs, state=state, episode_start=episode_start, deterministic=True
        )
        episode_start = np.zeros(1, dtype=bool)
        time_before = unwrapped.time_s
        obs, reward, terminated, truncated, info = env.step(action)
        steps += 1
        total_return += float(reward)
        trace.time_s.append(info["time_s"])
        trace.cost.append(info["cost"])
        trace.sent.append(int(info["transmitted"]))
        if info["transmitted"]:
            trace.transmission_times_s.append(time_before)
            trace.transmission_actions.append(np.asarray(action))
        if sampler is not None and sample_every and steps % sample_every == 0:
            trace.samples.append(sampler())
        if steps % 1000 == 0:
            bar.update(1000)
        if terminated or truncated:
            break
    bar.close()
    record = {
        "seed": seed,
        "wall_time_s": time.perf_counter() - started,
        "return": total_return,
        **info["episode_metrics"],
    }
    return record, trace


def run_parallel_episode(
    env: Any,
    policy: Any,
    seed: int | None = None,
    *,
    sample_every: int | None = None,
    progress: bool = False,
    description: str = "",
) -> tuple[dict[str, Any], EpisodeTrace]:
    """Run one episode of a PettingZoo ``ParallelEnv`` with ``policy`` shared by all agents.

    The agents' observations are stacked (in ``env.possible_agents`` order) and answered by
    one ``predict`` call per step, so a recurrent ``state`` holds one row per agent. The trace
    pools the agents' costs per step and keeps each step's transmit bits in
    ``transmission_actions`` (see :meth:`EpisodeTrace.channel_transmission_times`).

    Returns the episode record (as :func:`run_episode`, with ``return`` summed over agents and
    each agent's own ``return`` under ``agents``) and the trace.
    """
    trace = EpisodeTrace()
    unwrapped = env.unwrapped
    names = list(env.possible_agents)
    sampler: Callable | None = getattr(unwrapped, "state_dict", None) if sample_every else None
    observations, _ = env.reset(seed=seed)
    state, episode_start = None, np.ones(len(names), dtype=bool)
    returns = np.zeros(len(names))
    steps = 0
    bar = instants_bar(getattr(unwrapped, "n_steps", None), progress, description)
    started = time.perf_counter()
    if sampler is not None:
        trace.samples.append(sampler())
    infos: dict[str, Any] = {}
    while env.agents:
        batch = np.stack([observations[agent] for agent in names])
        actions, state = policy.predict(
            batch, state=state, episode_start=episode_start, deterministic=True
        )
        episode_start = np.zeros(len(names), dtype=bool)
        bits = np.asarray(actions).reshape(len(names))
        time_before = unwrapped.time_s
        observations, rewards, _, _, infos = env.step(
            {agent: int(bits[i]) for i, agent in enumerate(names)}
        )
        steps += 1
        returns += [rewards[agent] for agent in names]
        first = infos[names[0]]
        trace.time_s.append(first["time_s"])
        trace.cost.append(sum(infos[agent]["cost"] for agent in names))
        trace.sent.append(sum(int(infos[agent]["transmitted"]) for agent in names))
        if bits.any():
            trace.transmission_times_s.append(time_before)
            trace.transmission_actions.append(bits.copy())
        if sampler is not None and sample_every and steps % sample_every == 0:
            trace.samples.append(sampler())
        if steps % 1000 == 0:
            bar.update(1000)
    bar.close()
    metrics = infos[names[0]]["episode_metrics"]
    record = {
        "seed": seed,
        "wall_time_s": time.perf_counter() - started,
        "return": float(returns.sum()),
        **metrics,
    }
    record["agents"] = {
        agent: {"return": float(returns[i]), **metrics.get("agents", {}).get(agent, {})}
        for i, agent in enumerate(names)
    }
    return record, trace


def mean_record(records: list[dict[str, Any]]) -> dict[str, Any]:
    """Mean of every numeric key over episodes (keys that are ``None`` somewhere are skipped),
    plus ``failures``, the number of failed episodes, and for multi-agent records the mean of
    each agent's numeric keys under ``agents``."""
    mean: dict[str, Any] = {}
    for key in records[0]:
        values = [record.get(key) for record in records]
        if key == "seed" or not all(isinstance(v, int | float) for v in values):
            continue
        mean[key] = float(np.mean(np.asarray(values, dtype=float)))
    mean["failures"] = sum(record.get("failure") is not None for record in records)
    if all(isinstance(record.get("agents"), dict) for record in records):
        mean["agents"] = {
            agent: _numeric_mean([record["agents"].get(agent, {}) for record in records])
            for agent in records[0]["agents"]
        }
    return mean


def _numeric_mean(records: list[dict[str, Any]]) -> dict[str, float]:
    """Mean of every key that is a number in all ``records``."""
    return {
        key: float(np.mean([record[key] for record in records]))
        for key in records[0]
        if all(isinstance(record.get(key), int | float) for record in records)
    }


def to_jsonable(value: Any) -> Any:
    """``value`` with NumPy scalars and arrays turned into plain Python for ``json.dump``."""
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value

"""A transmission schedule of one scenario, and its exact run in the compiled loop.

A schedule is what a clairvoyant sender decides in advance: the sampling instants at which it
transmits and, at each, which channels send. :class:`ScheduleRun` replays a schedule on one
scenario with the environment's :meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_interval`
(one compiled call per transmission: send at its first instant, hold to the next), so a
schedule costs exactly what the same actions given to ``step`` one instant at a time cost.

Everything a step changes lives in the environment's loop arrays, so the loop's state just
before each transmission can be kept and restored: a change of the schedule at one instant is
replayed from there, not from the start (:meth:`ScheduleRun.window_cost`).
"""

from __future__ import annotations

from dataclasses import dataclass

import gymnasium as gym
import numpy as np

from etsc_envs.protocol import ScenarioSet
from etsc_envs.triggers.base import RuleTrigger

LoopState = tuple[np.ndarray, ...]
"""A copy of one row of the loop arrays: the whole state of an episode at one instant."""


@dataclass(frozen=True)
class Schedule:
    """Transmission instants (sorted, distinct, in ``0 .. n_steps - 1``) and, per instant, the
    channels that send there (``masks[i, c]`` is 1 where channel ``c`` sends at
    ``instants[i]``; every row sends at least one channel)."""

    instants: np.ndarray
    masks: np.ndarray

    def __post_init__(self) -> None:
        instants = np.asarray(self.instants, dtype=np.int64)
        masks = np.asarray(self.masks, dtype=np.int64)
        if masks.ndim != 2 or len(masks) != len(instants):
            raise ValueError(f"masks must be (instants, channels), got shape {masks.shape}")
        keep = masks.any(axis=1)
        instants, masks = instants[keep], masks[keep]
        if np.any(np.diff(instants) <= 0):
            raise ValueError("instants must be strictly increasing")
        object.__setattr__(self, "instants", instants)
        object.__setattr__(self, "masks", masks)

    @property
    def transmissions(self) -> int:
        """Channels sent over the episode (the count every record reports)."""
        return int(self.masks.sum())

    @classmethod
    def clock(cls, n_steps: int, n_channels: int, period: int) -> Schedule:
        """Every channel every ``period`` instants, from the first."""
        instants = np.arange(0, n_steps, period, dtype=np.int64)
        return cls(instants, np.ones((len(instants), n_channels), dtype=np.int64))

    def edited(self, silenced: list[tuple[int, int]], added: list[tuple[int, int]]) -> Schedule:
        """The schedule with each ``(instant, channel)`` of ``silenced`` not sending and each
        of ``added`` sending."""
        sends = {int(t): row.copy() for t, row in zip(self.instants, self.masks, strict=True)}
        width = self.masks.shape[1]
        for instant, channel in silenced:
            sends[instant][channel] = 0
        for instant, channel in added:
            sends.setdefault(instant, np.zeros(width, dtype=np.int64))[channel] = 1
        instants = sorted(sends)
        masks = np.array([sends[t] for t in instants], dtype=np.int64).reshape(-1, width)
        return Schedule(np.array(instants, dtype=np.int64), masks)

    def part(self, first: int, stop: int) -> Schedule:
        """The instants of indices ``first .. stop - 1`` alone."""
        return Schedule(self.instants[first:stop], self.masks[first:stop])

    def next_send(self, index: int, channel: int) -> int:
        """The index of ``channel``'s first send after its ``index``-th instant, or the number
        of instants if it sends no more."""
        later = np.flatnonzero(self.masks[index + 1 :, channel])
        return index + 1 + int(later[0]) if len(later) else len(self.instants)

    def previous_send(self, index: int, channel: int) -> int:
        """The index of ``channel``'s last send before its ``index``-th instant, or -1."""
        earlier = np.flatnonzero(self.masks[:index, channel])
        return int(earlier[-1]) if len(earlier) else -1

    def to_json(self) -> dict[str, list[list[int]] | list[int]]:
        return {"instants": self.instants.tolist(), "masks": self.masks.tolist()}


@dataclass
class Outcome:
    """The exact run of a schedule: its summed step cost, whether it failed, its mean cost and
    the loop's state and cumulative cost just before each of its instants (and at the end)."""

    schedule: Schedule
    cost: float
    failed: bool
    mean_cost: float
    states: list[LoopState]
    costs_before: np.ndarray

    @property
    def transmissions(self) -> int:
        return self.schedule.transmissions


class ScheduleRun:
    """One scenario of ``env_id`` (seed ``seed`` of ``scenarios``), ready to run schedules.

    The environment is made without a transmission penalty and with ``cost_scale=1``, so the
    return of an interval is minus its summed step cost (``info["cost"]``, the accuracy cost
    that ``mean_cost`` averages); neither changes the loop. ``steps`` counts the instants
    simulated, the unit of a search's budget.
    """

    def __init__(self, env_id: str, scenarios: ScenarioSet, seed: int) -> None:
        kwargs = scenarios.env_kwargs({"transmission_penalty": 0.0, "cost_scale": 1.0})
        self.env = gym.make(env_id, **kwargs).unwrapped
        if not hasattr(self.env, "run_interval"):
            raise ValueError(f"env_id: {env_id!r} is not a single-agent id of the suite")
        self.env_id = env_id
        self.seed = seed
        self.env.reset(seed=seed)
        self.initial = self.state()
        self.n_steps: int = self.env.n_steps
        self.n_channels: int = self.env.n_channels
        self.steps = 0

    def state(self) -> LoopState:
        return tuple(array[0].copy() for array in self.env.arrays)

    def restore(self, state: LoopState) -> None:
        for array, row in zip(self.env.arrays, state, strict=True):
            array[0] = row

    def _action(self, mask: np.ndarray) -> np.ndarray | int:
        return int(mask[0]) if self.n_channels == 1 else mask

    def _interval(self, mask: np.ndarray, instants: int) -> tuple[float, bool]:
        """``mask`` at the current instant, holds for the rest of ``instants``: the summed step
        cost and whether the episode ended in a failure."""
        _, reward, terminated, _, _, steps_run = self.env.run_interval(self._action(mask), instants)
        self.steps += steps_run
        return -reward, terminated

    def _segment(self, schedule: Schedule, start: int, stop: int) -> tuple[float, bool]:
        """From the restored state at instant ``start``, run ``schedule`` to instant ``stop``:
        the summed cost and whether it failed."""
        cost = 0.0
        now = start
        hold = np.zeros(self.n_channels, dtype=np.int64)
        index = int(np.searchsorted(schedule.instants, start))
        while now < stop:
            if index < len(schedule.instants) and schedule.instants[index] == now:
                mask = schedule.masks[index]
                index += 1
            else:
                mask = hold
            end = schedule.instants[index] if index < len(schedule.instants) else self.n_steps
            part, failed = self._interval(mask, int(min(end, stop)) - now)
            cost += part
            if failed:
                return cost, True
            now = int(min(end, stop))
        return cost, False

    def outcome(self, schedule: Schedule) -> Outcome:
        """The exact run of ``schedule`` from the scenario's start, keeping the state before
        each of its instants."""
        self.restore(self.initial)
        states: list[LoopState] = []
        costs = np.zeros(len(schedule.instants) + 1)
        cost, failed, now = 0.0, False, 0
        for index, instant in enumerate(schedule.instants):
            if not failed:
                part, failed = self._segment(schedule, now, int(instant))
                cost += part
                now = int(instant)
            states.append(self.state())
            costs[index] = cost
        if not failed:
            part, failed = self._segment(schedule, now, self.n_steps)
            cost += part
        costs[-1] = cost
        mean_cost = float(self.env.episode_metrics()["mean_cost"])
        return Outcome(schedule, cost, failed, mean_cost, states, costs)

    def follow(self, trigger: RuleTrigger) -> tuple[list[int], list[np.ndarray], float, bool]:
        """From the restored state to the horizon, the decisions of ``trigger`` (a rule or
        family point for this env), interval by interval in compiled calls
        (:meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_rule_interval`): the instants
        it sent at, the channels it sent there, the summed cost and whether it failed."""
        env = self.env
        instants: list[int] = []
        masks: list[np.ndarray] = []
        cost = 0.0
        while env.step_index < self.n_steps:
            before = env.transmissions.copy()
            start = env.step_index
            _, reward, terminated, _, _, steps_run = env.run_rule_interval(trigger, self.n_steps)
            self.steps += steps_run
            cost -= reward
            sent = (env.transmissions - before).astype(np.int64)
            if sent.any():
                instants.append(start)
                masks.append(sent)
            if terminated:
                return instants, masks, cost, True
        return instants, masks, cost, False

    def continued(
        self,
        base: Outcome,
        first: int,
        sends: list[tuple[int, np.ndarray]],
        trigger: RuleTrigger,
    ) -> tuple[Schedule, float] | None:
        """``base``'s schedule up to its instant index ``first``, then ``sends`` (instants at
        or after that instant, in order, each ``(instant, channels)``; a mask of zeros holds
        through its instant), then ``trigger``'s decisions from the instant after the last to
        the horizon: the schedule and its exact summed cost, or ``None`` if it fails. A move
        followed by the trigger: the rest of the episode reacts to the change, as the trigger
        would."""
        self.restore(base.states[first])
        now = int(base.schedule.instants[first])
        cost = float(base.costs_before[first])
        instants = list(base.schedule.instants[:first])
        masks = list(base.schedule.masks[:first])
        hold = np.zeros(self.n_channels, dtype=np.int64)
        for instant, mask in sends:
            for channels, length in ((hold, instant - now), (mask, 1)):
                if length > 0:
                    part, failed = self._interval(channels, length)
                    cost += part
                    if failed:
                        return None
            now = instant + 1
            if mask.any():
                instants.append(instant)
                masks.append(mask)
        if now < self.n_steps:
            later_instants, later_masks, part, failed = self.follow(trigger)
            if failed:
                return None
            cost += part
            instants += later_instants
            masks += later_masks
        masks_array = np.array(masks, dtype=np.int64).reshape(-1, self.n_channels)
        return Schedule(np.array(instants, dtype=np.int64), masks_array), cost

    def window_cost(self, base: Outcome, changed: Schedule, first: int, stop_index: int) -> float:
        """The summed cost over ``[start, stop)`` of ``changed`` — ``base``'s schedule changed
        at or after ``base``'s instant index ``first`` (instant ``start``) and before its
        instant index ``stop_index`` (``stop``; the horizon past the last) — minus ``base``'s
        over the same instants; ``inf`` if ``changed`` fails there. The screen of a move: the
        change's effect beyond ``stop`` is left out, and the exact run decides."""
        start = int(base.schedule.instants[first])
        stop = (
            int(base.schedule.instants[stop_index])
            if stop_index < len(base.schedule.instants)
            else self.n_steps
        )
        self.restore(base.states[first])
        cost, failed = self._segment(changed, start, stop)
        if failed:
            return float("inf")
        return cost - (base.costs_before[stop_index] - base.costs_before[first])


def trigger_episode(run: ScheduleRun, trigger: RuleTrigger) -> tuple[Schedule, float, bool]:
    """The episode of ``trigger`` (a rule or family point for ``run``'s env) on ``run``'s
    scenario from its start: the schedule it sends, its summed cost and whether it failed; its
    decisions run interval by interval in compiled calls
    (:meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_rule_interval`)."""
    run.restore(run.initial)
    instants, masks, cost, failed = run.follow(trigger)
    schedule = Schedule(
        np.array(instants, dtype=np.int64), np.array(masks).reshape(-1, run.n_channels)
    )
    return schedule, cost, failed


def trigger_schedule(run: ScheduleRun, trigger: RuleTrigger) -> Schedule:
    """The schedule ``trigger`` sends on ``run``'s scenario (:func:`trigger_episode`)."""
    return trigger_episode(run, trigger)[0]

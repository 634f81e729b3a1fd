"""The clairvoyant schedule of one scenario: a local search over transmission instants.

A trigger decides from what it has seen; a schedule chosen with the whole scenario known in
advance (initial state, disturbance phases) is not bound by that, so the best schedule bounds
what any trigger could reach on the scenario. This module searches for two of them, starting
from the trigger's own schedule and from the clock's:

* **fewest transmissions** at a summed cost no larger than the trigger's;
* **least cost** at no more transmissions than the trigger's.

Two ways of moving, by the length of the episode:

* **followed by the trigger** (:func:`improve_by_rollout`, exact): at each instant of the
  current schedule in time order, silence it, move it a fraction of the way to its neighbour
  or add a send halfway to the next, then let the trigger decide the rest of the episode (it
  reacts to the change, as a fixed schedule cannot); each change is run exactly to the
  horizon, and the best that the objective accepts is kept. A change of one instant can
  reshape the rest of an episode (paper 002: ±20 % of its cost), which only this judges;
* **screened in a window** (:func:`improve`, for long multi-channel episodes): one pass
  screens every move of the current schedule — silence one channel's send, move it, add one —
  by its effect on the cost from the state kept before the change up to the changed channel's
  next send and ``tail`` instants of the schedule beyond
  (:meth:`~agents.oracle.schedule.ScheduleRun.window_cost`). Of the screened moves whose
  windows do not overlap, it takes those that gain at an unchanged count (moves that lower the
  cost, and pairs of an add and a silence that gain together) and, for fewest transmissions,
  silences while their screened costs fit the slack to the trigger's cost. It runs the changed
  schedule exactly from the start; a schedule is accepted only on its exact run, and when the
  exact run misses, the last half of the moves is dropped and it runs again.

Where the run tunes (``tuning_steps``), each objective's first start is not the trigger's
schedule but the schedule of its family point tuned on the scenario for that objective
(:mod:`agents.oracle.tuned`): whole episodes with the trigger in the loop, the learned point
the tuning's first candidate, so the start is never worse than the trigger's.

A pass that finds nothing is followed by one at finer shift fractions. The search stops when a
pass finds nothing at the finest shift fractions, or at its budget of simulated instants. What it
returns is a schedule that exists, so the true limit lies at or below it: learned ÷ clairvoyant
is a lower bound of the gap.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from agents.oracle.schedule import Outcome, Schedule, ScheduleRun, trigger_schedule
from agents.oracle.tuned import point_policy, tune_on_scenario
from etsc_envs.triggers.base import RuleTrigger
from etsc_envs.triggers.family import LearnedTrigger

SHIFT_FRACTIONS = ((0.5,), (0.25,), (0.1,))
"""Fractions of the gap to a channel's neighbouring send that a send is moved by: the coarse
one first, each finer one once a pass at the one before finds nothing."""

START_SHARES = {"trigger": 0.375, "tuned": 0.375, "clock": 0.125}
"""The share of the budget each objective's search gets from each start: most from the
trigger's schedule (or, where the search tunes, from the tuned point's, which takes its place),
which starts at its cost and count; the clock's is the check that another start does not reach
further."""

CLOCK_RATIO = 1.1
"""The clock of fewest transmissions is bisected (geometrically) on its period to this ratio
of the last feasible and infeasible periods."""


@dataclass(frozen=True)
class Move:
    """One screened change of a schedule: silence ``(instant, channel)`` pairs, add others;
    ``delta`` is its screened cost change and ``spans`` the ranges of the schedule's instant
    indices whose windows it touches."""

    delta: float
    silenced: tuple[tuple[int, int], ...]
    added: tuple[tuple[int, int], ...]
    spans: tuple[tuple[int, int], ...]

    @property
    def sends(self) -> int:
        """Its change of the transmission count."""
        return len(self.added) - len(self.silenced)

    def __add__(self, other: Move) -> Move:
        return Move(
            self.delta + other.delta,
            self.silenced + other.silenced,
            self.added + other.added,
            self.spans + other.spans,
        )


@dataclass
class SearchLog:
    """The search's curve: after each accepted step, the instants simulated so far, the
    schedule's transmissions and its summed cost."""

    points: list[dict[str, float]] = field(default_factory=list)

    def note(self, run: ScheduleRun, outcome: Outcome) -> None:
        self.points.append(
            {"steps": run.steps, "transmissions": outcome.transmissions, "cost": outcome.cost}
        )


def screen_moves(
    run: ScheduleRun,
    base: Outcome,
    fractions: tuple[float, ...],
    tail: int | None,
    budget_steps: int,
    indices: range | None = None,
) -> list[Move]:
    """Every move of ``base``'s schedule, screened (see the module docstring), in the order of
    its instants (those of ``indices``, by default all) until ``run`` has simulated
    ``budget_steps`` instants."""
    schedule = base.schedule
    instants = schedule.instants
    count = len(instants)
    moves: list[Move] = []
    for index in range(count) if indices is None else indices:
        if run.steps >= budget_steps:
            break
        start = int(instants[index])
        for channel in np.flatnonzero(schedule.masks[index]):
            channel = int(channel)
            after = schedule.next_send(index, channel)
            stop = count if tail is None else min(after + tail, count)
            next_instant = int(instants[after]) if after < count else run.n_steps
            before = schedule.previous_send(index, channel)
            previous_instant = int(instants[before]) if before >= 0 else 0
            send = ((start, channel),)

            def screen(
                silenced: tuple[tuple[int, int], ...],
                added: tuple[tuple[int, int], ...],
                first: int,
                stop: int = stop,
            ) -> None:
                window = schedule.part(first, stop).edited(list(silenced), list(added))
                delta = run.window_cost(base, window, first, stop)
                if np.isfinite(delta):
                    moves.append(Move(delta, silenced, added, ((first, stop),)))

            screen(send, (), index)
            for fraction in fractions:
                later = start + round(fraction * (next_instant - start))
                if start < later < next_instant:
                    screen(send, ((later, channel),), index)
                earlier = start - round(fraction * (start - previous_instant))
                first = int(np.searchsorted(instants, earlier, side="right")) - 1
                if previous_instant < earlier < start and first >= 0:
                    screen(send, ((earlier, channel),), first)
            middle = (start + next_instant) // 2
            if start < middle < next_instant:
                screen((), ((middle, channel),), index)
    return moves


def _disjoint(moves: list[Move], taken: list[tuple[int, int]]) -> list[Move]:
    """``moves`` in order, each kept if none of its spans overlaps a span taken before
    (``taken`` grows)."""
    kept = []
    for move in moves:
        if all(high <= a or low >= b for low, high in move.spans for a, b in taken):
            taken.extend(move.spans)
            kept.append(move)
    return kept


def plan_least_cost(moves: list[Move], taken: list[tuple[int, int]]) -> list[Move]:
    """The moves that gain at an unchanged count, best first: shifts that lower the cost, and
    pairs of the best add with the cheapest silence while together they gain; their windows
    do not overlap (``taken`` receives their spans)."""
    shifts = sorted((m for m in moves if m.delta < 0 and m.sends == 0), key=lambda m: m.delta)
    gains = _disjoint(shifts, taken)
    adds = _disjoint(sorted((m for m in moves if m.sends > 0), key=lambda m: m.delta), taken)
    silences = sorted((m for m in moves if m.sends < 0), key=lambda m: m.delta)
    for added, silenced in zip(adds, _disjoint(silences, taken), strict=False):
        if added.delta + silenced.delta >= 0:
            break
        gains.append(added + silenced)
    return sorted(gains, key=lambda m: m.delta)


def plan_fewest(moves: list[Move], slack: float) -> list[Move]:
    """:func:`plan_least_cost`'s gains, then the silences, cheapest first, while their
    screened cost increases fit ``slack`` plus those gains."""
    taken: list[tuple[int, int]] = []
    gains = plan_least_cost(moves, taken)
    budget = slack - sum(m.delta for m in gains)
    silences = []
    for move in _disjoint(sorted((m for m in moves if m.sends < 0), key=lambda m: m.delta), taken):
        if move.delta > budget:
            break
        budget -= move.delta
        silences.append(move)
    return gains + silences


def _apply(schedule: Schedule, moves: list[Move]) -> Schedule:
    silenced = [pair for move in moves for pair in move.silenced]
    added = [pair for move in moves for pair in move.added]
    return schedule.edited(silenced, added)


def improve(
    run: ScheduleRun,
    start: Outcome,
    accept: Callable[[Outcome, Outcome], bool],
    plan: Callable[[list[Move], Outcome], list[Move]],
    budget_steps: int,
    tail: int | None,
    log: SearchLog,
) -> Outcome:
    """Passes of screened moves from ``start`` (see the module docstring) until a pass at the
    finest fractions finds nothing or ``run`` has simulated ``budget_steps`` instants (checked
    before each screen and exact run, so the last one overruns it).
    ``plan`` orders the screened moves to try (the last half is dropped when the exact run
    misses); ``accept(candidate, current)`` judges an exact run."""
    current = start
    level = 0
    while run.steps < budget_steps and level < len(SHIFT_FRACTIONS):
        moves = screen_moves(run, current, SHIFT_FRACTIONS[level], tail, budget_steps)
        chosen = plan(moves, current)
        found = None
        while chosen:
            candidate = run.outcome(_apply(current.schedule, chosen))
            if not candidate.failed and accept(candidate, current):
                found = candidate
                break
            if run.steps >= budget_steps:
                return current
            chosen = chosen[: len(chosen) // 2]
        if found is None:
            level += 1
            continue
        current = found
        log.note(run, current)
    return current


@dataclass(frozen=True)
class Candidate:
    """A changed schedule followed by the trigger, with its exact summed cost."""

    schedule: Schedule
    cost: float

    @property
    def transmissions(self) -> int:
        return self.schedule.transmissions


def _rollout_changes(
    current: Outcome, index: int, fractions: tuple[float, ...], n_steps: int
) -> list[tuple[int, list[tuple[int, np.ndarray]]]]:
    """The changes at ``current``'s instant index ``index``, each ``(first, sends)`` for
    :meth:`~agents.oracle.schedule.ScheduleRun.continued`: hold through to the next instant
    (silence), move the instant's sends a fraction of the way to the next or the previous
    instant, and add a send of its channels halfway to the next."""
    instants, masks = current.schedule.instants, current.schedule.masks
    start, mask = int(instants[index]), masks[index]
    following = int(instants[index + 1]) if index + 1 < len(instants) else n_steps
    hold = np.zeros_like(mask)
    changes = [(index, [(following - 1, hold)])]
    for fraction in fractions:
        later = start + round(fraction * (following - start))
        if start < later < following:
            changes.append((index, [(later, mask)]))
        if index > 0:
            previous = int(instants[index - 1])
            earlier = start - round(fraction * (start - previous))
            if previous < earlier < start:
                changes.append((index - 1, [(previous, masks[index - 1]), (earlier, mask)]))
    middle = (start + following) // 2
    if start < middle < following:
        changes.append((index, [(start, mask), (middle, mask)]))
    return changes


def improve_by_rollout(
    run: ScheduleRun,
    start: Outcome,
    trigger: RuleTrigger,
    accept: Callable[[Outcome | Candidate, Outcome | Candidate], bool],
    budget_steps: int,
    log: SearchLog,
) -> Outcome:
    """Passes over the current schedule's instants in time order: at each, every change of
    :func:`_rollout_changes`, followed by ``trigger`` to the horizon, run exactly; the best
    that ``accept`` takes (confirmed by the exact run of its schedule) becomes the current
    schedule, and the pass goes on after it. Finer shift fractions follow a pass that found
    nothing; the search stops after the finest, or at ``budget_steps`` instants (checked
    before each run)."""
    current = start
    level = 0
    while run.steps < budget_steps and level < len(SHIFT_FRACTIONS):
        found = False
        after = -1
        while run.steps < budget_steps:
            later = np.flatnonzero(current.schedule.instants > after)
            if not len(later):
                break
            index = int(later[0])
            best: Candidate | None = None
            for first, sends in _rollout_changes(
                current, index, SHIFT_FRACTIONS[level], run.n_steps
            ):
                if run.steps >= budget_steps:
                    break
                changed = run.continued(current, first, sends, trigger)
                if changed is None:
                    continue
                candidate = Candidate(*changed)
                if accept(candidate, best or current):
                    best = candidate
            after = int(current.schedule.instants[index])
            if best is not None:
                exact = run.outcome(best.schedule)
                if not exact.failed and accept(exact, current):
                    current, found = exact, True
                    log.note(run, current)
        if not found:
            level += 1
    return current


def _clock_fewest(run: ScheduleRun, target: float) -> Outcome | None:
    """A clock with a period within :data:`CLOCK_RATIO` of the longest whose exact cost is at
    most ``target`` (bisection on the period), or ``None`` if sending at every instant costs
    more."""
    low, high = 1, run.n_steps
    best = run.outcome(Schedule.clock(run.n_steps, run.n_channels, 1))
    if best.failed or best.cost > target:
        return None
    while high > CLOCK_RATIO * low and high - low > 1:
        period = min(max(round((low * high) ** 0.5), low + 1), high - 1)
        outcome = run.outcome(Schedule.clock(run.n_steps, run.n_channels, period))
        if not outcome.failed and outcome.cost <= target:
            low, best = period, outcome
        else:
            high = period
    return best


def _clock_least_cost(run: ScheduleRun, transmissions: int) -> Outcome:
    """The clock with the shortest period that sends at most ``transmissions`` (its run may
    fail: then it is no start)."""
    per_channel = max(transmissions // run.n_channels, 1)
    period = -(-run.n_steps // per_channel)
    return run.outcome(Schedule.clock(run.n_steps, run.n_channels, period))


def clairvoyant(
    run: ScheduleRun,
    learned: LearnedTrigger,
    budget_steps: int,
    tail: int | None,
    tuning_steps: int = 0,
) -> dict[str, Any]:
    """The fewest-transmissions and least-cost schedules of ``run``'s scenario against the
    learned trigger's schedule, each searched from the trigger's and the clock's schedule
    with its :data:`START_SHARES` of ``budget_steps`` simulated instants (the screening
    windows reach ``tail`` instants past a changed channel's next send, or the horizon for
    ``None``). With ``tuning_steps``, the trigger's start is its family point tuned on the
    scenario for the objective (:func:`agents.oracle.tuned.tune_on_scenario`, that many
    simulated instants, the learned point its first candidate) instead of its own schedule;
    the tuning counts against the start's share, and its moves get what is left of it, each
    followed (where ``tail`` is ``None``) by the tuned point, whose episode the start is.
    Returns the record of :func:`agents.oracle.run.run_oracle` without its settings."""
    trigger_policy = learned.policy_for(run.env)
    trigger = run.outcome(trigger_schedule(run, trigger_policy))
    if trigger.failed:
        raise ValueError(
            f"the trigger fails on scenario seed {run.seed}: no cost to match; judge it first"
        )
    results: dict[str, Any] = {"trigger": _record(run, trigger)}

    def fewest_plan(moves: list[Move], current: Outcome) -> list[Move]:
        return plan_fewest(moves, trigger.cost - current.cost)

    def fewest_accept(candidate: Outcome | Candidate, current: Outcome | Candidate) -> bool:
        return candidate.cost <= trigger.cost and (
            candidate.transmissions < current.transmissions
            or (candidate.transmissions == current.transmissions and candidate.cost < current.cost)
        )

    def least_cost_plan(moves: list[Move], current: Outcome) -> list[Move]:
        return plan_least_cost(moves, [])

    def least_cost_accept(candidate: Outcome | Candidate, current: Outcome | Candidate) -> bool:
        return candidate.transmissions <= trigger.transmissions and candidate.cost < current.cost

    objectives = {
        "fewest_transmissions": (
            lambda: _clock_fewest(run, trigger.cost),
            fewest_accept,
            fewest_plan,
        ),
        "least_cost": (
            lambda: _clock_least_cost(run, trigger.transmissions),
            least_cost_accept,
            least_cost_plan,
        ),
    }
    for number, (name, (clock, accept, plan)) in enumerate(objectives.items()):
        best: Outcome | None = None
        starts: dict[str, Any] = {}
        for start_name in ("tuned" if tuning_steps else "trigger", "clock"):
            begin = run.steps
            tuning: dict[str, Any] = {}
            follower = trigger_policy
            if start_name == "tuned":
                tuned = tune_on_scenario(
                    run, learned, trigger, name, tuning_steps, run.seed + number
                )
                start, tuning = tuned.outcome, {"tuning": tuned.record()}
                follower = point_policy(run, learned, tuned.point)
            else:
                start = trigger if start_name == "trigger" else clock()
            if start is None or start.failed:  # no clock meets the objective's bound
                starts[start_name] = None
                continue
            log = SearchLog()
            log.note(run, start)
            share = round(START_SHARES[start_name] * budget_steps)
            if tail is None:
                end = improve_by_rollout(run, start, follower, accept, begin + share, log)
            else:
                end = improve(run, start, accept, plan, begin + share, tail, log)
            starts[start_name] = {
                "start": _summary(start),
                "end": _summary(end),
                "curve": log.points,
                "steps": run.steps - begin,
                **tuning,
            }
            if best is None or accept(end, best):
                best = end
        assert best is not None
        results[name] = {**_record(run, best), "starts": starts}
    results["steps"] = run.steps
    return results


def _summary(outcome: Outcome) -> dict[str, Any]:
    return {"transmissions": outcome.transmissions, "cost": outcome.cost}


def _record(run: ScheduleRun, outcome: Outcome) -> dict[str, Any]:
    """An exact run as the record keeps it: the summed and mean cost, the transmissions, the
    schedule."""
    return {
        "transmissions": outcome.transmissions,
        "cost": outcome.cost,
        "mean_cost": outcome.mean_cost,
        "schedule": outcome.schedule.to_json(),
    }

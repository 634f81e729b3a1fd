"""The learned trigger's family point tuned on one scenario: a clairvoyant start.

The learned trigger is the one point of its family (:mod:`etsc_envs.triggers.family`) that
does best over many scenarios. Knowing the scenario, the best point for it alone may send
less at the same cost: its schedule exists and was chosen with the scenario known, so it is a
clairvoyant schedule, and unlike the local moves of :mod:`agents.oracle.search` the trigger
stays in the loop — every later send reacts to every earlier one, as in the exact rollouts,
over the whole episode, at the price of one episode per candidate.

The search is the learned trigger's own (:mod:`agents.search.cma_es`): CMA-ES (pycma) over the
same encoding θ → x (log2 of the threshold factors, of the floor and the heartbeat; the time
exponent; a coupled point's weights and strength), in the same box, from the learned point,
with the step :data:`TUNING_SIGMA` in those units. It differs in what a candidate is scored
by: one exact run of the scenario (:func:`~agents.oracle.schedule.trigger_episode`) and
the objective's constraint —

* **fewest transmissions**: the fewest sends among the points whose summed cost is at most the
  learned trigger's;
* **least cost**: the least summed cost among the points sending at most its transmissions;

— ranked feasible first (by the objective), then infeasible by how far they miss the bound, then
failed episodes. The learned point itself is the first candidate, so the tuned point is never
worse than the trigger on the objective. A network's weights (a modulated point) are kept as
they are.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from agents.oracle.schedule import Outcome, Schedule, ScheduleRun, trigger_episode
from agents.search.cma_es import EXPONENT_RANGE, SearchConfig, SearchSpace
from etsc_envs.triggers.base import RuleTrigger
from etsc_envs.triggers.family import FamilyPoint, LearnedTrigger

TUNING_SIGMA = 0.5
"""CMA-ES's initial step, in the search's units (log2 for factors, floor and heartbeat): a
factor of about 1.4 around the learned point, whose neighbourhood the tuning refines."""

OBJECTIVES = ("fewest_transmissions", "least_cost")
"""The objectives a bound can hold (:class:`Bound`), as the clairvoyant record names them."""


@dataclass(frozen=True)
class Bound:
    """An objective with its bound: the learned trigger's summed ``cost`` or its
    ``transmissions``, whichever the objective holds fixed."""

    objective: str
    cost: float
    transmissions: int

    def __post_init__(self) -> None:
        if self.objective not in OBJECTIVES:
            raise ValueError(f"objective must be one of {list(OBJECTIVES)}, got {self.objective!r}")

    def rank_key(self, cost: float, transmissions: int, failed: bool) -> tuple[int, float]:
        """Lower is better: ``(0, value)`` for a point within the bound (value: its sends or
        its cost), ``(1, miss)`` for one beyond it (miss: relative excess over the bound),
        ``(2, 0)`` for a failed episode."""
        if failed:
            return (2, 0.0)
        if self.objective == "fewest_transmissions":
            if cost <= self.cost:
                return (0, float(transmissions))
            return (1, (cost - self.cost) / max(abs(self.cost), 1e-300))
        if transmissions <= self.transmissions:
            return (0, cost)
        return (1, (transmissions - self.transmissions) / max(self.transmissions, 1))


@dataclass
class Tuned:
    """The tuning's result: the best point, its exact run, and the curve (after each
    generation, the instants simulated so far and the best point's sends and cost)."""

    point: FamilyPoint
    outcome: Outcome
    curve: list[dict[str, float]]
    candidates: int

    def record(self) -> dict[str, Any]:
        return {
            "point": self.point.to_json(),
            "candidates": self.candidates,
            "curve": self.curve,
        }


def search_space(learned: LearnedTrigger, n_steps: int) -> SearchSpace:
    """The search's encoding and box for ``learned``'s point: every plain part of θ, and the
    coupling where the point is coupled; the exponent's box widened to hold the point's p."""
    point = learned.point
    parts = ("factors", "floor", "heartbeat", "exponent")
    if point.coupling is not None:
        parts += ("coupling",)
    low, high = EXPONENT_RANGE
    config = SearchConfig(
        env_id=learned.env_id,
        penalty=1.0,  # the tuning scores by its own objective, never by the env's return
        start=point,
        search=parts,
        generations=1,
        population=2,
        scenarios=1,
        keywords=dict(learned.keywords),
        exponent_range=(min(low, point.exponent), max(high, point.exponent)),
    )
    return SearchSpace(config, n_steps, None)


def point_policy(run: ScheduleRun, learned: LearnedTrigger, point: FamilyPoint) -> RuleTrigger:
    """``point`` of ``learned``'s family as a trigger in ``run``'s env."""
    as_file = LearnedTrigger(learned.env_id, learned.family, point, learned.keywords)
    return as_file.policy_for(run.env)


def tune_on_scenario(
    run: ScheduleRun,
    learned: LearnedTrigger,
    trigger: Outcome,
    objective: str,
    budget_steps: int,
    seed: int,
) -> Tuned:
    """The point of ``learned``'s family best for ``objective`` on ``run``'s scenario (the
    module docstring), bounded by ``trigger`` — the learned point's own exact run there, the
    first candidate — and searched until ``run`` has simulated ``budget_steps`` more instants
    (checked before each generation, so the last one overruns it)."""
    bound = Bound(objective, trigger.cost, trigger.transmissions)
    space = search_space(learned, run.n_steps)
    start_point = space.decode(space.encode(learned.point).tolist())
    es = space.strategy(start_point, TUNING_SIGMA, np.random.default_rng([seed, 20_261_206]))
    stop = run.steps + budget_steps
    best_point, best_schedule, best_cost = learned.point, trigger.schedule, trigger.cost
    best_key = bound.rank_key(best_cost, best_schedule.transmissions, trigger.failed)
    candidates = 1
    curve = [_entry(run, best_schedule, best_cost)]
    while run.steps < stop:
        xs = es.ask()
        keys = []
        for x in xs:
            point = space.decode(x)
            schedule, cost, failed = trigger_episode(run, point_policy(run, learned, point))
            key = bound.rank_key(cost, schedule.transmissions, failed)
            keys.append(key)
            if key < best_key:
                best_key, best_point, best_schedule, best_cost = key, point, schedule, cost
        candidates += len(xs)
        order = sorted(range(len(xs)), key=keys.__getitem__)
        ranks = np.empty(len(xs))
        ranks[order] = np.arange(len(xs), dtype=float)
        es.tell(xs, ranks.tolist())  # CMA-ES uses the ranks alone
        curve.append(_entry(run, best_schedule, best_cost))
    outcome = trigger if best_point is learned.point else run.outcome(best_schedule)
    return Tuned(best_point, outcome, curve, candidates)


def _entry(run: ScheduleRun, schedule: Schedule, cost: float) -> dict[str, float]:
    return {"steps": run.steps, "transmissions": schedule.transmissions, "cost": cost}

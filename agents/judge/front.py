"""Is a learned front on or below the paper's threshold sweep and the periodic sweep?

The goal's third criterion (``docs/results.md``) compares curves, not points: over the paper
sweep's range of transmissions, the learned front must be on or below both the paper
trigger's threshold sweep and the periodic sweep. Each curve is read as its **envelope**
``E(x)``: the least mean cost the curve reaches with at most ``x`` transmissions. Between two
of its non-dominated points (:func:`agents.judge.pareto.non_dominated`; points with failures are not
points of a curve: a trigger that loses the loop reaches no accuracy) the envelope joins them
linearly in cost against log(transmissions) (costs may be 0: paper 003's orbit inside its
shell); beyond its
sparsest-in-cost point it stays flat (sending less than a budget is always allowed); below its
fewest transmissions it is undefined (the curve has no point there).

:func:`front_verdict` checks ``E_learned(x) <= E_sweep(x)`` at every breakpoint of the three
envelopes inside the paper sweep's range ``[a, b]`` (its failure-free points' least and most
transmissions). Both envelopes are linear in log(transmissions) between breakpoints, so the
check at the breakpoints is the check everywhere in the range. A learned envelope that is
undefined at ``a`` (no learned point as sparse as the paper's sparsest) does not cover the
range, and the verdict is not met there; a sweep undefined at ``x`` (the periodic sweep, where
every clock that sparse fails) sets no bound at ``x``. The verdict is on point estimates (the
mean over the set of each point's ``mean_cost`` and transmissions: every curve runs the same
scenarios); the plot draws each point's 95 % intervals beside it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

from etsc_envs.evaluation.statistics import summarize

Axes = Callable[[dict[str, Any]], tuple[float, float] | None]
"""A point's (transmissions, mean cost) on one scenario set, ``None`` where it failed there."""


def set_axes(point: dict[str, Any]) -> tuple[float, float] | None:
    """(transmissions, mean cost) of a point on the scenario set (means over its scenarios),
    ``None`` if it failed on any of them."""
    if point.get("failures"):
        return None
    return float(point["transmissions"]["mean"]), float(point["mean_cost"]["mean"])


def paper_scenario_axes(point: dict[str, Any]) -> tuple[float, float] | None:
    """(transmissions, mean cost) of a point's paper-scenario episode (``None``: not run, or
    failed)."""
    episode = point.get("paper_scenario")
    if episode is None or episode.get("failure") is not None:
        return None
    return float(episode["transmissions"]), float(episode["mean_cost"])


def envelope(pairs: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The non-dominated (transmissions, cost) pairs of a curve, by transmissions: each
    costs less than every pair with fewer or as many transmissions."""
    front: list[tuple[float, float]] = []
    for sent, cost in sorted(pairs):
        if sent > 0 and (not front or cost < front[-1][1]):
            front.append((sent, cost))
    return front


def envelope_cost(front: list[tuple[float, float]], sent: float) -> float | None:
    """``E(sent)`` of :func:`envelope`'s pairs (module docstring), ``None`` below its first."""
    if not front or sent < front[0][0]:
        return None
    for (x0, y0), (x1, y1) in itertools.pairwise(front):
        if sent <= x1:
            weight = (math.log(sent) - math.log(x0)) / (math.log(x1) - math.log(x0))
            return y0 + weight * (y1 - y0)
    return front[-1][1]


def compare(
    learned: list[tuple[float, float]],
    sweep: list[tuple[float, float]],
    span: tuple[float, float],
) -> dict[str, Any]:
    """``E_learned`` against ``E_sweep`` over ``span``: the largest ratio of the two where both
    are defined (``worst_ratio``, at ``worst_at`` transmissions), whether the learned envelope
    is defined over the whole span (``covers``), and ``met``: covers and ratio <= 1."""
    learned_front, sweep_front = envelope(learned), envelope(sweep)
    low, high = span
    breakpoints = sorted(
        {low, high} | {sent for sent, _ in learned_front + sweep_front if low <= sent <= high}
    )
    covers = envelope_cost(learned_front, low) is not None
    worst_ratio, worst_at = -math.inf, None
    for sent in breakpoints:
        ours, theirs = envelope_cost(learned_front, sent), envelope_cost(sweep_front, sent)
        if ours is None or theirs is None:
            continue
        ratio = _ratio(ours, theirs)
        if ratio > worst_ratio:
            worst_ratio, worst_at = ratio, sent
    met = covers and worst_at is not None and worst_ratio <= 1.0
    return {
        "covers": covers,
        "worst_ratio": None if worst_at is None else worst_ratio,
        "worst_at": worst_at,
        "met": met,
    }


def _ratio(ours: float, theirs: float) -> float:
    """ours / theirs, with 0 / 0 = 1 (both exact) and x / 0 = inf for x > 0."""
    if theirs > 0:
        return ours / theirs
    return 1.0 if ours <= 0 else math.inf


def front_verdict(
    learned: list[dict[str, Any]],
    paper: list[dict[str, Any]],
    periodic: list[dict[str, Any]],
    axes: Axes = set_axes,
) -> dict[str, Any]:
    """The learned points' front against the paper sweep and the periodic sweep (points of
    :func:`agents.judge.pareto.pareto`'s curves), on the axes ``axes`` reads (:func:`set_axes`, the
    scenario set; :func:`paper_scenario_axes`, the paper scenario). Points with failures are
    left out of every curve. Returns the paper sweep's ``range`` of transmissions, the
    learned front's (``None`` if every learned point failed: the criterion is then not met), a
    :func:`compare` of each sweep (``paper``, ``periodic``) and ``met`` (both); ``ValueError``
    if the paper sweep has no failure-free point."""

    def pairs(points: list[dict[str, Any]]) -> list[tuple[float, float]]:
        return [pair for pair in map(axes, points) if pair is not None]

    paper_pairs = pairs(paper)
    learned_pairs = pairs(learned)
    if not paper_pairs:
        raise ValueError("the paper sweep has no failure-free point to span a range")
    span = (min(sent for sent, _ in paper_pairs), max(sent for sent, _ in paper_pairs))
    if not learned_pairs:
        empty = {"covers": False, "worst_ratio": None, "worst_at": None, "met": False}
        return {
            "range": list(span),
            "learned_range": None,
            "paper": empty,
            "periodic": empty,
            "met": False,
        }
    against = {
        "paper": compare(learned_pairs, paper_pairs, span),
        "periodic": compare(learned_pairs, pairs(periodic), span),
    }
    return {
        "range": list(span),
        "learned_range": [
            min(sent for sent, _ in learned_pairs),
            max(sent for sent, _ in learned_pairs),
        ],
        **against,
        "met": all(verdict["met"] for verdict in against.values()),
    }


TRANSMISSIONS_AT_EQUAL_COST_MAX = 0.90
"""A learned point beats the hand-menu front with at most this fraction of the front's
transmissions at the point's cost..."""
COST_AT_EQUAL_TRANSMISSIONS_MAX = 0.97
"""...or at most this fraction of the front's cost at the point's transmissions."""


def envelope_transmissions(front: list[tuple[float, float]], cost: float) -> float | None:
    """The fewest transmissions at which :func:`envelope`'s pairs reach ``cost`` (the inverse
    of :func:`envelope_cost`, joined alike), ``None`` if no point of the front is as
    accurate."""
    if not front or cost < front[-1][1]:
        return None
    if cost >= front[0][1]:
        return front[0][0]
    for (x0, y0), (x1, y1) in itertools.pairwise(front):
        if y1 <= cost <= y0:
            weight = (y0 - cost) / (y0 - y1)
            return math.exp(math.log(x0) + weight * (math.log(x1) - math.log(x0)))
    return None


def menu_verdict(
    learned: list[dict[str, Any]],
    menu: list[dict[str, Any]],
    axes: Axes,
) -> dict[str, Any]:
    """Does a learned method beat the hand-menu front (the envelope of ``menu``: every hand
    rule's point, the paper and periodic sweeps included)? The method's point is the mean over
    its points (its search seeds) of their (transmissions, cost) on ``axes`` (:func:`set_axes`:
    means over the scenario set; :func:`paper_scenario_axes`: the paper episode), read at the
    upper ends of the 95 % bootstrap intervals of those means over the seeds (every point ran
    the same scenarios, so the seeds' spread is the method's uncertainty). It beats the front
    with at most :data:`TRANSMISSIONS_AT_EQUAL_COST_MAX` × the front's transmissions at its
    cost, or :data:`COST_AT_EQUAL_TRANSMISSIONS_MAX` × the front's cost at its transmissions.
    Returns both ratios at the bounds (``None`` where the front does not reach the cost or the
    transmissions) and at the means, each seed's pair, and ``met`` (at the bounds)."""
    front = envelope([pair for pair in map(axes, menu) if pair is not None])
    pairs = [pair for pair in map(axes, learned) if pair is not None]
    if not pairs or len(pairs) < len(learned):
        return {"seeds": pairs, "met": False, "failed": len(learned) - len(pairs)}
    sent = summarize([pair[0] for pair in pairs])
    cost = summarize([pair[1] for pair in pairs])

    def ratios(at_sent: float, at_cost: float) -> dict[str, float | None]:
        front_sent = envelope_transmissions(front, at_cost)
        front_cost = envelope_cost(front, at_sent)
        return {
            "transmissions": at_sent,
            "mean_cost": at_cost,
            "transmissions_ratio": None if front_sent is None else at_sent / front_sent,
            "cost_ratio": None if front_cost is None else _ratio(at_cost, front_cost),
        }

    bound = ratios(sent["mean_ci95"][1], cost["mean_ci95"][1])
    met = (
        bound["transmissions_ratio"] is not None
        and bound["transmissions_ratio"] <= TRANSMISSIONS_AT_EQUAL_COST_MAX
    ) or (
        bound["cost_ratio"] is not None and bound["cost_ratio"] <= COST_AT_EQUAL_TRANSMISSIONS_MAX
    )
    return {
        "seeds": pairs,
        "at_bound": bound,
        "at_mean": ratios(sent["mean"], cost["mean"]),
        "met": met,
    }


def menu_line(method: str, where: str, verdict: dict[str, Any]) -> str:
    """One line saying what :func:`menu_verdict` found."""
    if "at_bound" not in verdict:
        return f"{method}, {where}: a seed failed; it does not beat the hand-menu front"

    def shown(ratio: float | None) -> str:
        return "-" if ratio is None else f"x{ratio:.4g}"

    bound, mean = verdict["at_bound"], verdict["at_mean"]
    outcome = "**beats it**" if verdict["met"] else "does not beat it"
    return (
        f"{method}, {where}: against the hand-menu front, transmissions at equal cost "
        f"{shown(bound['transmissions_ratio'])} (goal <= {TRANSMISSIONS_AT_EQUAL_COST_MAX}; "
        f"{shown(mean['transmissions_ratio'])} at the seeds' mean), cost at equal transmissions "
        f"{shown(bound['cost_ratio'])} (goal <= {COST_AT_EQUAL_TRANSMISSIONS_MAX}; "
        f"{shown(mean['cost_ratio'])} at the mean), at the 95 % bounds over "
        f"{len(verdict['seeds'])} seeds; {outcome}"
    )


def verdict_line(method: str, where: str, verdict: dict[str, Any]) -> str:
    """One line saying what :func:`front_verdict` found."""
    low, high = verdict["range"]
    if verdict["learned_range"] is None:
        return f"{method}, {where}: every learned point failed; front criterion not met"
    learned_low, learned_high = verdict["learned_range"]
    parts = []
    for sweep in ("paper", "periodic"):
        part = verdict[sweep]
        ratio = part["worst_ratio"]
        at = "" if ratio is None else f" (worst x{ratio:.4g} at {part['worst_at']:.4g})"
        state = "on or below" if part["met"] else "not on or below"
        parts.append(f"{state} the {sweep} sweep{at}")
    covered = "" if verdict["paper"]["covers"] else "; does not reach the range's sparse end"
    return (
        f"{method}, {where}: front over {learned_low:.4g}-{learned_high:.4g} transmissions, "
        f"the paper sweep's range {low:.4g}-{high:.4g}{covered}; {'; '.join(parts)}; "
        f"front criterion {'**met**' if verdict['met'] else 'not met'}"
    )

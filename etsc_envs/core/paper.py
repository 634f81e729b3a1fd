"""What the suite knows about one paper, as one record.

Each problem folder holds ``paper.py`` with ``PAPER = Paper(...)``: the paper's ids, its
triggering rule (:class:`Rule`: trigger class, threshold keywords, the sweep of a Pareto front),
other event rules on the same signals, its shield, the periodic sweep that the learners use,
its headline metrics and its reproduction. :mod:`etsc_envs.papers` collects the
records and looks them up by id (:func:`etsc_envs.papers.paper_of`).

This module is problem-agnostic: it imports no trigger, so the trigger modules, the problem
folders and the records import in one direction only.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from etsc_envs.triggers.base import RuleTrigger

SCALES = (0.25, 0.5, 1.0, 2.0, 4.0)
"""Multiples of a rule's default thresholds swept where the threshold is a free positive
number."""

PERIODIC_EVERY = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000)
"""Sampling instants between periodic transmissions swept on a Pareto front."""

RULE_NAMES = ("paper", "error_time")
"""The names of the event rules a paper record may carry (:attr:`Paper.rules`), as
``python -m baselines.evaluate --policy NAME`` and a decision set's ``rule`` name them."""


@dataclass(frozen=True)
class Rule:
    """An event rule of a paper's ids.

    Args:
        trigger: its rule trigger class (its thresholds are constructor keywords).
        thresholds: the keywords of ``trigger`` that set how much error it tolerates before
            transmitting, at their default values (a fresh dict each call).
        sweep_scales: the multiples of ``thresholds()`` at which a Pareto front runs the rule.
        sweep_points: the front's points written out, where the threshold is not a free
            positive number (paper 001's c lies in (0, 1)); when given, ``sweep_scales`` is
            unused.
    """

    trigger: type[RuleTrigger]
    thresholds: Callable[[], dict[str, float]]
    sweep_scales: tuple[float, ...] = SCALES
    sweep_points: tuple[Mapping[str, float], ...] = field(default=(), hash=False)

    def sweep(self) -> list[dict[str, float]]:
        """The threshold keywords of each point of the rule's curve on a Pareto front."""
        if self.sweep_points:
            return [dict(point) for point in self.sweep_points]
        values = self.thresholds()
        return [
            {name: scale * value for name, value in values.items()} for scale in self.sweep_scales
        ]


@dataclass(frozen=True)
class Paper:
    """One paper of the suite.

    Args:
        number: the paper's number, ``"000"`` .. (``python -m baselines.reproduce --paper``).
        folder: its problem folder under ``etsc_envs/``.
        title: the title its reproduction prints.
        ids: its environment ids (Gymnasium, and PettingZoo where it has a multi-agent form).
        rule: the paper's own triggering rule (``--policy paper``).
        error_time: the error-time rule on the same signals (``--policy error_time``), on
            papers whose observation carries a per-channel sampling error; ``None`` elsewhere.
        shield: the class of its shield (:class:`etsc_envs.triggers.InnerFormationShield`'s
            interface), where the paper gives a condition under which a hold is unsafe.
        periodic_every: sampling instants between periodic transmissions swept on a front.
        headline_metrics: the paper's own metrics shown beside ``mean_cost`` and the
            transmissions when results are judged.
        cost: what ``mean_cost`` (the mean per-step accuracy cost, before ``cost_scale``)
            is for its ids: the per-step cost's formula and units, as the env pages give it.
        reproduction: the module (of the checkout, not installed) that reproduces the paper's
            numbers, with ``PAPER``, ``TITLE`` and ``reproduce(plot_dir, progress)``.
    """

    number: str
    folder: str
    title: str
    ids: tuple[str, ...]
    rule: Rule
    error_time: Rule | None = None
    shield: type[Any] | None = None
    periodic_every: tuple[int, ...] = PERIODIC_EVERY
    headline_metrics: tuple[str, ...] = ()
    cost: str = ""
    reproduction: str = ""

    @property
    def trigger(self) -> type[RuleTrigger]:
        """The paper's trigger policy class."""
        return self.rule.trigger

    @property
    def rules(self) -> dict[str, Rule]:
        """Rule name (of :data:`RULE_NAMES`) → the rule, for the rules this paper has."""
        named = {"paper": self.rule, "error_time": self.error_time}
        return {name: rule for name, rule in named.items() if rule is not None}

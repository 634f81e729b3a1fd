"""The one comparison of the suite: does a trigger beat, tie or lose to another, at the 95 %
bound, failures counted first.

Every verdict the suite prints comes from :func:`compare` — an :class:`~etsc_envs.evaluation.
Evaluation`'s comparison with the paper's rule and its standing on the leaderboard, the goal and
"beats periodic" of ``agents.results``:

1. **Failures first.** A candidate that failed any episode meets and beats nothing: it
   ``loses`` where the reference failed none, and the pair is ``both fail`` where the reference
   failed too (a failed episode is cut short, so its cost and transmissions say nothing). A
   candidate that failed none ``beats`` a reference that failed some, whatever the axes say.
2. **Then each axis** (cost, transmissions): the 95 % interval of the candidate against the
   reference (:class:`Axis`) — a per-scenario ratio's with ``limit`` 1 (or a goal's limit), or
   a difference's with ``limit`` 0 — ``beats`` when it lies wholly below the limit, ``loses``
   when wholly above, ``ties`` when it reaches the limit. A scenario where the reference's
   value is 0 and the candidate's is not loses that axis (no ratio says so).
3. **Overall**: ``beats`` when every axis beats, ``loses`` when one loses and none beats,
   ``ties`` when every axis ties, ``trade-off`` when one beats and another loses, ``better``
   when some beat and the rest tie. ``met`` is "beats on every axis" (the goal's criterion).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

OUTCOMES = ("beats", "better", "ties", "trade-off", "loses", "both fail")
"""Every overall outcome of :func:`compare`, best first."""


@dataclass(frozen=True)
class Axis:
    """One axis of a comparison: the 95 % interval of the candidate against the reference.

    Args:
        interval: ``[low, high]`` of a ratio candidate / reference (``limit`` 1, or a goal's
            bound) or of a difference candidate − reference (``limit`` 0); ``None`` where no
            interval exists (every reference 0).
        limit: the value that separates better (below) from worse (above).
        worse_where_reference_zero: scenarios where the reference's value is 0 and the
            candidate's is not (they have no ratio; the candidate is worse there).
    """

    interval: tuple[float, float] | list[float] | None
    limit: float = 1.0
    worse_where_reference_zero: int = 0

    def outcome(self) -> tuple[str, str | None]:
        """``beats``, ``ties`` or ``loses``, and the reason of anything but ``beats``."""
        if self.worse_where_reference_zero:
            return "loses", (
                f"above 0 on {self.worse_where_reference_zero} scenario(s) where the reference is 0"
            )
        if self.interval is None:
            return "ties", "no interval (the reference is 0 on every scenario)"
        low, high = (float(bound) for bound in self.interval)
        if high < self.limit:
            return "beats", None
        if low > self.limit:
            return "loses", f"interval [{low:.4g}, {high:.4g}] above {self.limit:g}"
        return "ties", f"interval [{low:.4g}, {high:.4g}] reaches {self.limit:g}"


@dataclass(frozen=True)
class Verdict:
    """What :func:`compare` found.

    Attributes:
        outcome: one of :data:`OUTCOMES`.
        axes: each axis's ``beats``, ``ties`` or ``loses`` (empty where failures decided).
        reasons: why it is not ``beats`` on each axis, or what the failures decided.
        failures: the candidate's and the reference's failed episodes.
    """

    outcome: str
    axes: dict[str, str] = field(default_factory=dict)
    reasons: tuple[str, ...] = ()
    failures: tuple[int, int] = (0, 0)

    @property
    def met(self) -> bool:
        """Whether the candidate beats the reference on every axis (never with a failure)."""
        return self.outcome == "beats"

    def to_json(self) -> dict[str, Any]:
        """The verdict as JSON: ``outcome``, ``met``, ``axes``, ``reasons``, ``failures``."""
        return {
            "outcome": self.outcome,
            "met": self.met,
            "axes": dict(self.axes),
            "reasons": list(self.reasons),
            "failures": list(self.failures),
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Verdict:
        """The verdict :meth:`to_json` wrote."""
        failures = data.get("failures", (0, 0))
        return cls(
            data["outcome"],
            dict(data.get("axes", {})),
            tuple(data.get("reasons", ())),
            (int(failures[0]), int(failures[1])),
        )

    def text(self) -> str:
        """The verdict in words: the outcome, with its reasons unless it beats."""
        word = f"**{self.outcome}**" if self.met else self.outcome
        return word if not self.reasons else f"{word} ({'; '.join(self.reasons)})"


def compare(candidate_failures: int, reference_failures: int, axes: Mapping[str, Axis]) -> Verdict:
    """The verdict of a candidate against a reference (see the module docstring).

    Args:
        candidate_failures: the candidate's failed episodes.
        reference_failures: the reference's failed episodes (on the same scenarios, or on its
            own set for an unpaired comparison).
        axes: name → :class:`Axis` (``cost``, ``transmissions``, ...), at least one.
    """
    if not axes:
        raise ValueError("axes must name at least one axis")
    failures = (int(candidate_failures), int(reference_failures))
    if failures[0] and failures[1]:
        reason = f"both fail: the candidate {failures[0]} episode(s), the reference {failures[1]}"
        return Verdict("both fail", reasons=(reason,), failures=failures)
    if failures[0]:
        reason = f"the candidate fails {failures[0]} episode(s), the reference none"
        return Verdict("loses", reasons=(reason,), failures=failures)
    if failures[1]:
        reason = f"the reference fails {failures[1]} episode(s), the candidate none"
        return Verdict("beats", reasons=(reason,), failures=failures)
    outcomes = {name: axis.outcome() for name, axis in axes.items()}
    words = {name: word for name, (word, _) in outcomes.items()}
    reasons = tuple(f"{name} {reason}" for name, (_, reason) in outcomes.items() if reason)
    found = set(words.values())
    if found == {"beats"}:
        outcome = "beats"
    elif found == {"ties"}:
        outcome = "ties"
    elif "beats" in found and "loses" in found:
        outcome = "trade-off"
    elif "loses" in found:
        outcome = "loses"
    else:
        outcome = "better"
    return Verdict(outcome, words, reasons, failures)


def ratio_axis(ratio: Mapping[str, Any], limit: float = 1.0) -> Axis:
    """The :class:`Axis` of a paired ratio (:func:`~etsc_envs.evaluation.statistics.
    paired_ratio` or :func:`~etsc_envs.evaluation.statistics.seeds_ratio`): the interval of
    the IQM of the per-scenario ratios against ``limit``."""
    return Axis(ratio.get("iqm_ci95"), limit, int(ratio.get("worse_where_reference_zero", 0)))


def difference_axis(
    candidate: tuple[float, float] | list[float], reference: tuple[float, float] | list[float]
) -> Axis:
    """The :class:`Axis` of two unpaired 95 % intervals (of means on their own scenarios): the
    candidate beats when its whole interval lies below the reference's, loses when above."""
    return Axis((candidate[0] - reference[1], candidate[1] - reference[0]), 0.0)

"""The front criterion: a learned front on or below the paper and periodic sweeps over the
paper sweep's range of transmissions (:mod:`agents.judge.front`)."""

from __future__ import annotations

import math

import pytest

from agents.judge.front import (
    envelope,
    envelope_cost,
    envelope_transmissions,
    front_verdict,
    menu_verdict,
    paper_scenario_axes,
    set_axes,
    verdict_line,
)
from agents.judge.pareto import front_verdicts


def point(sent: float, cost: float, failures: int = 0, paper: tuple | None = None) -> dict:
    """A point as :func:`agents.judge.pareto.pareto` writes it (set aggregates, paper episode)."""
    episode = None
    if paper is not None:
        episode = {"transmissions": paper[0], "mean_cost": paper[1], "failure": None}
    return {
        "transmissions": {"mean": sent},
        "mean_cost": {"mean": cost},
        "failures": failures,
        "paper_scenario": episode,
    }


PAPER = [point(100, 4.0), point(200, 3.0), point(400, 2.0)]
PERIODIC = [point(50, 9.0, failures=3), point(100, 5.0), point(400, 1.5), point(800, 1.8)]


def test_the_envelope_keeps_the_best_cost_within_each_budget():
    front = envelope([(800, 1.8), (100, 5.0), (400, 1.5), (200, 6.0)])
    assert front == [(100, 5.0), (400, 1.5)]
    assert envelope_cost(front, 50) is None  # no point that sparse
    assert envelope_cost(front, 100) == 5.0
    # halfway in log(transmissions) between 100 and 400, halfway in cost
    assert envelope_cost(front, 200) == pytest.approx(3.25)
    assert envelope_cost(front, 10_000) == 1.5  # sending less than the budget is allowed


def test_a_front_below_both_sweeps_over_the_range_meets_the_criterion():
    learned = [point(90, 3.5), point(150, 2.6), point(400, 1.4)]
    verdict = front_verdict(learned, PAPER, PERIODIC)
    assert verdict["range"] == [100, 400]
    assert verdict["learned_range"] == [90, 400]
    assert verdict["paper"]["met"] and verdict["periodic"]["met"] and verdict["met"]
    assert verdict["periodic"]["worst_ratio"] < 1


def test_a_single_point_does_not_cover_the_range():
    """One learned point cheaper than both sweeps where it sits, but the paper sweep reaches
    sparser: the front does not cover the range, whatever its ratios."""
    verdict = front_verdict([point(150, 1.0)], PAPER, PERIODIC)
    assert not verdict["paper"]["covers"] and not verdict["met"]


def test_a_front_above_a_sweep_between_its_own_points_is_caught():
    """Learned points each below the clock's envelope at their own transmissions (5 at 100,
    1.5 from 400 on), but the join between them passes above the clock's point at 400: the
    check at every breakpoint of both envelopes sees it."""
    learned = [point(100, 3.9), point(1600, 1.0)]
    verdict = front_verdict(learned, PAPER, PERIODIC)
    assert verdict["periodic"]["worst_at"] == 400
    assert verdict["periodic"]["worst_ratio"] == pytest.approx((3.9 - 2.9 * 2 / 4) / 1.5)
    assert not verdict["periodic"]["met"]


def test_failed_points_are_not_points_of_a_curve():
    """A learned point with failures does not count, and the clock that fails (every 50
    instants here, hypothetically cheap) sets no bound."""
    learned = [point(90, 0.1, failures=1), point(100, 3.5), point(400, 1.4)]
    verdict = front_verdict(learned, PAPER, [*PERIODIC, point(60, 0.01, failures=64)])
    assert verdict["learned_range"] == [100, 400] and verdict["met"]
    failed = front_verdict([point(100, 1.0, failures=2)], PAPER, PERIODIC)
    assert failed["learned_range"] is None and not failed["met"]
    assert "every learned point failed" in verdict_line("m", "set", failed)
    with pytest.raises(ValueError, match="paper sweep has no failure-free point"):
        front_verdict([point(100, 1.0)], [point(100, 1.0, failures=1)], PERIODIC)


def test_zero_costs_compare_exactly():
    """Paper 003's orbit may stay inside its shell (cost 0): 0 against 0 is a tie, anything
    above 0 against 0 is infinitely worse."""
    assert front_verdict([point(100, 0.0)], [point(100, 0.0)], [point(100, 0.0)])["met"]
    verdict = front_verdict([point(100, 0.1)], [point(100, 0.0)], [point(100, 1.0)])
    assert verdict["paper"]["worst_ratio"] == math.inf and not verdict["met"]


def test_the_paper_scenario_is_judged_on_its_own_episode():
    learned = [point(100, 9.0, paper=(80, 1.0))]
    paper = [point(100, 1.0, paper=(100, 2.0))]
    periodic = [point(100, 1.0, paper=(100, 3.0))]
    assert not front_verdict(learned, paper, periodic)["met"]
    assert front_verdict(learned, paper, periodic, paper_scenario_axes)["met"]


def test_pareto_judges_every_learned_method_on_the_set_and_the_paper_scenario():
    result = {
        "curves": {
            "paper": [point(100, 4.0, paper=(100, 4.0)), point(400, 2.0, paper=(400, 2.0))],
            "periodic": [point(100, 5.0, paper=(100, 5.0))],
            "learned": [
                {**point(90, 3.0, paper=(90, 3.0)), "method": "front"},
                {**point(400, 1.0, paper=(400, 1.0)), "method": "front"},
                {**point(300, 3.0), "method": "single"},
            ],
        }
    }
    verdicts = front_verdicts(result)
    assert verdicts["front"]["set"]["met"] and verdicts["front"]["paper"]["met"]
    assert "paper" not in verdicts["single"] and not verdicts["single"]["set"]["met"]


def bounded(sent: float, cost: float, policy: str = "paper") -> dict:
    """A point on the set and on the paper scenario alike."""
    return {
        "policy": policy,
        "transmissions": {"mean": sent},
        "mean_cost": {"mean": cost},
        "failures": 0,
        "paper_scenario": {"transmissions": sent, "mean_cost": cost, "failure": None},
    }


MENU = [bounded(100, 4.0), bounded(400, 2.0), bounded(1600, 1.0)]


def test_the_inverse_envelope_joins_in_log_transmissions():
    front = envelope([(100, 4.0), (400, 2.0)])
    assert envelope_transmissions(front, 3.0) == pytest.approx(200.0)
    assert envelope_transmissions(front, 5.0) == 100
    assert envelope_transmissions(front, 1.0) is None  # the menu never gets that accurate


def test_a_learned_method_beats_the_menu_by_transmissions_or_by_cost():
    fewer = menu_verdict([bounded(170, 3.0, "learned:x")] * 3, MENU, set_axes)
    assert fewer["at_bound"]["transmissions_ratio"] == pytest.approx(170 / 200)
    assert fewer["met"]
    cheaper = menu_verdict([bounded(400, 1.9, "learned:x")] * 3, MENU, set_axes)
    assert cheaper["at_bound"]["cost_ratio"] == pytest.approx(0.95) and cheaper["met"]
    level = menu_verdict([bounded(400, 2.0, "learned:x")] * 3, MENU, set_axes)
    assert not level["met"]


def test_the_menu_verdict_reads_the_seeds_mean_at_its_intervals_upper_bound():
    """Seeds of 150 and 190 transmissions at cost 3: their mean (170) beats the front, the
    upper end of its interval over the seeds (190, x0.95) does not."""
    seeds = [bounded(150, 3.0, "learned:x"), bounded(190, 3.0, "learned:x")]
    verdict = menu_verdict(seeds, MENU, set_axes)
    assert verdict["at_mean"]["transmissions_ratio"] == pytest.approx(0.85)
    assert verdict["at_bound"]["transmissions_ratio"] == pytest.approx(0.95)
    assert not verdict["met"]
    failed = {**bounded(100, 1.0, "learned:x"), "failures": 2}
    assert not menu_verdict([*seeds, failed], MENU, set_axes)["met"]


def test_pareto_judges_searched_methods_against_every_hand_point():
    result = {
        "curves": {
            "paper": MENU[:2],
            "periodic": [bounded(1600, 1.0, policy="periodic")],
            "learned": [
                {**bounded(170, 3.0, policy="learned:a.json"), "method": "search"},
                {**bounded(100, 3.5, policy="sb3:pinned.zip"), "method": "pinned"},
            ],
        }
    }
    verdicts = front_verdicts(result)
    assert "set_menu" not in verdicts["pinned"]
    # the pinned rule is a hand point: the search's 170 at 3.0 is not below its envelope
    assert not verdicts["search"]["set_menu"]["met"]
    assert verdicts["search"]["set_menu"]["at_bound"]["transmissions_ratio"] > 0.9
    result["curves"]["learned"].pop()
    verdicts = front_verdicts(result)
    assert verdicts["search"]["set_menu"]["met"] and verdicts["search"]["paper_menu"]["met"]


def test_a_front_of_searches_is_judged_against_the_menu_per_penalty():
    """Seeds of one penalty are one method; a front's penalties are not pooled as seeds."""

    def trial(penalty: float, seed: int, sent: float, cost: float) -> dict:
        path = f"learned:front/trials/penalty={penalty:g},seed={seed}/learned.json"
        return {**bounded(sent, cost, policy=path), "method": "front"}

    result = {
        "curves": {
            "paper": MENU[:2],
            "periodic": [bounded(1600, 1.0, policy="periodic")],
            "learned": [trial(10, 0, 170, 3.0), trial(10, 1, 170, 3.0), trial(1, 0, 1600, 1.0)],
        }
    }
    verdicts = front_verdicts(result)
    assert "set_menu" not in verdicts["front"] and "set" in verdicts["front"]
    assert verdicts["front penalty=10"]["set_menu"]["met"]  # x0.85 at equal cost
    assert verdicts["front penalty=10"]["set_menu"]["seeds"] == [(170.0, 3.0)] * 2
    assert not verdicts["front penalty=1"]["set_menu"]["met"]
    assert "paper_menu" in verdicts["front penalty=1"]
    one_penalty = {
        **result,
        "curves": {**result["curves"], "learned": result["curves"]["learned"][:2]},
    }
    assert front_verdicts(one_penalty)["front"]["set_menu"]["met"]

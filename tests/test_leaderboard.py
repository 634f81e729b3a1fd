"""``docs/leaderboard.md`` is what ``python -m agents.leaderboard`` makes of the records."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

pytest.importorskip("rliable")

from agents.judge import leaderboard

BOARD = next(b for b in leaderboard.BOARDS if b.env_id == "etsc/AttitudeTracking-v0")


def test_committed_leaderboard_is_what_the_records_give() -> None:
    text = leaderboard.render(leaderboard.RECORDS, None, leaderboard.OUTPUT.with_suffix("").name)
    committed = leaderboard.OUTPUT.read_text(encoding="utf-8")
    assert text == committed, "docs/leaderboard.md is stale: run python -m agents.leaderboard"
    data = json.loads(leaderboard.DATA.read_text(encoding="utf-8"))
    assert data == json.loads(json.dumps(leaderboard.leaderboard_data(leaderboard.RECORDS))), (
        "etsc_envs/data/leaderboard.json is stale: run python -m agents.leaderboard"
    )


def test_every_figure_of_the_page_is_committed() -> None:
    page = leaderboard.OUTPUT.read_text(encoding="utf-8")
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", page)
    assert len(images) == len(leaderboard.BOARDS)
    for image in images:
        assert (leaderboard.OUTPUT.parent / image).is_file(), image


def test_rows_read_the_records_they_name() -> None:
    rows = {row.trigger: row for row in leaderboard.board_rows(leaderboard.RECORDS, BOARD)}
    record = json.loads(
        (leaderboard.RECORDS / BOARD.hand / "results.json").read_text(encoding="utf-8")
    )
    recorded = record["sets"]["test"]["paper"]["aggregates"]["mean_cost"]
    paper = rows["paper's rule"].sets["test"]
    # the paper's rule on the test set: the same mean and the same bootstrap interval as the
    # record's own aggregate (both from etsc_envs.evaluation.statistics.summarize)
    assert paper.cost["mean"] == recorded["mean"]
    assert paper.cost["mean_ci95"] == recorded["mean_ci95"]
    assert paper.episodes == 64 and paper.failures == 0
    # the hand point is one deterministic trigger: one run of the test set
    hand = rows[leaderboard.HAND].sets["test"]
    assert hand.episodes == 64
    assert hand.cost["mean"] == pytest.approx(
        record["sets"]["test"]["models"][0]["learned"]["mean"]["mean_cost"]
    )
    assert "menu of 14 rules" in rows[leaderboard.HAND].what
    # the clock runs at the hand point's rate: about its transmissions, far fewer than always
    clock = rows["clock"].sets["test"]
    assert clock.sent["mean"] == pytest.approx(hand.sent["mean"], rel=0.02)
    assert rows["always"].sets["test"].sent["mean"] == 50_000
    learned = rows[leaderboard.LEARNED]
    seeds = json.loads(
        (leaderboard.RECORDS / BOARD.learned / "results.json").read_text(encoding="utf-8")
    )["models"]
    assert len(seeds) >= 5 and f"({len(seeds)} search seeds" in learned.what
    assert learned.sets["test"] is not None and learned.sets["test"].episodes == len(seeds) * 64


@pytest.mark.parametrize("board", leaderboard.BOARDS, ids=lambda board: board.name)
def test_the_clairvoyant_row_reads_its_schedules(board) -> None:
    """The clairvoyant row: the fewest-transmission schedules' means over the scenarios its
    record judged, its ratios in words, no paper-scenario cell, never in the across-id
    summary (it is not a trigger)."""
    rows = {row.trigger: row for row in leaderboard.board_rows(leaderboard.RECORDS, board)}
    row = rows[leaderboard.ORACLE]
    oracle = json.loads(
        (leaderboard.RECORDS / board.oracle / "oracle.json").read_text(encoding="utf-8")
    )
    test = row.sets["test"]
    assert test is not None and row.sets["paper"] is None
    assert test.episodes == len(oracle["per_scenario"]) == 16
    fewest = [scenario["fewest_transmissions"] for scenario in oracle["per_scenario"]]
    assert test.sent["mean"] == pytest.approx(np.mean([s["transmissions"] for s in fewest]))
    assert test.cost["mean"] == pytest.approx(np.mean([s["mean_cost"] for s in fewest]))
    for scenario in oracle["per_scenario"]:  # never more cost than the trigger it matched
        assert scenario["fewest_transmissions"]["mean_cost"] <= (
            scenario["trigger"]["mean_cost"] * (1 + 1e-12)
        )
        assert (
            scenario["fewest_transmissions"]["transmissions"]
            <= (scenario["trigger"]["transmissions"])
        )
    assert "learned ÷ clairvoyant" in row.what and test.cost_values is None


@pytest.mark.parametrize("board", leaderboard.BOARDS, ids=lambda board: board.name)
def test_every_row_names_a_command_that_can_run_from_a_clone(board) -> None:
    """Each row with a record names the command that makes it; the files that command reads
    (models, configs) are in the repository, and it writes the record's own folder."""
    rows = leaderboard.board_rows(leaderboard.RECORDS, board)
    for row in rows:
        if row.record == "—":
            assert row.command is None and not any(row.sets.values()), row.trigger
            continue
        assert row.command is not None, row.trigger
        folder = row.record.strip("`/").split("/")[0]
        assert f"docs/results/{folder}" in row.command, (row.trigger, row.command)
        for path in re.findall(r"(?:--model|--config) (\S+)", row.command):
            assert (leaderboard.ROOT / path).is_file(), (row.trigger, path)


def test_the_command_of_a_record_lists_its_models_and_sets() -> None:
    record = {
        "env": "etsc/AttitudeTracking-v0",
        "models": ["models/a.json", "models/b.json"],
        "env_args": {"horizon_s": 10.0},
        "sets": {"test": {}},
    }
    assert leaderboard.results_command(record, "X_learned/sub") == (
        "python -m agents.results etsc/AttitudeTracking-v0 --model models/a.json "
        "--model models/b.json --env-arg horizon_s=10.0 --scenarios test "
        "--out docs/results/X_learned"
    )


def test_records_of_other_scenarios_are_refused() -> None:
    rows = {row.trigger: row for row in leaderboard.board_rows(leaderboard.RECORDS, BOARD)}
    paper = rows["paper's rule"].sets["test"]
    shifted = leaderboard.Measure(
        paper.cost,
        paper.sent,
        0,
        64,
        paper.cost_values,
        paper.sent_values,
        tuple(seed + 1 for seed in paper.seeds),
    )
    with pytest.raises(ValueError, match="other scenarios"):
        leaderboard._scenario_scores(shifted, paper)


def test_the_readme_table_is_what_the_records_give() -> None:
    boards = leaderboard.all_rows(leaderboard.RECORDS)
    readme = leaderboard.README.read_text(encoding="utf-8")
    table = leaderboard.readme_table(boards)
    assert leaderboard.with_readme_table(readme, table) == readme, (
        "README.md's table is stale: run python -m agents.leaderboard"
    )
    assert len(table) == 3 + len(leaderboard.BOARDS) + 1


def test_the_best_rl_agent_meets_the_cost_bound_first() -> None:
    def row(trigger: str, cost: float, sent: float, failures: int = 0) -> leaderboard.Row:
        measure = leaderboard.Measure({"mean": cost}, {"mean": sent}, failures, 64)
        return leaderboard.Row(trigger, "", "", {"test": measure, "paper": None})

    paper = row("paper's rule", 1.0, 100.0)
    cheap_many = row("per-instant PPO", 1.0, 90.0)
    dear_few = row("self-triggered PPO", 1.2, 10.0)
    assert leaderboard.best_rl_row([paper, cheap_many, dear_few]) is cheap_many
    within_few = row("self-triggered PPO", 1.04, 10.0)
    assert leaderboard.best_rl_row([paper, cheap_many, within_few]) is within_few
    failed = row("self-triggered PPO", 1.0, 1.0, failures=1)
    assert leaderboard.best_rl_row([paper, cheap_many, failed]) is cheap_many
    fails_more = row("per-instant PPO", 0.5, 1.0, failures=2)
    assert leaderboard.best_rl_row([paper, fails_more, failed]) is failed
    assert leaderboard.best_rl_row([paper]) is None

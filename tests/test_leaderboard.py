"""``docs/leaderboard.md`` is what ``python -m agents.leaderboard`` makes of the records."""

from __future__ import annotations

import json
import re
from pathlib import Path

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
        (leaderboard.RECORDS / BOARD.best / "results.json").read_text(encoding="utf-8")
    )
    recorded = record["sets"]["test"]["paper"]["aggregates"]["mean_cost"]
    paper = rows["paper's rule"].sets["test"]
    # the paper's rule on the test set: the same mean and the same bootstrap interval as the
    # record's own aggregate (both from etsc_envs.evaluation.statistics.summarize)
    assert paper.cost["mean"] == recorded["mean"]
    assert paper.cost["mean_ci95"] == recorded["mean_ci95"]
    assert paper.episodes == 64 and paper.failures == 0
    # five pinned seeds that recorded the same episodes count as one run, their episodes five
    best = rows["best hand-designed rule"].sets["test"]
    assert best.episodes == 5 * 64
    assert best.cost["mean"] == pytest.approx(
        record["sets"]["test"]["models"][0]["learned"]["mean"]["mean_cost"]
    )
    # the clock runs at the best rule's rate: about its transmissions, and far fewer than always
    clock = rows["clock"].sets["test"]
    assert clock.sent["mean"] == pytest.approx(best.sent["mean"], rel=0.02)
    assert rows["always"].sets["test"].sent["mean"] == 50_000


def test_a_learned_record_adds_its_row(tmp_path: Path) -> None:
    records = tmp_path / "results"
    records.mkdir()
    for folder in {BOARD.sweeps, BOARD.best, f"{BOARD.name}_ppo", BOARD.self_triggered}:
        assert folder is not None
        (records / folder).symlink_to(leaderboard.RECORDS / folder)
    triggers = [row.trigger for row in leaderboard.board_rows(records, BOARD)]
    assert "learned trigger (ES)" not in triggers

    record = json.loads(
        (leaderboard.RECORDS / BOARD.best / "results.json").read_text(encoding="utf-8")
    )
    for judged in record["sets"].values():
        for model in judged["models"]:
            for episode in model["learned"]["episodes"]:
                episode["mean_cost"] /= 2.0
    (records / f"{BOARD.name}_learned").mkdir()
    (records / f"{BOARD.name}_learned" / "results.json").write_text(json.dumps(record))
    rows = {row.trigger: row for row in leaderboard.board_rows(records, BOARD)}
    learned, best = rows["learned trigger (ES)"], rows["best hand-designed rule"]
    assert learned.record == f"`{BOARD.name}_learned/`"
    for name in leaderboard.SETS:
        assert learned.sets[name].cost["mean"] == pytest.approx(best.sets[name].cost["mean"] / 2)
        assert learned.sets[name].sent["mean"] == best.sets[name].sent["mean"]

    # a variant of the search gets its own row, named by its folder's suffix
    (records / f"{BOARD.name}_learned_modulated").mkdir()
    (records / f"{BOARD.name}_learned_modulated" / "results.json").write_text(json.dumps(record))
    triggers = [row.trigger for row in leaderboard.board_rows(records, BOARD)]
    assert triggers[-2:] == ["learned trigger (ES)", "learned trigger (ES, modulated)"]


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

"""``agents.judge.penalty_choice``: a front's penalty is chosen from validation records only,
as the largest whose seeds' mean chosen point contains the start's."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from agents.judge.penalty_choice import choose_penalty, main
from agents.sweep.results import SweepTrial, write_summary

START = (150.0, 0.0100)


def _front(tmp_path: Path, chosen: dict[tuple[float, int], tuple[float, float]]) -> Path:
    """A front of searches whose trial at (penalty, seed) chose the validation point given."""
    trials = []
    for (penalty, seed), (sent, cost) in chosen.items():
        name = f"penalty={penalty:g},seed={seed}"
        folder = tmp_path / "trials" / name
        folder.mkdir(parents=True)
        curve = [
            {"generation": 0, "validation_transmissions": START[0], "validation_cost": START[1]},
            {"generation": 1},
            {"generation": 2, "validation_transmissions": sent, "validation_cost": cost},
        ]
        record = {"search": {"chosen_generation": 2}, "curve": curve}
        (folder / "curve.json").write_text(json.dumps(record))
        (folder / "learned.json").write_text("{}")
        values = {"penalty": penalty, "seed": seed}
        trials.append(SweepTrial(name, values, "finished", None, folder, None))
    write_summary(tmp_path, {"env_id": "etsc/AttitudeTracking-v0", "kind": "front"}, trials)
    return tmp_path


def test_the_largest_penalty_whose_mean_contains_the_start_is_chosen(tmp_path: Path) -> None:
    front = _front(
        tmp_path,
        {
            (30.0, 0): (170.0, 0.0090),  # more transmissions: does not contain
            (30.0, 1): (160.0, 0.0091),
            (100.0, 0): (140.0, 0.0099),  # contains
            (100.0, 1): (148.0, 0.0098),
            (300.0, 0): (120.0, 0.0099),  # one seed costs more, the mean still contains
            (300.0, 1): (130.0, 0.01005),
            (1000.0, 0): (100.0, 0.0120),  # costs more: does not contain
            (1000.0, 1): (110.0, 0.0110),
        },
    )
    choice = choose_penalty(front)
    assert [row["contains_start"] for row in choice["penalties"]] == [False, True, True, False]
    assert choice["chosen"] == 300.0
    assert choice["penalties"][2]["learned"] == {
        "transmissions": 125.0,
        "mean_cost": pytest.approx(0.009975),
    }


def test_no_penalty_is_chosen_where_none_contains(tmp_path: Path, capsys) -> None:
    front = _front(tmp_path, {(1.0, 0): (300.0, 0.009), (10.0, 0): (100.0, 0.011)})
    assert choose_penalty(front)["chosen"] is None
    assert main([str(front)]) == 0
    assert "chosen: no penalty contains the start" in capsys.readouterr().out


def test_an_unfinished_trial_is_refused(tmp_path: Path, capsys) -> None:
    front = _front(tmp_path, {(1.0, 0): (100.0, 0.009)})
    summary = json.loads((front / "sweep_summary.json").read_text())
    summary["trials"][0]["status"] = "incomplete"
    (front / "sweep_summary.json").write_text(json.dumps(summary))
    with pytest.raises(SystemExit):
        main([str(front)])
    assert "is incomplete; finish the sweep first" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("summary", "message"),
    [
        (None, r"RESULTS_DIR: '.*' holds no sweep_summary\.json"),
        ("{not json", r"RESULTS_DIR: .*sweep_summary\.json is not readable JSON"),
        ('{"sweep": "x"}', r"RESULTS_DIR: .*sweep_summary\.json is not a sweep summary"),
    ],
)
def test_a_folder_that_is_not_a_sweep_is_named(tmp_path: Path, capsys, summary, message) -> None:
    if summary is not None:
        (tmp_path / "sweep_summary.json").write_text(summary)
    with pytest.raises(SystemExit):
        main([str(tmp_path)])
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert re.search(message, error), error


def _training_front(tmp_path: Path, runs: dict[tuple[float, int], list[tuple]]) -> Path:
    """A front of training runs whose evaluations at (penalty, seed) recorded the
    (return, transmissions, mean cost) given, beside the paper rule's validation."""
    trials = []
    for (penalty, seed), evaluations in runs.items():
        name = f"transmission_penalty={penalty:g},seed={seed}"
        folder = tmp_path / "trials" / name
        folder.mkdir(parents=True)
        paper = {"transmissions": START[0], "mean_cost": START[1], "return": -1.0}
        entries = [
            {"learned": {"return": r, "transmissions": sent, "mean_cost": cost}, "paper": paper}
            for r, sent, cost in evaluations
        ]
        (folder / "evaluations.json").write_text(json.dumps(entries))
        values = {"env_kwargs.transmission_penalty": penalty, "seed": seed}
        trials.append(SweepTrial(name, values, "finished", None, folder, None))
    write_summary(tmp_path, {"env_id": "etsc/AttitudeTracking-v0", "kind": "front"}, trials)
    return tmp_path


def test_a_training_front_is_judged_at_its_best_validation_checkpoints(tmp_path: Path) -> None:
    """Each run's point is its best-return evaluation (the checkpoint it keeps), not its last;
    the reference is the paper rule every run validated."""
    front = _training_front(
        tmp_path,
        {
            (100.0, 0): [(-5.0, 100.0, 0.009), (-2.0, 140.0, 0.0099), (-3.0, 90.0, 0.02)],
            (100.0, 1): [(-1.0, 146.0, 0.0097)],
            (300.0, 0): [(-4.0, 120.0, 0.011), (-9.0, 80.0, 0.0090)],
            (300.0, 1): [(-1.0, 110.0, 0.012)],
        },
    )
    choice = choose_penalty(front)
    assert choice["reference"] == "paper rule"
    assert choice["penalties"][0]["learned"] == {
        "transmissions": 143.0,
        "mean_cost": pytest.approx(0.0098),
    }
    assert [row["contains_start"] for row in choice["penalties"]] == [True, False]
    assert choice["chosen"] == 100.0
    assert choice["penalties"][1]["larger_ratio"] == pytest.approx(1.15)


def test_a_run_is_judged_at_its_best_trained_checkpoint_not_an_untrained_one(
    tmp_path: Path,
) -> None:
    """An evaluation of a network no gradient step had touched (``"trained": false``) is not
    the checkpoint a run keeps, however well it scored; a run that validated no trained
    policy is refused in one line."""
    runs = {(100.0, 0): [(-1.0, 10.0, 0.009), (-7.0, 140.0, 0.0099)]}
    front = _training_front(tmp_path / "front", runs)
    record = front / "trials" / "transmission_penalty=100,seed=0" / "evaluations.json"
    entries = json.loads(record.read_text())
    entries[0]["trained"] = False
    record.write_text(json.dumps(entries))
    assert choose_penalty(front)["penalties"][0]["learned"]["transmissions"] == 140.0
    entries[1]["trained"] = False
    record.write_text(json.dumps(entries))
    with pytest.raises(ValueError, match="validated no trained policy"):
        choose_penalty(front)


def test_where_no_penalty_contains_the_closest_is_named(tmp_path: Path, capsys) -> None:
    front = _training_front(
        tmp_path,
        {(10.0, 0): [(-1.0, 300.0, 0.009)], (100.0, 0): [(-1.0, 160.0, 0.0101)]},
    )
    choice = choose_penalty(front)
    assert choice["chosen"] is None and choice["closest"] == 100.0
    assert main([str(front)]) == 0
    assert "no penalty contains the paper rule (closest: 100)" in capsys.readouterr().out

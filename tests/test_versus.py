"""``agents.judge.versus``: a method's seeds against one model of another record."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from agents.judge import versus

SEEDS = list(range(2_000_000, 2_000_008))


def _model(path: str, cost: list[float], sent: list[float], failed: int = 0) -> dict:
    episodes = [
        {
            "seed": seed,
            "mean_cost": c,
            "transmissions": s,
            "failure": "collision" if i < failed else None,
        }
        for i, (seed, c, s) in enumerate(zip(SEEDS, cost, sent, strict=True))
    ]
    return {"model": path, "learned": {"episodes": episodes}}


def _record(folder: Path, models: dict[str, tuple[list[float], list[float]]], **kw) -> Path:
    """A results.json with one ``test`` set: each model's per-scenario cost and transmissions."""
    record = {
        "env": kw.get("env", "etsc/InnerFormation-v0"),
        "models": list(models),
        "sets": {"test": {"models": [_model(path, *values) for path, values in models.items()]}},
    }
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "results.json").write_text(json.dumps(record))
    return folder


@pytest.fixture
def records(tmp_path: Path) -> tuple[Path, Path, Path]:
    rng = np.random.default_rng(0)
    cost = list(1.0 + 0.1 * rng.random(len(SEEDS)))
    sent = list(100.0 + rng.integers(0, 20, len(SEEDS)))
    shipped = tmp_path / "shipped.json"
    shipped.write_text('{"point": 2}')
    (tmp_path / "a.json").write_text('{"point": 1}')
    reference = _record(
        tmp_path / "reference",
        {
            str(tmp_path / "a.json"): (cost, [2 * s for s in sent]),
            str(tmp_path / "b.json"): (cost, sent),  # the copy's bytes: shipped.json's
        },
    )
    (tmp_path / "b.json").write_text('{"point": 2}')
    candidate = _record(
        tmp_path / "candidate",
        {
            "seed0.json": (cost, [0.8 * s for s in sent]),
            "seed1.json": ([c * 1.001 for c in cost], [0.7 * s for s in sent]),
            "seed2.json": (cost, [0.75 * s for s in sent]),
        },
    )
    return candidate, reference, shipped


def test_ratios_are_per_scenario_and_per_seed(records) -> None:
    candidate, reference, shipped = records
    _, ours = versus.load_record(candidate, "CANDIDATE")
    _, theirs = versus.load_record(reference / "results.json", "REFERENCE")
    index = versus.reference_index(theirs, str(shipped))  # matched by its bytes
    assert index == 1
    judged = versus.compare_records(ours, theirs, index)["test"]
    sent = judged["transmission ratio"]
    np.testing.assert_allclose(sent["per_run"], [0.8, 0.7, 0.75])
    assert sent["iqm_ci95"][1] < 1.0
    assert judged["cost ratio"]["range"] == pytest.approx([1.0, 1.001])
    # fewer transmissions at the 95 % bound, the cost's interval reaching 1: better, a win
    assert judged["verdict"]["outcome"] == "better" and judged["wins"]
    # against the other model (twice the transmissions) the candidate beats it by far more
    far = versus.compare_records(ours, theirs, 0)["test"]["transmission ratio"]
    np.testing.assert_allclose(far["per_run"], [0.4, 0.35, 0.375])


def test_a_failed_episode_loses_whatever_the_ratios(records) -> None:
    candidate, reference, _ = records
    record = json.loads((candidate / "results.json").read_text())
    record["sets"]["test"]["models"][2]["learned"]["episodes"][0]["failure"] = "left the cavity"
    _, theirs = versus.load_record(reference, "REFERENCE")
    judged = versus.compare_records(record, theirs, 1)["test"]
    assert judged["verdict"]["outcome"] == "loses" and not judged["wins"]


def test_the_command_prints_and_writes(records, tmp_path: Path, capsys) -> None:
    candidate, reference, shipped = records
    out = tmp_path / "versus.json"
    assert (
        versus.main(
            [str(candidate), str(reference), "--reference-model", str(shipped), "--json", str(out)]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "transmissions ×0.75" in printed and "**wins**" in printed
    written = json.loads(out.read_text())
    assert written["reference_model"].endswith("b.json") and written["sets"]["test"]["wins"]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"reference_model": None}, "--reference-model is needed: the reference judged 2 models"),
        ({"reference_model": "nowhere.json"}, "--reference-model: cannot read 'nowhere.json'"),
        ({"env": "etsc/AttitudeTracking-v0"}, "the records judge different ids"),
        ({"seeds": True}, "the records ran different scenarios on the test set"),
        ({"candidate": "missing"}, "CANDIDATE: no readable results.json"),
    ],
)
def test_bad_input_gets_one_line(records, tmp_path: Path, capsys, change, message) -> None:
    candidate, reference, shipped = records
    if "env" in change or "seeds" in change:
        record = json.loads((candidate / "results.json").read_text())
        record["env"] = change.get("env", record["env"])
        if "seeds" in change:
            record["sets"]["test"]["models"][0]["learned"]["episodes"][3]["seed"] = 7
        (candidate / "results.json").write_text(json.dumps(record))
    argv = [str(tmp_path / change.get("candidate", "candidate")), str(reference)]
    model = change.get("reference_model", str(shipped))
    if model is not None:
        argv += ["--reference-model", model]
    with pytest.raises(SystemExit) as stop:
        versus.main(argv)
    assert stop.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert message in error


def test_a_model_of_neither_path_nor_bytes_is_refused(records, tmp_path: Path) -> None:
    _, reference, _ = records
    other = tmp_path / "other.json"
    other.write_text('{"point": 3}')
    _, theirs = versus.load_record(reference, "REFERENCE")
    with pytest.raises(ValueError, match="none of the reference's models"):
        versus.reference_index(theirs, str(other))


def test_a_json_model_is_known_by_its_data_whatever_its_layout(records, tmp_path: Path) -> None:
    """A shipped trigger is written indented and a record's copy compact: the same model."""
    _, reference, _ = records
    indented = tmp_path / "indented.json"
    indented.write_text(json.dumps({"point": 2}, indent=2))
    _, theirs = versus.load_record(reference, "REFERENCE")
    assert versus.reference_index(theirs, str(indented)) == 1

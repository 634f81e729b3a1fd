"""``python -m agents.judge.learning_curves``: when a run first matches the paper trigger."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from agents.judge.learning_curves import learning_curves, main, parse_runs, search_validations

PAPER = {"mean_cost": 1.0, "transmissions": 100.0, "failures": 0}


def _run(folder: Path, points: list[tuple[float, float, int]], instants_per_step: int) -> Path:
    """A run folder whose evaluations have the (cost, transmissions, failures) ``points``."""
    folder.mkdir(parents=True)
    evaluations = [
        {
            "timesteps": 10 * (index + 1),
            "env_steps": 10 * (index + 1) * instants_per_step,
            "wall_time_s": 2.0 * (index + 1),
            "learned": {"mean_cost": cost, "transmissions": sent, "failures": failures},
            "paper": PAPER,
        }
        for index, (cost, sent, failures) in enumerate(points)
    ]
    (folder / "evaluations.json").write_text(json.dumps(evaluations), encoding="utf-8")
    return folder


def test_a_run_reaches_the_paper_trigger_when_as_accurate_on_no_more_transmissions(
    tmp_path: Path,
) -> None:
    always = _run(tmp_path / "always", [(0.5, 1000.0, 0), (0.9, 400.0, 0)], 1)
    # too costly, then a failure, then within 5 % on fewer transmissions
    late = _run(tmp_path / "late", [(1.2, 50.0, 0), (1.0, 60.0, 1), (1.04, 70.0, 0)], 100)
    result = learning_curves(
        parse_runs([f"instant={always}", f"decisions={late}"]), cost_tolerance=1.05
    )
    instant, decisions = result["methods"]["instant"], result["methods"]["decisions"]
    assert instant["reached"] == "0/1" and instant["env_steps_to_reach"]["median"] is None
    assert decisions["reached"] == "1/1"
    assert decisions["runs"][0]["reached_at_env_steps"] == 3000
    assert decisions["wall_time_s_to_reach"] == {"median": 6.0, "range": [6.0, 6.0]}


def test_an_untrained_network_does_not_reach_the_paper_trigger(tmp_path: Path) -> None:
    """A validation of a network no gradient step had touched is drawn on the curve, but a run
    reaches the paper trigger only with a trained policy."""
    folder = _run(tmp_path / "dqn", [(1.0, 50.0, 0), (1.2, 80.0, 0), (1.0, 90.0, 0)], 1)
    evaluations = json.loads((folder / "evaluations.json").read_text(encoding="utf-8"))
    evaluations[0]["trained"] = False
    (folder / "evaluations.json").write_text(json.dumps(evaluations), encoding="utf-8")
    (run,) = learning_curves(parse_runs([f"dqn={folder}"]), 1.05)["methods"]["dqn"]["runs"]
    assert [point["trained"] for point in run["points"]] == [False, True, True]
    assert run["reached_at_env_steps"] == 30


def test_seeds_of_a_method_are_summarised_together(tmp_path: Path) -> None:
    runs = [
        _run(tmp_path / f"seed{seed}", [(2.0, 50.0, 0)] * seed + [(1.0, 50.0, 0)], 1)
        for seed in range(3)
    ]
    out = tmp_path / "out"
    argv = [arg for run in runs for arg in ("--run", f"ppo={run}")]
    assert main([*argv, "--out", str(out)]) == 0
    result = json.loads((out / "learning_curves.json").read_text(encoding="utf-8"))
    assert result["methods"]["ppo"]["env_steps_to_reach"] == {"median": 20.0, "range": [10, 30]}
    assert (out / "learning_curves.png").stat().st_size > 0


def test_the_interval_over_seeds_is_the_geometric_mean_of_the_runs(tmp_path: Path) -> None:
    """Two runs whose cost ratios are 2 and 8 at every evaluation: the band's mean is their
    geometric mean, 4, at every abscissa of their common range, its interval inside [2, 8];
    one run alone has no band."""
    runs = [_run(tmp_path / f"seed{cost:g}", [(cost, 50.0, 0)] * 4, 1) for cost in (2.0, 8.0)]
    result = learning_curves(parse_runs([f"ppo={run}" for run in runs]), cost_tolerance=1.05)
    band = result["methods"]["ppo"]["bands"]["env_steps"]
    assert band["x"][0] == 10 and band["x"][-1] == 40
    assert band["cost_ratio"]["geometric_mean"] == pytest.approx([4.0] * len(band["x"]))
    assert all(2.0 - 1e-9 <= low <= high <= 8.0 + 1e-9 for low, high in band["cost_ratio"]["ci95"])
    assert band["transmission_ratio"]["geometric_mean"] == pytest.approx([0.5] * len(band["x"]))
    alone = learning_curves(parse_runs([f"ppo={runs[0]}"]), cost_tolerance=1.05)
    assert alone["methods"]["ppo"]["bands"] is None
    free = _run(tmp_path / "cost0", [(0.0, 50.0, 0)] * 4, 1)  # 003 keeps its shell at cost 0
    result = learning_curves(parse_runs([f"ppo={runs[0]}", f"ppo={free}"]), cost_tolerance=1.05)
    band = result["methods"]["ppo"]["bands"]["env_steps"]
    assert band["cost_ratio"] is None  # 0 has no logarithm
    assert band["transmission_ratio"]["geometric_mean"] == pytest.approx([0.5] * len(band["x"]))


@pytest.mark.parametrize("spec", ["no-separator", "=folder", "label="])
def test_a_malformed_run_names_the_option(spec: str, capsys) -> None:
    with pytest.raises(SystemExit):
        main(["--run", spec])
    assert "--run" in capsys.readouterr().err


def test_a_run_without_instants_is_refused(tmp_path: Path, capsys) -> None:
    folder = _run(tmp_path / "old", [(1.0, 50.0, 0)], 1)
    entries = json.loads((folder / "evaluations.json").read_text(encoding="utf-8"))
    del entries[0]["env_steps"]
    (folder / "evaluations.json").write_text(json.dumps(entries), encoding="utf-8")
    with pytest.raises(SystemExit):
        main(["--run", f"old={folder}", "--out", str(tmp_path / "out")])
    assert "env_steps" in capsys.readouterr().err


def test_a_search_is_a_run_against_the_paper_trigger_on_its_validation_scenarios(
    tmp_path: Path,
) -> None:
    """An agents.search folder's validated means are read against the paper trigger, which
    is run on the search's own validation scenarios; earlier results join with --include."""
    from baselines.evaluate import evaluate

    folder = tmp_path / "search"
    folder.mkdir()
    (folder / "config.yaml").write_text(
        "env_id: etsc/InnerFormation-v0\npenalty: 5.0\nsearch: [factors]\ngenerations: 2\n"
        "population: 2\nscenarios: 1\nvalidation_size: 2\n"
    )
    paper = evaluate(
        "etsc/InnerFormation-v0",
        "paper",
        env_args={"transmission_penalty": 5.0},
        scenarios="validation",
        set_size=2,
    )["mean"]
    records = [
        {"generation": 0, "env_steps": 100, "wall_s": 1.0, "returns": [0.0]},
        {
            "generation": 1,
            "env_steps": 200,
            "wall_s": 2.0,
            "returns": [0.0],
            "validation": {
                "mean_cost": paper["mean_cost"] * 1.01,
                "transmissions": paper["transmissions"] * 0.5,
                "failures": 0,
            },
        },
    ]
    (folder / "generations.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    earlier = learning_curves(
        parse_runs([f"ppo={_run(tmp_path / 'ppo', [(2.0, 50, 0)], 1)}"]), 1.05
    )
    result = learning_curves(parse_runs([f"es={folder}"]), 1.05, [earlier])
    assert set(result["methods"]) == {"ppo", "es"}
    (run,) = result["methods"]["es"]["runs"]
    assert run["reached_at_env_steps"] == 200
    assert run["points"][0]["cost_ratio"] == pytest.approx(1.01)
    assert result["methods"]["ppo"]["reached"] == "0/1"

    # a committed record keeps the search's curve.json, not its generations
    (folder / "generations.jsonl").unlink()
    validation = records[1]["validation"]
    entry = {
        "generation": 1,
        "env_steps": 200,
        "wall_s": 2.0,
        "validation_cost": validation["mean_cost"],
        "validation_transmissions": validation["transmissions"],
    }
    for failures in (2, None):  # None: a curve older than its failures key
        kept = entry if failures is None else {**entry, "validation_failures": failures}
        (folder / "curve.json").write_text(json.dumps({"search": {}, "curve": [kept]}))
        (read,) = search_validations(folder)
        assert read == {
            "env_steps": 200,
            "wall_s": 2.0,
            "mean_cost": validation["mean_cost"],
            "transmissions": validation["transmissions"],
            "failures": failures,
        }
    (run,) = learning_curves(parse_runs([f"es={folder}"]), 1.05)["methods"]["es"]["runs"]
    assert run["reached_at_env_steps"] == 200 and run["points"][0]["failures"] is None


def test_an_out_folder_holding_other_runs_is_refused(tmp_path: Path, capsys) -> None:
    """The same runs are drawn again in place (also as an included result with a new run
    of the same label, whose summary is recomputed); other runs need their own --out."""
    first = _run(tmp_path / "first", [(1.2, 50.0, 0)], 1)
    second = _run(tmp_path / "second", [(1.0, 50.0, 0)], 1)
    out = tmp_path / "out"
    assert main(["--run", f"ppo={first}", "--out", str(out)]) == 0
    assert main(["--run", f"ppo={first}", "--out", str(out)]) == 0
    with pytest.raises(SystemExit):
        main(["--run", f"ppo={second}", "--out", str(out)])
    assert f"--out {out} holds the learning curves of 1 other runs (ppo)" in capsys.readouterr().err
    grown = tmp_path / "grown"
    included = ["--include", str(out / "learning_curves.json")]
    assert main([*included, "--run", f"ppo={second}", "--out", str(grown)]) == 0
    result = json.loads((grown / "learning_curves.json").read_text(encoding="utf-8"))
    assert result["methods"]["ppo"]["reached"] == "1/2"


@pytest.mark.parametrize(
    ("content", "says"),
    [
        (None, "not a readable JSON file"),
        ("{", "not JSON"),
        ("[1]", "not a learning_curves.json"),
    ],
)
def test_an_unreadable_include_is_refused_in_one_line(
    tmp_path: Path, capsys, content: str | None, says: str
) -> None:
    earlier = tmp_path / "learning_curves.json"
    if content is not None:
        earlier.write_text(content, encoding="utf-8")
    with pytest.raises(SystemExit):
        main(["--include", str(earlier), "--out", str(tmp_path / "out")])
    (line,) = [text for text in capsys.readouterr().err.splitlines() if "error:" in text]
    assert f"--include {earlier}: {says}" in line


def test_searches_of_one_configuration_share_one_paper_evaluation(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The paper trigger is evaluated once per configuration, not once per search folder."""
    import baselines.evaluate
    from agents.judge.learning_curves import paper_validation

    calls = []

    def counted(env_id: str, policy: str, **kwargs: object) -> dict:
        calls.append((env_id, policy, kwargs))
        return {
            "mean": {"mean_cost": 1.0, "transmissions": 10.0},
            "aggregates": {"failure": {"count": 0}},
        }

    monkeypatch.setattr(baselines.evaluate, "evaluate", counted)
    paper_validation.cache_clear()
    curve = {
        "generation": 1,
        "env_steps": 200,
        "wall_s": 2.0,
        "validation_cost": 0.5,
        "validation_transmissions": 5.0,
        "validation_failures": 0,
    }
    specs = []
    for name, validation_size in (("a", 2), ("b", 2), ("c", 3)):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "config.yaml").write_text(
            "env_id: etsc/InnerFormation-v0\npenalty: 5.0\nsearch: [factors]\ngenerations: 2\n"
            f"population: 2\nscenarios: 1\nvalidation_size: {validation_size}\n"
        )
        (folder / "curve.json").write_text(json.dumps({"search": {}, "curve": [curve]}))
        specs.append(f"es={folder}")
    runs = learning_curves(parse_runs(specs), 1.05)["methods"]["es"]["runs"]
    paper_validation.cache_clear()
    assert [run["points"][0]["cost_ratio"] for run in runs] == [0.5, 0.5, 0.5]
    assert [kwargs["set_size"] for _, _, kwargs in calls] == [2, 3]


def test_training_counts_the_sampling_instants_each_step_simulates(tmp_path: Path) -> None:
    """The curves' abscissa: a per-instant step of 003's env with ``decision_interval`` 4 runs
    4 sampling instants, a self-triggered decision the ``elapsed_steps`` it reports."""
    pytest.importorskip("stable_baselines3")
    from agents.train.validation_callback import PaperComparisonCallback

    callback = PaperComparisonCallback(
        "etsc/AsteroidOrbitKeeping-v0",
        {"decision_interval": 4},
        every=10**9,
        out_path=tmp_path / "evaluations.json",
        set_size=1,
    )
    callback.locals = {"infos": [{}, {}, {"elapsed_steps": 3}]}
    callback._on_step()
    assert callback.env_steps == 4 + 4 + 3


_SEARCH_CONFIG = (
    "env_id: etsc/InnerFormation-v0\npenalty: 5.0\nsearch: [factors]\ngenerations: 2\n"
    "population: 2\nscenarios: 1\nvalidation_size: 2\n"
)


@pytest.mark.parametrize(
    ("files", "says"),
    [
        ({"evaluations.json": '[{"timesteps": 1'}, "evaluations.json: not JSON"),
        ({"evaluations.json": '{"a": 1}'}, "evaluations.json: not a record of agents.train"),
        ({"evaluations.json": '[{"timesteps": 1, "env_steps": 2}]'}, "KeyError('learned')"),
        ({"evaluations.json": "[]"}, "no validation recorded yet"),
        ({"curve.json": "[1]", "config.yaml": _SEARCH_CONFIG}, "curve.json: not a record"),
        ({"generations.jsonl": '{"env_steps": 1, "validation": {}}\n'}, "KeyError('wall_s')"),
        ({"generations.jsonl": "{\n{}\n"}, "generations.jsonl: line 1: not JSON"),
        ({"curve.json": "{}", "config.yaml": "x: ["}, "config.yaml: not a readable YAML file"),
        ({"curve.json": "{}", "config.yaml": "x: 1"}, "config.yaml: config key 'search'"),
    ],
)
def test_a_damaged_run_record_is_refused_in_one_line_naming_the_run(
    tmp_path: Path, capsys, files: dict[str, str], says: str
) -> None:
    """Whatever is wrong inside a run's folder, the error is one line that starts with the
    --run it came from and names the file."""
    folder = tmp_path / "run"
    folder.mkdir()
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    if "generations.jsonl" in files:
        (folder / "config.yaml").write_text(_SEARCH_CONFIG, encoding="utf-8")
    with pytest.raises(SystemExit):
        main(["--run", f"es={folder}", "--out", str(tmp_path / "out")])
    (line,) = [text for text in capsys.readouterr().err.splitlines() if "error:" in text]
    assert f"--run es={folder}: " in line and says in line


def test_a_search_being_written_is_read_up_to_its_last_whole_generation(tmp_path: Path) -> None:
    """A torn last line of generations.jsonl (the search is writing it) is left out."""
    folder = tmp_path / "search"
    folder.mkdir()
    validation = {"mean_cost": 1.0, "transmissions": 10.0, "failures": 0}
    whole = {"generation": 0, "env_steps": 100, "wall_s": 1.0, "validation": validation}
    (folder / "generations.jsonl").write_text(json.dumps(whole) + '\n{"generation": 1, "env')
    assert search_validations(folder) == [{"env_steps": 100, "wall_s": 1.0, **validation}]

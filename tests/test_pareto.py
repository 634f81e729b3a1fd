"""``python -m agents.judge.pareto``: the three curves, their JSON and their plot."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from agents.judge.pareto import main, non_dominated
from etsc_envs.papers import PAPER_IDS, paper_of
from etsc_envs.triggers.attitude_tracking import PAPER_PSI


def test_pareto_writes_the_curves_with_intervals_and_the_paper_scenario(tmp_path: Path) -> None:
    out_dir = tmp_path / "pareto"
    argv = ["etsc/AttitudeTracking-v0", "--env-arg", "horizon_s=0.3", "--set-size", "3"]
    assert main([*argv, "--out", str(out_dir)]) == 0
    result = json.loads((out_dir / "pareto.json").read_text(encoding="utf-8"))
    assert (out_dir / "pareto.png").stat().st_size > 0
    assert (result["scenarios"], result["set_size"]) == ("test", 3)
    curves = result["curves"]
    assert len(curves["paper"]) == len(paper_of("etsc/AttitudeTracking-v0").rule.sweep())
    assert any(point["args"] == {"psi": PAPER_PSI} for point in curves["paper"])
    periods = [point["args"]["every"] for point in curves["periodic"]]
    assert periods == list(paper_of("etsc/AttitudeTracking-v0").periodic_every)
    assert curves["learned"] == []
    steps = 300
    for point in curves["periodic"]:
        expected = -(-steps // point["args"]["every"])  # at k = 0, K, 2K..
        assert point["transmissions"]["mean"] == expected
        assert point["transmissions"]["mean_ci95"] == [expected, expected]
        assert point["paper_scenario"]["transmissions"] == expected
    for point in curves["paper"]:
        low, high = point["mean_cost"]["mean_ci95"]
        assert low <= point["mean_cost"]["mean"] <= high
    paper_counts = [point["transmissions"]["mean"] for point in curves["paper"]]
    assert paper_counts == sorted(paper_counts, reverse=True), "a higher Ψ transmits less"


def test_an_id_with_an_error_time_rule_gets_its_curve_and_reuse_keeps_it(tmp_path: Path) -> None:
    argv = ["etsc/InnerFormation-v0", "--env-arg", "horizon_s=1.0", "--set-size", "2"]
    first = tmp_path / "first"
    assert main([*argv, "--out", str(first)]) == 0
    result = json.loads((first / "pareto.json").read_text(encoding="utf-8"))
    curve = result["curves"]["error_time"]
    expected = paper_of("etsc/InnerFormation-v0").rules["error_time"].sweep()
    assert [point["args"] for point in curve] == expected
    counts = [point["transmissions"]["mean"] for point in curve]
    assert counts == sorted(counts, reverse=True) and counts[0] > counts[-1], "a larger A waits"
    second = tmp_path / "second"
    assert main([*argv, "--out", str(second), "--reuse", str(first / "pareto.json")]) == 0
    again = json.loads((second / "pareto.json").read_text(encoding="utf-8"))
    assert again["curves"]["error_time"] == curve


def test_the_front_keeps_only_non_dominated_points() -> None:
    points = [(10, 1.0), (20, 0.5), (15, 2.0), (40, 0.6), (40, 0.4), (5, 3.0)]
    front = non_dominated(
        [{"sent": sent, "cost": cost} for sent, cost in points],
        lambda p: p["cost"],
        lambda p: p["sent"],
    )
    assert [(p["sent"], p["cost"]) for p in front] == [(5, 3.0), (10, 1.0), (20, 0.5), (40, 0.4)]


@pytest.mark.parametrize("env_id", PAPER_IDS)
def test_every_sweep_is_accepted_by_its_paper_trigger(env_id: str) -> None:
    from etsc_envs.evaluation.policy_specs import episode_setup

    setup = episode_setup(env_id, {})
    for args in paper_of(env_id).rule.sweep():
        setup.make_policy("paper", args)
    setup.env.close()


def test_reuse_keeps_the_earlier_curves_and_checks_they_match(tmp_path: Path) -> None:
    first = tmp_path / "first"
    argv = ["etsc/AttitudeTracking-v0", "--env-arg", "horizon_s=0.05", "--set-size", "2"]
    assert main([*argv, "--out", str(first)]) == 0
    earlier = json.loads((first / "pareto.json").read_text(encoding="utf-8"))
    second = tmp_path / "second"
    assert main([*argv, "--out", str(second), "--reuse", str(first / "pareto.json")]) == 0
    again = json.loads((second / "pareto.json").read_text(encoding="utf-8"))
    assert again["curves"] == earlier["curves"]
    with pytest.raises(SystemExit):
        main(["etsc/AttitudeTracking-v0", "--reuse", str(first / "pareto.json")])


def test_the_pettingzoo_cluster_shares_its_central_forms_baseline_points(tmp_path: Path) -> None:
    argv = ["--env-arg", "horizon_s=0.05", "--set-size", "2"]
    central, shared = tmp_path / "central", tmp_path / "shared"
    assert main(["etsc/ClusterContainmentCentral-v0", *argv, "--out", str(central)]) == 0
    assert main(["etsc/ClusterContainment-v0", *argv, "--out", str(shared)]) == 0
    reused = tmp_path / "reused"
    reuse = ["--reuse", str(central / "pareto.json")]
    assert main(["etsc/ClusterContainment-v0", *argv, "--out", str(reused), *reuse]) == 0
    curves = [
        json.loads((folder / "pareto.json").read_text(encoding="utf-8"))["curves"]
        for folder in (central, shared, reused)
    ]
    for name in ("paper", "periodic"):
        assert curves[0][name] == curves[1][name] == curves[2][name]
    with pytest.raises(SystemExit):
        main(["etsc/AttitudeTracking-v0", *argv, *reuse])


def test_costs_within_one_decade_still_get_labelled_ticks() -> None:
    import matplotlib.pyplot as plt

    from agents.judge.pareto import _log_axes

    figure, axes = plt.subplots()
    axes.plot([10, 100, 1000], [3.1, 3.4, 4.2])
    _log_axes(axes, [3.1, 3.4, 4.2])
    figure.canvas.draw()
    labels = [tick.get_text() for tick in axes.get_yticklabels(minor=True) if tick.get_text()]
    plt.close(figure)
    assert labels, "a cost axis inside one decade needs labelled minor ticks"


def test_judged_models_are_read_from_their_judgement_as_a_run_gives_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A model judged by agents.judge.results gives, through ``--judged``, the point that running
    it gives (set aggregates and paper-scenario episode), under its folder's method; a
    judgement of another set size is refused naming ``--judged``."""
    from agents.judge.results import main as judge

    model = str(Path(__file__).resolve().parents[1] / "models" / "AttitudeTracking-v0_ppo.zip")
    argv = ["etsc/AttitudeTracking-v0", "--env-arg", "horizon_s=0.3", "--set-size", "3"]
    judged = tmp_path / "front" / "transmission_penalty=1"
    assert judge([*argv, "--model", model, "--out", str(judged)]) == 0
    run, read = tmp_path / "run", tmp_path / "read"
    assert main([*argv, "--model", model, "--out", str(run)]) == 0
    reuse = ["--reuse", str(run / "pareto.json")]
    assert main([*argv, "--judged", str(tmp_path / "front"), "--out", str(read), *reuse]) == 0
    ran = json.loads((run / "pareto.json").read_text(encoding="utf-8"))["curves"]["learned"]
    got = json.loads((read / "pareto.json").read_text(encoding="utf-8"))["curves"]["learned"]
    assert [point["method"] for point in got] == ["front"]
    for key in ("policy", "mean_cost", "transmissions", "failures", "paper_scenario"):
        assert got[0][key] == ran[0][key], key
    assert (read / "pareto.png").stat().st_size > 0
    other_size = [*argv[:-1], "2", "--judged", str(tmp_path / "front")]
    with pytest.raises(SystemExit) as refused:
        main([*other_size, "--out", str(tmp_path / "refused")])
    assert refused.value.code == 2
    assert "--judged:" in capsys.readouterr().err

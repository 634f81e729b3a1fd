"""The benchmark as a library call (``etsc_envs.evaluate``, ``etsc-envs``) and the one verdict.

* ``etsc_envs.evaluate`` gives ``python -m baselines.evaluate``'s records, record for record,
  and a callable trigger the records of the same trigger answering through ``predict``;
* the comparison with the paper's rule and every verdict come from
  :func:`etsc_envs.evaluation.verdict.compare`, failures first;
* bad inputs are refused with one line naming the argument and what it allows;
* ``etsc_envs.leaderboard`` holds the numbers of ``docs/leaderboard.md``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import etsc_envs
from agents.judge.leaderboard import _with_interval
from baselines.evaluate import main as baselines_main
from etsc_envs.cli import main as etsc_envs_main
from etsc_envs.evaluation.leaderboard import leaderboard_ids
from etsc_envs.evaluation.verdict import Axis, compare
from etsc_envs.protocol import TEST_SEEDS

ENV_ID = "etsc/AttitudeTracking-v0"
SHORT = {"horizon_s": 0.05}
"""50 instants of paper 002: enough for a clock and the rule to differ."""


def without_wall_time(records: list[dict]) -> list[dict]:
    return [{k: v for k, v in record.items() if k != "wall_time_s"} for record in records]


def every_4(observation: np.ndarray) -> int:
    """A clock read from the observation: transmit once 4 instants passed since the last."""
    return int(observation[-1] >= 0.004 - 1e-9)


class Every4:
    """:func:`every_4` answering like SB3 (a batch of observations)."""

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        observations = np.atleast_2d(observation)
        actions = (observations[:, -1] >= 0.004 - 1e-9).astype(np.int64)
        return (actions if np.ndim(observation) == 2 else actions[0]), state


def test_the_library_gives_the_commands_records(tmp_path: Path) -> None:
    output = tmp_path / "periodic.json"
    argv = [ENV_ID, "--policy", "periodic", "--policy-arg", "every=4", "--env-arg=horizon_s=0.05"]
    assert (
        baselines_main([*argv, "--scenarios", "test", "--set-size", "3", "--json", str(output)])
        == 0
    )
    command = json.loads(output.read_text(encoding="utf-8"))
    library = etsc_envs.evaluate(
        "periodic", ENV_ID, "test", size=3, policy_args={"every": 4}, env_args=SHORT, progress=False
    )
    assert without_wall_time(library.records) == without_wall_time(command["episodes"])
    assert [r["seed"] for r in library.records] == list(TEST_SEEDS[:3])
    assert library.comparison is not None and command["comparison"] is not None
    assert library.comparison["verdict"] == command["comparison"]["verdict"]
    # a clock every 4 instants sends about a quarter of the rule's... or more: the physics
    # decides, and the ratio's interval says which; here it is computed, not assumed
    ratio = library.comparison["transmissions"]
    assert ratio["iqm_ci95"][0] <= ratio["iqm"] <= ratio["iqm_ci95"][1]
    assert library.to_json()["cost"] == library.cost and "eq. (50)" in library.cost


def test_a_callable_and_predict_give_the_same_records() -> None:
    options = {"size": 3, "env_args": SHORT, "progress": False, "reference": None}
    as_callable = etsc_envs.evaluate(every_4, ENV_ID, **options)
    as_predict = etsc_envs.evaluate(Every4(), ENV_ID, **options)
    records = without_wall_time(as_callable.records)
    assert records == without_wall_time(as_predict.records)
    # the first measurement is sent at reset; then instants 4, 8, ..., 48
    assert all(record["transmissions"] == 12 for record in records)
    one_by_one = etsc_envs.evaluate(every_4, ENV_ID, on_episode=lambda *_: None, **options)
    assert without_wall_time(one_by_one.records) == records


def test_a_per_agent_callable_serves_every_agent_of_the_pettingzoo_id() -> None:
    options = {"size": 2, "env_args": {"horizon_s": 0.2}, "progress": False}
    always = etsc_envs.evaluate(lambda observation: 1, "etsc/ClusterContainment-v0", **options)
    records = always.records
    assert all(record["transmission_rate"] == 1.0 for record in records)
    assert set(records[0]["agents"]) and always.comparison is not None
    verdict = always.comparison["verdict"]
    assert verdict["axes"]["transmissions"] == "loses"  # every instant, every agent


@pytest.mark.parametrize(
    ("call", "expected"),
    [
        (lambda: etsc_envs.evaluate("paper", "etsc/NoSuch-v0"), r"^env_id: 'etsc/NoSuch-v0' is"),
        (lambda: etsc_envs.evaluate(3, ENV_ID), r"^policy must be .* neither predict nor"),
        (lambda: etsc_envs.evaluate("paper", ENV_ID, "tset"), r"^scenarios must be one of"),
        (lambda: etsc_envs.evaluate("paper", ENV_ID, size=0), r"^size: .* 1\.\.1000000, got 0"),
        (lambda: etsc_envs.evaluate("pape", ENV_ID), r"^policy must be one of paper"),
        (
            lambda: etsc_envs.evaluate(
                lambda observation: 2, ENV_ID, size=1, env_args=SHORT, progress=False
            ),
            r"^policy: answered 2 for 1 observation\(s\) of etsc/AttitudeTracking-v0, whose "
            r"actions are Discrete\(2\) \(0 hold, 1 transmit",
        ),
    ],
)
def test_bad_inputs_get_one_line_naming_the_argument(call, expected) -> None:
    with pytest.raises(ValueError) as error:
        call()
    message = str(error.value)
    assert "\n" not in message and re.search(expected, message), message


@pytest.mark.parametrize("destination", ["/dev/full", "folder", "file/below", "loop"])
def test_an_unwritable_json_is_one_line(tmp_path: Path, capsys, destination: str) -> None:
    (tmp_path / "folder").mkdir()
    (tmp_path / "file").write_text("x")
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    path = destination if destination.startswith("/") else str(tmp_path / destination)
    argv = ["evaluate", ENV_ID, "--policy", "always", "--env-arg=horizon_s=0.01"]
    with pytest.raises(SystemExit) as exit_info:
        etsc_envs_main([*argv, "--scenarios", "paper", "--json", path])
    assert exit_info.value.code in (1, 2)
    err = capsys.readouterr().err.strip().splitlines()
    assert "Traceback" not in "\n".join(err) and "--json" in err[-1], err


def test_ctrl_c_before_any_episode_keeps_an_existing_json(tmp_path: Path, capsys, monkeypatch):
    import etsc_envs.evaluation.run as run

    output = tmp_path / "good.json"
    output.write_text('{"complete": true}\n')

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(run, "run_batch", interrupted)
    argv = ["evaluate", ENV_ID, "--policy", "always", "--env-arg=horizon_s=0.01", "--json"]
    assert etsc_envs_main([*argv, str(output), "--scenarios", "paper"]) == 130
    assert output.read_text() == '{"complete": true}\n'
    assert "0 of 1 episode(s) finished" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("failures", "axes", "outcome"),
    [
        ((1, 1), {"cost": Axis((0.1, 0.2))}, "both fail"),  # a lower cost, cut short: no win
        ((1, 0), {"cost": Axis((0.1, 0.2))}, "loses"),
        ((0, 2), {"cost": Axis((3.0, 4.0))}, "beats"),
        ((0, 0), {"cost": Axis((0.1, 0.2)), "transmissions": Axis((0.9, 1.1))}, "better"),
        ((0, 0), {"cost": Axis((0.1, 0.2)), "transmissions": Axis((1.1, 1.2))}, "trade-off"),
        ((0, 0), {"cost": Axis((1.0, 1.0))}, "ties"),  # the same records
        ((0, 0), {"cost": Axis(None)}, "ties"),  # both 0 everywhere: no ratio either way
        ((0, 0), {"cost": Axis((0.5, 0.9), worse_where_reference_zero=1)}, "loses"),
        ((0, 0), {"cost": Axis((-2.0, -1.0), limit=0.0)}, "beats"),  # unpaired intervals
    ],
)
def test_the_verdict_counts_failures_first(failures, axes, outcome) -> None:
    verdict = compare(*failures, axes)
    assert verdict.outcome == outcome
    assert verdict.met is (outcome == "beats")


def test_a_zero_cost_reference_is_beaten_by_no_positive_cost() -> None:
    from etsc_envs.evaluation.statistics import paired_ratio
    from etsc_envs.evaluation.verdict import ratio_axis

    zero = np.zeros(4)
    assert compare(0, 0, {"cost": ratio_axis(paired_ratio(zero, zero))}).outcome == "ties"
    worse = paired_ratio(np.array([0.0, 0.1, 0.0, 0.0]), zero)
    assert compare(0, 0, {"cost": ratio_axis(worse)}).outcome == "loses"


def test_the_leaderboard_data_holds_the_pages_numbers() -> None:
    page = Path("docs/leaderboard.md").read_text(encoding="utf-8")
    for env_id in leaderboard_ids():
        section = page.split(f"## `{env_id}`")[1].split("\n## ")[0]
        cells = {
            line.split(" | ")[0].removeprefix("| "): line.split(" | ")
            for line in section.splitlines()
            if line.startswith("| ") and not line.startswith("| trigger")
        }
        rows = etsc_envs.leaderboard(env_id)
        assert [row.trigger for row in rows] == list(cells)
        for row in rows:
            if row.test is None:
                continue
            cost = {"mean": row.test.cost, "mean_ci95": list(row.test.cost_ci95)}
            sent = {"mean": row.test.transmissions, "mean_ci95": list(row.test.transmissions_ci95)}
            line = cells[row.trigger]
            assert line[2:5] == [
                _with_interval(cost),
                _with_interval(sent),
                f"{row.test.failures}/{row.test.episodes}",
            ]


def test_a_test_set_evaluation_stands_among_the_rows() -> None:
    evaluation = etsc_envs.evaluate(
        "always", ENV_ID, size=2, env_args=SHORT, progress=False, reference=None
    )
    standing = evaluation.standing()
    assert standing[0]["trigger"] == "always"
    assert all(
        entry["outcome"] in ("beats", "better", "ties", "trade-off", "loses") for entry in standing
    )
    with pytest.raises(ValueError, match=r"^standing: the leaderboard is on the test set"):
        etsc_envs.evaluate("always", ENV_ID, "paper", env_args=SHORT, progress=False).standing()

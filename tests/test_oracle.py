"""The clairvoyant schedule (agents.oracle): schedules as data, their exact replay in the
compiled loop, the screen of a move, the search's guarantees, its command, its sweep and its
judgement."""

from __future__ import annotations

import itertools
import json
from typing import Any

import numpy as np
import pytest
import yaml

import etsc_envs
from agents.judge.oracle import judge, read_runs
from agents.judge.oracle import main as judge_main
from agents.oracle.__main__ import main as oracle_main
from agents.oracle.run import oracle_config_from_dict, run_oracle
from agents.oracle.schedule import Outcome, Schedule, ScheduleRun, trigger_schedule
from agents.oracle.search import clairvoyant
from agents.oracle.tuned import Bound, tune_on_scenario
from agents.sweep.config import sweep_config_from_dict
from agents.sweep.processes import run_sweep_in_processes
from etsc_envs.protocol import scenario_set
from etsc_envs.triggers.base import RuleTrigger
from etsc_envs.triggers.family import LearnedTrigger

ENV_ID = "etsc/AttitudeTracking-v0"
TRIGGER = "models/AttitudeTracking-v0_learned.json"
MULTI = "etsc/InnerFormation-v0"


@pytest.fixture(scope="module")
def run() -> ScheduleRun:
    return ScheduleRun(ENV_ID, scenario_set("test", 1), scenario_set("test", 1).seeds[0])


@pytest.fixture(scope="module")
def learned(run: ScheduleRun) -> Schedule:
    return trigger_schedule(run, LearnedTrigger.load(TRIGGER).policy_for(run.env))


# ------------------------------------------------------------------------- schedules
def test_a_schedule_drops_silent_instants_and_refuses_unsorted_ones() -> None:
    schedule = Schedule(np.array([0, 5, 9]), np.array([[1, 0], [0, 0], [1, 1]]))
    with pytest.raises(ValueError, match="masks must be"):
        Schedule(np.array([0, 5]), np.array([1, 0]))
    assert schedule.instants.tolist() == [0, 9]
    assert schedule.transmissions == 3
    with pytest.raises(ValueError, match="instants must be strictly increasing"):
        Schedule(np.array([4, 4]), np.ones((2, 1)))


def test_the_neighbouring_sends_of_a_channel() -> None:
    schedule = Schedule(np.array([0, 3, 7, 12]), np.array([[1, 0], [0, 1], [1, 0], [0, 1]]))
    assert schedule.next_send(0, 0) == 2
    assert schedule.next_send(2, 0) == 4  # none after: the count
    assert schedule.previous_send(3, 1) == 1
    assert schedule.previous_send(1, 1) == -1
    assert Schedule.clock(10, 2, 4).instants.tolist() == [0, 4, 8]


hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

pairs = st.lists(st.tuples(st.integers(0, 40), st.integers(0, 2)), max_size=12)


@settings(max_examples=60, deadline=None)
@given(sends=pairs, silenced=pairs, added=pairs)
def test_an_edit_silences_and_adds_exactly_the_pairs_named(
    sends: list[tuple[int, int]], silenced: list[tuple[int, int]], added: list[tuple[int, int]]
) -> None:
    base = Schedule(np.zeros(0, dtype=np.int64), np.zeros((0, 3))).edited([], sends)
    present = {
        (int(t), c)
        for t, row in zip(base.instants, base.masks, strict=True)
        for c in range(3)
        if row[c]
    }
    assert present == set(sends)
    kept = [pair for pair in silenced if pair in present]
    edited = base.edited(kept, added)
    after = {
        (int(t), c)
        for t, row in zip(edited.instants, edited.masks, strict=True)
        for c in range(3)
        if row[c]
    }
    assert after == (present - set(kept)) | set(added)
    assert edited.transmissions == len(after)
    assert np.all(np.diff(edited.instants) > 0) and np.all(edited.masks.any(axis=1))


# ------------------------------------------------------------------------- exact replay
def test_a_triggers_schedule_replays_its_episode_exactly(
    run: ScheduleRun, learned: Schedule
) -> None:
    """The learned trigger's schedule, replayed with run_interval, costs what the trigger's
    own evaluation records on the same test scenario."""
    evaluation = etsc_envs.evaluate(
        f"learned:{TRIGGER}", ENV_ID, "test", size=1, reference=None, progress=False
    )
    (episode,) = evaluation.records
    outcome = run.outcome(learned)
    assert not outcome.failed
    assert outcome.transmissions == episode["transmissions"]
    assert outcome.mean_cost == pytest.approx(episode["mean_cost"], rel=1e-12)
    assert outcome.cost / run.n_steps == pytest.approx(episode["mean_cost"], rel=1e-12)


def test_the_state_kept_before_each_send_resumes_the_episode(
    run: ScheduleRun, learned: Schedule
) -> None:
    outcome = run.outcome(learned)
    assert len(outcome.states) == len(learned.instants)
    middle = len(learned.instants) // 2
    # silencing nothing, screened to the horizon from the middle, changes nothing
    assert run.window_cost(outcome, learned, middle, len(learned.instants)) == pytest.approx(
        0.0, abs=1e-9 * outcome.cost
    )


def test_a_move_screened_to_the_horizon_is_its_exact_effect(
    run: ScheduleRun, learned: Schedule
) -> None:
    base = run.outcome(learned)
    index = len(learned.instants) // 3
    instant = int(learned.instants[index])
    changed = learned.edited([(instant, 0)], [(instant + 7, 0)])
    screened = run.window_cost(base, changed, index, len(learned.instants))
    exact = run.outcome(changed).cost - base.cost
    assert exact != 0.0
    assert screened == pytest.approx(exact, rel=1e-9, abs=1e-12)


def test_a_change_followed_by_the_trigger_is_run_exactly(
    run: ScheduleRun, learned: Schedule
) -> None:
    """Resumed at one of its own instants, the trigger sends its own schedule again; after a
    silenced instant its reaction is a schedule whose exact run costs what the rollout
    summed."""
    trigger = LearnedTrigger.load(TRIGGER).policy_for(run.env)
    base = run.outcome(learned)
    index = len(learned.instants) // 2
    same = run.continued(base, index, [], trigger)
    assert same is not None
    assert np.array_equal(same[0].instants, learned.instants)
    assert same[1] == pytest.approx(base.cost, rel=1e-12)
    following = int(learned.instants[index + 1])
    silenced = run.continued(base, index, [(following - 1, np.zeros(1, dtype=np.int64))], trigger)
    assert silenced is not None
    schedule, cost = silenced
    assert int(learned.instants[index]) not in schedule.instants.tolist()
    assert np.array_equal(schedule.instants[:index], learned.instants[:index])
    assert run.outcome(schedule).cost == pytest.approx(cost, rel=1e-12)


def test_a_multi_channel_schedule_replays_per_channel() -> None:
    run = ScheduleRun(MULTI, scenario_set("test", 1), scenario_set("test", 1).seeds[0])
    trigger = LearnedTrigger.load("models/InnerFormation-v0_learned.json").policy_for(run.env)
    schedule = trigger_schedule(run, trigger)
    assert schedule.masks.shape[1] == 3
    assert 0 < schedule.transmissions < 3 * len(schedule.instants)  # channels send apart
    assert run.outcome(schedule).transmissions == int(run.env.transmissions.sum())


# ------------------------------------------------------------------------- the search
@pytest.fixture(scope="module")
def found(run: ScheduleRun) -> dict:
    return clairvoyant(run, LearnedTrigger.load(TRIGGER), budget_steps=6 * run.n_steps, tail=None)


def test_the_search_keeps_its_constraints_on_the_exact_run(run: ScheduleRun, found: dict) -> None:
    trigger = found["trigger"]
    for objective in ("fewest_transmissions", "least_cost"):
        record = found[objective]
        schedule = Schedule(
            np.array(record["schedule"]["instants"]), np.array(record["schedule"]["masks"])
        )
        replay = run.outcome(schedule)
        assert not replay.failed
        assert replay.cost == record["cost"] and replay.transmissions == record["transmissions"]
        assert replay.transmissions <= trigger["transmissions"]
        assert replay.cost <= trigger["cost"]
    # it spent its budget, then stopped (the clocks' bisection and a pass's last exact runs
    # overrun it by a bounded number of episodes)
    assert 6 * run.n_steps <= found["steps"] < 40 * run.n_steps


def test_the_windowed_search_keeps_its_constraints_too() -> None:
    run = ScheduleRun(MULTI, scenario_set("test", 1), scenario_set("test", 1).seeds[0])
    trigger = LearnedTrigger.load("models/InnerFormation-v0_learned.json")
    found = clairvoyant(run, trigger, budget_steps=run.n_steps // 2, tail=1)
    for objective in ("fewest_transmissions", "least_cost"):
        assert found[objective]["transmissions"] <= found["trigger"]["transmissions"]
        assert found[objective]["cost"] <= found["trigger"]["cost"]


def test_a_clock_that_fails_is_no_start() -> None:
    """Paper 003's clock at the learned trigger's count of bursts leaves the shell: the
    least-cost search then starts from the trigger alone."""
    run = ScheduleRun(
        "etsc/AsteroidOrbitKeeping-v0", scenario_set("test", 1), scenario_set("test", 1).seeds[0]
    )
    trigger = LearnedTrigger.load("models/AsteroidOrbitKeeping-v0_learned.json")
    found = clairvoyant(run, trigger, budget_steps=run.n_steps, tail=None)
    assert found["least_cost"]["starts"]["clock"] is None
    assert found["least_cost"]["transmissions"] <= found["trigger"]["transmissions"]


def test_every_start_is_recorded_with_its_curve(found: dict) -> None:
    starts = found["least_cost"]["starts"]
    assert set(starts) == {"trigger", "clock"}
    curve = starts["trigger"]["curve"]
    assert curve[0]["transmissions"] == found["trigger"]["transmissions"]
    costs = [point["cost"] for point in curve]
    assert costs == sorted(costs, reverse=True)  # an accepted step never costs more


# ------------------------------------------------------------------------- the tuned start
@pytest.mark.parametrize("objective", ["fewest_transmissions", "least_cost"])
def test_the_tuned_point_is_the_learned_one_or_better_on_its_objective(
    run: ScheduleRun, objective: str
) -> None:
    """The tuning's first candidate is the learned point, so its result keeps the bound and
    is at least as good as the trigger on the objective; its schedule is the point's own
    episode, replayed exactly."""
    learned = LearnedTrigger.load(TRIGGER)
    trigger = run.outcome(trigger_schedule(run, learned.policy_for(run.env)))
    tuned = tune_on_scenario(run, learned, trigger, objective, 3 * run.n_steps, seed=0)
    outcome = tuned.outcome
    assert not outcome.failed
    # one axis is the bound, the other the objective: the trigger meets both
    assert outcome.transmissions <= trigger.transmissions
    assert outcome.cost <= trigger.cost
    point = LearnedTrigger(ENV_ID, learned.family, tuned.point, learned.keywords)
    replay = trigger_schedule(run, point.policy_for(run.env))
    assert np.array_equal(replay.instants, outcome.schedule.instants)
    assert tuned.curve[0]["transmissions"] == trigger.transmissions
    assert tuned.candidates > 1
    sent = [entry["transmissions"] for entry in tuned.curve]
    if objective == "fewest_transmissions":
        assert sent == sorted(sent, reverse=True)  # the best so far never sends more


def test_the_tuning_is_deterministic_and_seeded(run: ScheduleRun) -> None:
    learned = LearnedTrigger.load(TRIGGER)
    trigger = run.outcome(trigger_schedule(run, learned.policy_for(run.env)))
    first = tune_on_scenario(run, learned, trigger, "least_cost", run.n_steps, seed=3)
    again = tune_on_scenario(run, learned, trigger, "least_cost", run.n_steps, seed=3)
    assert first.point == again.point and first.curve[-1]["cost"] == again.curve[-1]["cost"]


@pytest.mark.parametrize(
    ("objective", "best_first"),
    [
        # (cost, transmissions, failed), from the best to the worst against cost 10, 100 sends
        (
            "fewest_transmissions",
            [
                (9.0, 80, False),
                (10.0, 90, False),
                (10.5, 10, False),
                (12.0, 5, False),
                (1.0, 1, True),
            ],
        ),
        (
            "least_cost",
            [
                (5.0, 100, False),
                (6.0, 50, False),
                (1.0, 101, False),
                (0.0, 150, False),
                (0.0, 1, True),
            ],
        ),
    ],
)
def test_a_bound_ranks_feasible_first_then_by_the_miss_then_failures(
    objective: str, best_first: list[tuple[float, int, bool]]
) -> None:
    bound = Bound(objective, cost=10.0, transmissions=100)
    keys = [bound.rank_key(*point) for point in best_first]
    assert all(better < worse for better, worse in itertools.pairwise(keys))
    with pytest.raises(ValueError, match="objective must be one of"):
        Bound("fewest", cost=10.0, transmissions=100)


def test_the_search_from_the_tuned_start_records_its_tuning(run: ScheduleRun) -> None:
    learned = LearnedTrigger.load(TRIGGER)
    found = clairvoyant(
        run, learned, budget_steps=run.n_steps, tail=None, tuning_steps=2 * run.n_steps
    )
    for objective in ("fewest_transmissions", "least_cost"):
        starts = found[objective]["starts"]
        assert set(starts) == {"tuned", "clock"}
        tuning = starts["tuned"]["tuning"]
        assert tuning["candidates"] > 1
        assert starts["tuned"]["start"]["transmissions"] <= found["trigger"]["transmissions"]
        assert found[objective]["transmissions"] <= found["trigger"]["transmissions"]
        assert found[objective]["cost"] <= found["trigger"]["cost"]


def test_the_tuned_starts_moves_are_followed_by_the_tuned_point(
    run: ScheduleRun, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A move from the tuned start is followed by the trigger whose episode the start is —
    the tuned point, whose own decisions replay the start's schedule — not by the learned
    trigger, which would replace the tuned tail after any change."""
    import agents.oracle.search as search

    followed: list[tuple[Schedule, Schedule]] = []
    improve = search.improve_by_rollout

    def recording(run_: ScheduleRun, start: Outcome, trigger: RuleTrigger, *rest: Any) -> Outcome:
        followed.append((start.schedule, trigger_schedule(run_, trigger)))
        return improve(run_, start, trigger, *rest)

    monkeypatch.setattr(search, "improve_by_rollout", recording)
    learned = LearnedTrigger.load(TRIGGER)
    found = clairvoyant(
        run, learned, budget_steps=4 * run.n_steps, tail=None, tuning_steps=run.n_steps
    )
    calls = iter(followed)  # in order: each objective's tuned start, then its clock's if any
    for objective in ("fewest_transmissions", "least_cost"):
        starts = found[objective]["starts"]
        start, replay = next(calls)
        assert starts["tuned"]["start"]["transmissions"] == start.transmissions
        assert np.array_equal(replay.instants, start.instants)
        assert np.array_equal(replay.masks, start.masks)
        if starts["clock"] is not None:
            next(calls)
    assert next(calls, None) is None


# ------------------------------------------------------------------------- settings, command
@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"env_id": "etsc/ClusterContainment-v0"}, "key 'env_id' must be a single-agent id"),
        ({"scenarios": "paper"}, "key 'scenarios' must be one of"),
        ({"scenario": -1}, "key 'scenario' must be an index 0..999999 of the test seeds"),
        ({"scenario": 1_000_000}, "key 'scenario' must be an index 0..999999 of the test seeds"),
        ({"budget_episodes": 0}, "key 'budget_episodes' must be a number > 0"),
        ({"tail": 1.5}, "key 'tail' must be an integer >= 0 or null"),
        ({"tuning_episodes": -1}, "key 'tuning_episodes' must be a number >= 0"),
        ({"tuning_episodes": True}, "key 'tuning_episodes' must be a number >= 0"),
        ({"trigger": "models/InnerFormation-v0_learned.json"}, "is a trigger of"),
        ({"speed": 2}, "unknown keys"),
    ],
)
def test_bad_settings_get_one_line_naming_the_key(change: dict, message: str) -> None:
    raw = {"env_id": ENV_ID, "trigger": TRIGGER, "scenario": 0, **change}
    with pytest.raises(ValueError, match=message) as error:
        oracle_config_from_dict(raw)
    assert "\n" not in str(error.value)


def test_the_command_refuses_bad_input_in_one_line(tmp_path, capsys) -> None:
    base = [ENV_ID, "--trigger", TRIGGER, "--scenario", "0", "--out", str(tmp_path)]
    assert oracle_main([*base, "--tail", "far"]) == 2
    assert (
        capsys.readouterr().err.strip()
        == "error: --tail must be an integer >= 0 or none, got 'far'"
    )
    for change, line in [
        (["--scenario", "-1"], "error: --scenario must be an index 0..999999 of the test seeds"),
        (["--budget-episodes", "0"], "error: --budget-episodes must be a number > 0, got 0.0"),
        (["--tuning-episodes", "-2"], "error: --tuning-episodes must be a number >= 0, got -2.0"),
        (["--scenarios", "paper"], "error: --scenarios must be one of"),
        (["--trigger", str(tmp_path / "none.json")], "error: --trigger: "),
    ]:
        assert oracle_main([*base, *change]) == 2
        assert capsys.readouterr().err.strip().startswith(line)
    assert oracle_main(["etsc/Nope-v0", *base[1:]]) == 2
    assert capsys.readouterr().err.startswith("error: ENV_ID must be a single-agent id")
    (tmp_path / "oracle.json").write_text("{}")
    assert oracle_main(base) == 2
    assert "already holds a record" in capsys.readouterr().err
    assert (tmp_path / "oracle.json").read_text() == "{}"  # not overwritten


def test_a_run_writes_its_record(tmp_path) -> None:
    config = oracle_config_from_dict(
        {"env_id": ENV_ID, "trigger": TRIGGER, "scenario": 1, "budget_episodes": 1, "tail": 2}
    )
    record = run_oracle(config, tmp_path)
    assert record["seed"] == scenario_set("test", 2).seeds[1]
    assert json.loads((tmp_path / "oracle.json").read_text())["seed"] == record["seed"]


# ------------------------------------------------------------------------- sweep and judge
def test_an_oracle_sweep_runs_its_scenarios_and_is_judged(tmp_path, capsys) -> None:
    base = tmp_path / "oracle.yaml"
    base.write_text(
        yaml.safe_dump(
            {"env_id": ENV_ID, "trigger": TRIGGER, "scenario": 0, "budget_episodes": 1, "tail": 2}
        )
    )
    sweep = sweep_config_from_dict(
        {
            "base": str(base),
            "results_dir": str(tmp_path / "sweep"),
            "kind": "front",
            "learner": "oracle",
            "grid": {"scenario": [0, 1]},
        }
    )
    trials = run_sweep_in_processes(sweep, 1, resume=False, description={})
    assert [trial.status for trial in trials] == ["finished", "finished"]
    records = read_runs(tmp_path / "sweep")
    assert [record["seed"] for record in records] == list(scenario_set("test", 2).seeds)
    summary = judge(records)
    ratio = summary["learned_over_clairvoyant"]["transmissions_at_equal_cost"]
    assert ratio["n"] == 2 and ratio["iqm"] >= 1.0
    out = tmp_path / "judged"
    assert judge_main([str(tmp_path / "sweep"), "--out", str(out)]) == 0
    assert judge_main([str(tmp_path / "sweep"), "--out", str(out)]) == 0  # again, in place
    held = json.loads((out / "oracle.json").read_text())
    (out / "oracle.json").write_text(json.dumps({**held, "seeds": held["seeds"][:1]}))
    assert judge_main([str(tmp_path / "sweep"), "--out", str(out)]) == 2
    assert "holds the clairvoyant schedules of" in capsys.readouterr().err
    assert json.loads((out / "oracle.json").read_text())["seeds"] == held["seeds"][:1]
    assert judge_main([str(tmp_path / "nowhere"), "--out", str(out)]) == 2
    assert capsys.readouterr().err.startswith("error: SWEEP_DIR: ")


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"kind": "search"}, "sweep key 'kind' must be 'front' with learner 'oracle'"),
        ({"grid": {"seed": [0]}}, "unknown oracle key 'seed'"),
    ],
)
def test_an_oracle_sweep_config_is_checked(tmp_path, change: dict, message: str) -> None:
    base = tmp_path / "oracle.yaml"
    base.write_text(yaml.safe_dump({"env_id": ENV_ID, "trigger": TRIGGER, "scenario": 0}))
    raw = {"base": str(base), "results_dir": str(tmp_path / "s"), "kind": "front"}
    with pytest.raises(ValueError, match=message):
        sweep_config_from_dict({**raw, "learner": "oracle", "grid": {"scenario": [0]}, **change})


def test_the_judgement_pairs_scenarios_by_seed() -> None:
    def record(seed: int, sent: tuple[int, int, int], cost: tuple[float, float, float]) -> dict:
        names = ("trigger", "fewest_transmissions", "least_cost")
        parts = dict(zip(names, zip(sent, cost, strict=True), strict=True))
        out = {
            "settings": {
                "env_id": ENV_ID,
                "trigger": TRIGGER,
                "scenarios": "test",
                "tail": None,
                "budget_episodes": 1.0,
            },
            "seed": seed,
            "steps": 1,
            "wall_time_s": 1.0,
        }
        for name, (n, c) in parts.items():
            out[name] = {
                "transmissions": n,
                "mean_cost": c,
                "starts": {"trigger": None, "clock": None},
            }
        return out

    records = [record(s, (100, 50, 100), (2.0, 1.9, 1.0)) for s in range(4)]
    records[0]["settings"] = {**records[0]["settings"], "tuning_episodes": 3.0}
    summary = judge(records)
    assert summary["budget_episodes"] == [1.0]
    assert summary["tuning_episodes"] == [0.0, 3.0]  # a run without the key did not tune
    ratios = summary["learned_over_clairvoyant"]
    assert ratios["transmissions_at_equal_cost"]["iqm"] == pytest.approx(2.0)
    assert ratios["cost_at_equal_transmissions"]["iqm"] == pytest.approx(2.0)

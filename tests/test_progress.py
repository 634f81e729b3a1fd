"""A long job's progress when its standard error is redirected: lines that say what runs, the
share done and the time left (``etsc_envs.evaluation.progress``), fed by the episode runners' bars,
and ``python -m baselines.reproduce`` speaking before its first run."""

from __future__ import annotations

import io
import re
import types

from baselines import reproduce
from baselines.reproductions.report import Scenario, stages
from etsc_envs.evaluation.episodes import instants_bar
from etsc_envs.evaluation.progress import JobBar, JobProgress, clock, current_job

LINE = re.compile(r"^\[ *(\d+)%\] (.+) \| (\d+:\d\d) elapsed, (about (\d+:\d\d) left|estimating)")


def test_a_redirected_job_writes_a_line_per_stage_with_the_share_and_the_time_left():
    stream = io.StringIO()
    with JobProgress(400, stream=stream, line_every_s=0.0) as job:
        job.stage("paper 999: run 1/2 (first)")
        job.advance(100)
        job.stage("paper 999: run 2/2 (second)")
        job.reach(400)
    lines = stream.getvalue().splitlines()
    parsed = [LINE.match(line) for line in lines]
    assert all(parsed), lines
    assert [m.group(2) for m in parsed[:1]] == ["paper 999: run 1/2 (first)"]
    assert parsed[0].group(1) == "0" and "estimating" in lines[0]  # nothing done yet
    assert [int(m.group(1)) for m in parsed] == [0, 25, 25, 100]
    assert all(m.group(5) for m in parsed[1:])  # every later line estimates the time left
    assert parsed[-1].group(5) == "0:00"


def test_lines_between_stages_wait_for_the_interval():
    stream = io.StringIO()
    with JobProgress(10_000, stream=stream, line_every_s=3600.0) as job:
        job.stage("one stage")
        for _ in range(10):
            job.advance(1000)
    assert len(stream.getvalue().splitlines()) == 1  # the stage's line only
    assert job.done == 10_000


def test_episode_bars_inside_a_job_count_for_the_job():
    assert current_job() is None
    assert not isinstance(instants_bar(100, False, ""), JobBar)
    with JobProgress(5000, stream=io.StringIO()) as job:
        bar = instants_bar(3000, False, "an episode")
        assert isinstance(bar, JobBar)
        with bar:
            bar.update(1000)
            bar.update(1000)
        assert job.done == 2000
        job.advance(10_000)
        assert job.done == 5000  # never beyond the plan
    assert current_job() is None


def test_stages_inside_a_job_name_each_run_as_it_starts():
    scenarios = [Scenario(label, (), "paper") for label in ("first", "second")]
    stream = io.StringIO()
    with JobProgress(10, stream=stream) as job:
        for index, scenario in enumerate(stages(scenarios, "paper 999"), start=1):
            assert job.stage_text == f"paper 999: run {index}/2 ({scenario.label})"
    assert "paper 999: run 2/2 (second)" in stream.getvalue()


def test_clock_reads_minutes_and_hours():
    assert clock(5) == "0:05"
    assert clock(125.4) == "2:05"
    assert clock(3 * 3600 + 61) == "3:01:01"


def test_reproduce_says_what_it_does_before_its_first_run(monkeypatch, capsys):
    """The main job's first line comes before any work, and each run of a paper gets its own
    progress line with the share of the plan done (here a stand-in reproduction of 3000
    planned instants)."""

    def fake_reproduce(plot_dir=None, progress=False):
        for _ in stages([Scenario("a run", (), "paper")], "paper 999"):
            assert capsys.readouterr().err.count("\n") >= 3  # said before the run's work
            with instants_bar(3000, progress, "") as bar:
                bar.update(1000)
        return {"paper": "999", "title": "A stand-in", "env": "none", "tables": [], "claims": []}

    module = types.SimpleNamespace(
        TITLE="A stand-in", planned_instants=lambda: 3000, reproduce=fake_reproduce
    )
    monkeypatch.setattr(reproduce, "REPRODUCTIONS", {"999": module})
    assert reproduce.main(["--paper", "999"]) == 0
    captured = capsys.readouterr()
    assert "Paper 999: A stand-in" in captured.out
    assert "Claims not reproduced: none" in captured.out

"""``python -m etsc_envs.benchmark --protocol``: the command it times runs the policy it names."""

from __future__ import annotations

import subprocess
from typing import Any

import pytest

from etsc_envs import benchmark


def test_protocol_times_the_policy_it_is_given(monkeypatch: pytest.MonkeyPatch) -> None:
    commands: list[list[str]] = []

    def record(command: list[str], **keywords: Any) -> subprocess.CompletedProcess:
        commands.append(command)
        return subprocess.CompletedProcess(command, 0)

    monkeypatch.setattr(benchmark.subprocess, "run", record)
    result = benchmark.benchmark_protocol(
        ["etsc/AttitudeTracking-v0"], 4, 2, "periodic", ["every=8"]
    )
    assert (result["policy"], result["policy_args"], result["set_size"]) == (
        "periodic",
        ["every=8"],
        4,
    )
    assert len(commands) == 3, "a one-scenario warm-up, then the timed runs"
    expected = ["-m", "baselines.evaluate", "etsc/AttitudeTracking-v0", "--policy", "periodic"]
    expected += ["--policy-arg", "every=8", "--scenarios", "test", "--set-size"]
    assert [command[1:] for command in commands] == [[*expected, size] for size in "144"]
    figure = result["ids"]["etsc/AttitudeTracking-v0"]["wall_time_s"]
    assert 0.0 < figure["min"] <= figure["median"] <= figure["max"]


def test_protocol_defaults_to_the_paper_trigger() -> None:
    arguments = benchmark.build_parser().parse_args(["--protocol"])
    assert (arguments.protocol, arguments.protocol_policy, arguments.protocol_arg) == (
        64,
        "paper",
        [],
    )

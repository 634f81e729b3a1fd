"""``python -m etsc_envs.benchmark --protocol``: the command it times runs the policy it names."""

from __future__ import annotations

import importlib
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


@pytest.mark.parametrize(
    ("module", "argv", "message"),
    [
        (
            "judging",
            ["etsc/AttitudeTracking-v0", "--model", "m.zip", "--set-size", "0"],
            "--set-size",
        ),
        (
            "judging",
            ["etsc/AttitudeTracking-v0", "--model", "m.zip", "--repeats", "0"],
            "--repeats",
        ),
        ("judging", ["etsc/Nope-v0", "--model", "m.zip"], "etsc/Nope-v0"),
        ("judging", ["etsc/AttitudeTracking-v0", "--model", "m.zip"], "m.zip"),
        (
            "judging",
            ["etsc/AttitudeTracking-v0", "--model", "models/AttitudeTracking-v0_ppo.zip"],
            "does not take self-triggered decisions",
        ),
        ("decisions", ["--repeats", "0"], "--repeats"),
        ("decisions", ["--env", "etsc/Nope-v0"], "etsc/Nope-v0"),
        ("search", ["--generations", "0"], "--generations"),
    ],
)
def test_bench_commands_refuse_bad_input_in_one_line(
    module: str, argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Each ``agents.bench`` command names the argument and exits 2 before timing anything."""
    bench = importlib.import_module(f"agents.bench.{module}")
    with pytest.raises(SystemExit) as exit_info:
        bench.main(argv)
    assert exit_info.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert error.startswith(f"python -m agents.bench.{module}: error:") and message in error

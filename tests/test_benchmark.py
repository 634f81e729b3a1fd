"""``python -m etsc_envs.benchmark``: the timed protocol run names the policy it timed."""

from __future__ import annotations

import json

from etsc_envs.benchmark import main


def test_protocol_times_the_policy_it_is_given(capsys) -> None:
    argv = [
        "--env",
        "etsc/AttitudeTracking-v0",
        "--steps",
        "10",
        "--repeats",
        "1",
        "--num-envs",
        "1",
        "--protocol",
        "2",
        "--protocol-policy",
        "periodic",
        "--protocol-arg",
        "every=8",
        "--json",
        "-",
    ]
    assert main(argv) == 0
    protocol = json.loads(capsys.readouterr().out)["protocol"]
    assert (protocol["policy"], protocol["policy_args"], protocol["set_size"]) == (
        "periodic",
        ["every=8"],
        2,
    )
    figure = protocol["ids"]["etsc/AttitudeTracking-v0"]["wall_time_s"]
    assert 0.0 < figure["min"] <= figure["median"] <= figure["max"]

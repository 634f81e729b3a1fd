"""``python -m etsc_envs.compile`` compiles what every id runs: each Gymnasium id's single env
(step, holds, metrics), its native vector env, and every rule the compiled loop runs for it (the
paper's rule, its error-time rule, its trigger family, the clock), and the PettingZoo id's
parallel env. A piece missing from the list would leave its first call to compile for a minute."""

from __future__ import annotations

import gymnasium as gym
import pytest

import etsc_envs
from etsc_envs.compile import kernel_tasks, main, rule_triggers
from etsc_envs.papers import paper_of
from etsc_envs.triggers import ClockTrigger
from etsc_envs.triggers.base import RuleTrigger


def test_the_kernel_list_covers_every_id():
    tasks = kernel_tasks()
    pieces: dict[str, set[str]] = {}
    for task in tasks:
        pieces.setdefault(task.env_id, set()).add(task.what)
    assert set(pieces) == set(etsc_envs.ENV_IDS) | set(etsc_envs.PETTINGZOO_ENV_IDS)
    for env_id in etsc_envs.ENV_IDS:
        assert {"env step, holds and metrics", "vector env step", "paper rule"} <= pieces[env_id]
        assert "trigger family" in pieces[env_id]
        assert ("error-time rule" in pieces[env_id]) == (paper_of(env_id).error_time is not None)
    for env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        assert pieces[env_id] == {"parallel env step"}
        assert etsc_envs.PETTINGZOO_LOOP_IDS[env_id] in pieces  # its loop's rules and vector env
    # every receiver but paper 003's (a burst refuses transmissions) runs the clock as a rule
    clocks = {env_id for env_id, whats in pieces.items() if "clock" in whats}
    assert clocks == set(etsc_envs.ENV_IDS) - {"etsc/AsteroidOrbitKeeping-v0"}


@pytest.mark.parametrize("env_id", sorted(etsc_envs.ENV_IDS))
def test_each_rule_listed_is_the_rule_the_suite_runs(env_id):
    env = gym.make(env_id)
    built = {name: build(env) for name, build in rule_triggers(env_id).items()}
    env.close()
    assert all(isinstance(trigger, RuleTrigger) for trigger in built.values())
    assert type(built["paper rule"]).rule is paper_of(env_id).trigger.rule
    assert built["trigger family"].paper_class is paper_of(env_id).trigger
    if "clock" in built:
        assert isinstance(built["clock"], ClockTrigger)


def test_an_unknown_id_is_refused_with_the_known_ones(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--env", "etsc/Nothing-v0"])
    assert exit_info.value.code == 2
    assert "etsc/AttitudeTracking-v0" in capsys.readouterr().err

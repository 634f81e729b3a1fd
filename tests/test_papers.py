"""The paper records (``etsc_envs/<problem>/paper.py``) and their registry
(:mod:`etsc_envs.papers`): every registered id has exactly one record, the record is its own
folder's, its facts agree with the trigger, env and reproduction they name, and the modules
import in one direction."""

from __future__ import annotations

import importlib
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pettingzoo
import pytest

import etsc_envs
from etsc_envs.core.paper import RULE_NAMES
from etsc_envs.papers import (
    PAPER_IDS,
    PAPERS,
    ids_with_rule,
    paper_numbered,
    paper_of,
    rule_of,
)

GYMNASIUM_IDS = sorted(etsc_envs.ENV_IDS)


def test_every_registered_id_has_one_record_and_every_record_id_is_registered():
    registered = {env_id for env_id in gym.registry if env_id.startswith("etsc/")}
    registered |= {
        env_id
        for registry in (pettingzoo.parallel_registry, pettingzoo.aec_registry)
        for env_id in registry
        if env_id.startswith("etsc/")
    }
    assert registered == {*etsc_envs.ENV_IDS, *etsc_envs.PETTINGZOO_ENV_IDS}
    assert set(PAPER_IDS) == registered
    ids = [env_id for paper in PAPERS for env_id in paper.ids]
    assert len(ids) == len(set(ids)), "an id belongs to two papers"


def test_papers_are_numbered_in_order_and_found_by_number():
    assert [paper.number for paper in PAPERS] == ["000", "001", "002", "003", "004"]
    for paper in PAPERS:
        assert paper_numbered(paper.number) is paper


@pytest.mark.parametrize("env_id", PAPER_IDS)
def test_an_id_maps_to_the_record_of_the_folder_that_implements_it(env_id):
    paper = paper_of(env_id)
    assert importlib.import_module(f"etsc_envs.{paper.folder}.paper").PAPER is paper
    loop_id = etsc_envs.PETTINGZOO_LOOP_IDS.get(env_id, env_id)
    assert paper_of(loop_id) is paper
    entry_point = gym.spec(loop_id).entry_point
    assert entry_point.startswith(f"etsc_envs.{paper.folder}.env:"), entry_point
    for rule in paper.rules.values():
        assert rule.trigger.__module__ == f"etsc_envs.triggers.{paper.folder}"
    if paper.shield is not None:
        assert paper.shield.__module__ == f"etsc_envs.triggers.{paper.folder}"


@pytest.mark.parametrize("paper", PAPERS, ids=lambda paper: paper.number)
def test_a_record_names_the_reproduction_of_its_paper(paper):
    module = importlib.import_module(paper.reproduction)
    assert (paper.number, paper.title) == (module.PAPER, module.TITLE)
    assert module.ENV_ID in paper.ids


@pytest.mark.parametrize("env_id", GYMNASIUM_IDS)
def test_a_rules_thresholds_are_its_triggers_defaults_and_a_point_of_its_sweep(env_id):
    env = gym.make(env_id, disable_env_checker=True)
    names = env.unwrapped.observation_names
    for name, rule in paper_of(env_id).rules.items():
        thresholds = rule.thresholds()
        assert thresholds and all(value > 0 for value in thresholds.values()), name
        default = rule.trigger(env.observation_space, env.action_space, names)
        given = rule.trigger(env.observation_space, env.action_space, names, **thresholds)
        np.testing.assert_array_equal(given.rule_parameters, default.rule_parameters)
        halved = {key: 0.5 * value for key, value in thresholds.items()}
        moved = rule.trigger(env.observation_space, env.action_space, names, **halved)
        assert not np.array_equal(moved.rule_parameters, default.rule_parameters), name
        sweep = rule.sweep()
        assert len(sweep) >= 5 and thresholds in sweep, name
        assert all(set(point) == set(thresholds) for point in sweep), name
    env.close()


def test_rules_and_defaults_of_the_records():
    assert ids_with_rule("paper") == list(PAPER_IDS)
    assert ids_with_rule("error_time") == ["etsc/InnerFormation-v0"]
    for paper in PAPERS:
        assert set(paper.rules) <= set(RULE_NAMES)
        assert list(paper.periodic_every) == sorted(set(paper.periodic_every))
        assert paper.headline_metrics
    # eq. (15) of paper 001 needs 0 < c < 1: every swept c stays inside.
    cluster = paper_of("etsc/ClusterContainment-v0")
    assert all(0.0 < point["c"] < 1.0 for point in cluster.rule.sweep())


def test_unknown_ids_numbers_and_rules_are_refused_with_the_argument_named():
    with pytest.raises(ValueError, match="env_id must be one of"):
        paper_of("etsc/Nothing-v0")
    with pytest.raises(ValueError, match="number must be one of"):
        paper_numbered("999")
    with pytest.raises(ValueError, match="rule must be one of"):
        ids_with_rule("heartbeat")
    with pytest.raises(ValueError, match=r"env_id must be one of .*InnerFormation"):
        rule_of("etsc/AttitudeTracking-v0", "error_time")


def test_modules_import_in_one_direction():
    """Registering the ids imports no trigger or record; the triggers import no record."""
    code = (
        "import sys, etsc_envs\n"
        "assert not [m for m in sys.modules if m.startswith(('etsc_envs.triggers', "
        "'etsc_envs.papers'))]\n"
        "import etsc_envs.triggers\n"
        "assert not [m for m in sys.modules if m == 'etsc_envs.papers' or m.endswith('.paper')]\n"
        "import etsc_envs.papers\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)

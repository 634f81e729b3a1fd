"""The error-time rule of paper 004's env (a reference trigger beside eqs. (4)-(6)): its
condition, the interval law it implies, its place among the decisions of a decision set, its
command line, and its bad arguments."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import etsc_envs  # noqa: F401  (registers the ids)
from etsc_envs.evaluation.episodes import run_episode
from etsc_envs.evaluation.policy_specs import make_policy
from etsc_envs.papers import rule_of
from etsc_envs.triggers.inner_formation import (
    AXES,
    ERROR_TIME_REFERENCE_S,
    InnerFormationErrorTimeTrigger,
    default_error_time_thresholds,
    default_thresholds,
)
from tests.rule_sets import rule_set, rule_wrapper
from tests.test_decisions import RecordedActions

FORMATION = "etsc/InnerFormation-v0"
SAMPLING_PERIOD_S = 1e-3


def formation_env(**kwargs) -> gym.Env:
    return gym.make(FORMATION, **kwargs)


def error_time_trigger(env: gym.Env, **kwargs) -> InnerFormationErrorTimeTrigger:
    return InnerFormationErrorTimeTrigger(
        env.observation_space, env.action_space, env.unwrapped.observation_names, **kwargs
    )


def observations(env: gym.Env, errors: np.ndarray, elapsed_s: np.ndarray) -> np.ndarray:
    """Observations (zeros elsewhere) with the given per-axis sampling errors and times since
    transmission, one row per entry of the leading axis."""
    names = env.unwrapped.observation_names
    obs = np.zeros((len(errors), len(names)), dtype=np.float32)
    for axis, letter in enumerate(AXES):
        obs[:, names.index(f"sampling_error_m_{letter}")] = errors[:, axis]
        obs[:, names.index(f"time_since_transmission_s_{axis}")] = elapsed_s[:, axis]
    return obs


def test_each_axis_fires_when_its_error_times_its_elapsed_time_passes_its_threshold():
    env = formation_env(horizon_s=0.05)
    areas = np.array([2e-6, 5e-6, 1e-5])
    trigger = error_time_trigger(env, area1=areas[0], area2=areas[1], area3=areas[2])
    rng = np.random.default_rng(0)
    errors = rng.uniform(-2e-4, 2e-4, size=(500, 3))
    elapsed = rng.uniform(0.0, 0.2, size=(500, 3))
    action, _ = trigger.predict(observations(env, errors, elapsed))
    product = np.abs(errors.astype(np.float32)) * elapsed.astype(np.float32)
    expected = product.astype(np.float64) > areas
    assert 0.2 < expected.mean() < 0.8
    np.testing.assert_array_equal(action.astype(bool), expected)


@pytest.mark.parametrize("area", [1e-6, 4e-6])
def test_under_a_steady_drift_the_interval_is_the_square_root_of_area_over_speed(area):
    """A sampling error growing at v after a transmission, v τ, passes the rule at
    τ = √(A / v): four times the speed gives half the interval (the paper's rule, Π / v, a
    quarter; a clock, the same)."""
    env = formation_env(horizon_s=0.05)
    trigger = error_time_trigger(env, area=area)
    elapsed = np.arange(1, 2001) * SAMPLING_PERIOD_S
    intervals = []
    for speed in (1e-3, 4e-3):
        errors = speed * elapsed
        obs = observations(
            env, np.repeat(errors[:, None], 3, axis=1), np.repeat(elapsed[:, None], 3, axis=1)
        )
        action, _ = trigger.predict(obs)
        first = int(np.argmax(action[:, 0]))
        assert action[first:, 0].all() and not action[:first, 0].any()
        intervals.append(elapsed[first])
        assert elapsed[first] == pytest.approx(np.sqrt(area / speed), abs=SAMPLING_PERIOD_S)
    assert intervals[0] / intervals[1] == pytest.approx(2.0, rel=0.02)


def test_default_thresholds_are_the_paper_thresholds_times_the_reference_time():
    np.testing.assert_allclose(
        default_error_time_thresholds(), default_thresholds() * ERROR_TIME_REFERENCE_S
    )
    env = formation_env(horizon_s=0.05)
    np.testing.assert_allclose(error_time_trigger(env).thresholds, default_error_time_thresholds())
    assert rule_of(FORMATION, "error_time").trigger is InnerFormationErrorTimeTrigger


def test_follow_the_error_time_rule_is_the_error_time_trigger():
    """Always choosing "error_time x1" in a decision set whose rule is ``error_time`` takes the
    error-time trigger's actions, instant for instant (through compiled intervals)."""
    decisions = rule_set(FORMATION, max_exponent=3, rule="error_time", factors=(1.0, 2.0))
    assert decisions.label(len(decisions.hold_indices)) == "error_time x1"
    base = RecordedActions(formation_env(horizon_s=2.0))
    wrapper = rule_wrapper(base, max_exponent=3, rule="error_time", factors=(1.0, 2.0))
    wrapper.reset(seed=4)
    done = False
    while not done:
        _, _, terminated, truncated, _ = wrapper.step(decisions.action("error_time x1"))
        done = terminated or truncated
    reference = RecordedActions(formation_env(horizon_s=2.0))
    run_episode(reference, error_time_trigger(reference), seed=4)
    assert np.array(reference.actions).sum() > 10
    np.testing.assert_array_equal(np.array(base.actions), np.array(reference.actions))


def test_the_command_line_policy_is_the_error_time_rule():
    env = formation_env(horizon_s=0.05)
    policy = make_policy("error_time", env, {"area": 3e-6}, FORMATION)
    assert isinstance(policy, InnerFormationErrorTimeTrigger)
    np.testing.assert_allclose(policy.thresholds, 3e-6)


@pytest.mark.parametrize(
    ("env_id", "kwargs", "message"),
    [
        (FORMATION, {"rule": "integral"}, "rule must be one of"),
        (
            "etsc/AttitudeTracking-v0",
            {"rule": "error_time"},
            "env_id must be one of .* for rule 'error_time'",
        ),
        (FORMATION, {"rule": "error_time", "shield_multiple": 2.0}, "shield_multiple"),
    ],
)
def test_a_decision_set_refuses_a_rule_it_cannot_run(env_id, kwargs, message):
    with pytest.raises(ValueError, match=message):
        rule_set(env_id, **kwargs)


@pytest.mark.parametrize("kwargs", [{"area": 0.0}, {"area2": -1e-6}, {"area3": float("nan")}])
def test_bad_thresholds_name_themselves(kwargs):
    with pytest.raises(ValueError, match="area"):
        error_time_trigger(formation_env(horizon_s=0.05), **kwargs)


def test_the_command_line_names_ids_without_an_error_time_rule():
    env = gym.make("etsc/AttitudeTracking-v0", horizon_s=0.05)
    with pytest.raises(ValueError, match="no error_time trigger"):
        make_policy("error_time", env, {}, "etsc/AttitudeTracking-v0")

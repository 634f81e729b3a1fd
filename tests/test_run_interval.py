"""``EventTriggeredEnv.run_interval`` and ``run_rule_interval``: one compiled call over several
sampling instants equals the same actions (or the paper rule's decisions) given to ``step`` one
instant at a time, bit for bit (observation, rewards and
their discounted sum, termination, info and episode metrics, every loop array), for every
Gymnasium id, also across a failure and up to the horizon; bad arguments raise."""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest

from etsc_envs import ENV_IDS
from etsc_envs.papers import paper_of, rule_of
from etsc_envs.triggers import PeriodicPolicy

SEED = 5
HORIZONS_S = {
    "etsc/AttitudeTracking-v0": 0.1,
    "etsc/InnerFormation-v0": 0.1,
    "etsc/OrbitAttitudeTracking-v0": 0.1,
    "etsc/AsteroidOrbitKeeping-v0": 60.0,
    "etsc/ClusterContainmentCentral-v0": 1.0,
}
"""About 100 instants (240 for the asteroid, whose horizon is at least one 50-s burst)."""

FAILING = {
    "etsc/AttitudeTracking-v0": ({"max_rate_rad_s": 0.05, "horizon_s": 2.0}, 14),
    "etsc/InnerFormation-v0": ({"initial_velocity_mps": (0.2, 0.0, 0.0), "horizon_s": 20.0}, 190),
    "etsc/OrbitAttitudeTracking-v0": ({"max_velocity_error_m_s": 0.005, "horizon_s": 1.0}, 142),
    "etsc/AsteroidOrbitKeeping-v0": ({}, 7055),
    "etsc/ClusterContainmentCentral-v0": ({"max_rate_rad_s": 0.016, "horizon_s": 100.0}, 752),
}
"""Keywords under which transmitting once at reset and holding after fails, and the instant
(seed 0) at which it does."""


def transmit_all(env: gym.Env) -> np.ndarray:
    """The action transmitting every channel."""
    return np.ones(env.action_space.shape, dtype=np.int64)


def stepped(env: gym.Env, first_action, instants: int, gamma: float) -> tuple:
    """What ``run_interval`` should return, from ``step`` one instant at a time."""
    action, total = first_action, 0.0
    for instant in range(instants):
        observation, reward, terminated, truncated, info = env.step(action)
        total += gamma**instant * reward
        action = np.zeros_like(first_action)
        if terminated or truncated:
            break
    return observation, total, terminated, truncated, info, instant + 1


def assert_same_loop(compiled: gym.Env, stepwise: gym.Env, got: tuple, expected: tuple) -> None:
    """The two results (of ``step`` or ``run_interval``) and every loop array are equal, bit
    for bit."""
    np.testing.assert_array_equal(got[0], expected[0])
    np.testing.assert_equal(list(got[1:]), list(expected[1:]))
    for mine, theirs in zip(compiled.unwrapped.arrays, stepwise.unwrapped.arrays, strict=True):
        np.testing.assert_array_equal(mine, theirs)


def pair(env_id: str, seed: int = SEED, **kwargs) -> tuple[gym.Env, gym.Env]:
    """Two envs reset alike."""
    envs = tuple(gym.make(env_id, **kwargs) for _ in range(2))
    for env in envs:
        env.reset(seed=seed)
    return envs


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_an_interval_equals_its_steps_up_to_the_horizon(env_id):
    compiled, stepwise = pair(env_id, horizon_s=HORIZONS_S[env_id], randomize=True)
    rng = np.random.default_rng(0)
    for _ in range(3):
        action = compiled.action_space.sample()
        assert_same_loop(compiled, stepwise, compiled.step(action), stepwise.step(action))
    n_steps = compiled.unwrapped.n_steps
    intervals = [
        (transmit_all(compiled), 37, 0.9),
        (rng.integers(0, 2, compiled.action_space.shape), 1, 0.5),
    ]
    for first_action, instants, gamma in intervals:
        got = compiled.unwrapped.run_interval(first_action, instants, gamma)
        assert not (got[2] or got[3]) and got[5] == instants
        assert_same_loop(compiled, stepwise, got, stepped(stepwise, first_action, instants, gamma))
    left = n_steps - compiled.unwrapped.step_index
    got = compiled.unwrapped.run_interval(transmit_all(compiled), 10 * n_steps, 1.0)
    expected = stepped(stepwise, transmit_all(compiled), 10 * n_steps, 1.0)
    assert got[3] and not got[2] and got[5] == left
    assert "episode_metrics" in got[4]
    assert_same_loop(compiled, stepwise, got, expected)
    with pytest.raises(RuntimeError, match="run_interval"):
        compiled.unwrapped.run_interval(0 * transmit_all(compiled), 1)


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_an_interval_stops_at_a_failure_as_its_steps_do(env_id):
    kwargs, failure_step = FAILING[env_id]
    compiled, stepwise = pair(env_id, seed=0, **kwargs)
    first_action, instants = transmit_all(compiled), 2 * failure_step
    got = compiled.unwrapped.run_interval(first_action, instants, 0.99)
    assert got[2] and not got[3] and got[5] == failure_step
    assert got[4]["failure"] == got[4]["episode_metrics"]["failure"]
    assert_same_loop(compiled, stepwise, got, stepped(stepwise, first_action, instants, 0.99))


def test_an_interval_draws_the_same_render_frame():
    compiled, stepwise = pair("etsc/InnerFormation-v0", horizon_s=0.05, render_mode="rgb_array")
    first_action = np.array([1, 0, 1])
    compiled.unwrapped.run_interval(first_action, 30, 0.9)
    stepped(stepwise, first_action, 30, 0.9)
    np.testing.assert_array_equal(compiled.render(), stepwise.render())


def test_a_pickled_env_runs_the_same_intervals():
    env = gym.make("etsc/AttitudeTracking-v0", horizon_s=0.1).unwrapped
    env.reset(seed=SEED)
    env.run_interval(1, 10, 0.9)
    copy = pickle.loads(pickle.dumps(env))
    got, expected = (e.run_interval(1, 20, 0.9) for e in (env, copy))
    np.testing.assert_array_equal(got[0], expected[0])
    assert got[1:] == expected[1:]


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ((1, 0, 0.9), r"instants must be an integer >= 1, got 0"),
        ((1, 2.0, 0.9), r"instants must be an integer >= 1, got 2\.0 \(float\)"),
        ((1, True, 0.9), r"instants must be an integer >= 1"),
        ((1, 4, 0.0), r"gamma must be a finite number in \(0, 1\], got 0\.0"),
        ((1, 4, 1.5), r"gamma must be a finite number in \(0, 1\]"),
        ((1, 4, float("nan")), r"gamma must be a finite number in \(0, 1\]"),
        ((1, 4, "0.9"), r"gamma must be a finite number in \(0, 1\], got '0\.9' \(str\)"),
        ((2, 4, 0.9), r"first_action must be 0 \(hold\) or 1 \(transmit\), got 2"),
        (([1, 1], 4, 0.9), r"first_action must be 0 \(hold\) or 1 \(transmit\)"),
    ],
)
def test_bad_arguments_name_themselves(arguments, message):
    env = gym.make("etsc/AttitudeTracking-v0", horizon_s=0.1).unwrapped
    env.reset(seed=SEED)
    with pytest.raises(ValueError, match=message):
        env.run_interval(*arguments)
    assert env.step_index == 0


def test_an_interval_before_reset_asks_for_one():
    env = gym.make("etsc/AttitudeTracking-v0", horizon_s=0.1).unwrapped
    with pytest.raises(gym.error.ResetNeeded, match="run_interval"):
        env.run_interval(1, 4)


def paper_trigger(env: gym.Env, factor: float = 1.0):
    """The env's paper trigger with its threshold keywords scaled by ``factor``."""
    return scaled_rule_trigger(
        env.spec.id,
        factor,
        env.observation_space,
        env.action_space,
        env.unwrapped.observation_names,
    )


def scaled_rule_trigger(env_id, factor, observation_space, action_space, names, rule="paper"):
    """The stand-alone ``rule`` trigger of ``env_id`` with its thresholds scaled by ``factor``."""
    chosen = rule_of(env_id, rule)
    thresholds = {name: factor * value for name, value in chosen.thresholds().items()}
    return chosen.trigger(observation_space, action_space, names, **thresholds)


RULE_HORIZONS_S = {
    "etsc/AsteroidOrbitKeeping-v0": 1200.0,
    "etsc/ClusterContainmentCentral-v0": 20.0,
}
"""Longer horizons where the paper's rule sends only every minute or so."""


def rule_stepped(env: gym.Env, trigger, instants: int, gamma: float) -> tuple:
    """What ``run_rule_interval`` should return, from ``step`` one instant at a time: the
    trigger decides every instant, and the interval ends before a later instant at which it
    sends."""
    total, observation = 0.0, env.unwrapped.arrays.observation[0].copy()
    info: dict = {}
    for instant in range(instants):
        action, _ = trigger.predict(observation)
        if instant > 0 and np.any(action):
            return observation, total, False, False, info, instant
        observation, reward, terminated, truncated, info = env.step(action)
        total += gamma**instant * reward
        if terminated or truncated:
            break
    return observation, total, terminated, truncated, info, instant + 1


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_a_rule_interval_equals_the_rules_steps(env_id):
    """Intervals of the paper's rule (several thresholds) end where the stepped rule sends
    again, and the last one runs on to the horizon, bit for bit."""
    horizon_s = RULE_HORIZONS_S.get(env_id, HORIZONS_S[env_id])
    compiled, stepwise = pair(env_id, horizon_s=horizon_s, randomize=True)
    triggers = [paper_trigger(compiled, factor) for factor in (0.5, 1.0, 1.5)]
    n_steps = compiled.unwrapped.n_steps
    lengths, index = [], 0
    while compiled.unwrapped.step_index < n_steps:
        trigger = triggers[index % len(triggers)]
        got = compiled.unwrapped.run_rule_interval(trigger, n_steps, 0.99)
        assert_same_loop(compiled, stepwise, got, rule_stepped(stepwise, trigger, n_steps, 0.99))
        lengths.append(got[5])
        index += 1
    assert got[3] and "episode_metrics" in got[4]
    assert len(lengths) > 2, "the rule sent again within the horizon"


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_a_rule_interval_stops_at_a_failure_as_its_steps_do(env_id):
    kwargs, failure_step = FAILING[env_id]
    compiled, stepwise = pair(env_id, seed=0, **kwargs)
    if env_id == "etsc/ClusterContainmentCentral-v0":  # eq. (15) needs c < 1: raise rho
        trigger = paper_of(env_id).trigger(
            compiled.observation_space,
            compiled.action_space,
            compiled.unwrapped.observation_names,
            rho=1e12,
        )
    else:
        trigger = paper_trigger(compiled, 1e6)  # sends at most at the reset, then holds
    got = compiled.unwrapped.run_rule_interval(trigger, 2 * failure_step, 0.99)
    assert got[2] and abs(got[5] - failure_step) <= 1
    expected = rule_stepped(stepwise, trigger, 2 * failure_step, 0.99)
    assert_same_loop(compiled, stepwise, got, expected)


def test_a_rule_interval_refuses_a_trigger_of_another_env():
    env = gym.make("etsc/InnerFormation-v0", horizon_s=0.1)
    other = gym.make("etsc/AttitudeTracking-v0", horizon_s=0.1)
    env.reset(seed=SEED)
    with pytest.raises(ValueError, match="trigger must be a paper rule"):
        env.unwrapped.run_rule_interval(paper_trigger(other), 4)
    with pytest.raises(ValueError, match="trigger must be a paper rule"):
        env.unwrapped.run_rule_interval(
            PeriodicPolicy(other.observation_space, other.action_space, every=2), 4
        )


def test_an_error_time_interval_equals_the_rules_steps():
    """The error-time rule of 004 (a RuleTrigger beside the paper's) runs compiled intervals
    that end where the stepped rule sends again, bit for bit."""
    env_id = "etsc/InnerFormation-v0"
    compiled, stepwise = pair(env_id, horizon_s=0.5, randomize=True)
    triggers = [
        scaled_rule_trigger(
            env_id,
            factor,
            compiled.observation_space,
            compiled.action_space,
            compiled.unwrapped.observation_names,
            "error_time",
        )
        for factor in (0.05, 0.2)
    ]
    n_steps = compiled.unwrapped.n_steps
    lengths = []
    while compiled.unwrapped.step_index < n_steps:
        trigger = triggers[len(lengths) % len(triggers)]
        got = compiled.unwrapped.run_rule_interval(trigger, n_steps, 0.99)
        assert_same_loop(compiled, stepwise, got, rule_stepped(stepwise, trigger, n_steps, 0.99))
        lengths.append(got[5])
    assert got[3] and len(lengths) > 2

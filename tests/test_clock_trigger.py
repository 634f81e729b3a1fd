"""The compiled clock: :class:`ClockTrigger` takes :class:`PeriodicPolicy`'s decisions.

Checked properties (every id, Gymnasium and PettingZoo):

* instant for instant, the clock rule on the episode's observations transmits exactly where
  the counter-based :class:`PeriodicPolicy` does (instants 0, K, 2K, ...), so the records of
  the two through the per-instant loop are equal bit for bit;
* the batch path, which runs the clock inside the compiled loop, gives the records of
  :class:`PeriodicPolicy` stepped one instant at a time, a scenario that fails early included;
* ``--policy periodic`` builds the compiled clock where the receiver takes every transmission
  (paper 003's, which refuses one during a burst, keeps the counter); bad periods, sampling
  periods, policy arguments and observation layouts are refused naming the argument.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from test_batch import SEEDS, SHORT_HORIZONS, assert_same_record

from etsc_envs.evaluation.batch import run_batch
from etsc_envs.evaluation.policy_specs import episode_setup
from etsc_envs.triggers import ClockTrigger, PeriodicPolicy

EVERY = 7
ASTEROID = "etsc/AsteroidOrbitKeeping-v0"
CLOCK_IDS = sorted(set(SHORT_HORIZONS) - {ASTEROID})
"""The ids whose receiver takes every transmission (paper 003's refuses one during a burst)."""


def periodic_reference(setup: Any, every: int) -> PeriodicPolicy:
    observation_space, action_space, _ = setup.policy_spaces()
    return PeriodicPolicy(observation_space, action_space, every=every)


def per_instant_records(env_id: str, every: int, env_args: dict[str, Any]) -> list[Any]:
    setup = episode_setup(env_id, env_args)
    policy = periodic_reference(setup, every)
    records = [setup.run(setup.env, policy, seed)[0] for seed in SEEDS]
    setup.env.close()
    return records


@pytest.mark.parametrize("env_id", CLOCK_IDS)
def test_clock_rule_transmits_where_the_counter_does(env_id: str) -> None:
    env_args = {"randomize": True, "horizon_s": SHORT_HORIZONS[env_id]}
    setup = episode_setup(env_id, env_args)
    clock = setup.make_policy("periodic", {"every": EVERY})
    assert isinstance(clock, ClockTrigger)
    reference = periodic_reference(setup, EVERY)
    clock_record, clock_trace = setup.run(setup.env, clock, SEEDS[0])
    counter_record, counter_trace = setup.run(setup.env, reference, SEEDS[0])
    setup.env.close()
    assert_same_record(counter_record, clock_record)
    assert clock_record["transmissions"] > 0
    assert_same_record(counter_trace.transmission_times_s, clock_trace.transmission_times_s)
    sent = [np.ravel(action).tolist() for action in clock_trace.transmission_actions]
    assert sent == [np.ravel(action).tolist() for action in counter_trace.transmission_actions]


@pytest.mark.parametrize("env_id", CLOCK_IDS)
def test_compiled_clock_gives_the_records_of_the_counter(env_id: str) -> None:
    env_args = {"randomize": True, "horizon_s": SHORT_HORIZONS[env_id]}
    single = per_instant_records(env_id, EVERY, env_args)
    setup = episode_setup(env_id, env_args)
    clock = setup.make_policy("periodic", {"every": EVERY})
    setup.env.close()
    batch = run_batch(env_id, clock, SEEDS, env_args)
    for one, other in zip(single, batch, strict=True):
        assert_same_record(one, other)


def test_compiled_clock_keeps_a_scenario_that_fails_early() -> None:
    env_id = "etsc/AttitudeTracking-v0"
    env_args = {"randomize": True, "horizon_s": 2.0, "max_rate_rad_s": 0.4}
    single = per_instant_records(env_id, 400, env_args)
    assert all(record["failure"] is not None for record in single), "a slow clock must fail"
    assert len({record["steps"] for record in single}) == len(SEEDS), "they fail apart"
    setup = episode_setup(env_id, env_args)
    clock = setup.make_policy("periodic", {"every": 400})
    setup.env.close()
    for one, other in zip(single, run_batch(env_id, clock, SEEDS, env_args), strict=True):
        assert_same_record(one, other)


def test_a_receiver_that_refuses_transmissions_keeps_the_counter() -> None:
    """On paper 003 a burst in progress refuses a transmission, so the time since the last
    burst does not count the clock's instants: ``periodic`` stays the counter-based policy."""
    setup = episode_setup(ASTEROID, {"horizon_s": 500.0})
    policy = setup.make_policy("periodic", {"every": EVERY})
    setup.env.close()
    assert type(policy) is PeriodicPolicy


@pytest.fixture
def formation() -> gym.Env:
    environment = gym.make("etsc/InnerFormation-v0", horizon_s=0.1)
    yield environment
    environment.close()


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        ({"every": 0}, "every must be an integer >= 1"),
        ({"every": 2.5}, "every must be an integer >= 1"),
        ({"every": True}, "every must be an integer >= 1"),
        ({"every": 3, "sampling_period_s": 0.0}, "sampling_period_s must be a finite number > 0"),
        ({"every": 3, "sampling_period_s": float("nan")}, "sampling_period_s must be"),
    ],
)
def test_bad_clock_arguments_name_themselves(
    formation: gym.Env, keywords: dict[str, Any], message: str
) -> None:
    names = formation.unwrapped.observation_names
    with pytest.raises(ValueError, match=message):
        ClockTrigger(formation.observation_space, formation.action_space, names, **keywords)


def test_a_clock_needs_one_time_since_transmission_per_channel(formation: gym.Env) -> None:
    names = tuple(name for name in formation.unwrapped.observation_names if not name.endswith("_2"))
    with pytest.raises(ValueError, match="one time_since_transmission_s\\* per channel"):
        ClockTrigger(formation.observation_space, formation.action_space, names, every=3)


def test_the_clock_reads_only_the_times_since_transmission(formation: gym.Env) -> None:
    """A batch of observations whose other entries are noise: the decisions follow the times."""
    names = formation.unwrapped.observation_names
    clock = ClockTrigger(
        formation.observation_space, formation.action_space, names, every=4, sampling_period_s=0.5
    )
    rng = np.random.default_rng(0)
    observations = rng.normal(size=(6, len(names))).astype(np.float32)
    times = [index for index, name in enumerate(names) if name.startswith("time_since")]
    elapsed = np.array([0.0, 0.5, 1.5, 1.75, 2.0, 3.0], dtype=np.float32)
    observations[:, times] = elapsed[:, None]
    actions, _ = clock.predict(observations)
    expected = np.array([1, 0, 0, 1, 1, 1])
    assert actions.tolist() == np.repeat(expected[:, None], 3, axis=1).tolist()


def test_periodic_takes_only_its_period() -> None:
    setup = episode_setup("etsc/AttitudeTracking-v0", {"horizon_s": 0.1})
    with pytest.raises(ValueError, match="periodic takes every=K"):
        setup.make_policy("periodic", {"every": 3, "sampling_period_s": 0.5})
    setup.env.close()

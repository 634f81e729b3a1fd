"""``settled``: each env's own criterion of a settled loop at the horizon (docs/protocol.md)."""

from __future__ import annotations

import gymnasium as gym
import pytest

import etsc_envs  # noqa: F401  (registers the ids)
from etsc_envs.cluster.env import SETTLED_HULL_DISTANCE
from etsc_envs.inner_formation.env import SETTLED_OFFSET_FRACTION


def unwrapped(env_id: str, **kwargs):
    return gym.make(env_id, **kwargs).unwrapped


@pytest.mark.parametrize(
    ("omega_converge_time_s", "final_hull_distance", "settled"),
    [
        (600.0, 0.5 * SETTLED_HULL_DISTANCE, True),
        (600.0, 2.0 * SETTLED_HULL_DISTANCE, False),
        (None, 0.5 * SETTLED_HULL_DISTANCE, False),
    ],
)
def test_the_cluster_settles_when_rates_converge_near_the_hull(
    omega_converge_time_s, final_hull_distance, settled
) -> None:
    env = unwrapped("etsc/ClusterContainmentCentral-v0")
    metrics = {
        "omega_converge_time_s": omega_converge_time_s,
        "final_hull_distance": final_hull_distance,
        "converge_time_s": None,
    }
    assert env._settled_at_end(metrics) is settled


def test_the_inner_mass_settles_within_a_tenth_of_the_cavity() -> None:
    env = unwrapped("etsc/InnerFormation-v0")
    band = SETTLED_OFFSET_FRACTION * env.params.cavity_radius_m
    assert env._settled_at_end({"ss_pos_err_m": 0.9 * band})
    assert not env._settled_at_end({"ss_pos_err_m": 1.1 * band})


def test_orbit_attitude_settles_only_with_both_settling_times() -> None:
    env = unwrapped("etsc/OrbitAttitudeTracking-v0")
    assert env._settled_at_end({"settle_att_s": 80.0, "settle_pos_s": 150.0})
    assert not env._settled_at_end({"settle_att_s": 80.0, "settle_pos_s": None})


def test_a_failed_or_unfinished_episode_is_not_settled() -> None:
    env = gym.make("etsc/AttitudeTracking-v0", horizon_s=2.0, max_rate_rad_s=0.4)
    env.reset(seed=0)
    assert env.unwrapped.episode_metrics()["settled"] is False, "not at the horizon yet"
    while True:
        _, _, terminated, truncated, info = env.step(0)
        if terminated or truncated:
            break
    assert terminated and info["failure"] is not None
    assert info["episode_metrics"]["settled"] is False


def test_the_paper_scenario_of_paper_002_settles_with_every_sample_sent() -> None:
    env = gym.make("etsc/AttitudeTracking-v0", horizon_s=20.0)
    env.reset(seed=0)
    while True:
        _, _, terminated, truncated, info = env.step(1)
        if terminated or truncated:
            break
    assert truncated and info["episode_metrics"]["settled"] is True

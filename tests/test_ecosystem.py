"""The environments as the ecosystem's own tools expect them.

Checked properties:

* every env (each Gymnasium id, its native vector env, the PettingZoo env made by
  ``pettingzoo.make`` in both forms) passes the Gymnasium, Stable-Baselines3 and PettingZoo
  checkers with every warning turned into an error (finite observation bounds, render modes);
* ``pettingzoo.make("parallel" | "aec", id)`` builds the cluster from PettingZoo's registry and
  honours ``max_cycles``, whose truncation carries ``episode_metrics``;
* ``render_mode="rgb_array"`` draws a frame that changes as the episode runs (the accuracy cost
  and the transmission instants so far), on single, vector and PettingZoo envs alike; an unknown
  render mode is a ValueError naming the argument;
* each env's docstring and signature list the keywords of its parameter dataclass.
"""

from __future__ import annotations

import dataclasses
import inspect
import warnings

import gymnasium as gym
import numpy as np
import pettingzoo
import pytest
from gymnasium.utils.env_checker import check_env as gymnasium_check_env
from pettingzoo.test import api_test, parallel_api_test
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import etsc_envs
from etsc_envs.asteroid.params import AsteroidParams
from etsc_envs.attitude_tracking.params import AttitudeTrackingParams
from etsc_envs.cluster.parallel_env import ClusterContainmentEnv
from etsc_envs.cluster.params import ClusterContainmentParams
from etsc_envs.core.keywords import field_docs
from etsc_envs.inner_formation.env import InnerFormationEnv
from etsc_envs.inner_formation.params import InnerFormationParams
from etsc_envs.orbit_attitude.params import OrbitAttitudeParams

CLUSTER_ID = "etsc/ClusterContainment-v0"
SHORT = {"horizon_s": 1.0}


def short(env_id: str) -> dict[str, float]:
    """A short horizon for ``env_id`` (the asteroid's is at least one 50-s burst)."""
    return {"horizon_s": 50.0} if env_id == "etsc/AsteroidOrbitKeeping-v0" else SHORT


PARAMS_OF = {
    "etsc/AttitudeTracking-v0": AttitudeTrackingParams,
    "etsc/OrbitAttitudeTracking-v0": OrbitAttitudeParams,
    "etsc/ClusterContainmentCentral-v0": ClusterContainmentParams,
    "etsc/InnerFormation-v0": InnerFormationParams,
    "etsc/AsteroidOrbitKeeping-v0": AsteroidParams,
}


@pytest.fixture(autouse=True)
def warnings_are_errors():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


@pytest.mark.parametrize("env_id", sorted(etsc_envs.ENV_IDS))
def test_gymnasium_and_sb3_checkers_pass_without_a_warning(env_id):
    # Gymnasium's checker also makes the env in every declared render mode; "human" without a
    # display says in one warning that it shows nothing (etsc_envs.core.render.HumanWindow),
    # the one warning allowed here.
    warnings.filterwarnings("ignore", message=r".*render_mode='human' needs an interactive")
    env = gym.make(env_id, render_mode="rgb_array", **short(env_id)).unwrapped
    assert np.all(np.isfinite(env.observation_space.low))
    assert np.all(np.isfinite(env.observation_space.high))
    gymnasium_check_env(env)
    sb3_check_env(env, warn=True)
    env.close()


def test_pettingzoo_checkers_pass_on_envs_made_by_pettingzoo_make():
    # The checkers reset with options={"options": 1}; the env drops that unknown key with a
    # warning naming it (etsc_envs.core.multi_agent), the one warning allowed here.
    warnings.filterwarnings("ignore", message=r"options: unknown key\(s\) \['options'\]")
    parallel_api_test(pettingzoo.make("parallel", CLUSTER_ID, scenario="pi1"), num_cycles=20)
    api_test(pettingzoo.make("aec", CLUSTER_ID, render_mode="rgb_array"), num_cycles=5)


def test_pettingzoo_make_honours_max_cycles_with_episode_metrics():
    env = pettingzoo.make("parallel", CLUSTER_ID, max_cycles=3)
    env.reset(seed=0)
    for cycle in range(3):
        _, _, terminated, truncated, infos = env.step(dict.fromkeys(env.agents, 1))
        assert not any(terminated.values())
        assert all(truncated.values()) == (cycle == 2)
    assert env.agents == []
    metrics = infos["follower_0"]["episode_metrics"]
    assert metrics["transmissions"] == 3 * len(env.possible_agents)
    aec = pettingzoo.make("aec", CLUSTER_ID, max_cycles=2)
    aec.reset(seed=0)
    steps = 0
    for _ in aec.agent_iter():
        *_, terminated, truncated, _ = aec.last()
        aec.step(None if terminated or truncated else 0)
        steps += 1
    assert steps == 3 * len(aec.possible_agents)  # two cycles, then every agent's last()
    with pytest.raises(ValueError, match="max_cycles"):
        pettingzoo.make("parallel", CLUSTER_ID, max_cycles=0)


def frames_of_a_short_episode(env, step):
    """The frame after 10 and after 60 steps of ``step``."""
    frames = []
    for count in range(60):
        step(count)
        if count in (9, 59):
            frame = env.render()
            frames.append(frame[0] if isinstance(frame, tuple) else frame)
    return frames


@pytest.mark.parametrize("env_id", sorted(etsc_envs.ENV_IDS))
def test_rgb_array_frames_show_the_episode_so_far(env_id):
    env = gym.make(env_id, render_mode="rgb_array", **short(env_id))
    env.reset(seed=0)
    early, late = frames_of_a_short_episode(env, lambda k: env.step(env.action_space.sample()))
    assert early.dtype == np.uint8 and early.ndim == 3 and early.shape[2] == 3
    assert early.std() > 0  # not a blank canvas
    assert not np.array_equal(early, late)  # the curves grew


def test_vector_and_pettingzoo_envs_render_frames_too():
    envs = gym.make_vec(
        "etsc/AttitudeTracking-v0",
        num_envs=2,
        vectorization_mode="vector_entry_point",
        render_mode="rgb_array",
        **SHORT,
    )
    envs.reset(seed=0)
    frames = envs.render()
    assert len(frames) == 2
    early, late = frames_of_a_short_episode(envs, lambda k: envs.step(np.ones(2, dtype=int)))
    assert not np.array_equal(early, late)
    parallel = pettingzoo.make("parallel", CLUSTER_ID, render_mode="rgb_array")
    parallel.reset(seed=0)
    early, late = frames_of_a_short_episode(
        parallel, lambda k: parallel.step(dict.fromkeys(parallel.agents, k % 2))
    )
    assert early.shape == late.shape and not np.array_equal(early, late)


def test_no_render_mode_renders_nothing_and_unknown_modes_are_refused():
    env = gym.make("etsc/AttitudeTracking-v0", disable_env_checker=True).unwrapped
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert env.render() is None
    with pytest.raises(ValueError, match="render_mode must be one of"):
        InnerFormationEnv(render_mode="ansi")


@pytest.mark.parametrize("env_id", sorted(PARAMS_OF))
def test_docstring_and_signature_list_the_parameter_keywords(env_id):
    env_class = type(gym.make(env_id, disable_env_checker=True).unwrapped)
    fields = [field.name for field in dataclasses.fields(PARAMS_OF[env_id])]
    parameters = inspect.signature(env_class).parameters
    docs = field_docs(PARAMS_OF[env_id])
    for name in fields:
        assert name in parameters
        assert f"    {name} (" in env_class.__doc__
    assert "render_mode" in parameters
    assert not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters.values())
    assert docs["horizon_s"] and docs["horizon_s"].split()[0] in env_class.__doc__
    cluster_parameters = inspect.signature(ClusterContainmentEnv).parameters
    assert {"scenario", "max_cycles", "render_mode"} <= set(cluster_parameters)

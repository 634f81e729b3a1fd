"""Native vector environments against the single environments and Gymnasium's SyncVectorEnv.

Every id with a ``vector_entry_point`` is checked: sub-environment 0 reset with seed ``s``
follows the single environment reset with seed ``s`` step for step, and the whole batch equals
``SyncVectorEnv`` over the single environments (observations, rewards, terminations,
truncations, autoresets, final observations) in both autoreset modes.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode
from numpy.testing import assert_array_equal

from etsc_envs import VECTOR_ENTRY_POINTS

SHORT_EPISODE = {
    "etsc/AttitudeTracking-v0": {"horizon_s": 0.02},
    "etsc/InnerFormation-v0": {"horizon_s": 0.02},
    "etsc/OrbitAttitudeTracking-v0": {"horizon_s": 0.02},
    "etsc/ClusterContainmentCentral-v0": {"horizon_s": 0.2},
    "etsc/AsteroidOrbitKeeping-v0": {"horizon_s": 5.0, "burst_duration_s": 2.0},
}
"""Kwargs that make an episode about 20 steps long, so that tests cross an autoreset."""

VECTOR_IDS = sorted(VECTOR_ENTRY_POINTS)


def short_kwargs(env_id: str) -> dict:
    return {"randomize": True, **SHORT_EPISODE[env_id]}


def random_actions(space: gym.Space, n_steps: int, seed: int) -> list:
    space.seed(seed)
    return [space.sample() for _ in range(n_steps)]


def make_native(env_id: str, num_envs: int, **kwargs) -> gym.vector.VectorEnv:
    return gym.make_vec(
        env_id, num_envs=num_envs, vectorization_mode="vector_entry_point", **kwargs
    )


def test_every_single_env_id_has_a_native_vector_env():
    import etsc_envs

    assert set(VECTOR_ENTRY_POINTS) == set(etsc_envs.ENV_IDS)
    for env_id, entry_point in VECTOR_ENTRY_POINTS.items():
        assert gym.spec(env_id).vector_entry_point == entry_point


@pytest.mark.parametrize("env_id", VECTOR_IDS)
def test_sub_env_zero_follows_the_single_env_step_for_step(env_id):
    kwargs = short_kwargs(env_id)
    single = gym.make(env_id, **kwargs)
    vector = make_native(env_id, 3, **kwargs)
    seed = 11
    single_obs, _ = single.reset(seed=seed)
    vector_obs, _ = vector.reset(seed=seed)
    assert_array_equal(vector_obs[0], single_obs)
    ended_at = None
    for step, actions in enumerate(random_actions(vector.action_space, 60, seed=5)):
        single_obs, reward, terminated, truncated, info = single.step(actions[0])
        vector_obs, rewards, terminations, truncations, infos = vector.step(actions)
        assert_array_equal(vector_obs[0], single_obs, err_msg=f"step {step}")
        assert rewards[0] == reward, f"step {step}"
        assert (terminations[0], truncations[0]) == (terminated, truncated)
        assert infos["transmissions"][0] == info["transmissions"]
        if terminated or truncated:
            ended_at = step
            assert infos["_episode_metrics"][0]
            assert infos["episode_metrics"]["mean_cost"][0] == info["episode_metrics"]["mean_cost"]
            break
    assert ended_at is not None, "the short episode should end within 60 steps"
    single.close()
    vector.close()


@pytest.mark.parametrize("autoreset_mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
@pytest.mark.parametrize("env_id", VECTOR_IDS)
def test_native_vector_env_equals_sync_vector_env(env_id, autoreset_mode):
    kwargs = short_kwargs(env_id)
    num_envs = 4
    native = make_native(env_id, num_envs, autoreset_mode=autoreset_mode, **kwargs)
    sync = gym.make_vec(
        env_id,
        num_envs=num_envs,
        vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": autoreset_mode},
        **kwargs,
    )
    assert native.single_observation_space == sync.single_observation_space
    assert native.single_action_space == sync.single_action_space
    assert native.observation_space == sync.observation_space
    native_obs, _ = native.reset(seed=3)
    sync_obs, _ = sync.reset(seed=3)
    assert_array_equal(native_obs, sync_obs)
    episodes_ended = 0
    for step, actions in enumerate(random_actions(native.action_space, 70, seed=2)):
        native_out = native.step(actions)
        sync_out = sync.step(actions)
        for name, a, b in zip(
            ("observations", "rewards", "terminations", "truncations"),
            native_out[:4],
            sync_out[:4],
            strict=True,
        ):
            assert_array_equal(a, b, err_msg=f"{name} at step {step}")
        native_info, sync_info = native_out[4], sync_out[4]
        assert_array_equal(native_info["transmissions"], sync_info["transmissions"])
        if autoreset_mode == AutoresetMode.SAME_STEP and "final_obs" in sync_info:
            ended = sync_info["_final_obs"]
            assert_array_equal(native_info["_final_obs"], ended)
            for index in np.flatnonzero(ended):
                assert_array_equal(native_info["final_obs"][index], sync_info["final_obs"][index])
        episodes_ended += int(np.sum(native_out[2] | native_out[3]))
    assert episodes_ended >= num_envs, "every sub-environment should finish an episode"
    native.close()
    sync.close()


def test_reset_mask_resets_only_the_chosen_sub_envs():
    env_id = VECTOR_IDS[0]
    vector = make_native(env_id, 3, **short_kwargs(env_id))
    vector.reset(seed=0)
    for _ in range(3):
        vector.step(np.ones(vector.action_space.shape, dtype=np.int64))
    before = vector.unwrapped.arrays.step_index.copy()
    observations, infos = vector.reset(options={"reset_mask": np.array([False, True, False])})
    assert_array_equal(vector.unwrapped.arrays.step_index, [before[0], 0, before[2]])
    assert_array_equal(infos["_transmissions"], [False, True, False])
    assert observations.shape == vector.observation_space.shape


@pytest.mark.parametrize("env_id", VECTOR_IDS)
def test_step_rows_steps_the_chosen_rows_as_their_single_envs(env_id):
    """step_rows moves only the masked rows, each exactly as its single env's step; the other
    rows keep their state; a row whose episode ended is refused by name."""
    kwargs = short_kwargs(env_id)
    vector = make_native(env_id, 3, **kwargs).unwrapped
    singles = [gym.make(env_id, **kwargs) for _ in range(3)]
    vector.reset(seed=[4, 5, 6])
    for index, single in enumerate(singles):
        single.reset(seed=4 + index)
    masks = [np.array(mask) for mask in ([True, False, True], [False, True, False], [True] * 3)]
    ended = np.zeros(3, dtype=bool)
    for step, actions in enumerate(random_actions(vector.action_space, 60, seed=8)):
        rows = masks[step % 3] & ~ended
        if not rows.any():
            break
        held = vector.arrays.observation[~rows].copy()
        observations, rewards, terminated, truncated = vector.step_rows(actions, rows)
        assert_array_equal(observations[~rows], held, err_msg=f"held rows at step {step}")
        assert not (terminated | truncated)[~rows].any() and not rewards[~rows].any()
        for index in np.flatnonzero(rows):
            single_obs, reward, single_term, single_trunc, _ = singles[index].step(actions[index])
            assert_array_equal(observations[index], single_obs, err_msg=f"step {step}")
            assert rewards[index] == reward, f"step {step}"
            assert (terminated[index], truncated[index]) == (single_term, single_trunc)
        ended |= terminated | truncated
    assert ended.any(), "a short episode should end within 60 steps"
    with pytest.raises(RuntimeError, match=rf"sub-environments \[{np.flatnonzero(ended)[0]}"):
        vector.step_rows(np.zeros(vector.action_space.shape, dtype=np.int64), ended)
    vector.close()
    for single in singles:
        single.close()


def test_disabled_autoreset_refuses_to_step_a_finished_sub_env():
    env_id = "etsc/AttitudeTracking-v0"
    vector = make_native(env_id, 2, autoreset_mode="disabled", horizon_s=0.002)
    vector.reset(seed=0)
    vector.step(np.zeros(2, dtype=np.int64))
    _, _, _, truncations, _ = vector.step(np.zeros(2, dtype=np.int64))
    assert truncations.all()
    with pytest.raises(RuntimeError, match="reset them first"):
        vector.step(np.zeros(2, dtype=np.int64))
    vector.reset(options={"reset_mask": np.array([True, True])})
    vector.step(np.zeros(2, dtype=np.int64))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"num_envs": 0}, "num_envs must be an integer >= 1"),
        ({"num_envs": 2, "autoreset_mode": "sometimes"}, "autoreset_mode must be one of"),
    ],
)
def test_bad_vector_arguments_name_the_argument(kwargs, message):
    from etsc_envs.attitude_tracking.env import AttitudeTrackingVectorEnv

    with pytest.raises(ValueError, match=message):
        AttitudeTrackingVectorEnv(**kwargs)


def test_a_vector_env_refused_by_its_constructor_closes_quietly():
    """``__del__`` closes the half-made object a refused constructor leaves: no thread pool
    or sub-environment exists yet, and closing must not raise."""
    from etsc_envs.attitude_tracking.env import AttitudeTrackingVectorEnv

    half_made = AttitudeTrackingVectorEnv.__new__(AttitudeTrackingVectorEnv)
    half_made.close()
    assert half_made.closed


@pytest.mark.parametrize("actions", [np.array([0, 2]), np.array([1, 0, 1]), np.ones((2, 2))])
def test_bad_actions_name_the_allowed_shape_and_values(actions):
    vector = make_native("etsc/AttitudeTracking-v0", 2)
    vector.reset(seed=0)
    with pytest.raises(ValueError, match=r"actions must be an array of shape \(2,\)"):
        vector.step(actions)


def test_bad_seed_list_is_a_clear_error():
    vector = make_native("etsc/AttitudeTracking-v0", 2)
    with pytest.raises(ValueError, match="one per sub-environment"):
        vector.reset(seed=[1, 2, 3])


def test_threads_step_disjoint_rows_like_one_thread():
    """A batch big enough to be split over threads gives what its rows give one by one."""
    env_id = "etsc/AttitudeTracking-v0"
    kwargs = short_kwargs(env_id)
    big = make_native(env_id, 32, **kwargs)
    assert len(big.unwrapped._chunks) >= 1
    big_obs, _ = big.reset(seed=7)
    small = [make_native(env_id, 1, **kwargs) for _ in range(32)]
    rows = [env.reset(seed=7 + index)[0][0] for index, env in enumerate(small)]
    assert_array_equal(big_obs, np.stack(rows))
    for actions in random_actions(big.action_space, 10, seed=1):
        big_obs, big_rewards, *_ = big.step(actions)
        for index, env in enumerate(small):
            obs, rewards, *_ = env.step(actions[index : index + 1])
            assert_array_equal(big_obs[index], obs[0])
            assert big_rewards[index] == rewards[0]

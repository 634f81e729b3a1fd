"""``etsc/ClusterContainment-v0`` and ``etsc/ClusterContainmentCentral-v0`` (paper 001).

Checked properties:

* API: PettingZoo's ``parallel_api_test`` and ``api_test`` (AEC form of the module
  ``etsc_envs.cluster_containment_v0``), the Gymnasium and Stable-Baselines3 checkers on the
  central env, ``make_parallel`` / ``make_aec`` and the id tables of ``etsc_envs``;
* reproducibility: a seeded multi-step episode (randomized, random actions) repeats exactly,
  after a reset too, and another seed differs; randomized draws stay in the documented ranges;
* one model, two interfaces: for the same actions the parallel env's observations are the
  central env's blocks and its per-agent rewards sum to the central reward;
* graph theory: -L_F⁻¹ L_FL is row-stochastic and non-negative (Lemma 1) with c_ij > 0
  exactly when leader j reaches follower i (Theorem 3) on random reachable digraphs; an
  unreachable follower is a ValueError (Assumption 3); the Figure 2 substitute satisfies the
  properties its docstring claims and the Figure 5 substitute has the π1 cells of section 5.2;
* physics: a cluster on a random reachable digraph converges to σ_d = -L_F⁻¹ L_FL σ_L (eq. 8),
  computed here independently; the MRP kinematics of the plant match the core's quaternion
  kinematics along a tumbling trajectory; the regressor reproduces M σ̈ + C σ̇ of the rigid
  body (eqs. 5, 13); the adaptation laws (20)-(21) and the held control (16), (19) act as
  written; the paper's scenario converges under the paper's trigger with sparse events;
* the observation is the named view of the loop (eq. 14-15 terms, containment error, held u,
  clocks); rewards, infos and episode metrics (with per-agent values) follow their definitions;
* the paper's trigger eq. (15) fires exactly at its threshold, for one agent and centrally;
* bad arguments and actions raise errors naming them; a failure terminates every agent;
* commands: ``evaluate`` (function and command line) reports per-agent values for the
  PettingZoo id; the reproduction report carries the paper's numbers; the distance to the
  leaders' hull (Definition 4) is right on hand-computed cases.
"""

from __future__ import annotations

import itertools
import json
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gymnasium_check_env
from numpy.testing import assert_allclose, assert_array_equal
from pettingzoo.test import api_test, parallel_api_test

import etsc_envs
from baselines.evaluate import evaluate
from baselines.reproductions import cluster as reproduction
from etsc_envs import cluster_containment_v0
from etsc_envs.cluster.closed_loop import integrate_loop
from etsc_envs.cluster.controller import regressor
from etsc_envs.cluster.dynamics import attitude_rate
from etsc_envs.cluster.env import FEATURE_NAMES, cluster_model
from etsc_envs.cluster.params import (
    FIGURE_2_EDGES,
    FIGURE_5_CELLS,
    TABLE_1_ATTITUDES,
    TABLE_1_RATES,
    ClusterContainmentParams,
)
from etsc_envs.cluster.topology import (
    adjacency_from_edges,
    containment_weights,
    hull_distance,
    is_pi1_partition,
    reachable_from,
    validate_adjacency,
)
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.metrics import COMMON_EPISODE_KEYS
from etsc_envs.core.rotations import quat_kinematics, quat_to_mrp
from etsc_envs.papers import paper_of
from etsc_envs.triggers import ClusterContainmentTrigger

PARALLEL_ID = "etsc/ClusterContainment-v0"
CENTRAL_ID = "etsc/ClusterContainmentCentral-v0"
PERIOD_S = 0.01
N_PAPER = 6
AGENTS = [f"follower_{i}" for i in range(N_PAPER)]
COMMON_METRIC_KEYS = set(COMMON_EPISODE_KEYS) | {
    "converge_time_s",
    "omega_converge_time_s",
    "final_containment_err",
    "agents",
}
AGENT_METRIC_KEYS = {
    "transmissions",
    "transmission_rate",
    "mean_interevent_s",
    "min_interevent_s",
    "final_sigma",
    "target_sigma",
}


# --------------------------------------------------------------------------- helpers
def parallel(**kwargs):
    return cluster_containment_v0.parallel_env(**kwargs)


API_TEST_OPTIONS_NOTE = "options: unknown key(s) ['options'] ignored"
"""The env's warning about the made-up reset option PettingZoo's API tests pass."""


def only_infinite_bound_warnings(caught: list[warnings.WarningMessage]) -> list[str]:
    """Messages of caught warnings other than the checkers' notes about infinite Box bounds
    and the env's note about the API tests' made-up reset option."""
    return [
        str(w.message)
        for w in caught
        if "infinity" not in str(w.message) and API_TEST_OPTIONS_NOTE not in str(w.message)
    ]


def random_reachable_digraph(rng: np.random.Generator, n: int, m: int) -> np.ndarray:
    """Random weighted digraph, followers 0..n-1 then leaders, every follower reached."""
    adjacency = np.zeros((n + m, n + m))
    for i in range(n):
        senders = rng.choice([j for j in range(n + m) if j != i], size=2, replace=False)
        adjacency[i, senders] = rng.uniform(0.5, 2.0, size=2)
    order = rng.permutation(n)  # a chain from a leader through all followers guarantees reach
    adjacency[order[0], n + rng.integers(m)] = 1.0
    for previous, follower in itertools.pairwise(order):
        adjacency[follower, previous] = max(adjacency[follower, previous], 0.7)
    return adjacency


def independent_targets(adjacency: np.ndarray, leaders: np.ndarray) -> np.ndarray:
    """Eq. (8) written out here: L = diag(A 1) - A, σ_d = -L_F⁻¹ L_FL σ_L."""
    n = adjacency.shape[0] - len(leaders)
    laplacian = np.diag(adjacency.sum(axis=1)) - adjacency
    return -np.linalg.inv(laplacian[:n, :n]) @ laplacian[:n, n:] @ leaders


def rollout(env, seed: int, actions: np.ndarray):
    """Observations, rewards and infos of a parallel episode driven by ``actions`` (T × N)."""
    obs, _ = env.reset(seed=seed)
    record = [obs]
    for row in actions:
        obs, rewards, _, _, infos = env.step(dict(zip(env.possible_agents, row, strict=True)))
        record.append((obs, rewards, {a: infos[a]["cost"] for a in infos}))
    return record


def assert_same_rollout(first, second) -> None:
    for a, b in zip(first, second, strict=True):
        if isinstance(a, dict):
            for agent in a:
                assert_array_equal(a[agent], b[agent])
            continue
        for part_a, part_b in zip(a, b, strict=True):
            for agent in part_a:
                assert_array_equal(part_a[agent], part_b[agent])


# --------------------------------------------------------------------------- API
def test_parallel_api_test():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        parallel_api_test(parallel(horizon_s=1.0), num_cycles=200)
    assert only_infinite_bound_warnings(caught) == []


def test_aec_api_test():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        api_test(cluster_containment_v0.env(horizon_s=1.0, scenario="pi1"), num_cycles=200)
    assert only_infinite_bound_warnings(caught) == []


def test_raw_env_is_the_unwrapped_aec_form():
    raw = cluster_containment_v0.raw_env(horizon_s=0.05)
    raw.reset(seed=0)
    assert raw.possible_agents == AGENTS
    assert isinstance(raw.unwrapped, cluster_containment_v0.ClusterContainmentEnv)


def test_central_env_passes_gymnasium_and_sb3_checkers():
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make(CENTRAL_ID, horizon_s=0.1, randomize=True)
    assert env.action_space == gym.spaces.MultiBinary(N_PAPER)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gymnasium_check_env(env.unwrapped, skip_render_check=True)
        sb3_check_env(env.unwrapped, warn=True)
    assert only_infinite_bound_warnings(caught) == []


def test_ids_and_make_helpers():
    assert CENTRAL_ID in etsc_envs.ENV_IDS
    assert etsc_envs.PETTINGZOO_ENV_IDS[PARALLEL_ID] == "etsc_envs.cluster_containment_v0"
    env = etsc_envs.make_parallel(PARALLEL_ID, scenario="pi1", horizon_s=0.05)
    assert len(env.possible_agents) == 9
    aec = etsc_envs.make_aec(PARALLEL_ID, horizon_s=0.05)
    aec.reset(seed=0)
    assert aec.agent_selection == "follower_0"
    with pytest.raises(ValueError, match="unknown PettingZoo id"):
        etsc_envs.make_parallel("etsc/NoSuchEnv-v0")
    assert paper_of(PARALLEL_ID) is paper_of(CENTRAL_ID)
    assert paper_of(CENTRAL_ID).trigger is ClusterContainmentTrigger


# --------------------------------------------------------------------------- reproducibility
def test_seeded_multi_step_episode_repeats_exactly():
    actions = (np.random.default_rng(0).random((300, N_PAPER)) < 0.2).astype(int)
    first, second = parallel(randomize=True), parallel(randomize=True)
    reference = rollout(first, 11, actions)
    assert_same_rollout(rollout(second, 11, actions), reference)
    assert_same_rollout(rollout(first, 11, actions), reference)  # reset restores everything
    other, _ = second.reset(seed=12)
    assert not np.array_equal(other["follower_0"], reference[0]["follower_0"])


def test_randomized_draws_stay_in_documented_ranges():
    env = parallel(randomize=True, horizon_s=0.05)
    norms, rates, phases = [], [], []
    for seed in range(15):
        env.reset(seed=seed)
        state = env.state_dict()
        norms.append(np.linalg.norm(state["sigma"], axis=1))
        rates.append(state["omega"])
        phases.append(env.loop.model.disturbance_phase)
    norms, rates, phases = np.array(norms), np.array(rates), np.array(phases)
    assert norms.max() <= 0.6 and rates.__abs__().max() <= 0.015
    assert phases.min() >= 0.0 and phases.max() < 2 * np.pi
    assert norms.std() > 0.05 and rates.std() > 0.003 and phases.std() > 1.0


def test_default_reset_is_table_1():
    env = parallel(horizon_s=0.05)
    env.reset(seed=3)
    state = env.state_dict()
    assert_array_equal(state["sigma"], np.array(TABLE_1_ATTITUDES))
    assert_array_equal(state["omega"], np.array(TABLE_1_RATES))
    assert_array_equal(state["theta_hat"], np.tile([22.0, 26.0, 25.0, 0.0, 0.0, 0.0], (6, 1)))
    assert_array_equal(state["leaders"][2], [-0.08, 0.1, 0.09])


# --------------------------------------------------------------------------- two interfaces
def test_parallel_env_is_the_central_loop_split_by_agent():
    central = gym.make(CENTRAL_ID, horizon_s=0.5, randomize=True).unwrapped
    split = parallel(horizon_s=0.5, randomize=True)
    actions = (np.random.default_rng(4).random((50, N_PAPER)) < 0.3).astype(int)
    central_obs, _ = central.reset(seed=2)
    split_obs, _ = split.reset(seed=2)
    names = split.agent_observation_names
    for row in actions:
        for i, agent in enumerate(AGENTS):
            expected = [
                central_obs[central.observation_index(f"{name}_{i}")] for name in names[:-1]
            ] + [central_obs[central.observation_index(f"time_since_transmission_s_{i}")]]
            assert_array_equal(split_obs[agent], expected)
        central_obs, reward, _, _, info = central.step(row)
        split_obs, rewards, _, _, infos = split.step(dict(zip(AGENTS, row, strict=True)))
        assert_allclose(sum(rewards.values()), reward, rtol=1e-12)
        assert_allclose(sum(infos[a]["cost"] for a in AGENTS), info["cost"], rtol=1e-12)
        assert_array_equal(split.state(), central_obs)


# --------------------------------------------------------------------------- graph theory
@pytest.mark.parametrize("seed", range(5))
def test_containment_weights_are_lemma_1_and_theorem_3(seed):
    rng = np.random.default_rng(seed)
    n, m = 5, 3
    adjacency = random_reachable_digraph(rng, n, m)
    weights = containment_weights(validate_adjacency("adjacency", adjacency, n, m), n)
    assert np.all(weights >= -1e-12)
    assert_allclose(weights.sum(axis=1), 1.0, atol=1e-12)
    for j in range(m):
        reached = reachable_from(adjacency, n + j)
        for i in range(n):
            assert (weights[i, j] > 1e-12) == (i in reached), (i, j)


def test_unreachable_follower_is_rejected():
    # Followers 0-2, leaders 3-4: 0 hears leader 3, 1 hears 0, 2 hears nobody.
    adjacency = adjacency_from_edges(5, [(0, 3), (1, 0)])
    with pytest.raises(ValueError, match=r"adjacency violates Assumption 3: follower\(s\) \[2\]"):
        validate_adjacency("adjacency", adjacency, 3, 2)
    # 1 and 2 hear each other but no leader reaches their cycle.
    cycle_without_leader = adjacency_from_edges(5, [(0, 3), (1, 2), (2, 1)])
    with pytest.raises(ValueError, match=r"Assumption 3: follower\(s\) \[1, 2\]"):
        parallel(
            adjacency=cycle_without_leader,
            leader_attitudes=np.zeros((2, 3)),
            nominal_inertias=np.tile(np.eye(3) * 20, (3, 1, 1)),
            initial_attitudes=np.zeros((3, 3)),
            initial_rates=np.zeros((3, 3)),
            constant_disturbances=np.zeros((3, 3)),
        )


def test_figure_2_substitute_has_the_documented_structure():
    adjacency = ClusterContainmentParams().adjacency
    weights = containment_weights(adjacency, N_PAPER)
    follower_block, leader_block = adjacency[:N_PAPER, :N_PAPER], adjacency[:N_PAPER, N_PAPER:]
    assert np.all(leader_block.sum(axis=1) == 1.0)  # every follower hears one leader
    assert np.all(follower_block.sum(axis=1) == 1.0)  # ... and one follower
    assert np.all(weights > 0.0)  # every follower is reached by all three leaders
    assert all(0 in reachable_from(adjacency, i) for i in (0, 1, 2, 3))  # cycle 1→4→3→2→1
    assert len(FIGURE_2_EDGES) == int(adjacency.sum())


def test_figure_5_substitute_has_the_cells_of_section_5_2():
    params = ClusterContainmentParams(scenario="pi1")
    assert (params.n_followers, params.n_leaders) == (9, 3)
    assert is_pi1_partition(params.adjacency, FIGURE_5_CELLS)
    # A different grouping of the same graph is not a π1 partition.
    assert not is_pi1_partition(
        params.adjacency, [(9,), (10,), (11,), (0, 1, 2, 3), (4, 5, 6, 7), (8,)]
    )
    targets = independent_targets(params.adjacency, params.leader_attitudes)
    for cell in FIGURE_5_CELLS:
        followers = [i for i in cell if i < params.n_followers]
        assert_allclose(targets[followers], targets[followers[:1]].repeat(len(followers), 0))
    leaders = params.leader_attitudes
    assert_allclose(targets[0], leaders[0] / 2 + leaders[1] / 4 + leaders[2] / 4, atol=1e-14)
    assert_allclose(targets[2:6], np.tile(leaders.mean(axis=0), (4, 1)), atol=1e-14)
    assert_allclose(targets[8], (leaders[1] + leaders[2]) / 2, atol=1e-14)
    assert np.all(params.adjacency[2:4, 9:] == 1.0)  # 3 and 4 hear all three leaders


# --------------------------------------------------------------------------- physics
def test_cluster_on_random_digraph_converges_to_eq_8():
    """No disturbance, faster gains: the followers settle on -L_F⁻¹ L_FL σ_L (eq. 8)."""
    rng = np.random.default_rng(7)
    n, m = 4, 3
    adjacency = random_reachable_digraph(rng, n, m)
    leaders = rng.uniform(-0.15, 0.15, size=(m, 3))
    env = parallel(
        adjacency=adjacency,
        leader_attitudes=leaders,
        nominal_inertias=np.array(ClusterContainmentParams().nominal_inertias[:n]),
        initial_attitudes=rng.uniform(-0.3, 0.3, size=(n, 3)),
        initial_rates=np.zeros((n, 3)),
        constant_disturbances=np.zeros((n, 3)),
        alpha=0.3,
        control_gain=(40.0, 40.0, 40.0),
        horizon_s=120.0,
    )
    env.reset(seed=0)
    expected = independent_targets(adjacency, leaders)
    assert_allclose(env.state_dict()["targets"], expected, atol=1e-14)
    while env.agents:
        env.step(dict.fromkeys(env.agents, 1))
    final = env.state_dict()["sigma"]
    initial = np.linalg.norm(env.loop.params.initial_attitudes - expected, axis=1)
    assert np.all(initial > 0.05)
    assert np.abs(final - expected).max() < 1e-3 * initial.min()
    assert np.abs(env.state_dict()["omega"]).max() < 1e-5


@jit
def _rigid_body_with_quaternion(t, y, args):
    """q̇ = ½ q ⊗ [ω, 0] (core) and J ω̇ = -ω × J ω, y = [q, ω]."""
    inertia, inverse = args
    dy = np.empty(7)
    dy[0:4] = quat_kinematics(y[0:4], y[4:7])
    dy[4:7] = inverse @ -np.cross(y[4:7], inertia @ y[4:7])
    return dy


_quaternion_rk4 = make_rk4_step(_rigid_body_with_quaternion)


def test_mrp_plant_matches_quaternion_kinematics():
    """Torque-free tumbling (u = d = 0): σ(t) of the cluster's plant equals the MRP of the
    quaternion integrated with the core's kinematics."""
    params = ClusterContainmentParams(periodic_disturbance_fraction=0.0)
    model = cluster_model(params, np.zeros((N_PAPER, 4)))
    model = model._replace(constant_disturbance=np.zeros((N_PAPER, 3)))
    rng = np.random.default_rng(3)
    y = np.zeros((N_PAPER, 13))
    y[:, 0:3] = rng.uniform(-0.2, 0.2, size=(N_PAPER, 3))
    y[:, 3:6] = rng.uniform(-0.08, 0.08, size=(N_PAPER, 3))
    quaternions = []
    for i in range(N_PAPER):
        s2 = y[i, 0:3] @ y[i, 0:3]
        q = np.r_[2 * y[i, 0:3], 1 - s2] / (1 + s2)
        quaternions.append(np.r_[q, y[i, 3:6]])
    control = np.zeros((N_PAPER, 3))
    for k in range(1000):
        y = integrate_loop(k * 0.02, y, 0.02, (control, model))
        for i in range(N_PAPER):
            quaternions[i] = _quaternion_rk4(
                k * 0.02, quaternions[i], 0.02, (model.inertia[i], model.inertia_inverse[i])
            )
    for i in range(N_PAPER):
        assert_allclose(y[i, 0:3], quat_to_mrp(quaternions[i][0:4]), atol=1e-9)
        assert_allclose(y[i, 3:6], quaternions[i][4:7], atol=1e-11)
    assert np.abs(y[:, 0:3]).max() > 0.3  # the bodies did rotate far


def test_regressor_is_the_euler_lagrange_form_of_the_rigid_body():
    """Y(σ, σ̇, σ̇_r = σ̇, σ̈_r = σ̈) Θ = M σ̈ + C σ̇ = G⁻ᵀ (J ω̇ + ω × J ω) (eqs. 4, 5, 13)."""
    rng = np.random.default_rng(9)
    for _ in range(20):
        sigma = rng.uniform(-0.5, 0.5, 3)
        omega, omega_dot = rng.normal(size=3), rng.normal(size=3)
        a = rng.normal(size=(3, 3))
        inertia = a @ a.T + 3 * np.eye(3)
        theta = np.array(
            [
                inertia[0, 0],
                inertia[1, 1],
                inertia[2, 2],
                inertia[0, 1],
                inertia[0, 2],
                inertia[1, 2],
            ]
        )
        s2 = sigma @ sigma
        skew = np.array(
            [[0, -sigma[2], sigma[1]], [sigma[2], 0, -sigma[0]], [-sigma[1], sigma[0], 0]]
        )
        g = 0.25 * ((1 - s2) * np.eye(3) + 2 * skew + 2 * np.outer(sigma, sigma))
        sigma_dot = g @ omega
        g_dot = (g_of(sigma + 1e-6 * sigma_dot) - g_of(sigma - 1e-6 * sigma_dot)) / 2e-6
        sigma_ddot = g_dot @ omega + g @ omega_dot
        expected = np.linalg.solve(g.T, inertia @ omega_dot + np.cross(omega, inertia @ omega))
        y = np.array(regressor(sigma, omega, attitude_rate(sigma, omega), sigma_dot, sigma_ddot))
        assert_allclose(y @ theta, expected, rtol=1e-7, atol=1e-8)


def g_of(sigma: np.ndarray) -> np.ndarray:
    """G(σ) of eq. (2), written out here."""
    s2 = sigma @ sigma
    skew = np.array([[0, -sigma[2], sigma[1]], [sigma[2], 0, -sigma[0]], [-sigma[1], sigma[0], 0]])
    return 0.25 * ((1 - s2) * np.eye(3) + 2 * skew + 2 * np.outer(sigma, sigma))


def test_adaptation_laws_and_held_control_act_as_written():
    env = parallel(horizon_s=5.0, switching="saturation")
    env.reset(seed=0)
    params = env.params
    gain, lam = np.array(params.control_gain), np.array(params.adaptation_gain)
    delta, gamma = params.saturation_width, params.switching_gain_rate
    for k in range(200):
        before = env.state_dict()
        transmit = k % 25 == 0
        env.step(dict.fromkeys(AGENTS, int(transmit)))
        after = env.state_dict()
        if transmit:  # eq. (19) on the state at the event, saturated to ±1
            u = (
                -gain * before["s"]
                + before["y_theta"]
                - before["k_hat"][:, None] * np.clip(before["s"] / delta, -1, 1)
            )
            assert_allclose(after["u"], np.clip(u, -1, 1), rtol=1e-12, atol=1e-15)
        else:  # eq. (16): held between events
            assert_array_equal(after["u"], before["u"])
        # eqs. (20)-(21) by the trapezoidal rule over one period (RK4 inside the env)
        k_rate = gamma * 0.5 * (np.abs(before["s"]).sum(1) + np.abs(after["s"]).sum(1))
        assert_allclose(after["k_hat"] - before["k_hat"], k_rate * PERIOD_S, rtol=1e-3)
        theta_rate = (
            -0.5
            * lam
            * (
                np.einsum("nij,ni->nj", before["regressor"], before["s"])
                + np.einsum("nij,ni->nj", after["regressor"], after["s"])
            )
        )
        assert_allclose(
            after["theta_hat"] - before["theta_hat"], theta_rate * PERIOD_S, rtol=2e-3, atol=1e-12
        )
    assert np.abs(after["theta_hat"] - before["theta_hat"]).max() > 0.0


def test_paper_scenario_converges_with_sparse_events():
    """200 s of section 5.1 under eq. (15): errors fall for every follower, events stay rare."""
    env = parallel(horizon_s=200.0)
    policy = ClusterContainmentTrigger(
        env.observation_space("follower_0"),
        env.action_space("follower_0"),
        env.agent_observation_names,
    )
    obs, _ = env.reset(seed=0)
    start = env.state_dict()["containment_error"]
    while env.agents:
        actions, _ = policy.predict(np.stack([obs[a] for a in AGENTS]))
        obs, _, _, _, infos = env.step(dict(zip(AGENTS, actions, strict=True)))
    metrics = infos["follower_0"]["episode_metrics"]
    final = np.array([metrics["agents"][a]["final_containment_err"] for a in AGENTS])
    assert np.all(final < 0.95 * start) and final.sum() < 0.7 * start.sum()
    events = np.array([metrics["agents"][a]["transmissions"] for a in AGENTS])
    assert np.all(events > 5) and events.max() < 0.01 * 20_000
    assert metrics["failure"] is None


# --------------------------------------------------------------------------- observation
def test_observation_is_the_named_view_of_the_loop():
    env = parallel(horizon_s=1.0, randomize=True)
    names = env.agent_observation_names
    assert names == (*FEATURE_NAMES, "time_since_transmission_s")
    index = {name: env.observation_index(name) for name in names}
    obs, _ = env.reset(seed=5)
    clock = np.zeros(N_PAPER)
    rng = np.random.default_rng(5)
    for _ in range(60):
        bits = (rng.random(N_PAPER) < 0.2).astype(int)
        obs, *_ = env.step(dict(zip(AGENTS, bits, strict=True)))
        clock = np.where(bits == 1, PERIOD_S, clock + PERIOD_S)
        state = env.state_dict()
        e_j = np.linalg.norm(state["y_theta_event"] - state["y_theta"], axis=1)
        e_s = np.linalg.norm(state["s_event"] - state["s"], axis=1)
        for i, agent in enumerate(AGENTS):
            view = obs[agent]
            assert view.dtype == np.float32 and view in env.observation_space(agent)
            assert_allclose(view[index["event_error"]], e_j[i] + e_s[i], rtol=1e-5, atol=1e-9)
            assert_allclose(
                view[index["state_threshold"]], 0.5 * np.linalg.norm(state["s"][i]), rtol=1e-5
            )
            assert_allclose(view[index["e_J_norm"]], e_j[i], rtol=1e-5, atol=1e-9)
            assert_allclose(view[index["time_s"]], state["time_s"], rtol=1e-6)
            error = [view[index[f"containment_error_{a}"]] for a in "xyz"]
            assert_allclose(error, state["sigma"][i] - state["targets"][i], rtol=1e-5, atol=1e-7)
            assert_allclose(
                [view[index[f"u_{a}"]] for a in "xyz"], state["u"][i], rtol=1e-5, atol=1e-9
            )
            assert_allclose(view[index["time_since_transmission_s"]], clock[i], rtol=1e-5)
    assert e_s.max() > 0.0  # holding makes the event errors grow: the check is not vacuous


def test_rewards_infos_and_episode_metrics():
    penalty, scale = 0.3, 0.5
    env = parallel(horizon_s=0.3, transmission_penalty=penalty, cost_scale=scale)
    env.reset(seed=0)
    bits = np.zeros((30, N_PAPER), dtype=int)
    bits[::3, 0] = 1
    bits[[1, 2, 10], 4] = 1
    for k, row in enumerate(bits):
        _, rewards, terminations, truncations, infos = env.step(dict(zip(AGENTS, row, strict=True)))
        errors = env.state_dict()["containment_error"]
        for i, agent in enumerate(AGENTS):
            assert_allclose(infos[agent]["cost"], errors[i], rtol=1e-12)
            assert_allclose(rewards[agent], -errors[i] / scale - penalty * row[i], rtol=1e-12)
            assert infos[agent]["transmitted"] == row[i]
            assert infos[agent]["transmissions"] == bits[: k + 1, i].sum()
        assert not any(terminations.values())
        assert all(truncations.values()) == (k == 29)
    assert env.agents == []
    metrics = infos["follower_0"]["episode_metrics"]
    assert set(metrics) >= COMMON_METRIC_KEYS
    assert metrics["transmissions"] == bits.sum() and metrics["steps"] == 30
    follower_4 = metrics["agents"]["follower_4"]
    assert set(follower_4) >= AGENT_METRIC_KEYS
    assert follower_4["transmissions"] == 3
    assert_allclose(follower_4["mean_interevent_s"], 0.045)
    assert_allclose(follower_4["min_interevent_s"], 0.01)
    assert metrics["agents"]["follower_1"]["mean_interevent_s"] is None
    assert_allclose(follower_4["target_sigma"], env.state_dict()["targets"][4])
    with pytest.raises(RuntimeError):
        env.step(dict.fromkeys(AGENTS, 0))


# --------------------------------------------------------------------------- trigger
def test_paper_trigger_fires_at_the_eq_15_threshold():
    env = parallel(horizon_s=0.05)
    space = env.observation_space("follower_0")
    policy = ClusterContainmentTrigger(
        space, env.action_space("follower_0"), env.agent_observation_names
    )
    index = {
        name: env.observation_index(name)
        for name in ("event_error", "state_threshold", "sqrt_lambda_min_K", "time_s")
    }
    batch = np.zeros((4, space.shape[0]), dtype=np.float32)
    batch[:, index["state_threshold"]] = 0.5
    batch[:, index["sqrt_lambda_min_K"]] = 1.0
    batch[:, index["time_s"]] = 4.0
    threshold = 0.6 * 0.5 + 2.0 * np.exp(-0.5 * 4.0)
    batch[:, index["event_error"]] = threshold * np.array([0.5, 0.999, 1.001, 2.0])
    actions, _ = policy.predict(batch)
    assert_array_equal(actions, [0, 0, 1, 1])
    central = gym.make(CENTRAL_ID, horizon_s=0.05).unwrapped
    central_policy = ClusterContainmentTrigger(
        central.observation_space, central.action_space, central.observation_names
    )
    obs = np.zeros(central.observation_space.shape, dtype=np.float32)
    for i in range(N_PAPER):
        for name, column in index.items():
            obs[central.observation_index(f"{name}_{i}")] = batch[i % 4, column]
    assert_array_equal(central_policy.predict(obs)[0], [0, 0, 1, 1, 0, 0])


@pytest.mark.parametrize(
    ("kwargs", "named"), [({"c": 1.0}, "c"), ({"rho": 0.0}, "rho"), ({"nu": 1.5}, "nu")]
)
def test_paper_trigger_rejects_bad_parameters(kwargs, named):
    env = parallel(horizon_s=0.05)
    with pytest.raises(ValueError, match=named):
        ClusterContainmentTrigger(
            env.observation_space("follower_0"),
            env.action_space("follower_0"),
            env.agent_observation_names,
            **kwargs,
        )


# --------------------------------------------------------------------------- errors
@pytest.mark.parametrize(
    ("kwargs", "named"),
    [
        ({"scenario": "ring"}, "scenario"),
        ({"adjacency": np.zeros((8, 8))}, "adjacency"),
        ({"adjacency": -ClusterContainmentParams().adjacency}, "adjacency"),
        ({"adjacency": ClusterContainmentParams().adjacency + np.eye(9)}, "adjacency"),
        ({"adjacency": ClusterContainmentParams().adjacency + np.eye(9, k=-8)}, "adjacency"),
        ({"nominal_inertias": np.tile(-np.eye(3), (6, 1, 1))}, "nominal_inertias"),
        ({"inertia_uncertainty": np.tile(-30 * np.eye(3), (6, 1, 1))}, "inertia_uncertainty"),
        ({"initial_attitudes": np.zeros((6, 2))}, "initial_attitudes"),
        ({"initial_rates": np.zeros((5, 3))}, "initial_rates"),
        ({"leader_attitudes": np.zeros(3)}, "leader_attitudes"),
        ({"control_gain": (1.0, -1.0, 1.0)}, "control_gain"),
        ({"adaptation_gain": (2.0, 2.0, 2.0)}, "adaptation_gain"),
        ({"switching": "tanh"}, "switching"),
        ({"alpha": 0.0}, "alpha"),
        ({"sampling_period_s": -0.01}, "sampling_period_s"),
        ({"transmission_penalty": -1.0}, "transmission_penalty"),
    ],
)
def test_bad_constructor_argument_is_named(kwargs, named):
    with pytest.raises(ValueError, match=named):
        parallel(**kwargs)


def test_unknown_keyword_is_a_type_error():
    with pytest.raises(TypeError, match="horizon"):
        gym.make(CENTRAL_ID, horizon=1.0)


@pytest.mark.parametrize(
    ("actions", "message"),
    [
        ({"follower_0": 1}, "missing"),
        ({**dict.fromkeys(AGENTS, 0), "follower_9": 1}, "unknown"),
        ({**dict.fromkeys(AGENTS, 0), "follower_2": 2}, "action of follower_2"),
        ({**dict.fromkeys(AGENTS, 0), "follower_3": "1"}, "action of follower_3"),
        ({**dict.fromkeys(AGENTS, 0), "follower_5": [1, 0]}, "action of follower_5"),
    ],
)
def test_bad_actions_are_rejected(actions, message):
    env = parallel(horizon_s=0.05)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=message):
        env.step(actions)


def test_failure_terminates_every_agent_and_charges_the_horizon():
    env = parallel(max_rate_rad_s=0.0101, horizon_s=50.0)
    central = env.loop
    env.reset(seed=0)
    while env.agents:
        _, rewards, terminations, truncations, infos = env.step(dict.fromkeys(env.agents, 0))
    assert all(terminations.values()) and not any(truncations.values())
    failure = infos["follower_0"]["failure"]
    assert failure.startswith("diverged: |omega| of follower_")
    cut = central.n_steps - central.step_index
    assert cut > 0
    expected_total = (
        -(central.channel_costs.sum() + central.failure_cost * cut) / central.cost_scale
    )
    assert_allclose(sum(rewards.values()), expected_total, rtol=1e-12)
    assert infos["follower_3"]["episode_metrics"]["failure"] == failure


# --------------------------------------------------------------------------- commands
def test_evaluate_reports_per_agent_values():
    result = evaluate(PARALLEL_ID, "paper", env_args={"horizon_s": 0.5}, episodes=2, seed=3)
    episode = result["episodes"][0]
    assert set(episode["agents"]) == set(AGENTS)
    assert set(episode["agents"]["follower_0"]) >= AGENT_METRIC_KEYS | {"return"}
    assert_allclose(episode["return"], sum(a["return"] for a in episode["agents"].values()))
    assert set(result["mean"]["agents"]) == set(AGENTS)
    assert "transmissions" in result["mean"]["agents"]["follower_2"]


def test_evaluate_windows_add_up_over_the_agents():
    result = evaluate(
        PARALLEL_ID,
        "periodic",
        policy_args={"every": 5},
        env_args={"horizon_s": 0.5},
        seed=3,
        windows_s=[0.0, 0.2, 0.5],
    )
    episode = result["episodes"][0]
    split = episode["windows"]
    # Every follower updates at steps 0, 5, 10, ... (10 ms each): 4 updates before 0.2 s and 6
    # after, six followers.
    assert [w["transmissions"] for w in split] == [24, 36]
    assert (
        sum(w["transmissions"] for w in split)
        == episode["transmissions"]
        == sum(agent["transmissions"] for agent in episode["agents"].values())
    )
    assert all(w["cost"] > 0.0 for w in split)


def test_reproduction_report_has_the_papers_numbers():
    result = reproduction.reproduce(horizon_s=20.0)
    names = [table["name"] for table in result["tables"]]
    assert len(names) == 4
    events = result["tables"][0]["rows"]
    assert [row["metrics"]["ET sat events"]["paper"] for row in events] == [
        391,
        445,
        405,
        354,
        402,
        480,
    ]
    assert all(row["metrics"]["TT updates"]["paper"] == 120_000 for row in events)
    assert all(row["metrics"]["TT updates"]["ours"] == 2_000 for row in events)
    pi1 = result["tables"][2]["rows"]
    assert [row["metrics"]["ET sat events"]["paper"] for row in pi1] == [
        232,
        247,
        522,
        420,
        162,
        142,
        196,
        288,
        315,
    ]
    assert len(result["claims"]) == 11
    theorem_4 = next(c for c in result["claims"] if "3, 4, 5, 6" in c["claim"])
    assert theorem_4["holds"]


def test_evaluate_command_for_the_pettingzoo_id(capsys):
    from baselines import evaluate as evaluate_module

    argv = [PARALLEL_ID, "--policy", "periodic", "--policy-arg", "every=10"]
    argv += ["--env-arg", "horizon_s=0.5", "--env-arg", "scenario=pi1", "--json", "-"]
    assert evaluate_module.main(argv) == 0
    result = json.loads(capsys.readouterr().out)
    agents = result["episodes"][0]["agents"]
    assert len(agents) == 9
    assert all(values["transmissions"] == 5 for values in agents.values())
    assert (
        evaluate_module.main([PARALLEL_ID, "--policy", "paper", "--env-arg", "horizon_s=0.2"]) == 0
    )
    printed = capsys.readouterr().out
    assert "follower_5: return=" in printed and "transmissions=" in printed


def test_hull_distance_of_definition_4():
    triangle = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    assert hull_distance(np.array([0.2, 0.3, 0.0]), triangle) < 1e-6  # inside
    assert_allclose(hull_distance(np.array([0.2, 0.3, 0.4]), triangle), 0.4, atol=1e-6)
    assert_allclose(hull_distance(np.array([2.0, -1.0, 0.0]), triangle), np.sqrt(2.0), atol=1e-6)
    assert_allclose(hull_distance(np.array([1.0, 1.0, 0.0]), triangle), np.sqrt(0.5), atol=1e-6)

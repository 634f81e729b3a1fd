"""``etsc/OrbitAttitudeTracking-v0`` (paper 000, Zhang et al. 2019): API, physics and numerics.

Checked properties:

* the environment passes the Gymnasium and Stable-Baselines3 checkers and resolves through
  ``"etsc_envs:..."`` in a fresh interpreter; ``reset(seed=...)`` is reproducible, the paper
  scenario's ΔD is a fixed draw while ``misalignment_seed=None`` and ``randomize=True`` draw
  from the env's RNG (within the documented ranges);
* the observation holds e_c = Γ_c - Γ_cout, S, η̃ = log(g_e), Ṽ (eq. 21's inputs) and the
  transmission clock; the paper's trigger is eq. (21); a transmission restarts the integral of
  eq. (23); reward, cost and the episode metrics follow their definitions;
* actuators: D of eq. (35) has rank 6, the allocation f = D†Γ_c reproduces Γ_c without
  saturation, bias and misalignment, and saturation and bias act per thruster;
* dynamics: the plant's cancellation-free relative dynamics equal the controller's eq. (9)
  (H + Ξ⁻¹f(Ξ), written with absolute quantities) for the nominal model; the relative motion of
  an uncontrolled chaser matches two analytic Kepler orbits to 1e-8 m over 300 s (the numerical
  floor), and the total disturbance equals dS/dt - H1 - Ξ⁻¹Γ_c by finite differences;
* closed loop: with ``always`` the paper's scenario converges inside the paper's bounds, and the
  nominal loop's error floor is far below 1e-6 m and independent of the RK4 substeps;
* bad arguments and actions raise errors naming them; a divergence bound ends the episode.
"""

from __future__ import annotations

import math
import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gymnasium_check_env
from numpy.testing import assert_allclose, assert_array_equal

import etsc_envs  # noqa: F401  (registers the ids)
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.metrics import COMMON_EPISODE_KEYS
from etsc_envs.core.rotations import se3_exp, se3_log
from etsc_envs.orbit_attitude.closed_loop import integrate_plant
from etsc_envs.orbit_attitude.controller import eso_input, known_dynamics
from etsc_envs.orbit_attitude.dynamics import (
    PlantModel,
    chaser_pose_and_twist,
    error_pose,
    leader_pose,
    relative_derivative,
    thruster_outputs,
)
from etsc_envs.orbit_attitude.env import (
    COST_REFERENCE,
    FEATURE_NAMES,
    make_controller_gains,
    make_leader,
    make_plant_model,
)
from etsc_envs.orbit_attitude.params import OrbitAttitudeParams
from etsc_envs.triggers import AlwaysPolicy, OrbitAttitudeTrigger

ENV_ID = "etsc/OrbitAttitudeTracking-v0"
SHORT = {"horizon_s": 0.5}
NOMINAL = {
    "inertia_uncertainty_ratio": 0.0,
    "mass_uncertainty_kg": 0.0,
    "misalignment_std": 0.0,
    "thruster_bias_ratio": 0.0,
    "disturbances": False,
}
COMMON_METRIC_KEYS = set(COMMON_EPISODE_KEYS)
PAPER_METRIC_KEYS = {
    "ss_att_err_deg",
    "ss_angvel_err_degps",
    "ss_pos_err_m",
    "ss_vel_err_mps",
    "settle_att_s",
    "settle_pos_s",
    "eso_ss_err",
    "thruster_impulse_Ns",
}


def make(**kwargs) -> gym.Env:
    return gym.make(ENV_ID, **kwargs)


def block(obs: np.ndarray, env: gym.Env, prefix: str) -> np.ndarray:
    unwrapped = env.unwrapped
    return np.array([obs[unwrapped.observation_index(f"{prefix}_{a}")] for a in "xyz"], float)


def rollout(env: gym.Env, policy, seed: int | None = 0):
    """(observations, rewards, infos) of one episode."""
    obs, _ = env.reset(seed=seed)
    observations, rewards, infos = [obs], [], []
    while True:
        action, _ = policy.predict(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        observations.append(obs)
        rewards.append(reward)
        infos.append(info)
        if terminated or truncated:
            return np.array(observations), np.array(rewards), infos


def trigger(env: gym.Env, **kwargs) -> OrbitAttitudeTrigger:
    return OrbitAttitudeTrigger(
        env.observation_space, env.action_space, env.unwrapped.observation_names, **kwargs
    )


def always(env: gym.Env) -> AlwaysPolicy:
    return AlwaysPolicy(env.observation_space, env.action_space)


# --------------------------------------------------------------------------- API contracts
def test_gymnasium_and_sb3_checkers_pass():
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = make(**SHORT)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gymnasium_check_env(env.unwrapped, skip_render_check=True)
        sb3_check_env(make(**SHORT).unwrapped, warn=True)
    # unbounded physical components (errors, commands) are documented; nothing else may warn
    unexpected = [
        str(w.message)
        for w in caught
        if "infinity" not in str(w.message).lower() and "unbounded" not in str(w.message).lower()
    ]
    assert unexpected == []
    assert env.action_space == gym.spaces.Discrete(2)
    assert env.observation_space.dtype == np.float32
    assert env.unwrapped.observation_names == (*FEATURE_NAMES, "time_since_transmission_s")


def test_id_resolves_in_a_fresh_interpreter():
    code = (
        "import gymnasium as gym; "
        f"env = gym.make('etsc_envs:{ENV_ID}', horizon_s=0.01); "
        "obs, _ = env.reset(seed=0); print(obs.shape)"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == f"({len(FEATURE_NAMES) + 1},)"


def test_seeded_resets_reproduce_and_paper_scenario_is_fixed():
    env = make(**SHORT)
    first = rollout(env, trigger(env), seed=3)
    second = rollout(env, trigger(env), seed=3)
    assert_array_equal(first[0], second[0])
    assert_array_equal(first[1], second[1])
    # the paper scenario's ΔD is a fixed draw: the seed does not change it
    other = rollout(env, trigger(env), seed=4)
    assert_array_equal(first[0], other[0])
    expected = 0.01 * np.random.default_rng(0).normal(size=(6, 12))
    assert_allclose(env.unwrapped.misalignment, expected, rtol=0, atol=0)


@pytest.mark.parametrize("kwargs", [{"misalignment_seed": None}, {"randomize": True}])
def test_random_draws_come_from_the_env_rng(kwargs):
    env = make(**SHORT, **kwargs)
    a = rollout(env, trigger(env), seed=1)
    b = rollout(env, trigger(env), seed=1)
    c = rollout(env, trigger(env), seed=2)
    assert_array_equal(a[0], b[0])
    assert not np.array_equal(a[0], c[0])


def test_randomized_initial_errors_stay_in_documented_ranges():
    env = make(horizon_s=0.01, randomize=True)
    for seed in range(20):
        obs, _ = env.reset(seed=seed)
        phi = block(obs, env, "phi")
        chi = se3_exp(np.concatenate([phi, block(obs, env, "chi")]))[:3, 3]
        assert np.linalg.norm(phi) <= np.deg2rad(100.0) + 1e-6
        assert np.linalg.norm(chi) <= 60.0 + 1e-3
        assert_array_equal(block(obs, env, "dw"), 0.0)
        leader = env.unwrapped.leader
        assert 0.0 <= leader.raan < 2 * np.pi and 0.0 <= leader.latitude_argument0 < 2 * np.pi


def test_paper_initial_points():
    for point, phi_deg, chi in (
        ("P1", (76.71, -14.02, 60.05), (3.61, -28.7, -9.82)),
        ("P2", (63.6, -13.2, 51.0), (-3.4, -55.8, 0.1)),
    ):
        env = make(horizon_s=0.01, initial_point=point)
        obs, _ = env.reset(seed=0)
        assert_allclose(block(obs, env, "phi"), np.deg2rad(phi_deg), rtol=1e-6)
        assert_allclose(block(obs, env, "chi"), chi, rtol=1e-6)
        assert_array_equal(block(obs, env, "dv"), 0.0)


# --------------------------------------------------------------------------- observation, trigger
def test_observation_matches_the_loop_and_the_clock():
    env = make(horizon_s=0.05)
    unwrapped = env.unwrapped
    obs, _ = env.reset(seed=0)
    assert_array_equal(obs[:6], 0.0)  # Γ_c synchronised with Γ_cout(0) at t0
    period = unwrapped.sampling_period_s
    clock = unwrapped.observation_index("time_since_transmission_s")
    for action, periods in zip([1, 0, 0, 1, 0], [1, 2, 3, 1, 2], strict=True):
        obs, *_ = env.step(action)
        state = unwrapped.state_dict()
        assert_allclose(obs[:6], state["held_command"] - state["command"], rtol=1e-6, atol=1e-9)
        assert_allclose(obs[6:12], state["surface"], rtol=1e-6, atol=1e-12)
        assert_allclose(obs[12:18], se3_log(error_pose(unwrapped.plant_state)), rtol=1e-6)
        assert_allclose(obs[18:24], unwrapped.plant_state[7:13], rtol=1e-6, atol=1e-12)
        assert obs[clock] == pytest.approx(periods * period, abs=1e-9)


def test_transmission_sends_the_command_and_restarts_the_integral():
    env = make(horizon_s=0.05)
    unwrapped = env.unwrapped
    env.reset(seed=0)
    for _ in range(5):
        env.step(0)
    assert unwrapped.controller_state[14:16].min() > 0.0
    fresh = unwrapped.kernels.channel_values(
        unwrapped.state, unwrapped.constants, unwrapped.time_s
    )[0].copy()
    state = unwrapped.state_dict()
    assert_allclose(fresh, state["fresh_command"], rtol=1e-12)
    _, _, _, _, info = env.step(1)
    assert info["transmitted"] == 1
    assert_array_equal(unwrapped.held[0], fresh)
    # after one period the integral holds h ϕ̂(t_k) only
    period = unwrapped.sampling_period_s
    assert_allclose(unwrapped.controller_state[14:16], period * state["phi_hat"], rtol=1e-12)


def test_paper_trigger_is_equation_21():
    env = make(horizon_s=0.2)
    policy = trigger(env, a1=0.6, a2=0.8, gamma1=0.001, gamma2=0.003)
    obs, _ = env.reset(seed=0)
    fired = 0
    for _ in range(200):
        ec1, ec2 = block(obs, env, "ec1"), block(obs, env, "ec2")
        s1, s2 = block(obs, env, "s1"), block(obs, env, "s2")
        expected = (
            np.linalg.norm(ec1) >= 0.6 * np.linalg.norm(s1) + 0.001
            or np.linalg.norm(ec2) >= 0.8 * np.linalg.norm(s2) + 0.003
        )
        action, _ = policy.predict(obs)
        assert bool(action) == expected
        fired += int(action)
        obs, *_ = env.step(action)
    assert 0 < fired < 200


def test_larger_gamma_transmits_less():
    env = make(horizon_s=1.0, initial_point="P1")
    sent = {}
    for gammas in ((0.001, 0.003), (0.1, 0.2)):
        _, _, infos = rollout(env, trigger(env, gamma1=gammas[0], gamma2=gammas[1]))
        sent[gammas] = infos[-1]["transmissions"]
    assert sent[(0.1, 0.2)] < sent[(0.001, 0.003)]


# --------------------------------------------------------------------------- reward and metrics
def test_reward_cost_and_metrics_follow_their_definitions():
    penalty, scale = 0.7, 3.0
    env = make(horizon_s=0.5, transmission_penalty=penalty, cost_scale=scale)
    unwrapped = env.unwrapped
    obs, _ = env.reset(seed=0)
    period = unwrapped.sampling_period_s
    rng = np.random.default_rng(0)
    records, impulse, costs = [], 0.0, []
    while True:
        action = int(rng.integers(2))
        obs, reward, terminated, truncated, info = env.step(action)
        phi, chi = block(obs, env, "phi"), block(obs, env, "chi")
        dw, dv = block(obs, env, "dw"), block(obs, env, "dv")
        norms = [np.linalg.norm(x) for x in (phi, dw, chi, dv)]
        cost = 0.25 * sum(np.log1p(n / r) for n, r in zip(norms, COST_REFERENCE, strict=True))
        assert info["cost"] == pytest.approx(cost, rel=1e-5)
        assert reward == pytest.approx(-info["cost"] / scale - penalty * info["transmitted"])
        costs.append(info["cost"])
        impulse += period * np.abs(unwrapped.state_dict()["thruster_output"]).sum()
        records.append(np.concatenate([np.abs(phi), np.abs(dw), np.abs(chi), np.abs(dv)]))
        assert set(info) >= {"transmitted", "transmissions", "time_s", "cost"}
        if terminated or truncated:
            break
    assert truncated and not terminated
    metrics = info["episode_metrics"]
    assert set(metrics) >= COMMON_METRIC_KEYS | PAPER_METRIC_KEYS
    assert set(metrics["eso_ss_err"]) == {"e1_rot", "e1_trans", "e2_rot_Nm", "e2_trans_N"}
    records = np.array(records)
    window = records[len(records) - len(records) // 5 :]
    deg = 180.0 / np.pi
    assert metrics["ss_att_err_deg"] == pytest.approx(window[:, 0:3].max() * deg, rel=1e-5)
    assert metrics["ss_angvel_err_degps"] == pytest.approx(window[:, 3:6].max() * deg, rel=1e-5)
    assert metrics["ss_pos_err_m"] == pytest.approx(window[:, 6:9].max(), rel=1e-5)
    assert metrics["ss_vel_err_mps"] == pytest.approx(window[:, 9:12].max(), rel=1e-5)
    assert metrics["thruster_impulse_Ns"] == pytest.approx(impulse, rel=1e-9)
    assert metrics["mean_cost"] == pytest.approx(np.mean(costs), rel=1e-9)
    assert metrics["settle_att_s"] is None and metrics["settle_pos_s"] is None  # 0.5 s: not yet


# --------------------------------------------------------------------------- actuators
def test_distribution_matrix_and_allocation():
    params = OrbitAttitudeParams()
    d = params.distribution_matrix()
    assert d.shape == (6, 12) and np.linalg.matrix_rank(d) == 6
    assert_array_equal(d[3], [-1, 0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0])
    assert_array_equal(d[0], 0.5 * np.array([0, 1, -1, 0, 1, -1, 0, -1, 1, 0, -1, 1]))
    leader = make_leader(params, 0.0, 0.0)
    ideal = make_plant_model(
        OrbitAttitudeParams(misalignment_std=0.0, thruster_bias_ratio=0.0),
        leader,
        np.zeros((6, 12)),
    )
    rng = np.random.default_rng(5)
    for command in rng.uniform(-0.2, 0.2, size=(20, 6)):
        demand, output, wrench = thruster_outputs(command, ideal)
        assert np.abs(demand).max() <= params.thruster_max_force_n
        assert_allclose(output, demand, rtol=0, atol=0)
        assert_allclose(wrench, command, rtol=0, atol=1e-14)
    # bias and saturation act per thruster, misalignment only in the plant's D
    misalignment = 0.01 * rng.normal(size=(6, 12))
    real = make_plant_model(params, leader, misalignment)
    command = np.array([0.3, -0.2, 0.1, 3.0, -1.0, 0.5])
    demand, output, wrench = thruster_outputs(command, real)
    assert_allclose(demand, np.linalg.pinv(d) @ command, rtol=1e-12)
    assert_allclose(output, 1.005 * np.clip(demand, -0.5, 0.5), rtol=1e-14)
    assert_allclose(wrench, (d + misalignment) @ output, rtol=1e-12)


# --------------------------------------------------------------------------- dynamics
def nominal_models(**overrides):
    params = OrbitAttitudeParams(**{**NOMINAL, **overrides})
    leader = make_leader(params, 0.3, 1.1)
    return (
        params,
        make_plant_model(params, leader, np.zeros((6, 12))),
        make_controller_gains(params, leader),
    )


def test_relative_dynamics_equal_the_papers_equation_9():
    """With the nominal model and no input, the plant's dṼ/dt is H + Ξ⁻¹ f(Ξ) of eq. (9)."""
    _, model, gains = nominal_models()
    rng = np.random.default_rng(6)
    for t in (0.0, 417.0):
        for _ in range(10):
            y = np.zeros(13)
            phi = rng.normal(size=3)
            y[0:4] = np.concatenate([np.sin(0.5) * phi / np.linalg.norm(phi), [np.cos(0.5)]])
            y[4:7] = 50.0 * rng.normal(size=3)
            y[7:13] = rng.normal(size=6) * [0.05, 0.05, 0.05, 1.0, 1.0, 1.0]
            plant = relative_derivative(t, y, (np.zeros(6), model))[7:13]
            paper = known_dynamics(t, error_pose(y), y[7:13].copy(), gains)
            assert_allclose(plant, paper, rtol=1e-9, atol=1e-13)


def test_absolute_twist_and_pose_recompose_the_chaser():
    _, model, _ = nominal_models()
    y = np.zeros(13)
    y[3] = 1.0
    y[4:7] = [10.0, -20.0, 5.0]
    g_a, twist = chaser_pose_and_twist(100.0, y, model.leader)
    g_d = leader_pose(100.0, model.leader)
    assert_allclose(g_a[:3, 3] - g_d[:3, 3], g_d[:3, :3] @ y[4:7], atol=1e-8)
    n, a = model.leader.rate, model.leader.radius
    assert_allclose(twist, [0, 0, n, -n * (-20.0), n * (a + 10.0), 0.0], rtol=1e-12)


def kepler_propagate(r0: np.ndarray, v0: np.ndarray, t: float, mu: float) -> np.ndarray:
    """Position after ``t`` on the two-body orbit through (r0, v0), by universal variables."""
    r0n = np.linalg.norm(r0)
    vr0 = r0 @ v0 / r0n
    alpha = 2.0 / r0n - v0 @ v0 / mu
    x = math.sqrt(mu) * abs(alpha) * t
    for _ in range(50):
        z = alpha * x * x
        c = (1 - math.cos(math.sqrt(z))) / z if z > 1e-8 else 0.5 - z / 24
        s = (math.sqrt(z) - math.sin(math.sqrt(z))) / z**1.5 if z > 1e-8 else 1 / 6 - z / 120
        f = (
            r0n * vr0 / math.sqrt(mu) * x * x * c
            + (1 - alpha * r0n) * x**3 * s
            + r0n * x
            - math.sqrt(mu) * t
        )
        df = r0n * vr0 / math.sqrt(mu) * x * (1 - z * s) + (1 - alpha * r0n) * x * x * c + r0n
        step = f / df
        x -= step
        if abs(step) < 1e-15 * abs(x):
            break
    z = alpha * x * x
    c = (1 - math.cos(math.sqrt(z))) / z
    s = (math.sqrt(z) - math.sin(math.sqrt(z))) / z**1.5
    f_lagrange = 1 - x * x / r0n * c
    g_lagrange = t - x**3 / math.sqrt(mu) * s
    return f_lagrange * r0 + g_lagrange * v0


def test_relative_motion_matches_two_kepler_orbits_to_1e_8_m():
    """The numerical floor: an uncontrolled chaser (no J2, spherical inertia) integrated by the
    env's RK4 at 1 ms in the error variables stays within 1e-8 m of the difference of two
    analytic Kepler orbits over 300 s."""
    _, model, _ = nominal_models(j2=0.0)
    model = model._replace(inertia=np.eye(3), inertia_inv=np.eye(3))
    leader = model.leader
    y = np.zeros(13)
    y[3] = 1.0
    y[4:7] = [3.61, -28.7, -9.82]
    y[10:13] = [0.01, -0.02, 0.005]
    g_a, twist = chaser_pose_and_twist(0.0, y, leader)
    r_c0, v_c0 = g_a[:3, 3], g_a[:3, :3] @ twist[3:]
    g_d = leader_pose(0.0, leader)
    r_d0 = g_d[:3, 3]
    v_d0 = g_d[:3, :3] @ np.array([0.0, leader.rate * leader.radius, 0.0])
    h, steps = 1e-3, 300_000
    state = y.copy()
    wrench = np.zeros(6)
    checkpoints = {100_000, 200_000, 300_000}
    for k in range(steps):
        state = integrate_plant(k * h, state, h, (wrench, model))
        if k + 1 in checkpoints:
            t = (k + 1) * h
            r_c = kepler_propagate(r_c0, v_c0, t, leader.mu)
            r_d = kepler_propagate(r_d0, v_d0, t, leader.mu)
            reference = leader_pose(t, leader)[:3, :3].T @ (r_c - r_d)
            assert_allclose(state[4:7], reference, rtol=0, atol=1e-8)


def test_total_disturbance_is_the_surface_rate_not_explained_by_the_model():
    """Δd = dS/dt - H1 - Ξ⁻¹Γ_c (section III-B), checked by a central difference of S along the
    true plant with the command held."""
    env = make(horizon_s=10.0)
    unwrapped = env.unwrapped
    env.reset(seed=0)
    for _ in range(3000):
        env.step(1)
    state = unwrapped.state_dict()
    held = state["held_command"]
    wrench = thruster_outputs(held, unwrapped.model)[2]
    h = 1e-4
    t = unwrapped.time_s

    def surface_at(dt: float) -> np.ndarray:
        y = unwrapped.plant_state.copy()
        if dt != 0.0:
            y = make_rk4_step(relative_derivative)(t, y, dt, (wrench, unwrapped.model))
        from etsc_envs.orbit_attitude.closed_loop import controller_view

        return controller_view(t + dt, y, unwrapped.controller_state, unwrapped.gains)

    _, _, drift, _, _, _ = surface_at(0.0)
    s_plus = surface_at(h)[1]
    s_minus = surface_at(-h)[1]
    surface_rate = (s_plus - s_minus) / (2 * h)
    from etsc_envs.orbit_attitude.controller import inertia_solve

    expected = (
        surface_rate - drift - inertia_solve(eso_input(held, unwrapped.gains), unwrapped.gains)
    )
    assert_allclose(state["total_disturbance"], expected, rtol=1e-4, atol=1e-8)


def test_disturbance_step_is_the_jump_of_the_total_disturbance_at_a_transmission():
    """Changing only the held command moves Δd by Ξ⁻¹ ``disturbance_step``, in the saturated
    and in the unsaturated regime; with the nominal model the step is zero."""
    from etsc_envs.orbit_attitude.closed_loop import disturbance_step, total_disturbance

    small_before = np.full(6, 1e-3)
    small_after = np.array([2e-3, -1e-3, 0.0, 3e-3, 0.0, -2e-3])
    for kwargs in ({}, NOMINAL):
        env = make(horizon_s=1.0, **kwargs)
        unwrapped = env.unwrapped
        env.reset(seed=0)
        env.step(1)
        held = unwrapped.state_dict()["held_command"]  # ~25 N: saturated thrusters
        model, gains = unwrapped.model, unwrapped.gains
        t, y = unwrapped.time_s, unwrapped.plant_state

        def disturbance(command, model=model, gains=gains, t=t, y=y):
            wrench = thruster_outputs(command, model)[2]
            fed = eso_input(command, gains)
            return total_disturbance(t, y, wrench, fed, np.zeros(6), model, gains)

        for before, after in ((held, 0.5 * held), (small_before, small_after)):
            jump = disturbance(after) - disturbance(before)
            step = disturbance_step(before, after, model, gains)
            expected = np.concatenate([gains.inertia @ jump[0:3], gains.mass * jump[3:6]])
            assert_allclose(step, expected, rtol=1e-9, atol=1e-15)
            if kwargs is NOMINAL:
                assert_allclose(step, 0.0, atol=1e-15)
        if kwargs is not NOMINAL:
            # unsaturated, ΔJ = 0.1 J dominates: torque step ≈ (1/1.1 - 1) of the command step
            step = disturbance_step(small_before, small_after, model, gains)
            ratio = np.abs(step[0:3]).max() / np.abs(small_after - small_before)[0:3].max()
            assert 0.05 < ratio < 0.2


# --------------------------------------------------------------------------- closed loop
def test_always_transmitting_converges_inside_the_papers_bounds():
    """The paper's P1 with the controller at 10 ms (for test time) and ``always``."""
    env = make(sampling_period_s=0.01, horizon_s=200.0)
    _, _, infos = rollout(env, always(env))
    metrics = infos[-1]["episode_metrics"]
    assert metrics["failure"] is None
    assert metrics["settle_att_s"] < 180.0 and metrics["settle_pos_s"] < 200.0
    assert metrics["ss_att_err_deg"] < 4e-4
    assert metrics["ss_angvel_err_degps"] < 2e-3
    assert metrics["ss_pos_err_m"] < 1e-5
    assert metrics["ss_vel_err_mps"] < 2e-6


def test_nominal_closed_loop_error_floor_is_far_below_1e_6_m():
    """Without disturbances and uncertainties the loop converges to a floor set by numerics
    alone: η̃ below 1e-9 m and 1e-9 rad, the same with 1 or 4 RK4 substeps per period."""
    finals = []
    for substeps in (1, 4):
        env = make(
            **NOMINAL,
            horizon_s=60.0,
            plant_substeps=substeps,
            initial_attitude_error_deg=(0.05, -0.02, 0.03),
            initial_position_error_m=(0.02, -0.05, 0.01),
        )
        rollout(env, always(env))
        unwrapped = env.unwrapped
        eta = se3_log(error_pose(unwrapped.plant_state))
        finals.append(eta)
        assert np.abs(eta[3:]).max() < 1e-9
        assert np.abs(eta[:3]).max() < 1e-9
        # Ṽ keeps the digital controller's chattering at 1 ms, far below the paper's bounds
        assert np.abs(unwrapped.plant_state[7:10]).max() < 1e-6
        assert np.abs(unwrapped.plant_state[10:13]).max() < 1e-7
    assert_allclose(finals[0], finals[1], rtol=0, atol=1e-12)


def test_observer_variants_and_eso_input():
    params = OrbitAttitudeParams(observer="ref19")
    gains = make_controller_gains(params, make_leader(params, 0.0, 0.0))
    assert_array_equal(gains.k2, 0.0)
    assert_array_equal(gains.k4, 0.0)
    assert_array_equal(gains.k5, 0.0)
    assert np.all(gains.k1 > 0) and np.all(gains.k3 > 0)
    assert gains.eso_sees_saturation
    literal = make_controller_gains(
        OrbitAttitudeParams(eso_input="commanded"), make_leader(params, 0.0, 0.0)
    )
    assert not literal.eso_sees_saturation


# --------------------------------------------------------------------------- errors and failure
@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"sampling_period_s": 0.0}, "sampling_period_s"),
        ({"horizon_s": -1.0}, "horizon_s"),
        ({"nominal_inertia": ((20, 1, 0), (0, 21, 0), (0, 0, 20))}, "nominal_inertia"),
        ({"initial_point": "P3"}, "initial_point"),
        ({"observer": "luenberger"}, "observer"),
        ({"eso_input": "ideal"}, "eso_input"),
        ({"eso_k5": (0.01, 3.2)}, "eso_k1..eso_k5"),
        ({"eso_alpha2": 0.5}, "eso_alpha1"),
        ({"surface_alpha": 1.2}, "surface_alpha"),
        ({"gain_k1": (6.0, -8.0)}, "gain_k1"),
        ({"misalignment_seed": -1}, "misalignment_seed"),
        ({"plant_substeps": 0}, "plant_substeps"),
        ({"initial_attitude_error_deg": (180.0, 10.0, 0.0)}, "initial_attitude_error_deg"),
        ({"initial_position_error_m": (1.0, 2.0)}, "initial_position_error_m"),
        ({"thruster_max_force_n": 0.0}, "thruster_max_force_n"),
        ({"transmission_penalty": -1.0}, "transmission_penalty"),
        ({"cost_scale": 0.0}, "cost_scale"),
        ({"randomize": "yes"}, "randomize"),
    ],
)
def test_bad_arguments_raise_value_errors_naming_them(kwargs, name):
    with pytest.raises(ValueError, match=name):
        make(**kwargs)


def test_unknown_argument_and_bad_actions():
    with pytest.raises(TypeError, match="unknown argument"):
        make(sampling_period=0.01)
    env = make(**SHORT)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action must be"):
        env.step(2)
    with pytest.raises(ValueError, match="gamma1"):
        trigger(env, gamma1=0.0)
    with pytest.raises(ValueError, match="a2"):
        trigger(env, a2=-1.0)


def test_divergence_bound_terminates_and_charges_the_rest_of_the_horizon():
    env = make(horizon_s=1.0, max_velocity_error_m_s=0.005)
    obs, _ = env.reset(seed=0)
    steps = 0
    while True:
        obs, reward, terminated, truncated, info = env.step(1)
        steps += 1
        if terminated or truncated:
            break
    assert terminated and not truncated
    assert "diverged: |dv|" in info["failure"]
    assert info["episode_metrics"]["failure"] == info["failure"]
    unwrapped = env.unwrapped
    remaining = unwrapped.n_steps - steps
    expected = -(info["cost"] + unwrapped.failure_cost * remaining) - 1.0
    assert reward == pytest.approx(expected)
    assert np.all(np.isfinite(obs))
    with pytest.raises(RuntimeError):
        env.step(0)


def test_params_are_a_frozen_validated_dataclass():
    params = OrbitAttitudeParams()
    with pytest.raises(AttributeError):
        params.horizon_s = 1.0  # type: ignore[misc]
    assert params.true_mass_kg == 105.0
    assert_allclose(params.true_inertia, 1.1 * np.asarray(params.nominal_inertia))
    assert params.leader_rate_rad_s == pytest.approx(math.sqrt(398600.4e9 / 6778.14e3**3))
    phi, chi = params.initial_error()
    assert_allclose(np.rad2deg(phi), [76.71, -14.02, 60.05])
    assert_allclose(chi, [3.61, -28.7, -9.82])
    assert isinstance(
        make_plant_model(params, make_leader(params, 0, 0), np.zeros((6, 12))), PlantModel
    )

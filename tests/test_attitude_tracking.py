"""``etsc/AttitudeTracking-v0`` (paper 002, Cai et al. 2019): API contracts and closed-loop physics.

Checked properties:

* the environment passes the Gymnasium and Stable-Baselines3 environment checkers, and its id
  resolves through ``"etsc_envs:..."`` in an interpreter that never imported the package;
* ``reset(seed=...)`` makes everything reproducible (also with ``randomize=True``, whose draws
  stay inside the documented ranges), and different seeds give different episodes;
* the observation is the named, ``float32`` view of the loop at t_k: e_1, σ, z, x̂_2 and the
  eq. (27) statistic agree with the loop's signals, and the transmission clock restarts at one
  sampling period after a transmission and grows by one period per held step;
* ``info``, episode metrics, truncation at ``horizon_s`` and the reward
  ``-cost/cost_scale - transmission_penalty * transmitted`` follow the design page, and the cost
  and the paper's metrics E_v, E_q (eq. 50), T_A (eq. 51), E_c (eq. 52) follow their definitions;
* physics: transmitting at every instant, the tracking error of the paper's scenario converges,
  the ESO's x̂_2 tracks the total disturbance x_2 = ż - J0⁻¹u (itself checked against a finite
  difference of z) and x̂_1 tracks x_1; plant quaternions stay unit; the desired attitude
  integrates the square-wave ω_d of eqs. (54)-(55); ``uncertainties=False`` removes ΔJ and d;
* the paper's trigger with a larger Ψ transmits less;
* bad arguments and actions raise errors naming them; a diverging episode terminates cleanly.
"""

from __future__ import annotations

import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gymnasium_check_env
from numpy.testing import assert_allclose, assert_array_equal

import etsc_envs  # noqa: F401  (registers the ids)
from etsc_envs.core.metrics import COMMON_EPISODE_KEYS
from etsc_envs.triggers import AttitudeTrackingTrigger

ENV_ID = "etsc/AttitudeTracking-v0"
PERIOD_S = 0.001
INITIAL_ATTITUDE_ERROR = 0.4690  # |q_ev(0)| of the paper's q(0) = (0.3, -0.2, -0.3, 0.8832)

COMMON_METRIC_KEYS = set(COMMON_EPISODE_KEYS)
PAPER_METRIC_KEYS = {"E_v", "E_q", "T_A_ms", "E_c", "mean_input_norm"}
STEP_INFO_KEYS = {"transmitted", "transmissions", "time_s", "cost"}


# --------------------------------------------------------------------------- helpers
def make(**kwargs) -> gym.Env:
    """A fresh environment through the registry."""
    return gym.make(ENV_ID, **kwargs)


def components(obs: np.ndarray, env: gym.Env, prefix: str) -> np.ndarray:
    """The observation's ``prefix_x, prefix_y, prefix_z`` entries."""
    unwrapped = env.unwrapped
    return np.array([obs[unwrapped.observation_index(f"{prefix}_{axis}")] for axis in "xyz"])


def rms(signal: np.ndarray) -> float:
    """Root mean square of the vector norm over the leading (time) axis."""
    return float(np.sqrt(np.mean(np.sum(np.square(signal), axis=-1))))


def g1(y: np.ndarray, b: float) -> np.ndarray:
    """g_1(y) = b y + φ(y) with φ of eq. (18), written independently of the library."""
    return b * y + 0.25 * np.sin(np.clip(y, -np.pi / 2, np.pi / 2))


def paper_statistic(e1: np.ndarray, sigma: np.ndarray, epsilon: np.ndarray, b: float, c: float):
    """Σ_i Σ_j |α_ji(e_1i, σ_i)| / ε_min of eq. (27), with g_2(y) = c y."""
    alpha1 = g1(e1 + sigma, b) - g1(e1, b)
    alpha2 = c * sigma
    return (np.abs(alpha1).sum() + np.abs(alpha2).sum()) / epsilon.min()


def eq50_integrands(state: dict[str, np.ndarray]) -> tuple[float, float]:
    """(1/3) Σ|ω_i - ω_di| and (1/4) Σ|q_i - q_di| of eq. (50) at one instant."""
    rate = np.abs(state["omega"] - state["omega_d"]).sum() / 3.0
    attitude = np.abs(state["q"] - state["q_d"]).sum() / 4.0
    return float(rate), float(attitude)


def run_to_end(env: gym.Env, policy, seed: int = 0) -> dict:
    """Run ``policy`` (an SB3-style trigger) until the episode ends; return the last info."""
    obs, _ = env.reset(seed=seed)
    while True:
        action, _ = policy.predict(obs)
        obs, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            return info


def only_infinite_bound_warnings(caught: list[warnings.WarningMessage]) -> list[str]:
    """Messages of caught warnings other than the checkers' note about infinite Box bounds."""
    return [str(w.message) for w in caught if "infinity" not in str(w.message)]


# --------------------------------------------------------------------------- fixtures
@pytest.fixture(scope="module")
def always_run() -> dict:
    """15 s of the paper's scenario transmitting at every instant, sampled every 10 ms."""
    env = make(horizon_s=15.0)
    unwrapped = env.unwrapped
    env.reset(seed=0)
    samples = [unwrapped.state_dict()]
    info: dict = {}
    for step in range(1, unwrapped.n_steps + 1):
        _, _, terminated, truncated, info = env.step(1)
        assert not terminated, info.get("failure")
        if step % 10 == 0:
            samples.append(unwrapped.state_dict())
    assert truncated
    trace = {key: np.array([s[key] for s in samples]) for key in samples[0]}
    return {"trace": trace, "metrics": info["episode_metrics"]}


# --------------------------------------------------------------------------- API checkers
@pytest.mark.parametrize(
    "kwargs", [{}, {"reference": "square", "randomize": True}], ids=["paper", "square-random"]
)
def test_passes_gymnasium_and_sb3_env_checkers(kwargs):
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = make(horizon_s=0.05, **kwargs)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gymnasium_check_env(env.unwrapped, skip_render_check=True)
        sb3_check_env(env.unwrapped, warn=True)
    assert only_infinite_bound_warnings(caught) == []


def test_id_resolves_in_a_fresh_interpreter():
    code = "\n".join(
        [
            "import sys, gymnasium",
            "assert 'etsc_envs' not in sys.modules",
            "env = gymnasium.make('etsc_envs:etsc/AttitudeTracking-v0', horizon_s=0.01)",
            "obs, info = env.reset(seed=0)",
            "steps, truncated = 0, False",
            "while not truncated:",
            "    obs, reward, terminated, truncated, info = env.step(1)",
            "    steps += 1",
            "print(steps, obs.shape[0], info['transmissions'])",
        ]
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["10", "14", "10"]


# --------------------------------------------------------------------------- reproducibility
def rollout_observations(env: gym.Env, seed: int, actions: np.ndarray) -> np.ndarray:
    """Observations of an episode reset with ``seed`` and driven by ``actions``."""
    obs, _ = env.reset(seed=seed)
    observations = [obs]
    for action in actions:
        obs, *_ = env.step(int(action))
        observations.append(obs)
    return np.array(observations)


def test_seeded_reset_reproduces_a_randomized_episode():
    actions = np.random.default_rng(0).integers(0, 2, size=300)
    first, second = make(randomize=True), make(randomize=True)
    reference = rollout_observations(first, 123, actions)
    assert_array_equal(rollout_observations(second, 123, actions), reference)
    # Resetting an env that already ran restores everything (observer, channel, clock).
    assert_array_equal(rollout_observations(first, 123, actions), reference)
    other, _ = second.reset(seed=124)
    assert not np.array_equal(other, reference[0])


def test_randomized_initial_conditions_stay_in_documented_ranges():
    env = make(randomize=True)
    unwrapped = env.unwrapped
    angles, rates, phases = [], [], []
    for seed in range(20):
        env.reset(seed=seed)
        state = unwrapped.state_dict()
        assert_allclose(np.linalg.norm(state["q"]), 1.0, atol=1e-12)
        angles.append(2.0 * np.arccos(min(abs(state["q"][3]), 1.0)))
        rates.append(state["omega"])
        phases.append(np.r_[unwrapped.model.inertia_phase, unwrapped.model.disturbance_phase])
    angles, rates, phases = np.array(angles), np.array(rates), np.array(phases)
    assert angles.max() <= np.deg2rad(60.0) + 1e-9
    assert np.abs(rates).max() <= 0.05
    assert phases.min() >= 0.0 and phases.max() < 2.0 * np.pi
    # The draws do vary from seed to seed.
    assert angles.std() > 0.05 and rates.std() > 0.005
    assert np.all(phases.std(axis=0) > 0.5)  # each ΔJ and d phase is drawn


def test_default_reset_is_the_paper_initial_point():
    env = make()
    env.reset(seed=0)
    state = env.unwrapped.state_dict()
    paper_q0 = np.array([0.3, -0.2, -0.3, 0.8832])
    assert_allclose(state["q"], paper_q0 / np.linalg.norm(paper_q0), atol=1e-12)
    assert_allclose(state["omega"], 0.0, atol=0.0)
    assert_allclose(state["q_d"], [0.0, 0.0, 0.0, 1.0], atol=0.0)
    assert_allclose(np.linalg.norm(state["q_e"][:3]), INITIAL_ATTITUDE_ERROR, atol=1e-3)


# --------------------------------------------------------------------------- observation
def test_observation_names_match_the_space():
    env = make(horizon_s=0.05)
    names = env.unwrapped.observation_names
    assert len(names) == env.observation_space.shape[0] == len(set(names))
    assert env.observation_space.dtype == np.float32
    for name in (
        "trigger_statistic",
        "time_since_transmission_s",
        "e1_x",
        "e1_y",
        "e1_z",
        "sigma_x",
        "sigma_y",
        "sigma_z",
        "z_x",
        "x2_hat_x",
    ):
        assert name in names
    obs, _ = env.reset(seed=0)
    assert obs.dtype == np.float32 and obs in env.observation_space


def test_observation_components_are_the_loop_signals():
    env = make(horizon_s=0.5, randomize=True)
    unwrapped = env.unwrapped
    epsilon = np.array(unwrapped.params.observer_epsilon)
    b, c = unwrapped.params.observer_b, unwrapped.params.observer_c
    actions = np.random.default_rng(1).random(500) < 0.05
    obs, _ = env.reset(seed=7)
    statistics = []
    for action in actions:
        obs, *_ = env.step(int(action))
        assert obs.dtype == np.float32 and obs in env.observation_space
        state = unwrapped.state_dict()
        e1 = (state["x1"] - state["x1_hat"]) / epsilon
        sigma = (state["xi"] - state["x1"]) / epsilon
        assert_allclose(components(obs, env, "z"), state["x1"], rtol=1e-6, atol=1e-7)
        assert_allclose(components(obs, env, "x2_hat"), state["x2_hat"], rtol=1e-6, atol=1e-7)
        assert_allclose(components(obs, env, "e1"), e1, rtol=1e-5, atol=1e-6)
        assert_allclose(components(obs, env, "sigma"), sigma, rtol=1e-5, atol=1e-6)
        statistic = paper_statistic(e1, sigma, epsilon, b, c)
        assert_allclose(
            obs[unwrapped.observation_index("trigger_statistic")], statistic, rtol=1e-5, atol=1e-6
        )
        statistics.append(statistic)
    # Holding makes σ (and the statistic) grow away from zero: the check is not vacuous.
    assert max(statistics) > 0.1


def test_time_since_transmission_restarts_and_grows():
    env = make(horizon_s=0.05)
    clock = env.unwrapped.observation_index("time_since_transmission_s")
    actions = [1, 0, 0, 0, 1, 1, 0, 1, 0, 0, 0, 0, 0, 1]
    obs, _ = env.reset(seed=0)
    assert obs[clock] == 0.0
    expected = 0.0
    for action in actions:
        obs, *_ = env.step(action)
        expected = PERIOD_S if action else expected + PERIOD_S
        assert_allclose(obs[clock], expected, rtol=1e-5)


def test_info_every_step_and_episode_metrics_at_the_end():
    env = make(horizon_s=0.05)
    actions = np.random.default_rng(2).integers(0, 2, size=50)
    actions[:2] = 1  # at least two transmissions, so inter-event statistics exist
    _, info = env.reset(seed=0)
    assert set(info) >= STEP_INFO_KEYS
    for k, action in enumerate(actions):
        _, _, terminated, truncated, info = env.step(int(action))
        assert set(info) >= STEP_INFO_KEYS
        assert info["transmitted"] == action
        assert info["transmissions"] == actions[: k + 1].sum()
        assert_allclose(info["time_s"], (k + 1) * PERIOD_S)
        assert np.isfinite(info["cost"]) and info["cost"] >= 0.0
        assert not terminated
        assert truncated == (k == len(actions) - 1)
        assert ("episode_metrics" in info) == truncated
    metrics = info["episode_metrics"]
    assert set(metrics) >= COMMON_METRIC_KEYS | PAPER_METRIC_KEYS
    assert metrics["steps"] == 50 and metrics["failure"] is None
    assert_allclose(metrics["sim_time_s"], 0.05)
    assert metrics["transmissions"] == actions.sum()
    assert_allclose(metrics["transmission_rate"], actions.mean())
    sent_at = np.flatnonzero(actions) * PERIOD_S
    assert_allclose(metrics["mean_interevent_s"], np.diff(sent_at).mean())
    assert_allclose(metrics["min_interevent_s"], np.diff(sent_at).min())
    assert_allclose(metrics["T_A_ms"], 1000.0 * 0.05 / actions.sum())


@pytest.mark.parametrize(
    ("horizon_s", "sampling_period_s", "steps"),
    [(0.05, 0.001, 50), (0.05, 0.002, 25), (0.03, 0.0005, 60)],
)
def test_truncates_exactly_at_the_horizon(horizon_s, sampling_period_s, steps):
    env = make(horizon_s=horizon_s, sampling_period_s=sampling_period_s)
    env.reset(seed=0)
    for k in range(1, steps + 1):
        _, _, terminated, truncated, info = env.step(k % 3 == 0)
        assert not terminated
        assert truncated == (k == steps)
    assert info["episode_metrics"]["steps"] == steps
    assert_allclose(info["time_s"], horizon_s)


def test_reward_and_cost_follow_their_definitions():
    penalty, scale = 0.37, 0.05
    env = make(horizon_s=0.1, transmission_penalty=penalty, cost_scale=scale)
    unwrapped = env.unwrapped
    env.reset(seed=0)
    for k in range(100):
        action = int(k % 4 == 0)
        _, reward, _, _, info = env.step(action)
        rate, attitude = eq50_integrands(unwrapped.state_dict())
        assert_allclose(info["cost"], rate + attitude, rtol=1e-12)
        assert_allclose(reward, -info["cost"] / scale - penalty * action, rtol=1e-12)


# --------------------------------------------------------------------------- physics
def test_always_transmitting_tracks_the_reference(always_run):
    trace = always_run["trace"]
    attitude_error = np.linalg.norm(trace["q_e"][:, :3], axis=1)
    rate_error = np.linalg.norm(trace["omega_e"], axis=1)
    assert_allclose(attitude_error[0], INITIAL_ATTITUDE_ERROR, atol=1e-3)
    assert attitude_error[-1] < 0.01
    assert rate_error[-1] < 0.01
    assert always_run["metrics"]["transmissions"] == always_run["metrics"]["steps"] == 15000


def test_desired_rate_is_the_sinusoid_of_eq_53(always_run):
    trace = always_run["trace"]
    t = trace["time_s"][:, None]
    expected = 0.05 * np.sin(np.pi * np.array([1.0, 2.0, 3.0]) * t / 20.0)
    assert_allclose(trace["omega_d"], expected, atol=1e-15)
    # The spacecraft follows it: ω - ω_d is small at the end (ω_d itself is 0.05 rad/s scale).
    assert np.abs(trace["omega"][-1] - trace["omega_d"][-1]).max() < 5e-3


def test_eso_estimates_track_the_extended_states(always_run):
    trace = always_run["trace"]
    settled = trace["time_s"] > 5.0
    x2, x2_hat = trace["x2"][settled], trace["x2_hat"][settled]
    # Measured ratio ≈ 0.3 with the paper's ε = 0.4: x̂_2 follows x_2 up to a lag.
    assert rms(x2 - x2_hat) < 0.5 * rms(x2)
    x1, x1_hat = trace["x1"], trace["x1_hat"]
    # x̂_1 starts on the first measurement and stays within 3 mrad/s once settled
    # (measured max 2.9e-3; |x_1(0)| ≈ 0.93 rad/s).
    assert_allclose(x1_hat[0], x1[0], atol=1e-12)
    assert np.linalg.norm(x1[settled] - x1_hat[settled], axis=1).max() < 5e-3
    assert np.linalg.norm(x1[0]) > 0.9


def test_total_disturbance_is_z_dot_minus_nominal_input():
    """x_2 = ż - J0⁻¹u (eqs. 10, 14-15), against a backward difference of z along the run."""
    env = make(horizon_s=2.0, randomize=True)
    unwrapped = env.unwrapped
    inverse_nominal = np.linalg.inv(np.array(unwrapped.params.nominal_inertia))
    env.reset(seed=3)
    previous = unwrapped.state_dict()["x1"]
    errors, magnitudes = [], []
    for k in range(unwrapped.n_steps):
        env.step(int(k % 7 == 0))
        state = unwrapped.state_dict()
        z_dot = (state["x1"] - previous) / PERIOD_S
        errors.append(np.abs(z_dot - inverse_nominal @ state["u"] - state["x2"]).max())
        magnitudes.append(np.abs(state["x2"]).max())
        previous = state["x1"]
    # O(h) difference error (measured ≤ 1e-3) against a signal of median size ≈ 0.08.
    assert max(errors) < 3e-3
    assert np.median(magnitudes) > 0.02


def test_quaternions_stay_unit_and_mean_cost_is_ev_plus_eq(always_run):
    trace, metrics = always_run["trace"], always_run["metrics"]
    assert_allclose(np.linalg.norm(trace["q"], axis=1), 1.0, atol=1e-9)
    assert_allclose(np.linalg.norm(trace["q_d"], axis=1), 1.0, atol=1e-9)
    assert_allclose(metrics["mean_cost"], metrics["E_v"] + metrics["E_q"], rtol=1e-9)


def test_paper_metrics_follow_equations_50_to_52():
    env = make(horizon_s=1.0)
    unwrapped = env.unwrapped
    trigger = AttitudeTrackingTrigger(
        env.observation_space, env.action_space, unwrapped.observation_names, psi=0.1
    )
    obs, _ = env.reset(seed=0)
    omega = [unwrapped.state_dict()["omega"]]
    rate_errors, attitude_errors, input_norms, sent = [], [], [], 0
    truncated = False
    while not truncated:
        action, _ = trigger.predict(obs)
        obs, _, _, truncated, info = env.step(action)
        state = unwrapped.state_dict()
        rate, attitude = eq50_integrands(state)
        rate_errors.append(rate)
        attitude_errors.append(attitude)
        input_norms.append(np.abs(state["u"]).sum())
        omega.append(state["omega"])
        sent += int(action)
    metrics = info["episode_metrics"]
    assert 1 < sent < 1000
    assert_allclose(metrics["E_v"], np.mean(rate_errors), rtol=1e-10)
    assert_allclose(metrics["E_q"], np.mean(attitude_errors), rtol=1e-10)
    assert_allclose(metrics["mean_cost"], metrics["E_v"] + metrics["E_q"], rtol=1e-10)
    assert_allclose(metrics["T_A_ms"], 1000.0 * 1.0 / sent, rtol=1e-10)
    assert_allclose(metrics["mean_input_norm"], np.mean(input_norms), rtol=1e-10)
    kinetic = 0.5 * np.square(np.array(omega))
    assert_allclose(metrics["E_c"], np.abs(np.diff(kinetic, axis=0)).sum(), rtol=1e-10)


def test_desired_attitude_integrates_the_square_wave():
    """q_d from identity under constant ω_d is exp(ω_d t/2); the sign flip at T undoes it."""
    switch_s = 0.5
    env = make(horizon_s=2 * switch_s, reference="square", square_switch_period_s=switch_s)
    unwrapped = env.unwrapped
    levels = np.array(unwrapped.params.square_levels)
    speed = np.linalg.norm(levels)
    env.reset(seed=0)
    for step in range(1, unwrapped.n_steps + 1):
        env.step(0)
        state = unwrapped.state_dict()
        t = state["time_s"]
        if step == 400:
            half_angle = 0.5 * speed * t
            expected = np.r_[np.sin(half_angle) * levels / speed, np.cos(half_angle)]
            assert_allclose(state["q_d"], expected, atol=1e-12)
            assert_allclose(state["omega_d"], levels)
        if step == 700:
            assert_allclose(state["omega_d"], -levels)
    assert_allclose(state["q_d"], [0.0, 0.0, 0.0, 1.0], atol=2e-5)


def test_without_uncertainties_the_disturbance_is_zero():
    quiet, disturbed = make(horizon_s=1.0, uncertainties=False), make(horizon_s=1.0)
    for env in (quiet, disturbed):
        env.reset(seed=0)
    assert_array_equal(quiet.unwrapped.model.disturbance_amplitude, np.zeros(3))
    assert_array_equal(quiet.unwrapped.model.inertia_amplitude, np.zeros(3))
    assert np.all(disturbed.unwrapped.model.disturbance_amplitude > 0)
    for _ in range(1000):
        quiet_obs, *_ = quiet.step(1)
        disturbed_obs, *_ = disturbed.step(1)
    assert not np.allclose(quiet_obs, disturbed_obs, rtol=0.0, atol=1e-4)


def free_rate_section_4(duration_s: float, h: float = 1e-3) -> np.ndarray:
    """ω(duration_s) of eq. (1) with u = 0 from rest, ΔJ and d of section 4 (numpy RK4)."""
    nominal = np.array([[20.0, 1.2, 0.9], [1.2, 17.0, 1.4], [0.9, 1.4, 15.0]])
    weights = np.array([0.1, 0.2, 0.3])

    def rate_derivative(t: float, omega: np.ndarray) -> np.ndarray:
        inertia = nominal + np.diag(np.array([1.0, 2.0, 3.0]) * np.sin(weights * t))
        torque = weights * np.sin(weights * t) - np.cross(omega, inertia @ omega)
        return np.linalg.solve(inertia, torque)

    omega, t = np.zeros(3), 0.0
    for _ in range(round(duration_s / h)):
        k1 = rate_derivative(t, omega)
        k2 = rate_derivative(t + h / 2, omega + h / 2 * k1)
        k3 = rate_derivative(t + h / 2, omega + h / 2 * k2)
        k4 = rate_derivative(t + h, omega + h * k3)
        omega, t = omega + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), t + h
    return omega


@pytest.mark.parametrize("uncertainties", [False, True])
def test_spacecraft_at_rest_moves_only_under_uncertainties(uncertainties):
    """ω_d = 0, q(0) = q_d(0), ω(0) = 0 and no transmission after t_0: x̂ stays 0, so u = 0
    and only ΔJ(t) and d(t) of section 4 move the spacecraft, as eq. (1) says."""
    env = make(
        horizon_s=2.0,
        reference="square",
        square_levels=(0.0, 0.0, 0.0),
        initial_attitude=(0.0, 0.0, 0.0, 1.0),
        uncertainties=uncertainties,
    )
    unwrapped = env.unwrapped
    env.reset(seed=0)
    for _ in range(unwrapped.n_steps):
        env.step(0)
        assert_array_equal(unwrapped.state_dict()["u"], np.zeros(3))
    state = unwrapped.state_dict()
    if uncertainties:
        expected = free_rate_section_4(2.0)
        assert np.abs(expected).min() > 1e-4
        assert_allclose(state["omega"], expected, rtol=1e-6)
        assert np.abs(state["x2"]).min() > 1e-4
    else:
        assert_array_equal(state["x2"], np.zeros(3))
        assert_array_equal(state["omega"], np.zeros(3))
        assert_array_equal(state["q"], [0.0, 0.0, 0.0, 1.0])


def test_larger_psi_transmits_less():
    transmissions = {}
    for psi in (0.1, 1.5):
        env = make(horizon_s=10.0)
        trigger = AttitudeTrackingTrigger(
            env.observation_space, env.action_space, env.unwrapped.observation_names, psi=psi
        )
        info = run_to_end(env, trigger)
        assert info["episode_metrics"]["failure"] is None
        transmissions[psi] = info["transmissions"]
    assert transmissions[1.5] < transmissions[0.1] < 0.1 * 10_000
    assert transmissions[1.5] > 0


# --------------------------------------------------------------------------- errors
@pytest.mark.parametrize(
    ("kwargs", "named"),
    [
        ({"sampling_period_s": -0.001}, "sampling_period_s"),
        ({"horizon_s": 0}, "horizon_s"),
        ({"nominal_inertia": ((20, 1.2, 0.9), (1.0, 17, 1.4), (0.9, 1.4, 15))}, "nominal_inertia"),
        ({"nominal_inertia": ((1, 0, 0), (0, -1, 0), (0, 0, 1))}, "nominal_inertia"),
        ({"nominal_inertia": ((1, 0), (0, 1))}, "nominal_inertia"),
        ({"reference": "triangle"}, "reference"),
        ({"observer_epsilon": (0.4, 0.4)}, "observer_epsilon"),
        ({"observer_epsilon": (0.4, 0.0, 0.4)}, "observer_epsilon"),
        ({"initial_attitude": (1, 1, 0, 0)}, "initial_attitude"),
        ({"transmission_penalty": -1}, "transmission_penalty"),
        ({"cost_scale": 0}, "cost_scale"),
        ({"observer_b": 1.0, "observer_c": 5.0}, "observer_b"),
        ({"observer_b": 3.5}, "observer_b"),
    ],
)
def test_bad_constructor_argument_is_named(kwargs, named):
    with pytest.raises(ValueError, match=named):
        make(**kwargs)


def test_unknown_keyword_is_a_type_error():
    with pytest.raises(TypeError, match="horizon"):
        make(horizon=1.0)


@pytest.mark.parametrize("action", [2, -1, "x", [1, 1], 0.5])
def test_bad_action_is_rejected(action):
    env = make(horizon_s=0.05)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(action)


def test_step_after_truncation_raises():
    env = make(horizon_s=0.002)
    env.reset(seed=0)
    env.step(1)
    assert env.step(1)[3]
    with pytest.raises(RuntimeError):
        env.step(1)
    env.reset(seed=0)
    env.step(0)  # a reset starts a new episode


# --------------------------------------------------------------------------- failure
def test_divergence_terminates_the_episode():
    env = make(max_rate_rad_s=0.05)
    obs, _ = env.reset(seed=0)
    for _ in range(env.unwrapped.n_steps):
        obs, reward, terminated, truncated, info = env.step(1)
        if terminated or truncated:
            break
    assert terminated and not truncated
    assert info["failure"].startswith("diverged")
    assert np.all(np.isfinite(obs)) and np.isfinite(reward)
    metrics = info["episode_metrics"]
    assert metrics["failure"] == info["failure"]
    assert metrics["steps"] < env.unwrapped.n_steps
    with pytest.raises(RuntimeError):
        env.step(1)


def test_terminal_observation_is_a_new_array():
    env = make(max_rate_rad_s=0.05).unwrapped
    previous, _ = env.reset(seed=0)
    terminated = False
    while not terminated:
        terminal, _, terminated, truncated, _ = env.step(1)
        assert not truncated
        assert not np.shares_memory(terminal, previous)
        previous = terminal


def test_rate_bound_above_the_rate_transient_does_not_terminate():
    env = make(horizon_s=1.5, max_rate_rad_s=0.8)
    unwrapped = env.unwrapped
    env.reset(seed=0)
    peak = 0.0
    for _ in range(unwrapped.n_steps):
        _, _, terminated, truncated, info = env.step(1)
        state = unwrapped.state_dict()
        peak = max(peak, np.linalg.norm(state["omega"]), np.linalg.norm(state["omega_e"]))
        if terminated or truncated:
            break
    assert peak < 0.8
    assert not terminated, info.get("failure")


def test_inertia_by_rows_gives_the_array_arithmetic_bit_for_bit():
    """J(t) = J0 + ΔJ(t) of section 4 is built as rows, with no array made per call
    (docs/performance.md): its entries are J0's with ΔJ(t) on the diagonal, and ω̇ of eq. (1)
    from it equals, bit for bit, the same products and solve on J(t) as a 3×3 array."""
    from etsc_envs.attitude_tracking.closed_loop import episode_model
    from etsc_envs.attitude_tracking.dynamics import disturbance, inertia, rate_derivative_given
    from etsc_envs.core import vec3

    env = make(randomize=True)
    env.reset(seed=5)
    model = episode_model(env.unwrapped.state, env.unwrapped.constants)
    rng = np.random.default_rng(1)
    for _ in range(20):
        t = float(rng.uniform(0.0, 50.0))
        omega, torque = tuple(rng.normal(scale=0.1, size=3)), tuple(rng.normal(size=3))
        rows = inertia(t, model)
        variation = vec3.sine_wave(
            model.inertia_amplitude, model.inertia_frequency, t, model.inertia_phase
        )
        array = model.nominal_inertia.copy()
        array[np.diag_indices(3)] += variation
        assert_array_equal(np.array(rows), array)
        d = disturbance(t, model)
        gyroscopic = vec3.cross(omega, vec3.matvec(array, omega))
        by_array = vec3.solve(array, vec3.add(vec3.add(vec3.negate(gyroscopic), torque), d))
        assert rate_derivative_given(rows, d, omega, torque) == by_array


def test_plant_step_evaluates_the_half_step_terms_once_bit_for_bit():
    """The RK4 step of eq. (1)-(2) computes ω_d, J and d at t + h/2 once for its two middle
    stages: it equals, bit for bit, the classical RK4 that computes every stage's terms at its
    own time (so the shared evaluation changes no record)."""
    from etsc_envs.attitude_tracking.closed_loop import episode_model, integrate_plant
    from etsc_envs.attitude_tracking.dynamics import plant_derivative, plant_time_terms

    env = make(randomize=True)
    env.reset(seed=3)
    loop = env.unwrapped
    model = episode_model(loop.state, loop.constants)
    rng = np.random.default_rng(0)
    h = loop.sampling_period_s
    for _ in range(20):
        t = float(rng.uniform(0.0, 50.0))
        y = np.concatenate([rng.normal(size=4), rng.normal(scale=0.1, size=3), rng.normal(size=4)])
        args = (rng.normal(size=3), model)

        def k(time_s: float, stage: np.ndarray) -> np.ndarray:
            return plant_derivative(plant_time_terms(time_s, args), stage, args)  # noqa: B023

        k1 = k(t, y)
        k2 = k(t + 0.5 * h, y + 0.5 * h * k1)
        k3 = k(t + 0.5 * h, y + 0.5 * h * k2)
        k4 = k(t + h, y + h * k3)
        expected = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        assert_array_equal(integrate_plant(t, y, h, args), expected)

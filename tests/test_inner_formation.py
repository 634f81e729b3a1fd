"""``etsc/InnerFormation-v0`` (paper 004, Hao & Zhang 2024): model, observer theory, contracts.

Checked properties:

* eq. (2) as implemented equals its component form; the observer polynomial (A4) for the
  paper's β is Hurwitz and P of (A3) is a valid Lyapunov certificate;
* every axis's closed loop (plant, ESO eq. 3, feedback eqs. 15-16) is stable, read from the
  Jacobian of the implemented loop;
* without disturbance the continuous ESO (``always``) converges to the true state and r → 0;
  with the paper's Δa the steady estimation errors lie inside Theorem 1's bounds (8)-(10);
* the paper's trigger: a smaller Π transmits more and estimates better, and the measured
  minimum inter-event time respects (A24);
* Gymnasium and SB3 checkers, determinism under a seed, per-axis channel bookkeeping, the
  reward definition, the failure path and argument errors.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import etsc_envs  # noqa: F401  (registers the ids)
from etsc_envs.inner_formation import InnerFormationEnv, InnerFormationParams
from etsc_envs.inner_formation.closed_loop import loop_derivative
from etsc_envs.inner_formation.design import estimation_bounds, observer_certificate
from etsc_envs.inner_formation.dynamics import lumped_term
from etsc_envs.triggers.inner_formation import InnerFormationTrigger, default_thresholds

ENV_ID = "etsc/InnerFormation-v0"


def run(env: InnerFormationEnv, policy=None, seed: int = 0) -> dict:
    """Run one episode (``policy=None`` transmits every axis at every instant)."""
    obs, _ = env.reset(seed=seed)
    while True:
        action = np.ones(3, dtype=np.int64) if policy is None else policy.predict(obs)[0]
        obs, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            return info["episode_metrics"]


def paper_trigger(env: InnerFormationEnv, scale: float = 1.0) -> InnerFormationTrigger:
    pi1, pi2, pi3 = scale * default_thresholds()
    return InnerFormationTrigger(
        env.observation_space, env.action_space, env.observation_names, pi1=pi1, pi2=pi2, pi3=pi3
    )


# --------------------------------------------------------------------------- model and theory
def test_lumped_term_matches_the_component_form_of_eq_2():
    env = InnerFormationEnv()
    env.reset()
    n1, n2, n3 = env.params.orbit_rate
    rng = np.random.default_rng(0)
    r, v = rng.normal(size=3), rng.normal(size=3)
    t = 1.7
    delta_a = np.array(env.params.disturbance_amplitude) * np.sin(
        np.array(env.params.disturbance_frequency) * t + np.array(env.params.disturbance_phase)
    )
    expected = delta_a + np.array(
        [
            2 * n3 * v[1]
            - 2 * n2 * v[2]
            + (n3**2 + n2**2) * r[0]
            - n2 * n1 * r[1]
            - n3 * n1 * r[2],
            -2 * n3 * v[0]
            + 2 * n1 * v[2]
            - n2 * n1 * r[0]
            + (n3**2 + n1**2) * r[1]
            - n3 * n2 * r[2],
            2 * n2 * v[0]
            - 2 * n1 * v[1]
            - n3 * n1 * r[0]
            - n3 * n2 * r[1]
            + (n2**2 + n1**2) * r[2],
        ]
    )
    assert_allclose(lumped_term(t, r, v, env.model), expected, rtol=1e-12, atol=1e-15)


def test_observer_polynomial_is_hurwitz_and_p_certifies_it():
    beta = InnerFormationParams().observer_beta
    certificate = observer_certificate(beta)
    assert np.all(certificate.characteristic_roots.real < 0.0)
    closed = np.diag([1.0, 1.0], 1) - np.outer(beta, [1.0, 0.0, 0.0])
    p = certificate.lyapunov_matrix
    assert np.all(np.linalg.eigvalsh(p) > 0.0)
    assert_allclose(p @ closed + closed.T @ p, -np.eye(3), atol=1e-12)
    with pytest.raises(ValueError, match="Hurwitz"):
        observer_certificate((1.0, 0.5, 1.0))  # b1 b2 < b3


def test_each_axis_closed_loop_is_stable():
    """Eigenvalues of the implemented loop's Jacobian (n = 0, Δa = 0, continuous sampling)."""
    env = InnerFormationEnv(orbit_rate=(0.0, 0.0, 0.0), disturbance_amplitude=(0.0, 0.0, 0.0))
    env.reset()

    def derivative(y):
        return loop_derivative(0.0, y, (y[0:3].copy(), env.model, env.design))

    jacobian = np.empty((15, 15))
    for column in range(15):
        step = np.zeros(15)
        step[column] = 1e-6
        jacobian[:, column] = (derivative(step) - derivative(-step)) / 2e-6
    eigenvalues = np.linalg.eigvals(jacobian)
    assert eigenvalues.real.max() < -0.03  # the slowest axis: s² + 0.07 s + 0.05


# --------------------------------------------------------------------------- closed loop
def test_continuous_observer_is_exact_without_disturbance():
    env = InnerFormationEnv(
        orbit_rate=(0.0, 0.0, 0.0), disturbance_amplitude=(0.0, 0.0, 0.0), horizon_s=150.0
    )
    metrics = run(env)
    # What remains is the zero-order hold of r over one period, |ṙ| t_s ~ 1e-8 m here.
    assert metrics["ss_pos_est_err_m"] < 1e-7
    assert metrics["ss_dist_est_err_mps2"] < 1e-8
    assert metrics["ss_pos_err_m"] < 3e-4  # from 17 mm; the slowest axis decays as e^(-0.035 t)


@pytest.fixture(scope="module")
def event_triggered_runs():
    """The paper trigger at Π/2, Π and 2Π over 60 s (steady window: the last 12 s)."""
    records = {}
    for scale in (0.5, 1.0, 2.0):
        env = InnerFormationEnv(horizon_s=60.0)
        records[scale] = run(env, paper_trigger(env, scale))
    return records


def test_steady_errors_lie_inside_theorem_1_bounds(event_triggered_runs):
    params = InnerFormationParams()
    bounds = estimation_bounds(params, default_thresholds())
    record = event_triggered_runs[1.0]
    assert record["failure"] is None
    assert np.all(np.array(record["ss_pos_est_err_m_per_axis"]) < bounds["position_m"])
    assert np.all(np.array(record["ss_vel_est_err_mps_per_axis"]) < bounds["velocity_mps"])
    assert np.all(np.array(record["ss_dist_est_err_mps2_per_axis"]) < bounds["disturbance_mps2"])
    # The bounds the env reports use the largest sampling error it saw, at least Π.
    assert np.all(np.array(record["max_sampling_error_m_per_axis"]) >= default_thresholds())


def test_smaller_threshold_transmits_more_and_estimates_better(event_triggered_runs):
    fine, middle, coarse = (event_triggered_runs[s] for s in (0.5, 1.0, 2.0))
    assert fine["transmissions"] > middle["transmissions"] > coarse["transmissions"]
    assert fine["ss_pos_est_err_m"] < middle["ss_pos_est_err_m"] < coarse["ss_pos_est_err_m"]
    assert middle["transmission_rate"] < 0.05


def test_interevent_times_respect_the_zeno_bound(event_triggered_runs):
    for record in event_triggered_runs.values():
        measured = np.array(record["min_interevent_s_per_axis"])
        bound = np.array(record["zeno_bound_s_per_axis"])
        assert np.all(bound > 0.0)
        assert np.all(measured >= bound)


# --------------------------------------------------------------------------- contracts
def test_environment_checkers():
    from gymnasium.utils.env_checker import check_env
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    check_env(gym.make(ENV_ID, horizon_s=0.05).unwrapped, skip_render_check=True)
    sb3_check_env(gym.make(ENV_ID, horizon_s=0.05, randomize=True).unwrapped)


def test_seeded_resets_are_reproducible():
    actions = np.random.default_rng(3).integers(0, 2, size=(300, 3))
    runs = []
    for _ in range(2):
        env = gym.make(ENV_ID, randomize=True, horizon_s=1.0)
        obs, _ = env.reset(seed=11)
        observations = [obs]
        for action in actions:
            observations.append(env.step(action)[0])
        runs.append(np.array(observations))
    assert_array_equal(runs[0], runs[1])
    other, _ = gym.make(ENV_ID, randomize=True).reset(seed=12)
    assert not np.array_equal(other, runs[0][0])


def test_transmitting_one_axis_refreshes_only_that_axis():
    env = InnerFormationEnv(horizon_s=1.0)
    obs, _ = env.reset(seed=0)
    error = slice(0, 3)
    clock = [env.observation_index(f"time_since_transmission_s_{i}") for i in range(3)]
    for _ in range(50):
        obs, *_ = env.step(np.zeros(3, dtype=np.int64))
    assert np.all(np.abs(obs[error]) > 0.0)
    obs, reward, _, _, info = env.step(np.array([0, 1, 0]))
    assert info["transmitted"] == 1
    assert_array_equal(env.transmissions, [0, 1, 0])
    assert abs(obs[1]) < abs(obs[0]) and abs(obs[1]) < abs(obs[2])
    assert_allclose(obs[clock], [0.051, 0.001, 0.051], atol=1e-6)
    assert_allclose(reward, -info["cost"] / env.cost_scale - env.transmission_penalty, rtol=1e-6)


def test_leaving_the_cavity_terminates_with_a_reason():
    env = InnerFormationEnv(initial_velocity_mps=(0.2, 0.0, 0.0))
    obs, _ = env.reset()
    while True:
        obs, reward, terminated, truncated, info = env.step(np.ones(3, dtype=np.int64))
        if terminated or truncated:
            break
    assert terminated and not truncated
    assert info["failure"].startswith("collision")
    assert np.all(np.isfinite(obs)) and np.isfinite(reward)
    assert info["episode_metrics"]["failure"] == info["failure"]


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"sampling_period_s": -0.001}, "sampling_period_s"),
        ({"horizon_s": 0.0}, "horizon_s"),
        ({"observer_beta": (1.0, 0.5, 1.0)}, "observer_beta"),
        ({"observer_gain": (6.0, 0.0, 6.0)}, "observer_gain"),
        ({"feedback_gains": ((1.0, 2.0), (1.0, 2.0), (1.0, 2.0))}, "feedback_gains"),
        ({"initial_position_m": (0.1, 0.0, 0.0)}, "initial_position_m"),
        ({"observer_start": "middle"}, "observer_start"),
        ({"lyapunov_sigma": 1.5}, "lyapunov_sigma"),
        ({"transmission_penalty": -1.0}, "transmission_penalty"),
    ],
)
def test_bad_arguments_name_themselves(kwargs, name):
    with pytest.raises(ValueError, match=name):
        InnerFormationEnv(**kwargs)


def test_bad_thresholds_and_actions_are_rejected():
    env = InnerFormationEnv(horizon_s=0.01)
    with pytest.raises(ValueError, match="pi"):
        InnerFormationTrigger(env.observation_space, env.action_space, env.observation_names, pi=0)
    env.reset()
    with pytest.raises(ValueError, match="action"):
        env.step(1)

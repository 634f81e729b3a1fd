"""Algebraic and kinematic identities of the rotation module :mod:`etsc_envs.core.rotations`.

Checked properties (on ~50 seeded random quaternions / rotation vectors each):

* the Hamilton product is associative and ``q ⊗ q* = [0, 0, 0, 1]`` for unit ``q``;
* ``attitude_matrix(q)`` is a proper rotation (orthonormal, det +1), follows the documented
  passive convention (R-frame components to B-frame components, ``q`` = B relative to R) and
  composes as ``A(p ⊗ q) = A(q) A(p)`` (``p`` = B/R, ``q`` = C/B gives ``p ⊗ q`` = C/R);
* ``so3_exp(φ) = attitude_matrix(q(φ))ᵀ`` and ``so3_log`` inverts it for ``‖φ‖ < π``, including
  tiny angles and angles within 1e-4 of π; ``se3_log`` inverts ``se3_exp`` and ``se3_inverse``
  is the group inverse;
* MRPs: ``q`` and ``-q`` share one MRP set with ``‖σ‖ ≤ 1``, the quaternion round trip holds up
  to sign, and ``σ̇ = G(σ) ω`` agrees with a finite difference along the quaternion kinematics;
* the quaternion kinematics preserve the norm and integrate a constant body rate exactly;
* ``error_quaternion`` matches the explicit component formula of the attitude-tracking paper;
* ``solve3``, ``skew`` and ``cross`` agree with NumPy.
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.rotations import (
    attitude_matrix,
    cross,
    error_quaternion,
    mrp_kinematics_matrix,
    mrp_to_quat,
    quat_conjugate,
    quat_from_rotation_vector,
    quat_kinematics,
    quat_multiply,
    quat_normalize,
    quat_to_mrp,
    se3_exp,
    se3_inverse,
    se3_log,
    skew,
    so3_exp,
    so3_log,
    solve3,
)

N_SAMPLES = 50
IDENTITY_QUAT = np.array([0.0, 0.0, 0.0, 1.0])


def random_unit_quaternions(seed: int, n: int = N_SAMPLES) -> np.ndarray:
    """Uniformly distributed unit quaternions (normalised Gaussian 4-vectors)."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def random_rotation_vectors(seed: int, n: int = N_SAMPLES, max_angle: float = 0.999 * np.pi):
    """Rotation vectors with uniformly random axis and angle in ``[0, max_angle)``."""
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    return axes * rng.uniform(0.0, max_angle, size=(n, 1))


def random_vectors(seed: int, n: int = N_SAMPLES, scale: float = 1.0) -> np.ndarray:
    return scale * np.random.default_rng(seed).normal(size=(n, 3))


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


# --------------------------------------------------------------------------- vector helpers


def test_skew_and_cross_agree_with_numpy_cross():
    a_all, b_all = random_vectors(1), random_vectors(2)
    for a, b in zip(a_all, b_all, strict=True):
        expected = np.cross(a, b)
        assert_allclose(skew(a) @ b, expected, rtol=0, atol=1e-14)
        assert_allclose(cross(a, b), expected, rtol=0, atol=1e-14)
        assert_allclose(skew(a), -skew(a).T, rtol=0, atol=0)


def test_solve3_agrees_with_numpy_solve():
    rng = np.random.default_rng(3)
    for _ in range(N_SAMPLES):
        matrix = rng.normal(size=(3, 3)) + 3.0 * np.eye(3)
        assert np.linalg.cond(matrix) < 1e3
        rhs = rng.normal(size=3)
        x = solve3(matrix, rhs)
        assert_allclose(x, np.linalg.solve(matrix, rhs), rtol=1e-12, atol=1e-12)
        assert_allclose(matrix @ x, rhs, rtol=0, atol=1e-12)


# --------------------------------------------------------------------------- quaternion algebra


def test_quat_multiply_is_associative():
    ps, qs, rs = (
        random_unit_quaternions(10),
        random_unit_quaternions(11),
        random_unit_quaternions(12),
    )
    for p, q, r in zip(ps, qs, rs, strict=True):
        left = quat_multiply(quat_multiply(p, q), r)
        right = quat_multiply(p, quat_multiply(q, r))
        assert_allclose(left, right, rtol=0, atol=1e-14)


def test_quat_multiply_matches_documented_hamilton_formula():
    for p, q in zip(random_unit_quaternions(13), random_unit_quaternions(14), strict=True):
        expected = np.empty(4)
        expected[:3] = p[3] * q[:3] + q[3] * p[:3] + np.cross(p[:3], q[:3])
        expected[3] = p[3] * q[3] - p[:3] @ q[:3]
        assert_allclose(quat_multiply(p, q), expected, rtol=0, atol=1e-15)


def test_quaternion_times_conjugate_is_identity():
    for q in random_unit_quaternions(15):
        assert_allclose(quat_multiply(q, quat_conjugate(q)), IDENTITY_QUAT, rtol=0, atol=1e-15)
        assert_allclose(quat_multiply(quat_conjugate(q), q), IDENTITY_QUAT, rtol=0, atol=1e-15)
        assert_allclose(quat_multiply(IDENTITY_QUAT, q), q, rtol=0, atol=0)


def test_quat_normalize_gives_unit_norm_along_input():
    rng = np.random.default_rng(16)
    for raw in rng.normal(size=(N_SAMPLES, 4)) * 5.0:
        q = quat_normalize(raw)
        assert_allclose(np.linalg.norm(q), 1.0, rtol=0, atol=1e-15)
        assert_allclose(q * np.linalg.norm(raw), raw, rtol=1e-14, atol=1e-14)


# --------------------------------------------------------------------------- attitude matrix


def test_attitude_matrix_is_proper_orthonormal():
    for q in random_unit_quaternions(20):
        a = attitude_matrix(q)
        assert_allclose(a @ a.T, np.eye(3), rtol=0, atol=1e-14)
        assert_allclose(np.linalg.det(a), 1.0, rtol=0, atol=1e-14)
        # q and -q describe the same attitude.
        assert_allclose(attitude_matrix(-q), a, rtol=0, atol=0)


def test_attitude_matrix_is_passive_reference_to_body():
    """B rotated by θ about z_R: the R-frame x axis has B components [cos θ, -sin θ, 0]."""
    theta = 0.7
    q = np.array([0.0, 0.0, np.sin(theta / 2), np.cos(theta / 2)])
    a = attitude_matrix(q)
    assert_allclose(a @ [1.0, 0.0, 0.0], [np.cos(theta), -np.sin(theta), 0.0], atol=1e-15)
    assert_allclose(a @ [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], atol=1e-15)
    # The same quaternion built from the rotation vector θ z.
    assert_allclose(quat_from_rotation_vector(np.array([0.0, 0.0, theta])), q, atol=1e-15)


def test_attitude_matrix_composition_order():
    """With ``p`` = B/R and ``q`` = C/B, ``p ⊗ q`` = C/R, so ``A_CR = A_CB A_BR``."""
    for p, q in zip(random_unit_quaternions(21), random_unit_quaternions(22), strict=True):
        assert_allclose(
            attitude_matrix(quat_multiply(p, q)),
            attitude_matrix(q) @ attitude_matrix(p),
            rtol=0,
            atol=1e-14,
        )


def test_attitude_matrix_of_conjugate_is_transpose():
    for q in random_unit_quaternions(23):
        assert_allclose(attitude_matrix(quat_conjugate(q)), attitude_matrix(q).T, atol=1e-15)


# --------------------------------------------------------------------------- SO(3)


def test_so3_exp_is_transpose_of_attitude_matrix():
    for phi in random_rotation_vectors(30):
        assert_allclose(
            so3_exp(phi), attitude_matrix(quat_from_rotation_vector(phi)).T, rtol=0, atol=1e-14
        )


def test_quat_from_rotation_vector_is_unit_with_half_angle():
    for phi in random_rotation_vectors(31):
        q = quat_from_rotation_vector(phi)
        angle = np.linalg.norm(phi)
        assert_allclose(np.linalg.norm(q), 1.0, atol=1e-15)
        assert_allclose(q[3], np.cos(angle / 2), atol=1e-15)
        # A rotation about φ leaves φ itself unchanged.
        assert_allclose(so3_exp(phi) @ phi, phi, atol=1e-14)


def test_so3_log_inverts_so3_exp():
    for phi in random_rotation_vectors(32):
        assert_allclose(so3_log(so3_exp(phi)), phi, rtol=0, atol=1e-10)


@pytest.mark.parametrize("angle", [0.0, 1e-10, 1e-8, 1e-7, 1e-6, 1e-5, 1e-3])
def test_so3_log_small_angles(angle):
    for axis in random_vectors(33, n=10):
        phi = angle * unit(axis)
        assert_allclose(so3_log(so3_exp(phi)), phi, rtol=1e-9, atol=1e-16)
        assert_allclose(quat_from_rotation_vector(phi)[:3], 0.5 * phi, rtol=1e-6, atol=0)


@pytest.mark.parametrize("gap", [1e-3, 1e-4, 1e-7, 1e-8])
def test_so3_log_near_pi(gap):
    """Within 1e-4 of π the log still recovers φ to better than a micro-radian."""
    for axis in random_vectors(34, n=10):
        phi = (np.pi - gap) * unit(axis)
        rotation = so3_exp(phi)
        recovered = so3_log(rotation)
        assert_allclose(recovered, phi, rtol=0, atol=1e-6)
        assert_allclose(so3_exp(recovered), rotation, rtol=0, atol=1e-6)


@pytest.mark.parametrize("gap", [1e-4, 1e-5, 2e-6])
def test_so3_log_near_pi_is_accurate_to_conditioning(gap):
    """Best attainable accuracy near π is ~eps/gap (the axis read from a small sin(angle))."""
    for axis in random_vectors(34, n=10):
        phi = (np.pi - gap) * unit(axis)
        assert_allclose(so3_log(so3_exp(phi)), phi, rtol=0, atol=1e-8)


def test_so3_log_at_pi_gives_the_same_rotation():
    """At exactly π the axis sign is ambiguous: compare the rotations, not the vectors.

    The angle comes from ``atan2(sin, cos)``; the axis from the symmetric part of R.
    """
    for axis in random_vectors(35, n=20):
        phi = np.pi * unit(axis)
        rotation = so3_exp(phi)
        recovered = so3_log(rotation)
        assert_allclose(np.linalg.norm(recovered), np.pi, rtol=0, atol=1e-7)
        assert_allclose(np.abs(recovered @ unit(axis)), np.pi, rtol=0, atol=1e-7)
        assert_allclose(so3_exp(recovered), rotation, rtol=0, atol=1e-7)


# --------------------------------------------------------------------------- SE(3)


def random_twists(seed: int) -> np.ndarray:
    phis = random_rotation_vectors(seed)
    rhos = random_vectors(seed + 1000, scale=3.0)
    return np.hstack([phis, rhos])


def test_se3_log_inverts_se3_exp():
    for xi in random_twists(40):
        g = se3_exp(xi)
        assert_allclose(g[3], [0.0, 0.0, 0.0, 1.0], atol=0)
        assert_allclose(g[:3, :3], so3_exp(xi[:3]), atol=0)
        assert_allclose(se3_log(g), xi, rtol=0, atol=1e-10)


def test_se3_exp_of_pure_translation_and_tiny_rotation():
    xi = np.array([0.0, 0.0, 0.0, 1.0, -2.0, 3.0])
    expected = np.eye(4)
    expected[:3, 3] = xi[3:]
    assert_allclose(se3_exp(xi), expected, atol=0)
    xi_small = np.array([1e-10, -2e-10, 3e-10, 1.0, -2.0, 3.0])
    assert_allclose(se3_log(se3_exp(xi_small)), xi_small, rtol=1e-9, atol=1e-15)


def test_se3_inverse_is_group_inverse():
    for xi in random_twists(41):
        g = se3_exp(xi)
        assert_allclose(g @ se3_inverse(g), np.eye(4), rtol=0, atol=1e-13)
        assert_allclose(se3_inverse(g) @ g, np.eye(4), rtol=0, atol=1e-13)
        assert_allclose(se3_inverse(g), se3_exp(-xi), rtol=0, atol=1e-13)


# --------------------------------------------------------------------------- MRPs


def test_mrp_same_for_quaternion_and_its_negative_and_short():
    for q in random_unit_quaternions(50):
        sigma = quat_to_mrp(q)
        assert_allclose(quat_to_mrp(-q), sigma, rtol=0, atol=1e-15)
        assert np.linalg.norm(sigma) <= 1.0 + 1e-15


def test_mrp_quaternion_round_trip_up_to_sign():
    for q in random_unit_quaternions(51):
        q_back = mrp_to_quat(quat_to_mrp(q))
        assert_allclose(np.linalg.norm(q_back), 1.0, atol=1e-15)
        assert_allclose(q_back, np.sign(q[3]) * q, rtol=0, atol=1e-14)
        assert_allclose(attitude_matrix(q_back), attitude_matrix(q), rtol=0, atol=1e-14)


def test_mrp_of_rotation_vector_is_tan_quarter_angle():
    for phi in random_rotation_vectors(52):
        sigma = quat_to_mrp(quat_from_rotation_vector(phi))
        angle = np.linalg.norm(phi)
        assert_allclose(sigma, np.tan(angle / 4) * phi / angle, rtol=0, atol=1e-14)


def test_mrp_kinematics_matrix_matches_finite_difference():
    """``G(σ) ω`` is the derivative of ``σ(q)`` along ``q̇ = ½ q ⊗ [ω, 0]``."""
    h = 1e-6
    qs = random_unit_quaternions(53, n=2 * N_SAMPLES)
    qs = qs[np.abs(qs[:, 3]) > 0.05][:N_SAMPLES]  # stay away from the shadow-set switch
    omegas = random_vectors(54, n=len(qs))
    for q, omega in zip(qs, omegas, strict=True):
        sigma = quat_to_mrp(q)
        finite_difference = (quat_to_mrp(q + h * quat_kinematics(q, omega)) - sigma) / h
        assert_allclose(finite_difference, mrp_kinematics_matrix(sigma) @ omega, atol=1e-4)


# --------------------------------------------------------------------------- kinematics


def test_quat_kinematics_is_half_q_times_omega():
    for q, omega in zip(random_unit_quaternions(60), random_vectors(61), strict=True):
        expected = 0.5 * quat_multiply(q, np.append(omega, 0.0))
        assert_allclose(quat_kinematics(q, omega), expected, rtol=0, atol=1e-15)


def test_quat_kinematics_preserves_norm():
    """``d/dt ‖q‖² = 2 q · q̇ = 0``."""
    for q, omega in zip(random_unit_quaternions(62), random_vectors(63, scale=5.0), strict=True):
        assert_allclose(2.0 * q @ quat_kinematics(q, omega), 0.0, rtol=0, atol=1e-14)


@jit
def _quat_derivative(t, y, args):
    return quat_kinematics(y, args[0])


_quat_rk4_step = make_rk4_step(_quat_derivative)


def test_constant_body_rate_rotates_about_body_axis():
    """A constant body rate ω for time T gives ``q(T) = q0 ⊗ q(ω T)``, with ``‖q‖`` kept."""
    q0 = random_unit_quaternions(64, n=1)[0]
    omega = np.array([0.3, -0.2, 0.5])
    h, steps = 1e-2, 200
    q = q0.copy()
    for k in range(steps):
        q = _quat_rk4_step(k * h, q, h, (omega,))
    expected = quat_multiply(q0, quat_from_rotation_vector(omega * h * steps))
    assert_allclose(q, expected, rtol=0, atol=1e-10)
    assert_allclose(np.linalg.norm(q), 1.0, atol=1e-10)


# --------------------------------------------------------------------------- tracking error


def test_error_quaternion_matches_paper_formula():
    """``q_ev = q_d4 q_v - q_dv × q_v - q_4 q_dv``, ``q_e4 = q_dv · q_v + q_4 q_d4``."""
    for q, q_d in zip(random_unit_quaternions(70), random_unit_quaternions(71), strict=True):
        qv, q4, qdv, qd4 = q[:3], q[3], q_d[:3], q_d[3]
        expected = np.empty(4)
        expected[:3] = qd4 * qv - np.cross(qdv, qv) - q4 * qdv
        expected[3] = qdv @ qv + q4 * qd4
        assert_allclose(error_quaternion(q, q_d), expected, rtol=0, atol=1e-15)


def test_error_quaternion_is_body_relative_to_desired():
    """``A(q_e) = A(q) A(q_d)ᵀ`` (D→B); zero error exactly when the attitudes coincide."""
    for q, q_d in zip(random_unit_quaternions(72), random_unit_quaternions(73), strict=True):
        q_e = error_quaternion(q, q_d)
        assert_allclose(
            attitude_matrix(q_e), attitude_matrix(q) @ attitude_matrix(q_d).T, rtol=0, atol=1e-14
        )
        assert_allclose(error_quaternion(q, q), IDENTITY_QUAT, rtol=0, atol=1e-15)

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
* the closed-form ``G(σ)⁻¹`` inverts ``G(σ)`` and ``Ġ(σ, σ̇)`` matches a central difference;
* the quaternion kinematics preserve the norm and integrate a constant body rate exactly;
* ``error_quaternion`` matches the explicit component formula of the attitude-tracking paper;
* ``solve3``, ``skew`` and ``cross`` agree with NumPy;
* SE(3) operators: ``se3_exp`` is the matrix exponential and ``se3_log`` its inverse, whose Φ
  agrees with SciPy's rotation vector; ``Ad`` is a homomorphism conjugating twists, ``ad`` is
  the Lie bracket and the derivative of ``Ad``, ``ad*`` is its dual and conserves the rigid
  body's energy; ``G = J_r⁻¹`` is the rate of exponential coordinates (finite differences at
  large, small and tiny angles) and equals paper 000's A and T blocks; small-angle series meet
  the closed forms.
"""

import numpy as np
import pytest
import scipy.linalg
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.rotations import (
    attitude_matrix,
    cross,
    error_quaternion,
    mrp_kinematics_matrix,
    mrp_kinematics_matrix_inverse,
    mrp_kinematics_matrix_rate,
    mrp_to_quat,
    quat_conjugate,
    quat_from_rotation_vector,
    quat_kinematics,
    quat_multiply,
    quat_normalize,
    quat_to_mrp,
    se3_ad,
    se3_adjoint,
    se3_coad,
    se3_exp,
    se3_inverse,
    se3_log,
    se3_right_jacobian_inverse,
    skew,
    so3_exp,
    so3_left_jacobian,
    so3_log,
    so3_right_jacobian_inverse,
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


# --------------------------------------------------------------------------- MRP Jacobian


def test_mrp_kinematics_matrix_inverse_is_the_inverse():
    """``G⁻¹(σ) G(σ) = I`` for MRPs inside and outside the unit sphere."""
    rng = np.random.default_rng(80)
    for sigma in rng.uniform(-1.5, 1.5, size=(N_SAMPLES, 3)):
        product = mrp_kinematics_matrix_inverse(sigma) @ mrp_kinematics_matrix(sigma)
        assert_allclose(product, np.eye(3), rtol=0, atol=1e-12)


def test_mrp_kinematics_matrix_rate_matches_finite_difference():
    """``Ġ`` along ``σ̇`` is the central difference of ``G(σ + t σ̇)`` at ``t = 0``."""
    rng = np.random.default_rng(81)
    h = 1e-6
    for sigma, sigma_dot in zip(
        rng.uniform(-1.0, 1.0, size=(N_SAMPLES, 3)), random_vectors(82), strict=True
    ):
        forward = mrp_kinematics_matrix(sigma + h * sigma_dot)
        backward = mrp_kinematics_matrix(sigma - h * sigma_dot)
        assert_allclose(
            mrp_kinematics_matrix_rate(sigma, sigma_dot), (forward - backward) / (2 * h), atol=1e-8
        )


# --------------------------------------------------------------------------- SE(3) operators
# Ordering [rotation, translation]: V = [ω, v], g = [[R, r], [0, 1]] (orbit-attitude papers).


def random_poses(seed: int, n: int = N_SAMPLES, scale: float = 10.0) -> list[np.ndarray]:
    """Homogeneous rigid motions with uniformly random rotations and Gaussian translations."""
    rng = np.random.default_rng(seed)
    poses = []
    for phi, r in zip(
        random_rotation_vectors(seed + 1000, n), rng.normal(size=(n, 3)), strict=True
    ):
        g = np.eye(4)
        g[:3, :3] = so3_exp(phi)
        g[:3, 3] = scale * r
        poses.append(g)
    return poses


def random_velocities(seed: int, n: int = N_SAMPLES) -> np.ndarray:
    """Gaussian twists [ω, v] (the existing ``random_twists`` draws exponential coordinates)."""
    return np.random.default_rng(seed).normal(size=(n, 6))


def hat6(twist: np.ndarray) -> np.ndarray:
    """The 4×4 matrix ``V^ = [[ω^×, v], [0, 0]]`` of se(3)."""
    out = np.zeros((4, 4))
    out[:3, :3] = skew(twist[:3])
    out[:3, 3] = twist[3:]
    return out


def test_se3_exp_matches_matrix_exponential_and_log_round_trips():
    """``se3_exp`` is ``expm`` of the 4×4 twist matrix; ``se3_log`` inverts it (‖φ‖ < π)."""
    for phi, chi in zip(random_rotation_vectors(90), random_vectors(91, scale=30.0), strict=True):
        xi = np.concatenate([phi, chi])
        assert_allclose(se3_exp(xi), scipy.linalg.expm(hat6(xi)), rtol=0, atol=1e-11)
        assert_allclose(se3_log(se3_exp(xi)), xi, rtol=0, atol=1e-8)


def test_se3_log_rotation_part_matches_an_independent_rotation_vector():
    """Φ of ``se3_log`` equals SciPy's rotation vector of the pose's rotation matrix, and χ
    solves ``r = J_l(Φ) χ`` (eq. 6 of paper 000) with J_l written out independently."""
    for g in random_poses(92):
        xi = se3_log(g)
        reference = Rotation.from_matrix(g[:3, :3]).as_rotvec()
        assert_allclose(xi[:3], reference, rtol=0, atol=1e-10)
        theta = np.linalg.norm(reference)
        k = skew(reference)
        s_matrix = (
            np.eye(3)
            + (1 - np.cos(theta)) / theta**2 * k
            + (theta - np.sin(theta)) / theta**3 * k @ k
        )
        assert_allclose(s_matrix @ xi[3:], g[:3, 3], rtol=0, atol=1e-9)


def test_so3_small_angle_jacobian_and_exp_have_no_cancellation():
    """At θ = 1e-6 the left Jacobian and exp agree with their series to machine precision
    (the closed forms (1 - cos θ)/θ² and (θ - sin θ)/θ³ lose ~1e-4 there)."""
    for phi in random_rotation_vectors(93, max_angle=1e-6):
        k = skew(phi)
        theta = np.linalg.norm(phi)
        series_jacobian = np.eye(3) + (0.5 - theta**2 / 24) * k + (1 / 6 - theta**2 / 120) * k @ k
        assert_allclose(so3_left_jacobian(phi), series_jacobian, rtol=0, atol=1e-17)
        series_exp = np.eye(3) + (1 - theta**2 / 6) * k + (0.5 - theta**2 / 24) * k @ k
        assert_allclose(so3_exp(phi), series_exp, rtol=0, atol=1e-17)


def test_adjoint_is_a_homomorphism_and_conjugates_twists():
    """``Ad_{g1 g2} = Ad_{g1} Ad_{g2}``, ``Ad_{g⁻¹} = Ad_g⁻¹``, ``(Ad_g V)^ = g V^ g⁻¹``."""
    poses_a, poses_b = random_poses(94), random_poses(95)
    for g1, g2, twist in zip(poses_a, poses_b, random_velocities(96), strict=True):
        assert_allclose(se3_adjoint(g1 @ g2), se3_adjoint(g1) @ se3_adjoint(g2), atol=1e-11)
        assert_allclose(se3_adjoint(se3_inverse(g1)) @ se3_adjoint(g1), np.eye(6), atol=1e-12)
        assert_allclose(
            hat6(se3_adjoint(g1) @ twist), g1 @ hat6(twist) @ se3_inverse(g1), atol=1e-11
        )


def test_ad_is_the_lie_bracket_and_the_derivative_of_adjoint():
    """``(ad_V W)^ = [V^, W^]``, antisymmetry, Jacobi, ``ad_V = d/dt Ad_{exp(tV)}|₀``, and the
    paper's component form ``ad_(ω,v)(η,ψ) = (ω×η, ω×ψ - η×v)``."""
    twists_a, twists_b, twists_c = (
        random_velocities(97),
        random_velocities(98),
        random_velocities(99),
    )
    h = 1e-6
    for a, b, c in zip(twists_a, twists_b, twists_c, strict=True):
        bracket = hat6(a) @ hat6(b) - hat6(b) @ hat6(a)
        assert_allclose(hat6(se3_ad(a) @ b), bracket, atol=1e-13)
        assert_allclose(se3_ad(a) @ b, -se3_ad(b) @ a, atol=1e-13)
        jacobi = se3_ad(a) @ se3_ad(b) @ c + se3_ad(b) @ se3_ad(c) @ a + se3_ad(c) @ se3_ad(a) @ b
        assert_allclose(jacobi, np.zeros(6), atol=1e-12)
        derivative = (se3_adjoint(se3_exp(h * a)) - se3_adjoint(se3_exp(-h * a))) / (2 * h)
        assert_allclose(derivative, se3_ad(a), atol=1e-8)
        omega, v, eta, psi = a[:3], a[3:], b[:3], b[3:]
        assert_allclose(
            se3_ad(a) @ b,
            np.concatenate([np.cross(omega, eta), np.cross(omega, psi) - np.cross(eta, v)]),
            atol=1e-13,
        )


def test_coadjoint_is_the_dual_of_ad_and_conserves_rigid_body_energy():
    """``⟨ad*_V P, W⟩ = ⟨P, ad_V W⟩``; the paper's form ``ad*_(ω,v)(η,ψ) = (η×ω + ψ×v, ψ×ω)``;
    and the free rigid body ``Ξ V̇ = ad*_V Ξ V`` conserves ``½ Vᵀ Ξ V``."""
    inertia = np.diag([20.0, 21.0, 20.5]) + 0.5
    xi = np.zeros((6, 6))
    xi[:3, :3] = inertia
    xi[3:, 3:] = 100.0 * np.eye(3)
    for v_twist, w_twist, p in zip(
        random_velocities(100), random_velocities(101), random_velocities(102), strict=True
    ):
        assert_allclose(
            (se3_coad(v_twist) @ p) @ w_twist, p @ (se3_ad(v_twist) @ w_twist), atol=1e-12
        )
        omega, v, eta, psi = v_twist[:3], v_twist[3:], p[:3], p[3:]
        assert_allclose(
            se3_coad(v_twist) @ p,
            np.concatenate([np.cross(eta, omega) + np.cross(psi, v), np.cross(psi, omega)]),
            atol=1e-13,
        )
        v_dot = np.linalg.solve(xi, se3_coad(v_twist) @ xi @ v_twist)
        assert abs(v_twist @ xi @ v_dot) < 1e-11 * (v_twist @ xi @ v_twist)


def test_right_jacobian_inverse_is_the_rate_of_exponential_coordinates():
    """``d/dt log(g exp(t V)) = G(ξ) V`` (eq. 7 of paper 000) for large, small and tiny angles;
    ``A(φ) = J_r⁻¹(φ)`` alone does the same for SO(3)."""
    h = 1e-6
    for max_angle, seed in ((0.95 * np.pi, 103), (0.1, 104), (1e-4, 105)):
        for phi, chi, twist in zip(
            random_rotation_vectors(seed, max_angle=max_angle),
            random_vectors(seed + 10, scale=20.0),
            random_velocities(seed + 20),
            strict=True,
        ):
            xi = np.concatenate([phi, chi])
            g = se3_exp(xi)
            rate = (se3_log(g @ se3_exp(h * twist)) - se3_log(g @ se3_exp(-h * twist))) / (2 * h)
            assert_allclose(se3_right_jacobian_inverse(xi) @ twist, rate, rtol=1e-6, atol=1e-7)
            rotation = so3_exp(phi)
            so3_rate = (
                so3_log(rotation @ so3_exp(h * twist[:3]))
                - so3_log(rotation @ so3_exp(-h * twist[:3]))
            ) / (2 * h)
            assert_allclose(so3_right_jacobian_inverse(phi) @ twist[:3], so3_rate, atol=1e-7)


def paper_coupling_block(phi: np.ndarray, chi: np.ndarray) -> np.ndarray:
    """T(Φ, χ) of G(η̃) exactly as paper 000 prints it below eq. (7)."""
    theta = np.linalg.norm(phi)
    s, c = np.sin(theta), np.cos(theta)
    k = skew(phi)
    a_matrix = np.eye(3) + 0.5 * k + (1 / theta**2 - (1 + c) / (2 * theta * s)) * k @ k
    s_matrix = np.eye(3) + (1 - c) / theta**2 * k + (theta - s) / theta**3 * k @ k
    s_chi = s_matrix @ chi
    return (
        0.5 * skew(s_chi) @ a_matrix
        + (1 / theta**2 - (1 + c) / (2 * theta * s)) * (np.outer(phi, chi) + (phi @ chi) * a_matrix)
        - (1 + c) * (theta - s) / (2 * theta * s**2) * np.outer(s_chi, phi)
        + ((1 + c) * (theta + s) / (2 * theta**3 * s**2) - 2 / theta**4)
        * (phi @ chi)
        * np.outer(phi, phi)
    )


def test_right_jacobian_inverse_matches_the_papers_blocks():
    """G(η̃) = [[A, 0], [T, A]] with A and T as paper 000 writes them (θ away from 0 and π)."""
    for phi, chi in zip(
        random_rotation_vectors(106, max_angle=0.9 * np.pi),
        random_vectors(107, scale=30.0),
        strict=True,
    ):
        if np.linalg.norm(phi) < 0.05:
            continue
        g_matrix = se3_right_jacobian_inverse(np.concatenate([phi, chi]))
        assert_allclose(g_matrix[:3, 3:], np.zeros((3, 3)), atol=0)
        assert_allclose(g_matrix[3:, 3:], g_matrix[:3, :3], atol=0)
        assert_allclose(g_matrix[3:, :3], paper_coupling_block(phi, chi), rtol=1e-9, atol=1e-9)


def test_right_jacobian_inverse_is_continuous_at_the_series_switch():
    """The series branches (θ < 0.1) meet the closed forms without a jump."""
    axis = unit(np.array([0.3, -0.5, 0.8]))
    chi = np.array([3.0, -20.0, 7.0])
    below = se3_right_jacobian_inverse(np.concatenate([(0.1 - 1e-9) * axis, chi]))
    above = se3_right_jacobian_inverse(np.concatenate([(0.1 + 1e-9) * axis, chi]))
    assert_allclose(below, above, rtol=0, atol=1e-8)


def test_euler_321_quaternion_is_the_yaw_pitch_roll_rotation():
    """``attitude_matrix(quat_from_euler321(φ, θ, ψ)) = R1(φ) R2(θ) R3(ψ)`` (passive), i.e. the
    transpose of SciPy's intrinsic 'ZYX' rotation, and ``quat_to_euler321`` inverts it."""
    from etsc_envs.core.rotations import quat_from_euler321, quat_to_euler321

    rng = np.random.default_rng(108)
    for _ in range(N_SAMPLES):
        roll, yaw = rng.uniform(-np.pi, np.pi, size=2)
        pitch = rng.uniform(-0.49 * np.pi, 0.49 * np.pi)
        q = quat_from_euler321(roll, pitch, yaw)
        assert_allclose(np.linalg.norm(q), 1.0, atol=1e-15)
        expected = Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_matrix().T
        assert_allclose(attitude_matrix(q), expected, atol=1e-12)
        assert_allclose(quat_to_euler321(q), [roll, pitch, yaw], atol=1e-9)
        assert_allclose(quat_to_euler321(-q), [roll, pitch, yaw], atol=1e-9)


def test_quaternion_angle_is_the_principal_rotation_angle():
    from etsc_envs.core.rotations import quat_angle

    for phi in random_rotation_vectors(109):
        q = quat_from_rotation_vector(phi)
        assert_allclose(quat_angle(q), np.linalg.norm(phi), atol=1e-12)
        assert_allclose(quat_angle(-q), np.linalg.norm(phi), atol=1e-12)
    assert quat_angle(np.array([0.0, 0.0, 0.0, 1.0])) == 0.0

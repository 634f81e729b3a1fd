"""Rotation and rigid-motion algebra: quaternions, modified Rodrigues parameters, SO(3), SE(3).

Conventions (used by every problem of the suite):

* A quaternion is ``q = [q1, q2, q3, q4]`` with vector part ``q_v = q[:3]`` and scalar part
  ``q4`` last, as in the attitude papers. The product is Hamilton's,
  ``p ⊗ q = [p4 q_v + q4 p_v + p_v × q_v,  p4 q4 - p_v · q_v]``.
* ``q`` gives the attitude of a body frame B relative to a reference frame R. The kinematics
  with the body-frame angular velocity ω are ``q̇ = ½ q ⊗ [ω, 0]``, i.e.
  ``q̇_v = ½ (q4 I + q_v^×) ω``, ``q̇4 = -½ q_vᵀ ω``.
* ``attitude_matrix(q)`` is the direction-cosine matrix that maps R-frame components of a vector
  to B-frame components, ``(1 - 2 q_vᵀq_v) I + 2 q_v q_vᵀ - 2 q4 q_v^×``. ``so3_exp`` returns the
  rotation matrix ``R = attitude_matrix(q)ᵀ`` of the same rotation (B-frame components to R).
* MRPs are ``σ = q_v / (1 + q4)``.

All functions are compiled (see :mod:`etsc_envs.core.jit`) and take and return float64 arrays.
"""

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import (
    fused_dot,
    fused_dot6,
    fused_matmul,
    fused_matvec3,
    fused_multiply_add,
)

_SMALL_ANGLE = 1e-8


IDENTITY_ROWS = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
"""The 3×3 identity as a :data:`~etsc_envs.core.vec3.Mat3`."""


@jit
def skew_rows(a) -> vec3.Mat3:
    """Cross-product matrix ``a^×`` such that ``a^× b = a × b``, as the tuple of its rows."""
    return ((0.0, -a[2], a[1]), (a[2], 0.0, -a[0]), (-a[1], a[0], 0.0))


@jit
def skew(a: np.ndarray) -> np.ndarray:
    """Cross-product matrix ``a^×`` such that ``a^× b = a × b`` (:func:`skew_rows`)."""
    return vec3.to_matrix(skew_rows(a))


@jit
def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Vector product ``a × b`` of two 3-vectors."""
    return vec3.to_array(vec3.cross(a, b))


@jit
def solve3(matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve the 3×3 linear system ``matrix · x = rhs`` by Cramer's rule."""
    return vec3.to_array(vec3.solve(matrix, rhs))


@jit
def quat_multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product ``p ⊗ q`` of scalar-last quaternions."""
    return _quaternion_array(quat_product(p, q))


@jit
def _quaternion_array(q) -> np.ndarray:
    out = np.empty(4)
    for i in range(4):
        out[i] = q[i]
    return out


@jit
def quat_product(p, q) -> tuple[float, float, float, float]:
    """Hamilton product ``p ⊗ q`` as a tuple (see :mod:`etsc_envs.core.vec3`); ``p`` and ``q``
    may be arrays or tuples."""
    vector = vec3.add(vec3.add(vec3.scale(p[3], q), vec3.scale(q[3], p)), vec3.cross(p, q))
    return (vector[0], vector[1], vector[2], p[3] * q[3] - p[0] * q[0] - p[1] * q[1] - p[2] * q[2])


@jit
def _conjugate(q) -> tuple[float, float, float, float]:
    return (-q[0], -q[1], -q[2], q[3])


@jit
def quat_conjugate(q: np.ndarray) -> np.ndarray:
    """Conjugate ``[-q_v, q4]``, the inverse of a unit quaternion."""
    return _quaternion_array(_conjugate(q))


@jit
def quat_normalize(q: np.ndarray) -> np.ndarray:
    """Unit quaternion along ``q``."""
    return q / np.sqrt(fused_dot(q, q))


@jit
def quat_rate(q, omega) -> tuple[float, float, float, float]:
    """Quaternion rate ``q̇ = ½ q ⊗ [ω, 0]`` for the body-frame rate ω, as a tuple (see
    :mod:`etsc_envs.core.vec3`); ``q`` and ``omega`` may be arrays or tuples."""
    vector_rate = vec3.scale(0.5, vec3.add(vec3.scale(q[3], omega), vec3.cross(q, omega)))
    return (vector_rate[0], vector_rate[1], vector_rate[2], -0.5 * vec3.dot(q, omega))


@jit
def quat_kinematics(q: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Quaternion rate ``q̇ = ½ q ⊗ [ω, 0]`` for the body-frame rate ω (eq. (1)/(2) of 002)."""
    return _quaternion_array(quat_rate(q, omega))


@jit
def quat_error(q, q_desired) -> tuple[float, float, float, float]:
    """Attitude error ``q_e = q_d* ⊗ q`` (eq. (4) of 002) as a tuple: B relative to the desired
    frame."""
    return quat_product(_conjugate(q_desired), q)


@jit
def error_quaternion(q: np.ndarray, q_desired: np.ndarray) -> np.ndarray:
    """Attitude error ``q_e = q_d* ⊗ q`` (eq. (4) of 002): B relative to the desired frame."""
    return _quaternion_array(quat_error(q, q_desired))


@jit
def attitude_rows(q) -> vec3.Mat3:
    """DCM ``(1 - 2 q_vᵀq_v) I + 2 q_v q_vᵀ - 2 q4 q_v^×`` mapping R-frame to B-frame
    components, as the tuple of its rows (:data:`~etsc_envs.core.vec3.Mat3`)."""
    x, y, z = q[0], q[1], q[2]
    diagonal = 1.0 - 2.0 * vec3.dot(q, q)
    twice_scalar = 2.0 * q[3]
    return (
        (
            diagonal + 2.0 * (x * x),
            2.0 * (x * y) - twice_scalar * -z,
            2.0 * (x * z) - twice_scalar * y,
        ),
        (
            2.0 * (y * x) - twice_scalar * z,
            diagonal + 2.0 * (y * y),
            2.0 * (y * z) - twice_scalar * -x,
        ),
        (
            2.0 * (z * x) - twice_scalar * -y,
            2.0 * (z * y) - twice_scalar * x,
            diagonal + 2.0 * (z * z),
        ),
    )


@jit
def attitude_matrix(q: np.ndarray) -> np.ndarray:
    """DCM ``(1 - 2 q_vᵀq_v) I + 2 q_v q_vᵀ - 2 q4 q_v^×`` mapping R-frame to B-frame components
    (:func:`attitude_rows` as an array)."""
    return vec3.to_matrix(attitude_rows(q))


@jit
def quat_from_rotation_vector(phi: np.ndarray) -> np.ndarray:
    """Unit quaternion of the rotation by angle ``‖φ‖`` about ``φ/‖φ‖``."""
    angle = np.sqrt(fused_dot(phi, phi))
    out = np.empty(4)
    if angle < _SMALL_ANGLE:
        out[:3] = 0.5 * phi
    else:
        out[:3] = np.sin(0.5 * angle) / angle * phi
    out[3] = np.cos(0.5 * angle)
    return quat_normalize(out)


@jit
def _one_minus_cos_over_sq(angle: float) -> float:
    """``(1 - cos θ)/θ²`` as ``½ (sin(θ/2)/(θ/2))²``, free of the cancellation at small θ."""
    half_sinc = np.sin(0.5 * angle) / (0.5 * angle)
    return 0.5 * half_sinc * half_sinc


@jit
def so3_exp(phi: np.ndarray) -> np.ndarray:
    """Rotation matrix ``exp(φ^×)`` (Rodrigues' formula)."""
    angle = np.sqrt(fused_dot(phi, phi))
    phi_x = skew(phi)
    if angle < _SMALL_ANGLE:
        return np.eye(3) + phi_x + fused_matmul(0.5 * phi_x, phi_x)
    return (
        np.eye(3)
        + np.sin(angle) / angle * phi_x
        + fused_matmul(_one_minus_cos_over_sq(angle) * phi_x, phi_x)
    )


@jit
def so3_log_rows(rotation) -> vec3.Vec3:
    """Rotation vector φ with ``so3_exp(φ) = rotation`` and ``‖φ‖ ≤ π``, for a rotation given
    by its rows (a :data:`~etsc_envs.core.vec3.Mat3` or an array), as a tuple.

    The angle is ``atan2(sin θ, cos θ)`` from the antisymmetric part and the trace, which stays
    accurate near π where ``arccos`` of the trace does not.
    """
    trace = ((0.0 + rotation[0][0]) + rotation[1][1]) + rotation[2][2]
    cos_angle = min(1.0, max(-1.0, 0.5 * (trace - 1.0)))
    axis_sin = (
        0.5 * (rotation[2][1] - rotation[1][2]),
        0.5 * (rotation[0][2] - rotation[2][0]),
        0.5 * (rotation[1][0] - rotation[0][1]),
    )
    sin_angle = np.sqrt(vec3.dot(axis_sin, axis_sin))
    angle = np.arctan2(sin_angle, cos_angle)
    if angle < 1e-6:
        return axis_sin
    if sin_angle > 1e-3 or cos_angle > 0.0:
        return vec3.scale(angle / sin_angle, axis_sin)
    return vec3.as_vec3(
        _so3_log_near_pi(vec3.to_matrix(rotation), cos_angle, vec3.to_array(axis_sin), angle)
    )


@jit
def _so3_log_near_pi(
    rotation: np.ndarray, cos_angle: float, axis_sin: np.ndarray, angle: float
) -> np.ndarray:
    """:func:`so3_log_rows` near π, where the axis comes from the symmetric part:
    ``(R + Rᵀ)/2 = cos θ I + (1 - cos θ) a aᵀ``."""
    outer = (0.5 * (rotation + rotation.T) - cos_angle * np.eye(3)) / (1.0 - cos_angle)
    column = int(np.argmax(np.diag(outer)))
    axis = outer[:, column] / np.sqrt(outer[column, column])
    if axis @ axis_sin < 0.0:
        axis = -axis
    return angle * axis / np.sqrt(axis @ axis)


@jit
def so3_log(rotation: np.ndarray) -> np.ndarray:
    """Rotation vector φ with ``so3_exp(φ) = rotation`` and ``‖φ‖ ≤ π`` (:func:`so3_log_rows`)."""
    return vec3.to_array(so3_log_rows(rotation))


@jit
def so3_left_jacobian_rows(phi) -> vec3.Mat3:
    """Left Jacobian of SO(3), the map from twist to translation in :func:`se3_exp`, as the
    tuple of its rows."""
    angle = np.sqrt(vec3.dot(phi, phi))
    phi_x = skew_rows(phi)
    if angle < _SMALL_ANGLE:
        return vec3.rows_add(
            vec3.rows_add(IDENTITY_ROWS, vec3.rows_scale(0.5, phi_x)),
            vec3.rows_divide(vec3.product(phi_x, phi_x), 6.0),
        )
    if angle < 0.1:  # (θ - sin θ)/θ³ by its series: the closed form cancels to ~1e-16/θ²
        a2 = angle * angle
        third = 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0 - a2 * a2 * a2 / 362880.0
    else:
        third = (angle - np.sin(angle)) / angle**3
    return vec3.rows_add(
        vec3.rows_add(IDENTITY_ROWS, vec3.rows_scale(_one_minus_cos_over_sq(angle), phi_x)),
        vec3.product(vec3.rows_scale(third, phi_x), phi_x),
    )


@jit
def so3_left_jacobian(phi: np.ndarray) -> np.ndarray:
    """Left Jacobian of SO(3) (:func:`so3_left_jacobian_rows`) as an array."""
    return vec3.to_matrix(so3_left_jacobian_rows(phi))


@jit
def se3_exp(xi: np.ndarray) -> np.ndarray:
    """Homogeneous 4×4 matrix ``exp(ξ^)`` of the twist ``ξ = [φ, χ]`` (rotation first)."""
    g = np.eye(4)
    g[:3, :3] = so3_exp(xi[:3])
    g[:3, 3] = so3_left_jacobian(xi[:3]) @ xi[3:]
    return g


@jit
def se3_log_parts(rotation, position) -> tuple[vec3.Vec3, vec3.Vec3]:
    """Exponential coordinates ``(φ, χ)`` with ``se3_exp([φ, χ]) = [[R, p], [0, 1]]`` for the
    rotation ``R`` given by its rows and the translation ``p``, as two tuples."""
    phi = so3_log_rows(rotation)
    return phi, vec3.solve_rows(so3_left_jacobian_rows(phi), position)


@jit
def se3_log(g: np.ndarray) -> np.ndarray:
    """Exponential coordinates ``ξ = [φ, χ]`` with ``se3_exp(ξ) = g`` (:func:`se3_log_parts`)."""
    phi, chi = se3_log_parts(g[:3, :3], g[:3, 3])
    xi = np.empty(6)
    vec3.store(xi[:3], phi)
    vec3.store(xi[3:], chi)
    return xi


@jit
def se3_inverse(g: np.ndarray) -> np.ndarray:
    """Inverse ``[Rᵀ, -Rᵀ p; 0, 1]`` of a homogeneous rigid motion."""
    out = np.eye(4)
    rotation_t = np.ascontiguousarray(g[:3, :3].T)
    out[:3, :3] = rotation_t
    out[:3, 3] = fused_matvec3(-rotation_t, g[:3, 3])
    return out


@jit
def quat_to_mrp(q: np.ndarray) -> np.ndarray:
    """Modified Rodrigues parameters ``σ = q_v / (1 + q4)`` (the short rotation, ``‖σ‖ ≤ 1``)."""
    sign = 1.0 if q[3] >= 0.0 else -1.0
    return sign * q[:3] / (1.0 + sign * q[3])


@jit
def mrp_to_quat(sigma: np.ndarray) -> np.ndarray:
    """Unit quaternion ``[2σ, 1 - σᵀσ] / (1 + σᵀσ)`` of an MRP vector."""
    s2 = sigma @ sigma
    out = np.empty(4)
    out[:3] = 2.0 * sigma / (1.0 + s2)
    out[3] = (1.0 - s2) / (1.0 + s2)
    return out


@jit
def mrp_kinematics(sigma) -> vec3.Mat3:
    """The rows of ``G(σ) = ½[(1 - σᵀσ)/2 I + σ^× + σσᵀ]``, so that ``σ̇ = G(σ) ω``.

    Written entry by entry (it sits on the hot path of MRP-based problems).
    """
    x, y, z = sigma[0], sigma[1], sigma[2]
    diagonal = 0.5 * (1.0 - (x * x + y * y + z * z))
    return (
        (0.5 * (diagonal + x * x), 0.5 * (-z + x * y), 0.5 * (y + x * z)),
        (0.5 * (z + y * x), 0.5 * (diagonal + y * y), 0.5 * (-x + y * z)),
        (0.5 * (-y + z * x), 0.5 * (x + z * y), 0.5 * (diagonal + z * z)),
    )


@jit
def mrp_kinematics_matrix(sigma: np.ndarray) -> np.ndarray:
    """``G(σ)`` of :func:`mrp_kinematics` as a 3×3 array."""
    return vec3.to_matrix(mrp_kinematics(sigma))


@jit
def mrp_inverse_scale(sigma) -> float:
    """``16 / (1 + σᵀσ)²``, the factor of :func:`mrp_kinematics_matrix_inverse`."""
    return 16.0 / (1.0 + sigma[0] ** 2 + sigma[1] ** 2 + sigma[2] ** 2) ** 2


@jit
def mrp_kinematics_matrix_inverse(sigma: np.ndarray) -> np.ndarray:
    """``G(σ)⁻¹ = 16 G(σ)ᵀ / (1 + σᵀσ)²``, so that ``ω = G(σ)⁻¹ σ̇``.

    ``4 G(σ)`` is ``(1 + σᵀσ)`` times a rotation matrix, hence the closed form; it exists for
    every σ.
    """
    return mrp_inverse_scale(sigma) * np.ascontiguousarray(mrp_kinematics_matrix(sigma).T)


@jit
def mrp_kinematics_rate(sigma, sigma_dot) -> vec3.Mat3:
    """The rows of the time derivative ``Ġ = ½[-(σᵀσ̇) I + σ̇^× + σ̇σᵀ + σσ̇ᵀ]`` of ``G(σ)``
    along ``σ̇``."""
    s, d = sigma, sigma_dot
    half_projection = 0.5 * (s[0] * d[0] + s[1] * d[1] + s[2] * d[2])
    return (
        (
            0.5 * (d[0] * s[0] + s[0] * d[0]) - half_projection,
            0.5 * (d[0] * s[1] + s[0] * d[1]) - 0.5 * d[2],
            0.5 * (d[0] * s[2] + s[0] * d[2]) + 0.5 * d[1],
        ),
        (
            0.5 * (d[1] * s[0] + s[1] * d[0]) + 0.5 * d[2],
            0.5 * (d[1] * s[1] + s[1] * d[1]) - half_projection,
            0.5 * (d[1] * s[2] + s[1] * d[2]) - 0.5 * d[0],
        ),
        (
            0.5 * (d[2] * s[0] + s[2] * d[0]) - 0.5 * d[1],
            0.5 * (d[2] * s[1] + s[2] * d[1]) + 0.5 * d[0],
            0.5 * (d[2] * s[2] + s[2] * d[2]) - half_projection,
        ),
    )


@jit
def mrp_kinematics_matrix_rate(sigma: np.ndarray, sigma_dot: np.ndarray) -> np.ndarray:
    """``Ġ`` of :func:`mrp_kinematics_rate` as a 3×3 array."""
    return vec3.to_matrix(mrp_kinematics_rate(sigma, sigma_dot))


# --------------------------------------------------------------------------- SE(3) operators
# Twists and wrenches are ordered rotation first, V = [ω, v] and Γ = [τ, f], as in the
# orbit-attitude papers; ``g = [[R, r], [0, 1]]`` maps body-frame coordinates to the
# reference frame.


@jit
def block_lower_times(diagonal, lower, vector) -> tuple:
    """``[[D, 0], [L, D]] @ v`` for 3×3 blocks D and L given by their rows and a 6-vector v, as
    a 6-tuple: bit for bit :func:`~etsc_envs.core.linalg.fused_matvec6` of the 6×6 array (its
    upper-right block +0)."""
    d, low = diagonal, lower
    return (
        fused_dot6((d[0][0], d[0][1], d[0][2], 0.0, 0.0, 0.0), vector),
        fused_dot6((d[1][0], d[1][1], d[1][2], 0.0, 0.0, 0.0), vector),
        fused_dot6((d[2][0], d[2][1], d[2][2], 0.0, 0.0, 0.0), vector),
        fused_dot6((low[0][0], low[0][1], low[0][2], d[0][0], d[0][1], d[0][2]), vector),
        fused_dot6((low[1][0], low[1][1], low[1][2], d[1][0], d[1][1], d[1][2]), vector),
        fused_dot6((low[2][0], low[2][1], low[2][2], d[2][0], d[2][1], d[2][2]), vector),
    )


@jit
def pose_product(rotation1, position1, rotation2, position2) -> tuple[vec3.Mat3, vec3.Vec3]:
    """``g1 g2`` for ``g = [[R, p], [0, 1]]`` given as rotation rows and translation, as
    ``(R, p)``: bit for bit the 4×4 :func:`~etsc_envs.core.linalg.fused_matmul` (each entry a
    fused multiply-add chain over the four columns of g1, the last with g2's bottom row)."""
    rotation = vec3.product(rotation1, rotation2)
    position = vec3.rows_matvec_chain(rotation1, position2)
    return (
        (
            (
                fused_multiply_add(position1[0], 0.0, rotation[0][0]),
                fused_multiply_add(position1[0], 0.0, rotation[0][1]),
                fused_multiply_add(position1[0], 0.0, rotation[0][2]),
            ),
            (
                fused_multiply_add(position1[1], 0.0, rotation[1][0]),
                fused_multiply_add(position1[1], 0.0, rotation[1][1]),
                fused_multiply_add(position1[1], 0.0, rotation[1][2]),
            ),
            (
                fused_multiply_add(position1[2], 0.0, rotation[2][0]),
                fused_multiply_add(position1[2], 0.0, rotation[2][1]),
                fused_multiply_add(position1[2], 0.0, rotation[2][2]),
            ),
        ),
        (
            fused_multiply_add(position1[0], 1.0, position[0]),
            fused_multiply_add(position1[1], 1.0, position[1]),
            fused_multiply_add(position1[2], 1.0, position[2]),
        ),
    )


@jit
def pose_inverse(rotation, position) -> tuple[vec3.Mat3, vec3.Vec3]:
    """``g⁻¹ = [[Rᵀ, -Rᵀ p], [0, 1]]`` for ``g = [[R, p], [0, 1]]`` given as rotation rows and
    translation, as ``(Rᵀ, -Rᵀ p)`` (the values of :func:`se3_inverse`)."""
    rotation_t = vec3.transpose(rotation)
    return rotation_t, vec3.rows_matvec(vec3.rows_negate(rotation_t), position)


@jit
def se3_adjoint(g: np.ndarray) -> np.ndarray:
    """Adjoint ``Ad_g = [[R, 0], [r^× R, R]]`` (6×6), so that ``(Ad_g V)^ = g V^ g⁻¹``."""
    rotation = np.ascontiguousarray(g[:3, :3])
    out = np.zeros((6, 6))
    out[:3, :3] = rotation
    out[3:, 3:] = rotation
    out[3:, :3] = fused_matmul(skew(g[:3, 3]), rotation)
    return out


@jit
def se3_ad(twist: np.ndarray) -> np.ndarray:
    """Adjoint of the Lie algebra, ``ad_V = [[ω^×, 0], [v^×, ω^×]]`` (6×6), the matrix of the
    Lie bracket: ``ad_V W = [ω × η, ω × ψ - η × v]`` for ``W = [η, ψ]``."""
    omega_x = skew(twist[:3])
    out = np.zeros((6, 6))
    out[:3, :3] = omega_x
    out[3:, 3:] = omega_x
    out[3:, :3] = skew(twist[3:])
    return out


@jit
def se3_coad(twist: np.ndarray) -> np.ndarray:
    """Co-adjoint ``ad*_V = ad_Vᵀ = [[-ω^×, -v^×], [0, -ω^×]]`` (6×6).

    With ``Ξ = diag(J, m I)`` the free rigid body reads ``Ξ V̇ = ad*_V Ξ V``, i.e.
    ``J ω̇ = -ω × Jω - v × m v`` and ``m v̇ = -ω × m v``.
    """
    return np.ascontiguousarray(se3_ad(twist).T)


@jit
def so3_right_jacobian_inverse_rows(phi) -> vec3.Mat3:
    """``J_r⁻¹(φ) = I + ½ φ^× + (1/θ² - (1 + cos θ)/(2θ sin θ)) (φ^×)²`` for ``θ = ‖φ‖ < π``,
    as the tuple of its rows.

    It maps a body-frame rate to the rate of the exponential coordinates:
    ``Ṙ = R ω^×`` with ``R = exp(φ^×)`` gives ``φ̇ = J_r⁻¹(φ) ω``.
    """
    angle = np.sqrt(vec3.dot(phi, phi))
    phi_x = skew_rows(phi)
    if angle < 0.1:
        a2 = angle * angle
        coefficient = 1.0 / 12.0 + a2 / 720.0 + a2 * a2 / 30240.0 + a2 * a2 * a2 / 1209600.0
    else:
        coefficient = 1.0 / angle**2 - (1.0 + np.cos(angle)) / (2.0 * angle * np.sin(angle))
    square = vec3.product(vec3.rows_scale(coefficient, phi_x), phi_x)
    return (
        _identity_row_plus(0, phi_x[0], square[0]),
        _identity_row_plus(1, phi_x[1], square[1]),
        _identity_row_plus(2, phi_x[2], square[2]),
    )


@jit
def _identity_row_plus(row: int, half_of, plus) -> vec3.Vec3:
    """Row ``row`` of ``(I + ½ half_of) + plus`` from the rows ``half_of`` and ``plus``."""
    return (
        ((1.0 if row == 0 else 0.0) + 0.5 * half_of[0]) + plus[0],
        ((1.0 if row == 1 else 0.0) + 0.5 * half_of[1]) + plus[1],
        ((1.0 if row == 2 else 0.0) + 0.5 * half_of[2]) + plus[2],
    )


@jit
def so3_right_jacobian_inverse(phi: np.ndarray) -> np.ndarray:
    """``J_r⁻¹(φ)`` (:func:`so3_right_jacobian_inverse_rows`) as an array."""
    return vec3.to_matrix(so3_right_jacobian_inverse_rows(phi))


@jit
def se3_left_jacobian_coupling_rows(phi, rho) -> vec3.Mat3:
    """The off-diagonal block ``Q(φ, ρ)`` of the left Jacobian of SE(3) (Barfoot's form), as
    the tuple of its rows.

    ``J_l(ξ) = [[J_l(φ), 0], [Q(φ, ρ), J_l(φ)]]`` for ``ξ = [φ, ρ]``; series coefficients are
    used below θ = 0.1, where the closed forms lose digits to cancellation.
    """
    angle = np.sqrt(vec3.dot(phi, phi))
    a2 = angle * angle
    if angle < 0.1:
        c1 = 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0 - a2 * a2 * a2 / 362880.0
        c2 = 1.0 / 24.0 - a2 / 720.0 + a2 * a2 / 40320.0 - a2 * a2 * a2 / 3628800.0
        c3 = 1.0 / 120.0 - a2 / 2520.0 + a2 * a2 / 120960.0 - a2 * a2 * a2 / 9979200.0
    else:
        s, c = np.sin(angle), np.cos(angle)
        c1 = (angle - s) / angle**3
        c2 = (a2 + 2.0 * c - 2.0) / (2.0 * a2 * a2)
        c3 = (2.0 * angle - 3.0 * s + angle * c) / (2.0 * a2 * a2 * angle)
    p = skew_rows(phi)
    r = skew_rows(rho)
    pr = vec3.product(p, r)
    rp = vec3.product(r, p)
    prp = vec3.product(pr, p)
    pp = vec3.product(p, p)
    ppr = vec3.product(pp, r)
    rpp = vec3.product(rp, p)
    prpp = vec3.product(prp, p)
    pprp = vec3.product(ppr, p)
    return (
        _coupling_row(0, r, pr, rp, prp, ppr, rpp, prpp, pprp, c1, c2, c3),
        _coupling_row(1, r, pr, rp, prp, ppr, rpp, prpp, pprp, c1, c2, c3),
        _coupling_row(2, r, pr, rp, prp, ppr, rpp, prpp, pprp, c1, c2, c3),
    )


@jit
def _coupling_entry(r, pr, rp, prp, ppr, rpp, prpp, pprp, c1, c2, c3) -> float:
    """One entry of :func:`se3_left_jacobian_coupling_rows` from the same entry of each
    product."""
    return 0.5 * r + c1 * (pr + rp + prp) + c2 * (ppr + rpp - 3.0 * prp) + c3 * (prpp + pprp)


@jit
def _coupling_row(i, r, pr, rp, prp, ppr, rpp, prpp, pprp, c1, c2, c3) -> vec3.Vec3:
    """Row ``i`` of :func:`se3_left_jacobian_coupling_rows` from the products' rows."""
    return (
        _coupling_entry(
            r[i][0],
            pr[i][0],
            rp[i][0],
            prp[i][0],
            ppr[i][0],
            rpp[i][0],
            prpp[i][0],
            pprp[i][0],
            c1,
            c2,
            c3,
        ),
        _coupling_entry(
            r[i][1],
            pr[i][1],
            rp[i][1],
            prp[i][1],
            ppr[i][1],
            rpp[i][1],
            prpp[i][1],
            pprp[i][1],
            c1,
            c2,
            c3,
        ),
        _coupling_entry(
            r[i][2],
            pr[i][2],
            rp[i][2],
            prp[i][2],
            ppr[i][2],
            rpp[i][2],
            prpp[i][2],
            pprp[i][2],
            c1,
            c2,
            c3,
        ),
    )


@jit
def se3_right_jacobian_inverse_blocks(phi, rho) -> tuple[vec3.Mat3, vec3.Mat3]:
    """The blocks ``(A, T)`` of ``G(ξ) = J_r⁻¹(ξ) = [[A, 0], [T, A]]`` for exponential
    coordinates ``ξ = [φ, ρ]``, each as the tuple of its rows.

    With ``g = exp(ξ^)`` and ``ġ = g V^`` (body-frame twist V), ``ξ̇ = G(ξ) V``. Here
    ``A = J_r⁻¹(φ)`` and ``T = -A Q(-φ, -ρ) A``, since ``J_r(ξ) = J_l(-ξ)``.
    """
    a = so3_right_jacobian_inverse_rows(phi)
    coupling = se3_left_jacobian_coupling_rows(vec3.negate(phi), vec3.negate(rho))
    return a, vec3.product(vec3.product(vec3.rows_negate(a), coupling), a)


@jit
def se3_right_jacobian_inverse(xi: np.ndarray) -> np.ndarray:
    """``G(ξ) = J_r⁻¹(ξ) = [[A, 0], [T, A]]`` (6×6) for exponential coordinates ``ξ = [φ, ρ]``
    (:func:`se3_right_jacobian_inverse_blocks`)."""
    a, t = se3_right_jacobian_inverse_blocks(xi[:3], xi[3:])
    out = np.zeros((6, 6))
    out[:3, :3] = vec3.to_matrix(a)
    out[3:, 3:] = vec3.to_matrix(a)
    out[3:, :3] = vec3.to_matrix(t)
    return out


@jit
def se3_right_jacobian_inverse_times(phi, rho, twist) -> tuple:
    """``G(ξ) V`` for ``ξ = [φ, ρ]`` and a 6-vector ``V``, as a 6-tuple: bit for bit
    :func:`~etsc_envs.core.linalg.fused_matvec6` of :func:`se3_right_jacobian_inverse`."""
    a, t = se3_right_jacobian_inverse_blocks(phi, rho)
    return block_lower_times(a, t, twist)


# --------------------------------------------------------------------------- Euler angles
@jit
def quat_from_euler321(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Unit quaternion of the 3-2-1 sequence (yaw ψ about z, pitch θ about the new y, roll φ
    about the new x), so that ``attitude_matrix(q) = R1(φ) R2(θ) R3(ψ)``."""
    cr, sr = np.cos(0.5 * roll), np.sin(0.5 * roll)
    cp, sp = np.cos(0.5 * pitch), np.sin(0.5 * pitch)
    cy, sy = np.cos(0.5 * yaw), np.sin(0.5 * yaw)
    out = np.empty(4)
    out[0] = sr * cp * cy - cr * sp * sy
    out[1] = cr * sp * cy + sr * cp * sy
    out[2] = cr * cp * sy - sr * sp * cy
    out[3] = cr * cp * cy + sr * sp * sy
    return out


@jit
def quat_to_euler321(q: np.ndarray) -> np.ndarray:
    """``[roll, pitch, yaw]`` of the 3-2-1 sequence of :func:`quat_from_euler321` (pitch in
    [-π/2, π/2], roll and yaw in (-π, π])."""
    dcm = attitude_matrix(q)
    out = np.empty(3)
    out[0] = np.arctan2(dcm[1, 2], dcm[2, 2])
    out[1] = -np.arcsin(min(1.0, max(-1.0, dcm[0, 2])))
    out[2] = np.arctan2(dcm[0, 1], dcm[0, 0])
    return out


@jit
def quat_angle(q: np.ndarray) -> float:
    """Principal rotation angle ``2 atan2(‖q_v‖, |q4|)`` of a unit quaternion, in [0, π]."""
    return 2.0 * float(np.arctan2(np.sqrt(q[:3] @ q[:3]), abs(q[3])))

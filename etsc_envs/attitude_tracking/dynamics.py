"""Plant, disturbances and desired motion of paper 002, as compiled pure functions.

The integrated state is ``y = [q (4), ω (3), q_d (4)]``: the spacecraft attitude and body rate
of eq. (1) and the desired attitude of eq. (2), advanced together so that one fixed-step
integration keeps them synchronous.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import inline_jit, jit
from etsc_envs.core.rotations import attitude_matrix, quat_error, quat_rate

SINUSOID, SQUARE = 0, 1

PlantModel = namedtuple(
    "PlantModel",
    [
        "nominal_inertia",  # J0, eq. (49)
        "inertia_amplitude",  # ΔJ(t) = diag(a sin(w t + phase))
        "inertia_frequency",
        "inertia_phase",
        "disturbance_amplitude",  # d(t) = a sin(w t + phase)
        "disturbance_frequency",
        "disturbance_phase",
        "reference_kind",  # SINUSOID (eq. 53) or SQUARE (eqs. 54-55)
        "reference_amplitude",  # per-axis amplitude (sinusoid) or level (square), rad/s
        "reference_frequency",  # rad/s, sinusoid only
        "reference_switch_period",  # T of eqs. (54)-(55), square only
    ],
)
"""Everything the plant and the desired motion depend on, as arrays and scalars."""


@inline_jit
def inertia(t: float, model: PlantModel) -> vec3.Mat3:
    """True inertia J(t) = J0 + ΔJ(t) of section 4, by rows (no array is made per call)."""
    variation = vec3.sine_wave(
        model.inertia_amplitude, model.inertia_frequency, t, model.inertia_phase
    )
    nominal = model.nominal_inertia
    return (
        (nominal[0, 0] + variation[0], nominal[0, 1], nominal[0, 2]),
        (nominal[1, 0], nominal[1, 1] + variation[1], nominal[1, 2]),
        (nominal[2, 0], nominal[2, 1], nominal[2, 2] + variation[2]),
    )


@inline_jit
def disturbance(t: float, model: PlantModel) -> vec3.Vec3:
    """External torque d(t) of section 4, N·m."""
    return vec3.sine_wave(
        model.disturbance_amplitude, model.disturbance_frequency, t, model.disturbance_phase
    )


@inline_jit
def desired_rate(t: float, model: PlantModel) -> vec3.Vec3:
    """ω_d(t): eq. (53) for the sinusoid, eqs. (54)-(55) for the square wave."""
    if model.reference_kind == SINUSOID:
        amplitude, frequency = model.reference_amplitude, model.reference_frequency
        return (
            amplitude[0] * np.sin(frequency[0] * t),
            amplitude[1] * np.sin(frequency[1] * t),
            amplitude[2] * np.sin(frequency[2] * t),
        )
    half_period_index = int(np.floor(t / model.reference_switch_period))
    sign = 1.0 if half_period_index % 2 == 0 else -1.0
    return vec3.scale(sign, model.reference_amplitude)


@jit
def desired_rate_derivative(t: float, model: PlantModel) -> vec3.Vec3:
    """ω̇_d(t) (zero between the switches of the square wave)."""
    if model.reference_kind == SINUSOID:
        amplitude, frequency = model.reference_amplitude, model.reference_frequency
        return (
            amplitude[0] * frequency[0] * np.cos(frequency[0] * t),
            amplitude[1] * frequency[1] * np.cos(frequency[1] * t),
            amplitude[2] * frequency[2] * np.cos(frequency[2] * t),
        )
    return (0.0, 0.0, 0.0)


@inline_jit
def rate_derivative_given(inertia_now: vec3.Mat3, disturbance_now, omega, torque) -> vec3.Vec3:
    """ω̇ from eq. (1), J ω̇ = -ω^× J ω + u + d, for the inertia J (by rows) and disturbance d
    of one instant."""
    gyroscopic = vec3.cross(omega, vec3.rows_matvec(inertia_now, omega))
    return vec3.solve_rows(
        inertia_now, vec3.add(vec3.add(vec3.negate(gyroscopic), torque), disturbance_now)
    )


@jit
def rate_derivative(t: float, omega, torque, model: PlantModel) -> vec3.Vec3:
    """ω̇ from eq. (1), J ω̇ = -ω^× J ω + u + d, with J = J(t) and d = d(t)."""
    return rate_derivative_given(inertia(t, model), disturbance(t, model), omega, torque)


@inline_jit
def plant_time_terms(t: float, args):
    """What :func:`plant_derivative` needs of the time t: ``(ω_d(t), J(t), d(t))`` (eqs. 53-55
    and section 4), for the plant ``args[1]``. RK4 evaluates them once for its two stages at
    t + h/2 (:func:`~etsc_envs.core.integration.make_rk4_step`)."""
    model = args[1]
    return desired_rate(t, model), inertia(t, model), disturbance(t, model)


@inline_jit
def plant_derivative(time_terms, y: np.ndarray, args) -> np.ndarray:
    """ẏ for ``y = [q, ω, q_d]``: eq. (1) with the held torque ``args[0]``, and eq. (2), with
    the time-dependent terms ``time_terms`` of :func:`plant_time_terms`."""
    torque = args[0]
    omega_d, inertia_now, disturbance_now = time_terms
    omega = vec3.as_vec3(y[4:7])
    attitude_rate = quat_rate(y[0:4], omega)
    desired_attitude_rate = quat_rate(y[7:11], omega_d)
    dy = np.empty(11)
    for i in range(4):
        dy[i] = attitude_rate[i]
        dy[7 + i] = desired_attitude_rate[i]
    vec3.store(dy[4:7], rate_derivative_given(inertia_now, disturbance_now, omega, torque))
    return dy


@jit
def tracking_error(t: float, y: np.ndarray, attitude_gain: np.ndarray, model: PlantModel):
    """Error quaternion q_e and rate ω_e = ω - C ω_d of eq. (4), and z = ω_e + K q_ev (eq. 8).

    Returns ``(q_e, omega_e, z, C, omega_d)``: the tuples q_e, ω_e and z, the array C, and the
    desired rate ω_d(t) they were computed with.
    """
    q_e = quat_error(y[0:4], y[7:11])
    dcm = attitude_matrix(q_e)
    omega_d = desired_rate(t, model)
    omega_e = vec3.subtract(y[4:7], vec3.matvec(dcm, omega_d))
    z = vec3.add(omega_e, vec3.multiply(attitude_gain, q_e))
    return q_e, omega_e, z, dcm, omega_d


@jit
def total_disturbance(
    t: float, y: np.ndarray, torque: np.ndarray, attitude_gain: np.ndarray, model: PlantModel
) -> np.ndarray:
    """The extended state x_2 = F + G + d̄ of eq. (14), i.e. ż - J0⁻¹ u (eqs. 10 and 15).

    Computed from the true plant: ż = ω̇ + ω_e^× C ω_d - C ω̇_d + ½ K (q_e4 I + q_ev^×) ω_e.
    """
    q_e, omega_e, _, dcm, omega_d = tracking_error(t, y, attitude_gain, model)
    z_dot = vec3.add(
        vec3.subtract(
            vec3.add(
                rate_derivative(t, y[4:7], torque, model),
                vec3.cross(omega_e, vec3.matvec(dcm, omega_d)),
            ),
            vec3.matvec(dcm, desired_rate_derivative(t, model)),
        ),
        vec3.multiply(attitude_gain, quat_rate(q_e, omega_e)),
    )
    return vec3.to_array(vec3.subtract(z_dot, vec3.solve(model.nominal_inertia, torque)))

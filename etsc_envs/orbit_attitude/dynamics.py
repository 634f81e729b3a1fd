"""Plant of paper 000: the chaser's 6-DOF motion relative to a virtual leader on a circular orbit.

The chaser obeys eqs. (1)-(2): ``J ω̇ + ω × Jω = M_G + τ + d_τ``, ``m v̇ + m ω × v = f_G + u + d_f``
with the true inertia ``J + ΔJ`` and mass ``m + Δm``, gravity with J2 (f_G) and the
gravity-gradient moment M_G. The virtual leader flies a Keplerian circular orbit with its body
frame on the orbit frame F_o (x radial, y along-track, z orbit normal), so that
``V_d = [0, 0, n, 0, n a, 0]`` and ``V̇_d = 0``.

**Integrated state.** Absolute positions are ~6.8e6 m while the paper's steady errors are
~1e-5 m, so the plant is integrated in the error variables of eqs. (5)-(8) rather than in ECI:

``y = [q_e (4), r_e (3), Δω (3), Δv (3)]``

where ``g_e = g_d⁻¹ g_a = [[R_e, r_e], [0, 1]]`` (R_e = attitude_matrix(q_e)ᵀ maps chaser-body
components to the leader frame, r_e is the chaser's position in the leader frame) and
``Ṽ = [Δω, Δv] = V - Ad_{g_e⁻¹} V_d`` (eq. 7). Its kinematics are ``ġ_e = g_e Ṽ^``. Writing
eq. (8) with the plant of eq. (2) and the leader's own equilibrium
``R_dᵀ g_Kepler(r_d) = ω_d × v_d`` cancels the large terms (-ω × v and gravity, ~8.7 m/s²
each) analytically:

``Δω̇ = ω̇ + Δω × (R_eᵀ ω_d)``
``Δv̇ = -Δω × Δv - 2 (R_eᵀ ω_d) × Δv + R_eᵀ[-ω_d × (ω_d × r_e) + δg] + (u + d_f)/m``

with ``δg = g_Kepler(a e_x + r_e) - g_Kepler(a e_x) + R_dᵀ a_J2(r_a)`` in the leader frame, the
Kepler difference evaluated without cancellation (:func:`kepler_gravity_difference`). Every
integrated quantity is then of the size of the tracking error, and the RK4 truncation error
scales with it. ``docs/fidelity.md`` quotes the resulting error floor.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import jit
from etsc_envs.core.rotations import (
    IDENTITY_ROWS,
    attitude_matrix,
    attitude_rows,
    cross,
    quat_rate,
)

LeaderOrbit = namedtuple(
    "LeaderOrbit",
    [
        "mu",  # gravitational parameter, m³/s²
        "radius",  # a, m
        "rate",  # n = sqrt(μ/a³), rad/s
        "raan",  # Ω, rad
        "inclination",  # i, rad
        "latitude_argument0",  # u(0), rad
    ],
)
"""The virtual leader's circular Keplerian orbit."""

PlantModel = namedtuple(
    "PlantModel",
    [
        "leader",  # LeaderOrbit
        "earth_radius",  # r_e of the J2 term, m
        "j2",  # J2 (0 switches the oblateness off)
        "inertia",  # J + ΔJ, 3×3
        "inertia_inv",
        "mass",  # m + Δm
        "distribution",  # D + ΔD, 6×12: what the thrusters really produce
        "allocation",  # D† = Dᵀ(D Dᵀ)⁻¹ of the nominal D, 12×6
        "max_force",  # f_max, N
        "bias_ratio",  # f̄_i = ratio · sat(f_i)
        "torque_offset",  # d_τ = offset + amplitude sin(frequency t + phase)
        "torque_amplitude",
        "torque_frequency",
        "torque_phase",
        "force_offset",  # d_f = offset + amplitude sin(force_frequency t + phase)
        "force_amplitude",
        "force_frequency",  # 2π‖ω_d‖, rad/s
        "force_phase",
    ],
)
"""Everything the true plant depends on, as arrays and scalars."""


PlantTerms = namedtuple(
    "PlantTerms",
    [
        "leader",
        "earth_radius",
        "j2",
        "inertia",  # rows of J + ΔJ
        "inertia_inv",
        "mass",
        "torque_offset",
        "torque_amplitude",
        "torque_frequency",
        "torque_phase",
        "force_offset",
        "force_amplitude",
        "force_frequency",
        "force_phase",
    ],
)
"""The fields of :class:`PlantModel` that the relative motion reads, as floats and tuples
(:func:`plant_terms`): an RK4 step passes them to each stage's derivative without copying
array structures or counting their references."""


@jit
def plant_terms(model: PlantModel) -> PlantTerms:
    """The :class:`PlantTerms` of ``model``."""
    return PlantTerms(
        model.leader,
        model.earth_radius,
        model.j2,
        vec3.rows(model.inertia),
        vec3.rows(model.inertia_inv),
        model.mass,
        vec3.as_vec3(model.torque_offset),
        vec3.as_vec3(model.torque_amplitude),
        vec3.as_vec3(model.torque_frequency),
        vec3.as_vec3(model.torque_phase),
        vec3.as_vec3(model.force_offset),
        vec3.as_vec3(model.force_amplitude),
        model.force_frequency,
        vec3.as_vec3(model.force_phase),
    )


# --------------------------------------------------------------------------- leader
@jit
def _rotation_z(angle: float) -> vec3.Mat3:
    c, s = np.cos(angle), np.sin(angle)
    return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))


@jit
def _rotation_x(angle: float) -> vec3.Mat3:
    c, s = np.cos(angle), np.sin(angle)
    return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))


@jit
def leader_rotation_rows(t: float, leader: LeaderOrbit) -> vec3.Mat3:
    """R_d(t): leader body frame (= F_o: radial, along-track, normal) to ECI components, as the
    tuple of its rows.

    ``R_d = R_z(Ω) R_x(i) R_z(u(t))`` with the argument of latitude ``u = u(0) + n t``.
    """
    return vec3.product(
        vec3.product(_rotation_z(leader.raan), _rotation_x(leader.inclination)),
        _rotation_z(leader.latitude_argument0 + leader.rate * t),
    )


@jit
def leader_rotation(t: float, leader: LeaderOrbit) -> np.ndarray:
    """R_d(t) (:func:`leader_rotation_rows`) as a 3×3 array."""
    return vec3.to_matrix(leader_rotation_rows(t, leader))


@jit
def leader_position(t: float, leader: LeaderOrbit) -> np.ndarray:
    """r_d(t) in ECI, m."""
    return leader_rotation(t, leader)[:, 0] * leader.radius


@jit
def leader_pose(t: float, leader: LeaderOrbit) -> np.ndarray:
    """g_d(t) = [[R_d, r_d], [0, 1]]."""
    g = np.eye(4)
    rotation = leader_rotation(t, leader)
    g[:3, :3] = rotation
    g[:3, 3] = rotation[:, 0] * leader.radius
    return g


@jit
def leader_twist_of(leader: LeaderOrbit) -> tuple:
    """V_d = [ω_d, v_d] = [0, 0, n, 0, n a, 0] in the leader's body frame (constant), as a
    6-tuple."""
    return (0.0, 0.0, leader.rate, 0.0, leader.rate * leader.radius, 0.0)


# --------------------------------------------------------------------------- gravity
@jit
def kepler_gravity(position, mu: float) -> vec3.Vec3:
    """-μ r / ‖r‖³."""
    r2 = vec3.dot(position, position)
    return vec3.scale(-mu / (r2 * np.sqrt(r2)), position)


@jit
def kepler_gravity_difference(offset, radius: float, mu: float) -> vec3.Vec3:
    """``g(a e_x + ρ) - g(a e_x)`` for ``g(r) = -μ r/‖r‖³``, without cancellation.

    With ``r = d + ρ`` and ``d = a e_x``: ``g(r) - g(d) = -μ/‖r‖³ [ρ + (1 - ‖r‖³/a³) d]`` and
    ``1 - ‖r‖³/a³ = -expm1(1.5 log1p(s))``, ``s = (2 a ρ_x + ρ·ρ)/a²`` (Battin's device), so the
    result keeps full relative precision for any small ρ.
    """
    s = (2.0 * radius * offset[0] + vec3.dot(offset, offset)) / (radius * radius)
    growth = 1.5 * math.log1p(s)
    one_minus_ratio = -math.expm1(growth)
    r3 = radius**3 * math.exp(growth)
    out = vec3.scale(-mu / r3, offset)
    return (out[0] - mu / r3 * one_minus_ratio * radius, out[1], out[2])


@jit
def j2_acceleration(position, mu: float, earth_radius: float, j2: float) -> vec3.Vec3:
    """``-(3 J2 μ r_e² / (2‖r‖⁵)) (E - 5 r_z²/‖r‖² I) r`` with ``E = diag(1, 1, 3)`` (ECI)."""
    r2 = vec3.dot(position, position)
    factor = -1.5 * j2 * mu * earth_radius**2 / (r2 * r2 * np.sqrt(r2))
    z2 = position[2] * position[2] / r2
    return (
        factor * (1.0 - 5.0 * z2) * position[0],
        factor * (1.0 - 5.0 * z2) * position[1],
        factor * (3.0 - 5.0 * z2) * position[2],
    )


@jit
def gravity_gradient_torque(position_body, inertia, mu: float) -> vec3.Vec3:
    """M_G = 3 μ/‖r‖⁵ (Rᵀr) × J (Rᵀr), with the position given in body components (Rᵀr) and J
    by its rows (an array or a :data:`~etsc_envs.core.vec3.Mat3`)."""
    r2 = vec3.dot(position_body, position_body)
    return vec3.scale(
        3.0 * mu / (r2 * r2 * np.sqrt(r2)),
        vec3.cross(position_body, vec3.rows_matvec(inertia, position_body)),
    )


# --------------------------------------------------------------------------- disturbances
@jit
def disturbance_torque(t: float, model: PlantModel) -> vec3.Vec3:
    """d_τ(t) of section IV, N·m (body frame)."""
    return vec3.add(
        model.torque_offset,
        vec3.sine_wave(model.torque_amplitude, model.torque_frequency, t, model.torque_phase),
    )


@jit
def disturbance_force(t: float, model: PlantModel) -> vec3.Vec3:
    """d_f(t) of section IV, N (body frame); its frequency is 2π‖ω_d‖."""
    angle = model.force_frequency * t
    amplitude, phase = model.force_amplitude, model.force_phase
    return vec3.add(
        model.force_offset,
        (
            amplitude[0] * np.sin(angle + phase[0]),
            amplitude[1] * np.sin(angle + phase[1]),
            amplitude[2] * np.sin(angle + phase[2]),
        ),
    )


# --------------------------------------------------------------------------- thrusters
@jit
def thruster_outputs(command: np.ndarray, model: PlantModel):
    """Allocation and actuator model of eqs. (10)-(12): the wrench the thrusters really apply.

    ``f = D† Γ_c`` (the paper's allocation), ``u_a = sat(f) + f̄`` with the output bias
    ``f̄ = ratio · sat(f)``, and ``Γ_actual = (D + ΔD) u_a``. Returns ``(f, u_a, Γ_actual)``.
    """
    demand = model.allocation @ command
    limit = model.max_force
    saturated = np.minimum(np.maximum(demand, -limit), limit)
    output = saturated * (1.0 + model.bias_ratio)
    return demand, output, model.distribution @ output


# --------------------------------------------------------------------------- relative motion
@jit
def plant_time_terms(t: float, args):
    """What :func:`relative_rate` needs of the time t: ``(R_d(t), d_τ(t), d_f(t))`` (R_d as
    rows; the identity, unused, without the J2 term). ``args = (wrench, terms)``, ``terms`` the
    :class:`PlantTerms`."""
    model = args[1]
    rotation_d = leader_rotation_rows(t, model.leader) if model.j2 != 0.0 else IDENTITY_ROWS
    return rotation_d, disturbance_torque(t, model), disturbance_force(t, model)


@jit
def relative_derivative(t: float, y: np.ndarray, args) -> np.ndarray:
    """ẏ for ``y = [q_e, r_e, Δω, Δv]`` at time t under the body-frame thruster wrench
    ``args[0]`` of the plant ``args[1]`` (a :class:`PlantModel`; :func:`relative_rate`)."""
    wrench, model = args
    terms = (wrench, plant_terms(model))
    return relative_rate(plant_time_terms(t, terms), y, terms)


@jit
def relative_rate(time_terms, y: np.ndarray, args) -> np.ndarray:
    """ẏ for ``y = [q_e, r_e, Δω, Δv]`` under the body-frame thruster wrench ``args[0]``, with
    the time-dependent terms ``time_terms`` of :func:`plant_time_terms`.

    ``args = (wrench, terms)``, ``terms`` the plant's :class:`PlantTerms`; the wrench is held
    constant over the sampling period (ZOH of the thruster commands). See the module docstring
    for the equations.
    """
    wrench, model = args
    rotation_d, torque_disturbance, force_disturbance = time_terms
    leader = model.leader
    q = y[0:4]
    offset = y[4:7]
    rate_error = y[7:10]
    velocity_error = y[10:13]
    to_body = attitude_rows(q)  # R_eᵀ
    leader_rate = (0.0, 0.0, leader.rate)
    leader_rate_body = vec3.rows_matvec(to_body, leader_rate)  # R_eᵀ ω_d

    # rotation: J ω̇ = -ω × Jω + M_G + τ + d_τ, then Δω̇ = ω̇ + Δω × R_eᵀω_d (ω̇_d = 0)
    omega = vec3.add(rate_error, leader_rate_body)
    position_leader = (offset[0] + leader.radius, offset[1], offset[2])
    position_body = vec3.rows_matvec(to_body, position_leader)
    torque = vec3.subtract(
        vec3.add(
            vec3.add(wrench[0:3], gravity_gradient_torque(position_body, model.inertia, leader.mu)),
            torque_disturbance,
        ),
        vec3.cross(omega, vec3.rows_matvec(model.inertia, omega)),
    )
    rate_error_dot = vec3.add(
        vec3.rows_matvec(model.inertia_inv, torque), vec3.cross(rate_error, leader_rate_body)
    )

    # translation: Coriolis, centrifugal, differential gravity, forces
    gravity_leader = kepler_gravity_difference(offset, leader.radius, leader.mu)
    if model.j2 != 0.0:
        position_eci = vec3.rows_matvec(rotation_d, position_leader)
        gravity_leader = vec3.add(
            gravity_leader,
            vec3.rows_matvec_transposed(
                rotation_d, j2_acceleration(position_eci, leader.mu, model.earth_radius, model.j2)
            ),
        )
    centrifugal = vec3.negate(vec3.cross(leader_rate, vec3.cross(leader_rate, offset)))
    force = vec3.add(wrench[3:6], force_disturbance)
    velocity_error_dot = vec3.add(
        vec3.add(
            vec3.subtract(
                vec3.negate(vec3.cross(rate_error, velocity_error)),
                vec3.scale(2.0, vec3.cross(leader_rate_body, velocity_error)),
            ),
            vec3.rows_matvec(to_body, vec3.add(centrifugal, gravity_leader)),
        ),
        vec3.divide(force, (model.mass, model.mass, model.mass)),
    )

    attitude_rate = quat_rate(q, rate_error)
    # R_e Δv with the row kernel on the transpose: vec3.rows_matvec_transposed sums in another
    # order (dgemv's on a transposed view) and would change the last bits
    offset_rate = vec3.rows_matvec(vec3.transpose(to_body), velocity_error)
    dy = np.empty(13)
    for i in range(4):
        dy[i] = attitude_rate[i]
    for i in range(3):
        dy[4 + i] = offset_rate[i]
        dy[7 + i] = rate_error_dot[i]
        dy[10 + i] = velocity_error_dot[i]
    return dy


@jit
def error_pose(y: np.ndarray) -> np.ndarray:
    """g_e = [[R_e, r_e], [0, 1]] of the integrated state."""
    g = np.eye(4)
    g[:3, :3] = attitude_matrix(y[0:4]).T
    g[:3, 3] = y[4:7]
    return g


@jit
def chaser_pose_and_twist(t: float, y: np.ndarray, leader: LeaderOrbit):
    """The chaser's absolute g_a = g_d g_e (ECI) and body twist V = Ṽ + Ad_{g_e⁻¹} V_d.

    Only for diagnostics and tests: the plant is never integrated in these variables.
    """
    g_e = error_pose(y)
    g_a = leader_pose(t, leader) @ g_e
    rotation_e_t = np.ascontiguousarray(g_e[:3, :3].T)
    leader_rate = np.zeros(3)
    leader_rate[2] = leader.rate
    leader_velocity = np.zeros(3)
    leader_velocity[1] = leader.rate * leader.radius
    twist = np.empty(6)
    twist[0:3] = y[7:10] + rotation_e_t @ leader_rate
    twist[3:6] = y[10:13] + rotation_e_t @ (
        leader_velocity + cross(leader_rate, np.ascontiguousarray(y[4:7]))
    )
    return g_a, twist

"""Orbit-attitude coupled dynamics near the asteroid, eqs. (1) and (7)-(12) of paper 003.

Frames: A is the asteroid's body frame (x long axis, z spin axis), in which eq. (1) writes the
orbit; I is the inertial frame that coincides with A at t = 0, so A turns by ω_T t about z;
B is the spacecraft's body frame. The Sun is fixed in I (its motion over 12 000 s is 0.14°).

The integrated state is ``y = [r (3), v (3), q (4), ω (3), b̂ (1), Δv (1)]``: position and
velocity of eq. (1) in A (m, m/s), attitude q of B relative to I (scalar last) and body rate ω
of eqs. (9)-(12), the adaptive gain b̂ of eq. (19), and the accumulated Δv = ∫ ‖τ‖/m dt.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.asteroid.gravity_grid import grid_potential_and_attraction
from etsc_envs.core import vec3
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import fused_matmul
from etsc_envs.core.rotations import attitude_matrix, quat_rate

STATE_SIZE = 15
R, V, Q, W, B_HAT, DELTA_V = (
    slice(0, 3),
    slice(3, 6),
    slice(6, 10),
    slice(10, 13),
    13,
    14,
)

PlantModel = namedtuple(
    "PlantModel",
    [
        "gm",  # G M of eqs. (7) and (11), m³/s²
        "spin_rate",  # ω_T of Ω_T = [0, 0, ω_T], rad/s
        "mass",  # m of eq. (1), kg
        "inertia",  # J of eq. (21), 3×3, kg·m²
        "srp_pressure_area",  # P A of eq. (8), N
        "srp_normal_coefficient",  # 2 (C_s + C_d / 3) of eq. (8)
        "srp_sun_coefficient",  # C_d + C_a of eq. (8)
        "srp_arm",  # [0, L, 0] of eq. (10), m
        "thrust_arm",  # [0, L_τ, 0]: thrust torque arm (0 in the paper's eq. 9), m
        "perturbation_scale",  # 1 keeps f_gg and f_SRP in eq. (1), 0 removes them
        "sun_inertial",  # unit vector toward the Sun in I
        "grid",  # GridField of the polyhedral gravity
    ],
)
"""Everything the plant depends on, as arrays and scalars."""


@jit
def inertial_to_asteroid(t: float, spin_rate: float) -> np.ndarray:
    """C_AI(t): maps I-frame components to A-frame components (A turned by ω_T t about z)."""
    angle = spin_rate * t
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros((3, 3))
    out[0, 0] = c
    out[0, 1] = s
    out[1, 0] = -s
    out[1, 1] = c
    out[2, 2] = 1.0
    return out


@jit
def asteroid_to_body(t: float, q: np.ndarray, spin_rate: float) -> np.ndarray:
    """C_BA(t) = C_BI(q) C_AI(t)ᵀ: maps A-frame components to spacecraft-body components."""
    return fused_matmul(attitude_matrix(q), inertial_to_asteroid(t, spin_rate).T)


@jit
def srp_force(body_from_asteroid: np.ndarray, sun_asteroid, model: PlantModel) -> vec3.Vec3:
    """f_SRP = -[2 (C_s + C_d/3) n̂_fp + (C_d + C_a) n̂_sp] P A of eq. (8), in A.

    n̂_fp is the panel normal, the body x axis; n̂_sp points from the spacecraft to the Sun.
    """
    panel_normal = body_from_asteroid[0, :]
    return vec3.scale(
        -model.srp_pressure_area,
        vec3.add(
            vec3.scale(model.srp_normal_coefficient, panel_normal),
            vec3.scale(model.srp_sun_coefficient, sun_asteroid),
        ),
    )


@jit
def gravity_gradient_force(r, body_from_asteroid: np.ndarray, model: PlantModel) -> vec3.Vec3:
    """f_gg = -(3 G M / ‖r‖⁵) [J + (tr J / 2 - (5/2) r̂ᵀ J r̂) I] r of eq. (7), in A.

    J is the spacecraft's inertia expressed in A, C_BAᵀ J C_BA.
    """
    inertia_a = fused_matmul(fused_matmul(body_from_asteroid.T, model.inertia), body_from_asteroid)
    radius = np.sqrt(vec3.dot(r, r))
    unit = vec3.divide(r, (radius, radius, radius))
    scalar = 0.5 * np.trace(model.inertia) - 2.5 * vec3.dot(unit, vec3.matvec(inertia_a, unit))
    return vec3.scale(
        -3.0 * model.gm / radius**5, vec3.add(vec3.matvec(inertia_a, r), vec3.scale(scalar, r))
    )


@jit
def gravity_gradient_torque(r_body, model: PlantModel) -> vec3.Vec3:
    """T_gg = (3 G M / ‖r‖⁵) r × J r of eq. (11), with r in B."""
    radius = np.sqrt(vec3.dot(r_body, r_body))
    return vec3.scale(
        3.0 * model.gm / radius**5, vec3.cross(r_body, vec3.matvec(model.inertia, r_body))
    )


@jit
def orbit_acceleration(r: np.ndarray, v: np.ndarray, force, model: PlantModel) -> vec3.Vec3:
    """r̈ of eq. (1): g(r)_pg - 2 Ω_T × ṙ - Ω_T × (Ω_T × r) + (f_gg + f_SRP + τ)/m, in A."""
    _, attraction = grid_potential_and_attraction(r, model.grid)
    w = model.spin_rate
    coriolis = (2.0 * w * v[1], -2.0 * w * v[0], 0.0)  # -2 Ω × v
    centrifugal = (w * w * r[0], w * w * r[1], 0.0)  # -Ω × (Ω × r)
    mass = model.mass
    return vec3.add(
        vec3.add(vec3.add(attraction, coriolis), centrifugal),
        vec3.divide(force, (mass, mass, mass)),
    )


@jit
def plant_derivative(t: float, y: np.ndarray, thrust, torque, model: PlantModel) -> np.ndarray:
    """ẏ of eqs. (1), (9) and (12) for the thrust τ (A frame, N) and control torque u (B, N·m).

    The entries of b̂ and Δv are left at zero (the controller integrates them).
    """
    r, v, q, omega = y[R], y[V], y[Q], y[W]
    body_from_asteroid = asteroid_to_body(t, q, model.spin_rate)
    sun_asteroid = vec3.matvec(inertial_to_asteroid(t, model.spin_rate), model.sun_inertial)
    solar = srp_force(body_from_asteroid, sun_asteroid, model)
    perturbation = vec3.add(gravity_gradient_force(r, body_from_asteroid, model), solar)
    force = vec3.add(vec3.scale(model.perturbation_scale, perturbation), thrust)
    disturbance = vec3.add(
        vec3.add(
            gravity_gradient_torque(vec3.matvec(body_from_asteroid, r), model),
            vec3.cross(model.srp_arm, vec3.matvec(body_from_asteroid, solar)),
        ),
        vec3.cross(model.thrust_arm, vec3.matvec(body_from_asteroid, thrust)),
    )
    inertia = model.inertia
    gyroscopic = vec3.cross(omega, vec3.matvec(inertia, omega))
    acceleration = orbit_acceleration(r, v, force, model)
    attitude_rate = quat_rate(q, omega)
    rate_derivative = vec3.solve(
        inertia, vec3.add(vec3.add(vec3.negate(gyroscopic), disturbance), torque)
    )
    dy = np.zeros(STATE_SIZE)
    dy[R] = v
    vec3.store(dy[V], acceleration)
    for i in range(4):
        dy[Q][i] = attitude_rate[i]
    vec3.store(dy[W], rate_derivative)
    return dy


@jit
def jacobi_integral(r: np.ndarray, v: np.ndarray, model: PlantModel) -> float:
    """C = ½‖ṙ‖² - ½ ω_T² (x² + y²) - U(r), constant along eq. (1) when only the polyhedral
    gravity acts (m²/s²)."""
    potential, _ = grid_potential_and_attraction(r, model.grid)
    w = model.spin_rate
    return 0.5 * vec3.dot(v, v) - 0.5 * w * w * (r[0] ** 2 + r[1] ** 2) - potential

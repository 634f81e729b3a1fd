"""One sampling period of the closed loop of paper 000, compiled as a single call.

At every sampling instant t_k the controller measures g_e and Ṽ, evaluates S and H1, and computes
Γ_cout (eq. 22); the trigger side compares it with the command Γ_c held at the thrusters
(eq. 21). Over [t_k, t_k + h) the thrusters apply the held command through the allocation and
actuator model (eqs. 10-12), the plant is integrated by RK4 in the error variables
(:mod:`etsc_envs.orbit_attitude.dynamics`), and the controller's own states — ESO eq. (14),
adaptive law eq. (24) and the integral of eq. (23) — advance by one forward-Euler step, as a
digital controller running at the sampling period does.

Controller state ``c = [Ẑ1 (6), Ẑ2 (6), ϕ̂ (2), ∫_{t_k}^t ϕ̂ ds (2)]``.
"""

from __future__ import annotations

import numpy as np

from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.rotations import se3_log
from etsc_envs.orbit_attitude.controller import (
    ControllerGains,
    adaptive_derivative,
    adaptive_gain,
    control_law,
    eso_derivative,
    eso_input,
    inertia_solve,
    inertia_times,
    known_dynamics,
    sliding_surface,
    surface_drift,
)
from etsc_envs.orbit_attitude.dynamics import (
    PlantModel,
    error_pose,
    relative_derivative,
    thruster_outputs,
)

N_FEATURES = 24
N_CONTROLLER_STATE = 16
N_DIAGNOSTICS = 14
"""``[‖Φ‖, ‖χ‖, max|Φ_i|, max|Δω_i|, max|χ_i|, max|Δv_i|, max|e1_i| (i ≤ 3), max|e1_i| (i > 3),
max|(J e2)_i| (N·m), max|m e2_i| (N), Σ|u_a| h (N·s), ‖Δω‖, ‖Δv‖, 1 if all finite else 0]``
after each step."""
integrate_plant = make_rk4_step(relative_derivative)


@jit
def controller_view(t: float, y: np.ndarray, c: np.ndarray, gains: ControllerGains):
    """What the controller computes at ``t`` from the measured g_e, Ṽ and its own state ``c``.

    Returns ``(η̃, S, H1, H + Ξ⁻¹f(Ξ), Γ_cout, Γ_cout at a transmission)``. ``Γ_cout`` uses the
    integral of eq. (23) accumulated since the last transmission (what the trigger compares
    with the held command); a transmission at ``t`` restarts that integral, so the command it
    sends is the second one, with the integral at zero.
    """
    g_e = error_pose(y)
    twist_error = np.ascontiguousarray(y[7:13])
    eta = se3_log(g_e)
    known = known_dynamics(t, g_e, twist_error, gains)
    surface = sliding_surface(eta, twist_error, gains)
    drift = surface_drift(known, eta, twist_error, gains)
    z2 = c[6:12]
    phi_hat = c[12:14]
    command = control_law(
        drift, z2, surface, adaptive_gain(phi_hat, c[14:16], surface, t, gains), gains
    )
    fresh = control_law(
        drift, z2, surface, adaptive_gain(phi_hat, np.zeros(2), surface, t, gains), gains
    )
    return eta, surface, drift, known, command, fresh


@jit
def observation_features(
    eta: np.ndarray, surface: np.ndarray, y: np.ndarray, held: np.ndarray, command: np.ndarray
) -> np.ndarray:
    """``[e_c (6), S (6), η̃ (6), Ṽ (6)]`` with ``e_c = Γ_c - Γ_cout`` (eq. 21's inputs)."""
    features = np.empty(N_FEATURES)
    features[0:6] = held - command
    features[6:12] = surface
    features[12:18] = eta
    features[18:24] = y[7:13]
    return features


@jit
def total_disturbance(
    t: float,
    y: np.ndarray,
    wrench: np.ndarray,
    held: np.ndarray,
    known: np.ndarray,
    model: PlantModel,
    gains: ControllerGains,
) -> np.ndarray:
    """The true Δd = dṼ/dt - (H + Ξ⁻¹f(Ξ)) - Ξ⁻¹Γ_c of eq. (9), from the true plant.

    ``wrench`` is what the thrusters really apply for the held command ``held``; Γ_c is what
    the ESO is fed (:func:`~etsc_envs.orbit_attitude.controller.eso_input`), so Δd is exactly
    the extended state Z2 the ESO estimates.
    """
    true_rate = relative_derivative(t, y, (wrench, model))[7:13]
    return true_rate - known - inertia_solve(eso_input(held, gains), gains)


@jit
def tracking_cost(eta: np.ndarray, twist_error: np.ndarray, reference: np.ndarray) -> float:
    """Per-step accuracy cost ``¼ Σ_j log(1 + ‖x_j‖ / ref_j)`` for x = Φ, Δω, χ, Δv."""
    cost = np.log1p(np.sqrt(eta[0:3] @ eta[0:3]) / reference[0])
    cost += np.log1p(np.sqrt(twist_error[0:3] @ twist_error[0:3]) / reference[1])
    cost += np.log1p(np.sqrt(eta[3:6] @ eta[3:6]) / reference[2])
    cost += np.log1p(np.sqrt(twist_error[3:6] @ twist_error[3:6]) / reference[3])
    return 0.25 * cost


@jit
def closed_loop_step(
    t: float,
    h: float,
    substeps: int,
    y: np.ndarray,
    c: np.ndarray,
    held: np.ndarray,
    model: PlantModel,
    gains: ControllerGains,
    view: np.ndarray,
    cost_reference: np.ndarray,
    with_disturbance: bool,
):
    """Advance plant and controller from t to t + h with the held command ``held``.

    ``view = [S(t), H1(t)]`` is what the controller evaluated at t (returned by the previous
    step, or :func:`initial_view`). Returns ``(y_next, c_next, fresh_command, features,
    view_next, cost, diagnostics, e1, e2, thruster_output)``: the states at t + h, the command a
    transmission at t + h would send, the observation features and ``[S, H1]`` there, the
    step's :func:`tracking_cost` at t + h, the :data:`N_DIAGNOSTICS` summary, the ESO errors
    ``e1 = Ẑ1 - S`` and ``e2 = Ẑ2 - Δd`` at t + h (Δd with the command held over the period
    just simulated; only if ``with_disturbance``, else zeros), and the thruster outputs u_a over
    the period (N).
    """
    # controller at t: ESO, adaptive law and the integral of eq. (23), forward Euler
    surface = view[0:6]
    drift = view[6:12]
    dz1, dz2 = eso_derivative(c[0:6], c[6:12], surface, drift, eso_input(held, gains), gains)
    c_next = c.copy()
    c_next[0:6] += h * dz1
    c_next[6:12] += h * dz2
    c_next[12:14] += h * adaptive_derivative(c[12:14], surface, t, gains)
    c_next[14:16] += h * c[12:14]

    # plant over [t, t + h) under the held command (ZOH at the thrusters)
    _, output, wrench = thruster_outputs(held, model)
    y_next = y
    dt = h / substeps
    for i in range(substeps):
        y_next = integrate_plant(t + i * dt, y_next, dt, (wrench, model))
        y_next[0:4] /= np.sqrt(y_next[0:4] @ y_next[0:4])

    # what the controller sees at t + h
    t_next = t + h
    eta, surface, drift, known, command, fresh = controller_view(t_next, y_next, c_next, gains)
    features = observation_features(eta, surface, y_next, held, command)
    view_next = np.empty(12)
    view_next[0:6] = surface
    view_next[6:12] = drift
    e1 = c_next[0:6] - surface
    e2 = np.zeros(6)
    if with_disturbance:
        e2 = c_next[6:12] - total_disturbance(t_next, y_next, wrench, held, known, model, gains)
    twist_error = y_next[7:13]
    cost = tracking_cost(eta, twist_error, cost_reference)
    e2_physical = inertia_times(e2, gains)
    diagnostics = np.empty(N_DIAGNOSTICS)
    diagnostics[0] = np.sqrt(eta[0:3] @ eta[0:3])
    diagnostics[1] = np.sqrt(eta[3:6] @ eta[3:6])
    diagnostics[2] = np.abs(eta[0:3]).max()
    diagnostics[3] = np.abs(twist_error[0:3]).max()
    diagnostics[4] = np.abs(eta[3:6]).max()
    diagnostics[5] = np.abs(twist_error[3:6]).max()
    diagnostics[6] = np.abs(e1[0:3]).max()
    diagnostics[7] = np.abs(e1[3:6]).max()
    diagnostics[8] = np.abs(e2_physical[0:3]).max()
    diagnostics[9] = np.abs(e2_physical[3:6]).max()
    diagnostics[10] = h * np.abs(output).sum()
    diagnostics[11] = np.sqrt(twist_error[0:3] @ twist_error[0:3])
    diagnostics[12] = np.sqrt(twist_error[3:6] @ twist_error[3:6])
    diagnostics[13] = 1.0 if np.isfinite(y_next).all() and np.isfinite(features).all() else 0.0
    return y_next, c_next, fresh, features, view_next, cost, diagnostics, e1, e2, output


@jit
def initial_view(y: np.ndarray, c: np.ndarray, gains: ControllerGains):
    """At t = 0: ``(η̃, [S, H1], Γ_cout)`` — Γ_cout is the command a transmission at t_0 sends."""
    eta, surface, drift, _, command, _ = controller_view(0.0, y, c, gains)
    view = np.empty(12)
    view[0:6] = surface
    view[6:12] = drift
    return eta, view, command

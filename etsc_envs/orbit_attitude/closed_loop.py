"""One sampling period of the closed loop of paper 000, compiled as a single call.

At every sampling instant t_k the controller measures g_e and Ṽ, evaluates S and H1, and computes
Γ_cout (eq. 22); the trigger side compares it with the command Γ_c held at the thrusters
(eq. 21). Over [t_k, t_k + h) the thrusters apply the held command through the allocation and
actuator model (eqs. 10-12), the plant is integrated by RK4 in the error variables
(:mod:`etsc_envs.orbit_attitude.dynamics`), and the controller's own states — ESO eq. (14),
adaptive law eq. (24) and the integral of eq. (23) — advance by one forward-Euler step, as a
digital controller running at the sampling period does.

Controller state ``c = [Ẑ1 (6), Ẑ2 (6), ϕ̂ (2), ∫_{t_k}^t ϕ̂ ds (2)]``.

The environment keeps one loop in a flat state row (layout below) and reaches it through the
kernels of :data:`KERNELS` (see :mod:`etsc_envs.core.compiled_loop`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.compiled_loop import ProblemKernels, always_accepts, stored_features
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import as_array, fused_dot
from etsc_envs.core.rotations import attitude_rows, se3_log_parts
from etsc_envs.orbit_attitude.controller import (
    ControllerGains,
    adaptive_denominator_of,
    adaptive_derivative,
    adaptive_gain_of,
    block_norms_of,
    control_law,
    eso_derivative,
    eso_input,
    fixed_gain_feedback,
    inertia_solve,
    inertia_solve_of,
    inertia_times,
    inertia_times_of,
    known_dynamics_of,
    sliding_surface,
    surface_drift,
)
from etsc_envs.orbit_attitude.dynamics import (
    LeaderOrbit,
    PlantModel,
    plant_terms,
    plant_time_terms,
    relative_derivative,
    relative_rate,
    thruster_outputs,
)

N_FEATURES = 24
N_DIAGNOSTICS = 14
"""``[‖Φ‖, ‖χ‖, max|Φ_i|, max|Δω_i|, max|χ_i|, max|Δv_i|, max|e1_i| (i ≤ 3), max|e1_i| (i > 3),
max|(J e2)_i| (N·m), max|m e2_i| (N), Σ|u_a| h (N·s), ‖Δω‖, ‖Δv‖, 1 if all finite else 0]``
after each step."""

PLANT = slice(0, 13)  # y = [q_e, r_e, Δω, Δv] of the error variables (dynamics module)
CONTROLLER = slice(13, 29)  # c = [Ẑ1, Ẑ2, ϕ̂, ∫_{t_k}^t ϕ̂ ds], eqs. (14), (23), (24)
VIEW = slice(29, 41)  # [S, H1] the controller evaluated at the current instant
COMMAND = slice(41, 47)  # Γ_cout a transmission now sends (eq. 22, integral of eq. 23 at zero)
FEATURES = slice(47, 71)  # [e_c, S, η̃, Ṽ], see observation_features
THRUSTER_OUTPUT = slice(71, 83)  # u_a over the last period, eqs. (10)-(12), N
DIAGNOSTICS = slice(83, 97)  # the N_DIAGNOSTICS summary of the last step
STEADY_MAX = slice(97, 105)  # maxima of DIAGNOSTICS[2:10] over the steady-state window
IMPULSE = 105  # Σ|u_a| h over the episode, N·s
SETTLING_BOUND = slice(106, 108)  # the settling bands on ‖Φ‖ and ‖χ‖
SETTLING_TIME = slice(108, 110)  # since when ‖Φ‖ (‖χ‖) stays in its band; NaN while outside
LEADER_RAAN = 110  # the leader's Ω, rad
LEADER_LATITUDE = 111  # the leader's argument of latitude u(0), rad
TORQUE_PHASE = slice(112, 115)  # phases of d_τ
FORCE_PHASE = slice(115, 118)  # phases of d_f
MISALIGNMENT = slice(118, 190)  # ΔD, 6×12 row-major
TRUE_DISTRIBUTION = slice(190, 262)  # D + ΔD, 6×12 row-major (summed once per episode)
HELD_COMMAND = slice(262, 268)  # the Γ_c THRUSTER_OUTPUT, HELD_WRENCH and HELD_FED were made of
HELD_WRENCH = slice(268, 274)  # Γ_actual of Γ_c, eqs. (10)-(12)
HELD_FED = slice(274, 280)  # what the ESO is fed for Γ_c (controller.eso_input)
STATE_WIDTH = 280
"""Layout of the state row."""

INTEGRAL = slice(14, 16)
"""∫_{t_k}^t ϕ̂ ds inside the controller state ``c``."""

NON_FINITE, POSITION_DIVERGED, RATE_DIVERGED, VELOCITY_DIVERGED = 1, 2, 3, 4
"""Failure codes of :func:`loop_failure`."""

LoopConstants = namedtuple(
    "LoopConstants",
    [
        "model",  # PlantModel with the nominal leader angles, phases and D (ΔD = 0)
        "gains",  # ControllerGains with the nominal leader angles
        "cost_reference",  # the four references of tracking_cost
        "plant_substeps",  # RK4 steps of the plant per sampling period
        "steady_start",  # steps after which the steady-state window begins
        "max_position_error",  # failure bounds on ‖χ‖ (m), ‖Δω‖ (rad/s), ‖Δv‖ (m/s)
        "max_rate_error",
        "max_velocity_error",
    ],
)
"""What every episode shares; the leader's angles, the disturbance phases and ΔD of the
episode are taken from the state row (:func:`episode_model`, :func:`episode_gains`)."""

integrate_plant = make_rk4_step(relative_rate, plant_time_terms)


@jit
def controller_terms(t: float, y: np.ndarray, c: np.ndarray, gains: ControllerGains):
    """What the controller computes at ``t`` from the measured g_e, Ṽ and its own state ``c``,
    as 6-tuples (see :func:`controller_view`)."""
    rotation_e = vec3.transpose(attitude_rows(y[0:4]))  # g_e = [[R_e, r_e], [0, 1]]
    position_e = y[4:7]
    twist_error = y[7:13]
    phi, chi = se3_log_parts(rotation_e, position_e)
    eta = (phi[0], phi[1], phi[2], chi[0], chi[1], chi[2])
    known = known_dynamics_of(t, rotation_e, position_e, twist_error, gains)
    surface = sliding_surface(eta, twist_error, gains)
    drift = surface_drift(known, eta, twist_error, gains)
    z2 = c[6:12]
    phi_hat = c[12:14]
    fixed_gain = fixed_gain_feedback(drift, z2, surface, gains)
    denominator = adaptive_denominator_of(block_norms_of(surface), t, gains)
    integral = c[14:16]
    command = control_law(
        fixed_gain, surface, adaptive_gain_of(phi_hat, integral, denominator, gains)
    )
    restarted = adaptive_gain_of(phi_hat, (0.0, 0.0), denominator, gains)
    fresh = control_law(fixed_gain, surface, restarted)
    return eta, surface, drift, known, command, fresh


@jit
def controller_view(t: float, y: np.ndarray, c: np.ndarray, gains: ControllerGains):
    """What the controller computes at ``t`` from the measured g_e, Ṽ and its own state ``c``.

    Returns ``(η̃, S, H1, H + Ξ⁻¹f(Ξ), Γ_cout, Γ_cout at a transmission)`` as arrays.
    ``Γ_cout`` uses the integral of eq. (23) accumulated since the last transmission (what the
    trigger compares with the held command); a transmission at ``t`` restarts that integral, so
    the command it sends is the second one, with the integral at zero.
    """
    eta, surface, drift, known, command, fresh = controller_terms(t, y, c, gains)
    return (
        as_array(eta),
        as_array(surface),
        as_array(drift),
        as_array(known),
        as_array(command),
        as_array(fresh),
    )


@jit
def store_features(out: np.ndarray, eta, surface, y: np.ndarray, held: np.ndarray, command) -> None:
    """Write ``[e_c (6), S (6), η̃ (6), Ṽ (6)]`` with ``e_c = Γ_c - Γ_cout`` (eq. 21's inputs)
    into ``out``."""
    for i in range(6):
        out[i] = held[i] - command[i]
        out[6 + i] = surface[i]
        out[12 + i] = eta[i]
        out[18 + i] = y[7 + i]


@jit
def total_disturbance(
    t: float,
    y: np.ndarray,
    wrench: np.ndarray,
    fed: np.ndarray,
    known,
    model: PlantModel,
    gains: ControllerGains,
) -> np.ndarray:
    """The true Δd = dṼ/dt - (H + Ξ⁻¹f(Ξ)) - Ξ⁻¹Γ_c of eq. (9), from the true plant.

    ``wrench`` is what the thrusters really apply for the held command; Γ_c here is ``fed``,
    what the ESO is fed for it (:func:`~etsc_envs.orbit_attitude.controller.eso_input`), so Δd
    is exactly the extended state Z2 the ESO estimates.
    """
    true_rate = relative_derivative(t, y, (wrench, model))
    solved = inertia_solve_of(fed, gains)
    out = np.empty(6)
    for i in range(6):
        out[i] = (true_rate[7 + i] - known[i]) - solved[i]
    return out


@jit
def disturbance_step(
    before: np.ndarray, after: np.ndarray, model: PlantModel, gains: ControllerGains
) -> np.ndarray:
    """Ξ times the jump of Δd when the held command steps from ``before`` to ``after``.

    Δd of section II-C holds Ξ1⁻¹Γ_actual − Ξ⁻¹Γ_c (ΔΞ̃, ΔD and the bias acting on the
    command), the one part of it that jumps at a transmission; everything else in Δd moves
    continuously with the state. The ESO sees a jump only through its effect on S afterwards,
    so at that transmission e2 changes by the jump whatever the observer. Returned as [N·m, N].
    """
    wrench_step = thruster_outputs(after, model)[2] - thruster_outputs(before, model)[2]
    true_step = np.empty(6)
    true_step[0:3] = model.inertia_inv @ wrench_step[0:3]
    true_step[3:6] = wrench_step[3:6] / model.mass
    fed_step = inertia_solve(eso_input(after, gains) - eso_input(before, gains), gains)
    return inertia_times(true_step - fed_step, gains)


@jit
def abs_max(x) -> float:
    """``np.abs(x).max()`` without the temporary: the largest |x_i| (an array or a tuple), or
    the first NaN."""
    largest = np.abs(x[0])
    for i in range(len(x)):
        value = np.abs(x[i])
        if np.isnan(value):
            return value
        if value > largest:
            largest = value
    return largest


@jit
def all_finite(x: np.ndarray) -> bool:
    """``np.isfinite(x).all()`` without the temporary."""
    finite = True
    for i in range(x.size):
        if not np.isfinite(x[i]):
            finite = False
            break
    return finite


@jit
def tracking_cost(eta, twist_error, reference: np.ndarray) -> float:
    """Per-step accuracy cost ``¼ Σ_j log(1 + ‖x_j‖ / ref_j)`` for x = Φ, Δω, χ, Δv (η̃ and Ṽ
    as arrays or tuples)."""
    cost = np.log1p(np.sqrt(vec3.dot(eta[0:3], eta[0:3])) / reference[0])
    cost += np.log1p(np.sqrt(vec3.dot(twist_error[0:3], twist_error[0:3])) / reference[1])
    cost += np.log1p(np.sqrt(vec3.dot(eta[3:6], eta[3:6])) / reference[2])
    cost += np.log1p(np.sqrt(vec3.dot(twist_error[3:6], twist_error[3:6])) / reference[3])
    return 0.25 * cost


@jit
def closed_loop_step(
    state: np.ndarray,
    t: float,
    h: float,
    substeps: int,
    held: np.ndarray,
    model: PlantModel,
    gains: ControllerGains,
    cost_reference: np.ndarray,
    with_disturbance: bool,
) -> float:
    """Advance plant and controller in the state row from t to t + h with the held command
    ``held``, and return the step's :func:`tracking_cost` at t + h.

    The row's ``THRUSTER_OUTPUT``, ``HELD_WRENCH`` and ``HELD_FED`` are what the thrusters and
    the ESO make of ``held`` (:func:`hold_command`), its ``VIEW = [S(t), H1(t)]`` what the
    controller evaluated at t. The step writes the states at t + h (``PLANT``, ``CONTROLLER``),
    the command a transmission at t + h would send (``COMMAND``), the observation features and
    ``[S, H1]`` there (``FEATURES``, ``VIEW``) and the :data:`N_DIAGNOSTICS` summary
    (``DIAGNOSTICS``; its maxima of the ESO errors ``e1 = Ẑ1 - S`` and ``e2 = Ẑ2 - Δd`` at
    t + h, Δd with the command held over the period just simulated, are computed only if
    ``with_disturbance``, else zero).
    """
    # controller at t: ESO, adaptive law and the integral of eq. (23), forward Euler
    c = state[CONTROLLER]
    view = state[VIEW]
    output = state[THRUSTER_OUTPUT]
    wrench = state[HELD_WRENCH]
    fed = state[HELD_FED]
    dz1, dz2 = eso_derivative(c[0:6], c[6:12], view[0:6], view[6:12], fed, gains)
    dphi = adaptive_derivative(c[12:14], view[0:6], t, gains)
    for i in range(6):
        c[i] = c[i] + h * dz1[i]
        c[6 + i] = c[6 + i] + h * dz2[i]
    for j in range(2):
        c[14 + j] = c[14 + j] + h * c[12 + j]
        c[12 + j] = c[12 + j] + h * dphi[j]

    # plant over [t, t + h) under the held command (ZOH at the thrusters)
    y = state[PLANT]
    dt = h / substeps
    plant = (
        (wrench[0], wrench[1], wrench[2], wrench[3], wrench[4], wrench[5]),
        plant_terms(model),
    )
    for i in range(substeps):
        y_next = integrate_plant(t + i * dt, y, dt, plant)
        y_next[0:4] /= np.sqrt(fused_dot(y_next[0:4], y_next[0:4]))
        y[:] = y_next

    # what the controller sees at t + h
    t_next = t + h
    eta, surface, drift, known, command, fresh = controller_terms(t_next, y, c, gains)
    features = state[FEATURES]
    store_features(features, eta, surface, y, held, command)
    fresh_command = state[COMMAND]
    for i in range(6):
        fresh_command[i] = fresh[i]
        view[i] = surface[i]
        view[6 + i] = drift[i]
    twist_error = y[7:13]
    cost = tracking_cost(eta, twist_error, cost_reference)
    diagnostics = state[DIAGNOSTICS]
    diagnostics[0] = np.sqrt(vec3.dot(eta[0:3], eta[0:3]))
    diagnostics[1] = np.sqrt(vec3.dot(eta[3:6], eta[3:6]))
    diagnostics[2] = abs_max(eta[0:3])
    diagnostics[3] = abs_max(twist_error[0:3])
    diagnostics[4] = abs_max(eta[3:6])
    diagnostics[5] = abs_max(twist_error[3:6])
    diagnostics[6] = abs_max((c[0] - surface[0], c[1] - surface[1], c[2] - surface[2]))
    diagnostics[7] = abs_max((c[3] - surface[3], c[4] - surface[4], c[5] - surface[5]))
    diagnostics[8] = 0.0
    diagnostics[9] = 0.0
    if with_disturbance:
        disturbance = total_disturbance(t_next, y, wrench, fed, known, model, gains)
        e2_physical = inertia_times_of(
            (
                c[6] - disturbance[0],
                c[7] - disturbance[1],
                c[8] - disturbance[2],
                c[9] - disturbance[3],
                c[10] - disturbance[4],
                c[11] - disturbance[5],
            ),
            gains,
        )
        diagnostics[8] = abs_max(e2_physical[0:3])
        diagnostics[9] = abs_max(e2_physical[3:6])
    total_output = 0.0
    for i in range(output.size):
        total_output += np.abs(output[i])
    diagnostics[10] = h * total_output
    diagnostics[11] = np.sqrt(vec3.dot(twist_error[0:3], twist_error[0:3]))
    diagnostics[12] = np.sqrt(vec3.dot(twist_error[3:6], twist_error[3:6]))
    diagnostics[13] = 1.0 if all_finite(y) and all_finite(features) else 0.0
    return cost


@jit
def initial_view(y: np.ndarray, c: np.ndarray, gains: ControllerGains):
    """At t = 0: ``(η̃, [S, H1], Γ_cout)`` — Γ_cout is the command a transmission at t_0 sends."""
    eta, surface, drift, _, command, _ = controller_view(0.0, y, c, gains)
    view = np.empty(12)
    view[0:6] = surface
    view[6:12] = drift
    return eta, view, command


@jit
def episode_leader(state: np.ndarray, shared: LeaderOrbit) -> LeaderOrbit:
    """The leader's orbit of the episode: the shared one with the state row's Ω and u(0)."""
    return LeaderOrbit(
        shared.mu,
        shared.radius,
        shared.rate,
        state[LEADER_RAAN],
        shared.inclination,
        state[LEADER_LATITUDE],
    )


@jit
def episode_model(state: np.ndarray, constants: LoopConstants) -> PlantModel:
    """The true plant of the episode: the shared model with the state row's leader, disturbance
    phases and misalignment (D + ΔD)."""
    shared = constants.model
    return PlantModel(
        episode_leader(state, shared.leader),
        shared.earth_radius,
        shared.j2,
        shared.inertia,
        shared.inertia_inv,
        shared.mass,
        state[TRUE_DISTRIBUTION].reshape(6, 12),
        shared.allocation,
        shared.max_force,
        shared.bias_ratio,
        shared.torque_offset,
        shared.torque_amplitude,
        shared.torque_frequency,
        state[TORQUE_PHASE],
        shared.force_offset,
        shared.force_amplitude,
        shared.force_frequency,
        state[FORCE_PHASE],
    )


@jit
def episode_gains(state: np.ndarray, constants: LoopConstants) -> ControllerGains:
    """The controller of the episode: the shared gains with the state row's leader orbit."""
    shared = constants.gains
    return ControllerGains(
        episode_leader(state, shared.leader),
        shared.earth_radius,
        shared.j2,
        shared.inertia,
        shared.inertia_inv,
        shared.mass,
        shared.theta1,
        shared.theta2,
        shared.alpha,
        shared.singularity_floor,
        shared.beta,
        shared.alpha1,
        shared.alpha2,
        shared.k1,
        shared.k2,
        shared.k3,
        shared.k4,
        shared.k5,
        shared.gain_k1,
        shared.gain_k2,
        shared.ell,
        shared.epsilon,
        shared.sigma,
        shared.distribution,
        shared.allocation,
        shared.max_force,
        shared.eso_sees_saturation,
    )


@jit
def record_statistics(
    state: np.ndarray, diagnostics: np.ndarray, time_next: float, steady: bool
) -> None:
    """Update the episode's running metrics with the step ending at ``time_next``: impulse,
    settling times (‖Φ‖, ‖χ‖ re-entering their bands) and the steady-state maxima."""
    state[IMPULSE] += diagnostics[10]
    bounds = state[SETTLING_BOUND]
    settled = state[SETTLING_TIME]
    for i in range(2):
        if diagnostics[i] > bounds[i]:
            settled[i] = np.nan
        elif np.isnan(settled[i]):
            settled[i] = time_next
    if steady:
        state[STEADY_MAX] = np.maximum(state[STEADY_MAX], diagnostics[2:10])


@jit
def channel_values(state: np.ndarray, constants: LoopConstants, time_s: float) -> np.ndarray:
    """The controller's transmission: the current Γ_cout with the integral restarted."""
    return state[COMMAND].copy().reshape(1, 6)


@jit
def hold_command(
    state: np.ndarray, command: np.ndarray, model: PlantModel, gains: ControllerGains
) -> None:
    """Store in the state row what the thrusters (eqs. 10-12: u_a, Γ_actual) and the ESO's
    model (:func:`~etsc_envs.orbit_attitude.controller.eso_input`) make of the held ``command``.

    They depend on nothing else, so they are computed once per transmission, not every step.
    """
    _, state[THRUSTER_OUTPUT], state[HELD_WRENCH] = thruster_outputs(command, model)
    state[HELD_FED] = eso_input(command, gains)
    state[HELD_COMMAND] = command


@jit
def holds(state: np.ndarray, command: np.ndarray) -> bool:
    """Whether the state row's :func:`hold_command` values were made of ``command``."""
    stored = state[HELD_COMMAND]
    same = True
    for i in range(stored.size):
        if command[i] != stored[i]:
            same = False
            break
    return same


@jit
def advance_loop(
    state: np.ndarray,
    constants: LoopConstants,
    step_index: int,
    h: float,
    held: np.ndarray,
    sent: np.ndarray,
    channel_costs: np.ndarray,
) -> None:
    """One sampling period in the state row; the cost is :func:`tracking_cost` at t_k + h."""
    if sent[0] != 0:  # a transmission at t_k restarts ∫_{t_k} ϕ̂ ds of eq. (23)
        state[CONTROLLER][INTEGRAL] = 0.0
    steady = step_index + 1 > constants.steady_start
    model = episode_model(state, constants)
    gains = episode_gains(state, constants)
    if not holds(state, held[0]):
        hold_command(state, held[0], model, gains)
    channel_costs[0] = closed_loop_step(
        state,
        step_index * h,
        h,
        constants.plant_substeps,
        held[0],
        model,
        gains,
        constants.cost_reference,
        steady,
    )
    record_statistics(state, state[DIAGNOSTICS], (step_index + 1) * h, steady)


@jit
def loop_failure(state: np.ndarray, constants: LoopConstants) -> int:
    """A non-finite state, or ‖χ‖, ‖Δω‖ or ‖Δv‖ beyond its bound (checked in that order)."""
    diagnostics = state[DIAGNOSTICS]
    if diagnostics[13] != 1.0:
        return NON_FINITE
    if diagnostics[1] > constants.max_position_error:
        return POSITION_DIVERGED
    if diagnostics[11] > constants.max_rate_error:
        return RATE_DIVERGED
    if diagnostics[12] > constants.max_velocity_error:
        return VELOCITY_DIVERGED
    return 0


KERNELS = ProblemKernels(
    channel_values=channel_values,
    accepts=always_accepts,
    advance=advance_loop,
    failure=loop_failure,
    features=stored_features(FEATURES),
)
"""The compiled loop of paper 000."""

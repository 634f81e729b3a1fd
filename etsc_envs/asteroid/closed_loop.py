"""One decision period of the closed loop of paper 003, compiled as a single call.

The orbit thrust of eqs. (16)-(17) and the attitude law of eqs. (18)-(19) are continuous-time
state feedback, so they are evaluated inside the RK4 derivative together with eqs. (1), (9) and
(12); only the on/off state of the thrusters changes at the sampling instants: they fire during
the sampling periods that start less than ``burst_duration`` after the triggering instant
(section 4: "the thrusters work for 50 s after each time of triggering"). One decision period is
``n_substeps`` sampling periods of ``h`` (0.25 s in section 4).

The environment keeps one loop in a flat state row (layout below) and reaches it through the
kernels of :data:`KERNELS` (see :mod:`etsc_envs.core.compiled_loop`). Its single channel
carries the triggering instant: the held value is the start of the last accepted burst (NaN
before the first), and a request while that burst runs is refused.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.asteroid.controller import (
    LoopGains,
    adaptive_law,
    attitude_law,
    barrier_statistic,
    sliding_vector,
    thrust_law,
)
from etsc_envs.asteroid.dynamics import (
    B_HAT,
    DELTA_V,
    STATE_SIZE,
    PlantModel,
    Q,
    R,
    V,
    W,
    plant_derivative,
)
from etsc_envs.asteroid.gravity import Polyhedron
from etsc_envs.asteroid.gravity_grid import collides, grid_clearance
from etsc_envs.core import vec3
from etsc_envs.core.compiled_loop import ProblemKernels, stored_features
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import fused_dot
from etsc_envs.core.rotations import quat_error

N_FEATURES = 14
OK, NON_FINITE, LEFT_REGION, COLLISION, ATTITUDE_DIVERGED = 0, 1, 2, 3, 4

PLANT = slice(0, STATE_SIZE)  # y = [r, v, q, ω, b̂, Δv] of dynamics.py
FEATURES = slice(15, 29)  # orbit_features at the current instant
SUN_DIRECTION = slice(29, 32)  # the Sun's unit vector in I, from the episode's Sun azimuth
DESIRED_ATTITUDE = slice(32, 36)  # q_D of eq. (18): the Sun-pointing frame
MIN_RADIUS = 36  # least ‖r‖ so far (at the reset and the substeps' ends), m
MAX_RADIUS = 37  # greatest ‖r‖ so far, m
TIME_OUTSIDE = 38  # time spent outside the shell, s
MIN_CLEARANCE = 39  # least height above the surface so far, m
FAILURE_CODE = 40  # OK or the failure of the last decision period
STATE_WIDTH = 41
"""Layout of the state row."""

LoopConstants = namedtuple(
    "LoopConstants",
    [
        "gains",  # LoopGains (q_D is taken from the state row)
        "model",  # PlantModel (the Sun's direction is taken from the state row)
        "polyhedron",  # Polyhedron of the body, for the exact collision test
        "substep_s",  # h: the sampling period, s
        "substeps",  # sampling periods per decision period
        "burst_duration",  # s
        "shell",  # (r_min, r_max), m
        "region",  # the operating region's (inner, outer) radii, m
        "max_rate",  # divergence bound on ‖ω‖, rad/s
    ],
)
"""What every episode shares: gains, plant model and body, the sampling and burst timing, and
the cost and failure bounds."""


@jit
def closed_loop_derivative(t: float, y: np.ndarray, args) -> np.ndarray:
    """ẏ of the whole loop; ``args = (thrusting, gains, model)``."""
    thrusting, gains, model = args
    thrust = thrust_law(y[R], gains) if thrusting else (0.0, 0.0, 0.0)
    s = sliding_vector(quat_error(y[Q], gains.desired_attitude), y[W], gains)
    dy = plant_derivative(t, y, thrust, attitude_law(s, y[B_HAT], gains), model)
    dy[B_HAT] = adaptive_law(s, y[B_HAT], gains)
    dy[DELTA_V] = np.sqrt(vec3.dot(thrust, thrust)) / model.mass
    return dy


integrate = make_rk4_step(closed_loop_derivative)


@jit
def is_thrusting(t: float, burst_start: float, burst_duration: float) -> bool:
    """Whether the sampling period starting at ``t`` belongs to the burst begun at
    ``burst_start`` (NaN when no burst was ever triggered)."""
    return burst_start <= t < burst_start + burst_duration - 1e-9


@jit
def orbit_features(
    t: float, y: np.ndarray, burst_start: float, burst_duration: float, gains: LoopGains, grid
) -> np.ndarray:
    """The observation's problem part at ``t`` (see ``env.FEATURE_NAMES``)."""
    r, v = y[R], y[V]
    radius = np.sqrt(vec3.dot(r, r))
    features = np.empty(N_FEATURES)
    features[0] = radius
    features[1] = gains.reference_radius - radius
    features[2] = vec3.dot(r, v) / radius
    features[3] = vec3.dot(r, v)
    features[4] = barrier_statistic(r, v, gains.reference_radius)
    features[5:8] = r
    features[8:11] = v
    thrusting = is_thrusting(t, burst_start, burst_duration)
    features[11] = 1.0 if thrusting else 0.0
    features[12] = burst_start + burst_duration - t if thrusting else 0.0
    features[13] = grid_clearance(r, grid)
    return features


@jit
def closed_loop_step(
    t: float,
    y: np.ndarray,
    h: float,
    n_substeps: int,
    burst_start: float,
    burst_duration: float,
    shell: np.ndarray,
    region: np.ndarray,
    max_rate: float,
    gains: LoopGains,
    model: PlantModel,
    poly: Polyhedron,
):
    """Advance the loop by ``n_substeps`` RK4 steps of ``h`` from ``t``.

    Returns ``(y, substeps_done, failure_code, cost, time_outside, min_radius, max_radius,
    min_clearance, features)``: the state after the last completed substep; the number of
    substeps run (fewer than ``n_substeps`` after a failure); one of OK, NON_FINITE,
    LEFT_REGION, COLLISION, ATTITUDE_DIVERGED; the cost ∫ d² dt with d the distance outside
    ``shell = [r_min, r_max]`` (m²·s); the time spent outside the shell; the extreme radii and
    the least clearance above the surface at the substeps' ends; and the features at the end.
    """
    cost = 0.0
    time_outside = 0.0
    min_radius = np.inf
    max_radius = 0.0
    min_clearance = np.inf
    failure = OK
    done = 0
    for _ in range(n_substeps):
        thrusting = is_thrusting(t, burst_start, burst_duration)
        candidate = integrate(t, y, h, (thrusting, gains, model))
        candidate[Q] /= np.sqrt(fused_dot(candidate[Q], candidate[Q]))
        if not np.all(np.isfinite(candidate)):
            failure = NON_FINITE
            break
        y = candidate
        t += h
        done += 1
        r = y[R]
        radius = np.sqrt(vec3.dot(r, r))
        outside = max(0.0, radius - shell[1], shell[0] - radius)
        cost += outside * outside * h
        if outside > 0.0:
            time_outside += h
        min_radius = min(min_radius, radius)
        max_radius = max(max_radius, radius)
        min_clearance = min(min_clearance, grid_clearance(r, model.grid))
        if radius < region[0] or radius > region[1]:
            failure = LEFT_REGION
            break
        if collides(r, model.grid, poly):
            failure = COLLISION
            break
        if np.sqrt(vec3.dot(y[W], y[W])) > max_rate:
            failure = ATTITUDE_DIVERGED
            break
    features = orbit_features(t, y, burst_start, burst_duration, gains, model.grid)
    return (
        y,
        done,
        failure,
        cost,
        time_outside,
        min_radius,
        max_radius,
        min_clearance,
        features,
    )


@jit
def episode_gains(state: np.ndarray, constants: LoopConstants) -> LoopGains:
    """The controller gains of the episode: the shared ones with the state row's q_D."""
    shared = constants.gains
    return LoopGains(
        shared.reference_radius,
        shared.shell_half_width,
        shared.thrust_gain,
        shared.max_thrust,
        shared.attitude_gain,
        shared.sliding_gain,
        shared.adaptive_rate,
        shared.adaptive_leakage,
        shared.tanh_sharpness,
        state[DESIRED_ATTITUDE],
    )


@jit
def episode_model(state: np.ndarray, constants: LoopConstants) -> PlantModel:
    """The plant model of the episode: the shared one with the state row's Sun direction."""
    shared = constants.model
    return PlantModel(
        shared.gm,
        shared.spin_rate,
        shared.mass,
        shared.inertia,
        shared.srp_pressure_area,
        shared.srp_normal_coefficient,
        shared.srp_sun_coefficient,
        shared.srp_arm,
        shared.thrust_arm,
        shared.perturbation_scale,
        state[SUN_DIRECTION],
        shared.grid,
    )


@jit
def channel_values(state: np.ndarray, constants: LoopConstants, time_s: float) -> np.ndarray:
    """The trigger's transmission: the instant t_k at which the burst starts."""
    return np.full((1, 1), time_s)


@jit
def accepts_burst(
    state: np.ndarray, held: np.ndarray, constants: LoopConstants, time_s: float, channel: int
) -> bool:
    """A burst can start unless the one begun at the held instant still fires."""
    return not is_thrusting(time_s, held[0, 0], constants.burst_duration)


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
    """One decision period in the state row; the cost is ∫ d² dt outside the shell."""
    (
        plant,
        _,
        failure,
        cost,
        time_outside,
        min_radius,
        max_radius,
        min_clearance,
        features,
    ) = closed_loop_step(
        step_index * h,
        state[PLANT],
        constants.substep_s,
        constants.substeps,
        held[0, 0],
        constants.burst_duration,
        constants.shell,
        constants.region,
        constants.max_rate,
        episode_gains(state, constants),
        episode_model(state, constants),
        constants.polyhedron,
    )
    state[PLANT] = plant
    state[FEATURES] = features
    state[FAILURE_CODE] = failure
    state[TIME_OUTSIDE] += time_outside
    state[MIN_RADIUS] = min(state[MIN_RADIUS], min_radius)
    state[MAX_RADIUS] = max(state[MAX_RADIUS], max_radius)
    state[MIN_CLEARANCE] = min(state[MIN_CLEARANCE], min_clearance)
    channel_costs[0] = cost


@jit
def loop_failure(state: np.ndarray, constants: LoopConstants) -> int:
    """The failure closed_loop_step found in the last decision period (OK for none)."""
    return int(state[FAILURE_CODE])


KERNELS = ProblemKernels(
    channel_values=channel_values,
    accepts=accepts_burst,
    advance=advance_loop,
    failure=loop_failure,
    features=stored_features(FEATURES),
)
"""The compiled loop of paper 003."""

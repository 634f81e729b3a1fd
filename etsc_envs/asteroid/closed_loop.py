"""One decision period of the closed loop of paper 003, compiled as a single call.

The orbit thrust of eqs. (16)-(17) and the attitude law of eqs. (18)-(19) are continuous-time
state feedback, so they are evaluated inside the RK4 derivative together with eqs. (1), (9) and
(12); only the on/off state of the thrusters changes at the sampling instants: they fire during
the sampling periods that start less than ``burst_duration`` after the triggering instant
(section 4: "the thrusters work for 50 s after each time of triggering"). One decision period is
``n_substeps`` sampling periods of ``h`` (0.25 s in section 4).
"""

from __future__ import annotations

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
    PlantModel,
    Q,
    R,
    V,
    W,
    plant_derivative,
)
from etsc_envs.asteroid.gravity import Polyhedron
from etsc_envs.asteroid.gravity_grid import collides, grid_clearance
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.rotations import error_quaternion

N_FEATURES = 14
OK, NON_FINITE, LEFT_REGION, COLLISION, ATTITUDE_DIVERGED = 0, 1, 2, 3, 4


@jit
def closed_loop_derivative(t: float, y: np.ndarray, args) -> np.ndarray:
    """ẏ of the whole loop; ``args = (thrusting, gains, model)``."""
    thrusting, gains, model = args
    thrust = thrust_law(y[R], gains) if thrusting else np.zeros(3)
    s = sliding_vector(error_quaternion(y[Q], gains.desired_attitude), y[W], gains)
    dy = plant_derivative(t, y, thrust, attitude_law(s, y[B_HAT], gains), model)
    dy[B_HAT] = adaptive_law(s, y[B_HAT], gains)
    dy[DELTA_V] = np.sqrt(thrust @ thrust) / model.mass
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
    radius = np.sqrt(r @ r)
    features = np.empty(N_FEATURES)
    features[0] = radius
    features[1] = gains.reference_radius - radius
    features[2] = (r @ v) / radius
    features[3] = r @ v
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
        candidate[Q] /= np.sqrt(candidate[Q] @ candidate[Q])
        if not np.all(np.isfinite(candidate)):
            failure = NON_FINITE
            break
        y = candidate
        t += h
        done += 1
        r = y[R]
        radius = np.sqrt(r @ r)
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
        if np.sqrt(y[W] @ y[W]) > max_rate:
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

"""``etsc/ClusterContainmentCentral-v0``: one agent decides, for every follower, when to update.

Paper 001's loop (Figure 1): each follower's controller samples its state, computes the control
law eq. (19) and updates its actuators only at its own events; the adaptation laws (20)-(21)
run continuously. Here one central agent sends a ``MultiBinary(N)`` vector at every 0.01-s
sampling instant, bit i triggering follower i's event. The decentralised PettingZoo form,
``etsc/ClusterContainment-v0`` (:mod:`etsc_envs.cluster.parallel_env`), shares this loop.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from etsc_envs.cluster.closed_loop import (
    CONVERGENCE_FRACTION,
    CONVERGENCE_THRESHOLD,
    DISTURBANCE_PHASE,
    FEATURES,
    KERNELS,
    LAST_FAST_STEP,
    LAST_OUTSIDE_STEP,
    MIN_CONVERGENCE_THRESHOLD,
    N_FEATURES,
    NON_FINITE,
    NORMS,
    PLANT,
    SAMPLE,
    SAMPLE_WIDTH,
    LoopConstants,
    episode_model,
    follower_signals,
    follower_table,
    note_outside_followers,
    note_peak_rate,
    state_width,
    write_agent_features,
    write_event_samples,
)
from etsc_envs.cluster.dynamics import ClusterModel
from etsc_envs.cluster.params import ClusterContainmentParams, replace_params
from etsc_envs.cluster.picture import PICTURE
from etsc_envs.cluster.topology import containment_targets, hull_distance
from etsc_envs.core.keywords import document_keywords
from etsc_envs.core.multi_agent import MultiAgentLoop, agent_major_names, agent_metrics
from etsc_envs.core.vector_env import EventTriggeredVectorEnv

FEATURE_NAMES = (
    "event_error",
    "state_threshold",
    "e_J_norm",
    "e_s_norm",
    "s_norm",
    "sqrt_lambda_min_K",
    "time_s",
    "sigma_x", "sigma_y", "sigma_z",
    "omega_x", "omega_y", "omega_z",
    "containment_error_x", "containment_error_y", "containment_error_z",
    "u_x", "u_y", "u_z",
)  # fmt: skip
"""One follower's observation components (the central env suffixes each with ``_i``):

* ``event_error`` — ‖e_J‖ + λ_max(K)‖e_s‖, the left side of eq. (15) without its s-term;
* ``state_threshold`` — ½ λ_min(K) ‖s‖: eq. (15) fires when event_error ≥ c · state_threshold
  + μ(t), with μ(t) = ρ √λ_min(K) exp(-ν t);
* ``e_J_norm``, ``e_s_norm`` — ‖e_J‖ and ‖e_s‖ of eq. (14) (since the follower's last event);
* ``s_norm`` — ‖s‖, the sliding variable eq. (10);
* ``sqrt_lambda_min_K`` — √λ_min(K), the factor of μ(t) in eq. (15);
* ``time_s`` — t, the argument of μ(t);
* ``sigma_*``, ``omega_*`` — the follower's MRP attitude (rad) and body rate (rad/s);
* ``containment_error_*`` — σ_i - σ_d,i, the offset from its containment target (eq. 8);
* ``u_*`` — the control held since its last event (eq. 16), N·m.

Bounds: σ, ω and the containment error within the failure bounds, u within the torque limit,
t within the horizon, the norms >= 0; the norms' upper bounds are unbounded (±``UNBOUNDED``):
the adaptive gains of eqs. (20)-(21) grow without a stated limit, and e_J with them.
"""

PERIODIC_TERMS = 4
RANDOM_ATTITUDE_MAX_NORM = 0.6
RANDOM_RATE_MAX_RAD_S = 0.015
SETTLED_HULL_DISTANCE = 0.01
"""``settled`` (the protocol's criterion, not the paper's): every follower's rate has
converged (``omega_converge_time_s`` exists) and every follower ends within this MRP distance
of the leaders' convex hull. The sliding-mode boundary layer leaves a follower an offset of
about s/(α·in-degree) outside it (docs/fidelity.md, reading 2); on the paper scenario and on
the 256 test draws of the reach study the final distance stays below 0.008."""


def cluster_model(params: ClusterContainmentParams, disturbance_phase: np.ndarray) -> ClusterModel:
    """The compiled loop's parameter bundle for ``params``."""
    inertia = params.true_inertias
    return ClusterModel(
        adjacency=np.array(params.adjacency, dtype=float),
        leader_attitudes=np.array(params.leader_attitudes, dtype=float),
        inertia=inertia,
        inertia_inverse=np.linalg.inv(inertia),
        constant_disturbance=np.array(params.constant_disturbances, dtype=float),
        periodic_fraction=float(params.periodic_disturbance_fraction),
        periodic_rates=np.array(params.periodic_disturbance_rates, dtype=float),
        disturbance_phase=np.array(disturbance_phase, dtype=float),
        alpha=float(params.alpha),
        control_gain=np.array(params.control_gain, dtype=float),
        adaptation_gain=np.array(params.adaptation_gain, dtype=float),
        switching_gain_rate=float(params.switching_gain_rate),
        saturating=params.switching == "saturation",
        saturation_width=float(params.saturation_width),
        torque_limit=float(params.torque_limit),
        targets=containment_targets(params.adjacency, params.leader_attitudes),
    )


@document_keywords(ClusterContainmentParams)
class ClusterContainmentCentralEnv(MultiAgentLoop):
    """Attitude containment of a microsatellite cluster with one central trigger (paper 001).

    Args:
        params: the paper's model and scenario; keyword overrides of its fields (for example
            ``scenario="pi1"``, ``switching="sign"``, ``horizon_s=300``, ``adjacency=...``)
            are applied on top.
        transmission_penalty: λ, reward lost per follower update.
        cost_scale: the per-step cost Σ_i ‖σ_i - σ_d,i‖ (rad) is divided by this. A failure is
            charged, for every step it cuts from the horizon, N times the largest distance a
            follower can have from its target before failing.
        randomize: at every reset draw each σ_i(0) uniformly in the ball ‖σ‖ ≤ 0.6 (Table 1's
            largest is 0.59), each ω_i(0) component uniformly in ±0.015 rad/s (Table 1's
            largest) and the phases of the four periodic terms of eq. (68) uniformly in
            [0, 2π), instead of the scenario's fixed values.

    Action: ``MultiBinary(N)``; bit i triggers follower i's event (sample, compute eq. (19),
    update the actuator). Observation: each follower's :data:`FEATURE_NAMES` suffixed with its
    index, then ``time_since_transmission_s_i`` for every follower.
    """

    kernels = KERNELS
    picture = PICTURE

    def __init__(
        self,
        params: ClusterContainmentParams | None = None,
        *,
        transmission_penalty: float = 0.1,
        cost_scale: float = 1.0,
        randomize: bool = False,
        render_mode: str | None = None,
        **overrides: Any,
    ) -> None:
        self.params = replace_params(params, overrides)
        p = self.params
        n = p.n_followers
        self.agent_names = tuple(f"follower_{i}" for i in range(n))
        self.agent_feature_names = FEATURE_NAMES
        self.targets = containment_targets(p.adjacency, p.leader_attitudes)
        error_bound = p.max_mrp_norm + float(np.linalg.norm(self.targets, axis=1).max())
        low, high = self._feature_bounds(error_bound)
        super().__init__(
            feature_names=agent_major_names(FEATURE_NAMES, n),
            feature_low=np.tile(low, n),
            feature_high=np.tile(high, n),
            n_channels=n,
            channel_width=SAMPLE_WIDTH,
            state_width=state_width(n),
            constants=LoopConstants(
                model=cluster_model(p, np.zeros((n, PERIODIC_TERMS))),
                limits=np.array([p.max_mrp_norm, p.max_rate_rad_s]),
            ),
            sampling_period_s=p.sampling_period_s,
            horizon_s=p.horizon_s,
            transmission_penalty=transmission_penalty,
            cost_scale=cost_scale,
            randomize=randomize,
            failure_cost=n * error_bound,
            render_mode=render_mode,
        )

    @property
    def followers(self) -> np.ndarray:
        """The followers' records of the state row, N×``FOLLOWER_WIDTH`` (see
        :mod:`etsc_envs.cluster.closed_loop` for the layout)."""
        return follower_table(self.state)

    @property
    def model(self) -> ClusterModel:
        """The cluster model of the current episode (with its disturbance phases)."""
        return episode_model(self.state, self.constants)

    def _feature_bounds(self, error_bound: float) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of one follower's features: the failure bounds limit σ, ω and the error."""
        p = self.params
        low = np.zeros(N_FEATURES)
        high = np.full(N_FEATURES, np.inf)
        high[FEATURE_NAMES.index("time_s")] = p.horizon_s
        for prefix, bound in (
            ("sigma", p.max_mrp_norm),
            ("omega", p.max_rate_rad_s),
            ("containment_error", error_bound),
            ("u", p.torque_limit),
        ):
            start = FEATURE_NAMES.index(f"{prefix}_x")
            low[start : start + 3], high[start : start + 3] = -bound, bound
        return low, high

    # ----------------------------------------------------------------- hooks
    def _reset_problem(self, options: dict[str, Any] | None) -> None:
        p = self.params
        n = p.n_followers
        rng = self.np_random
        followers = self.followers
        if self.randomize:
            directions = rng.normal(size=(n, 3))
            directions /= np.linalg.norm(directions, axis=1, keepdims=True)
            radii = RANDOM_ATTITUDE_MAX_NORM * rng.uniform(0.0, 1.0, size=(n, 1)) ** (1.0 / 3.0)
            attitudes = radii * directions
            rates = rng.uniform(-RANDOM_RATE_MAX_RAD_S, RANDOM_RATE_MAX_RAD_S, size=(n, 3))
            followers[:, DISTURBANCE_PHASE] = rng.uniform(
                0.0, 2.0 * np.pi, size=(n, PERIODIC_TERMS)
            )
        else:
            attitudes = np.array(p.initial_attitudes, dtype=float)
            rates = np.array(p.initial_rates, dtype=float)
        y = followers[:, PLANT]
        y[:, 0:3] = attitudes
        y[:, 3:6] = rates
        y[:, 6:12] = np.array(p.initial_parameter_estimate, dtype=float)
        y[:, 12] = p.initial_switching_gain
        model = self.model
        samples = followers[:, SAMPLE]
        write_event_samples(y, model, samples)
        write_agent_features(0.0, y, samples, samples, model, followers[:, FEATURES])
        followers[:, NORMS] = np.stack(
            [np.linalg.norm(attitudes, axis=1), np.linalg.norm(rates, axis=1)], axis=1
        )
        self._start_convergence_bookkeeping(np.linalg.norm(attitudes - self.targets, axis=1))

    def _start_convergence_bookkeeping(self, errors: np.ndarray) -> None:
        """Thresholds of the convergence times from the initial errors, and step 0 noted."""
        followers = self.followers
        followers[:, CONVERGENCE_THRESHOLD] = np.maximum(
            CONVERGENCE_FRACTION * errors, MIN_CONVERGENCE_THRESHOLD
        )
        followers[:, LAST_OUTSIDE_STEP] = -1.0
        self.state[LAST_FAST_STEP] = -1.0
        note_outside_followers(followers, errors, 0)
        note_peak_rate(self.state, followers[:, NORMS][:, 1].max(), 0)

    def _failure_message(self, code: int) -> str:
        if code == NON_FINITE:
            return "non-finite state"
        norms = self.followers[:, NORMS]
        limits = self.constants.limits
        worst, column = np.unravel_index(np.argmax(norms / limits), norms.shape)
        name, bound, unit = (
            ("sigma", "max_mrp_norm", "") if column == 0 else ("omega", "max_rate_rad_s", " rad/s")
        )
        return (
            f"diverged: |{name}| of {self.agent_names[worst]} = {norms[worst, column]:.3g}"
            f"{unit} > {bound} = {limits[column]}"
        )

    def _paper_metrics(self) -> dict[str, Any]:
        h, steps = self.sampling_period_s, self.step_index
        followers = self.followers
        last_outside = followers[:, LAST_OUTSIDE_STEP]
        inside_since = (last_outside + 1) * h
        converged = last_outside < steps
        sigma = followers[:, 0:3]
        errors = np.linalg.norm(sigma - self.targets, axis=1)
        agents = agent_metrics(self.arrays, steps, self.agent_names)
        for i, name in enumerate(self.agent_names):
            agents[name].update(
                final_sigma=sigma[i].tolist(),
                target_sigma=self.targets[i].tolist(),
                final_containment_err=float(errors[i]),
                converge_time_s=float(inside_since[i]) if converged[i] else None,
            )
        return {
            "converge_time_s": float(inside_since.max()) if converged.all() else None,
            "omega_converge_time_s": self._omega_converge_time(),
            "final_containment_err": float(errors.max()),
            "final_hull_distance": max(
                hull_distance(point, np.asarray(self.params.leader_attitudes)) for point in sigma
            ),
            "agents": agents,
        }

    def _settled_at_end(self, metrics: dict[str, Any]) -> bool:
        """Rates converged and every follower within :data:`SETTLED_HULL_DISTANCE` of the hull.

        ``converge_time_s`` (entry within 5 % of the initial hull distance) is too strict a
        test of settling for random starts: a follower that starts near the hull has a
        threshold below the boundary layer's offset and never meets it, though it ends as
        close to the hull as the others."""
        return (
            metrics["omega_converge_time_s"] is not None
            and metrics["final_hull_distance"] <= SETTLED_HULL_DISTANCE
        )

    def _omega_converge_time(self) -> float | None:
        """First time after which every ‖ω_i‖ stays below 5 % of the episode's peak."""
        last = int(self.state[LAST_FAST_STEP])
        if last >= self.step_index:
            return None
        return (last + 1) * self.sampling_period_s

    # ----------------------------------------------------------------- diagnostics
    def state_dict(self) -> dict[str, np.ndarray]:
        """Named copies of the loop's signals at the current instant (for plots and tests)."""
        followers = self.followers
        y = np.ascontiguousarray(followers[:, PLANT])
        sigma_dot, s, regressors = follower_signals(y, self.model)
        samples = followers[:, SAMPLE]
        features = followers[:, FEATURES]
        held = self.held
        return {
            "time_s": np.array(self.time_s),
            "sigma": y[:, 0:3].copy(),
            "omega": y[:, 3:6].copy(),
            "sigma_dot": sigma_dot,
            "theta_hat": y[:, 6:12].copy(),
            "k_hat": y[:, 12].copy(),
            "s": s,
            "regressor": regressors,
            "y_theta": samples[:, 6:9].copy(),
            "u": held[:, 0:3].copy(),
            "u_now": samples[:, 0:3].copy(),
            "s_event": held[:, 3:6].copy(),
            "y_theta_event": held[:, 6:9].copy(),
            "e_J_norm": features[:, 2].copy(),
            "e_s_norm": features[:, 3].copy(),
            "event_error": features[:, 0].copy(),
            "state_threshold": features[:, 1].copy(),
            "sqrt_lambda_min_K": features[:, 5].copy(),
            "targets": self.targets.copy(),
            "leaders": np.array(self.params.leader_attitudes, dtype=float),
            "containment_error": np.linalg.norm(y[:, 0:3] - self.targets, axis=1),
        }


class ClusterContainmentCentralVectorEnv(EventTriggeredVectorEnv):
    """``num_envs`` :class:`ClusterContainmentCentralEnv` stepped in one compiled call (the
    id's ``vector_entry_point``)."""

    single_env_class = ClusterContainmentCentralEnv

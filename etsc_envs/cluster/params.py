"""The numbers of paper 001 (attitude containment of a microsatellite cluster, section 5).

Two scenarios: ``"paper"`` (section 5.1: 6 followers, leaders 7-9) and ``"pi1"`` (section 5.2:
9 followers, leaders 10-12, a topology with a π1 cell partition). Every array whose size
depends on the number of followers N or leaders M defaults to ``None``, meaning "the
scenario's value"; giving all of them (adjacency, leaders, inertias, initial states, constant
disturbances) defines another cluster. Followers are 0-based in code: the paper's satellite
``k`` is follower ``k - 1`` and its leader ``N + j`` is node ``N + j - 1``.

The paper's Figures 2 and 5 (the topologies) did not survive in the text and eq. (71) (the
inertias of section 5.2) is missing; the designs below are this suite's, built so that the
text's statements about them hold (docs/fidelity.md, paper 001, readings 1-3).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from etsc_envs.cluster.topology import adjacency_from_edges, validate_adjacency
from etsc_envs.core.validation import (
    apply_overrides,
    require_choice,
    require_field_types,
    require_float_array,
    require_non_negative,
    require_positive,
    require_spd_matrix,
    require_vector,
)

SCENARIOS = ("paper", "pi1")
SWITCHING_FUNCTIONS = ("sign", "saturation")

LEADER_ATTITUDES = ((0.09, 0.06, -0.08), (0.06, -0.1, 0.05), (-0.08, 0.1, 0.09))
"""σ_7, σ_8, σ_9 of eq. (63) (and σ_10, σ_11, σ_12 of eq. (70), the same values), rad."""

NOMINAL_INERTIAS = (
    ((20.0, 0.0, 2.0), (0.0, 25.0, 0.0), (2.0, 0.0, 29.0)),
    ((22.0, 1.0, 0.5), (1.0, 24.0, 3.0), (0.5, 3.0, 22.0)),
    ((25.0, 0.8, 2.0), (0.8, 29.0, 1.0), (2.0, 1.0, 21.0)),
    ((23.0, 0.4, 0.0), (0.4, 26.0, 0.8), (0.0, 0.8, 28.0)),
    ((22.0, 0.2, 0.0), (0.2, 26.0, 0.6), (0.0, 0.6, 24.0)),
    ((23.0, 0.4, 0.0), (0.4, 24.0, 0.8), (0.0, 0.8, 28.0)),
)
"""J_01 .. J_06 of eq. (64), kg·m²."""

TABLE_1_ATTITUDES = (
    (0.1, 0.4, -0.3),
    (0.3, 0.2, 0.3),
    (-0.2, 0.1, -0.1),
    (-0.4, 0.2, -0.1),
    (0.3, -0.5, 0.1),
    (0.2, 0.2, -0.3),
)
"""σ_i(0) of Table 1 (followers 1-6; Table 2 repeats them), rad."""
TABLE_1_RATES = (
    (0.01, 0.0, 0.0),
    (0.0, 0.01, 0.0),
    (0.0, 0.0, 0.01),
    (0.0, 0.0, -0.01),
    (0.0, -0.015, 0.0),
    (0.0, 0.0, 0.015),
)
"""ω_i(0) of Table 1, rad/s."""
TABLE_2_EXTRA_ATTITUDES = ((0.2, -0.1, -0.4), (-0.4, -0.3, 0.1), (-0.2, -0.3, 0.2))
"""σ_7(0) .. σ_9(0) of Table 2, rad."""
TABLE_2_EXTRA_RATES = ((0.01, -0.01, 0.0), (0.0, 0.015, -0.01), (0.01, 0.0, -0.015))
"""ω_7(0) .. ω_9(0) of Table 2, rad/s."""

CONSTANT_DISTURBANCES = (
    (0.0012, -0.0018, 0.0012),
    (0.001, 0.0014, -0.0017),
    (-0.0013, 0.0016, -0.001),
    (0.0015, -0.0014, -0.0013),
    (-0.001, -0.001, 0.0015),
    (-0.0012, 0.0013, 0.0014),
)
"""d_l1 .. d_l6 of eq. (67), N·m."""
EXTRA_CONSTANT_DISTURBANCES = (
    (-0.0016, 0.001, 0.0012),
    (-0.0018, 0.001, -0.0012),
    (0.0011, -0.0015, -0.0014),
)
"""d_l7 .. d_l9 of eq. (72), N·m."""

FIGURE_2_EDGES = (
    (1, 7), (1, 2),
    (2, 9), (2, 3),
    (3, 8), (3, 4),
    (4, 9), (4, 1),
    (5, 8), (5, 1),
    (6, 8), (6, 5),
)  # fmt: skip
"""Substitute for Figure 2 (lost): ``(receiver, sender)`` in the paper's 1-based numbering.

Every follower hears one leader and one follower: leader 7 feeds follower 1, leader 9 feeds 2
and 4, leader 8 feeds 3, 5 and 6; followers 1→4→3→2→1 form a directed cycle and 5, 6 relay
from 1 and 5. Every follower is reached by all three leaders, so every target lies inside the
leaders' triangle (docs/fidelity.md, paper 001, reading 1).
"""

FIGURE_5_EDGES = (
    (9, 11), (9, 12),
    (1, 10), (1, 9), (2, 10), (2, 9), (2, 1),
    (7, 10), (7, 9), (8, 10), (8, 9), (8, 7),
    (3, 10), (3, 11), (3, 12), (3, 4), (4, 10), (4, 11), (4, 12),
    (5, 3), (6, 4), (6, 5),
)  # fmt: skip
"""Substitute for Figure 5 (lost), 1-based ``(receiver, sender)``, 9 followers, leaders 10-12.

π1 cells (Definition 2): {10}, {11}, {12}, {1, 2, 7, 8}, {3, 4}, {5, 6}, {9}. Each of 1, 2, 7,
8 hears one member of {10} and one of {9} (plus links inside the cell, which Theorem 4 leaves
free); each of 3, 4 hears all three leaders; each of 5, 6 hears one of {3, 4} and nothing
outside, so 3, 4, 5, 6 share one steady state (section 5.2: "C5 only receive information from
C3"); 9 hears leaders 11 and 12. Steady states: σ10/2 + σ11/4 + σ12/4, the leaders' centroid,
(σ11 + σ12)/2 (docs/fidelity.md, paper 001, reading 2).
"""
FIGURE_5_CELLS = ((9,), (10,), (11,), (0, 1, 6, 7), (2, 3), (4, 5), (8,))
"""The π1 partition of :data:`FIGURE_5_EDGES`, 0-based node indices."""


def _scenario_defaults(scenario: str) -> dict[str, object]:
    """The N- and M-sized fields of a scenario."""
    if scenario == "paper":
        return {
            "adjacency": adjacency_from_edges(9, ((r - 1, s - 1) for r, s in FIGURE_2_EDGES)),
            "leader_attitudes": LEADER_ATTITUDES,
            "nominal_inertias": NOMINAL_INERTIAS,
            "initial_attitudes": TABLE_1_ATTITUDES,
            "initial_rates": TABLE_1_RATES,
            "constant_disturbances": CONSTANT_DISTURBANCES,
        }
    return {
        "adjacency": adjacency_from_edges(12, ((r - 1, s - 1) for r, s in FIGURE_5_EDGES)),
        "leader_attitudes": LEADER_ATTITUDES,
        # Eq. (71) is lost: followers 1-6 keep eq. (64) and 7-9 repeat J_01 .. J_03.
        "nominal_inertias": NOMINAL_INERTIAS + NOMINAL_INERTIAS[:3],
        "initial_attitudes": TABLE_1_ATTITUDES + TABLE_2_EXTRA_ATTITUDES,
        "initial_rates": TABLE_1_RATES + TABLE_2_EXTRA_RATES,
        "constant_disturbances": CONSTANT_DISTURBANCES + EXTRA_CONSTANT_DISTURBANCES,
    }


@dataclass(frozen=True)
class ClusterContainmentParams:
    """Model, controller and scenario of paper 001; defaults are the paper's values.

    Every field can be overridden as a keyword argument of the environments. Fields left
    ``None`` take the value of ``scenario``; after construction they hold arrays.
    """

    scenario: str = "paper"
    """'paper' (section 5.1, Figure 2, Table 1) or 'pi1' (section 5.2, Figure 5, Table 2)."""
    adjacency: Any = None
    """(N+M)×(N+M) adjacency, a_ij > 0 when i receives from j (section 2.3); followers first."""
    leader_attitudes: Any = None
    """M×3 stationary leader MRPs, eq. (63) / eq. (70), rad."""
    nominal_inertias: Any = None
    """N×3×3 nominal inertias J_0i, eq. (64), kg·m² (the plant's J_i = J_0i + ΔJ_i)."""
    inertia_uncertainty: Any = None
    """N×3×3 ΔJ_i of eq. (5); not given by the paper, None means zero (docs/fidelity.md)."""
    initial_attitudes: Any = None
    """N×3 σ_i(0), Table 1 / Table 2, rad."""
    initial_rates: Any = None
    """N×3 ω_i(0), Table 1 / Table 2, rad/s."""
    constant_disturbances: Any = None
    """N×3 constant torques d_li, eq. (67) / eq. (72), N·m."""
    periodic_disturbance_fraction: float = 0.2
    """The 1/5 of eq. (68): d_uni scales the constant torque's components."""
    periodic_disturbance_rates: tuple = (1.0 / 12.0, 1.0 / 15.0, 1.0 / 10.0, 1.0 / 15.0)
    """Angular rates (rad/s) of sin(t/12), cos(t/15), sin(t/10) cos(t/15) in eq. (68)."""
    initial_parameter_estimate: tuple = (22.0, 26.0, 25.0, 0.0, 0.0, 0.0)
    """Θ̂_i(0) = [J11, J22, J33, J12, J13, J23] (section 5.1), kg·m²."""
    initial_switching_gain: float = 0.0
    """k̂_i(0) of eq. (21); not given by the paper."""
    alpha: float = 0.02
    """α of eqs. (9)-(10) (eq. 65)."""
    control_gain: tuple = (1.0, 1.0, 1.0)
    """diag(K_i) of eq. (19) (eq. 65: K_i = [1 1 1]ᵀ)."""
    adaptation_gain: tuple = (2.0, 2.0, 2.0, 2.0, 2.0, 2.0)
    """diag(Λ_i) of eq. (20); eq. (65) writes diag(2 2 2) for a 6-parameter Θ_i."""
    switching_gain_rate: float = 0.001
    """Γ_i of eq. (21) (eq. 65)."""
    switching: str = "saturation"
    """Robust term of eq. (19): 'saturation' sat(s, δ) of Remark 2 (eq. 51), or 'sign' sgn(s)
    as eq. (19) prints it; with 'sign' the event condition (15) fires at most sampling instants
    once s reaches its sliding band (docs/fidelity.md, paper 001, reading 5)."""
    saturation_width: float = 0.001
    """δ of eq. (51), used with ``switching='saturation'``; the paper says only 'small'."""
    torque_limit: float = 1.0
    """Bound on each body-torque component, N·m (section 5.1.1: [-1, 1] N·m)."""
    sampling_period_s: float = 0.01
    """Sampling period (section 5.1.2: 0.01 s)."""
    horizon_s: float = 1200.0
    """Simulation length (section 5.1.2: 1200 s)."""
    max_mrp_norm: float = 1.0
    """Failure bound on ‖σ_i‖: beyond 1 the MRP describes a rotation past 180°."""
    max_rate_rad_s: float = 0.5
    """Failure bound on ‖ω_i‖ (the paper's rates stay below 0.03 rad/s)."""

    def __post_init__(self) -> None:
        require_field_types(self)
        require_choice("scenario", self.scenario, SCENARIOS)
        defaults = _scenario_defaults(self.scenario)
        for name, value in defaults.items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, value)
        leaders = require_float_array("leader_attitudes", self.leader_attitudes)
        if leaders.ndim != 2 or leaders.shape[1] != 3 or not np.all(np.isfinite(leaders)):
            raise ValueError(f"leader_attitudes must be an M×3 array, got shape {leaders.shape}")
        outside = np.flatnonzero(np.linalg.norm(leaders, axis=1) > 1.0)
        if outside.size:
            raise ValueError(
                f"leader_attitudes must be MRPs in the unit ball (|σ| <= 1, rotations up to "
                f"180°); leader(s) {outside.tolist()} have |σ| = "
                f"{np.linalg.norm(leaders[outside], axis=1).round(6).tolist()}"
            )
        initial = require_float_array("initial_attitudes", self.initial_attitudes)
        if initial.ndim != 2 or initial.shape[1] != 3 or len(initial) < 1:
            raise ValueError(f"initial_attitudes must be an N×3 array, got shape {initial.shape}")
        n, m = len(initial), len(leaders)
        object.__setattr__(self, "leader_attitudes", leaders)
        object.__setattr__(self, "adjacency", validate_adjacency("adjacency", self.adjacency, n, m))
        for name in ("initial_attitudes", "initial_rates", "constant_disturbances"):
            array = require_float_array(name, getattr(self, name))
            if array.shape != (n, 3) or not np.all(np.isfinite(array)):
                raise ValueError(f"{name} must be a finite {n}×3 array, got shape {array.shape}")
            object.__setattr__(self, name, array)
        for name in ("nominal_inertias", "inertia_uncertainty"):
            if getattr(self, name) is None:
                continue
            array = require_float_array(name, getattr(self, name))
            if array.shape != (n, 3, 3) or not np.all(np.isfinite(array)):
                raise ValueError(f"{name} must be a finite {n}×3×3 array, got shape {array.shape}")
            object.__setattr__(self, name, array)
        uncertainty = self.true_inertias - self.nominal_inertias
        for i in range(n):
            require_spd_matrix(f"nominal_inertias[{i}]", self.nominal_inertias[i])
            if not np.allclose(uncertainty[i], uncertainty[i].T):
                raise ValueError(f"inertia_uncertainty[{i}] must be symmetric")
            try:
                require_spd_matrix(f"inertia_uncertainty[{i}]", self.true_inertias[i])
            except ValueError as error:
                raise ValueError(
                    f"inertia_uncertainty[{i}]: J_0i + ΔJ_i must be positive definite ({error})"
                ) from None
        if np.any(np.linalg.norm(initial, axis=1) >= self.max_mrp_norm):
            raise ValueError(
                f"initial_attitudes must have ‖σ_i‖ < max_mrp_norm = {self.max_mrp_norm}"
            )
        require_vector("periodic_disturbance_rates", self.periodic_disturbance_rates, 4)
        require_vector("initial_parameter_estimate", self.initial_parameter_estimate, 6)
        require_vector("control_gain", self.control_gain, 3, positive=True)
        require_vector("adaptation_gain", self.adaptation_gain, 6, positive=True)
        require_choice("switching", self.switching, SWITCHING_FUNCTIONS)
        require_non_negative("periodic_disturbance_fraction", self.periodic_disturbance_fraction)
        require_non_negative("initial_switching_gain", self.initial_switching_gain)
        for name in (
            "alpha",
            "switching_gain_rate",
            "saturation_width",
            "torque_limit",
            "sampling_period_s",
            "horizon_s",
            "max_mrp_norm",
            "max_rate_rad_s",
        ):
            require_positive(name, getattr(self, name))

    @property
    def n_followers(self) -> int:
        """N."""
        return len(self.initial_attitudes)

    @property
    def n_leaders(self) -> int:
        """M."""
        return len(self.leader_attitudes)

    @property
    def true_inertias(self) -> np.ndarray:
        """J_i = J_0i + ΔJ_i (eq. 5), N×3×3 (ΔJ_i = 0 when ``inertia_uncertainty`` is None)."""
        nominal = require_float_array("nominal_inertias", self.nominal_inertias)
        if self.inertia_uncertainty is None:
            return nominal.copy()
        return nominal + require_float_array("inertia_uncertainty", self.inertia_uncertainty)


def replace_params(
    params: ClusterContainmentParams | None, overrides: dict[str, object]
) -> ClusterContainmentParams:
    """``params`` (``None`` for the defaults) with ``overrides`` applied; a new ``scenario``
    restores that scenario's arrays for every N/M-sized field not overridden. Unknown names and
    a ``params`` of another type raise ``TypeError``."""
    current = params.scenario if isinstance(params, ClusterContainmentParams) else "paper"
    if "scenario" in overrides and overrides["scenario"] != current:
        reset = dict.fromkeys((*_scenario_defaults("paper"), "inertia_uncertainty"))
        overrides = {**reset, **overrides}
    return apply_overrides(ClusterContainmentParams, params, overrides, "the cluster environments")

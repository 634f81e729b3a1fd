"""The per-axis send-on-delta conditions eqs. (4)-(6) of paper 004 as a trigger policy, and the
error-time rule on the same sampling errors (a reference trigger beside the paper's)."""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

import gymnasium as gym
import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.core.validation import require_positive
from etsc_envs.inner_formation.design import equal_share_thresholds
from etsc_envs.inner_formation.params import InnerFormationParams
from etsc_envs.triggers.base import RuleTrigger

AXES = ("x", "y", "z")

PAPER_SHIELD_MULTIPLE = 2.0
"""How many Π_i the shield of :class:`InnerFormationShield` lets a sampling error reach."""


def default_thresholds() -> np.ndarray:
    """Π_i sized by condition (7) for the paper's parameters (equal shares of the bound (A9))."""
    return equal_share_thresholds(InnerFormationParams())


def axis_thresholds(
    default: Callable[[], np.ndarray],
    name: str,
    common: float | None,
    per_axis: tuple[float | None, float | None, float | None],
    unit: str,
) -> np.ndarray:
    """The three per-axis thresholds of a trigger: ``common`` on every axis (``default()`` if
    ``None``), each overridden by its entry of ``per_axis`` where given; ``ValueError`` naming
    ``name``, ``name1``..``name3`` unless all are finite and > 0 (in ``unit``)."""
    thresholds = default() if common is None else np.full(3, float(common))
    for axis, value in enumerate(per_axis):
        if value is not None:
            thresholds[axis] = float(value)
    if not np.all(np.isfinite(thresholds)) or np.any(thresholds <= 0.0):
        raise ValueError(
            f"{name}, {name}1, {name}2, {name}3 must be finite numbers > 0 ({unit}), "
            f"got {thresholds}"
        )
    return thresholds


@jit
def inner_formation_condition(observation, indices, parameters, statistic, threshold):
    """Eqs. (4)-(6)'s two sides on one observation: for axis i, |r_i(t) - r_i(t_k)|
    (``sampling_error_m_*``, ``indices[i]``) against Π_i (``parameters[i]``); the axis
    transmits when the error is greater."""
    for axis in range(3):
        statistic[axis] = abs(float(observation[indices[axis]]))
        threshold[axis] = parameters[axis]


class InnerFormationTrigger(RuleTrigger):
    """Axis i transmits when |r_i(t) - r_i(t_k)| > Π_i (the complement of eqs. 4-6).

    Args:
        pi: one threshold Π for all axes (m), or
        pi1, pi2, pi3: per-axis thresholds (m). Unset thresholds default to
            :func:`default_thresholds`, which sizes them from condition (7).
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        pi: float | None = None,
        pi1: float | None = None,
        pi2: float | None = None,
        pi3: float | None = None,
    ) -> None:
        thresholds = axis_thresholds(default_thresholds, "pi", pi, (pi1, pi2, pi3), "m")
        self.thresholds = thresholds
        super().__init__(
            observation_space,
            action_space,
            indices=[observation_names.index(f"sampling_error_m_{a}") for a in AXES],
            parameters=thresholds,
            keywords={"pi1": thresholds[0], "pi2": thresholds[1], "pi3": thresholds[2]},
        )

    condition = staticmethod(inner_formation_condition)
    strict = True
    threshold_groups: ClassVar[dict[str, tuple[str, ...]]] = {"pi": ("pi1", "pi2", "pi3")}

    @classmethod
    def paper_thresholds(cls) -> dict[str, float]:
        pi1, pi2, pi3 = default_thresholds()
        return {"pi1": float(pi1), "pi2": float(pi2), "pi3": float(pi3)}


ERROR_TIME_REFERENCE_S = 0.05
"""The default error-time thresholds are Π_i × this (s): near the mean interval between an
axis's transmissions under the paper's rule at Π_i on the paper scenario (12 840 transmissions
of 3 axes in 200 s, 47 ms), so that factor 1 sends about as often as the paper's rule."""


def default_error_time_thresholds() -> np.ndarray:
    """A_i = Π_i × :data:`ERROR_TIME_REFERENCE_S` (m·s), with Π_i of :func:`default_thresholds`."""
    return default_thresholds() * ERROR_TIME_REFERENCE_S


@jit
def inner_formation_error_time_condition(observation, indices, parameters, statistic, threshold):
    """The error-time rule's two sides on one observation: axis i compares |r_i(t) - r_i(t_k)|
    · (t - t_k) (``sampling_error_m_*`` at ``indices[i]``, ``time_since_transmission_s_*`` at
    ``indices[3 + i]``) with A_i (``parameters[i]``); it transmits when the product is the
    larger."""
    for axis in range(3):
        error = abs(float(observation[indices[axis]]))
        elapsed = float(observation[indices[3 + axis]])
        statistic[axis] = error * elapsed
        threshold[axis] = parameters[axis]


class InnerFormationErrorTimeTrigger(RuleTrigger):
    """Axis i transmits when its sampling error times the time since its last transmission,
    |r_i(t) - r_i(t_k)| · (t - t_k), passes A_i (not a rule of paper 004: a reference beside it).

    Why this product: an axis whose measurement drifts at speed v_i accumulates a sampling error
    v_i τ, so an interval of length h costs ∫ |r_i - r_i(t_k)| dt = v_i h² / 2. For a given
    number of transmissions that integral is least when their density is ∝ √v_i, h ∝ 1/√v_i.
    Eqs. (4)-(6) transmit at h = Π_i / v_i (density ∝ v_i) and a clock at a constant h
    (density independent of v_i): the two ends of the family h ∝ v_i^(-p). The product
    |r_i - r_i(t_k)| τ ≈ v_i τ² passes A_i at τ = √(A_i / v_i), the optimum's p = 1/2. The
    sampling error enters the env's per-step cost Σ_i |r_i - ζ_i| through the observer, which
    tracks the held measurement (eq. 3). docs/results.md compares it with the paper's rule and
    the clock.

    Args:
        area: one threshold A for all axes (m·s), or
        area1, area2, area3: per-axis thresholds (m·s). Unset thresholds default to
            :func:`default_error_time_thresholds`.
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        area: float | None = None,
        area1: float | None = None,
        area2: float | None = None,
        area3: float | None = None,
    ) -> None:
        thresholds = axis_thresholds(
            default_error_time_thresholds, "area", area, (area1, area2, area3), "m·s"
        )
        self.thresholds = thresholds
        names = [f"sampling_error_m_{a}" for a in AXES] + [
            f"time_since_transmission_s_{axis}" for axis in range(3)
        ]
        super().__init__(
            observation_space,
            action_space,
            indices=[observation_names.index(name) for name in names],
            parameters=thresholds,
            keywords={"area1": thresholds[0], "area2": thresholds[1], "area3": thresholds[2]},
        )

    condition = staticmethod(inner_formation_error_time_condition)
    strict = True
    threshold_groups: ClassVar[dict[str, tuple[str, ...]]] = {"area": ("area1", "area2", "area3")}

    @classmethod
    def paper_thresholds(cls) -> dict[str, float]:
        """The default areas (:func:`default_error_time_thresholds`; not the paper's own)."""
        area1, area2, area3 = default_error_time_thresholds()
        return {"area1": float(area1), "area2": float(area2), "area3": float(area3)}


def predicted_sampling_error(velocity_estimate: np.ndarray, hold_s: np.ndarray) -> np.ndarray:
    """|r_i(t_k + h) - r_i(t_k)| to first order in h after a transmission at t_k: |ψ_i| h.

    Args:
        velocity_estimate: ψ_i, the observer's velocity estimates, shape ``(batch, 3)`` (m/s).
        hold_s: hold durations h, shape ``(n,)`` (s).

    Returns the predicted sampling errors, shape ``(batch, n, 3)`` (m).
    """
    return np.abs(velocity_estimate)[:, None, :] * np.asarray(hold_s)[None, :, None]


class InnerFormationShield:
    """Which holds keep every axis' sampling error within ``multiple`` × Π_i.

    Theorem 1's bounds (8)-(10) are proved for sampling errors |r_i(t) - r_i(t_k)| ≤ Π_i, which
    eqs. (4)-(6) enforce, and grow with Π_i (:mod:`etsc_envs.inner_formation.design`): sampling
    errors kept within m Π_i keep the estimation errors within the bounds of the thresholds
    m Π_i. A hold of h
    after a transmission is called unsafe when its first-order sampling error
    (:func:`predicted_sampling_error`) passes m Π_i on some axis; the paper's own rule with its
    thresholds scaled by f keeps the error within f Π_i (one sampling period's motion aside), so
    it is unsafe when f > m. A hold of one sampling period (transmitting at every instant) is
    always allowed.

    Args:
        observation_names: the environment's ``observation_names``.
        sampling_period_s: the environment's sampling period (s).
        multiple: m > 0.
        thresholds: Π_i (m); :func:`default_thresholds` when unset.
    """

    def __init__(
        self,
        observation_names: tuple[str, ...],
        sampling_period_s: float,
        multiple: float = PAPER_SHIELD_MULTIPLE,
        thresholds: np.ndarray | None = None,
    ) -> None:
        self.multiple = require_positive("multiple", multiple)
        self.sampling_period_s = require_positive("sampling_period_s", sampling_period_s)
        self.thresholds = default_thresholds() if thresholds is None else np.asarray(thresholds)
        self.velocity_indices = [
            observation_names.index(f"velocity_estimate_mps_{a}") for a in AXES
        ]

    def allowed_holds(self, obs: np.ndarray, hold_steps: np.ndarray) -> np.ndarray:
        """Whether each hold of ``hold_steps`` sampling periods is safe after a transmission at
        the instant of each observation: booleans of shape ``(batch, n)``."""
        hold_steps = np.asarray(hold_steps)
        hold_s = hold_steps * self.sampling_period_s
        error = predicted_sampling_error(obs[:, self.velocity_indices], hold_s)
        within = (error <= self.multiple * self.thresholds).all(axis=2)
        return within | (hold_steps == 1)[None, :]

    def allowed_factors(self, factors: np.ndarray) -> np.ndarray:
        """Whether the paper's rule with its thresholds scaled by each factor is safe."""
        return np.asarray(factors) <= self.multiple

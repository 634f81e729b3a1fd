"""Episode metrics common to every environment: accuracy cost and communication statistics."""

from __future__ import annotations

from typing import Any

import numpy as np

from etsc_envs.core.compiled_loop import LoopArrays

COMMON_EPISODE_KEYS = (
    "steps",
    "sim_time_s",
    "mean_cost",
    "transmissions",
    "transmission_rate",
    "mean_interevent_s",
    "min_interevent_s",
    "failure",
    "settled",
)
"""Keys every environment's ``episode_metrics`` carries (the design page's common record;
``failure`` and ``settled`` are added by the env, the paper's own metrics come beside them)."""


def interevent_summary(
    transmissions: np.ndarray, interevent_sum_s: np.ndarray, interevent_min_s: np.ndarray
) -> tuple[float | None, float | None]:
    """Mean and minimum time between consecutive transmissions of the given channels pooled
    (``None`` when no channel transmitted twice)."""
    intervals = int(np.maximum(np.asarray(transmissions) - 1, 0).sum())
    if intervals == 0:
        return None, None
    return float(np.sum(interevent_sum_s) / intervals), float(np.min(interevent_min_s))


def communication_metrics(arrays: LoopArrays, sim_time_s: float) -> dict[str, Any]:
    """The common record of the first row of ``arrays`` (all its channels pooled), without
    ``failure``.

    ``transmission_rate`` is transmissions per sampling instant and per channel, so that 1.0
    means every channel sent at every instant whatever the number of channels.
    """
    steps = int(arrays.step_index[0])
    transmissions = arrays.transmissions[0]
    n_channels = transmissions.shape[0]
    mean_interevent_s, min_interevent_s = interevent_summary(
        transmissions, arrays.interevent_sum_s[0], arrays.interevent_min_s[0]
    )
    total = int(transmissions.sum())
    return {
        "steps": steps,
        "sim_time_s": sim_time_s,
        "mean_cost": float(arrays.cost_sum[0]) / steps if steps else 0.0,
        "transmissions": total,
        "transmission_rate": total / (steps * n_channels) if steps else 0.0,
        "mean_interevent_s": mean_interevent_s,
        "min_interevent_s": min_interevent_s,
    }

"""Episode metrics common to every environment: accuracy cost and communication statistics."""

from __future__ import annotations

import numpy as np

from etsc_envs.core.channel import HeldChannel

COMMON_EPISODE_KEYS = (
    "steps",
    "sim_time_s",
    "mean_cost",
    "transmissions",
    "transmission_rate",
    "mean_interevent_s",
    "min_interevent_s",
    "failure",
)
"""Keys every environment's ``episode_metrics`` carries (the design page's common record;
``failure`` is added by the step loop, the paper's own metrics come beside them)."""


def interevent_summary(intervals_s: list[float]) -> tuple[float | None, float | None]:
    """Mean and minimum of inter-event times (``None`` when fewer than two transmissions)."""
    if not intervals_s:
        return None, None
    return float(np.mean(intervals_s)), float(np.min(intervals_s))


def communication_metrics(
    channel: HeldChannel, steps: int, sim_time_s: float, cost_sum: float
) -> dict:
    """The common episode record of the design page (all channels pooled).

    ``transmission_rate`` is transmissions per sampling instant and per channel, so that 1.0
    means every channel sent at every instant whatever the number of channels.
    """
    transmissions = int(channel.transmissions.sum())
    pooled = [dt for intervals in channel.interevent_s for dt in intervals]
    mean_interevent_s, min_interevent_s = interevent_summary(pooled)
    return {
        "steps": steps,
        "sim_time_s": sim_time_s,
        "mean_cost": cost_sum / steps if steps else 0.0,
        "transmissions": transmissions,
        "transmission_rate": transmissions / (steps * channel.n_channels) if steps else 0.0,
        "mean_interevent_s": mean_interevent_s,
        "min_interevent_s": min_interevent_s,
    }

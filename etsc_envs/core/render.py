"""``render_mode="rgb_array"`` of every environment: the episode so far as one picture.

An environment rendering frames keeps an :class:`EpisodeTrace` (the time, the accuracy cost of
the reward and each channel's transmission instants, recorded once per step) and draws it with
:func:`draw_frame`: the per-step accuracy cost ``cost_k`` against time on top (what the reward
penalises: each paper's tracking errors, see the environment's docs), and one row of
transmission instants per channel below. Matplotlib draws off-screen (the Agg canvas), so no
display is needed.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

RENDER_MODES = ("rgb_array",)
"""The render modes every environment of the suite accepts (besides ``None``)."""

FRAME_SIZE_PX = (640, 480)
"""Width and height of a frame, pixels."""
FRAME_DPI = 100


class EpisodeTrace:
    """What a frame shows, recorded step by step since the last reset.

    Args:
        n_channels: the separately triggered channels of the loop.
    """

    def __init__(self, n_channels: int) -> None:
        self.n_channels = n_channels
        self.clear()

    def clear(self) -> None:
        """Forget the episode (at a reset)."""
        self.times_s: list[float] = []
        self.costs: list[float] = []
        self.transmit_times_s: list[list[float]] = [[] for _ in range(self.n_channels)]

    def record(self, time_s: float, cost: float, sent: np.ndarray) -> None:
        """One step that ended at ``time_s`` with accuracy cost ``cost``; ``sent[i]`` is nonzero
        if channel ``i`` transmitted at the step's start, ``time_s`` minus one period earlier."""
        self.times_s.append(time_s)
        self.costs.append(cost)
        for channel in np.flatnonzero(sent):
            self.transmit_times_s[channel].append(time_s)


def draw_frame(trace: EpisodeTrace, channel_labels: tuple[str, ...], title: str) -> np.ndarray:
    """The trace as an RGB image, ``uint8`` of shape ``(height, width, 3)``."""
    width, height = FRAME_SIZE_PX
    figure = Figure(figsize=(width / FRAME_DPI, height / FRAME_DPI), dpi=FRAME_DPI)
    canvas = FigureCanvasAgg(figure)
    cost_axes, event_axes = figure.subplots(
        2, 1, sharex=True, gridspec_kw={"height_ratios": [3, max(1, min(trace.n_channels, 3))]}
    )
    figure.suptitle(title, fontsize=10)
    costs = np.asarray(trace.costs)
    cost_axes.plot(trace.times_s, costs, linewidth=0.8)
    if costs.size and np.all(costs > 0.0):
        cost_axes.set_yscale("log")
    cost_axes.set_ylabel("accuracy cost per step")
    cost_axes.grid(alpha=0.3)
    event_axes.eventplot(trace.transmit_times_s, linelengths=0.8, linewidths=0.6)
    event_axes.set_yticks(range(trace.n_channels), labels=channel_labels, fontsize=7)
    event_axes.set_ylim(-0.6, trace.n_channels - 0.4)
    event_axes.set_xlabel("time (s)")
    event_axes.set_title("transmissions", fontsize=9)
    figure.tight_layout()
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()

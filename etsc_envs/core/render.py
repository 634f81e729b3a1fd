"""``render_mode="rgb_array"`` and ``"human"`` of every environment: the system beside the
episode so far.

A frame has two halves. On the left, the problem's :class:`SystemPicture` draws the system at
the current instant (the spacecraft, the formation, the cluster or the asteroid, with a trail
through the states of the frames drawn before in the episode). On the right, the per-step
accuracy cost ``cost_k`` of the reward (each paper's tracking errors, see the environment's
docs) over the episode's horizon, and below it one row of transmission instants per channel,
each row labelled with its count. Matplotlib draws off-screen (the Agg canvas), so no display is
needed for ``"rgb_array"``.

Nothing is computed on the step's hot path unless a render mode is set: an environment that
renders keeps an :class:`EpisodeTrace` (each step's cost and transmit bits), and the system's
state is read only when a frame is drawn. ``"human"`` shows the same frames in a Matplotlib
window (:class:`HumanWindow`), redrawn as the episode runs at most ``render_fps`` times per
second of wall-clock time.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.gridspec import SubplotSpec
from matplotlib.ticker import LogFormatter

RENDER_MODES = ("rgb_array", "human")
"""The render modes every environment of the suite accepts (besides ``None``)."""


class RenderModes(list):
    """An env's ``metadata["render_modes"]``: a list whose membership test refuses a mode that
    is not a string with one line naming ``render_mode`` (``gym.make`` tests membership, then
    calls string methods on the mode, before the env's own check runs)."""

    def __contains__(self, mode: object) -> bool:
        if mode is not None and not isinstance(mode, str):
            raise ValueError(f"render_mode must be one of {tuple(self)} or None, got {mode!r}")
        return super().__contains__(mode)


RENDER_FPS = 10
"""Frames per second of ``"human"`` mode (wall-clock) and of the GIFs made from the frames."""

FRAME_SIZE_PX = (960, 480)
"""Width and height of a frame, pixels."""
FRAME_DPI = 100

TRANSMISSION_COLOR = "#6a0dad"
"""The colour of the transmission marks, used nowhere else in a frame (a test counts its
pixels)."""
AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4")
"""The colours of a frame's x, y and z axes in the system pictures."""
COST_COLOR = "#1f77b4"
EVENT_COLUMNS = 2000
"""Transmission instants closer than ``horizon / EVENT_COLUMNS`` share one mark (a frame is
narrower than this in pixels, so a dense row looks the same and draws in bounded time)."""
COST_POINTS = 1000
"""A cost curve with more steps is drawn as its per-bin minimum and maximum over this many bins."""


@dataclass(frozen=True)
class SystemPicture:
    """How a problem draws its system.

    Args:
        snapshot: ``snapshot(env) -> 1-D array``, the state the picture needs at the current
            instant (read when a frame is drawn; the frames' snapshots form the trail).
        draw: ``draw(env, figure, region, trail)`` draws the system into the ``region`` of
            ``figure``; ``trail`` stacks the snapshots of the episode's frames, the current one
            last.
    """

    snapshot: Callable[[Any], np.ndarray]
    draw: Callable[[Any, Figure, SubplotSpec, np.ndarray], None]


class EpisodeTrace:
    """What a frame shows, recorded since the last reset.

    Args:
        n_channels: the separately triggered channels of the loop.
        period_s: the sampling period (s); a transmission at step ``k`` is drawn at its start,
            ``k × period_s``.
    """

    def __init__(self, n_channels: int, period_s: float) -> None:
        self.n_channels = n_channels
        self.period_s = period_s
        self.clear()

    def clear(self) -> None:
        """Forget the episode (at a reset)."""
        self.times_s: list[float] = []
        self.costs: list[float] = []
        self.transmit_times_s: list[list[float]] = [[] for _ in range(self.n_channels)]
        self.snapshot_times_s: list[float] = []
        self.snapshots: list[np.ndarray] = []

    def record(self, step_index: int, cost: float, sent: np.ndarray) -> None:
        """Step ``step_index`` (0 for the first of the episode), its accuracy cost ``cost`` and
        its transmit bits ``sent`` (nonzero where a channel transmitted at the step's start)."""
        start_s = step_index * self.period_s
        self.times_s.append(start_s + self.period_s)
        self.costs.append(cost)
        for channel in np.flatnonzero(sent):
            self.transmit_times_s[channel].append(start_s)

    def note_snapshot(self, time_s: float, snapshot: np.ndarray) -> np.ndarray:
        """Add the system's state of a frame drawn at ``time_s`` to the trail (once per
        instant), and return the trail."""
        if self.snapshot_times_s and self.snapshot_times_s[-1] == time_s:
            self.snapshots[-1] = snapshot
        else:
            self.snapshot_times_s.append(time_s)
            self.snapshots.append(snapshot)
        return np.stack(self.snapshots)


def draw_frame(
    trace: EpisodeTrace,
    channel_labels: tuple[str, ...],
    title: str,
    horizon_s: float,
    system: Callable[[Figure, SubplotSpec], None] | None = None,
) -> np.ndarray:
    """The frame as an RGB image, ``uint8`` of shape ``(height, width, 3)``: ``system`` (a
    problem's :attr:`SystemPicture.draw` bound to its env and trail) on the left, the cost and
    transmission strips of ``trace`` over ``[0, horizon_s]`` on the right."""
    width, height = FRAME_SIZE_PX
    figure = Figure(figsize=(width / FRAME_DPI, height / FRAME_DPI), dpi=FRAME_DPI)
    canvas = FigureCanvasAgg(figure)
    figure.suptitle(title, fontsize=10)
    outer = figure.add_gridspec(
        1, 2, width_ratios=[1.0, 1.1], left=0.03, right=0.985, top=0.9, bottom=0.1, wspace=0.28
    )
    if system is not None:
        system(figure, outer[0])
    rows = max(1, min(trace.n_channels, 4))
    strips = outer[1].subgridspec(2, 1, height_ratios=[3, rows], hspace=0.35)
    cost_axes = figure.add_subplot(strips[0])
    event_axes = figure.add_subplot(strips[1], sharex=cost_axes)
    _draw_cost(cost_axes, trace)
    _draw_transmissions(event_axes, trace, channel_labels, horizon_s)
    cost_axes.set_xlim(-0.01 * horizon_s, 1.01 * horizon_s)  # marks at 0 clear of the spine
    cost_axes.tick_params(labelbottom=False)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def _draw_cost(axes: Axes, trace: EpisodeTrace) -> None:
    """The accuracy cost per step against time, as its min/max envelope when dense."""
    times, costs = np.asarray(trace.times_s), np.asarray(trace.costs)
    if costs.size > COST_POINTS:
        edges = np.linspace(0, costs.size, COST_POINTS + 1).astype(int)[:-1]
        low, high = np.minimum.reduceat(costs, edges), np.maximum.reduceat(costs, edges)
        axes.fill_between(times[edges], low, high, color=COST_COLOR, linewidth=0.8)
    else:
        axes.plot(times, costs, color=COST_COLOR, linewidth=0.9)
    if costs.size and np.all(costs > 0.0):
        axes.set_yscale("log")
        # plain labels: mathtext (10^k) costs a tenth of a second per frame
        axes.yaxis.set_major_formatter(LogFormatter())
        axes.yaxis.set_minor_formatter(LogFormatter(labelOnlyBase=False))
    axes.set_ylabel("accuracy cost per step", fontsize=8)
    axes.tick_params(which="both", labelsize=7)
    axes.grid(alpha=0.3)


def _draw_transmissions(
    axes: Axes, trace: EpisodeTrace, labels: tuple[str, ...], horizon_s: float
) -> None:
    """One row per channel, a mark at each transmission instant (top row: channel 0)."""
    resolution = horizon_s / EVENT_COLUMNS
    for channel, times in enumerate(trace.transmit_times_s):
        row = trace.n_channels - 1 - channel
        marks = np.unique(np.round(np.asarray(times) / resolution)) * resolution
        axes.vlines(
            marks, row - 0.38, row + 0.38, colors=TRANSMISSION_COLOR, linewidth=1.0,
            antialiased=False,
        )  # fmt: skip
    counts = [len(times) for times in trace.transmit_times_s]
    axes.set_yticks(
        range(trace.n_channels),
        labels=[f"{label} ({count})" for label, count in zip(labels, counts, strict=True)][::-1],
        fontsize=7 if trace.n_channels <= 6 else 6,
    )
    axes.set_ylim(-0.6, trace.n_channels - 0.4)
    axes.set_xlabel("time (s)", fontsize=8)
    axes.tick_params(axis="x", labelsize=7)
    axes.set_title("transmissions", fontsize=8)


# ----------------------------------------------------------------- drawing helpers
def view_matrix(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Rows: the screen's right and up directions and the direction towards the viewer, in
    world components, for a viewer at ``azimuth_deg`` about z (from x) and ``elevation_deg``
    above the x-y plane (an orthographic view)."""
    azimuth, elevation = np.radians(azimuth_deg), np.radians(elevation_deg)
    toward = np.array(
        [
            np.cos(elevation) * np.cos(azimuth),
            np.cos(elevation) * np.sin(azimuth),
            np.sin(elevation),
        ]
    )
    right = np.array([-np.sin(azimuth), np.cos(azimuth), 0.0])
    return np.stack([right, np.cross(toward, right), toward])


def draw_triad(
    axes: Axes,
    view: np.ndarray,
    rotation: np.ndarray,
    origin: np.ndarray,
    length: float,
    *,
    linestyle: str = "-",
    linewidth: float = 2.0,
    alpha: float = 1.0,
    labels: tuple[str, str, str] | None = None,
) -> None:
    """A frame's x, y and z axes (the columns of ``rotation``, world components) from
    ``origin``, projected by ``view`` (:func:`view_matrix`)."""
    start = view[:2] @ origin
    for column, color in enumerate(AXIS_COLORS):
        end = view[:2] @ (origin + length * rotation[:, column])
        axes.plot(
            [start[0], end[0]],
            [start[1], end[1]],
            color=color,
            linestyle=linestyle,
            linewidth=linewidth,
            alpha=alpha,
            solid_capstyle="round",
        )
        if labels is not None:
            axes.annotate(labels[column], (end[0], end[1]), color=color, fontsize=7, alpha=alpha)


def bare_axes(axes: Axes, extent: float) -> None:
    """Equal aspect over ``±extent`` without ticks (a picture, not a plot)."""
    axes.set_xlim(-extent, extent)
    axes.set_ylim(-extent, extent)
    axes.set_aspect("equal")
    axes.set_xticks([])
    axes.set_yticks([])


class HumanWindow:
    """``render_mode="human"``: the frames shown in a Matplotlib window, redrawn at most
    :data:`RENDER_FPS` times per wall-clock second while the episode runs.

    Without an interactive Matplotlib backend (no display, or ``MPLBACKEND=agg``) nothing can
    be shown: the first frame warns once, in one line, and the window stays closed."""

    def __init__(self) -> None:
        self._figure: Figure | None = None
        self._image: Any = None
        self._shown_at = -np.inf
        self._warned = False

    def due(self) -> bool:
        """Whether a redraw is due (1/:data:`RENDER_FPS` s since the last)."""
        return time.monotonic() - self._shown_at >= 1.0 / RENDER_FPS

    def show(self, frame: np.ndarray) -> None:
        """Show ``frame`` (an RGB array) in the window, opening it at the first call."""
        self._shown_at = time.monotonic()
        backend = matplotlib.get_backend().lower()
        if backend in _NON_INTERACTIVE_BACKENDS:
            if not self._warned:
                gym.logger.warn(
                    f"render_mode='human' needs an interactive Matplotlib backend (this one is "
                    f"{backend!r}, no display): nothing is shown; use render_mode='rgb_array'"
                )
                self._warned = True
            return
        import matplotlib.pyplot as plt  # a window needs pyplot's backend machinery

        if self._figure is None or not plt.fignum_exists(self._figure.number):
            width, height = FRAME_SIZE_PX
            self._figure = plt.figure(figsize=(width / FRAME_DPI, height / FRAME_DPI))
            axes = self._figure.add_axes((0.0, 0.0, 1.0, 1.0))
            axes.set_axis_off()
            self._image = axes.imshow(frame)
            plt.show(block=False)
        else:
            self._image.set_data(frame)
        self._figure.canvas.draw_idle()
        self._figure.canvas.flush_events()

    def close(self) -> None:
        """Close the window (if open)."""
        if self._figure is not None:
            import matplotlib.pyplot as plt

            plt.close(self._figure)
            self._figure = None


_NON_INTERACTIVE_BACKENDS = frozenset({"agg", "cairo", "pdf", "pgf", "ps", "svg", "template"})

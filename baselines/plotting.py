"""Figures shared by the commands: one episode's cost and transmission pattern."""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from etsc_envs.core.files import atomic_write_bytes
from etsc_envs.evaluation.episodes import EpisodeTrace


def save(figure: plt.Figure, path: Path) -> Path:
    """Write ``figure`` to ``path`` (creating folders; whole or not at all, in the format of
    the file's suffix) and close it."""
    buffer = io.BytesIO()
    figure.savefig(
        buffer, format=Path(path).suffix.lstrip(".") or None, dpi=120, bbox_inches="tight"
    )
    plt.close(figure)
    return atomic_write_bytes(path, buffer.getvalue())


def plot_interevent(axis: plt.Axes, transmission_times_s: list[float], label: str = "") -> None:
    """Inter-event intervals against the time of the later event (as in the papers' figures)."""
    times = np.asarray(transmission_times_s)
    if len(times) > 1:
        axis.plot(times[1:], np.diff(times), ".", markersize=3, label=label or None)
    axis.set_xlabel("time (s)")
    axis.set_ylabel("inter-event interval (s)")


def plot_episode(trace: EpisodeTrace, path: Path, title: str) -> Path:
    """Per-step cost, cumulative transmissions and inter-event intervals of one episode."""
    figure, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    axes[0].semilogy(trace.time_s, np.maximum(trace.cost, 1e-12))
    axes[0].set_ylabel("cost per step")
    axes[1].step(trace.transmission_times_s, np.arange(1, len(trace.transmission_times_s) + 1))
    axes[1].set_ylabel("transmissions")
    plot_interevent(axes[2], trace.transmission_times_s)
    axes[0].set_title(title)
    return save(figure, path)

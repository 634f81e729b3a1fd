"""Counterparts of paper 001's Figures 3, 4 and 6 from sampled episodes of the cluster."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from baselines.plotting import plot_interevent, save
from etsc_envs.evaluation.episodes import EpisodeTrace
from etsc_envs.triggers.cluster import trigger_threshold

AXES = ("x", "y", "z")
TRIGGER_WINDOW_S = 200.0


def _followers(trace: EpisodeTrace) -> int:
    return trace.samples[0]["sigma"].shape[0]


def plot_signal(trace: EpisodeTrace, name: str, path: Path, title: str, unit: str) -> Path:
    """One panel per axis, one line per follower (Figs. 3(a), 3(b), 3(e), 4(a)-(c), 6(a)-(b)).

    For the attitude, each follower's containment target σ_d,i is dashed in the same colour.
    """
    time_s, signal = trace.sampled("time_s"), trace.sampled(name)
    targets = trace.samples[0]["targets"]
    figure, axes = plt.subplots(3, 1, figsize=(9, 7), sharex=True)
    for a, axis in enumerate(axes):
        for i in range(signal.shape[1]):
            line = axis.plot(time_s, signal[:, i, a], lw=1, label=f"{i + 1}")[0]
            if name == "sigma":
                axis.axhline(targets[i, a], color=line.get_color(), ls="--", lw=0.6)
        axis.set_ylabel(f"{name}_{AXES[a]} ({unit})")
    axes[0].legend(ncol=signal.shape[1], fontsize=7, title="follower", loc="upper right")
    axes[0].set_title(title)
    axes[-1].set_xlabel("t (s)")
    return save(figure, path)


def plot_interevent_times(trace: EpisodeTrace, path: Path, title: str) -> Path:
    """Inter-event times of every follower against time (Figs. 3(c)-(d), 6(c)-(d))."""
    n = _followers(trace)
    figure, axes = plt.subplots(n, 1, figsize=(9, 1.4 * n + 1), sharex=True)
    for i, axis in enumerate(np.atleast_1d(axes)):
        plot_interevent(axis, list(trace.channel_transmission_times(i)))
        axis.set_ylabel(f"{i + 1}", rotation=0)
        axis.set_xlabel("")
    np.atleast_1d(axes)[0].set_title(title + " (inter-event time, s)")
    np.atleast_1d(axes)[-1].set_xlabel("t (s)")
    return save(figure, path)


def plot_hull_trajectories(trace: EpisodeTrace, path: Path, title: str) -> Path:
    """Attitude trajectories with the leaders' convex hull (Figs. 3(f), 4(d), 6(f)-(h))."""
    sigma = trace.sampled("sigma")
    leaders, targets = trace.samples[0]["leaders"], trace.samples[0]["targets"]
    figure = plt.figure(figsize=(13, 4.5))
    for panel, (a, b) in enumerate(((0, 1), (0, 2), (1, 2))):
        axis = figure.add_subplot(1, 3, panel + 1)
        hull = np.vstack([leaders, leaders[:1]])
        axis.fill(hull[:, a], hull[:, b], color="0.85", label="leaders' hull")
        axis.plot(leaders[:, a], leaders[:, b], "k^", label="leaders")
        for i in range(sigma.shape[1]):
            line = axis.plot(sigma[:, i, a], sigma[:, i, b], lw=0.8, label=f"{i + 1}")[0]
            axis.plot(*sigma[0, i, [a, b]], "o", color=line.get_color(), ms=3)
            axis.plot(*targets[i, [a, b]], "x", color=line.get_color(), ms=7)
        axis.set_xlabel(f"sigma_{AXES[a]}")
        axis.set_ylabel(f"sigma_{AXES[b]}")
    figure.axes[0].legend(fontsize=6, ncol=2)
    figure.suptitle(title + " (o start, x target σ_d,i)")
    return save(figure, path)


def plot_trigger(trace: EpisodeTrace, path: Path, title: str) -> Path:
    """Eq. (15)'s event error against its threshold over the first 200 s (Figs. 3(g)-(h))."""
    time_s = trace.sampled("time_s")
    window = time_s <= TRIGGER_WINDOW_S
    error = trace.sampled("event_error")[window]
    state_threshold = trace.sampled("state_threshold")[window]
    n = error.shape[1]
    figure, axes = plt.subplots(n, 1, figsize=(9, 1.5 * n + 1), sharex=True)
    for i, axis in enumerate(np.atleast_1d(axes)):
        threshold = trigger_threshold(
            state_threshold[:, i], trace.samples[0]["sqrt_lambda_min_K"][i], time_s[window]
        )
        axis.semilogy(time_s[window], np.maximum(error[:, i], 1e-9), lw=0.7, label="event error")
        axis.semilogy(time_s[window], threshold, lw=0.7, label="threshold")
        axis.set_ylabel(f"{i + 1}", rotation=0)
    np.atleast_1d(axes)[0].legend(fontsize=7, loc="upper right")
    np.atleast_1d(axes)[0].set_title(title)
    np.atleast_1d(axes)[-1].set_xlabel("t (s)")
    return save(figure, path)


def draw_figures(traces: dict[str, EpisodeTrace], plot_dir: Path) -> list[str]:
    """Figs. 3 (ET, section 5.1), 4 (time-triggered) and 6 (π1 topology)."""
    written = []
    for key, number in (("et", 3), ("tt", 4), ("pi1", 6)):
        trace = traces[key]
        name = {"et": "event-triggered", "tt": "time-triggered", "pi1": "pi1 topology, ET"}[key]
        prefix = plot_dir / f"fig{number}"
        written += [
            plot_signal(
                trace,
                "sigma",
                Path(f"{prefix}_attitudes.png"),
                f"Fig. {number}: attitudes, {name}",
                "rad",
            ),
            plot_signal(
                trace,
                "omega",
                Path(f"{prefix}_rates.png"),
                f"Fig. {number}: body rates, {name}",
                "rad/s",
            ),
            plot_signal(
                trace,
                "u",
                Path(f"{prefix}_control.png"),
                f"Fig. {number}: held control u, {name}",
                "N m",
            ),
            plot_hull_trajectories(
                trace, Path(f"{prefix}_hull.png"), f"Fig. {number}: trajectories, {name}"
            ),
        ]
        if key != "tt":
            written += [
                plot_interevent_times(
                    trace, Path(f"{prefix}_interevent.png"), f"Fig. {number}, {name}"
                ),
                plot_trigger(
                    trace, Path(f"{prefix}_trigger.png"), f"Fig. {number}: eq. (15), {name}"
                ),
            ]
    return [str(path) for path in written]

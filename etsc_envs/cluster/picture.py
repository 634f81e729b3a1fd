"""The system in a frame of paper 001's cluster (``etsc/ClusterContainmentCentral-v0`` and
the PettingZoo ``etsc/ClusterContainment-v0``): the followers' attitudes and the leaders' hull.

Attitudes are points of MRP space (σ, section 2). The leaders' attitudes span the convex hull
that containment (Definition 4) asks the followers to enter: its edges and faces are drawn,
the leaders as stars, each follower's σ_i as a dot with its trail through the episode's frames
and its containment target σ_d,i (eq. 8) as a cross of its colour. The view looks across the
leaders' plane, tilted so that distances off it stay visible, and zooms to what is in play;
the largest follower distance from the hull is written below.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.gridspec import SubplotSpec
from scipy.spatial import ConvexHull, QhullError

from etsc_envs.cluster.closed_loop import PLANT, follower_table
from etsc_envs.cluster.topology import hull_distance
from etsc_envs.core.render import SystemPicture, bare_axes

TILT_DEG = 35.0
"""The view's tilt from the normal of the leaders' plane."""
FOLLOWER_COLORS = ("#ff7f0e", "#2ca02c", "#d62728", "#1f77b4", "#8c564b", "#e377c2",
                   "#7f7f7f", "#bcbd22", "#17becf")  # fmt: skip


def snapshot(env: Any) -> np.ndarray:
    """Every follower's σ_i at the current instant, follower after follower."""
    return follower_table(env.state)[:, PLANT][:, 0:3].ravel()


def hull_view(leaders: np.ndarray) -> np.ndarray:
    """Rows: screen right, screen up and the direction towards the viewer, looking across the
    plane of the leaders' two main directions at :data:`TILT_DEG` from its normal."""
    centred = leaders - leaders.mean(axis=0)
    directions = np.linalg.svd(centred)[2] if len(leaders) > 1 else np.eye(3)
    if len(leaders) < 3:  # a segment or a point: any plane through it
        directions = np.linalg.qr(np.vstack([directions[:1], np.eye(3)]).T)[0].T
    right, second, normal = directions[0], directions[1], np.cross(directions[0], directions[1])
    tilt = np.radians(TILT_DEG)
    toward = np.cos(tilt) * normal + np.sin(tilt) * second
    return np.stack([right, np.cross(toward, right), toward])


def hull_edges(leaders: np.ndarray) -> list[tuple[int, int]]:
    """The edges of the leaders' convex hull (every pair up to a triangle, or when flat)."""
    pairs = list(itertools.combinations(range(len(leaders)), 2))
    if len(leaders) <= 3:
        return pairs
    try:
        hull = ConvexHull(leaders)
    except QhullError:  # coplanar leaders
        return pairs
    return sorted({tuple(sorted(pair)) for face in hull.simplices for pair in
                   itertools.combinations(face, 2)})  # fmt: skip


def draw(env: Any, figure: Figure, region: SubplotSpec, trail: np.ndarray) -> None:
    """Hull, leaders, targets, the followers' trails and attitudes."""
    leaders = np.asarray(env.params.leader_attitudes, dtype=float)
    targets = env.targets
    n = len(targets)
    view = hull_view(leaders)[:2]
    centre = leaders.mean(axis=0)
    paths = (trail.reshape(len(trail), n, 3) - centre) @ view.T  # frames × followers × 2
    hull_2d = (leaders - centre) @ view.T
    targets_2d = (targets - centre) @ view.T
    in_play = np.vstack([paths[-1], hull_2d, targets_2d])
    axes = figure.add_subplot(region)
    bare_axes(axes, 1.25 * float(np.abs(in_play).max()))
    if len(leaders) >= 3:
        axes.fill(*hull_2d[_outline(hull_2d)].T, color="0.88", zorder=0)
    for i, j in hull_edges(leaders):
        axes.plot(*hull_2d[[i, j]].T, color="0.35", linewidth=1.0)
    axes.plot(*hull_2d.T, "*", color="black", markersize=11, label="leaders")
    for follower in range(n):
        color = FOLLOWER_COLORS[follower % len(FOLLOWER_COLORS)]
        axes.plot(*paths[:, follower].T, color=color, linewidth=0.8, alpha=0.6)
        axes.plot(*targets_2d[follower], "x", color=color, markersize=7, markeredgewidth=1.5)
        axes.plot(*paths[-1, follower], "o", color=color, markersize=6)
        axes.annotate(str(follower), paths[-1, follower], xytext=(4, 3),
                      textcoords="offset points", fontsize=7, color=color)  # fmt: skip
    sigma = trail[-1].reshape(n, 3)
    worst = max(hull_distance(point, leaders) for point in sigma)
    axes.set_title("followers' MRPs (dots, targets x) and the leaders' hull", fontsize=8)
    axes.text(0.02, 0.02, f"largest distance from the hull {worst:.3g}",
              transform=axes.transAxes, fontsize=8)  # fmt: skip


def _outline(points: np.ndarray) -> np.ndarray:
    """Indices of the 2-D convex outline of ``points`` (all of them when degenerate)."""
    try:
        return ConvexHull(points).vertices
    except QhullError:
        return np.arange(len(points))


PICTURE = SystemPicture(snapshot=snapshot, draw=draw)

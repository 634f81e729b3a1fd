"""The system in a frame of ``etsc/OrbitAttitudeTracking-v0``: chaser and leader, each with
its frame.

The scene is the virtual leader's frame F_o (x radial, y along-track, z orbit normal, dashed
at the origin; an arrow points at the Earth) in an oblique view; the chaser sits at r_e with
its body axes R_e = attitude_matrix(q_e)ᵀ (paper 000's g_e = g_d⁻¹ g_a, the pose error of
eqs. (5)-(6)), with the trail of its position through the episode's frames. The scale is the
trail's reach, so the whole approach stays in view; ‖Φ‖ and ‖χ‖ of η̃ = log(g_e) are written
beside them.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.gridspec import SubplotSpec

from etsc_envs.core.render import SystemPicture, bare_axes, draw_triad, view_matrix
from etsc_envs.core.rotations import attitude_matrix, quat_angle
from etsc_envs.orbit_attitude.closed_loop import FEATURES, PLANT

VIEW = view_matrix(azimuth_deg=-60.0, elevation_deg=25.0)
CHI = slice(15, 18)
"""χ in the features row ``[e_c, S, η̃, Ṽ]`` (η̃ = [Φ, χ] from 12)."""


def snapshot(env: Any) -> np.ndarray:
    """``[q_e (4), r_e (3), χ (3)]`` at the current instant (r_e and χ in m)."""
    features = env.state[FEATURES]
    return np.concatenate([env.state[PLANT][0:7], features[CHI]])


def draw(env: Any, figure: Figure, region: SubplotSpec, trail: np.ndarray) -> None:
    """The leader's frame at the origin, the chaser's at r_e, the chaser's path."""
    axes = figure.add_subplot(region)
    positions = trail[:, 4:7]
    reach = max(float(np.linalg.norm(positions, axis=1).max()), 1e-3)
    extent = 1.35 * reach
    bare_axes(axes, extent)
    length = 0.3 * reach
    origin = np.zeros(3)
    draw_triad(
        axes, VIEW, np.eye(3), origin, length, linestyle="--", linewidth=1.4, alpha=0.6,
        labels=("radial", "along-track", "normal"),
    )  # fmt: skip
    earth = VIEW[:2] @ np.array([-0.7 * reach, 0.0, 0.0])
    tip = (earth[0], earth[1])
    axes.annotate("", tip, xytext=(0.0, 0.0), arrowprops={"arrowstyle": "->", "color": "0.6"})
    axes.text(*tip, "to Earth", fontsize=7, color="0.4", ha="center", va="bottom")
    path = positions @ VIEW[:2].T
    axes.plot(path[:, 0], path[:, 1], color="0.45", linewidth=0.9)
    q_e, r_e = trail[-1, 0:4], trail[-1, 4:7]
    draw_triad(axes, VIEW, attitude_matrix(q_e).T, r_e, length, labels=("x", "y", "z"))
    axes.plot(*path[-1], "o", color="black", markersize=4)
    axes.plot(0.0, 0.0, "s", color="0.4", markersize=5)
    axes.set_title("chaser (solid) and leader frame (dashed)", fontsize=8)
    attitude_deg = np.degrees(quat_angle(q_e))
    chi = float(np.linalg.norm(trail[-1, 7:10]))
    axes.text(
        0.02, 0.02, f"|Φ| = {attitude_deg:.3g}°   |χ| = {chi:.3g} m   scale ±{extent:.3g} m",
        transform=axes.transAxes, fontsize=8,
    )  # fmt: skip


PICTURE = SystemPicture(snapshot=snapshot, draw=draw)

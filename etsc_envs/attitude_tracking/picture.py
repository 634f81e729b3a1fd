"""The system in a frame of ``etsc/AttitudeTracking-v0``: the body axes against the reference.

Both frames are drawn from the inertial origin in an oblique view: the desired frame R_d of
the reference motion (dashed, eq. (3)'s q_d) and the body frame B (solid, the plant's q), with
the unit sphere's outline and the trail of the body axes' tips through the episode's frames.
The angle of q_e = q_d* ⊗ q (eq. 4) is written beside them.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.gridspec import SubplotSpec
from matplotlib.patches import Circle

from etsc_envs.attitude_tracking.closed_loop import PLANT
from etsc_envs.core.render import AXIS_COLORS, SystemPicture, bare_axes, draw_triad, view_matrix
from etsc_envs.core.rotations import attitude_matrix, error_quaternion, quat_angle

VIEW = view_matrix(azimuth_deg=35.0, elevation_deg=20.0)


def snapshot(env: Any) -> np.ndarray:
    """``[q (4), q_d (4)]`` at the current instant."""
    plant = env.state[PLANT]
    return np.concatenate([plant[0:4], plant[7:11]])


def draw(env: Any, figure: Figure, region: SubplotSpec, trail: np.ndarray) -> None:
    """The reference frame (dashed) and the body frame (solid), the tips' trails."""
    axes = figure.add_subplot(region)
    bare_axes(axes, 1.3)
    axes.add_patch(Circle((0.0, 0.0), 1.0, fill=False, color="0.75", linewidth=0.8))
    tips = np.stack([attitude_matrix(q).T for q in trail[:, 0:4]])  # B → inertial, per frame
    for column, color in enumerate(AXIS_COLORS):
        path = tips[:, :, column] @ VIEW[:2].T
        axes.plot(path[:, 0], path[:, 1], color=color, linewidth=0.7, alpha=0.35)
    q, q_d = trail[-1, 0:4], trail[-1, 4:8]
    origin = np.zeros(3)
    draw_triad(
        axes, VIEW, attitude_matrix(q_d).T, origin, 1.0, linestyle="--", linewidth=1.4,
        alpha=0.55,
    )  # fmt: skip
    draw_triad(axes, VIEW, tips[-1], origin, 1.0, labels=("x", "y", "z"))
    error_deg = np.degrees(quat_angle(error_quaternion(q, q_d)))
    axes.set_title("body axes (solid) vs reference (dashed)", fontsize=8)
    axes.text(0.02, 0.02, f"attitude error {error_deg:.2f}°", transform=axes.transAxes, fontsize=8)


PICTURE = SystemPicture(snapshot=snapshot, draw=draw)

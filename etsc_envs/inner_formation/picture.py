"""The system in a frame of ``etsc/InnerFormation-v0``: the inner test mass in its cavity.

Left, the cavity of radius R (``cavity_radius_m``) at true scale seen along z, with the inner
mass's centre r (paper 004's relative position r_12, eq. 1) and its trail through the
episode's frames. Right, a zoom of the same view centred on the mass, showing what the
event-triggered loop works with: where the measurement each axis's observer last received,
r(t_k), lies from r (held since that axis's last event; eqs. (4)-(6) send when an axis's gap
passes Π_i) and where the observer's estimate ζ (eq. 3) lies, at the current instant.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.gridspec import SubplotSpec
from matplotlib.patches import Circle

from etsc_envs.core.render import SystemPicture, bare_axes
from etsc_envs.inner_formation.closed_loop import LOOP

ZOOM_STEPS_UM = (1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1e3, 2e3, 5e3, 1e4, 1e5)
"""Half-widths of the zoom (µm): the smallest that holds the three points with a margin."""


def snapshot(env: Any) -> np.ndarray:
    """``[r (3), ζ (3), r(t_k) (3)]`` at the current instant (m)."""
    loop = env.state[LOOP]
    return np.concatenate([loop[0:3], loop[6:9], env.held[:, 0]])


def draw(env: Any, figure: Figure, region: SubplotSpec, trail: np.ndarray) -> None:
    """The cavity with the mass and its trail; the zoom on r with r(t_k) and ζ (x-y plane)."""
    radius_mm = 1e3 * env.params.cavity_radius_m
    mm = 1e3 * trail
    cavity_axes, zoom_axes = (figure.add_subplot(cell) for cell in region.subgridspec(1, 2))
    bare_axes(cavity_axes, 1.08 * radius_mm)
    cavity_axes.add_patch(Circle((0, 0), radius_mm, facecolor="0.93", edgecolor="0.3"))
    cavity_axes.plot(mm[:, 0], mm[:, 1], color="0.45", linewidth=0.8)
    cavity_axes.plot(*mm[-1, 0:2], "o", color="black", markersize=5)
    cavity_axes.set_title(f"cavity, R = {radius_mm:g} mm (x-y)", fontsize=8)
    offset_mm = float(np.linalg.norm(mm[-1, 0:3]))
    cavity_axes.text(0.0, -0.12, f"|r| = {offset_mm:.3g} mm", transform=cavity_axes.transAxes,
                     fontsize=8)  # fmt: skip

    um = 1e3 * mm[-1].reshape(3, 3)[:, 0:2]  # rows: r, ζ, r(t_k) in the x-y plane, µm
    offsets = um - um[0]  # the zoom is centred on the mass
    reach = 1.3 * float(np.abs(offsets).max())
    half = next((step for step in ZOOM_STEPS_UM if step >= reach), ZOOM_STEPS_UM[-1])
    bare_axes(zoom_axes, half)
    zoom_axes.axhline(0.0, color="0.85", linewidth=0.6)
    zoom_axes.axvline(0.0, color="0.85", linewidth=0.6)
    zoom_axes.plot(0.0, 0.0, "o", color="black", markersize=6, label="r")
    zoom_axes.plot(*offsets[2], "s", markerfacecolor="none", color="#ff7f0e", markersize=8,
                   markeredgewidth=1.5, label="r(t_k), held")  # fmt: skip
    zoom_axes.plot(*offsets[1], "x", color="#17becf", markersize=8, markeredgewidth=1.5,
                   label="ζ, estimate")  # fmt: skip
    zoom_axes.set_title(f"around the mass, ±{half:g} µm", fontsize=8)
    zoom_axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.02), fontsize=7, ncol=1,
                     frameon=False)  # fmt: skip


PICTURE = SystemPicture(snapshot=snapshot, draw=draw)

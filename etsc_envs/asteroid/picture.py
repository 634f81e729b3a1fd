"""The system in a frame of ``etsc/AsteroidOrbitKeeping-v0``: the asteroid, the orbit and the
safe shell.

Above, the scene in the inertial frame I seen face-on to the configured orbit plane (it holds
the spin axis z): the asteroid's shape turned by its spin ω_T t (C_AI of eq. 1), its facets lit
by the Sun; the safe shell r_0 ± ``shell_half_width_m`` that paper 003's barrier eq. (15)
keeps the orbit in (green), the reference circle r_0 (dashed) and the operating region's
bounds (dotted); the spacecraft's trail through the episode's frames and the spacecraft
(an orange star while a thrust burst of eqs. (16)-(17) fires). Below, ‖r‖ - r_0 over the
episode against the shell, where a 5-m band on a 200-m orbit becomes visible: its value now
(a dot) and the least and greatest it has been since the reset (lines, from every sampling
period of the loop; the radius oscillates between bursts faster than frames are usually
drawn, so the frames' own values would alias).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.gridspec import SubplotSpec
from matplotlib.patches import Annulus, Circle

from etsc_envs.asteroid.closed_loop import MAX_RADIUS, MIN_RADIUS, PLANT
from etsc_envs.asteroid.dynamics import R, inertial_to_asteroid
from etsc_envs.core.render import SystemPicture, bare_axes

SHELL_COLOR = "#2ca02c"
BURST_COLOR = "#ff7f0e"


def snapshot(env: Any) -> np.ndarray:
    """``[t, r in I (3), burst firing (0/1), least ‖r‖, greatest ‖r‖]`` at the current
    instant (the extremes since the reset)."""
    t = env.time_s
    state = env.state
    position = inertial_to_asteroid(t, env.model.spin_rate).T @ state[PLANT][R]
    extremes = (state[MIN_RADIUS], state[MAX_RADIUS])
    return np.array([t, *position, float(env.burst_active()), *extremes])


def orbit_view(azimuth_deg: float) -> np.ndarray:
    """Rows: screen right (the orbit plane's node at ``azimuth_deg``), screen up (the spin
    axis z) and the plane's normal, towards the viewer."""
    azimuth = np.radians(azimuth_deg)
    node = np.array([np.cos(azimuth), np.sin(azimuth), 0.0])
    pole = np.array([0.0, 0.0, 1.0])
    return np.stack([node, pole, np.cross(node, pole)])


def draw(env: Any, figure: Figure, region: SubplotSpec, trail: np.ndarray) -> None:
    """The lit asteroid, shell, orbit trail and spacecraft; the radius strip below."""
    p = env.params
    scene_cell, radius_cell = region.subgridspec(2, 1, height_ratios=[3.2, 1], hspace=0.3)
    axes = figure.add_subplot(scene_cell)
    view = orbit_view(p.orbit_plane_azimuth_deg)
    t = trail[-1, 0]
    shape = env.body.shape
    vertices = shape.vertices @ inertial_to_asteroid(t, env.model.spin_rate)  # rows in I
    extent = 1.05 * max(p.operating_region_m[1], float(np.linalg.norm(vertices, axis=1).max()))
    bare_axes(axes, extent)
    _draw_body(axes, vertices[shape.faces], view, env.model.sun_inertial)
    r0, half = p.reference_radius_m, p.shell_half_width_m
    axes.add_patch(Annulus((0, 0), r0 + half, 2 * half, color=SHELL_COLOR, alpha=0.45, lw=0))
    axes.add_patch(Circle((0, 0), r0, fill=False, color=SHELL_COLOR, linestyle="--", lw=0.6))
    for bound in p.operating_region_m:
        axes.add_patch(Circle((0, 0), bound, fill=False, color="0.6", linestyle=":", lw=0.8))
    path = trail[:, 1:4] @ view[:2].T
    axes.plot(*path.T, color="black", linewidth=0.9)
    firing = trail[-1, 4] > 0.0
    axes.plot(*path[-1], "*" if firing else "o", color=BURST_COLOR if firing else "black",
              markersize=11 if firing else 5)  # fmt: skip
    axes.set_title("asteroid, orbit and safe shell (orbit plane, inertial)", fontsize=8)

    strip = figure.add_subplot(radius_cell)
    error = float(np.linalg.norm(trail[-1, 1:4])) - r0
    lowest, highest = trail[:, 5] - r0, trail[:, 6] - r0
    strip.axhspan(-half, half, color=SHELL_COLOR, alpha=0.3, lw=0)
    for extreme in (lowest, highest):
        strip.step(trail[:, 0], extreme, where="post", color="black", linewidth=0.8)
    strip.plot(trail[-1, 0], error, "o", color="black", markersize=4)
    reach = max(1.6 * half, 1.1 * float(max(-lowest.min(), highest.max())))
    strip.set_ylim(-reach, reach)
    strip.set_xlim(0.0, env.horizon_s)
    strip.set_ylabel("|r| - r0 (m)", fontsize=7)
    strip.set_title("now (dot), least and greatest so far (lines)", fontsize=7)
    strip.tick_params(labelsize=7)


def _draw_body(axes: Any, facets: np.ndarray, view: np.ndarray, sun: np.ndarray) -> None:
    """The facets facing the viewer, far ones first, grey by their lighting from ``sun``."""
    normals = np.cross(facets[:, 1] - facets[:, 0], facets[:, 2] - facets[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    visible = normals @ view[2] > 0.0
    facets, normals = facets[visible], normals[visible]
    order = np.argsort(facets.mean(axis=1) @ view[2])
    light = np.clip(normals[order] @ sun, 0.0, 1.0)
    shade = (0.3 + 0.55 * light)[:, None] * np.ones(3)
    polygons = facets[order] @ view[:2].T
    axes.add_collection(
        PolyCollection(list(polygons), facecolors=shade, edgecolors=shade, linewidths=0.3)
    )


PICTURE = SystemPicture(snapshot=snapshot, draw=draw)

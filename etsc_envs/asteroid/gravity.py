"""Polyhedral gravity of a homogeneous asteroid (Werner & Scheeres 1997), eqs. (2)-(6) of paper 003.

For a field point x, with r_i = v_i - x the vector from x to vertex i:

* edge factor (eq. 4): L_e = ln[(|r_a| + |r_b| + e) / (|r_a| + |r_b| - e)] for the edge a-b of
  length e, and edge dyad (eq. 2) E_e = n_A n_A,eᵀ + n_B n_B,eᵀ from the two facets' outward
  normals n and outward in-plane edge normals n_e;
* facet factor (eq. 5): the signed solid angle ω_f = 2 atan2(r_1·(r_2×r_3),
  |r_1||r_2||r_3| + |r_1| r_2·r_3 + |r_2| r_3·r_1 + |r_3| r_1·r_2) and dyad (eq. 3) F_f = n_f n_fᵀ;
* potential U = ½Gρ(Σ_e L_e r_eᵀE_e r_e - Σ_f ω_f r_fᵀF_f r_f), attraction g = ∇U =
  -Gρ Σ_e L_e E_e r_e + Gρ Σ_f ω_f F_f r_f (eq. 6), gradient tensor ∇∇U = Gρ Σ_e L_e E_e -
  Gρ Σ_f ω_f F_f, whose trace -Gρ Σ_f ω_f is 0 outside and -4πGρ inside the body.

Eq. (6) of the paper writes g with the opposite overall sign convention of r_e, r_f; the code
uses the form above (vectors from the field point, g pointing toward the body) and
``atan2`` so that solid angles seen from inside the body are right (the arctan of eq. (5) is
only correct while the denominator is positive).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import prange

from etsc_envs.asteroid.shape import ShapeModel
from etsc_envs.core.jit import jit, parallel_jit

GRAVITATIONAL_CONSTANT = 6.6743e-11
"""G of section 2, m³ kg⁻¹ s⁻²."""

Polyhedron = namedtuple(
    "Polyhedron",
    [
        "vertices",  # (V, 3) m
        "faces",  # (F, 3) vertex indices, counter-clockwise from outside
        "face_normals",  # (F, 3) outward unit normals n_f
        "edges",  # (E, 2) vertex indices a, b
        "edge_lengths",  # (E,) |v_b - v_a|
        "edge_dyads",  # (E, 3, 3) E_e of eq. (2)
        "face_centroids",  # (F, 3) centroids, for distance queries
        "face_radii",  # (F,) largest centroid-to-vertex distance of each facet
        "g_rho",  # G ρ, s⁻²
    ],
)
"""A shape with the per-edge and per-facet constants of eqs. (2)-(3) and its G ρ."""


def make_polyhedron(shape: ShapeModel, density_kg_m3: float) -> Polyhedron:
    """The constants of eqs. (2)-(3) for ``shape`` of homogeneous ``density_kg_m3``."""
    vertices, faces, edges = shape.vertices, shape.faces, shape.edges
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    normals = np.cross(b - a, c - a)
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    n_vertices = len(vertices)
    edge_row = {int(i) * n_vertices + int(j): row for row, (i, j) in enumerate(edges)}
    dyads = np.zeros((len(edges), 3, 3))
    for face, normal in zip(faces, normals, strict=True):
        for start, end in ((0, 1), (1, 2), (2, 0)):
            i, j = int(face[start]), int(face[end])
            direction = vertices[j] - vertices[i]
            edge_normal = np.cross(direction, normal)
            edge_normal /= np.linalg.norm(edge_normal)
            dyads[edge_row[min(i, j) * n_vertices + max(i, j)]] += np.outer(normal, edge_normal)
    lengths = np.linalg.norm(vertices[edges[:, 1]] - vertices[edges[:, 0]], axis=1)
    centroids = (a + b + c) / 3.0
    radii = np.max([np.linalg.norm(corner - centroids, axis=1) for corner in (a, b, c)], axis=0)
    return Polyhedron(
        vertices=np.ascontiguousarray(vertices),
        faces=np.ascontiguousarray(faces),
        face_normals=np.ascontiguousarray(normals),
        edges=np.ascontiguousarray(edges),
        edge_lengths=lengths,
        edge_dyads=dyads,
        face_centroids=centroids,
        face_radii=radii,
        g_rho=GRAVITATIONAL_CONSTANT * float(density_kg_m3),
    )


@jit
def _solid_angle(relative: np.ndarray, norms: np.ndarray, i: int, j: int, k: int) -> float:
    """ω_f of eq. (5) for the facet (i, j, k), from the vectors ``relative`` to the vertices."""
    x1, y1, z1 = relative[i, 0], relative[i, 1], relative[i, 2]
    x2, y2, z2 = relative[j, 0], relative[j, 1], relative[j, 2]
    x3, y3, z3 = relative[k, 0], relative[k, 1], relative[k, 2]
    triple = x1 * (y2 * z3 - z2 * y3) + y1 * (z2 * x3 - x2 * z3) + z1 * (x2 * y3 - y2 * x3)
    d1, d2, d3 = norms[i], norms[j], norms[k]
    denominator = (
        d1 * d2 * d3
        + d1 * (x2 * x3 + y2 * y3 + z2 * z3)
        + d2 * (x3 * x1 + y3 * y1 + z3 * z1)
        + d3 * (x1 * x2 + y1 * y2 + z1 * z2)
    )
    return 2.0 * np.arctan2(triple, denominator)


@jit
def _relative_vertices(point: np.ndarray, poly: Polyhedron):
    """Vectors r_i = v_i - x from ``point`` to every vertex, and their lengths."""
    relative = poly.vertices - point
    norms = np.sqrt(relative[:, 0] ** 2 + relative[:, 1] ** 2 + relative[:, 2] ** 2)
    return relative, norms


@jit
def solid_angle_sum(point: np.ndarray, poly: Polyhedron) -> float:
    """Σ_f ω_f seen from ``point``: 4π inside the body, 0 outside (2π on a facet)."""
    relative, norms = _relative_vertices(point, poly)
    total = 0.0
    for f in range(len(poly.faces)):
        total += _solid_angle(relative, norms, poly.faces[f, 0], poly.faces[f, 1], poly.faces[f, 2])
    return total


@jit
def is_inside(point: np.ndarray, poly: Polyhedron) -> bool:
    """Whether ``point`` lies inside the body (the solid angles sum to 4π, not 0)."""
    return abs(solid_angle_sum(point, poly)) > 2.0 * np.pi


@jit
def field(point: np.ndarray, poly: Polyhedron):
    """Potential U (m²/s²), attraction g = ∇U (m/s², eq. 6) and gradient tensor ∇∇U (s⁻²).

    Returns ``(U, g, gradient)``; valid inside and outside the body.
    """
    relative, norms = _relative_vertices(point, poly)
    potential = 0.0
    acceleration = np.zeros(3)
    gradient = np.zeros((3, 3))
    dyad_r = np.empty(3)
    for e in range(len(poly.edges)):
        a, b = poly.edges[e, 0], poly.edges[e, 1]
        span = norms[a] + norms[b]
        length = poly.edge_lengths[e]
        factor = np.log((span + length) / (span - length))
        dyad = poly.edge_dyads[e]
        for row in range(3):
            dyad_r[row] = (
                dyad[row, 0] * relative[a, 0]
                + dyad[row, 1] * relative[a, 1]
                + dyad[row, 2] * relative[a, 2]
            )
        for row in range(3):
            potential += factor * relative[a, row] * dyad_r[row]
            acceleration[row] -= factor * dyad_r[row]
            for column in range(3):
                gradient[row, column] += factor * dyad[row, column]
    for f in range(len(poly.faces)):
        i, j, k = poly.faces[f, 0], poly.faces[f, 1], poly.faces[f, 2]
        omega = _solid_angle(relative, norms, i, j, k)
        normal = poly.face_normals[f]
        height = (
            normal[0] * relative[i, 0] + normal[1] * relative[i, 1] + normal[2] * relative[i, 2]
        )
        potential -= omega * height * height
        for row in range(3):
            acceleration[row] += omega * height * normal[row]
            for column in range(3):
                gradient[row, column] -= omega * normal[row] * normal[column]
    g_rho = poly.g_rho
    return 0.5 * g_rho * potential, g_rho * acceleration, g_rho * gradient


@parallel_jit
def fields(points: np.ndarray, poly: Polyhedron):
    """:func:`field` at every row of ``points`` ``(N, 3)`` (parallel over points).

    Returns ``(U (N,), g (N, 3), gradient (N, 3, 3))``.
    """
    n = len(points)
    potentials = np.empty(n)
    accelerations = np.empty((n, 3))
    gradients = np.empty((n, 3, 3))
    for p in prange(n):
        potentials[p], accelerations[p], gradients[p] = field(points[p], poly)
    return potentials, accelerations, gradients


@jit
def _closest_on_triangle(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray):
    """Closest point to ``p`` on triangle abc (Ericson, Real-Time Collision Detection, 5.1.5)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = ab @ ap, ac @ ap
    if d1 <= 0.0 and d2 <= 0.0:
        return a
    bp = p - b
    d3, d4 = ab @ bp, ac @ bp
    if d3 >= 0.0 and d4 <= d3:
        return b
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        return a + d1 / (d1 - d3) * ab
    cp = p - c
    d5, d6 = ab @ cp, ac @ cp
    if d6 >= 0.0 and d5 <= d6:
        return c
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        return a + d2 / (d2 - d6) * ac
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b)
    denominator = 1.0 / (va + vb + vc)
    return a + ab * (vb * denominator) + ac * (vc * denominator)


@jit
def _squared_distance_to_face(point: np.ndarray, poly: Polyhedron, f: int) -> float:
    """Squared distance from ``point`` to facet ``f``."""
    i, j, k = poly.faces[f, 0], poly.faces[f, 1], poly.faces[f, 2]
    closest = _closest_on_triangle(point, poly.vertices[i], poly.vertices[j], poly.vertices[k])
    offset = point - closest
    return offset @ offset


@jit
def surface_distance(point: np.ndarray, poly: Polyhedron) -> float:
    """Signed distance from ``point`` to the surface: > 0 outside the body, < 0 inside.

    Facets whose bounding sphere is farther than the best distance so far are skipped.
    """
    offsets = poly.face_centroids - point
    centre_distances = np.sqrt(offsets[:, 0] ** 2 + offsets[:, 1] ** 2 + offsets[:, 2] ** 2)
    best = _squared_distance_to_face(point, poly, int(np.argmin(centre_distances)))
    for f in range(len(poly.faces)):
        lower = centre_distances[f] - poly.face_radii[f]
        if lower > 0.0 and lower * lower >= best:
            continue
        best = min(best, _squared_distance_to_face(point, poly, f))
    distance = np.sqrt(best)
    return -distance if is_inside(point, poly) else distance


@parallel_jit
def surface_distances(points: np.ndarray, poly: Polyhedron) -> np.ndarray:
    """:func:`surface_distance` at every row of ``points`` (parallel over points)."""
    out = np.empty(len(points))
    for p in prange(len(points)):
        out[p] = surface_distance(points[p], poly)
    return out

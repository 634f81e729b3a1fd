"""The polyhedral gravity field precomputed on a grid and interpolated (the hot path of eq. (1)).

Evaluating eqs. (2)-(6) costs a logarithm per edge and an arctangent per facet (about 0.25 ms
for 3688 facets), four times per RK4 step. The field is static in the body frame, so it is
computed once on the nodes of a Cartesian grid covering a spherical shell around the body and
interpolated with the tricubic Hermite interpolant of the potential (Lekien & Marsden 2005):

* every node stores U, ∇U = g and the mixed derivatives U_xy, U_xz, U_yz (exact, from the
  polyhedron's gradient tensor) and U_xyz (central differences of those);
* inside a cell the potential is the unique tricubic matching these 8 values at the 8 corners;
  the attraction is the exact gradient of that interpolant, so the interpolated field is
  conservative (the Jacobi integral of eq. (1) is conserved up to the integrator's error) and
  continuous across cells;
* nodes also store the signed distance to the surface, which screens collisions: a point whose
  interpolated distance exceeds √3 h is certainly outside the body, otherwise the exact
  solid-angle test decides.

Values are stored per unit Gρ, so one grid serves every density. A grid is identified by the
shape's fingerprint and its region and spacing; :func:`load_or_build` looks for it among the
package data, then in the user cache (``$ETSC_ENVS_CACHE`` or ``~/.cache/etsc_envs``), and
builds and caches it otherwise (tens of seconds for a 3688-facet shape).

``python -m etsc_envs.asteroid.gravity_grid`` rebuilds the packaged Itokawa grid and reports its
interpolation error against direct evaluation.
"""

from __future__ import annotations

import logging
import os
import time
from collections import namedtuple
from itertools import pairwise
from pathlib import Path

import numpy as np

from etsc_envs.asteroid.gravity import (
    GRAVITATIONAL_CONSTANT,
    Polyhedron,
    fields,
    is_inside,
    make_polyhedron,
    surface_distances,
)
from etsc_envs.asteroid.shape import ShapeModel
from etsc_envs.core.files import output_folder_argument
from etsc_envs.core.jit import jit

FORMAT_VERSION = 1
GRID_MARGIN_M = 2.0
"""The grid covers the shell widened by this on both sides, so that the RK4 stages of a step
that ends just outside the operating region still find data."""
STORAGE_DTYPE = np.float32
"""Node values are stored in single precision: a relative rounding of 6e-8, 100 times below the
interpolation error, for half the file size."""
PACKAGE_DATA = Path(__file__).parent / "data"
LOGGER = logging.getLogger(__name__)

GridField = namedtuple(
    "GridField",
    [
        "origin",  # (3,) position of node (0, 0, 0), m
        "spacing",  # h, m
        "node_index",  # (nx, ny, nz) int32: row of each node in node_data, -1 if not stored
        "node_data",  # (n, 8): U, U_x, U_y, U_z, U_xy, U_xz, U_yz, U_xyz per unit Gρ
        "node_distance",  # (n,) signed distance to the surface, m (> 0 outside)
        "g_rho",  # G ρ of the body, s⁻²
    ],
)
"""A gravity grid ready for the compiled interpolation."""


# --------------------------------------------------------------------------- geometry of the grid
def grid_layout(outer_radius_m: float, spacing_m: float) -> tuple[np.ndarray, tuple[int, int, int]]:
    """Origin and node counts of the cubic node lattice covering the ball of ``outer_radius_m``
    (plus the margin) with two spare nodes on each side (for the central differences)."""
    half = int(np.ceil((outer_radius_m + GRID_MARGIN_M) / spacing_m)) + 2
    origin = np.full(3, -half * spacing_m)
    nodes = 2 * half + 1
    return origin, (nodes, nodes, nodes)


def needed_cells(
    origin: np.ndarray, counts: tuple, spacing: float, inner: float, outer: float
) -> np.ndarray:
    """Boolean ``(nx-1, ny-1, nz-1)``: cells that meet the shell ``inner ≤ |x| ≤ outer``
    widened by :data:`GRID_MARGIN_M`."""
    inner, outer = inner - GRID_MARGIN_M, outer + GRID_MARGIN_M
    axes = [origin[i] + spacing * np.arange(counts[i] - 1) for i in range(3)]
    low = np.meshgrid(*axes, indexing="ij")
    nearest_sq = np.zeros(low[0].shape)
    farthest_sq = np.zeros(low[0].shape)
    for lower in low:
        upper = lower + spacing
        nearest = np.where(lower > 0.0, lower, np.where(upper < 0.0, -upper, 0.0))
        nearest_sq += nearest**2
        farthest_sq += np.maximum(np.abs(lower), np.abs(upper)) ** 2
    return (nearest_sq <= outer**2) & (farthest_sq >= inner**2)


def _dilate(mask: np.ndarray) -> np.ndarray:
    """``mask`` grown by one node along each axis (both directions)."""
    grown = mask.copy()
    for axis in range(3):
        forward = [slice(None)] * 3
        backward = [slice(None)] * 3
        forward[axis], backward[axis] = slice(1, None), slice(None, -1)
        grown[tuple(forward)] |= mask[tuple(backward)]
        grown[tuple(backward)] |= mask[tuple(forward)]
    return grown


def _corner_nodes(cells: np.ndarray) -> np.ndarray:
    """Boolean node mask of every corner of the marked cells."""
    nodes = np.zeros(tuple(n + 1 for n in cells.shape), dtype=bool)
    for di in (0, 1):
        for dj in (0, 1):
            for dk in (0, 1):
                ni, nj, nk = cells.shape
                nodes[di : di + ni, dj : dj + nj, dk : dk + nk] |= cells
    return nodes


# --------------------------------------------------------------------------- building
def build(
    shape: ShapeModel,
    inner_radius_m: float,
    outer_radius_m: float,
    spacing_m: float,
) -> dict[str, np.ndarray]:
    """Evaluate the polyhedral field per unit Gρ on every node the shell's cells need.

    Returns the arrays of the grid file (see :func:`save`).
    """
    origin, counts = grid_layout(outer_radius_m, spacing_m)
    cells = needed_cells(origin, counts, spacing_m, inner_radius_m, outer_radius_m)
    corners = _corner_nodes(cells)
    evaluated = _dilate(corners)
    flat = np.flatnonzero(evaluated)
    points = origin + spacing_m * np.column_stack(np.unravel_index(flat, counts))
    unit = make_polyhedron(shape, 1.0 / GRAVITATIONAL_CONSTANT)
    potential, acceleration, gradient = fields(points, unit)
    distance = surface_distances(points, unit)
    hessian = np.full((*counts, 3), np.nan)
    hessian.reshape(-1, 3)[flat] = gradient[:, [0, 0, 1], [1, 2, 2]]  # U_xy, U_xz, U_yz
    third = _mixed_third_derivative(hessian, spacing_m)
    index = np.full(counts, -1, dtype=np.int64)
    index.reshape(-1)[flat] = np.arange(len(flat))
    kept = index[corners]
    data = np.empty((len(kept), 8), dtype=STORAGE_DTYPE)
    data[:, 0] = potential[kept]
    data[:, 1:4] = acceleration[kept]
    data[:, 4:7] = gradient[kept][:, [0, 0, 1], [1, 2, 2]]
    data[:, 7] = third[corners]
    if not np.all(np.isfinite(data)):
        raise RuntimeError("gravity grid: non-finite field values (a node lies on an edge?)")
    return {
        "format_version": np.array(FORMAT_VERSION),
        "fingerprint": np.array(shape.fingerprint()),
        "origin": origin,
        "spacing_m": np.array(spacing_m),
        "counts": np.array(counts),
        "inner_radius_m": np.array(inner_radius_m),
        "outer_radius_m": np.array(outer_radius_m),
        "nodes": np.packbits(corners.reshape(-1)),
        "node_data": data,
        "node_distance": distance[kept].astype(STORAGE_DTYPE),
    }


def _mixed_third_derivative(hessian: np.ndarray, spacing: float) -> np.ndarray:
    """U_xyz at every node from central differences of U_xy (along z), U_xz (y) and U_yz (x),
    averaged; NaN where a neighbour is missing."""
    third = np.full(hessian.shape[:3], np.nan)
    inner = (slice(1, -1),) * 3
    estimates = []
    for component, axis in ((0, 2), (1, 1), (2, 0)):
        ahead = [slice(1, -1)] * 3
        behind = [slice(1, -1)] * 3
        ahead[axis], behind[axis] = slice(2, None), slice(None, -2)
        estimates.append(
            (hessian[(*ahead, component)] - hessian[(*behind, component)]) / (2.0 * spacing)
        )
    third[inner] = np.mean(estimates, axis=0)
    return third


# --------------------------------------------------------------------------- files and cache
def save(arrays: dict[str, np.ndarray], path: str | Path) -> Path:
    """Write a grid (as returned by :func:`build`) to a compressed ``.npz`` file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    # NumPy's stub types **arrays as if one could be its allow_pickle keyword.
    np.savez_compressed(path, **arrays)  # pyright: ignore[reportArgumentType]
    return path


def cache_directory() -> Path:
    """Where built grids are kept: ``$ETSC_ENVS_CACHE`` or ``~/.cache/etsc_envs``."""
    configured = os.environ.get("ETSC_ENVS_CACHE")
    return Path(configured) if configured else Path.home() / ".cache" / "etsc_envs"


def grid_file_name(shape: ShapeModel, inner: float, outer: float, spacing: float) -> str:
    """File name identifying the grid of ``shape`` over a shell at a spacing."""
    return (
        f"gravity_grid_{shape.fingerprint()}_{inner:g}_{outer:g}_{spacing:g}_v{FORMAT_VERSION}.npz"
    )


def to_grid_field(arrays: dict[str, np.ndarray], g_rho: float) -> GridField:
    """The compiled-side view of grid arrays for a body of ``g_rho`` = Gρ."""
    counts = tuple(int(c) for c in arrays["counts"])
    total = int(np.prod(counts))
    stored = np.unpackbits(arrays["nodes"], count=total).astype(bool)
    index = np.full(total, -1, dtype=np.int32)
    index[stored] = np.arange(int(stored.sum()), dtype=np.int32)
    return GridField(
        origin=np.asarray(arrays["origin"], dtype=float),
        spacing=float(arrays["spacing_m"]),
        node_index=index.reshape(counts),
        node_data=np.ascontiguousarray(arrays["node_data"], dtype=float),
        node_distance=np.ascontiguousarray(arrays["node_distance"], dtype=float),
        g_rho=float(g_rho),
    )


def load_or_build(
    shape: ShapeModel,
    g_rho: float,
    inner_radius_m: float,
    outer_radius_m: float,
    spacing_m: float,
) -> GridField:
    """The grid of ``shape`` over the shell, from the package data, the cache, or built now."""
    name = grid_file_name(shape, inner_radius_m, outer_radius_m, spacing_m)
    for folder in (PACKAGE_DATA, cache_directory()):
        path = folder / name
        if path.is_file():
            with np.load(path) as stored:
                arrays = dict(stored)
            if str(arrays["fingerprint"]) == shape.fingerprint():
                return to_grid_field(arrays, g_rho)
    origin, counts = grid_layout(outer_radius_m, spacing_m)
    cells = needed_cells(origin, counts, spacing_m, inner_radius_m, outer_radius_m)
    estimate = int(_dilate(_corner_nodes(cells)).sum())
    target = cache_directory() / name
    LOGGER.warning(
        "Computing the polyhedral gravity grid of %s (%d facets) on %d nodes, spacing %g m, "
        "shell %g-%g m; this runs once (about %.0f s) and is cached in %s",
        shape.name,
        len(shape.faces),
        estimate,
        spacing_m,
        inner_radius_m,
        outer_radius_m,
        estimate * len(shape.faces) * 1.2e-7,
        target,
    )
    arrays = build(shape, inner_radius_m, outer_radius_m, spacing_m)
    try:
        save(arrays, target)
    except OSError as error:
        LOGGER.warning("could not cache the gravity grid in %s: %s", target, error)
    return to_grid_field(arrays, g_rho)


# --------------------------------------------------------------------------- interpolation
@jit
def _hermite_basis(t: float, spacing: float):
    """Cubic Hermite weights on a cell of width ``spacing`` at fraction ``t``.

    Returns ``(w, dw)``, each ``(2, 2)``: ``w[corner, 0]`` multiplies the corner's value,
    ``w[corner, 1]`` its derivative; ``dw`` are the derivatives of ``w`` along the axis.
    """
    t2 = t * t
    t3 = t2 * t
    w = np.empty((2, 2))
    dw = np.empty((2, 2))
    w[0, 0] = 2.0 * t3 - 3.0 * t2 + 1.0
    w[1, 0] = -2.0 * t3 + 3.0 * t2
    w[0, 1] = (t3 - 2.0 * t2 + t) * spacing
    w[1, 1] = (t3 - t2) * spacing
    dw[0, 0] = (6.0 * t2 - 6.0 * t) / spacing
    dw[1, 0] = (-6.0 * t2 + 6.0 * t) / spacing
    dw[0, 1] = 3.0 * t2 - 4.0 * t + 1.0
    dw[1, 1] = 3.0 * t2 - 2.0 * t
    return w, dw


@jit
def _cell(point: np.ndarray, grid: GridField):
    """Lower-corner node indices of the cell holding ``point`` and the fractions inside it, or
    index -1 if the point is off the lattice."""
    index = np.empty(3, dtype=np.int64)
    fraction = np.empty(3)
    counts = grid.node_index.shape
    for axis in range(3):
        scaled = (point[axis] - grid.origin[axis]) / grid.spacing
        if not scaled >= 0.0 or scaled >= counts[axis] - 1:
            index[0] = -1
            return index, fraction
        index[axis] = int(scaled)
        fraction[axis] = scaled - index[axis]
    return index, fraction


@jit
def grid_potential_and_attraction(point: np.ndarray, grid: GridField):
    """Interpolated U (m²/s²) and g = ∇U (m/s²) at ``point``; NaN where the grid has no data."""
    acceleration = np.full(3, np.nan)
    index, fraction = _cell(point, grid)
    if index[0] < 0:
        return np.nan, acceleration
    wx, dwx = _hermite_basis(fraction[0], grid.spacing)
    wy, dwy = _hermite_basis(fraction[1], grid.spacing)
    wz, dwz = _hermite_basis(fraction[2], grid.spacing)
    potential = 0.0
    gx = gy = gz = 0.0
    for a in range(2):
        for b in range(2):
            for c in range(2):
                row = grid.node_index[index[0] + a, index[1] + b, index[2] + c]
                if row < 0:
                    return np.nan, acceleration
                d = grid.node_data[row]
                x0, x1, dx0, dx1 = wx[a, 0], wx[a, 1], dwx[a, 0], dwx[a, 1]
                y0, y1, dy0, dy1 = wy[b, 0], wy[b, 1], dwy[b, 0], dwy[b, 1]
                z0, z1, dz0, dz1 = wz[c, 0], wz[c, 1], dwz[c, 0], dwz[c, 1]
                # Σ over the 8 data of value·(x-weight)(y-weight)(z-weight), grouped by x.
                yz00 = d[0] * y0 * z0 + d[2] * y1 * z0 + d[3] * y0 * z1 + d[6] * y1 * z1
                yz10 = d[1] * y0 * z0 + d[4] * y1 * z0 + d[5] * y0 * z1 + d[7] * y1 * z1
                potential += x0 * yz00 + x1 * yz10
                gx += dx0 * yz00 + dx1 * yz10
                gy += x0 * (d[0] * dy0 * z0 + d[2] * dy1 * z0 + d[3] * dy0 * z1 + d[6] * dy1 * z1)
                gy += x1 * (d[1] * dy0 * z0 + d[4] * dy1 * z0 + d[5] * dy0 * z1 + d[7] * dy1 * z1)
                gz += x0 * (d[0] * y0 * dz0 + d[2] * y1 * dz0 + d[3] * y0 * dz1 + d[6] * y1 * dz1)
                gz += x1 * (d[1] * y0 * dz0 + d[4] * y1 * dz0 + d[5] * y0 * dz1 + d[7] * y1 * dz1)
    acceleration[0] = grid.g_rho * gx
    acceleration[1] = grid.g_rho * gy
    acceleration[2] = grid.g_rho * gz
    return grid.g_rho * potential, acceleration


@jit
def grid_clearance(point: np.ndarray, grid: GridField) -> float:
    """Trilinear interpolation of the signed surface distance (m), within √3 h of the truth;
    NaN off the grid."""
    index, fraction = _cell(point, grid)
    if index[0] < 0:
        return np.nan
    total = 0.0
    for a in range(2):
        for b in range(2):
            for c in range(2):
                row = grid.node_index[index[0] + a, index[1] + b, index[2] + c]
                if row < 0:
                    return np.nan
                weight = (
                    (fraction[0] if a else 1.0 - fraction[0])
                    * (fraction[1] if b else 1.0 - fraction[1])
                    * (fraction[2] if c else 1.0 - fraction[2])
                )
                total += weight * grid.node_distance[row]
    return total


@jit
def collides(point: np.ndarray, grid: GridField, poly: Polyhedron) -> bool:
    """Whether ``point`` is inside the body: decided by the grid's clearance when it is more than
    √3 h from the surface, by the exact solid-angle test otherwise."""
    clearance = grid_clearance(point, grid)
    margin = np.sqrt(3.0) * grid.spacing
    if clearance > margin:
        return False
    if clearance < -margin:
        return True
    return is_inside(point, poly)


# --------------------------------------------------------------------------- accuracy and CLI
CLEARANCE_BANDS_M = (0.0, 5.0, 10.0, 20.0, 40.0, np.inf)
"""Height bands of the error report; the cell-diagonal height √3 h is added to them (above it,
no cell holding the point reaches the surface)."""


def interpolation_error(
    shape: ShapeModel,
    grid: GridField,
    inner_radius_m: float,
    outer_radius_m: float,
    n_points: int = 4000,
    seed: int = 0,
) -> list[dict[str, float]]:
    """Relative error ‖g_grid - g_direct‖ / ‖g_direct‖ at random points of the shell outside the
    body (uniform in volume), grouped by height above the surface.

    Returns one record per band of :data:`CLEARANCE_BANDS_M` (plus √3 h): ``low_m``,
    ``high_m``, ``points``, ``max``, ``p99`` and ``median`` of the relative error (bands without
    points are omitted).
    """
    rng = np.random.default_rng(seed)
    directions = rng.normal(size=(n_points, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    radii = rng.uniform(inner_radius_m**3, outer_radius_m**3, n_points) ** (1.0 / 3.0)
    points = directions * radii[:, None]
    poly = make_polyhedron(shape, grid.g_rho / GRAVITATIONAL_CONSTANT)
    _, direct, _ = fields(points, poly)
    heights = surface_distances(points, poly)
    interpolated = np.array([grid_potential_and_attraction(p, grid)[1] for p in points])
    error = np.linalg.norm(interpolated - direct, axis=1) / np.linalg.norm(direct, axis=1)
    report = []
    bands = sorted({*CLEARANCE_BANDS_M, round(np.sqrt(3.0) * grid.spacing, 1)})
    for low, high in pairwise(bands):
        band = (heights > low) & (heights <= high)
        if band.any():
            report.append(
                {
                    "low_m": float(low),
                    "high_m": float(high),
                    "points": int(band.sum()),
                    "max": float(error[band].max()),
                    "p99": float(np.percentile(error[band], 99)),
                    "median": float(np.median(error[band])),
                }
            )
    return report


def main(argv: list[str] | None = None) -> int:
    import argparse

    from etsc_envs.asteroid.params import AsteroidParams
    from etsc_envs.asteroid.shape import itokawa_shape, read_shape, write_obj

    defaults = AsteroidParams()
    parser = argparse.ArgumentParser(
        prog="python -m etsc_envs.asteroid.gravity_grid",
        description="Regenerate the packaged Itokawa shape and gravity grid, and measure the "
        "grid's interpolation error against direct polyhedral evaluation.",
    )
    parser.add_argument(
        "--out",
        default=str(PACKAGE_DATA),
        type=output_folder_argument("--out"),
        help="destination folder",
    )
    parser.add_argument("--points", type=int, default=4000, help="random points for the error")
    args = parser.parse_args(argv)
    folder = Path(args.out)
    inner, outer = defaults.operating_region_m
    spacing = defaults.grid_spacing_m
    shape_path = write_obj(itokawa_shape(), folder / "itokawa.obj")
    shape = read_shape(shape_path)
    started = time.perf_counter()
    arrays = build(shape, inner, outer, spacing)
    grid_path = save(arrays, folder / grid_file_name(shape, inner, outer, spacing))
    print(
        f"{grid_path}: {len(arrays['node_data'])} nodes, spacing {spacing:g} m, shell "
        f"{inner:g}-{outer:g} m, built in {time.perf_counter() - started:.0f} s, "
        f"{grid_path.stat().st_size / 1e6:.2f} MB"
    )
    density = defaults.asteroid_mass_kg / shape.volume_m3
    grid = to_grid_field(arrays, GRAVITATIONAL_CONSTANT * density)
    print("relative error of the interpolated attraction, by height above the surface:")
    for band in interpolation_error(shape, grid, inner, outer, args.points):
        print(
            f"  ({band['low_m']:g}, {band['high_m']:g}] m: {band['points']:5d} points, "
            f"max {band['max']:.2e}, 99th percentile {band['p99']:.2e}, "
            f"median {band['median']:.2e}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Polyhedral gravity, gravity grid and shape models of paper 003 (:mod:`etsc_envs.asteroid`).

Checked properties:

* the polyhedral field (eqs. 2-6) of a triangulated box equals the closed-form potential and
  attraction of a homogeneous rectangular prism (Nagy 1966; checked against quadrature while
  writing this test) to 1e-10 relative, outside and inside the box;
* the facets' solid angles (eq. 5) sum to 4π inside and 0 outside; for the Itokawa shape the
  fraction of random box points found inside matches its volume;
* the Laplacian of the potential, taken as a finite-difference divergence of g, is 0 outside
  and -4πGρ inside; g is the finite-difference gradient of U and the gradient tensor that of g;
* far from Itokawa the attraction tends to G M / r² along -r̂, its relative deviation falling
  like r⁻² (like r⁻⁴ for a cube, whose quadrupole vanishes);
* the signed surface distance of a box matches the analytic one;
* the packaged gravity grid: its node values are the direct field at the nodes (so it belongs
  to the packaged shape), its interpolated attraction is within 1e-4 of the direct one wherever
  the point's cell lies outside the body, it is the exact gradient of the interpolated potential
  (a conservative field) and continuous across cells; a grid for a small shape is built, cached
  and found again;
* the packaged shape is what :func:`itokawa_shape` generates from the published figures
  (1846 vertices, 3688 facets, 5532 edges, 535 × 294 × 209 m, 1.84e7 m³, principal axes);
* OBJ, PLY (ASCII and binary) and both PDS ``.tab`` layouts read back the same mesh, and
  malformed files raise :class:`ShapeFileError` saying what is wrong.
"""

from __future__ import annotations

import struct

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from etsc_envs.asteroid import gravity_grid
from etsc_envs.asteroid.body import PACKAGED_SHAPE, asteroid_body, packaged_itokawa
from etsc_envs.asteroid.gravity import (
    GRAVITATIONAL_CONSTANT,
    field,
    fields,
    make_polyhedron,
    solid_angle_sum,
    surface_distance,
    surface_distances,
)
from etsc_envs.asteroid.shape import (
    ShapeFileError,
    ShapeModel,
    convex_hull_faces,
    itokawa_shape,
    read_shape,
    write_obj,
)

DENSITY = 2000.0
G_RHO = GRAVITATIONAL_CONSTANT * DENSITY
ITOKAWA_MASS = 3.58e10
BOX_LOW = np.array([-30.0, -20.0, -15.0]) + np.array([5.0, -3.0, 2.0])
BOX_HIGH = np.array([30.0, 20.0, 15.0]) + np.array([5.0, -3.0, 2.0])


# --------------------------------------------------------------------------- helpers
def box_shape(low: np.ndarray = BOX_LOW, high: np.ndarray = BOX_HIGH) -> ShapeModel:
    """The box [low, high] as 12 triangles."""
    corners = np.array(
        [[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])]
    )
    centre = 0.5 * (low + high)
    return ShapeModel(corners, convex_hull_faces(corners - centre), "box")


def _corner_sum(function, low: np.ndarray, high: np.ndarray) -> float:
    """Σ ± f at the 8 corners: the definite triple 'upper minus lower' in x, y and z."""
    total = 0.0
    for i, x in enumerate((low[0], high[0])):
        for j, y in enumerate((low[1], high[1])):
            for k, z in enumerate((low[2], high[2])):
                total += (-1) ** (i + j + k + 1) * function(x, y, z)
    return total


def prism_field(point: np.ndarray, low: np.ndarray, high: np.ndarray):
    """Potential ∫ Gρ/r dV and attraction ∫ Gρ (x' - x)/r³ dV of the homogeneous box (Nagy)."""
    lo, hi = low - point, high - point

    def potential(x, y, z):
        r = np.sqrt(x * x + y * y + z * z)
        return (
            x * y * np.log(z + r)
            + y * z * np.log(x + r)
            + z * x * np.log(y + r)
            - 0.5 * x * x * np.arctan(y * z / (x * r))
            - 0.5 * y * y * np.arctan(z * x / (y * r))
            - 0.5 * z * z * np.arctan(x * y / (z * r))
        )

    def attraction_z(x, y, z):
        r = np.sqrt(x * x + y * y + z * z)
        return -(x * np.log(y + r) + y * np.log(x + r) - z * np.arctan(x * y / (z * r)))

    g = np.empty(3)
    for axis in range(3):
        order = [(axis + 1) % 3, (axis + 2) % 3, axis]  # the axis plays the role of z
        g[axis] = _corner_sum(
            lambda a, b, c, order=order: attraction_z(a, b, c), lo[order], hi[order]
        )
    return G_RHO * _corner_sum(potential, lo, hi), G_RHO * g


def random_directions(n: int, seed: int) -> np.ndarray:
    directions = np.random.default_rng(seed).normal(size=(n, 3))
    return directions / np.linalg.norm(directions, axis=1)[:, None]


@pytest.fixture(scope="module")
def itokawa():
    shape = packaged_itokawa()
    density = ITOKAWA_MASS / shape.volume_m3
    return shape, make_polyhedron(shape, density)


@pytest.fixture(scope="module")
def packaged_body():
    return asteroid_body(packaged_itokawa(), ITOKAWA_MASS, (170.0, 230.0), 8.0)


# --------------------------------------------------------------------------- polyhedral field
@pytest.mark.parametrize(
    "point",
    [(80.0, 31.0, -17.0), (-64.0, -52.0, 43.0), (6.0, 21.0, 40.0), (11.0, -7.0, 4.0)],
    ids=["outside", "outside-far", "above-face", "inside"],
)
def test_box_field_matches_the_closed_form_prism(point):
    point = np.array(point)
    poly = make_polyhedron(box_shape(), DENSITY)
    potential, attraction, _ = field(point, poly)
    expected_potential, expected_attraction = prism_field(point, BOX_LOW, BOX_HIGH)
    assert_allclose(potential, expected_potential, rtol=1e-10)
    assert_allclose(attraction, expected_attraction, rtol=1e-10, atol=1e-10 * G_RHO)
    assert np.linalg.norm(expected_attraction) > 1e-3 * G_RHO  # not a trivially small field


def test_solid_angles_sum_to_four_pi_inside_and_zero_outside(itokawa):
    poly = make_polyhedron(box_shape(), DENSITY)
    rng = np.random.default_rng(3)
    inside = rng.uniform(BOX_LOW + 0.5, BOX_HIGH - 0.5, size=(50, 3))
    outside = 0.5 * (BOX_LOW + BOX_HIGH) + 60.0 * random_directions(50, 4)
    for point in inside:
        assert_allclose(solid_angle_sum(point, poly), 4.0 * np.pi, rtol=1e-12)
    for point in outside:
        assert abs(solid_angle_sum(point, poly)) < 1e-12
    # Itokawa: every sum is 0 or 4π, and the share of 4π-points is the volume fraction.
    shape, body = itokawa
    low, high = shape.vertices.min(axis=0), shape.vertices.max(axis=0)
    points = rng.uniform(low, high, size=(2000, 3))
    sums = np.array([solid_angle_sum(p, body) for p in points])
    assert np.all(np.isclose(sums, 0.0, atol=1e-9) | np.isclose(sums, 4.0 * np.pi, atol=1e-9))
    fraction = np.mean(sums > 2.0 * np.pi)
    expected = shape.volume_m3 / np.prod(high - low)
    assert abs(fraction - expected) < 4.0 * np.sqrt(expected * (1 - expected) / len(points))


def _divergence(poly, point: np.ndarray, step: float) -> float:
    total = 0.0
    for axis in range(3):
        offset = np.zeros(3)
        offset[axis] = step
        total += (field(point + offset, poly)[1][axis] - field(point - offset, poly)[1][axis]) / (
            2.0 * step
        )
    return total


def test_laplacian_is_zero_outside_and_minus_four_pi_g_rho_inside(itokawa):
    _, poly = itokawa
    for point in 200.0 * random_directions(6, 5):
        if surface_distance(point, poly) < 10.0:
            continue
        tensor_scale = np.linalg.norm(field(point, poly)[2])
        assert abs(_divergence(poly, point, 0.05)) < 1e-6 * tensor_scale
    for point in ([0.0, 0.0, 0.0], [-120.0, 30.0, 10.0], [150.0, -20.0, 5.0]):
        point = np.array(point)
        assert surface_distance(point, poly) < -10.0
        assert_allclose(_divergence(poly, point, 0.05), -4.0 * np.pi * poly.g_rho, rtol=1e-6)


def test_attraction_and_tensor_are_derivatives_of_the_potential(itokawa):
    _, poly = itokawa
    step = 0.01
    for point in (np.array([30.0, 190.0, 40.0]), np.array([-150.0, -60.0, 110.0])):
        potential, attraction, tensor = field(point, poly)
        for axis in range(3):
            offset = np.zeros(3)
            offset[axis] = step
            ahead, behind = field(point + offset, poly), field(point - offset, poly)
            assert_allclose((ahead[0] - behind[0]) / (2 * step), attraction[axis], rtol=1e-7)
            assert_allclose(
                (ahead[1] - behind[1]) / (2 * step),
                tensor[:, axis],
                rtol=1e-6,
                atol=1e-7 * np.abs(tensor).max(),
            )
        assert_allclose(tensor, tensor.T, atol=1e-12 * np.abs(tensor).max())
        assert potential > 0.0 and attraction @ point < 0.0  # U > 0, g points inward


def test_far_field_tends_to_a_point_mass(itokawa):
    _, poly = itokawa
    gm = GRAVITATIONAL_CONSTANT * ITOKAWA_MASS
    directions = random_directions(8, 6)
    deviations = {}
    for radius in (5e3, 10e3, 20e3):
        _, attraction, _ = fields(radius * directions, poly)
        magnitude = np.linalg.norm(attraction, axis=1)
        deviations[radius] = np.abs(magnitude / (gm / radius**2) - 1.0).max()
        cosines = -np.einsum("ij,ij->i", attraction, directions) / magnitude
        assert np.all(cosines > 1.0 - 1e-5)
    assert deviations[20e3] < 1e-4
    ratio = deviations[10e3] / deviations[20e3]
    assert 3.5 < ratio < 4.5  # quadrupole: deviation ∝ r⁻²
    cube = make_polyhedron(box_shape(np.full(3, -50.0), np.full(3, 50.0)), DENSITY)
    cube_gm = G_RHO * 100.0**3
    point = np.array([0.6, 0.48, 0.64])
    near, far = (np.linalg.norm(field(d * point, cube)[1]) * d**2 / cube_gm - 1 for d in (1e3, 2e3))
    assert 12.0 < near / far < 20.0  # cubic symmetry: no quadrupole, deviation ∝ r⁻⁴


def test_signed_surface_distance_of_a_box():
    poly = make_polyhedron(box_shape(), DENSITY)
    rng = np.random.default_rng(7)
    centre, half = 0.5 * (BOX_LOW + BOX_HIGH), 0.5 * (BOX_HIGH - BOX_LOW)
    points = centre + rng.uniform(-2.0, 2.0, size=(200, 3)) * half
    offsets = np.abs(points - centre) - half
    outside = np.linalg.norm(np.maximum(offsets, 0.0), axis=1)
    expected = np.where(outside > 0.0, outside, offsets.max(axis=1))
    assert_allclose(surface_distances(points, poly), expected, atol=1e-9)
    assert (expected < 0).sum() > 10 and (expected > 0).sum() > 10


# --------------------------------------------------------------------------- gravity grid
def test_packaged_grid_nodes_are_the_direct_field(packaged_body, itokawa):
    _, poly = itokawa
    grid = packaged_body.grid
    stored = np.argwhere(grid.node_index >= 0)
    chosen = stored[np.random.default_rng(8).choice(len(stored), 40, replace=False)]
    points = grid.origin + grid.spacing * chosen
    potential, attraction, tensor = fields(points, poly)
    rows = grid.node_index[tuple(chosen.T)]
    data = grid.node_data[rows] * grid.g_rho
    assert_allclose(data[:, 0], potential, rtol=1e-6)
    scale = np.linalg.norm(attraction, axis=1)[:, None]
    assert np.abs(data[:, 1:4] - attraction).max(axis=1).max() < 1e-6 * scale.max()
    mixed = tensor[:, [0, 0, 1], [1, 2, 2]]
    assert np.abs(data[:, 4:7] - mixed).max() < 1e-6 * np.abs(tensor).max()
    distances = surface_distances(points, poly)
    assert_allclose(grid.node_distance[rows], distances, atol=1e-4)


def test_packaged_grid_interpolates_within_1e_minus_4(packaged_body, itokawa):
    _, poly = itokawa
    grid = packaged_body.grid
    rng = np.random.default_rng(9)
    radii = rng.uniform(172.0, 228.0, 400)
    points = random_directions(400, 10) * radii[:, None]
    heights = surface_distances(points, poly)
    clear = heights > np.sqrt(3.0) * grid.spacing
    _, direct, _ = fields(points[clear], poly)
    interpolated = np.array(
        [gravity_grid.grid_potential_and_attraction(p, grid)[1] for p in points[clear]]
    )
    error = np.linalg.norm(interpolated - direct, axis=1) / np.linalg.norm(direct, axis=1)
    assert clear.sum() > 250
    assert error.max() < 1e-4
    clearance = np.array([gravity_grid.grid_clearance(p, grid) for p in points])
    assert np.abs(clearance - heights).max() < np.sqrt(3.0) * grid.spacing


def test_interpolated_field_is_conservative_and_continuous(packaged_body):
    grid = packaged_body.grid
    step = 1e-3
    for point in (np.array([13.0, -190.0, 71.0]), np.array([-90.0, 120.0, -140.0])):
        _, attraction = gravity_grid.grid_potential_and_attraction(point, grid)
        for axis in range(3):
            offset = np.zeros(3)
            offset[axis] = step
            ahead = gravity_grid.grid_potential_and_attraction(point + offset, grid)[0]
            behind = gravity_grid.grid_potential_and_attraction(point - offset, grid)[0]
            assert_allclose((ahead - behind) / (2 * step), attraction[axis], rtol=1e-7)
    # Across a cell face (a node plane) U and g agree on both sides.
    node_plane = grid.origin[0] + grid.spacing * 20
    for side in (np.array([node_plane, 150.0, 130.0]),):
        nudge = np.array([1e-9, 0.0, 0.0])
        left = gravity_grid.grid_potential_and_attraction(side - nudge, grid)
        right = gravity_grid.grid_potential_and_attraction(side + nudge, grid)
        assert_allclose(left[0], right[0], rtol=1e-10)
        assert_allclose(left[1], right[1], rtol=1e-8)
    off_grid = gravity_grid.grid_potential_and_attraction(np.array([0.0, 0.0, 400.0]), grid)
    assert np.isnan(off_grid[0]) and np.all(np.isnan(off_grid[1]))


def test_grid_of_a_small_shape_is_built_cached_and_reused(tmp_path, monkeypatch):
    monkeypatch.setenv("ETSC_ENVS_CACHE", str(tmp_path))
    shape = itokawa_shape(n_vertices=50)
    g_rho = GRAVITATIONAL_CONSTANT * ITOKAWA_MASS / shape.volume_m3
    grid = gravity_grid.load_or_build(shape, g_rho, 300.0, 330.0, 10.0)
    cached = list(tmp_path.glob("gravity_grid_*.npz"))
    assert len(cached) == 1 and shape.fingerprint() in cached[0].name

    def no_build(*args, **kwargs):
        raise AssertionError("the cached grid should have been used")

    monkeypatch.setattr(gravity_grid, "build", no_build)
    again = gravity_grid.load_or_build(shape, g_rho, 300.0, 330.0, 10.0)
    assert_array_equal(again.node_data, grid.node_data)
    poly = make_polyhedron(shape, g_rho / GRAVITATIONAL_CONSTANT)
    point = np.array([120.0, -250.0, 130.0])
    _, direct, _ = field(point, poly)
    _, interpolated = gravity_grid.grid_potential_and_attraction(point, grid)
    assert_allclose(interpolated, direct, rtol=1e-4)


# --------------------------------------------------------------------------- the shape
def test_packaged_shape_is_generated_from_the_published_figures():
    generated = itokawa_shape()
    shipped = read_shape(PACKAGED_SHAPE)
    assert_array_equal(shipped.faces, generated.faces)
    assert_allclose(shipped.vertices, generated.vertices, atol=1e-8)
    assert (len(generated.vertices), len(generated.faces), len(generated.edges)) == (
        1846,
        3688,
        5532,
    )
    assert_allclose(generated.extents_m, [535.0, 294.0, 209.0], rtol=1e-9)
    assert_allclose(generated.volume_m3, 1.84e7, rtol=1e-9)
    assert np.linalg.norm(generated.centroid_m) < 1e-9
    inertia = generated.inertia_per_density()
    off_diagonal = inertia - np.diag(np.diag(inertia))
    assert np.abs(off_diagonal).max() < 1e-9 * np.abs(inertia).max()
    assert inertia[0, 0] < inertia[1, 1] < inertia[2, 2]  # x long axis, z spin axis


# --------------------------------------------------------------------------- file readers
TETRA_VERTICES = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
TETRA_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
SMALL = itokawa_shape(n_vertices=40)


def _obj_text(faces: np.ndarray = TETRA_FACES, vertices: np.ndarray = TETRA_VERTICES) -> str:
    lines = [f"v {x} {y} {z}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    return "\n".join(lines) + "\n"


def _ply_bytes(binary: bool) -> bytes:
    header = [
        "ply",
        "format " + ("binary_little_endian 1.0" if binary else "ascii 1.0"),
        "element vertex 4",
        "property float x",
        "property float y",
        "property float z",
        "element face 4",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    head = ("\n".join(header) + "\n").encode()
    if binary:
        body = b"".join(struct.pack("<3f", *v) for v in TETRA_VERTICES)
        body += b"".join(struct.pack("<B3i", 3, *f) for f in TETRA_FACES)
        return head + body
    rows = [" ".join(str(c) for c in v) for v in TETRA_VERTICES]
    rows += ["3 " + " ".join(str(i) for i in f) for f in TETRA_FACES]
    return head + ("\n".join(rows) + "\n").encode()


def _plate_tab(vertex_count: int = 4, plate_count: int = 4) -> str:
    lines = [str(vertex_count)]
    lines += [
        f"{i + 1} {x / 1000} {y / 1000} {z / 1000}" for i, (x, y, z) in enumerate(TETRA_VERTICES)
    ]
    lines += [str(plate_count)]
    lines += [f"{i + 1} {a + 1} {b + 1} {c + 1}" for i, (a, b, c) in enumerate(TETRA_FACES)]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("kind", ["obj", "ply-ascii", "ply-binary", "tab-plates", "tab-vf"])
def test_readers_return_the_same_mesh(tmp_path, kind):
    path = tmp_path / {"obj": "m.obj", "tab-plates": "m.tab", "tab-vf": "m.tab"}.get(kind, "m.ply")
    if kind == "obj":
        path.write_text(_obj_text())
    elif kind.startswith("ply"):
        path.write_bytes(_ply_bytes(binary=kind == "ply-binary"))
    elif kind == "tab-plates":
        path.write_text(_plate_tab())
    else:
        lines = _obj_text().splitlines()
        path.write_text(
            "\n".join(
                f"{line.split()[0]} "
                + " ".join(
                    str(float(t) / 1000) if line.startswith("v") else t for t in line.split()[1:]
                )
                for line in lines
            )
            + "\n"
        )
    shape = read_shape(path)
    assert_allclose(shape.vertices, TETRA_VERTICES, atol=1e-6)
    assert_allclose(shape.volume_m3, 1.0 / 6.0, rtol=1e-6)


def test_obj_round_trip_and_inward_meshes_are_flipped(tmp_path):
    shape = itokawa_shape(n_vertices=40)
    again = read_shape(write_obj(shape, tmp_path / "shape.obj"))
    assert_allclose(again.vertices, shape.vertices, atol=1e-8)
    assert_array_equal(again.faces, shape.faces)
    inward = ShapeModel(TETRA_VERTICES, TETRA_FACES[:, ::-1], "inward")
    assert inward.volume_m3 > 0.0
    assert_array_equal(inward.faces, TETRA_FACES)


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("m.obj", _obj_text().replace("v 1.0", "v one"), "line 2"),
        ("m.obj", _obj_text().replace("f 1 3 2", "f 0 3 2"), "start at 1"),
        ("m.obj", _obj_text().replace("f 1 3 2", "f 1 3 9"), "out of range"),
        ("m.obj", _obj_text(SMALL.faces[1:], SMALL.vertices), "not closed"),
        ("m.obj", _obj_text(np.vstack([TETRA_FACES[:3], TETRA_FACES[3:, ::-1]])), "oriented"),
        ("m.obj", _obj_text().replace("f 1 3 2", "f 1 1 2"), "repeats a vertex"),
        ("m.obj", "# nothing here\n", "no 'v' vertex"),
        ("m.stl", "solid x\n", "unknown shape format"),
        ("m.tab", _plate_tab(vertex_count=5), "expected 'index a b c', got '4'"),
        ("m.tab", _plate_tab(plate_count=5), "only 4 lines follow"),
        ("m.tab", _plate_tab().replace("\n1 1 3 2", "\n1 0 3 2"), "start at 1"),
        ("m.ply", _ply_bytes(binary=True)[:-7].decode("latin-1"), "ends before"),
        ("m.ply", "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n", "'face' elements"),
    ],
    ids=[
        "obj-number",
        "obj-zero-index",
        "obj-index-range",
        "open-surface",
        "flipped-facet",
        "degenerate-facet",
        "obj-empty",
        "unknown-format",
        "tab-vertex-count",
        "tab-plate-count",
        "tab-zero-index",
        "ply-truncated",
        "ply-no-faces",
    ],
)
def test_malformed_shape_files_raise_clear_errors(tmp_path, name, content, message):
    path = tmp_path / name
    path.write_bytes(content.encode("latin-1"))
    with pytest.raises(ShapeFileError, match=message):
        read_shape(path)


def test_missing_shape_file_and_bad_unit(tmp_path):
    with pytest.raises(ShapeFileError, match="not found"):
        read_shape(tmp_path / "absent.obj")
    path = tmp_path / "m.obj"
    path.write_text(_obj_text())
    with pytest.raises(ValueError, match="length_unit_m"):
        read_shape(path, length_unit_m=-1.0)

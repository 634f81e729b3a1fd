"""Asteroid shape models: a closed triangle mesh, the project's Itokawa shape, and file readers.

Paper 003 evaluates the polyhedral gravity of eqs. (2)-(6) on a 3688-facet Itokawa model (its
Fig. 2: 3688 facets, 1846 vertices, 5532 edges). That model is not redistributable, so the suite
generates its own shape from Itokawa's published figures (:func:`itokawa_shape`) with exactly the
paper's facet, vertex and edge counts, and reads a user's own model from OBJ, PLY or the PDS
``.tab`` vertex/facet formats (:func:`read_shape`).

A :class:`ShapeModel` is validated on construction: a closed, consistently oriented triangle
surface (every edge shared by exactly two facets traversed in opposite directions), with facets
counter-clockwise seen from outside (a consistently inward mesh is flipped). Coordinates are
metres in the asteroid's body frame, whose z axis is the spin axis of eq. (1).

``python -m etsc_envs.asteroid.shape --out itokawa.obj`` writes the generated shape.
"""

from __future__ import annotations

import argparse
import gzip
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import brentq
from scipy.spatial import ConvexHull

from etsc_envs.core.files import atomic_write_text, output_file_argument

ITOKAWA_EXTENTS_M = (535.0, 294.0, 209.0)
"""Itokawa's overall dimensions along its long, intermediate and short axes (Fujiwara et al.,
Science 312, 1330, 2006)."""
ITOKAWA_VOLUME_M3 = 1.84e7
"""Itokawa's volume (Fujiwara et al. 2006)."""
PAPER_VERTEX_COUNT = 1846
"""Vertices of the paper's model (Fig. 2); a closed triangulated sphere with V vertices has
2V - 4 = 3688 facets and 3V - 6 = 5532 edges, the paper's counts."""

# The generated shape: a large "body" lobe and a smaller "head" lobe along x (Itokawa's
# sea-otter outline), each a superellipsoid |x/a|^p + |y/b|^p + |z/c|^p = 1, joined by a smooth
# maximum of their radial distances seen from a point inside both. Only the proportions matter:
# the mesh is then scaled to ITOKAWA_EXTENTS_M and p is solved for ITOKAWA_VOLUME_M3.
_BODY_LOBE = ((-95.0, 0.0, 0.0), (175.0, 147.0, 104.5))
_HEAD_LOBE = ((160.0, 0.0, 0.0), (110.0, 115.0, 85.0))
_STAR_CENTRE = (65.0, 0.0, 0.0)
_SMOOTH_MAX_POWER = 10.0
_DIRECTION_WARP = (2.0, 1.2, 1.0)
_RADIAL_BISECTIONS = 60


class ShapeFileError(ValueError):
    """A shape file or mesh that cannot describe a closed asteroid surface (says where and why)."""


@dataclass(frozen=True, eq=False)
class ShapeModel:
    """A closed triangle surface in the asteroid body frame.

    Args:
        vertices: ``(V, 3)`` vertex coordinates, m.
        faces: ``(F, 3)`` vertex indices of each triangular facet.
        name: where the shape came from (file name or generator), used in messages.
    """

    vertices: np.ndarray
    faces: np.ndarray
    name: str = "shape"
    edges: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        vertices, faces, edges = _validated_mesh(self.vertices, self.faces, self.name)
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)
        object.__setattr__(self, "edges", edges)

    @property
    def volume_m3(self) -> float:
        """Enclosed volume (sum of the signed tetrahedra from the origin)."""
        return float(_signed_tetra_volumes(self.vertices, self.faces).sum())

    @property
    def centroid_m(self) -> np.ndarray:
        """Centre of volume, the centre of mass of a homogeneous body."""
        a, b, c = (self.vertices[self.faces[:, i]] for i in range(3))
        weights = _signed_tetra_volumes(self.vertices, self.faces)
        return (weights[:, None] * (a + b + c)).sum(axis=0) / (4.0 * weights.sum())

    @property
    def extents_m(self) -> np.ndarray:
        """Size of the axis-aligned bounding box along x, y, z."""
        return self.vertices.max(axis=0) - self.vertices.min(axis=0)

    @property
    def max_radius_m(self) -> float:
        """Largest distance of a vertex from the origin (the Brillouin sphere's radius)."""
        return float(np.sqrt((self.vertices**2).sum(axis=1)).max())

    def inertia_per_density(self) -> np.ndarray:
        """Inertia tensor about the origin of the homogeneous body of unit density (m⁵)."""
        a, b, c = (self.vertices[self.faces[:, i]] for i in range(3))
        det = 6.0 * _signed_tetra_volumes(self.vertices, self.faces)
        second = np.zeros((3, 3))
        for i in range(3):
            for j in range(3):
                squares = a[:, i] * a[:, j] + b[:, i] * b[:, j] + c[:, i] * c[:, j]
                sums = (a[:, i] + b[:, i] + c[:, i]) * (a[:, j] + b[:, j] + c[:, j])
                second[i, j] = (det * (squares + sums)).sum() / 120.0
        return np.trace(second) * np.eye(3) - second

    def centred(self) -> ShapeModel:
        """The same surface translated so that its centre of mass is the origin."""
        return ShapeModel(self.vertices - self.centroid_m, self.faces, self.name)

    def scaled(self, factors: np.ndarray | float) -> ShapeModel:
        """The surface with each coordinate multiplied by ``factors`` (one or three numbers)."""
        return ShapeModel(self.vertices * np.asarray(factors, dtype=float), self.faces, self.name)

    def fingerprint(self) -> str:
        """A short hash of the vertex coordinates and facets (identifies cached gravity grids)."""
        import hashlib

        digest = hashlib.sha256()
        digest.update(np.ascontiguousarray(self.vertices, dtype="<f8").tobytes())
        digest.update(np.ascontiguousarray(self.faces, dtype="<i8").tobytes())
        return digest.hexdigest()[:16]


# --------------------------------------------------------------------------- validation
def _signed_tetra_volumes(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0


def _validated_mesh(
    vertices: np.ndarray, faces: np.ndarray, name: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices, outward faces and unique edges ``(E, 2)``, or :class:`ShapeFileError`."""
    vertices = np.array(vertices, dtype=float)
    faces_in = np.asarray(faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) < 4:
        raise ShapeFileError(f"{name}: vertices must be (V >= 4, 3), got shape {vertices.shape}")
    if not np.all(np.isfinite(vertices)):
        raise ShapeFileError(f"{name}: vertex coordinates must be finite")
    if faces_in.ndim != 2 or faces_in.shape[1] != 3 or len(faces_in) < 4:
        raise ShapeFileError(f"{name}: facets must be (F >= 4, 3), got shape {faces_in.shape}")
    if not np.issubdtype(faces_in.dtype, np.integer):
        raise ShapeFileError(f"{name}: facet vertex indices must be integers")
    faces = faces_in.astype(np.int64)
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise ShapeFileError(
            f"{name}: facet vertex index out of range [0, {len(vertices) - 1}] "
            f"(found {faces.min()}..{faces.max()})"
        )
    repeated = (
        (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    )
    if repeated.any():
        raise ShapeFileError(
            f"{name}: facet {int(np.flatnonzero(repeated)[0])} repeats a vertex (degenerate)"
        )
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    areas = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    scale = np.ptp(vertices, axis=0).max()
    if areas.min() <= 1e-12 * scale**2:
        raise ShapeFileError(
            f"{name}: facet {int(np.argmin(areas))} has zero area (collinear vertices)"
        )
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    keys = directed[:, 0] * len(vertices) + directed[:, 1]
    unique_keys, counts = np.unique(keys, return_counts=True)
    if counts.max() > 1:
        key = unique_keys[np.argmax(counts)]
        raise ShapeFileError(
            f"{name}: edge {key // len(vertices)}->{key % len(vertices)} is traversed twice in "
            "the same direction: facets are not consistently oriented or an edge is shared by "
            "more than two facets"
        )
    reverse = directed[:, 1] * len(vertices) + directed[:, 0]
    unmatched = ~np.isin(reverse, unique_keys)
    if unmatched.any():
        i, j = directed[np.flatnonzero(unmatched)[0]]
        raise ShapeFileError(
            f"{name}: the surface is not closed ({int(unmatched.sum())} edges belong to one "
            f"facet only, e.g. {i}-{j}); a gravity model needs a watertight shape"
        )
    if _signed_tetra_volumes(vertices, faces).sum() < 0.0:
        faces = faces[:, ::-1].copy()
    forward = directed[:, 0] < directed[:, 1]
    edges = directed[forward]
    return vertices, faces, edges


# --------------------------------------------------------------------------- generation
def fibonacci_directions(n: int) -> np.ndarray:
    """``n`` nearly uniform unit vectors on the golden-angle (Fibonacci) spiral."""
    index = np.arange(n) + 0.5
    z = 1.0 - 2.0 * index / n
    azimuth = np.pi * (1.0 + np.sqrt(5.0)) * index
    ring = np.sqrt(1.0 - z * z)
    return np.column_stack([ring * np.cos(azimuth), ring * np.sin(azimuth), z])


def convex_hull_faces(points: np.ndarray) -> np.ndarray:
    """Outward facets of the convex hull of ``points`` around the origin (for unit vectors, a
    closed triangulation of the sphere)."""
    faces = ConvexHull(points).simplices.astype(np.int64)
    a, b, c = (points[faces[:, i]] for i in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a) < 0.0
    faces[inward] = faces[inward][:, ::-1]
    return faces


def superellipsoid_ray_distance(
    directions: np.ndarray, centre: np.ndarray, semi_axes: np.ndarray, exponent: float
) -> np.ndarray:
    """Distance from the origin along each unit ``direction`` to the surface of the convex
    superellipsoid ``Σ |(x - centre)_i / semi_axes_i|^exponent = 1``, which contains the origin.
    """
    lower = np.zeros(len(directions))
    upper = np.full(len(directions), 2.0 * (np.abs(centre).max() + semi_axes.max()))
    for _ in range(_RADIAL_BISECTIONS):
        middle = 0.5 * (lower + upper)
        level = (np.abs((middle[:, None] * directions - centre) / semi_axes) ** exponent).sum(1)
        outside = level > 1.0
        upper = np.where(outside, middle, upper)
        lower = np.where(outside, lower, middle)
    return 0.5 * (lower + upper)


def _principal_axes(shape: ShapeModel) -> ShapeModel:
    """``shape`` (centred) rotated so that x, y, z are its principal axes of least, middle and
    largest inertia, with the farther tip of the long axis on +x."""
    _, axes = np.linalg.eigh(shape.inertia_per_density())
    if np.linalg.det(axes) < 0.0:
        axes[:, 2] *= -1.0
    vertices = shape.vertices @ axes
    if vertices[:, 0].max() < -vertices[:, 0].min():
        vertices[:, :2] *= -1.0
    return ShapeModel(vertices, shape.faces, shape.name)


def _two_lobe_shape(exponent: float, n_vertices: int) -> ShapeModel:
    """The two-lobe surface at ``exponent``, centred, on principal axes, scaled to the extents."""
    warp = np.array(_DIRECTION_WARP)
    directions = fibonacci_directions(n_vertices) * warp
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    faces = convex_hull_faces(directions)
    star = np.array(_STAR_CENTRE)
    power = _SMOOTH_MAX_POWER
    distances = [
        superellipsoid_ray_distance(directions, np.array(c) - star, np.array(s), exponent)
        for c, s in (_BODY_LOBE, _HEAD_LOBE)
    ]
    radius = (distances[0] ** power + distances[1] ** power) ** (1.0 / power)
    shape = ShapeModel(star + directions * radius[:, None], faces, "itokawa-like")
    shape = _principal_axes(shape.centred())
    return shape.scaled(np.array(ITOKAWA_EXTENTS_M) / shape.extents_m).centred()


def itokawa_shape(n_vertices: int = PAPER_VERTEX_COUNT) -> ShapeModel:
    """The suite's Itokawa shape, generated from published figures only.

    A two-lobe ("body" and "head") superellipsoid outline is triangulated radially with
    ``n_vertices`` vertices (1846 gives the paper's 3688 facets and 5532 edges), centred on its
    centre of mass, rotated to its principal axes (x long, z spin = largest inertia), scaled to
    535 × 294 × 209 m, and its superellipsoid exponent is solved so that the volume is
    1.84e7 m³. The result is deterministic.
    """
    if n_vertices < 12:
        raise ValueError(f"n_vertices must be >= 12, got {n_vertices}")

    def volume_gap(exponent: float) -> float:
        return _two_lobe_shape(exponent, n_vertices).volume_m3 / ITOKAWA_VOLUME_M3 - 1.0

    exponent = brentq(volume_gap, 2.0, 4.0, xtol=1e-12)
    # SciPy types brentq's root as a union with its full_output=True result.
    shape = _two_lobe_shape(exponent, n_vertices)  # pyright: ignore[reportArgumentType]
    return ShapeModel(shape.vertices, shape.faces, f"itokawa-like ({len(shape.faces)} facets)")


# --------------------------------------------------------------------------- file readers
def read_shape(path: str | Path, length_unit_m: float | None = None) -> ShapeModel:
    """Read a closed triangle mesh from an OBJ, PLY (ASCII or binary) or PDS ``.tab`` file.

    Args:
        path: the file; ``.gz`` compression is accepted.
        length_unit_m: metres per file unit. Default: 1 for OBJ and PLY, 1000 for ``.tab``
            (PDS small-body shape models are in kilometres).

    Raises :class:`ShapeFileError` (a ``ValueError``) naming the file, the line and the problem.
    """
    path = Path(path)
    if not path.is_file():
        raise ShapeFileError(f"shape file not found: {path}")
    suffixes = [s.lower() for s in path.suffixes]
    if suffixes and suffixes[-1] == ".gz":
        suffixes = suffixes[:-1]
        raw = gzip.decompress(path.read_bytes())
    else:
        raw = path.read_bytes()
    kind = suffixes[-1] if suffixes else ""
    readers = {".obj": (_parse_obj, 1.0), ".ply": (_parse_ply, 1.0), ".tab": (_parse_tab, 1000.0)}
    if kind not in readers:
        raise ShapeFileError(f"{path}: unknown shape format {kind!r}; use .obj, .ply or .tab")
    parser, default_unit = readers[kind]
    unit = default_unit if length_unit_m is None else float(length_unit_m)
    if not np.isfinite(unit) or unit <= 0.0:
        raise ValueError(f"length_unit_m must be a finite number > 0, got {length_unit_m!r}")
    vertices, faces = parser(raw, path.name)
    return ShapeModel(np.asarray(vertices) * unit, np.asarray(faces, dtype=np.int64), path.name)


def _text_lines(raw: bytes, name: str) -> list[str]:
    try:
        return raw.decode("utf-8").splitlines()
    except UnicodeDecodeError as error:
        raise ShapeFileError(f"{name}: not a text file ({error})") from None


def _numbers(tokens: list[str], kind: type, name: str, line_number: int) -> list:
    try:
        return [kind(token) for token in tokens]
    except ValueError:
        raise ShapeFileError(
            f"{name}, line {line_number}: expected {kind.__name__} values, got {' '.join(tokens)!r}"
        ) from None


def _fan(polygon: list[int]) -> list[list[int]]:
    """Triangles of a polygon's fan from its first vertex."""
    return [[polygon[0], polygon[i], polygon[i + 1]] for i in range(1, len(polygon) - 1)]


def _parse_obj(raw: bytes, name: str) -> tuple[list, list]:
    """Wavefront OBJ: ``v x y z`` and ``f i j k ...`` (1-based, negative = relative, ``i/t/n``)."""
    vertices, faces = [], []
    for number, line in enumerate(_text_lines(raw, name), start=1):
        tokens = line.split("#", 1)[0].split()
        if not tokens:
            continue
        if tokens[0] == "v":
            if len(tokens) < 4:
                raise ShapeFileError(f"{name}, line {number}: a vertex needs x y z: {line!r}")
            vertices.append(_numbers(tokens[1:4], float, name, number))
        elif tokens[0] == "f":
            if len(tokens) < 4:
                raise ShapeFileError(f"{name}, line {number}: a facet needs 3 vertices: {line!r}")
            indices = _numbers([t.split("/")[0] for t in tokens[1:]], int, name, number)
            if 0 in indices:
                raise ShapeFileError(f"{name}, line {number}: OBJ vertex indices start at 1")
            polygon = [i - 1 if i > 0 else len(vertices) + i for i in indices]
            faces.extend(_fan(polygon))
    if not vertices or not faces:
        raise ShapeFileError(f"{name}: no 'v' vertex or 'f' facet lines found")
    return vertices, faces


_PLY_TYPES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B",
    "short": "h", "int16": "h", "ushort": "H", "uint16": "H",
    "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}  # fmt: skip


def _parse_ply(raw: bytes, name: str) -> tuple[list, list]:
    """Stanford PLY (ascii, binary_little_endian or binary_big_endian) with ``vertex`` x, y, z
    and ``face`` ``vertex_indices`` (or ``vertex_index``) list elements."""
    end = raw.find(b"end_header")
    if not raw.startswith(b"ply") or end < 0:
        raise ShapeFileError(f"{name}: not a PLY file (missing 'ply' magic or 'end_header')")
    header = raw[:end].decode("ascii", errors="replace").splitlines()
    body = raw[raw.index(b"\n", end) + 1 :]
    fmt, elements = None, []
    for number, line in enumerate(header, start=1):
        tokens = line.split()
        if not tokens:
            continue
        if tokens[0] == "format":
            fmt = tokens[1] if len(tokens) > 1 else None
        elif tokens[0] == "element":
            if len(tokens) != 3:
                raise ShapeFileError(f"{name}, header line {number}: bad element line {line!r}")
            elements.append((tokens[1], int(_numbers([tokens[2]], int, name, number)[0]), []))
        elif tokens[0] == "property":
            if not elements:
                raise ShapeFileError(f"{name}, header line {number}: property before element")
            prop = tokens[1:]
            types = prop[1:3] if prop[0] == "list" else prop[:1]
            if any(t not in _PLY_TYPES for t in types):
                raise ShapeFileError(f"{name}, header line {number}: unknown type in {line!r}")
            elements[-1][2].append(prop)
    formats = {"ascii": None, "binary_little_endian": "<", "binary_big_endian": ">"}
    if fmt not in formats:
        raise ShapeFileError(f"{name}: unsupported PLY format {fmt!r}")
    names = [e[0] for e in elements]
    if "vertex" not in names or "face" not in names:
        raise ShapeFileError(f"{name}: a PLY shape needs 'vertex' and 'face' elements")
    reader = _PlyAscii(body, name) if fmt == "ascii" else _PlyBinary(body, formats[fmt], name)
    vertices, faces = [], []
    for element, count, properties in elements:
        prop_names = [p[-1] for p in properties]
        if element == "vertex" and not {"x", "y", "z"} <= set(prop_names):
            raise ShapeFileError(f"{name}: PLY vertices need x, y and z properties")
        face_list = next((p for p in ("vertex_indices", "vertex_index") if p in prop_names), None)
        if element == "face" and face_list is None:
            raise ShapeFileError(f"{name}: PLY faces need a vertex_indices list property")
        for _ in range(count):
            record = {p[-1]: reader.read(p) for p in properties}
            if element == "vertex":
                vertices.append([record["x"], record["y"], record["z"]])
            elif element == "face":
                indices = record[face_list]
                if not isinstance(indices, list):
                    raise ShapeFileError(f"{name}: PLY face property {face_list!r} is not a list")
                polygon = [int(i) for i in indices]
                if len(polygon) < 3:
                    raise ShapeFileError(f"{name}: PLY face with {len(polygon)} vertices")
                faces.extend(_fan(polygon))
    return vertices, faces


class _PlyAscii:
    """Token reader for the body of an ASCII PLY file."""

    def __init__(self, body: bytes, name: str) -> None:
        self.tokens = body.decode("ascii", errors="replace").split()
        self.position = 0
        self.name = name

    def _next(self, kind: str) -> float | int:
        if self.position >= len(self.tokens):
            raise ShapeFileError(f"{self.name}: PLY body ends before all elements were read")
        token = self.tokens[self.position]
        self.position += 1
        try:
            return float(token) if _PLY_TYPES[kind] in "fd" else int(token)
        except ValueError:
            raise ShapeFileError(f"{self.name}: bad PLY value {token!r}") from None

    def read(self, prop: list[str]) -> float | int | list:
        if prop[0] == "list":
            return [self._next(prop[2]) for _ in range(int(self._next(prop[1])))]
        return self._next(prop[0])


class _PlyBinary:
    """Struct reader for the body of a binary PLY file."""

    def __init__(self, body: bytes, order: str, name: str) -> None:
        self.body, self.order, self.position, self.name = body, order, 0, name

    def _next(self, kind: str) -> float | int:
        code = self.order + _PLY_TYPES[kind]
        size = struct.calcsize(code)
        if self.position + size > len(self.body):
            raise ShapeFileError(f"{self.name}: PLY body ends before all elements were read")
        (value,) = struct.unpack_from(code, self.body, self.position)
        self.position += size
        return value

    def read(self, prop: list[str]) -> float | int | list:
        if prop[0] == "list":
            return [self._next(prop[2]) for _ in range(int(self._next(prop[1])))]
        return self._next(prop[0])


def _parse_tab(raw: bytes, name: str) -> tuple[list, list]:
    """PDS small-body shape ``.tab``, either with ``v x y z`` / ``f i j k`` lines (1-based, as
    OBJ), or the plate format: a vertex count, ``index x y z`` lines, a plate count and
    ``index i j k`` lines (1-based vertex indices)."""
    lines = [(n, line.split()) for n, line in enumerate(_text_lines(raw, name), start=1)]
    lines = [(n, tokens) for n, tokens in lines if tokens]
    if not lines:
        raise ShapeFileError(f"{name}: empty file")
    if lines[0][1][0].lower() in ("v", "f"):
        return _parse_obj(raw.lower(), name)
    position = 0

    def block(count_label: str, value_kind: type) -> list:
        nonlocal position
        if position >= len(lines):
            raise ShapeFileError(f"{name}: missing the {count_label} count line")
        number, tokens = lines[position]
        count = _numbers(tokens[:1], int, name, number)[0]
        if count <= 0:
            raise ShapeFileError(f"{name}, line {number}: {count_label} count must be > 0")
        rows = lines[position + 1 : position + 1 + count]
        if len(rows) < count:
            raise ShapeFileError(
                f"{name}: {count_label} count {count} on line {number}, but only {len(rows)} "
                "lines follow"
            )
        values = []
        for row_number, row in rows:
            if len(row) != 4:
                raise ShapeFileError(
                    f"{name}, line {row_number}: expected 'index a b c', got {' '.join(row)!r}"
                )
            values.append(_numbers(row[1:], value_kind, name, row_number))
        position += 1 + count
        return values

    vertices = block("vertex", float)
    plates = block("plate", int)
    if position != len(lines):
        raise ShapeFileError(f"{name}, line {lines[position][0]}: unexpected data after plates")
    if min(min(p) for p in plates) < 1:
        raise ShapeFileError(f"{name}: plate vertex indices start at 1")
    return vertices, [[i - 1 for i in plate] for plate in plates]


# --------------------------------------------------------------------------- writing
def write_obj(shape: ShapeModel, path: str | Path) -> Path:
    """Write ``shape`` as a Wavefront OBJ file (metres, 1-based facets)."""
    lines = [f"# {shape.name}: {len(shape.vertices)} vertices, {len(shape.faces)} facets, metres"]
    lines += [f"v {x:.9f} {y:.9f} {z:.9f}" for x, y, z in shape.vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in shape.faces]
    return atomic_write_text(path, "\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m etsc_envs.asteroid.shape",
        description="Write the suite's generated Itokawa shape as an OBJ file.",
    )
    parser.add_argument(
        "--out",
        required=True,
        type=output_file_argument("--out", stdout=False),
        help="destination .obj file",
    )
    parser.add_argument("--vertices", type=int, default=PAPER_VERTEX_COUNT)
    args = parser.parse_args(argv)
    shape = itokawa_shape(args.vertices)
    write_obj(shape, args.out)
    extents = " x ".join(f"{e:.1f}" for e in shape.extents_m)
    print(f"{args.out}: {shape.name}, {extents} m, volume {shape.volume_m3:.4g} m^3")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

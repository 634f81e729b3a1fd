"""The asteroid as the loop sees it: shape, polyhedron constants and gravity grid.

The suite's Itokawa shape ships as ``data/itokawa.obj`` (written by
``python -m etsc_envs.asteroid.gravity_grid``, which also writes its gravity grid next to it);
a user's shape comes from a file or a :class:`ShapeModel`. Bodies are cached per process, so
many environments share one grid.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from etsc_envs.asteroid.gravity import GRAVITATIONAL_CONSTANT, Polyhedron, make_polyhedron
from etsc_envs.asteroid.gravity_grid import PACKAGE_DATA, GridField, load_or_build
from etsc_envs.asteroid.shape import ShapeModel, read_shape
from etsc_envs.core.validation import require_positive

PACKAGED_SHAPE = PACKAGE_DATA / "itokawa.obj"
CENTRING_TOLERANCE_M = 1e-3
"""A shape whose centre of mass is farther than this from the origin is translated onto it
(eq. (1) is written about the asteroid's centre of mass)."""


@dataclass(frozen=True, eq=False)
class AsteroidBody:
    """A homogeneous polyhedral asteroid of given mass, with its gravity grid."""

    shape: ShapeModel
    density_kg_m3: float
    polyhedron: Polyhedron
    grid: GridField


@functools.lru_cache(maxsize=1)
def packaged_itokawa() -> ShapeModel:
    """The suite's generated Itokawa shape (3688 facets), as shipped with the package."""
    shape = read_shape(PACKAGED_SHAPE)
    return ShapeModel(shape.vertices, shape.faces, "itokawa-like (3688 facets)")


def resolve_shape(
    shape: str | Path | ShapeModel | None, length_unit_m: float | None = None
) -> ShapeModel:
    """The shape to use: the packaged Itokawa for ``None``, a file path, or a model, centred on
    its centre of mass when it is off the origin."""
    if length_unit_m is not None:
        require_positive("shape_length_unit_m", length_unit_m)
        if not isinstance(shape, str | Path):
            raise ValueError(
                "shape_length_unit_m applies only to a shape file (shape=PATH), "
                f"got shape={shape!r}"
            )
    if shape is None:
        model = packaged_itokawa()
    elif isinstance(shape, ShapeModel):
        model = shape
    elif isinstance(shape, str | Path):
        model = read_shape(shape, length_unit_m)
    else:
        raise ValueError(f"shape must be None, a file path or a ShapeModel, got {type(shape)}")
    if np.linalg.norm(model.centroid_m) > CENTRING_TOLERANCE_M:
        model = model.centred()
    return model


@functools.lru_cache(maxsize=8)
def _cached_body(
    shape: ShapeModel, mass_kg: float, region: tuple[float, float], spacing_m: float
) -> AsteroidBody:
    density = mass_kg / shape.volume_m3
    grid = load_or_build(shape, GRAVITATIONAL_CONSTANT * density, region[0], region[1], spacing_m)
    return AsteroidBody(shape, density, make_polyhedron(shape, density), grid)


def asteroid_body(
    shape: ShapeModel, mass_kg: float, region: tuple[float, float], spacing_m: float
) -> AsteroidBody:
    """The body of ``shape`` with total mass ``mass_kg`` (density M / V) and its gravity grid
    over ``region`` = (inner, outer) radii at ``spacing_m``."""
    if shape.volume_m3 <= 0.0:
        raise ValueError(f"{shape.name}: the shape must enclose a positive volume")
    return _cached_body(shape, float(mass_kg), (float(region[0]), float(region[1])), spacing_m)

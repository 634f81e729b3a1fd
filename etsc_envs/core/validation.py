"""Constructor-argument checks that raise ``ValueError`` naming the argument and what is allowed."""

from __future__ import annotations

import dataclasses
import numbers
from collections.abc import Iterable
from typing import Any

import numpy as np


def _real_number(name: str, value: float, allowed: str) -> float:
    """``value`` as a float, or ``ValueError`` if it is not a real number (a string, say)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(
            f"{name} must be a finite number {allowed}, got {value!r} ({type(value).__name__})"
        )
    return float(value)


def require_positive(name: str, value: float) -> float:
    """``value`` as a float, or ``ValueError`` unless it is a finite real number > 0."""
    value = _real_number(name, value, "> 0")
    if not np.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


def require_non_negative(name: str, value: float) -> float:
    """``value`` as a float, or ``ValueError`` unless it is a finite real number >= 0."""
    value = _real_number(name, value, ">= 0")
    if not np.isfinite(value) or value < 0.0:
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return value


def require_choice(name: str, value: str, choices: Iterable[str]) -> str:
    """``value``, or ``ValueError`` listing the allowed choices."""
    choices = tuple(choices)
    if value not in choices:
        raise ValueError(f"{name} must be one of {choices}, got {value!r}")
    return value


def require_vector(
    name: str, value: Iterable[float], length: int, *, positive: bool = False
) -> np.ndarray:
    """``value`` as a finite float64 vector of ``length`` entries (all > 0 if ``positive``)."""
    array = np.asarray(value, dtype=float)
    if array.shape != (length,) or not np.all(np.isfinite(array)):
        raise ValueError(
            f"{name} must be {length} finite numbers, got shape {array.shape}: {value!r}"
        )
    if positive and np.any(array <= 0.0):
        raise ValueError(f"{name} must have every entry > 0, got {value!r}")
    return array


def require_unit_quaternion(
    name: str, value: Iterable[float], tolerance: float = 1e-3
) -> np.ndarray:
    """``value`` normalised to unit length, or ``ValueError`` if its norm is off by > tolerance."""
    array = require_vector(name, value, 4)
    norm = float(np.linalg.norm(array))
    if abs(norm - 1.0) > tolerance:
        raise ValueError(
            f"{name} must be a unit quaternion (|q| = 1 ± {tolerance}), got |q| = {norm:.6g}"
        )
    return array / norm


def require_spd_matrix(name: str, value: Iterable[Iterable[float]]) -> np.ndarray:
    """``value`` as a symmetric positive-definite 3×3 matrix, or ``ValueError`` saying why not."""
    matrix = np.asarray(value, dtype=float)
    if matrix.shape != (3, 3) or not np.all(np.isfinite(matrix)):
        raise ValueError(f"{name} must be a finite 3x3 matrix, got shape {matrix.shape}")
    if not np.allclose(matrix, matrix.T, rtol=0.0, atol=1e-12 * max(1.0, np.abs(matrix).max())):
        raise ValueError(f"{name} must be symmetric, got {matrix.tolist()}")
    if np.linalg.eigvalsh(matrix).min() <= 0.0:
        raise ValueError(
            f"{name} must be positive definite, got eigenvalues {np.linalg.eigvalsh(matrix)}"
        )
    return matrix


def apply_overrides(params: Any, overrides: dict[str, Any], owner: str) -> Any:
    """``params`` (a frozen dataclass) with ``overrides`` applied field by field, validated again.

    Raises ``TypeError`` naming ``owner`` and the unknown keyword(s) if an override is not a field.
    """
    unknown = set(overrides) - {field.name for field in dataclasses.fields(params)}
    if unknown:
        raise TypeError(f"unknown argument(s) for {owner}: {sorted(unknown)}")
    return dataclasses.replace(params, **overrides)

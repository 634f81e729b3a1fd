"""Constructor-argument checks that raise ``ValueError`` naming the argument and what is allowed."""

from __future__ import annotations

import dataclasses
import numbers
from collections.abc import Iterable
from typing import Any, TypeVar

import numpy as np

Choice = TypeVar("Choice")


def _real_number(name: str, value: object, allowed: str) -> float:
    """``value`` as a float, or ``ValueError`` if it is not a real number (a string, say)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(
            f"{name} must be a finite number{' ' if allowed else ''}{allowed}, "
            f"got {value!r} ({type(value).__name__})"
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


def require_int_at_least(name: str, value: int, minimum: int) -> int:
    """``value`` as an ``int``, or ``ValueError`` unless it is an integer >= ``minimum`` (a
    ``bool`` or a float such as ``2.0`` is refused)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(
            f"{name} must be an integer >= {minimum}, got {value!r} ({type(value).__name__})"
        )
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def require_discount(name: str, value: float) -> float:
    """``value`` as a float, or ``ValueError`` unless it is a real number in (0, 1]."""
    value = _real_number(name, value, "in (0, 1]")
    if not 0.0 < value <= 1.0:
        raise ValueError(f"{name} must be a finite number in (0, 1], got {value!r}")
    return value


def require_rule_trigger(name: str, trigger: Any, n_channels: int) -> Any:
    """``trigger`` if it is a paper rule (a ``RuleTrigger``: compiled ``rule`` with
    ``rule_indices`` and ``rule_parameters``) writing ``n_channels`` transmit bits, else
    ``ValueError`` naming ``name``."""
    if getattr(trigger, "n_channels", None) != n_channels or not hasattr(trigger, "rule"):
        raise ValueError(
            f"{name} must be a paper rule (RuleTrigger) with {n_channels} transmit bit(s), "
            f"got {trigger!r}"
        )
    return trigger


def require_choice(name: str, value: Choice, choices: Iterable[Choice]) -> Choice:
    """``value``, or ``ValueError`` listing the allowed choices."""
    choices = tuple(choices)
    if value not in choices:
        raise ValueError(f"{name} must be one of {choices}, got {value!r}")
    return value


def require_bool(name: str, value: object) -> bool:
    """``value`` as a ``bool``, or ``ValueError`` unless it is ``True`` or ``False`` (a string
    such as ``"no"`` or a number is refused rather than read by its truth value)."""
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"{name} must be True or False, got {value!r} ({type(value).__name__})")
    return bool(value)


def require_float_array(name: str, value: Any) -> np.ndarray:
    """``value`` as a float64 array, or ``ValueError`` naming ``name`` if it is text or cannot
    be read as numbers (a ragged nesting, say)."""
    if isinstance(value, str | bytes):
        raise ValueError(f"{name} must be numbers, got the text {value!r}")
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numbers, got {value!r}") from None


def require_vector(
    name: str, value: Iterable[float], length: int, *, positive: bool = False
) -> np.ndarray:
    """``value`` as a finite float64 vector of ``length`` entries (all > 0 if ``positive``)."""
    array = require_float_array(name, value)
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
    matrix = require_float_array(name, value)
    if matrix.shape != (3, 3) or not np.all(np.isfinite(matrix)):
        raise ValueError(f"{name} must be a finite 3x3 matrix, got shape {matrix.shape}")
    if not np.allclose(matrix, matrix.T, rtol=0.0, atol=1e-12 * max(1.0, np.abs(matrix).max())):
        raise ValueError(f"{name} must be symmetric, got {matrix.tolist()}")
    eigenvalues = np.linalg.eigvalsh(matrix)
    if eigenvalues.min() <= 0.0:
        raise ValueError(f"{name} must be positive definite, got eigenvalues {eigenvalues}")
    log_determinant = float(np.sum(np.log(eigenvalues)))
    if not np.log(np.finfo(float).tiny) <= log_determinant <= np.log(np.finfo(float).max):
        raise ValueError(
            f"{name} must have a determinant inside float64's normal range (solving with it "
            f"divides by it), got eigenvalues {eigenvalues}"
        )
    if eigenvalues.max() > MAX_CONDITION_NUMBER * eigenvalues.min():
        raise ValueError(
            f"{name} must be well conditioned (largest / smallest eigenvalue <= "
            f"{MAX_CONDITION_NUMBER:g}), got eigenvalues {eigenvalues}"
        )
    return matrix


MAX_CONDITION_NUMBER = 1e8
"""The largest ratio of a matrix parameter's eigenvalues (an inertia): beyond it, solving with
the matrix in float64 loses more than half of its digits."""


def step_count(horizon_s: float, sampling_period_s: float) -> int:
    """The sampling instants in ``horizon_s``, or ``ValueError`` unless the horizon is a whole
    number of sampling periods (within a relative 1e-9, for decimal fractions)."""
    periods = horizon_s / sampling_period_s
    count = round(periods)
    if not 1 <= count <= MAX_STEPS or abs(periods - count) > 1e-9 * periods:
        raise ValueError(
            f"horizon_s must be a whole number of sampling periods ({sampling_period_s} s), "
            f"from 1 to {MAX_STEPS:.0e}, got {horizon_s} s = {periods:.6g} periods"
        )
    return count


MAX_STEPS = 10**12
"""The most sampling instants an episode may have: step counters are 64-bit integers in the
compiled loop (and a longer episode would not end in any time anyone waits for)."""


def require_reset_options(options: Any, allowed: Iterable[str] = ()) -> dict[str, Any]:
    """``options`` of ``reset()`` as a dict (``{}`` for ``None``), or ``ValueError`` if it is
    not a mapping or holds a key outside ``allowed``."""
    allowed = tuple(allowed)
    if options is None:
        return {}
    if not isinstance(options, dict):
        raise ValueError(
            f"options must be None or a dict with keys in {list(allowed)}, "
            f"got {options!r} ({type(options).__name__})"
        )
    unknown = sorted(str(key) for key in options if key not in allowed)
    if unknown:
        takes = f"takes only {list(allowed)}" if allowed else "takes no options"
        raise ValueError(f"options: unknown key(s) {unknown}; this environment's reset {takes}")
    return dict(options)


def _annotation_names(annotation: Any) -> set[str]:
    """The type names of a field annotation: a string under postponed evaluation, else a class
    (its name) or a union such as ``float | None`` (its text)."""
    text = annotation if isinstance(annotation, type | str) else str(annotation)
    text = text.__name__ if isinstance(text, type) else text
    return {part.strip() for part in str(text).split("|")}


def require_field_types(params: Any) -> None:
    """``ValueError`` naming the first field of the dataclass ``params`` whose value does not
    fit its annotation: ``bool`` fields take only ``True``/``False``, ``int`` and ``float``
    fields real numbers (not text, not bools), ``str`` fields text, ``tuple`` fields numbers
    (any nesting NumPy reads as a float array); ``| None`` admits ``None``. Range checks stay
    with each parameter class."""
    for field in dataclasses.fields(params):
        names = _annotation_names(field.type)
        value = getattr(params, field.name)
        if value is None and "None" in names:
            continue
        if "bool" in names:
            require_bool(field.name, value)
        elif "int" in names:
            if isinstance(value, bool) or not isinstance(value, numbers.Integral):
                raise ValueError(
                    f"{field.name} must be an integer, got {value!r} ({type(value).__name__})"
                )
        elif "float" in names:
            _real_number(field.name, value, "")
        elif "str" in names:
            if not isinstance(value, str):
                raise ValueError(
                    f"{field.name} must be a string, got {value!r} ({type(value).__name__})"
                )
        elif "tuple" in names:
            require_float_array(field.name, value)


def apply_overrides(params_class: type, params: Any, overrides: dict[str, Any], owner: str) -> Any:
    """``params`` (a frozen dataclass of ``params_class``; ``None`` for its defaults) with
    ``overrides`` applied field by field, validated again.

    Raises ``TypeError`` naming ``owner`` if ``params`` is of another type or an override is
    not a field.
    """
    if params is None:
        params = params_class()
    elif not isinstance(params, params_class):
        raise TypeError(
            f"params of {owner} must be None or a {params_class.__name__}, "
            f"got {params!r} ({type(params).__name__})"
        )
    unknown = set(overrides) - {field.name for field in dataclasses.fields(params)}
    if unknown:
        raise TypeError(f"unknown argument(s) for {owner}: {sorted(unknown)}")
    return dataclasses.replace(params, **overrides)


MIN_COST_SCALE = 1e-6
"""The smallest ``cost_scale``: a finite cost below ~1e302 then gives a finite reward."""
MAX_TRANSMISSION_PENALTY = 1e12
"""The largest ``transmission_penalty``: its charge for every channel stays finite and leaves
the accuracy term digits to count in."""


def require_in_range(name: str, value: Any, low: float, high: float) -> float:
    """``value`` as a float in ``[low, high]``, or ``ValueError`` naming ``name`` and the range."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise ValueError(f"{name} must be a number in [{low:g}, {high:g}], got {value!r}")
    number = float(value)
    if not low <= number <= high:
        raise ValueError(f"{name} must be a number in [{low:g}, {high:g}], got {value!r}")
    return number

"""Constructor-argument checks of :mod:`etsc_envs.core.validation`.

Checked properties: every ``require_*`` helper rejects physically meaningless input (negative,
zero, NaN or infinite magnitudes, vectors of the wrong length, non-unit attitude quaternions,
inertia-like matrices that are not symmetric positive definite, unknown options) with a
``ValueError`` naming the offending argument, and returns the cleaned value otherwise
(floats, float64 arrays, a renormalised quaternion).
"""

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from etsc_envs.core.validation import (
    apply_overrides,
    require_bool,
    require_choice,
    require_field_types,
    require_non_negative,
    require_positive,
    require_reset_options,
    require_spd_matrix,
    require_unit_quaternion,
    require_vector,
    step_count,
)

BAD_NUMBERS = [np.nan, np.inf, -np.inf]


NOT_NUMBERS = ["0.001", b"1", True, None, [1.0]]


@pytest.mark.parametrize("value", [0.0, -1.0, -1e-300, *BAD_NUMBERS, *NOT_NUMBERS])
def test_require_positive_rejects(value):
    with pytest.raises(ValueError, match="sample_time_s"):
        require_positive("sample_time_s", value)


@pytest.mark.parametrize("value", [1e-12, 0.1, 3, np.float32(2.5)])
def test_require_positive_accepts(value):
    result = require_positive("sample_time_s", value)
    assert isinstance(result, float)
    assert result == float(value)


@pytest.mark.parametrize("value", [-1.0, -1e-300, *BAD_NUMBERS, *NOT_NUMBERS])
def test_require_non_negative_rejects(value):
    with pytest.raises(ValueError, match="threshold"):
        require_non_negative("threshold", value)


@pytest.mark.parametrize("value", [0.0, 0, 2.0])
def test_require_non_negative_accepts(value):
    result = require_non_negative("threshold", value)
    assert isinstance(result, float)
    assert result == float(value)


def test_require_choice():
    assert require_choice("trigger", "relative", ["fixed", "relative"]) == "relative"
    assert require_choice("trigger", "fixed", (c for c in ("fixed", "relative"))) == "fixed"
    with pytest.raises(ValueError, match="trigger") as info:
        require_choice("trigger", "Relative", ["fixed", "relative"])
    assert "fixed" in str(info.value)
    assert "relative" in str(info.value)


@pytest.mark.parametrize(
    "value",
    [[1.0, 2.0], [1.0, 2.0, 3.0, 4.0], [[1.0, 2.0, 3.0]], [1.0, np.nan, 3.0], [np.inf, 0.0, 0.0]],
)
def test_require_vector_rejects(value):
    with pytest.raises(ValueError, match="initial_rate"):
        require_vector("initial_rate", value, 3)


def test_require_vector_accepts_and_converts():
    result = require_vector("initial_rate", [1, -2, 3], 3)
    assert result.dtype == np.float64
    assert_array_equal(result, [1.0, -2.0, 3.0])
    assert_array_equal(require_vector("gains", (0.5, 2.0), 2, positive=True), [0.5, 2.0])


@pytest.mark.parametrize("value", [[1.0, 0.0, 3.0], [1.0, -2.0, 3.0]])
def test_require_vector_positive_rejects_non_positive_entries(value):
    with pytest.raises(ValueError, match="gains"):
        require_vector("gains", value, 3, positive=True)


@pytest.mark.parametrize(
    "value",
    [
        [0.0, 0.0, 0.0, 1.1],
        [0.0, 0.0, 0.0, 0.0],
        [0.5, 0.5, 0.5, 0.4],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 0.0, np.nan],
    ],
)
def test_require_unit_quaternion_rejects(value):
    with pytest.raises(ValueError, match="initial_attitude"):
        require_unit_quaternion("initial_attitude", value)


def test_require_unit_quaternion_normalises_nearly_unit_input():
    direction = np.array([0.1, -0.3, 0.5, 0.8])
    direction /= np.linalg.norm(direction)
    result = require_unit_quaternion("initial_attitude", 1.00002 * direction)
    assert_allclose(np.linalg.norm(result), 1.0, rtol=0, atol=1e-15)
    assert_allclose(result, direction, rtol=0, atol=1e-15)


def test_require_unit_quaternion_tolerance_is_configurable():
    q = [0.0, 0.0, 0.0, 1.01]
    assert_allclose(require_unit_quaternion("q", q, tolerance=0.02), [0.0, 0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="q"):
        require_unit_quaternion("q", q)


SPD = np.array([[10.0, 1.0, 0.5], [1.0, 12.0, -0.3], [0.5, -0.3, 8.0]])


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        (np.eye(2), "3x3"),
        (np.ones(3), "3x3"),
        (np.where(np.eye(3) > 0, np.nan, 0.0), "finite"),
        (SPD + np.triu(np.full((3, 3), 0.1), 1), "symmetric"),
        (np.diag([1.0, 2.0, -3.0]), "positive definite"),
        (np.diag([1.0, 0.0, 3.0]), "positive definite"),
        (np.array([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), "positive definite"),
    ],
    ids=["2x2", "vector", "nan", "non-symmetric", "negative", "singular", "indefinite"],
)
def test_require_spd_matrix_rejects(value, reason):
    with pytest.raises(ValueError, match="inertia") as info:
        require_spd_matrix("inertia", value)
    assert reason in str(info.value)


def test_require_spd_matrix_accepts():
    result = require_spd_matrix("inertia", SPD.tolist())
    assert result.dtype == np.float64
    assert_array_equal(result, SPD)


@pytest.mark.parametrize("value", ["no", "False", 0, 1, None, np.array([True])])
def test_require_bool_refuses_everything_but_a_bool(value):
    with pytest.raises(ValueError, match="randomize must be True or False"):
        require_bool("randomize", value)


@pytest.mark.parametrize("value", [True, False, np.True_])
def test_require_bool_accepts_bools(value):
    assert require_bool("randomize", value) is bool(value)


@pytest.mark.parametrize(
    ("horizon_s", "period_s", "steps"),
    [(0.003, 0.001, 3), (300.0, 0.001, 300_000), (0.5, 0.01, 50)],
)
def test_step_count_of_whole_horizons(horizon_s, period_s, steps):
    assert step_count(horizon_s, period_s) == steps


@pytest.mark.parametrize(("horizon_s", "period_s"), [(0.0015, 0.001), (0.0004, 0.001)])
def test_step_count_refuses_a_fraction_of_a_period(horizon_s, period_s):
    with pytest.raises(ValueError, match="horizon_s must be a whole number"):
        step_count(horizon_s, period_s)


def test_require_reset_options():
    assert require_reset_options(None) == {}
    assert require_reset_options({"reset_mask": 1}, ["reset_mask"]) == {"reset_mask": 1}
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['foo'\].*takes no options"):
        require_reset_options({"foo": 1})
    with pytest.raises(ValueError, match="options must be None or a dict"):
        require_reset_options("string")


@dataclasses.dataclass(frozen=True)
class _Fields:
    flag: bool = True
    count: int = 1
    gain: float = 1.0
    limit: float | None = None
    mode: str = "a"
    vector: tuple = (1.0, 2.0)
    anything: object = None


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("flag", "no"),
        ("count", 1.5),
        ("count", True),
        ("gain", "1.0"),
        ("limit", "x"),
        ("mode", 3),
        ("vector", "abc"),
        ("vector", [[1.0], [1.0, 2.0]]),
    ],
)
def test_require_field_types_names_the_field(name, value):
    with pytest.raises(ValueError, match=name):
        require_field_types(_Fields(**{name: value}))


def test_require_field_types_accepts_fitting_values():
    require_field_types(_Fields(flag=np.False_, count=np.int64(3), gain=2, limit=None))
    require_field_types(_Fields(vector=np.zeros(2), anything="free"))


def test_apply_overrides_refuses_params_of_another_type():
    with pytest.raises(TypeError, match=r"params of Owner must be None or a _Fields, got 'x'"):
        apply_overrides(_Fields, "x", {}, "Owner")
    assert apply_overrides(_Fields, None, {"gain": 3.0}, "Owner").gain == 3.0

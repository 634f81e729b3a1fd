"""The tuple helpers of :mod:`etsc_envs.core.vec3` return the bits of the array expressions
they replace inside compiled code (the papers' reproductions rely on it), for arrays and
tuples alike."""

import numpy as np
import pytest
from numba import njit
from numpy.testing import assert_allclose

from etsc_envs.core import vec3
from etsc_envs.core.linalg import matvec, matvec_transposed
from etsc_envs.core.rotations import quat_multiply, quat_product


@njit
def _array_expressions(a, b, matrix, factor, t, phase):
    return (
        a + b,
        a - b,
        -a,
        factor * a,
        a * b,
        a / b,
        np.abs(a).sum(),
        a @ b,
        matrix @ a,
        matrix.T @ a,
        b * np.sin(a * t + phase),
    )


@njit
def _tuple_helpers(a, b, matrix, factor, t, phase):
    return (
        vec3.add(a, b),
        vec3.subtract(a, b),
        vec3.negate(a),
        vec3.scale(factor, a),
        vec3.multiply(a, b),
        vec3.divide(a, b),
        vec3.absolute_sum(a),
        vec3.dot(a, b),
        vec3.matvec(matrix, a),
        vec3.matvec_transposed(matrix, a),
        vec3.sine_wave(b, a, t, phase),
    )


@njit
def _as_tuple(a):
    return vec3.as_vec3(a)


def _inputs(rng):
    scale = 10.0 ** rng.uniform(-6, 4, size=3)
    return (
        rng.normal(size=3) * scale,
        rng.normal(size=3),
        rng.normal(size=(3, 3)) * scale[:, None],
        float(rng.normal()),
        float(rng.uniform(0.0, 100.0)),
        rng.uniform(0.0, 2.0 * np.pi, size=3),
    )


BLAS_BACKED = {7: "dot", 8: "matvec", 9: "matvec_transposed"}
"""Positions of the expressions that compiled code hands to BLAS: their summation order is the
BLAS kernel's, which depends on the machine (``OPENBLAS_CORETYPE`` included)."""


def _within_blas_rounding(got, want, terms) -> bool:
    """Equal up to the rounding error bound of a 3-term sum, 3 eps × Σ|terms| per entry."""
    bound = 3.0 * np.finfo(float).eps * np.asarray(terms)
    return bool(np.all(np.abs(np.asarray(got) - np.asarray(want)) <= bound))


def test_helpers_return_the_bits_of_the_array_expressions():
    """Element-wise helpers return the very bits; the sums that compiled code gives to BLAS
    are equal to within their rounding bound (bit-equal on machines whose BLAS kernel sums in
    the helpers' order, as the one the reproductions' digits were recorded on)."""
    rng = np.random.default_rng(21)
    for _ in range(500):
        a, b, matrix, factor, t, phase = _inputs(rng)
        expected = _array_expressions(a, b, matrix, factor, t, phase)
        terms = {
            7: np.abs(a) @ np.abs(b),
            8: np.abs(matrix) @ np.abs(a),
            9: np.abs(matrix).T @ np.abs(a),
        }
        for computed in (
            _tuple_helpers(a, b, matrix, factor, t, phase),
            _tuple_helpers(_as_tuple(a), _as_tuple(b), matrix, factor, t, phase),
        ):
            for index, (got, want) in enumerate(zip(computed, expected, strict=True)):
                if index in BLAS_BACKED:
                    assert _within_blas_rounding(got, want, terms[index]), BLAS_BACKED[index]
                else:
                    assert np.array_equal(np.asarray(got), np.asarray(want))


def test_cross_matches_numpy_and_solve_solves():
    rng = np.random.default_rng(22)
    for _ in range(200):
        a, b, matrix, *_ = _inputs(rng)
        assert np.array_equal(np.array(vec3.cross(a, b)), np.cross(a, b))
        well_posed = matrix + 3.0 * np.abs(matrix).max() * np.eye(3)
        assert_allclose(
            vec3.solve(well_posed, b), np.linalg.solve(well_posed, b), rtol=1e-12, atol=1e-14
        )


def test_quaternion_product_tuple_and_array_forms_agree():
    rng = np.random.default_rng(23)
    for _ in range(200):
        p, q = rng.normal(size=4), rng.normal(size=4)
        assert np.array_equal(np.array(quat_product(p, q)), quat_multiply(p, q))
        assert np.array_equal(np.array(quat_product(tuple(p), tuple(q))), quat_multiply(p, q))


def test_store_and_to_array_copy_the_entries():
    out = np.zeros(5)
    vec3.store(out[1:4], (1.0, 2.0, 3.0))
    assert np.array_equal(out, [0.0, 1.0, 2.0, 3.0, 0.0])
    assert np.array_equal(vec3.to_array((4.0, 5.0, 6.0)), [4.0, 5.0, 6.0])


@pytest.mark.parametrize("helper", [vec3.add, vec3.cross, vec3.dot])
def test_helpers_accept_array_views(helper):
    row = np.arange(10.0)
    view = row[2:5]
    assert np.array_equal(np.asarray(helper(view, view)), np.asarray(helper(tuple(view), view)))


@njit
def _loop_products(matrix, wide, a):
    return matvec(matrix, a), matvec_transposed(matrix, a), matvec_transposed(wide, a)


@njit
def _from_zero_helpers(matrix, wide, a):
    columns = np.empty(wide.shape[1])
    for column in range(wide.shape[1]):
        columns[column] = vec3.column_dot_from_zero(wide, column, a)
    return (
        vec3.matvec_from_zero(matrix, a),
        vec3.matvec_transposed_from_zero(matrix, a),
        columns,
    )


def test_from_zero_helpers_return_the_bits_of_the_linalg_loops():
    """The ``*_from_zero`` helpers sum as the loops of :mod:`etsc_envs.core.linalg` do (no
    BLAS involved), for array rows and tuple rows alike."""
    rng = np.random.default_rng(24)
    for _ in range(500):
        a, _, matrix, *_ = _inputs(rng)
        wide = rng.normal(size=(3, 6)) * 10.0 ** rng.uniform(-6, 4, size=(3, 1))
        expected = _loop_products(matrix, wide, a)
        rows = tuple(tuple(row) for row in matrix)
        for computed in (
            _from_zero_helpers(matrix, wide, a),
            _from_zero_helpers(matrix, wide, _as_tuple(a)),
        ):
            for got, want in zip(computed, expected, strict=True):
                assert np.array_equal(np.asarray(got), want)
        assert np.array_equal(np.asarray(vec3.matvec_from_zero(rows, a)), expected[0])
        assert np.array_equal(vec3.to_matrix(rows), matrix)

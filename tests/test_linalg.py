"""The loop-written products of :mod:`etsc_envs.core.linalg` agree with NumPy's ``@``.

Checked on seeded random matrices of the shapes the suite uses (3×3, 3×6, 6×3) and on
non-contiguous views (slices of larger arrays), which the compiled code passes around.
"""

from fractions import Fraction

import numpy as np
import pytest
from numba import njit
from numpy.testing import assert_allclose

from etsc_envs.core.linalg import (
    fused_dot,
    fused_matmul,
    fused_matvec3,
    fused_matvec3_transposed,
    fused_matvec6,
    fused_multiply_add,
    matmul,
    matvec,
    matvec_transposed,
)

SHAPES = [(3, 3), (3, 6), (6, 3), (1, 4)]


@pytest.mark.parametrize(("rows", "columns"), SHAPES)
def test_matvec_and_its_transpose_match_numpy(rows, columns):
    rng = np.random.default_rng(rows * 10 + columns)
    matrix = rng.normal(size=(rows, columns))
    vector = rng.normal(size=columns)
    assert_allclose(matvec(matrix, vector), matrix @ vector, rtol=1e-14, atol=1e-14)
    other = rng.normal(size=rows)
    assert_allclose(matvec_transposed(matrix, other), matrix.T @ other, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize(("rows", "inner", "columns"), [(3, 3, 3), (3, 3, 6), (6, 3, 1)])
def test_matmul_matches_numpy(rows, inner, columns):
    rng = np.random.default_rng(rows + 7 * inner + 49 * columns)
    left, right = rng.normal(size=(rows, inner)), rng.normal(size=(inner, columns))
    assert_allclose(matmul(left, right), left @ right, rtol=1e-14, atol=1e-14)


def test_products_accept_non_contiguous_views():
    rng = np.random.default_rng(5)
    big = rng.normal(size=(6, 13))
    matrix, vector = big[1:4, 3:6], big[:, 7][1:4]
    assert not matrix.flags.c_contiguous
    assert_allclose(matvec(matrix, vector), matrix @ vector, rtol=1e-14, atol=1e-14)
    assert_allclose(matmul(matrix, matrix.T), matrix @ matrix.T, rtol=1e-14, atol=1e-14)


@njit
def _compiled_blas_dot(left, right):
    return left @ right


@njit
def _compiled_blas_matvec(matrix, vector):
    return matrix @ vector


@njit
def _compiled_blas_transposed_matvec(matrix, vector):
    return matrix.T @ vector


@njit
def _compiled_blas_matmul(left, right):
    return left @ right


@njit
def _compiled_fused_multiply_add(left, right, addend):
    return fused_multiply_add(left, right, addend)


def _within_rounding(got, want, terms, length: int) -> bool:
    """Equal up to the rounding error bound of a ``length``-term sum, length eps × Σ|terms|."""
    bound = length * np.finfo(float).eps * np.asarray(terms)
    return bool(np.all(np.abs(np.asarray(got) - np.asarray(want)) <= bound))


def test_fused_products_match_compiled_blas_to_its_rounding():
    """The fused helpers replace ``@`` inside compiled code. They sum in the order of the BLAS
    kernels of the machine the reproductions' digits were recorded on, and agree with any
    machine's BLAS to within the rounding bound of the sum (a kernel that sums in another
    order, as ``OPENBLAS_CORETYPE=Haswell`` selects on some processors, changes last bits)."""
    rng = np.random.default_rng(11)
    for _ in range(2000):
        scale = 10.0 ** rng.uniform(-8, 6, size=3)
        matrix, vector = rng.normal(size=(3, 3)) * scale, rng.normal(size=3)
        quaternion = rng.normal(size=4)
        scaled = vector * scale
        assert _within_rounding(
            fused_dot(scaled, vector),
            _compiled_blas_dot(scaled, vector),
            np.abs(scaled) @ np.abs(vector),
            3,
        )
        assert _within_rounding(
            fused_dot(quaternion, quaternion),
            _compiled_blas_dot(quaternion, quaternion),
            quaternion @ quaternion,
            4,
        )
        assert _within_rounding(
            fused_matvec3(matrix, vector),
            _compiled_blas_matvec(matrix, vector),
            np.abs(matrix) @ np.abs(vector),
            3,
        )
        assert _within_rounding(
            fused_matvec3_transposed(matrix, vector),
            _compiled_blas_transposed_matvec(matrix, vector),
            np.abs(matrix).T @ np.abs(vector),
            3,
        )
    for size in (3, 4, 6):
        for _ in range(500):
            left = rng.normal(size=(size, size)) * 10.0 ** rng.uniform(-8, 6, size=(size, 1))
            right = rng.normal(size=(size, size))
            assert _within_rounding(
                fused_matmul(left, right),
                _compiled_blas_matmul(left, right),
                np.abs(left) @ np.abs(right),
                size,
            )
    for rows in (6, 12):
        for _ in range(500):
            matrix = rng.normal(size=(rows, 6)) * 10.0 ** rng.uniform(-8, 6, size=(rows, 1))
            vector = rng.normal(size=6)
            assert _within_rounding(
                fused_matvec6(matrix, vector),
                _compiled_blas_matvec(matrix, vector),
                np.abs(matrix) @ np.abs(vector),
                6,
            )


def test_fused_multiply_add_rounds_once_compiled_and_in_python():
    rng = np.random.default_rng(12)
    for _ in range(500):
        left, right, addend = rng.normal(size=3) * 10.0 ** rng.uniform(-5, 5, size=3)
        exact = float(Fraction(left) * Fraction(right) + Fraction(addend))
        assert fused_multiply_add(left, right, addend) == exact
        assert _compiled_fused_multiply_add(left, right, addend) == exact
    # a case where rounding the product first loses the answer entirely
    left = 1.0 + 2.0**-30
    assert _compiled_fused_multiply_add(left, left, -(1.0 + 2.0**-29)) == 2.0**-60

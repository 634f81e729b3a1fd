"""The loop-written products of :mod:`etsc_envs.core.linalg` agree with NumPy's ``@``.

Checked on seeded random matrices of the shapes the suite uses (3×3, 3×6, 6×3) and on
non-contiguous views (slices of larger arrays), which the compiled code passes around.
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from etsc_envs.core.linalg import matmul, matvec, matvec_transposed

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

"""Matrices as tuples of rows in the compiled hot path (``vec3.rows_*``, ``vec3.product``,
the SE(3) forms of :mod:`etsc_envs.core.rotations`) return the bits of the array products they
replace (:mod:`etsc_envs.core.linalg`'s fused chains, which are OpenBLAS's), so that paper 000's
step computes without temporaries what it computed with them."""

import numpy as np
import pytest
from numba import njit

from etsc_envs.core import rotations, vec3
from etsc_envs.core.linalg import fused_matmul, fused_matvec3, fused_matvec6


@njit
def _row_forms(matrix, other, vector):
    rows, other_rows = vec3.rows(matrix), vec3.rows(other)
    return (
        vec3.to_array(vec3.rows_matvec(rows, vector)),
        vec3.to_array(vec3.rows_matvec_transposed(rows, vector)),
        vec3.to_matrix(vec3.product(rows, other_rows)),
        vec3.to_array(vec3.rows_matvec_chain(rows, vector)),
        vec3.to_matrix(vec3.transpose(rows)),
        vec3.to_array(vec3.solve_rows(rows, vector)),
    )


@njit
def _array_forms(matrix, other, vector):
    column = np.empty((3, 1))
    column[:, 0] = vector
    return (
        fused_matvec3(matrix, vector),
        vec3.to_array(vec3.matvec_transposed(matrix, vector)),
        fused_matmul(matrix, other),
        fused_matmul(matrix, column)[:, 0],
        np.ascontiguousarray(matrix.T),
        vec3.to_array(vec3.solve(matrix, vector)),
    )


@njit
def _se3_forms(phi, rho, twist, rotation, position, rotation2, position2):
    g = np.eye(4)
    g[:3, :3] = vec3.to_matrix(rotation)
    g[:3, 3] = vec3.to_array(position)
    g2 = np.eye(4)
    g2[:3, :3] = vec3.to_matrix(rotation2)
    g2[:3, 3] = vec3.to_array(position2)
    xi = np.concatenate((vec3.to_array(phi), vec3.to_array(rho)))
    product_rotation, product_position = rotations.pose_product(
        rotation, position, rotation2, position2
    )
    inverse_rotation, inverse_position = rotations.pose_inverse(rotation, position)
    inverse = rotations.se3_inverse(g)
    return (
        np.array(rotations.se3_right_jacobian_inverse_times(phi, rho, twist)),
        fused_matvec6(rotations.se3_right_jacobian_inverse(xi), twist),
        vec3.to_matrix(product_rotation),
        fused_matmul(g, g2)[:3, :3].copy(),
        vec3.to_array(product_position),
        fused_matmul(g, g2)[:3, 3].copy(),
        vec3.to_matrix(inverse_rotation),
        inverse[:3, :3].copy(),
        vec3.to_array(inverse_position),
        inverse[:3, 3].copy(),
        np.array(rotations.block_lower_times(rotation, rotation2, twist)),
        fused_matvec6(_block_lower(g[:3, :3], g2[:3, :3]), twist),
    )


@njit
def _block_lower(diagonal, lower):
    out = np.zeros((6, 6))
    out[:3, :3] = diagonal
    out[3:, 3:] = diagonal
    out[3:, :3] = lower
    return out


@pytest.mark.parametrize("seed", range(20))
def test_row_helpers_return_the_bits_of_the_fused_array_products(seed):
    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.uniform(-6, 4, size=3)
    matrix = rng.normal(size=(3, 3)) * scale[:, None]
    other = rng.normal(size=(3, 3))
    vector = rng.normal(size=3) * scale
    got, want = _row_forms(matrix, other, vector), _array_forms(matrix, other, vector)
    for row_form, array_form in zip(got, want, strict=True):
        assert np.array_equal(row_form, array_form)


@pytest.mark.parametrize("seed", range(20))
def test_se3_tuple_forms_return_the_bits_of_the_matrix_forms(seed):
    rng = np.random.default_rng(seed)
    angle = rng.choice([1e-9, 0.05, 1.0, 3.0])  # each branch of the series and closed forms
    axis = rng.normal(size=3)
    phi = tuple(angle * axis / np.linalg.norm(axis))
    rho = tuple(rng.normal(size=3) * 10.0 ** rng.uniform(-5, 2))
    twist = rng.normal(size=6)
    rotation = vec3.rows(rotations.so3_exp(np.array(phi)))
    rotation2 = vec3.rows(rotations.so3_exp(rng.normal(size=3)))
    position, position2 = tuple(rng.normal(size=3) * 7e6), tuple(rng.normal(size=3))
    forms = _se3_forms(phi, rho, twist, rotation, position, rotation2, position2)
    for tuple_form, matrix_form in zip(forms[0::2], forms[1::2], strict=True):
        assert np.array_equal(tuple_form, matrix_form)

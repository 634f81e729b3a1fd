"""3-vectors as tuples of three floats, for the allocation-free compiled hot path.

Inside compiled code every NumPy expression on a small array allocates its result (about
25 ns with the matching free), and a step of an RK4-integrated loop evaluates hundreds of
them. A tuple of floats lives in registers instead. These helpers take any indexable
3-vector (a tuple or a float64 array) and return tuples, so that equations read as they do
with arrays: ``add(cross(omega, momentum), torque)``.

Each helper performs the same floating-point operations, in the same order, as the array
expression it replaces (products through :func:`etsc_envs.core.linalg.fused_multiply_add`
where NumPy's ``@`` calls OpenBLAS), so rewriting an equation with them leaves its results
unchanged to the last bit.
"""

from __future__ import annotations

import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import fused_column_dot3, fused_multiply_add, fused_row_dot3

Vec3 = tuple[float, float, float]
"""A 3-vector as returned by the helpers of this module."""
Mat3 = tuple[Vec3, Vec3, Vec3]
"""A 3×3 matrix as the tuple of its rows."""


@jit
def as_vec3(vector) -> Vec3:
    """The first three entries of ``vector`` (an array or a tuple)."""
    return (vector[0], vector[1], vector[2])


@jit
def store(out: np.ndarray, vector) -> None:
    """Write the three entries of ``vector`` into ``out[0:3]``."""
    out[0] = vector[0]
    out[1] = vector[1]
    out[2] = vector[2]


@jit
def to_array(vector) -> np.ndarray:
    """A new float64 array holding the three entries of ``vector``."""
    out = np.empty(3)
    store(out, vector)
    return out


@jit
def to_matrix(rows) -> np.ndarray:
    """A new 3×3 float64 array holding the rows ``rows`` (a :data:`Mat3` or an array)."""
    out = np.empty((3, 3))
    for i in range(3):
        store(out[i], rows[i])
    return out


@jit
def add(a, b) -> Vec3:
    """``a + b``."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@jit
def subtract(a, b) -> Vec3:
    """``a - b``."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@jit
def negate(a) -> Vec3:
    """``-a``."""
    return (-a[0], -a[1], -a[2])


@jit
def scale(factor: float, a) -> Vec3:
    """``factor * a`` for a scalar ``factor``."""
    return (factor * a[0], factor * a[1], factor * a[2])


@jit
def multiply(a, b) -> Vec3:
    """The elementwise product ``a * b``."""
    return (a[0] * b[0], a[1] * b[1], a[2] * b[2])


@jit
def divide(a, b) -> Vec3:
    """The elementwise quotient ``a / b``."""
    return (a[0] / b[0], a[1] / b[1], a[2] / b[2])


@jit
def absolute_sum(a) -> float:
    """``np.abs(a).sum()``, summed from zero in index order as NumPy's compiled ``sum`` does."""
    return 0.0 + abs(a[0]) + abs(a[1]) + abs(a[2])


@jit
def sine_wave(amplitude, frequency, t: float, phase) -> Vec3:
    """``amplitude * sin(frequency * t + phase)`` per component."""
    return (
        amplitude[0] * np.sin(frequency[0] * t + phase[0]),
        amplitude[1] * np.sin(frequency[1] * t + phase[1]),
        amplitude[2] * np.sin(frequency[2] * t + phase[2]),
    )


@jit
def cross(a, b) -> Vec3:
    """Vector product ``a × b``."""
    return (
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    )


@jit
def dot(a, b) -> float:
    """``a @ b`` as the chain ``fma(a_2, b_2, fma(a_1, b_1, a_0 b_0))`` (see
    :func:`etsc_envs.core.linalg.fused_dot`)."""
    return fused_multiply_add(a[2], b[2], fused_multiply_add(a[1], b[1], a[0] * b[0]))


@jit
def matvec(matrix: np.ndarray, vector) -> Vec3:
    """``matrix @ vector`` for a C-ordered 3×3 array (see
    :func:`etsc_envs.core.linalg.fused_row_dot3`)."""
    return (
        fused_row_dot3(matrix, 0, vector),
        fused_row_dot3(matrix, 1, vector),
        fused_row_dot3(matrix, 2, vector),
    )


@jit
def matvec_transposed(matrix: np.ndarray, vector) -> Vec3:
    """``matrix.T @ vector`` for a C-ordered 3×3 array (see
    :func:`etsc_envs.core.linalg.fused_column_dot3`)."""
    return (
        fused_column_dot3(matrix, 0, vector),
        fused_column_dot3(matrix, 1, vector),
        fused_column_dot3(matrix, 2, vector),
    )


@jit
def rows(matrix: np.ndarray) -> Mat3:
    """The rows of a 3×3 array as a :data:`Mat3`."""
    return (
        (matrix[0, 0], matrix[0, 1], matrix[0, 2]),
        (matrix[1, 0], matrix[1, 1], matrix[1, 2]),
        (matrix[2, 0], matrix[2, 1], matrix[2, 2]),
    )


@jit
def solve(matrix: np.ndarray, rhs) -> Vec3:
    """The solution x of the 3×3 system ``matrix · x = rhs`` (:func:`solve_rows`)."""
    return solve_rows(rows(matrix), rhs)


@jit
def solve_rows(a, rhs) -> Vec3:
    """The solution x of the 3×3 system ``a · x = rhs`` for ``a`` given by its rows (a
    :data:`Mat3`), by Cramer's rule: the adjugate times ``rhs`` (rows as in :func:`matvec`),
    divided by the determinant."""
    c00 = a[1][1] * a[2][2] - a[1][2] * a[2][1]
    c01 = a[1][2] * a[2][0] - a[1][0] * a[2][2]
    c02 = a[1][0] * a[2][1] - a[1][1] * a[2][0]
    det = a[0][0] * c00 + a[0][1] * c01 + a[0][2] * c02
    c10 = a[0][2] * a[2][1] - a[0][1] * a[2][2]
    c11 = a[0][0] * a[2][2] - a[0][2] * a[2][0]
    c12 = a[0][1] * a[2][0] - a[0][0] * a[2][1]
    c20 = a[0][1] * a[1][2] - a[0][2] * a[1][1]
    c21 = a[0][2] * a[1][0] - a[0][0] * a[1][2]
    c22 = a[0][0] * a[1][1] - a[0][1] * a[1][0]
    r0, r1, r2 = rhs[0], rhs[1], rhs[2]
    return (
        fused_multiply_add(c20, r2, fused_multiply_add(c00, r0, c10 * r1)) / det,
        fused_multiply_add(c21, r2, fused_multiply_add(c01, r0, c11 * r1)) / det,
        fused_multiply_add(c22, r2, fused_multiply_add(c02, r0, c12 * r1)) / det,
    )


@jit
def column_dot_from_zero(rows, column: int, vector) -> float:
    """Entry ``column`` of ``matrix.T @ vector`` for a matrix of three rows ``rows`` (tuples or
    array rows, of any length), summed from zero in row order without fused multiply-adds:
    the value the loop of :func:`etsc_envs.core.linalg.matvec_transposed` returns."""
    return (
        0.0
        + rows[0][column] * vector[0]
        + rows[1][column] * vector[1]
        + rows[2][column] * vector[2]
    )


@jit
def matvec_from_zero(rows, vector) -> Vec3:
    """``matrix @ vector`` for a 3×3 matrix given by its rows (a :data:`Mat3` or an array),
    each entry summed from zero in index order without fused multiply-adds: the value the loop
    of :func:`etsc_envs.core.linalg.matvec` returns."""
    return (
        0.0 + rows[0][0] * vector[0] + rows[0][1] * vector[1] + rows[0][2] * vector[2],
        0.0 + rows[1][0] * vector[0] + rows[1][1] * vector[1] + rows[1][2] * vector[2],
        0.0 + rows[2][0] * vector[0] + rows[2][1] * vector[1] + rows[2][2] * vector[2],
    )


@jit
def matvec_transposed_from_zero(rows, vector) -> Vec3:
    """``matrix.T @ vector`` for a 3×3 matrix given by its rows, by
    :func:`column_dot_from_zero`: the value the loop of
    :func:`etsc_envs.core.linalg.matvec_transposed` returns."""
    return (
        column_dot_from_zero(rows, 0, vector),
        column_dot_from_zero(rows, 1, vector),
        column_dot_from_zero(rows, 2, vector),
    )


@jit
def rows_matvec(rows, vector) -> Vec3:
    """``matrix @ vector`` for a 3×3 matrix given by its rows (a :data:`Mat3`), each entry
    ``fma(m_2 v_2, fma(m_0 v_0, m_1 v_1))``: the value :func:`matvec` (OpenBLAS's ``dgemv``)
    returns for the same matrix as a C-ordered array."""
    return (
        fused_multiply_add(
            rows[0][2], vector[2], fused_multiply_add(rows[0][0], vector[0], rows[0][1] * vector[1])
        ),
        fused_multiply_add(
            rows[1][2], vector[2], fused_multiply_add(rows[1][0], vector[0], rows[1][1] * vector[1])
        ),
        fused_multiply_add(
            rows[2][2], vector[2], fused_multiply_add(rows[2][0], vector[0], rows[2][1] * vector[1])
        ),
    )


@jit
def rows_matvec_transposed(rows, vector) -> Vec3:
    """``matrix.T @ vector`` for a 3×3 matrix given by its rows (a :data:`Mat3`), each entry
    ``fma(m_2j v_2, fma(m_1j v_1, m_0j v_0))``: the value :func:`matvec_transposed` returns
    for the same matrix as a C-ordered array."""
    return (
        fused_multiply_add(
            rows[2][0], vector[2], fused_multiply_add(rows[1][0], vector[1], rows[0][0] * vector[0])
        ),
        fused_multiply_add(
            rows[2][1], vector[2], fused_multiply_add(rows[1][1], vector[1], rows[0][1] * vector[0])
        ),
        fused_multiply_add(
            rows[2][2], vector[2], fused_multiply_add(rows[1][2], vector[1], rows[0][2] * vector[0])
        ),
    )


@jit
def transpose(rows) -> Mat3:
    """The transpose of a 3×3 matrix given by its rows, as a :data:`Mat3`."""
    return (
        (rows[0][0], rows[1][0], rows[2][0]),
        (rows[0][1], rows[1][1], rows[2][1]),
        (rows[0][2], rows[1][2], rows[2][2]),
    )


@jit
def _product_row(left_row, right) -> Vec3:
    """Row ``left_row @ right`` with each entry the chain of
    :func:`etsc_envs.core.linalg.fused_matmul`: ``fma(l_2, r_2j, fma(l_1, r_1j, l_0 r_0j))``."""
    return (
        fused_multiply_add(
            left_row[2],
            right[2][0],
            fused_multiply_add(left_row[1], right[1][0], left_row[0] * right[0][0]),
        ),
        fused_multiply_add(
            left_row[2],
            right[2][1],
            fused_multiply_add(left_row[1], right[1][1], left_row[0] * right[0][1]),
        ),
        fused_multiply_add(
            left_row[2],
            right[2][2],
            fused_multiply_add(left_row[1], right[1][2], left_row[0] * right[0][2]),
        ),
    )


@jit
def product(left, right) -> Mat3:
    """``left @ right`` for 3×3 matrices given by their rows: bit for bit the value of
    :func:`etsc_envs.core.linalg.fused_matmul` (OpenBLAS's ``dgemm``) on the same matrices."""
    return (
        _product_row(left[0], right),
        _product_row(left[1], right),
        _product_row(left[2], right),
    )


@jit
def rows_add(a, b) -> Mat3:
    """``a + b`` for 3×3 matrices given by their rows."""
    return (add(a[0], b[0]), add(a[1], b[1]), add(a[2], b[2]))


@jit
def rows_scale(factor: float, a) -> Mat3:
    """``factor * a`` for a scalar ``factor`` and a 3×3 matrix given by its rows."""
    return (scale(factor, a[0]), scale(factor, a[1]), scale(factor, a[2]))


@jit
def rows_divide(a, divisor: float) -> Mat3:
    """``a / divisor`` for a 3×3 matrix given by its rows and a scalar ``divisor``."""
    return (
        (a[0][0] / divisor, a[0][1] / divisor, a[0][2] / divisor),
        (a[1][0] / divisor, a[1][1] / divisor, a[1][2] / divisor),
        (a[2][0] / divisor, a[2][1] / divisor, a[2][2] / divisor),
    )


@jit
def rows_negate(a) -> Mat3:
    """``-a`` for a 3×3 matrix given by its rows."""
    return (negate(a[0]), negate(a[1]), negate(a[2]))


@jit
def rows_matvec_chain(rows, vector) -> Vec3:
    """``matrix @ vector`` for a 3×3 matrix given by its rows, each entry the chain
    ``fma(m_2 v_2, fma(m_1 v_1, m_0 v_0))`` of :func:`etsc_envs.core.linalg.fused_matmul` (a
    column of a matrix product; :func:`rows_matvec` is OpenBLAS's ``dgemv`` order instead)."""
    return (
        fused_multiply_add(
            rows[0][2], vector[2], fused_multiply_add(rows[0][1], vector[1], rows[0][0] * vector[0])
        ),
        fused_multiply_add(
            rows[1][2], vector[2], fused_multiply_add(rows[1][1], vector[1], rows[1][0] * vector[0])
        ),
        fused_multiply_add(
            rows[2][2], vector[2], fused_multiply_add(rows[2][1], vector[1], rows[2][0] * vector[0])
        ),
    )

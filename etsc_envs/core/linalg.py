"""Products of small dense matrices written as loops, for the compiled hot path.

Inside compiled code NumPy's ``@`` on 3-vectors and 3×3 matrices goes through BLAS, whose call
overhead (~150 ns) dwarfs the arithmetic; these loops do the same products in a few tens of
nanoseconds. Any shapes are accepted, so they also serve 3×6 regressors.
"""

from fractions import Fraction

import numpy as np
from numba import types
from numba.extending import intrinsic, overload

from etsc_envs.core.jit import jit


@jit
def as_array(values) -> np.ndarray:
    """A new float64 array holding the entries of ``values`` (a tuple of floats or an array)."""
    out = np.empty(len(values))
    for i in range(len(values)):
        out[i] = values[i]
    return out


@jit
def matvec(matrix: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """``matrix @ vector`` for an m×n matrix and an n-vector."""
    rows, columns = matrix.shape
    out = np.zeros(rows)
    for i in range(rows):
        total = 0.0
        for j in range(columns):
            total += matrix[i, j] * vector[j]
        out[i] = total
    return out


@jit
def matvec_transposed(matrix: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """``matrix.T @ vector`` for an m×n matrix and an m-vector, without forming the transpose."""
    rows, columns = matrix.shape
    out = np.zeros(columns)
    for i in range(rows):
        for j in range(columns):
            out[j] += matrix[i, j] * vector[i]
    return out


@jit
def matmul(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``left @ right`` for an m×k and a k×n matrix."""
    rows, inner = left.shape
    columns = right.shape[1]
    out = np.zeros((rows, columns))
    for i in range(rows):
        for k in range(inner):
            factor = left[i, k]
            for j in range(columns):
                out[i, j] += factor * right[k, j]
    return out


def fused_multiply_add(left: float, right: float, addend: float) -> float:
    """``left * right + addend`` rounded once, as a fused multiply-add does.

    Compiled, this is LLVM's ``llvm.fma.f64`` (exact on every CPU); as plain Python (with
    ``NUMBA_DISABLE_JIT=1``) the exact rational result rounded to the nearest float.
    """
    return float(Fraction(left) * Fraction(right) + Fraction(addend))


@intrinsic
def _llvm_fma(typingctx, left, right, addend):
    signature = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, sig, args):
        return builder.fma(*args)

    return signature, codegen


# Numba's stubs: jit_options is a TypedDict without "cache", and an @intrinsic is called
# without its typing context.
@overload(fused_multiply_add, jit_options={"cache": True})  # pyright: ignore[reportArgumentType]
def _fused_multiply_add_compiled(left, right, addend):
    def implementation(left, right, addend):
        return _llvm_fma(left, right, addend)  # pyright: ignore[reportCallIssue]

    return implementation


@jit
def fused_dot(left: np.ndarray, right: np.ndarray) -> float:
    """``left @ right`` as the chain ``fma(l_n, r_n, ... fma(l_1, r_1, l_0 r_0))``: the same
    value, bit for bit, as the OpenBLAS ``ddot`` NumPy's ``@`` calls for 3- and 4-vectors,
    without the call's overhead."""
    total = left[0] * right[0]
    for i in range(1, left.shape[0]):
        total = fused_multiply_add(left[i], right[i], total)
    return total


@jit
def fused_row_dot3(matrix: np.ndarray, row: int, vector) -> float:
    """Entry ``row`` of ``matrix @ vector`` for a C-ordered 3×3 matrix, as ``fma(m_2 v_2,
    fma(m_0 v_0, m_1 v_1))``: the value OpenBLAS's ``dgemv`` returns, bit for bit."""
    partial = fused_multiply_add(matrix[row, 0], vector[0], matrix[row, 1] * vector[1])
    return fused_multiply_add(matrix[row, 2], vector[2], partial)


@jit
def fused_column_dot3(matrix: np.ndarray, column: int, vector) -> float:
    """Entry ``column`` of ``matrix.T @ vector`` for a C-ordered 3×3 matrix, as ``fma(m_2j v_2,
    fma(m_1j v_1, m_0j v_0))``: the value OpenBLAS's ``dgemv`` returns on the transposed view,
    bit for bit."""
    partial = fused_multiply_add(matrix[1, column], vector[1], matrix[0, column] * vector[0])
    return fused_multiply_add(matrix[2, column], vector[2], partial)


@jit
def fused_matvec3(matrix: np.ndarray, vector) -> np.ndarray:
    """``matrix @ vector`` for a C-ordered 3×3 matrix by :func:`fused_row_dot3`: the same
    value, bit for bit, as the OpenBLAS ``dgemv`` NumPy's ``@`` calls, without the call's
    overhead."""
    out = np.empty(3)
    for i in range(3):
        out[i] = fused_row_dot3(matrix, i, vector)
    return out


@jit
def fused_matvec3_transposed(matrix: np.ndarray, vector) -> np.ndarray:
    """``matrix.T @ vector`` for a C-ordered 3×3 matrix by :func:`fused_column_dot3`: the same
    value, bit for bit, as the OpenBLAS ``dgemv`` NumPy's ``@`` calls on the transposed view,
    without the call's overhead."""
    out = np.empty(3)
    for j in range(3):
        out[j] = fused_column_dot3(matrix, j, vector)
    return out


@jit
def fused_dot6(row, vector) -> float:
    """``row @ vector`` for 6-vectors (arrays or tuples), as ``((m_0 v_0 + m_2 v_2) +
    (m_1 v_1 + m_3 v_3)) + fma(m_4, v_4, m_5 v_5)``: OpenBLAS's ``dgemv`` on the transposed view
    sums the first four products in vector lanes and adds the last two separately, and returns
    this value bit for bit as an entry of a matrix-vector product."""
    lanes = (row[0] * vector[0] + row[2] * vector[2]) + (row[1] * vector[1] + row[3] * vector[3])
    return lanes + fused_multiply_add(row[4], vector[4], row[5] * vector[5])


@jit
def fused_row_dot6(matrix: np.ndarray, row: int, vector: np.ndarray) -> float:
    """Entry ``row`` of ``matrix @ vector`` for a C-ordered matrix of 6 columns
    (:func:`fused_dot6` of the row)."""
    return fused_dot6(matrix[row], vector)


@jit
def fused_matvec6(matrix: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """``matrix @ vector`` for a C-ordered matrix of 6 columns (any rows) by
    :func:`fused_row_dot6`: the same value, bit for bit, as the OpenBLAS ``dgemv`` NumPy's ``@``
    calls, without the call's overhead."""
    out = np.empty(matrix.shape[0])
    for i in range(matrix.shape[0]):
        out[i] = fused_row_dot6(matrix, i, vector)
    return out


@jit
def fused_matmul(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``left @ right``, each entry the chain ``fma(l_in r_nj, ... fma(l_i1 r_1j, l_i0 r_0j))``:
    the same value, bit for bit, as the OpenBLAS ``dgemm`` NumPy's ``@`` calls for the square
    3×3, 4×4 and 6×6 products of the suite, without the call's overhead."""
    rows, inner = left.shape
    columns = right.shape[1]
    out = np.empty((rows, columns))
    for i in range(rows):
        for j in range(columns):
            total = left[i, 0] * right[0, j]
            for k in range(1, inner):
                total = fused_multiply_add(left[i, k], right[k, j], total)
            out[i, j] = total
    return out

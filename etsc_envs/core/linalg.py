"""Products of small dense matrices written as loops, for the compiled hot path.

Inside compiled code NumPy's ``@`` on 3-vectors and 3×3 matrices goes through BLAS, whose call
overhead (~150 ns) dwarfs the arithmetic; these loops do the same products in a few tens of
nanoseconds. Any shapes are accepted, so they also serve 3×6 regressors.
"""

import numpy as np

from etsc_envs.core.jit import jit


@jit
def dot(left: np.ndarray, right: np.ndarray) -> float:
    """``left @ right`` for two vectors of the same length."""
    total = 0.0
    for i in range(left.shape[0]):
        total += left[i] * right[i]
    return total


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

"""Information topology of the cluster (paper 001, sections 2.3, 2.4 and 4).

Nodes ``0 .. N-1`` are the followers and ``N .. N+M-1`` the leaders (the paper numbers them
``1 .. N`` and ``N+1 .. N+M``). The adjacency matrix has ``a_ij > 0`` when node ``i`` receives
information from node ``j``; the Laplacian is ``L = diag(Σ_j a_ij) - A`` and splits as eq. (6)
into ``L_F`` (followers among themselves) and ``L_FL`` (leaders to followers). Leaders receive
nothing (their rows are zero), so the last block row of eq. (6) is zero.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
from scipy.optimize import nnls

from etsc_envs.core.validation import require_float_array

MAX_WEIGHT = 1e6
"""Largest accepted a_ij. The paper's graphs have unit weights; the control law (19) and the
sliding variable (10) multiply states by the weights and their sums, which overflow to
``inf`` for weights near the float range (1e308 did on the first step)."""


def adjacency_from_edges(n_nodes: int, edges: Iterable[tuple[int, int]]) -> np.ndarray:
    """Unit-weight adjacency matrix with ``a[i, j] = 1`` for each ``(receiver i, sender j)``."""
    adjacency = np.zeros((n_nodes, n_nodes))
    for receiver, sender in edges:
        adjacency[receiver, sender] = 1.0
    return adjacency


def laplacian(adjacency: np.ndarray) -> np.ndarray:
    """``L = [l_ij]`` with ``l_ii = Σ_{j≠i} a_ij`` and ``l_ij = -a_ij`` (section 2.3)."""
    return np.diag(adjacency.sum(axis=1)) - adjacency


def laplacian_blocks(adjacency: np.ndarray, n_followers: int) -> tuple[np.ndarray, np.ndarray]:
    """``(L_F, L_FL)`` of eq. (6): the follower rows split at the follower/leader columns."""
    full = laplacian(adjacency)
    return full[:n_followers, :n_followers], full[:n_followers, n_followers:]


def reachable_from(adjacency: np.ndarray, source: int) -> set[int]:
    """Every node with a directed path from ``source`` (information flows from j to i when
    ``a_ij > 0``), ``source`` excluded unless it lies on a cycle through itself."""
    reached: set[int] = set()
    frontier = [source]
    while frontier:
        node = frontier.pop()
        for receiver in np.flatnonzero(adjacency[:, node] > 0.0):
            if receiver not in reached:
                reached.add(int(receiver))
                frontier.append(int(receiver))
    return reached


def followers_without_leader(adjacency: np.ndarray, n_followers: int) -> list[int]:
    """Followers that no leader reaches: the ones violating Assumption 3."""
    reached: set[int] = set()
    for leader in range(n_followers, adjacency.shape[0]):
        reached |= reachable_from(adjacency, leader)
    return [i for i in range(n_followers) if i not in reached]


def validate_adjacency(
    name: str, value: Sequence[Sequence[float]], n_followers: int, n_leaders: int
) -> np.ndarray:
    """``value`` as an ``(N+M)×(N+M)`` adjacency matrix, or ``ValueError`` saying what is wrong.

    Checks: finite weights in [0, :data:`MAX_WEIGHT`], no self-edges (``a_ii = 0``), no
    information into a leader (the paper's stationary leaders are not affected by other members) and
    Assumption 3 (every follower is reached by at least one leader).
    """
    n_nodes = n_followers + n_leaders
    matrix = require_float_array(name, value)
    if matrix.shape != (n_nodes, n_nodes) or not np.all(np.isfinite(matrix)):
        raise ValueError(
            f"{name} must be a finite {n_nodes}x{n_nodes} matrix ({n_followers} followers then "
            f"{n_leaders} leaders), got shape {matrix.shape}"
        )
    if np.any(matrix < 0.0) or np.any(matrix > MAX_WEIGHT):
        raise ValueError(
            f"{name} must have weights 0 <= a_ij <= {MAX_WEIGHT:g}, got a largest of "
            f"{matrix.max():g} and a smallest of {matrix.min():g}"
        )
    if np.any(np.diag(matrix) != 0.0):
        raise ValueError(f"{name} must have a zero diagonal (no self-edges, a_ii = 0)")
    if np.any(matrix[n_followers:] != 0.0):
        raise ValueError(
            f"{name}: leaders (rows {n_followers}..{n_nodes - 1}) must not receive information"
        )
    orphans = followers_without_leader(matrix, n_followers)
    if orphans:
        raise ValueError(
            f"{name} violates Assumption 3: follower(s) {orphans} (0-based) are reached by no "
            "leader, so L_F is singular and their attitude is not contained"
        )
    return matrix


def containment_weights(adjacency: np.ndarray, n_followers: int) -> np.ndarray:
    """``C = -L_F⁻¹ L_FL`` (Lemma 1, section 4.1): row ``i`` holds the convex weights of the
    leaders in follower ``i``'s steady state."""
    l_f, l_fl = laplacian_blocks(adjacency, n_followers)
    return -np.linalg.solve(l_f, l_fl)


def containment_targets(adjacency: np.ndarray, leader_attitudes: np.ndarray) -> np.ndarray:
    """``σ_d = -(L_F⁻¹ L_FL ⊗ I_3) σ_L`` of eq. (8), one row per follower."""
    n_followers = adjacency.shape[0] - len(leader_attitudes)
    return containment_weights(adjacency, n_followers) @ leader_attitudes


def is_pi1_partition(adjacency: np.ndarray, cells: Sequence[Sequence[int]]) -> bool:
    """Definition 2: in every cell, all members have the same (weighted) number of neighbours in
    each other cell. Links inside a cell are unconstrained. ``cells`` must partition the nodes."""
    members = sorted(node for cell in cells for node in cell)
    if members != list(range(adjacency.shape[0])):
        raise ValueError("cells must partition the nodes 0 .. N+M-1, each node in one cell")
    for cell in cells:
        for other in cells:
            if other is cell:
                continue
            counts = adjacency[np.ix_(list(cell), list(other))].sum(axis=1)
            if not np.allclose(counts, counts[0], rtol=0.0, atol=1e-12):
                return False
    return True


def hull_distance(point: np.ndarray, vertices: np.ndarray) -> float:
    """Euclidean distance from ``point`` to the convex hull of ``vertices`` (Definition 4).

    Minimises ‖Σ λ_j x_j - point‖ over λ ≥ 0 with Σ λ_j = 1, the sum enforced by a heavily
    weighted extra row of a non-negative least-squares problem.
    """
    weight = 1e4
    matrix = np.vstack([vertices.T, weight * np.ones(len(vertices))])
    weights, _ = nnls(matrix, np.append(point, weight))
    return float(np.linalg.norm(vertices.T @ weights - point))

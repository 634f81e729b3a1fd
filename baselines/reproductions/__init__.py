"""Reproductions of the papers' reported numbers, one module per paper."""

from __future__ import annotations

from baselines.reproductions import (
    asteroid,
    attitude_tracking,
    cluster,
    inner_formation,
    orbit_attitude,
)

REPRODUCTIONS = {
    "000": orbit_attitude,
    "001": cluster,
    "002": attitude_tracking,
    "003": asteroid,
    "004": inner_formation,
}
"""Paper number → module with ``PAPER``, ``TITLE`` and ``reproduce(plot_dir, progress)``."""

"""Reproductions of the papers' reported numbers, one module per paper."""

from __future__ import annotations

import importlib

from etsc_envs.papers import PAPERS

REPRODUCTIONS = {paper.number: importlib.import_module(paper.reproduction) for paper in PAPERS}
"""Paper number → module with ``PAPER``, ``TITLE`` and ``reproduce(plot_dir, progress)`` (each
paper record's :attr:`~etsc_envs.core.paper.Paper.reproduction`)."""

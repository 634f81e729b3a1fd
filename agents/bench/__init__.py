"""Throughput benchmarks: self-triggered decisions (:mod:`~agents.bench.decisions`), judging
a self-triggered model (:mod:`~agents.bench.judging`) and the search
(:mod:`~agents.bench.search`)."""

from __future__ import annotations

import argparse


def require_counts(parser: argparse.ArgumentParser, args: argparse.Namespace, *names: str) -> None:
    """``parser.error`` naming the first option of ``names`` (``--NAME``) that is below 1: the
    benchmarks' counts of runs and generations."""
    for name in names:
        value = getattr(args, name)
        if value < 1:
            parser.error(f"--{name} must be an integer >= 1, got {value}")

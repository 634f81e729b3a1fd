"""Throughput benchmarks: self-triggered decisions (:mod:`~agents.bench.decisions`) and judging
a self-triggered model (:mod:`~agents.bench.judging`)."""

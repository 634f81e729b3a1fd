"""Throughput of the CMA-ES search (:mod:`agents.search`) in env steps per second per core.

    python -m agents.bench.search [--config PATH ...] [--generations G] [--repeats R]

For each config (default: the searches of papers 002 and 004), ``R`` timed runs of the search
itself (:func:`agents.search.cma_es.run_search`: the config's first ``G`` generations, into a
fresh temporary folder, every candidate scored in this process), after one untimed run of one
generation that loads the compiled code. A run's env steps are those the search records
(``env_steps`` of its ``generations.jsonl``: every candidate's training episodes and the
validations of the mean). Each figure is the median [min-max] of the runs' env steps per second
of the process's CPU time (all its threads: the rate per core, steadier than wall time on a
shared machine) and per second of wall time.
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from agents.bench import require_counts
from agents.search.cma_es import Evaluator, SearchConfig, load_config, run_search

DEFAULT_CONFIGS = ("configs/search/attitude_tracking.yaml", "configs/search/inner_formation.yaml")


def time_search(config: SearchConfig) -> tuple[int, float, float]:
    """The env steps, CPU seconds and wall seconds of ``config``'s search run in this process."""
    with tempfile.TemporaryDirectory() as folder:
        wall = time.perf_counter()
        cpu = time.process_time()
        run_search(config, Path(folder), Evaluator(0, None), progress=lambda line: None)
        cpu = time.process_time() - cpu
        wall = time.perf_counter() - wall
        last = (Path(folder) / "generations.jsonl").read_text().splitlines()[-1]
    return int(json.loads(last)["env_steps"]), cpu, wall


def rates(config: SearchConfig, repeats: int) -> dict[str, list[float]]:
    """Env steps per CPU second and per wall second of ``repeats`` timed runs of the search,
    after an untimed one-generation run."""
    time_search(replace(config, generations=1))
    runs: dict[str, list[float]] = {"per_core": [], "per_wall_s": []}
    for _ in range(repeats):
        steps, cpu, wall = time_search(config)
        runs["per_core"].append(steps / cpu)
        runs["per_wall_s"].append(steps / wall)
    return runs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.bench.search", description=(__doc__ or "").split("\n\n")[0]
    )
    parser.add_argument("--config", action="append", help="configs/search/NAME.yaml (repeatable)")
    parser.add_argument("--generations", type=int, default=1, help="generations per timed run")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per config")
    args = parser.parse_args(argv)
    require_counts(parser, args, "generations", "repeats")
    try:  # every config is checked before the first is timed
        configs = [load_config(path) for path in args.config or DEFAULT_CONFIGS]
    except ValueError as error:
        parser.error(str(error))
    for path, loaded in zip(args.config or DEFAULT_CONFIGS, configs, strict=True):
        config = replace(loaded, generations=args.generations)
        for name, values in rates(config, args.repeats).items():
            print(
                f"{config.env_id} ({path}), env steps/s {name.replace('_', ' ')}: "
                f"{statistics.median(values):,.0f} [{min(values):,.0f}-{max(values):,.0f}]",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

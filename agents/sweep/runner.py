"""Training sweeps on Ray Tune: a grid (or a search) over training-config keys, every trial one
``agents.train`` run.

``python -m agents.sweep --config configs/sweeps/NAME.yaml [--address ADDR] [--resume]``

Without ``--address`` (and without ``RAY_ADDRESS``) the command starts a Ray instance on this
machine and stops it at the end; with one it joins that cluster (``ray start --head`` on one
machine, ``ray start --address HEAD:6379`` on the others, or ``ray up``). Each trial reserves
``cpus_per_trial`` cores, so Ray runs as many trials at once as the cores allow. The config's
keys are in :mod:`agents.sweep.config`; the results folder's layout in
:mod:`agents.sweep.results`.

``--resume`` continues an interrupted sweep from Tune's saved state (``Tuner.restore``):
finished and failed trials are not run again; interrupted ones start again (from their newest
checkpoint when the training config saves checkpoints).

A trial that raises is recorded as failed with its error and does not stop the others. The
command writes ``sweep_summary.json`` and prints one line per trial; it exits with 1 when a
trial failed, or when a front is incomplete, else 0.

``--processes N`` runs a grid sweep (kinds ``front`` and ``grid``, no scheduler or search)
without Ray, N trials at a time in worker processes on this machine
(:mod:`agents.sweep.processes`); it writes the same results folder, and ``--resume`` continues
it by running the trials that had not finished, also after the config's grid has grown (more
seeds or penalties: the finished trials are kept, the new points run).

Needs the ``sweep`` extra (``pip install -e ".[train,sweep]"``), except with ``--processes``.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import sys
from pathlib import Path
from typing import Any

import yaml

from agents.sweep.cluster import check_reachable, join
from agents.sweep.config import SweepConfig, load_sweep_config
from agents.sweep.processes import run_sweep_in_processes
from agents.sweep.results import (
    SweepTrial,
    one_line_error,
    trial_scores,
    trial_status,
    write_summary,
)
from etsc_envs.core.files import require_writable_folder

OPTUNA_SEED = 0
"""The seed of an Optuna search's sampler (:mod:`agents.sweep.config`)."""


def connect(address: str | None) -> None:
    """Join the Ray cluster at ``address`` (:func:`agents.sweep.cluster.join`), or start a Ray
    instance on this machine (never another one already running here, which Ray's default
    would join)."""
    import ray

    if address is None:
        ray.init(address="local", include_dashboard=False)
        return
    join(address)


def build_tuner(sweep: SweepConfig, resume: bool) -> Any:
    """A ``Tuner`` for the sweep: new, or restored from its saved state when ``resume``."""
    from ray import tune

    from agents.sweep.trial import run_trial, trial_dirname

    trainable = tune.with_resources(
        tune.with_parameters(run_trial, sweep=sweep), {"cpu": sweep.cpus_per_trial}
    )
    if resume:
        return tune.Tuner.restore(str(sweep.tune_dir), trainable=trainable)
    return tune.Tuner(
        trainable,
        param_space=_param_space(sweep),
        tune_config=tune.TuneConfig(
            num_samples=sweep.num_samples,
            max_concurrent_trials=sweep.max_concurrent_trials,
            scheduler=_scheduler(sweep),
            search_alg=_search_algorithm(sweep),
            metric=sweep.metric,
            mode=sweep.mode,
            trial_dirname_creator=functools.partial(trial_dirname, sweep),
        ),
        run_config=tune.RunConfig(
            name=sweep.tune_dir.name,
            storage_path=str(sweep.tune_dir.parent),
            failure_config=tune.FailureConfig(max_failures=0, fail_fast=False),
        ),
    )


def _param_space(sweep: SweepConfig) -> dict[str, Any]:
    from ray import tune

    space: dict[str, Any] = {key: tune.grid_search(values) for key, values in sweep.grid.items()}
    for key, spec in sweep.search.items():
        ((distribution, arguments),) = spec.items()
        sampler = getattr(tune, distribution)
        space[key] = sampler(arguments) if distribution == "choice" else sampler(*arguments)
    return space


def _scheduler(sweep: SweepConfig) -> Any:
    if sweep.scheduler is None:
        return None
    from ray.tune.schedulers import ASHAScheduler

    grace = sweep.grace_timesteps or max(sweep.total_timesteps // 10, 1)
    return ASHAScheduler(
        time_attr="timesteps",
        max_t=sweep.total_timesteps,
        grace_period=min(grace, sweep.total_timesteps),
    )


def _search_algorithm(sweep: SweepConfig) -> Any:
    if sweep.search_algorithm is None:
        return None
    from ray.tune.search.optuna import OptunaSearch

    return OptunaSearch(points_to_evaluate=[sweep.search_start], seed=OPTUNA_SEED)


def summarize(sweep: SweepConfig, results: Any) -> list[SweepTrial]:
    """Every trial of Tune's ``ResultGrid`` as the summary records it, in Tune's order (the
    grid's), and, for a grid, the points that Tune had not started when it was interrupted."""
    grid_values = {}
    if not sweep.search:
        grid_values = {sweep.trial_name(point): point for point in sweep.grid_points()}
    trials = []
    for result in results:
        name = Path(result.path).name
        folder = sweep.trial_folder(name)
        error = None if result.error is None else one_line_error(result.error)
        values = result.config or _started_values(result.path) or grid_values.get(name, {})
        runs = [run for _, run in sweep.trial_runs(values, folder)]
        trials.append(
            SweepTrial(
                name=name,
                values={key: values[key] for key in sweep.swept_keys if key in values},
                status=trial_status(runs, error),
                error=error,
                folder=folder,
                scores=trial_scores(runs) if error is None else None,
            )
        )
    if grid_values:  # grid points that Tune had not created when it was interrupted
        started = {trial.name for trial in trials}
        trials += [
            SweepTrial(name, values, "incomplete", None, sweep.trial_folder(name), None)
            for name, values in grid_values.items()
            if name not in started
        ]
    return trials


def _started_values(tune_trial_dir: str) -> dict[str, Any]:
    """The values of a trial that never reported (no config in its result), from the
    ``params.json`` Tune writes when a trial starts; empty if it never started (a grid
    point's values then follow from its name, a search trial's were not drawn)."""
    params = Path(tune_trial_dir) / "params.json"
    return json.loads(params.read_text(encoding="utf-8")) if params.is_file() else {}


def run_sweep(sweep: SweepConfig, address: str | None, resume: bool) -> list[SweepTrial]:
    """Run (or resume) the sweep on Ray, write its summary and return its trials."""
    import ray
    from ray import tune

    if resume and not tune.Tuner.can_restore(str(sweep.tune_dir)):
        raise ValueError(f"--resume: no saved sweep in {str(sweep.tune_dir)!r} to continue")
    if address is not None:
        check_reachable(address)  # before anything is written
    sweep.start_or_continue(resume, sweep.tune_dir.exists() or sweep.trials_dir.exists())
    connect(address)
    try:
        results = build_tuner(sweep, resume).fit()
    finally:
        ray.shutdown()
    trials = summarize(sweep, results)
    write_summary(sweep.results_dir, _description(sweep), trials)
    return trials


def _description(sweep: SweepConfig) -> dict[str, Any]:
    return {
        "sweep": sweep.path,
        "env_id": sweep.base["env_id"],
        "kind": sweep.kind,
        "swept_keys": sweep.swept_keys,
    }


def _report(sweep: SweepConfig, trials: list[SweepTrial]) -> int:
    """Print one line per trial and the exit code of the sweep."""
    for trial in trials:
        detail = trial.error if trial.status == "failed" else ""
        if trial.status == "finished" and trial.scores:
            detail = " ".join(f"{key} {value:.4g}" for key, value in trial.scores.items())
        print(f"{trial.status:10s} {trial.name}  {detail}".rstrip())
    incomplete = [trial for trial in trials if trial.status == "incomplete"]
    if incomplete:
        print(f"{len(incomplete)} trial(s) incomplete; continue with --resume", file=sys.stderr)
    print(f"wrote {Path(sweep.results_dir) / 'sweep_summary.json'}")
    failed = any(trial.status == "failed" for trial in trials)
    return 1 if failed or (sweep.kind == "front" and incomplete) else 0


def build_parser() -> argparse.ArgumentParser:
    """The command line of :func:`main`."""
    parser = argparse.ArgumentParser(
        prog="python -m agents.sweep",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--config", required=True, type=Path, help="YAML sweep config")
    parser.add_argument(
        "--address",
        help="Ray cluster to run on (HOST:PORT, ray://HOST:PORT or auto; default RAY_ADDRESS, "
        "else a Ray instance started on this machine)",
    )
    parser.add_argument(
        "--resume", action="store_true", help="continue the interrupted sweep of the config"
    )
    parser.add_argument(
        "--processes",
        type=int,
        metavar="N",
        help="run a grid sweep without Ray, N trials at a time in processes on this machine",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line: validate the config, run the sweep, report its trials."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.processes is not None and args.address is not None:
        parser.error("--address joins a Ray cluster; --processes runs without Ray")
    if args.processes is None:
        try:
            import ray  # noqa: F401
            from ray import tune  # noqa: F401
        except ImportError:
            parser.error('Ray Tune is not installed: pip install -e ".[train,sweep]"')
    address = args.address or os.environ.get("RAY_ADDRESS") or None
    try:
        sweep = load_sweep_config(args.config)
        require_writable_folder(sweep.results_dir, "results_dir")
        if args.processes is None:
            trials = run_sweep(sweep, address, args.resume)
        else:
            trials = run_sweep_in_processes(sweep, args.processes, args.resume, _description(sweep))
    except (OSError, ValueError, yaml.YAMLError) as error:
        parser.error(str(error))
    except KeyboardInterrupt:
        processes = "" if args.processes is None else f" --processes {args.processes}"
        print(
            f"\ninterrupted; finished trials are kept, continue the sweep with: python -m "
            f"agents.sweep --config {args.config}{processes} --resume",
            file=sys.stderr,
        )
        return 130
    return _report(sweep, trials)

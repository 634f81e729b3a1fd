"""A grid sweep on this machine's cores without Ray: every trial one ``agents.train`` run in a
worker process of a process pool.

``python -m agents.sweep --config configs/sweeps/NAME.yaml --processes N`` takes this path.
It writes the same results folder as the Ray path (:mod:`agents.sweep.results`: the trials'
folders, ``sweep_settings.json`` and ``sweep_summary.json``, no ``tune/``), so that
``agents.results --sweep`` and ``agents.judge.pareto --sweep`` read either. It runs grids
only (kinds ``front`` and ``grid`` without a scheduler or a search, which need Tune). A trial
whose training had finished is not run again, so the same command continues an interrupted sweep; an
unfinished trial starts again from its newest checkpoint where its config saves them.

Workers are spawned, not forked: a forked child of a process that has run torch can deadlock
in its OpenMP pool (the reason :mod:`etsc_envs.evaluation.batch` spawns too). A sweep stops as
Ctrl-C stops it on SIGTERM too (``kill PID``: a background job ignores SIGINT), and its
workers end with it however it ends, so no trial trains on unseen.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from agents.sweep.config import SweepConfig
from agents.sweep.learners import run_trial
from agents.sweep.results import (
    SweepTrial,
    one_line_error,
    trial_finished,
    trial_scores,
    trial_status,
    write_summary,
)
from etsc_envs.evaluation.batch import die_with_parent


def check_process_sweep(sweep: SweepConfig, processes: int) -> None:
    """``ValueError`` unless ``processes`` is a count >= 1 and the sweep is a grid that needs
    no Tune scheduler or search."""
    if isinstance(processes, bool) or not isinstance(processes, int) or processes < 1:
        raise ValueError(f"--processes must be an integer >= 1, got {processes!r}")
    if sweep.search or sweep.scheduler is not None or sweep.search_algorithm is not None:
        raise ValueError(
            "--processes runs grid sweeps only (no search, scheduler or search_algorithm); "
            f"{sweep.path} needs Ray Tune: leave --processes out"
        )


def _run_trial(sweep: SweepConfig, values: dict[str, Any], folder: Path) -> str | None:
    """Train one trial into ``folder`` (continuing from its newest checkpoint if it has one);
    ``None`` on success, else the error as ``Type: first line``."""
    if _STOP is not None and _STOP.is_set():
        return "interrupted"
    signal.signal(signal.SIGINT, signal.default_int_handler)  # a running trial stops on Ctrl-C
    try:
        run_trial(sweep, values, folder)
    except Exception as error:  # a failed trial is recorded, the others go on
        return one_line_error(error)
    except KeyboardInterrupt:  # the sweep's runner says how to continue
        return "interrupted"
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    return None


_STOP: Any = None
"""In a worker: the runner's event, set when the sweep is interrupted."""


def _start_worker(stop: Any, parent: int) -> None:
    """A worker between trials ignores Ctrl-C (the terminal sends it to every process of the
    sweep): the runner stops the pool, and only a running trial stops on it; once ``stop`` is
    set, a trial still queued to the worker returns without training. The worker ends when
    the runner's process ``parent`` does, even if it is killed."""
    global _STOP
    _STOP = stop
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent(parent)


@contextlib.contextmanager
def _terminate_as_interrupt() -> Iterator[None]:
    """While the trials run, SIGTERM raises ``KeyboardInterrupt`` in the runner as Ctrl-C does
    (where this is the main thread, the only one that may set a handler)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def interrupt(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def run_sweep_in_processes(
    sweep: SweepConfig, processes: int, resume: bool, description: dict[str, Any]
) -> list[SweepTrial]:
    """Start the sweep (or continue it if ``resume``, a grown grid too:
    :meth:`~agents.sweep.config.SweepConfig.start_or_continue`), run the grid's unfinished
    trials, ``processes`` at a time, write the summary (with ``description``, the sweep's
    header) and return every trial in the grid's order."""
    check_process_sweep(sweep, processes)
    sweep.start_or_continue(resume, sweep.trials_dir.exists(), grid_may_grow=True)
    points = {sweep.trial_name(values): values for values in sweep.grid_points()}
    pending = {
        name: values
        for name, values in points.items()
        if not trial_finished(sweep.trial_folder(name))
    }
    errors: dict[str, str | None] = {}
    if pending:
        context = multiprocessing.get_context("spawn")
        stop = context.Event()
        with (
            _terminate_as_interrupt(),
            ProcessPoolExecutor(
                min(processes, len(pending)),
                mp_context=context,
                initializer=_start_worker,
                initargs=(stop, os.getpid()),
            ) as pool,
        ):
            futures = {
                name: pool.submit(_run_trial, sweep, values, sweep.trial_folder(name))
                for name, values in pending.items()
            }
            try:
                errors = {name: future.result() for name, future in futures.items()}
            except KeyboardInterrupt:
                stop.set()  # trials queued to a worker already return at once
                pool.shutdown(wait=False, cancel_futures=True)
                for worker in multiprocessing.active_children():  # a running trial stops
                    if worker.pid is not None:
                        os.kill(worker.pid, signal.SIGINT)
                raise
    trials = []
    for name, values in points.items():
        folder = sweep.trial_folder(name)
        error = errors.get(name)
        trials.append(
            SweepTrial(
                name=name,
                values=values,
                status=trial_status([folder], error),
                error=error,
                folder=folder,
                scores=trial_scores([folder]) if error is None else None,
            )
        )
    write_summary(sweep.results_dir, description, trials)
    return trials

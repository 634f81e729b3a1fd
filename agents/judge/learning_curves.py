"""How fast each decision structure learns: validation curves of training runs against
simulated instants and wall-clock time.

    python -m agents.judge.learning_curves --run LABEL=RUN_DIR [--run LABEL=RUN_DIR ...]
                                     [--include LEARNING_CURVES_JSON ...]
                                     [--cost-tolerance 1.05] [--out DIR]

Each ``RUN_DIR`` is the output folder of ``python -m agents.train`` (its ``evaluations.json``:
the policy and the paper trigger on the validation scenarios, with the sampling instants
simulated for training so far and the training wall time at every evaluation) or of
``python -m agents.search`` (its ``generations.jsonl``, or in a committed record its
``curve.json``: the validated mean of the evolution strategy, against the paper trigger run
once on the same validation scenarios; a ``curve.json`` older than its ``validation_failures``
key leaves the mean's failures unknown, and such a run reaches the paper trigger on cost and
transmissions alone).
``--include LEARNING_CURVES_JSON`` keeps the methods of an earlier result (runs whose folders
are no longer at hand) beside the new runs. Runs with the
same ``LABEL`` (one method, several training seeds) are drawn in one colour and summarised
together.

A run **reaches the paper trigger** at its first evaluation of a trained policy
(:mod:`agents.train.kept_checkpoint`; an untrained network is drawn but reaches nothing) whose
validation ``mean_cost`` is at most ``cost_tolerance`` times the paper trigger's and whose
transmissions are at most the paper trigger's: as accurate (within the goal's tolerance) on no
more transmissions. Cost alone
would be reached by a policy that transmits at every instant. The report gives, per run, the
instants and seconds it took (``null`` if it never did) and, per label, the median and range
over the runs that reached it.

Per label with two or more runs, ``bands`` holds the interval over seeds: on a grid of
:data:`BAND_POINTS` abscissae across the range every run covers (instants, seconds), the
geometric mean of the runs' ratios (each run interpolated in log ratio) with the 95 % bootstrap
interval of that mean (:func:`~etsc_envs.evaluation.statistics.summarize` of the logs). The
figure draws each band and its mean over the runs' own curves.

Writes ``learning_curves.json`` and ``learning_curves.png`` (cost and transmissions relative to
the paper trigger against instants and against seconds) into ``DIR`` (default
``results/learning_curves``).
"""

from __future__ import annotations

import argparse
import functools
import json
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from agents.train.kept_checkpoint import may_be_kept
from baselines.plotting import save
from etsc_envs.core.files import output_folder_argument, require_writable_folder
from etsc_envs.core.json_files import in_file, read_json_file, read_json_lines, require_mapping
from etsc_envs.evaluation.arguments import write_json
from etsc_envs.evaluation.statistics import summarize

DEFAULT_COST_TOLERANCE = 1.05
"""The goal's cost tolerance: within 5 % of the paper trigger's ``mean_cost``."""


BAND_POINTS = 40
"""Abscissae of a label's interval over seeds."""

ZERO_LINEAR_RANGE = 0.1
"""Where a ratio reaches 0 its axis is symmetric-log, linear within this range of 0."""

AXES = ("env_steps", "wall_time_s")
RATIOS = ("cost_ratio", "transmission_ratio")

RUN_RECORDS = ("evaluations.json", "generations.jsonl", "curve.json")
"""A training run's validation record (``agents.train``) or a search's (``agents.search``: its
generations, or the curve a committed record keeps of them)."""


def parse_runs(specs: list[str]) -> list[tuple[str, Path]]:
    """``LABEL=RUN_DIR`` pairs, each folder holding an ``evaluations.json``."""
    runs = []
    for spec in specs:
        label, separator, folder = spec.partition("=")
        if not separator or not label or not folder:
            raise ValueError(f"--run must be LABEL=RUN_DIR, got {spec!r}")
        if not any((Path(folder) / name).is_file() for name in RUN_RECORDS):
            raise ValueError(f"--run {spec}: no {' or '.join(RUN_RECORDS)} in {folder}")
        runs.append((label, Path(folder)))
    if not runs:
        raise ValueError("--run: give at least one LABEL=RUN_DIR")
    return runs


def search_validations(folder: Path) -> list[dict[str, Any]]:
    """The validated mean of each validating generation of the search in ``folder``: from
    ``generations.jsonl`` (a torn last line, a generation being written, is left out), else
    from ``curve.json`` (``failures`` ``None`` where the curve does not keep them); each with
    its ``env_steps`` and ``wall_s``."""
    generations = folder / "generations.jsonl"
    if generations.is_file():
        records, _ = read_json_lines(generations, generations.name)
        with _record_keys(generations.name):
            return [
                {"env_steps": r["env_steps"], "wall_s": r["wall_s"], **r["validation"]}
                for r in records
                if "validation" in r
            ]
    curve_file = folder / "curve.json"
    with _record_keys(curve_file.name):
        return [
            {
                "env_steps": entry["env_steps"],
                "wall_s": entry["wall_s"],
                "mean_cost": entry["validation_cost"],
                "transmissions": entry["validation_transmissions"],
                "failures": entry.get("validation_failures"),
            }
            for entry in read_json_file(curve_file, curve_file.name)["curve"]
            if "validation_cost" in entry
        ]


@contextmanager
def _record_keys(name: str) -> Iterator[None]:
    """A record of the wrong shape (a key missing, a list for a mapping) as one ``ValueError``
    naming the file ``name``."""
    try:
        yield
    except (KeyError, TypeError, AttributeError) as error:
        raise ValueError(
            f"{name}: not a record of agents.train or agents.search ({error!r})"
        ) from None


@functools.cache
def paper_validation(env_id: str, env_args_json: str, set_size: int) -> dict[str, Any]:
    """The paper trigger's means (and failure count) on the first ``set_size`` validation
    scenarios of ``env_id`` with the env args of ``env_args_json``, evaluated once per process
    (the evaluation is deterministic): the searches of one configuration share it."""
    from baselines.evaluate import evaluate

    evaluated = evaluate(
        env_id,
        "paper",
        env_args=json.loads(env_args_json),
        scenarios="validation",
        set_size=set_size,
    )
    return {**evaluated["mean"], "failures": evaluated["aggregates"]["failure"]["count"]}


def search_evaluations(folder: Path) -> list[dict[str, Any]]:
    """A search's validation curve (:func:`search_validations`) in the form of a training
    run's ``evaluations.json``, the paper trigger evaluated once on the same validation
    scenarios (those of the search's ``config.yaml``) as the reference."""
    from agents.search.cma_es import config_from_dict, read_config

    path = folder / "config.yaml"
    raw = read_config(path, where=path.name)
    with in_file(path.name):
        config = config_from_dict(raw)
    paper = paper_validation(
        config.env_id,
        json.dumps(config.env_args(training=False), sort_keys=True),
        config.validation_size,
    )
    return [
        {
            "timesteps": validation["env_steps"],
            "env_steps": validation["env_steps"],
            "wall_time_s": validation["wall_s"],
            "learned": validation,
            "paper": paper,
        }
        for validation in search_validations(folder)
    ]


def run_curve(folder: Path, cost_tolerance: float) -> dict[str, Any]:
    """One run's validation curve relative to the paper trigger, and where it reached it."""
    record = folder / "evaluations.json"
    if record.is_file():
        evaluations = read_json_file(record, record.name)
    else:
        evaluations = search_evaluations(folder)
    with _record_keys(record.name):
        missing = [entry["timesteps"] for entry in evaluations if "env_steps" not in entry]
        if missing:
            raise ValueError(
                f"evaluations at {missing} record no env_steps (trained before they were "
                f"logged); retrain to compare learning speed"
            )
        points = []
        for entry in evaluations:
            learned, paper = entry["learned"], entry["paper"]
            points.append(
                {
                    "timesteps": entry["timesteps"],
                    "env_steps": entry["env_steps"],
                    "wall_time_s": entry["wall_time_s"],
                    "cost_ratio": learned["mean_cost"] / paper["mean_cost"],
                    "transmission_ratio": learned["transmissions"] / paper["transmissions"],
                    "failures": learned["failures"],
                    "trained": may_be_kept(entry),
                }
            )
        if not points:
            raise ValueError("no validation recorded yet")
        paper_failures = evaluations[0]["paper"]["failures"]
    reached = next(
        (
            point
            for point in points
            if point["trained"]
            and point["cost_ratio"] <= cost_tolerance
            and point["transmission_ratio"] <= 1.0
            and (point["failures"] is None or point["failures"] <= paper_failures)
        ),
        None,
    )
    return {
        "run": str(folder),
        "points": points,
        "reached_at_env_steps": None if reached is None else reached["env_steps"],
        "reached_at_wall_time_s": None if reached is None else reached["wall_time_s"],
    }


def _spread(values: list[float]) -> dict[str, Any]:
    if not values:
        return {"median": None, "range": None}
    return {"median": float(np.median(values)), "range": [min(values), max(values)]}


def seed_bands(runs: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The interval over seeds of the module docstring for one label's runs (``None`` for
    fewer than two, or where their abscissae share no range; a ratio's band is ``None`` where
    a run's ratio reaches 0, which has no logarithm)."""
    if len(runs) < 2:
        return None
    bands: dict[str, Any] = {}
    for x_key in AXES:
        low = max(run["points"][0][x_key] for run in runs)
        high = min(run["points"][-1][x_key] for run in runs)
        if not high > low:
            return None
        grid = np.linspace(low, high, BAND_POINTS)
        band: dict[str, Any] = {"x": grid.tolist()}
        for y_key in RATIOS:
            values = [np.array([point[y_key] for point in run["points"]]) for run in runs]
            if any(np.any(ratios <= 0.0) for ratios in values):
                band[y_key] = None
                continue
            logs = np.array(
                [
                    np.interp(grid, [point[x_key] for point in run["points"]], np.log(ratios))
                    for run, ratios in zip(runs, values, strict=True)
                ]
            )
            summaries = [summarize(column) for column in logs.T]
            band[y_key] = {
                "geometric_mean": [float(np.exp(item["mean"])) for item in summaries],
                "ci95": [[float(np.exp(v)) for v in item["mean_ci95"]] for item in summaries],
            }
        bands[x_key] = band
    return bands


def read_earlier(path: Path) -> dict[str, Any]:
    """The ``learning_curves.json`` given to ``--include``, refused in one line naming the
    option when it cannot be read or is not such a result."""
    result = read_json_file(path, f"--include {path}")
    if not isinstance(result, dict) or not isinstance(result.get("methods"), dict):
        raise ValueError(
            f"--include {path}: not a learning_curves.json (no 'methods' object); give the "
            "file python -m agents.judge.learning_curves wrote"
        )
    return result


def learning_curves(
    runs: list[tuple[str, Path]],
    cost_tolerance: float,
    earlier: list[dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """Every run's curve, grouped by label, with the per-label summary of the module
    docstring; the methods of ``earlier`` results (``learning_curves.json`` of runs whose
    folders are gone) are kept beside them."""
    if not cost_tolerance >= 1.0:
        raise ValueError(f"--cost-tolerance must be at least 1, got {cost_tolerance!r}")
    methods: dict[str, dict[str, Any]] = {}
    for result in earlier or []:
        if result.get("cost_tolerance") != cost_tolerance:
            raise ValueError(
                f"--include: that result used cost tolerance {result.get('cost_tolerance')}, "
                f"not {cost_tolerance}"
            )
        methods.update(result["methods"])
    for label, folder in runs:
        with in_file(f"--run {label}={folder}"):
            curve = run_curve(folder, cost_tolerance)
        methods.setdefault(label, {"runs": []})["runs"].append(curve)
    for method in methods.values():
        method["bands"] = seed_bands(method["runs"])
        reached = [run for run in method["runs"] if run["reached_at_env_steps"] is not None]
        method["reached"] = f"{len(reached)}/{len(method['runs'])}"
        method["env_steps_to_reach"] = _spread([run["reached_at_env_steps"] for run in reached])
        method["wall_time_s_to_reach"] = _spread([run["reached_at_wall_time_s"] for run in reached])
    return {"cost_tolerance": cost_tolerance, "methods": methods}


def plot(result: dict[str, Any], path: Path) -> None:
    """Cost and transmissions relative to the paper trigger, against instants and seconds."""
    figure, axes = plt.subplots(2, 2, figsize=(11, 7.5), sharey="row")
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    if len(result["methods"]) > len(colours):  # a colour per method, none repeated
        colours = [plt.get_cmap("tab20")(i) for i in range(20)]
    legend = []  # one entry per method, drawn whether or not its band exists on every panel
    for index, (label, method) in enumerate(result["methods"].items()):
        colour = colours[index % len(colours)]
        bands = method.get("bands")
        seeds = len(method["runs"])
        legend.append(
            Line2D(
                [],
                [],
                color=colour,
                linewidth=2.0 if bands else 1.5,
                marker="" if bands else ".",
                label=f"{label} ({seeds} run{'s' if seeds > 1 else ''})",
            )
        )
        for run in method["runs"]:
            points = run["points"]
            for column, x_key in enumerate(AXES):
                x = [point[x_key] for point in points]
                for row, y_key in enumerate(RATIOS):
                    axes[row, column].plot(
                        x,
                        [point[y_key] for point in points],
                        color=colour,
                        alpha=0.25 if bands else 0.8,
                        linewidth=0.8 if bands else 1.5,
                        marker="" if bands else ".",
                    )
        if not bands:
            continue
        for column, x_key in enumerate(AXES):
            band = bands[x_key]
            for row, y_key in enumerate(RATIOS):
                if band[y_key] is None:
                    continue
                low, high = np.array(band[y_key]["ci95"]).T
                axes[row, column].fill_between(band["x"], low, high, color=colour, alpha=0.25)
                axes[row, column].plot(
                    band["x"],
                    band[y_key]["geometric_mean"],
                    color=colour,
                    linewidth=2.0,
                )
    zero = {
        y_key: any(
            point[y_key] == 0.0
            for method in result["methods"].values()
            for run in method["runs"]
            for point in run["points"]
        )
        for y_key in RATIOS
    }
    for row, (y_key, name) in enumerate(
        zip(RATIOS, ("mean_cost / paper", "transmissions / paper"), strict=True)
    ):
        axes[row, 0].set_ylabel(name + (" (symlog: 0 drawn)" if zero[y_key] else ""))
        for column in range(2):
            axes[row, column].axhline(1.0, color="k", linewidth=0.8, linestyle=":")
            if zero[y_key]:  # a ratio of 0 (003's shell kept: no cost) has no logarithm
                axes[row, column].set_yscale("symlog", linthresh=ZERO_LINEAR_RANGE)
                axes[row, column].set_ylim(bottom=-0.1 * ZERO_LINEAR_RANGE)
            else:
                axes[row, column].set_yscale("log")
            axes[row, column].grid(True, which="major", alpha=0.3)
    for column in range(2):
        axes[0, column].axhline(result["cost_tolerance"], color="k", linewidth=0.8, linestyle="--")
    for row in range(2):  # budgets span 10^6 (PPO) to 10^8 (a large search) instants
        axes[row, 0].set_xscale("log")
    axes[1, 0].set_xlabel("sampling instants simulated for training")
    axes[1, 1].set_xlabel("training wall time (s)")
    figure.legend(handles=legend, loc="lower center", ncol=3, frameon=False)
    figure.suptitle(
        "validation scenarios: learned trigger relative to the paper's (thin: runs; bold and "
        "shaded: geometric mean over seeds, 95 % interval)",
        fontsize=10,
    )
    rows = -(-len(legend) // 3)
    figure.tight_layout(rect=(0, 0.035 + 0.03 * rows, 1, 0.95))
    save(figure, path)


def curve_runs(result: dict[str, Any]) -> set[tuple[str, str]]:
    """The (label, run folder) of every run of a ``learning_curves.json``."""
    return {
        (label, str(run["run"]))
        for label, method in result["methods"].items()
        for run in method["runs"]
    }


def require_own_curves(out_dir: Path, runs: list[tuple[str, Path]], earlier: list[dict]) -> None:
    """``ValueError`` before any work when ``out_dir`` holds the ``learning_curves.json`` of
    other runs: the same runs are drawn again in place, another comparison gets its own
    folder."""
    path = out_dir / "learning_curves.json"
    if not path.exists():
        return
    held = curve_runs(require_mapping(read_json_file(path, f"--out {path}"), ""))
    mine = {(label, str(folder)) for label, folder in runs}.union(*map(curve_runs, earlier))
    if held != mine:
        raise ValueError(
            f"--out {out_dir} holds the learning curves of {len(held)} other runs "
            f"({', '.join(sorted({label for label, _ in held}))}); give these runs their own --out"
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.judge.learning_curves",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--run", action="append", default=[], metavar="LABEL=RUN_DIR")
    parser.add_argument(
        "--include",
        action="append",
        default=[],
        type=Path,
        metavar="LEARNING_CURVES_JSON",
        help="keep the methods of an earlier result beside the runs (repeatable)",
    )
    parser.add_argument("--cost-tolerance", type=float, default=DEFAULT_COST_TOLERANCE)
    parser.add_argument("--out", type=output_folder_argument("--out"), help="output folder")
    args = parser.parse_args(argv)
    out_dir = args.out or Path("results") / "learning_curves"
    try:
        require_writable_folder(out_dir, "--out")
        earlier = [read_earlier(path) for path in args.include]
        runs = parse_runs(args.run) if args.run or not earlier else []
        require_own_curves(out_dir, runs, earlier)
        result = learning_curves(runs, args.cost_tolerance, earlier)
    except (ValueError, OSError, KeyError) as error:
        parser.error(str(error))
    write_json(result, str(out_dir / "learning_curves.json"))
    plot(result, out_dir / "learning_curves.png")
    for label, method in result["methods"].items():
        steps, seconds = method["env_steps_to_reach"], method["wall_time_s_to_reach"]
        print(
            f"{label}: reached the paper trigger in {method['reached']} runs; instants "
            f"{steps['median']} {steps['range']}, seconds {seconds['median']} {seconds['range']}"
        )
    print(f"wrote {out_dir / 'learning_curves.json'} and {out_dir / 'learning_curves.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

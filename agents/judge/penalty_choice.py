"""Which penalty of a front a report takes, chosen on the validation set alone.

A run's transmission penalty λ sets where its trigger lands on the trade-off between cost
and transmissions: at the headline's own λ a search may trade transmissions for cost and
leave the headline's rate (paper 000 at λ = 1 went to 2-3 × the headline's transmissions).
The goal asks first that the learned trigger *contain* a reference (no more mean cost and no
more transmissions), so the front's λ is chosen by that criterion, read where choices are made:

* a front of **searches** (``learner: search``) validates each search's start (the menu's
  best rule, from which every search starts) at its first generation and its chosen point at
  the generation it chose, on the same validation scenarios (:mod:`agents.search.cma_es`,
  ``curve.json``): the reference is the start;
* a front of **training runs** (``learner: train``, swept over
  ``env_kwargs.transmission_penalty``) validates the paper's rule once and the policy at every
  evaluation, on the same validation scenarios
  (:class:`~agents.train.validation_callback.PaperComparisonCallback`, ``evaluations.json``):
  the reference is the paper's rule, the chosen point the evaluation of the best validation
  return (the checkpoint ``best_model.zip`` keeps);
* per λ, the mean over the seeds of the chosen points' validation (transmissions, mean cost)
  **contains** the reference's mean when neither exceeds it;
* the chosen λ is the **largest** that contains (the suite's question is communicating less
  at the same accuracy); none, where no λ does. ``closest`` then names the λ whose mean comes
  nearest, the smallest larger ratio to the reference (``max`` of transmissions and cost ratio),
  which a report may show as "no λ reached the reference; the closest".

The test set is not read. ::

    python -m agents.judge.penalty_choice RESULTS_DIR [--json PATH]

prints one line per λ and the choice, and with ``--json`` writes them.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from agents.sweep.results import EVALUATIONS_FILE, SEARCH_CURVE_FILE, read_sweep
from agents.train.kept_checkpoint import kept_evaluation
from etsc_envs.core.files import output_file_argument
from etsc_envs.evaluation.arguments import write_json

PENALTY_KEYS = ("penalty", "env_kwargs.transmission_penalty")
"""The swept key that is λ: a search config's, a training config's."""

Point = tuple[float, float]


def validation_points(folder: Path) -> tuple[Point, Point]:
    """The (transmissions, mean cost) on the validation set of a trial's reference and of its
    chosen point: a search's start (its first validation) and chosen generation, from its
    ``curve.json``; a training run's paper rule and best-return evaluation, from its
    ``evaluations.json``."""
    path = folder / SEARCH_CURVE_FILE
    if not path.is_file():
        return training_points(folder)
    record = json.loads(path.read_text(encoding="utf-8"))
    validated = [row for row in record["curve"] if "validation_cost" in row]
    chosen = record["search"]["chosen_generation"]
    (best,) = [row for row in validated if row["generation"] == chosen]

    def point(row: dict[str, Any]) -> tuple[float, float]:
        return float(row["validation_transmissions"]), float(row["validation_cost"])

    return point(validated[0]), point(best)


def training_points(folder: Path) -> tuple[Point, Point]:
    """A training run's paper rule and the evaluation of the checkpoint it keeps (the best
    validation return of a trained policy, the first of equal ones:
    :func:`~agents.train.kept_checkpoint.kept_evaluation`), from its ``evaluations.json``."""
    path = folder / EVALUATIONS_FILE
    if not path.is_file():
        raise ValueError(
            f"RESULTS_DIR: trial {folder.name!r} holds neither {SEARCH_CURVE_FILE} nor "
            f"{EVALUATIONS_FILE} (a training run validates with evaluation_every)"
        )
    evaluations = json.loads(path.read_text(encoding="utf-8"))
    if not evaluations:
        raise ValueError(f"RESULTS_DIR: trial {folder.name!r} has no evaluation")
    best = kept_evaluation(evaluations)
    if best is None:
        raise ValueError(f"RESULTS_DIR: trial {folder.name!r} validated no trained policy")

    def point(summary: dict[str, Any]) -> Point:
        return float(summary["transmissions"]), float(summary["mean_cost"])

    return point(best["paper"]), point(best["learned"])


def choose_penalty(results_dir: str | Path) -> dict[str, Any]:
    """Per penalty of the sweep in ``results_dir`` (a front of searches or of training runs):
    its seeds, the mean of their chosen validation points, the reference's (key ``start``),
    whether the mean contains it and its larger ratio to it; ``chosen``, the largest penalty
    that contains (``None`` if none), and ``closest``, the penalty of the smallest larger
    ratio. ``ValueError`` if a trial did not finish or the sweep varies more than penalty and
    seed."""
    trials = read_sweep(results_dir, "RESULTS_DIR")
    by_penalty: dict[float, list[tuple[Point, Point]]] = {}
    references: set[str] = set()
    for trial in trials:
        keys = [key for key in PENALTY_KEYS if set(trial.values) == {key, "seed"}]
        if not keys:
            raise ValueError(
                f"RESULTS_DIR: {str(results_dir)!r} sweeps {sorted(trial.values)}, not a front "
                f"over a penalty ({' or '.join(PENALTY_KEYS)}) and seed"
            )
        if trial.status != "finished":
            raise ValueError(
                f"RESULTS_DIR: trial {trial.name!r} is {trial.status}; finish the sweep first"
            )
        references.add("start" if keys[0] == "penalty" else "paper rule")
        by_penalty.setdefault(float(trial.values[keys[0]]), []).append(
            validation_points(trial.folder)
        )
    penalties = []
    for penalty, runs in sorted(by_penalty.items()):
        start = np.mean([start for start, _ in runs], axis=0)
        chosen = np.mean([chosen for _, chosen in runs], axis=0)
        ratios = [
            c / s if s > 0 else (1.0 if c == 0 else np.inf)
            for c, s in zip(chosen, start, strict=True)
        ]
        penalties.append(
            {
                "penalty": penalty,
                "seeds": len(runs),
                "start": {"transmissions": float(start[0]), "mean_cost": float(start[1])},
                "learned": {"transmissions": float(chosen[0]), "mean_cost": float(chosen[1])},
                "contains_start": bool(chosen[0] <= start[0] and chosen[1] <= start[1]),
                "larger_ratio": float(max(ratios)),
            }
        )
    if len(references) != 1:
        raise ValueError(f"RESULTS_DIR: {str(results_dir)!r} mixes searches and training runs")
    (reference,) = references
    containing = [row["penalty"] for row in penalties if row["contains_start"]]
    return {
        "results_dir": str(results_dir),
        "reference": reference,
        "criterion": "largest penalty whose seeds' mean validation point contains the "
        f"{reference}'s",
        "penalties": penalties,
        "chosen": max(containing) if containing else None,
        "closest": min(penalties, key=lambda row: row["larger_ratio"])["penalty"],
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.judge.penalty_choice",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("results_dir", type=Path, metavar="RESULTS_DIR")
    parser.add_argument("--json", type=output_file_argument("--json"), help="write the choice")
    args = parser.parse_args(argv)
    try:
        choice = choose_penalty(args.results_dir)
    except (ValueError, OSError) as error:
        parser.error(str(error))
    for row in choice["penalties"]:
        learned, start = row["learned"], row["start"]
        print(
            f"penalty {row['penalty']:g} ({row['seeds']} seeds): validation "
            f"{learned['transmissions']:.1f} transmissions at {learned['mean_cost']:.6g} "
            f"against the {choice['reference']}'s {start['transmissions']:.1f} at "
            f"{start['mean_cost']:.6g}: "
            f"{'contains' if row['contains_start'] else 'does not contain'} it"
        )
    chosen = choice["chosen"]
    print(
        "chosen: "
        + (
            f"no penalty contains the {choice['reference']} (closest: {choice['closest']:g})"
            if chosen is None
            else f"{chosen:g}"
        )
    )
    if args.json:
        write_json(choice, args.json)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

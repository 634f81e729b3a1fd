"""Which penalty of a front of searches a report takes, chosen on the validation set alone.

A search's transmission penalty λ sets where its trigger lands on the trade-off between cost
and transmissions: at the headline's own λ a search may trade transmissions for cost and
leave the headline's rate (paper 000 at λ = 1 went to 2-3 × the headline's transmissions).
The goal asks first that the learned trigger *contain* the headline (no more mean cost and no
more transmissions), so the front's λ is chosen by that criterion, read where choices are made:

* each search validates its start (the menu's best rule, from which every search starts) at
  its first generation and its chosen point at the generation it chose, on the same
  validation scenarios (:mod:`agents.search.cma_es`, ``curve.json``);
* per λ, the mean over the seeds of the chosen points' validation (transmissions, mean cost)
  **contains** the start's when neither exceeds the start's;
* the chosen λ is the **largest** that contains (the suite's question is communicating less
  at the same accuracy); none, where no λ does.

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

from agents.sweep.results import SEARCH_CURVE_FILE, read_sweep
from etsc_envs.core.files import output_file_argument
from etsc_envs.evaluation.arguments import write_json


def validation_points(folder: Path) -> tuple[tuple[float, float], tuple[float, float]]:
    """The (transmissions, mean cost) on the validation set of a search's start (its first
    validation) and of its chosen point, from the search's ``curve.json``."""
    path = folder / SEARCH_CURVE_FILE
    if not path.is_file():
        raise ValueError(f"RESULTS_DIR: trial {folder.name!r} holds no {SEARCH_CURVE_FILE}")
    record = json.loads(path.read_text(encoding="utf-8"))
    validated = [row for row in record["curve"] if "validation_cost" in row]
    chosen = record["search"]["chosen_generation"]
    (best,) = [row for row in validated if row["generation"] == chosen]

    def point(row: dict[str, Any]) -> tuple[float, float]:
        return float(row["validation_transmissions"]), float(row["validation_cost"])

    return point(validated[0]), point(best)


def choose_penalty(results_dir: str | Path) -> dict[str, Any]:
    """Per penalty of the sweep in ``results_dir`` (a front of ``learner: search``): its
    seeds, the mean of their chosen validation points, the start's, and whether the mean
    contains the start; and ``chosen``, the largest penalty that does (``None`` if none).
    ``ValueError`` if a trial did not finish or the sweep varies more than penalty and seed."""
    trials = read_sweep(results_dir)
    by_penalty: dict[float, list[tuple[tuple[float, float], tuple[float, float]]]] = {}
    for trial in trials:
        if set(trial.values) != {"penalty", "seed"}:
            raise ValueError(
                f"RESULTS_DIR: {str(results_dir)!r} sweeps {sorted(trial.values)}, not a front "
                f"of searches over penalty and seed"
            )
        if trial.status != "finished":
            raise ValueError(
                f"RESULTS_DIR: trial {trial.name!r} is {trial.status}; finish the sweep first"
            )
        by_penalty.setdefault(float(trial.values["penalty"]), []).append(
            validation_points(trial.folder)
        )
    penalties = []
    for penalty, runs in sorted(by_penalty.items()):
        start = np.mean([start for start, _ in runs], axis=0)
        chosen = np.mean([chosen for _, chosen in runs], axis=0)
        penalties.append(
            {
                "penalty": penalty,
                "seeds": len(runs),
                "start": {"transmissions": float(start[0]), "mean_cost": float(start[1])},
                "learned": {"transmissions": float(chosen[0]), "mean_cost": float(chosen[1])},
                "contains_start": bool(chosen[0] <= start[0] and chosen[1] <= start[1]),
            }
        )
    containing = [row["penalty"] for row in penalties if row["contains_start"]]
    return {
        "results_dir": str(results_dir),
        "criterion": "largest penalty whose seeds' mean validation point contains the start's",
        "penalties": penalties,
        "chosen": max(containing) if containing else None,
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
            f"against the start's {start['transmissions']:.1f} at {start['mean_cost']:.6g}: "
            f"{'contains' if row['contains_start'] else 'does not contain'} it"
        )
    chosen = choice["chosen"]
    print("chosen: " + ("no penalty contains the start" if chosen is None else f"{chosen:g}"))
    if args.json:
        write_json(choice, args.json)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

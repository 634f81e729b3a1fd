"""How far the learned trigger is from the clairvoyant schedules, over a set of scenarios.

    python -m agents.judge.oracle SWEEP_DIR --out docs/results/<EnvName>_oracle

reads the finished trials of a ``learner: oracle`` sweep (one :mod:`agents.oracle` run per
scenario, ``oracle.json``) and writes to ``--out``:

* ``oracle.json`` — the searches' settings (``budget_episodes`` and ``tuning_episodes``, the
  values the runs used; ``tail``); per scenario: the seed, the trigger's transmissions and mean
  cost, the fewest-transmissions schedule's (at no more than the trigger's summed cost) and
  the least-cost schedule's (at no more transmissions), which start each came from, the
  instants simulated and the wall time; and over the scenarios (paired by seed,
  :func:`~etsc_envs.evaluation.statistics.paired_ratio`): learned ÷ clairvoyant
  transmissions (IQM with its bootstrap interval), learned ÷ clairvoyant cost, and the means
  of each schedule's transmissions and mean cost
  (:func:`~etsc_envs.evaluation.statistics.summarize`);
* ``schedules.npz`` — every schedule's instants and channel masks
  (``<seed>_<objective>_instants``, ``<seed>_<objective>_masks``), for plots and checks;

and ``oracle.json`` names the commands that made it (the sweep's, read from its summary, and
this one).

A found schedule exists, so each ratio is a lower bound of the learned trigger's true
distance to the limit on those scenarios.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from agents.sweep.results import ORACLE_FILE, read_summary, read_sweep
from etsc_envs.core.files import atomic_write_text, require_writable_folder
from etsc_envs.core.json_files import read_json_file, require_mapping
from etsc_envs.evaluation.statistics import paired_ratio, summarize

OBJECTIVES = ("fewest_transmissions", "least_cost")


def read_runs(results_dir: str | Path) -> list[dict[str, Any]]:
    """Every finished trial's record of a ``learner: oracle`` sweep, by scenario seed;
    ``ValueError`` naming ``SWEEP_DIR`` if a trial did not finish, none did, or they judge
    another id or trigger than the first."""
    trials = read_sweep(results_dir, "SWEEP_DIR")
    unfinished = [trial.name for trial in trials if trial.status != "finished"]
    if unfinished:
        raise ValueError(f"SWEEP_DIR: trials {unfinished} of {results_dir} did not finish")
    records = []
    for trial in trials:
        path = trial.folder / ORACLE_FILE
        if not path.is_file():
            raise ValueError(f"SWEEP_DIR: trial {trial.name!r} holds no {ORACLE_FILE}")
        records.append(json.loads(path.read_text(encoding="utf-8")))
    if not records:
        raise ValueError(f"SWEEP_DIR: {results_dir} holds no trial")
    first = records[0]["settings"]
    for record in records:
        settings = record["settings"]
        for key in ("env_id", "trigger", "scenarios"):
            if settings[key] != first[key]:
                raise ValueError(
                    f"SWEEP_DIR: trials judge other {key}s: {settings[key]!r} and {first[key]!r}"
                )
    return sorted(records, key=lambda record: record["seed"])


def _scenario(record: dict[str, Any]) -> dict[str, Any]:
    """One scenario's row (its schedules left out)."""
    row: dict[str, Any] = {"seed": record["seed"]}
    for part in ("trigger", *OBJECTIVES):
        found = record[part]
        row[part] = {"transmissions": found["transmissions"], "mean_cost": found["mean_cost"]}
        if part != "trigger":
            row[part]["starts"] = {
                name: None if start is None else {"start": start["start"], "end": start["end"]}
                for name, start in found["starts"].items()
            }
    row["steps"] = record["steps"]
    row["wall_time_s"] = record["wall_time_s"]
    return row


def judge(records: list[dict[str, Any]]) -> dict[str, Any]:
    """The summary of :func:`read_runs`'s records (the module docstring's ``oracle.json``)."""

    def values(part: str, key: str) -> np.ndarray:
        return np.array([record[part][key] for record in records], dtype=float)

    settings = records[0]["settings"]
    summary = {
        "env_id": settings["env_id"],
        "trigger": settings["trigger"],
        "scenarios": settings["scenarios"],
        "seeds": [record["seed"] for record in records],
        "budget_episodes": sorted({record["settings"]["budget_episodes"] for record in records}),
        # runs from before the tuned start have no tuning_episodes: they did not tune
        "tuning_episodes": sorted(
            {record["settings"].get("tuning_episodes", 0.0) for record in records}
        ),
        "tail": settings["tail"],
        "learned_over_clairvoyant": {
            "transmissions_at_equal_cost": paired_ratio(
                values("trigger", "transmissions"), values("fewest_transmissions", "transmissions")
            ),
            "cost_at_equal_transmissions": paired_ratio(
                values("trigger", "mean_cost"), values("least_cost", "mean_cost")
            ),
        },
        "means": {
            part: {
                "transmissions": summarize(values(part, "transmissions")),
                "mean_cost": summarize(values(part, "mean_cost")),
            }
            for part in ("trigger", *OBJECTIVES)
        },
        "wall_time_s": float(sum(record["wall_time_s"] for record in records)),
        "per_scenario": [_scenario(record) for record in records],
    }
    return summary


def schedule_arrays(records: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    """Every record's schedules as the arrays of ``schedules.npz``."""
    arrays = {}
    for record in records:
        for objective in OBJECTIVES:
            schedule = record[objective]["schedule"]
            key = f"{record['seed']}_{objective}"
            arrays[f"{key}_instants"] = np.array(schedule["instants"], dtype=np.int64)
            arrays[f"{key}_masks"] = np.array(schedule["masks"], dtype=np.int8)
    return arrays


def require_own_record(out: Path, records: list[dict[str, Any]]) -> None:
    """``ValueError`` before any work when ``out`` holds the ``oracle.json`` of another id,
    trigger or set of scenarios: a record is judged again in place, never replaced by
    another's."""
    path = out / "oracle.json"
    if not path.exists():
        return
    held = require_mapping(read_json_file(path, f"--out {path}"), "")
    settings = records[0]["settings"]
    mine = (settings["env_id"], settings["trigger"], [record["seed"] for record in records])
    if (held.get("env_id"), held.get("trigger"), held.get("seeds")) != mine:
        raise ValueError(
            f"--out {out} holds the clairvoyant schedules of {held.get('trigger')!r} on "
            f"{held.get('env_id')!r}, {len(held.get('seeds') or [])} scenarios; give this "
            f"sweep its own --out"
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.judge.oracle", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("sweep_dir", metavar="SWEEP_DIR", help="a learner: oracle sweep's folder")
    parser.add_argument("--out", required=True, help="folder of oracle.json and schedules.npz")
    args = parser.parse_args(argv)
    try:
        out = require_writable_folder(args.out, "--out")
        records = read_runs(args.sweep_dir)
        require_own_record(out, records)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    summary = judge(records)
    sweep = read_summary(args.sweep_dir, "SWEEP_DIR").get("sweep")
    summary["commands"] = [
        *([f"python -m agents.sweep --config {sweep} --processes 2 --resume"] if sweep else []),
        f"python -m agents.judge.oracle {args.sweep_dir} --out {args.out}",
    ]
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "oracle.json", json.dumps(summary, indent=1) + "\n")
    np.savez_compressed(out / "schedules.npz", **schedule_arrays(records))
    ratios = summary["learned_over_clairvoyant"]
    for name, ratio in ratios.items():
        if ratio["iqm"] is None:  # every clairvoyant schedule costs 0 and the trigger does not
            print(f"learned ÷ clairvoyant, {name}: no ratio (the clairvoyant schedules cost 0)")
            continue
        low, high = ratio["iqm_ci95"]
        print(f"learned ÷ clairvoyant, {name}: IQM {ratio['iqm']:.4g} [{low:.4g}, {high:.4g}]")
    print(f"wrote {out / 'oracle.json'} and {out / 'schedules.npz'} ({len(records)} scenarios)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""One method against one trigger of another record, paired on the same scenarios.

``agents.results`` judges a method (its training seeds) against the paper's rule and the clock.
Some questions compare two methods instead — does the state-dependent network beat the plain
point it was searched from (issue #50, item 4)? This command reads two ``results.json`` of
``agents.results`` on the same id and scenario sets: the **candidate** (every model of it,
taken as the method's seeds) and one **reference model** of the other record. Per scenario set
both had, it reports, as ``agents.results`` does against the paper's rule:

* the IQM over seeds × scenarios of the per-scenario ratios candidate ÷ reference of the mean
  cost and of the transmissions, with rliable's stratified bootstrap 95 % interval and each
  seed's own IQM (:func:`~etsc_envs.evaluation.statistics.seeds_ratio`);
* the verdict of :func:`~etsc_envs.evaluation.verdict.compare` on both ratios against 1,
  failures counted first: ``beats`` (both below 1), ``better`` (one below, the other reaching
  1), ``ties``, ``trade-off``, ``loses``.

The candidate **wins** on a set where the verdict is ``beats`` or ``better``: fewer
transmissions or less cost at the 95 % bound, and no more of the other. ::

    python -m agents.judge.versus CANDIDATE REFERENCE --reference-model PATH [--json PATH]

CANDIDATE and REFERENCE are ``results.json`` files or the folders holding them. PATH names the
reference's model as its record lists it, or any file with the same contents (a shipped copy such
as ``models/<id>_learned.json``: JSON files are compared as data, so a record's compact copy of
an indented file is the same model); it may be left out where the reference judged one model.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from etsc_envs.core.files import output_file_argument
from etsc_envs.core.json_files import read_json_file, read_json_text
from etsc_envs.evaluation.arguments import write_json
from etsc_envs.evaluation.statistics import seeds_ratio
from etsc_envs.evaluation.verdict import compare, ratio_axis

WINS = ("beats", "better")
"""The verdicts that count as a win of the candidate."""

AXES = {"cost ratio": "mean_cost", "transmission ratio": "transmissions"}
"""Each axis of the comparison and the episode key it divides."""


def load_record(path: str | Path, argument: str) -> tuple[Path, dict[str, Any]]:
    """The ``results.json`` at ``path`` (or inside the folder ``path``) and its contents;
    ``ValueError`` naming ``argument`` where there is none or it is not a record."""
    path = Path(path)
    file = path / "results.json" if path.is_dir() else path
    try:
        record = read_json_file(file)
    except ValueError as error:
        raise ValueError(
            f"{argument}: no readable results.json at {str(path)!r} ({error})"
        ) from None
    if not isinstance(record, dict) or not {"env", "models", "sets"} <= set(record):
        raise ValueError(f"{argument}: {str(file)!r} is not a results.json of agents.results")
    return file, record


def reference_index(record: dict[str, Any], model: str | None) -> int:
    """Which of ``record``'s models ``model`` names: its path as listed, or a file with the
    same contents as one listed (:func:`_contents`); ``None`` for the only one.
    ``ValueError`` naming ``--reference-model`` otherwise."""
    models = list(record["models"])
    if model is None:
        if len(models) != 1:
            raise ValueError(
                f"--reference-model is needed: the reference judged {len(models)} models "
                f"({', '.join(models)})"
            )
        return 0
    if model in models:
        return models.index(model)
    data = _contents(model)
    if data is None:
        raise ValueError(f"--reference-model: cannot read {model!r}")
    same = [i for i, listed in enumerate(models) if _contents(listed) == data]
    if not same:
        raise ValueError(
            f"--reference-model: {model!r} is none of the reference's models "
            f"({', '.join(models)}), by path or by contents"
        )
    return same[0]


def _contents(path: str) -> object:
    """The contents of ``path``: its data where it is JSON (a learned trigger file, written
    indented in ``models/`` and compact in records), else its bytes (an SB3 zip); ``None``
    where it cannot be read."""
    try:
        data = Path(path).read_bytes()
    except OSError:
        return None
    try:
        return read_json_text(data.decode("utf-8"))
    except ValueError:  # UnicodeDecodeError included: a zip's bytes
        return data


def compare_records(
    candidate: dict[str, Any], reference: dict[str, Any], index: int
) -> dict[str, dict[str, Any]]:
    """Per scenario set of both records, the candidate's models against the reference's model
    ``index`` (see the module docstring). ``ValueError`` where the ids differ, the records
    share no set, or a shared set's scenarios differ."""
    if candidate["env"] != reference["env"]:
        raise ValueError(
            f"the records judge different ids: {candidate['env']} and {reference['env']}"
        )
    names = [name for name in candidate["sets"] if name in reference["sets"]]
    if not names:
        raise ValueError(
            f"the records share no scenario set ({list(candidate['sets'])} and "
            f"{list(reference['sets'])})"
        )
    sets = {}
    for name in names:
        ours, theirs = candidate["sets"][name], reference["sets"][name]
        runs = [model["learned"]["episodes"] for model in ours["models"]]
        base = theirs["models"][index]["learned"]["episodes"]
        seeds = [episode["seed"] for episode in base]
        if any([episode["seed"] for episode in run] != seeds for run in runs):
            raise ValueError(f"the records ran different scenarios on the {name} set")
        ratios = {
            axis: seeds_ratio(
                np.array([[episode[key] for episode in run] for run in runs], dtype=float),
                np.array([episode[key] for episode in base], dtype=float),
            )
            for axis, key in AXES.items()
        }
        failures = sum(episode["failure"] is not None for run in runs for episode in run)
        verdict = compare(
            failures,
            sum(episode["failure"] is not None for episode in base),
            {axis: ratio_axis(ratio) for axis, ratio in ratios.items()},
        )
        sets[name] = {
            "seeds": len(runs),
            "scenarios": len(seeds),
            **ratios,
            "verdict": verdict.to_json(),
            "wins": verdict.outcome in WINS,
        }
    return sets


def _ratio_text(ratio: dict[str, Any]) -> str:
    """``×0.95 [0.93, 0.97] (seeds 0.94–0.96)``, or why there is no ratio."""
    if ratio["iqm"] is None:
        return f"no ratio (the reference is 0 where the candidate is not on all {ratio['n']})"
    low, high = ratio["iqm_ci95"]
    first, last = ratio["range"]
    return f"×{ratio['iqm']:.4g} [{low:.4g}, {high:.4g}] (seeds {first:.4g}–{last:.4g})"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.judge.versus",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("candidate", metavar="CANDIDATE", help="results.json (or its folder)")
    parser.add_argument("reference", metavar="REFERENCE", help="results.json (or its folder)")
    parser.add_argument("--reference-model", metavar="PATH", help="the reference's model")
    parser.add_argument("--json", type=output_file_argument("--json"), help="write the comparison")
    args = parser.parse_args(argv)
    try:
        candidate_file, candidate = load_record(args.candidate, "CANDIDATE")
        reference_file, reference = load_record(args.reference, "REFERENCE")
        index = reference_index(reference, args.reference_model)
        sets = compare_records(candidate, reference, index)
    except ValueError as error:
        parser.error(str(error))
    model = reference["models"][index]
    print(f"{candidate['env']}: {candidate_file} ({len(candidate['models'])} models) ÷ {model}")
    for name, judged in sets.items():
        verdict = judged["verdict"]
        print(
            f"- {name} ({judged['seeds']} seeds × {judged['scenarios']} scenarios): cost "
            f"{_ratio_text(judged['cost ratio'])}, transmissions "
            f"{_ratio_text(judged['transmission ratio'])}; {verdict['outcome']}"
            + (f" ({'; '.join(verdict['reasons'])})" if verdict["reasons"] else "")
            + (": **wins**" if judged["wins"] else "")
        )
    if args.json:
        write_json(
            {
                "env": candidate["env"],
                "candidate": str(candidate_file),
                "candidate_models": list(candidate["models"]),
                "reference": str(reference_file),
                "reference_model": model,
                "sets": sets,
            },
            args.json,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

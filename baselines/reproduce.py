"""Reproduce the papers' reported numbers and figures.

    python -m baselines.reproduce [--paper NNN ...] [--json PATH|-] [--plot DIR]

Prints, for every metric a paper reports, the paper's value beside the suite's, then checks the
paper's qualitative claims. Without ``--paper`` every available reproduction runs. What runs
now, the share of the planned sampling instants done and an estimate of the time left go to
standard error (:mod:`etsc_envs.evaluation.progress`): a bar on a terminal, a line at each run and
every 20 s when redirected.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from baselines.reproductions import REPRODUCTIONS
from baselines.reproductions.report import render
from etsc_envs.core.files import output_file_argument, output_folder_argument
from etsc_envs.evaluation.arguments import write_json
from etsc_envs.evaluation.progress import JobProgress


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m baselines.reproduce",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--paper",
        action="append",
        choices=sorted(REPRODUCTIONS),
        help="paper number (repeatable); default: all available",
    )
    parser.add_argument(
        "--json",
        metavar="PATH|-",
        type=output_file_argument("--json"),
        help="write the comparison as JSON",
    )
    parser.add_argument(
        "--plot",
        metavar="DIR",
        type=output_folder_argument("--plot"),
        help="write the papers' figure counterparts",
    )
    parser.add_argument(
        "--strict",
        action="store_true",
        help="exit with status 1 if any claim of a paper is not reproduced",
    )
    args = parser.parse_args(argv)
    papers = args.paper or sorted(REPRODUCTIONS)
    print(
        f"Reproducing paper{'s' if len(papers) > 1 else ''} {', '.join(papers)}: planning the "
        "runs (each id's first step loads its compiled kernels, or compiles them where "
        "`python -m etsc_envs.compile` has not run)",
        file=sys.stderr,
        flush=True,
    )
    plans = {paper: REPRODUCTIONS[paper].planned_instants() for paper in papers}
    results = []
    with JobProgress(sum(plans.values())) as job:
        planned = 0
        for paper in papers:
            module = REPRODUCTIONS[paper]
            job.stage(f"paper {paper}: {module.TITLE}")
            plot_dir = Path(args.plot) / f"paper_{paper}" if args.plot else None
            result = module.reproduce(plot_dir=plot_dir)
            planned += plans[paper]
            job.reach(planned)
            results.append(result)
            if args.json != "-":
                job.write(render(result) + "\n")
    if args.json:
        write_json({"reproductions": results}, args.json)
    failing = {r["paper"]: sum(not item["holds"] for item in r.get("claims", [])) for r in results}
    failing = {paper: count for paper, count in failing.items() if count}
    if args.json != "-":
        summary = ", ".join(f"paper {p}: {n}" for p, n in failing.items()) or "none"
        print(f"Claims not reproduced: {summary} (docs/fidelity.md explains each)")
    return 1 if args.strict and failing else 0


if __name__ == "__main__":
    raise SystemExit(main())

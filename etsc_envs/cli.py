"""The installed command ``etsc-envs``: the benchmark from the wheel alone.

    etsc-envs evaluate ENV_ID --policy POLICY [--policy-arg k=v ...] [--env-arg k=v ...]
                       [--scenarios paper|validation|test [--set-size K] | --episodes N --seed S]
                       [--reference paper|none] [--json PATH|-]
    etsc-envs leaderboard [ENV_ID]
    etsc-envs compile [--ids ...]

``evaluate`` runs :func:`etsc_envs.evaluate` (POLICY: ``paper | error_time | periodic | always |
learned:PATH | sb3:PATH``, or a ``.json``/``.zip`` path) and prints the means, the 95 %
intervals and the paired comparison with the paper's rule, and where a test-set result stands
on the leaderboard; ``--json`` writes :meth:`~etsc_envs.evaluation.Evaluation.to_json`.
Outputs are checked before the work; a bad argument is refused with one line; Ctrl-C keeps the
finished episodes (marked partial) and never replaces a ``--json`` file when none finished.
``leaderboard`` prints the rows of ``docs/leaderboard.md``; ``compile`` is
``python -m etsc_envs.compile``. ``python -m baselines.evaluate`` is the same ``evaluate`` with
figures and time windows (:func:`evaluate_arguments`, :func:`run_evaluation`).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from dataclasses import asdict
from typing import Any

import gymnasium as gym

from etsc_envs.core.files import output_file_argument
from etsc_envs.evaluation.arguments import limit_torch_threads, parse_assignments, write_json
from etsc_envs.evaluation.leaderboard import LEADERBOARD_PAGE, leaderboard, leaderboard_ids
from etsc_envs.evaluation.policy_specs import POLICY_CHOICES
from etsc_envs.evaluation.run import EpisodeHook, Evaluation, EvaluationInterrupted, evaluate
from etsc_envs.evaluation.verdict import Verdict
from etsc_envs.protocol import DEFAULT_SET_SIZE, SCENARIO_SET_NAMES

REFERENCES = ("paper", "none")
"""``--reference``: the paper's rule on the same scenarios, or no comparison."""


def positive_integer(text: str) -> int:
    """``--set-size`` of every command that judges on a scenario set: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"takes an integer >= 1 (scenarios), got {text!r}")
    return value


def evaluate_arguments(parser: argparse.ArgumentParser, scenarios: str | None) -> None:
    """Add the arguments of ``evaluate`` to ``parser``; without ``--scenarios`` nor
    ``--episodes`` it runs the set ``scenarios``, or one episode of seed ``--seed`` where
    ``scenarios`` is ``None``."""
    parser.set_defaults(default_scenarios=scenarios)
    parser.add_argument(
        "env_id", help="a registered Gymnasium or PettingZoo id, e.g. etsc/AttitudeTracking-v0"
    )
    parser.add_argument(
        "--policy", required=True, help=f"{POLICY_CHOICES}, or a .json or .zip path"
    )
    parser.add_argument("--policy-arg", action="append", metavar="K=V", help="policy parameter")
    parser.add_argument("--env-arg", action="append", metavar="K=V", help="environment kwarg")
    parser.add_argument(
        "--scenarios",
        choices=SCENARIO_SET_NAMES,
        help="a fixed scenario set of the test protocol"
        + (f" (default {scenarios}, unless --episodes)" if scenarios else ""),
    )
    parser.add_argument(
        "--set-size",
        type=positive_integer,
        default=DEFAULT_SET_SIZE,
        metavar="K",
        help=f"scenarios of the validation or test set (default {DEFAULT_SET_SIZE})",
    )
    parser.add_argument(
        "--episodes",
        type=positive_integer,
        metavar="N",
        help="an ad-hoc draw of N episodes instead of a set"
        + ("" if scenarios else " (default 1 when no --scenarios)"),
    )
    parser.add_argument("--seed", type=int, default=0, help="the first seed of --episodes")
    parser.add_argument(
        "--reference",
        choices=REFERENCES,
        default="paper",
        help="compare with the paper's rule on the same scenarios (default), or not",
    )
    parser.add_argument(
        "--json",
        metavar="PATH|-",
        type=output_file_argument("--json"),
        help="write the results as JSON",
    )


def run_evaluation(
    parser: argparse.ArgumentParser,
    args: argparse.Namespace,
    *,
    windows_s: Sequence[float] | None = None,
    on_episode: EpisodeHook | None = None,
) -> int:
    """Run the ``evaluate`` of ``args`` and report it: the summary, ``--json``, one line for a
    bad argument (``parser.error``), and on Ctrl-C the finished episodes' records (none
    written when none finished). Returns the exit status."""
    limit_torch_threads()
    scenarios, episodes = args.scenarios, None
    if scenarios is None:
        scenarios = None if args.episodes is not None else args.default_scenarios
        episodes = args.episodes or (None if scenarios else 1)
    try:
        evaluation = evaluate(
            args.policy,
            args.env_id,
            scenarios,
            size=args.set_size,
            episodes=episodes,
            seed=args.seed,
            policy_args=parse_assignments(args.policy_arg, "--policy-arg"),
            env_args=parse_assignments(args.env_arg, "--env-arg"),
            reference=None if args.reference == "none" else args.reference,
            progress=sys.stderr.isatty(),
            windows_s=windows_s,
            on_episode=on_episode,
        )
    except (ValueError, TypeError, gym.error.Error) as error:
        parser.error(str(error))
    except EvaluationInterrupted as interrupted:
        partial = interrupted.evaluation
        finished = len(partial.records)
        where = "not written (no --json)"
        if not finished:
            where = "none to write" + (f"; {args.json} left as it was" if args.json else "")
        elif args.json:
            _write(parser, partial.to_json(), args.json)
            output = "standard output" if args.json == "-" else args.json
            where = f"written to {output}, marked partial"
        print(
            f"interrupted: {finished} of {partial.planned} episode(s) finished, their "
            f"records {where}",
            file=sys.stderr,
        )
        return 130
    except KeyboardInterrupt:
        print("interrupted before any episode ran; nothing written", file=sys.stderr)
        return 130
    if args.json:
        _write(parser, evaluation.to_json(), args.json)
    summary = sys.stderr if args.json == "-" else sys.stdout
    print(evaluation.summary(), file=summary)
    if evaluation.scenarios and evaluation.scenarios["name"] == "test" and not args.env_arg:
        print(_standing_text(evaluation), file=summary)
    return 0


def _write(parser: argparse.ArgumentParser, payload: dict[str, Any], destination: str) -> None:
    """:func:`~etsc_envs.evaluation.arguments.write_json`, a system's refusal as one line."""
    try:
        write_json(payload, destination)
    except OSError as error:
        parser.exit(1, f"{parser.prog}: --json {destination} cannot be written: {error.strerror}\n")


def _standing_text(evaluation: Evaluation) -> str:
    """Where a test-set result stands among the leaderboard's rows, one line per row."""
    try:
        standing = evaluation.standing()
    except ValueError as error:  # an id without leaderboard rows
        return f"  leaderboard: {error}"
    lines = [f"  against the leaderboard ({LEADERBOARD_PAGE}; mean intervals, failures first):"]
    for row in standing:
        lines.append(f"    {row['trigger']:>28s}  {Verdict.from_json(row).text()}")
    return "\n".join(lines)


def leaderboard_text(env_id: str) -> str:
    """An id's leaderboard rows as lines (test set and paper scenario)."""
    from etsc_envs.papers import paper_of

    lines = [f"{env_id}: mean_cost is {paper_of(env_id).cost}"]
    for row in leaderboard(env_id):
        cells = []
        for name, measure in (("test", row.test), ("paper scenario", row.paper)):
            if measure is None:
                cells.append(f"{name}: —")
                continue
            cells.append(
                f"{name}: cost {measure.cost:.4g} [{measure.cost_ci95[0]:.4g}, "
                f"{measure.cost_ci95[1]:.4g}], sent {measure.transmissions:.4g}, failed "
                f"{measure.failures}/{measure.episodes}"
            )
        lines.append(f"  {row.trigger}: " + "; ".join(cells))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """``etsc-envs``: the subcommands of the module docstring."""
    parser = argparse.ArgumentParser(
        prog="etsc-envs",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    commands = parser.add_subparsers(dest="command", required=True)
    evaluating = commands.add_parser("evaluate", help="score a trigger on a scenario set")
    evaluate_arguments(evaluating, scenarios="test")
    board = commands.add_parser("leaderboard", help="the rows of docs/leaderboard.md")
    board.add_argument("env_id", nargs="?", help="one id (default: every id)")
    board.add_argument("--json", action="store_true", help="print the rows as JSON")
    commands.add_parser("compile", help="python -m etsc_envs.compile", add_help=False)
    args, rest = parser.parse_known_args(argv)
    if args.command == "compile":
        from etsc_envs import compile as compiling

        return compiling.main(rest)
    if rest:
        parser.error(f"unrecognized arguments: {' '.join(rest)}")
    if args.command == "evaluate":
        return run_evaluation(evaluating, args)
    ids = leaderboard_ids() if args.env_id is None else [args.env_id]
    try:
        if args.json:
            rows = {env_id: [asdict(row) for row in leaderboard(env_id)] for env_id in ids}
            print(json.dumps(rows, indent=2))
        else:
            print("\n".join(leaderboard_text(env_id) for env_id in ids))
    except ValueError as error:
        board.error(str(error))
    return 0

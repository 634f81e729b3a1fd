"""A learned trigger against the paper's trigger and the clock, under the test protocol: the
rows of ``docs/results.md``.

    python -m agents.results ENV_ID (--model PATH [--model PATH ...] | --sweep RESULTS_DIR)
                             [--scenarios paper test] [--set-size K] [--env-arg k=v ...]
                             [--out DIR]

For each scenario set (:mod:`etsc_envs.protocol`; default the paper scenario and the test set)
it runs the paper's trigger, every ``--model`` (several models are training seeds of one
method), and, for each model, periodic transmission at that model's own rate (every ``k``
sampling instants on every channel, ``k`` matching the model's mean transmissions on the set;
models at the same ``k``, such as seeds that learned the same decisions, share one run of it).
All scenarios of a set run at once in the native vector env (:mod:`etsc_envs.evaluation.batch`).

Per set and model it reports the paired per-scenario ratios with 95 % bootstrap intervals
(:mod:`etsc_envs.evaluation.statistics`) and two verdicts of
:func:`etsc_envs.evaluation.verdict.compare` (failures counted first: a trigger that failed an
episode meets and beats nothing):

* **goal vs the paper** — met when the interval of the cost ratio (IQM of the per-scenario
  ratios learned / paper) lies below :data:`COST_RATIO_MAX` and that of the transmission ratio
  below :data:`TRANSMISSION_RATIO_MAX`;
* **against periodic** — the cost ratio learned / periodic at the learned rate against 1:
  beats, ties or loses; a learned trigger whose records are the clock's on every scenario
  ties.

With three or more models the method's verdicts use the IQM over seeds × scenarios with
rliable's stratified bootstrap interval, and the range of the per-seed IQMs; with fewer, the
page states that there is no claim (a claim stands on at least :data:`MIN_CLAIM_SEEDS` seeds).

The tables name each model by what it is (:func:`model_kind`: ``PPO #1``, ``self-triggered
MaskablePPO #2``, ``learned trigger #1``, ``hand point #1``), and so does its row's ``kind``.

Writes ``results.json`` (every episode record included) into ``DIR`` (default
``results/<env name>``) and prints the tables as Markdown. A ``DIR`` whose ``results.json``
judged other models (or another id) is refused before any work: each model, or set of seeds,
gets its own ``--out``. With ``--sweep`` (the results folder
of ``python -m agents.sweep``) the finished trials that differ only in their seed form one
method: each such group is compared into ``DIR/<group>/results.json``, its trials' models as
the method's training seeds.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import etsc_envs
from agents.sweep.results import finished_trials
from baselines.evaluate import evaluate
from etsc_envs.cli import positive_integer
from etsc_envs.core.files import output_folder_argument, require_writable_folder
from etsc_envs.core.json_files import read_json_file, require_mapping
from etsc_envs.decisions import decision_set_path
from etsc_envs.evaluation import verdict
from etsc_envs.evaluation.arguments import (
    limit_torch_threads,
    model_spec,
    parse_assignments,
    write_json,
)
from etsc_envs.evaluation.policy_specs import episode_setup, require_policies
from etsc_envs.evaluation.statistics import paired_ratio, seeds_ratio
from etsc_envs.evaluation.verdict import Verdict, ratio_axis
from etsc_envs.papers import PAPER_IDS, paper_of
from etsc_envs.protocol import DEFAULT_SET_SIZE, PROTOCOL_VERSION, SCENARIO_SET_NAMES
from etsc_envs.sb3_models import infer_sb3_algorithm
from etsc_envs.triggers.family import LearnedTrigger

COST_RATIO_MAX = 1.05
"""The learned trigger may be this much less accurate than the paper's (cost ratio bound)."""

TRANSMISSION_RATIO_MAX = 0.70
"""...with at most this fraction of its transmissions."""

MIN_CLAIM_SEEDS = 3
"""Training seeds a method's claim stands on, at least."""


def channel_count(env_id: str, env_args: dict[str, Any]) -> int:
    """Transmit channels of ``env_id`` (agents of a PettingZoo id)."""
    setup = episode_setup(env_id, env_args)
    env = setup.env
    loop = env.loop if env_id in etsc_envs.PETTINGZOO_ENV_IDS else env.unwrapped
    count = int(loop.n_channels)
    env.close()
    return count


def equal_rate_period(steps: float, transmissions: float, channels: int) -> int:
    """Sampling instants between periodic transmissions (on all ``channels``) that give about
    ``transmissions`` in ``steps`` instants."""
    if transmissions <= 0:
        return max(int(steps), 1)
    return max(round(channels * steps / transmissions), 1)


def _column(result: dict[str, Any], key: str) -> np.ndarray:
    return np.array([record[key] for record in result["episodes"]], dtype=float)


def _failures(result: dict[str, Any]) -> int:
    return sum(record["failure"] is not None for record in result["episodes"])


def goal_verdict(vs_paper: dict[str, Any], failures: int, paper_failures: int) -> Verdict:
    """The goal against the paper's rule (:func:`~etsc_envs.evaluation.verdict.compare`): the
    cost ratio's interval below :data:`COST_RATIO_MAX` and the transmission ratio's below
    :data:`TRANSMISSION_RATIO_MAX`, failures counted first."""
    return verdict.compare(
        failures,
        paper_failures,
        {
            "cost ratio": ratio_axis(vs_paper["mean_cost"], COST_RATIO_MAX),
            "transmission ratio": ratio_axis(vs_paper["transmissions"], TRANSMISSION_RATIO_MAX),
        },
    )


def clock_verdict(cost_ratio: dict[str, Any], failures: int, clock_failures: int) -> Verdict:
    """Against the clock at the learned rate (:func:`~etsc_envs.evaluation.verdict.compare`):
    the cost ratio's interval below 1, failures counted first; records that are the clock's on
    every scenario tie (their ratio's interval is [1, 1])."""
    return verdict.compare(failures, clock_failures, {"cost ratio": ratio_axis(cost_ratio)})


def model_kind(model: str) -> str:
    """What a ``--model`` is, as the tables name it: a family point's file is the ``hand
    point`` (its ``hand`` record) or a ``learned trigger`` (a search's); an SB3 zip is its
    algorithm (``PPO``, ``MaskablePPO``, ``DQN``), ``self-triggered`` where a decision set sits
    beside it. A name, not a verdict: "learned trigger" is kept for what an optimiser found in a
    rule's family."""
    kind, _, path = model_spec(model).partition(":")
    if kind == "learned":
        return "hand point" if LearnedTrigger.load(path).hand else "learned trigger"
    algorithm = infer_sb3_algorithm(path).__name__
    return f"self-triggered {algorithm}" if decision_set_path(path).is_file() else algorithm


def _compare_set(
    env_id: str,
    models: list[str],
    env_args: dict[str, Any],
    scenarios: str,
    set_size: int,
    progress: bool,
) -> dict[str, Any]:
    """One scenario set: the paper trigger, every model and its equal-rate clock."""

    def run(spec: str, policy_args: dict[str, Any] | None = None) -> dict[str, Any]:
        if progress:
            print(f"[{scenarios} set] {spec} {policy_args or ''}", file=sys.stderr, flush=True)
        return evaluate(
            env_id,
            spec,
            policy_args=policy_args,
            env_args=env_args,
            scenarios=scenarios,
            set_size=set_size,
            progress=progress and sys.stderr.isatty(),
        )

    paper = run("paper")
    channels = channel_count(env_id, {**env_args, **paper["env_args"]})
    learned_rows = []
    clocks: dict[int, dict[str, Any]] = {}  # one run per period: seeds often share their rate
    for model in models:
        learned = run(model_spec(model))
        every = equal_rate_period(
            learned["mean"]["steps"], learned["mean"]["transmissions"], channels
        )
        if every not in clocks:
            clocks[every] = run("periodic", {"every": every})
        periodic = clocks[every]
        vs_paper = {
            key: paired_ratio(_column(learned, key), _column(paper, key))
            for key in ("mean_cost", "transmissions")
        }
        vs_periodic = paired_ratio(_column(learned, "mean_cost"), _column(periodic, "mean_cost"))
        learned_rows.append(
            {
                "model": model,
                "kind": model_kind(model),
                "learned": learned,
                "periodic_every": every,
                "periodic": periodic,
                "vs_paper": vs_paper,
                "vs_periodic": {"mean_cost": vs_periodic},
                "goal": goal_verdict(vs_paper, _failures(learned), _failures(paper)).to_json(),
                "beats_periodic": clock_verdict(
                    vs_periodic, _failures(learned), _failures(periodic)
                ).to_json(),
            }
        )
    compared: dict[str, Any] = {
        "scenarios": paper["scenarios"],
        "paper": paper,
        "models": learned_rows,
        "method": _method(learned_rows, paper),
    }
    return compared


def _method(rows: list[dict[str, Any]], paper: dict[str, Any]) -> dict[str, Any]:
    """The method's verdicts over its training seeds (rliable IQM, stratified bootstrap)."""
    seeds = len(rows)
    if seeds < MIN_CLAIM_SEEDS:
        return {
            "seeds": seeds,
            "claim": False,
            "note": f"{seeds} training seed(s): a claim needs at least {MIN_CLAIM_SEEDS}",
        }
    ratios = {
        key: seeds_ratio(
            np.vstack([_column(row["learned"], key) for row in rows]), _column(paper, key)
        )
        for key in ("mean_cost", "transmissions")
    }
    periodic = seeds_ratio(
        np.vstack([_column(row["learned"], "mean_cost") for row in rows]),
        np.vstack([_column(row["periodic"], "mean_cost") for row in rows]),
    )
    worst = max(_failures(row["learned"]) for row in rows)
    worst_clock = min(_failures(row["periodic"]) for row in rows)
    return {
        "seeds": seeds,
        "claim": True,
        "vs_paper": ratios,
        "vs_periodic": {"mean_cost": periodic},
        "goal": goal_verdict(ratios, worst, _failures(paper)).to_json(),
        "beats_periodic": clock_verdict(periodic, worst, worst_clock).to_json(),
    }


def compare(
    env_id: str,
    models: list[str],
    env_args: dict[str, Any] | None = None,
    scenario_sets: tuple[str, ...] = ("paper", "test"),
    set_size: int = DEFAULT_SET_SIZE,
    progress: bool = False,
) -> dict[str, Any]:
    """The comparison of the module docstring, as a JSON-ready mapping."""
    if not models:
        raise ValueError("--model must name at least one SB3 zip or learned trigger")
    for name in scenario_sets:
        if name not in SCENARIO_SET_NAMES:
            raise ValueError(f"--scenarios must be among {SCENARIO_SET_NAMES}, got {name!r}")
    env_args = dict(env_args or {})
    require_policies(env_id, env_args, [model_spec(model) for model in models])
    return {
        "env": env_id,
        "models": list(models),
        "env_args": env_args,
        "protocol_version": PROTOCOL_VERSION,
        "goal": {
            "cost_ratio_max": COST_RATIO_MAX,
            "transmission_ratio_max": TRANSMISSION_RATIO_MAX,
            "min_claim_seeds": MIN_CLAIM_SEEDS,
        },
        "sets": {
            name: _compare_set(env_id, models, env_args, name, set_size, progress)
            for name in scenario_sets
        },
    }


def seed_groups(trials: list[Any]) -> dict[str, list[str]]:
    """Sweep trials grouped by their name without its ``seed=`` part (one method each, the
    trials' other swept values): group name → the models of its trials."""
    groups: dict[str, list[str]] = {}
    for trial in trials:
        kept = [part for part in trial.name.split(",") if not part.startswith("seed=")]
        groups.setdefault(",".join(kept) or "all", []).append(str(trial.model))
    return groups


def _number(value: Any) -> str:
    if value is None:
        return "—"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def _with_interval(summary: dict[str, Any], key: str = "mean") -> str:
    low, high = summary[f"{key}_ci95"]
    if summary["n"] == 1:
        return _number(summary[key])
    return f"{_number(summary[key])} [{_number(low)}, {_number(high)}]"


def _ratio_text(ratio: dict[str, Any]) -> str:
    if ratio["iqm"] is None:
        return "—"
    low, high = ratio["iqm_ci95"]
    if ratio["n"] == 1:
        return f"×{ratio['iqm']:.3g}"
    return f"×{ratio['iqm']:.3g} [{low:.3g}, {high:.3g}]"


def _policy_row(name: str, result: dict[str, Any], keys: tuple[str, ...]) -> str:
    aggregates = result["aggregates"]
    failure = aggregates["failure"]
    settled = aggregates.get("settled")
    mean = result["mean"]
    cells = [
        name,
        _with_interval(aggregates["mean_cost"]),
        _with_interval(aggregates["transmissions"]),
        f"{failure['count']}/{failure['n']}",
        f"{settled['count']}/{settled['n']}" if settled else "—",
        *(_number(mean.get(key)) for key in keys),
    ]
    return "| " + " | ".join(cells) + " |"


def markdown(result: dict[str, Any]) -> str:
    """The comparison as Markdown: one table per scenario set (with the paper's headline
    metrics, :attr:`~etsc_envs.core.paper.Paper.headline_metrics`), then the verdicts."""
    env_id = result["env"]
    keys = paper_of(env_id).headline_metrics if env_id in PAPER_IDS else ()
    lines = []
    for name, compared in result["sets"].items():
        size = compared["scenarios"]["size"]
        title = "Paper scenario" if name == "paper" else f"{name.title()} set ({size} scenarios)"
        lines += [
            f"**{title}** — means with 95 % bootstrap intervals",
            "",
            "| trigger | mean_cost | transmissions | failures | settled | "
            + " | ".join(keys)
            + " |",
            "|---" * (5 + len(keys)) + "|",
            _policy_row("paper", compared["paper"], keys),
        ]
        names = [f"{row['kind']} #{index}" for index, row in enumerate(compared["models"], 1)]
        for name, row in zip(names, compared["models"], strict=True):
            lines.append(_policy_row(name, row["learned"], keys))
            lines.append(
                _policy_row(f"periodic every {row['periodic_every']}", row["periodic"], keys)
            )
        lines.append("")
        for name, row in zip(names, compared["models"], strict=True):
            lines.append(
                f"- {name} (`{row['model']}`): cost ×paper "
                f"{_ratio_text(row['vs_paper']['mean_cost'])}, transmissions ×paper "
                f"{_ratio_text(row['vs_paper']['transmissions'])}, cost ×periodic "
                f"{_ratio_text(row['vs_periodic']['mean_cost'])} (IQM of per-scenario ratios); "
                f"goal {goal_text(row['goal'])}; against periodic "
                f"{verdict_text(row['beats_periodic'])}"
            )
        method = compared["method"]
        if method["claim"]:
            lines.append(
                f"- method over {method['seeds']} seeds (rliable IQM, stratified bootstrap): "
                f"cost ×paper {_ratio_text(method['vs_paper']['mean_cost'])}, transmissions "
                f"×paper {_ratio_text(method['vs_paper']['transmissions'])}; goal "
                f"{goal_text(method['goal'])}; against periodic "
                f"{verdict_text(method['beats_periodic'])}"
            )
        else:
            lines.append(f"- no claim: {method['note']}")
        lines.append("")
    return "\n".join(lines)


def verdict_text(result: dict[str, Any]) -> str:
    """A verdict's JSON in words (:meth:`~etsc_envs.evaluation.verdict.Verdict.text`)."""
    return Verdict.from_json(result).text()


def goal_text(result: dict[str, Any]) -> str:
    """The goal's verdict in words: "**met**", or "not met" with its outcome and reasons."""
    return "**met**" if result["met"] else f"not met: {verdict_text(result)}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.results",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("env_id", help="a Gymnasium or PettingZoo id of etsc-envs")
    parser.add_argument(
        "--model",
        action="append",
        default=[],
        help="an SB3 zip or a learned trigger (learned:PATH or a .json file); repeat for "
        "several training or search seeds",
    )
    parser.add_argument(
        "--sweep",
        metavar="RESULTS_DIR",
        help="compare the finished trials of a sweep (agents.sweep), grouped by everything "
        "but their seed, each group into DIR/<group>/results.json",
    )
    parser.add_argument(
        "--scenarios",
        nargs="+",
        choices=SCENARIO_SET_NAMES,
        default=["paper", "test"],
        help="scenario sets to judge on (default: paper test)",
    )
    parser.add_argument("--set-size", type=positive_integer, default=DEFAULT_SET_SIZE, metavar="K")
    parser.add_argument("--env-arg", action="append", metavar="K=V", help="environment kwarg")
    parser.add_argument(
        "--out",
        type=output_folder_argument("--out"),
        help="output folder (default results/<env name>)",
    )
    args = parser.parse_args(argv)
    limit_torch_threads()
    if bool(args.model) == bool(args.sweep):
        parser.error("give --model (one or more) or --sweep, not both")
    out_dir = Path(args.out or Path("results") / args.env_id.split("/")[-1])
    try:
        require_writable_folder(out_dir, "--out")
        methods = (
            {out_dir: args.model}
            if args.model
            else {
                out_dir / group: models
                for group, models in seed_groups(finished_trials(args.sweep, args.env_id)).items()
            }
        )
        env_args = parse_assignments(args.env_arg, "--env-arg")
        for folder, models in methods.items():
            require_own_results(folder, args.env_id, models)
        for folder, models in methods.items():
            result = compare(
                args.env_id,
                models,
                env_args,
                tuple(dict.fromkeys(args.scenarios)),
                args.set_size,
                progress=True,
            )
            write_json(result, str(folder / "results.json"))
            print(markdown(result))
            print(f"wrote {folder / 'results.json'}", flush=True)
    except (ValueError, TypeError, gym.error.Error) as error:
        parser.error(str(error))
    except OSError as error:
        parser.error(f"--out {out_dir} could not be written: {error.strerror or error}")
    except KeyboardInterrupt:
        print(
            "\ninterrupted; results written so far are kept, none is partly written",
            file=sys.stderr,
        )
        return 130
    return 0


def require_own_results(folder: Path, env_id: str, models: list[str]) -> None:
    """``ValueError`` before any work when ``folder`` holds the ``results.json`` of other
    models or another id (a finished comparison is never replaced by another model's; the
    same models are judged again in place)."""
    path = folder / "results.json"
    if not path.exists():
        return
    record = require_mapping(read_json_file(path, f"--out {path}"), "")
    if record.get("env") != env_id or record.get("models") != list(models):
        raise ValueError(
            f"--out {folder} holds the results of {record.get('models')} on "
            f"{record.get('env')}; give each model its own --out"
        )


if __name__ == "__main__":
    raise SystemExit(main())

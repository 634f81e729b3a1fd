"""Accuracy against transmissions: the paper's trigger, periodic sampling and learned triggers,
under the test protocol.

    python -m agents.judge.pareto ENV_ID [--model PATH ...] [--sweep RESULTS_DIR ...]
                                   [--judged RESULTS_DIR ...]
                                   [--scenarios test|validation] [--set-size K]
                                   [--env-arg k=v ...] [--out DIR]
                                   [--reuse PARETO_JSON] [--menu PARETO_JSON ...]

Every point of three curves runs on a scenario set of the protocol (default the test set, all
its scenarios at once in the native vector env) and on the paper scenario:

* the paper's trigger over a sweep of its threshold (the paper record's
  :meth:`~etsc_envs.core.paper.Rule.sweep`: Ψ for 002, γ1 and γ2 for 000, c for 001, α for
  003, Π for 004), the paper's own value included;
* on ids with another event rule (the record's other :attr:`~etsc_envs.core.paper.Paper.rules`:
  004's error-time rule), that rule over a sweep of its threshold, as a curve of its own;
* periodic transmission every ``k`` sampling instants (the record's
  :attr:`~etsc_envs.core.paper.Paper.periodic_every`), wide enough to reach periods at which
  the clock fails;
* each ``--model`` (an SB3 zip, with its observation statistics beside it if it has them),
  typically one per transmission penalty λ, and the model of every finished trial of each
  ``--sweep`` (the results folder of ``python -m agents.sweep``: a front in one option). The
  ``--model`` points form one method, ``learned``; each sweep is a method of its own, named
  after its folder, and drawn as its own curve;
* each model already judged by ``python -m agents.results`` in a ``--judged`` folder (every
  ``results.json`` under it, a sweep's groups included): its point is read from the
  judgement's records on the same scenario set instead of being run again, and the folder is
  a method of its own; a judgement without the paper scenario leaves the point out of the
  paper-scenario panel.

A point records the set's aggregates (mean ``mean_cost`` and transmissions with 95 % bootstrap
intervals, failures) and the paper scenario's episode. The plot shows each curve's
non-dominated points joined, with interval bars on both axes, dominated points faint, points
with failures crossed, and the paper scenario in a second panel.

A method of ``learned:`` triggers (a search's) is also judged against the **hand-menu front**,
the envelope of every point that no search found: the sweeps, every other model, and every
point of each ``--menu`` result (earlier fronts: hand rule variants, the headlines among
them), drawn as a curve of its own (:func:`agents.judge.front.menu_verdict`).
The seeds of one search setting are one method there: a ``--sweep`` front over penalties is
judged per penalty (:func:`search_groups`).

Writes ``pareto.json`` and ``pareto.png`` into ``DIR`` (default
``results/pareto/<env name>``). ``--reuse PARETO_JSON`` keeps the paper, periodic (and other
rule) curves of an earlier run (same closed loop, kwargs and scenario set: the PettingZoo cluster
may reuse its central form's) and runs only the models and the curves it lacks.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import gymnasium as gym
import matplotlib.pyplot as plt
from matplotlib import ticker

import etsc_envs
from agents.judge.front import (
    front_verdict,
    menu_line,
    menu_verdict,
    paper_scenario_axes,
    set_axes,
    verdict_line,
)
from agents.sweep.results import sweep_models
from agents.train.validation_callback import episode_summary
from baselines.evaluate import evaluate
from baselines.plotting import save
from etsc_envs.cli import positive_integer
from etsc_envs.core.files import output_folder_argument, require_writable_folder
from etsc_envs.core.json_files import read_json_file
from etsc_envs.evaluation.arguments import (
    limit_torch_threads,
    model_spec,
    parse_assignments,
    write_json,
)
from etsc_envs.evaluation.policy_specs import require_policies
from etsc_envs.papers import PAPER_IDS, paper_of
from etsc_envs.protocol import DEFAULT_SET_SIZE


def run_point(
    env_id: str,
    policy_spec: str,
    policy_args: dict[str, Any],
    env_kwargs: dict[str, Any],
    scenarios: str,
    set_size: int,
) -> dict[str, Any]:
    """One point: the policy on the scenario set (aggregates) and on the paper scenario."""
    print(f"{env_id}: {policy_spec} {policy_args or ''}", file=sys.stderr, flush=True)
    on_set = evaluate(
        env_id,
        policy_spec,
        policy_args=policy_args,
        env_args=env_kwargs,
        scenarios=scenarios,
        set_size=set_size,
        progress=sys.stderr.isatty(),
    )
    on_paper = evaluate(
        env_id, policy_spec, policy_args=policy_args, env_args=env_kwargs, scenarios="paper"
    )
    return point_of(policy_spec, policy_args, on_set, on_paper)


def point_of(
    policy_spec: str,
    policy_args: dict[str, Any],
    on_set: dict[str, Any],
    on_paper: dict[str, Any] | None,
) -> dict[str, Any]:
    """A point from a policy's evaluations (``baselines.evaluate``'s results) on the scenario
    set and on the paper scenario (``None``: not run there)."""
    aggregates = on_set["aggregates"]
    return {
        "policy": policy_spec,
        "args": policy_args,
        "mean_cost": aggregates["mean_cost"],
        "transmissions": aggregates["transmissions"],
        "failures": aggregates["failure"]["count"],
        "paper_scenario": None if on_paper is None else episode_summary(on_paper["episodes"][0]),
    }


def judged_points(
    folder: Path, env_id: str, env_kwargs: dict[str, Any], scenarios: str, set_size: int
) -> list[dict[str, Any]]:
    """The learned points of every model judged by :mod:`agents.judge.results` under ``folder``
    (each ``results.json``, in path order), read from its records on ``scenarios`` (and on
    the paper scenario where it was judged there), with ``folder``'s name as their method.
    ``ValueError`` naming ``--judged`` if a judgement is of another id, env kwargs or scenario
    set, or if the folder holds none."""
    files = sorted(Path(folder).rglob("results.json"))
    if not files:
        raise ValueError(f"--judged: no results.json of agents.judge.results under {str(folder)!r}")
    points = []
    for path in files:
        judged = json.loads(path.read_text(encoding="utf-8"))
        on_set = judged.get("sets", {}).get(scenarios)
        identity = (judged.get("env"), judged.get("env_args"))
        size = None if on_set is None else on_set["scenarios"]["size"]
        if identity != (env_id, env_kwargs) or size != set_size:
            raise ValueError(
                f"--judged: {path} judges (env, env_args, {scenarios} set size) = "
                f"{(*identity, size)}, not {(env_id, env_kwargs, set_size)}"
            )
        on_paper = judged["sets"].get("paper")
        for index, row in enumerate(on_set["models"]):
            paper_run = None if on_paper is None else on_paper["models"][index]["learned"]
            point = point_of(model_spec(row["model"]), {}, row["learned"], paper_run)
            points.append({**point, "method": Path(folder).name})
    return points


def closed_loop_id(env_id: str) -> str:
    """The Gymnasium id of the closed loop ``env_id`` runs: a PettingZoo id's agents share the
    loop of its central form, so the paper and periodic points of the two ids are the same
    episodes (the agents' bits are the central form's action) and one's curves serve both."""
    return etsc_envs.PETTINGZOO_LOOP_IDS.get(env_id, env_id)


def pareto(
    env_id: str,
    models: list[str],
    env_kwargs: dict[str, Any],
    scenarios: str = "test",
    set_size: int = DEFAULT_SET_SIZE,
    reuse: dict[str, Any] | None = None,
    methods: list[str] | None = None,
    judged: list[Path] | None = None,
    menu: list[dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """The three curves of the module docstring for ``env_id``; with ``reuse`` (an earlier
    result of the same id, kwargs and scenario set), its paper and periodic curves are kept and
    only the models run. ``methods`` names each model's method (the plot draws each method as
    its own curve; default one method, ``learned``); the models judged under each folder of
    ``judged`` join the learned points without running (:func:`judged_points`); every point
    of each earlier result of ``menu`` (same closed loop, kwargs and scenario set) joins the
    ``hand_menu`` curve, the hand-menu front a search is judged against (:func:`hand_menu`)."""
    methods = list(methods) if methods is not None else [LEARNED] * len(models)
    if len(methods) != len(models):
        raise ValueError(f"methods: one per model ({len(models)}), got {len(methods)}")
    paper = paper_of(env_id)
    if scenarios not in ("test", "validation"):
        raise ValueError(f"--scenarios must be 'test' or 'validation', got {scenarios!r}")
    identity = (closed_loop_id(env_id), env_kwargs, scenarios, set_size)
    for option, results in (("--reuse", [] if reuse is None else [reuse]), ("--menu", menu)):
        for earlier_result in results or []:
            earlier = (
                closed_loop_id(str(earlier_result.get("env"))),
                *(earlier_result.get(key) for key in ("env_kwargs", "scenarios", "set_size")),
            )
            if earlier != identity:
                raise ValueError(
                    f"{option}: that result is of (closed loop, env_kwargs, scenarios, "
                    f"set_size) = {earlier}, not {identity}"
                )

    require_policies(env_id, env_kwargs, [model_spec(path) for path in models])
    read = [
        point
        for folder in judged or []
        for point in judged_points(folder, env_id, env_kwargs, scenarios, set_size)
    ]

    def point(spec: str, args: dict[str, Any]) -> dict[str, Any]:
        return run_point(env_id, spec, args, env_kwargs, scenarios, set_size)

    if reuse is None:
        curves = {
            "paper": [point("paper", args) for args in paper.rule.sweep()],
            "periodic": [point("periodic", {"every": k}) for k in paper.periodic_every],
        }
    else:
        curves = {name: reuse["curves"][name] for name in ("paper", "periodic")}
    for name, rule in paper.rules.items():
        if name != "paper":
            earlier = None if reuse is None else reuse["curves"].get(name)
            curves[name] = earlier or [point(name, args) for args in rule.sweep()]
    if menu:
        curves["hand_menu"] = [
            point
            for earlier_result in menu
            for curve in earlier_result["curves"].values()
            for point in curve
        ]
    curves["learned"] = [
        {**point(model_spec(path), {}), "method": method}
        for path, method in zip(models, methods, strict=True)
    ] + read
    result = {
        "env": env_id,
        "env_kwargs": env_kwargs,
        "scenarios": scenarios,
        "set_size": set_size,
        "curves": curves,
    }
    result["fronts"] = front_verdicts(result)
    return result


def front_verdicts(result: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Each learned method's front against the paper and periodic sweeps
    (:func:`agents.judge.front.front_verdict`), on the scenario set (``set``) and on the paper
    scenario (``paper``, where its points ran there); and, for a method of searches, the hand
    menu's verdict (``set_menu``, ``paper_menu``) over its search seeds. A front of searches
    over penalties (a sweep's trials ``penalty=…,seed=…``) is judged against the menu per
    penalty, under ``"<method> penalty=…"``: seeds of one penalty are one method, a front's
    penalties are not."""
    curves = result["curves"]
    verdicts: dict[str, dict[str, Any]] = {}
    menu = hand_menu(result)
    for method, points in learned_methods(result):
        verdicts[method] = {"set": front_verdict(points, curves["paper"], curves["periodic"])}
        searched = all(str(point.get("policy")).startswith("learned:") for point in points)
        groups = search_groups(method, points) if searched else {}
        on_paper = all(point.get("paper_scenario") is not None for point in points)
        if on_paper:
            try:
                verdicts[method]["paper"] = front_verdict(
                    points, curves["paper"], curves["periodic"], paper_scenario_axes
                )
            except ValueError:
                on_paper = False
        for name, seeds in groups.items():
            verdicts.setdefault(name, {})["set_menu"] = menu_verdict(seeds, menu, set_axes)
            if on_paper:
                verdicts[name]["paper_menu"] = menu_verdict(seeds, menu, paper_scenario_axes)
    return verdicts


def search_groups(method: str, points: list[dict[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    """The seeds of each search setting among a method's ``learned:`` points, by name: the
    method itself where its trigger files do not lie in sweep trials (``a=1,seed=0/``) or all
    differ only in their seed, else ``"<method> <trial name without its seed>"`` per setting."""
    groups: dict[str, list[dict[str, Any]]] = {}
    for point in points:
        trial = Path(str(point["policy"]).removeprefix("learned:")).parent.name
        values = [part for part in trial.split(",") if "=" in part]
        setting = ",".join(part for part in values if not part.startswith("seed="))
        groups.setdefault(setting, []).append(point)
    if len(groups) == 1:
        return {method: points}
    return {f"{method} {setting}".rstrip(): seeds for setting, seeds in groups.items()}


def hand_menu(result: dict[str, Any]) -> list[dict[str, Any]]:
    """The hand-menu front's points: every point of ``result`` that no search found (the
    paper's threshold sweep, the periodic sweep, other rules' sweeps and every judged or run
    model whose policy is not a ``learned:`` trigger)."""
    return [
        point
        for points in result["curves"].values()
        for point in points
        if not str(point.get("policy")).startswith("learned:")
    ]


def non_dominated(points: list[dict[str, Any]], cost: Any, sent: Any) -> list[dict[str, Any]]:
    """The points no other point beats on both axes (fewer transmissions and lower cost),
    sorted by transmissions."""
    front, best_cost = [], float("inf")
    for candidate in sorted(points, key=lambda p: (sent(p), cost(p))):
        if cost(candidate) < best_cost:
            front.append(candidate)
            best_cost = cost(candidate)
    return front


LEARNED = "learned"
"""The method of a learned point that names none (results written before methods existed)."""

STYLES = {
    "paper": ("o", "-", "C0", "paper trigger (threshold sweep)"),
    "periodic": ("s", "--", "C1", "periodic (clock)"),
    "error_time": ("P", "-.", "C8", "error-time rule (threshold sweep)"),
    "hand_menu": ("h", "-", "C7", "hand menu (every earlier trigger's point)"),
}
LEARNED_STYLES = [("*", ":", "C3"), ("D", ":", "C2"), ("^", ":", "C4"), ("v", ":", "C5")]
"""Marker, line and colour of each learned method in turn."""


def series(result: dict[str, Any]) -> list[tuple[tuple[str, str, str, str], list[dict]]]:
    """The curves to draw: the paper sweep, the periodic sweep, another rule's sweep where the
    result has one, then one per learned method (in order of appearance), each with its
    (marker, line, colour, label)."""
    drawn = [(STYLES[name], result["curves"][name]) for name in STYLES if name in result["curves"]]
    for index, (method, points) in enumerate(learned_methods(result)):
        marker, line, color = LEARNED_STYLES[index % len(LEARNED_STYLES)]
        drawn.append(((marker, line, color, method), points))
    return drawn


def learned_methods(result: dict[str, Any]) -> list[tuple[str, list[dict[str, Any]]]]:
    """Each learned method of ``result`` (in order of appearance) with its points."""
    learned = result["curves"].get("learned", [])
    methods = list(dict.fromkeys(point.get("method", LEARNED) for point in learned))
    return [
        (method, [point for point in learned if point.get("method", LEARNED) == method])
        for method in methods
    ]


def _draw_set(axes: plt.Axes, result: dict[str, Any]) -> None:
    """Means with interval bars; fronts joined, dominated points faint, failures crossed (the
    learned methods first, so that the baselines' smaller markers stay visible on them)."""
    for (marker, line, color, label), points in reversed(series(result)):
        learned = label not in {style[3] for style in STYLES.values()}
        usable = [p for p in points if p["transmissions"]["mean"] > 0]
        failed = [p for p in usable if p["failures"]]
        finished = [p for p in usable if not p["failures"]]
        front = non_dominated(
            finished, lambda p: p["mean_cost"]["mean"], lambda p: p["transmissions"]["mean"]
        )
        for group, alpha in ((finished, 0.25), (front, 1.0)):
            if not group:
                continue
            axes.errorbar(
                [p["transmissions"]["mean"] for p in group],
                [p["mean_cost"]["mean"] for p in group],
                xerr=_bars([p["transmissions"] for p in group]),
                yerr=_bars([p["mean_cost"] for p in group]),
                fmt=marker + (line if group is front else ""),
                color=color,
                alpha=alpha,
                markersize=9 if learned else 5,
                capsize=2,
                linewidth=1.2,
            )
        if failed:
            axes.plot(
                [p["transmissions"]["mean"] for p in failed],
                [p["mean_cost"]["mean"] for p in failed],
                "x",
                color=color,
                markersize=8,
            )


def _bars(summaries: list[dict[str, Any]]) -> list[list[float]]:
    return [
        [max(s["mean"] - s["mean_ci95"][0], 0.0) for s in summaries],
        [max(s["mean_ci95"][1] - s["mean"], 0.0) for s in summaries],
    ]


def _draw_paper_scenario(axes: plt.Axes, result: dict[str, Any]) -> None:
    for (marker, line, color, label), points in reversed(series(result)):
        learned = label not in {style[3] for style in STYLES.values()}
        scenario = [
            p["paper_scenario"]
            for p in points
            if p["paper_scenario"] is not None and p["paper_scenario"]["transmissions"]
        ]
        finished = [p for p in scenario if p["failure"] is None]
        front = non_dominated(finished, lambda p: p["mean_cost"], lambda p: p["transmissions"])
        axes.plot(
            [p["transmissions"] for p in finished],
            [p["mean_cost"] for p in finished],
            marker,
            color=color,
            alpha=0.25,
        )
        axes.plot(
            [p["transmissions"] for p in front],
            [p["mean_cost"] for p in front],
            marker + line,
            color=color,
            markersize=9 if learned else 5,
        )
        failed = [p for p in scenario if p["failure"] is not None]
        axes.plot(
            [p["transmissions"] for p in failed],
            [p["mean_cost"] for p in failed],
            "x",
            color=color,
            markersize=8,
        )


def _log_axes(axes: plt.Axes, costs: list[float]) -> None:
    """Log transmissions; log cost (symlog when a cost is 0), major labels only — and the
    cost's minor ticks too when its costs lie within one decade (no major tick to label)."""
    axes.set_xscale("log")
    positive = [cost for cost in costs if cost > 0]
    within_a_decade = bool(positive) and max(positive) < 10.0 * min(positive)
    if positive and len(positive) == len(costs):
        axes.set_yscale("log")
    else:  # a zero cost (paper 003 inside its shell) has no place on a log axis
        axes.set_yscale("symlog", linthresh=min(positive, default=1.0))
        axes.set_ylim(bottom=0.0)
        within_a_decade = False
    axes.xaxis.set_minor_formatter(ticker.NullFormatter())
    axes.yaxis.set_minor_formatter(
        ticker.FormatStrFormatter("%.3g") if within_a_decade else ticker.NullFormatter()
    )
    axes.xaxis.set_major_locator(ticker.LogLocator(numticks=6))
    axes.grid(True, which="both", alpha=0.3)
    axes.set_xlabel("transmissions per episode")


def plot(result: dict[str, Any], path: Path) -> None:
    """The scenario set's curves (left, with intervals) and the paper scenario's (right)."""
    figure, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.8))
    _draw_set(left, result)
    _draw_paper_scenario(right, result)
    points = [p for curve in result["curves"].values() for p in curve]
    _log_axes(left, [p["mean_cost"]["mean"] for p in points])
    _log_axes(right, [p["paper_scenario"]["mean_cost"] for p in points if p["paper_scenario"]])
    left.set_ylabel("mean_cost (accuracy cost per step)")
    left.set_title(
        f"{result['scenarios']} set, {result['set_size']} scenarios: mean, 95 % intervals",
        fontsize=10,
    )
    right.set_title("paper scenario", fontsize=10)
    handles = [
        plt.Line2D([], [], marker=marker, linestyle=line, color=color, label=label)
        for (marker, line, color, label), _ in series(result)
    ]
    handles.append(plt.Line2D([], [], marker="x", linestyle="", color="k", label="with failures"))
    figure.legend(handles=handles, loc="lower center", ncol=4, frameon=False)
    figure.suptitle(f"{result['env']}: accuracy against communication", fontsize=11)
    figure.tight_layout(rect=(0, 0.08, 1, 0.95))
    save(figure, path)


def _earlier_result(text: str) -> dict[str, Any]:
    """``--reuse``: the ``pareto.json`` of an earlier run, read as a JSON object."""
    try:
        reuse = json.loads(Path(text).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as error:
        raise argparse.ArgumentTypeError(
            f"takes the pareto.json of an earlier run, got {text!r} ({type(error).__name__})"
        ) from None
    if not isinstance(reuse, dict):
        raise argparse.ArgumentTypeError(
            f"takes the pareto.json of an earlier run, got {text!r} (not a JSON object)"
        )
    return reuse


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.judge.pareto",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("env_id", choices=PAPER_IDS)
    parser.add_argument(
        "--model",
        action="append",
        default=[],
        help="an SB3 zip or a learned trigger (learned:PATH or .json; repeatable)",
    )
    parser.add_argument("--scenarios", choices=("test", "validation"), default="test")
    parser.add_argument("--set-size", type=positive_integer, default=DEFAULT_SET_SIZE, metavar="K")
    parser.add_argument(
        "--sweep",
        action="append",
        default=[],
        metavar="RESULTS_DIR",
        help="add the model of every finished trial of a sweep (agents.sweep; repeatable)",
    )
    parser.add_argument(
        "--judged",
        action="append",
        default=[],
        type=Path,
        metavar="RESULTS_DIR",
        help="add the models judged by agents.judge.results under a folder, read from their "
        "records without running them again (repeatable)",
    )
    parser.add_argument(
        "--menu",
        action="append",
        default=[],
        type=Path,
        metavar="PARETO_JSON",
        help="every point of an earlier result joins the hand-menu front (repeatable)",
    )
    parser.add_argument("--env-arg", action="append", metavar="K=V", help="env keyword")
    parser.add_argument("--out", type=output_folder_argument("--out"), help="output folder")
    parser.add_argument(
        "--reuse",
        type=_earlier_result,
        metavar="PARETO_JSON",
        help="keep the paper and periodic curves of an earlier run; run only the models",
    )
    args = parser.parse_args(argv)
    limit_torch_threads()
    out_dir = args.out or Path("results") / "pareto" / args.env_id.split("/")[-1]
    try:
        require_writable_folder(out_dir, "--out")
        env_kwargs = parse_assignments(args.env_arg, "--env-arg")
        reuse = args.reuse
        models, methods = list(args.model), [LEARNED] * len(args.model)
        for results_dir in args.sweep:
            found = sweep_models([results_dir], args.env_id)
            models += found
            methods += [Path(results_dir).name] * len(found)
        result = pareto(
            args.env_id,
            models,
            env_kwargs,
            args.scenarios,
            args.set_size,
            reuse,
            methods,
            args.judged,
            [read_json_file(path, f"--menu {path}") for path in args.menu],
        )
        write_json(result, str(out_dir / "pareto.json"))
        plot(result, out_dir / "pareto.png")
    except (ValueError, TypeError, OSError, gym.error.Error) as error:
        parser.error(str(error))
    except KeyboardInterrupt:
        print("\ninterrupted; no file was left partly written", file=sys.stderr)
        return 130
    for name, points in result["curves"].items():
        for point in points:
            cost, sent = point["mean_cost"], point["transmissions"]
            print(
                f"{name:9s} {json.dumps(point['args'])[:40]:40s} mean_cost {cost['mean']:.4g} "
                f"transmissions {sent['mean']:.4g} failures {point['failures']}"
            )
    for method, verdicts in result["fronts"].items():
        for where, verdict in verdicts.items():
            place = "paper scenario" if where.startswith("paper") else f"{args.scenarios} set"
            line = menu_line if where.endswith("_menu") else verdict_line
            print(line(method, place, verdict))
    methods = {method for method, _ in learned_methods(result)}
    if any(name not in methods for name in result["fronts"]):
        print(
            "a front's menu verdicts are per search setting; one is a claim only where that "
            "setting was chosen on the validation set (python -m agents.judge.penalty_choice)"
        )
    print(f"wrote {out_dir / 'pareto.json'} and {out_dir / 'pareto.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""The leaderboard: every id's triggers on the test set and the paper scenario, from the records.

    python -m agents.leaderboard [--records DIR] [--out PATH]

Reads the judged records under ``docs/results/`` — ``results.json`` of ``agents.judge.results``,
``pareto.json`` of ``agents.judge.pareto`` and the JSON of ``baselines.evaluate --json`` — and runs
nothing. Writes ``docs/leaderboard.md`` and one figure per id beside it
(``docs/leaderboard/<EnvName>.png``).

Per id (:data:`BOARDS`), one row per trigger, each from a named record:

* **always** — transmit at every instant (the periodic sweep's ``every=1`` point, or a
  ``<EnvName>_always/`` record of ``baselines.evaluate --policy always``);
* **the paper's rule** at the paper's thresholds, and **the clock** at the best rule's rate
  (periodic transmission every ``k`` instants, ``k`` matched to it), both from the best rule's
  record;
* **the best hand-designed rule** — the rule variant the validation set chose from a menu,
  judged as the self-triggered PPO policy pinned to it (it takes the rule's actions exactly);
* **per-instant PPO** (``<EnvName>_ppo/``) and **self-triggered PPO** (PPO free to move its
  decisions, where such a run was judged);
* **learned trigger (ES)** — ``<EnvName>_learned/results.json`` wherever it exists (a
  parametric trigger family optimised by ``agents.search``).

Absolute means come with 95 % intervals from :mod:`etsc_envs.evaluation.statistics`: over the
scenarios for one run (:func:`~etsc_envs.evaluation.statistics.summarize`), over runs × scenarios
for several training seeds (:func:`~etsc_envs.evaluation.statistics.seeds_summary`, rliable's
stratified bootstrap); a sweep point keeps the interval its ``pareto.json`` records. The across-id
summary treats each test scenario of each id as one task, a method's score on it being its mean
over its seeds: the IQM of the per-scenario cost and transmission ratios to the paper's rule, and
the probability that the method's cost is below the rule's (ties one half), with bootstrap
intervals over the tasks (:func:`~etsc_envs.evaluation.statistics.paired_ratio`).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib import ticker

from baselines.plotting import save
from etsc_envs.core.files import atomic_write_text
from etsc_envs.evaluation.statistics import paired_ratio, seeds_summary, summarize

ROOT = Path(__file__).resolve().parents[2]
RECORDS = ROOT / "docs" / "results"
OUTPUT = ROOT / "docs" / "leaderboard.md"
DATA = ROOT / "etsc_envs" / "data" / "leaderboard.json"
"""The rows as package data (:func:`etsc_envs.leaderboard` reads them)."""
SETS = ("test", "paper")
"""The test set (64 scenarios) and the paper scenario."""


@dataclass(frozen=True)
class Board:
    """Where one id's rows come from (folders under the records directory).

    Attributes:
        env_id: the registered id.
        paper: the paper's number in the suite ("000" .. "004").
        sweeps: folder whose ``pareto.json`` holds the paper's threshold sweep and the periodic
            sweep on both sets (and the λ front drawn beside them).
        best: folder of the best hand-designed rule's ``results.json`` (its paper rule and its
            clock at the rule's rate are read there too).
        best_label: what that rule is, and how the judged policy holds it.
        self_triggered: folder of the self-triggered PPO run whose decisions PPO could move,
            or ``None`` where every judged self-triggered run was pinned to a rule.
        self_triggered_label: what that run is, or why there is none.
        front_label: what the λ front of ``sweeps`` is.
    """

    env_id: str
    paper: str
    sweeps: str
    best: str
    best_label: str
    self_triggered: str | None
    self_triggered_label: str
    front_label: str

    @property
    def name(self) -> str:
        """The id without its namespace, as records and figures are named."""
        return self.env_id.removeprefix("etsc/")


PINNED = "; chosen on validation, held by a pinned PPO policy (5 seeds)"
"""How the best rule's record holds it, where PPO was pinned to it."""

BOARDS = (
    Board(
        "etsc/OrbitAttitudeTracking-v0",
        "000",
        "OrbitAttitudeTracking-v0_holds_selected_front",
        "OrbitAttitudeTracking-v0_self_triggered_floor_relative_edge",
        "eq. (21) at γ × 4 with a1, a2 = 3.1, 3.5, gating a clock of 64 instants" + PINNED,
        None,
        "none judged: every self-triggered run was pinned to a rule or a clock",
        "λ front: eq. (21) at γ × 0.3 or clocks, chosen per λ on validation",
    ),
    Board(
        "etsc/ClusterContainment-v0",
        "001",
        "ClusterContainment-v0_channel_heartbeat_selected_front",
        "ClusterContainment-v0_self_triggered",
        "eq. (15) at c = 0.99 for every follower" + PINNED,
        None,
        "none judged: every self-triggered run was pinned to a rule",
        "λ front: eq. (15) with a heartbeat per follower, chosen per λ on validation",
    ),
    Board(
        "etsc/ClusterContainmentCentral-v0",
        "001",
        "ClusterContainmentCentral-v0_heartbeat_selected_front",
        "ClusterContainmentCentral-v0_self_triggered",
        "eq. (15) at c = 0.99" + PINNED,
        None,
        "none judged: every self-triggered run was pinned to a rule",
        "λ front: eq. (15) with a heartbeat per follower, chosen per λ on validation",
    ),
    Board(
        "etsc/AttitudeTracking-v0",
        "002",
        "AttitudeTracking-v0_selected_front",
        "AttitudeTracking-v0_self_triggered",
        "eq. (27) at 8Ψ with a heartbeat of 384 instants" + PINNED,
        "AttitudeTracking-v0_self_triggered_stage2",
        "holds or eq. (27) × f from scratch, λ = 100 then 300, 3 seeds",
        "λ front: rule with a heartbeat or clocks, chosen per λ on validation",
    ),
    Board(
        "etsc/AsteroidOrbitKeeping-v0",
        "003",
        "AsteroidOrbitKeeping-v0_self_triggered_front",
        "AsteroidOrbitKeeping-v0_self_triggered",
        "eq. (15) at α/16; chosen on validation, cloned into a PPO policy that kept it (5 seeds)",
        "AsteroidOrbitKeeping-v0_self_triggered_scratch/transmission_penalty=1",
        "holds or eq. (15) × f from scratch, λ = 1, 1 seed",
        "λ front: cloned from α/16, PPO at 4 λ",
    ),
    Board(
        "etsc/InnerFormation-v0",
        "004",
        "InnerFormation-v0_error_time_selected_front",
        "InnerFormation-v0_self_triggered_error_time",
        "error-time rule at 6A (not the paper's: interval ∝ v^(-1/2))" + PINNED,
        "InnerFormation-v0_self_triggered",
        "cloned from eqs. (4)-(6) at 2Π, then PPO, 5 seeds",
        "λ front: error-time rule or clocks, chosen per λ on validation",
    ),
)
"""Every id's rows, in the papers' order."""

SHORT_NAMES = {
    board.env_id: board.paper + (" central" if "Central" in board.env_id else "")
    for board in BOARDS
}
"""Each id as the across-id table names it: its paper, and which form of paper 001."""

PPO_LABEL = "one seed, trained before the protocol (checkpoint chosen on the paper scenario)"


@dataclass
class Measure:
    """One trigger on one scenario set.

    ``cost`` and ``sent`` are ``(runs, scenarios)`` per-episode values where the record keeps
    episodes, ``None`` for a sweep point (whose summaries come from ``pareto.json``).
    """

    cost: dict[str, Any]
    sent: dict[str, Any]
    failures: int
    episodes: int
    cost_values: np.ndarray | None = None
    sent_values: np.ndarray | None = None
    seeds: tuple[int, ...] = ()


@dataclass
class Row:
    """One leaderboard row: a trigger, what it is, its record and its measures per set."""

    trigger: str
    what: str
    record: str
    sets: dict[str, Measure | None]


def _load(path: Path) -> dict[str, Any]:
    return json.loads(path.read_text(encoding="utf-8"))


def _episodes_measure(runs: list[list[dict[str, Any]]]) -> Measure:
    """A measure of one or more runs' episode records (runs of one policy on the same
    scenarios, in the same order)."""
    cost = np.array([[episode["mean_cost"] for episode in run] for run in runs], dtype=float)
    sent = np.array([[episode["transmissions"] for episode in run] for run in runs], dtype=float)
    failures = sum(episode["failure"] is not None for run in runs for episode in run)
    seeds = tuple(int(episode["seed"]) for episode in runs[0])
    return Measure(_summary(cost), _summary(sent), failures, cost.size, cost, sent, seeds)


def _summary(values: np.ndarray) -> dict[str, Any]:
    """Mean and interval of ``(runs, scenarios)`` values; runs that recorded the same values
    (the seeds of a pinned policy) count as one run."""
    if np.all(values == values[0]):
        values = values[:1]
    if values.shape[0] == 1:
        summary = summarize(values[0])
        return {"mean": summary["mean"], "mean_ci95": summary["mean_ci95"]}
    return seeds_summary(values)


def _record_measure(record: dict[str, Any], name: str, part: str) -> Measure | None:
    """``part`` ("paper", "learned" or "periodic") of a ``results.json`` on set ``name``."""
    judged = record["sets"].get(name)
    if judged is None:
        return None
    if part == "paper":
        return _episodes_measure([judged["paper"]["episodes"]])
    runs = [model[part]["episodes"] for model in judged["models"]]
    if part == "periodic":  # the seeds of one rate share one clock
        runs = runs[:1]
    return _episodes_measure(runs)


def _sweep_measure(point: dict[str, Any], name: str) -> Measure:
    """A ``pareto.json`` point on the test set or its paper-scenario episode."""
    if name == "test":
        return Measure(
            point["mean_cost"], point["transmissions"], point["failures"], point["mean_cost"]["n"]
        )
    scenario = point["paper_scenario"]
    return Measure(
        {"mean": scenario["mean_cost"], "mean_ci95": None},
        {"mean": scenario["transmissions"], "mean_ci95": None},
        int(scenario["failure"] is not None),
        1,
    )


def _evaluate_measure(path: Path) -> Measure | None:
    """The episodes of a ``baselines.evaluate --json`` file, if it exists."""
    return _episodes_measure([_load(path)["episodes"]]) if path.is_file() else None


def _results_row(
    records: Path, folder: str | None, trigger: str, what: str, part: str = "learned"
) -> Row:
    if folder is None or not (records / folder / "results.json").is_file():
        return Row(trigger, what, "—", dict.fromkeys(SETS))
    record = _load(records / folder / "results.json")
    return Row(
        trigger,
        what,
        f"`{folder}/`",
        {name: _record_measure(record, name, part) for name in SETS},
    )


def _always_row(records: Path, board: Board, sweeps: dict[str, Any]) -> Row:
    what = "transmit at every instant"
    folder = f"{board.name}_always"
    if (records / folder).is_dir():
        sets = {name: _evaluate_measure(records / folder / f"{name}.json") for name in SETS}
        return Row("always", what, f"`{folder}/`", sets)
    every_instant = [p for p in sweeps["curves"]["periodic"] if p["args"].get("every") == 1]
    if not every_instant:
        return Row("always", what, "—", dict.fromkeys(SETS))
    sets = {name: _sweep_measure(every_instant[0], name) for name in SETS}
    return Row("always", what + " (the clock every instant)", f"`{board.sweeps}/`", sets)


def board_rows(records: Path, board: Board) -> list[Row]:
    """Every row of one id, in the leaderboard's order."""
    sweeps = _load(records / board.sweeps / "pareto.json")
    best = _load(records / board.best / "results.json")
    every = [best["sets"][name]["models"][0]["periodic_every"] for name in SETS]
    best_record = f"`{board.best}/`"
    rows = [
        _always_row(records, board, sweeps),
        Row(
            "paper's rule",
            "the paper's thresholds",
            best_record,
            {name: _record_measure(best, name, "paper") for name in SETS},
        ),
        Row(
            "clock",
            f"every {every[0]} (test set) and {every[1]} (paper scenario) instants: "
            "the best rule's rate",
            best_record,
            {name: _record_measure(best, name, "periodic") for name in SETS},
        ),
        Row(
            "best hand-designed rule",
            board.best_label,
            best_record,
            {name: _record_measure(best, name, "learned") for name in SETS},
        ),
        _results_row(records, f"{board.name}_ppo", "per-instant PPO", PPO_LABEL),
        _results_row(
            records, board.self_triggered, "self-triggered PPO", board.self_triggered_label
        ),
    ]
    for folder in sorted(records.glob(f"{board.name}_learned*/results.json")):
        name = folder.parent.name
        variant = name.removeprefix(f"{board.name}_learned").strip("_").replace("_", " ")
        trigger = LEARNED + (f", {variant})" if variant else ")")
        seeds = len(_load(folder)["models"])
        what = f"the rule's parametric family searched with CMA-ES ({seeds} search seeds)"
        rows.append(_results_row(records, name, trigger, what))
    return rows


LEARNED = "learned trigger (ES"
"""The start of a learned trigger's row name; a ``<EnvName>_learned_<variant>/`` record adds
its variant (``learned trigger (ES, modulated)``)."""


def _number(value: float) -> str:
    if value == 0.0:
        return "0"
    if abs(value) >= 1e5 or abs(value) < 1e-3:
        return f"{value:.3e}"
    return f"{value:.4g}"


def _with_interval(summary: dict[str, Any]) -> str:
    text = _number(summary["mean"])
    interval = summary.get("mean_ci95")
    if interval is None or interval[0] == interval[1]:
        return text
    return f"{text} [{_number(interval[0])}, {_number(interval[1])}]"


def _cells(measure: Measure | None) -> list[str]:
    if measure is None:
        return ["—", "—", "—"]
    return [
        _with_interval(measure.cost),
        _with_interval(measure.sent),
        f"{measure.failures}/{measure.episodes}",
    ]


def _table(rows: list[Row]) -> list[str]:
    lines = [
        "| trigger | what it is | test: mean cost | test: transmissions | test: failures "
        "| paper scenario: mean cost | paper scenario: transmissions | paper scenario: failures "
        "| record |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        cells = [row.trigger, row.what, *_cells(row.sets["test"]), *_cells(row.sets["paper"])]
        lines.append("| " + " | ".join([*cells, row.record]) + " |")
    return lines


SUMMARY_TRIGGERS = (
    "always",
    "clock",
    "best hand-designed rule",
    "per-instant PPO",
    "self-triggered PPO",
)
"""The triggers of the across-id summary (with every learned trigger found), each over the ids
whose record keeps its test episodes."""


def _scenario_scores(measure: Measure, reference: Measure) -> tuple[np.ndarray, np.ndarray]:
    """Each scenario's cost and transmissions averaged over the runs, checked to be the
    ``reference``'s scenarios in its order."""
    if measure.cost_values is None or measure.sent_values is None:
        raise ValueError("a sweep point keeps no episodes to compare scenario by scenario")
    if measure.seeds != reference.seeds:
        raise ValueError(f"records on other scenarios: {measure.seeds} against {reference.seeds}")
    return measure.cost_values.mean(axis=0), measure.sent_values.mean(axis=0)


def across_ids(boards: dict[str, list[Row]]) -> list[dict[str, Any]]:
    """The test-set summary of each trigger over the ids that have its record: the IQM of the
    per-scenario ratios to the paper's rule (cost and transmissions) and the probability of a
    lower cost than the rule, with bootstrap intervals over the scenarios of all those ids."""
    summary = []
    learned = sorted({row.trigger for rows in boards.values() for row in rows} - set(ROW_STYLES))
    for trigger in (*SUMMARY_TRIGGERS, *learned):
        costs, sents, paper_costs, paper_sents, ids = [], [], [], [], []
        for env_id, rows in boards.items():
            by_name = {row.trigger: row for row in rows}
            row, paper = by_name.get(trigger), by_name["paper's rule"].sets["test"]
            if row is None or row.sets["test"] is None or row.sets["test"].cost_values is None:
                continue
            cost, sent = _scenario_scores(row.sets["test"], paper)
            reference_cost, reference_sent = _scenario_scores(paper, paper)
            costs.append(cost)
            sents.append(sent)
            paper_costs.append(reference_cost)
            paper_sents.append(reference_sent)
            ids.append(env_id)
        if not ids:
            continue
        cost_ratio = paired_ratio(np.concatenate(costs), np.concatenate(paper_costs))
        sent_ratio = paired_ratio(np.concatenate(sents), np.concatenate(paper_sents))
        summary.append(
            {"trigger": trigger, "ids": ids, "cost": cost_ratio, "transmissions": sent_ratio}
        )
    return summary


def _ratio_cell(ratio: dict[str, Any], key: str) -> str:
    value, interval = ratio[key], ratio[f"{key}_ci95"]
    return f"{value:.3g} [{interval[0]:.3g}, {interval[1]:.3g}]"


def _summary_table(summary: list[dict[str, Any]]) -> list[str]:
    lines = [
        "| trigger | papers | scenarios | IQM cost / paper's rule "
        "| IQM transmissions / paper's rule | P(cost below the paper's rule) "
        "| scenarios where the rule costs 0 and it does not |",
        "|---|---|---|---|---|---|---|",
    ]
    for entry in summary:
        ids = ", ".join(SHORT_NAMES[env_id] for env_id in entry["ids"])
        cost = entry["cost"]
        lines.append(
            f"| {entry['trigger']} | {ids} | {cost['n']} | {_ratio_cell(cost, 'iqm')} "
            f"| {_ratio_cell(entry['transmissions'], 'iqm')} "
            f"| {_ratio_cell(cost, 'probability_of_improvement')} "
            f"| {cost['worse_where_reference_zero']} |"
        )
    return lines


ROW_STYLES = {
    "always": {"marker": "s", "color": "0.3", "markerfacecolor": "none", "markersize": 9},
    "paper's rule": {"marker": "o", "color": "C0", "markersize": 10},
    "clock": {"marker": "s", "color": "C1", "markersize": 9},
    "best hand-designed rule": {"marker": "*", "color": "C3", "markersize": 16},
    "per-instant PPO": {"marker": "^", "color": "C4", "markersize": 10},
    "self-triggered PPO": {"marker": "v", "color": "C5", "markersize": 10},
}
"""Each row's marker in the figures; a learned trigger takes one of :data:`LEARNED_STYLES`."""

LEARNED_STYLES = (
    {"marker": "D", "color": "C2", "markersize": 10},
    {"marker": "P", "color": "C9", "markersize": 11},
    {"marker": "X", "color": "C6", "markersize": 11},
)


def _style(trigger: str, triggers: list[str]) -> dict[str, Any]:
    """The marker of ``trigger`` among a figure's ``triggers``."""
    if trigger in ROW_STYLES:
        return ROW_STYLES[trigger]
    learned = [name for name in triggers if name not in ROW_STYLES]
    return LEARNED_STYLES[learned.index(trigger) % len(LEARNED_STYLES)]


SWEEP_STYLES = {
    "paper": ("o-", "C0", "paper's rule, threshold sweep"),
    "periodic": ("s--", "C1", "clock, period sweep"),
    "error_time": ("P-.", "C8", "error-time rule, threshold sweep"),
}
"""The sweeps' lines in the figures (``pareto.json`` curves)."""


def _curve(points: list[dict[str, Any]], name: str) -> tuple[list[float], list[float]]:
    """A sweep's points on one set without those that failed, by transmissions."""
    measures = [_sweep_measure(point, name) for point in points]
    kept = sorted(
        (m for m in measures if m.sent["mean"] > 0 and not m.failures),
        key=lambda m: m.sent["mean"],
    )
    return [m.sent["mean"] for m in kept], [m.cost["mean"] for m in kept]


def _front(points: list[dict[str, Any]], name: str) -> tuple[list[float], list[float]]:
    """The λ front's points on one set, each λ the mean over its seeds."""
    groups: dict[str, list[Measure]] = {}
    for point in points:
        groups.setdefault(point["policy"].split("seed=")[0], []).append(_sweep_measure(point, name))
    pairs = sorted(
        (
            float(np.mean([m.sent["mean"] for m in group])),
            float(np.mean([m.cost["mean"] for m in group])),
        )
        for group in groups.values()
    )
    return [x for x, _ in pairs], [y for _, y in pairs]


NARROW = 0.25
"""A cost interval is drawn where it spans less than this fraction of the panel's height; a
wider one (the scenarios' spread, larger than the triggers' differences) would hide the points,
and the paired comparisons of the report are the ones that separate triggers."""


def _span(values: list[float], log: bool, pad: float = 0.08) -> tuple[float, float]:
    """Limits around ``values`` with a margin (a factor on a log axis)."""
    low, high = min(values), max(values)
    if log:
        ratio = (high / low) ** pad if high > low else 1.5
        return low / ratio, high * ratio
    margin = pad * (high - low) if high > low else max(abs(high), 1.0) * 0.05
    return low - margin, high + margin


def _panel(
    axes: plt.Axes, board: Board, rows: list[Row], sweeps: dict[str, Any], name: str
) -> None:
    """One set's panel: sweeps and front as lines, rows as markers; the axes span the paper's
    sweep, the front and the rows (``always`` aside); a row outside them is drawn at the edge
    with its numbers written beside it."""
    curves = {
        curve: _curve(sweeps["curves"][curve], name)
        for curve in SWEEP_STYLES
        if curve in sweeps["curves"]
    }
    if sweeps["curves"].get("learned"):
        curves["front"] = _front(sweeps["curves"]["learned"], name)
    measures = [(row.trigger, row.sets[name]) for row in rows if row.sets[name] is not None]
    core_x = curves["paper"][0] + curves.get("front", ([], []))[0]
    core_x += [m.sent["mean"] for trigger, m in measures if trigger != "always" and not m.failures]
    x_low, x_high = _span([x for x in core_x if x > 0], log=True, pad=0.25)
    inside = [
        y
        for curve, (xs, ys) in curves.items()
        for x, y in zip(xs, ys, strict=True)
        if x_low <= x <= x_high and (curve != "periodic" or y <= 1.5 * max(curves["paper"][1]))
    ]
    inside += [m.cost["mean"] for _, m in measures if not m.failures]
    log_cost = min(inside) > 0 and max(inside) > 3 * min(inside)
    y_low, y_high = _span(inside, log=log_cost)
    for curve, (xs, ys) in curves.items():
        if curve == "front":
            axes.plot(xs, ys, "d:", color="C7", markersize=5, label=board.front_label)
        else:
            fmt, color, label = SWEEP_STYLES[curve]
            axes.plot(xs, ys, fmt, color=color, markersize=4, alpha=0.6, label=label)
    off_axes: list[str] = []
    for trigger, measure in measures:
        x, y = measure.sent["mean"], measure.cost["mean"]
        style = _style(trigger, [row.trigger for row in rows])
        if x_low <= x <= x_high and y_low <= y <= y_high:
            interval = measure.cost.get("mean_ci95")
            narrow = interval is not None and interval[1] - interval[0] < NARROW * (y_high - y_low)
            axes.errorbar(
                [x],
                [y],
                xerr=_bar(measure.sent),
                yerr=_bar(measure.cost) if narrow else None,
                capsize=3,
                elinewidth=1,
                linestyle="",
                zorder=4,
                **style,
            )
            if measure.failures:
                axes.plot(x, y, "x", color="k", markersize=12, zorder=5)
            continue
        edge_x, edge_y = min(max(x, x_low), x_high), min(max(y, y_low), y_high)
        axes.plot(edge_x, edge_y, linestyle="", zorder=4, clip_on=False, **style)
        if measure.failures:
            axes.plot(edge_x, edge_y, "x", color="k", markersize=12, zorder=5, clip_on=False)
        failed = f", {measure.failures}/{measure.episodes} failed" if measure.failures else ""
        off_axes.append(f"{trigger} {_number(x)} sent, cost {_number(y)}{failed}")
    axes.set_xscale("log")
    axes.set_xlim(x_low, x_high)
    if log_cost:
        axes.set_yscale("log")
    axes.set_ylim(y_low, y_high)
    if x_high / x_low < 150:  # under about two decades: label 2 and 5 times each power too
        axes.xaxis.set_minor_locator(ticker.LogLocator(subs=(2.0, 5.0)))
        axes.xaxis.set_minor_formatter(ticker.FuncFormatter(lambda value, _: f"{value:g}"))
    else:
        axes.xaxis.set_minor_formatter(ticker.NullFormatter())
    axes.grid(True, which="both", alpha=0.3)
    label = "transmissions per episode (log axis)"
    if off_axes:
        label += "\n" + "\n".join(f"off the axes: {item}" for item in off_axes)
    axes.set_xlabel(label)


def _bar(summary: dict[str, Any]) -> list[list[float]] | None:
    interval = summary.get("mean_ci95")
    if interval is None:
        return None
    mean = summary["mean"]
    return [[max(mean - interval[0], 0.0)], [max(interval[1] - mean, 0.0)]]


def figure(board: Board, rows: list[Row], sweeps: dict[str, Any], path: Path) -> None:
    """Accuracy against transmissions on the test set (left) and the paper scenario (right):
    the sweeps and the λ front as lines, each leaderboard row as a marker with its 95 %
    intervals (a cost interval wider than the panel, where scenarios differ more than
    triggers, is left out), a cross over a row with failures."""
    fig, panels = plt.subplots(1, 2, figsize=(12.0, 5.2))
    titles = (
        "test set, 64 scenarios: means (95 % intervals where narrow)",
        "paper scenario (one episode; intervals over seeds)",
    )
    for axes, name, title in zip(panels, SETS, titles, strict=True):
        _panel(axes, board, rows, sweeps, name)
        axes.set_title(title, fontsize=10)
    panels[0].set_ylabel("mean cost per step (lower is better)")
    handles, labels = panels[0].get_legend_handles_labels()
    for trigger in [row.trigger for row in rows if any(row.sets.values())]:
        style = _style(trigger, [row.trigger for row in rows])
        handles.append(plt.Line2D([], [], linestyle="", **style))
        labels.append(trigger)
    handles.append(plt.Line2D([], [], marker="x", linestyle="", color="k", markersize=9))
    labels.append("failures in some episodes")
    fig.legend(handles, labels, loc="lower center", ncol=3, frameon=False, fontsize=9)
    fig.suptitle(f"{board.env_id} (paper {board.paper}): accuracy against communication")
    fig.tight_layout(rect=(0, 0.14, 1, 0.97))
    save(fig, path)


HEADER = """# Leaderboard

Generated by `python -m agents.leaderboard` from the judged records under
[`results/`](results/) alone (nothing is re-run; do not edit by hand). Each id's table gives the
mean per-step accuracy cost (the env's `mean_cost`, lower is better) and the transmissions per
episode, with 95 % intervals, and the failed episodes, on the 64-scenario test set and the
paper scenario ([`protocol.md`](protocol.md)). A row over several training seeds pools them
(rliable's stratified bootstrap over scenarios and seeds; seeds that recorded the same episodes
count once); a sweep point keeps its `pareto.json` interval; the paper scenario is one episode
per seed. The best hand-designed rule is a menu choice made on the validation set — a tuned
baseline, not a learned trigger — judged as the self-triggered PPO policy started from it
(pinned, on 003 cloned), which took exactly its actions. The report is [`results.md`](results.md).
"""


def _units(board: Board) -> list[str]:
    """What an id's mean cost is (:attr:`etsc_envs.core.paper.Paper.cost`), with its env page."""
    from etsc_envs.papers import paper_of

    return [
        f"Mean cost: the mean per-step `mean_cost`, {paper_of(board.env_id).cost}; the env: "
        f"[{board.name}](envs/{board.name}.md); score a trigger against these rows: "
        "[benchmark.md](benchmark.md)."
    ]


def render(records: Path, figures: Path | None, link: str) -> str:
    """The leaderboard's Markdown (``link`` is the figures' folder as the page refers to it);
    draws the figures into ``figures`` unless it is ``None``."""
    boards = {board.env_id: board_rows(records, board) for board in BOARDS}
    lines = [HEADER, "## Across ids (test set)", ""]
    lines += [
        "Every test scenario of every id with the trigger's record is one task; a trigger's "
        "score on it is its mean over its seeds, divided by the paper's rule's on the same "
        "scenario. IQM (the interquartile mean, rliable's aggregate) and the probability of "
        "improvement come with bootstrap intervals over the tasks; a scenario where the rule's "
        "cost is 0 and the trigger's is not has no ratio and is counted in the last column "
        "(paper 003, inside its shell). `always` enters only where its episodes are recorded "
        "(a sweep point keeps none).",
        "",
        *_summary_table(across_ids(boards)),
        "",
    ]
    for board in BOARDS:
        rows = boards[board.env_id]
        lines += [
            f"## `{board.env_id}` (paper {board.paper})",
            "",
            *_units(board),
            "",
            *_table(rows),
            "",
        ]
        image = f"{link}/{board.name}.png"
        lines += [f"![{board.env_id}: cost against transmissions]({image})", ""]
        if figures is not None:
            sweeps = _load(records / board.sweeps / "pareto.json")
            figure(board, rows, sweeps, figures / f"{board.name}.png")
    return "\n".join(lines)


def _measure_json(measure: Measure | None) -> dict[str, Any] | None:
    """A row's measure on one set as the package data holds it."""
    if measure is None:
        return None
    return {
        "mean_cost": {"mean": measure.cost["mean"], "mean_ci95": measure.cost.get("mean_ci95")},
        "transmissions": {"mean": measure.sent["mean"], "mean_ci95": measure.sent.get("mean_ci95")},
        "failures": measure.failures,
        "episodes": measure.episodes,
    }


def leaderboard_data(records: Path) -> dict[str, Any]:
    """Every id's rows as data, the numbers of the page (:mod:`etsc_envs.evaluation.leaderboard`
    reads them): trigger, what it is, record, and per set the mean cost and transmissions with
    their intervals, failures and episodes; each id with its paper and what its cost is."""
    from etsc_envs.papers import paper_of

    return {
        "generated_by": "python -m agents.leaderboard",
        "page": "docs/leaderboard.md",
        "ids": {
            board.env_id: {
                "paper": board.paper,
                "cost": paper_of(board.env_id).cost,
                "rows": [
                    {
                        "trigger": row.trigger,
                        "what": row.what,
                        "record": row.record.strip("`"),
                        **{name: _measure_json(row.sets[name]) for name in SETS},
                    }
                    for row in board_rows(records, board)
                ],
            }
            for board in BOARDS
        },
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.leaderboard",
        description="docs/leaderboard.md and its figures from the judged records",
    )
    parser.add_argument("--records", type=Path, default=RECORDS, help="the records' folder")
    parser.add_argument(
        "--out", type=Path, default=OUTPUT, help="the Markdown file (figures beside it)"
    )
    parser.add_argument("--data", type=Path, default=DATA, help="the rows as JSON package data")
    args = parser.parse_args(argv)
    if not args.records.is_dir():
        parser.error(f"--records must be a folder of judged records, got {args.records}")
    figures = args.out.with_suffix("")
    text = render(args.records, figures, figures.name)
    atomic_write_text(args.out, text)
    atomic_write_text(args.data, json.dumps(leaderboard_data(args.records), indent=1) + "\n")
    print(f"wrote {args.out}, {len(BOARDS)} figures in {figures}/ and {args.data}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The shape of a reproduction: its scenarios and how one runs, the result's rows and claims,
and their text rendering (paper value beside ours, within :data:`TEXT_WIDTH` columns)."""

from __future__ import annotations

import sys
import textwrap
import time
from collections.abc import Container, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym

import etsc_envs
from etsc_envs.evaluation.episodes import EpisodeTrace, run_episode
from etsc_envs.evaluation.policy_specs import make_policy
from etsc_envs.evaluation.progress import current_job

TEXT_WIDTH = 100
"""Columns the rendered report fits in."""
LABEL_WIDTH = 44
"""Columns of the scenario label in a table row at most (fewer where the metric names are long;
a longer label gets lines of its own)."""
VALUE_COLUMNS = 34
"""Columns of a row besides the label and the metric name: indent, paper, ours, gap and the
spaces between."""


@dataclass(frozen=True)
class Scenario:
    """One simulation of a paper: environment kwargs and trigger policy (the label is only
    how a table names it, so the same run appearing in two tables is simulated once)."""

    label: str = field(compare=False)
    env_args: tuple[tuple[str, Any], ...]
    policy: str
    policy_args: tuple[tuple[str, Any], ...] = ()


def run_scenario(
    env_id: str, scenario: Scenario, sample_every: int | None = None
) -> tuple[dict[str, Any], EpisodeTrace]:
    """One episode of ``scenario`` on ``env_id`` with seed 0 (states sampled every
    ``sample_every`` steps when given)."""
    env = gym.make(env_id, **dict(scenario.env_args))
    policy = make_policy(scenario.policy, env, dict(scenario.policy_args), env_id)
    record, trace = run_episode(env, policy, seed=0, sample_every=sample_every)
    env.close()
    return record, trace


def scenario_instants(env_id: str, scenarios: Iterable[Scenario], **env_args: Any) -> int:
    """The sampling instants of one run of each of ``scenarios`` on ``env_id`` (a Gymnasium or
    PettingZoo id; ``env_args`` added to each scenario's): the work a reproduction plans, for
    its progress."""
    total = 0
    for scenario in scenarios:
        arguments = {**dict(scenario.env_args), **env_args}
        if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
            env = etsc_envs.make_parallel(env_id, **arguments)
        else:
            env = gym.make(env_id, **arguments)
        total += env.unwrapped.n_steps
        env.close()
    return total


def stages(scenarios: Iterable[Scenario], description: str) -> Iterator[Scenario]:
    """Yield ``scenarios``. Inside an open :class:`~etsc_envs.evaluation.progress.JobProgress`,
    tell the job which run starts; otherwise, after each run, write a line saying so to standard
    error (flushed, so that a long reproduction shows its progress when its output is
    redirected)."""
    scenarios = list(scenarios)
    start = time.perf_counter()
    for index, scenario in enumerate(scenarios, start=1):
        job = current_job()
        if job is not None:
            job.stage(f"{description}: run {index}/{len(scenarios)} ({scenario.label})")
            yield scenario
            continue
        yield scenario
        elapsed_s = time.perf_counter() - start
        print(
            f"{description}: run {index}/{len(scenarios)} done ({scenario.label}), "
            f"{elapsed_s:.0f} s",
            file=sys.stderr,
            flush=True,
        )


def run_scenarios(
    env_id: str,
    scenarios: Iterable[Scenario],
    sampled: Container[Scenario],
    sample_every: int,
    description: str,
) -> tuple[dict[Scenario, dict[str, Any]], dict[Scenario, EpisodeTrace]]:
    """Run each scenario once (those in ``sampled`` storing states every ``sample_every``
    steps), reporting each finished run (:func:`stages`), and return the episode records and
    traces by scenario."""
    records: dict[Scenario, dict[str, Any]] = {}
    traces: dict[Scenario, EpisodeTrace] = {}
    for scenario in stages(scenarios, description):
        every = sample_every if scenario in sampled else None
        records[scenario], traces[scenario] = run_scenario(env_id, scenario, every)
    return records, traces


def metric_row(scenario: Scenario, paper: dict[str, float | None], ours: dict[str, Any]) -> dict:
    """A table row: every metric the paper reports, its value and ours, and the relative gap.

    A paper value of ``None`` marks a metric the paper shows only qualitatively.
    """
    metrics = {}
    for name, paper_value in paper.items():
        value = ours.get(name)
        gap = None if value is None or not paper_value else value / paper_value - 1.0
        metrics[name] = {"paper": paper_value, "ours": value, "rel_diff": gap}
    return {
        "scenario": scenario.label,
        "env_args": dict(scenario.env_args),
        "policy": scenario.policy,
        "policy_args": dict(scenario.policy_args),
        "metrics": metrics,
    }


def claim(statement: str, holds: bool, detail: str) -> dict:
    """A qualitative statement of the paper checked on our runs."""
    return {"claim": statement, "holds": bool(holds), "detail": detail}


def _number(value: float | None) -> str:
    return "-" if value is None else f"{value:.4g}"


def render(result: dict) -> str:
    """Plain-text tables within :data:`TEXT_WIDTH` columns: one line per scenario and metric,
    ``paper  ours  gap``, then the paper's claims."""
    heading = f"Paper {result['paper']}: {result['title']}"
    lines = [*textwrap.wrap(heading, TEXT_WIDTH), f"  [{result['env']}]"]
    for table in result["tables"]:
        lines += ["", *textwrap.wrap(table["name"], TEXT_WIDTH)]
        name_width = max(len(name) for row in table["rows"] for name in row["metrics"])
        label_width = max(8, min(LABEL_WIDTH, TEXT_WIDTH - VALUE_COLUMNS - name_width))
        lines.append(
            f"  {'scenario':<{label_width}s} {'metric':<{name_width}s}"
            f" {'paper':>10s} {'ours':>10s} {'gap':>8s}"
        )
        for row in table["rows"]:
            label = row["scenario"]
            if len(label) > label_width:
                lines += textwrap.wrap(label, TEXT_WIDTH, initial_indent="  ")
                label = ""
            for name, entry in row["metrics"].items():
                gap = "" if entry["rel_diff"] is None else f"{100 * entry['rel_diff']:+.1f}%"
                lines.append(
                    f"  {label:<{label_width}s} {name:<{name_width}s}"
                    f" {_number(entry['paper']):>10s} {_number(entry['ours']):>10s} {gap:>8s}"
                )
                label = ""
    if result.get("claims"):
        lines += ["", "Claims of the paper"]
        for item in result["claims"]:
            mark = "holds " if item["holds"] else "FAILS "
            text = f"[{mark}] {item['claim']}: {item['detail']}"
            lines += textwrap.wrap(
                text, TEXT_WIDTH, initial_indent="  ", subsequent_indent="           "
            )
    if result.get("figures"):
        lines += ["", *textwrap.wrap("Figures: " + ", ".join(result["figures"]), TEXT_WIDTH)]
    return "\n".join(lines)

"""The shape of a reproduction: its scenarios and how one runs, the result's rows and claims,
and their text rendering (paper value beside ours)."""

from __future__ import annotations

from collections.abc import Container, Iterable
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
from tqdm import tqdm

from baselines.cli import make_policy
from baselines.episodes import EpisodeTrace, run_episode


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


def run_scenarios(
    env_id: str,
    scenarios: Iterable[Scenario],
    sampled: Container[Scenario],
    sample_every: int,
    description: str,
    progress: bool = False,
) -> tuple[dict[Scenario, dict[str, Any]], dict[Scenario, EpisodeTrace]]:
    """Run each scenario once (those in ``sampled`` storing states every ``sample_every``
    steps) and return the episode records and traces by scenario."""
    records: dict[Scenario, dict[str, Any]] = {}
    traces: dict[Scenario, EpisodeTrace] = {}
    for scenario in tqdm(list(scenarios), desc=description, disable=not progress, unit="run"):
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


def render(result: dict) -> str:
    """Plain-text tables: for every row and metric, ``paper  ours  (gap %)``."""
    lines = [f"Paper {result['paper']}: {result['title']}  [{result['env']}]"]
    for table in result["tables"]:
        lines += ["", table["name"]]
        names = list(table["rows"][0]["metrics"])
        width = max(32, *(len(n) + 20 for n in names))
        header = f"  {'scenario':<34s}" + "".join(
            f"{n + ' paper/ours (gap)':>{width}s}" for n in names
        )
        lines.append(header)
        for row in table["rows"]:
            cells = []
            for name in names:
                entry = row["metrics"][name]
                gap = "" if entry["rel_diff"] is None else f" ({100 * entry['rel_diff']:+.1f}%)"
                ours = "-" if entry["ours"] is None else f"{entry['ours']:.4g}"
                paper = "-" if entry["paper"] is None else f"{entry['paper']:.4g}"
                cells.append(f"{paper:>10s} / {ours:<8s}{gap:>10s}")
            lines.append(f"  {row['scenario']:<34s}" + "".join(f"{c:>{width}s}" for c in cells))
    if result.get("claims"):
        lines += ["", "Claims of the paper"]
        for item in result["claims"]:
            mark = "holds " if item["holds"] else "FAILS "
            lines.append(f"  [{mark}] {item['claim']}: {item['detail']}")
    if result.get("figures"):
        lines += ["", "Figures: " + ", ".join(result["figures"])]
    return "\n".join(lines)

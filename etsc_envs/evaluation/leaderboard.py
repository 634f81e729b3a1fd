"""The leaderboard as data: every id's rows of ``docs/leaderboard.md``, installed with the package
(``etsc_envs/data/leaderboard.json``, written by ``python -m agents.leaderboard`` beside the page
from the same rows).

    >>> from etsc_envs import leaderboard
    >>> [row.trigger for row in leaderboard("etsc/AttitudeTracking-v0")][:3]
    ['always', "paper's rule", 'clock']

An :class:`~etsc_envs.evaluation.run.Evaluation` on the test set says where it stands among
them (:meth:`~etsc_envs.evaluation.run.Evaluation.standing`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import Any

LEADERBOARD_FILE = "leaderboard.json"
"""The package data file, under ``etsc_envs/data/``."""

LEADERBOARD_PAGE = "docs/leaderboard.md"
"""The page of the checkout the data is the table of."""


@dataclass(frozen=True)
class SetMeasure:
    """One row's numbers on one scenario set.

    Attributes:
        cost: the mean of ``mean_cost`` over the set (the id's cost, :attr:`LeaderboardRow`).
        cost_ci95: its 95 % interval (``[mean, mean]`` where the record gives none).
        transmissions: the mean transmissions per episode.
        transmissions_ci95: its 95 % interval.
        failures: the failed episodes.
        episodes: the episodes judged (scenarios × runs).
    """

    cost: float
    cost_ci95: tuple[float, float]
    transmissions: float
    transmissions_ci95: tuple[float, float]
    failures: int
    episodes: int

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> SetMeasure:
        """The measure as the leaderboard's JSON holds it."""

        def interval(summary: dict[str, Any]) -> tuple[float, float]:
            low, high = summary.get("mean_ci95") or (summary["mean"], summary["mean"])
            return float(low), float(high)

        cost, sent = data["mean_cost"], data["transmissions"]
        return cls(
            float(cost["mean"]),
            interval(cost),
            float(sent["mean"]),
            interval(sent),
            int(data["failures"]),
            int(data["episodes"]),
        )


@dataclass(frozen=True)
class LeaderboardRow:
    """One trigger of an id's leaderboard.

    Attributes:
        trigger: the row's name (``paper's rule``, ``clock``, ...).
        what: what the trigger is.
        record: the judged record it is read from (a folder of ``docs/results/``).
        test: its numbers on the 64-scenario test set, or ``None``.
        paper: its numbers on the paper scenario, or ``None``.
    """

    trigger: str
    what: str
    record: str
    test: SetMeasure | None
    paper: SetMeasure | None


@cache
def _data() -> dict[str, Any]:
    text = (resources.files("etsc_envs") / "data" / LEADERBOARD_FILE).read_text("utf-8")
    return json.loads(text)


def leaderboard_ids() -> list[str]:
    """The ids the installed leaderboard has rows for."""
    return list(_data()["ids"])


def leaderboard(env_id: str) -> list[LeaderboardRow]:
    """The rows of ``env_id``'s table on ``docs/leaderboard.md``, in its order (``ValueError``
    naming ``env_id`` for an id without one). Costs are the id's ``mean_cost``
    (:attr:`etsc_envs.core.paper.Paper.cost` says its formula and units)."""
    ids = _data()["ids"]
    if env_id not in ids:
        raise ValueError(f"env_id must be one of {list(ids)}, got {env_id!r}")
    return [
        LeaderboardRow(
            row["trigger"],
            row["what"],
            row["record"],
            *(
                None if row[name] is None else SetMeasure.from_json(row[name])
                for name in ("test", "paper")
            ),
        )
        for row in ids[env_id]["rows"]
    ]

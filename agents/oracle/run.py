"""One clairvoyant-schedule run: its settings (:class:`OracleConfig`), checked when read, and
:func:`run_oracle`, which searches one scenario and writes its record.

The settings are the keys of ``configs/oracle/<problem>.yaml`` (a sweep's ``base`` with
``learner: oracle``, whose grid runs ``scenario`` over a set) and the options of
``python -m agents.oracle``:

* ``env_id`` — a single-agent id of the suite (the PettingZoo id's loop is the central id's);
* ``trigger`` — the learned trigger (a ``learned.json``) whose schedule and cost are matched;
* ``scenarios: test`` and ``scenario`` — the scenario: index ``scenario`` of the named set;
* ``budget_episodes`` — instants the search may simulate, in episodes of the id (each
  objective's search gets 3/8 from the trigger's schedule and 1/8 from the clock's,
  :data:`agents.oracle.search.START_SHARES`);
* ``tuning_episodes`` — with a number > 0, each objective's search starts from the learned
  trigger's family point tuned on the scenario (:mod:`agents.oracle.tuned`, that many episodes
  of CMA-ES candidates) instead of the trigger's own schedule; 0 (the default) starts from the
  trigger's schedule. The tuning counts against its start's share of ``budget_episodes``:
  moves from the tuned schedule get what the tuning leaves of it (nothing where the tuning
  takes more);
* ``tail`` — how a move is judged: ``null``, followed by the trigger to the horizon (from the
  tuned start, by the tuned point, whose episode it is) and run exactly
  (:func:`agents.oracle.search.improve_by_rollout`; for short episodes); an integer, screened
  over the changed channel's next send and ``tail`` instants of the schedule beyond
  (:func:`agents.oracle.search.improve`; for long multi-channel ones).
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from agents.oracle.schedule import ScheduleRun
from agents.oracle.search import clairvoyant
from agents.sweep.results import ORACLE_FILE
from etsc_envs.core.files import atomic_write_text
from etsc_envs.core.json_files import in_file, require_mapping
from etsc_envs.protocol import (
    DEFAULT_SET_SIZE,
    RESERVED_SEEDS,
    SCENARIO_SET_NAMES,
    scenario_set,
)
from etsc_envs.registry import VECTOR_ENTRY_POINTS
from etsc_envs.triggers.family import LearnedTrigger


@dataclass(frozen=True)
class OracleConfig:
    env_id: str
    trigger: str
    scenario: int
    scenarios: str = "test"
    budget_episodes: float = 100.0
    tail: int | None = None
    tuning_episodes: float = 0.0

    @property
    def seed(self) -> int:
        return scenario_set(self.scenarios, self.scenario + 1).seeds[self.scenario]


def oracle_config_from_dict(raw: Any) -> OracleConfig:
    """The settings in ``raw``, each checked (``ValueError`` naming the key and what it
    allows)."""
    names = tuple(OracleConfig.__dataclass_fields__)
    raw = require_mapping(raw, "", names, ("env_id", "trigger", "scenario"))
    values = {**asdict(OracleConfig("", "", 0)), **raw}
    if values["env_id"] not in VECTOR_ENTRY_POINTS:
        raise ValueError(
            f"key 'env_id' must be a single-agent id, one of {sorted(VECTOR_ENTRY_POINTS)} (the "
            f"PettingZoo id's loop is the central id's), got {values['env_id']!r}"
        )
    if values["scenarios"] not in SCENARIO_SET_NAMES[1:]:
        raise ValueError(
            f"key 'scenarios' must be one of {list(SCENARIO_SET_NAMES[1:])}, "
            f"got {values['scenarios']!r}"
        )
    scenario = values["scenario"]
    last = len(RESERVED_SEEDS[values["scenarios"]]) - 1
    if isinstance(scenario, bool) or not isinstance(scenario, int) or not 0 <= scenario <= last:
        raise ValueError(
            f"key 'scenario' must be an index 0..{last} of the {values['scenarios']} seeds "
            f"(the protocol's set is 0..{DEFAULT_SET_SIZE - 1}), got {scenario!r}"
        )
    budget = values["budget_episodes"]
    if isinstance(budget, bool) or not isinstance(budget, int | float) or not budget > 0:
        raise ValueError(f"key 'budget_episodes' must be a number > 0, got {budget!r}")
    tuning = values["tuning_episodes"]
    if isinstance(tuning, bool) or not isinstance(tuning, int | float) or not tuning >= 0:
        raise ValueError(f"key 'tuning_episodes' must be a number >= 0, got {tuning!r}")
    tail = values["tail"]
    if tail is not None and (isinstance(tail, bool) or not isinstance(tail, int) or tail < 0):
        raise ValueError(f"key 'tail' must be an integer >= 0 or null, got {tail!r}")
    with in_file("key 'trigger'"):
        learned = LearnedTrigger.load(values["trigger"])
    if learned.env_id != values["env_id"]:
        raise ValueError(
            f"key 'trigger': {values['trigger']!r} is a trigger of {learned.env_id!r}, "
            f"not of env_id {values['env_id']!r}"
        )
    return OracleConfig(
        **{**values, "budget_episodes": float(budget), "tuning_episodes": float(tuning)}
    )


def run_oracle(config: OracleConfig, out: str | Path) -> dict[str, Any]:
    """Search ``config``'s scenario for its clairvoyant schedules and write the record to
    ``out/oracle.json``: the settings, the scenario's seed, the trigger's run, the
    fewest-transmissions and least-cost schedules (each with its starts and curves), the
    instants simulated and the wall time."""
    began = time.perf_counter()
    seed = config.seed
    run = ScheduleRun(config.env_id, scenario_set(config.scenarios, config.scenario + 1), seed)
    found = clairvoyant(
        run,
        LearnedTrigger.load(config.trigger),
        round(config.budget_episodes * run.n_steps),
        config.tail,
        round(config.tuning_episodes * run.n_steps),
    )
    record = {
        "settings": asdict(config),
        "seed": seed,
        "n_steps": run.n_steps,
        **found,
        "wall_time_s": time.perf_counter() - began,
    }
    Path(out).mkdir(parents=True, exist_ok=True)
    atomic_write_text(Path(out) / ORACLE_FILE, json.dumps(record) + "\n")
    return record

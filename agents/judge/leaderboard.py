"""The leaderboard: every id's triggers on the test set and the paper scenario, from the records.

    python -m agents.leaderboard [--records DIR] [--out PATH]

Reads the judged records under ``docs/results/`` — ``results.json`` of ``agents.judge.results``,
``pareto.json`` of ``agents.judge.pareto`` and the JSON of ``baselines.evaluate --json`` — and runs
nothing. Writes ``docs/leaderboard.md`` and one figure per id beside it
(``docs/leaderboard/<EnvName>.png``).

Per id (:data:`BOARDS`), one row per trigger, each from a named record and with the command
that makes it:

* **always** — transmit at every instant (a ``<EnvName>_always/`` record of
  ``baselines.evaluate --policy always``, or the periodic sweep's ``every=1`` point);
* **the paper's rule** at the paper's thresholds, **the clock** at the hand point's rate
  (periodic transmission every ``k`` instants, ``k`` matched to it) and **the best
  hand-designed rule** (``models/<EnvName>_hand.json``, a point of the family chosen on
  validation from a menu), all three from ``<EnvName>_hand/``;
* the SB3 learners: **per-instant PPO** and, on self-triggered decisions, **PPO** and **DQN**
  (trained from scratch under the protocol, where such runs were judged: :attr:`Board.learners`);
* **learned trigger (ES)** — the searches of ``configs/search/<problem>.yaml``
  (:attr:`Board.learned`);
* **clairvoyant schedule** — not a trigger: the fewest transmissions at no more than the
  learned trigger's cost, found with each test scenario known in advance
  (``<EnvName>_oracle/``, :mod:`agents.judge.oracle`; its own scenarios, which the row
  names).

The figures draw the paper's threshold sweep, the periodic sweep and the hand menu's front from
``<EnvName>_learned_front/pareto.json`` (:attr:`Board.curves`) beside the rows.

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
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib import ticker

from baselines.plotting import save
from etsc_envs.core.files import atomic_write_text, require_writable_file, require_writable_folder
from etsc_envs.core.json_files import read_json_file, require_mapping
from etsc_envs.evaluation.statistics import paired_ratio, seeds_summary, summarize

ROOT = Path(__file__).resolve().parents[2]
RECORDS = ROOT / "docs" / "results"
OUTPUT = ROOT / "docs" / "leaderboard.md"
DATA = ROOT / "etsc_envs" / "data" / "leaderboard.json"
"""The rows as package data (:func:`etsc_envs.leaderboard` reads them)."""
SETS = ("test", "paper")
"""The test set (64 scenarios) and the paper scenario."""


@dataclass(frozen=True)
class LearnerRecord:
    """One reinforcement-learning row of an id.

    Attributes:
        folder: the folder of its ``results.json`` (``agents.results`` on the runs judged).
        what: what the runs are (decisions, seeds, λ and how it was chosen).
        command: the commands that make the record, where its models are not shipped.
    """

    folder: str
    what: str
    command: str | None = None


NOT_TRAINED = "none trained from scratch under the protocol yet"
"""What a self-triggered learner's row without a record says."""


@dataclass(frozen=True)
class Board:
    """Where one id's rows come from (folders under the records directory).

    Attributes:
        env_id: the registered id.
        paper: the paper's number in the suite ("000" .. "004").
        learned: folder of the learned trigger's ``results.json``: the searches of
            ``configs/search/<problem>.yaml``, the configuration the report chose.
        learners: the SB3 learners trained from scratch under the protocol, by row
            (:data:`RL_TRIGGERS`); a row without one says none was trained.
    """

    env_id: str
    paper: str
    learned: str
    learners: Mapping[str, LearnerRecord] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """The id without its namespace, as records and figures are named."""
        return self.env_id.removeprefix("etsc/")

    @property
    def hand(self) -> str:
        """Folder of the best hand point's ``results.json`` (``models/<id>_hand.json`` judged
        by ``agents.results``: the paper's rule and the clock at the hand point's rate too)."""
        return f"{self.name}_hand"

    @property
    def oracle(self) -> str:
        """Folder of the clairvoyant schedules' ``oracle.json`` (``agents.judge.oracle``): the
        central id's for paper 001's PettingZoo id, whose loop and learned decisions are the
        same."""
        return f"{self.name.replace('ClusterContainment-', 'ClusterContainmentCentral-')}_oracle"

    @property
    def curves(self) -> str:
        """Folder whose ``pareto.json`` holds the paper's threshold sweep, the periodic sweep
        and the hand menu's points on both sets (the learned trigger's judgement against the
        menu, ``agents.judge.pareto``)."""
        return f"{self.name}_learned_front"


def learner_front(
    env_id: str,
    sweep_name: str,
    record: str,
    processes: int = 2,
    judged_sweep: str | None = None,
) -> str:
    """The commands behind an SB3 learner's row: the sweep ``configs/sweeps/<sweep_name>.yaml``
    (penalties × seeds), the penalty chosen on validation, and the judgement of the sweep's
    groups into ``docs/results/<record>``; with ``judged_sweep``, the seeds judged are that
    sweep's (the chosen penalty's seeds trained again, where the front kept no models)."""
    front = f"runs/sweeps/{sweep_name}"
    commands = [
        f"python -m agents.sweep --processes {processes} --config configs/sweeps/{sweep_name}.yaml",
        f"python -m agents.judge.penalty_choice {front}",
    ]
    if judged_sweep is not None:
        commands.append(
            f"python -m agents.sweep --processes {processes} --config "
            f"configs/sweeps/{judged_sweep}.yaml"
        )
    judged = f"runs/sweeps/{judged_sweep or sweep_name}"
    commands.append(
        f"python -m agents.results {env_id} --sweep {judged} --out docs/results/{record}"
    )
    return " && ".join(commands)


def cluster_ppo(env_id: str, form: str, values: str) -> LearnerRecord:
    """Paper 001's per-instant PPO row (``form``: ``central`` or ``shared``; ``values``: how
    its hyperparameters were chosen): the closest λ of the front at the values before tuning,
    five seeds at the config's values judged."""
    record = f"{env_id.removeprefix('etsc/')}_ppo"
    return LearnerRecord(
        f"{record}/transmission_penalty=10",
        f"{values}, 5 seeds at λ = 10 per follower update, "
        "best-validation checkpoints (no λ of 1, 10 contained the paper rule on validation at "
        "the values before tuning; 10 came closest)",
        learner_front(
            env_id,
            f"cluster_{form}_ppo_front",
            record,
            judged_sweep=f"cluster_{form}_ppo",
        ),
    )


def self_triggered_dqn(
    env_id: str, sweep_name: str, penalty: str, what: str, processes: int = 2
) -> LearnerRecord:
    """An id's self-triggered DQN row: the five seeds of ``configs/sweeps/<sweep_name>.yaml`` at
    the judged ``penalty``, in ``<id>_self_triggered_dqn/``; ``what`` follows "DQN
    (semi-Markov target) on the same decisions, "."""
    record = f"{env_id.removeprefix('etsc/')}_self_triggered_dqn"
    return LearnerRecord(
        f"{record}/transmission_penalty={penalty}",
        f"DQN (semi-Markov target) on the same decisions, {what}",
        learner_front(env_id, sweep_name, record, processes=processes),
    )


def self_triggered_tuned(
    env_id: str,
    problem: str,
    penalty: str,
    decisions: str,
    choice: str,
    learner: Literal["PPO", "DQN"] = "PPO",
    tuning_budget: str | None = None,
) -> LearnerRecord:
    """An id's self-triggered ``learner`` row (``PPO`` or ``DQN``) at hyperparameters tuned on
    validation: the front ``configs/sweeps/<problem>_<stem>_front.yaml`` chose ``penalty``, and
    the five seeds of ``<problem>_<stem>.yaml`` at the tuned values are judged into
    ``<id>_<stem>_tuned/`` (``stem``: ``self_triggered``, ``self_triggered_dqn``); ``decisions``
    says what the policy chooses from, ``choice`` (after "5 seeds at λ = <penalty>") how the
    penalty and checkpoints were chosen. ``tuning_budget`` names a tuning's shorter runs (e.g.
    "25 000 decisions a run, a quarter of the budget"); without it the tuning ran the whole
    budget, so its best trial's two runs are the judged seeds 0 and 1."""
    stem = "self_triggered" if learner == "PPO" else f"self_triggered_{learner.lower()}"
    record = f"{env_id.removeprefix('etsc/')}_{stem}_tuned"
    tuning = (
        "the best trial's two runs are seeds 0 and 1"
        if tuning_budget is None
        else f"{tuning_budget}; the five seeds run the whole budget"
    )
    return LearnerRecord(
        f"{record}/transmission_penalty={penalty}",
        f"{decisions}, hyperparameters tuned on validation (6 Optuna trials × 2 seeds at "
        f"λ = {penalty}; {tuning}), 5 seeds at λ = {penalty}{choice}",
        learner_front(
            env_id,
            f"{problem}_{stem}_front",
            record,
            judged_sweep=f"{problem}_{stem}",
        ),
    )


BOARDS = (
    Board(
        "etsc/OrbitAttitudeTracking-v0",
        "000",
        "OrbitAttitudeTracking-v0_learned_large_budget",
        {
            "per-instant PPO": LearnerRecord(
                "OrbitAttitudeTracking-v0_ppo/transmission_penalty=1",
                "hyperparameters tuned on validation (6 Optuna trials × 2 seeds × 4 M steps; "
                "rl-zoo3's defaults stayed best), 5 seeds at the config's λ = 1 per "
                "transmission, best-validation checkpoints (λ = 1 does not contain the paper "
                "rule on validation)",
                learner_front(
                    "etsc/OrbitAttitudeTracking-v0",
                    "orbit_attitude_ppo_front",
                    "OrbitAttitudeTracking-v0_ppo",
                ),
            ),
            "self-triggered PPO": self_triggered_tuned(
                "etsc/OrbitAttitudeTracking-v0",
                "orbit_attitude",
                "1",
                "holds or eq. (21) × γ gating a 64-instant clock, from scratch",
                " (100 000 decisions of 60-s episodes each), best-validation checkpoints "
                "(λ = 1, the front's only penalty, does not contain the paper rule on "
                "validation)",
            ),
            "self-triggered DQN": self_triggered_tuned(
                "etsc/OrbitAttitudeTracking-v0",
                "orbit_attitude",
                "1",
                "DQN (semi-Markov target) on the same decisions from scratch",
                " (100 000 decisions of 60-s episodes each), best-validation checkpoints "
                "(λ = 1, the front's only penalty, does not contain the paper rule on "
                "validation)",
                learner="DQN",
                tuning_budget="25 000 decisions a run, a quarter of the budget",
            ),
        },
    ),
    Board(
        "etsc/ClusterContainment-v0",
        "001",
        "ClusterContainment-v0_learned",
        {
            "per-instant PPO": cluster_ppo(
                "etsc/ClusterContainment-v0",
                "shared",
                "hyperparameters tuned on validation (6 Optuna trials × 2 seeds × 6 M agent "
                "steps at λ = 10; rl-zoo3's defaults stayed best)",
            ),
            "self-triggered PPO": self_triggered_tuned(
                "etsc/ClusterContainment-v0",
                "cluster_shared",
                "10",
                "holds or eq. (15) × c, one policy shared by the followers, from scratch",
                " per follower update (12 288 follower decisions of 1200-s episodes each), "
                "best-validation checkpoints of trained networks (λ = 10, the front's only "
                "penalty, does not contain the paper rule on validation)",
            ),
            "self-triggered DQN": self_triggered_tuned(
                "etsc/ClusterContainment-v0",
                "cluster_shared",
                "10",
                "DQN (semi-Markov target) on the same decisions, one Q-network shared by the "
                "followers, from scratch",
                " per follower update (12 288 follower decisions of 1200-s episodes each), "
                "best-validation checkpoints of trained networks (λ = 10, the front's only "
                "penalty, does not contain the paper rule on validation)",
                learner="DQN",
            ),
        },
    ),
    Board(
        "etsc/ClusterContainmentCentral-v0",
        "001",
        "ClusterContainmentCentral-v0_learned",
        {
            "per-instant PPO": cluster_ppo(
                "etsc/ClusterContainmentCentral-v0",
                "central",
                "hyperparameters tuned on validation (6 Optuna trials × 2 seeds × 3 M steps at "
                "λ = 10; the best trial's two runs are seeds 0 and 1)",
            ),
            "self-triggered PPO": self_triggered_tuned(
                "etsc/ClusterContainmentCentral-v0",
                "cluster_central",
                "10",
                "holds after every follower transmits or eq. (15) × c from scratch",
                " per follower update (20 000 decisions of 1200-s episodes each), "
                "best-validation checkpoints (no λ of 1, 10 contained the paper rule on "
                "validation at the values before tuning; 10 came closest)",
            ),
            "self-triggered DQN": self_triggered_tuned(
                "etsc/ClusterContainmentCentral-v0",
                "cluster_central",
                "1",
                "DQN (semi-Markov target) on the same decisions from scratch",
                " per follower update (20 000 decisions of 1200-s episodes each), "
                "best-validation checkpoints (no λ of 1, 10 contained the paper rule on "
                "validation at the values before tuning; 1 came closest)",
                learner="DQN",
            ),
        },
    ),
    Board(
        "etsc/AttitudeTracking-v0",
        "002",
        "AttitudeTracking-v0_learned_wide_exponent",
        {
            "per-instant PPO": LearnerRecord(
                "AttitudeTracking-v0_ppo/transmission_penalty=300",
                "hyperparameters tuned on validation (Optuna, 16 trials), 5 seeds at λ = 300, "
                "best-validation checkpoints (no λ of 100, 300 contained the paper rule on "
                "validation; 300 came closest)",
                learner_front(
                    "etsc/AttitudeTracking-v0",
                    "attitude_tracking_ppo_front",
                    "AttitudeTracking-v0_ppo",
                ),
            ),
            "self-triggered PPO": self_triggered_tuned(
                "etsc/AttitudeTracking-v0",
                "attitude_tracking",
                "300",
                "holds or eq. (27) × f from scratch",
                ", best-validation checkpoints (no λ of 100, 300 contained the paper rule on "
                "validation at the values before tuning; 300 came closest)",
            ),
            "self-triggered DQN": self_triggered_tuned(
                "etsc/AttitudeTracking-v0",
                "attitude_tracking",
                "300",
                "DQN (semi-Markov target) on the same decisions from scratch",
                ", best-validation checkpoints (no λ of 100, 300 contained the paper rule on "
                "validation at the values before tuning; 300 came closest)",
                learner="DQN",
            ),
        },
    ),
    Board(
        "etsc/AsteroidOrbitKeeping-v0",
        "003",
        "AsteroidOrbitKeeping-v0_learned",
        {
            "per-instant PPO": LearnerRecord(
                "AsteroidOrbitKeeping-v0_ppo/transmission_penalty=1",
                "hyperparameters tuned on validation (Optuna, 16 trials), 5 seeds at the "
                "tuning's λ = 1, best-validation checkpoints (λ = 1 does not contain the paper "
                "rule on validation)",
                learner_front(
                    "etsc/AsteroidOrbitKeeping-v0",
                    "asteroid_ppo_front",
                    "AsteroidOrbitKeeping-v0_ppo",
                ),
            ),
            "self-triggered PPO": self_triggered_tuned(
                "etsc/AsteroidOrbitKeeping-v0",
                "asteroid",
                "0.3",
                "MaskablePPO: holds or eq. (15) × f from scratch",
                " (chosen on validation from 0.3, 1, 3, 10 at the values before tuning), "
                "best-validation checkpoints",
            ),
            "self-triggered DQN": self_triggered_tuned(
                "etsc/AsteroidOrbitKeeping-v0",
                "asteroid",
                "0.3",
                "DQN (semi-Markov target) on the same decisions from scratch, the shield "
                "replacing an unsafe hold",
                " (the PPO front's choice), best-validation checkpoints",
                learner="DQN",
            ),
        },
    ),
    Board(
        "etsc/InnerFormation-v0",
        "004",
        "InnerFormation-v0_learned_coupled",
        {
            "per-instant PPO": LearnerRecord(
                "InnerFormation-v0_ppo/transmission_penalty=5",
                "hyperparameters tuned on validation (6 Optuna trials × 2 seeds × 5 M steps), "
                "5 seeds at λ = 5 per transmitted axis, best-validation checkpoints (λ = 5 "
                "does not contain the paper rule on validation)",
                learner_front(
                    "etsc/InnerFormation-v0",
                    "inner_formation_ppo_front",
                    "InnerFormation-v0_ppo",
                ),
            ),
            "self-triggered PPO": LearnerRecord(
                "InnerFormation-v0_self_triggered_scratch/transmission_penalty=5",
                "MaskablePPO: holds or eqs. (4)–(6) × f from scratch, 5 seeds at λ = 5 (200 000 "
                "decisions, 2.3–2.4 M instants of 20-s episodes each), best-validation "
                "checkpoints (λ = 5 does not contain the paper rule on validation; λ = 2 was "
                "stopped at 50 000 decisions, ×7.7–13 the rule's transmissions)",
                learner_front(
                    "etsc/InnerFormation-v0",
                    "inner_formation_self_triggered_front",
                    "InnerFormation-v0_self_triggered_scratch",
                ),
            ),
            "self-triggered DQN": self_triggered_dqn(
                "etsc/InnerFormation-v0",
                "inner_formation_self_triggered_dqn_front",
                "5",
                "unmasked (the shield replaces an unsafe hold), from scratch, 5 seeds at λ = 5 "
                "(200 000 decisions of 20-s episodes each), best-validation checkpoints (λ = 5 "
                "does not contain the paper rule on validation: ×17 its transmissions)",
            ),
        },
    ),
)
"""Every id's rows, in the papers' order."""

SHORT_NAMES = {
    board.env_id: board.paper + (" central" if "Central" in board.env_id else "")
    for board in BOARDS
}
"""Each id as the across-id table names it: its paper, and which form of paper 001."""


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
    """One leaderboard row: a trigger, what it is, its record, its measures per set and the
    command that makes the record (``None`` where there is no record)."""

    trigger: str
    what: str
    record: str
    sets: dict[str, Measure | None]
    command: str | None = None


def _load(path: Path) -> dict[str, Any]:
    return require_mapping(read_json_file(path), "")


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
    (seeds that took the same decisions) count as one run."""
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


def results_command(record: dict[str, Any], folder: str) -> str:
    """The ``agents.results`` command that writes ``record`` (a ``results.json``) into
    ``docs/results/<folder>/``: its models, env keywords and scenario sets."""
    parts = ["python -m agents.results", record["env"]]
    parts += [f"--model {model}" for model in record["models"]]
    parts += [f"--env-arg {key}={value}" for key, value in record.get("env_args", {}).items()]
    sets = list(record["sets"])
    if sets != ["paper", "test"]:
        parts.append("--scenarios " + " ".join(sets))
    return " ".join([*parts, f"--out docs/results/{folder.split('/')[0]}"])


def _results_row(
    records: Path,
    folder: str | None,
    trigger: str,
    what: str,
    part: str = "learned",
    command: str | None = None,
) -> Row:
    if folder is None or not (records / folder / "results.json").is_file():
        return Row(trigger, what, "—", dict.fromkeys(SETS))
    record = _load(records / folder / "results.json")
    return Row(
        trigger,
        what,
        f"`{folder}/`",
        {name: _record_measure(record, name, part) for name in SETS},
        command or results_command(record, folder),
    )


def _always_row(records: Path, board: Board, sweeps: dict[str, Any]) -> Row:
    what = "transmit at every instant"
    folder = f"{board.name}_always"
    if (records / folder).is_dir():
        sets = {name: _evaluate_measure(records / folder / f"{name}.json") for name in SETS}
        command = " && ".join(
            f"python -m baselines.evaluate {board.env_id} --policy always --scenarios {name} "
            f"--json docs/results/{folder}/{name}.json"
            for name in SETS
        )
        return Row("always", what, f"`{folder}/`", sets, command)
    every_instant = [p for p in sweeps["curves"]["periodic"] if p["args"].get("every") == 1]
    if not every_instant:
        return Row("always", what, "—", dict.fromkeys(SETS))
    sets = {name: _sweep_measure(every_instant[0], name) for name in SETS}
    return Row(
        "always",
        what + " (the clock every instant)",
        f"`{board.curves}/`",
        sets,
        f"python -m agents.judge.pareto {board.env_id} --out docs/results/{board.curves} "
        "(its periodic sweep's every = 1)",
    )


def hand_label(record: dict[str, Any]) -> str:
    """What the hand point of a ``results.json`` is: its file's ``hand`` section (the rule,
    and how many rules the menu it was chosen from held)."""
    hand = _load(ROOT / record["models"][0])["hand"]
    return (
        f"{hand['rule']}; a point of the family chosen on {hand['chosen_on']} from a menu of "
        f"{len(hand['menu'])} rules and clocks (a tuned baseline)"
    )


def board_rows(records: Path, board: Board) -> list[Row]:
    """Every row of one id, in the leaderboard's order."""
    sweeps = _load(records / board.curves / "pareto.json")
    hand = _load(records / board.hand / "results.json")
    every = [hand["sets"][name]["models"][0]["periodic_every"] for name in SETS]
    hand_record, hand_command = f"`{board.hand}/`", results_command(hand, board.hand)
    learned = _load(records / board.learned / "results.json")
    return [
        _always_row(records, board, sweeps),
        Row(
            "paper's rule",
            "the paper's thresholds",
            hand_record,
            {name: _record_measure(hand, name, "paper") for name in SETS},
            hand_command,
        ),
        Row(
            "clock",
            f"every {every[0]} (test set) and {every[1]} (paper scenario) instants: "
            "the hand point's rate",
            hand_record,
            {name: _record_measure(hand, name, "periodic") for name in SETS},
            hand_command,
        ),
        Row(
            HAND,
            hand_label(hand),
            hand_record,
            {name: _record_measure(hand, name, "learned") for name in SETS},
            hand_command,
        ),
        *(_learner_row(records, board, trigger) for trigger in RL_TRIGGERS),
        _results_row(
            records,
            board.learned,
            LEARNED,
            f"the rule's parametric family searched with CMA-ES ({len(learned['models'])} "
            "search seeds, the penalty chosen on validation)",
        ),
        _oracle_row(records, board),
    ]


def _learner_row(records: Path, board: Board, trigger: str) -> Row:
    """An SB3 learner's row: its protocol record where one was judged, else a row saying none
    was trained."""
    record = board.learners.get(trigger)
    if record is not None:
        return _results_row(records, record.folder, trigger, record.what, command=record.command)
    return _results_row(records, None, trigger, NOT_TRAINED)


def _oracle_row(records: Path, board: Board) -> Row:
    """The clairvoyant schedules' row: their test scenarios' mean transmissions and cost at
    no more than the cost of the learned trigger they were searched against (the record's
    ``trigger``, the shipped point, which may be another search's than the learned row's),
    and learned ÷ clairvoyant (paired IQMs)."""
    path = records / board.oracle / "oracle.json"
    if not path.is_file():
        return Row(ORACLE, "not searched yet", "—", dict.fromkeys(SETS))
    oracle = _load(path)
    fewest, trigger = oracle["means"]["fewest_transmissions"], oracle["means"]["trigger"]
    ratios = oracle["learned_over_clairvoyant"]
    sent, cost = ratios["transmissions_at_equal_cost"], ratios["cost_at_equal_transmissions"]
    n = sent["n"]
    cost_text = (
        f"cost at its count ×{_ratio_cell(cost, 'iqm')}"
        if cost["iqm"] is not None
        else "cost at its count: both 0"
    )
    what = (
        f"fewest transmissions at no more than the cost of `{oracle['trigger']}`, each of the "
        f"first {n} test scenarios known in advance (there that trigger: "
        f"{_number(trigger['mean_cost']['mean'])} / {_number(trigger['transmissions']['mean'])});"
        f" learned ÷ clairvoyant (IQM): transmissions ×{_ratio_cell(sent, 'iqm')}, {cost_text}"
    )
    measure = Measure(fewest["mean_cost"], fewest["transmissions"], 0, n)
    return Row(
        ORACLE,
        what,
        f"`{board.oracle}/`",
        {"test": measure, "paper": None},
        " && ".join(oracle["commands"]),
    )


HAND = "best hand-designed rule"
"""The row of ``models/<id>_hand.json``."""

LEARNED = "learned trigger (ES)"
"""The row of the searched family point."""

ORACLE = "clairvoyant schedule (knows the scenario; not a trigger)"
"""The row of the clairvoyant schedules (:mod:`agents.oracle`)."""


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


PER_INSTANT_PPO = "per-instant PPO"
RL_TRIGGERS = (PER_INSTANT_PPO, "self-triggered PPO", "self-triggered DQN")
"""The rows of the SB3 learners (:attr:`Board.learners`), of which the README shows the best."""

SUMMARY_TRIGGERS = ("always", "clock", HAND, *RL_TRIGGERS, LEARNED)
"""The triggers of the across-id summary, each over the ids whose record keeps its test
episodes."""


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
    for trigger in SUMMARY_TRIGGERS:
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
    HAND: {"marker": "*", "color": "C3", "markersize": 16},
    "per-instant PPO": {"marker": "^", "color": "C4", "markersize": 10},
    "self-triggered PPO": {"marker": "v", "color": "C5", "markersize": 10},
    "self-triggered DQN": {"marker": "<", "color": "C6", "markersize": 10},
    LEARNED: {"marker": "D", "color": "C2", "markersize": 10},
    ORACLE: {"marker": "P", "color": "k", "markersize": 11},
}
"""Each row's marker in the figures."""


SWEEP_STYLES = {
    "paper": ("o-", "C0", "paper's rule, threshold sweep"),
    "periodic": ("s--", "C1", "clock, period sweep"),
    "error_time": ("P-.", "C8", "error-time rule, threshold sweep"),
}
"""The sweeps' lines in the figures (``pareto.json`` curves)."""


def _curve(points: list[dict[str, Any]], name: str) -> tuple[list[float], list[float]]:
    """A sweep's points on one set without those that failed, by transmissions (a point judged
    without the paper scenario is left out of its panel)."""
    measures = [
        _sweep_measure(point, name)
        for point in points
        if name != "paper" or point.get("paper_scenario") is not None
    ]
    kept = sorted(
        (m for m in measures if m.sent["mean"] > 0 and not m.failures),
        key=lambda m: m.sent["mean"],
    )
    return [m.sent["mean"] for m in kept], [m.cost["mean"] for m in kept]


def _envelope(points: list[dict[str, Any]], name: str) -> tuple[list[float], list[float]]:
    """The non-dominated points of the hand menu on one set (no point of the menu sends fewer
    transmissions at a lower cost), by transmissions."""
    xs, ys = _curve(points, name)
    kept: list[tuple[float, float]] = []
    for x, y in zip(xs, ys, strict=True):
        if not kept or y < kept[-1][1]:
            kept.append((x, y))
    return [x for x, _ in kept], [y for _, y in kept]


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


def _panel(axes: plt.Axes, rows: list[Row], sweeps: dict[str, Any], name: str) -> None:
    """One set's panel: sweeps and the hand menu's front as lines, rows as markers; the axes
    span the paper's sweep, the menu's front and the rows (``always`` aside); a row outside
    them is drawn at the edge with its numbers written beside it."""
    curves = {
        curve: _curve(sweeps["curves"][curve], name)
        for curve in SWEEP_STYLES
        if curve in sweeps["curves"]
    }
    if sweeps["curves"].get("hand_menu"):
        curves["menu"] = _envelope(sweeps["curves"]["hand_menu"], name)
    measures = [(row.trigger, row.sets[name]) for row in rows if row.sets[name] is not None]
    core_x = curves["paper"][0] + curves.get("menu", ([], []))[0]
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
        if curve == "menu":
            label = "hand menu's front (every rule, clock and decision tried)"
            axes.plot(xs, ys, "d:", color="C7", markersize=5, label=label)
        else:
            fmt, color, label = SWEEP_STYLES[curve]
            axes.plot(xs, ys, fmt, color=color, markersize=4, alpha=0.6, label=label)
    off_axes: list[str] = []
    for trigger, measure in measures:
        x, y = measure.sent["mean"], measure.cost["mean"]
        style = ROW_STYLES[trigger]
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
    the sweeps and the hand menu's front as lines, each leaderboard row as a marker with its 95 %
    intervals (a cost interval wider than the panel, where scenarios differ more than
    triggers, is left out), a cross over a row with failures."""
    fig, panels = plt.subplots(1, 2, figsize=(12.0, 5.2))
    titles = (
        "test set, 64 scenarios: means (95 % intervals where narrow)",
        "paper scenario (one episode; intervals over seeds)",
    )
    for axes, name, title in zip(panels, SETS, titles, strict=True):
        _panel(axes, rows, sweeps, name)
        axes.set_title(title, fontsize=10)
    panels[0].set_ylabel("mean cost per step (lower is better)")
    handles, labels = panels[0].get_legend_handles_labels()
    for row in [row for row in rows if any(row.sets.values())]:
        style = ROW_STYLES[row.trigger]
        handles.append(plt.Line2D([], [], linestyle="", **style))
        test = row.sets["test"]
        only = row.trigger == ORACLE and test is not None
        labels.append(
            f"{row.trigger}, first {test.episodes} test scenarios" if only else row.trigger
        )
    handles.append(plt.Line2D([], [], marker="x", linestyle="", color="k", markersize=9))
    labels.append("failures in some episodes")
    fig.legend(handles, labels, loc="lower center", ncol=3, frameon=False, fontsize=9)
    fig.suptitle(f"{board.env_id} (paper {board.paper}): accuracy against communication")
    fig.tight_layout(rect=(0, 0.14, 1, 0.97))
    save(fig, path)


HEADER = """# Leaderboard

Generated by `python -m agents.leaderboard` from the judged records under
[`results/`](results/) alone (nothing is re-run; do not edit by hand); each id's commands below
its table remake its records. Each table gives the mean per-step accuracy cost (the env's
`mean_cost`, lower is better; its formula and units are on the env's page) and the
transmissions per episode, with 95 % intervals, and the failed episodes, on the 64-scenario
test set and the paper scenario ([`protocol.md`](protocol.md)). A row over several seeds pools
them (rliable's stratified bootstrap over scenarios and seeds); the paper scenario is one
episode per seed. The best hand-designed rule is a point of the paper's trigger family chosen
on the validation set from a menu of rule variants and clocks (`models/<id>_hand.json`) — a
tuned baseline, not a learned trigger. The report is [`results.md`](results.md).
"""


def _units(board: Board) -> list[str]:
    """What an id's mean cost is (:attr:`etsc_envs.core.paper.Paper.cost`), with its env page."""
    from etsc_envs.papers import paper_of

    return [
        f"Mean cost: the mean per-step `mean_cost`, {paper_of(board.env_id).cost}; the env: "
        f"[{board.name}](envs/{board.name}.md); score a trigger against these rows: "
        "[benchmark.md](benchmark.md)."
    ]


README = ROOT / "README.md"
README_MARKERS = ("<!-- leaderboard: agents.leaderboard writes this table -->", "<!-- end -->")
"""The README's summary table lies between these lines."""


def best_rl_row(rows: list[Row]) -> Row | None:
    """The RL row of an id the README shows: among those with a test record and no failed
    test episode, the fewest transmissions at a cost within ×1.05 of the paper's rule's
    (the suite's goal); where none is within it, the cheapest; where every judged row fails
    some test episode, the one that fails fewest (its failures are shown beside it);
    ``None`` where no RL row has a test record."""
    by_name = {row.trigger: row for row in rows}
    paper = by_name["paper's rule"].sets["test"]
    judged = [row for row in rows if row.trigger in RL_TRIGGERS and row.sets["test"] is not None]
    if paper is None or not judged:
        return None

    def test_measure(row: Row) -> Measure:
        measure = row.sets["test"]
        assert measure is not None
        return measure

    clean = [row for row in judged if not test_measure(row).failures]
    if not clean:
        return min(
            judged, key=lambda row: (test_measure(row).failures, test_measure(row).cost["mean"])
        )
    limit = 1.05 * paper.cost["mean"]
    within = [row for row in clean if test_measure(row).cost["mean"] <= limit]
    if within:
        return min(within, key=lambda row: test_measure(row).sent["mean"])
    return min(clean, key=lambda row: test_measure(row).cost["mean"])


def _pair(measure: Measure | None) -> str:
    if measure is None:
        return "—"
    failed = f" ({measure.failures}/{measure.episodes} failed)" if measure.failures else ""
    return f"{_number(measure.cost['mean'])} / {_number(measure.sent['mean'])}{failed}"


def readme_table(boards: dict[str, list[Row]]) -> list[str]:
    """The README's table: per id, the test-set mean cost / transmissions of the paper's rule,
    the best hand point, the learned trigger and the best RL agent (:func:`best_rl_row`)."""
    lines = [
        README_MARKERS[0],
        "| id | paper's rule | best hand point | learned trigger (ES) | best RL agent |",
        "|---|---|---|---|---|",
    ]
    for board in BOARDS:
        by_name = {row.trigger: row for row in boards[board.env_id]}
        rl = best_rl_row(boards[board.env_id])
        rl_cell = "—" if rl is None else f"{_pair(rl.sets['test'])}, {rl.trigger}"
        cells = [
            f"[{SHORT_NAMES[board.env_id]}](docs/envs/{board.name}.md)",
            _pair(by_name["paper's rule"].sets["test"]),
            _pair(by_name[HAND].sets["test"]),
            _pair(by_name[LEARNED].sets["test"]),
            rl_cell,
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return [*lines, README_MARKERS[1]]


def with_readme_table(readme: str, table: list[str]) -> str:
    """``readme`` with the text between :data:`README_MARKERS` replaced by ``table``."""
    start, end = README_MARKERS
    if start not in readme or end not in readme.split(start, 1)[1]:
        raise ValueError(f"README.md: no table between {start!r} and {end!r}")
    before, rest = readme.split(start, 1)
    after = rest.split(end, 1)[1]
    return before + "\n".join(table) + after


def _commands(rows: list[Row]) -> list[str]:
    """Each record's command, once, with the rows it makes."""
    commands: dict[str, list[str]] = {}
    for row in rows:
        if row.command is not None:
            commands.setdefault(row.command, []).append(row.trigger)
    return [f"- {', '.join(triggers)}: `{command}`" for command, triggers in commands.items()]


def all_rows(records: Path) -> dict[str, list[Row]]:
    """Every id's rows."""
    return {board.env_id: board_rows(records, board) for board in BOARDS}


def render(
    records: Path, figures: Path | None, link: str, boards: dict[str, list[Row]] | None = None
) -> str:
    """The leaderboard's Markdown (``link`` is the figures' folder as the page refers to it)
    of ``boards`` (default every id's rows from ``records``); draws the figures into
    ``figures`` unless it is ``None``."""
    boards = all_rows(records) if boards is None else boards
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
        lines += [f"## `{board.env_id}` (paper {board.paper})", "", *_units(board), ""]
        lines += [*_table(rows), "", "Commands:", "", *_commands(rows), ""]
        image = f"{link}/{board.name}.png"
        lines += [f"![{board.env_id}: cost against transmissions]({image})", ""]
        if figures is not None:
            sweeps = _load(records / board.curves / "pareto.json")
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


def leaderboard_data(records: Path, boards: dict[str, list[Row]] | None = None) -> dict[str, Any]:
    """Every id's rows as data, the numbers of the page (:mod:`etsc_envs.evaluation.leaderboard`
    reads them): trigger, what it is, record, and per set the mean cost and transmissions with
    their intervals, failures and episodes; each id with its paper and what its cost is."""
    from etsc_envs.papers import paper_of

    boards = all_rows(records) if boards is None else boards
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
                    for row in boards[board.env_id]
                ],
            }
            for board in BOARDS
        },
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.leaderboard",
        description="docs/leaderboard.md and its figures from the judged records (and, from "
        "the shipped records, the README's table)",
    )
    parser.add_argument("--records", type=Path, default=RECORDS, help="the records' folder")
    parser.add_argument(
        "--out", type=Path, default=OUTPUT, help="the Markdown file (figures beside it)"
    )
    parser.add_argument("--data", type=Path, default=DATA, help="the rows as JSON package data")
    args = parser.parse_args(argv)
    if not args.records.is_dir():
        parser.error(f"--records must be a folder of judged records, got {args.records}")
    needed = [
        Path(folder) / name
        for board in BOARDS
        for folder, name in (
            (board.curves, "pareto.json"),
            (board.hand, "results.json"),
            (board.learned, "results.json"),
        )
    ]
    missing = [str(path) for path in needed if not (args.records / path).is_file()]
    if missing:
        parser.error(f"--records {args.records} lacks the judged records {missing}")
    figures = args.out.with_suffix("")
    try:
        require_writable_file(args.out, "--out")
        require_writable_file(args.data, "--data")
        require_writable_folder(figures, "--out (its figures' folder)")
        boards = all_rows(args.records)
        text = render(args.records, figures, figures.name, boards)
        atomic_write_text(args.out, text)
        atomic_write_text(
            args.data, json.dumps(leaderboard_data(args.records, boards), indent=1) + "\n"
        )
    except ValueError as error:
        parser.error(str(error))
    except OSError as error:
        parser.error(f"--out {args.out} could not be written: {error.strerror or error}")
    except KeyboardInterrupt:
        print(f"interrupted; {args.out} was not replaced", file=sys.stderr)
        return 130
    print(f"wrote {args.out}, {len(BOARDS)} figures in {figures}/ and {args.data}", file=sys.stderr)
    if args.records.resolve() == RECORDS:
        readme = with_readme_table(README.read_text(encoding="utf-8"), readme_table(boards))
        atomic_write_text(README, readme)
        print(f"wrote the table of {README}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

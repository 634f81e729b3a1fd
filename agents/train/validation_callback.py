"""Scoring a policy during training against the paper's trigger on the validation scenarios.

Model selection follows the test protocol (``docs/protocol.md``): the training run is scored
on the *validation* set only (the test set is for reporting), all its scenarios at once in the
native vector env (:func:`etsc_envs.evaluation.batch.run_batch`), and the best-scoring trained
model is kept (:mod:`agents.train.kept_checkpoint`).
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

from agents.train.kept_checkpoint import TRAINED_KEY, kept_evaluation
from agents.train.model_files import write_model
from etsc_envs.core.files import atomic_write_text
from etsc_envs.decisions import DecisionSet, SelfTriggeredPolicy
from etsc_envs.evaluation.batch import run_batch
from etsc_envs.evaluation.episodes import to_jsonable
from etsc_envs.evaluation.policy_specs import EpisodeSetup, episode_setup
from etsc_envs.protocol import scenario_set
from etsc_envs.sb3_models import NormalizedModel, ObservationStatistics

COMPARED_KEYS = ("mean_cost", "transmissions", "transmission_rate", "failure")
"""What a one-episode summary records (the two axes of the comparison and failure)."""


def episode_summary(record: dict[str, Any]) -> dict[str, Any]:
    """The compared keys of an episode record."""
    return {key: to_jsonable(record[key]) for key in COMPARED_KEYS}


def set_summary(records: list[dict[str, Any]]) -> dict[str, Any]:
    """Means over a scenario set of ``mean_cost``, ``transmissions``, ``transmission_rate``
    and ``return``, and the number of failed episodes."""
    summary: dict[str, Any] = {
        key: float(np.mean([record[key] for record in records]))
        for key in ("mean_cost", "transmissions", "transmission_rate", "return")
    }
    summary["failures"] = sum(record["failure"] is not None for record in records)
    return summary


def deployment(setup: EpisodeSetup, decisions: DecisionSet) -> tuple[Any, ...]:
    """``decisions`` with the transmit/hold spaces, observation names and sampling period a
    policy of them acts with on the env of ``setup`` (one agent's, for a PettingZoo id): the
    arguments of :class:`~etsc_envs.decisions.SelfTriggeredPolicy` after its model."""
    observation_space, action_space, names = setup.policy_spaces()
    env = setup.env
    loop = env.unwrapped.loop if callable(env.observation_space) else env.unwrapped
    period = float(loop.params.sampling_period_s)
    return decisions, observation_space, action_space, names, period


class PaperComparisonCallback(BaseCallback):
    """Every ``every`` training steps, run the current policy on the validation scenarios and
    log it beside the paper trigger's run of the same scenarios (run once, at the start).

    Args:
        env_id: the trained environment's id.
        env_kwargs: kwargs of the evaluation envs (the set's ``randomize`` replaces theirs).
        every: training steps between evaluations.
        out_path: JSON file that receives the list of evaluations after each one (each entry
            ``{"timesteps", "env_steps", "wall_time_s", "updates", "trained", "learned": {...},
            "paper": {...}}`` with :func:`set_summary`'s keys; ``env_steps`` counts the
            sampling instants simulated for training so far — ``timesteps`` times the env's
            ``decision_interval`` (1 but on 003, whose per-instant env may decide every few
            sampling periods), the sum of the decisions' ``info["elapsed_steps"]`` for
            self-triggered decisions — ``wall_time_s`` the training time since the start,
            evaluations included, ``updates`` the model's gradient updates so far and
            ``trained`` whether the evaluated policy had been trained).
        set_size: validation scenarios per evaluation.
        best_model_path: where the trained model with the highest mean validation return so
            far is saved (with its observation statistics beside it), or ``None``; a policy
            not yet trained is validated but never kept (:mod:`agents.train.kept_checkpoint`).
        decisions: the decision set of a model trained on self-triggered decisions (it is
            evaluated as :class:`~etsc_envs.decisions.SelfTriggeredPolicy` and saved with
            the set beside it), or ``None``.
        starts_trained: the run starts from an earlier, trained model (``init_from``): the
            policy it starts from is evaluated too (timesteps 0) and counts as trained, so that
            the run can keep it as its best model when reinforcement only makes it worse.

    Logged (TensorBoard and SB3's logger): ``eval/mean_cost``, ``eval/transmissions``,
    ``eval/return`` and the paper trigger's ``eval/paper_mean_cost``,
    ``eval/paper_transmissions``.
    """

    def __init__(
        self,
        env_id: str,
        env_kwargs: dict[str, Any],
        every: int,
        out_path: str | Path,
        set_size: int,
        best_model_path: str | Path | None = None,
        decisions: DecisionSet | None = None,
        starts_trained: bool = False,
    ) -> None:
        super().__init__()
        self.starts_trained = starts_trained
        self.env_id = env_id
        self.scenarios = scenario_set("validation", set_size)
        base = {key: value for key, value in env_kwargs.items() if key != "randomize"}
        self.env_kwargs = self.scenarios.env_kwargs(base)
        self.every = every
        self.out_path = Path(out_path)
        self.best_model_path = None if best_model_path is None else Path(best_model_path)
        self.evaluations: list[dict[str, Any]] = []
        self.paper: dict[str, Any] = {}
        self._next_evaluation = every
        self.decisions = decisions
        self._deployment: tuple[Any, ...] | None = None
        self.env_steps = 0
        self.instants_per_step = int(env_kwargs.get("decision_interval", 1))
        self._started = time.perf_counter()
        self._earlier_wall_time_s = 0.0

    def _on_training_start(self) -> None:
        setup = episode_setup(self.env_id, self.env_kwargs)
        paper_trigger = setup.make_policy("paper", {})
        if self.decisions is not None:
            self._deployment = deployment(setup, self.decisions)
        setup.env.close()
        self.paper = set_summary(self._run(paper_trigger))
        self._next_evaluation = self.num_timesteps + self.every
        self._started = time.perf_counter()
        if self.starts_trained and not self.evaluations:
            self._evaluate()

    def _on_step(self) -> bool:
        infos = self.locals.get("infos") or ()
        self.env_steps += sum(
            int(info.get("elapsed_steps", self.instants_per_step)) for info in infos
        )
        if self.num_timesteps < self._next_evaluation:
            return True
        self._next_evaluation += self.every
        self._evaluate()
        return True

    def _evaluate(self) -> None:
        """Run the current policy on the validation scenarios; record, log, keep the best
        trained one."""
        learned = set_summary(self._run(self._current_policy()))
        updates = int(self.model._n_updates)
        trained = self.starts_trained or updates > 0
        self.evaluations.append(
            {
                "timesteps": self.num_timesteps,
                "env_steps": self.env_steps,
                "wall_time_s": self._earlier_wall_time_s + time.perf_counter() - self._started,
                "updates": updates,
                TRAINED_KEY: trained,
                "scenarios": self.scenarios.describe(),
                "learned": learned,
                "paper": self.paper,
            }
        )
        for name, summary in (("", learned), ("paper_", self.paper)):
            self.logger.record(f"eval/{name}mean_cost", summary["mean_cost"])
            self.logger.record(f"eval/{name}transmissions", summary["transmissions"])
        self.logger.record("eval/return", learned["return"])
        if (
            self.best_model_path is not None
            and kept_evaluation(self.evaluations) is self.evaluations[-1]
        ):
            self._save_best()
        atomic_write_text(self.out_path, json.dumps(to_jsonable(self.evaluations), indent=2) + "\n")

    def restore(self, history: list[dict[str, Any]]) -> None:
        """Continue an interrupted run: keep its evaluations (up to the resumed checkpoint),
        among them the kept checkpoint's so far."""
        self.evaluations = list(history)
        if history:
            self.env_steps = int(history[-1].get("env_steps", history[-1]["timesteps"]))
            self._earlier_wall_time_s = float(history[-1].get("wall_time_s", 0.0))

    def _run(self, policy: Any) -> list[dict[str, Any]]:
        return run_batch(self.env_id, policy, self.scenarios.seeds, self.env_kwargs)

    def _save_best(self) -> None:
        """The current model (with statistics and decision set) as the best so far."""
        write_model(self.model, self.best_model_path, self.decisions)

    def _current_policy(self) -> Any:
        """The model, reading observations through a frozen copy of the training statistics
        (deployed as a transmit/hold policy when it takes self-triggered decisions)."""
        normalization = self.model.get_vec_normalize_env()
        model = (
            self.model
            if normalization is None
            else NormalizedModel(self.model, ObservationStatistics.of(normalization))
        )
        if self._deployment is None:
            return model
        return SelfTriggeredPolicy(model, *self._deployment)

"""Scoring a policy in training against the paper's trigger on the paper scenario."""

from __future__ import annotations

import json
import pickle
from pathlib import Path
from typing import Any

from stable_baselines3.common.callbacks import BaseCallback

from baselines.cli import EpisodeSetup, episode_setup
from baselines.episodes import to_jsonable
from baselines.policies import NormalizedModel
from etsc_envs.core.files import atomic_write_text

COMPARED_KEYS = ("mean_cost", "transmissions", "transmission_rate", "failure")
"""What an evaluation records of each episode (the two axes of the comparison and failure)."""


def episode_summary(record: dict[str, Any]) -> dict[str, Any]:
    """The compared keys of an episode record."""
    return {key: to_jsonable(record[key]) for key in COMPARED_KEYS}


class PaperComparisonCallback(BaseCallback):
    """Every ``every`` training steps, run the current policy for one episode of the paper
    scenario and log it beside the paper trigger's episode (run once, at the start).

    Args:
        env_id: the trained environment's id.
        env_kwargs: kwargs of the evaluation env (``randomize`` is forced false, so that the
            scenario is the paper's).
        every: training steps between evaluations.
        out_path: JSON file that receives the list of evaluations after each one.

    Logged (TensorBoard and SB3's logger): ``eval/mean_cost``, ``eval/transmissions`` and the
    paper trigger's ``eval/paper_mean_cost``, ``eval/paper_transmissions``.
    """

    def __init__(
        self, env_id: str, env_kwargs: dict[str, Any], every: int, out_path: str | Path
    ) -> None:
        super().__init__()
        self.env_id = env_id
        self.env_kwargs = {**env_kwargs, "randomize": False}
        self.every = every
        self.out_path = Path(out_path)
        self.evaluations: list[dict[str, Any]] = []
        self.paper: dict[str, Any] = {}
        self._next_evaluation = every
        self._setup: EpisodeSetup | None = None

    def _on_training_start(self) -> None:
        self._setup = episode_setup(self.env_id, self.env_kwargs)
        record, _ = self._setup.run(self._setup.env, self._setup.make_policy("paper", {}), seed=0)
        self.paper = episode_summary(record)
        self._next_evaluation = self.num_timesteps + self.every

    def _on_step(self) -> bool:
        if self.num_timesteps < self._next_evaluation:
            return True
        self._next_evaluation += self.every
        record, _ = self._setup.run(self._setup.env, self._current_policy(), seed=0)
        learned = episode_summary(record)
        self.evaluations.append(
            {"timesteps": self.num_timesteps, "learned": learned, "paper": self.paper}
        )
        for name, summary in (("", learned), ("paper_", self.paper)):
            self.logger.record(f"eval/{name}mean_cost", summary["mean_cost"])
            self.logger.record(f"eval/{name}transmissions", summary["transmissions"])
        atomic_write_text(self.out_path, json.dumps(self.evaluations, indent=2) + "\n")
        return True

    def _on_training_end(self) -> None:
        if self._setup is not None:
            self._setup.env.close()

    def _current_policy(self) -> Any:
        """The model, reading observations through a frozen copy of the training statistics."""
        normalization = self.model.get_vec_normalize_env()
        if normalization is None:
            return self.model
        return NormalizedModel(self.model, pickle.loads(pickle.dumps(normalization)))

"""Which of a training run's validations is the checkpoint the run keeps.

:class:`~agents.train.validation_callback.PaperComparisonCallback` validates the policy every
``evaluation_every`` steps and keeps the one of the highest mean validation return
(``best_model.zip``) — among the policies the run has *trained*. A network no gradient step
has touched yet is recorded on the learning curve (its ``evaluations.json`` entry says
``"trained": false``) but is not a learned policy, so it is never kept: DQN trains only after
``learning_starts`` steps and PPO only after its first rollout, and a validation may come
earlier (a from-scratch network that happens to hold well on validation would otherwise be
reported as what the learner learned). A run started from an earlier model (``init_from``) has
a trained policy from its start. The scores read back from ``evaluations.json`` — a tuning's
``best_validation_return`` (:func:`agents.sweep.results.scores`), the point of a run that
:mod:`agents.judge.penalty_choice` judges — apply the same rule through
:func:`kept_evaluation`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

TRAINED_KEY = "trained"
"""An ``evaluations.json`` entry's flag: whether the evaluated policy had been trained (entries
written before the flag existed lack it and count as trained)."""


def may_be_kept(entry: Mapping[str, Any]) -> bool:
    """Whether the policy of an ``evaluations.json`` entry may be the run's kept checkpoint."""
    return entry.get(TRAINED_KEY, True) is not False


def kept_evaluation(evaluations: Sequence[Mapping[str, Any]]) -> Mapping[str, Any] | None:
    """The entry of the checkpoint a run keeps: the first of the highest mean validation
    return among its trained policies; ``None`` while none was trained."""
    candidates = [entry for entry in evaluations if may_be_kept(entry)]
    return max(candidates, key=lambda entry: entry["learned"]["return"], default=None)

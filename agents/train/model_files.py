"""A trained model on disk: the SB3 zip, its observation statistics and its decision set.

Every model the trainer writes (the final model, SB3's periodic checkpoints, the best model
so far) goes through :func:`write_model`: each file through a temporary file and a rename,
the model last, so a model file on disk always has its statistics and decision set beside it,
and SIGINT held until the three are written (:func:`~etsc_envs.core.files.interrupts_deferred`)
— an interrupt inside PyTorch's zip writer would otherwise surface as its ``RuntimeError``
instead of the interrupt the command line turns into "continue with --resume".
"""

from __future__ import annotations

import io
from pathlib import Path

from stable_baselines3.common.base_class import BaseAlgorithm

from etsc_envs.core.files import atomic_write_bytes, interrupts_deferred
from etsc_envs.decisions import DecisionSet
from etsc_envs.sb3_models import ObservationStatistics, normalization_path


def write_model(
    model: BaseAlgorithm,
    path: Path,
    decisions: DecisionSet | None = None,
    statistics_path: Path | None = None,
) -> None:
    """Write ``model`` at ``path``, its ``VecNormalize`` statistics (if it has any, as
    :class:`~etsc_envs.sb3_models.ObservationStatistics` data) at ``statistics_path`` (default:
    :func:`~etsc_envs.sb3_models.normalization_path`) and its decision set (if any) beside it."""
    with interrupts_deferred():
        if decisions is not None:
            decisions.save(path)
        statistics = model.get_vec_normalize_env()
        if statistics is not None:
            statistics_path = statistics_path or normalization_path(path)
            atomic_write_bytes(statistics_path, ObservationStatistics.of(statistics).to_bytes())
        buffer = io.BytesIO()
        model.save(buffer)
        atomic_write_bytes(path, buffer.getvalue())

"""The loader of trained Stable-Baselines3 models lives in the installed package,
:mod:`etsc_envs.sb3_models`; these names are read from there by the modules of the checkout that
still import them from here."""

from etsc_envs.sb3_models import (
    ENV_ID_ATTRIBUTE,
    NormalizedModel,
    ObservationStatistics,
    infer_sb3_algorithm,
    legacy_normalization_path,
    load_sb3,
    normalization_path,
    require_model_fits,
    takes_action_masks,
)

__all__ = [
    "ENV_ID_ATTRIBUTE",
    "NormalizedModel",
    "ObservationStatistics",
    "infer_sb3_algorithm",
    "legacy_normalization_path",
    "load_sb3",
    "normalization_path",
    "require_model_fits",
    "takes_action_masks",
]

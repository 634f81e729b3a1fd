"""Trained Stable-Baselines3 models as trigger policies: loading a saved model (whichever
algorithm trained it) with the observation statistics saved beside it.

The analytic policies (the papers' triggers, periodic, always) live in
:mod:`etsc_envs.triggers`; all answer ``predict(obs, state=None, episode_start=None,
deterministic=True) -> (action, state)``.
"""

from __future__ import annotations

import inspect
import pickle
import warnings
import zipfile
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

ENV_ID_ATTRIBUTE = "etsc_env_id"
"""The attribute a model trained by :mod:`agents.train` carries, saved in its zip's ``data``
record: the id it was trained on (older saves do not record it)."""


def _one_line(error: BaseException) -> str:
    """``error`` as ``Type: message`` on one line."""
    return f"{type(error).__name__}: {' '.join(str(error).split())}"


def read_model_record(path: str | Path) -> dict[str, Any]:
    """The ``data`` record of a Stable-Baselines3 zip (spaces unpickled), or ``ValueError``
    naming the file if it is missing, not a zip, or not an SB3 save."""
    from stable_baselines3.common.save_util import json_to_data

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"sb3 model file not found: {path}")
    try:
        with zipfile.ZipFile(path) as archive, warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an unreadable entry is reported below instead
            record = json_to_data(archive.read("data").decode("utf-8"))
    except Exception as error:  # whatever a damaged or foreign file makes the readers raise
        raise ValueError(
            f"{path} is not a readable Stable-Baselines3 model ({_one_line(error)})"
        ) from None
    expected = {"policy_class": type, "observation_space": gym.Space, "action_space": gym.Space}
    missing = [
        key
        for key, kind in expected.items()
        if not isinstance(record, dict) or not isinstance(record.get(key), kind)
    ]
    if missing:
        raise ValueError(f"{path} is not a readable Stable-Baselines3 model (no valid {missing})")
    return record


MASKABLE_POLICY_MODULE = "sb3_contrib.common.maskable.policies"
"""The module of the policies of sb3-contrib's ``MaskablePPO`` (what its saves record)."""


def infer_sb3_algorithm(path: str | Path) -> type:
    """The SB3 algorithm class that saved ``path``, read from the zip's ``data`` record
    (sb3-contrib's ``MaskablePPO`` included).

    Off-policy algorithms save a policy of their own module (``stable_baselines3.dqn.policies``);
    PPO and A2C share ``stable_baselines3.common.policies`` and differ by PPO's ``clip_range``.
    """
    import stable_baselines3 as sb3

    data = read_model_record(path)
    policy_class = data["policy_class"]
    module = getattr(policy_class, "__module__", "")
    if module == MASKABLE_POLICY_MODULE:
        from sb3_contrib import MaskablePPO

        return MaskablePPO
    if module == "stable_baselines3.common.policies":
        algorithm_name = "PPO" if "clip_range" in data else "A2C"
    else:
        algorithm_name = module.split(".")[1].upper() if module.count(".") >= 1 else ""
    algorithm = getattr(sb3, algorithm_name, None)
    if algorithm is None:
        raise ValueError(f"cannot tell the SB3 algorithm of {path} (policy module {module})")
    return algorithm


def _same_layout(model_space: gym.Space, env_space: gym.Space) -> bool:
    """Whether a model for ``model_space`` can act in ``env_space``: the same space for
    actions; for observations the same kind, shape and dtype (bounds may differ, such as the
    transmission clock's, which grows with the horizon)."""
    if isinstance(env_space, gym.spaces.Box):
        return (
            isinstance(model_space, gym.spaces.Box)
            and model_space.shape == env_space.shape
            and model_space.dtype == env_space.dtype
        )
    return model_space == env_space


def require_model_fits(
    path: str | Path,
    observation_space: gym.Space,
    action_space: gym.Space,
    env_id: str,
    argument: str = "model",
) -> dict[str, Any]:
    """The model record of ``path`` (:func:`read_model_record`), or ``ValueError`` naming both
    envs' spaces and the model's env id when it was trained for spaces unlike ``env_id``'s."""
    record = read_model_record(path)
    model_observations = record["observation_space"]
    model_actions = record["action_space"]
    if _same_layout(model_observations, observation_space) and _same_layout(
        model_actions, action_space
    ):
        return record
    trained_on = record.get(ENV_ID_ATTRIBUTE) or _ids_fitting(model_observations, model_actions)
    raise ValueError(
        f"{argument} {path} was trained on {trained_on} (observations "
        f"{describe_space(model_observations)}, actions {describe_space(model_actions)}) and "
        f"cannot act in {env_id} (observations {describe_space(observation_space)}, actions "
        f"{describe_space(action_space)})"
    )


def describe_space(space: gym.Space) -> str:
    """``space`` in a few words on one line (a ``Box`` by shape and dtype, not its bounds)."""
    if isinstance(space, gym.spaces.Box):
        return f"Box(shape={space.shape}, dtype={space.dtype})"
    return " ".join(str(space).split())


def _ids_fitting(observation_space: gym.Space, action_space: gym.Space) -> str:
    """For a model that does not record its env id: the etsc-envs ids whose default spaces it
    fits (found by building each env once; only on the way to an error message)."""
    import etsc_envs

    fitting = []
    for env_id in sorted(etsc_envs.ENV_IDS):
        env = gym.make(env_id)
        if _same_layout(observation_space, env.observation_space) and _same_layout(
            action_space, env.action_space
        ):
            fitting.append(env_id)
        env.close()
    for env_id in sorted(etsc_envs.PETTINGZOO_ENV_IDS):
        env = etsc_envs.make_parallel(env_id)
        agent = env.possible_agents[0]
        if _same_layout(observation_space, env.observation_space(agent)) and _same_layout(
            action_space, env.action_space(agent)
        ):
            fitting.append(env_id)
    if not fitting:
        return "an env id it does not record (no etsc-envs id has its spaces)"
    return f"an env id it does not record (its spaces are those of {' and '.join(fitting)})"


NORMALIZATION_SUFFIX = "_vecnormalize.pkl"
"""A model ``NAME.zip`` trained on normalised observations keeps the statistics beside it, in
``NAME_vecnormalize.pkl`` (Stable-Baselines3's pickled ``VecNormalize``)."""


def normalization_path(model_path: str | Path) -> Path:
    """Where the observation statistics of the model saved at ``model_path`` live."""
    model_path = Path(model_path)
    return model_path.with_name(model_path.stem + NORMALIZATION_SUFFIX)


class NormalizedModel:
    """A Stable-Baselines3 model that reads observations through ``VecNormalize`` statistics
    (``predict`` never updates them).

    Args:
        model: the loaded model.
        normalization: the unpickled ``VecNormalize`` (its ``venv`` may be unset).
        freeze: switch the statistics' own updates off (``training = False``), as evaluation
            wants; ``False`` reads the live statistics of a run still training, which its
            training env goes on updating.
    """

    def __init__(self, model: Any, normalization: Any, freeze: bool = True) -> None:
        self.model = model
        self.normalization = normalization
        if freeze:
            self.normalization.training = False
        self.observation_space = model.observation_space
        self.action_space = model.action_space

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
        action_masks: np.ndarray | None = None,
    ) -> tuple[np.ndarray, Any]:
        """The model's ``predict`` on normalised observations (``action_masks`` is passed on
        when given, for sb3-contrib's ``MaskablePPO``)."""
        normalized = self.normalization.normalize_obs(np.asarray(observation, dtype=np.float32))
        masks = {} if action_masks is None else {"action_masks": action_masks}
        return self.model.predict(
            normalized,
            state=state,
            episode_start=episode_start,
            deterministic=deterministic,
            **masks,
        )


def takes_action_masks(model: Any) -> bool:
    """Whether ``model.predict`` takes ``action_masks`` (sb3-contrib's ``MaskablePPO``, also
    inside a :class:`NormalizedModel`)."""
    inner = model.model if isinstance(model, NormalizedModel) else model
    return "action_masks" in inspect.signature(inner.predict).parameters


def load_sb3(
    path: str | Path,
    env: gym.Env | None = None,
    *,
    observation_space: gym.Space | None = None,
    action_space: gym.Space | None = None,
    env_id: str = "this environment",
) -> Any:
    """Load a saved Stable-Baselines3 model, whichever algorithm trained it, with the
    observation statistics saved beside it if there are any (see :func:`normalization_path`).

    Given the spaces it must act in, first checks that the model fits them
    (:func:`require_model_fits`). A damaged or foreign model or statistics file raises one
    ``ValueError`` line naming it.
    """
    if observation_space is not None and action_space is not None:
        require_model_fits(path, observation_space, action_space, env_id)
    algorithm = infer_sb3_algorithm(path)
    try:
        model = algorithm.load(path, env=env, device="cpu")
    except Exception as error:  # whatever a damaged file makes SB3, torch or pickle raise
        raise ValueError(
            f"{path} is not a readable Stable-Baselines3 model ({_one_line(error)})"
        ) from None
    statistics = normalization_path(path)
    if not statistics.is_file():
        return model
    try:
        normalization = pickle.loads(statistics.read_bytes())
        normalization.normalize_obs  # noqa: B018 - what NormalizedModel needs of it
    except Exception as error:  # whatever a damaged or foreign pickle raises
        raise ValueError(
            f"observation statistics {statistics} (beside the model) are not a readable "
            f"VecNormalize ({_one_line(error)})"
        ) from None
    return NormalizedModel(model, normalization)

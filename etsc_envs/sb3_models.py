"""Trained Stable-Baselines3 models as trigger policies: loading a saved model (whichever
algorithm trained it) with the observation statistics saved beside it, and nothing in its
files unpickled (``docs/security.md``).

Stable-Baselines3 and torch are the ``train`` extra (``pip install 'etsc-envs[train]'``): they
are imported only when a model is loaded. :func:`etsc_envs.load_policy` is the entry point for
a project that installed the package; the analytic policies (the papers' triggers, periodic,
always) live in :mod:`etsc_envs.triggers`; all answer ``predict(obs, state=None,
episode_start=None, deterministic=True) -> (action, state)``.
"""

from __future__ import annotations

import base64
import importlib
import inspect
import io
import json
import pickletools
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from types import ModuleType
from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs import registry

ENV_ID_ATTRIBUTE = "etsc_env_id"
"""The attribute a model trained by :mod:`agents.train` carries, saved in its zip's ``data``
record: the id it was trained on (older saves do not record it)."""


def _one_line(error: BaseException) -> str:
    """``error`` as ``Type: message`` on one line."""
    return f"{type(error).__name__}: {' '.join(str(error).split())}"


def read_model_record(path: str | Path) -> dict[str, Any]:
    """The ``data`` record of a Stable-Baselines3 zip read as JSON, without unpickling any of
    its entries, or ``ValueError`` naming the file if it is missing, not a zip, or not an SB3
    save.

    SB3 stores the objects it cannot write as JSON (the policy class, the spaces, schedules,
    training buffers) as cloudpickle blobs inside the record, each beside the plain values of
    its attributes. The record returned keeps the plain values, with ``policy_module`` (the
    policy class's module), ``observation_space`` and ``action_space`` rebuilt from those
    attributes (:func:`_space_from_record`; a ``Box`` with unbounded limits: a policy reads
    only its shape and dtype), and ``serialized`` (each pickled entry's base64 text, never
    unpickled)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"sb3 model file not found: {path}")
    try:
        with zipfile.ZipFile(path) as archive:
            stored = json.loads(archive.read("data").decode("utf-8"))
        if not isinstance(stored, dict):
            raise ValueError("its data record is not a JSON object")
        serialized = {
            key: value[SERIALIZED]
            for key, value in stored.items()
            if isinstance(value, dict) and SERIALIZED in value
        }
        record = {key: value for key, value in stored.items() if key not in serialized}
        record["serialized"] = serialized
        record["policy_module"] = stored["policy_class"]["__module__"]
        for key in ("observation_space", "action_space"):
            record[key] = _space_from_record(stored[key])
    except Exception as error:  # whatever a damaged or foreign file makes the readers raise
        raise ValueError(
            f"{path} is not a readable Stable-Baselines3 model ({_one_line(error)})"
        ) from None
    return record


SERIALIZED = ":serialized:"
"""The key under which SB3's ``data`` record holds a cloudpickled object."""


def _space_from_record(entry: dict[str, Any]) -> gym.Space:
    """The space a cloudpickled entry of SB3's record describes, rebuilt from the plain
    attributes stored beside the pickle (``ValueError`` for another kind of space)."""
    kind = entry[":type:"]
    shape = tuple(int(size) for size in entry["_shape"])
    if kind == "<class 'gymnasium.spaces.box.Box'>":
        dtype = np.dtype(entry["dtype"])
        if dtype.kind != "f":
            raise ValueError(f"a Box of dtype {dtype} (the suite loads float Boxes)")
        return gym.spaces.Box(-np.inf, np.inf, shape, dtype.type)
    if kind == "<class 'gymnasium.spaces.discrete.Discrete'>":
        return gym.spaces.Discrete(int(entry["n"]), start=int(entry["start"]))
    if kind == "<class 'gymnasium.spaces.multi_binary.MultiBinary'>":
        return gym.spaces.MultiBinary(shape[0] if len(shape) == 1 else list(shape))
    if kind == "<class 'gymnasium.spaces.multi_discrete.MultiDiscrete'>":
        counts = [int(word) for word in str(entry["nvec"]).strip("[]").split()]
        return gym.spaces.MultiDiscrete(np.reshape(counts, shape), dtype=entry["dtype"])
    raise ValueError(
        f"a space of {kind} (the suite loads Box, Discrete, MultiBinary, MultiDiscrete)"
    )


def _pickled_names(blob: str) -> set[str]:
    """The ``module.name`` globals a base64 pickle refers to, read from its opcodes without
    unpickling it."""
    names, strings = set(), []
    for opcode, argument, _ in pickletools.genops(base64.b64decode(blob)):
        if isinstance(argument, str):
            strings.append(argument)
        if opcode.name == "GLOBAL" and isinstance(argument, str):
            names.add(argument.replace(" ", "."))
        elif opcode.name == "STACK_GLOBAL" and len(strings) >= 2:
            names.add(f"{strings[-2]}.{strings[-1]}")
    return names


def _default_policy_kwargs(
    path: str | Path, blob: str, algorithm: type, objects: dict[str, Any]
) -> dict[str, Any]:
    """The ``policy_kwargs`` to load ``path`` with when SB3 pickled them: the algorithm's own
    defaults (A2C's RMSprop optimizer, which SB3 stores as a class), if the pickle names no
    other class; else ``ValueError`` (custom activations or layers would act otherwise)."""
    model = algorithm(objects["policy_class"], env=None, _init_setup_model=False)
    defaults = dict(model.policy_kwargs)
    allowed = {
        f"{value.__module__}.{value.__qualname__}"
        for value in defaults.values()
        if isinstance(value, type)
    }
    names = _pickled_names(blob)
    if not names <= allowed:
        raise ValueError(
            f"{path}: its policy_kwargs name {sorted(names - allowed)}, which the suite does not "
            "load (unpickling runs whatever code the file carries; see docs/security.md)"
        )
    return defaults


ACTING_PLACEHOLDERS: dict[str, Any] = {
    "_last_obs": None,
    "_last_episode_starts": None,
    "_last_original_obs": None,
    "ep_info_buffer": None,
    "ep_success_buffer": None,
    "rollout_buffer_class": None,
    "replay_buffer_class": None,
    "lr_schedule": None,
    "exploration_schedule": None,
    "clip_range": 0.2,
    "train_freq": 1,
}
"""Pickled entries of SB3's record that hold training state only, and what a model loaded to
act (:func:`load_sb3`) gets in their place: the constructor's defaults, rebuilt by
``_setup_model`` where it needs them (a model loaded so is for acting, not for training on)."""


def safe_load_objects(
    path: str | Path,
    record: dict[str, Any],
    algorithm: type,
    observation_space: gym.Space | None = None,
    action_space: gym.Space | None = None,
) -> dict[str, Any]:
    """SB3's ``custom_objects`` for loading ``path`` to act without unpickling anything: every
    cloudpickled entry of its ``record`` (:func:`read_model_record`) replaced, the policy class
    by ``algorithm``'s ``MlpPolicy`` (of the module the record names), the spaces by the env's
    (or the record's rebuilt ones), training state by :data:`ACTING_PLACEHOLDERS`. Another
    pickled entry (a custom class, a schedule function, ``policy_kwargs`` holding classes) is
    refused with one ``ValueError`` line: loading it would run what the file carries."""
    policy_class = getattr(algorithm, "policy_aliases", {}).get("MlpPolicy")
    if policy_class is None or policy_class.__module__ != record["policy_module"]:
        raise ValueError(
            f"{path}: its policy class (module {record['policy_module']}) is not "
            f"{algorithm.__name__}'s MlpPolicy, the only policy the suite loads without "
            "unpickling it"
        )
    objects: dict[str, Any] = {
        "policy_class": policy_class,
        "observation_space": observation_space or record["observation_space"],
        "action_space": action_space or record["action_space"],
    }
    if "policy_kwargs" in record["serialized"]:
        objects["policy_kwargs"] = _default_policy_kwargs(
            path, record["serialized"]["policy_kwargs"], algorithm, objects
        )
    others = sorted(set(record["serialized"]) - set(objects) - set(ACTING_PLACEHOLDERS))
    if others:
        raise ValueError(
            f"{path}: its data record holds pickled {others}, which the suite does not load "
            "(unpickling runs whatever code the file carries; see docs/security.md)"
        )
    objects.update(
        {key: value for key, value in ACTING_PLACEHOLDERS.items() if key in record["serialized"]}
    )
    # an off-policy model acts without its replay buffer: one transition of the default class
    objects.update({"replay_buffer_kwargs": {}, "buffer_size": 1})
    return objects


TRAIN_EXTRA = "pip install 'etsc-envs[train]'"
"""What installs Stable-Baselines3, sb3-contrib and torch beside the package."""


def training_module(name: str) -> ModuleType:
    """The module ``name`` of the ``train`` extra (``stable_baselines3``, ``sb3_contrib``),
    imported now; ``ModuleNotFoundError`` in one line naming the extra if it is missing."""
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as error:
        raise ModuleNotFoundError(
            f"loading a Stable-Baselines3 model needs {error.name}, which the train extra "
            f"installs: {TRAIN_EXTRA}"
        ) from None


MASKABLE_POLICY_MODULE = "sb3_contrib.common.maskable.policies"
"""The module of the policies of sb3-contrib's ``MaskablePPO`` (what its saves record)."""


def infer_sb3_algorithm(path: str | Path) -> type:
    """The SB3 algorithm class that saved ``path``, read from the zip's ``data`` record
    (sb3-contrib's ``MaskablePPO`` included).

    Off-policy algorithms save a policy of their own module (``stable_baselines3.dqn.policies``);
    PPO and A2C share ``stable_baselines3.common.policies`` and differ by PPO's ``clip_range``.
    """
    data = read_model_record(path)
    module = data["policy_module"]
    if module == MASKABLE_POLICY_MODULE:
        return training_module("sb3_contrib").MaskablePPO
    sb3 = training_module("stable_baselines3")
    if module == "stable_baselines3.common.policies":
        algorithm_name = "PPO" if "clip_range" in {*data, *data["serialized"]} else "A2C"
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
    fitting = []
    for env_id in sorted(registry.ENV_IDS):
        env = gym.make(env_id)
        if _same_layout(observation_space, env.observation_space) and _same_layout(
            action_space, env.action_space
        ):
            fitting.append(env_id)
        env.close()
    for env_id in sorted(registry.PETTINGZOO_ENV_IDS):
        env = registry.make_parallel(env_id)
        agent = env.possible_agents[0]
        if _same_layout(observation_space, env.observation_space(agent)) and _same_layout(
            action_space, env.action_space(agent)
        ):
            fitting.append(env_id)
    if not fitting:
        return "an env id it does not record (no etsc-envs id has its spaces)"
    return f"an env id it does not record (its spaces are those of {' and '.join(fitting)})"


NORMALIZATION_SUFFIX = "_vecnormalize.npz"
"""A model ``NAME.zip`` trained on normalised observations keeps the statistics beside it, in
``NAME_vecnormalize.npz`` (:class:`ObservationStatistics`: arrays only, read with
``allow_pickle=False``)."""
LEGACY_NORMALIZATION_SUFFIX = "_vecnormalize.pkl"
"""Where earlier versions kept the statistics: SB3's pickled ``VecNormalize``, which is never
unpickled here (``python -m agents.train.convert_statistics`` converts one after checking that it
holds nothing else)."""


def normalization_path(model_path: str | Path) -> Path:
    """Where the observation statistics of the model saved at ``model_path`` live."""
    model_path = Path(model_path)
    return model_path.with_name(model_path.stem + NORMALIZATION_SUFFIX)


def legacy_normalization_path(model_path: str | Path) -> Path:
    """Where earlier versions kept the statistics of ``model_path`` (a pickle)."""
    model_path = Path(model_path)
    return model_path.with_name(model_path.stem + LEGACY_NORMALIZATION_SUFFIX)


@dataclass
class ObservationStatistics:
    """SB3 ``VecNormalize``'s running statistics as data: the observations' and the
    discounted returns' mean, variance and count (``RunningMeanStd``), and its settings.

    :meth:`normalize_obs` is ``VecNormalize.normalize_obs``: ``clip((o - mean) / sqrt(var +
    epsilon), -clip_obs, clip_obs)`` as float32 when ``norm_obs``."""

    observation_mean: np.ndarray
    observation_var: np.ndarray
    observation_count: float
    return_mean: float
    return_var: float
    return_count: float
    clip_obs: float
    clip_reward: float
    gamma: float
    epsilon: float
    norm_obs: bool
    norm_reward: bool

    SCALARS = (
        "observation_count",
        "return_mean",
        "return_var",
        "return_count",
        "clip_obs",
        "clip_reward",
        "gamma",
        "epsilon",
    )

    @classmethod
    def of(cls, normalization: Any) -> ObservationStatistics:
        """The statistics of a live ``VecNormalize`` (observations of a ``Box`` space)."""
        if isinstance(normalization.obs_rms, dict):
            raise ValueError("observation statistics of a Dict space are not supported")
        return cls(
            observation_mean=np.array(normalization.obs_rms.mean, dtype=np.float64),
            observation_var=np.array(normalization.obs_rms.var, dtype=np.float64),
            observation_count=float(normalization.obs_rms.count),
            return_mean=float(normalization.ret_rms.mean),
            return_var=float(normalization.ret_rms.var),
            return_count=float(normalization.ret_rms.count),
            clip_obs=float(normalization.clip_obs),
            clip_reward=float(normalization.clip_reward),
            gamma=float(normalization.gamma),
            epsilon=float(normalization.epsilon),
            norm_obs=bool(normalization.norm_obs),
            norm_reward=bool(normalization.norm_reward),
        )

    def to_bytes(self) -> bytes:
        """The statistics as an ``.npz`` archive of plain arrays."""
        buffer = io.BytesIO()
        arrays: dict[str, Any] = {
            field.name: np.asarray(getattr(self, field.name)) for field in fields(self)
        }
        np.savez(buffer, **arrays)
        return buffer.getvalue()

    @classmethod
    def read(cls, path: str | Path) -> ObservationStatistics:
        """The statistics saved at ``path`` (``allow_pickle=False``), or ``ValueError`` naming
        the file when it is not exactly these arrays, finite, with variances >= 0."""
        names = [field.name for field in fields(cls)]
        try:
            with np.load(path, allow_pickle=False) as archive:
                arrays = {name: archive[name] for name in archive.files}
        except Exception as error:  # a damaged or foreign file
            raise ValueError(
                f"observation statistics {path} are not a readable .npz ({_one_line(error)})"
            ) from None
        problem = None
        if sorted(arrays) != sorted(names):
            problem = f"arrays {sorted(arrays)}, expected {sorted(names)}"
        else:
            mean, var = arrays["observation_mean"], arrays["observation_var"]
            numbers = [arrays[name] for name in names if name not in ("norm_obs", "norm_reward")]
            if mean.ndim != 1 or var.shape != mean.shape:
                problem = f"observation mean {mean.shape} and variance {var.shape}"
            elif any(
                arrays[name].shape != () for name in (*cls.SCALARS, "norm_obs", "norm_reward")
            ):
                problem = "a setting that is not a single value"
            elif any(
                array.dtype.kind != "f" or not np.all(np.isfinite(array)) for array in numbers
            ):
                problem = "a value that is not a finite float"
            elif np.any(var < 0) or arrays["return_var"] < 0:
                problem = "a negative variance"
            elif any(arrays[name].dtype != np.bool_ for name in ("norm_obs", "norm_reward")):
                problem = "norm_obs or norm_reward not a boolean"
        if problem is not None:
            raise ValueError(
                f"observation statistics {path} are not VecNormalize statistics ({problem})"
            )
        return cls(
            observation_mean=arrays["observation_mean"].astype(np.float64),
            observation_var=arrays["observation_var"].astype(np.float64),
            norm_obs=bool(arrays["norm_obs"]),
            norm_reward=bool(arrays["norm_reward"]),
            **{name: float(arrays[name]) for name in cls.SCALARS},
        )

    def normalize_obs(self, observation: np.ndarray) -> np.ndarray:
        """``VecNormalize.normalize_obs`` with these statistics."""
        if not self.norm_obs:
            return observation
        normalized = (observation - self.observation_mean) / np.sqrt(
            self.observation_var + self.epsilon
        )
        return np.clip(normalized, -self.clip_obs, self.clip_obs).astype(np.float32)

    def restore(self, venv: Any) -> Any:
        """A ``VecNormalize`` around ``venv`` holding these statistics (to train on)."""
        vec_env = training_module("stable_baselines3.common.vec_env")
        normalization = vec_env.VecNormalize(
            venv,
            norm_obs=self.norm_obs,
            norm_reward=self.norm_reward,
            clip_obs=self.clip_obs,
            clip_reward=self.clip_reward,
            gamma=self.gamma,
            epsilon=self.epsilon,
        )
        if normalization.obs_rms.mean.shape != self.observation_mean.shape:
            raise ValueError(
                f"observation statistics of shape {self.observation_mean.shape} cannot "
                f"normalise observations of shape {normalization.obs_rms.mean.shape}"
            )
        normalization.obs_rms.mean = self.observation_mean.copy()
        normalization.obs_rms.var = self.observation_var.copy()
        normalization.obs_rms.count = self.observation_count
        normalization.ret_rms.mean = np.float64(self.return_mean)
        normalization.ret_rms.var = np.float64(self.return_var)
        normalization.ret_rms.count = self.return_count
        return normalization


GreedyActor = Callable[[np.ndarray, "np.ndarray | None"], np.ndarray]
"""Observations (and action masks, or ``None``) -> the model's deterministic actions."""


def greedy_actor(model: Any) -> GreedyActor | None:
    """``model.predict(observation, deterministic=True, [action_masks])``'s actions, computed
    without Stable-Baselines3's distribution objects, or ``None`` for a model it does not cover.

    Covered, over ``Box`` observations: PPO and MaskablePPO policies of the actor-critic family
    whose action distribution is categorical (``Discrete``, masked or not) or Bernoulli
    (``MultiBinary``), and DQN. The same modules run in the same order on the same tensors
    (features, actor latent, logits; Q-values for DQN), and the mode is taken as the
    distribution takes it (torch's ``logits_to_probs`` of the normalised logits, masked ones
    set to sb3-contrib's -1e8, then the argmax; ``round(sigmoid)`` for Bernoulli), so the
    actions are SB3's bit for bit (``tests/test_greedy_actor.py``). Building and validating the
    distribution object, and finding the device at every call, were two thirds of a batched
    ``predict``'s time. Recurrent policies, and any other class whose ``get_distribution`` is
    not the one read here, are not covered.
    """
    import torch
    from stable_baselines3.common.distributions import (
        BernoulliDistribution,
        CategoricalDistribution,
    )
    from stable_baselines3.common.policies import ActorCriticPolicy, BaseModel
    from stable_baselines3.dqn.policies import DQNPolicy
    from torch.distributions.utils import logits_to_probs

    policy: Any = getattr(model, "policy", None)
    kind = type(policy)
    if not isinstance(getattr(policy, "observation_space", None), gym.spaces.Box):
        return None
    if issubclass(kind, DQNPolicy) and kind._predict is DQNPolicy._predict:

        def q_values(obs: Any, masks: np.ndarray | None) -> Any:
            return policy._predict(obs, deterministic=True)

        return _greedy(policy, q_values, torch)
    families: dict[type, Any] = {ActorCriticPolicy: ActorCriticPolicy.get_distribution}
    masked_distribution: type | None = None
    try:
        from sb3_contrib.common.maskable.distributions import MaskableCategoricalDistribution
        from sb3_contrib.common.maskable.policies import MaskableActorCriticPolicy

        families[MaskableActorCriticPolicy] = MaskableActorCriticPolicy.get_distribution
        masked_distribution = MaskableCategoricalDistribution
    except ImportError:  # sb3-contrib not installed: SB3's policies only
        pass
    if not issubclass(kind, tuple(families)) or getattr(kind, "get_distribution", None) not in set(
        families.values()
    ):
        return None
    distribution = type(policy.action_dist)
    categorical = distribution in (CategoricalDistribution, masked_distribution)
    if not (categorical or distribution is BernoulliDistribution):
        return None

    def mode(obs: Any, masks: np.ndarray | None) -> Any:
        features = BaseModel.extract_features(policy, obs, policy.pi_features_extractor)
        logits = policy.action_net(policy.mlp_extractor.forward_actor(features))
        if not categorical:
            return torch.round(logits_to_probs(logits, is_binary=True))
        if masks is not None:
            allowed = torch.as_tensor(masks, dtype=torch.bool).reshape(logits.shape)
            logits = torch.where(allowed, logits, torch.tensor(-1e8, dtype=logits.dtype))
        normalized = logits - logits.logsumexp(dim=-1, keepdim=True)
        return torch.argmax(logits_to_probs(normalized), dim=1)

    return _greedy(policy, mode, torch)


def _greedy(policy: Any, actions_of: Callable[..., Any], torch: ModuleType) -> GreedyActor:
    """What ``policy.predict`` does around its ``_predict`` (evaluation mode, the observation
    as a tensor on the policy's device, the actions reshaped to the action space, a single
    observation unbatched), with ``actions_of(obs_tensor, masks)`` in its place. The device is
    read once (SB3 reads it from the parameters at every call)."""
    from stable_baselines3.common.utils import is_vectorized_observation

    device = policy.device
    space = policy.observation_space

    def act(observation: np.ndarray, masks: np.ndarray | None) -> np.ndarray:
        if policy.training:
            policy.set_training_mode(False)
        observation = np.asarray(observation)
        vectorized = is_vectorized_observation(observation, space)
        obs = torch.as_tensor(observation.reshape((-1, *space.shape)), device=device)
        with torch.no_grad():
            chosen = actions_of(obs, masks)
        actions = chosen.cpu().numpy().reshape((-1, *policy.action_space.shape))
        return actions if vectorized else actions.squeeze(axis=0)

    return act


class NormalizedModel:
    """A Stable-Baselines3 model that reads observations through ``VecNormalize`` statistics
    (``predict`` never updates them).

    Args:
        model: the loaded model.
        normalization: :class:`ObservationStatistics`, or a live ``VecNormalize``.
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
        self.greedy = greedy_actor(model)
        """:func:`greedy_actor` of the model (``None`` where SB3's ``predict`` answers)."""

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
        action_masks: np.ndarray | None = None,
    ) -> tuple[np.ndarray, Any]:
        """The model's ``predict`` on normalised observations (``action_masks`` is passed on
        when given, for sb3-contrib's ``MaskablePPO``); its deterministic actions by
        :attr:`greedy` where it covers the model."""
        normalized = self.normalization.normalize_obs(np.asarray(observation, dtype=np.float32))
        if deterministic and state is None and self.greedy is not None:
            return self.greedy(normalized, action_masks), state
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
    (:func:`require_model_fits`). Nothing the files carry is unpickled: the zip is loaded with
    :func:`safe_load_objects` as SB3's ``custom_objects`` (its tensors SB3 reads with
    ``torch.load(weights_only=True)``), the statistics are :class:`ObservationStatistics`,
    and a legacy pickled statistics file is refused. The model returned is for acting (its
    training state is the constructor's). A damaged or foreign model or statistics file, or
    statistics of another env's observations, raises one ``ValueError`` line naming it.
    """
    if observation_space is not None and action_space is not None:
        require_model_fits(path, observation_space, action_space, env_id)
    record = read_model_record(path)
    algorithm = infer_sb3_algorithm(path)
    objects = safe_load_objects(path, record, algorithm, observation_space, action_space)
    statistics = normalization_path(path)
    legacy = legacy_normalization_path(path)
    if not statistics.is_file() and legacy.is_file():
        raise ValueError(
            f"observation statistics {legacy} (beside the model) are a pickle, which is not "
            f"loaded (it could run code); convert them once with: python -m "
            f"agents.train.convert_statistics {legacy}"
        )
    normalization = ObservationStatistics.read(statistics) if statistics.is_file() else None
    if normalization is not None and normalization.observation_mean.shape != tuple(
        objects["observation_space"].shape
    ):
        raise ValueError(
            f"observation statistics {statistics} (beside the model) are of observations of "
            f"shape {normalization.observation_mean.shape}, the model's are "
            f"{tuple(objects['observation_space'].shape)}: statistics of another env"
        )
    try:
        model = algorithm.load(path, env=env, device="cpu", custom_objects=objects)
    except Exception as error:  # whatever a damaged file makes SB3 or torch raise
        raise ValueError(
            f"{path} is not a readable Stable-Baselines3 model ({_one_line(error)})"
        ) from None
    if normalization is None:
        return model
    return NormalizedModel(model, normalization)


def env_id_of(env: Any) -> str:
    """The id of ``env``, a Gymnasium env of this package (by its spec, else by its class) or
    a PettingZoo parallel env of it (by its ``metadata["name"]``, the module of its id);
    ``ValueError`` for any other env."""
    if callable(getattr(env, "observation_space", None)):  # a PettingZoo env
        name = env.metadata.get("name")
        for env_id, module in registry.PETTINGZOO_ENV_IDS.items():
            if module.rpartition(".")[2] == name:
                return env_id
    else:
        spec = getattr(env, "spec", None)
        if spec is not None and spec.id in registry.ENV_IDS:
            return spec.id
        unwrapped = type(env.unwrapped)
        for env_id, entry_point in registry.ENV_IDS.items():
            if entry_point == f"{unwrapped.__module__}:{unwrapped.__qualname__}":
                return env_id
    raise ValueError(
        f"env: {env!r} is not an env of etsc-envs (a Gymnasium env of {sorted(registry.ENV_IDS)} "
        f"or a PettingZoo parallel env of {sorted(registry.PETTINGZOO_ENV_IDS)})"
    )

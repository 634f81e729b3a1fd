"""Training configuration: the YAML keys, their validation and the algorithm names.

A config is a YAML mapping with these keys (the optional ones show their default):

* ``env_id`` — a registered Gymnasium id, e.g. ``etsc/AttitudeTracking-v0``, or a PettingZoo id
  of :data:`etsc_envs.PETTINGZOO_ENV_IDS`, trained with parameter sharing (one policy for all
  agents, each agent one sub-environment; ``n_envs`` counts copies of the whole system);
* ``env_kwargs: {}`` — passed to ``gym.make``; ``randomize`` defaults to ``true`` in training so
  that the agent does not overfit one trajectory;
* ``algorithm`` — one of :data:`ALGORITHMS` (``PPO``, ``A2C``, ``DQN``, and sb3-contrib's
  ``MaskablePPO``, which needs ``decisions``);
* ``policy`` — an SB3 policy alias of that algorithm, e.g. ``MlpPolicy``;
* ``hyperparameters: {}`` — keyword arguments of the algorithm's constructor, each of the
  kind of its default (a number, true/false); the counts of
  :data:`POSITIVE_COUNT_HYPERPARAMETERS` are integers >= 1;
* ``total_timesteps`` — environment steps to train for, summed over the vectorised envs;
* ``n_envs: 1`` — environments stepped together (in the id's native vector env, one compiled
  call per step);
* ``seed: 0`` — seeds the algorithm and the environments (``null`` leaves them unseeded);
  environment ``j`` is seeded ``seed + j``, and a seed range that reaches into the protocol's
  validation or test seeds is refused (:func:`etsc_envs.protocol.require_training_seeds`);
* ``out_dir`` — where the model, the resolved config and the summary are written (checked
  to be a writable folder, or one that can be made, before anything runs);
* ``normalize_observations: true`` — train on observations standardised by running
  statistics (SB3's ``VecNormalize``), saved beside the model for evaluation;
* ``observation_clip: 10.0`` — normalised observations are clipped to ± this (SB3's
  ``clip_obs``). It bounds the longest hold the policy can tell apart, at the transmission
  clock's running mean plus ``observation_clip`` standard deviations; the statistics start
  from the short holds of a random policy, so the shipped configs raise it out of the way;
* ``normalize_rewards: false`` — also scale rewards by a running estimate of the return;
* ``checkpoint_every: 0`` — save the model (and the statistics) every that many steps into
  ``out_dir/checkpoints``, from which ``--resume`` continues; 0 saves no checkpoints;
* ``evaluation_every: 0`` — every that many steps, run the current policy on the protocol's
  validation scenarios (the paper's trigger once, at the start) and log both (TensorBoard and
  ``out_dir/evaluations.json``), keeping the best trained model by mean validation return in
  ``out_dir/best_model.zip`` (:mod:`agents.train.kept_checkpoint`); 0 never evaluates;
* ``evaluation_scenarios: 16`` — validation scenarios per evaluation (the first of the set);
* ``evaluation_env_kwargs: {}`` — env kwargs of that evaluation on top of the training ones
  (the set's ``randomize`` replaces theirs), e.g. a shorter ``horizon_s``;
* ``tensorboard: true`` — write TensorBoard logs into ``out_dir/tensorboard``;
* ``init_from: null`` — a model saved by an earlier run (``model.zip`` or a checkpoint) to
  start from: its weights and, when saved beside it, its observation and return statistics
  (a curriculum, e.g. short episodes first, then the paper's horizon or another λ); it must
  have been trained for the observation and action spaces of ``env_id``; null starts from a
  random policy;
* ``decisions: null`` — train self-triggered decisions instead of the per-instant bit: the
  decision set's own JSON form (:mod:`etsc_envs.decisions.actions`: ``shield_multiple`` and
  ``actions``, a list of ``{kind: hold, instants: N}`` and ``{kind: trigger, rule: ...,
  point: {...}, cap: N, send_first: ...}``; ``env_id`` is the config's), trained from a random
  policy through :class:`etsc_envs.decisions.SelfTriggeredWrapper` (its ``gamma`` is
  ``hyperparameters.gamma``) on a ``DummyVecEnv`` of wrapped envs (for a PettingZoo id, of
  :class:`etsc_envs.decisions.FollowerDecisionEnv`). PPO, A2C, MaskablePPO and DQN then
  discount by elapsed instants (:mod:`agents.train.elapsed_discount`; DQN's target is
  ``r + gamma ** n * max Q'``); the models are saved with their
  decision set beside them, so that ``sb3:`` deploys them as transmit/hold policies;
* ``torch_threads: 1`` — threads PyTorch may use. The policies are small MLPs, whose
  batches of a few dozen rows run fastest on one thread; more threads contend with the
  vector env's stepping threads (twice the steps per second with one thread, measured on the
  2-core machine).

Every problem raises a ``ValueError`` naming the key and what it allows; a key of
:data:`REMOVED_KEYS` is refused with the reason it went.
"""

from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import inspect
import math
import os
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import yaml
from sb3_contrib import MaskablePPO
from stable_baselines3 import A2C, DQN, PPO
from stable_baselines3.common.base_class import BaseAlgorithm

import etsc_envs
from etsc_envs.core.files import require_writable_folder
from etsc_envs.decisions import DecisionSet, make_decision_env
from etsc_envs.evaluation.policy_specs import require_env_id
from etsc_envs.protocol import require_training_seeds
from etsc_envs.sb3_models import require_model_fits

ALGORITHMS: dict[str, type[BaseAlgorithm]] = {
    "PPO": PPO,
    "A2C": A2C,
    "DQN": DQN,
    "MaskablePPO": MaskablePPO,
}
"""Algorithm name in a config → Stable-Baselines3 class."""

TRAINING_ENV_DEFAULTS: dict[str, Any] = {"randomize": True}
"""Env kwargs that training sets unless the config's ``env_kwargs`` says otherwise."""

REQUIRED_KEYS = ("env_id", "algorithm", "policy", "total_timesteps", "out_dir")
OPTIONAL_DEFAULTS: dict[str, Any] = {
    "env_kwargs": {},
    "hyperparameters": {},
    "n_envs": 1,
    "seed": 0,
    "normalize_observations": True,
    "normalize_rewards": False,
    "observation_clip": 10.0,
    "checkpoint_every": 0,
    "evaluation_every": 0,
    "evaluation_scenarios": 16,
    "evaluation_env_kwargs": {},
    "tensorboard": True,
    "torch_threads": 1,
    "init_from": None,
    "decisions": None,
}

CONFIG_SET_ARGUMENTS = ("policy", "env", "seed")
"""Constructor arguments that come from the config's own keys, not from ``hyperparameters``."""

REMOVED_KEYS = {
    "start_from": "runs start from a random policy or from 'init_from'; the imitation and "
    "pinned starts are documented in docs/results.md and the git history",
}
"""Keys that configs no longer take → why (refused in one line rather than ignored)."""


@dataclasses.dataclass(frozen=True)
class TrainConfig:
    """A validated training config; see the module docstring for the meaning of each field."""

    env_id: str
    env_kwargs: dict[str, Any]
    algorithm: str
    policy: str
    hyperparameters: dict[str, Any]
    total_timesteps: int
    n_envs: int
    seed: int | None
    out_dir: str
    normalize_observations: bool
    normalize_rewards: bool
    observation_clip: float
    checkpoint_every: int
    evaluation_every: int
    evaluation_scenarios: int
    evaluation_env_kwargs: dict[str, Any]
    tensorboard: bool
    torch_threads: int
    init_from: str | None
    decisions: dict[str, Any] | None

    @property
    def algorithm_class(self) -> type[BaseAlgorithm]:
        """The Stable-Baselines3 class named by :attr:`algorithm`."""
        return ALGORITHMS[self.algorithm]

    def as_dict(self) -> dict[str, Any]:
        """The config as plain YAML-serialisable data, in the order of the fields."""
        return dataclasses.asdict(self)


def load_config(path: str | Path, overrides: Mapping[str, Any] | None = None) -> TrainConfig:
    """Read a YAML config, replace the keys given in ``overrides`` and validate the result."""
    with open(path, encoding="utf-8") as stream:
        raw = yaml.safe_load(stream)
    if not isinstance(raw, dict):
        raise ValueError(f"{path}: a training config must be a YAML mapping of keys to values")
    return config_from_dict({**raw, **(overrides or {})})


def config_from_dict(raw: Mapping[str, Any]) -> TrainConfig:
    """Validate a config mapping and fill in the optional keys' defaults."""
    for key, reason in REMOVED_KEYS.items():
        if key in raw:
            raise ValueError(f"config key {key!r} was removed: {reason}")
    _check_key_set(raw)
    values = {**OPTIONAL_DEFAULTS, **raw}
    algorithm = _check_algorithm(values["algorithm"])
    seed = _check_seed(values["seed"])
    n_envs = _check_positive_int("n_envs", values["n_envs"])
    if seed is not None:
        require_training_seeds(seed, n_envs, "config key 'seed'")
    env_id = _check_env_id(values["env_id"])
    env_kwargs = {**TRAINING_ENV_DEFAULTS, **_check_mapping("env_kwargs", values["env_kwargs"])}
    decisions = _check_decisions(values, algorithm, env_id, env_kwargs)
    _check_algorithm_fits_env(algorithm, env_id, env_kwargs, decisions)
    hyperparameters = _check_buffer_fits(
        _check_hyperparameters(values["hyperparameters"], algorithm), n_envs
    )
    total_timesteps = _check_positive_int("total_timesteps", values["total_timesteps"])
    _check_learning_starts(hyperparameters, total_timesteps)
    return TrainConfig(
        env_id=env_id,
        env_kwargs=env_kwargs,
        algorithm=algorithm,
        policy=_check_policy(values["policy"], algorithm),
        hyperparameters=hyperparameters,
        total_timesteps=total_timesteps,
        n_envs=n_envs,
        seed=seed,
        out_dir=_check_out_dir(values["out_dir"]),
        normalize_observations=_check_bool(
            "normalize_observations", values["normalize_observations"]
        ),
        normalize_rewards=_check_bool("normalize_rewards", values["normalize_rewards"]),
        observation_clip=_check_positive_float("observation_clip", values["observation_clip"]),
        checkpoint_every=_check_non_negative_int("checkpoint_every", values["checkpoint_every"]),
        evaluation_every=_check_non_negative_int("evaluation_every", values["evaluation_every"]),
        evaluation_scenarios=_check_positive_int(
            "evaluation_scenarios", values["evaluation_scenarios"]
        ),
        evaluation_env_kwargs=_check_mapping(
            "evaluation_env_kwargs", values["evaluation_env_kwargs"]
        ),
        tensorboard=_check_tensorboard(values["tensorboard"]),
        torch_threads=_check_positive_int("torch_threads", values["torch_threads"]),
        init_from=_check_init_from(values["init_from"], env_id, env_kwargs, decisions),
        decisions=decisions,
    )


def _check_learning_starts(hyperparameters: dict[str, Any], total_timesteps: int) -> None:
    """``ValueError`` if an off-policy learner would start learning only after the run ends:
    it would never update its network, and an untrained network is never kept
    (:mod:`agents.train.kept_checkpoint`)."""
    learning_starts = hyperparameters.get("learning_starts")
    if isinstance(learning_starts, int) and learning_starts >= total_timesteps:
        raise ValueError(
            f"config key 'hyperparameters.learning_starts' must be below total_timesteps "
            f"({total_timesteps}), got {learning_starts}: the run would never train"
        )


def require_key_set(
    raw: Mapping[str, Any], required: tuple[str, ...], optional: Iterable[str], kind: str
) -> None:
    """``ValueError`` naming the unknown and the missing keys of a ``kind`` mapping (a training
    config, a sweep)."""
    allowed = (*required, *optional)
    unknown = sorted(str(key) for key in raw if key not in allowed)
    if unknown:
        raise ValueError(f"unknown {kind} key(s) {unknown}; allowed keys: {list(allowed)}")
    missing = [key for key in required if key not in raw]
    if missing:
        raise ValueError(f"missing {kind} key(s) {missing}; required keys: {list(required)}")


def _check_key_set(raw: Mapping[str, Any]) -> None:
    require_key_set(raw, REQUIRED_KEYS, OPTIONAL_DEFAULTS, "config")


def _check_env_id(env_id: Any) -> str:
    if not isinstance(env_id, str) or not env_id:
        raise ValueError(f"config key 'env_id' must be a Gymnasium id string, got {env_id!r}")
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        return env_id
    module, _, bare_id = env_id.rpartition(":")
    if module:
        importlib.import_module(module)
    require_env_id(bare_id, "config key 'env_id'")
    return env_id


def _check_algorithm(name: Any) -> str:
    if name not in ALGORITHMS:
        raise ValueError(f"config key 'algorithm': {name!r} is not one of {list(ALGORITHMS)}")
    return name


def _check_decisions(
    values: Mapping[str, Any], algorithm: str, env_id: str, env_kwargs: dict[str, Any]
) -> dict[str, Any] | None:
    """``values["decisions"]`` (null, or a decision set's JSON form for ``env_id``:
    :meth:`~etsc_envs.decisions.DecisionSet.from_json`) as that form, once a decision env of
    ``env_id`` built with ``env_kwargs`` has taken it."""
    if values["decisions"] is None:
        if algorithm == "MaskablePPO":
            raise ValueError("config key 'algorithm': MaskablePPO needs the key 'decisions'")
        return None
    block = _check_mapping("decisions", values["decisions"])
    if "actions" not in block:
        raise ValueError(
            f"config key 'decisions' must be the decision set's own form {{shield_multiple: ..., "
            f"actions: [{{kind: hold, instants: N}}, {{kind: trigger, rule: ..., point: {{...}}, "
            f"cap: N, send_first: ...}}, ...]}}, got the keys {sorted(block)}"
        )
    try:
        decisions = DecisionSet.from_json(block, env_id)
        make_decision_env(env_id, env_kwargs, decisions).close()
    except (TypeError, ValueError) as error:
        raise ValueError(f"config key 'decisions': {' '.join(str(error).split())}") from None
    return decisions.to_json()


def _check_algorithm_fits_env(
    algorithm: str, env_id: str, env_kwargs: dict[str, Any], decisions: dict[str, Any] | None
) -> None:
    """DQN picks one of finitely many actions: it needs a ``Discrete`` action space."""
    if algorithm != "DQN" or decisions is not None:
        return
    _, action_space = policy_spaces(env_id, env_kwargs)
    if not isinstance(action_space, gym.spaces.Discrete):
        raise ValueError(
            f"config key 'algorithm': DQN needs a Discrete action space, and {env_id} acts "
            f"with {action_space}; use PPO or A2C"
        )


def policy_spaces(
    env_id: str, env_kwargs: dict[str, Any], decisions: dict[str, Any] | None = None
) -> tuple[gym.Space, gym.Space]:
    """The observation and action spaces the trained policy acts in (one agent's, for a
    PettingZoo id; the decisions' with ``decisions``), from one env built with
    ``env_kwargs``."""
    if decisions is not None:
        env = make_decision_env(env_id, env_kwargs, decisions)
        spaces = env.observation_space, env.action_space
    elif env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        env = etsc_envs.make_parallel(env_id, **env_kwargs)
        agent = env.possible_agents[0]
        spaces = env.observation_space(agent), env.action_space(agent)
    else:
        env = gym.make(env_id, **env_kwargs)
        spaces = env.observation_space, env.action_space
    env.close()
    return spaces


def _check_policy(policy: Any, algorithm: str) -> str:
    aliases = list(ALGORITHMS[algorithm].policy_aliases)
    if policy not in aliases:
        raise ValueError(
            f"config key 'policy': {policy!r} is not a {algorithm} policy; allowed: {aliases}"
        )
    return policy


def _check_mapping(key: str, value: Any) -> dict[str, Any]:
    if not isinstance(value, dict) or not all(isinstance(name, str) for name in value):
        raise ValueError(f"config key {key!r} must be a mapping of names to values, got {value!r}")
    return dict(value)


def _check_hyperparameters(value: Any, algorithm: str) -> dict[str, Any]:
    hyperparameters = _check_mapping("hyperparameters", value)
    set_elsewhere = sorted(set(hyperparameters) & set(CONFIG_SET_ARGUMENTS))
    if set_elsewhere:
        raise ValueError(
            f"config key 'hyperparameters': {set_elsewhere} come from the config's top-level "
            f"keys ('policy', 'seed') and the env_id, not from hyperparameters"
        )
    allowed = _constructor_arguments(ALGORITHMS[algorithm])
    unknown = sorted(set(hyperparameters) - set(allowed))
    if unknown:
        raise ValueError(
            f"config key 'hyperparameters': {unknown} are not {algorithm} arguments; "
            f"allowed: {allowed}"
        )
    defaults = _constructor_defaults(ALGORITHMS[algorithm])
    for name, entry in hyperparameters.items():
        _reject_numeric_string(f"hyperparameters.{name}", entry)
        _check_hyperparameter(name, entry, defaults.get(name))
    return hyperparameters


MIN_SAMPLE_BYTES = 64
"""The least memory one stored sample takes in SB3's rollout or replay buffer: the observation
(no id's has fewer than 10 float32 numbers), the action, and the reward, value, return, log
probability, advantage and episode start of the step."""


def machine_memory_bytes() -> int:
    """The physical memory of this machine."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def _check_buffer_fits(hyperparameters: dict[str, Any], n_envs: int) -> dict[str, Any]:
    """``hyperparameters`` unless the buffer they ask for (``n_steps`` per env times
    ``n_envs``, or ``buffer_size``) needs more than half of this machine's memory at
    :data:`MIN_SAMPLE_BYTES` a sample (``ValueError`` naming the key, before any allocation)."""
    available = machine_memory_bytes() // 2
    for name, samples in (
        ("n_steps", hyperparameters.get("n_steps", 0) * n_envs),
        ("buffer_size", hyperparameters.get("buffer_size", 0)),
    ):
        if samples * MIN_SAMPLE_BYTES > available:
            raise ValueError(
                f"config key 'hyperparameters.{name}' asks for a buffer of {samples:.3g} samples, "
                f"at least {samples * MIN_SAMPLE_BYTES / 2**30:.3g} GiB; this machine has "
                f"{available / 2**30:.3g} GiB for it (half its memory)"
            )
    return hyperparameters


POSITIVE_COUNT_HYPERPARAMETERS = (
    "n_steps",
    "batch_size",
    "n_epochs",
    "buffer_size",
    "target_update_interval",
    "stats_window_size",
)
"""Hyperparameters that count steps, samples or passes: integers >= 1 (0 makes SB3 fail with
an assertion or loop without collecting anything)."""


def _constructor_defaults(algorithm_class: type[BaseAlgorithm]) -> dict[str, Any]:
    parameters = inspect.signature(algorithm_class.__init__).parameters
    return {
        name: parameter.default
        for name, parameter in parameters.items()
        if parameter.default is not inspect.Parameter.empty
    }


def _check_hyperparameter(name: str, value: Any, default: Any) -> None:
    """``ValueError`` when ``value`` cannot be what the algorithm's constructor expects: a count
    of :data:`POSITIVE_COUNT_HYPERPARAMETERS` below 1, or a value of another kind than the
    default's (a number for a number, true/false for a flag)."""
    key = f"hyperparameters.{name}"
    if name in POSITIVE_COUNT_HYPERPARAMETERS and (
        isinstance(value, bool) or not isinstance(value, int) or value < 1
    ):
        raise ValueError(f"config key {key!r} must be an integer >= 1, got {value!r}")
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise ValueError(f"config key {key!r} must be true or false, got {value!r}")
    elif isinstance(default, int | float) and (
        isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value)
    ):
        raise ValueError(f"config key {key!r} must be a finite number, got {value!r}")
    if name in HYPERPARAMETER_RANGES and isinstance(value, int | float):
        inside, allows = HYPERPARAMETER_RANGES[name]
        if not inside(value):
            raise ValueError(f"config key {key!r} must be {allows}, got {value!r}")


HYPERPARAMETER_RANGES: dict[str, tuple[Callable[[float], bool], str]] = {
    "gamma": (lambda v: 0.0 < v <= 1.0, "in (0, 1]"),
    "gae_lambda": (lambda v: 0.0 < v <= 1.0, "in (0, 1]"),
    "learning_rate": (lambda v: v > 0.0, "> 0"),
    "clip_range": (lambda v: v > 0.0, "> 0"),
    "max_grad_norm": (lambda v: v > 0.0, "> 0"),
    "ent_coef": (lambda v: v >= 0.0, ">= 0"),
    "vf_coef": (lambda v: v >= 0.0, ">= 0"),
    "tau": (lambda v: 0.0 < v <= 1.0, "in (0, 1]"),
    "exploration_fraction": (lambda v: 0.0 <= v <= 1.0, "in [0, 1]"),
    "exploration_initial_eps": (lambda v: 0.0 <= v <= 1.0, "in [0, 1]"),
    "exploration_final_eps": (lambda v: 0.0 <= v <= 1.0, "in [0, 1]"),
}
"""The algorithms' hyperparameters that have a range: the discount and GAE's lambda (a
discount above 1 sums returns that grow without bound), rates and coefficients."""


def _constructor_arguments(algorithm_class: type[BaseAlgorithm]) -> list[str]:
    """Keyword arguments of the algorithm's constructor that a config may set."""
    parameters = inspect.signature(algorithm_class.__init__).parameters
    return [
        name
        for name in parameters
        if name != "self" and not name.startswith("_") and name not in CONFIG_SET_ARGUMENTS
    ]


def _reject_numeric_string(key: str, value: Any) -> None:
    """PyYAML reads ``3e-4`` as a string (it needs ``3.0e-4``); catch that before SB3 does."""
    if not isinstance(value, str):
        return
    try:
        number = float(value)
    except ValueError:
        return
    raise ValueError(
        f"config key {key!r}: {value!r} was read as a string; write a YAML number such as "
        f"{number!r} (PyYAML needs a dot and a signed exponent, e.g. 3.0e-4)"
    )


def _check_positive_float(key: str, value: Any) -> float:
    _reject_numeric_string(key, value)
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        raise ValueError(f"config key '{key}' must be a positive number, got {value!r}")
    return float(value)


def _check_positive_int(key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"config key {key!r} must be a positive integer, got {value!r}")
    return value


def _check_seed(value: Any) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"config key 'seed' must be a non-negative integer or null, got {value!r}")
    return value


def _check_out_dir(value: Any) -> str:
    if not isinstance(value, str | Path) or not str(value):
        raise ValueError(f"config key 'out_dir' must be a directory path, got {value!r}")
    require_writable_folder(value, "config key 'out_dir'")
    return str(value)


def _check_bool(key: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"config key {key!r} must be true or false, got {value!r}")
    return value


def _check_non_negative_int(key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"config key {key!r} must be an integer >= 0, got {value!r}")
    return value


def _check_init_from(
    value: Any, env_id: str, env_kwargs: dict[str, Any], decisions: dict[str, Any] | None
) -> str | None:
    """``value`` if it is null or a saved model that can act in ``env_id``'s spaces."""
    if value is None:
        return None
    if not isinstance(value, str) or not Path(value).is_file():
        raise ValueError(
            f"config key 'init_from' must be the path of a saved model (.zip) or null, "
            f"got {value!r}"
        )
    try:
        spaces = policy_spaces(env_id, env_kwargs, decisions)
    except (TypeError, ValueError) as error:
        raise ValueError(f"config key 'env_kwargs': {' '.join(str(error).split())}") from None
    require_model_fits(value, *spaces, env_id, "config key 'init_from':")
    return value


def _check_tensorboard(value: Any) -> bool:
    enabled = _check_bool("tensorboard", value)
    if enabled and importlib.util.find_spec("tensorboard") is None:
        raise ValueError(
            "config key 'tensorboard': the tensorboard package is not installed "
            "(pip install -e '.[train]'), or set tensorboard: false"
        )
    return enabled

"""Sweep configuration: the YAML keys of ``configs/sweeps/*.yaml``, their validation, and how a
trial's values become one training config. No Ray here: this module only reads and checks.

A sweep config is a YAML mapping with these keys (the optional ones show their default):

* ``base`` — the training config (``configs/train/*.yaml``, keys in :mod:`agents.train.config`)
  that every trial starts from;
* ``results_dir`` — the sweep's results folder: one subfolder per trial under ``trials/``
  (model, normalisation statistics, resolved config, evaluations), the sweep summary and
  Ray Tune's experiment state under ``tune/``;
* ``learner: train`` — what a trial runs: ``train`` (one ``agents.train`` run, ``base`` a
  training config) or ``search`` (one ``agents.search`` run, ``base`` a search config of
  ``configs/search/``, whose keys ``overrides`` and ``grid`` then set: a front of the learned
  trigger family over ``penalty`` × ``seed``); or ``oracle`` (one clairvoyant-schedule run
  of :mod:`agents.oracle`, ``base`` a config of ``configs/oracle/`` whose ``grid`` runs
  ``scenario`` over a set); a search or oracle sweep is a ``front``;
* ``kind`` — ``front`` (the trials form a reported front, e.g. transmission penalty × seed:
  every trial runs to its end, so neither a scheduler nor a search algorithm is allowed) or
  ``search`` (a hyperparameter search, which may use them);
* ``overrides: {}`` — training-config keys set in every trial;
* ``grid: {}`` — training-config key → list of values; every combination is one trial;
* ``search: {}`` — training-config key → a distribution sampled per trial, one of
  ``{uniform: [low, high]}``, ``{loguniform: [low, high]}``, ``{randint: [low, high]}``
  (``high`` excluded) or ``{choice: [values]}``; search sweeps only;
* ``num_samples: 1`` — trials drawn from ``search`` (each over the whole grid); search only;
* ``scheduler: null`` — ``asha`` stops hopeless trials early (Tune's ``ASHAScheduler`` on
  the training timesteps); search only;
* ``grace_timesteps: null`` — ASHA never stops a trial before this many timesteps (default a
  tenth of ``total_timesteps``);
* ``search_algorithm: null`` — ``optuna`` draws the ``search`` values with Tune's
  ``OptunaSearch`` (then ``grid`` must be empty); search only. Its first trial is the start
  (:attr:`SweepConfig.search_start`: the searched keys' values in ``base`` with
  ``overrides``, each inside its distribution), so the tuned values are compared with the
  values the search started from, and its sampler is seeded (0): a rerun draws the same
  trials while they do not depend on the finished ones (Optuna's start-up trials);
* ``metric: null``, ``mode: null`` — the reported metric (:data:`agents.sweep.results.METRICS`)
  that the scheduler or search algorithm optimises, and ``min`` or ``max``; required with
  either of them. A trial reports to Tune only once it has that metric (the evaluation
  metrics need ``evaluation_every``);
* ``trial_seeds: null`` — a list of training seeds: each trial of a search then trains once
  per seed (its values with ``seed`` set; one after another, in its folder's ``seed=S/``)
  and reports, once every seed has finished, the mean of their scores, so that a value is
  chosen for what it does over several seeds rather than for one seed's luck (learner
  ``train``, kind ``search``; no scheduler, which would compare one seed's partial runs
  with others', and ``seed`` swept nowhere else);
* ``cpus_per_trial: 1`` — CPU cores each trial reserves on the Ray cluster, so a 2-core
  machine runs two trials at a time and a cluster as many as it has cores;
* ``max_concurrent_trials: null`` — at most this many trials at once (null: as many as the
  cores allow).

Keys of ``overrides``, ``grid`` and ``search`` are training-config keys, dotted to reach into
a mapping: ``seed``, ``total_timesteps``, ``env_kwargs.transmission_penalty``,
``hyperparameters.learning_rate``. Paths (``base``, ``results_dir``, the training config's
``init_from``) are relative to the current folder, as in
``agents.train``.

Every problem raises a one-line ``ValueError`` naming the key and what it allows.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import json
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import yaml

from agents.oracle.run import OracleConfig, oracle_config_from_dict
from agents.search.cma_es import SearchConfig
from agents.search.cma_es import config_from_dict as search_config_from_dict
from agents.sweep.results import EVALUATION_METRICS, METRICS, SETTINGS_FILE, TRIALS_DIR
from agents.train.config import (
    OPTIONAL_DEFAULTS,
    REQUIRED_KEYS,
    TrainConfig,
    config_from_dict,
    require_key_set,
)
from etsc_envs.core.files import atomic_write_text

KINDS = ("front", "search")
LEARNERS = ("train", "search", "oracle")
SCHEDULERS = ("asha",)
SEARCH_ALGORITHMS = ("optuna",)
MODES = ("min", "max")
DISTRIBUTIONS = ("uniform", "loguniform", "randint", "choice")

REQUIRED_SWEEP_KEYS = ("base", "results_dir", "kind")
OPTIONAL_SWEEP_DEFAULTS: dict[str, Any] = {
    "overrides": {},
    "grid": {},
    "search": {},
    "num_samples": 1,
    "scheduler": None,
    "grace_timesteps": None,
    "search_algorithm": None,
    "metric": None,
    "mode": None,
    "cpus_per_trial": 1,
    "max_concurrent_trials": None,
    "learner": "train",
    "trial_seeds": None,
}
NESTED_TRAINING_KEYS = ("env_kwargs", "hyperparameters", "evaluation_env_kwargs")
"""Training-config keys whose value is a mapping that a dotted key may reach into."""

TUNE_DIR = "tune"
"""Subfolder of ``results_dir`` that holds Ray Tune's experiment state."""


@dataclasses.dataclass(frozen=True)
class SweepConfig:
    """A validated sweep config; see the module docstring for the meaning of each field.

    ``base`` is the base training config as a mapping (``overrides`` applied, paths made
    absolute), ready for :meth:`trial_config`.
    """

    path: str
    base: dict[str, Any]
    results_dir: str
    kind: str
    learner: str
    grid: dict[str, list[Any]]
    search: dict[str, dict[str, list[Any]]]
    num_samples: int
    scheduler: str | None
    grace_timesteps: int | None
    search_algorithm: str | None
    metric: str | None
    mode: str | None
    cpus_per_trial: float
    max_concurrent_trials: int | None
    trial_seeds: tuple[int, ...] | None = None

    def settings(self) -> dict[str, Any]:
        """Every setting of the sweep (not the path of its YAML), as JSON-ready data."""
        settings = dataclasses.asdict(self)
        del settings["path"]
        return settings

    @property
    def swept_keys(self) -> list[str]:
        """The keys that vary between trials, grid first, in the config's order."""
        return [*self.grid, *self.search]

    @property
    def total_timesteps(self) -> int:
        """The base training length (every trial's, unless swept)."""
        return int(self.base["total_timesteps"])

    @property
    def tune_dir(self) -> Path:
        """Ray Tune's experiment folder."""
        return Path(self.results_dir) / TUNE_DIR

    def grid_points(self) -> list[dict[str, Any]]:
        """Every combination of the grid's values, in the config's order."""
        keys = list(self.grid)
        combinations = itertools.product(*self.grid.values())
        return [dict(zip(keys, values, strict=True)) for values in combinations]

    @property
    def search_start(self) -> dict[str, Any]:
        """The searched keys' values before the search: ``base`` with ``overrides``."""
        return {key: _value_at(self.base, key) for key in self.search}

    def trial_name(self, values: Mapping[str, Any], trial_id: str | None = None) -> str:
        """A trial's folder name: its swept values as ``key=value`` joined by commas (the last
        part of a dotted key, unless two swept keys share it), e.g.
        ``transmission_penalty=0.05,seed=1``; a search trial adds its Tune ``trial_id``
        (sampled values need not differ in their printed digits)."""
        labels = _labels(self.swept_keys)
        parts = [f"{labels[key]}={format_value(values[key])}" for key in self.swept_keys]
        if self.search and trial_id is not None:
            parts.append(f"trial={trial_id}")
        return ",".join(parts) or "trial"

    @property
    def trials_dir(self) -> Path:
        """The folder of the trials' folders."""
        return Path(self.results_dir) / TRIALS_DIR

    def trial_folder(self, name: str) -> Path:
        """Where the trial called ``name`` writes its training outputs."""
        return self.trials_dir / name

    def trial_runs(
        self, values: Mapping[str, Any], folder: str | Path
    ) -> list[tuple[dict[str, Any], Path]]:
        """The training runs of the trial with the swept ``values`` whose folder is ``folder``,
        as (values, folder) pairs: the trial itself, or with ``trial_seeds`` one run per seed
        in ``folder/seed=S``."""
        folder = Path(folder)
        if self.trial_seeds is None:
            return [(dict(values), folder)]
        return [({**values, "seed": seed}, folder / f"seed={seed}") for seed in self.trial_seeds]

    def start_or_continue(self, resume: bool, started: bool, grid_may_grow: bool = False) -> None:
        """Refuse to start over a sweep that has ``started`` (``--resume`` continues it, with
        the settings it started with); record a new sweep's settings in ``sweep_settings.json``.

        A resumed sweep runs the trials it planned when it started, so ``--resume`` with
        changed settings is refused (they would mislabel the trials). The one change allowed,
        where ``grid_may_grow`` (the worker-process path, which runs every unfinished grid
        point; Tune restores the grid it started with), is a grown grid: the same keys, each
        keeping its values and perhaps adding some (more seeds, more penalties). Its finished
        trials keep their names and results; the new points run."""
        path = Path(self.results_dir) / SETTINGS_FILE
        now = json.dumps(self.settings(), indent=2, sort_keys=True) + "\n"
        if not resume:
            if started:
                raise ValueError(
                    f"results_dir {self.results_dir!r} already holds a sweep: continue it with "
                    f"--resume or choose another results_dir"
                )
            atomic_write_text(path, now)
            return
        if not started:
            raise ValueError(f"--resume: no sweep in {self.results_dir!r} to continue")
        if not path.is_file():
            return
        before = json.loads(path.read_text(encoding="utf-8"))
        after = json.loads(now)
        changed = sorted(key for key in {*before, *after} if before.get(key) != after.get(key))
        if changed == ["grid"] and _grown(before["grid"], after["grid"]):
            if grid_may_grow:
                atomic_write_text(path, now)
                return
            raise ValueError(
                "--resume: the sweep's grid grew since it started; Tune restores the grid it "
                "started with, so continue a grown grid with --processes N"
            )
        if changed:
            raise ValueError(
                f"--resume: the sweep's {changed} changed since it started (see {str(path)!r}); "
                f"resume it with the settings it started with, or start another results_dir"
            )

    def trial_mapping(self, values: Mapping[str, Any], out_dir: str | Path) -> dict[str, Any]:
        """The config of the trial with the swept ``values``, as the mapping its YAML holds."""
        raw = copy.deepcopy(self.base)
        for key, value in values.items():
            _assign(raw, key, value)
        if self.learner == "train":
            raw["out_dir"] = str(out_dir)
        return raw

    def trial_config(
        self, values: Mapping[str, Any], out_dir: str | Path
    ) -> TrainConfig | SearchConfig | OracleConfig:
        """The validated config of the trial with the swept ``values``: a training config, a
        search config for ``learner: search``, a clairvoyant-schedule run's for ``oracle``."""
        raw = self.trial_mapping(values, out_dir)
        if self.learner == "search":
            return search_config_from_dict(raw)
        if self.learner == "oracle":
            return oracle_config_from_dict(raw)
        return config_from_dict(raw)


def load_sweep_config(path: str | Path) -> SweepConfig:
    """Read a sweep YAML, validate it and every grid point's training config."""
    with open(path, encoding="utf-8") as stream:
        raw = yaml.safe_load(stream)
    if not isinstance(raw, dict):
        raise ValueError(f"{path}: a sweep config must be a YAML mapping of keys to values")
    return sweep_config_from_dict(raw, str(path))


def sweep_config_from_dict(raw: Mapping[str, Any], path: str = "<sweep>") -> SweepConfig:
    """Validate a sweep config mapping (see the module docstring) and fill in the defaults."""
    _check_key_set(raw)
    values = {**OPTIONAL_SWEEP_DEFAULTS, **raw}
    kind = _check_choice("kind", values["kind"], KINDS)
    learner = _check_choice("learner", values["learner"], LEARNERS)
    if learner != "train" and kind != "front":
        raise ValueError(
            f"sweep key 'kind' must be 'front' with learner {learner!r} (its trials are "
            "searches over a grid, each run to its end)"
        )
    check_key = {
        "train": _check_training_key,
        "search": _check_search_key,
        "oracle": _check_oracle_key,
    }[learner]
    base = _load_base(values["base"])
    overrides = _check_mapping("overrides", values["overrides"])
    for key, value in overrides.items():
        check_key("overrides", key)
        _assign(base, key, value)
    if learner == "train":
        base["out_dir"] = "<trial folder>"
        base["init_from"] = _absolute(base.get("init_from"))
    grid = _check_grid(values["grid"], check_key)
    search = _check_search(values["search"])
    overlap = sorted(set(grid) & set(search))
    if overlap:
        raise ValueError(f"sweep keys {overlap} are in both 'grid' and 'search'; keep each in one")
    scheduler = _check_optional_choice("scheduler", values["scheduler"], SCHEDULERS)
    search_algorithm = _check_optional_choice(
        "search_algorithm", values["search_algorithm"], SEARCH_ALGORITHMS
    )
    num_samples = _check_positive_int("num_samples", values["num_samples"])
    if kind == "front":
        _check_front(search, num_samples, scheduler, search_algorithm, values["grace_timesteps"])
    if search_algorithm is not None and grid:
        raise ValueError(
            "sweep key 'grid' must be empty with search_algorithm 'optuna': Optuna samples "
            "every swept key; give them as 'search' distributions (choice for a list)"
        )
    if not grid and not search:
        raise ValueError("sweep keys 'grid' and 'search' are both empty: a sweep needs trials")
    if search_algorithm is not None:
        _check_search_start(base, search)
    metric, mode = _check_objective(values["metric"], values["mode"], scheduler, search_algorithm)
    config = SweepConfig(
        path=path,
        base=base,
        results_dir=str(_check_path("results_dir", values["results_dir"]).resolve()),
        kind=kind,
        learner=learner,
        grid=grid,
        search=search,
        num_samples=num_samples,
        scheduler=scheduler,
        grace_timesteps=_check_grace(values["grace_timesteps"], scheduler),
        search_algorithm=search_algorithm,
        metric=metric,
        mode=mode,
        cpus_per_trial=_check_positive_number("cpus_per_trial", values["cpus_per_trial"]),
        max_concurrent_trials=_check_optional_positive_int(
            "max_concurrent_trials", values["max_concurrent_trials"]
        ),
        trial_seeds=_check_trial_seeds(
            values["trial_seeds"], learner, kind, scheduler, grid, search
        ),
    )
    _check_trial_configs(config)
    return config


def format_value(value: Any) -> str:
    """A swept value as it appears in a trial's folder name (no ``/``, no spaces)."""
    if isinstance(value, bool) or value is None:
        text = json.dumps(value)
    elif isinstance(value, float):
        text = format(value, ".6g")
    elif isinstance(value, int | str):
        text = str(value)
    else:
        text = json.dumps(value, separators=(",", ":"))
    return text.replace("/", "_").replace(" ", "")


def _labels(keys: list[str]) -> dict[str, str]:
    """Each key's last dotted part, or the whole key where two keys share that part."""
    last = [key.rpartition(".")[2] for key in keys]
    pairs = zip(keys, last, strict=True)
    return {key: key if last.count(part) > 1 else part for key, part in pairs}


def _assign(raw: dict[str, Any], key: str, value: Any) -> None:
    """Set the dotted training-config ``key`` of ``raw`` to ``value``."""
    top, _, inner = key.partition(".")
    if not inner:
        raw[top] = copy.deepcopy(value)
        return
    nested = raw.get(top)
    raw[top] = {**(nested if isinstance(nested, dict) else {}), inner: copy.deepcopy(value)}


def _value_at(raw: Mapping[str, Any], key: str) -> Any:
    """The value of the dotted training-config ``key`` in ``raw`` (``None`` where unset)."""
    top, _, inner = key.partition(".")
    nested = raw.get(top)
    if not inner:
        return nested
    return nested.get(inner) if isinstance(nested, dict) else None


def _check_search_start(base: Mapping[str, Any], search: Mapping[str, Any]) -> None:
    """An Optuna search starts from the searched keys' values in ``base`` (with the
    ``overrides``): each must lie inside its distribution."""
    for key, spec in search.items():
        ((distribution, arguments),) = spec.items()
        start = _value_at(base, key)
        if distribution == "choice":
            inside = start in arguments
        else:
            number = isinstance(start, int | float) and not isinstance(start, bool)
            low, high = arguments
            if distribution == "randint":
                inside = number and isinstance(start, int) and low <= start < high
            else:
                inside = number and low <= start <= high
        if not inside:
            raise ValueError(
                f"sweep key 'search.{key}': the search starts from {key} = {start!r} (the base "
                f"config with the overrides), outside {{{distribution}: {arguments!r}}}; set it "
                "inside with 'overrides'"
            )


def _check_key_set(raw: Mapping[str, Any]) -> None:
    require_key_set(raw, REQUIRED_SWEEP_KEYS, OPTIONAL_SWEEP_DEFAULTS, "sweep")


def _check_training_key(section: str, key: Any) -> str:
    """A dotted training-config key: a top-level key, or ``<mapping key>.<name>``."""
    allowed = [key for key in (*REQUIRED_KEYS, *OPTIONAL_DEFAULTS) if key != "out_dir"]
    if not isinstance(key, str):
        raise ValueError(f"sweep key {section!r}: {key!r} is not a training-config key")
    top, dot, inner = key.partition(".")
    if top not in allowed or (dot and (top not in NESTED_TRAINING_KEYS or not inner)):
        raise ValueError(
            f"sweep key {section!r}: unknown training-config key {key!r}; allowed: {allowed}, "
            f"or {list(NESTED_TRAINING_KEYS)} followed by '.name'"
        )
    return key


def _check_oracle_key(section: str, key: Any) -> str:
    """A key of a clairvoyant-schedule run (:class:`agents.oracle.run.OracleConfig`)."""
    allowed = list(OracleConfig.__dataclass_fields__)
    if key not in allowed:
        raise ValueError(f"sweep key {section!r}: unknown oracle key {key!r}; allowed: {allowed}")
    return key


def _check_search_key(section: str, key: Any) -> str:
    """A search-config key (:class:`agents.search.cma_es.SearchConfig`), or ``keywords.<name>``
    (an env keyword)."""
    allowed = list(SearchConfig.__dataclass_fields__)
    top, dot, inner = key.partition(".") if isinstance(key, str) else ("", "", "")
    if top not in allowed or (dot and (top != "keywords" or not inner)):
        raise ValueError(
            f"sweep key {section!r}: unknown search-config key {key!r}; allowed: {allowed}, "
            f"or 'keywords.name'"
        )
    return key


def _load_base(value: Any) -> dict[str, Any]:
    path = _check_path("base", value)
    try:
        with open(path, encoding="utf-8") as stream:
            raw = yaml.safe_load(stream)
    except OSError as error:
        raise ValueError(
            f"sweep key 'base': cannot read {str(path)!r} ({error.strerror})"
        ) from None
    if not isinstance(raw, dict):
        raise ValueError(f"sweep key 'base': {str(path)!r} is not a YAML mapping of keys to values")
    return raw


def _check_path(key: str, value: Any) -> Path:
    if not isinstance(value, str) or not value:
        raise ValueError(f"sweep key {key!r} must be a path, got {value!r}")
    return Path(value)


def _check_mapping(key: str, value: Any) -> dict[str, Any]:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise ValueError(f"sweep key {key!r} must be a mapping of keys to values, got {value!r}")
    return dict(value)


def _absolute(path: Any) -> Any:
    """A path (a model, a cache folder) as an absolute path (trials run in other folders),
    other values as they are."""
    return str(Path(path).resolve()) if isinstance(path, str) else path


def _check_grid(value: Any, check_key: Callable[[str, Any], str]) -> dict[str, list[Any]]:
    grid = _check_mapping("grid", value)
    for key, values in grid.items():
        check_key("grid", key)
        if not isinstance(values, list) or not values:
            raise ValueError(f"sweep key 'grid.{key}' must be a non-empty list, got {values!r}")
        if key == "init_from":
            grid[key] = values = [_absolute(entry) for entry in values]
        printed = [format_value(entry) for entry in values]
        if len(set(printed)) != len(printed):
            raise ValueError(f"sweep key 'grid.{key}' repeats a value: {values!r}")
    return grid


def _check_search(value: Any) -> dict[str, dict[str, list[Any]]]:
    search = _check_mapping("search", value)
    for key, spec in search.items():
        _check_training_key("search", key)
        if not isinstance(spec, dict) or len(spec) != 1 or next(iter(spec)) not in DISTRIBUTIONS:
            raise ValueError(
                f"sweep key 'search.{key}' must be one of {{uniform: [low, high]}}, "
                f"{{loguniform: [low, high]}}, {{randint: [low, high]}}, {{choice: [values]}}; "
                f"got {spec!r}"
            )
        ((distribution, arguments),) = spec.items()
        _check_distribution(f"search.{key}.{distribution}", distribution, arguments)
    return search


def _check_distribution(key: str, distribution: str, arguments: Any) -> None:
    if distribution == "choice":
        if not isinstance(arguments, list) or not arguments:
            raise ValueError(f"sweep key {key!r} must be a non-empty list, got {arguments!r}")
        return
    numbers = isinstance(arguments, list) and len(arguments) == 2
    numbers = numbers and all(
        isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)
        for x in arguments
    )
    if distribution == "randint":
        numbers = numbers and all(isinstance(x, int) for x in arguments)
    if not numbers or not arguments[0] < arguments[1]:
        raise ValueError(
            f"sweep key {key!r} must be [low, high] with low < high, got {arguments!r}"
        )
    if distribution == "loguniform" and arguments[0] <= 0:
        raise ValueError(f"sweep key {key!r} needs low > 0, got {arguments!r}")


def _check_front(
    search: dict[str, Any],
    num_samples: int,
    scheduler: str | None,
    search_algorithm: str | None,
    grace_timesteps: Any,
) -> None:
    """A front's trials all run to their end and form a fixed grid."""
    offending = [
        key
        for key, present in (
            ("scheduler", scheduler is not None),
            ("search_algorithm", search_algorithm is not None),
            ("grace_timesteps", grace_timesteps is not None),
            ("search", bool(search)),
            ("num_samples", num_samples != 1),
        )
        if present
    ]
    if offending:
        raise ValueError(
            f"sweep keys {offending} are for kind 'search': the trials of a front (kind "
            f"'front') are never stopped early or sampled, as that would bias the comparison"
        )


def _check_trial_seeds(
    value: Any,
    learner: str,
    kind: str,
    scheduler: str | None,
    grid: Mapping[str, Any],
    search: Mapping[str, Any],
) -> tuple[int, ...] | None:
    """A search's seeds per trial: two or more distinct integers, on a training search without
    a scheduler that sweeps ``seed`` nowhere else."""
    if value is None:
        return None
    if (
        not isinstance(value, list)
        or len(value) < 2
        or not all(isinstance(seed, int) and not isinstance(seed, bool) for seed in value)
        or len(set(value)) != len(value)
    ):
        raise ValueError(
            f"sweep key 'trial_seeds' must be a list of two or more distinct integer seeds, "
            f"got {value!r}"
        )
    offending = [
        reason
        for reason, present in (
            (f"learner {learner!r} (it trains: learner 'train')", learner != "train"),
            (f"kind {kind!r} (a search's trials: kind 'search')", kind != "search"),
            (f"scheduler {scheduler!r}", scheduler is not None),
            ("'seed' swept in 'grid' or 'search'", "seed" in grid or "seed" in search),
        )
        if present
    ]
    if offending:
        raise ValueError(
            f"sweep key 'trial_seeds' is for a hyperparameter search whose trials train once "
            f"per seed without a scheduler; not with {', '.join(offending)}"
        )
    return tuple(value)


def _check_objective(
    metric: Any, mode: Any, scheduler: str | None, search_algorithm: str | None
) -> tuple[str | None, str | None]:
    if scheduler is None and search_algorithm is None:
        if metric is not None or mode is not None:
            raise ValueError("sweep keys 'metric' and 'mode' need a scheduler or search_algorithm")
        return None, None
    metric = _check_choice("metric", metric, METRICS)
    return metric, _check_choice("mode", mode, MODES)


def _check_grace(value: Any, scheduler: str | None) -> int | None:
    if value is None:
        return None
    if scheduler is None:
        raise ValueError("sweep key 'grace_timesteps' needs scheduler 'asha'")
    return _check_positive_int("grace_timesteps", value)


def _check_choice(key: str, value: Any, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise ValueError(f"sweep key {key!r} must be one of {list(allowed)}, got {value!r}")
    return value


def _check_optional_choice(key: str, value: Any, allowed: tuple[str, ...]) -> str | None:
    return None if value is None else _check_choice(key, value, allowed)


def _check_positive_int(key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"sweep key {key!r} must be a positive integer, got {value!r}")
    return value


def _check_optional_positive_int(key: str, value: Any) -> int | None:
    return None if value is None else _check_positive_int(key, value)


def _check_positive_number(key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        raise ValueError(f"sweep key {key!r} must be a positive number, got {value!r}")
    return float(value)


def _check_trial_configs(config: SweepConfig) -> None:
    """Build the training config of every grid point (a search's keys at their lower bounds
    or first choice), so that a bad value is refused before any trial starts."""
    sample = {key: _first_value(spec) for key, spec in config.search.items()}
    for point in config.grid_points():
        values = {**point, **sample}
        try:
            trial = config.trial_config(values, config.trials_dir)
        except ValueError as error:
            where = config.trial_name(values) if values else "the base config"
            raise ValueError(f"{config.path}: trial {where}: {error}") from None
        if config.metric in EVALUATION_METRICS and not trial.evaluation_every:
            raise ValueError(
                f"sweep key 'metric': {config.metric!r} comes from the training run's "
                f"evaluations, and evaluation_every is 0; set it in the base config or "
                f"'overrides'"
            )


def _first_value(spec: dict[str, list[Any]]) -> Any:
    """A distribution's lower bound, or a choice's first value."""
    (arguments,) = spec.values()
    return arguments[0]


def _grown(before: dict[str, list[Any]], after: dict[str, list[Any]]) -> bool:
    """Whether grid ``after`` has ``before``'s keys, each with every value it had (and perhaps
    more): every trial of ``before`` is a trial of ``after``."""
    return set(before) == set(after) and all(
        all(value in after[key] for value in values) for key, values in before.items()
    )

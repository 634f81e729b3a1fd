"""Direct policy search: CMA-ES over a paper's trigger family (:mod:`etsc_envs.triggers.family`).

    python -m agents.search --config configs/search/NAME.yaml [--seed S] [--out DIR]
                            [--processes N | --address ADDR] [--resume | --overwrite]

The algorithm, in full:

1. θ (the family's point) is encoded as a vector x: log2 of each searched threshold factor,
   log2 of the floor and of the heartbeat in sampling instants (below -1: no floor; above
   log2 of the horizon: no heartbeat), the time exponent p (in ``exponent_range``, default
   [-1, 2]), log2 of each condition's weight and the strength κ when the config searches a
   coupled point (every candidate coupled as ``start.coupling``, whose ``refresh_all`` it
   keeps), and the network's weights when the
   config searches a state-dependent modulation. x starts at the config's ``start`` point
   (today's best hand rule, so the search begins where the menu ended).
2. Each generation, CMA-ES (pycma) asks for ``population`` candidates. Every candidate is
   scored on the same fresh batch of ``scenarios`` training scenarios (randomized draws whose
   seeds lie outside the protocol's validation and test ranges) by the env's own return at the
   penalty λ (``transmission_penalty``): ``-Σ cost_k / cost_scale - λ · transmissions``, the
   reward the PPO triggers get, averaged over the batch. CMA-ES is told the negated returns.
3. Every ``validate_every`` generations the distribution's mean (CMA-ES's ``xfavorite``, the
   mean mapped through the box constraints) is scored on the first
   ``validation_size`` validation scenarios at the full horizon; the learned trigger is the
   validated mean with the best validation return (the start point, validated at generation
   0, competes too). The test set is never touched here.

Candidates of a generation run in parallel: on a Ray instance of their own (the default where
Ray is installed), on a Ray cluster (``--address`` or ``RAY_ADDRESS``; docs/clusters.md) or in
``--processes N`` spawned worker processes. Each generation's candidates and returns are appended to
``generations.jsonl`` in the output folder: ``--resume`` rebuilds the CMA-ES state by replaying
them (pycma's sampler has its own seeded generator, so asking again draws the same candidates;
no pickle is written) and continues, and the result equals an uninterrupted run's.

Writes into ``DIR`` (default ``runs/search/<config stem>_seed<S>``): ``learned.json`` (a
``learned:`` trigger), ``curve.json`` and ``curve.png`` (training and validation returns
against env steps and wall time), ``generations.jsonl`` and ``config.yaml``.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import os
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import yaml

import etsc_envs
from agents.sweep.cluster import check_reachable, join
from etsc_envs.core.files import (
    atomic_write_text,
    output_folder_argument,
    require_writable_folder,
)
from etsc_envs.core.json_files import (
    in_file,
    read_json_lines,
    require_array,
    require_integer,
    require_mapping,
    require_number,
    require_string,
    require_strings,
)
from etsc_envs.core.validation import MAX_TRANSMISSION_PENALTY
from etsc_envs.papers import PAPER_IDS, paper_of
from etsc_envs.protocol import require_training_seeds, scenario_set
from etsc_envs.triggers.family import (
    CHANNEL,
    MAX_EXPONENT,
    MAX_HIDDEN,
    FamilyPoint,
    LearnedTrigger,
    Modulation,
    channel_name,
    require_factors,
    require_keywords,
)

TRAINING_SEED_BASE = 10_000_000
"""Training scenario seeds start here (above the protocol's reserved ranges): run seed S,
generation g, scenario i draws seed ``BASE + S · 1 000 000 + g · scenarios + i``."""

DIMENSIONS = ("factors", "floor", "heartbeat", "exponent", "coupling", "modulation")
"""The parts of θ a config may search."""

LOG2_FACTOR_RANGE = 8.0
"""A searched factor stays within 2^±8 of 1 (or inside the paper's bound)."""

EXPONENT_RANGE = (-1.0, 2.0)
"""The time exponent p's box by default (a config's ``exponent_range`` replaces it)."""
WEIGHT_RANGE = 4.0
STEP_SCALE = {
    "factors": 1.0,
    "floor": 1.0,
    "heartbeat": 1.0,
    "exponent": 0.25,
    "coupling": 0.5,
    "modulation": 0.3,
}
"""Initial step size of each part, relative to ``sigma`` (x is in log2 units for the factors,
the floor, the heartbeat and the coupling's weights)."""


@dataclass(frozen=True)
class SearchConfig:
    """A search, as its YAML file gives it (every key is checked; see configs/search/)."""

    env_id: str
    penalty: float
    start: FamilyPoint
    search: tuple[str, ...]
    generations: int
    population: int
    scenarios: int
    sigma: float = 1.0
    horizon_s: float | None = None
    validate_every: int = 5
    validation_size: int = 16
    hidden: int = 4
    inputs: tuple[str, ...] = ()
    keywords: dict[str, Any] = field(default_factory=dict)
    seed: int = 0
    exponent_range: tuple[float, float] = EXPONENT_RANGE

    @property
    def family(self) -> type:
        return paper_of(self.env_id).trigger

    def env_args(self, *, training: bool) -> dict[str, Any]:
        """The env keywords of a training (shortened horizon) or a validation scenario."""
        args: dict[str, Any] = {"transmission_penalty": self.penalty}
        if training and self.horizon_s is not None:
            args["horizon_s"] = self.horizon_s
        return args


MAX_SCENARIOS = 1024
"""The most scenarios one batch may run (``scenarios``, ``validation_size``): a batch keeps every
scenario's env and record in memory at once; docs/clusters.md lists every key's range)."""

MAX_POPULATION = 1024
MAX_GENERATIONS = 100_000
MAX_SIGMA = 2.0 * LOG2_FACTOR_RANGE
MAX_SEED = 2**31 - 1


def read_config(path: str | Path, where: str | None = None) -> dict[str, Any]:
    """The mapping of keys in the YAML file ``path`` (``ValueError`` starting with ``where``,
    default ``--config PATH``)."""
    where = where or f"--config {path}"
    try:
        raw = yaml.safe_load(Path(path).read_text())
    except (OSError, UnicodeDecodeError, yaml.YAMLError, RecursionError) as error:
        reason = getattr(error, "strerror", None) or str(error).splitlines()[0]
        raise ValueError(f"{where}: not a readable YAML file ({reason})") from None
    if not isinstance(raw, dict):
        raise ValueError(f"{where}: a search config is a mapping of keys")
    return raw


def load_config(path: str | Path) -> SearchConfig:
    """The search config in the YAML file ``path``; ``ValueError`` naming the key for a bad
    value."""
    return config_from_dict(read_config(path))


def config_from_dict(raw: dict[str, Any]) -> SearchConfig:
    """The search config of the mapping ``raw``, every key checked for its kind and range when
    it is read, before any work (``ValueError``: ``config key 'search.KEY' ...``, one line)."""
    try:
        return _checked_config(raw)
    except ValueError as error:
        raise ValueError(f"config {error}") from None


def _checked_config(raw: dict[str, Any]) -> SearchConfig:
    """:func:`config_from_dict`'s checks, naming keys as ``key 'search.KEY'``."""
    fields = SearchConfig.__dataclass_fields__
    raw = require_mapping(raw, "search", fields, ("env_id", "penalty", "search"))
    env_id = require_string(raw["env_id"], "search.env_id", PAPER_IDS)
    family = paper_of(env_id).trigger
    search = require_strings(raw["search"], "search.search", DIMENSIONS)
    if not search:
        raise ValueError(f"key 'search.search' must name at least one of {list(DIMENSIONS)}")
    start = FamilyPoint.from_json(raw.get("start", {}), "search.start")
    require_factors(family, start.factors, "search.start.factors")
    counts = {
        key: require_integer(raw.get(key, default), f"search.{key}", least, most)
        for key, default, least, most in (
            ("generations", None, 1, MAX_GENERATIONS),
            ("population", None, 2, MAX_POPULATION),
            ("scenarios", None, 1, MAX_SCENARIOS),
            ("validate_every", 5, 1, MAX_GENERATIONS),
            ("validation_size", 16, 1, MAX_SCENARIOS),
            ("hidden", 4, 1, MAX_HIDDEN),
            ("seed", 0, 0, MAX_SEED),
        )
    }
    penalty = require_number(
        raw["penalty"], "search.penalty", low=0.0, high=MAX_TRANSMISSION_PENALTY, low_open=True
    )
    sigma = require_number(
        raw.get("sigma", 1.0), "search.sigma", low=0.0, high=MAX_SIGMA, low_open=True
    )
    horizon_s = raw.get("horizon_s")
    if horizon_s is not None:
        horizon_s = require_number(horizon_s, "search.horizon_s", low=0.0, low_open=True)
    exponent_range = _exponent_range(raw.get("exponent_range", list(EXPONENT_RANGE)))
    if not exponent_range[0] <= start.exponent <= exponent_range[1]:
        raise ValueError(
            f"key 'search.start.exponent' must lie in exponent_range {list(exponent_range)}, "
            f"got {start.exponent!r}"
        )
    names = _observation_names(env_id, horizon_s)
    inputs = _inputs(env_id, raw.get("inputs", []), names)
    if "coupling" in search and start.coupling is None:
        raise ValueError(
            "key 'search.start.coupling' gives the coupling a search of coupling starts from "
            "(e.g. {weights: [1, 1, 1], strength: 0} on 004's three axes)"
        )
    if ("modulation" in search) != bool(inputs):
        raise ValueError(
            "key 'search.inputs' names the observations the network reads: needed by a search "
            "of modulation, and only by one"
        )
    return SearchConfig(
        env_id=env_id,
        penalty=penalty,
        start=start,
        search=search,
        sigma=sigma,
        horizon_s=horizon_s,
        inputs=inputs,
        keywords=require_keywords(family, raw.get("keywords", {}), "search.keywords"),
        exponent_range=exponent_range,
        **counts,
    )


def _exponent_range(value: Any) -> tuple[float, float]:
    """``[low, high]``: the box of the time exponent p, ``-MAX_EXPONENT <= low < high <=
    MAX_EXPONENT``."""
    bounds = require_array(value, "search.exponent_range", (2,))
    low, high = (float(bound) for bound in bounds)
    if not -MAX_EXPONENT <= low < high <= MAX_EXPONENT:
        raise ValueError(
            f"key 'search.exponent_range' must be [low, high] with -{MAX_EXPONENT:g} <= low < "
            f"high <= {MAX_EXPONENT:g}, got {value!r}"
        )
    return low, high


def _observation_names(env_id: str, horizon_s: float | None) -> tuple[str, ...]:
    """The observation names of one agent of ``env_id``'s closed loop; ``ValueError`` naming
    ``search.horizon_s`` where the env refuses that horizon."""
    loop_id = etsc_envs.PETTINGZOO_LOOP_IDS.get(env_id, env_id)
    try:
        env = gym.make(loop_id, **({} if horizon_s is None else {"horizon_s": horizon_s}))
    except ValueError as error:
        raise ValueError(f"key 'search.horizon_s': {error}") from None
    names = tuple(env.unwrapped.observation_names)
    env.close()
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        parallel = etsc_envs.make_parallel(env_id)
        names = tuple(parallel.unwrapped.agent_observation_names)
        parallel.close()
    return names


def _inputs(env_id: str, value: Any, names: tuple[str, ...]) -> tuple[str, ...]:
    """``search.inputs``: observation names of one agent of ``env_id`` (``names``), each
    holding :data:`~etsc_envs.triggers.family.CHANNEL` where every channel reads its own
    (``s_norm{channel}``); on a PettingZoo id every input must, since an agent observes only
    its own follower."""
    inputs = require_strings(value, "search.inputs")
    pettingzoo = env_id in etsc_envs.PETTINGZOO_ENV_IDS
    channels = sum(name.startswith("time_since_transmission_s") for name in names)
    for index, name in enumerate(inputs):
        if pettingzoo and CHANNEL not in name:
            raise ValueError(
                f"key 'search.inputs[{index}]': {name!r} must read each agent's own observation "
                f"on {env_id} (an input such as 's_norm{CHANNEL}')"
            )
        if CHANNEL not in name or pettingzoo:
            expanded = [channel_name(name, None)]
        else:
            expanded = [channel_name(name, c) for c in range(channels)]
        missing = [entry for entry in expanded if entry not in names]
        if missing:
            raise ValueError(
                f"key 'search.inputs[{index}]': {missing} are not observations of {env_id}"
            )
    return inputs


def _integer(key: str, value: Any, least: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ValueError(f"{key} must be an integer >= {least}, got {value!r}")
    return value


class SearchSpace:
    """The encoding of θ as the vector CMA-ES searches (the module docstring's step 1)."""

    def __init__(self, config: SearchConfig, n_steps: int, modulation: Modulation | None):
        self.config = config
        self.groups = tuple(config.family.threshold_groups) if "factors" in config.search else ()
        self.no_heartbeat = math.log2(n_steps) + 1.0
        self.modulation = modulation if "modulation" in config.search else None
        lower: list[float] = []
        upper: list[float] = []
        steps: list[float] = []
        for name in self.groups:
            low, high = config.family.factor_bounds.get(name, (0.0, math.inf))
            lower.append(max(-LOG2_FACTOR_RANGE, math.log2(low) if low > 0 else -math.inf))
            upper.append(min(LOG2_FACTOR_RANGE, math.log2(high) - 1e-6))
            steps.append(STEP_SCALE["factors"])
        for part, low, high in (
            ("floor", -1.0, math.log2(n_steps)),
            ("heartbeat", 0.0, self.no_heartbeat),
            ("exponent", *config.exponent_range),
        ):
            if part in config.search:
                lower.append(low)
                upper.append(high)
                steps.append(STEP_SCALE[part])
        coupling = config.start.coupling if "coupling" in config.search else None
        self.coupling_weights = 0 if coupling is None else len(coupling.weights)
        if self.coupling_weights:  # log2 of each condition's weight, then κ
            lower += [-LOG2_FACTOR_RANGE] * self.coupling_weights + [0.0]
            upper += [LOG2_FACTOR_RANGE] * self.coupling_weights + [1.0]
            steps += [STEP_SCALE["coupling"]] * self.coupling_weights + [STEP_SCALE["exponent"]]
        if self.modulation is not None:
            n = self.modulation.weights.size
            lower += [-WEIGHT_RANGE] * n
            upper += [WEIGHT_RANGE] * n
            steps += [STEP_SCALE["modulation"]] * n
        self.lower, self.upper, self.steps = np.array(lower), np.array(upper), np.array(steps)

    def encode(self, point: FamilyPoint) -> np.ndarray:
        x = [math.log2(point.factors.get(name, 1.0)) for name in self.groups]
        if "floor" in self.config.search:
            x.append(math.log2(point.floor_instants) if point.floor_instants >= 0.5 else -1.0)
        if "heartbeat" in self.config.search:
            beat = point.heartbeat_instants
            x.append(self.no_heartbeat if math.isinf(beat) else math.log2(beat))
        if "exponent" in self.config.search:
            x.append(point.exponent)
        if self.coupling_weights:
            coupling = point.coupling or self.config.start.coupling
            assert coupling is not None  # a search of coupling starts coupled
            x.extend([*(math.log2(weight) for weight in coupling.weights), coupling.strength])
        if self.modulation is not None:
            modulation = point.modulation or self.modulation
            x.extend(modulation.weights)
        return np.clip(np.array(x, dtype=float), self.lower, self.upper)

    def strategy(
        self, start: FamilyPoint, sigma: float, rng: np.random.Generator, **options: Any
    ) -> Any:
        """pycma's CMA-ES over this space from ``start`` with the initial step ``sigma``: the
        box, the per-coordinate steps, and every draw from ``rng`` (pycma's own seed unused,
        so a search is reproduced by its generator alone); ``options`` adds pycma options
        (``popsize``, ``maxiter``)."""
        import cma

        settings = {
            "bounds": [self.lower.tolist(), self.upper.tolist()],
            "CMA_stds": self.steps.tolist(),
            "seed": np.nan,
            "randn": lambda lam, n: rng.standard_normal((lam, n)),
            "verbose": -9,
            **options,
        }
        return cma.CMAEvolutionStrategy(self.encode(start).tolist(), sigma, settings)

    def decode(self, x: Sequence[float]) -> FamilyPoint:
        x = np.clip(np.asarray(x, dtype=float), self.lower, self.upper)
        start = self.config.start
        factors = dict(start.factors)
        i = 0
        for name in self.groups:
            factors[name] = float(2.0 ** x[i])
            i += 1
        changes: dict[str, Any] = {"factors": factors}
        if "floor" in self.config.search:
            changes["floor_instants"] = float(2.0 ** x[i]) if x[i] > -1.0 else 0.0
            i += 1
        if "heartbeat" in self.config.search:
            changes["heartbeat_instants"] = (
                math.inf if x[i] >= self.no_heartbeat - 1.0 else float(2.0 ** x[i])
            )
            i += 1
        if "exponent" in self.config.search:
            changes["exponent"] = float(x[i])
            i += 1
        if self.coupling_weights:
            assert start.coupling is not None  # a search of coupling starts coupled
            n = self.coupling_weights
            changes["coupling"] = replace(
                start.coupling,
                weights=tuple(float(2.0**w) for w in x[i : i + n]),
                strength=float(x[i + n]),
            )
            i += n + 1
        if self.modulation is not None:
            changes["modulation"] = self.modulation.with_weights(x[i:])
        return replace(start, **changes)


def score(
    env_id: str, env_args: dict[str, Any], learned: dict[str, Any], seeds: list[int]
) -> dict[str, float]:
    """The mean return, accuracy cost and transmissions of the learned trigger ``learned`` (its
    JSON form) over one episode per seed, all seeds in one batch
    (:func:`etsc_envs.evaluation.batch.run_batch`). A module-level function, so that worker
    processes and Ray tasks can run it."""
    from etsc_envs.evaluation.batch import run_batch

    env = (
        etsc_envs.make_parallel(env_id, **env_args)
        if env_id in etsc_envs.PETTINGZOO_ENV_IDS
        else gym.make(env_id, **env_args)
    )
    trigger = LearnedTrigger.from_json(learned).policy_for(env)
    env.close()
    records = run_batch(env_id, trigger, seeds, env_args)
    return {
        "return": float(np.mean([r["return"] for r in records])),
        "mean_cost": float(np.mean([r["mean_cost"] for r in records])),
        "transmissions": float(np.mean([r["transmissions"] for r in records])),
        "failures": int(sum(r["failure"] is not None for r in records)),
        "steps": int(sum(r["steps"] for r in records)),
    }


class Evaluator:
    """Runs :func:`score` for many candidates at once: in ``processes`` spawned worker
    processes, as Ray tasks (``processes`` ``None``: a local Ray, or the cluster at
    ``address``), or one after another in this process (``processes`` 0: a search that is
    itself one of many trials run in parallel, :mod:`agents.sweep.learners`)."""

    def __init__(self, processes: int | None, address: str | None) -> None:
        self.pool: ProcessPoolExecutor | None = None
        self.ray: Any = None
        if processes == 0:
            self.description = "this process"
        elif processes is not None:
            context = multiprocessing.get_context("spawn")
            self.pool = ProcessPoolExecutor(processes, mp_context=context)
            self.description = f"{processes} worker process(es)"
        else:
            import ray

            if address is None:  # a Ray of its own, never one already running here
                ray.init(address="local", include_dashboard=False, log_to_driver=False)
            else:
                join(address, include_dashboard=False, log_to_driver=False)
            self.ray = ray
            self.remote_score = ray.remote(score)
            self.description = f"Ray at {address or 'a local cluster'}"

    def map(self, calls: list[tuple[Any, ...]]) -> list[dict[str, float]]:
        if self.pool is not None:
            return list(self.pool.map(score, *zip(*calls, strict=True)))
        if self.ray is None:
            return [score(*call) for call in calls]
        return self.ray.get([self.remote_score.remote(*call) for call in calls])

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)
        if self.ray is not None:
            self.ray.shutdown()


def training_seeds(config: SearchConfig, generation: int) -> list[int]:
    first = TRAINING_SEED_BASE + config.seed * 1_000_000 + generation * config.scenarios
    require_training_seeds(first, config.scenarios, "seed")
    return list(range(first, first + config.scenarios))


def observation_statistics(config: SearchConfig) -> tuple[np.ndarray, np.ndarray]:
    """Mean and spread of the network's inputs over two training episodes of the start point
    in the id's closed loop (the normalisation the learned file carries; a per-channel input
    pooled over the channels); a constant input gets spread 1."""
    loop_id = etsc_envs.PETTINGZOO_LOOP_IDS.get(config.env_id, config.env_id)
    env = gym.make(loop_id, randomize=True, **config.env_args(training=True))
    loop = env.unwrapped
    names = tuple(loop.observation_names)
    trigger = _learned(config, config.start, {}).trigger(
        env.observation_space, env.action_space, names, loop.sampling_period_s
    )
    n_inputs = len(config.inputs)
    zeros = Modulation.zeros(config.inputs, np.zeros(n_inputs), np.ones(n_inputs), config.hidden)
    columns = zeros.input_columns(names, loop.n_channels)
    rows = []
    for seed in training_seeds(config, 0)[:2]:
        obs, _ = env.reset(seed=seed)
        done = False
        while not done:
            rows.extend(obs[own] for own in columns)
            action, _ = trigger.predict(obs)
            obs, _, terminated, truncated, _ = env.step(action)
            done = terminated or truncated
    env.close()
    data = np.array(rows, dtype=np.float64)
    spread = data.std(axis=0)
    return data.mean(axis=0), np.where(spread > 0, spread, 1.0)


def _learned(config: SearchConfig, point: FamilyPoint, search: dict[str, Any]) -> LearnedTrigger:
    return LearnedTrigger(config.env_id, config.family.__name__, point, config.keywords, search)


def run_search(
    config: SearchConfig,
    out: Path,
    evaluator: Evaluator,
    *,
    progress: Callable[[str], None] = print,
) -> LearnedTrigger:
    """The search of the module docstring into ``out``, continuing the generations already
    recorded in ``out/generations.jsonl``; returns the learned trigger."""
    loop_id = etsc_envs.PETTINGZOO_LOOP_IDS.get(config.env_id, config.env_id)
    env = gym.make(loop_id, **config.env_args(training=True))  # the horizon in instants
    n_steps = env.unwrapped.n_steps
    env.close()
    modulation = None
    if "modulation" in config.search:
        mean, spread = observation_statistics(config)
        modulation = Modulation.zeros(config.inputs, mean, spread, config.hidden)
    space = SearchSpace(config, n_steps, modulation)
    start = space.decode(space.encode(config.start))
    rng = np.random.default_rng([config.seed, 20_261_127])
    es = space.strategy(
        start, config.sigma, rng, popsize=config.population, maxiter=config.generations
    )

    out.mkdir(parents=True, exist_ok=True)
    log_path = out / "generations.jsonl"
    history, torn = read_history(log_path, config, len(space.lower))
    for record in history:  # replay: the same draws, told the recorded returns
        candidates = es.ask()
        if not np.allclose(np.array(candidates), np.array(record["candidates"]), atol=1e-12):
            raise ValueError(f"--resume: {log_path} was written by another config or seed")
        es.tell(candidates, [-value for value in record["returns"]])
    if torn:
        atomic_write_text(log_path, "".join(json.dumps(record) + "\n" for record in history))
        progress(
            f"--resume: dropped the torn last line of {log_path} (a generation cut off while "
            "being written); that generation runs again"
        )

    validation = scenario_set("validation", config.validation_size)
    validation_args = {**validation.env_args, **config.env_args(training=False)}
    training_args = {"randomize": True, **config.env_args(training=True)}
    started = time.perf_counter() - (history[-1]["wall_s"] if history else 0.0)
    steps = history[-1]["env_steps"] if history else 0
    first = len(history)
    session_started = time.perf_counter()
    for generation in range(first, config.generations):
        seeds = training_seeds(config, generation)
        candidates = es.ask()
        points = [space.decode(x) for x in candidates]
        calls = [
            (config.env_id, training_args, _learned(config, p, {}).to_json(), seeds) for p in points
        ]
        validate = generation % config.validate_every == 0 or generation == config.generations - 1
        mean_point = start if generation == 0 else space.decode(es.result.xfavorite)
        if validate:
            calls.append(
                (
                    config.env_id,
                    validation_args,
                    _learned(config, mean_point, {}).to_json(),
                    list(validation.seeds),
                )
            )
        results = evaluator.map(calls)
        returns = [r["return"] for r in results[: len(points)]]
        steps += sum(r["steps"] for r in results)
        es.tell(candidates, [-value for value in returns])
        record: dict[str, Any] = {
            "generation": generation,
            "candidates": [np.asarray(x).tolist() for x in candidates],
            "returns": returns,
            "transmissions": [r["transmissions"] for r in results[: len(points)]],
            "mean_cost": [r["mean_cost"] for r in results[: len(points)]],
            "env_steps": steps,
            "wall_s": time.perf_counter() - started,
        }
        if validate:
            record["validation"] = {"point": mean_point.to_json(), **results[-1]}
        with log_path.open("a") as log:
            log.write(json.dumps(record) + "\n")
        history.append(record)
        elapsed = record["wall_s"]
        done = generation + 1
        per_generation = (time.perf_counter() - session_started) / (done - first)
        eta = per_generation * (config.generations - done)
        validated = f", validation {results[-1]['return']:.4g}" if validate else ""
        progress(
            f"generation {done}/{config.generations}: best {max(returns):.4g}, "
            f"mean {np.mean(returns):.4g}{validated}; {elapsed:.0f} s, about {eta:.0f} s left"
        )
    return finish(config, out, history)


SCORE_KEYS = ("return", "mean_cost", "transmissions", "failures", "steps")
"""What :func:`score` returns, and a record's ``validation`` holds beside the point."""


def read_history(
    log_path: Path, config: SearchConfig, dimension: int
) -> tuple[list[dict[str, Any]], bool]:
    """The generations recorded in ``log_path`` (none if it does not exist), each checked by
    the suite's JSON reader against the search's shapes (``config.population`` candidates of
    ``dimension`` numbers), and whether a torn last line was left out; ``ValueError`` naming
    the line and key of a damaged record."""
    if not log_path.is_file():
        return [], False
    where = f"--resume: {log_path}"
    records, torn = read_json_lines(log_path, where)
    population = config.population
    keys = ("generation", "candidates", "returns", "transmissions", "mean_cost", "env_steps")
    with in_file(where):
        for number, record in enumerate(records, start=1):
            with in_file(f"line {number}"):
                record = require_mapping(record, "", (*keys, "wall_s", "validation"), keys)
                require_integer(record["generation"], "generation", number - 1, number - 1)
                require_array(record["candidates"], "candidates", (population, dimension))
                for key in ("returns", "transmissions", "mean_cost"):
                    require_array(record[key], key, (population,))
                require_integer(record["env_steps"], "env_steps", 0, 2**62)
                require_number(record.get("wall_s", 0.0), "wall_s", low=0.0)
                if "validation" in record:
                    validation = require_mapping(
                        record["validation"],
                        "validation",
                        ("point", *SCORE_KEYS),
                        ("point", *SCORE_KEYS),
                    )
                    FamilyPoint.from_json(validation["point"], "validation.point")
                    for key in SCORE_KEYS:
                        require_number(validation[key], f"validation.{key}")
    return records, torn


def finish(config: SearchConfig, out: Path, history: list[dict[str, Any]]) -> LearnedTrigger:
    """The learned trigger (the validated mean with the best validation return), its file and
    the search's curve, from the recorded generations."""
    validated = [record for record in history if "validation" in record]
    best = max(validated, key=lambda record: record["validation"]["return"])
    curve = [
        {
            "generation": record["generation"],
            "env_steps": record["env_steps"],
            "wall_s": record["wall_s"],
            "best_return": max(record["returns"]),
            "mean_return": float(np.mean(record["returns"])),
            **(
                {
                    "validation_return": record["validation"]["return"],
                    "validation_cost": record["validation"]["mean_cost"],
                    "validation_transmissions": record["validation"]["transmissions"],
                    "validation_failures": record["validation"]["failures"],
                }
                if "validation" in record
                else {}
            ),
        }
        for record in history
    ]
    search = {
        "penalty": config.penalty,
        "seed": config.seed,
        "generations": len(history),
        "population": config.population,
        "training_scenarios": config.scenarios,
        "training_horizon_s": config.horizon_s,
        "chosen_generation": best["generation"],
        "validation_size": config.validation_size,
        "validation_return": best["validation"]["return"],
        "start_validation_return": validated[0]["validation"]["return"],
        "env_steps": history[-1]["env_steps"],
        "wall_s": history[-1]["wall_s"],
    }
    learned = _learned(config, FamilyPoint.from_json(best["validation"]["point"]), search)
    learned.save(out / "learned.json")
    atomic_write_text(out / "curve.json", json.dumps({"search": search, "curve": curve}, indent=2))
    plot_curve(curve, out / "curve.png", config)
    return learned


def plot_curve(curve: list[dict[str, Any]], path: Path, config: SearchConfig) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, 2, figsize=(9, 3.4), constrained_layout=True)
    for axis, key, label in ((axes[0], "env_steps", "env steps"), (axes[1], "wall_s", "wall (s)")):
        axis.plot([c[key] for c in curve], [c["mean_return"] for c in curve], label="training mean")
        axis.plot([c[key] for c in curve], [c["best_return"] for c in curve], label="training best")
        validated = [c for c in curve if "validation_return" in c]
        axis.plot(
            [c[key] for c in validated],
            [c["validation_return"] for c in validated],
            "o-",
            label="validation (mean point)",
        )
        axis.set_xlabel(label)
        axis.set_ylabel("return per episode")
    axes[1].legend(loc="lower right", fontsize=8)
    figure.suptitle(f"CMA-ES on {config.env_id}, λ = {config.penalty:g}, seed {config.seed}")
    figure.savefig(path, dpi=90)
    plt.close(figure)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m agents.search", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--config", required=True, help="configs/search/NAME.yaml")
    parser.add_argument("--seed", type=int, help="the run's seed (default: the config's)")
    parser.add_argument("--out", type=output_folder_argument("--out"), help="output folder")
    parallel = parser.add_mutually_exclusive_group()
    parallel.add_argument("--processes", type=int, help="worker processes instead of Ray")
    parallel.add_argument("--address", help="a Ray cluster's address (default: RAY_ADDRESS)")
    again = parser.add_mutually_exclusive_group()
    again.add_argument("--resume", action="store_true", help="continue the run in --out")
    again.add_argument("--overwrite", action="store_true", help="start --out afresh")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        raw = read_config(args.config)
        config = config_from_dict(raw)
        if args.seed is not None:
            config = replace(config, seed=_integer("--seed", args.seed, 0))
        if args.processes is not None:
            _integer("--processes", args.processes, 1)
        out = args.out or Path("runs/search") / f"{Path(args.config).stem}_seed{config.seed}"
        require_writable_folder(out, "--out")
        recorded = {**raw, "seed": config.seed}
        require_same_search(out, recorded, args.resume, args.overwrite)
        address = args.address or os.environ.get("RAY_ADDRESS") or None
        if args.processes is None and address is not None:
            check_reachable(address)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    log_path = out / "generations.jsonl"
    out.mkdir(parents=True, exist_ok=True)
    from filelock import FileLock, Timeout

    lock = FileLock(str(out / ".search.lock"))
    try:
        lock.acquire(timeout=0)
    except Timeout:
        print(f"error: --out {out} is in use by another search", file=sys.stderr)
        return 2
    evaluator = None
    try:
        if args.overwrite and log_path.exists():
            log_path.unlink()
        atomic_write_text(out / "config.yaml", yaml.safe_dump(recorded))
        processes = args.processes
        if processes is None and address is None:
            try:
                import ray  # noqa: F401
            except ImportError:
                processes = os.cpu_count() or 1
        evaluator = Evaluator(processes, address)
        print(
            f"CMA-ES on {config.env_id} (λ = {config.penalty:g}, seed {config.seed}): "
            f"{config.generations} generations of {config.population} on {evaluator.description}"
            f"; writing {out}",
            flush=True,
        )
        learned = run_search(config, out, evaluator, progress=lambda line: print(line, flush=True))
    except (ValueError, OSError) as error:
        print(f"error: {one_line(error)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(
            f"interrupted; the finished generations are in {log_path}: run the same command with "
            "--resume to continue",
            file=sys.stderr,
        )
        return 130
    finally:
        if evaluator is not None:
            evaluator.close()
        lock.release()
    chosen = learned.search["chosen_generation"]
    print(f"learned trigger: {out / 'learned.json'} (the mean of generation {chosen})")
    return 0


def require_same_search(out: Path, recorded: dict[str, Any], resume: bool, again: bool) -> None:
    """``ValueError`` before anything is written when ``out`` holds a search and the command
    neither continues it (``resume``) nor starts afresh (``again``), or continues it with
    another config or seed than its ``config.yaml`` records."""
    if not (out / "generations.jsonl").exists():
        return
    if not (resume or again):
        raise ValueError(
            f"--out {out} holds a search; --resume continues it, --overwrite starts afresh"
        )
    stored = out / "config.yaml"
    if not resume or not stored.is_file():
        return
    try:
        before = yaml.safe_load(stored.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as error:
        raise ValueError(f"--resume: {stored} is not readable ({one_line(error)})") from None
    if not isinstance(before, dict):
        raise ValueError(f"--resume: {stored} is not a search config")
    changed = sorted(
        str(key) for key in set(before) | set(recorded) if before.get(key) != recorded.get(key)
    )
    if changed:
        raise ValueError(
            f"--resume: --out {out} holds a search of another config or seed (keys {changed} "
            "differ from its config.yaml); continue it with the same config and --seed, or "
            "start afresh with --overwrite or another --out"
        )


def one_line(error: BaseException) -> str:
    """The first line of ``error``'s message (its kind where it has none)."""
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__

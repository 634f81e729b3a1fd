"""Compile every kernel of every environment id once, into Numba's on-disk cache.

    python -m etsc_envs.compile [--env ID ...]

The suite's closed loops, rules and batch intervals are Numba functions cached on disk
(:mod:`etsc_envs.core.jit`): the first process that needs one compiles it (30–120 s for an
id's loop), every later process loads the machine code in well under a second. This command
pays that first compile ahead, with a progress bar naming what it compiles, so that the first
``gym.make`` and ``step`` of each id (and the first batch evaluation of a paper trigger or a
clock) start at once. It runs each id's kernels the way the suite calls them — a single env's
step, holds and metrics, a native vector env's step, and every rule of :func:`rule_triggers`
in ``predict``, in a single env's rule interval and in a vector env's batch of rule intervals
— on a few sampling instants, so the machine code cached is the machine code later calls load.

The cache lives beside the package's sources (``__pycache__``) where they are writable, as in a
checkout or an editable install, and in the user's cache directory otherwise (Numba's
``NUMBA_CACHE_DIR`` chooses another place). Any edit of the package's sources invalidates it
(:func:`etsc_envs.core.jit.package_source_stamp`); run the command again after one.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import gymnasium as gym
import numpy as np
from gymnasium.envs.registration import load_env_creator
from tqdm import tqdm

import etsc_envs
from etsc_envs.core.compiled_loop import always_accepts
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.papers import paper_of
from etsc_envs.triggers import ClockTrigger
from etsc_envs.triggers.base import RuleTrigger
from etsc_envs.triggers.family import FamilyPoint, family_trigger_class

INSTANTS = 3
"""Sampling instants each piece runs: enough to call every kernel, including a transmission
and a hold."""

CLOCK_EVERY = 2
"""The period (instants) of the clock compiled; any period runs the same machine code."""


class KernelTask(NamedTuple):
    """One piece of an id's compiled code: what it is, and how to run it briefly."""

    env_id: str
    what: str
    run: Callable[[], None]


RuleBuilder = Callable[[gym.Env], RuleTrigger]
"""Builds a rule trigger for a single environment of an id (from its spaces and names)."""


def rule_triggers(env_id: str) -> dict[str, RuleBuilder]:
    """The rules of ``env_id`` that the compiled loop runs, by name: the paper's rule, its
    error-time rule where it has one (:attr:`~etsc_envs.core.paper.Paper.error_time`), its
    parametric family (:mod:`etsc_envs.triggers.family`) and the clock (where the receiver
    takes every transmission, as ``--policy periodic`` then runs the clock rule)."""
    record = paper_of(env_id)
    paper = record.trigger
    builders: dict[str, RuleBuilder] = {"paper rule": lambda env: _rule(paper, env)}
    if record.error_time is not None:
        error_time = record.error_time.trigger
        builders["error-time rule"] = lambda env: _rule(error_time, env)
    if paper.condition is not None:
        family = family_trigger_class(paper)
        builders["trigger family"] = lambda env: _rule(
            family, env, point=FamilyPoint(), sampling_period_s=_loop(env).sampling_period_s
        )
    if env_id not in etsc_envs.PETTINGZOO_ENV_IDS and _takes_every_transmission(env_id):
        builders["clock"] = lambda env: _rule(
            ClockTrigger, env, every=CLOCK_EVERY, sampling_period_s=_loop(env).sampling_period_s
        )
    return builders


def kernel_tasks(env_ids: Sequence[str] | None = None) -> list[KernelTask]:
    """What :func:`main` compiles for each id of ``env_ids`` (default: every Gymnasium and
    PettingZoo id of the package), in order."""
    ids = list(env_ids) if env_ids is not None else _all_ids()
    tasks: list[KernelTask] = []
    for env_id in ids:
        if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
            tasks.append(KernelTask(env_id, "parallel env step", _parallel_step(env_id)))
            continue
        tasks += [
            KernelTask(env_id, "env step, holds and metrics", _single_step(env_id)),
            KernelTask(env_id, "vector env step", _vector_step(env_id)),
        ]
        tasks += [
            KernelTask(env_id, name, _rule_runs(env_id, build))
            for name, build in rule_triggers(env_id).items()
        ]
    return tasks


def _all_ids() -> list[str]:
    return [*etsc_envs.ENV_IDS, *etsc_envs.PETTINGZOO_ENV_IDS]


def _loop(env: gym.Env) -> EventTriggeredEnv:
    """The closed loop under ``env``'s wrappers (``TypeError`` for an env not of the suite)."""
    loop = env.unwrapped
    if not isinstance(loop, EventTriggeredEnv):
        raise TypeError(f"env must wrap an EventTriggeredEnv, got {type(loop).__name__}")
    return loop


def _rule(trigger_class: Callable[..., RuleTrigger], env: gym.Env, **keywords: Any) -> RuleTrigger:
    """A rule trigger class's trigger for ``env``, built with its own constructor arguments
    (not :class:`RuleTrigger`'s): ``env``'s spaces, its observation names and ``keywords``."""
    return trigger_class(
        env.observation_space, env.action_space, tuple(_loop(env).observation_names), **keywords
    )


def _takes_every_transmission(env_id: str) -> bool:
    """Whether the receiver of ``env_id`` takes every transmission (else a clock is a counter,
    not a rule: paper 003's burst refuses transmissions)."""
    env_class = load_env_creator(str(gym.spec(env_id).entry_point))
    if not (isinstance(env_class, type) and issubclass(env_class, EventTriggeredEnv)):
        raise TypeError(f"{env_id} is not an EventTriggeredEnv")
    return env_class.kernels.accepts is always_accepts


def _actions(space: gym.Space, transmit: bool) -> Any:
    if isinstance(space, gym.spaces.Discrete):
        return int(transmit)
    return np.full(space.shape or (), int(transmit), dtype=np.int64)


def _single_step(env_id: str) -> Callable[[], None]:
    def run() -> None:
        for randomize in (False, True):
            env = gym.make(env_id, randomize=randomize)
            env.reset(seed=0)
            for instant in range(INSTANTS):
                env.step(_actions(env.action_space, instant == 0))
            unwrapped = _loop(env)
            unwrapped.run_interval(_actions(env.action_space, True), INSTANTS)
            unwrapped.episode_metrics()
            env.close()

    return run


def _vector_step(env_id: str) -> Callable[[], None]:
    def run() -> None:
        envs = _vector_env(env_id)
        envs.reset(seed=0)
        for instant in range(INSTANTS):
            envs.step(np.stack([_actions(envs.single_action_space, instant == 0)] * 2))
        for env in envs.envs:
            env.episode_metrics()
        envs.close()

    return run


def _vector_env(env_id: str) -> Any:
    return gym.make_vec(
        env_id, num_envs=2, vectorization_mode="vector_entry_point", randomize=True
    ).unwrapped


def _rule_runs(env_id: str, build: RuleBuilder) -> Callable[[], None]:
    """The rule in ``predict``, in a single env's rule interval (with and without its first
    instant forced) and in a vector env's batch of rule intervals."""

    def run() -> None:
        env = gym.make(env_id, randomize=True)
        observation, _ = env.reset(seed=0)
        trigger = build(env)
        trigger.predict(observation)
        trigger.predict(np.stack([observation, observation]))
        unwrapped = _loop(env)
        unwrapped.run_rule_interval(trigger, INSTANTS)
        unwrapped.run_rule_interval(trigger, INSTANTS, send_first=True)
        env.close()
        envs = _vector_env(env_id)
        envs.reset(seed=0)
        rows = envs.num_envs
        envs.run_rule(trigger, INSTANTS, np.zeros(rows), np.zeros((rows, trigger.n_channels)))
        envs.close()

    return run


def _parallel_step(env_id: str) -> Callable[[], None]:
    def run() -> None:
        env = etsc_envs.make_parallel(env_id)
        env.reset(seed=0)
        for instant in range(INSTANTS):
            env.step({agent: int(instant == 0) for agent in env.agents})
        env.close()

    return run


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m etsc_envs.compile",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--env",
        action="append",
        choices=_all_ids(),
        metavar="ID",
        help="compile this id's kernels only (repeatable); default: every id",
    )
    args = parser.parse_args(argv)
    tasks = kernel_tasks(args.env)
    started = time.perf_counter()
    with tqdm(tasks, unit="piece", dynamic_ncols=True) as bar:
        for task in bar:
            bar.set_description(f"compiling {task.env_id}: {task.what}")
            task.run()
    elapsed_s = time.perf_counter() - started
    minutes, seconds = divmod(math.ceil(elapsed_s), 60)
    print(
        f"Compiled {len(tasks)} pieces of {len({task.env_id for task in tasks})} ids in "
        f"{minutes} min {seconds} s; later processes load them from Numba's disk cache."
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Throughput of every environment, single and vectorised, and the papers' reproduction times.

    python -m etsc_envs.benchmark [--steps N] [--repeats R] [--env ID ...]
                                  [--num-envs N ...] [--reproductions [NNN ...]]
                                  [--protocol [K]] [--protocol-policy SPEC]
                                  [--protocol-arg K=V ...] [--json PATH|-]

Every figure is the median of ``R`` timed runs (at least 5 by default) after an untimed warm-up
run that compiles and fills the caches, with the minimum and maximum beside it. Actions are
seeded random bits drawn before the clock starts, so only the environment is timed; an episode
that ends is reset inside the timed loop (its cost is part of the figure).

* ``single_steps_per_s``: one environment made by ``gym.make`` (Gymnasium's default wrappers
  included), ``N`` steps per run.
* ``vector_env_steps_per_s``: the id's native vector environment (``gym.make_vec(...,
  vectorization_mode="vector_entry_point")``) for each ``--num-envs`` (default 1, 16 and 256),
  counted in sub-environment steps, ``max(N, 200 × num_envs)`` of them per run.
* A PettingZoo id is timed as its ``ParallelEnv``, one step being every agent acting once; its
  record adds ``agent_steps_per_s``.
* ``--reproductions``: the wall time of ``python -m baselines.reproduce --paper NNN`` as a user
  runs it (a fresh process, the compiled code cached on disk), for the given papers or all.
* ``--protocol [K]``: the wall time of ``python -m baselines.evaluate ID --policy paper
  --scenarios test --set-size K`` (default K = 64) for every chosen id, as a user runs it;
  the test protocol asks for at most 2 minutes per id (``docs/protocol.md``).
  ``--protocol-policy SPEC`` times another ``--policy`` of ``baselines.evaluate`` instead
  (``periodic``, ``sb3:PATH``, ...), with its ``--protocol-arg K=V`` as ``--policy-arg``.

The JSON is ``{"machine": ..., "envs": {id: {"single_steps_per_s": {"median", "min", "max",
"runs"}, "vector_env_steps_per_s": {"1": {...}, "16": {...}, "256": {...}}}}, "reproductions":
{paper: {"wall_time_s": {...}}}, "protocol": {"set_size": K, "policy": SPEC, "policy_args":
[K=V, ...], "ids": {id: {"wall_time_s": {...}}}}}``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

import gymnasium as gym
import numba
import numpy as np

from etsc_envs import ENV_IDS, PETTINGZOO_ENV_IDS, VECTOR_ENTRY_POINTS, make_parallel
from etsc_envs.core.files import atomic_write_text, output_file_argument

DEFAULT_NUM_ENVS = (1, 16, 256)
VECTOR_CALLS_MIN = 200
"""A vector run makes at least this many batched steps."""
PAPERS = ("000", "001", "002", "003", "004")


def summary(values: list[float]) -> dict[str, Any]:
    """Median, minimum and maximum of the runs, and the runs themselves."""
    return {
        "median": statistics.median(values),
        "min": min(values),
        "max": max(values),
        "runs": values,
    }


def repeat_rate(run: Callable[[int], float], work: int, repeats: int) -> dict[str, Any]:
    """``work / seconds`` of ``repeats`` timed calls ``run(seed)``, seeds 0.., after a warm-up."""
    run(repeats)  # warm-up, with a seed none of the timed runs uses
    return summary([work / run(seed) for seed in range(repeats)])


def random_bits(space: gym.Space, count: int, seed: int) -> np.ndarray:
    """``count`` seeded samples of a ``Discrete(2)`` or ``MultiBinary`` (batch) space."""
    rng = np.random.default_rng(seed + 1)
    shape = () if isinstance(space, gym.spaces.Discrete) else space.shape or ()
    return rng.integers(0, 2, size=(count, *shape))


def time_single_env(env: gym.Env, steps: int, seed: int) -> float:
    """Seconds for ``steps`` random-action steps of ``env`` (resets included)."""
    actions = random_bits(env.action_space, steps, seed)
    env.reset(seed=seed)
    started = time.perf_counter()
    for action in actions:
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    return time.perf_counter() - started


def time_vector_env(env: gym.vector.VectorEnv, calls: int, seed: int) -> float:
    """Seconds for ``calls`` batched random-action steps of ``env`` (autoresets included)."""
    actions = random_bits(env.action_space, calls, seed)
    env.reset(seed=seed)
    started = time.perf_counter()
    for action in actions:
        env.step(action)
    return time.perf_counter() - started


def time_parallel_env(env: Any, steps: int, seed: int) -> float:
    """Seconds for ``steps`` random-action steps of a PettingZoo ``ParallelEnv``."""
    agents = env.possible_agents
    actions = random_bits(gym.spaces.MultiBinary(len(agents)), steps, seed)
    env.reset(seed=seed)
    started = time.perf_counter()
    for bits in actions:
        env.step(dict(zip(agents, bits, strict=True)))
        if not env.agents:
            env.reset()
    return time.perf_counter() - started


def benchmark_gym_id(
    env_id: str, steps: int, repeats: int, num_envs: tuple[int, ...]
) -> dict[str, Any]:
    """Single-env and native-vector-env throughput of a Gymnasium id."""
    env = gym.make(env_id)
    record: dict[str, Any] = {
        "single_steps_per_s": repeat_rate(
            lambda seed: time_single_env(env, steps, seed), steps, repeats
        )
    }
    env.close()
    if env_id in VECTOR_ENTRY_POINTS:
        rates = {}
        for count in num_envs:
            vector = gym.make_vec(env_id, num_envs=count, vectorization_mode="vector_entry_point")
            calls = max(VECTOR_CALLS_MIN, steps // count)
            rates[str(count)] = repeat_rate(
                lambda seed, vector=vector, calls=calls: time_vector_env(vector, calls, seed),
                calls * count,
                repeats,
            )
            vector.close()
        record["vector_env_steps_per_s"] = rates
    return record


def benchmark_pettingzoo_id(env_id: str, steps: int, repeats: int) -> dict[str, Any]:
    """Throughput of a PettingZoo id, in steps and in agent-steps."""
    env = make_parallel(env_id)
    n_agents = len(env.possible_agents)
    steps_rate = repeat_rate(lambda seed: time_parallel_env(env, steps, seed), steps, repeats)
    env.close()
    agent_rate = summary([rate * n_agents for rate in steps_rate["runs"]])
    return {"single_steps_per_s": steps_rate, "agent_steps_per_s": agent_rate, "agents": n_agents}


def time_reproduction(paper: str) -> float:
    """Wall-clock seconds of ``python -m baselines.reproduce --paper NNN`` in a fresh process."""
    command = [sys.executable, "-m", "baselines.reproduce", "--paper", paper]
    started = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - started


def benchmark_reproductions(papers: list[str], repeats: int) -> dict[str, Any]:
    """Median wall time of each paper's reproduction over ``repeats`` runs after a warm-up."""
    results = {}
    for paper in papers:
        time_reproduction(paper)
        results[paper] = {
            "wall_time_s": summary([time_reproduction(paper) for _ in range(repeats)])
        }
    return results


def time_test_set_evaluation(
    env_id: str, set_size: int, policy: str = "paper", policy_args: Sequence[str] = ()
) -> float:
    """Wall-clock seconds of ``policy`` (a ``--policy`` of ``baselines.evaluate``, with its
    ``K=V`` ``policy_args``) on ``set_size`` test scenarios of ``env_id`` (``python -m
    baselines.evaluate`` in a fresh process)."""
    command = [
        sys.executable,
        "-m",
        "baselines.evaluate",
        env_id,
        "--policy",
        policy,
        *[part for pair in policy_args for part in ("--policy-arg", pair)],
        "--scenarios",
        "test",
        "--set-size",
        str(set_size),
    ]
    started = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - started


def benchmark_protocol(
    env_ids: list[str],
    set_size: int,
    repeats: int,
    policy: str = "paper",
    policy_args: Sequence[str] = (),
) -> dict[str, Any]:
    """Median wall time of one policy on the test set of each id, after a warm-up run of one
    scenario that compiles or loads the machine code."""
    results = {}
    for env_id in env_ids:
        time_test_set_evaluation(env_id, 1, policy, policy_args)
        runs = [
            time_test_set_evaluation(env_id, set_size, policy, policy_args) for _ in range(repeats)
        ]
        results[env_id] = {"wall_time_s": summary(runs)}
    return {
        "set_size": set_size,
        "policy": policy,
        "policy_args": list(policy_args),
        "ids": results,
    }


def machine() -> dict[str, Any]:
    """What the figures were measured on."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {
        "cores": cores,
        "processor": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "gymnasium": gym.__version__,
    }


def print_report(payload: dict[str, Any]) -> None:
    """The figures as a table: median [min, max]."""

    def cell(figure: dict[str, Any]) -> str:
        return f"{figure['median']:>11,.0f} [{figure['min']:,.0f}, {figure['max']:,.0f}]"

    for env_id, record in payload["envs"].items():
        print(f"{env_id}")
        print(f"  single env               {cell(record['single_steps_per_s'])} steps/s")
        if "agent_steps_per_s" in record:
            agents = record["agents"]
            print(f"  agent-steps ({agents} agents)    {cell(record['agent_steps_per_s'])} /s")
        for count, figure in record.get("vector_env_steps_per_s", {}).items():
            print(f"  vector env, {count:>4} envs    {cell(figure)} env-steps/s")
    protocol = payload.get("protocol") or {}
    timed = " ".join([protocol.get("policy", "paper"), *protocol.get("policy_args", [])])
    for env_id, record in protocol.get("ids", {}).items():
        figure = record["wall_time_s"]
        print(
            f"{env_id}: {timed} on {protocol['set_size']} test scenarios "
            f"{figure['median']:.1f} s [{figure['min']:.1f}, {figure['max']:.1f}]"
        )
    for paper, record in payload.get("reproductions", {}).items():
        figure = record["wall_time_s"]
        print(
            f"reproduce --paper {paper}: {figure['median']:.1f} s "
            f"[{figure['min']:.1f}, {figure['max']:.1f}]"
        )


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m etsc_envs.benchmark",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--steps", type=int, default=20_000, help="steps per timed run")
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per figure")
    parser.add_argument(
        "--env",
        action="append",
        choices=sorted([*ENV_IDS, *PETTINGZOO_ENV_IDS]),
        help="only these ids (repeatable)",
    )
    parser.add_argument(
        "--num-envs",
        type=int,
        action="append",
        help=f"vector sizes to time (repeatable; default {' '.join(map(str, DEFAULT_NUM_ENVS))})",
    )
    parser.add_argument(
        "--reproductions",
        nargs="*",
        choices=PAPERS,
        metavar="NNN",
        help="also time these papers' reproductions (all if none given)",
    )
    parser.add_argument(
        "--protocol",
        nargs="?",
        type=int,
        const=64,
        metavar="K",
        help="also time the paper trigger on K test scenarios of every chosen id (default 64)",
    )
    parser.add_argument(
        "--protocol-policy",
        default="paper",
        metavar="SPEC",
        help="the --policy of baselines.evaluate that --protocol times (default paper)",
    )
    parser.add_argument(
        "--protocol-arg",
        action="append",
        default=[],
        metavar="K=V",
        help="a --policy-arg of the timed policy (repeatable)",
    )
    parser.add_argument(
        "--json",
        metavar="PATH|-",
        type=output_file_argument("--json"),
        help="write the results as JSON",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.steps < 1 or args.repeats < 1:
        parser.error("--steps and --repeats must be >= 1")
    num_envs = tuple(args.num_envs or DEFAULT_NUM_ENVS)
    if min(num_envs) < 1:
        parser.error("--num-envs must be >= 1")
    if args.protocol is not None and args.protocol < 1:
        parser.error(f"--protocol takes a set size >= 1, got {args.protocol}")
    envs = {}
    for env_id in args.env or [*ENV_IDS, *PETTINGZOO_ENV_IDS]:
        if env_id in PETTINGZOO_ENV_IDS:
            envs[env_id] = benchmark_pettingzoo_id(env_id, args.steps, args.repeats)
        else:
            envs[env_id] = benchmark_gym_id(env_id, args.steps, args.repeats, num_envs)
    payload: dict[str, Any] = {
        "machine": machine(),
        "steps_per_run": args.steps,
        "repeats": args.repeats,
        "envs": envs,
    }
    if args.reproductions is not None:
        papers: list[str] = args.reproductions or list(PAPERS)
        payload["reproductions"] = benchmark_reproductions(papers, args.repeats)
    if args.protocol is not None:
        ids = args.env or [*ENV_IDS, *PETTINGZOO_ENV_IDS]
        payload["protocol"] = benchmark_protocol(
            ids, args.protocol, args.repeats, args.protocol_policy, args.protocol_arg
        )
    if args.json == "-":
        json.dump(payload, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return 0
    if args.json:
        atomic_write_text(args.json, json.dumps(payload, indent=2) + "\n")
    print_report(payload)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

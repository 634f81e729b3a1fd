"""Steps per second of every registered environment (random actions, median of several runs).

    python -m etsc_envs.benchmark [--steps N] [--repeats R] [--env ID ...] [--json PATH|-]

Each run times ``N`` steps of a ``gym.make`` environment (with Gymnasium's default wrappers)
under seeded random actions, resetting when an episode ends; compilation is excluded by a
warm-up episode before timing. The JSON is ``{"envs": {id: {"single_steps_per_s": ...}}}``.
A PettingZoo id (``etsc_envs.PETTINGZOO_ENV_IDS``) is timed as its ``ParallelEnv``, one step
being every agent acting once; its record adds ``agent_steps_per_s`` (steps/s × agents).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import gymnasium as gym

from etsc_envs import ENV_IDS, PETTINGZOO_ENV_IDS, make_parallel


def time_steps(env: gym.Env, steps: int, seed: int) -> float:
    """Wall-clock seconds for ``steps`` random-action steps of ``env`` (resets included)."""
    env.action_space.seed(seed)
    env.reset(seed=seed)
    started = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
    return time.perf_counter() - started


def benchmark_env(env_id: str, steps: int, repeats: int) -> dict[str, float | list[float]]:
    """Median single-environment throughput of ``env_id`` over ``repeats`` timed runs."""
    env = gym.make(env_id)
    time_steps(env, 100, seed=0)  # compile and warm caches
    rates = [steps / time_steps(env, steps, seed=run) for run in range(repeats)]
    env.close()
    return {"single_steps_per_s": statistics.median(rates), "runs_steps_per_s": rates}


def time_parallel_steps(env, steps: int, seed: int) -> float:
    """Wall-clock seconds for ``steps`` random-action steps of a PettingZoo ``ParallelEnv``."""
    for offset, agent in enumerate(env.possible_agents):
        env.action_space(agent).seed(seed + offset)
    env.reset(seed=seed)
    started = time.perf_counter()
    for _ in range(steps):
        env.step({agent: env.action_space(agent).sample() for agent in env.agents})
        if not env.agents:
            env.reset()
    return time.perf_counter() - started


def benchmark_parallel_env(env_id: str, steps: int, repeats: int) -> dict[str, float | list[float]]:
    """Median throughput of the PettingZoo id ``env_id``, in steps and in agent-steps."""
    env = make_parallel(env_id)
    time_parallel_steps(env, 100, seed=0)  # compile and warm caches
    rates = [steps / time_parallel_steps(env, steps, seed=run) for run in range(repeats)]
    n_agents = len(env.possible_agents)
    env.close()
    median = statistics.median(rates)
    return {
        "single_steps_per_s": median,
        "agent_steps_per_s": median * n_agents,
        "agents": n_agents,
        "runs_steps_per_s": rates,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m etsc_envs.benchmark",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--steps", type=int, default=20_000, help="steps per timed run")
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per environment")
    parser.add_argument(
        "--env",
        action="append",
        choices=sorted([*ENV_IDS, *PETTINGZOO_ENV_IDS]),
        help="only these ids",
    )
    parser.add_argument("--json", metavar="PATH|-", help="write the results as JSON")
    args = parser.parse_args(argv)
    if args.steps < 1 or args.repeats < 1:
        parser.error("--steps and --repeats must be >= 1")
    results = {
        env_id: (benchmark_parallel_env if env_id in PETTINGZOO_ENV_IDS else benchmark_env)(
            env_id, args.steps, args.repeats
        )
        for env_id in args.env or [*ENV_IDS, *PETTINGZOO_ENV_IDS]
    }
    payload = {"steps_per_run": args.steps, "repeats": args.repeats, "envs": results}
    if args.json == "-":
        json.dump(payload, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return 0
    if args.json:
        Path(args.json).write_text(json.dumps(payload, indent=2) + "\n")
    for env_id, result in results.items():
        rate = result["single_steps_per_s"]
        agents = (
            f", {result['agent_steps_per_s']:.0f} agent-steps/s ({result['agents']} agents)"
            if "agent_steps_per_s" in result
            else ""
        )
        print(f"{env_id:36s} {rate:10.0f} steps/s (median of {args.repeats}){agents}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

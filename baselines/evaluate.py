"""Evaluate a trigger policy on an environment.

    python -m baselines.evaluate ENV_ID --policy POLICY [--policy-arg k=v ...]
        [--env-arg k=v ...] [--episodes N] [--seed S] [--json PATH|-] [--plot DIR]

POLICY is ``paper`` (the paper's triggering rule), ``periodic`` (``--policy-arg every=K``),
``always``, or ``sb3:PATH_TO_ZIP`` (a trained Stable-Baselines3 model).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import gymnasium as gym

from baselines.cli import (
    POLICY_CHOICES,
    episode_setup,
    limit_torch_threads,
    parse_assignments,
    write_json,
)
from baselines.episodes import mean_record
from baselines.plotting import plot_episode
from etsc_envs.core.files import output_file_argument, output_folder_argument


def evaluate(
    env_id: str,
    policy: str,
    *,
    policy_args: dict[str, Any] | None = None,
    env_args: dict[str, Any] | None = None,
    episodes: int = 1,
    seed: int = 0,
    plot_dir: str | Path | None = None,
    progress: bool = False,
) -> dict[str, Any]:
    """Run ``episodes`` episodes (seeds ``seed, seed+1, ...``) and return the design page's JSON.

    Returns ``{"env", "policy", "policy_args", "env_args", "episodes": [...], "mean": {...}}``.
    For a PettingZoo id (:data:`etsc_envs.PETTINGZOO_ENV_IDS`) one policy serves every agent
    and the records also hold each agent's values under ``agents``.
    """
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    policy_args, env_args = dict(policy_args or {}), dict(env_args or {})
    env, make_trigger, runner = episode_setup(env_id, env_args)
    trigger = make_trigger(policy, policy_args)
    records = []
    for episode in range(episodes):
        record, trace = runner(
            env,
            trigger,
            seed + episode,
            sample_every=None,
            progress=progress,
            description=f"{policy} episode {episode + 1}/{episodes}",
        )
        records.append(record)
        if plot_dir is not None:
            title = f"{env_id} - {policy} {policy_args or ''} - seed {seed + episode}"
            plot_episode(trace, Path(plot_dir) / f"episode_{episode:03d}.png", title)
    env.close()
    return {
        "env": env_id,
        "policy": policy,
        "policy_args": policy_args,
        "env_args": env_args,
        "episodes": records,
        "mean": mean_record(records),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m baselines.evaluate",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "env_id",
        help="a registered Gymnasium or PettingZoo id, e.g. etsc/AttitudeTracking-v0",
    )
    parser.add_argument("--policy", required=True, help=POLICY_CHOICES)
    parser.add_argument("--policy-arg", action="append", metavar="K=V", help="policy parameter")
    parser.add_argument("--env-arg", action="append", metavar="K=V", help="environment kwarg")
    parser.add_argument("--episodes", type=int, default=1)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--json",
        metavar="PATH|-",
        type=output_file_argument("--json"),
        help="write the results as JSON",
    )
    parser.add_argument(
        "--plot",
        metavar="DIR",
        type=output_folder_argument("--plot"),
        help="write one figure per episode",
    )
    args = parser.parse_args(argv)
    limit_torch_threads()
    try:
        result = evaluate(
            args.env_id,
            args.policy,
            policy_args=parse_assignments(args.policy_arg, "--policy-arg"),
            env_args=parse_assignments(args.env_arg, "--env-arg"),
            episodes=args.episodes,
            seed=args.seed,
            plot_dir=args.plot,
            progress=sys.stderr.isatty(),
        )
    except (ValueError, TypeError, gym.error.Error) as error:
        parser.error(str(error))
    if args.json:
        write_json(result, args.json)
    if args.json != "-":
        print(f"{result['env']}  policy={result['policy']} {result['policy_args'] or ''}")
        for key, value in result["mean"].items():
            if not isinstance(value, dict):
                print(f"  {key:>22s}  {value:.6g}")
        for agent, values in result["mean"].get("agents", {}).items():
            print(f"  {agent}: " + ", ".join(f"{k}={v:.6g}" for k, v in values.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

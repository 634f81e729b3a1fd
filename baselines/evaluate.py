"""Evaluate a trigger policy on an environment.

    python -m baselines.evaluate ENV_ID --policy POLICY [--policy-arg k=v ...]
        [--env-arg k=v ...] [--scenarios paper|validation|test [--set-size K]]
        [--episodes N] [--seed S] [--json PATH|-] [--plot DIR] [--windows T0,T1,...]

POLICY is ``paper`` (the paper's triggering rule; ``--policy-arg heartbeat=H`` pairs it with a
heartbeat, a transmission on every channel once H instants passed without one, and
``floor=F`` gates it with a clock, a channel transmitting only once F instants have passed
since its last transmission; with both, as always taking the self-triggered decision
"paper × f, floor F" whose interval cap is H), ``error_time``
(paper 004's error-time rule, ``--policy-arg area=A`` in m·s,
:attr:`etsc_envs.core.paper.Paper.error_time`; ``heartbeat=H`` pairs it too), ``periodic``
(``--policy-arg every=K``; with ``then_every=K2`` and ``switch_after=N`` the period becomes
K2 at instant N), ``always``, ``sb3:PATH_TO_ZIP`` (a trained Stable-Baselines3
model), or ``learned:PATH`` (a learned trigger file of ``agents.search``; ``--policy-arg
heartbeat_instants=H``, ``floor_instants=F`` or ``exponent=P`` replaces that component of its
θ, ``heartbeat_instants=inf`` removing the heartbeat). ``--scenarios`` runs a fixed scenario
set of the test protocol (docs/protocol.md); ``--episodes/--seed`` run ad-hoc draws instead.
The JSON holds every episode's record, the means, and the aggregates with 95 % intervals
(mean, median, IQM of mean_cost, transmissions and return; failure rate). ``--windows
0,20,60,300`` splits every episode by time: each record gets the summed per-step cost and the
transmissions of each window (``windows``), and the result their means over the episodes, to
see where in an episode a trigger gains or loses.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from baselines.batch import process_count, run_batch, run_batch_in_processes
from baselines.cli import limit_torch_threads, parse_assignments, write_json
from baselines.episodes import mean_record, window_edges
from baselines.plotting import plot_episode
from baselines.policy_specs import POLICY_CHOICES, episode_setup
from baselines.statistics import aggregate_lines, aggregate_records
from etsc_envs.core.files import output_file_argument, output_folder_argument
from etsc_envs.protocol import DEFAULT_SET_SIZE, SCENARIO_SET_NAMES, scenario_set


def evaluate(
    env_id: str,
    policy: str,
    *,
    policy_args: dict[str, Any] | None = None,
    env_args: dict[str, Any] | None = None,
    episodes: int = 1,
    seed: int = 0,
    scenarios: str | None = None,
    set_size: int = DEFAULT_SET_SIZE,
    plot_dir: str | Path | None = None,
    windows_s: Sequence[float] | None = None,
    progress: bool = False,
    processes: int | None = None,
) -> dict[str, Any]:
    """Run ``policy`` on a scenario set, or on ``episodes`` ad-hoc episodes (seeds ``seed,
    seed+1, ...``), and return the design page's JSON with the protocol's aggregates.

    Args:
        scenarios: ``"paper"``, ``"validation"`` or ``"test"`` (:mod:`etsc_envs.protocol`);
            when given, ``episodes`` and ``seed`` are not used.
        set_size: scenarios of the validation or test set.
        plot_dir: write one figure per episode (runs the episodes one by one).
        windows_s: edges of time windows (s, at least two, strictly increasing): each record
            gets ``windows``, the summed cost and the transmissions of each window
            (:meth:`baselines.episodes.EpisodeTrace.window_totals`), and the result the means
            over the episodes (runs the episodes one by one).
        processes: worker processes sharing a batch
            (:func:`baselines.batch.run_batch_in_processes`); ``None`` takes
            :func:`baselines.batch.process_count`'s, 1 runs it in this process.

    Episodes without plots or windows run at once in the id's native vector env
    (:func:`baselines.batch.run_batch`), a single one too (the paper scenario), so that a rule
    or a clock runs inside the compiled loop; the records equal the one-by-one runs'.

    Returns ``{"env", "policy", "policy_args", "env_args", "scenarios", "episodes": [...],
    "mean": {...}, "aggregates": {...}}``, with ``"windows": [...]`` when ``windows_s`` is
    given. For a PettingZoo id
    (:data:`etsc_envs.PETTINGZOO_ENV_IDS`) one policy serves every agent and the records also
    hold each agent's values under ``agents``.
    """
    policy_args, env_args = dict(policy_args or {}), dict(env_args or {})
    if scenarios is not None:
        chosen = scenario_set(scenarios, set_size)
        env_args, seeds = chosen.env_kwargs(env_args), list(chosen.seeds)
        described = chosen.describe()
    else:
        if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
            raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
        seeds, described = [seed + episode for episode in range(episodes)], None
    edges = None if windows_s is None else window_edges(windows_s)
    setup = episode_setup(env_id, env_args)
    if edges is not None:
        horizon_s = _horizon_s(setup.env)
        if edges[0] >= horizon_s:
            setup.env.close()
            raise ValueError(
                f"--windows: the first window must start inside the episode's horizon of "
                f"{horizon_s:g} s (else every window is empty), got "
                f"{', '.join(f'{edge:g}' for edge in edges)}"
            )
    trigger = setup.make_policy(policy, policy_args)
    records: list[dict[str, Any]] = []
    try:
        if plot_dir is None and edges is None:
            setup.env.close()
            processes = process_count(len(seeds)) if processes is None else processes
            description = f"{policy} on {len(seeds)} scenario" + ("s" if len(seeds) > 1 else "")
            if processes > 1:
                records[:] = run_batch_in_processes(
                    env_id,
                    policy,
                    policy_args,
                    seeds,
                    env_args,
                    processes=processes,
                    progress=progress,
                    description=description,
                )
            else:
                records[:] = run_batch(
                    env_id, trigger, seeds, env_args, progress=progress, description=description
                )
        else:
            for index, episode_seed in enumerate(seeds):
                record, trace = setup.run(
                    setup.env,
                    trigger,
                    episode_seed,
                    sample_every=None,
                    progress=progress,
                    description=f"{policy} episode {index + 1}/{len(seeds)}",
                )
                if edges is not None:
                    record["windows"] = trace.window_totals(edges)
                records.append(record)
                if plot_dir is not None:
                    title = f"{env_id} - {policy} {policy_args or ''} - seed {episode_seed}"
                    plot_episode(trace, Path(plot_dir) / f"episode_{index:03d}.png", title)
            setup.env.close()
    except KeyboardInterrupt:
        setup.env.close()
        raise EvaluationInterrupted(
            {**_result(env_id, policy, policy_args, env_args, described, records), "partial": True},
            len(seeds),
        ) from None
    result = _result(env_id, policy, policy_args, env_args, described, records)
    if edges is not None:
        result["windows"] = _mean_windows(records)
    return result


class EvaluationInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`evaluate`: ``result`` holds the records of the episodes that
    finished before it (``"partial": true``), ``planned`` the number of episodes asked for.
    Episodes run together in a batch (no plots, no windows) finish together, so an interrupted
    batch has none; episodes run one by one keep every one that ended."""

    def __init__(self, result: dict[str, Any], planned: int) -> None:
        super().__init__()
        self.result = result
        self.planned = planned


def _result(
    env_id: str,
    policy: str,
    policy_args: dict[str, Any],
    env_args: dict[str, Any],
    described: dict[str, Any] | None,
    records: list[dict[str, Any]],
) -> dict[str, Any]:
    """The JSON of :func:`evaluate` for ``records`` (no means nor aggregates of no record)."""
    return {
        "env": env_id,
        "policy": policy,
        "policy_args": policy_args,
        "env_args": env_args,
        "scenarios": described,
        "episodes": records,
        "mean": mean_record(records) if records else {},
        "aggregates": aggregate_records(records) if records else {},
    }


def _mean_windows(records: list[dict[str, Any]]) -> list[dict[str, float]]:
    """Each window's cost and transmissions averaged over the episodes' ``windows``."""
    return [
        {
            "from_s": window["from_s"],
            "to_s": window["to_s"],
            "cost": float(np.mean([record["windows"][i]["cost"] for record in records])),
            "transmissions": float(
                np.mean([record["windows"][i]["transmissions"] for record in records])
            ),
        }
        for i, window in enumerate(records[0]["windows"])
    ]


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
    parser.add_argument(
        "--scenarios",
        choices=SCENARIO_SET_NAMES,
        help="a fixed scenario set of the test protocol (instead of --episodes/--seed)",
    )
    parser.add_argument(
        "--set-size",
        type=positive_integer,
        default=DEFAULT_SET_SIZE,
        metavar="K",
        help=f"scenarios of the validation or test set (default {DEFAULT_SET_SIZE})",
    )
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
    parser.add_argument(
        "--windows",
        metavar="T0,T1,...",
        type=_window_edges_argument,
        help="split each episode by time at these instants (s): the summed cost and the "
        "transmissions of every window",
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
            scenarios=args.scenarios,
            set_size=args.set_size,
            plot_dir=args.plot,
            windows_s=args.windows,
            progress=sys.stderr.isatty(),
        )
    except (ValueError, TypeError, gym.error.Error) as error:
        parser.error(str(error))
    except EvaluationInterrupted as interrupted:
        finished = len(interrupted.result["episodes"])
        where = "not written (no --json)"
        if args.json:
            write_json(interrupted.result, args.json)
            output = "standard output" if args.json == "-" else args.json
            where = f"written to {output}, marked partial"
        print(
            f"interrupted: {finished} of {interrupted.planned} episode(s) finished, their "
            f"records {where}",
            file=sys.stderr,
        )
        return 130
    except KeyboardInterrupt:
        print("interrupted before any episode ran; nothing written", file=sys.stderr)
        return 130
    if args.json:
        write_json(result, args.json)
    summary = sys.stderr if args.json == "-" else sys.stdout
    print(_summary_text(result), file=summary)
    return 0


def _horizon_s(env: Any) -> float:
    """The episode length of ``env`` (a Gymnasium env or a PettingZoo parallel env)."""
    unwrapped = env.unwrapped
    return float(getattr(unwrapped, "loop", unwrapped).horizon_s)


def positive_integer(text: str) -> int:
    """``--set-size`` of every command that judges on a scenario set: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"takes an integer >= 1 (scenarios), got {text!r}")
    return value


def _window_edges_argument(text: str) -> tuple[float, ...]:
    """``--windows``' comma-separated seconds, checked by :func:`window_edges`."""
    try:
        return window_edges([float(word) for word in text.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(
            "takes at least two comma-separated times >= 0 in seconds, strictly increasing "
            f"(e.g. 0,20,60,300), got {text!r}"
        ) from None


def _summary_text(result: dict[str, Any]) -> str:
    """The means of every numeric key and the aggregates with their 95 % intervals."""
    scenarios = result["scenarios"]
    where = (
        f"{scenarios['name']} set, {scenarios['size']} scenario(s)"
        if scenarios
        else f"{len(result['episodes'])} episode(s)"
    )
    lines = [f"{result['env']}  policy={result['policy']} {result['policy_args'] or ''} ({where})"]
    for key, value in result["mean"].items():
        if isinstance(value, int | float):
            lines.append(f"  {key:>22s}  {value:.6g}")
    for agent, values in result["mean"].get("agents", {}).items():
        lines.append(f"  {agent}: " + ", ".join(f"{k}={v:.6g}" for k, v in values.items()))
    lines.append("  aggregates (95 % intervals):")
    lines.extend(f"    {line}" for line in aggregate_lines(result["aggregates"]))
    if "windows" in result:
        lines.append("  windows (means over the episodes):")
        for window in result["windows"]:
            span = f"{window['from_s']:g}-{window['to_s']:g} s"
            lines.append(
                f"    {span:>16s}  cost {window['cost']:.6g}  "
                f"transmissions {window['transmissions']:.6g}"
            )
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())

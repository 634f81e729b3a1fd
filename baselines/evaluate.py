"""Evaluate a trigger policy on an environment.

    python -m baselines.evaluate ENV_ID --policy POLICY [--policy-arg k=v ...]
        [--env-arg k=v ...] [--scenarios paper|validation|test [--set-size K]]
        [--episodes N] [--seed S] [--reference paper|none] [--json PATH|-] [--plot DIR]
        [--windows T0,T1,...]

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
The JSON holds every episode's record, the means, the aggregates with 95 % intervals
(mean, median, IQM of mean_cost, transmissions and return; failure rate) and, with
``--reference paper``, the paired comparison with the paper's rule on the same scenarios.
``--windows 0,20,60,300`` splits every episode by time: each record gets the summed per-step cost
and the transmissions of each window (``windows``), and the result their means over the episodes, to
see where in an episode a trigger gains or loses.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from baselines.plotting import plot_episode
from etsc_envs.cli import evaluate_arguments, run_evaluation
from etsc_envs.core.files import output_folder_argument
from etsc_envs.evaluation import evaluate as evaluate_policy
from etsc_envs.evaluation.episodes import EpisodeTrace, window_edges
from etsc_envs.protocol import DEFAULT_SET_SIZE


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
    """:func:`etsc_envs.evaluate` of the spec ``policy`` without a reference, as its JSON
    (:meth:`~etsc_envs.evaluation.Evaluation.to_json`): on the scenario set ``scenarios`` of
    ``set_size``, or on ``episodes`` ad-hoc episodes (seeds ``seed, seed+1, ...``), with one
    figure per episode in ``plot_dir``."""
    return evaluate_policy(
        policy,
        env_id,
        scenarios,
        size=set_size,
        episodes=None if scenarios is not None else episodes,
        seed=seed,
        policy_args=policy_args,
        env_args=env_args,
        reference=None,
        progress=progress,
        processes=processes,
        windows_s=windows_s,
        on_episode=None if plot_dir is None else _plotter(env_id, policy, policy_args, plot_dir),
    ).to_json()


def _plotter(
    env_id: str, policy: str, policy_args: dict[str, Any] | None, plot_dir: str | Path
) -> Any:
    """The ``on_episode`` hook that writes one figure per episode into ``plot_dir``."""

    def plot(index: int, record: dict[str, Any], trace: EpisodeTrace) -> None:
        title = f"{env_id} - {policy} {policy_args or ''} - seed {record['seed']}"
        plot_episode(trace, Path(plot_dir) / f"episode_{index:03d}.png", title)

    return plot


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m baselines.evaluate",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    evaluate_arguments(parser, scenarios=None)
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
    hook = None if args.plot is None else _plotter(args.env_id, args.policy, None, args.plot)
    return run_evaluation(parser, args, windows_s=args.windows, on_episode=hook)


def _window_edges_argument(text: str) -> tuple[float, ...]:
    """``--windows``' comma-separated seconds, checked by :func:`window_edges`."""
    try:
        return window_edges([float(word) for word in text.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(
            "takes at least two comma-separated times >= 0 in seconds, strictly increasing "
            f"(e.g. 0,20,60,300), got {text!r}"
        ) from None


if __name__ == "__main__":
    raise SystemExit(main())

"""Wall time of judging a self-triggered model: decision by decision against instant by
instant.

    python -m agents.bench.judging ENV_ID --model PATH [--set-size K] [--repeats R]

:func:`etsc_envs.evaluation.batch.run_batch` runs a
:class:`~etsc_envs.decisions.SelfTriggeredPolicy` decision by decision (one model call per decision
for the rows still running, each interval in one compiled call); any other policy is asked once per
sampling instant for the whole batch. This command times both on the first ``K`` scenarios of the
test set, in one process: the model as loaded, and the same policy seen only through its
``predict`` (so that :func:`~etsc_envs.evaluation.batch.run_batch` takes the per-instant path). It
checks that both give the same transmissions and costs, and prints the median [min-max] wall time
of ``R`` runs of each.
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

from agents.bench import require_counts
from etsc_envs.cli import positive_integer
from etsc_envs.decisions import SelfTriggeredPolicy
from etsc_envs.evaluation.arguments import limit_torch_threads
from etsc_envs.evaluation.batch import run_batch
from etsc_envs.evaluation.policy_specs import episode_setup
from etsc_envs.protocol import scenario_set


class PerInstant:
    """``policy`` behind its ``predict`` alone: the batch asks it every instant."""

    def __init__(self, policy: Any) -> None:
        self.policy = policy

    def predict(self, *args: Any, **kwargs: Any) -> Any:
        return self.policy.predict(*args, **kwargs)


def timed(
    env_id: str, policy: Any, seeds: list[int], env_kwargs: dict[str, Any]
) -> tuple[float, list[tuple[float, float]]]:
    """Wall seconds of one batch, and its records' (transmissions, mean_cost) per scenario."""
    start = time.perf_counter()
    records = run_batch(env_id, policy, seeds, env_kwargs)
    outcome = [(record["transmissions"], record["mean_cost"]) for record in records]
    return time.perf_counter() - start, outcome


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.bench.judging", description=(__doc__ or "").split("\n\n")[0]
    )
    parser.add_argument("env_id", help="a Gymnasium id of the suite")
    parser.add_argument("--model", required=True, help="a self-triggered SB3 zip")
    parser.add_argument(
        "--set-size", type=positive_integer, default=8, help="test scenarios (default 8)"
    )
    parser.add_argument("--repeats", type=int, default=3, help="timed runs of each path")
    args = parser.parse_args(argv)
    require_counts(parser, args, "repeats")
    limit_torch_threads()
    try:  # the id, the set and the model are checked before anything is timed
        scenarios = scenario_set("test", args.set_size)
        env_kwargs = scenarios.env_kwargs({})
        setup = episode_setup(args.env_id, env_kwargs)
        policy = setup.make_policy(f"sb3:{args.model}", {})
        setup.env.close()
    except ValueError as error:
        parser.error(str(error))
    if not isinstance(policy, SelfTriggeredPolicy):
        parser.error(
            f"--model: {args.model} does not take self-triggered decisions on {args.env_id} "
            "(a model saved with its decision set, on a Gymnasium id)"
        )
    seeds = list(scenarios.seeds)
    runners = {"decision by decision": policy, "instant by instant": PerInstant(policy)}
    times: dict[str, list[float]] = {name: [] for name in runners}
    outcomes = set()
    for _ in range(args.repeats):
        for name, runner in runners.items():
            seconds, outcome = timed(args.env_id, runner, seeds, env_kwargs)
            times[name].append(seconds)
            outcomes.add(tuple(outcome))
    if len(outcomes) != 1:
        raise SystemExit("the two paths gave different episodes")
    for name, values in times.items():
        print(
            f"{args.env_id} {args.model} on {len(seeds)} test scenarios, {name}: "
            f"{statistics.median(values):.1f} s [{min(values):.1f}-{max(values):.1f}]"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

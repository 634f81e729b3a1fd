"""Throughput of self-triggered decisions (:class:`etsc_envs.decisions.SelfTriggeredWrapper`).

    python -m agents.bench.decisions [--env ID ...] [--repeats R] [--per-instant]

For each id, three policies: a fixed hold of 2^6 instants, always "follow the paper" (the
paper's rule at its own threshold), and uniformly random decisions (the default decision set:
holds 1..1024 and the paper's rule with its threshold scaled by 0.5, 1, 2 or 4). Each figure
is the median [min-max] of ``R`` timed runs after an untimed warm-up, in decisions per second
and in env steps (sampling instants) per second, per second of wall time and per second of the
process's CPU time (steadier on a shared machine); the env is the id's default scenario made by
``gym.make``, reset inside the timed loop when an episode ends. ``--per-instant`` puts a plain
``gym.Wrapper`` between the decision wrapper and the env, so that every instant is one
``env.step`` call (the design before the compiled intervals).
"""

from __future__ import annotations

import argparse
import statistics
import time

import gymnasium as gym
import numpy as np

import etsc_envs
from agents.bench import require_counts
from etsc_envs.decisions import DecisionSet, Hold, SelfTriggeredWrapper, TriggerAction
from etsc_envs.triggers.family import FamilyPoint

DEFAULT_IDS = ("etsc/AttitudeTracking-v0", "etsc/InnerFormation-v0")
HOLD_EXPONENTS = range(11)
"""The benchmark set's holds: 2^0 .. 2^10 = 1024 instants."""
FACTORS = (0.5, 1.0, 2.0, 4.0)
"""The benchmark set's scalings of the paper rule's thresholds."""
HOLD_ACTION = 6
"""Hold 2^6 = 64 instants."""
DECISIONS = {"hold": 3000, "paper": 3000, "random": 2000}
"""Decisions per timed run."""
RATES = ("decisions_per_s", "steps_per_s", "decisions_per_cpu_s", "steps_per_cpu_s")


def time_decisions(
    wrapper: SelfTriggeredWrapper, policy: str, decisions: int, seed: int
) -> tuple[float, float, int]:
    """Wall and CPU seconds taken by ``decisions`` decisions of ``policy`` (``"hold"``,
    ``"paper"`` or ``"random"``), and the env steps they ran."""
    rng = np.random.default_rng(seed)
    n_actions = int(wrapper.action_space.n)
    fixed = {
        "hold": HOLD_ACTION,
        "paper": wrapper.decisions.action("paper x1"),
    }
    actions = (
        np.full(decisions, fixed[policy])
        if policy in fixed
        else rng.integers(0, n_actions, size=decisions)
    )
    wrapper.reset(seed=seed)
    steps = 0
    start, start_cpu = time.perf_counter(), time.process_time()
    for action in actions:
        _, _, terminated, truncated, info = wrapper.step(int(action))
        steps += info["elapsed_steps"]
        if terminated or truncated:
            wrapper.reset()
    return time.perf_counter() - start, time.process_time() - start_cpu, steps


def benchmark_decisions(env_id: str) -> DecisionSet:
    """The benchmark's decision set for ``env_id``: holds of 2^j instants (j in
    :data:`HOLD_EXPONENTS`), then the paper's rule with its thresholds scaled by each of
    :data:`FACTORS`, capped at the longest hold; no shield."""
    holds = [Hold(2**exponent) for exponent in HOLD_EXPONENTS]
    groups = TriggerAction().scaled_groups(env_id)
    rules = [
        TriggerAction(FamilyPoint({group: factor for group in groups}), cap=holds[-1].instants)
        for factor in FACTORS
    ]
    return DecisionSet(env_id, (*holds, *rules))


def make_wrapper(env_id: str, per_instant: bool) -> SelfTriggeredWrapper:
    """The decision wrapper over ``gym.make(env_id)`` (behind a plain wrapper if
    ``per_instant``) with :func:`benchmark_decisions`."""
    env = gym.make(env_id)
    wrapper_env = gym.Wrapper(env) if per_instant else env
    return SelfTriggeredWrapper(wrapper_env, benchmark_decisions(env_id))


def rates(env_id: str, policy: str, repeats: int, per_instant: bool) -> dict[str, list[float]]:
    """Decisions and env steps per wall and per CPU second of ``repeats`` timed runs after a
    warm-up."""
    wrapper = make_wrapper(env_id, per_instant)
    decisions = DECISIONS[policy]
    time_decisions(wrapper, policy, decisions, seed=repeats)
    record: dict[str, list[float]] = {name: [] for name in RATES}
    for seed in range(repeats):
        wall, cpu, steps = time_decisions(wrapper, policy, decisions, seed)
        pairs = ((decisions, wall), (steps, wall), (decisions, cpu), (steps, cpu))
        for name, (work, seconds) in zip(RATES, pairs, strict=True):
            record[name].append(work / seconds)
    return record


def summary(values: list[float]) -> str:
    """``median [min-max]``."""
    return f"{statistics.median(values):,.0f} [{min(values):,.0f}-{max(values):,.0f}]"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.bench.decisions", description=(__doc__ or "").split("\n\n")[0]
    )
    parser.add_argument("--env", nargs="+", default=list(DEFAULT_IDS), help="Gymnasium ids")
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per figure")
    parser.add_argument(
        "--per-instant", action="store_true", help="one env.step per instant (no compiled holds)"
    )
    args = parser.parse_args(argv)
    require_counts(parser, args, "repeats")
    unknown = [env_id for env_id in args.env if env_id not in etsc_envs.ENV_IDS]
    if unknown:
        parser.error(
            f"--env: {unknown} are not Gymnasium ids of the suite {sorted(etsc_envs.ENV_IDS)}"
        )
    for env_id in args.env:
        for policy in DECISIONS:
            record = rates(env_id, policy, args.repeats, args.per_instant)
            figures = ", ".join(f"{summary(record[name])} {name}" for name in RATES)
            print(f"{env_id} {policy}: {figures}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""The test protocol of the benchmark: fixed, versioned scenario sets (``docs/protocol.md``).

Every id is judged on three sets of scenarios:

* ``paper`` — the paper's own scenario (``randomize=False``, seed 0), one episode;
* ``validation`` — ``size`` draws of ``randomize=True`` with the seeds
  ``VALIDATION_SEEDS.start, VALIDATION_SEEDS.start + 1, ...``: model selection, checkpoint
  choice and hyperparameters;
* ``test`` — ``size`` draws with the seeds ``TEST_SEEDS.start, ...``: reporting only.

A scenario is fully determined by its seed: ``env.reset(seed=s)`` of an env made with
``randomize=True`` (and otherwise the same keywords) draws the same initial conditions and
disturbance phases on every machine. Both seed ranges are reserved: training refuses to seed
an environment inside them (:func:`require_training_seeds`), so no training run ever draws a
validation or test scenario through its seed.

    >>> from etsc_envs.protocol import scenario_set
    >>> test = scenario_set("test", size=64)
    >>> test.env_args, test.seeds[:2]
    ({'randomize': True}, (2000000, 2000001))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

PROTOCOL_VERSION = 1
"""Bumped whenever a set's seeds or the meaning of a scenario changes; results quote it."""

SCENARIO_SET_NAMES = ("paper", "validation", "test")
"""The names accepted by :func:`scenario_set` and by every ``--scenarios`` option."""

DEFAULT_SET_SIZE = 64
"""Scenarios in the validation and the test set unless a size is given."""

VALIDATION_SEEDS = range(1_000_000, 2_000_000)
"""Seeds reserved for the validation set (a set of size K takes the first K)."""

TEST_SEEDS = range(2_000_000, 3_000_000)
"""Seeds reserved for the test set (a set of size K takes the first K)."""

RESERVED_SEEDS = {"validation": VALIDATION_SEEDS, "test": TEST_SEEDS}

PAPER_SEED = 0
"""The seed of the paper scenario (it draws nothing: ``randomize=False``)."""


@dataclass(frozen=True)
class ScenarioSet:
    """A named, fixed set of scenarios: the env keywords that select them and one seed each."""

    name: str
    env_args: dict[str, Any]
    """Keywords every scenario of the set is built with (``randomize``)."""
    seeds: tuple[int, ...]
    """The reset seed of each scenario, in order."""

    @property
    def size(self) -> int:
        return len(self.seeds)

    def env_kwargs(self, base: dict[str, Any] | None = None) -> dict[str, Any]:
        """``base`` keywords with the set's own applied, or ``ValueError`` if ``base`` sets
        one of them to another value (a scenario set fixes ``randomize``)."""
        base = dict(base or {})
        for key, value in self.env_args.items():
            if key in base and base[key] != value:
                raise ValueError(
                    f"--env-arg {key}={base[key]!r} contradicts the {self.name!r} scenario set, "
                    f"which uses {key}={value!r}"
                )
        return {**base, **self.env_args}

    def describe(self) -> dict[str, Any]:
        """The set as JSON: name, protocol version, size and seed range."""
        return {
            "name": self.name,
            "protocol_version": PROTOCOL_VERSION,
            "size": self.size,
            "env_args": dict(self.env_args),
            "seeds": [self.seeds[0], self.seeds[-1]],
        }


def scenario_set(name: str, size: int = DEFAULT_SET_SIZE) -> ScenarioSet:
    """The scenario set ``name`` (one of :data:`SCENARIO_SET_NAMES`) with ``size`` scenarios
    (ignored for ``paper``, which has one).

    Raises ``ValueError`` naming the argument for an unknown name or a size outside
    ``1 .. len(range)``.
    """
    if name not in SCENARIO_SET_NAMES:
        raise ValueError(f"scenarios must be one of {SCENARIO_SET_NAMES}, got {name!r}")
    if name == "paper":
        return ScenarioSet("paper", {"randomize": False}, (PAPER_SEED,))
    reserved = RESERVED_SEEDS[name]
    if isinstance(size, bool) or not isinstance(size, int) or not 1 <= size <= len(reserved):
        raise ValueError(
            f"size: the size of a scenario set must be an integer in 1..{len(reserved)}, "
            f"got {size!r}"
        )
    return ScenarioSet(name, {"randomize": True}, tuple(reserved[:size]))


def reserved_overlap(first_seed: int, count: int) -> str | None:
    """The name of the reserved set that seeds ``first_seed .. first_seed + count - 1``
    touch, or ``None``."""
    last_seed = first_seed + count - 1
    for name, reserved in RESERVED_SEEDS.items():
        if first_seed <= reserved[-1] and last_seed >= reserved[0]:
            return name
    return None


def require_training_seeds(first_seed: int, count: int, argument: str = "seed") -> int:
    """``first_seed``, or ``ValueError`` naming ``argument`` if a training run that seeds
    ``count`` environments with ``first_seed, first_seed + 1, ...`` would draw a validation
    or test scenario."""
    overlap = reserved_overlap(first_seed, count)
    if overlap is not None:
        reserved = RESERVED_SEEDS[overlap]
        raise ValueError(
            f"{argument}={first_seed} with {count} environment(s) would seed inside the "
            f"{overlap} scenarios ({reserved.start}..{reserved.stop - 1}), which training never "
            f"uses; choose a seed below {VALIDATION_SEEDS.start - count + 1} or from "
            f"{TEST_SEEDS.stop} on"
        )
    return first_seed

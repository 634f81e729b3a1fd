"""The benchmark as a library call: :func:`evaluate` scores any trigger on the protocol's
scenario sets and compares it with the paper's rule on the same scenarios.

    >>> import etsc_envs
    >>> every_10 = lambda obs: 1 if ... else 0            # any obs -> action callable
    >>> result = etsc_envs.evaluate(every_10, "etsc/AttitudeTracking-v0", size=8)
    >>> result.comparison["verdict"]["outcome"]           # beats | better | ties | ... | loses

``python -m baselines.evaluate`` and ``etsc-envs evaluate`` are commands over this function
(:mod:`etsc_envs.cli`); their JSON is :meth:`Evaluation.to_json`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import gymnasium as gym
import numpy as np

import etsc_envs
from etsc_envs.evaluation.arguments import model_spec
from etsc_envs.evaluation.batch import process_count, run_batch, run_batch_in_processes
from etsc_envs.evaluation.episodes import EpisodeTrace, mean_record, window_edges
from etsc_envs.evaluation.leaderboard import LeaderboardRow, leaderboard
from etsc_envs.evaluation.policy_specs import NAMED_POLICIES, POLICY_CHOICES, episode_setup
from etsc_envs.evaluation.statistics import aggregate_lines, aggregate_records, paired_ratio
from etsc_envs.evaluation.verdict import Verdict, compare, difference_axis, ratio_axis
from etsc_envs.papers import paper_of
from etsc_envs.protocol import DEFAULT_SET_SIZE, scenario_set
from etsc_envs.triggers.base import RuleTrigger

EpisodeHook = Callable[[int, dict[str, Any], EpisodeTrace], None]
"""``(index, record, trace)`` after each episode run one by one (a figure per episode)."""


@dataclass
class Evaluation:
    """One policy on one scenario set: its episode records, their statistics, and its paired
    comparison with a reference policy on the same scenarios.

    Attributes:
        env_id: the id the policy ran on.
        policy: the policy as named (a spec such as ``paper`` or ``learned:PATH``, or the
            class of a policy object).
        policy_args: the spec's keywords.
        env_args: the env keywords every scenario used (the set's ``randomize`` included).
        scenarios: the scenario set (:meth:`etsc_envs.protocol.ScenarioSet.describe`), or
            ``None`` for an ad-hoc draw of seeds.
        records: one record per finished episode (the design page's keys, ``seed`` first).
        planned: the episodes asked for (more than ``len(records)`` after an interrupt).
        reference: the reference policy's evaluation on the same scenarios, or ``None``.
        windows_s: the edges of the time windows each record splits into (``windows``).
    """

    env_id: str
    policy: str
    policy_args: dict[str, Any]
    env_args: dict[str, Any]
    scenarios: dict[str, Any] | None
    records: list[dict[str, Any]]
    planned: int
    reference: Evaluation | None = None
    windows_s: tuple[float, ...] | None = field(default=None)

    @property
    def partial(self) -> bool:
        """Whether fewer episodes finished than were asked for (an interrupted run)."""
        return len(self.records) < self.planned

    @property
    def failures(self) -> int:
        """Episodes that failed (``failure`` not null)."""
        return sum(record["failure"] is not None for record in self.records)

    @property
    def cost(self) -> str:
        """What ``mean_cost`` is for this id: the per-step cost's formula and units
        (:attr:`etsc_envs.core.paper.Paper.cost`)."""
        return paper_of(self.env_id).cost

    @cached_property
    def mean(self) -> dict[str, Any]:
        """The mean of every numeric key over the records, and ``failures``."""
        return mean_record(self.records) if self.records else {}

    @cached_property
    def aggregates(self) -> dict[str, Any]:
        """Mean, median and IQM of ``mean_cost``, ``transmissions``, ``transmission_rate`` and
        ``return`` with 95 % intervals, and the failure rate with its interval
        (:func:`~etsc_envs.evaluation.statistics.aggregate_records`)."""
        return aggregate_records(self.records) if self.records else {}

    def values(self, key: str) -> np.ndarray:
        """Each record's ``key`` in scenario order."""
        return np.array([record[key] for record in self.records], dtype=float)

    @cached_property
    def comparison(self) -> dict[str, Any] | None:
        """The paired comparison with :attr:`reference` on the same scenarios (``None``
        without one): the per-scenario ratios candidate / reference of ``mean_cost``
        (``cost``) and ``transmissions`` with 95 % intervals
        (:func:`~etsc_envs.evaluation.statistics.paired_ratio`: IQM, ratio of means,
        probability of improvement), both sides' failures, and the verdict
        (:func:`~etsc_envs.evaluation.verdict.compare`: each ratio's interval against 1,
        failures first)."""
        reference = self.reference
        if reference is None or not self.records or len(reference.records) != len(self.records):
            return None
        ratios = {
            axis: paired_ratio(self.values(key), reference.values(key))
            for axis, key in (("cost", "mean_cost"), ("transmissions", "transmissions"))
        }
        verdict = compare(
            self.failures, reference.failures, {a: ratio_axis(r) for a, r in ratios.items()}
        )
        return {
            "reference": reference.policy,
            "reference_policy_args": reference.policy_args,
            **ratios,
            "failures": {"candidate": self.failures, "reference": reference.failures},
            "verdict": verdict.to_json(),
        }

    def standing(self) -> list[dict[str, Any]]:
        """Where this evaluation stands among the id's leaderboard rows
        (:func:`~etsc_envs.evaluation.leaderboard.leaderboard`), each row judged by
        :func:`~etsc_envs.evaluation.verdict.compare` on both axes — the 95 % intervals of the
        mean cost and of the transmissions, unpaired (beats where this whole interval lies
        below the row's), failures first. ``ValueError`` unless this ran on the test set."""
        if self.scenarios is None or self.scenarios["name"] != "test" or not self.records:
            raise ValueError(
                "standing: the leaderboard is on the test set; this evaluation ran on "
                f"{self.scenarios['name'] if self.scenarios else 'an ad-hoc draw of seeds'}"
            )
        cost, sent = (self.aggregates[key] for key in ("mean_cost", "transmissions"))
        standing = []
        for row in leaderboard(self.env_id):
            if row.test is None:
                continue
            verdict = _row_verdict(self.failures, cost, sent, row)
            standing.append({"trigger": row.trigger, "what": row.what, **verdict.to_json()})
        return standing

    def to_json(self) -> dict[str, Any]:
        """The design page's JSON: ``env``, ``policy``, ``policy_args``, ``env_args``,
        ``scenarios``, ``cost`` (what ``mean_cost`` is), ``episodes`` (the records), ``mean``,
        ``aggregates``, ``comparison`` (or ``null``), ``partial`` when interrupted, and
        ``windows`` (each window's means over the episodes) when windows were asked for."""
        result: dict[str, Any] = {
            "env": self.env_id,
            "policy": self.policy,
            "policy_args": self.policy_args,
            "env_args": self.env_args,
            "scenarios": self.scenarios,
            "cost": self.cost,
            "episodes": self.records,
            "mean": self.mean,
            "aggregates": self.aggregates,
            "comparison": self.comparison,
        }
        if self.partial:
            result["partial"] = True
        if self.windows_s is not None and self.records:
            result["windows"] = _mean_windows(self.records)
        return result

    def summary(self) -> str:
        """The means, the aggregates with their 95 % intervals and the comparison, as lines."""
        where = (
            f"{self.scenarios['name']} set, {self.scenarios['size']} scenario(s)"
            if self.scenarios
            else f"{len(self.records)} episode(s)"
        )
        lines = [f"{self.env_id}  policy={self.policy} {self.policy_args or ''} ({where})"]
        lines.append(f"  mean_cost is {self.cost}")
        for key, value in self.mean.items():
            if isinstance(value, int | float):
                lines.append(f"  {key:>22s}  {value:.6g}")
        for agent, values in self.mean.get("agents", {}).items():
            lines.append(f"  {agent}: " + ", ".join(f"{k}={v:.6g}" for k, v in values.items()))
        lines.append("  aggregates (95 % intervals):")
        lines.extend(f"    {line}" for line in aggregate_lines(self.aggregates))
        if self.windows_s is not None and self.records:
            lines.append("  windows (means over the episodes):")
            for window in _mean_windows(self.records):
                span = f"{window['from_s']:g}-{window['to_s']:g} s"
                lines.append(
                    f"    {span:>16s}  cost {window['cost']:.6g}  "
                    f"transmissions {window['transmissions']:.6g}"
                )
        comparison = self.comparison
        if comparison is not None:
            lines.append(
                f"  against {comparison['reference']} on the same scenarios (IQM of the "
                "per-scenario ratios, 95 % intervals):"
            )
            for axis in ("cost", "transmissions"):
                lines.append(f"    {axis:>13s}  {_ratio_text(comparison[axis])}")
            lines.append(f"    verdict: {Verdict.from_json(comparison['verdict']).text()}")
        return "\n".join(lines)


def _row_verdict(
    failures: int, cost: dict[str, Any], sent: dict[str, Any], row: LeaderboardRow
) -> Verdict:
    """:func:`compare` of a test-set evaluation's intervals with a leaderboard row's."""
    measure = row.test
    assert measure is not None
    return compare(
        failures,
        measure.failures,
        {
            "cost": difference_axis(cost["mean_ci95"], measure.cost_ci95),
            "transmissions": difference_axis(sent["mean_ci95"], measure.transmissions_ci95),
        },
    )


def _ratio_text(ratio: dict[str, Any]) -> str:
    if ratio["iqm"] is None:
        return "no ratio (the reference is 0 on every scenario)"
    low, high = ratio["iqm_ci95"]
    text = f"×{ratio['iqm']:.4g} [{low:.4g}, {high:.4g}]"
    if ratio["worse_where_reference_zero"]:
        text += f", above 0 on {ratio['worse_where_reference_zero']} where the reference is 0"
    return text


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


class EvaluationInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`evaluate`: ``evaluation`` holds the records of the episodes that
    finished before it (:attr:`Evaluation.partial`). Episodes run together in a batch finish
    together, so an interrupted batch has none; episodes run one by one keep every one that
    ended."""

    def __init__(self, evaluation: Evaluation) -> None:
        super().__init__()
        self.evaluation = evaluation


class CheckedPolicy:
    """A policy of the caller — an object with SB3's ``predict``, or a plain callable
    ``observation -> action`` asked row by row for a batch (one agent's observation each, for
    a PettingZoo id) — whose every answer is checked against the action space, so that a wrong
    action is refused with one line naming ``policy`` before the env reads it."""

    def __init__(self, policy: Any, action_space: gym.Space, env_id: str) -> None:
        self.policy = policy
        self.env_id = env_id
        self.action_space = action_space
        self.action_shape = tuple(action_space.shape or ())

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        observations = np.asarray(observation)
        single = observations.ndim == 1
        if callable(getattr(self.policy, "predict", None)):
            actions, state = self.policy.predict(
                observation, state=state, episode_start=episode_start, deterministic=deterministic
            )
        elif single:
            actions = self.policy(observations)
        else:
            actions = [np.asarray(self.policy(row)) for row in observations]
        expected = self.action_shape if single else (observations.shape[0], *self.action_shape)
        answer = np.asarray(actions)
        fits = (
            answer.size == int(np.prod(expected))
            and np.issubdtype(answer.dtype, np.number)
            and bool(np.all((answer == 0) | (answer == 1)))
        )
        if not fits:
            wrong = answer.ravel()[~((answer.ravel() == 0) | (answer.ravel() == 1))]
            what = (
                f"an action of shape {answer.shape}"
                if answer.size != int(np.prod(expected)) or wrong.size == 0
                else _shown(wrong[0].item() if wrong.dtype != object else wrong[0])
            )
            count = "an observation" if single else f"{observations.shape[0]} observation(s)"
            raise ValueError(
                f"policy: answered {what} for {count} of {self.env_id}, whose actions are "
                f"{self.action_space} (0 hold, 1 transmit"
                f"{'' if single else f'; shape {expected} for this batch'})"
            )
        return answer.reshape(expected).astype(np.int64), state


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def resolve_policy(policy: Any, policy_args: Mapping[str, Any] | None) -> tuple[str, Any]:
    """``(name, policy)``: a spec string (``paper``, ``learned:PATH``; a ``.json``/``.zip``
    path becomes ``learned:``/``sb3:``) as ``(spec, None)``; an object with ``predict`` or a
    callable as ``(its class name, the object)``. ``ValueError`` naming ``policy`` otherwise."""
    if isinstance(policy, str):
        spec = policy
        if spec.endswith((".json", ".zip")) and not spec.startswith(("learned:", "sb3:")):
            spec = model_spec(spec)
        if spec in NAMED_POLICIES or spec.startswith(("learned:", "sb3:")):
            return spec, None
        raise ValueError(
            f"policy must be one of {POLICY_CHOICES}, a .json or .zip path that "
            f"etsc_envs.load_policy reads, an object with predict(obs, state, episode_start, "
            f"deterministic) or a callable obs -> action; got {policy!r}"
        )
    if policy_args:
        raise ValueError(
            f"policy_args: only a policy spec takes keywords, got {dict(policy_args)} with a "
            f"{type(policy).__name__}"
        )
    if callable(getattr(policy, "predict", None)) or callable(policy):
        return type(policy).__name__, policy
    raise ValueError(
        f"policy must be a policy spec ({POLICY_CHOICES}), a .json or .zip path, an object "
        f"with predict(obs, state, episode_start, deterministic) or a callable obs -> action; "
        f"got a {type(policy).__name__} with neither predict nor __call__"
    )


def evaluate(
    policy: Any,
    env_id: str,
    scenarios: str | None = None,
    *,
    size: int = DEFAULT_SET_SIZE,
    episodes: int | None = None,
    seed: int = 0,
    policy_args: Mapping[str, Any] | None = None,
    env_args: Mapping[str, Any] | None = None,
    reference: str | None = "paper",
    progress: bool = True,
    processes: int | None = None,
    windows_s: Sequence[float] | None = None,
    on_episode: EpisodeHook | None = None,
) -> Evaluation:
    """Run ``policy`` on a scenario set of ``env_id`` and compare it with ``reference``.

    Args:
        policy: a policy spec (``paper | error_time | periodic | always | learned:PATH |
            sb3:PATH``, with ``policy_args``), a ``.json``/``.zip`` path that
            :func:`etsc_envs.load_policy` reads, an object with SB3's batched ``predict``, or
            a plain callable ``obs -> action``. For a PettingZoo id it is one agent's policy,
            shared by every agent.
        env_id: a Gymnasium or PettingZoo id of the suite.
        scenarios: ``"paper"``, ``"validation"`` or ``"test"`` (:mod:`etsc_envs.protocol`);
            the test set unless ``episodes`` is given.
        size: scenarios of the validation or test set (the protocol's 64 by default).
        episodes: run an ad-hoc draw of this many ``randomize``-as-given episodes, seeds
            ``seed, seed + 1, ...``, instead of a scenario set.
        policy_args: keywords of a policy spec (``every=K`` of ``periodic``, ...).
        env_args: keywords of every scenario's env.
        reference: the spec run on the same scenarios for :attr:`Evaluation.comparison`
            (the paper's rule by default; ``None``: no comparison). A policy that is the
            reference itself is compared with its own records.
        progress: a progress bar over the sampling instants.
        processes: worker processes sharing a batch of a spec's policy
            (:func:`~etsc_envs.evaluation.batch.run_batch_in_processes`); ``None`` takes
            :func:`~etsc_envs.evaluation.batch.process_count`'s, 1 runs it in this process.
        windows_s: edges of time windows (s): each record gets the summed cost and the
            transmissions of each window (runs the episodes one by one).
        on_episode: called with ``(index, record, trace)`` after each episode (runs the
            episodes one by one).

    The set runs in the id's native vector env (:func:`~etsc_envs.evaluation.batch.
    run_batch`; a rule or a clock inside the compiled loop, a callable row by row), unless
    ``windows_s`` or ``on_episode`` need each episode's trace; both paths give the same
    records. A policy object's answers are checked against the action space. Bad arguments
    raise ``ValueError`` naming the argument; Ctrl-C raises :class:`EvaluationInterrupted`
    with the finished episodes.
    """
    if scenarios is not None and episodes is not None:
        raise ValueError(f"give scenarios or episodes, not both; got {scenarios!r} and {episodes}")
    policy_args, env_args = dict(policy_args or {}), dict(env_args or {})
    if episodes is None:
        chosen = scenario_set("test" if scenarios is None else scenarios, size)
        env_args, seeds = chosen.env_kwargs(env_args), list(chosen.seeds)
        described: dict[str, Any] | None = chosen.describe()
    else:
        if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
            raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
        seeds, described = [seed + episode for episode in range(episodes)], None
    name, given = resolve_policy(policy, policy_args)
    edges = None if windows_s is None else window_edges(windows_s)
    if reference is not None and reference not in NAMED_POLICIES:
        raise ValueError(f"reference must be None or one of {NAMED_POLICIES}, got {reference!r}")
    run = _Runner(env_id, env_args, seeds, progress, processes, edges, on_episode)
    evaluation = Evaluation(env_id, name, policy_args, env_args, described, [], len(seeds))
    evaluation.windows_s = edges
    try:
        evaluation.records = run(name, given, policy_args)
        if reference == name and not policy_args:
            evaluation.reference = evaluation
        elif reference is not None:
            evaluation.reference = Evaluation(
                env_id, reference, {}, env_args, described, run(reference, None, {}), len(seeds)
            )
    except KeyboardInterrupt:
        evaluation.records = evaluation.records or run.finished
        raise EvaluationInterrupted(evaluation) from None
    return evaluation


class _Runner:
    """Runs a policy on one scenario set: in the native vector env, or one by one."""

    def __init__(
        self,
        env_id: str,
        env_args: dict[str, Any],
        seeds: list[int],
        progress: bool,
        processes: int | None,
        edges: tuple[float, ...] | None,
        on_episode: EpisodeHook | None,
    ) -> None:
        self.setup = episode_setup(env_id, env_args)
        self.setup.env.close()
        self.env_id, self.env_args, self.seeds = env_id, env_args, seeds
        self.progress, self.processes = progress, processes
        self.edges, self.on_episode = edges, on_episode
        self.finished: list[dict[str, Any]] = []
        if edges is not None:
            horizon_s = _horizon_s(self.setup.env)
            if edges[0] >= horizon_s:
                raise ValueError(
                    f"windows_s: the first window must start inside the episode's horizon of "
                    f"{horizon_s:g} s (else every window is empty), got "
                    f"{', '.join(f'{edge:g}' for edge in edges)}"
                )

    def policy(self, spec: str, given: Any, policy_args: dict[str, Any]) -> Any:
        """The policy to run: the spec's, or the caller's object checked (a rule trigger
        object of the suite as it is, for the compiled loop)."""
        if given is None:
            return self.setup.make_policy(spec, policy_args)
        if isinstance(given, RuleTrigger) or type(given).__module__.startswith("etsc_envs."):
            return given
        _, action_space, _ = self.setup.policy_spaces()
        return CheckedPolicy(given, action_space, self.env_id)

    def __call__(self, spec: str, given: Any, policy_args: dict[str, Any]) -> list[dict[str, Any]]:
        """The records of ``spec`` (or of the object ``given``) on every seed."""
        policy = self.policy(spec, given, policy_args)
        seeds = self.seeds
        description = f"{spec} on {len(seeds)} scenario" + ("s" if len(seeds) > 1 else "")
        one_by_one = self.edges is not None or self.on_episode is not None
        loop_id = etsc_envs.PETTINGZOO_LOOP_IDS.get(self.env_id, self.env_id)
        if not one_by_one and loop_id in etsc_envs.VECTOR_ENTRY_POINTS:
            processes = process_count(len(seeds)) if self.processes is None else self.processes
            if given is None and processes > 1:
                return run_batch_in_processes(
                    self.env_id,
                    spec,
                    policy_args,
                    seeds,
                    self.env_args,
                    processes=processes,
                    progress=self.progress,
                    description=description,
                )
            return run_batch(
                self.env_id,
                policy,
                seeds,
                self.env_args,
                progress=self.progress,
                description=description,
            )
        self.finished = []
        setup = episode_setup(self.env_id, self.env_args)
        try:
            for index, episode_seed in enumerate(seeds):
                record, trace = setup.run(
                    setup.env,
                    policy,
                    episode_seed,
                    sample_every=None,
                    progress=self.progress,
                    description=f"{spec} episode {index + 1}/{len(seeds)}",
                )
                if self.edges is not None:
                    record["windows"] = trace.window_totals(self.edges)
                self.finished.append(record)
                if self.on_episode is not None:
                    self.on_episode(index, record, trace)
        finally:
            setup.env.close()
        return self.finished


def _horizon_s(env: Any) -> float:
    """The episode length of ``env`` (a Gymnasium env or a PettingZoo parallel env)."""
    unwrapped = env.unwrapped
    return float(getattr(unwrapped, "loop", unwrapped).horizon_s)

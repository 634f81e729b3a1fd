"""Policies from their command-line specs: ``--policy paper | error_time | periodic | always |
sb3:PATH | learned:PATH`` with ``--policy-arg`` keywords, for one env or for every agent of a
PettingZoo env, and the setup of an episode (the env and its policy) that the evaluation
commands, the batch evaluator and training-time validation share."""

from __future__ import annotations

import dataclasses
import inspect
import math
from collections.abc import Callable
from typing import Any, NamedTuple

import gymnasium as gym

import etsc_envs
from etsc_envs.core.compiled_loop import always_accepts
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.paper import RULE_NAMES
from etsc_envs.core.validation import require_int_at_least
from etsc_envs.decisions.policy import sb3_policy
from etsc_envs.evaluation.episodes import run_episode, run_parallel_episode
from etsc_envs.papers import ids_with_rule, rule_of
from etsc_envs.triggers import AlwaysPolicy, PeriodicPolicy, SwitchedPeriodicPolicy
from etsc_envs.triggers.base import (
    ClockTrigger,
    HeartbeatPolicy,
    instants_seconds,
    policy_interface,
    timed_rule_class,
)
from etsc_envs.triggers.family import LearnedTrigger

NAMED_POLICIES = ("paper", "error_time", "periodic", "always")
"""The policy specs that name a rule or a clock rather than a file."""

POLICY_CHOICES = "paper | error_time | periodic | always | sb3:PATH_TO_ZIP | learned:PATH"
"""An ``sb3:`` model with ``NAME_decisions.json`` beside its zip takes self-triggered decisions
(:mod:`etsc_envs.decisions`)."""

LEARNED_POINT_ARGUMENTS = ("floor_instants", "heartbeat_instants", "exponent")
"""The components of a learned trigger's θ that ``--policy-arg`` may replace, to read how its
cost and transmissions depend on each (``heartbeat_instants=inf``: no heartbeat)."""


def check_policy_arguments(spec: str, policy_args: dict[str, Any], env_id: str) -> None:
    """``ValueError`` naming the ``--policy-arg`` that ``spec`` does not take, or whose value is
    not of its kind, with the keywords it takes: the rules' thresholds are finite numbers, every
    count of sampling instants (``every``, ``heartbeat``, ``floor``, ...) an integer >= 1.
    Other specs (models) are checked where they are loaded."""
    if spec.startswith("sb3:") and not spec.removeprefix("sb3:"):
        raise ValueError("--policy sb3: needs the path of a model zip, e.g. sb3:models/NAME.zip")
    if spec.startswith("learned:"):
        for key, value in policy_args.items():
            if key not in LEARNED_POINT_ARGUMENTS:
                takes = ", ".join(LEARNED_POINT_ARGUMENTS)
                raise ValueError(f"--policy-arg {key}: a learned trigger takes {takes}")
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"--policy-arg {key} must be a number, got {value!r}")
        return
    counts = {"every", "then_every", "switch_after"} if spec == "periodic" else set()
    numbers: set[str] = set()
    if spec in RULE_NAMES and env_id in ids_with_rule(spec):
        trigger_class = rule_of(env_id, spec).trigger
        parameters = list(inspect.signature(trigger_class.__init__).parameters)
        numbers = set(parameters[4:])  # after self, the two spaces and the observation names
        counts = {"heartbeat", "floor", "channel_heartbeat"}
    elif spec not in ("always", "periodic"):
        return
    for key, value in policy_args.items():
        if key not in counts | numbers and spec != "periodic":  # periodic's own line names it
            takes = ", ".join(sorted(counts | numbers)) or "no --policy-arg"
            raise ValueError(
                f"--policy-arg {key}: {spec} on {env_id} takes {takes}, got {key}={value!r}"
            )
        least = 0 if key == "switch_after" else 1
        if key in counts and (
            isinstance(value, bool) or not isinstance(value, int) or value < least
        ):
            raise ValueError(
                f"--policy-arg {key} must be an integer >= {least} (sampling instants), "
                f"got {value!r}"
            )
        if key in numbers and (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise ValueError(f"--policy-arg {key} must be a finite number, got {value!r}")


def make_policy(spec: str, env: gym.Env, policy_args: dict[str, Any], env_id: str) -> Any:
    """The policy named by ``spec`` (see :data:`POLICY_CHOICES`) for ``env``."""
    unwrapped: Any = env.unwrapped
    return _policy_for(
        spec,
        env.observation_space,
        env.action_space,
        lambda: unwrapped.observation_names,
        policy_args,
        env_id,
        lambda: unwrapped,
    )


def make_agent_policy(spec: str, env: Any, policy_args: dict[str, Any], env_id: str) -> Any:
    """The policy named by ``spec`` shared by every agent of a PettingZoo ``ParallelEnv``.

    The agents must have equal spaces; the policy is queried with the agents' observations
    stacked along the batch axis, one action per agent.
    """
    agent = env.possible_agents[0]
    if any(
        env.observation_space(other) != env.observation_space(agent)
        or env.action_space(other) != env.action_space(agent)
        for other in env.possible_agents
    ):
        raise ValueError(f"the agents of {env_id} differ in their spaces; no policy serves all")
    return _policy_for(
        spec,
        env.observation_space(agent),
        env.action_space(agent),
        lambda: env.unwrapped.agent_observation_names,
        policy_args,
        env_id,
        lambda: env.unwrapped.loop,
    )


class EpisodeSetup(NamedTuple):
    """An environment ready for evaluation episodes, with how to make policies for it and how
    to run one episode (Gymnasium and PettingZoo ids alike)."""

    env: Any
    make_policy: Callable[[str, dict[str, Any]], Any]
    """``(spec, policy_args) -> policy`` (for a PettingZoo id, one policy serves all agents)."""
    run: Callable[..., tuple[dict[str, Any], Any]]
    """:func:`~etsc_envs.evaluation.episodes.run_episode` or its PettingZoo form."""

    def policy_spaces(self) -> tuple[gym.Space, gym.Space, tuple[str, ...]]:
        """The observation space, action space and observation names a policy acts with
        (one agent's, for a PettingZoo id)."""
        observation_space, action_space, names, _ = policy_interface(self.env)
        return observation_space, action_space, names


def require_env_id(env_id: Any, argument: str = "env_id") -> str:
    """``env_id`` if it is registered with Gymnasium or a PettingZoo id of etsc-envs, else
    ``ValueError`` naming ``argument`` and listing the ids etsc-envs provides."""
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS or (
        isinstance(env_id, str) and env_id in gym.registry
    ):
        return env_id
    raise ValueError(
        f"{argument}: {env_id!r} is not registered; etsc-envs registers "
        f"{sorted(etsc_envs.ENV_IDS)} and the PettingZoo ids {sorted(etsc_envs.PETTINGZOO_ENV_IDS)}"
    )


def episode_setup(env_id: str, env_args: dict[str, Any]) -> EpisodeSetup:
    """``env_id`` (a Gymnasium or a PettingZoo id) built with ``env_args``, as an
    :class:`EpisodeSetup` (``ValueError`` for an unknown id)."""
    require_env_id(env_id)
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        env = etsc_envs.make_parallel(env_id, **env_args)
        return EpisodeSetup(
            env,
            lambda spec, args: make_agent_policy(spec, env, args, env_id),
            run_parallel_episode,
        )
    env = gym.make(env_id, **env_args)
    return EpisodeSetup(env, lambda spec, args: make_policy(spec, env, args, env_id), run_episode)


def require_policies(env_id: str, env_args: dict[str, Any], specs: list[str]) -> None:
    """Build every policy of ``specs`` once for ``env_id`` (loading each model and checking
    its spaces), so that a bad model is refused with one line before any long work."""
    setup = episode_setup(env_id, env_args)
    try:
        for spec in specs:
            setup.make_policy(spec, {})
    finally:
        setup.env.close()


def _policy_for(
    spec: str,
    observation_space: gym.Space,
    action_space: gym.Space,
    observation_names: Callable[[], tuple[str, ...]],
    policy_args: dict[str, Any],
    env_id: str,
    loop: Callable[[], EventTriggeredEnv],
) -> Any:
    """The policy named by ``spec`` for the given spaces (the names and the env's ``loop`` are
    read only if needed). ``periodic`` is :class:`ClockTrigger` — :class:`PeriodicPolicy`'s
    decisions as a rule that the compiled loop runs (:mod:`etsc_envs.evaluation.batch`) — where the
    receiver takes every transmission; where it may refuse one (paper 003's burst in
    progress), the time since transmission no longer counts the clock's instants, and
    ``periodic`` is the counter-based :class:`PeriodicPolicy`. ``periodic`` with
    ``then_every`` and ``switch_after`` is :class:`SwitchedPeriodicPolicy` (every ``every``
    instants before instant ``switch_after``, every ``then_every`` after it)."""
    check_policy_arguments(spec, policy_args, env_id)
    if spec == "always":
        return AlwaysPolicy(observation_space, action_space, **policy_args)
    if spec == "periodic":
        switch = {"then_every", "switch_after"}
        if set(policy_args) - {"every"} - switch:
            raise ValueError(
                f"--policy-arg: periodic takes every=K, and then_every=K2 with "
                f"switch_after=N (sampling instants), got {sorted(policy_args)}"
            )
        if switch & set(policy_args):
            if not switch <= set(policy_args) or "every" not in policy_args:
                raise ValueError(
                    f"--policy-arg: a switched periodic policy takes every, then_every and "
                    f"switch_after together, got {sorted(policy_args)}"
                )
            return SwitchedPeriodicPolicy(observation_space, action_space, **policy_args)
        environment = loop()
        if environment.kernels.accepts is not always_accepts:
            return PeriodicPolicy(observation_space, action_space, **policy_args)
        return ClockTrigger(
            observation_space,
            action_space,
            observation_names(),
            sampling_period_s=environment.sampling_period_s,
            **policy_args,
        )
    if spec in RULE_NAMES:
        if env_id not in ids_with_rule(spec):
            raise ValueError(f"no {spec} trigger for {env_id}; known: {ids_with_rule(spec)}")
        names = observation_names()
        arguments = dict(policy_args)
        heartbeat = arguments.pop("heartbeat", None)
        channel_heartbeat = arguments.pop("channel_heartbeat", None)
        floor = arguments.pop("floor", None)
        if channel_heartbeat is not None and floor is not None:
            raise ValueError(
                "--policy-arg: a rule takes channel_heartbeat or floor, not both, got "
                f"channel_heartbeat={channel_heartbeat!r} and floor={floor!r}"
            )
        floor_s, heartbeat_s = (
            None
            if instants is None
            else instants_seconds(
                require_int_at_least(f"--policy-arg {name}", instants, 1),
                loop().sampling_period_s,
            )
            for name, instants in (("floor", floor), ("channel_heartbeat", channel_heartbeat))
        )
        trigger_class, bound = timed_rule_class(rule_of(env_id, spec).trigger, floor_s, heartbeat_s)
        trigger = trigger_class(observation_space, action_space, names, **{**arguments, **bound})
        return trigger if heartbeat is None else HeartbeatPolicy(trigger, heartbeat)
    if spec.startswith("learned:"):
        learned = LearnedTrigger.load(spec.removeprefix("learned:"))
        if policy_args:
            try:
                point = dataclasses.replace(learned.point, **policy_args)
            except ValueError as error:
                raise ValueError(f"--policy-arg {error}") from None
            learned = dataclasses.replace(learned, point=point)
        try:
            return learned.trigger(
                observation_space,
                action_space,
                observation_names(),
                loop().sampling_period_s,
                env_id,
            )
        except ValueError as error:
            raise ValueError(f"--policy {spec}: {error}") from None
    if spec.startswith("sb3:"):
        if policy_args:
            raise ValueError(f"--policy-arg is not used by sb3 policies, got {policy_args}")
        return sb3_policy(
            spec.removeprefix("sb3:"),
            observation_space,
            action_space,
            tuple(observation_names()),
            loop().sampling_period_s,
            env_id,
        )
    raise ValueError(f"--policy must be one of {POLICY_CHOICES}, got {spec!r}")

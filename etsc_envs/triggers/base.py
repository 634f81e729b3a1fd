"""Trigger policies that answer like Stable-Baselines3 models.

Every policy has ``predict(obs, state=None, episode_start=None, deterministic=True) ->
(action, state)`` and accepts one observation or a batch (leading axis), so a single evaluator
runs paper triggers, periodic schedules and trained models alike. :class:`TriggerPolicy` is the
base of every policy here, :class:`RuleTrigger` that of the papers' rules
(:mod:`etsc_envs.triggers`); :class:`AlwaysPolicy` and :class:`PeriodicPolicy` are the
time-triggered references.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any, ClassVar, NamedTuple

import gymnasium as gym
import numpy as np

from etsc_envs.core.jit import closure_jit, jit


def transmit_bits(action_space: gym.Space) -> int | None:
    """Transmit bits per action: ``None`` for Discrete(2), ``n`` for MultiBinary(n)."""
    if isinstance(action_space, gym.spaces.Discrete) and action_space.n == 2:
        return None
    if isinstance(action_space, gym.spaces.MultiBinary):
        return int(np.prod(action_space.shape))
    raise ValueError(f"action_space must be Discrete(2) or MultiBinary(n), got {action_space}")


def batched_observations(obs: np.ndarray, observation_space: gym.Space) -> tuple[np.ndarray, bool]:
    """``obs`` with a leading batch axis, and whether the caller gave a single observation."""
    obs = np.asarray(obs)
    single = obs.shape == observation_space.shape
    return (obs[None] if single else obs), single


class PolicyInterface(NamedTuple):
    """What a trigger policy of an env is built for: the spaces it acts in, the names of its
    observation's entries and the env's sampling period (one agent's, for a PettingZoo env)."""

    observation_space: gym.Space
    action_space: gym.Space
    observation_names: tuple[str, ...]
    sampling_period_s: float


def policy_interface(env: Any) -> PolicyInterface:
    """The :class:`PolicyInterface` of ``env``: a Gymnasium env of the suite, or a PettingZoo
    parallel env, whose agents share one policy (queried with their observations stacked)."""
    unwrapped = env.unwrapped
    if callable(getattr(env, "observation_space", None)):  # a PettingZoo env: one agent's view
        agent = env.possible_agents[0]
        return PolicyInterface(
            env.observation_space(agent),
            env.action_space(agent),
            tuple(unwrapped.agent_observation_names),
            float(unwrapped.loop.sampling_period_s),
        )
    return PolicyInterface(
        env.observation_space,
        env.action_space,
        tuple(unwrapped.observation_names),
        float(unwrapped.sampling_period_s),
    )


class TriggerPolicy:
    """Base of the analytic trigger policies: maps transmit decisions to the action space.

    Subclasses implement :meth:`transmit`, returning booleans of shape ``(batch,)`` for
    ``Discrete(2)`` or ``(batch, n_channels)`` for ``MultiBinary``.
    """

    def __init__(self, observation_space: gym.Space, action_space: gym.Space) -> None:
        self.observation_space = observation_space
        self.action_space = action_space
        self.n_bits = transmit_bits(action_space)

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        raise NotImplementedError

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """Transmit decision(s) for ``observation`` in the Stable-Baselines3 calling convention."""
        obs, single = batched_observations(observation, self.observation_space)
        if episode_start is not None:
            state = self.reset_state(state, np.asarray(episode_start, dtype=bool), len(obs))
        decision, state = self.transmit(obs, state)
        action = decision.astype(np.int64)
        return (action[0] if single else action), state

    def reset_state(self, state: Any, episode_start: np.ndarray, batch: int) -> Any:
        """State after episodes restart where ``episode_start`` is set (stateless by default)."""
        return state


@functools.cache
def batched_rule(rule: Callable[..., None]) -> Callable[..., None]:
    """The compiled ``apply(observations, indices, parameters, out)`` that runs the per-instant
    kernel ``rule`` (see :class:`RuleTrigger`) on every row of ``observations`` (float32,
    ``(batch, F)``) into ``out`` (int64, ``(batch, C)``)."""

    @closure_jit
    def apply(observations, indices, parameters, out):
        for row in range(observations.shape[0]):
            rule(observations[row], indices, parameters, out[row])

    return apply


@functools.cache
def condition_rule(
    condition: Callable[..., None], conditions_per_channel: int, strict: bool
) -> Callable[..., None]:
    """The per-instant kernel ``rule(observation, indices, parameters, out)`` of a paper's
    triggering condition written as its two sides: ``condition(observation, indices,
    parameters, statistic, threshold)`` writes, for each of the ``C ×
    conditions_per_channel`` conditions (channel-major), the sampling statistic and the
    threshold it is compared with; channel c transmits when one of its conditions holds,
    ``statistic > threshold`` if ``strict``, else ``statistic >= threshold``. The parametric
    family (:mod:`etsc_envs.triggers.family`) compares the same two sides, weighted."""

    @closure_jit
    def rule(observation, indices, parameters, out):
        n_conditions = out.shape[0] * conditions_per_channel
        statistic = np.empty(n_conditions)
        threshold = np.empty(n_conditions)
        condition(observation, indices, parameters, statistic, threshold)
        for channel in range(out.shape[0]):
            fires = 0
            for j in range(conditions_per_channel):
                k = channel * conditions_per_channel + j
                if strict:
                    if statistic[k] > threshold[k]:
                        fires = 1
                elif statistic[k] >= threshold[k]:
                    fires = 1
            out[channel] = fires

    return rule


class RuleTrigger(TriggerPolicy):
    """Base of the papers' triggering rules: a stateless condition on one observation, written
    once as a compiled kernel.

    The class's :attr:`rule` has the signature ``rule(observation, indices, parameters, out)``:
    ``observation`` is one float32 observation row, ``indices`` (int64) and ``parameters``
    (float64) are the trigger's :attr:`rule_indices` and :attr:`rule_parameters`, and the rule
    writes 1 (transmit) or 0 (hold) for each channel into ``out`` (int64, one entry per
    transmit bit). :meth:`transmit` applies it to a batch of observations, and the compiled
    loop runs the same kernel inside its step loop
    (:func:`~etsc_envs.core.compiled_loop.make_loop_rule_interval`), so that Python and
    compiled decisions are the same by construction.

    Args:
        observation_space, action_space: the environment's spaces.
        indices: the observation components the rule reads.
        parameters: its design parameters, in the order the kernel reads them.
        keywords: the constructor keywords that give this trigger, so that
            :meth:`for_observations` can rebuild it for another observation layout.
    """

    rule: ClassVar[Callable[..., None]]

    condition: ClassVar[Callable[..., None] | None] = None
    """A paper's condition as its two sides (see :func:`condition_rule`), or ``None`` for a
    rule that is not a paper's (a clock). A class that sets it gets ``rule =
    condition_rule(condition, conditions_per_channel, strict)``."""
    conditions_per_channel: ClassVar[int] = 1
    strict: ClassVar[bool] = False
    threshold_groups: ClassVar[dict[str, tuple[str, ...]]] = {}
    """The threshold keywords the parametric family scales, by factor name (one factor may
    scale several keywords: Π for the three axes of paper 004)."""
    factor_bounds: ClassVar[dict[str, tuple[float, float]]] = {}
    """The factors' allowed ranges, where the paper bounds a threshold (others: (0, inf))."""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "condition" in cls.__dict__ and cls.condition is not None:
            rule = condition_rule(cls.condition, cls.conditions_per_channel, cls.strict)
            cls.rule = staticmethod(rule)  # type: ignore[assignment]

    @classmethod
    def paper_thresholds(cls) -> dict[str, float]:
        """The keywords of :attr:`threshold_groups` at the paper's values."""
        raise NotImplementedError(f"{cls.__name__} has no threshold keywords")

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        indices: Any,
        parameters: Any,
        keywords: dict[str, Any],
    ) -> None:
        super().__init__(observation_space, action_space)
        self.rule_indices = np.ascontiguousarray(indices, dtype=np.int64).reshape(-1)
        self.rule_parameters = np.ascontiguousarray(parameters, dtype=np.float64).reshape(-1)
        self.keywords = dict(keywords)

    @property
    def n_channels(self) -> int:
        """Transmit bits the rule writes per observation."""
        return 1 if self.n_bits is None else self.n_bits

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        observations = np.ascontiguousarray(obs, dtype=np.float32)
        out = np.zeros((len(observations), self.n_channels), dtype=np.int64)
        batched_rule(type(self).rule)(observations, self.rule_indices, self.rule_parameters, out)
        fires = out.astype(bool)
        return (fires[:, 0] if self.n_bits is None else fires), state

    def for_observations(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
    ) -> RuleTrigger:
        """The same rule, with the same keywords, for an env of other spaces and names (the
        loop of a PettingZoo id, whose agents each see a slice of its observation)."""
        return type(self)(observation_space, action_space, observation_names, **self.keywords)


class AlwaysPolicy(TriggerPolicy):
    """Transmit on every channel at every sampling instant (the time-triggered loop at t_s)."""

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        shape = (len(obs),) if self.n_bits is None else (len(obs), self.n_bits)
        return np.ones(shape, dtype=bool), state


def _instants(name: str, value: Any, least: int) -> int:
    """``value`` as a whole number of sampling instants ``>= least``, or ``ValueError`` naming
    ``name``."""
    if isinstance(value, bool) or int(value) != value or value < least:
        raise ValueError(f"{name} must be an integer >= {least} (sampling instants), got {value!r}")
    return int(value)


class PeriodicPolicy(TriggerPolicy):
    """Transmit every ``every`` sampling instants, starting with the first (time-triggered).

    The step counters are the recurrent ``state`` of the SB3 convention; pass
    ``episode_start`` (or ``state=None`` at a reset) to restart them.
    """

    def __init__(self, observation_space: gym.Space, action_space: gym.Space, every: int = 1):
        super().__init__(observation_space, action_space)
        self.every = _instants("every", every, 1)

    def reset_state(self, state: Any, episode_start: np.ndarray, batch: int) -> Any:
        counters = np.zeros(batch, dtype=np.int64) if state is None else np.array(state)
        counters[episode_start] = 0
        return counters

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        counters = np.zeros(len(obs), dtype=np.int64) if state is None else np.asarray(state)
        decision = counters % self.every == 0
        if self.n_bits is not None:
            decision = np.repeat(decision[:, None], self.n_bits, axis=1)
        return decision, counters + 1


class SwitchedPeriodicPolicy(TriggerPolicy):
    """A clock that changes its period once: transmit at the first instant, then whenever
    ``every`` instants have passed since the last transmission before instant ``switch_after``
    and ``then_every`` instants from it on (a time-switched clock, for asking whether a
    clock's transmissions are better spent early or late in an episode).

    The recurrent ``state`` holds, per row, the instants since the episode began and since the
    last transmission; pass ``episode_start`` (or ``state=None`` at a reset) to restart them.
    With ``switch_after = 0`` it is :class:`PeriodicPolicy` at ``then_every``.
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        every: int,
        then_every: int,
        switch_after: int,
    ) -> None:
        super().__init__(observation_space, action_space)
        self.every = _instants("every", every, 1)
        self.then_every = _instants("then_every", then_every, 1)
        self.switch_after = _instants("switch_after", switch_after, 0)

    def reset_state(self, state: Any, episode_start: np.ndarray, batch: int) -> Any:
        if state is None:
            return None
        elapsed, silent = (np.array(part) for part in state)
        elapsed[episode_start] = 0
        silent[episode_start] = 0
        return elapsed, silent

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        if state is None:
            state = (np.zeros(len(obs), dtype=np.int64), np.zeros(len(obs), dtype=np.int64))
        elapsed, silent = (np.asarray(part) for part in state)
        period = np.where(elapsed < self.switch_after, self.every, self.then_every)
        decision = (elapsed == 0) | (silent >= period)
        silent = np.where(decision, 1, silent + 1)
        if self.n_bits is not None:
            decision = np.repeat(decision[:, None], self.n_bits, axis=1)
        return decision, (elapsed + 1, silent)


class HeartbeatPolicy(TriggerPolicy):
    """A trigger paired with a heartbeat: ``trigger``'s decisions, and every channel at an
    instant where ``heartbeat`` instants have passed since some channel last transmitted, so no
    channel goes more than ``heartbeat`` instants without a transmission (an event trigger with
    a clock as its backstop).

    The recurrent ``state`` holds ``trigger``'s state and, per row and channel, the instants
    since that channel's last transmission; pass ``episode_start`` (or ``state=None`` at a reset)
    to restart them. Like :class:`PeriodicPolicy`, the heartbeat beats at the episode's first
    instant; always choosing the self-triggered decision "paper × f, heartbeat H"
    (:mod:`etsc_envs.decisions`) takes the same actions.
    """

    def __init__(self, trigger: TriggerPolicy, heartbeat: int) -> None:
        super().__init__(trigger.observation_space, trigger.action_space)
        self.trigger = trigger
        self.heartbeat = _instants("heartbeat", heartbeat, 1)

    def reset_state(self, state: Any, episode_start: np.ndarray, batch: int) -> Any:
        if state is None:
            return None
        inner, silent = state
        inner = self.trigger.reset_state(inner, episode_start, batch)
        silent = np.array(silent)
        silent[episode_start] = self.heartbeat
        return inner, silent

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        inner, silent = (None, None) if state is None else state
        channels = 1 if self.n_bits is None else self.n_bits
        if silent is None:
            silent = np.full((len(obs), channels), self.heartbeat, dtype=np.int64)
        decision, inner = self.trigger.transmit(obs, inner)
        sent = np.array(decision, dtype=bool).reshape(len(obs), channels)
        sent[silent.max(axis=1) >= self.heartbeat] = True
        silent = np.where(sent, 1, silent + 1)
        return (sent[:, 0] if self.n_bits is None else sent), (inner, silent)


TIME_SINCE_TRANSMISSION = "time_since_transmission_s"
"""The prefix of the observation components that hold each channel's time since its last
transmission (s): one per channel, in channel order."""


def time_since_transmission_indices(
    observation_names: tuple[str, ...], n_channels: int
) -> list[int]:
    """The observation indices of the ``n_channels`` channels' times since transmission, in
    channel order; ``ValueError`` naming ``observation_names`` unless there is one per
    channel."""
    times = [
        index
        for index, name in enumerate(observation_names)
        if name.startswith(TIME_SINCE_TRANSMISSION)
    ]
    if len(times) != n_channels:
        raise ValueError(
            f"observation_names must hold one {TIME_SINCE_TRANSMISSION}* per channel "
            f"({n_channels}), got {len(times)}"
        )
    return times


@functools.cache
def channel_timed_rule(rule: Callable[..., None], heartbeat: bool) -> Callable[..., None]:
    """The compiled kernel of ``rule`` with a bound B on each channel's time since
    transmission (the last ``C`` entries of ``indices``, C the channels; B the last entry of
    ``parameters``, s): with ``heartbeat`` every channel whose time has reached B transmits
    besides those ``rule`` fires for (a maximum inter-event time); without, a channel whose
    time is below B holds (a floor, a minimum inter-event time). ``rule`` reads its own
    indices and parameters by position, ahead of those entries."""

    @closure_jit
    def timed(observation, indices, parameters, out):
        rule(observation, indices, parameters, out)
        n_channels = out.shape[0]
        first_time = indices.shape[0] - n_channels
        bound_s = parameters[parameters.shape[0] - 1]
        for channel in range(n_channels):
            reached = float(observation[indices[first_time + channel]]) >= bound_s
            if heartbeat and reached:
                out[channel] = 1
            elif not heartbeat and not reached:
                out[channel] = 0

    return timed


def _channel_timed_trigger_class(
    trigger_class: type[RuleTrigger],
    kernel: Callable[..., None],
    keyword: str,
    name: str,
) -> type[RuleTrigger]:
    """A :class:`RuleTrigger` class running ``kernel`` (``trigger_class``'s rule with a bound
    on each channel's time since transmission, in seconds: the keyword ``keyword``), built with
    ``(observation_space, action_space, observation_names, keyword=..., **keywords)``,
    ``keywords`` those of ``trigger_class``."""

    class ChannelTimedTrigger(RuleTrigger):
        rule = staticmethod(kernel)

        def __init__(
            self,
            observation_space: gym.Space,
            action_space: gym.Space,
            observation_names: tuple[str, ...],
            **keywords: Any,
        ) -> None:
            if keyword not in keywords:
                raise TypeError(f"{name} needs the keyword {keyword} (s)")
            seconds = float(keywords.pop(keyword))
            if not np.isfinite(seconds) or seconds <= 0.0:
                raise ValueError(f"{keyword} must be a finite number > 0 (s), got {seconds!r}")
            inner = trigger_class(observation_space, action_space, observation_names, **keywords)
            times = time_since_transmission_indices(observation_names, inner.n_channels)
            setattr(self, keyword, seconds)
            self.inner = inner
            super().__init__(
                observation_space,
                action_space,
                indices=[*inner.rule_indices, *times],
                parameters=[*inner.rule_parameters, seconds],
                keywords={**inner.keywords, keyword: seconds},
            )

    ChannelTimedTrigger.__name__ = ChannelTimedTrigger.__qualname__ = name
    return ChannelTimedTrigger


@functools.cache
def floored_trigger_class(trigger_class: type[RuleTrigger]) -> type[RuleTrigger]:
    """A :class:`RuleTrigger` class whose triggers are those of ``trigger_class`` with a floor:
    a channel transmits when ``trigger_class``'s rule fires for it and at least ``floor_s``
    seconds have passed since its last transmission (a minimum inter-event time, the rule
    gating a clock). Built with ``(observation_space, action_space, observation_names,
    floor_s, **keywords)``, ``keywords`` those of ``trigger_class``; one class per rule, so the
    compiled loop compiles each floored rule once. At a reset the time since transmission is
    0, so a floored trigger alone first transmits once the floor has passed; a decision set's
    floored action transmits at its decision instant (:mod:`etsc_envs.decisions`)."""
    return _channel_timed_trigger_class(
        trigger_class,
        channel_timed_rule(trigger_class.rule, heartbeat=False),
        "floor_s",
        f"Floored{trigger_class.__name__}",
    )


@functools.cache
def channel_heartbeat_trigger_class(trigger_class: type[RuleTrigger]) -> type[RuleTrigger]:
    """A :class:`RuleTrigger` class whose triggers are those of ``trigger_class`` with a
    heartbeat per channel: a channel transmits when ``trigger_class``'s rule fires for it or
    once ``heartbeat_s`` seconds have passed since its own last transmission (a maximum
    inter-event time per channel; unlike :class:`HeartbeatPolicy`, one channel's heartbeat
    sends that channel alone, as a follower of paper 001 with a heartbeat of its own would).
    Built with ``(observation_space, action_space, observation_names, heartbeat_s,
    **keywords)``; one class per rule, so the compiled loop compiles each once. At a reset the
    time since transmission is 0, so the heartbeat first beats ``heartbeat_s`` after it."""
    return _channel_timed_trigger_class(
        trigger_class,
        channel_timed_rule(trigger_class.rule, heartbeat=True),
        "heartbeat_s",
        f"ChannelHeartbeat{trigger_class.__name__}",
    )


def timed_rule_class(
    trigger_class: type[RuleTrigger],
    floor_s: float | None = None,
    heartbeat_s: float | None = None,
) -> tuple[type[RuleTrigger], dict[str, float]]:
    """``trigger_class`` with a floor of ``floor_s`` seconds (:func:`floored_trigger_class`)
    or a heartbeat per channel of ``heartbeat_s`` seconds
    (:func:`channel_heartbeat_trigger_class`) where one is given, and the keyword that sets
    that bound when the class is built (``{}`` for neither); ``ValueError`` for both."""
    if floor_s is not None and heartbeat_s is not None:
        raise ValueError("floor_s and heartbeat_s: a rule takes one of the two")
    if floor_s is not None:
        return floored_trigger_class(trigger_class), {"floor_s": floor_s}
    if heartbeat_s is not None:
        return channel_heartbeat_trigger_class(trigger_class), {"heartbeat_s": heartbeat_s}
    return trigger_class, {}


def instants_seconds(instants: float, sampling_period_s: float) -> float:
    """The time since transmission that marks ``instants`` sampling instants: a channel that
    transmitted at instant k reaches it at instant k + ``instants`` (its time since
    transmission there is ``instants`` periods; half a period below, so float32 observations
    compare safely). A floor or heartbeat of ``instants`` instants is this many seconds; an
    infinite count (no bound) stays infinite."""
    if math.isinf(instants):
        return math.inf
    return (float(instants) - 0.5) * float(sampling_period_s)


@jit
def clock_rule(observation, indices, parameters, out):
    """Periodic transmission on one observation: channel c (its time since transmission at
    ``indices[c]``) transmits at the episode's first instant, where that time is 0 (below
    ``parameters[1]``, half a period), and once it reaches ``every`` periods (at least
    ``parameters[0]``, ``every - 1/2`` periods)."""
    for channel in range(out.shape[0]):
        elapsed = float(observation[indices[channel]])
        out[channel] = 1 if elapsed < parameters[1] or elapsed >= parameters[0] else 0


class ClockTrigger(RuleTrigger):
    """Periodic transmission every ``every`` sampling instants as a stateless rule on the
    channels' times since transmission, so that the compiled loop runs it like a paper's rule.

    Its decisions are :class:`PeriodicPolicy`'s (instants 0, K, 2K, ... of every episode on
    every channel): a channel's time since transmission is 0 only at the episode's first
    instant, and reaches K periods exactly K instants after each transmission
    (``tests/test_baselines.py`` checks the two instant for instant on every id).

    Args:
        every: K, the period in sampling instants (an integer >= 1).
        sampling_period_s: the env's sampling period (s).
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        every: int = 1,
        sampling_period_s: float = 1.0,
    ) -> None:
        self.every = _instants("every", every, 1)
        period = float(sampling_period_s)
        if not np.isfinite(period) or period <= 0.0:
            raise ValueError(
                f"sampling_period_s must be a finite number > 0 (s), got {sampling_period_s!r}"
            )
        bits = transmit_bits(action_space)
        channels = 1 if bits is None else bits
        times = time_since_transmission_indices(observation_names, channels)
        super().__init__(
            observation_space,
            action_space,
            indices=times,
            parameters=[instants_seconds(self.every, period), 0.5 * period],
            keywords={"every": self.every, "sampling_period_s": period},
        )

    rule = staticmethod(clock_rule)

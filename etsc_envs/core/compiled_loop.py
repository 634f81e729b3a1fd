"""The compiled step loop: one sampling instant of many independent closed loops in one call.

Every environment of the suite keeps the whole state of its closed loop in flat arrays with a
leading batch axis (:class:`LoopArrays`): the channel's held values and transmission
bookkeeping, the running cost, the observation, and one float64 row per environment holding
the problem's own state (plant, observer, controller, running metrics, per-episode model
parameters) in a layout the problem documents. A single environment owns a batch of one row;
a vector environment owns ``num_envs`` rows and each of its sub-environments is bound to a view
of one row. Both advance through the same compiled function, built once per problem by
:func:`make_loop_step` from five compiled kernels (:class:`ProblemKernels`), so the design
page's step semantics are written once:

1. at ``t_k = k h`` every channel whose transmit bit is set and whose receiver
   ``accepts`` it takes the current ``channel_values`` (zero-order hold);
2. ``advance`` moves plant, observer and controller to ``t_k + h`` with the held values and
   writes each channel's share of the step's accuracy cost;
3. ``failure`` returns 0 or a problem-specific code; a failure ends the episode, keeps the
   last observation, and charges ``failure_cost`` for every step it cuts from the horizon;
4. otherwise ``features`` and the time since each channel's last transmission form the
   observation;
5. the reward is ``-cost/cost_scale - transmission_penalty * (channels sent)``, in total and
   per channel (each channel pays its own cost, its own transmissions and an equal share of a
   failure charge, so the per-channel rewards sum to the total).

:func:`make_loop_interval` compiles, around the same step, an interval of several instants
(a first action, then holds) in one call, for decisions that hold the channel for many
instants (:meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_interval`).
:func:`loop_rule_interval` does the same for instants decided by a paper's triggering rule
(a compiled kernel of :class:`~etsc_envs.triggers.base.RuleTrigger`): the rule reads each
instant's observation inside the loop, for the self-triggered "follow the paper" decisions and
for evaluating a paper trigger over whole episodes without a Python call per instant.
"""

from __future__ import annotations

import functools
from collections import namedtuple
from collections.abc import Callable
from typing import Any

import numpy as np

from etsc_envs.core.jit import closure_jit, jit

LoopArrays = namedtuple(
    "LoopArrays",
    [
        "step_index",  # (n,) int64: sampling instants completed in the episode
        "held",  # (n, C, W): the value each channel's receiver holds
        "last_sent_s",  # (n, C): time of the last transmission (of the reset if none)
        "transmissions",  # (n, C) int64: transmissions in the episode
        "interevent_sum_s",  # (n, C): sum of the times between consecutive transmissions
        "interevent_min_s",  # (n, C): their minimum (inf while fewer than two)
        "sent",  # (n, C) int64: 1 where the last step transmitted
        "channel_costs",  # (n, C): each channel's accuracy cost of the last step
        "channel_rewards",  # (n, C): each channel's reward of the last step
        "reward",  # (n,): the last step's reward
        "cost",  # (n,): the last step's accuracy cost (all channels)
        "sent_count",  # (n,) int64: channels that transmitted in the last step
        "transmission_count",  # (n,) int64: transmissions in the episode (all channels)
        "cost_sum",  # (n,): accuracy cost summed over the episode
        "failure_code",  # (n,) int64: 0, or why the episode ended (problem-specific)
        "observation",  # (n, F + C) float32: features, then time since each transmission
        "state",  # (n, S): the problem's state row
    ],
)
"""Every array a batch of closed loops lives in (see the module docstring)."""

ProblemKernels = namedtuple(
    "ProblemKernels", ["channel_values", "accepts", "advance", "failure", "features"]
)
"""The compiled functions that make a closed loop out of the generic step:

* ``channel_values(state, constants, time_s) -> (C, W) array``: what each channel would send;
* ``accepts(state, held, constants, time_s, channel) -> bool``: whether the receiver takes a
  transmission now (use :func:`always_accepts` unless it can be busy);
* ``advance(state, constants, step_index, h, held, sent, channel_costs) -> None``: one sampling
  period from ``t_k = step_index * h``; updates ``state`` in place and writes ``channel_costs``;
* ``failure(state, constants) -> int``: 0, or a positive code the env turns into a message;
* ``features(state, constants, out) -> None``: the problem's observation components at the
  current instant.

``state`` is one row of :attr:`LoopArrays.state`; ``constants`` is the problem's immutable
namedtuple, the same for every environment of a batch.
"""


@jit
def always_accepts(
    state: np.ndarray, held: np.ndarray, constants, time_s: float, channel: int
) -> bool:
    """``accepts`` of a receiver that can always take a transmission."""
    return True


def stored_features(features: slice) -> Callable[..., None]:
    """``features`` kernel of a problem whose step stores the observation's features in the
    state row, at ``state[features]``."""
    start, stop = features.start, features.stop

    @jit
    def copy_features(state: np.ndarray, constants, out: np.ndarray) -> None:
        out[:] = state[start:stop]

    return copy_features


def allocate_loop_arrays(
    n_envs: int, n_channels: int, channel_width: int, n_features: int, state_width: int
) -> LoopArrays:
    """Zeroed arrays for ``n_envs`` closed loops."""
    return LoopArrays(
        step_index=np.zeros(n_envs, dtype=np.int64),
        held=np.zeros((n_envs, n_channels, channel_width)),
        last_sent_s=np.zeros((n_envs, n_channels)),
        transmissions=np.zeros((n_envs, n_channels), dtype=np.int64),
        interevent_sum_s=np.zeros((n_envs, n_channels)),
        interevent_min_s=np.full((n_envs, n_channels), np.inf),
        sent=np.zeros((n_envs, n_channels), dtype=np.int64),
        channel_costs=np.zeros((n_envs, n_channels)),
        channel_rewards=np.zeros((n_envs, n_channels)),
        reward=np.zeros(n_envs),
        cost=np.zeros(n_envs),
        sent_count=np.zeros(n_envs, dtype=np.int64),
        transmission_count=np.zeros(n_envs, dtype=np.int64),
        cost_sum=np.zeros(n_envs),
        failure_code=np.zeros(n_envs, dtype=np.int64),
        observation=np.zeros((n_envs, n_features + n_channels), dtype=np.float32),
        state=np.zeros((n_envs, state_width)),
    )


def loop_rows(arrays: LoopArrays, start: int, stop: int) -> LoopArrays:
    """Views of rows ``start:stop`` of every array (writes reach the batch)."""
    return LoopArrays(*(array[start:stop] for array in arrays))


def make_loop_step(kernels: ProblemKernels) -> Callable[..., None]:
    """Compile the step of the module docstring around a problem's kernels.

    The compiled function (which releases the GIL, so that threads can step disjoint row
    ranges of one batch at once) has the signature ``step(actions, active, arrays, constants, h,
    n_steps, cost_scale, transmission_penalty, failure_cost)``: ``actions`` is an ``(n, C)``
    int array of transmit bits, ``active`` an ``(n,)`` bool array of the rows to advance (the
    others are left untouched), ``arrays`` a :class:`LoopArrays` of ``n`` rows. The kernels
    are bound at compile time rather than passed as arguments so that the machine code can be
    cached on disk. Every problem's step shares one cache index, which records the argument
    types: a problem's ``constants`` must therefore be a namedtuple of an importable module (or
    a plain tuple), or other processes fail to read the index.
    """
    channel_values = kernels.channel_values
    accepts = kernels.accepts
    advance = kernels.advance
    failure = kernels.failure
    features = kernels.features

    @closure_jit
    def loop_step(
        actions,
        active,
        arrays,
        constants,
        h,
        n_steps,
        cost_scale,
        transmission_penalty,
        failure_cost,
    ):
        # One loop over the rows with the batch's arrays bound once: a per-row call taking the
        # namedtuple of arrays cost 0.4 µs a row in argument copies and reference counts.
        step_indices = arrays.step_index
        states = arrays.state
        helds = arrays.held
        sents = arrays.sent
        transmissions = arrays.transmissions
        last_sent_s = arrays.last_sent_s
        interevent_sum_s = arrays.interevent_sum_s
        interevent_min_s = arrays.interevent_min_s
        channel_costs = arrays.channel_costs
        channel_rewards = arrays.channel_rewards
        observations = arrays.observation
        n_channels = helds.shape[1]
        n_features = observations.shape[1] - n_channels
        scratch = np.empty(n_features)
        for i in range(actions.shape[0]):
            if not active[i]:
                continue
            step_index = step_indices[i]
            time_s = step_index * h
            state = states[i]
            held = helds[i]
            sent = sents[i]
            values = channel_values(state, constants, time_s)
            sent_total = 0
            for channel in range(n_channels):
                sent[channel] = 0
                if actions[i, channel] != 0 and accepts(state, held, constants, time_s, channel):
                    held[channel, :] = values[channel]
                    if transmissions[i, channel] > 0:
                        interval = time_s - last_sent_s[i, channel]
                        interevent_sum_s[i, channel] += interval
                        if interval < interevent_min_s[i, channel]:
                            interevent_min_s[i, channel] = interval
                    last_sent_s[i, channel] = time_s
                    transmissions[i, channel] += 1
                    sent[channel] = 1
                    sent_total += 1
            costs = channel_costs[i]
            advance(state, constants, step_index, h, held, sent, costs)
            step_index += 1
            step_indices[i] = step_index
            code = failure(state, constants)
            arrays.failure_code[i] = code
            cost = costs.sum()
            failure_charge = 0.0
            if code != 0:
                if not np.isfinite(cost):
                    costs[:] = 0.0
                    cost = 0.0
                failure_charge = failure_cost * (n_steps - step_index)
            else:
                observation = observations[i]
                features(state, constants, scratch)
                observation[:n_features] = scratch
                time_next = step_index * h
                for channel in range(n_channels):
                    observation[n_features + channel] = time_next - last_sent_s[i, channel]
            arrays.cost[i] = cost
            arrays.sent_count[i] = sent_total
            arrays.transmission_count[i] += sent_total
            arrays.cost_sum[i] += cost
            arrays.reward[i] = (
                -(cost + failure_charge) / cost_scale - transmission_penalty * sent_total
            )
            share = failure_charge / n_channels
            for channel in range(n_channels):
                channel_rewards[i, channel] = (
                    -(costs[channel] + share) / cost_scale - transmission_penalty * sent[channel]
                )

    return loop_step


def make_loop_interval(loop_step: Callable[..., None]) -> Callable[..., None]:
    """Compile an interval of several sampling instants around a compiled ``loop_step``.

    The compiled function has the signature ``interval(first_actions, active, arrays,
    constants, h, n_steps, cost_scale, transmission_penalty, failure_cost, instants, gamma,
    discounted, steps_run, step_costs, step_sent)``; the arguments up to ``failure_cost`` are
    ``loop_step``'s. Each active row runs ``loop_step`` with its ``first_actions`` at the first
    instant and all-zero actions (hold) after, for ``instants`` instants or until it fails or
    reaches the horizon ``n_steps``, whichever comes first. Per row it writes
    ``discounted = sum_k gamma**k * reward_k`` over the instants run (summed in order, as a
    Python loop over the steps would), ``steps_run``, and each instant's accuracy cost and
    transmit bits in ``step_costs[:, k]`` and ``step_sent[:, k]`` (``(n, >= instants)`` and
    ``(n, >= instants, C)`` arrays). The loop arrays end exactly as after ``steps_run`` calls of
    ``loop_step``, so the step semantics stay those of :func:`make_loop_step`.
    """

    @closure_jit
    def loop_interval(
        first_actions,
        active,
        arrays,
        constants,
        h,
        n_steps,
        cost_scale,
        transmission_penalty,
        failure_cost,
        instants,
        gamma,
        discounted,
        steps_run,
        step_costs,
        step_sent,
    ):
        running = active.copy()
        discounted[:] = 0.0
        steps_run[:] = 0
        actions = first_actions
        hold = np.zeros_like(first_actions)
        for instant in range(instants):
            loop_step(
                actions,
                running,
                arrays,
                constants,
                h,
                n_steps,
                cost_scale,
                transmission_penalty,
                failure_cost,
            )
            discount = gamma ** float(instant)
            any_running = False
            for i in range(running.shape[0]):
                if not running[i]:
                    continue
                discounted[i] += discount * arrays.reward[i]
                step_costs[i, instant] = arrays.cost[i]
                step_sent[i, instant] = arrays.sent[i]
                steps_run[i] = instant + 1
                running[i] = arrays.failure_code[i] == 0 and arrays.step_index[i] < n_steps
                any_running = any_running or running[i]
            if not any_running:
                break
            actions = hold

    return loop_interval


@functools.cache
def loop_rule_interval(
    loop_step: Callable[..., None], rule: Callable[..., None]
) -> Callable[..., None]:
    """Compile (once per step and rule) an interval whose instants a triggering rule decides.

    The compiled function has the signature ``interval(active, arrays, constants, h, n_steps,
    cost_scale, transmission_penalty, failure_cost, indices, parameters, instants, stop_on_rule,
    send_first, gamma, actions, discounted, channel_returns, steps_run, step_costs,
    step_sent)``; the arguments from ``arrays`` to ``failure_cost`` are ``loop_step``'s, and
    ``indices``, ``parameters`` those of ``rule(observation, indices, parameters, out)``. At
    each instant every running row's transmit bits are ``rule`` applied to its current
    observation (written to the scratch ``actions``, ``(n, C)`` int64), then ``loop_step``
    advances the running rows; with ``send_first``, every channel sends at the first instant
    whatever the rule decides (a heartbeat). A row runs ``instants`` instants, or until it fails
    or reaches the horizon ``n_steps``, or — with ``stop_on_rule`` — until just before a later
    instant (not the first) at which the rule sends on any channel: that instant is left for the
    next call. Per row it adds ``gamma**k * reward_k`` to ``discounted`` and each channel's
    reward to ``channel_returns`` (both summed in order, as a Python loop over the steps would,
    and not zeroed first), and writes ``steps_run`` and each instant's accuracy cost and
    transmit bits in ``step_costs[:, k]`` and ``step_sent[:, k]`` (``(n, >= instants)`` and
    ``(n, >= instants, C)`` arrays). The loop arrays end exactly as after ``steps_run`` calls of
    ``loop_step`` with the rule's decisions.
    """

    @closure_jit
    def rule_interval(
        active,
        arrays,
        constants,
        h,
        n_steps,
        cost_scale,
        transmission_penalty,
        failure_cost,
        indices,
        parameters,
        instants,
        stop_on_rule,
        send_first,
        gamma,
        actions,
        discounted,
        channel_returns,
        steps_run,
        step_costs,
        step_sent,
    ):
        running = active.copy()
        steps_run[:] = 0
        observations = arrays.observation
        n_channels = actions.shape[1]
        for instant in range(instants):
            any_running = False
            for i in range(running.shape[0]):
                if not running[i]:
                    continue
                rule(observations[i], indices, parameters, actions[i])
                if send_first and instant == 0:
                    actions[i][:] = 1
                if stop_on_rule and instant > 0 and actions[i].sum() > 0:
                    running[i] = False
                else:
                    any_running = True
            if not any_running:
                break
            loop_step(
                actions,
                running,
                arrays,
                constants,
                h,
                n_steps,
                cost_scale,
                transmission_penalty,
                failure_cost,
            )
            discount = gamma ** float(instant)
            for i in range(running.shape[0]):
                if not running[i]:
                    continue
                discounted[i] += discount * arrays.reward[i]
                for channel in range(n_channels):
                    channel_returns[i, channel] += arrays.channel_rewards[i, channel]
                step_costs[i, instant] = arrays.cost[i]
                step_sent[i, instant] = arrays.sent[i]
                steps_run[i] = instant + 1
                running[i] = arrays.failure_code[i] == 0 and arrays.step_index[i] < n_steps

    return rule_interval


def compiled_entry(dispatcher: Any, *args: Any) -> Callable[..., Any]:
    """The machine code of a compiled function for the types of ``args`` (compiled or loaded
    from the disk cache if need be).

    Calling it skips Numba's per-call type dispatch, which costs about 10 µs for the loop's
    namedtuples of arrays, against about 2 µs for the call itself. Later calls must pass
    arguments of exactly the same types (the same arrays' dtypes, dimensions and layouts).
    """
    if not hasattr(dispatcher, "compile"):  # NUMBA_DISABLE_JIT=1: a plain Python function
        return dispatcher
    return dispatcher.compile(tuple(dispatcher.typeof_pyval(arg) for arg in args))

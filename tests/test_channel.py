"""Zero-order-hold bookkeeping of :class:`HeldChannel` and the episode communication metrics.

Checked properties:

* the receiving side sees only the last transmitted value of each channel: a masked send
  refreshes exactly the masked channels, the others keep their held values;
* synchronising at reset is not a transmission; each send counts one transmission per masked
  channel, and inter-event intervals are recorded from the second transmission of a channel on;
* ``time_since_sent`` measures the age of each held value (since reset if never sent);
* ``communication_metrics`` pools the channels into the documented episode record, with the
  transmission rate normalised per sampling instant and per channel, and ``None`` inter-event
  statistics when no channel transmitted twice.
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from etsc_envs.core.channel import HeldChannel
from etsc_envs.core.metrics import (
    COMMON_EPISODE_KEYS,
    communication_metrics,
    interevent_summary,
)

METRIC_KEYS = {
    "steps",
    "sim_time_s",
    "mean_cost",
    "transmissions",
    "transmission_rate",
    "mean_interevent_s",
    "min_interevent_s",
}


@pytest.mark.parametrize(("n_channels", "width"), [(1, 3), (3, 1)])
def test_reset_synchronises_without_counting(n_channels, width):
    channel = HeldChannel(n_channels, width)
    values = np.array([1.0, 2.0, 3.0])
    channel.reset(values, time_s=2.0)
    assert_array_equal(channel.held, values.reshape(n_channels, width))
    assert_array_equal(channel.transmissions, np.zeros(n_channels))
    assert channel.interevent_s == [[] for _ in range(n_channels)]
    assert_allclose(channel.time_since_sent(2.5), np.full(n_channels, 0.5))


def test_single_channel_of_width_three_holds_the_whole_vector():
    channel = HeldChannel(1, 3)
    channel.reset(np.array([1.0, 2.0, 3.0]), 0.0)

    assert channel.send(np.array([False]), np.array([9.0, 9.0, 9.0]), 0.1) == 0
    assert_array_equal(channel.held, [[1.0, 2.0, 3.0]])
    assert_array_equal(channel.transmissions, [0])

    assert channel.send(np.array([True]), np.array([4.0, 5.0, 6.0]), 0.2) == 1
    assert_array_equal(channel.held, [[4.0, 5.0, 6.0]])
    assert_array_equal(channel.transmissions, [1])
    assert channel.interevent_s == [[]]  # first transmission after reset: no interval
    assert_allclose(channel.time_since_sent(0.5), [0.3])

    assert channel.send(np.array([1]), np.array([7.0, 8.0, 9.0]), 0.7) == 1
    assert_array_equal(channel.held, [[7.0, 8.0, 9.0]])
    assert_array_equal(channel.transmissions, [2])
    assert_allclose(channel.interevent_s[0], [0.5])
    assert_allclose(channel.time_since_sent(0.7), [0.0])


def test_three_scalar_channels_refresh_only_masked_entries():
    channel = HeldChannel(3, 1)
    channel.reset(np.array([1.0, 2.0, 3.0]), 1.0)

    sent = channel.send(np.array([True, False, True]), np.array([10.0, 20.0, 30.0]), 1.1)
    assert sent == 2
    assert_array_equal(channel.held[:, 0], [10.0, 2.0, 30.0])
    assert_array_equal(channel.transmissions, [1, 0, 1])
    assert channel.interevent_s == [[], [], []]
    assert_allclose(channel.time_since_sent(1.4), [0.3, 0.4, 0.3])

    sent = channel.send(np.array([1, 1, 0]), np.array([11.0, 21.0, 31.0]), 1.6)
    assert sent == 2
    assert_array_equal(channel.held[:, 0], [11.0, 21.0, 30.0])
    assert_array_equal(channel.transmissions, [2, 1, 1])
    assert_allclose(channel.interevent_s[0], [0.5])
    assert channel.interevent_s[1] == []  # channel 1's first transmission
    assert channel.interevent_s[2] == []
    assert_allclose(channel.time_since_sent(2.0), [0.4, 0.4, 0.9])

    # A new episode clears the counts and intervals.
    channel.reset(np.array([0.0, 0.0, 0.0]), 5.0)
    assert_array_equal(channel.transmissions, [0, 0, 0])
    assert channel.interevent_s == [[], [], []]
    assert_allclose(channel.time_since_sent(5.0), [0.0, 0.0, 0.0])


def run_schedule(channel, schedule, dt):
    """Send at step k on the channels listed in ``schedule[k]`` the value k."""
    for step, channels in schedule.items():
        mask = np.zeros(channel.n_channels, dtype=bool)
        mask[list(channels)] = True
        channel.send(mask, np.full(channel.n_channels * channel.width, float(step)), step * dt)


def test_communication_metrics_on_hand_computed_schedule():
    dt, steps = 0.1, 10
    channel = HeldChannel(3, 1)
    channel.reset(np.zeros(3), 0.0)
    # channel 0 at t = 0.2, 0.5, 0.9 (intervals 0.3, 0.4); channel 1 once at t = 0.4;
    # channel 2 at t = 0.1, 0.2 (interval 0.1).
    run_schedule(channel, {1: [2], 2: [0, 2], 4: [1], 5: [0], 9: [0]}, dt)
    metrics = communication_metrics(channel, steps, steps * dt, cost_sum=5.0)

    assert set(metrics) == METRIC_KEYS
    assert set(COMMON_EPISODE_KEYS) == METRIC_KEYS | {"failure"}  # the loop adds "failure"
    assert metrics["steps"] == 10
    assert_allclose(metrics["sim_time_s"], 1.0)
    assert_allclose(metrics["mean_cost"], 0.5)
    assert metrics["transmissions"] == 6
    assert_allclose(metrics["transmission_rate"], 6 / (10 * 3))
    assert_allclose(metrics["mean_interevent_s"], (0.3 + 0.4 + 0.1) / 3)
    assert_allclose(metrics["min_interevent_s"], 0.1)
    assert_array_equal(channel.held[:, 0], [9.0, 4.0, 2.0])


@pytest.mark.parametrize(
    "schedule",
    [{}, {3: [1]}, {2: [0], 6: [1], 7: [2]}],
    ids=["none", "one-transmission", "once-per-channel"],
)
def test_communication_metrics_without_intervals(schedule):
    """Fewer than two transmissions on every channel: no inter-event statistics."""
    channel = HeldChannel(3, 1)
    channel.reset(np.zeros(3), 0.0)
    run_schedule(channel, schedule, 0.1)
    metrics = communication_metrics(channel, 10, 1.0, cost_sum=2.0)
    n_sent = sum(len(channels) for channels in schedule.values())
    assert set(metrics) == METRIC_KEYS
    assert metrics["transmissions"] == n_sent
    assert_allclose(metrics["transmission_rate"], n_sent / 30)
    assert metrics["mean_interevent_s"] is None
    assert metrics["min_interevent_s"] is None


def test_communication_metrics_of_empty_episode():
    channel = HeldChannel(1, 3)
    channel.reset(np.zeros(3), 0.0)
    metrics = communication_metrics(channel, 0, 0.0, cost_sum=0.0)
    assert metrics["mean_cost"] == 0.0
    assert metrics["transmission_rate"] == 0.0
    assert metrics["transmissions"] == 0


def test_every_channel_every_step_has_rate_one():
    dt, steps = 0.05, 8
    channel = HeldChannel(3, 1)
    channel.reset(np.zeros(3), 0.0)
    run_schedule(channel, {k: [0, 1, 2] for k in range(1, steps + 1)}, dt)
    metrics = communication_metrics(channel, steps, steps * dt, cost_sum=0.0)
    assert_allclose(metrics["transmission_rate"], 1.0)
    assert_allclose(metrics["mean_interevent_s"], dt)
    assert_allclose(metrics["min_interevent_s"], dt)


def test_interevent_summary():
    assert interevent_summary([]) == (None, None)
    mean, minimum = interevent_summary([0.2, 0.4, 0.3])
    assert_allclose([mean, minimum], [0.3, 0.2])
    assert isinstance(mean, float)
    assert isinstance(minimum, float)

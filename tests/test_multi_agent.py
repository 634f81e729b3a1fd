"""The PettingZoo view of a shared multi-channel loop, :mod:`etsc_envs.core.multi_agent`.

Checked on a toy loop of two independent scalar integrators (channel i holds the control of
integrator i, which drifts away unless updated), so every number is known by hand:

* each agent observes its own feature block and its own transmission clock, with bounds taken
  from the loop's observation space; ``state()`` is the loop's whole observation;
* each agent's reward is ``-cost_i/cost_scale - transmission_penalty * sent_i`` and the rewards
  sum to the loop's reward, also on a failure, whose horizon charge is split evenly;
* all agents end together (truncation at the horizon, termination with the failure's reason),
  and the per-agent communication record counts each channel on its own;
* a loop that breaks the naming contract, and bad or missing actions, raise ``ValueError``.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from pettingzoo.test import parallel_api_test

from etsc_envs.core.channel import HeldChannel
from etsc_envs.core.loop import EventTriggeredEnv
from etsc_envs.core.multi_agent import (
    EventTriggeredParallelEnv,
    agent_major_names,
    agent_metrics,
)

DRIFT = 1.0
PERIOD_S = 0.1


class TwoIntegrators(EventTriggeredEnv):
    """ẋ_i = DRIFT - u_i with u_i held; an update sets u_i = DRIFT + x_i / PERIOD_S, which brings
    x_i back to 0 in one period. Cost_i = |x_i|; failure when |x_i| > ``limit``."""

    def __init__(self, limit: float = 10.0, names: tuple[str, ...] | None = None) -> None:
        self.agent_names = ("integrator_0", "integrator_1")
        self.agent_feature_names = ("x", "u")
        super().__init__(
            feature_names=names or agent_major_names(self.agent_feature_names, 2),
            feature_low=np.array([-limit, -np.inf, -limit, -np.inf]),
            feature_high=np.array([limit, np.inf, limit, np.inf]),
            n_channels=2,
            channel_width=1,
            sampling_period_s=PERIOD_S,
            horizon_s=1.0,
            transmission_penalty=0.5,
            cost_scale=2.0,
            failure_cost=3.0,
        )
        self.limit = limit
        self.x = np.zeros(2)
        self.channel_costs = np.zeros(2)

    def _reset_problem(self, options):
        self.x = np.array([0.2, 0.5])

    def _channel_values(self):
        return DRIFT + self.x / PERIOD_S

    def _advance(self):
        self.x = self.x + PERIOD_S * (DRIFT - self.channel.held[:, 0])
        self.channel_costs = np.abs(self.x)
        return float(self.channel_costs.sum())

    def _failure(self):
        return "runaway" if np.abs(self.x).max() > self.limit else None

    def _features(self):
        return np.array([self.x[0], self.channel.held[0, 0], self.x[1], self.channel.held[1, 0]])

    def _paper_metrics(self):
        return {"agents": agent_metrics(self.channel, self.step_index, self.agent_names)}


def test_passes_the_pettingzoo_parallel_api_test():
    parallel_api_test(EventTriggeredParallelEnv(TwoIntegrators()), num_cycles=50)


def test_observations_rewards_and_clocks_per_agent():
    env = EventTriggeredParallelEnv(TwoIntegrators())
    assert env.agent_observation_names == ("x", "u", "time_since_transmission_s")
    assert_array_equal(env.observation_space("integrator_1").low, [-10.0, -np.inf, 0.0])
    observations, infos = env.reset(seed=0)
    assert_allclose(observations["integrator_1"], [0.5, 6.0, 0.0])  # held u synchronised
    assert set(infos) == {"integrator_0", "integrator_1"}
    # Step 1 brings both to 0 (the reset synchronised both channels on the one-step law).
    env.step({"integrator_0": 0, "integrator_1": 1})
    # Step 2: integrator_0 holds u = 3 and drifts to -0.2; integrator_1 updates to u = 1.
    observations, rewards, _, _, infos = env.step({"integrator_0": 0, "integrator_1": 1})
    assert_allclose(observations["integrator_0"], [-0.2, 3.0, 0.2], rtol=1e-6)
    assert_allclose(observations["integrator_1"], [0.0, 1.0, 0.1], atol=1e-7)
    assert_allclose(rewards["integrator_0"], -0.2 / 2.0)
    assert_allclose(rewards["integrator_1"], -0.5, atol=1e-12)
    assert infos["integrator_1"]["transmissions"] == 2 and infos["integrator_1"]["transmitted"] == 1
    assert_allclose(infos["integrator_0"]["cost"], 0.2)
    assert_allclose(env.state()[:4], [-0.2, 3.0, 0.0, 1.0], atol=1e-7)


def test_truncation_ends_every_agent_with_per_agent_metrics():
    env = EventTriggeredParallelEnv(TwoIntegrators())
    env.reset(seed=0)
    bits = [(1, 0), (0, 0), (1, 1), (0, 0), (1, 0), (0, 0), (0, 0), (0, 0), (0, 0), (0, 0)]
    for k, (a, b) in enumerate(bits):
        _, _, terminations, truncations, infos = env.step({"integrator_0": a, "integrator_1": b})
        assert not any(terminations.values())
        assert all(truncations.values()) == (k == len(bits) - 1)
    assert env.agents == []
    agents = infos["integrator_0"]["episode_metrics"]["agents"]
    assert agents["integrator_0"]["transmissions"] == 3
    assert_allclose(agents["integrator_0"]["mean_interevent_s"], 0.2)
    assert_allclose(agents["integrator_0"]["transmission_rate"], 0.3)
    assert agents["integrator_1"]["transmissions"] == 1
    assert agents["integrator_1"]["mean_interevent_s"] is None
    with pytest.raises(RuntimeError):
        env.step({"integrator_0": 0, "integrator_1": 0})


def test_failure_terminates_all_and_rewards_sum_to_the_loop_reward():
    loop = TwoIntegrators(limit=0.75)
    env = EventTriggeredParallelEnv(loop)
    twin = TwoIntegrators(limit=0.75)
    env.reset(seed=0)
    twin.reset(seed=0)
    while env.agents:
        _, rewards, terminations, _, infos = env.step({"integrator_0": 0, "integrator_1": 0})
        _, reward, *_ = twin.step(np.zeros(2, dtype=int))
        assert_allclose(sum(rewards.values()), reward, rtol=1e-12)
    assert all(terminations.values())
    assert infos["integrator_0"]["failure"] == "runaway"
    cut = loop.n_steps - loop.step_index
    assert cut > 0
    assert_allclose(rewards["integrator_0"], -(loop.channel_costs[0] + 1.5 * cut) / 2.0)


def test_loop_breaking_the_naming_contract_is_rejected():
    with pytest.raises(ValueError, match="agent_major_names"):
        EventTriggeredParallelEnv(TwoIntegrators(names=("a", "b", "c", "d")))


@pytest.mark.parametrize(
    ("actions", "message"),
    [
        ({"integrator_0": 1}, "missing"),
        ({"integrator_0": 1, "integrator_1": 0, "other": 1}, "unknown"),
        ({"integrator_0": 3, "integrator_1": 0}, "action of integrator_0"),
        ({"integrator_0": 0, "integrator_1": np.array([1, 1])}, "action of integrator_1"),
    ],
)
def test_bad_actions_are_rejected(actions, message):
    env = EventTriggeredParallelEnv(TwoIntegrators())
    env.reset(seed=0)
    with pytest.raises(ValueError, match=message):
        env.step(actions)


def test_agent_metrics_count_each_channel():
    channel = HeldChannel(3, 1)
    channel.reset(np.zeros(3), 0.0)
    for t, mask in ((0.0, [1, 0, 0]), (0.5, [1, 1, 0]), (2.0, [1, 0, 0])):
        channel.send(np.array(mask, dtype=bool), np.ones(3), t)
    record = agent_metrics(channel, 40, ("a", "b", "c"))
    assert record["a"] == {
        "transmissions": 3,
        "transmission_rate": 3 / 40,
        "mean_interevent_s": 1.0,
        "min_interevent_s": 0.5,
    }
    assert record["b"]["transmissions"] == 1 and record["b"]["min_interevent_s"] is None
    assert record["c"]["transmission_rate"] == 0.0
    assert agent_major_names(("x", "y"), 2) == ("x_0", "y_0", "x_1", "y_1")

"""The PettingZoo view of a shared multi-channel loop, :mod:`etsc_envs.core.multi_agent`.

Checked on a toy compiled loop of independent scalar integrators (two unless said otherwise;
channel i holds the control of integrator i, which drifts away unless updated), so every
number is known by hand:

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

from etsc_envs.core.compiled_loop import ProblemKernels, always_accepts
from etsc_envs.core.jit import jit
from etsc_envs.core.loop_env import UNBOUNDED, EventTriggeredEnv
from etsc_envs.core.multi_agent import (
    EventTriggeredParallelEnv,
    agent_major_names,
    agent_metrics,
)

DRIFT = 1.0
PERIOD_S = 0.1
RUNAWAY = 1
LIMIT = 0
"""Index of the failure bound in the toy's constants, a plain tuple ``(limit,)``: the disk
cache's index of the shared loop step records the constants' type, and a namedtuple class of
this test module could not be unpickled by a process that never imported it."""


@jit
def toy_channel_values(state, constants, time_s):
    """The one-step law of every integrator, u_i = DRIFT + x_i / PERIOD_S."""
    n = state.shape[0] // 2
    return (DRIFT + state[:n] / PERIOD_S).reshape(n, 1)


@jit
def toy_advance(state, constants, step_index, h, held, sent, channel_costs):
    """x_i += h (DRIFT - u_i) with u_i held (kept in the state row for the features)."""
    n = state.shape[0] // 2
    for i in range(n):
        state[n + i] = held[i, 0]
        state[i] += h * (DRIFT - held[i, 0])
        channel_costs[i] = abs(state[i])


@jit
def toy_failure(state, constants):
    n = state.shape[0] // 2
    return RUNAWAY if np.abs(state[:n]).max() > constants[LIMIT] else 0


@jit
def toy_features(state, constants, out):
    n = state.shape[0] // 2
    for i in range(n):
        out[2 * i] = state[i]
        out[2 * i + 1] = state[n + i]


class Integrators(EventTriggeredEnv):
    """ẋ_i = DRIFT - u_i with u_i held; an update sets u_i = DRIFT + x_i / PERIOD_S, which brings
    x_i back to 0 in one period. Cost_i = |x_i|; failure when |x_i| > ``limit``. The state row
    is ``[x_0 .. x_{n-1}, u_0 .. u_{n-1}]``."""

    kernels = ProblemKernels(
        channel_values=toy_channel_values,
        accepts=always_accepts,
        advance=toy_advance,
        failure=toy_failure,
        features=toy_features,
    )

    def __init__(
        self,
        limit: float = 10.0,
        names: tuple[str, ...] | None = None,
        n_integrators: int = 2,
        horizon_s: float = 1.0,
    ) -> None:
        self.agent_names = tuple(f"integrator_{i}" for i in range(n_integrators))
        self.agent_feature_names = ("x", "u")
        super().__init__(
            feature_names=names or agent_major_names(self.agent_feature_names, n_integrators),
            feature_low=np.tile([-limit, -np.inf], n_integrators),
            feature_high=np.tile([limit, np.inf], n_integrators),
            n_channels=n_integrators,
            channel_width=1,
            state_width=2 * n_integrators,
            constants=(float(limit),),
            sampling_period_s=PERIOD_S,
            horizon_s=horizon_s,
            transmission_penalty=0.5,
            cost_scale=2.0,
            failure_cost=3.0,
        )

    def _reset_problem(self, options):
        n = self.n_channels
        self.state[:n] = np.linspace(0.2, 0.5, n)
        self.state[n:] = toy_channel_values(self.state, self.constants, 0.0)[:, 0]

    def _failure_message(self, code):
        return "runaway"

    def _paper_metrics(self):
        return {"agents": agent_metrics(self.arrays, self.step_index, self.agent_names)}

    def _settled_at_end(self, metrics):
        return True


# the API test resets with options={"options": 1} on purpose; the env says it ignores the key
@pytest.mark.filterwarnings("ignore:options. unknown key")
def test_passes_the_pettingzoo_parallel_api_test():
    parallel_api_test(EventTriggeredParallelEnv(Integrators()), num_cycles=50)


def test_observations_rewards_and_clocks_per_agent():
    env = EventTriggeredParallelEnv(Integrators())
    assert env.agent_observation_names == ("x", "u", "time_since_transmission_s")
    assert_array_equal(env.observation_space("integrator_1").low, [-10.0, -UNBOUNDED, 0.0])
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
    env = EventTriggeredParallelEnv(Integrators())
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
    loop = Integrators(limit=0.75)
    env = EventTriggeredParallelEnv(loop)
    twin = Integrators(limit=0.75)
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
        EventTriggeredParallelEnv(Integrators(names=("a", "b", "c", "d")))


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
    env = EventTriggeredParallelEnv(Integrators())
    env.reset(seed=0)
    with pytest.raises(ValueError, match=message):
        env.step(actions)


def test_agent_metrics_count_each_channel():
    loop = Integrators(limit=1e9, n_integrators=3, horizon_s=4.0)
    loop.reset(seed=0)
    sends = {0: [1, 0, 0], 5: [1, 1, 0], 20: [1, 0, 0]}  # at 0.0 s, 0.5 s and 2.0 s
    for k in range(40):
        loop.step(np.array(sends.get(k, [0, 0, 0])))
    record = agent_metrics(loop.arrays, 40, ("a", "b", "c"))
    assert record["a"] == {
        "transmissions": 3,
        "transmission_rate": 3 / 40,
        "mean_interevent_s": 1.0,
        "min_interevent_s": 0.5,
    }
    assert record["b"]["transmissions"] == 1 and record["b"]["min_interevent_s"] is None
    assert record["c"]["transmission_rate"] == 0.0
    assert agent_major_names(("x", "y"), 2) == ("x_0", "y_0", "x_1", "y_1")

"""The compiled step loop and the single-env base class, on a toy problem with known answers.

The toy: two channels each hold a scalar x_c with ẋ_c = drift_c - ξ_c (forward Euler), where ξ_c
is the value channel c last transmitted; the cost of channel c is |x_c|; the loop fails when
some |x_c| exceeds a bound; channel 1's receiver refuses transmissions while x_1 < 0.
"""

from __future__ import annotations

import os
import subprocess
import sys
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from etsc_envs.core.compiled_loop import (
    ProblemKernels,
    allocate_loop_arrays,
    loop_rows,
    make_loop_step,
)
from etsc_envs.core.jit import jit
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.metrics import COMMON_EPISODE_KEYS, interevent_summary

CONSTANTS = (np.array([1.0, 2.0]), 5.0)
"""(drift, bound). A plain tuple, not a namedtuple: the disk cache's index of the shared loop
step records the constants' type, and a namedtuple class of this test module could not be
unpickled by a process that never imported it."""
DRIFT, BOUND = 0, 1
H = 0.5
N_STEPS = 10
COST_SCALE = 2.0
PENALTY = 0.25
FAILURE_COST = 3.0


@jit
def toy_values(state, constants, time_s):
    return state[0:2].copy().reshape(2, 1)


@jit
def toy_accepts(state, held, constants, time_s, channel):
    return channel == 0 or state[1] >= 0.0


@jit
def toy_advance(state, constants, step_index, h, held, sent, channel_costs):
    for channel in range(2):
        state[channel] += h * (constants[DRIFT][channel] - held[channel, 0])
        channel_costs[channel] = abs(state[channel])


@jit
def toy_failure(state, constants):
    return 1 if max(abs(state[0]), abs(state[1])) > constants[BOUND] else 0


@jit
def toy_features(state, constants, out):
    out[0] = state[0]
    out[1] = state[1]


TOY_KERNELS = ProblemKernels(toy_values, toy_accepts, toy_advance, toy_failure, toy_features)
toy_step = make_loop_step(TOY_KERNELS)


def fresh_arrays(n_envs: int, x0: tuple[float, float] = (0.0, 0.0)):
    arrays = allocate_loop_arrays(n_envs, 2, 1, 2, 2)
    arrays.state[:, 0:2] = x0
    arrays.held[:, :, 0] = x0
    return arrays


def run_step(arrays, bits, active=None) -> None:
    n_envs = arrays.state.shape[0]
    actions = np.broadcast_to(np.asarray(bits, dtype=np.int64), (n_envs, 2)).copy()
    active = np.ones(n_envs, dtype=bool) if active is None else np.asarray(active)
    toy_step(actions, active, arrays, CONSTANTS, H, N_STEPS, COST_SCALE, PENALTY, FAILURE_COST)


def test_transmission_refreshes_the_held_value_and_holding_keeps_it():
    arrays = fresh_arrays(1)
    run_step(arrays, [0, 0])  # x = [0.5, 1.0], held stays 0
    assert_allclose(arrays.state[0, 0:2], [0.5, 1.0])
    run_step(arrays, [1, 0])  # channel 0 sends x_0(t_1) = 0.5 before advancing
    assert_allclose(arrays.held[0, :, 0], [0.5, 0.0])
    assert_allclose(arrays.state[0, 0:2], [0.5 + H * (1.0 - 0.5), 2.0])
    assert_array_equal(arrays.sent[0], [1, 0])
    run_step(arrays, [0, 0])
    assert_allclose(arrays.held[0, :, 0], [0.5, 0.0])
    assert_array_equal(arrays.transmissions[0], [1, 0])


def test_reward_is_cost_over_scale_plus_penalty_per_sent_channel():
    arrays = fresh_arrays(1)
    run_step(arrays, [1, 1])
    costs = np.abs(arrays.state[0, 0:2])
    assert_allclose(arrays.channel_costs[0], costs)
    assert arrays.reward[0] == pytest.approx(-costs.sum() / COST_SCALE - 2 * PENALTY)
    assert_allclose(arrays.channel_rewards[0], -costs / COST_SCALE - PENALTY)
    assert arrays.channel_rewards[0].sum() == pytest.approx(arrays.reward[0])
    assert arrays.cost_sum[0] == pytest.approx(costs.sum())


def test_observation_holds_features_and_time_since_each_transmission():
    arrays = fresh_arrays(1)
    run_step(arrays, [0, 0])
    run_step(arrays, [1, 0])
    run_step(arrays, [0, 0])
    assert_allclose(arrays.observation[0, 0:2], arrays.state[0, 0:2], rtol=1e-7)
    # channel 0 sent at t = 0.5 s, channel 1 never (time counts from the reset)
    assert_allclose(arrays.observation[0, 2:4], [3 * H - 0.5, 3 * H])
    assert arrays.observation.dtype == np.float32


def test_interevent_statistics_pool_the_gaps_between_consecutive_transmissions():
    arrays = fresh_arrays(1)
    pattern = [[1, 1], [0, 1], [1, 1], [0, 0], [0, 0], [1, 1]]
    sent_at: list[list[float]] = [[], []]
    for k, bits in enumerate(pattern):
        run_step(arrays, bits)
        for channel in range(2):
            if arrays.sent[0, channel]:
                sent_at[channel].append(k * H)
    gaps = [np.diff(times) for times in sent_at]
    mean_s, min_s = interevent_summary(
        arrays.transmissions[0], arrays.interevent_sum_s[0], arrays.interevent_min_s[0]
    )
    pooled = np.concatenate(gaps)
    assert mean_s == pytest.approx(pooled.mean())
    assert min_s == pytest.approx(pooled.min())
    assert_array_equal(arrays.transmissions[0], [len(t) for t in sent_at])


def test_interevent_summary_is_none_before_a_second_transmission():
    assert interevent_summary(np.array([1, 0]), np.zeros(2), np.full(2, np.inf)) == (None, None)


def test_a_refused_transmission_is_not_counted_or_charged():
    arrays = fresh_arrays(1, x0=(0.0, -1.0))  # channel 1 refuses while x_1 < 0
    run_step(arrays, [0, 1])
    assert_array_equal(arrays.sent[0], [0, 0])
    assert_array_equal(arrays.transmissions[0], [0, 0])
    assert arrays.reward[0] == pytest.approx(-arrays.channel_costs[0].sum() / COST_SCALE)


def test_failure_keeps_the_last_observation_and_charges_the_cut_horizon():
    arrays = fresh_arrays(1, x0=(4.4, 0.0))
    arrays.held[:] = 0.0  # x_0 grows by h * 1 = 0.5 per step: 4.9, 5.4
    run_step(arrays, [0, 0])
    assert arrays.failure_code[0] == 0
    kept = arrays.observation[0].copy()
    run_step(arrays, [0, 0])
    assert arrays.failure_code[0] == 1
    assert_array_equal(arrays.observation[0], kept)
    cost = arrays.channel_costs[0].sum()
    charge = FAILURE_COST * (N_STEPS - 2)
    assert arrays.reward[0] == pytest.approx(-(cost + charge) / COST_SCALE)
    assert arrays.channel_rewards[0].sum() == pytest.approx(arrays.reward[0])


def test_inactive_rows_are_left_untouched():
    arrays = fresh_arrays(3)
    run_step(arrays, [1, 1], active=[True, False, True])
    assert_array_equal(arrays.step_index, [1, 0, 1])
    assert_array_equal(arrays.state[1], [0.0, 0.0])
    assert_array_equal(arrays.transmissions[1], [0, 0])


def test_rows_of_a_batch_equal_single_rows():
    batch = fresh_arrays(4)
    singles = [fresh_arrays(1) for _ in range(4)]
    rng = np.random.default_rng(0)
    for _ in range(8):
        bits = rng.integers(0, 2, size=(4, 2))
        toy_step(bits, np.ones(4, bool), batch, CONSTANTS, H, N_STEPS, 2.0, 0.25, 3.0)
        for row, single in enumerate(singles):
            run_step(single, bits[row])
    for row, single in enumerate(singles):
        for name, array in zip(batch._fields, batch, strict=True):
            assert_array_equal(array[row], getattr(single, name)[0], err_msg=name)


def test_loop_rows_are_views_into_the_batch():
    batch = fresh_arrays(3)
    row = loop_rows(batch, 1, 2)
    row.state[0, 0] = 7.0
    assert batch.state[1, 0] == 7.0


class ToyEnv(EventTriggeredEnv):
    """The toy as a single environment (MultiBinary(2))."""

    kernels = TOY_KERNELS

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(
            feature_names=("x_0", "x_1"),
            feature_low=np.full(2, -np.inf),
            feature_high=np.full(2, np.inf),
            n_channels=2,
            channel_width=1,
            state_width=2,
            constants=CONSTANTS,
            sampling_period_s=H,
            horizon_s=kwargs.pop("horizon_s", N_STEPS * H),
            transmission_penalty=PENALTY,
            cost_scale=COST_SCALE,
            failure_cost=FAILURE_COST,
        )

    def _reset_problem(self, options: dict[str, Any] | None) -> None:
        self.state[0:2] = self.np_random.uniform(-0.1, 0.1, size=2)

    def _failure_message(self, code: int) -> str:
        return f"diverged: max |x| > {CONSTANTS[BOUND]}"

    def _paper_metrics(self) -> dict[str, Any]:
        return {"final_x": self.state[0:2].tolist()}

    def _settled_at_end(self, metrics: dict[str, Any]) -> bool:
        return max(abs(x) for x in metrics["final_x"]) < 0.5 * CONSTANTS[BOUND]


def test_env_reset_synchronises_the_channel_and_zeroes_the_clocks():
    env = ToyEnv()
    observation, info = env.reset(seed=1)
    assert_array_equal(env.held[:, 0], env.state[0:2])
    assert_allclose(observation[0:2], env.state[0:2], rtol=1e-7)
    assert_array_equal(observation[2:], [0.0, 0.0])
    assert info == {"transmitted": 0, "transmissions": 0, "time_s": 0.0, "cost": 0.0}


def test_env_episode_ends_with_metrics_and_refuses_further_steps():
    env = ToyEnv()
    env.reset(seed=0)
    sent = 0
    for _ in range(N_STEPS):
        _, _, terminated, truncated, info = env.step(np.array([1, 1]))
        sent += info["transmitted"]
        assert not terminated
    assert truncated
    metrics = info["episode_metrics"]
    assert set(COMMON_EPISODE_KEYS) <= set(metrics)
    assert metrics["transmissions"] == sent >= N_STEPS
    assert metrics["transmission_rate"] == pytest.approx(sent / (2 * N_STEPS))
    assert metrics["min_interevent_s"] == pytest.approx(H)
    assert metrics["final_x"] == env.state[0:2].tolist()
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.array([0, 0]))


def test_env_metrics_of_an_empty_episode():
    env = ToyEnv()
    env.reset(seed=0)
    metrics = env.episode_metrics()
    assert metrics["steps"] == 0 and metrics["sim_time_s"] == 0.0
    assert metrics["mean_cost"] == 0.0 and metrics["transmission_rate"] == 0.0
    assert metrics["mean_interevent_s"] is None and metrics["min_interevent_s"] is None
    assert metrics["failure"] is None


def test_env_failure_is_reported_by_its_message():
    env = ToyEnv()
    env.reset(seed=0)
    env.state[0] = 4.9
    _, _, terminated, truncated, info = env.step(np.array([0, 0]))
    assert terminated and not truncated
    assert info["failure"] == "diverged: max |x| > 5.0"
    assert info["episode_metrics"]["failure"] == info["failure"]


@pytest.mark.parametrize("action", [np.array([0, 2]), np.array([1]), "1"])
def test_env_bad_action_names_what_is_allowed(action):
    env = ToyEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="2 bits of 0/1"):
        env.step(action)


@pytest.mark.parametrize(
    ("kwargs", "message"), [({"horizon_s": 0.1}, "horizon_s must be a whole number")]
)
def test_env_bad_arguments_name_the_argument(kwargs, message):
    with pytest.raises(ValueError, match=message):
        ToyEnv(**kwargs)


def test_a_new_process_loads_the_loop_step_from_the_disk_cache(tmp_path):
    """The loop step closes over the problem's compiled kernels; its disk-cache entry must
    match in the next process (Numba's own key for closures never does, see
    ``ClosureFunctionCache``), or every process pays the 8–11-s compile again."""
    if os.environ.get("NUMBA_DISABLE_JIT") == "1":
        pytest.skip("nothing is compiled under NUMBA_DISABLE_JIT=1")
    script = (
        "import gymnasium as gym, etsc_envs\n"
        "env = gym.make('etsc/InnerFormation-v0')\n"
        "env.reset(seed=0)\n"
        "env.step(env.action_space.sample())\n"
        "print(sum(env.unwrapped.loop_step.stats.cache_hits.values()))\n"
    )
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    hits = [
        subprocess.run(
            [sys.executable, "-c", script],
            env=environment,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()[-1]
        for _ in range(2)
    ]
    assert hits == ["0", "1"], "compiled in the first process, loaded in the second"


def test_editing_a_callee_module_invalidates_its_callers_cache(tmp_path):
    """Numba invalidates a cached function only when its own file changes; a caller in another
    file carries the callee's code, so without the package stamp of ``core.jit`` it would keep
    computing with the callee's old body after an edit (plain ``njit(cache=True)`` prints 2.0
    in the third process below)."""
    if os.environ.get("NUMBA_DISABLE_JIT") == "1":
        pytest.skip("nothing is compiled under NUMBA_DISABLE_JIT=1")
    package = tmp_path / "packages" / "stampcheck"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    callee = package / "callee.py"
    callee.write_text("from etsc_envs.core.jit import jit\n\n@jit\ndef value():\n    return 1.0\n")
    (package / "caller.py").write_text(
        "from etsc_envs.core.jit import jit\nfrom stampcheck.callee import value\n\n"
        "@jit\ndef total():\n    return value() + 1.0\n"
    )
    script = (
        "from stampcheck.caller import total\n"
        "print(total(), sum(total.stats.cache_hits.values()))\n"
    )
    environment = {
        **os.environ,
        "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
        "PYTHONPATH": os.pathsep.join([str(package.parent), os.environ.get("PYTHONPATH", "")]),
    }

    def run() -> list[str]:
        return subprocess.run(
            [sys.executable, "-c", script],
            env=environment,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()

    assert run() == ["2.0", "0"]  # compiled
    assert run() == ["2.0", "1"]  # loaded from the disk cache
    callee.write_text(callee.read_text().replace("return 1.0", "return 5.25"))
    assert run() == ["6.25", "0"]  # the edit of the callee recompiles the caller
    assert run() == ["6.25", "1"]

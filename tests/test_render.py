"""The frames of ``render_mode="rgb_array"`` and ``"human"``.

Checked properties:

* the transmission strip marks every transmission of the episode, in its channel's row (the
  marks' pixels counted against ``info["transmissions"]``), for every Gymnasium id and the
  PettingZoo env;
* the system picture (left half of the frame) is drawn and follows the state;
* a transmission is drawn at the start of its step;
* ``"human"`` shows the frames in a Matplotlib window (the one ``"rgb_array"`` returns), and
  without a display warns once in one line while the episode runs on; a vector env refuses
  ``"human"`` naming the modes it allows;
* the projections the pictures use are rotations, and the asteroid's spacecraft is drawn in the
  inertial frame at the distance it has from the asteroid's centre, with the radius's extremes
  of the episode.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import warnings

import gymnasium as gym
import numpy as np
import pettingzoo
import pytest

import etsc_envs
from etsc_envs.asteroid.picture import orbit_view
from etsc_envs.asteroid.picture import snapshot as asteroid_snapshot
from etsc_envs.cluster.picture import hull_view
from etsc_envs.core.render import FRAME_SIZE_PX, TRANSMISSION_COLOR, EpisodeTrace, view_matrix

CLUSTER_ID = "etsc/ClusterContainment-v0"
SHORT = {
    "etsc/AttitudeTracking-v0": {"horizon_s": 0.4},
    "etsc/OrbitAttitudeTracking-v0": {"horizon_s": 0.4},
    "etsc/ClusterContainmentCentral-v0": {"horizon_s": 4.0},
    "etsc/InnerFormation-v0": {"horizon_s": 0.4},
    "etsc/AsteroidOrbitKeeping-v0": {"horizon_s": 400.0},  # bursts of 50 s
}
SPACING = {"etsc/AsteroidOrbitKeeping-v0": 240}  # 60 s: each burst ends before the next
"""Steps between two transmissions (20 by default), so that marks stand pixels apart."""


def marks(frame: np.ndarray) -> list[float]:
    """The mean pixel row of each transmission mark, left to right (a mark: a run of adjacent
    pixel columns holding the transmission colour)."""
    color = np.array([int(TRANSMISSION_COLOR[i : i + 2], 16) for i in (1, 3, 5)])
    marked = np.all(np.abs(frame.astype(int) - color) <= 3, axis=2)
    columns = np.flatnonzero(marked.any(axis=0))
    if columns.size == 0:
        return []
    runs = np.split(columns, np.flatnonzero(np.diff(columns) > 1) + 1)
    return [float(np.flatnonzero(marked[:, run].any(axis=1)).mean()) for run in runs]


def schedule(n_steps: int, n_channels: int, spacing: int) -> list[np.ndarray]:
    """Transmit bits per step: every ``spacing`` steps one channel, channels in turn (so every
    mark is one transmission of one channel), from step 1 (a mark at 0 would touch the axis)."""
    bits = []
    for k in range(n_steps):
        step_bits = np.zeros(n_channels, dtype=np.int64)
        if k % spacing == 1:
            step_bits[(k // spacing) % n_channels] = 1
        bits.append(step_bits)
    return bits


def channel_sequence(bits: list[np.ndarray]) -> list[int]:
    """The channels that transmitted, in order."""
    return [int(np.flatnonzero(b)[0]) for b in bits if b.any()]


def assert_strip_holds(frame: np.ndarray, transmissions: int, channels: list[int]) -> None:
    """One mark per transmission, each in its channel's row (channel 0 on top)."""
    rows = marks(frame)
    assert transmissions > 0
    assert len(rows) == transmissions == len(channels)
    row_of = {}
    for channel, row in zip(channels, rows, strict=True):
        row_of.setdefault(channel, []).append(row)
    centres = [np.mean(row_of[c]) for c in sorted(row_of)]
    assert all(np.ptp(row_of[c]) < 2 for c in row_of)  # one row per channel
    assert centres == sorted(centres)  # channel 0 on top


@pytest.mark.parametrize("env_id", sorted(etsc_envs.ENV_IDS))
def test_the_strip_marks_every_transmission_beside_the_system(env_id):
    env = gym.make(env_id, render_mode="rgb_array", **SHORT[env_id]).unwrapped
    env.reset(seed=0)
    first = env.render()
    assert first.shape == (FRAME_SIZE_PX[1], FRAME_SIZE_PX[0], 3) and first.dtype == np.uint8
    assert marks(first) == []
    bits = schedule(env.n_steps, env.n_channels, SPACING.get(env_id, 20))
    sent = []
    for step_bits in bits:
        action = int(step_bits[0]) if env.n_channels == 1 else step_bits
        *_, info = env.step(action)
        sent.append(step_bits if info["transmitted"] else 0 * step_bits)
    last = env.render()
    assert_strip_holds(last, info["transmissions"], channel_sequence(sent))
    system = slice(0, FRAME_SIZE_PX[0] // 2)
    assert (last[:, system] < 200).mean() > 0.01  # the system is drawn
    assert not np.array_equal(first[:, system], last[:, system])  # and it moved


def test_the_pettingzoo_env_draws_every_agents_transmissions():
    env = pettingzoo.make("parallel", CLUSTER_ID, render_mode="rgb_array", horizon_s=4.0)
    env.reset(seed=0)
    n = len(env.possible_agents)
    bits = schedule(env.unwrapped.n_steps, n, 20)
    for step_bits in bits:
        *_, infos = env.step(dict(zip(env.agents, step_bits.tolist(), strict=True)))
    transmissions = sum(info["transmissions"] for info in infos.values())
    assert_strip_holds(env.render(), transmissions, channel_sequence(bits))


def test_a_transmission_is_drawn_at_the_start_of_its_step():
    trace = EpisodeTrace(n_channels=2, period_s=0.5)
    trace.record(0, 1.0, np.array([1, 0]))
    trace.record(3, 2.0, np.array([0, 1]))
    assert trace.transmit_times_s == [[0.0], [1.5]]
    assert trace.times_s == [0.5, 2.0]


def test_human_mode_without_a_display_warns_once_and_runs():
    env = gym.make("etsc/InnerFormation-v0", render_mode="human", horizon_s=0.05)
    with pytest.warns(UserWarning, match=r"render_mode='human' needs an interactive"):
        env.reset(seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for _ in range(20):
            env.step(env.action_space.sample())
        assert env.render() is None
    env.close()
    with pytest.raises(ValueError, match=r"render_mode must be one of \(None, 'rgb_array'\)"):
        gym.make_vec(
            "etsc/InnerFormation-v0",
            num_envs=2,
            vectorization_mode="vector_entry_point",
            render_mode="human",
        )


WINDOW_SCRIPT = textwrap.dedent(
    """
    import warnings
    warnings.simplefilter("error")
    import gymnasium as gym, numpy as np, matplotlib.pyplot as plt
    import etsc_envs
    human, twin = (gym.make("etsc/InnerFormation-v0", render_mode=mode, horizon_s=0.05)
                   for mode in ("human", "rgb_array"))
    human.reset(seed=0), twin.reset(seed=0)
    assert len(plt.get_fignums()) == 1
    for k in range(30):
        bits = np.array([k % 2, k % 3 == 0, 0])
        human.step(bits), twin.step(bits)
    assert human.render() is None
    shown = np.asarray(plt.figure(plt.get_fignums()[0]).axes[0].images[0].get_array())
    frame = twin.render()
    # the strips match exactly; the system's trail holds the frames the window drew, which
    # depend on the wall clock
    assert shown.shape == frame.shape and np.array_equal(shown[:, 480:], frame[:, 480:])
    human.close()
    assert plt.get_fignums() == []
    """
)


def test_human_mode_shows_the_rgb_frames_in_a_window():
    # A backend with windows that needs no display (Matplotlib's template backend, named as a
    # module so that it counts as interactive).
    backend = {"MPLBACKEND": "module://matplotlib.backends.backend_template"}
    subprocess.run([sys.executable, "-c", WINDOW_SCRIPT], env={**os.environ, **backend},
                   check=True, timeout=300)  # fmt: skip


def test_the_views_are_rotations():
    leaders = np.array([[0.09, 0.06, -0.08], [0.06, -0.1, 0.05], [-0.08, 0.1, 0.09]])
    for view in (view_matrix(35.0, 20.0), orbit_view(130.0), hull_view(leaders)):
        np.testing.assert_allclose(view @ view.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(view) == pytest.approx(1.0)
    assert orbit_view(130.0)[1] @ np.array([0.0, 0.0, 1.0]) == 1.0  # the spin axis is up


def test_the_spacecraft_is_drawn_where_it_is():
    env = gym.make("etsc/AsteroidOrbitKeeping-v0", horizon_s=400.0).unwrapped
    env.reset(seed=0)
    for _ in range(800):
        env.step(0)
    time_s, *position, firing, lowest, highest = asteroid_snapshot(env)
    state = env.state_dict()
    metrics = env.episode_metrics()
    assert time_s == env.time_s and firing == 0.0
    assert np.linalg.norm(position) == pytest.approx(float(state["radius_m"]), rel=1e-12)
    assert (lowest, highest) == (metrics["min_radius_m"], metrics["max_radius_m"])
    assert lowest <= float(state["radius_m"]) <= highest
    spin = env.model.spin_rate * time_s  # I from A: turned back by ω_T t about z
    assert position[2] == pytest.approx(float(state["position_m"][2]))
    azimuth_a = np.arctan2(state["position_m"][1], state["position_m"][0])
    assert np.arctan2(position[1], position[0]) == pytest.approx(
        np.angle(np.exp(1j * (azimuth_a + spin)))
    )

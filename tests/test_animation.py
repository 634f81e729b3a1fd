"""GIFs from the environments' own frames (etsc_envs.animation).

Checked: frames are taken at the warped instants, the compiled path for a paper rule draws the
same frames as stepping the rule's decisions one by one, and the GIF holds every frame at the
requested width, looping, the last frame held.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from PIL import Image

from etsc_envs.animation import FINAL_HOLD_S, frame_steps, gym_frames, write_gif
from etsc_envs.papers import paper_of

ENV_ID = "etsc/AttitudeTracking-v0"


def test_frame_instants_are_warped_and_distinct():
    np.testing.assert_array_equal(frame_steps(100, 4, 1.0), [0, 25, 50, 75, 100])
    np.testing.assert_array_equal(frame_steps(100, 4, 2.0), [0, 6, 25, 56, 100])
    assert frame_steps(3, 10).tolist() == [0, 1, 2, 3]
    with pytest.raises(ValueError, match="frames must be an integer >= 1"):
        frame_steps(100, 0)
    with pytest.raises(ValueError, match="warp must be a finite number > 0"):
        frame_steps(100, 4, 0.0)


class Stepwise:
    """The rule's decisions through ``predict`` only (no compiled interval)."""

    def __init__(self, rule):
        self.rule = rule

    def predict(self, observation, deterministic=True):
        return self.rule.predict(observation, deterministic=deterministic)


def test_the_compiled_rule_draws_the_frames_of_its_steps(tmp_path):
    def frames(policy_of):
        env = gym.make(ENV_ID, render_mode="rgb_array", horizon_s=0.3).unwrapped
        rule = paper_of(ENV_ID).trigger(
            env.observation_space, env.action_space, observation_names=env.observation_names
        )
        return gym_frames(env, policy_of(rule), frames=3), env

    compiled, env = frames(lambda rule: rule)
    stepped, _ = frames(Stepwise)
    assert len(compiled) == 4 and env.transmissions.sum() > 1
    for a, b in zip(compiled, stepped, strict=True):
        np.testing.assert_array_equal(a, b)

    path = write_gif(compiled, tmp_path / "out.gif", fps=5, width=480)
    image = Image.open(path)
    assert image.n_frames == 4 and image.size == (480, 240)
    assert image.info["loop"] == 0 and image.info["duration"] == 200
    image.seek(3)
    assert image.info["duration"] == round(1000 * FINAL_HOLD_S)
    with pytest.raises(ValueError, match="render_mode='rgb_array'"):
        gym_frames(gym.make(ENV_ID, horizon_s=0.3).unwrapped, Stepwise(None))

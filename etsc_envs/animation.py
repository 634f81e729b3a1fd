"""Animated GIFs made from an environment's own ``render_mode="rgb_array"`` frames.

``python -m etsc_envs.animation`` writes one GIF per environment id, the paper's scenario run by
the paper's trigger, into ``docs/envs/<name>.gif`` (``--out`` another folder, ``--ids`` some
ids, ``--frames`` another count)::

    python -m etsc_envs.animation --ids etsc/AttitudeTracking-v0 --frames 40 --out /tmp/gifs

:func:`gym_frames` and :func:`write_gif` make the same from any policy that answers like a
Stable-Baselines3 model (a trained trigger, say)::

    env = gym.make("etsc/AttitudeTracking-v0", render_mode="rgb_array")
    write_gif(gym_frames(env.unwrapped, model, frames=60), "mine.gif")

Frames are taken at instants ``t_j = T (j/F)^warp`` (``j = 0 .. F``, ``T`` the horizon): with
the default warp of 2 the transient, where the papers' loops change fastest, gets more frames
than the settled end. Each frame's title gives its time.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, cast

import gymnasium as gym
import numpy as np
from PIL import Image

import etsc_envs
from etsc_envs.core.render import RENDER_FPS
from etsc_envs.papers import paper_of
from etsc_envs.triggers.base import RuleTrigger

GIF_DIR = Path("docs/envs")
"""Where the command writes, relative to the working directory (the checkout's root)."""
FRAMES = 100
"""Frames after the first of a GIF the command writes."""
WARP = 2.0
GIF_WIDTH_PX = 720
"""Width a GIF's frames are scaled to (the height keeps the frame's proportions)."""
COLORS = 256
"""Palette size of a GIF, one palette for all its frames."""
PALETTE_SAMPLES = 8
"""Frames, evenly spread and the last, whose colours make the palette."""
FINAL_HOLD_S = 2.0
"""How long the last frame stays before the GIF loops."""
SCENARIOS: dict[str, dict[str, Any]] = {"etsc/ClusterContainment-v0": {"scenario": "pi1"}}
"""Keywords of the command's episode per id, where not the default paper scenario (the
PettingZoo env shows section 5.2's nine followers; the central env section 5.1's six)."""
WARPS = {"etsc/AsteroidOrbitKeeping-v0": 1.0}
"""The command's warp per id, where not :data:`WARP`: paper 003's orbit keeps one pace."""


def gif_name(env_id: str) -> str:
    """The GIF's file name of ``env_id`` (``etsc/AttitudeTracking-v0``:
    ``AttitudeTracking-v0.gif``)."""
    return env_id.split("/", 1)[1] + ".gif"


def frame_steps(n_steps: int, frames: int, warp: float = WARP) -> np.ndarray:
    """The distinct step indices ``round(n_steps (j/frames)^warp)``, ``j = 0 .. frames``."""
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
        raise ValueError(f"frames must be an integer >= 1, got {frames!r}")
    if not np.isfinite(warp) or warp <= 0.0:
        raise ValueError(f"warp must be a finite number > 0, got {warp!r}")
    fractions = np.linspace(0.0, 1.0, frames + 1) ** warp
    return np.unique(np.round(fractions * n_steps).astype(int))


def gym_frames(env: Any, policy: Any, frames: int = FRAMES, warp: float = WARP) -> list[np.ndarray]:
    """Frames of one episode of ``env`` (an :class:`~etsc_envs.core.loop_env.EventTriggeredEnv`
    made with ``render_mode="rgb_array"``, reset here with seed 0) under ``policy.predict``, at
    :func:`frame_steps`; the episode stops early at a failure. A paper rule runs inside the
    compiled loop (:meth:`~etsc_envs.core.loop_env.EventTriggeredEnv.run_rule_interval`), with
    the same decisions as stepping it."""
    if getattr(env, "render_mode", None) != "rgb_array":
        raise ValueError("env must be made with render_mode='rgb_array'")
    observation, _ = env.reset(seed=0)
    rule = hasattr(policy, "rule") and getattr(policy, "n_channels", None) == env.n_channels
    shots = [env.render()]
    ended = False
    for target in frame_steps(env.n_steps, frames, warp)[1:]:
        while env.step_index < target and not ended:
            if rule:
                observation, _, terminated, truncated, _, _ = env.run_rule_interval(
                    policy, int(target - env.step_index)
                )
            else:
                action, _ = policy.predict(observation, deterministic=True)
                observation, _, terminated, truncated, _ = env.step(action)
            ended = terminated or truncated
        shots.append(env.render())
        if ended:
            break
    return shots


def parallel_frames(
    env: Any, policy: Any, frames: int = FRAMES, warp: float = WARP
) -> list[np.ndarray]:
    """Frames of one episode of a PettingZoo env of the suite (``render_mode="rgb_array"``,
    reset with seed 0) in which every agent acts by ``policy.predict`` on its own observation
    (all agents in one batch), at :func:`frame_steps`."""
    observations, _ = env.reset(seed=0)
    shots = [env.render()]
    for target in frame_steps(env.n_steps, frames, warp)[1:]:
        while env.agents and round(env.time_s / env.loop.sampling_period_s) < target:
            agents = list(env.agents)
            actions, _ = policy.predict(np.stack([observations[a] for a in agents]))
            observations, *_ = env.step(dict(zip(agents, actions.tolist(), strict=True)))
        shots.append(env.render())
        if not env.agents:
            break
    return shots


def write_gif(
    frames: Sequence[np.ndarray],
    path: str | Path,
    fps: float = RENDER_FPS,
    width: int = GIF_WIDTH_PX,
) -> Path:
    """``frames`` (RGB arrays) as a looping GIF at ``fps``, scaled to ``width`` pixels, the
    last frame held :data:`FINAL_HOLD_S`; returns the path written."""
    if not frames:
        raise ValueError("frames must hold at least one frame")
    height = round(frames[0].shape[0] * width / frames[0].shape[1])
    scaled = [
        Image.fromarray(frame).resize((width, height), Image.Resampling.LANCZOS) for frame in frames
    ]
    samples = scaled[:: max(1, len(scaled) // PALETTE_SAMPLES)] + scaled[-1:]
    sheet = Image.new("RGB", (width, height * len(samples)))
    for row, image in enumerate(samples):
        sheet.paste(image, (0, row * height))
    palette = sheet.quantize(COLORS, method=Image.Quantize.MAXCOVERAGE)
    images = [image.quantize(palette=palette, dither=Image.Dither.NONE) for image in scaled]
    period_ms = round(1000.0 / fps)
    durations = [period_ms] * (len(images) - 1) + [round(1000.0 * FINAL_HOLD_S)]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    images[0].save(
        path, save_all=True, append_images=images[1:], duration=durations, loop=0, optimize=True
    )
    return path


def paper_gif(env_id: str, out_dir: str | Path, frames: int = FRAMES) -> Path:
    """The GIF of ``env_id`` under the paper's trigger (the scenario of :data:`SCENARIOS`, else
    the paper's), written to ``out_dir``/:func:`gif_name`."""
    kwargs = {"render_mode": "rgb_array", **SCENARIOS.get(env_id, {})}
    # Built with the paper trigger's own constructor arguments (spaces, observation names),
    # which RuleTrigger's signature does not describe.
    trigger_class = cast(Callable[..., RuleTrigger], paper_of(env_id).trigger)
    env: Any  # the suite's env class, which make_parallel and gym.make type as their bases
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        env = etsc_envs.make_parallel(env_id, **kwargs)
        agent = env.possible_agents[0]
        trigger = trigger_class(
            env.observation_space(agent),
            env.action_space(agent),
            observation_names=env.agent_observation_names,
        )
        shots = parallel_frames(env, trigger, frames, WARPS.get(env_id, WARP))
    else:
        env = gym.make(env_id, **kwargs).unwrapped
        trigger = trigger_class(
            env.observation_space, env.action_space, observation_names=env.observation_names
        )
        shots = gym_frames(env, trigger, frames, WARPS.get(env_id, WARP))
    env.close()
    return write_gif(shots, Path(out_dir) / gif_name(env_id))


def main(argv: Sequence[str] | None = None) -> None:
    ids = sorted({*etsc_envs.ENV_IDS, *etsc_envs.PETTINGZOO_ENV_IDS})
    parser = argparse.ArgumentParser(
        prog="python -m etsc_envs.animation",
        description="One GIF per environment: the paper's scenario under the paper's trigger, "
        "from the env's own frames.",
    )
    parser.add_argument("--ids", nargs="+", choices=ids, default=ids, metavar="ID")
    parser.add_argument("--out", type=Path, default=GIF_DIR, help=f"folder (default {GIF_DIR})")
    parser.add_argument("--frames", type=int, default=FRAMES, help=f"default {FRAMES}")
    args = parser.parse_args(argv)
    for env_id in args.ids:
        path = paper_gif(env_id, args.out, args.frames)
        print(f"{env_id}: {path} ({path.stat().st_size / 1e6:.2f} MB)", flush=True)


if __name__ == "__main__":
    main()

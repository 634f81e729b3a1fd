"""Run trained triggers on a prefix of their id's paper scenario, as a project that installed
only the package would: ``python -I policy_prefix.py STEPS MODEL...`` prints one JSON object,
the prefix's record of each model (:func:`run_prefix`) and the top-level modules it imported.

``tests/test_installed_models.py`` runs it outside the checkout (and the same
:func:`run_prefix` on the checkout's ``baselines.evaluate`` policy, to compare).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import etsc_envs


def env_id_of(model: str | Path) -> str:
    """``models/<name>-v0_<method>.zip`` (or ``.json``): the id ``etsc/<name>-v0``."""
    return "etsc/" + Path(model).name.partition("_")[0]


def paper_env(env_id: str) -> Any:
    """The paper scenario of ``env_id``: its default keywords (a PettingZoo parallel env for a
    PettingZoo id)."""
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        return etsc_envs.make_parallel(env_id)
    return gym.make(env_id)


def run_prefix(policy: Any, env: Any, steps: int) -> dict[str, int]:
    """The first ``steps`` sampling instants of ``env``'s paper scenario (seed 0) under
    ``policy`` (fewer if the episode ends): ``steps`` run and ``transmissions`` (the env's
    count, summed over a PettingZoo env's agents) at the end."""
    pettingzoo = callable(env.observation_space)
    observations, _ = env.reset(seed=0)
    names = env.possible_agents if pettingzoo else [None]
    state, episode_start = None, np.ones(len(names), dtype=bool)
    transmissions, run = 0, 0
    for _ in range(steps):
        run += 1
        batch = np.stack([observations[name] for name in names]) if pettingzoo else observations
        actions, state = policy.predict(batch, state=state, episode_start=episode_start)
        episode_start = np.zeros(len(names), dtype=bool)
        if pettingzoo:
            chosen = {name: actions[index] for index, name in enumerate(names)}
            observations, _, terminated, truncated, infos = env.step(chosen)
            transmissions = sum(int(infos[name]["transmissions"]) for name in names)
            if any(terminated.values()) or any(truncated.values()):
                break
        else:
            observations, _, terminated, truncated, info = env.step(actions)
            transmissions = int(info["transmissions"])
            if terminated or truncated:
                break
    return {"steps": run, "transmissions": transmissions}


def main(steps: int, models: list[str]) -> dict[str, Any]:
    """Each model of ``models`` loaded with :func:`etsc_envs.load_policy` and run on
    ``steps`` instants of its id's paper scenario."""
    records = {}
    for model in models:
        env = paper_env(env_id_of(model))
        records[Path(model).name] = run_prefix(etsc_envs.load_policy(model, env), env, steps)
        env.close()
    return {
        "records": records,
        "etsc_envs": etsc_envs.__file__,
        "modules": sorted({name.partition(".")[0] for name in sys.modules}),
    }


if __name__ == "__main__":
    sys.stdout.write(json.dumps(main(int(sys.argv[1]), sys.argv[2:])) + "\n")

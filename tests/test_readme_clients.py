"""The client examples of the README and ``docs/clients.md`` run word for word.

Checked properties: each Python block of those pages that uses PettingZoo's registry or Ray
RLlib runs as written: the cluster from ``pettingzoo.make`` (both forms), RLlib multi-agent
PPO with one shared policy over ``ParallelPettingZooEnv`` and RLlib PPO on a Gymnasium id,
each RLlib one training iteration that samples the configured batch.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PYTHON_BLOCK = re.compile(r"```python\n(.*?)```", re.DOTALL)


PAGES = ("README.md", "docs/clients.md")
"""The pages whose client examples are run."""


def readme_blocks(marker: str) -> list[str]:
    """The Python blocks of :data:`PAGES` that contain ``marker``."""
    blocks = [
        block
        for page in PAGES
        for block in PYTHON_BLOCK.findall((ROOT / page).read_text(encoding="utf-8"))
    ]
    return [block for block in blocks if marker in block]


def test_the_pettingzoo_example_builds_both_forms_from_the_registry():
    (block,) = readme_blocks("central = gym.make")
    namespace: dict = {}
    exec(compile(block, "README.md", "exec"), namespace)
    assert len(namespace["parallel"].possible_agents) == 9  # scenario pi1
    aec = namespace["aec"]
    aec.reset(seed=0)
    assert aec.agent_selection == "follower_0"
    assert namespace["central"].action_space.n == 6


@pytest.fixture
def ray_session():
    pytest.importorskip(
        "ray.rllib",
        reason="Ray RLlib: the clients extra is not installed (pip install -e '.[clients]')",
    )
    import ray

    yield
    ray.shutdown()


def test_the_rllib_examples_train_one_iteration_each(ray_session, capsys):
    blocks = readme_blocks("from ray.rllib")
    assert len(blocks) == 2  # the cluster under a shared policy, and a Gymnasium id
    sampled = []
    for block in blocks:
        namespace: dict = {}
        exec(compile(block, "README.md", "exec"), namespace)
        sampled.append(float(capsys.readouterr().out.split()[-1]))
        assert namespace["config"].is_multi_agent == ("ParallelPettingZooEnv" in block)
    batches = [
        int(re.search(r"train_batch_size_per_learner=(\d+)", block).group(1)) for block in blocks
    ]
    assert all(count >= batch for count, batch in zip(sampled, batches, strict=True))

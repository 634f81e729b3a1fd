"""The environment pages ``docs/envs/<name>.md``: one per id, with its GIF, and the generated
blocks (summary, observation table, keywords) what the environments say now."""

from __future__ import annotations

from pathlib import Path

import pytest

from etsc_envs.animation import gif_name
from etsc_envs.pages import BLOCK, fill, page_ids, page_name

PAGE_DIR = Path(__file__).resolve().parent.parent / "docs" / "envs"


@pytest.mark.parametrize("env_id", page_ids())
def test_each_page_shows_its_gif_and_its_blocks_are_current(env_id):
    text = (PAGE_DIR / page_name(env_id)).read_text(encoding="utf-8")
    assert f"]({gif_name(env_id)})" in text
    assert {match.group(2) for match in BLOCK.finditer(text)} == {
        "summary", "observation", "keywords", "leaderboard",
    }  # fmt: skip
    assert fill(text, env_id) == text, "run python -m etsc_envs.pages"


def test_a_changed_table_is_rewritten():
    env_id = "etsc/InnerFormation-v0"
    text = (PAGE_DIR / page_name(env_id)).read_text(encoding="utf-8")
    stale = text.replace("`position_m_x`", "`position_x`")
    assert stale != text and fill(stale, env_id) == text

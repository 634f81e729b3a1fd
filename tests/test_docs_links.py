"""Every relative link and image in README.md and docs/**/*.md resolves to a file or folder of
the checkout (anchors and queries are not checked; links to other sites are not followed).

Read are Markdown inline links and images ``[text](target)`` / ``![alt](target)`` (a target in
angle brackets may hold spaces), reference definitions ``[name]: target`` and HTML ``src=`` /
``href=`` attributes, outside fenced code blocks and code spans.
"""

from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import unquote

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = sorted([ROOT / "README.md", *(ROOT / "docs").rglob("*.md")])

INLINE = re.compile(
    r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*(?:<([^>]+)>|([^)\s]+))(?:\s+\"[^\"]*\")?\s*\)"
)
DEFINITION = re.compile(r"^ {0,3}\[[^\]]+\]:\s*<?([^\s>]+)>?", re.MULTILINE)
HTML = re.compile(r"""(?:src|href)\s*=\s*["']([^"']+)["']""")
FENCE = re.compile(r"^ {0,3}(```|~~~).*?^ {0,3}\1[^\n]*$", re.MULTILINE | re.DOTALL)
CODE_SPAN = re.compile(r"(`+).+?\1", re.DOTALL)
EXTERNAL = re.compile(r"[a-zA-Z][\w+.-]*:|#")
"""A target with a scheme (``https:``, ``mailto:``) or an anchor of the page itself."""


def targets(text: str) -> list[str]:
    """The relative link and image targets of a Markdown text, outside code, in order."""
    prose = CODE_SPAN.sub("", FENCE.sub("", text))
    found = [angled or plain for angled, plain in INLINE.findall(prose)]
    found += DEFINITION.findall(prose) + HTML.findall(prose)
    return [target for target in found if not EXTERNAL.match(target)]


def test_the_reader_finds_links_and_skips_code_and_other_sites():
    text = (
        'See [a](docs/a.md#part), ![b](img/b.gif "title") and [c](<with space.md>).\n'
        "[web](https://x.org) [top](#top) `[no](f.md)` [nested [x]](n.md)\n"
        "```python\n[no](g.md)\n```\n"
        '[d]: ../d.md\n<img src="e.png">\n'
    )
    assert targets(text) == [
        "docs/a.md#part", "img/b.gif", "with space.md", "n.md", "../d.md", "e.png",
    ]  # fmt: skip


@pytest.mark.parametrize("page", PAGES, ids=lambda page: str(page.relative_to(ROOT)))
def test_every_relative_link_resolves(page):
    missing = []
    for target in targets(page.read_text(encoding="utf-8")):
        path = unquote(target.split("#", 1)[0].split("?", 1)[0])
        if path and not (page.parent / path).exists():
            missing.append(target)
    assert not missing, f"{page.relative_to(ROOT)} links to missing {missing}"

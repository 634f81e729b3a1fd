"""Every code block of the README runs as written.

Checked properties: each ``python`` block of ``README.md`` runs in a folder outside the checkout
(a temporary one, no ``PYTHONPATH``) from the installed package alone, so a block that needs the
checkout's tools (``agents``, ``baselines``) fails; each ``bash`` block runs in the checkout,
where the README says to run it, with ``python`` this interpreter. The blocks run in the
README's order in one shared temporary folder (a model one block saves, the next judges).

An HTML comment just above a block adjusts it, visibly in the README's source:
``<!-- snippet: skip (reason) -->`` leaves it out (the setup, main-job and test commands), and
``<!-- snippet: replace "OLD" "NEW" -->`` shortens a long one (a training budget, a scenario
set); ``{tmp}`` in ``NEW`` is the shared folder. A replacement whose ``OLD`` is not in its block
fails the test, so a directive cannot outlive the text it edits.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DIRECTIVE = re.compile(r"<!-- snippet: (.*?) -->")
REPLACE = re.compile(r'replace "(.*?)" "(.*?)"')
TIMEOUT_S = 600


@dataclass
class Snippet:
    """One fenced block of the README with the directives above it."""

    language: str
    code: str
    line: int
    skip: str | None = None
    replacements: list[tuple[str, str]] = field(default_factory=list)

    def prepared(self, tmp: Path) -> str:
        """The code with its replacements made (``{tmp}`` → the shared folder)."""
        code = self.code
        for old, new in self.replacements:
            if old not in code:
                raise AssertionError(f"README line {self.line}: replace {old!r}: not in the block")
            code = code.replace(old, new.replace("{tmp}", str(tmp)))
        return code


def snippets(text: str) -> list[Snippet]:
    """The README's ``python`` and ``bash`` blocks, each with the directives just above it."""
    found, pending, lines = [], [], text.splitlines()
    index = 0
    while index < len(lines):
        line = lines[index]
        directive = DIRECTIVE.fullmatch(line.strip())
        if directive:
            pending.append(directive.group(1))
        elif line.startswith("```") and line[3:].strip():
            language, start = line[3:].strip(), index + 1
            end = lines.index("```", start)
            if language in {"python", "bash"}:
                snippet = Snippet(language, "\n".join(lines[start:end]) + "\n", start)
                for text_ in pending:
                    if text_.startswith("skip"):
                        snippet.skip = text_
                    elif match := REPLACE.fullmatch(text_):
                        snippet.replacements.append((match.group(1), match.group(2)))
                    else:
                        raise AssertionError(f"README line {index}: unknown directive {text_!r}")
                found.append(snippet)
            pending, index = [], end
        elif line.strip():
            pending = []
        index += 1
    return found


SNIPPETS = snippets(README.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("readme")
    assert ROOT not in folder.parents
    return folder


def _environment() -> dict[str, str]:
    """This process's environment without a path into the checkout, with ``python`` first on
    the ``PATH`` being this interpreter."""
    environment = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    environment["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{environment['PATH']}"
    environment["MPLBACKEND"] = "Agg"
    return environment


def test_the_readme_has_runnable_blocks_and_skips_only_the_first() -> None:
    languages = {snippet.language for snippet in SNIPPETS}
    assert languages == {"python", "bash"}
    skipped = [snippet for snippet in SNIPPETS if snippet.skip]
    assert skipped == [SNIPPETS[0]], "only the setup, main-job and test commands are skipped"
    assert "python -m pytest" in SNIPPETS[0].code and "baselines.reproduce" in SNIPPETS[0].code


def test_a_replacement_that_no_longer_matches_fails() -> None:
    (snippet,) = snippets('<!-- snippet: replace "50_000" "2_048" -->\n```python\nx = 1\n```\n')
    with pytest.raises(AssertionError, match="not in the block"):
        snippet.prepared(Path("/tmp"))


@pytest.mark.parametrize("snippet", SNIPPETS, ids=[f"{s.language}-line{s.line}" for s in SNIPPETS])
def test_the_block_runs_as_written(snippet: Snippet, workdir: Path) -> None:
    if snippet.skip:
        pytest.skip(snippet.skip)
    code = snippet.prepared(workdir)
    if snippet.language == "python":
        script = workdir / f"readme_line{snippet.line}.py"
        script.write_text(code, encoding="utf-8")
        command, cwd = [sys.executable, str(script)], workdir
    else:
        command, cwd = ["bash", "-euo", "pipefail", "-c", code], ROOT
    result = subprocess.run(
        command,
        cwd=cwd,
        env=_environment(),
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert result.returncode == 0, (
        f"README line {snippet.line} ({snippet.language}, run in {cwd}) failed:\n"
        f"{result.stderr[-3000:]}"
    )

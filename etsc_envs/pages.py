"""The generated parts of the environment pages ``docs/envs/<name>.md``.

A page is written by hand except for blocks between ``<!-- generated:KIND -->`` and
``<!-- /generated -->``, which this module writes from the environment itself, so they stay
true: ``summary`` (spaces, period, horizon, how to make it), ``observation`` (every component
with its bounds and the meaning its problem documents in ``FEATURE_NAMES``) and ``keywords``
(every constructor keyword with its default and its documentation) and ``leaderboard`` (the
id's test-set rows of ``docs/leaderboard.md``, from the package data, with what its cost is)::

    python -m etsc_envs.pages            # rewrite the blocks of every page
    python -m etsc_envs.pages --check    # exit 1 if a page's blocks are not what they would be

``tests/test_docs_pages.py`` runs the check.
"""

from __future__ import annotations

import argparse
import ast
import fnmatch
import inspect
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym

import etsc_envs
from etsc_envs.core.keywords import field_docs
from etsc_envs.core.loop_env import UNBOUNDED
from etsc_envs.core.multi_agent import CLOCK_NAME

PAGE_DIR = Path("docs/envs")
"""Where the pages are, relative to the working directory (the checkout's root)."""
BLOCK = re.compile(r"(<!-- generated:(\w+) -->\n)(.*?)(<!-- /generated -->)", re.DOTALL)
CLOCK_MEANING = "time since the channel's last transmission (s)"


def page_name(env_id: str) -> str:
    """The page's file name of ``env_id`` (``etsc/AttitudeTracking-v0``:
    ``AttitudeTracking-v0.md``)."""
    return env_id.split("/", 1)[1] + ".md"


def page_ids() -> list[str]:
    """Every id with a page: the Gymnasium ids and the PettingZoo ids."""
    return sorted({*etsc_envs.ENV_IDS, *etsc_envs.PETTINGZOO_ENV_IDS})


def make(env_id: str) -> Any:
    """The env of ``env_id`` with its defaults (a PettingZoo id: its parallel env)."""
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        return etsc_envs.make_parallel(env_id)
    return gym.make(env_id, disable_env_checker=True).unwrapped


def _loop(env: Any) -> Any:
    """The Gymnasium loop of an env (the shared loop of a PettingZoo env)."""
    return getattr(env, "loop", env)


def feature_meanings(env: Any) -> tuple[dict[str, str], list[str]]:
    """The documentation of the problem's ``FEATURE_NAMES`` (the string after it in its
    module): pattern → meaning for each bullet ``* ``pattern``, ... — meaning``, and the
    paragraphs after the bullets."""
    module = inspect.getmodule(type(_loop(env)))
    if module is None:
        raise TypeError(f"env's loop class {type(_loop(env)).__name__} has no module")
    tree = ast.parse(inspect.getsource(module))
    doc = ""
    for statement, following in zip(tree.body, tree.body[1:], strict=False):
        targets = statement.targets if isinstance(statement, ast.Assign) else []
        named = any(isinstance(t, ast.Name) and t.id == "FEATURE_NAMES" for t in targets)
        if (
            named
            and isinstance(following, ast.Expr)
            and isinstance(following.value, ast.Constant)
            and isinstance(following.value.value, str)
        ):
            doc = inspect.cleandoc(following.value.value)
    meanings: dict[str, str] = {}
    paragraphs: list[str] = []
    for block in doc.split("\n\n")[1:]:
        if not block.startswith("* "):
            paragraphs.append(_markdown(" ".join(block.split())))
            continue
        for bullet in re.split(r"\n(?=\* )", block):
            head, _, meaning = " ".join(bullet[2:].split()).partition(" — ")
            for pattern in re.findall(r"``([^`]+)``", head):
                meanings[pattern] = _markdown(meaning.rstrip(";."))
    return meanings, paragraphs


def _markdown(text: str) -> str:
    """reStructuredText roles and literals of a docstring as Markdown."""
    text = re.sub(r":\w+:`~?(?:[\w.]+\.)?([^`]+)`", r"`\1`", text)
    return text.replace("``", "`")


def _meaning(name: str, meanings: dict[str, str]) -> str:
    for pattern, meaning in meanings.items():
        if fnmatch.fnmatchcase(name, pattern):
            return meaning
    if name.startswith(CLOCK_NAME):
        return CLOCK_MEANING
    raise ValueError(f"observation component {name!r} is not documented in FEATURE_NAMES")


def _bound(value: float) -> str:
    if value >= UNBOUNDED:
        return "∞"
    if value <= -UNBOUNDED:
        return "−∞"
    return f"{value:.6g}"


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def observation_block(env: Any) -> str:
    """The observation table: index, name, bounds and meaning of every component (for a
    multi-agent loop, one agent's block with its index ``i``), then the documentation's
    paragraphs."""
    meanings, paragraphs = feature_meanings(env)
    loop = _loop(env)
    rows = ["| index | name | low | high | meaning |", "|---|---|---|---|---|"]
    names = getattr(env, "agent_observation_names", None)
    if names is not None and env is not loop:  # a PettingZoo agent's own observation
        box = env.observation_space(env.possible_agents[0])
        entries = [(str(k), name, k) for k, name in enumerate(names)]
    elif hasattr(loop, "agent_feature_names"):  # a central env: agent blocks, then the clocks
        box = loop.observation_space
        width, n = len(loop.agent_feature_names), loop.n_channels
        entries = [(f"{width}·i + {k}", f"{name}_i", k)
                   for k, name in enumerate(loop.agent_feature_names)]  # fmt: skip
        entries.append((f"{width * n} + i", f"{CLOCK_NAME}_i", width * n))
        names = loop.agent_feature_names
    else:
        box = loop.observation_space
        entries = [(str(k), name, k) for k, name in enumerate(loop.observation_names)]
    for index, name, position in entries:
        base = name[:-2] if name.endswith("_i") else name
        rows.append(
            f"| {index} | `{name}` | {_bound(box.low[position])} | {_bound(box.high[position])}"
            f" | {_cell(_meaning(base, meanings))} |"
        )
    note = "∞: the largest float32 (`UNBOUNDED`), the bound of a component nothing bounds."
    return "\n".join([*rows, "", note, "", *(f"{p}\n" for p in paragraphs)]).rstrip() + "\n"


def summary_block(env_id: str, env: Any) -> str:
    """Spaces, sampling period, horizon and how to make the env, as a two-column table."""
    loop = _loop(env)
    if env is loop:
        action, observation = env.action_space, env.observation_space
        make_line = f'gym.make("{env_id}")'
    else:
        agent = env.possible_agents[0]
        action = env.action_space(agent)
        observation = env.observation_space(agent)
        make_line = f'pettingzoo.make("parallel", "{env_id}")'
    rows = [
        "| | |",
        "|---|---|",
        f"| Action space | `{action}` |",
        f"| Observation space | `Box({observation.shape}, float32)`, bounds below |",
        f"| Sampling period | {loop.sampling_period_s:g} s |",
        f"| Horizon (paper scenario) | {loop.horizon_s:g} s = {loop.n_steps} steps |",
        f"| Make | `{make_line}` (after `import etsc_envs`) |",
    ]
    if env is not loop:
        rows.insert(3, f"| Agents | `{'`, `'.join(env.possible_agents)}` |")
    return "\n".join(rows) + "\n"


def keyword_block(env: Any) -> str:
    """Every constructor keyword with its default and documentation (the parameter
    dataclass's field documentation, else the ``Args`` of the env's classes, the env's own
    first)."""
    env_class = type(env)
    params_docs = field_docs(type(_loop(env).params))
    args_docs: dict[str, str] = {}
    for cls in (*type(_loop(env)).__mro__, *env_class.__mro__)[::-1]:  # nearest class wins
        args_docs.update(_args_docs(cls.__doc__ or ""))
    rows = ["| keyword | default | meaning |", "|---|---|---|"]
    for name, parameter in inspect.signature(env_class).parameters.items():
        if parameter.kind is inspect.Parameter.VAR_KEYWORD:
            continue
        default = "required" if parameter.default is inspect.Parameter.empty else parameter.default
        meaning = params_docs.get(name) or args_docs.get(name, "")
        rows.append(f"| `{name}` | `{default!r}` | {_cell(_markdown(meaning))} |")
    return "\n".join(rows) + "\n"


def _args_docs(doc: str) -> dict[str, str]:
    """``name`` → text of each entry of a Google-style ``Args:`` section."""
    lines = inspect.cleandoc(doc).splitlines()
    if "Args:" not in lines:
        return {}
    entries: dict[str, str] = {}
    current: list[str] = []
    for line in lines[lines.index("Args:") + 1 :]:
        if line and not line.startswith(" "):
            break
        match = re.match(r"    ([\w, ]+): (.*)", line)
        if match:
            current = [match.group(2)]
            for name in match.group(1).split(","):
                entries[name.strip()] = current  # type: ignore[assignment]
        elif line.strip() and current:
            current.append(line.strip())
    return {name: " ".join(text) for name, text in entries.items()}


def leaderboard_block(env_id: str) -> str:
    """The id's test-set rows of the leaderboard (:func:`etsc_envs.leaderboard`): mean cost and
    transmissions with 95 % intervals and failures, after what the cost is and its links."""
    from etsc_envs.evaluation.leaderboard import leaderboard
    from etsc_envs.papers import paper_of

    def number(value: float) -> str:
        return f"{value:.0f}" if abs(value) >= 1e4 else f"{value:.4g}"

    def cell(mean: float, interval: tuple[float, float]) -> str:
        if interval[0] == interval[1]:
            return number(mean)
        return f"{number(mean)} [{number(interval[0])}, {number(interval[1])}]"

    lines = [
        f"`mean_cost` is the mean per-step cost {_markdown(paper_of(env_id).cost)}. The "
        "whole table (the paper scenario, the records, figures) is the "
        "[leaderboard](../leaderboard.md); to place your own trigger among these rows, see "
        "[score your trigger](../benchmark.md).",
        "",
        "| trigger | test: mean cost | test: transmissions | test: failures |",
        "|---|---|---|---|",
    ]
    for row in leaderboard(env_id):
        test = row.test
        if test is None:
            continue
        lines.append(
            f"| {row.trigger} | {cell(test.cost, test.cost_ci95)} "
            f"| {cell(test.transmissions, test.transmissions_ci95)} "
            f"| {test.failures}/{test.episodes} |"
        )
    return "\n".join(lines) + "\n"


BLOCKS: dict[str, Callable[[str, Any], str]] = {
    "summary": summary_block,
    "leaderboard": lambda env_id, env: leaderboard_block(env_id),
    "observation": lambda env_id, env: observation_block(env),
    "keywords": lambda env_id, env: keyword_block(env),
}


def fill(text: str, env_id: str, env: Any | None = None) -> str:
    """``text`` (a page) with every generated block rewritten for ``env_id``."""
    env = make(env_id) if env is None else env

    def write(match: re.Match) -> str:
        kind = match.group(2)
        if kind not in BLOCKS:
            raise ValueError(f"unknown generated block {kind!r}; known: {sorted(BLOCKS)}")
        return f"{match.group(1)}{BLOCKS[kind](env_id, env)}{match.group(4)}"

    return BLOCK.sub(write, text)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m etsc_envs.pages",
        description="Rewrite (or --check) the generated blocks of docs/envs/<name>.md.",
    )
    parser.add_argument("--check", action="store_true", help="exit 1 if a page would change")
    parser.add_argument("--dir", type=Path, default=PAGE_DIR, help=f"default {PAGE_DIR}")
    args = parser.parse_args(argv)
    stale = []
    for env_id in page_ids():
        path = args.dir / page_name(env_id)
        text = path.read_text(encoding="utf-8")
        filled = fill(text, env_id)
        if filled != text:
            stale.append(str(path))
            if not args.check:
                path.write_text(filled, encoding="utf-8")
    if stale:
        print(("stale: " if args.check else "rewrote: ") + ", ".join(stale))
    return 1 if stale and args.check else 0


if __name__ == "__main__":
    sys.exit(main())

"""The one reader of the suite's JSON files: learned triggers, decision sets, search resumes
(``generations.jsonl``) and judged records all come in through :func:`read_json_file` or
:func:`read_json_lines`, and their keys are checked with the ``require_*`` functions here.

Reading bounds the file's size (:data:`MAX_BYTES`) and its nesting (:data:`MAX_DEPTH`: a file
of ten thousand nested brackets is one line, not Python's ``RecursionError``). Every check
names the key by its dotted path (``key 'point.modulation.b2' must be ...``), refuses a key
the format does not define, a number of the wrong kind (``true`` or ``"1"`` for a number,
``"false"`` for a flag) and any value that is not finite, and an array is checked to the last
element against the shape its reader indexes (the compiled trigger kernels read their
parameters by position, so a short row would be read past its end). Every failure is one
``ValueError`` line; callers put the file's name in front (:func:`in_file`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

MAX_DEPTH = 32
"""The deepest nesting of arrays and objects a file of the suite may have (the deepest format,
a decision set's modulation weights, nests six)."""

MAX_BYTES = 256 * 2**20
"""The largest JSON file the suite reads (judged records with every episode are a few MB)."""


@contextmanager
def in_file(where: str) -> Iterator[None]:
    """Put ``where`` (the file as the user named it, ``learned:PATH``) in front of every
    ``ValueError`` raised inside the block."""
    try:
        yield
    except ValueError as error:
        raise ValueError(f"{where}: {error}") from None


def nesting_depth(value: Any) -> int:
    """How deep arrays and objects nest in ``value`` (a scalar is 0), without recursion."""
    deepest = 0
    stack: list[tuple[Any, int]] = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict | list):
            depth += 1
            deepest = max(deepest, depth)
            if depth > MAX_DEPTH:
                return depth
            children = item.values() if isinstance(item, dict) else item
            stack.extend((child, depth) for child in children)
    return deepest


def read_json_text(text: str) -> Any:
    """The JSON value of ``text``; ``ValueError`` for text that is not JSON or nests deeper than
    :data:`MAX_DEPTH`."""
    try:
        value = json.loads(text)
    except RecursionError:
        raise ValueError(f"nests deeper than {MAX_DEPTH} arrays or objects") from None
    except json.JSONDecodeError as error:
        raise ValueError(f"not JSON ({error})") from None
    if nesting_depth(value) > MAX_DEPTH:
        raise ValueError(f"nests deeper than {MAX_DEPTH} arrays or objects")
    return value


def _read_text(path: Path) -> str:
    try:
        if path.stat().st_size > MAX_BYTES:
            raise ValueError(f"larger than {MAX_BYTES // 2**20} MiB, more than any file it reads")
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise ValueError(f"not a readable JSON file ({reason})") from None


def read_json_file(path: str | Path, where: str | None = None) -> Any:
    """The JSON value in the file ``path``; ``ValueError`` starting with ``where`` (default the
    path) for a file that cannot be read, is not JSON, or nests too deep."""
    with in_file(where or str(path)):
        return read_json_text(_read_text(Path(path)))


def read_json_lines(path: str | Path, where: str | None = None) -> tuple[list[Any], bool]:
    """The JSON values of the lines of ``path`` (JSON Lines, appended one record at a time) and
    whether a torn last line (a write the process did not finish) was dropped; a damaged line
    before the last is a ``ValueError`` naming it."""
    with in_file(where or str(path)):
        lines = _read_text(Path(path)).splitlines()
        records: list[Any] = []
        for number, line in enumerate(lines, start=1):
            try:
                records.append(read_json_text(line))
            except ValueError as error:
                if number == len(lines):
                    return records, True
                raise ValueError(f"line {number}: {error}") from None
        return records, False


def require_mapping(
    value: Any, key: str, allowed: Iterable[str] | None = None, required: Iterable[str] = ()
) -> dict[str, Any]:
    """``value`` as a dict when it is a JSON object whose keys are among ``allowed`` (any when
    ``None``) and include ``required``."""
    if not isinstance(value, Mapping):
        raise ValueError(f"{_name(key)} must be a mapping of keys, got {_shown(value)}")
    if allowed is not None:
        allowed = sorted(allowed)
        unknown = sorted(str(name) for name in value if name not in allowed)
        if unknown:
            raise ValueError(f"{_name(key)}: unknown keys {unknown}; allowed {allowed}")
    missing = [name for name in required if name not in value]
    if missing:
        raise ValueError(f"{_name(key)} is missing {missing}")
    return dict(value)


def require_number(
    value: Any,
    key: str,
    *,
    low: float = -math.inf,
    high: float = math.inf,
    low_open: bool = False,
    infinity: bool = False,
) -> float:
    """``value`` as a float when it is a JSON number in ``[low, high]`` (``(low, high]`` when
    ``low_open``), finite unless ``infinity`` (then also the string ``"inf"``, JSON having no
    infinity)."""
    if infinity and value == "inf":
        value = math.inf
    if math.isinf(high) and math.isinf(low):
        allows = "a finite number"
    elif math.isinf(high):
        allows = f"a finite number {'>' if low_open else '>='} {low:g}"
    else:
        allows = f"a number in {'(' if low_open else '['}{low:g}, {high:g}]"
    if infinity:
        allows += ' or "inf"'
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{_name(key)} must be {allows}, got {_shown(value)}")
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if (
        math.isnan(number)
        or (math.isinf(number) and not (infinity and number > 0))
        or number < low
        or (low_open and number == low)
        or number > high
    ):
        raise ValueError(f"{_name(key)} must be {allows}, got {_shown(value)}")
    return number


def require_integer(value: Any, key: str, low: int, high: int) -> int:
    """``value`` when it is a JSON integer in ``low..high``."""
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise ValueError(f"{_name(key)} must be an integer in {low}..{high}, got {_shown(value)}")
    return value


def require_bool(value: Any, key: str) -> bool:
    """``value`` when it is ``true`` or ``false`` (not a string, not a number)."""
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"{_name(key)} must be true or false, got {_shown(value)}")
    return bool(value)


def require_string(value: Any, key: str, choices: Iterable[str] | None = None) -> str:
    """``value`` when it is a string (one of ``choices`` where given)."""
    options = None if choices is None else sorted(choices)
    if not isinstance(value, str) or (options is not None and value not in options):
        allows = "a string" if options is None else f"one of {options}"
        raise ValueError(f"{_name(key)} must be {allows}, got {_shown(value)}")
    return value


def require_strings(
    value: Any, key: str, choices: Iterable[str] | None = None, *, most: int = 64
) -> tuple[str, ...]:
    """``value`` as a tuple when it is a list of at most ``most`` distinct strings (each one of
    ``choices`` where given)."""
    if not isinstance(value, list | tuple) or len(value) > most:
        raise ValueError(
            f"{_name(key)} must be a list of at most {most} names, got {_shown(value)}"
        )
    names = tuple(require_string(name, f"{key}[{i}]", choices) for i, name in enumerate(value))
    if len(set(names)) != len(names):
        raise ValueError(f"{_name(key)} names an entry twice: {list(names)}")
    return names


def require_array(value: Any, key: str, shape: tuple[int | None, ...]) -> np.ndarray:
    """``value`` as a float64 array when it is nested JSON arrays of finite numbers of
    ``shape`` (``None``: any length along that axis, the same for every row)."""
    wanted = "(" + ", ".join("n" if size is None else str(size) for size in shape) + ")"
    if len(shape) == 1:
        wanted = wanted[:-1] + ",)"

    def refuse(problem: str) -> ValueError:
        return ValueError(
            f"{_name(key)} must be an array of shape {wanted} of finite numbers; {problem}"
        )

    sizes: list[int] = []
    level = [value]
    for axis, size in enumerate(shape):
        lengths = set()
        for item in level:
            if not isinstance(item, list | tuple | np.ndarray):
                raise refuse(f"got {_shown(item)} at depth {axis}")
            lengths.add(len(item))
        if len(lengths) > 1:
            raise refuse(f"its rows at depth {axis} have lengths {sorted(lengths)}")
        length = lengths.pop() if lengths else 0
        if size is not None and length != size:
            raise refuse(f"got length {length} along axis {axis}")
        sizes.append(length)
        level = [element for item in level for element in item]
    for element in level:
        if isinstance(element, bool) or not isinstance(element, int | float | np.floating):
            raise refuse(f"got the element {_shown(element)}")
    try:
        array = np.array(level, dtype=np.float64).reshape(sizes)
    except OverflowError:
        raise refuse("an element overflows a float") from None
    if not np.all(np.isfinite(array)):
        raise refuse("an element is NaN or infinite")
    return array


def require_env_id(stated: Any, env_id: str | None, key: str = "env_id") -> str:
    """The id a file ``stated`` (a string), refused when the file is applied to another env
    ``env_id`` (``None``: an env whose id is unknown, which is not checked)."""
    stated = require_string(stated, key)
    if env_id is not None and stated != env_id:
        raise ValueError(f"{_name(key)} is {stated!r}; it cannot be applied to {env_id}")
    return stated


def _name(key: str) -> str:
    """``key 'a.b'`` for a message, ``the top level`` for the whole file (``key`` empty)."""
    return f"key {key!r}" if key else "the top level"


def _shown(value: Any) -> str:
    """``value`` for a message: its repr, cut short, and its JSON kind for a container."""
    if isinstance(value, Mapping):
        return "a mapping"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."

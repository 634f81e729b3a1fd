"""Pieces shared by the command-line tools: ``k=v`` arguments, a ``--model`` as a policy spec,
JSON output, torch's thread count."""

from __future__ import annotations

import json
import sys
from typing import Any

import yaml

from etsc_envs.core.files import atomic_write_text
from etsc_envs.evaluation.episodes import to_jsonable


def limit_torch_threads() -> None:
    """Run PyTorch on one thread when torch is installed. The command-line tools query a policy
    with a batch of one observation per step; more threads only add synchronisation, and under
    load they made a step several times slower."""
    try:
        import torch
    except ImportError:
        return
    torch.set_num_threads(1)


def parse_value(text: str) -> Any:
    """A command-line value: an int or float if it reads as one (``3e-5`` included, which YAML
    1.1 would keep as a string), else YAML (booleans, lists, strings)."""
    for number in (int, float):
        try:
            return number(text)
        except ValueError:
            pass
    return yaml.safe_load(text)


def parse_assignments(pairs: list[str] | None, option: str) -> dict[str, Any]:
    """``["k=v", ...]`` as a dict, each value read by :func:`parse_value`."""
    parsed: dict[str, Any] = {}
    for pair in pairs or []:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise ValueError(f"{option} takes key=value, got {pair!r}")
        try:
            parsed[key] = parse_value(value)
        except yaml.YAMLError as error:
            problem = getattr(error, "problem", None) or type(error).__name__
            raise ValueError(
                f"{option} {key}: {value!r} is not a number, a list such as [0, 0, 0] or a "
                f"YAML value ({problem})"
            ) from None
    return parsed


def model_spec(model: str) -> str:
    """The ``--policy`` of a ``--model``: as given with a ``sb3:`` or ``learned:`` prefix, a
    learned trigger for a ``.json`` file, else an SB3 zip."""
    if model.startswith(("sb3:", "learned:")):
        return model
    return f"learned:{model}" if model.endswith(".json") else f"sb3:{model}"


def write_json(payload: dict[str, Any], destination: str) -> None:
    """Write ``payload`` as JSON to a file, compact (records of a test set run to megabytes:
    indentation doubled them) and whole or not at all, or indented to standard output for
    ``-``."""
    payload = to_jsonable(payload)
    if destination == "-":
        sys.stdout.write(json.dumps(payload, indent=2) + "\n")
    else:
        atomic_write_text(destination, json.dumps(payload, separators=(",", ":")) + "\n")

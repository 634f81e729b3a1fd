"""The tiny sweep that the sweep tests run, written into a test's temporary folder."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "configs" / "sweeps" / "tiny.yaml"


def tiny_sweep(tmp_path: Path, **keys: Any) -> Path:
    """``configs/sweeps/tiny.yaml`` with its results in ``tmp_path`` and ``keys`` replaced."""
    raw = yaml.safe_load(TINY.read_text(encoding="utf-8"))
    raw["base"] = str(ROOT / raw["base"])
    raw["results_dir"] = str(tmp_path / "sweep")
    raw.update(keys)
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(raw, sort_keys=False), encoding="utf-8")
    return path

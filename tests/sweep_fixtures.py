"""The tiny sweep that the sweep tests run, written into a test's temporary folder, and the
sweep command run where Ray cannot be imported."""

from __future__ import annotations

import subprocess
import sys
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


def command_without_ray(*arguments: str, sigint_ignored: bool = False) -> list[str]:
    """The sweep command in a Python where ``import ray`` fails (the worker-process path);
    with ``sigint_ignored``, started as a background job is (SIGINT ignored)."""
    code = (
        "import signal, sys\n"
        + ("signal.signal(signal.SIGINT, signal.SIG_IGN)\n" if sigint_ignored else "")
        + "sys.modules['ray'] = None  # as if Ray were not installed\n"
        "from agents.sweep.runner import main\n"
        f"raise SystemExit(main({list(arguments)!r}))\n"
    )
    return [sys.executable, "-c", code]


def sweep_without_ray(*arguments: str) -> subprocess.CompletedProcess:
    """:func:`command_without_ray` run to its end."""
    return subprocess.run(
        command_without_ray(*arguments), cwd=ROOT, capture_output=True, text=True, timeout=900
    )


def retrained_differences(folder: Path, out_dir: Path) -> list[str]:
    """Train the run of a sweep trial ``folder`` again with ``agents.train`` (its resolved
    ``config.yaml``, into ``out_dir``) and name every policy tensor and normalisation statistic
    that differs from the trial's: a sweep's trial must be the run its config describes, so
    that a record can be remade from its config and seed alone."""
    import numpy as np
    import torch
    from stable_baselines3.common.save_util import load_from_zip_file

    from agents.train.config import load_config
    from agents.train.training import train

    train(load_config(folder / "config.yaml", {"out_dir": str(out_dir)}))
    differences = []
    tensors = [load_from_zip_file(run / "model.zip")[1]["policy"] for run in (folder, out_dir)]
    for name, tensor in tensors[0].items():
        if not torch.equal(tensor, tensors[1][name]):
            differences.append(f"policy {name}")
    with (
        np.load(folder / "model_vecnormalize.npz") as a,
        np.load(out_dir / "model_vecnormalize.npz") as b,
    ):
        differences += [f"statistic {key}" for key in a.files if not np.array_equal(a[key], b[key])]
    return differences

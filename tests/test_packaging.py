"""What ``pip install`` of the package puts into site-packages.

Checked properties: a wheel built from the checkout holds the library ``etsc_envs`` alone at its
top level (no ``baselines`` or ``agents``, generic names other packages own), with the paper
triggers inside it (``etsc_envs.triggers``), its ``py.typed`` marker and the asteroid data.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_wheel_installs_only_the_etsc_envs_package(tmp_path):
    source = tmp_path / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    for name in ("etsc_envs", "baselines", "agents"):
        shutil.copytree(ROOT / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
    command = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation"]
    result = subprocess.run(
        [*command, "--wheel-dir", str(tmp_path / "dist"), str(source)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    (wheel,) = (tmp_path / "dist").glob("etsc_envs-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    top_level = {name.split("/")[0] for name in names if not name.split("/")[0].endswith("-info")}
    assert top_level == {"etsc_envs"}
    assert "etsc_envs/triggers/attitude_tracking.py" in names
    assert "etsc_envs/py.typed" in names
    assert any(name.startswith("etsc_envs/asteroid/data/") for name in names)

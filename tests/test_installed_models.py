"""Every model shipped in ``models/`` loads with ``etsc_envs.load_policy`` in a project that has
only the installed package, and acts there as the checkout's ``baselines.evaluate`` policy does.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import sysconfig
import venv
import zipfile
from pathlib import Path
from typing import Any

import gymnasium as gym
import pytest

pytest.importorskip("stable_baselines3")

from policy_prefix import env_id_of, run_prefix

import etsc_envs
from etsc_envs.evaluation.arguments import model_spec
from etsc_envs.evaluation.policy_specs import episode_setup

ROOT = Path(__file__).parents[1]
RUNNER = Path(__file__).with_name("policy_prefix.py")
MODELS = sorted(
    path
    for path in (ROOT / "models").iterdir()
    if path.suffix in (".zip", ".json") and not path.name.endswith("_decisions.json")
)
"""Every shipped trigger: SB3 zips (per-instant PPO, self-triggered) and learned triggers."""
STEPS = 400
"""The prefix of the paper scenario each model runs in the fast test."""
WHEEL_STEPS = 3000
"""The prefix each model runs from the wheel: a full paper episode is 48 000 to 300 000
instants, hours of one-at-a-time ``predict`` calls for every model together."""
CHECKOUT_MODULES = {"agents", "baselines", "tests", "policy_prefix"}
"""Top-level modules of the checkout outside the installed package."""


def test_load_policy_names_the_train_extra_and_refuses_other_envs(monkeypatch) -> None:
    """Without Stable-Baselines3 an SB3 model is refused with one line naming the extra that
    installs it; an env that is not of the package is refused naming ``env``."""
    model = str(ROOT / "models" / "AttitudeTracking-v0_ppo.zip")
    with pytest.raises(ValueError, match=r"^env: "):
        etsc_envs.load_policy(model, gym.make("CartPole-v1"))
    monkeypatch.setitem(sys.modules, "stable_baselines3", None)
    with pytest.raises(ModuleNotFoundError, match=r"^loading .* pip install 'etsc-envs\[train\]'$"):
        etsc_envs.load_policy(model, gym.make("etsc/AttitudeTracking-v0"))


def _isolated_run(python: str, cwd: Path, steps: int) -> dict[str, Any]:
    """:mod:`policy_prefix` run by ``python -I`` in ``cwd`` (a copy of the script: isolated
    mode puts neither the script's folder, nor the working folder, nor ``PYTHONPATH`` on
    ``sys.path``) over every shipped model."""
    script = cwd / RUNNER.name
    script.write_text(RUNNER.read_text(encoding="utf-8"), encoding="utf-8")
    result = subprocess.run(
        [python, "-I", str(script), str(steps), *map(str, MODELS)],
        cwd=cwd,
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads(result.stdout)


def _checkout_records(steps: int) -> dict[str, dict[str, int]]:
    """Each model's prefix under the checkout's ``baselines.evaluate`` policy (``--policy
    sb3:PATH`` or ``learned:PATH``)."""
    records = {}
    for model in MODELS:
        setup = episode_setup(env_id_of(model), {})
        policy = setup.make_policy(model_spec(str(model)), {})
        records[model.name] = run_prefix(policy, setup.env, steps)
        setup.env.close()
    return records


def _checkout_importable(python: str, cwd: Path) -> list[str]:
    """The checkout's top-level modules that ``python -I`` in ``cwd`` can find."""
    code = (
        "import importlib.util, json, sys; "
        "print(json.dumps([name for name in sys.argv[1:] if importlib.util.find_spec(name)]))"
    )
    found = subprocess.run(
        [python, "-I", "-c", code, *sorted(CHECKOUT_MODULES)],
        cwd=cwd,
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(found.stdout)


def test_every_shipped_model_runs_from_the_installed_package(tmp_path: Path) -> None:
    """In a process started outside the checkout, in isolated mode, the checkout's
    ``agents`` and ``baselines`` cannot be imported, and ``etsc_envs.load_policy`` loads every
    shipped model and takes the checkout's decisions on a prefix of the paper scenario."""
    assert _checkout_importable(sys.executable, tmp_path) == []
    isolated = _isolated_run(sys.executable, tmp_path, STEPS)
    assert not CHECKOUT_MODULES & set(isolated["modules"])
    assert set(isolated["records"]) == {model.name for model in MODELS}
    assert isolated["records"] == _checkout_records(STEPS)
    assert all(record["steps"] == STEPS for record in isolated["records"].values())
    assert any(record["transmissions"] > 0 for record in isolated["records"].values())


PIP = (sys.executable, "-m", "pip", "--quiet", "--isolated")
"""This environment's pip, reading no configuration; each command below adds ``--no-index``
and ``--no-deps``, so that it reads nothing but the paths it is given."""


def _build_wheel(destination: Path) -> Path:
    """The wheel of the package built from a copy of its sources (``pyproject.toml``,
    ``README.md``, ``etsc_envs/``), without network: ``pip wheel --no-build-isolation`` with
    this environment's setuptools."""
    source = destination / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    shutil.copytree(
        ROOT / "etsc_envs",
        source / "etsc_envs",
        ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", "*.pyc"),
    )
    wheels = destination / "wheels"
    subprocess.run(
        [
            *PIP,
            "wheel",
            "--no-index",
            "--no-deps",
            "--no-build-isolation",
            str(source),
            "--wheel-dir",
            str(wheels),
        ],
        check=True,
        capture_output=True,
    )
    (wheel,) = wheels.glob("etsc_envs-*.whl")
    return wheel


def _fresh_environment(directory: Path, wheel: Path) -> str:
    """A new virtual environment at ``directory`` holding ``wheel``, and its Python.

    The dependencies, the ``train`` extra's included, are this environment's installed
    packages, reused rather than installed again: the machine's package index does not hold
    every one of them (Stable-Baselines3, say), and a test must not download. This environment
    is itself a virtual environment, so ``--system-site-packages`` would reach the base
    interpreter's packages instead; the new environment reads this one's ``site-packages``
    through a ``.pth`` line, after its own. Such a line adds the folder alone: the ``.pth``
    files inside it, which install the checkout's editable finder, are not run, so
    ``etsc_envs`` imports from the wheel (the test checks ``etsc_envs.__file__``). The wheel
    is installed with ``pip install --target`` into the new ``site-packages``, which never
    touches another environment's packages."""
    venv.create(directory, with_pip=False)
    python = directory / "bin" / "python"
    paths = subprocess.run(
        [str(python), "-I", "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    )
    site = Path(paths.stdout.strip())
    reused = dict.fromkeys(sysconfig.get_paths()[key] for key in ("purelib", "platlib"))
    (site / "reused_environment.pth").write_text("\n".join(reused) + "\n", encoding="utf-8")
    subprocess.run(
        [*PIP, "install", "--no-index", "--no-deps", "--target", str(site), str(wheel)],
        check=True,
        capture_output=True,
    )
    return str(python)


TRAIN_EXTRA_CHECK = """
import json
from importlib.metadata import PackageNotFoundError, requires, version
from packaging.requirements import Requirement

unmet = []
for text in requires("etsc-envs"):
    requirement = Requirement(text)
    if requirement.marker is not None and not requirement.marker.evaluate({"extra": "train"}):
        continue
    try:
        if not requirement.specifier.contains(version(requirement.name), prereleases=True):
            unmet.append(text)
    except PackageNotFoundError:
        unmet.append(text)
print(json.dumps(unmet))
"""
"""The requirements of the installed ``etsc-envs`` with its ``train`` extra that the new
environment does not meet (its own metadata, read where the environment finds it first)."""


@pytest.mark.slow
def test_every_shipped_model_runs_from_the_wheel_in_a_fresh_environment(tmp_path: Path) -> None:
    """The wheel holds ``etsc_envs`` alone; a fresh virtual environment with it (and the
    ``train`` extra's packages) runs every shipped model on the first :data:`WHEEL_STEPS`
    instants of its id's paper scenario with ``etsc_envs`` imported from the wheel, taking the
    checkout's decisions (the same transmissions on the same prefix)."""
    wheel = _build_wheel(tmp_path)
    with zipfile.ZipFile(wheel) as archive:
        tops = {name.partition("/")[0] for name in archive.namelist()}
    assert tops == {"etsc_envs", wheel.name.partition("-py3")[0] + ".dist-info"}
    python = _fresh_environment(tmp_path / "venv", wheel)
    unmet = subprocess.run(
        [python, "-I", "-c", TRAIN_EXTRA_CHECK], capture_output=True, text=True, check=True
    )
    assert json.loads(unmet.stdout) == []
    work = tmp_path / "work"
    work.mkdir()
    assert _checkout_importable(python, work) == []
    isolated = _isolated_run(python, work, WHEEL_STEPS)
    assert Path(isolated["etsc_envs"]).is_relative_to(tmp_path / "venv")
    assert not CHECKOUT_MODULES & set(isolated["modules"])
    assert isolated["records"] == _checkout_records(WHEEL_STEPS)

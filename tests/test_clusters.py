"""``--address`` against a real Ray cluster on this machine (``ray start --head`` on 127.0.0.1):
``agents.search`` and ``agents.sweep`` join it and finish; a cluster that wants a token refuses
a driver without one in one line naming ``RAY_AUTH_MODE``, and takes one that has it. Slow
(a cluster start and two runs): ``pytest -m slow tests/test_clusters.py``."""

from __future__ import annotations

import os
import secrets
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from tests.sweep_fixtures import ROOT, tiny_sweep

pytestmark = pytest.mark.slow
pytest.importorskip("ray")

SEARCH = {
    "env_id": "etsc/AttitudeTracking-v0",
    "penalty": 1.0,
    "start": {"factors": {"psi": 1.0}},
    "search": ["factors"],
    "generations": 1,
    "population": 2,
    "scenarios": 1,
    "horizon_s": 0.2,
    "validation_size": 1,
}


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _head(tmp_path: Path, environment: dict[str, str]) -> Iterator[str]:
    """A Ray head on 127.0.0.1 (``ray start --block``, ended by its own process id), and its
    address."""
    port = _free_port()
    head = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "ray.scripts.scripts",
            "start",
            "--head",
            "--block",
            "--port",
            str(port),
            "--node-ip-address",
            "127.0.0.1",
            "--num-cpus",
            "2",
            "--include-dashboard",
            "false",
            "--disable-usage-stats",
        ],
        env=environment,
        stdout=(tmp_path / "head.log").open("w"),
        stderr=subprocess.STDOUT,
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                time.sleep(1)
        time.sleep(3)  # the raylet registers after the GCS port opens
        yield f"127.0.0.1:{port}"
    finally:
        head.terminate()
        head.wait(timeout=120)
        # The head leaves its address as this machine's default cluster; a later ray.init()
        # without an address would try to join it.
        current = Path(tempfile.gettempdir()) / "ray" / "ray_current_cluster"
        if current.is_file() and current.read_text().strip().endswith(f":{port}"):
            current.unlink()


def _run(module: str, arguments: list[str], environment: dict[str, str]) -> tuple[int, str]:
    done = subprocess.run(
        [sys.executable, "-m", module, *arguments],
        cwd=ROOT,
        env=environment,
        capture_output=True,
        text=True,
        timeout=900,
    )
    return done.returncode, done.stdout + done.stderr


def _environment(tmp_path: Path, **values: str) -> dict[str, str]:
    """This process's environment without Ray's address and token settings, with a home of its
    own (no ~/.ray/auth_token of the user's), and ``values``."""
    environment = {
        key: value
        for key, value in os.environ.items()
        if not key.startswith(("RAY_ADDRESS", "RAY_AUTH"))
    }
    return {**environment, "HOME": str(tmp_path / "home"), **values}


@pytest.fixture
def open_cluster(tmp_path: Path) -> Iterator[str]:
    yield from _head(tmp_path, _environment(tmp_path, RAY_AUTH_MODE="disabled"))


def test_search_and_sweep_join_a_local_cluster(tmp_path: Path, open_cluster: str) -> None:
    environment = _environment(tmp_path)
    config = tmp_path / "search.yaml"
    config.write_text(yaml.safe_dump(SEARCH))
    status, output = _run(
        "agents.search",
        ["--config", str(config), "--out", str(tmp_path / "search"), "--address", open_cluster],
        environment,
    )
    assert status == 0, output
    assert f"on Ray at {open_cluster}" in output
    assert (tmp_path / "search" / "learned.json").is_file()
    status, output = _run(
        "agents.sweep",
        ["--config", str(tiny_sweep(tmp_path)), "--address", open_cluster],
        environment,
    )
    assert status == 0, output
    assert (tmp_path / "sweep" / "sweep_summary.json").is_file()


def test_a_cluster_with_token_authentication_names_the_token(tmp_path: Path) -> None:
    token = secrets.token_hex(16)
    config = tmp_path / "search.yaml"
    config.write_text(yaml.safe_dump({**SEARCH, "generations": 1}))
    secured = _environment(tmp_path, RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=token)
    for address in _head(tmp_path, secured):
        out = ["--out", str(tmp_path / "search"), "--address", address]
        status, output = _run(
            "agents.search",
            ["--config", str(config), *out],
            _environment(tmp_path, RAY_AUTH_MODE="token"),
        )
        assert status == 2, output
        lines = [line for line in output.splitlines() if line.startswith("error:")]
        assert len(lines) == 1 and "RAY_AUTH_MODE=token" in lines[0], output
        assert "Traceback" not in output
        status, output = _run("agents.search", ["--config", str(config), *out], secured)
        assert status == 0, output

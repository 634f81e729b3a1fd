"""The new surfaces tried as a hostile user would: search configs refused when read with one line
naming the key, ``--resume`` checked before anything is written, outputs checked before the
work, a finished result never replaced by another model's, and configs drawn by hypothesis."""

from __future__ import annotations

import json
import socket
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
import yaml

from agents.search.cma_es import MAX_SCENARIOS, SearchConfig, config_from_dict, run_search
from agents.search.cma_es import main as search_main

GOOD = {
    "env_id": "etsc/AttitudeTracking-v0",
    "penalty": 1.0,
    "start": {"factors": {"psi": 1.0}, "heartbeat_instants": 50},
    "search": ["factors", "floor", "heartbeat", "exponent"],
    "generations": 4,
    "population": 4,
    "scenarios": 2,
    "validate_every": 2,
    "validation_size": 2,
    "horizon_s": 1.0,
}


def _error_lines(capsys) -> list[str]:
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    return [line for line in err.splitlines() if line.startswith("error:")]


@pytest.mark.parametrize(
    ("changes", "key"),
    [
        ({"env_id": "etsc/ClusterContainment-v0"}, "search.start.factors"),
        ({"hidden": [1000, 1000]}, "search.hidden"),
        ({"hidden": 1000}, "search.hidden"),
        ({"horizon_s": float("inf")}, "search.horizon_s"),
        ({"horizon_s": 1e-9}, "search.horizon_s"),
        ({"horizon_s": "1e-9"}, "search.horizon_s"),
        ({"horizon_s": True}, "search.horizon_s"),
        ({"search": [*GOOD["search"], "modulation"], "inputs": ["nope"]}, "search.inputs[0]"),
        ({"search": [*GOOD["search"], "modulation"], "inputs": 3}, "search.inputs"),
        ({"keywords": {"nu": 1.0}}, "search.keywords"),
        ({"keywords": ["psi"]}, "search.keywords"),
        ({"penalty": 1e300}, "search.penalty"),
        ({"scenarios": 10**9}, "search.scenarios"),
        ({"search": 3}, "search.search"),
        ({"start": 3}, "search.start"),
        ({"start": {"factors": {"wings": 2.0}}}, "search.start.factors"),
        ({"validation_size": 2_000_000}, "search.validation_size"),
        ({"start": {"first_instant": "false"}}, "search.start.first_instant"),
        ({"colour": "red"}, "unknown keys ['colour']"),
    ],
)
def test_a_bad_search_config_is_one_line_naming_its_key(
    tmp_path: Path, capsys, changes: dict[str, Any], key: str
) -> None:
    config = tmp_path / "bad.yaml"
    config.write_text(yaml.safe_dump({**GOOD, **changes}))
    assert search_main(["--config", str(config), "--out", str(tmp_path / "out")]) == 2
    lines = _error_lines(capsys)
    assert len(lines) == 1 and lines[0].startswith("error: config key 'search"), lines
    assert key in lines[0], lines
    assert not (tmp_path / "out").exists()


class ToyEvaluator:
    """Scores without running an env (the search's bookkeeping is what is tested)."""

    def map(self, calls: list[tuple[Any, ...]]) -> list[dict[str, float]]:
        return [
            {"return": -float(len(json.dumps(c[2]))), "mean_cost": 1.0, "transmissions": 1.0}
            | {"failures": 0, "steps": 10}
            for c in calls
        ]

    def close(self) -> None:
        pass


def _finished_search(tmp_path: Path) -> tuple[Path, Path]:
    """A finished toy search in ``tmp_path/out`` with its config.yaml, and its config file."""
    config = tmp_path / "search.yaml"
    config.write_text(yaml.safe_dump(GOOD))
    out = tmp_path / "out"
    run_search(config_from_dict(GOOD), out, ToyEvaluator(), progress=lambda line: None)
    (out / "config.yaml").write_text(yaml.safe_dump({**GOOD, "seed": 0}))
    return config, out


@pytest.mark.parametrize("change", [["--seed", "3"], "config"])
def test_resume_with_another_config_or_seed_changes_nothing(tmp_path: Path, capsys, change):
    config, out = _finished_search(tmp_path)
    if change == "config":
        config.write_text(yaml.safe_dump({**GOOD, "population": 6}))
        change = []
    before = {path.name: path.read_bytes() for path in out.iterdir()}
    status = search_main(["--config", str(config), "--out", str(out), "--resume", *change])
    assert status == 2
    lines = _error_lines(capsys)
    assert len(lines) == 1 and "--resume: --out" in lines[0] and "differ" in lines[0], lines
    assert {path.name: path.read_bytes() for path in out.iterdir()} == before


def test_resume_drops_a_torn_last_line_with_a_line_saying_so(tmp_path: Path) -> None:
    config = config_from_dict(GOOD)
    whole = run_search(config, tmp_path / "whole", ToyEvaluator(), progress=lambda line: None)
    torn = tmp_path / "torn"
    run_search(config, torn, ToyEvaluator(), progress=lambda line: None)
    log = torn / "generations.jsonl"
    lines = log.read_text().splitlines()
    log.write_text("\n".join(lines[:-1]) + "\n" + lines[-1][: len(lines[-1]) // 2])
    said: list[str] = []
    resumed = run_search(config, torn, ToyEvaluator(), progress=said.append)
    assert any("dropped the torn last line" in line for line in said), said
    assert resumed.point.to_json() == whole.point.to_json()
    assert len(log.read_text().splitlines()) == len(lines)


def test_a_damaged_record_before_the_last_line_names_line_and_key(tmp_path: Path) -> None:
    config = config_from_dict(GOOD)
    out = tmp_path / "out"
    run_search(config, out, ToyEvaluator(), progress=lambda line: None)
    log = out / "generations.jsonl"
    records = [json.loads(line) for line in log.read_text().splitlines()]
    records[0]["candidates"][1] = records[0]["candidates"][1][:-1]
    log.write_text("".join(json.dumps(record) + "\n" for record in records))
    with pytest.raises(ValueError, match=r"line 1: key 'candidates' must be an array of shape"):
        run_search(config, out, ToyEvaluator(), progress=lambda line: None)


def test_search_gives_up_on_an_unreachable_address_in_one_line(tmp_path: Path, capsys) -> None:
    config = tmp_path / "search.yaml"
    config.write_text(yaml.safe_dump(GOOD))
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    started = time.monotonic()
    out = str(tmp_path / "out")
    status = search_main(["--config", str(config), "--out", out, "--address", f"127.0.0.1:{port}"])
    assert status == 2 and time.monotonic() - started < 30
    lines = _error_lines(capsys)
    assert len(lines) == 1 and "--address: no Ray cluster answers" in lines[0], lines
    assert not Path(out).exists()


@pytest.mark.parametrize("kind", ["proc", "folder", "under_file", "loop"])
def test_leaderboard_refuses_a_bad_out_before_the_work(tmp_path: Path, capsys, kind) -> None:
    from agents.judge.leaderboard import main

    (tmp_path / "file").write_text("")
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    out = {
        "proc": "/proc/x.md",
        "folder": str(tmp_path),
        "under_file": str(tmp_path / "file" / "x.md"),
        "loop": str(tmp_path / "loop"),
    }[kind]
    started = time.monotonic()
    with pytest.raises(SystemExit) as exit_info:
        main(["--out", out])
    assert exit_info.value.code == 2 and time.monotonic() - started < 10
    assert "--out" in capsys.readouterr().err.strip().splitlines()[-1]


def test_leaderboard_refuses_an_empty_records_folder(tmp_path: Path, capsys) -> None:
    from agents.judge.leaderboard import main

    with pytest.raises(SystemExit) as exit_info:
        main(["--records", str(tmp_path), "--out", str(tmp_path / "board.md")])
    assert exit_info.value.code == 2
    assert "lacks the judged records" in capsys.readouterr().err


def test_results_never_replace_another_models_results(tmp_path: Path, capsys) -> None:
    from agents.judge.results import main

    out = tmp_path / "out"
    out.mkdir()
    first = {"env": "etsc/AttitudeTracking-v0", "models": ["models/first.json"], "sets": {}}
    (out / "results.json").write_text(json.dumps(first))
    model = "models/AttitudeTracking-v0_learned.json"
    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/AttitudeTracking-v0", "--model", model, "--out", str(out)])
    assert exit_info.value.code == 2
    assert "holds the results of ['models/first.json']" in capsys.readouterr().err
    assert json.loads((out / "results.json").read_text()) == first


def test_a_train_buffer_beyond_the_machine_is_refused_before_allocation() -> None:
    from agents.train.config import config_from_dict as train_config

    raw = yaml.safe_load(Path("configs/train/attitude_tracking_ppo.yaml").read_text())
    raw["hyperparameters"] = {**raw.get("hyperparameters", {}), "n_steps": 10**12}
    with pytest.raises(ValueError, match=r"config key 'hyperparameters.n_steps' asks for"):
        train_config(raw)


def test_an_inertia_whose_determinant_underflows_is_refused_at_construction() -> None:
    with pytest.raises(ValueError, match="nominal_inertia must have a determinant"):
        gym.make("etsc/AttitudeTracking-v0", nominal_inertia=(1e-300 * np.eye(3)).tolist())


def test_a_symlink_loop_output_is_one_line(tmp_path: Path) -> None:
    from etsc_envs.core.files import require_writable_file, require_writable_folder

    loop = tmp_path / "loop"
    loop.symlink_to(loop)
    for check in (require_writable_file, require_writable_folder):
        with pytest.raises(ValueError, match=r"--out cannot be written: .* symbolic link loop"):
            check(loop, "--out")


# ----------------------------------------------------------------------- properties (hypothesis)
hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**12), max_value=10**12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["psi", "factors", "z_x", "inf", "1e-9", "true", ""]),
)
VALUES = st.recursive(
    SCALARS,
    lambda children: st.one_of(
        st.lists(children, max_size=3), st.dictionaries(st.text(max_size=6), children, max_size=3)
    ),
    max_leaves=8,
)
KEYS = st.sampled_from([*SearchConfig.__dataclass_fields__, "colour"])


@settings(max_examples=60, deadline=None)
@given(changes=st.dictionaries(KEYS, VALUES, min_size=1, max_size=3))
def test_property_a_drawn_search_config_is_valid_or_one_line_naming_a_key(changes) -> None:
    try:
        config = config_from_dict({**GOOD, **changes})
    except ValueError as error:
        text = str(error)
        assert "\n" not in text and text.startswith("config key 'search"), text
    else:
        assert 1 <= config.scenarios <= MAX_SCENARIOS and config.population >= 2
        assert config.search and set(config.search) <= {
            "factors",
            "floor",
            "heartbeat",
            "exponent",
            "modulation",
        }

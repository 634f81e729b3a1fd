"""Learned-trigger files through the suite's one JSON reader: crafted files (short bias rows
the kernel would read past, NaN weights, a string flag, a file of another id) are refused with
one line naming the key, and any file drawn by hypothesis either loads and decides 0 or 1, or
is refused that way. CI runs this file also with ``NUMBA_BOUNDSCHECK=1``."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import gymnasium as gym
import numba
import numpy as np
import pytest

import etsc_envs
from etsc_envs.core.json_files import MAX_DEPTH
from etsc_envs.triggers.family import FamilyPoint, LearnedTrigger, Modulation

ENV_ID = "etsc/AttitudeTracking-v0"


def _valid() -> dict[str, Any]:
    """A learned file of 002 with a network on four observations (hidden 3 and 2)."""
    env = gym.make(ENV_ID)
    inputs = tuple(env.unwrapped.observation_names[:4])
    env.close()
    modulation = Modulation.zeros(inputs, np.zeros(4), np.ones(4), hidden=3)
    rng = np.random.default_rng(0)
    modulation = modulation.with_weights(rng.normal(size=modulation.weights.size))
    point = FamilyPoint(factors={"psi": 2.0}, heartbeat_instants=50, modulation=modulation)
    return LearnedTrigger(ENV_ID, "AttitudeTrackingTrigger", point).to_json()


VALID = _valid()


def _write(tmp_path: Path, data: Any, name: str = "learned.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def _decide(path: Path, env_id: str = ENV_ID) -> int:
    """The first decision of the file's trigger on a short episode of ``env_id``."""
    env = gym.make(env_id, horizon_s=0.2)
    policy = etsc_envs.load_policy(str(path), env)
    observation, _ = env.reset(seed=0)
    action, _ = policy.predict(observation)
    env.close()
    return int(np.asarray(action).ravel()[0])


def _mutated(path: tuple[str, ...], value: Any) -> dict[str, Any]:
    data = copy.deepcopy(VALID)
    place = data
    for key in path[:-1]:
        place = place[key]
    place[path[-1]] = value
    return data


MODULATION = ("point", "modulation")


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        ((*MODULATION, "b2"), [[], []], "key 'point.modulation.b2' must be an array"),
        ((*MODULATION, "b2"), [0.1], "key 'point.modulation.w2' must be an array of shape (1, 3)"),
        ((*MODULATION, "w1"), [[0.0] * 4] * 2 + [[0.0] * 3], "rows at depth 1 have lengths"),
        ((*MODULATION, "b1"), [float("nan")] * 3, "point.modulation.b1' must be an array"),
        ((*MODULATION, "b3"), [1e400, 0.0, 0.0], "point.modulation.b3"),
        ((*MODULATION, "scale"), [1.0, 1.0, 0.0, 1.0], "point.modulation.scale' must hold"),
        ((*MODULATION, "inputs"), ["z_x", 3, "a", "b"], "point.modulation.inputs[1]"),
        (("point", "first_instant"), "false", "key 'point.first_instant' must be true or false"),
        (("point", "exponent"), True, "key 'point.exponent' must be a number"),
        (("point", "heartbeat_instants"), "200", "key 'point.heartbeat_instants'"),
        (("point", "colour"), 1, "key 'point': unknown keys ['colour']"),
        (("point",), [1, 2], "key 'point' must be a mapping"),
        (("point", "factors", "psi"), 0.0, "key 'point.factors.psi' must be a finite number > 0"),
        (("point", "factors", "pi"), 1.0, "are not factors of AttitudeTrackingTrigger"),
        (("keywords",), {"nu": 1.0}, "key 'keywords': unknown keys ['nu']"),
        (("keywords",), ["psi"], "key 'keywords' must be a mapping"),
        (("colour",), "red", "the top level: unknown keys ['colour']"),
        (("env_id",), "etsc/InnerFormation-v0", "key 'family' must be one of"),
        (("version",), True, "key 'version'"),
    ],
)
def test_a_crafted_file_is_refused_with_one_line_naming_the_key(
    tmp_path: Path, path: tuple[str, ...], value: Any, message: str
) -> None:
    file = _write(tmp_path, _mutated(path, value))
    with pytest.raises(ValueError) as error:
        LearnedTrigger.load(file)
    text = str(error.value)
    assert "\n" not in text and text.startswith(f"learned:{file}: "), text
    assert message in text, text


def test_a_file_nested_past_the_bound_is_one_line(tmp_path: Path) -> None:
    for depth in (MAX_DEPTH + 1, 100_000):
        file = tmp_path / f"deep{depth}.json"
        file.write_text("[" * depth + "]" * depth)
        with pytest.raises(ValueError, match=f"nests deeper than {MAX_DEPTH}"):
            LearnedTrigger.load(file)


def test_a_file_of_another_id_of_the_same_family_is_refused(tmp_path: Path) -> None:
    """001's central and PettingZoo ids share a family; a file learned on one is not silently
    run on the other."""
    central = LearnedTrigger(
        "etsc/ClusterContainmentCentral-v0", "ClusterContainmentTrigger", FamilyPoint()
    )
    file = _write(tmp_path, central.to_json())
    parallel = etsc_envs.make_parallel("etsc/ClusterContainment-v0")
    with pytest.raises(ValueError, match="is 'etsc/ClusterContainmentCentral-v0'; it cannot"):
        etsc_envs.load_policy(str(file), parallel)


def test_a_valid_modulated_file_decides_within_its_arrays(tmp_path: Path) -> None:
    """Under NUMBA_BOUNDSCHECK=1 (CI) an index past any array raises IndexError here."""
    assert _decide(_write(tmp_path, VALID)) in (0, 1)


@pytest.mark.skipif(not numba.config.BOUNDSCHECK, reason="NUMBA_BOUNDSCHECK=1 only (CI runs it)")
def test_boundscheck_catches_a_network_shorter_than_its_widths() -> None:
    """The case the reader refuses, forced past it: with bounds checks compiled in, the kernel
    raises instead of reading past its parameters (so the CI step can fail)."""
    learned = LearnedTrigger.from_json(VALID)
    modulation = learned.point.modulation
    assert modulation is not None
    object.__setattr__(modulation, "b2", np.zeros((len(modulation.b2), 0)))
    env = gym.make(ENV_ID, horizon_s=0.2)
    policy = learned.policy_for(env)
    observation, _ = env.reset(seed=0)
    with pytest.raises(IndexError):
        policy.predict(observation)


# ----------------------------------------------------------------------- properties (hypothesis)
hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["inf", "false", "z_x", "psi", ""]),
)
VALUES = st.recursive(
    SCALARS,
    lambda children: st.one_of(
        st.lists(children, max_size=4), st.dictionaries(st.text(max_size=4), children, max_size=3)
    ),
    max_leaves=12,
)
KEY_PATHS = st.sampled_from(
    [
        ("format",),
        ("version",),
        ("env_id",),
        ("family",),
        ("keywords",),
        ("search",),
        ("extra",),
        ("point",),
        ("point", "factors"),
        ("point", "factors", "psi"),
        ("point", "floor_instants"),
        ("point", "heartbeat_instants"),
        ("point", "exponent"),
        ("point", "first_instant"),
        ("point", "modulation"),
        *((*MODULATION, name) for name in ("inputs", "mean", "scale", "w1", "b1", "w2", "b2")),
        (*MODULATION, "w3"),
        (*MODULATION, "b3"),
    ]
)


@settings(max_examples=60, deadline=None)
@given(changes=st.lists(st.tuples(KEY_PATHS, VALUES), min_size=1, max_size=3))
def test_property_a_drawn_file_loads_and_decides_or_is_refused_naming_a_key(
    tmp_path_factory: pytest.TempPathFactory, changes: list[tuple[tuple[str, ...], Any]]
) -> None:
    data = copy.deepcopy(VALID)
    for path, value in changes:
        place = data
        for key in path[:-1]:
            if not isinstance(place.get(key), dict):
                place[key] = {}
            place = place[key]
        place[path[-1]] = value
    file = _write(tmp_path_factory.mktemp("drawn"), data)
    try:
        decision = _decide(file)
    except ValueError as error:
        text = str(error)
        assert "\n" not in text and text.startswith(f"learned:{file}: "), text
        assert "key '" in text or "the top level" in text or "observations here" in text, text
    else:
        assert decision in (0, 1)


def _decision_set(point: Any) -> dict[str, Any]:
    return {
        "format": "etsc-envs/decision-set",
        "version": 2,
        "env_id": ENV_ID,
        "shield_multiple": None,
        "actions": [
            {"kind": "hold", "instants": 4},
            {"kind": "trigger", "rule": "paper", "point": point, "cap": 64, "send_first": False},
        ],
    }


@pytest.mark.parametrize(
    ("point", "message"),
    [
        ({"modulation": {**VALID["point"]["modulation"], "b2": [[], [], []]}}, "modulation.b2"),
        ({"modulation": {**VALID["point"]["modulation"], "b1": [float("nan")] * 3}}, "b1"),
        ({"first_instant": "false"}, "first_instant"),
        ([1], "point"),
    ],
)
def test_decision_set_files_go_through_the_same_reader(tmp_path: Path, point, message) -> None:
    """A decision set beside a model is read by the one reader: its family points are checked
    to the last array, and a file nested past the bound is refused, each in one line."""
    from etsc_envs.decisions import DecisionSet

    model = tmp_path / "model.zip"
    good = tmp_path / "model_decisions.json"
    good.write_text(json.dumps(_decision_set({"factors": {"psi": 2.0}})))
    assert DecisionSet.load(model).n_actions == 2
    good.write_text(json.dumps(_decision_set(point)))
    with pytest.raises(ValueError, match=message) as caught:
        DecisionSet.load(model)
    assert "\n" not in str(caught.value)
    good.write_text("[" * (MAX_DEPTH + 5) + "]" * (MAX_DEPTH + 5))
    with pytest.raises(ValueError, match="nests deeper"):
        DecisionSet.load(model)

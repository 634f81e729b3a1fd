"""The parametric trigger families (:mod:`etsc_envs.triggers.family`): each named point takes
the decisions of its stand-alone policy, scenario for scenario and record for record, in the
compiled loop; the kernel's decisions equal ``predict``'s; a learned file round-trips.

The fast run shortens each horizon (``HORIZON_S``); ``-m slow`` runs the full horizons."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from etsc_envs.evaluation.batch import run_batch
from etsc_envs.triggers import (
    AsteroidOrbitKeepingTrigger,
    AttitudeTrackingTrigger,
    ClusterContainmentTrigger,
    InnerFormationErrorTimeTrigger,
    InnerFormationTrigger,
    OrbitAttitudeTrigger,
)
from etsc_envs.triggers.base import (
    ClockTrigger,
    HeartbeatPolicy,
    channel_heartbeat_trigger_class,
    floored_trigger_class,
    instants_seconds,
)
from etsc_envs.triggers.family import (
    Coupling,
    FamilyPoint,
    LearnedTrigger,
    Modulation,
    family_trigger_class,
    scaled_thresholds,
)

PAPER_CLASSES = {
    "etsc/AttitudeTracking-v0": AttitudeTrackingTrigger,
    "etsc/InnerFormation-v0": InnerFormationTrigger,
    "etsc/OrbitAttitudeTracking-v0": OrbitAttitudeTrigger,
    "etsc/ClusterContainmentCentral-v0": ClusterContainmentTrigger,
    "etsc/AsteroidOrbitKeeping-v0": AsteroidOrbitKeepingTrigger,
}

HORIZON_S = {
    "etsc/AttitudeTracking-v0": 10.0,
    "etsc/InnerFormation-v0": 10.0,
    "etsc/OrbitAttitudeTracking-v0": 10.0,
    "etsc/ClusterContainmentCentral-v0": 100.0,
    "etsc/AsteroidOrbitKeeping-v0": 3000.0,
}
"""Shortened horizons of the fast run (s); long enough for every point to transmit."""

RAISED = {
    "etsc/AttitudeTracking-v0": {"psi": 8.0},
    "etsc/InnerFormation-v0": {"pi": 6.0},
    "etsc/OrbitAttitudeTracking-v0": {
        "gamma1": 4.0,
        "gamma2": 4.0,
        "a1": 3.1 / 0.6,
        "a2": 3.5 / 0.8,
    },
    "etsc/ClusterContainmentCentral-v0": {"c": 1.65},
    "etsc/AsteroidOrbitKeeping-v0": {"alpha": 1.0 / 16.0},
}
"""Each id's raised (or lowered) thresholds: its headline's factors."""

SEEDS = {"paper": ([0], {"randomize": False}), "randomized": ([11, 12], {"randomize": True})}


def _records(env_id: str, policy_builder, scenario: str, full: bool) -> list[dict]:
    seeds, env_args = SEEDS[scenario]
    env_args = dict(env_args)
    if not full:
        env_args["horizon_s"] = HORIZON_S[env_id]
    env = gym.make(env_id, **env_args)
    loop = env.unwrapped
    policy = policy_builder(
        env.observation_space, env.action_space, loop.observation_names, loop.sampling_period_s
    )
    env.close()
    records = run_batch(env_id, policy, seeds, env_args)
    for record in records:
        record.pop("wall_time_s")
    return records


def _points(env_id: str) -> dict[str, tuple[FamilyPoint, object]]:
    """Named points of ``env_id``'s family and a builder of each one's stand-alone policy."""
    paper = PAPER_CLASSES[env_id]
    family = family_trigger_class(paper)
    raised = RAISED[env_id]
    thresholds = scaled_thresholds(paper, raised)
    points = {
        "paper": (FamilyPoint(), lambda o, a, n, t: paper(o, a, n)),
        "clock 7": (
            FamilyPoint.clock(7),
            lambda o, a, n, t: ClockTrigger(o, a, n, every=7, sampling_period_s=t),
        ),
        "heartbeat 40": (
            FamilyPoint(factors=raised, heartbeat_instants=40),
            lambda o, a, n, t: channel_heartbeat_trigger_class(paper)(
                o, a, n, heartbeat_s=instants_seconds(40, t), **thresholds
            ),
        ),
        "floor 16": (
            FamilyPoint(factors=raised, floor_instants=16),
            lambda o, a, n, t: floored_trigger_class(paper)(
                o, a, n, floor_s=instants_seconds(16, t), **thresholds
            ),
        ),
        "raised": (FamilyPoint(factors=raised), lambda o, a, n, t: paper(o, a, n, **thresholds)),
    }
    if env_id == "etsc/InnerFormation-v0":
        points["error time x6"] = (
            FamilyPoint(factors={"pi": 6.0}, exponent=1.0),
            lambda o, a, n, t: InnerFormationErrorTimeTrigger(
                o, a, n, **{f"area{i}": 6.0 * v for i, v in enumerate(_areas(), start=1)}
            ),
        )
    if env_id == "etsc/AttitudeTracking-v0":
        points["rule with heartbeat 384 (HeartbeatPolicy)"] = (
            FamilyPoint(factors={"psi": 8.0}, heartbeat_instants=384, first_instant=True),
            lambda o, a, n, t: HeartbeatPolicy(paper(o, a, n, psi=0.8), 384),
        )
    assert family  # the class is built once per paper
    return points


def _areas() -> np.ndarray:
    from etsc_envs.triggers.inner_formation import default_error_time_thresholds

    return default_error_time_thresholds()


def _family(env_id: str, point: FamilyPoint):
    family = family_trigger_class(PAPER_CLASSES[env_id])
    return lambda o, a, n, t: family(o, a, n, point, t)


def _check_points(env_id: str, full: bool) -> None:
    for name, (point, stand_alone) in _points(env_id).items():
        for scenario in SEEDS:
            expected = _records(env_id, stand_alone, scenario, full)
            got = _records(env_id, _family(env_id, point), scenario, full)
            assert got == expected, f"{env_id}: the family at {name!r} ({scenario})"
            assert sum(record["transmissions"] for record in got) > 0, name


@pytest.mark.parametrize("env_id", sorted(PAPER_CLASSES))
def test_named_points_equal_their_stand_alone_policies(env_id: str) -> None:
    _check_points(env_id, full=False)


@pytest.mark.slow
@pytest.mark.parametrize("env_id", sorted(PAPER_CLASSES))
def test_named_points_equal_their_stand_alone_policies_full_horizon(env_id: str) -> None:
    _check_points(env_id, full=True)


def _modulated_point(env: gym.Env, seed: int) -> FamilyPoint:
    names = env.unwrapped.observation_names
    inputs = tuple(names[:4])
    rng = np.random.default_rng(seed)
    modulation = Modulation.zeros(inputs, np.zeros(4), np.ones(4), hidden=3)
    modulation = modulation.with_weights(rng.normal(size=modulation.weights.size))
    return FamilyPoint(
        factors={"psi": 4.0},
        floor_instants=3,
        heartbeat_instants=200,
        exponent=0.5,
        modulation=modulation,
    )


def test_kernel_decisions_equal_predict_and_the_python_model() -> None:
    """With a network, the compiled loop's decisions (run_batch over the rule) are predict's
    step by step, and predict's are the module docstring's formula evaluated in NumPy."""
    env_id = "etsc/AttitudeTracking-v0"
    env = gym.make(env_id, horizon_s=2.0, randomize=True)
    loop = env.unwrapped
    point = _modulated_point(env, 0)
    trigger = family_trigger_class(AttitudeTrackingTrigger)(
        env.observation_space,
        env.action_space,
        loop.observation_names,
        point,
        loop.sampling_period_s,
    )
    obs, _ = env.reset(seed=5)
    names = loop.observation_names
    m = point.modulation
    period = loop.sampling_period_s
    sent = 0
    done = False
    while not done:
        action, _ = trigger.predict(obs)
        x = (obs[[names.index(n) for n in m.inputs]].astype(np.float64) - m.mean) / m.scale
        g = np.clip(m.w3 @ np.tanh(m.w2 @ np.tanh(m.w1 @ x + m.b1) + m.b2) + m.b3, -3, 3)
        tau = float(obs[names.index("time_since_transmission_s")])
        statistic = float(obs[names.index("trigger_statistic")])
        expected = tau >= (200 - 0.5) * period * math.exp(g[2]) or (
            tau >= (3 - 0.5) * period * math.exp(g[1])
            and statistic * tau**0.5 > 0.4 * math.exp(g[0]) * 0.05**0.5
        )
        assert bool(action) == expected
        sent += int(action)
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    assert sent == info["transmissions"] > 0
    predicted = info["transmissions"]
    batch = run_batch(env_id, trigger, [5], {"horizon_s": 2.0, "randomize": True})
    assert batch[0]["transmissions"] == predicted


def _cluster_points(seed: int) -> tuple[Modulation, FamilyPoint]:
    """A random network per channel on 001's followers (each its own ‖s‖ and ‖e_s‖) and a
    plain point to put it in."""
    rng = np.random.default_rng(seed)
    per_channel = Modulation.zeros(
        ("s_norm{channel}", "e_s_norm{channel}"),
        np.array([0.02, 0.0]),
        np.array([0.002, 0.001]),  # the followers' ‖s‖ differ by about 0.004
        hidden=3,
    )
    per_channel = per_channel.with_weights(rng.normal(size=per_channel.weights.size))
    point = FamilyPoint(factors={"c": 1.5}, floor_instants=2, heartbeat_instants=300)
    return per_channel, point


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_network_per_channel_is_each_channels_own_network(seed: int) -> None:
    """Channel c of a per-channel network decides as a network for every channel reading
    channel c's inputs would (the same weights), on the observations of a cluster episode; an
    agent of the PettingZoo form, reading its own unsuffixed observation, decides as its
    channel of the central form."""
    import etsc_envs

    env = gym.make("etsc/ClusterContainmentCentral-v0", horizon_s=30.0, randomize=True)
    loop = env.unwrapped
    names = loop.observation_names
    family = family_trigger_class(ClusterContainmentTrigger)
    per_channel, point = _cluster_points(seed)

    def trigger(modulation: Modulation, space=env.observation_space, action=env.action_space):
        return family(space, action, names, replace(point, modulation=modulation), 0.01)

    own = trigger(per_channel)
    shared = [
        trigger(replace(per_channel, inputs=per_channel.channel_inputs(c)))
        for c in range(loop.n_channels)
    ]
    parallel = etsc_envs.make_parallel("etsc/ClusterContainment-v0")
    agent_names = parallel.unwrapped.agent_observation_names
    agent = family(
        parallel.observation_space(parallel.possible_agents[0]),
        parallel.action_space(parallel.possible_agents[0]),
        agent_names,
        replace(point, modulation=per_channel),
        0.01,
    )
    agent_columns = [
        [names.index(f"{name}_{c}") for name in agent_names] for c in range(loop.n_channels)
    ]
    obs, _ = env.reset(seed=3)
    decisions = np.zeros(loop.n_channels, dtype=int)
    differs = 0
    for _ in range(3000):
        action, _ = own.predict(obs)
        for c, network in enumerate(shared):
            assert action[c] == network.predict(obs)[0][c]
            assert action[c] == agent.predict(obs[agent_columns[c]])[0]
        decisions += action
        differs += int(len({tuple(network.predict(obs)[0]) for network in shared}) > 1)
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            break
    assert decisions.sum() > 0 and differs > 0, "the channels' networks must disagree somewhere"
    parallel.close()
    env.close()


def test_a_network_per_channel_round_trips_and_is_refused_where_it_cannot_act(tmp_path) -> None:
    """A per-channel network survives its learned file; braces other than {channel}, inputs
    a layout lacks and a per-channel network on a coupled point are refused by name."""
    per_channel, point = _cluster_points(0)
    point = replace(point, modulation=per_channel)
    path = tmp_path / "learned.json"
    family = "ClusterContainmentTrigger"
    LearnedTrigger("etsc/ClusterContainmentCentral-v0", family, point).save(path)
    loaded = LearnedTrigger.load(path)
    assert loaded.point.modulation.per_channel and loaded.point.to_json() == point.to_json()
    with pytest.raises(ValueError, match=r"'s_norm\{agent\}' holds braces other than"):
        replace(per_channel, inputs=("s_norm{agent}", "e_s_norm{channel}"))
    env = gym.make("etsc/InnerFormation-v0")
    names = env.unwrapped.observation_names
    make = family_trigger_class(InnerFormationTrigger)
    network = Modulation.zeros(("r{channel}",), np.zeros(1), np.ones(1), hidden=2)
    with pytest.raises(ValueError, match=r"modulation.inputs \['r_0', 'r_1', 'r_2'\] are not"):
        make(env.observation_space, env.action_space, names, FamilyPoint(modulation=network), 0.1)
    axes = Modulation.zeros(("time_since_transmission_s{channel}",), np.zeros(1), np.ones(1), 2)
    coupled = FamilyPoint(modulation=axes, coupling=Coupling((1.0, 1.0, 1.0)))
    with pytest.raises(ValueError, match="cannot steer a coupled point"):
        make(env.observation_space, env.action_space, names, coupled, 0.1)


def _coupled_trigger(env: gym.Env, point: FamilyPoint):
    loop = env.unwrapped
    family = family_trigger_class(InnerFormationTrigger)
    names = loop.observation_names
    return family(env.observation_space, env.action_space, names, point, loop.sampling_period_s)


COUPLED = {
    "004 norm, all channels": ("etsc/InnerFormation-v0", Coupling((1.0, 0.7, 1.3))),
    "004 kappa 0.4, own channel": (
        "etsc/InnerFormation-v0",
        Coupling((1.0, 0.7, 1.3), 0.4, refresh_all=False),
    ),
    "000 torque and force": ("etsc/OrbitAttitudeTracking-v0", Coupling((0.8, 1.5))),
}
COUPLED_START = {
    "etsc/InnerFormation-v0": {"factors": {"pi": 2.0}, "exponent": 0.5},
    "etsc/OrbitAttitudeTracking-v0": {"factors": {"gamma1": 2.0, "gamma2": 2.0}},
}


def _coupled_trigger(env: gym.Env, point: FamilyPoint):
    loop = env.unwrapped
    family = family_trigger_class(PAPER_CLASSES[env.spec.id])
    names = loop.observation_names
    return family(env.observation_space, env.action_space, names, point, loop.sampling_period_s)


@pytest.mark.parametrize("case", sorted(COUPLED))
def test_a_coupled_point_decides_by_its_formula(case: str) -> None:
    """A coupled point on 004's three axes and 000's two conditions: predict's decisions are
    the module docstring's formula in NumPy (channel c's condition Σ_j (w_cj r_cj)² + κ Σ_d≠c
    Σ_j (w_dj r_dj)² > 1 past the floor, a heartbeat or the first instant; every channel
    where refresh_all and one sends), and the compiled loop sends what predict sends."""
    env_id, coupling = COUPLED[case]
    env = gym.make(env_id, horizon_s=HORIZON_S[env_id], randomize=True)
    point = FamilyPoint(
        floor_instants=3,
        heartbeat_instants=300,
        first_instant=True,
        coupling=coupling,
        **COUPLED_START[env_id],
    )
    trigger = _coupled_trigger(env, point)
    inner = trigger.inner
    names = env.unwrapped.observation_names
    times = [i for i, name in enumerate(names) if name.startswith("time_since_transmission_s")]
    period = env.unwrapped.sampling_period_s
    weights, kappa, exponent = np.array(coupling.weights), coupling.strength, point.exponent
    indices = np.asarray(inner.rule_indices, dtype=np.int64)
    parameters = np.asarray(inner.rule_parameters, dtype=np.float64)
    obs, _ = env.reset(seed=3)
    sent, by_formula, done = 0, 0, False
    while not done:
        action, _ = trigger.predict(obs)
        statistic, threshold = np.empty(weights.size), np.empty(weights.size)
        type(inner).condition(obs, indices, parameters, statistic, threshold)
        tau = obs[times].astype(np.float64)
        per_condition = np.repeat(tau, weights.size // tau.size)
        ratios = statistic * per_condition**exponent / (threshold * 0.05**exponent)
        own = ((weights * ratios) ** 2).reshape(tau.size, -1).sum(axis=1)
        formula = (tau >= 2.5 * period) & (own + kappa * (own.sum() - own) > 1.0)
        clock = (tau < 0.5 * period) | (tau >= 299.5 * period)
        expected = formula | clock
        if coupling.refresh_all and expected.any():
            expected[:] = True
        assert np.atleast_1d(action).tolist() == expected.astype(int).tolist()
        by_formula += int((formula & ~clock).any())
        sent += int(np.sum(action))
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    assert by_formula > 5 and sent == info["transmissions"]
    env_args = {"horizon_s": HORIZON_S[env_id], "randomize": True}
    assert run_batch(env_id, trigger, [3], env_args)[0]["transmissions"] == sent


def test_the_paper_rule_is_a_coupled_point() -> None:
    """004 at unit weights, κ = 0, each axis sent alone: the paper's rule, record for record."""
    env_id = "etsc/InnerFormation-v0"
    coupled = FamilyPoint(coupling=Coupling((1.0, 1.0, 1.0), 0.0, refresh_all=False))
    paper = PAPER_CLASSES[env_id]
    for scenario in SEEDS:
        expected = _records(env_id, lambda o, a, n, t: paper(o, a, n), scenario, full=False)
        assert _records(env_id, _family(env_id, coupled), scenario, full=False) == expected


def test_a_coupled_point_needs_one_weight_per_condition() -> None:
    env = gym.make("etsc/InnerFormation-v0")
    with pytest.raises(ValueError, match=r"weights must hold one weight per condition \(3\)"):
        _coupled_trigger(env, FamilyPoint(coupling=Coupling((1.0, 1.0))))
    for bad, message in [
        ({"weights": [1.0, 0.0]}, r"point.coupling.weights' must hold one weight > 0"),
        ({"weights": [1.0], "strength": 1.5}, r"point.coupling.strength"),
        ({"weights": [1.0], "refresh_all": 1}, r"point.coupling.refresh_all"),
        ({"strength": 0.5}, r"point.coupling"),
    ]:
        with pytest.raises(ValueError, match=message):
            FamilyPoint.from_json({"coupling": bad})


def test_learned_file_round_trips_and_refuses_other_files(tmp_path) -> None:
    env = gym.make("etsc/AttitudeTracking-v0")
    point = _modulated_point(env, 1)
    learned = LearnedTrigger("etsc/AttitudeTracking-v0", "AttitudeTrackingTrigger", point)
    path = tmp_path / "learned.json"
    learned.save(path)
    loaded = LearnedTrigger.load(path)
    assert loaded.point.to_json() == point.to_json()
    assert "coupling" not in json.loads(path.read_text())["point"]  # older files stay as they are
    coupled = FamilyPoint(factors={"pi": 2.0}, coupling=Coupling((1.0, 0.5, 2.0), 0.25, False))
    LearnedTrigger("etsc/InnerFormation-v0", "InnerFormationTrigger", coupled).save(path)
    assert LearnedTrigger.load(path).point == coupled
    assert json.loads(path.read_text())["format"] == "etsc-envs/learned-trigger"
    path.write_text('{"format": "something else"}')
    with pytest.raises(ValueError, match=r"learned:.*format"):
        LearnedTrigger.load(path)


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        ({"factors": {"psi": -1.0}}, "factors.psi"),
        ({"floor_instants": -1.0}, "floor_instants"),
        ({"heartbeat_instants": 0.5}, "heartbeat_instants"),
        ({"exponent": float("nan")}, "exponent"),
        ({"coupling": (1.0, 1.0)}, "coupling must be a Coupling"),
    ],
)
def test_bad_points_are_refused_naming_the_argument(keywords, message) -> None:
    with pytest.raises(ValueError, match=message):
        FamilyPoint(**keywords)


def test_factors_outside_the_papers_bounds_are_refused() -> None:
    with pytest.raises(ValueError, match=r"factors\.a1"):
        scaled_thresholds(OrbitAttitudeTrigger, {"a1": 6.0})
    with pytest.raises(ValueError, match="allowed"):
        scaled_thresholds(AttitudeTrackingTrigger, {"pi": 2.0})


def test_load_policy_runs_a_learned_file_from_the_package(tmp_path) -> None:
    """``etsc_envs.load_policy`` (the installed package's loader) gives the family's trigger,
    the same decisions as building it directly; other files are refused naming the path."""
    import etsc_envs

    env = gym.make("etsc/AttitudeTracking-v0", horizon_s=1.0)
    point = FamilyPoint(factors={"psi": 4.0}, heartbeat_instants=100, first_instant=True)
    path = tmp_path / "learned.json"
    LearnedTrigger("etsc/AttitudeTracking-v0", "AttitudeTrackingTrigger", point).save(path)
    policy = etsc_envs.load_policy(str(path), env)
    direct = _family("etsc/AttitudeTracking-v0", point)(
        env.observation_space,
        env.action_space,
        env.unwrapped.observation_names,
        env.unwrapped.sampling_period_s,
    )
    obs, _ = env.reset(seed=3)
    for _ in range(300):
        action, _ = policy.predict(obs)
        assert action == direct.predict(obs)[0]
        obs, *_ = env.step(action)
    with pytest.raises(ValueError, match="path"):
        etsc_envs.load_policy(str(tmp_path / "model.pkl"), env)


def test_a_policy_arg_replaces_one_component_of_a_learned_theta(tmp_path) -> None:
    """``--policy learned:PATH --policy-arg heartbeat_instants=H`` runs the file's θ with that
    component replaced: the records of the file written with it; bad keys get one line."""
    from baselines.evaluate import evaluate

    point = FamilyPoint(factors={"psi": 8.0}, heartbeat_instants=384, exponent=0.3)
    original, changed = tmp_path / "original.json", tmp_path / "changed.json"
    family = ("etsc/AttitudeTracking-v0", "AttitudeTrackingTrigger")
    LearnedTrigger(*family, point).save(original)
    LearnedTrigger(*family, FamilyPoint(factors={"psi": 8.0}, exponent=0.3)).save(changed)
    episode = {"env_args": {"horizon_s": 3.0}, "episodes": 2, "processes": 1}
    replaced = evaluate(
        family[0], f"learned:{original}", policy_args={"heartbeat_instants": math.inf}, **episode
    )
    written = evaluate(family[0], f"learned:{changed}", **episode)
    kept = evaluate(family[0], f"learned:{original}", **episode)
    for key in ("transmissions", "mean_cost"):
        assert [e[key] for e in replaced["episodes"]] == [e[key] for e in written["episodes"]]
    assert replaced["mean"]["transmissions"] != kept["mean"]["transmissions"]
    with pytest.raises(ValueError, match="--policy-arg psi: a learned trigger takes floor_"):
        evaluate(family[0], f"learned:{original}", policy_args={"psi": 2.0}, **episode)
    with pytest.raises(ValueError, match="--policy-arg heartbeat_instants must be >= 1"):
        evaluate(family[0], f"learned:{original}", policy_args={"heartbeat_instants": 0}, **episode)


HAND_FILES = sorted(Path(__file__).parents[1].glob("models/*_hand.json"))


def test_every_id_ships_its_hand_point() -> None:
    import etsc_envs

    assert sorted(path.name.removesuffix("_hand.json") for path in HAND_FILES) == sorted(
        env_id.removeprefix("etsc/")
        for env_id in [*etsc_envs.ENV_IDS, *etsc_envs.PETTINGZOO_ENV_IDS]
    )


@pytest.mark.parametrize("path", HAND_FILES, ids=lambda path: path.name)
def test_a_hand_point_is_where_its_search_starts_and_names_its_menu(path: Path) -> None:
    """``models/<id>_hand.json`` is a point of the id's family (it loads with ``learned:``),
    says what menu it was chosen from, and is the start of each of the id's search configs: the
    learned trigger is searched from the hand point it is judged against (a coupled search
    from the hand point as the coupled point of its own geometry: unit weights, κ = 0, each
    channel sent alone). A search of the network alone starts at the shipped learned trigger,
    the best plain point, whose zero network leaves it unchanged."""
    import yaml

    import etsc_envs
    from agents.search.cma_es import load_config

    hand = LearnedTrigger.load(path)
    assert not hand.search and hand.hand["chosen_on"] == "validation"
    assert hand.hand["menu"] and all(isinstance(label, str) for label in hand.hand["menu"])
    configs = [
        config
        for config in Path(__file__).parents[1].glob("configs/search/*.yaml")
        if yaml.safe_load(config.read_text())["env_id"] == hand.env_id
    ]
    assert configs
    learned = path.with_name(path.name.replace("_hand.json", "_learned.json"))
    for config in configs:
        search = load_config(config)
        start = search.start
        if search.search == ("modulation",):
            assert start.to_json() == LearnedTrigger.load(learned).point.to_json(), config
            continue
        coupling = start.coupling
        if coupling is not None:
            assert set(coupling.weights) == {1.0} and coupling.strength == 0.0, config
            assert not coupling.refresh_all, config
            start = replace(start, coupling=None)
        assert start.to_json() == hand.point.to_json(), config
    if hand.env_id in etsc_envs.ENV_IDS:
        env = gym.make(hand.env_id)
        policy = etsc_envs.load_policy(f"learned:{path}", env)
        obs, _ = env.reset(seed=0)
        action, _ = policy.predict(obs)
        assert env.action_space.contains(np.asarray(action, dtype=env.action_space.dtype))

"""Sweep configs (``configs/sweeps/*.yaml``): validation, grid points, trial names and the
training config of each trial. No Ray needed."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

pytest.importorskip("stable_baselines3")

from agents.judge.penalty_choice import PENALTY_KEYS
from agents.sweep.config import SweepConfig, load_sweep_config, sweep_config_from_dict

ROOT = Path(__file__).resolve().parents[1]
BASE = str(ROOT / "configs" / "train" / "attitude_tracking_ppo.yaml")


def sweep(tmp_path: Path, **keys: Any) -> dict[str, Any]:
    """A valid front over two penalties and two seeds, with ``keys`` replaced."""
    raw = {
        "base": BASE,
        "results_dir": str(tmp_path / "sweep"),
        "kind": "front",
        "grid": {"env_kwargs.transmission_penalty": [0.05, 100.0], "seed": [1, 2]},
    }
    raw.update(keys)
    return raw


def test_a_grid_gives_every_combination_with_a_readable_name(tmp_path: Path) -> None:
    config = sweep_config_from_dict(sweep(tmp_path))
    points = config.grid_points()
    assert len(points) == 4
    names = [config.trial_name(point) for point in points]
    assert names[0] == "transmission_penalty=0.05,seed=1"
    assert names[-1] == "transmission_penalty=100,seed=2"
    assert len(set(names)) == 4
    assert config.trial_folder(names[0]) == tmp_path / "sweep" / "trials" / names[0]


def test_keys_that_share_their_last_part_are_named_in_full(tmp_path: Path) -> None:
    grid = {"env_kwargs.horizon_s": [1.0], "evaluation_env_kwargs.horizon_s": [2.0]}
    config = sweep_config_from_dict(sweep(tmp_path, grid=grid))
    (point,) = config.grid_points()
    assert config.trial_name(point) == "env_kwargs.horizon_s=1,evaluation_env_kwargs.horizon_s=2"


def test_a_trial_config_sets_its_values_and_keeps_the_rest_of_the_base(tmp_path: Path) -> None:
    overrides = {"total_timesteps": 4096, "hyperparameters.n_epochs": 2}
    config = sweep_config_from_dict(sweep(tmp_path, overrides=overrides))
    point = config.grid_points()[1]
    trial = config.trial_config(point, tmp_path / "trial")
    base = yaml.safe_load(Path(BASE).read_text(encoding="utf-8"))
    assert trial.env_kwargs["transmission_penalty"] == 0.05
    assert trial.env_kwargs["cost_scale"] == base["env_kwargs"]["cost_scale"]
    assert trial.seed == 2
    assert trial.total_timesteps == 4096
    assert trial.hyperparameters["n_epochs"] == 2
    assert trial.hyperparameters["learning_rate"] == base["hyperparameters"]["learning_rate"]
    assert trial.out_dir == str(tmp_path / "trial")


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ({"grids": {"seed": [1]}}, "unknown sweep key(s) ['grids']"),
        ({"grid": {"seeds": [1, 2]}}, "unknown training-config key 'seeds'"),
        ({"grid": {"seed.x": [1, 2]}}, "unknown training-config key 'seed.x'"),
        ({"overrides": {"total_steps": 10}}, "unknown training-config key 'total_steps'"),
        ({"grid": {"hyperparameters.n_step": [64]}}, "['n_step'] are not PPO arguments"),
        ({"grid": {}}, "'grid' and 'search' are both empty"),
        ({"grid": {"seed": []}}, "'grid.seed' must be a non-empty list"),
        ({"grid": {"seed": [1, 1]}}, "'grid.seed' repeats a value"),
        ({"grid": {"seed": [-1]}}, "config key 'seed' must be a non-negative integer"),
        ({"kind": "pareto"}, "'kind' must be one of ['front', 'search']"),
        ({"base": "missing.yaml"}, "sweep key 'base': cannot read 'missing.yaml'"),
        ({"cpus_per_trial": 0}, "'cpus_per_trial' must be a positive number"),
    ],
)
def test_bad_sweep_configs_are_refused_naming_the_key(
    tmp_path: Path, keys: dict[str, Any], message: str
) -> None:
    with pytest.raises(ValueError) as error:
        sweep_config_from_dict(sweep(tmp_path, **keys))
    assert message in str(error.value)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize(
    "keys",
    [
        {"scheduler": "asha", "metric": "cost_ratio", "mode": "min"},
        {"search": {"hyperparameters.learning_rate": {"loguniform": [1.0e-5, 1.0e-3]}}},
        {"num_samples": 3},
    ],
)
def test_a_front_is_never_stopped_early_or_sampled(tmp_path: Path, keys: dict[str, Any]) -> None:
    with pytest.raises(ValueError, match="never stopped early or sampled"):
        sweep_config_from_dict(sweep(tmp_path, **keys))


def test_a_search_may_use_asha_and_optuna_with_an_objective(tmp_path: Path) -> None:
    search = {
        "hyperparameters.learning_rate": {"loguniform": [1.0e-5, 3.0e-3]},
        "hyperparameters.n_epochs": {"randint": [1, 10]},
        "env_kwargs.transmission_penalty": {"choice": [10.0, 100.0]},
    }
    keys = {"kind": "search", "grid": {}, "search": search, "num_samples": 8}
    objective = {"scheduler": "asha", "search_algorithm": "optuna", "metric": "cost_ratio"}
    config = sweep_config_from_dict(sweep(tmp_path, **keys, **objective, mode="min"))
    assert config.num_samples == 8
    base = yaml.safe_load(Path(BASE).read_text())
    assert config.search_start == {
        "hyperparameters.learning_rate": base["hyperparameters"]["learning_rate"],
        "hyperparameters.n_epochs": base["hyperparameters"]["n_epochs"],
        "env_kwargs.transmission_penalty": base["env_kwargs"]["transmission_penalty"],
    }
    assert (
        config.trial_name(
            {
                "hyperparameters.learning_rate": 1.234567e-4,
                "hyperparameters.n_epochs": 3,
                "env_kwargs.transmission_penalty": 10.0,
            },
            "abc_00001",
        )
        == "learning_rate=0.000123457,n_epochs=3,transmission_penalty=10,trial=abc_00001"
    )
    with pytest.raises(ValueError, match="'metric' must be one of"):
        sweep_config_from_dict(sweep(tmp_path, **keys, scheduler="asha"))
    with pytest.raises(ValueError, match="'grid' must be empty with search_algorithm"):
        rate = {"hyperparameters.learning_rate": search["hyperparameters.learning_rate"]}
        sweep_config_from_dict(sweep(tmp_path, kind="search", **objective, mode="min", search=rate))
    with pytest.raises(ValueError, match="'cost_ratio' comes from the training run's evalu"):
        never = {"evaluation_every": 0}
        sweep_config_from_dict(sweep(tmp_path, **keys, **objective, mode="min", overrides=never))
    with pytest.raises(ValueError, match=r"must be \[low, high\] with low < high"):
        bad = {"hyperparameters.learning_rate": {"uniform": [1.0, 0.5]}}
        sweep_config_from_dict(sweep(tmp_path, kind="search", search=bad))
    with pytest.raises(ValueError, match="needs low > 0"):
        bad = {"hyperparameters.learning_rate": {"loguniform": [0.0, 0.5]}}
        sweep_config_from_dict(sweep(tmp_path, kind="search", search=bad))


RATE = {"hyperparameters.learning_rate": {"loguniform": [1.0e-5, 1.0e-3]}}


def test_a_search_trial_of_several_seeds_trains_each_in_its_own_folder(tmp_path: Path) -> None:
    config = sweep_config_from_dict(
        sweep(tmp_path, kind="search", grid={}, search=RATE, trial_seeds=[3, 7])
    )
    assert config.trial_seeds == (3, 7)
    runs = config.trial_runs({"hyperparameters.learning_rate": 1.0e-4}, tmp_path / "t")
    assert [folder for _, folder in runs] == [tmp_path / "t" / "seed=3", tmp_path / "t" / "seed=7"]
    for (values, folder), seed in zip(runs, (3, 7), strict=True):
        trial = config.trial_config(values, folder)
        assert (trial.seed, trial.hyperparameters["learning_rate"]) == (seed, 1.0e-4)
    plain = sweep_config_from_dict(sweep(tmp_path, kind="search", grid={}, search=RATE))
    assert plain.trial_runs({"seed": 1}, tmp_path / "t") == [({"seed": 1}, tmp_path / "t")]


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ({"trial_seeds": [1]}, "'trial_seeds' must be a list of two or more distinct integer"),
        ({"trial_seeds": [1, 1]}, "'trial_seeds' must be a list of two or more distinct integer"),
        ({"trial_seeds": [1, 2.5]}, "'trial_seeds' must be a list of two or more distinct"),
        ({"trial_seeds": 3}, "'trial_seeds' must be a list of two or more distinct integer"),
        ({"kind": "front", "search": {}, "grid": {"seed": [1]}}, "not with kind 'front'"),
        ({"scheduler": "asha", "metric": "cost_ratio", "mode": "min"}, "not with scheduler 'asha'"),
        ({"grid": {"seed": [1, 2]}}, "not with 'seed' swept in 'grid' or 'search'"),
    ],
)
def test_bad_trial_seeds_are_refused_in_one_line(
    tmp_path: Path, keys: dict[str, Any], message: str
) -> None:
    raw = {"kind": "search", "grid": {}, "search": RATE, "trial_seeds": [0, 1], **keys}
    with pytest.raises(ValueError) as error:
        sweep_config_from_dict(sweep(tmp_path, **raw))
    assert message in str(error.value) and "\n" not in str(error.value)


SHIPPED_SWEEPS = sorted(
    path for path in (ROOT / "configs" / "sweeps").glob("*.yaml") if path.name != "tiny.yaml"
)
SHIPPED_FRONTS = [
    path for path in SHIPPED_SWEEPS if yaml.safe_load(path.read_text())["kind"] == "front"
]
SHIPPED_TUNINGS = [path for path in SHIPPED_SWEEPS if path not in SHIPPED_FRONTS]


def _penalties(config: SweepConfig) -> list[float]:
    key = "penalty" if config.learner == "search" else "env_kwargs.transmission_penalty"
    return config.grid[key]


@pytest.mark.parametrize(
    ("search", "overrides", "shown"),
    [
        ({"hyperparameters.learning_rate": {"loguniform": [1.0e-5, 1.0e-3]}}, {}, "0.00208478"),
        ({"hyperparameters.n_epochs": {"randint": [1, 5]}}, {}, "n_epochs = 5"),
        ({"hyperparameters.gamma": {"choice": [0.9, 0.99]}}, {}, "gamma = 0.995"),
        (
            {"hyperparameters.learning_rate": {"uniform": [1.0e-4, 1.0e-3]}},
            {"hyperparameters.learning_rate": 2.0e-3},
            "learning_rate = 0.002",
        ),
    ],
)
def test_an_optuna_search_must_start_inside_its_distributions(
    tmp_path: Path, search: dict[str, Any], overrides: dict[str, Any], shown: str
) -> None:
    """Optuna's first trial is the base config with the overrides: a searched key whose start
    lies outside its distribution is refused in one line naming it."""
    keys = {"kind": "search", "grid": {}, "search": search, "overrides": overrides}
    objective = {"search_algorithm": "optuna", "metric": "cost_ratio", "mode": "min"}
    with pytest.raises(ValueError) as error:
        sweep_config_from_dict(sweep(tmp_path, **keys, **objective))
    message = str(error.value)
    assert f"'search.{next(iter(search))}'" in message and shown in message
    assert "\n" not in message
    assert sweep_config_from_dict(sweep(tmp_path, kind="search", grid={}, search=search))


@pytest.mark.parametrize("path", SHIPPED_FRONTS, ids=lambda path: path.stem)
def test_a_shipped_front_crosses_penalties_with_three_seeds(path: Path) -> None:
    """Every shipped sweep is a front: at least two penalties (a refinement between two
    penalties of a wider front, e.g. a larger search budget near the headline's rate) and three
    seeds; or a chosen configuration (no penalty in the grid, or the one penalty another front
    chose, kept in the grid for ``agents.judge.penalty_choice``) over five seeds or more."""
    config = load_sweep_config(path)
    assert config.kind == "front"
    assert Path(config.results_dir).parts[-3:-1] == ("runs", "sweeps")
    if config.learner == "oracle":  # one clairvoyant search per scenario of the first 16
        assert config.grid == {"scenario": list(range(16))}
        return
    if set(config.grid) == {"seed"} or len(_penalties(config)) == 1:
        assert len(config.grid["seed"]) >= 5
        return
    assert len(_penalties(config)) >= 2
    assert len(config.grid["seed"]) >= 3
    assert Path(config.results_dir).parts[-3:-1] == ("runs", "sweeps")


@pytest.mark.parametrize("path", SHIPPED_TUNINGS, ids=lambda path: path.stem)
def test_a_shipped_tuning_maximises_the_kept_checkpoints_validation_return(path: Path) -> None:
    """A shipped hyperparameter search scores each trial on the validation set alone, by the
    return of the checkpoint the run keeps, with Optuna drawing the values; the front that
    trains with the tuned values shares its base config."""
    config = load_sweep_config(path)
    assert (config.kind, config.search_algorithm) == ("search", "optuna")
    assert (config.metric, config.mode) == ("best_validation_return", "max")
    # at least 8 trained runs: trials, or trials x their training seeds (trial_seeds)
    assert config.search and config.num_samples * len(config.trial_seeds or (0,)) >= 8
    assert config.trial_mapping({}, Path("trial"))["evaluation_every"] > 0
    front = path.with_name(path.name.replace("_tuning", "_front"))
    assert front in SHIPPED_FRONTS
    assert yaml.safe_load(front.read_text())["base"] == yaml.safe_load(path.read_text())["base"]


def swept_penalties(grid: dict) -> list | None:
    """A front's penalties, under whichever of the swept keys that are λ it sweeps
    (:data:`agents.judge.penalty_choice.PENALTY_KEYS`)."""
    return next((grid[key] for key in PENALTY_KEYS if key in grid), None)


def test_the_shipped_fronts_are_of_the_suites_ids() -> None:
    """Each shipped front trains or searches an id of the suite (one front per id, method and
    penalty set at most: no two shipped fronts share a base config, algorithm, hyperparameters
    and swept penalties; a chosen configuration's ten search seeds, a training front's chosen
    penalty trained again, or its seeds at hyperparameters tuned since, sit beside the front
    that chose the penalty)."""
    import etsc_envs

    every_id = set(etsc_envs.ENV_IDS) | set(etsc_envs.PETTINGZOO_ENV_IDS)
    configs = [load_sweep_config(path) for path in SHIPPED_FRONTS]
    assert configs and {config.base["env_id"] for config in configs} <= every_id
    bases = [yaml.safe_load(path.read_text())["base"] for path in SHIPPED_FRONTS]
    methods = [
        (
            base,
            config.base.get("algorithm"),
            str(swept_penalties(config.grid)),
            json.dumps(config.base.get("hyperparameters"), sort_keys=True),
        )
        for base, config in zip(bases, configs, strict=True)
    ]
    assert len(set(methods)) == len(methods)


def test_the_package_and_the_tools_do_not_import_ray() -> None:
    code = (
        "import sys, etsc_envs, agents.train.training, agents.judge.pareto, agents.judge.results\n"
        "import agents.sweep.runner, agents.search.cma_es\n"
        "assert 'ray' not in sys.modules, 'ray was imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)


def test_without_ray_the_sweep_command_says_which_extra_to_install() -> None:
    code = (
        "import sys\n"
        "sys.modules['ray'] = None  # as if Ray were not installed\n"
        "from agents.sweep.runner import main\n"
        "main(['--config', 'configs/sweeps/tiny.yaml'])\n"
    )
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 2
    assert (
        run.stderr.strip()
        .splitlines()[-1]
        .endswith('Ray Tune is not installed: pip install -e ".[train,sweep]"')
    )


def test_model_paths_are_made_absolute_for_trials_that_run_elsewhere(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    model = ROOT / "models" / "AttitudeTracking-v0_ppo.zip"
    (tmp_path / "stage1.zip").write_bytes(model.read_bytes())
    monkeypatch.chdir(tmp_path)
    grid = {"init_from": ["stage1.zip"], "seed": [1]}
    config = sweep_config_from_dict(sweep(tmp_path, grid=grid, results_dir="out"))
    trial = config.trial_config(config.grid_points()[0], config.trial_folder("t"))
    assert trial.init_from == str(tmp_path / "stage1.zip")
    assert config.results_dir == str(tmp_path / "out")


def test_a_start_from_key_is_refused_in_a_base_and_in_overrides(tmp_path: Path) -> None:
    base = yaml.safe_load(
        (ROOT / "configs" / "train" / "attitude_tracking_self_triggered.yaml").read_text()
    )
    base_path = tmp_path / "base.yaml"
    base_path.write_text(yaml.safe_dump({**base, "start_from": {"steps": 8}}))
    with pytest.raises(ValueError, match="config key 'start_from' was removed"):
        sweep_config_from_dict(sweep(tmp_path, base=str(base_path)))
    overrides = {"start_from.steps": 8}
    with pytest.raises(ValueError, match=r"unknown training-config key 'start_from\.steps'"):
        sweep_config_from_dict(sweep(tmp_path, overrides=overrides))

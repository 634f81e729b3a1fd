"""Accuracy against transmissions: the paper's trigger, periodic sampling and learned triggers.

    python -m agents.pareto ENV_ID [--model PATH ...] [--sweep RESULTS_DIR ...]
                                   [--env-arg k=v ...] [--seed S] [--out DIR]
                                   [--reuse PARETO_JSON]

Runs one episode of the paper scenario (``randomize`` off) for every point of three curves and
plots ``mean_cost`` (the per-step accuracy cost the reward penalises) against the number of
transmissions:

* the paper's trigger over a sweep of its threshold (:data:`PAPER_SWEEPS`: Ψ for 002, γ1 and
  γ2 for 000, c for 001, α for 003, Π for 004), the paper's own value included;
* periodic transmission every ``k`` sampling instants (:func:`periodic_sweep`);
* each ``--model`` (an SB3 zip, with its observation statistics beside it if it has them),
  typically one per transmission penalty λ, and the model of every finished trial of each
  ``--sweep`` (the results folder of ``python -m agents.sweep``: a front in one option).

Writes ``pareto.json`` and ``pareto.png`` into ``DIR`` (default
``results/pareto/<env name>``). ``--reuse PARETO_JSON`` keeps the paper and periodic curves of
an earlier run (same id, kwargs and seed) and runs only the models.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt

import etsc_envs  # noqa: F401  (registers the ids)
from agents.evaluation import episode_summary
from agents.sweep_results import sweep_models
from baselines.cli import EpisodeSetup, episode_setup, limit_torch_threads, parse_assignments
from baselines.plotting import save
from baselines.triggers.asteroid import PAPER_ALPHA
from baselines.triggers.attitude_tracking import PAPER_PSI
from baselines.triggers.inner_formation import default_thresholds
from baselines.triggers.orbit_attitude import PAPER_GAMMA

SCALES = (0.25, 0.5, 1.0, 2.0, 4.0)
"""Multiples of the paper's threshold swept where the threshold is a free positive number."""


def _scaled(**paper_values: float) -> list[dict[str, float]]:
    return [{name: scale * value for name, value in paper_values.items()} for scale in SCALES]


def _inner_formation_sweep() -> list[dict[str, float]]:
    pi1, pi2, pi3 = default_thresholds()
    return _scaled(pi1=pi1, pi2=pi2, pi3=pi3)


def _cluster_sweep() -> list[dict[str, float]]:
    return [{"c": c} for c in (0.2, 0.4, 0.6, 0.8, 0.95)]


PAPER_SWEEPS = {
    "etsc/AttitudeTracking-v0": lambda: _scaled(psi=PAPER_PSI),
    "etsc/OrbitAttitudeTracking-v0": lambda: [
        {"gamma1": scale * PAPER_GAMMA[0], "gamma2": scale * PAPER_GAMMA[1]}
        for scale in (0.3, 1.0, 3.0, 10.0, 30.0, 100.0)
    ],
    "etsc/ClusterContainmentCentral-v0": _cluster_sweep,
    "etsc/ClusterContainment-v0": _cluster_sweep,
    "etsc/AsteroidOrbitKeeping-v0": lambda: _scaled(alpha=PAPER_ALPHA),
    "etsc/InnerFormation-v0": _inner_formation_sweep,
}
"""Id → the paper-trigger arguments of each point (the paper's own values among them)."""

PERIODIC_EVERY = (1, 2, 5, 10, 20, 50, 100, 200)
"""Sampling instants between periodic transmissions."""

PERIODIC_EVERY_BY_ID = {
    # A burst fires for 50 s = 200 sampling instants, so requests closer than that all land
    # inside a running burst: periodic bursts start 200 instants apart at the closest.
    "etsc/AsteroidOrbitKeeping-v0": (200, 240, 300, 400, 600, 800, 1200, 1600),
    # The paper's trigger updates a follower every few seconds (hundreds of 0.01-s instants).
    "etsc/ClusterContainmentCentral-v0": (10, 50, 100, 200, 500, 1000, 2000, 5000),
    "etsc/ClusterContainment-v0": (10, 50, 100, 200, 500, 1000, 2000, 5000),
}
"""Ids whose periodic sweep differs from :data:`PERIODIC_EVERY`."""


def periodic_sweep(env_id: str) -> tuple[int, ...]:
    """Sampling instants between periodic transmissions swept for ``env_id``."""
    return PERIODIC_EVERY_BY_ID.get(env_id, PERIODIC_EVERY)


def run_point(
    setup: EpisodeSetup, policy_spec: str, policy_args: dict[str, Any], seed: int
) -> dict[str, Any]:
    """One paper-scenario episode of a policy: its compared metrics and what it was."""
    policy = setup.make_policy(policy_spec, policy_args)
    record, _ = setup.run(setup.env, policy, seed=seed)
    return {"policy": policy_spec, "args": policy_args, **episode_summary(record)}


def pareto(
    env_id: str,
    models: list[str],
    env_kwargs: dict[str, Any],
    seed: int = 0,
    reuse: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """The three curves of the module docstring for ``env_id``; with ``reuse`` (an earlier
    result of the same id, kwargs and seed), its paper and periodic curves are kept and only
    the models run."""
    if env_id not in PAPER_SWEEPS:
        raise ValueError(f"no Pareto sweep for {env_id}; known: {sorted(PAPER_SWEEPS)}")
    if reuse is not None:
        earlier = (reuse.get("env"), reuse.get("env_kwargs"), reuse.get("seed"))
        if earlier != (env_id, env_kwargs, seed):
            raise ValueError(
                f"--reuse: that result is of (env, env_kwargs, seed) = {earlier}, "
                f"not {(env_id, env_kwargs, seed)}"
            )
    setup = episode_setup(env_id, {**env_kwargs, "randomize": False})
    if reuse is None:
        curves = {
            "paper": [run_point(setup, "paper", args, seed) for args in PAPER_SWEEPS[env_id]()],
            "periodic": [
                run_point(setup, "periodic", {"every": every}, seed)
                for every in periodic_sweep(env_id)
            ],
        }
    else:
        curves = {name: reuse["curves"][name] for name in ("paper", "periodic")}
    curves["learned"] = [run_point(setup, f"sb3:{path}", {}, seed) for path in models]
    setup.env.close()
    return {"env": env_id, "env_kwargs": env_kwargs, "seed": seed, "curves": curves}


def plot(result: dict[str, Any], path: Path) -> None:
    """``mean_cost`` against transmissions, one marker style per curve (log-log axes; the cost
    axis is linear near zero when some cost is exactly zero)."""
    figure, axes = plt.subplots(figsize=(6.0, 4.5))
    styles = {"paper": "o-", "periodic": "s--", "learned": "*"}
    labels = {
        "paper": "paper trigger (threshold sweep)",
        "periodic": "periodic",
        "learned": "learned",
    }
    for name, points in result["curves"].items():
        finished = [p for p in points if p["failure"] is None and p["transmissions"] > 0]
        if not finished:
            continue
        finished.sort(key=lambda point: point["transmissions"])
        axes.plot(
            [point["transmissions"] for point in finished],
            [point["mean_cost"] for point in finished],
            styles[name],
            label=labels[name],
            markersize=10 if name == "learned" else 5,
        )
    axes.set_xscale("log")
    costs = [
        point["mean_cost"]
        for points in result["curves"].values()
        for point in points
        if point["failure"] is None
    ]
    positive = [cost for cost in costs if cost > 0]
    if positive and len(positive) == len(costs):
        axes.set_yscale("log")
    else:  # a zero cost (paper 003 inside its shell) has no place on a log axis
        axes.set_yscale("symlog", linthresh=min(positive, default=1.0))
        axes.set_ylim(bottom=0.0)
    axes.set_xlabel("transmissions per episode")
    axes.set_ylabel("mean_cost (accuracy cost per step)")
    axes.set_title(f"{result['env']}: accuracy against communication", fontsize=10)
    axes.legend()
    axes.grid(True, which="both", alpha=0.3)
    save(figure, path)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.pareto",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("env_id", choices=sorted(PAPER_SWEEPS))
    parser.add_argument(
        "--model", action="append", default=[], help="an SB3 zip of a learned trigger (repeatable)"
    )
    parser.add_argument(
        "--sweep",
        action="append",
        default=[],
        metavar="RESULTS_DIR",
        help="add the model of every finished trial of a sweep (agents.sweep; repeatable)",
    )
    parser.add_argument("--env-arg", action="append", metavar="K=V", help="env keyword")
    parser.add_argument("--seed", type=int, default=0, help="reset seed of every episode")
    parser.add_argument("--out", type=Path, help="output folder")
    parser.add_argument(
        "--reuse",
        type=Path,
        metavar="PARETO_JSON",
        help="keep the paper and periodic curves of an earlier run; run only the models",
    )
    args = parser.parse_args(argv)
    limit_torch_threads()
    try:
        env_kwargs = parse_assignments(args.env_arg, "--env-arg")
        reuse = json.loads(args.reuse.read_text(encoding="utf-8")) if args.reuse else None
        models = args.model + sweep_models(args.sweep, args.env_id)
        result = pareto(args.env_id, models, env_kwargs, args.seed, reuse)
    except ValueError as error:
        parser.error(str(error))
    out_dir = args.out or Path("results") / "pareto" / args.env_id.split("/")[-1]
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "pareto.json").write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    plot(result, out_dir / "pareto.png")
    for name, points in result["curves"].items():
        for point in points:
            print(
                f"{name:9s} {json.dumps(point['args']):48s} mean_cost {point['mean_cost']:.4g}  "
                f"transmissions {point['transmissions']}"
            )
    print(f"wrote {out_dir / 'pareto.json'} and {out_dir / 'pareto.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

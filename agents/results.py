"""A learned trigger against the paper's trigger and periodic sampling: the rows of
``docs/results.md``.

    python -m agents.results ENV_ID (--model PATH | --sweep RESULTS_DIR)
                                    [--randomized-episodes K] [--env-arg k=v ...] [--out DIR]

On the paper scenario (``randomize`` off, seed 0) it runs the paper's trigger, the learned
model and periodic transmission at the learned model's rate (every ``k`` sampling instants on
every channel, ``k`` chosen so that the transmission counts match); on ``K`` randomized
scenarios (seeds :data:`RANDOMIZED_SEED` onwards, which training never draws: training envs
draw every reset from one generator seeded with the config's seed) it runs the paper's trigger
and the learned model. For each it records ``mean_cost``, the transmissions and the paper's own
metrics (:data:`PAPER_KEYS`), and it judges the goal: ``mean_cost`` at most
:data:`COST_TOLERANCE` above the paper trigger's with at least :data:`TRANSMISSION_SAVING`
fewer transmissions.

Writes ``results.json`` into ``DIR`` (default ``results/<env name>``) and prints the table as
Markdown. With ``--sweep`` (the results folder of ``python -m agents.sweep``) it compares the
model of every finished trial, each into ``DIR/<trial name>/results.json``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import etsc_envs
from agents.sweep_results import finished_trials
from baselines.cli import episode_setup, limit_torch_threads, parse_assignments
from baselines.episodes import to_jsonable
from baselines.evaluate import evaluate

RANDOMIZED_SEED = 10_000
"""First seed of the randomized evaluation scenarios."""

COST_TOLERANCE = 0.05
"""The learned trigger may be this much less accurate (relative ``mean_cost``)."""

TRANSMISSION_SAVING = 0.30
"""...and must transmit at least this much less than the paper's trigger."""

PAPER_KEYS = {
    "etsc/AttitudeTracking-v0": ("mean_input_norm",),
    "etsc/OrbitAttitudeTracking-v0": ("ss_att_err_deg", "ss_pos_err_m", "settle_pos_s"),
    "etsc/ClusterContainmentCentral-v0": ("converge_time_s", "final_containment_err"),
    "etsc/ClusterContainment-v0": ("converge_time_s", "final_containment_err"),
    "etsc/AsteroidOrbitKeeping-v0": ("min_radius_m", "max_radius_m", "delta_v_mps"),
    "etsc/InnerFormation-v0": ("ss_pos_err_m", "ss_pos_est_err_m"),
}
"""Id → the paper's own metrics shown beside ``mean_cost`` and the transmissions."""

ROW_KEYS = ("mean_cost", "transmissions", "failures")


def channel_count(env_id: str, env_args: dict[str, Any]) -> int:
    """Transmit channels of ``env_id`` (agents of a PettingZoo id)."""
    setup = episode_setup(env_id, env_args)
    env = setup.env
    loop = env.loop if env_id in etsc_envs.PETTINGZOO_ENV_IDS else env.unwrapped
    count = int(loop.n_channels)
    env.close()
    return count


def equal_rate_period(steps: float, transmissions: float, channels: int) -> int:
    """Sampling instants between periodic transmissions (on all ``channels``) that give about
    ``transmissions`` in ``steps`` instants."""
    if transmissions <= 0:
        return max(int(steps), 1)
    return max(round(channels * steps / transmissions), 1)


def _row(result: dict[str, Any], keys: tuple[str, ...]) -> dict[str, Any]:
    mean = result["mean"]
    return {key: mean.get(key) for key in (*ROW_KEYS, *keys)}


def meets_goal(learned: dict[str, Any], paper: dict[str, Any]) -> dict[str, Any]:
    """The goal's two ratios (learned over paper; ``None`` where the paper's value is 0) and
    whether the goal holds: ``mean_cost`` at most ``1 + COST_TOLERANCE`` times the paper's (so
    exactly 0 where the paper's is 0), at most ``1 - TRANSMISSION_SAVING`` times its
    transmissions, and no failed episode."""
    paper_cost, paper_sent = paper["mean_cost"], paper["transmissions"]
    met = (
        learned["mean_cost"] <= paper_cost * (1.0 + COST_TOLERANCE)
        and learned["transmissions"] <= paper_sent * (1.0 - TRANSMISSION_SAVING)
        and not learned["failures"]
    )
    return {
        "cost_ratio": learned["mean_cost"] / paper_cost if paper_cost else None,
        "transmission_ratio": learned["transmissions"] / paper_sent if paper_sent else None,
        "met": bool(met),
    }


def compare(
    env_id: str, model: str, env_args: dict[str, Any], randomized_episodes: int
) -> dict[str, Any]:
    """The comparison of the module docstring, as a JSON-ready mapping."""
    keys = PAPER_KEYS.get(env_id, ())
    paper_scenario = {**env_args, "randomize": False}
    learned_spec = f"sb3:{model}"
    paper = evaluate(env_id, "paper", env_args=paper_scenario)
    learned = evaluate(env_id, learned_spec, env_args=paper_scenario)
    every = equal_rate_period(
        learned["mean"]["steps"],
        learned["mean"]["transmissions"],
        channel_count(env_id, paper_scenario),
    )
    periodic = evaluate(env_id, "periodic", policy_args={"every": every}, env_args=paper_scenario)
    result: dict[str, Any] = {
        "env": env_id,
        "model": model,
        "env_args": env_args,
        "paper_scenario": {
            "paper": _row(paper, keys),
            "learned": _row(learned, keys),
            f"periodic every {every}": _row(periodic, keys),
        },
    }
    result["paper_scenario"]["goal"] = meets_goal(
        result["paper_scenario"]["learned"], result["paper_scenario"]["paper"]
    )
    if randomized_episodes > 0:
        randomized = {**env_args, "randomize": True}
        runs = {
            name: evaluate(
                env_id,
                spec,
                env_args=randomized,
                episodes=randomized_episodes,
                seed=RANDOMIZED_SEED,
            )
            for name, spec in (("paper", "paper"), ("learned", learned_spec))
        }
        rows = {name: _row(run, keys) for name, run in runs.items()}
        rows["goal"] = meets_goal(rows["learned"], rows["paper"])
        rows["episodes"] = randomized_episodes
        rows["seeds"] = [RANDOMIZED_SEED, RANDOMIZED_SEED + randomized_episodes - 1]
        result["randomized"] = rows
    return to_jsonable(result)


def markdown(result: dict[str, Any]) -> str:
    """The comparison as Markdown tables (one per scenario set)."""
    lines = []
    for section in ("paper_scenario", "randomized"):
        if section not in result:
            continue
        rows = {name: row for name, row in result[section].items() if isinstance(row, dict)}
        rows.pop("goal")
        columns = list(next(iter(rows.values())))
        title = (
            "Paper scenario"
            if section == "paper_scenario"
            else f"Randomized scenarios ({result[section]['episodes']} episodes, mean)"
        )
        lines += [f"**{title}**", "", "| trigger | " + " | ".join(columns) + " |"]
        lines.append("|---" * (len(columns) + 1) + "|")
        for name, row in rows.items():
            lines.append(f"| {name} | " + " | ".join(_cell(row[c]) for c in columns) + " |")
        goal = result[section]["goal"]
        lines += ["", _goal_sentence(goal), ""]
    return "\n".join(lines)


def _cell(value: Any) -> str:
    if value is None:
        return "—"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def _goal_sentence(goal: dict[str, Any]) -> str:
    cost, sent = goal["cost_ratio"], goal["transmission_ratio"]
    verdict = "met" if goal["met"] else "not met"
    return (
        f"Learned / paper: mean_cost ×{_cell(cost)}, transmissions ×{_cell(sent)} — goal "
        f"(≤ ×{1 + COST_TOLERANCE:.2f} cost, ≤ ×{1 - TRANSMISSION_SAVING:.2f} transmissions, "
        f"no failure) {verdict}."
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.results",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("env_id", help="a Gymnasium or PettingZoo id of etsc-envs")
    learned = parser.add_mutually_exclusive_group(required=True)
    learned.add_argument("--model", help="the SB3 zip of the learned trigger")
    learned.add_argument(
        "--sweep",
        metavar="RESULTS_DIR",
        help="compare the model of every finished trial of a sweep (agents.sweep), each "
        "written to DIR/<trial name>/results.json",
    )
    parser.add_argument("--randomized-episodes", type=int, default=5, metavar="K")
    parser.add_argument("--env-arg", action="append", metavar="K=V", help="environment kwarg")
    parser.add_argument("--out", help="output folder (default results/<env name>)")
    args = parser.parse_args(argv)
    limit_torch_threads()
    if args.randomized_episodes < 0:
        parser.error(f"--randomized-episodes must be >= 0, got {args.randomized_episodes}")
    out_dir = Path(args.out or Path("results") / args.env_id.split("/")[-1])
    try:
        models = {out_dir: args.model}
        if args.sweep is not None:
            models = {
                out_dir / trial.name: str(trial.model)
                for trial in finished_trials(args.sweep, args.env_id)
            }
        env_args = parse_assignments(args.env_arg, "--env-arg")
        results = {
            folder: compare(args.env_id, model, env_args, args.randomized_episodes)
            for folder, model in models.items()
        }
    except (ValueError, TypeError) as error:
        parser.error(str(error))
    for folder, result in results.items():
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "results.json").write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
        print(markdown(result))
        print(f"wrote {folder / 'results.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

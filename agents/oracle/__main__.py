"""``python -m agents.oracle ENV_ID --trigger PATH --scenario I --out DIR``: the clairvoyant
schedules of one scenario (:mod:`agents.oracle.search`), written to ``DIR/oracle.json``.

Many scenarios run in parallel through the sweep runner (``learner: oracle``, e.g.
``python -m agents.sweep --config configs/sweeps/oracle_attitude_tracking.yaml --processes 2
--resume``); ``python -m agents.judge.oracle`` reads them back.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from agents.oracle.run import ORACLE_FILE, OracleConfig, oracle_config_from_dict, run_oracle
from etsc_envs.core.files import require_writable_folder

ARGUMENTS = {
    "env_id": "ENV_ID",
    "trigger": "--trigger",
    "scenarios": "--scenarios",
    "scenario": "--scenario",
    "budget_episodes": "--budget-episodes",
    "tail": "--tail",
    "tuning_episodes": "--tuning-episodes",
}
"""The command-line argument of each setting (:class:`~agents.oracle.run.OracleConfig`)."""


def argument_error(error: ValueError) -> str:
    """A setting's one-line error as the command line says it: naming the argument given
    (``--scenario``), not the config key (``key 'scenario'``)."""
    message = str(error)
    for key, argument in ARGUMENTS.items():
        message = message.replace(f"key '{key}'", argument)
    return message


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m agents.oracle", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("env_id", help="a single-agent id, e.g. etsc/AttitudeTracking-v0")
    parser.add_argument("--trigger", required=True, help="the learned trigger (learned.json)")
    parser.add_argument("--scenario", type=int, required=True, help="index in the set")
    parser.add_argument("--scenarios", default="test", help="validation or test (default test)")
    parser.add_argument(
        "--budget-episodes", type=float, default=100.0, help="instants to simulate, in episodes"
    )
    parser.add_argument(
        "--tail", default="none", help="screening window past the next send, or none (exact)"
    )
    parser.add_argument(
        "--tuning-episodes",
        type=float,
        default=0.0,
        help="start from the trigger's family point tuned on the scenario, in episodes (0: no)",
    )
    parser.add_argument("--out", required=True, help="folder of the record")
    parser.add_argument("--overwrite", action="store_true", help="replace a record in --out")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        config, out = _checked(args)
        record = run_oracle(config, out)
    except ValueError as error:
        print(f"error: {argument_error(error)}", file=sys.stderr)
        return 2
    for name in ("trigger", "fewest_transmissions", "least_cost"):
        part = record[name]
        print(f"{name}: {part['transmissions']} transmissions, mean cost {part['mean_cost']:.6g}")
    print(f"wrote {out / ORACLE_FILE} ({record['wall_time_s']:.0f} s)")
    return 0


def _checked(args: argparse.Namespace) -> tuple[OracleConfig, Path]:
    """The run's settings and output folder, every argument checked before any work."""
    if args.tail == "none":
        tail = None
    elif args.tail.isdigit():
        tail = int(args.tail)
    else:
        raise ValueError(f"--tail must be an integer >= 0 or none, got {args.tail!r}")
    config = oracle_config_from_dict(
        {
            "env_id": args.env_id.removeprefix("etsc_envs:"),
            "trigger": args.trigger.removeprefix("learned:"),
            "scenario": args.scenario,
            "scenarios": args.scenarios,
            "budget_episodes": args.budget_episodes,
            "tail": tail,
            "tuning_episodes": args.tuning_episodes,
        }
    )
    out = Path(args.out)
    require_writable_folder(out, "--out")
    if (out / ORACLE_FILE).exists() and not args.overwrite:
        raise ValueError(f"--out {out} already holds a record; choose another or --overwrite")
    return config, out


if __name__ == "__main__":
    raise SystemExit(main())

"""Paper 004 (Hao & Zhang, Appl Sci 2024): Theorem 1's bounds, the claims of section 4, Figs. 1-5.

The paper reports no numbers for its simulation, only bounds (Theorem 1, Remark 1) and claims
(Figs. 1-5). Its "paper" column therefore holds the bounds (8)-(10) evaluated for each run's
largest sampling error; rows with nothing to compare show "-". The runs: the continuous ESO of
eq. (14) (``always``), and the send-on-delta trigger of eqs. (4)-(6) at the default thresholds Π
sized by condition (7), at Π/2 and at 2Π.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from baselines.plotting import save
from baselines.reproductions.report import (
    Scenario,
    claim,
    metric_row,
    run_scenarios,
    scenario_instants,
)
from etsc_envs.evaluation.episodes import EpisodeTrace
from etsc_envs.papers import paper_numbered
from etsc_envs.triggers.inner_formation import AXES, default_thresholds

PAPER = "004"
TITLE = paper_numbered(PAPER).title
ENV_ID = "etsc/InnerFormation-v0"
SAMPLE_EVERY = 100  # steps between stored states for the figures (0.1 s)
EARLY_WINDOW_S = 5.0
LATE_WINDOW_S = 40.0


def _event_triggered(scale: float, label: str) -> Scenario:
    thresholds = scale * default_thresholds()
    args = tuple((f"pi{axis + 1}", float(thresholds[axis])) for axis in range(3))
    return Scenario(label, (), "paper", args)


CONTINUOUS = Scenario("continuous ESO, eq. (14)", (), "always")
EVENT = _event_triggered(1.0, "event-triggered, Pi from (7)")
EVENT_FINE = _event_triggered(0.5, "event-triggered, Pi/2")
EVENT_COARSE = _event_triggered(2.0, "event-triggered, 2 Pi")
SCENARIOS = (CONTINUOUS, EVENT, EVENT_FINE, EVENT_COARSE)
FIGURE_RUNS = (CONTINUOUS, EVENT)


def _bound_rows(scenario: Scenario, record: dict[str, Any]) -> list[dict]:
    """One row per axis: the steady errors beside the bounds (8)-(10) for that run."""
    rows = []
    for axis, name in enumerate(AXES):
        bounds = {
            "pos_est_err_m": record["bound_pos_est_m_per_axis"][axis],
            "vel_est_err_mps": record["bound_vel_est_mps_per_axis"][axis],
            "dist_est_err_mps2": record["bound_dist_est_mps2_per_axis"][axis],
        }
        ours = {
            "pos_est_err_m": record["ss_pos_est_err_m_per_axis"][axis],
            "vel_est_err_mps": record["ss_vel_est_err_mps_per_axis"][axis],
            "dist_est_err_mps2": record["ss_dist_est_err_mps2_per_axis"][axis],
        }
        axis_scenario = Scenario(
            f"{scenario.label}, {name}", scenario.env_args, scenario.policy, scenario.policy_args
        )
        rows.append(metric_row(axis_scenario, bounds, ours))
    return rows


def _event_rates(trace: EpisodeTrace, horizon_s: float) -> tuple[float, float]:
    """Transmissions per second (all axes) in the first 5 s and in the last 40 s."""
    times = np.asarray(trace.transmission_times_s)
    counts = [len(action.nonzero()[0]) for action in trace.transmission_actions]
    counts = np.asarray(counts, dtype=float)
    early = counts[times < EARLY_WINDOW_S].sum() / EARLY_WINDOW_S
    late = counts[times >= horizon_s - LATE_WINDOW_S].sum() / LATE_WINDOW_S
    return early, late


ERROR_BOUND_KEYS = (
    ("pos_est_err_m", "pos_est_m"),
    ("vel_est_err_mps", "vel_est_mps"),
    ("dist_est_err_mps2", "dist_est_mps2"),
)


def _errors_within(errors_of: dict[str, Any], bounds_of: dict[str, Any]) -> bool:
    """Whether every steady error of one run lies inside the (8)-(10) bounds of another."""
    return all(
        errors_of[f"ss_{error}_per_axis"][axis] <= bounds_of[f"bound_{bound}_per_axis"][axis]
        for error, bound in ERROR_BOUND_KEYS
        for axis in range(3)
    )


def _claims(records: dict[Scenario, dict], traces: dict[Scenario, EpisodeTrace]) -> list[dict]:
    event, continuous = records[EVENT], records[CONTINUOUS]
    found = []
    inside = _errors_within(event, event)
    found.append(
        claim(
            "Theorem 1: event-triggered steady errors inside (8)-(10)",
            inside,
            f"largest |r - zeta| {event['ss_pos_est_err_m']:.3g} m, "
            f"|rdot - psi| {event['ss_vel_est_err_mps']:.3g} m/s, "
            f"|h - phi| {event['ss_dist_est_err_mps2']:.3g} m/s^2",
        )
    )
    keeps = _errors_within(event, continuous)
    found.append(
        claim(
            "Remark 1: event-based sampling keeps the continuous ESO's bounds",
            keeps,
            f"event-triggered errors within the eq. (14) bounds; position error "
            f"{event['ss_pos_est_err_m']:.3g} m vs continuous "
            f"{continuous['ss_pos_est_err_m']:.3g} m",
        )
    )
    found.append(
        claim(
            "Fig. 2: a small fraction of instants transmit",
            event["transmission_rate"] < 0.05,
            f"{100 * event['transmission_rate']:.2f} % of axis-instants",
        )
    )
    early, late = _event_rates(traces[EVENT], event["sim_time_s"])
    found.append(
        claim(
            "Fig. 2: dense sampling early, sparse once settled",
            early > 2.0 * late,
            f"{early:.0f}/s in the first {EARLY_WINDOW_S:.0f} s, {late:.0f}/s in the "
            f"last {LATE_WINDOW_S:.0f} s",
        )
    )
    initial_offset = float(np.linalg.norm(traces[EVENT].sampled("position")[0]))
    found.append(
        claim(
            "Fig. 1 / Theorem 2: r is practically convergent",
            event["ss_pos_err_m"] < 0.2 * initial_offset and event["failure"] is None,
            f"|r| <= {event['ss_pos_err_m']:.3g} m over the last 20 % "
            f"(from {initial_offset:.3g} m)",
        )
    )
    fine, coarse = records[EVENT_FINE], records[EVENT_COARSE]
    found.append(
        claim(
            "A smaller Pi transmits more and estimates better",
            fine["transmissions"] > event["transmissions"] > coarse["transmissions"]
            and fine["ss_pos_est_err_m"] < event["ss_pos_est_err_m"] < coarse["ss_pos_est_err_m"],
            f"transmissions {fine['transmissions']} > {event['transmissions']} > "
            f"{coarse['transmissions']}, |r - zeta| {fine['ss_pos_est_err_m']:.3g} < "
            f"{event['ss_pos_est_err_m']:.3g} < {coarse['ss_pos_est_err_m']:.3g} m",
        )
    )
    zeno = all(
        record["min_interevent_s_per_axis"][axis] >= record["zeno_bound_s_per_axis"][axis]
        for record in (event, fine, coarse)
        for axis in range(3)
    )
    found.append(
        claim(
            "Theorem 3: inter-event times respect (A24)",
            zeno,
            "minimum per axis "
            + ", ".join(
                f"{m * 1e3:.0f} ms >= {b * 1e3:.2g} ms"
                for m, b in zip(
                    event["min_interevent_s_per_axis"], event["zeno_bound_s_per_axis"], strict=True
                )
            ),
        )
    )
    return found


def _figures(traces: dict[Scenario, EpisodeTrace], plot_dir: Path) -> list[str]:
    event, continuous = traces[EVENT], traces[CONTINUOUS]
    written = []
    time_s = event.sampled("time_s")
    figure, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for axis, name in enumerate(AXES):
        axes[axis].plot(time_s, 1e3 * event.sampled("position")[:, axis], label="event-triggered")
        axes[axis].plot(
            continuous.sampled("time_s"),
            1e3 * continuous.sampled("position")[:, axis],
            "--",
            label="continuous",
        )
        axes[axis].set_ylabel(f"r_{name} (mm)")
    axes[0].legend(fontsize=8)
    axes[0].set_title("Relative motion under output feedback (Fig. 1)")
    axes[-1].set_xlabel("time (s)")
    written.append(save(figure, plot_dir / "fig1_relative_motion.png"))

    figure, axes = plt.subplots(3, 1, figsize=(8, 6), sharex=True)
    for axis, name in enumerate(AXES):
        instants = event.channel_transmission_times(axis)
        axes[axis].plot(instants[1:], 1e3 * np.diff(instants), ".", markersize=2)
        axes[axis].set_ylabel(f"{name}: interval (ms)")
        axes[axis].set_yscale("log")
    axes[0].set_title("Transmissions per axis: inter-event intervals (Fig. 2)")
    axes[-1].set_xlabel("time (s)")
    written.append(save(figure, plot_dir / "fig2_transmissions.png"))

    signals = (
        ("position", "position_estimate", "m"),
        ("velocity", "velocity_estimate", "m/s"),
        ("lumped_disturbance", "disturbance_estimate", "m/s^2"),
    )
    for axis, name in enumerate(AXES):
        figure, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
        for row, (truth, estimate, unit) in enumerate(signals):
            axes[row].plot(time_s, event.sampled(truth)[:, axis], label=truth)
            axes[row].plot(time_s, event.sampled(estimate)[:, axis], "--", label=estimate)
            axes[row].set_ylabel(unit)
            axes[row].legend(fontsize=8, loc="upper right")
        axes[0].set_title(f"Estimation on the {name} axis, event-triggered (Fig. {3 + axis})")
        axes[-1].set_xlabel("time (s)")
        written.append(save(figure, plot_dir / f"fig{3 + axis}_estimation_{name}.png"))
    return [str(path) for path in written]


def planned_instants() -> int:
    """The sampling instants of the runs :func:`reproduce` makes (its progress's plan)."""
    return scenario_instants(ENV_ID, SCENARIOS)


def reproduce(plot_dir: Path | None = None, progress: bool = False) -> dict[str, Any]:
    """Run the four scenarios and compare with Theorem 1, Theorem 3 and section 4's claims."""
    records, traces = run_scenarios(ENV_ID, SCENARIOS, FIGURE_RUNS, SAMPLE_EVERY, f"paper {PAPER}")
    empty = {
        "transmissions": None,
        "transmission_rate": None,
        "ss_pos_err_m": None,
        "min_interevent_s": None,
    }
    tables = [
        {
            "name": "Theorem 1 - steady estimation errors (ours) and the bounds (8)-(10) (paper)",
            "rows": [row for s in SCENARIOS[:2] for row in _bound_rows(s, records[s])],
        },
        {
            "name": "Section 4 - transmissions and control (the paper gives no numbers)",
            "rows": [metric_row(s, empty, records[s]) for s in SCENARIOS],
        },
    ]
    result = {
        "paper": PAPER,
        "title": TITLE,
        "env": ENV_ID,
        "tables": tables,
        "claims": _claims(records, traces),
    }
    if plot_dir is not None:
        result["figures"] = _figures(traces, Path(plot_dir))
    return result

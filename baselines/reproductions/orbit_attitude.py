"""Paper 000 (Zhang, Biggs, Ye, Sun, IEEE TAES 2019): section IV's numbers and Figs. 1-12.

The paper reports bounds read off its figures, not tables: settling times (Figs. 5-6), steady
tracking errors (Figs. 5-8), steady observer errors (Figs. 1-4) and, qualitatively, the effect of
γ_j on transmissions and accuracy (Figs. 9-12). Its "paper" column therefore holds those bounds
(our value should be at or below them: the gap column then reads negative) or "-" where the paper
gives no number. Four runs of the event-triggered loop (trigger eq. (21), 300 s at 1 ms):

* Case 1, P1 — a1 = 0.6, a2 = 0.8, γ1 = 0.001, γ2 = 0.003 (Figs. 1, 2, 5, 6, 9, 11a);
* Case 1, P1 with the observer of ref. [19] (k2 = k4 = k5 = 0; Figs. 3, 4);
* Case 1, P2 (Figs. 7, 8);
* Case 2, P1 — γ1 = 0.1, γ2 = 0.2 (Figs. 10, 11b, 12).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np

from baselines.plotting import plot_interevent, save
from baselines.reproductions.report import (
    Scenario,
    claim,
    metric_row,
    scenario_instants,
    stages,
)
from etsc_envs.evaluation.episodes import instants_bar
from etsc_envs.evaluation.policy_specs import make_policy
from etsc_envs.orbit_attitude.closed_loop import disturbance_step
from etsc_envs.orbit_attitude.dynamics import thruster_outputs
from etsc_envs.papers import paper_numbered

PAPER = "000"
TITLE = paper_numbered(PAPER).title
ENV_ID = "etsc/OrbitAttitudeTracking-v0"
SAMPLE_EVERY = 20  # steps between stored states (20 ms)
QUIET_WINDOW_S = (150.0, 155.0)  # the interval the paper magnifies in Figs. 9-11
CASE2 = (("gamma1", 0.1), ("gamma2", 0.2))
CONVERGENCE_BAND = 0.02  # an ESO error has converged once it stays within 2 % of its peak

P1 = Scenario("Case 1, P1", (), "paper")
REF19 = Scenario("Case 1, P1, observer of ref. [19]", (("observer", "ref19"),), "paper")
P2 = Scenario("Case 1, P2", (("initial_point", "P2"),), "paper")
P1_CASE2 = Scenario("Case 2 (gamma1=0.1, gamma2=0.2), P1", (), "paper", CASE2)
SCENARIOS = (P1, REF19, P2, P1_CASE2)

TRACKING_BOUNDS = {  # section IV on Figs. 5-8 (P2: "not affected" by the initial point)
    "settle_att_s": 180.0,
    "settle_pos_s": 200.0,
    "ss_att_err_deg": 4e-4,
    "ss_angvel_err_degps": 2e-3,
    "ss_pos_err_m": 1e-5,
    "ss_vel_err_mps": 2e-6,
}
OBSERVER_BOUNDS = {  # section IV on Figs. 1-2 (ESO eq. 14) and Figs. 3-4 (ref. [19])
    P1: {"e1_rot": 1e-5, "e1_trans": 3e-6, "e2_rot_Nm": 1e-4, "e2_trans_N": 5e-5},
    REF19: {"e1_rot": 1e-5, "e1_trans": 5e-6, "e2_rot_Nm": 2e-4, "e2_trans_N": 1e-4},
}
OBSERVER_TIMES = {  # "Ẑ1 tracks S in 10 s ... Δd is reconstructed by Ẑ2 within 15 s"
    P1: {"e1_converged_s": 10.0, "e2_converged_s": 15.0},
    REF19: {"e1_converged_s": None, "e2_converged_s": None},  # "slightly longer"
}
DISTURBANCE_STEP_KEYS = ("dd_step_rot_Nm", "dd_step_trans_N")
"""Largest |Ξ·(jump of Δd)| at a transmission in the steady window: no observer tracks a step
before it sees it, so the steady max of |e2| is of this size whatever the observer
(docs/fidelity.md)."""
COMMUNICATION_KEYS = (
    "transmissions",
    "transmissions_quiet_window",
    "mean_interevent_s",
    "ss_att_err_deg",
    "ss_pos_err_m",
)


@dataclass
class Run:
    """One episode: its record, sampled signals and every transmission (time, command)."""

    record: dict[str, Any]
    time_s: np.ndarray
    signals: dict[str, np.ndarray]
    transmission_times_s: np.ndarray
    transmitted_commands: np.ndarray
    thruster_outputs: np.ndarray = field(default_factory=lambda: np.zeros((0, 12)))


SIGNALS = ("eta", "twist_error", "e1", "e2")


def run_scenario(scenario: Scenario, progress: bool = False) -> Run:
    """One seeded episode of ``scenario``, sampling the loop every :data:`SAMPLE_EVERY` steps."""
    env = gym.make(ENV_ID, **dict(scenario.env_args))
    unwrapped = env.unwrapped
    policy = make_policy(scenario.policy, env, dict(scenario.policy_args), ENV_ID)
    obs, _ = env.reset(seed=0)
    n_samples = unwrapped.n_steps // SAMPLE_EVERY + 1
    signals = {name: np.zeros((n_samples, 6)) for name in SIGNALS}
    time_s = np.zeros(n_samples)

    def sample(index: int) -> None:
        state = unwrapped.state_dict()
        time_s[index] = state["time_s"]
        for name in SIGNALS:
            signals[name][index] = state[name]

    sample(0)
    times, commands = [0.0], [unwrapped.held[0].copy()]
    total_return, steps = 0.0, 0
    started = time.perf_counter()
    bar = instants_bar(unwrapped.n_steps, progress, scenario.label)
    while True:
        action, _ = policy.predict(obs, deterministic=True)
        time_before = unwrapped.time_s
        obs, reward, terminated, truncated, info = env.step(action)
        steps += 1
        total_return += reward
        if info["transmitted"]:
            times.append(time_before)
            commands.append(unwrapped.held[0].copy())
        if steps % SAMPLE_EVERY == 0:
            sample(steps // SAMPLE_EVERY)
        if steps % 10_000 == 0:
            bar.update(10_000)
        if terminated or truncated:
            break
    bar.close()
    kept = steps // SAMPLE_EVERY + 1
    record = {
        "seed": 0,
        "wall_time_s": time.perf_counter() - started,
        "return": total_return,
        **info["episode_metrics"],
    }
    commands_array = np.array(commands)
    outputs = np.array([thruster_outputs(c, unwrapped.model)[1] for c in commands_array])
    record.update(_disturbance_steps(unwrapped, np.array(times), commands_array))
    env.close()
    run = Run(
        record=record,
        time_s=time_s[:kept],
        signals={name: value[:kept] for name, value in signals.items()},
        transmission_times_s=np.array(times),
        transmitted_commands=commands_array,
        thruster_outputs=outputs,
    )
    _add_derived_metrics(run)
    return run


def _disturbance_steps(unwrapped: Any, times: np.ndarray, commands: np.ndarray) -> dict:
    """The largest jump of Ξ·Δd (torque and force parts) over the steady window's transmissions."""
    steady_from = unwrapped.constants.steady_start * unwrapped.params.sampling_period_s
    steps = np.array(
        [
            disturbance_step(before, after, unwrapped.model, unwrapped.gains)
            for before, after, t in zip(commands[:-1], commands[1:], times[1:], strict=True)
            if t >= steady_from
        ]
    ).reshape(-1, 6)
    largest = np.abs(steps).max(axis=0, initial=0.0)
    return dict(zip(DISTURBANCE_STEP_KEYS, (largest[0:3].max(), largest[3:6].max()), strict=True))


def _convergence_time(time_s: np.ndarray, error: np.ndarray) -> float:
    """The time after which max_i |error_i| stays within CONVERGENCE_BAND of its peak."""
    size = np.abs(error).max(axis=1)
    outside = np.nonzero(size > CONVERGENCE_BAND * size.max())[0]
    return float(time_s[min(outside[-1] + 1, len(time_s) - 1)]) if len(outside) else 0.0


def _add_derived_metrics(run: Run) -> None:
    """Observer convergence times and the transmissions in the paper's magnified window."""
    record = run.record
    record.update(record["eso_ss_err"])
    record["e1_converged_s"] = _convergence_time(run.time_s, run.signals["e1"])
    record["e2_converged_s"] = _convergence_time(run.time_s, run.signals["e2"])
    start, end = QUIET_WINDOW_S
    # the t = 0 entry is the initial synchronisation, not a transmission
    events = run.transmission_times_s[1:]
    record["transmissions_quiet_window"] = int(np.sum((events >= start) & (events < end)))


# --------------------------------------------------------------------------- claims
def _within(record: dict[str, Any], bounds: dict[str, float]) -> tuple[bool, str]:
    failing = [k for k, bound in bounds.items() if record.get(k) is None or record[k] > bound]
    detail = ", ".join(
        f"{k} {record.get(k) if record.get(k) is None else format(record[k], '.3g')} <= {bound:g}"
        for k, bound in bounds.items()
    )
    return not failing, detail + (f" (exceeded: {failing})" if failing else "")


def _claims(runs: dict[Scenario, Run]) -> list[dict]:
    p1, ref19, p2, case2 = (runs[s].record for s in SCENARIOS)
    found = []
    settle = {k: TRACKING_BOUNDS[k] for k in ("settle_att_s", "settle_pos_s")}
    steady = {k: v for k, v in TRACKING_BOUNDS.items() if k not in settle}
    for label, record in (("P1", p1), ("P2", p2)):
        ok, detail = _within(record, settle)
        found.append(
            claim(f"{label}: attitude settles within 180 s, position within 200 s", ok, detail)
        )
        ok, detail = _within(record, steady)
        found.append(
            claim(f"{label}: steady tracking errors within the paper's bounds", ok, detail)
        )
    for error in ("e1", "e2"):
        bounds = {k: v for k, v in OBSERVER_BOUNDS[P1].items() if k.startswith(error)}
        ok, detail = _within(p1, bounds)
        if error == "e2":
            detail += (
                "; the largest jump of the disturbance at a transmission in the same window is "
                + ", ".join(f"{k} {p1[k]:.3g}" for k in DISTURBANCE_STEP_KEYS)
            )
        found.append(claim(f"ESO eq. (14): steady {error} within Figs. 1-2's bounds", ok, detail))
    found.append(
        claim(
            "ESO eq. (14): Z1 tracks S in about 10 s, Z2 reconstructs the disturbance within 15 s",
            p1["e1_converged_s"] <= 12.5 and p1["e2_converged_s"] <= 15.0,
            f"e1 within 2% of its peak from {p1['e1_converged_s']:.1f} s, "
            f"e2 from {p1['e2_converged_s']:.1f} s",
        )
    )
    found.append(
        claim(
            "the observer of ref. [19] converges more slowly (Figs. 3-4 vs 1-2)",
            ref19["e1_converged_s"] > p1["e1_converged_s"]
            and ref19["e2_converged_s"] >= p1["e2_converged_s"],
            f"e1 {ref19['e1_converged_s']:.1f} s vs {p1['e1_converged_s']:.1f} s, "
            f"e2 {ref19['e2_converged_s']:.1f} s vs {p1['e2_converged_s']:.1f} s",
        )
    )
    keys = tuple(OBSERVER_BOUNDS[P1])
    smaller = [k for k in keys if p1[k] < ref19[k]]
    found.append(
        claim(
            "ESO eq. (14) has smaller steady errors than the observer of ref. [19]",
            len(smaller) == len(keys),
            ", ".join(f"{k} {p1[k]:.2g} vs {ref19[k]:.2g}" for k in keys),
        )
    )
    found.append(
        claim(
            "Case 2 (larger gamma) transmits less, also in t in [150, 155] (Figs. 10-11)",
            case2["transmissions"] < p1["transmissions"]
            and case2["transmissions_quiet_window"] < p1["transmissions_quiet_window"],
            f"{case2['transmissions']} vs {p1['transmissions']} in 300 s, "
            f"{case2['transmissions_quiet_window']} vs {p1['transmissions_quiet_window']} in "
            "[150, 155) s",
        )
    )
    worse = [k for k in steady if case2[k] > p1[k]]
    found.append(
        claim(
            "Case 2 tracks less accurately than Case 1 (Fig. 12)",
            len(worse) == len(steady),
            ", ".join(f"{k} {case2[k]:.2g} vs {p1[k]:.2g}" for k in steady),
        )
    )
    return found


# --------------------------------------------------------------------------- figures
def _components(axis: plt.Axes, t: np.ndarray, values: np.ndarray, labels: list[str]) -> None:
    for i, label in enumerate(labels):
        axis.plot(t, values[:, i], lw=0.8, label=label)
    axis.legend(fontsize=7, loc="upper right", ncol=len(labels))
    axis.grid(alpha=0.3)


def _error_figure(run: Run, signal: str, scales, names, units, path: Path, title: str) -> Path:
    """Two signals (rows) in linear scale and as |·| in log scale (columns)."""
    figure, axes = plt.subplots(2, 2, figsize=(12, 6.5), sharex=True)
    t = run.time_s
    for row, (block, scale, name, unit) in enumerate(
        zip(signal, scales, names, units, strict=True)
    ):
        key, part = block
        values = run.signals[key][:, part] * scale
        labels = [f"{name}{i + 1}" for i in range(3)]
        _components(axes[row, 0], t, values, labels)
        axes[row, 1].semilogy(t, np.maximum(np.abs(values), 1e-14), lw=0.6)
        axes[row, 0].set_ylabel(f"{name} ({unit})")
        axes[row, 1].set_ylabel(f"|{name}| ({unit})")
        axes[row, 1].grid(alpha=0.3, which="both")
    for axis in axes[-1]:
        axis.set_xlabel("time (s)")
    axes[0, 0].set_title(title)
    return save(figure, path)


def _thruster_figure(run: Run, path: Path, title: str) -> Path:
    """Thrusters 4, 8, 12 (as Fig. 9): whole run and the magnified [150, 155] s."""
    figure, axes = plt.subplots(3, 2, figsize=(12, 7), sharex="col")
    times = np.append(run.transmission_times_s, run.time_s[-1])
    for row, thruster in enumerate((4, 8, 12)):
        output = np.append(
            run.thruster_outputs[:, thruster - 1], run.thruster_outputs[-1, thruster - 1]
        )
        for col, window in enumerate(((0.0, run.time_s[-1]), QUIET_WINDOW_S)):
            axis = axes[row, col]
            axis.step(times, output, where="post", lw=0.7)
            axis.set_xlim(*window)
            axis.grid(alpha=0.3)
            axis.set_ylabel(f"thruster {thruster} (N)")
        inside = (times >= QUIET_WINDOW_S[0]) & (times <= QUIET_WINDOW_S[1])
        if inside.any():
            low, high = output[inside].min(), output[inside].max()
            pad = 0.1 * (high - low) + 1e-6
            axes[row, 1].set_ylim(low - pad, high + pad)
    axes[-1, 0].set_xlabel("time (s)")
    axes[-1, 1].set_xlabel("time (s), magnified")
    axes[0, 0].set_title(title)
    return save(figure, path)


def _events_figure(runs: dict[str, Run], path: Path) -> Path:
    """Fig. 11: release instants and inter-event times, Case 1 (a) and Case 2 (b)."""
    figure, axes = plt.subplots(2, 2, figsize=(12, 6.5))
    for row, (label, run) in enumerate(runs.items()):
        events = run.transmission_times_s[1:]
        plot_interevent(axes[row, 0], list(events))
        axes[row, 0].set_yscale("log")
        axes[row, 0].set_title(f"({'ab'[row]}) {label}: inter-event times")
        start, end = QUIET_WINDOW_S
        inside = events[(events >= start) & (events < end)]
        axes[row, 1].eventplot(inside, lineoffsets=0.5, linelengths=0.8, linewidths=0.5)
        axes[row, 1].set_xlim(start, end)
        axes[row, 1].set_yticks([])
        axes[row, 1].set_title(f"release instants in [{start:g}, {end:g}) s: {len(inside)}")
        axes[row, 1].set_xlabel("time (s)")
    figure.tight_layout()
    return save(figure, path)


def _comparison_figure(case1: Run, case2: Run, path: Path) -> Path:
    """Fig. 12: tracking errors of Case 1 and Case 2 (norms, log scale)."""
    figure, axes = plt.subplots(2, 2, figsize=(12, 6.5), sharex=True)
    blocks = (
        ("eta", slice(0, 3), np.rad2deg(1.0), "|Phi| (deg)"),
        ("twist_error", slice(0, 3), np.rad2deg(1.0), "|dw| (deg/s)"),
        ("eta", slice(3, 6), 1.0, "|chi| (m)"),
        ("twist_error", slice(3, 6), 1.0, "|dv| (m/s)"),
    )
    for axis, (key, part, scale, label) in zip(axes.flat, blocks, strict=True):
        for name, run in (("Case 1 (gamma 0.001/0.003)", case1), ("Case 2 (gamma 0.1/0.2)", case2)):
            norm = np.linalg.norm(run.signals[key][:, part], axis=1) * scale
            axis.semilogy(run.time_s, np.maximum(norm, 1e-14), lw=0.7, label=name)
        axis.set_ylabel(label)
        axis.grid(alpha=0.3, which="both")
        axis.legend(fontsize=7)
    for axis in axes[-1]:
        axis.set_xlabel("time (s)")
    return save(figure, path)


def _figures(runs: dict[Scenario, Run], plot_dir: Path) -> list[str]:
    deg = np.rad2deg(1.0)
    written = []
    for number, scenario, tag in ((1, P1, "P1"), (3, REF19, "ref19")):
        run = runs[scenario]
        written.append(
            _error_figure(
                run,
                (("e1", slice(0, 3)), ("e1", slice(3, 6))),
                (1.0, 1.0),
                ("e1_rot", "e1_trans"),
                ("rad/s", "m/s"),
                plot_dir / f"fig{number:02d}_eso_e1_{tag}.png",
                f"Observer error e1 = Z1 - S, {scenario.label} (Fig. {number})",
            )
        )
        written.append(
            _error_figure(
                run,
                (("e2", slice(0, 3)), ("e2", slice(3, 6))),
                (1.0, 1.0),
                ("e2_rot", "e2_trans"),
                ("rad/s^2", "m/s^2"),
                plot_dir / f"fig{number + 1:02d}_eso_e2_{tag}.png",
                f"Observer error e2 = Z2 - total disturbance, {scenario.label} (Fig. {number + 1})",
            )
        )
    for number, scenario, tag in ((5, P1, "P1"), (7, P2, "P2")):
        run = runs[scenario]
        written.append(
            _error_figure(
                run,
                (("eta", slice(0, 3)), ("twist_error", slice(0, 3))),
                (deg, deg),
                ("Phi", "dw"),
                ("deg", "deg/s"),
                plot_dir / f"fig{number:02d}_attitude_{tag}.png",
                f"Attitude and angular-velocity errors, {scenario.label} (Fig. {number})",
            )
        )
        written.append(
            _error_figure(
                run,
                (("eta", slice(3, 6)), ("twist_error", slice(3, 6))),
                (1.0, 1.0),
                ("chi", "dv"),
                ("m", "m/s"),
                plot_dir / f"fig{number + 1:02d}_position_{tag}.png",
                f"Position and velocity errors, {scenario.label} (Fig. {number + 1})",
            )
        )
    written.append(
        _thruster_figure(
            runs[P1], plot_dir / "fig09_thrusters_case1.png", "Thrusters 4, 8, 12, Case 1 (Fig. 9)"
        )
    )
    written.append(
        _thruster_figure(
            runs[P1_CASE2],
            plot_dir / "fig10_thrusters_case2.png",
            "Thrusters 4, 8, 12, Case 2 (Fig. 10)",
        )
    )
    written.append(
        _events_figure(
            {"Case 1": runs[P1], "Case 2": runs[P1_CASE2]}, plot_dir / "fig11_events.png"
        )
    )
    written.append(
        _comparison_figure(runs[P1], runs[P1_CASE2], plot_dir / "fig12_case1_vs_case2.png")
    )
    return [str(path) for path in written]


# --------------------------------------------------------------------------- entry point
def planned_instants() -> int:
    """The sampling instants of the runs :func:`reproduce` makes (its progress's plan)."""
    return scenario_instants(ENV_ID, SCENARIOS)


def reproduce(plot_dir: Path | None = None, progress: bool = False) -> dict[str, Any]:
    """Run the four scenarios and compare with section IV's bounds and claims."""
    runs = {
        scenario: run_scenario(scenario, progress)
        for scenario in stages(SCENARIOS, f"paper {PAPER}")
    }
    records = {scenario: run.record for scenario, run in runs.items()}
    tables = [
        {
            "name": "Tracking, Figs. 5-8 (paper: bounds; ours: settling and max over 240-300 s)",
            "rows": [metric_row(s, TRACKING_BOUNDS, records[s]) for s in (P1, P2)],
        },
        {
            "name": "Observer errors, Figs. 1-4 (paper: bounds; ours: max over 240-300 s)",
            "rows": [
                metric_row(
                    s,
                    {
                        **OBSERVER_BOUNDS[s],
                        **OBSERVER_TIMES[s],
                        **dict.fromkeys(DISTURBANCE_STEP_KEYS),
                    },
                    records[s],
                )
                for s in (P1, REF19)
            ],
        },
        {
            "name": "Communication vs accuracy, Figs. 9-12 (paper: qualitative only)",
            "rows": [
                metric_row(s, dict.fromkeys(COMMUNICATION_KEYS), records[s]) for s in (P1, P1_CASE2)
            ],
        },
    ]
    result = {
        "paper": PAPER,
        "title": TITLE,
        "env": ENV_ID,
        "tables": tables,
        "claims": _claims(runs),
        "records": {s.label: records[s] for s in SCENARIOS},
    }
    if plot_dir is not None:
        result["figures"] = _figures(runs, Path(plot_dir))
    return result

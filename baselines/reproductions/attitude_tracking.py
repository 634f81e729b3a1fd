"""Paper 002 (Cai et al., Sci China Inf Sci 2019): Tables 1-3 and Figures 2-11.

Time-triggered rows run the ``always`` policy (1 ms, every sampling instant) and the
``periodic`` policy with ``every=400`` (400 ms); event-triggered rows run eq. (27) with the
paper's Ψ. Every run uses the environment's defaults (the paper's scenario, T = 60 s).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from baselines.plotting import plot_interevent, save
from baselines.reproductions.report import (
    Scenario,
    claim,
    metric_row,
    run_scenarios,
    scenario_instants,
)
from etsc_envs.evaluation.episodes import EpisodeTrace
from etsc_envs.papers import paper_numbered

PAPER = "002"
TITLE = paper_numbered(PAPER).title
ENV_ID = "etsc/AttitudeTracking-v0"
SAMPLE_EVERY = 20  # steps between stored states for the figures (20 ms)


def _scenario(label: str, reference: str, policy: str, uncertainties: bool = True, **policy_args):
    env_args = (("reference", reference), ("uncertainties", uncertainties))
    return Scenario(label, env_args, policy, tuple(sorted(policy_args.items())))


def _tt(reference: str, period_ms: int) -> Scenario:
    if period_ms == 1:
        return _scenario("time-triggered 1 ms", reference, "always")
    return _scenario(f"time-triggered {period_ms} ms", reference, "periodic", every=period_ms)


def _et(reference: str, psi: float, uncertainties: bool = True, label: str = "") -> Scenario:
    label = label or f"event-triggered Psi={psi}"
    return _scenario(label, reference, "paper", uncertainties, psi=psi)


TABLE_1 = [  # sinusoidal ω_d, eq. (53)
    (_tt("sinusoid", 1), {"T_A_ms": 1.0, "E_v": 0.0115, "E_q": 0.0059, "E_c": 0.58}),
    (_tt("sinusoid", 400), {"T_A_ms": 400.0, "E_v": 0.0407, "E_q": 0.0073, "E_c": 3.41}),
    (_et("sinusoid", 0.1), {"T_A_ms": 101.21, "E_v": 0.0122, "E_q": 0.0059, "E_c": 0.59}),
    (_et("sinusoid", 1.5), {"T_A_ms": 402.13, "E_v": 0.0268, "E_q": 0.0075, "E_c": 0.84}),
]
TABLE_3 = [  # square-wave ω_d, eqs. (54)-(55)
    (_tt("square", 1), {"T_A_ms": 1.0, "E_v": 0.0152, "E_q": 0.0063, "E_c": 0.60}),
    (_tt("square", 400), {"T_A_ms": 400.0, "E_v": 0.0575, "E_q": 0.0094, "E_c": 3.77}),
    (_et("square", 0.1), {"T_A_ms": 60.90, "E_v": 0.0158, "E_q": 0.0063, "E_c": 0.61}),
    (_et("square", 2.5), {"T_A_ms": 401.52, "E_v": 0.0402, "E_q": 0.0092, "E_c": 1.16}),
]
TABLE_2 = [  # ET-ADRC with Ψ = 0.1, with and without ΔJ and d
    (
        _et("sinusoid", 0.1, True, "sinusoid, with uncertainties"),
        {"mean_input_norm": 1.49, "E_v": 0.0122, "E_q": 0.0059},
    ),
    (
        _et("sinusoid", 0.1, False, "sinusoid, without uncertainties"),
        {"mean_input_norm": 1.35, "E_v": 0.0123, "E_q": 0.0059},
    ),
    (
        _et("square", 0.1, True, "square wave, with uncertainties"),
        {"mean_input_norm": 1.90, "E_v": 0.0158, "E_q": 0.0063},
    ),
    (
        _et("square", 0.1, False, "square wave, without uncertainties"),
        {"mean_input_norm": 1.67, "E_v": 0.0157, "E_q": 0.0063},
    ),
]
TABLES = {
    "Table 1 - sinusoidal desired rate": TABLE_1,
    "Table 2 - effect of uncertainties (ET, Psi=0.1)": TABLE_2,
    "Table 3 - square-wave desired rate": TABLE_3,
}
FIGURE_RUNS = {TABLE_1[0][0], TABLE_1[2][0], TABLE_3[0][0], TABLE_3[2][0]}


def _claims(records: dict[Scenario, dict[str, Any]]) -> list[dict]:
    found = []
    for table, reference, psi_far in ((TABLE_1, "sinusoid", 1.5), (TABLE_3, "square", 2.5)):
        tt1, tt400, et_near, et_far = (records[row[0]] for row in table)
        ratio = tt1["transmissions"] / et_near["transmissions"]
        accuracy_gap = et_near["E_v"] / tt1["E_v"] - 1.0
        found.append(
            claim(
                f"{reference}: ET Psi=0.1 tracks about as well as TT 1 ms with far fewer samples",
                abs(accuracy_gap) < 0.15 and ratio > 30.0,
                f"E_v {et_near['E_v']:.4g} vs {tt1['E_v']:.4g} ({100 * accuracy_gap:+.1f}%), "
                f"{ratio:.0f}x fewer transmissions",
            )
        )
        found.append(
            claim(
                f"{reference}: at ~400 ms average period ET Psi={psi_far} beats TT 400 ms",
                et_far["E_v"] < tt400["E_v"] and et_far["E_c"] < tt400["E_c"],
                f"E_v {et_far['E_v']:.4g} < {tt400['E_v']:.4g}, "
                f"E_c {et_far['E_c']:.3g} < {tt400['E_c']:.3g} "
                f"(T_A {et_far['T_A_ms']:.0f} ms vs 400 ms)",
            )
        )
        found.append(
            claim(
                f"{reference}: a larger Psi transmits less",
                et_far["transmissions"] < et_near["transmissions"],
                f"{et_far['transmissions']} (Psi={psi_far}) < {et_near['transmissions']} (Psi=0.1)",
            )
        )
    for with_unc, without in ((TABLE_2[0][0], TABLE_2[1][0]), (TABLE_2[2][0], TABLE_2[3][0])):
        a, b = records[with_unc], records[without]
        found.append(
            claim(
                f"{dict(with_unc.env_args)['reference']}: uncertainties cost input, not accuracy",
                a["mean_input_norm"] > b["mean_input_norm"] and abs(a["E_v"] / b["E_v"] - 1) < 0.1,
                f"mean input {a['mean_input_norm']:.3g} vs {b['mean_input_norm']:.3g} N m, "
                f"E_v {a['E_v']:.4g} vs {b['E_v']:.4g}",
            )
        )
    return found


def _figure_tracking(traces: dict[str, EpisodeTrace], signal: str, path: Path, title: str) -> Path:
    """Figs. 2/3/8/9: tracked signal and its desired value, time- and event-triggered."""
    desired = {"q": "q_d", "omega": "omega_d"}[signal]
    width = 4 if signal == "q" else 3
    figure, axes = plt.subplots(width, 1, figsize=(8, 2.2 * width), sharex=True)
    for label, trace in traces.items():
        time_s = trace.sampled("time_s")
        for i, axis in enumerate(axes):
            axis.plot(time_s, trace.sampled(signal)[:, i], label=f"{signal}{i + 1} {label}")
    first = next(iter(traces.values()))
    for i, axis in enumerate(axes):
        axis.plot(first.sampled("time_s"), first.sampled(desired)[:, i], "k--", label="desired")
        axis.set_ylabel(f"{signal}{i + 1}")
        axis.legend(fontsize=7, loc="upper right")
    axes[0].set_title(title)
    axes[-1].set_xlabel("time (s)")
    return save(figure, path)


def _figure_observer(trace: EpisodeTrace, path: Path, title: str) -> Path:
    """Figs. 4/5/10/11: x_1 and x_2 with the ESO's estimates."""
    figure, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    time_s = trace.sampled("time_s")
    for axis, (state, estimate) in zip(axes, (("x1", "x1_hat"), ("x2", "x2_hat")), strict=True):
        truth, guess = trace.sampled(state), trace.sampled(estimate)
        for i in range(3):
            line = axis.plot(time_s, truth[:, i], label=f"{state}{i + 1}")[0]
            axis.plot(time_s, guess[:, i], "--", color=line.get_color(), label=f"{estimate}{i + 1}")
        axis.set_ylabel(state)
        axis.legend(fontsize=7, ncol=3, loc="upper right")
    axes[1].set_ylim(np.percentile(trace.sampled("x2"), [0.5, 99.5]) * 1.5)
    axes[0].set_title(title)
    axes[1].set_xlabel("time (s)")
    return save(figure, path)


def _figures(traces: dict[Scenario, EpisodeTrace], plot_dir: Path) -> list[str]:
    written = []
    for reference, table, numbers in (
        ("sinusoid", TABLE_1, (2, 3, 4, 5, 6)),
        ("square", TABLE_3, (8, 9, 10, 11, 7)),
    ):
        tt1, _, et_near, et_far = (row[0] for row in table)
        pair = {"TT 1 ms": traces[tt1], "ET Psi=0.1": traces[et_near]}
        fig_q, fig_w, fig_eso_et, fig_eso_tt, fig_intervals = numbers
        written.append(
            _figure_tracking(
                pair,
                "q",
                plot_dir / f"fig{fig_q}_quaternion_{reference}.png",
                f"Attitude quaternion tracking, {reference} (Fig. {fig_q})",
            )
        )
        written.append(
            _figure_tracking(
                pair,
                "omega",
                plot_dir / f"fig{fig_w}_rate_{reference}.png",
                f"Angular-velocity tracking, {reference} (Fig. {fig_w})",
            )
        )
        written.append(
            _figure_observer(
                traces[et_near],
                plot_dir / f"fig{fig_eso_et}_eso_et_{reference}.png",
                f"ET-ESO, Psi=0.1, {reference} (Fig. {fig_eso_et})",
            )
        )
        written.append(
            _figure_observer(
                traces[tt1],
                plot_dir / f"fig{fig_eso_tt}_eso_tt_{reference}.png",
                f"ESO, time-triggered 1 ms, {reference} (Fig. {fig_eso_tt})",
            )
        )
        figure, axis = plt.subplots(figsize=(8, 3))
        plot_interevent(axis, traces[et_far].transmission_times_s)
        axis.set_title(f"Sampling intervals, {et_far.label}, {reference} (Fig. {fig_intervals})")
        written.append(save(figure, plot_dir / f"fig{fig_intervals}_intervals_{reference}.png"))
    return [str(path) for path in written]


def _scenarios() -> list[Scenario]:
    """Every scenario of Tables 1-3, once each, in table order."""
    return list(dict.fromkeys(row[0] for rows in TABLES.values() for row in rows))


def planned_instants() -> int:
    """The sampling instants of the runs :func:`reproduce` makes (its progress's plan)."""
    return scenario_instants(ENV_ID, _scenarios())


def reproduce(plot_dir: Path | None = None, progress: bool = False) -> dict[str, Any]:
    """Run every scenario of Tables 1-3 once and compare with the paper's numbers."""
    scenarios = _scenarios()
    sampled = FIGURE_RUNS if plot_dir is not None else ()
    records, traces = run_scenarios(ENV_ID, scenarios, sampled, SAMPLE_EVERY, f"paper {PAPER}")
    tables = [
        {"name": name, "rows": [metric_row(s, paper, records[s]) for s, paper in rows]}
        for name, rows in TABLES.items()
    ]
    result = {
        "paper": PAPER,
        "title": TITLE,
        "env": ENV_ID,
        "tables": tables,
        "claims": _claims(records),
    }
    if plot_dir is not None:
        result["figures"] = _figures(traces, Path(plot_dir))
    return result

"""Paper 001 (attitude containment of a microsatellite cluster): section 5's numbers and claims.

Runs, each 1200 s at 0.01 s on ``etsc/ClusterContainment-v0`` (one agent per follower):

* section 5.1 (Figure 2 substitute, Table 1): the paper's trigger eq. (15) with the default
  robust term sat(s, δ) of Remark 2, the same with sgn(s) as eq. (19) prints it, and the
  time-triggered law eq. (69) (every follower updates at every 0.01-s instant, ``always``);
* section 5.2 (Figure 5 substitute with its π1 cells, Table 2): the paper's trigger.

Tables put the paper's numbers beside ours: events per follower, convergence times, and for
section 5.2 the spread of the final attitudes inside each π1 cell (Theorem 4 says zero).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

import etsc_envs
from baselines.reproductions.cluster_figures import draw_figures
from baselines.reproductions.report import (
    Scenario,
    claim,
    metric_row,
    scenario_instants,
    stages,
)
from etsc_envs.cluster.env import hull_distance
from etsc_envs.cluster.params import FIGURE_5_CELLS
from etsc_envs.evaluation.episodes import EpisodeTrace, run_parallel_episode
from etsc_envs.evaluation.policy_specs import make_agent_policy
from etsc_envs.papers import paper_numbered

PAPER = "001"
TITLE = paper_numbered(PAPER).title
ENV_ID = "etsc/ClusterContainment-v0"
PAPER_HORIZON_S = 1200.0
SAMPLE_EVERY = 100  # steps between stored states (1 s)
PLOT_SAMPLE_EVERY = 10  # finer when drawing the trigger figures (0.1 s)
CONVERGENCE_FRACTION = 0.05

EVENTS_5_1 = (391, 445, 405, 354, 402, 480)
"""Events of followers 1-6 in 1200 s (section 5.1.2)."""
EVENTS_5_2 = (232, 247, 522, 420, 162, 142, 196, 288, 315)
"""Events of followers 1-9 in 1200 s (section 5.2)."""
PERIODIC_UPDATES = 120_000
"""Updates of the time-triggered law eq. (69) in 1200 s at 0.01 s (section 5.1.2)."""
HULL_ENTRY_S = 600.0
"""'converges to the convex hull formed by the leaders at about 600 s' (sections 5.1.1, 5.1.2)."""
OMEGA_CONVERGENCE_S = 700.0
"""'angular velocity converges to 0 within 700 s' (sections 5.1.1, 5.1.2, 5.2)."""

ET_SAT = Scenario("ET eq. (15), sat (default)", (("scenario", "paper"),), "paper")
ET_SIGN = Scenario("ET eq. (15), sgn", (("scenario", "paper"), ("switching", "sign")), "paper")
TT = Scenario("TT eq. (69), 0.01 s", (("scenario", "paper"),), "always")
PI1 = Scenario("pi1: ET eq. (15), sat (default)", (("scenario", "pi1"),), "paper")
SCENARIOS = (ET_SAT, ET_SIGN, TT, PI1)


def run_scenario(
    scenario: Scenario, sample_every: int, horizon_s: float, progress: bool = False
) -> tuple[dict[str, Any], EpisodeTrace]:
    """One episode of ``scenario`` (the environment's defaults plus the scenario's kwargs)."""
    env = etsc_envs.make_parallel(ENV_ID, horizon_s=horizon_s, **dict(scenario.env_args))
    policy = make_agent_policy(scenario.policy, env, dict(scenario.policy_args), ENV_ID)
    record, trace = run_parallel_episode(
        env,
        policy,
        seed=0,
        sample_every=sample_every,
        progress=progress,
        description=scenario.label,
    )
    env.close()
    return record, trace


def hull_entry_times(trace: EpisodeTrace) -> tuple[np.ndarray, np.ndarray]:
    """Per follower: the first sampled time after which it stays within 5 % of its initial
    distance to the leaders' convex hull (Definition 4), NaN if it is outside at the end; and
    its final distance to the hull as a fraction of the initial one."""
    sigma, leaders = trace.sampled("sigma"), trace.samples[0]["leaders"]
    distances = np.array([[hull_distance(point, leaders) for point in row] for row in sigma])
    initial = np.maximum(distances[0], 1e-6)
    times = trace.sampled("time_s")
    entry = np.full(distances.shape[1], np.nan)
    for i in range(distances.shape[1]):
        outside = np.flatnonzero(distances[:, i] > CONVERGENCE_FRACTION * initial[i])
        if not len(outside):
            entry[i] = 0.0
        elif outside[-1] < len(times) - 1:
            entry[i] = times[outside[-1] + 1]
    return entry, distances[-1] / initial


def interevent_growth(trace: EpisodeTrace, horizon_s: float) -> tuple[float, float]:
    """Events per follower in the first and in the second half of the episode."""
    times = np.asarray(trace.transmission_times_s)
    counts = np.array([np.sum(action) for action in trace.transmission_actions])
    first = counts[times < horizon_s / 2].sum()
    n_agents = len(trace.transmission_actions[0]) if trace.transmission_actions else 1
    return first / n_agents, (counts.sum() - first) / n_agents


def _events(record: dict[str, Any]) -> list[int]:
    return [values["transmissions"] for values in record["agents"].values()]


def _event_rows(records: dict[Scenario, dict], paper: tuple[int, ...], runs: dict) -> list[dict]:
    """One row per follower: its events in each run beside the paper's count."""
    rows = []
    for k in range(len(paper)):
        scenario = Scenario(f"follower {k + 1} (follower_{k})", (), "per-run")
        reported = {name: float(numbers[k]) for name, (_, numbers) in runs.items()}
        ours = {name: float(_events(records[run])[k]) for name, (run, _) in runs.items()}
        rows.append(metric_row(scenario, reported, ours))
    return rows


def _cell_spread(record: dict[str, Any]) -> list[tuple[tuple[int, ...], float, float]]:
    """For each π1 cell of followers: members (1-based), spread of final σ, of targets σ_d."""
    agents = list(record["agents"].values())
    n_followers = len(agents)
    spreads = []
    for cell in FIGURE_5_CELLS:
        members = [i for i in cell if i < n_followers]
        if len(members) < 2:
            continue
        final = np.array([agents[i]["final_sigma"] for i in members])
        target = np.array([agents[i]["target_sigma"] for i in members])
        spread = float(np.max(np.linalg.norm(final[:, None] - final[None], axis=-1)))
        target_spread = float(np.max(np.linalg.norm(target[:, None] - target[None], axis=-1)))
        spreads.append((tuple(i + 1 for i in members), spread, target_spread))
    return spreads


def _tables(records: dict[Scenario, dict], convergence: dict[Scenario, dict]) -> list[dict]:
    paper_tt = (PERIODIC_UPDATES,) * len(EVENTS_5_1)
    event_table = _event_rows(
        records,
        EVENTS_5_1,
        {
            "ET sat events": (ET_SAT, EVENTS_5_1),
            "ET sgn events": (ET_SIGN, EVENTS_5_1),
            "TT updates": (TT, paper_tt),
        },
    )
    convergence_rows = [
        metric_row(
            scenario,
            {
                "hull_entry_s": HULL_ENTRY_S,
                "converge_time_s": HULL_ENTRY_S,
                "omega_converge_time_s": OMEGA_CONVERGENCE_S,
            },
            convergence[scenario],
        )
        for scenario in (ET_SAT, ET_SIGN, TT, PI1)
    ]
    cell_rows = [
        metric_row(
            Scenario(f"cell {{{', '.join(map(str, members))}}}", PI1.env_args, PI1.policy),
            {"final sigma spread": 0.0, "target spread": 0.0},
            {"final sigma spread": spread, "target spread": target_spread},
        )
        for members, spread, target_spread in _cell_spread(records[PI1])
    ]
    return [
        {"name": "Section 5.1 - events per follower in 1200 s", "rows": event_table},
        {
            "name": "Convergence (s); paper: hull at ~600 s, omega within 700 s",
            "rows": convergence_rows,
        },
        {
            "name": "Section 5.2 - events per follower in 1200 s (pi1 topology)",
            "rows": _event_rows(records, EVENTS_5_2, {"ET sat events": (PI1, EVENTS_5_2)}),
        },
        {"name": "Section 5.2 - Theorem 4: one steady state per pi1 cell (rad)", "rows": cell_rows},
    ]


def _claims(
    records: dict[Scenario, dict],
    convergence: dict[Scenario, dict],
    hull: dict[Scenario, tuple[np.ndarray, np.ndarray]],
    growth: dict[Scenario, tuple[float, float]],
) -> list[dict]:
    et, tt, pi1 = records[ET_SAT], records[TT], records[PI1]
    found = []
    most = max(_events(et))
    found.append(
        claim(
            "ET updates every follower far less often than the time-triggered law (120,000)",
            most < 0.01 * PERIODIC_UPDATES and min(_events(tt)) == PERIODIC_UPDATES,
            f"at most {most} events per follower (paper: at most 480) vs "
            f"{min(_events(tt))} periodic updates",
        )
    )
    gap = et["mean_cost"] / tt["mean_cost"] - 1.0
    found.append(
        claim(
            "ET keeps the control performance of the time-triggered law",
            abs(gap) < 0.05 and et["final_containment_err"] < 2.0 * tt["final_containment_err"],
            f"mean Σ‖σ_i - σ_d,i‖ {et['mean_cost']:.4g} vs {tt['mean_cost']:.4g} rad "
            f"({100 * gap:+.1f}%), final worst {et['final_containment_err']:.3g} vs "
            f"{tt['final_containment_err']:.3g} rad",
        )
    )
    for scenario in (ET_SAT, TT, PI1):
        entry = convergence[scenario]["hull_entry_s"]
        times, remaining = hull[scenario]
        inside = np.flatnonzero(~np.isnan(times))
        late = ", ".join(
            f"{i + 1} ends at {100 * remaining[i]:.0f}%" for i in np.flatnonzero(np.isnan(times))
        )
        found.append(
            claim(
                f"{scenario.label}: followers enter the leaders' hull at about 600 s",
                entry is not None and 0.75 * HULL_ENTRY_S <= entry <= 1.25 * HULL_ENTRY_S,
                f"{len(inside)} of {len(times)} followers within 5% of their initial distance "
                f"to the hull, the last from {np.max(times[inside], initial=0.0):.0f} s"
                + (f"; {late} of it" if late else ""),
            )
        )
        omega = records[scenario]["omega_converge_time_s"]
        found.append(
            claim(
                f"{scenario.label}: angular velocities converge to 0 within 700 s",
                omega is not None and omega <= OMEGA_CONVERGENCE_S,
                f"every |omega_i| below 5% of the peak from {omega} s",
            )
        )
    early, late = growth[ET_SAT]
    found.append(
        claim(
            "events are frequent early and sparse once the cluster converges (Fig. 3(c)-(d))",
            late < early,
            f"{early:.0f} events per follower in the first 600 s, {late:.0f} in the last 600 s",
        )
    )
    spreads = _cell_spread(pi1)
    worst = max(spread for _, spread, _ in spreads)
    targets = np.array([values["target_sigma"] for values in pi1["agents"].values()])
    final = np.array([values["final_sigma"] for values in pi1["agents"].values()])
    states = np.unique(np.round(targets, 9), axis=0)
    separation = min(np.linalg.norm(a - b) for i, a in enumerate(states) for b in states[i + 1 :])
    nearest = np.argmin(np.linalg.norm(final[:, None] - states[None], axis=-1), axis=1)
    own = np.argmin(np.linalg.norm(targets[:, None] - states[None], axis=-1), axis=1)
    found.append(
        claim(
            "pi1: followers of one cell converge to one attitude (Theorem 4)",
            bool(np.all(nearest == own)) and all(target < 1e-12 for _, _, target in spreads),
            f"targets equal inside every cell; every follower ends nearest its cell's steady "
            f"state (largest spread inside a cell {worst:.3g} rad, distinct steady states "
            f"{separation:.3g} rad apart)",
        )
    )
    shared = targets[2:6]
    found.append(
        claim(
            "pi1: followers 3, 4, 5, 6 share one azimuth (cell {5, 6} hears only cell {3, 4})",
            float(np.ptp(shared, axis=0).max()) < 1e-12,
            f"targets of 3-6 equal to {np.round(shared[0], 4).tolist()} rad",
        )
    )
    return found


def planned_instants(horizon_s: float = PAPER_HORIZON_S) -> int:
    """The sampling instants of the runs :func:`reproduce` makes with ``horizon_s`` (its
    progress's plan)."""
    return scenario_instants(ENV_ID, SCENARIOS, horizon_s=horizon_s)


def reproduce(
    plot_dir: Path | None = None, progress: bool = False, horizon_s: float = PAPER_HORIZON_S
) -> dict[str, Any]:
    """Run section 5's scenarios once and compare with the paper's numbers.

    ``horizon_s`` shortens every run (for quick checks; the paper's numbers are for 1200 s).
    """
    sample_every = PLOT_SAMPLE_EVERY if plot_dir is not None else SAMPLE_EVERY
    records, traces, convergence, hull, growth = {}, {}, {}, {}, {}
    for scenario in stages(SCENARIOS, f"paper {PAPER}"):
        record, trace = run_scenario(scenario, sample_every, horizon_s, progress)
        records[scenario], traces[scenario] = record, trace
        hull[scenario] = hull_entry_times(trace)
        entry = hull[scenario][0]
        convergence[scenario] = {
            "hull_entry_s": None if np.isnan(entry).any() else float(entry.max()),
            "converge_time_s": record["converge_time_s"],
            "omega_converge_time_s": record["omega_converge_time_s"],
        }
        growth[scenario] = interevent_growth(trace, horizon_s)
    result = {
        "paper": PAPER,
        "title": TITLE,
        "env": ENV_ID,
        "tables": _tables(records, convergence),
        "claims": _claims(records, convergence, hull, growth),
    }
    if plot_dir is not None:
        result["figures"] = draw_figures(
            {"et": traces[ET_SAT], "tt": traces[TT], "pi1": traces[PI1]}, Path(plot_dir)
        )
    return result

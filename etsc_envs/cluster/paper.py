"""Paper 001: "Event-triggered adaptive sliding mode attitude containment control for a
microsatellite cluster under directed topology".

The trigger is eq. (15) per follower, a state-dependent and a time-dependent term with
0 < c < 1 (:class:`~etsc_envs.triggers.ClusterContainmentTrigger`); the paper has a PettingZoo
id (one agent per follower) and a central Gymnasium id (one transmit bit per follower).
"""

from etsc_envs.core.paper import Paper, Rule
from etsc_envs.triggers.cluster import PAPER_C, ClusterContainmentTrigger


def _thresholds() -> dict[str, float]:
    return {"c": PAPER_C}


PAPER = Paper(
    number="001",
    folder="cluster",
    title="Event-triggered adaptive sliding-mode attitude containment of a microsatellite cluster",
    ids=("etsc/ClusterContainment-v0", "etsc/ClusterContainmentCentral-v0"),
    rule=Rule(
        ClusterContainmentTrigger,
        _thresholds,
        sweep_points=tuple({"c": c} for c in (0.2, 0.4, 0.6, 0.8, 0.95)),
    ),
    # The paper's trigger updates a follower every few seconds (hundreds of 0.01-s instants).
    periodic_every=(10, 50, 100, 200, 500, 1000, 2000, 5000, 10000),
    headline_metrics=("converge_time_s", "final_containment_err"),
    cost=(
        "Σᵢ ‖σᵢ − σ_d,i‖, the followers' summed distance from their containment targets (MRP, rad)"
    ),
    reproduction="baselines.reproductions.cluster",
)

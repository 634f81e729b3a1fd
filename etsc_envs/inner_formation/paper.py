"""Paper 004: L. Hao, Y. Zhang, "Event-Triggered Disturbance Estimation and Output Feedback
Control Design for Inner-Formation Systems" (Appl. Sci. 14, 3656, 2024).

The triggers are the per-axis send-on-delta conditions eqs. (4)-(6) with thresholds Π_i
(:class:`~etsc_envs.triggers.InnerFormationTrigger`); beside them runs an error-time rule on the
same sampling errors (:class:`~etsc_envs.triggers.InnerFormationErrorTimeTrigger`, not the
paper's), and a shield from Theorem 1's bounds (:class:`~etsc_envs.triggers.InnerFormationShield`).
"""

from etsc_envs.core.paper import Paper, Rule
from etsc_envs.triggers.inner_formation import (
    InnerFormationErrorTimeTrigger,
    InnerFormationShield,
    InnerFormationTrigger,
)

PAPER = Paper(
    number="004",
    folder="inner_formation",
    title="Event-triggered disturbance estimation and output feedback, inner formation (Hao 2024)",
    ids=("etsc/InnerFormation-v0",),
    rule=Rule(InnerFormationTrigger, InnerFormationTrigger.paper_thresholds),
    error_time=Rule(
        InnerFormationErrorTimeTrigger,
        InnerFormationErrorTimeTrigger.paper_thresholds,
        sweep_scales=(0.5, 1.0, 2.0, 4.0, 8.0, 16.0),
    ),
    shield=InnerFormationShield,
    headline_metrics=("ss_pos_err_m", "ss_pos_est_err_m"),
    cost=("Σᵢ |rᵢ| + Σᵢ |rᵢ − ζᵢ|, the offset and its estimation error (m)"),
    reproduction="baselines.reproductions.inner_formation",
)

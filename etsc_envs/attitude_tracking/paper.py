"""Paper 002: D. Cai, H. Zou, J. Wang, Y. Huang, D. Shi, "Event-triggered attitude tracking
for rigid spacecraft" (Sci. China Inf. Sci., 2019).

The trigger is eq. (27) on the measurement, with threshold Ψ
(:class:`~etsc_envs.triggers.AttitudeTrackingTrigger`).
"""

from etsc_envs.core.paper import Paper, Rule
from etsc_envs.triggers.attitude_tracking import AttitudeTrackingTrigger

PAPER = Paper(
    number="002",
    folder="attitude_tracking",
    title="Event-triggered attitude tracking for rigid spacecraft (Cai et al. 2019)",
    ids=("etsc/AttitudeTracking-v0",),
    rule=Rule(AttitudeTrackingTrigger, AttitudeTrackingTrigger.paper_thresholds),
    headline_metrics=("mean_input_norm",),
    cost=(
        "⅓ Σᵢ |ωᵢ − ω_d,i| + ¼ Σᵢ |qᵢ − q_d,i|, the integrands of the paper's E_v and E_q, eq. "
        "(50) (rad/s and quaternion units)"
    ),
    reproduction="baselines.reproductions.attitude_tracking",
)

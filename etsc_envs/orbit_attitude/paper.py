"""Paper 000: J. Zhang, J. D. Biggs, D. Ye, Z. Sun, "Extended-state-observer based
event-triggered orbit-attitude tracking for low-thrust spacecraft" (IEEE TAES, 2019).

The trigger is eq. (21) on the control-signal error, with thresholds γ1, γ2
(:class:`~etsc_envs.triggers.OrbitAttitudeTrigger`).
"""

from etsc_envs.core.paper import Paper, Rule
from etsc_envs.triggers.orbit_attitude import PAPER_GAMMA, OrbitAttitudeTrigger


def _thresholds() -> dict[str, float]:
    return {"gamma1": PAPER_GAMMA[0], "gamma2": PAPER_GAMMA[1]}


PAPER = Paper(
    number="000",
    folder="orbit_attitude",
    title=(
        "ESO-based event-triggered orbit-attitude tracking for low-thrust spacecraft (Zhang 2019)"
    ),
    ids=("etsc/OrbitAttitudeTracking-v0",),
    rule=Rule(OrbitAttitudeTrigger, _thresholds, sweep_scales=(0.3, 1.0, 3.0, 10.0, 30.0, 100.0)),
    headline_metrics=("ss_att_err_deg", "ss_pos_err_m", "settle_pos_s"),
    cost=(
        "¼ Σ log(1 + error/bound) over the attitude, rate, position and velocity errors against"
        " the paper's steady-state bounds (dimensionless)"
    ),
    reproduction="baselines.reproductions.orbit_attitude",
)

"""The papers' own triggering rules, one module per problem, looked up by environment id."""

from __future__ import annotations

from baselines.triggers.attitude_tracking import AttitudeTrackingTrigger

PAPER_TRIGGERS = {
    "etsc/AttitudeTracking-v0": AttitudeTrackingTrigger,
}
"""Environment id → the paper's trigger policy class."""

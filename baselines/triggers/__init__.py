"""The papers' own triggering rules, one module per problem, looked up by environment id."""

from __future__ import annotations

from baselines.triggers.asteroid import AsteroidOrbitKeepingTrigger
from baselines.triggers.attitude_tracking import AttitudeTrackingTrigger
from baselines.triggers.cluster import ClusterContainmentTrigger
from baselines.triggers.inner_formation import InnerFormationTrigger
from baselines.triggers.orbit_attitude import OrbitAttitudeTrigger

PAPER_TRIGGERS = {
    "etsc/AttitudeTracking-v0": AttitudeTrackingTrigger,
    "etsc/OrbitAttitudeTracking-v0": OrbitAttitudeTrigger,
    "etsc/ClusterContainment-v0": ClusterContainmentTrigger,
    "etsc/ClusterContainmentCentral-v0": ClusterContainmentTrigger,
    "etsc/InnerFormation-v0": InnerFormationTrigger,
    "etsc/AsteroidOrbitKeeping-v0": AsteroidOrbitKeepingTrigger,
}
"""Environment id → the paper's trigger policy class."""

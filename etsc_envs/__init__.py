"""etsc-envs: Gymnasium and PettingZoo environments for learning when to communicate in
event-triggered spacecraft control.

Importing the package registers every environment id (see :data:`ENV_IDS`).
"""

from gymnasium.envs.registration import register, registry

ENV_IDS = {
    "etsc/AttitudeTracking-v0": "etsc_envs.attitude_tracking.env:AttitudeTrackingEnv",
    "etsc/OrbitAttitudeTracking-v0": "etsc_envs.orbit_attitude.env:OrbitAttitudeTrackingEnv",
    "etsc/InnerFormation-v0": "etsc_envs.inner_formation.env:InnerFormationEnv",
}
"""Gymnasium id → entry point of every registered single-agent environment."""

for _env_id, _entry_point in ENV_IDS.items():
    if _env_id not in registry:
        register(id=_env_id, entry_point=_entry_point)

__version__ = "0.1.0"

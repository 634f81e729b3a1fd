"""etsc-envs: Gymnasium and PettingZoo environments for learning when to communicate in
event-triggered spacecraft control.

Importing the package registers every environment id (see :data:`ENV_IDS`); the PettingZoo ids
are listed in :data:`PETTINGZOO_ENV_IDS` and built by :func:`make_parallel` / :func:`make_aec`.
"""

from gymnasium.envs.registration import register, registry

ENV_IDS = {
    "etsc/AttitudeTracking-v0": "etsc_envs.attitude_tracking.env:AttitudeTrackingEnv",
    "etsc/OrbitAttitudeTracking-v0": "etsc_envs.orbit_attitude.env:OrbitAttitudeTrackingEnv",
    "etsc/ClusterContainmentCentral-v0": "etsc_envs.cluster.env:ClusterContainmentCentralEnv",
    "etsc/InnerFormation-v0": "etsc_envs.inner_formation.env:InnerFormationEnv",
    "etsc/AsteroidOrbitKeeping-v0": "etsc_envs.asteroid.env:AsteroidOrbitKeepingEnv",
}
"""Gymnasium id → entry point of every registered single-agent environment."""

VECTOR_ENTRY_POINTS = {
    "etsc/AttitudeTracking-v0": "etsc_envs.attitude_tracking.env:AttitudeTrackingVectorEnv",
    "etsc/OrbitAttitudeTracking-v0": (
        "etsc_envs.orbit_attitude.env:OrbitAttitudeTrackingVectorEnv"
    ),
    "etsc/InnerFormation-v0": "etsc_envs.inner_formation.env:InnerFormationVectorEnv",
    "etsc/AsteroidOrbitKeeping-v0": "etsc_envs.asteroid.env:AsteroidOrbitKeepingVectorEnv",
    "etsc/ClusterContainmentCentral-v0": (
        "etsc_envs.cluster.env:ClusterContainmentCentralVectorEnv"
    ),
}
"""Gymnasium id → its native vector environment, for ``gym.make_vec(id, num_envs=n,
vectorization_mode="vector_entry_point")`` (all sub-environments stepped in one compiled call)."""

for _env_id, _entry_point in ENV_IDS.items():
    if _env_id not in registry:
        register(
            id=_env_id,
            entry_point=_entry_point,
            vector_entry_point=VECTOR_ENTRY_POINTS.get(_env_id),
        )

PETTINGZOO_ENV_IDS = {
    "etsc/ClusterContainment-v0": "etsc_envs.cluster_containment_v0",
}
"""PettingZoo id → module with ``parallel_env``, ``env`` and ``raw_env`` (PettingZoo has no
global registry; use :func:`make_parallel` or :func:`make_aec`)."""

PETTINGZOO_LOOP_IDS = {
    "etsc/ClusterContainment-v0": "etsc/ClusterContainmentCentral-v0",
}
"""PettingZoo id → the Gymnasium id of the closed loop its agents share (the central form, one
transmit bit per agent), whose native vector env trains one policy for all agents."""


def _pettingzoo_module(env_id: str):
    import importlib

    if env_id not in PETTINGZOO_ENV_IDS:
        raise ValueError(f"unknown PettingZoo id {env_id!r}; known: {sorted(PETTINGZOO_ENV_IDS)}")
    return importlib.import_module(PETTINGZOO_ENV_IDS[env_id])


def make_parallel(env_id: str, **kwargs):
    """The PettingZoo ``ParallelEnv`` registered as ``env_id``, built with ``kwargs``.

    Example: ``make_parallel("etsc/ClusterContainment-v0", scenario="pi1")``.
    """
    return _pettingzoo_module(env_id).parallel_env(**kwargs)


def make_aec(env_id: str, **kwargs):
    """The PettingZoo AEC form (with PettingZoo's usual wrappers) of ``env_id``."""
    return _pettingzoo_module(env_id).env(**kwargs)


__version__ = "0.1.0"

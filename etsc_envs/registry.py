"""The ids of etsc-envs, their entry points and PettingZoo's ``make`` for them.

Kept apart from the package's ``__init__`` (which registers them on import) so that modules
of the package can read the tables without importing the package itself.
"""

from typing import Any, Literal

import pettingzoo
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

PETTINGZOO_ENV_IDS = {
    "etsc/ClusterContainment-v0": "etsc_envs.cluster_containment_v0",
}
"""PettingZoo id → module with ``parallel_env``, ``env`` and ``raw_env`` (PettingZoo's module
convention); the id is registered with ``pettingzoo.register`` for both env types."""

_PETTINGZOO_REGISTRIES = {"parallel": pettingzoo.parallel_registry, "aec": pettingzoo.aec_registry}
_PETTINGZOO_FUNCTIONS: tuple[tuple[Literal["parallel", "aec"], str], ...] = (
    ("parallel", "parallel_env"),
    ("aec", "env"),
)

PETTINGZOO_LOOP_IDS = {
    "etsc/ClusterContainment-v0": "etsc/ClusterContainmentCentral-v0",
}
"""PettingZoo id → the Gymnasium id of the closed loop its agents share (the central form, one
transmit bit per agent), whose native vector env trains one policy for all agents."""


def _require_pettingzoo_id(env_id: str) -> str:
    if env_id not in PETTINGZOO_ENV_IDS:
        raise ValueError(f"unknown PettingZoo id {env_id!r}; known: {sorted(PETTINGZOO_ENV_IDS)}")
    return env_id


def make_parallel(env_id: str, **kwargs: Any) -> pettingzoo.ParallelEnv:
    """``pettingzoo.make("parallel", env_id, **kwargs)`` for an id of this package
    (``ValueError`` for any other id)."""
    return pettingzoo.make("parallel", _require_pettingzoo_id(env_id), **_checked_cycles(kwargs))


def make_aec(env_id: str, **kwargs: Any) -> pettingzoo.AECEnv:
    """``pettingzoo.make("aec", env_id, **kwargs)``: the AEC form with PettingZoo's usual
    wrappers (``ValueError`` for an id not of this package)."""
    return pettingzoo.make("aec", _require_pettingzoo_id(env_id), **_checked_cycles(kwargs))


def _checked_cycles(kwargs: dict[str, Any]) -> dict[str, Any]:
    """``kwargs``, or ``ValueError`` for a ``max_cycles`` the envs refuse (PettingZoo's
    ``make`` reads -1 as "no limit" and drops it; the envs take ``None`` for that)."""
    cycles = kwargs.get("max_cycles")
    if cycles is not None and (
        isinstance(cycles, bool) or not isinstance(cycles, int) or cycles < 1
    ):
        raise ValueError(f"max_cycles must be None or an integer >= 1, got {cycles!r}")
    return kwargs


def register_all() -> None:
    """Register every id of :data:`ENV_IDS` with Gymnasium (with its native vector env) and
    every id of :data:`PETTINGZOO_ENV_IDS` with PettingZoo, as ``"parallel"`` and ``"aec"``
    envs; ids already registered are left as they are."""
    for env_id, entry_point in ENV_IDS.items():
        if env_id not in registry:
            register(
                id=env_id,
                entry_point=entry_point,
                vector_entry_point=VECTOR_ENTRY_POINTS.get(env_id),
            )
    for env_id, module in PETTINGZOO_ENV_IDS.items():
        for env_type, function in _PETTINGZOO_FUNCTIONS:
            if env_id not in _PETTINGZOO_REGISTRIES[env_type]:
                pettingzoo.register(env_type, env_id, f"{module}:{function}")

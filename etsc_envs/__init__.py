"""etsc-envs: Gymnasium and PettingZoo environments for learning when to communicate in
event-triggered spacecraft control.

Importing the package registers every environment id: the Gymnasium ids of :data:`ENV_IDS`
with Gymnasium, the PettingZoo ids of :data:`PETTINGZOO_ENV_IDS` with PettingZoo's registry,
as ``"parallel"`` and ``"aec"`` envs::

    import pettingzoo

    import etsc_envs

    env = pettingzoo.make("parallel", "etsc/ClusterContainment-v0", scenario="pi1")
    aec = pettingzoo.make("aec", "etsc/ClusterContainment-v0", max_cycles=1000)
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
"""PettingZoo id → module with ``parallel_env``, ``env`` and ``raw_env`` (PettingZoo's module
convention); the id is registered with ``pettingzoo.register`` for both env types."""

_PETTINGZOO_REGISTRIES = {"parallel": pettingzoo.parallel_registry, "aec": pettingzoo.aec_registry}
_PETTINGZOO_FUNCTIONS: tuple[tuple[Literal["parallel", "aec"], str], ...] = (
    ("parallel", "parallel_env"),
    ("aec", "env"),
)
for _env_id, _module in PETTINGZOO_ENV_IDS.items():
    for _env_type, _function in _PETTINGZOO_FUNCTIONS:
        if _env_id not in _PETTINGZOO_REGISTRIES[_env_type]:
            pettingzoo.register(_env_type, _env_id, f"{_module}:{_function}")

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


def load_policy(path: str, env: Any) -> Any:
    """The trigger policy stored at ``path`` for ``env`` (a Gymnasium env of this package, or
    a PettingZoo parallel env, whose agents then share the policy), answering
    ``predict(obs, state=None, episode_start=None, deterministic=True)`` like an SB3 model.

    Reads

    * a learned trigger (``learned.json`` of ``python -m agents.search``, or a ``learned:``
      prefix before its path): :class:`~etsc_envs.triggers.family.LearnedTrigger`;
    * a Stable-Baselines3 model (``NAME.zip``, or an ``sb3:`` prefix before its path), with
      the observation statistics beside it (:func:`etsc_envs.sb3_models.load_sb3_policy`;
      needs the ``train`` extra).

    Raises ``ValueError`` naming ``path`` for any other file.
    """
    path = str(path)
    if path.removeprefix("learned:").endswith(".json"):
        from etsc_envs.triggers.family import LearnedTrigger

        return LearnedTrigger.load(path.removeprefix("learned:")).policy_for(env)
    if path.removeprefix("sb3:").endswith(".zip"):
        from etsc_envs.sb3_models import load_sb3_policy

        return load_sb3_policy(path.removeprefix("sb3:"), env)
    raise ValueError(
        f"path: load_policy reads learned triggers (.json) and Stable-Baselines3 models (.zip), "
        f"got {path!r}"
    )


__version__ = "0.1.0"

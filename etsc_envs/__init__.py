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

from typing import TYPE_CHECKING, Any

from etsc_envs.registry import (
    ENV_IDS,
    PETTINGZOO_ENV_IDS,
    PETTINGZOO_LOOP_IDS,
    VECTOR_ENTRY_POINTS,
    make_aec,
    make_parallel,
    register_all,
)

if TYPE_CHECKING:
    from etsc_envs.evaluation import Evaluation, evaluate, leaderboard

__all__ = [
    "ENV_IDS",
    "PETTINGZOO_ENV_IDS",
    "PETTINGZOO_LOOP_IDS",
    "VECTOR_ENTRY_POINTS",
    "Evaluation",
    "evaluate",
    "leaderboard",
    "load_policy",
    "make_aec",
    "make_parallel",
]

register_all()

_BENCHMARK = ("Evaluation", "evaluate", "leaderboard")
"""Names of :mod:`etsc_envs.evaluation` served here, imported on first use so that ``import
etsc_envs`` (run by every ``gym.make("etsc_envs:...")``) stays light."""


def __getattr__(name: str) -> Any:
    """:func:`etsc_envs.evaluation.evaluate` (the benchmark as a library call),
    :class:`~etsc_envs.evaluation.Evaluation` and :func:`etsc_envs.evaluation.leaderboard`."""
    if name in _BENCHMARK:
        from etsc_envs import evaluation

        return getattr(evaluation, name)
    raise AttributeError(f"module 'etsc_envs' has no attribute {name!r}")


def load_policy(path: str, env: Any) -> Any:
    """The trigger policy stored at ``path`` for ``env`` (a Gymnasium env of this package, or
    a PettingZoo parallel env, whose agents then share the policy), answering
    ``predict(obs, state=None, episode_start=None, deterministic=True)`` like an SB3 model.

    Reads

    * a learned trigger (``learned.json`` of ``python -m agents.search``, or a ``learned:``
      prefix before its path): :class:`~etsc_envs.triggers.family.LearnedTrigger`;
    * a Stable-Baselines3 model (``NAME.zip``, or an ``sb3:`` prefix before its path), with
      the observation statistics beside it (:func:`etsc_envs.decisions.policy.load_sb3_policy`;
      needs the ``train`` extra).

    Raises ``ValueError`` naming ``path`` for any other file.
    """
    path = str(path)
    if path.removeprefix("learned:").endswith(".json"):
        from etsc_envs.triggers.family import LearnedTrigger

        return LearnedTrigger.load(path.removeprefix("learned:")).policy_for(env)
    if path.removeprefix("sb3:").endswith(".zip"):
        from etsc_envs.decisions.policy import load_sb3_policy

        return load_sb3_policy(path.removeprefix("sb3:"), env)
    raise ValueError(
        f"path: load_policy reads learned triggers (.json) and Stable-Baselines3 models (.zip), "
        f"got {path!r}"
    )


__version__ = "0.1.0"

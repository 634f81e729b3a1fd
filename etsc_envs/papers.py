"""The papers of the suite: one :class:`~etsc_envs.core.paper.Paper` record per problem folder
(``etsc_envs/<problem>/paper.py``), in the papers' order, and lookups by id and number::

    import gymnasium as gym
    from etsc_envs.papers import paper_of

    env = gym.make("etsc_envs:etsc/AttitudeTracking-v0")
    paper = paper_of("etsc/AttitudeTracking-v0")
    trigger = paper.trigger(
        env.observation_space, env.action_space, observation_names=env.unwrapped.observation_names
    )

Adding a paper touches its own folder (``paper.py`` beside its params) and one line of
:data:`PAPERS`. The ids' registration stays in :mod:`etsc_envs` as entry-point strings, so that
``import etsc_envs`` (run by every ``gym.make("etsc_envs:...")``) imports no environment or
trigger; ``tests/test_papers.py`` checks that every registered id has its record here.
"""

from __future__ import annotations

from etsc_envs.asteroid import paper as asteroid
from etsc_envs.attitude_tracking import paper as attitude_tracking
from etsc_envs.cluster import paper as cluster
from etsc_envs.core.paper import RULE_NAMES, Paper, Rule
from etsc_envs.inner_formation import paper as inner_formation
from etsc_envs.orbit_attitude import paper as orbit_attitude

PAPERS: tuple[Paper, ...] = (
    orbit_attitude.PAPER,
    cluster.PAPER,
    attitude_tracking.PAPER,
    asteroid.PAPER,
    inner_formation.PAPER,
)
"""Every paper of the suite, in the papers' order."""

_BY_ID = {env_id: paper for paper in PAPERS for env_id in paper.ids}
_BY_NUMBER = {paper.number: paper for paper in PAPERS}

PAPER_IDS: tuple[str, ...] = tuple(sorted(_BY_ID))
"""Every id of every paper, sorted."""


def paper_of(env_id: str) -> Paper:
    """The record of the paper ``env_id`` belongs to (``ValueError`` for an id of no paper)."""
    if env_id not in _BY_ID:
        raise ValueError(f"env_id must be one of {list(PAPER_IDS)}, got {env_id!r}")
    return _BY_ID[env_id]


def paper_numbered(number: str) -> Paper:
    """The record of paper ``number`` (``"000"`` ..; ``ValueError`` for any other)."""
    if number not in _BY_NUMBER:
        raise ValueError(f"number must be one of {sorted(_BY_NUMBER)}, got {number!r}")
    return _BY_NUMBER[number]


def ids_with_rule(name: str) -> list[str]:
    """The sorted ids whose paper has the event rule ``name`` (of :data:`RULE_NAMES`;
    ``ValueError`` for any other name)."""
    if name not in RULE_NAMES:
        raise ValueError(f"rule must be one of {list(RULE_NAMES)}, got {name!r}")
    return [env_id for env_id in PAPER_IDS if name in _BY_ID[env_id].rules]


def rule_of(env_id: str, name: str) -> Rule:
    """The event rule ``name`` of ``env_id``'s paper (``ValueError`` naming the ids that have
    it, where this one does not)."""
    rules = paper_of(env_id).rules
    if name not in rules:
        raise ValueError(
            f"env_id must be one of {ids_with_rule(name)} for rule {name!r}, got {env_id!r}"
        )
    return rules[name]


__all__ = [
    "PAPERS",
    "PAPER_IDS",
    "Paper",
    "Rule",
    "ids_with_rule",
    "paper_numbered",
    "paper_of",
    "rule_of",
]

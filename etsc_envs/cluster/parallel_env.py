"""``etsc/ClusterContainment-v0``: each follower decides for itself when to update (PettingZoo).

The decentralised form of paper 001: one agent per follower (``follower_0 .. follower_{N-1}``,
the paper's satellites 1..N), each choosing at every 0.01-s sampling instant whether its own
event fires, as eq. (15) does in the paper. All agents share one closed loop, the
:class:`~etsc_envs.cluster.env.ClusterContainmentCentralEnv`, through
:class:`~etsc_envs.core.multi_agent.EventTriggeredParallelEnv`.
"""

from __future__ import annotations

from typing import Any

from etsc_envs.cluster.env import ClusterContainmentCentralEnv
from etsc_envs.cluster.params import ClusterContainmentParams
from etsc_envs.core.keywords import document_keywords
from etsc_envs.core.multi_agent import EventTriggeredParallelEnv
from etsc_envs.core.render import RENDER_MODES, RenderModes


@document_keywords(ClusterContainmentParams)
class ClusterContainmentEnv(EventTriggeredParallelEnv):
    """Attitude containment of a microsatellite cluster, one trigger per follower (paper 001).

    Takes the arguments of :class:`ClusterContainmentCentralEnv` (``params``,
    ``transmission_penalty``, ``cost_scale``, ``randomize``, ``render_mode`` and any parameter
    override) and PettingZoo's ``max_cycles`` (truncate after that many steps).

    Each agent acts with ``Discrete(2)`` (1: its follower samples, computes eq. (19) and updates
    its actuator) and observes the components of
    :data:`etsc_envs.cluster.env.FEATURE_NAMES` followed by ``time_since_transmission_s``; its
    reward is ``-‖σ_i - σ_d,i‖/cost_scale - transmission_penalty * transmitted_i``.
    """

    # Not a ClassVar: ParallelEnv declares metadata an instance attribute.
    metadata: dict[str, Any] = {  # noqa: RUF012
        "name": "cluster_containment_v0",
        "render_modes": RenderModes(RENDER_MODES),
        "render_fps": 10,
        "is_parallelizable": True,
    }
    loop: ClusterContainmentCentralEnv

    def __init__(
        self,
        params: ClusterContainmentParams | None = None,
        *,
        transmission_penalty: float = 0.1,
        cost_scale: float = 1.0,
        randomize: bool = False,
        render_mode: str | None = None,
        max_cycles: int | None = None,
        **overrides: Any,
    ) -> None:
        super().__init__(
            ClusterContainmentCentralEnv(
                params,
                transmission_penalty=transmission_penalty,
                cost_scale=cost_scale,
                randomize=randomize,
                render_mode=render_mode,
                **overrides,
            ),
            max_cycles=max_cycles,
        )

    @property
    def params(self) -> ClusterContainmentParams:
        """The model and scenario of the shared loop."""
        return self.loop.params

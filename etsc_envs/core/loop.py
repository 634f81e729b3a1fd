"""The step loop shared by every single-agent environment of the suite.

One call to :meth:`EventTriggeredEnv.step` is one sampling instant ``t_k`` of the design page:
the agent's transmit bits refresh the held channel values from the current ones, then the
problem advances plant, observer and controller over one sampling period with the held values,
and the reward is ``-cost_k / cost_scale - transmission_penalty * (channels sent)``. A failure
(divergence, non-finite state) terminates the episode and charges ``failure_cost`` for each
step left to the horizon.

A problem subclasses :class:`EventTriggeredEnv` and provides five hooks: ``_reset_problem``
(initial state from ``self.np_random``), ``_channel_values`` (what a transmission would send
now), ``_advance`` (one sampling period with ``self.channel.held``, returning the step's cost),
``_failure`` (``None`` or why the episode must stop), ``_features`` (the problem's part of the
observation) and ``_paper_metrics`` (the paper's own episode metrics); optionally
``_accepts_transmission`` (which channels can take a transmission now, all by default).
"""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from etsc_envs.core.channel import HeldChannel
from etsc_envs.core.metrics import communication_metrics
from etsc_envs.core.validation import require_non_negative, require_positive


class EventTriggeredEnv(gym.Env):
    """Transmit-or-hold decision at every sampling instant of a closed loop.

    Args:
        feature_names: names of the problem's observation components (the observation is these
            followed by one ``time_since_transmission_s`` entry per channel).
        feature_low, feature_high: bounds of those components.
        n_channels: separately triggered channels; one gives ``Discrete(2)``, more give
            ``MultiBinary(n_channels)``.
        channel_width: length of the value each channel carries.
        sampling_period_s: the sampling period (s).
        horizon_s: the scenario's length (s); reaching it truncates the episode.
        transmission_penalty: λ, the reward lost per transmitted channel.
        cost_scale: divisor of the accuracy cost in the reward.
        failure_cost: the cost charged for every step a failure cuts from the horizon, so that
            ending an episode by diverging never pays more than staying in control.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": []}

    def __init__(
        self,
        *,
        feature_names: tuple[str, ...],
        feature_low: np.ndarray,
        feature_high: np.ndarray,
        n_channels: int,
        channel_width: int,
        sampling_period_s: float,
        horizon_s: float,
        transmission_penalty: float,
        cost_scale: float,
        failure_cost: float,
    ) -> None:
        self.sampling_period_s = require_positive("sampling_period_s", sampling_period_s)
        self.horizon_s = require_positive("horizon_s", horizon_s)
        if self.horizon_s < self.sampling_period_s:
            raise ValueError(
                f"horizon_s must be >= sampling_period_s ({self.sampling_period_s} s), "
                f"got {horizon_s}"
            )
        self.transmission_penalty = require_non_negative(
            "transmission_penalty", transmission_penalty
        )
        self.cost_scale = require_positive("cost_scale", cost_scale)
        self.failure_cost = require_non_negative("failure_cost", failure_cost)
        self.n_steps = round(self.horizon_s / self.sampling_period_s)

        self.channel = HeldChannel(n_channels, channel_width)
        clock_names = (
            ("time_since_transmission_s",)
            if n_channels == 1
            else tuple(f"time_since_transmission_s_{i}" for i in range(n_channels))
        )
        self.observation_names: tuple[str, ...] = tuple(feature_names) + clock_names
        self._n_features = len(feature_names)
        low = np.concatenate([feature_low, np.zeros(n_channels)]).astype(np.float32)
        high = np.concatenate([feature_high, np.full(n_channels, self.horizon_s)]).astype(
            np.float32
        )
        self.observation_space = gym.spaces.Box(low=low, high=high, dtype=np.float32)
        self.action_space = (
            gym.spaces.Discrete(2) if n_channels == 1 else gym.spaces.MultiBinary(n_channels)
        )
        self.step_index = 0
        self.cost_sum = 0.0
        self.failure: str | None = None
        self._last_observation = np.zeros(len(self.observation_names), dtype=np.float32)

    # ----------------------------------------------------------------- problem hooks
    def _reset_problem(self, options: dict[str, Any] | None) -> None:
        raise NotImplementedError

    def _channel_values(self) -> np.ndarray:
        raise NotImplementedError

    def _advance(self) -> float:
        raise NotImplementedError

    def _failure(self) -> str | None:
        raise NotImplementedError

    def _features(self) -> np.ndarray:
        raise NotImplementedError

    def _paper_metrics(self) -> dict[str, Any]:
        raise NotImplementedError

    def _accepts_transmission(self) -> np.ndarray:
        """Which channels can take a transmission now (default: all). A problem whose receiver
        is busy (a thrust burst already running) refuses one: the request changes nothing, is
        not counted and is not charged."""
        return np.ones(self.channel.n_channels, dtype=bool)

    # ----------------------------------------------------------------- Gymnasium API
    @property
    def time_s(self) -> float:
        """Simulated time of the current sampling instant."""
        return self.step_index * self.sampling_period_s

    def observation_index(self, name: str) -> int:
        """Position of the named component in the observation vector."""
        return self.observation_names.index(name)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        self.step_index = 0
        self.cost_sum = 0.0
        self.failure = None
        self._reset_problem(options)
        self.channel.reset(self._channel_values(), 0.0)
        observation = self._observation()
        return observation, {"transmitted": 0, "transmissions": 0, "time_s": 0.0, "cost": 0.0}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self.failure is not None or self.step_index >= self.n_steps:
            raise RuntimeError("step() called after the episode ended; call reset() first")
        mask = self._transmit_mask(action) & self._accepts_transmission()
        sent = self.channel.send(mask, self._channel_values(), self.time_s)
        cost = self._advance()
        self.step_index += 1
        self.failure = self._failure()
        terminated = self.failure is not None
        if terminated:
            cost = 0.0 if not np.isfinite(cost) else cost
            observation = self._last_observation.copy()
        else:
            observation = self._observation()
        self.cost_sum += cost
        truncated = not terminated and self.step_index >= self.n_steps
        charged = cost + (
            self.failure_cost * (self.n_steps - self.step_index) if terminated else 0.0
        )
        reward = -charged / self.cost_scale - self.transmission_penalty * sent
        info: dict[str, Any] = {
            "transmitted": sent,
            "transmissions": int(self.channel.transmissions.sum()),
            "time_s": self.time_s,
            "cost": cost,
        }
        if terminated:
            info["failure"] = self.failure
        if terminated or truncated:
            info["episode_metrics"] = self.episode_metrics()
        return observation, float(reward), terminated, truncated, info

    def episode_metrics(self) -> dict[str, Any]:
        """The design page's common metrics and the paper's own, for the episode so far."""
        record = communication_metrics(self.channel, self.step_index, self.time_s, self.cost_sum)
        record["failure"] = self.failure
        record.update(self._paper_metrics())
        return record

    # ----------------------------------------------------------------- internals
    def _observation(self) -> np.ndarray:
        """The observation at the current instant (remembered, to answer a copy after a failure)."""
        observation = np.empty(len(self.observation_names), dtype=np.float32)
        observation[: self._n_features] = self._features()
        observation[self._n_features :] = self.channel.time_since_sent(self.time_s)
        self._last_observation = observation
        return observation

    def _transmit_mask(self, action: Any) -> np.ndarray:
        """The action as one boolean per channel, or ``ValueError`` naming what is allowed."""
        bits = np.asarray(action)
        n_channels = self.channel.n_channels
        if bits.size != n_channels or not np.all((bits == 0) | (bits == 1)):
            allowed = "0 (hold) or 1 (transmit)" if n_channels == 1 else f"{n_channels} bits of 0/1"
            raise ValueError(f"action must be {allowed}, got {action!r}")
        return bits.reshape(n_channels).astype(bool)

"""The Gymnasium environment shared by every single-agent problem of the suite.

One call to :meth:`EventTriggeredEnv.step` is one sampling instant ``t_k`` of the design page,
run by the problem's compiled loop step (:mod:`etsc_envs.core.compiled_loop`) on a batch of
one row: the agent's transmit bits refresh the held channel values, plant, observer and
controller advance one sampling period, and the reward is ``-cost_k / cost_scale -
transmission_penalty * (channels sent)``. A failure (divergence, non-finite state, collision)
terminates the episode with ``info["failure"]`` and charges ``failure_cost`` for each step
left to the horizon.

Observation bounds are the problem's where the physics bounds a component (the failure bounds,
norms, clocks); a component the paper bounds only asymptotically, by constants it does not
state (observer estimates, sliding variables, trigger statistics), gets ±:data:`UNBOUNDED`, the
largest float32, and its problem says so in its ``FEATURE_NAMES`` docs. ``render_mode=
"rgb_array"`` draws the system (the problem's :attr:`EventTriggeredEnv.picture`) beside the
episode so far, ``"human"`` shows it in a window (:mod:`etsc_envs.core.render`).

A problem subclasses :class:`EventTriggeredEnv`, sets the class attribute ``kernels`` (its
:class:`~etsc_envs.core.compiled_loop.ProblemKernels`) and implements four Python hooks:
``_reset_problem`` (write the initial state row from ``self.np_random``),
``_failure_message`` (the text of a failure code), ``_paper_metrics`` (the paper's episode
metrics, read from the state row) and ``_settled_at_end`` (the problem's own criterion of a
settled loop at the horizon, reported as ``settled``). Everything a step changes lives in the
loop arrays, so a vector environment can bind many such environments to the rows of one batch
(:mod:`etsc_envs.core.vector_env`); Python attributes of a problem may be set by
``_reset_problem`` but never by a step.
"""

from __future__ import annotations

from collections import namedtuple
from collections.abc import Callable
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from etsc_envs.core.compiled_loop import (
    LoopArrays,
    ProblemKernels,
    allocate_loop_arrays,
    compiled_entry,
    loop_rule_interval,
    make_loop_interval,
    make_loop_step,
)
from etsc_envs.core.metrics import communication_metrics
from etsc_envs.core.render import (
    RENDER_FPS,
    RENDER_MODES,
    EpisodeTrace,
    HumanWindow,
    RenderModes,
    SystemPicture,
    draw_frame,
)
from etsc_envs.core.validation import (
    MAX_TRANSMISSION_PENALTY,
    MIN_COST_SCALE,
    require_bool,
    require_choice,
    require_discount,
    require_in_range,
    require_int_at_least,
    require_non_negative,
    require_positive,
    require_reset_options,
    require_rule_trigger,
    step_count,
)

UNBOUNDED = float(np.finfo(np.float32).max)
"""The bound of an observation component without a physical one: the largest finite float32
(a finite bound keeps the spaces' checkers and samplers well defined)."""


class EventTriggeredEnv(gym.Env):
    """Transmit-or-hold decision at every sampling instant of a compiled closed loop.

    Args:
        feature_names: names of the problem's observation components (the observation is these
            followed by one ``time_since_transmission_s`` entry per channel).
        feature_low, feature_high: bounds of those components.
        n_channels: separately triggered channels; one gives ``Discrete(2)``, more give
            ``MultiBinary(n_channels)``.
        channel_width: length of the value each channel carries.
        state_width: length of the problem's state row.
        constants: the problem's immutable parameters (a namedtuple the kernels read).
        sampling_period_s: the sampling period (s).
        horizon_s: the scenario's length (s); reaching it truncates the episode.
        transmission_penalty: λ, the reward lost per transmitted channel.
        cost_scale: divisor of the accuracy cost in the reward.
        failure_cost: the cost charged for every step a failure cuts from the horizon, so that
            ending an episode by diverging never pays more than staying in control.
        randomize: whether ``_reset_problem`` draws the episode's start (``True``/``False``
            only).
        render_mode: ``None``, ``"rgb_array"`` (:meth:`render` returns the frame: the system
            beside the accuracy cost and the transmission instants of the episode so far) or
            ``"human"`` (the frames in a Matplotlib window, redrawn as the episode runs).

    ``reset()`` takes the ``options`` keys of :attr:`reset_options` (none by default) and
    refuses others. An env can be pickled at any point (the compiled entry is rebuilt on the
    next step) and the copy continues exactly as the original would.
    """

    # Not a ClassVar: Env declares metadata an instance attribute.
    metadata: dict[str, Any] = {  # noqa: RUF012
        "render_modes": RenderModes(RENDER_MODES),
        "render_fps": RENDER_FPS,
    }
    kernels: ClassVar[ProblemKernels]
    picture: ClassVar[SystemPicture | None] = None
    """How a frame draws the problem's system (``None``: the strips only)."""
    loop_step: ClassVar[Callable[..., None]]
    loop_interval: ClassVar[Callable[..., None]]
    reset_options: ClassVar[tuple[str, ...]] = ()
    """The keys ``reset(options=...)`` accepts."""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "kernels" in cls.__dict__:
            cls.loop_step = staticmethod(make_loop_step(cls.kernels))
            cls.loop_interval = staticmethod(make_loop_interval(cls.loop_step))

    def __init__(
        self,
        *,
        feature_names: tuple[str, ...],
        feature_low: np.ndarray,
        feature_high: np.ndarray,
        n_channels: int,
        channel_width: int,
        state_width: int,
        constants: Any,
        sampling_period_s: float,
        horizon_s: float,
        transmission_penalty: float,
        cost_scale: float,
        failure_cost: float,
        randomize: bool = False,
        render_mode: str | None = None,
    ) -> None:
        self.randomize = require_bool("randomize", randomize)
        self.render_mode = require_choice("render_mode", render_mode, (None, *RENDER_MODES))
        self.sampling_period_s = require_positive("sampling_period_s", sampling_period_s)
        self._trace = (
            EpisodeTrace(n_channels, self.sampling_period_s) if render_mode is not None else None
        )
        self._window = HumanWindow() if render_mode == "human" else None
        self.horizon_s = require_positive("horizon_s", horizon_s)
        self.n_steps = step_count(self.horizon_s, self.sampling_period_s)
        self.transmission_penalty = require_in_range(
            "transmission_penalty", transmission_penalty, 0.0, MAX_TRANSMISSION_PENALTY
        )
        self.cost_scale = require_in_range("cost_scale", cost_scale, MIN_COST_SCALE, np.inf)
        self.failure_cost = require_non_negative("failure_cost", failure_cost)
        self.n_channels = n_channels
        self.constants = constants

        clock_names = (
            ("time_since_transmission_s",)
            if n_channels == 1
            else tuple(f"time_since_transmission_s_{i}" for i in range(n_channels))
        )
        self.observation_names: tuple[str, ...] = tuple(feature_names) + clock_names
        self.n_features = len(feature_names)
        low = np.concatenate([feature_low, np.zeros(n_channels)])
        high = np.concatenate([feature_high, np.full(n_channels, self.horizon_s)])
        low, high = (bound.clip(-UNBOUNDED, UNBOUNDED).astype(np.float32) for bound in (low, high))
        self.observation_space = gym.spaces.Box(low=low, high=high, dtype=np.float32)
        self.action_space = (
            gym.spaces.Discrete(2) if n_channels == 1 else gym.spaces.MultiBinary(n_channels)
        )
        self.loop_shape = (n_channels, channel_width, self.n_features, state_width)
        self._actions = np.zeros((1, n_channels), dtype=np.int64)
        self._active = np.ones(1, dtype=bool)
        self._has_reset = False
        self._interval_outputs = _interval_outputs(1, n_channels)
        self.bind(allocate_loop_arrays(1, *self.loop_shape))

    def bind(self, arrays: LoopArrays) -> None:
        """Live in ``arrays`` (one row, typically a view into a vector environment's batch)."""
        self.arrays = arrays
        self.state = arrays.state[0]
        self._loop_step_entry = None
        self._loop_interval_entry = None
        self._rule_interval_entries: dict[Any, Callable[..., Any]] = {}

    def __getstate__(self) -> dict[str, Any]:
        """Everything but the compiled entry points (machine code, not picklable; rebuilt from
        the disk cache on the next step)."""
        state = self.__dict__.copy()
        state["_loop_step_entry"] = None
        state["_loop_interval_entry"] = None
        state["_rule_interval_entries"] = {}
        if self._window is not None:  # a window does not travel
            state["_window"] = HumanWindow()
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Restore, binding :attr:`state` to the restored arrays again (pickle copies a view
        as an array of its own)."""
        self.__dict__.update(state)
        self.bind(self.arrays)

    # ----------------------------------------------------------------- problem hooks
    def _reset_problem(self, options: dict[str, Any] | None) -> None:
        raise NotImplementedError

    def _failure_message(self, code: int) -> str:
        raise NotImplementedError

    def _paper_metrics(self) -> dict[str, Any]:
        raise NotImplementedError

    def state_dict(self) -> dict[str, np.ndarray]:
        """Named copies of the loop's signals at the current instant (for plots and tests)."""
        raise NotImplementedError

    def _settled_at_end(self, metrics: dict[str, Any]) -> bool:
        """Whether the loop has settled by the problem's own criterion, judged at the horizon
        from the state row and the paper's ``metrics`` of the episode."""
        raise NotImplementedError

    def _initial_held(self) -> np.ndarray:
        """The values both sides of the channel agree on at reset (by default the current ones;
        not counted as a transmission)."""
        return self.kernels.channel_values(self.state, self.constants, 0.0)

    # ----------------------------------------------------------------- loop signals
    @property
    def step_index(self) -> int:
        """Sampling instants completed in the episode."""
        return int(self.arrays.step_index[0])

    @property
    def time_s(self) -> float:
        """Simulated time of the current sampling instant."""
        return self.step_index * self.sampling_period_s

    @property
    def held(self) -> np.ndarray:
        """The value each channel's receiver holds, ``(n_channels, channel_width)``."""
        return self.arrays.held[0]

    @property
    def transmissions(self) -> np.ndarray:
        """Transmissions of each channel in the episode."""
        return self.arrays.transmissions[0]

    @property
    def last_sent_s(self) -> np.ndarray:
        """When each channel last transmitted (the reset time if it has not)."""
        return self.arrays.last_sent_s[0]

    @property
    def channel_costs(self) -> np.ndarray:
        """Each channel's share of the last step's accuracy cost."""
        return self.arrays.channel_costs[0]

    @property
    def channel_rewards(self) -> np.ndarray:
        """Each channel's reward of the last step (they sum to the step's reward)."""
        return self.arrays.channel_rewards[0]

    @property
    def failure(self) -> str | None:
        """Why the episode ended early, or ``None``."""
        code = int(self.arrays.failure_code[0])
        return None if code == 0 else self._failure_message(code)

    def observation_index(self, name: str) -> int:
        """Position of the named component in the observation vector."""
        return self.observation_names.index(name)

    # ----------------------------------------------------------------- Gymnasium API
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        options = require_reset_options(options, self.reset_options)
        super().reset(seed=seed)
        self._has_reset = True
        arrays = self.arrays
        for array in arrays:  # the state row included: _reset_problem starts from zeros
            array[0] = 0
        arrays.interevent_min_s[0] = np.inf
        self._reset_problem(options or None)
        if self._trace is not None:
            self._trace.clear()
        arrays.held[0] = self._initial_held()
        features = np.empty(self.n_features)
        self.kernels.features(self.state, self.constants, features)
        arrays.observation[0, : self.n_features] = features
        if self._window is not None:
            self.render()
        return arrays.observation[0].copy(), self.reset_info()

    @staticmethod
    def reset_info() -> dict[str, Any]:
        """The ``info`` of a reset (the keys every step's info carries, at their start values)."""
        return {"transmitted": 0, "transmissions": 0, "time_s": 0.0, "cost": 0.0}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        self._require_running("step")
        self._set_transmit_bits("action", action)
        arguments = self._loop_arguments()
        if self._loop_step_entry is None:
            self._loop_step_entry = compiled_entry(self.loop_step, *arguments)
        self._loop_step_entry(*arguments)
        self.trace_step()
        observation, terminated, truncated, info = self._outcome()
        return observation, float(self.arrays.reward[0]), terminated, truncated, info

    def run_interval(
        self, first_action: Any, instants: int, gamma: float = 1.0
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any], int]:
        """Run up to ``instants`` sampling instants in one compiled call: ``first_action`` at
        the first, hold (every channel 0) at the others, stopping early at a failure or at the
        horizon.

        The episode (state, step counter, metrics, ``render`` trace) ends exactly as after the
        same actions given to :meth:`step` one instant at a time. Returns ``(observation,
        discounted_reward, terminated, truncated, info, steps_run)``: the observation,
        ``terminated``, ``truncated`` and ``info`` of the last instant run, ``sum_k gamma**k *
        reward_k`` over the ``steps_run`` instants run (summed in order, as a Python loop over
        :meth:`step`'s rewards would). ``ValueError`` naming the argument if ``first_action``
        is not an action, ``instants`` not an integer >= 1 or ``gamma`` not in (0, 1].
        """
        self._require_running("run_interval")
        instants = require_int_at_least("instants", instants, 1)
        gamma = require_discount("gamma", gamma)
        self._set_transmit_bits("first_action", first_action)
        outputs = self._outputs_for(instants)
        arguments = (*self._loop_arguments(), instants, gamma, *outputs)
        if self._loop_interval_entry is None:
            self._loop_interval_entry = compiled_entry(self.loop_interval, *arguments)
        start = self.step_index
        self._loop_interval_entry(*arguments)
        return self._interval_outcome(start, outputs)

    def run_rule_interval(
        self, trigger: Any, instants: int, gamma: float = 1.0, send_first: bool = False
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any], int]:
        """Run up to ``instants`` sampling instants decided by a paper's triggering rule in one
        compiled call, ending just before a later instant (not the first) at which the rule
        sends, at a failure or at the horizon: a self-triggered "follow the paper" interval.
        With ``send_first`` every channel sends at the first instant (the interval of the rule
        paired with a heartbeat).

        ``trigger`` is a :class:`~etsc_envs.triggers.base.RuleTrigger` built for this env's
        observations. The episode ends exactly as after giving :meth:`step` the trigger's
        decisions one instant at a time; the return is :meth:`run_interval`'s.
        """
        self._require_running("run_rule_interval")
        instants = require_int_at_least("instants", instants, 1)
        gamma = require_discount("gamma", gamma)
        require_rule_trigger("trigger", trigger, self.n_channels)
        outputs = self._outputs_for(instants)
        outputs.discounted[:] = 0.0
        arguments = (
            *self._loop_arguments()[1:],
            trigger.rule_indices,
            trigger.rule_parameters,
            instants,
            True,
            bool(send_first),
            gamma,
            self._actions,
            outputs.discounted,
            np.zeros((1, self.n_channels)),
            outputs.steps_run,
            outputs.step_costs,
            outputs.step_sent,
        )
        rule = type(trigger).rule
        entry = self._rule_interval_entries.get(rule)
        if entry is None:
            function = loop_rule_interval(self.loop_step, rule)
            entry = self._rule_interval_entries[rule] = compiled_entry(function, *arguments)
        start = self.step_index
        entry(*arguments)
        return self._interval_outcome(start, outputs)

    def _outputs_for(self, instants: int) -> IntervalOutputs:
        """The interval's output arrays, grown to hold ``instants`` instants."""
        if self._interval_outputs.step_costs.shape[1] < instants:
            self._interval_outputs = _interval_outputs(instants, self.n_channels)
        return self._interval_outputs

    def _interval_outcome(
        self, start: int, outputs: IntervalOutputs
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any], int]:
        """Note an interval that began at instant ``start`` for :meth:`render`, and return
        what :meth:`run_interval` returns."""
        steps_run = int(outputs.steps_run[0])
        self.trace_interval(start, outputs.step_costs[0, :steps_run], outputs.step_sent[0])
        observation, terminated, truncated, info = self._outcome()
        discounted = float(outputs.discounted[0])
        return observation, discounted, terminated, truncated, info, steps_run

    def _require_running(self, method: str) -> None:
        """``ResetNeeded`` before the first reset, ``RuntimeError`` after the episode ended."""
        arrays = self.arrays
        if not self._has_reset:
            raise gym.error.ResetNeeded(f"{method}() called before reset(); call reset() first")
        if arrays.failure_code[0] != 0 or arrays.step_index[0] >= self.n_steps:
            raise RuntimeError(f"{method}() called after the episode ended; call reset() first")

    def _loop_arguments(self) -> tuple[Any, ...]:
        """The arguments of the compiled loop step for this env's row and stored actions."""
        return (
            self._actions,
            self._active,
            self.arrays,
            self.constants,
            self.sampling_period_s,
            self.n_steps,
            self.cost_scale,
            self.transmission_penalty,
            self.failure_cost,
        )

    def _outcome(self) -> tuple[np.ndarray, bool, bool, dict[str, Any]]:
        """The observation, ``terminated``, ``truncated`` and ``info`` of the last step."""
        arrays = self.arrays
        terminated = bool(arrays.failure_code[0] != 0)
        truncated = bool(not terminated and arrays.step_index[0] >= self.n_steps)
        info = self.step_info(terminated or truncated)
        return arrays.observation[0].copy(), terminated, truncated, info

    def step_info(self, ended: bool) -> dict[str, Any]:
        """The ``info`` of the last step (with ``failure`` and ``episode_metrics`` if it ended
        the episode)."""
        arrays = self.arrays
        info: dict[str, Any] = {
            "transmitted": int(arrays.sent_count[0]),
            "transmissions": int(arrays.transmission_count[0]),
            "time_s": self.time_s,
            "cost": float(arrays.cost[0]),
        }
        if ended:
            failure = self.failure
            if failure is not None:
                info["failure"] = failure
            info["episode_metrics"] = self.episode_metrics()
        return info

    def episode_metrics(self) -> dict[str, Any]:
        """The design page's common metrics and the paper's own, for the episode so far.

        ``settled`` is true when the episode reached the horizon without failure and the loop
        meets the problem's settling criterion there (``_settled_at_end``); the test protocol
        asks it of the paper's trigger on every randomized scenario (docs/protocol.md)."""
        record = communication_metrics(self.arrays, self.time_s)
        record["failure"] = self.failure
        paper_metrics = self._paper_metrics()
        record.update(paper_metrics)
        record["settled"] = bool(
            record["failure"] is None
            and self.step_index >= self.n_steps
            and self._settled_at_end(paper_metrics)
        )
        return record

    # ----------------------------------------------------------------- rendering
    def trace_step(self) -> None:
        """Note the step just taken for :meth:`render` (nothing unless rendering)."""
        if self._trace is not None:
            self._trace.record(self.step_index - 1, float(self.arrays.cost[0]), self.arrays.sent[0])
            self._redraw_window()

    def trace_interval(self, start: int, costs: np.ndarray, sent: np.ndarray) -> None:
        """Note the ``len(costs)`` steps just run after instant ``start`` in one compiled call
        (each step's accuracy cost and transmit bits) for :meth:`render`."""
        if self._trace is not None:
            for instant, cost in enumerate(costs):
                self._trace.record(start + instant, float(cost), sent[instant])
            self._redraw_window()

    def _redraw_window(self) -> None:
        """``render_mode="human"``: redraw the window if a frame is due."""
        if self._window is not None and self._window.due():
            self.render()

    def render(self) -> np.ndarray | None:
        """The frame of the current instant: the system (the problem's :attr:`picture`, with a
        trail through the states of the episode's earlier frames) beside the accuracy cost per
        step and each channel's transmission instants so far. ``render_mode="rgb_array"``
        returns it as an RGB array; ``"human"`` shows it in the window and returns ``None``, as
        does an env without a render mode."""
        if self._trace is None:
            gym.logger.warn(
                f"render() called without a render_mode; pass render_mode as one of {RENDER_MODES}"
            )
            return None
        transmissions = int(self.transmissions.sum())
        title = f"{type(self).__name__}   t = {self.time_s:.3f} s   transmissions = {transmissions}"
        picture = self.picture
        system = None
        if picture is not None:
            trail = self._trace.note_snapshot(self.time_s, picture.snapshot(self))

            def draw_system(figure: Any, region: Any) -> None:
                picture.draw(self, figure, region, trail)

            system = draw_system
        frame = draw_frame(self._trace, self.channel_labels, title, self.horizon_s, system)
        if self._window is not None:
            self._window.show(frame)
            return None
        return frame

    def close(self) -> None:
        if self._window is not None:
            self._window.close()
        super().close()

    @property
    def channel_labels(self) -> tuple[str, ...]:
        """One name per channel (the agents' names where the loop has agents)."""
        names = getattr(self, "agent_names", None)
        if names is not None:
            return tuple(names)
        return ("channel",) if self.n_channels == 1 else tuple(map(str, range(self.n_channels)))

    # ----------------------------------------------------------------- internals
    def _set_transmit_bits(self, name: str, action: Any) -> None:
        """Store the action as one 0/1 per channel, or ``ValueError`` naming ``name`` and what
        is allowed."""
        if self.n_channels == 1 and isinstance(action, int | np.integer) and action in (0, 1):
            self._actions[0, 0] = action  # the common case, without array checks
            return
        bits = np.asarray(action)
        n_channels = self.n_channels
        if bits.size != n_channels or not np.all((bits == 0) | (bits == 1)):
            allowed = "0 (hold) or 1 (transmit)" if n_channels == 1 else f"{n_channels} bits of 0/1"
            raise ValueError(f"{name} must be {allowed}, got {action!r}")
        self._actions[0] = bits.reshape(n_channels)


IntervalOutputs = namedtuple(
    "IntervalOutputs", ["discounted", "steps_run", "step_costs", "step_sent"]
)
"""What the compiled interval writes for one row (see
:func:`~etsc_envs.core.compiled_loop.make_loop_interval`)."""


def _interval_outputs(capacity: int, n_channels: int) -> IntervalOutputs:
    """Output arrays of the compiled interval for one row and up to ``capacity`` instants."""
    return IntervalOutputs(
        discounted=np.zeros(1),
        steps_run=np.zeros(1, dtype=np.int64),
        step_costs=np.zeros((1, capacity)),
        step_sent=np.zeros((1, capacity, n_channels), dtype=np.int64),
    )

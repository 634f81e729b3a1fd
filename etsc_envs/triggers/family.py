"""Each paper's parametric trigger family: the paper's own condition generalised by a
parameter vector θ, one compiled kernel that the compiled loop, batch evaluation and
``predict`` run alike.

Per channel c, with τ the time since c last transmitted (the observation's
``time_since_transmission_s*``) and, for each of the paper's conditions of that channel, its
sampling statistic s and threshold h (:attr:`~etsc_envs.triggers.base.RuleTrigger.condition`,
computed with every threshold keyword multiplied by its learned factor), the channel
transmits when

* τ < τ_first (the episode's first instant, where τ = 0; τ_first = T/2 or 0 for never), or
* τ ≥ τ_max · e^{g_max} (a heartbeat), or
* τ ≥ τ_min · e^{g_min} (a floor) and one of its conditions holds in the weighted form
  ``s · τ^p  ⋗  h · e^{g_h} · τ_ref^p`` (⋗ the paper's own comparison, > or ≥),

where p is a time exponent, τ_ref the family's reference time (:data:`REFERENCE_S`), and
``g = (g_h, g_min, g_max)`` the output of a small state-dependent network (two tanh layers on
the normalised observation, :class:`Modulation`; one for all channels, or one per channel on
that channel's own inputs), zero when it has no weights. The weighting
is applied to both sides so that every named point is its stand-alone policy's comparison to
the last bit: with p = 0 and g = 0 both factors are exactly 1.

A **coupled** point (:class:`Coupling`: a weight w > 0 per condition, a strength κ in [0, 1]
and whether a send refreshes every channel) combines the conditions' ratios
``r_cj = s_cj · τ_c^p / (h_cj · e^{g_h} · τ_ref^p)`` in a weighted norm: channel c's condition
holds when ``Σ_j (w_cj r_cj)² + κ Σ_{d≠c} Σ_j (w_dj r_dj)² ⋗ 1``. Within a channel its
conditions always combine (000's force and torque: the paper fires when either ratio reaches
1, a max-norm; the coupled point on their weighted 2-norm); at κ = 1 every channel tests the
norm of all conditions, a diagonal quadratic (Lyapunov-like) geometry over the channels; at
κ = 0 with unit weights and one condition per channel it is the paper's condition per channel
(004's three axes). With ``refresh_all`` any channel's send (condition, heartbeat, first
instant) sends every channel.

Named points (``tests/test_family.py`` checks each against its stand-alone policy):

* the paper's rule: every factor 1, τ_min = 0, τ_max = ∞, p = 0, no first-instant send;
* the clock every K instants: τ_min = ∞, τ_max = (K - ½) T, first-instant send;
* the rule with a heartbeat per channel: τ_max = (H - ½) T;
* the rule gating a clock: τ_min = (F - ½) T;
* the rule with raised thresholds: factors other than 1 (000's a1, a2 up to Theorem 2's K2j);
* paper 004's error-time rule |r_i - r_i(t_k)| (t - t_k) > A_i: p = 1, τ_ref = 0.05 s;
* coupled at unit weights, κ = 0, without refresh_all, on a rule of one condition per channel
  (004's): the point without coupling.

Floors and heartbeats are given in sampling instants: a bound of K instants is reached K
instants after a transmission (:func:`~etsc_envs.triggers.base.instants_seconds`).
"""

from __future__ import annotations

import functools
import inspect
import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import gymnasium as gym
import numpy as np

from etsc_envs.core.jit import closure_jit, jit
from etsc_envs.core.json_files import (
    in_file,
    read_json_file,
    require_array,
    require_bool,
    require_env_id,
    require_mapping,
    require_number,
    require_string,
    require_strings,
)
from etsc_envs.triggers.base import (
    RuleTrigger,
    instants_seconds,
    policy_interface,
    time_since_transmission_indices,
    transmit_bits,
)

FORMAT = "etsc-envs/learned-trigger"
"""The ``format`` key of a learned trigger's JSON file."""
FORMAT_VERSION = 1

MAX_HIDDEN = 16
"""The widest hidden layer of the modulation network."""

MAX_EXPONENT = 4.0
"""|p| of a point stays within this: τ^4 spans 10^±4 over a decade of intervals."""

MODULATION_BOUND = 3.0
"""|g| is clipped here: the network scales a threshold or bound by at most e^3 ≈ 20 either way."""

REFERENCE_S: dict[str, float] = {
    "AttitudeTrackingTrigger": 0.05,
    "InnerFormationTrigger": 0.05,
    "InnerFormationErrorTimeTrigger": 0.05,
    "OrbitAttitudeTrigger": 0.05,
    "ClusterContainmentTrigger": 0.5,
    "AsteroidOrbitKeepingTrigger": 60.0,
}
"""τ_ref per paper trigger class (s): about the mean interval of the paper's rule, so that p
changes the thresholds little near it. 004's 0.05 s makes p = 1 the error-time rule at its
default areas (Π_i × 0.05 s, :data:`~etsc_envs.triggers.inner_formation.ERROR_TIME_REFERENCE_S`)."""


CHANNEL = "{channel}"
"""The placeholder of a per-channel input name (``s_norm{channel}``): channel c reads the name
with the suffix ``_c`` in its place (``s_norm_0`` … ``s_norm_5`` on paper 001's central
form), or with nothing where the trigger serves one agent whose observation names are
unsuffixed (``s_norm``, an agent of the PettingZoo form), the layouts of the paper triggers."""


def channel_name(name: str, channel: int | None) -> str:
    """The observation name input ``name`` reads on channel ``channel`` (``None``: the one
    channel of an agent's unsuffixed observation; see :data:`CHANNEL`)."""
    return name.replace(CHANNEL, "" if channel is None else f"_{channel}")


@dataclass(frozen=True)
class Modulation:
    """The state-dependent part of θ: ``g = clip(W3 tanh(W2 tanh(W1 x + b1) + b2) + b3)``
    on ``x = (obs[inputs] - mean) / scale``, three outputs (threshold, floor, heartbeat).

    ``inputs`` are observation names; the arrays are the layers' weights (``W1`` of shape
    ``(h1, len(inputs))``, ``W2`` ``(h2, h1)``, ``W3`` ``(3, h2)``). All-zero weights give
    g = 0, the plain family. Where a name holds :data:`CHANNEL` the network is **per
    channel**: the same weights evaluated once for each channel on that channel's inputs (its
    own follower's ‖s‖ on paper 001), each channel's g scaling its own threshold, floor and
    heartbeat, as one policy shared by the agents of a PettingZoo id reads each agent's own
    observation; names without it are read by every channel alike.
    """

    inputs: tuple[str, ...]
    mean: np.ndarray
    scale: np.ndarray
    w1: np.ndarray
    b1: np.ndarray
    w2: np.ndarray
    b2: np.ndarray
    w3: np.ndarray
    b3: np.ndarray

    def __post_init__(self) -> None:
        for name in self.inputs:
            rest = channel_name(name, None)
            if "{" in rest or "}" in rest:
                raise ValueError(
                    f"modulation.inputs: {name!r} holds braces other than {CHANNEL}, the only "
                    "placeholder of an input name"
                )
        for name in ("b1", "b2"):
            bias = np.asarray(getattr(self, name), dtype=np.float64)
            if bias.ndim != 1 or not 1 <= bias.size <= MAX_HIDDEN:
                raise ValueError(
                    f"modulation.{name} must be one row of 1..{MAX_HIDDEN} numbers, got shape "
                    f"{bias.shape}"
                )
        shapes = self.shapes(len(self.inputs), len(self.b1), len(self.b2))
        for name, shape in shapes.items():
            value = np.asarray(getattr(self, name), dtype=np.float64)
            if value.shape != shape or not np.all(np.isfinite(value)):
                raise ValueError(f"modulation.{name} must be finite of shape {shape}")
            object.__setattr__(self, name, value)
        if np.any(self.scale <= 0.0):
            raise ValueError("modulation.scale must be > 0")

    @staticmethod
    def shapes(n_inputs: int, h1: int, h2: int) -> dict[str, tuple[int, ...]]:
        """The shape of every array of a network on ``n_inputs`` inputs with hidden layers of
        ``h1`` and ``h2`` units (the compiled kernel reads them by these sizes)."""
        return {
            "mean": (n_inputs,),
            "scale": (n_inputs,),
            "w1": (h1, n_inputs),
            "b1": (h1,),
            "w2": (h2, h1),
            "b2": (h2,),
            "w3": (3, h2),
            "b3": (3,),
        }

    @classmethod
    def zeros(
        cls, inputs: tuple[str, ...], mean: np.ndarray, scale: np.ndarray, hidden: int
    ) -> Modulation:
        """The modulation with all weights zero (g = 0) on ``inputs``."""
        n = len(inputs)
        return cls(
            tuple(inputs),
            np.asarray(mean, dtype=np.float64),
            np.asarray(scale, dtype=np.float64),
            np.zeros((hidden, n)),
            np.zeros(hidden),
            np.zeros((hidden, hidden)),
            np.zeros(hidden),
            np.zeros((3, hidden)),
            np.zeros(3),
        )

    @property
    def hidden(self) -> tuple[int, int]:
        return len(self.b1), len(self.b2)

    @property
    def per_channel(self) -> bool:
        """Whether each channel evaluates the network on its own inputs (:data:`CHANNEL`)."""
        return any(CHANNEL in name for name in self.inputs)

    def channel_inputs(self, channel: int | None) -> tuple[str, ...]:
        """The observation names channel ``channel`` reads (``None``: the one channel of an
        agent's unsuffixed observation; see :data:`CHANNEL`)."""
        return tuple(channel_name(name, channel) for name in self.inputs)

    def input_columns(self, names: tuple[str, ...], channels: int) -> list[list[int]]:
        """The columns of an observation with these names that the network reads: one set
        per channel for a per-channel network on ``channels`` channels, else one set;
        ``ValueError`` naming the inputs that are not observations here."""
        unsuffixed = self.channel_inputs(None)
        if not self.per_channel or (channels == 1 and all(n in names for n in unsuffixed)):
            sets = [unsuffixed]  # every channel's inputs, or one agent's own observation
        else:
            sets = [self.channel_inputs(c) for c in range(channels)]
        missing = [name for inputs in sets for name in inputs if name not in names]
        if missing:
            raise ValueError(f"modulation.inputs {missing} are not observations here")
        return [[names.index(name) for name in inputs] for inputs in sets]

    @property
    def weights(self) -> np.ndarray:
        """The searched weights, flat: W1, b1, W2, b2, W3, b3."""
        return np.concatenate(
            [a.ravel() for a in (self.w1, self.b1, self.w2, self.b2, self.w3, self.b3)]
        )

    def with_weights(self, flat: np.ndarray) -> Modulation:
        """The same inputs and normalisation with the weights ``flat`` (see :attr:`weights`)."""
        flat = np.asarray(flat, dtype=np.float64)
        parts = []
        offset = 0
        for array in (self.w1, self.b1, self.w2, self.b2, self.w3, self.b3):
            parts.append(flat[offset : offset + array.size].reshape(array.shape))
            offset += array.size
        if offset != flat.size:
            raise ValueError(f"modulation weights: expected {offset} numbers, got {flat.size}")
        return Modulation(self.inputs, self.mean, self.scale, *parts)

    def to_json(self) -> dict[str, Any]:
        return {
            "inputs": list(self.inputs),
            **{
                name: getattr(self, name).tolist()
                for name in ("mean", "scale", "w1", "b1", "w2", "b2", "w3", "b3")
            },
        }

    @classmethod
    def from_json(cls, data: Any, key: str = "modulation") -> Modulation:
        """The network of the JSON form ``data`` (:meth:`to_json`), every array checked for its
        shape and finiteness (``ValueError`` naming the key, under ``key``)."""
        names = ("inputs", "mean", "scale", "w1", "b1", "w2", "b2", "w3", "b3")
        data = require_mapping(data, key, names, names)
        inputs = require_strings(data["inputs"], f"{key}.inputs")
        if not inputs:
            raise ValueError(f"key {key + '.inputs'!r} must name at least one observation")
        widths = [len(require_array(data[name], f"{key}.{name}", (None,))) for name in ("b1", "b2")]
        for name, width in zip(("b1", "b2"), widths, strict=True):
            if not 1 <= width <= MAX_HIDDEN:
                raise ValueError(f"key {f'{key}.{name}'!r} must hold 1..{MAX_HIDDEN} numbers")
        arrays = {
            name: require_array(data[name], f"{key}.{name}", shape)
            for name, shape in cls.shapes(len(inputs), *widths).items()
        }
        if np.any(arrays["scale"] <= 0.0):
            raise ValueError(f"key {key + '.scale'!r} must hold numbers > 0")
        return cls(inputs, **arrays)


@dataclass(frozen=True)
class Coupling:
    """How a coupled point's channels decide together (see the module docstring).

    Args:
        weights: w > 0, one per condition of the rule: channel-major, each channel's
            conditions in the rule's order (004: x, y, z; 000: torque, force).
        strength: κ in [0, 1], how much the other channels' ratios count in a channel's
            condition (1: every channel tests the weighted norm).
        refresh_all: whether any channel's send sends every channel.
    """

    weights: tuple[float, ...]
    strength: float = 1.0
    refresh_all: bool = True

    def __post_init__(self) -> None:
        weights = tuple(float(weight) for weight in self.weights)
        if not weights or not all(math.isfinite(w) and w > 0.0 for w in weights):
            raise ValueError(
                f"coupling.weights must be one finite weight > 0 per condition, got "
                f"{self.weights!r}"
            )
        object.__setattr__(self, "weights", weights)
        strength = float(self.strength)
        if not 0.0 <= strength <= 1.0:
            raise ValueError(f"coupling.strength must be a number in [0, 1], got {self.strength!r}")
        object.__setattr__(self, "strength", strength)
        object.__setattr__(
            self, "refresh_all", require_bool(self.refresh_all, "coupling.refresh_all")
        )

    def to_json(self) -> dict[str, Any]:
        return {
            "weights": list(self.weights),
            "strength": self.strength,
            "refresh_all": self.refresh_all,
        }

    @classmethod
    def from_json(cls, data: Any, key: str = "coupling") -> Coupling:
        """The coupling of the JSON form ``data`` (:meth:`to_json`; ``strength`` and
        ``refresh_all`` default to 1 and true), each key checked (``ValueError`` naming it)."""
        data = require_mapping(data, key, ("weights", "strength", "refresh_all"), ("weights",))
        weights = require_array(data["weights"], f"{key}.weights", (None,))
        if weights.size == 0 or not np.all(weights > 0.0):
            raise ValueError(
                f"key '{key}.weights' must hold one weight > 0 per condition, got "
                f"{data['weights']!r}"
            )
        return cls(
            weights=tuple(float(weight) for weight in weights),
            strength=require_number(
                data.get("strength", 1.0), f"{key}.strength", low=0.0, high=1.0
            ),
            refresh_all=require_bool(data.get("refresh_all", True), f"{key}.refresh_all"),
        )


def _non_negative_instants(name: str, value: Any) -> float:
    value = float(value)
    if math.isnan(value) or value < 0.0:
        raise ValueError(f"{name} must be a number >= 0 (sampling instants; inf for none)")
    return value


@dataclass(frozen=True)
class FamilyPoint:
    """θ, one point of a paper's trigger family (see the module docstring).

    Args:
        factors: factor name (the paper trigger's ``threshold_groups``) → its multiplier of
            the paper's threshold keywords; names left out stay at 1.
        floor_instants: τ_min in sampling instants (0: none).
        heartbeat_instants: τ_max in sampling instants (``inf``: none).
        exponent: p, the time exponent of the weighted condition.
        first_instant: send on every channel at the episode's first instant.
        modulation: the state-dependent network, or ``None`` (g = 0).
        coupling: how the channels decide together (:class:`Coupling`), or ``None`` for the
            paper's condition per channel.
    """

    factors: Mapping[str, float] = field(default_factory=dict)
    floor_instants: float = 0.0
    heartbeat_instants: float = math.inf
    exponent: float = 0.0
    first_instant: bool = False
    modulation: Modulation | None = None
    coupling: Coupling | None = None

    def __post_init__(self) -> None:
        factors = {}
        for name, value in dict(self.factors).items():
            value = float(value)
            if not math.isfinite(value) or value <= 0.0:
                raise ValueError(f"factors.{name} must be a finite number > 0, got {value!r}")
            factors[str(name)] = value
        object.__setattr__(self, "factors", factors)
        object.__setattr__(
            self, "floor_instants", _non_negative_instants("floor_instants", self.floor_instants)
        )
        heartbeat = _non_negative_instants("heartbeat_instants", self.heartbeat_instants)
        if heartbeat < 1.0:
            raise ValueError("heartbeat_instants must be >= 1 (sampling instants; inf for none)")
        object.__setattr__(self, "heartbeat_instants", heartbeat)
        exponent = float(self.exponent)
        if not math.isfinite(exponent) or abs(exponent) > MAX_EXPONENT:
            raise ValueError(
                f"exponent must be a number in [-{MAX_EXPONENT:g}, {MAX_EXPONENT:g}], "
                f"got {self.exponent!r}"
            )
        object.__setattr__(self, "exponent", exponent)
        object.__setattr__(self, "first_instant", require_bool(self.first_instant, "first_instant"))
        if self.coupling is not None and not isinstance(self.coupling, Coupling):
            raise ValueError(f"coupling must be a Coupling or None, got {self.coupling!r}")

    @classmethod
    def clock(cls, every: int) -> FamilyPoint:
        """The clock every ``every`` instants (:class:`~etsc_envs.triggers.base.ClockTrigger`)."""
        return cls(floor_instants=math.inf, heartbeat_instants=every, first_instant=True)

    def to_json(self) -> dict[str, Any]:
        return {
            "factors": dict(self.factors),
            "floor_instants": _json_number(self.floor_instants),
            "heartbeat_instants": _json_number(self.heartbeat_instants),
            "exponent": self.exponent,
            "first_instant": self.first_instant,
            "modulation": None if self.modulation is None else self.modulation.to_json(),
            **({} if self.coupling is None else {"coupling": self.coupling.to_json()}),
        }

    @classmethod
    def from_json(cls, data: Any, key: str = "point") -> FamilyPoint:
        """The point of the JSON form ``data`` (:meth:`to_json`; left-out keys take their
        defaults), each key checked for its kind and range (``ValueError`` naming the key,
        under ``key``)."""
        data = require_mapping(data, key, POINT_KEYS)
        factors = require_mapping(data.get("factors", {}), f"{key}.factors")
        modulation = data.get("modulation")
        coupling = data.get("coupling")
        return cls(
            factors={
                name: require_number(value, f"{key}.factors.{name}", low=0.0, low_open=True)
                for name, value in factors.items()
            },
            floor_instants=require_number(
                data.get("floor_instants", 0.0), f"{key}.floor_instants", low=0.0, infinity=True
            ),
            heartbeat_instants=require_number(
                data.get("heartbeat_instants", "inf"),
                f"{key}.heartbeat_instants",
                low=1.0,
                infinity=True,
            ),
            exponent=require_number(
                data.get("exponent", 0.0), f"{key}.exponent", low=-MAX_EXPONENT, high=MAX_EXPONENT
            ),
            first_instant=require_bool(data.get("first_instant", False), f"{key}.first_instant"),
            modulation=(
                None
                if modulation is None
                else Modulation.from_json(modulation, f"{key}.modulation")
            ),
            coupling=None if coupling is None else Coupling.from_json(coupling, f"{key}.coupling"),
        )


def _json_number(value: float) -> float | str:
    """``value``, with infinity as the string ``"inf"`` (JSON has no infinity)."""
    return "inf" if math.isinf(value) else value


POINT_KEYS = (
    "factors",
    "floor_instants",
    "heartbeat_instants",
    "exponent",
    "first_instant",
    "modulation",
    "coupling",
)
"""The keys of a point's JSON form."""


@jit
def dense_layer(parameters, offset, inputs, out, squash):
    """One layer of the modulation network: ``out = W inputs + b`` (``tanh`` of it if
    ``squash``), with W (row-major, ``len(out) × len(inputs)``) then b read from
    ``parameters`` at ``offset``; returns the offset after them."""
    n_in = inputs.shape[0]
    n_out = out.shape[0]
    for j in range(n_out):
        total = parameters[offset + n_out * n_in + j]
        for i in range(n_in):
            total += parameters[offset + j * n_in + i] * inputs[i]
        out[j] = np.tanh(total) if squash else total
    return offset + n_out * n_in + n_out


@jit
def modulation_outputs(observation, indices, parameters, first_input, n_inputs, q, h1, h2):
    """The network's clipped outputs ``g = (g_h, g_min, g_max)`` on the observation entries
    ``indices[first_input : first_input + n_inputs]``, its parameters (mean, scale, W1, b1,
    W2, b2, W3, b3) read from ``parameters`` at ``q``."""
    x = np.empty(n_inputs)
    for i in range(n_inputs):
        x[i] = (float(observation[indices[first_input + i]]) - parameters[q + i]) / (
            parameters[q + n_inputs + i]
        )
    q += 2 * n_inputs
    hidden1 = np.empty(h1)
    q = dense_layer(parameters, q, x, hidden1, True)
    hidden2 = np.empty(h2)
    q = dense_layer(parameters, q, hidden1, hidden2, True)
    g = np.empty(3)
    dense_layer(parameters, q, hidden2, g, False)
    for j in range(3):
        g[j] = min(max(g[j], -MODULATION_BOUND), MODULATION_BOUND)
    return g


@jit
def coupled_send(observation, time_indices, coupling, statistic, threshold, limits, strict, out):
    """A coupled point's decision (the module docstring) into ``out``; ``coupling`` holds 1, κ,
    refresh-all (1 or 0) and the conditions' weights, ``limits`` the floor, heartbeat and
    first-instant times (s), p and the thresholds' scale e^{g_h} τ_ref^p. A condition whose
    threshold side is 0 counts as ratio ∞ where its statistic side is positive, 0 where it is
    not."""
    floor_s, heartbeat_s, first_s, exponent, threshold_scale = limits
    channels = out.shape[0]
    per_channel = statistic.shape[0] // channels
    strength = coupling[1]
    own = np.zeros(channels)
    for channel in range(channels):
        weight = float(observation[time_indices[channel]]) ** exponent
        for j in range(per_channel):
            k = channel * per_channel + j
            side = statistic[k] * weight
            bound = threshold[k] * threshold_scale
            ratio = side / bound if bound > 0.0 else (np.inf if side > 0.0 else 0.0)
            own[channel] += (coupling[3 + k] * ratio) ** 2
    total = own.sum()
    any_fires = 0
    for channel in range(channels):
        elapsed = float(observation[time_indices[channel]])
        fires = 0
        if elapsed < first_s or elapsed >= heartbeat_s:
            fires = 1
        elif elapsed >= floor_s:
            mixed = own[channel]
            if strength > 0.0:
                mixed += strength * (total - own[channel])
            if mixed > 1.0 if strict else mixed >= 1.0:
                fires = 1
        out[channel] = fires
        any_fires = max(any_fires, fires)
    if coupling[2] > 0.0 and any_fires:
        for channel in range(channels):
            out[channel] = 1


@functools.cache
def family_rule(
    condition: Callable[..., None], conditions_per_channel: int, strict: bool
) -> Callable[..., None]:
    """The compiled kernel ``rule(observation, indices, parameters, out)`` of a paper's family
    (the module docstring's decision), over the paper's ``condition`` kernel.

    ``indices`` holds the paper's indices, then the C channels' time-since-transmission
    indices, then the network's input indices (one set read by every channel, or C sets,
    channel-major, each channel's network reading its own), then six counts: the paper's
    indices, the paper's parameters, the input sets (1 or C), the inputs of a set, and the two
    hidden widths (0 for no network).
    ``parameters`` holds the paper's (thresholds already scaled), then τ_min, τ_max, p,
    τ_ref, τ_first (s), then 1 for a coupled point (else 0), κ, 1 to refresh all channels
    (else 0) and the weights of the C × J conditions, then the network's mean, scale, W1, b1,
    W2, b2, W3, b3 (one network, whichever set it reads).
    """

    @closure_jit
    def rule(observation, indices, parameters, out):
        m = indices.shape[0]
        n_rule_indices = indices[m - 6]
        p0 = indices[m - 5]
        input_sets = indices[m - 4]
        n_inputs = indices[m - 3]
        h1 = indices[m - 2]
        h2 = indices[m - 1]
        channels = out.shape[0]
        n_conditions = channels * conditions_per_channel
        network_start = p0 + 8 + n_conditions
        first_input = n_rule_indices + channels
        g_threshold = 0.0
        g_floor = 0.0
        g_heartbeat = 0.0
        if h1 > 0 and input_sets == 1:
            g = modulation_outputs(
                observation, indices, parameters, first_input, n_inputs, network_start, h1, h2
            )
            g_threshold = g[0]
            g_floor = g[1]
            g_heartbeat = g[2]
        floor_s = parameters[p0] * np.exp(g_floor)
        heartbeat_s = parameters[p0 + 1] * np.exp(g_heartbeat)
        exponent = parameters[p0 + 2]
        threshold_scale = np.exp(g_threshold) * parameters[p0 + 3] ** exponent
        first_s = parameters[p0 + 4]
        statistic = np.empty(n_conditions)
        threshold = np.empty(n_conditions)
        condition(observation, indices, parameters, statistic, threshold)
        if parameters[p0 + 5] > 0.0:
            coupled_send(
                observation,
                indices[n_rule_indices : n_rule_indices + channels],
                parameters[p0 + 5 : p0 + 8 + n_conditions],
                statistic,
                threshold,
                (floor_s, heartbeat_s, first_s, exponent, threshold_scale),
                strict,
                out,
            )
            return
        for channel in range(channels):
            elapsed = float(observation[indices[n_rule_indices + channel]])
            if h1 > 0 and input_sets > 1:  # this channel's network on its own inputs
                g = modulation_outputs(
                    observation,
                    indices,
                    parameters,
                    first_input + channel * n_inputs,
                    n_inputs,
                    network_start,
                    h1,
                    h2,
                )
                floor_s = parameters[p0] * np.exp(g[1])
                heartbeat_s = parameters[p0 + 1] * np.exp(g[2])
                threshold_scale = np.exp(g[0]) * parameters[p0 + 3] ** exponent
            fires = 0
            if elapsed < first_s or elapsed >= heartbeat_s:
                fires = 1
            elif elapsed >= floor_s:
                weight = elapsed**exponent
                for j in range(conditions_per_channel):
                    k = channel * conditions_per_channel + j
                    if strict:
                        if statistic[k] * weight > threshold[k] * threshold_scale:
                            fires = 1
                    elif statistic[k] * weight >= threshold[k] * threshold_scale:
                        fires = 1
            out[channel] = fires

    return rule


def require_factors(
    trigger_class: type[RuleTrigger], factors: Mapping[str, float], key: str = "factors"
) -> None:
    """``ValueError`` naming ``key`` for a factor that is none of ``trigger_class``'s groups or
    lies outside the paper's bound."""
    groups = trigger_class.threshold_groups
    unknown = set(factors) - set(groups)
    if unknown:
        raise ValueError(
            f"key {key!r}: {sorted(unknown)} are not factors of {trigger_class.__name__}; "
            f"allowed {sorted(groups)}"
        )
    for name, value in factors.items():
        low, high = trigger_class.factor_bounds.get(name, (0.0, math.inf))
        if not low < value < high:
            raise ValueError(f"key '{key}.{name}' must lie in ({low:g}, {high:g}), got {value!r}")


def require_keywords(
    trigger_class: type[RuleTrigger], keywords: Any, key: str = "keywords"
) -> dict[str, float]:
    """``keywords`` when it maps keywords of ``trigger_class`` that its factors leave alone
    (paper 001's ν) to finite numbers (``ValueError`` naming ``key``)."""
    parameters = list(inspect.signature(trigger_class.__init__).parameters)[4:]
    thresholds = {name for names in trigger_class.threshold_groups.values() for name in names}
    allowed = [name for name in parameters if name not in thresholds]
    keywords = require_mapping(keywords, key, allowed)
    return {name: require_number(value, f"{key}.{name}") for name, value in keywords.items()}


def scaled_thresholds(
    trigger_class: type[RuleTrigger], factors: Mapping[str, float]
) -> dict[str, float]:
    """The paper's threshold keywords of ``trigger_class`` each multiplied by its group's factor
    (``ValueError`` naming an unknown factor or one outside the paper's bound)."""
    require_factors(trigger_class, factors)
    groups = trigger_class.threshold_groups
    paper = trigger_class.paper_thresholds()
    return {
        keyword: paper[keyword] * float(factors.get(name, 1.0))
        for name, keywords in groups.items()
        for keyword in keywords
    }


@functools.cache
def family_trigger_class(trigger_class: type[RuleTrigger]) -> type[RuleTrigger]:
    """The :class:`RuleTrigger` class of ``trigger_class``'s family (one per paper, so the
    compiled loop compiles each family once), built with ``(observation_space, action_space,
    observation_names, point, sampling_period_s, **keywords)``: ``point`` a
    :class:`FamilyPoint`, ``keywords`` other keywords of ``trigger_class`` that the factors
    leave alone (paper 001's ν)."""
    if trigger_class.condition is None:
        raise ValueError(f"{trigger_class.__name__} has no paper condition to generalise")
    kernel = family_rule(
        trigger_class.condition, trigger_class.conditions_per_channel, trigger_class.strict
    )
    # Built with the paper trigger's own constructor arguments (spaces, observation names,
    # thresholds), which RuleTrigger's signature does not describe.
    paper_trigger = cast(Callable[..., RuleTrigger], trigger_class)

    class FamilyTrigger(RuleTrigger):
        rule = staticmethod(kernel)
        paper_class = trigger_class

        def __init__(
            self,
            observation_space: gym.Space,
            action_space: gym.Space,
            observation_names: tuple[str, ...],
            point: FamilyPoint,
            sampling_period_s: float,
            **keywords: Any,
        ) -> None:
            if not isinstance(point, FamilyPoint):
                raise ValueError(f"point must be a FamilyPoint, got {type(point).__name__}")
            period = float(sampling_period_s)
            if not math.isfinite(period) or period <= 0.0:
                raise ValueError(f"sampling_period_s must be a finite number > 0, got {period!r}")
            thresholds = scaled_thresholds(trigger_class, point.factors)
            inner = paper_trigger(
                observation_space, action_space, observation_names, **keywords, **thresholds
            )
            self.point = point
            self.inner = inner
            names = tuple(observation_names)
            bits = transmit_bits(action_space)
            channels = 1 if bits is None else bits
            times = time_since_transmission_indices(names, channels)
            bounds = [
                instants_seconds(point.floor_instants, period),
                instants_seconds(point.heartbeat_instants, period),
                point.exponent,
                REFERENCE_S[trigger_class.__name__],
                0.5 * period if point.first_instant else 0.0,
            ]
            # 1, κ, refresh-all and the conditions' weights; zeros for the paper's geometry
            coupling = point.coupling
            conditions = channels * trigger_class.conditions_per_channel
            if coupling is None:
                coupled = [0.0] * (conditions + 3)
            elif len(coupling.weights) == conditions:
                coupled = [1.0, coupling.strength, float(coupling.refresh_all), *coupling.weights]
            else:
                raise ValueError(
                    f"point.coupling.weights must hold one weight per condition ({conditions}), "
                    f"got {len(coupling.weights)}"
                )
            modulation = point.modulation
            if modulation is None:
                inputs: list[int] = []
                network: list[float] = []
                input_sets, n_inputs, hidden = 1, 0, (0, 0)
            else:
                columns = modulation.input_columns(names, channels)
                if len(columns) > 1 and coupling is not None:
                    raise ValueError(
                        f"point.modulation: a network per channel ({CHANNEL} in its inputs) "
                        "cannot steer a coupled point, whose channels decide together"
                    )
                inputs = [column for own in columns for column in own]
                input_sets, n_inputs = len(columns), len(modulation.inputs)
                network = [
                    *modulation.mean,
                    *modulation.scale,
                    *modulation.weights,
                ]
                hidden = modulation.hidden
            super().__init__(
                observation_space,
                action_space,
                indices=[
                    *inner.rule_indices,
                    *times,
                    *inputs,
                    len(inner.rule_indices),
                    len(inner.rule_parameters),
                    input_sets,
                    n_inputs,
                    *hidden,
                ],
                parameters=[
                    *inner.rule_parameters,
                    *bounds,
                    *coupled,
                    *network,
                ],
                keywords={"point": point, "sampling_period_s": period, **keywords},
            )

    FamilyTrigger.__name__ = FamilyTrigger.__qualname__ = f"{trigger_class.__name__}Family"
    return FamilyTrigger


def family_trigger(
    trigger_class: type[RuleTrigger],
    point: FamilyPoint,
    keywords: Mapping[str, Any],
    observation_space: gym.Space,
    action_space: gym.Space,
    observation_names: tuple[str, ...],
    sampling_period_s: float,
) -> RuleTrigger:
    """The family of ``trigger_class`` at ``point`` (with the trigger's fixed ``keywords``) as
    a trigger policy for an env of these spaces, observation names and sampling period."""
    # Built with FamilyTrigger's own constructor arguments (family_trigger_class).
    family = cast(Callable[..., RuleTrigger], family_trigger_class(trigger_class))
    return family(
        observation_space, action_space, observation_names, point, sampling_period_s, **keywords
    )


HAND_KEYS = ("rule", "menu", "chosen_on", "chosen_by", "validation_front", "replaces")
"""The ``hand`` section of a hand point's file: the rule in words, the menu's labels, the set
that chose it, how, the record of that choice and what the point replaces."""


def read_hand(value: Any) -> dict[str, Any]:
    """A file's ``hand`` section, checked (``{}`` where the file is a searched trigger's)."""
    hand = require_mapping(value, "hand", HAND_KEYS)
    if not hand:
        return hand
    require_mapping(hand, "hand", HAND_KEYS, HAND_KEYS[:3])
    for name in HAND_KEYS:
        if name == "menu":
            require_strings(hand[name], "hand.menu")
        elif name in hand:
            require_string(hand[name], f"hand.{name}")
    return hand


@dataclass(frozen=True)
class LearnedTrigger:
    """A point of a trigger family as a file: the environment id, the paper trigger class
    whose family it belongs to, the point θ, the paper trigger's other keywords, and where the
    point came from — ``search``, what ``agents.search`` recorded (penalty, seeds, scores), for
    a learned trigger; ``hand``, the menu a hand-designed rule was chosen from and the
    validation record that chose it (``models/<id>_hand.json``). Data for the report."""

    env_id: str
    family: str
    point: FamilyPoint
    keywords: Mapping[str, Any] = field(default_factory=dict)
    search: Mapping[str, Any] = field(default_factory=dict)
    hand: Mapping[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "env_id": self.env_id,
            "family": self.family,
            "point": self.point.to_json(),
            "keywords": dict(self.keywords),
            **({"search": dict(self.search)} if self.search else {}),
            **({"hand": dict(self.hand)} if self.hand else {}),
        }

    @classmethod
    def from_json(cls, data: Any) -> LearnedTrigger:
        """The learned trigger of the JSON form ``data`` (:meth:`to_json`), every key checked
        (``ValueError`` naming it): the format and version, an id of the suite and its paper's
        family, the point and the family's other keywords; ``search`` is the search's record,
        kept as data, and ``hand`` a hand point's provenance (:func:`read_hand`)."""
        from etsc_envs.papers import PAPER_IDS, paper_of  # the records import this module

        names = ("format", "version", "env_id", "family", "point", "keywords", "search", "hand")
        data = require_mapping(data, "", names)
        if data.get("format") != FORMAT:
            raise ValueError(f"key 'format' must be {FORMAT!r}, got {data.get('format')!r}")
        require_mapping(data, "", names, names[:5])
        if data["version"] != FORMAT_VERSION or isinstance(data["version"], bool):
            raise ValueError(
                f"key 'version' is {data['version']!r}; this suite reads {FORMAT_VERSION}"
            )
        env_id = require_string(data["env_id"], "env_id", PAPER_IDS)
        trigger_class = paper_of(env_id).trigger
        family = require_string(data["family"], "family", [trigger_class.__name__])
        point = FamilyPoint.from_json(data["point"])
        require_factors(trigger_class, point.factors, "point.factors")
        return cls(
            env_id=env_id,
            family=family,
            point=point,
            keywords=require_keywords(trigger_class, data.get("keywords", {})),
            search=require_mapping(data.get("search", {}), "search"),
            hand=read_hand(data.get("hand", {})),
        )

    def save(self, path: str | Path) -> None:
        from etsc_envs.core.files import atomic_write_text

        atomic_write_text(str(path), json.dumps(self.to_json(), indent=2) + "\n")

    @classmethod
    def load(cls, path: str | Path) -> LearnedTrigger:
        """The learned trigger in the JSON file ``path``, read by the suite's one JSON reader
        (:mod:`etsc_envs.core.json_files`; ``ValueError`` naming ``learned:PATH`` and the key
        for a file that is not one)."""
        where = f"learned:{path}"
        data = read_json_file(path, where)
        with in_file(where):
            return cls.from_json(data)

    def policy_for(self, env: Any) -> RuleTrigger:
        """The trigger policy of this point for ``env``: a Gymnasium env of the suite, or a
        PettingZoo parallel env (one policy for every agent, queried with their observations
        stacked); ``ValueError`` when ``env`` is another id's."""
        return self.trigger(*policy_interface(env), env_id=env_id_of(env))

    def trigger(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        sampling_period_s: float,
        env_id: str | None = None,
    ) -> RuleTrigger:
        """The trigger policy of this point for an env of these spaces and names (of the id
        ``env_id``, which must be the file's, where known)."""
        from etsc_envs.papers import PAPERS  # the records import the trigger modules

        require_env_id(self.env_id, env_id)
        families = {paper.trigger.__name__: paper.trigger for paper in PAPERS}
        if self.family not in families:
            raise ValueError(f"family must be one of {sorted(families)}, got {self.family!r}")
        return family_trigger(
            families[self.family],
            self.point,
            self.keywords,
            observation_space,
            action_space,
            observation_names,
            sampling_period_s,
        )


def env_id_of(env: Any) -> str | None:
    """The suite's id of ``env`` (a Gymnasium env made from its id, or the PettingZoo env),
    or ``None`` for an env built another way."""
    from etsc_envs.registry import PETTINGZOO_ENV_IDS

    if callable(getattr(env, "observation_space", None)):  # a PettingZoo env
        return next(iter(PETTINGZOO_ENV_IDS))
    spec = getattr(env, "spec", None) or getattr(env.unwrapped, "spec", None)
    return None if spec is None else spec.id.removeprefix("etsc_envs:")

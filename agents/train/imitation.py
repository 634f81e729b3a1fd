"""Start a learned trigger from the paper's trigger: behaviour cloning before reinforcement.

A random initial policy transmits at half of all sampling instants, and its first transmit-
or-hold patterns are far from anything that keeps the loop accurate; with episodes of 10⁴–10⁵
instants, reinforcement learning alone then spends most of its budget rediscovering what the
paper's triggering rule already knows (in paper 004's loop, for example, PPO from scratch
lost the inner mass to the cavity wall for millions of steps). Cloning first makes the policy
act like the paper's rule, on the training distribution, and fits the value function to the
returns that rule earns; PPO then trades transmissions against accuracy from there.

:func:`imitate_paper_trigger` runs the paper's trigger on the training ``VecEnv`` (randomized
scenarios, through the same normalisation wrapper, whose statistics it thereby initialises),
then trains the policy's action head to reproduce its decisions (cross-entropy) and the value
head to predict the discounted returns of the collected episodes.

:func:`imitate_decision` does the same for self-triggered decisions
(:class:`etsc_envs.decisions.SelfTriggeredWrapper`): the demonstrator takes one fixed decision of
the set (the better of the paper's rule at some threshold and the best clock, chosen on the
validation set), and returns are discounted by the instants each decision lasted. A fitted
clone of one fixed decision agrees with it on the states the demonstrations visited only:
elsewhere (later times, larger errors) the network's output may leave it, and on papers 000
and 001 it did.
:func:`pin_decision` then makes the decision exact — the policy's mode at every observation —
so that the learner starts from the baseline itself and not from an approximation of it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.vec_env import VecEnv, VecNormalize

from etsc_envs.decisions import DecisionSet, FixedDecision
from etsc_envs.evaluation.policy_specs import episode_setup


def paper_trigger(env_id: str, env_kwargs: dict[str, Any]) -> Any:
    """The paper's triggering rule for the observations of ``env_id`` (one agent's, for a
    PettingZoo id), answering batches like an SB3 model."""
    setup = episode_setup(env_id, env_kwargs)
    policy = setup.make_policy("paper", {})
    setup.env.close()
    return policy


def collect_demonstrations(
    env: VecEnv, policy: Any, steps: int, gamma: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run ``policy`` on ``env`` for ``steps`` transitions (summed over sub-environments).

    Returns the observations the learner sees (normalised if ``env`` normalises), the
    policy's actions, and the discounted returns from each transition to the end of its
    episode or of the collection (a transition whose info gives ``elapsed_steps`` = n, a
    self-triggered decision, discounts what follows by ``gamma**n``).
    """
    rollout = max(steps // env.num_envs, 1)
    observation = env.reset()
    episode_start = np.ones(env.num_envs, dtype=bool)
    state = None
    observations, actions, rewards, dones, discounts = [], [], [], [], []
    for _ in range(rollout):
        raw = env.get_original_obs() if isinstance(env, VecNormalize) else observation
        action, state = policy.predict(raw, state=state, episode_start=episode_start)
        observations.append(observation)
        actions.append(action)
        observation, reward, done, infos = env.step(action)
        rewards.append(reward)
        dones.append(done)
        elapsed = np.array([info.get("elapsed_steps", 1) for info in infos], dtype=np.float64)
        discounts.append(gamma**elapsed)
        episode_start = done
    returns = np.zeros((rollout, env.num_envs), dtype=np.float32)
    following = np.zeros(env.num_envs, dtype=np.float32)
    for index in range(rollout - 1, -1, -1):
        following = rewards[index] + discounts[index] * following * (1.0 - dones[index])
        returns[index] = following
    return (
        np.concatenate(observations),
        np.concatenate(actions),
        returns.reshape(-1),
    )


def clone(
    model: BaseAlgorithm,
    observations: np.ndarray,
    actions: np.ndarray,
    returns: np.ndarray,
    epochs: int,
    batch_size: int,
    separate_heads: bool = False,
) -> dict[str, float]:
    """Fit ``model``'s policy to the demonstrated ``actions`` (negative log-likelihood) and its
    value head to ``returns`` (squared error, weighted as PPO's ``vf_coef``), with the model's
    own optimiser. With ``separate_heads`` each loss takes its own clipped gradient step per
    batch (self-triggered decisions: their returns, sums over whole intervals, are large
    enough at the start that the value loss's gradient would use up the clipped norm of a
    joint step). Returns the last epoch's mean losses and the policy's agreement with the
    demonstrations (deterministic actions)."""
    policy = model.policy
    policy.set_training_mode(True)
    device = policy.device
    count = len(observations)
    observation_tensor = torch.as_tensor(observations, device=device)
    if isinstance(model.action_space, spaces.Discrete):  # as PPO's own update feeds them
        action_tensor = torch.as_tensor(actions, device=device).long().flatten()
    else:
        action_tensor = torch.as_tensor(actions, device=device, dtype=torch.float32)
    return_tensor = torch.as_tensor(returns, device=device)
    value_weight = float(getattr(model, "vf_coef", 0.5))
    generator = np.random.default_rng(0)
    losses = {"action_loss": 0.0, "value_loss": 0.0}
    for _ in range(epochs):
        order = generator.permutation(count)
        sums = {"action_loss": 0.0, "value_loss": 0.0}
        for start in range(0, count, batch_size):
            batch = order[start : start + batch_size]
            values, log_prob, _ = policy.evaluate_actions(
                observation_tensor[batch], action_tensor[batch]
            )
            action_loss = -log_prob.mean()
            value_loss = torch.nn.functional.mse_loss(values.flatten(), return_tensor[batch])
            losses_to_step = (
                [action_loss, value_weight * value_loss]
                if separate_heads
                else [action_loss + value_weight * value_loss]
            )
            for loss in losses_to_step:
                policy.optimizer.zero_grad()
                loss.backward()
                torch.nn.utils.clip_grad_norm_(policy.parameters(), model.max_grad_norm)
                policy.optimizer.step()
            sums["action_loss"] += action_loss.item() * len(batch)
            sums["value_loss"] += value_loss.item() * len(batch)
        losses = {name: total / count for name, total in sums.items()}
    policy.set_training_mode(False)
    predicted, _ = policy.predict(observations, deterministic=True)
    agreement = float(np.mean(predicted.reshape(actions.shape) == actions))
    return {**losses, "agreement": agreement}


def imitate_paper_trigger(
    model: BaseAlgorithm, env_id: str, env_kwargs: dict[str, Any], steps: int, epochs: int
) -> dict[str, Any]:
    """Clone the paper's trigger into ``model`` (see the module docstring) from ``steps``
    transitions on the model's own training env; returns the fit's summary."""
    env = model.get_env()
    gamma = float(getattr(model, "gamma", 0.99))
    observations, actions, returns = collect_demonstrations(
        env, paper_trigger(env_id, env_kwargs), steps, gamma
    )
    batch_size = int(getattr(model, "batch_size", 256))
    summary = clone(model, observations, actions, returns, epochs, batch_size)
    return {
        "steps": len(observations),
        "demonstrated_transmit_rate": float(np.mean(actions)),
        **summary,
    }


def pin_decision(model: BaseAlgorithm, action: int, probability: float) -> float:
    """Set the action head of ``model`` (a categorical policy's last linear layer) so that the
    policy takes ``action`` with ``probability`` at every observation and shares ``1 -
    probability`` evenly among its other actions: weights zero, and a bias of ``log(p (n - 1) /
    (1 - p))`` on ``action`` over ``n`` actions. Its deterministic policy is then ``action``
    exactly; the zero weights still receive gradients, so PPO can make it depend on the state.
    Returns the bias margin."""
    if not 0.0 < probability < 1.0:
        raise ValueError(f"probability must be in (0, 1), got {probability!r}")
    head = model.policy.action_net
    count = head.out_features
    if not 0 <= action < count:
        raise ValueError(f"action must be in 0..{count - 1}, got {action!r}")
    margin = math.log(probability * (count - 1) / (1.0 - probability)) if count > 1 else 0.0
    with torch.no_grad():
        head.weight.zero_()
        head.bias.zero_()
        head.bias[action] = margin
    return margin


def imitate_decision(
    model: BaseAlgorithm,
    decisions: DecisionSet,
    label: str,
    steps: int,
    epochs: int,
    pinned_probability: float | None = None,
) -> dict[str, Any]:
    """Clone the decision ``label`` of ``decisions`` (``"paper x0.25"``, ``"hold 64"``) into
    ``model``, a learner of self-triggered decisions, from ``steps`` decisions on its own
    training env; with ``pinned_probability``, the action head is then pinned to the decision
    (:func:`pin_decision`; the fit still sets the value head and the observation statistics).
    Returns the fit's summary; where pinned, its ``agreement`` is the pinned policy's and
    ``clone_agreement`` the fit's."""
    action = decisions.action(label)
    env = model.get_env()
    gamma = float(getattr(model, "gamma", 0.99))
    observations, actions, returns = collect_demonstrations(
        env, FixedDecision(action), steps, gamma
    )
    batch_size = int(getattr(model, "batch_size", 256))
    summary = clone(model, observations, actions, returns, epochs, batch_size, separate_heads=True)
    described = label
    if pinned_probability is not None:
        pin_decision(model, action, pinned_probability)
        predicted, _ = model.policy.predict(observations, deterministic=True)
        summary["clone_agreement"] = summary["agreement"]
        summary["agreement"] = float(np.mean(predicted.reshape(actions.shape) == actions))
        described = f"{label}, pinned at probability {pinned_probability:g}"
    return {"steps": len(observations), "decision": described, **summary}

"""Accuracy of the compiled classical Runge–Kutta step of :mod:`etsc_envs.core.integration`.

Checked properties, each against a closed-form solution:

* exponential decay ``ẏ = -a y`` reaches ``exp(-a t)`` to ~1e-10 after 1 s with h = 1e-3;
* the global error on a harmonic oscillator is 4th order (halving h divides it by ~16);
* the energy of the undamped oscillator is conserved to 1e-9 (relative) over 10 periods with
  h = 1e-3 period (RK4 dissipates only ~(ωh)⁶/72 per step);
* explicit time dependence is evaluated at the right stage times (``ẏ = cos t`` gives
  ``sin t``), and ``args`` is passed through to the derivative unchanged;
* the step does not modify its input state in place.
"""

import itertools

import numpy as np
import pytest
from numpy.testing import assert_allclose

from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit


@jit
def exponential_decay(t, y, args):
    return -args[0] * y


@jit
def harmonic_oscillator(t, y, args):
    omega = args[0]
    out = np.empty(2)
    out[0] = y[1]
    out[1] = -omega * omega * y[0]
    return out


@jit
def cosine_forcing(t, y, args):
    return np.cos(t) * np.ones_like(y)


@jit
def linear_forcing(t, y, args):
    """``ẏ = c₀ + c₁ t``: two separate ``args`` entries, exact for RK4 (a polynomial in t)."""
    return (args[0] + args[1] * t) * np.ones_like(y)


decay_step = make_rk4_step(exponential_decay)
oscillator_step = make_rk4_step(harmonic_oscillator)
cosine_step = make_rk4_step(cosine_forcing)
linear_step = make_rk4_step(linear_forcing)


def integrate(step, y0, t0, h, n_steps, args):
    y = np.array(y0, dtype=float)
    for k in range(n_steps):
        y = step(t0 + k * h, y, h, args)
    return y


def oscillator_exact(y0, omega, t):
    x0, v0 = y0
    return np.array(
        [
            x0 * np.cos(omega * t) + v0 / omega * np.sin(omega * t),
            -x0 * omega * np.sin(omega * t) + v0 * np.cos(omega * t),
        ]
    )


@pytest.mark.parametrize("rate", [0.5, 1.0, 3.0])
def test_exponential_decay_matches_exp(rate):
    y0 = np.array([1.0, -2.0, 0.25])
    y = integrate(decay_step, y0, 0.0, 1e-3, 1000, (rate,))
    assert_allclose(y, y0 * np.exp(-rate * 1.0), rtol=1e-10, atol=0)


def test_harmonic_oscillator_is_fourth_order():
    omega = 2.0
    y0 = np.array([1.0, 0.5])
    t_end = 2.0
    errors = []
    for n_steps in (50, 100, 200):
        y = integrate(oscillator_step, y0, 0.0, t_end / n_steps, n_steps, (omega,))
        errors.append(np.linalg.norm(y - oscillator_exact(y0, omega, t_end)))
    for coarse, fine in itertools.pairwise(errors):
        assert 12.0 < coarse / fine < 20.0


def test_undamped_oscillator_conserves_energy():
    omega = 3.0
    period = 2.0 * np.pi / omega
    h = 1e-3 * period
    y0 = np.array([0.7, -1.1])

    def energy(y):
        return 0.5 * y[1] ** 2 + 0.5 * omega**2 * y[0] ** 2

    y = integrate(oscillator_step, y0, 0.0, h, 10_000, (omega,))
    assert_allclose(energy(y), energy(y0), rtol=1e-9, atol=0)
    # After exactly 10 periods the state is back where it started, up to the RK4 phase lag
    # of ~(ωh)⁵/120 per step (~1e-9 rad in total).
    assert_allclose(y, y0, rtol=0, atol=1e-8)


def test_cosine_forcing_integrates_to_sine():
    t0, h, n_steps = 0.3, 1e-3, 2000
    y0 = np.array([0.0, 1.0])
    y = integrate(cosine_step, y0, t0, h, n_steps, ())
    t_end = t0 + h * n_steps
    assert_allclose(y, y0 + np.sin(t_end) - np.sin(t0), rtol=0, atol=1e-12)


def test_polynomial_forcing_is_exact_and_args_pass_through():
    """A single step of ``ẏ = c₀ + c₁ t`` from t = 1 is exact: Δy = c₀ h + c₁ (t h + h²/2)."""
    t, h, c0, c1 = 1.0, 0.5, 2.0, -3.0
    y = linear_step(t, np.array([1.0]), h, (c0, c1))
    assert_allclose(y, [1.0 + c0 * h + c1 * (t * h + 0.5 * h * h)], rtol=0, atol=1e-15)


def test_step_does_not_modify_input_state():
    y0 = np.array([1.0, 0.5])
    before = y0.copy()
    y1 = oscillator_step(0.0, y0, 0.1, (2.0,))
    assert_allclose(y0, before, rtol=0, atol=0)
    assert not np.shares_memory(y0, y1)

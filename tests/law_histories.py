"""Displacement and normal-load histories for the contact-law tests.

Displacements are in units of the law's macroslip displacement ``x_slip = 2 fy
/ kt`` times ``scale`` so that the same shapes exercise microslip and
macroslip for any parameters.
"""

from __future__ import annotations

import numpy as np


def through(points, steps):
    """Piecewise-linear path through ``points`` with ``steps`` samples per segment
    (int or sequence), the first point included once."""
    points = np.asarray(points, dtype=float)
    if np.isscalar(steps):
        steps = [int(steps)] * (len(points) - 1)
    parts = [points[:1]]
    for a, b, k in zip(points[:-1], points[1:], steps):
        parts.append(np.linspace(a, b, int(k) + 1)[1:])
    return np.concatenate(parts)


def random_walk(rng, n, step):
    """Gaussian random walk from 0 (reversals at almost every sample)."""
    return np.concatenate(([0.0], np.cumsum(rng.normal(scale=step, size=n - 1))))


def random_reversals(rng, nrev, amp, steps=(3, 40)):
    """Random reversal points in [-amp, amp], random sample counts between them."""
    pts = np.concatenate(([0.0], rng.uniform(-amp, amp, nrev)))
    return through(pts, rng.integers(steps[0], steps[1], nrev))


def nested_then_growing(depth, amp, steps=20, shrink=0.9):
    """Deeply nested loops: reversal points amp, -amp shrink, amp shrink^2, ...
    (``depth`` of them), then growing back out, each excursion 5 % past the
    earlier reversal point of its sign, so every pair is wiped in turn."""
    inward = [amp * shrink**k * (-1) ** k for k in range(depth)]
    sign = -np.sign(inward[-1])
    outward = []
    for j in range(depth - 2, -1, -1):
        outward.append(sign * amp * shrink**j * 1.05)
        sign = -sign
    return through([0.0] + inward + outward, steps)


def growing_sine(amp, cycles, steps_per_cycle):
    """Sine whose amplitude grows linearly from 0 to ``amp``."""
    t = np.linspace(0.0, cycles, int(cycles * steps_per_cycle) + 1)
    return amp * (t / cycles) * np.sin(2.0 * np.pi * t)


def decaying_sine(amp, cycles, steps_per_cycle, offset=0.0):
    """Sine whose amplitude decays linearly to 5 % (nested loops), plus offset."""
    t = np.linspace(0.0, cycles, int(cycles * steps_per_cycle) + 1)
    return offset + amp * (1.0 - 0.95 * t / cycles) * np.sin(2.0 * np.pi * t)


def normal_history(rng, n, n_ref, eta, separation_allowed=True):
    """Smooth random normal load n_ref (1 + eta * s(t)), s a random
    quasi-periodic signal in [-1, 1]; with eta > 1 it separates."""
    phase = np.cumsum(rng.uniform(0.0, 0.15, n))
    s = np.sin(phase + rng.uniform(0, 2 * np.pi))
    N = n_ref * (1.0 + eta * s)
    if not separation_allowed:
        N = np.maximum(N, 0.05 * n_ref)
    return N

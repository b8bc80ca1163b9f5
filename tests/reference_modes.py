"""Independent plain-Python references for the nonlinear-mode tests.

Nothing here imports jointdyn: the describing function of a single-DOF
oscillator with a Jenkins element or a uniform Iwan contact at constant
normal load is computed from the exact steady Masing loop, written out from
the backbones of docs/model.md section 2, by adaptive quadrature
(scipy.integrate.quad with the kinks as break points).

One harmonic, x = a cos(theta): on the unloading half cycle (theta from 0
to pi) the force is ``T = Tb(a) - 2 Tb((a - x) / 2)`` (Masing), on the
other half ``T(theta + pi) = -T(theta)``; the first-harmonic coefficients
are ``T1c = (2/pi) int_0^pi T cos``, ``T1s = (2/pi) int_0^pi T sin``, and
(docs/model.md section 9)::

    omega^2 = (k + T1c / a) / m,   E = -pi a T1s,   D = E / (2 pi m omega^2 a^2).
"""

from __future__ import annotations

import math

from scipy.integrate import quad


def jenkins_backbone(kt: float, fy: float):
    """Virgin curve of one Jenkins element: Tb(x) = min(kt x, fy) (x >= 0), with its kink."""
    return (lambda x: min(kt * x, fy)), [fy / kt]


def iwan_backbone(kt: float, fy: float):
    """Virgin curve of the uniform Iwan contact: kt x - kt^2 x^2 / (4 fy) up to 2 fy / kt, then fy."""
    xs = 2.0 * fy / kt

    def tb(x):
        return kt * x - kt * kt * x * x / (4.0 * fy) if x <= xs else fy

    return tb, [xs]


def loop_force(tb, a: float, theta: float) -> float:
    """Steady contact force at phase theta in [0, pi] of x = a cos(theta) (unloading branch), N."""
    x = a * math.cos(theta)
    return tb(a) - 2.0 * tb(0.5 * (a - x))


def first_harmonic(tb, kinks, a: float):
    """(T1c, T1s) of the steady loop of amplitude a, by quadrature with the kinks as break points."""
    # the argument (a - x)/2 = a (1 - cos theta) / 2 reaches a kink x_k at cos theta = 1 - 2 x_k / a
    pts = [math.acos(1.0 - 2.0 * xk / a) for xk in kinks if 2.0 * xk / a < 2.0]
    # absolute floor at rounding of the force scale (a stuck Jenkins loop has T1s = 0)
    opts = dict(points=pts or None, limit=200, epsabs=1e-13 * abs(tb(a)), epsrel=1e-13)
    c = quad(lambda t: loop_force(tb, a, t) * math.cos(t), 0.0, math.pi, **opts)[0]
    s = quad(lambda t: loop_force(tb, a, t) * math.sin(t), 0.0, math.pi, **opts)[0]
    return 2.0 * c / math.pi, 2.0 * s / math.pi


def describing_function(m: float, k: float, tb, kinks, a: float):
    """(omega rad/s, damping ratio, energy per cycle J) of the one-harmonic mode of amplitude a."""
    t1c, t1s = first_harmonic(tb, kinks, a)
    w2 = (k + t1c / a) / m
    E = -math.pi * a * t1s
    return math.sqrt(w2), E / (2.0 * math.pi * m * w2 * a * a), E


def iwan_energy(kt: float, fy: float, a: float) -> float:
    """Closed-form energy per cycle of the uniform Iwan contact (docs/model.md section 2), J."""
    if a <= 2.0 * fy / kt:
        return kt * kt * a ** 3 / (3.0 * fy)
    return 4.0 * fy * a - 16.0 * fy * fy / (3.0 * kt)


def masing_qsma(m: float, k: float, tb, a: float):
    """QSMA of the single-DOF oscillator: (omega from the secant, damping ratio from the Masing loop area).

    omega^2 = (k + Tb(a) / a) / m;  E = 8 int_0^a Tb - 4 a Tb(a) (the
    linear spring's share cancels);  D = E / (2 pi (k a + Tb(a)) a).
    """
    work = quad(tb, 0.0, a, limit=200, epsabs=0.0, epsrel=1e-13)[0]
    E = 8.0 * work - 4.0 * a * tb(a)
    F = k * a + tb(a)
    return math.sqrt(F / (m * a)), E / (2.0 * math.pi * F * a)


__all__ = ["jenkins_backbone", "iwan_backbone", "loop_force", "first_harmonic", "describing_function",
           "iwan_energy", "masing_qsma"]

"""Where inside a step of the time integrator something happens (compiled, inlined).

The integrator (:mod:`jointdyn.dynamics._core`) interpolates a step by cubic
Hermite polynomials (values and velocities at both ends): a velocity
reversal inside the step is the root of the interpolant's derivative
(:func:`_hermite_root`), the re-contact or opening of a normal spring the
first sign change of its load on the interpolant (:func:`_crossing`); a
change of a law's motion state is located by bisection probes. The step is
then split there, unless the split lies within :data:`_SPLIT_GUARD` of
either end.
"""

from __future__ import annotations

from .._jit import jit

# a change of motion state inside a step is located by this many probes (the
# first at _SPLIT_GUARD, then bisection: 2^-38 of a step) and the step is
# split there unless it lies within _SPLIT_GUARD of either end (the same
# guard applies to reversal splits); compile-time constants of the templates
# (a change here recompiles via the source hash). Fewer probes (24: 1e-7 of
# a step) changed the outcome of a nearly unstable orbit (eta 1.5, beta 2,
# gamma 1.18: periodic -> not settled)
_BISECT_PROBES = 40
_SPLIT_GUARD = 1e-6


@jit(inline="always")
def _hermite_root(u0, u1, du0, du1, h):
    """Root s in (0, 1) of the derivative of the cubic Hermite interpolant.

    ``du0`` and ``du1`` (velocities, units of u per second) have opposite
    signs, so the derivative has exactly one root in (0, 1); found by
    bisection on the quadratic (robust, called only at reversals).
    """
    d = (u1 - u0) / h
    lo = 0.0
    hi = 1.0
    sg0 = du0 > 0.0
    for _ in range(60):
        s = 0.5 * (lo + hi)
        p = du0 * (1.0 - 4.0 * s + 3.0 * s * s) + du1 * (3.0 * s * s - 2.0 * s) + 6.0 * d * (s - s * s)
        if (p > 0.0) == sg0:
            lo = s
        else:
            hi = s
    return 0.5 * (lo + hi)


@jit(inline="always")
def _hermite_value(u0, u1, du0, du1, h, s):
    """Cubic Hermite interpolant of u at fraction s of a step of length h."""
    s2 = s * s
    s3 = s2 * s
    return (
        (2.0 * s3 - 3.0 * s2 + 1.0) * u0
        + (s3 - 2.0 * s2 + s) * h * du0
        + (-2.0 * s3 + 3.0 * s2) * u1
        + (s3 - s2) * h * du1
    )


@jit(inline="always")
def _crossing(P, kn, g0, g1, dg0, dg1, h):  # pragma: no cover - compiled
    """First sign change of P + kn g inside a step on the cubic Hermite
    interpolant of g (values g0, g1, slopes dg0, dg1); returns (fraction of
    the step, 2.0 when there is none; True at a re-contact).

    A sign change between the ends is bisected; without one, an extremum of
    g inside the step whose value has the other sign (the contact opens and
    closes again within the step) brackets the first crossing.
    """
    closed0 = P + kn * g0 > 0.0
    lo = 0.0
    hi = 1.0
    if (P + kn * g1 > 0.0) == closed0:
        if not dg0 * dg1 < 0.0:
            return 2.0, False
        hi = _hermite_root(g0, g1, dg0, dg1, h)
        if (P + kn * _hermite_value(g0, g1, dg0, dg1, h, hi) > 0.0) == closed0:
            return 2.0, False
    for _ in range(60):
        sm = 0.5 * (lo + hi)
        if (P + kn * _hermite_value(g0, g1, dg0, dg1, h, sm) > 0.0) == closed0:
            lo = sm
        else:
            hi = sm
    return 0.5 * (lo + hi), not closed0

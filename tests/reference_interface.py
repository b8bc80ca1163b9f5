"""Plain-Python references of the interface node pair (docs/model.md section 10).

Written from the model page, independently of the compiled kernels (no numpy,
no numba, no arrays of pairs):

- :func:`path_step`: the exact update along the straight path of one step, by
  the formulas of the model page as they are written there (the exit instant
  from the quadratic's roots, the slip angle from ``tan(phi / 2)`` and the
  power of the load ratio, or the exponential at constant load);
- :class:`PairRef`: one pair that holds its slider and its last point as
  floats and commits on every call (``exact=True``: :func:`path_step` from
  the last point; ``exact=False``: the radial return of the end point);
- :func:`substep`: the radial return along the same straight path in many
  sub-steps (the re-closing instant a sub-sample), the independent check of
  the closed form (first order in the sub-step when the slip turns).
"""

from __future__ import annotations

import math

STICK, SLIP, OPEN = 0, 1, 2


def radial_step(kt, kn, mu, P, u1, u2, g, w):
    """Radial return of the trial at (u1, u2, g) from the slider w: (T1, T2, N, code, w_new)."""
    N = max(0.0, P + kn * g)
    if N == 0.0:
        return 0.0, 0.0, 0.0, OPEN, (u1, u2)
    t1, t2 = kt * (u1 - w[0]), kt * (u2 - w[1])
    r = math.hypot(t1, t2)
    if r <= mu * N:
        return t1, t2, N, STICK, (w[0], w[1])
    T1, T2 = mu * N * t1 / r, mu * N * t2 / r
    return T1, T2, N, SLIP, (u1 - T1 / kt, u2 - T2 / kt)


def _exit_root(A, B, C, length):
    """First x in [0, length) where A x^2 + B x + C (C <= 0 at x = 0) rises above 0, or None."""
    if C == 0.0:  # on the circle: the roots are 0 and -B / A
        if B > 0.0 or (B == 0.0 and A > 0.0):
            return 0.0
        return -B / A if A > 0.0 and -B / A < length else None
    if A == 0.0:
        roots = [-C / B] if B != 0.0 else []
    else:
        disc = B * B - 4.0 * A * C
        if disc < 0.0:
            return None
        roots = sorted(((-B - math.sqrt(disc)) / (2 * A), (-B + math.sqrt(disc)) / (2 * A)))
    for x in roots:
        if 0.0 <= x < length and 2 * A * x + B > 0.0:
            return x
    return None


def path_step(kt, kn, mu, P, start, end, w):
    """The exact step along the straight path from ``start`` = (u1, u2, g) to ``end`` from the
    committed slider ``w`` (a start outside the disc slides back onto it radially first).

    Returns (T1, T2, N, code, w_new): code the state at the end (SLIP on the circle after a slide)."""
    (a1, a2, g0), (u1, u2, g) = start, end
    n0, n1 = P + kn * g0, P + kn * g
    if n1 <= 0.0:
        return 0.0, 0.0, 0.0, OPEN, (u1, u2)
    v1, v2 = u1 - a1, u2 - a2
    s = math.hypot(v1, v2)
    ndot = n1 - n0
    slid = False
    if n0 <= 0.0:  # closes at tau0 with no force and no memory
        tau0, T1, T2, N0 = n0 / (n0 - n1), 0.0, 0.0, 0.0
    else:
        tau0, N0 = 0.0, n0
        T1, T2 = kt * (a1 - w[0]), kt * (a2 - w[1])
        r = math.hypot(T1, T2)
        if r > mu * n0:
            T1, T2, slid = mu * n0 * T1 / r, mu * n0 * T2 / r, True
    length = 1.0 - tau0
    A = (kt * s) ** 2 - (mu * ndot) ** 2
    B = 2.0 * (kt * (T1 * v1 + T2 * v2) - mu * mu * N0 * ndot)
    C = min(0.0, T1 * T1 + T2 * T2 - (mu * N0) ** 2)
    if slid or C > -1e-12 * (mu * N0) ** 2:  # on the circle (to rounding: a pair that was slipping)
        C = 0.0
    x = _exit_root(A, B, C, length)
    if x is None:  # stuck to the end
        T1, T2 = T1 + kt * v1 * length, T2 + kt * v2 * length
        on_circle = (s == 0.0 and ndot == 0.0) or math.hypot(T1, T2) >= mu * n1
        return T1, T2, n1, SLIP if slid and on_circle else STICK, (u1 - T1 / kt, u2 - T2 / kt)
    Ts1, Ts2 = T1 + kt * v1 * x, T2 + kt * v2 * x
    Ns = N0 + ndot * x
    if s == 0.0:
        angle = math.atan2(Ts2, Ts1)
    else:
        phi_s = 0.0 if Ns == 0.0 or mu == 0.0 else math.atan2(v1 * Ts2 - v2 * Ts1, v1 * Ts1 + v2 * Ts2)
        rest = length - x
        if phi_s == 0.0:
            ratio = 0.0
        elif ndot == 0.0:
            ratio = math.exp(-kt * s * rest / (mu * Ns))
        else:
            ratio = math.exp(-kt * s / (mu * ndot) * math.log1p(ndot * rest / Ns))  # (n1 / Ns)^(...)
        phi = math.pi if abs(phi_s) == math.pi else 2.0 * math.atan(math.tan(phi_s / 2.0) * ratio)
        angle = math.atan2(v2, v1) + phi
    T1, T2 = mu * n1 * math.cos(angle), mu * n1 * math.sin(angle)
    return T1, T2, n1, SLIP, (u1 - T1 / kt, u2 - T2 / kt)


def substep(kt, kn, mu, P, start, end, w, m):
    """Radial return along the straight path in m equal sub-steps (the re-closing instant inserted
    as a sub-sample, then m equal sub-steps to the end); the start point itself is the first
    sub-sample. Returns (T1, T2, N, w_new) at the end."""
    (a1, a2, g0), (u1, u2, g) = start, end
    n0, n1 = P + kn * g0, P + kn * g
    taus = [0.0]
    if n0 <= 0.0 < n1:
        taus.append(n0 / (n0 - n1))
    t0 = taus[-1]
    taus += [t0 + (1.0 - t0) * k / m for k in range(1, m + 1)]
    out = None
    for tau in taus:
        out = radial_step(kt, kn, mu, P, a1 + tau * (u1 - a1), a2 + tau * (u2 - a2), g0 + tau * (g - g0), w)
        w = out[4]
    return out[0], out[1], out[2], w


class PairRef:
    """One node pair: N = max(0, P + kn g), T = kt (u - w), |T| <= mu N; each call steps from the
    point of the previous call (the first from the point itself)."""

    def __init__(self, kt, kn, mu, preload, w=(0.0, 0.0), exact=True):
        self.kt, self.kn, self.mu, self.P = float(kt), float(kn), float(mu), float(preload)
        self.w = (float(w[0]), float(w[1]))
        self.last = None
        self.exact = exact

    def step(self, u1, u2, g):
        """Step to (u1, u2) m, g m; returns (T1 N, T2 N, N N, code) and commits."""
        start = self.last if self.last is not None else (u1, u2, g)
        if self.exact:
            T1, T2, N, code, self.w = path_step(self.kt, self.kn, self.mu, self.P, start, (u1, u2, g), self.w)
        else:
            T1, T2, N, code, self.w = radial_step(self.kt, self.kn, self.mu, self.P, u1, u2, g, self.w)
        self.last = (u1, u2, g)
        return T1, T2, N, code


def march_ref(pairs, U1, U2, G):
    """March reference pairs over rows of histories (U1[j][i]: sample j, pair i); returns lists
    T1[j][i], T2[j][i], N[j][i], code[j][i]."""
    out = ([], [], [], [])
    for j in range(len(U1)):
        rows = [p.step(U1[j][i], U2[j][i], G[j][i]) for i, p in enumerate(pairs)]
        for k in range(4):
            out[k].append([r[k] for r in rows])
    return out

"""Plain-Python references for Segalman's four-parameter Iwan law (no jointdyn import).

The density of slip displacements (docs/model.md, Segalman's law) at the
reference load: R phi^chi on [0, phi_max] plus S delta(phi - phi_max), with

    phi_max = F_S (1 + beta) / (K_T (beta + (chi+1)/(chi+2)))
    R = F_S (chi+1) / (phi_max^(chi+2) (beta + (chi+1)/(chi+2)))
    S = F_S beta / (phi_max (beta + (chi+1)/(chi+2)))

Closed forms at constant load, the quadrature of the density into n
Jenkins elements (equal stiffness bins, each element carrying the slip force
of its bin) and the one-harmonic describing function of a single-DOF
oscillator by adaptive quadrature of the Masing loop.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad


def density(kt, fy, chi, beta):
    """(phi_max m, R, S) of the density."""
    d = beta + (chi + 1.0) / (chi + 2.0)
    phi_max = fy * (1.0 + beta) / (kt * d)
    R = fy * (chi + 1.0) / (phi_max ** (chi + 2.0) * d)
    S = fy * beta / (phi_max * d)
    return phi_max, R, S


def backbone(kt, fy, chi, beta):
    """Virgin curve F(u) (u >= 0, N) and its kink (phi_max)."""
    phi_max, R, _ = density(kt, fy, chi, beta)

    def f(u):
        if u >= phi_max:
            return fy
        return kt * u - R * u ** (chi + 2.0) / ((chi + 1.0) * (chi + 2.0))

    return f, [phi_max]


def masing_down(kt, fy, chi, beta, A, u):
    """Unloading branch from the tip (A, F(A)) of a steady loop, N."""
    f, _ = backbone(kt, fy, chi, beta)
    return f(A) - 2.0 * f(0.5 * (A - u))


def energy(kt, fy, chi, beta, A):
    """Energy dissipated per steady cycle of amplitude A, J (every element with slip
    displacement phi dissipates 4 phi (A - phi) per unit stiffness once it slips)."""
    phi_max, R, S = density(kt, fy, chi, beta)
    if A <= phi_max:
        return 4.0 * R * A ** (chi + 3.0) / ((chi + 2.0) * (chi + 3.0))
    p = phi_max
    return 4.0 * R * (A * p ** (chi + 2.0) / (chi + 2.0) - p ** (chi + 3.0) / (chi + 3.0)) + 4.0 * S * p * (A - p)


def elements(kt, fy, chi, beta, n):
    """(stiffnesses N/m, slip forces N) of n elements from equal-stiffness bins of the
    continuum (each with the stiffness and slip force of its bin), plus the delta."""
    phi_max, R, S = density(kt, fy, chi, beta)
    e = phi_max * (np.arange(n + 1) / n) ** (1.0 / (chi + 1.0))
    k = R * np.diff(e ** (chi + 1.0)) / (chi + 1.0)
    f = R * np.diff(e ** (chi + 2.0)) / (chi + 2.0)
    if beta > 0.0:
        k = np.append(k, S)
        f = np.append(f, S * phi_max)
    return k, f


def describing_function(m, k, kt, fy, chi, beta, a):
    """(omega rad/s, damping ratio, energy J) of the one-harmonic mode of amplitude a."""
    f, kinks = backbone(kt, fy, chi, beta)

    def force(t):
        return f(a) - 2.0 * f(0.5 * a * (1.0 - math.cos(t)))

    pts = [math.acos(1.0 - 2.0 * xk / a) for xk in kinks if 2.0 * xk / a < 2.0]
    opts = dict(points=pts or None, limit=400, epsabs=1e-14 * abs(f(a)), epsrel=1e-12)
    c = 2.0 / math.pi * quad(lambda t: force(t) * math.cos(t), 0.0, math.pi, **opts)[0]
    s = 2.0 / math.pi * quad(lambda t: force(t) * math.sin(t), 0.0, math.pi, **opts)[0]
    w2 = (k + c / a) / m
    E = -math.pi * a * s
    return math.sqrt(w2), E / (2.0 * math.pi * m * w2 * a * a), E


# --- the law, one piece at a time ----------------------------------------------------

from reference_exact import MACROSLIP, SEPARATION, STICK_SLIP, ExactIwanRef, _line, _on_line  # noqa: E402


def _constants(chi, beta):
    """(u_max, c_R, c_S): slip strengths u = phi kt / fy run over [0, u_max]; T = fy (c_R
    int u^chi P du + c_S P(u_max)) (R and S of :func:`density` in the units of u and fy)."""
    d = beta + (chi + 1.0) / (chi + 2.0)
    umax = (1.0 + beta) / d
    return umax, (chi + 1.0) / (umax ** (chi + 2.0) * d), beta / (1.0 + beta)


class SegalmanRef(ExactIwanRef):
    """The exact Segalman law: the uniform law's pieces of P(u) on [0, u_max] (see
    ``reference_exact.py``: shift, clip, join) with the weight u^chi and the delta at
    u_max. A merge keeps the weighted integral of P over the three pieces (its vertex
    value found from the integral's linearity in it): the triple the uniform law would
    merge if its weighted vertex lies within the limits, else the least cost (the uniform
    law's measure) among the triples whose weighted vertex does. Uses the uniform
    reference's merge when chi = 0 (weight 1: the same law)."""

    def __init__(self, kt, mu, n_ref, chi, beta, capacity, x0=0.0, n0=None):
        super().__init__(kt, mu, n_ref, capacity, x0, n0)
        self.chi = float(chi)
        self.umax, self.c_r, self.c_s = _constants(self.chi, float(beta))
        self.pieces = [[0.0, self.umax, 0.0, 0.0]]

    def _wint(self, lo, hi, a, b):
        c = self.chi
        if c == 0.0:
            return (hi - lo) * (a + 0.5 * b * (hi + lo))
        return a * (hi ** (c + 1) - lo ** (c + 1)) / (c + 1) + b * (hi ** (c + 2) - lo ** (c + 2)) / (c + 2)

    def step(self, x, N):
        alpha = N * (1.0 / self.n_ref)
        if alpha <= 0.0 or self.fy <= 0.0:
            self.pieces = [[0.0, self.umax, 0.0, 0.0]]
            self.x_prev = x
            return 0.0, 0.0, (SEPARATION if alpha <= 0.0 else MACROSLIP)
        dq = self.kt / self.fy * (x - self.x_prev)
        self.x_prev = x
        new = []
        for lo, hi, a, b in self.pieces:
            for seg in self._clip(lo, hi, a + dq, b, alpha):
                if new and new[-1][2] == seg[2] and new[-1][3] == seg[3]:
                    new[-1][1] = seg[1]
                else:
                    new.append(seg)
        while len(new) > self.capacity:
            if self.chi == 0.0:
                self._merge_least(new, alpha)
            else:
                self._merge_weighted(new, alpha)
        self.pieces = new
        total = sum(self._wint(*p) for p in new)
        c = self.chi
        stuck = sum(((h - lo) if c == 0.0 else (h ** (c + 1) - lo ** (c + 1)) / (c + 1))
                    for lo, h, a, b in new if not _on_line(a, b, alpha))
        lo, hi, a, b = new[-1]
        end_stuck = 0.0 if _on_line(a, b, alpha) else 1.0
        code = STICK_SLIP if stuck > 0.0 or end_stuck > 0.0 else MACROSLIP
        T = self.fy * (self.c_r * total + self.c_s * (a + b * self.umax))
        return T, self.kt * (self.c_r * stuck + self.c_s * end_stuck), code

    def _two_pieces(self, u0, p0, uw, pw, u3, p3):
        def through(l, pl, h, ph):
            b = (ph - pl) / (h - l)
            return self._wint(l, h, pl - b * l, b)
        return through(u0, p0, uw, pw) + through(uw, pw, u3, p3)

    @staticmethod
    def _uniform_choice(pieces, alpha):
        """j of the uniform law's merge (reference_exact.ExactIwanRef._merge_least)."""

        def value(piece, u):
            return piece[2] + piece[3] * u

        def integral(piece):
            lo, hi, a, b = piece
            return (hi - lo) * (a + 0.5 * b * (hi + lo))

        best = None
        for j in range(1, len(pieces) - 1):
            left, mid, right = pieces[j - 1], pieces[j], pieces[j + 1]
            u0, u1, u2, u3 = left[0], left[1], mid[1], right[1]
            p0, p1, p2, p3 = value(left, u0), value(left, u1), value(mid, u2), value(right, u3)
            area2 = 2.0 * (integral(left) + integral(mid) + integral(right))
            uw = 0.5 * (u1 + u2)
            d, wl, wr = u3 - u0, uw - u0, u3 - uw
            pwd = area2 - wl * p0 - wr * p3
            e1 = (p0 - p1) * wl * d + (pwd - p0 * d) * (u1 - u0)
            e2 = (pwd - p2 * d) * wr + (p3 * d - pwd) * (u2 - uw)
            if abs(pwd) > alpha * uw * d:
                continue
            num, den = abs(e1) * wr + abs(e2) * wl, wl * wr
            if best is None or num * best[1] < best[0] * den:
                best = (num, den, j)
        return 1 if best is None else best[2]

    def _merge_weighted(self, pieces, alpha):
        def value(piece, u):
            return piece[2] + piece[3] * u

        def vertex(j):
            left, mid, right = pieces[j - 1], pieces[j], pieces[j + 1]
            u0, u1, u2, u3 = left[0], left[1], mid[1], right[1]
            p0, p3 = value(left, u0), value(right, u3)
            target = self._wint(*left) + self._wint(*mid) + self._wint(*right)
            uw = 0.5 * (u1 + u2)
            i0 = self._two_pieces(u0, p0, uw, 0.0, u3, p3)
            i1 = self._two_pieces(u0, p0, uw, 1.0, u3, p3)
            return u0, u1, u2, u3, p0, value(left, u1), value(mid, u2), p3, uw, (target - i0) / (i1 - i0)

        # the triple the uniform law merges (its rule and its operations: reference_exact.py),
        # kept when its weighted vertex lies within the limits
        j_uniform = self._uniform_choice(pieces, alpha)
        u0, u1, u2, u3, p0, p1, p2, p3, uw, pw = vertex(j_uniform)
        if abs(pw) <= alpha * uw:
            pieces[j_uniform - 1 : j_uniform + 2] = [_line(u0, p0, uw, pw, alpha), _line(uw, pw, u3, p3, alpha)]
            return
        # else the least cost among the weighted vertices within the limits (the first, clamped, if none)
        best, best_j = math.inf, 1
        for j in range(1, len(pieces) - 1):
            u0, u1, u2, u3, p0, p1, p2, p3, uw, pw = vertex(j)
            if abs(pw) > alpha * uw:
                continue
            e1 = p0 + (pw - p0) * (u1 - u0) / (uw - u0) - p1
            e2 = pw + (p3 - pw) * (u2 - uw) / (u3 - uw) - p2
            cost = (abs(e1) + abs(e2)) * (u3 - u0)
            if cost < best:
                best, best_j = cost, j
        u0, u1, u2, u3, p0, p1, p2, p3, uw, pw = vertex(best_j)
        pw = min(max(pw, -alpha * uw), alpha * uw)
        pieces[best_j - 1 : best_j + 2] = [_line(u0, p0, uw, pw, alpha), _line(uw, pw, u3, p3, alpha)]


"""Plain-Python reference of the interface node pair (docs/model.md section 10).

Written from the model page, independently of the compiled kernels (no numpy,
no numba, no arrays of pairs): one object per pair that holds its slider as
two floats and commits on every call of :meth:`PairRef.step`. The oracle of
``test_interface.py``.
"""

from __future__ import annotations

import math

STICK, SLIP, OPEN = 0, 1, 2


class PairRef:
    """One node pair: N = max(0, P + kn g), T = kt (u - w), |T| <= mu N, radial return."""

    def __init__(self, kt, kn, mu, preload, w=(0.0, 0.0)):
        self.kt, self.kn, self.mu, self.P = float(kt), float(kn), float(mu), float(preload)
        self.w = [float(w[0]), float(w[1])]

    def step(self, u1, u2, g):
        """Step to (u1, u2) m, g m; returns (T1 N, T2 N, N N, code) and commits. The step starts at
        the point of the previous call (the first at the point itself); radial return of the end
        point does not need it."""
        N = max(0.0, self.P + self.kn * g)
        if N == 0.0:
            self.w = [u1, u2]
            return 0.0, 0.0, 0.0, OPEN
        t1 = self.kt * (u1 - self.w[0])
        t2 = self.kt * (u2 - self.w[1])
        r = math.sqrt(t1 * t1 + t2 * t2)
        if r <= self.mu * N:
            return t1, t2, N, STICK
        s = self.mu * N / r
        T1, T2 = s * t1, s * t2
        self.w = [u1 - T1 / self.kt, u2 - T2 / self.kt]
        return T1, T2, N, SLIP


def march_ref(pairs, U1, U2, G):
    """March reference pairs over rows of histories (U1[j][i]: sample j, pair i); returns lists
    T1[j][i], T2[j][i], N[j][i], code[j][i]."""
    out = ([], [], [], [])
    for j in range(len(U1)):
        rows = [p.step(U1[j][i], U2[j][i], G[j][i]) for i, p in enumerate(pairs)]
        for k in range(4):
            out[k].append([r[k] for r in rows])
    return out

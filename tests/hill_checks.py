"""A check shared by the stability tests: the time-domain period map confirms Hill's verdict."""

from __future__ import annotations

import math

import numpy as np

from jointdyn.hb import monodromy_multipliers


def assert_period_map_confirms(br, calm_lam: float) -> None:
    """On branch ``br`` (with some unstable points), the most unstable point and the point nearest
    ``calm_lam`` (stable): the largest Floquet multiplier of the time-domain period map equals
    exp(2 pi growth) of Hill's method within 1e-2, above 1 at the first and below 1 at the second."""
    u = np.flatnonzero(~br.stable)
    assert u.size
    worst = u[np.argmax(br.growth[u])]
    calm = int(np.argmin(np.abs(br.lam - calm_lam)))
    assert br.stable[calm]
    mono = {}
    for i in (worst, calm):
        mu_mono = float(np.max(np.abs(monodromy_multipliers(br.problem, br.X[i], br.lam[i]))))
        mu_hill = math.exp(2.0 * math.pi * br.growth[i])
        assert abs(mu_mono - mu_hill) < 1e-2
        mono[i] = mu_mono
    assert mono[worst] > 1.0 + 2e-3 and mono[calm] < 1.0

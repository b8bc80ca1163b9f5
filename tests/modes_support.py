"""Test support shared by the nonlinear-mode test modules (uses jointdyn)."""

from __future__ import annotations

import math

import numpy as np


def solve_at(backbone, amplitude):
    """(omega rad/s, xi rad/s, X) of the backbone's EPMC problem solved at exactly
    ``amplitude`` (m), started from the nearest backbone point."""
    p = backbone.problem
    i = int(np.argmin(np.abs(np.log(backbone.amplitude_m / amplitude))))
    v, ok, _ = p.solve(amplitude, p.pack(backbone.X[i], backbone.omega_rad_s[i], backbone.xi_rad_s[i]))
    assert ok
    X, w, xi = p.unpack(v, math.log10(amplitude))
    return w, xi, X

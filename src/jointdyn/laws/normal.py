"""Normal-load descriptions: prescribed (harmonic or sampled) or from a spring.

MODEL.md section 1: either N(t) is prescribed, or it comes from a unilateral
spring N = max(0, N_ref + kn v) with normal approach v. N <= 0 means the
interface is open. Each description can list the instants where N crosses
zero inside an interval, so that drivers and integrators put a step boundary
exactly at separation and re-contact instead of smearing it over a step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V

__all__ = ["NormalLoad", "HarmonicLoad", "SampledLoad", "UnilateralSpring"]


class NormalLoad:
    """Interface: ``N(t)`` (vectorised) and ``zero_crossings(t0, t1)``."""

    def __call__(self, t):  # pragma: no cover - interface
        raise NotImplementedError

    def zero_crossings(self, t0: float, t1: float) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError


@dataclass(frozen=True)
class HarmonicLoad(NormalLoad):
    """N(t) = n0 + n1 sin(omega t + delta)  (MODEL.md section 6).

    Parameters
    ----------
    n0 : float
        Static (preload) part N0, N (> 0).
    n1 : float
        Amplitude N1 = eta N0, N (>= 0).
    omega : float
        Angular frequency, rad/s (>= 0).
    delta : float
        Phase, rad.
    """

    n0: float
    n1: float = 0.0
    omega: float = 0.0
    delta: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "n0", V.positive("n0", self.n0))
        object.__setattr__(self, "n1", V.nonnegative("n1", self.n1))
        object.__setattr__(self, "omega", V.nonnegative("omega", self.omega))
        object.__setattr__(self, "delta", V.finite("delta", self.delta))

    @property
    def eta(self) -> float:
        """N1 / N0."""
        return self.n1 / self.n0

    def __call__(self, t):
        return self.n0 + self.n1 * np.sin(self.omega * np.asarray(t, dtype=float) + self.delta)

    def zero_crossings(self, t0: float, t1: float) -> np.ndarray:
        """Instants in (t0, t1) where N changes sign (separation / re-contact)."""
        if self.n1 <= self.n0 or self.omega == 0.0:
            return np.empty(0)
        # sin(phi) = -n0/n1 at phi = asin(-r) + 2k pi and pi - asin(-r) + 2k pi
        r = -self.n0 / self.n1
        base = (math.asin(r), math.pi - math.asin(r))
        w = self.omega
        out = []
        for b in base:
            # phi = w t + delta = b + 2 pi k
            k0 = math.floor((w * t0 + self.delta - b) / (2 * math.pi))
            k = k0
            while True:
                t = (b + 2 * math.pi * k - self.delta) / w
                if t >= t1:
                    break
                if t > t0:
                    out.append(t)
                k += 1
        return np.array(sorted(out))


@dataclass(frozen=True)
class SampledLoad(NormalLoad):
    """N(t) given at samples, linear in between.

    Parameters
    ----------
    t : array_like
        Strictly increasing times, s.
    values : array_like
        Normal load at those times, N (finite).
    """

    t: np.ndarray
    values: np.ndarray

    def __post_init__(self) -> None:
        t = V.increasing("t", V.finite_array("t", self.t))
        n = V.finite_array("N", self.values)
        V.same_length(t=t, N=n)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "values", n)

    def __call__(self, t):
        return np.interp(t, self.t, self.values)

    def zero_crossings(self, t0: float, t1: float) -> np.ndarray:
        n = self.values
        i = np.flatnonzero((n[:-1] > 0) != (n[1:] > 0))
        tt = self.t[i] + (0.0 - n[i]) * (self.t[i + 1] - self.t[i]) / (n[i + 1] - n[i])
        return tt[(tt > t0) & (tt < t1)]


@dataclass(frozen=True)
class UnilateralSpring:
    """Normal contact spring N = max(0, n_ref + kn v).

    Parameters
    ----------
    n_ref : float
        Preload at v = 0, N (> 0).
    kn : float
        Normal stiffness, N/m (> 0).
    """

    n_ref: float
    kn: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "n_ref", V.positive("n_ref", self.n_ref))
        object.__setattr__(self, "kn", V.positive("kn", self.kn))

    def load(self, v):
        """Normal load (N) for normal approach ``v`` (m, positive closes)."""
        return np.maximum(0.0, self.n_ref + self.kn * np.asarray(v, dtype=float))

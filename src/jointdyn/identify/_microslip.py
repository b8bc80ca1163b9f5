"""What a backbone that stays in microslip determines: k + kt, R, chi and zeta.

Below the slip displacement phi_max the virgin curve of Segalman's law (and
Iwan's, chi = 0, R = kt^2 / (2 fy)) is

    F(u) = kt u - R u^(chi+2) / ((chi+1)(chi+2)),

which does not contain the slip force or beta apart from R, and the modal
oscillator adds k to kt. The describing function of that curve is a closed
form (e = chi + 2, W(n) = int_0^{pi/2} sin^n = sqrt(pi)/2 Gamma((n+1)/2) /
Gamma(n/2 + 1)):

    K1(A) = kt - c1(chi) R A^(chi+1),  c1 = 8 e W(2e) / (pi (chi+1)(chi+2)(e+1)),
    E(A)  = 4 R A^(chi+3) / ((chi+2)(chi+3)),

so such a backbone is fitted with the parameters k + kt, R, chi and zeta,
each with its profile interval, instead of reporting values of kt, fy and
beta the data cannot separate.
"""

from __future__ import annotations

import math

import numpy as np

from ..laws.segalman import CHI_MAX, CHI_MIN, segalman_constants
from ._lsq import Param, solve

__all__ = ["microslip_backbone", "microslip_constants", "decay_model", "decay_times", "MICROSLIP_MODELS"]

#: ln A steps of the quadrature of a free decay (:func:`decay_model`) (-)
DECAY_GRID = 600

#: backbone models whose microslip is the power law above (jenkins has none; discrete is a staircase)
MICROSLIP_MODELS = ("iwan", "iwan-closed", "segalman")


def _c1(chi: float) -> float:
    e = chi + 2.0
    w2e = 0.5 * math.sqrt(math.pi) * math.exp(math.lgamma(e + 0.5) - math.lgamma(e + 1.0))
    return 8.0 * e * w2e / (math.pi * (chi + 1.0) * (chi + 2.0) * (e + 1.0))


def microslip_constants(law) -> tuple:
    """(chi, R in N/m^(chi+2), phi_max in m) of an Iwan or Segalman law at N = n_ref."""
    if law.name in ("iwan", "iwan-closed"):
        return 0.0, law.kt * law.kt / (2.0 * law.fy), 2.0 * law.fy / law.kt
    chi, beta = law.chi, law.beta
    pm = segalman_constants(chi, beta)[0] * law.fy / law.kt
    R = law.fy * (chi + 1.0) / (pm ** (chi + 2.0) * (beta + (chi + 1.0) / (chi + 2.0)))
    return chi, R, pm


def microslip_model(K, R, chi, zeta, m, A) -> tuple:
    """(omega rad/s, damping ratio) of the modal oscillator with the microslip curve."""
    # beyond the power law's reach (amplitudes of a backbone into macroslip) the stiffness
    # would turn negative: held at 1e-6 of the stuck one, the residual stays large and finite
    w2 = np.maximum((K - _c1(chi) * R * A ** (chi + 1.0)) / m, 1e-6 * K / m)
    w = np.sqrt(w2)
    en = 4.0 * R * A ** (chi + 3.0) / ((chi + 2.0) * (chi + 3.0))
    return w, en / (2.0 * math.pi * m * w2 * A * A) + zeta * math.sqrt(K / m) / w


def decay_model(v: dict, m: float, t: np.ndarray, lna_end: float) -> tuple:
    """(ln A, omega rad/s) at the times ``t`` (s, from t[0]) of the free decay of the microslip model
    ``v`` (K N/m, R, chi, zeta, lna0) released at ln A = lna0 at t[0]: -d ln A / dt =
    omega D (k + K1) / (k + F'), D in EPMC's definition and (k + K1) / (k + F') the ratio of
    :func:`jointdyn.identify.ringdown.epmc_factor`, integrated by quadrature over ln A down to
    ``lna_end`` - 1."""
    K, R, chi, zeta = v["K"], v["R"], v["chi"], v["zeta"]
    lev = np.linspace(v["lna0"], min(lna_end, v["lna0"]) - 1.0, DECAY_GRID)
    A = np.exp(lev)
    w, D = microslip_model(K, R, chi, zeta, m, A)
    ap = R * A ** (chi + 1.0)
    ratio = np.maximum(K - _c1(chi) * ap, 1e-6 * K) / np.maximum(K - ap / (chi + 1.0), 1e-6 * K)
    return decay_times(lev, w, w * D * ratio, t)


def decay_times(lev: np.ndarray, w: np.ndarray, rate: np.ndarray, t: np.ndarray) -> tuple:
    """(ln A, omega rad/s) at the times ``t`` (s, from t[0]) of a decay whose -d ln A / dt is
    ``rate`` (1/s) and frequency ``w`` at the falling levels ``lev`` of ln A (from the release):
    the time to each level by the trapezoidal rule on 1 / rate; beyond the last level at the
    last rate."""
    inv = 1.0 / np.maximum(rate, 1e-300)
    tl = np.concatenate(([0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * (lev[:-1] - lev[1:]))))
    span = float(t[-1] - t[0])
    if tl[-1] < span:  # beyond the grid: the last rate
        lev = np.append(lev, lev[-1] - (span - tl[-1]) / inv[-1])
        tl = np.append(tl, span)
        w = np.append(w, w[-1])
    lna = np.interp(t - t[0], tl, lev)
    return lna, np.interp(t - t[0], tl, w)


def decay_fit(win: dict, m: float, start: dict, fit_chi: bool, *, profile: bool = True, chi_bounds=None):
    """Least squares of :func:`decay_model` to a ring-down's windows ``win`` (``t``, ``lna``,
    ``omega`` and their standard errors ``sigma_lna``, ``sigma_omega``): (Solution, params) for
    lna0, K, R, zeta and, when ``fit_chi``, chi (within ``chi_bounds``, default Segalman's
    range), from ``start`` (K, R, zeta, chi); ``profile``: with profile-likelihood intervals."""
    t, lna, om = win["t"], win["lna"], win["omega"]
    sl, so = win["sigma_lna"], win["sigma_omega"]
    params = [Param("lna0", float(lna[0]), False, float(lna[0]) - 1.0, float(lna[0]) + 1.0),
              Param("K", start["K"], True, 1e-3 * start["K"], 1e3 * start["K"]),
              Param("R", start["R"], True, 1e-4 * start["R"], 1e4 * start["R"]),
              Param("zeta", max(start["zeta"], 1e-6), True, 0.0, 1.0 / max(start["zeta"], 1e-6))]
    if fit_chi:
        lo, hi = chi_bounds if chi_bounds is not None else (CHI_MIN, CHI_MAX)
        params.append(Param("chi", min(max(start["chi"], lo), hi), False, lo, hi))

    def fun(v):
        v = dict(v, chi=v.get("chi", start["chi"]))
        lf, wf = decay_model(v, m, t, float(lna[-1]))
        return np.concatenate(((lf - lna) / sl, (wf - om) / so))

    return solve(fun, params, profile=profile), params


def microslip_backbone(A, w, D, m, start: dict, *, fit_chi: bool, dscale: float, weights=(1.0, 1.0)) -> tuple:
    """Fit k + kt (``K``), ``R``, ``chi`` (when ``fit_chi``) and ``zeta`` to a microslip
    backbone, from the values ``start`` (those of the full model's optimum).

    Returns
    -------
    combinations : dict
        Name -> {"value", "interval", "unit", "meaning"} (JSON-ready).
    solution : Solution
        The least-squares solution (with profile intervals).
    """
    params = [Param("K", start["K"], True, 1e-3 * start["K"], 1e3 * start["K"]),
              Param("R", start["R"], True, 1e-4 * start["R"], 1e4 * start["R"]),
              Param("zeta", max(start["zeta"], 1e-9), True, 0.0, 1.0 / max(start["zeta"], 1e-9))]
    if fit_chi:
        params.append(Param("chi", start["chi"], False, CHI_MIN, CHI_MAX))

    def fun(v):
        wf, Df = microslip_model(v["K"], v["R"], v.get("chi", start["chi"]), v["zeta"], m, A)
        return np.concatenate((weights[0] * (wf - w) / w, weights[1] * (Df - D) / dscale))

    sol = solve(fun, params, profile=True)
    meaning = {"K": ("k_plus_kt", "N/m", "stuck stiffness of the mode, k + kt"),
               "R": ("R", "N/m^(chi+2)", "microslip coefficient: F = kt u - R u^(chi+2) / ((chi+1)(chi+2))"),
               "chi": ("chi", "-", "microslip exponent"),
               "zeta": ("zeta", "-", "linear damping ratio at the stuck frequency")}
    out = {}
    for p in params:
        name, unit, text = meaning[p.name]
        out[name] = {"value": sol.values[p.name], "interval": sol.intervals[p.name].to_dict(), "unit": unit,
                     "meaning": text}
    return out, sol

"""Fit a modal Iwan model to a measured backbone (amplitude, frequency, damping ratio).

The model of one mode with modal mass m (docs/model.md, "Identification")::

    m q'' + c q' + k q + F_J(q) = 0,   c = 2 zeta m omega_0,  omega_0 = sqrt((k + kt) / m)

with F_J a joint law at constant normal load. One harmonic, q = A cos(theta)
(the describing function): with T1c, T1s the first Fourier coefficients of
the steady Masing loop of amplitude A,

    omega^2 = (k + K1(A)) / m,   K1 = T1c / A,
    D = E(A) / (2 pi m omega^2 A^2) + zeta omega_0 / omega,   E = -pi A T1s.

K1 and E come from the law's virgin curve F by quadrature of the Masing
loop T(theta) = F(A) - 2 F(A (1 - cos theta) / 2) (Gauss-Legendre on the
smooth pieces between the kinks), not from the secant approximation. The
linear part is viscous with the damping ratio zeta at the stuck frequency
omega_0 (what a modal dashpot gives, and what EPMC computes).
"""

from __future__ import annotations

from collections.abc import Callable

import math
from dataclasses import replace

import numpy as np

from .. import _validate as V
from .. import config
from ..laws import law_parameters, make_law
from ..laws.segalman import CHI_MAX, CHI_MIN, segalman_constants
from ._lsq import (FIT_BETA_MAX, FIT_BETA_START, FIT_GRID_BETA, FIT_GRID_CHI, FIT_GRID_SLIP, Param, open_reason,
                   solve, start_values, status_of)
from ._microslip import MICROSLIP_MODELS, microslip_backbone, microslip_constants, microslip_model
from ._profile import FIT_LEVEL
from .result import FitResult, FitStatus

__all__ = ["fit_backbone", "describing_function", "BACKBONE_MODELS"]

#: laws a backbone fit accepts (at constant load: iwan-closed is iwan)
BACKBONE_MODELS = ("jenkins", "iwan", "segalman", "iwan-closed", "discrete")
#: Gauss-Legendre nodes per smooth piece of the Masing loop in the first-harmonic quadrature
#: of the describing function
FIT_QUAD_NODES = 64
#: fits refined by EPMC: most EPMC backbones (defect corrections), and the relative change (-)
#: of every parameter below which the refinement stops
FIT_REFINE_ITERATIONS = 4
FIT_REFINE_RTOL = 1e-4


def _virgin_curve(law):
    """(F(u) vectorised for u >= 0 in m -> N, kink displacements m) of a law at N = n_ref."""
    kt, fy = law.kt, law.fy
    name = law.name
    if name == "jenkins":
        return (lambda u: np.minimum(kt * u, fy)), [fy / kt]
    if name in ("iwan", "iwan-closed"):
        xs = 2.0 * fy / kt
        return (lambda u: np.where(u < xs, kt * u - kt * kt * u * u / (4.0 * fy), fy)), [xs]
    if name == "segalman":
        chi, beta = law.chi, law.beta
        umax, _, _ = segalman_constants(chi, beta)
        pm = umax * fy / kt
        d = beta + (chi + 1.0) / (chi + 2.0)
        R = fy * (chi + 1.0) / (pm ** (chi + 2.0) * d)

        def f(u):
            v = np.minimum(u, pm)
            return np.where(u < pm, kt * v - R * v ** (chi + 2.0) / ((chi + 1.0) * (chi + 2.0)), fy)

        return f, [pm]
    if name == "discrete":
        n = law.n
        slip = 2.0 * fy * (np.arange(n) + 0.5) / (n * kt)  # slip displacement of each element
        return (lambda u: (kt / n) * np.minimum(np.asarray(u)[..., None], slip).sum(axis=-1)), [float(slip[-1])]
    raise ValueError(f"model must be one of {', '.join(BACKBONE_MODELS)}; got {name!r}")


def _nodes(q):
    x, w = np.polynomial.legendre.leggauss(q)
    return 0.5 * (x + 1.0), 0.5 * w


def describing_function(law, amplitude) -> tuple:
    """First-harmonic stiffness and loop energy of a law at constant load N = n_ref.

    Parameters
    ----------
    law : ContactLaw
        One of :data:`BACKBONE_MODELS` (its virgin curve gives the Masing loop).
    amplitude : array_like
        Displacement amplitudes A > 0, m.

    Returns
    -------
    k1 : ndarray
        T1c / A, N/m: the first-harmonic (in-phase) stiffness of the steady loop.
    energy : ndarray
        Energy dissipated per cycle, -pi A T1s, J.
    """
    A = np.atleast_1d(np.asarray(amplitude, dtype=float))
    F, kinks = _virgin_curve(law)
    t, w = _nodes(FIT_QUAD_NODES)
    # the Masing loop is smooth between 0, the angle where the virgin argument
    # A (1 - cos theta) / 2 crosses a kink, and pi: one Gauss-Legendre piece each
    # (a piece of zero length where the kink is not reached), all amplitudes at once
    cut = [np.arccos(np.clip(1.0 - 2.0 * xk / A, -1.0, 1.0)) for xk in sorted(kinks)]
    edges = np.stack([np.zeros(A.size)] + cut + [np.full(A.size, math.pi)], axis=1)
    lo, hi = edges[:, :-1, None], edges[:, 1:, None]
    th = (lo + (hi - lo) * t).reshape(A.size, -1)
    ww = ((hi - lo) * w).reshape(A.size, -1)
    T = F(A)[:, None] - 2.0 * F(0.5 * A[:, None] * (1.0 - np.cos(th)))
    t1c = 2.0 / math.pi * np.sum(ww * T * np.cos(th), axis=1)
    t1s = 2.0 / math.pi * np.sum(ww * T * np.sin(th), axis=1)
    k1 = t1c / A
    en = -math.pi * A * t1s
    return k1, en


def _model(law, k, zeta, m, A):
    """(omega rad/s, damping ratio) of the modal model at amplitudes A."""
    k1, en = describing_function(law, A)
    w2 = (k + k1) / m
    w = np.sqrt(np.maximum(w2, 1e-300))
    w0 = math.sqrt((k + law.kt) / m)
    return w, en / (2.0 * math.pi * m * w2 * A * A) + zeta * w0 / w


def _check(A, w, D, mass):
    out = []
    for name, v in (("amplitude_m", A), ("omega_rad_s", w), ("damping_ratio", D)):
        try:
            a = np.asarray(v, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be a 1-D array of finite numbers") from None
        if a.ndim != 1 or not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be a 1-D array of finite numbers, got shape {a.shape}")
        out.append(a)
    A, w, D = out
    if not (A.size == w.size == D.size):
        raise ValueError(f"amplitude_m, omega_rad_s and damping_ratio must have one length, "
                         f"got {A.size}, {w.size}, {D.size}")
    if A.size < 4:
        raise ValueError(f"amplitude_m must have at least 4 points, got {A.size}")
    if A.size > config.FIT_MAX_BACKBONE_POINTS:  # the bound of fit --backbone, before any fitting
        raise ValueError(f"amplitude_m must have at most {config.FIT_MAX_BACKBONE_POINTS} points "
                         "(config.FIT_MAX_BACKBONE_POINTS: each costs a describing function per evaluation), "
                         f"got {A.size}")
    if not (np.all(A > 0.0) and np.all(w > 0.0)):
        raise ValueError("amplitude_m and omega_rad_s must be > 0 (allowed range (0, inf))")
    if not np.all(D >= 0.0):
        raise ValueError("damping_ratio must be >= 0 (allowed range [0, inf))")
    return A, w, D, V.positive("mass", mass)


def _start(model, A, w, D, m):
    """Start values from the data (see fit_backbone)."""
    order = np.argsort(A)
    A, w, D = A[order], w[order], D[order]
    zeta0 = 0.5 * float(D[0])
    en = 2.0 * math.pi * m * w * w * A * A * np.maximum(D - zeta0, 0.0)
    fy0 = max(float(np.max(en / (4.0 * A))), 1e-12 * m * w[0] ** 2 * A[0])
    kstuck, kslip = m * w.max() ** 2, m * w.min() ** 2
    kt0 = max(1.1 * (kstuck - kslip), 1e-3 * kstuck)
    k0 = max(1.01 * kstuck - kt0, 0.05 * kstuck)
    start = {"k": k0, "kt": kt0, "fy": fy0, "zeta": max(zeta0, 1e-6)}
    names = {p.name for p in law_parameters(model)}
    if "chi" in names:
        low = slice(0, max(2, A.size // 2))
        ok = en[low] > 0.0
        chi0 = config.SEGALMAN_CHI
        if np.count_nonzero(ok) >= 2 and A[low][ok].max() > 1.2 * A[low][ok].min():
            chi0 = float(np.clip(np.polyfit(np.log(A[low][ok]), np.log(en[low][ok]), 1)[0] - 3.0,
                                 CHI_MIN + 0.01, 1.0))
        start["chi"] = chi0
    if "beta" in names:
        start["beta"] = FIT_BETA_START
    return start


def _epmc_defect(law, k, zeta, m, A, harmonics, samples):
    """(omega, D) of EPMC with ``harmonics`` harmonics minus those of the describing
    function at the amplitudes A; None when EPMC does not cover the range."""
    from ..modes import ModeStatus, epmc
    from ..systems import System

    c = 2.0 * zeta * math.sqrt((k + law.kt) * m)
    b = epmc(System.sdof(m=m, k=k, law=law, c=c), (float(A.min()), float(A.max())), harmonics=harmonics,
             samples=samples, progress=False)
    if b.status is not ModeStatus.COMPLETE or b.points < 2:
        return None
    # the defect at EPMC's own amplitudes (small and smooth), interpolated in log amplitude
    wD, DD = _model(law, k, zeta, m, b.amplitude_m)
    la = np.log(b.amplitude_m)
    return (np.interp(np.log(A), la, b.omega_rad_s - wD), np.interp(np.log(A), la, b.damping_ratio - DD))


def _refine(sol, params, fun, law_of, m, A, harmonics, samples):
    """Defect correction by EPMC (see fit_backbone): the solution refitted with the
    describing function plus the EPMC defect at the last parameters, until the parameters
    change by less than ``FIT_REFINE_RTOL``. Returns (solution, True) or
    (the describing-function solution, False) when an EPMC backbone fails, and the last
    defect (zeros when none was computed)."""
    defect = (np.zeros(A.size), np.zeros(A.size))
    for _ in range(FIT_REFINE_ITERATIONS):
        v = sol.values
        d = _epmc_defect(law_of(v), v["k"], v["zeta"], m, A, harmonics, samples)
        if d is None:
            return sol, False, defect
        defect = d
        # restart from the last values (a scale at 0, a zeta on its bound, keeps its old unit)
        start = [replace(p, value=v[p.name]) if (not p.positive or v[p.name] > 0.0) else p for p in params]
        new = solve(lambda u, d=defect: fun(u, *d), start)
        change = max(abs(new.values[k] - v[k]) / max(abs(v[k]), 1e-300) for k in v)
        sol = new
        if change <= FIT_REFINE_RTOL:
            break
    return sol, True, defect


def _params(s0) -> list:
    out = [Param("k", s0["k"], True, 1e-6 * s0["k"], 1e3 * s0["k"]),
           Param("kt", s0["kt"], True, 1e-4 * s0["kt"], 1e3 * s0["kt"]),
           Param("fy", s0["fy"], True, 1e-4 * s0["fy"], 1e4 * s0["fy"]),
           Param("zeta", s0["zeta"], True, 0.0, 1.0 / s0["zeta"])]
    if "chi" in s0:
        out.append(Param("chi", s0["chi"], False, CHI_MIN, CHI_MAX))
    if "beta" in s0:
        out.append(Param("beta", s0["beta"], False, 0.0, FIT_BETA_MAX))
    return out


def _grid(s0) -> list:
    """Further start points of a Segalman backbone fit (a global start): chi, beta and the
    slip force (factors of the data's start ``s0``) on the grid of ``_lsq.FIT_GRID_*``."""
    if "beta" not in s0:
        return []
    return [{**s0, "chi": c, "beta": b, "fy": f * s0["fy"]}
            for c in FIT_GRID_CHI for b in FIT_GRID_BETA for f in FIT_GRID_SLIP]


def _weights(r, n, p) -> list:
    """Weights of the frequency and damping residuals that give both the same variance (each
    column's noise has its own size; the profile's threshold assumes one variance)."""
    dof = max(n - 0.5 * p, 1.0)
    sw, sd = math.sqrt(float(r[:n] @ r[:n]) / dof), math.sqrt(float(r[n:] @ r[n:]) / dof)
    if not (sw > 1e-9 and sd > 1e-9):  # noise-free data (rounding only): nothing to balance
        return [1.0, 1.0]
    s = math.sqrt(sw * sd)
    return [s / sw, s / sd]


def _microslip_result(model, law, sol, m, A, w, D, dscale, weights, defect, refined):
    """The result of a backbone that stays below the fitted slip displacement: k, kt, fy (and
    beta) not determined apart; k + kt, R, chi and zeta fitted with their intervals."""
    chi, R, pm = microslip_constants(law)
    v = sol.values
    combos, msol = microslip_backbone(A, w - defect[0], D - defect[1], m,
                                      {"K": v["k"] + v["kt"], "R": R, "chi": chi, "zeta": v["zeta"]},
                                      fit_chi=model == "segalman", dscale=dscale, weights=weights)
    why = (f"the amplitudes stay in microslip (largest {A.max():.4g} m, below the slip displacement of every "
           f"model that fits): there the backbone depends on k + kt, R and chi only; measure into macroslip")
    reasons = {k: why for k in ("k", "kt", "fy_N") + (("beta",) if model == "segalman" else ())}
    mv = msol.values
    wf, Df = microslip_model(mv["K"], mv["R"], mv.get("chi", chi), mv["zeta"], m, A)
    wf, Df = wf + defect[0], Df + defect[1]
    values = {k: None for k in reasons}
    values["zeta"] = mv["zeta"]
    errors = {k: None for k in reasons}
    errors["zeta"] = msol.errors["zeta"]
    intervals = {k: None for k in reasons}
    intervals["zeta"] = msol.intervals["zeta"]
    if model == "segalman":
        values["chi"], errors["chi"], intervals["chi"] = mv["chi"], msol.errors["chi"], msol.intervals["chi"]
    for k in [k for k in ("chi", "zeta") if k in msol.open]:
        reasons[k] = open_reason(msol.intervals[k])
        values[k] = errors[k] = None
    status, message = status_of(msol, reasons)
    if refined is False:
        status, message = FitStatus.REFINE_FAILED, FitStatus.REFINE_FAILED.message
    r = np.concatenate(((wf - w) / w, (Df - D) / dscale))
    names = tuple(p for p in ("k", "kt", "fy_N", "zeta", "chi", "beta") if p in values)
    res = FitResult(kind="backbone", model=model, status=status, message=message, parameters=values,
                    standard_errors=errors, names=names, correlation=np.full((len(names), len(names)), np.nan),
                    not_identifiable=reasons, rms_residual=math.sqrt(float(np.mean(r * r))), law=law,
                    measured={"amplitude_m": A, "omega_rad_s": w, "damping_ratio": D},
                    fitted={"omega_rad_s": wf, "damping_ratio": Df}, evaluations=sol.evaluations + msol.evaluations,
                    intervals=intervals, conditional_on=(), determined_combinations=combos)
    return res, msol


def _microslip_suffices(micro, sol, p) -> bool:
    """Whether the microslip model (k + kt, R, chi, zeta) fits as well as the full one: its
    extra sum of squares below the F test's level ``FIT_LEVEL`` for the parameters it
    lacks. Then the data do not show the slip force, and kt, fy (beta) are not determined."""
    from scipy.stats import f

    msol = micro[1]
    m = sol.residual.size
    ssr, ssr_m = float(sol.residual @ sol.residual), float(msol.residual @ msol.residual)
    q = p - len(msol.values)
    dof = max(m - p, 1)
    if ssr <= 0.0:
        return ssr_m <= 0.0
    return (ssr_m - ssr) / q <= float(f.ppf(FIT_LEVEL, q, dof)) * ssr / dof


def modal_law(model: str, law_params) -> Callable:
    """The joint law of a modal fit (backbone, response curves) from fitted values ``v`` (kt N/m, fy N,
    and chi, beta where fitted), the held ``law_params`` validated once here.

    Raises
    ------
    ValueError
        ``law_params`` that ``model`` does not take or allow.
    """
    fixed = dict(law_params or {})
    make_law(model, kt=1.0, mu=1.0, n_ref=1.0, **fixed)

    def law_of(v):
        shape = {k: v[k] for k in ("chi", "beta") if k in v}
        return make_law(model, kt=v["kt"], mu=v["fy"], n_ref=1.0, **fixed, **shape)

    return law_of


def fit_backbone(amplitude_m, omega_rad_s, damping_ratio, *, mass: float, model: str = config.MODEL,
                 law_params: dict | None = None, start: dict | None = None, refine_harmonics: int | None = None,
                 refine_samples: int = config.HB_SAMPLES) -> FitResult:
    """Fit a modal Iwan model to a measured backbone by the one-harmonic describing function.

    Parameters
    ----------
    amplitude_m : array_like
        Modal amplitudes A (first-harmonic amplitude of the measured coordinate), m.
    omega_rad_s : array_like
        Natural frequency at each amplitude, rad/s.
    damping_ratio : array_like
        Damping ratio at each amplitude (-).
    mass : float
        Modal mass m, kg (for the measured coordinate).
    model : str
        Joint law, one of :data:`BACKBONE_MODELS`.
    law_params : dict, optional
        Law parameters held during the fit (``n`` of ``discrete``).
    start : dict, optional
        Start values by name (``k``, ``kt``, ``fy``, ``zeta``, ``chi``, ``beta``).
    refine_harmonics : int, optional
        Refine the fit with EPMC of this many harmonics (>= 1): the difference between
        EPMC's backbone of the fitted model and its describing function is subtracted
        from the data and the describing-function fit repeated (a defect correction, at
        most ``FIT_REFINE_ITERATIONS`` EPMC backbones), so that the parameters are
        those whose EPMC backbone fits the data.
    refine_samples : int
        AFT samples per period of the refining EPMC.

    Returns
    -------
    FitResult
        ``parameters`` k (N/m), kt (N/m), fy_N (N), zeta (-), and chi, beta for
        ``segalman``; ``rms_residual`` of the residuals (omega - measured) / measured and
        (D - measured) / max(measured D).

    Raises
    ------
    ValueError
        Bad arrays or mass, an unknown model or parameter.
    """
    V.choice("model", model, BACKBONE_MODELS)
    A, w, D, m = _check(amplitude_m, omega_rad_s, damping_ratio, mass)
    law_of = modal_law(model, law_params)
    s_data = _start(model, A, w, D, m)
    s0 = start_values(model, s_data, start)
    params = _params(s0)
    dscale = float(np.max(D)) if np.max(D) > 0.0 else 1.0
    weights = [1.0, 1.0]

    def fun(v, dw=0.0, dD=0.0):
        wf, Df = _model(law_of(v), v["k"], v["zeta"], m, A)
        return np.concatenate((weights[0] * (wf + dw - w) / w, weights[1] * (Df + dD - D) / dscale))

    sol = solve(fun, params, starts=[s_data] + _grid(s_data))
    weights[:] = _weights(sol.residual, A.size, len(params))
    refined, defect = None, (np.zeros(A.size), np.zeros(A.size))
    if refine_harmonics is not None:
        V.positive_int("refine_harmonics", refine_harmonics)
        sol, refined, defect = _refine(sol, params, fun, law_of, m, A, refine_harmonics, refine_samples)
    law = law_of(sol.values)
    if model in MICROSLIP_MODELS:
        micro = _microslip_result(model, law, sol, m, A, w, D, dscale, weights, defect, refined)
        if _microslip_suffices(micro, sol, len(params)):
            return micro[0]
    start_at = [replace(p, value=sol.values[p.name]) if (not p.positive or sol.values[p.name] > 0.0) else p
                for p in params]
    sol = solve(lambda v: fun(v, *defect), start_at, profile=True)
    reasons = {k: "the backbone depends too weakly on it (its standard error exceeds the limit): measure more "
                  "amplitudes, into macroslip for fy and kt, in microslip for chi" for k in sol.weak}
    for k in sol.open:
        reasons[k] = (reasons[k] + "; " if k in reasons else "") + open_reason(sol.intervals[k])
    law = law_of(sol.values)
    wf, Df = _model(law, sol.values["k"], sol.values["zeta"], m, A)
    wf, Df = wf + defect[0], Df + defect[1]  # EPMC's values when refined
    status, message = status_of(sol, reasons)
    if refined is False:
        status, message = FitStatus.REFINE_FAILED, FitStatus.REFINE_FAILED.message
    ren = {"fy": "fy_N"}
    values = {ren.get(k, k): (None if k in reasons else v) for k, v in sol.values.items()}
    errors = {ren.get(k, k): (None if k in reasons else v) for k, v in sol.errors.items()}
    r = np.concatenate(((wf - w) / w, (Df - D) / dscale))
    return FitResult(kind="backbone", model=model, status=status, message=message, parameters=values,
                     standard_errors=errors, names=tuple(ren.get(p.name, p.name) for p in params),
                     correlation=sol.correlation, not_identifiable={ren.get(k, k): v for k, v in reasons.items()},
                     rms_residual=math.sqrt(float(np.mean(r * r))), law=law,
                     measured={"amplitude_m": A, "omega_rad_s": w, "damping_ratio": D},
                     fitted={"omega_rad_s": wf, "damping_ratio": Df}, evaluations=sol.evaluations,
                     intervals={ren.get(k, k): v for k, v in sol.intervals.items()},
                     conditional_on=tuple(ren.get(k, k) for k in sol.weak))

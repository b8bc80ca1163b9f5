"""A modal Iwan model fitted to a ring-down's windows, with intervals the windows justify.

The backbone that :func:`jointdyn.backbone_from_ringdown` returns comes from one smooth
decay model fitted to all windows, so its points are not independent data: a fit to them
(:func:`jointdyn.fit_backbone`) has a residual near zero and intervals far narrower than the
record justifies (over six noise seeds of an Iwan decay they held the truth in none; for a
Segalman decay R came out 50 to 80 % off with an interval of +-1 %). Here the model is fitted
to what was measured, each window's ln A(t) and frequency, with the standard errors measured
from their scatter:

    -d ln A / dt = omega D (k + K1) / (k + F'),   omega^2 = (k + K1) / m,

the microslip model of :mod:`._microslip` (k + kt, R, chi, zeta; D in EPMC's definition, the
factor (k + K1) / (k + F') that of :func:`.ringdown.epmc_factor`), ln A(t) by quadrature of
dt = -d ln A / rate over ln A. The profile-likelihood intervals then come from independent
windows. A decay that stays in microslip determines k + kt and the decay over the amplitudes
it covers; a parameter whose interval is open, or wider than a factor
``RINGDOWN_FIT_MAX_SPAN`` (chi: ``RINGDOWN_FIT_BAR_SPAN`` in chi + 1; R, chi and zeta of a
Segalman decay trade against each other), is named not determined, and the combinations it does determine (the frequency and the
damping ratio at the top and the bottom of the decay) are given with their intervals.

A decay through macroslip is not of that form: there the whole modal model (k, kt, fy, zeta;
chi, beta) is fitted to the windows by the same energy balance with the law's describing
function and virgin curve (:mod:`._lawdecay`), fall by fall of ln A between windows.

Either way the fit says over which amplitudes it determines the damping ratio within
``RINGDOWN_DAMPING_RTOL`` (:func:`damping_range`): at the bottom of a decay the windows' noise
leaves it loose (a decay through macroslip with 1 % noise: up to 8 % off EPMC's at its last
windows), and the backbone's points outside are trimmed and said so.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ._lsq import open_reason, status_of
from ._microslip import decay_fit, decay_model, microslip_model

__all__ = ["fit_ringdown", "damping_range"]

#: a parameter of a ring-down fit whose 95 % interval spans more than this factor (high / low)
#: is reported as not determined (-)
RINGDOWN_FIT_MAX_SPAN = 1.2
#: chi, and every parameter of a decay through macroslip, is reported as not determined where
#: its 95 % interval spans more than this factor (high / low; for chi, in the microslip exponent
#: chi + 1): 1.06 holds it within about 3 % on each side, so that a determined value whose
#: interval covers the truth is within 3 % of it. Over 20 noise seeds of the Segalman decay of
#: tests/test_identify_ringdown.py (chi = -0.5) chi came out -0.507 on average (bias -0.007,
#: its standard error 0.0045) with a spread of 0.020 (4 % of chi + 1) and intervals of +-0.03
#: to +-0.08: the scatter, not a bias, put it up to 0.039 (8 %) off, which such a decay cannot
#: narrow; at the span of the microslip scales (1.2) five of the 20 seeds would have called it
#: determined, two of them 5 % off. Through macroslip, at 1.2, fy_N came out 3.6 % off (seed 1
#: of the decay from 5 slip displacements) while its interval covered the truth.
RINGDOWN_FIT_BAR_SPAN = 1.06
#: the fitted model's damping ratio is reported as determined by a ring-down (``damping_range``)
#: at the amplitudes where its 95 % interval lies within this fraction of it on each side (-):
#: the accuracy asked of a ring-down's damping ratio. At the noisy bottom of a decay the windows
#: fix it less well; there the backbone is trimmed and says so.
RINGDOWN_DAMPING_RTOL = 0.05
#: relative step of the forward differences of the damping range's Jacobians (-)
RINGDOWN_RANGE_STEP = 1e-5


def _span_reason(name, iv, span: float = RINGDOWN_FIT_MAX_SPAN) -> str | None:
    """Why a closed interval is too wide to call its parameter determined (None: narrow): wider
    than the factor ``span`` (chi: ``RINGDOWN_FIT_BAR_SPAN`` in chi + 1)."""
    if name == "chi":
        wide = not (iv.low > -1.0 and (iv.high + 1.0) / (iv.low + 1.0) <= RINGDOWN_FIT_BAR_SPAN)
    else:
        wide = not (iv.low > 0.0 and iv.high / iv.low <= span)
    if not wide:
        return None
    return (f"the ring-down bounds it only loosely ({iv.low:.4g} to {iv.high:.4g}, 95 % profile likelihood): "
            f"over the amplitudes it covers it trades against the other microslip parameters; the combinations "
            f"it determines are the frequency and damping ratio at the ends of the decay")


def _ends(sol, params, win, m, chi0) -> dict:
    """The frequency and the damping ratio (EPMC's) of the fitted microslip model at the largest
    and the smallest kept amplitude, each with a 95 % interval from the linearised covariance of
    the window fit (the delta method): what a decay determines even where R, chi and zeta trade
    against each other."""
    def at(v, a):
        w, D = microslip_model(v["K"], v["R"], v.get("chi", chi0), v["zeta"], m, np.array([a]))
        return np.array([w[0], D[0]])

    return _ends_of(sol, params, win, at)


def _ends_of(sol, params, win, at) -> dict:
    """The ends of :func:`_ends` for the model ``at(values, amplitude) -> [omega, D]``."""
    from scipy.stats import norm

    names = [p.name for p in params]
    se = np.array([sol.errors[n] if sol.errors[n] is not None else np.nan for n in names])
    cov = sol.correlation * np.outer(se, se)
    z = float(norm.ppf(0.975))
    out = {}
    for tag, a in (("top", float(np.exp(np.max(win["lna"])))), ("bottom", float(np.exp(np.min(win["lna"]))))):
        f0 = at(sol.values, a)
        grad = np.empty((2, len(names)))
        for j, n in enumerate(names):
            h = 1e-6 * max(abs(sol.values[n]), 1e-3)
            grad[:, j] = (at(dict(sol.values, **{n: sol.values[n] + h}), a) - f0) / h
        sd = np.sqrt(np.abs(np.einsum("ij,jk,ik->i", grad, cov, grad)))
        for i, (key, unit, what) in enumerate(((f"omega_{tag}_rad_s", "rad/s", "natural frequency"),
                                                (f"damping_ratio_{tag}", "-", "damping ratio (EPMC's)"))):
            ok = bool(np.isfinite(sd[i]))
            out[key] = {"value": float(f0[i]), "amplitude_m": a,
                        "interval": {"low": float(f0[i] - z * sd[i]) if ok else None,
                                     "high": float(f0[i] + z * sd[i]) if ok else None, "level": 0.95,
                                     "method": "linearised (delta method)"},
                        "unit": unit, "meaning": f"{what} at the {tag} of the decay, amplitude {a:.4g} m "
                                                 f"(95 % interval linearised)"}
    return out


def damping_range(fun, values: dict, params, A, damping_of, bound: float = RINGDOWN_DAMPING_RTOL) -> dict:
    """Where a fitted ring-down model determines its damping ratio within ``bound``.

    The 95 % interval of the model's damping ratio at each amplitude ``A`` (m) is linearised
    (the delta method) from the Jacobian of the whitened window residual ``fun`` at the optimum
    ``values``: its covariance is that of the windows' measured noise, scaled up (never down) by
    the residual variance where the fit leaves more than the noise; ``damping_of(values, A)``
    gives the damping ratios. The kept range is the longest run of consecutive points whose
    interval's half-width is at most ``bound`` of the value: the noise of the windows at the
    bottom of a decay (and at its top, where few windows fall fast) sets where it ends, not a
    fixed count of windows.

    Returns
    -------
    dict
        As :attr:`jointdyn.identify.FitResult.damping_range` (JSON-ready).
    """
    from scipy.stats import norm

    from ._lsq import FIT_XTOL
    from .result import covariance

    names = [p.name for p in params]
    r0 = fun(values)
    d0 = np.asarray(damping_of(values, A), float)
    J = np.empty((r0.size, len(names)))
    G = np.empty((d0.size, len(names)))
    for j, p in enumerate(params):
        h = RINGDOWN_RANGE_STEP * (max(abs(values[p.name]), 1e-300) if p.positive else 1.0)
        v = dict(values, **{p.name: values[p.name] + h})
        J[:, j] = (fun(v) - r0) / h
        G[:, j] = (np.asarray(damping_of(v, A), float) - d0) / h
    s2 = float(r0 @ r0) / max(r0.size - len(names), 1)
    # the residual's covariance (a direction the windows do not see: infinite, so no point is
    # determined through it), at the measured noise where the residual is smaller than that
    cov = covariance(J, r0, np.ones(len(names), bool), FIT_XTOL) * (max(s2, 1.0) / max(s2, 1e-300))
    with np.errstate(invalid="ignore"):
        half = float(norm.ppf(0.975)) * np.sqrt(np.abs(np.einsum("ij,jk,ik->i", G, cov, G))) / np.abs(d0)
    ok = np.isfinite(half) & (half <= bound)
    best, run = (0, 0), 0
    for i, good in enumerate(ok):  # the longest run of consecutive determined points
        run = run + 1 if good else 0
        if run > best[1] - best[0]:
            best = (i + 1 - run, i + 1)
    lo, hi = best
    inside = np.zeros(ok.size, bool)
    inside[lo:hi] = True
    A = np.asarray(A, float)
    return {"amplitude_high_m": float(np.max(A[lo:hi])) if hi > lo else None,
            "amplitude_low_m": float(np.min(A[lo:hi])) if hi > lo else None,
            "points": int(hi - lo), "trimmed_top": int(lo), "trimmed_bottom": int(ok.size - hi),
            "bound": float(bound), "level": 0.95,
            "half_width": [float(x) if np.isfinite(x) else None for x in half],
            "determined": [bool(x) for x in inside],
            "meaning": f"amplitudes over which the fitted model's damping ratio is determined within "
                       f"+-{100 * bound:g} % (95 %, linearised from the windows' measured noise); the points "
                       f"outside are trimmed"}


def _range_text(rng: dict) -> str:
    """One clause of a fit's message on its damping range."""
    if rng["points"] == 0:
        return (f"the damping ratio is determined within +-{100 * rng['bound']:g} % at no amplitude of the decay "
                f"(95 %, from the windows' noise): a longer or less noisy record")
    if rng["trimmed_top"] + rng["trimmed_bottom"] == 0:
        return (f"damping ratio determined within +-{100 * rng['bound']:g} % (95 %) at every point, "
                f"{rng['amplitude_high_m']:.4g} down to {rng['amplitude_low_m']:.4g} m")
    return (f"damping ratio determined within +-{100 * rng['bound']:g} % (95 %) from {rng['amplitude_high_m']:.4g} "
            f"down to {rng['amplitude_low_m']:.4g} m: {rng['trimmed_top']} point(s) trimmed at the top and "
            f"{rng['trimmed_bottom']} at the bottom, where the windows' noise fixes it less well")


def fit_ringdown(ringdown, *, mass: float, model: str = "iwan", law_params: dict | None = None,
                 start: dict | None = None):
    """Fit a modal Iwan model to a ring-down (module docstring).

    The backbone's points are fitted first (:func:`jointdyn.fit_backbone`); where they stay
    in microslip and the decay model held (``ringdown.windows``), k + kt, R, chi (Segalman) and
    zeta are fitted again to the windows themselves, and their values, intervals and what
    is not determined replace the backbone fit's.

    Parameters
    ----------
    ringdown : RingdownBackbone
        From :func:`jointdyn.backbone_from_ringdown`.
    mass : float
        Modal mass for the measured coordinate, kg.
    model : str
        Joint law, one of :data:`jointdyn.identify.BACKBONE_MODELS`.
    law_params, start : dict, optional
        As in :func:`jointdyn.fit_backbone` (its fit to the backbone's points starts the fit to the
        windows).

    Returns
    -------
    FitResult
        As :func:`jointdyn.fit_backbone`'s; ``determined_combinations`` from the windows, with
        ``omega_top_rad_s``, ``damping_ratio_top`` and their ``bottom`` counterparts added.
        A decay through macroslip (its windows' ``form`` "spline", or its top above the slip
        displacement of the fit to its points) has the whole model (k, kt, fy_N, zeta; chi, beta)
        fitted to the windows' falls of ln A and frequencies (:mod:`._lawdecay`), each parameter
        whose interval spans more than ``RINGDOWN_FIT_BAR_SPAN`` named not determined; a
        RingdownBackbone without windows is the backbone fit's, and its message says that its
        intervals treat the points as independent. A fit to the windows has ``damping_range``
        (:func:`damping_range`: the amplitudes where its damping ratio is determined within
        ``RINGDOWN_DAMPING_RTOL``) and ``measured["damping_determined"]`` (1 inside, 0 outside).

    Raises
    ------
    ValueError
        A ``ringdown`` that is not a RingdownBackbone, and as :func:`jointdyn.fit_backbone`.
    """
    from .backbone import fit_backbone
    from .ringdown import RingdownBackbone

    if not isinstance(ringdown, RingdownBackbone):
        raise ValueError(f"ringdown must be a RingdownBackbone (from backbone_from_ringdown), got "
                         f"{type(ringdown).__name__}")
    # the decay's own damping ratio of a spline through macroslip may dip below 0 in the noise
    res = fit_backbone(ringdown.amplitude_m, ringdown.omega_rad_s, np.maximum(ringdown.damping_ratio, 0.0),
                       mass=mass, model=model, law_params=law_params, start=start)
    from ._microslip import MICROSLIP_MODELS, microslip_constants

    if ringdown.windows is not None and _reaches_macroslip(ringdown, res, model):
        return _through_macroslip(ringdown, float(mass), model, law_params, res)
    if ringdown.windows is None or model not in MICROSLIP_MODELS:
        note = ("; the backbone's points come from one smooth model of the decay, so these intervals, which "
                "treat them as independent, are narrower than the record justifies")
        return replace(res, message=res.message + note)
    c = res.determined_combinations
    if c:
        chi0 = c["chi"]["value"] if "chi" in c else 0.0
        start = {"K": c["k_plus_kt"]["value"], "R": c["R"]["value"], "zeta": c["zeta"]["value"], "chi": chi0}
    else:  # the full model fitted the points better, but the decay is of the microslip form throughout
        chi0, R, _ = microslip_constants(res.law)
        v = res.parameters
        start = {"K": v["k"] + v["kt"], "R": R, "zeta": v["zeta"], "chi": chi0}
        why = ("the decay is of the microslip form throughout (its decay model held: see the ring-down's "
               "message): over its amplitudes the modal model depends on k + kt, R and chi only; release from "
               "higher, into macroslip")
        gone = ("k", "kt", "fy_N") + (("beta",) if model == "segalman" else ())
        res = replace(res, parameters={**res.parameters, **{k: None for k in gone}},
                      standard_errors={**res.standard_errors, **{k: None for k in gone}},
                      intervals={**res.intervals, **{k: None for k in gone}},
                      not_identifiable={**res.not_identifiable, **{k: why for k in gone}})
    sol, params = decay_fit(ringdown.windows, float(mass), start, model == "segalman")
    return _result(res, sol, params, ringdown.windows, float(mass), chi0)


def _reaches_macroslip(ringdown, res, model) -> bool:
    """Whether the decay is to be fitted with the whole law (:func:`_through_macroslip`): its
    decay model did not hold (``form`` "spline"), or the fit of its points preferred the whole
    model to the microslip one and puts the top of the decay above the slip displacement (a
    decay from a few slip displacements whose first windows, in macroslip, still passed the
    power law's test: fitted with the microslip decay it left the damping ratio 15 % off EPMC's
    at the top)."""
    from ._microslip import MICROSLIP_MODELS, microslip_constants

    if ringdown.windows.get("form") == "spline":
        return True
    if model not in MICROSLIP_MODELS or res.determined_combinations or res.law is None:
        return False
    return microslip_constants(res.law)[2] < float(np.max(ringdown.amplitude_m))


def _through_macroslip(ringdown, m, model, law_params, res):
    """A decay through macroslip: the whole modal model (k, kt, fy, zeta; chi, beta) fitted to
    the windows' falls of ln A and frequencies (:mod:`._lawdecay`), from the fit ``res`` of the
    backbone's points, with profile intervals; a parameter whose
    interval is open or wider than ``RINGDOWN_FIT_BAR_SPAN`` is named not determined."""
    from ._lawdecay import law_decay_fit, law_decay_residual, law_rates
    from .backbone import _params, modal_law

    win = ringdown.windows
    law_of = modal_law(model, law_params)
    v0 = {("fy" if k == "fy_N" else k): v for k, v in res.parameters.items()}
    s0 = {k: (v if v is not None and (v > 0.0 or k in ("chi", "beta")) else _fallback(k, res.law, v0))
          for k, v in v0.items()}
    params = _params(s0)
    sol = law_decay_fit(win, m, law_of, params)
    ren = {"fy": "fy_N"}
    reasons, parameters, errors, intervals = {}, {}, {}, {}
    for p in params:
        iv = sol.intervals[p.name]
        why = open_reason(iv) if not iv.closed else _span_reason(p.name, iv, RINGDOWN_FIT_BAR_SPAN)
        key = ren.get(p.name, p.name)
        parameters[key], errors[key], intervals[key] = sol.values[p.name], sol.errors[p.name], iv
        if why is not None:
            reasons[key] = why.replace("the other microslip parameters", "the other parameters")
            parameters[key] = errors[key] = None
    status, message = status_of(sol, reasons)
    law = law_of(sol.values)

    def at(v, a):
        w, D, _ = law_rates(law_of(v), v["k"], v["zeta"], m, np.array([a]))
        return np.array([w[0], D[0]])

    combos = _ends_of(sol, params, win, at)
    A, w, D = (res.measured[k] for k in ("amplitude_m", "omega_rad_s", "damping_ratio"))
    wf, Df, _ = law_rates(law, sol.values["k"], sol.values["zeta"], m, A)
    rng = damping_range(law_decay_residual(win, m, law_of), sol.values, params, A,
                        lambda v, a: law_rates(law_of(v), v["k"], v["zeta"], m, a)[1])
    rb = np.concatenate(((wf - w) / w, (Df - D) / max(float(np.max(D)), 1e-300)))
    message = (f"{message}; a decay through macroslip: the whole model fitted to the ring-down's {win['t'].size} "
               f"windows (the falls of ln A between them and their frequencies, each weighted by its measured "
               f"noise: rms weighted residual {math.sqrt(float(np.mean(sol.residual ** 2))):.3g}); the damping "
               f"ratio fitted is EPMC's, the backbone's points the decay's own; {_range_text(rng)}")
    measured = dict(res.measured, damping_determined=np.array(rng["determined"], float))
    return replace(res, status=status, message=message, parameters=parameters, standard_errors=errors,
                   measured=measured, damping_range=rng,
                   intervals=intervals, not_identifiable=reasons, determined_combinations=combos, law=law,
                   names=tuple(ren.get(p.name, p.name) for p in params), correlation=sol.correlation,
                   conditional_on=(), evaluations=res.evaluations + sol.evaluations,
                   fitted={"omega_rad_s": wf, "damping_ratio": Df}, rms_residual=math.sqrt(float(np.mean(rb * rb))))


def _fallback(name, law, v0):
    """A start value for a parameter the backbone's points left undetermined (None)."""
    if name == "zeta":
        return 1e-3
    if name == "k":
        return max(float(v0.get("kt") or law.kt), 1e-9)
    return {"kt": law.kt, "fy": law.fy}[name]


def _result(res, sol, params, win, m, chi0):
    names = {"K": "k_plus_kt", "R": "R", "chi": "chi", "zeta": "zeta"}
    meaning = {"k_plus_kt": ("N/m", "stuck stiffness of the mode, k + kt"),
               "R": ("N/m^(chi+2)", "microslip coefficient: F = kt u - R u^(chi+2) / ((chi+1)(chi+2))"),
               "chi": ("-", "microslip exponent"), "zeta": ("-", "linear damping ratio at the stuck frequency")}
    combos = {}
    reasons = dict(res.not_identifiable)
    parameters, errors, intervals = dict(res.parameters), dict(res.standard_errors), dict(res.intervals)
    for p in params:
        if p.name == "lna0":
            continue
        iv = sol.intervals[p.name]
        key = names[p.name]
        combos[key] = {"value": sol.values[p.name], "interval": iv.to_dict(), "unit": meaning[key][0],
                       "meaning": meaning[key][1]}
        why = open_reason(iv) if not iv.closed else _span_reason(p.name, iv)
        if why is not None:
            combos[key]["not_determined"] = why
        if p.name in ("zeta", "chi"):
            parameters[p.name], errors[p.name], intervals[p.name] = sol.values[p.name], sol.errors[p.name], iv
            reasons.pop(p.name, None)
            if why is not None:
                reasons[p.name] = why
                parameters[p.name] = errors[p.name] = None
    combos.update(_ends(sol, params, win, m, chi0))
    status, message = status_of(sol, reasons)
    lf, wf = decay_model(dict(sol.values, chi=sol.values.get("chi", chi0)), m, win["t"], float(win["lna"][-1]))
    r = np.concatenate(((lf - win["lna"]) / win["sigma_lna"], (wf - win["omega"]) / win["sigma_omega"]))
    loose = [k for k, v in combos.items() if "not_determined" in v and k not in ("zeta", "chi")]
    if loose:
        message += "; " + "; ".join(f"{k} not determined: {combos[k]['not_determined']}" for k in loose)
    message = (f"{message}; fitted to the ring-down's {win['t'].size} windows (ln A and frequency, each weighted by "
               f"its measured noise: rms weighted residual {math.sqrt(float(np.mean(r * r))):.3g})")
    v = sol.values
    A, w, D = (res.measured[k] for k in ("amplitude_m", "omega_rad_s", "damping_ratio"))
    wf, Df = microslip_model(v["K"], v["R"], v.get("chi", chi0), v["zeta"], m, A)
    rb = np.concatenate(((wf - w) / w, (Df - D) / max(float(np.max(D)), 1e-300)))

    def fun(u):  # the window residual of decay_fit
        lf_, wf_ = decay_model(dict(u, chi=u.get("chi", chi0)), m, win["t"], float(win["lna"][-1]))
        return np.concatenate(((lf_ - win["lna"]) / win["sigma_lna"], (wf_ - win["omega"]) / win["sigma_omega"]))

    rng = damping_range(fun, v, params, A,
                        lambda u, a: microslip_model(u["K"], u["R"], u.get("chi", chi0), u["zeta"], m, a)[1])
    message += "; " + _range_text(rng)
    return replace(res, status=status, message=message, parameters=parameters, standard_errors=errors,
                   measured=dict(res.measured, damping_determined=np.array(rng["determined"], float)),
                   damping_range=rng,
                   intervals=intervals, not_identifiable=reasons, determined_combinations=combos,
                   evaluations=res.evaluations + sol.evaluations, fitted={"omega_rad_s": wf, "damping_ratio": Df},
                   rms_residual=math.sqrt(float(np.mean(rb * rb))))

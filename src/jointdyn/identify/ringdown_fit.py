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
``RINGDOWN_FIT_MAX_SPAN`` (R, chi and zeta of a Segalman decay trade against each other),
is named not determined, and the combinations it does determine (the frequency and the
damping ratio at the top and the bottom of the decay) are given with their intervals.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ._lsq import Param, open_reason, solve, status_of
from ._microslip import decay_fit, decay_model, microslip_model

__all__ = ["fit_ringdown"]

#: a parameter of a ring-down fit whose 95 % interval spans more than this factor (high / low;
#: for chi, more than this minus one in absolute terms) is reported as not determined (-)
RINGDOWN_FIT_MAX_SPAN = 1.2


def _span_reason(name, iv) -> str | None:
    """Why a closed interval is too wide to call its parameter determined (None: narrow)."""
    if name == "chi":
        wide = iv.high - iv.low > 2.0 * (RINGDOWN_FIT_MAX_SPAN - 1.0)
    else:
        wide = not (iv.low > 0.0 and iv.high / iv.low <= RINGDOWN_FIT_MAX_SPAN)
    if not wide:
        return None
    return (f"the ring-down bounds it only loosely ({iv.low:.4g} to {iv.high:.4g}, 95 % profile likelihood): "
            f"over the amplitudes it covers it trades against the other microslip parameters; the combinations "
            f"it determines are the frequency and damping ratio at the ends of the decay")


def _ends(sol, params, win, m, chi0) -> dict:
    """The frequency and the damping ratio (EPMC's) of the fitted model at the largest and the
    smallest kept amplitude, each with a 95 % interval from the linearised covariance of the
    window fit (the delta method): what a decay determines even where R, chi and zeta trade
    against each other."""
    from scipy.stats import norm

    names = [p.name for p in params]
    se = np.array([sol.errors[n] if sol.errors[n] is not None else np.nan for n in names])
    cov = sol.correlation * np.outer(se, se)
    z = float(norm.ppf(0.975))

    def at(v, a):
        w, D = microslip_model(v["K"], v["R"], v.get("chi", chi0), v["zeta"], m, np.array([a]))
        return np.array([w[0], D[0]])

    out = {}
    for tag, a in (("top", float(np.exp(win["lna"][0]))), ("bottom", float(np.exp(win["lna"][-1])))):
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
        A decay through macroslip (``ringdown.windows`` None) is the backbone fit's, and its
        message says that its intervals treat the points as independent.

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
    res = fit_backbone(ringdown.amplitude_m, ringdown.omega_rad_s, ringdown.damping_ratio, mass=mass, model=model,
                       law_params=law_params, start=start)
    from ._microslip import MICROSLIP_MODELS, microslip_constants

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
    return replace(res, status=status, message=message, parameters=parameters, standard_errors=errors,
                   intervals=intervals, not_identifiable=reasons, determined_combinations=combos,
                   evaluations=res.evaluations + sol.evaluations, fitted={"omega_rad_s": wf, "damping_ratio": Df},
                   rms_residual=math.sqrt(float(np.mean(rb * rb))))

"""Fit a contact law to measured hysteresis loops (t, x, N, T).

Least squares of the law's force, marched under the measured displacement
x(t) and normal load N(t) from the virgin state at the first sample, against
the measured force T (docs/model.md, "Identification"). The normal load is
measured, so the friction coefficient mu is fitted (not only fy at one load).
Start values come from the data: kt from the initial slope after the
reversals (all elements stick there), mu from the macroslip plateau of
|T| / N, chi (Segalman) from the slope of log(energy per cycle) against
log(amplitude) (chi + 3 in microslip).
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate as V
from .. import config
from ..drivers import march
from ..laws import MACROSLIP, law_parameters, make_law
from ..laws.segalman import CHI_MAX, CHI_MIN
from ._lsq import (FIT_BETA_MAX, FIT_BETA_START, FIT_GRID_BETA, FIT_GRID_CHI, FIT_GRID_SLIP, Param, open_reason,
                   solve, start_values, status_of)
from .result import FitResult

__all__ = ["fit_loops", "LOOP_MODELS"]

#: laws a loop fit accepts
LOOP_MODELS = ("jenkins", "iwan", "segalman", "iwan-closed", "discrete")
#: law parameters fitted when the law has them (the others are held at their given values)
SHAPE_PARAMS = ("chi", "beta")
#: the displacement window after a reversal over which the initial slope (start of kt) is
#: measured, as a fraction of the peak-to-peak displacement (-)
FIT_SLOPE_WINDOW = 0.03
#: quantile of |T| / N over the samples in contact taken as the start of mu (-)
FIT_MU_QUANTILE = 0.99
#: a record whose |T| at the first sample is at most this fraction of max |T| (-) starts
#: from rest; samples of the ramp from rest to the first sample of any other record
FIT_REST_FORCE = 0.05
FIT_RAMP_SAMPLES = 200
#: a record fitted from rest whose first stroke leaves an rms residual above this many times
#: that of the rest was picked up mid-cycle (its first stroke then sets the state) (-)
FIT_FIRST_STROKE_MISFIT = 3.0


def _array(name, v):
    try:
        a = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a 1-D array of finite numbers") from None
    if a.ndim != 1 or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be a 1-D array of finite numbers, got shape {a.shape}")
    return a


def _check(x, N, T):
    x, N, T = _array("x", x), _array("N", N), _array("T", T)
    if not (x.size == N.size == T.size):
        raise ValueError(f"x, N and T must have one length, got {x.size}, {N.size}, {T.size}")
    if x.size < 10:
        raise ValueError(f"x must have at least 10 samples, got {x.size}")
    if x.size > config.FIT_MAX_LOOP_SAMPLES:  # the bound of fit --input, before any fitting
        raise ValueError(f"x must have at most {config.FIT_MAX_LOOP_SAMPLES} samples (config.FIT_MAX_LOOP_SAMPLES: "
                         f"the law is evaluated over every sample some hundred times), got {x.size}")
    if not np.any(N > 0.0):
        raise ValueError("N must be positive (in contact) at some samples: no sample has N > 0")
    if not np.ptp(x) > 0.0:
        raise ValueError("x must move: every sample is the same")
    if not np.any(T != 0.0):
        raise ValueError("T must not be zero at every sample")
    return x, N, T


def _reversals(x):
    """Indices of the samples where the direction of x changes (and 0)."""
    d = np.sign(np.diff(x))
    nz = np.flatnonzero(d)
    if nz.size == 0:
        return np.array([0])
    dd = d[nz]
    turns = nz[1:][dd[1:] != dd[:-1]]  # first move in the new direction starts at turns; reversal sample = turns
    return np.concatenate(([0], turns))


def _start_kt(x, T, rev):
    """Median slope of T against x just after each reversal (all elements stick)."""
    w = FIT_SLOPE_WINDOW * np.ptp(x)
    slopes = []
    ends = np.concatenate((rev[1:], [x.size - 1]))
    for r, e in zip(rev, ends):
        seg = slice(r, e + 1)
        near = np.abs(x[seg] - x[r]) <= w
        if np.count_nonzero(near) >= 3:
            xs, ts = x[seg][near], T[seg][near]
            if np.ptp(xs) > 0.0:
                slopes.append(np.polyfit(xs, ts, 1)[0])
    slopes = [s for s in slopes if s > 0.0]
    if not slopes:  # too few samples near the reversals: the secant of the whole record
        return max(np.ptp(T) / np.ptp(x), 1e-300)
    return float(np.median(slopes))


def _cycle_energies(x, T, rev):
    """(amplitude m, energy J) of each closed cycle between every other reversal."""
    out = []
    for i in range(rev.size - 2):
        a, b = rev[i], rev[i + 2]
        if i == 0 and a == 0:
            continue  # the virgin start is not a cycle
        amp = 0.5 * abs(x[rev[i + 1]] - x[a])
        e = abs(float(np.sum(0.5 * (T[a + 1 : b + 1] + T[a:b]) * np.diff(x[a : b + 1]))))
        if amp > 0.0 and e > 0.0:
            out.append((amp, e))
    return out


def _start_chi(x, T, rev, x_slip):
    """chi from the log-log slope of energy against amplitude (chi + 3) of the cycles in
    microslip; the default when fewer than two distinct amplitudes are there."""
    cyc = [(a, e) for a, e in _cycle_energies(x, T, rev) if a < 0.7 * x_slip]
    if len(cyc) >= 2:
        amps = np.array([c[0] for c in cyc])
        if amps.max() > 1.2 * amps.min():
            slope = np.polyfit(np.log(amps), np.log([c[1] for c in cyc]), 1)[0]
            return float(np.clip(slope - 3.0, CHI_MIN + 0.01, 1.0))
    return config.SEGALMAN_CHI


def _start(model, x, N, T, n_ref):
    """Start values (dict) from the data (module docstring)."""
    rev = _reversals(x)
    kt0 = _start_kt(x, T, rev)
    on = N > 0.0
    mu0 = float(np.quantile(np.abs(T[on]) / N[on], FIT_MU_QUANTILE))
    mu0 = max(mu0, 1e-12)
    start = {"kt": kt0, "mu": mu0}
    names = {p.name for p in law_parameters(model)}
    if "chi" in names:
        start["chi"] = _start_chi(x, T, rev, 2.0 * mu0 * n_ref / kt0)
    if "beta" in names:
        start["beta"] = FIT_BETA_START
    return start


def _params(model, start) -> list:
    out = [Param("kt", start["kt"], True, 1e-3 * start["kt"], 1e3 * start["kt"]),
           Param("mu", start["mu"], True, 1e-3 * start["mu"], 1e3 * start["mu"])]
    if "chi" in start:
        out.append(Param("chi", start["chi"], False, CHI_MIN, CHI_MAX))
    if "beta" in start:
        out.append(Param("beta", start["beta"], False, 0.0, FIT_BETA_MAX))
    return out


def _grid(s0) -> list:
    """Further start points of a Segalman fit (a global start): a grid over chi, beta and the
    slip force (mu) around the data's start values ``s0``."""
    if "beta" not in s0:
        return []
    return [{**s0, "chi": c, "beta": b, "mu": f * s0["mu"]}
            for c in FIT_GRID_CHI for b in FIT_GRID_BETA for f in FIT_GRID_SLIP]


def _record_start(x, N, T, from_rest):
    """(x and N to march, the mask of the record's samples fitted, a sentence saying how the
    initial slip state was set). A record from rest (|T| at the first sample at most
    ``FIT_REST_FORCE`` of max |T|, or ``from_rest``) is marched from the virgin state
    at its first sample and fitted whole. Any other record (a steady cycle picked up
    anywhere) is marched after a ramp from rest at x = 0 to its first sample, and its
    samples before the second reversal (the first full stroke between its extremes, which
    sets the state of every element that slips) only set the slip state: they are not
    fitted."""
    if from_rest is None:
        from_rest = abs(float(T[0])) <= FIT_REST_FORCE * float(np.max(np.abs(T)))
    if from_rest:
        return x, N, np.ones(x.size, bool), "from rest: the virgin state at the first sample"
    rev = _reversals(x)
    if rev.size < 3:
        raise ValueError("the record does not start from rest (T at the first sample is not 0) and has no full "
                         "stroke between two reversals to set the slip state: record at least one full cycle")
    ramp = np.linspace(0.0, float(x[0]), FIT_RAMP_SAMPLES, endpoint=False)
    fitted = np.arange(x.size) >= rev[2]
    return (np.concatenate((ramp, x)), np.concatenate((np.full(ramp.size, N[0]), N)), fitted,
            f"mid-cycle: ramped from rest at x = 0 to the first sample; samples 0 to {int(rev[2]) - 1} (the first "
            f"stroke) set the slip state and are not fitted")


def _setup(model, x, N, T, n_ref, fixed, from_rest) -> dict:
    """The pieces of a loop fit for one way of starting the record (:func:`_record_start`):
    the law of a parameter dict, the force on the record's samples, the residual function,
    the fitted-sample mask, the marched x and N and the sentence on the start."""
    xm, Nm, fitted, record_start = _record_start(x, N, T, from_rest)
    scale = float(np.max(np.abs(T)))

    def law_of(v):
        shape = {k: v[k] for k in SHAPE_PARAMS if k in v}
        return make_law(model, kt=v["kt"], mu=v["mu"], n_ref=n_ref, **fixed, **shape)

    def force(law):
        return march(law, xm, Nm)[0][xm.size - x.size:]

    def fun(v):
        return (force(law_of(v))[fitted] - T[fitted]) / scale

    return {"law_of": law_of, "force": force, "fun": fun, "fitted": fitted, "xm": xm, "Nm": Nm,
            "record_start": record_start, "from_rest": xm.size == x.size}


def _first_stroke_misfit(setup, values, x, T) -> bool:
    """Whether a record taken to start from rest (|T| small at its first sample) is fitted on
    its first stroke much worse than after it: then it was picked up in a steady cycle where
    the force happened to cross zero, and its first stroke must only set the slip state."""
    rev = _reversals(x)
    if rev.size < 3 or rev[2] < 10 or x.size - rev[2] < 10:
        return False
    r = setup["force"](setup["law_of"](values)) - T
    first, rest = r[: rev[2]], r[rev[2]:]
    return math.sqrt(float(np.mean(first * first))) > FIT_FIRST_STROKE_MISFIT * math.sqrt(
        float(np.mean(rest * rest)))


def _reasons(weak, law, xm, Nm, T, T_fit, n):
    """Why each weak parameter is not determined, from the fitted model's motion states."""
    code = march(law, xm, Nm)[2][xm.size - n:]
    x, N = xm[xm.size - n:], Nm[Nm.size - n:]
    on = N > 0.0
    use = float(np.max(np.abs(T_fit[on]) / (law.mu * N[on]))) if law.mu > 0.0 else 0.0
    macro = int(np.count_nonzero(code == MACROSLIP))
    # samples between stick and macroslip: the measured force clearly below the fitted plateau mu N
    micro = int(np.count_nonzero(on & (np.abs(T) < 0.9 * law.mu * np.maximum(N, 0.0)) & (code != MACROSLIP)))
    out = {}
    for name in weak:
        if name == "mu" and macro == 0:
            out[name] = (f"the loops never slip (|T| reaches at most {100 * use:.3g} % of mu N): the force does "
                         f"not determine the friction coefficient")
        elif name in SHAPE_PARAMS and micro < 0.05 * x.size:
            out[name] = (f"almost no microslip in the data ({micro} of {x.size} samples, the rest stuck or in "
                         f"macroslip): the shape of the slip-force density is not seen")
        else:
            out[name] = "the force depends too weakly on it for these data (its standard error exceeds the limit)"
    return out


def fit_loops(x, N, T, model: str = config.MODEL, *, t=None, n_ref: float | None = None,
              law_params: dict | None = None, start: dict | None = None, from_rest: bool | None = None) -> FitResult:
    """Fit a contact law to measured loops: least squares of its force under the measured x, N.

    Parameters
    ----------
    x : array_like
        Tangential displacement samples, m (the first sample is the virgin state).
    N : array_like
        Normal-load samples, N (N <= 0: separation).
    T : array_like
        Measured tangential force, N.
    model : str
        One of :data:`LOOP_MODELS`: ``jenkins``, ``iwan``, ``segalman``, ``iwan-closed``,
        ``discrete``.
    t : array_like, optional
        Time samples, s (kept with the data; the laws are rate independent).
    n_ref : float, optional
        Reference normal load, N (default the mean of N over the samples in contact);
        fy_N = mu n_ref.
    law_params : dict, optional
        Law parameters held during the fit (e.g. ``n`` of ``discrete``, ``capacity``).
    start : dict, optional
        Start values by name (``kt``, ``mu``, ``chi``, ``beta``); least squares begins at
        the one of these, the data's own start values and (Segalman) a grid over chi, beta
        and mu around them, whose sum of squares is least, so a poor start does not hold
        the fit.
    from_rest : bool, optional
        Whether the record starts from rest (the virgin state at the first sample). Default:
        when |T| at the first sample is at most ``FIT_REST_FORCE`` of max |T|.
        Otherwise, or when the fit from rest leaves on the first stroke an rms residual above
        ``FIT_FIRST_STROKE_MISFIT`` times that of the rest of the record, the first
        stroke only sets the slip state (``FitResult.record_start`` says which).

    Returns
    -------
    FitResult
        ``parameters`` kt (N/m), mu, fy_N (N), and chi, beta for ``segalman``.

    Raises
    ------
    ValueError
        Bad arrays (not 1-D, not finite, different lengths, fewer than 10 samples, no
        contact, no motion) or an unknown model or parameter.
    """
    V.choice("model", model, LOOP_MODELS)
    x, N, T = _check(x, N, T)
    fixed = dict(law_params or {})
    for k in fixed:
        if k in SHAPE_PARAMS:
            raise ValueError(f"law_params must not hold the fitted parameter {k}")
    make_law(model, kt=1.0, mu=1.0, n_ref=1.0, **fixed)  # validates the held law parameters
    n_ref = float(np.mean(N[N > 0.0])) if n_ref is None else V.positive("n_ref", n_ref)
    s_data = _start(model, x, N, T, n_ref)
    s0 = start_values(model, s_data, start)
    params = _params(model, s0)
    starts = [s_data] + _grid(s_data)
    setup = _setup(model, x, N, T, n_ref, fixed, from_rest)
    if from_rest is None and setup["from_rest"]:
        first = solve(setup["fun"], params, starts=starts)
        if _first_stroke_misfit(setup, first.values, x, T):
            setup = _setup(model, x, N, T, n_ref, fixed, False)
    law_of, force, fitted, xm, Nm = (setup[k] for k in ("law_of", "force", "fitted", "xm", "Nm"))
    sol = solve(setup["fun"], params, profile=True, starts=starts)
    law = law_of(sol.values)  # the optimum: one of the models that fit, also where some are not determined
    T_fit = force(law)
    weak = list(sol.weak) + [k for k in sol.open if k not in sol.weak]
    reasons = _reasons(weak, law, xm, Nm, T, T_fit, x.size)
    for k in sol.open:
        reasons[k] = f"{reasons[k]}; {open_reason(sol.intervals[k])}"
    status, message = status_of(sol, reasons)
    values = {k: (None if k in reasons else v) for k, v in sol.values.items()}
    errors = {k: (None if k in reasons else v) for k, v in sol.errors.items()}
    values["fy_N"] = None if values["mu"] is None else values["mu"] * n_ref
    errors["fy_N"] = None if errors["mu"] is None else errors["mu"] * n_ref
    intervals = dict(sol.intervals)
    iv = intervals["mu"]
    intervals["fy_N"] = type(iv)(*(None if b is None else b * n_ref for b in (iv.low, iv.high)), iv.level)
    r = (T_fit - T)[fitted]
    measured = {"x": x, "N": N, "T": T}
    if t is not None:
        measured["t"] = _array("t", t)
    return FitResult(kind="loops", model=model, status=status, message=message, parameters=values,
                     standard_errors=errors, names=tuple(p.name for p in params), correlation=sol.correlation,
                     not_identifiable=reasons, rms_residual=math.sqrt(float(np.mean(r * r))), n_ref=n_ref,
                     law=law, measured=measured, fitted={"T": T_fit}, evaluations=sol.evaluations,
                     intervals=intervals, conditional_on=tuple(sol.weak), record_start=setup["record_start"])

"""Intervals that cover the truth (issue 32): over 20 noise seeds for each kind of data, the
true value lies inside the reported 95 % profile-likelihood interval, or the parameter is
named as not determined, in at least 90 % of the fits, for every parameter; and parameters
the data cannot separate are named with the combination they do determine.

The data are made by the models themselves (jointdyn.march for loops, the describing
function for backbones, whose closed forms tests/test_identify.py checks), with white noise
of one standard deviation per column: 1 % of max |T| on loops; 0.1 % of omega and 1 % of the
largest damping ratio on backbones. With an exact model and such noise, a 95 % interval
misses in 1 fit of 20 on average; the bar of 18 of 20 leaves room for that, not for the
misses of linearised errors (16 standard errors off, issue 32)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.identify import FitStatus, describing_function, fit_backbone, fit_loops
from jointdyn.identify._microslip import microslip_constants
from jointdyn.laws import make_law

KT, NREF, SEEDS = 1e5, 100.0, 20
SEG = dict(chi=-0.5, beta=0.2)


def _covers(iv, true):
    return (iv.low is None or iv.low <= true) and (iv.high is None or true <= iv.high)


def _tally(fits, true):
    """(hits, named-not-determined) per parameter over the fits."""
    hits = {k: 0 for k in true}
    named = {k: 0 for k in true}
    for fit in fits:
        for k, v in true.items():
            if k in fit.not_identifiable:
                named[k] += 1
                hits[k] += 1
            else:
                hits[k] += _covers(fit.intervals[k], v)
    return hits, named


def _loops(case, seed):
    law = make_law("segalman", kt=KT, mu=0.3, n_ref=NREF, **SEG)
    t = np.linspace(0.0, 3.0, 600)
    if case == "macroslip":  # growing loops from 0.1 to 1.6 slip displacements, load +-30 %
        x = law.x_slip * np.sin(2 * np.pi * t) * np.interp(t, [0.0, 3.0], [0.1, 1.6])
        N = NREF * (1.0 + 0.3 * np.sin(2 * np.pi * t + 0.9))
    else:  # 0.85 slip displacements: macroslip only where the load is low (0.5 to 1.5 N_ref)
        x = 0.85 * law.x_slip * np.sin(2 * np.pi * t)
        N = NREF * (1.0 + 0.5 * np.sin(2 * np.pi * 0.37 * t + 0.3))
    T = jd.march(law, x, N)[0]
    T = T + 0.01 * np.max(np.abs(T)) * np.random.default_rng(seed).normal(size=T.size)
    return x, N, T


@pytest.mark.parametrize("case", ["macroslip", "macroslip-at-low-load"])
def test_loop_intervals_cover_the_truth(case):
    true = {"kt": KT, "mu": 0.3, "fy_N": 0.3 * NREF, "chi": SEG["chi"], "beta": SEG["beta"]}
    fits = [fit_loops(*_loops(case, seed), "segalman", n_ref=NREF) for seed in range(SEEDS)]
    hits, named = _tally(fits, true)
    assert min(hits.values()) >= 18, (hits, named)
    # the intervals are not vacuous: these loops determine every parameter in most fits,
    # and the intervals are narrow (a few percent)
    assert max(named.values()) <= 2, named
    for fit in fits:
        if not fit.not_identifiable:
            iv = fit.intervals["mu"]
            assert iv.high - iv.low < 0.05 * 0.3
            assert fit.intervals["fy_N"].low == pytest.approx(iv.low * NREF)


def _backbone(model, amplitudes, seed):
    law = make_law(model, kt=KT, mu=0.2, n_ref=NREF, **(SEG if model == "segalman" else {}))
    chi, R, pm = microslip_constants(law)
    m, k, zeta = 2.0, 4e5, 0.002
    A = np.asarray(amplitudes) * pm
    k1, en = describing_function(law, A)
    w = np.sqrt((k + k1) / m)
    D = en / (2.0 * math.pi * m * w * w * A * A) + zeta * math.sqrt((k + KT) / m) / w
    rng = np.random.default_rng(seed)
    w = w * (1.0 + 0.001 * rng.normal(size=A.size))
    D = D + 0.01 * D.max() * rng.normal(size=A.size)
    true = {"k": k, "kt": KT, "fy_N": law.fy, "zeta": zeta}
    if model == "segalman":
        true.update(SEG)
    return (A, w, D, m), true, {"k_plus_kt": k + KT, "R": R, "chi": chi, "zeta": zeta}


def test_backbone_into_macroslip_intervals_cover_the_truth():
    """40 seeds here: measured over 80 seeds the rates are 96, 96, 95 and 92.5 % for k, kt,
    fy_N and zeta; with 20, a 95 % interval falls below 18 hits in 7.5 % of seed sets."""
    fits = []
    for seed in range(2 * SEEDS):
        (A, w, D, m), true, _ = _backbone("iwan", np.geomspace(0.05, 5.0, 25), seed)
        fits.append(fit_backbone(A, w, D, mass=m, model="iwan"))
    hits, named = _tally(fits, true)
    assert min(hits.values()) >= 36, (hits, named)
    assert max(named.values()) <= 4, named
    assert all(not f.determined_combinations for f in fits)


def test_microslip_backbone_names_what_it_determines_and_covers_it():
    """Amplitudes up to 0.95 of the slip displacement (issue 32's case): kt, fy_N, k and beta
    named not determined, the combinations k + kt, R, chi and zeta given, with intervals
    that cover their true values."""
    fits, combos = [], []
    for seed in range(SEEDS):
        (A, w, D, m), true, comb = _backbone("segalman", np.geomspace(0.03, 0.95, 25), seed)
        fit = fit_backbone(A, w, D, mass=m, model="segalman")
        fits.append(fit)
        combos.append(comb)
    hits, named = _tally(fits, true)
    assert min(hits.values()) >= 18, (hits, named)
    for fit in fits:
        assert fit.status is FitStatus.PARTLY_IDENTIFIED and not fit.status.ok
        assert {"k", "kt", "fy_N", "beta"} <= set(fit.not_identifiable)
        assert fit.parameters["kt"] is None and fit.parameters["fy_N"] is None
        assert "microslip" in fit.not_identifiable["kt"]
        assert set(fit.determined_combinations) == {"k_plus_kt", "R", "chi", "zeta"}
        json_keys = set(fit.to_dict())
        assert {"intervals", "determined_combinations", "standard_errors_conditional_on"} <= json_keys
    ok = {k: sum(_covers_dict(f.determined_combinations[k]["interval"], c[k]) for f, c in zip(fits, combos))
          for k in combos[0]}
    assert min(ok.values()) >= 18, ok


def _covers_dict(iv, true):
    return (iv["low"] is None or iv["low"] <= true) and (iv["high"] is None or true <= iv["high"])

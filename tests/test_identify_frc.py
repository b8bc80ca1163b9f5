"""Stepped-sine response curves to a modal Iwan model (jointdyn.identify.fit_frc): curves made
by harmonic balance (one harmonic: the describing function's own model) at three force levels,
50 points each, 1 % noise on the amplitude: every parameter within 3 % and inside its 95 %
interval (the coverage over seeds is measured by benchmarks/coverage_frc.py), and the model's
response solved by fit_frc's root search against the curves without noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.hb import frc_hb
from jointdyn.identify.frc import fit_frc


#: AFT samples of the curves: at the automatic choice (128) harmonic balance's response is up to
#: 0.1 % in amplitude off the exact one-harmonic model the fit uses, systematically (comparable
#: to what 150 points of 1 % noise resolve); at 1024, 1.3e-5
SAMPLES = 1024


def _curves():
    law = jd.make_law("iwan", kt=1e5, mu=0.2, n_ref=100.0)
    m, k, zeta = 2.0, 4e5, 0.002
    cols = []
    for F in (5.0, 15.0, 30.0):  # below, into and well beyond macroslip at resonance
        s = jd.System.sdof(m=m, k=k, law=law, f1=F, c=2 * zeta * math.sqrt((k + 1e5) * m), n0=100.0)
        ds = frc_hb(s, 0.85, 1.1, harmonics=1, samples=SAMPLES, progress=False)
        assert ds.attrs["status"] == "complete"
        g, A = np.asarray(ds["gamma"]), np.asarray(ds["amplitude_m"])
        pick = np.linspace(0, g.size - 1, 50).astype(int)
        cols.append(np.column_stack([np.full(50, F), g[pick] * s.w0, A[pick]]))
    return np.concatenate(cols).T


def test_response_curves_by_hb_give_the_parameters_within_3_percent():
    m, k, zeta = 2.0, 4e5, 0.002
    F, w, A = _curves()
    A = A * (1.0 + 0.01 * np.random.default_rng(0).normal(size=A.size))
    fit = fit_frc(F, w, A, mass=m, model="iwan")
    assert fit.status.ok, fit.message
    true = {"k": k, "kt": 1e5, "fy_N": 20.0, "zeta": zeta}
    err = {n: fit.parameters[n] / v - 1.0 for n, v in true.items()}
    print("relative errors", err, "intervals", {n: (v.low, v.high) for n, v in fit.intervals.items()})
    # measured at seed 0 (curves with 1024 AFT samples): k -0.006 %, kt -0.002 %, fy_N +0.08 %,
    # zeta -0.09 % (the weighted equation error before the amplitude's own error gave zeta
    # +5.3 % and missed kt, fy, zeta)
    for name in true:
        assert abs(err[name]) < 0.03, err
        assert fit.intervals[name].closed and fit.intervals[name].covers(true[name]), name


def test_the_models_response_is_the_hb_curve():
    """fit_frc's response (the stable root of |Z(A)| A = F nearest the measurement) at the true
    parameters gives the HB curves' amplitudes within 1e-4 (measured 1.3e-5 with 1024 AFT samples;
    0.1 % with harmonic balance's automatic 128), the upper and the lower branch of a fold alike."""
    from jointdyn.identify.backbone import describing_function
    from jointdyn.identify.frc import response

    law = jd.make_law("iwan", kt=1e5, mu=20.0, n_ref=1.0)  # fy = 20 N at N = n_ref
    m, k, c = 2.0, 4e5, 2 * 0.002 * math.sqrt(5e5 * 2.0)
    F, w, A = _curves()

    def ratio(a):
        a = np.asarray(a, dtype=float)
        k1, en = (x.reshape(a.shape) for x in describing_function(law, a.ravel()))
        return np.hypot(k + k1 - m * w * w, en / (math.pi * a * a) + c * w) * a / F

    got = response(ratio, A, np.geomspace(A.min() / 3.0, A.max() * 3.0, 100))
    assert np.max(np.abs(got / A - 1.0)) < 1e-4

"""Single-nonlinear-mode synthesis: against full harmonic balance on the paper's
damper, the exact linear limit, the Den Hartog case, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
import tolerances as tol
from jointdyn.hb import frc_hb
from jointdyn.modes import epmc, qsma, single_mode_frc


def _hb_peak(system):
    """(first-harmonic amplitude m, gamma) at the point of largest first harmonic of a fine HB branch."""
    ds = frc_hb(system, 0.8, 1.6, progress=False, ds_max=0.01)
    assert ds.attrs["status"] == "complete"
    a = ds.harmonic_amplitude_m.values[:, 1]
    g = ds.gamma.values
    i = int(np.argmax(a))
    return a[i], g[i]


@pytest.mark.parametrize("beta", [1.0, 2.0, 5.0, 10.0])
def test_peak_matches_full_harmonic_balance(beta):
    s = jd.System.paper_damper(eta=0.0, beta=beta)
    ds = single_mode_frc(epmc(s, progress=False))
    assert ds.attrs["status"] == "complete"
    a_hb, g_hb = _hb_peak(s)
    assert ds.attrs["peak_amplitude_m"] == pytest.approx(a_hb, rel=tol.TEST_MODES_SYNTHESIS_RTOL)
    assert ds.attrs["peak_gamma"] == pytest.approx(g_hb, rel=tol.TEST_MODES_SYNTHESIS_RTOL)
    # the curve: low flank up to the peak, then the high flank down
    f = ds.flank.values
    assert list(np.unique(f)) == [-1, 0, 1] and np.all(np.diff(f) >= 0)
    peak = int(np.flatnonzero(f == 0)[0])
    assert ds.amplitude_m.values[peak] == pytest.approx(ds.amplitude_m.values.max(), rel=1e-12)
    assert np.all(np.diff(ds.omega_rad_s.values) >= 0)


def test_linear_limit_is_the_exact_frf():
    """Stuck Jenkins contact and viscous damping: the mode is linear and the synthesis
    is the exact FRF of the single DOF, |x| = F / (m sqrt((w^2 - W^2)^2 + (2 zeta w W)^2))."""
    m, k, kt = 10.0, 3.9e5, 3e5
    zeta = 0.02
    w = math.sqrt((k + kt) / m)
    f1 = 1.0  # far too weak to slip the 50 N element near resonance
    s = jd.System.sdof(m=m, k=k, law=jd.make_law("jenkins", kt=kt, mu=0.5, n_ref=100.0), f1=f1,
                       c=2 * zeta * math.sqrt((k + kt) * m))
    b = epmc(s, (1e-7, 1e-4), harmonics=3, progress=False)
    ds = single_mode_frc(b)
    assert ds.attrs["status"] == "complete"
    W = ds.omega_rad_s.values
    A = f1 / (m * np.sqrt((w * w - W * W) ** 2 + (2 * zeta * w * W) ** 2))
    np.testing.assert_allclose(ds.amplitude_m.values, A, rtol=1e-9)
    # the peak of a linear oscillator
    assert ds.attrs["peak_omega_rad_s"] == pytest.approx(w * math.sqrt(1 - 2 * zeta ** 2), rel=1e-9)
    assert ds.attrs["peak_amplitude_m"] == pytest.approx(f1 / (2 * zeta * m * w * w * math.sqrt(1 - zeta ** 2)),
                                                         rel=1e-9)


def test_below_the_den_hartog_limit_the_peak_is_above_the_range():
    s = jd.System.paper_damper(eta=0.0, beta=0.5)  # R/F = 0.5 < pi/4: unbounded at resonance
    ds = single_mode_frc(epmc(s, progress=False))
    assert ds.attrs["status"] == "peak-above-range" and math.isnan(ds.attrs["peak_amplitude_m"])


def test_from_qsma_and_with_another_forcing():
    s = jd.System.paper_damper(eta=0.0, beta=5.0)
    ds = single_mode_frc(qsma(s))
    assert ds.attrs["status"] == "complete" and ds.attrs["backbone_method"] == "qsma"
    a_hb, g_hb = _hb_peak(s)
    assert ds.attrs["peak_amplitude_m"] == pytest.approx(a_hb, rel=tol.TEST_MODES_SYNTHESIS_RTOL)
    # a weaker forcing given as another System with the same structure: a lower peak
    weak = jd.System.paper_damper(eta=0.0, beta=10.0)
    ds2 = single_mode_frc(epmc(s, progress=False), weak)
    assert ds2.attrs["peak_amplitude_m"] < ds.attrs["peak_amplitude_m"]


def test_bad_input():
    b = epmc(jd.System.paper_damper(eta=0.0), (1e-6, 1e-4), harmonics=1, progress=False)
    with pytest.raises(ValueError, match="backbone must be"):
        single_mode_frc("not a backbone")
    with pytest.raises(ValueError, match="system.force must have a non-zero entry"):
        single_mode_frc(b, jd.System.paper_damper(eta=0.0, f1=0.0))
    with pytest.raises(ValueError, match="1 DOFs"):
        single_mode_frc(b, jd.System(np.eye(2), None, np.eye(2), force=[1.0, 0.0]))
    for bad in (0.0, 1.0, float("nan")):
        with pytest.raises(ValueError, match="peak_rtol"):
            single_mode_frc(b, peak_rtol=bad)

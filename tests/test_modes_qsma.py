"""QSMA (quasi-static modal analysis): the Masing closed forms of the single-DOF
damper, agreement with the EPMC where the mode shape holds, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
import reference_modes as ref
import tolerances as tol
from jointdyn.modes import ModeStatus, QSMAOptions, epmc, qsma

M_, K_, KT, FY = 10.0, 3.9e5, 3.0e5, 50.0
XS = FY / KT


def test_iwan_equals_the_masing_secant_and_loop_area():
    b = qsma(jd.System.paper_damper(eta=0.0, model="iwan"))
    assert b.status is ModeStatus.COMPLETE and b.method == "qsma"
    assert b.points == 4 * QSMAOptions().steps_per_decade + 1
    tb, _ = ref.iwan_backbone(KT, FY)
    for a, w, D, E in zip(b.amplitude_m, b.omega_rad_s, b.damping_ratio, b.contact_energy_J[:, 0]):
        w_ref, D_ref = ref.masing_qsma(M_, K_, tb, a)
        assert w == pytest.approx(w_ref, rel=1e-13)
        # exact below macroslip (a quadratic backbone); past its onset (a kink of the
        # curvature inside one step) within the step's O(h^3) error
        rtol = tol.TEST_QSMA_MASING_RTOL if a <= 2 * XS else 1e-6
        assert D == pytest.approx(D_ref, rel=rtol)
        assert E == pytest.approx(ref.iwan_energy(KT, FY, a), rel=rtol)


def test_jenkins_equals_the_masing_closed_form_away_from_the_kink():
    b = qsma(jd.System.paper_damper(eta=0.0, model="jenkins"))
    tb, _ = ref.jenkins_backbone(KT, FY)
    for a, w, D in zip(b.amplitude_m, b.omega_rad_s, b.damping_ratio):
        w_ref, D_ref = ref.masing_qsma(M_, K_, tb, a)
        assert w == pytest.approx(w_ref, rel=1e-13)
        if a < XS * (1 - 1e-12):
            assert abs(D) <= 1e-14  # stuck
        elif a > 1.05 * XS:  # the slip onset is a kink of the force inside one push step: O(h^2)
            assert D == pytest.approx(D_ref, rel=1e-3)
        else:  # at the onset itself D is of the order of that error
            assert abs(D - D_ref) <= 1e-4


def test_agrees_with_one_harmonic_epmc_at_small_amplitude_on_two_dofs():
    """Below macroslip both tend to the linear stuck mode with the same loop energy:
    the relative differences vanish with the amplitude (docs/modes.md)."""
    M = np.diag([10.0, 2.0])
    K = np.array([[5e5, -1e5], [-1e5, 1e5]])
    law = jd.make_law("iwan", kt=3e5, mu=0.5, n_ref=100.0)
    s = jd.System(M, None, K, contacts=(jd.Contact(law, dof=0, dof2=1),))
    q = qsma(s, (1e-8, 1e-5))
    e = epmc(s, (1e-8, 1e-5), harmonics=1, samples=1024, progress=False)
    la = np.log(e.amplitude_m)
    errs = []
    for i in (0, q.points // 3, 2 * q.points // 3, q.points - 1):
        A = q.amplitude_m[i]
        w = np.interp(np.log(A), la, e.omega_rad_s)
        D = math.exp(np.interp(np.log(A), la, np.log(e.damping_ratio)))
        errs.append((abs(q.omega_rad_s[i] / w - 1), abs(q.damping_ratio[i] / D - 1), A))
    assert errs[0][0] < 1e-12 and errs[0][1] < 1e-5
    assert all(ew < 1e-6 and ed < 2e-3 for ew, ed, _ in errs)
    assert errs[-1][1] > errs[0][1]


def test_viscous_part_and_energy_per_contact():
    zeta = 0.02
    s = jd.System.sdof(m=M_, k=K_, law=jd.make_law("iwan", kt=KT, mu=0.5, n_ref=100.0),
                       c=2 * zeta * math.sqrt((K_ + KT) * M_))
    b = qsma(s, (0.01 * XS, 100 * XS))
    np.testing.assert_allclose(b.damping_ratio, b.damping_ratio_contacts + b.damping_ratio_viscous, rtol=1e-14)
    np.testing.assert_allclose(b.damping_ratio_viscous, zeta * math.sqrt((K_ + KT) / M_) / b.omega_rad_s,
                               rtol=1e-12)
    # D_contacts = E / (2 pi alpha q), alpha q = (k a + Tb(a)) a for one DOF
    alpha_q = (K_ * b.amplitude_m + _backbone_force(b.amplitude_m)) * b.amplitude_m
    np.testing.assert_allclose(b.damping_ratio_contacts, b.contact_energy_J[:, 0] / (2 * np.pi * alpha_q),
                               rtol=1e-9)


def _backbone_force(a):
    tb, _ = ref.iwan_backbone(KT, FY)
    return np.array([tb(x) for x in a])


def test_two_contacts_add_their_energies_and_multi_dof_runs():
    M = np.diag([1.0, 1.0, 1.0])
    K = np.array([[2e5, -1e5, 0.0], [-1e5, 2e5, -1e5], [0.0, -1e5, 1e5]])
    law = jd.make_law("iwan", kt=5e4, mu=0.3, n_ref=100.0)
    s = jd.System(M, None, K, contacts=(jd.Contact(law, dof=0), jd.Contact(law, dof=2, dof2=1)))
    b = qsma(s, (1e-6, 1e-2), output_dof=2)
    assert b.status.ok and b.contact_energy_J.shape == (b.points, 2)
    assert np.all(b.contact_energy_J > 0)
    assert np.all(np.diff(b.omega_rad_s) < 0)  # softening as more of the interface slips


def test_refuses_what_it_cannot_do():
    law = jd.make_law("iwan", kt=KT, mu=0.5, n_ref=100.0)
    spring = jd.System(np.diag([10.0, 1.0]), None, np.diag([3.9e5, 1e5]),
                       contacts=(jd.Contact(law, normal=jd.NormalSpring(kn=3e5, preload=100.0, dof=1)),))
    with pytest.raises(ValueError, match="QSMA takes constant normal loads only"):
        qsma(spring)
    with pytest.raises(ValueError, match="prescribed at a forcing frequency"):
        qsma(jd.System.paper_damper(eta=0.5))
    with pytest.raises(ValueError, match="steps_per_decade must be an integer >= 1"):
        qsma(jd.System.paper_damper(eta=0.0), steps_per_decade=0)


@pytest.mark.parametrize("lo, hi", [(0.5, 1.0), (0.3, 1.7), (1e-2, 1e2), (0.999, 1.0)])
def test_backbone_spans_the_requested_range_exactly(lo, hi):
    """First point at min, last at max (any ratio, not only whole decades), geometric in between with at
    least steps_per_decade points per decade."""
    b = qsma(jd.System.paper_damper(eta=0.0), (lo * XS, hi * XS))
    assert b.status.ok
    assert b.amplitude_m[0] == pytest.approx(lo * XS, rel=1e-12)
    assert b.amplitude_m[-1] == pytest.approx(hi * XS, rel=1e-12)
    step = np.diff(np.log10(b.amplitude_m))
    np.testing.assert_allclose(step, step[0], rtol=1e-6)
    assert step[0] <= 1.0 / QSMAOptions().steps_per_decade * (1 + 1e-9)

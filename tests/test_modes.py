"""Nonlinear modes by the EPMC: oracles (describing function, limits, energy
balance, harmonics, finite differences, an established tool) and bad input.

The describing-function references are computed independently in
``reference_modes.py`` (plain Python, quadrature of the exact Masing loop);
the tmdsimpy numbers and their provenance are in ``reference_tmdsimpy.py``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import jointdyn as jd
import reference_modes as ref
import tolerances as tol
from jointdyn.modes import EPMCOptions, EPMCProblem, ModeStatus, backbone_dataset, epmc
from modes_support import solve_at
from reference_tmdsimpy import HARMONICS, SAMPLES, TMDSIMPY_JENKINS_EPMC

M_, K_, KT, FY = 10.0, 3.9e5, 3.0e5, 50.0
XS = FY / KT
W_STUCK = math.sqrt((K_ + KT) / M_)
W_SLIP = math.sqrt(K_ / M_)

BACKBONES = {"jenkins": ref.jenkins_backbone(KT, FY), "iwan": ref.iwan_backbone(KT, FY),
             "iwan-closed": ref.iwan_backbone(KT, FY)}
#: AFT samples of the one-harmonic checks (the loop's kinks make the
#: trapezoidal projection converge as 1/samples^2)
DF_SAMPLES = {"jenkins": 8192, "iwan": 4096, "iwan-closed": 4096}


def _damper(model="iwan", **kw):
    return jd.System.paper_damper(eta=0.0, model=model, **kw)


_at = solve_at  # (omega, xi, X) of the EPMC solution at exactly an amplitude


@pytest.mark.parametrize("model", ["jenkins", "iwan", "iwan-closed"])
def test_one_harmonic_equals_the_describing_function(model):
    b = epmc(_damper(model), (1e-2 * XS, 1e2 * XS), harmonics=1, samples=DF_SAMPLES[model], progress=False)
    assert b.status is ModeStatus.COMPLETE and b.points >= 50
    tb, kinks = BACKBONES[model]
    for a, w, D, E in zip(b.amplitude_m, b.omega_rad_s, b.damping_ratio, b.contact_energy_J[:, 0]):
        w_ref, D_ref, E_ref = ref.describing_function(M_, K_, tb, kinks, a)
        assert abs(w - w_ref) <= tol.TEST_MODES_DF_RTOL * w_ref
        # rounding floors: of the damping ratio, and of the energy (units of the elastic energy kt a^2)
        assert abs(D - D_ref) <= tol.TEST_MODES_DF_RTOL * D_ref + 1e-14
        assert abs(E - E_ref) <= tol.TEST_MODES_DF_RTOL * E_ref + 1e-14 * KT * a * a
        if model != "jenkins":  # the loop area of the uniform Iwan contact (docs/model.md section 2)
            assert E_ref == pytest.approx(ref.iwan_energy(KT, FY, a), rel=1e-10)


@pytest.mark.parametrize("model", ["jenkins", "iwan"])
def test_damping_ratio_equals_dissipation_per_cycle(model):
    b = epmc(_damper(model), progress=False)
    assert b.status.ok
    total = b.damping_ratio_contacts + b.damping_ratio_viscous
    slipping = b.damping_ratio > 1e-12
    assert slipping.sum() > 30
    assert np.all(np.abs(b.damping_ratio - total)[slipping] <= tol.TEST_MODES_ENERGY_RTOL * b.damping_ratio[slipping])
    # stuck (Jenkins below slip): no dissipation, no self-excitation
    assert np.all(np.abs(b.damping_ratio[~slipping]) <= 1e-12)


def test_energy_balance_with_viscous_damping_on_two_dofs():
    M = np.diag([10.0, 2.0])
    K = np.array([[5e5, -1e5], [-1e5, 1e5]])
    law = jd.make_law("iwan", kt=3e5, mu=0.5, n_ref=100.0)
    C = jd.modal_damping(M, K, 0.01)
    s = jd.System(M, C, K, contacts=(jd.Contact(law, dof=0, dof2=1),))
    b = epmc(s, (1e-5, 1e-2), harmonics=5, progress=False)
    assert b.status.ok
    total = b.damping_ratio_contacts + b.damping_ratio_viscous
    assert np.all(np.abs(b.damping_ratio - total) <= tol.TEST_MODES_ENERGY_RTOL * b.damping_ratio)
    assert np.all(b.damping_ratio_viscous > 0) and np.all(b.damping_ratio_contacts > 0)


def test_tiny_amplitude_is_the_linear_stuck_mode():
    for model in ("iwan", "jenkins"):
        b = epmc(_damper(model), (1e-7 * XS, 1e-6 * XS), progress=False)
        assert b.omega_rad_s[0] == pytest.approx(W_STUCK, rel=tol.TEST_MODES_LINEAR_RTOL)
        assert b.linear.omega_rad_s == pytest.approx(W_STUCK, rel=1e-14)
        assert abs(b.damping_ratio[0]) <= 1e-6
    # two DOFs, second mode: frequency and shape of (M, K + kt b b^T)
    M = np.diag([1.0, 3.0])
    K = np.array([[4e5, -2e5], [-2e5, 2e5]])
    law = jd.make_law("iwan", kt=1e5, mu=0.3, n_ref=200.0)
    s = jd.System(M, None, K, contacts=(jd.Contact(law, dof=1),))
    from scipy.linalg import eigh

    lam, phi = eigh(K + np.diag([0.0, 1e5]), M)
    b = epmc(s, (1e-9, 1e-8), mode=2, output_dof=0, harmonics=3, progress=False)
    assert b.omega_rad_s[0] == pytest.approx(math.sqrt(lam[1]), rel=tol.TEST_MODES_LINEAR_RTOL)
    shape = b.X[0].reshape(7, 2)[1] / b.amplitude_m[0]
    np.testing.assert_allclose(shape, phi[:, 1] / phi[0, 1], rtol=1e-5)


@pytest.mark.parametrize("model", ["jenkins", "iwan"])
def test_large_amplitude_tends_to_the_slipping_mode(model):
    """omega -> sqrt(k/m); D a -> 2 fy / (pi k) (E -> 4 fy a), the error falling like 1/a."""
    b = epmc(_damper(model), (10 * XS, 1e4 * XS), progress=False)
    assert b.status.ok
    errs, werrs = [], []
    for q in (1e2, 1e3, 1e4):
        w, xi, _ = _at(b, q * XS)
        D = xi / (2 * w)
        errs.append(abs(D * q * XS * math.pi * K_ / (2 * FY) - 1))
        werrs.append(abs(w / W_SLIP - 1))
    assert errs[1] < 0.2 * errs[0] and errs[2] < 0.2 * errs[1] and errs[2] < 1e-3
    assert werrs[1] < werrs[0] and werrs[2] < werrs[1] and werrs[2] < 1e-5


def test_several_harmonics_converge_and_agree_with_one_harmonic_when_mildly_nonlinear():
    for model, qs in (("iwan", (0.1, 0.3, 1.0, 2.0)), ("jenkins", (2.0, 3.0, 5.0))):
        s = _damper(model)
        for q in qs:
            res = {}
            for H in (1, 7, 9):
                b = epmc(s, (0.999 * q * XS, q * XS), harmonics=H, samples=512, progress=False)
                res[H] = (b.omega_rad_s[-1], b.damping_ratio[-1])
            for i in (0, 1):
                assert res[7][i] == pytest.approx(res[1][i], rel=tol.TEST_MODES_ONE_HARMONIC_RTOL)
                assert res[7][i] == pytest.approx(res[9][i], rel=tol.TEST_MODES_H_CONVERGED_RTOL)


@pytest.mark.parametrize("model", ["iwan", "jenkins"])
def test_jacobian_matches_central_differences(model):
    s = jd.System(np.diag([10.0, 1.0]), np.array([[3.0, -1.0], [-1.0, 1.0]]),
                  np.array([[4e5, -1e5], [-1e5, 1e5]]),
                  contacts=(jd.Contact(jd.make_law(model, kt=3e5, mu=0.5, n_ref=100.0), dof=0),))
    p = EPMCProblem(s, harmonics=3, samples=64)
    b = epmc(s, (0.5 * XS, 3 * XS), harmonics=3, samples=64, progress=False)
    i = b.points // 2
    lam = math.log10(b.amplitude_m[i])
    v = p.pack(b.X[i], b.omega_rad_s[i], b.xi_rad_s[i])
    v = v + 1e-3 * np.random.default_rng(1).standard_normal(v.size)  # off the solution
    v[p.i_omega] = b.omega_rad_s[i] / p.w_ref
    R, Jv, Jl = p.residual(v, lam)
    h = 1e-7
    fd = np.empty_like(Jv)
    for j in range(v.size):
        e = np.zeros(v.size)
        e[j] = h
        fd[:, j] = (p.residual(v + e, lam)[0] - p.residual(v - e, lam)[0]) / (2 * h)
    fl = (p.residual(v, lam + h)[0] - p.residual(v, lam - h)[0]) / (2 * h)
    scale = np.max(np.abs(Jv))
    assert np.max(np.abs(fd - Jv)) <= tol.TEST_HB_JACOBIAN_RTOL * scale
    assert np.max(np.abs(fl - Jl)) <= tol.TEST_HB_JACOBIAN_RTOL * max(np.max(np.abs(Jl)), scale)


def test_tmdsimpy_epmc_on_the_jenkins_damper():
    """Same discrete equations as tmdsimpy (H = 7, 4096 samples): equal to rounding;
    at the default discretisation within the issue's 0.1 % and 1 %."""
    amps = np.array([r[0] for r in TMDSIMPY_JENKINS_EPMC])
    s = _damper("jenkins")
    for samples, rw, rd in ((SAMPLES, tol.TEST_MODES_TMDSIMPY_SAME_RTOL, tol.TEST_MODES_TMDSIMPY_SAME_RTOL),
                            (jd.config.HB_SAMPLES, tol.TEST_MODES_TMDSIMPY_OMEGA_RTOL,
                             tol.TEST_MODES_TMDSIMPY_DAMPING_RTOL)):
        b = epmc(s, (0.99 * amps[0], 1.01 * amps[-1]), harmonics=HARMONICS, samples=samples, progress=False)
        assert b.status.ok
        for a, w_ref, D_ref in TMDSIMPY_JENKINS_EPMC:
            w, xi, _ = _at(b, a)
            assert w == pytest.approx(w_ref, rel=rw)
            if D_ref > 1e-12:
                assert xi / (2 * w) == pytest.approx(D_ref, rel=rd)
            else:  # stuck: no damping
                assert abs(xi / (2 * w)) <= 1e-12


def test_viscous_part_follows_the_modal_convention():
    """SDOF with c = 2 zeta sqrt((k + kt) m): D_viscous = zeta omega_stuck / omega at every amplitude."""
    zeta = 0.01
    s = jd.System.sdof(m=M_, k=K_, law=jd.make_law("jenkins", kt=KT, mu=0.5, n_ref=100.0),
                       c=2 * zeta * math.sqrt((K_ + KT) * M_))
    b = epmc(s, (0.1 * XS, 100 * XS), harmonics=5, progress=False)
    np.testing.assert_allclose(b.damping_ratio_viscous, zeta * W_STUCK / b.omega_rad_s, rtol=1e-9)
    stuck = b.amplitude_m < 0.99 * XS
    np.testing.assert_allclose(b.damping_ratio[stuck], zeta, rtol=1e-9)
    np.testing.assert_allclose(b.omega_rad_s[stuck], W_STUCK, rtol=1e-12)


def test_dataset_and_frozen_result():
    b = epmc(_damper(), (0.1 * XS, 10 * XS), harmonics=3, progress=False)
    ds = backbone_dataset(b)
    assert ds.attrs["status"] == "complete" and ds.attrs["method"] == "epmc" and ds.attrs["linear_mode"] == 1
    for v in ("amplitude_m", "amplitude_q", "omega_rad_s", "frequency_hz", "gamma", "damping_ratio",
              "damping_ratio_contacts", "damping_ratio_viscous", "xi_rad_s", "contact_energy_J", "mode_shape_m",
              "harmonic_amplitude_m"):
        assert v in ds
    np.testing.assert_allclose(ds.amplitude_q, ds.amplitude_m / XS, rtol=1e-12)
    np.testing.assert_allclose(ds.harmonic_amplitude_m[:, 1, 0], ds.amplitude_m, rtol=1e-12)
    np.testing.assert_allclose(ds.mode_shape_m[:, 2, 0], 0.0, atol=1e-20)  # the phase normalisation
    # arc-length steps bound the spacing in decades of amplitude
    assert 0 < np.diff(np.log10(ds.amplitude_m)).max() <= EPMCOptions().ds_max * (1 + 1e-12)
    with pytest.raises(dataclasses.FrozenInstanceError):
        b.status = ModeStatus.FAILED


def test_max_points_keeps_the_points():
    b = epmc(_damper(), max_points=5, progress=False)
    assert b.status is ModeStatus.MAX_POINTS and b.points == 5 and not b.status.ok


@pytest.mark.parametrize("make, word", [
    (lambda: jd.System.paper_damper(eta=0.5), "contact 0: its normal load is a harmonic load with n1 = 50 N"),
    (lambda: dataclasses.replace(_damper(), contacts=(jd.Contact(jd.make_law("iwan", kt=KT, mu=0.5, n_ref=100.0),
                                                                  normal=jd.SampledLoad([90.0, 110.0])),)),
     "contact 0: its normal load is a SampledLoad, prescribed at a forcing frequency"),
    (lambda: jd.System(np.eye(2), None, np.zeros((2, 2)),
                       contacts=(jd.Contact(jd.make_law("iwan", kt=KT, mu=0.5, n_ref=100.0)),)),
     "K must be positive definite with every contact stuck"),
    (lambda: jd.System(np.eye(1), None, np.eye(1)), "system must have at least one contact"),
])
def test_bad_systems_are_refused_with_the_reason(make, word):
    with pytest.raises(ValueError, match=word.replace("(", r"\(").replace(")", r"\)")):
        epmc(make(), progress=False)


def test_normal_spring_goes_to_harmonic_balance_and_qsma_refuses_it():
    # the normal DOF does not move in the tangential mode: the spring keeps N at its
    # preload, and the backbone is that of the same system at constant load
    from jointdyn.modes import backbone_dataset, qsma

    law = jd.make_law("iwan", kt=KT, mu=0.5, n_ref=100.0)
    M, K = np.diag([10.0, 1.0]), np.diag([3.9e5, 1e5])
    spring = jd.System(M, None, K, contacts=(jd.Contact(law, dof=0,
                                                        normal=jd.NormalSpring(kn=3e5, preload=100.0, dof=1)),))
    const = jd.System(M, None, K + np.diag([0.0, 3e5]),
                      contacts=(jd.Contact(law, dof=0, normal=jd.ConstantLoad(100.0)),))
    amps = (1e-2 * 50.0 / KT, 1e2 * 50.0 / KT)
    a, b = (backbone_dataset(epmc(s, amps, progress=False)) for s in (spring, const))
    assert a.attrs["status"] == b.attrs["status"] == "complete"
    for name in ("amplitude_m", "omega_rad_s", "damping_ratio"):  # the same continuation, to rounding
        np.testing.assert_allclose(a[name].values, b[name].values, rtol=1e-9)
    with pytest.raises(ValueError, match="contact 0: QSMA takes constant normal loads only"):
        qsma(spring)


@pytest.mark.parametrize("kwargs, word", [
    (dict(amplitude=(1e-3, 1e-4)), "amplitude max must be > min"),
    (dict(amplitude=(0.0, 1e-4)), "amplitude min must be > 0"),
    (dict(amplitude=1e-3), "amplitude must be a pair"),
    (dict(mode=2), r"mode must be in \[1, 1\]"),
    (dict(mode=0), "mode must be an integer >= 1"),
    (dict(output_dof=1), r"output_dof must be in \[0, 0\]"),
    (dict(harmonics=0), "harmonics must be an integer >= 1"),
    (dict(samples=15), "samples must be an integer >= 16"),
])
def test_bad_arguments_name_the_parameter(kwargs, word):
    with pytest.raises(ValueError, match=word):
        epmc(_damper(), progress=False, **kwargs)


def test_output_dof_that_does_not_move_is_refused():
    M = np.eye(2)
    K = np.diag([1e5, 2e5])  # uncoupled: mode 1 moves DOF 0 only
    law = jd.make_law("iwan", kt=1e4, mu=0.5, n_ref=100.0)
    s = jd.System(M, None, K, contacts=(jd.Contact(law, dof=0),))
    with pytest.raises(ValueError, match="output_dof: DOF 1 does not move in linear stuck mode 1"):
        epmc(s, mode=1, output_dof=1, progress=False)


@pytest.mark.parametrize("model", ["jenkins", "iwan"])
def test_a_contact_split_in_two_halves_gives_the_same_mode_and_half_the_energy_each(model):
    """Two contacts with kt/2 and N0/2 on the same DOF are one contact with kt and N0 (same slip
    displacement, half the force each): same backbone, and each dissipates half the energy per cycle."""
    def system(n):
        law = jd.make_law(model, kt=KT / n, mu=0.5, n_ref=100.0 / n)
        return jd.System(np.array([[M_]]), None, np.array([[K_]]), contacts=(jd.Contact(law),) * n)

    from jointdyn.modes import qsma

    one, two = (epmc(system(n), (0.1 * XS, 10 * XS), harmonics=3, progress=False) for n in (1, 2))
    assert one.status.ok and two.status.ok and two.contact_energy_J.shape == (two.points, 2)
    for q in (0.5, 1.5, 5.0):
        w1, xi1, X1 = _at(one, q * XS)
        w2, xi2, X2 = _at(two, q * XS)
        assert w2 == pytest.approx(w1, rel=1e-10) and xi2 == pytest.approx(xi1, rel=1e-8, abs=1e-12)
        E1 = one.problem.energies(X1, w1, one.problem.evaluate(X1, w1))[2]
        E2 = two.problem.energies(X2, w2, two.problem.evaluate(X2, w2))[2]
        np.testing.assert_allclose(E2, [0.5 * E1[0]] * 2, rtol=1e-8, atol=1e-14 * KT * XS * XS)
    np.testing.assert_allclose(two.contact_energy_J[:, 0], two.contact_energy_J[:, 1], rtol=1e-12)
    q1, q2 = qsma(system(1), (0.1 * XS, 10 * XS)), qsma(system(2), (0.1 * XS, 10 * XS))
    np.testing.assert_allclose(q2.omega_rad_s, q1.omega_rad_s, rtol=1e-12)
    np.testing.assert_allclose(q2.contact_energy_J, 0.5 * q1.contact_energy_J.repeat(2, axis=1), rtol=1e-9,
                               atol=1e-15 * KT * XS * XS)

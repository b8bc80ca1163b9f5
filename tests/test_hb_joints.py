"""Harmonic balance of general structures: per-DOF forcing phases against the
exact linear FRF (stuck and slipping limits), a Jenkins contact whose normal
load varies in phase with the motion against the quadrature of its exact
loop (Yang, Chu & Menq), and the exact condensation onto the contact DOFs
against the uncondensed problem."""

import math

import numpy as np
import pytest
import tolerances

from jointdyn import System, config, modal_damping
from jointdyn.hb import continue_hb, frc_hb, harmonic_balance
from jointdyn.hb.condense import (
    CondensedHBProblem,
    make_problem,
    receptance,
    retained_dofs,
    use_condensed,
)
from jointdyn.hb.floquet import point_stability
from jointdyn.hb.problem import HBProblem
from jointdyn.kinematics import HarmonicLoad
from jointdyn.laws import Iwan, Jenkins
from jointdyn.systems import Contact

KT = 3e5


def _chain(n, *, mu=0.5, law_class=Jenkins, damping="rayleigh", phases=True, lumped=True):
    """n masses in a chain (ends to ground), two contacts (damping ``rayleigh``, ``modal``
    ratios or ``local`` at DOF 0; ``lumped`` or coupled mass matrix):
    DOF 1 to ground and DOF n-2 against DOF n-1; forcing on DOF 0 and n // 2."""
    k = 2e5 * np.linspace(1.0, 1.6, n + 1)
    K = np.zeros((n, n))
    for i in range(n + 1):
        a, b = i - 1, i
        if a >= 0:
            K[a, a] += k[i]
        if b < n:
            K[b, b] += k[i]
        if a >= 0 and b < n:
            K[a, b] = K[b, a] = -k[i]
    M = np.diag(np.linspace(1.0, 2.0, n))
    if not lumped:  # a consistent-mass-like coupling
        M += 0.1 * (np.eye(n, k=1) + np.eye(n, k=-1))
    C = 1e-5 * K + 0.5 * M
    if damping == "modal":  # diagonal in the modes, not a combination of M and K
        C = modal_damping(M, K, np.linspace(0.01, 0.05, n))
    elif damping == "local":  # a local damper: not diagonal in the modes
        C[0, 0] += 30.0
    law = law_class(kt=KT, mu=mu, n_ref=100.0)
    contacts = (Contact(law=law, dof=1, normal=HarmonicLoad(100.0, 30.0, 20.0)),
                Contact(law=law, dof=n - 2, dof2=n - 1, normal=HarmonicLoad(80.0, 0.0, 0.0)))
    f = np.zeros(n)
    f[0], f[n // 2] = 40.0, 25.0
    ph = np.zeros(n)
    if phases:
        ph[0], ph[n // 2] = -30.0, 70.0
    return System(M=M, C=C, K=K, contacts=contacts, force=f, force_phase_deg=ph)


def _linear_coefficients(s, w, K):
    """(a, b) per DOF of the exact steady state of M x'' + C x' + K x = f sin(w t + phi): x = a cos + b sin."""
    F = s.force * np.exp(1j * np.radians(s.force_phase_deg))
    Xc = np.linalg.solve(K - w * w * s.M + 1j * w * s.C, F)
    return Xc.imag, Xc.real


@pytest.mark.parametrize("condense", [False, True])
@pytest.mark.parametrize("limit", ["stuck", "slipping"])
def test_forcing_phases_give_the_exact_linear_frf_in_the_limits(limit, condense):
    # stuck: slip force far above the contact forces, the contacts are springs kt;
    # slipping: slip force ~1e-10 N, the contacts carry nothing
    s = _chain(6, mu=1e7 if limit == "stuck" else 1e-12)
    K = s.K.copy()
    if limit == "stuck":
        for c in s.contacts:
            b = np.zeros(s.ndof)
            b[c.dof] = 1.0
            if c.dof2 >= 0:
                b[c.dof2] = -1.0
            K += KT * np.outer(b, b)
    for g in (0.7, 1.0, 1.6):
        sol = harmonic_balance(s, g, harmonics=3, samples=64, condense=condense)
        assert sol.status.ok
        a, b = _linear_coefficients(s, g * s.w0, K)
        Xm = sol.problem.full_coefficients(sol.X, sol.problem.f1_ref).reshape(7, s.ndof)
        scale = np.max(np.abs(np.r_[a, b]))
        assert np.max(np.abs(Xm[1] - a)) <= tolerances.TEST_HB_LINEAR_LIMIT_RTOL * scale
        assert np.max(np.abs(Xm[2] - b)) <= tolerances.TEST_HB_LINEAR_LIMIT_RTOL * scale
        assert np.max(np.abs(Xm[[0, 3, 4, 5, 6]])) <= tolerances.TEST_HB_LINEAR_LIMIT_RTOL * scale
        amp = math.hypot(a[0], b[0])
        assert abs(sol.amplitude_m - amp) <= tolerances.TEST_HB_LINEAR_LIMIT_RTOL * amp


def test_phase_shift_of_every_force_shifts_the_response_in_time():
    # shifting every phase (forces and normal loads) by the same angle shifts the periodic
    # response by it in time; 45 degrees is 16 of the 128 AFT samples, so the sampled
    # loops are the same
    s = _chain(4, law_class=Iwan)
    s2 = System(M=s.M, C=s.C, K=s.K, contacts=tuple(
        Contact(law=c.law, dof=c.dof, dof2=c.dof2,
                normal=HarmonicLoad(c.normal.n0, c.normal.n1, c.normal.phase_deg + 45.0)) for c in s.contacts),
        force=s.force, force_phase_deg=s.force_phase_deg + 45.0)
    a = harmonic_balance(s, 1.1, harmonics=5, samples=128)
    b = harmonic_balance(s2, 1.1, harmonics=5, samples=128)
    assert a.status.ok and b.status.ok
    assert abs(a.amplitude_m - b.amplitude_m) <= 1e-9 * a.amplitude_m
    assert abs(a.offset_m - b.offset_m) <= 1e-9 * a.amplitude_m


@pytest.mark.parametrize("damping,lumped,law_class", [
    ("rayleigh", True, Jenkins), ("rayleigh", True, Iwan), ("rayleigh", False, Iwan),
    ("modal", True, Iwan), ("local", True, Jenkins), ("local", False, Iwan)])
def test_condensed_equals_uncondensed(damping, lumped, law_class):
    s = _chain(9, law_class=law_class, damping=damping, lumped=lumped)
    rec = receptance(s)
    assert rec.kind == ("state-space" if damping == "local" else "modal")
    assert (rec.basis is not None) == (damping == "rayleigh")  # factored modes: Rayleigh damping only
    for g in (0.8, 1.05, 1.4):
        full = harmonic_balance(s, g, harmonics=5, samples=128, condense=False)
        cond = harmonic_balance(s, g, harmonics=5, samples=128, condense=True)
        assert full.status.ok and cond.status.ok
        p = cond.problem
        # DOF 0, the contact's DOF 1 and the two-sided contact's x_7 - x_8 (one relative coordinate)
        assert isinstance(p, CondensedHBProblem) and p.dofs.tolist() == [0, 1, -1]
        Xf = full.X.reshape(p.nh, s.ndof)
        scale = np.max(np.abs(full.X))
        Y = (Xf @ p.coordinates.S.T).ravel()  # the coordinates y = S x of the full solution
        assert np.max(np.abs(Y - cond.X)) <= tolerances.TEST_HB_CONDENSED_RTOL * scale
        rec_all = p.full_coefficients(cond.X, p.f1_ref)
        assert np.max(np.abs(rec_all - full.X)) <= tolerances.TEST_HB_CONDENSED_RTOL * scale
        assert abs(full.amplitude_m - cond.amplitude_m) <= tolerances.TEST_HB_CONDENSED_RTOL * full.amplitude_m
        # the recovered response of a DOF that is not retained
        d = 4
        assert abs(cond.problem.amplitudes(cond.X, d, p.f1_ref)[0] - full.problem.amplitudes(full.X, d)[0]) \
            <= tolerances.TEST_HB_CONDENSED_RTOL * scale
        # Hill stability on the assembled full Jacobian
        assert cond.stable == full.stable
        assert abs(cond.growth - full.growth) <= 1e-7


@pytest.mark.parametrize("par", ["gamma", "f1", "eta", "delta", "n0"])
def test_condensed_jacobian_matches_central_differences(par):
    s = _chain(7, law_class=Iwan, damping="local")
    g = 1.1
    p = CondensedHBProblem(s, harmonics=3, samples=128, parameter=par, gamma=None if par == "gamma" else g)
    lam = {"gamma": g, "f1": p.f1_ref, "eta": 0.3, "delta": math.radians(20.0), "n0": 100.0}[par]
    X = harmonic_balance(s, g, harmonics=3, samples=128, condense=True).X
    ev = p.evaluate(X, lam)
    Ja = np.c_[ev.JX, ev.Jp]
    Jfd = np.empty_like(Ja)
    for j in range(X.size + 1):
        Xp, Xm, lp, lm = X.copy(), X.copy(), lam, lam
        if j < X.size:
            h = 1e-6 * np.abs(X).max()
            Xp[j] += h
            Xm[j] -= h
        else:
            h = 1e-6 * abs(lam)
            lp, lm = lam + h, lam - h
        Jfd[:, j] = (p.evaluate(Xp, lp).R - p.evaluate(Xm, lm).R) / (2 * h)
    assert np.max(np.abs(Ja - Jfd)) <= tolerances.TEST_HB_JACOBIAN_RTOL * np.max(np.abs(Ja))


def test_condensed_continuation_in_a_system_parameter():
    # a SystemParameter rebuilds (and condenses) the system at each value: the branch in mu
    # at a fixed frequency equals fixed-mu solutions of the uncondensed problem
    from jointdyn.hb.parameters import SystemParameter

    def build(mu):
        return _chain(7, law_class=Jenkins, mu=mu)

    par = SystemParameter("mu", build, lower=1e-3)
    br = continue_hb(build(0.5), 0.5, 0.8, parameter=par, gamma=1.1, harmonics=3, samples=64, condense=True,
                     progress=False)
    assert br.status == "complete" and br.problem.condensed
    for i in (0, br.lam.size // 2, br.lam.size - 1):
        full = harmonic_balance(build(br.lam[i]), 1.1, harmonics=3, samples=64, condense=False)
        Xf = (full.X.reshape(br.problem.nh, 7) @ br.problem.coordinates.S.T).ravel()  # y = S x
        assert np.max(np.abs(Xf - br.X[i])) <= 1e-7 * np.max(np.abs(Xf))


def test_condensed_branch_solves_the_uncondensed_equations():
    # every point of a condensed branch, recovered on all DOFs, solves the full
    # problem (to the continuation's tolerance) with the full problem's stability
    s = _chain(9, law_class=Iwan)
    br = continue_hb(s, 0.7, 1.5, harmonics=5, samples=128, condense=True, progress=False)
    assert br.status == "complete" and br.problem.condensed
    full = HBProblem(s, harmonics=5, samples=128)
    fs = max(full.f1_ref, max(c.law.mu * c.law.n_ref for c in s.contacts))
    picks = np.unique(np.r_[np.arange(0, br.lam.size, 15), br.lam.size - 1])
    for i in picks:
        X = br.problem.full_coefficients(br.X[i], br.lam[i])
        ev = full.evaluate(X, br.lam[i])
        assert np.max(np.abs(ev.R)) <= 10 * config.CONT_TOL * fs
        stable, growth, _ = point_stability(full, ev.JX, full.omega(br.lam[i]))
        assert stable == br.stable[i] and abs(growth - br.growth[i]) <= 1e-7
    ds = frc_hb(s, 0.7, 0.8, harmonics=5, samples=128, condense=True, response_dof=4, progress=False)
    assert ds.attrs["condensed"] == 1 and ds.attrs["stability"] == "hill"


def test_automatic_choice_and_bad_input():
    small, large = _chain(4), _chain(30)
    assert not use_condensed(small) and use_condensed(large)
    assert isinstance(make_problem(large), CondensedHBProblem)
    assert type(make_problem(small)) is HBProblem
    assert retained_dofs(large).tolist() == [0, 1, 28, 29]
    assert retained_dofs(large, (7,)).tolist() == [0, 1, 7, 28, 29]
    with pytest.raises(ValueError, match="condense"):
        harmonic_balance(small, 1.0, condense="yes")
    with pytest.raises(ValueError, match="response_dof"):
        retained_dofs(large, (30,))
    p = CondensedHBProblem(large, harmonics=2, samples=32)
    X = np.zeros(p.size)
    with pytest.raises(ValueError, match="parameter value"):
        p.dof_coefficients(X, 10)
    with pytest.raises(ValueError, match="w must be given"):
        p.forcing(large.force)
    br = continue_hb(large, 0.9, 1.0, harmonics=2, samples=32, condense=True, max_points=5)
    assert br.problem.condensed


@pytest.mark.parametrize("damping,lumped", [("rayleigh", True), ("rayleigh", False), ("modal", True),
                                            ("local", False)])
def test_receptance_equals_a_direct_solve(damping, lumped):
    s = _chain(11, damping=damping, lumped=lumped)
    rec = receptance(s)
    cols = [0, 3, 10]
    for W in (37.0, 0.9 * s.w0, 5.0 * s.w0):
        direct = np.linalg.solve(s.K - W * W * s.M + 1j * W * s.C, np.eye(s.ndof)[:, cols])
        H = rec.block(W, np.arange(s.ndof), cols)
        assert np.max(np.abs(H - direct)) <= 1e-11 * np.max(np.abs(direct))
    F = np.linspace(-1.0, 2.0, s.ndof) + 1j * np.linspace(0.5, 0.0, s.ndof)
    assert np.allclose(rec.project(F), rec.rows(np.arange(s.ndof)).T @ F, rtol=0, atol=1e-12 * np.abs(F).max())


def test_a_wrong_expansion_is_refused(monkeypatch):
    import jointdyn.hb.condense as cd

    def unnormalised(w2, Ct):
        lam, Y = real_state_space(w2, Ct)
        return lam, 2.0 * Y

    real_state_space = cd._state_space
    monkeypatch.setattr(cd, "_state_space", unnormalised)
    with pytest.raises(ValueError, match="condense"):
        cd.receptance(_chain(5, damping="local"))


def _jenkins_loop(kt, mu, n0, n1, A):
    """The steady loop of a Jenkins element (stiffness kt, slip force mu N) under
    u = A sin(tau), N = n0 + n1 sin(tau) (normal load in phase with the motion;
    Yang, Chu & Menq, JSV 210 (1998) 461), as pieces (start, end, T(tau)) over
    [pi/2, 5 pi/2): at the reversals tau = pi/2, 3 pi/2 the element sticks; it
    slips again where the stuck force reaches -+mu N, and slips until the next
    reversal (while slipping, d(kt u)/dtau and d(mu N)/dtau keep the same sign
    when kt A > mu n1)."""
    ka, mn1 = kt * A, mu * n1
    s1 = (ka - mn1 - 2.0 * mu * n0) / (ka + mn1)  # stuck force reaches -mu N in (pi/2, 3 pi/2)
    s2 = (2.0 * mu * n0 - mn1 - ka) / (ka - mn1)  # and +mu N in (3 pi/2, 5 pi/2)
    assert ka > mn1 and abs(s1) < 1.0 and abs(s2) < 1.0
    t1, t2 = math.pi - math.asin(s1), 2.0 * math.pi + math.asin(s2)
    top, bottom = mu * (n0 + n1), -mu * (n0 - n1)
    return [(0.5 * math.pi, t1, lambda t: top + ka * (math.sin(t) - 1.0)),
            (t1, 1.5 * math.pi, lambda t: -mu * (n0 + n1 * math.sin(t))),
            (1.5 * math.pi, t2, lambda t: bottom + ka * (math.sin(t) + 1.0)),
            (t2, 2.5 * math.pi, lambda t: mu * (n0 + n1 * math.sin(t)))]


def _first_harmonic(pieces):
    """(mean, cos, sin) Fourier coefficients of the piecewise loop by adaptive quadrature."""
    from scipy.integrate import quad

    def integral(weight):
        return sum(quad(lambda t, f=f: f(t) * weight(t), a, b, epsabs=0.0, epsrel=1e-12)[0] for a, b, f in pieces)

    return np.array([integral(lambda t: 1.0) / (2.0 * math.pi), integral(math.cos) / math.pi,
                     integral(math.sin) / math.pi])


@pytest.mark.parametrize("A", [3e-4, 1e-3])
def test_one_harmonic_jenkins_with_in_phase_normal_load_matches_the_exact_loop(A):
    # the forcing (amplitude and phase) that makes u = X0 + A sin(tau) the one-harmonic
    # solution by the quadrature's coefficients; harmonic balance must return that motion.
    # 4096 samples: the AFT's sampled loop converges as Ns^-2 (measured 6e-8 and 1.3e-7 relative)
    kt, mu, n0, n1, m, k, g = 3e5, 0.5, 100.0, 40.0, 10.0, 3.9e5, 1.2
    c = 2e-3 * math.sqrt(k * m)
    ref = _first_harmonic(_jenkins_loop(kt, mu, n0, n1, A))
    w = g * math.sqrt(k / m)
    fa, fb = c * w * A + ref[1], (k - m * w * w) * A + ref[2]
    law = Jenkins(kt=kt, mu=mu, n_ref=n0)
    s = System(M=[[m]], C=[[c]], K=[[k]], force=[math.hypot(fa, fb)], force_phase_deg=[math.degrees(math.atan2(fa, fb))],
               contacts=(Contact(law=law, dof=0, normal=HarmonicLoad(n0, n1, 0.0)),))
    sol = harmonic_balance(s, g, harmonics=1, samples=4096)
    assert sol.status.ok
    expected = np.array([-ref[0] / k, 0.0, A])
    assert np.max(np.abs(sol.X - expected)) <= tolerances.TEST_HB_YCM_RTOL * A


@pytest.mark.parametrize("damping", ["rayleigh", "local"])
def test_static_condensation_by_modes_equals_cholesky(damping):
    from jointdyn.hb.condense import _static_cholesky, _static_parts

    s = _chain(10, damping=damping)
    c = retained_dofs(s)
    Z0m, S0m = _static_parts(s.K, c, receptance(s))
    Z0c, S0c = _static_cholesky(s.K, c)
    assert np.max(np.abs(Z0m - Z0c)) <= 1e-9 * np.max(np.abs(Z0c))
    rows = np.arange(s.ndof)
    assert np.max(np.abs(S0m(rows) - S0c(rows))) <= 1e-9
    # a structure held only through the retained DOFs (K singular): the Cholesky route
    free = s.K.copy()
    free[0, 0] -= 2e5 * 1.0  # DOF 0 loses its spring to ground
    free[-1, -1] -= 2e5 * 1.6
    assert np.linalg.eigvalsh(free)[0] < 1e-8 * np.max(np.abs(free))
    Z0, S0 = _static_parts(free, c, None)
    x = S0(rows) @ np.array([1.0, 0.0, 0.0, -1.0])
    f = free @ x
    assert np.max(np.abs(np.delete(f, c))) <= 1e-9 * np.max(np.abs(f))  # no load on the other DOFs
    assert np.allclose(f[c], Z0 @ np.array([1.0, 0.0, 0.0, -1.0]), rtol=1e-9, atol=1e-9 * np.max(np.abs(f)))

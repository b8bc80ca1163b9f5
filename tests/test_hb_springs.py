"""Harmonic balance with the normal load from the structure (issue 10), mixed
laws and selection vectors.

Oracles: central differences of the residual (exact Jacobian, through
separation too), the time integrator's steady state with and without
separation, the exact linear FRF of the fully stuck and fully slipping limits
(contact closed: springs kt and kn), the uncondensed problem for the
condensed one, each subsystem alone for decoupled contacts with different
laws, and DOF pairs for the same selections written as vectors.
"""

import numpy as np
import pytest
import tolerances as C

import jointdyn as jd
from jointdyn.hb import frc_hb, harmonic_balance
from jointdyn.hb.condense import CondensedHBProblem, retained_dofs
from jointdyn.hb.problem import HBProblem
from jointdyn.laws import make_law

KT, KN, P = 3e5, 3e5, 100.0


def _damper(fn, law_name="jenkins", *, mu=0.5, direction=False):
    """Tangential DOF 0 (10 kg, 3e5 N/m) on a contact whose normal spring sits on DOF 1
    (1 kg, 1e5 N/m of its own), normal force fn sin(w t + 60 deg); 2 % modal damping.
    With fn = 100 N the contact stays closed, with fn = 200 N it opens about 40 % of
    the period. ``direction``: the same selections written as vectors."""
    M = np.diag([10.0, 1.0])
    K = np.diag([3e5, 1e5])
    law = make_law(law_name, kt=KT, mu=mu, n_ref=P)
    if direction:
        spring = jd.NormalSpring(kn=KN, preload=P, direction=[0.0, 1.0])
        contact = jd.Contact(law, direction=[1.0, 0.0], normal=spring)
    else:
        contact = jd.Contact(law, dof=0, normal=jd.NormalSpring(kn=KN, preload=P, dof=1))
    Cm = jd.modal_damping(M, K + np.diag([0.0, KN]), 0.02)
    return jd.System(M, Cm, K, contacts=(contact,), force=[25.0, fn], force_phase_deg=[0.0, 60.0])


def _chain(n, law, *, mu=0.5):
    """n masses in a chain, tangential contact between DOFs 1 and 2 whose normal spring
    acts between DOF n-1 and ground; forcing with phases on DOFs 0 and n-1."""
    k = 2e5 * np.linspace(1.0, 1.6, n + 1)
    K = np.diag(k[:-1] + k[1:]) - np.diag(k[1:-1], 1) - np.diag(k[1:-1], -1)
    M = np.diag(np.linspace(1.0, 2.0, n))
    spring = jd.NormalSpring(kn=KN, preload=P, dof=n - 1)
    contact = jd.Contact(make_law(law, kt=KT, mu=mu, n_ref=P), dof=1, dof2=2, normal=spring)
    f = np.zeros(n)
    f[0], f[n - 1] = 30.0, 40.0
    ph = np.zeros(n)
    ph[n - 1] = 45.0
    return jd.System(M, 1e-5 * K + 0.5 * M, K, contacts=(contact,), force=f, force_phase_deg=ph)


def _central_jacobian(p, X, lam):
    """dR/dX and dR/dp by central differences."""
    J = np.empty((X.size, X.size + 1))
    for j in range(X.size + 1):
        Xp, Xm, lp, lm = X.copy(), X.copy(), lam, lam
        if j < X.size:
            h = 1e-7 * np.abs(X).max()
            Xp[j] += h
            Xm[j] -= h
        else:
            h = 1e-7 * lam
            lp, lm = lam + h, lam - h
        J[:, j] = (p.evaluate(Xp, lp).R - p.evaluate(Xm, lm).R) / (2 * h)
    return J


@pytest.mark.parametrize("fn", [100.0, 200.0])
@pytest.mark.parametrize("law_name", ["jenkins", "iwan", "discrete"])
def test_jacobian_matches_central_differences(law_name, fn):
    s = _damper(fn, law_name)
    sol = harmonic_balance(s, 1.1, harmonics=3, samples=128)
    assert sol.status.ok
    p = HBProblem(s, harmonics=3, samples=128)
    ev = p.evaluate(sol.X, 1.1)
    # closed throughout (fn = 100 N) or open over part of the period (fn = 200 N)
    assert (np.min(ev.N) > 0.0) == (fn == 100.0)
    Ja = np.c_[ev.JX, ev.Jp]
    # the spring enters dR/dX through the normal DOF (column of DOF 1, harmonic 0)
    assert Ja[1, 1] != s.K[1, 1]
    assert np.max(np.abs(Ja - _central_jacobian(p, sol.X, 1.1))) <= C.TEST_HB_JACOBIAN_RTOL * np.max(np.abs(Ja))


@pytest.mark.parametrize("fn, gammas, H, Ns", [
    (100.0, (0.8, 1.0, 1.3), 7, 256),
    # with separation the normal force has kinks: more harmonics
    (200.0, (0.8, 1.0, 1.3), 15, 512),
])
def test_harmonic_balance_equals_the_time_integrator(fn, gammas, H, Ns):
    s = _damper(fn)
    for g in gammas:
        hb = harmonic_balance(s, g, harmonics=H, samples=Ns)
        td = jd.steady_state(s, g)
        assert hb.status.ok and td.status == "periodic" and td.period_multiple == 1
        N = hb.problem.evaluate(hb.X, g).N
        assert (np.min(N) == 0.0) == (fn == 200.0)  # separation where expected
        # the mean normal load balances the preload (DOF 1 holds no static load)
        assert abs(hb.amplitude_m - td.amplitude_m) <= C.TEST_HB_SPRING_VS_TIME_RTOL * td.amplitude_m
        assert hb.stable


@pytest.mark.parametrize("condense", [False, True])
@pytest.mark.parametrize("limit", ["stuck", "slipping"])
def test_stuck_and_slipping_limits_equal_the_linear_frf(limit, condense):
    # mu huge: the contact is the spring kt; mu tiny: it carries nothing; the
    # normal spring stays closed (stiffness kn) in both
    s = _chain(6, "iwan", mu=1e7 if limit == "stuck" else 1e-12)
    n = s.ndof
    Klin = s.K.copy()
    Klin[n - 1, n - 1] += KN
    if limit == "stuck":
        b = np.zeros(n)
        b[1], b[2] = 1.0, -1.0
        Klin += KT * np.outer(b, b)
    for g in (0.7, 1.3, 1.6):  # away from resonances, where the spring would open
        sol = harmonic_balance(s, g, harmonics=3, samples=64, condense=condense)
        assert sol.status.ok
        w = g * s.w0
        F = s.force * np.exp(1j * np.radians(s.force_phase_deg))
        Xc = np.linalg.solve(Klin - w * w * s.M + 1j * w * s.C, F)
        Xm = sol.problem.full_coefficients(sol.X, sol.problem.f1_ref).reshape(7, n)
        scale = np.max(np.abs(Xc))
        assert np.max(np.abs(Xm[1] - Xc.imag)) <= C.TEST_HB_LINEAR_LIMIT_RTOL * scale
        assert np.max(np.abs(Xm[2] - Xc.real)) <= C.TEST_HB_LINEAR_LIMIT_RTOL * scale
        assert np.max(np.abs(Xm[[0, 3, 4, 5, 6]])) <= C.TEST_HB_LINEAR_LIMIT_RTOL * scale
        assert np.min(sol.problem.evaluate(sol.X, g).N) > 0.0


@pytest.mark.parametrize("law_name", ["jenkins", "iwan"])
def test_condensed_equals_uncondensed(law_name):
    s = _chain(9, law_name)
    # the normal DOF is retained with the tangential ones
    assert retained_dofs(s).tolist() == [0, 1, 2, 8]
    for g in (0.8, 1.05, 1.4):
        full = harmonic_balance(s, g, harmonics=5, samples=128, condense=False)
        cond = harmonic_balance(s, g, harmonics=5, samples=128, condense=True)
        assert full.status.ok and cond.status.ok
        assert isinstance(cond.problem, CondensedHBProblem)
        scale = np.max(np.abs(full.X))
        rec = cond.problem.full_coefficients(cond.X, cond.problem.f1_ref)
        assert np.max(np.abs(rec - full.X)) <= C.TEST_HB_CONDENSED_RTOL * scale
        assert cond.stable == full.stable
        assert abs(cond.growth - full.growth) <= 1e-7


def test_condensed_jacobian_matches_central_differences():
    s = _chain(7, "iwan")
    p = CondensedHBProblem(s, harmonics=3, samples=128)
    X = harmonic_balance(s, 1.1, harmonics=3, samples=128, condense=True).X
    ev = p.evaluate(X, 1.1)
    Ja = np.c_[ev.JX, ev.Jp]
    assert np.max(np.abs(Ja - _central_jacobian(p, X, 1.1))) <= C.TEST_HB_JACOBIAN_RTOL * np.max(np.abs(Ja))


def test_branch_through_resonance_agrees_with_single_points():
    s = _damper(100.0)
    ds = frc_hb(s, 0.7, 1.5, harmonics=5, samples=128)
    assert ds.attrs["status"] == "complete" and ds.stable.values.all()
    for i in range(0, ds.sizes["point"], max(1, ds.sizes["point"] // 4)):
        g = float(ds.gamma[i])
        one = harmonic_balance(s, g, harmonics=5, samples=128)
        assert abs(one.amplitude_m - float(ds.amplitude_m[i])) <= C.TEST_HB_MIXED_RTOL * one.amplitude_m


def test_selection_vectors_equal_dof_pairs():
    for fn in (100.0, 200.0):
        a = HBProblem(_damper(fn), harmonics=3, samples=64)
        b = HBProblem(_damper(fn, direction=True), harmonics=3, samples=64)
        X = a.linear_guess(1.1) * (1.0 + 0.3 * np.sin(np.arange(a.size)))
        ea, eb = a.evaluate(X, 1.1), b.evaluate(X, 1.1)
        assert np.array_equal(ea.R, eb.R) and np.array_equal(ea.JX, eb.JX)
    # a selection vector between two DOFs equals the DOF pair, condensed too
    s = _chain(6, "jenkins")
    c = s.contacts[0]
    d = np.zeros(6)
    d[1], d[2] = 1.0, -1.0
    v = jd.System(s.M, s.C, s.K, force=s.force, force_phase_deg=s.force_phase_deg,
                  contacts=(jd.Contact(c.law, direction=d, normal=c.normal),))
    for condense in (False, True):
        x = harmonic_balance(s, 1.1, harmonics=3, samples=64, condense=condense)
        y = harmonic_balance(v, 1.1, harmonics=3, samples=64, condense=condense)
        assert x.status.ok and y.status.ok
        assert np.max(np.abs(x.X - y.X)) <= C.TEST_HB_CONDENSED_RTOL * np.max(np.abs(x.X))


def _decoupled():
    """Spring damper (DOFs 0, 1, Jenkins) and a closed-form Iwan contact with a harmonic load
    (DOF 2), with no structural coupling: (combined system, part A, part B)."""
    a = _damper(100.0)
    law_b = make_law("iwan-closed", kt=2e5, mu=0.4, n_ref=80.0)
    cb = jd.Contact(law_b, dof=0, normal=jd.HarmonicLoad(80.0, 30.0, 20.0))
    b = jd.System(np.array([[5.0]]), np.array([[20.0]]), np.array([[2e5]]), contacts=(cb,), force=[15.0],
                  force_phase_deg=[30.0])
    M = np.zeros((3, 3))
    Cm = np.zeros((3, 3))
    K = np.zeros((3, 3))
    for Z, za, zb in ((M, a.M, b.M), (Cm, a.C, b.C), (K, a.K, b.K)):
        Z[:2, :2], Z[2:, 2:] = za, zb
    cs = (a.contacts[0], jd.Contact(law_b, dof=2, normal=cb.normal))
    both = jd.System(M, Cm, K, contacts=cs, force=[25.0, 100.0, 15.0], force_phase_deg=[0.0, 60.0, 30.0])
    return both, a, b


def test_mixed_laws_equal_each_law_alone():
    both, a, b = _decoupled()
    assert type(both.contacts[0].law) is not type(both.contacts[1].law)
    H, Ns, g = 3, 128, 1.1
    assert both.w0 == a.w0  # the lowest natural frequency is part A's
    gb = g * both.w0 / b.w0  # the same frequency for part B
    pa, pb, pc = (HBProblem(s, harmonics=H, samples=Ns) for s in (a, b, both))
    nh = 2 * H + 1
    rng = np.random.default_rng(3)
    Xa = pa.linear_guess(g) * (1.0 + 0.2 * rng.standard_normal(pa.size))
    Xb = pb.linear_guess(gb) * (1.0 + 0.2 * rng.standard_normal(pb.size))
    Xc = np.c_[Xa.reshape(nh, 2), Xb.reshape(nh, 1)].ravel()
    ea, eb, ec = pa.evaluate(Xa, g), pb.evaluate(Xb, gb), pc.evaluate(Xc, g)
    Rc = ec.R.reshape(nh, 3)
    Jc = ec.JX.reshape(nh, 3, nh, 3)
    for part, e, cols in ((Xa, ea, slice(0, 2)), (Xb, eb, slice(2, 3))):
        m = part.size
        assert np.max(np.abs(Rc[:, cols].ravel() - e.R)) <= 1e-12 * np.max(np.abs(e.R))
        assert np.max(np.abs(Jc[:, cols, :, cols].reshape(m, m) - e.JX)) <= 1e-12 * np.max(np.abs(e.JX))
    assert not np.any(Jc[:, :2, :, 2]) and not np.any(Jc[:, 2, :, :2])
    # solved: the combined system's response is each part's
    sc = harmonic_balance(both, g, harmonics=H, samples=Ns)
    sa = harmonic_balance(a, g, harmonics=H, samples=Ns)
    sb = harmonic_balance(b, gb, harmonics=H, samples=Ns)
    assert sc.status.ok and sa.status.ok and sb.status.ok
    Xs = sc.X.reshape(nh, 3)
    assert np.max(np.abs(Xs[:, :2].ravel() - sa.X)) <= C.TEST_HB_MIXED_RTOL * np.max(np.abs(sa.X))
    assert np.max(np.abs(Xs[:, 2] - sb.X)) <= C.TEST_HB_MIXED_RTOL * np.max(np.abs(sb.X))


def test_load_parameters_and_sampled_loads_are_refused():
    s = _damper(100.0)
    with pytest.raises(ValueError, match="parameter: 'eta'"):
        HBProblem(s, parameter="eta", gamma=1.0)
    c = jd.Contact(make_law("jenkins", kt=KT, mu=0.5, n_ref=P), dof=0, normal=jd.SampledLoad([100.0, 150.0, 50.0]))
    s2 = jd.System(np.diag([10.0]), None, np.diag([3e5]), contacts=(c,), force=[25.0])
    with pytest.raises(ValueError, match="contact 0 normal"):
        HBProblem(s2)

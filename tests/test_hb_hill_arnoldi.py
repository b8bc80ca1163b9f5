"""Hill's method at any size (jointdyn.hb.hill_arnoldi): shift-invert Arnoldi against dense Hill (the same
labels, exponents to 1e-6) on branches both run, on every form of the Jacobian, and against the time domain
(the monodromy of the period map) on a model beyond the dense method's size."""

import math

import numpy as np
import pytest

from jointdyn import System
from jointdyn.hb import (
    StabilityOptions,
    branch_dataset,
    continue_hb,
    harmonic_balance,
    hill_arnoldi_exponents,
    hill_exponents,
)
from hill_checks import assert_period_map_confirms

ARNOLDI = StabilityOptions(method="arnoldi")
DENSE = StabilityOptions(method="dense")
#: exponents (1/s) of both methods agree to this times w
EXPONENT_ATOL = 1e-6


@pytest.fixture(scope="module")
def damper_branches():
    """The closed-form damper with its fold pair near gamma 1.18 (an unstable stretch), both methods."""
    s = System.paper_damper(eta=10.0, beta=2.0, model="iwan-closed")
    kw = dict(harmonics=7, samples=128, progress=False)
    return continue_hb(s, 0.5, 2.0, stability=DENSE, **kw), continue_hb(s, 0.5, 2.0, stability=ARNOLDI, **kw)


def test_arnoldi_labels_and_growth_equal_dense_hill_along_a_branch(damper_branches):
    a, b = damper_branches
    assert np.array_equal(a.lam, b.lam)  # one continuation: the stability alone differs
    assert a.stable.any() and (~a.stable).any()
    assert np.array_equal(a.stable, b.stable)
    np.testing.assert_allclose(b.growth, a.growth, rtol=0, atol=EXPONENT_ATOL)
    assert (a.stability, b.stability) == ("hill", "hill-arnoldi")
    assert branch_dataset(b).attrs["stability"] == "hill-arnoldi"
    assert np.array_equal(a.fold, b.fold)


def test_arnoldi_exponents_are_the_dense_ones_nearest_the_axis(damper_branches):
    a, _ = damper_branches
    p, s = a.problem, a.problem.system
    u = np.flatnonzero(~a.stable)
    for i in (u[0], u[-1], 0, a.lam.size // 2, a.lam.size - 1):
        ev = p.evaluate(a.X[i], a.lam[i])
        w = p.omega(a.lam[i])
        sel, lam = hill_exponents(ev.JX, s.M, s.C, w, p.H)
        found = hill_arnoldi_exponents(ev.JX, s.M, s.C, w, p.H, ARNOLDI)
        assert found.exponents.size and found.band > 0.0
        for z in found.exponents:  # every exponent found is an eigenvalue of Hill's matrix
            assert np.min(np.abs(lam - z)) <= EXPONENT_ATOL * w
        # the one with the largest real part is dense Hill's (up to its conjugate)
        assert min(abs(found.exponents[0] - sel[0]), abs(found.exponents[0] - sel[0].conj())) <= EXPONENT_ATOL * w
        assert abs(found.growth - sel[0].real / w) <= EXPONENT_ATOL


def _interface_chain(nodes):
    from test_modes_tmdsimpy_interface import _module

    return _module("benchmarks/bench_hb_interface_chain.py").chain(nodes)


@pytest.mark.parametrize("kind", ["sparse", "blocks"])
def test_sparse_and_block_jacobians_give_the_dense_exponents(kind):
    """The interfaces' chain: Q(sigma) from a scipy.sparse Jacobian or harmonic blocks (SuperLU) equals the
    dense one (LAPACK)."""
    s = _interface_chain(4)
    sol = harmonic_balance(s, 1.0, harmonics=2, samples=32, stability=False)
    assert sol.status.ok and math.isnan(sol.growth)
    p = sol.problem
    lam = p.f1_ref
    w = p.omega(lam)
    dense = p.evaluate(sol.X, lam).JX
    other = (p.evaluate_sparse if kind == "sparse" else p.evaluate_blocks)(sol.X, lam).JX
    assert not isinstance(other, np.ndarray)
    a = hill_arnoldi_exponents(dense, s.M, s.C, w, p.H, ARNOLDI)
    b = hill_arnoldi_exponents(other, s.M, s.C, w, p.H, ARNOLDI)
    sel, _ = hill_exponents(dense, s.M, s.C, w, p.H)
    assert a.exponents.size == b.exponents.size > 0
    for z in b.exponents:  # the same set (the order of equal real parts aside)
        assert np.min(np.abs(a.exponents - z)) <= EXPONENT_ATOL * w
    assert abs(b.growth - sel[0].real / w) <= EXPONENT_ATOL


def test_single_point_stability_by_either_method_and_none():
    s = System.paper_damper(eta=10.0, beta=2.0, model="iwan-closed")
    d = harmonic_balance(s, 0.9, harmonics=7, samples=128, stability=DENSE)
    r = harmonic_balance(s, 0.9, harmonics=7, samples=128, stability=ARNOLDI)
    n = harmonic_balance(s, 0.9, harmonics=7, samples=128, stability=False)
    assert d.status.ok and d.stable == r.stable and abs(d.growth - r.growth) <= EXPONENT_ATOL
    assert np.max(np.abs(r.multipliers)) == pytest.approx(np.max(np.abs(d.multipliers)), abs=1e-6)
    assert math.isnan(n.growth) and not n.stable and n.multipliers.size == 0


def _damper_with_a_chain(extra: int = 19) -> System:
    """The closed-form damper (DOF 0, its contact and forcing) with a damped chain of ``extra`` masses hung
    from it by a soft spring: the fold pair near gamma 1.18 stays, and Hill's companion matrix at H = 7 has
    2 (1 + extra) 15 rows (600 for 19), beyond the dense method's size."""
    d = System.paper_damper(eta=10.0, beta=2.0, model="iwan-closed")
    m0, k0 = float(d.M[0, 0]), float(d.K[0, 0])
    n = 1 + extra
    M = np.diag([m0] + [0.2 * m0] * extra)
    K = np.zeros((n, n))
    K[0, 0] = k0
    for i, k in enumerate([0.02 * k0] + [2.0 * k0] * (extra - 1)):
        K[i, i] += k
        K[i + 1, i + 1] += k
        K[i, i + 1] -= k
        K[i + 1, i] -= k
    K[np.arange(1, n), np.arange(1, n)] += k0
    C = np.zeros((n, n))
    C[1:, 1:] = 2e-4 * K[1:, 1:] / math.sqrt(k0 / m0)
    f = np.zeros(n)
    f[0] = float(d.force[0])
    return System(M=M, C=C, K=K, contacts=d.contacts, force=f)


def test_time_integration_confirms_an_unstable_and_a_stable_point_beyond_the_dense_size():
    s = _damper_with_a_chain()
    br = continue_hb(s, 1.1, 1.3, harmonics=7, samples=128, progress=False)
    assert 2 * s.ndof * (2 * br.problem.H + 1) > StabilityOptions().dense_max_rows
    assert br.status.ok and br.stability == "hill-arnoldi"
    assert_period_map_confirms(br, 1.27)


def test_modal_damping_as_an_operator_gives_the_exponents_of_its_dense_matrix():
    """A System whose C is a ModalDamping operator: Arnoldi (on the operator's system) equals dense Hill on the
    dense C, at every point of a branch."""
    import jointdyn as jd

    s = _damper_with_a_chain(5)
    op = jd.modal_damping(s.M, s.K, 0.01, form="operator")
    so = jd.System(M=s.M, C=op, K=s.K, contacts=s.contacts, force=s.force)
    br = continue_hb(so, 1.1, 1.3, harmonics=5, samples=64, stability=ARNOLDI, progress=False)
    assert br.status.ok and br.stability == "hill-arnoldi"
    p = br.problem
    for i in range(0, br.lam.size, max(1, br.lam.size // 8)):
        w = p.omega(br.lam[i])
        sel, _ = hill_exponents(p.evaluate(br.X[i], br.lam[i]).JX, s.M, op.toarray(), w, p.H)
        assert abs(br.growth[i] - sel[0].real / w) <= EXPONENT_ATOL


def test_stability_numbers_are_options(damper_branches):
    """StabilityOptions.rtol, confirm and small_eig: the defaults those of the module constants they replaced,
    each honoured, each refused outside its range with its name."""
    from jointdyn.hb import hill_stability

    opt = StabilityOptions()
    assert (opt.rtol, opt.confirm, opt.small_eig) == (1e-6, 1e-4, 200)
    a, _ = damper_branches
    p, s = a.problem, a.problem.system
    i = int(np.flatnonzero(~a.stable)[0])
    JX, w = p.evaluate(a.X[i], a.lam[i]).JX, p.omega(a.lam[i])
    stable, growth, mult = hill_stability(JX, s.M, s.C, w, p.H)
    assert not stable and growth == a.growth[i] > opt.rtol
    # one point at a time (small_eig 0) for the batched path of this 30-row companion: the same growth
    lap = hill_stability(JX, s.M, s.C, w, p.H, StabilityOptions(small_eig=0))
    assert abs(lap[1] - growth) <= 1e-12 and not lap[0]
    # the growth is compared with rtol: a bound above it labels the point stable
    assert hill_stability(JX, s.M, s.C, w, p.H, StabilityOptions(rtol=2.0 * growth))[0]
    for name, bad in (("rtol", 0.0), ("confirm", -1.0), ("small_eig", -1), ("arnoldi_pole_rtol", 1.0)):
        with pytest.raises(ValueError, match=name):
            StabilityOptions(**{name: bad})


def test_confirm_band_decides_by_the_period_map_only_inside_it():
    """A growth between rtol and confirm goes to the time-domain period map; confirm at rtol sends none."""
    from jointdyn.hb.floquet import confirmed_stability

    br = continue_hb(System.paper_damper(eta=10.0, beta=2.0, model="iwan-closed"), 0.5, 0.6, harmonics=3,
                     samples=64, progress=False)
    i = np.array([0, br.lam.size - 1])
    opt = StabilityOptions()
    growth = np.array([0.5 * (opt.rtol + opt.confirm), 2.0 * opt.confirm])
    stable, checked = confirmed_stability(br.problem, br.X[i], br.lam[i], growth, opt)
    assert checked == 1 and stable[0] and not stable[1]  # the period map of a stable point says stable
    stable, checked = confirmed_stability(br.problem, br.X[i], br.lam[i], growth,
                                           StabilityOptions(confirm=opt.rtol))
    assert checked == 0 and not stable.any()


def test_single_solution_decides_a_marginal_growth_by_the_period_map_as_the_branch_does(monkeypatch):
    """One dispatcher (jointdyn.hb.floquet) for branches and single solutions: a single solution whose growth
    lies between rtol and confirm goes to the period map, and gets the branch's label at the same point."""
    import jointdyn.hb.frc as frc

    s = System.paper_damper(eta=10.0, beta=2.0, model="iwan-closed")
    br = continue_hb(s, 1.17, 1.19, harmonics=5, samples=64, progress=False)
    opt = StabilityOptions()
    band = np.flatnonzero((br.growth > opt.rtol) & (br.growth < opt.confirm))
    assert band.size and br.counters["monodromy_checks"] == band.size
    i = int(band[0])
    sol = harmonic_balance(s, br.lam[i], harmonics=5, samples=64, guess=br.X[i])
    assert sol.status.ok and sol.growth == pytest.approx(br.growth[i], rel=1e-6)
    assert sol.stable == br.stable[i]
    calls = []
    real = frc.confirmed_stability

    def spy(problem, X, lam, growth, options):
        stable, checked = real(problem, X, lam, growth, options)
        calls.append((float(growth[0]), checked))
        return (~stable if checked else stable), checked  # what the period map says is what is reported

    monkeypatch.setattr(frc, "confirmed_stability", spy)
    flipped = harmonic_balance(s, br.lam[i], harmonics=5, samples=64, guess=br.X[i])
    assert calls == [(pytest.approx(br.growth[i], rel=1e-6), 1)] and flipped.stable == (not br.stable[i])
    calls.clear()
    kept = harmonic_balance(s, br.lam[i], harmonics=5, samples=64, guess=br.X[i],
                            stability=StabilityOptions(confirm=opt.rtol))  # an empty band: Hill's label stands
    assert [c for _, c in calls] == [0] and not kept.stable


def _chain_point():
    """One solution of the damper with a chain of three masses (8 exponents) near its fold pair: its Jacobian,
    M, C, w, H."""
    s = _damper_with_a_chain(3)
    sol = harmonic_balance(s, 1.2, harmonics=3, samples=64, stability=False, condense=False)
    assert sol.status.ok
    p = sol.problem
    return p.evaluate(sol.X, p.f1_ref).JX, s.M, s.C, p.omega(p.f1_ref), p.H


@pytest.mark.parametrize("k", [12, 3])
def test_one_real_shift_finds_every_eigenvalue_of_the_band_it_reports(k):
    """arnoldi_shifts = 1: every eigenvalue of Hill's whole companion matrix (dense LAPACK) in the band it
    reports between 0 and i w/2 is found; where its disk does not reach i w/2 (few eigenvalues, k = 3) the
    covering shifts are added and the result is that of their layout."""
    JX, M, C, w, H = _chain_point()
    one = hill_arnoldi_exponents(JX, M, C, w, H, StabilityOptions(method="arnoldi", arnoldi_eigenvalues=k,
                                                                  arnoldi_shifts=1))
    three = hill_arnoldi_exponents(JX, M, C, w, H, StabilityOptions(method="arnoldi", arnoldi_eigenvalues=k,
                                                                    arnoldi_shifts=3))
    _, lam = hill_exponents(JX, M, C, w, H)
    assert one.band > 0.0
    inside = lam[(np.abs(lam.real) <= one.band) & (np.abs(lam.imag) <= 0.5 * w)]
    assert inside.size
    for z in inside:
        assert np.min(np.abs(one.exponents - z)) <= EXPONENT_ATOL * w
    assert abs(one.growth - three.growth) <= EXPONENT_ATOL
    if k == 3:  # the covering shifts: the very layout of three
        assert one.band == pytest.approx(three.band, rel=1e-12)
        assert one.exponents.size == three.exponents.size
        for z in three.exponents:
            assert np.min(np.abs(one.exponents - z)) <= EXPONENT_ATOL * w
    for name, bad in (("arnoldi_shifts", 0), ("arnoldi_cover_shifts", 1)):
        with pytest.raises(ValueError, match=name):
            StabilityOptions(**{name: bad})

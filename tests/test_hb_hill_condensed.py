"""Hill's method through the condensed form (jointdyn.hb.hill_condensed): the Floquet exponents of a condensed
problem equal those of shift-invert Arnoldi and of dense Hill on the full Jacobian it recovers, for every form of
the receptance (Rayleigh with a lumped and a dense mass, modal damping dense and as an operator, a
non-proportional C taking the state-space expansion, no damping); the same labels along a condensed branch with
its fold pair; an unstable and a stable point confirmed by the time-domain period map."""

import math

import numpy as np
import pytest
from test_hb_hill_arnoldi import ARNOLDI, DENSE, _damper_with_a_chain

import jointdyn as jd
from jointdyn import System
from jointdyn.damping import dense_damping
from jointdyn.hb import (
    StabilityOptions,
    continue_hb,
    harmonic_balance,
    hill_arnoldi_exponents,
    hill_exponents,
)
from jointdyn.hb.floquet import point_stability
from jointdyn.hb.hill_condensed import condensed_hill_exponents
from hill_checks import assert_period_map_confirms

#: exponents agree to this relative to their modulus (and growth Re(s)/w to this)
RTOL = 1e-6


def _variant(kind: str) -> System:
    """The closed-form damper with a chain of 9 masses (10 DOFs), its damping of the given kind."""
    s = _damper_with_a_chain(9)
    M, K = s.M, s.K
    if kind == "state-space":  # the chain's own C: damped only off DOF 0, not diagonal in the modes
        return s
    if kind == "dense-mass":  # a dense mass matrix (a reduced model's), Rayleigh damping: Cholesky of M
        M = M + 0.05 * float(M[0, 0]) * np.ones_like(M) / M.shape[0]
        C = 0.02 * M + 1e-4 * K
    elif kind == "rayleigh":
        C = 0.02 * M + 1e-4 * K
    elif kind == "modal":
        C = jd.modal_damping(M, K, 0.01)
    elif kind == "operator":
        C = jd.modal_damping(M, K, 0.01, form="operator")
    else:
        C = np.zeros_like(M)
    return System(M=M, C=C, K=K, contacts=s.contacts, force=s.force)


def _close(a, b, scale):
    """Largest distance from a member of ``a`` to the nearest of ``b``, over ``scale``."""
    return max(float(np.min(np.abs(b - z))) for z in a) / scale


@pytest.mark.parametrize("kind", ["rayleigh", "dense-mass", "modal", "operator", "state-space", "undamped"])
def test_condensed_exponents_equal_the_full_jacobians(kind):
    s = _variant(kind)
    C = dense_damping(s.C)
    for gamma in (0.9, 1.25):
        sol = harmonic_balance(s, gamma, harmonics=5, samples=64, condense=True, stability=False)
        p = sol.problem
        assert sol.status.ok and p.condensed and p.n < s.ndof
        assert (p.receptance.modes is not None) == (kind == "state-space")  # the expansion each takes
        lam = p.f1_ref
        w = p.omega(lam)
        JX = p.evaluate(sol.X, lam).JX
        J = p.full_jacobian(JX, w)
        got = condensed_hill_exponents(p, JX, w, ARNOLDI)
        ref = hill_arnoldi_exponents(J, s.M, C, w, p.H, ARNOLDI)
        sel, every = hill_exponents(J, s.M, C, w, p.H)
        assert got.exponents.size == ref.exponents.size > 0
        scale = float(np.max(np.abs(ref.exponents)))
        assert _close(got.exponents, ref.exponents, scale) <= RTOL
        assert _close(ref.exponents, got.exponents, scale) <= RTOL
        assert _close(got.exponents, every, scale) <= RTOL  # eigenvalues of Hill's matrix
        assert got.band == pytest.approx(ref.band, rel=RTOL)
        assert abs(got.growth - ref.growth) <= RTOL * abs(ref.growth) + 1e-12
        assert abs(got.growth - sel[0].real / w) <= RTOL * abs(sel[0].real / w) + 1e-12


@pytest.mark.parametrize("offset", [0.0, 1e-10])
def test_a_shift_on_a_pole_of_the_receptance(offset):
    """Undamped: at w = w_r / 1.5 the shift i w/2 of the first harmonic's u combination lies on the structural
    mode r (sigma + i w = i w_r), a pole of the receptance where the Woodbury solve cancels (exponents 7 % off,
    an unstable one missed, before such shifts were moved): the shift is moved, and the exponents are dense
    Hill's."""
    s = _variant("undamped")
    sol = harmonic_balance(s, 0.9, harmonics=3, samples=64, condense=True, stability=False)
    p = sol.problem
    JX = p.evaluate(sol.X, p.f1_ref).JX
    for r in (0, 1):
        w = math.sqrt(float(p.receptance.a[r])) / 1.5 * (1.0 + offset)
        J = p.full_jacobian(JX, w)
        got = condensed_hill_exponents(p, JX, w, ARNOLDI)
        sel, every = hill_exponents(J, s.M, dense_damping(s.C), w, p.H)
        assert _close(got.exponents, every, float(np.max(np.abs(every)))) <= RTOL
        assert abs(got.growth - sel[0].real / w) <= RTOL * max(abs(sel[0].real / w), 1e-3)


@pytest.fixture(scope="module")
def condensed_branches():
    """The damper with a damped chain of 19 masses (the fold pair near gamma 1.18), condensed: Arnoldi through
    the condensed form (the default beyond dense_max_rows) and dense Hill on the full Jacobians."""
    s = _damper_with_a_chain()
    kw = dict(harmonics=7, samples=128, progress=False, condense=True)
    return (continue_hb(s, 1.1, 1.3, **kw), continue_hb(s, 1.1, 1.3, stability=DENSE, **kw))


def test_condensed_branch_labels_equal_dense_hill(condensed_branches):
    a, d = condensed_branches
    assert a.problem.condensed and 2 * a.problem.system.ndof * a.problem.nh > StabilityOptions().dense_max_rows
    assert (a.stability, d.stability) == ("hill-arnoldi", "hill")
    assert np.array_equal(a.lam, d.lam)  # one continuation: the stability alone differs
    assert a.stable.any() and (~a.stable).any()
    assert np.array_equal(a.stable, d.stable)
    np.testing.assert_allclose(a.growth, d.growth, rtol=RTOL, atol=1e-12)
    assert a.fold.any() and np.array_equal(a.fold, d.fold)


def test_time_integration_confirms_an_unstable_and_a_stable_condensed_point(condensed_branches):
    br, _ = condensed_branches
    assert_period_map_confirms(br, 1.27)


def test_single_condensed_point_by_either_method():
    s = _damper_with_a_chain()
    d = harmonic_balance(s, 1.25, harmonics=7, samples=128, condense=True, stability=DENSE)
    r = harmonic_balance(s, 1.25, harmonics=7, samples=128, condense=True)  # Arnoldi by size
    assert d.problem.condensed and d.status.ok and d.stable == r.stable
    assert abs(d.growth - r.growth) <= RTOL * abs(d.growth)
    assert np.max(np.abs(r.multipliers)) == pytest.approx(np.max(np.abs(d.multipliers)), rel=RTOL)
    stable, growth, _ = point_stability(r.problem, r.problem.evaluate(r.X, r.problem.f1_ref).JX,
                                        r.problem.omega(r.problem.f1_ref))
    assert stable == r.stable and growth == pytest.approx(r.growth, rel=RTOL)

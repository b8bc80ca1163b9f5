"""Compiled contact-law kernels agree with the plain-Python references.

``tests/reference.py`` re-implements every registered law from its
specification alone (the discrete Iwan model of MODEL.md section 5, the
exact Iwan law's pieces, the closed-form Iwan law with full Masing memory,
the paper's last-reversal rule); a registered law without a reference fails. These tests march both over
random histories (nested, growing, random-walk displacements; constant,
varying and separating normal loads) and require the same force (to
``TEST_REFERENCE_ATOL_FY * fy``), the same tangent and the same motion state
at every sample.
"""

import numpy as np
import pytest

import law_histories as H
from law_cases import registry_laws
from reference import REFERENCES, march_ref, reference_for

from jointdyn import IwanClosedForm, make_law, march
from jointdyn.laws import law_names
import tolerances as C

KT, MU, NREF = 1e5, 0.1, 100.0
XS = 2.0 * MU * NREF / KT  # macroslip displacement 2 fy / kt of the closed form

#: every registered law with every parameter set of law_cases.variants
LAWS = {case: (name, law) for case, name, law in registry_laws(KT, MU, NREF)}
FULL = IwanClosedForm(kt=KT, mu=MU, n_ref=NREF)


def _histories():
    out = []
    for seed in range(4):
        rng = np.random.default_rng(100 + seed)
        n = 700
        xs = [
            H.random_walk(rng, n, 0.15 * XS),
            H.random_reversals(rng, 40, 2.0 * XS)[:n],
            H.nested_then_growing(12, 1.5 * XS, steps=7, shrink=0.8),
        ]
        for k, x in enumerate(xs):
            eta = (0.0, 0.6, 1.4)[(seed + k) % 3]  # constant, varying, separating
            N = H.normal_history(rng, x.size, NREF, eta)
            out.append(pytest.param(x, N, id=f"seed{seed}-shape{k}-eta{eta}"))
    return out


def _compare(name, law, x, N):
    T, kT, code, _ = march(law, x, N)
    Tr, kTr, cr = march_ref(reference_for(name, law, x[0], N[0]), x, N)
    np.testing.assert_allclose(T, Tr, rtol=0, atol=C.TEST_REFERENCE_ATOL_FY * law.fy)
    np.testing.assert_allclose(kT, kTr, rtol=0, atol=C.TEST_REFERENCE_ATOL_KT * law.kt)
    np.testing.assert_array_equal(code, np.asarray(cr, dtype=np.int8))
    return T, code


@pytest.mark.parametrize("name", law_names())
def test_every_registered_law_has_a_reference(name):
    assert name in REFERENCES, (
        f"law {name!r} is registered but tests/reference.py has no plain-Python reference for it: "
        "write one from the law's specification and add it to REFERENCES"
    )


@pytest.mark.parametrize("case", sorted(LAWS))
@pytest.mark.parametrize("x,N", _histories())
def test_kernel_matches_reference(case, x, N):
    _compare(*LAWS[case], x, N)


def test_histories_exercise_every_state():
    """The histories above are not trivial: all three motion states, deep
    stacks and stack overflow occur (guards the test itself)."""
    seen = set()
    for p in _histories():
        x, N = p.values
        _, code = _compare("iwan-closed", FULL, x, N)
        seen.update(np.unique(code).tolist())
    assert seen == {0, 1, 2}
    x = H.nested_then_growing(12, 1.5 * XS, steps=7, shrink=0.8)
    s = march(FULL, x[:-60], np.full(x.size - 60, NREF))[3]
    assert s[7] >= 8  # reversal stack depth 8 or more mid-way out (row 7 = m)


def test_reference_stack_overflow_differs_only_when_deeper_than_capacity():
    """max_depth=4 equals the unlimited stack while at most 4 points are live
    and differs after a deeper nest (the documented limitation is real)."""
    x = H.nested_then_growing(10, 1.5 * XS, steps=9, shrink=0.85)
    N = np.full(x.size, NREF)
    T64 = march(FULL, x, N)[0]
    T4 = march(IwanClosedForm(kt=KT, mu=MU, n_ref=NREF, max_depth=4), x, N)[0]
    first_overflow = 1 + 9 * 5  # the fifth reversal point is pushed at the 5th one
    np.testing.assert_array_equal(T64[:first_overflow], T4[:first_overflow])
    assert np.max(np.abs(T64 - T4)) > 1e-3 * MU * NREF


def test_zero_friction_and_separation_reference():
    """mu = 0: no force at all, separation exactly where N <= 0."""
    rng = np.random.default_rng(7)
    x = H.random_walk(rng, 200, 1e-5)
    N = H.normal_history(rng, 200, NREF, 1.5)
    for name in law_names():
        law = make_law(name, kt=KT, mu=0.0, n_ref=NREF)
        T, code = _compare(name, law, x, N)
        assert np.all(T == 0.0)
        moving = np.concatenate(([False], np.diff(x) != 0.0))
        # a discrete element with zero slip force counts as stuck when it does
        # not move (x[0]); any motion slips it
        assert set(np.unique(code[moving]).tolist()) <= {1, 2}
        assert np.all((code == 2) == (N <= 0.0))

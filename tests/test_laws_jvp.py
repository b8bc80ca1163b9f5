"""Forward-mode kernels (``step_jvp``) against central finite differences.

The derivative of the force history along a perturbation of the displacement
history and/or the normal-load history, propagated through the state by
``step_jvp``, must equal the central difference of marches of ``step``
(Richardson-extrapolated from two steps; to ``TEST_JVP_RTOL`` of the
largest derivative) for histories with
reversals, macroslip, varying load and separation, as long as no sample sits
at a state transition (the perturbed marches must pass through the same
motion states, which the test checks). The laws are built with few elements
(``law_cases.variants(small=True)``): with many, one of them changes between
stick and slip within the difference step at a large share of the samples,
and its memory keeps the two perturbed marches on different sides. The primal outputs of ``step_jvp``
must be ``step``'s bit for bit.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import law_histories as H

from law_cases import registry_laws

from jointdyn import Iwan, IwanClosedForm, march
from jointdyn.laws import law_names, make_law
import tolerances as C
from jointdyn._jit import specialize

KT, MU, NREF = 1e5, 0.1, 100.0
XS = 2.0 * MU * NREF / KT


def _march_jvp_template(params, s0, ds0, x, dx, N, dN, T, kT, code, dT):  # pragma: no cover - compiled
    a = s0.copy()
    b = np.empty_like(s0)
    da = ds0.copy()
    db = np.empty_like(ds0)
    for i in range(x.shape[0]):
        t_, k_, c_ = STEP_JVP(params, a, da, b, db, x[i], dx[i], N[i], dN[i], dT[i])  # noqa: F821
        T[i] = t_
        kT[i] = k_
        code[i] = c_
        a, b = b, a
        da, db = db, da


def march_jvp(law, x, dx, N, dN, state):
    n, nd = dx.shape
    T, kT, dT = np.empty(n), np.empty(n), np.empty((n, nd))
    code = np.empty(n, dtype=np.int8)
    ds0 = np.zeros((law.state_size, nd))
    fn = specialize(_march_jvp_template, STEP_JVP=law.step_jvp)
    fn(law.params, state, ds0, x, np.ascontiguousarray(dx), N, np.ascontiguousarray(dN), T, kT, code, dT)
    return T, kT, code, dT


#: every registered law with every parameter set of law_cases.variants (few elements)
LAWS = {case: law for case, _, law in registry_laws(KT, MU, NREF, small=True)}
FULL = IwanClosedForm(kt=KT, mu=MU, n_ref=NREF)


def _case(seed, eta):
    rng = np.random.default_rng(seed)
    x = H.random_reversals(rng, 14, 2.5 * XS, steps=(6, 30))
    N = H.normal_history(rng, x.size, NREF, eta)
    n = x.size
    # three directions: displacement only, load only, both; the first sample
    # is held (it fixes the virgin state the marches start from)
    dx = np.zeros((n, 3))
    dN = np.zeros((n, 3))
    dx[1:, 0] = rng.normal(size=n - 1) * XS
    dN[1:, 1] = rng.normal(size=n - 1) * NREF
    dx[1:, 2] = rng.normal(size=n - 1) * XS
    dN[1:, 2] = rng.normal(size=n - 1) * NREF
    return x, N, dx, dN


def _central_difference(law, x, N, dxj, dNj, s0, h, code0):
    Tp, _, cp, _ = march(law, x + h * dxj, N + h * dNj, state=s0)
    Tm, _, cm, _ = march(law, x - h * dxj, N - h * dNj, state=s0)
    # the perturbed histories cross no state transition
    np.testing.assert_array_equal(cp, code0)
    np.testing.assert_array_equal(cm, code0)
    return (Tp - Tm) / (2 * h)


def _richardson_difference(law, x, N, dxj, dNj, s0, code0):
    """Central differences at steps h and h / 2 (``TEST_JVP_FD_STEP``),
    Richardson-extrapolated: error O(h^4). Laws whose state moves its own
    breakpoints (the exact Iwan law's pieces, merged at a small capacity)
    are curved enough within h that the plain central difference is off by
    1e-4 of the derivative."""
    h = C.TEST_JVP_FD_STEP
    d1 = _central_difference(law, x, N, dxj, dNj, s0, h, code0)
    d2 = _central_difference(law, x, N, dxj, dNj, s0, 0.5 * h, code0)
    return (4.0 * d2 - d1) / 3.0


@pytest.mark.parametrize("name", sorted(LAWS))
@pytest.mark.parametrize("seed,eta", [(1, 0.0), (2, 0.5), (3, 0.8), (4, 1.3), (5, 1.6)])
def test_jvp_equals_finite_differences(name, seed, eta):
    law = LAWS[name]
    x, N, dx, dN = _case(seed, eta)
    s0 = law.initial_state(x[0], N[0])
    T, kT, code, dT = march_jvp(law, x, dx, N, dN, s0)
    T0, kT0, code0, _ = march(law, x, N, state=s0)
    # primal outputs of step_jvp are step's, exactly
    np.testing.assert_array_equal(T, T0)
    np.testing.assert_array_equal(kT, kT0)
    np.testing.assert_array_equal(code, code0)
    for j in range(dx.shape[1]):
        fd = _richardson_difference(law, x, N, dx[:, j], dN[:, j], s0, code0)
        scale = np.max(np.abs(fd))
        assert scale > 0.0
        np.testing.assert_allclose(dT[:, j], fd, rtol=0, atol=C.TEST_JVP_RTOL * scale)


def test_jvp_cases_cover_every_state():
    """Guard of the test above: its histories reach all motion states."""
    seen = set()
    for seed, eta in [(1, 0.0), (4, 1.3)]:
        x, N, dx, dN = _case(seed, eta)
        seen.update(np.unique(march(FULL, x, N)[2]).tolist())
    assert seen == {0, 1, 2}


@pytest.mark.parametrize("law", [FULL, Iwan(kt=KT, mu=MU, n_ref=NREF)], ids=["iwan-closed", "iwan"])
def test_jvp_of_constant_load_branch_closed_form(law):
    """d T / d x along a Masing branch: kT of the branch, by hand: after a
    reversal at q0 the slope is kt (1 - (q0 - q)/(4 alpha)) (c = 2); the
    closed form and the exact law (equal at constant load)."""
    x = np.concatenate([np.linspace(0, 0.8 * XS, 20), np.linspace(0.8 * XS, 0.0, 21)[1:]])
    N = np.full(x.size, NREF)
    dx = np.zeros((x.size, 1))
    dx[-1, 0] = 1.0  # move only the last sample
    dN = np.zeros_like(dx)
    T, kT, code, dT = march_jvp(law, x, dx, N, dN, law.initial_state(0.0, NREF))
    q0, q = 1.6, 0.0
    assert dT[-1, 0] == pytest.approx(KT * (1 - (q0 - q) / 4.0), rel=1e-12)
    assert kT[-1] == pytest.approx(KT * (1 - (q0 - q) / 4.0), rel=1e-12)


@pytest.mark.parametrize("name", law_names())
def test_init_jvp_is_the_exact_derivative_of_the_virgin_state(name):
    """init_jvp writes init's state and its derivative along dx0, dn0: equal
    to central differences of initial_state (the virgin state is smooth on
    each side of n0 = 0), on both sides of separation, for several
    directions at once."""
    rng = np.random.default_rng(11)
    law = make_law(name, kt=KT, mu=MU, n_ref=NREF)
    for x0, n0 in ((0.0, NREF), (3.1 * XS, 0.4 * NREF), (-1.7 * XS, -0.5 * NREF)):
        dx0 = rng.normal(size=3) * XS
        dn0 = rng.normal(size=3) * NREF
        s = np.full(law.state_size, np.nan)
        ds = np.full((law.state_size, 3), np.nan)
        law.init_jvp(law.params, x0, dx0, n0, dn0, s, ds)
        np.testing.assert_array_equal(s, law.initial_state(x0, n0))
        h = C.TEST_JVP_FD_STEP
        for j in range(3):
            fd = (law.initial_state(x0 + h * dx0[j], n0 + h * dn0[j])
                  - law.initial_state(x0 - h * dx0[j], n0 - h * dn0[j])) / (2 * h)
            scale = max(np.max(np.abs(fd)), np.max(np.abs(ds[:, j])), 1e-300)
            np.testing.assert_allclose(ds[:, j], fd, rtol=0, atol=C.TEST_JVP_RTOL * scale)


@given(
    steps=st.lists(
        st.tuples(st.floats(-2e-3, 2e-3), st.floats(-50.0, 250.0)), min_size=1, max_size=40
    ),
    seed=st.integers(0, 2**32 - 1),
)
@settings(max_examples=60, deadline=None)
def test_jenkins_kernels_are_the_one_element_discrete_kernels_bit_for_bit(steps, seed):
    # Jenkins has kernels of its own (the one element inlined); the same operations as the n-element
    # kernels, so the same bits: force, stiffness, code, states and derivatives, in and out of separation
    from jointdyn.laws import DiscreteIwan, Jenkins
    from jointdyn.laws.discrete import discrete_step, discrete_step_jvp, jenkins_step, jenkins_step_jvp

    jk, d1 = Jenkins(3e5, 0.5, 100.0), DiscreteIwan(3e5, 0.5, 100.0, n=1)
    np.testing.assert_array_equal(jk.params, d1.params)
    p = jk.params
    rng = np.random.default_rng(seed)
    nd = 3
    s = [np.zeros(jk.state_size) for _ in range(4)]
    ds = [np.zeros((jk.state_size, nd)) for _ in range(4)]
    jk.init(p, 0.0, 100.0, s[0])
    jk.init(p, 0.0, 100.0, s[2])
    for x, N in steps:
        dx, dN = rng.normal(size=nd), rng.normal(size=nd)
        dTa, dTb = np.empty(nd), np.empty(nd)
        a = jenkins_step_jvp(p, s[0], ds[0], s[1], ds[1], x, dx, N, dN, dTa)
        b = discrete_step_jvp(p, s[2], ds[2], s[3], ds[3], x, dx, N, dN, dTb)
        assert [v.hex() if isinstance(v, float) else v for v in a] == \
               [v.hex() if isinstance(v, float) else v for v in b]
        assert jenkins_step(p, s[0], np.empty_like(s[0]), x, N) == discrete_step(p, s[2], np.empty_like(s[2]), x, N)
        for u, v in ((s[1], s[3]), (ds[1], ds[3]), (dTa, dTb)):
            assert u.tobytes() == v.tobytes()
        s = [s[1], s[0], s[3], s[2]]
        ds = [ds[1], ds[0], ds[3], ds[2]]

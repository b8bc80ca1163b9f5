"""The interface node pair (docs/model.md section 10): kernels against the plain-Python reference,
exact derivatives against finite differences, validation of the parameters."""

import math

import numpy as np
import pytest
from hypothesis import assume, event, given, settings
from hypothesis import strategies as st

from reference_interface import PairRef, march_ref

from jointdyn.interfaces import (
    Interface,
    interface_march,
    interface_march_jvp,
    interface_step,
    interface_step_jvp,
    interface_step_tangent,
)
from jointdyn.laws import MACROSLIP, SEPARATION, STICK_SLIP

finite = dict(allow_nan=False, allow_infinity=False)


def _pair(kt=1e3, kn=2e3, mu=0.4, preload=2.0):
    return Interface(kt=kt, kn=kn, mu=mu, preload=preload, pairs=[[0, 1, 2, -1, -1, -1]])


# --- kernels against the plain-Python reference -------------------------------------


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), npairs=st.integers(1, 6))
def test_kernels_equal_the_reference_on_random_walks(seed, npairs):
    rng = np.random.default_rng(seed)
    kt = rng.uniform(1e2, 1e4, npairs)
    kn = rng.uniform(1e2, 1e4, npairs)
    mu = rng.uniform(0.0, 1.0, npairs)
    P = rng.uniform(0.0, 5.0, npairs)
    it = Interface(kt=kt, kn=kn, mu=mu, preload=P, pairs=np.arange(6 * npairs).reshape(npairs, 6))
    nt = 60
    scale = float(np.max(mu * P / kt)) + 1e-6
    U1 = np.cumsum(rng.normal(0.0, scale, (nt, npairs)), axis=0)
    U2 = np.cumsum(rng.normal(0.0, scale, (nt, npairs)), axis=0)
    G = np.cumsum(rng.normal(0.0, float(np.max(P / kn)), (nt, npairs)), axis=0)
    refs = [PairRef(kt[i], kn[i], mu[i], P[i], (U1[0, i], U2[0, i])) for i in range(npairs)]
    rT1, rT2, rN, rc = (np.array(a) for a in march_ref(refs, U1.tolist(), U2.tolist(), G.tolist()))
    w = np.stack([U1[0], U2[0]], axis=1)
    for j in range(nt):
        k = max(j - 1, 0)
        T, N, code, w = it.step(np.stack([U1[j], U2[j]], axis=1), G[j], w, np.stack([U1[k], U2[k]], axis=1), G[k])
        f = max(1.0, float(np.max(mu * P)))
        np.testing.assert_allclose(T[:, 0], rT1[j], rtol=0, atol=1e-12 * f)
        np.testing.assert_allclose(T[:, 1], rT2[j], rtol=0, atol=1e-12 * f)
        np.testing.assert_allclose(N, rN[j], rtol=1e-14, atol=0)
        np.testing.assert_array_equal(code, rc[j])
        assert np.all(np.hypot(T[:, 0], T[:, 1]) <= mu * N * (1 + 1e-12) + 1e-300)


def test_states_and_their_codes():
    it = _pair()  # kt 1e3, kn 2e3, mu 0.4, P 2: slip force 0.8 N at g = 0
    w = it.initial_state()
    T, N, code, w1 = it.step([[5e-4, 0.0]], [0.0], w)  # |T*| = 0.5 < 0.8: stuck
    assert code[0] == STICK_SLIP and T[0, 0] == 0.5 and N[0] == 2.0 and np.all(w1 == 0.0)
    T, N, code, w1 = it.step([[6e-4, 8e-4]], [0.0], w)  # |T*| = 1 > 0.8: slips along (0.6, 0.8)
    assert code[0] == MACROSLIP
    np.testing.assert_allclose(T[0], [0.48, 0.64], rtol=1e-15)
    np.testing.assert_allclose(w1[0], [6e-4 - 0.48e-3, 8e-4 - 0.64e-3], rtol=1e-12)
    T, N, code, w1 = it.step([[3e-4, 1e-4]], [-1e-3], w)  # P + kn g = 0: open
    assert code[0] == SEPARATION and np.all(T == 0.0) and N[0] == 0.0
    np.testing.assert_array_equal(w1[0], [3e-4, 1e-4])


def test_forces_on_the_structure_follow_the_normal_spring_signs():
    it = Interface(kt=1e3, kn=1e3, mu=0.5, preload=1.0, pairs=[[0, 1, 2, 3, 4, 5], [3, -1, 5, -1, -1, -1]])
    x = np.array([1e-4, 2e-4, 1e-4, 0.0, 0.0, 0.0])
    u, g = it.relative(x)
    np.testing.assert_allclose(u, [[1e-4, 2e-4], [0.0, 0.0]])
    np.testing.assert_allclose(g, [1e-4, 0.0])
    T, N, code, _ = it.step(u, g, it.initial_state())
    f = it.forces(T, N, 6)
    # pair 0: N - P = kn g = 0.1 N pushes a_n down and b_n up; T = kt u (stuck) pulls side A back
    np.testing.assert_allclose(f, [-0.1, -0.2, -0.1, 0.1, 0.2, 0.1], rtol=1e-12)
    # while stuck the pairs are springs: f = -d/dx (kt |u|^2 / 2 + kn g^2 / 2) (preload cancelled at rest)
    h = 1e-9
    grad = np.empty(6)
    for d in range(6):
        e = np.zeros(6)
        e[d] = h
        en = [0.5e3 * (it.relative(x + s * e)[0] ** 2).sum() + 0.5e3 * (it.relative(x + s * e)[1] ** 2).sum()
              for s in (1.0, -1.0)]
        grad[d] = (en[0] - en[1]) / (2 * h)
    np.testing.assert_allclose(f, -grad, rtol=1e-6, atol=1e-9)


# --- exact derivatives -------------------------------------------------------------------


def _step1(params, x, w):
    """One pair's step from the start x[:3] = (u1, u2, g) to the end x[3:] from the slider w:
    ((T1, T2, N), w_new, code)."""
    T = np.empty((1, 2))
    N = np.empty(1)
    code = np.empty(1, dtype=np.int8)
    w_new = np.empty((1, 2))
    interface_step(params, x[None, 0:2], x[2:3], x[None, 3:5], x[5:6], w[None], w_new, T, N, code)
    return np.array([T[0, 0], T[0, 1], N[0]]), w_new[0].copy(), int(code[0])


def _steps_of_every_kind():
    """Start (u1, u2, g), end and slider of one pair (kt 1e3, kn 2e3, mu 0.4, P 2: slip force 0.8 N,
    opening at g = -1e-3 m) such that every state change happens inside a step: stuck, slipping,
    leaving the disc inside the step, opening, re-closing, N rising and falling, a start outside the
    disc."""
    mm = st.floats(-2e-3, 2e-3, **finite)
    return st.tuples(mm, mm, st.floats(-1.6e-3, 1.5e-3, **finite), mm, mm, st.floats(-1.6e-3, 1.5e-3, **finite),
                     st.floats(-1.5e-3, 1.5e-3, **finite), st.floats(-1.5e-3, 1.5e-3, **finite))


@settings(max_examples=300, deadline=None)
@given(case=_steps_of_every_kind(), dirs=st.lists(st.floats(-1.0, 1.0, **finite), min_size=16, max_size=16))
def test_tangent_and_jvp_equal_finite_differences(case, dirs):
    """The exact derivatives of the straight-path step with respect to its start, end and committed
    slider (interface_step_jvp) and to its end (interface_step_tangent) against central differences,
    through stick, slip, opening and re-closing inside the step (away from the instants where a state
    change reaches an end of the step)."""
    it = _pair()
    p = it.params
    kt, kn, mu, P = p[0]
    a1, a2, g0, u1, u2, g, w1, w2 = case
    x = np.array([a1 * 0.5, a2 * 0.5, g0, u1, u2, g])
    w = np.array([a1 * 0.5 + w1 * 0.5, a2 * 0.5 + w2 * 0.5])
    assume(math.hypot(u1 - x[0], u2 - x[1]) > 1e-6)  # the slip direction of v / |v|
    y0, wn0, c0 = _step1(p, x, w)
    n0, n1 = P + kn * g0, P + kn * g
    assume(abs(n1) > 1e-3 * P and abs(n0) > 1e-3 * P)
    event(f"state {c0}" + (", re-closing" if n0 < 0 < n1 else "") + (", N falls" if n1 < n0 else ""))
    # the 8 inputs (start, end, slider) one by one and two random mixtures of them
    D = np.concatenate([np.eye(8), np.array(dirs).reshape(8, 2)], axis=1)  # (8 inputs, 10 directions)
    h = 1e-9
    fd = np.empty((5, D.shape[1]))
    for k in range(D.shape[1]):
        d = D[:, k] * h
        yp, wp, cp = _step1(p, x + d[:6], w + d[6:])
        ym, wm, cm = _step1(p, x - d[:6], w - d[6:])
        assume(cp == cm == c0)
        fd[:3, k] = (yp - ym) / (2 * h)
        fd[3:, k] = (wp - wm) / (2 * h)
    nd = D.shape[1]
    du0 = np.ascontiguousarray(D[None, 0:2]).reshape(1, 2, nd)
    dg0 = np.ascontiguousarray(D[None, 2])
    du = np.ascontiguousarray(D[None, 3:5]).reshape(1, 2, nd)
    dg = np.ascontiguousarray(D[None, 5])
    dw = np.ascontiguousarray(D[None, 6:8]).reshape(1, 2, nd)
    T, N, code, w_new = np.empty((1, 2)), np.empty(1), np.empty(1, dtype=np.int8), np.empty((1, 2))
    dT, dN, dwn = np.empty((1, 2, nd)), np.empty((1, nd)), np.empty((1, 2, nd))
    interface_step_jvp(p, x[None, 0:2], du0, x[2:3], dg0, x[None, 3:5], du, x[5:6], dg, w[None], dw, w_new, dwn,
                       T, dT, N, dN, code)
    assert code[0] == c0 and np.array_equal(np.array([T[0, 0], T[0, 1], N[0]]), y0)
    assert np.array_equal(w_new[0], wn0)
    an = np.concatenate([dT[0], dN, dwn[0]], axis=0)
    scale = np.abs(fd).max(axis=0) + kt * 1e-3
    np.testing.assert_allclose(an[:3], fd[:3], rtol=0, atol=2e-5 * scale.max())
    np.testing.assert_allclose(an[3:], fd[3:], rtol=0, atol=2e-5 * (np.abs(fd[3:]).max() + 1e-3))
    # the tangent: the columns of the end point with the start and the slider fixed
    J = np.empty((1, 3, 3))
    interface_step_tangent(p, x[None, 0:2], x[2:3], x[None, 3:5], x[5:6], w[None], w_new, T, N, code, J)
    assert code[0] == c0 and np.array_equal(np.array([T[0, 0], T[0, 1], N[0]]), y0)
    np.testing.assert_allclose(J[0], an[:3, 3:6], rtol=1e-13, atol=1e-13 * kt)


def _march_jvp(it, U, dU, G, dG):
    """March with derivatives along the directions of dU (nt, np, 2, nd), dG (nt, np, nd)."""
    p = it.params
    nt, npairs = G.shape
    nd = dG.shape[2]
    w = np.ascontiguousarray(U[0].copy())
    dw = np.ascontiguousarray(dU[0].copy())
    T = np.empty((nt, npairs, 2))
    N = np.empty((nt, npairs))
    code = np.empty((nt, npairs), dtype=np.int8)
    dT = np.empty((nt, npairs, 2, nd))
    dN = np.empty((nt, npairs, nd))
    for j in range(nt):
        w_new = np.empty_like(w)
        dw_new = np.empty_like(dw)
        k = max(j - 1, 0)  # the step's start point: the previous sample
        interface_step_jvp(p, U[k], dU[k], G[k], dG[k], U[j], dU[j], G[j], dG[j], w, dw, w_new, dw_new,
                           T[j], dT[j], N[j], dN[j], code[j])
        w, dw = w_new, dw_new
    return T, N, code, dT, dN


def _history(a1, a2, g0, g1, nt=240):
    s = np.linspace(0.0, 2.0, nt)
    U = np.zeros((nt, 1, 2))
    U[:, 0, 0] = a1 * np.sin(2 * np.pi * s)
    U[:, 0, 1] = a2 * np.sin(4 * np.pi * s + 0.3)
    G = (g0 + g1 * np.sin(2 * np.pi * s + 1.0))[:, None]
    return U, G


@settings(max_examples=25, deadline=None)
@given(a1=st.floats(2e-4, 3e-3), a2=st.floats(0.0, 3e-3), g1=st.floats(0.0, 2.5e-3))
def test_jvp_through_a_history_of_stick_slip_separation_and_recontact(a1, a2, g1):
    """Derivatives with respect to the amplitudes and the normal offset, carried through the sliders
    of a whole march (stick, slip, opening and re-contact), against central differences."""
    it = _pair()
    g0 = 2e-4

    def run(x):
        U, G = _history(x[0], x[1], x[2], g1)
        shapes, _ = _history(1.0, 1.0, 0.0, 0.0)  # d u1 / d a1 and d u2 / d a2
        dU = np.zeros(U.shape + (3,))
        dU[..., 0, 0] = shapes[..., 0]
        dU[..., 1, 1] = shapes[..., 1]
        dG = np.zeros(G.shape + (3,))
        dG[..., 2] = 1.0
        return _march_jvp(it, U, dU, G, dG)

    x0 = np.array([a1, a2 if a2 > 0 else 0.0, g0])
    T, N, code, dT, dN = run(x0)
    h = 1e-7 * np.array([a1, max(a2, 1e-3), 1e-3])
    for k in range(3):
        e = np.zeros(3)
        e[k] = h[k]
        Tp, Np, cp, _, _ = run(x0 + e)
        Tm, Nm, cm, _, _ = run(x0 - e)
        assume(np.array_equal(cp, code) and np.array_equal(cm, code))
        scale = float(np.max(np.abs(dT[..., k]))) + 1.0
        np.testing.assert_allclose(dT[..., k], (Tp - Tm) / (2 * h[k]), rtol=0, atol=1e-5 * scale)
        np.testing.assert_allclose(dN[..., k], (Np - Nm) / (2 * h[k]), rtol=0, atol=1e-5 * (np.max(np.abs(dN)) + 1))


def test_compiled_marches_equal_the_step_by_step_march():
    """interface_march and interface_march_jvp: the same bits as the kernels called sample by sample,
    derivatives of the starting sliders carried through."""
    it = Interface(kt=[1e3, 2e3], kn=[2e3, 1e3], mu=[0.4, 0.2], preload=[2.0, 1.0],
                   pairs=[[0, 1, 2, -1, -1, -1], [3, 4, 5, -1, -1, -1]])
    U1, G1 = _history(2e-3, 1e-3, 2e-4, 2e-3)
    U = np.ascontiguousarray(np.concatenate([U1, 0.5 * U1[:, :, ::-1]], axis=1))
    G = np.ascontiguousarray(np.concatenate([G1, -0.7 * G1], axis=1))
    rng = np.random.default_rng(2)
    dU = rng.normal(size=U.shape + (4,))
    dG = rng.normal(size=G.shape + (4,))
    dU[0] = 0.0
    T, N, code, dT, dN = _march_jvp(it, U, dU, G, dG)
    nt, npairs = G.shape
    T2, N2, c2 = np.empty_like(T), np.empty_like(N), np.empty_like(code)
    wf = np.empty((npairs, 2))
    interface_march(it.params, np.ascontiguousarray(U[0]), U, G, T2, N2, c2, wf)
    assert np.array_equal(T, T2) and np.array_equal(N, N2) and np.array_equal(code, c2)
    T3, N3, c3 = np.empty_like(T), np.empty_like(N), np.empty_like(code)
    dT3, dN3 = np.empty_like(dT), np.empty_like(dN)
    wf3, dwf3 = np.empty((npairs, 2)), np.empty((npairs, 2, 4))
    interface_march_jvp(it.params, np.ascontiguousarray(U[0]), np.zeros((npairs, 2, 4)), U, dU, G, dG,
                        T3, dT3, N3, dN3, c3, wf3, dwf3)
    assert np.array_equal(T, T3) and np.array_equal(code, c3) and np.array_equal(wf, wf3)
    assert np.array_equal(dT, dT3) and np.array_equal(dN, dN3)
    # a derivative of the starting sliders reaches the forces until the pair slips or opens
    dw0 = np.zeros((npairs, 2, 1))
    dw0[0, 0, 0] = 1.0
    dT4 = np.empty((nt, npairs, 2, 1))
    interface_march_jvp(it.params, np.ascontiguousarray(U[0]), dw0, U, np.zeros((nt, npairs, 2, 1)), G,
                        np.zeros((nt, npairs, 1)), T3, dT4, N3, np.empty((nt, npairs, 1)), c3, wf3,
                        np.empty((npairs, 2, 1)))
    first_change = int(np.argmax(code[:, 0] != STICK_SLIP))
    assert first_change > 0
    np.testing.assert_array_equal(dT4[:first_change, 0, 0, 0], -1e3)


def test_jvp_history_covers_every_state():
    """The history family above meets every motion state and re-contact (so the property is not vacuous)."""
    it = _pair()
    U, G = _history(2e-3, 1e-3, 2e-4, 2e-3)
    T, N, code, _, _ = _march_jvp(it, U, np.zeros(U.shape + (1,)), G, np.zeros(G.shape + (1,)))
    c = code[:, 0]
    assert {STICK_SLIP, MACROSLIP, SEPARATION} <= set(c.tolist())
    assert np.any((c[:-1] == SEPARATION) & (c[1:] != SEPARATION))  # re-contact


# --- parameters ----------------------------------------------------------------------------


@pytest.mark.parametrize("kw, msg", [
    (dict(kt=-1.0), "kt must be > 0"),
    (dict(kn=0.0), "kn must be > 0"),
    (dict(mu=-0.1), "mu must be >= 0"),
    (dict(preload=float("nan")), "preload must be finite"),
    (dict(kt=[1.0, 2.0, 3.0]), r"kt must be a number or a list of 2 numbers"),
    (dict(preload=[1.0, -2.0]), r"preload\[1\] must be >= 0"),
    (dict(pairs=[[0, 1, 2]]), "pairs must be a table of at least one row of 6 DOF indices"),
    (dict(pairs=[[0, 1, 2, -1, -1, -2], [3, 4, 5, -1, -1, -1]]), r"pairs\[0, 5\] \(b_n\) must be an integer >= -1"),
    (dict(pairs=[[0, 1, 2, -1, -1, -1], [3, 4, 3, -1, -1, -1]]), r"pairs\[1\] names a DOF twice"),
    (dict(pairs=[[0, 1, 2, -1, -1, -1], [-1] * 6]), r"pairs\[1\] names no DOF"),
    (dict(pairs=[[0.5, 1, 2, -1, -1, -1], [3, 4, 5, -1, -1, -1]]), r"pairs\[0, 0\] \(a_t1\)"),
])
def test_bad_parameters_name_the_parameter(kw, msg):
    args = dict(kt=1e3, kn=1e3, mu=0.3, preload=1.0, pairs=[[0, 1, 2, -1, -1, -1], [3, 4, 5, -1, -1, -1]])
    args.update(kw)
    with pytest.raises(ValueError, match=msg):
        Interface(**args)


def test_dofs_beyond_the_structure_are_refused():
    it = Interface(kt=1e3, kn=1e3, mu=0.3, preload=1.0, pairs=[[0, 1, 7, -1, -1, -1]])
    with pytest.raises(ValueError, match=r"pairs\[0, 2\] \(a_n\) must be in \[-1, 5\]"):
        it.check_ndof(6)


# --- the interface as seen by the structure --------------------------------------------------


def test_tangent_of_the_structure_forces_equals_finite_differences():
    """K = -df/dx of the generalised forces through stuck, slipping and open pairs, pairs sharing DOFs,
    fixed sides; all stuck: the springs kt, kt, kn; all open: nothing."""
    it = Interface(kt=[1e3, 2e3, 3e3], kn=[2e3, 1e3, 4e3], mu=[0.5, 0.2, 0.3], preload=[2.0, 1.0, 0.5],
                   pairs=[[0, 1, 2, 3, 4, 5], [3, -1, 5, 6, 7, -1], [-1, 7, 8, 0, -1, 2]])
    ndof = 9
    rng = np.random.default_rng(5)
    w = rng.normal(0.0, 1e-4, (3, 2))
    # stuck everywhere (tiny motion around the sliders), and all open (large opening)
    B = it.selection(ndof)
    x_stuck = np.linalg.lstsq(B[[0, 1, 3, 4, 6, 7]], w.ravel(), rcond=None)[0]
    f, K = it.tangent(x_stuck, w)
    springs = B.T @ np.diag(np.repeat(np.stack([it.kt, it.kt, it.kn], 1), 1, 0).ravel()) @ B
    np.testing.assert_allclose(K, springs, rtol=1e-14, atol=0)
    x_open = np.zeros(ndof)
    x_open[[5, 2, 8]] = -1.0, -2.0, -3.0  # g = -1 m for every pair
    assert np.all(it.step(*it.relative(x_open), w)[2] == SEPARATION)
    np.testing.assert_array_equal(it.tangent(x_open, w)[1], 0.0)
    # a mix, against central differences of the forces at fixed sliders
    seen = set()
    for seed in range(20):
        x = np.random.default_rng(seed).normal(0.0, 8e-4, ndof)
        f, K = it.tangent(x, w)
        codes = it.step(*it.relative(x), w)[2]
        h = 1e-10
        fd = np.empty((ndof, ndof))
        for d in range(ndof):
            e = np.zeros(ndof)
            e[d] = h
            cp, cm = it.step(*it.relative(x + e), w)[2], it.step(*it.relative(x - e), w)[2]
            if not (np.array_equal(cp, codes) and np.array_equal(cm, codes)):
                break
            fd[:, d] = -(it.tangent(x + e, w)[0] - it.tangent(x - e, w)[0]) / (2 * h)
        else:
            np.testing.assert_allclose(K, fd, rtol=1e-5, atol=1e-5 * np.abs(K).max())
            seen |= set(codes.tolist())
    assert seen == {STICK_SLIP, MACROSLIP, SEPARATION}

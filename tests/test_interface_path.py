"""The node pair integrated exactly along straight paths (docs/model.md section 10): the closed form
of the plain-Python reference against the radial return in many sub-steps along the same path, the
kernels against the reference, the semigroup property of the exact update, radial return as its
special case without turning, and the dissipation of a turning slip in closed form."""

import math

import numpy as np
from hypothesis import assume, event, example, given, settings
from hypothesis import strategies as st

from reference_interface import OPEN, SLIP, STICK, path_step, radial_step, substep

from jointdyn.interfaces import interface_step
from jointdyn.laws import MACROSLIP, SEPARATION, STICK_SLIP

finite = dict(allow_nan=False, allow_infinity=False)
KT, KN, MU, P = 1e3, 2e3, 0.4, 2.0  # slip force 0.8 N, slip displacement 0.8 mm, opens at g = -1 mm
PARAMS = np.array([[KT, KN, MU, P]])
CODES = {STICK: STICK_SLIP, SLIP: MACROSLIP, OPEN: SEPARATION}


def _kernel(params, start, end, w):
    """interface_step of one pair: (T1, T2, N, code, w_new)."""
    T, N = np.empty((1, 2)), np.empty(1)
    code, w_new = np.empty(1, dtype=np.int8), np.empty((1, 2))
    interface_step(params, np.array([start[:2]]), np.array([start[2]]), np.array([end[:2]]), np.array([end[2]]),
                   np.array([w], dtype=float), w_new, T, N, code)
    return T[0, 0], T[0, 1], N[0], int(code[0]), (w_new[0, 0], w_new[0, 1])


def _step_case():
    """A start (u1, u2, g), an end, and the committed force at the start as a fraction rho of the slip
    force (rho = 1: a pair that was slipping; above 1: a start outside the disc) at an angle alpha."""
    mm = st.floats(-2e-3, 2e-3, **finite)
    g = st.floats(-1.5e-3, 1.5e-3, **finite)
    return st.tuples(mm, mm, g, mm, mm, g, st.sampled_from([0.0, 0.3, 0.9, 1.0, 1.0, 1.5]),
                     st.floats(0.0, 2 * math.pi, **finite))


def _slider(start, rho, alpha):
    f = rho * MU * max(P + KN * start[2], 0.0)
    return start[0] - f * math.cos(alpha) / KT, start[1] - f * math.sin(alpha) / KT


def _label(start, end, code):
    n0, n1 = P + KN * start[2], P + KN * end[2]
    return (["stuck", "slipping", "open"][code] + (", re-closing" if n0 <= 0.0 < n1 else "")
            + (", opening" if n1 <= 0.0 < n0 else "") + (", N rising" if n1 > n0 else ", N falling"))


@settings(max_examples=60, deadline=None)
@given(case=_step_case())
@example(case=(0.0, 0.0, -1.4e-3, 2e-3, 1e-3, 1e-3, 0.0, 0.0))  # re-closes, then slips at once
@example(case=(0.0, 0.0, -1.2e-3, 1e-4, 0.0, 0.5e-3, 0.0, 0.0))  # re-closes and sticks
@example(case=(0.0, 0.0, 0.0, 1.5e-3, 0.5e-3, 0.0, 0.9, 2.0))  # sticks, leaves the disc, turns
@example(case=(0.0, 0.0, 0.0, 1e-3, 0.0, -1.2e-3, 0.5, 1.0))  # opens inside the step
@example(case=(0.0, 0.0, 0.0, 1e-3, 1e-3, 1e-3, 1.0, 1.0))  # slipping, turning, N rising
@example(case=(0.0, 0.0, 0.0, 1e-3, 1e-3, -0.8e-3, 1.0, 1.0))  # slipping, turning, N falling
@example(case=(0.0, 0.0, 0.0, 1e-4, 0.0, -0.8e-3, 1.0, 2.5))  # stuck, N falls and makes it slip
def test_closed_form_equals_the_radial_return_in_many_substeps(case):
    """The reference's closed form (exit instant from the quadratic, slip angle from tan(phi / 2))
    against the radial return along the same straight path in 1000 and 2000 sub-steps, extrapolated
    (first order in the sub-step): stick, slip, leaving the disc inside the step, opening,
    re-closing, N rising and falling."""
    a1, a2, g0, u1, u2, g, rho, alpha = case
    start, end = (a1, a2, g0), (u1, u2, g)
    w = _slider(start, rho, alpha)
    T1, T2, N, code, _ = path_step(KT, KN, MU, P, start, end, w)
    event(_label(start, end, code))
    r1 = substep(KT, KN, MU, P, start, end, w, 1000)
    r2 = substep(KT, KN, MU, P, start, end, w, 2000)
    assert abs(r2[2] - N) <= 1e-12 * P  # N at the end (g interpolated to the end: rounding)
    tol = 1e-6 * MU * P
    for k, T in enumerate((T1, T2)):
        assert abs(2 * r2[k] - r1[k] - T) < tol
    assert math.hypot(T1, T2) <= MU * N * (1 + 1e-12)


@settings(max_examples=300, deadline=None)
@given(case=_step_case(), kt=st.floats(1e2, 1e4), kn=st.floats(1e2, 1e4), mu=st.sampled_from([0.0, 0.05, 0.4, 1.0]))
def test_kernels_equal_the_closed_form_reference(case, kt, kn, mu):
    """interface_step against the plain-Python closed form, single steps of every kind, to rounding."""
    a1, a2, g0, u1, u2, g, rho, alpha = case
    start, end = (a1, a2, g0), (u1, u2, g)
    w = _slider(start, rho, alpha)
    ref = path_step(kt, kn, mu, P, start, end, w)
    out = _kernel(np.array([[kt, kn, mu, P]]), start, end, w)
    event(_label(start, end, ref[3]))
    f = MU * P * 1e-12
    assert abs(out[0] - ref[0]) <= f and abs(out[1] - ref[1]) <= f
    tie = abs(math.hypot(ref[0], ref[1]) - mu * ref[2]) <= 1e-12 * mu * ref[2]  # the state at a tie is rounding
    assert out[2] == ref[2] and (out[3] == CODES[ref[3]] or tie)
    assert abs(out[4][0] - ref[4][0]) <= f / kt * 10 and abs(out[4][1] - ref[4][1]) <= f / kt * 10


@settings(max_examples=60, deadline=None)
@given(case=_step_case(), m=st.integers(2, 9))
def test_the_exact_update_is_a_semigroup(case, m):
    """Stepping along a straight path in one step or in m steps through points on it gives the same
    force and slider (the radial return does not: it is first order when the slip turns)."""
    a1, a2, g0, u1, u2, g, rho, alpha = case
    start, end = np.array([a1, a2, g0]), np.array([u1, u2, g])
    w = _slider(start, min(rho, 1.0), alpha)
    one = _kernel(PARAMS, start, end, w)
    wk, pk = w, start
    for k in range(1, m + 1):
        q = start + (end - start) * k / m
        many = _kernel(PARAMS, pk, q, wk)
        wk, pk = many[4], q
    event(_label(tuple(start), tuple(end), [STICK_SLIP, MACROSLIP, SEPARATION].index(one[3])))
    np.testing.assert_allclose(many[:3], one[:3], rtol=0, atol=1e-12 * MU * P)
    np.testing.assert_allclose(many[4], one[4], rtol=0, atol=1e-12 * MU * P / KT)


@settings(max_examples=60, deadline=None)
@given(theta=st.floats(0.0, 2 * math.pi), x0=st.floats(-2e-3, 2e-3), x1=st.floats(-2e-3, 2e-3),
       g0=st.floats(-1.5e-3, 1.5e-3), g1=st.floats(-1.5e-3, 1.5e-3), rho=st.floats(-1.5, 1.5))
# a step whose squared length is subnormal, from a force on the circle (found by a random draw: the
# path length taken as sqrt(v1^2 + v2^2) lost seven digits there and the force left the disc by 1e-7)
@example(theta=0.0, x0=0.0, x1=2.0581115907980989e-159, g0=0.0, g1=0.0, rho=1.0)
def test_without_turning_the_exact_update_is_the_radial_return(theta, x0, x1, g0, g1, rho):
    """Motion along a line at any angle with the committed force on the same line (1-D motion): the
    exact update is the radial return of the end point, to rounding, whatever the normal load does."""
    c, s = math.cos(theta), math.sin(theta)
    start, end = (x0 * c, x0 * s, g0), (x1 * c, x1 * s, g1)
    f = rho * MU * max(P + KN * g0, 0.0) / KT
    w = (start[0] - f * c, start[1] - f * s)
    ex = _kernel(PARAMS, start, end, w)
    if P + KN * g0 > 0.0 and abs(rho) > 1.0:  # a start outside the disc: slid back onto it first
        w = (start[0] - math.copysign(MU * (P + KN * g0) / KT, rho) * c,
             start[1] - math.copysign(MU * (P + KN * g0) / KT, rho) * s)
    if P + KN * g0 <= 0.0:  # open at the start: no memory
        w = start[:2]
    n0, n1 = P + KN * g0, P + KN * g1
    assume(not (n0 <= 0.0 < n1))  # re-closing inside the step: the radial return re-closes at the sample
    rr = radial_step(KT, KN, MU, P, end[0], end[1], g1, w)
    np.testing.assert_allclose(ex[:3], rr[:3], rtol=0, atol=1e-12 * MU * P)


@settings(max_examples=60, deadline=None)
@given(alpha=st.floats(-1.55, 1.55), s=st.floats(1e-5, 5e-3), theta=st.floats(0.0, 2 * math.pi),
       g=st.floats(-0.9e-3, 1.5e-3))
def test_dissipation_of_a_turning_slip_in_closed_form(alpha, s, theta, g):
    """At constant load a slipping pair (force on the circle at the angle alpha from the motion v)
    dissipates along the step D = mu N (|v| + (mu N / kt) ln((1 + t1^2) / (1 + t0^2))), t = tan(phi / 2)
    (from cos phi = 1 + (1 / k) d ln(1 + t^2) / dtau, k = kt |v| / (mu N)); its elastic energy does not
    change, so the work of T along the path (Gauss-Legendre over points of the path, each an exact
    step from the start) equals D."""
    N = P + KN * g
    v = s * np.array([math.cos(theta), math.sin(theta)])
    e0 = np.array([math.cos(theta + alpha), math.sin(theta + alpha)])
    start = (0.0, 0.0, g)
    w = tuple(-MU * N * e0 / KT)
    T_end = _kernel(PARAMS, start, (v[0], v[1], g), w)
    phi1 = math.atan2(v[0] * T_end[1] - v[1] * T_end[0], v @ T_end[:2])
    D = MU * N * (s + MU * N / KT * math.log((1 + math.tan(phi1 / 2) ** 2) / (1 + math.tan(alpha / 2) ** 2)))
    x, wq = np.polynomial.legendre.leggauss(40)
    tau = 0.5 * (x + 1.0)
    W = 0.0
    for tk, wk in zip(tau, wq):
        Tk = _kernel(PARAMS, start, (tk * v[0], tk * v[1], g), w)
        W += 0.5 * wk * (Tk[0] * v[0] + Tk[1] * v[1])
    assert D > 0.0
    np.testing.assert_allclose(W, D, rtol=1e-10, atol=1e-14 * MU * P * s)


def test_structure_tangent_from_a_start_point_equals_finite_differences():
    """Interface.tangent(x, w, x0): K = -df/dx with the step's start x0 and the sliders fixed, through
    stuck, slipping (turning) and open pairs and a pair that re-closes inside the step, against
    central differences of Interface.step from the same start."""
    from jointdyn.interfaces import Interface

    it = Interface(kt=[1e3, 2e3, 3e3, 1e3], kn=[2e3, 1e3, 4e3, 2e3], mu=[0.5, 0.2, 0.3, 0.4],
                   preload=[2.0, 1.0, 0.5, 1.0],
                   pairs=[[0, 1, 2, 3, 4, 5], [3, -1, 5, 6, 7, -1], [-1, 7, 8, 0, -1, 2], [9, 10, 11, -1, -1, -1]])
    ndof = 12
    seen = set()
    for seed in range(30):
        rng = np.random.default_rng(seed)
        x0 = rng.normal(0.0, 4e-4, ndof)
        x = x0 + rng.normal(0.0, 8e-4, ndof)
        x0[11], x[11] = -1e-3, 1e-3  # pair 3 open at the start, closed at the end
        u0, g0 = it.relative(x0)
        w = u0 + rng.normal(0.0, 2e-4, (4, 2))
        f, K = it.tangent(x, w, x0)
        codes = it.step(*it.relative(x), w, u0, g0)[2]
        h = 1e-10
        fd = np.empty((ndof, ndof))
        for d in range(ndof):
            e = np.zeros(ndof)
            e[d] = h
            out = [it.step(*it.relative(x + sg * e), w, u0, g0) for sg in (1.0, -1.0)]
            if not all(np.array_equal(o[2], codes) for o in out):
                break
            fp, fm = (it.forces(o[0], o[1], ndof) for o in out)
            fd[:, d] = -(fp - fm) / (2 * h)
        else:
            np.testing.assert_allclose(K, fd, rtol=1e-5, atol=1e-5 * np.abs(K).max())
            np.testing.assert_allclose(f, it.forces(*it.step(*it.relative(x), w, u0, g0)[:2], ndof), rtol=0, atol=0)
            seen |= set(codes.tolist())
    assert seen == {STICK_SLIP, MACROSLIP, SEPARATION}

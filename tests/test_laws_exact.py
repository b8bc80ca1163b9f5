"""The exact Iwan law (``iwan``, ``jointdyn.laws.exact``) against its oracles.

* the plain-Python reference ``tests/reference_exact.py`` (same algorithm,
  lists of pieces): same force, tangent and motion state to rounding, with
  and without merges (small capacities);
* the full-memory closed form at constant normal load (both exact there):
  nested, growing, decaying and random histories, several load ratios;
* the discrete model under varying load with separation: its error against
  the exact law shrinks like 1/n^2 (n = 500 ... 4000);
* ``step_jvp`` against central finite differences of ``step`` marches,
  with and without merges (the derivative of a merge is exact too);
* the describing-function energy per cycle (docs/model.md section 2) at
  constant load, below and beyond macroslip;
* hypothesis properties: |T| <= alpha fy, T = 0 and SEPARATION where
  N <= 0, 0 <= kT <= kt, at most ``capacity`` pieces, no energy created
  over a closed cycle, committed state never written, a march in two
  pieces equals one march.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import law_histories as H
import tolerances as C
from reference import march_ref
from reference_exact import ExactIwanRef

from jointdyn import DiscreteIwan, Iwan, IwanClosedForm, make_law, march
from jointdyn._jit import specialize
from jointdyn.laws.exact import SNAP, piece_count

KT, MU, NREF = 1e5, 0.1, 100.0
FY = MU * NREF
XS = 2.0 * FY / KT


def _pieces(law, x, N):
    """Piece count after every sample of a march (from the virgin state)."""
    p = law.params
    s = law.initial_state(x[0], N[0])
    s_new = np.empty_like(s)
    out = np.empty(x.size, dtype=int)
    for i, (xi, ni) in enumerate(zip(x, N)):
        law.step(p, s, s_new, xi, ni)
        s, s_new = s_new, s
        out[i] = piece_count(s)
    return out


# --- reference ------------------------------------------------------------------
def _reference_cases():
    out = []
    for seed in range(4):
        rng = np.random.default_rng(100 + seed)
        xs = [
            H.random_walk(rng, 700, 0.15 * XS),
            H.random_reversals(rng, 40, 2.0 * XS)[:700],
            H.nested_then_growing(12, 1.5 * XS, steps=7, shrink=0.8),
        ]
        for k, x in enumerate(xs):
            eta = (0.0, 0.6, 1.4)[(seed + k) % 3]  # constant, varying, separating
            out.append(pytest.param(x, H.normal_history(rng, x.size, NREF, eta), id=f"seed{seed}-shape{k}-eta{eta}"))
    t = np.linspace(0.0, 6.0, 6 * 300 + 1)  # out of phase: many pieces, merges at small capacities
    out.append(pytest.param(1.2 * XS * np.sin(2 * np.pi * t), NREF * (1 + 0.8 * np.cos(2 * np.pi * t)), id="quadrature"))
    return out


@pytest.mark.parametrize("capacity", [3, 5, 16, 200])
@pytest.mark.parametrize("x,N", _reference_cases())
def test_kernel_matches_reference(capacity, x, N):
    law = Iwan(kt=KT, mu=MU, n_ref=NREF, capacity=capacity)
    T, kT, code, _ = march(law, x, N)
    Tr, kTr, cr = march_ref(ExactIwanRef(KT, MU, NREF, capacity, x[0], N[0]), x, N)
    np.testing.assert_allclose(T, Tr, rtol=0, atol=C.TEST_EXACT_REFERENCE_ATOL_FY * FY)
    np.testing.assert_allclose(kT, kTr, rtol=0, atol=C.TEST_EXACT_REFERENCE_ATOL_KT * KT)
    np.testing.assert_array_equal(code, np.asarray(cr, dtype=np.int8))


def test_reference_cases_merge_and_separate():
    """Guard of the test above: its cases reach all three motion states, and
    the out-of-phase case needs more pieces than the small capacities (so
    merges are compared too)."""
    seen = set()
    for p in _reference_cases():
        x, N = p.values
        seen.update(np.unique(march(Iwan(kt=KT, mu=MU, n_ref=NREF), x, N)[2]).tolist())
    assert seen == {0, 1, 2}
    x, N = _reference_cases()[-1].values
    assert _pieces(Iwan(kt=KT, mu=MU, n_ref=NREF, capacity=200), x, N).max() > 16


def test_zero_friction():
    """mu = 0: no force, MACROSLIP in contact, SEPARATION where N <= 0."""
    rng = np.random.default_rng(7)
    x = H.random_walk(rng, 200, 1e-5)
    N = H.normal_history(rng, 200, NREF, 1.5)
    T, kT, code, _ = march(Iwan(kt=KT, mu=0.0, n_ref=NREF), x, N)
    assert np.all(T == 0.0) and np.all(kT == 0.0)
    np.testing.assert_array_equal(code, np.where(N <= 0.0, 2, 1))


# --- closed form at constant load ----------------------------------------------------
def _constant_load_histories():
    out = []
    for seed in range(3):
        rng = np.random.default_rng(seed)
        out.append(pytest.param(H.random_walk(rng, 3000, 0.05 * XS), id=f"walk{seed}"))
        out.append(pytest.param(H.random_reversals(rng, 60, 2.5 * XS, steps=(5, 80)), id=f"reversals{seed}"))
    out.append(pytest.param(H.nested_then_growing(30, 1.8 * XS, steps=40, shrink=0.9), id="deep-nest-30"))
    out.append(pytest.param(H.nested_then_growing(12, 0.9 * XS, steps=40, shrink=0.8), id="nest-microslip"))
    out.append(pytest.param(H.growing_sine(3.0 * XS, 8, 400), id="growing"))
    out.append(pytest.param(H.decaying_sine(1.5 * XS, 8, 400, offset=0.3 * XS), id="decaying-offset"))
    return out


@pytest.mark.parametrize("alpha", [1.0, 0.4, 1.7])
@pytest.mark.parametrize("x", _constant_load_histories())
def test_equals_full_memory_closed_form_at_constant_load(alpha, x):
    law = Iwan(kt=KT, mu=MU, n_ref=NREF)
    N = np.full(x.size, alpha * NREF)
    # no merge: the exact law is exact here
    assert _pieces(law, x, N).max() < law.capacity
    T, kT, code, _ = march(law, x, N)
    Tc, kTc, cc, _ = march(IwanClosedForm(kt=KT, mu=MU, n_ref=NREF, memory="full"), x, N)
    np.testing.assert_allclose(T, Tc, rtol=0, atol=C.TEST_EXACT_CLOSED_FORM_ATOL_FY * FY)
    np.testing.assert_allclose(kT, kTc, rtol=0, atol=C.TEST_EXACT_CLOSED_FORM_ATOL_FY * KT)


# --- discrete model converges to it ------------------------------------------------
@pytest.mark.parametrize("eta,delta", [(0.5, 0.7), (1.5, 0.7), (0.9, 1.6)])
def test_discrete_converges_like_one_over_n_squared(eta, delta):
    t = np.linspace(0.0, 3.0, 3001)
    x = XS * (0.8 * np.sin(2 * np.pi * t) + 0.5 * np.sin(7.3 * t) * np.exp(-0.3 * t) + 0.2 * np.sin(23 * t))
    N = NREF * (1.0 + eta * np.sin(2 * np.pi * 1.3 * t + delta))
    law = Iwan(kt=KT, mu=MU, n_ref=NREF, capacity=4000)
    assert _pieces(law, x, N).max() < law.capacity
    T = march(law, x, N)[0]
    err = [np.max(np.abs(march(DiscreteIwan(kt=KT, mu=MU, n_ref=NREF, n=n), x, N)[0] - T)) for n in (500, 1000, 2000, 4000)]
    assert err[-1] <= C.TEST_EXACT_DISCRETE_4000_FY * FY
    for e_coarse, e_fine in zip(err[:-1], err[1:]):
        assert e_fine * C.TEST_EXACT_DISCRETE_RATIO <= e_coarse


# --- forward mode ----------------------------------------------------------------------
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


def _march_jvp(law, x, dx, N, dN, s0, ds0):
    n, nd = dx.shape
    T, kT, dT = np.empty(n), np.empty(n), np.empty((n, nd))
    code = np.empty(n, dtype=np.int8)
    fn = specialize(_march_jvp_template, STEP_JVP=law.step_jvp)
    fn(law.params, s0, ds0, x, np.ascontiguousarray(dx), N, np.ascontiguousarray(dN), T, kT, code, dT)
    return T, kT, code, dT


def _jvp_case(seed, eta):
    rng = np.random.default_rng(seed)
    x = H.random_reversals(rng, 14, 2.5 * XS, steps=(6, 30))
    N = H.normal_history(rng, x.size, NREF, eta)
    n = x.size
    # directions: displacement only, load only, both, and the first sample
    # alone (through init_jvp: it moves the virgin state's x_prev)
    dx = np.zeros((n, 4))
    dN = np.zeros((n, 4))
    dx[1:, 0] = rng.normal(size=n - 1) * XS
    dN[1:, 1] = rng.normal(size=n - 1) * NREF
    dx[1:, 2] = rng.normal(size=n - 1) * XS
    dN[1:, 2] = rng.normal(size=n - 1) * NREF
    dx[0, 3] = XS
    return x, N, dx, dN


@pytest.mark.parametrize("seed,eta", [(1, 0.0), (2, 0.5), (3, 0.8), (4, 1.3), (5, 1.6)])
def test_jvp_equals_finite_differences(seed, eta):
    law = Iwan(kt=KT, mu=MU, n_ref=NREF, capacity=500)
    x, N, dx, dN = _jvp_case(seed, eta)
    assert _pieces(law, x, N).max() < law.capacity  # no merge: exact derivatives
    s0 = np.empty(law.state_size)
    ds0 = np.empty((law.state_size, dx.shape[1]))
    law.init_jvp(law.params, x[0], dx[0], N[0], dN[0], s0, ds0)
    np.testing.assert_array_equal(s0, law.initial_state(x[0], N[0]))
    T, kT, code, dT = _march_jvp(law, x, dx, N, dN, s0, ds0)
    T0, kT0, code0, _ = march(law, x, N)
    np.testing.assert_array_equal(T, T0)  # primal outputs of step_jvp are step's
    np.testing.assert_array_equal(kT, kT0)
    np.testing.assert_array_equal(code, code0)
    h = C.TEST_JVP_FD_STEP
    for j in range(dx.shape[1]):
        xp, xm = x + h * dx[:, j], x - h * dx[:, j]
        Np, Nm = N + h * dN[:, j], N - h * dN[:, j]
        np.testing.assert_array_equal(march(law, xp, Np)[2], code0)  # no state transition crossed
        np.testing.assert_array_equal(march(law, xm, Nm)[2], code0)
        fd = _richardson(law, x, N, dx[:, j], dN[:, j])
        scale = np.max(np.abs(fd))
        assert scale > 0.0
        np.testing.assert_allclose(dT[:, j], fd, rtol=0, atol=C.TEST_JVP_RTOL * scale)


def _richardson(law, x, N, dxj, dNj):
    """Central differences of marches at h and h / 2, Richardson-extrapolated
    (error O(h^4): the merged states are curved within h)."""
    d = []
    for h in (C.TEST_JVP_FD_STEP, 0.5 * C.TEST_JVP_FD_STEP):
        d.append((march(law, x + h * dxj, N + h * dNj)[0] - march(law, x - h * dxj, N - h * dNj)[0]) / (2 * h))
    return (4.0 * d[1] - d[0]) / 3.0


@pytest.mark.parametrize("capacity", [3, 8, 32])
def test_jvp_with_merges_is_exact(capacity):
    """Merges are differentiated exactly (breakpoints carry their
    derivatives): equal to finite differences on a history that needs
    several times the capacity, merging at most steps."""
    law = Iwan(kt=KT, mu=MU, n_ref=NREF, capacity=capacity)
    t = np.linspace(0.0, 2.0, 2 * 1000 + 1)
    x = 2.5 * XS * np.sin(2 * np.pi * t)
    N = NREF * (1 + 0.9 * np.cos(2 * np.pi * t))
    assert _pieces(Iwan(kt=KT, mu=MU, n_ref=NREF, capacity=1000), x, N).max() > 1.5 * 32
    dx = np.zeros((x.size, 2))
    dN = np.zeros_like(dx)
    dx[1:, 0] = XS * np.cos(2 * np.pi * t[1:])
    dN[1:, 1] = NREF * np.sin(4 * np.pi * t[1:])
    s0, ds0 = law.initial_state(x[0], N[0]), np.zeros((law.state_size, 2))
    dT = _march_jvp(law, x, dx, N, dN, s0, ds0)[3]
    for j in range(2):
        fd = _richardson(law, x, N, dx[:, j], dN[:, j])
        np.testing.assert_allclose(dT[:, j], fd, rtol=0, atol=C.TEST_JVP_RTOL * np.max(np.abs(fd)))


# --- describing-function energy ----------------------------------------------------------
def _energy_formula(A, alpha):
    fy = alpha * FY  # constant load: the model at fy' = alpha fy
    if A <= 2 * fy / KT:
        return KT**2 * A**3 / (3 * fy)
    return 4 * fy * A - 16 * fy**2 / (3 * KT)


@pytest.mark.parametrize("alpha", [1.0, 0.6])
@pytest.mark.parametrize("qa", [0.3, 1.0, 1.9, 2.0, 2.5, 8.0])
def test_energy_per_cycle(alpha, qa):
    """Loop area of the second cycle of x = A sin(2 pi t) (trapezoid rule)."""
    A = qa * FY / KT
    spc = 4000
    t = np.arange(2 * spc + 1) / spc
    x = A * np.sin(2 * np.pi * t)
    T = march(Iwan(kt=KT, mu=MU, n_ref=NREF), x, np.full(x.size, alpha * NREF))[0]
    E = float(np.sum(0.5 * (T[spc + 1 :] + T[spc:-1]) * np.diff(x[spc:])))
    assert E == pytest.approx(_energy_formula(A, alpha), rel=C.TEST_EXACT_ENERGY_RTOL)


# --- construction ---------------------------------------------------------------------------
def test_registered_and_validated():
    law = make_law("iwan", kt=KT, mu=MU, n_ref=NREF, capacity="12")
    assert isinstance(law, Iwan) and law.capacity == 12
    assert law.state_size == 2 + 3 * 3 * 12
    for bad in (2, 0, -1, 3.5, "x", float("nan")):
        with pytest.raises(ValueError, match="capacity"):
            Iwan(kt=KT, mu=MU, n_ref=NREF, capacity=bad)
    with pytest.raises(ValueError, match="kt"):
        make_law("iwan", kt=0.0, mu=MU, n_ref=NREF)


@pytest.mark.parametrize(
    "row,value,what",
    [
        (1, 0.0, "piece count"), (1, 33.0, "piece count"), (1, 1.5, "piece count"), (1, np.nan, "entries 0..1"),
        (0, np.inf, "entries 0..1"), (2, 1.5, "breakpoints"), (2, 0.0, "breakpoints"), (3, np.nan, "live pieces"),
    ],
)
def test_check_state(row, value, what):
    """A user-supplied state: x_prev and the piece count finite, the count an
    integer in [1, capacity], the live pieces finite, breakpoints strictly
    increasing from above 0 to u = 2; rows beyond the live pieces are free."""
    law = Iwan(kt=KT, mu=MU, n_ref=NREF)
    s = law.initial_state()
    s[row] = value
    with pytest.raises(ValueError, match=what):
        law.check_state(s)
    with pytest.raises(ValueError, match="state"):
        march(law, [0.0, 1e-4], [NREF, NREF], state=s)
    x = XS * np.sin(np.linspace(0.0, 7.0, 300))
    N = NREF * (1 + 0.8 * np.cos(np.linspace(0.0, 9.0, 300)))
    s = march(law, x, N)[3]
    m = piece_count(s)
    assert m > 2
    dirty = s.copy()
    dirty[2 + 3 * m :] = np.nan
    np.testing.assert_array_equal(law.check_state(dirty)[: 2 + 3 * m], s[: 2 + 3 * m])
    s[2 + 3 * (m - 1)] = 1.999  # the last live breakpoint is not u = 2
    with pytest.raises(ValueError, match="breakpoints"):
        law.check_state(s)
    s[2 + 3 * (m - 1)] = 2.0
    s[2 + 3] = s[2]  # two equal breakpoints
    with pytest.raises(ValueError, match="breakpoints"):
        law.check_state(s)


def test_scales_and_bounds():
    law = Iwan(kt=KT, mu=MU, n_ref=NREF)
    assert law.x_slip == 2.0 * FY / KT and law.passive
    assert law.max_force(2.0 * NREF) == pytest.approx(2.0 * FY) and law.max_force(-1.0) == 0.0
    # the virgin curve reaches macroslip at x_slip and not before
    x = np.linspace(0.0, 1.2 * law.x_slip, 1201)
    T, kT, code, _ = march(law, x, np.full(x.size, NREF))
    assert np.all(code[x < law.x_slip * (1 - 1e-9)] == 0) and np.all(code[x > law.x_slip * (1 + 1e-9)] == 1)
    assert T[-1] == pytest.approx(FY, rel=1e-12)


# --- hypothesis properties ---------------------------------------------------------------
SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
waypoints = st.lists(st.floats(-4.0, 4.0), min_size=2, max_size=14)
substeps = st.lists(st.integers(1, 25), min_size=15, max_size=15)
alphas = st.lists(st.floats(-0.6, 2.5).map(lambda a: 0.0 if abs(a) < 1e-9 else a), min_size=2, max_size=14)


@st.composite
def laws(draw, capacities=(3, 4, 8, 32)):
    kt = 10.0 ** draw(st.floats(3.0, 8.0))
    mu = draw(st.floats(0.01, 1.0))
    n_ref = 10.0 ** draw(st.floats(0.0, 4.0))
    return Iwan(kt=kt, mu=mu, n_ref=n_ref, capacity=draw(st.sampled_from(capacities)))


@st.composite
def histories(draw, law):
    """x through random waypoints (units of x_slip), N through random ratios."""
    pts = draw(waypoints)
    x0 = draw(st.floats(-2.0, 2.0))
    x = law.x_slip * (x0 + H.through(pts, draw(substeps)[: len(pts) - 1]))
    a = np.array(draw(alphas))
    if draw(st.booleans()):
        a = np.full(2, a[0])
    t = np.linspace(0.0, 1.0, x.size)
    return x, law.n_ref * np.interp(t, np.linspace(0.0, 1.0, a.size), a)


@SETTINGS
@given(data=st.data())
def test_force_bound_codes_tangent_capacity(data):
    law = data.draw(laws())
    x, N = data.draw(histories(law))
    T, kT, code, s = march(law, x, N)
    alpha = N / law.n_ref
    assert np.all(np.abs(T) <= np.maximum(alpha, 0.0) * law.fy * (1.0 + C.TEST_FORCE_BOUND_RTOL))
    assert np.all(T[N <= 0.0] == 0.0)
    assert np.array_equal(code == 2, N <= 0.0)
    assert np.all((kT >= 0.0) & (kT <= law.kt * (1.0 + 1e-12)))
    inside = N > 0.0
    assert np.array_equal((code == 1)[inside], (kT == 0.0)[inside])  # macroslip <=> nothing stuck
    assert _pieces(law, x, N).max() <= law.capacity


def _outside_limits(law, x, N):
    """Largest excess of |P(u)| over alpha u at the breakpoints of the
    committed states of a march (units of fy; 0 when every element is
    within its slip force), and the largest slope |b| of a piece."""
    p = law.params
    s = law.initial_state(x[0], N[0])
    s_new = np.empty_like(s)
    worst = 0.0
    slope = 0.0
    for xi, ni in zip(x, N):
        law.step(p, s, s_new, xi, ni)
        s, s_new = s_new, s
        alpha = ni / law.n_ref
        m = piece_count(s)
        hi = s[2 : 2 + 3 * m : 3]
        lo = np.concatenate(([0.0], hi[:-1]))
        a, b = s[3 : 3 + 3 * m : 3], s[4 : 4 + 3 * m : 3]
        for u in (lo, hi):
            worst = max(worst, float(np.max(np.abs(a + b * u) - max(alpha, 0.0) * u)))
        slope = max(slope, float(np.max(np.abs(b))))
    return worst, slope


@SETTINGS
@given(data=st.data())
def test_merged_states_stay_within_the_limits(data):
    """Merges keep every element within its slip force, also at small
    capacities where most steps merge: |P(u)| <= alpha u up to the dropped
    cuts (a cut within SNAP of an end of its piece leaves that end beyond the
    limit by at most |b -+ alpha| SNAP, b the piece's slope)."""
    law = data.draw(laws(capacities=(3, 4, 8)))
    x, N = data.draw(histories(law))
    alpha_max = max(1.0, float(np.max(np.abs(N))) / law.n_ref)
    worst, slope = _outside_limits(law, x, N)
    assert worst <= (slope + alpha_max) * SNAP + 1e-12 * alpha_max


def test_merges_within_the_limits_out_of_phase():
    """The out-of-phase loops of Fig 4 need several times the capacity: the
    merged states hold no element beyond its slip force (a merge that keeps
    the integral through a corner on a clip line would put one there)."""
    t = np.linspace(0.0, 4.0, 4 * 2000 + 1)
    x = 2.5 * XS * np.sin(2 * np.pi * t) * (1 + 0.3 * np.sin(0.7 * t))
    for eta in (0.3, 0.9, 1.2):
        N = NREF * (1 + eta * np.sin(2 * np.pi * t + np.pi / 2))
        for cap in (8, 32):
            law = Iwan(kt=KT, mu=MU, n_ref=NREF, capacity=cap)
            assert _pieces(law, x, N).max() == cap  # merges happen
            assert _outside_limits(law, x, N)[0] <= 1e-12


def _cycle_work(x, T):
    return float(np.sum(0.5 * (T[1:] + T[:-1]) * np.diff(x)))


@SETTINGS
@given(data=st.data())
def test_no_energy_created_over_a_closed_cycle(data):
    """From the virgin state (trapezoid integral >= 0) and after any history
    (>= -kt sum(dx^2)/8, the trapezoid error bound of elastic-plastic
    elements; see test_laws_properties), at a constant load."""
    law = data.draw(laws(capacities=(32,)))
    alpha = data.draw(st.floats(0.05, 2.5))
    state = None
    x_start = data.draw(st.floats(-2.0, 2.0)) * law.x_slip
    slack = 0.0
    if data.draw(st.booleans()):
        x_pre, N_pre = data.draw(histories(law))
        state = march(law, x_pre, N_pre)[3]
        x_start = x_pre[-1]
    pts = data.draw(waypoints)
    x = x_start + law.x_slip * H.through([0.0] + pts + [0.0], data.draw(substeps)[: len(pts) + 1])
    if state is not None:
        slack = law.kt * np.sum(np.diff(x) ** 2) / 8.0
    T = march(law, x, np.full(x.size, alpha * law.n_ref), state=state)[0]
    A = max(np.max(np.abs(x - x_start)), law.x_slip)
    assert _cycle_work(x, T) >= -slack - C.TEST_ENERGY_CREATION_TOL * law.fy * A


@settings(max_examples=30, deadline=None)
@given(data=st.data())
def test_kernels_leave_committed_state_untouched(data):
    law = data.draw(laws())
    x, N = data.draw(histories(law))
    x, N = x[:80], N[:80]
    p = law.params
    nd = data.draw(st.integers(1, 3))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    s = law.initial_state(x[0], N[0])
    ds = rng.normal(size=(law.state_size, nd))
    s_new, ds_new, dT = np.empty_like(s), np.empty_like(ds), np.empty(nd)
    for xi, ni in zip(x, N):
        keep, dkeep = s.copy(), ds.copy()
        out = law.step(p, s, s_new, xi, ni)
        assert s.tobytes() == keep.tobytes()
        out_j = law.step_jvp(p, s, ds, s_new, ds_new, xi, rng.normal(size=nd), ni, rng.normal(size=nd), dT)
        assert s.tobytes() == keep.tobytes() and ds.tobytes() == dkeep.tobytes()
        assert out == out_j
        s, s_new = s_new.copy(), s
        ds, ds_new = ds_new.copy(), ds


@settings(max_examples=30, deadline=None)
@given(data=st.data())
def test_march_in_pieces_equals_one_march(data):
    law = data.draw(laws())
    x, N = data.draw(histories(law))
    k = data.draw(st.integers(1, x.size - 1))
    T, kT, code, _ = march(law, x, N)
    T1, kT1, c1, s1 = march(law, x[:k], N[:k])
    T2, kT2, c2, _ = march(law, x[k:], N[k:], state=s1)
    assert np.array_equal(np.concatenate([T1, T2]), T)
    assert np.array_equal(np.concatenate([kT1, kT2]), kT)
    assert np.array_equal(np.concatenate([c1, c2]), code)


@settings(max_examples=30, deadline=None)
@given(data=st.data())
def test_rows_beyond_the_live_pieces_stay_zero(data):
    """From the virgin state (zero buffers), every state written by ``step``
    and ``step_jvp`` (merges and separation included) holds zeros beyond its
    live pieces, values and derivatives: two states with the same pieces are
    equal entry by entry (the harmonic-balance AFT stops marching periods on
    that comparison)."""
    law = data.draw(laws())
    x, N = data.draw(histories(law))
    p = law.params
    nd = 2
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    s, ds = np.empty(law.state_size), np.empty((law.state_size, nd))
    law.init_jvp(p, x[0], rng.normal(size=nd), N[0], rng.normal(size=nd), s, ds)
    s_new, ds_new, dT = np.zeros_like(s), np.zeros_like(ds), np.empty(nd)
    v, v_new = s.copy(), np.zeros_like(s)
    for xi, ni in zip(x, N):
        law.step_jvp(p, s, ds, s_new, ds_new, xi, rng.normal(size=nd), ni, rng.normal(size=nd), dT)
        law.step(p, v, v_new, xi, ni)
        s, s_new, ds, ds_new, v, v_new = s_new, s, ds_new, ds, v_new, v
        live = 2 + 3 * piece_count(s)
        assert not s[live:].any() and not ds[live:].any() and not v[live:].any()
        assert v.tobytes() == s.tobytes()

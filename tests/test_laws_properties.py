"""Hypothesis property tests of every contact law over random parameters
and random displacement and normal-load histories.

Every registered law is drawn (``law_cases.laws``), with random law
parameters within their declared ranges.

* the step contract: |T| <= law.max_force(N) (+ rounding), T = 0, kT = 0
  and code SEPARATION exactly where N <= 0, valid codes, 0 <= kT <= kt,
  kT = 0 in macroslip;
* no energy is created over a closed displacement cycle at constant N:
  from the virgin state the trapezoidal cycle integral of T dx is >= 0 for any
  sampling (per element it bounds the stored energy, which is >= 0); from an
  arbitrary state (laws declared ``passive``) it is >= -kt sum(dx^2)/8, the
  largest trapezoid error of an
  elastic-plastic element per step (an exact cycle integral is >= 0 by
  Ilyushin's postulate);
* the kernels never write their committed state (``step`` and ``step_jvp``),
  and a march split in two pieces (state handed over) equals one march.
"""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import law_histories as H
from law_cases import laws

from jointdyn import DiscreteIwan, Iwan, IwanClosedForm, march
from jointdyn.laws import MACROSLIP, SEPARATION
import tolerances as C

SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


waypoints = st.lists(st.floats(-4.0, 4.0), min_size=2, max_size=14)
substeps = st.lists(st.integers(1, 25), min_size=13, max_size=13)
# subnormal loads are flushed to 0 (N = 0 exactly is kept: it separates);
# sums of subnormal slip limits round far beyond any relative tolerance
alphas = st.lists(st.floats(-0.6, 2.5).map(lambda a: 0.0 if abs(a) < 1e-9 else a), min_size=2, max_size=14)


def _path(points, steps, scale, x0=0.0):
    return x0 + scale * H.through(points, steps[: len(points) - 1])


@st.composite
def histories(draw, law):
    """x through random waypoints (units of x_slip), N through random alphas."""
    xs = law.x_slip
    x = _path(draw(waypoints), draw(substeps), xs, draw(st.floats(-2.0, 2.0)) * xs)
    a = np.array(draw(alphas))
    if draw(st.booleans()):
        a = np.full(2, a[0])  # constant normal load (maybe separated)
    t = np.linspace(0.0, 1.0, x.size)
    N = law.n_ref * np.interp(t, np.linspace(0.0, 1.0, a.size), a)
    return x, N


@SETTINGS
@given(data=st.data())
def test_force_bound_codes_tangent(data):
    """The step contract of jointdyn.laws._base for every registered law."""
    law = data.draw(laws())
    x, N = data.draw(histories(law))
    T, kT, code, _ = march(law, x, N)
    bound = law.max_force(N) * (1.0 + C.TEST_FORCE_BOUND_RTOL)
    assert np.all(np.abs(T) <= bound)
    assert np.all(T[N <= 0.0] == 0.0)
    assert np.all(kT[N <= 0.0] == 0.0)
    assert np.all(np.isin(code, [0, 1, 2]))
    assert np.array_equal(code == SEPARATION, N <= 0.0)
    assert np.all(kT >= 0.0)
    assert np.all(kT <= law.kt * (1.0 + 1e-12))
    assert np.all(kT[code == MACROSLIP] == 0.0)
    if isinstance(law, IwanClosedForm):  # the closed form's clip: exactly the slip force
        alpha = N / law.n_ref
        slip = code == MACROSLIP
        assert np.array_equal(np.abs(T[slip]), alpha[slip] * law.fy)
    elif isinstance(law, (DiscreteIwan, Iwan)):  # every element slipping <=> no stiffness left
        inside = N > 0.0
        assert np.array_equal((code == MACROSLIP)[inside], (kT == 0.0)[inside])


def _cycle_work(x, T):
    return float(np.sum(0.5 * (T[1:] + T[:-1]) * np.diff(x)))


@SETTINGS
@given(data=st.data())
def test_no_energy_created_from_virgin_state(data):
    law = data.draw(laws())
    alpha = data.draw(st.floats(0.05, 2.5))
    pts = data.draw(waypoints)
    x = _path([0.0] + pts + [0.0], data.draw(st.lists(st.integers(1, 25), min_size=15, max_size=15)), law.x_slip)
    x = x + data.draw(st.floats(-2.0, 2.0)) * law.x_slip
    T = march(law, x, np.full(x.size, alpha * law.n_ref))[0]
    A = np.max(np.abs(x - x[0]))
    assert _cycle_work(x, T) >= -C.TEST_ENERGY_CREATION_TOL * law.fy * max(A, law.x_slip)


@SETTINGS
@given(data=st.data())
def test_no_energy_created_after_any_history(data):
    law = data.draw(laws().filter(lambda law: law.passive))
    alpha = data.draw(st.floats(0.05, 2.5))
    x_pre, N_pre = data.draw(histories(law))
    state = march(law, x_pre, N_pre)[3]
    pts = data.draw(waypoints)
    x_end = x_pre[-1]
    steps = data.draw(st.lists(st.integers(1, 25), min_size=15, max_size=15))
    x = x_end + H.through([0.0] + pts + [0.0], steps[: len(pts) + 1]) * law.x_slip
    # the cycle starts where the pre-history ended, at the new constant load
    T = march(law, x, np.full(x.size, alpha * law.n_ref), state=state)[0]
    A = np.max(np.abs(x - x_end))
    slack = law.kt * np.sum(np.diff(x) ** 2) / 8.0
    assert _cycle_work(x, T) >= -slack - C.TEST_ENERGY_CREATION_TOL * law.fy * max(A, law.x_slip)


@settings(max_examples=30, deadline=None)
@given(data=st.data())
def test_kernels_leave_committed_state_untouched(data):
    law = data.draw(laws())
    x, N = data.draw(histories(law))
    x, N = x[:60], N[:60]
    p = law.params
    nd = data.draw(st.integers(1, 3))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    s = law.initial_state(x[0], N[0])
    ds = rng.normal(size=(law.state_size, nd))
    s_new = np.empty_like(s)
    ds_new = np.empty_like(ds)
    dT = np.empty(nd)
    for xi, ni in zip(x, N):
        keep, dkeep = s.copy(), ds.copy()
        out = law.step(p, s, s_new, xi, ni)
        # bytes: rows beyond the live part of a state may hold anything (NaN)
        assert s.tobytes() == keep.tobytes()
        out_j = law.step_jvp(p, s, ds, s_new, ds_new, xi, rng.normal(size=nd), ni, rng.normal(size=nd), dT)
        assert s.tobytes() == keep.tobytes() and ds.tobytes() == dkeep.tobytes()
        assert out == out_j  # primal outputs of step_jvp are step's, bit for bit
        s, s_new = s_new.copy(), s
        ds, ds_new = ds_new.copy(), ds


@settings(max_examples=30, deadline=None)
@given(data=st.data())
def test_march_in_pieces_equals_one_march(data):
    """Committing is complete: marching a history in two pieces, the second
    from the state the first returned, gives the same forces bit for bit."""
    law = data.draw(laws())
    x, N = data.draw(histories(law))
    k = data.draw(st.integers(1, x.size - 1))
    T, kT, code, s_end = march(law, x, N)
    T1, kT1, c1, s1 = march(law, x[:k], N[:k])
    T2, kT2, c2, s2 = march(law, x[k:], N[k:], state=s1)
    assert np.array_equal(np.concatenate([T1, T2]), T)
    assert np.array_equal(np.concatenate([kT1, kT2]), kT)
    assert np.array_equal(np.concatenate([c1, c2]), code)

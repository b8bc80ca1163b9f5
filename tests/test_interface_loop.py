"""Quasi-static loops of interfaces (docs/model.md section 10): the exact checks of the element
(circular orbit, isotropy, 1-D reduction to the discrete Iwan model) and its energy balance."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from jointdyn import DiscreteIwan, Jenkins, march, quasistatic
from jointdyn.drivers import interface_loop
from jointdyn.drivers.interface_loop import _insert_crossings
from jointdyn.interfaces import Interface, interface_march
from jointdyn.laws import MACROSLIP, SEPARATION, STICK_SLIP

KT, KN, MU, P = 1e3, 2e3, 0.4, 2.0


def _one_pair(**kw):
    args = dict(kt=KT, kn=KN, mu=MU, preload=P, pairs=[[0, 1, 2, -1, -1, -1]])
    args.update(kw)
    return Interface(**args)


def _circle(n, a, cycles=3):
    t = np.arange(cycles * n + 1) / n
    return t, a * np.cos(2 * np.pi * t), a * np.sin(2 * np.pi * t)


#: samples per cycle of the polygon that meets the circular orbit's energy to 1e-6 (measured error
#: -6.5e-7 at 4096, -2.6e-6 at 2048: second order, the inscribed polygon and the trapezoidal work)
CIRCLE_SAMPLES = 4096


def test_circular_orbit_dissipates_2_pi_mu_N_rho():
    """Steady circular orbit at constant load: E = 2 pi mu N sqrt(a^2 - (mu N / kt)^2). The element is
    exact along each side of the inscribed polygon, so the error is the polygon's and the trapezoidal
    work's, second order in the step: 1e-6 with CIRCLE_SAMPLES samples per cycle."""
    r = MU * P / KT
    a = 2.0 * r
    exact = 2 * math.pi * MU * P * math.sqrt(a * a - r * r)
    it = _one_pair()
    err = []
    for n in (CIRCLE_SAMPLES // 2, CIRCLE_SAMPLES):
        t, u1, u2 = _circle(n, a)
        res = interface_loop(it, t, u1, u2, np.zeros_like(t), period=1.0)
        assert res.n_cycles == 3 and res.status == "ok" and res.status.ok
        np.testing.assert_allclose(res.slip_fraction, [1.0])
        # |T| = mu N at every sample of the last cycle
        sl = res.t >= res.t_start_s
        np.testing.assert_allclose(np.hypot(*res.T[sl, 0].T), MU * P, rtol=1e-12)
        err.append(res.energy_J / exact - 1.0)
    assert abs(err[1]) < 1e-6
    assert 3.9 < err[0] / err[1] < 4.1  # second order


def test_circular_orbit_inside_the_friction_circle_sticks():
    a = 0.5 * MU * P / KT
    t, u1, u2 = _circle(256, a, cycles=2)
    res = interface_loop(_one_pair(), t, u1 - a, u2, np.zeros_like(t), period=1.0)
    np.testing.assert_allclose(res.stick_fraction, [1.0])
    assert abs(res.energy_J) < 1e-15


@settings(max_examples=20, deadline=None)
@given(theta=st.floats(0.0, 2 * math.pi), amp=st.floats(0.3, 5.0))
def test_a_line_orbit_at_any_angle_is_the_jenkins_loop(theta, amp):
    """Isotropy: u = x(t) (cos theta, sin theta) gives the Jenkins element's loop along the line and no
    force across it."""
    A = amp * MU * P / KT
    t = np.linspace(0.0, 2.0, 801)
    x = A * np.sin(2 * np.pi * t)
    res = interface_loop(_one_pair(), t, x * math.cos(theta), x * math.sin(theta), np.zeros_like(t), period=1.0)
    e = np.array([math.cos(theta), math.sin(theta)])
    along = res.T[:, 0] @ e
    across = res.T[:, 0] @ np.array([-e[1], e[0]])
    T_j, _, code_j, _ = march(Jenkins(kt=KT, mu=MU, n_ref=P), x, np.full_like(x, P))
    np.testing.assert_allclose(along, T_j, rtol=0, atol=1e-12 * MU * P)
    np.testing.assert_allclose(across, 0.0, atol=1e-12 * MU * P)
    fy = MU * P
    clear = np.abs(np.abs(T_j) - fy) > 1e-9 * fy  # the state at a tie with the slip limit is rounding
    np.testing.assert_array_equal(res.code[clear, 0], code_j[clear])
    ref = quasistatic(Jenkins(kt=KT, mu=MU, n_ref=P), t, x, np.full_like(x, P), period=1.0).last_cycle()
    np.testing.assert_allclose(res.energy_J, ref["energy_J"], rtol=1e-11, atol=1e-18)
    # and the closed form 4 fy (A - fy / kt), up to the trapezoidal rule over the kinks at slip onset
    closed = 4 * fy * (A - fy / KT) if A > fy / KT else 0.0
    np.testing.assert_allclose(res.energy_J, closed, rtol=2e-3, atol=1e-9 * fy * A)


def _patch(n):
    """n pairs in the proportions of the discrete Iwan model's slip forces: f_i = 2 (i + 1/2) / n^2."""
    f = 2.0 * (np.arange(n) + 0.5) / n**2
    assert abs(f.sum() - 1.0) < 1e-14
    it = Interface(kt=KT, kn=KN * f, mu=MU, preload=P * f,
                   pairs=[[3 * i, 3 * i + 1, 3 * i + 2, -1, -1, -1] for i in range(n)])
    return it, DiscreteIwan(kt=n * KT, mu=MU, n_ref=P, n=n)


def _reduction_history(nt=1201, g1=1.5 * P / KN):
    t = np.linspace(0.0, 3.0, nt)
    x = 4 * MU * P / KT * (np.sin(2 * np.pi * t) + 0.3 * np.sin(6 * np.pi * t + 0.4))
    g = g1 * np.sin(2 * np.pi * t + 1.1)
    return t, x, g


@pytest.mark.parametrize("n", [1, 7, 40])
def test_one_direction_patch_is_the_discrete_iwan_model(n):
    """P_i = P f_i, kn_i = kn f_i, common normal approach, motion along t1: the patch's force is the
    discrete Iwan model's with slip forces mu P f_i under N = max(0, P + kn g), sample by sample
    (kernels), separation and re-contact included. The opening and closing instants are samples (as
    the drivers insert them): the pair re-closes at its exact instant inside a step, the contact
    laws at the sample."""
    it, law = _patch(n)
    t, x, g = _reduction_history()
    t, (x, g), inserted = _insert_crossings(t, [x, g], (P + KN * g)[:, None])
    assert inserted.any()
    nt = t.size
    U = np.zeros((nt, n, 2))
    U[:, :, 0] = x[:, None]
    G = np.ascontiguousarray(np.repeat(g[:, None], n, axis=1))
    T = np.empty((nt, n, 2))
    N = np.empty((nt, n))
    code = np.empty((nt, n), dtype=np.int8)
    interface_march(it.params, np.ascontiguousarray(U[0]), U, G, T, N, code, np.empty((n, 2)))
    Nd = np.maximum(0.0, P + KN * g)
    Td, _, code_d, _ = march(law, x, Nd, state=law.initial_state(x[0], Nd[0]))
    np.testing.assert_allclose(T[:, :, 0].sum(axis=1), Td, rtol=0, atol=1e-12 * MU * P)
    np.testing.assert_allclose(T[:, :, 1], 0.0, atol=0)
    np.testing.assert_allclose(N.sum(axis=1), Nd, rtol=1e-13, atol=1e-13 * P)  # the crossings: N ~ 0
    assert np.any(code_d == SEPARATION) and np.any(code_d == MACROSLIP)
    np.testing.assert_array_equal(code[:, 0] == SEPARATION, code_d == SEPARATION)


def test_one_direction_patch_loop_equals_the_discrete_loop():
    """The same through the quasi-static drivers: crossings inserted at the same instants, the same
    energy per cycle and fractions of the patch as a whole."""
    n = 12
    it, law = _patch(n)
    t, x, g = _reduction_history()
    res = interface_loop(it, t, x, np.zeros_like(x), g, period=1.0)
    ref = quasistatic(law, t, x, P + KN * g, period=1.0)
    np.testing.assert_allclose(res.t, ref.t, rtol=1e-15, atol=0)
    np.testing.assert_allclose(res.T[:, :, 0].sum(axis=1), ref.T, rtol=0, atol=1e-12 * MU * P)
    last = ref.last_cycle()
    np.testing.assert_allclose(res.energy_J, last["energy_J"], rtol=1e-11)
    np.testing.assert_allclose(res.open_fraction, last["separation_fraction"], atol=1e-12)
    assert res.n_inserted == ref.n_inserted > 0


def test_energy_balance_of_a_pair():
    """Work done on each pair over every step = change of its elastic energy |T|^2 / (2 kt) + work of T
    on its slider (the sliders as the kernel commits them), to rounding; the slider's dissipation
    T_new . dw is never negative; over a closed cycle of g the normal spring returns its work."""
    rng = np.random.default_rng(3)
    it = Interface(kt=[KT, 2 * KT], kn=KN, mu=[MU, 0.1], preload=[P, 0.5], pairs=[[0, 1, 2, -1, -1, -1],
                                                                             [3, 4, 5, -1, -1, -1]])
    nt = 400
    U = np.ascontiguousarray(np.cumsum(rng.normal(0, MU * P / KT, (nt, 2, 2)), axis=0))
    G = np.ascontiguousarray(np.cumsum(rng.normal(0, 0.5 * P / KN, (nt, 2)), axis=0))
    w = U[0].copy()
    kt = it.params[:, 0]
    work = np.zeros(2)
    diss = np.zeros(2)
    T_old = np.zeros((2, 2))
    for j in range(nt):
        k = max(j - 1, 0)
        T, N, code, w_new = it.step(U[j], G[j], w, U[k], G[k])
        if j:
            du = U[j] - U[j - 1]
            work += np.sum(0.5 * (T + T_old) * du, axis=1)
            d = np.sum(0.5 * (T + T_old) * (w_new - w), axis=1)
            diss += d
            assert np.all(np.sum(T * (w_new - w), axis=1) >= -1e-15)
        T_old, w = T, w_new
    stored = np.sum(T_old**2, axis=1) / (2 * kt)
    np.testing.assert_allclose(work, stored + diss, rtol=1e-12, atol=1e-15)
    assert np.all(diss > 0.0)
    # normal work over closed cycles of g, with opening and closing inside steps
    t = np.linspace(0.0, 2.0, 37)
    g = 1.3 * P / KN * np.sin(2 * np.pi * t + 0.2)
    res = interface_loop(_one_pair(), t, np.zeros_like(t), np.zeros_like(t), g, period=1.0)
    assert res.n_inserted > 0
    sl = (res.t >= 1.0 - 1e-12)
    wn = np.sum(0.5 * (res.N[sl][1:, 0] + res.N[sl][:-1, 0]) * np.diff(res.g[sl][:, 0]))
    assert abs(wn) < 1e-12 * P * P / KN


def test_fractions_and_open_cycles():
    # N = P (1 - 4 tri(t)), tri a triangle 0 -> 1 -> 0 over the period (linear between samples):
    # open where tri > 1/4, i.e. for t in (1/8, 7/8), three quarters of the cycle
    t = np.linspace(0.0, 1.0, 11)
    tri = 1.0 - np.abs(2.0 * t - 1.0)
    g = -4.0 * P / KN * tri
    res = interface_loop(_one_pair(), t, 1e-5 * np.sin(2 * np.pi * t), np.zeros_like(t), g, period=1.0)
    assert res.n_inserted == 2
    np.testing.assert_allclose(res.open_fraction, [0.75], atol=1e-14)
    np.testing.assert_allclose(res.stick_fraction + res.slip_fraction + res.open_fraction, 1.0, atol=1e-14)
    res = interface_loop(_one_pair(), t, np.zeros_like(t), np.zeros_like(t), np.full_like(t, -P / KN * 2))
    assert res.status == "open" and res.status.ok
    assert res.energy_J == 0.0


def test_per_pair_columns_and_bad_input():
    it = Interface(kt=KT, kn=KN, mu=MU, preload=[P, 0.0], pairs=[[0, 1, 2, -1, -1, -1], [3, 4, 5, -1, -1, -1]])
    t = np.linspace(0.0, 1.0, 11)
    u = np.stack([np.sin(t), 2 * np.sin(t)], axis=1) * 1e-3
    res = interface_loop(it, t, u, 0.0 * u, np.zeros_like(u))
    assert res.u.shape == (11, 2, 2) and res.T.shape == (11, 2, 2) and res.N.shape == (11, 2)
    # a pair without preload touches without load: open at g = 0, its force 0
    assert np.all(res.code[:, 1] == SEPARATION) and np.all(res.T[:, 1] == 0.0)
    with pytest.raises(ValueError, match="u1 must have one column per pair"):
        interface_loop(it, t, np.zeros((11, 3)), np.zeros(11), np.zeros(11))
    with pytest.raises(ValueError, match="g must have one row per sample"):
        interface_loop(it, t, np.zeros(11), np.zeros(11), np.zeros(10))
    with pytest.raises(ValueError, match="t must be strictly increasing"):
        interface_loop(it, t[::-1], np.zeros(11), np.zeros(11), np.zeros(11))
    with pytest.raises(ValueError, match="period must be"):
        interface_loop(it, t, np.zeros(11), np.zeros(11), np.zeros(11), period=5.0)
    with pytest.raises(ValueError, match="u2 must be an array of real numbers"):
        interface_loop(it, t, np.zeros(11), ["a"] * 11, np.zeros(11))
    with pytest.raises(ValueError, match="g must be finite"):
        interface_loop(it, t, np.zeros(11), np.zeros(11), np.full(11, np.nan))
    with pytest.raises(ValueError, match="interface must be"):
        interface_loop(object(), t, np.zeros(11), np.zeros(11), np.zeros(11))
    assert STICK_SLIP == 0

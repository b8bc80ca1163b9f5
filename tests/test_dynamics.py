"""Oracles for the time integrator and the steady-state solver (issue 3)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tolerances
from jointdyn.drivers import march
from jointdyn.kinematics import ConstantLoad, HarmonicLoad
from jointdyn.laws import SEPARATION, make_law
from jointdyn.systems import PAPER, Contact, System
from jointdyn.dynamics import (
    Restart,
    RunStatus,
    SteadyState,
    SteadyStatus,
    Trajectory,
    integrate,
    integrate_sampled,
    steady_state,
)
from jointdyn.dynamics._core import LOADS_HARMONIC, RUN_BLOWUP, RUN_OK, RUN_OVERFLOW
from jointdyn.dynamics._model import make_model, run
from jointdyn.dynamics import MarchOptions, SteadyStateOptions

#: the steady state's defaults
SS = SteadyStateOptions()

M, K, KT = PAPER["m"], PAPER["k"], PAPER["kt"]


def _linear_amp(k_total, m, c, f, w):
    return f / abs(k_total - m * w * w + 1j * c * w)


# --- linear limits ---------------------------------------------------------


@pytest.mark.parametrize("gamma", [0.5, 0.9, 1.7, 2.5])
def test_stuck_contact_is_linear_k_plus_kt_oscillator(gamma):
    # eta = 0, forcing so small that the Iwan contact never leaves the
    # linear part of its backbone: x'' response of (m, k + kt, c)
    zeta = 0.02
    s = System.paper_damper(eta=0.0, f1=0.01, zeta=zeta)
    r = steady_state(s, gamma)
    assert r.status == "periodic" and r.period_multiple == 1
    w = gamma * math.sqrt(K / M)
    X = _linear_amp(K + KT, M, 2 * zeta * math.sqrt(K * M), 0.01, w)
    assert r.amplitude_m == pytest.approx(X, rel=tolerances.TEST_TI_LINEAR_RTOL)
    assert r.amplitude_q == pytest.approx(KT * r.amplitude_m / 50.0, rel=1e-12)


def test_two_dof_contact_between_dofs_linear_limit():
    # contact between DOF 0 and DOF 1 (u = x0 - x1), tiny force on DOF 1
    law = make_law("iwan", kt=2e5, mu=0.5, n_ref=100.0)
    Mm = np.diag([2.0, 1.0])
    Kk = np.array([[3e5, -1e5], [-1e5, 1e5]])
    Cc = 1e-4 * Kk + 0.5 * Mm
    f = np.array([0.0, 0.02])
    s = System(M=Mm, C=Cc, K=Kk, contacts=(Contact(law=law, dof=0, dof2=1, normal=ConstantLoad(100.0)),), force=f)
    gamma = 0.7
    r = steady_state(s, gamma, response_dof=1)
    assert r.status == "periodic"
    w = gamma * s.w0
    B = np.array([1.0, -1.0])
    Z = Kk + 2e5 * np.outer(B, B) - w * w * Mm + 1j * w * Cc
    X = np.linalg.solve(Z, f)
    assert r.amplitude_m == pytest.approx(abs(X[1]), rel=tolerances.TEST_TI_LINEAR_RTOL)
    assert r.loop is not None and r.loop.x.shape[1] == 2


def test_linear_system_without_contacts():
    s = System.sdof(m=2.0, k=8e4, f1=3.0, zeta=0.05)
    w0 = math.sqrt(8e4 / 2.0)
    for gamma in (0.6, 1.0, 1.8):
        r = steady_state(s, gamma)
        assert r.status == "periodic" and math.isnan(r.amplitude_q)
        X = _linear_amp(8e4, 2.0, 2 * 0.05 * math.sqrt(8e4 * 2.0), 3.0, gamma * w0)
        assert r.amplitude_m == pytest.approx(X, rel=1e-4)
        assert r.energy_viscous_J == pytest.approx(r.work_force_J, rel=1e-4)
    # undamped linear resonance grows without bound
    r = steady_state(System.sdof(m=2.0, k=8e4, f1=3.0), 1.0, max_periods=200)
    assert r.status == "unbounded" and math.isnan(r.amplitude_m)


def test_two_dof_separating_contact_events_and_law():
    # contact from DOF 1 to ground with eta = 1.5 (separation), forced DOF 0
    law = make_law("iwan", kt=2e5, mu=0.5, n_ref=100.0)
    Mm = np.diag([1.0, 2.0])
    Kk = np.array([[2e5, -1e5], [-1e5, 1.5e5]])
    c = Contact(law=law, dof=1, normal=HarmonicLoad(100.0, 150.0, math.degrees(0.4)))
    s = System(M=Mm, C=np.zeros((2, 2)), K=Kk, contacts=(c,), force=[20.0, 0.0])
    gamma = 1.2
    tr = integrate(s, gamma, periods=4)
    w = gamma * s.w0
    ev = c.normal.zero_crossings(w, 0.0, tr.t[-1])
    assert ev.size == 8
    for te in ev:
        assert np.min(np.abs(tr.t - te)) <= 1e-12 * tr.t[-1]
    T = march(law, tr.x[:, 1], tr.N[:, 0])[0]
    assert np.max(np.abs(T - tr.T[:, 0])) <= tolerances.TEST_TI_MARCH_ATOL_FY * law.fy
    r = steady_state(s, gamma, response_dof=0)
    assert r.status == "periodic"
    diss = r.energy_contact_J + r.energy_viscous_J
    assert diss == pytest.approx(r.work_force_J, rel=tolerances.TEST_TI_ENERGY_RTOL)
    rec = r.to_record()
    assert rec["status"] == "periodic" and rec["amplitude_m"] == r.amplitude_m


# --- the paper damper: peak, Den Hartog, energy, step size -----------------


@pytest.mark.parametrize("eta", [0.0, 0.5])
def test_lightly_damped_peak_at_stuck_frequency(eta):
    # beta = 1000: almost everything sticks, the peak is the stuck linear
    # resonance gamma = sqrt((k + kt)/k) = 1.330 (docs/model.md section 6)
    s = System.paper_damper(eta=eta, beta=1000.0)
    g_lin = math.sqrt((K + KT) / K)

    def scan(gammas, warm):
        out, prev = [], None
        for g in gammas:
            r = steady_state(s, g, start=prev, keep_loop=False)
            assert r.status == "periodic", (g, r.status, r.message)
            # no thousands of periods even at this light damping
            assert r.periods < 1000, (g, r.periods)
            out.append(r.amplitude_q)
            prev = r if warm else None
        return np.array(out)

    # coarse scan from the linear estimate, then a warm-started fine scan
    coarse = np.arange(1.25, 1.4001, 0.025)
    a = scan(coarse, warm=False)
    g0 = coarse[int(np.argmax(a))]
    fine = np.arange(g0 - 0.02, g0 + 0.02001, 0.005)
    b = scan(fine, warm=True)
    peak = fine[int(np.argmax(b))]
    assert abs(peak - g_lin) <= tolerances.TEST_TI_PEAK_GAMMA_ATOL
    # far from the peak the response is the linear stuck one (q << 1)
    assert a[0] < 0.2 * b.max()


def test_den_hartog_unbounded_and_bounded():
    # no viscous damping, eta = 0: friction R = mu N0 against F1 = R / beta.
    # beta = 0.1 < pi/4: unbounded at resonance; never a plain number
    r = steady_state(System.paper_damper(eta=0.0, beta=0.1), 1.0)
    assert r.status == "unbounded"
    assert math.isnan(r.amplitude_q) and math.isnan(r.amplitude_m)
    assert r.period_multiple == 0 and not r.status.ok
    # beta = 1 > pi/4: bounded, periodic
    r = steady_state(System.paper_damper(eta=0.0, beta=1.0), 1.0)
    assert r.status == "periodic" and np.isfinite(r.amplitude_q)


@pytest.mark.parametrize(
    "kw,gamma",
    [
        (dict(eta=0.5, beta=2.0), 1.1),
        (dict(eta=1.5, beta=2.0), 0.8),
        (dict(eta=1.5, beta=2.0, delta_deg=math.degrees(1.0)), 1.3),
        (dict(eta=0.5, beta=5.0, zeta=0.02), 1.2),
    ],
)
def test_energy_balance_at_steady_state(kw, gamma):
    r = steady_state(System.paper_damper(**kw), gamma)
    assert r.status == "periodic"
    diss = r.energy_contact_J + r.energy_viscous_J
    assert r.work_force_J > 0 and r.energy_contact_J > 0
    assert diss == pytest.approx(r.work_force_J, rel=tolerances.TEST_TI_ENERGY_RTOL)
    if kw.get("zeta", 0.0) == 0.0:
        assert r.energy_viscous_J == 0.0


@pytest.mark.parametrize("eta", [0.5, 1.5])
@pytest.mark.parametrize("gamma", [0.8, 1.1, 1.5])
def test_step_halving_changes_amplitude_little(eta, gamma):
    s = System.paper_damper(eta=eta, beta=2.0)
    a = steady_state(s, gamma, keep_loop=False)
    b = steady_state(s, gamma, steps_per_period=2 * SS.march.steps_per_period, start=a, keep_loop=False)
    assert a.status == b.status == "periodic"
    assert b.amplitude_m == pytest.approx(a.amplitude_m, rel=tolerances.TEST_TI_STEP_HALVING_RTOL)


# --- the compiled law inside the integrator, events ------------------------


@pytest.mark.parametrize("model,eta", [("iwan", 0.5), ("iwan", 1.5), ("discrete", 1.5), ("iwan-paper", 0.8)])
def test_integrator_law_agrees_with_march(model, eta):
    s = System.paper_damper(eta=eta, beta=1.5, model=model, n=40 if model == "discrete" else None)
    tr = integrate(s, 1.05, periods=6)
    assert isinstance(tr, Trajectory) and tr.status == "ok"
    law = s.contacts[0].law
    T, _, code, _ = march(law, tr.x[:, 0], tr.N[:, 0])
    assert np.max(np.abs(T - tr.T[:, 0])) <= tolerances.TEST_TI_MARCH_ATOL_FY * law.fy
    assert np.array_equal(code.astype(np.int8), tr.code[:, 0])


@settings(max_examples=12, deadline=None)
@given(
    eta=st.floats(0.0, 2.5),
    delta=st.floats(-3.0, 3.0),
    beta=st.floats(0.3, 20.0),
    gamma=st.floats(0.3, 2.5),
    model=st.sampled_from(["iwan", "jenkins", "iwan-paper"]),
)
def test_property_law_in_integrator_equals_march(eta, delta, beta, gamma, model):
    # for any loads, the forces recorded by the integrator are those of the
    # law marched over the recorded displacement and normal-load samples,
    # every sample is finite and an open contact carries no force
    s = System.paper_damper(eta=eta, beta=beta, delta_deg=math.degrees(delta), model=model)
    tr = integrate(s, gamma, periods=3, steps_per_period=64)
    assert tr.status == "ok" and np.all(np.isfinite(tr.x)) and np.all(np.diff(tr.t) > 0)
    law = s.contacts[0].law
    T = march(law, tr.x[:, 0], tr.N[:, 0])[0]
    assert np.max(np.abs(T - tr.T[:, 0])) <= tolerances.TEST_TI_MARCH_ATOL_FY * law.fy
    assert np.all(np.abs(tr.T[:, 0]) <= law.fy * np.maximum(tr.N[:, 0], 0.0) / law.n_ref * (1 + 1e-9) + 1e-12)


def test_separation_and_recontact_are_step_boundaries():
    s = System.paper_damper(eta=1.5, beta=2.0)
    gamma = 0.9
    tr = integrate(s, gamma, periods=3)
    w = gamma * s.w0
    c = s.contacts[0]
    ev = c.normal.zero_crossings(w, 0.0, tr.t[-1])
    assert ev.size == 6
    for te in ev:
        i = int(np.argmin(np.abs(tr.t - te)))
        assert abs(tr.t[i] - te) <= 1e-12 * tr.t[-1]
        assert tr.N[i, 0] <= 1e-9 * c.n0  # exactly 0 (separation) or tiny (re-contact)
    # open interface: no force, and only between the events
    sep = tr.code[:, 0] == SEPARATION
    assert np.all(tr.T[sep, 0] == 0.0)
    assert np.all(tr.N[sep, 0] <= 0.0)


@pytest.mark.parametrize("delta", [math.pi + math.asin(1 / 1.5), -math.asin(1 / 1.5)])
def test_event_at_the_period_boundary(delta):
    # separation (first) or re-contact (second) exactly at w t = 0 mod 2 pi
    s = System.paper_damper(eta=1.5, beta=2.0, delta_deg=math.degrees(delta))
    tr = integrate(s, 1.1, periods=3)
    law = s.contacts[0].law
    T = march(law, tr.x[:, 0], tr.N[:, 0])[0]
    assert np.max(np.abs(T - tr.T[:, 0])) <= tolerances.TEST_TI_MARCH_ATOL_FY * law.fy
    assert 0.0 <= tr.N[0, 0] <= 1e-9 * law.n_ref
    a = steady_state(s, 1.1, keep_loop=False)
    b = steady_state(s, 1.1, steps_per_period=2 * SS.march.steps_per_period, keep_loop=False)
    assert a.status.ok and b.status.ok
    assert b.amplitude_m == pytest.approx(a.amplitude_m, rel=tolerances.TEST_TI_STEP_HALVING_RTOL)


def test_velocity_reversals_are_step_boundaries():
    # each sign change of the contact velocity has a sample at the extremum
    s = System.paper_damper(eta=0.5, beta=2.0)
    tr = integrate(s, 1.1, periods=4)
    v = tr.v[:, 0]
    vscale = np.max(np.abs(v))
    i = np.flatnonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0)
    assert i.size >= 6
    # a reversal sample has |v| tiny compared with a step's velocity change
    near = np.minimum(np.abs(v[i]), np.abs(v[i + 1]))
    assert np.all(near <= 1e-6 * vscale)


def test_sampled_loads_match_harmonic_run():
    s = System.paper_damper(eta=1.2, beta=2.0)
    gamma = 1.1
    w = gamma * s.w0
    periods = 4
    t = np.linspace(0.0, periods * 2 * math.pi / w, periods * 1024 + 1)
    F = s.force[0] * np.sin(w * t)
    c = s.contacts[0]
    N = c.normal.at(w * t)
    a = integrate_sampled(s, t, F[:, None], N[:, None])
    b = integrate(s, gamma, periods=periods, steps_per_period=1024)
    xa = np.interp(b.t, a.t, a.x[:, 0])
    assert np.max(np.abs(xa - b.x[:, 0])) <= 2e-3 * np.max(np.abs(b.x[:, 0]))
    # callables are sampled at t
    c2 = integrate_sampled(s, t, lambda tt: [s.force[0] * math.sin(w * tt)], lambda tt: [c.n0 + c.n1 * math.sin(w * tt)])
    assert np.array_equal(c2.x, a.x)


def test_sampled_free_vibration_without_contacts():
    s = System.sdof(m=1.0, k=100.0)
    t = np.linspace(0.0, 10.0, 2001)
    tr = integrate_sampled(s, t, np.zeros((t.size, 1)), None, x0=[1.0])
    assert tr.status == "ok" and tr.t.size == t.size
    assert np.max(np.abs(tr.x[:, 0] - np.cos(10.0 * t))) <= 1e-5


# --- steady-state bookkeeping -----------------------------------------------


@pytest.mark.parametrize("eta", [0.5, 1.5])
def test_contact_energy_is_the_loop_area(eta):
    # E_c (integrated with the RK4 stages) vs the area of the recorded
    # hysteresis loop, closed polygon over the step ends (fine steps)
    s = System.paper_damper(eta=eta, beta=2.0)
    r = steady_state(s, 1.1, steps_per_period=2048)
    lp = r.loop
    u, T = lp.x[:, 0], lp.T[:, 0]
    area = float(np.sum(0.5 * (T[1:] + T[:-1]) * np.diff(u)))
    assert area == pytest.approx(r.energy_contact_J, rel=1e-4)


def test_loop_is_one_closed_period_and_warm_start_is_cheap():
    s = System.paper_damper(eta=0.5, beta=2.0)
    r = steady_state(s, 1.2)
    assert isinstance(r, SteadyState) and r.status.ok
    lp = r.loop
    w = r.omega
    assert lp.t[-1] == pytest.approx(2 * math.pi / w, rel=1e-12)
    X = 0.5 * (lp.x[:, 0].max() - lp.x[:, 0].min())
    assert X == pytest.approx(r.amplitude_m, rel=1e-6)
    assert np.abs(lp.x[-1, 0] - lp.x[0, 0]) <= 10 * SS.amp_rtol * r.amplitude_m
    assert isinstance(r.restart, Restart)
    r2 = steady_state(s, 1.2, start=r)
    assert r2.status.ok and r2.periods <= SS.check_periods + SS.chunk + 1
    assert r2.amplitude_m == pytest.approx(r.amplitude_m, rel=10 * SS.amp_rtol)
    r3 = steady_state(s, 1.3, start=r, keep_loop=False)
    assert r3.status.ok and r3.loop is None


def test_unsettled_response_is_not_reported_as_a_number():
    # near the jump of the eta = 0.5, beta = 2 curve the closed-form Iwan law
    # (not the discrete one nor the exact law, which are period-1 there)
    # settles to a period-7 response, beyond p <= SS.max_multiple:
    # "not-settled", amplitudes NaN
    s = System.paper_damper(eta=0.5, beta=2.0, model="iwan-closed")
    r = steady_state(s, 1.15)
    assert r.status == "not-settled"
    assert math.isnan(r.amplitude_q) and math.isnan(r.amplitude_m)
    assert r.periods < SS.max_periods
    assert steady_state(System.paper_damper(eta=0.5, beta=2.0), 1.15).status == "periodic"


# --- statuses and the runner's buffers ------------------------------------------


def test_status_enumerations():
    assert [m.code for m in (RunStatus.OK, RunStatus.BLOW_UP, RunStatus.OVERFLOW)] == [RUN_OK, RUN_BLOWUP, RUN_OVERFLOW]
    # files and tables carry the values
    assert [m.value for m in SteadyStatus] == ["periodic", "not-settled", "unbounded"]
    assert SteadyStatus.PERIODIC.ok and not SteadyStatus.NOT_SETTLED.ok and not SteadyStatus.UNBOUNDED.ok
    assert RunStatus.OK.ok and not RunStatus.BLOW_UP.ok
    assert all(m.message for m in (*RunStatus, *SteadyStatus))
    r = steady_state(System.paper_damper(eta=0.5, beta=2.0), 1.2, keep_loop=False)
    assert r.status is SteadyStatus.PERIODIC and r.status == "periodic" and r.status.ok


def test_blow_up_is_reported():
    # negative damping: the response grows like exp(25 t) until the guard stops it
    s = System(M=[[1.0]], C=[[-50.0]], K=[[100.0]], force=[1.0])
    tr = integrate(s, 1.0, periods=200)
    assert tr.status is RunStatus.BLOW_UP and not tr.status.ok
    assert tr.t[-1] < 200 * 2 * math.pi / 10.0
    r = steady_state(s, 1.0)
    assert r.status is SteadyStatus.UNBOUNDED and r.message == "blow-up"


def test_full_sample_buffer_is_enlarged_and_the_run_repeated():
    s = System.paper_damper(eta=1.5, beta=2.0)
    model = make_model(s, 1.1 * s.w0, MarchOptions(steps_per_period=64))
    x0, v0 = np.array([1e-4]), np.zeros(1)
    S0 = model.initial_states(x0)
    runs = []
    for capacity in (1, 100000):
        x, v, S = x0.copy(), v0.copy(), S0.copy()
        res = run(model, model.grid, LOADS_HARMONIC, x, v, S, 2, record=True, capacity=capacity)
        assert res.status is RunStatus.OK and res.done == 2
        runs.append((res, x, S))
    (a, xa, Sa), (b, xb, Sb) = runs
    for p, q in zip(a.samples, b.samples):
        np.testing.assert_array_equal(p, q)
    np.testing.assert_array_equal(xa, xb)
    np.testing.assert_array_equal(Sa, Sb)


# --- bad input ---------------------------------------------------------------


@pytest.mark.parametrize(
    "kw,name",
    [
        (dict(gamma=0.0), "gamma"),
        (dict(gamma=-1.0), "gamma"),
        (dict(gamma=float("nan")), "gamma"),
        (dict(steps_per_period=0), "steps_per_period"),
        (dict(steps_per_period=-5), "steps_per_period"),
        (dict(amp_rtol=0.0), "amp_rtol"),
        (dict(energy_rtol=float("nan")), "energy_rtol"),
        (dict(check_periods=1), "check_periods"),
        (dict(max_periods=0), "max_periods"),
        (dict(response_dof=3), "response_dof"),
        (dict(start="x"), "start"),
    ],
)
def test_bad_input_names_the_parameter(kw, name):
    s = System.paper_damper(eta=0.5, beta=2.0)
    args = dict(gamma=1.0)
    args.update(kw)
    g = args.pop("gamma")
    with pytest.raises(ValueError, match=name):
        steady_state(s, g, **args)


def test_bad_input_integrate():
    s = System.paper_damper(eta=0.5, beta=2.0)
    with pytest.raises(ValueError, match="periods"):
        integrate(s, 1.0, periods=0)
    with pytest.raises(ValueError, match="gamma"):
        integrate(s, float("nan"))
    with pytest.raises(ValueError, match="steps_per_period"):
        integrate(s, 1.0, steps_per_period=0)
    with pytest.raises(ValueError, match="x0"):
        integrate(s, 1.0, x0=[float("nan")])
    t = np.linspace(0, 1, 5)
    with pytest.raises(ValueError, match="t must be strictly increasing"):
        integrate_sampled(s, t[::-1], np.zeros((5, 1)), np.ones((5, 1)))
    with pytest.raises(ValueError, match="normal"):
        integrate_sampled(s, t, np.zeros((5, 1)), np.ones((4, 1)))
    with pytest.raises(ValueError, match="force"):
        integrate_sampled(s, t, np.full((5, 1), np.nan), np.ones((5, 1)))

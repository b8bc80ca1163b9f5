"""Harmonic balance: oracles (describing function, finite differences, time
integration, monodromy), folds and stability, unbounded responses, input
validation."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import tolerances
from jointdyn import System
from jointdyn.dynamics import MarchOptions
from jointdyn.continuation import continuation, turning_points
from jointdyn.hb import (
    HBProblem,
    continue_hb,
    frc_hb,
    harmonic_balance,
    hill_exponents,
    monodromy_multipliers,
)
from jointdyn.kinematics import HarmonicLoad
from jointdyn.laws import Jenkins

KT, FY, M, K, F1, ZETA = 3e5, 50.0, 10.0, 3.9e5, 20.0, 1e-3


def _jenkins_system():
    law = Jenkins(kt=KT, mu=0.5, n_ref=100.0)
    return System.sdof(m=M, k=K, law=law, f1=F1, zeta=ZETA)


def _df_amplitude(gamma):
    """Describing-function amplitude of the Jenkins oscillator (closed form).

    Equivalent stiffness and damping of a Jenkins element (spring kt, slip
    force fy) for x = A cos(theta) (Caughey 1960): with
    cos(theta*) = 1 - 2 fy / (kt A), k_eq = kt (theta* - sin(2 theta*)/2) / pi
    and d_eq = 4 fy (1 - fy / (kt A)) / (pi A) for A > fy/kt; k_eq = kt,
    d_eq = 0 below. Amplitude equation:
    A^2 [(k + k_eq - m w^2)^2 + (c w + d_eq)^2] = F1^2.
    """
    w = gamma * math.sqrt(K / M)
    c = 2 * ZETA * math.sqrt(K * M)

    def res(A):
        if A <= FY / KT:
            keq, deq = KT, 0.0
        else:
            ts = math.acos(1 - 2 * FY / (KT * A))
            keq = KT / math.pi * (ts - 0.5 * math.sin(2 * ts))
            deq = 4 * FY / (math.pi * A) * (1 - FY / (KT * A))
        return A * A * ((K + keq - M * w * w) ** 2 + (c * w + deq) ** 2) - F1 * F1

    grid = np.geomspace(1e-7, 1e-1, 3000)
    r = np.array([res(a) for a in grid])
    idx = np.flatnonzero(np.sign(r[:-1]) != np.sign(r[1:]))
    assert idx.size == 1, "the DF equation must have a single root at the test frequencies"
    return brentq(res, grid[idx[0]], grid[idx[0] + 1], xtol=1e-18, rtol=1e-15)


@pytest.mark.parametrize("gamma", [1.0, 1.25, 1.35, 1.42])
def test_one_harmonic_equals_describing_function(gamma):
    # 1024 samples per period: the AFT quadrature of the kinked Jenkins force
    # converges as Ns^-2 (measured: 256 -> 3e-5, 1024 -> 4e-7 relative)
    sol = harmonic_balance(_jenkins_system(), gamma, harmonics=1, samples=1024)
    assert sol.status.ok
    A = math.hypot(sol.X[1], sol.X[2])
    assert abs(sol.X[0]) < 1e-12  # symmetric loop: no offset
    assert abs(A - _df_amplitude(gamma)) <= tolerances.TEST_HB_DF_RTOL * _df_amplitude(gamma)


@pytest.mark.parametrize(
    "model,eta,par",
    [("iwan", 0.5, "eta"), ("jenkins", 0.5, "delta"), ("discrete", 0.3, "n0"), ("iwan", 0.5, "gamma"),
     ("iwan-paper", 0.5, "f1"),
     # separation: the re-contact phase moves with eta, delta and n0 (virgin restart there)
     ("iwan", 1.5, "eta"), ("jenkins", 1.5, "delta"), ("iwan", 1.5, "n0"), ("discrete", 1.5, "gamma")],
)
def test_jacobian_matches_central_differences(model, eta, par):
    sysm = System.paper_damper(eta=eta, beta=2.0, model=model, n=20 if model == "discrete" else None, delta_deg=math.degrees(0.3),
                               zeta=0.01)
    g = 1.1
    p = HBProblem(sysm, harmonics=4, samples=128, parameter=par, gamma=None if par == "gamma" else g)
    lam = {"eta": eta, "delta": math.degrees(0.3), "n0": 100.0, "gamma": g, "f1": p.f1_ref}[par]
    X = harmonic_balance(sysm, g, harmonics=4, samples=128).X
    ev = _assert_jacobian_matches_central_differences(p, X, lam, 1e-6 * max(abs(lam), 1e-3))
    assert ev.info[2] == 1.0  # the marched force repeated


def _assert_jacobian_matches_central_differences(p, X, lam, h_lam):
    """Assert that the AFT Jacobians of problem p at (X, lam) match central differences (steps 1e-6 max|X|
    and h_lam); dR/dX and dR/dp each against their own scale (N/m and N per unit of p differ by orders).
    Returns the evaluation at (X, lam)."""
    ev = p.evaluate(X, lam)
    Ja = np.c_[ev.JX, ev.Jp]
    Jfd = np.empty_like(Ja)
    for j in range(X.size + 1):
        Xp, Xm, lp, lm = X.copy(), X.copy(), lam, lam
        h = 1e-6 * np.abs(X).max() if j < X.size else h_lam
        if j < X.size:
            Xp[j] += h
            Xm[j] -= h
        else:
            lp, lm = lam + h, lam - h
        Jfd[:, j] = (p.evaluate(Xp, lp).R - p.evaluate(Xm, lm).R) / (2 * h)
    assert np.max(np.abs(Ja[:, :-1] - Jfd[:, :-1])) <= tolerances.TEST_HB_JACOBIAN_RTOL * np.max(np.abs(Ja[:, :-1]))
    assert np.max(np.abs(Ja[:, -1] - Jfd[:, -1])) <= tolerances.TEST_HB_JACOBIAN_RTOL * np.max(np.abs(Ja[:, -1]))
    return ev


def test_jacobian_through_the_separation_grid_matches_central_differences():
    # the default law at eta = 1.5, beta = 1000, near its peak: it slips only in the last ~0.002 rad before
    # separation, and the AFT marches it at phases graded towards separation (fourier.separation_grid); the
    # projection is linear in the samples, so the Jacobian through it stays exact
    sysm = System.paper_damper(eta=1.5, beta=1000.0)
    g = 1.3034
    p = HBProblem(sysm, harmonics=4, samples=128)
    assert p._uniform is not None and p._taug.size > 128
    X = harmonic_balance(sysm, g, harmonics=4, samples=128).X
    ev = _assert_jacobian_matches_central_differences(p, X, g, 1e-6)
    assert (ev.T.shape, ev.code.shape) == ((1, 128), (1, 128))  # reported at the uniform samples


def test_hb_equals_time_integration_at_stable_points():
    from jointdyn.dynamics import steady_state

    cases = [(System.paper_damper(eta=0.01, beta=1.0, model="iwan"), 1.25),
             (System.paper_damper(eta=0.5, beta=2.0, model="iwan"), 1.5)]
    for sysm, g in cases:
        sol = harmonic_balance(sysm, g, harmonics=7, samples=128)
        assert sol.status.ok and sol.stable
        ss = steady_state(sysm, g)
        assert ss.status == "periodic"
        assert abs(sol.amplitude_m - ss.amplitude_m) <= tolerances.TEST_HB_VS_TIME_RTOL * ss.amplitude_m


def test_jenkins_branch_complete_and_agrees_with_df():
    ds = frc_hb(_jenkins_system(), 0.6, 1.8, harmonics=1, samples=1024)
    assert ds.attrs["status"] == "complete"
    assert ds.gamma.values[0] == 0.6 and ds.gamma.values[-1] == 1.8
    assert ds.stable.values.all() and ds.attrs["folds"] == 0
    for i in range(0, ds.sizes["point"], 7):
        g = float(ds.gamma[i])
        A = float(ds.amplitude_m[i])
        assert abs(A - _df_amplitude(g)) <= 1e-3 * _df_amplitude(g)
    for name in ("gamma", "amplitude_q", "amplitude_m", "offset_m", "max_abs_m", "stable", "fold"):
        assert ds[name].dims == ("point",)
    assert ds.attrs["harmonics"] == 1 and ds.attrs["samples"] == 1024


def test_eta_1p5_folds_with_unstable_segment_between():
    # the closed form's fold pair near gamma 1.2816 (the exact law has none
    # there, and neither has its time-domain sweep): fold detection and
    # stability between the folds are what is tested
    ds = frc_hb(System.paper_damper(eta=1.5, beta=20.0, model="iwan-closed"), 0.8, 1.8)
    assert ds.attrs["status"] == "complete"
    f = np.flatnonzero(ds.fold.values)
    assert f.size >= 2
    between = ds.stable.values[f[0]:f[-1] + 1]
    assert (~between).any()
    # far from the folds the response is stable
    assert ds.stable.values[: max(f[0] - 5, 1)].all() and ds.stable.values[f[-1] + 5:].all()


def test_eta_1p5_time_domain_sweeps_jump_at_the_hb_turning_points():
    # eta = 1.5 (separation), beta = 2, the paper's contact model (last
    # reversal rule): the HB branch turns back at A and forward again at
    # B < A; the up sweep jumps up at A, the down sweep jumps down at B, and
    # the HB branch between them is unstable
    from jointdyn.sweeps import frc_sweep, to_frame

    ds = frc_hb(System.paper_damper(eta=1.5, beta=2.0, model="iwan-paper"), 1.0, 1.3, samples=512)
    assert ds.attrs["status"] == "complete"
    tp = np.flatnonzero(ds.fold.values)
    assert tp.size == 2 and ds.attrs["folds"] == 2
    gB, gA = np.sort(ds.gamma.values[tp])
    assert gA - gB > 5e-3
    qA, qB = ds.amplitude_q.values[tp[0]], ds.amplitude_q.values[tp[1]]
    assert qB > qA
    between = (ds.point > tp[0]) & (ds.point < tp[1])
    assert (~ds.stable.values[between.values]).any()
    g = np.round(np.arange(gB - 0.004, gA + 0.004, 0.001), 6)
    td = to_frame(frc_sweep(g, etas=(1.5,), betas=(2.0,), model="iwan-paper", directions=("up", "down"),
                            progress=False, n_workers=1))
    mid = 0.5 * (qA + qB)
    up = td[(td.direction == "up") & (td.status_name == "periodic")].sort_values("gamma")
    dn = td[(td.direction == "down") & (td.status_name == "periodic")].sort_values("gamma")
    g_up = up.gamma[up.amplitude_q > mid].min()  # first high point sweeping up
    g_up_low = up.gamma[up.amplitude_q < mid].max()  # last low point
    g_dn = dn.gamma[dn.amplitude_q > mid].min()  # last high point sweeping down
    g_dn_low = dn.gamma[dn.amplitude_q < mid].max()  # first low point
    assert g_up_low < gA + 1.5e-3 and g_up > gA - 1.5e-3
    assert g_dn_low < gB + 1.5e-3 and g_dn > gB - 1.5e-3
    assert g_up > g_dn + 5e-3  # hysteresis: the two sweeps jump at different gammas


@pytest.mark.parametrize("model,params", [("discrete", {"n": 100}), ("iwan", {})])
def test_eta_1p5_discrete_ground_truth_has_no_jump(model, params):
    # the same case with the exact discrete contact and with the exact Iwan
    # law (the default): one stable branch, no fold; the jump above comes
    # from the closed form's approximation
    ds = frc_hb(System.paper_damper(eta=1.5, beta=2.0, model=model, law_params=params), 1.0, 1.3, samples=512)
    assert ds.attrs["status"] == "complete"
    assert not ds.fold.values.any()
    assert ds.stable.values.all()
    assert np.all(np.diff(ds.gamma.values) > 0)


def test_hill_agrees_with_monodromy():
    # the closed form's fold pair near gamma 1.183 gives an unstable stretch
    # to compare the two stability methods on (the exact law has no fold here)
    br = continue_hb(System.paper_damper(eta=10.0, beta=2.0, model="iwan-closed"), 0.5, 2.0, harmonics=7,
                     samples=128)
    f = np.flatnonzero(br.fold)
    assert f.size >= 2
    # the fold pair that encloses the unstable stretch (the closed form's steep corners are folds too)
    u = np.flatnonzero(~br.stable)
    assert u.size
    lo, hi = f[f <= u[0]].max(), f[f >= u[-1]].min()
    # and a stable point low on the rising flank (gamma 0.58; higher up, 0.6 to 1.0, Hill's 7 harmonics and the
    # monodromy of the closed form's jumping force differ by 0.02 to 0.3 in the largest multiplier, both < 1)
    picks = [lo - 3, (lo + hi) // 2, hi + 3, int(np.argmin(np.abs(br.lam - 0.58)))]
    seen = set()
    for i in picks:
        ev = br.problem.evaluate(br.X[i], br.lam[i])
        w = br.problem.omega(br.lam[i])
        s, _ = hill_exponents(ev.JX, br.problem.system.M, br.problem.system.C, w, br.problem.H)
        mu_hill = np.max(np.abs(np.exp(s * 2 * np.pi / w)))
        mu_mono = np.max(np.abs(monodromy_multipliers(br.problem, br.X[i], br.lam[i])))
        assert abs(mu_hill - mu_mono) < 1e-2
        if abs(mu_mono - 1) > 2e-3:
            assert (mu_mono > 1) == (not br.stable[i])
        seen.add(bool(br.stable[i]))
    assert seen == {True, False}
    # the march of the period map from its options: the steps as the field or the keyword, bit for bit
    i = picks[-1]
    by_kw = monodromy_multipliers(br.problem, br.X[i], br.lam[i], steps_per_period=512)
    by_options = monodromy_multipliers(br.problem, br.X[i], br.lam[i], march=MarchOptions(steps_per_period=512))
    assert np.array_equal(by_kw, by_options)


def test_unbounded_below_den_hartog_limit():
    # beta = 0.5 < pi/4, no viscous damping: no steady state near gamma = 1
    ds = frc_hb(System.paper_damper(eta=0.01, beta=0.5, model="iwan"), 0.6, 1.6)
    assert ds.attrs["status"] == "unbounded"
    assert "gamma" in ds.attrs["message"] and "Den Hartog" in ds.attrs["message"]
    seg = ds.branch.values
    assert set(seg) == {0, 1}
    assert ds.gamma.values[seg == 0].max() < 1.0 < ds.gamma.values[seg == 1].min()
    # above the limit the same system is bounded
    ok = frc_hb(System.paper_damper(eta=0.01, beta=1.0, model="iwan"), 0.6, 1.6)
    assert ok.attrs["status"] == "complete"


def test_generic_continuation_finds_both_folds_of_a_cubic():
    # y^3 - y + lam = 0: folds at lam = -+2 / (3 sqrt 3)
    def res(y, lam):
        return np.array([y[0] ** 3 - y[0] + lam]), np.array([[3 * y[0] ** 2 - 1]]), np.array([1.0])

    r = continuation(res, np.array([1.5]), -1.5, 1.5, ds=0.05, ds_max=0.1)
    assert r.status == "complete" and r.counters["folds"] == 2
    lam_f = np.sort(r.lam[r.fold])
    assert np.allclose(lam_f, [-2 / (3 * math.sqrt(3)), 2 / (3 * math.sqrt(3))], atol=0.05)
    assert np.all(np.abs(r.y[:, 0] ** 3 - r.y[:, 0] + r.lam) < 1e-8)


def _damper(eta=0.1, delta=0.0, n0=100.0, f1=25.0):  # delta in degrees, like the parameter
    from jointdyn.laws import Iwan

    law = Iwan(kt=3e5, mu=0.5, n_ref=100.0)
    return System.sdof(m=10.0, k=3.9e5, law=law, f1=f1, n0=n0, eta=eta, delta_deg=delta)


def test_turning_points_ignore_jitter_within_the_band():
    lam = np.array([0.0, 1.0, 2.0, 2.0001, 1.99995, 2.5, 3.0, 2.0, 1.0, 1.5, 4.0])
    assert list(turning_points(lam, band=0.01)) == [6, 8]
    assert list(turning_points(lam, band=0.0)) == [3, 4, 6, 8]


@pytest.mark.parametrize("par,start,stop", [("eta", 0.1, 0.6), ("delta", 0.0, 85.0), ("n0", 80.0, 140.0),
                                            ("f1", 10.0, 40.0)])
def test_continuation_in_a_parameter_matches_fixed_solutions(par, start, stop):
    br = continue_hb(_damper(**{par: start}), start, stop, parameter=par, gamma=1.4, harmonics=5, samples=128)
    assert br.status == "complete" and br.lam[-1] == stop
    for i in (br.lam.size // 3, br.lam.size - 1):
        ref = harmonic_balance(_damper(**{par: float(br.lam[i])}), 1.4, harmonics=5, samples=128, guess=br.X[i])
        assert ref.status.ok and ref.iterations <= 2
        assert np.allclose(ref.X, br.X[i], rtol=0, atol=1e-8 * np.abs(ref.X).max())


def test_downward_frequency_sweep_matches_upward():
    up = frc_hb(_jenkins_system(), 0.8, 1.6, harmonics=3)
    down = frc_hb(_jenkins_system(), 1.6, 0.8, harmonics=3)
    assert up.attrs["status"] == down.attrs["status"] == "complete"
    g = np.linspace(0.85, 1.55, 8)
    iu, idn = np.argsort(up.gamma.values), np.argsort(down.gamma.values)
    a_up = np.interp(g, up.gamma.values[iu], up.amplitude_m.values[iu])
    a_dn = np.interp(g, down.gamma.values[idn], down.amplitude_m.values[idn])
    assert np.allclose(a_up, a_dn, rtol=2e-2)


@pytest.mark.parametrize(
    "kwargs,name",
    [
        (dict(harmonics=0), "harmonics"),
        (dict(harmonics=7, samples=10), "samples"),
        (dict(gamma_start=1.0, gamma_stop=1.0), "gamma"),
        (dict(gamma_start=-0.5), "gamma_start"),
        (dict(gamma_stop=float("nan")), "gamma_stop"),
        (dict(response_dof=3), "response_dof"),
    ],
)
def test_bad_input_names_the_parameter(kwargs, name):
    args = dict(gamma_start=0.6, gamma_stop=1.8)
    args.update(kwargs)
    g0, g1 = args.pop("gamma_start"), args.pop("gamma_stop")
    with pytest.raises(ValueError, match=name):
        frc_hb(_jenkins_system(), g0, g1, **args)


def test_two_dof_contact_between_masses_equals_time_integration():
    from jointdyn.dynamics import steady_state
    from jointdyn.laws import Iwan
    from jointdyn.systems import Contact

    law = Iwan(kt=3e5, mu=0.5, n_ref=100.0)
    M = np.diag([10.0, 5.0])
    K = np.array([[5.9e5, -2e5], [-2e5, 2e5]])
    s = System(M=M, C=1e-4 * K, K=K, force=[40.0, 0.0],
               contacts=(Contact(law=law, dof=0, dof2=1, normal=HarmonicLoad(100.0, 30.0, math.degrees(0.4))),))
    for g in (1.0, 1.2):
        sol = harmonic_balance(s, g, harmonics=7, samples=256)
        ss = steady_state(s, g)
        assert sol.status.ok and sol.stable and ss.status == "periodic"
        assert abs(sol.amplitude_m - ss.amplitude_m) <= tolerances.TEST_HB_VS_TIME_RTOL * ss.amplitude_m


def test_fully_stuck_contact_gives_the_linear_solution():
    # slip force far above anything the forcing can reach: the contact is a
    # linear spring kt and HB must return the stuck linear solution exactly
    law = Jenkins(kt=KT, mu=1e6, n_ref=100.0)
    s = System.sdof(m=M, k=K, law=law, f1=F1, zeta=0.02)
    for g in (0.7, 1.3, 1.6):
        sol = harmonic_balance(s, g, harmonics=3, samples=64)
        w = g * math.sqrt(K / M)
        c = 2 * 0.02 * math.sqrt(K * M)
        A = F1 / math.hypot(K + KT - M * w * w, c * w)
        assert sol.status.ok and abs(sol.amplitude_m - A) <= 1e-10 * A


def test_fig6_hb_figure_from_saved_tables(tmp_path):
    import pandas as pd

    from jointdyn.figures.hb import _plot_fig6_hb, fig6_hb_data

    tables = fig6_hb_data(etas=(0.5,), betas=(2.0,), gamma=(0.8, 1.6), time_domain=False)
    hb = tables["hb"]
    assert {"gamma", "amplitude_q", "stable", "fold", "gap", "branch"} <= set(hb.columns)
    hb.to_csv(tmp_path / "hb.csv", index=False)
    paths = _plot_fig6_hb({"hb": pd.read_csv(tmp_path / "hb.csv")}, tmp_path)
    assert all(p.exists() and p.stat().st_size > 0 for p in paths)


def test_results_are_frozen():
    import dataclasses

    sol = harmonic_balance(_jenkins_system(), 1.2, harmonics=3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        sol.status = "not-converged"
    br = continue_hb(_jenkins_system(), 1.2, 1.3, harmonics=3, progress=False)
    with pytest.raises(dataclasses.FrozenInstanceError):
        br.status = "failed"
    assert br.status.ok and br.status == "complete"


def test_builtin_parameter_objects():
    from jointdyn.hb import DELTA, ETA, F1, GAMMA, N0, PARAMETERS, parameter_named

    assert PARAMETERS == ("gamma", "f1", "eta", "n0", "delta")
    assert [parameter_named(n) for n in PARAMETERS] == [GAMMA, F1, ETA, N0, DELTA]
    assert parameter_named(ETA) is ETA
    with pytest.raises(ValueError, match="parameter"):
        parameter_named("mu")
    s = _damper(eta=0.2, delta=40.0, n0=90.0)
    p = HBProblem(s, harmonics=2, samples=16, parameter="n0", gamma=1.3)
    co, d = N0.contact_loads(p, 120.0)  # the load rows hold the phase in radians
    assert np.allclose(co, [[120.0, 0.2 * 120.0, math.radians(40.0)]]) and np.allclose(d, [[1.0, 0.2, 0.0]])
    p = HBProblem(s, harmonics=2, samples=16, parameter="delta", gamma=1.3)
    co, d = DELTA.contact_loads(p, 90.0)  # the parameter in degrees
    assert np.allclose(co, [[90.0, 0.2 * 90.0, math.pi / 2]]) and np.allclose(d, [[0.0, 0.0, math.pi / 180]])
    assert GAMMA.frequency(p, 1.5) == (1.5 * p.w0, p.w0)
    with pytest.raises(ValueError, match="eta start"):
        ETA.check_range(-0.1, 1.0)


def test_system_parameter_continues_any_value_that_builds_a_system():
    # the static normal load as a generic parameter (central-difference dR/dp)
    # gives the same solutions as the built-in n0 (exact dR/dp)
    from jointdyn.hb import SystemParameter

    par = SystemParameter("load", lambda v: _damper(n0=v), lower=1.0)
    gen = continue_hb(_damper(n0=80.0), 80.0, 140.0, parameter=par, gamma=1.4, harmonics=5, progress=False)
    ref = continue_hb(_damper(n0=80.0), 80.0, 140.0, parameter="n0", gamma=1.4, harmonics=5, progress=False)
    assert gen.status.ok and gen.lam[-1] == 140.0 and gen.parameter == "load"
    assert np.allclose(gen.X[-1], ref.X[-1], rtol=0, atol=1e-8 * np.abs(ref.X[-1]).max())
    for i in (gen.lam.size // 2, gen.lam.size - 1):
        sol = harmonic_balance(_damper(n0=float(gen.lam[i])), 1.4, harmonics=5, guess=gen.X[i])
        assert sol.status.ok and sol.iterations <= 2
    # its dR/dp is a central difference of the exact one
    p_gen = HBProblem(_damper(n0=100.0), harmonics=5, parameter=par, gamma=1.4)
    p_ref = HBProblem(_damper(n0=100.0), harmonics=5, parameter="n0", gamma=1.4)
    X = gen.X[gen.lam.size // 2]
    e_gen, e_ref = p_gen.evaluate(X, 100.0), p_ref.evaluate(X, 100.0)
    assert np.array_equal(e_gen.R, e_ref.R)
    # (the law's forward mode carries one direction fewer without a load parameter: rounding)
    assert np.allclose(e_gen.JX, e_ref.JX, rtol=0, atol=1e-14 * np.abs(e_ref.JX).max())
    assert np.max(np.abs(e_gen.Jp - e_ref.Jp)) <= 1e-6 * np.max(np.abs(e_ref.Jp))
    with pytest.raises(ValueError, match="load start"):
        continue_hb(_damper(), 0.5, 2.0, parameter=par, gamma=1.4)


def test_system_parameter_in_the_friction_coefficient():
    from jointdyn.hb import SystemParameter
    from jointdyn.laws import Iwan

    def build(mu):
        return System.sdof(m=10.0, k=3.9e5, law=Iwan(kt=3e5, mu=mu, n_ref=100.0), f1=25.0, eta=0.3)

    par = SystemParameter("mu", build, scale_value=0.5, lower=0.0)
    br = continue_hb(build(0.6), 0.6, 0.3, parameter=par, gamma=1.3, harmonics=5, progress=False)
    assert br.status.ok and br.lam[-1] == 0.3
    sol = harmonic_balance(build(0.45), 1.3, harmonics=5)
    i = int(np.argmin(np.abs(br.lam - 0.45)))
    ref = harmonic_balance(build(float(br.lam[i])), 1.3, harmonics=5, guess=br.X[i])
    assert ref.status.ok and ref.iterations <= 2 and sol.status.ok

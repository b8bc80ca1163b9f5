"""The exact Iwan law (``iwan``) inside every solver.

* quasi-static driver: Fig 4-type loops (separation, load in quadrature)
  equal the discrete model at n = 4000 to its discretisation error;
* CLI ``jointdyn loop --model iwan``;
* time-domain steady states of the paper damper equal the discrete model
  (n = 1000) to its discretisation error; a small sweep is periodic
  everywhere and dissipates (no negative contact energy);
* harmonic balance: exact Jacobian (forward mode through ``step_jvp`` and
  ``init_jvp``) against central differences; a branch of the paper damper
  (eta 0.5, beta 2) is complete and agrees with the time domain.
"""

import json

import math

import numpy as np
import pytest

import tolerances as C
from jointdyn import DiscreteIwan, Iwan, System, harmonic_loop, make_law
from jointdyn.cli import main
from jointdyn.dynamics import steady_state
from jointdyn.hb import HBProblem, frc_hb, harmonic_balance
from jointdyn.sweeps import frc_sweep

KT, MU, N0, A = 1e5, 0.1, 100.0, 0.5e-3


@pytest.mark.parametrize("eta,delta", [(0.6, 0.0), (1.2, 0.0), (0.6, 90.0), (1.2, 90.0)])
def test_quasistatic_loops_equal_discrete_4000(eta, delta):
    """Without merges (large capacity) the loop is the discrete model's up
    to its O(1/n^2) error; the default capacity adds the merges' error."""
    exact = harmonic_loop(Iwan(kt=KT, mu=MU, n_ref=N0, capacity=4096), A, eta=eta, delta_deg=delta)
    default = harmonic_loop(make_law("iwan", kt=KT, mu=MU, n_ref=N0), A, eta=eta, delta_deg=delta)
    rd = harmonic_loop(DiscreteIwan(kt=KT, mu=MU, n_ref=N0, n=4000), A, eta=eta, delta_deg=delta)
    fy = MU * N0
    np.testing.assert_allclose(exact.T, rd.T, rtol=0, atol=C.TEST_EXACT_DISCRETE_4000_FY * fy)
    np.testing.assert_allclose(default.T, exact.T, rtol=0, atol=C.TEST_EXACT_MERGE_FY * fy)
    e, ed = exact.cycles["energy_J"].values, rd.cycles["energy_J"].values
    np.testing.assert_allclose(e, ed, rtol=C.TEST_EXACT_DISCRETE_4000_FY)
    assert default.law_name == "iwan"


def test_cli_loop(capsys):
    rc = main(["loop", "--json", "--model", "iwan", "--eta", "1.2", "--delta", "90", "--steps-per-cycle", "400"])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0 and d["model"] == "iwan"
    assert d["energy_J"] > 0 and d["separation_fraction"] > 0


@pytest.mark.parametrize("eta,beta,gamma", [(0.5, 2.0, 1.2), (1.5, 2.0, 1.1), (1.5, 10.0, 1.3)])
def test_steady_state_equals_discrete(eta, beta, gamma):
    tight = dict(amp_rtol=1e-8, energy_rtol=1e-7)
    r = steady_state(System.paper_damper(eta=eta, beta=beta, model="iwan"), gamma, **tight)
    rd = steady_state(System.paper_damper(eta=eta, beta=beta, model="discrete", n=1000), gamma, **tight)
    assert r.status == rd.status == "periodic"
    # discrete n = 1000 is within 3e-6 of the limit at these points (docs/exact-iwan.md)
    assert r.amplitude_q == pytest.approx(rd.amplitude_q, rel=1e-4)


def test_sweep_periodic_and_dissipating():
    ds = frc_sweep([0.8, 1.0, 1.15, 1.3, 1.6], etas=(0.5, 1.5), betas=(2.0,), model="iwan", n_workers=1,
                   progress=False)
    assert np.all(ds.status.values == 0)
    assert np.all(ds.energy_contact_J.values > 0)


@pytest.mark.parametrize("par", ["gamma", "eta", "f1"])
def test_hb_jacobian_matches_central_differences(par):
    sysm = System.paper_damper(eta=0.5, beta=2.0, model="iwan", delta_deg=math.degrees(0.3), zeta=0.01)
    g = 1.1
    p = HBProblem(sysm, harmonics=4, samples=128, parameter=par, gamma=None if par == "gamma" else g)
    lam = {"eta": 0.5, "gamma": g, "f1": p.f1_ref}[par]
    X = harmonic_balance(sysm, g, harmonics=4, samples=128).X
    ev = p.evaluate(X, lam)
    Ja = np.c_[ev.JX, ev.Jp]
    Jfd = np.empty_like(Ja)
    for j in range(X.size + 1):
        Xp, Xm, lp, lm = X.copy(), X.copy(), lam, lam
        if j < X.size:
            h = 1e-6 * np.abs(X).max()
            Xp[j] += h
            Xm[j] -= h
        else:
            h = 1e-6 * max(abs(lam), 1e-3)
            lp, lm = lam + h, lam - h
        Jfd[:, j] = (p.evaluate(Xp, lp).R - p.evaluate(Xm, lm).R) / (2 * h)
    assert np.max(np.abs(Ja - Jfd)) <= C.TEST_HB_JACOBIAN_RTOL * np.max(np.abs(Ja))


def test_hb_branch_complete_and_agrees_with_time_domain():
    sysm = System.paper_damper(eta=0.5, beta=2.0, model="iwan")
    ds = frc_hb(sysm, 0.6, 1.8, progress=False)
    assert ds.attrs["status"] == "complete"
    assert ds.gamma.values.min() <= 0.6 + 1e-9 and ds.gamma.values.max() >= 1.8 - 1e-9
    for g in (0.9, 1.2, 1.4):
        sol = harmonic_balance(sysm, g)
        ss = steady_state(sysm, g)
        assert sol.status.ok and ss.status == "periodic"
        assert sol.amplitude_m == pytest.approx(ss.amplitude_m, rel=C.TEST_HB_VS_TIME_RTOL)


def test_capacity_reaches_the_law_through_systems():
    law = Iwan(kt=3e5, mu=0.5, n_ref=100.0, capacity=8)
    sysm = System.sdof(m=10.0, k=3.9e5, law=law, f1=25.0, n0=100.0, eta=1.5)
    r = steady_state(sysm, 1.2)
    assert r.status == "periodic"
    assert r.restart.states.shape[1] == law.state_size

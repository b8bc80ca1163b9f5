"""Time integration of Systems with interfaces (docs/model.md section 10; issue 23, time domain).

Oracles: all pairs stuck is the linear structure with the springs kt, kt, kn in place, all pairs open
is the structure without them (exact linear steady states); a patch of pairs moving along t1 with
preloads and normal stiffnesses in common proportions is the discrete Iwan law under the same normal
spring (the same runner, the same steps: equal to rounding); the energy balance over a steady period;
the per-pair dissipation adds up to the contacts' total.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.cli import main
from jointdyn.dynamics import MarchOptions
from jointdyn.dynamics._model import make_model, sliders
from jointdyn.kinematics import NormalSpring

M = np.diag([1.0, 1.0, 1.0, 2.0])
K0 = np.array([[1.2e3, -0.2e3, 0.0, -0.5e3],
               [-0.2e3, 1.0e3, 0.0, 0.0],
               [0.0, 0.0, 0.5e3, 0.0],
               [-0.5e3, 0.0, 0.0, 1.5e3]])  # fmt: skip
PAIRS = [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1], [1, 0, -1, 3, -1, 2]]


def _system(itf, force=(1.0, 0.5, 0.3, 0.0), phase=(0.0, 90.0, 0.0, 0.0), K=K0):
    return jd.System(M=M, C=0.01 * K0, K=K, force=list(force), force_phase_deg=list(phase),
                     interfaces=(itf,) if itf is not None else (), w0_rad_s=30.0)  # fmt: skip


def _linear_amplitudes(system, w):
    """|X| of the exact linear steady state of the system (no contacts, no interfaces), m."""
    f = system.force * np.exp(1j * np.radians(system.force_phase_deg))
    X = np.linalg.solve(system.K - w * w * system.M + 1j * w * system.C, f)
    return np.abs(X)


def _pair_springs(itf, n):
    B = itf.selection(n)
    k = np.stack([itf.kt, itf.kt, itf.kn], axis=1).ravel()
    return B.T @ (k[:, None] * B)


@pytest.mark.parametrize("gamma", [0.8, 1.3])
def test_all_pairs_stuck_is_the_linear_structure_with_their_springs(gamma):
    itf = jd.Interface(kt=[400.0, 300.0, 250.0], kn=[800.0, 600.0, 700.0], mu=1e6, preload=5.0, pairs=PAIRS)
    s = _system(itf)
    lin = _system(None, K=K0 + _pair_springs(itf, 4))
    w = gamma * 30.0
    X = _linear_amplitudes(lin, w)
    for dof in (0, 3):
        r = jd.steady_state(s, gamma, steps_per_period=2048, response_dof=dof, amp_rtol=1e-12, energy_rtol=1e-9)
        assert r.status.ok, r.status
        assert abs(r.amplitude_m - X[dof]) <= 1e-9 * X[dof]
        np.testing.assert_array_equal(r.pair_stick, 1.0)
        np.testing.assert_array_equal(r.pair_slip, 0.0)


def test_all_pairs_open_is_the_structure_without_them():
    # no preload and the normal sides held at contact: N = max(0, 0) = 0, every pair open all the time
    pairs = [[0, 1, -1, -1, -1, -1], [3, -1, -1, 0, -1, -1]]
    itf = jd.Interface(kt=400.0, kn=800.0, mu=0.3, preload=0.0, pairs=pairs)
    s = _system(itf)
    X = _linear_amplitudes(_system(None), 1.1 * 30.0)
    r = jd.steady_state(s, 1.1, steps_per_period=2048, amp_rtol=1e-12, energy_rtol=1e-9)
    assert r.status.ok
    assert abs(r.amplitude_m - X[0]) <= 1e-9 * X[0]
    np.testing.assert_array_equal(r.pair_open, 1.0)
    np.testing.assert_array_equal(r.pair_energy_J, 0.0)


def _reduction_systems(n, force_n):
    """A tangential DOF 0 and a normal DOF 1: the discrete Iwan law (n elements) with a normal
    spring, and n pairs along t1 with P_i = P f_i, kn_i = kn f_i, kt_i = kt / n (the element's)."""
    kt, mu, P, kn = 2e3, 0.4, 1.0, 3e3
    Kb = np.array([[1e3, 0.0], [0.0, 2e3]])
    Mb = np.diag([1.0, 0.5])
    f = 2.0 * (np.arange(n) + 0.5) / n**2  # element i's share of the slip force: sums to 1
    law = jd.DiscreteIwan(kt=kt, mu=mu, n_ref=P, n=n)
    contact = jd.Contact(law=law, dof=0, normal=NormalSpring(kn=kn, preload=P, dof=1))
    kw = dict(M=Mb, C=0.01 * Kb, K=Kb, force=[0.2, force_n], force_phase_deg=[0.0, 60.0], w0_rad_s=40.0)
    iwan = jd.System(contacts=(contact,), **kw)
    itf = jd.Interface(kt=kt / n, kn=kn * f, mu=mu, preload=P * f, pairs=[[0, -1, 1, -1, -1, -1]] * n)
    return iwan, jd.System(interfaces=(itf,), **kw)


@pytest.mark.parametrize("force_n", [0.5, 3.0])  # the normal load varies; with 3.0 the patch opens
def test_one_dimensional_patch_is_the_discrete_iwan_law_under_a_normal_spring(force_n):
    """The same steps give the same response to rounding (measured without event splits: 3e-15 of the
    amplitude, 2e-15 of the contact energy). With them, while the patch stays closed, the only
    difference is that the pairs do not split the step at a reversal where none of them slips (the
    Iwan contact always does): measured 2e-10. Once it opens, the steps must split at the openings
    and closings (events on): a pair
    re-closing inside a step restarts virgin at the instant it closes on the straight path, the
    Iwan law at the step's end. With events on, the Iwan contact's steps also split where all its
    elements start slipping (bisection on its state) and its load is snapped at the located
    instants, which the pairs need not: the two then differ at the discretisation level (measured
    8e-7 of the amplitude, 2e-5 of the energy per period)."""
    iwan, patch = _reduction_systems(8, force_n)
    opened = force_n == 3.0
    for events, tol in ((True, 1e-5),) if opened else ((False, 1e-13), (True, 1e-8)):
        out = []
        for s in (iwan, patch):
            model = make_model(s, 40.0, MarchOptions(steps_per_period=256), events=events)
            x, v = np.zeros(2), np.zeros(2)
            S = model.initial_states(x)
            res = model.run_periods(x, v, S, 6, rec=True)
            out.append(res)
        a, b = out
        scale = np.max(np.abs(a.samples[1]))
        if not events or a.samples[1].shape == b.samples[1].shape:
            assert np.max(np.abs(a.samples[1] - b.samples[1])) <= tol * scale
        assert np.max(np.abs(a.z_end[:, :2] - b.z_end[:, :2])) <= tol * scale
        e_ref = abs(a.summary[0, 2])
        np.testing.assert_allclose(a.summary[:, 2], b.summary[:, 2], rtol=10 * tol, atol=10 * tol * e_ref)
    if opened:
        assert np.any(b.pairs[:, :, 3] > 0)  # the patch did open


def test_energy_balance_and_per_pair_results_over_a_steady_period():
    # 2-D slip (forcing in t1 and t2 90 degrees apart) and a varying normal load that opens some pairs
    itf = jd.Interface(kt=[400.0, 300.0, 250.0], kn=[800.0, 600.0, 700.0], mu=0.3, preload=[1.0, 0.5, 0.05],
                       pairs=PAIRS)  # fmt: skip
    s = _system(itf, force=(1.0, 1.0, 0.2, 0.0))
    r = jd.steady_state(s, 1.0, steps_per_period=1024, amp_rtol=1e-10, energy_rtol=1e-9)
    assert r.status.ok, r.status  # measured: balance 9e-12 of the work (1024 steps), 4e-14 with 4096
    W, Ec, Ev = r.work_force_J, r.energy_contact_J, r.energy_viscous_J
    assert Ec > 0.05 * W  # the pairs dissipate
    assert abs(W - Ec - Ev) <= 1e-8 * W
    assert abs(np.sum(r.pair_energy_J) - Ec) <= 1e-12 * W
    fr = r.pair_stick + r.pair_slip + r.pair_open
    np.testing.assert_allclose(fr, 1.0, rtol=1e-12)
    assert np.all(r.pair_slip > 0) and np.any(r.pair_open > 0)
    assert np.all(r.pair_energy_J > 0)


def test_interfaces_mix_with_contacts_and_warm_start():
    itf = jd.Interface(kt=400.0, kn=800.0, mu=0.3, preload=0.5, pairs=PAIRS[:2])
    contact = jd.Contact(law=jd.Jenkins(kt=300.0, mu=0.3, n_ref=1.0), dof=1, normal=jd.ConstantLoad(1.0))
    s = jd.System(M=M, C=0.01 * K0, K=K0, force=[1.0, 0.5, 0.3, 0.0], contacts=(contact,), interfaces=(itf,),
                  w0_rad_s=30.0)  # fmt: skip
    r = jd.steady_state(s, 1.0)
    assert r.status.ok
    model = make_model(s, 30.0, MarchOptions(steps_per_period=256))
    assert r.restart.states.shape == (model.pack.state_rows, model.pack.slen)
    assert sliders(model.pack, r.restart.states).shape == (2, 2)
    again = jd.steady_state(s, 1.0, start=r)
    assert again.status.ok and again.periods < r.periods
    assert again.amplitude_m == pytest.approx(r.amplitude_m, rel=1e-5)
    tr = jd.integrate(s, 1.0, periods=2)
    assert tr.status.ok and tr.T.shape[1] == 1


SYSTEM_FILE = """\
[structure]
M = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
K = [[1e3, 0.0, 0.0], [0.0, 1e3, 0.0], [0.0, 0.0, 1e3]]

[[force]]
dof = 0
amplitude = 0.5

[[interface]]
kt = 1.5e3
kn = 1.5e3
mu = 0.5
preload = 0.5
pairs = [[0, 1, 2, -1, -1, -1]]
"""


def test_cli_frc_time_domain_takes_interfaces(tmp_path, capsys):
    p = tmp_path / "sys.toml"
    p.write_text(SYSTEM_FILE)
    rc = main(["frc", "--system", str(p), "--gamma", "0.9:1.1:0.1", "--json", "--out", str(tmp_path / "out")])
    assert rc == 0, capsys.readouterr().err
    assert math.isfinite(float(np.loadtxt(tmp_path / "out" / "frc.csv", delimiter=",", skiprows=1, usecols=1,
                                          max_rows=1)))  # fmt: skip

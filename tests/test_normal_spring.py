"""Time integration with the normal load from the structure (issue 10).

Oracles: the prescribed-load model it reduces to when the normal DOF is light
and stays closed, the linear FRFs of the fully stuck and fully slipping
limits, the energy balance over a steady period, an independent event-located
integration through separation and re-contact (``reference_spring.py``), and
decoupled subsystems with different laws computed alone.
"""

import numpy as np
import pytest
from reference_spring import JenkinsSpringReference

import tolerances as C

import jointdyn as jd
from jointdyn.laws import make_law
from jointdyn.systems import PAPER

#: (eta, beta, delta_deg, gamma) on the paper's grid, eta < 1 (contact closed)
GRID_SUBSET = (
    (0.5, 1.0, 0.0, 1.0),
    (0.5, 2.0, 90.0, 0.8),
    (0.9, 5.0, 180.0, 1.2),
    (0.01, 1000.0, 0.0, 1.6),
    (0.5, 0.1, 45.0, 1.4),
    (0.9, 1.0, 270.0, 0.6),
    (0.5, 10.0, 135.0, 1.1),
)


@pytest.mark.parametrize("eta, beta, delta_deg, gamma", GRID_SUBSET)
def test_light_normal_dof_reproduces_the_prescribed_load(eta, beta, delta_deg, gamma):
    # normal force Fn = eta n0 < n0 on a light normal DOF: N follows
    # n0 (1 + eta sin(w t + delta)) up to the normal DOF's dynamics
    res = {}
    for normal in ("prescribed", "spring"):
        s = jd.System.paper_damper(eta=eta, beta=beta, delta_deg=delta_deg, normal=normal)
        res[normal] = jd.steady_state(s, gamma)
        assert res[normal].status == "periodic" and res[normal].period_multiple == 1
    p, q = res["prescribed"], res["spring"]
    assert q.amplitude_m == pytest.approx(p.amplitude_m, rel=C.TEST_SPRING_PRESCRIBED_RTOL)
    assert q.energy_contact_J == pytest.approx(p.energy_contact_J, rel=C.TEST_SPRING_PRESCRIBED_RTOL)


def _three_dof(law_name, mu):
    """Tangential DOF 0, normal DOF 1 on a closed spring, DOF 2 coupled to both; phased forcing."""
    M = np.diag([2.0, 0.5, 1.0])
    K = np.array([[4e5, 0.0, -1e5], [0.0, 2e5, -5e4], [-1e5, -5e4, 3e5]])
    kt, kn, P = 3e5, 3e5, 100.0
    spring = jd.NormalSpring(kn=kn, preload=P, dof=1)
    contact = jd.Contact(make_law(law_name, kt=kt, mu=mu, n_ref=P), dof=0, normal=spring)
    Kref = K + kn * np.outer(np.eye(3)[1], np.eye(3)[1])
    Cm = jd.modal_damping(M, Kref, 0.02)
    system = jd.System(M, Cm, K, contacts=(contact,), force=[20.0, 15.0, 10.0], force_phase_deg=[0.0, 60.0, -120.0])
    return system, Kref, kt


def _linear_response(system, Klin, w, t):
    """x(t), v(t) of the linear steady state under the system's phased forcing, and its amplitudes X."""
    F = system.force * np.exp(1j * np.radians(system.force_phase_deg))
    X = np.linalg.solve(Klin - w * w * system.M + 1j * w * system.C, F)
    z = np.exp(1j * w * np.asarray(t, dtype=float))[:, None] * X[None, :]
    return z.imag, (1j * w * z).imag, X


@pytest.mark.parametrize("law_name", ["jenkins", "iwan"])
@pytest.mark.parametrize("limit", ["stuck", "slipping"])
def test_stuck_and_slipping_limits_equal_the_linear_frf(law_name, limit):
    # mu large: the contact is the spring kt; mu tiny: no tangential force;
    # the normal spring stays closed (kn |g| <= 8.4 N < P): stiffness kn
    system, Kref, kt = _three_dof(law_name, 1e6 if limit == "stuck" else 1e-9)
    gamma = 1.1
    w = gamma * system.w0
    Klin = Kref.copy()
    if limit == "stuck":
        Klin[0, 0] += kt
    x0, v0, X = _linear_response(system, Klin, w, [0.0])
    offset = np.zeros(3)
    if limit == "stuck":  # the contact is virgin (unstretched) at x0: the orbit is shifted statically
        offset = np.linalg.solve(Kref, kt * np.eye(3)[0] * x0[0, 0])
    tr = jd.integrate(system, gamma, periods=2, x0=x0[0] + offset, v0=v0[0])
    kn_g = 3e5 * np.max(np.abs(tr.x[:, 1]))
    assert kn_g < 100.0
    err = np.max(np.abs(tr.x - _linear_response(system, Klin, w, tr.t)[0] - offset)) / np.max(np.abs(X))
    assert err < C.TEST_SPRING_LINEAR_RTOL


@pytest.mark.parametrize("model", ["iwan", "jenkins"])
@pytest.mark.parametrize("eta, beta, delta_deg, gamma", [GRID_SUBSET[0], GRID_SUBSET[2], GRID_SUBSET[4]])
def test_energy_balance_over_a_steady_period(model, eta, beta, delta_deg, gamma):
    # the spring is conservative (piecewise quadratic potential, also when it
    # opens): the forcing's work per period is dissipated by the contact and
    # the viscous dampers (normal DOF's included)
    s = jd.System.paper_damper(eta=eta, beta=beta, delta_deg=delta_deg, normal="spring", model=model)
    r = jd.steady_state(s, gamma)
    assert r.status == "periodic"
    assert r.energy_viscous_J > 0.0
    residual = r.work_force_J - r.energy_contact_J - r.energy_viscous_J
    assert abs(residual) <= C.TEST_SPRING_ENERGY_RTOL * r.work_force_J


def _separating_damper():
    """The coupled paper damper (Jenkins contact) whose normal force exceeds the preload: it opens."""
    s = jd.System.paper_damper(eta=1.5, beta=1.0, delta_deg=0.0, model="jenkins", normal="spring", zeta=0.02)
    ref = JenkinsSpringReference(s.M, s.C, s.K, s.force, s.force_phase_deg, s.w0, [1.0, 0.0], [0.0, 1.0],
                                 PAPER["kt"], PAPER["mu"], PAPER["kn"], PAPER["n0"])  # fmt: skip
    return s, ref


def _reference_error(s, ref, steps_per_period):
    tr = jd.integrate(s, 1.0, periods=3, steps_per_period=steps_per_period)
    xr, switches = ref.run(np.zeros(2), np.zeros(2), tr.t[-1], tr.t, xscale=1e-3)
    return np.max(np.abs(tr.x - xr), axis=0) / np.max(np.abs(xr), axis=0), xr, switches


def test_separation_and_recontact_against_an_independent_integration():
    s, ref = _separating_damper()
    err_fine, xr, switches = _reference_error(s, ref, 2000)
    # the contact did open (N = n0 + kn y < 0 in the reference) and close again
    gap_load = PAPER["n0"] + PAPER["kn"] * xr[:, 1]
    closing = (gap_load[:-1] < 0.0) & (gap_load[1:] >= 0.0)
    assert np.min(gap_load) < 0.0 and np.any(closing) and switches > 4
    # the normal DOF drifts while open (no stiffness of its own): millimetres
    assert np.max(np.abs(xr[:, 1])) > 1e-2
    assert np.all(err_fine < C.TEST_SPRING_REFERENCE_RTOL)
    # step-converged: the default step's error shrinks with the step
    err_default = _reference_error(s, ref, None)[0]
    assert np.all(err_fine < err_default)


def test_mixed_laws_in_one_system_equal_their_decoupled_parts():
    # a Jenkins contact on a normal spring (DOFs 0, 1) and an exact Iwan
    # contact with a prescribed harmonic load (DOF 2), structurally decoupled
    a = jd.System.paper_damper(eta=0.5, beta=1.0, delta_deg=30.0, normal="spring", model="jenkins", zeta=0.01)
    law_b = make_law("iwan", kt=2e5, mu=0.4, n_ref=80.0)

    def contact_b(dof):
        return jd.Contact(law_b, dof=dof, normal=jd.HarmonicLoad(80.0, 30.0, phase_deg=-45.0))

    b = jd.System(np.diag([8.0]), np.diag([30.0]), np.diag([3e5]), contacts=(contact_b(0),), force=[30.0],
                  force_phase_deg=[20.0])  # fmt: skip
    M, Cm, K = (np.zeros((3, 3)) for _ in range(3))
    M[:2, :2], Cm[:2, :2], K[:2, :2] = a.M, a.C, a.K
    M[2, 2], Cm[2, 2], K[2, 2] = 8.0, 30.0, 3e5
    ab = jd.System(M, Cm, K, contacts=(a.contacts[0], contact_b(2)), force=[*a.force, 30.0],
                   force_phase_deg=[*a.force_phase_deg, 20.0], w0_rad_s=a.w0)  # fmt: skip
    gamma, spp = 1.05, 2048
    whole = jd.integrate(ab, gamma, periods=3, steps_per_period=spp)
    for part, dofs, g in ((a, [0, 1], gamma), (b, [2], gamma * a.w0 / b.w0)):
        alone = jd.integrate(part, g, periods=3, steps_per_period=spp)
        # the same grid points; each part's reversals split the other's steps
        ta, tw = np.round(alone.t / alone.t[-1] * 1e12), np.round(whole.t / whole.t[-1] * 1e12)
        xa, xw = alone.x[np.isin(ta, tw)], whole.x[np.isin(tw, ta)][:, dofs]
        assert xa.shape[0] > 0.9 * alone.t.size
        err = np.max(np.abs(xw - xa), axis=0) / np.max(np.abs(xa), axis=0)
        assert np.all(err < C.TEST_MIXED_DECOUPLED_RTOL)

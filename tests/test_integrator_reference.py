"""The RK4 integrator against an independent reference (SciPy DOP853 at tight tolerance).

A test-only smooth contact law (defined here, compiled through
``jointdyn._jit.jit``, a :class:`ContactLaw` subclass that is not
registered): T = alpha fy tanh(kt u / fy), alpha = N / n_ref, an elastic
spring that saturates at the slip force. It has no memory and no kinks, so
the equations of motion are smooth and the integrator must show its
fourth order; the reference (``tests/reference_dynamics.py``) integrates
the same equations without any of jointdyn's machinery.
"""

import math
from dataclasses import dataclass

import numpy as np

import tolerances
from jointdyn._jit import jit
from jointdyn.dynamics import integrate
from jointdyn.dynamics._model import pack_system
from jointdyn.laws import SEPARATION, STICK_SLIP, ContactLaw, law_names
from jointdyn.systems import Contact, System
from reference_dynamics import integrate_reference


@jit
def tanh_step(params, s_old, s_new, x, N):  # pragma: no cover - compiled
    """T = (N / n_ref) fy tanh(kt x / fy); state: the last displacement."""
    kt, fy, n_ref = params[0], params[1], params[2]
    s_new[0] = x
    if N <= 0.0:
        return 0.0, 0.0, SEPARATION
    th = math.tanh(kt * x / fy)
    return N / n_ref * fy * th, N / n_ref * kt * (1.0 - th * th), STICK_SLIP


@jit
def tanh_init(params, x0, n0, s):  # pragma: no cover - compiled
    s[0] = x0


@dataclass(frozen=True)
class TanhSpring(ContactLaw):
    """Smooth saturating spring (test only, not registered)."""

    @property
    def step(self):
        return tanh_step

    @property
    def init(self):
        return tanh_init

    @property
    def params(self):
        return np.array([self.kt, self.fy, self.n_ref])

    @property
    def state_size(self):
        return 1

    @property
    def x_slip(self):
        return self.fy / self.kt


def _tanh_force(law):
    return lambda u, N: N / law.n_ref * law.fy * math.tanh(law.kt * u / law.fy)


def _system():
    # two DOFs, a contact between them with a harmonic normal load that
    # never opens (smooth), forcing on both DOFs; resonance near the forcing
    law = TanhSpring(kt=2e5, mu=0.5, n_ref=100.0)
    M = np.diag([1.0, 0.5])
    K = np.array([[3e5, -1e5], [-1e5, 1e5]])
    C = 2e-5 * K + 0.5 * M
    c = Contact(law=law, dof=0, dof2=1, n0=100.0, n1=30.0, delta=0.5)
    return System(M=M, C=C, K=K, contacts=(c,), force=[40.0, 25.0])


def _error(system, gamma, periods, spp):
    """Largest |x - x_ref| relative to max |x| over the run, and the run."""
    tr = integrate(system, gamma, periods=periods, steps_per_period=spp)
    c = system.contacts[0]
    b = np.array([1.0, -1.0])
    xs = float(np.max(np.abs(tr.x)))
    xr, vr = integrate_reference(system.M, system.C, system.K, system.force, gamma * system.w0,
                                 [(b, _tanh_force(c.law), c.n0, c.n1, c.delta)], tr.t, xscale=xs)  # fmt: skip
    return float(np.max(np.abs(xr - tr.x))) / xs, float(np.max(np.abs(vr - tr.v))) / float(np.max(np.abs(tr.v))), tr


def test_test_law_is_not_registered():
    assert "tanh" not in " ".join(law_names()) and TanhSpring.name == "base"


def test_rk4_agrees_with_dop853_to_its_truncation_error():
    system = _system()
    gamma, periods = 1.1, 3
    w = gamma * system.w0
    errs = []
    for spp in (128, 256, 512):
        ex, ev, tr = _error(system, gamma, periods, spp)
        assert tr.status == "ok" and np.all(tr.code == STICK_SLIP)
        errs.append((ex, ev))
        # bound: RK4 advances a free oscillation of frequency W with a phase
        # error of (W h)^5 / 120 per step, (W h)^4 W t / 120 over a time t
        # (the amplitude error is of higher order); the stiffest mode w_max
        # errs most, so this holds for any mix of modes (here the response
        # sits near the forcing frequency and the error is far below it)
        h = 2 * math.pi / w / spp
        w_max = pack_system(system).w_max
        bound = (w_max * h) ** 4 * w_max * tr.t[-1] / 120.0
        assert ex <= bound and ev <= bound, (spp, ex, ev, bound)
    # fourth order: halving the step divides the error by ~16 (the
    # reference's own error, ~1e-12, is 1000x below the finest one)
    for (e1, v1), (e2, v2) in zip(errs, errs[1:]):
        lo, hi = tolerances.TEST_TI_ORDER_RATIO
        assert lo <= e1 / e2 <= hi and lo <= v1 / v2 <= hi, (e1 / e2, v1 / v2)
    assert errs[-1][0] <= tolerances.TEST_TI_REFERENCE_RTOL


def test_contact_force_is_the_law_at_the_recorded_state():
    # the recorded T is the law at the recorded relative displacement and load
    system = _system()
    tr = integrate(system, 0.8, periods=2)
    law = system.contacts[0].law
    T = np.array([_tanh_force(law)(x[0] - x[1], N) for x, N in zip(tr.x, tr.N[:, 0])])
    assert np.max(np.abs(T - tr.T[:, 0])) <= 1e-12 * law.fy

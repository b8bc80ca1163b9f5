"""The compiled periodicity test of steady_state against a plain-numpy reference.

``_periodic_arrays`` (compiled, called for every candidate multiple p after
every chunk of periods) must take the same decision as the straightforward
array formulation below on histories near and far from periodic.
"""

import dataclasses

import numpy as np

from jointdyn.dynamics import SteadyStateOptions
from jointdyn.dynamics._core import N_SUMMARY, S_EC, S_EV, S_W, S_XMAX, S_XMIN
from jointdyn.dynamics import MarchOptions
from jointdyn.dynamics._model import make_model
from jointdyn.dynamics.steady import _History, _check_periodic
from jointdyn.systems import System


def _reference(summ, Z, p, K, n, w, K_stuck, M, floor, amp_rtol, energy_rtol, balance_rtol):
    P = summ.shape[0]
    if P < K * p:
        return False
    S = summ[P - K * p:].reshape(K, p, N_SUMMARY)
    Zw = Z[P - K * p:]
    amps = 0.5 * (S[:, :, S_XMAX].max(axis=1) - S[:, :, S_XMIN].min(axis=1))
    es = (S[:, :, S_EC] + S[:, :, S_EV]).mean(axis=1)
    ws = S[:, :, S_W].mean(axis=1)
    A = float(amps.max())
    xs = max(A, floor)
    if A - amps.min() > amp_rtol * xs:
        return False
    dz = np.abs(Zw[p::p][:K] - Zw[:-1:p][:K])
    if dz[:, :n].max() > amp_rtol * xs or dz[:, n:].max() > amp_rtol * xs * max(w, 1e-300):
        return False
    zl = Zw[-1]
    stored = 0.5 * (zl[:n] @ K_stuck @ zl[:n] + zl[n:] @ M @ zl[n:])
    stored = max(stored, 0.5 * float(np.max(np.diag(K_stuck))) * A * A)
    flow = max(np.abs(ws).max(), np.abs(es).max())
    etol = max(energy_rtol * flow, amp_rtol * stored, 1e-300)
    if es.max() - es.min() > etol or ws.max() - ws.min() > etol:
        return False
    btol = max(balance_rtol * flow, amp_rtol * stored)
    return not abs(ws.mean() - es.mean()) > btol


def test_compiled_periodicity_check_equals_reference():
    system = System.paper_damper(eta=0.5, beta=2.0)
    model = make_model(system, 1.1 * system.w0, MarchOptions(steps_per_period=64))
    rng = np.random.default_rng(7)
    defaults = SteadyStateOptions()
    amp_rtol, energy_rtol = defaults.amp_rtol, defaults.energy_rtol
    outcomes = set()
    for case in range(3000):
        periods = int(rng.integers(1, 30))
        p = int(rng.integers(1, 5))
        K = int(rng.integers(2, 5))
        A = 10.0 ** rng.uniform(-6, -3)
        E = 10.0 ** rng.uniform(-3, 1)
        # a p-periodic pattern plus noise whose size straddles the tolerances
        base = rng.uniform(0.5, 1.0, size=(p, 3))
        noise = 10.0 ** rng.uniform(-7, -2)
        summ = np.zeros((periods, N_SUMMARY))
        Z = np.zeros((periods + 1, 2))
        pattern_z = rng.normal(size=(p, 2)) * [A, A * model.w]
        for k in range(periods + 1):
            Z[k] = pattern_z[k % p] * (1 + noise * rng.normal(size=2))
        for k in range(periods):
            b = base[k % p]
            summ[k, S_XMAX] = A * b[0] * (1 + noise * rng.normal())
            summ[k, S_XMIN] = -A * b[0] * (1 + noise * rng.normal())
            summ[k, S_EC] = E * b[1] * (1 + noise * rng.normal())
            summ[k, S_EV] = 0.1 * E * b[1] * (1 + noise * rng.normal())
            summ[k, S_W] = 1.1 * E * b[1] * (1 + (noise + rng.choice([0.0, 0.05])) * rng.normal())
        h = _History(Z[0])
        h.add(summ, Z[1:])
        got = _check_periodic(h, p, model, dataclasses.replace(defaults, check_periods=K))
        floor = 1e-14 + 1e-9 * sum(c.law.fy / c.law.kt for c in system.contacts)
        want = _reference(h.summ, h.Z, p, K, model.n, model.w, model.pack.K_stuck, system.M, floor,
                          amp_rtol, energy_rtol, defaults.balance_rtol)  # fmt: skip
        assert got == want, f"case {case}"
        outcomes.add(got)
    assert outcomes == {True, False}

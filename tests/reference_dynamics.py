"""Plain reference integration of a forced structure with memoryless contacts.

Written from the equation of motion (docs/model.md section 6, systems.py),
independently of jointdyn's integrator: no step grid, no events, no
trial/commit law states, no Numba. The contact law is any smooth function
T(u, N) of the tangential displacement and the normal load (an elastic law
has no memory, so the state of the ODE is (x, v) alone), and SciPy's
adaptive DOP853 (order 8) integrates to a tolerance far below the RK4
truncation error of the integrator under test. Oracle of
``test_integrator_reference.py``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

#: tolerances of the reference integration (relative; absolute in units of
#: the largest displacement resp. velocity scale given by the caller)
REF_RTOL = 1e-12
REF_ATOL_REL = 1e-14


def integrate_reference(M, C, K, force, w, contacts, t_eval, *, x0=None, v0=None, xscale=1.0):
    """x(t), v(t) of M x'' + C x' + K x = f sin(w t) - sum_c b_c T_c(b_c . x, N_c(t)).

    Parameters
    ----------
    M, C, K : ndarray (n, n)
        Mass (kg), damping (N s/m) and stiffness (N/m) matrices.
    force : ndarray (n,)
        Forcing amplitudes f, N.
    w : float
        Forcing frequency, rad/s.
    contacts : list of (b, law, n0, n1, delta)
        Selection row b (n,), a callable ``law(u, N) -> T`` (m, N -> N) and
        the harmonic normal load N = n0 + n1 sin(w t + delta) (N, N, rad).
    t_eval : ndarray
        Output times, s (increasing, from 0).
    x0, v0 : ndarray, optional
        Initial state (m, m/s); default rest.
    xscale : float
        Displacement scale (m) of the absolute tolerance (velocities: w xscale).

    Returns
    -------
    x, v : ndarray (len(t_eval), n)
    """
    M = np.asarray(M, dtype=float)
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    f = np.asarray(force, dtype=float)

    def rhs(t, y):
        x, v = y[:n], y[n:]
        r = f * math.sin(w * t) - C @ v - K @ x
        for b, law, n0, n1, delta in contacts:
            r = r - b * law(float(b @ x), n0 + n1 * math.sin(w * t + delta))
        return np.concatenate([v, Minv @ r])

    y0 = np.concatenate([np.zeros(n) if x0 is None else x0, np.zeros(n) if v0 is None else v0])
    atol = REF_ATOL_REL * np.concatenate([np.full(n, xscale), np.full(n, xscale * w)])
    sol = solve_ivp(rhs, (0.0, float(t_eval[-1])), y0, method="DOP853", rtol=REF_RTOL, atol=atol, t_eval=t_eval)
    if not sol.success:
        raise RuntimeError(f"reference integration failed: {sol.message}")
    return sol.y[:n].T, sol.y[n:].T

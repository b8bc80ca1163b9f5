"""Plain reference integration of a structure with a Jenkins contact on a unilateral normal spring.

Written from the equations of motion (docs/model.md section 8), independently
of jointdyn's integrator (no step grid, no trial/commit law states, no
Numba): a hybrid system integrated by SciPy's adaptive DOP853 between
events located by ``solve_ivp``, with the contact in one of four modes::

    M x'' + C x' + K x + bt T + bn (N - P) = f sin(w t + phi),
    g = bn . x,  u = bt . x,  N = P + kn g (closed),

    OPEN      N = 0, T = 0                     -> STICK at P + kn g = 0 rising
    STICK     T = kt (u - z), z fixed          -> SLIP(+-1) at kt (u - z) = +-mu N,
                                                  OPEN at P + kn g = 0 falling
    SLIP(s)   T = s mu N, z' = u' - s mu N'/kt -> STICK at s z' = 0 falling,
                                                  OPEN at P + kn g = 0 falling

z is the slider position of the Jenkins element (spring kt in series with a
slider whose limit mu N follows the normal load): exact for any normal-load
history, the element re-contacts unstretched (virgin) and slips when a
falling load reaches its force. Oracle of ``test_normal_spring.py``.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

OPEN, STICK, SLIP_POS, SLIP_NEG = 0, 1, 2, 3
REF_RTOL = 1e-11


class JenkinsSpringReference:
    """The hybrid system above; ``run`` integrates it from a state at t = 0.

    Parameters
    ----------
    M, C, K : ndarray (n, n)
        Mass (kg), damping (N s/m), stiffness (N/m).
    force, phase_deg : ndarray (n,)
        Forcing amplitudes (N) and phases (degrees).
    w : float
        Forcing frequency, rad/s.
    bt, bn : ndarray (n,)
        Tangential and normal selection rows.
    kt, mu, kn, P : float
        Jenkins stiffness (N/m), friction coefficient, normal stiffness
        (N/m), preload (N).
    """

    def __init__(self, M, C, K, force, phase_deg, w, bt, bn, kt, mu, kn, P):
        self.Minv = np.linalg.inv(np.asarray(M, dtype=float))
        self.C, self.K = np.asarray(C, dtype=float), np.asarray(K, dtype=float)
        self.f = np.asarray(force, dtype=float)
        self.phi = np.radians(np.asarray(phase_deg, dtype=float))
        self.w, self.bt, self.bn = w, np.asarray(bt, dtype=float), np.asarray(bn, dtype=float)
        self.kt, self.mu, self.kn, self.P = kt, mu, kn, P
        self.n = self.Minv.shape[0]

    def _forces(self, y, mode):
        """(T, N) in ``mode`` at the state y = (x, v, z)."""
        n = self.n
        x = y[:n]
        N = self.P + self.kn * (self.bn @ x)
        if mode == OPEN:
            return 0.0, 0.0
        if mode == STICK:
            return self.kt * (self.bt @ x - y[2 * n]), N
        return (1.0 if mode == SLIP_POS else -1.0) * self.mu * N, N

    def _rhs(self, t, y, mode):
        n = self.n
        x, v = y[:n], y[n : 2 * n]
        T, N = self._forces(y, mode)
        F = self.f * np.sin(self.w * t + self.phi)
        a = self.Minv @ (F - self.C @ v - self.K @ x - self.bt * T - self.bn * (N - self.P))
        dz = 0.0
        if mode in (SLIP_POS, SLIP_NEG):
            s = 1.0 if mode == SLIP_POS else -1.0
            dz = self.bt @ v - s * self.mu * self.kn * (self.bn @ v) / self.kt
        return np.concatenate([v, a, [dz]])

    def _events(self, mode):
        """(event functions, next mode of each) of ``mode``."""
        n = self.n

        def gap(t, y, *_):
            return self.P + self.kn * (self.bn @ y[:n])

        if mode == OPEN:
            gap.direction = 1.0
            return [gap], [STICK]
        gap.direction = -1.0
        if mode == STICK:
            def up(t, y, *_):
                return self.kt * (self.bt @ y[:n] - y[2 * n]) - self.mu * gap(t, y)

            def down(t, y, *_):
                return self.kt * (self.bt @ y[:n] - y[2 * n]) + self.mu * gap(t, y)

            up.direction, down.direction = 1.0, -1.0
            return [gap, up, down], [OPEN, SLIP_POS, SLIP_NEG]
        s = 1.0 if mode == SLIP_POS else -1.0

        def stop(t, y, *_):
            return s * self._rhs(t, y, mode)[2 * n]

        stop.direction = -1.0
        return [gap, stop], [OPEN, STICK]

    def run(self, x0, v0, t_end, t_eval, *, xscale):
        """x(t_eval) (m) from (x0, v0) at t = 0, contact closed and virgin (z = u)."""
        n = self.n
        y = np.concatenate([x0, v0, [self.bt @ x0]])
        mode = STICK if self.P + self.kn * (self.bn @ x0) > 0 else OPEN
        atol = np.concatenate([np.full(n, 1e-13 * xscale), np.full(n, 1e-13 * xscale * self.w), [1e-13 * xscale]])
        t, out, switches = 0.0, np.full((len(t_eval), n), np.nan), 0
        while t < t_end:
            funcs, nxt = self._events(mode)
            for f in funcs:
                f.terminal = True
            mask = (t_eval >= t) & (t_eval <= t_end)
            sol = solve_ivp(self._rhs, (t, t_end), y, method="DOP853", rtol=REF_RTOL, atol=atol, events=funcs,
                            args=(mode,), dense_output=True)
            if not sol.success:
                raise RuntimeError(sol.message)
            t1 = sol.t[-1]
            sel = mask & (t_eval <= t1)
            if np.any(sel):
                out[sel] = sol.sol(t_eval[sel])[:n].T
            y = sol.y[:, -1].copy()
            hit = [k for k, te in enumerate(sol.t_events) if te.size]
            if not hit:
                break
            k = min(hit, key=lambda kk: sol.t_events[kk][0])
            if mode == OPEN:  # re-contact: the element starts unstretched (virgin)
                y[2 * n] = self.bt @ y[:n]
            mode, t = nxt[k], t1
            switches += 1
        return out, switches

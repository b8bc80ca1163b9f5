"""Harmonic-balance residual of a :class:`~jointdyn.systems.System`.

Equation of motion (MODEL.md section 6, generalised in ``systems.py``)::

    M x'' + C x' + K x + sum_c B_c T_c(u_c, N_c) = f sin(w t),
    u_c = B_c^T x,   N_c(t) = n0_c + n1_c sin(w t + delta_c).

In normalised time tau = w t, x(tau) = sum_h Q_h(tau) X_h with the real
Fourier basis Q = (1, cos tau, sin tau, ..., cos H tau, sin H tau); the
normal load N_c(tau) does not depend on w. Galerkin projection on the same
basis gives, for harmonic k (coefficients a_k of cos, b_k of sin)::

    (K - k^2 w^2 M) a_k + k w C b_k + F_a,k(X) = 0
    (K - k^2 w^2 M) b_k - k w C a_k + F_b,k(X) = f delta_{k1}

and K a_0 + F_0(X) = 0 for the constant term (the offset). F(X) are the
Fourier coefficients of the contact forces, evaluated by alternating
frequency-time (:mod:`jointdyn.hb._aft`) with exact forward-mode
Jacobians. The unknowns are ordered harmonic-major:
``X[h * n + i]`` is coefficient h of DOF i.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .. import config
from ..systems import Contact, System
from ._aft import _aft_kernel, aft_contact, fourier_matrices

__all__ = ["HBProblem", "PARAMETERS"]

#: scalar parameters that harmonic balance can be continued in
PARAMETERS = ("gamma", "f1", "eta", "n0", "delta")


@dataclass
class _Eval:
    R: np.ndarray
    JX: np.ndarray
    Jp: np.ndarray
    T: list
    code: list
    info: np.ndarray


class HBProblem:
    """Harmonic-balance residual R(X, p) and its exact Jacobian.

    Parameters
    ----------
    system : System
        Structure, contacts and forcing.
    harmonics : int
        Highest harmonic H (>= 1); the constant term is always included.
    samples : int
        Time samples per period for the AFT (>= 2H + 2).
    parameter : str
        Continuation parameter, one of :data:`PARAMETERS`: ``gamma``
        (w / w0), ``f1`` (forcing amplitude: the force vector is scaled so
        that its largest entry is f1, N), ``eta`` (N1/N0 of every contact),
        ``n0`` (static normal load of every contact, N; eta kept) or
        ``delta`` (phase of every contact's normal load, rad).
    gamma : float, optional
        Fixed w / w0 when the parameter is not ``gamma``.
    max_passes : int
        Bound on the periods marched per AFT evaluation.
    """

    def __init__(self, system: System, *, harmonics: int = 7, samples: int = 128,
                 parameter: str = "gamma", gamma: float | None = None,
                 max_passes: int = config.HB_MAX_PASSES):
        if not isinstance(system, System):
            raise ValueError("system must be a jointdyn.System")
        self.H = V.positive_int("harmonics", harmonics, 1)
        self.Ns = V.positive_int("samples", samples, 2 * self.H + 2)
        self.parameter = V.choice("parameter", parameter, PARAMETERS)
        if parameter != "gamma":
            if gamma is None:
                raise ValueError("gamma must be given (> 0) when the parameter is not gamma")
            self.gamma_fixed = V.positive("gamma", gamma)
        else:
            self.gamma_fixed = None
        self.max_passes = V.positive_int("max_passes", max_passes, 2)
        self.system = system
        self.n = system.ndof
        self.nh = 2 * self.H + 1
        self.size = self.n * self.nh
        self.w0 = system.w0
        if not self.w0 > 0:
            raise ValueError("system must have a positive lowest natural frequency w0 (K positive definite)")
        self.E, self.P = fourier_matrices(self.H, self.Ns)
        self.tau = 2.0 * np.pi * np.arange(self.Ns) / self.Ns
        self._fine = {}
        self._lin = None
        self._params = [c.law.params for c in system.contacts]
        self._kernels = [_aft_kernel(c.law) for c in system.contacts]
        self.contacts = list(system.contacts)
        fmax = float(np.max(np.abs(system.force))) if system.force.size else 0.0
        self.f_dir = system.force / fmax if fmax > 0 else system.force.copy()
        self.f1_ref = fmax
        # contact selection vectors B_c (dof minus dof2)
        self.B = []
        for c in self.contacts:
            b = np.zeros(self.n)
            b[c.dof] += 1.0
            if c.dof2 >= 0:
                b[c.dof2] -= 1.0
            self.B.append(b)

    # --- parameter handling -------------------------------------------------
    def parameter_value(self) -> float:
        """Current value of the continuation parameter in ``system``."""
        p = self.parameter
        if p == "gamma":
            return float("nan")
        if p == "f1":
            return self.f1_ref
        c = self.contacts[0]
        return {"eta": c.eta, "n0": c.n0, "delta": c.delta}[p]

    def _split(self, p):
        """(w, f, contact loads [(n0, n1, delta)], dN/dp per contact or None)."""
        par = self.parameter
        gamma = p if par == "gamma" else self.gamma_fixed
        w = gamma * self.w0
        f = self.f_dir * (p if par == "f1" else self.f1_ref)
        loads = []
        for c in self.contacts:
            n0, n1, dl = c.n0, c.n1, c.delta
            dn = None
            if par == "eta":
                n1 = p * n0
                dn = n0 * np.sin(self.tau + dl)
            elif par == "n0":
                eta = c.eta
                n0, n1 = p, eta * p
                dn = 1.0 + eta * np.sin(self.tau + dl)
            elif par == "delta":
                dl = p
                dn = n1 * np.cos(self.tau + dl)
            loads.append((n0, n1, dl, dn))
        return w, f, loads

    def normal_loads(self, p):
        """Normal-load samples N_c(tau_j) per contact, N."""
        _, _, loads = self._split(p)
        return [n0 + n1 * np.sin(self.tau + dl) for (n0, n1, dl, _) in loads]

    # --- linear part --------------------------------------------------------
    def _linear_parts(self):
        """A(w) = A_K + w A_C + w^2 A_M (built once)."""
        if getattr(self, "_lin", None) is None:
            n = self.n
            M, C, K = self.system.M, self.system.C, self.system.K
            AK = np.kron(np.eye(self.nh), K)
            AC = np.zeros((self.size, self.size))
            AM = np.zeros((self.size, self.size))
            for k in range(1, self.H + 1):
                ic = (2 * k - 1) * n
                is_ = 2 * k * n
                AM[ic:ic + n, ic:ic + n] = -(k * k) * M
                AM[is_:is_ + n, is_:is_ + n] = -(k * k) * M
                AC[ic:ic + n, is_:is_ + n] = k * C
                AC[is_:is_ + n, ic:ic + n] = -k * C
            self._lin = (AK, AC, AM)
        return self._lin

    def linear_matrix(self, w):
        """Block matrix A(w) of the linear terms (size n(2H+1)): per harmonic k
        ``[[K - k^2 w^2 M, k w C], [-k w C, K - k^2 w^2 M]]``, K for k = 0."""
        AK, AC, AM = self._linear_parts()
        return AK + w * AC + (w * w) * AM

    def linear_matrix_dw(self, w):
        """dA/dw."""
        _, AC, AM = self._linear_parts()
        return AC + (2.0 * w) * AM

    def forcing(self, f):
        """Coefficient vector of f sin(tau)."""
        Fe = np.zeros(self.size)
        Fe[2 * self.n:3 * self.n] = f
        return Fe

    def linear_guess(self, p, stuck: bool = True):
        """Linear response with every contact stuck (stiffness kt) or absent.

        Used to start Newton and continuation (MODEL.md section 6: all
        stuck -> linear system with K + kt).
        """
        w, f, _ = self._split(p)
        A = self.linear_matrix(w)
        if stuck:
            for c, b in zip(self.contacts, self.B):
                Kc = c.law.kt * np.outer(b, b)
                for h in range(self.nh):
                    A[h * self.n:(h + 1) * self.n, h * self.n:(h + 1) * self.n] += Kc
        return np.linalg.solve(A, self.forcing(f))

    # --- residual -----------------------------------------------------------
    def evaluate(self, X, p) -> _Eval:
        """Residual R (N), dR/dX (N/m) and dR/dp at coefficients X and parameter p."""
        w, f, loads = self._split(p)
        A = self.linear_matrix(w)
        R = A @ X - self.forcing(f)
        JX = A.copy()
        if self.parameter == "gamma":
            Jp = self.linear_matrix_dw(w) @ X * self.w0
        elif self.parameter == "f1":
            Jp = -self.forcing(self.f_dir)
        else:
            Jp = np.zeros(self.size)
        Xm = X.reshape(self.nh, self.n)
        Ts, codes = [], []
        info = np.zeros(3)
        info[2] = 1.0
        for c, b, (n0, n1, dl, dn), prm, krn in zip(self.contacts, self.B, loads, self._params, self._kernels):
            U = Xm @ b
            Nsamp = n0 + n1 * np.sin(self.tau + dl)
            F, dFdU, dFdp, T, code, inf = aft_contact(c.law, self.E, self.P, U, Nsamp, dn,
                                                      max_passes=self.max_passes,
                                                      rtol=config.HB_PERIODIC_RTOL, params=prm, kernel=krn)
            # scatter: R[h*n + i] += b_i F_h ; JX[(h,i),(g,j)] += b_i b_j dF_hg
            if self.n == 1:
                R += F * b[0]
                JX += dFdU * (b[0] * b[0])
                if dFdp is not None:
                    Jp += dFdp * b[0]
            else:
                R += (F[:, None] * b[None, :]).ravel()
                bb = np.outer(b, b)
                JX += (dFdU[:, None, :, None] * bb[None, :, None, :]).reshape(self.size, self.size)
                if dFdp is not None:
                    Jp += (dFdp[:, None] * b[None, :]).ravel()
            Ts.append(T)
            codes.append(code)
            info[0] = max(info[0], inf[0])
            info[1] = max(info[1], inf[1])
            # worst case over the contacts: 0 (not repeated) < 2 < 1
            rank = {1.0: 2, 2.0: 1, 0.0: 0}
            if rank[float(inf[2])] < rank[float(info[2])]:
                info[2] = inf[2]
        return _Eval(R, JX, Jp, Ts, codes, info)

    # --- post-processing ----------------------------------------------------
    def reconstruct(self, X, dof: int, points: int = 1024):
        """x_dof(tau) on a fine grid of ``points`` samples over one period, m."""
        Ef = self._fine.get(points)
        if Ef is None:
            Ef = self._fine[points] = fourier_matrices(self.H, points)[0]
        return Ef @ X.reshape(self.nh, self.n)[:, dof]

    @staticmethod
    def _peak(x, i):
        """Parabolic refinement of the grid extremum x[i] (periodic samples).

        The error of the vertex of the parabola through three samples is
        O(h^4) for a smooth peak: with 1024 samples per period about 1e-9
        of the amplitude (the raw grid value is up to 5e-6 off).
        """
        n = x.size
        xm, x0, xp = x[(i - 1) % n], x[i], x[(i + 1) % n]
        den = xm - 2.0 * x0 + xp
        if den == 0.0:
            return float(x0)
        return float(x0 - 0.125 * (xp - xm) ** 2 / den)

    def amplitudes(self, X, dof: int):
        """(half peak-to-peak, mean, max |x|) of x_dof(t), m.

        Extrema located on 1024 samples per period and refined by a
        parabola through the three samples around each.
        """
        x = self.reconstruct(X, dof)
        hi = max(self._peak(x, int(np.argmax(x))), float(x.max()))
        lo = min(self._peak(x, int(np.argmin(x))), float(x.min()))
        c0 = float(X.reshape(self.nh, self.n)[0, dof])
        return 0.5 * (hi - lo), c0, max(abs(hi), abs(lo))

    def first_harmonic_amplitude(self, X, dof: int) -> float:
        """sqrt(a_1^2 + b_1^2) of DOF ``dof``, m."""
        Xm = X.reshape(self.nh, self.n)
        return math.hypot(Xm[1, dof], Xm[2, dof])

    def omega(self, p) -> float:
        """Angular frequency w (rad/s) at parameter p."""
        return (p if self.parameter == "gamma" else self.gamma_fixed) * self.w0


def contact_of(system: System) -> Contact:
    """First contact of the system (reference for q = kt x / fy)."""
    if not system.contacts:
        raise ValueError("system must have at least one contact")
    return system.contacts[0]

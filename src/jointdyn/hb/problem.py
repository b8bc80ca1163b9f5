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
from .._jit import jit
from ..laws.discrete import discrete_init, discrete_step_jvp
from ..systems import Contact, System
from ._aft import _eval_kernel, _fourier_shared, _initial_state_derivatives

__all__ = ["HBProblem", "PARAMETERS"]

#: scalar parameters that harmonic balance can be continued in
PARAMETERS = ("gamma", "f1", "eta", "n0", "delta")


@dataclass(slots=True)
class _Eval:
    R: np.ndarray
    JX: np.ndarray
    Jp: np.ndarray
    T: np.ndarray  # (contacts, Ns): force samples of each contact, N (a row per contact)
    code: np.ndarray  # (contacts, Ns): motion-state codes of each contact
    info: np.ndarray
    #: (R, JX, Jp) scaled as asked by ``HBProblem.evaluate(..., scales=)`` (else None)
    scaled: tuple | None = None


def _pad_rows(rows, width=None):
    """Stack 1-D arrays into a C-contiguous (len(rows), width) float array, zero-padded."""
    m = max([len(r) for r in rows], default=1) if width is None else width
    out = np.zeros((len(rows), max(m, 1)))
    for i, r in enumerate(rows):
        out[i, : len(r)] = r
    return out


@jit
def _extrema(Ef, c):  # pragma: no cover - compiled
    """(max, min) of x = Ef c with the parabolic refinement of HBProblem._peak."""
    x = Ef @ c
    n = x.size
    hi_i = np.argmax(x)
    lo_i = np.argmin(x)
    out = np.empty(2)
    for k in range(2):
        i = hi_i if k == 0 else lo_i
        xm = x[(i - 1) % n]
        x0 = x[i]
        xp = x[(i + 1) % n]
        den = xm - 2.0 * x0 + xp
        pk = x0 if den == 0.0 else x0 - 0.125 * (xp - xm) ** 2 / den
        if k == 0:
            out[0] = x0 if pk < x0 else pk  # max(peak, grid max)
        else:
            out[1] = x0 if pk > x0 else pk  # min(peak, grid min)
    return out[0], out[1]


def _eval_kernel_no_contact():
    """Evaluation kernel for a system without contacts (the march is never reached)."""
    from .._jit import specialize
    from ._aft import _eval_template

    return specialize(_eval_template, STEP_JVP=discrete_step_jvp, INIT=discrete_init)


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

    def __init__(self, system: System, *, harmonics: int = config.HB_HARMONICS, samples: int = config.HB_SAMPLES,
                 parameter: str = "gamma", gamma: float | None = None,
                 max_passes: int = config.HB_MAX_PASSES):
        if not isinstance(system, System):
            raise ValueError("system must be a jointdyn.System")
        system.require_in_phase_forcing("harmonic balance")
        system.require_prescribed_single_law("harmonic balance")
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
        self.E, self.P = _fourier_shared(self.H, self.Ns)
        self.tau = 2.0 * np.pi * np.arange(self.Ns) / self.Ns
        self._fine = {}
        self._lin = None
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
        # inputs of the compiled evaluation, built once: selection rows,
        # kernel parameters and virgin states padded to common lengths
        nc = len(self.contacts)
        self._Bm = np.array(self.B, dtype=np.float64).reshape(nc, self.n)
        self._Pm = _pad_rows([c.law.params for c in self.contacts])
        self._ssz = max([c.law.state_size for c in self.contacts], default=1)
        # one law class per System (checked there): one kernel for every contact
        self._kernel = _eval_kernel(self.contacts[0].law) if nc else _eval_kernel_no_contact()
        self._fixed_loads = None
        self._zero = np.zeros(self.size)
        self._dummy = np.zeros((1, 1))
        self._zero1 = np.zeros(1)
        self._noscale = np.zeros(3)

    # --- parameter handling -------------------------------------------------
    def parameter_value(self) -> float:
        """Current value of the continuation parameter in ``system``."""
        p = self.parameter
        if p == "gamma":
            return float("nan")
        if p == "f1":
            return self.f1_ref
        c = self.contacts[0]
        return {"eta": c.eta, "n0": c.n0, "delta": c.normal.phase_rad}[p]

    def _split(self, p):
        """(w, f, contact loads [(n0, n1, delta)], dN/dp per contact or None)."""
        par = self.parameter
        gamma = p if par == "gamma" else self.gamma_fixed
        w = gamma * self.w0
        f = self.f_dir * (p if par == "f1" else self.f1_ref)
        loads = []
        for c in self.contacts:
            n0, n1, dl = c.n0, c.n1, math.radians(c.phase_deg)
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
    def _eval_inputs(self, p):
        """(w, dw/dp, Fe, Fp, Nsamp (nc, Ns), dN (nc, Ns) or None, (sx, sn) rows).

        Loads independent of p (parameters gamma and f1) are built once.
        """
        par = self.parameter
        if par == "gamma" and self._fixed_inputs is not None:
            dwdp, Fe, Fp, Nsamp, dN, SX, SN = self._fixed_inputs
            return p * self.w0, dwdp, Fe, Fp, Nsamp, dN, SX, SN
        if par in ("gamma", "f1") and self._fixed_loads is not None:
            Nsamp, SX, SN = self._fixed_loads
            dN = None
        else:
            _, _, loads = self._split(p)
            nc = len(self.contacts)
            Nsamp = np.empty((nc, self.Ns))
            dN = None if par in ("gamma", "f1") else np.empty((nc, self.Ns))
            sx, sn = [], []
            for k, (c, (n0, n1, dl, dn)) in enumerate(zip(self.contacts, loads)):
                Nsamp[k] = n0 + n1 * np.sin(self.tau + dl)
                if dN is not None:
                    dN[k] = dn
                dx_, dn_ = _initial_state_derivatives(c.law, 0.0, float(Nsamp[k, 0]))
                sx.append(dx_)
                sn.append(dn_)
            SX = _pad_rows(sx, self._ssz)
            SN = _pad_rows(sn, self._ssz)
            if par in ("gamma", "f1"):
                self._fixed_loads = (Nsamp, SX, SN)
        gamma = p if par == "gamma" else self.gamma_fixed
        w = gamma * self.w0
        if par == "f1":
            Fe = self.forcing(self.f_dir * p)
            Fp = self.forcing(self.f_dir)
        else:
            if self._forcing_fixed is None:
                self._forcing_fixed = self.forcing(self.f_dir * self.f1_ref)
            Fe = self._forcing_fixed
            Fp = self._zero
        dwdp = self.w0 if par == "gamma" else 0.0
        if par == "gamma":
            self._fixed_inputs = (dwdp, Fe, Fp, Nsamp, dN, SX, SN)
        return w, dwdp, Fe, Fp, Nsamp, dN, SX, SN

    _forcing_fixed = None
    _fixed_inputs = None
    _scales_seen = None

    def evaluate(self, X, p, scales=None) -> _Eval:
        """Residual R (N), dR/dX (N/m) and dR/dp at coefficients X and parameter p.

        One compiled call (:func:`jointdyn.hb._aft._eval_template`): linear
        part, AFT of every contact with exact forward-mode derivatives, and
        the scatter into R, dR/dX, dR/dp. With ``scales = (xs, fs, ps)``
        (unknowns, forces and parameter scales) the same call also fills
        ``scaled = (R / fs, JX * (xs / fs), Jp * (ps / fs))``.
        """
        X = np.ascontiguousarray(X, dtype=np.float64)
        w, dwdp, Fe, Fp, Nsamp, dN, SX, SN = self._eval_inputs(p)
        AK, AC, AM = self._linear_parts()
        nc = len(self.contacts)
        R = np.empty(self.size)
        JX = np.empty((self.size, self.size))
        Jp = np.empty(self.size)
        T = np.empty((nc, self.Ns))
        code = np.empty((nc, self.Ns), dtype=np.int64)
        info = np.empty(3)
        has_p = dN is not None
        if scales is None:
            scl, Rs, JXs, Jps = self._noscale, self._zero1, self._dummy, self._zero1
        else:
            if scales is not self._scales_seen:
                xs, fs, ps = scales
                self._scl = np.array([fs, xs / fs, ps / fs])
                self._scales_seen = scales
            scl = self._scl
            Rs, JXs, Jps = np.empty(self.size), np.empty((self.size, self.size)), np.empty(self.size)
        self._kernel(AK, AC, AM, float(w), float(dwdp), X, Fe, Fp, self._Bm, self._Pm, self._ssz, SX, SN, self.E, self.P,
                     Nsamp, dN if has_p else self._dummy, has_p, int(self.max_passes),
                     float(config.HB_PERIODIC_RTOL), R, JX, Jp, T, code, info, scl, Rs, JXs, Jps)
        return _Eval(R, JX, Jp, T, code, info, None if scales is None else (Rs, JXs, Jps))

    # --- post-processing ----------------------------------------------------
    def reconstruct(self, X, dof: int, points: int = 1024):
        """x_dof(tau) on a fine grid of ``points`` samples over one period, m."""
        Ef = self._fine.get(points)
        if Ef is None:
            Ef = self._fine[points] = _fourier_shared(self.H, points)[0]
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
        parabola through the three samples around each (:meth:`_peak`;
        compiled in :func:`_extrema`).
        """
        Ef = self._fine.get(1024)
        if Ef is None:
            Ef = self._fine[1024] = _fourier_shared(self.H, 1024)[0]
        Xm = np.asarray(X, dtype=np.float64).reshape(self.nh, self.n)
        hi, lo = _extrema(Ef, np.ascontiguousarray(Xm[:, dof]))
        c0 = float(Xm[0, dof])
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

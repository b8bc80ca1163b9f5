"""Hill's method for a condensed harmonic-balance problem, at the cost of the condensed solve.

A condensed problem (:class:`~jointdyn.hb.condense.CondensedHBProblem`)
solves for the harmonics of the m retained coordinates y = S x only (DOFs, or
relative coordinates: :mod:`jointdyn.hb._coordinates`); its stability is
that of the full structure, Hill's quadratic problem of n DOFs::

    Q(s) = J_X + s D1 + s^2 D2 = Lin(s) + S^T G S,

Lin the linear terms (the full structure's J_X without its contacts, with
D1 = I (x) C + 2 w nabla (x) M and D2 = I (x) M), S the retained
coordinates' rows for every harmonic and G = JX_c - Z_red(w) the contact part of
the condensed Jacobian (m (2H+1) square, it couples harmonics).
Shift-invert Arnoldi (:func:`~jointdyn.hb.hill_arnoldi.shift_invert_exponents`:
the shifts, ARPACK and Hill's selection of the full method) needs one solve
with Q(sigma) per product. Here it runs in the coordinates of the undamped
mass-normalised modes Phi of (M, K) (x = (I (x) Phi) q, a similarity of the
companion matrix: the eigenvalues are the same), where D2 = I and the
linear part of harmonic k is diagonalised by the complex combinations
u = a - i b, v = a + i b of its cosine and sine coefficients into
Z_q(sigma + i k w) and Z_q(sigma - i k w), with::

    Z_q(p) = diag(w_r^2) + p Phi^T C Phi + p^2 I,
    Z_q(p)^-1 = diag(1 / (w_r^2 + p^2 + p c_r))       (modal damping),
    Z_q(p)^-1 = Y diag(1 / (p - lambda_r)) Y^T        (state-space),

the receptance of :func:`~jointdyn.hb.condense.receptance` at a complex
frequency (Y, lambda_r the damped eigenpairs in modal coordinates, Psi =
Phi Y). With P = I (x) Phi_c (Phi_c = S Phi: the coordinates' rows) the solve of
(Lin + P^T G P) x = r is, by the Woodbury identity::

    u = Lin^-1 r,   (I + H_cc G) x_c = P u,   x = u - Lin^-1 P^T G x_c,

H_cc(sigma) = P Lin^-1 P^T = Psi_c diag(g) Psi_c^T per harmonic and
combination (m x m). So each shift costs H_cc (O(m^2 R) per harmonic) and
one dense LU of size m (2H+1); each product O(m R) per harmonic with modal
damping (R = n modes: the full structure is never formed) or O(n^2) per
harmonic for a state-space expansion (the products with Y). Near a pole of
the receptance (an undamped mode at sigma + i k w) the two terms of x cancel:
the solve loses about 1e-16 / delta of relative accuracy where a factor's
denominator is delta of its terms' size (measured on an undamped chain:
exponents off by 7 % at delta ~ 1e-16, 2.6e-9 relative at delta = 2e-8,
2e-11 at 2e-6), and Arnoldi can miss an exponent there. A shift where some
delta is at most ``StabilityOptions.arnoldi_pole_rtol`` (1e-8), or where
I + H_cc G is exactly singular, is therefore moved as the full method moves
a singular Q(sigma) (by 1e-3 w).

The exponents are those of the full Jacobian's Arnoldi and of dense Hill to
rounding (tests/test_hb_hill_condensed.py).
"""

from __future__ import annotations

import warnings

import numpy as np

from .._cache import by_identity
from .hill_arnoldi import ArnoldiExponents, shift_invert_exponents
from .stability_options import StabilityOptions

__all__ = ["condensed_hill_exponents"]


@by_identity
def _modes(problem):
    """(Phi_c (m, n) real, Psi_c (m, R), w_r^2 (n,) or None, c (n,) or None, Ct (n, n) or None, Y (n, R)
    or None, lambda (R,) or None) of a condensed problem (module docstring): modal damping with w_r^2 and
    c, a state-space expansion with Ct, Y and lambda."""
    rec, coords = problem.receptance, problem.coordinates
    Psi_c = np.ascontiguousarray(rec.rows_of(coords))
    if rec.modes is None:  # modal: Psi = Phi
        return Psi_c, Psi_c, np.asarray(rec.a, dtype=np.float64), np.asarray(rec.b, dtype=np.float64), None, \
            None, None
    Phi, Ct, Y = rec.modes
    Phi_c = Phi[coords.dofs] if coords.unit else coords.S @ Phi
    return (np.ascontiguousarray(Phi_c), Psi_c, None, None, np.asarray(Ct), np.asarray(Y),
            np.asarray(rec.a, dtype=np.complex128))


class _CondensedShiftInvert:
    """``v -> (A - sigma I)^-1 v`` of Hill's companion matrix in modal coordinates (module docstring)."""

    def __init__(self, modes, G, w: float, H: int, sigma, pole_rtol: float):
        self.Phi_c, Psi_c, self.w2, self.c, self.Ct, self.Y, self.lam = modes
        self.sigma, self.w, self.H, self.G = sigma, w, H, G
        self.R = self.Phi_c.shape[1]
        self.N = self.R * (2 * H + 1)
        self.dtype = np.complex128 if isinstance(sigma, complex) else np.float64
        k = np.arange(1, H + 1, dtype=np.float64)
        # the complex frequencies of the constant, the u and the v combinations of each harmonic
        p = np.concatenate(([complex(sigma)], sigma + 1j * k * w, sigma - 1j * k * w))
        self.g = self._factors(p, pole_rtol)  # (2H + 1, R)
        m = Psi_c.shape[0]
        Hb = (self.g[:, None, :] * Psi_c[None, :, :]) @ Psi_c.T  # Psi_c diag(g) Psi_c^T, (2H + 1, m, m)
        nh = 2 * H + 1
        Hcc = np.zeros((nh * m, nh * m), dtype=np.complex128)
        Hcc[:m, :m] = Hb[0]
        for j in range(1, H + 1):
            hu, hv = Hb[j], Hb[H + j]
            ci, si = (2 * j - 1) * m, 2 * j * m
            Hcc[ci:ci + m, ci:ci + m] = Hcc[si:si + m, si:si + m] = 0.5 * (hu + hv)
            Hcc[ci:ci + m, si:si + m] = -0.5j * (hu - hv)
            Hcc[si:si + m, ci:ci + m] = 0.5j * (hu - hv)
        import scipy.linalg as sla  # not at import: a short command on a small model never loads it

        with np.errstate(all="ignore"):
            F = np.eye(nh * m) + Hcc @ G
        if not np.all(np.isfinite(F)):
            raise ValueError("I + H_cc G is not finite")
        with warnings.catch_warnings():  # a zero pivot is reported below
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            lu = sla.lu_factor(F, check_finite=False)
        if not np.all(np.abs(lu[0].diagonal()) > 0.0):
            raise ValueError("I + H_cc(sigma) G is exactly singular")
        self._lu_solve = lambda b: sla.lu_solve(lu, b, check_finite=False)

    def _factors(self, p, pole_rtol: float):
        """g_r(p) (len(p), R): 1 / (w_r^2 + p^2 + p c_r), or 1 / (p - lambda_r); ValueError within
        ``pole_rtol`` of a pole (relative to the sum of the moduli of the terms)."""
        p = p[:, None]
        if self.c is not None:
            den = self.w2[None, :] + p * p + p * self.c[None, :]
            scale = np.abs(self.w2)[None, :] + np.abs(p) ** 2 + np.abs(p * self.c[None, :])
        else:
            den = p - self.lam[None, :]
            scale = np.abs(p) + np.abs(self.lam)[None, :]
        if not np.all(np.abs(den) > pole_rtol * scale):
            raise ValueError("the linear part Lin(sigma) is singular to rounding (a mode at sigma + i k w)")
        return 1.0 / den

    def _zinv(self, U, g):
        """Z_q(p)^-1 of each row of U (rows, n) at the factors g (rows, R)."""
        if self.Y is None:
            return U * g
        return ((U @ self.Y) * g) @ self.Y.T

    def _lin_inv(self, V):
        """Lin(sigma)^-1 V for V (2H+1, n): the constant, then each harmonic through its u and v."""
        H = self.H
        out = np.empty(V.shape, dtype=np.complex128)
        out[0] = self._zinv(V[:1], self.g[:1])[0]
        if H:
            A, B = V[1::2], V[2::2]
            U = self._zinv(A - 1j * B, self.g[1:H + 1])
            W = self._zinv(A + 1j * B, self.g[H + 1:])
            out[1::2] = 0.5 * (U + W)
            out[2::2] = 0.5j * (U - W)
        return out

    def _d1(self, A):
        """D1 A = (I (x) Phi^T C Phi) A + 2 w (nabla (x) I) A for A (2H+1, n)."""
        out = A * self.c[None, :] if self.Ct is None else A @ self.Ct
        k = np.arange(1, self.H + 1, dtype=np.float64)[:, None]
        out[1::2] += 2.0 * self.w * k * A[2::2]
        out[2::2] -= 2.0 * self.w * k * A[1::2]
        return out

    def solve(self, r):
        """Q(sigma)^-1 r (r: (2H+1) n, modal coordinates)."""
        V = np.asarray(r).reshape(2 * self.H + 1, self.R)
        u = self._lin_inv(V)
        xc = self._lu_solve((u @ self.Phi_c.T).ravel())
        corr = (self.G @ xc).reshape(2 * self.H + 1, -1) @ self.Phi_c
        return (u - self._lin_inv(corr)).ravel()

    def __call__(self, v):
        v = np.asarray(v).ravel()
        a, b = v[: self.N], v[self.N:]
        A = a.reshape(2 * self.H + 1, self.R)
        x = -self.solve(b + self._d1(A).ravel() + self.sigma * a)
        if self.dtype == np.float64:  # real in exact arithmetic at a real shift
            x = x.real
        return np.concatenate((x, a + self.sigma * x))


def condensed_hill_exponents(problem, JX, w, options: StabilityOptions | None = None) -> ArnoldiExponents:
    """Floquet exponents nearest the imaginary axis of a condensed problem's solution (module docstring).

    Parameters
    ----------
    problem : CondensedHBProblem
        The condensed problem (its receptance and retained coordinates).
    JX : ndarray (m(2H+1), m(2H+1))
        Its Jacobian dR/dX at the solution, N/m.
    w : float
        Angular frequency of the solution, rad/s.
    options : StabilityOptions, optional
        ``arnoldi_shifts``, ``arnoldi_eigenvalues``, ``arnoldi_tol``, ``arnoldi_maxiter``,
        ``arnoldi_pole_rtol``.

    Returns
    -------
    ArnoldiExponents
        As :func:`~jointdyn.hb.hill_arnoldi.hill_arnoldi_exponents` on the full Jacobian
        (:meth:`~jointdyn.hb.condense.CondensedHBProblem.full_jacobian`) gives them.

    Raises
    ------
    numpy.linalg.LinAlgError
        Where Q(sigma) is singular at a shift, or ARPACK does not converge.
    """
    opt = StabilityOptions() if options is None else options
    w = float(w)
    modes = _modes(problem)
    G = np.ascontiguousarray(problem.contact_jacobian(JX, w))
    return shift_invert_exponents(lambda sigma: _CondensedShiftInvert(modes, G, w, problem.H, sigma,
                                                                      opt.arnoldi_pole_rtol),
                                  problem.system.ndof, problem.H, w, opt)

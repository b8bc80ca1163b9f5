"""Harmonic-balance residual of a :class:`~jointdyn.systems.System`.

Equation of motion (docs/model.md section 6, generalised in ``systems.py``)::

    M x'' + C x' + K x + sum_c B_c T_c(u_c, N_c) = F(t),
    F_i(t) = f_i sin(w t + phi_i) = f_i sin(phi_i) cos(w t) + f_i cos(phi_i) sin(w t),
    u_c = B_c^T x,   N_c(t) = n0_c + n1_c sin(w t + delta_c).

In normalised time tau = w t, x(tau) = sum_h Q_h(tau) X_h with the real
Fourier basis Q = (1, cos tau, sin tau, ..., cos H tau, sin H tau) of
:mod:`jointdyn.fourier`; the normal load N_c(tau) does not depend on w.
Galerkin projection on the same basis gives, for harmonic k (coefficients
a_k of cos, b_k of sin)::

    (K - k^2 w^2 M) a_k + k w C b_k + F_a,k(X) = f sin(phi) delta_{k1}
    (K - k^2 w^2 M) b_k - k w C a_k + F_b,k(X) = f cos(phi) delta_{k1}

and K a_0 + F_0(X) = 0 for the constant term (the offset). F(X) are the
Fourier coefficients of the contact forces, evaluated by alternating
frequency-time (:mod:`jointdyn.hb._aft`) with exact forward-mode
Jacobians. The unknowns are ordered harmonic-major:
``X[h * n + i]`` is coefficient h of unknown DOF i (here every DOF of the
system: ``dofs[i] == i``; the condensed problem of
:mod:`jointdyn.hb.condense` keeps the contact DOFs only). How the
continuation parameter enters (frequency, forcing amplitudes, normal
loads) is the business of a parameter object
(:mod:`jointdyn.hb.parameters`); the forcing phases phi are the system's
and stay fixed.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .. import config
from .._cache import by_identity, by_value
from ..damping import dense_damping, is_operator
from ..fourier import STARTS, STOPS, derivative_matrix, extrema, fourier_matrices, phases, separation_grid
from ..kinematics import NORMAL_SPRING, contact_kinematics, no_contact_init_jvp, no_contact_step_jvp, selection_matrix
from ..laws import law_dispatch
from ..laws._base import MACROSLIP, SEPARATION, STICK_SLIP
from ..systems import System
from ._aft import HB_PERIODIC_RTOL, NO_EVENT, PERIOD_ONE, eval_kernel, recontact_events
from ._recontact import HB_RECONTACT_ALPHA
from ._rigid import held_by_contacts, mean_gauge
from ._aft_pairs import pair_directions, pairs_aft_kernel
from ._sparse import linear_entries
from .levels import Level
from .options import HBOptions, hb_options
from .parameters import SystemParameter, _FixedFrequency, parameter_named

__all__ = ["HBProblem"]


@dataclass(slots=True)
class _Eval:
    R: np.ndarray
    JX: np.ndarray
    Jp: np.ndarray
    T: np.ndarray  # (contacts, Ns): force samples of each contact, N (a row per contact)
    code: np.ndarray  # (contacts, Ns): motion-state codes of each contact
    #: [periods marched, last change of the force (N), force period]: see jointdyn.hb._aft.INFO_*
    info: np.ndarray
    #: (R, JX, Jp) scaled as asked by ``HBProblem.evaluate(..., scales=)`` (else None)
    scaled: tuple | None = None
    #: (contacts, Ns): normal-load samples of each contact, N (prescribed, or max(0, P + kn g))
    N: np.ndarray | None = None
    #: interfaces' node pairs, all interfaces in turn (None without interfaces): tangential forces
    #: (pairs, Ns, 2) N, normal loads (pairs, Ns) N and motion codes (pairs, Ns) of the last marched period
    pair_T: np.ndarray | None = None
    pair_N: np.ndarray | None = None
    pair_code: np.ndarray | None = None


def _pad_rows(rows, width=None):
    """Stack 1-D arrays into a C-contiguous (len(rows), width) float array, zero-padded."""
    m = max([len(r) for r in rows], default=1) if width is None else width
    out = np.zeros((len(rows), max(m, 1)))
    for i, r in enumerate(rows):
        out[i, : len(r)] = r
    return out


def _load_samples(tau, n0, n1, delta, d=None):
    """Normal load N = n0 + n1 sin(tau + delta) at the phases ``tau`` (N), and its derivative.

    ``d = (dn0, dn1, ddelta)``: derivatives of the coefficients along a
    parameter; the derivative of the samples is returned with them (None
    without ``d``). The one place where harmonic balance writes the
    harmonic normal load out.
    """
    ph = tau + delta
    N = n0 + n1 * np.sin(ph)
    if d is None:
        return N, None
    dn0, dn1, ddelta = d
    dN = dn0 + dn1 * np.sin(ph)
    if ddelta != 0.0:
        dN = dN + (n1 * ddelta) * np.cos(ph)
    return N, dN


def _load_events(n0: float, n1: float, delta: float) -> tuple:
    """Phases where N = n0 + n1 sin(tau + delta) crosses zero, as ``(tau, side)`` of
    :func:`~jointdyn.fourier.event_projection`: re-contact (N rises through zero: the force starts) and
    separation (it stops); empty when N keeps its sign."""
    if not abs(n1) > abs(n0):
        return ()
    a = math.asin(-n0 / n1)
    return tuple(sorted(((ph - delta) % (2.0 * math.pi), STARTS if n1 * math.cos(ph) > 0.0 else STOPS)
                        for ph in (a, math.pi - a)))


def _linear_blocks(system: System, H: int, gauge=None):
    """(AK, AC, AM) with A(w) = AK + w AC + w^2 AM the linear terms of harmonics 0..H (dense; their entries
    per harmonic block: :func:`jointdyn.hb._sparse.linear_entries`); ``gauge`` (n, n), N/m, added to K on
    harmonic 0 alone (:func:`mean_gauge`)."""
    size = system.ndof * (2 * H + 1)
    rows, cols, *values = linear_entries(system.K, dense_damping(system.C), system.M, H)
    out = []
    for v in values:
        # into zeroed arrays by the blocks' entries (np.kron writes every entry: seconds at thousands of unknowns)
        A = np.zeros((size, size))
        A[rows, cols] = v
        out.append(A)
    if gauge is not None:
        n = system.ndof
        out[0][:n, :n] += gauge
    return tuple(out)


def harmonic_columns(n: int, H: int) -> np.ndarray:
    """(n (2H+1), 2) int64: per row of the unknowns (harmonic-major: mean, cos 1, sin 1, ...), the columns
    ``[lo, hi)`` of its harmonic's block, where alone the linear terms of harmonic balance couple it."""
    h = np.arange(n * (2 * H + 1)) // n
    k = (h + 1) // 2
    lo = np.where(k == 0, 0, (2 * k - 1) * n)
    hi = np.where(k == 0, n, (2 * k + 1) * n)
    return np.ascontiguousarray(np.stack((lo, hi), axis=1), dtype=np.int64)


class HBProblem:
    """Harmonic-balance residual R(X, p) and its exact Jacobian.

    Parameters
    ----------
    system : System
        Structure, contacts and forcing.
    harmonics : int
        Highest harmonic H (>= 1); the constant term is always included.
    samples : int
        Uniform time samples per period for the AFT (>= 2H + 2); where a
        prescribed normal load separates, the AFT also marches phases
        graded towards each separation (:meth:`_aft_grid`), and evaluations
        report the uniform samples.
    parameter : str or HBParameter
        Continuation parameter: a built-in name (``gamma``, ``f1``,
        ``eta``, ``n0``, ``delta``; see :mod:`jointdyn.hb.parameters`) or a
        parameter object (e.g. :class:`~jointdyn.hb.parameters.SystemParameter`).
    gamma : float, optional
        Fixed w / w0 when the parameter is not ``gamma``.
    max_passes : int
        Bound on the periods marched per AFT evaluation.
    options : HBOptions, optional
        Harmonic balance's numbers (:class:`~jointdyn.hb.options.HBOptions`; None: the defaults): here
        the size of Hill's method and the block preconditioner of the large solves.
    """

    def __init__(self, system: System, *, harmonics: int = config.HB_HARMONICS, samples: int = config.HB_SAMPLES,
                 parameter="gamma", gamma: float | None = None, max_passes: int = config.HB_MAX_PASSES,
                 options: HBOptions | None = None):
        self.options = hb_options(options)
        self._setup(system, harmonics, samples, parameter, gamma, max_passes, None)
        self._lin_blocks = None  # (AK, AC, AM), built at their first use (:attr:`_lin`)
        # what the parameter does not move is built once
        self._fixed_forcing = None if self.parameter.enters_forcing else self._forcing_at(0.0)
        self._fixed_loads = None if self.parameter.enters_loads else self._loads_at(0.0)

    def _setup(self, system, harmonics, samples, parameter, gamma, max_passes, dofs) -> None:
        """Validation and everything but the linear part, for the unknown DOFs ``dofs``
        (system DOF numbers; None: every DOF)."""
        if not isinstance(system, System):
            raise ValueError("system must be a jointdyn.System")
        system.require_phase_loads("harmonic balance")
        if dofs is None:
            dofs = np.arange(system.ndof)
        self.H, self.Ns = Level.of(harmonics, samples)
        self.parameter = parameter_named(parameter)
        self.gamma_fixed = None
        if self.parameter.needs_gamma:
            if gamma is None:
                raise ValueError("gamma must be given (> 0) when the parameter is not gamma")
            self.gamma_fixed = V.positive("gamma", gamma)
        self.max_passes = V.positive_int("max_passes", max_passes, 2)
        self.system = system
        #: system DOF of each unknown DOF (X[h * n + i] is harmonic h of DOF dofs[i])
        self.dofs = np.asarray(dofs, dtype=np.int64)
        #: position of each unknown DOF among them (dof_index, asked at every continuation step)
        self._dof_positions = {int(d): i for i, d in enumerate(self.dofs)}
        self.n = self.dofs.size
        self.nh = 2 * self.H + 1
        self.size = self.n * self.nh
        self._lin_cols = harmonic_columns(self.n, self.H)
        self.w0 = system.w0
        if not self.w0 > 0:
            raise ValueError("system must have a positive lowest natural frequency w0 (K positive definite)")
        self.E, self.P = fourier_matrices(self.H, self.Ns)
        self.tau = phases(self.Ns)
        self.contacts = list(system.contacts)
        fmax = float(np.max(np.abs(system.force))) if system.force.size else 0.0
        self.f_dir = system.force / fmax if fmax > 0 else system.force.copy()
        self.f1_ref = fmax
        phi = np.radians(system.force_phase_deg)
        #: per system DOF, sin and cos of the forcing phase: f sin(w t + phi) has the
        #: coefficients f sin(phi) of cos(w t) and f cos(phi) of sin(w t)
        self.phase_sin, self.phase_cos = np.sin(phi), np.cos(phi)
        #: True when the structure is held only through its contacts (:func:`held_by_contacts`): the laws and
        #: the interfaces' pairs restart virgin at the reference displacement (the preloaded static state), not
        #: at the mean of their motion, so that a stuck contact holds the mean position (made once, here)
        self.restart_at_reference = held_by_contacts(system)
        #: s M Phi_r Phi_r^T M (n, n), N/m, added to K on harmonic 0 of a free-free structure (its stuck
        #: stiffness has rigid-body modes Phi_r: :func:`mean_gauge`); None for a structure held in place
        self.gauge = mean_gauge(system, self.w0)
        if self.gauge is not None and self.n != system.ndof:
            raise ValueError("condense: the structure is free-free (rigid-body modes even with every contact "
                             "stuck), so its receptance has no static part to condense with; use condense=False "
                             "(or None: the full problem)")
        self._contact_inputs(contact_kinematics(contacts_only(system)))
        self._interface_inputs()
        #: the AFT's phases and matrices (:meth:`_aft_grid`); evaluations report the uniform samples
        self._taug, self._Eg, self._Pg, self._uniform = self._aft_grid()
        self._dummy = np.zeros((1, 1))
        self._no_blocks = np.zeros((0, 0, 0))
        self._zero1 = np.zeros(1)
        self._noscale = np.zeros(3)
        self._scales_seen = None

    def _contact_inputs(self, kin) -> None:
        """Selection rows, spring rows, kernel parameters and the compiled kernel (built once).

        Contacts with different law kernels go through one dispatching
        kernel (:func:`jointdyn.laws.law_dispatch`); its parameter rows are
        the laws' own (zero padded) when every contact has the same kernels.
        """
        nc = len(self.contacts)
        springs = kin.normal_kind == NORMAL_SPRING
        #: True when some contact's normal load comes from a normal spring
        self.has_springs = bool(np.any(springs))
        if self.has_springs and self.parameter.enters_loads:
            raise ValueError(f"parameter: {self.parameter.name!r} moves prescribed normal loads; a system with "
                             "normal springs takes its loads from the structure (use gamma, f1 or a SystemParameter)")
        #: per contact (n0, n1, delta) of its normal load as given in the system (N, N, rad);
        #: (P, kn, 0) for a spring contact (kinematics.ContactKinematics.normal_par)
        self.load_coefficients = kin.normal_par.copy()
        self.B = list(self._on_unknowns(selection_matrix(kin, self.system.ndof)))
        #: normal rows (g_c = Bn[c] . x over the unknown DOFs), zero for a prescribed load
        self.Bn = list(self._on_unknowns(selection_matrix(kin, self.system.ndof, normal=True)))
        self._Bm = np.array(self.B, dtype=np.float64).reshape(nc, self.n)
        self._Bnm = np.array(self.Bn, dtype=np.float64).reshape(nc, self.n)
        #: (P, kn, restart load at a re-contact between samples) per contact, kn = 0 for a prescribed load
        self._Sp = np.zeros((nc, 3))
        self._Sp[springs, :2] = kin.normal_par[springs, :2]
        self._Sp[:, 2] = HB_RECONTACT_ALPHA * self._Sp[:, 0]
        if nc:
            disp = law_dispatch([c.law for c in self.contacts])
            self._Pm, self._ssz = disp.P, disp.state_size
            self._kernel = eval_kernel(disp.step_jvp, disp.init_jvp, self.has_springs)
        else:
            self._Pm, self._ssz = _pad_rows([]), 1
            self._kernel = eval_kernel(no_contact_step_jvp, no_contact_init_jvp)

    def _interface_inputs(self) -> None:
        """The interfaces' pairs on the unknown DOFs and their parameters, all interfaces stacked (built once)."""
        itfs = self.system.interfaces
        #: True when the system has interfaces (their pairs are evaluated by :func:`~jointdyn.hb._aft_pairs.pairs_aft`)
        self.has_interfaces = bool(itfs)
        if not itfs:
            return
        #: per pair (stacked over the interfaces) the positions of its six DOFs among the unknowns (-1: fixed;
        #: a condensed problem on relative coordinates: of the pair's coordinates, side a or b by their sign)
        self.pair_positions = self._pair_positions(np.vstack([itf.pairs for itf in itfs]))
        #: per pair kt, kn, mu, preload (N/m, N/m, -, N)
        self.pair_params = np.ascontiguousarray(np.vstack([itf.params for itf in itfs]))
        self._pair_dirs = pair_directions(self.E, self.restart_at_reference)

    def _on_unknowns(self, B):
        """Rows B (k, ndof) acting on the system DOFs, as rows acting on the unknowns (k, n)."""
        return B[:, self.dofs]

    def _pair_positions(self, table):
        """Positions among the unknowns of the DOFs of the pairs' ``table`` (pairs, 6), -1 kept (fixed)."""
        pos = np.full(table.shape, -1, dtype=np.int64)
        for (i, k), d in np.ndenumerate(table):
            if d >= 0:
                pos[i, k] = self.dof_index(int(d))
        return pos

    def _aft_grid(self):
        """(tau, E, P, uniform) of the AFT: the phases the laws are marched at, their synthesis and analysis
        matrices, and the positions of the uniform samples among the phases (None: the phases are the
        uniform samples). With separations and re-contacts of the prescribed normal loads, where one grid
        serves every contact (the same phases for all) and the parameter does not move them:
        :func:`~jointdyn.fourier.separation_grid` (extra phases graded towards each separation, the
        re-contact corners taken into account); the uniform samples and projection otherwise."""
        uniform = (self.tau, self.E, self.P, None)
        if not self.contacts or self.has_springs or self.parameter.enters_loads or self.system.interfaces:
            return uniform
        events = {_load_events(*co) for co in self.load_coefficients}
        if len(events) != 1:
            return uniform
        ev = events.pop()
        if not ev:
            return uniform
        tau, E, P, at = separation_grid(self.H, self.Ns, ev)
        return tau, E, P, (None if tau.size == self.Ns else at)

    @property
    def _lin(self):
        """(AK, AC, AM) of :func:`_linear_blocks`, dense (3 N^2 entries: 730 MB at 5500 unknowns), built at
        their first use: an evaluation with a sparse Jacobian (:meth:`evaluate_sparse`) never needs them."""
        if getattr(self, "_lin_blocks", None) is None:
            self._lin_blocks = _linear_blocks(self.system, self.H, self.gauge)
        return self._lin_blocks

    @property
    def condensed(self) -> bool:
        """True when the unknowns are the harmonics of some DOFs only (:mod:`jointdyn.hb.condense`)."""
        return False

    def dof_index(self, dof: int) -> int:
        """Position among the unknown DOFs of system DOF ``dof`` (ValueError naming it if absent)."""
        try:
            return self._dof_positions[dof]
        except (KeyError, TypeError):
            pass
        hit = np.flatnonzero(self.dofs == dof)
        if hit.size == 0:
            raise ValueError(f"dof {dof!r} is not among the unknowns of this problem ({self.dofs.tolist()})")
        return int(hit[0])

    # --- parameter ----------------------------------------------------------
    def omega(self, p) -> float:
        """Angular frequency w (rad/s) at parameter p."""
        return self.parameter.frequency(self, p)[0]

    def contact_loads(self, p):
        """Per contact (n0, n1, delta) of the normal load at parameter p: array (contacts, 3) (N, N, rad)."""
        return self.parameter.contact_loads(self, p)[0]

    def _split(self, p):
        """(w, f, [(n0, n1, delta, None)] per contact) at parameter p (the monodromy check's inputs)."""
        loads = [(float(a), float(b), float(c), None) for a, b, c in self.contact_loads(p)]
        return self.omega(p), self.parameter.forcing(self, p)[0], loads

    def _forcing_at(self, p):
        """(Fe, Fp): coefficient vectors of the forcing and of its derivative along p."""
        f, df = self.parameter.forcing(self, p)
        return self.forcing(f), (np.zeros(self.size) if df is None else self.forcing(df))

    def _loads_at(self, p):
        """(Nsamp, dN, events): normal-load samples (contacts, Ns), their derivative along p (or None),
        and the re-contact events of the AFT (:func:`jointdyn.hb._aft.recontact_events`)."""
        co, d = self.parameter.contact_loads(self, p)
        nc = len(self.contacts)
        ng = self._taug.size
        Nsamp = np.empty((nc, ng))
        dN = None if d is None else np.empty((nc, ng))
        for k in range(nc):
            Nsamp[k], dn = _load_samples(self._taug, co[k, 0], co[k, 1], co[k, 2], None if d is None else d[k])
            if dN is not None:
                dN[k] = dn
        events = recontact_events(self._taug, co, d, uniform=self._uniform is None)
        # a spring's re-contact phases depend on the unknowns: located in the AFT itself
        events[0][self._Sp[:, 1] > 0.0] = NO_EVENT
        return Nsamp, dN, events

    # --- linear part --------------------------------------------------------
    def linear_matrix(self, w):
        """Block matrix A(w) of the linear terms (size n(2H+1)): per harmonic k
        ``[[K - k^2 w^2 M, k w C], [-k w C, K - k^2 w^2 M]]``, K for k = 0."""
        AK, AC, AM = self._lin
        out = np.zeros_like(AK)
        for lo, hi in np.unique(self._lin_cols, axis=0):  # the harmonics' blocks, where alone they are nonzero
            b = (slice(lo, hi), slice(lo, hi))
            out[b] = AK[b] + w * AC[b] + (w * w) * AM[b]
        return out

    def _linear_terms(self, w):
        """(AK, AC, AM, w) of the compiled evaluation: A(w) = AK + w AC + w^2 AM."""
        return (*self._lin, float(w))

    def forcing(self, f, w: float | None = None):
        """Coefficient vector of the forcing f_i sin(tau + phi_i), amplitudes f (N) per DOF.

        The phases phi are the system's. ``w`` (rad/s) is not needed here
        (the condensed problem's forcing depends on it).
        """
        n = self.n
        Fe = np.zeros(self.size)
        s = self.phase_sin
        Fe[n:2 * n] = np.where(s != 0.0, f * s, 0.0)
        Fe[2 * n:3 * n] = f * self.phase_cos
        return Fe

    def linear_guess(self, p, stuck: bool = True):
        """Linear response with every contact stuck (stiffness kt) or absent
        (normal springs closed, stiffness kn, in both cases).

        Used to start Newton and continuation (docs/model.md section 6: all
        stuck -> linear system with K + kt).
        """
        q = self.problem_at(p) if isinstance(self.parameter, SystemParameter) else self
        w = self.omega(p)
        Kc = q.pair_stiffness(stuck) if q.has_interfaces else np.zeros((q.n, q.n))
        if stuck:
            for c, b, bn, kn in zip(q.contacts, q.B, q.Bn, q._Sp[:, 1]):
                Kc += c.law.kt * np.outer(b, b) + kn * np.outer(bn, bn)
        F = q.forcing(q.parameter.forcing(q, p)[0], w)
        if type(q).linear_matrix is HBProblem.linear_matrix and q.size >= config.CONT_KRYLOV_SOLVE:
            # block-diagonal over the harmonics: one solve per harmonic, no (2H+1) n square matrix
            return self._linear_guess_blocks(w, Kc, F)
        A = q.linear_matrix(w)
        for h in range(q.nh):
            A[h * q.n:(h + 1) * q.n, h * q.n:(h + 1) * q.n] += Kc
        return np.linalg.solve(A, F)

    def _linear_guess_blocks(self, w, Kc, F):
        """The solution of (A(w) + blockdiag(Kc)) X = F by one solve per harmonic block."""
        from ._precond import harmonic_blocks

        K, C, M = (np.asarray(a, dtype=np.float64) for a in (self.system.K, self.system.C, self.system.M))
        n, X = self.n, np.empty(self.size)
        for k, (lo, hi) in enumerate(harmonic_blocks(n, self.H)):
            if k == 0:
                X[lo:hi] = np.linalg.solve(K + Kc if self.gauge is None else K + Kc + self.gauge, F[lo:hi])
                continue
            D = K + Kc - (k * w) ** 2 * M
            X[lo:hi] = np.linalg.solve(np.block([[D, (k * w) * C], [-(k * w) * C, D]]), F[lo:hi])
        return X

    def pair_stiffness(self, stuck: bool = True) -> np.ndarray:
        """Stiffness (n, n) N/m of the interfaces' pairs on the unknown DOFs: every pair closed at rest
        (preload > 0) as its springs kt, kt, kn (``stuck``) or kn alone; the other pairs open (nothing)."""
        Kp = np.zeros((self.n, self.n))
        for pos, (kt, kn, _, P) in zip(self.pair_positions, self.pair_params):
            if not P > 0.0:
                continue
            for k, ks in ((0, kt if stuck else 0.0), (1, kt if stuck else 0.0), (2, kn)):
                b = np.zeros(self.n)
                for col, sign in ((k, 1.0), (k + 3, -1.0)):
                    if pos[col] >= 0:
                        b[pos[col]] += sign
                Kp += ks * np.outer(b, b)
        return Kp

    # --- residual -----------------------------------------------------------
    def evaluate(self, X, p, scales=None) -> _Eval:
        """Residual R (N), dR/dX (N/m) and dR/dp at coefficients X and parameter p.

        One compiled call (:func:`jointdyn.hb._aft._eval_template`): linear
        part, AFT of every contact with exact forward-mode derivatives, and
        the scatter into R, dR/dX, dR/dp (for a
        :class:`~jointdyn.hb.parameters.SystemParameter`, dR/dp is a central
        difference of the residual). With ``scales = (xs, fs, ps)``
        (unknowns, forces and parameter scales) the same call also fills
        ``scaled = (R / fs, JX * (xs / fs), Jp * (ps / fs))``.
        """
        if isinstance(self.parameter, SystemParameter):
            return self._evaluate_central(X, p, scales)
        return self._run(np.ascontiguousarray(X, dtype=np.float64), *self._inputs(p), scales)

    def _inputs(self, p):
        """(w, dw/dp, Fe, Fp, Nsamp, dN, events) at parameter p: what the parameter fixes, as the evaluation
        takes it."""
        w, dwdp = self.parameter.frequency(self, p)
        Fe, Fp = self._fixed_forcing if self._fixed_forcing is not None else self._forcing_at(p)
        Nsamp, dN, events = self._fixed_loads if self._fixed_loads is not None else self._loads_at(p)
        return w, dwdp, Fe, Fp, Nsamp, dN, events

    def _run(self, X, w, dwdp, Fe, Fp, Nsamp, dN, events, scales) -> _Eval:
        """The compiled evaluation at the given frequency, forcing and loads."""
        nc = len(self.contacts)
        size = self.size
        R = np.empty(size)
        JX = np.empty((size, size))
        Jp = np.empty(size)
        ng = self._taug.size
        T = np.empty((nc, ng))
        Nout = np.empty((nc, ng))
        code = np.empty((nc, ng), dtype=np.int64)
        info = np.empty(3)
        has_p = dN is not None
        if scales is None:
            scaled = (self._noscale, self._zero1, self._dummy, self._zero1)
        else:
            if scales is not self._scales_seen:
                xs, fs, ps = scales
                self._scl = np.array([fs, xs / fs, ps / fs])
                self._scales_seen = scales
            scaled = (self._scl, np.empty(size), np.empty((size, size)), np.empty(size))
        self._kernel((*self._linear_terms(w), float(dwdp), X, Fe, Fp, self._lin_cols),
                     (self._Bm, self._Pm, self._ssz, self._Bnm, self._Sp, self.has_springs),
                     (Nsamp, dN if has_p else self._dummy, has_p, events), (self._Eg, self._Pg),
                     (int(self.max_passes), float(HB_PERIODIC_RTOL), bool(self.restart_at_reference)),
                     (R, JX, Jp, T, Nout, code, info), scaled)
        if self._uniform is not None:
            at = self._uniform
            T, code, Nout = T[:, at], code[:, at], Nout[:, at]
        ev = _Eval(R, JX, Jp, T, code, info, None if scales is None else scaled[1:], Nout)
        if self.has_interfaces:
            self._add_pairs(X, ev, scaled)
        return ev

    def _add_pairs(self, X, ev: _Eval, scaled) -> None:
        """The interfaces' reactions and exact Jacobian added to ``ev`` (and its scaled copies)."""
        npairs, ns = self.pair_params.shape[0], self.Ns
        ev.pair_T, ev.pair_N = np.empty((npairs, ns, 2)), np.empty((npairs, ns))
        ev.pair_code = np.empty((npairs, ns), dtype=np.int8)
        pairs_aft_kernel()(self.pair_positions, self.pair_params, X, self.n, self.E, self.P, *self._pair_dirs,
                           int(self.max_passes), float(HB_PERIODIC_RTOL), ev.R, ev.JX, self._no_blocks,
                           ev.pair_T, ev.pair_N, ev.pair_code, ev.info)
        if ev.scaled is not None:
            scl = scaled[0]
            np.divide(ev.R, scl[0], out=scaled[1])
            np.multiply(ev.JX, scl[1], out=scaled[2])

    def block_preconditioner(self, columns=()):
        """The structured preconditioner of this problem's large solves (one factorisation per harmonic,
        :class:`jointdyn.hb._precond.HarmonicBlocks`; ``columns``: those of the Jacobian it takes exactly),
        or None where ``options.block_preconditioner`` is off or below ``config.CONT_KRYLOV_SOLVE`` unknowns."""
        if not self.options.block_preconditioner or self.size + 1 < config.CONT_KRYLOV_SOLVE:
            return None
        from ._precond import HarmonicBlocks

        return HarmonicBlocks(self.n, self.H, columns)

    # --- sparse Jacobian ------------------------------------------------------
    def sparse_pattern(self):
        """The CSR pattern of dR/dX (:class:`jointdyn.hb._sparse.SparsePattern`; built once), or None
        where :meth:`evaluate_sparse` does not apply: scalar contacts (their kernel writes a dense
        Jacobian), no interfaces, a condensed problem, a free-free structure (its gauge of the mean,
        :func:`mean_gauge`, is dense), or a
        :class:`~jointdyn.hb.parameters.SystemParameter`."""
        if (self.contacts or not self.has_interfaces or self.condensed or self.gauge is not None
                or isinstance(self.parameter, SystemParameter)):
            return None
        if getattr(self, "_pattern", None) is None:
            from ._sparse import SparsePattern

            sys_ = self.system
            split = self.damping_split()
            C = sys_.C if split is None else split.rayleigh
            self._pattern = SparsePattern((sys_.K, C, sys_.M), self.H, self.pair_positions)
        return self._pattern

    def damping_split(self):
        """The split of a modal damping operator into its Rayleigh part and the rest
        (:class:`jointdyn.hb._damped.DampingSplit`; built once), or None where C is an array."""
        if not is_operator(self.system.C):
            return None
        if getattr(self, "_damping", None) is None:
            from ._damped import DampingSplit

            self._damping = DampingSplit(self.system.C, self.system.M, self.system.K)
        return self._damping

    def evaluate_sparse(self, X, p) -> _Eval:
        """:meth:`evaluate` with dR/dX as a ``scipy.sparse.csr_matrix`` (N/m), for a system whose only
        nonlinear elements are interfaces (:meth:`sparse_pattern`), not condensed; no scaled copies. The linear terms
        are summed by their nonzeros and the pairs' Jacobians assembled into the pattern: the values are
        those of :meth:`evaluate` up to the order of the sums. With modal damping as an operator
        (:meth:`damping_split`), dR/dX is a :class:`jointdyn.hb._damped.DampedJacobian`: the sparse matrix with
        the Rayleigh part of C, and the rest of C as an operator."""
        pat = self.sparse_pattern()
        if pat is None:
            raise ValueError("evaluate_sparse: the system must have interfaces and no scalar contacts, and the "
                             "parameter must not be a SystemParameter")
        X = np.ascontiguousarray(X, dtype=np.float64)
        w, dwdp, Fe, Fp, _, _, _ = self._inputs(p)
        R, Jp, lin_values = pat.linear(X, w, dwdp, Fe, Fp)
        split = self.damping_split()
        if split is not None:  # the damping beyond its Rayleigh part, as an operator (jointdyn.hb._damped)
            Y, dY = split.harmonics(X, self.n, self.H, w)
            R += Y
            Jp += dwdp * dY
        ev, G = self._pairs_eval(X, R, Jp)
        ev.JX = pat.jacobian(lin_values, G)
        if split is not None:
            from ._damped import DampedJacobian

            ev.JX = DampedJacobian(ev.JX, split, self.n, self.H, w)
        return ev

    def _pairs_eval(self, X, R, Jp):
        """The pairs' AFT added to the linear residual ``R`` (in place): the evaluation (without dR/dX)
        and the pairs' Jacobian blocks ``G`` (npairs, 3 nh, 3 nh), N/m."""
        npairs, ns, nd = self.pair_params.shape[0], self.Ns, 3 * self.nh
        G = np.empty((npairs, nd, nd))
        info = np.array([0.0, 0.0, PERIOD_ONE])
        ev = _Eval(R, None, Jp, np.empty((0, ns)), np.empty((0, ns), dtype=np.int64), info, None, np.empty((0, ns)))
        ev.pair_T, ev.pair_N = np.empty((npairs, ns, 2)), np.empty((npairs, ns))
        ev.pair_code = np.empty((npairs, ns), dtype=np.int8)
        pairs_aft_kernel()(self.pair_positions, self.pair_params, X, self.n, self.E, self.P, *self._pair_dirs,
                           int(self.max_passes), float(HB_PERIODIC_RTOL), ev.R, self._dummy, G,
                           ev.pair_T, ev.pair_N, ev.pair_code, ev.info)
        return ev, G

    def large_jacobian(self) -> str:
        """How the Jacobian is evaluated from ``config.CONT_KRYLOV_SOLVE`` unknowns: ``"sparse"``
        (:meth:`evaluate_sparse`: at most ``config.CONT_SPARSE_DENSITY`` of its entries nonzero),
        ``"blocks"`` (:meth:`evaluate_blocks`: a structure dense on its DOFs, with
        ``options.block_preconditioner``) or ``"dense"`` (:meth:`evaluate`: smaller problems, scalar
        contacts, condensed problems, a SystemParameter)."""
        if (self.size < config.CONT_KRYLOV_SOLVE or self.contacts or not self.has_interfaces or self.condensed
                or isinstance(self.parameter, SystemParameter)):
            return "dense"
        if self.gauge is not None:  # the gauge of the mean is dense on the DOFs
            return "blocks" if self.options.block_preconditioner else "dense"
        sys_ = self.system
        # an upper bound of the pattern's density without building it (np.unique of millions of keys for a
        # reduced model, only to find it dense); modal damping enters the pattern by its Rayleigh part
        nd = 3 * self.nh
        split = self.damping_split()
        C = sys_.C if split is None else split.rayleigh
        bound = (np.count_nonzero((sys_.K != 0.0) | (sys_.M != 0.0)) * self.nh
                 + 2 * self.H * np.count_nonzero(C) + 4 * self.pair_positions.shape[0] * nd * nd)
        if bound <= 4 * config.CONT_SPARSE_DENSITY * float(self.size) ** 2:
            if self.sparse_pattern().density <= config.CONT_SPARSE_DENSITY:
                return "sparse"
        return "blocks" if self.options.block_preconditioner else "dense"

    def evaluate_blocks(self, X, p) -> _Eval:
        """:meth:`evaluate_sparse` with dR/dX as a :class:`jointdyn.hb._jacobian.HarmonicJacobian` (N/m): the
        linear terms as one dense block per harmonic, the pairs' Jacobians as a sparse matrix; for a
        structure dense on its DOFs (a reduced model), where summing the dense blocks into one sparse
        matrix at every evaluation costs more than the rest of it. Same conditions and values."""
        if self.contacts or not self.has_interfaces or self.condensed or isinstance(self.parameter, SystemParameter):
            raise ValueError("evaluate_blocks: the system must have interfaces and no scalar contacts, and the "
                             "parameter must not be a SystemParameter")
        from ._jacobian import HarmonicJacobian
        from ._precond import harmonic_blocks

        X = np.ascontiguousarray(X, dtype=np.float64)
        w, dwdp, Fe, Fp, _, _, _ = self._inputs(p)
        spans = harmonic_blocks(self.n, self.H)
        K, C, M = (np.asarray(a, dtype=np.float64) for a in (self.system.K, self.system.C, self.system.M))
        n = self.n
        R, Jp, blocks = -Fe.copy(), -np.asarray(Fp, dtype=np.float64).copy(), []
        for k, (lo, hi) in enumerate(spans):
            B = np.empty((hi - lo, hi - lo))
            if k == 0:
                B[:] = K if self.gauge is None else K + self.gauge
            else:
                np.multiply(M, -(k * w) ** 2, out=B[:n, :n])
                B[:n, :n] += K
                B[n:, n:] = B[:n, :n]
                np.multiply(C, k * w, out=B[:n, n:])
                np.negative(B[:n, n:], out=B[n:, :n])
                if dwdp != 0.0:  # d(block)/dw X: -2 k^2 w M on the diagonal, +-k C off it
                    MX, CX = M @ X[lo:hi].reshape(2, n).T, C @ X[lo:hi].reshape(2, n).T
                    Jp[lo:lo + n] += dwdp * (-2.0 * k * k * w * MX[:, 0] + k * CX[:, 1])
                    Jp[lo + n:hi] += dwdp * (-2.0 * k * k * w * MX[:, 1] - k * CX[:, 0])
            R[lo:hi] += B @ X[lo:hi]
            blocks.append(B)
        ev, G = self._pairs_eval(X, R, Jp)
        ev.JX = HarmonicJacobian(spans, blocks, self._pairs_pattern().jacobian(np.empty(0), G))
        return ev

    def _pairs_pattern(self):
        """The CSR pattern of the pairs' part of dR/dX alone (built once)."""
        if getattr(self, "_pair_pattern", None) is None:
            from ._sparse import SparsePattern

            Z = np.zeros((self.n, self.n))
            self._pair_pattern = SparsePattern((Z, Z, Z), self.H, self.pair_positions)
        return self._pair_pattern

    def problem_at(self, p: float):
        """The harmonic-balance problem of the System that this problem's
        :class:`~jointdyn.hb.parameters.SystemParameter` builds at p, at this problem's fixed frequency
        (cached); condensed onto the same DOFs when this one is."""
        par = self.parameter
        return _problem_at(type(self), par, self.H, self.Ns, self.max_passes, self.gamma_fixed * self.w0,
                           self.system.ndof, len(self.contacts), float(p),
                           tuple(int(d) for d in self.dofs) if self.condensed else None)

    def _evaluate_central(self, X, p, scales) -> _Eval:
        """Residual of the System built at p; dR/dp by a central difference (SystemParameter)."""
        par = self.parameter
        h = par.step(p)
        ev = self.problem_at(p).evaluate(X, p)
        Rp = self.problem_at(p + h).evaluate(X, p + h).R
        Rm = self.problem_at(p - h).evaluate(X, p - h).R
        Jp = (Rp - Rm) / (2.0 * h)
        scaled = None
        if scales is not None:
            xs, fs, ps = scales
            scaled = (ev.R / fs, ev.JX * (xs / fs), Jp * (ps / fs))
        return dataclasses.replace(ev, Jp=Jp, scaled=scaled)

    # --- post-processing ----------------------------------------------------
    def dof_coefficients(self, X, dof: int, p=None):
        """Harmonic coefficients (2H+1) of system DOF ``dof`` at the coefficients X, m.

        ``X`` is one coefficient vector or a stack (points, size); the result
        is (2H+1,) or (points, 2H+1). ``p`` (the parameter value, one per
        point) is needed only by a condensed problem for a DOF that is not
        among its unknowns.
        """
        X = np.asarray(X, dtype=np.float64)
        return X.reshape(X.shape[:-1] + (self.nh, self.n))[..., self.dof_index(dof)]

    def full_coefficients(self, X, p):
        """Coefficients of every DOF of the system (harmonic-major, ``ndof * (2H+1)``), m."""
        return np.array(X, dtype=np.float64)

    def amplitudes(self, X, dof: int, p=None):
        """(half peak-to-peak, mean, max |x|) of x_dof(t), m.

        Extrema located on ``fourier.HB_FINE_SAMPLES`` samples per period
        and refined by a parabola (:func:`jointdyn.fourier.extrema`). ``p``
        as in :meth:`dof_coefficients`.
        """
        c = self.dof_coefficients(X, dof, p)
        hi, lo = extrema(c, self.H)
        c0 = float(c[0])
        return 0.5 * (hi - lo), c0, max(abs(hi), abs(lo))

    def first_harmonic_amplitude(self, X, dof: int, p=None) -> float:
        """sqrt(a_1^2 + b_1^2) of DOF ``dof``, m."""
        c = self.dof_coefficients(X, dof, p)
        return math.hypot(c[1], c[2])

    def pair_results(self, X, ev: _Eval) -> dict | None:
        """Per node pair of the interfaces (stacked over them) at coefficients X (m) and their evaluation
        ``ev``: ``energy_J`` the energy dissipated per cycle, ``oint T . du`` (J, the sum over the AFT samples,
        the quadrature of the Galerkin projection, so that the energy balance holds to the residual), and the
        fractions of the period ``stick``, ``slip`` and ``open`` (over the samples, their sum 1): the data
        of a slip map. None without interfaces."""
        if not self.has_interfaces:
            return None
        npairs = self.pair_positions.shape[0]
        Xm = np.asarray(X, dtype=np.float64).reshape(self.nh, self.n)
        Y = np.zeros((self.nh, npairs, 2))
        for k in range(2):
            for col, sign in ((k, 1.0), (k + 3, -1.0)):
                pos = self.pair_positions[:, col]
                live = pos >= 0
                Y[:, live, k] += sign * Xm[:, pos[live]]
        du = np.einsum("jh,hpk->pjk", self.E @ derivative_matrix(self.H), Y)  # du/dtau at the samples, m
        code = ev.pair_code
        return {"energy_J": np.einsum("pjk,pjk->p", ev.pair_T, du) * (2.0 * math.pi / self.Ns),
                "stick": np.mean(code == STICK_SLIP, axis=1), "slip": np.mean(code == MACROSLIP, axis=1),
                "open": np.mean(code == SEPARATION, axis=1)}

    def dense_jacobians(self) -> bool:
        """True when a branch of this problem is continued with dense Jacobians: at most
        ``options.dense_max_unknowns`` unknowns (else :meth:`large_jacobian` decides)."""
        return self.size <= self.options.dense_max_unknowns


def contacts_only(system: System) -> System:
    """The system itself without interfaces, else a copy without them (cached per object): what the
    scalar contacts' packing (:func:`~jointdyn.kinematics.contact_kinematics`) reads; the interfaces' pairs
    are evaluated on their own (:func:`~jointdyn.hb._aft_pairs.pairs_aft`)."""
    if not system.interfaces:
        return system
    return _stripped(system)


def stuck_stiffness(system: System) -> np.ndarray:
    """K_reference + sum_c kt_c b_c b_c^T (N/m): the structure with every contact stuck (and every interface
    pair closed at rest stuck: its springs kt, kt beside the kn of K_reference), the static stiffness that
    harmonic balance and the linear modes of the nonlinear modes start from."""
    B = selection_matrix(contact_kinematics(contacts_only(system)), system.ndof)
    K = system.K_reference.copy()
    for c, b in zip(system.contacts, B):
        K += c.law.kt * np.outer(b, b)
    for itf in system.interfaces:
        Bi = itf.selection(system.ndof)
        closed = itf.preload > 0.0
        for k in range(2):
            rows = Bi[k::3][closed]
            K += rows.T @ (itf.kt[closed][:, None] * rows)
    return K


@by_identity
def _stripped(system: System) -> System:
    return dataclasses.replace(system, interfaces=(), w0_rad_s=system.w0)


def reference_scales(system: System) -> tuple[float, float]:
    """(kt N/m, fy N) that normalise amplitudes (q = kt x / fy): the first contact's law, else the
    interfaces' patch as a whole along one tangential direction (kt the sum of the pairs' kt, fy the sum
    of their slip forces at rest, mu P); ValueError naming ``system`` when it has neither."""
    if system.contacts:
        law = system.contacts[0].law
        return float(law.kt), float(law.fy)
    if system.interfaces:
        kt = sum(float(np.sum(itf.kt)) for itf in system.interfaces)
        return kt, sum(float(np.sum(itf.mu * itf.preload)) for itf in system.interfaces)
    raise ValueError("system must have at least one contact or interface")


def amplitude_q_meaning(system: System) -> str:
    """What ``amplitude_q`` is for ``system`` (the long name of the variable, and of the JSON key
    ``amplitude_q_meaning``): the reference scales of :func:`reference_scales` in words."""
    if system.contacts:
        return "kt X / fy of the first contact (X the amplitude in m, fy = mu n_ref)"
    kt, fy = reference_scales(system)
    if not fy > 0.0:
        return ("undefined (null): every interface pair is open at rest (mu x preload = 0), so there is no slip "
                "force to scale by; see amplitude_m")
    return ("sum(kt) X / sum(mu preload) of the interfaces' pairs taken as one patch along one tangential "
            "direction (X the amplitude in m)")


@by_value(maxsize=8)
def _problem_at(cls, parameter, H, Ns, max_passes, w, ndof, ncontacts, p, dofs):
    """Problem of class ``cls`` (:class:`HBProblem`, or the condensed problem when ``dofs`` is not None) of
    ``parameter.build(p)`` at frequency w (the last few values of p are kept), condensed onto ``dofs``
    unless None."""
    system = parameter.build(p)
    if not isinstance(system, System):
        raise ValueError(f"build({parameter.name} = {p!r}) must return a jointdyn.System")
    if system.ndof != ndof or len(system.contacts) != ncontacts:
        raise ValueError(f"build({parameter.name} = {p!r}) must keep {ndof} DOFs and {ncontacts} contacts")
    kw = {"harmonics": H, "samples": Ns, "parameter": _FixedFrequency(w), "max_passes": max_passes}
    if dofs is None:
        return cls(system, **kw)
    q = cls(system, response_dofs=[d for d in dofs if d >= 0], **kw)  # -1: a relative coordinate
    if tuple(int(d) for d in q.dofs) != dofs:
        raise ValueError(f"build({parameter.name} = {p!r}) must keep the contacts on the same DOFs "
                         f"(condensed onto {list(dofs)}, got {q.dofs.tolist()})")
    return q

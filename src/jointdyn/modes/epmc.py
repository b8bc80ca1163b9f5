"""Extended periodic motion concept (EPMC, Krack 2015): backbones of nonlinear modes.

A nonlinear mode of a damped structure is sought as a periodic *free*
motion of (docs/model.md section 9, docs/modes.md)::

    M x'' + (C - xi M) x' + K x + sum_c B_c T_c(u_c, N_c) = 0,

where the artificial negative mass-proportional damping xi M x' cancels
the dissipation exactly. In normalised time tau = omega t the motion is
expanded in harmonics 0..H (:mod:`jointdyn.fourier`) and the equations are
those of harmonic balance (:class:`~jointdyn.hb.HBProblem`) without
forcing, with ``C - xi M`` for C. The contact forces come from the same
compiled AFT evaluation, with the same laws and the same exact
forward-mode Jacobians; the linear part's derivatives along omega and xi
are written out::

    R(X, omega, xi) = R_hb(X, omega) - xi omega A_M X,
    dR/dX = J_hb - xi omega A_M,
    dR/domega = (A_C + 2 omega A_M) X - xi A_M X,     dR/dxi = -omega A_M X,

with ``A_M`` the block ``[[0, k M], [-k M, 0]]`` of harmonic k (the
damping block of harmonic balance with M for C).

Unknowns and normalisation. The modal amplitude ``a`` is the
first-harmonic amplitude of the output DOF; the phase is fixed by a zero
sine coefficient of that DOF's first harmonic, so that its cosine
coefficient is ``a``. Both coefficients are known, and their places in the
vector of unknowns hold omega and xi instead: the system stays square
(``n (2H + 1)`` equations and unknowns). The continuation parameter is
``lam = log10(a)`` (logarithmic stepping over decades), the coefficients
are scaled by ``a`` (``X = a Y``), omega and xi by the linear stuck
frequency, and the residual by ``k_ref a`` (``k_ref`` the largest diagonal
entry of the stuck stiffness), so every scaled quantity is of order one at
every amplitude and the derivative along lam is exact::

    R_s = R(a Y) / (k_ref a),   dR_s/dlam = ln(10) (J Y / k_ref - R_s).

The branch starts at the smallest amplitude from the linear stuck mode
(:func:`jointdyn.modes._free.linear_stuck_mode`) and is followed by the
generic pseudo-arc-length continuation (:mod:`jointdyn.continuation`).

Large structures: ``epmc(system, ..., reduce=n_modes)`` computes the
backbone on a Craig-Bampton reduction (:func:`jointdyn.reduction.reduce_system`)
whose boundary DOFs are the contact DOFs, the DOFs of the interfaces'
node pairs, the forced DOFs and the output DOF, plus ``n_modes`` fixed-interface modes. The output DOF is a boundary
DOF, kept as it is, so the backbone's amplitude is that of the full
model's output DOF; the backbone holds the reduction (its linear-mode
error report and the expansion of the mode shape to the full model).

Normal loads: every autonomous load that harmonic balance evaluates
(constant loads; a normal spring as soon as the harmonic-balance contact
evaluation takes it) is taken as it is; loads prescribed at a forcing
frequency are refused (:func:`jointdyn.modes._free.check_free_vibration`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _validate as V
from .. import config
from ..continuation import (ContinuationOptions, ContinuationStatus, ParameterProgress, continuation, make_options,
                            newton, preconditioned_by)
from ..fourier import derivative_matrix
from ..hb import HBProblem
from ..hb._sparse import linear_entries
from ..hb.levels import AUTO, Discretisation, check_memory
from ..hb.options import HBOptions
from ..hb.options import hb_options as _hb_options
from ..hb.problem import contacts_only
from ..hb.results import sliding_as_a_whole
from ..kinematics import contact_kinematics, selection_matrix
from ._free import amplitude_range, check_free_vibration, linear_stuck_mode, output_dof_of
from .backbone import Backbone, ModeStatus
from .options import EPMCOptions
from .options import epmc_options as _epmc_options

__all__ = ["EPMCProblem", "epmc"]

_LN10 = math.log(10.0)


def mass_damping_block(M: np.ndarray, H: int) -> np.ndarray:
    """A_M: the harmonic-balance damping block of harmonics 0..H with M for C (size n (2H + 1))."""
    n = M.shape[0]
    A = np.zeros((n * (2 * H + 1), n * (2 * H + 1)))
    for k in range(1, H + 1):
        ic = (2 * k - 1) * n
        is_ = 2 * k * n
        A[ic:ic + n, is_:is_ + n] = k * M
        A[is_:is_ + n, ic:ic + n] = -k * M
    return A


def _sparse_mass_damping(M: np.ndarray, H: int):
    """:func:`mass_damping_block` as a ``scipy.sparse.csr_matrix``: the damping entries of harmonic balance
    (:func:`jointdyn.hb._sparse.linear_entries`) with M for C."""
    import scipy.sparse as sps

    zero = np.zeros_like(M)
    rows, cols, _, km, _ = linear_entries(zero, M, zero, H)  # M in C's place: the entries +-k M
    on = km != 0.0
    size = M.shape[0] * (2 * H + 1)
    return sps.csr_matrix((km[on], (rows[on], cols[on])), shape=(size, size))


class EPMCProblem:
    """Scaled EPMC residual ``R(v, lam)`` and its exact Jacobians (module docstring).

    Parameters
    ----------
    system : System
        Structure with frictional contacts under autonomous normal loads;
        its forcing is not used.
    mode : int
        Linear stuck mode to start from (1-based, increasing frequency).
    output_dof : int, optional
        DOF whose first-harmonic amplitude is the modal amplitude (default:
        the system's response DOF).
    harmonics : int
        Highest harmonic H (>= 1).
    samples : int
        AFT samples per period (>= 2H + 2).
    max_passes : int
        Bound on the periods marched per AFT evaluation.
    hb_options : HBOptions, optional
        Harmonic balance's numbers of the contact evaluation (:class:`~jointdyn.hb.options.HBOptions`;
        None: the defaults).
    epmc_options : EPMCOptions, optional
        The EPMC's own numbers (:class:`~jointdyn.modes.options.EPMCOptions`; None: the defaults).

    Attributes
    ----------
    hb : HBProblem
        Harmonic balance of the unforced system (the contact evaluation).
    options : EPMCOptions
        The EPMC's own numbers.
    linear : LinearMode
        The linear stuck mode.
    i_omega, i_xi : int
        Places of omega and xi in the scaled unknowns ``v`` (those of the
        cosine and sine coefficients of the output DOF's first harmonic).
    w_ref, k_ref : float
        Scales of omega and xi (rad/s) and of the residual (N/m).
    """

    def __init__(self, system, *, mode: int = 1, output_dof: int | None = None,
                 harmonics: int = config.HB_HARMONICS, samples: int = config.HB_SAMPLES,
                 max_passes: int = config.HB_MAX_PASSES, hb_options: HBOptions | None = None,
                 epmc_options: EPMCOptions | None = None):
        self.options = _epmc_options(epmc_options)
        check_free_vibration(system, "EPMC", held=True)
        self.system = system
        self.output_dof = output_dof_of(system, output_dof)
        n = system.ndof
        H = V.positive_int("harmonics", harmonics, 1)
        V.positive_int("samples", samples, 2 * H + 2)
        free = dataclasses.replace(system, force=np.zeros(n), force_phase_deg=np.zeros(n))
        try:
            self.hb = HBProblem(free, harmonics=harmonics, samples=samples, max_passes=max_passes,
                                options=hb_options)
        except ValueError as exc:
            raise ValueError(f"{exc} (EPMC evaluates the contacts by harmonic balance)") from None
        self.linear = linear_stuck_mode(system, mode, self.output_dof)
        self.n, self.H, self.size = n, self.hb.H, self.hb.size
        # dense A_M for small problems (one product beats 2H small ones); by blocks from the size where the
        # continuation's solves go large (an N x N A_M is 240 MB at 5500 unknowns)
        self.A_M = mass_damping_block(system.M, self.H) if self.size < config.CONT_KRYLOV_SOLVE else None
        self._mass_blocks = [(k * system.M, -k * system.M, slice((2 * k - 1) * n, 2 * k * n),
                              slice(2 * k * n, (2 * k + 1) * n)) for k in range(1, self.H + 1)]
        self.i_omega = n + self.output_dof
        self.i_xi = 2 * n + self.output_dof
        # interfaces from the size where the continuation's solves go large: the Jacobian stays sparse (a sparse
        # structure, jointdyn.hb._sparse) or in its harmonic blocks (a dense one, jointdyn.hb._jacobian) from
        # the evaluation on
        #: how the residual's Jacobian is evaluated (:meth:`jointdyn.hb.HBProblem.large_jacobian`)
        self.kind = self.hb.large_jacobian()
        #: True when the residual's Jacobian is a scipy.sparse matrix
        self.sparse = self.kind == "sparse"
        self._A_M_sparse = _sparse_mass_damping(system.M, self.H) if self.sparse else None
        self.w_ref = self.linear.omega_rad_s
        self.k_ref = float(np.max(np.abs(np.diag(self.linear.stiffness))))
        self.B = selection_matrix(contact_kinematics(contacts_only(system)), n)
        self.last = None

    # --- unknowns -----------------------------------------------------------
    def unpack(self, v, lam):
        """(X m, omega rad/s, xi 1/s) of the scaled unknowns ``v`` at ``lam = log10(a)``."""
        Y = np.array(v, dtype=np.float64)
        w = Y[self.i_omega] * self.w_ref
        xi = Y[self.i_xi] * self.w_ref
        Y[self.i_omega] = 1.0
        Y[self.i_xi] = 0.0
        return (10.0 ** lam) * Y, w, xi

    def pack(self, X, omega, xi):
        """Scaled unknowns of coefficients X (m, normalised: sine of the output DOF's first harmonic 0),
        omega (rad/s) and xi (1/s)."""
        a = X[self.i_omega]
        v = np.asarray(X, dtype=np.float64) / a
        v[self.i_omega] = omega / self.w_ref
        v[self.i_xi] = xi / self.w_ref
        return v

    def linear_guess(self):
        """Scaled unknowns of the linear stuck mode: shape, frequency and the viscous modal damping of C."""
        phi = self.linear.mass_normalised
        xi0 = float(phi @ (self.system.C @ phi))  # phi^T C phi / phi^T M phi, 1/s
        X = np.zeros(self.size)
        X[self.n:2 * self.n] = self.linear.shape
        return self.pack(X, self.linear.omega_rad_s, xi0)

    # --- residual -----------------------------------------------------------
    def evaluate(self, X, omega):
        """The harmonic-balance evaluation (residual without xi, contact forces) at X (m), omega (rad/s); its
        Jacobian sparse where :attr:`sparse`."""
        if self.sparse:
            return self.hb.evaluate_sparse(X, omega / self.hb.w0)
        if self.kind == "blocks":
            return self.hb.evaluate_blocks(X, omega / self.hb.w0)
        return self.hb.evaluate(X, omega / self.hb.w0)

    def residual(self, v, lam):
        """``(R_s, dR_s/dv, dR_s/dlam)``: the scaled residual and its exact Jacobians (dR_s/dv a
        ``scipy.sparse`` matrix where :attr:`sparse`)."""
        a = 10.0 ** lam
        X, w, xi = self.unpack(v, lam)
        Y = X / a
        ev = self.evaluate(X, w)
        self.last = (X, w, xi, ev)
        cx = self._times_mass_damping(X)
        R = ev.R - (xi * w) * cx
        if self.sparse and getattr(ev.JX, "structured", False):  # modal damping as an operator
            J = ev.JX.plus_sparse(-(xi * w) * self._A_M_sparse)
        elif self.sparse:
            J = ev.JX - (xi * w) * self._A_M_sparse
        elif self.kind == "blocks":
            J = ev.JX
            for k, (lo, hi) in enumerate(J.spans[1:], start=1):  # -xi w A_M on the harmonics' blocks, in place
                n = self.n
                J.blocks[k][:n, n:] -= (xi * w * k) * self.system.M
                J.blocks[k][n:, :n] += (xi * w * k) * self.system.M
        else:
            # in place on the evaluation's own Jacobian (nothing reads it afterwards): at thousands of unknowns
            # every copy of an N x N array costs as much as the AFT of hundreds of node pairs
            J = ev.JX
            self._subtract_mass_damping(J, xi * w)
        ka = self.k_ref * a
        Rs = R / ka
        Jlam = _LN10 * (J @ Y / self.k_ref - Rs)
        # the columns of omega and xi (module docstring)
        c_omega = self.w_ref * (ev.Jp / self.hb.w0 - xi * cx) / ka
        c_xi = -self.w_ref * w * cx / ka
        return Rs, self._scaled_jacobian(J, c_omega, c_xi), Jlam

    def _scaled_jacobian(self, J, c_omega, c_xi):
        """dR_s/dv: J / k_ref with the columns of omega and xi replaced (in place on a dense J)."""
        if self.kind == "blocks" or getattr(J, "structured", False):
            return J.scaled(1.0 / self.k_ref).with_columns({self.i_omega: c_omega, self.i_xi: c_xi})
        if not self.sparse:
            J /= self.k_ref
            J[:, self.i_omega] = c_omega
            J[:, self.i_xi] = c_xi
            return J
        import scipy.sparse as sps

        Jv = (J * (1.0 / self.k_ref)).tocsc()
        for i in (self.i_omega, self.i_xi):
            Jv.data[Jv.indptr[i]:Jv.indptr[i + 1]] = 0.0
        cols = np.stack((c_omega, c_xi), axis=1)
        r, c = np.nonzero(cols)
        return Jv + sps.csc_matrix((cols[r, c], (r, np.array((self.i_omega, self.i_xi))[c])), shape=Jv.shape)

    def _times_mass_damping(self, X):
        """A_M @ X, m kg (by blocks for large problems: A_M is zero outside its 2H blocks)."""
        if self.A_M is not None:
            return self.A_M @ X
        out = np.zeros_like(X)
        for kM, mkM, c, s in self._mass_blocks:
            out[c] = kM @ X[s]
            out[s] = mkM @ X[c]
        return out

    def _subtract_mass_damping(self, J, f):
        """J -= f A_M in place (on A_M's blocks only for large problems)."""
        if self.A_M is not None:
            J -= f * self.A_M
            return
        for kM, mkM, c, s in self._mass_blocks:
            J[c, s] -= f * kM
            J[s, c] -= f * mkM

    def solve(self, amplitude: float, guess, options: ContinuationOptions | None = None, **overrides):
        """Newton at a fixed amplitude (m) from scaled unknowns ``guess``: ``(v, converged, iterations)``."""
        opt = _options(options, overrides, self.options)
        return newton(self.residual, np.asarray(guess, dtype=np.float64), math.log10(amplitude), opt)

    # --- per point ----------------------------------------------------------
    def energies(self, X, omega, ev):
        """Per period: (int x'^T M x' dt in J s, viscous energy J, energy of each contact J, energy of each
        interface pair J or None, :meth:`~jointdyn.hb.HBProblem.pair_results`).

        Integrals of products of trigonometric polynomials are exact on the
        coefficients; the contact energies ``oint T_c du_c`` are the
        discrete sums over the AFT samples, the quadrature the Galerkin
        projection uses, so that the energy balance of a converged point
        holds to its residual.
        """
        hb = self.hb
        Xm = X.reshape(hb.nh, self.n)
        DX = derivative_matrix(self.H) @ Xm  # d/dtau, m
        M, C = self.system.M, self.system.C
        kin = omega * math.pi * float(np.einsum("ri,ij,rj->", DX, M, DX))
        visc = omega * math.pi * float(np.einsum("ri,ir->", DX, C @ DX.T))  # C may be an operator
        du = hb.E @ (DX @ self.B.T)  # (Ns, contacts): du_c/dtau at the samples, m
        contact = np.einsum("cj,jc->c", ev.T, du) * (2.0 * math.pi / hb.Ns)
        pairs = hb.pair_results(X, ev)
        return kin, visc, contact, (None if pairs is None else pairs["energy_J"])

    def modal_amplitude(self, X) -> float:
        """sqrt(a1^T M a1 + b1^T M b1) of the first harmonic, kg^1/2 m."""
        Xm = X.reshape(self.hb.nh, self.n)
        M = self.system.M
        return math.sqrt(float(Xm[1] @ M @ Xm[1] + Xm[2] @ M @ Xm[2]))


def _repeated_note(linear) -> str:
    """Why a start from a repeated eigenvalue fails, or ''."""
    if not linear.repeated:
        return ""
    others = " and ".join(str(j) for j in linear.repeated)
    return (f": its frequency {linear.omega_rad_s:.6g} rad/s is repeated (mode {others} too), so the mode shape "
            "at small amplitude is any combination of theirs and the start is singular; detune the structure "
            "slightly (e.g. the stiffness of one of the symmetric DOFs by 1e-4 of its value)")


def _options(options, overrides, eopts: EPMCOptions) -> ContinuationOptions:
    """The step control of EPMC: the defaults of ``eopts`` (:class:`~jointdyn.modes.options.EPMCOptions`),
    then ``options``, then ``overrides``."""
    if options is None:
        options = ContinuationOptions(ds=eopts.ds_start, ds_max=eopts.ds_max, tol=eopts.tol)
    return make_options(options, overrides)


_STATUS = {
    ContinuationStatus.COMPLETE: ModeStatus.COMPLETE,
    ContinuationStatus.MAX_POINTS: ModeStatus.MAX_POINTS,
}


def _points(problem: EPMCProblem, lam, V, stash):
    """Per-point arrays of the backbone from the continued unknowns (evaluations reused from ``stash``)."""
    p = lam.size
    nc = len(problem.system.contacts)
    out = {k: np.empty(p) for k in ("amplitude_m", "omega_rad_s", "xi_rad_s", "damping_ratio",
                                      "damping_ratio_contacts", "damping_ratio_viscous", "modal_amplitude",
                                      "energy_viscous_J")}
    out["X"] = np.empty((p, problem.size))
    out["contact_energy_J"] = np.empty((p, nc))
    for i in range(p):
        X, w, xi = problem.unpack(V[i], lam[i])
        ev = stash.get(X.tobytes())
        if ev is None:
            ev = problem.evaluate(X, w)
        kin, visc, contact, pairs = problem.energies(X, w, ev)
        out["amplitude_m"][i] = 10.0 ** lam[i]
        out["omega_rad_s"][i] = w
        out["xi_rad_s"][i] = xi
        out["damping_ratio"][i] = xi / (2.0 * w)
        dissipated = float(np.sum(contact)) + (0.0 if pairs is None else float(np.sum(pairs)))
        out["damping_ratio_contacts"][i] = dissipated / (2.0 * w * kin)
        out["damping_ratio_viscous"][i] = visc / (2.0 * w * kin)
        out["modal_amplitude"][i] = problem.modal_amplitude(X)
        out["energy_viscous_J"][i] = visc
        out["contact_energy_J"][i] = contact
        if pairs is not None:
            out.setdefault("pair_energy_J", np.empty((p, pairs.size)))[i] = pairs
        out["X"][i] = X
    return out


def _backbone(problem: EPMCProblem, status, message, lam, V, stash, counters, reduction=None) -> Backbone:
    pts = _points(problem, np.asarray(lam, dtype=np.float64), V, stash)
    return Backbone(method="epmc", status=status, message=message, system=problem.system, linear=problem.linear,
                    output_dof=problem.output_dof, harmonics=problem.H, samples=problem.hb.Ns,
                    counters=dict(counters), problem=problem, reduction=reduction, **pts)


def _reduce(system, n_modes: int, output_dof):
    """(reduced System, CraigBampton): boundary = contact, pair, forced and output DOFs, plus ``n_modes`` modes."""
    from ..reduction import default_boundary, reduce_system

    out = output_dof_of(system, output_dof)
    target = system if out == system.response_dof else dataclasses.replace(system, output_dof=out)
    return reduce_system(target, n_modes, sorted(set(default_boundary(target)) | {out}))


def epmc(system, amplitude=None, *, mode: int = 1, output_dof: int | None = None,
         harmonics: int | str = config.HB_HARMONICS, samples: int | str = config.HB_SAMPLES,
         options: ContinuationOptions | None = None, progress: bool | None = None, reduce: int | None = None,
         hb_options: HBOptions | None = None, epmc_options: EPMCOptions | None = None, **overrides) -> Backbone:
    """Backbone of a nonlinear mode by the extended periodic motion concept.

    Parameters
    ----------
    system : System
        Structure with frictional contacts; every normal load autonomous
        (constant, or a normal spring once harmonic balance evaluates it);
        its forcing is ignored.
    amplitude : (float, float), optional
        Range (min, max) of the modal amplitude, the first-harmonic
        amplitude of the output DOF, m (default: ``config.MODES_AMPLITUDE_Q``
        times fy / kt of the first contact). Stepped in log10.
    mode : int
        Linear stuck mode the backbone starts from (1-based).
    output_dof : int, optional
        DOF of the modal amplitude (default: the system's response DOF).
    harmonics : int or "auto"
        Highest harmonic H (>= 1). ``"auto"``: from ``config.HB_HARMONICS``,
        raised to 2H + 1 while the backbone's frequency or damping at its
        check points changes by more than ``config.HB_AUTO_RTOL`` with it
        (``jointdyn.modes._auto``; the levels tried and the last check are
        in the message and counters), as ``frc_hb`` does for a branch.
    samples : int or "auto"
        AFT samples per period (>= 2H + 2). ``"auto"``: from
        ``config.HB_SAMPLES``, doubled the same way (where a contact
        separates, its force jumps and too few samples make the backbone
        ripple).
    options : ContinuationOptions, optional
        Step control in the scaled unknowns (arc length in decades of
        amplitude); default ``ds``, ``ds_max`` and ``tol`` of ``epmc_options``
        (``ds_start``, ``ds_max``, ``tol``);
        keyword arguments override its fields (``ds_max``, ``max_points``,
        ``tol``, ...).
    progress : bool, optional
        Show a tqdm bar (None: only on a TTY).
    reduce : int, optional
        Compute the backbone on a Craig-Bampton reduction keeping the
        contact DOFs, the DOFs of the interfaces' node pairs, the forced
        DOFs and the output DOF plus this many
        fixed-interface modes (0 .. interior DOFs; all of them: exact up to
        rounding). ``mode`` then counts the linear modes of the reduced
        model, the same as the full model's while the reduction resolves
        them (``Backbone.reduction.error``). Default: the full model.
    hb_options : HBOptions, optional
        Harmonic balance's numbers of the contact evaluation and of the automatic discretisation
        (:class:`~jointdyn.hb.options.HBOptions`: the Jacobian's form, ``auto_max_harmonics``,
        ``auto_max_samples``, ...; None: the defaults).
    epmc_options : EPMCOptions, optional
        The EPMC's own numbers (:class:`~jointdyn.modes.options.EPMCOptions`: default steps and
        tolerance, Newton iterations of the start, check points of the automatic discretisation;
        None: the defaults).

    Returns
    -------
    Backbone
        ``status`` complete, max-points, failed (the points computed are
        kept) or no-start (empty). With ``reduce``, its ``system``,
        ``X``, ``linear``, ``output_dof`` and ``problem`` are those of the
        reduced model and ``reduction`` is the
        :class:`~jointdyn.reduction.CraigBampton` (``error``: linear
        modes against the full model's; :meth:`Backbone.full_shape`: the
        harmonics of the mode shape on the full model's DOFs).
    """
    hbo, eopts = _hb_options(hb_options), _epmc_options(epmc_options)
    check_memory(system, Discretisation.of(harmonics, samples), options=hbo)
    if harmonics == AUTO or samples == AUTO:
        from ._auto import auto_backbone

        return auto_backbone(epmc, system, amplitude, harmonics=harmonics, samples=samples, mode=mode,
                             output_dof=output_dof, options=options, progress=progress, reduce=reduce,
                             hb_options=hbo, epmc_options=eopts, **overrides)
    check_free_vibration(system, "EPMC", held=True)
    lo, hi = amplitude_range(system, amplitude)
    reduction = None
    if reduce is not None:
        system, reduction = _reduce(system, reduce, output_dof)
        output_dof = None
    problem = EPMCProblem(system, mode=mode, output_dof=output_dof, harmonics=harmonics, samples=samples,
                          hb_options=hbo, epmc_options=eopts)
    opt = _options(options, overrides, eopts)
    lam0, lam1 = math.log10(lo), math.log10(hi)
    with preconditioned_by(problem.hb.block_preconditioner((problem.i_omega, problem.i_xi))):
        return _walked(problem, lam0, lam1, opt, progress, reduction)


def _walked(problem: EPMCProblem, lam0, lam1, opt, progress, reduction) -> Backbone:
    """The backbone of :func:`epmc` from log10 amplitudes lam0 to lam1."""
    v0, ok, _ = newton(problem.residual, problem.linear_guess(), lam0, opt, max_iter=problem.options.start_max_iter)
    if not ok:
        return _backbone(problem, ModeStatus.NO_START, f"Newton did not converge at the smallest amplitude "
                         f"{10.0 ** lam0:.6g} m from linear stuck mode {problem.linear.index}"
                         f"{_repeated_note(problem.linear)}", np.empty(0),
                         np.empty((0, problem.size)), {}, {"points": 0}, reduction)
    stash = {}

    def keep(v, lam):
        last = problem.last
        X = problem.unpack(v, lam)[0]
        if last is not None and last[0].tobytes() == X.tobytes():
            # without its Jacobian (modified in place, and N x N per point): the per-point results do not use it
            stash[X.tobytes()] = dataclasses.replace(last[3], JX=None, scaled=None)

    # the bar fills over the range of log10(amplitude), not against max_points
    with ParameterProgress(lam0, lam1, "EPMC", progress, name="log10(a / m)") as bar:
        res = continuation(problem.residual, v0, lam0, lam1, opt, monitor=keep, progress=bar)
    status = _STATUS.get(res.status, ModeStatus.FAILED if res.lam.size else ModeStatus.NO_START)
    message = res.message.replace("lam = ", "log10(amplitude / m) = ")
    if status is ModeStatus.FAILED and problem.hb.restart_at_reference and problem.last is not None:
        # a part held only through its contacts that slides as a whole: its mean is not unique (the physics)
        message += sliding_as_a_whole(problem.hb, problem.last[3].JX)
    return _backbone(problem, status, message, res.lam, res.y, stash, res.counters, reduction)

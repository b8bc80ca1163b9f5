"""Quasi-static modal analysis (QSMA, Lacayo and Allen 2019): the fast backbone estimate.

The structure is pushed statically along a linear stuck mode through the
contact laws: the load ``f = M phi alpha`` (phi the mass-normalised mode,
alpha the modal force, N kg^-1/2) grows from zero, with the output DOF's
displacement prescribed on a geometric grid and alpha an unknown
(displacement control passes the softening to macroslip without a limit
point), and the equilibrium::

    K x + sum_c B_c T_c(B_c^T x) = M phi alpha,   x[out] = a,

is solved by Newton's method at every grid point from the contact states
committed at the previous one (the virgin loading curve of every contact:
one compiled call, :func:`_push_template`). Per amplitude a:

* modal displacement q = phi^T M x and secant frequency omega^2 = alpha / q;
* Masing's rule: the steady loop of amplitude a is the virgin curve
  stretched by 2, so the energy one contact dissipates per cycle is
  ``E_c = 8 int_0^U T_c du - 4 U T_c(U)`` (U the contact's displacement at
  the turning point). Summed over the contacts this is the area of the
  modal loop ``8 int alpha dq - 4 q alpha`` (the elastic energy cancels).
  The work integrals use the laws' tangents at both ends of each step
  (Hermite's corrected trapezoidal rule, exact for cubic pieces: the
  uniform Iwan backbone is quadratic);
* damping ratio D = E / (2 pi alpha q), and the viscous part
  ``omega x^T C x / (2 alpha q)``.

A free-free structure (the stuck stiffness has rigid-body modes Phi_r,
:func:`jointdyn.systems.free_modes`) is pushed with K + (M Phi_r)(M Phi_r)^T:
the load M phi and the contact forces do no work on Phi_r, so this is the
free structure's equilibrium with its rigid-body part at zero. A part held
only through its contacts is held by them while they stick; where they
slip as a whole the load along the mode is held at their slip force and
the prescribed displacement carries the push on (the part slides), so the
quasi-static backbone continues through macroslip with a falling secant
frequency.

It assumes what the EPMC does not: a motion that stays on the static
deflection shape, harmonic in time, and Masing loops (constant normal
loads). docs/modes.md compares it with the EPMC and says where it holds.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import jit, specialize
from ..continuation.linalg import lu_solve
from ..kinematics import contact_kinematics, selection_matrix
from ..systems import free_modes
from ._free import amplitude_range, check_free_vibration, linear_stuck_mode, output_dof_of
from .backbone import Backbone, ModeStatus
from .options import QSMAOptions, qsma_options

__all__ = ["qsma", "push_grid"]

#: the defaults of the push (:class:`~jointdyn.modes.options.QSMAOptions`)
_DEFAULT = QSMAOptions()


def _push_template(grid, lin, con, ctl, out):  # pragma: no cover - compiled
    """Displacement-controlled static push through the contact laws; returns the points reached.

    * ``grid`` (p,): prescribed displacements of the output DOF (m),
      increasing from above 0;
    * ``lin = (K, f, j)``: stiffness (n, n) N/m, load shape ``f = M phi``
      (n,), output DOF j;
    * ``con = (Bm, Pm, Nc, ssz)``: selection rows (contacts, n), kernel
      parameters (contacts, m), constant normal loads (contacts,) N, state
      length;
    * ``ctl = (tol, max_iter)``: Newton's relative tolerance and iterations;
    * ``out = (xs, als, Ts, kTs)``: per point (p + 1 rows, row 0 the
      virgin origin) the displacements (n,) m, the modal force alpha, each
      contact's force (N) and tangent (N/m) at the end of the step.
    """
    K, f, j = lin
    Bm, Pm, Nc, ssz = con
    tol, max_iter = ctl
    xs, als, Ts, kTs = out
    n = K.shape[0]
    nc = Bm.shape[0]
    s_old = np.zeros((nc, ssz))
    s_new = np.zeros((nc, ssz))
    jvp = (np.zeros((ssz, 0)), np.zeros((ssz, 0)), np.zeros(0))  # no derivative directions
    x = np.zeros(n)
    A = np.empty((n + 1, n + 1))
    r = np.empty(n + 1)
    for c in range(nc):
        INIT(Pm[c], 0.0, Nc[c], s_old[c])  # noqa: F821
    _contact_forces(STEP_JVP, Pm, Bm, Nc, s_old, s_new, jvp, x, Ts[0], kTs[0])  # noqa: F821
    als[0] = 0.0
    alpha = 0.0
    a_prev = 0.0
    for i in range(grid.shape[0]):
        a = grid[i]
        _predict(x, a, a_prev, j)
        alpha = alpha * (a / a_prev) if a_prev > 0.0 else 0.0
        ok = False
        for _ in range(max_iter):
            _contact_forces(STEP_JVP, Pm, Bm, Nc, s_old, s_new, jvp, x, Ts[i + 1], kTs[i + 1])  # noqa: F821
            if _assemble(K, f, j, Bm, Ts[i + 1], kTs[i + 1], x, alpha, a, A, r) <= tol:
                ok = True
                break
            if not lu_solve(A, r):
                return i
            for k in range(n):
                x[k] -= r[k]
            alpha -= r[n]
        if not ok:
            return i
        for c in range(nc):
            for k in range(ssz):
                s_old[c, k] = s_new[c, k]
        for k in range(n):
            xs[i + 1, k] = x[k]
        als[i + 1] = alpha
        a_prev = a
    return grid.shape[0]


@jit(inline="always")
def _predict(x, a, a_prev, j):  # pragma: no cover - compiled
    """Newton's start: the last equilibrium scaled to the new amplitude (the output DOF alone at first)."""
    if a_prev > 0.0:
        for k in range(x.shape[0]):
            x[k] *= a / a_prev
    else:
        x[j] = a


@jit(inline="always")
def _contact_forces(step_jvp, Pm, Bm, Nc, s_old, s_new, jvp, x, T, kT):  # pragma: no cover - compiled
    """Force T[c] (N) and tangent kT[c] (N/m) of every contact at displacements x, from the committed states.

    The law's ``step_jvp`` with no derivative direction: its primal outputs
    are those of ``step`` bit for bit (law contract), and it is the kernel
    harmonic balance has compiled already (``step`` is inlined into its
    callers, which costs a compile of the whole law per template).
    """
    ds, dd, d1 = jvp
    for c in range(Bm.shape[0]):
        u = 0.0
        for k in range(x.shape[0]):
            u += Bm[c, k] * x[k]
        t_, k_, _ = step_jvp(Pm[c], s_old[c], ds, s_new[c], dd, u, d1, Nc[c], d1, d1)
        T[c] = t_
        kT[c] = k_


@jit(inline="always")
def _assemble(K, f, j, Bm, T, kT, x, alpha, a, A, r):  # pragma: no cover - compiled
    """Residual r = (K x + B T - f alpha, x_j - a) and its Jacobian A; returns the relative residual.

    The relative residual is max |r| over the force rows divided by the
    largest elastic, contact or applied force (N / N).
    """
    n = x.shape[0]
    scale = 0.0
    err = 0.0
    for i in range(n):
        acc = -f[i] * alpha
        scale = max(scale, abs(acc))
        el = 0.0
        for k in range(n):
            el += K[i, k] * x[k]
            A[i, k] = K[i, k]
        scale = max(scale, abs(el))
        acc += el
        for c in range(Bm.shape[0]):
            bi = Bm[c, i]
            if bi != 0.0:
                acc += bi * T[c]
                scale = max(scale, abs(bi * T[c]))
                for k in range(n):
                    A[i, k] += bi * Bm[c, k] * kT[c]
        A[i, n] = -f[i]
        r[i] = acc
        err = max(err, abs(acc))
    for k in range(n + 1):
        A[n, k] = 0.0
    A[n, j] = 1.0
    r[n] = x[j] - a
    return err / scale if scale > 0.0 else err


def push_grid(lo: float, hi: float, steps_per_decade: int = _DEFAULT.steps_per_decade,
              decades_below: int = _DEFAULT.decades_below, substeps: int = 1):
    """(grid, first): the push's displacements (m) and the index of ``lo`` in it.

    Geometric, from ``lo`` ``decades_below`` decades down to ``hi``, with
    ``substeps`` steps per backbone point and at least ``steps_per_decade``
    backbone points per decade. ``lo`` and ``hi`` are grid points, and from
    ``lo`` on every ``substeps``-th point is a backbone point, ``hi``
    included.
    """
    below = np.geomspace(lo * 10.0 ** (-decades_below), lo, decades_below * steps_per_decade * substeps + 1)[:-1]
    m = substeps * max(int(math.ceil(math.log10(hi / lo) * steps_per_decade)), 1)
    return np.concatenate((below, np.geomspace(lo, hi, m + 1))), below.size


def _hermite_work(u, T, kT):
    """int_0^u T du along the push for every contact (J), Hermite's corrected trapezoidal rule.

    ``u``, ``T``, ``kT``: (points + 1, contacts) with row 0 the origin.
    """
    du = np.diff(u, axis=0)
    inc = 0.5 * du * (T[1:] + T[:-1]) + du * du / 12.0 * (kT[:-1] - kT[1:])
    return np.concatenate((np.zeros((1, u.shape[1])), np.cumsum(inc, axis=0)))


def _gauged_stiffness(system) -> np.ndarray:
    """K (N/m), plus (M Phi_r)(M Phi_r)^T for the rigid-body modes Phi_r of a free-free structure
    (:func:`jointdyn.systems.free_modes`, M-orthonormal): the push's load M phi is M-orthogonal to them and
    the contacts cannot act on them (b^T Phi_r = 0), so the gauged equilibrium is the free structure's with
    the rigid-body part of x at zero (Phi_r^T M x = 0), the gauge harmonic balance puts on the mean."""
    K = np.array(system.K_reference, dtype=np.float64)
    MP = system.M @ free_modes(system)
    if MP.shape[1]:
        K += MP @ MP.T
    return K


def _push(system, grid, out_dof, linear, opts: QSMAOptions):
    """The compiled push: ``(reached, xs, alpha, T, kT)`` with row 0 the origin."""
    kin = contact_kinematics(system)
    Bm = np.ascontiguousarray(selection_matrix(kin, system.ndof))
    laws = [c.law for c in system.contacts]
    width = max(law.params.size for law in laws)
    Pm = np.zeros((len(laws), max(width, 1)))
    for i, law in enumerate(laws):
        Pm[i, :law.params.size] = law.params
    Nc = np.array([c.normal.n0 for c in system.contacts], dtype=np.float64)
    ssz = max(law.state_size for law in laws)
    p = grid.size
    nc = len(laws)
    xs = np.zeros((p + 1, system.ndof))
    als = np.zeros(p + 1)
    Ts = np.zeros((p + 1, nc))
    kTs = np.zeros((p + 1, nc))
    K = np.ascontiguousarray(_gauged_stiffness(system))
    f = np.ascontiguousarray(system.M @ linear.mass_normalised)
    kernel = specialize(_push_template, STEP_JVP=laws[0].step_jvp, INIT=laws[0].init)
    reached = kernel(grid, (K, f, int(out_dof)), (Bm, Pm, Nc, int(ssz)),
                     (float(opts.tol), int(opts.max_iter)), (xs, als, Ts, kTs))
    return int(reached), xs, als, Ts, kTs, Bm


def qsma(system, amplitude=None, *, mode: int = 1, output_dof: int | None = None,
         steps_per_decade: int | None = None, options: QSMAOptions | None = None) -> Backbone:
    """Backbone of a nonlinear mode by quasi-static modal analysis (module docstring).

    Parameters
    ----------
    system : System
        Structure with frictional contacts at constant normal loads; its
        forcing is ignored. Held in place, held only through its contacts,
        or free-free (the rigid-body part of the push held at zero).
    amplitude : (float, float), optional
        Range (min, max) of the output DOF's displacement at the turning
        point of the push, m (default: ``config.MODES_AMPLITUDE_Q`` times
        fy / kt of the first contact).
    mode : int
        Linear stuck mode pushed along (1-based).
    output_dof : int, optional
        DOF whose displacement is prescribed and reported (default: the
        system's response DOF).
    steps_per_decade : int, optional
        Backbone points per decade of amplitude (default ``options.steps_per_decade``, 40); the push
        takes ``options.substeps`` steps per point.
    options : QSMAOptions, optional
        The push's numbers (:class:`~jointdyn.modes.options.QSMAOptions`; None: the defaults).

    Returns
    -------
    Backbone
        ``method = "qsma"``, ``harmonics = 1``: X holds the static
        deflection as the cosine coefficients; status complete or failed
        (Newton failed at a step; the points before are kept).
    """
    from .. import _validate as V

    check_free_vibration(system, "QSMA", springs=False, held=True)
    lo, hi = amplitude_range(system, amplitude)
    out_dof = output_dof_of(system, output_dof)
    opts = qsma_options(options)
    spd = opts.steps_per_decade if steps_per_decade is None else steps_per_decade
    spd = V.positive_int("steps_per_decade", spd, 1)
    linear = linear_stuck_mode(system, mode, out_dof)
    sub = opts.substeps
    grid, first = push_grid(lo, hi, spd, opts.decades_below, substeps=sub)
    reached, xs, als, Ts, kTs, Bm = _push(system, grid, out_dof, linear, opts)
    u = xs @ Bm.T
    W = _hermite_work(u[:reached + 1], Ts[:reached + 1], kTs[:reached + 1])
    sel = slice(first + 1, reached + 1, sub)  # backbone rows in the requested range (row 0 is the origin)
    x, alpha, U, T = xs[sel], als[sel], u[sel], Ts[sel]
    E = 8.0 * W[sel] - 4.0 * U * T
    phi = linear.mass_normalised
    M, C = system.M, system.C
    q = x @ (M @ phi)
    w = np.sqrt(alpha / q)
    xCx = np.einsum("pi,ip->p", x, C @ x.T)  # C may be an operator (jointdyn.damping)
    xMx = np.einsum("pi,ij,pj->p", x, M, x)
    Dc = E.sum(axis=1) / (2.0 * np.pi * alpha * q)
    Dv = w * xCx / (2.0 * alpha * q)
    X = np.zeros((x.shape[0], 3 * system.ndof))
    X[:, system.ndof:2 * system.ndof] = x
    ok = reached == grid.size
    status = ModeStatus.COMPLETE if ok else (ModeStatus.FAILED if x.shape[0] else ModeStatus.NO_START)
    message = ("pushed to the largest amplitude" if ok else
               f"the static equilibrium did not converge at {grid[reached]:.6g} m (Newton, "
               f"{opts.max_iter} iterations)")
    return Backbone(method="qsma", status=status, message=message, system=system, linear=linear,
                    output_dof=out_dof, harmonics=1, samples=0, amplitude_m=x[:, out_dof].copy(), omega_rad_s=w,
                    xi_rad_s=2.0 * (Dc + Dv) * w, damping_ratio=Dc + Dv, damping_ratio_contacts=Dc,
                    damping_ratio_viscous=Dv, modal_amplitude=np.sqrt(xMx), X=X, contact_energy_J=E,
                    energy_viscous_J=np.pi * w * xCx, counters={"points": int(x.shape[0]),
                                                                 "push_steps": int(reached)})

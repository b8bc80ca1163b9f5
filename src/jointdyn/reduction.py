"""Craig-Bampton reduction of a linear structure onto its contact DOFs.

A model with many linear DOFs and a few contacts is integrated in time on
the coordinates q = (x_b, eta): the boundary DOFs x_b (contacts, forcing,
output) kept as they are, plus ``n_modes`` fixed-interface modes of the
interior::

    x = T q,   T = [[I, 0], [Psi, Phi]]   (rows: boundary, interior),
    Psi = -K_ii^-1 K_ib                   (static constraint modes),
    K_ii Phi = M_ii Phi diag(w_j^2)       (lowest n_modes, Phi^T M_ii Phi = I),

    M_r = T^T M T,  K_r = T^T K T,  C_r = T^T C T,  f_r = T^T f.

With every interior mode kept T is square and invertible: the reduced model
is the full one in other coordinates. The error of fewer modes is reported
by comparing the reduced model's natural frequencies and mode shapes with
the full model's (:class:`ModeError`).

Sparse M, K (an FE model's) are reduced without a dense copy of the full
matrices: one sparse factorisation of K_ii gives Psi, shift-invert Lanczos
the lowest interior modes. :func:`reduce_interface` keeps the DOFs of an
interface's node pairs (and any others asked for) and returns the reduced
matrices, forcing and pair table, a linear :class:`~jointdyn.System` for
every solver (time integration, harmonic balance, nonlinear modes).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from . import _validate as V
from .damping import dense_damping
from .kinematics import NormalSpring
from .systems import Contact, System

__all__ = ["CraigBampton", "InterfaceReduction", "ModeError", "craig_bampton", "default_boundary",
           "reduce_interface", "reduce_system"]

#: linear modes compared by the error report of a sparse Craig-Bampton
#: reduction (the lowest ones; a dense reduction compares all of its size)
REDUCTION_SPARSE_ERROR_MODES = 12


@dataclass(frozen=True)
class ModeError:
    """Linear modes of the reduced model against the full model's.

    Attributes
    ----------
    w_full_rad_s, w_reduced_rad_s : ndarray (m,)
        The m = reduced-size lowest natural frequencies of each model, rad/s.
    relative_error : ndarray (m,)
        (w_reduced - w_full) / w_full (>= 0 up to rounding: a reduction
        only stiffens); absolute, rad/s, for a rigid-body mode (w_full = 0).
    mac : ndarray (m,)
        Modal assurance criterion of the expanded reduced shape T phi_r
        against the full shape, in [0, 1] (1: same shape).
    """

    w_full_rad_s: np.ndarray
    w_reduced_rad_s: np.ndarray
    relative_error: np.ndarray
    mac: np.ndarray

    def rows(self) -> list[tuple[int, float, float, float, float]]:
        """(mode, w_full, w_reduced, relative error, MAC) per mode."""
        return [(j + 1, float(a), float(b), float(e), float(m)) for j, (a, b, e, m)
                in enumerate(zip(self.w_full_rad_s, self.w_reduced_rad_s, self.relative_error, self.mac))]  # fmt: skip

    def worst(self, modes: int) -> float:
        """Largest |relative frequency error| over the lowest ``modes`` modes."""
        return float(np.max(np.abs(self.relative_error[:modes])))


@dataclass(frozen=True)
class CraigBampton:
    """A Craig-Bampton reduction (:func:`craig_bampton`).

    Attributes
    ----------
    M, K : ndarray (r, r)
        Reduced mass (kg) and stiffness (N/m); r = len(boundary) + n_modes.
    C : ndarray (r, r) or None
        Reduced damping (N s/m), when a C was given.
    T : ndarray (n, r)
        x = T q: full DOFs from the reduced coordinates (the boundary DOFs
        first, in the given order, then the modal amplitudes).
    boundary : ndarray of int (nb,)
        Full-model indices of the boundary DOFs (reduced coordinate j < nb
        is the full DOF ``boundary[j]``).
    interior_w_rad_s : ndarray (n_modes,)
        Natural frequencies of the kept fixed-interface modes, rad/s.
    error : ModeError
        Reduced against full linear modes of the stiffness given as
        ``K_modes`` (default K).
    """

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray | None
    T: np.ndarray
    boundary: np.ndarray
    interior_w_rad_s: np.ndarray
    error: ModeError

    @property
    def size(self) -> int:
        """Number of reduced coordinates."""
        return self.T.shape[1]

    def expand(self, q) -> np.ndarray:
        """Full DOFs x = T q (q: (r,) or (samples, r))."""
        q = np.asarray(q, dtype=np.float64)
        return q @ self.T.T if q.ndim == 2 else self.T @ q


def _matrix(name: str, A, n: int | None) -> np.ndarray:
    A = V.finite_array(name, np.atleast_2d(A), 2)
    n = A.shape[0] if n is None else n
    if A.shape != (n, n):
        raise ValueError(f"{name} must be {n} x {n}, got shape {A.shape}")
    if not np.allclose(A, A.T, rtol=1e-12, atol=1e-12 * float(np.max(np.abs(A), initial=0.0))):
        raise ValueError(f"{name} must be symmetric")
    return A


def _boundary(boundary_dofs, n: int) -> np.ndarray:
    b = np.asarray(boundary_dofs, dtype=np.int64).ravel()
    if b.size == 0 or np.any(b < 0) or np.any(b >= n):
        raise ValueError(f"boundary_dofs must be a non-empty list of DOFs in [0, {n - 1}], got {b.tolist()}")
    if np.unique(b).size != b.size:
        raise ValueError(f"boundary_dofs must not repeat a DOF, got {b.tolist()}")
    return b


def _modes(K, M, count: int | None = None):
    """(w rad/s, mass-normalised shapes) of (K, M), increasing: all, or the lowest ``count``."""
    from scipy.linalg import eigh

    subset = None if count is None or count >= K.shape[0] else [0, count - 1]
    lam, phi = eigh(K, M, subset_by_index=subset)
    return np.sqrt(np.maximum(lam, 0.0)), phi


def _positive_definite(A) -> bool:
    """Whether the symmetric A is positive definite (its Cholesky factorisation exists)."""
    try:
        np.linalg.cholesky(A)
    except np.linalg.LinAlgError:
        return False
    return True


def _sparse_modes(K, M, count: int):
    """(w rad/s, mass-normalised shapes) of the lowest ``count`` modes of sparse (K, M): shift-invert
    Lanczos about a negative shift (K - sigma M is positive definite for a positive semi-definite K)."""
    from scipy.sparse.linalg import eigsh

    n = K.shape[0]
    if count >= n - 1:
        return _modes(K.toarray(), M.toarray(), count)
    scale = float(np.max(np.abs(K.diagonal())) / np.max(np.abs(M.diagonal())))
    lam, phi = eigsh(K.tocsc(), k=count, M=M.tocsc(), sigma=-1e-6 * scale, which="LM")
    order = np.argsort(lam)
    lam, phi = lam[order], phi[:, order]
    phi = phi / np.sqrt(np.einsum("ij,ij->j", phi, M @ phi))
    return np.sqrt(np.maximum(lam, 0.0)), phi


def _mode_error(M, K, T, Mr, Kr, count: int | None = None) -> ModeError:
    """Reduced (Mr, Kr) modes against the full (M, K) modes (dense or sparse), matched by order: all
    of the reduced size, or the lowest ``count``."""
    w_red, phi_red = _modes(Kr, Mr, count)
    m = min(w_red.size, phi_red.shape[1])
    w_red, phi_red = w_red[:m], phi_red[:, :m]
    w_full, phi_full = _sparse_modes(K, M, m) if _is_sparse(M) else _modes(K, M, m)
    w_full, phi_full = w_full[:m], phi_full[:, :m]
    expanded = T @ phi_red
    Me = M @ expanded
    num = np.einsum("ij,ij->j", phi_full, Me) ** 2
    den = np.einsum("ij,ij->j", phi_full, M @ phi_full) * np.einsum("ij,ij->j", expanded, Me)
    scale = np.where(w_full > 0.0, w_full, 1.0)
    return ModeError(w_full_rad_s=w_full, w_reduced_rad_s=w_red, relative_error=(w_red - w_full) / scale,
                     mac=num / den)  # fmt: skip


def _is_sparse(A) -> bool:
    import scipy.sparse as sp

    return sp.issparse(A)


def _sparse_matrix(name: str, A, n: int | None):
    """A sparse symmetric matrix (CSR, float64) with finite entries, n x n."""
    import scipy.sparse as sp

    A = sp.csr_matrix(A, dtype=np.float64)
    n = A.shape[0] if n is None else n
    if A.shape != (n, n):
        raise ValueError(f"{name} must be {n} x {n}, got shape {A.shape}")
    if not np.all(np.isfinite(A.data)):
        raise ValueError(f"{name} must have finite entries")
    top = float(np.max(np.abs(A.data), initial=0.0))
    if abs(A - A.T).max() > 1e-12 * top:
        raise ValueError(f"{name} must be symmetric")
    return A


def _sparse_transform(M, K, b: np.ndarray, n_modes: int):
    """T (dense n x r) and the kept interior frequencies of a sparse model (see :func:`craig_bampton`)."""
    from scipy.sparse.linalg import splu

    n = M.shape[0]
    interior = np.setdiff1d(np.arange(n), b)
    nb = b.size
    T = np.zeros((n, nb + n_modes))
    T[b, np.arange(nb)] = 1.0
    if not interior.size:
        return T, np.zeros(0)
    Kii = K[interior][:, interior]
    not_pd = "K: the interior block (boundary DOFs fixed) must be positive definite"
    try:  # no pivoting, symmetric ordering: K_ii = P^T L D L^T P, positive definite iff D > 0 (Sylvester)
        lu = splu(Kii.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
    except RuntimeError:  # a zero pivot
        raise ValueError(not_pd) from None
    if not (np.array_equal(lu.perm_r, lu.perm_c) and np.all(lu.U.diagonal() > 0.0)):
        raise ValueError(not_pd)
    T[np.ix_(interior, np.arange(nb))] = -lu.solve(K[interior][:, b].toarray())
    if not n_modes:
        return T, np.zeros(0)
    w, phi = _sparse_modes(Kii, M[interior][:, interior], n_modes)
    T[np.ix_(interior, nb + np.arange(n_modes))] = phi[:, :n_modes]
    return T, w


def _craig_bampton_sparse(M, K, b, n_modes, C, K_modes, error_modes) -> CraigBampton:
    M = _sparse_matrix("M", M, None)
    n = M.shape[0]
    K = _sparse_matrix("K", K, n)
    b = _boundary(b, n)
    n_modes = V.positive_int("n_modes", n_modes, 0)
    if n_modes > n - b.size:
        raise ValueError(f"n_modes must be in [0, {n - b.size}] (interior DOFs), got {n_modes}")
    T, w_int = _sparse_transform(M, K, b, n_modes)

    def project(A):
        R = T.T @ (A @ T)
        return 0.5 * (R + R.T)

    Mr, Kr = project(M), project(K)
    Cr = None if C is None else project(_sparse_matrix("C", C, n))
    Km = K if K_modes is None else _sparse_matrix("K_modes", K_modes, n)
    count = REDUCTION_SPARSE_ERROR_MODES if error_modes is None else error_modes
    error = _mode_error(M, Km, T, Mr, project(Km), min(count, T.shape[1]))
    return CraigBampton(M=Mr, K=Kr, C=Cr, T=T, boundary=b, interior_w_rad_s=w_int, error=error)


def craig_bampton(M, K, boundary_dofs, n_modes: int, *, C=None, K_modes=None,
                  error_modes: int | None = None) -> CraigBampton:  # fmt: skip
    """Craig-Bampton reduction of (M, K[, C]) onto ``boundary_dofs`` plus ``n_modes`` interior modes.

    Parameters
    ----------
    M, K : array_like (n, n)
        Mass (kg, symmetric positive definite) and stiffness (N/m,
        symmetric; its interior block must be positive definite: the
        structure is held when the boundary DOFs are fixed).
    boundary_dofs : sequence of int
        DOFs kept as coordinates (contacts, forcing, output), in this order.
    n_modes : int
        Fixed-interface modes kept, 0 .. n - len(boundary_dofs) (all: exact).
    C : array_like (n, n), optional
        Viscous damping, N s/m (projected as T^T C T).
    K_modes : array_like (n, n), optional
        Stiffness whose linear modes the error report compares (default K;
        e.g. ``System.K_reference`` with the normal springs closed).
    error_modes : int, optional
        Modes the error report compares, the lowest ones (default: all of
        the reduced size for dense matrices,
        ``REDUCTION_SPARSE_ERROR_MODES`` for sparse ones).

    Returns
    -------
    CraigBampton
        Dense reduced matrices; M, K (and C, K_modes) may be scipy sparse
        matrices (then every one given is treated as sparse).
    """
    if any(_is_sparse(A) for A in (M, K, C, K_modes)):
        return _craig_bampton_sparse(M, K, boundary_dofs, n_modes, C, K_modes, error_modes)
    M = _matrix("M", M, None)
    n = M.shape[0]
    K = _matrix("K", K, n)
    b = _boundary(boundary_dofs, n)
    interior = np.setdiff1d(np.arange(n), b)
    n_modes = V.positive_int("n_modes", n_modes, 0)
    if n_modes > interior.size:
        raise ValueError(f"n_modes must be in [0, {interior.size}] (interior DOFs), got {n_modes}")
    Kii, Mii = K[np.ix_(interior, interior)], M[np.ix_(interior, interior)]
    if interior.size and not _positive_definite(Kii):
        raise ValueError("K: the interior block (boundary DOFs fixed) must be positive definite")
    nb = b.size
    T = np.zeros((n, nb + n_modes))
    T[b, np.arange(nb)] = 1.0
    w_int = np.zeros(0)
    if interior.size:
        T[np.ix_(interior, np.arange(nb))] = -np.linalg.solve(Kii, K[np.ix_(interior, b)])
        if n_modes:
            w_int, phi = _modes(Kii, Mii, n_modes)
            T[np.ix_(interior, nb + np.arange(n_modes))] = phi[:, :n_modes]
    Mr, Kr = T.T @ M @ T, T.T @ K @ T
    Mr, Kr = 0.5 * (Mr + Mr.T), 0.5 * (Kr + Kr.T)
    Cr = None
    if C is not None:
        Cr = T.T @ _matrix("C", C, n) @ T
        Cr = 0.5 * (Cr + Cr.T)
    Km = K if K_modes is None else _matrix("K_modes", K_modes, n)
    error = _mode_error(M, Km, T, Mr, T.T @ Km @ T, error_modes)
    return CraigBampton(M=Mr, K=Kr, C=Cr, T=T, boundary=b, interior_w_rad_s=w_int, error=error)


def _dofs_of(c) -> list[int]:
    """Full DOFs a selection (a Contact or a NormalSpring) touches."""
    if c.direction is not None:
        return [int(i) for i in np.flatnonzero(c.direction)]
    return [c.dof] + ([c.dof2] if c.dof2 >= 0 else [])


def _reduced_selection(sel, cb: CraigBampton) -> dict:
    """dof/dof2 (boundary DOFs) or direction = T^T b of a selection, in reduced coordinates."""
    pos = {int(d): j for j, d in enumerate(cb.boundary)}
    if sel.direction is None and all(d in pos for d in _dofs_of(sel)):
        return dict(dof=pos[sel.dof], dof2=pos[sel.dof2] if sel.dof2 >= 0 else -1)
    full = np.zeros(cb.T.shape[0])
    if sel.direction is not None:
        full[: sel.direction.size] = sel.direction
    else:
        full[sel.dof] += 1.0
        if sel.dof2 >= 0:
            full[sel.dof2] -= 1.0
    return dict(direction=cb.T.T @ full)


def _reduced_contact(c: Contact, cb: CraigBampton) -> Contact:
    normal = c.normal
    if isinstance(normal, NormalSpring):
        normal = NormalSpring(kn=normal.kn, preload=normal.preload, **_reduced_selection(normal, cb))
    return Contact(c.law, normal=normal, **_reduced_selection(c, cb))


def _project_forcing(T, force, phase_deg) -> tuple[np.ndarray, np.ndarray]:
    """(amplitudes, phases deg) of the reduced forcing T^T f."""
    if np.any(phase_deg != 0.0):  # amplitude and phase of sum_i T_ij f_i exp(i phi_i)
        F = T.T @ (force * np.exp(1j * np.radians(phase_deg)))
        return np.abs(F), np.degrees(np.angle(F))
    return T.T @ force, np.zeros(T.shape[1])  # in-phase forcing stays in phase (signed amplitudes)


def default_boundary(system: System) -> list[int]:
    """Contact DOFs (tangential and normal), the DOFs of the interfaces' node pairs, forced DOFs and the
    response DOF, increasing."""
    dofs = {system.response_dof}
    for c in system.contacts:
        dofs.update(_dofs_of(c))
        if isinstance(c.normal, NormalSpring):
            dofs.update(_dofs_of(c.normal))
    dofs.update(_pair_dofs(system))
    dofs.update(int(i) for i in np.flatnonzero(system.force))
    return sorted(dofs)


def _pair_dofs(system: System) -> set[int]:
    """The DOFs named by the node pairs of the system's interfaces (the fixed sides, -1, left out)."""
    return {int(d) for itf in system.interfaces for d in itf.pairs.ravel() if d >= 0}


def _reduced_interfaces(system: System, cb: CraigBampton) -> tuple:
    """The system's interfaces with their pair tables in reduced coordinates (boundary DOFs, kept as they
    are); ValueError naming ``boundary_dofs`` when a pair's DOF is interior (a pair acts on its own DOFs
    only: it cannot act on a combination of modes)."""
    missing = sorted(_pair_dofs(system) - {int(d) for d in cb.boundary})
    if missing:
        raise ValueError(f"boundary_dofs must contain every DOF of the interfaces' node pairs, missing "
                         f"{missing[:10]}{' ...' if len(missing) > 10 else ''}")
    pos = np.full(system.ndof, -1, dtype=np.int64)
    pos[cb.boundary] = np.arange(cb.boundary.size)
    return tuple(dataclasses.replace(itf, pairs=np.where(itf.pairs >= 0, pos[np.maximum(itf.pairs, 0)], -1))
                 for itf in system.interfaces)


def reduce_system(system: System, n_modes: int, boundary_dofs=None) -> tuple[System, CraigBampton]:
    """Craig-Bampton reduction of a System for the time integrator.

    Parameters
    ----------
    system : System
        The full model.
    n_modes : int
        Fixed-interface modes kept (see :func:`craig_bampton`).
    boundary_dofs : sequence of int, optional
        Default :func:`default_boundary`: the contact DOFs, the DOFs of the
        interfaces' node pairs, the forced DOFs and the response DOF (which
        must be a boundary DOF, as must every DOF of a node pair).

    Returns
    -------
    (System, CraigBampton)
        The reduced system (same contacts, laws and normal loads on the
        reduced coordinates, the same interfaces with their pair tables on
        the reduced coordinates of their DOFs, forcing T^T f with its
        phases, w0 and response DOF of the full model) and the reduction,
        whose ``error`` compares the linear modes with the normal springs
        closed and the tangential contacts free (``System.K_reference``).
        A pair acts on boundary DOFs only, so the reduction is exact up to
        rounding with every interior mode kept, as for the contacts.
    """
    if not isinstance(system, System):
        raise ValueError(f"system must be a System, got {type(system).__name__}")
    b = default_boundary(system) if boundary_dofs is None else boundary_dofs
    # modal damping made dense: T^T C T of a reduced model is dense whatever C is
    cb = craig_bampton(system.M, system.K, b, n_modes, C=dense_damping(system.C), K_modes=system.K_reference)
    out = int(system.response_dof)
    if out not in cb.boundary:
        raise ValueError(f"boundary_dofs must contain the response DOF {out}")
    force, phase = _project_forcing(cb.T, system.force, system.force_phase_deg)
    interfaces = _reduced_interfaces(system, cb)
    reduced = System(M=cb.M, C=cb.C, K=cb.K, contacts=tuple(_reduced_contact(c, cb) for c in system.contacts),
                     interfaces=interfaces, force=force, force_phase_deg=phase, w0_rad_s=system.w0,
                     output_dof=int(np.flatnonzero(cb.boundary == out)[0]))  # fmt: skip
    return reduced, cb


@dataclass(frozen=True)
class InterfaceReduction:
    """A structure reduced onto an interface's node pairs (:func:`reduce_interface`).

    Attributes
    ----------
    M, K : ndarray (r, r)
        Reduced mass (kg) and stiffness (N/m).
    C : ndarray (r, r) or None
        Reduced damping (N s/m), when a C was given.
    force, force_phase_deg : ndarray (r,)
        Reduced forcing amplitudes (N) and phases (deg), T^T f.
    pairs : ndarray of int (npairs, 6)
        The pair table in reduced coordinates (-1 stays -1).
    kept : ndarray of int
        Reduced coordinates of the extra DOFs asked for (``keep``), in order.
    reduction : CraigBampton
        The transformation (``T``, ``boundary``, ``expand``) and its error report.
    """

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray | None
    force: np.ndarray
    force_phase_deg: np.ndarray
    pairs: np.ndarray
    kept: np.ndarray
    reduction: CraigBampton

    @property
    def size(self) -> int:
        """Number of reduced coordinates."""
        return self.M.shape[0]

    def system(self, *, output_dof: int | None = None, w0_rad_s: float | None = None) -> System:
        """The reduced structure as a :class:`~jointdyn.System` without contacts.

        Parameters
        ----------
        output_dof : int, optional
            Reduced coordinate reported (default: the first kept DOF, else 0).
        w0_rad_s : float, optional
            Reference frequency of gamma, rad/s (default: the System's own).
        """
        out = output_dof if output_dof is not None else (int(self.kept[0]) if self.kept.size else None)
        return System(M=self.M, C=self.C, K=self.K, force=self.force, force_phase_deg=self.force_phase_deg,
                      w0_rad_s=w0_rad_s, output_dof=out)  # fmt: skip


def _pair_table(pairs) -> np.ndarray:
    p = np.asarray(pairs)
    if p.ndim != 2 or p.shape[1] != 6 or p.shape[0] == 0 or not np.issubdtype(p.dtype, np.integer):
        raise ValueError(f"pairs must be an integer array of shape (npairs, 6), got {p.dtype} {p.shape}")
    if np.any(p < -1):
        raise ValueError(f"pairs must hold DOF indices or -1 (fixed), got {int(p.min())}")
    return p.astype(np.int64)


def reduce_interface(M, K, pairs, n_modes: int, *, C=None, force=None, force_phase_deg=None, keep=(),
                     error_modes: int | None = None) -> InterfaceReduction:  # fmt: skip
    """Craig-Bampton reduction keeping the DOFs of an interface's node pairs.

    Parameters
    ----------
    M, K : array_like or scipy sparse (n, n)
        Mass (kg) and stiffness (N/m) with the interface nodes in their pair
        frames (:meth:`jointdyn.fe.PairTable.to_local`); K with the pairs
        open (the structure held when the interface DOFs are fixed).
    pairs : array_like of int (npairs, 6)
        DOFs a_t1, a_t2, a_n, b_t1, b_t2, b_n of each pair (-1: fixed).
    n_modes : int
        Fixed-interface modes kept (see :func:`craig_bampton`).
    C : array_like (n, n), optional
        Viscous damping, N s/m.
    force, force_phase_deg : array_like (n,), optional
        Forcing amplitudes (N) and phases (deg) on the full DOFs.
    keep : sequence of int
        Further DOFs kept as coordinates (forcing, output), after the
        interface DOFs.
    error_modes : int, optional
        Modes compared by the error report (see :func:`craig_bampton`).

    Returns
    -------
    InterfaceReduction
        Coordinates: the interface DOFs in the order of the pair table
        (pair 0's a_t1, a_t2, ..., each DOF once), the kept DOFs, then the
        modal amplitudes.
    """
    p = _pair_table(pairs)
    n = M.shape[0] if hasattr(M, "shape") else len(M)
    if np.any(p >= n):
        raise ValueError(f"pairs must hold DOFs in [0, {n - 1}] or -1 (fixed), got {int(p.max())}")
    flat = p.ravel()
    flat = flat[flat >= 0]
    _, first = np.unique(flat, return_index=True)
    iface = flat[np.sort(first)]
    extra = [int(d) for d in np.asarray(keep, dtype=np.int64).ravel() if d not in set(iface.tolist())]
    boundary = np.concatenate([iface, np.asarray(extra, dtype=np.int64)])
    cb = craig_bampton(M, K, boundary, n_modes, C=C, error_modes=error_modes)
    f = np.zeros(n) if force is None else V.finite_array("force", force)
    ph = np.zeros(n) if force_phase_deg is None else V.finite_array("force_phase_deg", force_phase_deg)
    if f.shape != (n,) or ph.shape != (n,):
        raise ValueError(f"force and force_phase_deg must have {n} entries, got {f.size} and {ph.size}")
    fr, phr = _project_forcing(cb.T, f, ph)
    pos = np.full(n, -1, dtype=np.int64)
    pos[cb.boundary] = np.arange(cb.boundary.size)
    reduced_pairs = np.where(p >= 0, pos[np.maximum(p, 0)], -1)
    kept = pos[np.asarray(keep, dtype=np.int64).ravel()] if len(keep) else np.zeros(0, dtype=np.int64)
    return InterfaceReduction(M=cb.M, K=cb.K, C=cb.C, force=fr, force_phase_deg=phr, pairs=reduced_pairs,
                              kept=kept, reduction=cb)  # fmt: skip

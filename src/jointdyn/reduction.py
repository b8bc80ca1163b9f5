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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _validate as V
from .kinematics import NormalSpring
from .systems import Contact, System

__all__ = ["CraigBampton", "ModeError", "craig_bampton", "default_boundary", "reduce_system"]


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


def _mode_error(M, K, T, Mr, Kr) -> ModeError:
    """Reduced (Mr, Kr) modes against the full (M, K) modes, matched by order."""
    w_red, phi_red = _modes(Kr, Mr)
    m = w_red.size
    w_full, phi_full = _modes(K, M, m)
    w_full, phi_full = w_full[:m], phi_full[:, :m]
    expanded = T @ phi_red
    num = np.einsum("ij,ik,kj->j", phi_full, M, expanded) ** 2
    den = np.einsum("ij,ik,kj->j", phi_full, M, phi_full) * np.einsum("ij,ik,kj->j", expanded, M, expanded)
    scale = np.where(w_full > 0.0, w_full, 1.0)
    return ModeError(w_full_rad_s=w_full, w_reduced_rad_s=w_red, relative_error=(w_red - w_full) / scale,
                     mac=num / den)  # fmt: skip


def craig_bampton(M, K, boundary_dofs, n_modes: int, *, C=None, K_modes=None) -> CraigBampton:
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

    Returns
    -------
    CraigBampton
    """
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
    error = _mode_error(M, Km, T, Mr, T.T @ Km @ T)
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


def default_boundary(system: System) -> list[int]:
    """Contact DOFs (tangential and normal), forced DOFs and the response DOF, increasing."""
    dofs = {system.response_dof}
    for c in system.contacts:
        dofs.update(_dofs_of(c))
        if isinstance(c.normal, NormalSpring):
            dofs.update(_dofs_of(c.normal))
    dofs.update(int(i) for i in np.flatnonzero(system.force))
    return sorted(dofs)


def reduce_system(system: System, n_modes: int, boundary_dofs=None) -> tuple[System, CraigBampton]:
    """Craig-Bampton reduction of a System for the time integrator.

    Parameters
    ----------
    system : System
        The full model.
    n_modes : int
        Fixed-interface modes kept (see :func:`craig_bampton`).
    boundary_dofs : sequence of int, optional
        Default :func:`default_boundary`: the contact DOFs, the forced DOFs
        and the response DOF (which must be a boundary DOF).

    Returns
    -------
    (System, CraigBampton)
        The reduced system (same contacts, laws and normal loads on the
        reduced coordinates, forcing T^T f with its phases, w0 and response
        DOF of the full model) and the reduction, whose ``error`` compares
        the linear modes with the normal springs closed and the tangential
        contacts free (``System.K_reference``).
    """
    if not isinstance(system, System):
        raise ValueError(f"system must be a System, got {type(system).__name__}")
    system.require_no_interfaces("reduce_system")
    b = default_boundary(system) if boundary_dofs is None else boundary_dofs
    cb = craig_bampton(system.M, system.K, b, n_modes, C=system.C, K_modes=system.K_reference)
    out = int(system.response_dof)
    if out not in cb.boundary:
        raise ValueError(f"boundary_dofs must contain the response DOF {out}")
    if np.any(system.force_phase_deg != 0.0):  # amplitude and phase of sum_i T_ij f_i exp(i phi_i)
        F = cb.T.T @ (system.force * np.exp(1j * np.radians(system.force_phase_deg)))
        force, phase = np.abs(F), np.degrees(np.angle(F))
    else:  # in-phase forcing stays in phase (signed amplitudes)
        force, phase = cb.T.T @ system.force, np.zeros(cb.size)
    reduced = System(M=cb.M, C=cb.C, K=cb.K, contacts=tuple(_reduced_contact(c, cb) for c in system.contacts),
                     force=force, force_phase_deg=phase, w0_rad_s=system.w0,
                     output_dof=int(np.flatnonzero(cb.boundary == out)[0]))  # fmt: skip
    return reduced, cb

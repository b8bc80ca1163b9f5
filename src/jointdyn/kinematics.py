"""Contact kinematics: how the structure's motion reaches a contact and back.

This module is the one home of the contact geometry and of the normal load:
the tangential selection of each contact from the structure's degrees of
freedom, the normal load as a function of time and state, the instants
where a prescribed load crosses zero, the load tables of a step grid, and
the kernels that stand in for "no contact" in compiled loops of systems
without contacts (they are not a contact law and are registered nowhere).

Data layout
-----------
:func:`contact_kinematics` packs the contacts of a System into a frozen
:class:`ContactKinematics`; compiled code receives its ``arrays`` tuple
``(tan_idx, tan_w, normal_kind, normal_par)``:

``tan_idx``  int64 (nc, m)    DOFs entering the tangential displacement of
                              contact c; ``tan_idx[c, 0]`` is always a DOF,
                              later entries may be -1 (unused)
``tan_w``    float64 (nc, m)  their weights: u_c = sum_k tan_w[c, k] x[tan_idx[c, k]]
                              (a contact between DOFs a and b: (a, b), (1, -1);
                              against ground: (a, -1), (1, 0))
``normal_kind`` int64 (nc,)   how N_c is produced (:data:`NORMAL_HARMONIC`)
``normal_par``  float64 (nc, 3)  its parameter row; for NORMAL_HARMONIC
                              (n0 N, n1 N, delta rad): N = n0 + n1 sin(phase + delta),
                              phase = w t

The compiled helpers :func:`tangential` and :func:`apply_tangential_force`
take the selection arrays and a contact index, :func:`normal_load` the kind
of a contact's normal load, its parameter row, the phase and the state;
they are inlined into the loops that call them (arrays rather than the
tuple: an inlined helper that unpacks a tuple in a hot loop costs reference
counting on every call). A new kind of normal load (a unilateral
normal spring N = max(0, P + kn g), g the normal approach selected from the
state) is one more ``normal_kind`` code with its parameter row and one more
branch of :func:`normal_load`; tables of prescribed loads
(:func:`load_table`, :func:`midpoint_loads`) and their zero crossings
(:func:`load_events`) concern the prescribed kinds only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._cache import by_identity
from ._jit import jit

__all__ = [
    "NORMAL_HARMONIC",
    "ContactKinematics",
    "contact_kinematics",
    "selection_matrix",
    "tangential",
    "apply_tangential_force",
    "harmonic_load",
    "harmonic_load_samples",
    "normal_load_samples",
    "normal_load",
    "normal_load_at",
    "load_table",
    "midpoint_loads",
    "load_events",
    "sampled_load_grid",
    "tangential_history",
    "no_contact_step",
    "no_contact_step_jvp",
    "no_contact_init",
    "no_contact_init_jvp",
]

#: normal load prescribed as n0 + n1 sin(phase + delta), phase = w t
NORMAL_HARMONIC = 0


@dataclass(frozen=True)
class ContactKinematics:
    """Contact selection and normal-load description of a system, as arrays.

    Attributes
    ----------
    tan_idx : ndarray of int64, shape (nc, m)
        DOFs of each contact's tangential displacement (-1: unused entry).
    tan_w : ndarray of float64, shape (nc, m)
        Their weights (dimensionless).
    normal_kind : ndarray of int64, shape (nc,)
        Kind of normal load per contact (:data:`NORMAL_HARMONIC`).
    normal_par : ndarray of float64, shape (nc, 3)
        Parameter row of each normal load (n0 N, n1 N, delta rad).
    """

    tan_idx: np.ndarray
    tan_w: np.ndarray
    normal_kind: np.ndarray
    normal_par: np.ndarray

    @property
    def ncontacts(self) -> int:
        """Number of contacts."""
        return self.tan_idx.shape[0]

    @property
    def arrays(self) -> tuple:
        """``(tan_idx, tan_w, normal_kind, normal_par)``: the argument of the compiled helpers."""
        return (self.tan_idx, self.tan_w, self.normal_kind, self.normal_par)


@by_identity
def contact_kinematics(system) -> ContactKinematics:
    """Pack the contacts of ``system`` (a :class:`~jointdyn.System`), cached per object.

    Each contact gives its tangential selection from ``(dof, dof2)``
    (``u = x[dof] - x[dof2]``, or ``x[dof]`` against ground) and its
    harmonic normal load ``(n0, n1, delta)``.
    """
    cs = system.contacts
    nc = len(cs)
    idx = np.full((nc, 2), -1, dtype=np.int64)
    wts = np.zeros((nc, 2))
    for i, c in enumerate(cs):
        idx[i, 0] = c.dof
        wts[i, 0] = 1.0
        if c.dof2 >= 0:
            idx[i, 1] = c.dof2
            wts[i, 1] = -1.0
    kind = np.full(nc, NORMAL_HARMONIC, dtype=np.int64)
    par = np.array([[c.n0, c.n1, c.delta] for c in cs], dtype=np.float64).reshape(nc, 3)
    return ContactKinematics(idx, wts, kind, par)


def selection_matrix(kin: ContactKinematics, ndof: int) -> np.ndarray:
    """Dense selection rows B (nc, ndof): u_c = B[c] . x (weights of the same DOF add up)."""
    B = np.zeros((kin.ncontacts, ndof))
    for c in range(kin.ncontacts):
        for d, wt in zip(kin.tan_idx[c], kin.tan_w[c]):
            if d >= 0:
                B[c, d] += wt
    return B


# --- compiled helpers (inlined into the loops that call them) -----------------


@jit(inline="always")
def tangential(tan_idx, tan_w, c, y, off):  # pragma: no cover - compiled
    """u_c = sum_k w_k y[off + idx_k]: the tangential displacement (off = 0)
    or velocity (off = ndof, y = (x, v)) of contact c."""
    u = y[off + tan_idx[c, 0]] * tan_w[c, 0]
    for k in range(1, tan_idx.shape[1]):
        if tan_idx[c, k] >= 0:
            u += y[off + tan_idx[c, k]] * tan_w[c, k]
    return u


@jit(inline="always")
def apply_tangential_force(tan_idx, tan_w, c, T, f):  # pragma: no cover - compiled
    """Subtract the reaction B_c T of contact c's tangential force T (N) from the forces f."""
    for k in range(tan_idx.shape[1]):
        if tan_idx[c, k] >= 0:
            f[tan_idx[c, k]] -= tan_w[c, k] * T


@jit(inline="always")
def harmonic_load(n0, n1, delta, phase):  # pragma: no cover - compiled
    """N = n0 + n1 sin(phase + delta), N (``phase`` rad, scalars or arrays)."""
    return n0 + n1 * np.sin(phase + delta)


def harmonic_load_samples(n0, n1, delta, phase):
    """:func:`harmonic_load` in NumPy, for arrays of phases (rad): N = n0 + n1 sin(phase + delta), N."""
    return harmonic_load.py_func(n0, n1, delta, np.asarray(phase, dtype=np.float64))


def normal_load_samples(kin: ContactKinematics, phase) -> np.ndarray:
    """Prescribed normal loads (N) of every contact at the phases w t (rad), shape (nc, len(phase))."""
    par = kin.normal_par
    return harmonic_load_samples(par[:, 0:1], par[:, 1:2], par[:, 2:3], np.asarray(phase, dtype=np.float64)[None, :])


@jit(inline="always")
def normal_load(kind, par, c, phase, x):  # pragma: no cover - compiled
    """Normal load (N) of contact c, of kind ``kind`` with parameter row
    ``par[c]``, at forcing phase w t (rad) and structure state x (m).

    A prescribed kind ignores the state; the kinds produced by the structure
    read it here. NaN for an unknown kind (packing admits none). The row is
    indexed here rather than passed as a view (a view costs reference
    counting in the loops that call this).
    """
    N = math.nan
    if kind == NORMAL_HARMONIC:
        N = harmonic_load(par[c, 0], par[c, 1], par[c, 2], phase)
    return N


@jit
def load_table(kin, t, w):  # pragma: no cover - compiled
    """Prescribed normal loads N_c(t_j) (N) at times t (s), forcing frequency w (rad/s)."""
    kind, par = kin[2], kin[3]
    N = np.empty((t.shape[0], kind.shape[0]))
    for j in range(t.shape[0]):
        for c in range(kind.shape[0]):
            N[j, c] = normal_load(kind[c], par, c, w * t[j], t[:0])
    return N


@jit
def midpoint_loads(kin, t, w, phase0):  # pragma: no cover - compiled
    """Prescribed normal loads at the midpoints of the steps of the grid t (s), N.

    The phase of step j is ``phase0 + w (t_j + (t_(j+1) - t_j) / 2)``.
    """
    kind, par = kin[2], kin[3]
    J = t.shape[0] - 1
    N = np.empty((J, kind.shape[0]))
    for j in range(J):
        pm = phase0 + w * (t[j] + 0.5 * (t[j + 1] - t[j]))
        for c in range(kind.shape[0]):
            N[j, c] = normal_load(kind[c], par, c, pm, t[:0])
    return N


@jit
def tangential_history(kin, X):  # pragma: no cover - compiled
    """Tangential displacements u[j, c] (m) of every contact for the states X[j] (m), shape (ns, nc)."""
    tan_idx, tan_w = kin[0], kin[1]
    U = np.empty((X.shape[0], tan_idx.shape[0]))
    for j in range(X.shape[0]):
        for c in range(tan_idx.shape[0]):
            U[j, c] = tangential(tan_idx, tan_w, c, X[j], 0)
    return U


def normal_load_at(kin: ContactKinematics, c: int, w: float, t: float) -> float:
    """Prescribed normal load (N) of contact c at time t (s), forcing frequency w (rad/s)."""
    return float(_normal_load_scalar(kin.normal_kind[c], kin.normal_par, c, w * t))


@jit
def _normal_load_scalar(kind, par, c, phase):  # pragma: no cover - compiled
    return normal_load(kind, par, c, phase, par[0])


def load_events(kin: ContactKinematics, w: float, period: float):
    """Zero crossings of the prescribed normal loads in [0, period).

    Returns a list of ``(time s, contact, rising)``; ``rising`` is True at a
    re-contact (N turns positive), False at a separation. Contacts whose load
    never turns tensile (n1 <= n0) have none.
    """
    from .laws.normal import HarmonicLoad

    events = []
    for c in range(kin.ncontacts):
        if kin.normal_kind[c] != NORMAL_HARMONIC:
            continue
        n0, n1, delta = (float(v) for v in kin.normal_par[c])
        if n1 > n0:
            for te in HarmonicLoad(n0, n1, w, delta).zero_crossings(-1e-300, period):
                te = float(te) % period
                events.append((te, c, math.cos(w * te + delta) > 0.0))
    return events


def sampled_load_grid(t, F, N, recontact_alpha: float):
    """Step grid of sampled loads: the samples plus the zero crossings of N.

    F (N) and N (N) are piecewise linear between the sample times t (s);
    every instant where a normal load changes sign inside an interval is
    inserted, with the load snapped to 0 at a separation and to
    ``recontact_alpha`` times its largest magnitude at a re-contact.
    Returns (t, F, N) tables, C-contiguous.
    """
    nc = N.shape[1]
    tl, Fl, Nl = [t[0]], [F[0]], [N[0]]
    for i in range(t.size - 1):
        cross = []
        for c in range(nc):
            a, b = N[i, c], N[i + 1, c]
            if (a > 0) != (b > 0) and a != b:
                s = a / (a - b)
                if 0.0 < s < 1.0:
                    cross.append((s, c, b > 0))
        for s, c, rising in sorted(cross):
            ti = t[i] + s * (t[i + 1] - t[i])
            Fi = F[i] + s * (F[i + 1] - F[i])
            Ni = N[i] + s * (N[i + 1] - N[i])
            Ni[c] = recontact_alpha * abs(N[:, c]).max() if rising else 0.0
            tl.append(ti)
            Fl.append(Fi)
            Nl.append(Ni)
        tl.append(t[i + 1])
        Fl.append(F[i + 1])
        Nl.append(N[i + 1])
    tg = np.array(tl)
    Fg = np.ascontiguousarray(np.array(Fl).reshape(tg.size, F.shape[1]))
    Ng = np.ascontiguousarray(np.array(Nl).reshape(tg.size, nc))
    return tg, Fg, Ng


# --- kernels for systems without contacts --------------------------------------


@jit
def no_contact_step(params, s_old, s_new, x, N):  # pragma: no cover - never reached
    """Kernel bound in compiled loops of systems without contacts (no force)."""
    return 0.0, 0.0, 0


@jit
def no_contact_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):  # pragma: no cover
    """Forward-mode twin of :func:`no_contact_step` (no force, no derivative)."""
    for j in range(dT.shape[0]):
        dT[j] = 0.0
    return 0.0, 0.0, 0


@jit
def no_contact_init(params, x0, n0, s):  # pragma: no cover - never reached
    """Virgin state of :func:`no_contact_step` (empty)."""
    for r in range(s.shape[0]):
        s[r] = 0.0


@jit
def no_contact_init_jvp(params, x0, dx0, n0, dn0, s, ds):  # pragma: no cover - never reached
    """:func:`no_contact_init` with derivatives (all zero)."""
    for r in range(s.shape[0]):
        s[r] = 0.0
        for j in range(ds.shape[1]):
            ds[r, j] = 0.0

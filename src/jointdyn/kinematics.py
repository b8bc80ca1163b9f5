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
``(tan_idx, tan_w, normal_kind, normal_par)``::

    tan_idx      int64 (nc, m)     DOFs entering the tangential displacement
                                   of contact c; tan_idx[c, 0] is always a
                                   DOF, later entries may be -1 (unused)
    tan_w        float64 (nc, m)   their weights:
                                   u_c = sum_k tan_w[c, k] x[tan_idx[c, k]]
                                   (between DOFs a and b: (a, b), (1, -1);
                                   against ground: (a, -1), (1, 0))
    normal_kind  int64 (nc,)       how N_c is produced (NORMAL_HARMONIC)
    normal_par   float64 (nc, 3)   its parameter row; for NORMAL_HARMONIC
                                   (n0 N, n1 N, delta rad):
                                   N = n0 + n1 sin(phase + delta), phase = w t

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
from typing import ClassVar

import numpy as np

from . import _validate as V
from ._cache import by_identity
from ._jit import jit

__all__ = [
    "NormalLoad",
    "ConstantLoad",
    "HarmonicLoad",
    "SampledLoad",
    "NormalSpring",
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


# --- normal loads (what users write) ------------------------------------------------


class NormalLoad:
    """Base of the normal-load descriptions of a contact.

    ``autonomous`` is True for loads that do not depend on a forcing
    frequency (a constant load, a normal spring): only those have a place in
    a free vibration (nonlinear modes). ``prescribed`` is True for loads
    given as a function of time (they ignore the motion).

    Every kind has ``n0``, the static part of the load (N): the constant or
    mean load, or the preload of a spring.
    """

    autonomous: ClassVar[bool] = False
    prescribed: ClassVar[bool] = True


@dataclass(frozen=True)
class ConstantLoad(NormalLoad):
    """N(t) = n0 (N, > 0): a constant normal load."""

    n0: float
    autonomous: ClassVar[bool] = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "n0", V.positive("n0", self.n0))

    def at(self, phase):
        """Normal load (N) at forcing phases w t (rad)."""
        return np.full(np.shape(phase), self.n0)


@dataclass(frozen=True)
class HarmonicLoad(NormalLoad):
    """N(t) = n0 + n1 sin(w t + phase), prescribed at the excitation frequency w.

    Parameters
    ----------
    n0 : float
        Static part N0, N (> 0).
    n1 : float
        Amplitude N1, N (>= 0); eta = n1 / n0, the contact opens during part
        of the period when eta > 1.
    phase_deg : float
        Phase of the load relative to the forcing sin(w t), degrees.
    """

    n0: float
    n1: float = 0.0
    phase_deg: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "n0", V.positive("n0", self.n0))
        object.__setattr__(self, "n1", V.nonnegative("n1", self.n1))
        object.__setattr__(self, "phase_deg", V.finite("phase_deg", self.phase_deg))
        V.derived("n1 / n0", self.n1 / self.n0)

    @property
    def eta(self) -> float:
        """N1 / N0."""
        return self.n1 / self.n0

    @property
    def phase_rad(self) -> float:
        """The phase in radians."""
        return math.radians(self.phase_deg)

    def at(self, phase):
        """Normal load (N) at forcing phases w t (rad)."""
        return harmonic_load_samples(self.n0, self.n1, self.phase_rad, np.asarray(phase, dtype=np.float64))

    def zero_crossings(self, w: float, t0: float, t1: float) -> np.ndarray:
        """Instants in (t0, t1) (s) where N changes sign (separation / re-contact), w in rad/s."""
        if self.n1 <= self.n0 or w == 0.0:
            return np.empty(0)
        return np.array(_crossings(self.n0, self.n1, self.phase_rad, w, t0, t1))


@dataclass(frozen=True)
class SampledLoad(NormalLoad):
    """A periodic normal load sampled over one forcing period.

    Parameters
    ----------
    values : array_like
        N at the phases w t = 2 pi j / m, j = 0..m-1 (m >= 2 samples, finite,
        N); linear between samples, periodic.
    """

    values: np.ndarray

    def __post_init__(self) -> None:
        v = V.finite_array("values", self.values)
        if v.size < 2:
            raise ValueError(f"values must have at least 2 samples per period, got {v.size}")
        object.__setattr__(self, "values", v)

    @property
    def n0(self) -> float:
        """Mean of the samples, N."""
        return float(np.mean(self.values))

    def at(self, phase):
        """Normal load (N) at forcing phases w t (rad): periodic linear interpolation."""
        m = self.values.size
        grid = 2.0 * np.pi * np.arange(m + 1) / m
        ph = np.mod(np.asarray(phase, dtype=np.float64), 2.0 * np.pi)
        return np.interp(ph, grid, np.append(self.values, self.values[0]))


@dataclass(frozen=True)
class NormalSpring(NormalLoad):
    """Normal load produced by the structure: N = max(0, preload + kn g).

    g is the normal approach of the two sides (m, positive closes the
    contact): ``x[dof] - x[dof2]`` (``dof2 = -1``: against ground) or
    ``direction . x``. The contact pushes the sides apart with N and the
    preload is a static force P pressing them together, so the structure
    feels ``Bn (N - P)``: at rest g = 0 and N = P; while closed the spring
    is linear (stiffness kn), while open only the structure holds the
    normal DOFs.

    Parameters
    ----------
    kn : float
        Normal contact stiffness, N/m (> 0).
    preload : float
        Normal load at g = 0, N (> 0).
    dof, dof2 : int
        Normal DOF pair (dof2 = -1: ground).
    direction : array_like, optional
        Selection vector over the DOFs instead of ``dof``/``dof2``.
    """

    kn: float
    preload: float
    dof: int = 0
    dof2: int = -1
    direction: np.ndarray | None = None

    autonomous: ClassVar[bool] = True
    prescribed: ClassVar[bool] = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "kn", V.positive("kn", self.kn))
        object.__setattr__(self, "preload", V.positive("preload", self.preload))
        dof, dof2, direction = _selection("normal", self.dof, self.dof2, self.direction)
        object.__setattr__(self, "dof", dof)
        object.__setattr__(self, "dof2", dof2)
        object.__setattr__(self, "direction", direction)
        V.derived("preload / kn (opening displacement, m)", self.preload / self.kn)

    @property
    def n0(self) -> float:
        """The preload, N."""
        return self.preload

    def load(self, g):
        """Normal load (N) for normal approach ``g`` (m, positive closes)."""
        return np.maximum(0.0, self.preload + self.kn * np.asarray(g, dtype=np.float64))


def _selection(what: str, dof, dof2, direction):
    """Validated (dof, dof2, direction) of a tangential or normal selection."""
    if direction is not None:
        if dof not in (0, None) or dof2 not in (-1, None):
            raise ValueError(f"{what} selection: give either dof/dof2 or direction, not both")
        d = V.finite_array(f"{what} direction", direction)
        if not np.any(d != 0.0):
            raise ValueError(f"{what} direction must have a non-zero entry")
        return 0, -1, d
    dof = V.positive_int(f"{what} dof", dof, 0)
    if dof2 != -1:
        dof2 = V.positive_int(f"{what} dof2", dof2, 0)
        if dof2 == dof:
            raise ValueError(f"{what} dof2 must differ from dof ({dof}); use -1 for ground")
    return dof, dof2, None


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
    (``u = x[dof] - x[dof2]``, or ``x[dof]`` against ground) or from its
    selection vector ``direction`` (the non-zero entries), and its normal
    load (constant and harmonic loads as ``(n0, n1, delta rad)``).
    """
    cs = system.contacts
    nc = len(cs)
    sel = [_sparse_selection(c.dof, c.dof2, c.direction) for c in cs]
    width = max([len(i) for i, _ in sel], default=2)
    idx = np.full((nc, max(width, 2)), -1, dtype=np.int64)
    wts = np.zeros((nc, max(width, 2)))
    for i, (ii, ww) in enumerate(sel):
        idx[i, : len(ii)] = ii
        wts[i, : len(ww)] = ww
    kind = np.full(nc, NORMAL_HARMONIC, dtype=np.int64)
    par = np.zeros((nc, 3))
    for i, c in enumerate(cs):
        load = c.normal
        if isinstance(load, HarmonicLoad):
            par[i] = (load.n0, load.n1, load.phase_rad)
        elif isinstance(load, ConstantLoad):
            par[i] = (load.n0, 0.0, 0.0)
        else:
            raise ValueError(f"contact {i}: a normal load of type {type(load).__name__} is not supported by "
                             "this solver (constant and harmonic loads are)")
    return ContactKinematics(idx, wts, kind, par)


def _sparse_selection(dof, dof2, direction):
    """(DOF indices, weights) of a selection: (dof, dof2) as (1, -1), or the non-zero entries of direction."""
    if direction is not None:
        nz = np.flatnonzero(direction)
        return nz.astype(np.int64), direction[nz].astype(np.float64)
    if dof2 >= 0:
        return np.array([dof, dof2], dtype=np.int64), np.array([1.0, -1.0])
    return np.array([dof], dtype=np.int64), np.array([1.0])


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
    events = []
    for c in range(kin.ncontacts):
        if kin.normal_kind[c] != NORMAL_HARMONIC:
            continue
        n0, n1, delta = (float(v) for v in kin.normal_par[c])
        if n1 > n0:
            for te in _crossings(n0, n1, delta, w, -1e-300, period):
                te = float(te) % period
                events.append((te, c, math.cos(w * te + delta) > 0.0))
    return events


def _crossings(n0, n1, delta, w, t0, t1):
    """Zero crossings in (t0, t1) of n0 + n1 sin(w t + delta) (delta in rad)."""
    r = -n0 / n1
    out = []
    for b in (math.asin(r), math.pi - math.asin(r)):
        k = math.floor((w * t0 + delta - b) / (2 * math.pi))
        while True:
            t = (b + 2 * math.pi * k - delta) / w
            if t >= t1:
                break
            if t > t0:
                out.append(t)
            k += 1
    return sorted(out)


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

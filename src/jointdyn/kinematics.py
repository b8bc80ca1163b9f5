"""Contact kinematics: how the structure's motion reaches a contact and back.

This module is the one home of the contact geometry and of the normal load:
the tangential selection of each contact from the structure's degrees of
freedom, the normal load as a function of time and state, the instants
where a prescribed load crosses zero, the load tables of a step grid. It
re-exports the kernels that stand in for "no contact" in compiled loops of
systems without contacts (defined in :mod:`jointdyn.laws._dispatch`, where
they also fill the unused slots of the mixed-law dispatchers; they are not
a contact law and are registered nowhere).

Data layout
-----------
:func:`contact_kinematics` packs the contacts of a System into a frozen
:class:`ContactKinematics`; compiled code receives its ``arrays`` tuple
``(tan_idx, tan_w, normal_kind, normal_par, nrm_idx, nrm_w, normal_table)``::

    tan_idx       int64 (nc, m)     DOFs entering the tangential displacement
                                    of contact c; tan_idx[c, 0] is always a
                                    DOF, later entries may be -1 (unused)
    tan_w         float64 (nc, m)   their weights:
                                    u_c = sum_k tan_w[c, k] x[tan_idx[c, k]]
                                    (between DOFs a and b: (a, b), (1, -1);
                                    against ground: (a, -1), (1, 0))
    normal_kind   int64 (nc,)       how N_c is produced: NORMAL_HARMONIC,
                                    NORMAL_SAMPLED or NORMAL_SPRING
    normal_par    float64 (nc, 3)   its parameter row; column 0 is always the
                                    static part n0 of the load (N):
                                    NORMAL_HARMONIC (n0 N, n1 N, delta rad):
                                    N = n0 + n1 sin(phase + delta), phase = w t
                                    (a constant load has n1 = 0);
                                    NORMAL_SAMPLED (mean N, m, 0): m samples
                                    per period in normal_table[c, :m + 1];
                                    NORMAL_SPRING (preload P N, kn N/m, 0):
                                    N = max(0, P + kn g)
    nrm_idx       int64 (nc, mn)    DOFs of the normal approach g of a spring
                                    contact (all -1 for a prescribed load)
    nrm_w         float64 (nc, mn)  their weights:
                                    g_c = sum_k nrm_w[c, k] x[nrm_idx[c, k]]
    normal_table  float64 (nc, L)   samples of the sampled loads at the phases
                                    2 pi i / m, i = 0..m, the last equal to
                                    the first (periodic); zero rows otherwise

The structure feels ``Bt_c T_c`` from every contact and ``Bn_c (N_c - P_c)``
from every spring contact (:func:`apply_tangential_force`,
:func:`apply_normal_force`).

The compiled helpers :func:`tangential` (any selection: tangential or
normal rows) and :func:`apply_tangential_force` take the selection arrays
and a contact index; :func:`prescribed_load` the kind, parameter rows and
table of the loads that are functions of the phase, :func:`spring_load`
the spring rows and the state, :func:`normal_load` all of them (any kind).
They are inlined into the loops that call them (arrays rather than the
tuple: an inlined helper that unpacks a tuple in a hot loop costs reference
counting on every call). Tables of prescribed loads (:func:`load_table`,
:func:`midpoint_loads`) hold the preload for a spring contact (its load at
rest; solvers compute a spring's load from the state), and the zero
crossings (:func:`load_events`) concern the prescribed kinds only: a
spring's separation and re-contact instants depend on the motion and are
located by the solver.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from . import _validate as V
from ._cache import by_identity
from ._jit import jit
from .laws._dispatch import no_contact_init, no_contact_init_jvp, no_contact_step, no_contact_step_jvp

__all__ = [
    "NormalLoad",
    "ConstantLoad",
    "HarmonicLoad",
    "SampledLoad",
    "NormalSpring",
    "NORMAL_HARMONIC",
    "NORMAL_SAMPLED",
    "NORMAL_SPRING",
    "ContactKinematics",
    "contact_kinematics",
    "selection_matrix",
    "tangential",
    "apply_tangential_force",
    "apply_normal_force",
    "harmonic_load",
    "sampled_load",
    "prescribed_load",
    "spring_load",
    "harmonic_load_samples",
    "normal_load_samples",
    "normal_load",
    "normal_load_at",
    "normal_history",
    "load_table",
    "midpoint_loads",
    "load_events",
    "load_breakpoints",
    "has_springs",
    "sampled_load_grid",
    "tangential_history",
    "no_contact_step",
    "no_contact_step_jvp",
    "no_contact_init",
    "no_contact_init_jvp",
]

#: normal load prescribed as n0 + n1 sin(phase + delta), phase = w t
NORMAL_HARMONIC = 0
#: normal load prescribed as a periodic table over one forcing period, linear in phase
NORMAL_SAMPLED = 1
#: normal load produced by the structure: max(0, P + kn g), g = Bn . x
NORMAL_SPRING = 2


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
    """Contact selections and normal-load descriptions of a system, as arrays.

    Attributes
    ----------
    tan_idx : ndarray of int64, shape (nc, m)
        DOFs of each contact's tangential displacement (-1: unused entry).
    tan_w : ndarray of float64, shape (nc, m)
        Their weights (dimensionless).
    normal_kind : ndarray of int64, shape (nc,)
        Kind of normal load per contact (``NORMAL_*``).
    normal_par : ndarray of float64, shape (nc, 3)
        Parameter row of each normal load (module docstring; column 0: n0, N).
    nrm_idx : ndarray of int64, shape (nc, mn)
        DOFs of the normal approach of each spring contact (-1: unused).
    nrm_w : ndarray of float64, shape (nc, mn)
        Their weights (dimensionless).
    normal_table : ndarray of float64, shape (nc, L)
        Samples of the sampled loads over one period plus the first again, N.
    """

    tan_idx: np.ndarray
    tan_w: np.ndarray
    normal_kind: np.ndarray
    normal_par: np.ndarray
    nrm_idx: np.ndarray
    nrm_w: np.ndarray
    normal_table: np.ndarray

    @property
    def ncontacts(self) -> int:
        """Number of contacts."""
        return self.tan_idx.shape[0]

    @property
    def arrays(self) -> tuple:
        """``(tan_idx, tan_w, normal_kind, normal_par, nrm_idx, nrm_w, normal_table)``:
        the argument of the compiled helpers."""
        return (self.tan_idx, self.tan_w, self.normal_kind, self.normal_par, self.nrm_idx, self.nrm_w,
                self.normal_table)  # fmt: skip

    @property
    def springs(self) -> np.ndarray:
        """Indices of the spring contacts (normal load from the structure)."""
        return np.flatnonzero(self.normal_kind == NORMAL_SPRING)


def has_springs(kin: ContactKinematics) -> bool:
    """True when some contact's normal load comes from a normal spring."""
    return bool(np.any(kin.normal_kind == NORMAL_SPRING))


@by_identity
def contact_kinematics(system, with_interfaces: bool = False) -> ContactKinematics:
    """Pack the contacts of ``system`` (a :class:`~jointdyn.System`), cached per object.

    Each contact gives its tangential selection from ``(dof, dof2)``
    (``u = x[dof] - x[dof2]``, or ``x[dof]`` against ground) or from its
    selection vector ``direction`` (the non-zero entries), and its normal
    load: constant and harmonic loads as ``(n0, n1, delta rad)``, sampled
    loads as ``(mean, m, 0)`` with their table row, normal springs as
    ``(preload, kn, 0)`` with their normal selection row. A System with
    interfaces is refused (ValueError naming ``interfaces``) unless
    ``with_interfaces`` (a solver that marches the interfaces itself: time
    integration); harmonic balance and EPMC pack the scalar contacts of
    :func:`~jointdyn.hb.problem.contacts_only` here and evaluate the
    interfaces themselves; the remaining callers (QSMA, which refuses
    interfaces before, the time-domain period map) take scalar contacts only.
    """
    if getattr(system, "interfaces", ()) and not with_interfaces:
        raise ValueError(f"interfaces: this computation takes scalar contacts only (the System has "
                         f"{len(system.interfaces)} interfaces); harmonic balance, EPMC backbones, time integration "
                         "and the quasi-static loops (jointdyn.drivers.interface_loop) take interfaces")
    cs = system.contacts
    nc = len(cs)
    tan_idx, tan_w = _pack_rows([_sparse_selection(c.dof, c.dof2, c.direction) for c in cs])
    kind = np.full(nc, NORMAL_HARMONIC, dtype=np.int64)
    par = np.zeros((nc, 3))
    nsel = [(np.zeros(0, dtype=np.int64), np.zeros(0))] * nc
    ms = [load.values.size for load in (c.normal for c in cs) if isinstance(load, SampledLoad)]
    table = np.zeros((nc, max(ms, default=0) + 1))
    for i, c in enumerate(cs):
        load = c.normal
        if isinstance(load, HarmonicLoad):
            par[i] = (load.n0, load.n1, load.phase_rad)
        elif isinstance(load, ConstantLoad):
            par[i] = (load.n0, 0.0, 0.0)
        elif isinstance(load, SampledLoad):
            m = load.values.size
            kind[i] = NORMAL_SAMPLED
            par[i] = (load.n0, float(m), 0.0)
            table[i, :m] = load.values
            table[i, m] = load.values[0]
        elif isinstance(load, NormalSpring):
            kind[i] = NORMAL_SPRING
            par[i] = (load.preload, load.kn, 0.0)
            nsel[i] = _sparse_selection(load.dof, load.dof2, load.direction)
        else:
            raise ValueError(f"contact {i}: a normal load of type {type(load).__name__} is not supported "
                             "(constant, harmonic, sampled loads and normal springs are)")
    nrm_idx, nrm_w = _pack_rows(nsel)
    return ContactKinematics(tan_idx, tan_w, kind, par, nrm_idx, nrm_w, table)


def _pack_rows(sel):
    """Selection rows (idx, weights) padded with (-1, 0) to a common width (at least 2)."""
    width = max([len(i) for i, _ in sel] + [2])
    idx = np.full((len(sel), width), -1, dtype=np.int64)
    wts = np.zeros((len(sel), width))
    for i, (ii, ww) in enumerate(sel):
        idx[i, : len(ii)] = ii
        wts[i, : len(ww)] = ww
    return idx, wts


def _sparse_selection(dof, dof2, direction):
    """(DOF indices, weights) of a selection: (dof, dof2) as (1, -1), or the non-zero entries of direction."""
    if direction is not None:
        nz = np.flatnonzero(direction)
        return nz.astype(np.int64), direction[nz].astype(np.float64)
    if dof2 >= 0:
        return np.array([dof, dof2], dtype=np.int64), np.array([1.0, -1.0])
    return np.array([dof], dtype=np.int64), np.array([1.0])


def selection_matrix(kin: ContactKinematics, ndof: int, normal: bool = False) -> np.ndarray:
    """Dense selection rows B (nc, ndof): u_c = B[c] . x (weights of the same DOF add up).

    ``normal=True``: the normal rows Bn (g_c = Bn[c] . x), zero for a
    contact whose load is prescribed.
    """
    idx, wts = (kin.nrm_idx, kin.nrm_w) if normal else (kin.tan_idx, kin.tan_w)
    B = np.zeros((kin.ncontacts, ndof))
    for c in range(kin.ncontacts):
        for d, wt in zip(idx[c], wts[c]):
            if d >= 0:
                B[c, d] += wt
    return B


# --- compiled helpers (inlined into the loops that call them) -----------------


@jit(inline="always")
def tangential(tan_idx, tan_w, c, y, off):  # pragma: no cover - compiled
    """u_c = sum_k w_k y[off + idx_k]: the displacement (off = 0) or velocity
    (off = ndof, y = (x, v)) selected by row c of a selection (tangential
    rows, or the normal rows ``nrm_idx, nrm_w``: the normal approach g_c)."""
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
def apply_normal_force(nrm_idx, nrm_w, c, dN, f):  # pragma: no cover - compiled
    """Subtract the reaction Bn_c (N_c - P_c) of a spring contact (``dN = N - P``, N) from the forces f."""
    for k in range(nrm_idx.shape[1]):
        if nrm_idx[c, k] >= 0:
            f[nrm_idx[c, k]] -= nrm_w[c, k] * dN


@jit(inline="always")
def harmonic_load(n0, n1, delta, phase):  # pragma: no cover - compiled
    """N = n0 + n1 sin(phase + delta), N (``phase`` rad, scalars or arrays)."""
    return n0 + n1 * np.sin(phase + delta)


@jit(inline="always")
def sampled_load(table, c, m, phase):  # pragma: no cover - compiled
    """Periodic linear interpolation of row c of a sampled-load table (m
    samples per period, ``table[c, m] = table[c, 0]``) at phase (rad), N."""
    pos = (phase / (2.0 * math.pi)) % 1.0 * m
    i = int(pos)
    if i >= m:  # pos rounded up to m
        i = m - 1
    fr = pos - i
    return table[c, i] + fr * (table[c, i + 1] - table[c, i])


@jit(inline="always")
def prescribed_load(kind, par, table, c, phase):  # pragma: no cover - compiled
    """Normal load (N) of contact c as a function of the forcing phase w t
    (rad): harmonic or sampled; the preload for a spring contact (its load
    at rest: a spring's load comes from the state, :func:`spring_load`).
    The rows are indexed here rather than passed as views (a view costs
    reference counting in the loops that call this)."""
    if kind == NORMAL_HARMONIC:
        return harmonic_load(par[c, 0], par[c, 1], par[c, 2], phase)
    if kind == NORMAL_SAMPLED:
        return sampled_load(table, c, int(par[c, 1]), phase)
    return par[c, 0]


@jit(inline="always")
def spring_load(par, nrm_idx, nrm_w, c, x):  # pragma: no cover - compiled
    """N = max(0, P + kn g) (N) of spring contact c at displacements x (m)."""
    N = par[c, 0] + par[c, 1] * tangential(nrm_idx, nrm_w, c, x, 0)
    return N if N > 0.0 else 0.0


@jit(inline="always")
def normal_load(kind, par, table, nrm_idx, nrm_w, c, phase, x):  # pragma: no cover - compiled
    """Normal load (N) of contact c, of any kind, at forcing phase w t (rad)
    and structure state x (m; read by spring contacts only)."""
    if kind == NORMAL_SPRING:
        return spring_load(par, nrm_idx, nrm_w, c, x)
    return prescribed_load(kind, par, table, c, phase)


def harmonic_load_samples(n0, n1, delta, phase):
    """:func:`harmonic_load` in NumPy, for arrays of phases (rad): N = n0 + n1 sin(phase + delta), N."""
    return harmonic_load.py_func(n0, n1, delta, np.asarray(phase, dtype=np.float64))


def normal_load_samples(kin: ContactKinematics, phase) -> np.ndarray:
    """Prescribed normal loads (N) of every contact at the phases w t (rad), shape (nc, len(phase)).

    A spring contact's row holds its preload (its load at rest).
    """
    phase = np.asarray(phase, dtype=np.float64)
    par = kin.normal_par
    out = harmonic_load_samples(par[:, 0:1], par[:, 1:2], par[:, 2:3], phase[None, :])
    for c in np.flatnonzero(kin.normal_kind != NORMAL_HARMONIC):
        out[c] = _prescribed_samples(kin.normal_kind, par, kin.normal_table, c, phase)
    return out


@jit
def _prescribed_samples(kind, par, table, c, phase):  # pragma: no cover - compiled
    out = np.empty(phase.shape[0])
    for j in range(phase.shape[0]):
        out[j] = prescribed_load(kind[c], par, table, c, phase[j])
    return out


@jit
def load_table(kin, t, w):  # pragma: no cover - compiled
    """Prescribed normal loads N_c(t_j) (N) at times t (s), forcing frequency w (rad/s)
    (a spring contact: its preload)."""
    kind, par, table = kin[2], kin[3], kin[6]
    N = np.empty((t.shape[0], kind.shape[0]))
    for j in range(t.shape[0]):
        for c in range(kind.shape[0]):
            N[j, c] = prescribed_load(kind[c], par, table, c, w * t[j])
    return N


@jit
def midpoint_loads(kin, t, w, phase0):  # pragma: no cover - compiled
    """Prescribed normal loads at the midpoints of the steps of the grid t (s), N.

    The phase of step j is ``phase0 + w (t_j + (t_(j+1) - t_j) / 2)``.
    """
    kind, par, table = kin[2], kin[3], kin[6]
    J = t.shape[0] - 1
    N = np.empty((J, kind.shape[0]))
    for j in range(J):
        pm = phase0 + w * (t[j] + 0.5 * (t[j + 1] - t[j]))
        for c in range(kind.shape[0]):
            N[j, c] = prescribed_load(kind[c], par, table, c, pm)
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


@jit
def normal_history(kin, X, t, w):  # pragma: no cover - compiled
    """Normal loads N[j, c] (N) of every contact (any kind) for the states X[j]
    (m) at the times t[j] (s), forcing frequency w (rad/s), shape (ns, nc)."""
    kind, par, nrm_idx, nrm_w, table = kin[2], kin[3], kin[4], kin[5], kin[6]
    N = np.empty((X.shape[0], kind.shape[0]))
    for j in range(X.shape[0]):
        for c in range(kind.shape[0]):
            N[j, c] = normal_load(kind[c], par, table, nrm_idx, nrm_w, c, w * t[j], X[j])
    return N


def normal_load_at(kin: ContactKinematics, c: int, w: float, t: float) -> float:
    """Prescribed normal load (N) of contact c at time t (s), forcing frequency w (rad/s)
    (a spring contact: its preload)."""
    return float(_normal_load_scalar(kin.normal_kind[c], kin.normal_par, kin.normal_table, c, w * t))


@jit
def _normal_load_scalar(kind, par, table, c, phase):  # pragma: no cover - compiled
    return prescribed_load(kind, par, table, c, phase)


def load_events(kin: ContactKinematics, w: float, period: float):
    """Zero crossings of the prescribed normal loads in [0, period).

    Returns a list of ``(time s, contact, rising)``; ``rising`` is True at a
    re-contact (N turns positive), False at a separation. Harmonic loads
    whose load never turns tensile (n1 <= n0) have none; a sampled load
    crosses where its linear interpolation does (a sample exactly at 0
    counts as open).
    """
    events = []
    for c in range(kin.ncontacts):
        kind = kin.normal_kind[c]
        if kind == NORMAL_HARMONIC:
            n0, n1, delta = (float(v) for v in kin.normal_par[c])
            if n1 > n0:
                for te in _crossings(n0, n1, delta, w, -1e-300, period):
                    te = float(te) % period
                    events.append((te, c, math.cos(w * te + delta) > 0.0))
        elif kind == NORMAL_SAMPLED:
            m = int(kin.normal_par[c, 1])
            v = kin.normal_table[c, : m + 1]
            for i in range(m):
                a, b = float(v[i]), float(v[i + 1])
                if (a > 0.0) != (b > 0.0):
                    te = (i + a / (a - b)) / m * period
                    events.append((te % period, c, b > 0.0))
    return events


def load_breakpoints(kin: ContactKinematics, period: float) -> np.ndarray:
    """Instants in [0, period) (s) where a sampled load changes slope (its
    sample phases), sorted and unique; empty without sampled loads."""
    out = [np.arange(int(kin.normal_par[c, 1])) * (period / int(kin.normal_par[c, 1]))
           for c in range(kin.ncontacts) if kin.normal_kind[c] == NORMAL_SAMPLED]  # fmt: skip
    return np.unique(np.concatenate(out)) if out else np.zeros(0)


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

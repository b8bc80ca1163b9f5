"""The coordinates a condensed harmonic-balance problem keeps, and its static condensation onto them.

A condensed problem (:mod:`jointdyn.hb.condense`) keeps the harmonics of m
retained coordinates ``y = S x`` (S: m x n, full row rank) and eliminates
the rest of the structure exactly. Every nonlinear force acts through S:
a contact's selection row b (u_c = b . x) and, for an interface's node pair,
its three relative coordinates ``x[a_k] - x[b_k]`` (a fixed side: a unit
row). With the contact forces ``S^T gamma`` the condensed problem reads,
per harmonic, ``y = S H(W) (F - S^T gamma)``, so only ``S H S^T`` and
``S H F`` enter, both exact from the spectral expansion of the receptance.

Two choices of S (:func:`retained_coordinates`):

* the retained DOFs (unit rows of :func:`retained_dofs`: every DOF a
  contact or a pair touches, DOF 0 and the response DOFs), the form of a
  structure whose contacts act on one DOF each (to ground): there both
  choices are the same;
* relative coordinates: the distinct rows (up to sign) of the contacts'
  selections and of the pairs' relative coordinates, plus unit rows for
  DOF 0 and the response DOFs. A two-sided pair then costs three unknowns
  per harmonic instead of six (a lap joint of 120 pairs: 362 instead of
  721). Taken when those rows are fewer than the retained DOFs and linearly
  independent (else the DOFs).

The static harmonic (W = 0) needs the static Schur complement onto y,
Z0 = (S K^-1 S^T)^-1 where K is positive definite (from the expansion, in
:mod:`jointdyn.hb.condense`), and otherwise by a basis change that completes
S (:func:`static_cholesky`): pivot DOFs P with S_P invertible (QR with
column pivoting of S), x = A y + N z with A = S_P^-1 on the rows P (S A = I)
and N = [-S_P^-1 S_o; I] a basis of the null space of S (the DOFs o not
pivots), so that K restricted to null(S) is N^T K N, factored by Cholesky;
for unit rows this is the partition of K into retained and other DOFs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kinematics import contact_kinematics, selection_matrix
from ..systems import System
from .problem import contacts_only

__all__ = ["Coordinates", "retained_dofs", "retained_coordinates", "static_cholesky"]


def _key(row):
    """(key, sign) of a row (n,): its non-zero entries as a tuple, the sign making the first positive."""
    nz = np.flatnonzero(row)
    sign = 1.0 if row[nz[0]] > 0.0 else -1.0
    return tuple((int(i), float(sign * row[i])) for i in nz), sign


@dataclass(frozen=True, eq=False)
class Coordinates:
    """The m retained coordinates y = S x of a condensed problem (module docstring).

    Attributes
    ----------
    S : ndarray (m, n)
        The rows (dimensionless selections).
    dofs : ndarray (m,) of int64
        The DOF of each unit row, -1 for any other row.
    """

    S: np.ndarray
    dofs: np.ndarray
    _index: dict = field(default_factory=dict, repr=False)

    @classmethod
    def of_rows(cls, rows) -> Coordinates:
        """Coordinates of the distinct (up to sign) non-zero rows of ``rows`` (k, n), each with its first
        non-zero entry positive, in the order of their entries (the same set gives the same order)."""
        found = {}
        for row in rows:
            if np.any(row != 0.0):
                key, sign = _key(row)
                found.setdefault(key, sign * row)
        keys = sorted(found)
        index = {key: i for i, key in enumerate(keys)}
        S = np.array([found[key] for key in keys], dtype=np.float64).reshape(len(keys), -1)
        dofs = np.array([int(np.flatnonzero(r)[0]) if np.count_nonzero(r) == 1 and r[r != 0.0][0] == 1.0 else -1
                         for r in S], dtype=np.int64)
        return cls(S, dofs, index)

    @classmethod
    def of_dofs(cls, dofs, n: int) -> Coordinates:
        """The unit rows of the DOFs ``dofs`` (sorted, distinct) of a structure of n DOFs."""
        dofs = np.asarray(dofs, dtype=np.int64)
        S = np.zeros((dofs.size, n))
        S[np.arange(dofs.size), dofs] = 1.0
        return cls(S, dofs, {((int(d), 1.0),): i for i, d in enumerate(dofs)})

    @property
    def m(self) -> int:
        """Number of coordinates."""
        return self.S.shape[0]

    @property
    def unit(self) -> bool:
        """True when every coordinate is a DOF (unit rows)."""
        return bool(np.all(self.dofs >= 0))

    def express(self, B) -> np.ndarray:
        """Rows B (k, n) in the coordinates: C (k, m) with C S = B, exactly (with unit rows: B on the
        retained DOFs; otherwise each row of B a coordinate up to sign, or zero). ValueError for a row that
        is not."""
        B = np.asarray(B, dtype=np.float64)
        if self.unit:
            if np.any(np.delete(B, self.dofs, axis=1) != 0.0):
                raise ValueError("condense: a contact row acts on a DOF that is not retained")
            return B[:, self.dofs]
        out = np.zeros((B.shape[0], self.m))
        for i, row in enumerate(B):
            if np.any(row != 0.0):
                key, sign = _key(row)
                if key not in self._index:
                    raise ValueError("condense: a contact row is not among the retained coordinates")
                out[i, self._index[key]] = sign
        return out

    def position(self, a: int, b: int) -> tuple[int, int]:
        """(position of side a, position of side b) among the coordinates for the relative coordinate
        x[a] - x[b] (a or b -1: a fixed side; a position -1: none): with unit rows the positions of the
        DOFs a and b; otherwise (j, -1) when it is coordinate j, (-1, j) when it is minus coordinate j."""
        if self.unit:
            pos = {int(d): i for i, d in enumerate(self.dofs)}
            if (a >= 0 and a not in pos) or (b >= 0 and b not in pos):
                raise ValueError(f"condense: the pair's DOFs {a}, {b} are not among the retained DOFs")
            return pos.get(a, -1), pos.get(b, -1)
        if a < 0 and b < 0:
            return -1, -1
        row = np.zeros(self.S.shape[1])
        row[a] += 1.0 if a >= 0 else 0.0
        row[b] -= 1.0 if b >= 0 else 0.0
        key, sign = _key(row)
        if key not in self._index:
            raise ValueError(f"condense: the pair's coordinate x[{a}] - x[{b}] is not retained")
        return (self._index[key], -1) if sign > 0.0 else (-1, self._index[key])


def retained_dofs(system: System, response_dofs=()) -> np.ndarray:
    """Sorted DOFs kept by a condensed problem onto DOFs: contact selections (tangential
    and, for normal springs, normal), the DOFs of the interfaces' node pairs, DOF 0 and
    ``response_dofs``."""
    kin = contact_kinematics(contacts_only(system))
    B = np.vstack([selection_matrix(kin, system.ndof), selection_matrix(kin, system.ndof, normal=True)])
    keep = set(np.flatnonzero(np.any(B != 0.0, axis=0)).tolist()) | {0}
    for itf in system.interfaces:  # the six DOFs of every node pair
        keep |= set(itf.pairs[itf.pairs >= 0].tolist())
    for d in response_dofs:
        d = int(d)
        if not 0 <= d < system.ndof:
            raise ValueError(f"response_dof must be in [0, {system.ndof - 1}], got {d!r}")
        keep.add(d)
    return np.array(sorted(keep), dtype=np.int64)


def retained_coordinates(system: System, response_dofs=(), relative: bool = True) -> Coordinates:
    """The coordinates a condensed problem keeps (module docstring): relative coordinates when
    ``relative`` and they are fewer than the retained DOFs and independent, else the retained DOFs."""
    dofs = retained_dofs(system, response_dofs)
    n = system.ndof
    if not relative:
        return Coordinates.of_dofs(dofs, n)
    units = np.zeros((1 + len(response_dofs), n))
    units[0, 0] = 1.0
    units[np.arange(1, units.shape[0]), np.asarray(response_dofs, dtype=np.int64)] = 1.0
    kin = contact_kinematics(contacts_only(system))
    rows = [units, selection_matrix(kin, n), selection_matrix(kin, n, normal=True)]
    for itf in system.interfaces:
        P = np.zeros((3 * itf.pairs.shape[0], n))
        for k in range(3):
            for side, sign in ((k, 1.0), (k + 3, -1.0)):
                d = itf.pairs[:, side]
                on = np.flatnonzero(d >= 0)
                P[3 * on + k, d[on]] += sign
        rows.append(P)
    coords = Coordinates.of_rows(np.vstack(rows))
    if coords.m >= dofs.size or np.linalg.matrix_rank(coords.S) < coords.m:
        return Coordinates.of_dofs(dofs, n)
    return coords


def static_cholesky(K, coords: Coordinates):
    """(Z0, S0) of the static condensation onto ``coords`` by a Cholesky factorisation of K on null(S)
    (module docstring): Z0 (m, m) N/m, S0 a function ``rows -> S0[rows]`` (x = S0 y for a static load
    S^T lambda). ValueError naming ``condense`` when K is not positive definite on null(S) (a static load
    there would have no unique response)."""
    from scipy.linalg import LinAlgError, cho_factor, cho_solve, qr

    K = np.asarray(K, dtype=np.float64)
    n, m = K.shape[0], coords.m
    if coords.unit:
        piv, SP = coords.dofs, np.eye(m)
    else:
        piv = np.sort(qr(coords.S, mode="r", pivoting=True)[1][:m])
        SP = coords.S[:, piv]
    o = np.setdiff1d(np.arange(n), piv)
    A = np.zeros((n, m))
    A[piv] = np.linalg.inv(SP)
    S0 = A.copy()
    if o.size == 0:
        return A.T @ K @ A, S0.__getitem__
    N = np.zeros((n, o.size))
    N[o, np.arange(o.size)] = 1.0
    if not coords.unit:
        N[piv] = -A[piv] @ coords.S[:, o]
    KN = K @ N if not coords.unit else K[:, o]
    try:
        cf = cho_factor(N.T @ KN if not coords.unit else K[np.ix_(o, o)])
    except LinAlgError:
        raise ValueError("condense: K restricted to the motions that leave the retained coordinates at zero "
                         "must be positive definite (the structure must be held when the contacts are "
                         "fixed)") from None
    T0 = -cho_solve(cf, KN.T @ A)
    S0 += N @ T0
    Z0 = A.T @ (K @ S0)
    return 0.5 * (Z0 + Z0.T), S0.__getitem__

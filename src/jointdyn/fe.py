"""Interfaces from finite-element data: node pairs, their frames, the structure in those frames.

After meshing, a bolted joint's contact patch is a set of node pairs: node a
on side A and node b on side B at the same place, with the normal n of the
patch there. The interface element (docs/model.md section 10) reads one DOF
per direction of each pair::

    u_k = x[a_tk] - x[b_tk]   (k = 1, 2),    g = x[a_n] - x[b_n]

(g > 0 closes the pair), while an FE model's DOFs at a node are its global
x, y, z displacements. This module rotates the DOFs of every interface node
into its pair's frame (t1, t2, n): with R the 3 x 3 matrix whose rows are
t1, t2, n, the node's local DOFs are x' = R x, and over the whole model::

    x = Q x',   Q orthogonal (R^T on the interface nodes' DOF triplets,
                the identity elsewhere),
    M' = Q^T M Q,   K' = Q^T K Q,   C' = Q^T C Q,   f' = Q^T f.

The triplet of DOF indices is kept, only their meaning changes (first: along
t1, then t2, then n), so that the pair table holds plain DOF indices as the
element wants them. A rotation rather than a projection matrix: M', K' keep
symmetry, definiteness and natural frequencies exactly, a reduction keeps
exactly six coordinates per pair, and nodes away from the interface keep
their global DOFs (forcing and output there are unchanged; forcing or output
at an interface node are in its pair frame).

The normal n points from side A into side B: moving node a along n
(towards b) closes the pair. Both nodes of a pair take the pair's frame, so a
node in several pairs must get the same frame from each.

Sources of pairs: :func:`interface_from_triplets` (each pair's two nodes as
DOF triplets plus a normal) and :func:`interface_from_mesh` (two named node
sets of a mesh file read by meshio, matched by nearest node).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar
from pathlib import Path

import numpy as np


__all__ = ["LapJoint", "PairTable", "ReducedJoint", "interface_from_mesh", "interface_from_triplets", "lap_joint", "match_nodes",
           "pair_frames", "pair_springs", "read_node_sets"]  # fmt: skip

#: two mesh nodes are the same point (a node pair) when their distance is
#: within this fraction of the diagonal of the two node sets' bounding box
FE_MATCH_RTOL = 1e-6
#: a node in two pairs must get the same frame from both: rows t1, t2, n
#: equal to this (unit vectors)
FE_FRAME_ATOL = 1e-9
#: a given tangent is along the normal when its part normal to n is below
#: this fraction of its length
FE_TANGENT_RTOL = 1e-8


@dataclass(frozen=True)
class PairTable:
    """Node pairs of an interface in their frames (:func:`interface_from_triplets`).

    Attributes
    ----------
    pairs : ndarray of int (npairs, 6)
        Per pair the DOFs a_t1, a_t2, a_n, b_t1, b_t2, b_n of the model in
        pair frames (:meth:`to_local`); -1: side B fixed (ground).
    frames : ndarray (npairs, 3, 3)
        Per pair the rows t1, t2, n (unit vectors, global components,
        right-handed: t1 x t2 = n).
    Q : scipy.sparse.csr_matrix (ndof, ndof)
        x = Q x': global DOFs from the DOFs in pair frames (orthogonal).
    nodes : ndarray of int (npairs, 2) or None
        Mesh node indices of sides A and B (-1: ground), when the pairs
        came from a mesh (:func:`interface_from_mesh`).
    """

    pairs: np.ndarray
    frames: np.ndarray
    Q: object
    nodes: np.ndarray | None = None

    @property
    def npairs(self) -> int:
        """Number of node pairs."""
        return self.pairs.shape[0]

    @property
    def ndof(self) -> int:
        """DOFs of the whole model."""
        return self.Q.shape[0]

    @property
    def dofs(self) -> np.ndarray:
        """The interface DOFs (every DOF of a pair, ground excluded), increasing."""
        return np.unique(self.pairs[self.pairs >= 0])

    def to_local(self, A):
        """A matrix (n, n) as Q^T A Q, or a vector (n,) as Q^T f: into pair frames.

        Dense input gives dense output, sparse gives sparse (CSR).
        """
        import scipy.sparse as sp

        if sp.issparse(A):
            return (self.Q.T @ A.tocsr() @ self.Q).tocsr()
        A = np.asarray(A, dtype=np.float64)
        if A.shape == (self.ndof,):
            return self.Q.T @ A
        if A.shape != (self.ndof, self.ndof):
            raise ValueError(f"A must be ({self.ndof}, {self.ndof}) or ({self.ndof},), got shape {A.shape}")
        return np.asarray((self.Q.T @ (self.Q.T @ A).T).T)

    def to_global(self, x) -> np.ndarray:
        """Global DOFs x = Q x' from DOFs in pair frames; x' (n,) or (samples, n)."""
        x = np.asarray(x, dtype=np.float64)
        return self.Q @ x if x.ndim == 1 else np.asarray((self.Q @ x.T).T)


def pair_frames(normals, tangents=None) -> np.ndarray:
    """Orthonormal right-handed frames (t1, t2, n) from normals.

    Parameters
    ----------
    normals : array_like (npairs, 3) or (3,)
        Normal of each pair (any length > 0; normalised).
    tangents : array_like (npairs, 3) or (3,), optional
        Direction of t1 (its part normal to n is used). Default: the global
        axis with the smallest component along n (the first on a tie), so
        that n = z gives t1 = x, t2 = y.

    Returns
    -------
    ndarray (npairs, 3, 3)
        Rows t1, t2 = n x t1, n.
    """
    n = np.atleast_2d(np.asarray(normals, dtype=np.float64))
    if n.ndim != 2 or n.shape[1] != 3 or not np.all(np.isfinite(n)):
        raise ValueError(f"normals must be finite 3-vectors, shape (npairs, 3), got shape {n.shape}")
    length = np.linalg.norm(n, axis=1)
    if np.any(length == 0.0):
        raise ValueError(f"normals must not be zero (pair {int(np.flatnonzero(length == 0.0)[0])})")
    n = n / length[:, None]
    if tangents is None:
        t = np.eye(3)[np.argmin(np.abs(n), axis=1)]
    else:
        t = np.broadcast_to(np.asarray(tangents, dtype=np.float64), n.shape).copy()
    given = np.linalg.norm(t, axis=1)
    t = t - np.sum(t * n, axis=1)[:, None] * n
    tl = np.linalg.norm(t, axis=1)
    bad = ~(tl > FE_TANGENT_RTOL * given)
    if np.any(bad):
        raise ValueError(f"tangents must be finite, non-zero and not along the normal (pair {int(np.argmax(bad))})")
    t1 = t / tl[:, None]
    return np.stack([t1, np.cross(n, t1), n], axis=1)


def _triplets(name: str, dofs, npairs: int | None, ndof: int, ground: bool) -> np.ndarray:
    d = np.asarray(dofs)
    if d.ndim != 2 or d.shape[1] != 3 or (npairs is not None and d.shape[0] != npairs):
        want = f"({npairs}, 3)" if npairs is not None else "(npairs, 3)"
        raise ValueError(f"{name} must have shape {want}, got {d.shape}")
    if d.shape[0] == 0:
        raise ValueError(f"{name} must have at least one pair")
    if not np.issubdtype(d.dtype, np.integer):
        raise ValueError(f"{name} must hold integer DOF indices, got dtype {d.dtype}")
    d = d.astype(np.int64)
    fixed = np.all(d == -1, axis=1)
    bad = ~fixed & np.any((d < 0) | (d >= ndof), axis=1) if ground else np.any((d < 0) | (d >= ndof), axis=1)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        allowed = f"in [0, {ndof - 1}]" + (" (or all -1: fixed)" if ground else "")
        raise ValueError(f"{name} row {i}: DOFs must be {allowed}, got {d[i].tolist()}")
    same = (d[:, 0] == d[:, 1]) | (d[:, 1] == d[:, 2]) | (d[:, 0] == d[:, 2])
    if np.any(same & ~fixed):
        i = int(np.flatnonzero(same & ~fixed)[0])
        raise ValueError(f"{name} row {i}: the x, y, z DOFs of a node must differ, got {d[i].tolist()}")
    return d


def _rotation(trip: np.ndarray, frames: np.ndarray, pair_of: np.ndarray, ndof: int):
    """Q (sparse) from the node triplets, each with the frame of its pair; checks one frame per node."""
    import scipy.sparse as sp

    uniq, first, inv = np.unique(trip, axis=0, return_index=True, return_inverse=True)
    inv = inv.ravel()
    flat = uniq.ravel()
    values, counts = np.unique(flat, return_counts=True)
    if np.any(counts > 1):
        d = int(values[np.argmax(counts > 1)])
        rows = np.flatnonzero(np.any(trip == d, axis=1))
        pairs = sorted(set(pair_of[rows].tolist()))
        raise ValueError(f"DOF {d} belongs to two different node triplets (pairs {pairs}): a DOF is one direction "
                         "of one node")  # fmt: skip
    R = frames[pair_of]
    diff = np.max(np.abs(R - R[first][inv]), axis=(1, 2))
    if np.any(diff > FE_FRAME_ATOL):
        k = int(np.argmax(diff))
        raise ValueError(f"normals: the node with DOFs {trip[k].tolist()} gets different frames from pairs "
                         f"{int(pair_of[first[inv[k]]])} and {int(pair_of[k])}")  # fmt: skip
    Ru = R[first]  # x_global[triplet] = R^T x_local[triplet]
    rows = np.repeat(uniq, 3, axis=1).ravel()
    cols = np.tile(uniq, (1, 3)).ravel()
    vals = np.transpose(Ru, (0, 2, 1)).reshape(-1)
    rest = np.setdiff1d(np.arange(ndof), flat)
    Q = sp.csr_matrix((np.concatenate([vals, np.ones(rest.size)]),
                       (np.concatenate([rows, rest]), np.concatenate([cols, rest]))), shape=(ndof, ndof))  # fmt: skip
    return Q


def interface_from_triplets(dofs_a, dofs_b, normals, ndof: int, *, tangents=None, nodes=None) -> PairTable:
    """Pair table and pair frames from node DOF triplets and normals.

    Parameters
    ----------
    dofs_a : array_like of int (npairs, 3)
        Global x, y, z DOFs of each pair's node on side A.
    dofs_b : array_like of int (npairs, 3)
        The same for side B; a row of -1 fixes side B (contact with ground).
    normals : array_like (npairs, 3) or (3,)
        Normal of each pair (or one for all), pointing from side A into
        side B (g > 0 closes the pair when node a moves along it).
    ndof : int
        DOFs of the whole model.
    tangents : array_like, optional
        Direction of t1 (see :func:`pair_frames`).
    nodes : array_like of int (npairs, 2), optional
        Node indices to keep with the table.

    Returns
    -------
    PairTable
        Pairs as DOF indices of the model in pair frames: transform M, K, C
        and forcing with :meth:`PairTable.to_local`.
    """
    if not isinstance(ndof, (int, np.integer)) or ndof < 3:
        raise ValueError(f"ndof must be an integer >= 3, got {ndof!r}")
    a = _triplets("dofs_a", dofs_a, None, int(ndof), False)
    b = _triplets("dofs_b", dofs_b, a.shape[0], int(ndof), True)
    npairs = a.shape[0]
    n = np.asarray(normals, dtype=np.float64)
    if n.shape not in ((3,), (npairs, 3)):
        raise ValueError(f"normals must have shape (3,) or ({npairs}, 3), got {n.shape}")
    frames = pair_frames(np.broadcast_to(n, (npairs, 3)), tangents)
    has_b = ~np.all(b == -1, axis=1)
    both = np.intersect1d(a.ravel(), b[has_b].ravel())
    if both.size:
        raise ValueError(f"dofs_a and dofs_b share DOF {int(both[0])}: the two sides of a pair are different nodes")
    pair_of = np.concatenate([np.arange(npairs), np.flatnonzero(has_b)])
    Q = _rotation(np.concatenate([a, b[has_b]]), frames, pair_of, int(ndof))
    pairs = np.concatenate([a, b], axis=1)
    node_arr = None if nodes is None else np.asarray(nodes, dtype=np.int64).reshape(npairs, 2)
    return PairTable(pairs=pairs, frames=frames, Q=Q, nodes=node_arr)


def match_nodes(points, ids_a, ids_b, *, tol: float | None = None, where: str = "",
                names=("A", "B")) -> np.ndarray:  # fmt: skip
    """The node of ``ids_b`` at the place of each node of ``ids_a`` (one to one).

    Parameters
    ----------
    points : array_like (nnodes, 3)
        Node coordinates, m.
    ids_a, ids_b : array_like of int
        The two node sets (same size, no node in both).
    tol : float, optional
        Largest distance of a pair, m (default ``FE_MATCH_RTOL`` times
        the diagonal of the two sets' bounding box).
    where, names : str, (str, str)
        File and set names for the error messages.

    Returns
    -------
    ndarray of int
        ids_b matched to ids_a, in the order of ids_a.
    """
    from scipy.spatial import cKDTree

    pre = f"{where}: " if where else ""
    ia, ib = np.asarray(ids_a, dtype=np.int64), np.asarray(ids_b, dtype=np.int64)
    if ia.size != ib.size:
        raise ValueError(f"{pre}node sets {names[0]} ({ia.size} nodes) and {names[1]} ({ib.size} nodes) "
                         "must have the same number of nodes (one pair per node)")  # fmt: skip
    shared = np.intersect1d(ia, ib)
    if shared.size:
        raise ValueError(f"{pre}node sets {names[0]} and {names[1]} share node {int(shared[0])}: a pair needs "
                         "two nodes at one place (duplicate the interface nodes)")  # fmt: skip
    p = np.asarray(points, dtype=np.float64)
    pa, pb = p[ia], p[ib]
    if tol is None:
        both = np.concatenate([pa, pb])
        diag = float(np.linalg.norm(both.max(axis=0) - both.min(axis=0))) if both.size else 0.0
        tol = FE_MATCH_RTOL * (diag if diag > 0.0 else 1.0)
    dist, k = cKDTree(pb).query(pa)
    far = dist > tol
    if np.any(far):
        i = int(np.argmax(far))
        raise ValueError(f"{pre}node {int(ia[i])} of set {names[0]} has no node of set {names[1]} within {tol:.3g} m "
                         f"(nearest: node {int(ib[k[i]])} at {dist[i]:.3g} m)")  # fmt: skip
    values, counts = np.unique(k, return_counts=True)
    if np.any(counts > 1):
        j = int(values[np.argmax(counts > 1)])
        raise ValueError(f"{pre}node {int(ib[j])} of set {names[1]} is the nearest of several nodes of set "
                         f"{names[0]} (reduce tol)")  # fmt: skip
    return ib[k]


def _cell_nodes(mesh, blocks, selector) -> np.ndarray:
    """Nodes of the cells picked by ``selector(block index, block)`` (an index array or None)."""
    ids = [np.asarray(block.data)[sel].ravel() for j, block in enumerate(blocks)
           if (sel := selector(j, block)) is not None and len(sel)]  # fmt: skip
    return np.unique(np.concatenate(ids)) if ids else np.zeros(0, dtype=np.int64)


def _node_set(mesh, name: str, where: str) -> np.ndarray:
    """Nodes of a named set: a point set (Abaqus NSET), a cell set (Gmsh 4 physical group, ELSET) or a
    Gmsh 2 physical group (field_data + cell_data 'gmsh:physical')."""
    if name in mesh.point_sets:
        return np.unique(np.asarray(mesh.point_sets[name], dtype=np.int64))
    if name in mesh.cell_sets:
        sets = mesh.cell_sets[name]
        return _cell_nodes(mesh, mesh.cells, lambda j, _b: np.asarray(sets[j], dtype=np.int64))
    phys = mesh.cell_data.get("gmsh:physical")
    if name in mesh.field_data and phys is not None:
        tag = int(mesh.field_data[name][0])
        return _cell_nodes(mesh, mesh.cells, lambda j, _b: np.flatnonzero(np.asarray(phys[j]) == tag))
    known = sorted(set(mesh.point_sets) | {k for k in mesh.cell_sets if not k.startswith("gmsh:")}
                   | set(mesh.field_data))  # fmt: skip
    raise ValueError(f"{where}: no node set '{name}' (named sets in the file: {', '.join(known) or 'none'})")


def read_node_sets(path, names) -> tuple[np.ndarray, dict]:
    """Node coordinates and named node sets of a mesh file (meshio: Gmsh, Abaqus, Nastran, ...).

    Parameters
    ----------
    path : str or Path
        Mesh file; a set is an Abaqus NSET, a Gmsh physical group (version 2
        or 4) or any cell set meshio reads (its cells' nodes).
    names : sequence of str
        Sets to return.

    Returns
    -------
    (ndarray (nnodes, 3), dict)
        Coordinates (m; 2-D meshes get z = 0) and {name: node indices,
        increasing}.
    """
    import meshio

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such mesh file")
    try:
        mesh = meshio.read(path)
    except (Exception, SystemExit) as exc:  # meshio raises many kinds, and exits on an unreadable Gmsh file
        raise ValueError(f"{path}: cannot read the mesh ({type(exc).__name__}: {exc})") from None
    p = np.asarray(mesh.points, dtype=np.float64)
    points = np.zeros((p.shape[0], 3))
    points[:, : p.shape[1]] = p
    sets = {}
    for name in names:
        ids = _node_set(mesh, name, str(path))
        if ids.size == 0:
            raise ValueError(f"{path}: node set '{name}' is empty")
        sets[name] = ids
    return points, sets


def interface_from_mesh(path, set_a: str, set_b: str, normal, *, tangent=None, tol: float | None = None,
                        node_dofs=None) -> PairTable:  # fmt: skip
    """Pair table from two named node sets of a mesh file, matched node to node.

    Parameters
    ----------
    path : str or Path
        Mesh file read by meshio (see :func:`read_node_sets`).
    set_a, set_b : str
        Names of the node sets of sides A and B; every node of A is paired
        with the node of B at its place (one to one, within ``tol``).
    normal : array_like (3,) or (npairs, 3)
        Normal pointing from side A into side B: one for all pairs, or one
        per pair in the order of set A's nodes (increasing node index).
    tangent : array_like, optional
        Direction of t1 (see :func:`pair_frames`).
    tol : float, optional
        Largest distance of a pair, m (see :func:`match_nodes`).
    node_dofs : array_like of int (nnodes, 3), optional
        The model's x, y, z DOFs of each mesh node (default 3 i, 3 i + 1,
        3 i + 2 for node i: ``ndof = 3 nnodes``).

    Returns
    -------
    PairTable
        With ``nodes`` the mesh node indices of each pair.
    """
    points, sets = read_node_sets(path, [set_a, set_b])
    ids_a = sets[set_a]
    ids_b = match_nodes(points, ids_a, sets[set_b], tol=tol, where=str(path), names=(set_a, set_b))
    nn = points.shape[0]
    if node_dofs is None:
        table, ndof = 3 * np.arange(nn)[:, None] + np.arange(3), 3 * nn
    else:
        table = np.asarray(node_dofs)
        if table.shape != (nn, 3) or not np.issubdtype(table.dtype, np.integer):
            raise ValueError(f"node_dofs must be an integer array of shape ({nn}, 3) (one row per mesh node of "
                             f"{path}), got {table.dtype} {table.shape}")  # fmt: skip
        ndof = int(table.max()) + 1
    return interface_from_triplets(table[ids_a], table[ids_b], normal, ndof, tangents=tangent,
                                   nodes=np.stack([ids_a, ids_b], axis=1))  # fmt: skip


def pair_springs(pairs, kt, kn, ndof: int, *, stuck=None, closed=None):
    """Stiffness of node pairs replaced by linear springs (kt, kt, kn), sparse (ndof, ndof), N/m.

    The linear structure of an interface with every pair stuck is K + this;
    with every pair open, K alone.

    Parameters
    ----------
    pairs : array_like of int (npairs, 6)
        a_t1, a_t2, a_n, b_t1, b_t2, b_n per pair (-1: fixed).
    kt, kn : float or array_like (npairs,)
        Tangential and normal stiffness per pair, N/m.
    ndof : int
        Size of the model.
    stuck, closed : array_like of bool (npairs,), optional
        Pairs with tangential springs (default all) and with the normal
        spring (default all).
    """
    import scipy.sparse as sp

    p = np.asarray(pairs, dtype=np.int64)
    npairs = p.shape[0]
    kt = np.broadcast_to(np.asarray(kt, dtype=np.float64), (npairs,))
    kn = np.broadcast_to(np.asarray(kn, dtype=np.float64), (npairs,))
    on_t = np.ones(npairs, bool) if stuck is None else np.asarray(stuck, bool)
    on_n = np.ones(npairs, bool) if closed is None else np.asarray(closed, bool)
    rows, cols, vals = [], [], []
    for k, stiff in ((0, kt * on_t), (1, kt * on_t), (2, kn * on_n)):
        a, b = p[:, k], p[:, 3 + k]
        for i, j, sign in ((a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)):
            ok = (i >= 0) & (j >= 0)
            rows.append(i[ok])
            cols.append(j[ok])
            vals.append(sign * stiff[ok])
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(ndof, ndof))


@dataclass(frozen=True)
class ReducedJoint:
    """A bolted joint's structure reduced onto its interface, with its node pairs: what the shipped lap
    joint (:class:`LapJoint`) and a joint built from scratch (:class:`jointdyn.bolted.BoltedJoint`) share.

    Attributes
    ----------
    M, K : ndarray (r, r)
        Reduced mass (kg) and stiffness (N/m), every pair open.
    pairs : ndarray of int (npairs, 6)
        Reduced coordinates a_t1, a_t2, a_n, b_t1, b_t2, b_n of each pair.
    kt, kn, mu, preload : ndarray (npairs,)
        Tangential and normal stiffness (N/m), friction coefficient and
        normal load at rest (N) of each pair.
    area : ndarray (npairs,)
        Contact area of each pair, m^2.
    xy : ndarray (npairs, 2)
        Position of each pair in the patch, m.
    """

    #: the linear states :meth:`linear_K` takes
    STATES: ClassVar[tuple[str, ...]] = ("stuck", "slip", "open")

    M: np.ndarray
    K: np.ndarray
    pairs: np.ndarray
    kt: np.ndarray
    kn: np.ndarray
    mu: np.ndarray
    preload: np.ndarray
    area: np.ndarray
    xy: np.ndarray

    @property
    def npairs(self) -> int:
        """Number of node pairs."""
        return self.pairs.shape[0]

    def linear_K(self, state: str = "stuck") -> np.ndarray:
        """Stiffness of a linear state (one of ``STATES``), N/m: "stuck" (every pair stuck: springs kt, kt,
        kn), "slip" (every pair slipping: the normal springs kn only) or "open" (none)."""
        from . import _validate as V

        V.choice("state", state, self.STATES)
        if state == "open":
            return self.K.copy()
        kt = self.kt if state == "stuck" else 0.0
        return self.K + pair_springs(self.pairs, kt, self.kn, self.K.shape[0]).toarray()


@dataclass(frozen=True)
class LapJoint(ReducedJoint):
    """The bolted lap joint shipped with jointdyn, reduced onto its interface (:func:`lap_joint`).

    Two steel plates (100 x 25 x 5 mm each, clamped at their far ends)
    overlap over a 25 x 25 mm patch held by one bolt (12 kN); made by
    ``docs/scripts/lap_joint_model.py`` (docs/lap-joint.md). The patch is
    meshed with 264 node pairs; the static contact solve under the bolt
    leaves 120 of them loaded at rest, and those are the model's pairs (its
    interface). The other 144 are apart at rest: their nodes are interior
    DOFs of the reduction, and only their places and areas are kept
    (``open_xy``, ``open_area``, for pictures of the patch).

    Attributes
    ----------
    M, K : ndarray (r, r)
        Craig-Bampton mass (kg) and stiffness (N/m), pairs open.
    pairs : ndarray of int (npairs, 6)
        Reduced coordinates a_t1, a_t2, a_n, b_t1, b_t2, b_n of each pair
        loaded at rest (A: lower plate, B: upper; t1 = x along the beam,
        t2 = y, n = z).
    kt, kn, mu, preload : ndarray (npairs,)
        Tangential and normal stiffness (N/m), friction coefficient and
        normal load at rest (N, > 0).
    area : ndarray (npairs,)
        Contact area of each pair, m^2.
    xy : ndarray (npairs, 2)
        Position of each pair in the patch, m.
    open_xy : ndarray (nopen, 2)
        Positions of the patch's node pairs that are apart at rest (not in
        the model), m.
    open_area : ndarray (nopen,)
        Their contact areas, m^2.
    output_dof : int
        Reduced coordinate of the output (z at the top of the lower plate,
        37.5 mm from its clamp, mid-width).
    frequencies_hz : dict
        The four lowest natural frequencies (Hz) of the reduced model as the
        script computed them, with every pair stuck ("stuck") and every
        pair open ("open").
    """

    #: the linear states :meth:`linear_K` takes: every pair of the model stuck, or open
    STATES: ClassVar[tuple[str, ...]] = ("stuck", "open")

    open_xy: np.ndarray
    open_area: np.ndarray
    output_dof: int
    frequencies_hz: dict


#: the linear states of :attr:`LapJoint.frequencies_hz`, in the order stored
_LAP_STATES = ("stuck", "open")


def _unpack_upper(upper: np.ndarray) -> np.ndarray:
    n = int(round((np.sqrt(8 * upper.size + 1) - 1) / 2))
    A = np.zeros((n, n))
    A[np.triu_indices(n)] = upper
    return A + np.triu(A, 1).T


def lap_joint() -> LapJoint:
    """The shipped bolted lap joint (reduced FE model and interface table), see :class:`LapJoint`."""
    from importlib.resources import files

    with files("jointdyn").joinpath("data/lap_joint.npz").open("rb") as fh, np.load(fh) as z:
        d = {k: z[k] for k in z.files}
    freq = {s: d["frequencies_hz"][i] for i, s in enumerate(_LAP_STATES)}
    return LapJoint(M=_unpack_upper(d["M_upper"]), K=_unpack_upper(d["K_upper"]), pairs=d["pairs"], kt=d["kt"],
                    kn=d["kn"], mu=d["mu"], preload=d["preload"], area=d["area"], xy=d["xy"],
                    open_xy=d["open_xy"], open_area=d["open_area"], output_dof=int(d["output_dof"]),
                    frequencies_hz=freq)  # fmt: skip

"""A bolted lap joint built from scratch: a worked example of an FE model with an interface.

:func:`bolted_lap` meshes two steel plates that overlap over a long patch
held by one bolt (scikit-fem, 27-node hexahedra, linear elasticity), pairs
the nodes of the patch node to node (:func:`jointdyn.fe.interface_from_triplets`),
gives every pair a preload from a pressure peaked under the bolt and a
contact stiffness from its area, and reduces the plates by Craig-Bampton
onto the pairs' DOFs (:func:`jointdyn.reduction.reduce_interface`). With
the default sizes it is the scale benchmark's model (about 1200 reduced
DOFs, 200 pairs; ``benchmarks/bench_fe3d.py``); smaller meshes give the
same joint for tests and first tries.

The geometry (defaults): plate A (lower, z in [0, t]) spans x in
[0, free + overlap], plate B (upper, z in [t, 2 t]) x in [free, 2 free +
overlap]; both are ``width`` wide and clamped at their far ends, so the
two plates form a clamped-clamped beam of 105 mm whose middle 75 mm are
the joint (the default sizes, chosen so that the first bending frequency
falls by 31 % when every pair slips: 2943 Hz stuck, 2026 Hz slipping).
The bolt sits at the patch's centre; the patch's nodes inside the bolt
hole (``hole_m``) carry no pair (the hole is not meshed: its material
stays, a small extra stiffness).

The interface (one pair per node of the patch outside the hole, a on A's
top face, b on B's bottom face, normal +z from A into B, frames = the
global axes):

- area ``A_i``: the integral of the node's quadratic shape function over
  the patch face (Simpson weights of the face grid);
- preload ``P_i = F w_i A_i / sum_j(w_j A_j)`` with the pressure shape
  ``w = exp(-(r / r0)^2)`` of the distance r from the bolt's axis
  (``pressure_radius_m`` = r0): the pressure peaks at the bolt and the
  preloads sum to the bolt force F exactly;
- stiffness ``kn_i = kn_per_area A_i`` and ``kt_i = MINDLIN kn_i`` (Mindlin's
  ratio 2 (1 - nu) / (2 - nu) of two bodies of one material). The default
  ``kn_per_area`` (2e13 N/m^3, as the shipped lap joint) makes the
  patch's total normal stiffness about the plates' shear stiffness across
  the overlap (``BoltedJoint.stiffness_ratio``), so the contact is as
  compliant as the structure around it and the first bending mode's
  frequency falls by more than 30 % when every pair slips (with a long
  overlap: the slipping plates bend as two thin ones there).

Why reduced (dense) and not the full sparse model: the mesh of the default
joint has 7560 DOFs (the quadratic elements that bending needs);
Craig-Bampton onto the 200 pairs' 1200 DOFs, the output DOF and
``n_modes`` fixed-interface modes (1213 DOFs with 12 modes) keeps the
first four natural frequencies with every pair stuck to within
``BoltedJoint.reduction_error`` (6e-4; the first to 4e-5), and the
interface alone has 1200 DOFs, so the full model would be 6 times larger
for the same nonlinear unknowns; a reduced model dense on its interface is
also what users bring (every interface DOF coupled to every other).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import _validate as V
from .fe import ReducedJoint, interface_from_triplets, match_nodes, pair_springs

__all__ = ["BoltedJoint", "bolted_lap", "MINDLIN", "clamped_pair", "hex_elastic", "simpson_weights"]

#: steel: Young's modulus (Pa), Poisson's ratio, density (kg/m^3)
STEEL = (210e9, 0.3, 7850.0)
#: kt / kn of two elastic bodies of one material (Mindlin), nu = 0.3
MINDLIN = 2.0 * (1.0 - STEEL[1]) / (2.0 - STEEL[1])


@dataclass(frozen=True)
class BoltedJoint(ReducedJoint):
    """The bolted lap joint of :func:`bolted_lap`, reduced onto its interface.

    Attributes
    ----------
    M, K : ndarray (r, r)
        Craig-Bampton mass (kg) and stiffness (N/m), every pair open.
    pairs : ndarray of int (npairs, 6)
        Reduced coordinates a_t1, a_t2, a_n, b_t1, b_t2, b_n (A: lower plate,
        B: upper; t1 = x along the beam, t2 = y, n = z).
    kt, kn, mu, preload, area : ndarray (npairs,)
        Tangential and normal stiffness (N/m), friction coefficient, normal
        load at rest (N) and contact area (m^2) of each pair.
    xy : ndarray (npairs, 2)
        Position of each pair in the patch, m.
    bolt_xy : ndarray (2,)
        Position of the bolt's axis, m.
    bolt_force_n : float
        The bolt's clamping force, N (the sum of the preloads).
    output_dof : int
        Reduced coordinate of the output: z on top of plate B above the
        bolt.
    full_dofs : int
        DOFs of the full (meshed) model.
    reduction_error : float
        Largest relative error of the reduced model's first natural
        frequencies (every pair stuck) against the full model's, or NaN
        when not checked (``check=False``).
    stiffness_ratio : float
        sum(kn) over the plates' shear stiffness across the overlap
        (G x overlap area / thickness).
    """

    bolt_xy: np.ndarray
    bolt_force_n: float
    output_dof: int
    full_dofs: int
    reduction_error: float
    stiffness_ratio: float
    frequencies_hz: dict = field(default_factory=dict)

    def natural_frequencies_hz(self, state: str = "stuck", count: int = 4) -> np.ndarray:
        """The ``count`` lowest natural frequencies (Hz) of a linear state (:meth:`linear_K`)."""
        from scipy.linalg import eigh

        lam = eigh(self.linear_K(state), self.M, eigvals_only=True, subset_by_index=[0, count - 1])
        return np.sqrt(np.maximum(lam, 0.0)) / (2.0 * np.pi)

    def system(self, force_n: float, zeta: float, *, damping_form: str = "array"):
        """The joint as a :class:`~jointdyn.systems.System`: modal damping ``zeta`` of every mode of the
        stuck structure (:func:`jointdyn.systems.modal_damping`, ``damping_form`` "array" or "operator"),
        one :class:`~jointdyn.interfaces.Interface` of the pairs and a force of amplitude ``force_n`` (N) at
        the output DOF, which is also the system's output."""
        from .interfaces import Interface
        from .systems import System, modal_damping

        itf = Interface(kt=self.kt, kn=self.kn, mu=self.mu, preload=self.preload, pairs=self.pairs)
        force = np.zeros(self.M.shape[0])
        force[self.output_dof] = V.finite("force_n", force_n)
        C = modal_damping(self.M, self.linear_K("stuck"), zeta, form=damping_form)
        return System(M=self.M, C=C, K=self.K, interfaces=(itf,), force=force, output_dof=self.output_dof)


def hex_elastic(xs, ys, zs, E: float, nu: float, rho: float):
    """(M, K sparse, DOF locations (n, 3), x, y, z DOFs per node (nodes, 3)) of a linear-elastic block on the
    tensor grid ``xs`` x ``ys`` x ``zs`` (m; element ends and midpoints come from scikit-fem's 27-node
    hexahedra), Young's modulus ``E`` (Pa), Poisson's ratio ``nu``, density ``rho`` (kg/m^3)."""
    try:
        from skfem import Basis, BilinearForm, ElementHex2, ElementVector, MeshHex, asm
        from skfem.helpers import dot
        from skfem.models.elasticity import lame_parameters, linear_elasticity
    except ImportError:
        raise ImportError("jointdyn.bolted meshes with scikit-fem: pip install 'jointdyn[fe]'") from None

    mesh = MeshHex.init_tensor(np.asarray(xs, float), np.asarray(ys, float), np.asarray(zs, float))
    basis = Basis(mesh, ElementVector(ElementHex2()), intorder=4)
    K = asm(linear_elasticity(*lame_parameters(E, nu)), basis)

    @BilinearForm
    def mass(u, v, w):
        return rho * dot(u, v)

    M = asm(mass, basis)
    nodes = np.stack(basis.split_indices(), axis=1).astype(np.int64)
    return M.tocsr(), K.tocsr(), basis.doflocs.T, nodes


def _plate(lower: bool, g: dict):
    """(M, K sparse, DOF locations (n, 3), x, y, z DOFs per node) of one plate (:func:`hex_elastic`)."""
    free = np.linspace(0.0, g["free"], g["elements"][1] + 1)
    over = np.linspace(g["free"], g["free"] + g["overlap"], g["elements"][0] + 1)
    xs = np.concatenate([free, over[1:]]) if lower else np.concatenate([over, over[-1] + free[1:]])
    zs = np.linspace(0.0, g["thick"], g["elements"][3] + 1) + (0.0 if lower else g["thick"])
    return hex_elastic(xs, np.linspace(0.0, g["width"], g["elements"][2] + 1), zs, *STEEL)


def clamped_pair(lower, upper, x_far: float):
    """Two plates (each ``(M, K, DOF locations, x/y/z DOFs per node)``, :func:`hex_elastic`) side by side,
    plate A (``lower``) clamped at x = 0 and plate B (``upper``) at x = ``x_far`` (m): M, K on the free
    DOFs, node locations, x/y/z free-DOF indices per node and each node's side (0 A, 1 B), clamped nodes
    left out."""
    import scipy.sparse as sp

    parts = [lower, upper]
    offset = parts[0][0].shape[0]
    M = sp.block_diag([parts[0][0], parts[1][0]], format="csr")
    K = sp.block_diag([parts[0][1], parts[1][1]], format="csr")
    locs = np.concatenate([parts[0][2], parts[1][2]])
    nodes = np.concatenate([parts[0][3], parts[1][3] + offset])
    side = np.concatenate([np.zeros(len(parts[0][3]), int), np.ones(len(parts[1][3]), int)])
    x = locs[nodes[:, 0], 0]
    clamped = ((side == 0) & np.isclose(x, 0.0)) | ((side == 1) & np.isclose(x, x_far))
    free = np.setdiff1d(np.arange(M.shape[0]), nodes[clamped].ravel())
    index = np.full(M.shape[0], -1)
    index[free] = np.arange(free.size)
    keep = ~clamped
    return M[free][:, free].tocsr(), K[free][:, free].tocsr(), locs[nodes[keep, 0]], index[nodes[keep]], side[keep]


def _assemble(g: dict):
    """Both plates clamped at their far ends (:func:`clamped_pair`)."""
    return clamped_pair(_plate(True, g), _plate(False, g), 2 * g["free"] + g["overlap"])


def simpson_weights(xs: np.ndarray) -> np.ndarray:
    """Integrals (m) of the 1-D quadratic shape functions of the nodes ``xs`` (element ends and midpoints)."""
    w = np.zeros(xs.size)
    for e in range(0, xs.size - 2, 2):
        w[e : e + 3] += (xs[e + 2] - xs[e]) * np.array([1.0, 4.0, 1.0]) / 6.0
    return w


def _patch(points, triplets, side, g: dict):
    """Pair table, nodal areas (m^2) and places (m) of the patch's nodes outside the hole."""
    x0 = g["free"]
    r = np.hypot(points[:, 0] - g["bolt"][0], points[:, 1] - g["bolt"][1])
    tol = 1e-9 * g["overlap"]
    inside = (points[:, 0] > x0 - tol) & (points[:, 0] < x0 + g["overlap"] + tol) & (r > g["hole"])
    face = np.isclose(points[:, 2], g["thick"])
    a = np.flatnonzero(inside & face & (side == 0))
    b = match_nodes(points, a, np.flatnonzero(inside & face & (side == 1)), names=("A top", "B bottom"))
    table = interface_from_triplets(triplets[a], triplets[b], [0.0, 0.0, 1.0], int(triplets.max()) + 1)
    xg = np.linspace(x0, x0 + g["overlap"], 2 * g["elements"][0] + 1)
    yg = np.linspace(0.0, g["width"], 2 * g["elements"][2] + 1)
    ix = np.rint((points[a, 0] - x0) / (xg[1] - xg[0])).astype(int)
    iy = np.rint(points[a, 1] / (yg[1] - yg[0])).astype(int)
    return table, simpson_weights(xg)[ix] * simpson_weights(yg)[iy], points[a, :2]


def _geometry(length_m, width_m, thick_m, overlap_m, hole_m, elements) -> dict:
    free = V.positive("length_m", length_m) - V.positive("overlap_m", overlap_m)
    if free <= 0.0:
        raise ValueError(f"overlap_m must be < length_m ({length_m!r}), got {overlap_m!r}")
    el = tuple(int(e) for e in elements)
    if len(el) != 4 or any(e < 1 for e in el) or any(e != v for e, v in zip(el, elements)):
        raise ValueError(f"elements must be 4 integers >= 1 (overlap, free part, width, thickness), got {elements!r}")
    width = V.positive("width_m", width_m)
    hole = V.positive("hole_m", hole_m)
    if hole >= 0.5 * min(width, overlap_m):
        raise ValueError(f"hole_m must be < half the smaller of width_m and overlap_m, got {hole_m!r}")
    return {"free": free, "overlap": float(overlap_m), "width": width, "thick": V.positive("thick_m", thick_m),
            "hole": hole, "elements": el, "bolt": (free + 0.5 * float(overlap_m), 0.5 * width)}


def bolted_lap(*, length_m: float = 0.09, width_m: float = 0.025, thick_m: float = 0.005, overlap_m: float = 0.075,
               hole_m: float = 0.009, elements=(12, 2, 4, 2), bolt_force_n: float = 20e3,
               pressure_radius_m: float = 0.02, kn_per_area: float = 2e13, mu: float = 0.3, n_modes: int = 12,
               check: bool = True) -> BoltedJoint:  # fmt: skip
    """Mesh, pair, preload and reduce the bolted lap joint (see the module's docstring).

    Parameters
    ----------
    length_m, width_m, thick_m : float
        Length, width and thickness of each plate, m (> 0).
    overlap_m : float
        Length of the overlap (the contact patch), m (0 < overlap_m < length_m).
    hole_m : float
        Radius of the bolt hole (no pair within it), m (> 0, less than half the
        patch's width and length).
    elements : (int, int, int, int)
        27-node hexahedra along the overlap, along each free part, across the
        width and through each plate's thickness (>= 1). The patch has
        (2 e0 + 1) (2 e2 + 1) nodes, less those in the hole: the default
        (12, 2, 4, 2) gives 25 x 9 - 25 = 200 pairs.
    bolt_force_n : float
        The bolt's clamping force, N (> 0): the sum of the preloads.
    pressure_radius_m : float
        r0 of the pressure shape exp(-(r / r0)^2) around the bolt's axis, m
        (> 0).
    kn_per_area : float
        Normal contact stiffness per unit area, N/m^3 (> 0).
    mu : float
        Friction coefficient of every pair (>= 0).
    n_modes : int
        Fixed-interface modes kept by the reduction (>= 1).
    check : bool
        Compare the reduced model's first four natural frequencies (every
        pair stuck) with the full model's (``reduction_error``; a sparse
        eigensolve of the full model).

    Returns
    -------
    BoltedJoint
        The reduced model and its interface; ``frequencies_hz`` holds the
        first four natural frequencies (Hz) of the reduced model for each
        state of :meth:`BoltedJoint.linear_K` and, with ``check``, the full
        model's with every pair stuck ("stuck_full").
    """
    from .reduction import reduce_interface

    g = _geometry(length_m, width_m, thick_m, overlap_m, hole_m, elements)
    force = V.positive("bolt_force_n", bolt_force_n)
    r0 = V.positive("pressure_radius_m", pressure_radius_m)
    kpa = V.positive("kn_per_area", kn_per_area)
    mu = V.nonnegative("mu", mu)
    n_modes = V.positive_int("n_modes", n_modes)
    M, K, points, triplets, side = _assemble(g)
    table, area, xy = _patch(points, triplets, side, g)
    M, K = table.to_local(M), table.to_local(K)
    w = np.exp(-((np.hypot(xy[:, 0] - g["bolt"][0], xy[:, 1] - g["bolt"][1]) / r0) ** 2)) * area
    preload = force * w / w.sum()
    kn = kpa * area
    kt = MINDLIN * kn
    top = (side == 1) & np.isclose(points[:, 2], 2 * g["thick"])
    out = int(triplets[np.flatnonzero(top)[np.argmin(np.hypot(*(points[top, :2] - g["bolt"]).T))], 2])
    red = reduce_interface(M, K, table.pairs, int(n_modes), keep=[out])
    G = STEEL[0] / (2.0 * (1.0 + STEEL[1]))
    joint = BoltedJoint(M=red.M, K=red.K, pairs=red.pairs, kt=kt, kn=kn, mu=np.full(kn.size, mu), preload=preload,
                        area=area, xy=xy, bolt_xy=np.asarray(g["bolt"]), bolt_force_n=force,
                        output_dof=int(red.kept[0]), full_dofs=int(M.shape[0]), reduction_error=float("nan"),
                        stiffness_ratio=float(kn.sum() / (G * g["overlap"] * g["width"] / g["thick"])))  # fmt: skip
    freq = {s: joint.natural_frequencies_hz(s) for s in BoltedJoint.STATES}
    err = float("nan")
    if check:
        freq["stuck_full"] = _sparse_frequencies(M, K + pair_springs(table.pairs, kt, kn, M.shape[0]), 4)
        err = float(np.max(np.abs(freq["stuck"] - freq["stuck_full"]) / freq["stuck_full"]))
    object.__setattr__(joint, "frequencies_hz", freq)
    object.__setattr__(joint, "reduction_error", err)
    return joint


def _sparse_frequencies(M, K, count: int) -> np.ndarray:
    """Lowest natural frequencies (Hz) of a sparse model (shift-invert Lanczos)."""
    from scipy.sparse.linalg import eigsh

    lam = eigsh(K.tocsc(), k=count, M=M.tocsc(), sigma=-1.0, which="LM", return_eigenvectors=False)
    return np.sqrt(np.sort(lam)) / (2.0 * np.pi)

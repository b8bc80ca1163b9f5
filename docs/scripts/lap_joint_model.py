"""The bolted lap joint shipped with jointdyn: FE model, preload, reduction.

Two steel plates, each 100 x 25 x 5 mm, overlap over 25 mm (a 25 x 25 mm
patch) and are clamped at their far ends (a clamped-clamped beam of 175 mm
with the joint in the middle). One M8 bolt through the middle of the patch
clamps them with a preload of 12 kN. The script

1. meshes each plate with 27-node hexahedra (scikit-fem; quadratic, so that
   bending is not locked; 8 x 8 elements over the patch) and assembles M
   and K (18360 free DOFs);
2. pairs the nodes of the patch node to node (lower plate A, upper plate B,
   normal +z from A into B): every node of the 17 x 17 face grid except the
   25 inside the bolt hole's radius, i.e. 264 pairs; the hole itself is not
   meshed (its material stays: a small extra stiffness);
3. states the interface stiffness per pair from its area A_i (the integral
   of its node's shape function over the patch face):
   kn_i = KN_PER_AREA A_i and kt_i = MINDLIN kn_i with Mindlin's ratio
   2 (1 - nu) / (2 - nu) for two bodies of one material;
4. distributes the preload over the patch by a static contact solve: the
   bolt head and the nut press (uniform pressure on their bearing annulus,
   as nodal forces over the nodal areas) on the top of B and the bottom of
   A, the closed pairs are stuck (springs kt_i, kt_i, kn_i), and an active
   set removes the pairs that would pull (an open pair carries nothing);
   the preload of pair i is its normal force P_i (their sum is the bolt
   force up to what the clamps carry; pairs that open get P_i = 0: 144 of
   the 264). The bolt's own axial stiffness is left out: it acts as a
   constant force;
5. reduces the model by Craig-Bampton onto the DOFs of the pairs loaded at
   rest (120 pairs, 720 DOFs: t1, t2, n of both nodes of each pair, which
   here are x, y, z: the frames are the global axes), the output DOF (z at
   the top of plate A, 37.5 mm from its clamp, mid-width) and N_MODES
   fixed-interface modes: 733 DOFs. The open pairs' nodes are interior
   DOFs: they are apart at rest, and the interface element has no initial
   gap (given to it, they would touch at zero load and clap in every
   cycle), so the model's interface is the loaded pairs;
6. reports the linear natural frequencies of the full model with every pair
   stuck (springs kt, kt, kn), of the reduced and the full model with the
   loaded pairs stuck and the others open, and with every pair open, and
   writes the reduced model to src/jointdyn/data/lap_joint.npz
   (``--write``): the loaded pairs' table, stiffnesses, friction
   coefficients, preloads, areas and places, and the open pairs' places and
   areas (``open_xy``, ``open_area``).

Run: ``python docs/scripts/lap_joint_model.py [--write] [--figure
docs/img/lap-joint-preload.png]`` (needs the ``fe`` extra: scikit-fem).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh, spsolve

from jointdyn.bolted import clamped_pair, hex_elastic, simpson_weights
from jointdyn.fe import interface_from_triplets, match_nodes, pair_springs
from jointdyn.reduction import reduce_interface

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "src" / "jointdyn" / "data" / "lap_joint.npz"

#: steel
E, NU, RHO = 210e9, 0.3, 7850.0
#: plate length, width, thickness and overlap, m
LENGTH, WIDTH, THICK, OVERLAP = 0.100, 0.025, 0.005, 0.025
#: quadratic elements: along the free part, along the overlap, across the width, through the thickness
ELEMENTS = dict(free=10, overlap=8, width=8, thick=2)
#: bolt: preload (N), radius of the hole (no pairs inside) and outer radius of the head's bearing annulus, m
BOLT = dict(force=12e3, hole=0.0045, head=0.0065)
#: normal contact stiffness per unit area, N/m^3 (a chosen value: kn of a pair is this times its area)
KN_PER_AREA = 2e13
#: kt / kn of two elastic bodies of one material (Mindlin): 2 (1 - nu) / (2 - nu)
MINDLIN = 2.0 * (1.0 - NU) / (2.0 - NU)
#: friction coefficient stored with the model
MU = 0.3
#: fixed-interface modes kept
N_MODES = 12
#: output DOF: z at the top of plate A, this far from its clamp, mid-width, m
OUTPUT_X = 0.0375


def _grid(a: float, b: float, elements: int) -> np.ndarray:
    return np.linspace(a, b, elements + 1)


def plate(lower: bool):
    """(M, K sparse, DOF locations (n, 3), x, y, z DOFs per node (nodes, 3)) of one plate.

    Lower plate A: x in [0, LENGTH], z in [0, THICK], overlap at its right end; upper plate B: shifted by
    LENGTH - OVERLAP in x and THICK in z, overlap at its left end.
    """
    free = _grid(0.0, LENGTH - OVERLAP, ELEMENTS["free"])
    over = _grid(LENGTH - OVERLAP, LENGTH, ELEMENTS["overlap"])
    xs = np.concatenate([free, over[1:]])
    if not lower:
        xs = (LENGTH - OVERLAP) + np.concatenate([over - over[0], OVERLAP + free[1:]])
    zs = _grid(0.0, THICK, ELEMENTS["thick"]) + (0.0 if lower else THICK)
    M, K, locs, nodes = hex_elastic(xs, _grid(0.0, WIDTH, ELEMENTS["width"]), zs, E, NU, RHO)
    assert np.allclose(locs[nodes[:, 0]], locs[nodes[:, 2]])  # one location per triplet
    return M, K, locs, nodes


def assemble():
    """Both plates, clamped: M, K (free DOFs), node locations and triplets (free DOF indices), sides."""
    return clamped_pair(plate(True), plate(False), 2 * LENGTH - OVERLAP)


def patch(points, triplets, side):
    """The pair table: nodes of A's top face and B's bottom face in the overlap, outside the hole."""
    cx, cy = LENGTH - 0.5 * OVERLAP, 0.5 * WIDTH
    r = np.hypot(points[:, 0] - cx, points[:, 1] - cy)
    inside = (points[:, 0] > LENGTH - OVERLAP - 1e-9) & (points[:, 0] < LENGTH + 1e-9) & (r > BOLT["hole"] - 1e-9)
    face = np.isclose(points[:, 2], THICK)
    a = np.flatnonzero(inside & face & (side == 0))
    b = match_nodes(points, a, np.flatnonzero(inside & face & (side == 1)), names=("A top", "B bottom"))
    table = interface_from_triplets(triplets[a], triplets[b], [0.0, 0.0, 1.0], int(triplets.max()) + 1)
    over = _grid(LENGTH - OVERLAP, LENGTH, 2 * ELEMENTS["overlap"])
    wy = simpson_weights(_grid(0.0, WIDTH, 2 * ELEMENTS["width"]))
    wx = simpson_weights(over)
    ix = np.rint((points[a, 0] - over[0]) / (over[1] - over[0])).astype(int)
    iy = np.rint(points[a, 1] / (WIDTH / (2 * ELEMENTS["width"]))).astype(int)
    return table, wx[ix] * wy[iy], points[a, :2]


def bolt_loads(points, triplets, side, ndof):
    """Nodal forces of the head (down on B's top) and the nut (up on A's bottom): uniform pressure on the
    bearing annulus hole < r <= head, by nodal areas (Simpson weights on the patch grid)."""
    cx, cy = LENGTH - 0.5 * OVERLAP, 0.5 * WIDTH
    hx, hy = OVERLAP / (2 * ELEMENTS["overlap"]), WIDTH / (2 * ELEMENTS["width"])
    r = np.hypot(points[:, 0] - cx, points[:, 1] - cy)
    ring = (r > BOLT["hole"] - 1e-9) & (r <= BOLT["head"] + 1e-9)
    wx = simpson_weights(_grid(0.0, OVERLAP, 2 * ELEMENTS["overlap"]))
    wy = simpson_weights(_grid(0.0, WIDTH, 2 * ELEMENTS["width"]))
    f = np.zeros(ndof)
    for s, z, sign in ((1, 2 * THICK, -1.0), (0, 0.0, 1.0)):
        sel = np.flatnonzero(ring & (side == s) & np.isclose(points[:, 2], z))
        ix = np.rint((points[sel, 0] - (LENGTH - OVERLAP)) / hx).astype(int)
        iy = np.rint(points[sel, 1] / hy).astype(int)
        area = wx[ix] * wy[iy]
        f[triplets[sel, 2]] += sign * BOLT["force"] * area / area.sum()
    return f


def interface_springs(pairs, kt, kn, active, ndof):
    """Stiffness of the pairs as springs: kt, kt, kn on the active (closed, stuck) ones, none on the others."""
    closed = np.asarray(active) > 0.0
    return pair_springs(pairs, kt, kn, ndof, stuck=closed, closed=closed)


def preload(K, pairs, kt, kn, f, max_iter: int = 50):
    """Static contact solve: normal force per pair (>= 0) and the iterations of the active set."""
    active = np.ones(pairs.shape[0])
    for it in range(1, max_iter + 1):
        x = spsolve((K + interface_springs(pairs, kt, kn, active, K.shape[0])).tocsc(), f)
        g = x[pairs[:, 2]] - x[pairs[:, 5]]  # closes when positive
        new = (g > 0.0).astype(float)
        if np.array_equal(new, active):
            return kn * g * active, it
        active = new
    raise RuntimeError(f"the active set did not settle in {max_iter} iterations")


def frequencies(M, K, count=4):
    """Lowest natural frequencies, Hz (sparse: shift-invert Lanczos; dense: LAPACK)."""
    if sp.issparse(K):
        lam = eigsh(K.tocsc(), k=count, M=M.tocsc(), sigma=-1.0, which="LM", return_eigenvectors=False)
    else:
        from scipy.linalg import eigh

        lam = eigh(K, M, eigvals_only=True, subset_by_index=[0, count - 1])
    return np.sqrt(np.sort(lam)) / (2.0 * np.pi)


def _states(pairs, kt, kn, P, n):
    return {"every pair stuck": interface_springs(pairs, kt, kn, np.ones(len(kn)), n),
            "loaded pairs stuck": pair_springs(pairs, kt, kn, n, stuck=P > 0, closed=P > 0),
            "open": sp.csr_matrix((n, n))}  # fmt: skip


def build():
    """The whole model; returns (arrays to save, report)."""
    t0 = time.perf_counter()
    M, K, points, triplets, side = assemble()
    table, area, xy = patch(points, triplets, side)
    M, K = table.to_local(M), table.to_local(K)  # the pair frames (here the global axes)
    kn = KN_PER_AREA * area
    kt = MINDLIN * kn
    P, iterations = preload(K, table.pairs, kt, kn, table.to_local(bolt_loads(points, triplets, side, M.shape[0])))
    on = P > 0.0  # the interface: the pairs loaded at rest; the others' nodes are interior DOFs
    out = int(triplets[np.argmin(np.hypot(points[:, 0] - OUTPUT_X, points[:, 1] - 0.5 * WIDTH)
                                 + 10.0 * np.abs(points[:, 2] - THICK) + 10.0 * side), 2])  # fmt: skip
    red = reduce_interface(M, K, table.pairs[on], N_MODES, keep=[out])
    report = dict(full_dof=int(M.shape[0]), reduced_dof=red.size, pairs=int(table.npairs),
                  fixed_interface_modes=N_MODES, preload_n=float(P.sum()), pairs_preloaded=int(np.sum(on)),
                  active_set_iterations=iterations, frequencies_hz={})  # fmt: skip
    for name, Kc in _states(table.pairs, kt, kn, P, M.shape[0]).items():
        report["frequencies_hz"][name] = dict(full=frequencies(M, K + Kc).tolist())
        if name != "every pair stuck":  # the reduced model has the loaded pairs' DOFs only
            Kr = red.K + red.reduction.T.T @ (Kc @ red.reduction.T)
            report["frequencies_hz"][name]["reduced"] = frequencies(red.M, Kr).tolist()
    report["seconds"] = round(time.perf_counter() - t0, 1)
    data = dict(M=red.M, K=red.K, pairs=red.pairs, kt=kt[on], kn=kn[on], mu=np.full(int(on.sum()), MU), preload=P[on],
                area=area[on], xy=xy[on], open_area=area[~on], open_xy=xy[~on], output_dof=np.int64(red.kept[0]),
                frames=table.frames[on],
                frequencies_hz=np.array([report["frequencies_hz"][s]["reduced"] for s in
                                         ("loaded pairs stuck", "open")]))  # fmt: skip
    return data, report


def save(data: dict, path: Path) -> None:
    """Compressed npz; M and K as their upper triangles (``M_upper``, ``K_upper``, row-major)."""
    n = data["M"].shape[0]
    iu = np.triu_indices(n)
    arrays = {k: v for k, v in data.items() if k not in ("M", "K")}
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, M_upper=data["M"][iu], K_upper=data["K"][iu], **arrays)


def preload_figure(data: dict, path: Path) -> None:
    """The pairs over the patch, coloured by their preload (pressure P_i / A_i, MPa)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xy = 1e3 * np.concatenate([data["xy"], data["open_xy"]])
    p = np.concatenate([data["preload"] / data["area"], np.zeros(len(data["open_xy"]))]) / 1e6
    fig, ax = plt.subplots(figsize=(5.2, 4.2))
    opened = p == 0.0
    sc = ax.scatter(xy[~opened, 0], xy[~opened, 1], c=p[~opened], s=30, cmap="viridis", edgecolors="k",
                    linewidths=0.4, vmin=0.0)  # fmt: skip
    ax.scatter(xy[opened, 0], xy[opened, 1], s=30, facecolors="white", edgecolors="k", linewidths=0.4,
               label="open at rest (not in the reduced model's interface)")  # fmt: skip
    cx, cy = 1e3 * (LENGTH - 0.5 * OVERLAP), 1e3 * 0.5 * WIDTH
    for r, style in ((BOLT["hole"], "-"), (BOLT["head"], "--")):
        ax.add_patch(plt.Circle((cx, cy), 1e3 * r, fill=False, ls=style, color="0.3"))
    fig.colorbar(sc, ax=ax, label="contact pressure at rest, MPa")
    ax.set(xlabel="x, mm (along the beam)", ylabel="y, mm", aspect="equal")
    ax.set_title(f"{len(p)} pairs, {np.sum(~opened)} loaded at rest, bolt {BOLT['force'] / 1e3:.0f} kN: "
                 "static contact solve", fontsize=9)  # fmt: skip
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), frameon=False)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help=f"write {OUT.relative_to(ROOT)}")
    parser.add_argument("--figure", type=Path, help="draw the preload over the patch into this PNG")
    args = parser.parse_args(argv)
    data, report = build()
    print(json.dumps(report, indent=1))
    if args.figure:
        preload_figure(data, args.figure)
    if args.write:
        save(data, OUT)
        print(f"wrote {OUT.relative_to(ROOT)} ({OUT.stat().st_size / 1e6:.2f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Interfaces from FE data (jointdyn.fe, issue 23 point 3).

Oracles: the pair frames are orthonormal and right-handed; the rotation into
pair frames is orthogonal (same natural frequencies) and turns the projections
t_k . (x_A - x_B), n . (x_A - x_B) into differences of single DOFs; node sets
of small meshes written by meshio (Abaqus NSETs, Gmsh 2 and 4 physical
groups) are paired with the nodes at the same place.
"""

import meshio
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from jointdyn.fe import interface_from_mesh, interface_from_triplets, match_nodes, pair_frames, read_node_sets


def _spd(n, rng):
    A = rng.normal(size=(n, n))
    return A @ A.T + n * np.eye(n)


@pytest.mark.parametrize("normals", [np.array([0.0, 0.0, 2.0]), np.array([[1.0, -2.0, 0.5], [0.0, 1.0, 0.0]]),
                                     np.array([[1.0, 1.0, 1.0], [-1.0, 0.0, 0.0]])])  # fmt: skip
def test_frames_are_orthonormal_right_handed_and_keep_the_normal(normals):
    F = pair_frames(np.atleast_2d(normals))
    for R in F:
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)
        np.testing.assert_allclose(np.cross(R[0], R[1]), R[2], atol=1e-14)
    n = np.atleast_2d(normals)
    np.testing.assert_allclose(F[:, 2], n / np.linalg.norm(n, axis=1)[:, None], atol=1e-15)


_coord = st.floats(-1e3, 1e3, allow_nan=False).filter(lambda v: v == 0.0 or abs(v) > 1e-6)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(_coord, _coord, _coord).filter(lambda v: max(map(abs, v)) > 1e-3), min_size=1,
                max_size=5))  # fmt: skip
def test_frames_of_any_normals(normals):
    n = np.array(normals)
    F = pair_frames(n)
    np.testing.assert_allclose(F @ np.transpose(F, (0, 2, 1)), np.broadcast_to(np.eye(3), F.shape), atol=1e-13)
    np.testing.assert_allclose(np.linalg.det(F), 1.0, atol=1e-13)
    np.testing.assert_allclose(F[:, 2], n / np.linalg.norm(n, axis=1)[:, None], atol=1e-15)


def test_normal_z_gives_x_y_and_a_tangent_is_honoured():
    np.testing.assert_array_equal(pair_frames([0.0, 0.0, 1.0])[0], np.eye(3))
    F = pair_frames([0.0, 0.0, 1.0], tangents=[1.0, 1.0, 5.0])[0]
    np.testing.assert_allclose(F[0], [2**-0.5, 2**-0.5, 0.0], atol=1e-15)
    with pytest.raises(ValueError, match="tangents"):
        pair_frames([0.0, 0.0, 1.0], tangents=[0.0, 0.0, 3.0])
    with pytest.raises(ValueError, match="normals must not be zero"):
        pair_frames([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])


def _model(rng):
    """Five nodes, 15 DOFs (node i: 3i .. 3i+2); pairs (0, 1) and (2, 3) with tilted normals, node 4 against
    ground."""
    n = 15
    node = lambda i: [3 * i, 3 * i + 1, 3 * i + 2]  # noqa: E731
    dofs_a = np.array([node(0), node(2), node(4)])
    dofs_b = np.array([node(1), node(3), [-1, -1, -1]])
    normals = np.array([[0.3, -0.2, 1.0], [1.0, 0.4, 0.1], [0.0, 1.0, 1.0]])
    return n, dofs_a, dofs_b, normals, _spd(n, rng), _spd(n, rng)


def test_rotation_turns_projections_into_dof_differences():
    rng = np.random.default_rng(4)
    n, dofs_a, dofs_b, normals, M, K = _model(rng)
    table = interface_from_triplets(dofs_a, dofs_b, normals, n)
    np.testing.assert_array_equal(table.pairs, np.concatenate([dofs_a, dofs_b], axis=1))
    x = rng.normal(size=n)
    xl = table.to_local(x)
    np.testing.assert_allclose(table.to_global(xl), x, atol=1e-14)
    for i, (a, b) in enumerate(zip(dofs_a, dofs_b)):
        rel = x[a] - (x[b] if b[0] >= 0 else 0.0)
        p = table.pairs[i]
        local = xl[p[:3]] - (xl[p[3:]] if p[3] >= 0 else 0.0)
        np.testing.assert_allclose(local, table.frames[i] @ rel, atol=1e-14)
    # the structure in pair frames: same energies, same natural frequencies
    Ml, Kl = table.to_local(M), table.to_local(K)
    np.testing.assert_allclose(xl @ Kl @ xl, x @ K @ x, rtol=1e-13)
    from scipy.linalg import eigh

    np.testing.assert_allclose(eigh(Kl, Ml, eigvals_only=True), eigh(K, M, eigvals_only=True), rtol=1e-12)
    np.testing.assert_array_equal(table.dofs, np.arange(15))


def test_sparse_matrices_stay_sparse():
    import scipy.sparse as sp

    rng = np.random.default_rng(5)
    n, dofs_a, dofs_b, normals, _, K = _model(rng)
    table = interface_from_triplets(dofs_a, dofs_b, normals, n)
    Ks = table.to_local(sp.csr_matrix(K))
    assert sp.issparse(Ks)
    np.testing.assert_allclose(Ks.toarray(), table.to_local(K), atol=1e-12)


@pytest.mark.parametrize("change, match", [
    (lambda a, b, nrm: (a[:, :2], b, nrm), r"dofs_a must have shape \(npairs, 3\)"),
    (lambda a, b, nrm: (a + 100, b, nrm), r"dofs_a row 0: DOFs must be in \[0, 14\]"),
    (lambda a, b, nrm: (a, np.where(b == 3, -1, b), nrm), r"dofs_b row 0: DOFs must be in \[0, 14\] \(or all -1"),
    (lambda a, b, nrm: (np.array([[0, 0, 1], *a[1:]]), b, nrm), "x, y, z DOFs of a node must differ"),
    (lambda a, b, nrm: (a, np.array([a[0], *b[1:]]), nrm), "share DOF 0"),
    (lambda a, b, nrm: (a, np.array([b[0], a[0] + [15, 15, 15], [-1] * 3]), nrm), r"DOFs must be in"),
    (lambda a, b, nrm: (a, np.array([b[0], b[0], [-1] * 3]), nrm), "gets different frames from pairs 0 and 1"),
    (lambda a, b, nrm: (a, np.array([b[0], [3, 4, 9], [-1] * 3]), nrm), "DOF 3 belongs to two different node"),
    (lambda a, b, nrm: (a, b, nrm[:2]), r"normals must have shape \(3,\) or \(3, 3\)"),
])  # fmt: skip
def test_bad_triplets_name_the_parameter(change, match):
    n, dofs_a, dofs_b, normals, _, _ = _model(np.random.default_rng(0))
    a, b, nrm = change(dofs_a, dofs_b, normals)
    with pytest.raises(ValueError, match=match):
        interface_from_triplets(a, b, nrm, n)


def test_a_node_in_two_pairs_with_one_frame_is_accepted():
    table = interface_from_triplets([[0, 1, 2], [3, 4, 5]], [[6, 7, 8], [6, 7, 8]], [0.0, 1.0, 0.0], 9)
    assert table.npairs == 2
    np.testing.assert_allclose((table.Q.T @ table.Q).toarray(), np.eye(9), atol=1e-15)


# --- mesh files -----------------------------------------------------------------------------------------


def _patch(rng, gap=0.0):
    """Two 4 x 3 node grids at the same place (side B numbered in a shuffled order, optionally lifted by gap),
    quads on each, plus one node that is in no set."""
    xs, ys = np.meshgrid(np.linspace(0.0, 0.03, 4), np.linspace(0.0, 0.02, 3), indexing="ij")
    grid = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, 0.005)], axis=1)
    perm = rng.permutation(grid.shape[0])
    points = np.concatenate([grid, grid[perm] + [0.0, 0.0, gap], [[1.0, 1.0, 1.0]]])
    quads = np.array([[i * 3 + j, (i + 1) * 3 + j, (i + 1) * 3 + j + 1, i * 3 + j + 1]
                      for i in range(3) for j in range(2)])  # fmt: skip
    where_b = np.argsort(perm) + grid.shape[0]  # node of side B at grid point k
    return points, quads, where_b[quads], grid.shape[0]


def _expected_b(points, n):
    """For each node of side A (0 .. n-1) the node of side B at its place."""
    d = np.linalg.norm(points[:n, None, :] - points[None, n : 2 * n, :], axis=2)
    return n + np.argmin(d, axis=1)


def _write(tmp_path, fmt, points, qa, qb, n):
    if fmt == "inp":
        mesh = meshio.Mesh(points, [("quad", qa), ("quad", qb)],
                           point_sets={"TOP": np.arange(n), "BOTTOM": np.arange(n, 2 * n)})  # fmt: skip
        path = tmp_path / "patch.inp"
        mesh.write(path)
        return path
    phys = [np.full(len(qa), 1), np.full(len(qb), 2)]
    kw = dict(cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
              field_data={"TOP": np.array([1, 2]), "BOTTOM": np.array([2, 2])})  # fmt: skip
    if fmt == "gmsh":  # version 4.1 needs the entity of every node
        tags = np.array([[2, 1]] * n + [[2, 2]] * n + [[0, 3]])
        kw["point_data"] = {"gmsh:dim_tags": tags}
    mesh = meshio.Mesh(points, [("quad", qa), ("quad", qb)], **kw)
    path = tmp_path / f"patch-{fmt}.msh"
    mesh.write(path, file_format=fmt, binary=False)
    return path


@pytest.mark.parametrize("fmt", ["inp", "gmsh22", "gmsh"])
def test_named_sets_are_paired_node_to_node(tmp_path, fmt):
    rng = np.random.default_rng(11)
    points, qa, qb, n = _patch(rng)
    path = _write(tmp_path, fmt, points, qa, qb, n)
    read, sets = read_node_sets(path, ["TOP", "BOTTOM"])  # Gmsh 4 renumbers the nodes by entity
    assert read.shape == points.shape and sets["TOP"].size == sets["BOTTOM"].size == n
    key = lambda p: sorted(map(tuple, np.round(p, 12)))  # noqa: E731
    assert key(read[sets["TOP"]]) == key(points[:n]) and key(read[sets["BOTTOM"]]) == key(points[n : 2 * n])
    table = interface_from_mesh(path, "TOP", "BOTTOM", [0.0, 0.0, -1.0])
    assert table.npairs == n
    np.testing.assert_array_equal(table.nodes[:, 0], sets["TOP"])
    np.testing.assert_array_equal(read[table.nodes[:, 0]], read[table.nodes[:, 1]])
    assert np.intersect1d(table.nodes[:, 1], sets["BOTTOM"]).size == n
    np.testing.assert_array_equal(table.pairs[:, 0], 3 * table.nodes[:, 0])
    np.testing.assert_array_equal(table.pairs[:, 5], 3 * table.nodes[:, 1] + 2)
    assert table.ndof == 3 * points.shape[0]
    np.testing.assert_allclose(table.frames[:, 2], np.tile([0.0, 0.0, -1.0], (n, 1)))


def test_custom_node_dofs(tmp_path):
    rng = np.random.default_rng(12)
    points, qa, qb, n = _patch(rng)
    path = _write(tmp_path, "inp", points, qa, qb, n)
    node_dofs = np.arange(3 * points.shape[0]).reshape(3, -1).T  # blocked numbering: x of all, y of all, z ...
    table = interface_from_mesh(path, "TOP", "BOTTOM", [0.0, 0.0, 1.0], node_dofs=node_dofs)
    np.testing.assert_array_equal(table.pairs[:, 2], 2 * points.shape[0] + table.nodes[:, 0])
    with pytest.raises(ValueError, match=r"node_dofs must be an integer array of shape \(25, 3\)"):
        interface_from_mesh(path, "TOP", "BOTTOM", [0.0, 0.0, 1.0], node_dofs=node_dofs[:3])


def test_mesh_errors_are_one_line_naming_file_and_set(tmp_path):
    rng = np.random.default_rng(13)
    points, qa, qb, n = _patch(rng, gap=1e-4)
    path = _write(tmp_path, "inp", points, qa, qb, n)
    with pytest.raises(ValueError, match=r"patch.inp: no node set 'SIDE' \(named sets in the file: BOTTOM, TOP\)"):
        interface_from_mesh(path, "TOP", "SIDE", [0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match=r"patch.inp: node 0 of set TOP has no node of set BOTTOM within") as e:
        interface_from_mesh(path, "TOP", "BOTTOM", [0.0, 0.0, 1.0])
    assert "\n" not in str(e.value)
    table = interface_from_mesh(path, "TOP", "BOTTOM", [0.0, 0.0, 1.0], tol=2e-4)  # a gap within tol
    np.testing.assert_array_equal(table.nodes[:, 1], _expected_b(points, n))
    with pytest.raises(ValueError, match="no such mesh file"):
        interface_from_mesh(tmp_path / "none.msh", "TOP", "BOTTOM", [0.0, 0.0, 1.0])
    bad = tmp_path / "bad.msh"
    bad.write_text("$MeshFormat\nnot a mesh\n")
    with pytest.raises(ValueError, match=r"bad.msh: cannot read the mesh"):
        interface_from_mesh(bad, "TOP", "BOTTOM", [0.0, 0.0, 1.0])


def test_match_nodes_is_one_to_one():
    pts = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.0, 0, 0], [1.0, 0, 0], [0.5, 0, 0], [5.0, 0, 0]])
    np.testing.assert_array_equal(match_nodes(pts, [0, 1], [3, 2]), [2, 3])
    with pytest.raises(ValueError, match=r"f.inp: node sets A \(2 nodes\) and B \(3 nodes\)"):
        match_nodes(pts, [0, 1], [2, 3, 4], where="f.inp")
    with pytest.raises(ValueError, match="share node 2"):
        match_nodes(pts, [0, 2], [2, 3])
    with pytest.raises(ValueError, match="node 4 of set B is the nearest of several"):
        match_nodes(pts, [0, 1], [4, 5], tol=0.6)


def test_pair_springs_with_ground_and_subsets():
    from jointdyn.fe import pair_springs

    pairs = np.array([[0, 1, 2, 3, 4, 5], [6, 7, 8, -1, -1, -1]])
    S = pair_springs(pairs, [10.0, 20.0], [30.0, 40.0], 9).toarray()
    x = np.random.default_rng(2).normal(size=9)
    u = np.array([x[0] - x[3], x[1] - x[4], x[2] - x[5], x[6], x[7], x[8]])
    k = np.array([10.0, 10.0, 30.0, 20.0, 20.0, 40.0])
    assert x @ S @ x == pytest.approx(np.sum(k * u**2), rel=1e-14)
    S = pair_springs(pairs, 10.0, 30.0, 9, stuck=[True, False], closed=[False, True]).toarray()
    k = np.array([10.0, 10.0, 0.0, 0.0, 0.0, 30.0])
    assert x @ S @ x == pytest.approx(np.sum(k * u**2), rel=1e-14)

"""Harmonic balance with interfaces at scale (issue 23): an EPMC backbone and an HB branch of a chain model.

The model: a chain of nodes with three DOFs each (t1, t2, n), springs
between neighbours in each direction (``COUPLING``: stiff, so that the first
mode is isolated, as a bolted beam's first bending mode is; held to ground
more stiffly in t2, so that the first mode is in t1), and at every node a node pair against ground with a
preload peaked in the middle of the chain (the pressure of a bolted patch),
H = 5 and 128 samples. Measured: the EPMC backbone of mode 1 over three
decades of amplitude and the HB forced-response branch across its
resonance (gamma 0.8..1.2), wall-clock seconds and points, and where the
branch spends its time (Hill's method, against the continuation); beside
them, in the same run, the same chain with its pairs replaced by one scalar
contact per node (a Jenkins element along t1 under a normal spring, and a
spring kt along t2: the same stuck structure): the cost of today's contacts
on the same structure.

Quick: 16 nodes (48 DOFs, 16 pairs); full: 167 nodes (501 DOFs, 167 pairs),
the size of the issue's target (about 500 DOFs and 200 pairs; target 60 s
each on 2 cores), 5511 unknowns. There the Jacobian stays sparse from the
evaluation on (``jointdyn.hb._sparse``: this chain's K, M and C are sparse
and each pair couples only its own DOFs), the Newton systems are factorised
by SuperLU and the factors reused through GMRES (``factorisations`` counts
the dense and sparse ones), and the branch's stability is computed by
shift-invert Arnoldi (:mod:`jointdyn.hb.floquet`: dense Hill is beyond
``StabilityOptions.dense_max_rows`` here). Both backbones run
over the three decades, bounded to ``MAX_POINTS`` points.
"""

from __future__ import annotations

import time

import numpy as np

H, NS = 5, 128
MAX_POINTS = 400
#: stiffness of the springs between neighbouring nodes along t1, t2 and n, N/m, of the measured chain:
#: stiff against the pairs' kt (2e4 N/m), so that the chain's first mode is isolated as the first
#: bending mode of a bolted beam is (with every pair stuck the next mode along t1 is at 2.0 times mode
#: 1's frequency at 167 nodes, beyond the first t2 and n modes at 1.07 and 1.56 times)
COUPLING = (1.8e8, 2.34e8, 3.6e8)
#: ... and those of the chain's first version, the default of :func:`chain` (the tests and the tmdsimpy
#: comparison at 16 nodes use it): at 167 nodes its first eight modes lie within 4 % of each other (all
#: along t1), and its backbone followed a mode that changed its shape through that cluster as the pairs
#: began to slip: the continuation stalled about half-way up the three decades
SOFT_COUPLING = (1e5, 1.3e5, 2e5)


def chain(nodes: int, pairs: bool = True, coupling=SOFT_COUPLING):
    """The chain System (module docstring): interface pairs, or scalar contacts (``pairs=False``), its
    neighbours coupled by springs ``coupling`` (t1, t2, n; N/m)."""
    import jointdyn as jd
    from jointdyn.interfaces import Interface
    from jointdyn.kinematics import NormalSpring
    from jointdyn.laws.discrete import Jenkins

    n = 3 * nodes
    K = np.zeros((n, n))
    for i in range(nodes - 1):
        for d, kd in enumerate(coupling):
            a, b = 3 * i + d, 3 * (i + 1) + d
            K[a, a] += kd
            K[b, b] += kd
            K[a, b] -= kd
            K[b, a] -= kd
    # ground springs differ per direction: the uniform t1 and t2 modes are not degenerate
    K[np.arange(n), np.arange(n)] += np.tile([1e3, 4e3, 1e3], nodes)
    P = 10.0 * (0.2 + np.exp(-((np.arange(nodes) - nodes / 2) / (nodes / 4)) ** 2))
    f = np.zeros(n)
    f[0], f[1] = 1.0, 0.5
    kw = dict(M=0.1 * np.eye(n), C=1e-4 * K, K=K, force=f, force_phase_deg=np.where(np.arange(n) == 1, 90.0, 0.0),
              output_dof=0)
    if pairs:
        table = np.full((nodes, 6), -1)
        table[:, :3] = 3 * np.arange(nodes)[:, None] + np.arange(3)
        return jd.System(**kw, interfaces=(Interface(kt=2e4, kn=5e4, mu=0.5, preload=P, pairs=table),))
    # the pairs' stuck t2 stiffness as a spring to ground: the same stuck structure, mode 1 along t1
    kw["K"] = K + np.diag(np.tile([0.0, 2e4, 0.0], nodes))
    cs = tuple(jd.Contact(Jenkins(kt=2e4, mu=0.5, n_ref=float(p)), dof=3 * i,
                          normal=NormalSpring(kn=5e4, preload=float(p), dof=3 * i + 2)) for i, p in enumerate(P))
    return jd.System(**kw, contacts=cs)


def _backbone(s, a, top, max_points):
    from jointdyn.modes import epmc

    t0 = time.perf_counter()
    # bounded at the full size, so that a backbone slowed down by the kinks of hundreds of pairs' slip onsets ends
    bound = {} if max_points is None else {"max_points": max_points}
    b = epmc(s, (0.01 * a, top * a), harmonics=H, samples=NS, **bound)
    return time.perf_counter() - t0, b.status.value, b.points, _factorisations(b.counters)


def _branch(s):
    from jointdyn.hb import branch as hb_branch
    from jointdyn.hb import continue_hb

    hill = [0.0]
    # the branch's stability (jointdyn.hb.floquet.growths: dense Hill on chunks of points, Arnoldi point by
    # point), timed where the branch calls it
    origs = {"growths": hb_branch.growths}

    def timed(f):
        def run(*args):
            t = time.perf_counter()
            out = f(*args)
            hill[0] += time.perf_counter() - t
            return out
        return run

    for name, f in origs.items():
        setattr(hb_branch, name, timed(f))
    try:
        t0 = time.perf_counter()
        br = continue_hb(s, 0.8, 1.2, harmonics=H, samples=NS, condense=False)
        return (time.perf_counter() - t0, br.status.value, int(br.lam.size), hill[0],
                _factorisations(br.counters))
    finally:
        for name, f in origs.items():
            setattr(hb_branch, name, f)


def _factorisations(counters) -> int:
    """LU factorisations of the large Newton systems (dense and sparse; 0 below their size)."""
    return int(counters.get("factorisations", 0) + counters.get("sparse_factorisations", 0))


def run(quick: bool) -> dict:
    nodes = 16 if quick else 167
    out = {"nodes": nodes, "dofs": 3 * nodes, "pairs": nodes, "harmonics": H, "samples": NS}
    from jointdyn.hb.problem import reference_scales

    # one amplitude range for both backbones: the pairs' mean slip displacement (the default scale of the
    # contacts, the first contact's fy / kt, is that of the lightest pair at the end of the chain, 3 times smaller)
    kt, fy = reference_scales(chain(nodes, True, COUPLING))
    for name, pairs in (("interface", True), ("contacts", False)):
        s = chain(nodes, pairs, COUPLING)
        t, status, points, nf = _backbone(s, fy / kt, 10.0, MAX_POINTS)
        out[f"{name}_epmc_s"], out[f"{name}_epmc_status"], out[f"{name}_epmc_points"] = t, status, points
        out[f"{name}_epmc_factorisations"] = nf
        t, status, points, hill, nf = _branch(s)
        out[f"{name}_hb_s"], out[f"{name}_hb_status"], out[f"{name}_hb_points"] = t, status, points
        out[f"{name}_hb_hill_s"], out[f"{name}_hb_factorisations"] = hill, nf
    return out
